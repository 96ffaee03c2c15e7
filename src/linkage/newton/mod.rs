//! Newton–Raphson equilibrium of a nonlinear body: large kinematics, cables, struts.
//!
//! Load step by load step (`load_control`), with a line search and automatic halving of
//! increments that do not converge; or along an arc length (`arc_length`; see
//! [`crate::linkage::PathMethod`]).
//!
//! At every iteration the tangent stiffness is refilled in the pattern computed once
//! ([`StiffnessAssembly::fill`]) and refactored on the symbolic factorization computed once.
//! Under load control each increment starts from the path extrapolated through the last
//! converged states when that is closer to equilibrium, which saves the predictor's solve.

use crate::linkage::body_state::{
    factor_at, fill_tangent, full_loads, internal_forces, loads_at, member_response_at,
    node_vector, norm,
};
use crate::linkage::line_search::backtrack;
use crate::linkage::mechanism::diagnose_mechanism;
use crate::linkage::step_state::{force_scale, free_out_of_balance, post_process};
use crate::linkage::tangent_solver::{TangentError, TangentSolver};
use crate::linkage::{
    direction_name, Body, Convergence, DofMap, PathMethod, PhaseTimes, SolveError, SolverUsed,
    StepState, StiffnessAssembly,
};
use crate::Real;
use std::time::Instant;

mod arc_length;
mod load_control;
mod saved;
mod stops;

pub use self::saved::SavedNewton;
pub use self::stops::{add_stop_forces, stop_forces, Stop};

/// The reason of an increment stopped by [`crate::linkage::Interrupt`] (never retried: the
/// retry returns [`SolveError::Interrupted`]).
pub(super) const INTERRUPTED: &str = "interrupted";

/// Why one load increment failed (the step is retried with half the increment).
#[derive(Clone, Debug)]
struct IncrementFailure {
    reason: String,
    history: Vec<Real>,
    /// Tangent solves made (one fewer than residuals when it started from an extrapolation).
    solves: usize,
}

/// The nonlinear equilibrium of one body, advanced step by step. Holds the current
/// displacement field between steps.
///
/// ```
/// use linkage::linkage::{Body, Dimension, Kinematics, Material, Member, NewtonEquilibrium, Schedule, Support};
/// use nalgebra::Vector3;
///
/// // A bar 1 m long along x pulled to twice its length by its end support.
/// let mut body = Body::new("bar", Dimension::Two);
/// body.materials.push(Material::new("rubber", 1e7, 1e-4));
/// body.nodes = vec![Vector3::zeros(), Vector3::new(1.0, 0.0, 0.0)];
/// body.members.push(Member { nodes: [0, 1], material: 0 });
/// body.supports.push(Support::fixed(0, [true, true, false]));
/// body.supports.push(Support {
///     node: 1,
///     fixed: [true, true, false],
///     displacement: Vector3::new(1.0, 0.0, 0.0),
///     schedule: Schedule::Linear,
/// });
/// body.kinematics = Kinematics::Large;
/// let mut newton = NewtonEquilibrium::new(&body).unwrap();
/// let state = newton.solve_step(&body, 1, 1).unwrap();
/// // Engineering strain (2L − L)/L = 1, so N = E A.
/// assert!((state.axial_forces[0] - 1e7 * 1e-4).abs() < 1e-9);
/// ```
pub struct NewtonEquilibrium {
    /// The free/support partition.
    pub dofs: DofMap,
    /// The pattern of `K_ff` and the place of each member entry.
    pub assembly: StiffnessAssembly,
    /// Time spent in each phase so far, s (assembly: tangent refills and internal forces).
    pub times: PhaseTimes,
    /// Entries of the factor of the tangent.
    pub factor_entries: usize,
    /// Relative residual after each Newton iteration of the last increment solved (the
    /// quadratic convergence shows here); when the increment started from the extrapolated
    /// path, the first entry is the residual there, before any correction.
    pub residual_history: Vec<Real>,
    solver: Option<TangentSolver>,
    values: Vec<Real>,
    /// Displacement per body DOF at the last solved step, m.
    u: Vec<Real>,
    /// Load factor at the last solved step (arc length).
    lambda: Real,
    /// The step `u` belongs to.
    step: usize,
    /// The last converged increment of the free DOFs (arc length: keeps the path direction).
    previous: Vec<Real>,
    /// Negative pivots of the last factored tangent.
    negative_pivots: usize,
    /// The most negative pivots of a tangent factored in the current increment, and in the
    /// converged increments of the step being solved.
    increment_pivots: usize,
    step_pivots: usize,
    /// Norm of the displacement change of the last load-control step, m (0 before one).
    last_change: Real,
    /// The largest force scale (applied or reaction norm, N) and displacement norm (m) of the
    /// states converged so far: floors of what "relative" refers to, so that unloading back to
    /// zero (where both vanish) still converges.
    force_floor: Real,
    displacement_floor: Real,
    /// The last converged states of the load path (pseudo-time, displacement per body DOF),
    /// newest last, at most [`PATH_POINTS`]: the next increment starts from their
    /// extrapolation.
    path: Vec<(Real, Vec<Real>)>,
    /// Force per body DOF of the following pressures at the current displacement, N.
    follower: Vec<Real>,
    /// The pseudo-time (step units) and steps the following pressures are evaluated at.
    follower_time: (Real, usize),
    /// Per node pair joined by a member, sorted: `((lower, higher), member)`, to place the
    /// pressures' load stiffness (empty without pressures).
    pair_members: Vec<((usize, usize), usize)>,
    /// Fixed planes the body presses against (see [`Stop`]; empty without).
    stops: Vec<Stop>,
}

