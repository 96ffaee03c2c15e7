//! `linkage bench`: lattice, large-displacement, contact, render and file-reading benchmarks.

pub mod contact;
pub mod large;
pub mod lattice;
pub mod read;
pub mod render;
