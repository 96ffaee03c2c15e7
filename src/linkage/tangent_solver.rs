//! Factor and solve the tangent stiffness `K_ff` of a nonlinear body, iteration after
//! iteration on one sparse pattern: the ordering and symbolic factorization are done once,
//! every iteration refactors the values only. A tangent that is not positive definite (past a
//! limit point) is factored by LDLᵀ on the same ordering, which also counts its negative pivots.

use crate::linkage::cholesky::{CholeskyError, SparseCholesky};
use crate::linkage::ldlt::SparseLdlt;
use crate::linkage::StiffnessAssembly;
use crate::Real;

/// The factorization of the current tangent.
pub(crate) struct TangentSolver {
    cholesky: SparseCholesky,
    /// Built the first time a tangent is not positive definite.
    ldlt: Option<SparseLdlt>,
    /// Whether the last factorization is the LDLᵀ one.
    indefinite: bool,
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
        Ok(TangentSolver {
            cholesky,
            ldlt: None,
            indefinite: false,
        })
    }

    /// Factor a tangent that must be positive definite (LLᵀ only).
    pub(crate) fn factorize_definite(&mut self, values: &[Real]) -> Result<(), TangentError> {
        self.indefinite = false;
        match self.cholesky.factorize(values) {
            Ok(()) => Ok(()),
            Err(CholeskyError::NonPositivePivot { dof })
            | Err(CholeskyError::NearlySingular { dof, .. }) => {
                Err(TangentError::Indefinite { dof })
            }
            Err(other) => Err(TangentError::Other(other.to_string())),
        }
    }

    /// Factor the tangent with `values` (lower triangle in the pattern of `assembly`): LLᵀ,
    /// or LDLᵀ when LLᵀ meets a non-positive pivot. Returns the number of negative pivots
    /// (0: positive definite; k > 0: k unstable directions).
    pub(crate) fn factorize(
        &mut self,
        assembly: &StiffnessAssembly,
        values: &[Real],
    ) -> Result<usize, TangentError> {
        let dof = match self.factorize_definite(values) {
            Ok(()) => return Ok(0),
            Err(TangentError::Indefinite { dof }) => dof,
            Err(other) => return Err(other),
        };
        if self.ldlt.is_none() {
            let ldlt =
                SparseLdlt::with_ordering_of(&self.cholesky, &assembly.col_ptr, &assembly.row_idx)
                    .map_err(|e| TangentError::Other(e.to_string()))?;
            self.ldlt = Some(ldlt);
        }
        let Some(ldlt) = self.ldlt.as_mut() else {
            return Err(TangentError::Indefinite { dof });
        };
        match ldlt.factorize(values) {
            Ok(negative) => {
                self.indefinite = true;
                Ok(negative)
            }
            Err(_) => Err(TangentError::Indefinite { dof }),
        }
    }

    /// Solve `K x = rhs` in place with the last successful factorization.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        match (self.indefinite, self.ldlt.as_mut()) {
            (true, Some(ldlt)) => ldlt.solve_in_place(rhs),
            _ => self.cholesky.solve_in_place(rhs),
        }
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
