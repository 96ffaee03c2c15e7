//! Crossing a contact step in increments: halved when Newton fails, doubled again after two successes, each started from the extrapolated path (the contact counterpart of a body's load control).
//!
//! A step goes from the last converged pseudo-time to the step's, with the loads, prescribed
//! support displacements and obstacle offsets interpolated between steps. An increment that
//! fails (Newton not converged, a state not finite, a tangent that cannot be factored) is
//! undone: the displacements, the contact set, the normals and the condensed path's contact
//! forces go back to the last converged state, and the increment is halved
//! ([`IncrementSize`], as for a body). The condensed path cuts as the coupled one does and
//! stays condensed (its loads are interpolated within a step as the coupled path's are); it
//! gives way to the coupled solve only where a body cannot be condensed on the nodes its
//! contacts reach. Only the converged end of the step is reported.

use crate::contact::condensed::CondensedState;
use crate::contact::evaluate::friction_key;
use crate::contact::problem::{newton_limits, Problem, PATH_POINTS};
use crate::contact::report::ContactStep;
use crate::contact::{ActiveContact, Committed, ContactError, ContactSet, ContactSolver, Obstacle};
use crate::linalg::CholeskyError;
use crate::linkage::body_state::{loads_at, norm, prescribed_at};
use crate::linkage::{lagrange_weights, Body, IncrementSize};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;
use std::time::Instant;

/// A tangential load within this fraction of μ N is at the edge of sliding.
const EDGE: Real = 1e-6;

/// What an increment is undone to: the last converged state.
pub(crate) struct Converged {
    u: Vec<Vec<Real>>,
    active: ContactSet,
    normals: HashMap<ActiveContact, Vector3<Real>>,
    /// The condensed path's state (`None` on the coupled path).
    condensed: Option<CondensedState>,
}

impl ContactSolver {
    /// Solve `step` of `steps` for `bodies` (the ones given to [`ContactSolver::new`]).
    /// Steps are meant to come in order: each starts from the displacements and the contact
    /// set of the step before (asking for step 0 starts over). A step Newton cannot cross at
    /// once is crossed in halved increments (`cuts` in the result); it fails when an increment
    /// of `1/2^max_cuts` of a step (the smallest `[bodies.newton] max_cuts`) still fails.
    pub fn solve_step(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
    ) -> Result<ContactStep, ContactError> {
        let out = self.settle_step(bodies, obstacles, step, steps)?;
        let reported = self.report(bodies, obstacles, step, steps, out)?;
        self.commit_friction(bodies, obstacles, step as Real, steps, step);
        Ok(reported)
    }

