//! Solves with a factored matrix minus sparse rank-one terms, by the Woodbury identity: the
//! factorization of `A₀` is kept and every solve with `A = A₀ − Σ kᵢ gᵢ gᵢᵀ` is corrected.
//!
//! With `G = [g₁ … g_r]`, `D = diag(kᵢ)`, `Z = A₀⁻¹ G` and `S = D⁻¹ − Gᵀ Z` (r × r):
//! `A⁻¹ = A₀⁻¹ + Z S⁻¹ Zᵀ` and `Zᵀ f = Gᵀ (A₀⁻¹ f)`. `S` is positive definite exactly when `A`
//! is (its Schur complement), so the pivot of each new row of `S`'s Cholesky factor tells
//! whether the removal leaves `A` singular. A removal costs one solve with `A₀` and `O(n r)`;
//! callers refactor `A` after some removals so that `r` stays small.
//!
//! The same identity serves an unsymmetric tangent on a symmetric factor: [`LowRankCorrection`]
//! solves `(S + U Vᵀ) x = r` as `y − Z (I + Vᵀ Z)⁻¹ Vᵀ y` with `y = S⁻¹ r` and `Z = S⁻¹ U` (the
//! slip of friction), exactly, so Newton keeps its quadratic convergence.

use super::tree_solve::{dot8, FactorColumn, ReachWork, SupernodalSolver};
use super::SparseCholesky;
use crate::Real;
use std::time::Instant;

/// A removal that would leave the matrix singular (or nearly): `1 − k gᵀ A⁻¹ g` fell to
/// `ratio`, at or below the tolerance.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("removing the rank-one term leaves the matrix singular (1 - k g'A^-1 g = {ratio:e})")]
pub struct SingularUpdate {
    /// `1 − k gᵀ A⁻¹ g` with `A` before the removal: 1 for a term that is not needed, 0 for
    /// one that was the only stiffness along `g`.
    pub ratio: Real,
}

/// The answer of [`LowRankUpdate::remove`]: what the removed term did to the solutions.
#[derive(Clone, Debug, PartialEq)]
pub struct Removal {
    /// `w = A⁻¹ g` with `A` before the removal (length n).
    pub w: Vec<Real>,
    /// `s = 1/k − gᵀ w > 0`: a solution `x` of `A x = f` becomes `x + w (gᵀ x)/s` after the
    /// removal (Sherman–Morrison).
    pub s: Real,
}

/// The Woodbury correction of solves with a factored `A₀` after removing sparse rank-one
/// terms `kᵢ gᵢ gᵢᵀ`. The base solve (`A₀⁻¹` in place) is passed to each call.
#[derive(Clone, Debug, Default)]
pub struct LowRankUpdate {
    n: usize,
    /// Each `gᵢ` as (index, value) pairs.
    terms: Vec<Vec<(usize, Real)>>,
    /// `Z = A₀⁻¹ G`, column after column (n per column).
    z: Vec<Real>,
    /// The Cholesky factor of `S`, row after row of its lower triangle (row i holds i + 1).
    l: Vec<Real>,
    /// Removals at or below this `1 − k gᵀ A⁻¹ g` are refused as singular.
    tolerance: Real,
}

impl LowRankUpdate {
    /// No terms removed yet from an n × n `A₀`; removals with `1 − k gᵀA⁻¹g ≤ tolerance`
    /// (e.g. 1e-9) are refused.
    pub fn new(n: usize, tolerance: Real) -> Self {
        LowRankUpdate {
            n,
            tolerance,
            ..Default::default()
        }
    }

    /// Terms removed since `A₀` was factored (the rank of the correction).
    pub fn rank(&self) -> usize {
        self.terms.len()
    }

    /// Forget every removal (after `A` was refactored with them).
    pub fn clear(&mut self) {
        self.terms.clear();
        self.z.clear();
        self.l.clear();
    }

    /// `Gᵀ x`.
    fn g_transpose(&self, x: &[Real]) -> Vec<Real> {
        self.terms
            .iter()
            .map(|g| g.iter().map(|&(i, v)| v * x[i]).sum())
            .collect()
    }

