//! The time steps of a dynamic world with contact: every body's integrator gives its inertia
//! term ([`StepForm`]), the contact solver solves all bodies and their contacts at once
//! ([`ContactSolver::solve_time_step_within`]), and each body's motion is finished from the
//! solved configuration. The energy bookkeeping of contact (penalty energy, friction's
//! dissipation, the work of moving obstacles) is here too.
//!
//! # Time on the contact solver
//!
//! The contact solver reads loads, prescribed displacements and obstacle offsets at a
//! pseudo-time in load-step units ([`crate::linkage::body_state::factor_at`]); a dynamic scene
//! gives its factors in time ([`time_factor`]). The solver gets copies of the bodies and
//! obstacles whose schedules are sampled at `N + 1` equally spaced times (`N` a multiple of
//! every schedule's intervals, so the piecewise linear factors are reproduced exactly), and
//! time `t` is pseudo-time `1 + N t / duration`.
//!
//! # What each integrator does with contact
//!
//! The contact solver evaluates the member forces at the configuration `y` of the
//! integrator's step form (`y = b u_{n+1} + (1 − b) u_n`). For Newmark, generalized-α and
//! backward Euler that is their own form. For the energy–momentum method (`b = ½`) the member
//! forces at the midpoint equal the discrete gradient for bodies with small displacements
//! (linear members): energy is then conserved to the Newton tolerance while the contact set
//! does not change within a step, exactly against planes (see `src/contact/time_step.rs`); a
//! body with large displacements gets the midpoint rule's forces (not exactly conservative).
//! Mass-proportional damping enters the inertia term (`(c + α c_v) M`); stiffness-proportional
//! damping is not supported with contact (the scene is refused).
//!
//! # Breaking members
//!
//! A world with breaking bodies solves each clock step through
//! [`BreakingBodies::solve_trial_step`](crate::scene::BreakingBodies::solve_trial_step) with
//! [`ContactTrialSteps`]: every trial sub-step of the event search is a [`DynamicContact::solve`]
//! from the state [`DynamicContact::save`] took at the step's start (or the event's), put back
//! by [`DynamicContact::restore`] before the next trial. [`DynamicContact::solve`] copies the
//! broken members' modulus factors into the solver's bodies first. The contract and the energy
//! bookkeeping are in `src/scene/dynamic_fracture.rs`.

use crate::contact::{
    penetration_tolerance, ContactError, ContactSolver, NodeContact, Obstacle, TimeStepState,
};
use crate::linkage::dynamics::{
    time_factor, BodyMotion, InertiaTerm, Integrator, TimeStepFailure, TimeStepReport,
};
use crate::linkage::{Body, PhaseTimes, Schedule};
use crate::scene::dynamic_fracture::TrialSteps;
use crate::scene::results::{BodyResult, PairForce, StepSummary};
use crate::scene::run_error::RunError;
use crate::scene::simulation::contact_forces;
use crate::scene::World;
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

/// The most samples of a schedule in time the contact solver gets (a scene whose schedules'
/// intervals have no common multiple below it is sampled this finely, linear in between).
const MAX_SAMPLES: usize = 10_000;

/// One solved time step of all bodies with contact.
#[derive(Clone, Debug, Default)]
pub struct ContactTimeStep {
    /// Per body, what its step reports (Newton iterations, work, dissipation).
    pub reports: Vec<TimeStepReport>,
    /// Contact iterations of the step.
    pub contact_iterations: usize,
    /// Largest penetration at the step's solution, m.
    pub max_penetration: Real,
    /// Warnings of the contact solver.
    pub warnings: Vec<String>,
}

