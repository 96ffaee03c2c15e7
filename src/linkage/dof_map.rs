//! The partition of a body's DOFs into free and supported ones (paper Eq. 5).

use crate::linkage::Body;

/// Where one degree of freedom of a body goes in the partitioned system of paper Eq. 5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DofSlot {
    /// Row/column of `K_ff` (an unknown displacement).
    Free(usize),
    /// Index among the supported DOFs (an unknown reaction, a known displacement).
    Supported(usize),
}

/// The free/support partition of a body's DOFs (paper Eq. 5). A body DOF is
/// `node * dofs_per_node + direction`; free DOFs are numbered node by node, so the DOFs of one
/// node are consecutive and a node's neighbours come in node order.
#[derive(Clone, Debug, PartialEq)]
pub struct DofMap {
    /// 2 or 3.
    pub dofs_per_node: usize,
    /// Slot of every body DOF.
    pub slots: Vec<DofSlot>,
    /// Body DOF of each free DOF.
    pub free: Vec<usize>,
    /// Body DOF of each supported DOF.
    pub supported: Vec<usize>,
}

impl DofMap {
    /// Partition the DOFs of `body` by its supports (the fixed directions of a node combine).
    pub fn new(body: &Body) -> Self {
        let d = body.dimension.dofs_per_node();
        let mut fixed = vec![false; body.dof_count()];
        for s in &body.supports {
            for dir in 0..d {
                fixed[s.node * d + dir] |= s.fixed[dir];
            }
        }
        let mut map = DofMap {
            dofs_per_node: d,
            slots: Vec::with_capacity(fixed.len()),
            free: Vec::new(),
            supported: Vec::new(),
        };
        for (dof, is_fixed) in fixed.into_iter().enumerate() {
            if is_fixed {
                map.slots.push(DofSlot::Supported(map.supported.len()));
                map.supported.push(dof);
            } else {
                map.slots.push(DofSlot::Free(map.free.len()));
                map.free.push(dof);
            }
        }
        map
    }

    /// The node (0-based) and direction (0 = x, 1 = y, 2 = z) of a body DOF.
    pub fn node_and_direction(&self, dof: usize) -> (usize, usize) {
        (dof / self.dofs_per_node, dof % self.dofs_per_node)
    }

    /// The free index of (`node`, `direction`), if that DOF is free.
    pub fn free_index(&self, node: usize, direction: usize) -> Option<usize> {
        match self.slots[node * self.dofs_per_node + direction] {
            DofSlot::Free(i) => Some(i),
            DofSlot::Supported(_) => None,
        }
    }
}

/// "x", "y" or "z".
pub fn direction_name(direction: usize) -> &'static str {
    ["x", "y", "z"][direction.min(2)]
}
