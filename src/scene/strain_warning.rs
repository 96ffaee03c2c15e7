//! The warning of a linear body strained far past what the linear model holds for: a unit slip
//! (`youngs_modulus = 200`, meant 200e9 Pa) runs "ok" with displacements of kilometres.

use crate::linkage::{Body, Kinematics, StepState};
use crate::Real;

/// A linear body (`kinematics = "linear"`) whose member strain passes this in magnitude (5 %)
/// is warned about: small-displacement theory holds for strains of a few per mille, and no
/// structural material stays elastic at 5 %.
pub const LINEAR_STRAIN_WARNING: Real = 0.05;

/// The warning of `step` of a linear `body` whose largest member strain `|ε|` in `state`
/// passes [`LINEAR_STRAIN_WARNING`] (broken members and members of fallen pieces aside):
/// the member (1-based), its strain, the largest displacement, and what to change: the unit
/// of its material's `youngs_modulus` when that is below 1e6 Pa (below 1e3, E was probably
/// given in GPa: "200 Pa: did you mean 200e9?"; from 1e3, in MPa: "did you mean 70000e6?"),
/// else the loads' units, and `kinematics = "large"` when the strains are meant. `None` for
/// a large-displacement body or strains within the bound.
pub fn large_strain_warning(body: &Body, step: usize, state: &StepState) -> Option<String> {
    if body.kinematics != Kinematics::Linear {
        return None;
    }
    let gone: Vec<usize> = state.fracture.as_ref().map_or(Vec::new(), |f| {
        f.fallen
            .iter()
            .flat_map(|p| p.nodes.iter().copied())
            .collect()
    });
    let broken = |m: usize| {
        state
            .fracture
            .as_ref()
            .is_some_and(|f| f.broken.contains(&m))
            || body
                .members
                .get(m)
                .is_some_and(|member| member.nodes.iter().any(|n| gone.contains(n)))
    };
    let (member, strain) = state
        .strains
        .iter()
        .enumerate()
        .filter(|(m, e)| e.is_finite() && !broken(*m))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map(|(m, e)| (m, *e))?;
    if strain.abs() <= LINEAR_STRAIN_WARNING {
        return None;
    }
    let material = body
        .members
        .get(member)
        .and_then(|m| body.materials.get(m.material))?;
    let e = material.youngs_modulus;
    let largest = state
        .displacements
        .iter()
        .map(|u| u.norm())
        .fold(0.0, Real::max);
    let unit = if e < 1e3 {
        format!(
            "material '{}' has youngs_modulus = {e} Pa: did you mean {e}e9 (a modulus in GPa written as Pa)? ",
            material.name
        )
    } else if e < 1e6 {
        format!(
            "material '{}' has youngs_modulus = {e} Pa: did you mean {e}e6 (a modulus in MPa written as Pa)? ",
            material.name
        )
    } else {
        "check the units of the loads (N) and of the modulus (Pa); ".to_string()
    };
    Some(format!(
        "step {step}: body '{}': member {} is strained {:.3} % (largest displacement {largest:.4e} m): the linear model (kinematics = \"linear\") holds for small strains, and this is past {:.0} %: {unit}if the strains are meant, solve the body with kinematics = \"large\" (warned once per body)",
        body.name,
        member + 1,
        100.0 * strain,
        100.0 * LINEAR_STRAIN_WARNING,
    ))
}
