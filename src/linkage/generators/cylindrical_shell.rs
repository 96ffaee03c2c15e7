//! The cylindrical shell of the paper's Fig. 7.

use super::error::{allocate, check_count, check_length, sum_of_products};
use super::size::Terms;
use super::GeneratorError;
use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;

/// The cylindrical shell of the paper's Fig. 7: a tube of `radius` (m) along +x from
/// x = 0 to x = `length` (m), open at both ends.
///
/// `rings` (at least 2) rings of `sectors` (at least 3) nodes, evenly spaced along the axis;
/// node `s` of ring `r` is node `r · sectors + s`, at `(x_r, radius · cos θ_s, radius · sin θ_s)`
/// with `θ_s = 2π s / sectors`. Ring 0 lies at x = 0: fixing it fully clamps the tube.
///
/// Each four-node cell between two rings is split into two patches along the diagonal from
/// `(r, s)` to `(r + 1, s + 1)`; patches are counter-clockwise seen from outside, so their
/// normals point away from the axis: `2 · (rings − 1) · sectors` patches.
///
/// Members: per ring, its `sectors` segments; per cell, the axial member, the patch diagonal,
/// and the cell's second diagonal, which is no patch edge. The tube is rigid once ring 0 is
/// clamped with one diagonal per cell too (3 members per free node, statically determinate),
/// but all those diagonals wind the same way round the axis, so the tube is chiral: pulled
/// along its axis it twists further round than it stretches. The second diagonal removes
/// that, as in the paper's square (Fig. 4). Member count: `sectors · (4 · rings − 3)`.
pub fn cylindrical_shell(
    radius: Real,
    length: Real,
    rings: usize,
    sectors: usize,
) -> Result<Geometry, GeneratorError> {
    const SHAPE: &str = "cylindrical_shell";
    check_length(SHAPE, "radius", radius)?;
    check_length(SHAPE, "length", length)?;
    check_count(SHAPE, "rings", rings, 2)?;
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
    let mut patches = allocate(
        sum_of_products(&counts.patches),
        SHAPE,
        "rings, sectors",
        too_large,
    )?;

    let directions: Vec<(Real, Real)> = (0..sectors)
        .map(|s| (std::f64::consts::TAU * (s as Real / sectors as Real)).sin_cos())
        .collect();
    for r in 0..rings {
        let x = length * (r as Real / (rings - 1) as Real);
        nodes.extend(
            directions
                .iter()
                .map(|&(sin, cos)| Vector3::new(x, radius * cos, radius * sin)),
        );
    }

    let node = |r: usize, s: usize| r * sectors + s % sectors;
    members.extend((0..sectors).map(|s| [node(0, s), node(0, s + 1)]));
    for r in 1..rings {
        for s in 0..sectors {
            members.push([node(r, s), node(r, s + 1)]);
            members.push([node(r - 1, s), node(r, s)]);
            members.push([node(r - 1, s), node(r, s + 1)]);
            members.push([node(r - 1, s + 1), node(r, s)]);
        }
    }
    // Going round in s is going round the axis counter-clockwise seen from +x, and the
    // tangent of the ring crossed with +x points outward: each triangle takes a step in s
    // before a step in x.
    for r in 0..rings - 1 {
        for s in 0..sectors {
            patches.push([node(r, s), node(r, s + 1), node(r + 1, s + 1)]);
            patches.push([node(r, s), node(r + 1, s + 1), node(r + 1, s)]);
        }
    }

    Ok(Geometry {
        dimension: Dimension::Three,
        nodes,
        members,
        patches,
    })
}

/// The node, member and patch counts of a cylindrical shell of `rings` and `sectors`.
pub(super) fn terms(rings: usize, sectors: usize) -> Terms {
    let cells = rings.saturating_sub(1);
    Terms {
        nodes: vec![vec![rings, sectors]],
        members: vec![vec![rings, sectors], vec![3, cells, sectors]],
        patches: vec![vec![2, cells, sectors]],
    }
}

