//! Members that break in time (issue 31 item 5): a time step in which a breaking member
//! reaches its strength is cut at the event.
//!
//! After a time step from `t` to `t + h` is solved, the stress of every intact breaking member
//! (its axial force over its area, tension positive, at the step's end configuration) is
//! compared with its strength. When some member is beyond it, the event time is found within
//! the step: the step is solved again from `t` (every motion restored) with the length `θ h`,
//! `θ` from the secant of each member's stress between the bracket's ends
//! ([`critical_fraction`]), the bracket narrowed (Illinois: a side kept twice in a row moves
//! the next guess halfway to the middle), until the first member is at its strength to
//! [`AT_STRENGTH`] (relative) with no member beyond it by more, or the bracket is narrower than
//! [`EVENT_TIME`] of the step. There every member at its strength breaks in one event (so
//! symmetric members break together): its modulus factor becomes 0 ([`Body::member_factors`]),
//! its strain energy at the event goes to the step's `dissipated` (fracture), the kept factor
//! of a linear body is dropped, and Newmark's and generalized-α's acceleration is rebalanced
//! on the weakened body. The rest of the step, `(1 − θ) h`, is then solved from the event state
//! the same way (it may break more members). The sub-steps' lengths add up to `h`, so the
//! clock's ticks are unchanged.
//!
//! Nothing is removed from the solve: a piece cut loose keeps its lumped mass, which holds it
//! in the step's `c M + K` tangent, so it flies on with its momentum and falls under gravity.
//! A break changes no velocity, so the momenta of the pieces are those of the body at the
//! event; with the energy-momentum integrator the energy balance
//! `kinetic + strain − work + dissipated` holds to the Newton tolerance through the break.
//!
//! A sub-step that cannot be solved restores every motion and every member broken in the step
//! and returns the failure: the clock halves the whole step as for any failed step.
//!
//! # With contact
//!
//! The search asks only for "solve the step from the saved state over a given length", and for
//! a solver that keeps state between steps, for a way to save and restore it ([`TrialSteps`],
//! [`BreakingBodies::solve_trial_step`]). The contact time step
//! (`ContactTrialSteps` in `src/scene/dynamic_contact.rs`) saves with the motions everything a
//! time step changes in the contact solver: the displacements the next step starts from, the
//! contact set and its normals, friction's committed history (stick anchors and slips, so a
//! retried sub-step slips from the same anchors and dissipates `μ f_N |Δslip|` once), the step
//! count and pseudo-time, the penalty energy of the energy bookkeeping.
//! Each trial sub-step of the search starts from that state; the state at the bracket's end is
//! saved with the motions there. So the sub-steps that make up a step are exactly the time
//! steps of lengths `θ h, (1 − θ) h` of the contact solver, and a step in which nothing breaks
//! is the contact step itself, bit for bit.
//!
//! The contact solver assembles its own copies of the bodies: the modulus factors of the broken
//! members are copied to them before every sub-step, and when they change the factor of the
//! tangent kept from the last time step is dropped (`ContactSolver::forget_kept_factor`), so
//! nothing stale survives a break. A break changes no position: the contacts at the event are those
//! of the intact body, and a piece cut loose keeps its mass and its contacts (it may rest on,
//! slide along or fly off what it touches). With contact, Newmark's and generalized-α's
//! acceleration is not rebalanced on loads and members alone (that would drop the contact
//! forces at the event) but shifted by the member forces lost: `a ← a + M⁻¹ (f_int,before(u)
//! − f_int,after(u))` at the free DOFs, which for Newmark (balanced at the step's end) is the
//! balance of the weakened body with its contact forces.
//!
//! Energy: the break removes the broken members' strain energy at the event from `strain` and
//! adds it to `dissipated` (the penalty energy is unchanged: no position moves), so the
//! balance `kinetic + strain + contact − work + dissipated` is that of the contact steps
//! before and after, which `energy_momentum` keeps exactly against planes while the contact
//! set holds within a step (see `src/contact/time_step.rs`).

use crate::linkage::body_state::{internal_forces, member_response_at};
use crate::linkage::dynamics::{
    strain_energy, BodyMotion, Motion, TimeStepFailure, TimeStepReport,
};
use crate::linkage::fracture::{breaks_members, critical_fraction, member_limits, MemberLimits};
use crate::linkage::{Body, SolveError};
use crate::Real;

/// A member is at its strength when its stress is within this fraction of it: the time step's
/// Newton tolerance (1e-10 relative) leaves the stresses accurate to about this.
pub const AT_STRENGTH: Real = 1e-8;

/// The event search stops when its bracket is narrower than this fraction of the step.
pub const EVENT_TIME: Real = 1e-12;

/// Trial sub-steps allowed to find one event.
const MAX_REFINEMENTS: usize = 60;

