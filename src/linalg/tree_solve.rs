//! Triangular solves that walk a supernodal factor `A = Pᵀ L Lᵀ P` (faer's storage, as
//! [`SparseCholesky`] keeps it), for the rank-one updates of a kept factor
//! ([`FactorLowRankUpdate`](super::FactorLowRankUpdate)):
//!
//! - a forward solve `L z = P b` for a right-hand side with a few nonzeros (a member's two
//!   nodes), over the supernodes on the paths from those rows to the root of the elimination
//!   tree only: `z` is zero everywhere else (Gilbert–Peierls), so it costs a few percent of a
//!   full forward solve on a 3D lattice;
//! - a backward solve `Lᵀ x = y` that runs independent subtrees side by side: a supernode
//!   reads only its ancestors' entries of `x`, final before it starts, and writes only its
//!   own, so once a separator is solved its children's subtrees are independent.
//!
//! Every supernode's arithmetic is the same fixed sequence of loops whichever thread runs it
//! and however the subtrees are scheduled (partial sums in a fixed order, no sum across
//! threads), so results are bitwise the same on one thread and on many.

use super::tree_cholesky::{children_lists, SupernodeArrays, MIN_TREE_DOFS};
use super::SparseCholesky;
use crate::Real;
use rayon::prelude::*;

const NONE: usize = usize::MAX;

/// Deepest nesting of subtrees handed to other threads; below it a subtree is solved in one
/// piece (the results are the same either way; this only bounds the recursion).
const MAX_SPLIT_DEPTH: usize = 24;

/// Fewest factor entries in a subtree worth a task of its own in the backward solve.
const MIN_SPLIT_ENTRIES: f64 = 2e5;

/// A column of `L⁻¹ P b` for a sparse `b`: its nonzero rows in the factor's (permuted) order,
/// ascending, and their values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FactorColumn {
    /// Rows in the permuted order, ascending.
    pub rows: Vec<usize>,
    /// Values at those rows.
    pub values: Vec<Real>,
}

impl FactorColumn {
    /// `Σ self[i] x[i]` with `x` dense in the permuted order.
    pub fn dot_dense(&self, x: &[Real]) -> Real {
        let mut acc = [0.0; 4];
        let (r4, v4) = (self.rows.chunks_exact(4), self.values.chunks_exact(4));
        let (rr, vr) = (r4.remainder(), v4.remainder());
        for (r, v) in r4.zip(v4) {
            for k in 0..4 {
                acc[k] += v[k] * x[r[k]];
            }
        }
        let tail: Real = rr.iter().zip(vr).map(|(&r, &v)| v * x[r]).sum();
        (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
    }

    /// `x += a self`, `x` dense in the permuted order.
    pub fn add_to(&self, a: Real, x: &mut [Real]) {
        for (&r, &v) in self.rows.iter().zip(&self.values) {
            x[r] += a * v;
        }
    }
}

/// `Σ a[i] b[i]` in eight interleaved partial sums added in a fixed order: vectorizable with
/// independent chains of additions, and the same bits on every machine and thread.
pub(crate) fn dot8(a: &[Real], b: &[Real]) -> Real {
    let mut acc = [0.0; 8];
    let (a8, b8) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ar, br) = (a8.remainder(), b8.remainder());
    for (x, y) in a8.zip(b8) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let tail: Real = ar.iter().zip(br).map(|(x, y)| x * y).sum();
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail
}

