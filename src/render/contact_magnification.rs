//! The automatic magnification of a run whose bodies touch obstacles or each other: the
//! largest round factor at which no drawn node crosses into an obstacle or another body
//! deeper than it is solved to be, never below 1.

use crate::contact::{Obstacle, ObstacleShape, Obstacles};
use crate::render::deformed_body::vec3;
use crate::render::obstacles::{bodies_diagonal, place_obstacle};
use crate::scene::{ModelBody, ModelFile, StepResult};
use crate::Real;
use nalgebra::Vector3;
use std::collections::HashSet;

/// The round factors (1, 2 or 5 times a power of ten) from `start` down to 1, largest first.
pub fn round_factors_down(start: Real) -> Vec<Real> {
    let mut out = Vec::new();
    if !(start.is_finite() && start > 1.0) {
        return vec![1.0];
    }
    let mut decade = 10f64.powf(start.log10().floor());
    while decade >= 1.0 {
        for k in [5.0, 2.0, 1.0] {
            let m = k * decade;
            if m <= start * (1.0 + 1e-12) && m >= 1.0 {
                out.push(m);
            }
        }
        decade /= 10.0;
    }
    if out.last() != Some(&1.0) {
        out.push(1.0);
    }
    out
}

/// The largest of [`round_factors_down`]`(start)` at which no node of `steps`, drawn at
/// undeformed + factor × displacement, lies deeper inside an obstacle (at its place at that
/// step) or another body's drawn region than at factor 1 (the penetration the penalty solved
/// for). A 2D body's region is its member triangles; a 3D body's, its closed patch surface (3D
/// bodies without patches are not looked into).
pub fn contact_magnification(model: &ModelFile, steps: &[StepResult], start: Real) -> Real {
    let candidates = round_factors_down(start);
    if candidates == [1.0] {
        return 1.0;
    }
    let obstacles = model_obstacles(model);
    let regions: Vec<Vec<[usize; 3]>> = model.bodies.iter().map(region_triangles).collect();
    for &m in &candidates {
        if m == 1.0 || !crosses(model, steps, obstacles.as_ref(), &regions, m) {
            return m;
        }
    }
    1.0
}

/// The obstacles of `model.json` as colliders at step 0 (a half-space's square as the
/// half-space), `None` when there are none or they cannot be made.
fn model_obstacles(model: &ModelFile) -> Option<Obstacles> {
    if model.obstacles.is_empty() {
        return None;
    }
    let diagonal = bodies_diagonal(model);
    let list: Vec<Obstacle> = model
        .obstacles
        .iter()
        .map(|o| {
            let mut at0 = o.clone();
            at0.offsets = vec![[0.0; 3]];
            let placed = place_obstacle(&at0, 0, diagonal);
            let shape = match placed.half_space {
                Some(normal) => ObstacleShape::HalfSpace {
                    point: placed.vertices.iter().sum::<Vector3<Real>>()
                        / placed.vertices.len().max(1) as Real,
                    normal,
                },
                None => ObstacleShape::Mesh {
                    vertices: placed.vertices,
                    triangles: placed.triangles,
                },
            };
            Obstacle {
                name: o.name.clone(),
                shape,
                travel: Vector3::zeros(),
                schedule: Default::default(),
            }
        })
        .collect();
    Obstacles::new(&list).ok()
}

/// The triangles (0-based) that make a body's region: a 3D body's patches; a 2D body's
/// triples of nodes joined pairwise by members.
fn region_triangles(body: &ModelBody) -> Vec<[usize; 3]> {
    if body.dimension == 3 {
        return body.patches.iter().map(|p| p.map(|k| k - 1)).collect();
    }
    let n = body.nodes.len();
    let mut adjacent: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut edges = HashSet::new();
    for m in &body.members {
        let (a, b) = (m[0] - 1, m[1] - 1);
        if a < n && b < n && a != b {
            adjacent[a].push(b);
            adjacent[b].push(a);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let mut out = Vec::new();
    for (a, list) in adjacent.iter().enumerate() {
        for &b in list.iter().filter(|&&b| b > a) {
            for &c in adjacent[b].iter().filter(|&&c| c > b) {
                if edges.contains(&(a, c)) {
                    out.push([a, b, c]);
                }
            }
        }
    }
    out
}

/// Drawn positions of every body's nodes at factor `m`.
fn drawn(model: &ModelFile, step: &StepResult, m: Real) -> Vec<Vec<Vector3<Real>>> {
    model
        .bodies
        .iter()
        .zip(&step.bodies)
        .map(|(b, r)| {
            b.nodes
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    vec3(p) + r.displacements.get(k).map_or(Vector3::zeros(), |u| vec3(u)) * m
                })
                .collect()
        })
        .collect()
}

