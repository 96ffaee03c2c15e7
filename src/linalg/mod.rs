//! Sparse linear algebra that knows matrices, not bodies: direct solvers (Cholesky and LDLᵀ on
//! faer with a METIS ordering) apart from matrix-free ones (conjugate gradients and their
//! preconditioners: block Jacobi, smoothed-aggregation multigrid), and the storage they share.

pub use self::block_jacobi::{BlockJacobi, SingularBlock};
pub use self::cholesky::{CholeskyError, SparseCholesky};
pub use self::conjugate_gradient::{conjugate_gradient, CgReport, CgSettings, Preconditioner};
pub use self::ldlt::SparseLdlt;
pub use self::low_rank::{
    FactorLowRankUpdate, LowRankCorrection, LowRankUpdate, Removal, SingularUpdate, SparseColumn,
};
pub use self::multigrid::{MultigridError, SmoothedAggregation};
pub use self::symmetric_csr::{dot, SymmetricCsr};

mod block_jacobi;
pub(crate) mod block_matrix;
pub mod cholesky;
mod conjugate_gradient;
pub mod ldlt;
mod low_rank;
pub mod multigrid;
mod node_symbolic;
pub mod ordering;
mod symmetric_csr;
mod trailing_order;
mod tree_cholesky;
pub mod tree_solve;
