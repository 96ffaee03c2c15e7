//! A body from an MSH mesh: members along the edges of its lines, triangles and tetrahedra;
//! patches from the tetrahedra's boundary faces (outward) or, without tetrahedra, from a 3D
//! mesh's triangles; physical groups as node groups.

use crate::linkage::{Dimension, Geometry};
use crate::scene::import::msh::{MshElementKind, MshMesh};
use crate::scene::import::{ImportedModel, ModelFileError, NodeGroup};
use std::collections::HashMap;
use std::path::Path;

/// The distinct node pairs of `edges` in first-seen order, each as `[lower, higher]`.
fn distinct_edges(edges: impl Iterator<Item = [usize; 2]>) -> Vec<[usize; 2]> {
    let mut seen = std::collections::HashSet::new();
    edges
        .map(|[a, b]| [a.min(b), a.max(b)])
        .filter(|e| seen.insert(*e))
        .collect()
}

/// The faces of tetrahedra that belong to one tetrahedron only, each turned so that its
/// normal `(b − a) × (c − a)` points away from the tetrahedron's fourth node (outward), in the
/// order first seen.
pub(crate) fn boundary_faces(
    nodes: &[nalgebra::Vector3<crate::Real>],
    tetrahedra: &[[usize; 4]],
) -> Vec<[usize; 3]> {
    let mut faces: HashMap<[usize; 3], (usize, [usize; 3])> = HashMap::new();
    let mut order = Vec::new();
    for t in tetrahedra {
        for (skip, &opposite) in t.iter().enumerate() {
            let mut face = [0usize; 3];
            let mut k = 0;
            for (i, &n) in t.iter().enumerate() {
                if i != skip {
                    face[k] = n;
                    k += 1;
                }
            }
            let [a, b, c] = face;
            let normal = (nodes[b] - nodes[a]).cross(&(nodes[c] - nodes[a]));
            let face = if normal.dot(&(nodes[opposite] - nodes[a])) > 0.0 {
                [a, c, b]
            } else {
                face
            };
            let mut key = face;
            key.sort_unstable();
            let entry = faces.entry(key).or_insert_with(|| {
                order.push(key);
                (0, face)
            });
            entry.0 += 1;
        }
    }
    order
        .iter()
        .filter_map(|key| faces.get(key).filter(|(n, _)| *n == 1).map(|(_, f)| *f))
        .collect()
}

/// The body of an MSH mesh read from `path` (which names it in errors).
pub fn model_of_msh(path: &Path, mesh: &MshMesh) -> Result<ImportedModel, ModelFileError> {
    let members_of = |kind: MshElementKind| kind != MshElementKind::Point;
    // Nodes some member uses, renumbered in file order.
    let mut used = vec![false; mesh.nodes.len()];
    for e in mesh.elements.iter().filter(|e| members_of(e.kind)) {
        e.nodes.iter().for_each(|&n| used[n] = true);
    }
    if !used.iter().any(|&u| u) {
        return Err(ModelFileError::at(
            path,
            mesh.elements.first().map_or(1, |e| e.line),
            "the mesh has only point elements: a body needs lines, triangles or tetrahedra (mesh the curves, surfaces or volumes; gmsh saves only the elements of physical groups when there are any, so add the body's surface or volume to one)",
        ));
    }
    let mut index = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    for (n, &u) in used.iter().enumerate() {
        if u {
            index[n] = nodes.len();
            nodes.push(mesh.nodes[n]);
        }
    }
    let tetrahedra: Vec<[usize; 4]> = mesh
        .elements
        .iter()
        .filter(|e| e.kind == MshElementKind::Tetrahedron)
        .map(|e| [0, 1, 2, 3].map(|k| index[e.nodes[k]]))
        .collect();
    let dimension = if !tetrahedra.is_empty() || nodes.iter().any(|p| p.z != 0.0) {
        Dimension::Three
    } else {
        Dimension::Two
    };
    for (e, t) in mesh
        .elements
        .iter()
        .filter(|e| e.kind == MshElementKind::Tetrahedron)
        .zip(&tetrahedra)
    {
        let [a, b, c, d] = t.map(|n| nodes[n]);
        let volume = (b - a).cross(&(c - a)).dot(&(d - a)) / 6.0;
        let scale = [b - a, c - a, d - a]
            .iter()
            .map(|v| v.norm())
            .fold(0.0, f64::max);
        if volume.abs() <= 1e-12 * scale.powi(3) {
            return Err(ModelFileError::at(
                path,
                e.line,
                "a tetrahedron of this element block has no volume (its four nodes lie in one plane): remesh",
            ));
        }
    }
    let edges = mesh.elements.iter().flat_map(|e| {
        let n: Vec<usize> = e.nodes.iter().map(|&k| index[k]).collect();
        let pairs: &[[usize; 2]] = match e.kind {
            MshElementKind::Point => &[],
            MshElementKind::Line => &[[0, 1]],
            MshElementKind::Triangle => &[[0, 1], [1, 2], [2, 0]],
            MshElementKind::Tetrahedron => &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
        };
        pairs
            .iter()
            .map(move |&[i, j]| [n[i], n[j]])
            .collect::<Vec<_>>()
    });
    let members = distinct_edges(edges);
    let patches = if !tetrahedra.is_empty() {
        boundary_faces(&nodes, &tetrahedra)
    } else if dimension == Dimension::Three {
        let mut seen = std::collections::HashSet::new();
        mesh.elements
            .iter()
            .filter(|e| e.kind == MshElementKind::Triangle)
            .map(|e| [0, 1, 2].map(|k| index[e.nodes[k]]))
            .filter(|t| {
                let mut key = *t;
                key.sort_unstable();
                seen.insert(key)
            })
            .collect()
    } else {
        Vec::new()
    };
    // Physical groups: named ones by name, the others by their tag.
    let mut physical: Vec<(i64, i64)> = Vec::new();
    for e in &mesh.elements {
        for g in &e.groups {
            if !physical.contains(g) {
                physical.push(*g);
            }
        }
    }
    let mut order: Vec<(i64, i64, String)> = mesh.physical_names.clone();
    for &(dim, tag) in &physical {
        if !order.iter().any(|(d, t, _)| *d == dim && *t == tag) {
            order.push((dim, tag, tag.to_string()));
        }
    }
    let mut groups: Vec<NodeGroup> = Vec::new();
    for (dim, tag, name) in order {
        let mut members: Vec<usize> = mesh
            .elements
            .iter()
            .filter(|e| e.groups.contains(&(dim, tag)))
            .flat_map(|e| e.nodes.iter().map(|&n| index[n]))
            .filter(|&n| n != usize::MAX)
            .collect();
        members.sort_unstable();
        members.dedup();
        match groups.iter_mut().find(|g| g.name == name) {
            // gmsh allows one name on groups of several dimensions: their nodes together.
            Some(g) => {
                g.nodes.extend(members);
                g.nodes.sort_unstable();
                g.nodes.dedup();
            }
            None => groups.push(NodeGroup {
                name,
                nodes: members,
            }),
        }
    }
    Ok(ImportedModel {
        geometry: Geometry {
            dimension,
            nodes,
            members,
            patches,
        },
        groups,
        materials: Vec::new(),
        member_materials: Vec::new(),
        unassigned: None,
        supports: Vec::new(),
        loads: Vec::new(),
        warnings: Vec::new(),
    })
}
