//! The settle loop of one load step (solve → find contacts → penalties, until the contact set and equilibrium settle) and the coupled Newton of all bodies.

use crate::contact::body_part::BodyPart;
use crate::contact::condensed::CondensedSolver;
use crate::contact::coupled::CoupledSolver;
use crate::contact::coupled_iterative::CoupledIterative;
use crate::contact::detect::{candidate_nodes, Geometry};
use crate::contact::increments::Converged;
use crate::contact::pressing::{flip_warning, FLIP_WITHIN};
use crate::contact::problem::{
    interrupted, newton_limits, round_off_residual, Problem, FORCE_FLOOR,
};
use crate::contact::report::{finish, ContactStep};
use crate::contact::start::{no_start_overlap, one_dimension};
use crate::contact::{
    default_penalty, penetration_tolerance, ActiveContact, ContactError, ContactSet,
    ContactSettings, FrictionHistory, Obstacle, Penalty, Target,
};
use crate::linkage::body_state::{loads_at, prescribed_at};
use crate::linkage::dynamics::InertiaTerm;
use crate::linkage::{
    Body, DofMap, Mechanism, PathMethod, PhaseTimes, SolveError, SolverUsed, StiffnessAssembly,
};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::time::Instant;

/// All the bodies of a scene with contact, solved together step by step.
///
/// Within one contact iteration the set of active contacts is fixed and Newton solves all the
/// bodies together: out-of-balance `r = F + f_c(u) − f_int(u)`, tangent `K_T(u) + K_c(u)` with
/// each active contact adding its penalty stiffness `k n nᵀ` (implicit penalty). Then every
/// node is projected on the obstacles: the nodes inside one form the next set (a node of the
/// set that came out, pulled by its penalty, leaves it). The step has settled when the set
/// found is the set solved. A set seen before (the contact flips back and forth) has settled
/// when the set solved is within a penetration tolerance of the set found (see
/// `contact::pressing`); where only obstacle contacts come and go it is settled again keeping
/// the obstacle contacts of the set solved that still press (depth > 0 along their normal),
/// and if it flips even so, the loop goes back to the set solved when it first flipped, with a
/// warning naming the nodes. Other flips, and running out of contact iterations, keep the last
/// set solved with a warning. When every body is linear, the Newton runs
/// on the contact candidates instead ([`CondensedSolver`]).
pub struct ContactSolver {
    pub(crate) parts: Vec<BodyPart>,
    pub(crate) geometry: Geometry,
    pub(crate) coupled: CoupledSolver,
    /// Every body linear: each factored once per run and condensed on its contact candidates
    /// (`None`: the coupled solve).
    pub(crate) condensed: Option<CondensedSolver>,
    /// A body found to move inside itself (beyond rigid motions) when it was condensed: named
    /// if no contact holds it either.
    pub(crate) mechanism: Option<Box<Mechanism>>,
    pub(crate) settings: ContactSettings,
    /// Friction of the pairs and its history at the last converged state (`None`: every
    /// pair frictionless).
    pub(crate) friction: Option<FrictionHistory>,
    /// The contact set of the last solved step (the next step starts from it).
    pub(crate) active: ContactSet,
    /// The last normal seen per contact (used when a node lies exactly on the surface).
    pub(crate) normals: HashMap<ActiveContact, Vector3<Real>>,
    /// The step the displacements belong to.
    pub(crate) step: usize,
    /// Time steps solved ([`ContactSolver::solve_time_step`]; messages name them).
    pub(crate) time_steps: usize,
    /// The pseudo-time of the last time step solved (step units; 0 before the first).
    pub(crate) time_at: Real,
    /// Largest nodal move of a stabilised iteration, m: the smallest mean member length.
    pub(crate) move_cap: Real,
    /// The last converged states (pseudo-time, displacements per body), newest last, at most
    /// [`PATH_POINTS`]: an increment on the coupled path starts from their extrapolation.
    pub(crate) path: Vec<(Real, Vec<Vec<Real>>)>,
    /// Conjugate-gradient iterations before the step being solved.
    pub(crate) linear_before: usize,
    /// Time spent so far in each phase, s.
    pub times: PhaseTimes,
    /// Time spent so far finding contacts (projecting nodes on obstacles), s.
    pub query_seconds: Real,
    /// Per body, its nodes removed from the solve (a piece that fell off: held in place,
    /// touching nothing); empty when none is.
    pub(crate) removed: Vec<Vec<bool>>,
    /// The largest force scale a step of the run reported so far, N: the floor of the next
    /// steps' residuals, so a body whose forces vanish (split, unloaded) is not measured
    /// against round-off.
    pub(crate) largest_force_scale: Real,
    /// The largest coordinate of a node, m (see [`round_off_residual`]).
    pub(crate) extent: Real,
}

