//! The stiffness of one member (paper Eq. 1–2): `AE/L` and its block in global axes.

use crate::linkage::{Body, Dimension, Material};
use crate::Real;
use nalgebra::{DMatrix, Matrix3, Vector3};

/// Axial stiffness of a member, N/m: `k = A E / L` (paper Eq. 1 read as `F = k D`).
pub fn axial_stiffness(material: &Material, length: Real) -> Real {
    material.area * material.youngs_modulus / length
}

/// The axial stiffness `A E / L` of every member of `body`, in member order, N/m (`E` its
/// material's times its factor, [`Body::member_modulus`]).
pub fn member_stiffnesses(body: &Body) -> Vec<Real> {
    (0..body.members.len())
        .map(|m| member_axial_stiffness(body, m))
        .collect()
}

/// The axial stiffness `A E / L` of member `m` of `body`, N/m (`E` its material's times its
/// factor, [`Body::member_modulus`]).
pub fn member_axial_stiffness(body: &Body, m: usize) -> Real {
    body.materials[body.members[m].material].area * body.member_modulus(m) / body.member_length(m)
}

/// The linear stiffness block `(A E / L) n nᵀ` of member `m` of `body` at rest, N/m (paper
/// Eq. 1–2; see [`member_block`]).
pub fn linear_member_block(body: &Body, m: usize) -> Matrix3<Real> {
    let [a, b] = body.members[m].nodes;
    member_block(
        &body.nodes[a],
        &body.nodes[b],
        member_axial_stiffness(body, m),
    )
}

/// The 3×3 block `k n nᵀ` of a member from `a` to `b` (n the unit axis): the member matrix of
/// Eq. 2 is `[B −B; −B B]` in these blocks (in 2D its upper-left 2×2 holds `cos²φ`,
/// `sinφ cosφ`, `sin²φ` times `k`).
pub fn member_block(a: &Vector3<Real>, b: &Vector3<Real>, k: Real) -> Matrix3<Real> {
    let d = b - a;
    let n = d / d.norm();
    n * n.transpose() * k
}

/// The full element stiffness matrix of paper Eq. 2 (with the `AE/L` factor the printed
/// matrix leaves implicit), generalised to 3D: 4×4 in 2D (`U1 V1 U2 V2`), 6×6 in 3D.
pub fn member_stiffness_matrix(
    dimension: Dimension,
    a: &Vector3<Real>,
    b: &Vector3<Real>,
    k: Real,
) -> DMatrix<Real> {
    let d = dimension.dofs_per_node();
    let block = member_block(a, b, k);
    DMatrix::from_fn(2 * d, 2 * d, |r, c| {
        let sign = if (r < d) == (c < d) { 1.0 } else { -1.0 };
        sign * block[(r % d, c % d)]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_eq2_in_2d() {
        // A member at φ = 30°: A = cos²φ, B = sinφ cosφ, C = sin²φ, times AE/L.
        let phi: Real = 30f64.to_radians();
        let l = 2.0;
        let a = Vector3::zeros();
        let b = Vector3::new(l * phi.cos(), l * phi.sin(), 0.0);
        let mat = Material::new("m", 200e9, 1e-4);
        let k = axial_stiffness(&mat, l);
        assert_eq!(k, 1e-4 * 200e9 / 2.0);
        let m = member_stiffness_matrix(Dimension::Two, &a, &b, k);
        let (ca, cb, cc) = (phi.cos().powi(2), phi.sin() * phi.cos(), phi.sin().powi(2));
        let expect = [
            [ca, cb, -ca, -cb],
            [cb, cc, -cb, -cc],
            [-ca, -cb, ca, cb],
            [-cb, -cc, cb, cc],
        ];
        for r in 0..4 {
            for c in 0..4 {
                assert!(
                    (m[(r, c)] - k * expect[r][c]).abs() <= 1e-9 * k,
                    "({r},{c})"
                );
            }
        }
    }

    #[test]
    fn rigid_motions_cause_no_force_and_3d_is_symmetric() {
        let a = Vector3::new(0.1, -0.2, 0.3);
        let b = Vector3::new(1.0, 0.5, -0.7);
        let m = member_stiffness_matrix(Dimension::Three, &a, &b, 3.0);
        assert!((m.clone() - m.transpose()).abs().max() < 1e-15);
        // A translation of both ends gives no end forces.
        let t = nalgebra::DVector::from_vec(vec![1.0, 2.0, 3.0, 1.0, 2.0, 3.0]);
        assert!((&m * t).abs().max() < 1e-12);
        // Stretching along the axis by δ gives end forces ±kδ along the axis.
        let n = (b - a).normalize();
        let mut u = nalgebra::DVector::zeros(6);
        u.rows_mut(3, 3).copy_from(&(n * 0.01));
        let f = &m * u;
        assert!((f.rows(3, 3) - n * 0.03).norm() < 1e-14);
        assert!((f.rows(0, 3) + n * 0.03).norm() < 1e-14);
    }
}
