//! The contact surface of a 3D body: its patches as a parry `TriMesh` (oriented for a closed
//! surface, two-sided for an open shell), rebuilt from the deformed nodes at every query.

use crate::contact::ties::{self, Pressed};
use crate::contact::Target;
use crate::linkage::Body;
use crate::Real;
use nalgebra::Vector3;
use rapier3d_f64::math::Vector;
use rapier3d_f64::parry::query::PointQueryWithLocation;
use rapier3d_f64::parry::shape::{TriMesh, TriMeshFlags};

/// A 3D body's contact surface: a closed surface, every patch facing out, or an open shell
/// (two-sided: a node is pushed back to the side it came from).
pub struct PatchSurface {
    /// The patches, as body node indices, counter-clockwise seen from outside (an open
    /// shell: as given, all turning the same way).
    pub patches: Vec<[usize; 3]>,
    /// The body nodes the patches use (mesh vertex i is body node `nodes[i]`).
    pub nodes: Vec<usize>,
    /// Whether the patches had to be turned round to face out.
    pub flipped: bool,
    /// Open shell only: per patch, whether its edges a→b, b→c, c→a are on the shell's rim
    /// (edges of one patch only). Empty for a closed surface.
    pub rim_edges: Vec<[bool; 3]>,
    /// Open shell only: per patch, whether its corners a, b, c are on the rim.
    pub rim_corners: Vec<[bool; 3]>,
    /// Per surface node (by position in `nodes`), the patches around it, ascending.
    pub fans: Vec<Vec<usize>>,
}

