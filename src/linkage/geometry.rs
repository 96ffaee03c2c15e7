//! The shape of a linkage without materials, supports or loads.

use crate::linkage::Dimension;
use crate::Real;
use nalgebra::Vector3;

/// The shape of a linkage without materials, supports or loads: what the paper's three
/// files (nodes, links, patches) hold and what a generator makes. Indices are 0-based.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    /// 2D (nodes in the plane z = 0, two DOFs each) or 3D.
    pub dimension: Dimension,
    /// Node positions, m.
    pub nodes: Vec<Vector3<Real>>,
    /// Members as pairs of node indices.
    pub members: Vec<[usize; 2]>,
    /// Outward-facing triangular surface patches (counter-clockwise seen from outside), 3D only.
    pub patches: Vec<[usize; 3]>,
}
