//! A box lattice: cubic cells whose nodes are joined to all their neighbours, and its boundary patches.

use super::error::{allocate, check_count, check_length, sum_of_products};
use super::size::Terms;
use super::GeneratorError;
use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;

/// The 13 offsets to the neighbours of a node that come later in the node order's sense of
/// "forward": each of the 26 neighbour pairs is made once, from its first node.
const FORWARD: [[isize; 3]; 13] = [
    [1, 0, 0],
    [0, 1, 0],
    [0, 0, 1],
    [1, 1, 0],
    [1, -1, 0],
    [1, 0, 1],
    [1, 0, -1],
    [0, 1, 1],
    [0, 1, -1],
    [1, 1, 1],
    [1, 1, -1],
    [1, -1, 1],
    [1, -1, -1],
];

/// A 3D box of `cells[0] × cells[1] × cells[2]` rectangular cells from the origin to `size`
/// (m), every node joined to all its 26 neighbours.
///
/// Nodes sit at the cell corners, x fastest: node `i + (nx + 1) · (j + (ny + 1) · k)` is at
/// `(i · size[0] / nx, j · size[1] / ny, k · size[2] / nz)`. Members: the cell edges, both
/// diagonals of every cell face and the 4 body diagonals of every cell, listed node by node
/// (each from its lower-numbered end, in the order of `FORWARD`), so the members of one
/// node are together in memory. Member count:
/// `nx(ny+1)(nz+1) + (nx+1)ny(nz+1) + (nx+1)(ny+1)nz + 2[nx·ny(nz+1) + nx(ny+1)nz + (nx+1)ny·nz] + 4·nx·ny·nz`
/// (851,320 for 40³ cells).
///
/// Patches: every cell face on the boundary of the box, split into two triangles
/// counter-clockwise seen from outside (normals point away from the box):
/// `4 · (ny·nz + nx·nz + nx·ny)` patches. Each cell count must be at least 1.
///
/// Runs in time and memory proportional to the member count, with every list allocated
/// once at its final size.
pub fn box_lattice(size: [Real; 3], cells: [usize; 3]) -> Result<Geometry, GeneratorError> {
    const SHAPE: &str = "box_lattice";
    for (parameter, value) in ["size[0]", "size[1]", "size[2]"].into_iter().zip(size) {
        check_length(SHAPE, parameter, value)?;
    }
    for (parameter, value) in ["cells[0]", "cells[1]", "cells[2]"].into_iter().zip(cells) {
        check_count(SHAPE, parameter, value, 1)?;
    }
    let [nx, ny, nz] = cells;
    let too_large = || format!("{cells:?}");
    let [nx1, ny1] = [nx.saturating_add(1), ny.saturating_add(1)];
    let counts = terms(cells);
    let mut nodes = allocate(sum_of_products(&counts.nodes), SHAPE, "cells", too_large)?;
    let member_count = sum_of_products(&counts.members);
    let mut members = allocate(member_count, SHAPE, "cells", too_large)?;
    let mut patches = allocate(sum_of_products(&counts.patches), SHAPE, "cells", too_large)?;

    for k in 0..=nz {
        let z = size[2] * (k as Real / nz as Real);
        for j in 0..=ny {
            let y = size[1] * (j as Real / ny as Real);
            nodes.extend((0..=nx).map(|i| Vector3::new(size[0] * (i as Real / nx as Real), y, z)));
        }
    }

    let node = |[i, j, k]: [usize; 3]| i + nx1 * (j + ny1 * k);
    // The neighbour coordinate `c + o`, if it is still inside `0..=n`.
    let step = |c: usize, o: isize, n: usize| c.checked_add_signed(o).filter(|&c| c <= n);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let here = node([i, j, k]);
                for [di, dj, dk] in FORWARD {
                    if let (Some(a), Some(b), Some(c)) =
                        (step(i, di, nx), step(j, dj, ny), step(k, dk, nz))
                    {
                        members.push([here, node([a, b, c])]);
                    }
                }
            }
        }
    }
    debug_assert_eq!(Some(members.len()), member_count);

    for axis in 0..3 {
        // (u, v, axis) is a right-handed frame: u × v points along +axis.
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (layer, outward_is_positive) in [(0, false), (cells[axis], true)] {
            for b in 0..cells[v] {
                for a in 0..cells[u] {
                    let corner = |du: usize, dv: usize| {
                        let mut c = [0; 3];
                        c[axis] = layer;
                        c[u] = a + du;
                        c[v] = b + dv;
                        node(c)
                    };
                    let (p00, p10, p11, p01) =
                        (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    if outward_is_positive {
                        patches.push([p00, p10, p11]);
                        patches.push([p00, p11, p01]);
                    } else {
                        patches.push([p00, p01, p11]);
                        patches.push([p00, p11, p10]);
                    }
                }
            }
        }
    }

    Ok(Geometry {
        dimension: Dimension::Three,
        nodes,
        members,
        patches,
    })
}

/// The node, member and patch counts of a box lattice of `cells`.
pub(super) fn terms(cells: [usize; 3]) -> Terms {
    let [nx, ny, nz] = cells;
    // Saturating, so a count past usize::MAX is caught by the checked products.
    let [nx1, ny1, nz1] = cells.map(|n| n.saturating_add(1));
    Terms {
        nodes: vec![vec![nx1, ny1, nz1]],
        members: vec![
            vec![nx, ny1, nz1],
            vec![nx1, ny, nz1],
            vec![nx1, ny1, nz],
            vec![2, nx, ny, nz1],
            vec![2, nx, ny1, nz],
            vec![2, nx1, ny, nz],
            vec![4, nx, ny, nz],
        ],
        patches: vec![vec![4, ny, nz], vec![4, nx, nz], vec![4, nx, ny]],
    }
}

