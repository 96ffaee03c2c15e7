//! `linkage bench`: lattice, large-displacement, contact, fracture, dynamics, render, file-reading and preparation benchmarks.

pub mod cholmod;
pub mod contact;
pub mod dynamics;
pub mod fracture;
pub mod large;
pub mod lattice;
pub mod opensees;
pub mod prepare;
pub mod read;
pub mod render;
