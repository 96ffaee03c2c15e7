//! The energy–momentum method (Simo & Tarnow 1992; Gonzalez 2000): the midpoint rule with the
//! member forces of the discrete gradient of their energy.

use crate::linkage::dynamics::{InertiaTerm, Integrator, Motion, StepForm};
use crate::Real;

/// Energy–momentum: `u_{n+1} = u_n + h/2 (v_n + v_{n+1})`,
/// `M (v_{n+1} − v_n) = h (F_{n+½} − f_algo)`, with `f_algo` per member the discrete gradient
/// `[V(l_{n+1}) − V(l_n)]/(l_{n+1} − l_n) · (d_n + d_{n+1})/(l_n + l_{n+1})`. Solved at the
/// midpoint `y = (u_n + u_{n+1})/2`: `f_algo + (4/h²) M (y − u_n − h v_n / 2) = F`. Conserves
/// energy, linear and angular momentum to the Newton tolerance; for linear members it is the
/// trapezoidal rule.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EnergyMomentum;

impl Integrator for EnergyMomentum {
    fn name(&self) -> &'static str {
        "energy_momentum"
    }

    fn form(&self, start: &Motion, mass: &[Real], h: Real) -> StepForm {
        StepForm {
            blend: 0.5,
            inertia: InertiaTerm {
                mass: mass.to_vec(),
                coefficient: 4.0 / (h * h),
                predictor: start
                    .u
                    .iter()
                    .zip(&start.v)
                    .map(|(u, v)| u + 0.5 * h * v)
                    .collect(),
            },
            velocity_coefficient: 2.0 / h,
            velocity_predictor: start.u.clone(),
            discrete_gradient: true,
        }
    }

    fn finish(&self, start: &Motion, u: Vec<Real>, h: Real) -> Motion {
        let v: Vec<Real> = u
            .iter()
            .zip(&start.u)
            .zip(&start.v)
            .map(|((u1, u0), v0)| 2.0 * (u1 - u0) / h - v0)
            .collect();
        let a = v.iter().zip(&start.v).map(|(a, b)| (a - b) / h).collect();
        Motion { u, v, a }
    }
}