impl ContactSolver {
    /// Validate the bodies, build their patterns and the rapier colliders of the obstacles,
    /// and analyze the coupled pattern once.
    pub fn new(
        bodies: &[Body],
        obstacles: &[Obstacle],
        settings: ContactSettings,
    ) -> Result<Self, ContactError> {
        ContactSolver::build(bodies, obstacles, settings)
    }

    /// [`ContactSolver::new`] with the settings as given (a dynamic world's too). A body needs
    /// no supports: its inertia or its contacts may hold it.
    pub(crate) fn build(
        bodies: &[Body],
        obstacles: &[Obstacle],
        settings: ContactSettings,
    ) -> Result<Self, ContactError> {
        let t = Instant::now();
        one_dimension(bodies)?;
        let mut parts = Vec::with_capacity(bodies.len());
        let mut node_offsets = Vec::with_capacity(bodies.len());
        let mut nodes = 0;
        for body in bodies {
            // Inertia or the contacts may hold a body without supports (where nothing does,
            // the settle loop names the motions left free).
            body.validate_touching().map_err(SolveError::from)?;
            if let PathMethod::ArcLength { .. } = body.newton.path {
                return Err(ContactError::ArcLength {
                    body: body.name.clone(),
                    reason: "the contact solver advances by load control, while the arc length scales the body's loads by a factor it finds".to_string(),
                    remedy: "use the default load schedules; a contact step that Newton cannot solve at once is crossed in halved increments (see [bodies.newton] max_cuts)".to_string(),
                });
            }
            let dofs = DofMap::new(body);
            let assembly = StiffnessAssembly::new(body, &dofs).map_err(SolveError::from)?;
            parts.push(BodyPart {
                u: vec![0.0; body.dof_count()],
                penalty: Penalty {
                    stiffness: settings.penalty.unwrap_or_else(|| default_penalty(body)),
                },
                tolerance: settings
                    .tolerance
                    .unwrap_or_else(|| penetration_tolerance(body)),
                local: Vec::new(),
                dofs,
                assembly,
            });
            node_offsets.push(nodes);
            nodes += body.nodes.len();
        }
        let mut times = PhaseTimes {
            assembly: t.elapsed().as_secs_f64(),
            ..Default::default()
        };
        let geometry = Geometry::new(bodies, obstacles, settings.self_contact)?;
        no_start_overlap(bodies, &parts, &geometry)?;
        let mut condensed = None;
        let mut mechanism = None;
        let iterative = {
            let dofs: Vec<&DofMap> = parts.iter().map(|p| &p.dofs).collect();
            let assemblies: Vec<&StiffnessAssembly> = parts.iter().map(|p| &p.assembly).collect();
            CoupledIterative::new(bodies, &dofs, &assemblies)
        };
        // Condensing needs a factorization of every body: not for one solved iteratively.
        // Nor for a body whose members break: a break changes the compliance condensed.
        if settings.condense
            && iterative.is_none()
            && bodies
                .iter()
                .all(|b| !b.is_nonlinear() && !crate::linkage::fracture::breaks_members(b))
        {
            // Obstacle offsets along their travel, sampled (a candidate missed is added later).
            let travels: Vec<Vec<Vector3<Real>>> = obstacles
                .iter()
                .map(|o| (0..=32).map(|s| o.offset(s, 32)).collect())
                .collect();
            let marks = candidate_nodes(bodies, &geometry, &travels);
            (condensed, mechanism) = CondensedSolver::build(bodies, &parts, marks, &mut times);
        }
        let t = Instant::now();
        let coupled = CoupledSolver::new(&parts, node_offsets, condensed.is_none(), iterative)?;
        times.symbolic += t.elapsed().as_secs_f64();
        let friction = settings.friction.any().then(|| {
            let names: Vec<&str> = obstacles
                .iter()
                .map(|o| o.name.as_str())
                .chain(bodies.iter().map(|b| b.name.as_str()))
                .collect();
            let laws = bodies
                .iter()
                .map(|b| {
                    names
                        .iter()
                        .map(|other| settings.friction.law(&b.name, other))
                        .collect()
                })
                .collect();
            let dofs: Vec<usize> = bodies.iter().map(|b| b.dof_count()).collect();
            FrictionHistory::new(
                laws,
                obstacles.len(),
                &dofs,
                vec![Vector3::zeros(); obstacles.len()],
            )
        });
        Ok(ContactSolver {
            friction,
            move_cap: bodies
                .iter()
                .filter(|b| !b.members.is_empty())
                .map(|b| 10.0 * penetration_tolerance(b))
                .fold(Real::INFINITY, Real::min),
            parts,
            geometry,
            coupled,
            condensed,
            mechanism,
            settings,
            active: ContactSet::default(),
            normals: HashMap::new(),
            step: 0,
            time_steps: 0,
            time_at: 0.0,
            path: vec![(
                0.0,
                bodies.iter().map(|b| vec![0.0; b.dof_count()]).collect(),
            )],
            linear_before: 0,
            times,
            query_seconds: 0.0,
            removed: Vec::new(),
            largest_force_scale: 0.0,
            extent: bodies
                .iter()
                .flat_map(|b| &b.nodes)
                .map(|x| x.amax())
                .fold(0.0, Real::max),
        })
    }

