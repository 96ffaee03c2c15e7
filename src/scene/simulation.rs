//! One load step of a world: every body solved (alone, or all together with their contacts)
//! and the step's result and summary line.

use crate::contact::{
    penetration_tolerance, self_contact_on, ContactFracture, ContactSolver, FractureStop,
    NodeContact, SelfContactWatch,
};
use crate::linkage::fracture::{breaks_members, BreakEvent, FractureState};
use crate::linkage::{Body, BodySolver, NewtonEquilibrium, PhaseTimes, SolveError, StepState};
use crate::scene::arc_length_stops::{arc_length_stops, stop_contacts};
use crate::scene::capacity::CapacityWatch;
use crate::scene::contact_concentration::concentrated_contact_warnings;
use crate::scene::instability::InstabilityWatch;
use crate::scene::results::{
    BodyFracture, BodyResult, BodySize, BreakRecord, Collapse, ContactForce, PairForce, StepResult,
    StepSummary, SummaryBreak,
};
use crate::scene::run_error::RunError;
use crate::scene::strain_warning::large_strain_warning;
use crate::scene::World;
use crate::Real;

/// What solves a world's steps: one solver per body, or one for all bodies and their contacts.
pub enum WorldSolver {
    /// One solver per body, in scene order: linear superposition, or Newton for a nonlinear
    /// body (a scene without contact, or one arc-length body whose Newton holds the scene's
    /// fixed half-spaces as stops).
    Bodies(Vec<BodySolver>),
    /// All bodies solved together with their contacts (a scene with obstacles or `[contact]`).
    Contact(Box<ContactSolver>),
}

/// A world ready to step: each body's stiffness assembled and factored once. The solvers hold
/// what carries from one step to the next (the Newton state, the contact set).
pub struct Simulation<'w> {
    /// The scene being run.
    pub world: &'w World,
    /// The solvers of its bodies.
    pub solver: WorldSolver,
    /// What the instability warnings remember of the previous step.
    watch: InstabilityWatch,
    /// Per body, whether its strains were warned about already ([`large_strain_warning`]).
    strain_warned: Vec<bool>,
    /// The contact pairs (body, other) warned about as carried by one node already.
    concentration_warned: Vec<(String, String)>,
    /// Each breaking body's peak carried load.
    capacity: CapacityWatch,
    /// Breaking members in a scene with contact: the bodies as they break.
    fracture: Option<ContactFracture>,
    /// Per body, in a scene solved body by body, the watch for its self-contact (breaking
    /// bodies with self-contact on); empty once on the contact solver.
    self_watch: Vec<Option<SelfContactWatch>>,
    /// A body's collapse in the step being solved body by body, whose state is known: the
    /// step is written with it and then the collapse returned ([`RunError::Collapse`]).
    collapsed: Option<RunError>,
}

