//! Sharp features of polyhedral obstacles (cuboids, meshes) and cylinders' rims: the face, edge or corner a node crossed since the last solved state, and the points sampled along sharp edges that press a coarse body's patches.

use crate::contact::cylinder_rim::CylinderRim;
use crate::contact::obstacles::{from_glam, to_glam};
use crate::contact::{ActiveContact, ContactSet, ObstacleShape, Target};
use crate::Real;
use nalgebra::{Rotation3, Vector3};
use rapier3d_f64::parry::query::PointQuery;
use rapier3d_f64::parry::shape::Triangle;
use std::collections::HashMap;
use std::sync::Mutex;

/// Faces met at a crossing point count as crossed when the node moves into them at least this
/// fraction of the rate at which it moves into the face it moves into most: a node pressed
/// straight into a face that merely slides along a side face through the same edge (the rim of
/// a flush plate) has crossed the one face, while a node moving down the bisector of an edge
/// crosses both.
pub const CROSSED_RATE: Real = 0.25;

/// An edge is sharp when the normals of its two faces differ by more than this angle (rad,
/// 30°): a cuboid's or a wedge's edges are, the facets of a finely tessellated curve are not.
pub const SHARP_ANGLE: Real = std::f64::consts::FRAC_PI_6;

/// Points along sharp edges are at most this fraction of the shortest member apart.
pub const SAMPLE_SPACING: Real = 0.5;

/// More points than this along an obstacle's sharp edges are refused before any is made (240 MB
/// of points): an obstacle sized far beyond its bodies (a cuboid 1e19 m long) would need them.
pub const MAX_SHARP_SAMPLES: Real = 1e7;

/// How many points the sharp edges of `shape` take at [`SAMPLE_SPACING`] × `shortest` (the
/// bodies' shortest member, m), estimated from its edge lengths before any point is made: a
/// cuboid's 12 edges, `8 (a + b + c)` for half extents a, b, c; a cylinder's two rims, `4 π r`;
/// a mesh's edges, half the sum of its triangles' perimeters (every edge a sharp one at most);
/// 0 for the smooth shapes.
pub fn sharp_sample_estimate(shape: &ObstacleShape, shortest: Real) -> Real {
    let length = match shape {
        ObstacleShape::Cuboid { half_extents, .. } => {
            8.0 * (half_extents.x.abs() + half_extents.y.abs() + half_extents.z.abs())
        }
        ObstacleShape::Cylinder { radius, .. } => 2.0 * std::f64::consts::TAU * radius.abs(),
        ObstacleShape::Mesh {
            vertices,
            triangles,
        } => {
            let edge = |a: usize, b: usize| match (vertices.get(a), vertices.get(b)) {
                (Some(p), Some(q)) => (p - q).norm(),
                _ => 0.0,
            };
            triangles
                .iter()
                .map(|t| edge(t[0], t[1]) + edge(t[1], t[2]) + edge(t[2], t[0]))
                .sum::<Real>()
                / 2.0
        }
        _ => 0.0,
    };
    length / (SAMPLE_SPACING * shortest)
}

/// Where and along which normal a node entered a polyhedral obstacle, in the obstacle's frame at
/// the start of its travel (world coordinates minus the obstacle's offset).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crossing {
    /// The point on the obstacle's surface where the node crossed it, m.
    pub(crate) point: Vector3<Real>,
    /// Outward unit normal: the crossed face's, or at an edge or corner the normalised mean of
    /// the normals of the faces crossed there.
    pub(crate) normal: Vector3<Real>,
}

impl Crossing {
    /// The depth (m) of `x` behind the plane through the crossing with its normal, the obstacle
    /// at `offset`: linear in `x`, so `k n nᵀ` is its exact stiffness.
    pub(crate) fn depth(&self, x: &Vector3<Real>, offset: &Vector3<Real>) -> Real {
        (self.point + offset - x).dot(&self.normal)
    }
}

/// A closed polyhedral obstacle as outward triangles, in the world frame at offset 0.
pub(crate) struct Polyhedron {
    vertices: Vec<Vector3<Real>>,
    triangles: Vec<[usize; 3]>,
    normals: Vec<Vector3<Real>>,
}

