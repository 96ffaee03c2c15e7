//! One V-cycle, the application of the preconditioner: smooth, restrict, recurse, prolong,
//! smooth.

use super::setup::SmoothedAggregation;
use super::smoother::{chebyshev, Product, SmootherMatrix};
use super::transfer::Transfer;
use crate::linalg::{Preconditioner, SymmetricCsr};
use crate::Real;

/// Vectors one V-cycle needs on a level, kept between cycles.
#[derive(Default)]
pub(super) struct Work {
    pub(super) r: Vec<Real>,
    pub(super) d: Vec<Real>,
    coarse_b: Vec<Real>,
    coarse_x: Vec<Real>,
}

/// One level of the hierarchy: its smoother's matrix (full rows only when the smoother uses
/// them and the level is not the finest, which the caller owns), the smoother's data, and the
/// transfer to the next level.
pub(super) struct Level {
    pub(super) matrix: Option<SymmetricCsr>,
    pub(super) smoother: SmootherMatrix,
    pub(super) inverse_diagonal: Vec<Real>,
    pub(super) lambda_max: Real,
    pub(super) transfer: Transfer,
}

impl Level {
    /// The smoother's product (`fine` is the finest matrix).
    fn product<'a>(&'a self, fine: &'a SymmetricCsr) -> &'a dyn Product {
        self.smoother.product(self.matrix.as_ref().unwrap_or(fine))
    }
}

impl SmoothedAggregation {
    /// One V-cycle from a zero guess for `A x = b` on `level` (`fine` is the finest matrix).
    fn cycle(&mut self, level: usize, fine: &SymmetricCsr, b: &[Real], x: &mut [Real]) {
        if level == self.levels.len() {
            x.copy_from_slice(b);
            self.coarse.solve_in_place(x);
            return;
        }
        let mut w = std::mem::take(&mut self.work[level]);
        let n = b.len();
        for v in [&mut w.r, &mut w.d] {
            v.resize(n, 0.0);
        }
        let coarse_n = self.sizes[level + 1];
        w.coarse_b.resize(coarse_n, 0.0);
        w.coarse_x.resize(coarse_n, 0.0);
        {
            let lv = &self.levels[level];
            let a = lv.product(fine);
            chebyshev(a, &lv.inverse_diagonal, lv.lambda_max, b, x, &mut w, true);
            a.residual(b, x, &mut w.r);
            lv.transfer.restrict(&w.r, &mut w.coarse_b);
        }
        self.cycle(level + 1, fine, &w.coarse_b, &mut w.coarse_x);
        let lv = &self.levels[level];
        lv.transfer.prolong_add(&w.coarse_x, x);
        chebyshev(
            lv.product(fine),
            &lv.inverse_diagonal,
            lv.lambda_max,
            b,
            x,
            &mut w,
            false,
        );
        self.work[level] = w;
    }
}

impl Preconditioner for SmoothedAggregation {
    /// `z = M⁻¹ r`: one V-cycle from a zero guess.
    fn apply(&mut self, fine: &SymmetricCsr, r: &[Real], z: &mut [Real]) {
        self.cycle(0, fine, r, z);
    }
}
