//! Members that break (or soften by teeth) in a scene with contact, event by event.
//!
//! Contact makes the response to the load nonlinear (the contact set changes with it), so the
//! critical load of a member is not one linear solve away. Within a step the bodies are first
//! settled at the step's load. When a breaking member is then beyond its strength, the load at
//! which the first one reaches it is found between the last settled state below it and the
//! step's end: the secant of the members' stresses between the two states gives a candidate
//! load (exact when the contact set does not change between them: linear bodies on a fixed
//! contact set respond linearly to the loads, support displacements and obstacle travel);
//! contact is settled there, and the bracket narrowed, until the member is at its strength to
//! [`AT_STRENGTH`]. The member breaks (or passes a tooth) at that load, contact is settled
//! again there with the weakened body, then at the step's load, and so on until no member is
//! beyond its strength at the step's load. Members break only at settled states.
//!
//! Snap-backs are followed as [`BreakingEquilibrium`](crate::linkage::fracture::BreakingEquilibrium)
//! follows them: when members beyond their strength at the step's load are, just after a
//! break, already beyond it at the break's load, the weakened body reaches their strength at a
//! lower load. Frictionless contact of linear bodies does not depend on the path, so contact is
//! settled lower on the weakened body until those members are within their strength
//! (`ContactFracture::below`), and the search runs between there and the break's state; the
//! next break is recorded at its lower load (the fraction of the step's increment below the
//! previous break's, below 0 when it lies in an earlier step's).
//!
//! A body under large displacements (or with tension- or compression-only members) breaks the
//! same way: its members' stresses are those the results report (the member response at the
//! displacement), not linear in the load even on a fixed contact set, so the secant is only a
//! first guess and the bracket is narrowed by settles until the member is at its strength.
//!
//! With friction, every settle of the search is one increment of friction's history from the
//! step's start (a step cut into increments is settled again at its end as one), and after a
//! break the history is committed at the break's state, so what follows starts from the slip
//! there; at the step's end it is committed as without fracture. The load is never lowered: the
//! state of a body with friction at a lower load depends on the way there, so members beyond
//! their strength just after a break (a snap-back without friction) break at that break's load,
//! one event after the other.
//!
//! A broken member keeps its place in the body with a modulus factor of zero (a softened one:
//! its tooth's, [`Body::member_factors`]), so numbering, patterns, surfaces and the materials
//! stay. Contact
//! is solved on the coupled path for a scene with breaking bodies: the condensed path factors
//! each body once per run, and a break changes its compliance.
//!
//! A break after which contact cannot be settled may have cut a piece loose. A piece held by
//! contact settles like the rest. Otherwise the pieces the break left without support (as
//! without contact: connected parts without supports, and nodes on fewer intact members than
//! their DOFs, see [`released_pieces`]) that touch nothing in the last settled contact set are
//! removed from the solve: they fell off. Their members carry nothing from then on, their loads
//! are dropped, their nodes are held where they were made (undeformed) and are no longer looked
//! for contacts, and contact is settled again. When nothing can be removed, or contact still
//! cannot be settled, the break is the structure's collapse; the state it collapsed in is
//! settled and reported as without contact (see `ContactFracture::collapse_state`).

use crate::contact::{ContactError, ContactSolver, ContactStep, Obstacle, Target};
use crate::linkage::body_state::{linear_stretch, member_response_at, undeformed_axis};
use crate::linkage::fracture::{
    breaks_members, critical_fraction, member_limits, released_pieces, BreakEvent, FallenPiece,
    FractureState, MemberLimits, Tooth,
};
use crate::linkage::{Body, DofMap, SolveError, StiffnessAssembly, Support};
use crate::Real;
use nalgebra::Vector3;

/// A member counts as at its strength within this fraction of it (the contact Newton's
/// residual of 1e-10 leaves the stresses accurate to about this).
pub const AT_STRENGTH: Real = 1e-8;

/// Settles allowed to find one critical load.
const MAX_REFINEMENTS: usize = 60;

/// One breaking body's members: strengths, teeth and what has broken.
struct Breaking {
    limits: MemberLimits,
    first_limits: MemberLimits,
    teeth: Vec<Vec<Tooth>>,
    tooth: Vec<usize>,
    /// Per member its modulus as a fraction of its material's (0 once broken).
    factor: Vec<Real>,
    axes: Vec<Vector3<Real>>,
    lengths: Vec<Real>,
    broken: Vec<usize>,
}