impl Polyhedron {
    /// The triangles of a cuboid or a mesh (`None` for the smooth shapes and a half-space,
    /// which keep the nearest-point projection).
    pub(crate) fn of(shape: &ObstacleShape) -> Option<Self> {
        let (vertices, triangles) = match shape {
            ObstacleShape::Cuboid {
                center,
                half_extents,
                rotation,
            } => {
                let r = Rotation3::new(*rotation);
                let h = half_extents;
                let vertices = (0..8)
                    .map(|i| {
                        let s = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
                        center + r * Vector3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
                    })
                    .collect();
                // Two outward triangles per face (vertex i has x, y, z bits 1, 2, 4).
                let quads = [
                    [0, 4, 6, 2], // −x
                    [1, 3, 7, 5], // +x
                    [0, 1, 5, 4], // −y
                    [2, 6, 7, 3], // +y
                    [0, 2, 3, 1], // −z
                    [4, 5, 7, 6], // +z
                ];
                let triangles: Vec<[usize; 3]> = quads
                    .iter()
                    .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
                    .collect();
                (vertices, triangles)
            }
            ObstacleShape::Mesh {
                vertices,
                triangles,
            } => {
                // Corners that repeat are one vertex (the collider merges them too).
                let mut index: HashMap<[u64; 3], usize> = HashMap::new();
                let mut merged = Vec::new();
                let map: Vec<usize> = vertices
                    .iter()
                    .map(|v| {
                        *index
                            .entry([v.x, v.y, v.z].map(Real::to_bits))
                            .or_insert_with(|| {
                                merged.push(*v);
                                merged.len() - 1
                            })
                    })
                    .collect();
                let triangles = triangles
                    .iter()
                    .map(|t| t.map(|i| map[i]))
                    .filter(|[a, b, c]| a != b && b != c && a != c)
                    .collect();
                (merged, triangles)
            }
            _ => return None,
        };
        let normals = triangles
            .iter()
            .map(|&[a, b, c]: &[usize; 3]| {
                let n: Vector3<Real> =
                    (vertices[b] - vertices[a]).cross(&(vertices[c] - vertices[a]));
                n.try_normalize(0.0).unwrap_or_default()
            })
            .collect();
        Some(Polyhedron {
            vertices,
            triangles,
            normals,
        })
    }

    /// The distance from `p` to triangle `t`, m.
    fn distance_to(&self, t: usize, p: &Vector3<Real>) -> Real {
        let [a, b, c] = self.triangles[t].map(|i| to_glam(&self.vertices[i]));
        let projection = Triangle::new(a, b, c).project_local_point(to_glam(p), true);
        (from_glam(projection.point) - p).norm()
    }

    /// Where the segment from `from` (outside or on the surface) to `to` (m, both in the frame
    /// at offset 0) last entered the polyhedron, with the normal of the faces crossed there (see
    /// [`CROSSED_RATE`]); faces within `tolerance` (m) of the crossing point meet there. `None`
    /// when the segment enters nowhere (it starts inside).
    pub(crate) fn crossing(
        &self,
        from: &Vector3<Real>,
        to: &Vector3<Real>,
        tolerance: Real,
    ) -> Option<Crossing> {
        let mut last: Option<Real> = None;
        for (t, n) in self.normals.iter().enumerate() {
            let v = self.vertices[self.triangles[t][0]];
            let (da, db) = ((from - v).dot(n), (to - v).dot(n));
            if da < -tolerance || db >= 0.0 || da <= db {
                continue;
            }
            let s = (da / (da - db)).clamp(0.0, 1.0);
            let p = from + (to - from) * s;
            if self.distance_to(t, &p) <= tolerance && last.is_none_or(|l| s > l) {
                last = Some(s);
            }
        }
        let point = from + (to - from) * last?;
        // The faces meeting at the crossing point that the node moved into, one per direction.
        let mut faces: Vec<(Vector3<Real>, Real)> = Vec::new();
        for (t, n) in self.normals.iter().enumerate() {
            let v = self.vertices[self.triangles[t][0]];
            let rate = (from - to).dot(n);
            if rate <= 0.0
                || (point - v).dot(n).abs() > tolerance
                || self.distance_to(t, &point) > tolerance
                || faces.iter().any(|(m, _)| m.dot(n) > 1.0 - 1e-9)
            {
                continue;
            }
            faces.push((*n, rate));
        }
        let most = faces.iter().map(|f| f.1).fold(0.0, Real::max);
        let sum: Vector3<Real> = faces
            .iter()
            .filter(|f| f.1 >= CROSSED_RATE * most)
            .map(|f| f.0)
            .sum();
        let normal = sum.try_normalize(0.0)?;
        Some(Crossing { point, normal })
    }