/// Four dot products `aⱼ · b` at once (each `aⱼ` at least as long as `b`), each in four
/// interleaved partial sums added in a fixed order: four streams of the factor in flight at
/// a time, which a single dot product leaves waiting on memory.
fn dots4(a: [&[Real]; 4], b: &[Real]) -> [Real; 4] {
    let n = b.len();
    let [a0, a1, a2, a3] = a.map(|x| &x[..n]);
    let mut acc = [[0.0; 4]; 4];
    let chunks = a0
        .chunks_exact(4)
        .zip(a1.chunks_exact(4))
        .zip(a2.chunks_exact(4).zip(a3.chunks_exact(4)))
        .zip(b.chunks_exact(4));
    for (((c0, c1), (c2, c3)), y) in chunks {
        for k in 0..4 {
            acc[0][k] += c0[k] * y[k];
            acc[1][k] += c1[k] * y[k];
            acc[2][k] += c2[k] * y[k];
            acc[3][k] += c3[k] * y[k];
        }
    }
    let tail = n - n % 4;
    let mut out = [0.0; 4];
    for (j, (o, col)) in out.iter_mut().zip([a0, a1, a2, a3]).enumerate() {
        let rest: Real = col[tail..].iter().zip(&b[tail..]).map(|(x, y)| x * y).sum();
        *o = (acc[j][0] + acc[j][1]) + (acc[j][2] + acc[j][3]) + rest;
    }
    out
}

/// The supernodal structure of a factor, built once per symbolic analysis, and the solves
/// that walk it (see the module documentation). The factor's values are passed to each solve.
#[derive(Debug)]
pub struct SupernodalSolver {
    n: usize,
    /// First column of each supernode, and `n` at the end.
    begin: Vec<usize>,
    /// Rows below each supernode's diagonal block.
    pattern_ptr: Vec<usize>,
    pattern: Vec<usize>,
    /// Start of each supernode's values, and the length at the end.
    val_ptr: Vec<usize>,
    /// The supernode of each (permuted) column.
    super_of: Vec<usize>,
    /// Parent supernode, `NONE` for a root.
    parent: Vec<usize>,
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// `inv[old] = new`.
    inv: Vec<usize>,
    /// Smallest supernode of each subtree when every subtree is contiguous (postorder), so
    /// that the backward solve can split them; `None` otherwise.
    first: Option<Vec<usize>>,
    children_ptr: Vec<usize>,
    children: Vec<usize>,
    roots: Vec<usize>,
    /// Factor entries of each subtree.
    entries: Vec<f64>,
    /// Subtrees with more entries than this are split among threads.
    split_entries: f64,
}

/// Scratch of the sparse forward solve: supernodes met, and the updates of one supernode.
#[derive(Debug, Default)]
pub struct ReachWork {
    mark: Vec<bool>,
    reach: Vec<usize>,
    below: Vec<Real>,
}

impl SupernodalSolver {
    /// The solver for `chol`'s factor when it is supernodal and has at least 20,000 rows
    /// (`MIN_TREE_DOFS`, as for the tree-parallel factorization: smaller bodies keep faer's
    /// solves and their exact results).
    pub fn new(chol: &SparseCholesky) -> Option<Self> {
        let arrays = chol.supernode_arrays()?;
        if arrays.n() < MIN_TREE_DOFS {
            return None;
        }
        Self::from_arrays(arrays, chol.permutation().to_vec())
    }

    /// The solver for the supernodes `arrays` of a factor of `P A Pᵀ`, `perm[new] = old`;
    /// `None` when a supernode's parent comes before it.
    pub(crate) fn from_arrays(arrays: SupernodeArrays, perm: Vec<usize>) -> Option<Self> {
        let n = arrays.n();
        let ns = arrays.len();
        let SupernodeArrays {
            begin,
            pattern_ptr,
            pattern,
            val_ptr,
            super_of,
        } = arrays;
        let parent: Vec<usize> = (0..ns)
            .map(|k| {
                pattern[pattern_ptr[k]..pattern_ptr[k + 1]]
                    .first()
                    .map_or(NONE, |&r| super_of[r])
            })
            .collect();
        let mut inv = vec![0usize; n];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        // Subtree sizes and entries; postorder when every subtree ends at its root.
        let mut first: Vec<usize> = (0..ns).collect();
        let mut size = vec![1usize; ns];
        let mut entries = vec![0.0; ns];
        let mut postordered = true;
        for k in 0..ns {
            entries[k] += (val_ptr[k + 1] - val_ptr[k]) as f64;
            postordered &= k + 1 == first[k] + size[k];
            let p = parent[k];
            if p != NONE {
                if p <= k {
                    return None;
                }
                first[p] = first[p].min(first[k]);
                size[p] += size[k];
                entries[p] += entries[k];
            }
        }
        let (children_ptr, children) =
            children_lists(parent.iter().map(|&p| (p != NONE).then_some(p)));
        let roots: Vec<usize> = (0..ns).filter(|&k| parent[k] == NONE).collect();
        let total: f64 = roots.iter().map(|&r| entries[r]).sum();
        Some(SupernodalSolver {
            n,
            begin,
            pattern_ptr,
            pattern,
            val_ptr,
            super_of,
            parent,
            perm,
            inv,
            first: postordered.then_some(first),
            children_ptr,
            children,
            roots,
            entries,
            split_entries: (total / 64.0).max(MIN_SPLIT_ENTRIES),
        })
    }