/// Why a step with breaking members stopped.
#[derive(Debug)]
pub enum FractureStop {
    /// Contact could not be solved (before any break of the step that explains it).
    Contact(ContactError),
    /// A break left contact unable to hold the body: its collapse.
    Collapse {
        /// Body index.
        body: usize,
        /// The member (0-based) whose break did it.
        member: usize,
        /// The breaks of that body in the step, the last one included.
        breaks: Vec<BreakEvent>,
        /// The state it collapsed in, when it could be settled (see
        /// [`ContactFracture::collapse_state`]): the step as reported, every body's fracture
        /// state with it.
        state: Option<Box<CollapseState>>,
    },
}

/// The state a structure collapsed in: the step's report at the load the step reached, and
/// per body its fracture state (`None` for a body that does not break).
pub type CollapseState = (ContactStep, Vec<Option<FractureState>>);

impl From<ContactError> for FractureStop {
    fn from(e: ContactError) -> Self {
        FractureStop::Contact(e)
    }
}

/// The bodies of a contact scene as they break, and each breaking body's members.
pub struct ContactFracture {
    /// The bodies as they are now (broken members of modulus factor zero).
    pub bodies: Vec<Body>,
    original: Vec<Body>,
    breaking: Vec<Option<Breaking>>,
    /// Per breaking body its members' stresses (Pa) at the end of the last step solved.
    last: Vec<Vec<Real>>,
    /// Per body, its nodes removed with pieces that fell off.
    fallen: Vec<Vec<bool>>,
    /// The pseudo-time of the solver's current state.
    now: Real,
}

impl ContactFracture {
    /// The breaking state of `bodies` (each member's strength drawn with its scatter, its
    /// teeth with its softening); `None` when no body breaks.
    pub fn new(bodies: &[Body]) -> Result<Option<Self>, SolveError> {
        if !bodies.iter().any(breaks_members) {
            return Ok(None);
        }
        let breaking = bodies
            .iter()
            .map(|body| {
                if !breaks_members(body) {
                    return Ok(None);
                }
                let limits = member_limits(body);
                let teeth = crate::linkage::fracture::member_teeth(body, &limits)?;
                let n = body.members.len();
                Ok(Some(Breaking {
                    first_limits: limits.clone(),
                    limits,
                    teeth,
                    tooth: vec![0; n],
                    factor: vec![1.0; n],
                    axes: body
                        .members
                        .iter()
                        .map(|m| undeformed_axis(body, m.nodes[0], m.nodes[1]))
                        .collect(),
                    lengths: (0..n).map(|m| body.member_length(m)).collect(),
                    broken: Vec::new(),
                }))
            })
            .collect::<Result<Vec<_>, SolveError>>()?;
        Ok(Some(ContactFracture {
            bodies: bodies.to_vec(),
            original: bodies.to_vec(),
            last: bodies.iter().map(|b| vec![0.0; b.members.len()]).collect(),
            fallen: bodies.iter().map(|b| vec![false; b.nodes.len()]).collect(),
            breaking,
            now: 0.0,
        }))
    }

    /// Every breaking member's stress at the solver's current displacements, Pa, per body
    /// (empty for a body that does not break).
    fn stresses(&self, solver: &ContactSolver) -> Vec<Vec<Real>> {
        self.breaking
            .iter()
            .enumerate()
            .map(|(b, br)| {
                let Some(br) = br else { return Vec::new() };
                let body = &self.original[b];
                let u = &solver.parts[b].u;
                if body.is_nonlinear() {
                    // Large displacements or slack members: the stress the results report.
                    let now = &self.bodies[b];
                    return (0..now.members.len())
                        .map(|m| {
                            let area = now.materials[now.members[m].material].area;
                            member_response_at(now, u, m).force / area
                        })
                        .collect();
                }
                let d = body.dimension.dofs_per_node();
                body.members
                    .iter()
                    .enumerate()
                    .map(|(m, member)| {
                        let material = &body.materials[member.material];
                        let strain =
                            linear_stretch(u, d, member.nodes, &br.axes[m]) / br.lengths[m];
                        material.youngs_modulus * br.factor[m] * strain * material.area
                            / material.area
                    })
                    .collect()
            })
            .collect()
    }