    /// Points along the convex sharp edges (see [`SHARP_ANGLE`]), ends included (corners once),
    /// at most `spacing` (m) apart.
    pub(crate) fn sharp_points(&self, spacing: Real) -> Vec<Vector3<Real>> {
        let mut points = Vec::new();
        let mut corners = vec![false; self.vertices.len()];
        for (a, b) in self.sharp_edges() {
            let (pa, pb) = (self.vertices[a], self.vertices[b]);
            // (A length of a whole number of spacings is that many pieces, round-off aside.)
            let pieces = ((pb - pa).norm() / spacing * (1.0 - 1e-9)).ceil().max(1.0) as usize;
            for i in 0..=pieces {
                let end = if i == 0 {
                    Some(a)
                } else if i == pieces {
                    Some(b)
                } else {
                    None
                };
                if let Some(v) = end {
                    if std::mem::replace(&mut corners[v], true) {
                        continue;
                    }
                }
                points.push(pa + (pb - pa) * (i as Real / pieces as Real));
            }
        }
        points
    }

    /// Where the convex sharp edges cross the plane z = 0 (the corners of a 2D scene's section).
    pub(crate) fn section_corners(&self) -> Vec<Vector3<Real>> {
        let mut points: Vec<Vector3<Real>> = Vec::new();
        for (a, b) in self.sharp_edges() {
            let (pa, pb) = (self.vertices[a], self.vertices[b]);
            if (pa.z > 0.0) == (pb.z > 0.0) || pa.z == pb.z {
                continue;
            }
            let s = pa.z / (pa.z - pb.z);
            let mut p = pa + (pb - pa) * s;
            p.z = 0.0;
            points.push(p);
        }
        points
    }

    /// The convex sharp edges (see [`SHARP_ANGLE`]) as sorted vertex pairs.
    fn sharp_edges(&self) -> Vec<(usize, usize)> {
        let mut edges: HashMap<(usize, usize), Vec<usize>> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                edges.entry((a.min(b), a.max(b))).or_default().push(t);
            }
        }
        let mut sharp: Vec<(usize, usize)> = edges
            .iter()
            .filter(|(&(a, b), faces)| {
                let [f, g] = faces[..] else { return false };
                let (nf, ng) = (self.normals[f], self.normals[g]);
                // Convex: the far corner of one face lies behind the other's plane.
                let c = self.triangles[g].into_iter().find(|&i| i != a && i != b);
                let convex =
                    c.is_some_and(|c| (self.vertices[c] - self.vertices[a]).dot(&nf) < 0.0);
                convex && nf.dot(&ng) < SHARP_ANGLE.cos()
            })
            .map(|(&e, _)| e)
            .collect();
        sharp.sort_unstable();
        sharp
    }
}

/// An obstacle with sharp features: polyhedral (a cuboid, a mesh) or a cylinder (its rims).
pub(crate) enum SharpShape {
    /// Triangles, their edges sharp where the faces turn by more than [`SHARP_ANGLE`].
    Polyhedron(Polyhedron),
    /// A cylinder: smooth side, flat caps, sharp rims.
    Cylinder(CylinderRim),
}

impl SharpShape {
    /// The sharp features of `shape`; `None` for the smooth shapes and a half-space.
    pub(crate) fn of(shape: &ObstacleShape) -> Option<Self> {
        match shape {
            ObstacleShape::Cylinder {
                center,
                radius,
                half_height,
                rotation,
            } => Some(SharpShape::Cylinder(CylinderRim::new(
                *center,
                *radius,
                *half_height,
                *rotation,
            ))),
            _ => Polyhedron::of(shape).map(SharpShape::Polyhedron),
        }
    }