    /// Rows of the factor.
    pub fn n(&self) -> usize {
        self.n
    }

    /// `perm[new] = old`: the original row of each row of the factor.
    pub fn permutation(&self) -> &[usize] {
        &self.perm
    }

    /// The factor's row of original row `old`.
    pub fn permuted(&self, old: usize) -> usize {
        self.inv[old]
    }

    /// Whether the backward solve can run subtrees side by side (the ordering is a postorder).
    pub fn splits_subtrees(&self) -> bool {
        self.first.is_some()
    }

    fn pattern(&self, k: usize) -> &[usize] {
        &self.pattern[self.pattern_ptr[k]..self.pattern_ptr[k + 1]]
    }

    fn children(&self, k: usize) -> &[usize] {
        &self.children[self.children_ptr[k]..self.children_ptr[k + 1]]
    }

    /// Forward-solves supernode `k` from its column `c0` on (the ones before are zero):
    /// `x` dense in the permuted order, its entries below `k` updated.
    fn forward_supernode(
        &self,
        k: usize,
        c0: usize,
        l: &[f64],
        x: &mut [Real],
        below: &mut Vec<Real>,
    ) {
        self.forward_block(k, c0, l, x, 0, below);
        for (&r, &b) in self.pattern(k).iter().zip(below.iter()) {
            x[r] -= b;
        }
    }

    /// `z = L⁻¹ P b` for the sparse `b` (original rows, values; rows may repeat), `l` the
    /// factor's values. `x` (length n, the permuted order) must be zero on entry; it holds `z`
    /// on return, which is also returned as a column (its nonzero supernodes' rows only).
    pub fn forward_sparse(
        &self,
        l: &[f64],
        b: &[(usize, Real)],
        x: &mut [Real],
        work: &mut ReachWork,
    ) -> FactorColumn {
        let ns = self.begin.len() - 1;
        work.mark.resize(ns, false);
        work.reach.clear();
        for &(i, v) in b {
            let row = self.inv[i];
            x[row] += v;
            let mut k = self.super_of[row];
            while k != NONE && !work.mark[k] {
                work.mark[k] = true;
                work.reach.push(k);
                k = self.parent[k];
            }
        }
        for &k in &work.reach {
            work.mark[k] = false;
        }
        // A parent comes after its children, so ascending order is an order of elimination.
        work.reach.sort_unstable();
        let mut z = FactorColumn::default();
        for &k in &work.reach {
            let (sb, se) = (self.begin[k], self.begin[k + 1]);
            let Some(c0) = x[sb..se].iter().position(|&v| v != 0.0) else {
                continue;
            };
            self.forward_supernode(k, c0, l, x, &mut work.below);
            z.rows.extend(sb + c0..se);
            z.values.extend_from_slice(&x[sb + c0..se]);
        }
        z
    }

    /// `x ← L⁻¹ x`, `x` dense in the permuted order (all supernodes, one thread).
    pub fn forward_dense(&self, l: &[f64], x: &mut [Real], work: &mut ReachWork) {
        for k in 0..self.begin.len() - 1 {
            let (sb, se) = (self.begin[k], self.begin[k + 1]);
            if let Some(c0) = x[sb..se].iter().position(|&v| v != 0.0) {
                self.forward_supernode(k, c0, l, x, &mut work.below);
            }
        }
    }

