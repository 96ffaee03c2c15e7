//! Sparse LLᵀ for paper Eq. 9: ordering and symbolic analysis once, numeric factorizations many times.

use std::fmt;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Side};
use rayon::iter::{IndexedParallelIterator, ParallelExtend, ParallelIterator};
use std::sync::atomic::{AtomicBool, Ordering as AtomicOrdering};

use super::node_symbolic::{node_symbolic, NodeSymbolic};
use super::ordering::{
    best_of_two_orderings, expand_to_dofs, factor_entries, graph_of_pattern, nested_dissection,
    nested_dissection_with_trailing, FactorCost, OrderingError, SECOND_ORDERING,
};
use super::trailing_order::postorder_keeping_trailing;
use super::tree_cholesky::{SupernodeArrays, TreePlan, MIN_TREE_DOFS};
use super::tree_solve::{ReachWork, SupernodalSolver};

/// Default smallest accepted pivot ratio `d_j / A_jj` (dimensionless): below it the
/// matrix is treated as singular to working precision.
pub const DEFAULT_PIVOT_TOLERANCE: f64 = 1e-12;

/// Why an analysis, a factorization or its input was rejected.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CholeskyError {
    /// faer met a pivot that is zero, negative or NaN; `dof` is the ORIGINAL
    /// (unpermuted) row/column index.
    #[error(
        "the matrix is not positive definite: non-positive pivot at DOF {dof} \
         (a mechanism, a missing support or a negative stiffness)"
    )]
    NonPositivePivot {
        /// Original row/column index of the failed pivot.
        dof: usize,
    },
    /// The factorization succeeded but a pivot is tiny relative to its diagonal entry,
    /// `d_j / A_jj < pivot_tolerance`: the matrix is singular to working precision (a
    /// mechanism whose zero pivot came out as round-off instead of 0).
    #[error(
        "the matrix is singular to working precision at DOF {dof}: pivot / diagonal = {ratio:.3e} \
         (a mechanism or a missing support)"
    )]
    NearlySingular {
        /// Original row/column index of the smallest ratio.
        dof: usize,
        /// The smallest ratio `d_j / A_jj` found.
        ratio: f64,
    },
    /// Malformed pattern, values of the wrong length, non-finite values or bad groups.
    #[error("invalid input to the sparse Cholesky solver: {0}")]
    InvalidInput(String),
    /// The fill-reducing ordering could not be computed.
    #[error("fill-reducing ordering failed: {0}")]
    Ordering(#[from] OrderingError),
    /// faer's symbolic analysis or a buffer allocation failed (index overflow or out of memory).
    #[error("sparse Cholesky analysis failed: {0}")]
    Resources(String),
}

/// Which fill-reducing ordering [`SparseCholesky::analyze_with`] computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FillOrdering {
    /// METIS nested dissection (of the node graph when groups are given). 2–4× less
    /// work than AMD on 3D lattices.
    #[default]
    NestedDissection,
    /// faer's approximate minimum degree on the DOF graph (groups are ignored).
    Amd,
    /// No reordering (for tests and comparisons).
    Identity,
}

/// Storage of the factor: faer picks from the flop count per nonzero unless forced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FactorLayout {
    /// Let faer choose (simplicial for very sparse factors, supernodal otherwise).
    #[default]
    Auto,
    /// Column by column.
    Simplicial,
    /// Dense blocks of columns with a shared pattern.
    Supernodal,
}

/// Tuning of [`SparseCholesky::analyze_with`]; the default is what
/// [`SparseCholesky::analyze`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CholeskyOptions {
    /// The fill-reducing ordering.
    pub ordering: FillOrdering,
    /// The factor storage.
    pub layout: FactorLayout,
    /// Threads for faer's dense kernels: 0 = the size of rayon's global pool, 1 = sequential.
    pub threads: usize,
}

/// Sizes of the factorization, for printing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CholeskyStats {
    /// Matrix dimension (number of free DOFs).
    pub n: usize,
    /// Stored entries of A's lower triangle, diagonal included.
    pub nnz_a: usize,
    /// Entries of L's lower triangle, diagonal included (supernode padding counted).
    pub nnz_l: usize,
    /// Length of the value buffer of L (a supernode's diagonal block is stored square).
    pub factor_values: usize,
    /// Whether the factor is supernodal (else simplicial).
    pub supernodal: bool,
    /// Number of supernodes (0 when simplicial).
    pub supernodes: usize,
    /// The ordering that was used.
    pub ordering: FillOrdering,
}

impl fmt::Display for CholeskyStats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let fill = self.nnz_l as f64 / self.nnz_a.max(1) as f64;
        write!(
            f,
            "n = {}, nnz(A lower) = {}, nnz(L) = {} ({fill:.1}× fill), {:?} ordering, ",
            self.n, self.nnz_a, self.nnz_l, self.ordering
        )?;
        if self.supernodal {
            write!(f, "supernodal ({} supernodes)", self.supernodes)
        } else {
            write!(f, "simplicial")
        }
    }
}

/// Sparse LLᵀ of a symmetric positive definite matrix given by its lower triangle in
/// CSC form, with a fill-reducing ordering and symbolic analysis done once, numeric
/// factorizations repeated on the same pattern with reused buffers (paper Eq. 9 is
/// solved with this).
pub struct SparseCholesky {
    n: usize,
    /// A's lower-triangle pattern, kept to view each new value array as a matrix.
    pattern: SymbolicSparseColMat<usize>,
    structure: Structure,
    /// `perm[new] = old`.
    perm: Vec<usize>,
    /// Position in A's value array of the diagonal entry of permuted column j.
    a_diag: Vec<usize>,
    /// Position in `l_values` of L's diagonal entry of permuted column j.
    l_diag: Vec<usize>,
    l_values: Vec<f64>,
    /// Workspace for both the numeric factorization and the solve.
    mem: MemBuffer,
    par: Par,
    /// Factor independent subtrees side by side (large supernodal factors on several threads).
    tree: Option<TreePlan>,
    pivot_tolerance: f64,
    ordering: FillOrdering,
    /// The two nested dissections tried on the tree path (`None` elsewhere).
    orderings: Option<OrderingChoice>,
    factorized: bool,
    /// `l_values` holds only zeros (nothing factored into it since the analysis).
    l_zero: bool,
}

/// The two nested dissections [`SparseCholesky::analyze_with`] orders a large body with on
/// several threads (METIS's defaults and [`SECOND_ORDERING`]), by their factors on the node
/// graph.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrderingChoice {
    /// The kept ordering's factor (the one with fewer flops; METIS's defaults on a tie).
    pub chosen: FactorCost,
    /// The other ordering's factor.
    pub other: FactorCost,
    /// Whether the kept one is [`SECOND_ORDERING`] (else METIS's defaults).
    pub second_chosen: bool,
}

/// The factor's symbolic structure and what solves with it.
enum Structure {
    /// faer's analysis of the DOF matrix; faer's factorization (or the tree plan's, in
    /// faer's storage) and faer's solve.
    Faer(SymbolicCholesky<usize>),
    /// The tree path's own supernodes from the node graph ([`node_symbolic`]): factored by
    /// the tree plan, solved by the supernodal solver with these buffers.
    Nodes {
        arrays: SupernodeArrays,
        solver: Box<SupernodalSolver>,
        work: ReachWork,
        /// The right-hand side in the permuted order.
        x: Vec<f64>,
    },
}

impl fmt::Debug for SparseCholesky {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SparseCholesky")
            .field("stats", &self.stats())
            .field("pivot_tolerance", &self.pivot_tolerance)
            .field("factorized", &self.factorized)
            .finish_non_exhaustive()
    }
}