impl<'w> Simulation<'w> {
    /// Assemble and factor every body of `world`.
    pub fn new(world: &'w World) -> Result<Self, RunError> {
        if world.has_contact() {
            let refused = |body: &Body, reason: &str, remedy: &str| RunError::Solve {
                scene: world.source.clone(),
                source: SolveError::BreakingUnsupported {
                    body: body.name.clone(),
                    reason: reason.to_string(),
                    remedy: remedy.to_string(),
                },
            };
            // Breaking bodies in contact: nonlinear ones too (their members' stresses as the
            // results report them), with friction too (see `ContactFracture`), but not along
            // an arc-length path.
            for body in world.bodies.iter().filter(|b| breaks_members(b)) {
                if let crate::linkage::PathMethod::ArcLength { .. } = body.newton.path {
                    return Err(refused(
                        body,
                        "are not followed along an arc-length path (the search for a member's critical load moves the load, which the arc length sets)",
                        "follow the path by its schedules ([bodies.path] method = \"schedules\")",
                    ));
                }
            }
        }
        // One body on an arc-length path against fixed half-spaces: its own Newton with one
        // stop per half-space; any other arc-length scene with contact is refused here.
        let stops = if world.has_contact() {
            arc_length_stops(world)?
        } else {
            None
        };
        let solver = if let Some(stops) = stops {
            let mut newton =
                NewtonEquilibrium::new(&world.bodies[0]).map_err(|source| RunError::Solve {
                    scene: world.source.clone(),
                    source,
                })?;
            newton.set_stops(stops);
            WorldSolver::Bodies(vec![BodySolver::Nonlinear(Box::new(newton))])
        } else if world.has_contact() {
            let contact =
                ContactSolver::new(&world.bodies, &world.obstacles, world.contact.clone())
                    .map_err(|source| RunError::Contact {
                        scene: world.source.clone(),
                        source,
                    })?;
            WorldSolver::Contact(Box::new(contact))
        } else {
            let solvers = world
                .bodies
                .iter()
                .map(BodySolver::new)
                .collect::<Result<Vec<_>, _>>()
                .map_err(|source| RunError::Solve {
                    scene: world.source.clone(),
                    source,
                })?;
            WorldSolver::Bodies(solvers)
        };
        let fracture = if matches!(solver, WorldSolver::Contact(_)) {
            ContactFracture::new(&world.bodies).map_err(|source| RunError::Solve {
                scene: world.source.clone(),
                source,
            })?
        } else {
            None
        };
        let self_watch = if world.has_contact() {
            Vec::new()
        } else {
            self_watches(world)
        };
        Ok(Simulation {
            world,
            solver,
            watch: InstabilityWatch::default(),
            strain_warned: vec![false; world.bodies.len()],
            concentration_warned: Vec::new(),
            capacity: CapacityWatch::default(),
            fracture,
            self_watch,
            collapsed: None,
        })
    }

    /// The contact solver, in a scene with contact.
    pub fn contact(&self) -> Option<&ContactSolver> {
        match &self.solver {
            WorldSolver::Contact(c) => Some(c),
            WorldSolver::Bodies(_) => None,
        }
    }

    /// The result of `step` (0..=steps) and its summary line (without the time). Steps are
    /// meant to come in order; asking for an earlier one starts the nonlinear solvers over.
    ///
    /// A scene solved body by body whose breaking body touches itself at the end of a step
    /// (see [`SelfContactWatch`]) goes on with the contact solver from that step: the steps
    /// before it are solved again with contact (nothing touched in them, so their state is the
    /// same) to bring the contact solver to the step's start, and the step is solved with it.
    pub fn step(&mut self, step: usize) -> Result<(StepResult, StepSummary), RunError> {
        let world = self.world;
        let mut summary = empty_summary(step, world.load_factor(step));
        // Per body its state and, with contact, the nodes pressing on something.
        let (states, contacts) = if matches!(self.solver, WorldSolver::Contact(_)) {
            self.solve_with_contact(step, &mut summary)?
        } else {
            match self.solve_bodies(step, &mut summary)? {
                Ok(states) => {
                    let contacts = self.stop_contacts(step, &mut summary);
                    (states, contacts)
                }
                Err(touch) => {
                    self.switch_to_contact(step)?;
                    summary = empty_summary(step, world.load_factor(step));
                    summary.warnings.push(touch);
                    self.solve_with_contact(step, &mut summary)?
                }
            }
        };
        let mut result = StepResult {
            step,
            load_factor: summary.load_factor,
            time: None,
            bodies: Vec::with_capacity(world.bodies.len()),
        };
        for (k, (body, state)) in world.bodies.iter().zip(&states).enumerate() {
            summary.residual = summary.residual.max(state.residual);
            summary.overloaded += state.overloaded.len();
            summary.max_displacement = state
                .displacements
                .iter()
                .map(|u| u.norm())
                .fold(summary.max_displacement, Real::max);
            let mut written = BodyResult::new(body, state);
            // Numbers that overflow (an absurd material or load) would reach the JSON as null.
            let overflow = written.non_finite().or_else(|| {
                (!summary.max_displacement.is_finite()).then_some("displacement magnitudes")
            });
            if let Some(quantity) = overflow {
                return Err(RunError::Solve {
                    scene: world.source.clone(),
                    source: SolveError::Overflow {
                        body: body.name.clone(),
                        quantity,
                    },
                });
            }
            if let Some(contacts) = contacts.get(k) {
                written.contacts = contact_forces(body, contacts);
            }
            if let Some(fracture) = &state.fracture {
                *summary.broken.get_or_insert(0) += fracture.broken.len();
                summary.warnings.extend(fallen_warnings(body, fracture));
                written.fracture = Some(self.body_fracture(fracture, step));
            }
            result.bodies.push(written);
        }
        // The state a structure collapsed in has no equilibrium (its broken members' load is
        // on): its out-of-balance is not a solve that stopped short.
        if self.collapsed.is_none() {
            summary
                .warnings
                .extend(residual_warnings(&world.bodies, step, &states));
        }
        let failed = self.capacity.warnings(&world.bodies, step, &states);
        summary.warnings.extend(failed);
        let warnings = self
            .watch
            .warnings(&world.bodies, step, &states, &summary.contact_forces);
        summary.warnings.extend(warnings);
        summary
            .warnings
            .extend(self.slip_warnings(step, &states, &contacts));
        if let Some(RunError::Collapse {
            collapse, breaks, ..
        }) = self.collapsed.take()
        {
            // The state the structure collapsed in: written as the run's last step, flagged.
            summary.collapse = true;
            for b in &mut result.bodies {
                if b.name == collapse.body {
                    if let Some(f) = b.fracture.as_mut() {
                        f.collapse = true;
                    }
                }
            }
            return Err(RunError::Collapse {
                collapse,
                breaks,
                written: Some(Box::new((result, summary))),
            });
        }
        Ok((result, summary))
    }

