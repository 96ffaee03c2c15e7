//! One body: its nodes, members, patches, supports and loads, and the linear solve of the paper.

pub use self::assembly::ModelTooLarge;
pub use self::assembly::StiffnessAssembly;
pub use self::block_jacobi::{BlockJacobi, SingularBlock};
pub use self::body::{
    bounding_diagonal, check_members, Body, BodyError, Dimension, Member, MemberProblem, NodalLoad,
    Schedule, Support,
};
pub use self::conjugate_gradient::{conjugate_gradient, CgReport, CgSettings};
pub use self::dof_map::{direction_name, DofMap, DofSlot};
pub use self::equilibrium::{Equilibrium, PhaseTimes, SolveError, StepState};
pub use self::geometry::Geometry;
pub use self::material::Material;
pub use self::mechanism::Mechanism;
pub use self::member_stiffness::{axial_stiffness, member_block, member_stiffness_matrix};
pub use self::smoothed_aggregation::{MultigridError, SmoothedAggregation};
pub use self::symmetric_csr::{dot, Preconditioner, SymmetricCsr};

mod assembly;
mod block_jacobi;
mod body;
pub mod cholesky;
mod conjugate_gradient;
mod dof_map;
mod equilibrium;
pub mod generators;
mod geometry;
mod material;
mod mechanism;
mod member_stiffness;
pub mod ordering;
pub mod paper_files;
mod smoothed_aggregation;
mod symmetric_csr;