    /// See [`Polyhedron::crossing`] and [`CylinderRim::crossing`].
    pub(crate) fn crossing(
        &self,
        from: &Vector3<Real>,
        to: &Vector3<Real>,
        tolerance: Real,
    ) -> Option<Crossing> {
        match self {
            SharpShape::Polyhedron(p) => p.crossing(from, to, tolerance),
            SharpShape::Cylinder(c) => c.crossing(from, to, tolerance),
        }
    }

    /// Points along the sharp edges, at most `spacing` (m) apart.
    pub(crate) fn sharp_points(&self, spacing: Real) -> Vec<Vector3<Real>> {
        match self {
            SharpShape::Polyhedron(p) => p.sharp_points(spacing),
            SharpShape::Cylinder(c) => c.sharp_points(spacing),
        }
    }

    /// Where the sharp edges cross z = 0.
    pub(crate) fn section_corners(&self) -> Vec<Vector3<Real>> {
        match self {
            SharpShape::Polyhedron(p) => p.section_corners(),
            SharpShape::Cylinder(c) => c.section_corners(),
        }
    }
}

/// The sharp features of every obstacle and the crossings of the nodes into them.
pub(crate) struct Features {
    /// Per obstacle, its sharp features (`None`: a smooth obstacle).
    polyhedra: Vec<Option<SharpShape>>,
    /// Per obstacle, the points along its sharp edges at offset 0, m (2D: the corners of its
    /// section by z = 0).
    pub(crate) points: Vec<Vec<Vector3<Real>>>,
    /// Per body, per node: its position at the last solved state, m.
    start: Vec<Vec<Vector3<Real>>>,
    /// Per obstacle, its offset at the last solved state, m.
    start_offsets: Vec<Vector3<Real>>,
    /// Crossings of the contacts of the last solved state, kept while they stay in the set.
    committed: HashMap<(usize, usize, usize), Option<Crossing>>,
    /// Crossings found during the step (the first time each node was found inside), so that a
    /// contact keeps one normal through the step's Newton iterations.
    pending: Mutex<HashMap<(usize, usize, usize), Option<Crossing>>>,
    /// Faces within this distance of a crossing point meet there, and a node this near the
    /// surface may have crossed it, m.
    pub(crate) tolerance: Real,
}

impl Features {
    /// The features of `shapes`; `shortest` is the shortest member of the bodies (m), the
    /// scale of the sample spacing and of the tolerance; `dimension` 2 samples sections.
    pub(crate) fn new(
        shapes: &[&ObstacleShape],
        start: Vec<Vec<Vector3<Real>>>,
        shortest: Real,
        two_d: bool,
    ) -> Self {
        let polyhedra: Vec<Option<SharpShape>> = shapes.iter().map(|s| SharpShape::of(s)).collect();
        let points = polyhedra
            .iter()
            .map(|p| match p {
                Some(p) if two_d => p.section_corners(),
                Some(p) if shortest.is_finite() => p.sharp_points(SAMPLE_SPACING * shortest),
                _ => Vec::new(),
            })
            .collect();
        Features {
            start_offsets: vec![Vector3::zeros(); polyhedra.len()],
            polyhedra,
            points,
            start,
            committed: HashMap::new(),
            pending: Mutex::new(HashMap::new()),
            tolerance: if shortest.is_finite() {
                1e-6 * shortest
            } else {
                0.0
            },
        }
    }

    /// The crossing of `node` of `body` (now at `x`, m) into obstacle `o` (at `offset`, m): the
    /// one remembered for this contact, else found on the segment from the node's position at
    /// the last solved state, and remembered. `None` for a smooth obstacle or a node that was
    /// inside already (the nearest-point projection is used then).
    pub(crate) fn crossing(
        &self,
        body: usize,
        node: usize,
        o: usize,
        x: &Vector3<Real>,
        offset: &Vector3<Real>,
    ) -> Option<Crossing> {
        let polyhedron = self.polyhedra.get(o)?.as_ref()?;
        let key = (body, node, o);
        if let Some(c) = self.committed.get(&key) {
            return *c;
        }
        let mut pending = self.pending.lock().unwrap_or_else(|e| e.into_inner());
        *pending.entry(key).or_insert_with(|| {
            let from = self.start.get(body)?.get(node)? - self.start_offsets[o];
            polyhedron.crossing(&from, &(x - offset), self.tolerance)
        })
    }