/// The force per body DOF (N) of `body`'s following pressures at displacement `u` (per body
/// DOF, m), each at its schedule's factor at pseudo-time `t` of `steps`, on the deformed faces.
pub(crate) fn follower_forces(body: &Body, u: &[Real], t: Real, steps: usize, out: &mut [Real]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    let d = body.dimension.dofs_per_node();
    for p in &body.pressures {
        let factor = factor_at(&p.schedule, t, steps);
        if factor == 0.0 {
            continue;
        }
        crate::linkage::face_forces(
            &p.faces,
            p.pressure * factor,
            |n| body.nodes[n] + node_vector(u, d, n),
            |n, f| {
                for k in 0..d {
                    out[n * d + k] += f[k];
                }
            },
        );
    }
}

/// A node pair joined by a member and the member: `((lower, higher), member)`.
pub(crate) type PairMember = ((usize, usize), usize);

/// Per node pair joined by a member of `body`, sorted: `((lower, higher), member)`, to place
/// the following pressures' load stiffness ([`add_follower_load_stiffness`]).
pub(crate) fn pair_members(body: &Body) -> Vec<PairMember> {
    let mut pairs: Vec<PairMember> = body
        .members
        .iter()
        .enumerate()
        .map(|(m, member)| {
            let [a, b] = member.nodes;
            ((a.min(b), a.max(b)), m)
        })
        .collect();
    pairs.sort_unstable();
    pairs
}