/// One break in time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimedBreak {
    /// The member, 0-based.
    pub member: usize,
    /// When it reached its strength, s.
    pub time: Real,
}

/// The breaking members of a dynamic scene's bodies, and their own copies of the bodies (with
/// the broken members' modulus factors at 0).
pub struct BreakingBodies {
    /// The bodies as they are now, in scene order.
    pub bodies: Vec<Body>,
    /// Per body per member its tensile and compressive strengths (Pa), `None` when it does not
    /// break.
    limits: Vec<MemberLimits>,
    /// Per body the members broken so far, in order.
    pub broken: Vec<Vec<usize>>,
    /// Per body the breaks not yet taken by [`BreakingBodies::take_breaks`].
    pending: Vec<Vec<TimedBreak>>,
}

/// The solve of one time step of all bodies from `t0` over `h` (s): on success every motion is
/// at `t0 + h`; on failure every motion is unchanged.
pub type StepSolve<'a> = dyn FnMut(
        &mut [BodyMotion],
        &[Body],
        Real,
        Real,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)>
    + 'a;

/// What the event search needs of a time step's solve that keeps its own state between steps
/// (the contact solver: its contact set, friction history, penalty energy): the solve, and a
/// way to save that state and put it back, so a trial sub-step that was solved can be undone.
pub trait TrialSteps {
    /// The solver's state besides the motions.
    type Saved: Clone;
    /// Whether forces act that the bodies alone do not give (contact): a break then shifts
    /// Newmark's and generalized-α's acceleration by the member forces lost, `Δa = M⁻¹ Δf_int`,
    /// instead of rebalancing it on the loads and members alone.
    const OTHER_FORCES: bool;
    /// Solve one (sub-)step of all bodies from `t0` over `h` (s) from the motions' state: on
    /// success every motion is at `t0 + h`; on failure the motions and the solver's state are
    /// as before the call.
    fn solve(
        &mut self,
        motions: &mut [BodyMotion],
        bodies: &[Body],
        t0: Real,
        h: Real,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)>;
    /// The solver's state now.
    fn save(&self) -> Self::Saved;
    /// Put the solver back in a saved state.
    fn restore(&mut self, saved: Self::Saved);
}

/// A closure ([`StepSolve`]) that keeps nothing between steps, as [`TrialSteps`].
struct Stateless<'s, 'a>(&'s mut StepSolve<'a>);

impl TrialSteps for Stateless<'_, '_> {
    type Saved = ();
    const OTHER_FORCES: bool = false;
    fn solve(
        &mut self,
        motions: &mut [BodyMotion],
        bodies: &[Body],
        t0: Real,
        h: Real,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
        (self.0)(motions, bodies, t0, h)
    }
    fn save(&self) {}
    fn restore(&mut self, _: ()) {}
}

impl BreakingBodies {
    /// The breaking members of `bodies`, or `None` when no member breaks. Softening members
    /// are not followed in time: an error says so.
    pub fn new(bodies: &[Body]) -> Result<Option<Self>, SolveError> {
        if !bodies.iter().any(breaks_members) {
            return Ok(None);
        }
        for body in bodies {
            if let Some(m) = body.materials.iter().find(|m| m.softening.is_some()) {
                return Err(SolveError::BreakingUnsupported {
                    body: body.name.clone(),
                    reason: format!(
                        "that soften (material '{}') are not followed in time yet",
                        m.name
                    ),
                    remedy: "remove its softening (it then breaks at its strength), or remove [dynamics]"
                        .to_string(),
                });
            }
        }
        Ok(Some(BreakingBodies {
            bodies: bodies.to_vec(),
            limits: bodies.iter().map(member_limits).collect(),
            broken: vec![Vec::new(); bodies.len()],
            pending: vec![Vec::new(); bodies.len()],
        }))
    }

    /// The breaks since the last call, per body.
    pub fn take_breaks(&mut self) -> Vec<Vec<TimedBreak>> {
        self.pending.iter_mut().map(std::mem::take).collect()
    }

    /// Per body per member its stress (Pa) over its strength in that sense at the motions'
    /// displacements: `σ/f_t` in tension, `−σ/f_c` in compression; 0 for a member that is
    /// broken or does not break. Also the stresses themselves.
    fn stresses(&self, motions: &[BodyMotion]) -> Vec<Vec<Real>> {
        self.bodies
            .iter()
            .zip(motions)
            .zip(&self.limits)
            .map(|((body, m), limits)| {
                limits
                    .iter()
                    .enumerate()
                    .map(|(j, l)| match l {
                        Some(_) if body.modulus_factor(j) > 0.0 => {
                            member_response_at(body, &m.motion.u, j).force
                                / body.materials[body.members[j].material].area
                        }
                        _ => 0.0,
                    })
                    .collect()
            })
            .collect()
    }

