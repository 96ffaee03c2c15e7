//! The paper's linkage model of one body and its equilibrium, linear and nonlinear.

pub use self::assembly::ModelTooLarge;
pub use self::assembly::StiffnessAssembly;
pub use self::body::{
    bounding_diagonal, prescribed_displacements, Body, BodyError, Dimension, Member, MemberProblem,
    NodalLoad, Schedule, Support,
};
pub use self::body_solver::BodySolver;
pub use self::boundary_segments::boundary_segments;
pub use self::convergence::{Convergence, NotFinite};
pub use self::dof_map::{direction_name, DofMap, DofSlot};
pub use self::equilibrium::{Equilibrium, PhaseTimes, SolveError};
pub use self::geometry::Geometry;
pub use self::interrupt::Interrupt;
pub use self::kinematics::{Kinematics, NewtonSettings, PathMethod};
pub use self::material::{Behaviour, Failure, Material, Scatter, Softening};
pub use self::mechanism::Mechanism;
pub use self::member_check::check_members;
pub use self::member_response::{member_response, scaled_member_response, MemberResponse};
pub use self::member_stiffness::{
    axial_stiffness, linear_member_block, member_axial_stiffness, member_block,
    member_stiffness_matrix, member_stiffnesses,
};
pub(crate) use self::newton::{
    add_follower_load_stiffness, follower_forces, lagrange_weights, pair_members, IncrementSize,
};
pub use self::newton::{add_stop_forces, stop_forces, NewtonEquilibrium, SavedNewton, Stop};
pub use self::pressure::{
    chosen_patches, face_forces, load_stiffness_blocks, load_stiffness_parts, pressure_loads,
    pressure_loads_on, symmetric_load_stiffness_blocks, Pressure, PressureFaces,
};
pub use self::self_weight::self_weight_loads;
pub use self::solver_choice::{
    IterativeSettings, SolverChoice, SolverSettings, SolverUsed, AUTO_CONTACT_ITERATIVE_DOFS_3D,
    AUTO_ITERATIVE_DOFS_2D, AUTO_ITERATIVE_DOFS_3D,
};
pub(crate) use self::step_state::post_process;
pub use self::step_state::StepState;

mod assembly;
mod body;
mod body_solver;
pub mod body_state;
mod boundary_segments;
mod convergence;
mod dof_map;
pub mod dynamics;
mod equilibrium;
pub mod fracture;
pub mod generators;
mod geometry;
pub mod homogenize;
mod interrupt;
mod iterative_solver;
mod kinematics;
pub(crate) mod line_search;
mod load_patterns;
mod material;
pub(crate) mod mechanism;
mod member_check;
mod member_response;
mod member_stiffness;
mod newton;
pub mod prepare;
mod pressure;
pub mod rigid_modes;
mod self_weight;
mod solver_choice;
mod step_state;
mod tangent_solver;
#[cfg(test)]
mod test_lattice;