    /// Whether the bodies are solved condensed on their contact candidates (every body linear,
    /// each factored once per run), rather than as one coupled system.
    pub fn is_condensed(&self) -> bool {
        self.condensed.is_some()
    }

    /// Contact candidates of `body` on the condensed path (nodes; `None` on the coupled path).
    pub fn candidate_nodes(&self, body: usize) -> Option<usize> {
        self.condensed.as_ref()?.candidates(body)
    }

    /// The smallest force scale a residual is measured against, N: `FORCE_FLOOR` times the
    /// smallest penalty times the smallest tolerance (a force of the order of a member's
    /// `E A`). Where nothing is loaded (step 0, a node touching a surface at a depth of
    /// round-off) the residual is then round-off over a real force, not round-off over round-off.
    pub(crate) fn force_floor(&self) -> Real {
        let k = self
            .parts
            .iter()
            .map(|p| p.penalty.stiffness)
            .fold(Real::INFINITY, Real::min);
        let tolerance = self
            .parts
            .iter()
            .map(|p| p.tolerance)
            .fold(Real::INFINITY, Real::min);
        let floor = FORCE_FLOOR * k * tolerance;
        if floor.is_finite() {
            floor
        } else {
            0.0
        }
    }

    /// The out-of-balance the coordinates' round-off leaves in the penalties of `set`, N:
    /// a Newton stalled below it has converged (see [`round_off_residual`]).
    pub(crate) fn round_off(&self, set: &ContactSet) -> Real {
        let penalty = self
            .parts
            .iter()
            .map(|p| p.penalty.stiffness)
            .fold(0.0, Real::max);
        round_off_residual(self.extent, penalty, set.len())
    }

