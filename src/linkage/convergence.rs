//! The convergence monitor of every Newton iteration in the crate.
//!
//! The relative residual, its history, finiteness, and the round-off floor where it stalls.

use crate::Real;

/// The relative residual of one Newton iteration was not finite (NaN or infinite): a member
/// collapsed, or the iteration diverged.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the residual is not finite")]
pub struct NotFinite;

/// The relative residuals of one Newton solve, oldest first, and its tolerance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Convergence {
    /// Converged when the relative residual is at most this.
    pub tolerance: Real,
    /// Relative residual after each iteration so far.
    pub history: Vec<Real>,
}

/// Stalled at round-off: within this many tolerances and no longer falling by half.
const STALL_TOLERANCES: Real = 100.0;

impl Convergence {
    /// A monitor with no iterations yet.
    pub fn new(tolerance: Real) -> Self {
        Convergence {
            tolerance,
            history: Vec::new(),
        }
    }

    /// `out_of_balance / scale` (both N); with nothing to measure against, 0 when nothing is
    /// out of balance and infinite otherwise.
    pub fn relative(out_of_balance: Real, scale: Real) -> Real {
        if scale > 0.0 {
            out_of_balance / scale
        } else if out_of_balance > 0.0 {
            Real::INFINITY
        } else {
            0.0
        }
    }

    /// Record the relative residual of an iteration (kept even when it is not finite, so the
    /// history shows it).
    pub fn record(&mut self, relative: Real) -> Result<Real, NotFinite> {
        self.history.push(relative);
        if relative.is_finite() {
            Ok(relative)
        } else {
            Err(NotFinite)
        }
    }

    /// Whether the last residual is within the tolerance.
    pub fn within_tolerance(&self) -> bool {
        self.last().is_some_and(|r| r <= self.tolerance)
    }

    /// Whether the iteration has reached its round-off floor: at least three residuals, the
    /// last within 100× the tolerance and no longer below half the one before it (more
    /// iterations only stir round-off; seen: 1.79e-10 held for 30 iterations when faer's
    /// parallel rounding fell that way against a tolerance of 1e-10).
    pub fn stalled(&self) -> bool {
        self.stalled_within(STALL_TOLERANCES * self.tolerance)
    }

    /// Whether the iteration has stalled at or below the relative residual `bound`: at least
    /// three residuals, the last at most `bound` and no longer below half the one before it.
    pub fn stalled_within(&self, bound: Real) -> bool {
        let n = self.history.len();
        n >= 3 && self.history[n - 1] <= bound && self.history[n - 1] >= 0.5 * self.history[n - 2]
    }

    /// Whether the last residual fell below a tenth of the one before (fast convergence: a
    /// modified Newton step may keep its factorization).
    pub fn converging_fast(&self) -> bool {
        let n = self.history.len();
        n >= 2 && self.history[n - 1] < 0.1 * self.history[n - 2]
    }

    /// The last residual recorded.
    pub fn last(&self) -> Option<Real> {
        self.history.last().copied()
    }

    /// Residuals recorded so far.
    pub fn len(&self) -> usize {
        self.history.len()
    }

    /// Whether nothing was recorded yet.
    pub fn is_empty(&self) -> bool {
        self.history.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_residual_and_its_limits() {
        assert_eq!(Convergence::relative(1.0, 4.0), 0.25);
        assert_eq!(Convergence::relative(0.0, 0.0), 0.0);
        assert_eq!(Convergence::relative(1e-20, 0.0), Real::INFINITY);
        let mut c = Convergence::new(1e-10);
        assert_eq!(c.record(1.0), Ok(1.0));
        assert!(!c.within_tolerance() && !c.stalled());
        assert_eq!(c.record(Real::NAN), Err(NotFinite));
        assert_eq!(c.len(), 2);
    }

    #[test]
    fn stalls_only_near_the_tolerance_and_when_no_longer_falling() {
        let mut c = Convergence::new(1e-10);
        for r in [1e-2, 5e-9, 4e-9] {
            c.record(r).unwrap();
        }
        // 4e-9 ≤ 100 · 1e-10 and ≥ half of 5e-9.
        assert!(c.stalled() && !c.within_tolerance() && !c.converging_fast());
        let mut c = Convergence::new(1e-10);
        for r in [1e-2, 5e-9, 1e-9] {
            c.record(r).unwrap();
        }
        // Still falling by more than half.
        assert!(!c.stalled());
        let mut c = Convergence::new(1e-10);
        for r in [1e-2, 2e-2, 1.5e-2] {
            c.record(r).unwrap();
        }
        // Far above the floor: not stalled, just slow.
        assert!(!c.stalled());
        c.record(1e-11).unwrap();
        assert!(c.within_tolerance() && c.converging_fast());
    }
}
