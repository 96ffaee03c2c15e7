//! What a body that its supports and contacts do not hold is free to do: the error that names its free rigid motions (and the load along them) instead of "found no contact that holds it".

use crate::contact::body_part::position;
use crate::contact::evaluate::friction_key;
use crate::contact::free_motions::{FreeMotions, Held};
use crate::contact::{ContactError, ContactSet, ContactSolver};
use crate::linkage::body_state::node_vector;
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;

impl ContactSolver {
    /// The error for the first body that the contacts of `found` leave free to move rigidly
    /// with its supports ([`ContactError::Free`]): its free motions at the current
    /// displacements, and the part of its loads `forces` (N per body DOF; following pressures at
    /// pseudo-time `time`) along them. A
    /// contact holds along its normal, and along its surface too where it has friction
    /// (μ > 0). Where the settle loop gave up (`settled` false) the bodies touching something
    /// are judged; at a settled state, the loaded bodies without any support (a balanced
    /// load does not make a free motion held: a block on a frictionless floor). `None` when
    /// every body judged is held.
    pub(crate) fn free_body(
        &self,
        bodies: &[Body],
        found: &ContactSet,
        (forces, offsets): (&[Vec<Real>], &[Vector3<Real>]),
        time: (Real, usize),
        step: usize,
        settled: bool,
    ) -> Option<ContactError> {
        // At a settled state only a loaded body without any support is judged: most scenes
        // have none, and then the contacts are not evaluated again.
        let unsupported = |b: usize, body: &Body| {
            body.supports.iter().all(|s| !s.fixed.iter().any(|f| *f))
                && forces[b].iter().any(|f| *f != 0.0)
        };
        if settled
            && !bodies
                .iter()
                .enumerate()
                .any(|(b, body)| unsupported(b, body))
        {
            return None;
        }
        let problem = self.problem(bodies, found, (forces, time), offsets, step);
        let mut normals = self.normals.clone();
        let evaluated = problem.evaluate(&mut normals, &self.parts);
        let mut held: Vec<Vec<Held>> = vec![Vec::new(); bodies.len()];
        let mut touching = vec![false; bodies.len()];
        for e in &evaluated.list {
            let Some(n) = e.normal else { continue };
            let mu = match (&self.friction, &e.tangential) {
                (Some(history), Some(_)) => history.law(&friction_key(&e.contact).0).0,
                _ => 0.0,
            };
            let mut directions = vec![n];
            if mu > 0.0 {
                let t1 = n.cross(&Vector3::ith(n.iamin(), 1.0)).normalize();
                directions.extend([t1, n.cross(&t1)]);
            }
            for &(b, node, _) in &e.nodes {
                touching[b] = true;
                let point = position(bodies, &self.parts, b, node);
                held[b].extend(
                    directions
                        .iter()
                        .map(|&direction| Held { point, direction }),
                );
            }
        }
        for (b, body) in bodies.iter().enumerate() {
            let judged = if settled {
                unsupported(b, body)
            } else {
                touching[b]
            };
            if !judged {
                continue;
            }
            let d = self.parts[b].dofs.dofs_per_node;
            let load: Vector3<Real> = (0..body.nodes.len())
                .map(|n| node_vector(&forces[b], d, n))
                .sum();
            let nodes: Vec<Vector3<Real>> = (0..body.nodes.len())
                .map(|n| position(bodies, &self.parts, b, n))
                .collect();
            for s in &body.supports {
                for d in (0..3).filter(|&d| s.fixed[d]) {
                    held[b].push(Held {
                        point: nodes[s.node],
                        direction: Vector3::ith(d, 1.0),
                    });
                }
            }
            let free = FreeMotions::of(body.dimension, &nodes, &held[b]);
            if free.is_empty() {
                continue;
            }
            return Some(ContactError::Free {
                step,
                body: body.name.clone(),
                motions: free.describe(),
                push: free.push(&load),
            });
        }
        None
    }
}
