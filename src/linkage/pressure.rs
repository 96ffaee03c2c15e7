//! Pressure on a body's surface patches as nodal loads: each chosen patch's force −p · (area
//! vector) shared equally by its three nodes, on the undeformed patches.

use crate::linkage::{Body, NodalLoad, Schedule};
use crate::Real;
use nalgebra::Vector3;

/// The nodal loads of `pressure` (Pa, positive pushing into the body) on every patch of `body`
/// whose three nodes are all `chosen`: per patch the force −p · n A, n A the outward area
/// vector ((b − a) × (c − a) / 2, m²), one third to each node; per node in node order, growing
/// by `schedule`. On a closed surface the forces sum to zero; on a flat face to p times its
/// area. The patches are the undeformed ones (the load does not follow the deformation).
pub fn pressure_loads(
    body: &Body,
    chosen: &[bool],
    pressure: Real,
    schedule: &Schedule,
) -> Vec<NodalLoad> {
    let mut force = vec![Vector3::zeros(); body.nodes.len()];
    let mut loaded = vec![false; body.nodes.len()];
    for &[a, b, c] in &body.patches {
        if !(chosen[a] && chosen[b] && chosen[c]) {
            continue;
        }
        let (pa, pb, pc) = (body.nodes[a], body.nodes[b], body.nodes[c]);
        let share = -(pb - pa).cross(&(pc - pa)) * (pressure / 6.0);
        for n in [a, b, c] {
            force[n] += share;
            loaded[n] = true;
        }
    }
    (0..body.nodes.len())
        .filter(|&n| loaded[n])
        .map(|node| NodalLoad {
            node,
            force: force[node],
            schedule: schedule.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators::box_lattice;
    use crate::linkage::Dimension;

    fn lattice_body() -> Body {
        let g = box_lattice([0.3, 0.2, 0.1], [3, 2, 2]).unwrap();
        let mut body = Body::new("box", Dimension::Three);
        body.nodes = g.nodes;
        body.patches = g.patches;
        body
    }

    #[test]
    fn on_a_closed_surface_it_sums_to_zero_and_on_a_face_to_p_times_its_area() {
        let body = lattice_body();
        let all = vec![true; body.nodes.len()];
        let total: Vector3<Real> = pressure_loads(&body, &all, 1e5, &Schedule::Linear)
            .iter()
            .map(|l| l.force)
            .sum();
        assert!(total.norm() < 1e-9, "{total:?}");
        // The top face y = 0.2: 0.3 m × 0.1 m, pushed down by p A = 1e5 · 0.03 = 3000 N.
        let top: Vec<bool> = body.nodes.iter().map(|p| p.y > 0.2 - 1e-12).collect();
        let loads = pressure_loads(&body, &top, 1e5, &Schedule::Linear);
        let total: Vector3<Real> = loads.iter().map(|l| l.force).sum();
        assert!((total.y + 3000.0).abs() < 1e-9, "{total:?}");
        assert!(total.x.abs() < 1e-9 && total.z.abs() < 1e-9);
        assert_eq!(loads.len(), 4 * 3);
    }
}
