//! The sparse pattern of `K_ff` (paper Eq. 3–4), computed once, and its refill member by member.

use crate::linkage::{Body, DofMap, DofSlot};
use crate::Real;
use nalgebra::Matrix3;
use rayon::prelude::*;

/// Marks a block entry that does not land in `K_ff` (one of its DOFs is supported).
const NOT_FREE: u32 = u32::MAX;

/// The sparse pattern of `K_ff` (lower triangle, compressed columns) of one body, computed
/// once, with the place of every member entry in it, so that refilling the values (paper
/// Eq. 3–4: adding each member's Eq. 2 matrix into the global one) is a single pass over the
/// members with no sorting and no allocation. The default is the empty pattern (no free DOF,
/// no member): a placeholder where no matrix is assembled.
#[derive(Clone, Debug, Default)]
pub struct StiffnessAssembly {
    /// Number of free DOFs (rows and columns of `K_ff`).
    pub n: usize,
    /// Column starts, length `n + 1`.
    pub col_ptr: Vec<usize>,
    /// Row of each stored entry; ascending within a column; the diagonal comes first.
    pub row_idx: Vec<usize>,
    /// The node of each free DOF: lets the ordering work on the node graph.
    pub groups: Vec<usize>,
    /// Per node: place of entry (row direction p, column direction q), p ≥ q, at `3p + q`.
    diagonal: Vec<[u32; 9]>,
    /// Per member: place of entry (higher node's direction p, lower node's direction q) at `3p + q`.
    cross: Vec<[u32; 9]>,
}

/// The pattern would need more than 4 × 10⁹ entries.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("body '{body}' is too large: its stiffness matrix would hold {entries} entries (at most {limit})")]
pub struct ModelTooLarge {
    /// Body name.
    pub body: String,
    /// Entries needed.
    pub entries: usize,
    /// Entries allowed.
    pub limit: usize,
}

impl StiffnessAssembly {
    /// The pattern of `K_ff` for `body` under the partition `dofs`. Members must be valid
    /// (see `Body::validate`).
    pub fn new(body: &Body, dofs: &DofMap) -> Result<Self, ModelTooLarge> {
        let d = dofs.dofs_per_node;
        let nodes = body.nodes.len();
        // Free DOFs of each node in direction order, as (direction, free index).
        let local = |node: usize, dir: usize| -> Option<usize> {
            match dofs.slots[node * d + dir] {
                DofSlot::Free(i) => Some(i),
                DofSlot::Supported(_) => None,
            }
        };
        let free_count = |node: usize| (0..d).filter(|&p| local(node, p).is_some()).count();
        let nfree: Vec<usize> = (0..nodes).map(free_count).collect();

        // Lower node adjacency: for node j, the neighbours i > j joined to it by a member.
        let mut start = vec![0usize; nodes + 1];
        for m in &body.members {
            let (lo, hi) = ordered(m.nodes);
            if nfree[lo] > 0 && nfree[hi] > 0 {
                start[lo + 1] += 1;
            }
        }
        for j in 0..nodes {
            start[j + 1] += start[j];
        }
        let mut neighbours = vec![0usize; start[nodes]];
        let mut fill = start.clone();
        for m in &body.members {
            let (lo, hi) = ordered(m.nodes);
            if nfree[lo] > 0 && nfree[hi] > 0 {
                neighbours[fill[lo]] = hi;
                fill[lo] += 1;
            }
        }
        // Rows below the diagonal block of node j's columns, before neighbour entry e.
        let mut block_offset = vec![0usize; neighbours.len()];
        let mut below = vec![0usize; nodes];
        for j in 0..nodes {
            let list = &mut neighbours[start[j]..start[j + 1]];
            list.sort_unstable();
            let mut acc = 0;
            for (e, &i) in list.iter().enumerate() {
                block_offset[start[j] + e] = acc;
                acc += nfree[i];
            }
            below[j] = acc;
        }

        let n = dofs.free.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        let mut groups = Vec::with_capacity(n);
        for &dof in &dofs.free {
            let (j, q) = dofs.node_and_direction(dof);
            let diag = (q..d).filter(|&p| local(j, p).is_some()).count();
            col_ptr.push(col_ptr[col_ptr.len() - 1] + diag + below[j]);
            groups.push(j);
        }
        let nnz = col_ptr[n];
        if nnz >= NOT_FREE as usize {
            return Err(ModelTooLarge {
                body: body.name.clone(),
                entries: nnz,
                limit: NOT_FREE as usize - 1,
            });
        }
        // Columns are independent: split row_idx at column starts and fill them in parallel.
        let mut row_idx = vec![0usize; nnz];
        let mut columns = Vec::with_capacity(n);
        let mut rest = row_idx.as_mut_slice();
        for c in 0..n {
            let (column, tail) = rest.split_at_mut(col_ptr[c + 1] - col_ptr[c]);
            columns.push((dofs.free[c], column));
            rest = tail;
        }
        columns.into_par_iter().for_each(|(dof, column)| {
            let (j, q) = dofs.node_and_direction(dof);
            let rows = (q..d).filter_map(|p| local(j, p)).chain(
                neighbours[start[j]..start[j + 1]]
                    .iter()
                    .flat_map(|&i| (0..d).filter_map(move |p| local(i, p))),
            );
            for (slot, r) in column.iter_mut().zip(rows) {
                *slot = r;
            }
        });

        let mut diagonal = vec![[NOT_FREE; 9]; nodes];
        for (j, places) in diagonal.iter_mut().enumerate() {
            for q in 0..d {
                let Some(c) = local(j, q) else { continue };
                let mut offset = 0;
                for p in q..d {
                    if local(j, p).is_some() {
                        places[3 * p + q] = (col_ptr[c] + offset) as u32;
                        offset += 1;
                    }
                }
            }
        }
        let mut cross = vec![[NOT_FREE; 9]; body.members.len()];
        body.members
            .par_iter()
            .zip(cross.par_iter_mut())
            .for_each(|(m, places)| {
                let (lo, hi) = ordered(m.nodes);
                if nfree[lo] == 0 || nfree[hi] == 0 {
                    return;
                }
                let list = &neighbours[start[lo]..start[lo + 1]];
                let e = start[lo] + list.partition_point(|&i| i < hi);
                for q in 0..d {
                    let Some(c) = local(lo, q) else { continue };
                    let diag = (q..d).filter(|&p| local(lo, p).is_some()).count();
                    let mut offset = 0;
                    for p in 0..d {
                        if local(hi, p).is_some() {
                            places[3 * p + q] =
                                (col_ptr[c] + diag + block_offset[e] + offset) as u32;
                            offset += 1;
                        }
                    }
                }
            });
        Ok(StiffnessAssembly {
            n,
            col_ptr,
            row_idx,
            groups,
            diagonal,
            cross,
        })
    }

