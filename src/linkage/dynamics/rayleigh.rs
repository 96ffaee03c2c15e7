//! Rayleigh damping `C = α M + β K`: a drag on every node's mass and a dashpot beside every
//! member.

use crate::Real;

/// Rayleigh damping coefficients: the damping force is `α M v + β K v`, with `K v` taken
/// member by member along each member's current axis (`β (E A / L) l̇` per active member), so
/// that rigid motions of a large-displacement body are not damped; for linear kinematics this
/// is exactly `β K v`. A mode of circular frequency ω gets the damping ratio
/// `ζ = α/(2ω) + β ω/2`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RayleighDamping {
    /// α, 1/s: mass-proportional.
    pub mass: Real,
    /// β, s: stiffness-proportional.
    pub stiffness: Real,
}

impl RayleighDamping {
    /// Whether both coefficients are zero.
    pub fn is_none(&self) -> bool {
        self.mass == 0.0 && self.stiffness == 0.0
    }

    /// The damping ratio of a mode of circular frequency `omega` (rad/s): `α/(2ω) + βω/2`.
    pub fn ratio(&self, omega: Real) -> Real {
        self.mass / (2.0 * omega) + self.stiffness * omega / 2.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_damping_ratio_is_alpha_over_two_omega_plus_beta_omega_over_two() {
        let c = RayleighDamping {
            mass: 2.0,
            stiffness: 1e-3,
        };
        // 2/(2·10) + 1e-3·10/2 = 0.1 + 0.005.
        assert!((c.ratio(10.0) - 0.105).abs() < 1e-15);
        assert!(RayleighDamping::default().is_none() && !c.is_none());
    }
}
