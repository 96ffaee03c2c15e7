//! Preconditioned conjugate gradients for `K_ff U_f = F_f` (paper Eq. 8) on bodies too large to
//! factor, warm-started from the best guess at hand.

use crate::linalg::{dot, SymmetricCsr};
use crate::Real;
use rayon::prelude::*;

/// An approximate inverse of a symmetric positive definite matrix, applied once per
/// conjugate-gradient iteration.
pub trait Preconditioner {
    /// `z = M⁻¹ r` for the matrix `a`.
    fn apply(&mut self, a: &SymmetricCsr, r: &[Real], z: &mut [Real]);
}

/// When conjugate gradients stop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgSettings {
    /// Stop when ‖b − A x‖ ≤ tolerance · ‖b‖ (default 1e-10).
    pub tolerance: Real,
    /// Give up after this many iterations (default 10,000).
    pub max_iterations: usize,
    /// A force scale, N: the target becomes `tolerance · max(‖b‖, reference_norm)`, so a
    /// Newton correction whose right-hand side is already tiny against the load is not solved
    /// to round-off (default 0: relative to ‖b‖ alone).
    pub reference_norm: Real,
}

impl Default for CgSettings {
    fn default() -> Self {
        CgSettings {
            tolerance: 1e-10,
            max_iterations: 10_000,
            reference_norm: 0.0,
        }
    }
}

/// How a solve went.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgReport {
    /// Iterations run.
    pub iterations: usize,
    /// True relative residual ‖b − A x‖ / max(‖b‖, reference) of the returned x, recomputed
    /// from scratch.
    pub residual: Real,
    /// Whether the tolerance was reached.
    pub converged: bool,
    /// Whether a direction of zero or negative curvature `pᵀAp ≤ 0` was met: the matrix is
    /// singular (a mechanism) or indefinite.
    pub breakdown: bool,
}

/// Solve `A x = b` from the initial guess in `x` (warm start; zeros for a cold one) with
/// preconditioned conjugate gradients. `x` holds the last iterate on return.
pub fn conjugate_gradient(
    a: &SymmetricCsr,
    m: &mut dyn Preconditioner,
    b: &[Real],
    x: &mut [Real],
    settings: CgSettings,
) -> CgReport {
    let n = a.n;
    let b_norm = dot(b, b).sqrt();
    let mut report = CgReport {
        iterations: 0,
        residual: 0.0,
        converged: true,
        breakdown: false,
    };
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return report;
    }
    let scale = b_norm.max(settings.reference_norm);
    let target = settings.tolerance * scale;
    let mut r = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut p = vec![0.0; n];
    let mut q = vec![0.0; n];
    // The recurrence residual drifts from the true one: when it claims convergence, check the
    // true residual and restart from it if it is not there yet.
    loop {
        a.multiply(x, &mut r);
        r.par_iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
        let mut r_norm = dot(&r, &r).sqrt();
        if report.iterations == 0 && r_norm > b_norm {
            // The initial guess is worse than none: start from zero.
            x.iter_mut().for_each(|v| *v = 0.0);
            r.copy_from_slice(b);
            r_norm = b_norm;
        }
        report.residual = r_norm / scale;
        if r_norm <= target || report.iterations >= settings.max_iterations || report.breakdown {
            break;
        }
        m.apply(a, &r, &mut z);
        p.copy_from_slice(&z);
        let mut rz = dot(&r, &z);
        while r_norm > target && report.iterations < settings.max_iterations {
            a.multiply(&p, &mut q);
            let curvature = dot(&p, &q);
            if curvature.is_nan() || curvature <= 0.0 {
                report.breakdown = true;
                break;
            }
            let alpha = rz / curvature;
            x.par_iter_mut()
                .zip(&p)
                .for_each(|(xi, pi)| *xi += alpha * pi);
            r.par_iter_mut()
                .zip(&q)
                .for_each(|(ri, qi)| *ri -= alpha * qi);
            m.apply(a, &r, &mut z);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            p.par_iter_mut()
                .zip(&z)
                .for_each(|(pi, zi)| *pi = zi + beta * *pi);
            r_norm = dot(&r, &r).sqrt();
            report.iterations += 1;
        }
    }
    report.converged =
        !report.breakdown && report.residual.is_finite() && report.residual <= settings.tolerance;
    report
}
