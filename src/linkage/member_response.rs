//! One member's axial force and tangent stiffness at a displacement state.
//!
//! For both kinematics and every material behaviour.

use crate::linkage::{Kinematics, Material};
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// Stiffness a member keeps in the *tangent only* while it carries no force (a slack cable, a
/// strut pulled apart), as a fraction of `E A / L`, in every direction. It keeps the tangent
/// non-singular when a node hangs on slack members only; the internal forces, the residual and
/// so the converged answer use the true zero force.
pub const SLACK_STIFFNESS: Real = 1e-6;

/// A member's response at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MemberResponse {
    /// Engineering strain: `n₀·(u_b − u_a)/L` (linear) or `(l − L)/L` (large), tension positive.
    pub strain: Real,
    /// Axial force, N, tension positive: `E A ε` where the behaviour lets the member act, else 0.
    pub force: Real,
    /// Unit vector from end a to end b along which the force acts: the undeformed axis
    /// (linear) or the current one (large). End b receives `−force · axis`, end a `+force · axis`
    /// from the member (its internal force vector is `[−N n; N n]`).
    pub axis: Vector3<Real>,
    /// The 3×3 block `B` of the member's tangent stiffness `[B −B; −B B]`, N/m:
    /// `(E A / L) n nᵀ` (linear), `(E A / L) n nᵀ + (N / l)(I − n nᵀ)` (large: material plus
    /// geometric stiffness), or `SLACK_STIFFNESS · (E A / L) I` for a member that carries no force.
    pub tangent: Matrix3<Real>,
}

/// The response of a member of `material` from undeformed ends `a0`, `b0` (m) displaced by
/// `ua`, `ub` (m).
pub fn member_response(
    kinematics: Kinematics,
    material: &Material,
    a0: &Vector3<Real>,
    b0: &Vector3<Real>,
    ua: &Vector3<Real>,
    ub: &Vector3<Real>,
) -> MemberResponse {
    scaled_member_response(kinematics, material, 1.0, a0, b0, ua, ub)
}

/// [`member_response`] of a member whose Young's modulus is `modulus_factor` times its
/// material's (a softened or broken member: see [`crate::linkage::Body::member_factors`]).
pub fn scaled_member_response(
    kinematics: Kinematics,
    material: &Material,
    modulus_factor: Real,
    a0: &Vector3<Real>,
    b0: &Vector3<Real>,
    ua: &Vector3<Real>,
    ub: &Vector3<Real>,
) -> MemberResponse {
    let d0 = b0 - a0;
    let rest = d0.norm();
    let n0 = d0 / rest;
    let ea = material.youngs_modulus * modulus_factor * material.area;
    let k = ea / rest;
    let (strain, axis, length) = match kinematics {
        Kinematics::Linear => (n0.dot(&(ub - ua)) / rest, n0, rest),
        Kinematics::Large => {
            let d = d0 + ub - ua;
            let l = d.norm();
            // A member squeezed to zero length has no direction: keep the undeformed one
            // (the iteration that got there is rejected by its residual anyway).
            let n = if l > 0.0 { d / l } else { n0 };
            ((l - rest) / rest, n, l)
        }
    };
    if !material.behaviour.is_active(strain) {
        return MemberResponse {
            strain,
            force: 0.0,
            axis,
            tangent: Matrix3::identity() * (SLACK_STIFFNESS * k),
        };
    }
    let force = ea * strain;
    let nn = axis * axis.transpose();
    let tangent = match kinematics {
        Kinematics::Linear => nn * k,
        Kinematics::Large if length > 0.0 => nn * k + (Matrix3::identity() - nn) * (force / length),
        Kinematics::Large => nn * k,
    };
    MemberResponse {
        strain,
        force,
        axis,
        tangent,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::Behaviour;

    fn v(x: Real, y: Real, z: Real) -> Vector3<Real> {
        Vector3::new(x, y, z)
    }

    /// The tangent is the derivative of the internal force `N n` at end b with respect to
    /// the position of end b: check it against central differences.
    #[test]
    fn large_tangent_is_the_derivative_of_the_force() {
        let m = Material::new("m", 3.0, 2.0);
        let (a0, b0) = (v(0.1, 0.2, -0.3), v(1.2, -0.4, 0.5));
        let ua = v(0.05, -0.1, 0.2);
        let ub = v(-0.3, 0.4, 0.1);
        let r = member_response(Kinematics::Large, &m, &a0, &b0, &ua, &ub);
        let h = 1e-6;
        for j in 0..3 {
            let mut e = Vector3::zeros();
            e[j] = h;
            let fp = member_response(Kinematics::Large, &m, &a0, &b0, &ua, &(ub + e));
            let fm = member_response(Kinematics::Large, &m, &a0, &b0, &ua, &(ub - e));
            let col = (fp.axis * fp.force - fm.axis * fm.force) / (2.0 * h);
            for i in 0..3 {
                assert!((col[i] - r.tangent[(i, j)]).abs() < 1e-7, "({i},{j})");
            }
        }
    }

    #[test]
    fn rigid_rotation_and_slack_cable_carry_no_force() {
        let mut m = Material::new("m", 200e9, 1e-4);
        let (a0, b0) = (v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
        // A quarter turn about z: b moves to (0, 1).
        let r = member_response(
            Kinematics::Large,
            &m,
            &a0,
            &b0,
            &v(0.0, 0.0, 0.0),
            &v(-1.0, 1.0, 0.0),
        );
        assert!(r.force.abs() < 1e-9 * 200e9 * 1e-4);
        let lin = member_response(
            Kinematics::Linear,
            &m,
            &a0,
            &b0,
            &v(0.0, 0.0, 0.0),
            &v(-1.0, 1.0, 0.0),
        );
        assert!((lin.force + 200e9 * 1e-4).abs() < 1e-3);
        m.behaviour = Behaviour::TensionOnly;
        let slack = member_response(
            Kinematics::Large,
            &m,
            &a0,
            &b0,
            &v(0.0, 0.0, 0.0),
            &v(-0.1, 0.0, 0.0),
        );
        assert_eq!(slack.force, 0.0);
        assert!(slack.strain < 0.0);
    }

    /// A modulus factor is the member of a material with the scaled modulus, to the bit (so
    /// fracture's factors reproduce its former copies of the material).
    #[test]
    fn a_modulus_factor_is_a_material_of_scaled_modulus() {
        let m = Material::new("m", 30e9, 2e-3);
        let (a0, b0) = (v(0.0, 0.0, 0.0), v(0.3, 0.1, -0.2));
        let (ua, ub) = (v(1e-4, -2e-4, 0.0), v(-3e-4, 5e-5, 2e-4));
        for kinematics in [Kinematics::Linear, Kinematics::Large] {
            for f in [0.0, 0.37, 1.0] {
                let mut scaled = m.clone();
                scaled.youngs_modulus *= f;
                let copy = member_response(kinematics, &scaled, &a0, &b0, &ua, &ub);
                let factor = scaled_member_response(kinematics, &m, f, &a0, &b0, &ua, &ub);
                assert_eq!(copy, factor, "{kinematics:?} {f}");
            }
        }
    }
}