/// The contact solver of a dynamic world, with what carries between time steps.
pub struct DynamicContact {
    solver: ContactSolver,
    /// The world's bodies and obstacles with their schedules sampled in pseudo-time.
    bodies: Vec<Body>,
    obstacles: Vec<Obstacle>,
    /// Intervals of the sampling: time `t` is pseudo-time `1 + samples · t / duration`.
    samples: usize,
    duration: Real,
    /// The deepest a node may end a time step inside what it touches, m (1 % of the mean
    /// member length of the body with the shortest, or twice the last step's deepest if
    /// more), unless the step is already the smallest.
    deepest: Real,
    /// The largest penetration of the last time step solved, m.
    last_depth: Real,
    /// Per body, the contacts of the last time step solved (at its configuration `y`).
    pub contacts: Vec<Vec<NodeContact>>,
    /// Per body, the total contact force per obstacle or body touched, at the last step.
    pub totals: Vec<Vec<(String, Vector3<Real>)>>,
    /// Sticking and slipping contacts at the last step.
    pub sticking: usize,
    /// See `sticking`.
    pub slipping: usize,
    /// Penalty energy `Σ ½ k d²` of the contacts at the end of the last step, J.
    pub penalty_energy: Real,
}

impl DynamicContact {
    /// The contact solver of the dynamic `world` (obstacles or `[contact]`).
    pub fn new(world: &World, duration: Real) -> Result<Self, RunError> {
        let samples = sample_count(world);
        let sampled = |s: &Schedule| sample(s, samples, duration);
        let mut bodies = world.bodies.clone();
        for b in &mut bodies {
            for l in &mut b.loads {
                l.schedule = sampled(&l.schedule);
            }
            for s in &mut b.supports {
                s.schedule = sampled(&s.schedule);
            }
        }
        let mut obstacles = world.obstacles.clone();
        for o in &mut obstacles {
            o.schedule = sampled(&o.schedule);
        }
        let mut solver = ContactSolver::dynamic(&bodies, &obstacles, world.contact.clone())
            .map_err(|source| RunError::Contact {
                scene: world.source.clone(),
                source,
            })?;
        solver.start_time_steps_at(1.0);
        let deepest = bodies
            .iter()
            .map(penetration_tolerance)
            .filter(|t| *t > 0.0)
            .fold(Real::INFINITY, Real::min);
        Ok(DynamicContact {
            solver,
            contacts: vec![Vec::new(); bodies.len()],
            totals: vec![Vec::new(); bodies.len()],
            bodies,
            obstacles,
            samples,
            duration,
            deepest,
            last_depth: 0.0,
            sticking: 0,
            slipping: 0,
            penalty_energy: 0.0,
        })
    }

    /// Pseudo-time of the contact solver at time `t`, step units.
    fn at(&self, t: Real) -> Real {
        1.0 + self.samples as Real * (t / self.duration)
    }

