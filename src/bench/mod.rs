//! `linkage bench`: lattice, large-displacement and render benchmarks.

pub mod large;
pub mod lattice;
pub mod render;
