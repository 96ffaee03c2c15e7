//! `linkage`: deformable bodies as linkage models (Ku & Ching, "Modeling Deformable
//! Objects Using a Linkage Model", 1991).
//!
//! A body is a set of nodes joined by axial members (a truss). Each member has the
//! axial stiffness `AE/L` (paper Eq. 1); assembling the member matrices (Eq. 2) gives
//! the global stiffness `K` (Eq. 3–4); supports split the degrees of freedom into free
//! and supported ones (Eq. 5); `K_ff U_f = F_f` gives the displacements (Eq. 8–9) and
//! the supports answer with the reactions (Eq. 10).
//!
//! ```
//! use linkage::linkage::{Body, Dimension, Material, Member, NodalLoad, Schedule, Support};
//! use linkage::linkage::Equilibrium;
//! use nalgebra::Vector3;
//!
//! // One steel bar 1 m long along x, fixed at node 1, pulled by 1 kN at node 2.
//! let mut body = Body::new("bar", Dimension::Two);
//! body.materials.push(Material::new("steel", 200e9, 1e-4));
//! body.nodes = vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0)];
//! body.members.push(Member { nodes: [0, 1], material: 0 });
//! body.supports.push(Support::fixed(0, [true, true, false]));
//! body.supports.push(Support::fixed(1, [false, true, false]));
//! body.loads.push(NodalLoad { node: 1, force: Vector3::new(1000.0, 0.0, 0.0), schedule: Schedule::Linear });
//! let mut eq = Equilibrium::new(&body).unwrap();
//! let state = eq.solve_step(&body, 1, 1).unwrap();
//! // Eq. 1: D = F L / (A E)
//! assert!((state.displacements[1].x - 1000.0 / (1e-4 * 200e9)).abs() < 1e-15);
//! ```
//!
//! Large displacements (members whose force follows their current length and acts along their
//! current direction), cables and struts are solved step by step by Newton–Raphson in
//! [`linkage::NewtonEquilibrium`] (with an arc-length path for snap-through);
//! [`linkage::BodySolver`] picks the solver a body needs.
//!
//! The scene files, the load-step driver and the result files live in [`scene`].
//!
//! The layers, each knowing only those before it:
//! - [`linalg`]: sparse matrices, knowing nothing of bodies: Cholesky and LDLᵀ (faer, METIS),
//!   conjugate gradients and their preconditioners (block Jacobi, smoothed aggregation).
//! - [`linkage`]: the paper's model and its equilibrium: bodies, members, assembly, the
//!   body-state kernel, the linear solve and Newton.
//! - [`contact`]: deformed bodies against each other and rigid obstacles (parry, rapier).
//! - [`scene`]: scene files, the load-step driver, result writers and readers.
//! - [`render`]: pictures of results; [`bench`]: `linkage bench`.
#![warn(missing_docs)]

/// The one scalar type: SI units throughout (m, N, Pa, m²).
pub type Real = f64;

pub mod bench;
pub mod contact;
pub mod linalg;
pub mod linkage;
pub mod render;
pub mod scene;