    /// The offset of obstacle `o` at the last solved state, m.
    pub(crate) fn start_offset(&self, o: usize) -> Vector3<Real> {
        self.start_offsets.get(o).copied().unwrap_or_default()
    }

    /// Forget the crossings found since the last [`Features::record`].
    pub(crate) fn forget_pending(&mut self) {
        self.pending
            .get_mut()
            .unwrap_or_else(|e| e.into_inner())
            .clear();
    }

    /// Commit the crossings of the contacts of `active` (the last solved state, the node
    /// positions `start` and obstacle `offsets` there, m) and forget the others.
    pub(crate) fn record(
        &mut self,
        active: &ContactSet,
        start: Vec<Vec<Vector3<Real>>>,
        offsets: Vec<Vector3<Real>>,
    ) {
        let pending = std::mem::take(self.pending.get_mut().unwrap_or_else(|e| e.into_inner()));
        let mut committed = HashMap::new();
        for &ActiveContact { body, node, with } in &active.contacts {
            let Target::Obstacle(o) = with else { continue };
            let key = (body, node, o);
            if let Some(c) = pending.get(&key).or_else(|| self.committed.get(&key)) {
                committed.insert(key, *c);
            }
        }
        self.committed = committed;
        self.start = start;
        self.start_offsets = offsets;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unit_cube() -> Polyhedron {
        Polyhedron::of(&ObstacleShape::Cuboid {
            center: Vector3::zeros(),
            half_extents: Vector3::repeat(0.5),
            rotation: Vector3::zeros(),
        })
        .unwrap()
    }

    #[test]
    fn cuboid_triangles_face_outward() {
        let p = unit_cube();
        for (t, n) in p.normals.iter().enumerate() {
            let centre: Vector3<Real> = p.triangles[t]
                .iter()
                .map(|&i| p.vertices[i])
                .sum::<Vector3<Real>>()
                / 3.0;
            assert!((n.dot(&centre) - 0.5).abs() < 1e-12, "{t}: {n:?}");
        }
    }

    #[test]
    fn a_node_crossing_a_face_takes_that_face_not_the_nearest() {
        // Entered through the top face, now nearest to the +x face.
        let c = unit_cube()
            .crossing(
                &Vector3::new(0.45, 0.6, 0.0),
                &Vector3::new(0.45, 0.1, 0.0),
                1e-9,
            )
            .unwrap();
        assert!((c.normal - Vector3::y()).norm() < 1e-12);
        assert!((c.depth(&Vector3::new(0.45, 0.1, 0.0), &Vector3::zeros()) - 0.4).abs() < 1e-12);
    }

    #[test]
    fn crossing_at_an_edge_takes_the_mean_normal() {
        let c = unit_cube()
            .crossing(
                &Vector3::new(0.6, 0.6, 0.1),
                &Vector3::new(0.4, 0.4, 0.1),
                1e-9,
            )
            .unwrap();
        let mean = Vector3::new(1.0, 1.0, 0.0).normalize();
        assert!((c.normal - mean).norm() < 1e-12, "{c:?}");
    }

    #[test]
    fn sliding_along_a_side_face_into_the_bottom_is_the_bottom() {
        // A node on the bottom edge pushed up into the cube, a hair inward through the side.
        let c = unit_cube()
            .crossing(
                &Vector3::new(0.5, -0.5, 0.0),
                &Vector3::new(0.5 - 1e-6, -0.49, 0.0),
                1e-9,
            )
            .unwrap();
        assert!((c.normal + Vector3::y()).norm() < 1e-12, "{c:?}");
    }

    #[test]
    fn a_cube_has_twelve_sharp_edges_and_eight_corners() {
        let points = unit_cube().sharp_points(0.5);
        // Each edge in two pieces: 8 corners and 12 midpoints.
        assert_eq!(points.len(), 20);
        let section = Polyhedron::of(&ObstacleShape::Cuboid {
            center: Vector3::zeros(),
            half_extents: Vector3::repeat(0.5),
            rotation: Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_4),
        })
        .unwrap()
        .section_corners();
        assert_eq!(section.len(), 4, "{section:?}");
        assert!(section
            .iter()
            .any(|p| (p - Vector3::new(0.0, -0.5 * 2f64.sqrt(), 0.0)).norm() < 1e-12));
    }
}
