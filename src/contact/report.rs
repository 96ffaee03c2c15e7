//! The report of a settled step: each body's state, the contacts each node receives, the totals per pair, and the warnings.

use crate::contact::body_part::BodyPart;
use crate::contact::evaluate::friction_key;
use crate::contact::evaluate::Evaluation;
use crate::contact::problem::Problem;
use crate::contact::{ContactError, NodeContact, SlipState, Target};
use crate::linkage::body_state::{internal_force_vector, member_response_at, norm};
use crate::linkage::{post_process, Body, StepState};
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;

/// A solved step of a scene with contact.
#[derive(Clone, Debug, Default)]
pub struct ContactStep {
    /// Per body, in scene order.
    pub states: Vec<StepState>,
    /// Per body, the nodes pressing on an obstacle or another body.
    pub contacts: Vec<Vec<NodeContact>>,
    /// Contact iterations (solves with a fixed contact set) the step took.
    pub contact_iterations: usize,
    /// Newton iterations, all contact iterations and increments together (failed attempts
    /// included).
    pub newton_iterations: usize,
    /// Halvings of the increment in this step (0: crossed in one increment).
    pub cuts: usize,
    /// Negative pivots of the last coupled tangent factored (LDLᵀ: a body buckling under
    /// contact; 0 when it was positive definite).
    pub negative_pivots: usize,
    /// Conjugate-gradient iterations of the step (bodies solved iteratively).
    pub linear_iterations: usize,
    /// Largest penetration at the solution, m.
    pub max_penetration: Real,
    /// What the user should know: penetration above tolerance, a contact set that did not
    /// settle.
    pub warnings: Vec<String>,
    /// Whether some iteration needed the stabilisation (a body held only by contact).
    pub stabilised: bool,
    /// Per body, the total contact force it receives from each obstacle or body it touches,
    /// as (name of the other, force in N), in name order.
    pub totals: Vec<Vec<(String, Vector3<Real>)>>,
    /// Contacts that stick (friction holds them).
    pub sticking: usize,
    /// Contacts that slip (at `μ f_N`; frictionless contacts slip always).
    pub slipping: usize,
}

/// States, contacts and penetration of the settled step of `p` into `out`, from its contacts
/// `evaluated` at the solution.
pub(crate) fn finish(
    p: &Problem,
    parts: &[BodyPart],
    evaluated: Evaluation,
    mut out: ContactStep,
) -> Result<ContactStep, ContactError> {
    let (bodies, step) = (p.bodies, p.step);
    let Evaluation { forces: all, list } = evaluated;
    // Per body, per node touched: (what it touches, deepest depth, force received).
    let mut touched: Vec<Vec<NodeContact>> = vec![Vec::new(); bodies.len()];
    for e in &list {
        let name = p.geometry.target_name(bodies, e.contact.with).to_string();
        let n = e.normal.unwrap_or_default();
        let normal_force = n * e.normal_force();
        let (tangential, state, slip, dissipated) = match &e.tangential {
            Some(t) => {
                let (key, _) = friction_key(&e.contact);
                let before = p
                    .friction
                    .and_then(|h| h.committed.get(&key))
                    .map_or(Vector3::zeros(), |c| c.slip);
                (t.force, t.state, before + t.slip, -t.force.dot(&t.slip))
            }
            None => (Vector3::zeros(), SlipState::Slip, Vector3::zeros(), 0.0),
        };
        match state {
            SlipState::Stick => out.sticking += 1,
            SlipState::Slip => out.slipping += 1,
        }
        out.max_penetration = out.max_penetration.max(e.depth);
        let part = &parts[e.contact.body];
        // An obstacle's sharp point presses the body's surface nodes: all of them touch it.
        let sharp = matches!(e.contact.with, Target::Sharp { .. });
        if e.depth > part.tolerance && sharp {
            out.warnings.push(format!(
                "step {step}: a sharp edge of '{name}' is {:.3e} m inside body '{}' (tolerance {:.3e} m): raise [contact] penalty",
                e.depth,
                bodies[e.contact.body].name,
                part.tolerance
            ));
        } else if e.depth > part.tolerance {
            out.warnings.push(format!(
                "step {step}: node {} of body '{}' is {:.3e} m inside '{name}' (tolerance {:.3e} m): raise [contact] penalty",
                e.contact.node + 1,
                bodies[e.contact.body].name,
                e.depth,
                part.tolerance
            ));
        }
        for (k, &(b, node, w)) in e.nodes.iter().enumerate() {
            // The pressing node touches the target; a surface node touches the pressing body.
            let (with, depth) = if k == 0 || sharp {
                (name.clone(), e.depth.max(0.0))
            } else {
                (bodies[e.contact.body].name.clone(), 0.0)
            };
            // The contact's dissipation once: on its pressing node, or a sharp point's
            // surface nodes by their weights.
            let share = if sharp {
                w
            } else if k == 0 {
                1.0
            } else {
                0.0
            };
            let list = &mut touched[b];
            match list.iter_mut().find(|t| t.node == node && t.with == with) {
                Some(t) => {
                    t.friction_dissipated += dissipated * share;
                    t.depth = t.depth.max(depth);
                    t.force += e.force() * w;
                    // Summed as vectors here; made a unit normal and its size below.
                    t.normal += normal_force * w;
                    t.tangential_force += tangential * w;
                    t.slip += slip * w;
                    if state == SlipState::Slip {
                        t.state = SlipState::Slip;
                    }
                }
                None => list.push(NodeContact {
                    node,
                    with,
                    depth,
                    force: e.force() * w,
                    normal: normal_force * w,
                    normal_force: 0.0,
                    tangential_force: tangential * w,
                    state,
                    slip: slip * w,
                    friction_dissipated: dissipated * share,
                }),
            }
        }
    }
    // The bodies side by side (each body's arithmetic is the same as alone); the first body
    // in order that fails decides, as one at a time did.
    let iterations = out.newton_iterations;
    let each: Vec<Result<BodyReport, ContactError>> = bodies
        .par_iter()
        .zip(all)
        .zip(touched)
        .enumerate()
        .map(|(b, ((body, fc), contacts))| {
            body_report(
                p,
                (b, &parts[b]),
                body,
                &p.applied(b, &parts[b].u),
                fc,
                contacts,
                iterations,
            )
        })
        .collect();
    for report in each {
        let (totals, state, contacts) = report?;
        out.totals.push(totals);
        out.states.push(state);
        out.contacts.push(contacts);
    }
    Ok(out)
}

