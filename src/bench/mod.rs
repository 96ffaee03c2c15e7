//! `linkage bench`: lattice, large-displacement, contact, render, file-reading and preparation benchmarks.

pub mod contact;
pub mod large;
pub mod lattice;
pub mod prepare;
pub mod read;
pub mod render;