impl SparseCholesky {
    /// Symbolic analysis of the n×n pattern (lower triangle CSC: `col_ptr` of length
    /// n + 1, `row_idx` sorted ascending within each column, every diagonal entry
    /// present), with METIS nested dissection and faer's choice of layout.
    ///
    /// `groups`: `Some(dof → node index)` orders the (smaller) node graph with METIS and
    /// expands it to DOFs, keeping the DOFs of one node together; `None` orders the DOF graph.
    pub fn analyze(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        groups: Option<&[usize]>,
    ) -> Result<Self, CholeskyError> {
        Self::analyze_with(n, col_ptr, row_idx, groups, CholeskyOptions::default())
    }

    /// [`analyze`](Self::analyze) with a choice of ordering, layout and threads.
    pub fn analyze_with(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        groups: Option<&[usize]>,
        options: CholeskyOptions,
    ) -> Result<Self, CholeskyError> {
        Self::analyze_inner(n, col_ptr, row_idx, groups, options, true)
    }

    /// [`analyze_with`](Self::analyze_with) as it is for small bodies, whatever the size:
    /// faer's analysis, factorization and solve, without the tree path (for comparisons).
    pub fn analyze_with_faers_loop(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        groups: Option<&[usize]>,
        options: CholeskyOptions,
    ) -> Result<Self, CholeskyError> {
        Self::analyze_inner(n, col_ptr, row_idx, groups, options, false)
    }

    fn analyze_inner(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        groups: Option<&[usize]>,
        options: CholeskyOptions,
        tree_allowed: bool,
    ) -> Result<Self, CholeskyError> {
        check_lower_pattern(n, col_ptr, row_idx)?;
        if let Some(g) = groups {
            if g.len() != n {
                return Err(CholeskyError::InvalidInput(format!(
                    "{} group entries for {n} DOFs",
                    g.len()
                )));
            }
        }

        // Large bodies on several threads: postorder, so that the tree plan applies.
        let tree_parallel = tree_allowed
            && options.ordering == FillOrdering::NestedDissection
            && options.threads != 1
            && n >= MIN_TREE_DOFS;
        let custom = match options.ordering {
            FillOrdering::NestedDissection => {
                let n_nodes = groups.map_or(n, |g| g.iter().max().map_or(0, |&m| m + 1));
                let (xadj, adjncy) = graph_of_pattern(n, col_ptr, row_idx, groups, n_nodes)?;
                if tree_parallel {
                    let mut sizes = vec![0usize; n_nodes];
                    match groups {
                        Some(g) => g.iter().for_each(|&node| sizes[node] += 1),
                        None => sizes.fill(1),
                    }
                    // Two nested dissections side by side (one per core), the cheaper kept:
                    // the factorization is at the machine's dense rate, so fewer flops is
                    // what makes it faster, and METIS's draws vary the flops by 2–4%.
                    let chosen = best_of_two_orderings(&xadj, &adjncy, &sizes, SECOND_ORDERING)?;
                    let (node_perm, node_inv) = (&chosen.perm, &chosen.inv);
                    // The factor's pages are faulted in on the other core while the ordering
                    // is postordered and analysed (the first touch of a 2 GB factor takes
                    // about as long as the analysis itself), up to its size as the node
                    // graph gives it.
                    let entries = chosen.cost.entries;
                    let done = AtomicBool::new(false);
                    let (early, analysed) = rayon::join(
                        || prefault(entries, &done),
                        || {
                            let analysed =
                                node_symbolic(n, &xadj, &adjncy, node_perm, node_inv, groups);
                            done.store(true, AtomicOrdering::Relaxed);
                            analysed
                        },
                    );
                    let mut solver =
                        Self::from_nodes(n, col_ptr, row_idx, analysed?, options, early)?;
                    solver.orderings = Some(OrderingChoice {
                        chosen: chosen.cost,
                        other: chosen.other,
                        second_chosen: chosen.second_chosen,
                    });
                    return Ok(solver);
                }
                let (node_perm, node_inv) = nested_dissection(&xadj, &adjncy)?;
                Some(match groups {
                    Some(g) => expand_to_dofs(&node_perm, g)?,
                    None => (node_perm, node_inv),
                })
            }
            // faer 0.24's `SymmetricOrdering::Identity` skips the conversion to the upper
            // triangle its symbolic analysis reads, so a lower-triangle input gets a wrong
            // elimination tree (and a panic in the numeric step): pass the identity as a
            // custom permutation instead.
            FillOrdering::Identity => Some(((0..n).collect(), (0..n).collect())),
            FillOrdering::Amd => None,
        };
        let (pattern, symbolic) = symbolic_analysis(n, col_ptr, row_idx, custom, options)?;
        Self::from_symbolic(
            n,
            col_ptr,
            row_idx,
            pattern,
            symbolic,
            options,
            false,
            Vec::new(),
        )
    }

    /// Symbolic analysis with the DOFs of the nodes marked `trailing` (`trailing[node]`,
    /// `groups[dof] = node`) ordered last and the others by METIS nested dissection, in the
    /// supernodal layout: the last block of the factor is then the Cholesky factor of the
    /// Schur complement on the trailing DOFs ([`trailing_factor`](Self::trailing_factor)).
    /// Large bodies analysed for several threads take the tree path of
    /// [`analyze_with`](Self::analyze_with) (the node graph's analysis, postordered, with the
    /// factor's first touch overlapped, the tree-parallel factorization and solves) when its
    /// postorder keeps the trailing DOFs last (one tree holds them); otherwise faer's analysis
    /// of the DOF matrix, postordered for the tree plan where that keeps them last.
    pub fn analyze_trailing(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        groups: &[usize],
        trailing: &[bool],
        threads: usize,
    ) -> Result<Self, CholeskyError> {
        check_lower_pattern(n, col_ptr, row_idx)?;
        if groups.len() != n {
            return Err(CholeskyError::InvalidInput(format!(
                "{} group entries for {n} DOFs",
                groups.len()
            )));
        }
        let n_nodes = trailing.len();
        let (xadj, adjncy) = graph_of_pattern(n, col_ptr, row_idx, Some(groups), n_nodes)?;
        let (node_perm, node_inv) = nested_dissection_with_trailing(&xadj, &adjncy, trailing)?;
        let options = CholeskyOptions {
            ordering: FillOrdering::NestedDissection,
            layout: FactorLayout::Supernodal,
            threads,
        };
        let large = threads != 1 && n >= MIN_TREE_DOFS;
        let is_trailing = |d: usize| trailing[groups[d]];
        let mut early = Vec::new();
        if large {
            // As in `analyze_with`: the factor's pages are faulted in on the other core while
            // the node graph is analysed.
            let mut sizes = vec![0usize; n_nodes];
            groups.iter().for_each(|&node| sizes[node] += 1);
            let done = AtomicBool::new(false);
            let (prefaulted, analysed) = rayon::join(
                || {
                    let entries = factor_entries(&xadj, &adjncy, &node_perm, &node_inv, &sizes);
                    prefault(entries, &done)
                },
                || {
                    let analysed =
                        node_symbolic(n, &xadj, &adjncy, &node_perm, &node_inv, Some(groups));
                    done.store(true, AtomicOrdering::Relaxed);
                    analysed
                },
            );
            let analysed = analysed?;
            let m = groups.iter().filter(|&&g| trailing[g]).count();
            if analysed.perm[n - m..].iter().all(|&d| is_trailing(d)) {
                return Self::from_nodes(n, col_ptr, row_idx, analysed, options, prefaulted);
            }
            // The node postorder interleaves them: faer's analysis of the ordering as it was
            // (its buffer continues the prefaulted one).
            early = prefaulted;
        }
        let (perm, inv) = expand_to_dofs(&node_perm, groups)?;
        // Postordered for the tree-parallel factorization and solves where the trailing DOFs
        // stay last.
        let postordered = large
            .then(|| postorder_keeping_trailing(col_ptr, row_idx, &perm, &inv, is_trailing))
            .flatten();
        let tree_parallel = postordered.is_some();
        let custom = Some(postordered.unwrap_or((perm, inv)));
        let (pattern, symbolic) = symbolic_analysis(n, col_ptr, row_idx, custom, options)?;
        Self::from_symbolic(
            n,
            col_ptr,
            row_idx,
            pattern,
            symbolic,
            options,
            tree_parallel,
            early,
        )
    }

