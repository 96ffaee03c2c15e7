//! The peak member stress of a step and its largest ratio to strength, for `summary.json`
//! and the batch table.

use crate::scene::{StepResult, World};
use crate::Real;

/// The member stress of largest magnitude in `step` (Pa, signed), and the largest |σ| over the
/// strength of its member's material in that sense (tensile for σ > 0, compressive for σ < 0),
/// over the members of `world` that have one.
pub(crate) fn peak_stress(
    step: &StepResult,
    world: Option<&World>,
) -> (Option<Real>, Option<Real>) {
    let mut peak: Option<Real> = None;
    let mut ratio: Option<Real> = None;
    for body in &step.bodies {
        let model = world.and_then(|w| w.bodies.iter().find(|b| b.name == body.name));
        for (m, &s) in body.stresses.iter().enumerate() {
            if peak.is_none_or(|p| s.abs() > p.abs()) {
                peak = Some(s);
            }
            let material = model.and_then(|b| {
                b.members
                    .get(m)
                    .and_then(|member| b.materials.get(member.material))
            });
            let strength = material.and_then(|mat| {
                if s >= 0.0 {
                    mat.tensile_strength
                } else {
                    mat.compressive_strength
                }
            });
            if let Some(limit) = strength.filter(|l| *l > 0.0) {
                let r = s.abs() / limit;
                if ratio.is_none_or(|q| r > q) {
                    ratio = Some(r);
                }
            }
        }
    }
    (peak, ratio)
}