    /// Per breaking body, whether each member is beyond its strength in `stress` by more than
    /// [`AT_STRENGTH`] (intact members of a breaking material only; empty for other bodies).
    fn beyond(&self, stress: &[Vec<Real>]) -> Vec<Vec<bool>> {
        self.breaking
            .iter()
            .enumerate()
            .map(|(b, br)| {
                let Some(br) = br else { return Vec::new() };
                (0..br.factor.len())
                    .map(|m| match br.limits[m] {
                        Some((tensile, compressive)) if br.factor[m] != 0.0 => {
                            let s = stress[b][m];
                            s > tensile * (1.0 + AT_STRENGTH)
                                || s < -compressive * (1.0 + AT_STRENGTH)
                        }
                        _ => false,
                    })
                    .collect()
            })
            .collect()
    }

    /// Whether any member of `of` (per body, as [`ContactFracture::beyond`] gives) is beyond
    /// its strength in `stress`.
    fn any_beyond(&self, stress: &[Vec<Real>], of: &[Vec<bool>]) -> bool {
        self.beyond(stress)
            .iter()
            .zip(of)
            .any(|(now, of)| now.iter().zip(of).any(|(&a, &b)| a && b))
    }

    /// The first member of `over` (per body, the members beyond their strength at the step's
    /// load) to reach its strength on the secant from stresses `lo` to `hi`: (body, member,
    /// fraction of the way), the smallest fraction, ties by body then member. Members beyond
    /// their strength by less than [`AT_STRENGTH`] at `hi` do not count.
    fn first_over(
        &self,
        lo: &[Vec<Real>],
        hi: &[Vec<Real>],
        over: &[Vec<bool>],
    ) -> Option<(usize, usize, Real)> {
        let mut best: Option<(usize, usize, Real)> = None;
        for (b, br) in self.breaking.iter().enumerate() {
            let Some(br) = br else { continue };
            for m in 0..br.factor.len() {
                let Some((tensile, compressive)) = br.limits[m] else {
                    continue;
                };
                if br.factor[m] == 0.0 || !over[b][m] {
                    continue;
                }
                let (a, end) = (lo[b][m], hi[b][m]);
                if end <= tensile * (1.0 + AT_STRENGTH) && end >= -compressive * (1.0 + AT_STRENGTH)
                {
                    continue;
                }
                if let Some(f) = critical_fraction(a, end - a, tensile, compressive) {
                    if best.is_none_or(|(_, _, g)| f < g) {
                        best = Some((b, m, f));
                    }
                }
            }
        }
        best
    }

    /// The members of `over` (per body) other than member `m` of body `b` that are at their
    /// strength in `stress` (to [`AT_STRENGTH`]) as it is: they tie with it (by body, then
    /// member).
    fn tied(
        &self,
        b: usize,
        m: usize,
        stress: &[Vec<Real>],
        over: &[Vec<bool>],
    ) -> Vec<(usize, usize)> {
        let mut tied = Vec::new();
        for (c, br) in self.breaking.iter().enumerate() {
            let Some(br) = br else { continue };
            for (j, (&factor, &beyond)) in br.factor.iter().zip(&over[c]).enumerate() {
                if (c, j) != (b, m) && factor > 0.0 && beyond && self.at_strength(c, j, stress) {
                    tied.push((c, j));
                }
            }
        }
        tied
    }

    /// Whether member `m` of body `b` is at its strength (tensile or compressive) in `stress`
    /// to [`AT_STRENGTH`].
    fn at_strength(&self, b: usize, m: usize, stress: &[Vec<Real>]) -> bool {
        let Some(br) = &self.breaking[b] else {
            return false;
        };
        let Some((tensile, compressive)) = br.limits[m] else {
            return false;
        };
        at_limit(stress[b][m], tensile) || at_limit(-stress[b][m], compressive)
    }

