//! Rigid obstacles as drawn: in 3D their surfaces shaded in their own neutral colour through
//! the bodies' depth buffer; in 2D the filled outline of their cut by z = 0 (a half-space as a
//! filled band). Each at its place at the step drawn (`model.json`'s offsets: the translation
//! contact used at that step).

use crate::render::colour_scale::{OBSTACLE_EDGE, OBSTACLE_FILL, OBSTACLE_SURFACE};
use crate::render::draw3d::corner_normals;
use crate::render::{Mesh, MeshKind, Primitive, View};
use crate::scene::{ModelFile, ModelObstacle, HALF_SPACE_PATCH};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashMap;

/// Side of the square a half-space is drawn as, in bounding diagonals of the bodies
/// (`model.json` stores a larger one, [`HALF_SPACE_PATCH`]; this one stays under the bodies).
pub const HALF_SPACE_DRAWN: Real = 1.5;

/// Depth of the band a 2D half-space is drawn as, in bounding diagonals of the bodies.
pub const HALF_SPACE_BAND: Real = 0.12;

/// One obstacle at one step, as drawn: its surface moved to the step's place (a half-space's
/// square cut down to [`HALF_SPACE_DRAWN`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PlacedObstacle {
    /// Surface vertices, m.
    pub vertices: Vec<Vector3<Real>>,
    /// Triangles, 0-based, counter-clockwise seen from outside.
    pub triangles: Vec<[usize; 3]>,
    /// The outward unit normal when the obstacle is a half-space.
    pub half_space: Option<Vector3<Real>>,
}

/// Bounding diagonal of all bodies' undeformed nodes, m (what `model.json` sized a half-space's
/// square by).
pub fn bodies_diagonal(model: &ModelFile) -> Real {
    let mut lo = Vector3::repeat(Real::INFINITY);
    let mut hi = Vector3::repeat(Real::NEG_INFINITY);
    for p in model.bodies.iter().flat_map(|b| &b.nodes) {
        let v = crate::render::deformed_body::vec3(p);
        lo = lo.inf(&v);
        hi = hi.sup(&v);
    }
    if lo.x.is_finite() {
        (hi - lo).norm()
    } else {
        0.0
    }
}

/// Whether `o` is the square `model.json` stores for a half-space: 4 vertices, 2 triangles, a
/// side of [`HALF_SPACE_PATCH`] bodies' diagonals (1 m when that is 0).
fn is_half_space_square(o: &ModelObstacle, diagonal: Real) -> bool {
    if o.vertices.len() != 4 || o.triangles.len() != 2 {
        return false;
    }
    let side = if diagonal > 0.0 && diagonal.is_finite() {
        HALF_SPACE_PATCH * diagonal
    } else {
        1.0
    };
    let v = |k: usize| Vector3::from(o.vertices[k]);
    [(0, 1), (1, 2), (2, 3), (3, 0)]
        .iter()
        .all(|&(a, b)| ((v(a) - v(b)).norm() - side).abs() <= 1e-9 * side)
}

/// Obstacle `o` of a model whose bodies' diagonal is `diagonal`, at stored step `step` (its
/// offset; the last stored offset beyond them).
pub fn place_obstacle(o: &ModelObstacle, step: usize, diagonal: Real) -> PlacedObstacle {
    let offset = o
        .offsets
        .get(step)
        .or(o.offsets.last())
        .map(|d| Vector3::from(*d))
        .unwrap_or_default();
    let mut vertices: Vec<Vector3<Real>> = o
        .vertices
        .iter()
        .map(|v| Vector3::from(*v) + offset)
        .collect();
    let triangles: Vec<[usize; 3]> = o
        .triangles
        .iter()
        .map(|t| t.map(|k| k.saturating_sub(1)))
        .collect();
    let mut half_space = None;
    if is_half_space_square(o, diagonal) {
        let centre = vertices.iter().sum::<Vector3<Real>>() / 4.0;
        let shrink = if diagonal > 0.0 {
            HALF_SPACE_DRAWN / HALF_SPACE_PATCH
        } else {
            1.0
        };
        for v in &mut vertices {
            *v = centre + (*v - centre) * shrink;
        }
        let t = triangles[0];
        let n = (vertices[t[1]] - vertices[t[0]]).cross(&(vertices[t[2]] - vertices[t[0]]));
        half_space = n.try_normalize(1e-300);
    }
    PlacedObstacle {
        vertices,
        triangles,
        half_space,
    }
}

