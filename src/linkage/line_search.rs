//! Backtracking on the out-of-balance norm, shared by the Newton solvers.

use crate::Real;

/// Armijo backtracking (sufficient decrease 1e-4): `trial(s)` moves to the fraction `s` of the
/// correction and returns the residual norm there, for s = 1, 1/2, … 1/16; the first `s` with
/// `r ≤ (1 − 1e-4 s) r0` is accepted. Returns `(s, accepted)`. When none is accepted, `s` is the
/// best one tried (1 if every trial diverged) and the caller moves there: the state is the last
/// trial's, and the iteration limit decides.
pub(crate) fn backtrack(r0: Real, mut trial: impl FnMut(Real) -> Real) -> (Real, bool) {
    let mut best = (Real::INFINITY, 1.0);
    let mut s = 1.0;
    for _ in 0..5 {
        let r = trial(s);
        if r.is_finite() && r <= (1.0 - 1e-4 * s) * r0 {
            return (s, true);
        }
        if r < best.0 {
            best = (r, s);
        }
        s *= 0.5;
    }
    (if best.0.is_finite() { best.1 } else { 1.0 }, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn takes_the_first_sufficient_decrease_else_the_best() {
        // r(s) = |1 − 4 s|: s = 1 gives 3, s = 1/2 gives 1, s = 1/4 gives 0.
        let tried = std::cell::RefCell::new(Vec::new());
        let (s, ok) = backtrack(1.0, |s| {
            tried.borrow_mut().push(s);
            (1.0 - 4.0 * s).abs()
        });
        assert_eq!((s, ok), (0.25, true));
        assert_eq!(*tried.borrow(), vec![1.0, 0.5, 0.25]);
        // Nothing decreases: the smallest residual tried.
        let (s, ok) = backtrack(1.0, |s| 2.0 + s);
        assert_eq!((s, ok), (0.0625, false));
        // Everything diverges: the full step.
        assert_eq!(backtrack(1.0, |_| Real::NAN), (1.0, false));
    }
}