    /// Break member `m` of body `b`, or move it to its next tooth (returned, 1-based: the
    /// tooth passed). The body's member factor follows (its materials stay the scene's).
    fn break_member(&mut self, b: usize, m: usize) -> Option<usize> {
        let br = self.breaking[b].as_mut()?;
        let next = br.tooth[m] + 1;
        let passed = match br.teeth[m].get(next).copied() {
            Some(t) => {
                br.tooth[m] = next;
                br.factor[m] = t.stiffness_factor;
                let (tensile, compressive) = br.first_limits[m].unwrap_or((1.0, 1.0));
                br.limits[m] = Some((
                    t.tensile_strength,
                    compressive * (t.tensile_strength / tensile),
                ));
                Some(next)
            }
            None => {
                br.factor[m] = 0.0;
                br.broken.push(m);
                None
            }
        };
        let body = &mut self.bodies[b];
        if body.member_factors.len() != body.members.len() {
            body.member_factors = vec![1.0; body.members.len()];
        }
        body.member_factors[m] = br.factor[m];
        passed
    }

    /// Settle contact at pseudo-time `t` from the solver's current state.
    fn settle(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        t: Real,
        (step, steps): (usize, usize),
    ) -> Result<(), ContactError> {
        let from = self.now;
        self.now = t;
        solver
            .settle_at(&self.bodies, obstacles, from, t, steps, step)
            .map(|_| ())
    }

