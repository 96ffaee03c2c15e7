//! The scene's rigid obstacles as fixed colliders in rapier, queried by point projection.

use crate::contact::{Obstacle, ObstacleShape};
use crate::Real;
use nalgebra::Vector3;
use rapier3d_f64::geometry::{ColliderBuilder, ColliderHandle, ColliderSet, SharedShape};
use rapier3d_f64::math::{Pose, Vector};
use rapier3d_f64::parry::shape::TriMeshFlags;

/// Where a node stands against one obstacle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObstacleProjection {
    /// Penetration depth, m: positive inside the obstacle, negative outside (the gap).
    pub depth: Real,
    /// Outward unit normal of the obstacle's surface at the nearest point; `None` when the node
    /// lies exactly on the surface with no direction to tell (a depth of 0).
    pub normal: Option<Vector3<Real>>,
    /// The nearest point of the obstacle's surface, m.
    pub surface: Vector3<Real>,
}

/// Rigid obstacles held as fixed colliders (no rigid bodies: they never move by themselves;
/// a prescribed travel is applied by moving the query point the other way).
pub struct Obstacles {
    /// rapier's collider set, one collider per obstacle.
    pub colliders: ColliderSet,
    /// Per obstacle, in scene order: its collider and its description.
    pub entries: Vec<(ColliderHandle, Obstacle)>,
}