    /// The warnings of `step` about what a user may not have meant, each once per run (from
    /// step 0 again when the run starts over): a linear body strained past a few percent
    /// ([`large_strain_warning`]), and at the last step a contact carried by one node
    /// ([`concentrated_contact_warnings`]: at the full load; while a press starts, one node
    /// touching first is no concern).
    fn slip_warnings(
        &mut self,
        step: usize,
        states: &[StepState],
        contacts: &[Vec<NodeContact>],
    ) -> Vec<String> {
        let world = self.world;
        if step == 0 {
            self.strain_warned = vec![false; world.bodies.len()];
            self.concentration_warned.clear();
        }
        let mut out = Vec::new();
        for (k, (body, state)) in world.bodies.iter().zip(states).enumerate() {
            if let Some(warned) = self.strain_warned.get_mut(k).filter(|w| !**w) {
                if let Some(w) = large_strain_warning(body, step, state) {
                    *warned = true;
                    out.push(w);
                }
            }
            let Some(touching) = contacts
                .get(k)
                .filter(|c| step == world.steps && !c.is_empty())
            else {
                continue;
            };
            let positions: Vec<nalgebra::Vector3<Real>> = body
                .nodes
                .iter()
                .zip(&state.displacements)
                .map(|(x, u)| x + u)
                .collect();
            out.extend(concentrated_contact_warnings(
                body,
                step,
                &positions,
                touching,
                &mut self.concentration_warned,
            ));
        }
        out
    }

