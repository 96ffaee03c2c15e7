//! Solving `(S + U Vᵀ) x = r` with a factored `S` and a few sparse columns `U`, `V` (the Woodbury identity): the unsymmetric part of a tangent on a symmetric factorization.
//!
//! `(S + U Vᵀ)⁻¹ r = y − Z (I + Vᵀ Z)⁻¹ Vᵀ y`, with `y = S⁻¹ r` and `Z = S⁻¹ U`: one solve
//! with `S` per column of `U` when the correction is formed, then one per right-hand side and
//! a dense solve of the size of the correction. Exact (to round-off), so Newton keeps its
//! quadratic convergence.

use crate::Real;

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