    /// [`ContactSolver::solve_step`] without the report of the settled state (its counts
    /// only): fracture reports a step once its members have broken.
    pub(crate) fn settle_step(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
    ) -> Result<ContactStep, ContactError> {
        let restart = step == 0 || step < self.step;
        if restart {
            for p in &mut self.parts {
                p.u.iter_mut().for_each(|v| *v = 0.0);
            }
            self.active = ContactSet::default();
            self.normals.clear();
            self.path = vec![(0.0, self.parts.iter().map(|p| p.u.clone()).collect())];
            if let Some(h) = self.friction.as_mut() {
                h.clear();
                h.offsets = obstacles.iter().map(|o| o.offset_at(0.0, steps)).collect();
            }
        }
        if let Some(c) = self.condensed.as_mut() {
            c.start_step(restart);
        }
        let start = if restart { 0 } else { self.step };
        self.step = step;
        self.linear_before = self.coupled.linear_iterations();
        let max_cuts = bodies.iter().map(|b| b.newton.max_cuts).min().unwrap_or(10);
        let end = step as Real;
        let mut t = start as Real;
        let mut size = IncrementSize::default();
        let mut out = ContactStep::default();
        loop {
            // An increment crosses at most a step (the condensed path, uncut, the whole way to
            // the step asked for, as it always has).
            let whole = self.condensed.is_some() && size.depth == 0;
            let t1 = if whole || end - t <= size.fraction() * (1.0 + 1e-12) {
                end
            } else {
                t + size.fraction()
            };
            let saved = self.converged_state();
            if let Some(c) = self.condensed.as_mut() {
                c.aim(t1, steps);
            }
            // Every increment starts from the last converged state: the shells' sides too.
            self.geometry
                .record_sides(bodies, &self.parts, &self.active);
            let offsets_there = obstacles.iter().map(|o| o.offset_at(t, steps)).collect();
            self.geometry
                .record_crossings(bodies, &self.parts, &self.active, offsets_there);
            self.extrapolate(bodies, obstacles, t1, steps, step);
            match self.settle(bodies, obstacles, (t1, steps), step, None) {
                Ok(done) => {
                    out.contact_iterations += done.contact_iterations;
                    out.newton_iterations += done.newton_iterations;
                    out.stabilised |= done.stabilised;
                    out.warnings.extend(done.warnings);
                    if let Some(c) = self.condensed.as_mut() {
                        c.solved(t1);
                    }
                    if self.path.len() == PATH_POINTS {
                        self.path.remove(0);
                    }
                    self.path
                        .push((t1, self.parts.iter().map(|p| p.u.clone()).collect()));
                    size.succeeded();
                    t = t1;
                    if t >= end {
                        break;
                    }
                    // Friction's history moves on with each converged increment (the end of
                    // the step is committed once it is reported).
                    self.commit_friction(bodies, obstacles, t, steps, step);
                }
                Err(e) if self.friction.is_some() && gives_up(&e, &size, max_cuts) => {
                    // With friction, a body that will not settle may be one pushed along its
                    // contacts beyond μ N: say so by name (judged where the attempt ended,
                    // which has found the contacts the loads press it on).
                    let sliding = self.sliding(bodies, obstacles, step, steps);
                    self.restore_increment(saved)?;
                    if let Some(sliding) = sliding {
                        return Err(sliding);
                    }
                    if !retried(&e) {
                        return Err(e);
                    }
                    if !size.failed(max_cuts) {
                        return Err(cut_to(e, step, &size));
                    }
                }
                Err(e) if retried(&e) => {
                    if let ContactError::NotConverged { history, .. } = &e {
                        out.newton_iterations += history.len().saturating_sub(1);
                    }
                    self.restore_increment(saved)?;
                    if !size.failed(max_cuts) {
                        return Err(cut_to(e, step, &size));
                    }
                }
                Err(e) => return Err(e),
            }
        }
        out.cuts = size.cuts;
        Ok(out)
    }

    /// Settle at pseudo-time `t` of `steps` (within `step`) from the current state, solved at
    /// pseudo-time `from`, in one increment: breaking members move the load back and forth
    /// within a step (see `ContactFracture`). The converged path is left alone.
    pub(crate) fn settle_at(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        from: Real,
        t: Real,
        steps: usize,
        step: usize,
    ) -> Result<ContactStep, ContactError> {
        self.geometry
            .record_sides(bodies, &self.parts, &self.active);
        let offsets_there = obstacles.iter().map(|o| o.offset_at(from, steps)).collect();
        self.geometry
            .record_crossings(bodies, &self.parts, &self.active, offsets_there);
        self.settle(bodies, obstacles, (t, steps), step, None)
    }

    /// Start the converged path over from the current state at the step solved: after members
    /// broke, the states before belong to another structure.
    pub(crate) fn restart_path(&mut self) {
        self.path = vec![(
            self.step as Real,
            self.parts.iter().map(|p| p.u.clone()).collect(),
        )];
    }

