//! A closed, outward-facing triangle mesh as parry's oriented `TriMesh`: which side of it a
//! point is on (angle-weighted pseudo-normals), and where a segment leaves it.
//!
//! parry is the contact layer's geometry crate; preparation uses it here, behind this small
//! type, because its BVH and pseudo-normal inside test are what isosurface stuffing needs.

use super::PrepareError;
use crate::Real;
use nalgebra::Vector3;
use parry3d_f64::math::Vector;
use parry3d_f64::query::{PointQuery, Ray, RayCast};
use parry3d_f64::shape::{TriMesh, TriMeshFlags};

/// Which side of the surface a point is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Side {
    /// Strictly inside.
    Inside,
    /// On the surface (within the snapping distance).
    On,
    /// Strictly outside.
    Outside,
}

/// A closed oriented surface to fill.
pub(crate) struct ClosedSurface {
    mesh: TriMesh,
    /// Distance below which a point counts as on the surface, m.
    snap: Real,
}

fn to_parry(p: &Vector3<Real>) -> Vector {
    Vector::new(p.x, p.y, p.z)
}

fn from_parry(p: Vector) -> Vector3<Real> {
    Vector3::new(p.x, p.y, p.z)
}

impl ClosedSurface {
    /// The surface of `triangles` over `vertices` (m), which must face outward and be closed;
    /// points closer than `snap` (m) count as on it.
    pub(crate) fn new(
        vertices: &[Vector3<Real>],
        triangles: &[[usize; 3]],
        snap: Real,
    ) -> Result<Self, PrepareError> {
        let points = vertices.iter().map(to_parry).collect();
        let indices = triangles
            .iter()
            .map(|t| t.map(|v| v as u32))
            .collect::<Vec<_>>();
        let mesh = TriMesh::with_flags(points, indices, TriMeshFlags::ORIENTED)
            .map_err(|e| PrepareError::Mesh(format!("{e:?}")))?;
        Ok(ClosedSurface { mesh, snap })
    }

    /// The side of the surface `p` (m) is on, and the nearest surface point (m).
    pub(crate) fn side(&self, p: &Vector3<Real>) -> (Side, Vector3<Real>) {
        let projection = self.mesh.project_local_point(to_parry(p), false);
        let nearest = from_parry(projection.point);
        let side = if (nearest - p).norm() <= self.snap {
            Side::On
        } else if projection.is_inside {
            Side::Inside
        } else {
            Side::Outside
        };
        (side, nearest)
    }

    /// Where the segment from `inside` to `outside` (m) first crosses the surface: its
    /// parameter in (0, 1) from `inside`, and the point (m), on the mesh.
    pub(crate) fn crossing(
        &self,
        inside: &Vector3<Real>,
        outside: &Vector3<Real>,
    ) -> (Real, Vector3<Real>) {
        let ray = Ray::new(to_parry(inside), to_parry(&(outside - inside)));
        if let Some(t) = self.mesh.cast_local_ray(&ray, 1.0, false) {
            if t > 0.0 && t < 1.0 {
                return (t, from_parry(ray.point_at(t)));
            }
        }
        // Grazing rays can miss by round-off: bisect the inside test, then land on the mesh.
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            let p = inside + (outside - inside) * mid;
            if self.mesh.project_local_point(to_parry(&p), false).is_inside {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t: Real = 0.5 * (lo + hi);
        let p = inside + (outside - inside) * t;
        let on = from_parry(self.mesh.project_local_point(to_parry(&p), false).point);
        (t.clamp(1e-6, 1.0 - 1e-6), on)
    }
}