/// One body's part of the report: its totals per pair, its state and its contacts.
type BodyReport = (Vec<(String, Vector3<Real>)>, StepState, Vec<NodeContact>);

/// The report of one body (`part` of `body`, number `b`, applied `forces` (following pressures
/// included), contact forces `fc` per DOF,
/// the nodes it touches with) after `iterations` Newton iterations.
fn body_report(
    p: &Problem,
    (b, part): (usize, &BodyPart),
    body: &Body,
    forces: &[Real],
    fc: Vec<Real>,
    mut contacts: Vec<NodeContact>,
    iterations: usize,
) -> Result<BodyReport, ContactError> {
    let step = p.step;
    let d = part.dofs.dofs_per_node;
    let mut internal = internal_force_vector(body, &part.u);
    for (i, f) in internal.iter_mut().zip(&fc) {
        *i -= f;
    }
    // Within a time step the inertia force balances the rest: at a free DOF it is part of the
    // residual's balance, at a held one part of the reaction (the support moves the mass).
    if let Some(term) = p.inertia.and_then(|i| i.get(b)) {
        term.add_force(&part.u, &mut internal);
    }
    let members = (0..body.members.len()).map(|m| {
        let r = member_response_at(body, &part.u, m);
        (r.strain, r.force)
    });
    let mut state = post_process(body, &part.dofs, &part.u, forces, &internal, members);
    state.iterations = iterations;
    // Relative to the largest of applied, reaction and contact forces (a body held by
    // contact alone has no reactions), and at least the force floor (which holds the run's
    // largest scale so far: forces that vanish, as a split body's, leave a real scale).
    let unbalanced = |dofs: &[usize]| -> Real {
        dofs.iter()
            .map(|&dof| (internal[dof] - forces[dof]).powi(2))
            .sum::<Real>()
            .sqrt()
    };
    let out_of_balance = unbalanced(&part.dofs.free);
    let reacted = unbalanced(&part.dofs.supported);
    let scale = norm(forces).max(reacted).max(norm(&fc)).max(p.force_floor);
    state.force_scale = scale;
    state.residual = if scale > 0.0 {
        out_of_balance / scale
    } else {
        out_of_balance
    };
    if !state.residual.is_finite()
        || state
            .displacements
            .iter()
            .any(|u| !u.iter().all(|c| c.is_finite()))
    {
        return Err(ContactError::NotFinite { step });
    }
    for c in &mut contacts {
        for k in d..3 {
            c.force[k] = 0.0;
            c.normal[k] = 0.0;
            c.tangential_force[k] = 0.0;
            c.slip[k] = 0.0;
        }
        c.normal_force = c.normal.norm();
        if c.normal_force > 0.0 {
            c.normal /= c.normal_force;
        }
    }
    contacts.sort_by(|a, b| a.node.cmp(&b.node).then(a.with.cmp(&b.with)));
    Ok((totals(&contacts), state, contacts))
}

/// The total force of `contacts` per body or obstacle touched, N, in name order.
fn totals(contacts: &[NodeContact]) -> Vec<(String, Vector3<Real>)> {
    let mut totals: Vec<(String, Vector3<Real>)> = Vec::new();
    for c in contacts {
        match totals.iter_mut().find(|(with, _)| *with == c.with) {
            Some((_, f)) => *f += c.force,
            None => totals.push((c.with.clone(), c.force)),
        }
    }
    totals.sort_by(|a, b| a.0.cmp(&b.0));
    totals
}