    /// The problem of the current state with `set`, `forces` (N per body DOF; following
    /// pressures at pseudo-time `time`) and the obstacles at `offsets` (m), for `step`: the
    /// contact Newton's limits and friction's history.
    pub(crate) fn problem<'a>(
        &'a self,
        bodies: &'a [Body],
        set: &'a ContactSet,
        (forces, time): (&'a [Vec<Real>], (Real, usize)),
        offsets: &'a [Vector3<Real>],
        step: usize,
    ) -> Problem<'a> {
        let (tolerance, max_iterations) = newton_limits(bodies);
        Problem {
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
            inertia: None,
        }
    }

    /// The sliding of a body at `step` of `steps`, from the current state: a body whose
    /// applied loads at the step have a part along its contacts (perpendicular to the sum of
    /// their normal forces) beyond the `Σ μ f_N` they hold there, or equal to it to within
    /// `EDGE` ([`ContactError::EdgeOfSliding`]). `None` when no body is.
    fn sliding(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        step: usize,
        steps: usize,
    ) -> Option<ContactError> {
        self.friction.as_ref()?;
        let t = step as Real;
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset_at(t, steps)).collect();
        // The contacts where the attempt ended (the set it solved last is not kept).
        let found = self.look(bodies, &self.active.clone(), &offsets, &[]);
        let history = self.friction.as_ref()?;
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, t, steps)).collect();
        let problem = self.problem(bodies, &found, (&forces, (t, steps)), &offsets, step);
        let mut normals = self.normals.clone();
        let evaluated = problem.evaluate(&mut normals, &self.parts);
        // Per body: the mean direction its contacts press it along, and the largest μ among
        // them. Where the attempt ended the depths (and so the normal forces) are those of a
        // state out of balance; the load's own normal part is what the contacts must carry.
        let mut normal = vec![Vector3::<Real>::zeros(); bodies.len()];
        let mut mu = vec![0.0; bodies.len()];
        for e in &evaluated.list {
            let Some(n) = e.normal else { continue };
            let (key, _) = friction_key(&e.contact);
            let (m, _) = history.law(&key);
            for &(b, _, w) in &e.nodes {
                normal[b] += n * w;
                mu[b] = Real::max(mu[b], m);
            }
        }
        let mut worst: Option<(usize, Real, Real)> = None;
        for (b, body) in bodies.iter().enumerate() {
            let d = self.parts[b].dofs.dofs_per_node;
            let mut load = Vector3::zeros();
            for node in 0..body.nodes.len() {
                load += crate::linkage::body_state::node_vector(&forces[b], d, node);
            }
            let Some(n) = normal[b].try_normalize(0.0) else {
                continue;
            };
            let along = (load - n * load.dot(&n)).norm();
            let capacity = mu[b] * load.dot(&n).abs();
            // At μ N to within EDGE it is at the edge of sliding (told so, not "slides").
            if along > 1e-9 * load.norm()
                && along >= capacity * (1.0 - EDGE)
                && worst.is_none_or(|(_, a, c)| along - capacity > a - c)
            {
                worst = Some((b, along, capacity));
            }
        }
        let (b, load, capacity) = worst?;
        if load <= capacity * (1.0 + EDGE) {
            return Some(ContactError::EdgeOfSliding {
                step,
                body: bodies[b].name.clone(),
                load,
                capacity,
            });
        }
        Some(ContactError::Sliding {
            step,
            body: bodies[b].name.clone(),
            load,
            capacity,
        })
    }

    /// Commit friction's history at the converged state at pseudo-time `t` of `steps`: each
    /// active contact's tangential force and slip, the displacements and obstacle offsets
    /// (relative motion is measured from here on). A contact no longer active forgets its
    /// history.
    pub(crate) fn commit_friction(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        t: Real,
        steps: usize,
        step: usize,
    ) {
        let Some(history) = self.friction.as_ref() else {
            return;
        };
        let offsets: Vec<Vector3<Real>> = obstacles.iter().map(|o| o.offset_at(t, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, t, steps)).collect();
        let problem = self.problem(bodies, &self.active, (&forces, (t, steps)), &offsets, step);
        let mut normals = self.normals.clone();
        let evaluated = problem.evaluate(&mut normals, &self.parts);
        let mut committed = HashMap::new();
        for e in &evaluated.list {
            let Some(tangential) = &e.tangential else {
                continue;
            };
            let (key, _) = friction_key(&e.contact);
            let before = history.committed.get(&key).copied().unwrap_or_default();
            committed.insert(
                key,
                Committed {
                    force: tangential.force,
                    slip: before.slip + tangential.slip,
                },
            );
        }
        let u = self.parts.iter().map(|p| p.u.clone()).collect();
        if let Some(history) = self.friction.as_mut() {
            history.committed = committed;
            history.u = u;
            history.offsets = offsets;
        }
    }

    /// The state an increment starts from.
    pub(crate) fn converged_state(&self) -> Converged {
        Converged {
            u: self.parts.iter().map(|p| p.u.clone()).collect(),
            active: self.active.clone(),
            normals: self.normals.clone(),
            condensed: self.condensed.as_ref().map(|c| c.saved()),
        }
    }

    /// Undo a failed increment (the condensed path's contact forces too, where they still
    /// fit its candidates).
    pub(crate) fn restore(&mut self, saved: Converged) {
        self.restore_keeping(saved);
    }

    /// [`ContactSolver::restore`], then leave the condensed path unless it was restored: the
    /// attempt left it, or a body's candidates grew so that the saved forces no longer fit
    /// (the coupled solve goes on from the restored displacements).
    fn restore_increment(&mut self, saved: Converged) -> Result<(), ContactError> {
        if !self.restore_keeping(saved) {
            self.leave_condensed()?;
        }
        Ok(())
    }

    /// Undo a failed increment; whether the condensed path's state was restored.
    fn restore_keeping(&mut self, saved: Converged) -> bool {
        // Crossings found in the failed increment belong to a state that is gone.
        self.geometry.forget_crossings_found();
        self.restore_state(saved)
    }

    /// Go back to the state of a set that flipped (`saved` when it first flipped, within the
    /// same settle: the crossings found so far stay); leave the condensed path unless its
    /// state was restored.
    pub(crate) fn restore_flip(&mut self, saved: Converged) -> Result<(), ContactError> {
        if !self.restore_state(saved) {
            self.leave_condensed()?;
        }
        Ok(())
    }

    /// Put back the displacements, the contact set, the normals and the condensed path's
    /// state of `saved`; whether the condensed path's state was restored.
    fn restore_state(&mut self, saved: Converged) -> bool {
        for (p, u) in self.parts.iter_mut().zip(saved.u) {
            p.u = u;
        }
        self.active = saved.active;
        self.normals = saved.normals;
        match (self.condensed.as_mut(), saved.condensed) {
            (Some(c), Some(state)) => c.restore(state),
            _ => false,
        }
    }

    /// Leave the condensed path (if on it) for the coupled solve of all bodies.
    pub(crate) fn leave_condensed(&mut self) -> Result<(), ContactError> {
        if self.condensed.take().is_some() {
            let t = Instant::now();
            self.coupled.rebuild(&self.parts)?;
            self.times.symbolic += t.elapsed().as_secs_f64();
        }
        Ok(())
    }

    /// On the coupled path, move to the extrapolation at pseudo-time `t1` of the converged path
    /// (a secant through the last two states, or a quadratic through the last three), supports
    /// at their prescribed displacements, when its out-of-balance with the current contact set
    /// is smaller than that of the current state with the supports moved. Returns whether it
    /// moved. Newton iterates from there, so the answer is the same, only reached from closer.
    fn extrapolate(
        &mut self,
        bodies: &[Body],
        obstacles: &[Obstacle],
        t1: Real,
        steps: usize,
        step: usize,
    ) -> bool {
        let n = self.path.len();
        let current_is_newest = n >= 2
            && self.path[n - 1]
                .1
                .iter()
                .zip(&self.parts)
                .all(|(u, p)| *u == p.u);
        if self.condensed.is_some() || !current_is_newest {
            return false;
        }
        let t = Instant::now();
        let offsets: Vec<Vector3<Real>> =
            obstacles.iter().map(|o| o.offset_at(t1, steps)).collect();
        let forces: Vec<Vec<Real>> = bodies.iter().map(|b| loads_at(b, t1, steps)).collect();
        for (part, body) in self.parts.iter_mut().zip(bodies) {
            let prescribed = prescribed_at(body, t1, steps);
            for &dof in &part.dofs.supported {
                part.u[dof] = prescribed[dof];
            }
        }
        let current: Vec<Vec<Real>> = self.parts.iter().map(|p| p.u.clone()).collect();
        let mut best = self.out_of_balance_norm(bodies, (&forces, (t1, steps)), &offsets, step);
        let mut chosen = None;
        for points in 2..=n {
            let tail = &self.path[n - points..];
            let times: Vec<Real> = tail.iter().map(|p| p.0).collect();
            let weights = lagrange_weights(&times, t1);
            for (b, part) in self.parts.iter_mut().enumerate() {
                for &dof in &part.dofs.free {
                    part.u[dof] = tail
                        .iter()
                        .zip(&weights)
                        .map(|(p, w)| w * p.1[b][dof])
                        .sum();
                }
            }
            let r = self.out_of_balance_norm(bodies, (&forces, (t1, steps)), &offsets, step);
            if r.is_finite() && r < best {
                best = r;
                chosen = Some(self.parts.iter().map(|p| p.u.clone()).collect::<Vec<_>>());
            }
        }
        let moved = chosen.is_some();
        for (p, u) in self.parts.iter_mut().zip(chosen.unwrap_or(current)) {
            p.u = u;
        }
        self.times.assembly += t.elapsed().as_secs_f64();
        moved
    }

    /// The norm of the coupled out-of-balance force at the current displacements with the
    /// current contact set (its normals taken from a copy of the cache), N.
    fn out_of_balance_norm(
        &self,
        bodies: &[Body],
        (forces, time): (&[Vec<Real>], (Real, usize)),
        offsets: &[Vector3<Real>],
        step: usize,
    ) -> Real {
        let problem = self.problem(bodies, &self.active, (forces, time), offsets, step);
        let mut normals = self.normals.clone();
        let evaluated = problem.evaluate(&mut normals, &self.parts);
        let (r, _) = self
            .coupled
            .out_of_balance(&problem, &self.parts, &evaluated);
        norm(&r)
    }
}

