//! Load control: each step's loads and prescribed displacements follow their schedules.
//!
//! A step is crossed in increments halved when Newton does not converge; each increment starts
//! from the path extrapolated through the last converged states when that is closer to
//! equilibrium.

use super::{
    lagrange_weights, IncrementFailure, IncrementSize, NewtonEquilibrium, INTERRUPTED, PATH_POINTS,
};
use crate::linkage::body_state::{norm, prescribed_at, tangent_times};
use crate::linkage::step_state::force_scale;
use crate::linkage::{Body, Convergence, SolveError};
use crate::Real;

impl NewtonEquilibrium {
    /// Load control: advance from `target − 1` to `target`, halving the increment when it
    /// does not converge. Returns (Newton iterations, cuts).
    pub(super) fn advance_schedules(
        &mut self,
        body: &Body,
        target: usize,
        steps: usize,
    ) -> Result<(usize, usize), SolveError> {
        self.advance_between(body, (target - 1) as Real, target as Real, target, steps)
    }

    /// Load control from the current state, solved at pseudo-time `from` (step units), to
    /// pseudo-time `to`, up or down (a fracture search moves the load both ways), in
    /// increments of at most a step halved when they do not converge; `step` names the step
    /// in errors. Returns (Newton iterations, cuts).
    pub(crate) fn advance_between(
        &mut self,
        body: &Body,
        from: Real,
        to: Real,
        step: usize,
        steps: usize,
    ) -> Result<(usize, usize), SolveError> {
        let (end, up) = (to, to >= from);
        let mut t = from;
        let mut size = IncrementSize::default();
        let mut iterations = 0;
        while if up { t < end } else { t > end } {
            let dt = size.fraction();
            let t1 = if (end - t).abs() <= dt * (1.0 + 1e-12) {
                end
            } else if up {
                t + dt
            } else {
                t - dt
            };
            let saved = self.u.clone();
            self.increment_pivots = 0;
            match self.increment(body, t1, steps) {
                Ok(n) => {
                    iterations += n;
                    self.step_pivots = self.step_pivots.max(self.increment_pivots);
                    t = t1;
                    size.succeeded();
                    if self.path.len() == PATH_POINTS {
                        self.path.remove(0);
                    }
                    self.path.push((t1, self.u.clone()));
                }
                Err(failure) => {
                    iterations += failure.solves;
                    self.u = saved;
                    size.retry(body, step, failure)?;
                }
            }
        }
        Ok((iterations, size.cuts))
    }

    /// One load-control increment from the current state to pseudo-time `t1`: the path
    /// extrapolated from the last converged states, or else a tangent predictor (either also
    /// moves the prescribed supports), then Newton corrections with a line search. Returns the
    /// Newton iterations (tangent solves).
    pub(super) fn increment(
        &mut self,
        body: &Body,
        t1: Real,
        steps: usize,
    ) -> Result<usize, IncrementFailure> {
        let settings = body.newton;
        let nd = body.dof_count();
        let forces = self.forces_at(body, t1, steps);
        let prescribed = prescribed_at(body, t1, steps);
        self.follower_time = (t1, steps);
        if !body.pressures.is_empty() {
            super::follower_forces(body, &self.u, t1, steps, &mut self.follower);
        }
        let reference = norm(&self.applied(&forces));
        if let Some(s) = self.solver.as_mut() {
            s.set_reference(reference);
        }
        let mut convergence = Convergence::new(settings.tolerance);
        let mut internal = vec![0.0; nd];
        // Start from the path extrapolated through the last converged states when that is
        // closer to equilibrium; otherwise take a tangent predictor from the current state.
        let extrapolated = self.extrapolate(body, t1, &forces, &prescribed, &mut internal);
        let fail = |reason: String, history: &[Real]| IncrementFailure {
            reason,
            history: history.to_vec(),
            solves: history.len().saturating_sub(usize::from(extrapolated)),
        };
        let (mut last_step, mut iterations) = if extrapolated {
            (Real::INFINITY, 0)
        } else {
            let last_step = self
                .tangent_predictor(body, &forces, &prescribed, &mut internal)
                .map_err(|r| fail(r, &convergence.history))?;
            (last_step, 1)
        };
        loop {
            let r = self.out_of_balance(body, &forces, &mut internal);
            let scale =
                force_scale(&self.dofs, &self.applied(&forces), &internal).max(self.force_floor);
            let rnorm = norm(&r);
            if convergence
                .record(Convergence::relative(rnorm, scale))
                .is_err()
            {
                return Err(fail(
                    "the residual is not finite (a member collapsed or the iteration diverged)"
                        .to_string(),
                    &convergence.history,
                ));
            }
            let u_norm = norm(&self.u).max(self.displacement_floor);
            if convergence.within_tolerance()
                && (last_step <= settings.displacement_tolerance * u_norm.max(Real::MIN_POSITIVE)
                    || rnorm == 0.0)
            {
                self.converged(scale, u_norm);
                self.residual_history = convergence.history;
                return Ok(iterations);
            }
            if iterations >= settings.max_iterations {
                return Err(fail(
                    format!(
                        "no convergence in {} Newton iterations",
                        settings.max_iterations
                    ),
                    &convergence.history,
                ));
            }
            if settings.interrupt.is_raised() {
                return Err(fail(INTERRUPTED.to_string(), &convergence.history));
            }
            self.refactor(body)
                .map_err(|reason| fail(reason, &convergence.history))?;
            let mut delta = r.clone();
            self.solve(&mut delta)
                .map_err(|r| fail(r, &convergence.history))?;
            last_step = self.line_search(body, &forces, &delta, rnorm, &mut internal);
            iterations += 1;
        }
    }