    /// Rows of the coupled system of all bodies (their free DOFs).
    pub fn free_dofs(&self, body: usize) -> usize {
        self.parts.get(body).map_or(0, |p| p.assembly.n)
    }

    /// The linear solver `body`'s rows get: "iterative" (conjugate gradients on the coupled
    /// tangent, multigrid on the body's block) or "direct".
    pub fn solver_used(&self, body: usize) -> SolverUsed {
        self.coupled.solver_used(body)
    }

    /// The penalty stiffness used for `body`, N/m.
    pub fn penalty(&self, body: usize) -> Real {
        self.parts.get(body).map_or(0.0, |p| p.penalty.stiffness)
    }

    /// The contacts of `found` after keeping patches against `solved`, timed as a query; with
    /// the contacts `kept` too (see [`Geometry::query_keeping`]).
    pub(crate) fn look(
        &mut self,
        bodies: &[Body],
        solved: &ContactSet,
        offsets: &[Vector3<Real>],
        kept: &[ActiveContact],
    ) -> ContactSet {
        let t = Instant::now();
        let mut found = self
            .geometry
            .query_keeping(bodies, &self.parts, offsets, kept);
        if !self.removed.is_empty() {
            let removed = &self.removed;
            found.contacts.retain(|c| {
                matches!(c.with, Target::Sharp { .. })
                    || !removed.get(c.body).is_some_and(|r| r[c.node])
            });
        }
        let found = self
            .geometry
            .keep_patches(bodies, &self.parts, solved, found);
        self.query_seconds += t.elapsed().as_secs_f64();
        found
    }

