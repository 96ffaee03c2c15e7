//! Numeric supernodal LLᵀ that works on independent subtrees of the elimination tree at once.
//!
//! faer 0.24's supernodal factorization visits the supernodes one after another and hands
//! its parallelism to the dense kernels only, which pays for the large separators at the top
//! of a nested-dissection tree but leaves one core idle (or spinning at a barrier) through
//! the many small supernodes below them. Nested dissection makes the two halves of every
//! separator independent: here subtrees with enough work are factored side by side (rayon),
//! each with sequential kernels, and the separators above them with faer's parallel kernels.
//! The factor is written in faer's own storage, so faer's solve reads it unchanged.
//!
//! The algorithm is faer's left-looking one: a supernode gathers the updates of the
//! descendants whose rows meet its columns, then factors its diagonal block and solves for
//! the rows below it. Only the dense update product is formed apart and subtracted, so the
//! factor agrees with faer's to rounding (not bit for bit).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch, LltError};
use faer::linalg::matmul::matmul;
use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::{Accum, MatMut, MatRef, Par};
use rayon::prelude::*;

/// Below this many flops of factorization work the tree plan is not built: faer's own
/// sequential loop is as fast, and small bodies keep its exact results.
pub(crate) const MIN_TREE_WORK: f64 = 2e8;

/// Narrowest column block of a supernode whose updates are shared between threads.
const MIN_BLOCK_COLUMNS: usize = 16;

/// Fewest rows of a row block of the solve below a supernode's diagonal block, when that
/// solve is split into rayon tasks.
const MIN_BLOCK_ROWS: usize = 64;

/// Fewest columns of an update product whose square part is formed as a lower triangle only
/// (below it the full square costs less than the triangular product's blocking).
const MIN_TRIANGULAR_PRODUCT: usize = 16;

/// Fewest DOFs for which [`postorder`] is applied to a nested-dissection ordering, so that
/// the tree plan can be used; smaller bodies keep their ordering (and their exact results).
pub(crate) const MIN_TREE_DOFS: usize = 20_000;

/// `perm` (`perm[new] = old`) followed by a postorder of the elimination tree of the permuted
/// matrix (A's lower CSC pattern, original order): the same fill and the same tree, but
/// every subtree's columns (and so its supernodes) contiguous, which faer's analysis of a
/// custom ordering does not ensure. Returns `(perm, inv)`.
pub(crate) fn postorder(
    col_ptr: &[usize],
    row_idx: &[usize],
    perm: &[usize],
    inv: &[usize],
) -> (Vec<usize>, Vec<usize>) {
    let n = perm.len();
    // Each permuted column's rows above the diagonal.
    let mut ptr = vec![0usize; n + 1];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            let (a, b) = (inv[i], inv[j]);
            if a != b {
                ptr[a.max(b) + 1] += 1;
            }
        }
    }
    for k in 0..n {
        ptr[k + 1] += ptr[k];
    }
    let mut next = ptr.clone();
    let mut upper = vec![0usize; ptr[n]];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            let (a, b) = (inv[i], inv[j]);
            if a != b {
                let (lo, hi) = (a.min(b), a.max(b));
                upper[next[hi]] = lo;
                next[hi] += 1;
            }
        }
    }
    // Liu's elimination tree with path compression.
    const NONE: usize = usize::MAX;
    let mut parent = vec![NONE; n];
    let mut ancestor = vec![NONE; n];
    for k in 0..n {
        for &start in &upper[ptr[k]..ptr[k + 1]] {
            let mut i = start;
            while ancestor[i] != NONE && ancestor[i] != k {
                let up = ancestor[i];
                ancestor[i] = k;
                i = up;
            }
            if ancestor[i] == NONE {
                ancestor[i] = k;
                parent[i] = k;
            }
        }
    }
    // Children in ascending order, then a depth-first postorder from the roots.
    let (child_ptr, child) = children_lists(parent.iter().map(|&p| (p != NONE).then_some(p)));
    let mut order = Vec::with_capacity(n);
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for root in (0..n).filter(|&k| parent[k] == NONE) {
        stack.push((root, child_ptr[root]));
        while let Some(top) = stack.last_mut() {
            let (k, c) = *top;
            if c < child_ptr[k + 1] {
                top.1 += 1;
                stack.push((child[c], child_ptr[child[c]]));
            } else {
                order.push(k);
                stack.pop();
            }
        }
    }
    let new_perm: Vec<usize> = order.iter().map(|&k| perm[k]).collect();
    let mut new_inv = vec![0usize; n];
    for (new, &old) in new_perm.iter().enumerate() {
        new_inv[old] = new;
    }
    (new_perm, new_inv)
}