/// Whether the failure `e` ends the step: not retried, or retried at the smallest increment
/// `max_cuts` allows.
fn gives_up(e: &ContactError, size: &IncrementSize, max_cuts: usize) -> bool {
    !retried(e) || size.depth >= max_cuts
}

/// Whether a failed increment is retried with half the increment: Newton did not converge,
/// the state is not finite, or the tangent could not be factored even stabilised.
fn retried(e: &ContactError) -> bool {
    matches!(
        e,
        ContactError::NotConverged { .. }
            | ContactError::NotFinite { .. }
            | ContactError::Factorization(
                CholeskyError::NonPositivePivot { .. } | CholeskyError::NearlySingular { .. }
            )
    )
}

/// The error of step `step` after its smallest increment failed with `e`: how far it was cut.
fn cut_to(e: ContactError, step: usize, size: &IncrementSize) -> ContactError {
    let (reason, history) = match e {
        ContactError::NotConverged {
            reason, history, ..
        } => (reason, history),
        ContactError::NotFinite { .. } => (
            "the solution is not finite (check the penalty and the loads)".to_string(),
            Vec::new(),
        ),
        other => (other.to_string(), Vec::new()),
    };
    ContactError::NotConverged {
        step,
        depth: size.depth,
        cuts: size.cuts,
        reason,
        history,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failures_newton_can_get_past_by_cutting_are_retried_and_report_the_depth() {
        let failed = ContactError::NotConverged {
            step: 3,
            depth: 0,
            cuts: 0,
            reason: "no convergence in 4 Newton iterations".to_string(),
            history: vec![1e-2, 1e-4],
        };
        assert!(retried(&failed));
        assert!(retried(&ContactError::NotFinite { step: 3 }));
        assert!(retried(&ContactError::Factorization(
            CholeskyError::NonPositivePivot { dof: 0 }
        )));
        // A body no contact holds is not helped by smaller increments.
        assert!(!retried(&ContactError::Unsupported {
            step: 3,
            body: "bar".to_string(),
            iterations: 50,
            contacts: 0,
        }));
        let mut size = IncrementSize::default();
        assert!(size.failed(2) && size.failed(2) && !size.failed(2));
        let message = cut_to(failed, 3, &size).to_string();
        assert!(
            message.starts_with("step 3: equilibrium with contact did not converge, even with its increment cut to 1/4 of the step (2 halvings deep, the most [bodies.newton] max_cuts allows; 2 halvings in this step in all"),
            "{message}"
        );
        assert!(message.contains("no convergence in 4 Newton iterations; relative residuals of the last attempt: [1.0e-2, 1.0e-4]"), "{message}");
    }
}
