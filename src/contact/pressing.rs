//! A contact set that flips back and forth, settled on the contacts that still press: a node that comes in without a force and goes out with one (a rim node under a flush press plate's edge, pushed out sideways from under it by its own force) keeps its contact while its depth along its normal is positive; a set that flips even so goes back to the set solved when it first flipped, with a warning naming its nodes.

use crate::contact::{ActiveContact, ContactSet, ContactSolver, Target};
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;

/// How many nodes a flip's warning names per body before "and N more".
const NAMED: usize = 8;

impl ContactSolver {
    /// The obstacle contacts of `set` (the set just solved, with the loads `forces`, N per
    /// body DOF, and the obstacles at `offsets`, m, of pseudo-time `time` of `step`) whose
    /// depth along their own normal is still positive at the current displacements: they
    /// press, so they stay, even where the nearest-point query no longer finds the node inside
    /// (pushed out past an obstacle's edge along the plane of the face it crossed). Such a
    /// contact leaves only once its depth is not positive.
    pub(crate) fn still_pressing(
        &self,
        bodies: &[Body],
        set: &ContactSet,
        (forces, offsets): (&[Vec<Real>], &[Vector3<Real>]),
        time: (Real, usize),
        step: usize,
    ) -> Vec<ActiveContact> {
        let obstacles = ContactSet {
            contacts: set
                .contacts
                .iter()
                .filter(|c| matches!(c.with, Target::Obstacle(_)))
                .copied()
                .collect(),
        };
        let problem = self.problem(bodies, &obstacles, (forces, time), offsets, step);
        // A copy of the normals: looking does not change the state solved.
        let mut normals = self.normals.clone();
        let evaluated = problem.evaluate(&mut normals, &self.parts);
        evaluated
            .list
            .iter()
            .filter(|e| e.normal.is_some() && e.depth > 0.0)
            .map(|e| e.contact)
            .collect()
    }
}

/// A flip settles as it is when it is within the bodies' penetration tolerance: every contact
/// that comes in without a force at most this many tolerances deep, and every contact that
/// goes out pulling at most this many tolerances (see [`ContactSolver::flip_gap`]).
pub(crate) const FLIP_WITHIN: Real = 1.0;

impl ContactSolver {
    /// How far the set `solved` is from settled when the set `found` after it was seen before
    /// (both evaluated at the current displacements, loads `forces`, obstacles at `offsets`,
    /// pseudo-time `time` of `step`), in penetration tolerances of the contacts' bodies: the
    /// deepest contact found and not solved (a node inside without a force) and the largest
    /// pull of a contact solved and not found (a contact held that came out along its normal,
    /// depth < 0). Only the contacts that differ are evaluated.
    pub(crate) fn flip_gap(
        &self,
        bodies: &[Body],
        (solved, found): (&ContactSet, &ContactSet),
        (forces, offsets): (&[Vec<Real>], &[Vector3<Real>]),
        time: (Real, usize),
        step: usize,
    ) -> Real {
        let (joined, left) = found.difference(solved);
        let worst = |contacts: Vec<ActiveContact>, sign: Real| {
            let set = ContactSet { contacts };
            let problem = self.problem(bodies, &set, (forces, time), offsets, step);
            let mut normals = self.normals.clone();
            problem
                .evaluate(&mut normals, &self.parts)
                .list
                .iter()
                .map(|e| sign * e.depth / self.parts[e.contact.body].tolerance)
                .fold(0.0, Real::max)
        };
        worst(joined, 1.0).max(worst(left, -1.0))
    }
}

/// The warning of a set that flips even keeping the contacts that still press, at `step`:
/// the set solved and the set found after it (`sets`), `gap` (penetration tolerances, see
/// [`ContactSolver::flip_gap`]), or the contact iterations it ran out of.
pub(crate) fn flip_warning(
    bodies: &[Body],
    step: usize,
    (solved, found): (&ContactSet, &ContactSet),
    gap: Real,
    iterations: Option<usize>,
) -> String {
    let (joined, left) = found.difference(solved);
    let how = match iterations {
        Some(n) => format!("did not settle in {n} contact iterations"),
        None => format!("is {gap:.2} penetration tolerances from settled"),
    };
    format!(
        "step {step}: the contact set flips back and forth ({} come in without a force or go out with one) and {how} even keeping the contacts that still press: kept the set solved when it first flipped; use more steps, a larger [contact] penalty, or an obstacle whose edge is not flush with a row of the body's nodes",
        flipping(bodies, joined.iter().chain(&left)),
    )
}

/// The nodes of `contacts`, as "body 'block' nodes 3, 7 and 12" per body (1-based, each
/// once, at most [`NAMED`] per body), and the count of sharp obstacle points among them.
fn flipping<'a>(bodies: &[Body], contacts: impl Iterator<Item = &'a ActiveContact>) -> String {
    let mut nodes = Vec::new();
    let mut points = 0;
    for c in contacts {
        if matches!(c.with, Target::Sharp { .. }) {
            points += 1;
        } else {
            nodes.push((c.body, c.node));
        }
    }
    nodes.sort_unstable();
    nodes.dedup();
    let mut parts = Vec::new();
    for (b, body) in bodies.iter().enumerate() {
        let of: Vec<String> = nodes
            .iter()
            .filter(|(nb, _)| *nb == b)
            .map(|(_, n)| (n + 1).to_string())
            .collect();
        if of.is_empty() {
            continue;
        }
        let shown = of.len().min(NAMED);
        let list = match (&of[..shown], of.len() - shown) {
            ([one], _) => one.clone(),
            (some, 0) => format!(
                "{} and {}",
                some[..some.len() - 1].join(", "),
                some[some.len() - 1]
            ),
            (some, more) => format!("{} and {more} more", some.join(", ")),
        };
        parts.push(format!(
            "body '{}' node{} {list}",
            body.name,
            if of.len() == 1 { "" } else { "s" }
        ));
    }
    if points > 0 {
        parts.push(format!("{points} points along sharp obstacle edges"));
    }
    parts.join("; ")
}