    /// Solve `step` with the contact solver (breaking members event by event when a body
    /// breaks): per body its state and its contacts; the step's counts go into `summary`.
    #[allow(clippy::type_complexity)]
    fn solve_with_contact(
        &mut self,
        step: usize,
        summary: &mut StepSummary,
    ) -> Result<(Vec<StepState>, Vec<Vec<NodeContact>>), RunError> {
        let world = self.world;
        let WorldSolver::Contact(contact) = &mut self.solver else {
            return Ok((Vec::new(), Vec::new()));
        };
        let contact_error = |source| RunError::Contact {
            scene: world.source.clone(),
            source,
        };
        let mut collapsed = None;
        let (solved, fractures) = match self.fracture.as_mut() {
            None => (
                contact
                    .solve_step(&world.bodies, &world.obstacles, step, world.steps)
                    .map_err(contact_error)?,
                Vec::new(),
            ),
            Some(fr) => match fr.solve_step(contact, &world.obstacles, step, world.steps) {
                Ok(solved) => solved,
                Err(FractureStop::Contact(e)) => return Err(contact_error(e)),
                Err(FractureStop::Collapse {
                    body,
                    member,
                    breaks,
                    state,
                }) => {
                    let name = &world.bodies[body].name;
                    // With its state known, the step is written with it, as a body solved on
                    // its own writes it (see `Simulation::step`).
                    match state {
                        Some(state) => {
                            collapsed = Some((name, member, breaks));
                            *state
                        }
                        None => return Err(self.collapse(name, step, member, &breaks)),
                    }
                }
            },
        };
        let mut solved = solved;
        for (state, f) in solved.states.iter_mut().zip(fractures) {
            state.fracture = f;
        }
        summary.iterations = solved.newton_iterations;
        summary.cuts = solved.cuts;
        summary.negative_pivots = solved.negative_pivots;
        // Conjugate gradients count no pivots: the stability of a nonlinear body solved by
        // them is unknown (a linear one's stiffness is positive definite).
        summary.pivots_unknown = (0..world.bodies.len())
            .filter(|&b| {
                world.bodies[b].is_nonlinear()
                    && contact.solver_used(b) != crate::linkage::SolverUsed::Direct
            })
            .count();
        summary.linear_iterations = solved.linear_iterations;
        summary.contact_iterations = solved.contact_iterations;
        summary.sticking = solved.sticking;
        summary.slipping = solved.slipping;
        summary.max_penetration = solved.max_penetration;
        summary.warnings.append(&mut solved.warnings);
        for (body, totals) in world.bodies.iter().zip(&solved.totals) {
            let d = body.dimension.dofs_per_node();
            for (with, force) in totals {
                summary.contact_forces.push(PairForce {
                    body: body.name.clone(),
                    with: with.clone(),
                    force: force.as_slice()[..d].to_vec(),
                });
            }
        }
        if let Some((name, member, breaks)) = collapsed {
            self.collapsed = Some(self.collapse(name, step, member, &breaks));
        }
        Ok((solved.states, solved.contacts))
    }

    /// Solve `step` body by body: per body its state (`Ok`), or, when a breaking body touches
    /// itself at the end of the step, `Err` with the warning that says so (nothing kept).
    #[allow(clippy::type_complexity)]
    fn solve_bodies(
        &mut self,
        step: usize,
        summary: &mut StepSummary,
    ) -> Result<Result<Vec<StepState>, String>, RunError> {
        let world = self.world;
        let WorldSolver::Bodies(solvers) = &mut self.solver else {
            return Ok(Ok(Vec::new()));
        };
        let mut states = Vec::with_capacity(solvers.len());
        let mut collapsed = None;
        for (body, solver) in world.bodies.iter().zip(solvers.iter_mut()) {
            let state = match solver.solve_step(body, step, world.steps) {
                Ok(state) => state,
                Err(SolveError::Collapse {
                    body,
                    step,
                    member,
                    breaks,
                    state,
                }) => {
                    // With its state known, the step is written with it (the other bodies
                    // solved too); the first collapse is the run's.
                    match state {
                        Some(state) if collapsed.is_none() => {
                            collapsed = Some((body, step, member, breaks));
                            *state
                        }
                        _ => return Err(self.collapse(&body, step, member, &breaks)),
                    }
                }
                Err(source) => {
                    return Err(RunError::Solve {
                        scene: world.source.clone(),
                        source,
                    })
                }
            };
            add_newton_counts(summary, &state);
            states.push(state);
        }
        if let Some((body, step, member, breaks)) = collapsed {
            self.collapsed = Some(self.collapse(&body, step, member, &breaks));
            return Ok(Ok(states));
        }
        for (b, state) in states.iter().enumerate() {
            let Some(watch) = self.self_watch.get_mut(b).and_then(Option::as_mut) else {
                continue;
            };
            let body = &world.bodies[b];
            if step == 0 && watch.checked > 0 {
                // A run started over: the watch starts at rest too.
                *watch = SelfContactWatch::new(body).map_err(|source| RunError::Contact {
                    scene: world.source.clone(),
                    source,
                })?;
            }
            let d = body.dimension.dofs_per_node();
            let u: Vec<Real> = state
                .displacements
                .iter()
                .flat_map(|v| v.iter().take(d).copied().collect::<Vec<_>>())
                .collect();
            let Some(fracture) = &state.fracture else {
                continue;
            };
            let tension = |m: usize| match &solvers[b] {
                BodySolver::Breaking(eq) => eq.broke_in_tension(m),
                BodySolver::LargeBreaking(eq) => eq.broke_in_tension(m),
                _ => false,
            };
            let fallen = fracture.fallen.iter().flat_map(|p| p.nodes.iter().copied());
            if let Some(touch) = watch.check(&u, &fracture.broken, tension, fallen) {
                return Ok(Err(format!(
                    "body '{}' touches itself at step {step} (node {}: {}): the scene is solved with contact from this step on (steps 0 to {} solved again with it)",
                    body.name,
                    touch.node + 1,
                    touch.what,
                    step.saturating_sub(1)
                )));
            }
        }
        Ok(Ok(states))
    }

