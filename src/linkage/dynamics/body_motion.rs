//! One body in time: its motion, lumped mass and damping, and the Newton solve of one time
//! step on the body's tangent with the integrator's `c·M` on the diagonal.

use crate::linkage::body_state::{internal_forces, member_response_at, norm};
use crate::linkage::dynamics::discrete_gradient::{
    discrete_gradient_block, discrete_gradient_forces,
};
use crate::linkage::dynamics::integrator::advanced;
use crate::linkage::dynamics::time_schedule::{loads_at_time, prescribed_at_time};
use crate::linkage::dynamics::{Integrator, Motion, RayleighDamping, StepForm};
use crate::linkage::step_state::post_process;
use crate::linkage::tangent_solver::{TangentError, TangentSolver};
use crate::linkage::{
    direction_name, Body, Convergence, DofMap, PhaseTimes, SolveError, SolverUsed, StepState,
    StiffnessAssembly,
};
use crate::Real;
use std::time::Instant;

/// What one solved time step of one body reports.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimeStepReport {
    /// Newton iterations (tangent solves).
    pub iterations: usize,
    /// Relative residual after each iteration.
    pub residual_history: Vec<Real>,
    /// Work of the applied forces and of the supports over the step, J.
    pub external_work: Real,
    /// Work of the damping forces over the step (dissipated), J.
    pub dissipated: Real,
}

/// Why a time step of one body could not be solved (the driver halves the step).
#[derive(Clone, Debug, PartialEq)]
pub struct TimeStepFailure {
    /// What went wrong.
    pub reason: String,
    /// Relative residual after each iteration of the attempt.
    pub history: Vec<Real>,
}

/// Stalled at round-off: within [`ROUND_OFF_TOLERANCES`] tolerances and no longer falling by
/// half. A time step's residual has a floor of `ε |u| c M`, relative `2ε|u|/(h|v|)` for a
/// body that coasts: far from the origin with a short step it can sit above a tight tolerance.
fn at_round_off(c: &Convergence) -> bool {
    let n = c.history.len();
    n >= 2
        && c.history[n - 1] <= ROUND_OFF_TOLERANCES * c.tolerance
        && c.history[n - 1] >= 0.5 * c.history[n - 2]
}

/// See [`at_round_off`].
const ROUND_OFF_TOLERANCES: Real = 1e3;

/// One body advanced in time. Holds its motion between steps and, for a linear body, the
/// factorization of `c₀ M + c₁ C + K` while the step size does not change.
pub struct BodyMotion {
    /// The free/support partition.
    pub dofs: DofMap,
    /// The pattern of the step's tangent (that of `K_ff`).
    pub assembly: StiffnessAssembly,
    /// Lumped mass per body DOF, kg.
    pub mass: Vec<Real>,
    /// Displacement, velocity and acceleration per body DOF at the current time.
    pub motion: Motion,
    /// Rayleigh damping.
    pub damping: RayleighDamping,
    /// Time spent in each phase so far, s.
    pub times: PhaseTimes,
    /// Numeric factorizations so far.
    pub factorizations: usize,
    solver: Option<TangentSolver>,
    values: Vec<Real>,
    /// The step size (s) and integrator the factor in `solver` was made for, when it can be
    /// kept (a linear body: its tangent depends on nothing else).
    kept: Option<(Real, &'static str)>,
}

/// The parts of a step's out-of-balance per body DOF, N.
struct Forces {
    /// Applied forces at the evaluation time.
    applied: Vec<Real>,
    /// Member forces (or their discrete gradient).
    internal: Vec<Real>,
    /// Damping forces.
    damping: Vec<Real>,
    /// Inertia forces `c M (y − predictor)`.
    inertia: Vec<Real>,
}

impl BodyMotion {
    /// Prepare `body` to move from rest at its undeformed state with the initial `velocity`
    /// per body DOF (m/s), lumped `mass` per body DOF (kg) and `damping`. Its pattern is
    /// analyzed once; no support is needed (the mass term holds a free body).
    pub fn new(
        body: &Body,
        mass: Vec<Real>,
        velocity: Vec<Real>,
        damping: RayleighDamping,
    ) -> Result<Self, SolveError> {
        body.validate_moving()?;
        let t = Instant::now();
        let dofs = DofMap::new(body);
        let assembly = StiffnessAssembly::new(body, &dofs)?;
        let mut times = PhaseTimes {
            assembly: t.elapsed().as_secs_f64(),
            ..Default::default()
        };
        let solver = if assembly.n > 0 {
            let t = Instant::now();
            let s = TangentSolver::new(body, &dofs, &assembly).map_err(|e| {
                SolveError::Factorization {
                    body: body.name.clone(),
                    message: e.to_string(),
                }
            })?;
            times.symbolic += t.elapsed().as_secs_f64();
            Some(s)
        } else {
            None
        };
        let nd = body.dof_count();
        Ok(BodyMotion {
            dofs,
            assembly,
            mass,
            motion: Motion {
                u: vec![0.0; nd],
                v: velocity,
                a: vec![0.0; nd],
            },
            damping,
            times,
            factorizations: 0,
            solver,
            values: Vec::new(),
            kept: None,
        })
    }

