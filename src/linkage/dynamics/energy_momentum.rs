//! The energy–momentum method (Simo & Tarnow 1992; Gonzalez 2000): the midpoint rule with the
//! member forces of the discrete gradient of their energy.

use crate::linkage::dynamics::integrator::advanced;
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
        let predictor_increment: Vec<Real> = start.v.iter().map(|v| 0.5 * h * v).collect();
        StepForm {
            blend: 0.5,
            inertia: InertiaTerm {
                mass: mass.to_vec(),
                coefficient: 4.0 / (h * h),
                predictor: advanced(start, &predictor_increment),
            },
            predictor_increment,
            velocity_coefficient: 2.0 / h,
            velocity_predictor: vec![0.0; start.u.len()],
            discrete_gradient: true,
        }
    }

    fn finish(&self, start: &Motion, du: Vec<Real>, h: Real) -> Motion {
        let v: Vec<Real> = du
            .iter()
            .zip(&start.v)
            .map(|(d, v0)| 2.0 * d / h - v0)
            .collect();
        let a = v.iter().zip(&start.v).map(|(a, b)| (a - b) / h).collect();
        Motion {
            u: advanced(start, &du),
            v,
            a,
        }
    }
}
