//! The state a contact scene starts from: all bodies of one dimension, and no node inside an
//! obstacle or another body by more than the contact tolerance at step 0.

use crate::contact::body_part::BodyPart;
use crate::contact::detect::Geometry;
use crate::contact::evaluate::evaluate;
use crate::contact::{ContactError, Target};
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

/// A node inside an obstacle or another body at step 0, deeper than the contact tolerance.
#[derive(Debug, thiserror::Error)]
#[error("body '{body}' starts inside {kind} '{with}': its node {node} is {depth:.3e} m deep at step 0 (the contact tolerance is {tolerance:.3e} m): move body '{body}' (or {kind} '{with}') by at least {depth:.3e} m{direction} so that they at most touch at step 0")]
pub struct StartOverlap {
    /// Body name.
    pub body: String,
    /// "obstacle" or "body".
    pub kind: &'static str,
    /// The obstacle or body it is inside.
    pub with: String,
    /// The deepest node, 1-based.
    pub node: usize,
    /// Its depth, m.
    pub depth: Real,
    /// The body's contact tolerance, m.
    pub tolerance: Real,
    /// " along [nx, ny(, nz)]": the outward normal there, or empty.
    pub direction: String,
}

/// The deepest contact of a body: node, depth (m), target and normal.
type Deepest = (usize, Real, Target, Option<Vector3<Real>>);

/// `Err` naming the first body whose dimension differs from the first body's.
pub(crate) fn one_dimension(bodies: &[Body]) -> Result<(), ContactError> {
    let Some(first) = bodies.first() else {
        return Ok(());
    };
    match bodies.iter().find(|b| b.dimension != first.dimension) {
        Some(other) => Err(ContactError::MixedDimensions {
            first: first.name.clone(),
            first_dimension: first.dimension.dofs_per_node(),
            other: other.name.clone(),
            other_dimension: other.dimension.dofs_per_node(),
        }),
        None => Ok(()),
    }
}

/// `Err` naming, for the first body found, the node deepest inside an obstacle or another body
/// at step 0 (`parts` undisplaced, obstacles at the start of their travel) when it is deeper
/// than the body's contact tolerance.
pub(crate) fn no_start_overlap(
    bodies: &[Body],
    parts: &[BodyPart],
    geometry: &Geometry,
) -> Result<(), ContactError> {
    let offsets = vec![Vector3::zeros(); geometry.obstacles.len()];
    let set = geometry.query(bodies, parts, &offsets);
    let evaluated = evaluate(
        geometry,
        &mut HashMap::new(),
        bodies,
        parts,
        &set,
        &offsets,
        None,
    );
    // Per body the deepest contact beyond its tolerance.
    let mut deepest: Vec<Option<Deepest>> = vec![None; bodies.len()];
    for e in &evaluated.list {
        let b = e.contact.body;
        // A sharp obstacle point inside a body has no node to name (its nodes are outside).
        if matches!(e.contact.with, Target::Sharp { .. }) {
            continue;
        }
        if e.depth > parts[b].tolerance && deepest[b].is_none_or(|(_, d, _, _)| e.depth > d) {
            deepest[b] = Some((e.contact.node, e.depth, e.contact.with, e.normal));
        }
    }
    let Some((b, (node, depth, with, normal))) = deepest
        .into_iter()
        .enumerate()
        .find_map(|(b, d)| d.map(|d| (b, d)))
    else {
        return Ok(());
    };
    let kind = match with {
        Target::Obstacle(_) => "obstacle",
        _ => "body",
    };
    let d = bodies[b].dimension.dofs_per_node();
    let direction = normal.map_or_else(String::new, |n| {
        let c: Vec<String> = n.as_slice()[..d]
            .iter()
            .map(|v| format!("{v:.3}"))
            .collect();
        format!(" along [{}]", c.join(", "))
    });
    Err(ContactError::StartsInside(Box::new(StartOverlap {
        body: bodies[b].name.clone(),
        kind,
        with: geometry.target_name(bodies, with).to_string(),
        node: node + 1,
        depth,
        tolerance: parts[b].tolerance,
        direction,
    })))
}
