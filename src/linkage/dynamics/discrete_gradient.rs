//! Member forces of the energy–momentum method: the discrete gradient of each member's energy
//! between the two ends of a time step (see the module README).

use crate::linkage::body_state::node_vector;
use crate::linkage::{Body, Kinematics};
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// A member's stretch measure `q` (m) and the unit direction of its force. Linear kinematics:
/// `q = n₀·(u_b − u_a)` along `n₀`; large: `q = l − L` along the current axis.
fn stretch(body: &Body, u: &[Real], m: usize) -> (Real, Vector3<Real>) {
    let d = body.dimension.dofs_per_node();
    let [a, b] = body.members[m].nodes;
    let d0 = body.nodes[b] - body.nodes[a];
    let rest = d0.norm();
    let du = node_vector(u, d, b) - node_vector(u, d, a);
    match body.kinematics {
        Kinematics::Linear => {
            let n0 = d0 / rest;
            (n0.dot(&du), n0)
        }
        Kinematics::Large => {
            let dd = d0 + du;
            (dd.norm() - rest, dd)
        }
    }
}

/// `E A / L` of member `m` (N/m), with its modulus factor, and its rest length `L` (m).
fn stiffness_and_length(body: &Body, m: usize) -> (Real, Real) {
    let member = body.members[m];
    let [a, b] = member.nodes;
    let rest = (body.nodes[b] - body.nodes[a]).norm();
    let material = &body.materials[member.material];
    (
        material.youngs_modulus * body.modulus_factor(m) * material.area / rest,
        rest,
    )
}

/// The energy of member `m` at stretch `q` (m), J: `k q² / 2` where its behaviour lets it act
/// (strain `q / L`), else 0.
fn potential(body: &Body, m: usize, q: Real) -> Real {
    let (k, rest) = stiffness_and_length(body, m);
    let behaviour = body.materials[body.members[m].material].behaviour;
    if behaviour.is_active(q / rest) {
        0.5 * k * q * q
    } else {
        0.0
    }
}

/// The strain energy of `body` at displacement `u` (per body DOF, m), J: `Σ k q² / 2` over the
/// members that act.
pub fn strain_energy(body: &Body, u: &[Real]) -> Real {
    (0..body.members.len())
        .map(|m| potential(body, m, stretch(body, u, m).0))
        .sum()
}

/// The discrete-gradient axial force of member `m` between stretches `q0` and `q1` (m), N:
/// `[V(q1) − V(q0)]/(q1 − q0)`; `k (q0 + q1)/2` when the member acts at both ends (exact, and
/// free of the quotient's cancellation as `q1 → q0`), 0 when at neither.
fn algorithmic_force(body: &Body, m: usize, q0: Real, q1: Real) -> Real {
    let (k, rest) = stiffness_and_length(body, m);
    let behaviour = body.materials[body.members[m].material].behaviour;
    match (
        behaviour.is_active(q0 / rest),
        behaviour.is_active(q1 / rest),
    ) {
        (true, true) => 0.5 * k * (q0 + q1),
        (false, false) => 0.0,
        _ => (potential(body, m, q1) - potential(body, m, q0)) / (q1 - q0),
    }
}

/// The internal force per body DOF (N) of the discrete gradient between displacements `u0`
/// and `u1` (per body DOF, m), into `out`: member `m` pushes its ends with `∓N̄ e`, `N̄` its
/// [`algorithmic_force`] and `e = n₀` (linear) or `(d₀ + d₁)/(l₀ + l₁)` (large: the discrete
/// gradient of the length, not a unit vector). Then `f·(u1 − u0) = V(u1) − V(u0)` exactly, the
/// forces of a member are equal and opposite and, for large kinematics, along the midpoint
/// chord: energy, linear and angular momentum are conserved.
pub fn discrete_gradient_forces(body: &Body, u0: &[Real], u1: &[Real], out: &mut [Real]) {
    let d = body.dimension.dofs_per_node();
    out.iter_mut().for_each(|v| *v = 0.0);
    for m in 0..body.members.len() {
        let (q0, e0) = stretch(body, u0, m);
        let (q1, e1) = stretch(body, u1, m);
        let n = algorithmic_force(body, m, q0, q1);
        if n == 0.0 {
            continue;
        }
        let dir = match body.kinematics {
            Kinematics::Linear => e0,
            Kinematics::Large => {
                let (_, rest) = stiffness_and_length(body, m);
                (e0 + e1) / (q0 + q1 + 2.0 * rest)
            }
        };
        let [a, b] = body.members[m].nodes;
        for k in 0..d {
            out[a * d + k] -= n * dir[k];
            out[b * d + k] += n * dir[k];
        }
    }
}

