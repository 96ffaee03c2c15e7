//! The saw-tooth softening of a member (sequentially linear analysis, Rots & Invernizzi 2004):
//! instead of breaking at its strength, a member passes through `n` teeth; at each its
//! stiffness and its strength drop, and past the last it breaks.
//!
//! Tooth `i` (0-based, `i < n`) has the tensile strength `σᵢ = f_t (1 − i/n)` and reaches it at
//! the strain `εᵢ = ε₀ + i h` (`ε₀ = f_t/E`): its Young's modulus is `Eᵢ = σᵢ/εᵢ`. The peaks lie
//! on a straight softening line from `(ε₀, f_t)` to `(ε₀ + n h, 0)`. A member pulled through
//! its teeth by a growing elongation dissipates, per unit volume, the energy its stiffness
//! drops release, `D(h) = Σᵢ ½ (Eᵢ − Eᵢ₊₁) εᵢ²` (`Eₙ = 0`), the area under its saw-tooth
//! stress–strain path. `h` is chosen per member so that `D(h) A L = G_f A`: every member
//! dissipates the fracture energy `G_f` (J/m²) over its cross-section, whatever its length
//! (the crack band regularisation of Bažant & Oh, one member being the band). Matching the
//! dissipation rather than the area under the line (Rots' choice) keeps `G_f` exact for any
//! `n`: a saw-tooth lies under its line and dissipates about half of the line's area.
//!
//! One tooth is the brittle member: it breaks at `f_t` having dissipated its elastic energy
//! `f_t² A L/(2E)`, whatever `G_f`.

use crate::Real;

/// One tooth of a member's saw-tooth: its Young's modulus as a fraction of the material's, and
/// its tensile strength, Pa.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tooth {
    /// `Eᵢ / E`, in (0, 1]; 1 for the first tooth.
    pub stiffness_factor: Real,
    /// `σᵢ`, Pa.
    pub tensile_strength: Real,
}

/// `D(h)` of the module documentation, J/m³, for `teeth` teeth of strength `f_t` (Pa) and
/// Young's modulus `E` (Pa) with strain spacing `h`.
pub fn saw_tooth_dissipation(youngs_modulus: Real, tensile: Real, teeth: usize, h: Real) -> Real {
    let e0 = tensile / youngs_modulus;
    let n = teeth as Real;
    let modulus = |i: usize| {
        if i >= teeth {
            0.0
        } else {
            tensile * (1.0 - i as Real / n) / (e0 + i as Real * h)
        }
    };
    (0..teeth)
        .map(|i| {
            let e = e0 + i as Real * h;
            0.5 * (modulus(i) - modulus(i + 1)) * e * e
        })
        .sum()
}

/// The teeth of a member of undeformed length `length` (m), Young's modulus `E` (Pa) and
/// tensile strength `f_t` (Pa) that dissipates `fracture_energy` (J/m²) over its section in
/// `teeth` teeth. `Err(least)` when `G_f` is below the least a member of `teeth ≥ 2` can
/// dissipate, its elastic energy at the strength per unit area, `f_t² L/(2E)` (J/m², returned).
pub fn saw_tooth(
    youngs_modulus: Real,
    tensile: Real,
    length: Real,
    fracture_energy: Real,
    teeth: usize,
) -> Result<Vec<Tooth>, Real> {
    let e0 = tensile / youngs_modulus;
    let brittle = 0.5 * tensile * e0;
    let target = fracture_energy / length;
    if teeth <= 1 {
        return Ok(vec![Tooth {
            stiffness_factor: 1.0,
            tensile_strength: tensile,
        }]);
    }
    // (NaN fails the comparison too.)
    if target.partial_cmp(&brittle) != Some(std::cmp::Ordering::Greater) {
        return Err(brittle * length);
    }
    let d = |h: Real| saw_tooth_dissipation(youngs_modulus, tensile, teeth, h);
    // D grows from the brittle energy at h = 0 without bound; bracket, then bisect to the
    // last bit.
    let (mut lo, mut hi) = (0.0, e0);
    while d(hi) < target {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if d(mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let h = 0.5 * (lo + hi);
    let n = teeth as Real;
    Ok((0..teeth)
        .map(|i| {
            let strength = tensile * (1.0 - i as Real / n);
            let strain = e0 + i as Real * h;
            Tooth {
                stiffness_factor: if i == 0 {
                    1.0
                } else {
                    strength / strain / youngs_modulus
                },
                tensile_strength: strength,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_teeth_dissipate_the_fracture_energy() {
        // E = 30 GPa, f_t = 3 MPa, L = 0.1 m, G_f = 100 J/m²: G_f / L = 1000 J/m³, the
        // brittle energy f_t²/(2E) = 150 J/m³.
        let (e, f, l, g) = (30e9, 3e6, 0.1, 100.0);
        for n in [2, 5, 20] {
            let teeth = saw_tooth(e, f, l, g, n).unwrap();
            assert_eq!(teeth.len(), n);
            // Energy released at each drop, ½ (Eᵢ − Eᵢ₊₁) εᵢ², εᵢ = σᵢ / Eᵢ, summed by hand.
            let mut sum = 0.0;
            for i in 0..n {
                let ei = e * teeth[i].stiffness_factor;
                let next = teeth.get(i + 1).map_or(0.0, |t| e * t.stiffness_factor);
                let strain = teeth[i].tensile_strength / ei;
                sum += 0.5 * (ei - next) * strain * strain;
                // Strengths fall by f_t / n a tooth, stiffness falls.
                let expected = f * (1.0 - i as Real / n as Real);
                assert!((teeth[i].tensile_strength - expected).abs() < 1e-9 * f);
                assert!(next < ei);
            }
            assert!((sum * l - g).abs() < 1e-9 * g, "{n}: {}", sum * l);
        }
    }

    #[test]
    fn one_tooth_is_brittle_and_too_little_energy_is_refused() {
        let t = saw_tooth(30e9, 3e6, 0.1, 1.0, 1).unwrap();
        assert_eq!(
            t,
            vec![Tooth {
                stiffness_factor: 1.0,
                tensile_strength: 3e6
            }]
        );
        // Brittle energy per area: 150 J/m³ × 0.1 m = 15 J/m².
        assert!((saw_tooth(30e9, 3e6, 0.1, 14.0, 3).unwrap_err() - 15.0).abs() < 1e-9);
    }
}
