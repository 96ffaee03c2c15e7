//! Faces of a triangle mesh that cross each other: a sweep along x over the faces' boxes,
//! then exact-sign segment–triangle tests for pairs that share no vertex.

use super::PrepareError;
use crate::Real;
use nalgebra::Vector3;

/// Six times the signed volume of `(a, b, c, d)`.
fn orient(a: &Vector3<Real>, b: &Vector3<Real>, c: &Vector3<Real>, d: &Vector3<Real>) -> Real {
    (b - a).dot(&(c - a).cross(&(d - a)))
}

/// Whether segment `pq` passes strictly through the inside of triangle `abc` (touching and
/// coplanar contact do not count).
fn segment_crosses(p: &Vector3<Real>, q: &Vector3<Real>, t: [&Vector3<Real>; 3]) -> bool {
    let [a, b, c] = t;
    let (s1, s2) = (orient(a, b, c, p), orient(a, b, c, q));
    if s1 * s2 >= 0.0 {
        return false;
    }
    let (d1, d2, d3) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    (d1 > 0.0 && d2 > 0.0 && d3 > 0.0) || (d1 < 0.0 && d2 < 0.0 && d3 < 0.0)
}

/// The first pair of faces (1-based, in sweep order) that cross each other, if any. Faces that
/// share a vertex are not tested against each other.
pub(crate) fn check_self_intersection(
    vertices: &[Vector3<Real>],
    triangles: &[[usize; 3]],
) -> Result<(), PrepareError> {
    let boxes: Vec<(Vector3<Real>, Vector3<Real>)> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| vertices[v]);
            (a.inf(&b).inf(&c), a.sup(&b).sup(&c))
        })
        .collect();
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0.x.total_cmp(&boxes[j].0.x).then(i.cmp(&j)));
    for (k, &f) in order.iter().enumerate() {
        let (lo, hi) = boxes[f];
        for &g in &order[k + 1..] {
            let (glo, ghi) = boxes[g];
            if glo.x > hi.x {
                break;
            }
            if glo.y > hi.y || ghi.y < lo.y || glo.z > hi.z || ghi.z < lo.z {
                continue;
            }
            let (tf, tg) = (triangles[f], triangles[g]);
            if tf.iter().any(|v| tg.contains(v)) {
                continue;
            }
            let pf = tf.map(|v| &vertices[v]);
            let pg = tg.map(|v| &vertices[v]);
            let edge_through = |s: [&Vector3<Real>; 3], t: [&Vector3<Real>; 3]| {
                (0..3).any(|e| segment_crosses(s[e], s[(e + 1) % 3], t))
            };
            if edge_through(pf, pg) || edge_through(pg, pf) {
                let (a, b) = (f.min(g), f.max(g));
                let at = (vertices[triangles[a][0]]
                    + vertices[triangles[a][1]]
                    + vertices[triangles[a][2]])
                    / 3.0;
                return Err(PrepareError::SelfIntersecting {
                    faces: [a + 1, b + 1],
                    at: [at.x, at.y, at.z],
                });
            }
        }
    }
    Ok(())
}
