//! What stays fixed over the frames of a run: the box the camera fits, the magnification, the
//! arrow scales and the colour ranges.

use crate::render::contact_magnification::contact_magnification;
use crate::render::draw3d::{node_peak_stresses, node_stresses};
use crate::render::obstacles::{bodies_diagonal, place_obstacle, HALF_SPACE_BAND};
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
    /// Largest contact force at a node over the run, N.
    pub max_contact: Real,
    /// Arrow length per newton of every force, applied or contact (one scale, so equal forces
    /// draw equally long), m/N: the largest force gets 15% of `size`.
    pub force_scale: Real,
    /// Whether bodies touch obstacles or each other in this run (there are obstacles, several
    /// bodies or contact forces): the automatic magnification is then the largest round
    /// factor at which nothing is drawn through what it touches (1 for a body touching
    /// itself), see [`contact_magnification`].
    pub contact: bool,
    /// Whether some contact of the run has a tangential (friction) force: its arrows and
    /// legend are drawn.
    pub friction: bool,
    /// Largest |axial stress| of a member over the run, Pa.
    pub stress_limit: Real,
    /// Largest |mean stress of the members at a node| over the run (surface colours), Pa.
    pub node_stress_limit: Real,
    /// Largest |stress of the most stressed member at a node| over the run (surface colours
    /// by the largest member stress), Pa.
    pub node_peak_limit: Real,
    /// The last stored step.
    pub last_step: usize,
    /// The unit direction drawn upwards (the model's `up`, +y when it has none).
    pub up: Vector3<Real>,
    /// A dynamic run's GIF plays this many times slower than real time (1: real time), as
    /// [`crate::render::timed_delays`] chose: the frame titles state it. `None` (measured
    /// extents): no GIF timed by the run's times, nothing stated.
    pub gif_slowdown: Option<Real>,
    /// The magnification and colour ranges are shared by this many variants of a sweep
    /// ([`crate::render::SharedScale`]): the frames say so. `None`: the run's own.
    pub shared_by: Option<usize>,
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
        let mut node_peak_limit: Real = 0.0;
        let mut touching = !model.obstacles.is_empty() || model.bodies.len() > 1;
        for r in steps {
            for (b, m) in r.bodies.iter().zip(&model.bodies) {
                for u in &b.displacements {
                    max_displacement = max_displacement.max(vec3(u).norm());
                }
                for l in &b.loads {
                    max_force = max_force.max(vec3(&l.force).norm());
                }
                touching |= !b.contacts.is_empty();
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
                    for s in node_peak_stresses(m, &b.stresses) {
                        node_peak_limit = node_peak_limit.max(s.abs());
                    }
                }
            }
        }
        // A body touching itself (pieces of a broken body) could be drawn through itself.
        let self_contact = steps.iter().any(|r| {
            r.bodies
                .iter()
                .any(|b| b.contacts.iter().any(|c| c.with == b.name))
        });
        let magnification = magnification.unwrap_or_else(|| {
            let free = auto_magnification(max_displacement, size);
            match (touching, self_contact) {
                (false, _) => free,
                (true, true) => 1.0,
                (true, false) => contact_magnification(model, steps, free),
            }
        });
        let largest = max_force.max(max_contact);
        let force_scale = if largest > 0.0 {
            0.15 * size / largest
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
                    .chain(b.contacts.iter().map(|c| (c.node, &c.force, force_scale)))
                    .chain(
                        b.contacts
                            .iter()
                            .map(|c| (c.node, &c.tangential_force, force_scale)),
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
        include_obstacles(model, steps, &mut lo, &mut hi);
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
            max_contact,
            force_scale,
            contact: touching,
            friction,
            stress_limit,
            node_stress_limit,
            node_peak_limit,
            last_step,
            up: model.up.map_or_else(Vector3::y, |u| vec3(&u)),
            gif_slowdown: None,
            shared_by: None,
        }
    }
}

/// How far around the bodies (and their arrows) the camera takes in obstacles, in bounding
/// diagonals of the bodies: a block under a shell shows whole, a floor only near the bodies.
pub const OBSTACLE_MARGIN: Real = 0.25;

/// Grow the box `lo`–`hi` (the bodies and their arrows) by the parts of the obstacles of
/// `model`, at each of `steps`, that lie within [`OBSTACLE_MARGIN`] of it (2D: their cut by
/// z = 0 as drawn).
fn include_obstacles(
    model: &ModelFile,
    steps: &[StepResult],
    lo: &mut Vector3<Real>,
    hi: &mut Vector3<Real>,
) {
    if model.obstacles.is_empty() {
        return;
    }
    let is_3d = model.bodies.iter().any(|b| b.dimension == 3);
    let diagonal = bodies_diagonal(model);
    let unit = if diagonal > 0.0 { diagonal } else { 1.0 };
    let margin = Vector3::repeat(OBSTACLE_MARGIN * unit);
    let (near_lo, near_hi) = (*lo - margin, *hi + margin);
    let mut grow_lo = *lo;
    let mut grow_hi = *hi;
    let stored: Vec<usize> = if steps.is_empty() {
        vec![0]
    } else {
        steps.iter().map(|s| s.step).collect()
    };
    for o in &model.obstacles {
        for &k in &stored {
            let placed = place_obstacle(o, k, diagonal);
            let points: Vec<Vector3<Real>> = if is_3d {
                placed.vertices.clone()
            } else {
                placed
                    .cut(HALF_SPACE_BAND * unit)
                    .into_iter()
                    .flatten()
                    .collect()
            };
            let (mut a, mut b) = (
                Vector3::repeat(Real::INFINITY),
                Vector3::repeat(Real::NEG_INFINITY),
            );
            for p in &points {
                a = a.inf(p);
                b = b.sup(p);
            }
            // The obstacle's box clipped to the near box; nothing when they do not meet.
            let (a, b) = (a.sup(&near_lo), b.inf(&near_hi));
            if (0..3).all(|i| a[i] <= b[i]) {
                grow_lo = grow_lo.inf(&a);
                grow_hi = grow_hi.sup(&b);
            }
        }
    }
    *lo = grow_lo;
    *hi = grow_hi;
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
