//! A body as a model file gives it: geometry, named node groups and, from an INP file,
//! materials, supports and loads.

use crate::linkage::Geometry;
use crate::scene::import::ModelFileError;
use crate::scene::import::{inp::read_inp, msh::read_msh, msh_model::model_of_msh};
use crate::Real;
use nalgebra::Vector3;
use std::path::Path;

/// A named set of nodes: a gmsh physical group, an INP `*NSET` or `*ELSET` (the nodes of its
/// elements). `[[bodies.supports]] group = "clamp"` selects them.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeGroup {
    /// The name as the file writes it.
    pub name: String,
    /// Its nodes, 0-based, ascending, each once.
    pub nodes: Vec<usize>,
}

/// A material and cross-section of an INP file: one `*SOLID SECTION` over one `*MATERIAL`.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelMaterial {
    /// Name for the scene and the links file: the `*MATERIAL` name, or `MATERIAL_ELSET` when
    /// the material has sections of several areas.
    pub name: String,
    /// Young's modulus E, Pa (`*ELASTIC`'s first value).
    pub youngs_modulus: Real,
    /// Cross-section area A, m² (the line after `*SOLID SECTION`).
    pub area: Real,
    /// Density ρ, kg/m³ (`*DENSITY`), if given.
    pub density: Option<Real>,
}

/// The directions an INP file holds at one node (its `*BOUNDARY` lines combined).
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSupport {
    /// The node, 0-based.
    pub node: usize,
    /// Held x, y, z.
    pub fixed: [bool; 3],
    /// Prescribed displacement of the held directions, m (0 elsewhere).
    pub displacement: Vector3<Real>,
}

/// What one model file gives a body. Nodes are numbered in the order the file lists them
/// (only nodes some member or patch uses are kept); members are the distinct element edges in
/// element order.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportedModel {
    /// Nodes (m), members and outward patches (3D).
    pub geometry: Geometry,
    /// Named node groups, in the order the file defines them.
    pub groups: Vec<NodeGroup>,
    /// Materials with their sections (INP; empty for MSH).
    pub materials: Vec<ModelMaterial>,
    /// Per member the index of its material in `materials`; `None` where the file gives none
    /// (every member of an MSH file). Empty when no member has one.
    pub member_materials: Vec<Option<usize>>,
    /// Why some member has no material, naming the file, line and element (INP), when one has
    /// none: the error a scene gets if it names no material of its own either.
    pub unassigned: Option<String>,
    /// Supports, one per supported node, in node order (INP).
    pub supports: Vec<ModelSupport>,
    /// Concentrated loads, N, one per loaded node with the forces on it summed (INP).
    pub loads: Vec<(usize, Vector3<Real>)>,
    /// What was read but not used, each kind once with its file and line.
    pub warnings: Vec<String>,
}

/// The group called `name` among `groups`: exactly, else the one whose name differs only in
/// case (INP names are case-insensitive).
pub fn find_group<'a>(groups: &'a [NodeGroup], name: &str) -> Option<&'a NodeGroup> {
    groups.iter().find(|g| g.name == name).or_else(|| {
        let mut same = groups.iter().filter(|g| g.name.eq_ignore_ascii_case(name));
        match (same.next(), same.next()) {
            (Some(g), None) => Some(g),
            _ => None,
        }
    })
}

/// Read a model file by its extension: `.msh` (gmsh MSH 4.1, ASCII or binary) or `.inp`
/// (Abaqus/CalculiX). Errors name the file and line.
pub fn read_model(path: &Path) -> Result<ImportedModel, ModelFileError> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    match extension.as_str() {
        "msh" => model_of_msh(path, &read_msh(path)?),
        "inp" => read_inp(path),
        _ => Err(ModelFileError::at(
            path,
            0,
            "a model file is a gmsh mesh (.msh, MSH 4.1) or an Abaqus/CalculiX input file (.inp): rename it or convert it",
        )),
    }
}