/// The supernodal tree and the maps the parallel factorization needs, built once per pattern.
pub(crate) struct TreePlan {
    n: usize,
    /// First column of each supernode, and `n` at the end.
    begin: Vec<usize>,
    /// Rows below each supernode's diagonal block: `pattern[pattern_ptr[s]..pattern_ptr[s + 1]]`.
    pattern_ptr: Vec<usize>,
    pattern: Vec<usize>,
    /// Start of each supernode's values in the factor, and the length at the end.
    val_ptr: Vec<usize>,
    /// Smallest supernode of each subtree (subtrees are contiguous: postorder).
    first: Vec<usize>,
    children_ptr: Vec<usize>,
    children: Vec<usize>,
    /// Descendants whose rows meet each supernode's columns, ascending.
    updaters_ptr: Vec<usize>,
    updaters: Vec<usize>,
    /// Flops of each subtree.
    work: Vec<f64>,
    roots: Vec<usize>,
    /// The entries of A (its lower CSC, original order) by factor column: those of column
    /// `c` are `scatter_src[scatter_ptr[c]..scatter_ptr[c + 1]]` (their place in A's values),
    /// landing at `scatter_dst[..]` in the factor's values.
    scatter_ptr: Vec<usize>,
    scatter_src: Vec<usize>,
    scatter_dst: Vec<usize>,
    /// Start of each factor column's values (the column's supernode block is column-major),
    /// and the length at the end.
    col_start: Vec<usize>,
    /// Widest supernode, for the dense Cholesky's workspace.
    max_width: usize,
    /// Subtrees with more work than this are split among the threads.
    split_work: f64,
}

/// The children of each node of a forest given by its parents (`None` for a root), in
/// ascending order: node `k`'s are `children[children_ptr[k]..children_ptr[k + 1]]`.
pub(crate) fn children_lists(
    parent: impl ExactSizeIterator<Item = Option<usize>> + Clone,
) -> (Vec<usize>, Vec<usize>) {
    let n = parent.len();
    let mut children_ptr = vec![0usize; n + 1];
    for p in parent.clone().flatten() {
        children_ptr[p + 1] += 1;
    }
    for k in 0..n {
        children_ptr[k + 1] += children_ptr[k];
    }
    let mut fill = children_ptr.clone();
    let mut children = vec![0usize; children_ptr[n]];
    for (k, p) in parent.enumerate() {
        if let Some(p) = p {
            children[fill[p]] = k;
            fill[p] += 1;
        }
    }
    (children_ptr, children)
}

/// The supernodes of a supernodal symbolic factor as plain arrays, shared by the tree
/// factorization and the tree solves: read from faer's analysis ([`SupernodeArrays::new`]) or
/// built from the node graph ([`node_symbolic`](super::node_symbolic)).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SupernodeArrays {
    /// First column of each supernode, and `n` at the end.
    pub begin: Vec<usize>,
    /// Supernode `k`'s rows below its columns are `pattern[pattern_ptr[k]..pattern_ptr[k + 1]]`.
    pub pattern_ptr: Vec<usize>,
    pub pattern: Vec<usize>,
    /// Start of each supernode's values in the factor, and their length at the end.
    pub val_ptr: Vec<usize>,
    /// The supernode of each column.
    pub super_of: Vec<usize>,
}