    /// Per body of a world solved body by body, what its stops (fixed half-spaces of an
    /// arc-length body, see [`arc_length_stops`]) do at the step just solved, as a contact
    /// step reports it: per body its pressed nodes; each stop's total force and the deepest
    /// node's depth go into `summary`. Empty without stops.
    fn stop_contacts(&self, step: usize, summary: &mut StepSummary) -> Vec<Vec<NodeContact>> {
        let WorldSolver::Bodies(solvers) = &self.solver else {
            return Vec::new();
        };
        let mut out = Vec::with_capacity(solvers.len());
        for (body, solver) in self.world.bodies.iter().zip(solvers) {
            let BodySolver::Nonlinear(newton) = solver else {
                out.push(Vec::new());
                continue;
            };
            let (contacts, totals) = stop_contacts(body, newton.stops(), newton.displacement());
            let d = body.dimension.dofs_per_node();
            for (with, force) in totals {
                summary.contact_forces.push(PairForce {
                    body: body.name.clone(),
                    with,
                    force: force.as_slice()[..d].to_vec(),
                });
            }
            summary.max_penetration = contacts
                .iter()
                .map(|c| c.depth)
                .fold(summary.max_penetration, Real::max);
            // Frictionless: every contact slips; one deeper than the contact tolerance warns
            // as the contact solver's does.
            summary.slipping += contacts.len();
            let tolerance = self
                .world
                .contact
                .tolerance
                .unwrap_or_else(|| penetration_tolerance(body));
            for c in contacts.iter().filter(|c| c.depth > tolerance) {
                summary.warnings.push(format!(
                    "step {step}: node {} of body '{}' is {:.3e} m inside '{}' (tolerance {tolerance:.3e} m): raise [contact] penalty",
                    c.node + 1,
                    body.name,
                    c.depth,
                    c.with
                ));
            }
            out.push(contacts);
        }
        out
    }

    /// Put the world on the contact solver and bring it to the start of `step`: steps 0 to
    /// `step − 1` solved again with contact (their results are those already written).
    fn switch_to_contact(&mut self, step: usize) -> Result<(), RunError> {
        let world = self.world;
        let contact = ContactSolver::new(&world.bodies, &world.obstacles, world.contact.clone())
            .map_err(|source| RunError::Contact {
                scene: world.source.clone(),
                source,
            })?;
        self.solver = WorldSolver::Contact(Box::new(contact));
        self.fracture = ContactFracture::new(&world.bodies).map_err(|source| RunError::Solve {
            scene: world.source.clone(),
            source,
        })?;
        self.self_watch.clear();
        for s in 0..step {
            let mut replay = empty_summary(s, world.load_factor(s));
            self.solve_with_contact(s, &mut replay)?;
        }
        Ok(())
    }

    /// The collapse of body `body` at `step` by breaking `member` (0-based), `breaks` the
    /// body's breaks of the step.
    fn collapse(&self, body: &str, step: usize, member: usize, breaks: &[BreakEvent]) -> RunError {
        let records = self.break_records(breaks, step);
        RunError::Collapse {
            collapse: Collapse {
                step,
                body: body.to_string(),
                load_factor: records.last().map_or(0.0, |r| r.load_factor),
                member: member + 1,
            },
            breaks: records
                .iter()
                .map(|r| SummaryBreak {
                    step,
                    body: body.to_string(),
                    member: r.member,
                    load_factor: r.load_factor,
                    tooth: r.tooth,
                    time: None,
                })
                .collect(),
            written: None,
        }
    }

