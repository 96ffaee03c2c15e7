//! `K_ff` in full compressed rows for the iterative solver: both triangles stored, so the
//! matrix–vector product runs row by row on every core with no write conflicts.

use crate::Real;
use rayon::prelude::*;

/// Rows handed to one task in the parallel loops: large enough to amortise scheduling,
/// small enough to balance two cores.
const ROWS_PER_TASK: usize = 2048;

/// A symmetric matrix stored in full compressed rows (both triangles), built from the
/// lower-triangle compressed columns of a stiffness assembly. Its pattern is
/// built once; `refill` copies new values through a stored map.
#[derive(Clone, Debug)]
pub struct SymmetricCsr {
    /// Rows and columns.
    pub n: usize,
    /// Row starts, length `n + 1`.
    pub row_ptr: Vec<usize>,
    /// Column of each entry, ascending within a row.
    pub col: Vec<u32>,
    /// Value of each entry.
    pub val: Vec<Real>,
    /// For each entry of `val`, the lower-triangle entry it copies: refilling is a gather,
    /// every entry written once, in parallel.
    source: Vec<u32>,
}

impl SymmetricCsr {
    /// The full pattern of the symmetric matrix whose lower triangle is `col_ptr`/`row_idx`
    /// (compressed columns, diagonal present); values zero until [`SymmetricCsr::refill`].
    pub fn from_lower(n: usize, col_ptr: &[usize], row_idx: &[usize]) -> Self {
        let mut count = vec![0usize; n + 1];
        for c in 0..n {
            for &r in &row_idx[col_ptr[c]..col_ptr[c + 1]] {
                count[r + 1] += 1;
                if r != c {
                    count[c + 1] += 1;
                }
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let row_ptr = count.clone();
        let nnz = row_ptr[n];
        let mut next = count;
        let mut col = vec![0u32; nnz];
        let mut source = vec![0u32; nnz];
        // Column by column, so every row receives its columns in ascending order.
        for c in 0..n {
            for (k, &r) in row_idx[col_ptr[c]..col_ptr[c + 1]].iter().enumerate() {
                let e = col_ptr[c] + k;
                let lower = next[r];
                col[lower] = c as u32;
                next[r] += 1;
                source[lower] = e as u32;
                if r != c {
                    let p = next[c];
                    col[p] = r as u32;
                    source[p] = e as u32;
                    next[c] += 1;
                }
            }
        }
        // Row i receives its columns j < i while columns j are visited, then i and every r > i
        // while column i is visited (rows ascending, diagonal first): sorted by construction.
        let csr = SymmetricCsr {
            n,
            row_ptr,
            col,
            val: vec![0.0; nnz],
            source,
        };
        csr.check_sorted();
        csr
    }

    /// The symmetric matrix whose lower triangle is `col_ptr`/`row_idx`/`lower_values`, without
    /// the map [`SymmetricCsr::refill`] needs: a third less memory for a matrix filled once
    /// (a linear body's `K_ff`), whose refill map would outlive its only use.
    pub fn from_lower_values(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        lower_values: &[Real],
    ) -> Self {
        let mut csr = Self::from_lower(n, col_ptr, row_idx);
        csr.refill(lower_values);
        csr.source = Vec::new();
        csr
    }

    /// A matrix given directly by its full rows (columns ascending in each row); it has no
    /// lower-triangle map, so [`SymmetricCsr::refill`] does not apply to it.
    pub fn from_rows(n: usize, row_ptr: Vec<usize>, col: Vec<u32>, val: Vec<Real>) -> Self {
        let csr = SymmetricCsr {
            n,
            row_ptr,
            col,
            val,
            source: Vec::new(),
        };
        csr.check_sorted();
        csr
    }

    fn check_sorted(&self) {
        debug_assert!((0..self.n).all(|i| {
            self.col[self.row_ptr[i]..self.row_ptr[i + 1]]
                .windows(2)
                .all(|w| w[0] < w[1])
        }));
    }

    /// Copy the lower-triangle values (in the assembly's order) into both triangles. Only for a
    /// matrix made by [`SymmetricCsr::from_lower`], which keeps the map.
    pub fn refill(&mut self, lower_values: &[Real]) {
        debug_assert_eq!(self.source.len(), self.val.len(), "no refill map");
        self.val
            .par_chunks_mut(ROWS_PER_TASK * 32)
            .zip(self.source.par_chunks(ROWS_PER_TASK * 32))
            .for_each(|(values, sources)| {
                for (v, &e) in values.iter_mut().zip(sources) {
                    *v = lower_values[e as usize];
                }
            });
    }

    /// The lower-triangle values in the order they were given to [`SymmetricCsr::refill`].
    pub fn lower_values(&self, count: usize) -> Vec<Real> {
        let mut lower = vec![0.0; count];
        for (&v, &e) in self.val.iter().zip(&self.source) {
            if let Some(slot) = lower.get_mut(e as usize) {
                *slot = v;
            }
        }
        lower
    }

    /// The diagonal entry of every row.
    pub fn diagonal(&self) -> Vec<Real> {
        (0..self.n)
            .into_par_iter()
            .with_min_len(ROWS_PER_TASK)
            .map(|i| {
                let start = self.row_ptr[i];
                self.col[start..self.row_ptr[i + 1]]
                    .binary_search(&(i as u32))
                    .map_or(0.0, |k| self.val[start + k])
            })
            .collect()
    }

    /// `y = A x`, rows in parallel; each row is summed in a fixed order, so the result does
    /// not depend on the number of threads.
    pub fn multiply(&self, x: &[Real], y: &mut [Real]) {
        self.for_each_row_product(x, y, |yi, ax| *yi = ax);
    }

    /// `r = b − A x` in one pass.
    pub fn residual(&self, b: &[Real], x: &[Real], r: &mut [Real]) {
        r.copy_from_slice(b);
        self.subtract_product(x, r);
    }

    /// `r −= A x` in one pass.
    pub fn subtract_product(&self, x: &[Real], r: &mut [Real]) {
        self.for_each_row_product(x, r, |ri, ax| *ri -= ax);
    }

    /// Calls `update(y_i, (A x)_i)` for every row, rows in parallel.
    fn for_each_row_product(
        &self,
        x: &[Real],
        y: &mut [Real],
        update: impl Fn(&mut Real, Real) + Sync,
    ) {
        y.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let first = chunk * ROWS_PER_TASK;
                for (k, yi) in out.iter_mut().enumerate() {
                    let i = first + k;
                    let range = self.row_ptr[i]..self.row_ptr[i + 1];
                    update(yi, row_times(&self.col[range.clone()], &self.val[range], x));
                }
            });
    }
}

