//! The surface of a rigid obstacle as triangles at step 0, for pictures and ParaView files.
//! Positions and rotations come from the collider contact uses ([`primitive_collider`]), so
//! what is drawn is what the bodies press on.

use crate::contact::obstacles::{from_glam, primitive_collider, to_glam};
use crate::contact::ObstacleShape;
use crate::Real;
use nalgebra::Vector3;

/// Segments around a ball, cylinder or capsule (about its local y axis).
pub const AROUND: usize = 32;
/// Segments from pole to pole of a ball (half of them on each half of a capsule).
pub const POLE_TO_POLE: usize = 16;

/// A triangle surface: vertices (m) and counter-clockwise (seen from outside) triangles of
/// 0-based vertex indices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Surface {
    /// Vertices, m.
    pub vertices: Vec<Vector3<Real>>,
    /// Triangles, 0-based vertex indices.
    pub triangles: Vec<[usize; 3]>,
}

/// The surface of `shape` at step 0. A half-space, which has none that ends, is drawn as a
/// square of side `patch_side` (m) centred on the projection of `near` on its plane. A cuboid
/// has 12 triangles; a ball `POLE_TO_POLE` × `AROUND` faces; a cylinder and a capsule are
/// closed surfaces of revolution about their local y axis; a mesh is its own triangles.
pub fn obstacle_surface(shape: &ObstacleShape, near: &Vector3<Real>, patch_side: Real) -> Surface {
    let local = match shape {
        ObstacleShape::Mesh {
            vertices,
            triangles,
        } => {
            return Surface {
                vertices: vertices.clone(),
                triangles: triangles.clone(),
            }
        }
        ObstacleShape::HalfSpace { point, normal } => {
            // Drawn in world coordinates: the collider's frame is a translation only.
            let n = normal.normalize();
            let centre = near - n * (near - point).dot(&n);
            let (u, v) = plane_axes(&n);
            let h = 0.5 * patch_side;
            return Surface {
                vertices: [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                    .iter()
                    .map(|(a, b)| centre + u * (a * h) + v * (b * h))
                    .collect(),
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            };
        }
        ObstacleShape::Cuboid { half_extents, .. } => cuboid(half_extents),
        ObstacleShape::Ball { radius, .. } => {
            let profile = (0..=POLE_TO_POLE)
                .map(|k| arc_point(*radius, k, POLE_TO_POLE, 0.0))
                .collect::<Vec<_>>();
            revolution(&profile)
        }
        ObstacleShape::Cylinder {
            radius,
            half_height,
            ..
        } => revolution(&[
            (0.0, *half_height),
            (*radius, *half_height),
            (*radius, -*half_height),
            (0.0, -*half_height),
        ]),
        ObstacleShape::Capsule {
            radius,
            half_height,
            ..
        } => {
            let half = POLE_TO_POLE / 2;
            let top = (0..=half).map(|k| arc_point(*radius, k, POLE_TO_POLE, *half_height));
            let bottom =
                (half..=POLE_TO_POLE).map(|k| arc_point(*radius, k, POLE_TO_POLE, -*half_height));
            revolution(&top.chain(bottom).collect::<Vec<_>>())
        }
    };
    match primitive_collider(shape) {
        Some(builder) => {
            let collider = builder.build();
            let pose = collider.position();
            Surface {
                vertices: local
                    .vertices
                    .iter()
                    .map(|p| from_glam(pose.transform_point(to_glam(p))))
                    .collect(),
                triangles: local.triangles,
            }
        }
        None => local,
    }
}

/// Two unit vectors spanning the plane of unit normal `n`. The first is `n × z` when `n` is
/// not along z, so in a 2D scene (normal in the plane z = 0) the square crosses z = 0 along
/// its full side.
fn plane_axes(n: &Vector3<Real>) -> (Vector3<Real>, Vector3<Real>) {
    let z = Vector3::z();
    let u = if n.cross(&z).norm() > 1e-6 {
        n.cross(&z).normalize()
    } else {
        n.cross(&Vector3::x()).normalize()
    };
    (u, n.cross(&u))
}

/// Point `k` of `count` on a half circle of `radius` from the +y pole to the −y pole, as
/// (distance from the axis, y + `shift`).
fn arc_point(radius: Real, k: usize, count: usize, shift: Real) -> (Real, Real) {
    let t = std::f64::consts::PI * k as Real / count as Real;
    let rho = if k == 0 || k == count {
        0.0
    } else {
        radius * t.sin()
    };
    (rho, radius * t.cos() + shift)
}

/// The 8 corners and 12 outward triangles of a box centred at the origin.
fn cuboid(h: &Vector3<Real>) -> Surface {
    let vertices = (0..8)
        .map(|k| {
            let s = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
            Vector3::new(s(1) * h.x, s(2) * h.y, s(4) * h.z)
        })
        .collect();
    // Corner k has x from bit 1, y from bit 2, z from bit 4.
    let quads = [
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Surface {
        vertices,
        triangles,
    }
}

/// The closed surface swept by turning `profile` (distance from the y axis, y), from top to
/// bottom, about the y axis in `AROUND` segments. A point on the axis (distance 0) is one
/// vertex (a pole); the others are rings.
fn revolution(profile: &[(Real, Real)]) -> Surface {
    let mut vertices = Vec::new();
    let mut rings: Vec<Vec<usize>> = Vec::new();
    for &(rho, y) in profile {
        let start = vertices.len();
        if rho == 0.0 {
            vertices.push(Vector3::new(0.0, y, 0.0));
            rings.push(vec![start; AROUND]);
        } else {
            for j in 0..AROUND {
                let phi = 2.0 * std::f64::consts::PI * j as Real / AROUND as Real;
                vertices.push(Vector3::new(rho * phi.cos(), y, rho * phi.sin()));
            }
            rings.push((start..start + AROUND).collect());
        }
    }
    let mut triangles = Vec::new();
    for w in rings.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        for j in 0..AROUND {
            let k = (j + 1) % AROUND;
            // Outward with x = ρ cos φ, z = ρ sin φ and the profile running down y.
            if a[j] != a[k] {
                triangles.push([a[j], a[k], b[k]]);
            }
            if b[j] != b[k] {
                triangles.push([a[j], b[k], b[j]]);
            }
        }
    }
    Surface {
        vertices,
        triangles,
    }
}

/// The cut of `surface` by the plane z = 0: one segment per triangle that has corners on
/// both sides (a corner on the plane counts as above it), as pairs of points.
pub fn cut_by_z0(vertices: &[Vector3<Real>], triangles: &[[usize; 3]]) -> Vec<[Vector3<Real>; 2]> {
    let mut segments = Vec::new();
    for t in triangles {
        let p = t.map(|i| vertices[i]);
        let mut ends = Vec::with_capacity(2);
        for (a, b) in [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])] {
            if (a.z >= 0.0) != (b.z >= 0.0) {
                let s = a.z / (a.z - b.z);
                let mut x = a + (b - a) * s;
                x.z = 0.0;
                ends.push(x);
            }
        }
        if let [a, b] = ends[..] {
            segments.push([a, b]);
        }
    }
    segments
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Obstacle, Obstacles};
    use crate::linkage::Schedule;

    fn shapes() -> Vec<ObstacleShape> {
        let r = Vector3::new(0.3, -0.7, 1.1);
        let c = Vector3::new(1.0, -2.0, 0.5);
        vec![
            ObstacleShape::Cuboid {
                center: c,
                half_extents: Vector3::new(0.4, 0.2, 0.7),
                rotation: r,
            },
            ObstacleShape::Ball {
                center: c,
                radius: 0.6,
            },
            ObstacleShape::Cylinder {
                center: c,
                radius: 0.6,
                half_height: 0.9,
                rotation: r,
            },
            ObstacleShape::Capsule {
                center: c,
                radius: 0.6,
                half_height: 0.9,
                rotation: r,
            },
            ObstacleShape::HalfSpace {
                point: c,
                normal: Vector3::new(1.0, 2.0, -0.5).normalize(),
            },
        ]
    }

    /// Every vertex lies on the surface the contact projects on, and every triangle's normal
    /// points out of it (along the outward normal contact finds at the triangle's centroid).
    #[test]
    fn surfaces_lie_on_the_colliders_and_face_out() {
        for shape in shapes() {
            let s = obstacle_surface(&shape, &Vector3::new(3.0, 1.0, -1.0), 5.0);
            let o = Obstacles::new(&[Obstacle {
                name: "o".into(),
                shape: shape.clone(),
                travel: Vector3::zeros(),
                schedule: Schedule::Linear,
            }])
            .unwrap();
            for v in &s.vertices {
                let p = o.project(0, v, &Vector3::zeros()).unwrap();
                assert!(p.depth.abs() < 1e-9, "{shape:?}: {v} at depth {}", p.depth);
            }
            for t in &s.triangles {
                let [a, b, c] = t.map(|i| s.vertices[i]);
                let n = (b - a).cross(&(c - a));
                if n.norm() < 1e-12 {
                    continue;
                }
                // Just inside, so the nearest surface point is on this face.
                let mid = (a + b + c) / 3.0 - n.normalize() * 1e-3;
                let p = o.project(0, &mid, &Vector3::zeros()).unwrap();
                let outward = p.normal.unwrap();
                assert!(
                    outward.dot(&n.normalize()) > 0.5,
                    "{shape:?}: triangle {t:?} faces in"
                );
            }
        }
    }

    #[test]
    fn counts() {
        let s = shapes();
        let far = Vector3::zeros();
        assert_eq!(obstacle_surface(&s[0], &far, 1.0).triangles.len(), 12);
        assert_eq!(obstacle_surface(&s[0], &far, 1.0).vertices.len(), 8);
        assert_eq!(
            obstacle_surface(&s[1], &far, 1.0).triangles.len(),
            2 * AROUND * (POLE_TO_POLE - 1)
        );
        assert_eq!(obstacle_surface(&s[4], &far, 1.0).triangles.len(), 2);
    }

    #[test]
    fn a_cut_square_in_the_plane_is_its_side() {
        // The half-space y < 0 of a 2D scene: its 4 m square crosses z = 0 along x.
        let s = obstacle_surface(
            &ObstacleShape::HalfSpace {
                point: Vector3::zeros(),
                normal: Vector3::y(),
            },
            &Vector3::new(1.0, 3.0, 0.0),
            4.0,
        );
        let cut = cut_by_z0(&s.vertices, &s.triangles);
        let xs: Vec<Real> = cut.iter().flat_map(|s| [s[0].x, s[1].x]).collect();
        let lo = xs.iter().cloned().fold(Real::INFINITY, Real::min);
        let hi = xs.iter().cloned().fold(Real::NEG_INFINITY, Real::max);
        assert!(
            (lo + 1.0).abs() < 1e-12 && (hi - 3.0).abs() < 1e-12,
            "{cut:?}"
        );
        assert!(cut
            .iter()
            .all(|s| s[0].y.abs() < 1e-15 && s[1].y.abs() < 1e-15));
    }
}
