//! The circular disk of the paper's Fig. 1.

use super::error::{allocate, check_count, check_length, sum_of_products};
use super::size::Terms;
use super::GeneratorError;
use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;

/// The circular disk of the paper's Fig. 1, in the plane z = 0, centred at the origin.
///
/// `radius` is in m. Node 0 is the centre; then come `rings` rings of `sectors` nodes each,
/// ring r (1-based) at radius `r · radius / rings`, node s of a ring at the angle
/// `2π s / sectors` from +x: node index `1 + (r − 1) · sectors + s`.
///
/// Members: `sectors` spokes from the centre to ring 1 and the `sectors` segments of ring 1
/// (with `rings = 1, sectors = 8` this is the paper's disk: 9 nodes, 16 members); then for
/// each further ring, the radial members from the ring inside, the ring's segments, and both
/// diagonals of every four-node cell between the two rings, as in the paper's square
/// (Fig. 4), so the disk has no preferred direction of shear. Member count:
/// `sectors · (2 + 4 · (rings − 1))`.
///
/// `rings` must be at least 1 and `sectors` at least 3. No patches (2D).
pub fn disk(radius: Real, rings: usize, sectors: usize) -> Result<Geometry, GeneratorError> {
    const SHAPE: &str = "disk";
    check_length(SHAPE, "radius", radius)?;
    check_count(SHAPE, "rings", rings, 1)?;
    check_count(SHAPE, "sectors", sectors, 3)?;
    let too_large = || format!("{rings}, {sectors}");
    let counts = terms(rings, sectors);
    let mut nodes = allocate(
        sum_of_products(&counts.nodes),
        SHAPE,
        "rings, sectors",
        too_large,
    )?;
    let mut members = allocate(
        sum_of_products(&counts.members),
        SHAPE,
        "rings, sectors",
        too_large,
    )?;

    nodes.push(Vector3::zeros());
    let directions: Vec<(Real, Real)> = (0..sectors)
        .map(|s| (std::f64::consts::TAU * (s as Real / sectors as Real)).sin_cos())
        .collect();
    for r in 1..=rings {
        let ring_radius = radius * (r as Real / rings as Real);
        nodes.extend(
            directions
                .iter()
                .map(|&(sin, cos)| Vector3::new(ring_radius * cos, ring_radius * sin, 0.0)),
        );
    }

    let node = |r: usize, s: usize| 1 + (r - 1) * sectors + s % sectors;
    members.extend((0..sectors).map(|s| [0, node(1, s)]));
    members.extend((0..sectors).map(|s| [node(1, s), node(1, s + 1)]));
    for r in 2..=rings {
        for s in 0..sectors {
            members.push([node(r - 1, s), node(r, s)]);
            members.push([node(r, s), node(r, s + 1)]);
            members.push([node(r - 1, s), node(r, s + 1)]);
            members.push([node(r - 1, s + 1), node(r, s)]);
        }
    }

    Ok(Geometry {
        dimension: Dimension::Two,
        nodes,
        members,
        patches: Vec::new(),
    })
}

/// The node and member counts of a disk of `rings` and `sectors`.
pub(super) fn terms(rings: usize, sectors: usize) -> Terms {
    Terms {
        nodes: vec![vec![1], vec![rings, sectors]],
        members: vec![vec![2, sectors], vec![4, rings.saturating_sub(1), sectors]],
        patches: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::rigidity::{assert_members_valid, assert_rigid};
    use super::*;

    #[test]
    fn coarsest_disk_is_the_papers_fig_1() {
        let g = disk(1.0, 1, 8).unwrap();
        assert_eq!(g.dimension, Dimension::Two);
        assert_eq!(g.nodes.len(), 9);
        assert_eq!(g.members.len(), 16);
        assert!(g.patches.is_empty());
        assert_members_valid(&g);
        for p in &g.nodes[1..] {
            assert!((p.norm() - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn counts_and_positions_of_refined_disks() {
        for (rings, sectors) in [(1, 3), (2, 8), (3, 12), (5, 7)] {
            let g = disk(0.5, rings, sectors).unwrap();
            assert_eq!(g.nodes.len(), 1 + rings * sectors);
            assert_eq!(g.members.len(), sectors * (2 + 4 * (rings - 1)));
            assert_members_valid(&g);
            let rim = g.nodes.iter().map(|p| p.norm()).fold(0.0, Real::max);
            assert!((rim - 0.5).abs() < 1e-15);
            assert!(g.nodes.iter().all(|p| p.z == 0.0));
        }
    }

    #[test]
    fn disk_is_rigid_with_centre_pinned_and_one_rim_node_held_tangentially() {
        for rings in 1..=3 {
            for sectors in [8, 12] {
                let g = disk(1.0, rings, sectors).unwrap();
                // Node 1 sits on +x, so its tangential direction is y.
                let rim = 1 + (rings - 1) * sectors;
                assert_rigid(
                    &g,
                    &[(0, 0), (0, 1), (rim, 1)],
                    &format!("disk rings {rings} sectors {sectors}"),
                );
            }
        }
    }

    #[test]
    fn bad_parameters_are_refused_with_the_allowed_values() {
        let e = disk(0.0, 1, 8).unwrap_err().to_string();
        assert!(e.contains("radius") && e.contains("greater than 0"), "{e}");
        assert!(disk(Real::NAN, 1, 8).is_err());
        let e = disk(1.0, 0, 8).unwrap_err().to_string();
        assert!(e.contains("rings = 0") && e.contains("1 or more"), "{e}");
        let e = disk(1.0, 1, 2).unwrap_err().to_string();
        assert!(e.contains("sectors = 2") && e.contains("3 or more"), "{e}");
        let e = disk(1.0, usize::MAX, 8).unwrap_err().to_string();
        assert!(
            e.contains("rings, sectors = ") && e.contains("than fit in memory"),
            "{e}"
        );
    }
}