/// Add to the tangent `values` (N/m, in the pattern of `assembly` over `dofs`; `pairs` from
/// [`pair_members`]) the symmetric part of `body`'s following pressures' load stiffness at
/// displacement `u` (per body DOF, m) and pseudo-time `t` of `steps` (see
/// [`crate::linkage::symmetric_load_stiffness_blocks`]) where it is the whole of it on the
/// free DOFs (a closed surface under one pressure, or a rim that moves only in supported
/// directions): Newton is then exact and quadratic. Elsewhere the skew part is not small, the
/// symmetric part alone can slow Newton down, and the tangent leaves the load stiffness out
/// (Newton converges linearly). Shared by a body's Newton and the contact solver's.
pub(crate) fn add_follower_load_stiffness(
    body: &Body,
    (dofs, assembly, pairs): (&DofMap, &StiffnessAssembly, &[PairMember]),
    u: &[Real],
    (t, steps): (Real, usize),
    values: &mut [Real],
) {
    let d = body.dimension.dofs_per_node();
    let slots = &dofs.slots;
    let (skew, symmetric) = crate::linkage::load_stiffness_parts(
        body.pressures
            .iter()
            .map(|p| (&p.faces, p.pressure * factor_at(&p.schedule, t, steps))),
        |n| body.nodes[n] + node_vector(u, d, n),
        |n, k| k < d && matches!(slots[n * d + k], crate::linkage::DofSlot::Free(_)),
    );
    if skew > SYMMETRIC_LOAD_STIFFNESS * symmetric {
        return;
    }
    for p in &body.pressures {
        let factor = factor_at(&p.schedule, t, steps);
        if factor == 0.0 {
            continue;
        }
        crate::linkage::symmetric_load_stiffness_blocks(
            &p.faces,
            p.pressure * factor,
            |n| body.nodes[n] + node_vector(u, d, n),
            |i, j, block| {
                // Each unordered pair comes as (i, j) and (j, i): keep the one with the
                // higher node as rows, which is what the lower triangle stores.
                if i <= j {
                    return;
                }
                if let Ok(k) = pairs.binary_search_by(|probe| probe.0.cmp(&(j, i))) {
                    assembly.add_pair_block(pairs[k].1, &block, values);
                }
            },
        );
    }
}

/// The skew part of the pressures' load stiffness on the free DOFs, relative to its symmetric
/// part, below which the symmetric part is taken as the whole (round-off of a closed surface).
const SYMMETRIC_LOAD_STIFFNESS: Real = 1e-8;

/// A load-control step whose displacement change is more than this many times the step
/// before's has the tangent sampled between its start and end (see
/// `NewtonEquilibrium::watch_path`): a softening body's steps grow by less (a body at 95 % of
/// a limit load, about 1.4 times), a snap-through's by far more.
const PATH_CHECK_RATIO: Real = 2.0;

/// Points between a checked step's start and end at which the tangent is factored.
const PATH_SAMPLES: usize = 3;

/// Converged states kept for the extrapolation (three: up to a quadratic through them).
const PATH_POINTS: usize = 3;

/// The Lagrange weights at `t` of the points at `times` (distinct): the polynomial through
/// values at `times` is, at `t`, the sum of each value times its weight (a secant through two
/// converged states, a quadratic through three).
pub(crate) fn lagrange_weights(times: &[Real], t: Real) -> Vec<Real> {
    (0..times.len())
        .map(|j| {
            (0..times.len())
                .filter(|&m| m != j)
                .map(|m| (t - times[m]) / (times[j] - times[m]))
                .product()
        })
        .collect()
}

impl NewtonEquilibrium {
    /// Validate `body`, build its pattern, analyze it once and check that the undeformed
    /// tangent is not singular (a mechanism is reported with its nodes).
    pub fn new(body: &Body) -> Result<Self, SolveError> {
        body.validate()?;
        let t = Instant::now();
        let dofs = DofMap::new(body);
        let assembly = StiffnessAssembly::new(body, &dofs)?;
        let nd = body.dof_count();
        let mut eq = NewtonEquilibrium {
            previous: vec![0.0; assembly.n],
            dofs,
            assembly,
            times: PhaseTimes::default(),
            factor_entries: 0,
            residual_history: Vec::new(),
            solver: None,
            values: Vec::new(),
            u: vec![0.0; nd],
            lambda: 0.0,
            step: 0,
            negative_pivots: 0,
            increment_pivots: 0,
            step_pivots: 0,
            last_change: 0.0,
            force_floor: 0.0,
            displacement_floor: 0.0,
            path: vec![(0.0, vec![0.0; nd])],
            follower: vec![0.0; nd],
            follower_time: (0.0, 1),
            pair_members: Vec::new(),
            stops: Vec::new(),
        };
        if !body.pressures.is_empty() {
            eq.pair_members = pair_members(body);
        }
        eq.fill_tangent(body);
        eq.times.assembly += t.elapsed().as_secs_f64();
        if eq.assembly.n > 0 {
            let t = Instant::now();
            let solver = TangentSolver::new(body, &eq.dofs, &eq.assembly).map_err(|e| {
                SolveError::Factorization {
                    body: body.name.clone(),
                    message: e.to_string(),
                }
            })?;
            eq.times.symbolic += t.elapsed().as_secs_f64();
            eq.solver = Some(solver);
            let t = Instant::now();
            let first = match eq.solver.as_mut() {
                Some(s) => s.factorize_definite(&eq.values),
                None => Ok(()),
            };
            eq.times.numeric += t.elapsed().as_secs_f64();
            match first {
                Ok(_) => {}
                Err(TangentError::Indefinite { dof }) => {
                    let solver = eq.solver.as_mut().and_then(|s| s.cholesky_mut());
                    if let Some(c) = solver {
                        return Err(SolveError::Mechanism(Box::new(diagnose_mechanism(
                            body,
                            &eq.dofs,
                            &eq.assembly,
                            &eq.values,
                            c,
                            dof,
                        ))));
                    }
                }
                Err(TangentError::Other(message)) => {
                    return Err(SolveError::Factorization {
                        body: body.name.clone(),
                        message,
                    })
                }
            }
            eq.factor_entries = eq.solver.as_ref().map_or(0, |s| s.factor_entries());
        }
        Ok(eq)
    }

