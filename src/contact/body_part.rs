//! One body's part of a contact solve (its DOFs, stiffness pattern, displacements and penalty)
//! and the positions and moves read from it: what detection, evaluation, self-contact and the
//! solvers share, knowing nothing of the loop that drives them.

use crate::contact::Penalty;
use crate::linkage::body_state::node_vector;
use crate::linkage::{Body, DofMap, StiffnessAssembly};
use crate::Real;
use nalgebra::Vector3;

/// One body's part of the solve.
pub(crate) struct BodyPart {
    /// The body's free and supported DOFs.
    pub(crate) dofs: DofMap,
    /// The body's stiffness pattern, computed once.
    pub(crate) assembly: StiffnessAssembly,
    /// Displacement per body DOF, m (kept between steps: the next step starts here).
    pub(crate) u: Vec<Real>,
    /// The body's penalty.
    pub(crate) penalty: Penalty,
    /// Penetration above which a step is warned about, m.
    pub(crate) tolerance: Real,
    /// The body's tangent values in its assembly's pattern, N/m.
    pub(crate) local: Vec<Real>,
}

/// The deformed position of `node` of body `b`, m.
pub(crate) fn position(
    bodies: &[Body],
    parts: &[BodyPart],
    b: usize,
    node: usize,
) -> Vector3<Real> {
    let part = &parts[b];
    bodies[b].nodes[node] + node_vector(&part.u, part.dofs.dofs_per_node, node)
}

/// The largest nodal length of a move of `part`, m, given per free index by `moved` (m).
pub(crate) fn largest_nodal_move(part: &BodyPart, mut moved: impl FnMut(usize) -> Real) -> Real {
    let d = part.dofs.dofs_per_node;
    let mut moves = vec![0.0; part.u.len() / d.max(1)];
    for (i, &dof) in part.dofs.free.iter().enumerate() {
        let m = moved(i);
        moves[dof / d] += m * m;
    }
    moves.into_iter().map(Real::sqrt).fold(0.0, Real::max)
}