    /// Number of stored entries of the lower triangle.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Refill `values` (resized to `nnz`) with `K_ff`: member `m` contributes
    /// `[B −B; −B B]` with `B = block(m)` (3×3; in 2D only the upper-left 2×2 is read).
    pub fn fill(
        &self,
        body: &Body,
        mut block: impl FnMut(usize) -> Matrix3<Real>,
        values: &mut Vec<Real>,
    ) {
        values.clear();
        values.resize(self.nnz(), 0.0);
        for (m, member) in body.members.iter().enumerate() {
            let b = block(m);
            let places = &self.cross[m];
            for (k, &place) in places.iter().enumerate() {
                if place != NOT_FREE {
                    values[place as usize] -= b[(k / 3, k % 3)];
                }
            }
            for node in member.nodes {
                for (k, &place) in self.diagonal[node].iter().enumerate() {
                    if place != NOT_FREE {
                        values[place as usize] += b[(k / 3, k % 3)];
                    }
                }
            }
        }
    }

    /// Add to `values` a node block of `K_ff` between the two nodes of `member`: `block` has the
    /// directions of the member's higher-numbered node as rows and those of its lower one as
    /// columns (the transposed block above the diagonal is implied; in 2D only the upper-left
    /// 2×2 is read).
    pub fn add_pair_block(&self, member: usize, block: &Matrix3<Real>, values: &mut [Real]) {
        for (k, &place) in self.cross[member].iter().enumerate() {
            if place != NOT_FREE {
                values[place as usize] += block[(k / 3, k % 3)];
            }
        }
    }

    /// Add the symmetric 3×3 `block` (in 2D its upper-left 2×2) to `node`'s own block of
    /// `K_ff` in `values` (a penalty spring holding the node).
    pub fn add_node_block(&self, node: usize, block: &Matrix3<Real>, values: &mut [Real]) {
        for (k, &place) in self.diagonal[node].iter().enumerate() {
            if place != NOT_FREE {
                values[place as usize] += block[(k / 3, k % 3)];
            }
        }
    }

    /// The place in the value array of `K_ff`'s diagonal entry of `node`'s direction `dir`,
    /// if that DOF is free (to hold a DOF that lost every member).
    pub fn diagonal_place(&self, node: usize, dir: usize) -> Option<usize> {
        let place = self.diagonal[node][4 * dir];
        (place != NOT_FREE).then_some(place as usize)
    }

