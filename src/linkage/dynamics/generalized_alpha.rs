//! The generalized-α method of Chung & Hulbert (1993), from the spectral radius ρ∞.

use crate::linkage::dynamics::integrator::{alpha_form, newmark_finish};
use crate::linkage::dynamics::{Integrator, Motion, StepForm};
use crate::Real;

/// Generalized-α: `M a_{n+1−α_m} + C v_{n+1−α_f} + f_int(u_{n+1−α_f}) = F(t_{n+1−α_f})` with
/// the Newmark relations, `x_{n+1−α} = (1 − α) x_{n+1} + α x_n` and, from ρ∞ ∈ [0, 1],
/// `α_f = ρ∞/(1 + ρ∞)`, `α_m = (2ρ∞ − 1)/(1 + ρ∞)`, `γ = ½ − α_m + α_f`,
/// `β = ¼(1 − α_m + α_f)²` (= `1/(1+ρ∞)²`). Second order; a mode with ωh → ∞ loses the
/// factor ρ∞ of its amplitude per step. OpenSees's `GeneralizedAlpha alphaM alphaF` uses the
/// complementary convention (its α are `1 − α` here).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralizedAlpha {
    /// ρ∞, the spectral radius at infinite frequency, in [0, 1] (default 0.8).
    pub rho_inf: Real,
}

impl GeneralizedAlpha {
    /// `(α_m, α_f)` of ρ∞.
    pub fn alphas(&self) -> (Real, Real) {
        let r = self.rho_inf;
        ((2.0 * r - 1.0) / (1.0 + r), r / (1.0 + r))
    }

    /// `(β, γ)` of ρ∞.
    pub fn newmark_parameters(&self) -> (Real, Real) {
        let (am, af) = self.alphas();
        let gamma = 0.5 - am + af;
        (0.25 * (1.0 - am + af).powi(2), gamma)
    }
}

impl Integrator for GeneralizedAlpha {
    fn name(&self) -> &'static str {
        "generalized_alpha"
    }

    fn form(&self, start: &Motion, mass: &[Real], h: Real) -> StepForm {
        alpha_form(start, mass, h, self.newmark_parameters(), self.alphas())
    }

    fn finish(&self, start: &Motion, du: Vec<Real>, h: Real) -> Motion {
        let (beta, gamma) = self.newmark_parameters();
        newmark_finish(start, du, h, beta, gamma)
    }

    fn needs_initial_acceleration(&self) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_inf_gives_the_chung_hulbert_parameters() {
        // ρ∞ = 0.8: α_f = 0.8/1.8, α_m = 0.6/1.8, γ = ½ + 0.2/1.8, β = 1/1.8².
        let g = GeneralizedAlpha { rho_inf: 0.8 };
        let (am, af) = g.alphas();
        assert!((af - 0.8 / 1.8).abs() < 1e-15 && (am - 0.6 / 1.8).abs() < 1e-15);
        let (beta, gamma) = g.newmark_parameters();
        assert!((beta - 1.0 / 3.24).abs() < 1e-15 && (gamma - (0.5 + 0.2 / 1.8)).abs() < 1e-15);
    }
}