/// Where a point lies against an open shell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShellSide {
    /// The patch of the nearest point.
    pub patch: usize,
    /// Distance to the shell, m.
    pub distance: Real,
    /// +1 in front of that patch (along its normal, `a b c` counter-clockwise seen from there),
    /// −1 behind it, 0 on it.
    pub side: Real,
    /// Whether the nearest point is on the shell's rim (the point is beside the shell, not
    /// in front of or behind it).
    pub on_rim: bool,
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
        let fans = fans(&patches, &nodes);
        Ok(Some(PatchSurface {
            patches,
            nodes,
            flipped,
            rim_edges: Vec::new(),
            rim_corners: Vec::new(),
            fans,
        }))
    }

    /// The patches of `body` as an open shell (two-sided), `None` without patches. Call it when
    /// [`PatchSurface::of`] finds the surface not closed: the patches must still turn the same
    /// way across every shared edge (so that "in front" means one side of the whole shell).
    pub fn open_shell(body: &Body) -> Option<Self> {
        if body.patches.is_empty() {
            return None;
        }
        let mut undirected: Vec<(usize, usize)> = body
            .patches
            .iter()
            .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
            .map(|(a, b)| (a.min(b), a.max(b)))
            .collect();
        undirected.sort_unstable();
        let once = |a: usize, b: usize| {
            let e = (a.min(b), a.max(b));
            let first = undirected.partition_point(|x| *x < e);
            undirected.get(first + 1) != Some(&e)
        };
        let rim_edges: Vec<[bool; 3]> = body
            .patches
            .iter()
            .map(|&[a, b, c]| [once(a, b), once(b, c), once(c, a)])
            .collect();
        let mut rim_node = vec![false; body.nodes.len()];
        for (patch, edges) in body.patches.iter().zip(&rim_edges) {
            for i in (0..3).filter(|&i| edges[i]) {
                rim_node[patch[i]] = true;
                rim_node[patch[(i + 1) % 3]] = true;
            }
        }
        let rim_corners = body
            .patches
            .iter()
            .map(|p| p.map(|n| rim_node[n]))
            .collect();
        let mut nodes: Vec<usize> = body.patches.iter().flatten().copied().collect();
        nodes.sort_unstable();
        nodes.dedup();
        let fans = fans(&body.patches, &nodes);
        Some(PatchSurface {
            patches: body.patches.clone(),
            nodes,
            flipped: false,
            rim_edges,
            rim_corners,
            fans,
        })
    }

    /// The patches around body node `node`, ascending (empty off the surface).
    pub fn fan(&self, node: usize) -> &[usize] {
        self.nodes
            .binary_search(&node)
            .map_or(&[], |i| self.fans[i].as_slice())
    }

    /// The patches having both `a` and `b` as corners (two on a closed surface), ascending.
    pub fn edge_patches(&self, [a, b]: [usize; 2]) -> Vec<usize> {
        let around_b = self.fan(b);
        self.fan(a)
            .iter()
            .filter(|p| around_b.contains(p))
            .copied()
            .collect()
    }

    /// The area-weighted mean of the outward normals of `patches` at the positions
    /// `position(node)`, as a unit vector (`None` when they cancel or are degenerate): the sum
    /// of their corners' cross products, each twice its patch's area times its normal.
    pub fn mean_normal(
        &self,
        patches: &[usize],
        position: impl Fn(usize) -> Vector3<Real>,
    ) -> Option<Vector3<Real>> {
        let sum: Vector3<Real> = patches
            .iter()
            .map(|&p| {
                let [a, b, c] = self.patches[p].map(&position);
                (b - a).cross(&(c - a))
            })
            .sum();
        let length = sum.norm();
        (length > 0.0 && length.is_finite()).then(|| sum / length)
    }

    /// The contact target of body `body` (whose surface this is) for a node at `x` (m) that
    /// the tie rule sent to `pressed` (positions `position(node)`, m), by `contact::ties`: a
    /// single patch whose foot lies within [`ties::BAND`] of an edge or corner of it presses
    /// that edge or corner; an edge or corner presses with the patches around it that turn less
    /// than 45° from the mean of those that tied (not the side faces beyond a box's edge). A
    /// corner's patches are a mask over [`PatchSurface::fan`] (more than 64: the patch).
    pub(crate) fn target(
        &self,
        body: usize,
        pressed: Pressed,
        x: &Vector3<Real>,
        position: impl Fn(usize) -> Vector3<Real>,
    ) -> Target {
        let normal = |p: usize| {
            let [a, b, c] = self.patches[p].map(&position);
            (b - a).cross(&(c - a)).try_normalize(0.0)
        };
        let (feature, tied) = match pressed {
            Pressed::Patch(patch) => match ties::near_feature(x, &self.patches[patch], &position) {
                Some(feature) => (feature, vec![patch]),
                None => return Target::Patch { body, patch },
            },
            Pressed::Edge(nodes) => (Pressed::Edge(nodes), self.edge_patches(nodes)),
            Pressed::Corner(node, tied) => (Pressed::Corner(node, Vec::new()), tied),
        };
        let lowest = tied.iter().copied().min().unwrap_or(0);
        let Some(reference) = self.mean_normal(&tied, &position) else {
            return Target::Patch {
                body,
                patch: lowest,
            };
        };
        let smooth = |p: &usize| normal(*p).is_some_and(|n| n.dot(&reference) >= ties::SMOOTH_COS);
        match feature {
            Pressed::Edge(nodes) => {
                if self.edge_patches(nodes).iter().all(smooth) {
                    Target::Edge { body, nodes }
                } else {
                    Target::Patch {
                        body,
                        patch: lowest,
                    }
                }
            }
            Pressed::Corner(node, _) => {
                let mut mask = 0u64;
                for (i, p) in self.fan(node).iter().enumerate() {
                    if smooth(p) {
                        if i >= 64 {
                            return Target::Patch {
                                body,
                                patch: lowest,
                            };
                        }
                        mask |= 1 << i;
                    }
                }
                Target::Corner {
                    body,
                    node,
                    tied: mask,
                }
            }
            Pressed::Patch(patch) => Target::Patch { body, patch },
        }
    }

    /// The patches around corner `node` selected by `mask` (bit i: the i-th of
    /// [`PatchSurface::fan`]).
    pub fn fan_tied(&self, node: usize, mask: u64) -> Vec<usize> {
        self.fan(node)
            .iter()
            .enumerate()
            .filter(|&(i, _)| i < 64 && mask >> i & 1 == 1)
            .map(|(_, &p)| p)
            .collect()
    }

    /// Whether this is an open shell (a two-sided target).
    pub fn is_open(&self) -> bool {
        !self.rim_edges.is_empty()
    }

    /// Where `x` (m) lies against the open shell `mesh` (made by [`PatchSurface::mesh`] at the
    /// positions `position(node)`): the nearest patch, the distance and the side.
    pub fn shell_side(
        &self,
        mesh: &TriMesh,
        x: &Vector3<Real>,
        position: impl Fn(usize) -> Vector3<Real>,
    ) -> ShellSide {
        let (projection, (patch, _)) =
            mesh.project_local_point_and_get_location(Vector::new(x.x, x.y, x.z), false);
        let patch = patch as usize;
        let p = Vector3::new(projection.point.x, projection.point.y, projection.point.z);
        let distance = (x - p).norm();
        let [a, b, c] = self.patches[patch].map(&position);
        let normal = (b - a).cross(&(c - a));
        let along = (x - p).dot(&normal);
        let side = if distance == 0.0 || along == 0.0 {
            0.0
        } else {
            along.signum()
        };
        // The nearest point on a rim corner or a rim edge of the patch, and the point not
        // straight in front of or behind it: beside the shell.
        let corners = [a, b, c];
        let edges = self.rim_edges.get(patch).copied().unwrap_or([false; 3]);
        let rim_corners = self.rim_corners.get(patch).copied().unwrap_or([false; 3]);
        let near = 1e-9 * (b - a).norm().max((c - a).norm());
        let on_rim_point = (0..3).any(|i| {
            (rim_corners[i] && (p - corners[i]).norm() <= near)
                || (edges[i] && segment_distance(&p, &corners[i], &corners[(i + 1) % 3]) <= near)
        });
        let normal_length = normal.norm();
        let sideways = if normal_length > 0.0 {
            let n = normal / normal_length;
            let d = x - p;
            (d - n * d.dot(&n)).norm()
        } else {
            0.0
        };
        let on_rim = on_rim_point && sideways > 1e-6 * distance;
        ShellSide {
            patch,
            distance,
            side,
            on_rim,
        }
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
        let flags = if self.is_open() {
            TriMeshFlags::empty()
        } else {
            TriMeshFlags::ORIENTED
        };
        let mesh = TriMesh::with_flags(vertices, indices, flags).ok()?;
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

/// Per node of `nodes` (sorted body nodes), the patches around it, ascending.
fn fans(patches: &[[usize; 3]], nodes: &[usize]) -> Vec<Vec<usize>> {
    let mut fans = vec![Vec::new(); nodes.len()];
    for (p, corners) in patches.iter().enumerate() {
        for n in corners {
            if let Ok(i) = nodes.binary_search(n) {
                fans[i].push(p);
            }
        }
    }
    fans
}

/// Distance from `p` to the segment `a b`, m.
fn segment_distance(p: &Vector3<Real>, a: &Vector3<Real>, b: &Vector3<Real>) -> Real {
    let ab = b - a;
    let length2 = ab.norm_squared();
    let t = if length2 > 0.0 {
        ((p - a).dot(&ab) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
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

    /// A unit square in z = 0 of two patches facing +z, as an open shell: its four outer edges
    /// are the rim, the diagonal is not; points above and below are on opposite sides, points
    /// beside the rim are beside it, and points straight above the rim or the diagonal are not.
    #[test]
    fn open_square_has_two_sides_and_a_rim() {
        let geometry = crate::linkage::Geometry {
            dimension: crate::linkage::Dimension::Three,
            nodes: vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.0, 0.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(0.0, 1.0, 0.0),
            ],
            members: vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]],
            patches: vec![[0, 1, 2], [0, 2, 3]],
        };
        let body = Body::from_geometry("square", geometry, Material::new("m", 1e7, 1e-4));
        assert_eq!(
            PatchSurface::of(&body).err(),
            Some(SurfaceProblem::NotClosed([1, 2]))
        );
        let s = PatchSurface::open_shell(&body).unwrap();
        assert!(s.is_open());
        assert_eq!(s.rim_edges, vec![[true, true, false], [false, true, true]]);
        let (mesh, _) = s.mesh(|n| body.nodes[n]).unwrap();
        let at = |x: Real, y: Real, z: Real| {
            s.shell_side(&mesh, &Vector3::new(x, y, z), |n| body.nodes[n])
        };
        let above = at(0.7, 0.2, 0.3);
        assert_eq!((above.patch, above.side, above.on_rim), (0, 1.0, false));
        assert!((above.distance - 0.3).abs() < 1e-15);
        let below = at(0.2, 0.7, -0.1);
        assert_eq!((below.patch, below.side, below.on_rim), (1, -1.0, false));
        assert!(
            at(0.5, 0.5, 0.2).side == 1.0 && !at(0.5, 0.5, 0.2).on_rim,
            "over the diagonal"
        );
        assert!(!at(1.0, 0.5, -0.2).on_rim, "straight below a rim edge");
        assert!(
            at(1.2, 0.5, 0.0).on_rim && at(1.2, 0.5, -0.1).on_rim,
            "beside the rim"
        );
        assert!(at(-0.1, -0.1, 0.1).on_rim, "beside a corner");
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