#[cfg(test)]
mod tests {
    use super::super::rigidity::{
        assert_members_valid, assert_patch_edges_are_members, assert_rigid, patch_centroid,
        patch_normal, solve_unit_truss,
    };
    use super::*;

    fn first_ring_fixed(sectors: usize) -> Vec<(usize, usize)> {
        (0..sectors)
            .flat_map(|s| (0..3).map(move |d| (s, d)))
            .collect()
    }

    #[test]
    fn counts_and_extent() {
        for (rings, sectors) in [(2, 3), (4, 8), (7, 5)] {
            let g = cylindrical_shell(0.2, 1.5, rings, sectors).unwrap();
            assert_eq!(g.dimension, Dimension::Three);
            assert_eq!(g.nodes.len(), rings * sectors);
            assert_eq!(g.members.len(), sectors * (4 * rings - 3));
            assert_eq!(g.patches.len(), 2 * (rings - 1) * sectors);
            assert_members_valid(&g);
            assert_patch_edges_are_members(&g);
            for p in &g.nodes {
                assert!((p.yz().norm() - 0.2).abs() < 1e-15);
            }
            assert_eq!(g.nodes[0], Vector3::new(0.0, 0.2, 0.0));
            assert_eq!(g.nodes[rings * sectors - 1].x, 1.5);
        }
    }

    #[test]
    fn patches_face_away_from_the_axis() {
        for (rings, sectors) in [(4, 8), (2, 3)] {
            let g = cylindrical_shell(0.3, 2.0, rings, sectors).unwrap();
            for &t in &g.patches {
                let n = patch_normal(&g, t);
                let c = patch_centroid(&g, t);
                let outward = Vector3::new(0.0, c.y, c.z);
                assert!(n.dot(&outward) > 0.5 * n.norm() * outward.norm(), "{t:?}");
            }
        }
    }

    #[test]
    fn shell_is_rigid_with_the_first_ring_clamped() {
        for (rings, sectors) in [(4, 8), (2, 3), (6, 12)] {
            let g = cylindrical_shell(1.0, 2.0, rings, sectors).unwrap();
            assert_rigid(
                &g,
                &first_ring_fixed(sectors),
                &format!("shell rings {rings} sectors {sectors}"),
            );
        }
    }

    #[test]
    fn pulling_the_clamped_tube_along_its_axis_does_not_twist_it() {
        // Pins the second diagonal: with one diagonal per cell the end ring turned by more
        // than it moved along the axis (tangential 6.0 against axial 5.0 at k = 1).
        let (rings, sectors) = (6, 12);
        let g = cylindrical_shell(1.0, 3.0, rings, sectors).unwrap();
        let mut forces = vec![Vector3::zeros(); g.nodes.len()];
        for f in &mut forces[(rings - 1) * sectors..] {
            f.x = 1.0;
        }
        let u = solve_unit_truss(&g, &first_ring_fixed(sectors), &forces);
        for (p, u) in g.nodes.iter().zip(&u).skip((rings - 1) * sectors) {
            let tangential = Vector3::new(0.0, -p.z, p.y).normalize();
            assert!(u.x > 1.0);
            assert!(u.dot(&tangential).abs() < 1e-9 * u.x, "{u:?} at {p:?}");
        }
    }

    #[test]
    fn bad_parameters_are_refused_with_the_allowed_values() {
        let e = cylindrical_shell(0.0, 1.0, 2, 8).unwrap_err().to_string();
        assert!(
            e.contains("radius = 0") && e.contains("greater than 0"),
            "{e}"
        );
        let e = cylindrical_shell(1.0, Real::NAN, 2, 8)
            .unwrap_err()
            .to_string();
        assert!(e.contains("length = NaN"), "{e}");
        let e = cylindrical_shell(1.0, 1.0, 1, 8).unwrap_err().to_string();
        assert!(e.contains("rings = 1") && e.contains("2 or more"), "{e}");
        let e = cylindrical_shell(1.0, 1.0, 2, 2).unwrap_err().to_string();
        assert!(e.contains("sectors = 2") && e.contains("3 or more"), "{e}");
        assert!(cylindrical_shell(1.0, 1.0, usize::MAX, 8).is_err());
    }
}
