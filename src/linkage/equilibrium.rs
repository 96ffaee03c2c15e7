//! The paper's linear equilibrium (Eq. 5–10), the phase times and the errors of every body solve.

use crate::linalg::cholesky::{CholeskyError, SparseCholesky};
use crate::linkage::assembly::ModelTooLarge;
use crate::linkage::body_state::{linear_internal_forces, linear_stretch, undeformed_axis};
use crate::linkage::iterative_solver::IterativeSolver;
use crate::linkage::load_patterns::{solve_load_patterns, LoadPattern};
use crate::linkage::mechanism::{diagnose_mechanism, Mechanism};
use crate::linkage::step_state::post_process;
use crate::linkage::{
    member_block, member_stiffnesses, Body, BodyError, DofMap, SolverUsed, StepState,
    StiffnessAssembly,
};
use crate::Real;
use std::time::Instant;

/// Wall time of the phases of a linear solve, s.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    /// Pattern construction and value fill of `K_ff`.
    pub assembly: Real,
    /// Fill-reducing ordering and symbolic factorization.
    pub symbolic: Real,
    /// Numeric Cholesky factorization.
    pub numeric: Real,
    /// Forward and back substitution (all load patterns).
    pub solve: Real,
}

/// Why a body could not be solved.
#[derive(Debug, thiserror::Error)]
pub enum SolveError {
    /// The body fails validation.
    #[error(transparent)]
    Body(#[from] BodyError),
    /// The body is too large for the 32-bit pattern positions.
    #[error(transparent)]
    TooLarge(#[from] ModelTooLarge),
    /// `K_ff` is singular: some nodes can move without stretching any member.
    #[error("{0}")]
    Mechanism(Box<Mechanism>),
    /// The factorization failed for another reason.
    #[error("body '{body}': the sparse factorization failed: {message}")]
    Factorization {
        /// Body name.
        body: String,
        /// What faer reported.
        message: String,
    },
    /// The run was asked to stop ([`crate::linkage::Interrupt`]) while `step` was solved.
    #[error("body '{body}': step {step} was interrupted")]
    Interrupted {
        /// Body name.
        body: String,
        /// The step being solved.
        step: usize,
    },
    /// A nonlinear step did not converge even with its increment halved `depth` (= the
    /// body's `max_cuts`) times.
    #[error("body '{body}': step {step} did not converge, even with its load increment cut to 1/{} of the step ({depth} halvings deep, the most [bodies.newton] max_cuts allows; {cuts} halvings in this step in all, as the increment grows again after two successes): {reason}; relative residuals of the last attempt: [{}]. Use more steps (smaller increments), raise [bodies.newton] max_cuts or max_iterations, or follow a limit point with [bodies.path] method = \"arc_length\"", 1u64 << (*.depth).min(63), format_history(.history))]
    NotConverged {
        /// Body name.
        body: String,
        /// The step (1-based) that failed.
        step: usize,
        /// Halvings of the increment in force when it failed.
        depth: usize,
        /// Halvings in this step in all.
        cuts: usize,
        /// Why the last attempt failed.
        reason: String,
        /// Relative residual after each iteration of the last attempt.
        history: Vec<Real>,
    },
    /// A time step did not converge even at the smallest step size (`[dynamics] time_step`
    /// halved `halvings` times).
    #[error("body '{body}': the time step from t = {time} s did not converge, even at {step:e} s ({halvings} halvings of [dynamics] time_step, the most allowed): {reason}; relative residuals of the last attempt: [{}]. Give a smaller time_step, raise [bodies.newton] max_iterations, or check for a member crushed through zero length", format_history(.history))]
    TimeStepNotConverged {
        /// Body name.
        body: String,
        /// Start of the step, s.
        time: Real,
        /// The last step size tried, s.
        step: Real,
        /// Halvings of the time step.
        halvings: usize,
        /// Why the last attempt failed.
        reason: String,
        /// Relative residual after each iteration of the last attempt (boxed: the variant then
        /// stays smaller than [`SolveError::NotConverged`], so the error stays small).
        history: Box<[Real]>,
    },
    /// The iterative solver did not converge and the direct solver would not fit in memory.
    #[error("body '{body}': conjugate gradients stopped at relative residual {residual:e} after {iterations} iterations ({when}), and the direct solver would need {needed_mb} MB of the {available_mb} MB available: raise [bodies.solver] max_iterations, loosen its tolerance, or check the body for a mechanism (nodes held by nothing)")]
    IterativeFailed {
        /// Body name.
        body: String,
        /// Which solve (load patterns, or a step).
        when: String,
        /// Relative residual reached.
        residual: Real,
        /// Iterations run.
        iterations: usize,
        /// Memory the factor would need, MB.
        needed_mb: u64,
        /// Memory available, MB.
        available_mb: u64,
    },
    /// The solution holds numbers beyond the range of `f64` (a material or load far out of
    /// scale, e.g. an area of 1e-308 m²).
    #[error("body '{body}': the {quantity} of the solution overflow (beyond 1.8e308): check the materials' youngs_modulus and area and the loads for values far out of scale")]
    Overflow {
        /// Body name.
        body: String,
        /// Which numbers, e.g. `"displacements"`.
        quantity: &'static str,
    },
    /// A break left the supported part of the body a mechanism: the structure collapsed (a
    /// result of the run, not a failure).
    #[error("body '{body}' collapsed at step {step}: breaking member {} left its supported part a mechanism", .member + 1)]
    Collapse {
        /// Body name.
        body: String,
        /// The step (1-based) in which it collapsed.
        step: usize,
        /// The member (0-based) whose break made it a mechanism.
        member: usize,
        /// The breaks of that step, the last one included.
        breaks: Vec<crate::linkage::fracture::BreakEvent>,
        /// The state it collapsed in, when known: the displacements at the load of the last
        /// event (just before it) with every member broken so far, the event's included,
        /// broken (no equilibrium: the structure is a mechanism there).
        state: Option<Box<StepState>>,
    },
    /// A softening member's fracture energy is less than it dissipates breaking brittle.
    #[error("body '{body}': member {}: softening.fracture_energy = {fracture_energy} J/m² is below the {least:e} J/m² the member dissipates breaking at once (f_t² L/(2E), length {length} m): raise fracture_energy above it, or use teeth = 1 (brittle)", .member + 1)]
    SofteningTooBrittle {
        /// Body name.
        body: String,
        /// The member, 0-based.
        member: usize,
        /// The material's G_f, J/m².
        fracture_energy: Real,
        /// The least G_f the member can have, J/m².
        least: Real,
        /// Its undeformed length, m.
        length: Real,
    },
    /// Breaking members are not supported for this body.
    #[error("body '{body}': members of a material with failure = \"break\" {reason}: use failure = \"mark\" for this body, or {remedy}")]
    BreakingUnsupported {
        /// Body name.
        body: String,
        /// What the body has that breaking does not support yet.
        reason: String,
        /// What to change instead.
        remedy: String,
    },
    /// A large-displacement body's following pressure in a dynamic scene: a time step does not
    /// take a load that follows the deformed faces yet (it would be silently left out).
    #[error("body '{body}': its pressure follows the deformed faces (kinematics = \"large\"), which a time step does not take yet ([dynamics]): use kinematics = \"small\" for this body (the pressure then acts on the undeformed faces), or remove [dynamics]")]
    FollowingPressureInTime {
        /// Body name.
        body: String,
    },
    /// The solve returned a result that does not satisfy equilibrium.
    #[error("body '{body}': the solution misses equilibrium by {residual:e} (relative): the stiffness matrix is too ill-conditioned (members of very different stiffness, or nearly collinear members); check the materials and the geometry")]
    Inaccurate {
        /// Body name.
        body: String,
        /// Relative out-of-balance force.
        residual: Real,
    },
}

/// The linear equilibrium of one body (paper Eq. 5–10): `K_ff` assembled and factored once,
/// one solve per distinct load schedule, every step a weighted sum of those solutions.
///
/// It keeps only the load patterns' solutions: the matrix and its factor are dropped once they
/// are solved, so a large body holds no more than its results through the steps.
pub struct Equilibrium {
    /// The free/support partition.
    pub dofs: DofMap,
    /// Rows (and columns) of `K_ff`: the free DOFs.
    pub free_dofs: usize,
    /// Stored entries of the lower triangle of `K_ff`.
    pub matrix_entries: usize,
    /// Time spent in each phase, s.
    pub times: PhaseTimes,
    /// Entries of the Cholesky factor (0 when nothing is free or solved iteratively).
    pub factor_entries: usize,
    /// Which solver produced the answer: direct, iterative, or iterative then direct when
    /// conjugate gradients did not converge.
    pub solver_used: SolverUsed,
    /// Conjugate-gradient iterations, all load patterns.
    pub linear_iterations: usize,
    patterns: Vec<LoadPattern>,
    stiffness: Vec<Real>,
}

/// The pattern of `K_ff` of `body` and its values (lower triangle, N/m), paper Eq. 3–4.
fn assemble(
    body: &Body,
    dofs: &DofMap,
    stiffness: &[Real],
) -> Result<(StiffnessAssembly, Vec<Real>), ModelTooLarge> {
    let assembly = StiffnessAssembly::new(body, dofs)?;
    let mut values = Vec::new();
    assembly.fill(
        body,
        |m| {
            let [a, b] = body.members[m].nodes;
            member_block(&body.nodes[a], &body.nodes[b], stiffness[m])
        },
        &mut values,
    );
    Ok((assembly, values))
}

impl Equilibrium {
    /// Validate, assemble, factor and solve every load pattern of `body`.
    pub fn new(body: &Body) -> Result<Self, SolveError> {
        body.validate()?;
        let t = Instant::now();
        let dofs = DofMap::new(body);
        let stiffness = member_stiffnesses(body);
        let (mut assembly, mut values) = assemble(body, &dofs, &stiffness)?;
        let times = PhaseTimes {
            assembly: t.elapsed().as_secs_f64(),
            ..Default::default()
        };
        let mut eq = Equilibrium {
            dofs,
            free_dofs: assembly.n,
            matrix_entries: assembly.nnz(),
            times,
            factor_entries: 0,
            solver_used: SolverUsed::Direct,
            linear_iterations: 0,
            patterns: Vec::new(),
            stiffness,
        };
        let mut fell_back = None;
        if eq.free_dofs > 0
            && body
                .solver
                .use_iterative(eq.dofs.dofs_per_node, eq.free_dofs)
        {
            let t = Instant::now();
            let mut it = IterativeSolver::with_values(
                &assembly,
                &values,
                &eq.dofs,
                &body.nodes,
                body.solver.iterative,
            );
            // The solver holds K_ff in full rows now. The lower triangle and the members'
            // places in it would stay resident through the whole solve (a quarter of the
            // memory of a large body) for a fallback that is rare: release them, and assemble
            // again if conjugate gradients fail.
            drop(assembly);
            drop(values);
            eq.times.symbolic = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let mut failure = None;
            let patterns = eq.solve_patterns(body, &mut |rhs: &mut [Real]| {
                let mut x = vec![0.0; rhs.len()];
                match it.solve(rhs, &mut x, 0.0) {
                    Ok(report) if report.converged => {
                        rhs.copy_from_slice(&x);
                        true
                    }
                    Ok(report) => {
                        failure = Some((report.residual, report.iterations));
                        false
                    }
                    Err(_) => {
                        failure = Some((Real::INFINITY, 0));
                        false
                    }
                }
            });
            // The multigrid set-up is set-up, as a direct solver's analysis is.
            eq.times.symbolic += it.setup_seconds;
            eq.times.solve = t.elapsed().as_secs_f64() - it.setup_seconds;
            eq.linear_iterations = it.iterations;
            drop(it);
            if let Some(patterns) = patterns {
                eq.patterns = patterns;
                eq.solver_used = SolverUsed::Iterative;
                return Ok(eq);
            }
            // Conjugate gradients failed: the direct solver decides (and names a mechanism).
            fell_back = failure;
            eq.solver_used = SolverUsed::IterativeThenDirect;
            let t = Instant::now();
            (assembly, values) = assemble(body, &eq.dofs, &eq.stiffness)?;
            eq.times.assembly += t.elapsed().as_secs_f64();
        }
        let mut cholesky = None;
        if eq.free_dofs > 0 {
            let t = Instant::now();
            let a = &assembly;
            let mut c = SparseCholesky::analyze(a.n, &a.col_ptr, &a.row_idx, Some(&a.groups))
                .map_err(|e| eq.factorization_error(body, e))?;
            eq.times.symbolic += t.elapsed().as_secs_f64();
            if let Some((residual, iterations)) = fell_back {
                let needed = c.stats().factor_values as u64 * 8;
                if let Some(available) = available_memory() {
                    if needed > available / 10 * 8 {
                        return Err(SolveError::IterativeFailed {
                            body: body.name.clone(),
                            when: "solving its load patterns".to_string(),
                            residual,
                            iterations,
                            needed_mb: needed >> 20,
                            available_mb: available >> 20,
                        });
                    }
                }
            }
            let t = Instant::now();
            if let Err(e) = c.factorize(&values) {
                return Err(eq.singular(body, &assembly, &values, &mut c, e));
            }
            eq.times.numeric = t.elapsed().as_secs_f64();
            eq.factor_entries = c.stats().nnz_l;
            cholesky = Some(c);
        }
        let t = Instant::now();
        let patterns = eq.solve_patterns(body, &mut |rhs: &mut [Real]| {
            if let Some(c) = cholesky.as_mut() {
                c.solve_in_place(rhs);
            }
            true
        });
        eq.patterns = patterns.unwrap_or_default();
        eq.times.solve += t.elapsed().as_secs_f64();
        Ok(eq)
    }

    fn factorization_error(&self, body: &Body, e: CholeskyError) -> SolveError {
        SolveError::Factorization {
            body: body.name.clone(),
            message: e.to_string(),
        }
    }

    /// Turn a failed factorization into a mechanism report naming nodes and directions.
    fn singular(
        &self,
        body: &Body,
        assembly: &StiffnessAssembly,
        values: &[Real],
        c: &mut SparseCholesky,
        e: CholeskyError,
    ) -> SolveError {
        let pivot = match e {
            CholeskyError::NonPositivePivot { dof } => dof,
            CholeskyError::NearlySingular { dof, .. } => dof,
            other => return self.factorization_error(body, other),
        };
        SolveError::Mechanism(Box::new(diagnose_mechanism(
            body, &self.dofs, assembly, values, c, pivot,
        )))
    }

    /// Every load pattern of `body` solved by `solve` (see [`solve_load_patterns`]).
    fn solve_patterns(
        &self,
        body: &Body,
        solve: &mut dyn FnMut(&mut [Real]) -> bool,
    ) -> Option<Vec<LoadPattern>> {
        solve_load_patterns(body, &self.dofs, self.free_dofs, &self.stiffness, solve)
    }

    /// The state at `step` of `steps` (step 0: undeformed, unloaded).
    pub fn solve_step(
        &self,
        body: &Body,
        step: usize,
        steps: usize,
    ) -> Result<StepState, SolveError> {
        let nd = body.dof_count();
        let d = self.dofs.dofs_per_node;
        let mut u = vec![0.0; nd];
        let mut forces = vec![0.0; nd];
        for p in &self.patterns {
            let f = p.schedule.factor(step, steps);
            if f == 0.0 {
                continue;
            }
            for i in 0..nd {
                u[i] += f * p.displacements[i];
                forces[i] += f * p.forces[i];
            }
        }
        let mut internal = vec![0.0; nd];
        linear_internal_forces(body, &self.stiffness, &u, &mut internal);
        let members = body.members.iter().enumerate().map(|(m, member)| {
            let [a, b] = member.nodes;
            let n = undeformed_axis(body, a, b);
            let stretch = linear_stretch(&u, d, [a, b], &n);
            let strain = stretch / body.member_length(m);
            let material = &body.materials[member.material];
            (strain, body.member_modulus(m) * strain * material.area)
        });
        let mut state = post_process(body, &self.dofs, &u, &forces, &internal, members);
        state.iterations = usize::from(step > 0);
        if step == 1 {
            // Every load pattern was solved before the first step.
            state.linear_iterations = self.linear_iterations;
        }
        if !state.residual.is_finite() || state.residual > 1e-6 {
            return Err(SolveError::Inaccurate {
                body: body.name.clone(),
                residual: state.residual,
            });
        }
        Ok(state)
    }
}

fn format_history(history: &[Real]) -> String {
    let items: Vec<String> = history.iter().map(|r| format!("{r:.1e}")).collect();
    items.join(", ")
}

/// Memory the system can still give this process (MemAvailable), bytes; `None` where unknown.
pub(crate) fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
