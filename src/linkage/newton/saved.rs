//! A Newton state saved and restored: a fracture search under large displacements solves the
//! same stretch of the load path again and again from one converged state
//! ([`crate::linkage::fracture::LargeBreakingEquilibrium`]).

use super::{pair_members, NewtonEquilibrium, PATH_POINTS};
use crate::linkage::tangent_solver::TangentSolver;
use crate::linkage::{Body, DofMap, SolveError, StiffnessAssembly};
use crate::Real;

/// What a [`NewtonEquilibrium`] carries from one increment to the next: the displacement, the
/// converged path it extrapolates from, the floors of its relative tests and its pivot counts.
#[derive(Clone, Debug)]
pub struct SavedNewton {
    u: Vec<Real>,
    lambda: Real,
    step: usize,
    previous: Vec<Real>,
    negative_pivots: usize,
    increment_pivots: usize,
    step_pivots: usize,
    last_change: Real,
    force_floor: Real,
    displacement_floor: Real,
    path: Vec<(Real, Vec<Real>)>,
    follower: Vec<Real>,
    follower_time: (Real, usize),
}

impl NewtonEquilibrium {
    /// The state to come back to with [`NewtonEquilibrium::restore`].
    pub fn save(&self) -> SavedNewton {
        SavedNewton {
            u: self.u.clone(),
            lambda: self.lambda,
            step: self.step,
            previous: self.previous.clone(),
            negative_pivots: self.negative_pivots,
            increment_pivots: self.increment_pivots,
            step_pivots: self.step_pivots,
            last_change: self.last_change,
            force_floor: self.force_floor,
            displacement_floor: self.displacement_floor,
            path: self.path.clone(),
            follower: self.follower.clone(),
            follower_time: self.follower_time,
        }
    }

    /// Go back to a state given by [`NewtonEquilibrium::save`] (the factor is refilled by the
    /// next increment, which always refactors before it solves).
    pub fn restore(&mut self, saved: SavedNewton) {
        self.u = saved.u;
        self.lambda = saved.lambda;
        self.step = saved.step;
        self.previous = saved.previous;
        self.negative_pivots = saved.negative_pivots;
        self.increment_pivots = saved.increment_pivots;
        self.step_pivots = saved.step_pivots;
        self.last_change = saved.last_change;
        self.force_floor = saved.force_floor;
        self.displacement_floor = saved.displacement_floor;
        self.path = saved.path;
        self.follower = saved.follower;
        self.follower_time = saved.follower_time;
    }

    /// The current displacement per body DOF, m.
    pub fn displacements(&self) -> &[Real] {
        &self.u
    }

    /// Forget the converged path before the current state, which is solved at pseudo-time
    /// `t` (step units): after members broke, the states before belong to another structure
    /// and are not extrapolated from.
    pub fn restart_path(&mut self, t: Real) {
        self.path = vec![(t, self.u.clone())];
        self.path.truncate(PATH_POINTS);
    }

    /// Solve again at the load of pseudo-time `t` (step units; the current state's) after
    /// `body` changed (members broke): Newton from the current displacement, at a load that
    /// does not change, so there is nothing to halve. `step` names the step in the error.
    /// Returns the Newton iterations.
    pub fn solve_again_at(
        &mut self,
        body: &Body,
        t: Real,
        step: usize,
        steps: usize,
    ) -> Result<usize, SolveError> {
        self.restart_path(t);
        self.increment_pivots = 0;
        let saved = self.u.clone();
        match self.increment(body, t, steps) {
            Ok(n) => {
                self.step_pivots = self.step_pivots.max(self.increment_pivots);
                self.restart_path(t);
                Ok(n)
            }
            Err(failure) => {
                self.u = saved;
                Err(SolveError::NotConverged {
                    body: body.name.clone(),
                    step,
                    depth: 0,
                    cuts: 0,
                    reason: failure.reason,
                    history: failure.history,
                })
            }
        }
    }

    /// [`NewtonEquilibrium::advance_between`] for the fracture search: load control from the
    /// current state at pseudo-time `from` to `to` (either way). Returns (iterations, cuts).
    pub fn advance(
        &mut self,
        body: &Body,
        (from, to): (Real, Real),
        step: usize,
        steps: usize,
    ) -> Result<(usize, usize), SolveError> {
        self.advance_between(body, from, to, step, steps)
    }

    /// Conjugate-gradient iterations so far and the state of `step` at the current
    /// displacement (see `finish_step`), for a caller that advanced it itself.
    pub fn state_of_step(
        &mut self,
        body: &Body,
        (step, steps): (usize, usize),
        (iterations, cuts): (usize, usize),
        cg_before: usize,
    ) -> Result<crate::linkage::StepState, SolveError> {
        self.finish_step(body, (step, steps), (iterations, cuts), cg_before)
    }

    /// Negative pivots of the last tangent factored (0 with conjugate gradients: unknown).
    pub fn negative_pivots(&self) -> usize {
        self.negative_pivots
    }

    /// Take `body`'s supports anew (nodes of pieces that fell off held, or given back): its DOF
    /// map, the tangent's pattern and solver. The nodes `held` (now held where they were made)
    /// go back to their undeformed places; the converged path restarts at pseudo-time `t`.
    pub fn refit(&mut self, body: &Body, held: &[usize], t: Real) -> Result<(), SolveError> {
        let dofs = DofMap::new(body);
        let assembly = StiffnessAssembly::new(body, &dofs)?;
        let solver = if assembly.n > 0 {
            Some(TangentSolver::new(body, &dofs, &assembly).map_err(|e| {
                SolveError::Factorization {
                    body: body.name.clone(),
                    message: e.to_string(),
                }
            })?)
        } else {
            None
        };
        let d = dofs.dofs_per_node;
        for &n in held {
            self.u[n * d..(n + 1) * d].iter_mut().for_each(|v| *v = 0.0);
        }
        self.previous = vec![0.0; assembly.n];
        self.values.clear();
        self.dofs = dofs;
        self.assembly = assembly;
        self.solver = solver;
        if !body.pressures.is_empty() {
            self.pair_members = pair_members(body);
        }
        self.restart_path(t);
        Ok(())
    }

    /// Start over from the undeformed, unloaded state (step 0).
    pub fn start_over(&mut self) {
        self.u.iter_mut().for_each(|v| *v = 0.0);
        self.previous.iter_mut().for_each(|v| *v = 0.0);
        self.lambda = 0.0;
        self.step = 0;
        self.negative_pivots = 0;
        self.last_change = 0.0;
        self.force_floor = 0.0;
        self.displacement_floor = 0.0;
        self.path = vec![(0.0, self.u.clone())];
    }
}