    /// The largest ratio of stress to strength over the intact breaking members.
    fn worst(&self, stress: &[Vec<Real>]) -> Real {
        let mut worst: Real = 0.0;
        for (s, limits) in stress.iter().zip(&self.limits) {
            for (s, l) in s.iter().zip(limits) {
                if let Some((ft, fc)) = l {
                    worst = worst.max(ratio(*s, *ft, *fc));
                }
            }
        }
        worst
    }

    /// The smallest fraction of the bracket `[lo, hi]` at which a member beyond its strength
    /// at `hi` reaches it, its stress linear between `slo` and `shi`; in `[0, 1]`.
    fn secant(&self, slo: &[Vec<Real>], shi: &[Vec<Real>]) -> Real {
        let mut first: Real = 1.0;
        for ((a, c), limits) in slo.iter().zip(shi).zip(&self.limits) {
            for ((a, c), l) in a.iter().zip(c).zip(limits) {
                if let Some((ft, fc)) = l {
                    if let Some(f) = critical_fraction(*a, c - a, *ft, *fc) {
                        first = first.min(f);
                    }
                }
            }
        }
        first.clamp(0.0, 1.0)
    }

    /// Solve the time step from `t0` over `h` (s) of a run lasting `duration`, breaking
    /// members at their events within it (see the module documentation). `solve` solves one
    /// (sub-)step of all bodies from the motions' state; `rebalance` is true for integrators
    /// that carry a balanced acceleration (Newmark, generalized-α). Per body the reports of
    /// the sub-steps summed (iterations, work, dissipation including the strain energy the
    /// breaks released; the residual history of the last sub-step).
    pub fn solve_step(
        &mut self,
        motions: &mut [BodyMotion],
        solve: &mut StepSolve<'_>,
        (t0, h, duration): (Real, Real, Real),
        rebalance: bool,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
        self.solve_trial_step(motions, &mut Stateless(solve), (t0, h, duration), rebalance)
    }

    /// [`BreakingBodies::solve_step`] with a solver that keeps its own state between steps
    /// ([`TrialSteps`]): that state is saved with the motions before each trial sub-step and
    /// put back with them when the search tries another length, and when the step fails.
    pub fn solve_trial_step<S: TrialSteps>(
        &mut self,
        motions: &mut [BodyMotion],
        solver: &mut S,
        (t0, h, duration): (Real, Real, Real),
        rebalance: bool,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
        let saved_motions: Vec<Motion> = motions.iter().map(|m| m.motion.clone()).collect();
        let saved_solver = solver.save();
        let saved_factors: Vec<Vec<Real>> = self
            .bodies
            .iter()
            .map(|b| b.member_factors.clone())
            .collect();
        let saved_counts: Vec<(usize, usize)> = self
            .broken
            .iter()
            .zip(&self.pending)
            .map(|(b, p)| (b.len(), p.len()))
            .collect();
        let result = self.breaking_step(motions, solver, (t0, h, duration), rebalance);
        if result.is_err() {
            for (m, s) in motions.iter_mut().zip(saved_motions) {
                m.motion = s;
                m.forget_factor();
            }
            solver.restore(saved_solver);
            for (k, body) in self.bodies.iter_mut().enumerate() {
                body.member_factors = saved_factors[k].clone();
                self.broken[k].truncate(saved_counts[k].0);
                self.pending[k].truncate(saved_counts[k].1);
            }
        }
        result
    }