    /// Hold the body against `stops` from now on: their penalty forces join its residual and
    /// their stiffness its tangent (see [`Stop`]).
    pub fn set_stops(&mut self, stops: Vec<Stop>) {
        self.stops = stops;
    }

    /// The fixed planes the body presses against.
    pub fn stops(&self) -> &[Stop] {
        &self.stops
    }

    /// The current displacement per body DOF, m (of the last step solved).
    pub fn displacement(&self) -> &[Real] {
        &self.u
    }

    /// Conjugate-gradient iterations so far (0 with the direct solver).
    pub fn linear_iterations(&self) -> usize {
        self.solver.as_ref().map_or(0, |s| s.iterations())
    }

    /// Which linear solver the tangent gets: direct or iterative.
    pub fn solver_used(&self) -> SolverUsed {
        if self.solver.as_ref().is_some_and(|s| s.is_iterative()) {
            if self.solver.as_ref().is_some_and(|s| s.fell_back()) {
                SolverUsed::IterativeThenDirect
            } else {
                SolverUsed::Iterative
            }
        } else {
            SolverUsed::Direct
        }
    }

    /// The state at `step` of `steps`. Steps are solved in order from the last one solved;
    /// asking for an earlier step restarts from the undeformed state.
    pub fn solve_step(
        &mut self,
        body: &Body,
        step: usize,
        steps: usize,
    ) -> Result<StepState, SolveError> {
        if step < self.step || step == 0 {
            // Step 0 (no load, no support moved) is in equilibrium undeformed.
            self.start_over();
        }
        let mut iterations = 0;
        let mut cuts = 0;
        let cg_before = self.linear_iterations();
        self.step_pivots = 0;
        while self.step < step {
            let target = self.step + 1;
            let (i, c) = match body.newton.path {
                PathMethod::Schedules => {
                    let start = self.u.clone();
                    let done = self.advance_schedules(body, target, steps)?;
                    self.watch_path(body, &start);
                    done
                }
                PathMethod::ArcLength { length } => {
                    self.advance_arc_length(body, target, length)?
                }
            };
            iterations += i;
            cuts += c;
            self.step = target;
        }
        self.finish_step(body, (step, steps), (iterations, cuts), cg_before)
    }

    /// The state of `step` of `steps` at the current displacement, which is solved at that
    /// step's load, with the step's Newton `iterations` and `cuts` and the conjugate-gradient
    /// iterations counted before it (`cg_before`); [`SolveError::Inaccurate`] when it holds
    /// numbers that are not finite.
    pub(crate) fn finish_step(
        &mut self,
        body: &Body,
        (step, steps): (usize, usize),
        (iterations, cuts): (usize, usize),
        cg_before: usize,
    ) -> Result<StepState, SolveError> {
        self.step = step;
        let mut state = self.state(body, steps);
        state.iterations = iterations;
        state.cuts = cuts;
        state.linear_iterations = self.linear_iterations() - cg_before;
        if step > 0 {
            state.residual_history = self.residual_history.clone();
        }
        if !state.residual.is_finite()
            || state
                .displacements
                .iter()
                .any(|u| !u.iter().all(|c| c.is_finite()))
            || !state.axial_forces.iter().all(|n| n.is_finite())
        {
            return Err(SolveError::Inaccurate {
                body: body.name.clone(),
                residual: state.residual,
            });
        }
        Ok(state)
    }

