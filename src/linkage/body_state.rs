//! One body at a displacement field: the kernel every solver evaluates a body through.
//!
//! Node vectors, member responses, internal forces `K·u`, the tangent, and the loads and
//! prescribed displacements at a pseudo-time.
//!
//! Every solver of the crate (the linear solve, the Newton solves, contact) evaluates a body
//! through these functions. A displacement field is one value per body DOF (`d` per node, node
//! by node: see [`crate::linkage::DofMap`]), m; forces likewise, N.

use crate::linkage::{
    prescribed_displacements, scaled_member_response, Body, MemberResponse, Schedule,
    StiffnessAssembly,
};
use crate::Real;
use nalgebra::Vector3;

/// The displacement of `node` in `u` (per body DOF, `d` per node), m; zero past `d`.
pub fn node_vector(u: &[Real], d: usize, node: usize) -> Vector3<Real> {
    let mut v = Vector3::zeros();
    for k in 0..d {
        v[k] = u[node * d + k];
    }
    v
}

/// The response of member `m` at the displacement `u` (per body DOF), for the body's
/// kinematics and the member's material and modulus factor (paper Eq. 1 for linear
/// kinematics).
pub fn member_response_at(body: &Body, u: &[Real], m: usize) -> MemberResponse {
    let d = body.dimension.dofs_per_node();
    let member = body.members[m];
    let [a, b] = member.nodes;
    scaled_member_response(
        body.kinematics,
        &body.materials[member.material],
        body.modulus_factor(m),
        &body.nodes[a],
        &body.nodes[b],
        &node_vector(u, d, a),
        &node_vector(u, d, b),
    )
}

/// The internal (member) force per body DOF at `u`, N, into `out`: member `m` pushes its ends
/// with `∓N n` (its response at `u`, so large kinematics and cables are included).
pub fn internal_forces(body: &Body, u: &[Real], out: &mut [Real]) {
    let d = body.dimension.dofs_per_node();
    out.iter_mut().for_each(|v| *v = 0.0);
    for m in 0..body.members.len() {
        let r = member_response_at(body, u, m);
        let [a, b] = body.members[m].nodes;
        for k in 0..d {
            out[a * d + k] -= r.force * r.axis[k];
            out[b * d + k] += r.force * r.axis[k];
        }
    }
}

/// [`internal_forces`] into a new vector.
pub fn internal_force_vector(body: &Body, u: &[Real]) -> Vec<Real> {
    let mut out = vec![0.0; body.dof_count()];
    internal_forces(body, u, &mut out);
    out
}

/// `K u` of the paper's linear model (Eq. 3–4) per body DOF, N, into `out`: member `m` of axial
/// stiffness `stiffness[m]` (`AE/L`, N/m) along its undeformed axis. The linear solve keeps the
/// stiffness per member, so this is cheaper than [`internal_forces`] on a linear body.
pub fn linear_internal_forces(body: &Body, stiffness: &[Real], u: &[Real], out: &mut [Real]) {
    let d = body.dimension.dofs_per_node();
    out.iter_mut().for_each(|v| *v = 0.0);
    for (m, member) in body.members.iter().enumerate() {
        let [a, b] = member.nodes;
        let n = undeformed_axis(body, a, b);
        let force = stiffness[m] * linear_stretch(u, d, [a, b], &n);
        for k in 0..d {
            out[a * d + k] -= force * n[k];
            out[b * d + k] += force * n[k];
        }
    }
}

/// The stretch of the member between `nodes` in the paper's linear model, m: the displacement
/// `u` (per body DOF, `d` per node) of its second end relative to its first, along its
/// undeformed unit `axis`.
pub fn linear_stretch(u: &[Real], d: usize, nodes: [usize; 2], axis: &Vector3<Real>) -> Real {
    let [a, b] = nodes;
    (0..d)
        .map(|k| axis[k] * (u[b * d + k] - u[a * d + k]))
        .sum()
}

/// The unit vector from node `a` to node `b` of the undeformed body.
pub fn undeformed_axis(body: &Body, a: usize, b: usize) -> Vector3<Real> {
    (body.nodes[b] - body.nodes[a]).normalize()
}

/// `K_T(u) v` over all body DOFs, member by member, N (`v` per body DOF, m).
pub fn tangent_times(body: &Body, u: &[Real], v: &[Real], out: &mut [Real]) {
    let d = body.dimension.dofs_per_node();
    out.iter_mut().for_each(|x| *x = 0.0);
    for m in 0..body.members.len() {
        let [a, b] = body.members[m].nodes;
        let dv = node_vector(v, d, b) - node_vector(v, d, a);
        if dv == Vector3::zeros() {
            continue;
        }
        let f = member_response_at(body, u, m).tangent * dv;
        for k in 0..d {
            out[a * d + k] -= f[k];
            out[b * d + k] += f[k];
        }
    }
}

