//! `linkage bench`: lattice, large-displacement, render and file-reading benchmarks.

pub mod large;
pub mod lattice;
pub mod read;
pub mod render;