    /// After a load-control step from displacement `start` to the current one: when the step
    /// moved more than [`PATH_CHECK_RATIO`] times the step before it, factor the tangent at
    /// points between the two states ([`PATH_SAMPLES`] along the straight line) and count
    /// their negative pivots into the step's (`negative_pivots_met` of the state): a stable
    /// start and end with an unstable region between them is a limit point passed within the
    /// step, which the solved states alone do not show. Ordinary steps cost nothing more.
    fn watch_path(&mut self, body: &Body, start: &[Real]) {
        let change = self
            .u
            .iter()
            .zip(start)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<Real>()
            .sqrt();
        let before = std::mem::replace(&mut self.last_change, change);
        if !(change > PATH_CHECK_RATIO * before && before > 0.0) || self.solver.is_none() {
            return;
        }
        let end = self.u.clone();
        let (pivots, increment) = (self.negative_pivots, self.increment_pivots);
        for k in 1..=PATH_SAMPLES {
            let s = k as Real / (PATH_SAMPLES + 1) as Real;
            for ((u, a), b) in self.u.iter_mut().zip(start).zip(&end) {
                *u = a + s * (b - a);
            }
            let t = Instant::now();
            self.fill_tangent(body);
            self.times.assembly += t.elapsed().as_secs_f64();
            let t = Instant::now();
            if let Ok(negative) = self.factorize() {
                self.step_pivots = self.step_pivots.max(negative);
            }
            self.times.numeric += t.elapsed().as_secs_f64();
        }
        self.u = end;
        // The factor now holds a sample's tangent: the next increment refactors before it
        // solves (its predictor and every correction do); the counts are the end's again.
        self.negative_pivots = pivots;
        self.increment_pivots = increment;
    }

    /// The full state at the current displacement (post-processing shared with the linear
    /// solve).
    fn state(&self, body: &Body, steps: usize) -> StepState {
        let mut forces = self.forces_at(body, self.step as Real, steps);
        if !body.pressures.is_empty() {
            let mut follower = vec![0.0; forces.len()];
            follower_forces(body, &self.u, self.step as Real, steps, &mut follower);
            forces.iter_mut().zip(&follower).for_each(|(f, p)| *f += p);
        }
        let mut internal = vec![0.0; self.u.len()];
        internal_forces(body, &self.u, &mut internal);
        if !self.stops.is_empty() {
            // The stops' forces balance the members as the supports' do: taken off the
            // internal forces, the out-of-balance is `F + F_stop − f_int`.
            let mut pushed = vec![0.0; self.u.len()];
            add_stop_forces(body, &self.stops, &self.u, &mut pushed);
            internal.iter_mut().zip(&pushed).for_each(|(f, p)| *f -= p);
        }
        let members = (0..body.members.len()).map(|m| {
            let r = member_response_at(body, &self.u, m);
            (r.strain, r.force)
        });
        let mut state = post_process(body, &self.dofs, &self.u, &forces, &internal, members);
        let mut scale = force_scale(&self.dofs, &forces, &internal).max(self.force_floor);
        if let PathMethod::ArcLength { .. } = body.newton.path {
            state.load_factor = Some(self.lambda);
            scale = scale.max(norm(&full_loads(body)));
        }
        let out_of_balance = free_out_of_balance(&self.dofs, &forces, &internal);
        state.residual = Convergence::relative(out_of_balance, scale);
        state.negative_pivots = self.negative_pivots;
        state.negative_pivots_met = self.step_pivots.max(self.negative_pivots);
        state.pivots_unknown = self.solver.as_ref().is_some_and(|s| s.is_iterative());
        state
    }