/// Whether some node at factor `m` is deeper in an obstacle, or inside another body, than at
/// factor 1.
fn crosses(
    model: &ModelFile,
    steps: &[StepResult],
    obstacles: Option<&Obstacles>,
    regions: &[Vec<[usize; 3]>],
    m: Real,
) -> bool {
    let size = bodies_diagonal(model).max(1e-12);
    for step in steps {
        let (at1, atm) = (drawn(model, step, 1.0), drawn(model, step, m));
        if let Some(obstacles) = obstacles {
            for (k, o) in model.obstacles.iter().enumerate() {
                let offset = o
                    .offsets
                    .get(step.step)
                    .or(o.offsets.last())
                    .map(|d| Vector3::from(*d))
                    .unwrap_or_default();
                let depth = |p: &Vector3<Real>| {
                    obstacles
                        .project(k, p, &offset)
                        .map_or(Real::NEG_INFINITY, |q| q.depth)
                };
                for (b1, bm) in at1.iter().zip(&atm) {
                    for (p1, pm) in b1.iter().zip(bm) {
                        if depth(pm) > depth(p1).max(0.0) + 1e-9 * size {
                            return true;
                        }
                    }
                }
            }
        }
        for (i, region) in regions.iter().enumerate() {
            if region.is_empty() {
                continue;
            }
            let dim3 = model.bodies[i].dimension == 3;
            for (j, (b1, bm)) in at1.iter().zip(&atm).enumerate() {
                if j == i {
                    continue;
                }
                for (p1, pm) in b1.iter().zip(bm) {
                    if inside(pm, &atm[i], region, dim3) && !inside(p1, &at1[i], region, dim3) {
                        return true;
                    }
                }
            }
        }
    }
    false
}

/// Whether `p` lies inside the region of `triangles` over `points`: in 2D (x, y) inside one
/// of the triangles; in 3D inside the closed surface (a ray's crossings are odd).
fn inside(
    p: &Vector3<Real>,
    points: &[Vector3<Real>],
    triangles: &[[usize; 3]],
    dim3: bool,
) -> bool {
    let ok = |t: &[usize; 3]| t.iter().all(|&k| k < points.len());
    if !dim3 {
        return triangles.iter().filter(|t| ok(t)).any(|t| {
            let [a, b, c] = t.map(|k| points[k]);
            let side = |u: &Vector3<Real>, v: &Vector3<Real>| {
                (v.x - u.x) * (p.y - u.y) - (v.y - u.y) * (p.x - u.x)
            };
            let (s1, s2, s3) = (side(&a, &b), side(&b, &c), side(&c, &a));
            // Strictly inside: a node on a shared edge (bodies in contact) does not count.
            (s1 > 0.0 && s2 > 0.0 && s3 > 0.0) || (s1 < 0.0 && s2 < 0.0 && s3 < 0.0)
        });
    }
    // A ray in a direction no lattice is aligned with.
    let d = Vector3::new(0.5773, 0.6123, 0.5401).normalize();
    let mut hits = 0usize;
    for t in triangles.iter().filter(|t| ok(t)) {
        let [a, b, c] = t.map(|k| points[k]);
        let (e1, e2) = (b - a, c - a);
        let h = d.cross(&e2);
        let det = e1.dot(&h);
        if det.abs() < 1e-300 {
            continue;
        }
        let s = p - a;
        let u = s.dot(&h) / det;
        let q = s.cross(&e1);
        let v = d.dot(&q) / det;
        let t = e2.dot(&q) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 {
            hits += 1;
        }
    }
    hits % 2 == 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_factors_go_down_to_one() {
        assert_eq!(
            round_factors_down(50.0),
            vec![50.0, 20.0, 10.0, 5.0, 2.0, 1.0]
        );
        assert_eq!(round_factors_down(1.0), vec![1.0]);
        assert_eq!(round_factors_down(200.0)[..3], [200.0, 100.0, 50.0]);
    }

    #[test]
    fn a_point_in_a_2d_triangle_and_in_a_closed_tetrahedron() {
        let pts = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 1.0, 0.0),
            Vector3::new(0.0, 0.0, 1.0),
        ];
        let tri = [[0, 1, 2]];
        assert!(inside(&Vector3::new(0.2, 0.2, 0.0), &pts, &tri, false));
        assert!(!inside(&Vector3::new(0.6, 0.6, 0.0), &pts, &tri, false));
        let tet = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        assert!(inside(&Vector3::new(0.1, 0.1, 0.1), &pts, &tet, true));
        assert!(!inside(&Vector3::new(0.5, 0.5, 0.5), &pts, &tet, true));
        assert!(!inside(&Vector3::new(-0.1, 0.1, 0.1), &pts, &tet, true));
    }
}
