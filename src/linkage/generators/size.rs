//! How large a generated shape will be, counted from its parameters before anything is made,
//! so that an absurd cell count can be refused against the machine's memory instead of
//! aborting on an allocation (see `scene::fits_machine`).

use super::{box_lattice, cylindrical_shell, disk, rectangle};
use crate::Real;

/// The node, member and patch counts of a generated shape, each a sum of products of its
/// parameters: the generator allocates its lists from them (exact, `None` past `usize`), and
/// [`GeneratedSize`] is their value as floats.
#[derive(Clone, Debug, Default)]
pub(super) struct Terms {
    pub nodes: Vec<Vec<usize>>,
    pub members: Vec<Vec<usize>>,
    pub patches: Vec<Vec<usize>>,
}

/// The size of the shape a generator would make. Floats: an absurd count is beyond every
/// integer type (`cells = [1e9, 1e9, 1e9]` makes 1e27 nodes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneratedSize {
    /// Nodes.
    pub nodes: Real,
    /// Members.
    pub members: Real,
    /// Boundary patches (triangles; 3D shapes only).
    pub patches: Real,
}

impl Terms {
    /// The counts as floats.
    pub(super) fn size(&self) -> GeneratedSize {
        let sum = |terms: &[Vec<usize>]| -> Real {
            terms
                .iter()
                .map(|factors| factors.iter().map(|&f| f as Real).product::<Real>())
                .sum()
        };
        GeneratedSize {
            nodes: sum(&self.nodes),
            members: sum(&self.members),
            patches: sum(&self.patches),
        }
    }
}

/// The size of `disk(radius, rings, sectors)` (any radius).
pub fn disk_size(rings: usize, sectors: usize) -> GeneratedSize {
    disk::terms(rings, sectors).size()
}

/// The size of `rectangle(width, height, cells_x, cells_y)` (any width and height).
pub fn rectangle_size(cells_x: usize, cells_y: usize) -> GeneratedSize {
    rectangle::terms(cells_x, cells_y).size()
}

/// The size of `cylindrical_shell(radius, length, rings, sectors)` (any radius and length).
pub fn cylindrical_shell_size(rings: usize, sectors: usize) -> GeneratedSize {
    cylindrical_shell::terms(rings, sectors).size()
}

/// The size of `box_lattice(size, cells)` (any size).
pub fn box_lattice_size(cells: [usize; 3]) -> GeneratedSize {
    box_lattice::terms(cells).size()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::generators::{box_lattice, cylindrical_shell, disk, rectangle};

    /// The counted sizes are those of the shapes made.
    #[test]
    fn the_counts_are_those_of_the_shapes_made() {
        let check = |size: GeneratedSize, g: crate::linkage::Geometry| {
            assert_eq!(size.nodes, g.nodes.len() as Real);
            assert_eq!(size.members, g.members.len() as Real);
            assert_eq!(size.patches, g.patches.len() as Real);
        };
        check(disk_size(3, 7), disk(1.0, 3, 7).unwrap());
        check(disk_size(1, 3), disk(1.0, 1, 3).unwrap());
        check(rectangle_size(4, 3), rectangle(2.0, 1.0, 4, 3).unwrap());
        check(
            cylindrical_shell_size(5, 6),
            cylindrical_shell(1.0, 2.0, 5, 6).unwrap(),
        );
        check(
            box_lattice_size([3, 2, 4]),
            box_lattice([1.0, 1.0, 1.0], [3, 2, 4]).unwrap(),
        );
    }

    /// Absurd counts are floats, not overflows: 1000³ cells make 1001³ nodes and
    /// 13·1000³ + 9·1000² + 3·1000 members (by hand from the box lattice's terms).
    #[test]
    fn absurd_counts_are_counted_without_overflow() {
        let s = box_lattice_size([1000, 1000, 1000]);
        assert_eq!(s.nodes, 1001.0 * 1001.0 * 1001.0);
        let n: Real = 1000.0;
        let members = 3.0 * n * (n + 1.0) * (n + 1.0) + 6.0 * n * n * (n + 1.0) + 4.0 * n * n * n;
        assert!(
            (s.members - members).abs() <= 1e-12 * members,
            "{}",
            s.members
        );
        let huge = box_lattice_size([usize::MAX; 3]);
        assert!(huge.nodes > 1e57 && huge.nodes.is_finite());
    }
}
