//! `linkage bench`: lattice, large-displacement, contact and render benchmarks.

pub mod contact;
pub mod large;
pub mod lattice;
pub mod render;
