//! The postorder of a candidates-last ordering, kept only while the candidates stay last.
//!
//! The tree-parallel factorization and solves ([`super::tree_cholesky`]) need every subtree of
//! the elimination tree contiguous, which a postorder gives. When the trailing DOFs (a body's
//! contact candidates) are joined into one tree with every leading DOF beside them, they form
//! its top and a postorder keeps them last, so the last block of the factor is still the
//! factor of their Schur complement. A leading part that hangs under trailing DOFs of another
//! tree (for example two pieces, each with candidates of its own) would be interleaved with
//! them; such an ordering is kept as it was, without the tree plan. (Large bodies first try
//! the node graph's analysis, whose own postorder `analyze_trailing` checks the same way; this
//! DOF-level postorder is the fallback when that check fails.)

use super::tree_cholesky::postorder;

/// The postorder of `(perm, inv)` (`perm[new] = old`, over the lower CSC pattern
/// `col_ptr`/`row_idx`) when the DOFs for which `trailing(dof)` holds are still the last ones
/// after it; `None` otherwise (the caller then keeps `(perm, inv)`).
pub(crate) fn postorder_keeping_trailing(
    col_ptr: &[usize],
    row_idx: &[usize],
    perm: &[usize],
    inv: &[usize],
    trailing: impl Fn(usize) -> bool,
) -> Option<(Vec<usize>, Vec<usize>)> {
    let m = perm.iter().filter(|&&d| trailing(d)).count();
    let (post, post_inv) = postorder(col_ptr, row_idx, perm, inv);
    post[post.len() - m..]
        .iter()
        .all(|&d| trailing(d))
        .then_some((post, post_inv))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::cholesky::tests::lower_csc;
    use crate::linalg::ordering::{
        expand_to_dofs, graph_of_pattern, nested_dissection_with_trailing,
    };
    use crate::linalg::SparseCholesky;
    use faer::linalg::solvers::DenseSolveCore;

    /// Grids of `nx × ny × nz` nodes, one after another (separate components), 3 DOFs per
    /// node coupled to the 6 neighbours by 3 × 3 blocks (`groups[dof] = node`): an SPD matrix
    /// (diagonally dominant) with the structure of a linkage body.
    fn grids(shapes: &[[usize; 3]]) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>, Vec<usize>) {
        let mut e = Vec::new();
        let mut base = 0;
        for &[nx, ny, nz] in shapes {
            let node = |x: usize, y: usize, z: usize| base + (z * ny + y) * nx + x;
            for z in 0..nz {
                for y in 0..ny {
                    for x in 0..nx {
                        let a = node(x, y, z);
                        for k in 0..3 {
                            e.push((3 * a + k, 3 * a + k, 20.0 + k as f64));
                        }
                        e.push((3 * a + 1, 3 * a, 0.5));
                        e.push((3 * a + 2, 3 * a + 1, -0.25));
                        let next = [
                            (x + 1 < nx).then(|| node(x + 1, y, z)),
                            (y + 1 < ny).then(|| node(x, y + 1, z)),
                            (z + 1 < nz).then(|| node(x, y, z + 1)),
                        ];
                        for (axis, b) in next.into_iter().enumerate() {
                            let Some(b) = b else { continue };
                            for k in 0..3 {
                                for l in 0..3 {
                                    let v = if k == l {
                                        -1.0 - 0.1 * axis as f64
                                    } else {
                                        0.05
                                    };
                                    e.push((3 * b + k, 3 * a + l, v));
                                }
                            }
                        }
                    }
                }
            }
            base += nx * ny * nz;
        }
        let n = 3 * base;
        let (c, r, v) = lower_csc(n, e);
        let groups = (0..n).map(|d| d / 3).collect();
        (n, c, r, v, groups)
    }

    fn is_permutation(perm: &[usize], inv: &[usize]) -> bool {
        let mut seen = vec![false; perm.len()];
        perm.iter()
            .all(|&p| p < seen.len() && !std::mem::replace(&mut seen[p], true))
            && perm.iter().enumerate().all(|(k, &p)| inv[p] == k)
    }

    /// `(perm, inv)`.
    type Order = (Vec<usize>, Vec<usize>);

    /// Candidates-last ordering of the grids, its postorder if it keeps them last.
    fn orderings(
        n: usize,
        col_ptr: &[usize],
        rows: &[usize],
        groups: &[usize],
        trailing: &[bool],
    ) -> (Order, Option<Order>) {
        let (x, a) = graph_of_pattern(n, col_ptr, rows, Some(groups), trailing.len()).unwrap();
        let (node_perm, _) = nested_dissection_with_trailing(&x, &a, trailing).unwrap();
        let (perm, inv) = expand_to_dofs(&node_perm, groups).unwrap();
        let post = postorder_keeping_trailing(col_ptr, rows, &perm, &inv, |d| trailing[groups[d]]);
        ((perm, inv), post)
    }

    /// Several components: a grid with candidates on one face, a grid without any and a
    /// lone node. The postorder is a permutation (every DOF once) with the candidates last;
    /// with candidates in two components their trees would interleave, and it is refused.
    #[test]
    fn postorder_of_several_components_is_a_permutation_with_candidates_last() {
        let (n, col_ptr, rows, _, groups) = grids(&[[5, 4, 3], [3, 3, 2], [1, 1, 1]]);
        let nodes = n / 3;
        // The z = 0 face of the first grid.
        let trailing: Vec<bool> = (0..nodes).map(|v| v < 20).collect();
        let ((perm, inv), post) = orderings(n, &col_ptr, &rows, &groups, &trailing);
        assert!(is_permutation(&perm, &inv));
        let (post, post_inv) = post.expect("one tree holds every candidate");
        assert!(is_permutation(&post, &post_inv));
        assert_ne!(post, perm, "the postorder regroups the ordering by trees");
        let m = 3 * 20;
        assert!(post[n - m..].iter().all(|&d| trailing[groups[d]]));
        assert!(post[..n - m].iter().all(|&d| !trailing[groups[d]]));
        // Candidates also on the second grid's z = 0 face: two trees under candidates.
        let both: Vec<bool> = (0..nodes)
            .map(|v| v < 20 || (60..69).contains(&v))
            .collect();
        let ((perm, inv), post) = orderings(n, &col_ptr, &rows, &groups, &both);
        assert!(is_permutation(&perm, &inv));
        assert!(post.is_none());
    }

    /// A body over the tree plan's size (24 × 24 × 12 nodes, 20,736 DOFs) with one face's 576
    /// nodes last: analysed on several threads (the node graph's analysis, tree-parallel
    /// factorization) its trailing block gives the same Schur complement `S = L₂₂ L₂₂ᵀ` as the
    /// sequential analysis without postorder (the path before), to 1e-12 of its largest entry,
    /// and its compliance `S⁻¹` the same to 1e-12 relative.
    #[test]
    fn tree_parallel_trailing_factor_gives_the_same_schur_complement() {
        let (n, col_ptr, rows, vals, groups) = grids(&[[24, 24, 12]]);
        let trailing: Vec<bool> = (0..n / 3).map(|v| v < 24 * 24).collect();
        let m = 3 * 24 * 24;
        let schur = |threads: usize| {
            let mut chol =
                SparseCholesky::analyze_trailing(n, &col_ptr, &rows, &groups, &trailing, threads)
                    .unwrap();
            let tree = chol.is_tree_parallel() && chol.has_node_structure();
            chol.factorize(&vals).unwrap();
            let (dofs, l) = chol.trailing_factor(m).unwrap();
            assert!(dofs.iter().all(|&d| trailing[groups[d]]));
            // In factor order; the two orderings may order the candidates differently.
            let s = &l * l.transpose();
            let c = s.llt(faer::Side::Lower).unwrap().inverse();
            (tree, dofs, s, c)
        };
        let (tree, d1, s1, c1) = schur(0);
        let (seq, d2, s2, c2) = schur(1);
        assert!(tree && !seq);
        let largest = |a: &faer::Mat<f64>| {
            let mut w: f64 = 0.0;
            for j in 0..m {
                for i in 0..m {
                    w = w.max(a[(i, j)].abs());
                }
            }
            w
        };
        // Entry (i, j) of the first is DOFs (d1[i], d1[j]); find them in the second.
        let mut at2 = vec![0; n];
        d2.iter().enumerate().for_each(|(k, &d)| at2[d] = k);
        let diff = |a: &faer::Mat<f64>, b: &faer::Mat<f64>| {
            let mut w: f64 = 0.0;
            for j in 0..m {
                for i in 0..m {
                    w = w.max((a[(i, j)] - b[(at2[d1[i]], at2[d1[j]])]).abs());
                }
            }
            w
        };
        let (ds, dc) = (diff(&s1, &s2) / largest(&s2), diff(&c1, &c2) / largest(&c2));
        eprintln!("Schur complement {ds:.1e}, compliance {dc:.1e} of the largest entry");
        assert!(ds < 1e-12, "Schur complements differ by {ds:.1e}");
        assert!(dc < 1e-12, "compliances differ by {dc:.1e}");
    }

    /// A body over the tree plan's size (24 × 24 × 12 nodes, 20,736 DOFs) with a 6 × 6 patch
    /// of one face last, analysed for two threads: it takes the node graph's analysis and the
    /// tree path, and its trailing block gives `L₂₂ L₂₂ᵀ` equal to the Schur complement
    /// `S = A₂₂ − A₂₁ A₁₁⁻¹ A₁₂` formed column by column from solves with `A₁₁` alone (faer's
    /// sequential factorization of the leading DOFs, another code path), to 1e-10 of S's
    /// largest entry.
    #[test]
    fn node_path_trailing_factor_is_the_factor_of_the_schur_complement() {
        let (n, col_ptr, rows, vals, groups) = grids(&[[24, 24, 12]]);
        assert!(n >= crate::linalg::tree_cholesky::MIN_TREE_DOFS);
        let trailing: Vec<bool> = (0..n / 3).map(|v| v < 24 * 6 && v % 24 < 6).collect();
        let m = 3 * 36;
        let mut chol =
            SparseCholesky::analyze_trailing(n, &col_ptr, &rows, &groups, &trailing, 2).unwrap();
        assert!(chol.has_node_structure() && chol.is_tree_parallel());
        chol.factorize(&vals).unwrap();
        let (dofs, l) = chol.trailing_factor(m).unwrap();
        assert!(dofs.iter().all(|&d| trailing[groups[d]]));
        // Local numbers: leading DOFs ascending, trailing DOFs in the factor's order.
        let mut local = vec![usize::MAX; n];
        let leading: Vec<usize> = (0..n).filter(|&d| !trailing[groups[d]]).collect();
        leading.iter().enumerate().for_each(|(k, &d)| local[d] = k);
        let mut slot = vec![usize::MAX; n];
        dofs.iter().enumerate().for_each(|(k, &d)| slot[d] = k);
        let nl = n - m;
        let mut e11 = Vec::new();
        let mut a12 = vec![vec![0.0; nl]; m];
        let mut s = faer::Mat::<f64>::zeros(m, m);
        for c in 0..n {
            for p in col_ptr[c]..col_ptr[c + 1] {
                let (r, v) = (rows[p], vals[p]);
                match (slot[r], slot[c]) {
                    (usize::MAX, usize::MAX) => e11.push((local[r], local[c], v)),
                    (usize::MAX, j) => a12[j][local[r]] += v,
                    (i, usize::MAX) => a12[i][local[c]] += v,
                    (i, j) => {
                        s[(i, j)] = v;
                        s[(j, i)] = v;
                    }
                }
            }
        }
        let (c11, r11, v11) = lower_csc(nl, e11);
        let options = crate::linalg::cholesky::CholeskyOptions {
            threads: 1,
            ..Default::default()
        };
        let mut a11 = SparseCholesky::analyze_with(nl, &c11, &r11, None, options).unwrap();
        assert!(!a11.is_tree_parallel());
        a11.factorize(&v11).unwrap();
        for j in 0..m {
            let mut x = a12[j].clone();
            a11.solve_in_place(&mut x);
            for i in 0..m {
                s[(i, j)] -= a12[i].iter().zip(&x).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        let llt = &l * l.transpose();
        let (mut worst, mut largest): (f64, f64) = (0.0, 0.0);
        for j in 0..m {
            for i in 0..m {
                worst = worst.max((llt[(i, j)] - s[(i, j)]).abs());
                largest = largest.max(s[(i, j)].abs());
            }
        }
        eprintln!("L22 L22ᵀ − S: {:.1e} of the largest entry", worst / largest);
        assert!(
            worst < 1e-10 * largest,
            "L22 L22ᵀ differs from the Schur complement by {:.1e} of its largest entry",
            worst / largest
        );
        assert!((0..m).all(|i| (i + 1..m).all(|j| l[(i, j)] == 0.0)));
    }
}
