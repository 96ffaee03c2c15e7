//! Anderson acceleration of the condensed Newton's iteration with a kept factor: an approximate one (large contact sets with friction), or an exact one whose frozen-normal tangent converges only linearly (frictionless).

use crate::Real;
use nalgebra::{DMatrix, DVector};
use std::collections::VecDeque;

/// Anderson mixing (type II, Walker & Ni 2011) of the fixed-point iteration `x ← x + g(x)`,
/// where `x` is the condensed state (contact forces at the candidates, N, then rigid
/// amplitudes, m) and `g(x)` the correction of a kept factor: a chord iteration, linear at a
/// rate of 0.3–0.5 in a shear with an approximate factor (see `FrictionInverse`), 0.4–0.97
/// with the exact frozen-normal one of balls pressed together (see `CHORD_RATE`). From the
/// last `depth` differences of iterates `Δx` and of corrections `Δg`, the next step is
///
/// `d = g − (ΔX + ΔG) γ`, `γ = argmin ‖g − ΔG γ‖`,
///
/// the step of the secant model that fits the last iterations; with no history, `d = g`.
/// `γ` is fitted on the force entries only (the norm of the residual is in N; amplitudes are
/// in m). The caller keeps the iteration safe: it takes `d` only when the exact residual falls
/// with it, and restarts the history when the map changes (a new factor, contacts held or let
/// go).
pub(crate) struct Anderson {
    depth: usize,
    /// The last iterate and its correction.
    last: Option<(Vec<Real>, Vec<Real>)>,
    /// Differences of successive iterates and of their corrections, oldest first.
    dx: VecDeque<Vec<Real>>,
    dg: VecDeque<Vec<Real>>,
    /// The number of leading entries (forces) the fit is made on.
    fitted: usize,
}

impl Anderson {
    /// Mixing over the last `depth` iterations, fitted on the first `fitted` entries.
    pub(crate) fn new(depth: usize, fitted: usize) -> Self {
        Anderson {
            depth,
            last: None,
            dx: VecDeque::new(),
            dg: VecDeque::new(),
            fitted,
        }
    }

    /// Forget the history (the map `g` changed).
    pub(crate) fn reset(&mut self) {
        self.last = None;
        self.dx.clear();
        self.dg.clear();
    }

    /// The number of differences kept.
    pub(crate) fn len(&self) -> usize {
        self.dx.len()
    }

    /// Take the iterate `x` and its correction `g` into the history and return the mixed step
    /// (`None` with no history yet, or when the fit is degenerate: then `g` itself).
    pub(crate) fn step(&mut self, x: &[Real], g: &[Real]) -> Option<Vec<Real>> {
        if let Some((x0, g0)) = self.last.take() {
            if x0.len() == x.len() {
                self.dx
                    .push_back(x.iter().zip(&x0).map(|(a, b)| a - b).collect());
                self.dg
                    .push_back(g.iter().zip(&g0).map(|(a, b)| a - b).collect());
                while self.dx.len() > self.depth {
                    self.dx.pop_front();
                    self.dg.pop_front();
                }
            } else {
                self.dx.clear();
                self.dg.clear();
            }
        }
        self.last = Some((x.to_vec(), g.to_vec()));
        let m = self.dg.len();
        if m == 0 {
            return None;
        }
        let n = self.fitted.min(g.len());
        let a = DMatrix::<Real>::from_fn(n, m, |i, j| self.dg[j][i]);
        let b = DVector::<Real>::from_fn(n, |i, _| g[i]);
        let svd = a.svd(true, true);
        let largest = svd.singular_values.max();
        if !(largest > 0.0 && largest.is_finite()) {
            return None;
        }
        // Directions the history hardly spans are left out of the fit (a near-singular fit
        // would extrapolate wildly).
        let gamma = svd.solve(&b, 1e-10 * largest).ok()?;
        if gamma.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let mut d = g.to_vec();
        for (j, &c) in gamma.iter().enumerate() {
            for (i, v) in d.iter_mut().enumerate() {
                *v -= c * (self.dx[j][i] + self.dg[j][i]);
            }
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a linear map the chord iteration `x ← x + P (b − A x)` converges at the rate of
    /// `I − P A`; Anderson mixing of depth n solves an n-dimensional problem in at most n + 1
    /// steps (GMRES-equivalent, Walker & Ni 2011, for type II with full history).
    #[test]
    fn mixing_solves_a_linear_chord_iteration_in_dimension_plus_one_steps() {
        let n = 6;
        let a = DMatrix::<Real>::from_fn(n, n, |i, j| {
            if i == j {
                4.0 + i as Real
            } else {
                ((i * 3 + j * 5) % 7) as Real * 0.3
            }
        });
        let b = DVector::<Real>::from_fn(n, |i, _| 1.0 + i as Real);
        let exact = a.clone().lu().solve(&b).expect("regular");
        // P: the inverse of A's diagonal only (a chord iteration with an approximate factor).
        let p = DMatrix::<Real>::from_fn(n, n, |i, j| if i == j { 1.0 / a[(i, i)] } else { 0.0 });
        let g = |x: &DVector<Real>| &p * (&b - &a * x);
        let mut plain = DVector::<Real>::zeros(n);
        for _ in 0..n + 1 {
            plain += g(&plain);
        }
        let mut mixing = Anderson::new(n, n);
        let mut x = DVector::<Real>::zeros(n);
        for _ in 0..n + 1 {
            let gx = g(&x);
            let d = mixing
                .step(x.as_slice(), gx.as_slice())
                .unwrap_or_else(|| gx.as_slice().to_vec());
            x += DVector::from_vec(d);
        }
        let error = (&x - &exact).amax() / exact.amax();
        let plain_error = (&plain - &exact).amax() / exact.amax();
        assert!(error <= 1e-10, "mixed: {error:e}");
        assert!(plain_error > 1e-3, "the plain iteration: {plain_error:e}");
        // A reset forgets: the next step is the plain correction.
        mixing.reset();
        assert_eq!(mixing.len(), 0);
        assert!(mixing.step(x.as_slice(), g(&x).as_slice()).is_none());
    }
}
