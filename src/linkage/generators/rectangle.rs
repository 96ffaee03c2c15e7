//! The 2D rectangle of the paper's Fig. 4–6, cells with both diagonals.

use super::error::{allocate, check_count, check_length, sum_of_products};
use super::size::Terms;
use super::GeneratorError;
use crate::linkage::{Dimension, Geometry};
use crate::Real;
use nalgebra::Vector3;

/// The 2D solid of the paper's Fig. 4–6: a `width` × `height` rectangle (m) of
/// `cells_x` × `cells_y` rectangular cells, each with its four sides and BOTH diagonals,
/// in the plane z = 0 with its lower-left corner at the origin.
///
/// Nodes go row by row from the bottom, x fastest: node `i + (cells_x + 1) · j` is at
/// `(i · width / cells_x, j · height / cells_y)`. Members: the horizontal sides row by row,
/// then the vertical sides row by row, then per cell (row by row) the diagonal rising to the
/// right and the one falling to the right. One cell is the paper's square: 4 nodes, 6 members.
///
/// `cells_x` and `cells_y` must be at least 1. No patches (2D).
pub fn rectangle(
    width: Real,
    height: Real,
    cells_x: usize,
    cells_y: usize,
) -> Result<Geometry, GeneratorError> {
    const SHAPE: &str = "rectangle";
    check_length(SHAPE, "width", width)?;
    check_length(SHAPE, "height", height)?;
    check_count(SHAPE, "cells_x", cells_x, 1)?;
    check_count(SHAPE, "cells_y", cells_y, 1)?;
    let (nx, ny) = (cells_x, cells_y);
    let too_large = || format!("{nx}, {ny}");
    let counts = terms(nx, ny);
    let mut nodes = allocate(
        sum_of_products(&counts.nodes),
        SHAPE,
        "cells_x, cells_y",
        too_large,
    )?;
    let mut members = allocate(
        sum_of_products(&counts.members),
        SHAPE,
        "cells_x, cells_y",
        too_large,
    )?;

    for j in 0..=ny {
        let y = height * (j as Real / ny as Real);
        nodes.extend((0..=nx).map(|i| Vector3::new(width * (i as Real / nx as Real), y, 0.0)));
    }

    let node = |i: usize, j: usize| i + (nx + 1) * j;
    for j in 0..=ny {
        members.extend((0..nx).map(|i| [node(i, j), node(i + 1, j)]));
    }
    for j in 0..ny {
        members.extend((0..=nx).map(|i| [node(i, j), node(i, j + 1)]));
    }
    for j in 0..ny {
        for i in 0..nx {
            members.push([node(i, j), node(i + 1, j + 1)]);
            members.push([node(i + 1, j), node(i, j + 1)]);
        }
    }

    Ok(Geometry {
        dimension: Dimension::Two,
        nodes,
        members,
        patches: Vec::new(),
    })
}

/// The node and member counts of a rectangle of `nx` × `ny` cells.
pub(super) fn terms(nx: usize, ny: usize) -> Terms {
    // Saturating, so a count past usize::MAX is caught by the checked products.
    let (nx1, ny1) = (nx.saturating_add(1), ny.saturating_add(1));
    Terms {
        nodes: vec![vec![nx1, ny1]],
        members: vec![vec![nx, ny1], vec![nx1, ny], vec![2, nx, ny]],
        patches: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::super::rigidity::{assert_members_valid, assert_rigid};
    use super::*;

    #[test]
    fn one_cell_is_the_papers_square() {
        let g = rectangle(1.0, 1.0, 1, 1).unwrap();
        assert_eq!(g.nodes.len(), 4);
        assert_eq!(g.members.len(), 6);
        assert_members_valid(&g);
        assert_eq!(g.nodes[3], Vector3::new(1.0, 1.0, 0.0));
    }

    #[test]
    fn counts_and_node_order() {
        let g = rectangle(3.0, 0.5, 3, 2).unwrap();
        assert_eq!(g.nodes.len(), 12);
        assert_eq!(g.members.len(), 3 * 3 + 4 * 2 + 2 * 6);
        assert_members_valid(&g);
        assert_eq!(g.nodes[0], Vector3::zeros());
        assert_eq!(g.nodes[1], Vector3::new(1.0, 0.0, 0.0));
        assert_eq!(g.nodes[4], Vector3::new(0.0, 0.25, 0.0));
        assert_eq!(g.nodes[11], Vector3::new(3.0, 0.5, 0.0));
    }

    #[test]
    fn rectangle_is_rigid_pinned_lower_left_and_held_in_y_lower_right() {
        for (nx, ny) in [(1, 1), (3, 2), (1, 4)] {
            let g = rectangle(2.0, 1.0, nx, ny).unwrap();
            assert_rigid(
                &g,
                &[(0, 0), (0, 1), (nx, 1)],
                &format!("rectangle {nx}×{ny}"),
            );
        }
    }

    #[test]
    fn bad_parameters_are_refused_with_the_allowed_values() {
        let e = rectangle(-1.0, 1.0, 1, 1).unwrap_err().to_string();
        assert!(
            e.contains("width = -1") && e.contains("greater than 0"),
            "{e}"
        );
        let e = rectangle(1.0, Real::INFINITY, 1, 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("height = inf"), "{e}");
        let e = rectangle(1.0, 1.0, 1, 0).unwrap_err().to_string();
        assert!(e.contains("cells_y = 0") && e.contains("1 or more"), "{e}");
        let e = rectangle(1.0, 1.0, usize::MAX, 3).unwrap_err().to_string();
        assert!(
            e.contains(&format!("cells_x, cells_y = {}, 3 asks", usize::MAX)),
            "{e}"
        );
        assert!(rectangle(1.0, 1.0, 3, usize::MAX).is_err());
    }
}
