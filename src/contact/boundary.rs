//! The contact surface of a 2D body: its outer boundary, found from the members, and points
//! against its segments.

use crate::linkage::{Body, Dimension};
use crate::Real;
use nalgebra::Vector3;
use std::f64::consts::TAU;

/// The outer boundary of a planar linkage as a closed loop of nodes, counter-clockwise (the body
/// on the left of each segment, its outward normal on the right).
///
/// Walks the outer face of the member graph: start at the lowest node (then leftmost), and at
/// every node take the member that turns most to the right, that is the first one
/// counter-clockwise from the member just arrived by. Members that cross inside the body (the
/// two diagonals of a cell) do not disturb it. `None` when the walk does not close (a body whose
/// outer members cross each other, or a single member).
pub fn boundary_loop(body: &Body) -> Option<Vec<usize>> {
    let n = body.nodes.len();
    if n < 3 {
        return None;
    }
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    for m in &body.members {
        let [a, b] = m.nodes;
        neighbours[a].push(b);
        neighbours[b].push(a);
    }
    let start = (0..n)
        .filter(|&i| !neighbours[i].is_empty())
        .min_by(|&i, &j| {
            let (p, q) = (body.nodes[i], body.nodes[j]);
            p.y.total_cmp(&q.y).then(p.x.total_cmp(&q.x))
        })?;
    let angle = |from: usize, to: usize| -> Real {
        let d = body.nodes[to] - body.nodes[from];
        d.y.atan2(d.x).rem_euclid(TAU)
    };
    // Arrived at the lowest node "from the left": the back direction points along −x.
    let mut back = std::f64::consts::PI;
    let mut current = start;
    let mut previous = usize::MAX;
    let mut loop_nodes = vec![start];
    for _ in 0..=2 * body.members.len() {
        let next = neighbours[current]
            .iter()
            .copied()
            .filter(|&w| w != previous || neighbours[current].len() == 1)
            .min_by(|&w1, &w2| {
                let t1 = (angle(current, w1) - back).rem_euclid(TAU);
                let t2 = (angle(current, w2) - back).rem_euclid(TAU);
                let t1 = if t1 == 0.0 { TAU } else { t1 };
                let t2 = if t2 == 0.0 { TAU } else { t2 };
                t1.total_cmp(&t2)
            })?;
        if next == start {
            return (loop_nodes.len() >= 3).then_some(loop_nodes);
        }
        if loop_nodes.contains(&next) {
            return None;
        }
        back = angle(next, current);
        previous = current;
        current = next;
        loop_nodes.push(next);
    }
    None
}

/// A contact surface: the closed loop of boundary nodes of a 2D body, counter-clockwise.
pub(crate) struct Surface {
    /// Body nodes of the loop, in order.
    pub(crate) nodes: Vec<usize>,
}

impl Surface {
    /// The boundary of a 2D body; `None` for a 3D body or a boundary that cannot be traced.
    pub(crate) fn of(body: &Body) -> Option<Surface> {
        if body.dimension != Dimension::Two {
            return None;
        }
        boundary_loop(body).map(|nodes| Surface { nodes })
    }

    /// The segment before segment `i` in the loop.
    pub(crate) fn previous(&self, i: usize) -> usize {
        (i + self.nodes.len() - 1) % self.nodes.len()
    }

    /// The segment after segment `i` in the loop.
    pub(crate) fn next(&self, i: usize) -> usize {
        (i + 1) % self.nodes.len()
    }

    /// The end nodes of segment `i`.
    pub(crate) fn segment(&self, i: usize) -> (usize, usize) {
        (self.nodes[i], self.nodes[(i + 1) % self.nodes.len()])
    }
}

/// A point against a boundary segment from `a` to `b` of a counter-clockwise loop.
pub(crate) struct SegmentProjection {
    /// Barycentric weight of `b` of the nearest point (0 at a, 1 at b).
    pub(crate) t: Real,
    /// Distance to the nearest point, m.
    pub(crate) distance: Real,
    /// Depth behind the segment's line along its outward normal, m (negative in front).
    pub(crate) depth: Real,
    /// Outward unit normal (to the right of a → b).
    pub(crate) normal: Option<Vector3<Real>>,
}

/// Project `x` on the segment `a`–`b` (z = 0).
pub(crate) fn segment_projection(
    x: &Vector3<Real>,
    a: &Vector3<Real>,
    b: &Vector3<Real>,
) -> SegmentProjection {
    let e = b - a;
    let length2 = e.norm_squared();
    let t = if length2 > 0.0 {
        ((x - a).dot(&e) / length2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let nearest = a + e * t;
    let normal = if length2 > 0.0 {
        Some(Vector3::new(e.y, -e.x, 0.0) / length2.sqrt())
    } else {
        None
    };
    SegmentProjection {
        t,
        distance: (x - nearest).norm(),
        depth: normal.map_or(0.0, |n| (nearest - x).dot(&n)),
        normal,
    }
}

/// Whether `x` lies inside the closed polygon `points` (even–odd rule, z ignored).
pub(crate) fn inside_polygon(x: &Vector3<Real>, points: &[Vector3<Real>]) -> bool {
    let mut inside = false;
    let n = points.len();
    for i in 0..n {
        let (p, q) = (points[i], points[(i + n - 1) % n]);
        if (p.y > x.y) != (q.y > x.y) && x.x < (q.x - p.x) * (x.y - p.y) / (q.y - p.y) + p.x {
            inside = !inside;
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators;
    use crate::linkage::{Dimension, Material};

    #[test]
    fn disk_boundary_is_its_outer_ring_counter_clockwise() {
        let geometry = generators::disk(1.0, 3, 12).unwrap();
        let body = Body::from_geometry("d", geometry, Material::new("m", 1e7, 1e-4));
        let l = boundary_loop(&body).unwrap();
        assert_eq!(l.len(), 12);
        // Every loop node is on the rim, and the loop turns counter-clockwise (positive area).
        let mut area = 0.0;
        for (i, &a) in l.iter().enumerate() {
            let b = l[(i + 1) % l.len()];
            assert!((body.nodes[a].norm() - 1.0).abs() < 1e-12);
            area += body.nodes[a].x * body.nodes[b].y - body.nodes[b].x * body.nodes[a].y;
        }
        assert!(area > 0.0);
        assert_eq!(body.dimension, Dimension::Two);
    }

    #[test]
    fn rectangle_with_crossing_diagonals() {
        let geometry = generators::rectangle(2.0, 1.0, 4, 2).unwrap();
        let body = Body::from_geometry("r", geometry, Material::new("m", 1e7, 1e-4));
        let l = boundary_loop(&body).unwrap();
        // (4 + 2) · 2 boundary nodes.
        assert_eq!(l.len(), 12);
        assert_eq!(l[0], 0);
        assert_eq!(l[1], 1, "starts along the bottom edge");
    }
}
