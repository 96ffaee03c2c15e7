//! Crisfield's cylindrical arc-length method, which follows the path through limit points.
//!
//! The load factor is an unknown, and each increment keeps the length of the free
//! displacement increment.

use super::{IncrementFailure, IncrementSize, NewtonEquilibrium, INTERRUPTED};
use crate::linkage::body_state::{full_loads, norm};
use crate::linkage::step_state::force_scale;
use crate::linkage::{Body, Convergence, SolveError};
use crate::Real;

impl NewtonEquilibrium {
    /// Arc length: advance one step of `length` along the path, in sub-increments that are
    /// halved when they do not converge. Returns (Newton iterations, cuts).
    pub(super) fn advance_arc_length(
        &mut self,
        body: &Body,
        target: usize,
        length: Real,
    ) -> Result<(usize, usize), SolveError> {
        let mut covered = 0.0;
        let mut size = IncrementSize::default();
        let mut iterations = 0;
        while covered < length * (1.0 - 1e-12) {
            let arc = (length * size.fraction()).min(length - covered);
            let (u0, l0, p0) = (self.u.clone(), self.lambda, self.previous.clone());
            match self.arc_increment(body, arc) {
                Ok(n) => {
                    iterations += n;
                    covered += arc;
                    size.succeeded();
                }
                Err(failure) => {
                    iterations += failure.solves;
                    (self.u, self.lambda, self.previous) = (u0, l0, p0);
                    size.retry(body, target, failure)?;
                }
            }
        }
        Ok((iterations, size.cuts))
    }

    /// One increment of Crisfield's cylindrical arc-length method: `|Δu_f| = arc`, with the
    /// load factor λ an unknown. Predictor along the tangent `K δu_t = F_ref`, in the direction
    /// of the previous increment; corrections `δu = δu_R + δλ δu_t` with δλ from the
    /// constraint's quadratic, the root keeping the increment closest to the previous one.
    pub(super) fn arc_increment(
        &mut self,
        body: &Body,
        arc: Real,
    ) -> Result<usize, IncrementFailure> {
        let settings = body.newton;
        let nd = body.dof_count();
        let reference = full_loads(body);
        let ref_f: Vec<Real> = self.dofs.free.iter().map(|&dof| reference[dof]).collect();
        let ref_norm = norm(&reference);
        let mut convergence = Convergence::new(settings.tolerance);
        let fail = |reason: String, history: &[Real]| IncrementFailure {
            reason,
            history: history.to_vec(),
            solves: history.len(),
        };
        if ref_norm == 0.0 {
            return Err(fail(
                "the arc-length method needs loads to scale: add [[bodies.loads]]".to_string(),
                &convergence.history,
            ));
        }
        let u0 = self.u.clone();
        let lambda0 = self.lambda;
        self.refactor(body)
            .map_err(|r| fail(r, &convergence.history))?;
        let mut dt = ref_f.clone();
        self.solve(&mut dt)
            .map_err(|r| fail(r, &convergence.history))?;
        let dt_norm = norm(&dt);
        if !(dt_norm.is_finite() && dt_norm > 0.0) {
            return Err(fail(
                "the tangent solve along the reference load failed".to_string(),
                &convergence.history,
            ));
        }
        // Follow the previous direction (Feng's criterion); the first step loads positively.
        let dot: Real = self.previous.iter().zip(&dt).map(|(a, b)| a * b).sum();
        let sign = if dot < 0.0 { -1.0 } else { 1.0 };
        let mut dlambda = sign * arc / dt_norm;
        let mut du: Vec<Real> = dt.iter().map(|v| v * dlambda).collect();
        let apply = |eq: &mut Self, du: &[Real], dlambda: Real| {
            for (i, &dof) in eq.dofs.free.iter().enumerate() {
                eq.u[dof] = u0[dof] + du[i];
            }
            eq.lambda = lambda0 + dlambda;
        };
        apply(self, &du, dlambda);
        let mut last_step = arc;
        let mut iterations = 1;
        let mut internal = vec![0.0; nd];
        loop {
            let forces: Vec<Real> = reference.iter().map(|f| f * self.lambda).collect();
            let r = self.out_of_balance(body, &forces, &mut internal);
            let scale = force_scale(&self.dofs, &forces, &internal)
                .max(ref_norm)
                .max(self.force_floor);
            if let Err(e) = convergence.record(Convergence::relative(norm(&r), scale)) {
                return Err(fail(e.to_string(), &convergence.history));
            }
            let u_norm = norm(&self.u).max(self.displacement_floor);
            if convergence.within_tolerance()
                && last_step <= settings.displacement_tolerance * u_norm.max(arc)
            {
                self.converged(scale, u_norm);
                self.previous = du;
                self.residual_history = convergence.history;
                return Ok(iterations);
            }
            if iterations >= settings.max_iterations {
                return Err(fail(
                    format!("no convergence in {} iterations", settings.max_iterations),
                    &convergence.history,
                ));
            }
            if settings.interrupt.is_raised() {
                return Err(fail(INTERRUPTED.to_string(), &convergence.history));
            }
            self.refactor(body)
                .map_err(|reason| fail(reason, &convergence.history))?;
            let mut dr = r;
            self.solve(&mut dr)
                .map_err(|r| fail(r, &convergence.history))?;
            let mut dt = ref_f.clone();
            self.solve(&mut dt)
                .map_err(|r| fail(r, &convergence.history))?;
            // |Δu + δu_R + δλ δu_t|² = arc²
            let base: Vec<Real> = du.iter().zip(&dr).map(|(a, b)| a + b).collect();
            let a = dot_product(&dt, &dt);
            let b = 2.0 * dot_product(&dt, &base);
            let c = dot_product(&base, &base) - arc * arc;
            let disc = b * b - 4.0 * a * c;
            if disc.is_nan() || disc < 0.0 || a == 0.0 {
                return Err(fail(
                    "the arc-length constraint has no real root (the increment is too long here)"
                        .to_string(),
                    &convergence.history,
                ));
            }
            let q = -0.5 * (b + b.signum() * disc.sqrt());
            let roots = [q / a, if q != 0.0 { c / q } else { q / a }];
            let choose = |dl: Real| -> Real {
                base.iter()
                    .zip(&dt)
                    .zip(&du)
                    .map(|((x, t), d)| (x + dl * t) * d)
                    .sum()
            };
            let dl = if choose(roots[0]) >= choose(roots[1]) {
                roots[0]
            } else {
                roots[1]
            };
            let correction: Vec<Real> = dr.iter().zip(&dt).map(|(r, t)| r + dl * t).collect();
            last_step = norm(&correction);
            for (d, c) in du.iter_mut().zip(&correction) {
                *d += c;
            }
            dlambda += dl;
            apply(self, &du, dlambda);
            iterations += 1;
        }
    }
}

/// The dot product of two vectors of the same length.
fn dot_product(a: &[Real], b: &[Real]) -> Real {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
