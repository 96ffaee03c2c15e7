//! Scattered member strengths: a Weibull law drawn from a seeded, portable generator.

use crate::linkage::fracture::MemberLimits;
use crate::linkage::{Body, Failure};
use crate::Real;
use rand_chacha::rand_core::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `count` factors drawn from the Weibull law of unit scale and modulus (shape) `modulus`,
/// `F(x) = 1 − exp(−x^m)`, by its inverse: `x = (−ln(1 − U))^(1/m)` with U uniform in [0, 1)
/// from 53 bits of ChaCha8 seeded by `seed` (rand_core's portable `seed_from_u64`). The same
/// seed gives the same factors on every machine and thread count: the draws are sequential.
pub fn weibull_factors(count: usize, modulus: Real, seed: u64) -> Vec<Real> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let u = (rng.next_u64() >> 11) as Real / (1u64 << 53) as Real;
            (-(1.0 - u).ln()).powf(1.0 / modulus)
        })
        .collect()
}

/// Each member's tensile and compressive strength (Pa, infinite for none) when its material
/// breaks: the material's, times a Weibull factor per member when it has `scatter` (one
/// generator per material, drawing for its members in member order).
pub fn member_limits(body: &Body) -> MemberLimits {
    let mut factors: Vec<Option<std::vec::IntoIter<Real>>> = body
        .materials
        .iter()
        .enumerate()
        .map(|(i, mat)| {
            let scatter = mat.scatter.filter(|_| mat.failure == Failure::Break)?;
            let count = body.members.iter().filter(|m| m.material == i).count();
            Some(weibull_factors(count, scatter.weibull_modulus, scatter.seed).into_iter())
        })
        .collect();
    body.members
        .iter()
        .map(|m| {
            let mat = &body.materials[m.material];
            if mat.failure != Failure::Break {
                return None;
            }
            let f = factors[m.material]
                .as_mut()
                .and_then(|it| it.next())
                .unwrap_or(1.0);
            Some((
                mat.tensile_strength.map_or(Real::INFINITY, |s| s * f),
                mat.compressive_strength.map_or(Real::INFINITY, |s| s * f),
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_of_many_draws_is_the_weibull_mean() {
        // Modulus 2: mean Γ(1 + 1/2) = √π / 2 = 0.886227, standard deviation
        // √(1 − π/4) = 0.4633; 200,000 draws: standard error 0.001, tolerance 5 of them.
        let x = weibull_factors(200_000, 2.0, 7);
        let mean = x.iter().sum::<Real>() / x.len() as Real;
        assert!(
            (mean - std::f64::consts::PI.sqrt() / 2.0).abs() < 0.005,
            "{mean}"
        );
        // The median is (ln 2)^(1/m).
        let mut sorted = x.clone();
        sorted.sort_by(|a, b| a.total_cmp(b));
        assert!((sorted[100_000] - 2f64.ln().sqrt()).abs() < 0.005);
    }

    #[test]
    fn the_same_seed_draws_the_same_numbers() {
        assert_eq!(weibull_factors(5, 12.0, 7), weibull_factors(5, 12.0, 7));
        assert_ne!(weibull_factors(5, 12.0, 7), weibull_factors(5, 12.0, 8));
    }
}