impl PlacedObstacle {
    /// The cut by the plane z = 0 as closed loops of points (z = 0): the outline of a 2D
    /// scene's obstacle. A half-space gives the band below its boundary line, `band` deep; an
    /// open surface other than a half-space gives its cut as open lines (not closed).
    pub fn cut(&self, band: Real) -> Vec<Vec<Vector3<Real>>> {
        let side = |k: usize| self.vertices[k].z >= 0.0;
        let point = |a: usize, b: usize| {
            let (p, q) = (self.vertices[a], self.vertices[b]);
            let t = if p.z == q.z { 0.5 } else { p.z / (p.z - q.z) };
            let mut x = p + (q - p) * t;
            x.z = 0.0;
            x
        };
        let key = |a: usize, b: usize| (a.min(b), a.max(b));
        // Each triangle that crosses z = 0 gives one segment between two of its edges.
        let mut segments: Vec<[(usize, usize); 2]> = Vec::new();
        for t in &self.triangles {
            if t.iter().any(|&k| k >= self.vertices.len()) {
                continue;
            }
            let crossing: Vec<(usize, usize)> = [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
                .into_iter()
                .filter(|&(a, b)| side(a) != side(b))
                .map(|(a, b)| key(a, b))
                .collect();
            if let [e, f] = crossing[..] {
                segments.push([e, f]);
            }
        }
        if let Some(n) = self.half_space {
            // The boundary line: the farthest-apart cut points; the band lies inside.
            let points: Vec<Vector3<Real>> = segments
                .iter()
                .flat_map(|s| s.iter().map(|&(a, b)| point(a, b)))
                .collect();
            let mut ends = None;
            let mut longest = -1.0;
            for (i, p) in points.iter().enumerate() {
                for q in &points[i + 1..] {
                    let d = (p - q).norm();
                    if d > longest {
                        longest = d;
                        ends = Some((*p, *q));
                    }
                }
            }
            let mut n2 = n;
            n2.z = 0.0;
            return match (ends, n2.try_normalize(1e-12)) {
                (Some((a, b)), Some(n2)) => {
                    vec![vec![a, b, b - n2 * band, a - n2 * band]]
                }
                _ => Vec::new(),
            };
        }
        // Chain the segments through the edges they share.
        let mut at_edge: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (i, s) in segments.iter().enumerate() {
            for e in s {
                at_edge.entry(*e).or_default().push(i);
            }
        }
        let mut used = vec![false; segments.len()];
        let mut loops = Vec::new();
        for start in 0..segments.len() {
            if used[start] {
                continue;
            }
            used[start] = true;
            let first = segments[start][0];
            let mut chain = vec![point(first.0, first.1)];
            let mut edge = segments[start][1];
            loop {
                chain.push(point(edge.0, edge.1));
                if edge == first {
                    break;
                }
                let next = at_edge
                    .get(&edge)
                    .and_then(|list| list.iter().copied().find(|&j| !used[j]));
                let Some(j) = next else { break };
                used[j] = true;
                edge = if segments[j][0] == edge {
                    segments[j][1]
                } else {
                    segments[j][0]
                };
            }
            if chain.len() >= 3 {
                loops.push(chain);
            }
        }
        loops
    }

    /// The surface as a shaded mesh in the obstacle colour, only the triangles facing the
    /// camera of `view` (a closed obstacle loses nothing), see-through where a body lies
    /// behind it ([`MeshKind::Obstacle`]); a half-space seen from inside (a press above the
    /// bodies) as a see-through plane ([`MeshKind::Plane`]), so it does not hide them.
    pub fn mesh(&self, view: &View) -> Mesh {
        let front: Vec<[usize; 3]> = self
            .triangles
            .iter()
            .copied()
            .filter(|t| {
                if t.iter().any(|&k| k >= self.vertices.len()) {
                    return false;
                }
                let [a, b, c] = t.map(|k| view.project(&self.vertices[k]));
                // Pixel y points down: counter-clockwise from outside shows as clockwise.
                (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0
            })
            .collect();
        let (triangles, kind) = if front.is_empty() && self.half_space.is_some() {
            let all: Vec<[usize; 3]> = self
                .triangles
                .iter()
                .copied()
                .filter(|t| t.iter().all(|&k| k < self.vertices.len()))
                .collect();
            (all, MeshKind::Plane)
        } else {
            (front, MeshKind::Obstacle)
        };
        Mesh {
            normals: corner_normals(&self.vertices, &triangles),
            positions: self.vertices.clone(),
            colours: vec![OBSTACLE_SURFACE; self.vertices.len()],
            triangles,
            kind,
        }
    }
}

/// The obstacles of `model` at stored step `step` as things to draw: shaded surfaces (3D
/// runs) or filled cuts by z = 0 (2D runs).
pub fn obstacle_primitives(
    model: &ModelFile,
    step: usize,
    is_3d: bool,
    view: &View,
) -> Vec<Primitive> {
    let diagonal = bodies_diagonal(model);
    let band = HALF_SPACE_BAND * if diagonal > 0.0 { diagonal } else { 1.0 };
    model
        .obstacles
        .iter()
        .map(|o| {
            let placed = place_obstacle(o, step, diagonal);
            if is_3d {
                Primitive::Surface(placed.mesh(view))
            } else {
                Primitive::Region {
                    loops: placed.cut(band),
                    fill: OBSTACLE_FILL,
                    edge: OBSTACLE_EDGE,
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> ModelObstacle {
        let s = crate::contact::obstacle_surface(
            &crate::contact::ObstacleShape::Cuboid {
                center: Vector3::new(1.0, 2.0, 0.0),
                half_extents: Vector3::new(0.5, 0.25, 0.3),
                rotation: Vector3::zeros(),
            },
            &Vector3::zeros(),
            1.0,
        );
        ModelObstacle {
            name: "box".into(),
            vertices: s.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
            triangles: s.triangles.iter().map(|t| t.map(|k| k + 1)).collect(),
            offsets: vec![[0.0; 3], [0.0, -0.5, 0.0]],
        }
    }

    #[test]
    fn a_box_cut_by_z_0_is_its_rectangle_at_its_offset() {
        let o = cube();
        let loops = place_obstacle(&o, 1, 1.0).cut(0.1);
        assert_eq!(loops.len(), 1);
        let l = &loops[0];
        let (mut lo, mut hi) = (Vector3::repeat(1e9), Vector3::repeat(-1e9));
        for p in l {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        assert!((lo - Vector3::new(0.5, 1.25, 0.0)).norm() < 1e-12, "{lo}");
        assert!((hi - Vector3::new(1.5, 1.75, 0.0)).norm() < 1e-12, "{hi}");
        // Closed: the last point is the first.
        assert!((l[0] - l[l.len() - 1]).norm() < 1e-12);
    }
}