    /// The written form of breaks of `step`: 1-based members, the step's fractions of its
    /// load increment turned into load factors.
    fn break_records(&self, breaks: &[BreakEvent], step: usize) -> Vec<BreakRecord> {
        let (from, to) = (
            self.world.load_factor(step.saturating_sub(1)),
            self.world.load_factor(step),
        );
        breaks
            .iter()
            .map(|b| BreakRecord {
                member: b.member + 1,
                load_factor: from + b.fraction * (to - from),
                tooth: b.tooth,
                time: None,
            })
            .collect()
    }

    fn body_fracture(&self, fracture: &FractureState, step: usize) -> BodyFracture {
        let mut fallen: Vec<usize> = fracture
            .fallen
            .iter()
            .flat_map(|p| p.nodes.iter().map(|n| n + 1))
            .collect();
        fallen.sort_unstable();
        BodyFracture {
            broken: fracture.broken.iter().map(|m| m + 1).collect(),
            breaks: self.break_records(&fracture.breaks, step),
            fallen,
            collapse: false,
        }
    }

    /// Model sizes for the summary.
    pub fn sizes(&self) -> Vec<BodySize> {
        self.world
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let (free_dofs, solver) = match &self.solver {
                    WorldSolver::Contact(c) => (c.free_dofs(i), c.solver_used(i).to_string()),
                    WorldSolver::Bodies(solvers) => {
                        solvers.get(i).map_or((0, String::new()), |s| {
                            (s.free_dofs(), s.solver_used().to_string())
                        })
                    }
                };
                BodySize {
                    name: b.name.clone(),
                    dimension: b.dimension.dofs_per_node(),
                    nodes: b.nodes.len(),
                    members: b.members.len(),
                    patches: b.patches.len(),
                    free_dofs,
                    solver,
                }
            })
            .collect()
    }

    /// Time spent so far in each phase, s, summed over the bodies, and in contact queries.
    pub(crate) fn times(&self) -> (PhaseTimes, Real) {
        match &self.solver {
            WorldSolver::Contact(c) => (c.times, c.query_seconds),
            WorldSolver::Bodies(solvers) => {
                let mut sum = PhaseTimes::default();
                for s in solvers {
                    let t = s.times();
                    sum.assembly += t.assembly;
                    sum.symbolic += t.symbolic;
                    sum.numeric += t.numeric;
                    sum.solve += t.solve;
                }
                (sum, 0.0)
            }
        }
    }
}

/// Per body of a world solved body by body, the watch for its self-contact: breaking bodies
/// with self-contact on (see [`self_contact_on`]) whose surface is one the contact detection
/// takes (pressures too: the contact solver takes them, following ones included).
fn self_watches(world: &World) -> Vec<Option<SelfContactWatch>> {
    world
        .bodies
        .iter()
        .map(|body| {
            if !(breaks_members(body) && self_contact_on(body, world.contact.self_contact)) {
                return None;
            }
            // A surface the contact detection refuses (patches that disagree) would refuse the
            // contact solver too: such a body is solved as before, without the watch.
            SelfContactWatch::new(body).ok()
        })
        .collect()
}

/// A step's relative residual above this is worth a warning: four orders of magnitude above
/// the default Newton tolerance (1e-10), where a linear breaking body's solve already counts
/// as inaccurate.
pub const RESIDUAL_WARNING: Real = 1e-6;

/// One warning per body whose solved state leaves an out-of-balance force above
/// [`RESIDUAL_WARNING`] of the force it is measured against (in a contact scene the run's
/// largest so far, so a body whose forces vanish does not alarm for nothing).
fn residual_warnings(bodies: &[Body], step: usize, states: &[StepState]) -> Vec<String> {
    bodies
        .iter()
        .zip(states)
        .filter(|(_, s)| s.residual > RESIDUAL_WARNING)
        .map(|(body, s)| {
            format!(
                "step {step}: body '{}': the out-of-balance force is {:.2e} of the force it is measured against{}: the state is not in equilibrium to the accuracy asked for; look for a warning above on why the solve stopped short, or try more steps",
                body.name,
                s.residual,
                if s.force_scale > 0.0 {
                    format!(
                        " ({:.3e} N: the largest of the step's forces and of the run's so far)",
                        s.force_scale
                    )
                } else {
                    String::new()
                }
            )
        })
        .collect()
}

