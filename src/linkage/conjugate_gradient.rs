//! Preconditioned conjugate gradients for `K_ff U_f = F_f` (paper Eq. 8) on bodies too large to
//! factor, warm-started from the best guess at hand.

use crate::linkage::{dot, Preconditioner, SymmetricCsr};
use crate::Real;
use rayon::prelude::*;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::cholesky::SparseCholesky;
    use crate::linkage::test_lattice::lattice_system;
    use crate::linkage::{BlockJacobi, StiffnessAssembly};

    /// `K_ff` of a small lattice with its bottom fixed, as assembly, values and full rows.
    fn lattice() -> (StiffnessAssembly, Vec<Real>, SymmetricCsr) {
        let s = lattice_system([4, 3, 5]);
        (s.assembly, s.values, s.matrix)
    }

    #[test]
    fn agrees_with_the_direct_solve_and_warm_starts_help() {
        let (asm, values, csr) = lattice();
        let b: Vec<Real> = (0..asm.n)
            .map(|i| ((i * 7919) % 13) as Real - 6.0)
            .collect();
        let mut direct = b.clone();
        let mut chol =
            SparseCholesky::analyze(asm.n, &asm.col_ptr, &asm.row_idx, Some(&asm.groups)).unwrap();
        chol.factorize(&values).unwrap();
        chol.solve_in_place(&mut direct);
        let mut m = BlockJacobi::new(&csr, &asm.groups).unwrap();
        let mut x = vec![0.0; asm.n];
        let cold = conjugate_gradient(&csr, &mut m, &b, &mut x, CgSettings::default());
        assert!(cold.converged && cold.residual <= 1e-10, "{cold:?}");
        let scale = direct.iter().map(|v| v.abs()).fold(0.0, Real::max);
        let err = x
            .iter()
            .zip(&direct)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, Real::max);
        assert!(
            err <= 1e-8 * scale,
            "iterative and direct differ by {err:e} of {scale:e}"
        );
        // A nearby right-hand side from the previous answer needs fewer iterations.
        let b2: Vec<Real> = b.iter().map(|v| 1.1 * v).collect();
        let mut warm: Vec<Real> = x.iter().map(|v| 1.05 * v).collect();
        let warm_report = conjugate_gradient(&csr, &mut m, &b2, &mut warm, CgSettings::default());
        assert!(warm_report.converged);
        assert!(
            warm_report.iterations < cold.iterations,
            "{} vs {}",
            warm_report.iterations,
            cold.iterations
        );
        // Thread count does not change the answer: one thread gives the same bits.
        let mut one = vec![0.0; asm.n];
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let single =
            pool.install(|| conjugate_gradient(&csr, &mut m, &b, &mut one, CgSettings::default()));
        assert_eq!(single.iterations, cold.iterations);
        assert_eq!(one, x);
    }

    #[test]
    fn an_unreachable_tolerance_is_reported_not_hidden() {
        let (asm, _, csr) = lattice();
        let b = vec![1.0; asm.n];
        let mut m = BlockJacobi::new(&csr, &asm.groups).unwrap();
        let mut x = vec![0.0; asm.n];
        let settings = CgSettings {
            tolerance: 1e-30,
            max_iterations: 50,
            reference_norm: 0.0,
        };
        let r = conjugate_gradient(&csr, &mut m, &b, &mut x, settings);
        assert!(!r.converged);
        assert_eq!(r.iterations, 50);
        assert!(r.residual.is_finite() && r.residual > 1e-30);
    }
}
