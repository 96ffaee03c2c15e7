//! Factor and solve the tangent stiffness `K_ff` of a nonlinear body, iteration after iteration.
//!
//! One sparse pattern: the ordering and symbolic factorization are done once,
//! every iteration refactors the values only. A tangent that is not positive definite (past a
//! limit point) is factored by LDLᵀ on the same ordering, which also counts its negative pivots.
//! A large body may instead be solved by multigrid conjugate gradients, warm-started, with the
//! direct factorization as the fallback when they do not converge.

use crate::linalg::cholesky::{CholeskyError, SparseCholesky};
use crate::linalg::ldlt::SparseLdlt;
use crate::linkage::iterative_solver::IterativeSolver;
use crate::linkage::{Body, DofMap, StiffnessAssembly};
use crate::Real;

/// The factorization (or the iterative solver) of the current tangent.
pub(crate) struct TangentSolver {
    /// Analyzed at construction for a direct body, on the first fallback for an iterative one.
    cholesky: Option<SparseCholesky>,
    /// Built the first time a tangent is not positive definite.
    ldlt: Option<SparseLdlt>,
    /// Whether the last factorization is the LDLᵀ one.
    indefinite: bool,
    /// Conjugate gradients for a large body.
    iterative: Option<IterativeSolver>,
    /// The pattern, kept for a fallback factorization.
    assembly: StiffnessAssembly,
    /// Force scale of the current increment, N: iterative solves stop at tolerance × it.
    reference: Real,
    /// Whether an iterative solve did not converge and the tangent was factored instead.
    fell_back: bool,
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
    /// Prepare the solver of `body`'s tangent: order and analyze the pattern (direct), or build
    /// the full-row pattern (iterative, when the body's solver settings choose it).
    pub(crate) fn new(
        body: &Body,
        dofs: &DofMap,
        assembly: &StiffnessAssembly,
    ) -> Result<Self, CholeskyError> {
        let iterative = body
            .solver
            .use_iterative(dofs.dofs_per_node, assembly.n)
            .then(|| IterativeSolver::new(assembly, dofs, &body.nodes, body.solver.iterative));
        let cholesky = if iterative.is_none() {
            Some(analyze(assembly)?)
        } else {
            None
        };
        Ok(TangentSolver {
            cholesky,
            ldlt: None,
            indefinite: false,
            iterative,
            assembly: assembly.clone(),
            reference: 0.0,
            fell_back: false,
        })
    }

    /// The force scale of the increment being solved, N.
    pub(crate) fn set_reference(&mut self, reference: Real) {
        self.reference = reference;
    }

    /// Whether the tangent is solved by conjugate gradients.
    pub(crate) fn is_iterative(&self) -> bool {
        self.iterative.is_some()
    }

    /// Whether an iterative solve fell back to factoring the tangent (at least once).
    pub(crate) fn fell_back(&self) -> bool {
        self.fell_back
    }

    /// Conjugate-gradient iterations so far (0 for a direct body).
    pub(crate) fn iterations(&self) -> usize {
        self.iterative.as_ref().map_or(0, |i| i.iterations)
    }

    /// Factor a tangent that must be positive definite (LLᵀ only). An iterative body only
    /// takes the new values: its solves check themselves.
    pub(crate) fn factorize_definite(&mut self, values: &[Real]) -> Result<(), TangentError> {
        self.indefinite = false;
        if let Some(it) = self.iterative.as_mut() {
            it.refill(values);
            return Ok(());
        }
        self.factorize_direct_definite(values)
    }

    fn factorize_direct_definite(&mut self, values: &[Real]) -> Result<(), TangentError> {
        self.indefinite = false;
        if self.cholesky.is_none() {
            self.cholesky =
                Some(analyze(&self.assembly).map_err(|e| TangentError::Other(e.to_string()))?);
        }
        let Some(cholesky) = self.cholesky.as_mut() else {
            return Err(TangentError::Other("no factorization".to_string()));
        };
        match cholesky.factorize(values) {
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
    /// (0: positive definite; k > 0: k unstable directions). An iterative body takes the values
    /// and reports 0.
    pub(crate) fn factorize(&mut self, values: &[Real]) -> Result<usize, TangentError> {
        if let Some(it) = self.iterative.as_mut() {
            it.refill(values);
            self.indefinite = false;
            return Ok(0);
        }
        self.factorize_direct(values)
    }

    fn factorize_direct(&mut self, values: &[Real]) -> Result<usize, TangentError> {
        let dof = match self.factorize_direct_definite(values) {
            Ok(()) => return Ok(0),
            Err(TangentError::Indefinite { dof }) => dof,
            Err(other) => return Err(other),
        };
        if self.ldlt.is_none() {
            let Some(cholesky) = self.cholesky.as_ref() else {
                return Err(TangentError::Indefinite { dof });
            };
            let ldlt = SparseLdlt::with_ordering_of(
                cholesky,
                &self.assembly.col_ptr,
                &self.assembly.row_idx,
            )
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

    /// Solve `K x = rhs` in place with the last factorization, or iteratively; an iterative
    /// solve that does not converge falls back to factoring this tangent.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) -> Result<(), TangentError> {
        if let Some(it) = self.iterative.as_mut() {
            let mut x = vec![0.0; rhs.len()];
            let report = it
                .solve(rhs, &mut x, self.reference)
                .map_err(|e| TangentError::Other(e.to_string()));
            if let Ok(report) = report {
                if report.converged {
                    rhs.copy_from_slice(&x);
                    return Ok(());
                }
            }
            // Not converged (or no hierarchy: a singular or indefinite tangent): factor it.
            self.fell_back = true;
            let values = it.lower_values(&self.assembly);
            self.factorize_direct(&values)?;
        }
        match (self.indefinite, self.ldlt.as_mut(), self.cholesky.as_mut()) {
            (true, Some(ldlt), _) => ldlt.solve_in_place(rhs),
            (_, _, Some(cholesky)) => cholesky.solve_in_place(rhs),
            _ => {
                return Err(TangentError::Other(
                    "the tangent was not factored".to_string(),
                ))
            }
        }
        Ok(())
    }

    /// The underlying LLᵀ (for the mechanism diagnosis), when one was analyzed.
    pub(crate) fn cholesky_mut(&mut self) -> Option<&mut SparseCholesky> {
        self.cholesky.as_mut()
    }

    /// Entries of the factor (0 while solving iteratively).
    pub(crate) fn factor_entries(&self) -> usize {
        self.cholesky.as_ref().map_or(0, |c| c.stats().nnz_l)
    }
}

fn analyze(assembly: &StiffnessAssembly) -> Result<SparseCholesky, CholeskyError> {
    SparseCholesky::analyze(
        assembly.n,
        &assembly.col_ptr,
        &assembly.row_idx,
        Some(&assembly.groups),
    )
}