    /// Solve `step` of `steps` with `solver` (built on these bodies), breaking members event by
    /// event (see the module documentation). Returns the step and, per body, its fracture state
    /// (`None` for a body that does not break).
    pub fn solve_step(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
    ) -> Result<(ContactStep, Vec<Option<FractureState>>), FractureStop> {
        if step == 0 {
            if self.fallen.iter().flatten().any(|&f| f) {
                // The solver holds the removed nodes: give it the whole bodies back.
                for (b, body) in self.original.iter().enumerate() {
                    if self.fallen[b].iter().any(|&f| f) {
                        refit_body(solver, b, body)?;
                    }
                }
                solver.removed.clear();
                self.fallen
                    .iter_mut()
                    .for_each(|f| f.iter_mut().for_each(|v| *v = false));
            }
            self.bodies = self.original.clone();
            let fresh = ContactFracture::new(&self.original)
                .ok()
                .flatten()
                .map(|f| f.breaking);
            if let Some(breaking) = fresh {
                self.breaking = breaking;
            }
            for l in &mut self.last {
                l.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        // Friction's history at the step's start: the search settles every trial load as one
        // increment from there (or from the last break's state, committed after it).
        let history = solver.friction.clone();
        let out = solver.settle_step(&self.bodies, obstacles, step, steps)?;
        self.now = step as Real;
        let friction = history.is_some();
        if friction && step > 0 && out.cuts > 0 {
            // The cut step committed friction's history at its increments: settle the step's
            // end again as one increment from its start, as the search settles its loads.
            let reached = solver.friction.clone();
            let saved = solver.converged_state();
            solver.friction = history.clone();
            self.now = (step - 1) as Real;
            if self
                .settle(solver, obstacles, step as Real, (step, steps))
                .is_err()
            {
                solver.restore(saved);
                solver.friction = reached;
            }
            self.now = step as Real;
        }
        let mut events: Vec<Vec<BreakEvent>> = vec![Vec::new(); self.bodies.len()];
        let mut fallen: Vec<Vec<FallenPiece>> = vec![Vec::new(); self.bodies.len()];
        if step > 0 {
            let end = step as Real;
            // The search runs between a settled state where the members beyond their strength
            // at the step's load are within it (`lo`, at `t_lo`) and one where some are (`top`):
            // the step's end, or after a break that sent others past their strength at its
            // load, that break's load (a snap-back: they reach it lower).
            let (mut t_lo, mut lo) = (end - 1.0, self.last.clone());
            let mut at_end = self.stresses(solver);
            let mut top = (end, at_end.clone());
            // The load the step reached: a snap-back's later breaks are recorded at a lower
            // load, but the load does not go back (the load of a collapse state).
            let mut reached = end - 1.0;
            loop {
                let over = self.beyond(&at_end);
                let Some((b, m, t_break)) = self.critical_load(
                    solver,
                    obstacles,
                    (step, steps),
                    (t_lo, &lo),
                    (top.0, &top.1),
                    &over,
                )?
                else {
                    break;
                };
                // Members at their strength at the same load (symmetric twins) break with it,
                // in one event, as without contact.
                let at_break = self.stresses(solver);
                let tied = self.tied(b, m, &at_break, &over);
                reached = reached.max(t_break);
                // Each member's modulus factor before the event (a collapse state is settled
                // with them).
                let mut before = Vec::new();
                for (b, m) in std::iter::once((b, m)).chain(tied) {
                    before.push((b, m, self.bodies[b].modulus_factor(m)));
                    let tooth = self.break_member(b, m);
                    events[b].push(BreakEvent {
                        member: m,
                        fraction: t_break - (end - 1.0),
                        tooth,
                    });
                }
                // The state just after the break, at its load, then at the step's.
                let mut after = Vec::new();
                for t in [t_break, end] {
                    if !self.settle_or_release(
                        solver,
                        obstacles,
                        t,
                        (step, steps),
                        b,
                        m,
                        &mut fallen[b],
                    )? {
                        let state = self.collapse_state(
                            solver,
                            obstacles,
                            (step, steps),
                            (reached, &before),
                            out,
                            (&events, &mut fallen),
                        );
                        return Err(FractureStop::Collapse {
                            body: b,
                            member: m,
                            breaks: std::mem::take(&mut events[b]),
                            state: state.map(Box::new),
                        });
                    }
                    if t == t_break {
                        after = self.stresses(solver);
                        if friction {
                            // The slip up to the break is history: what follows starts there.
                            solver.commit_friction(&self.bodies, obstacles, t, steps, step);
                        }
                    }
                }
                at_end = self.stresses(solver);
                let over = self.beyond(&at_end);
                if friction {
                    // With friction the state at a lower load depends on the way there: the
                    // load is not lowered, members beyond their strength at the break's load
                    // break there, one after the other (a cascade at that load).
                    let top_stress = if self.any_beyond(&after, &over) {
                        after.clone()
                    } else {
                        at_end.clone()
                    };
                    let top_t = if self.any_beyond(&after, &over) {
                        t_break
                    } else {
                        end
                    };
                    (t_lo, lo) = (t_break, after);
                    top = (top_t, top_stress);
                } else if self.any_beyond(&after, &over) {
                    (t_lo, lo) = self.below(
                        solver,
                        obstacles,
                        (step, steps),
                        (t_break, &after),
                        &at_end,
                        t_lo,
                        &over,
                    )?;
                    top = (t_break, after);
                } else {
                    (t_lo, lo) = (t_break, after);
                    top = (end, at_end.clone());
                }
            }
            if self.now != end {
                self.settle(solver, obstacles, end, (step, steps))?;
            }
            if events.iter().any(|e| !e.is_empty()) {
                solver.restart_path();
            }
        }
        // Reported once, after the step's breaks.
        let out = solver.report(&self.bodies, obstacles, step, steps, out)?;
        if friction {
            solver.commit_friction(&self.bodies, obstacles, step as Real, steps, step);
        }
        self.last = self.stresses(solver);
        let states = self
            .breaking
            .iter()
            .zip(events)
            .map(|(br, breaks)| {
                br.as_ref().map(|br| FractureState {
                    broken: br.broken.clone(),
                    breaks,
                    fallen: Vec::new(),
                })
            })
            .zip(fallen)
            .map(|(state, pieces)| {
                state.map(|mut s| {
                    s.fallen = pieces;
                    s
                })
            })
            .collect();
        Ok((out, states))
    }

    /// The state a structure collapsed in, as [`BreakingEquilibrium`](crate::linkage::fracture::BreakingEquilibrium)
    /// writes it without contact: contact settled at the load the step `reached` (pseudo-time:
    /// its highest break's) on the bodies as they were before the collapse's event (`before`:
    /// its members, each with its modulus factor then), then reported with every member broken
    /// so far, the event's included, broken (no equilibrium: the structure is a mechanism
    /// there). `out` is the step's report to fill; `events` and `fallen` the step's breaks and
    /// pieces that fell off, per body. `None` when contact cannot be settled there.
    fn collapse_state(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        (step, steps): (usize, usize),
        (reached, before): (Real, &[(usize, usize, Real)]),
        out: ContactStep,
        (events, fallen): (&[Vec<BreakEvent>], &mut [Vec<FallenPiece>]),
    ) -> Option<CollapseState> {
        let after: Vec<Real> = before
            .iter()
            .map(|&(b, m, _)| self.bodies[b].modulus_factor(m))
            .collect();
        for &(b, m, factor) in before {
            self.bodies[b].member_factors[m] = factor;
        }
        let saved = solver.converged_state();
        let from = self.now;
        let settled = self.settle(solver, obstacles, reached, (step, steps));
        if settled.is_err() {
            solver.restore(saved);
            self.now = from;
        }
        for (&(b, m, _), &factor) in before.iter().zip(&after) {
            self.bodies[b].member_factors[m] = factor;
        }
        settled.ok()?;
        let report = solver
            .report_at(&self.bodies, obstacles, (reached, steps), step, None, out)
            .ok()?;
        let states = self
            .breaking
            .iter()
            .zip(events)
            .zip(fallen.iter_mut())
            .map(|((br, breaks), pieces)| {
                br.as_ref().map(|br| FractureState {
                    broken: br.broken.clone(),
                    breaks: breaks.clone(),
                    fallen: std::mem::take(pieces),
                })
            })
            .collect();
        Some((report, states))
    }

    /// Settle at pseudo-time `t` after member `m` of body `b` broke; when contact cannot be
    /// settled, remove the pieces of body `b` that fell off (appended to `fallen`) and settle
    /// again. `false` when that cannot be done: the structure's collapse.
    #[allow(clippy::too_many_arguments)]
    fn settle_or_release(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        t: Real,
        steps: (usize, usize),
        b: usize,
        m: usize,
        fallen: &mut Vec<FallenPiece>,
    ) -> Result<bool, FractureStop> {
        let saved = solver.converged_state();
        let from = self.now;
        if self.settle(solver, obstacles, t, steps).is_ok() {
            return Ok(true);
        }
        solver.restore(saved);
        self.now = from;
        let pieces = self.loose_pieces(solver, b);
        if pieces.is_empty() || self.is_collapse(b, &pieces, obstacles) {
            return Ok(false);
        }
        for nodes in &pieces {
            self.remove_nodes(b, nodes);
        }
        if solver.removed.is_empty() {
            solver.removed = self.fallen.clone();
        } else {
            solver.removed[b] = self.fallen[b].clone();
        }
        refit_body(solver, b, &self.bodies[b])?;
        fallen.extend(
            pieces
                .into_iter()
                .map(|nodes| FallenPiece { member: m, nodes }),
        );
        // A failed settle leaves the state it started from (a collapse state starts there).
        let saved = solver.converged_state();
        if self.settle(solver, obstacles, t, steps).is_ok() {
            return Ok(true);
        }
        solver.restore(saved);
        self.now = from;
        Ok(false)
    }

    /// The pieces of body `b` without support (see [`released_pieces`]) none of whose nodes
    /// touches anything in the solver's contact set.
    fn loose_pieces(&self, solver: &ContactSolver, b: usize) -> Vec<Vec<usize>> {
        let body = &self.bodies[b];
        let members: Vec<[usize; 2]> = body.members.iter().map(|x| x.nodes).collect();
        let intact: Vec<bool> = (0..members.len())
            .map(|j| body.modulus_factor(j) > 0.0)
            .collect();
        let dofs = &solver.parts[b].dofs;
        let mut supported = vec![false; body.nodes.len()];
        for &dof in &dofs.supported {
            supported[dof / dofs.dofs_per_node] = true;
        }
        let mut touching = vec![false; body.nodes.len()];
        for c in &solver.active.contacts {
            match c.with {
                Target::Sharp { .. } => {}
                _ if c.body == b => touching[c.node] = true,
                _ => {}
            }
            let (Target::Segment { body: o, .. }
            | Target::Patch { body: o, .. }
            | Target::Vertex { body: o, .. }
            | Target::Edge { body: o, .. }
            | Target::Corner { body: o, .. }) = c.with
            else {
                continue;
            };
            if o == b {
                // Another body presses on this one: both are held together.
                touching.iter_mut().for_each(|t| *t = true);
            }
        }
        released_pieces(
            &members,
            &intact,
            &supported,
            &self.fallen[b],
            dofs.dofs_per_node,
        )
        .into_iter()
        .filter(|piece| !piece.iter().any(|&n| touching[n]))
        .collect()
    }

    /// Whether the loose `pieces` of body `b` are its collapse rather than pieces falling off
    /// (as [`BreakingEquilibrium`](crate::linkage::fracture::BreakingEquilibrium) decides
    /// without contact): a loaded piece still hanging on the rest by intact members (a
    /// mechanism under load), or a loss after which nothing drives the rest (no load left on
    /// it, no support and no obstacle that moves).
    fn is_collapse(&self, b: usize, pieces: &[Vec<usize>], obstacles: &[Obstacle]) -> bool {
        let body = &self.bodies[b];
        let mut released = self.fallen[b].clone();
        for &n in pieces.iter().flatten() {
            released[n] = true;
        }
        let loaded = |n: usize| {
            body.loads
                .iter()
                .any(|l| l.node == n && l.force != Vector3::zeros())
        };
        let hanging = |piece: &[usize]| {
            body.members.iter().enumerate().any(|(j, member)| {
                let [a, c] = member.nodes;
                body.modulus_factor(j) > 0.0
                    && (piece.binary_search(&a).is_ok() && !released[c]
                        || piece.binary_search(&c).is_ok() && !released[a])
            })
        };
        if pieces
            .iter()
            .any(|piece| hanging(piece) && piece.iter().any(|&n| loaded(n)))
        {
            return true;
        }
        let driven = body
            .loads
            .iter()
            .any(|l| !released[l.node] && l.force != Vector3::zeros())
            || body
                .supports
                .iter()
                .any(|s| !released[s.node] && s.displacement != Vector3::zeros())
            || obstacles.iter().any(|o| o.offset(1, 1) != Vector3::zeros());
        !driven
    }

    /// Take `nodes` of body `b` out of the solve: their members carry nothing, their loads are
    /// dropped, and they are held where they were made.
    fn remove_nodes(&mut self, b: usize, nodes: &[usize]) {
        let body = &mut self.bodies[b];
        for &n in nodes {
            self.fallen[b][n] = true;
        }
        if body.member_factors.len() != body.members.len() {
            body.member_factors = vec![1.0; body.members.len()];
        }
        let gone = &self.fallen[b];
        for (j, member) in body.members.iter().enumerate() {
            if member.nodes.iter().any(|&n| gone[n]) {
                body.member_factors[j] = 0.0;
                if let Some(br) = self.breaking[b].as_mut() {
                    br.factor[j] = 0.0;
                }
            }
        }
        body.loads.retain(|l| !gone[l.node]);
        body.supports
            .extend(nodes.iter().map(|&n| Support::fixed(n, [true; 3])));
    }

    /// A settled state below a break at `t_break` (pseudo-time; stresses `after`, the state
    /// just after it) that sent members of `over` past their strength at its load, where,
    /// settled with the body as it is now, every member of `over` is within its strength:
    /// (pseudo-time, stresses). Frictionless contact of linear bodies does not depend on the
    /// path, so settling at a lower load is as good as reaching it by unloading. Tried first
    /// twice as far below `t_break` as the secant from `after` to the step's end (`at_end`)
    /// puts the first crossing, then at `t_lo` (where the last search started), the step's
    /// start and the unloaded state (pseudo-time 0). A settle that fails is retried halfway
    /// to `t_break`. When no state is found the break's own: the member then breaks there, as
    /// [`ContactFracture::critical_load`] does with a bracket that starts beyond the strength.
    #[allow(clippy::too_many_arguments)]
    fn below(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        (step, steps): (usize, usize),
        (t_break, after): (Real, &[Vec<Real>]),
        at_end: &[Vec<Real>],
        t_lo: Real,
        over: &[Vec<bool>],
    ) -> Result<(Real, Vec<Vec<Real>>), FractureStop> {
        let end = step as Real;
        let mut first: Option<Real> = None;
        for (b, br) in self.breaking.iter().enumerate() {
            let Some(br) = br else { continue };
            for (m, limits) in br.limits.iter().enumerate() {
                let Some((tensile, compressive)) = *limits else {
                    continue;
                };
                let (a, z) = (after[b][m], at_end[b][m]);
                if !over[b][m] || (a <= tensile && a >= -compressive) {
                    continue;
                }
                if let Some(f) = critical_fraction(a, z - a, tensile, compressive) {
                    first = Some(first.map_or(f, |g: Real| g.min(f)));
                }
            }
        }
        let mut t = match first {
            Some(f) if end > t_break && f < 0.0 => (t_break + 2.0 * f * (end - t_break)).max(0.0),
            _ if t_lo < t_break => t_lo,
            _ => end - 1.0,
        };
        let mut failures = 0;
        while t < t_break && t >= 0.0 {
            let saved = solver.converged_state();
            let from = self.now;
            if self.settle(solver, obstacles, t, (step, steps)).is_err() {
                solver.restore(saved);
                self.now = from;
                failures += 1;
                if failures > 6 {
                    break;
                }
                t = 0.5 * (t + t_break);
                continue;
            }
            let stress = self.stresses(solver);
            if !self.any_beyond(&stress, over) {
                return Ok((t, stress));
            }
            match [t_lo, end - 1.0, 0.0].into_iter().find(|&lower| lower < t) {
                Some(lower) => t = lower,
                None => break,
            }
        }
        Ok((t_break, after.to_vec()))
    }

    /// The first member of `over` (per body: beyond its strength at the step's load) to reach
    /// its strength between the settled state at pseudo-time `t_lo` (stresses `lo`, those
    /// members within their strength) and the one at `t_hi` (stresses `hi`): (body, member,
    /// pseudo-time), contact settled there; `None` when no member of `over` is beyond its
    /// strength at `t_hi`.
    #[allow(clippy::type_complexity)]
    fn critical_load(
        &mut self,
        solver: &mut ContactSolver,
        obstacles: &[Obstacle],
        (step, steps): (usize, usize),
        (t_lo, lo): (Real, &[Vec<Real>]),
        (t_hi, hi): (Real, &[Vec<Real>]),
        over: &[Vec<bool>],
    ) -> Result<Option<(usize, usize, Real)>, FractureStop> {
        let end = step as Real;
        let (mut t_lo, mut lo) = (t_lo, lo.to_vec());
        let (mut t_hi, mut hi) = (t_hi, hi.to_vec());
        let Some(mut found) = self.first_over(&lo, &hi, over) else {
            return Ok(None);
        };
        for _ in 0..MAX_REFINEMENTS {
            let (b, m, f) = found;
            if f <= 0.0 {
                // Beyond its strength already where the bracket starts.
                self.settle(solver, obstacles, t_lo, (step, steps))?;
                return Ok(Some((b, m, t_lo)));
            }
            let t = t_lo + f.min(1.0) * (t_hi - t_lo);
            self.settle(solver, obstacles, t, (step, steps))?;
            let at = self.stresses(solver);
            match self.first_over(&lo, &at, over) {
                // Someone beyond its strength at t: the crossing is before it.
                Some(next) if !self.at_strength(next.0, next.1, &at) => {
                    (t_hi, hi) = (t, at);
                    found = self.first_over(&lo, &hi, over).unwrap_or(next);
                }
                _ if self.at_strength(b, m, &at) || t_hi - t_lo <= 1e-12 * end.max(1.0) => {
                    return Ok(Some((b, m, t)));
                }
                _ => {
                    (t_lo, lo) = (t, at);
                    match self.first_over(&lo, &hi, over) {
                        Some(next) => found = next,
                        None => {
                            self.settle(solver, obstacles, t_hi, (step, steps))?;
                            return Ok(Some((b, m, t_hi)));
                        }
                    }
                }
            }
        }
        let (b, m, _) = found;
        self.settle(solver, obstacles, t_hi, (step, steps))?;
        Ok(Some((b, m, t_hi)))
    }
}

/// Whether `stress` (Pa) is at `limit` (Pa, positive; infinite: none) to [`AT_STRENGTH`]. A
/// missing strength is never reached: `∞ − s` compared with `AT_STRENGTH · ∞` would be.
fn at_limit(stress: Real, limit: Real) -> bool {
    limit.is_finite() && (stress - limit).abs() <= AT_STRENGTH * limit
}

/// Give the solver body `b`'s supports anew (nodes removed or given back): its DOF map, its
/// stiffness pattern and the coupled system (with conjugate gradients: the body's block
/// preconditioner too).
fn refit_body(solver: &mut ContactSolver, b: usize, body: &Body) -> Result<(), ContactError> {
    let dofs = DofMap::new(body);
    let assembly = StiffnessAssembly::new(body, &dofs).map_err(SolveError::from)?;
    let part = &mut solver.parts[b];
    part.dofs = dofs;
    part.assembly = assembly;
    part.local.clear();
    solver.coupled.rebuild_renumbered(&solver.parts, (b, body))
}
