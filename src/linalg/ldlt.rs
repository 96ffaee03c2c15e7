//! Sparse LDLᵀ for symmetric *indefinite* tangents (past a limit point, a compressed member's
//! negative geometric stiffness): the LLᵀ of [`SparseCholesky`] stops at the first negative
//! pivot, LDLᵀ goes on and counts the negative pivots (the number of unstable directions,
//! Sylvester's law of inertia). It reuses the fill-reducing ordering of an analyzed
//! [`SparseCholesky`], so its factor has the same structure; it is built only when an
//! indefinite tangent first appears.
//!
//! No pivoting: a pivot that is exactly zero (a singular tangent, a mechanism) is an error.

use crate::linalg::cholesky::{factor_diagonal_positions, CholeskyError, SparseCholesky};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::{LdltError, LdltRegularization};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};

/// A numeric LDLᵀ factorization on a fixed pattern and ordering, refactored many times.
pub struct SparseLdlt {
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// Position of each pivot `D_jj` (permuted column j) in `l_values`.
    d_diag: Vec<usize>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    factorized: bool,
}

impl SparseLdlt {
    /// Symbolic analysis of the lower-triangle pattern (`col_ptr`, `row_idx`, as given to
    /// `cholesky`) with the ordering `cholesky` computed.
    pub fn with_ordering_of(
        cholesky: &SparseCholesky,
        col_ptr: &[usize],
        row_idx: &[usize],
    ) -> Result<Self, CholeskyError> {
        let n = col_ptr.len() - 1;
        let perm = cholesky.permutation().to_vec();
        let mut inverse = vec![0usize; n];
        for (new, &old) in perm.iter().enumerate() {
            inverse[old] = new;
        }
        let pattern =
            SymbolicSparseColMat::new_checked(n, n, col_ptr.to_vec(), None, row_idx.to_vec());
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(PermRef::new_checked(&perm, &inverse, n)),
            CholeskySymbolicParams::default(),
        )
        .map_err(|e| CholeskyError::Resources(format!("LDLᵀ symbolic factorization: {e:?}")))?;
        let req = StackReq::or(
            symbolic.factorize_numeric_ldlt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        );
        let mem = MemBuffer::try_new(req).map_err(|_| {
            CholeskyError::Resources(format!("LDLᵀ workspace of {} bytes", req.size_bytes()))
        })?;
        let mut l_values = Vec::new();
        l_values
            .try_reserve_exact(symbolic.len_val())
            .map_err(|_| CholeskyError::Resources("LDLᵀ factor".to_string()))?;
        l_values.resize(symbolic.len_val(), 0.0);
        let d_diag = factor_diagonal_positions(&symbolic);
        Ok(SparseLdlt {
            n,
            pattern,
            symbolic,
            perm,
            d_diag,
            l_values,
            mem,
            factorized: false,
        })
    }

    /// Factor `values` (lower triangle, in the pattern's order). Returns the number of negative
    /// pivots: 0 for a positive definite matrix, k for a matrix with k negative eigenvalues.
    pub fn factorize(&mut self, values: &[f64]) -> Result<usize, CholeskyError> {
        self.factorized = false;
        if values.len() != self.pattern.row_idx().len() || values.iter().any(|v| !v.is_finite()) {
            return Err(CholeskyError::InvalidInput(
                "LDLᵀ: values of the wrong length or not finite".to_string(),
            ));
        }
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        let result = self.symbolic.factorize_numeric_ldlt(
            &mut self.l_values,
            a,
            Side::Lower,
            LdltRegularization::default(),
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        if let Err(LdltError::ZeroPivot { index }) = result {
            // faer reports the column 1-based (simplicial) or 0-based (supernodal), as for LLᵀ.
            let col = match self.symbolic.raw() {
                SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                SymbolicCholeskyRaw::Supernodal(_) => index,
            };
            return Err(CholeskyError::NonPositivePivot {
                dof: self.perm[col.min(self.n.saturating_sub(1))],
            });
        }
        let mut negative = 0;
        for &p in &self.d_diag {
            let d = self.l_values[p];
            if !d.is_finite() || d == 0.0 {
                return Err(CholeskyError::NearlySingular { dof: 0, ratio: 0.0 });
            }
            negative += usize::from(d < 0.0);
        }
        self.factorized = true;
        Ok(negative)
    }

    /// Solve `L D Lᵀ x = b` in place (original DOF order).
    ///
    /// # Panics
    /// If the last [`factorize`](Self::factorize) did not succeed, or `rhs.len() != n`.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(
            self.factorized,
            "SparseLdlt::solve_in_place needs a successful factorize"
        );
        let n = self.n;
        LdltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal matrix with diagonal d_i and off-diagonal 1 (lower CSC).
    fn tridiagonal(d: &[f64]) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = d.len();
        let (mut c, mut r, mut v) = (vec![0], Vec::new(), Vec::new());
        for (j, &dj) in d.iter().enumerate() {
            r.push(j);
            v.push(dj);
            if j + 1 < n {
                r.push(j + 1);
                v.push(1.0);
            }
            c.push(r.len());
        }
        (c, r, v)
    }

    #[test]
    fn solves_an_indefinite_matrix_and_counts_its_negative_eigenvalues() {
        // Diagonal −4 at two places, +4 elsewhere, off-diagonals 1: Gershgorin puts two
        // eigenvalues below −2 and the rest above 2.
        let d: Vec<f64> = (0..40)
            .map(|i| if i == 7 || i == 30 { -4.0 } else { 4.0 })
            .collect();
        let (c, r, v) = tridiagonal(&d);
        let groups: Vec<usize> = (0..40).collect();
        let mut chol = SparseCholesky::analyze(40, &c, &r, Some(&groups)).unwrap();
        assert!(
            chol.factorize(&v).is_err(),
            "LLᵀ refuses an indefinite matrix"
        );
        let mut ldlt = SparseLdlt::with_ordering_of(&chol, &c, &r).unwrap();
        assert_eq!(ldlt.factorize(&v).unwrap(), 2);
        let x_true: Vec<f64> = (0..40).map(|i| (i as f64 * 0.3).cos()).collect();
        let mut b = vec![0.0; 40];
        for i in 0..40 {
            b[i] = d[i] * x_true[i]
                + if i > 0 { x_true[i - 1] } else { 0.0 }
                + if i + 1 < 40 { x_true[i + 1] } else { 0.0 };
        }
        ldlt.solve_in_place(&mut b);
        for i in 0..40 {
            assert!((b[i] - x_true[i]).abs() < 1e-12);
        }
        // Positive definite: no negative pivot.
        let (_, _, v) = tridiagonal(&[4.0; 40]);
        assert_eq!(ldlt.factorize(&v).unwrap(), 0);
    }
}