    /// `x ← L⁻¹ x`, `x` dense in the permuted order, independent subtrees side by side (falls
    /// back to [`forward_dense`](Self::forward_dense) when the ordering is not a postorder).
    ///
    /// A subtree's updates of the rows after it (its root's pattern, as for every supernode
    /// in it) are summed in a buffer of its own and subtracted once its siblings are done, in
    /// the order of the children. Which subtrees are split depends on the structure only, so
    /// the result has the same bits on any number of threads (not those of `forward_dense`).
    pub fn forward(&self, l: &[f64], x: &mut [Real], work: &mut ReachWork) {
        assert_eq!(
            x.len(),
            self.n,
            "forward solve of a vector of the wrong length"
        );
        let Some(first) = &self.first else {
            return self.forward_dense(l, x, work);
        };
        let mut parts = Vec::with_capacity(self.roots.len());
        let mut rest = x;
        for &r in &self.roots {
            let lo = self.begin[first[r]];
            let (part, tail) = rest.split_at_mut(self.begin[r + 1] - lo);
            parts.push((r, lo, part));
            rest = tail;
        }
        // A root's pattern is empty: nothing leaves its subtree.
        parts.into_par_iter().for_each(|(r, lo, part)| {
            self.forward_subtree(r, l, part, lo, &mut [], &mut Vec::new(), 0)
        });
    }

    /// Forward-solves the subtree of `k`, whose columns `local` holds (from column `lo` on);
    /// the updates of rows after the subtree are added to `out` (one entry per row of `k`'s
    /// pattern).
    #[allow(clippy::too_many_arguments)]
    fn forward_subtree(
        &self,
        k: usize,
        l: &[f64],
        local: &mut [Real],
        lo: usize,
        out: &mut [Real],
        below: &mut Vec<Real>,
        depth: usize,
    ) {
        let Some(first) = &self.first else {
            return;
        };
        let outside = self.pattern(k);
        let mut chain_start = first[k];
        if depth < MAX_SPLIT_DEPTH && self.entries[k] > self.split_entries {
            let mut fork = k;
            while let [only] = self.children(fork) {
                fork = *only;
            }
            let children = self.children(fork);
            if !children.is_empty() {
                let (lower, _) = local.split_at_mut(self.begin[fork] - lo);
                let mut parts = Vec::with_capacity(children.len());
                let mut rest = lower;
                for &c in children {
                    let start = self.begin[first[c]];
                    let (part, tail) = rest.split_at_mut(self.begin[c + 1] - start);
                    parts.push((c, start, part, vec![0.0; self.pattern(c).len()]));
                    rest = tail;
                }
                parts.par_iter_mut().for_each(|(c, start, part, buf)| {
                    self.forward_subtree(*c, l, part, *start, buf, &mut Vec::new(), depth + 1)
                });
                let sums: Vec<(usize, Vec<Real>)> =
                    parts.into_iter().map(|(c, _, _, buf)| (c, buf)).collect();
                for (c, buf) in &sums {
                    self.scatter_out(self.pattern(*c), buf, local, lo, outside, out);
                }
                chain_start = fork;
            }
        }
        for s in chain_start..=k {
            self.forward_block(s, 0, l, local, lo, below);
            let pat = self.pattern(s);
            self.scatter_out(pat, below, local, lo, outside, out);
        }
    }

    /// Subtracts `values` (at the ascending rows `rows`) from `local` (rows from `lo` on)
    /// where the rows fall in it, and adds them to `out` (at the places of `outside`, the
    /// ascending rows after `local`, which hold every other row) elsewhere.
    fn scatter_out(
        &self,
        rows: &[usize],
        values: &[Real],
        local: &mut [Real],
        lo: usize,
        outside: &[usize],
        out: &mut [Real],
    ) {
        let hi = lo + local.len();
        let split = rows.partition_point(|&r| r < hi);
        for (&r, &v) in rows[..split].iter().zip(values) {
            local[r - lo] -= v;
        }
        let mut j = 0;
        for (&r, &v) in rows[split..].iter().zip(&values[split..]) {
            while outside[j] != r {
                j += 1;
            }
            out[j] += v;
        }
    }