impl SupernodeArrays {
    /// The arrays of `s`.
    pub(crate) fn new(s: &SymbolicSupernodalCholesky<usize>) -> Self {
        let n = s.nrows();
        let ns = s.n_supernodes();
        let begin: Vec<usize> = s
            .supernode_begin()
            .iter()
            .copied()
            .chain(std::iter::once(n))
            .collect();
        let mut pattern_ptr = Vec::with_capacity(ns + 1);
        let mut pattern = Vec::new();
        pattern_ptr.push(0);
        for k in 0..ns {
            pattern.extend_from_slice(s.supernode(k).pattern());
            pattern_ptr.push(pattern.len());
        }
        let val_ptr = s.col_ptr_for_val().to_vec();
        let mut super_of = vec![0usize; n];
        for k in 0..ns {
            super_of[begin[k]..begin[k + 1]].fill(k);
        }
        SupernodeArrays {
            begin,
            pattern_ptr,
            pattern,
            val_ptr,
            super_of,
        }
    }

    /// Columns (rows) of the factor.
    pub(crate) fn n(&self) -> usize {
        self.begin.last().copied().unwrap_or(0)
    }

    /// Number of supernodes.
    pub(crate) fn len(&self) -> usize {
        self.begin.len().saturating_sub(1)
    }

    /// Rows of supernode `k` below its diagonal block.
    pub(crate) fn pattern(&self, k: usize) -> &[usize] {
        &self.pattern[self.pattern_ptr[k]..self.pattern_ptr[k + 1]]
    }

    /// Entries of L's lower triangle, diagonal included (a supernode's zeros counted).
    pub(crate) fn nnz(&self) -> usize {
        (0..self.len())
            .map(|k| {
                let w = self.begin[k + 1] - self.begin[k];
                w * (w + 1) / 2 + w * self.pattern(k).len()
            })
            .sum()
    }

    /// Flops of the factorization: w³/3 + w²p + wp² per supernode (w columns, p rows below).
    pub(crate) fn flops(&self) -> f64 {
        (0..self.len())
            .map(|k| {
                let w = (self.begin[k + 1] - self.begin[k]) as f64;
                let p = self.pattern(k).len() as f64;
                w * w * w / 3.0 + w * w * p + w * p * p
            })
            .sum()
    }

    /// Position of each diagonal entry L_jj in the factor's values (supernode blocks are
    /// column-major, their square diagonal block on top).
    pub(crate) fn diagonal_positions(&self) -> Vec<usize> {
        let mut pos = Vec::with_capacity(self.n());
        for k in 0..self.len() {
            let w = self.begin[k + 1] - self.begin[k];
            let rows = w + self.pattern(k).len();
            pos.extend((0..w).map(|c| self.val_ptr[k] + c * rows + c));
        }
        pos
    }
}

/// Per-task workspace.
struct Scratch {
    /// Row → its place in the current supernode's block.
    local: Vec<usize>,
    /// Buffers of the updates.
    work: UpdateWork,
    mem: MemBuffer,
}