    /// The solver for the node graph's analysis: the factor's buffer (continuing `early`),
    /// the tree plan and the supernodal solver. Where the tree plan does not apply (one
    /// thread, too little work), faer analyses the same ordering and the solver is faer's
    /// loop on it, postordered as before.
    fn from_nodes(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        analysed: NodeSymbolic,
        options: CholeskyOptions,
        early: Vec<f64>,
    ) -> Result<Self, CholeskyError> {
        let NodeSymbolic { arrays, perm, inv } = analysed;
        let par = match options.threads {
            1 => Par::Seq,
            t => Par::rayon(t),
        };
        let multi = matches!(par, Par::Rayon(t) if t.get() > 1);
        let len = arrays.val_ptr.last().copied().unwrap_or(0);
        // The factor's first touch (split among the threads) beside the tree plan and the
        // solver's other arrays.
        let ((l_values, solver), (tree, (pattern, a_diag, l_diag))) = rayon::join(
            || {
                (
                    zeroed(early, len),
                    SupernodalSolver::from_arrays(arrays.clone(), perm.clone()),
                )
            },
            || {
                let tree = if multi {
                    TreePlan::new(arrays.clone(), col_ptr, row_idx, &inv)
                } else {
                    None
                };
                let pattern = SymbolicSparseColMat::new_checked(
                    n,
                    n,
                    col_ptr.to_vec(),
                    None,
                    row_idx.to_vec(),
                );
                let a_diag: Vec<usize> = perm.iter().map(|&old| col_ptr[old]).collect();
                (tree, (pattern, a_diag, arrays.diagonal_positions()))
            },
        );
        let (Some(tree), Some(solver)) = (tree, solver) else {
            let (pattern, symbolic) =
                symbolic_analysis(n, col_ptr, row_idx, Some((perm, inv)), options)?;
            return Self::from_symbolic(
                n,
                col_ptr,
                row_idx,
                pattern,
                symbolic,
                options,
                true,
                Vec::new(),
            );
        };
        let l_values = l_values?;
        Ok(Self {
            n,
            pattern,
            structure: Structure::Nodes {
                arrays,
                solver: Box::new(solver),
                work: ReachWork::default(),
                x: vec![0.0; n],
            },
            perm,
            a_diag,
            l_diag,
            l_values,
            mem: MemBuffer::new(StackReq::EMPTY),
            par,
            tree: Some(tree),
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            ordering: options.ordering,
            orderings: None,
            factorized: false,
            l_zero: true,
        })
    }

