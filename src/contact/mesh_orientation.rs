//! A closed triangle mesh turned outward as a whole: faces made to agree with their neighbours
//! across every edge, then each closed piece turned so that its faces face out (positive
//! enclosed volume), as body patches are. An open or non-manifold mesh is refused with an edge.

use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

/// Why a triangle mesh cannot be an obstacle's closed surface. Vertex and face numbers are
/// 1-based, in file order (after repeated corners are merged).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeshProblem {
    /// An edge with one face only: the mesh has a hole there.
    #[error("the edge from vertex {} to vertex {} (at {:?} and {:?} m) belongs to face {face} only: the mesh is open there; it must be closed (watertight): add the missing faces", .edge[0], .edge[1], .at[0], .at[1])]
    Open {
        /// The edge's vertices, 1-based.
        edge: [usize; 2],
        /// Their positions, m.
        at: [[Real; 3]; 2],
        /// The one face along it, 1-based.
        face: usize,
    },
    /// An edge shared by more than two faces.
    #[error("the edge from vertex {} to vertex {} belongs to {count} faces (first {}): a closed surface has exactly two per edge; split the mesh into separate obstacles", .edge[0], .edge[1], .faces[0])]
    NonManifold {
        /// The edge's vertices, 1-based.
        edge: [usize; 2],
        /// How many faces share it.
        count: usize,
        /// Some of those faces, 1-based.
        faces: Vec<usize>,
    },
    /// Faces that cannot all agree (a Möbius-like, one-sided surface).
    #[error("face {face} cannot be turned to agree with all its neighbours: the surface is one-sided; the mesh must enclose a volume")]
    OneSided {
        /// A face where the contradiction shows, 1-based.
        face: usize,
    },
}

/// What [`orient_outward`] changed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Orientation {
    /// The triangles, each counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// Faces (1-based) turned round in all: to agree with their neighbours, and with their
    /// whole piece when it faced inward.
    pub turned: Vec<usize>,
}