/// Fill the tangent stiffness `K_T(u)` (lower triangle of `K_ff`, N/m) into `values`, in the
/// pattern of `assembly` computed once.
pub fn fill_tangent(body: &Body, assembly: &StiffnessAssembly, u: &[Real], values: &mut Vec<Real>) {
    assembly.fill(body, |m| member_response_at(body, u, m).tangent, values);
}

/// A schedule's factor at pseudo-time `t` (step units, fractional between steps): linear
/// between the factors of the steps around it, exact at whole steps.
pub fn factor_at(schedule: &Schedule, t: Real, steps: usize) -> Real {
    let k = t.ceil().max(1.0) as usize;
    let f1 = schedule.factor(k, steps);
    let f0 = schedule.factor(k - 1, steps);
    let w = t - (k - 1) as Real;
    if w >= 1.0 {
        f1
    } else {
        f0 + w * (f1 - f0)
    }
}

/// The applied force per body DOF at pseudo-time `t` of `steps`, N: each load at its
/// schedule's [`factor_at`].
pub fn loads_at(body: &Body, t: Real, steps: usize) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut f = vec![0.0; body.dof_count()];
    for l in &body.loads {
        let factor = factor_at(&l.schedule, t, steps);
        for k in 0..d {
            f[l.node * d + k] += factor * l.force[k];
        }
    }
    f
}

/// The loads at full value per body DOF, N (the arc-length method's reference pattern).
pub fn full_loads(body: &Body) -> Vec<Real> {
    let d = body.dimension.dofs_per_node();
    let mut f = vec![0.0; body.dof_count()];
    for l in &body.loads {
        for k in 0..d {
            f[l.node * d + k] += l.force[k];
        }
    }
    f
}

/// The prescribed displacement per body DOF at pseudo-time `t` of `steps`, m (zero at free
/// DOFs and at supports that only hold).
pub fn prescribed_at(body: &Body, t: Real, steps: usize) -> Vec<Real> {
    prescribed_displacements(body, |schedule| factor_at(schedule, t, steps))
}

/// The Euclidean norm of `v`.
pub fn norm(v: &[Real]) -> Real {
    v.iter().map(|x| x * x).sum::<Real>().sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{Dimension, Material, Member, NodalLoad};

    /// A bar along x, 2 m, EA = 2e5 N: AE/L = 1e5 N/m.
    fn bar() -> Body {
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("m", 2e9, 1e-4));
        body.nodes = vec![Vector3::zeros(), Vector3::new(2.0, 0.0, 0.0)];
        body.members.push(Member {
            nodes: [0, 1],
            material: 0,
        });
        body.loads.push(NodalLoad {
            node: 1,
            force: Vector3::new(10.0, -4.0, 0.0),
            schedule: Schedule::Linear,
        });
        body
    }

    #[test]
    fn internal_forces_are_k_u_for_a_stretched_bar() {
        let body = bar();
        // Node 2 moves 1 mm along the bar and 5 mm across: N = 1e5 · 1e-3 = 100 N.
        let u = [0.0, 0.0, 1e-3, 5e-3];
        let f = internal_force_vector(&body, &u);
        assert!(
            (f[0] + 100.0).abs() < 1e-9 && (f[2] - 100.0).abs() < 1e-9,
            "{f:?}"
        );
        assert!(f[1].abs() < 1e-12 && f[3].abs() < 1e-12);
        let mut g = vec![0.0; 4];
        linear_internal_forces(&body, &[1e5], &u, &mut g);
        for (a, b) in f.iter().zip(&g) {
            assert!((a - b).abs() < 1e-9);
        }
        // The tangent of a linear bar is K itself: K_T v = K v.
        let mut t = vec![0.0; 4];
        tangent_times(&body, &[0.0; 4], &u, &mut t);
        for (a, b) in f.iter().zip(&t) {
            assert!((a - b).abs() < 1e-9);
        }
    }

    #[test]
    fn loads_grow_linearly_between_steps() {
        let body = bar();
        // Step 1.5 of 4 on the linear schedule: factor 1.5 / 4.
        let f = loads_at(&body, 1.5, 4);
        assert!((f[2] - 10.0 * 0.375).abs() < 1e-12 && (f[3] + 4.0 * 0.375).abs() < 1e-12);
        assert_eq!(loads_at(&body, 0.0, 4), vec![0.0; 4]);
        assert_eq!(full_loads(&body), vec![0.0, 0.0, 10.0, -4.0]);
        assert_eq!(norm(&[3.0, 4.0]), 5.0);
    }
}