    /// The forward solve of supernode `k`'s own columns from its column `c0` on (the ones
    /// before are zero) in `local` (rows from `lo` on), and in `below` the products of its
    /// rows below them with those columns.
    fn forward_block(
        &self,
        k: usize,
        c0: usize,
        l: &[f64],
        local: &mut [Real],
        lo: usize,
        below: &mut Vec<Real>,
    ) {
        let (sb, se) = (self.begin[k], self.begin[k + 1]);
        let w = se - sb;
        let pat = self.pattern(k);
        let rows = w + pat.len();
        let block = &l[self.val_ptr[k]..self.val_ptr[k + 1]];
        below.clear();
        below.resize(pat.len(), 0.0);
        let top = &mut local[sb - lo..se - lo];
        for c in c0..w {
            let col = &block[c * rows..(c + 1) * rows];
            let xc = top[c] / col[c];
            top[c] = xc;
            if xc == 0.0 {
                continue;
            }
            for (xi, &v) in top[c + 1..].iter_mut().zip(&col[c + 1..w]) {
                *xi -= v * xc;
            }
            for (bi, &v) in below.iter_mut().zip(&col[w..]) {
                *bi += v * xc;
            }
        }
    }

    /// `x ← L⁻ᵀ x`, `x` dense in the permuted order, independent subtrees side by side.
    pub fn backward(&self, l: &[f64], x: &mut [Real]) {
        assert_eq!(
            x.len(),
            self.n,
            "backward solve of a vector of the wrong length"
        );
        match &self.first {
            Some(first) => {
                let mut parts = Vec::with_capacity(self.roots.len());
                let mut rest = x;
                for &r in &self.roots {
                    let lo = self.begin[first[r]];
                    let (part, tail) = rest.split_at_mut(self.begin[r + 1] - lo);
                    parts.push((r, lo, part));
                    rest = tail;
                }
                parts.into_par_iter().for_each(|(r, lo, part)| {
                    self.backward_subtree(r, l, part, lo, &Above::default(), 0)
                });
            }
            None => {
                let above = Above::default();
                for k in (0..self.begin.len() - 1).rev() {
                    self.backward_supernode(k, l, x, 0, &above, &mut Vec::new());
                }
            }
        }
    }

    /// Backward-solves the subtree of `k`, whose columns `local` holds (from column `lo` on);
    /// `above` holds the final entries of every row after them.
    fn backward_subtree(
        &self,
        k: usize,
        l: &[f64],
        local: &mut [Real],
        lo: usize,
        above: &Above,
        depth: usize,
    ) {
        let Some(first) = &self.first else {
            return;
        };
        let mut gathered = Vec::new();
        if depth < MAX_SPLIT_DEPTH && self.entries[k] > self.split_entries {
            // Down the chain of single children (postorder: the only child of `s` is
            // `s − 1`) to the first supernode with several, whose subtrees are independent.
            let mut fork = k;
            loop {
                self.backward_supernode(fork, l, local, lo, above, &mut gathered);
                match self.children(fork) {
                    [only] => fork = *only,
                    _ => break,
                }
            }
            let children = self.children(fork);
            if children.is_empty() {
                return;
            }
            let (below, solved) = local.split_at_mut(self.begin[fork] - lo);
            let above = above.with(self.begin[fork], solved);
            let mut parts = Vec::with_capacity(children.len());
            let mut rest = below;
            for &c in children {
                let start = self.begin[first[c]];
                let (part, tail) = rest.split_at_mut(self.begin[c + 1] - start);
                parts.push((c, start, part));
                rest = tail;
            }
            parts.into_par_iter().for_each(|(c, start, part)| {
                self.backward_subtree(c, l, part, start, &above, depth + 1)
            });
        } else {
            for s in (first[k]..=k).rev() {
                self.backward_supernode(s, l, local, lo, above, &mut gathered);
            }
        }
    }

