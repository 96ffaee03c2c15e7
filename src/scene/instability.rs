//! Warnings of instabilities under load control: a step whose solved tangent has negative
//! pivots (the body is past a limit point or buckles), a step whose Newton iterations met
//! negative pivots on the way to a stable solution (a limit point passed within the step), or
//! whose displacements jump by far more
//! than the step before them although what drives them did not (a snap-through to a distant
//! equilibrium). Load control cannot follow such a path; the arc-length method can. Bodies on
//! an arc-length path are not watched: passing limit points is what it is for.

use crate::linkage::{Body, PathMethod, StepState};
use crate::scene::results::PairForce;
use crate::Real;
use nalgebra::Vector3;

/// A step's largest nodal displacement change must exceed this many times the step before's
/// (times the change of what drives the body, when that grew) to be a jump.
pub const JUMP_RATIO: Real = 10.0;

/// ...and this fraction of the body's size (its bounding diagonal): smaller changes are not
/// worth a warning, however their ratio reads.
pub const JUMP_FLOOR: Real = 1e-3;

/// What one step changed in a body, compared between consecutive steps.
#[derive(Clone, Copy, Debug, Default)]
struct Increment {
    /// Largest change of a node's displacement, m.
    displacement: Real,
    /// Norm of the change of the applied loads, N.
    loads: Real,
    /// Largest change of a supported node's displacement (prescribed motions), m.
    supports: Real,
    /// Norm of the change of the body's contact forces (per pair totals), N.
    contact: Real,
}

/// What the watch keeps of a body's last step.
#[derive(Clone, Debug, Default)]
struct Kept {
    /// Displacement per node, m.
    displacements: Vec<Vector3<Real>>,
    /// Applied load per node, N.
    loads: Vec<Vector3<Real>>,
    /// Contact force totals per pair, N.
    contact: Vec<Real>,
    /// Negative pivots of its solved tangent.
    negative_pivots: usize,
    /// The change that step made (none for the first step watched).
    increment: Option<Increment>,
}

/// What [`InstabilityWatch::warnings`] remembers of the previous step, per body.
#[derive(Clone, Debug, Default)]
pub struct InstabilityWatch {
    /// The step last watched.
    step: Option<usize>,
    /// Per body, in scene order.
    kept: Vec<Kept>,
}

impl InstabilityWatch {
    /// The warnings of `step` from the bodies' solved `states` (in scene order) and the step's
    /// contact force totals; remembers the step for the next call. A step that does not follow
    /// the last one watched (step 0, a restart) only starts the record.
    pub fn warnings(
        &mut self,
        bodies: &[Body],
        step: usize,
        states: &[StepState],
        contact_forces: &[PairForce],
    ) -> Vec<String> {
        let follows = step > 0 && self.step == Some(step - 1) && self.kept.len() == bodies.len();
        if !follows {
            self.kept = vec![Kept::default(); bodies.len()];
        }
        self.step = Some(step);
        let mut warnings = Vec::new();
        for ((body, state), kept) in bodies.iter().zip(states).zip(&mut self.kept) {
            let loads = nodal_loads(body, state);
            let contact: Vec<Real> = contact_forces
                .iter()
                .filter(|p| p.body == body.name)
                .flat_map(|p| p.force.iter().copied())
                .collect();
            let increment = follows.then(|| Increment {
                displacement: largest_change(&state.displacements, &kept.displacements, None),
                loads: change_norm(&loads, &kept.loads),
                supports: largest_change(
                    &state.displacements,
                    &kept.displacements,
                    Some(&supported_nodes(body)),
                ),
                contact: contact
                    .iter()
                    .zip(kept.contact.iter().chain(std::iter::repeat(&0.0)))
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<Real>()
                    .sqrt(),
            });
            if body.newton.path == PathMethod::Schedules && body.is_nonlinear() && step > 0 {
                if state.negative_pivots > 0 {
                    warnings.push(negative_pivots_warning(body, step, state.negative_pivots));
                }
                let jumped = match (increment, kept.increment) {
                    (Some(now), Some(before)) if is_jump(&now, &before, body.size()) => {
                        warnings.push(jump_warning(body, step, &now, &before));
                        true
                    }
                    _ => false,
                };
                // A stable end reached through an unstable region from a stable start (an
                // unstable start was told at its own step), which the jump did not already tell.
                if state.negative_pivots == 0
                    && state.negative_pivots_met > 0
                    && follows
                    && kept.negative_pivots == 0
                    && !jumped
                {
                    warnings.push(limit_passed_warning(body, step, state.negative_pivots_met));
                }
            }
            *kept = Kept {
                displacements: state.displacements.clone(),
                loads,
                contact,
                negative_pivots: state.negative_pivots,
                increment,
            };
        }
        warnings
    }
}

/// Whether `now` is a jump after `before`: its largest displacement change is above
/// [`JUMP_FLOOR`] of the body's `size` and more than [`JUMP_RATIO`] times the previous one
/// scaled by how much more the loads, prescribed motions or contact forces changed (so a
/// schedule that jumps, a support that starts moving or a contact that starts pressing is
/// not a jump of the body's own).
fn is_jump(now: &Increment, before: &Increment, size: Real) -> bool {
    now.displacement > JUMP_FLOOR * size
        && now.displacement > JUMP_RATIO * driven(now, before) * before.displacement
}