    /// Forget the kept factorization of a linear body: its members changed (one broke), so
    /// the next step refactors even at the same step size.
    pub fn forget_factor(&mut self) {
        self.kept = None;
    }

    /// Which linear solver the step's tangent gets: direct or iterative.
    pub fn solver_used(&self) -> SolverUsed {
        if self.solver.as_ref().is_some_and(|s| s.is_iterative()) {
            SolverUsed::Iterative
        } else {
            SolverUsed::Direct
        }
    }

    /// The acceleration that balances the state at t = 0, `a₀ = M⁻¹(F(0) − f_int(u₀) − C v₀)`
    /// at the free DOFs (0 at the supported ones), into the motion: Newmark and generalized-α
    /// start from it, so that a load applied in full at t = 0 acts from the first step.
    pub fn balance_initial_acceleration(&mut self, body: &Body, duration: Real) {
        self.balance_acceleration(body, 0.0, duration);
    }

    /// [`BodyMotion::balance_initial_acceleration`] at time `t` (s) of `duration`, from the
    /// current displacement and velocity: after a member breaks at `t` the acceleration jumps
    /// (its force is gone), and Newmark and generalized-α continue from the balanced one.
    pub fn balance_acceleration(&mut self, body: &Body, t: Real, duration: Real) {
        let forces = loads_at_time(body, t, duration);
        let mut internal = vec![0.0; forces.len()];
        internal_forces(body, &self.motion.u, &mut internal);
        let mut damping = vec![0.0; forces.len()];
        self.damping_forces(body, &self.motion.u, &self.motion.v, &mut damping);
        self.motion.a.iter_mut().for_each(|a| *a = 0.0);
        for &dof in &self.dofs.free {
            self.motion.a[dof] = (forces[dof] - internal[dof] - damping[dof]) / self.mass[dof];
        }
    }

    /// The Rayleigh damping force per body DOF (N) at configuration `y` and velocity `v`:
    /// `α M v` plus, per member that acts at `y`, `β (E A/L) (e·Δv) e` along its axis `e` there.
    fn damping_forces(&self, body: &Body, y: &[Real], v: &[Real], out: &mut [Real]) {
        out.iter_mut().for_each(|x| *x = 0.0);
        if self.damping.mass != 0.0 {
            for ((o, m), v) in out.iter_mut().zip(&self.mass).zip(v) {
                *o += self.damping.mass * m * v;
            }
        }
        if self.damping.stiffness != 0.0 {
            let d = body.dimension.dofs_per_node();
            for (m, member) in body.members.iter().enumerate() {
                let r = member_response_at(body, y, m);
                if r.force == 0.0 && r.strain != 0.0 {
                    continue;
                }
                let k = body.member_modulus(m) * body.materials[member.material].area
                    / body.member_length(m);
                let [a, b] = member.nodes;
                let rate: Real = (0..d)
                    .map(|i| r.axis[i] * (v[b * d + i] - v[a * d + i]))
                    .sum();
                let f = self.damping.stiffness * k * rate;
                for i in 0..d {
                    out[a * d + i] -= f * r.axis[i];
                    out[b * d + i] += f * r.axis[i];
                }
            }
        }
    }

    /// The forces of the step `form` at the increment `w = y − u_n` of its configuration (per
    /// body DOF, m) from the motion's `u_n`, with the applied forces `applied` at the
    /// evaluation time. The inertia and damping terms are formed from `w` alone (no round-off
    /// of the size of `|u_n|`).
    fn forces(&self, body: &Body, form: &StepForm, w: &[Real], applied: &[Real]) -> Forces {
        let n = w.len();
        let start = &self.motion.u;
        let y = advanced(&self.motion, w);
        let mut internal = vec![0.0; n];
        if form.discrete_gradient {
            let u1 = self.step_end(form, w);
            discrete_gradient_forces(body, start, &u1, &mut internal);
        } else {
            internal_forces(body, &y, &mut internal);
        }
        let mut damping = vec![0.0; n];
        if !self.damping.is_none() {
            let v: Vec<Real> = w
                .iter()
                .zip(&form.velocity_predictor)
                .map(|(w, p)| form.velocity_coefficient * (w - p))
                .collect();
            self.damping_forces(body, &y, &v, &mut damping);
        }
        let c = form.inertia.coefficient;
        let inertia = (0..n)
            .map(|i| c * form.inertia.mass[i] * (w[i] - form.predictor_increment[i]))
            .collect();
        Forces {
            applied: applied.to_vec(),
            internal,
            damping,
            inertia,
        }
    }