    /// `x_k ← L_kk⁻ᵀ (x_k − L_bkᵀ x_b)` for supernode `k` (b: its rows below), `local` holding
    /// the columns from `lo` on, `above` the rows after `local`.
    fn backward_supernode(
        &self,
        k: usize,
        l: &[f64],
        local: &mut [Real],
        lo: usize,
        above: &Above,
        gathered: &mut Vec<Real>,
    ) {
        let (sb, se) = (self.begin[k], self.begin[k + 1]);
        let w = se - sb;
        let pat = self.pattern(k);
        let rows = w + pat.len();
        let block = &l[self.val_ptr[k]..self.val_ptr[k + 1]];
        above.gather(pat, local, lo, gathered);
        let top = &mut local[sb - lo..se - lo];
        // The rows below first, columns ascending, four at a time.
        let n_below = gathered.len();
        gathered.resize(n_below + w, 0.0);
        let (below, sums) = gathered.split_at_mut(n_below);
        let col = |c: usize| &block[c * rows..(c + 1) * rows];
        let grouped = w - w % 4;
        for c in (0..grouped).step_by(4) {
            let d = dots4([c, c + 1, c + 2, c + 3].map(|j| &col(j)[w..]), below);
            sums[c..c + 4].copy_from_slice(&d);
        }
        for (c, sum) in sums.iter_mut().enumerate().skip(grouped) {
            *sum = dot8(&col(c)[w..], below);
        }
        // Then the diagonal block from its last column back, in groups of four: the part of
        // the four columns' sums below the group at once, then the small triangle.
        let mut end = w;
        while end > 0 {
            let start = end.saturating_sub(4);
            if end - start == 4 {
                let d = dots4(
                    [start, start + 1, start + 2, start + 3].map(|j| &col(j)[end..w]),
                    &top[end..],
                );
                for (s, v) in sums[start..end].iter_mut().zip(d) {
                    *s += v;
                }
            } else {
                for (c, sum) in sums.iter_mut().enumerate().take(end).skip(start) {
                    *sum += dot8(&col(c)[end..w], &top[end..]);
                }
            }
            for c in (start..end).rev() {
                let inside: Real = (c + 1..end).map(|i| col(c)[i] * top[i]).sum();
                top[c] = (top[c] - (sums[c] + inside)) / col(c)[c];
            }
            end = start;
        }
    }
}

/// Final entries of the rows after a subtree: slices of the solution, each from its row on,
/// ascending and together covering every row from the first slice's start to the end.
#[derive(Default)]
struct Above<'a> {
    parts: Vec<(usize, &'a [Real])>,
}

