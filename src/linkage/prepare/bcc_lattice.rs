//! A body-centred cubic lattice: cube corners ("black") and cube centres ("red"), its edges
//! and its tetrahedra (Labelle & Shewchuk 2007, §3).

use crate::Real;
use nalgebra::Vector3;

/// A lattice edge's kind: long edges (corner–corner and centre–centre, length h) and short
/// ones (centre–corner, length √3/2 · h) warp with different thresholds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum EdgeKind {
    /// Axis-aligned, length h.
    Long,
    /// Centre to corner, length √3/2 · h.
    Short,
}

/// A BCC lattice of `cells` cubes of side `h` (m) from `origin` (m). Vertex ids: the
/// `(nx+1)(ny+1)(nz+1)` corners first, x fastest, then the `nx·ny·nz` centres.
#[derive(Clone, Debug)]
pub(crate) struct BccLattice {
    /// The lowest corner, m.
    pub origin: Vector3<Real>,
    /// Cube side, m.
    pub h: Real,
    /// Cubes along x, y and z.
    pub cells: [usize; 3],
}

impl BccLattice {
    /// Corner vertices.
    pub fn corner_count(&self) -> usize {
        self.cells.iter().map(|n| n + 1).product()
    }

    /// All vertices, corners and centres.
    pub fn vertex_count(&self) -> usize {
        self.corner_count() + self.cells.iter().product::<usize>()
    }

    /// The id of corner `c`.
    fn corner(&self, c: [usize; 3]) -> usize {
        let [nx, ny, _] = self.cells;
        c[0] + (nx + 1) * (c[1] + (ny + 1) * c[2])
    }

    /// The id of the centre of cube `c`.
    fn centre(&self, c: [usize; 3]) -> usize {
        let [nx, ny, _] = self.cells;
        self.corner_count() + c[0] + nx * (c[1] + ny * c[2])
    }

    /// The position of vertex `id`, m.
    pub fn position(&self, id: usize) -> Vector3<Real> {
        let [nx, ny, _] = self.cells;
        let (id, half) = match id.checked_sub(self.corner_count()) {
            Some(r) => ((r % nx, (r / nx) % ny, r / (nx * ny)), 0.5),
            None => (
                (
                    id % (nx + 1),
                    (id / (nx + 1)) % (ny + 1),
                    id / ((nx + 1) * (ny + 1)),
                ),
                0.0,
            ),
        };
        let (i, j, k) = id;
        self.origin + Vector3::new(i as Real + half, j as Real + half, k as Real + half) * self.h
    }

    /// Every lattice edge once, as `(a, b, kind)` with `a < b`, in a fixed order.
    pub fn for_each_edge(&self, mut f: impl FnMut(usize, usize, EdgeKind)) {
        let [nx, ny, nz] = self.cells;
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let c = [i, j, k];
                    for axis in 0..3 {
                        if c[axis] < self.cells[axis] {
                            let mut d = c;
                            d[axis] += 1;
                            f(self.corner(c), self.corner(d), EdgeKind::Long);
                        }
                    }
                }
            }
        }
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = [i, j, k];
                    let here = self.centre(c);
                    for axis in 0..3 {
                        if c[axis] + 1 < self.cells[axis] {
                            let mut d = c;
                            d[axis] += 1;
                            f(here, self.centre(d), EdgeKind::Long);
                        }
                    }
                    for corner in 0..8 {
                        let d = [i + (corner & 1), j + ((corner >> 1) & 1), k + (corner >> 2)];
                        f(self.corner(d), here, EdgeKind::Short);
                    }
                }
            }
        }
    }

    /// Every lattice tetrahedron once: two neighbouring centres and an edge of the square
    /// face between them, 12 per interior cube, each of volume h³/12.
    pub fn for_each_tet(&self, mut f: impl FnMut([usize; 4])) {
        let [nx, ny, nz] = self.cells;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = [i, j, k];
                    let here = self.centre(c);
                    for axis in 0..3 {
                        if c[axis] + 1 >= self.cells[axis] {
                            continue;
                        }
                        let mut d = c;
                        d[axis] += 1;
                        let there = self.centre(d);
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let corner = |du: usize, dv: usize| {
                            let mut p = d;
                            p[u] += du;
                            p[v] += dv;
                            self.corner(p)
                        };
                        let square = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        for e in 0..4 {
                            f([here, there, square[e], square[(e + 1) % 4]]);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volume(p: [Vector3<Real>; 4]) -> Real {
        (p[1] - p[0]).dot(&(p[2] - p[0]).cross(&(p[3] - p[0]))) / 6.0
    }

    #[test]
    fn tets_fill_the_inner_cubes_and_have_the_stated_edges() {
        let l = BccLattice {
            origin: Vector3::new(1.0, 2.0, 3.0),
            h: 0.5,
            cells: [3, 3, 3],
        };
        let mut total = 0.0;
        let mut count = 0;
        l.for_each_tet(|t| {
            let p = t.map(|v| l.position(v));
            let v = volume(p).abs();
            // Hand calculation: a BCC tet is an eighth... of an octahedron of the dual: h³/12.
            assert!((v - 0.125 / 12.0).abs() < 1e-15, "{v}");
            assert!(((p[0] - p[1]).norm() - 0.5).abs() < 1e-15);
            assert!(((p[2] - p[3]).norm() - 0.5).abs() < 1e-15);
            for (a, b) in [(0, 2), (0, 3), (1, 2), (1, 3)] {
                assert!(((p[a] - p[b]).norm() - 0.5 * 0.75f64.sqrt()).abs() < 1e-15);
            }
            total += v;
            count += 1;
        });
        // 3 × 2 × 3 neighbouring centre pairs per axis, 4 tets each.
        assert_eq!(count, 3 * 18 * 4);
        assert!((total - count as Real * 0.125 / 12.0).abs() < 1e-12);
        let mut edges = 0;
        l.for_each_edge(|a, b, kind| {
            let length = (l.position(a) - l.position(b)).norm();
            let expected = match kind {
                EdgeKind::Long => 0.5,
                EdgeKind::Short => 0.5 * 0.75f64.sqrt(),
            };
            assert!((length - expected).abs() < 1e-15);
            edges += 1;
        });
        assert_eq!(edges, 3 * 3 * 16 + 3 * 3 * 2 * 3 + 8 * 27);
    }
}