    /// The solver for a finished symbolic analysis: the factor's buffer (continuing `early`,
    /// zeros already faulted in, see [`prefault`]), the workspace and, where `tree_parallel`
    /// (the ordering was postordered for it), the tree plan.
    #[allow(clippy::too_many_arguments)]
    fn from_symbolic(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        pattern: SymbolicSparseColMat<usize>,
        symbolic: SymbolicCholesky<usize>,
        options: CholeskyOptions,
        tree_parallel: bool,
        early: Vec<f64>,
    ) -> Result<Self, CholeskyError> {
        let perm: Vec<usize> = match symbolic.perm() {
            Some(p) => p.arrays().0.to_vec(),
            None => (0..n).collect(),
        };
        // Lower CSC with sorted rows and the diagonal present: the diagonal opens its column.
        let a_diag: Vec<usize> = perm.iter().map(|&old| col_ptr[old]).collect();
        let l_diag = factor_diagonal_positions(&symbolic);

        let par = match options.threads {
            1 => Par::Seq,
            t => Par::rayon(t),
        };
        let req = StackReq::or(
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, par),
        );
        let mem = MemBuffer::try_new(req).map_err(|_| {
            CholeskyError::Resources(format!("workspace of {} bytes", req.size_bytes()))
        })?;
        // The factor's first touch (page faults) and the tree plan side by side.
        let (l_values, tree) = rayon::join(
            || zeroed(early, symbolic.len_val()),
            || match (symbolic.raw(), par) {
                (SymbolicCholeskyRaw::Supernodal(s), Par::Rayon(t))
                    if tree_parallel && t.get() > 1 =>
                {
                    let mut inv = vec![0; n];
                    for (new, &old) in perm.iter().enumerate() {
                        inv[old] = new;
                    }
                    TreePlan::new(SupernodeArrays::new(s), col_ptr, row_idx, &inv)
                }
                _ => None,
            },
        );
        let l_values = l_values?;
        Ok(Self {
            n,
            pattern,
            structure: Structure::Faer(symbolic),
            perm,
            a_diag,
            l_diag,
            l_values,
            mem,
            par,
            tree,
            pivot_tolerance: DEFAULT_PIVOT_TOLERANCE,
            ordering: options.ordering,
            orderings: None,
            factorized: false,
            l_zero: true,
        })
    }

    /// Numeric factorization of `values` (same layout as `row_idx`). Reuses the factor
    /// buffer and the workspace: no allocation.
    ///
    /// On success every pivot ratio `d_j / A_jj = L_jj² / A_jj` is at least
    /// [`pivot_tolerance`](Self::pivot_tolerance). On error the factor is unusable
    /// until the next successful call.
    pub fn factorize(&mut self, values: &[f64]) -> Result<(), CholeskyError> {
        self.factorized = false;
        let nnz = self.pattern.row_idx().len();
        if values.len() != nnz {
            return Err(CholeskyError::InvalidInput(format!(
                "{} values for a pattern of {nnz} entries",
                values.len()
            )));
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            // Only on the error path: find the column for the message.
            let col = self.pattern.col_ptr().partition_point(|&p| p <= k) - 1;
            return Err(CholeskyError::InvalidInput(format!(
                "value {} at row {}, column {col} is not finite",
                values[k],
                self.pattern.row_idx()[k]
            )));
        }
        if let Some(plan) = &self.tree {
            let zeroed = std::mem::replace(&mut self.l_zero, false);
            if let Err(col) = plan.factorize(values, &mut self.l_values, self.par, zeroed) {
                return Err(CholeskyError::NonPositivePivot {
                    dof: self.perm[col.min(self.n - 1)],
                });
            }
            return self.check_pivots(values);
        }
        let Structure::Faer(symbolic) = &self.structure else {
            // The node graph's structure is only built with its tree plan.
            return Err(CholeskyError::Resources(
                "no factorization for the node graph's structure".into(),
            ));
        };
        let a = SparseColMatRef::new(self.pattern.as_ref(), values);
        let result = symbolic.factorize_numeric_llt(
            &mut self.l_values,
            a,
            Side::Lower,
            Default::default(),
            self.par,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        if let Err(LltError::NonPositivePivot { index }) = result {
            return Err(CholeskyError::NonPositivePivot {
                dof: self.perm[self.failed_column(index)],
            });
        }
        self.check_pivots(values)
    }

    /// Whether the tree-parallel factorization is in use (large supernodal factors with
    /// more than one thread).
    pub fn is_tree_parallel(&self) -> bool {
        self.tree.is_some()
    }

    /// Rejects a factor with a pivot ratio below the tolerance; marks it usable otherwise.
    fn check_pivots(&mut self, values: &[f64]) -> Result<(), CholeskyError> {
        // O(n): one pass over the pivots in permuted order.
        let (mut worst, mut worst_at) = (f64::INFINITY, 0);
        for (j, (&lp, &ap)) in self.l_diag.iter().zip(&self.a_diag).enumerate() {
            let l = self.l_values[lp];
            let ratio = l * l / values[ap];
            if ratio < worst {
                worst = ratio;
                worst_at = j;
            }
        }
        if worst < self.pivot_tolerance {
            return Err(CholeskyError::NearlySingular {
                dof: self.perm[worst_at],
                ratio: worst,
            });
        }
        self.factorized = true;
        Ok(())
    }

    /// Solves `L Lᵀ x = b` in place: `rhs` holds `b` on entry and `x` on return, both in
    /// the original (unpermuted) DOF order. No allocation.
    ///
    /// # Panics
    /// If the last [`factorize`](Self::factorize) did not succeed, or `rhs.len() != n`.
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        assert!(
            self.factorized,
            "SparseCholesky::solve_in_place needs a successful factorize first"
        );
        assert_eq!(rhs.len(), self.n, "right-hand side length must equal n");
        let n = self.n;
        match &mut self.structure {
            Structure::Faer(symbolic) => LltRef::new(symbolic, &self.l_values)
                .solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(rhs, n, 1),
                    self.par,
                    MemStack::new(&mut self.mem),
                ),
            Structure::Nodes {
                solver, work, x, ..
            } => {
                for (xi, &old) in x.iter_mut().zip(&self.perm) {
                    *xi = rhs[old];
                }
                solver.forward(&self.l_values, x, work);
                solver.backward(&self.l_values, x);
                for (&xi, &old) in x.iter().zip(&self.perm) {
                    rhs[old] = xi;
                }
            }
        }
    }

    /// n, nnz(A lower), nnz(L), and whether the factorization is supernodal, for printing.
    pub fn stats(&self) -> CholeskyStats {
        let raw = match &self.structure {
            Structure::Faer(symbolic) => symbolic.raw(),
            Structure::Nodes { arrays, .. } => {
                return CholeskyStats {
                    n: self.n,
                    nnz_a: self.pattern.row_idx().len(),
                    nnz_l: arrays.nnz(),
                    factor_values: self.l_values.len(),
                    supernodal: true,
                    supernodes: arrays.len(),
                    ordering: self.ordering,
                }
            }
        };
        let (supernodal, supernodes, nnz_l) = match raw {
            SymbolicCholeskyRaw::Simplicial(s) => (false, 0, s.len_val()),
            SymbolicCholeskyRaw::Supernodal(s) => {
                let begin = s.supernode_begin();
                let end = s.supernode_end();
                let nnz = (0..s.n_supernodes())
                    .map(|k| {
                        let w = end[k] - begin[k];
                        w * (w + 1) / 2 + w * s.supernode(k).pattern().len()
                    })
                    .sum();
                (true, s.n_supernodes(), nnz)
            }
        };
        CholeskyStats {
            n: self.n,
            nnz_a: self.pattern.row_idx().len(),
            nnz_l,
            factor_values: self.l_values.len(),
            supernodal,
            supernodes,
            ordering: self.ordering,
        }
    }

    /// The fill-reducing permutation, `perm[new] = old` (original DOF index of
    /// factor column `new`).
    pub fn permutation(&self) -> &[usize] {
        &self.perm
    }

    /// The supernodal structure of the factor (`None` when simplicial), for solves that walk
    /// it ([`SupernodalSolver`](super::tree_solve::SupernodalSolver)).
    /// `None` also for the tree path's own structure: see
    /// [`supernode_arrays`](Self::supernode_arrays).
    pub(crate) fn supernodal_symbolic(&self) -> Option<&SymbolicSupernodalCholesky<usize>> {
        match &self.structure {
            Structure::Faer(symbolic) => match symbolic.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => Some(s),
                SymbolicCholeskyRaw::Simplicial(_) => None,
            },
            Structure::Nodes { .. } => None,
        }
    }

    /// The factor's supernodes as plain arrays (`None` when simplicial), whichever analysis
    /// built them.
    pub(crate) fn supernode_arrays(&self) -> Option<SupernodeArrays> {
        match &self.structure {
            Structure::Faer(symbolic) => match symbolic.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => Some(SupernodeArrays::new(s)),
                SymbolicCholeskyRaw::Simplicial(_) => None,
            },
            Structure::Nodes { arrays, .. } => Some(arrays.clone()),
        }
    }

    /// Flops of the numeric factorization by its supernodes (w³/3 + w²p + wp² for w columns
    /// and p rows below them); `None` when simplicial.
    pub fn factor_flops(&self) -> Option<f64> {
        self.supernode_arrays().map(|a| a.flops())
    }

    /// The two nested dissections the analysis chose from, with their factors' sizes and
    /// flops on the node graph; `None` unless it took the tree path of
    /// [`analyze_with`](Self::analyze_with).
    pub fn ordering_choice(&self) -> Option<OrderingChoice> {
        self.orderings
    }

    /// Whether the factor's structure comes from the node graph (the tree path's own
    /// analysis) rather than from faer's analysis of the DOF matrix.
    pub fn has_node_structure(&self) -> bool {
        matches!(self.structure, Structure::Nodes { .. })
    }

    /// The factor's values in faer's storage, `None` unless the last factorization succeeded.
    pub(crate) fn factor_values(&self) -> Option<&[f64]> {
        self.factorized.then_some(&self.l_values[..])
    }

    /// Smallest accepted pivot ratio `d_j / A_jj` (dimensionless).
    pub fn pivot_tolerance(&self) -> f64 {
        self.pivot_tolerance
    }

    /// Sets the smallest accepted pivot ratio `d_j / A_jj` (dimensionless; 0 disables
    /// the check). Takes effect at the next [`factorize`](Self::factorize).
    ///
    /// # Panics
    /// If `tolerance` is negative or NaN.
    pub fn set_pivot_tolerance(&mut self, tolerance: f64) {
        assert!(
            tolerance >= 0.0,
            "pivot tolerance must be ≥ 0, got {tolerance}"
        );
        self.pivot_tolerance = tolerance;
    }

    /// Whether the last [`factorize`](Self::factorize) succeeded, so that
    /// [`solve_in_place`](Self::solve_in_place) may be called.
    pub fn is_factorized(&self) -> bool {
        self.factorized
    }

    /// The last `m` columns of the factor: the original DOFs of factor columns `n − m..n`,
    /// and the dense lower-triangular block `L₂₂` of those rows and columns, for which
    /// `L₂₂ L₂₂ᵀ = A₂₂ − A₂₁ A₁₁⁻¹ A₁₂`, the Schur complement on those DOFs (N/m for a
    /// stiffness). `None` before a successful factorization or for a simplicial factor.
    pub fn trailing_factor(&self, m: usize) -> Option<(Vec<usize>, faer::Mat<f64>)> {
        if !self.factorized || m > self.n {
            return None;
        }
        let from_faer;
        let arrays = match &self.structure {
            Structure::Faer(symbolic) => match symbolic.raw() {
                SymbolicCholeskyRaw::Supernodal(s) => {
                    from_faer = SupernodeArrays::new(s);
                    &from_faer
                }
                SymbolicCholeskyRaw::Simplicial(_) => return None,
            },
            Structure::Nodes { arrays, .. } => arrays,
        };
        let first = self.n - m;
        let mut block = faer::Mat::<f64>::zeros(m, m);
        // Supernode k: a column-major block of (width + pattern) rows × width columns from
        // val_ptr[k], its square diagonal block on top (faer's storage and the node path's).
        // The columns side by side (the block is as large as the compliance).
        block
            .as_mut()
            .par_col_iter_mut()
            .enumerate()
            .for_each(|(j, mut column)| {
                let col = first + j;
                let k = arrays.super_of[col];
                let (start, end) = (arrays.begin[k], arrays.begin[k + 1]);
                let width = end - start;
                let pattern = arrays.pattern(k);
                let rows = width + pattern.len();
                let c = col - start;
                let base = arrays.val_ptr[k] + c * rows;
                let values = &self.l_values[base..base + rows];
                for (r, &v) in values.iter().enumerate().take(width).skip(c) {
                    column[start + r - first] = v;
                }
                for (&row, &v) in pattern.iter().zip(&values[width..]) {
                    column[row - first] = v;
                }
            });
        Some((self.perm[first..].to_vec(), block))
    }

    /// Maps faer's failed-pivot index to the permuted column.
    fn failed_column(&self, index: usize) -> usize {
        // faer 0.24 reports the column one-based from its simplicial kernel and
        // zero-based from its supernodal (dense) kernel; the tests pin both.
        let col = match &self.structure {
            Structure::Faer(symbolic) => match symbolic.raw() {
                SymbolicCholeskyRaw::Simplicial(_) => index.saturating_sub(1),
                SymbolicCholeskyRaw::Supernodal(_) => index,
            },
            Structure::Nodes { .. } => index,
        };
        col.min(self.n.saturating_sub(1))
    }
}