/// The 3×3 block of member `m`'s tangent of the discrete-gradient force with respect to the
/// midpoint `y = (u0 + u1)/2`, N/m, for an elastic member with large kinematics: the symmetric
/// part `g I + (g'/2)(d̄ eᵀ + e d̄ᵀ)` of `∂(g(l̄) d̄)/∂d̄ = g I + g' d̄ eᵀ`, with `d̄` the midpoint
/// chord, `l̄ = (l₀ + l₁)/2`, `g = k (1 − L/l̄)`, `g' = k L / l̄²`, `e = d₁ / l₁`. `None` for other
/// members (their response tangent at `y` serves).
pub fn discrete_gradient_block(
    body: &Body,
    u0: &[Real],
    u1: &[Real],
    m: usize,
) -> Option<Matrix3<Real>> {
    if body.kinematics != Kinematics::Large {
        return None;
    }
    let behaviour = body.materials[body.members[m].material].behaviour;
    let (k, rest) = stiffness_and_length(body, m);
    let (q0, d0) = stretch(body, u0, m);
    let (q1, d1) = stretch(body, u1, m);
    if !(behaviour.is_active(q0 / rest) && behaviour.is_active(q1 / rest)) {
        return None;
    }
    let l1 = q1 + rest;
    let lbar = rest + 0.5 * (q0 + q1);
    if l1 <= 0.0 || lbar <= 0.0 {
        return None;
    }
    let dbar = 0.5 * (d0 + d1);
    let e = d1 / l1;
    let g = k * (1.0 - rest / lbar);
    let gp = k * rest / (lbar * lbar);
    Some(Matrix3::identity() * g + (dbar * e.transpose() + e * dbar.transpose()) * (0.5 * gp))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{Behaviour, Dimension, Material, Member};

    fn bar(kinematics: Kinematics, behaviour: Behaviour) -> Body {
        let mut body = Body::new("bar", Dimension::Three);
        let mut m = Material::new("m", 2e3, 1e-2);
        m.behaviour = behaviour;
        body.materials.push(m);
        body.nodes = vec![Vector3::zeros(), Vector3::new(2.0, 0.0, 0.0)];
        body.members.push(Member {
            nodes: [0, 1],
            material: 0,
        });
        body.kinematics = kinematics;
        body
    }

    /// `f·(u1 − u0) = V(u1) − V(u0)` to round-off, for every kinematics and behaviour, and a
    /// step that crosses slack.
    #[test]
    fn the_discrete_gradient_does_the_work_of_the_energy_difference() {
        let u0 = [0.0, 0.0, 0.0, 0.3, -0.2, 0.1];
        let u1 = [0.1, 0.05, 0.0, -0.4, 0.6, -0.2];
        for kin in [Kinematics::Linear, Kinematics::Large] {
            for beh in [
                Behaviour::Elastic,
                Behaviour::TensionOnly,
                Behaviour::CompressionOnly,
            ] {
                let body = bar(kin, beh);
                let mut f = [0.0; 6];
                discrete_gradient_forces(&body, &u0, &u1, &mut f);
                let work: Real = f
                    .iter()
                    .zip(u1.iter().zip(&u0))
                    .map(|(f, (a, b))| f * (a - b))
                    .sum();
                let dv = strain_energy(&body, &u1) - strain_energy(&body, &u0);
                assert!(
                    (work - dv).abs() < 1e-12 * (1.0 + dv.abs()),
                    "{kin:?} {beh:?}: {work} vs {dv}"
                );
                // Equal and opposite.
                for k in 0..3 {
                    assert!((f[k] + f[3 + k]).abs() < 1e-12);
                }
            }
        }
    }

    /// The symmetric block against central differences of the force's symmetric part.
    #[test]
    fn the_block_is_the_symmetric_part_of_the_derivative() {
        let body = bar(Kinematics::Large, Behaviour::Elastic);
        let u0 = [0.0, 0.0, 0.0, 0.3, -0.2, 0.1];
        let y = [0.0, 0.0, 0.0, 0.1, 0.3, -0.1];
        let u1 = |y: &[Real; 6]| -> [Real; 6] { std::array::from_fn(|i| 2.0 * y[i] - u0[i]) };
        let block = discrete_gradient_block(&body, &u0, &u1(&y), 0).unwrap();
        let h = 1e-6;
        let mut jac = Matrix3::zeros();
        for j in 0..3 {
            let (mut yp, mut ym) = (y, y);
            yp[3 + j] += h;
            ym[3 + j] -= h;
            let (mut fp, mut fm) = ([0.0; 6], [0.0; 6]);
            discrete_gradient_forces(&body, &u0, &u1(&yp), &mut fp);
            discrete_gradient_forces(&body, &u0, &u1(&ym), &mut fm);
            for i in 0..3 {
                jac[(i, j)] = (fp[3 + i] - fm[3 + i]) / (2.0 * h);
            }
        }
        let sym = (jac + jac.transpose()) * 0.5;
        assert!(
            (sym - block).norm() < 1e-5 * block.norm(),
            "{sym} vs {block}"
        );
    }
}
