//! Symbolic analysis of a factor whose rows come in nodes, done on the node graph.
//!
//! The DOFs of a node share their structure, so the elimination tree, the column counts and
//! the supernodes of the DOF matrix follow from those of the node graph (3× fewer columns,
//! about 1/9 of the entries of L to walk for 3 DOFs a node): faer's supernodal analysis of
//! the node graph, ordered by the postorder of its elimination tree, is expanded here to
//! DOFs, each node standing for a dense block of its DOFs. The structure is exact where
//! coupled nodes couple in all their DOFs (a linkage's stiffness) and a superset of the
//! DOF matrix's fill otherwise (extra entries are explicit zeros, which the factorization
//! fills correctly). Used by the tree path of [`SparseCholesky`](super::SparseCholesky) in
//! place of faer's analysis of the DOF matrix (0.45 s of the 40³ lattice's analysis).

use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::{SupernodalThreshold, SymbolicSupernodalParams};
use faer::sparse::SymbolicSparseColMat;
use faer::Side;

use super::cholesky::CholeskyError;
use super::ordering::expand_to_dofs;
use super::tree_cholesky::{postorder, SupernodeArrays};

/// faer's relaxed amalgamation thresholds, `(combined columns, fraction of zeros)`, with
/// columns counted in nodes instead of DOFs: faer's defaults are (4, 1.0), (16, 0.8),
/// (48, 0.1), (any, 0.05) in DOFs; a node is 3 DOFs (the first rule never applies to 3-DOF
/// nodes), and the fraction of zeros is the same in nodes as in DOFs.
const NODE_RELAX: &[(usize, f64)] = &[(5, 0.8), (16, 0.1), (usize::MAX, 0.05)];

/// A symbolic factor from the node graph: its supernodes over DOFs and the DOF ordering.
#[derive(Debug)]
pub(crate) struct NodeSymbolic {
    /// The supernodes, in the permuted DOF order.
    pub arrays: SupernodeArrays,
    /// `perm[new] = old` over DOFs: the node ordering, postordered, expanded to DOFs.
    pub perm: Vec<usize>,
    /// `inv[old] = new`.
    pub inv: Vec<usize>,
}

