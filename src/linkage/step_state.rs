//! The solved state of a body at one step, and its post-processing from a displacement field.
//!
//! Shared by the linear solve ([`crate::linkage::Equilibrium`]) and the Newton solve.

use crate::linkage::body_state::{node_vector, norm};
use crate::linkage::{Body, Convergence, DofMap, DofSlot};
use crate::Real;
use nalgebra::Vector3;

/// The solved state of a body at one load step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepState {
    /// Displacement of every node, m.
    pub displacements: Vec<Vector3<Real>>,
    /// Axial force of every member, N, tension positive.
    pub axial_forces: Vec<Real>,
    /// Engineering strain of every member (change of length over length), tension positive.
    pub strains: Vec<Real>,
    /// Axial stress of every member, Pa, tension positive (axial force over area).
    pub stresses: Vec<Real>,
    /// Members (0-based) whose stress is beyond their material's strength.
    pub overloaded: Vec<usize>,
    /// Per supported node (0-based), the force the supports exert on the body, N (paper Eq. 10).
    pub reactions: Vec<(usize, Vector3<Real>)>,
    /// Per loaded node (0-based), the applied force at this step, N.
    pub loads: Vec<(usize, Vector3<Real>)>,
    /// Out-of-balance force at the free DOFs over the largest of applied force and reaction
    /// norms (0 when nothing is loaded).
    pub residual: Real,
    /// The force the contact solver took the residual relative to, N (the largest of the
    /// applied, reaction and contact force norms, and of the run's largest so far); 0 where
    /// the residual is not a contact step's.
    pub force_scale: Real,
    /// Equilibrium iterations this step took (1 for a linear step, Newton iterations otherwise).
    pub iterations: usize,
    /// How many times the step's load increment was halved because Newton did not converge.
    pub cuts: usize,
    /// Conjugate-gradient iterations this step's solves took (0 with the direct solver).
    pub linear_iterations: usize,
    /// Relative residual after each Newton iteration of the step's last increment (empty for a
    /// linear step): shows the convergence rate.
    pub residual_history: Vec<Real>,
    /// The load factor the step reached when the path decides it (arc length); `None` when the
    /// schedules decide it.
    pub load_factor: Option<Real>,
    /// Negative pivots of the tangent stiffness at the solution (0: stable; k: unstable in k
    /// directions). Counted by the LDLᵀ factorization of the last Newton iteration, whose
    /// iterate differs from the solution by less than the displacement tolerance; always 0 for
    /// a linear body.
    pub negative_pivots: usize,
    /// The most negative pivots of any tangent factored during the step's Newton iterations
    /// (the increments that converged); above [`Self::negative_pivots`] when an iterate
    /// crossed an unstable region on its way to the solution: the load passed a limit point
    /// within the step (a snap-through). Always 0 for a linear body.
    pub negative_pivots_met: usize,
    /// Whether the tangent was solved by conjugate gradients, which count no pivots: then
    /// `negative_pivots` (0) says nothing of the state's stability.
    pub pivots_unknown: bool,
    /// Members broken so far and in this step, pieces fallen off: a body with breaking
    /// members only.
    pub fracture: Option<crate::linkage::fracture::FractureState>,
}

/// Build the state from a displacement per body DOF `u` (m), the applied force per body DOF
/// `forces` (N), the internal (member) force per body DOF `internal` (N) and each member's
/// `(strain, axial force)`. Reactions are `internal − forces` at the supported DOFs (Eq. 10);
/// the residual is `|internal − forces|` over the free DOFs relative to the larger of the
/// applied force and reaction norms.
pub(crate) fn post_process(
    body: &Body,
    dofs: &DofMap,
    u: &[Real],
    forces: &[Real],
    internal: &[Real],
    members: impl Iterator<Item = (Real, Real)>,
) -> StepState {
    let d = dofs.dofs_per_node;
    let mut state = StepState {
        displacements: (0..body.nodes.len())
            .map(|i| node_vector(u, d, i))
            .collect(),
        ..Default::default()
    };
    for ((strain, force), member) in members.zip(&body.members) {
        let material = &body.materials[member.material];
        let stress = force / material.area;
        state.strains.push(strain);
        state.stresses.push(stress);
        state.axial_forces.push(force);
        if material.is_overloaded(stress) {
            state.overloaded.push(state.axial_forces.len() - 1);
        }
    }
    let mut supported_node = vec![false; body.nodes.len()];
    for &dof in &dofs.supported {
        supported_node[dof / d] = true;
    }
    for (node, _) in supported_node.iter().enumerate().filter(|(_, s)| **s) {
        let mut r = Vector3::zeros();
        for k in 0..d {
            if let DofSlot::Supported(_) = dofs.slots[node * d + k] {
                r[k] = internal[node * d + k] - forces[node * d + k];
            }
        }
        state.reactions.push((node, r));
    }
    let mut loaded = vec![false; body.nodes.len()];
    for l in &body.loads {
        loaded[l.node] = true;
    }
    for p in &body.pressures {
        for face in p.faces.nodes() {
            face.iter().for_each(|&n| loaded[n] = true);
        }
    }
    for (node, _) in loaded.iter().enumerate().filter(|(_, l)| **l) {
        let mut f = Vector3::zeros();
        for k in 0..d {
            f[k] = forces[node * d + k];
        }
        state.loads.push((node, f));
    }
    state.residual = relative_residual(dofs, forces, internal);
    state
}

/// `|internal − forces|` over the free DOFs, relative to the larger of the norm of the applied
/// forces and the norm of the reactions (`internal − forces` at the supported DOFs); 0 when
/// both are zero.
pub(crate) fn relative_residual(dofs: &DofMap, forces: &[Real], internal: &[Real]) -> Real {
    let out_of_balance = free_out_of_balance(dofs, forces, internal);
    Convergence::relative(out_of_balance, force_scale(dofs, forces, internal))
}

/// The larger of the applied force norm and the reaction norm, N: what "relative" refers to.
pub(crate) fn force_scale(dofs: &DofMap, forces: &[Real], internal: &[Real]) -> Real {
    let applied = norm(forces);
    let reacted = difference_norm(&dofs.supported, forces, internal);
    applied.max(reacted)
}

/// `|internal − forces|` over the free DOFs, N: the out-of-balance force.
pub(crate) fn free_out_of_balance(dofs: &DofMap, forces: &[Real], internal: &[Real]) -> Real {
    difference_norm(&dofs.free, forces, internal)
}

/// `|internal − forces|` over the body DOFs `over`, N.
fn difference_norm(over: &[usize], forces: &[Real], internal: &[Real]) -> Real {
    over.iter()
        .map(|&dof| (internal[dof] - forces[dof]).powi(2))
        .sum::<Real>()
        .sqrt()
}
