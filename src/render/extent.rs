//! What stays fixed over the frames of a run: the box the camera fits, the magnification, the
//! arrow scales and the colour ranges.

use crate::render::draw3d::node_stresses;
use crate::scene::{ModelFile, RunResults, StepResult};
use crate::Real;
use nalgebra::Vector3;

/// What stays fixed over all frames of a run, so the animation does not jump: the box the
/// camera fits, the displacement magnification, the force arrow scale and the colour range.
#[derive(Clone, Debug, PartialEq)]
pub struct RunExtent {
    /// Whether any body is 3D.
    pub is_3d: bool,
    /// Diagonal of the undeformed model's bounding box, m.
    pub size: Real,
    /// Largest node displacement over the run, m.
    pub max_displacement: Real,
    /// Displacements are drawn this many times larger than they are.
    pub magnification: Real,
    /// Corner of the box holding everything drawn at any step (magnified shape, arrows), m.
    pub min: Vector3<Real>,
    /// Opposite corner, m.
    pub max: Vector3<Real>,
    /// Largest applied force at a node over the run, N.
    pub max_force: Real,
    /// Arrow length per newton of applied force, m/N (the largest force gets 15% of `size`).
    pub force_scale: Real,
    /// Arrow length per newton of contact force, m/N.
    pub contact_scale: Real,
    /// Whether some contact of the run has a tangential (friction) force: its arrows and
    /// legend are drawn.
    pub friction: bool,
    /// Largest |axial stress| of a member over the run, Pa.
    pub stress_limit: Real,
    /// Largest |mean stress of the members at a node| over the run (surface colours), Pa.
    pub node_stress_limit: Real,
    /// The last stored step.
    pub last_step: usize,
}

fn vec3(p: &[Real]) -> Vector3<Real> {
    Vector3::new(
        p.first().copied().unwrap_or(0.0),
        p.get(1).copied().unwrap_or(0.0),
        p.get(2).copied().unwrap_or(0.0),
    )
}

/// A round magnification (1, 2 or 5 times a power of ten) that draws the largest
/// displacement at about a tenth of the model; 1 when displacements are already visible.
pub fn auto_magnification(max_displacement: Real, size: Real) -> Real {
    if !(max_displacement > 0.0 && size > 0.0) || max_displacement >= 0.02 * size {
        return 1.0;
    }
    let want = 0.1 * size / max_displacement;
    let decade = 10f64.powf(want.log10().floor());
    let m = [5.0, 2.0, 1.0]
        .iter()
        .map(|k| k * decade)
        .find(|&m| m <= want)
        .unwrap_or(decade);
    m.max(1.0)
}

/// Where the arrow for `force` at node `at` goes: away from the body when the force pulls
/// outwards (tail at the node), towards the node when it pushes in (tip at the node).
pub fn arrow_ends(
    at: Vector3<Real>,
    force: Vector3<Real>,
    scale: Real,
    centre: Vector3<Real>,
) -> (Vector3<Real>, Vector3<Real>) {
    let v = force * scale;
    if v.dot(&(at - centre)) >= 0.0 {
        (at, at + v)
    } else {
        (at - v, at)
    }
}

impl RunExtent {
    /// Measure all stored steps of `run` (`magnification`: `None` for the automatic one).
    pub fn of_run(run: &RunResults, magnification: Option<Real>) -> RunExtent {
        let last_step = run.steps.last().map_or(0, |s| s.step);
        Self::of_steps(&run.model, &run.steps, last_step, magnification)
    }

    /// Measure the stored steps `numbers` of a run of `model`; `read` gives a step's results
    /// (called once per step; [`RunExtent::of_run`] takes results already in memory).
    pub fn measure<E>(
        model: &ModelFile,
        numbers: &[usize],
        magnification: Option<Real>,
        read: impl FnMut(usize) -> Result<StepResult, E>,
    ) -> Result<RunExtent, E> {
        let steps = numbers
            .iter()
            .copied()
            .map(read)
            .collect::<Result<Vec<_>, E>>()?;
        let last_step = numbers.last().copied().unwrap_or(0);
        Ok(Self::of_steps(model, &steps, last_step, magnification))
    }