    /// `S⁻¹ c` with the stored factor (forward then back substitution).
    fn s_solve(&self, c: &mut [Real]) {
        capacitance_solve(&self.l, c);
    }

    /// `x += Z c`.
    fn add_z_times(&self, c: &[Real], x: &mut [Real]) {
        for (j, &cj) in c.iter().enumerate() {
            if cj != 0.0 {
                let col = &self.z[j * self.n..(j + 1) * self.n];
                x.iter_mut().zip(col).for_each(|(xi, zi)| *xi += cj * zi);
            }
        }
    }

    /// Replace `rhs` by `A⁻¹ rhs`, `A` the matrix after every removal so far.
    pub fn solve(&self, base: &mut dyn FnMut(&mut [Real]), rhs: &mut [Real]) {
        base(rhs);
        if self.terms.is_empty() {
            return;
        }
        let mut c = self.g_transpose(rhs);
        self.s_solve(&mut c);
        self.add_z_times(&c, rhs);
    }

    /// Remove `k g gᵀ` (`g` sparse: (index, value) pairs, `k > 0`) from the matrix, or refuse
    /// when that would leave it singular (nothing is changed then).
    pub fn remove(
        &mut self,
        base: &mut dyn FnMut(&mut [Real]),
        g: &[(usize, Real)],
        k: Real,
    ) -> Result<Removal, SingularUpdate> {
        let mut y = vec![0.0; self.n];
        for &(i, v) in g {
            y[i] += v;
        }
        base(&mut y);
        // c = Gᵀ y = Zᵀ g; w = y + Z S⁻¹ c is A⁻¹ g with the current A.
        let c = self.g_transpose(&y);
        let mut sc = c.clone();
        self.s_solve(&mut sc);
        let mut w = y.clone();
        self.add_z_times(&sc, &mut w);
        let s = 1.0 / k - g.iter().map(|&(i, v)| v * w[i]).sum::<Real>();
        let ratio = s * k;
        if ratio.is_nan() || ratio <= self.tolerance {
            return Err(SingularUpdate { ratio });
        }
        capacitance_row(&mut self.l, &c, s);
        self.z.extend_from_slice(&y);
        self.terms.push(g.to_vec());
        Ok(Removal { w, s })
    }
}

/// `S⁻¹ c` with `l` the Cholesky factor of `S`, row after row of its lower triangle (forward
/// then back substitution).
fn capacitance_solve(l: &[Real], c: &mut [Real]) {
    let r = c.len();
    let row = |i: usize| i * (i + 1) / 2;
    for i in 0..r {
        let li = &l[row(i)..row(i) + i + 1];
        let sum: Real = (0..i).map(|j| li[j] * c[j]).sum();
        c[i] = (c[i] - sum) / li[i];
    }
    for i in (0..r).rev() {
        let sum: Real = (i + 1..r).map(|j| l[row(j) + i] * c[j]).sum();
        c[i] = (c[i] - sum) / l[row(i) + i];
    }
}

/// Append to `l` (the factor of `S`, see [`capacitance_solve`]) the row of a new term whose
/// column of `S` above the diagonal is `−c` and whose Schur complement is `s`:
/// `l = L⁻¹ (−c)` and the pivot `√s`.
fn capacitance_row(l: &mut Vec<Real>, c: &[Real], s: Real) {
    let mut row: Vec<Real> = c.iter().map(|v| -v).collect();
    let r = row.len();
    for i in 0..r {
        let start = i * (i + 1) / 2;
        let sum: Real = (0..i).map(|j| l[start + j] * row[j]).sum();
        row[i] = (row[i] - sum) / l[start + i];
    }
    row.push(s.sqrt());
    l.extend_from_slice(&row);
}

