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

use crate::Real;

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
        let r = c.len();
        let row = |i: usize| i * (i + 1) / 2;
        for i in 0..r {
            let li = &self.l[row(i)..row(i) + i + 1];
            let sum: Real = (0..i).map(|j| li[j] * c[j]).sum();
            c[i] = (c[i] - sum) / li[i];
        }
        for i in (0..r).rev() {
            let sum: Real = (i + 1..r).map(|j| self.l[row(j) + i] * c[j]).sum();
            c[i] = (c[i] - sum) / self.l[row(i) + i];
        }
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
        // The new row of L: l = L⁻¹ (−c) and its pivot √(1/k − gᵀy − l·l) = √s.
        let mut l: Vec<Real> = c.iter().map(|v| -v).collect();
        let r = l.len();
        for i in 0..r {
            let start = i * (i + 1) / 2;
            let sum: Real = (0..i).map(|j| self.l[start + j] * l[j]).sum();
            l[i] = (l[i] - sum) / self.l[start + i];
        }
        l.push(s.sqrt());
        self.l.extend_from_slice(&l);
        self.z.extend_from_slice(&y);
        self.terms.push(g.to_vec());
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