/// `Σ val_k x[col_k]` with four interleaved partial sums (a single chain of additions would
/// bound the product by the adder's latency, not by memory), combined in a fixed order.
#[inline(always)]
fn row_times(col: &[u32], val: &[Real], x: &[Real]) -> Real {
    let mut acc = [0.0; 4];
    let mut cols = col.chunks_exact(4);
    let mut vals = val.chunks_exact(4);
    for (c, v) in (&mut cols).zip(&mut vals) {
        for k in 0..4 {
            acc[k] += v[k] * x[c[k] as usize];
        }
    }
    let mut sum = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (&c, &v) in cols.remainder().iter().zip(vals.remainder()) {
        sum += v * x[c as usize];
    }
    sum
}

/// `Σ a_i b_i`, summed in fixed chunks whose partial sums are added in order: the same
/// result whatever the number of threads.
pub fn dot(a: &[Real], b: &[Real]) -> Real {
    let partials: Vec<Real> = a
        .par_chunks(ROWS_PER_TASK)
        .zip(b.par_chunks(ROWS_PER_TASK))
        .map(|(x, y)| x.iter().zip(y).map(|(p, q)| p * q).sum::<Real>())
        .collect();
    partials.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_rows_match_the_lower_triangle() {
        // Lower triangle of [[4, 1, 0], [1, 5, 2], [0, 2, 6]] in compressed columns.
        let col_ptr = [0, 2, 4, 5];
        let row_idx = [0, 1, 1, 2, 2];
        let mut a = SymmetricCsr::from_lower(3, &col_ptr, &row_idx);
        a.refill(&[4.0, 1.0, 5.0, 2.0, 6.0]);
        assert_eq!(a.row_ptr, vec![0, 2, 5, 7]);
        assert_eq!(a.col, vec![0, 1, 0, 1, 2, 1, 2]);
        assert_eq!(a.diagonal(), vec![4.0, 5.0, 6.0]);
        assert_eq!(a.val, vec![4.0, 1.0, 1.0, 5.0, 2.0, 2.0, 6.0]);
        assert_eq!(a.lower_values(5), vec![4.0, 1.0, 5.0, 2.0, 6.0]);
        let mut r = vec![0.0; 3];
        a.residual(&[10.0, 20.0, 30.0], &[1.0, 2.0, 3.0], &mut r);
        assert_eq!(r, vec![4.0, 3.0, 8.0]);
        let mut y = vec![0.0; 3];
        a.multiply(&[1.0, 2.0, 3.0], &mut y);
        assert_eq!(y, vec![6.0, 17.0, 22.0]);
        assert_eq!(dot(&[1.0, 2.0, 3.0], &[4.0, 5.0, 6.0]), 32.0);
    }

    #[test]
    fn filled_once_equals_refilled_and_keeps_no_map() {
        let col_ptr = [0, 2, 4, 5];
        let row_idx = [0, 1, 1, 2, 2];
        let lower = [4.0, 1.0, 5.0, 2.0, 6.0];
        let mut refilled = SymmetricCsr::from_lower(3, &col_ptr, &row_idx);
        refilled.refill(&lower);
        let once = SymmetricCsr::from_lower_values(3, &col_ptr, &row_idx, &lower);
        assert_eq!(once.row_ptr, refilled.row_ptr);
        assert_eq!(once.col, refilled.col);
        assert_eq!(once.val, refilled.val);
        assert!(once.source.is_empty());
    }
}