/// [`LowRankUpdate`] kept in the factor's own space, for large supernodal factors: with
/// `A₀ = Pᵀ L Lᵀ P`, each removed term's column is `zᵢ = L⁻¹ P gᵢ`, nonzero only on the paths
/// from `gᵢ`'s rows to the root of the elimination tree (a few percent of the rows on a 3D
/// lattice), so `S = D⁻¹ − Zᵀ Z` takes sparse dot products, and `A⁻¹ f` is
/// `Pᵀ L⁻ᵀ (y + Z S⁻¹ Zᵀ y)` with `y = L⁻¹ P f`: one forward and ONE backward solve. A removal
/// costs a forward solve over those paths only ([`SupernodalSolver::forward_sparse`]), the
/// sparse combination and one backward solve (subtrees side by side), instead of a full solve
/// and `O(n r)`.
#[derive(Debug)]
pub struct FactorLowRankUpdate {
    solver: SupernodalSolver,
    /// `zᵢ = L⁻¹ P gᵢ`, sparse.
    z: Vec<FactorColumn>,
    /// The Cholesky factor of `S`, as in [`LowRankUpdate`].
    l: Vec<Real>,
    tolerance: Real,
    /// Dense workspace in the factor's order, zero between calls.
    x: Vec<Real>,
    work: ReachWork,
    /// Time in the sparse forward solves of removals, s.
    pub forward_seconds: Real,
    /// Time in the backward solves, s.
    pub backward_seconds: Real,
}

impl FactorLowRankUpdate {
    /// No terms removed yet from the factored `A₀` of `chol` (its structure; the values are
    /// read at each call, so refactoring on the same pattern keeps this valid after
    /// [`clear`](Self::clear)); removals with `1 − k gᵀA⁻¹g ≤ tolerance` are refused. `None`
    /// when the factor is not supernodal or small (see [`SupernodalSolver::new`]).
    pub fn new(chol: &SparseCholesky, tolerance: Real) -> Option<Self> {
        let solver = SupernodalSolver::new(chol)?;
        let n = solver.n();
        Some(FactorLowRankUpdate {
            solver,
            z: Vec::new(),
            l: Vec::new(),
            tolerance,
            x: vec![0.0; n],
            work: ReachWork::default(),
            forward_seconds: 0.0,
            backward_seconds: 0.0,
        })
    }

    /// Terms removed since `A₀` was factored.
    pub fn rank(&self) -> usize {
        self.z.len()
    }

    /// Forget every removal (after `A` was refactored with them).
    pub fn clear(&mut self) {
        self.z.clear();
        self.l.clear();
    }

    /// Stored entries of the columns `zᵢ` (the work of the sparse products per removal).
    pub fn stored_entries(&self) -> usize {
        self.z.iter().map(|z| z.rows.len()).sum()
    }

    /// `x += Z c`, then the backward solve, then the result in the original order into `out`;
    /// the workspace is zero again on return.
    fn finish(&mut self, l: &[f64], c: &[Real], out: &mut [Real]) {
        for (zj, &cj) in self.z.iter().zip(c) {
            if cj != 0.0 {
                zj.add_to(cj, &mut self.x);
            }
        }
        let t = Instant::now();
        self.solver.backward(l, &mut self.x);
        self.backward_seconds += t.elapsed().as_secs_f64();
        for (&old, x) in self.solver.permutation().iter().zip(self.x.iter_mut()) {
            out[old] = *x;
            *x = 0.0;
        }
    }

    /// Replace `rhs` by `A⁻¹ rhs`, `A` the matrix after every removal so far, with `chol`
    /// factored (the same factor as at the last [`clear`](Self::clear)).
    ///
    /// # Panics
    /// If `chol` is not factored or `rhs.len()` is not its size.
    pub fn solve(&mut self, chol: &SparseCholesky, rhs: &mut [Real]) {
        let l = chol
            .factor_values()
            .expect("FactorLowRankUpdate::solve needs a factored matrix");
        assert_eq!(
            rhs.len(),
            self.x.len(),
            "right-hand side of the wrong length"
        );
        for (x, &old) in self.x.iter_mut().zip(self.solver.permutation()) {
            *x = rhs[old];
        }
        self.solver.forward_dense(l, &mut self.x, &mut self.work);
        let mut c: Vec<Real> = self.z.iter().map(|z| z.dot_dense(&self.x)).collect();
        capacitance_solve(&self.l, &mut c);
        self.finish(l, &c, rhs);
    }

