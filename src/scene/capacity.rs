//! The load a breaking body carries against its peak: a body pulled by prescribed
//! displacements whose members break until it carries next to nothing has failed, although
//! every step of it is in equilibrium and reads "ok". This watch says so, with the peak load
//! and the capacity left.

use crate::linkage::{Body, StepState};
use crate::Real;
use nalgebra::Vector3;

/// A breaking body that carries less than this fraction of its peak load has failed.
pub const FAILED_FRACTION: Real = 0.5;

/// Per body, its peak carried load and whether its failure was told.
#[derive(Clone, Debug, Default)]
pub struct CapacityWatch {
    /// Per body: the largest carried load so far (N), its step, and whether it was told.
    peaks: Vec<(Real, usize, bool)>,
}

impl CapacityWatch {
    /// The warnings of `step` from the bodies' solved `states` (scene order): one, once per
    /// body, when a body with broken members first carries less than [`FAILED_FRACTION`] of
    /// its peak load (see [`carried_load`]). Step 0 starts the record over.
    pub fn warnings(&mut self, bodies: &[Body], step: usize, states: &[StepState]) -> Vec<String> {
        if step == 0 || self.peaks.len() != bodies.len() {
            self.peaks = vec![(0.0, 0, false); bodies.len()];
        }
        let mut warnings = Vec::new();
        for ((body, state), peak) in bodies.iter().zip(states).zip(&mut self.peaks) {
            let Some(fracture) = &state.fracture else {
                continue;
            };
            let Some(load) = carried_load(body, state) else {
                continue;
            };
            if load > peak.0 {
                *peak = (load, step, peak.2);
            }
            if peak.2 || fracture.broken.is_empty() || load >= FAILED_FRACTION * peak.0 {
                continue;
            }
            peak.2 = true;
            warnings.push(format!(
                "step {step}: body '{}' carries {:.1} % of its peak load ({:.4e} N against {:.4e} N at step {}) after {} of its {} members broke: it has failed",
                body.name,
                100.0 * load / peak.0,
                load,
                peak.0,
                peak.1,
                fracture.broken.len(),
                body.members.len()
            ));
        }
        warnings
    }
}

/// The load `body` carries in `state`: the norm of the summed reactions at the nodes whose
/// supports prescribe a displacement (what pulls or presses it), N; `None` when no support
/// moves (under loads alone the body carries what is applied until it collapses).
pub fn carried_load(body: &Body, state: &StepState) -> Option<Real> {
    let mut moving: Vec<usize> = body
        .supports
        .iter()
        .filter(|s| s.displacement != Vector3::zeros())
        .map(|s| s.node)
        .collect();
    if moving.is_empty() {
        return None;
    }
    moving.sort_unstable();
    moving.dedup();
    let sum: Vector3<Real> = state
        .reactions
        .iter()
        .filter(|(n, _)| moving.binary_search(n).is_ok())
        .map(|(_, r)| r)
        .sum();
    Some(sum.norm())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::fracture::FractureState;
    use crate::linkage::{Dimension, Material, Member, Support};

    /// A bar pulled at node 2 by a prescribed displacement: the carried load is the reaction
    /// there; the watch warns once when it falls below half the peak with a member broken.
    #[test]
    fn a_pulled_body_that_loses_its_load_is_told_once_with_its_peak() {
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("steel", 200e9, 1e-4));
        body.nodes = vec![Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
        body.members.push(Member {
            nodes: [0, 1],
            material: 0,
        });
        body.supports.push(Support::fixed(0, [true, true, false]));
        let mut pull = Support::fixed(1, [true, true, false]);
        pull.displacement = Vector3::new(1e-3, 0.0, 0.0);
        body.supports.push(pull);
        let state = |reaction: Real, broken: Vec<usize>| StepState {
            reactions: vec![
                (0, Vector3::new(-reaction, 0.0, 0.0)),
                (1, Vector3::new(reaction, 0.0, 0.0)),
            ],
            fracture: Some(FractureState {
                broken,
                ..Default::default()
            }),
            ..Default::default()
        };
        assert_eq!(carried_load(&body, &state(250.0, vec![])), Some(250.0));
        let bodies = [body];
        let mut watch = CapacityWatch::default();
        assert!(watch.warnings(&bodies, 0, &[state(0.0, vec![])]).is_empty());
        assert!(watch
            .warnings(&bodies, 1, &[state(1000.0, vec![])])
            .is_empty());
        // 60 % of the peak: not failed.
        assert!(watch
            .warnings(&bodies, 2, &[state(600.0, vec![0])])
            .is_empty());
        let w = watch.warnings(&bodies, 3, &[state(4.0, vec![0])]);
        assert_eq!(w.len(), 1);
        assert!(
            w[0].contains("carries 0.4 % of its peak load")
                && w[0].contains("at step 1")
                && w[0].contains("it has failed"),
            "{}",
            w[0]
        );
        assert!(watch
            .warnings(&bodies, 4, &[state(3.0, vec![0])])
            .is_empty());
    }
}
