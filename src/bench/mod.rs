//! `linkage bench`: lattice, large-displacement, contact, fracture, render and file-reading benchmarks.

pub mod contact;
pub mod fracture;
pub mod large;
pub mod lattice;
pub mod read;
pub mod render;