impl TreePlan {
    /// The plan for the supernodes `arrays` with A's lower pattern (`col_ptr`, `row_idx`,
    /// original order) and the permutation `inv[old] = new` of the symbolic analysis. `None`
    /// when the supernodes are not in postorder, an entry of A falls outside the structure or
    /// the work is too small to gain from it.
    pub(crate) fn new(
        arrays: SupernodeArrays,
        col_ptr: &[usize],
        row_idx: &[usize],
        inv: &[usize],
    ) -> Option<Self> {
        let n = arrays.n();
        let ns = arrays.len();
        let SupernodeArrays {
            begin,
            pattern_ptr,
            pattern,
            val_ptr,
            super_of,
        } = arrays;
        let pat = |k: usize| &pattern[pattern_ptr[k]..pattern_ptr[k + 1]];

        // Parents, subtree sizes and postorder check.
        let parent: Vec<Option<usize>> = (0..ns)
            .map(|k| pat(k).first().map(|&r| super_of[r]))
            .collect();
        let mut first: Vec<usize> = (0..ns).collect();
        let mut size = vec![1usize; ns];
        let mut work = vec![0.0; ns];
        for k in 0..ns {
            let w = (begin[k + 1] - begin[k]) as f64;
            let rows = w + pat(k).len() as f64;
            work[k] += w * rows * rows;
            if k + 1 != first[k] + size[k] {
                return None;
            }
            if let Some(p) = parent[k] {
                if p <= k {
                    return None;
                }
                first[p] = first[p].min(first[k]);
                size[p] += size[k];
                work[p] += work[k];
            }
        }
        let roots: Vec<usize> = (0..ns).filter(|&k| parent[k].is_none()).collect();
        let total: f64 = roots.iter().map(|&r| work[r]).sum();
        if total < MIN_TREE_WORK {
            return None;
        }
        let (children_ptr, children) = children_lists(parent.iter().copied());

        // Descendant d updates every supernode its rows fall in.
        let mut counts = vec![0usize; ns + 1];
        let mut targets = Vec::new();
        for d in 0..ns {
            let mut last = usize::MAX;
            for &r in pat(d) {
                let t = super_of[r];
                if t != last {
                    targets.push((t, d));
                    counts[t + 1] += 1;
                    last = t;
                }
            }
        }
        for k in 0..ns {
            counts[k + 1] += counts[k];
        }
        let updaters_ptr = counts.clone();
        let mut updaters = vec![0usize; targets.len()];
        // `targets` is ordered by d, so each list comes out ascending.
        for (t, d) in targets {
            updaters[counts[t]] = d;
            counts[t] += 1;
        }

        // Where each entry of A lands in the factor, bucketed by factor column so that
        // assembling A touches the factor in order, column range by column range.
        let mut col_start = Vec::with_capacity(n + 1);
        for k in 0..ns {
            let rows = begin[k + 1] - begin[k] + pat(k).len();
            col_start.extend((0..begin[k + 1] - begin[k]).map(|c| val_ptr[k] + c * rows));
        }
        col_start.push(val_ptr[ns]);
        let mut scatter_ptr = vec![0usize; n + 1];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                scatter_ptr[inv[i].min(inv[j]) + 1] += 1;
            }
        }
        for c in 0..n {
            scatter_ptr[c + 1] += scatter_ptr[c];
        }
        let mut next = scatter_ptr.clone();
        let mut scatter_src = vec![0usize; row_idx.len()];
        // Each entry's factor row first, replaced by its place below.
        let mut scatter_dst = vec![0usize; row_idx.len()];
        for j in 0..n {
            for (p, &i) in row_idx
                .iter()
                .enumerate()
                .take(col_ptr[j + 1])
                .skip(col_ptr[j])
            {
                let (a, b) = (inv[i], inv[j]);
                let (r, c) = if a >= b { (a, b) } else { (b, a) };
                scatter_src[next[c]] = p;
                scatter_dst[next[c]] = r;
                next[c] += 1;
            }
        }
        // Supernode by supernode, a row below the diagonal block is found through a map of
        // the supernode's rows (`owner` marks which supernode set it) instead of a search.
        let mut owner = vec![usize::MAX; n];
        let mut place = vec![0usize; n];
        for k in 0..ns {
            let (b, e) = (begin[k], begin[k + 1]);
            for (i, &r) in pat(k).iter().enumerate() {
                owner[r] = k;
                place[r] = e - b + i;
            }
            for c in b..e {
                for dst in &mut scatter_dst[scatter_ptr[c]..scatter_ptr[c + 1]] {
                    let r = *dst;
                    let local = if r < e {
                        r - b
                    } else if owner[r] == k {
                        place[r]
                    } else {
                        return None;
                    };
                    *dst = col_start[c] + local;
                }
            }
        }
        let max_width = (0..ns).map(|k| begin[k + 1] - begin[k]).max().unwrap_or(0);
        Some(TreePlan {
            n,
            begin,
            pattern_ptr,
            pattern,
            val_ptr,
            first,
            children_ptr,
            children,
            updaters_ptr,
            updaters,
            work,
            roots,
            scatter_ptr,
            scatter_src,
            scatter_dst,
            col_start,
            max_width,
            split_work: (total / 64.0).max(1e6),
        })
    }

    fn pattern(&self, k: usize) -> &[usize] {
        &self.pattern[self.pattern_ptr[k]..self.pattern_ptr[k + 1]]
    }

    fn children(&self, k: usize) -> &[usize] {
        &self.children[self.children_ptr[k]..self.children_ptr[k + 1]]
    }

    fn scratch(&self) -> Scratch {
        Scratch {
            local: vec![0; self.n],
            work: UpdateWork::default(),
            mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(
                self.max_width,
                Par::Seq,
                Default::default(),
            )),
        }
    }

    /// Factors A (`values` in the layout of its lower CSC pattern) into `l` (faer's
    /// supernodal values). `par`: the kernels' parallelism above the split subtrees. On a
    /// non-positive pivot returns its column in the permuted order (the smallest such
    /// column among the subtrees that failed). `zeroed`: `l` holds only zeros already.
    pub(crate) fn factorize(
        &self,
        values: &[f64],
        l: &mut [f64],
        par: Par,
        zeroed: bool,
    ) -> Result<(), usize> {
        self.assemble(values, l, zeroed);
        // The roots' subtrees tile the supernodes in order.
        let mut parts = Vec::with_capacity(self.roots.len());
        let mut rest = l;
        for &r in &self.roots {
            let len = self.val_ptr[r + 1] - self.val_ptr[self.first[r]];
            let (part, tail) = rest.split_at_mut(len);
            parts.push((r, part));
            rest = tail;
        }
        let threads = match par {
            Par::Seq => 1,
            Par::Rayon(t) => t.get(),
        };
        if threads > 1 && parts.len() > 1 {
            let errors: Vec<Result<(), usize>> = parts
                .into_par_iter()
                .map(|(r, part)| self.subtree(r, part, &mut self.scratch(), par, threads))
                .collect();
            errors.into_iter().min_by_key(|e| e.err()).unwrap_or(Ok(()))
        } else {
            let mut scratch = self.scratch();
            for (r, part) in parts {
                self.subtree(r, part, &mut scratch, par, threads)?;
            }
            Ok(())
        }
    }

    /// Zeros the factor (unless `zeroed`: it holds only zeros) and adds A's entries to their
    /// places, in ranges of factor columns side by side.
    fn assemble(&self, values: &[f64], l: &mut [f64], zeroed: bool) {
        const PIECES: usize = 64;
        let len = l.len();
        let mut parts = Vec::with_capacity(PIECES);
        let mut rest = l;
        let mut c0 = 0;
        for piece in 1..=PIECES {
            // Columns up to about piece/PIECES of the values.
            let c1 = if piece == PIECES {
                self.n
            } else {
                self.col_start
                    .partition_point(|&s| s * PIECES < len * piece)
                    .clamp(c0, self.n)
            };
            let (part, tail) = rest.split_at_mut(self.col_start[c1] - self.col_start[c0]);
            parts.push((c0, c1, part));
            rest = tail;
            c0 = c1;
        }
        parts.into_par_iter().for_each(|(c0, c1, part)| {
            if !zeroed {
                part.fill(0.0);
            }
            let base = self.col_start[c0];
            let entries = self.scatter_ptr[c0]..self.scatter_ptr[c1];
            for (&p, &d) in self.scatter_src[entries.clone()]
                .iter()
                .zip(&self.scatter_dst[entries])
            {
                part[d - base] += values[p];
            }
        });
    }

    /// Factors the subtree of `k`, whose values are `l` (from its first supernode on).
    /// `tasks`: the threads of the pool; above 1, subtrees may be handed to other threads,
    /// and the chains above their forks split their work into tasks.
    fn subtree(
        &self,
        k: usize,
        l: &mut [f64],
        scratch: &mut Scratch,
        par: Par,
        tasks: usize,
    ) -> Result<(), usize> {
        let split = tasks > 1;
        let base = self.val_ptr[self.first[k]];
        if split && self.work[k] > self.split_work {
            // A separator split into several supernodes is a chain of single children
            // (postorder: the only child of `s` is `s - 1`); the independent subtrees start
            // below the first supernode with more than one child.
            let mut fork = k;
            while let [only] = self.children(fork) {
                fork = *only;
            }
            let children = self.children(fork);
            if children.len() > 1 {
                let (below, _) = l.split_at_mut(self.val_ptr[fork] - base);
                let mut parts = Vec::with_capacity(children.len());
                let mut rest = below;
                for &c in children {
                    let len = self.val_ptr[c + 1] - self.val_ptr[self.first[c]];
                    let (part, tail) = rest.split_at_mut(len);
                    parts.push((c, part));
                    rest = tail;
                }
                let results: Vec<Result<(), usize>> = parts
                    .into_par_iter()
                    .map(|(c, part)| {
                        let mut own = self.scratch();
                        self.subtree(c, part, &mut own, Par::Seq, tasks)
                    })
                    .collect();
                if let Some(e) = results.into_iter().filter_map(Result::err).min() {
                    return Err(e);
                }
                // The chain from the fork up to `k`, each with the shared kernels (at the top)
                // or sequential kernels in tasks that an idle thread can take: below the top,
                // the two halves' chains differ in work (the root separator is merged with
                // one of them), and the thread done first would otherwise wait.
                for s in fork..=k {
                    self.supernode(s, l, base, scratch, par, tasks)?;
                }
                return Ok(());
            }
        }
        let kernels = if split { Par::Seq } else { par };
        for s in self.first[k]..=k {
            // Only the separators at the top of an unsplit tree are big enough to share.
            let p = if s == k { par } else { kernels };
            self.supernode(s, l, base, scratch, p, 1)?;
        }
        Ok(())
    }

    /// Updates supernode `k` by its descendants, factors its diagonal block and solves for
    /// its rows below. `l` holds the values from offset `base` up to and including `k`'s.
    ///
    /// With several threads (`par`, or `tasks` for rayon tasks with sequential kernels) and
    /// a wide supernode, the descendants' updates are applied to column blocks of `k` side
    /// by side, each block by one thread with sequential products: the updates of a
    /// separator come from hundreds of small descendants, and sharing each small product
    /// between threads cost a barrier each. With sequential kernels and several `tasks`,
    /// the solve for the rows below is split into row blocks likewise.
    fn supernode(
        &self,
        k: usize,
        l: &mut [f64],
        base: usize,
        scratch: &mut Scratch,
        par: Par,
        tasks: usize,
    ) -> Result<(), usize> {
        let (sb, se) = (self.begin[k], self.begin[k + 1]);
        let w = se - sb;
        let pat = self.pattern(k);
        let rows = w + pat.len();
        for (i, &r) in pat.iter().enumerate() {
            scratch.local[r] = w + i;
        }
        let (head, own) = l.split_at_mut(self.val_ptr[k] - base);
        let own = &mut own[..self.val_ptr[k + 1] - self.val_ptr[k]];
        let head = &*head;
        let updaters = &self.updaters[self.updaters_ptr[k]..self.updaters_ptr[k + 1]];
        let threads = match par {
            Par::Seq => tasks,
            Par::Rayon(t) => t.get().max(tasks),
        };
        let blocks = (4 * threads).min(w / MIN_BLOCK_COLUMNS);
        if threads > 1 && blocks > 1 && !updaters.is_empty() {
            // Column c holds rows − c entries of the lower triangle; blocks of about equal
            // entries balance the update work.
            let total = w * rows - w * (w - 1) / 2;
            let mut bounds = vec![0];
            let mut sum = 0;
            for c in 0..w {
                sum += rows - c;
                if sum * blocks >= total * bounds.len() && bounds.len() < blocks {
                    bounds.push(c + 1);
                }
            }
            if *bounds.last().unwrap_or(&0) != w {
                bounds.push(w);
            }
            let mut parts = Vec::with_capacity(bounds.len());
            let mut rest = &mut *own;
            for pair in bounds.windows(2) {
                let (part, tail) = rest.split_at_mut((pair[1] - pair[0]) * rows);
                parts.push((pair[0], pair[1], part));
                rest = tail;
            }
            let local = &scratch.local;
            parts.into_par_iter().for_each(|(c0, c1, part)| {
                let mut work = UpdateWork::default();
                self.update_columns(k, head, base, updaters, (c0, c1), local, part, &mut work);
            });
        } else {
            let mut work = std::mem::take(&mut scratch.work);
            self.update_columns(
                k,
                head,
                base,
                updaters,
                (0, w),
                &scratch.local,
                own,
                &mut work,
            );
            scratch.work = work;
        }
        let ls = MatMut::from_column_major_slice_mut(own, rows, w);
        let (mut top, bot) = ls.split_at_row_mut(w);
        match cholesky_in_place(
            top.rb_mut(),
            Default::default(),
            par,
            MemStack::new(&mut scratch.mem),
            Default::default(),
        ) {
            Ok(_) => {}
            Err(LltError::NonPositivePivot { index }) => return Err(sb + index),
        }
        let row_blocks = (4 * tasks).min(pat.len() / MIN_BLOCK_ROWS);
        if matches!(par, Par::Seq) && row_blocks > 1 {
            // Each row of the block below is solved on its own: row blocks side by side,
            // split at fixed places (the same bits whichever thread takes a block).
            let mut parts = Vec::with_capacity(row_blocks);
            let mut rest = bot;
            for b in 0..row_blocks {
                let len = rest.nrows() / (row_blocks - b);
                let (part, tail) = rest.split_at_row_mut(len);
                parts.push(part);
                rest = tail;
            }
            let top = top.rb();
            parts.into_par_iter().for_each(|part| {
                solve_lower_triangular_in_place(top, part.transpose_mut(), Par::Seq);
            });
        } else {
            solve_lower_triangular_in_place(top.rb(), bot.transpose_mut(), par);
        }
        Ok(())
    }

    /// Subtracts from columns `c0..c1` of supernode `k` (`part`, column-major with all of
    /// `k`'s rows) the products of the descendants `updaters` whose rows meet them.
    /// `head` holds the factor's values from offset `base` up to `k`'s; `local` maps a row
    /// below `k`'s diagonal block to its place in `k`'s block.
    #[allow(clippy::too_many_arguments)]
    fn update_columns(
        &self,
        k: usize,
        head: &[f64],
        base: usize,
        updaters: &[usize],
        (c0, c1): (usize, usize),
        local: &[usize],
        part: &mut [f64],
        work: &mut UpdateWork,
    ) {
        let (sb, se) = (self.begin[k], self.begin[k + 1]);
        let rows = (se - sb) + self.pattern(k).len();
        let (lo, hi) = (sb + c0, sb + c1);
        for &d in updaters {
            let dw = self.begin[d + 1] - self.begin[d];
            let dpat = self.pattern(d);
            let p0 = dpat.partition_point(|&r| r < lo);
            let mid = dpat[p0..].partition_point(|&r| r < hi);
            if mid == 0 {
                continue;
            }
            let ld = MatRef::from_column_major_slice(
                &head[self.val_ptr[d] - base..self.val_ptr[d + 1] - base],
                dw + dpat.len(),
                dw,
            );
            let below = dpat.len() - p0;
            let top = ld.subrows(dw + p0, mid);
            work.product.resize(below * mid, 0.0);
            let prod =
                MatMut::from_column_major_slice_mut(&mut work.product[..below * mid], below, mid);
            let (prod_top, prod_bot) = prod.split_at_row_mut(mid);
            // Only the lower triangle of the square part is scattered: computing just it
            // halves the work where a separator's rows fall in this block.
            if mid >= MIN_TRIANGULAR_PRODUCT {
                triangular::matmul(
                    prod_top,
                    BlockStructure::TriangularLower,
                    Accum::Replace,
                    top,
                    BlockStructure::Rectangular,
                    top.transpose(),
                    BlockStructure::Rectangular,
                    1.0,
                    Par::Seq,
                );
            } else {
                matmul(
                    prod_top,
                    Accum::Replace,
                    top,
                    top.transpose(),
                    1.0,
                    Par::Seq,
                );
            }
            if below > mid {
                let rest = ld.subrows(dw + p0 + mid, below - mid);
                matmul(
                    prod_bot,
                    Accum::Replace,
                    rest,
                    top.transpose(),
                    1.0,
                    Par::Seq,
                );
            }
            // Rows of the product in `k`'s block, then each column's lower part scattered.
            let rows_d = &dpat[p0..];
            work.target.clear();
            work.target.extend(
                rows_d
                    .iter()
                    .map(|&r| if r < se { r - sb } else { local[r] }),
            );
            for (j, src) in work.product[..below * mid].chunks_exact(below).enumerate() {
                let dst = &mut part[(rows_d[j] - lo) * rows..][..rows];
                for (&ri, &v) in work.target[j..].iter().zip(&src[j..]) {
                    dst[ri] -= v;
                }
            }
        }
    }
}