/// The summary line of `step` before anything is solved.
pub(crate) fn empty_summary(step: usize, load_factor: Real) -> StepSummary {
    StepSummary {
        step,
        load_factor,
        iterations: 0,
        cuts: 0,
        negative_pivots: 0,
        pivots_unknown: 0,
        residuals: Vec::new(),
        contact_iterations: 0,
        sticking: 0,
        slipping: 0,
        linear_iterations: 0,
        residual: 0.0,
        max_displacement: 0.0,
        overloaded: 0,
        max_penetration: 0.0,
        seconds: 0.0,
        warnings: Vec::new(),
        contact_forces: Vec::new(),
        broken: None,
        peak_stress: None,
        stress_ratio: None,
        dynamics: None,
        collapse: false,
    }
}

/// One warning per piece that fell off: its size, its first nodes and the break that released it.
fn fallen_warnings(body: &Body, fracture: &FractureState) -> Vec<String> {
    fracture
        .fallen
        .iter()
        .map(|p| {
            let shown: Vec<String> = p.nodes.iter().take(8).map(|n| (n + 1).to_string()).collect();
            let more = if p.nodes.len() > 8 { ", …" } else { "" };
            format!(
                "body '{}': breaking member {} left a piece of {} node(s) ({}{more}) without support: it fell off and was removed from the solve",
                body.name,
                p.member + 1,
                p.nodes.len(),
                shown.join(", ")
            )
        })
        .collect()
}

/// Fold one body's Newton counts into the step's line: iterations (largest, with that body's
/// residual history), cuts, conjugate-gradient iterations and negative pivots (summed), and
/// the load factor when the body's path (arc length) decides it.
fn add_newton_counts(summary: &mut StepSummary, state: &StepState) {
    if state.iterations > summary.iterations {
        summary.residuals = state.residual_history.clone();
    }
    summary.iterations = summary.iterations.max(state.iterations);
    summary.cuts += state.cuts;
    summary.linear_iterations += state.linear_iterations;
    summary.negative_pivots += state.negative_pivots;
    summary.pivots_unknown += usize::from(state.pivots_unknown);
    if let Some(lambda) = state.load_factor {
        summary.load_factor = lambda;
    }
}

/// The written form of a body's contacts: 1-based nodes, one force component per dimension.
pub(crate) fn contact_forces(body: &Body, contacts: &[NodeContact]) -> Vec<ContactForce> {
    let d = body.dimension.dofs_per_node();
    contacts
        .iter()
        .map(|c| ContactForce {
            node: c.node + 1,
            with: c.with.clone(),
            depth: c.depth,
            force: c.force.as_slice()[..d].to_vec(),
            normal: c.normal.as_slice()[..d].to_vec(),
            normal_force: c.normal_force,
            tangential_force: c.tangential_force.as_slice()[..d].to_vec(),
            state: c.state.name().to_string(),
            slip: c.slip.as_slice()[..d].to_vec(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::Dimension;

    /// A residual of 1.2e-3 of the run's largest force warns, naming the body, the value and
    /// the scale; one at the Newton tolerance does not.
    #[test]
    fn a_residual_warns_only_when_really_large() {
        let bodies = [Body::new("block", Dimension::Three)];
        let state = |residual: Real| StepState {
            residual,
            force_scale: 2.5e4,
            ..Default::default()
        };
        assert!(residual_warnings(&bodies, 9, &[state(1e-10)]).is_empty());
        assert!(residual_warnings(&bodies, 9, &[state(RESIDUAL_WARNING)]).is_empty());
        let w = residual_warnings(&bodies, 9, &[state(1.2e-3)]);
        assert_eq!(w.len(), 1);
        assert!(
            w[0].starts_with("step 9: body 'block': the out-of-balance force is 1.20e-3")
                && w[0].contains("2.500e4 N"),
            "{}",
            w[0]
        );
    }
}
