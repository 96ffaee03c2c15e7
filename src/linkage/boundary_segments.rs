//! The boundary segments of a 2D linkage: members with the body on one side only, outer
//! boundary and holes alike.

use crate::linkage::Body;

/// The members of the 2D `body` whose two nodes are both `chosen` and that lie on its
/// boundary, each as `[a, b]` with the body on the left of `a → b` (its outward normal on the
/// right). A member is on the boundary when it closes at least one triangle of members and
/// the third nodes of all such triangles lie on the same side of it (a cell with both
/// diagonals puts two triangles on the inner side of its sides, none outside); members that
/// close no triangle (a bare bar or chain) have no side and are left out. In member order.
pub fn boundary_segments(body: &Body, chosen: &[bool]) -> Vec<[usize; 2]> {
    let n = body.nodes.len();
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    for m in &body.members {
        let [a, b] = m.nodes;
        if chosen[a] || chosen[b] {
            neighbours[a].push(b);
            neighbours[b].push(a);
        }
    }
    // Neighbours of every node are needed for the third node of a triangle: fill the rest.
    for m in &body.members {
        let [a, b] = m.nodes;
        if !(chosen[a] || chosen[b]) {
            neighbours[a].push(b);
            neighbours[b].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    let mut out = Vec::new();
    let mut seen: Vec<(usize, usize)> = Vec::new();
    for m in &body.members {
        let [a, b] = m.nodes;
        if !(chosen[a] && chosen[b]) {
            continue;
        }
        let key = (a.min(b), a.max(b));
        if seen.binary_search(&key).is_ok() {
            continue;
        }
        let (pa, pb) = (body.nodes[a], body.nodes[b]);
        let (mut left, mut right) = (false, false);
        let (na, nb) = (&neighbours[a], &neighbours[b]);
        let (mut i, mut j) = (0, 0);
        while i < na.len() && j < nb.len() {
            match na[i].cmp(&nb[j]) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    let c = body.nodes[na[i]];
                    let side = (pb - pa).cross(&(c - pa)).z;
                    if side > 0.0 {
                        left = true;
                    } else if side < 0.0 {
                        right = true;
                    }
                    i += 1;
                    j += 1;
                }
            }
        }
        if left != right {
            let pos = seen.partition_point(|&k| k < key);
            seen.insert(pos, key);
            out.push(if left { [a, b] } else { [b, a] });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators::rectangle;
    use crate::linkage::{Dimension, Member};

    #[test]
    fn a_lattice_with_crossed_cells_has_its_outline_as_boundary_counter_clockwise() {
        // A 2 × 1 lattice of cells with both diagonals: 6 nodes, the outline has 6 sides.
        let g = rectangle(2.0, 1.0, 2, 1).unwrap();
        let mut body = Body::new("plate", Dimension::Two);
        body.nodes = g.nodes;
        body.members = g
            .members
            .iter()
            .map(|&nodes| Member { nodes, material: 0 })
            .collect();
        let all = vec![true; body.nodes.len()];
        let segments = boundary_segments(&body, &all);
        assert_eq!(segments.len(), 6, "{segments:?}");
        // Counter-clockwise: the signed area of the outline from its segments is +2 m².
        let area: f64 = segments
            .iter()
            .map(|&[a, b]| {
                let (p, q) = (body.nodes[a], body.nodes[b]);
                0.5 * (p.x * q.y - q.x * p.y)
            })
            .sum();
        assert!((area - 2.0).abs() < 1e-12, "{area}");
        // Only the bottom row chosen: its two sides.
        let bottom: Vec<bool> = body.nodes.iter().map(|p| p.y < 1e-12).collect();
        assert_eq!(boundary_segments(&body, &bottom).len(), 2);
    }
}
