//! The contact surface of a 3D body: its patches as an oriented parry `TriMesh`, rebuilt from the
//! deformed nodes at every query.

use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;
use rapier3d_f64::math::Vector;
use rapier3d_f64::parry::query::PointQueryWithLocation;
use rapier3d_f64::parry::shape::{TriMesh, TriMeshFlags};

/// A 3D body's closed surface, every patch facing out.
pub struct PatchSurface {
    /// The patches, as body node indices, counter-clockwise seen from outside.
    pub patches: Vec<[usize; 3]>,
    /// The body nodes the patches use (mesh vertex i is body node `nodes[i]`).
    pub nodes: Vec<usize>,
    /// Whether the patches had to be turned round to face out.
    pub flipped: bool,
}

/// Why a body's patches cannot be a contact surface.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SurfaceProblem {
    /// An edge is not shared by exactly two patches (an open shell or a torn surface): the
    /// 1-based nodes of one such edge.
    NotClosed([usize; 2]),
    /// Two patches sharing an edge face opposite ways and no turning fixes them all.
    Inconsistent([usize; 2]),
}

impl PatchSurface {
    /// The surface of `body`'s patches: `Ok(None)` without patches; the patches turned round
    /// if they all face in (a closed surface of negative volume).
    pub fn of(body: &Body) -> Result<Option<Self>, SurfaceProblem> {
        if body.patches.is_empty() {
            return Ok(None);
        }
        // Every directed edge once, every undirected edge twice: closed and consistent.
        let mut directed: Vec<(usize, usize)> = body
            .patches
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .collect();
        directed.sort_unstable();
        for w in directed.windows(2) {
            if w[0] == w[1] {
                return Err(SurfaceProblem::Inconsistent([w[0].0 + 1, w[0].1 + 1]));
            }
        }
        for &(a, b) in &directed {
            if directed.binary_search(&(b, a)).is_err() {
                return Err(SurfaceProblem::NotClosed([a + 1, b + 1]));
            }
        }
        let volume: Real = body
            .patches
            .iter()
            .map(|&[a, b, c]| body.nodes[a].dot(&body.nodes[b].cross(&body.nodes[c])))
            .sum();
        let flipped = volume < 0.0;
        let patches: Vec<[usize; 3]> = body
            .patches
            .iter()
            .map(|&[a, b, c]| if flipped { [a, c, b] } else { [a, b, c] })
            .collect();
        let mut nodes: Vec<usize> = patches.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        Ok(Some(PatchSurface {
            patches,
            nodes,
            flipped,
        }))
    }

    /// The oriented mesh at the positions `position(node)` (m), and its bounding box.
    pub fn mesh(
        &self,
        position: impl Fn(usize) -> Vector3<Real>,
    ) -> Option<(TriMesh, [Vector3<Real>; 2])> {
        let points: Vec<Vector3<Real>> = self.nodes.iter().map(|&n| position(n)).collect();
        let mut lo = Vector3::repeat(Real::INFINITY);
        let mut hi = Vector3::repeat(-Real::INFINITY);
        for p in &points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        let vertices = points.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let index = |n: usize| self.nodes.binary_search(&n).unwrap_or(0) as u32;
        let indices = self
            .patches
            .iter()
            .map(|&[a, b, c]| [index(a), index(b), index(c)])
            .collect();
        let mesh = TriMesh::with_flags(vertices, indices, TriMeshFlags::ORIENTED).ok()?;
        Some((mesh, [lo, hi]))
    }

    /// Whether `x` (m) is inside `mesh`: the patch nearest to it and its distance, m.
    pub fn inside(mesh: &TriMesh, x: &Vector3<Real>) -> Option<(usize, Real)> {
        let (projection, (patch, _)) =
            mesh.project_local_point_and_get_location(Vector::new(x.x, x.y, x.z), false);
        if !projection.is_inside {
            return None;
        }
        let p = projection.point;
        let distance = (Vector3::new(p.x, p.y, p.z) - x).norm();
        Some((patch as usize, distance))
    }
}

/// A point against a triangle `a b c` (counter-clockwise seen from outside).
pub struct TriangleProjection {
    /// Barycentric weights of the nearest point of the triangle's plane, clamped to the triangle.
    pub weights: [Real; 3],
    /// Depth behind the plane along the outward normal, m (negative in front).
    pub depth: Real,
    /// Outward unit normal.
    pub normal: Option<Vector3<Real>>,
}

/// Project `x` on the plane of the triangle `a b c`.
pub fn triangle_projection(
    x: &Vector3<Real>,
    a: &Vector3<Real>,
    b: &Vector3<Real>,
    c: &Vector3<Real>,
) -> TriangleProjection {
    let cross = (b - a).cross(&(c - a));
    let area2 = cross.norm();
    if area2 == 0.0 || !area2.is_finite() {
        return TriangleProjection {
            weights: [1.0, 0.0, 0.0],
            depth: 0.0,
            normal: None,
        };
    }
    let n = cross / area2;
    let depth = (a - x).dot(&n);
    let p = x + n * depth;
    let wa = (b - p).cross(&(c - p)).dot(&n) / area2;
    let wb = (c - p).cross(&(a - p)).dot(&n) / area2;
    let mut w = [wa, wb, 1.0 - wa - wb];
    for v in &mut w {
        *v = v.max(0.0);
    }
    let sum: Real = w.iter().sum();
    let weights = if sum > 0.0 {
        [w[0] / sum, w[1] / sum, w[2] / sum]
    } else {
        [1.0 / 3.0; 3]
    };
    TriangleProjection {
        weights,
        depth,
        normal: Some(n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators;
    use crate::linkage::Material;

    #[test]
    fn box_surface_is_closed_and_outward_and_finds_inside_points() {
        let g = generators::box_lattice([1.0, 1.0, 1.0], [2, 2, 2]).unwrap();
        let body = Body::from_geometry("b", g, Material::new("m", 1e7, 1e-4));
        let s = PatchSurface::of(&body).unwrap().unwrap();
        assert!(!s.flipped);
        let (mesh, [lo, hi]) = s.mesh(|n| body.nodes[n]).unwrap();
        assert!((hi - lo - Vector3::repeat(1.0)).norm() < 1e-12);
        let (_, d) = PatchSurface::inside(&mesh, &Vector3::new(0.5, 0.9, 0.5)).unwrap();
        assert!((d - 0.1).abs() < 1e-12);
        assert!(PatchSurface::inside(&mesh, &Vector3::new(0.5, 1.1, 0.5)).is_none());
        // Turned inside out, the patches are turned back.
        let mut inverted = body.clone();
        inverted.patches.iter_mut().for_each(|p| p.swap(1, 2));
        assert!(PatchSurface::of(&inverted).unwrap().unwrap().flipped);
    }

    #[test]
    fn triangle_weights_and_depth() {
        let (a, b, c) = (
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
        );
        let t = triangle_projection(&Vector3::new(0.25, 0.25, -0.1), &a, &b, &c);
        assert!((t.depth - 0.1).abs() < 1e-15);
        assert!((t.weights[0] - 0.5).abs() < 1e-15 && (t.weights[1] - 0.25).abs() < 1e-15);
    }
}
