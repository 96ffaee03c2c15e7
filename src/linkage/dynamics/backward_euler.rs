//! Backward (implicit) Euler: first order, strongly damping.

use crate::linkage::dynamics::integrator::advanced;
use crate::linkage::dynamics::{InertiaTerm, Integrator, Motion, StepForm};
use crate::Real;

/// Backward Euler: `v_{n+1} = (u_{n+1} − u_n)/h`, `M (v_{n+1} − v_n)/h + C v_{n+1} +
/// f_int(u_{n+1}) = F(t_{n+1})`. A linear mode of circular frequency ω keeps the factor
/// `1/√(1 + ω²h²)` of its amplitude per step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BackwardEuler;

impl Integrator for BackwardEuler {
    fn name(&self) -> &'static str {
        "backward_euler"
    }

    fn form(&self, start: &Motion, mass: &[Real], h: Real) -> StepForm {
        let predictor_increment: Vec<Real> = start.v.iter().map(|v| h * v).collect();
        StepForm {
            blend: 1.0,
            inertia: InertiaTerm {
                mass: mass.to_vec(),
                coefficient: 1.0 / (h * h),
                predictor: advanced(start, &predictor_increment),
            },
            predictor_increment,
            velocity_coefficient: 1.0 / h,
            velocity_predictor: vec![0.0; start.u.len()],
            discrete_gradient: false,
        }
    }

    fn finish(&self, start: &Motion, du: Vec<Real>, h: Real) -> Motion {
        let v: Vec<Real> = du.iter().map(|d| d / h).collect();
        let a = v.iter().zip(&start.v).map(|(a, b)| (a - b) / h).collect();
        Motion {
            u: advanced(start, &du),
            v,
            a,
        }
    }
}