#[cfg(test)]
mod tests {
    use super::super::rigidity::{
        assert_members_valid, assert_patch_edges_are_members, assert_rigid, patch_centroid,
        patch_normal,
    };
    use super::*;

    fn expected_members([nx, ny, nz]: [usize; 3]) -> usize {
        nx * (ny + 1) * (nz + 1)
            + (nx + 1) * ny * (nz + 1)
            + (nx + 1) * (ny + 1) * nz
            + 2 * (nx * ny * (nz + 1) + nx * (ny + 1) * nz + (nx + 1) * ny * nz)
            + 4 * nx * ny * nz
    }

    #[test]
    fn one_cell_joins_every_pair_of_its_eight_corners() {
        let g = box_lattice([1.0, 2.0, 3.0], [1, 1, 1]).unwrap();
        assert_eq!(g.nodes.len(), 8);
        assert_eq!(g.members.len(), 28);
        assert_eq!(g.patches.len(), 12);
        assert_members_valid(&g);
        assert_eq!(g.nodes[7], Vector3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn counts_node_order_and_validity() {
        for cells in [[1, 2, 3], [2, 2, 3], [4, 1, 2], [3, 3, 3]] {
            let g = box_lattice([0.4, 0.5, 0.6], cells).unwrap();
            let [nx, ny, nz] = cells;
            assert_eq!(g.nodes.len(), (nx + 1) * (ny + 1) * (nz + 1));
            assert_eq!(g.members.len(), expected_members(cells));
            assert_eq!(g.members.capacity(), g.members.len());
            assert_eq!(g.patches.len(), 4 * (ny * nz + nx * nz + nx * ny));
            assert_members_valid(&g);
            assert_patch_edges_are_members(&g);
            let (i, j, k) = (1, 1, 2);
            let p = g.nodes[i + (nx + 1) * (j + (ny + 1) * k)];
            let expected = Vector3::new(
                0.4 * i as Real / nx as Real,
                0.5 * j as Real / ny as Real,
                0.6 * k as Real / nz as Real,
            );
            assert!((p - expected).norm() < 1e-15, "{p:?} {expected:?}");
            assert_eq!(*g.nodes.last().unwrap(), Vector3::new(0.4, 0.5, 0.6));
        }
    }

    #[test]
    fn every_node_inside_has_26_neighbours() {
        let g = box_lattice([1.0; 3], [2, 2, 2]).unwrap();
        let centre = 1 + 3 * (1 + 3);
        let degree = g.members.iter().filter(|m| m.contains(&centre)).count();
        assert_eq!(degree, 26);
    }

    #[test]
    fn benchmark_size_has_the_stated_member_count() {
        let g = box_lattice([1.0; 3], [40, 40, 40]).unwrap();
        assert_eq!(
            g.members.len(),
            3 * 40 * 41 * 41 + 2 * (3 * 40 * 40 * 41) + 4 * 40 * 40 * 40
        );
        assert_eq!(g.members.len(), 851_320);
        assert_eq!(g.nodes.len(), 41 * 41 * 41);
    }

    #[test]
    fn patches_face_away_from_the_box_centre_and_cover_its_surface() {
        let size = [1.0, 2.0, 0.5];
        let g = box_lattice(size, [2, 3, 2]).unwrap();
        let centre = Vector3::from(size) / 2.0;
        let mut area = 0.0;
        for &t in &g.patches {
            let n = patch_normal(&g, t);
            let c = patch_centroid(&g, t);
            // Outward on a box face: along the face's axis, towards the side the patch is on.
            let axis = n.iamax();
            assert!(n[axis] * (c[axis] - centre[axis]) > 0.0, "{t:?}");
            assert!((c[axis] - centre[axis]).abs() > 0.49 * size[axis]);
            area += n.norm() / 2.0;
        }
        assert!((area - 2.0 * (2.0 * 0.5 + 1.0 * 0.5 + 1.0 * 2.0)).abs() < 1e-12);
    }

    #[test]
    fn lattice_is_rigid_with_its_bottom_face_fixed() {
        let cells = [2, 2, 3];
        let g = box_lattice([1.0, 1.0, 1.5], cells).unwrap();
        let bottom: Vec<(usize, usize)> =
            (0..9).flat_map(|n| (0..3).map(move |d| (n, d))).collect();
        assert_rigid(&g, &bottom, "lattice 2×2×3");
    }

    #[test]
    fn bad_parameters_are_refused_with_the_allowed_values() {
        let e = box_lattice([1.0, -2.0, 1.0], [1, 1, 1])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("size[1] = -2") && e.contains("greater than 0"),
            "{e}"
        );
        let e = box_lattice([1.0; 3], [1, 1, 0]).unwrap_err().to_string();
        assert!(e.contains("cells[2] = 0") && e.contains("1 or more"), "{e}");
        let e = box_lattice([1.0; 3], [usize::MAX, 1, 1])
            .unwrap_err()
            .to_string();
        assert!(e.contains("more nodes or members than fit"), "{e}");
        assert!(box_lattice([1.0; 3], [1 << 30, 1 << 30, 1 << 30]).is_err());
    }
}