    fn breaking_step<S: TrialSteps>(
        &mut self,
        motions: &mut [BodyMotion],
        solver: &mut S,
        (t0, h, duration): (Real, Real, Real),
        rebalance: bool,
    ) -> Result<Vec<TimeStepReport>, (usize, TimeStepFailure)> {
        let end = t0 + h;
        let mut t = t0;
        let mut total = vec![TimeStepReport::default(); motions.len()];
        let add = |total: &mut [TimeStepReport], reports: Vec<TimeStepReport>| {
            for (sum, r) in total.iter_mut().zip(reports) {
                sum.iterations += r.iterations;
                sum.external_work += r.external_work;
                sum.dissipated += r.dissipated;
                sum.residual_history = r.residual_history;
            }
        };
        loop {
            let rest = end - t;
            let start: Vec<Motion> = motions.iter().map(|m| m.motion.clone()).collect();
            let start_solver = solver.save();
            let s_start = self.stresses(motions);
            let reports = solver.solve(motions, &self.bodies, t, rest)?;
            let s_end = self.stresses(motions);
            if self.worst(&s_end) <= 1.0 + AT_STRENGTH {
                add(&mut total, reports);
                if self.worst(&s_end) >= 1.0 - AT_STRENGTH {
                    self.break_at_strength::<S>(
                        motions,
                        &s_end,
                        (end, duration),
                        &mut total,
                        rebalance,
                    );
                }
                return Ok(total);
            }
            // The event lies within (t, end]: find θ.
            let (mut lo, mut slo) = (0.0, s_start);
            let mut hi = 1.0;
            let mut shi = s_end;
            let mut at_hi: (Vec<Motion>, Vec<TimeStepReport>, S::Saved) = (
                motions.iter().map(|m| m.motion.clone()).collect(),
                reports,
                solver.save(),
            );
            let mut kept_side = 0i32;
            let mut event = None;
            for _ in 0..MAX_REFINEMENTS {
                if hi - lo <= EVENT_TIME * h / rest.max(Real::MIN_POSITIVE) {
                    break;
                }
                let mut theta = lo + (hi - lo) * self.secant(&slo, &shi);
                if kept_side.abs() >= 2 {
                    theta = 0.5 * (theta + 0.5 * (lo + hi));
                }
                if theta <= lo || theta >= hi {
                    theta = 0.5 * (lo + hi);
                }
                for (m, s) in motions.iter_mut().zip(&start) {
                    m.motion = s.clone();
                }
                solver.restore(start_solver.clone());
                let reports = solver.solve(motions, &self.bodies, t, theta * rest)?;
                let s = self.stresses(motions);
                let worst = self.worst(&s);
                if worst > 1.0 + AT_STRENGTH {
                    hi = theta;
                    shi = s;
                    at_hi = (
                        motions.iter().map(|m| m.motion.clone()).collect(),
                        reports,
                        solver.save(),
                    );
                    kept_side = if kept_side < 0 { kept_side - 1 } else { -1 };
                } else if worst >= 1.0 - AT_STRENGTH {
                    event = Some((theta, s, reports));
                    break;
                } else {
                    lo = theta;
                    slo = s;
                    kept_side = if kept_side > 0 { kept_side + 1 } else { 1 };
                }
            }
            let (theta, s, reports) = match event {
                Some(e) => e,
                None => {
                    // The bracket closed on a jump: break at its end, where members are beyond.
                    for (m, s) in motions.iter_mut().zip(at_hi.0) {
                        m.motion = s;
                    }
                    solver.restore(at_hi.2);
                    (hi, shi, at_hi.1)
                }
            };
            add(&mut total, reports);
            t = if theta >= 1.0 { end } else { t + theta * rest };
            self.break_at_strength::<S>(motions, &s, (t, duration), &mut total, rebalance);
            if t >= end {
                return Ok(total);
            }
        }
    }

    /// Break every intact breaking member at (or beyond) its strength in `stress`, at time
    /// `t`: its modulus factor to 0, its strain energy into the body's `dissipated`.
    fn break_at_strength<S: TrialSteps>(
        &mut self,
        motions: &mut [BodyMotion],
        stress: &[Vec<Real>],
        (t, duration): (Real, Real),
        total: &mut [TimeStepReport],
        rebalance: bool,
    ) {
        for (k, body) in self.bodies.iter_mut().enumerate() {
            let breaking: Vec<usize> = self.limits[k]
                .iter()
                .enumerate()
                .filter_map(|(j, l)| {
                    let (ft, fc) = (*l)?;
                    (body.modulus_factor(j) > 0.0
                        && ratio(stress[k][j], ft, fc) >= 1.0 - AT_STRENGTH)
                        .then_some(j)
                })
                .collect();
            if breaking.is_empty() {
                continue;
            }
            let m = &mut motions[k];
            let before = strain_energy(body, &m.motion.u);
            let mut lost = Vec::new();
            if rebalance && S::OTHER_FORCES {
                lost = vec![0.0; m.motion.u.len()];
                internal_forces(body, &m.motion.u, &mut lost);
            }
            if body.member_factors.is_empty() {
                body.member_factors = vec![1.0; body.members.len()];
            }
            for &j in &breaking {
                body.member_factors[j] = 0.0;
                self.broken[k].push(j);
                self.pending[k].push(TimedBreak { member: j, time: t });
            }
            total[k].dissipated += before - strain_energy(body, &m.motion.u);
            m.forget_factor();
            if rebalance && S::OTHER_FORCES {
                // The contact forces at the event are those of the intact body: keep them in
                // the acceleration, taking away only the member forces that are gone.
                let mut after = vec![0.0; lost.len()];
                internal_forces(body, &m.motion.u, &mut after);
                for &dof in &m.dofs.free {
                    m.motion.a[dof] += (lost[dof] - after[dof]) / m.mass[dof];
                }
            } else if rebalance {
                m.balance_acceleration(body, t, duration);
            }
        }
    }
}

/// A member's stress `s` (Pa) over its strength in that sense: `s/ft` in tension, `−s/fc` in
/// compression (strengths positive, infinite for none).
fn ratio(s: Real, ft: Real, fc: Real) -> Real {
    if s >= 0.0 {
        s / ft
    } else {
        -s / fc
    }
}
