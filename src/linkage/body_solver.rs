//! The solver a body needs: the paper's linear superposition, or Newton for a nonlinear body.

use crate::linkage::fracture::{breaks_members, BreakingEquilibrium, LargeBreakingEquilibrium};
use crate::linkage::{
    Body, Equilibrium, NewtonEquilibrium, PhaseTimes, SolveError, SolverUsed, StepState,
};

/// One body's equilibrium solver, chosen by [`Body::is_nonlinear`].
pub enum BodySolver {
    /// Linear kinematics and elastic members: factor once, superpose load patterns.
    Linear(Box<Equilibrium>),
    /// Large kinematics, cables or struts, or an arc-length path: Newton step by step, holding
    /// the current state between steps.
    Nonlinear(Box<NewtonEquilibrium>),
    /// Linear, with members that break: factor once, break members event by event.
    Breaking(Box<BreakingEquilibrium>),
    /// Nonlinear (by load control), with members that break: Newton, each break at the load
    /// found by a search over Newton solves.
    LargeBreaking(Box<LargeBreakingEquilibrium>),
}

impl BodySolver {
    /// Validate `body` and prepare its solver (for a linear body: solve it).
    pub fn new(body: &Body) -> Result<Self, SolveError> {
        let breaking = breaks_members(body);
        Ok(if breaking && body.is_nonlinear() {
            BodySolver::LargeBreaking(Box::new(LargeBreakingEquilibrium::new(body)?))
        } else if breaking {
            BodySolver::Breaking(Box::new(BreakingEquilibrium::new(body)?))
        } else if body.is_nonlinear() {
            BodySolver::Nonlinear(Box::new(NewtonEquilibrium::new(body)?))
        } else {
            BodySolver::Linear(Box::new(Equilibrium::new(body)?))
        })
    }

    /// The state at `step` of `steps`. A nonlinear body solves the steps in order (asking
    /// for an earlier step than the last one solved restarts it).
    pub fn solve_step(
        &mut self,
        body: &Body,
        step: usize,
        steps: usize,
    ) -> Result<StepState, SolveError> {
        match self {
            BodySolver::Linear(eq) => eq.solve_step(body, step, steps),
            BodySolver::Nonlinear(newton) => newton.solve_step(body, step, steps),
            BodySolver::Breaking(eq) => eq.solve_step(body, step, steps),
            BodySolver::LargeBreaking(eq) => eq.solve_step(body, step, steps),
        }
    }

    /// Which linear solver produced the answers: direct, iterative, or iterative then direct
    /// when conjugate gradients did not converge on a linear body.
    pub fn solver_used(&self) -> SolverUsed {
        match self {
            BodySolver::Linear(eq) => eq.solver_used,
            BodySolver::Nonlinear(newton) => newton.solver_used(),
            BodySolver::Breaking(_) => SolverUsed::Direct,
            BodySolver::LargeBreaking(eq) => eq.newton.solver_used(),
        }
    }

    /// Rows of `K_ff`.
    pub fn free_dofs(&self) -> usize {
        match self {
            BodySolver::Linear(eq) => eq.free_dofs,
            BodySolver::Nonlinear(newton) => newton.assembly.n,
            BodySolver::Breaking(eq) => eq.assembly.n,
            BodySolver::LargeBreaking(eq) => eq.newton.assembly.n,
        }
    }

    /// Time spent so far in each phase, s.
    pub fn times(&self) -> PhaseTimes {
        match self {
            BodySolver::Linear(eq) => eq.times,
            BodySolver::Nonlinear(newton) => newton.times,
            BodySolver::Breaking(eq) => eq.times,
            BodySolver::LargeBreaking(eq) => eq.times(),
        }
    }
}
