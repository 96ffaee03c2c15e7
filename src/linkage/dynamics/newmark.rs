//! Newmark's method (β, γ), as OpenSees has it (`integrator('Newmark', γ, β)`).

use crate::linkage::dynamics::integrator::{alpha_form, newmark_finish};
use crate::linkage::dynamics::{Integrator, Motion, StepForm};
use crate::Real;

/// Newmark: `u_{n+1} = u_n + h v_n + h²((½ − β) a_n + β a_{n+1})`,
/// `v_{n+1} = v_n + h((1 − γ) a_n + γ a_{n+1})`, equilibrium at `t_{n+1}`. β = ¼, γ = ½ is the
/// trapezoidal rule (average acceleration): unconditionally stable, no numerical damping.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Newmark {
    /// β (default ¼).
    pub beta: Real,
    /// γ ≥ ½ (default ½).
    pub gamma: Real,
}

impl Default for Newmark {
    fn default() -> Self {
        Newmark {
            beta: 0.25,
            gamma: 0.5,
        }
    }
}

impl Integrator for Newmark {
    fn name(&self) -> &'static str {
        "newmark"
    }

    fn form(&self, start: &Motion, mass: &[Real], h: Real) -> StepForm {
        alpha_form(start, mass, h, (self.beta, self.gamma), (0.0, 0.0))
    }

    fn finish(&self, start: &Motion, du: Vec<Real>, h: Real) -> Motion {
        newmark_finish(start, du, h, self.beta, self.gamma)
    }

    fn needs_initial_acceleration(&self) -> bool {
        true
    }
}
