//! Load patterns: the loads and prescribed displacements of one schedule, solved once each
//! (the linear model lets every step be a weighted sum of them).

use crate::linkage::body_state::linear_internal_forces;
use crate::linkage::{Body, DofMap, Schedule};
use crate::Real;
use nalgebra::Vector3;

/// The loads and prescribed displacements that share one schedule, and the displacement field
/// they cause at full value: the linear model lets each step be a sum of these (superposition).
#[derive(Clone, Debug)]
pub(crate) struct LoadPattern {
    /// How the pattern grows over the steps.
    pub(crate) schedule: Schedule,
    /// Applied force per body DOF at full value, N.
    pub(crate) forces: Vec<Real>,
    /// Displacement per body DOF at full value, m: prescribed at supported DOFs, solved at free ones.
    pub(crate) displacements: Vec<Real>,
}

/// Group loads and prescribed displacements by schedule and solve `K_ff U_f = F_f − K_fs U_s`
/// (paper Eq. 6 with non-zero `U_s`) once for each group. `solve` replaces a right-hand
/// side by its solution, or says it could not (then `None`).
pub(crate) fn solve_load_patterns(
    body: &Body,
    dofs: &DofMap,
    n: usize,
    stiffness: &[Real],
    solve: &mut dyn FnMut(&mut [Real]) -> bool,
) -> Option<Vec<LoadPattern>> {
    let nd = body.dof_count();
    let d = dofs.dofs_per_node;
    let mut patterns: Vec<LoadPattern> = Vec::new();
    let pattern_of = |schedule: &Schedule, patterns: &mut Vec<LoadPattern>| -> usize {
        if let Some(i) = patterns.iter().position(|p| &p.schedule == schedule) {
            return i;
        }
        patterns.push(LoadPattern {
            schedule: schedule.clone(),
            forces: vec![0.0; nd],
            displacements: vec![0.0; nd],
        });
        patterns.len() - 1
    };
    for l in &body.loads {
        let p = pattern_of(&l.schedule, &mut patterns);
        for dir in 0..d {
            patterns[p].forces[l.node * d + dir] += l.force[dir];
        }
    }
    for s in &body.supports {
        if s.displacement == Vector3::zeros() {
            continue;
        }
        let p = pattern_of(&s.schedule, &mut patterns);
        for dir in 0..d {
            if s.fixed[dir] {
                patterns[p].displacements[s.node * d + dir] = s.displacement[dir];
            }
        }
    }
    let mut rhs = vec![0.0; n];
    let mut internal = vec![0.0; nd];
    for p in &mut patterns {
        // F_f − K_fs U_s: the internal force of the prescribed displacements alone.
        linear_internal_forces(body, stiffness, &p.displacements, &mut internal);
        for (i, &dof) in dofs.free.iter().enumerate() {
            rhs[i] = p.forces[dof] - internal[dof];
        }
        if !rhs.is_empty() && !solve(&mut rhs) {
            return None;
        }
        for (i, &dof) in dofs.free.iter().enumerate() {
            p.displacements[dof] = rhs[i];
        }
    }
    Some(patterns)
}