/// The supernodal structure of the `n`-DOF matrix whose node graph is `(xadj, adjncy)`
/// (symmetric, no self loops, as [`graph_of_pattern`](super::ordering::graph_of_pattern)
/// gives it) ordered by `node_perm` (`node_inv` its inverse), `groups[dof] = node` (`None`:
/// a node is a DOF). The node ordering is postordered first (the same fill), so that every
/// subtree's supernodes are contiguous, as the tree factorization needs. Nodes without DOFs
/// (fully supported) drop out.
pub(crate) fn node_symbolic(
    n: usize,
    xadj: &[usize],
    adjncy: &[usize],
    node_perm: &[usize],
    node_inv: &[usize],
    groups: Option<&[usize]>,
) -> Result<NodeSymbolic, CholeskyError> {
    let n_nodes = node_perm.len();
    // The node graph's lower triangle (CSC, the diagonal first, rows ascending).
    let mut col_ptr = Vec::with_capacity(n_nodes + 1);
    let mut row_idx = Vec::with_capacity(n_nodes + adjncy.len() / 2);
    col_ptr.push(0);
    for j in 0..n_nodes {
        row_idx.push(j);
        let start = row_idx.len();
        row_idx.extend(adjncy[xadj[j]..xadj[j + 1]].iter().filter(|&&i| i > j));
        row_idx[start..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    let (perm, inv) = postorder(&col_ptr, &row_idx, node_perm, node_inv);
    let pattern = SymbolicSparseColMat::new_checked(n_nodes, n_nodes, col_ptr, None, row_idx);
    let params = CholeskySymbolicParams {
        supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
        supernodal_params: SymbolicSupernodalParams {
            relax: Some(NODE_RELAX),
        },
        ..Default::default()
    };
    let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&perm, &inv, n_nodes));
    let symbolic = factorize_symbolic_cholesky(pattern.as_ref(), Side::Lower, ordering, params)
        .map_err(|e| CholeskyError::Resources(format!("symbolic factorization: {e:?}")))?;
    let SymbolicCholeskyRaw::Supernodal(s) = symbolic.raw() else {
        return Err(CholeskyError::Resources(
            "the node graph's analysis is not supernodal".into(),
        ));
    };

    // First DOF of each permuted node.
    let mut size = vec![0usize; n_nodes];
    match groups {
        Some(g) => g.iter().for_each(|&node| size[node] += 1),
        None => size.fill(1),
    }
    let mut offset = Vec::with_capacity(n_nodes + 1);
    offset.push(0);
    for &old in &perm {
        offset.push(offset.last().copied().unwrap_or(0) + size[old]);
    }
    if offset[n_nodes] != n {
        return Err(CholeskyError::InvalidInput(format!(
            "the groups give {} DOFs for {n}",
            offset[n_nodes]
        )));
    }
    let (dof_perm, dof_inv) = match groups {
        Some(g) => expand_to_dofs(&perm, g)?,
        None => (perm, inv),
    };

    // Each node supernode, expanded; those of nodes without DOFs vanish.
    let ns = s.n_supernodes();
    let (node_begin, node_end) = (s.supernode_begin(), s.supernode_end());
    let mut begin = Vec::with_capacity(ns + 1);
    let mut pattern_ptr = Vec::with_capacity(ns + 1);
    let mut rows = Vec::new();
    let mut val_ptr = Vec::with_capacity(ns + 1);
    pattern_ptr.push(0);
    val_ptr.push(0);
    for k in 0..ns {
        let (db, de) = (offset[node_begin[k]], offset[node_end[k]]);
        if db == de {
            continue;
        }
        begin.push(db);
        for &r in s.supernode(k).pattern() {
            rows.extend(offset[r]..offset[r + 1]);
        }
        pattern_ptr.push(rows.len());
        let w = de - db;
        let below = pattern_ptr[pattern_ptr.len() - 1] - pattern_ptr[pattern_ptr.len() - 2];
        val_ptr.push(val_ptr[val_ptr.len() - 1] + w * (w + below));
    }
    begin.push(n);
    let mut super_of = vec![0usize; n];
    for k in 0..begin.len() - 1 {
        super_of[begin[k]..begin[k + 1]].fill(k);
    }
    Ok(NodeSymbolic {
        arrays: SupernodeArrays {
            begin,
            pattern_ptr,
            pattern: rows,
            val_ptr,
            super_of,
        },
        perm: dof_perm,
        inv: dof_inv,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench::cholmod::{lattice_system, relative_residual, LowerSystem};
    use crate::linalg::cholesky::{
        symbolic_analysis, CholeskyOptions, FactorLayout, SparseCholesky,
    };
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::SparseColMatRef;
    use faer::Par;

    fn two_threads() -> CholeskyOptions {
        CholeskyOptions {
            threads: 2,
            ..Default::default()
        }
    }

    /// Factor of `s` by faer's own analysis and loop with the ordering `perm`, as supernode
    /// arrays and values.
    fn faers_factor(s: &LowerSystem, perm: &[usize]) -> (SupernodeArrays, Vec<f64>) {
        let mut inv = vec![0; s.n];
        for (new, &old) in perm.iter().enumerate() {
            inv[old] = new;
        }
        let options = CholeskyOptions {
            layout: FactorLayout::Supernodal,
            threads: 1,
            ..Default::default()
        };
        let (pattern, symbolic) = symbolic_analysis(
            s.n,
            &s.col_ptr,
            &s.row_idx,
            Some((perm.to_vec(), inv)),
            options,
        )
        .unwrap();
        let mut l = vec![0.0; symbolic.len_val()];
        let mut mem = MemBuffer::new(
            symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()),
        );
        symbolic
            .factorize_numeric_llt(
                &mut l,
                SparseColMatRef::new(pattern.as_ref(), &s.values),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .unwrap();
        let SymbolicCholeskyRaw::Supernodal(sup) = symbolic.raw() else {
            panic!("not supernodal")
        };
        (SupernodeArrays::new(sup), l)
    }

    /// Column `j` of a supernodal factor: (row, value) pairs, rows ascending.
    fn column(a: &SupernodeArrays, l: &[f64], j: usize) -> Vec<(usize, f64)> {
        let k = a.super_of[j];
        let (b, e) = (a.begin[k], a.begin[k + 1]);
        let (w, c) = (e - b, j - b);
        let rows = w + a.pattern(k).len();
        let col = &l[a.val_ptr[k] + c * rows..a.val_ptr[k] + (c + 1) * rows];
        (j..e)
            .zip(&col[c..w])
            .chain(a.pattern(k).iter().copied().zip(&col[w..]))
            .map(|(r, &v)| (r, v))
            .collect()
    }

    /// The node graph's factor is faer's factor with the same ordering: the entries both
    /// store agree to 1e-12 of the largest entry, and those only one of them stores (zeros of
    /// amalgamation, or of node blocks that are not full) are zero to the same tolerance; the solve of the tree path
    /// reaches a residual under 1e-12; and a second analysis and factorization give the same
    /// ordering, structure and solution bits.
    fn check_against_faer(s: &LowerSystem) {
        let mut chol = SparseCholesky::analyze_with(
            s.n,
            &s.col_ptr,
            &s.row_idx,
            s.groups.as_deref(),
            two_threads(),
        )
        .unwrap();
        assert!(chol.has_node_structure() && chol.is_tree_parallel());
        chol.factorize(&s.values).unwrap();
        let ours = chol.supernode_arrays().unwrap();
        let l = chol.factor_values().unwrap().to_vec();
        let (theirs, lf) = faers_factor(s, chol.permutation());
        let scale = lf.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut dense = vec![f64::NAN; s.n];
        let (mut worst, mut extra, mut shared, mut faers_zeros) = (0.0f64, 0usize, 0usize, 0usize);
        for j in 0..s.n {
            let mine = column(&ours, &l, j);
            for &(r, v) in &mine {
                dense[r] = v;
            }
            for (r, v) in column(&theirs, &lf, j) {
                if dense[r].is_nan() {
                    // A zero of faer's amalgamation outside the node structure.
                    worst = worst.max(v.abs());
                    faers_zeros += 1;
                } else {
                    worst = worst.max((dense[r] - v).abs());
                    dense[r] = f64::NAN;
                    shared += 1;
                }
            }
            for &(r, v) in &mine {
                if !dense[r].is_nan() {
                    // An entry faer does not store: zero in exact arithmetic.
                    worst = worst.max(v.abs());
                    extra += 1;
                    dense[r] = f64::NAN;
                }
            }
        }
        assert!(
            worst <= 1e-12 * scale,
            "L differs by {worst:e} of {scale:e}"
        );
        assert_eq!(shared + extra, ours.nnz());
        assert_eq!(shared + faers_zeros, theirs.nnz());
        println!(
            "n = {}: nnz(L) {} (node structure) against {} (faer), {} supernodes against {}, flops {:.3e} against {:.3e}; \
             entries only in ours {extra}, only in faer's {faers_zeros}",
            s.n,
            ours.nnz(),
            theirs.nnz(),
            ours.len(),
            theirs.len(),
            ours.flops(),
            theirs.flops()
        );
        let mut x = s.rhs.clone();
        chol.solve_in_place(&mut x);
        let r = relative_residual(s, &x);
        assert!(r < 1e-12, "residual {r:e}");
        // The same input, the same bits.
        let mut again = SparseCholesky::analyze_with(
            s.n,
            &s.col_ptr,
            &s.row_idx,
            s.groups.as_deref(),
            two_threads(),
        )
        .unwrap();
        assert_eq!(again.permutation(), chol.permutation());
        assert_eq!(again.supernode_arrays().unwrap(), ours);
        again.factorize(&s.values).unwrap();
        let mut y = s.rhs.clone();
        again.solve_in_place(&mut y);
        assert!(x.iter().zip(&y).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn node_structure_of_a_lattice_is_faers_factor() {
        // 16×16×25 cells: 21,675 free DOFs, above MIN_TREE_DOFS.
        let (s, _) = lattice_system([16, 16, 25]).unwrap();
        check_against_faer(&s);
    }

    /// A jittered irregular mesh: nodes with 4 to 26 neighbours, some DOFs held (removed), some
    /// nodes without any DOF, and couplings whose 3×3 blocks are not full, so that the node
    /// structure is a strict superset of the DOF fill in places.
    #[test]
    fn node_structure_of_an_irregular_mesh_is_faers_factor() {
        let m = 21usize;
        let hash = |a: usize, b: usize| {
            let mut h = (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (b as u64);
            h ^= h >> 29;
            h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
            (h ^ (h >> 32)) as usize
        };
        let node = |x: usize, y: usize, z: usize| (z * m + y) * m + x;
        let nodes = m * m * m;
        // DOF index of (node, direction), None when held.
        let mut dof = vec![[None; 3]; nodes];
        let mut groups = Vec::new();
        for (v, d) in dof.iter_mut().enumerate() {
            let all_held = hash(v, 99) % 23 == 0;
            for (k, slot) in d.iter_mut().enumerate() {
                if !all_held && hash(v, k) % 9 != 0 {
                    *slot = Some(groups.len());
                    groups.push(v);
                }
            }
        }
        let n = groups.len();
        assert!(n >= 20_000, "{n} DOFs");
        let mut entries: Vec<(usize, usize, f64)> = Vec::new();
        let mut diag = vec![1.0; n];
        for z in 0..m {
            for y in 0..m {
                for x in 0..m {
                    let v = node(x, y, z);
                    for (dx, dy, dz) in (0..27).map(|t| (t % 3, (t / 3) % 3, t / 9)) {
                        let (ux, uy, uz) = (x + dx, y + dy, z + dz);
                        if (dx, dy, dz) == (0, 0, 0) || ux < 1 || uy < 1 || uz < 1 {
                            continue;
                        }
                        let (ux, uy, uz) = (ux - 1, uy - 1, uz - 1);
                        if ux >= m || uy >= m || uz >= m {
                            continue;
                        }
                        let u = node(ux, uy, uz);
                        // Each link once, about half of them kept.
                        if u <= v || hash(v * 31 + u, 7) % 2 == 0 {
                            continue;
                        }
                        for (a, &i) in dof[v].iter().enumerate() {
                            for (b, &j) in dof[u].iter().enumerate() {
                                let (Some(i), Some(j)) = (i, j) else { continue };
                                // Some block entries absent.
                                if (a + b + hash(u, v)) % 4 == 0 {
                                    continue;
                                }
                                let w = -0.1 - 0.01 * (hash(i, j) % 10) as f64;
                                entries.push((i.max(j), i.min(j), w));
                                diag[i] += w.abs();
                                diag[j] += w.abs();
                            }
                        }
                    }
                }
            }
        }
        entries.extend(diag.iter().enumerate().map(|(i, &d)| (i, i, d)));
        entries.sort_by_key(|&(i, j, _)| (j, i));
        entries.dedup_by(|b, a| {
            if (a.0, a.1) == (b.0, b.1) {
                a.2 += b.2;
                true
            } else {
                false
            }
        });
        let mut col_ptr = vec![0usize; n + 1];
        for &(_, j, _) in &entries {
            col_ptr[j + 1] += 1;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        let s = LowerSystem {
            n,
            col_ptr,
            row_idx: entries.iter().map(|e| e.0).collect(),
            values: entries.iter().map(|e| e.2).collect(),
            rhs: (0..n).map(|i| ((i * 7) % 13) as f64 - 6.0).collect(),
            groups: Some(groups),
        };
        check_against_faer(&s);
    }
}