impl<'a> Above<'a> {
    /// These rows with `rows` (from row `start`) in front.
    fn with(&self, start: usize, rows: &'a [Real]) -> Above<'a> {
        let mut parts = Vec::with_capacity(self.parts.len() + 1);
        parts.push((start, rows));
        parts.extend_from_slice(&self.parts);
        Above { parts }
    }

    /// `out[i] = x[rows[i]]` for ascending `rows`, read from `local` (rows from `lo` on) or
    /// from these slices.
    fn gather(&self, rows: &[usize], local: &[Real], lo: usize, out: &mut Vec<Real>) {
        out.clear();
        let hi = lo + local.len();
        let mut part = 0;
        out.extend(rows.iter().map(|&r| {
            if r < hi {
                return local[r - lo];
            }
            while self.parts[part].0 + self.parts[part].1.len() <= r {
                part += 1;
            }
            let (start, values) = self.parts[part];
            values[r - start]
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::cholmod::lattice_system;
    use crate::linalg::cholesky::CholeskyOptions;

    fn max_rel_diff(a: &[Real], b: &[Real]) -> Real {
        let scale = b.iter().fold(0.0 as Real, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0 as Real, |m, (x, y)| m.max((x - y).abs()))
            / scale
    }

    /// On a lattice large enough for the path (21,675 DOFs, postordered for two threads), the
    /// sparse forward solve of a member's six entries followed by the backward solve, and the
    /// dense forward and backward solves, agree with faer's solve to 1e-12; the backward
    /// solve gives the same bits on one thread and on two.
    #[test]
    fn sparse_forward_and_split_backward_solve_like_faer() {
        let (s, _) = lattice_system([16, 16, 25]).unwrap();
        let options = CholeskyOptions {
            threads: 2,
            ..Default::default()
        };
        let mut chol =
            SparseCholesky::analyze_with(s.n, &s.col_ptr, &s.row_idx, s.groups.as_deref(), options)
                .unwrap();
        chol.factorize(&s.values).unwrap();
        let solver = SupernodalSolver::new(&chol).unwrap();
        assert!(solver.splits_subtrees());
        let values = chol.factor_values().unwrap().to_vec();
        let l = &values[..];
        let n = s.n;
        let mut work = ReachWork::default();
        // A member between the DOFs of two neighbouring nodes in the middle of the lattice.
        let (a, b) = (3 * (n / 6), 3 * (n / 6) + 3);
        let g: Vec<(usize, Real)> = vec![
            (a, -0.6),
            (a + 1, -0.8),
            (a + 2, 0.0),
            (b, 0.6),
            (b + 1, 0.8),
            (b + 2, 0.0),
        ];
        let mut x = vec![0.0; n];
        let z = solver.forward_sparse(l, &g, &mut x, &mut work);
        // z is sparse: a small share of the rows.
        assert!(z.rows.len() < n / 4, "{} of {n} rows", z.rows.len());
        assert!(z.rows.windows(2).all(|w| w[0] < w[1]));
        // Outside its rows x is zero, inside it is z.
        let mut dense = vec![0.0; n];
        for (&r, &v) in z.rows.iter().zip(&z.values) {
            dense[r] = v;
        }
        assert_eq!(x, dense);
        // The dense forward solve of the same b gives the same z to rounding.
        let mut y = vec![0.0; n];
        for &(i, v) in &g {
            y[solver.permuted(i)] += v;
        }
        solver.forward_dense(l, &mut y, &mut work);
        assert!(max_rel_diff(&y, &x) < 1e-12);
        // Backward on one thread and on two.
        let run = |threads: usize, mut v: Vec<Real>| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| solver.backward(l, &mut v));
            v
        };
        let one = run(1, x.clone());
        let two = run(2, x);
        assert!(one
            .iter()
            .zip(&two)
            .all(|(p, q)| p.to_bits() == q.to_bits()));
        let mut w = vec![0.0; n];
        for (new, &old) in solver.permutation().iter().enumerate() {
            w[old] = one[new];
        }
        let mut expected = vec![0.0; n];
        for &(i, v) in &g {
            expected[i] += v;
        }
        chol.solve_in_place(&mut expected);
        let d = max_rel_diff(&w, &expected);
        assert!(
            d < 1e-12,
            "sparse forward + backward differ from faer by {d:e}"
        );
        // The split forward solve: the dense one's result to rounding, the same bits on one
        // thread and on two.
        let mut f = vec![0.0; n];
        for (new, &old) in solver.permutation().iter().enumerate() {
            f[new] = s.rhs[old];
        }
        let forward = |threads: usize, mut v: Vec<Real>| {
            let mut work = ReachWork::default();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| solver.forward(l, &mut v, &mut work));
            v
        };
        let (one, two) = (forward(1, f.clone()), forward(2, f.clone()));
        assert!(one
            .iter()
            .zip(&two)
            .all(|(p, q)| p.to_bits() == q.to_bits()));
        solver.forward_dense(l, &mut f, &mut work);
        let d = max_rel_diff(&two, &f);
        assert!(d < 1e-12, "split forward differs from dense by {d:e}");
        // A full right-hand side: dense forward, backward.
        let mut f = vec![0.0; n];
        for (new, &old) in solver.permutation().iter().enumerate() {
            f[new] = s.rhs[old];
        }
        solver.forward_dense(l, &mut f, &mut work);
        solver.backward(l, &mut f);
        let mut u = vec![0.0; n];
        for (new, &old) in solver.permutation().iter().enumerate() {
            u[old] = f[new];
        }
        let mut expected = s.rhs.clone();
        chol.solve_in_place(&mut expected);
        let d = max_rel_diff(&u, &expected);
        assert!(
            d < 1e-12,
            "dense forward + backward differ from faer by {d:e}"
        );
    }
}
