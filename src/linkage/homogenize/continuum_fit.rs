//! `continuum_modulus`: the member area that gives a body a chosen Young's modulus as a solid.

use super::uniaxial::{effective_elasticity, EffectiveElasticity, HomogenizeError};
use crate::linkage::Body;
use crate::Real;

/// Why a body's members cannot be given the area its `continuum_modulus` asks for.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ContinuumFitError {
    /// Members of other materials share the body.
    #[error("body '{body}': material '{material}' gives continuum_modulus, so every member of the body must be of it, but member {member} is of material '{other}': give the body one material, or give '{material}' an `area` instead")]
    Mixed {
        /// Body name.
        body: String,
        /// The material with `continuum_modulus`.
        material: String,
        /// A member (1-based) of another material.
        member: usize,
        /// Its material.
        other: String,
    },
    /// The homogenization failed.
    #[error("{0} (material with continuum_modulus: give it an `area` instead)")]
    Homogenize(#[from] HomogenizeError),
}

/// If `body`'s members are of a material with `continuum_modulus` (Pa), set that material's
/// area (in the body's own copy) to `A = E_c / ē(A = 1 m²)` so that the body's mean Young's
/// modulus as a solid of `volume` m³ is `E_c`; the body's elasticity with that area, or `None`
/// when no member's material gives `continuum_modulus`.
pub fn fit_continuum_modulus(
    body: &mut Body,
    volume: Real,
) -> Result<Option<EffectiveElasticity>, ContinuumFitError> {
    let Some(first) = body
        .members
        .iter()
        .position(|m| body.materials[m.material].continuum_modulus.is_some())
    else {
        return Ok(None);
    };
    let material = body.members[first].material;
    if let Some((k, other)) = body
        .members
        .iter()
        .enumerate()
        .find(|(_, m)| m.material != material)
    {
        return Err(ContinuumFitError::Mixed {
            body: body.name.clone(),
            material: body.materials[material].name.clone(),
            member: k + 1,
            other: body.materials[other.material].name.clone(),
        });
    }
    let target = body.materials[material].continuum_modulus.unwrap_or(0.0);
    body.materials[material].area = 1.0;
    let unit = effective_elasticity(body, volume)?;
    if !(unit.youngs_modulus.is_finite() && unit.youngs_modulus > 0.0) {
        return Err(HomogenizeError::NotSolid {
            body: body.name.clone(),
            why: format!(
                "its uniaxial tests give a modulus of {:e} Pa per m² of member area",
                unit.youngs_modulus
            ),
        }
        .into());
    }
    let area = target / unit.youngs_modulus;
    body.materials[material].area = area;
    // E is linear in the areas, ν independent of them.
    Ok(Some(EffectiveElasticity {
        youngs_moduli: unit.youngs_moduli.map(|e| e * area),
        youngs_modulus: unit.youngs_modulus * area,
        ..unit
    }))
}
