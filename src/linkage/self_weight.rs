//! Self-weight lumped to the nodes: each member's weight ρ A L g shared half and half by its
//! two end nodes (the lumped masses ρAL/2 per member end).

use crate::linkage::dynamics::node_masses;
use crate::linkage::{Body, NodalLoad, Schedule};
use crate::Real;
use nalgebra::Vector3;

/// The nodal loads of `body`'s self-weight under `gravity` (m/s²), with `density[k]` (kg/m³)
/// the density of `body.materials[k]` (`None`: weightless): per node, the sum over its members
/// of ρ A L / 2 · g (N), in node order, growing by `schedule`. Nodes that carry no weight get
/// no load. Their sum is exactly ρ g Σ A L up to round-off.
pub fn self_weight_loads(
    body: &Body,
    density: &[Option<Real>],
    gravity: Vector3<Real>,
    schedule: &Schedule,
) -> Vec<NodalLoad> {
    let mass = node_masses(body, density);
    mass.iter()
        .enumerate()
        .filter(|(_, &m)| m > 0.0)
        .map(|(node, &m)| NodalLoad {
            node,
            force: gravity * m,
            schedule: schedule.clone(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{Dimension, Material, Member};

    #[test]
    fn a_bar_of_two_members_weighs_rho_g_a_l_shared_by_its_ends() {
        // Hand calculation: steel 7850 kg/m³, A = 1e-4 m², members of 1 m and 2 m:
        // weights 7850·1e-4·1·9.81 = 7.70085 N and 15.4017 N; the middle node carries half of each.
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("steel", 200e9, 1e-4));
        body.nodes = vec![
            Vector3::zeros(),
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(3.0, 0.0, 0.0),
        ];
        body.members = vec![
            Member {
                nodes: [0, 1],
                material: 0,
            },
            Member {
                nodes: [1, 2],
                material: 0,
            },
        ];
        let g = Vector3::new(0.0, -9.81, 0.0);
        let loads = self_weight_loads(&body, &[Some(7850.0)], g, &Schedule::Linear);
        let w = 7850.0 * 1e-4 * 9.81;
        let expected = [0.5 * w, 1.5 * w, w];
        for (l, e) in loads.iter().zip(expected) {
            assert!((l.force.y + e).abs() < 1e-12 * e, "{l:?} {e}");
        }
        assert!(self_weight_loads(&body, &[None], g, &Schedule::Linear).is_empty());
    }
}