    /// Applied force per body DOF at pseudo-time `t` (step units, fractional between steps),
    /// N: each load's schedule interpolated linearly between steps; in arc-length mode the
    /// reference load times the current load factor.
    fn forces_at(&self, body: &Body, t: Real, steps: usize) -> Vec<Real> {
        if let PathMethod::ArcLength { .. } = body.newton.path {
            return full_loads(body).iter().map(|f| f * self.lambda).collect();
        }
        loads_at(body, t, steps)
    }

    fn fill_tangent(&mut self, body: &Body) {
        fill_tangent(body, &self.assembly, &self.u, &mut self.values);
        if body.newton.load_stiffness {
            self.add_load_stiffness(body);
        }
        if !self.stops.is_empty() {
            stops::add_stop_stiffness(body, &self.stops, &self.u, &self.assembly, &mut self.values);
        }
    }

    /// Add the following pressures' load stiffness at the current displacement where it is
    /// symmetric (see [`add_follower_load_stiffness`]).
    fn add_load_stiffness(&mut self, body: &Body) {
        add_follower_load_stiffness(
            body,
            (&self.dofs, &self.assembly, &self.pair_members),
            &self.u,
            self.follower_time,
            &mut self.values,
        );
    }

    /// The applied force per body DOF, N: the nodal `forces` plus the following pressures at
    /// the current displacement (as last evaluated by [`Self::out_of_balance`]).
    fn applied(&self, forces: &[Real]) -> Vec<Real> {
        forces
            .iter()
            .zip(&self.follower)
            .map(|(f, p)| f + p)
            .collect()
    }

    fn factorize(&mut self) -> Result<usize, TangentError> {
        let Some(solver) = self.solver.as_mut() else {
            return Ok(0);
        };
        let negative = solver.factorize(&self.values)?;
        self.negative_pivots = negative;
        self.increment_pivots = self.increment_pivots.max(negative);
        Ok(negative)
    }

    /// Refill and refactor the tangent at the current displacement.
    fn refactor(&mut self, body: &Body) -> Result<(), String> {
        let t = Instant::now();
        self.fill_tangent(body);
        self.times.assembly += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let result = self.factorize();
        self.times.numeric += t.elapsed().as_secs_f64();
        result.map(|_| ()).map_err(|e| self.describe(e))
    }

    /// What a failed tangent factorization means for the user.
    fn describe(&self, error: TangentError) -> String {
        match error {
            TangentError::Indefinite { dof } => {
                let (node, dir) = self.dofs.node_and_direction(self.dofs.free[dof]);
                format!(
                    "the tangent stiffness is singular or indefinite at node {} ({}): the body is at or past a limit point or buckles",
                    node + 1,
                    direction_name(dir)
                )
            }
            TangentError::Other(m) => m,
        }
    }

    fn solve(&mut self, rhs: &mut [Real]) -> Result<(), String> {
        let t = Instant::now();
        let result = match self.solver.as_mut() {
            Some(s) => s.solve_in_place(rhs),
            None => Ok(()),
        };
        self.times.solve += t.elapsed().as_secs_f64();
        result.map_err(|e| self.describe(e))
    }

    /// Internal forces and the free out-of-balance `F + F_p − f_int` at the current
    /// displacement, `F_p` the following pressures (kept for [`Self::applied`]; timed as
    /// assembly).
    fn out_of_balance(&mut self, body: &Body, forces: &[Real], internal: &mut [Real]) -> Vec<Real> {
        let t = Instant::now();
        internal_forces(body, &self.u, internal);
        if !body.pressures.is_empty() {
            let (t1, steps) = self.follower_time;
            follower_forces(body, &self.u, t1, steps, &mut self.follower);
        }
        if !self.stops.is_empty() {
            // The stops push as the supports hold: off the internal forces.
            let mut pushed = vec![0.0; internal.len()];
            add_stop_forces(body, &self.stops, &self.u, &mut pushed);
            internal.iter_mut().zip(&pushed).for_each(|(f, p)| *f -= p);
        }
        self.times.assembly += t.elapsed().as_secs_f64();
        self.dofs
            .free
            .iter()
            .map(|&dof| forces[dof] + self.follower[dof] - internal[dof])
            .collect()
    }

