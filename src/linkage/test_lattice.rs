//! A lattice stiffness system for the solver tests (one fixture instead of one per test module),
//! and the tests of `crate::linalg` that run on it: `linalg` knows no bodies, so they live here.

use crate::linalg::multigrid::MODES;
use crate::linalg::SymmetricCsr;
use crate::linkage::generators::lattice_body;
use crate::linkage::rigid_modes::rigid_body_rows;
use crate::linkage::{linear_member_block, DofMap, StiffnessAssembly};
use crate::Real;

/// `K_ff` of a lattice of `cells` with its bottom face fixed (see [`lattice_body`]).
pub(crate) struct LatticeSystem {
    pub assembly: StiffnessAssembly,
    /// Lower-triangle values in the assembly's pattern.
    pub values: Vec<Real>,
    /// The same matrix in full rows.
    pub matrix: SymmetricCsr,
    /// The rigid-body rows of every free DOF (the multigrid's near-null space).
    pub near_null_space: Vec<[Real; MODES]>,
}

pub(crate) fn lattice_system(cells: [usize; 3]) -> LatticeSystem {
    let body = lattice_body(cells).expect("valid lattice");
    let dofs = DofMap::new(&body);
    let assembly = StiffnessAssembly::new(&body, &dofs).expect("small lattice");
    let mut values = Vec::new();
    assembly.fill(&body, |m| linear_member_block(&body, m), &mut values);
    let mut matrix = SymmetricCsr::from_lower(assembly.n, &assembly.col_ptr, &assembly.row_idx);
    matrix.refill(&values);
    let near_null_space = rigid_body_rows(&body.nodes, &dofs);
    LatticeSystem {
        assembly,
        values,
        matrix,
        near_null_space,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::block_matrix::BlockMatrix;
    use crate::linalg::cholesky::SparseCholesky;
    use crate::linalg::{conjugate_gradient, BlockJacobi, CgSettings, SmoothedAggregation};

    #[test]
    fn block_products_match_the_full_rows_to_single_precision() {
        let s = lattice_system([4, 3, 5]);
        let a = &s.matrix;
        let blocks = BlockMatrix::<3>::from_full_rows(a).expect("node blocks of 3");
        assert_eq!(3 * blocks.blocks, a.n);
        let x: Vec<Real> = (0..a.n).map(|i| (i as Real * 0.37).sin()).collect();
        let mut exact = vec![0.0; a.n];
        a.multiply(&x, &mut exact);
        let mut y = vec![0.0; a.n];
        blocks.multiply(&x, &mut y);
        let scale = exact.iter().map(|v| v.abs()).fold(0.0, Real::max);
        let diagonal_scale = a.diagonal().iter().copied().fold(0.0, Real::max);
        for (p, q) in y.iter().zip(&exact) {
            // Each of 81 products carries a relative error of 2⁻²⁴ of its entry.
            assert!((p - q).abs() <= 81.0 * 6e-8 * diagonal_scale, "{p} vs {q}");
        }
        assert!(scale > 0.0);
        let b: Vec<Real> = (0..a.n).map(|i| i as Real).collect();
        let mut r = vec![0.0; a.n];
        blocks.residual(&b, &x, &mut r);
        for i in 0..a.n {
            assert_eq!(r[i], b[i] - y[i]);
        }
        // Not made of aligned 2×2 blocks (a node has 3 DOFs): refused.
        assert!(BlockMatrix::<2>::from_full_rows(a).is_none());
    }

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

    #[test]
    fn multigrid_cg_matches_the_direct_solve_in_far_fewer_iterations() {
        let LatticeSystem {
            matrix: csr,
            assembly: asm,
            values,
            near_null_space,
        } = lattice_system([8, 8, 10]);
        let b: Vec<Real> = (0..asm.n)
            .map(|i| ((i * 7919) % 13) as Real - 6.0)
            .collect();
        let mut direct = b.clone();
        let mut chol =
            SparseCholesky::analyze(asm.n, &asm.col_ptr, &asm.row_idx, Some(&asm.groups)).unwrap();
        chol.factorize(&values).unwrap();
        chol.solve_in_place(&mut direct);

        // Three levels at least: a small coarse size forces recursion.
        let mut amg =
            SmoothedAggregation::with_coarse_size(&csr, &asm.groups, &near_null_space, 200)
                .unwrap();
        assert!(amg.sizes.len() >= 3, "{:?}", amg.sizes);
        let mut x = vec![0.0; asm.n];
        let report = conjugate_gradient(&csr, &mut amg, &b, &mut x, CgSettings::default());
        assert!(report.converged && report.residual <= 1e-10, "{report:?}");
        let scale = direct.iter().map(|v| v.abs()).fold(0.0, Real::max);
        let err = x
            .iter()
            .zip(&direct)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, Real::max);
        assert!(err <= 1e-8 * scale, "{err:e} of {scale:e}");

        // Built and applied on one thread, the hierarchy gives the same bits.
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let (single, one) = pool.install(|| {
            let mut amg =
                SmoothedAggregation::with_coarse_size(&csr, &asm.groups, &near_null_space, 200)
                    .unwrap();
            let mut one = vec![0.0; asm.n];
            let r = conjugate_gradient(&csr, &mut amg, &b, &mut one, CgSettings::default());
            (r, one)
        });
        assert_eq!(single.iterations, report.iterations);
        assert_eq!(one, x);

        // Galerkin products formed in bands (8 on the finest level here) give the same bits.
        let mut banded = SmoothedAggregation::with_band_rows(
            &csr,
            &asm.groups,
            &near_null_space,
            200,
            asm.n / 8,
        )
        .unwrap();
        assert_eq!(banded.sizes, amg.sizes);
        let mut z = vec![0.0; asm.n];
        let r = conjugate_gradient(&csr, &mut banded, &b, &mut z, CgSettings::default());
        assert_eq!(r.iterations, report.iterations);
        assert_eq!(z, x);

        let mut jacobi = BlockJacobi::new(&csr, &asm.groups).unwrap();
        let mut y = vec![0.0; asm.n];
        let plain = conjugate_gradient(&csr, &mut jacobi, &b, &mut y, CgSettings::default());
        assert!(
            report.iterations * 4 < plain.iterations,
            "multigrid {} vs block-Jacobi {} iterations",
            report.iterations,
            plain.iterations
        );
    }
}
