//! The set of active contacts the settle loop iterates on, and the contacts reported per node.

use crate::contact::SlipState;
use crate::Real;
use nalgebra::Vector3;

/// A node held against a surface during one contact iteration (or, for [`Target::Sharp`], a
/// point of an obstacle's sharp edge held against a body's surface).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ActiveContact {
    /// Body of the node (index in the scene); for [`Target::Sharp`], the body pressed.
    pub body: usize,
    /// The node, 0-based; for [`Target::Sharp`], the obstacle's sharp point.
    pub node: usize,
    /// What it presses on.
    pub with: Target,
}

/// What a node presses on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Target {
    /// An obstacle (index in the scene).
    Obstacle(usize),
    /// A boundary segment of a 2D body.
    Segment {
        /// The body (index in the scene).
        body: usize,
        /// The segment: from the i-th node of the body's boundary loop to the next.
        segment: usize,
    },
    /// A surface patch of a 3D body.
    Patch {
        /// The body (index in the scene).
        body: usize,
        /// The patch (index in the body's patches).
        patch: usize,
    },
    /// A boundary vertex of a 2D body, pressed along the mean normal of its two segments (a
    /// node equally near both).
    Vertex {
        /// The body (index in the scene).
        body: usize,
        /// Position of the vertex in the body's boundary loop.
        vertex: usize,
    },
    /// A point along a sharp edge of a polyhedral obstacle (2D: a corner of its section)
    /// pressing a patch (2D: a boundary segment) of the contact's body: an edge or corner
    /// between the nodes of a coarse body.
    Sharp {
        /// The obstacle (index in the scene).
        obstacle: usize,
        /// The patch (3D) or boundary segment (2D) of the body pressed.
        patch: usize,
    },
    /// The other end of a broken member of the node's own body whose crack has closed (its
    /// ends closer than its rest length): the crack's faces press on each other there.
    Closing {
        /// The body (index in the scene).
        body: usize,
        /// The broken member (index in the body's members); the node is its first end.
        member: usize,
    },
    /// An edge between two surface patches of a 3D body, pressed along the area-weighted mean
    /// normal of its two patches: the node's nearest point of the surface lies on both patches
    /// (a tie, see `contact::ties`).
    Edge {
        /// The body (index in the scene).
        body: usize,
        /// The body nodes at the edge's ends, 0-based, smaller first.
        nodes: [usize; 2],
    },
    /// A surface node (corner) of a 3D body, pressed along the area-weighted mean normal of
    /// the patches around it that the node is equally near: its nearest point of the surface
    /// is that corner, on several patches at once (a tie, see `contact::ties`).
    Corner {
        /// The body (index in the scene).
        body: usize,
        /// The body node at the corner, 0-based.
        node: usize,
        /// Which patches around the corner tied: bit i for the i-th of them in ascending
        /// patch order (`PatchSurface::fan`).
        tied: u64,
    },
}

/// The active contacts, sorted: two sets compare equal when the same nodes touch the same
/// surfaces (the settle loop stops there, and detects a set it has seen before).
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash)]
pub struct ContactSet {
    /// Sorted, without repeats.
    pub contacts: Vec<ActiveContact>,
}

impl ContactSet {
    /// A set from contacts in any order.
    pub fn new(mut contacts: Vec<ActiveContact>) -> Self {
        contacts.sort_unstable();
        contacts.dedup();
        ContactSet { contacts }
    }

    /// Number of active contacts.
    pub fn len(&self) -> usize {
        self.contacts.len()
    }

    /// Whether nothing touches.
    pub fn is_empty(&self) -> bool {
        self.contacts.is_empty()
    }

    /// Contacts in `self` and not in `other`, then in `other` and not in `self`.
    pub fn difference(&self, other: &ContactSet) -> (Vec<ActiveContact>, Vec<ActiveContact>) {
        let only = |a: &ContactSet, b: &ContactSet| {
            a.contacts
                .iter()
                .filter(|c| b.contacts.binary_search(c).is_err())
                .copied()
                .collect::<Vec<_>>()
        };
        (only(self, other), only(other, self))
    }
}

/// A node pressing on an obstacle or another body at a solved step.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeContact {
    /// The node, 0-based.
    pub node: usize,
    /// Name of the obstacle or body it touches.
    pub with: String,
    /// Penetration depth, m (≥ 0).
    pub depth: Real,
    /// Force the node receives, N: `normal_force · normal + tangential_force`.
    pub force: Vector3<Real>,
    /// Unit normal of the contact, from the surface towards the node.
    pub normal: Vector3<Real>,
    /// Normal force the node receives, N (≥ 0 pressing).
    pub normal_force: Real,
    /// Tangential (friction) force the node receives, N.
    pub tangential_force: Vector3<Real>,
    /// Whether the contact sticks or slips (frictionless contacts slip).
    pub state: SlipState,
    /// Slip of the node over what it touches, accumulated since the contact began, m.
    pub slip: Vector3<Real>,
    /// Energy friction dissipated in the increment solved by the contacts this node presses
    /// with, J: `−f_T · Δs` of each contact's return mapping (`Δs` the slip it added), counted
    /// once per contact (on its pressing node; a sharp point's share by weight), never on
    /// the nodes that only receive a contact's reaction.
    pub friction_dissipated: Real,
}
