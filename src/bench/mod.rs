//! `linkage bench`: lattice, large-displacement, contact, fracture, render, file-reading and preparation benchmarks.

pub mod cholmod;
pub mod contact;
pub mod fracture;
pub mod large;
pub mod lattice;
pub mod prepare;
pub mod read;
pub mod render;
