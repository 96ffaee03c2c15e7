//! Penalty forces: a node that has crossed a surface is pushed back along the surface normal in
//! proportion to its depth, and the penalty's stiffness goes into the Newton matrix.

use crate::linkage::{member_stiffnesses, Body};
use crate::Real;
use nalgebra::{Matrix3, Vector3};

/// The default penalty stiffness is this many times the mean axial stiffness `E A / L` of the
/// body's members (see [`default_penalty`]).
pub const PENALTY_FACTOR: Real = 100.0;

/// The default penalty stiffness of `body`, N/m: `PENALTY_FACTOR · mean(E A / L)` over its
/// members. A node pressed with force `F` then sinks `F / k` into the surface, about 1/100 of
/// how much the members next to it shorten under that force: small against the deformation,
/// while the penalty adds at most about a hundredfold to the diagonal (the direct solve does
/// not mind). For a pair of bodies, the smaller of their two penalties is used.
pub fn default_penalty(body: &Body) -> Real {
    if body.members.is_empty() {
        return 0.0;
    }
    let sum: Real = member_stiffnesses(body).iter().sum();
    PENALTY_FACTOR * sum / body.members.len() as Real
}

/// The penetration above which a step is warned about by default, m: 1% of the mean member
/// length of `body`.
pub fn penetration_tolerance(body: &Body) -> Real {
    if body.members.is_empty() {
        return 0.0;
    }
    let sum: Real = (0..body.members.len()).map(|m| body.member_length(m)).sum();
    0.01 * sum / body.members.len() as Real
}

/// A linear penalty spring along a contact normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Penalty {
    /// Stiffness, N/m of penetration.
    pub stiffness: Real,
}

impl Penalty {
    /// The force on a node `depth` (m) below a surface with outward unit `normal`:
    /// `f = k · depth · n`, N. A negative depth (the node has come out while its contact is
    /// held within one contact iteration) gives a pull, which the settle loop then removes.
    pub fn force(&self, depth: Real, normal: &Vector3<Real>) -> Vector3<Real> {
        normal * (self.stiffness * depth)
    }

    /// The stiffness of that force against the node's motion, `−∂f/∂x = k n nᵀ`, N/m: exact
    /// for a flat surface; for a curved one the term `k · depth · ∂n/∂x` is left out (it is of
    /// the order depth / radius of curvature, so Newton still converges, linearly at that rate).
    pub fn stiffness(&self, normal: &Vector3<Real>) -> Matrix3<Real> {
        normal * normal.transpose() * self.stiffness
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stiffness_is_the_derivative_of_the_force_along_the_normal() {
        let p = Penalty { stiffness: 2e6 };
        let n = Vector3::new(0.6, 0.8, 0.0);
        let dx = n * 1e-6;
        // Moving into the surface by dx raises the depth by |dx|.
        let df = p.force(1e-6, &n) - p.force(0.0, &n);
        assert!((df - p.stiffness(&n) * dx).norm() < 1e-12);
    }
}
