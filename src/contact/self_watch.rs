//! The watch for self-contact in a breaking body solved without contact (a scene without
//! obstacles and without `[contact]`): after each load step, whether the body now touches
//! itself by the rules of [`crate::contact::self_contact_on`]'s self-contact (a crack broken
//! in tension closed beyond round-off; a surface node behind a segment or patch of its own
//! body that it came to from the front since the last step). While nothing touches, the body
//! keeps its fast solver (factored once, low-rank updates per break); the first touch found
//! tells the driver to go on with the contact solver.
//!
//! The watch is the contact detection itself, run on the one body with no obstacles, so it
//! finds exactly what the contact solver would find at the same state. Pieces that fell off
//! (removed from the body's solve, held at rest) neither press nor are pressed.

use crate::contact::body_part::BodyPart;
use crate::contact::detect::Geometry;
use crate::contact::{
    default_penalty, penetration_tolerance, ContactError, ContactSet, Penalty, Target,
};
use crate::linkage::{Body, DofMap, StiffnessAssembly};
use crate::Real;

/// A self-contact found by the watch: the first one, for the message.
#[derive(Debug, Clone, PartialEq)]
pub struct SelfTouch {
    /// The pressing node, 0-based.
    pub node: usize,
    /// What it touches, in words (with 1-based numbers).
    pub what: String,
}

/// One breaking body's self-contact watch (see the module documentation).
pub struct SelfContactWatch {
    /// The body with its broken and fallen members at modulus factor zero.
    body: Vec<Body>,
    geometry: Geometry,
    parts: Vec<BodyPart>,
    /// Members seen broken so far.
    broken: Vec<bool>,
    /// Nodes of pieces that fell off.
    fallen: Vec<bool>,
    /// Steps checked so far.
    pub checked: usize,
}

impl SelfContactWatch {
    /// The watch of `body` at rest (step 0).
    pub fn new(body: &Body) -> Result<Self, ContactError> {
        let bodies = vec![body.clone()];
        let geometry = Geometry::new(&bodies, &[], None)?;
        // Detection reads the displacements, DOF map, penalty and tolerance only: no pattern.
        let dofs = DofMap::new(body);
        let assembly = StiffnessAssembly::default();
        let parts = vec![BodyPart {
            u: vec![0.0; body.dof_count()],
            penalty: Penalty {
                stiffness: default_penalty(body),
            },
            tolerance: penetration_tolerance(body),
            local: Vec::new(),
            dofs,
            assembly,
        }];
        let mut watch = SelfContactWatch {
            broken: vec![false; body.members.len()],
            fallen: vec![false; body.nodes.len()],
            body: bodies,
            geometry,
            parts,
            checked: 0,
        };
        watch.record();
        Ok(watch)
    }

    /// Take the current state as the start of the next step.
    fn record(&mut self) {
        self.geometry
            .record_sides(&self.body, &self.parts, &ContactSet::new(Vec::new()));
    }

    /// The body's state at the end of a step: displacements `u` per body DOF (m), the members
    /// broken so far (0-based) with `in_tension` telling for each whether it broke in tension,
    /// and the nodes that fell off so far. Returns the first self-contact found, or `None`
    /// (then this state is the start of the next step).
    pub fn check(
        &mut self,
        u: &[Real],
        broken: &[usize],
        in_tension: impl Fn(usize) -> bool,
        fallen: impl IntoIterator<Item = usize>,
    ) -> Option<SelfTouch> {
        self.checked += 1;
        let body = &mut self.body[0];
        if body.member_factors.len() != body.members.len() {
            body.member_factors = vec![1.0; body.members.len()];
        }
        for n in fallen {
            self.fallen[n] = true;
        }
        for (m, member) in body.members.iter().enumerate() {
            if member.nodes.iter().any(|&n| self.fallen[n]) && !self.broken[m] {
                // Gone with its piece: never a crack.
                self.broken[m] = true;
                body.member_factors[m] = 0.0;
                self.geometry.own.mark_broken(0, m, false);
            }
        }
        for &m in broken {
            if !self.broken[m] {
                self.broken[m] = true;
                body.member_factors[m] = 0.0;
                self.geometry.own.mark_broken(0, m, in_tension(m));
            }
        }
        self.parts[0].u.copy_from_slice(u);
        let found = self.geometry.query(&self.body, &self.parts, &[]);
        let touch = found
            .contacts
            .iter()
            .find(|c| !self.involves_fallen(c.node, c.with))
            .map(|c| SelfTouch {
                node: c.node,
                what: self.describe(c.with),
            });
        if touch.is_none() {
            self.record();
        }
        touch
    }

    /// Whether a contact of `node` against `with` involves a node that fell off.
    fn involves_fallen(&self, node: usize, with: Target) -> bool {
        let gone = |n: usize| self.fallen[n];
        gone(node) || self.target_nodes(with).into_iter().any(gone)
    }

    /// The body nodes of a self-contact target.
    fn target_nodes(&self, with: Target) -> Vec<usize> {
        let g = &self.geometry;
        match with {
            Target::Segment { segment, .. } => g.surfaces[0]
                .as_ref()
                .map(|s| {
                    let (a, b) = s.segment(segment);
                    vec![a, b]
                })
                .unwrap_or_default(),
            Target::Patch { patch, .. } => g.patch_surfaces[0]
                .as_ref()
                .and_then(|s| s.patches.get(patch))
                .map(|p| p.to_vec())
                .unwrap_or_default(),
            Target::Vertex { vertex, .. } => g.surfaces[0]
                .as_ref()
                .and_then(|s| s.nodes.get(vertex).copied())
                .into_iter()
                .collect(),
            Target::Closing { member, .. } => self.body[0].members[member].nodes.to_vec(),
            Target::Edge { nodes, .. } => nodes.to_vec(),
            Target::Corner { node, .. } => vec![node],
            Target::Obstacle(_) | Target::Sharp { .. } => Vec::new(),
        }
    }

    /// A target in words, with 1-based numbers.
    fn describe(&self, with: Target) -> String {
        let nodes: Vec<String> = self
            .target_nodes(with)
            .iter()
            .map(|n| (n + 1).to_string())
            .collect();
        match with {
            Target::Closing { member, .. } => format!(
                "the crack of member {} (nodes {}) closed",
                member + 1,
                nodes.join(", ")
            ),
            _ => format!("behind its own surface between nodes {}", nodes.join(", ")),
        }
    }
}
