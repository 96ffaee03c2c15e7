//! Factor and solve the tangent stiffness `K_ff` of a nonlinear body, iteration after
//! iteration on one sparse pattern: the ordering and symbolic factorization are done once,
//! every iteration refactors the values only.

use crate::linkage::cholesky::{CholeskyError, SparseCholesky};
use crate::linkage::StiffnessAssembly;
use crate::Real;

/// The factorization of the current tangent.
pub(crate) struct TangentSolver {
    cholesky: SparseCholesky,
}

/// Why the tangent could not be factored.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum TangentError {
    /// A pivot was zero or negative (free index): the tangent is singular or indefinite.
    Indefinite {
        /// Free DOF index of the pivot.
        dof: usize,
    },
    /// Anything else the factorization reported.
    Other(String),
}

impl TangentSolver {
    /// Order and analyze the pattern of `assembly` (once per body).
    pub(crate) fn new(assembly: &StiffnessAssembly) -> Result<Self, CholeskyError> {
        let cholesky = SparseCholesky::analyze(
            assembly.n,
            &assembly.col_ptr,
            &assembly.row_idx,
            Some(&assembly.groups),
        )?;
        Ok(TangentSolver { cholesky })
    }

    /// Factor the tangent with `values` (lower triangle in the assembly's pattern). Returns
    /// the number of negative pivots (0: positive definite).
    pub(crate) fn factorize(&mut self, values: &[Real]) -> Result<usize, TangentError> {
        match self.cholesky.factorize(values) {
            Ok(()) => Ok(0),
            Err(CholeskyError::NonPositivePivot { dof })
            | Err(CholeskyError::NearlySingular { dof, .. }) => {
                Err(TangentError::Indefinite { dof })
            }
            Err(other) => Err(TangentError::Other(other.to_string())),
        }
    }

    /// Solve `K x = rhs` in place with the last successful factorization.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        self.cholesky.solve_in_place(rhs);
    }

    /// The underlying LLᵀ (for the mechanism diagnosis).
    pub(crate) fn cholesky_mut(&mut self) -> &mut SparseCholesky {
        &mut self.cholesky
    }

    /// Entries of the factor.
    pub(crate) fn factor_entries(&self) -> usize {
        self.cholesky.stats().nnz_l
    }
}