    /// Move the free DOFs by `s δ` with `s` = 1, 1/2, … 1/16: the first `s` that lowers the
    /// out-of-balance norm (Armijo, 1e-4), else the best tried. Returns the length moved.
    fn line_search(
        &mut self,
        body: &Body,
        forces: &[Real],
        delta: &[Real],
        r0: Real,
        internal: &mut [Real],
    ) -> Real {
        let base: Vec<Real> = self.dofs.free.iter().map(|&dof| self.u[dof]).collect();
        let (s, accepted) = backtrack(r0, |s| {
            self.move_free(&base, delta, s);
            norm(&self.out_of_balance(body, forces, internal))
        });
        if !accepted {
            self.move_free(&base, delta, s);
        }
        s * norm(delta)
    }

    /// Raise the floors of the relative tests to a converged state's force scale (N) and
    /// displacement norm (m).
    fn converged(&mut self, force_scale: Real, displacement_norm: Real) {
        self.force_floor = self.force_floor.max(force_scale);
        self.displacement_floor = self.displacement_floor.max(displacement_norm);
    }

    /// Free displacements `base + s δ` (both per free DOF).
    fn move_free(&mut self, base: &[Real], delta: &[Real], s: Real) {
        for (i, &dof) in self.dofs.free.iter().enumerate() {
            self.u[dof] = base[i] + s * delta[i];
        }
    }
}

/// The size of the next increment within a step, as the fraction `2^-depth` of the step:
/// halved after an increment fails, doubled again after two successes in a row (so a hard
/// stretch of the path is crossed in small increments, and the rest of the step is not).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct IncrementSize {
    /// Halvings of the increment in force.
    pub(crate) depth: usize,
    streak: usize,
    /// Halvings so far in this step.
    pub(crate) cuts: usize,
}

impl IncrementSize {
    /// The increment as a fraction of a step.
    pub(crate) fn fraction(&self) -> Real {
        0.5f64.powi(self.depth.min(1000) as i32)
    }

    /// After a converged increment: double again after two in a row.
    pub(crate) fn succeeded(&mut self) {
        self.streak += 1;
        if self.streak >= 2 && self.depth > 0 {
            self.depth -= 1;
            self.streak = 0;
        }
    }

    /// Halve; false when that would go below `2^-max_cuts` of a step.
    pub(crate) fn failed(&mut self, max_cuts: usize) -> bool {
        self.streak = 0;
        if self.depth >= max_cuts {
            return false;
        }
        self.depth += 1;
        self.cuts += 1;
        true
    }
    /// After `failure` of an increment of step `step`: halve, or give the step's error when
    /// the increment is already the smallest allowed.
    fn retry(
        &mut self,
        body: &Body,
        step: usize,
        failure: IncrementFailure,
    ) -> Result<(), SolveError> {
        if body.newton.interrupt.is_raised() {
            return Err(SolveError::Interrupted {
                body: body.name.clone(),
                step,
            });
        }
        if self.failed(body.newton.max_cuts) {
            Ok(())
        } else {
            Err(not_converged(body, step, self, failure))
        }
    }
}

/// The error for a step that could not be solved even with the smallest increment.
fn not_converged(
    body: &Body,
    step: usize,
    size: &IncrementSize,
    failure: IncrementFailure,
) -> SolveError {
    SolveError::NotConverged {
        body: body.name.clone(),
        step,
        depth: size.depth,
        cuts: size.cuts,
        reason: failure.reason,
        history: failure.history,
    }
}

#[cfg(test)]
mod tests {
    use super::lagrange_weights;

    #[test]
    fn lagrange_weights_extrapolate_a_secant_and_a_parabola_exactly() {
        assert_eq!(lagrange_weights(&[0.0, 1.0], 2.0), [-1.0, 2.0]);
        let times = [1.0, 1.5, 2.0];
        let w = lagrange_weights(&times, 2.5);
        let at: f64 = times.iter().zip(&w).map(|(t, w)| w * t * t).sum();
        assert!((at - 6.25).abs() < 1e-14, "{at}");
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }
}