    /// Solve the time step from `t0` of length `h` (s) for every body and their contacts.
    /// With `may_cut`, a step that leaves a node deeper than 1 % of a member inside what it
    /// touches fails (the driver halves it). On failure nothing changes and the reason is
    /// returned (body 0 is named: the bodies are solved together).
    pub fn solve(
        &mut self,
        motions: &mut [BodyMotion],
        world_bodies: &[Body],
        integrator: &dyn Integrator,
        (t0, h, may_cut): (Real, Real, bool),
    ) -> Result<ContactTimeStep, (usize, TimeStepFailure)> {
        let duration = self.duration;
        // Members broken so far (modulus factor 0) reach the bodies the contact solver
        // assembles; nothing else of a body changes in time.
        // A kept factor of the tangent is then stale: it is dropped.
        let mut changed = false;
        for (mine, given) in self.bodies.iter_mut().zip(world_bodies) {
            if mine.member_factors != given.member_factors {
                mine.member_factors.clone_from(&given.member_factors);
                changed = true;
            }
        }
        if changed {
            self.solver.forget_kept_factor();
        }
        let forms: Vec<_> = motions
            .iter()
            .map(|m| integrator.form(&m.motion, &m.mass, h))
            .collect();
        let b = forms.first().map_or(1.0, |f| f.blend);
        // Mass-proportional damping α M v_eval, v_eval = c_v (y − p_v), joins c M (y − p).
        // (The velocity predictor is relative to u_n; the inertia predictor is absolute.)
        let inertia: Vec<InertiaTerm> = forms
            .iter()
            .zip(motions.iter())
            .map(|(f, m)| {
                let alpha = m.damping.mass * f.velocity_coefficient;
                let c = f.inertia.coefficient;
                InertiaTerm {
                    mass: f.inertia.mass.clone(),
                    coefficient: c + alpha,
                    predictor: f
                        .inertia
                        .predictor
                        .iter()
                        .zip(&f.velocity_predictor)
                        .zip(&m.motion.u)
                        .map(|((p, q), u)| (c * p + alpha * (u + q)) / (c + alpha))
                        .collect(),
                }
            })
            .collect();
        let te = t0 + b * h;
        let at = self.at(te);
        let steps = self.samples + 1;
        // A crossing within the step shows as a node far deeper than the step before left
        // any: cut when deeper than the limit and twice the last step's deepest (a contact
        // pressed slowly deeper by a soft penalty is warned about, not cut).
        let deepest = may_cut.then_some(self.deepest.max(2.0 * self.last_depth));
        let solved = self
            .solver
            .solve_time_step_within(
                &self.bodies,
                &self.obstacles,
                (at, steps),
                &inertia,
                deepest,
            )
            .map_err(|e: ContactError| {
                (
                    0,
                    TimeStepFailure {
                        reason: e.to_string(),
                        history: Vec::new(),
                    },
                )
            })?;
        let mut out = ContactTimeStep {
            contact_iterations: solved.contact_iterations,
            max_penetration: solved.max_penetration,
            warnings: solved.warnings.clone(),
            ..Default::default()
        };
        // Obstacle moves over the step, m.
        let moved: HashMap<&str, Vector3<Real>> = self
            .obstacles
            .iter()
            .zip(&motion_of_obstacles(
                &self.obstacles,
                self.at(t0),
                self.at(t0 + h),
                steps,
            ))
            .map(|(o, d)| (o.name.as_str(), *d))
            .collect();
        let mut penalty = 0.0;
        for (k, ((m, body), form)) in motions.iter_mut().zip(world_bodies).zip(&forms).enumerate() {
            let d = body.dimension.dofs_per_node();
            let state = &solved.states[k];
            let start = m.motion.u.clone();
            // Δu = u_{n+1} − u_n from y = u_n + b Δu.
            let mut du = vec![0.0; start.len()];
            for (node, y) in state.displacements.iter().enumerate() {
                for q in 0..d {
                    let i = node * d + q;
                    du[i] = (y[q] - start[i]) / b;
                }
            }
            let applied = crate::linkage::dynamics::loads_at_time(body, te, duration);
            let mut report = TimeStepReport {
                iterations: state.iterations.max(solved.newton_iterations),
                residual_history: state.residual_history.clone(),
                ..Default::default()
            };
            report.external_work = applied.iter().zip(&du).map(|(f, x)| f * x).sum();
            for (node, r) in &state.reactions {
                for q in 0..d {
                    report.external_work += r[q] * du[node * d + q];
                }
            }
            // Mass damping's work, α M v_eval · Δu.
            if m.damping.mass != 0.0 {
                for (i, x) in du.iter().enumerate() {
                    // y − u_n = b Δu; the velocity predictor is relative to u_n.
                    let v = form.velocity_coefficient * (b * x - form.velocity_predictor[i]);
                    report.dissipated += m.damping.mass * m.mass[i] * v * x;
                }
            }
            for c in &solved.contacts[k] {
                let at_node = |q: usize| du[c.node * d + q];
                let node_move =
                    Vector3::new(at_node(0), at_node(1), if d > 2 { at_node(2) } else { 0.0 });
                if let Some(o) = moved.get(c.with.as_str()) {
                    // The moving obstacle's work on the body: the force it gives times its move.
                    report.external_work += c.force.dot(o);
                }
                if c.depth > 0.0 {
                    // Friction: −f_T · Δs = μ f_N |Δs| while slipping, per contact. (Not the
                    // difference of the node's summed slips: a node that presses and also
                    // receives another contact's reaction sums both into one entry.)
                    report.dissipated += c.friction_dissipated;
                    // The penalty energy at the step's end: the depth at y carried to u_{n+1}
                    // along the normal (exact for a plane; the other body's move is not
                    // followed), ½ k d² with k = f_N / d.
                    let target = moved.get(c.with.as_str()).map_or(Vector3::zeros(), |o| *o);
                    let end = c.depth - c.normal.dot(&((node_move - target) * (1.0 - b)));
                    if end > 0.0 {
                        penalty += 0.5 * c.normal_force / c.depth * end * end;
                    }
                }
            }
            m.motion = integrator.finish(&m.motion, du, h);
            out.reports.push(report);
        }
        self.last_depth = out.max_penetration;
        self.penalty_energy = penalty;
        self.contacts = solved.contacts;
        self.totals = solved.totals;
        self.sticking = solved.sticking;
        self.slipping = solved.slipping;
        Ok(out)
    }
}