    /// `u_{n+1} = u_n + w / b`, the step's end from the increment `w` of the blend.
    fn step_end(&self, form: &StepForm, w: &[Real]) -> Vec<Real> {
        let du: Vec<Real> = w.iter().map(|w| w / form.blend).collect();
        advanced(&self.motion, &du)
    }

    /// Refill the tangent `K_T(y) + β c_v K + (c + α c_v) M` and factor it, unless a linear
    /// body keeps its factor for this step size.
    fn refactor(
        &mut self,
        body: &Body,
        form: &StepForm,
        w: &[Real],
        h: Real,
        name: &'static str,
    ) -> Result<(), String> {
        let linear = !body.is_nonlinear();
        if linear && self.kept == Some((h, name)) {
            return Ok(());
        }
        let t = Instant::now();
        let start = self.motion.u.clone();
        let y = advanced(&self.motion, w);
        let y = &y;
        let u1 = self.step_end(form, w);
        let beta_c = self.damping.stiffness * form.velocity_coefficient;
        let dg = form.discrete_gradient;
        self.assembly.fill(
            body,
            |m| {
                let r = member_response_at(body, y, m);
                let block = if dg {
                    discrete_gradient_block(body, &start, &u1, m).unwrap_or(r.tangent)
                } else {
                    r.tangent
                };
                if beta_c != 0.0 && !(r.force == 0.0 && r.strain != 0.0) {
                    let k = body.member_modulus(m) * body.materials[body.members[m].material].area
                        / body.member_length(m);
                    block + r.axis * r.axis.transpose() * (beta_c * k)
                } else {
                    block
                }
            },
            &mut self.values,
        );
        let diagonal = form.inertia.coefficient + self.damping.mass * form.velocity_coefficient;
        let d = self.dofs.dofs_per_node;
        for &dof in &self.dofs.free {
            if let Some(place) = self.assembly.diagonal_place(dof / d, dof % d) {
                self.values[place] += diagonal * self.mass[dof];
            }
        }
        self.times.assembly += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let result = match self.solver.as_mut() {
            Some(s) => s.factorize(&self.values).map(|_| ()),
            None => Ok(()),
        };
        self.times.numeric += t.elapsed().as_secs_f64();
        self.factorizations += 1;
        self.kept = if linear { Some((h, name)) } else { None };
        result.map_err(|e| {
            self.kept = None;
            self.describe(e)
        })
    }

    fn describe(&self, error: TangentError) -> String {
        match error {
            TangentError::Indefinite { dof } => {
                let (node, dir) = self.dofs.node_and_direction(self.dofs.free[dof]);
                format!(
                    "the step's tangent c·M + K_T is singular or indefinite at node {} ({}): a member is crushed through zero length, or the step is too long",
                    node + 1,
                    direction_name(dir)
                )
            }
            TangentError::Other(m) => m,
        }
    }