/// Buffers of one thread's updates: one product and the rows it lands on.
#[derive(Default)]
struct UpdateWork {
    /// One update product, column-major.
    product: Vec<f64>,
    /// Place in the current supernode's block of each row of the product.
    target: Vec<usize>,
}

#[cfg(test)]
mod tests {
    use crate::bench::cholmod::{lattice_system, relative_residual};
    use crate::linalg::cholesky::{CholeskyError, CholeskyOptions, SparseCholesky};

    fn analyzed(s: &crate::bench::cholmod::LowerSystem, tree: bool) -> SparseCholesky {
        let options = CholeskyOptions {
            threads: 2,
            ..Default::default()
        };
        let analyze = if tree {
            SparseCholesky::analyze_with
        } else {
            SparseCholesky::analyze_with_faers_loop
        };
        analyze(s.n, &s.col_ptr, &s.row_idx, s.groups.as_deref(), options).unwrap()
    }

    #[test]
    fn tree_factor_solves_like_faers_loop() {
        // 16×16×25 cells, 21,675 DOFs: large enough for the tree plan (MIN_TREE_DOFS, MIN_TREE_WORK).
        let (s, _) = lattice_system([16, 16, 25]).unwrap();
        let mut tree = analyzed(&s, true);
        assert!(tree.is_tree_parallel());
        let mut plain = analyzed(&s, false);
        assert!(!plain.is_tree_parallel());
        let (mut x, mut y) = (s.rhs.clone(), s.rhs.clone());
        tree.factorize(&s.values).unwrap();
        plain.factorize(&s.values).unwrap();
        tree.solve_in_place(&mut x);
        plain.solve_in_place(&mut y);
        // faer's own loop reaches about 1e-13 here (cond(K) is large: a slender lattice).
        let (rt, rp) = (relative_residual(&s, &x), relative_residual(&s, &y));
        assert!(
            rt < 1e-12 && rp < 1e-12,
            "residuals {rt:e} (tree), {rp:e} (faer's loop)"
        );
        let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = x
            .iter()
            .zip(&y)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            diff <= 1e-11 * scale,
            "max difference {diff:e} of {scale:e}"
        );
        // Refactoring new values on the same pattern gives the new answer.
        let doubled: Vec<f64> = s.values.iter().map(|v| 2.0 * v).collect();
        tree.factorize(&doubled).unwrap();
        let mut z = s.rhs.clone();
        tree.solve_in_place(&mut z);
        let diff = z
            .iter()
            .zip(&x)
            .fold(0.0f64, |m, (a, b)| m.max((2.0 * a - b).abs()));
        assert!(diff <= 1e-11 * scale, "max difference {diff:e}");
    }

    #[test]
    fn tree_factor_names_a_negative_pivot_by_its_dof() {
        let (mut s, _) = lattice_system([16, 16, 25]).unwrap();
        // A negative diagonal entry fails exactly at its own pivot, in either loop.
        let dof = 1234;
        s.values[s.col_ptr[dof]] = -1.0;
        for tree in [true, false] {
            let mut c = analyzed(&s, tree);
            assert_eq!(c.is_tree_parallel(), tree);
            assert_eq!(
                c.factorize(&s.values),
                Err(CholeskyError::NonPositivePivot { dof }),
                "tree = {tree}"
            );
            assert!(!c.is_factorized());
        }
    }
}