    /// The tangent predictor from the current state: `K_ff Δu_f = F_f − f_int,f − K_fs Δu_s`,
    /// which also moves the prescribed supports to `prescribed`. Returns the length moved.
    pub(super) fn tangent_predictor(
        &mut self,
        body: &Body,
        forces: &[Real],
        prescribed: &[Real],
        internal: &mut [Real],
    ) -> Result<Real, String> {
        let nd = body.dof_count();
        let mut rhs = self.out_of_balance(body, forces, internal);
        self.refactor(body)?;
        let mut du_s = vec![0.0; nd];
        let mut moved = false;
        for &dof in &self.dofs.supported {
            du_s[dof] = prescribed[dof] - self.u[dof];
            moved |= du_s[dof] != 0.0;
        }
        if moved {
            let mut k_du = vec![0.0; nd];
            tangent_times(body, &self.u, &du_s, &mut k_du);
            for (i, &dof) in self.dofs.free.iter().enumerate() {
                rhs[i] -= k_du[dof];
            }
        }
        self.solve(&mut rhs)?;
        for &dof in &self.dofs.supported {
            self.u[dof] = prescribed[dof];
        }
        for (i, &dof) in self.dofs.free.iter().enumerate() {
            self.u[dof] += rhs[i];
        }
        Ok(norm(&rhs))
    }

    /// Move to the extrapolation at pseudo-time `t1` of the converged path (a secant through
    /// the last two states, or a quadratic through the last three), supports at `prescribed`,
    /// when it leaves a smaller out-of-balance than the current state with the supports moved.
    /// Returns whether it moved; Newton iterates from there, so the answer is the same, only
    /// reached from closer (on a smooth path the first out-of-balance is orders smaller than
    /// the load increment, and a tangent solve is saved).
    pub(super) fn extrapolate(
        &mut self,
        body: &Body,
        t1: Real,
        forces: &[Real],
        prescribed: &[Real],
        internal: &mut [Real],
    ) -> bool {
        let n = self.path.len();
        // Only from the newest converged state, which the increment starts from.
        if n < 2 || self.path[n - 1].1 != self.u {
            return false;
        }
        let current = self.u.clone();
        for &dof in &self.dofs.supported {
            self.u[dof] = prescribed[dof];
        }
        let mut best = norm(&self.out_of_balance(body, forces, internal));
        let mut chosen = None;
        for points in 2..=n {
            let tail = &self.path[n - points..];
            let times: Vec<Real> = tail.iter().map(|p| p.0).collect();
            let weights = lagrange_weights(&times, t1);
            for &dof in &self.dofs.free {
                self.u[dof] = tail.iter().zip(&weights).map(|(p, w)| w * p.1[dof]).sum();
            }
            let r = norm(&self.out_of_balance(body, forces, internal));
            if r.is_finite() && r < best {
                best = r;
                chosen = Some(self.u.clone());
            }
        }
        match chosen {
            Some(u) => {
                self.u = u;
                true
            }
            None => {
                self.u = current;
                false
            }
        }
    }
}