    /// Measure `steps` of a run of `model`, the last stored being `last_step`.
    fn of_steps(
        model: &ModelFile,
        steps: &[StepResult],
        last_step: usize,
        magnification: Option<Real>,
    ) -> RunExtent {
        let undeformed: Vec<Vec<Vector3<Real>>> = model
            .bodies
            .iter()
            .map(|b| b.nodes.iter().map(|p| vec3(p)).collect())
            .collect();
        let mut lo = Vector3::repeat(Real::INFINITY);
        let mut hi = Vector3::repeat(Real::NEG_INFINITY);
        for p in undeformed.iter().flatten() {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        if !lo.x.is_finite() {
            lo = Vector3::zeros();
            hi = Vector3::zeros();
        }
        let size = (hi - lo).norm().max(1e-12);
        let centres: Vec<Vector3<Real>> = undeformed
            .iter()
            .map(|nodes| nodes.iter().sum::<Vector3<Real>>() / nodes.len().max(1) as Real)
            .collect();
        let mut max_displacement: Real = 0.0;
        let mut max_force: Real = 0.0;
        let mut max_contact: Real = 0.0;
        let mut friction = false;
        let mut stress_limit: Real = 0.0;
        let mut node_stress_limit: Real = 0.0;
        for r in steps {
            for (b, m) in r.bodies.iter().zip(&model.bodies) {
                for u in &b.displacements {
                    max_displacement = max_displacement.max(vec3(u).norm());
                }
                for l in &b.loads {
                    max_force = max_force.max(vec3(&l.force).norm());
                }
                for c in &b.contacts {
                    max_contact = max_contact.max(vec3(&c.force).norm());
                    friction |= c.tangential_force.iter().any(|t| *t != 0.0);
                }
                for s in &b.stresses {
                    stress_limit = stress_limit.max(s.abs());
                }
                if m.dimension == 3 && !m.patches.is_empty() {
                    for s in node_stresses(m, &b.stresses) {
                        node_stress_limit = node_stress_limit.max(s.abs());
                    }
                }
            }
        }
        let magnification =
            magnification.unwrap_or_else(|| auto_magnification(max_displacement, size));
        let force_scale = if max_force > 0.0 {
            0.15 * size / max_force
        } else {
            0.0
        };
        let contact_scale = if max_contact > 0.0 {
            0.08 * size / max_contact
        } else {
            0.0
        };
        for r in steps {
            for (i, b) in r.bodies.iter().enumerate() {
                let (Some(nodes), Some(centre)) = (undeformed.get(i), centres.get(i)) else {
                    continue;
                };
                let at = |n: usize| {
                    let u = b.displacements.get(n).map(|u| vec3(u)).unwrap_or_default();
                    nodes.get(n).copied().unwrap_or_default() + u * magnification
                };
                for n in 0..nodes.len() {
                    let p = at(n);
                    lo = lo.inf(&p);
                    hi = hi.sup(&p);
                }
                let forces = b
                    .loads
                    .iter()
                    .map(|l| (l.node, &l.force, force_scale))
                    .chain(b.contacts.iter().map(|c| (c.node, &c.force, contact_scale)))
                    .chain(
                        b.contacts
                            .iter()
                            .map(|c| (c.node, &c.tangential_force, contact_scale)),
                    );
                for (node, f, scale) in forces {
                    let (t, h) = arrow_ends(at(node.saturating_sub(1)), vec3(f), scale, *centre);
                    for p in [t, h] {
                        lo = lo.inf(&p);
                        hi = hi.sup(&p);
                    }
                }
            }
        }
        // Room for support marks around the shape.
        let pad = Vector3::repeat(0.02 * size);
        RunExtent {
            is_3d: model.bodies.iter().any(|b| b.dimension == 3),
            size,
            max_displacement,
            magnification,
            min: lo - pad,
            max: hi + pad,
            max_force,
            force_scale,
            contact_scale,
            friction,
            stress_limit,
            node_stress_limit,
            last_step,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn magnification_is_round_and_only_for_tiny_displacements() {
        assert_eq!(auto_magnification(0.1, 1.0), 1.0);
        assert_eq!(auto_magnification(0.0, 1.0), 1.0);
        assert_eq!(auto_magnification(1e-4, 1.0), 1000.0);
        assert_eq!(auto_magnification(3e-4, 1.0), 200.0);
    }
}