    /// Remove `k g gᵀ` (`g` sparse: (index, value) pairs, `k > 0`) from the matrix, or refuse
    /// when that would leave it singular (nothing is changed then); `chol` as in
    /// [`solve`](Self::solve).
    ///
    /// # Panics
    /// If `chol` is not factored.
    pub fn remove(
        &mut self,
        chol: &SparseCholesky,
        g: &[(usize, Real)],
        k: Real,
    ) -> Result<Removal, SingularUpdate> {
        let l = chol
            .factor_values()
            .expect("FactorLowRankUpdate::remove needs a factored matrix");
        let t = Instant::now();
        let z = self
            .solver
            .forward_sparse(l, g, &mut self.x, &mut self.work);
        self.forward_seconds += t.elapsed().as_secs_f64();
        // c = Zᵀ z = Gᵀ A₀⁻¹ g; gᵀ A⁻¹ g = z·z + cᵀ S⁻¹ c.
        let c: Vec<Real> = self.z.iter().map(|zj| zj.dot_dense(&self.x)).collect();
        let mut sc = c.clone();
        capacitance_solve(&self.l, &mut sc);
        let g_inv_g = dot8(&z.values, &z.values) + dot8(&c, &sc);
        let s = 1.0 / k - g_inv_g;
        let ratio = s * k;
        if ratio.is_nan() || ratio <= self.tolerance {
            for &r in &z.rows {
                self.x[r] = 0.0;
            }
            return Err(SingularUpdate { ratio });
        }
        // w = A⁻¹ g = Pᵀ L⁻ᵀ (z + Z S⁻¹ c), x holding z.
        let mut w = vec![0.0; self.x.len()];
        self.finish(l, &sc, &mut w);
        capacitance_row(&mut self.l, &c, s);
        self.z.push(z);
        Ok(Removal { w, s })
    }
}

/// A sparse vector: (row, value) pairs, rows repeated or not.
pub type SparseColumn = Vec<(usize, Real)>;

/// The Woodbury correction of a factored `S` for `U Vᵀ`, formed once per factorization.
pub struct LowRankCorrection {
    /// `Z = S⁻¹ U`, one dense column per pair.
    z: Vec<Vec<Real>>,
    /// The columns of `V`.
    v: Vec<SparseColumn>,
    /// LU of `I + Vᵀ Z`.
    lu: nalgebra::LU<Real, nalgebra::Dyn, nalgebra::Dyn>,
}

impl LowRankCorrection {
    /// The correction for the pairs `(u, v)` of `U Vᵀ = Σ u vᵀ`, with `solve` solving `S x = b`
    /// in place. `None` when there is no pair, or `I + Vᵀ S⁻¹ U` is singular (then `S + U Vᵀ`
    /// is too).
    pub fn new(
        n: usize,
        pairs: Vec<(SparseColumn, SparseColumn)>,
        mut solve: impl FnMut(&mut [Real]),
    ) -> Option<Self> {
        if pairs.is_empty() {
            return None;
        }
        let m = pairs.len();
        let mut z = Vec::with_capacity(m);
        let mut v = Vec::with_capacity(m);
        for (u, vc) in pairs {
            let mut col = vec![0.0; n];
            for (i, x) in u {
                col[i] += x;
            }
            solve(&mut col);
            z.push(col);
            v.push(vc);
        }
        let mut small = nalgebra::DMatrix::<Real>::identity(m, m);
        for (i, vi) in v.iter().enumerate() {
            for (j, zj) in z.iter().enumerate() {
                small[(i, j)] += vi.iter().map(|&(r, x)| x * zj[r]).sum::<Real>();
            }
        }
        let lu = small.lu();
        if !lu.is_invertible() {
            return None;
        }
        Some(LowRankCorrection { z, v, lu })
    }

    /// Pairs in the correction.
    pub fn len(&self) -> usize {
        self.z.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.z.is_empty()
    }