    /// Solve the time step from `t0` of length `h` (s) with `integrator`, in a run lasting
    /// `duration` (s): Newton on the configuration `y` of the integrator's [`StepForm`], to
    /// the body's `[bodies.newton] tolerance` (relative to the largest of the applied,
    /// member, damping and inertia forces and the inertia force of the predicted motion).
    /// On success the motion is at `t0 + h`; on failure it is unchanged.
    pub fn step(
        &mut self,
        body: &Body,
        integrator: &dyn Integrator,
        t0: Real,
        h: Real,
        duration: Real,
    ) -> Result<TimeStepReport, TimeStepFailure> {
        let form = integrator.form(&self.motion, &self.mass, h);
        let b = form.blend;
        let start = self.motion.u.clone();
        let t1 = t0 + h;
        let applied: Vec<Real> = loads_at_time(body, t0, duration)
            .iter()
            .zip(&loads_at_time(body, t1, duration))
            .map(|(a, c)| (1.0 - b) * a + b * c)
            .collect();
        let prescribed = prescribed_at_time(body, t1, duration);
        // Newton carries the increment w = y − u_n of the configuration, not y: the momenta
        // are then exact sums of the solved increments (see the module README). Start from
        // the motion continued at its velocity; the supports at their place.
        let mut w: Vec<Real> = self.motion.v.iter().map(|v| b * h * v).collect();
        for &dof in &self.dofs.supported {
            w[dof] = b * (prescribed[dof] - start[dof]);
        }
        // The inertia force of the predicted motion: the scale of a body that only coasts.
        let coasting = norm(
            &self
                .dofs
                .free
                .iter()
                .map(|&i| form.inertia.coefficient * self.mass[i] * form.predictor_increment[i])
                .collect::<Vec<_>>(),
        );
        let mut convergence = Convergence::new(body.newton.tolerance);
        let fail = |reason: String, c: &Convergence| TimeStepFailure {
            reason,
            history: c.history.clone(),
        };
        let mut iterations = 0;
        let forces = loop {
            let t = Instant::now();
            let f = self.forces(body, &form, &w, &applied);
            self.times.assembly += t.elapsed().as_secs_f64();
            let free_norm =
                |v: &[Real]| norm(&self.dofs.free.iter().map(|&i| v[i]).collect::<Vec<_>>());
            let r: Vec<Real> = self
                .dofs
                .free
                .iter()
                .map(|&i| f.applied[i] - f.internal[i] - f.damping[i] - f.inertia[i])
                .collect();
            let scale = [
                free_norm(&f.applied),
                free_norm(&f.internal),
                free_norm(&f.damping),
                free_norm(&f.inertia),
                coasting,
            ]
            .into_iter()
            .fold(0.0, Real::max);
            let rnorm = norm(&r);
            if convergence
                .record(Convergence::relative(rnorm, scale))
                .is_err()
            {
                return Err(fail(
                    "the residual is not finite (a member collapsed or the iteration diverged)"
                        .to_string(),
                    &convergence,
                ));
            }
            if convergence.within_tolerance() || (iterations > 0 && at_round_off(&convergence)) {
                break f;
            }
            if iterations >= body.newton.max_iterations {
                return Err(fail(
                    format!(
                        "no convergence in {} Newton iterations",
                        body.newton.max_iterations
                    ),
                    &convergence,
                ));
            }
            self.refactor(body, &form, &w, h, integrator.name())
                .map_err(|reason| fail(reason, &convergence))?;
            let mut delta = r;
            let t = Instant::now();
            let solved = match self.solver.as_mut() {
                Some(s) => s.solve_in_place(&mut delta),
                None => Ok(()),
            };
            self.times.solve += t.elapsed().as_secs_f64();
            solved.map_err(|e| fail(self.describe(e), &convergence))?;
            for (i, &dof) in self.dofs.free.iter().enumerate() {
                w[dof] += delta[i];
            }
            iterations += 1;
        };
        let du: Vec<Real> = w.iter().map(|w| w / b).collect();
        let mut report = TimeStepReport {
            iterations,
            residual_history: convergence.history,
            ..Default::default()
        };
        let supported =
            |i: usize| matches!(self.dofs.slots[i], crate::linkage::DofSlot::Supported(_));
        for (i, &du) in du.iter().enumerate() {
            let reaction = if supported(i) {
                forces.internal[i] + forces.damping[i] + forces.inertia[i] - forces.applied[i]
            } else {
                0.0
            };
            report.external_work += (forces.applied[i] + reaction) * du;
            report.dissipated += forces.damping[i] * du;
        }
        self.motion = integrator.finish(&self.motion, du, h);
        Ok(report)
    }

    /// The state at the current motion and time `t` (s) of `duration`: displacements, member
    /// forces and strains, applied loads and the support reactions including the supported
    /// nodes' inertia (`f_int + M a − F`); `residual` is left 0 for the driver to fill.
    pub fn state(&self, body: &Body, t: Real, duration: Real) -> StepState {
        let forces = loads_at_time(body, t, duration);
        let mut internal = vec![0.0; forces.len()];
        internal_forces(body, &self.motion.u, &mut internal);
        for ((f, m), a) in internal.iter_mut().zip(&self.mass).zip(&self.motion.a) {
            *f += m * a;
        }
        let members = (0..body.members.len()).map(|m| {
            let r = member_response_at(body, &self.motion.u, m);
            (r.strain, r.force)
        });
        let mut state = post_process(
            body,
            &self.dofs,
            &self.motion.u,
            &forces,
            &internal,
            members,
        );
        state.residual = 0.0;
        state
    }
}