/// What a time step changes in a [`DynamicContact`]: the contact solver's state
/// ([`TimeStepState`]) and the bookkeeping carried to the next step (the last depth, the contacts and forces reported, the penalty energy).
#[derive(Clone)]
pub struct DynamicContactState {
    solver: TimeStepState,
    last_depth: Real,
    contacts: Vec<Vec<NodeContact>>,
    totals: Vec<Vec<(String, Vector3<Real>)>>,
    sticking: usize,
    slipping: usize,
    penalty_energy: Real,
}

impl DynamicContact {
    /// The state the next time step starts from.
    pub fn save(&self) -> DynamicContactState {
        DynamicContactState {
            solver: self.solver.time_step_state(),
            last_depth: self.last_depth,
            contacts: self.contacts.clone(),
            totals: self.totals.clone(),
            sticking: self.sticking,
            slipping: self.slipping,
            penalty_energy: self.penalty_energy,
        }
    }

    /// Go back to a state saved by [`DynamicContact::save`]: the time steps solved since are
    /// undone.
    pub fn restore(&mut self, saved: DynamicContactState) {
        self.solver.restore_time_step_state(saved.solver);
        self.last_depth = saved.last_depth;
        self.contacts = saved.contacts;
        self.totals = saved.totals;
        self.sticking = saved.sticking;
        self.slipping = saved.slipping;
        self.penalty_energy = saved.penalty_energy;
    }
}

/// The contact time steps of one clock step as the event search of breaking members takes
/// them ([`TrialSteps`]): each sub-step solved by [`DynamicContact::solve`], its contact counts
/// recorded in the frame's summary line; a sub-step undone takes back its largest penetration
/// (its contact iterations stay counted: they were done).
pub struct ContactTrialSteps<'a> {
    /// The contact solver.
    pub contact: &'a mut DynamicContact,
    /// The bodies' integrator.
    pub integrator: &'a dyn Integrator,
    /// Whether a step too deep may fail (to be halved): not at the smallest step.
    pub may_cut: bool,
    /// The summary line of the frame the step belongs to.
    pub summary: &'a mut StepSummary,
}

impl TrialSteps for ContactTrialSteps<'_> {
    type Saved = (DynamicContactState, Real);
    const OTHER_FORCES: bool = true;

    fn solve(
        &mut self,
        motions: &mut [BodyMotion],
        bodies: &[Body],
        t0: Real,
        h: Real,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
        self.contact
            .solve(motions, bodies, self.integrator, (t0, h, self.may_cut))
            .map(|s| s.record(self.summary))
    }

    fn save(&self) -> Self::Saved {
        (self.contact.save(), self.summary.max_penetration)
    }

    fn restore(&mut self, (contact, penetration): Self::Saved) {
        self.contact.restore(contact);
        self.summary.max_penetration = penetration;
    }
}

/// The most contact warnings one stored state's summary line keeps.
const MAX_WARNINGS: usize = 5;