    /// The settle loop at pseudo-time `t` of `steps` (the end of an increment of step `step`,
    /// which messages name), from the current displacements and contact set `self.active`:
    /// loads, prescribed displacements and obstacles at `t`. Leaves the settled set in
    /// `self.active` and returns the counts and warnings (the states are reported by
    /// [`ContactSolver::report`]).
    pub(crate) fn settle(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        (t, steps): (Real, usize),
        step: usize,
        inertia: Option<&[InertiaTerm]>,
    ) -> Result<ContactStep, ContactError> {
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset_at(t, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, t, steps)).collect();
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            let prescribed = prescribed_at(body, t, steps);
            for &dof in &part.dofs.supported {
                part.u[dof] = prescribed[dof];
            }
        }
        let mut set = self.active.clone();
        let mut seen: Vec<ContactSet> = Vec::new();
        let mut out = ContactStep::default();
        let mut refinements = 0;
        // Once the set flipped: the state and set solved then (a contact of the set solved
        // stays while it still presses from there on).
        let mut first_flip: Option<(Converged, ContactSet)> = None;
        loop {
            let pressing = first_flip.is_some();
            if interrupted(bodies) {
                return Err(ContactError::Interrupted { step });
            }
            out.contact_iterations += 1;
            let (iterations, settled) =
                self.newton(bodies, &set, (&forces, &offsets), (t, steps), step, inertia)?;
            out.newton_iterations += iterations;
            out.stabilised |= !settled;
            // Once the set flipped, the contacts of the set solved that still press stay.
            let mut kept = Vec::new();
            if pressing {
                kept = self.still_pressing(bodies, &set, (&forces, &offsets), (t, steps), step);
            }
            let mut found = self.look(bodies, &set, &offsets, &kept);
            if settled && found == set && self.condensed.is_some() {
                // Settled on the candidates: solve for every node, and look again with them.
                let differs = self.expand_condensed();
                if pressing {
                    kept = self.still_pressing(bodies, &set, (&forces, &offsets), (t, steps), step);
                }
                found = self.look(bodies, &set, &offsets, &kept);
                // The placement was off by the compliance's round-off (a penalty turns 1e-13 m
                // into forces the tolerance sees): above a tenth of the tolerance, Newton again
                // from the solve, which returns at once when the residual there is within it.
                if found == set && differs > 1e-11 && refinements < 3 {
                    refinements += 1;
                    continue;
                }
            }
            if !settled {
                // A stabilised move toward the contacts: look again, no equilibrium yet.
                if out.contact_iterations >= self.settings.max_iterations {
                    if let Some(m) = self.mechanism.take() {
                        return Err(ContactError::Mechanism { step, mechanism: m });
                    }
                    // A body touching surfaces that leave it free to move along them: say
                    // which motions are free (and whether its loads push it along one).
                    if let Some(free) =
                        self.free_body(bodies, &found, (&forces, &offsets), (t, steps), step, false)
                    {
                        return Err(free);
                    }
                    return Err(ContactError::Unsupported {
                        step,
                        body: bodies
                            .get(self.coupled.unheld)
                            .map_or_else(String::new, |b| b.name.clone()),
                        iterations: out.contact_iterations,
                        contacts: found.len(),
                    });
                }
                set = found;
                continue;
            }
            if found == set {
                break;
            }
            if seen.contains(&found) {
                // Within the tolerance (no node inside beyond it without its force, no contact
                // pulling beyond it), the set solved has settled.
                let gap = self.flip_gap(
                    bodies,
                    (&set, &found),
                    (&forces, &offsets),
                    (t, steps),
                    step,
                );
                if gap <= FLIP_WITHIN {
                    break;
                }
                if let Some((saved, solved)) = first_flip.take() {
                    // It flips even so: back to the set solved when it first flipped, said.
                    out.warnings
                        .push(flip_warning(bodies, step, (&set, &found), gap, None));
                    self.restore_flip(saved)?;
                    set = solved;
                    break;
                }
                // The set flips back and forth: nodes that come in without a force go out
                // with one (a rim node under a flush plate's edge, pushed out sideways from
                // under it by its own force). When only obstacle contacts come and go, settle
                // again keeping the obstacle contacts of the set solved that still press (depth
                // > 0 along their normal); other flips keep the last set solved, said.
                let (joined, left) = found.difference(&set);
                if !joined
                    .iter()
                    .chain(&left)
                    .all(|c| matches!(c.with, Target::Obstacle(_)))
                {
                    out.warnings.push(format!(
                        "step {step}: the contact set flips back and forth ({} contacts come in and {} go out between iterations, {gap:.2} penetration tolerances from settled): kept the last set solved; use more steps or a larger [contact] penalty",
                        joined.len(),
                        left.len()
                    ));
                    break;
                }
                let kept = self.still_pressing(bodies, &set, (&forces, &offsets), (t, steps), step);
                let kept = self.look(bodies, &set, &offsets, &kept);
                if kept == set {
                    break;
                }
                first_flip = Some((self.converged_state(), set.clone()));
                seen.clear();
                seen.push(set);
                set = kept;
                continue;
            }
            if out.contact_iterations >= self.settings.max_iterations {
                if let Some((saved, solved)) = first_flip.take() {
                    let iterations = self.settings.max_iterations;
                    out.warnings.push(flip_warning(
                        bodies,
                        step,
                        (&set, &found),
                        0.0,
                        Some(iterations),
                    ));
                    self.restore_flip(saved)?;
                    set = solved;
                    break;
                }
                out.warnings.push(format!(
                    "step {step}: the contact set did not settle in {} contact iterations: kept the last set solved; use more steps",
                    self.settings.max_iterations
                ));
                break;
            }
            seen.push(set);
            set = found;
        }
        // A body without supports that its contacts leave free to move (the condensed path
        // settles it where its loads balance along the free motions): named, not solved.
        self.active = set;
        self.expand_condensed();
        if inertia.is_none() {
            let set = &self.active;
            if let Some(free) =
                self.free_body(bodies, set, (&forces, &offsets), (t, steps), step, true)
            {
                return Err(free);
            }
        }
        Ok(out)
    }

    /// The report of the settled end of `step` of `steps` (states, contacts, totals) into
    /// `out`, from the current displacements and contact set.
    pub(crate) fn report(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
        out: ContactStep,
    ) -> Result<ContactStep, ContactError> {
        self.report_at(bodies, obstacles, (step as Real, steps), step, None, out)
    }

    /// The report of the settled state at pseudo-time `t` of `steps` (named `step` in
    /// messages) into `out`, with the bodies' `inertia` in their balance (a time step) or
    /// without (`None`: a load step).
    pub(crate) fn report_at(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        (t, steps): (Real, usize),
        step: usize,
        inertia: Option<&[InertiaTerm]>,
        mut out: ContactStep,
    ) -> Result<ContactStep, ContactError> {
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset_at(t, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, t, steps)).collect();
        let (tolerance, max_iterations) = newton_limits(bodies);
        let problem = Problem {
            bodies,
            geometry: &self.geometry,
            set: &self.active,
            forces: &forces,
            time: (t, steps),
            offsets: &offsets,
            step,
            tolerance,
            max_iterations,
            move_cap: self.move_cap,
            // The run's largest force scale so far (none at step 0: a run starts over).
            force_floor: self.force_floor().max(if step == 0 {
                0.0
            } else {
                self.largest_force_scale
            }),
            round_off: self.round_off(&self.active),
            friction: self.friction.as_ref(),
            inertia,
        };
        let evaluated = problem.evaluate(&mut self.normals, &self.parts);
        out.negative_pivots = self.coupled.negative_pivots;
        out.linear_iterations = self.coupled.linear_iterations() - self.linear_before;
        let out = finish(&problem, &self.parts, evaluated, out)?;
        self.largest_force_scale = out
            .states
            .iter()
            .map(|s| s.force_scale)
            .fold(problem.force_floor, Real::max);
        Ok(out)
    }

    /// The full displacements of the condensed bodies (see [`CondensedSolver::expand`]; 0 on
    /// the coupled path).
    fn expand_condensed(&mut self) -> Real {
        match self.condensed.as_mut() {
            Some(c) => c.expand(&mut self.parts, &mut self.times),
            None => 0.0,
        }
    }

    /// Newton on all bodies with the contact set fixed (loads `forces` and obstacles at
    /// `offsets`, following pressures at pseudo-time `time`): condensed on the candidates while
    /// every body can be, else coupled. Returns the iterations and whether it converged; `false`
    /// after one stabilised move (the tangent is singular with this set: a body held only by
    /// contact that has not reached its contacts yet), so that the contacts are looked for
    /// again.
    fn newton(
        &mut self,
        bodies: &[Body],
        set: &ContactSet,
        (forces, offsets): (&[Vec<Real>], &[Vector3<Real>]),
        time: (Real, usize),
        step: usize,
        inertia: Option<&[InertiaTerm]>,
    ) -> Result<(usize, bool), ContactError> {
        let (tolerance, max_iterations) = newton_limits(bodies);
        let problem = Problem {
            bodies,
            geometry: &self.geometry,
            set,
            forces,
            time,
            offsets,
            step,
            tolerance,
            max_iterations,
            move_cap: self.move_cap,
            force_floor: self.force_floor(),
            round_off: self.round_off(set),
            friction: self.friction.as_ref(),
            inertia,
        };
        if let Some(condensed) = self.condensed.as_mut() {
            let done = condensed.newton(
                &problem,
                &mut self.parts,
                &mut self.normals,
                &mut self.times,
            )?;
            if let Some(done) = done {
                return Ok(done);
            }
            // Leave the condensed path: the coupled solve from the full displacements (not
            // `leave_condensed`: `problem` borrows the geometry).
            self.condensed = None;
            let t = Instant::now();
            self.coupled.rebuild(&self.parts)?;
            self.times.symbolic += t.elapsed().as_secs_f64();
        }
        self.coupled.newton(
            &problem,
            &mut self.parts,
            &mut self.normals,
            &mut self.times,
        )
    }
}