    /// `y = K_ff x` from the stored lower triangle (for checks; the solves use the factor).
    pub fn multiply(&self, values: &[Real], x: &[Real], y: &mut [Real]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..self.n {
            let range = self.col_ptr[c]..self.col_ptr[c + 1];
            for (&r, &v) in self.row_idx[range.clone()].iter().zip(&values[range]) {
                y[r] += v * x[c];
                if r != c {
                    y[c] += v * x[r];
                }
            }
        }
    }
}

fn ordered([a, b]: [usize; 2]) -> (usize, usize) {
    (a.min(b), a.max(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linkage::{
        member_block, member_stiffness_matrix, Dimension, Material, Member, Support,
    };
    use nalgebra::{DMatrix, Vector3};

    fn dense_ff(a: &StiffnessAssembly, values: &[Real]) -> DMatrix<Real> {
        let mut k = DMatrix::zeros(a.n, a.n);
        for c in 0..a.n {
            let range = a.col_ptr[c]..a.col_ptr[c + 1];
            for (&r, &v) in a.row_idx[range.clone()].iter().zip(&values[range]) {
                assert!(r >= c, "lower triangle only");
                k[(r, c)] += v;
                if r != c {
                    k[(c, r)] += v;
                }
            }
        }
        k
    }

    /// A small irregular 3D body with one node partly supported and one fully supported.
    fn sample_body() -> Body {
        let mut b = Body::new("t", Dimension::Three);
        b.materials.push(Material::new("m", 7.0, 0.5));
        b.nodes = vec![
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(1.0, 0.1, 0.0),
            Vector3::new(0.2, 1.3, 0.1),
            Vector3::new(0.4, 0.3, 0.9),
            Vector3::new(1.1, 1.2, 0.8),
        ];
        for (i, j) in [
            (0, 1),
            (0, 2),
            (0, 3),
            (1, 2),
            (1, 3),
            (2, 3),
            (4, 1),
            (4, 2),
            (3, 4),
        ] {
            b.members.push(Member {
                nodes: [i, j],
                material: 0,
            });
        }
        b.supports.push(Support::fixed(0, [true, true, true]));
        b.supports.push(Support::fixed(2, [false, true, false]));
        b
    }

    #[test]
    fn sparse_fill_matches_dense_assembly_of_eq2() {
        let body = sample_body();
        let dofs = DofMap::new(&body);
        let a = StiffnessAssembly::new(&body, &dofs).unwrap();
        let k_of = |m: usize| 7.0 * 0.5 / body.member_length(m);
        let mut values = Vec::new();
        a.fill(
            &body,
            |m| {
                let [i, j] = body.members[m].nodes;
                member_block(&body.nodes[i], &body.nodes[j], k_of(m))
            },
            &mut values,
        );
        // Dense Eq. 3–4 assembly, then the free partition of Eq. 5.
        let nd = body.dof_count();
        let mut full = DMatrix::zeros(nd, nd);
        for (m, mem) in body.members.iter().enumerate() {
            let [i, j] = mem.nodes;
            let e =
                member_stiffness_matrix(Dimension::Three, &body.nodes[i], &body.nodes[j], k_of(m));
            let map = [3 * i, 3 * i + 1, 3 * i + 2, 3 * j, 3 * j + 1, 3 * j + 2];
            for r in 0..6 {
                for c in 0..6 {
                    full[(map[r], map[c])] += e[(r, c)];
                }
            }
        }
        let kff = DMatrix::from_fn(a.n, a.n, |r, c| full[(dofs.free[r], dofs.free[c])]);
        let sparse = dense_ff(&a, &values);
        assert!((&sparse - &kff).abs().max() < 1e-12);
        // K is symmetric.
        assert!((&full - full.transpose()).abs().max() < 1e-12);
        // Rows sorted within columns, diagonal first.
        for c in 0..a.n {
            let rows = &a.row_idx[a.col_ptr[c]..a.col_ptr[c + 1]];
            assert_eq!(rows[0], c);
            assert!(rows.windows(2).all(|w| w[0] < w[1]));
        }
        // multiply agrees with the dense matrix.
        let x: Vec<Real> = (0..a.n).map(|i| (i as Real * 0.37).sin()).collect();
        let mut y = vec![0.0; a.n];
        a.multiply(&values, &x, &mut y);
        let yd = &kff * nalgebra::DVector::from_vec(x);
        for i in 0..a.n {
            assert!((y[i] - yd[i]).abs() < 1e-12);
        }
    }
}