impl ContactTimeStep {
    /// Add the step's contact counts to the summary line of the frame it belongs to
    /// (contact iterations summed, the largest penetration, the first warnings) and give the
    /// bodies' reports.
    pub fn record(self, summary: &mut StepSummary) -> Vec<TimeStepReport> {
        summary.contact_iterations += self.contact_iterations;
        summary.max_penetration = summary.max_penetration.max(self.max_penetration);
        for w in self.warnings {
            if summary.warnings.len() < MAX_WARNINGS && !summary.warnings.contains(&w) {
                summary.warnings.push(w);
            }
        }
        self.reports
    }
}

impl DynamicContact {
    /// Time the contact solver spent in each phase so far, s.
    pub fn times(&self) -> PhaseTimes {
        self.solver.times
    }

    /// Time the contact solver spent finding contacts so far, s.
    pub fn query_seconds(&self) -> Real {
        self.solver.query_seconds
    }

    /// Body `k`'s contacts at the last time step into its written result.
    pub fn write_contacts(&self, k: usize, body: &Body, written: &mut BodyResult) {
        if let Some(c) = self.contacts.get(k) {
            written.contacts = contact_forces(body, c);
        }
    }

    /// The contact forces per pair and the stick/slip counts of the last time step into the
    /// frame's summary line.
    pub fn summarize(&self, bodies: &[Body], summary: &mut StepSummary) {
        summary.sticking = self.sticking;
        summary.slipping = self.slipping;
        for (body, totals) in bodies.iter().zip(&self.totals) {
            let d = body.dimension.dofs_per_node();
            for (with, force) in totals {
                summary.contact_forces.push(PairForce {
                    body: body.name.clone(),
                    with: with.clone(),
                    force: force.as_slice()[..d].to_vec(),
                });
            }
        }
    }
}

/// Each obstacle's move from pseudo-time `a` to `b` of `steps`, m.
fn motion_of_obstacles(
    obstacles: &[Obstacle],
    a: Real,
    b: Real,
    steps: usize,
) -> Vec<Vector3<Real>> {
    obstacles
        .iter()
        .map(|o| o.offset_at(b, steps) - o.offset_at(a, steps))
        .collect()
}

/// Intervals of the sampling of the world's schedules in time: the least common multiple of
/// their intervals (a schedule of `n` factors has `n − 1`), at most [`MAX_SAMPLES`].
fn sample_count(world: &World) -> usize {
    let intervals = world
        .bodies
        .iter()
        .flat_map(|b| {
            b.loads
                .iter()
                .map(|l| &l.schedule)
                .chain(b.supports.iter().map(|s| &s.schedule))
        })
        .chain(world.obstacles.iter().map(|o| &o.schedule))
        .filter_map(|s| match s {
            Schedule::Factors(f) if f.len() > 2 => Some(f.len() - 1),
            _ => None,
        });
    let mut n = 1usize;
    for k in intervals {
        n = n / gcd(n, k) * k;
        if n > MAX_SAMPLES {
            return MAX_SAMPLES;
        }
    }
    n
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// `schedule` (factors in time over `duration`) as the contact solver reads it: factors at
/// pseudo-times `1..=samples + 1` (time `k · duration / samples` at pseudo-time `k + 1`).
fn sample(schedule: &Schedule, samples: usize, duration: Real) -> Schedule {
    Schedule::Factors(
        (0..=samples)
            .map(|k| time_factor(schedule, duration * k as Real / samples as Real, duration))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::body_state::factor_at;

    #[test]
    fn sampled_schedules_give_the_factors_in_time_at_the_mapped_pseudo_time() {
        let duration = 0.3;
        for s in [
            Schedule::Linear,
            Schedule::Factors(vec![1.0]),
            Schedule::Factors(vec![0.0, 1.0, 0.5]),
        ] {
            let samples = 6;
            let sampled = sample(&s, samples, duration);
            for i in 0..=60 {
                let t = duration * i as Real / 60.0;
                let at = 1.0 + samples as Real * t / duration;
                let there = factor_at(&sampled, at, samples + 1);
                // Piecewise linear on a superset of the breakpoints: exact to round-off.
                assert!(
                    (there - time_factor(&s, t, duration)).abs() < 1e-14,
                    "{s:?} at {t}: {there}"
                );
            }
        }
    }
}