/// Make `triangles` over `vertices` (m) one consistently oriented, outward-facing closed
/// surface, or say why it is not one.
pub fn orient_outward(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
) -> Result<Orientation, MeshProblem> {
    // Per undirected edge, the faces along it.
    let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            edges.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut sorted: Vec<_> = edges.iter().collect();
    sorted.sort_unstable_by_key(|(e, _)| **e);
    for (&(a, b), faces) in &sorted {
        let at = |v: usize| [vertices[v].x, vertices[v].y, vertices[v].z];
        match faces.len() {
            2 => {}
            1 => {
                return Err(MeshProblem::Open {
                    edge: [a + 1, b + 1],
                    at: [at(a), at(b)],
                    face: faces[0] + 1,
                })
            }
            n => {
                return Err(MeshProblem::NonManifold {
                    edge: [a + 1, b + 1],
                    count: n,
                    faces: faces.iter().take(4).map(|f| f + 1).collect(),
                })
            }
        }
    }
    // Walk each piece from its first face: a neighbour runs along the shared edge the other
    // way when the two agree; otherwise it is turned.
    let runs = |t: &[usize; 3], a: usize, b: usize| {
        (t[0] == a && t[1] == b) || (t[1] == a && t[2] == b) || (t[2] == a && t[0] == b)
    };
    let mut oriented: Vec<Option<[usize; 3]>> = vec![None; triangles.len()];
    let mut pieces: Vec<Vec<usize>> = Vec::new();
    for start in 0..triangles.len() {
        if oriented[start].is_some() {
            continue;
        }
        oriented[start] = Some(triangles[start]);
        let mut piece = vec![start];
        let mut queue = vec![start];
        while let Some(f) = queue.pop() {
            let Some(t) = oriented[f] else { continue };
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                for &g in &edges[&(a.min(b), a.max(b))] {
                    if g == f {
                        continue;
                    }
                    let given = triangles[g];
                    // Agreeing with `t`, g runs from b to a.
                    let wanted = if runs(&given, b, a) {
                        given
                    } else {
                        [given[0], given[2], given[1]]
                    };
                    match oriented[g] {
                        None => {
                            oriented[g] = Some(wanted);
                            piece.push(g);
                            queue.push(g);
                        }
                        Some(o) if runs(&o, b, a) => {}
                        Some(_) => return Err(MeshProblem::OneSided { face: g + 1 }),
                    }
                }
            }
        }
        pieces.push(piece);
    }
    let mut out: Vec<[usize; 3]> = oriented.into_iter().flatten().collect();
    for piece in &pieces {
        // Six times the enclosed volume: positive when the faces face out.
        let volume: Real = piece
            .iter()
            .map(|&f| {
                let [a, b, c] = out[f];
                vertices[a].dot(&vertices[b].cross(&vertices[c]))
            })
            .sum();
        if volume < 0.0 {
            for &f in piece {
                let [a, b, c] = out[f];
                out[f] = [a, c, b];
            }
        }
    }
    let turned = out
        .iter()
        .zip(triangles)
        .enumerate()
        .filter(|(_, (o, t))| o != t)
        .map(|(f, _)| f + 1)
        .collect();
    Ok(Orientation {
        triangles: out,
        turned,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube's 12 triangles, counter-clockwise seen from outside.
    fn cube() -> (Vec<Vector3<Real>>, Vec<[usize; 3]>) {
        let v: Vec<Vector3<Real>> = (0..8)
            .map(|i| Vector3::new((i & 1) as Real, ((i >> 1) & 1) as Real, (i >> 2) as Real))
            .collect();
        let quads = [
            [0, 2, 3, 1], // z = 0, facing -z
            [4, 5, 7, 6], // z = 1
            [0, 1, 5, 4], // y = 0
            [2, 6, 7, 3], // y = 1
            [0, 4, 6, 2], // x = 0
            [1, 3, 7, 5], // x = 1
        ];
        let t = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        (v, t)
    }

    fn volume(v: &[Vector3<Real>], t: &[[usize; 3]]) -> Real {
        t.iter()
            .map(|&[a, b, c]| v[a].dot(&v[b].cross(&v[c])) / 6.0)
            .sum()
    }

    #[test]
    fn an_outward_cube_is_kept_as_it_is() {
        let (v, t) = cube();
        assert!(
            (volume(&v, &t) - 1.0).abs() < 1e-12,
            "the fixture faces out"
        );
        let o = orient_outward(&v, &t).unwrap();
        assert_eq!(o.triangles, t);
        assert!(o.turned.is_empty());
    }

    #[test]
    fn an_inward_cube_is_turned_round_whole_and_one_flipped_face_agrees_again() {
        let (v, t) = cube();
        let inward: Vec<[usize; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        let o = orient_outward(&v, &inward).unwrap();
        assert_eq!(o.triangles, t);
        assert_eq!(o.turned.len(), 12);
        let mut one = t.clone();
        one[5] = [t[5][1], t[5][0], t[5][2]];
        let o = orient_outward(&v, &one).unwrap();
        assert!((volume(&v, &o.triangles) - 1.0).abs() < 1e-12);
        assert_eq!(o.turned, vec![6]);
    }

    #[test]
    fn an_open_cube_names_an_edge_of_its_hole() {
        let (v, mut t) = cube();
        t.remove(3);
        match orient_outward(&v, &t) {
            Err(MeshProblem::Open { edge, face, .. }) => {
                // Face 4 (0-based 3) was [4, 7, 6]: its edges now have one face each (faces 3, 6, 8 of
                // the 11 left).
                assert!(edge.iter().all(|&n| [5, 7, 8].contains(&n)), "{edge:?}");
                assert!([3, 6, 8].contains(&face), "{face}");
            }
            other => panic!("expected an open mesh, got {other:?}"),
        }
        let message = orient_outward(&v, &t).unwrap_err().to_string();
        assert!(message.contains("watertight"), "{message}");
    }

    #[test]
    fn an_edge_of_three_faces_is_refused() {
        let (v, mut t) = cube();
        t.push([0, 1, 7]);
        assert!(matches!(
            orient_outward(&v, &t),
            Err(MeshProblem::NonManifold { .. }) | Err(MeshProblem::Open { .. })
        ));
    }
}