pub(crate) fn to_glam(v: &Vector3<Real>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

pub(crate) fn from_glam(v: Vector) -> Vector3<Real> {
    Vector3::new(v.x, v.y, v.z)
}

/// A fixed collider for a closed triangle mesh, oriented (so that points inside are told from
/// points outside).
pub fn mesh_collider(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
) -> Result<ColliderBuilder, String> {
    let indices = triangles.iter().map(|t| t.map(|i| i as u32)).collect();
    ColliderBuilder::trimesh_with_flags(
        vertices.iter().map(to_glam).collect(),
        indices,
        TriMeshFlags::ORIENTED | TriMeshFlags::MERGE_DUPLICATE_VERTICES,
    )
    .map_err(|e| format!("the triangle mesh cannot be built: {e}"))
}

/// The fixed collider of every shape but a mesh (`None` for a mesh, which has its own
/// vertices: [`mesh_collider`]), placed at the shape's step-0 position and rotation.
pub fn primitive_collider(shape: &ObstacleShape) -> Option<ColliderBuilder> {
    Some(match shape {
        ObstacleShape::HalfSpace { point, normal } => {
            ColliderBuilder::new(SharedShape::halfspace(to_glam(&normal.normalize())))
                .translation(to_glam(point))
        }
        ObstacleShape::Cuboid {
            center,
            half_extents,
            rotation,
        } => ColliderBuilder::cuboid(half_extents.x, half_extents.y, half_extents.z)
            .position(Pose::new(to_glam(center), to_glam(rotation))),
        ObstacleShape::Ball { center, radius } => {
            ColliderBuilder::ball(*radius).translation(to_glam(center))
        }
        ObstacleShape::Cylinder {
            center,
            radius,
            half_height,
            rotation,
        } => ColliderBuilder::cylinder(*half_height, *radius)
            .position(Pose::new(to_glam(center), to_glam(rotation))),
        ObstacleShape::Capsule {
            center,
            radius,
            half_height,
            rotation,
        } => ColliderBuilder::capsule_y(*half_height, *radius)
            .position(Pose::new(to_glam(center), to_glam(rotation))),
        ObstacleShape::Mesh { .. } => return None,
    })
}

impl Obstacles {
    /// Insert every obstacle of `list` as a fixed collider. Fails (naming the obstacle) for a
    /// triangle mesh parry cannot build.
    pub fn new(list: &[Obstacle]) -> Result<Self, String> {
        let mut colliders = ColliderSet::new();
        let mut entries = Vec::with_capacity(list.len());
        for obstacle in list {
            let collider = match &obstacle.shape {
                ObstacleShape::Mesh {
                    vertices,
                    triangles,
                } => mesh_collider(vertices, triangles)?,
                shape => primitive_collider(shape).ok_or_else(|| {
                    format!("obstacle '{}': no collider for its shape", obstacle.name)
                })?,
            };
            let handle = colliders.insert(collider.build());
            entries.push((handle, obstacle.clone()));
        }
        Ok(Obstacles { colliders, entries })
    }

    /// Number of obstacles.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Name of obstacle `index`.
    pub fn name(&self, index: usize) -> &str {
        &self.entries[index].1.name
    }

    /// Project the point `x` (m) on obstacle `index` translated by `offset` (m): depth,
    /// outward normal and nearest surface point. `None` if the obstacle is not in the set.
    pub fn project(
        &self,
        index: usize,
        x: &Vector3<Real>,
        offset: &Vector3<Real>,
    ) -> Option<ObstacleProjection> {
        let (handle, obstacle) = self.entries.get(index)?;
        let collider = self.colliders.get(*handle)?;
        let local = x - offset;
        if let ObstacleShape::HalfSpace { point, normal } = &obstacle.shape {
            // A plane's normal is its own, not the direction to the nearest point: at a depth
            // of 1e-10 m that direction carries the coordinates' round-off (1e-17 m) as 1e-7
            // of a turn, which a tilted floor's friction sees (issue 32, contact case 1).
            let n = normal.normalize();
            let depth = (point - local).dot(&n);
            return Some(ObstacleProjection {
                depth,
                normal: Some(n),
                surface: local + n * depth + offset,
            });
        }
        let projection =
            collider
                .shape()
                .project_point(collider.position(), to_glam(&local), false);
        let surface = from_glam(projection.point);
        let towards = surface - local;
        let distance = towards.norm();
        let normal = if distance > 0.0 && distance.is_finite() {
            // Inside: the surface is outward from the node; outside: the node is outward.
            Some(if projection.is_inside {
                towards / distance
            } else {
                -towards / distance
            })
        } else {
            None
        };
        Some(ObstacleProjection {
            depth: if projection.is_inside {
                distance
            } else {
                -distance
            },
            normal,
            surface: surface + offset,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::Schedule;

    fn one(shape: ObstacleShape) -> Obstacles {
        Obstacles::new(&[Obstacle {
            name: "o".into(),
            shape,
            travel: Vector3::zeros(),
            schedule: Schedule::Linear,
        }])
        .unwrap()
    }

    #[test]
    fn half_space_depth_and_normal() {
        let o = one(ObstacleShape::HalfSpace {
            point: Vector3::new(0.0, 1.0, 0.0),
            normal: Vector3::new(0.0, 1.0, 0.0),
        });
        let p = o
            .project(0, &Vector3::new(3.0, 0.75, 0.0), &Vector3::zeros())
            .unwrap();
        assert!((p.depth - 0.25).abs() < 1e-15);
        assert!((p.normal.unwrap() - Vector3::y()).norm() < 1e-15);
        let p = o
            .project(
                0,
                &Vector3::new(3.0, 1.5, 0.0),
                &Vector3::new(0.0, 1.0, 0.0),
            )
            .unwrap();
        assert!((p.depth - 0.5).abs() < 1e-15, "moved up by 1: {p:?}");
    }

    #[test]
    fn a_tilted_half_space_gives_its_own_normal_at_any_depth() {
        // Tilted 20°: a node 1e-10 m inside, at coordinates of 0.1 m (round-off 1e-17 m), gets
        // the plane's normal to round-off, not the direction to its nearest point (off by
        // 1e-7 there).
        let (s, c) = 20f64.to_radians().sin_cos();
        let n = Vector3::new(-s, c, 0.0);
        let o = one(ObstacleShape::HalfSpace {
            point: Vector3::zeros(),
            normal: n * 2.0,
        });
        let x = Vector3::new(0.1 * c, 0.1 * s, 0.05) - n * 1e-10;
        let p = o.project(0, &x, &Vector3::zeros()).unwrap();
        assert!((p.normal.unwrap() - n).norm() < 1e-15);
        assert!((p.depth - 1e-10).abs() < 1e-16, "{}", p.depth);
        assert!((p.surface - (x + n * p.depth)).norm() < 1e-16);
    }

    #[test]
    fn ball_normal_is_radial_inside_and_outside() {
        let o = one(ObstacleShape::Ball {
            center: Vector3::new(1.0, 0.0, 0.0),
            radius: 0.5,
        });
        for x in [Vector3::new(1.3, 0.2, 0.0), Vector3::new(2.0, 1.0, 0.0)] {
            let p = o.project(0, &x, &Vector3::zeros()).unwrap();
            let radial = (x - Vector3::new(1.0, 0.0, 0.0)).normalize();
            assert!((p.normal.unwrap() - radial).norm() < 1e-12);
            let expected = 0.5 - (x - Vector3::new(1.0, 0.0, 0.0)).norm();
            assert!((p.depth - expected).abs() < 1e-12);
        }
    }

    #[test]
    fn rotated_cuboid() {
        // A unit cube turned 90° about z: its x half extent now lies along y.
        let o = one(ObstacleShape::Cuboid {
            center: Vector3::zeros(),
            half_extents: Vector3::new(2.0, 0.5, 0.5),
            rotation: Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        });
        let p = o
            .project(0, &Vector3::new(0.0, 1.9, 0.0), &Vector3::zeros())
            .unwrap();
        assert!((p.depth - 0.1).abs() < 1e-12, "{p:?}");
        assert!((p.normal.unwrap() - Vector3::y()).norm() < 1e-12);
    }
}