/// Pattern (a copy of A's lower CSC) and faer's symbolic analysis with `custom =
/// Some((perm, inv))` or AMD, in the layout `options` asks for.
pub(crate) fn symbolic_analysis(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
    custom: Option<(Vec<usize>, Vec<usize>)>,
    options: CholeskyOptions,
) -> Result<(SymbolicSparseColMat<usize>, SymbolicCholesky<usize>), CholeskyError> {
    let ordering = match &custom {
        Some((fwd, inv)) => SymmetricOrdering::Custom(PermRef::new_checked(fwd, inv, n)),
        None => SymmetricOrdering::Amd,
    };

    let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr.to_vec(), None, row_idx.to_vec());
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: match options.layout {
            FactorLayout::Auto => SupernodalThreshold::AUTO,
            FactorLayout::Simplicial => SupernodalThreshold::FORCE_SIMPLICIAL,
            FactorLayout::Supernodal => SupernodalThreshold::FORCE_SUPERNODAL,
        },
        ..Default::default()
    };
    let symbolic = factorize_symbolic_cholesky(pattern.as_ref(), Side::Lower, ordering, params)
        .map_err(|e| CholeskyError::Resources(format!("symbolic factorization: {e:?}")))?;

    Ok((pattern, symbolic))
}

/// Checks a lower-triangle CSC pattern: offsets, sorted rows in range, diagonal first.
fn check_lower_pattern(
    n: usize,
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Result<(), CholeskyError> {
    let bad = |msg: String| Err(CholeskyError::InvalidInput(msg));
    if col_ptr.len() != n + 1 {
        return bad(format!(
            "col_ptr has {} entries, expected n + 1 = {}",
            col_ptr.len(),
            n + 1
        ));
    }
    if col_ptr[0] != 0 || col_ptr[n] != row_idx.len() {
        return bad(format!(
            "col_ptr must run from 0 to row_idx.len() = {} (found {} to {})",
            row_idx.len(),
            col_ptr[0],
            col_ptr[n]
        ));
    }
    for j in 0..n {
        let (start, end) = (col_ptr[j], col_ptr[j + 1]);
        if start > end {
            return bad(format!("col_ptr decreases at column {j}"));
        }
        let rows = &row_idx[start..end];
        if rows.first() != Some(&j) {
            return bad(format!(
                "column {j} must start with its diagonal entry (lower triangle, rows ascending); \
                 found {:?}",
                rows.first()
            ));
        }
        if let Some(w) = rows.windows(2).find(|w| w[0] >= w[1]) {
            return bad(format!(
                "rows of column {j} not strictly ascending ({} then {})",
                w[0], w[1]
            ));
        }
        if let Some(&last) = rows.last() {
            if last >= n {
                return bad(format!(
                    "row {last} in column {j} is out of range for n = {n}"
                ));
            }
        }
    }
    Ok(())
}

/// Position of each diagonal entry L_jj (permuted column j) in faer's value buffer.
pub(crate) fn factor_diagonal_positions(symbolic: &SymbolicCholesky<usize>) -> Vec<usize> {
    match symbolic.raw() {
        // Simplicial: CSC, the diagonal opens each column.
        SymbolicCholeskyRaw::Simplicial(s) => s.col_ptr()[..s.nrows()].to_vec(),
        // Supernodal: supernode k is a column-major block of (width + pattern) rows ×
        // width columns starting at col_ptr_for_val[k], its square diagonal block on top.
        SymbolicCholeskyRaw::Supernodal(s) => {
            let mut pos = Vec::with_capacity(s.nrows());
            let bounds = s.supernode_begin().iter().zip(s.supernode_end());
            for (k, (&start, &end)) in bounds.enumerate() {
                let width = end - start;
                let rows = width + s.supernode(k).pattern().len();
                let base = s.col_ptr_for_val()[k];
                pos.extend((0..width).map(|c| base + c * rows + c));
            }
            pos
        }
    }
}

/// Values faulted in ahead of the factor per step of [`prefault`] (2 MB).
const PREFAULT_CHUNK: usize = 1 << 18;

/// Up to `len` zeros, allocated fallibly and written (first touched) in steps until `done`
/// is set: run on an idle core while the analysis that fixes the factor's size goes on, and
/// continued by [`zeroed`]. On an allocation failure returns what it has (nothing): the
/// factor's own allocation reports the error.
fn prefault(len: usize, done: &AtomicBool) -> Vec<f64> {
    let mut v = Vec::new();
    if v.try_reserve_exact(len).is_err() {
        return v;
    }
    while v.len() < len && !done.load(AtomicOrdering::Relaxed) {
        let step = PREFAULT_CHUNK.min(len - v.len());
        v.extend(std::iter::repeat_n(0.0, step));
    }
    v
}

/// `start` (zeros) continued to `len` zeros, allocated fallibly and first touched in
/// parallel: for a large factor (2.3 GB at 200k DOFs) the page faults of the first write
/// cost seconds on one thread, and the factorization would otherwise take them all on its
/// first call.
fn zeroed(mut start: Vec<f64>, len: usize) -> Result<Vec<f64>, CholeskyError> {
    if start.len() >= len {
        start.truncate(len);
        start.shrink_to_fit();
        return Ok(start);
    }
    start
        .try_reserve_exact(len - start.len())
        .map_err(|_| CholeskyError::Resources(format!("factor of {len} values")))?;
    // Fills the reserved capacity in place (no reallocation).
    let rest = len - start.len();
    start.par_extend(rayon::iter::repeat_n(0.0, rest));
    Ok(start)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Lower-triangle CSC of a matrix given as (row, col, value) with row ≥ col;
    /// duplicates are summed.
    pub(crate) fn lower_csc(
        n: usize,
        mut entries: Vec<(usize, usize, f64)>,
    ) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        entries.sort_by_key(|&(i, j, _)| (j, i));
        let mut col_ptr = vec![0; n + 1];
        let (mut rows, mut vals) = (Vec::new(), Vec::new());
        let mut last = None;
        for (i, j, v) in entries {
            assert!(i >= j);
            if last == Some((i, j)) {
                *vals.last_mut().unwrap() += v;
                continue;
            }
            last = Some((i, j));
            rows.push(i);
            vals.push(v);
            col_ptr[j + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        (col_ptr, rows, vals)
    }

    /// 2D 5-point Laplacian on nx × ny plus `shift` on the diagonal.
    fn laplacian_2d(nx: usize, ny: usize, shift: f64) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let n = nx * ny;
        let mut e = Vec::new();
        for y in 0..ny {
            for x in 0..nx {
                let k = y * nx + x;
                e.push((k, k, 4.0 + shift));
                if x + 1 < nx {
                    e.push((k + 1, k, -1.0));
                }
                if y + 1 < ny {
                    e.push((k + nx, k, -1.0));
                }
            }
        }
        let (c, r, v) = lower_csc(n, e);
        (n, c, r, v)
    }

    /// y = A x for A given by its lower triangle.
    fn sym_mul(col_ptr: &[usize], rows: &[usize], vals: &[f64], x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; x.len()];
        for j in 0..x.len() {
            for p in col_ptr[j]..col_ptr[j + 1] {
                let i = rows[p];
                y[i] += vals[p] * x[j];
                if i != j {
                    y[j] += vals[p] * x[i];
                }
            }
        }
        y
    }

    fn all_options() -> Vec<CholeskyOptions> {
        let mut v = Vec::new();
        for ordering in [
            FillOrdering::NestedDissection,
            FillOrdering::Amd,
            FillOrdering::Identity,
        ] {
            for layout in [FactorLayout::Simplicial, FactorLayout::Supernodal] {
                for threads in [1, 2] {
                    v.push(CholeskyOptions {
                        ordering,
                        layout,
                        threads,
                    });
                }
            }
        }
        v
    }

    fn rel_err(a: &[f64], b: &[f64]) -> f64 {
        let d: f64 = a
            .iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt();
        d / b.iter().map(|y| y * y).sum::<f64>().sqrt()
    }

    #[test]
    fn solves_shifted_laplacian_in_every_configuration() {
        let (n, c, r, v) = laplacian_2d(12, 9, 0.1);
        let x_true: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin() + 1.0).collect();
        let b = sym_mul(&c, &r, &v, &x_true);
        for opt in all_options() {
            let mut chol = SparseCholesky::analyze_with(n, &c, &r, None, opt).unwrap();
            assert_eq!(
                chol.stats().supernodal,
                opt.layout == FactorLayout::Supernodal
            );
            chol.factorize(&v).unwrap();
            let mut x = b.clone();
            chol.solve_in_place(&mut x);
            assert!(
                rel_err(&x, &x_true) < 1e-12,
                "{opt:?}: {}",
                rel_err(&x, &x_true)
            );
            let res = sym_mul(&c, &r, &v, &x);
            assert!(rel_err(&res, &b) < 1e-12);
        }
    }

    /// The trailing block of the factor reproduces the Schur complement, computed densely
    /// from the solves `A₁₁⁻¹ A₁₂` column by column.
    #[test]
    fn trailing_block_is_the_factor_of_the_schur_complement() {
        // Pairs of DOFs per "node" so that groups matter; the trailing nodes are a stripe.
        let (nx, ny) = (9, 7);
        let (n1, c1, r1, v1) = laplacian_2d(nx, ny, 0.3);
        let mut e = Vec::new();
        for j in 0..n1 {
            for p in c1[j]..c1[j + 1] {
                for k in 0..2 {
                    e.push((2 * r1[p] + k, 2 * j + k, v1[p] * (1.0 + k as f64)));
                }
            }
            e.push((2 * j + 1, 2 * j, 0.5));
        }
        let n = 2 * n1;
        let (col_ptr, rows, vals) = lower_csc(n, e);
        let groups: Vec<usize> = (0..n).map(|d| d / 2).collect();
        let trailing: Vec<bool> = (0..n1).map(|node| node % nx == 4 || node == 3).collect();
        let m = 2 * trailing.iter().filter(|&&t| t).count();
        let mut chol =
            SparseCholesky::analyze_trailing(n, &col_ptr, &rows, &groups, &trailing, 1).unwrap();
        chol.factorize(&vals).unwrap();
        let (dofs, l) = chol.trailing_factor(m).unwrap();
        assert!(dofs.iter().all(|&d| trailing[d / 2]));
        // Dense A, then S = A22 − A21 A11⁻¹ A12 by Gaussian elimination of the leading DOFs.
        let mut a = faer::Mat::<f64>::zeros(n, n);
        for j in 0..n {
            for p in col_ptr[j]..col_ptr[j + 1] {
                a[(rows[p], j)] = vals[p];
                a[(j, rows[p])] = vals[p];
            }
        }
        let order: Vec<usize> = (0..n)
            .filter(|d| !dofs.contains(d))
            .chain(dofs.iter().copied())
            .collect();
        let mut b: Vec<Vec<f64>> = order
            .iter()
            .map(|&i| order.iter().map(|&j| a[(i, j)]).collect())
            .collect();
        for k in 0..n - m {
            let pivot = b[k].clone();
            for row in b.iter_mut().skip(k + 1) {
                let f = row[k] / pivot[k];
                for (x, p) in row.iter_mut().zip(&pivot).skip(k) {
                    *x -= f * p;
                }
            }
        }
        let mut worst: f64 = 0.0;
        for i in 0..m {
            for j in 0..m {
                let llt: f64 = (0..m).map(|k| l[(i, k)] * l[(j, k)]).sum();
                worst = worst.max((llt - b[n - m + i][n - m + j]).abs());
            }
        }
        assert!(
            worst < 1e-12,
            "L22 L22ᵀ differs from the Schur complement by {worst}"
        );
        // The upper triangle of the block is zero: it is a factor.
        assert!((0..m).all(|i| (i + 1..m).all(|j| l[(i, j)] == 0.0)));
    }

    #[test]
    fn refactorizing_gives_the_new_answer() {
        let (n, c, r, v) = laplacian_2d(10, 10, 0.5);
        let mut chol = SparseCholesky::analyze(n, &c, &r, None).unwrap();
        let x_true: Vec<f64> = (0..n).map(|i| i as f64 - 40.0).collect();
        chol.factorize(&v).unwrap();
        let mut x = sym_mul(&c, &r, &v, &x_true);
        chol.solve_in_place(&mut x);
        assert!(rel_err(&x, &x_true) < 1e-12);
        // New values on the same pattern: doubled and with a different shift.
        let v2: Vec<f64> = v
            .iter()
            .enumerate()
            .map(|(p, &a)| {
                if r[p] == c.partition_point(|&q| q <= p) - 1 {
                    2.0 * a + 3.0
                } else {
                    2.0 * a
                }
            })
            .collect();
        chol.factorize(&v2).unwrap();
        let b2 = sym_mul(&c, &r, &v2, &x_true);
        let mut x2 = b2.clone();
        chol.solve_in_place(&mut x2);
        assert!(rel_err(&x2, &x_true) < 1e-12);
        // And the old answer is not what comes out of the old right-hand side any more.
        let mut x3 = sym_mul(&c, &r, &v, &x_true);
        chol.solve_in_place(&mut x3);
        assert!(rel_err(&x3, &x_true) > 1e-3);
    }

    #[test]
    fn groups_keep_node_dofs_together() {
        // A 2D truss-like matrix: 3 DOFs per node, nodes on a 6×5 grid, DOFs of a node
        // interleaved (dof = d * nodes + node) so the expansion has work to do.
        let (nx, ny, per) = (6, 5, 3);
        let nodes = nx * ny;
        let n = nodes * per;
        let dof = |node: usize, d: usize| d * nodes + node;
        let mut e = Vec::new();
        let couple = |a: usize, b: usize, e: &mut Vec<(usize, usize, f64)>| {
            for da in 0..per {
                for db in 0..per {
                    let (i, j) = (dof(a, da), dof(b, db));
                    if i > j {
                        e.push((i, j, -0.1));
                    }
                }
            }
        };
        for y in 0..ny {
            for x in 0..nx {
                let k = y * nx + x;
                couple(k, k, &mut e);
                if x + 1 < nx {
                    couple(k + 1, k, &mut e);
                    couple(k, k + 1, &mut e);
                }
                if y + 1 < ny {
                    couple(k + nx, k, &mut e);
                    couple(k, k + nx, &mut e);
                }
            }
        }
        for i in 0..n {
            e.push((i, i, 10.0));
        }
        let (c, r, v) = lower_csc(n, e);
        let groups: Vec<usize> = (0..n).map(|i| i % nodes).collect();
        let mut chol = SparseCholesky::analyze(n, &c, &r, Some(&groups)).unwrap();
        let perm = chol.permutation().to_vec();
        let mut seen = vec![false; n];
        for &p in &perm {
            assert!(!seen[p]);
            seen[p] = true;
        }
        for block in perm.chunks(per) {
            assert!(
                block.iter().all(|&d| groups[d] == groups[block[0]]),
                "{block:?}"
            );
            assert!(block.windows(2).all(|w| w[0] < w[1]));
        }
        chol.factorize(&v).unwrap();
        let x_true: Vec<f64> = (0..n).map(|i| 1.0 + i as f64 / n as f64).collect();
        let mut x = sym_mul(&c, &r, &v, &x_true);
        chol.solve_in_place(&mut x);
        assert!(rel_err(&x, &x_true) < 1e-12);
    }

    #[test]
    fn free_free_spring_chain_is_singular() {
        // Path Laplacian without supports: rigid translation is a zero-energy mode.
        let n = 30;
        let mut e = Vec::new();
        for k in 0..n {
            e.push((k, k, if k == 0 || k == n - 1 { 1.0 } else { 2.0 }));
            if k + 1 < n {
                e.push((k + 1, k, -1.0));
            }
        }
        let (c, r, v) = lower_csc(n, e);
        for opt in all_options() {
            let mut chol = SparseCholesky::analyze_with(n, &c, &r, None, opt).unwrap();
            let err = chol.factorize(&v).unwrap_err();
            assert!(
                matches!(
                    err,
                    CholeskyError::NonPositivePivot { .. } | CholeskyError::NearlySingular { .. }
                ),
                "{opt:?}: {err}"
            );
            assert!(!chol.is_factorized());
        }
    }

    #[test]
    fn singular_dof_is_reported_by_its_original_index() {
        // Shifted Laplacian with DOF 37 cut loose: its row and column stay in the
        // pattern but are zero, diagonal included.
        let (n, c, r, mut v) = laplacian_2d(9, 8, 0.2);
        let bad = 37;
        for j in 0..n {
            for p in c[j]..c[j + 1] {
                if r[p] == bad || j == bad {
                    v[p] = 0.0;
                }
            }
        }
        for opt in all_options() {
            let mut chol = SparseCholesky::analyze_with(n, &c, &r, None, opt).unwrap();
            assert_eq!(
                chol.factorize(&v),
                Err(CholeskyError::NonPositivePivot { dof: bad }),
                "{opt:?}"
            );
        }
        // The last permuted column and the first one (off-by-one traps).
        for bad in [0, n - 1] {
            let (_, _, _, mut v) = laplacian_2d(9, 8, 0.2);
            for j in 0..n {
                for p in c[j]..c[j + 1] {
                    if r[p] == bad || j == bad {
                        v[p] = 0.0;
                    }
                }
            }
            for layout in [FactorLayout::Simplicial, FactorLayout::Supernodal] {
                let opt = CholeskyOptions {
                    ordering: FillOrdering::Identity,
                    layout,
                    threads: 1,
                };
                let mut chol = SparseCholesky::analyze_with(n, &c, &r, None, opt).unwrap();
                assert_eq!(
                    chol.factorize(&v),
                    Err(CholeskyError::NonPositivePivot { dof: bad })
                );
            }
        }
    }

    #[test]
    fn round_off_pivot_is_nearly_singular() {
        // A = BᵀB with B 3×4: rank 3, so one pivot is zero in exact arithmetic and
        // round-off in floating point.
        let b = [
            [1.0, 0.3, 0.7, 0.1],
            [0.2, 1.0, 0.45, 0.9],
            [0.6, 0.35, 1.0, 0.25],
        ];
        let n = 4;
        let mut e = Vec::new();
        for j in 0..n {
            for i in j..n {
                e.push((i, j, (0..3).map(|k| b[k][i] * b[k][j]).sum::<f64>()));
            }
        }
        let (c, r, v) = lower_csc(n, e);
        for opt in all_options() {
            let mut chol = SparseCholesky::analyze_with(n, &c, &r, None, opt).unwrap();
            match chol.factorize(&v) {
                // The last pivot comes out near 3e-17 of its diagonal entry.
                Err(CholeskyError::NearlySingular { dof, ratio }) => {
                    assert!(ratio > 0.0 && ratio < 1e-15, "{opt:?}: {ratio}");
                    assert_eq!(dof, chol.permutation()[n - 1]);
                }
                other => panic!("{opt:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn tolerance_is_adjustable() {
        // [[1, 1], [1, 1 + 1e-10]]: pivot ratio 1e-10/(1 + 1e-10).
        let (c, r) = (vec![0, 2, 3], vec![0, 1, 1]);
        let v = [1.0, 1.0, 1.0 + 1e-10];
        let mut chol = SparseCholesky::analyze(2, &c, &r, None).unwrap();
        chol.factorize(&v).unwrap();
        chol.set_pivot_tolerance(1e-8);
        match chol.factorize(&v) {
            Err(CholeskyError::NearlySingular { dof: 1, ratio }) => {
                assert!((ratio - 1e-10).abs() < 1e-14)
            }
            other => panic!("{other:?}"),
        }
        chol.set_pivot_tolerance(0.0);
        chol.factorize(&v).unwrap();
        let mut x = [2.0, 2.0 + 1e-10];
        chol.solve_in_place(&mut x);
        assert!((x[0] - 1.0).abs() < 1e-5 && (x[1] - 1.0).abs() < 1e-5);
    }

    #[test]
    fn rejects_bad_input() {
        let (n, c, r, v) = laplacian_2d(3, 3, 0.0);
        let err = |res: Result<SparseCholesky, CholeskyError>| {
            matches!(res, Err(CholeskyError::InvalidInput(_)))
        };
        assert!(err(SparseCholesky::analyze(n + 1, &c, &r, None)));
        // Missing diagonal of column 1.
        let (c2, r2) = (vec![0, 2, 3], vec![0, 1, 0]);
        assert!(err(SparseCholesky::analyze(2, &c2, &r2, None)));
        let (c3, r3) = (vec![0, 1, 2], vec![0, 1]);
        assert!(SparseCholesky::analyze(2, &c3, &r3, None).is_ok());
        let (c4, r4) = (vec![0, 2, 3], vec![0, 5, 1]);
        assert!(err(SparseCholesky::analyze(2, &c4, &r4, None)));
        assert!(err(SparseCholesky::analyze(n, &c, &r, Some(&[0, 1]))));
        let mut chol = SparseCholesky::analyze(n, &c, &r, None).unwrap();
        assert!(matches!(
            chol.factorize(&v[1..]),
            Err(CholeskyError::InvalidInput(_))
        ));
        let mut nan = v.clone();
        nan[3] = f64::NAN;
        assert!(matches!(
            chol.factorize(&nan),
            Err(CholeskyError::InvalidInput(_))
        ));
    }

    /// The factor's size from the node graph ([`factor_entries`]) is exact for a lattice,
    /// whose coupled nodes couple in all their DOFs, with supported nodes of 0 DOFs.
    #[test]
    fn node_graph_gives_the_factor_size() {
        let (s, _) = crate::bench::cholmod::lattice_system([4, 3, 5]).unwrap();
        let groups = s.groups.clone().unwrap();
        let options = CholeskyOptions {
            layout: FactorLayout::Simplicial,
            threads: 1,
            ..Default::default()
        };
        let chol =
            SparseCholesky::analyze_with(s.n, &s.col_ptr, &s.row_idx, Some(&groups), options)
                .unwrap();
        let n_nodes = groups.iter().max().unwrap() + 1;
        let (x, a) = graph_of_pattern(s.n, &s.col_ptr, &s.row_idx, Some(&groups), n_nodes).unwrap();
        let (perm, inv) = nested_dissection(&x, &a).unwrap();
        let mut sizes = vec![0; n_nodes];
        groups.iter().for_each(|&g| sizes[g] += 1);
        assert_eq!(
            factor_entries(&x, &a, &perm, &inv, &sizes),
            chol.stats().nnz_l
        );
    }

    /// A solve of a zero right-hand side gives positive zeros, in faer's loop and on the tree
    /// path: the condensed bodies' expansion skips that solve when nothing changed
    /// (`CondensedBody::expand`), which must give the same bits.
    #[test]
    fn a_zero_right_hand_side_solves_to_positive_zeros() {
        // 16×16×25 cells: 21,675 DOFs, above MIN_TREE_DOFS.
        let (s, _) = crate::bench::cholmod::lattice_system([16, 16, 25]).unwrap();
        let options = CholeskyOptions {
            threads: 2,
            ..Default::default()
        };
        for tree in [true, false] {
            let analyze = if tree {
                SparseCholesky::analyze_with
            } else {
                SparseCholesky::analyze_with_faers_loop
            };
            let mut chol =
                analyze(s.n, &s.col_ptr, &s.row_idx, s.groups.as_deref(), options).unwrap();
            assert_eq!(chol.is_tree_parallel(), tree);
            chol.factorize(&s.values).unwrap();
            let mut x = vec![0.0; s.n];
            chol.solve_in_place(&mut x);
            assert!(x.iter().all(|v| v.to_bits() == 0), "tree = {tree}");
        }
    }

    /// On the tree path the analysis keeps the cheaper of METIS's default ordering and
    /// [`SECOND_ORDERING`], whatever the thread count the two METIS calls get: the same
    /// ordering, factor sizes and solution bits on a pool of one thread and of two.
    #[test]
    fn tree_path_keeps_the_cheaper_of_two_orderings() {
        // 16×16×25 cells: 21,675 DOFs, above MIN_TREE_DOFS.
        let (s, _) = crate::bench::cholmod::lattice_system([16, 16, 25]).unwrap();
        assert!(s.n >= MIN_TREE_DOFS);
        let groups = s.groups.clone().unwrap();
        let options = CholeskyOptions {
            threads: 2,
            ..Default::default()
        };
        let run = |pool_threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(pool_threads)
                .build()
                .unwrap();
            pool.install(|| {
                let mut chol = SparseCholesky::analyze_with(
                    s.n,
                    &s.col_ptr,
                    &s.row_idx,
                    Some(&groups),
                    options,
                )
                .unwrap();
                chol.factorize(&s.values).unwrap();
                let mut x = s.rhs.clone();
                chol.solve_in_place(&mut x);
                (chol.permutation().to_vec(), chol.ordering_choice(), x)
            })
        };
        let (perm, choice, x) = run(2);
        let choice = choice.expect("the tree path records its two orderings");
        assert!(choice.chosen.flops <= choice.other.flops);
        // The recorded costs are those of the two METIS orderings of the node graph.
        let n_nodes = groups.iter().max().unwrap() + 1;
        let (gx, ga) =
            graph_of_pattern(s.n, &s.col_ptr, &s.row_idx, Some(&groups), n_nodes).unwrap();
        let mut sizes = vec![0; n_nodes];
        groups.iter().for_each(|&g| sizes[g] += 1);
        let cost = |o| {
            let (p, i) = crate::linalg::ordering::nested_dissection_with(&gx, &ga, o).unwrap();
            crate::linalg::ordering::factor_cost(&gx, &ga, &p, &i, &sizes)
        };
        let (first, second) = (cost(Default::default()), cost(SECOND_ORDERING));
        let expected = match choice.second_chosen {
            true => (second, first),
            false => (first, second),
        };
        assert_eq!((choice.chosen, choice.other), expected);
        // The residual of the solve with the chosen ordering.
        let r = rel_err(&sym_mul(&s.col_ptr, &s.row_idx, &s.values, &x), &s.rhs);
        assert!(r < 1e-12, "residual {r}");
        // One thread for both METIS calls, and again on two: the same bits.
        for threads in [1, 2] {
            let (p, c, y) = run(threads);
            assert_eq!((p, c), (perm.clone(), Some(choice)));
            assert!(y.iter().zip(&x).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    #[test]
    fn zeroed_continues_or_cuts_a_prefaulted_start() {
        let longer = zeroed(vec![0.0; 3], 10).unwrap();
        assert_eq!(longer, vec![0.0; 10]);
        let shorter = zeroed(vec![0.0; 10], 4).unwrap();
        assert_eq!(shorter, vec![0.0; 4]);
        let done = AtomicBool::new(false);
        assert_eq!(prefault(5, &done), vec![0.0; 5]);
        done.store(true, AtomicOrdering::Relaxed);
        assert!(prefault(5, &done).is_empty());
    }

    #[test]
    fn empty_and_diagonal_matrices() {
        let mut chol = SparseCholesky::analyze(0, &[0], &[], None).unwrap();
        chol.factorize(&[]).unwrap();
        chol.solve_in_place(&mut []);
        let mut chol =
            SparseCholesky::analyze(3, &[0, 1, 2, 3], &[0, 1, 2], Some(&[0, 0, 1])).unwrap();
        chol.factorize(&[2.0, 4.0, 8.0]).unwrap();
        let mut x = [2.0, 2.0, 2.0];
        chol.solve_in_place(&mut x);
        assert!(rel_err(&x, &[1.0, 0.5, 0.25]) < 1e-15);
        assert_eq!(chol.stats().nnz_l, 3);
    }
}
