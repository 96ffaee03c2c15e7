#![doc = include_str!("README.md")]

pub use self::continuum_fit::{fit_continuum_modulus, ContinuumFitError};
pub use self::uniaxial::{
    continuum_volume, effective_elasticity, EffectiveElasticity, HomogenizeError,
};

mod continuum_fit;
mod uniaxial;