    /// Turn `y = S⁻¹ r` into `(S + U Vᵀ)⁻¹ r`, in place.
    pub fn correct(&self, y: &mut [Real]) {
        let vy = nalgebra::DVector::<Real>::from_iterator(
            self.v.len(),
            self.v
                .iter()
                .map(|vi| vi.iter().map(|&(r, x)| x * y[r]).sum::<Real>()),
        );
        let Some(c) = self.lu.solve(&vy) else {
            return;
        };
        for (zj, cj) in self.z.iter().zip(c.iter()) {
            for (yi, zi) in y.iter_mut().zip(zj) {
                *yi -= cj * zi;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};

    /// A small SPD matrix: a chain of springs k = 1..n to ground and between neighbours.
    fn chain(n: usize) -> DMatrix<Real> {
        let mut a = DMatrix::zeros(n, n);
        for i in 0..n {
            a[(i, i)] += 1.0 + i as Real;
            if i + 1 < n {
                let k = 2.0 + i as Real;
                a[(i, i)] += k;
                a[(i + 1, i + 1)] += k;
                a[(i, i + 1)] -= k;
                a[(i + 1, i)] -= k;
            }
        }
        a
    }

    #[test]
    fn solves_match_a_dense_solve_after_each_removal() {
        let n = 6;
        let a0 = chain(n);
        let inv0 = a0.clone().cholesky().unwrap();
        let mut base = |x: &mut [Real]| {
            let v = inv0.solve(&DVector::from_column_slice(x));
            x.copy_from_slice(v.as_slice());
        };
        let mut update = LowRankUpdate::new(n, 1e-9);
        let mut a = a0.clone();
        let f: Vec<Real> = (0..n).map(|i| 1.0 + (i * i) as Real).collect();
        // Remove the springs between 0-1, 3-4 and 2-3 in turn.
        for (p, k) in [(0usize, 2.0), (3, 5.0), (2, 4.0)] {
            let g = vec![(p, 1.0), (p + 1, -1.0)];
            let removal = update.remove(&mut base, &g, k).unwrap();
            // w = A⁻¹ g before the removal; s = 1/k − g·w.
            let mut gv = DVector::zeros(n);
            gv[p] = 1.0;
            gv[p + 1] = -1.0;
            let w = a.clone().cholesky().unwrap().solve(&gv);
            assert!((DVector::from_vec(removal.w.clone()) - &w).norm() < 1e-12);
            assert!((removal.s - (1.0 / k - gv.dot(&w))).abs() < 1e-12);
            a -= &gv * gv.transpose() * k;
            let mut x = f.clone();
            update.solve(&mut base, &mut x);
            let exact = a
                .clone()
                .cholesky()
                .unwrap()
                .solve(&DVector::from_vec(f.clone()));
            assert!((DVector::from_vec(x) - &exact).norm() < 1e-12 * exact.norm());
        }
        assert_eq!(update.rank(), 3);
    }

    #[test]
    fn removing_the_only_stiffness_is_refused() {
        // One spring k = 3 to ground: A = [3]; removing it leaves 0.
        let mut base = |x: &mut [Real]| x[0] /= 3.0;
        let mut update = LowRankUpdate::new(1, 1e-9);
        let err = update.remove(&mut base, &[(0, 1.0)], 3.0).unwrap_err();
        assert!(err.ratio.abs() < 1e-15);
        assert_eq!(update.rank(), 0);
        // Removing two thirds of it is fine: 1 − k/3 = 1/3.
        let removal = update.remove(&mut base, &[(0, 1.0)], 2.0).unwrap();
        assert!((removal.s * 2.0 - 1.0 / 3.0).abs() < 1e-15);
    }
}

#[cfg(test)]
mod factor_space_tests {
    use super::*;
    use crate::linalg::cholesky::CholeskyOptions;
    use crate::linkage::body_state::undeformed_axis;
    use crate::linkage::generators::lattice_body;
    use crate::linkage::{linear_member_block, member_stiffnesses, DofMap, StiffnessAssembly};

    fn max_diff(a: &[Real], b: &[Real]) -> Real {
        a.iter()
            .zip(b)
            .fold(0.0 as Real, |m, (x, y)| m.max((x - y).abs()))
    }

    fn max_abs(a: &[Real]) -> Real {
        a.iter().fold(0.0 as Real, |m, x| m.max(x.abs()))
    }

    /// Removing three members of a lattice large enough for the path (16×16×25 cells, 21,675
    /// DOFs) one after another: `w = A⁻¹ g`, `s` and a solve after the removals agree with
    /// the dense-column update on faer's solves to 1e-12.
    #[test]
    fn the_factor_space_update_matches_the_dense_one() {
        let body = lattice_body([16, 16, 25]).unwrap();
        let dofs = DofMap::new(&body);
        let asm = StiffnessAssembly::new(&body, &dofs).unwrap();
        let mut values = Vec::new();
        asm.fill(&body, |m| linear_member_block(&body, m), &mut values);
        let options = CholeskyOptions {
            threads: 2,
            ..Default::default()
        };
        let mut chol = SparseCholesky::analyze_with(
            asm.n,
            &asm.col_ptr,
            &asm.row_idx,
            Some(&asm.groups),
            options,
        )
        .unwrap();
        chol.factorize(&values).unwrap();
        let mut sparse = FactorLowRankUpdate::new(&chol, 1e-9).unwrap();
        let mut dense = LowRankUpdate::new(asm.n, 1e-9);
        let stiffness = member_stiffnesses(&body);
        let members = body.members.len();
        for m in [members / 3, members / 2, members / 2 + 7] {
            let [a, b] = body.members[m].nodes;
            let axis = undeformed_axis(&body, a, b);
            let mut g = Vec::new();
            for (sign, node) in [(-1.0, a), (1.0, b)] {
                for dir in 0..3 {
                    if let Some(i) = dofs.free_index(node, dir) {
                        g.push((i, sign * axis[dir]));
                    }
                }
            }
            assert_eq!(g.len(), 6, "member {m} is inside the lattice");
            let k = stiffness[m];
            let fs = sparse.remove(&chol, &g, k).unwrap();
            let ds = dense
                .remove(&mut |x| chol.solve_in_place(x), &g, k)
                .unwrap();
            let dw = max_diff(&fs.w, &ds.w);
            assert!(
                dw <= 1e-12 * max_abs(&ds.w),
                "member {m}: w differs by {dw:e}"
            );
            assert!(
                (fs.s - ds.s).abs() <= 1e-12 / k,
                "member {m}: s = {:e} against {:e}",
                fs.s,
                ds.s
            );
        }
        assert_eq!(sparse.rank(), 3);
        let f: Vec<Real> = (0..asm.n).map(|i| ((i % 7) as Real - 3.0) * 10.0).collect();
        let (mut x, mut y) = (f.clone(), f);
        sparse.solve(&chol, &mut x);
        dense.solve(&mut |v| chol.solve_in_place(v), &mut y);
        let d = max_diff(&x, &y);
        assert!(d <= 1e-12 * max_abs(&y), "solve differs by {d:e}");
        sparse.clear();
        assert_eq!((sparse.rank(), sparse.stored_entries()), (0, 0));
    }
}

#[cfg(test)]
mod unsymmetric_tests {
    use super::*;

    #[test]
    fn solves_a_diagonal_plus_two_unsymmetric_rank_one_terms_exactly() {
        // S = diag(2, 3, 4, 5); U Vᵀ = u1 v1ᵀ + u2 v2ᵀ.
        let d = [2.0, 3.0, 4.0, 5.0];
        let pairs = vec![
            (vec![(0, 1.0), (2, 0.5)], vec![(1, 2.0)]),
            (vec![(3, -1.0)], vec![(0, 1.0), (3, 0.25)]),
        ];
        let mut a =
            nalgebra::DMatrix::<Real>::from_diagonal(&nalgebra::DVector::from_row_slice(&d));
        for (u, v) in &pairs {
            for &(i, x) in u {
                for &(j, y) in v {
                    a[(i, j)] += x * y;
                }
            }
        }
        let solve = |b: &mut [Real]| b.iter_mut().zip(d).for_each(|(x, di)| *x /= di);
        let c = LowRankCorrection::new(4, pairs, solve).unwrap();
        let r = [1.0, -2.0, 0.5, 3.0];
        let mut x = r.to_vec();
        solve(&mut x);
        c.correct(&mut x);
        let back = &a * nalgebra::DVector::from_row_slice(&x);
        for (b, r) in back.iter().zip(r) {
            assert!((b - r).abs() < 1e-14, "{b} against {r}");
        }
    }
}
