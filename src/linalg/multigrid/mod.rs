//! Smoothed-aggregation algebraic multigrid, a preconditioner for conjugate gradients.
#![doc = include_str!("README.md")]

pub use self::setup::{MultigridError, SmoothedAggregation};
pub use self::transfer::MODES;

mod cycle;
mod galerkin;
mod setup;
mod smoother;
mod transfer;
