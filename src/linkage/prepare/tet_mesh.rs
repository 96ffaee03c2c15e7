//! Tetrahedra to a linkage: their edges are the members, their faces that no other
//! tetrahedron shares are the patches (outward, closed), unused nodes dropped.

use super::PrepareError;
use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;

/// Tetrahedra over nodes (m); ids may leave nodes unused.
pub(crate) struct TetMesh {
    /// Node positions, m.
    pub nodes: Vec<Vector3<Real>>,
    /// Tetrahedra as four node ids, either orientation.
    pub tets: Vec<[usize; 4]>,
}

/// Six times the signed volume of `t`, m³.
pub(crate) fn six_volume(nodes: &[Vector3<Real>], t: [usize; 4]) -> Real {
    let [a, b, c, d] = t.map(|v| nodes[v]);
    (b - a).dot(&(c - a).cross(&(d - a)))
}

/// The four faces of the positively oriented `t`, each counter-clockwise seen from outside.
pub(crate) fn outward_faces([a, b, c, d]: [usize; 4]) -> [[usize; 3]; 4] {
    [[a, c, b], [a, b, d], [a, d, c], [b, c, d]]
}

impl TetMesh {
    /// The linkage of these tetrahedra, and its tetrahedra in the linkage's node numbers (each
    /// positively oriented). Refuses a body that is empty or that falls into pieces joined by
    /// less than a face (a mechanism), naming the `spacing` (m).
    pub(crate) fn into_geometry(
        self,
        spacing: Real,
    ) -> Result<(Geometry, Vec<[usize; 4]>), PrepareError> {
        let TetMesh { nodes, tets } = self;
        let unresolved = |problem: String| PrepareError::Unresolved { spacing, problem };
        // Orient, and drop nothing: a flat tetrahedron is a defect the tests must see.
        let mut tets: Vec<[usize; 4]> = tets
            .into_iter()
            .map(|t| {
                if six_volume(&nodes, t) < 0.0 {
                    [t[0], t[2], t[1], t[3]]
                } else {
                    t
                }
            })
            .collect();
        if tets.is_empty() {
            return Err(unresolved("has no members".to_string()));
        }
        // Number the nodes used, in id order (lattice order first: a banded numbering).
        let mut new_id = vec![usize::MAX; nodes.len()];
        for t in &tets {
            for &v in t {
                new_id[v] = 0;
            }
        }
        let mut kept = Vec::new();
        for (v, id) in new_id.iter_mut().enumerate() {
            if *id == 0 {
                *id = kept.len();
                kept.push(nodes[v]);
            }
        }
        for t in &mut tets {
            *t = t.map(|v| new_id[v]);
        }

        // Faces: sorted so that the two sides of an inner face are neighbours.
        let mut faces: Vec<([usize; 3], usize, [usize; 3])> = Vec::with_capacity(4 * tets.len());
        for (k, &t) in tets.iter().enumerate() {
            for f in outward_faces(t) {
                let mut key = f;
                key.sort_unstable();
                faces.push((key, k, f));
            }
        }
        faces.sort_unstable();
        let mut patches = Vec::new();
        let mut piece = UnionFind::new(tets.len());
        let mut i = 0;
        while i < faces.len() {
            let mut j = i + 1;
            while j < faces.len() && faces[j].0 == faces[i].0 {
                j += 1;
            }
            match j - i {
                1 => patches.push(faces[i].2),
                2 => piece.join(faces[i].1, faces[i + 1].1),
                n => {
                    return Err(unresolved(format!(
                        "has a face shared by {n} tetrahedra (an internal error of the stencils; please report the mesh)"
                    )))
                }
            }
            i = j;
        }
        let pieces = piece.count();
        if pieces > 1 {
            return Err(unresolved(format!(
                "falls into {pieces} pieces joined by edges or corners at most (a mechanism)"
            )));
        }
        let mut members: Vec<[usize; 2]> = tets
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b], [a, c], [a, d], [b, c], [b, d], [c, d]])
            .map(|[a, b]| [a.min(b), a.max(b)])
            .collect();
        members.sort_unstable();
        members.dedup();
        Ok((
            Geometry {
                dimension: Dimension::Three,
                nodes: kept,
                members,
                patches,
            },
            tets,
        ))
    }
}

/// Disjoint sets of tetrahedra joined across faces.
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
        }
    }

    fn root(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn join(&mut self, a: usize, b: usize) {
        let (a, b) = (self.root(a), self.root(b));
        if a != b {
            self.parent[a.max(b)] = a.min(b);
        }
    }

    fn count(&mut self) -> usize {
        (0..self.parent.len())
            .filter(|&x| self.root(x) == x)
            .count()
    }
}