/// How many times more the body's drive changed in `now` than in `before`: the largest ratio
/// of the load, prescribed-motion and contact-force changes, at least 1.
fn driven(now: &Increment, before: &Increment) -> Real {
    let growth = |a: Real, b: Real| {
        if a <= 0.0 {
            0.0
        } else if b <= 0.0 {
            Real::INFINITY
        } else {
            a / b
        }
    };
    growth(now.loads, before.loads)
        .max(growth(now.supports, before.supports))
        .max(growth(now.contact, before.contact))
        .max(1.0)
}

fn negative_pivots_warning(body: &Body, step: usize, count: usize) -> String {
    format!(
        "step {step}: body '{}': the tangent stiffness at the solved state has {count} negative pivot{}: the body is past a limit point or buckles, an unstable equilibrium that load control cannot follow (it may jump to a distant state or fail); trace the path with [bodies.path] method = \"arc_length\"",
        body.name,
        if count == 1 { "" } else { "s" }
    )
}

fn limit_passed_warning(body: &Body, step: usize, count: usize) -> String {
    format!(
        "step {step}: body '{}': a limit point was passed within the step: the solved states before and after it are stable, but the tangent stiffness between them (at the Newton iterates, or sampled on the way from one state to the other) has {count} negative pivot{}: an unstable region lies between them: the body probably snapped through to a distant equilibrium that load control cannot follow; trace the path with [bodies.path] method = \"arc_length\"",
        body.name,
        if count == 1 { "" } else { "s" }
    )
}

fn jump_warning(body: &Body, step: usize, now: &Increment, before: &Increment) -> String {
    format!(
        "step {step}: body '{}': the displacements jumped: the largest nodal change is {:.3e} m, {:.0} times the {:.3e} m of step {} under {}: the body probably snapped through past a limit point, and the steps around it are not a path it can follow; trace it with [bodies.path] method = \"arc_length\"",
        body.name,
        now.displacement,
        now.displacement / before.displacement.max(Real::MIN_POSITIVE),
        before.displacement,
        step - 1,
        match driven(now, before) {
            d if d <= 1.0 + 1e-6 => "a like change of the loads".to_string(),
            d => format!("a change of the loads, prescribed motions or contact forces only {d:.3} times that step's"),
        }
    )
}

/// Applied load per node, N.
fn nodal_loads(body: &Body, state: &StepState) -> Vec<Vector3<Real>> {
    let mut loads = vec![Vector3::zeros(); body.nodes.len()];
    for (node, f) in &state.loads {
        if let Some(l) = loads.get_mut(*node) {
            *l += f;
        }
    }
    loads
}

/// The nodes a support holds.
fn supported_nodes(body: &Body) -> Vec<usize> {
    let mut nodes: Vec<usize> = body.supports.iter().map(|s| s.node).collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// Largest `|a − b|` over the nodes (`only` these when given); `b` missing counts as zero.
fn largest_change(a: &[Vector3<Real>], b: &[Vector3<Real>], only: Option<&[usize]>) -> Real {
    let change = |n: usize| {
        let before = b.get(n).copied().unwrap_or_else(Vector3::zeros);
        a.get(n).map_or(0.0, |x| (x - before).norm())
    };
    match only {
        Some(nodes) => nodes.iter().map(|&n| change(n)).fold(0.0, Real::max),
        None => (0..a.len()).map(change).fold(0.0, Real::max),
    }
}

/// `‖a − b‖` over all nodes; `b` missing counts as zero.
fn change_norm(a: &[Vector3<Real>], b: &[Vector3<Real>]) -> Real {
    a.iter()
        .enumerate()
        .map(|(n, x)| (x - b.get(n).copied().unwrap_or_else(Vector3::zeros)).norm_squared())
        .sum::<Real>()
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn inc(displacement: Real, loads: Real) -> Increment {
        Increment {
            displacement,
            loads,
            ..Default::default()
        }
    }

    #[test]
    fn a_jump_is_far_more_displacement_for_a_like_load_change() {
        // Snap-through: 20 times the displacement for the same load change.
        assert!(is_jump(&inc(0.2, 1.0), &inc(0.01, 1.0), 2.0));
        // Softening short of it: 5 times.
        assert!(!is_jump(&inc(0.05, 1.0), &inc(0.01, 1.0), 2.0));
        // A schedule that jumps 30 times carries the displacement with it.
        assert!(!is_jump(&inc(0.3, 30.0), &inc(0.01, 1.0), 2.0));
        // A load starting after an idle step, or a stiffening body.
        assert!(!is_jump(&inc(0.3, 1.0), &inc(0.0, 0.0), 2.0));
        assert!(!is_jump(&inc(0.001, 1.0), &inc(0.01, 1.0), 2.0));
        // Too small to matter, whatever the ratio.
        assert!(!is_jump(&inc(1e-4, 1.0), &inc(1e-9, 1.0), 2.0));
    }
}
