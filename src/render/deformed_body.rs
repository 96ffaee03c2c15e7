//! One body at one step as it is drawn: undeformed and magnified deformed node positions.

use crate::scene::{BodyResult, ModelBody};
use crate::Real;
use nalgebra::Vector3;

/// One body at one step as it is drawn: undeformed and (magnified) deformed node positions.
pub struct DeformedBody<'a> {
    /// The undeformed model.
    pub model: &'a ModelBody,
    /// The step's results.
    pub result: &'a BodyResult,
    /// Undeformed positions, m.
    pub undeformed: Vec<Vector3<Real>>,
    /// Drawn positions: undeformed + magnification × displacement, m.
    pub positions: Vec<Vector3<Real>>,
    /// Centre of the undeformed nodes, m (which side is "outside").
    pub centre: Vector3<Real>,
    /// Whether member j is overloaded.
    pub overloaded: Vec<bool>,
    /// Whether member j is broken (fracture): it is left out of the drawing.
    pub broken: Vec<bool>,
}

/// A 2- or 3-component list as a 3-vector (z = 0 in 2D).
pub fn vec3(p: &[Real]) -> Vector3<Real> {
    Vector3::new(
        p.first().copied().unwrap_or(0.0),
        p.get(1).copied().unwrap_or(0.0),
        p.get(2).copied().unwrap_or(0.0),
    )
}

impl<'a> DeformedBody<'a> {
    /// `model` at the step of `result`, displacements drawn `magnification` times larger.
    pub fn new(model: &'a ModelBody, result: &'a BodyResult, magnification: Real) -> Self {
        let undeformed: Vec<Vector3<Real>> = model.nodes.iter().map(|p| vec3(p)).collect();
        let positions = undeformed
            .iter()
            .zip(&result.displacements)
            .map(|(p, u)| p + vec3(u) * magnification)
            .collect();
        let centre = undeformed.iter().sum::<Vector3<Real>>() / undeformed.len().max(1) as Real;
        let mut overloaded = vec![false; model.members.len()];
        for &j in &result.overloaded {
            if let Some(o) = overloaded.get_mut(j.wrapping_sub(1)) {
                *o = true;
            }
        }
        let mut broken = vec![false; model.members.len()];
        for &j in result.fracture.iter().flat_map(|f| &f.broken) {
            if let Some(b) = broken.get_mut(j.wrapping_sub(1)) {
                *b = true;
            }
        }
        DeformedBody {
            model,
            result,
            undeformed,
            positions,
            centre,
            overloaded,
            broken,
        }
    }

    /// Drawn position of 1-based node `n`.
    pub fn at(&self, n: usize) -> Vector3<Real> {
        self.positions
            .get(n.wrapping_sub(1))
            .copied()
            .unwrap_or_default()
    }
}
