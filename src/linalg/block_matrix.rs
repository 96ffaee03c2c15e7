//! A symmetric matrix in `B×B` blocks stored in single precision: the multigrid smoother's copy
//! of a level whose DOFs come in uniform blocks (a node's 3 directions, an aggregate's 6
//! modes). One column index serves `B²` values, and each value takes 4 bytes instead of 8, so a
//! product reads about a third of the memory of the full-row `f64` matrix; products accumulate
//! in `f64`.

use crate::linalg::SymmetricCsr;
use crate::Real;
use rayon::prelude::*;

/// Block rows handed to one parallel task.
pub const BLOCK_ROWS_PER_TASK: usize = 512;

/// A square matrix of `B×B` blocks in compressed block rows, values in `f32`.
#[derive(Clone, Debug)]
pub struct BlockMatrix<const B: usize> {
    /// Block rows (the matrix has `B · blocks` rows).
    pub blocks: usize,
    /// Block-row starts, length `blocks + 1`.
    pub row_ptr: Vec<usize>,
    /// Block column of each block, ascending within a block row.
    pub col: Vec<u32>,
    /// Each block, row-major.
    pub val: Vec<[[f32; B]; B]>,
}

impl<const B: usize> BlockMatrix<B> {
    /// The single-precision block copy of `a`, or `None` unless `a` has `B · k` rows and its
    /// pattern is made of whole `B×B` blocks aligned on multiples of `B` (every row of a block
    /// row holding the same columns).
    pub fn from_full_rows(a: &SymmetricCsr) -> Option<Self> {
        if !a.n.is_multiple_of(B) {
            return None;
        }
        let blocks = a.n / B;
        // The pattern first, so the values are written once into their final place.
        let aligned = (0..blocks)
            .into_par_iter()
            .with_min_len(BLOCK_ROWS_PER_TASK)
            .all(|block_row| {
                let first = B * block_row;
                let cols = &a.col[a.row_ptr[first]..a.row_ptr[first + 1]];
                cols.len().is_multiple_of(B)
                    && (first + 1..first + B)
                        .all(|r| a.col[a.row_ptr[r]..a.row_ptr[r + 1]] == *cols)
                    && cols.chunks_exact(B).all(|group| {
                        (group[0] as usize).is_multiple_of(B)
                            && group.iter().zip(group[0]..).all(|(&g, e)| g == e)
                    })
            });
        if !aligned {
            return None;
        }
        let mut row_ptr = Vec::with_capacity(blocks + 1);
        row_ptr.push(0);
        for block_row in 0..blocks {
            let first = B * block_row;
            let length = (a.row_ptr[first + 1] - a.row_ptr[first]) / B;
            row_ptr.push(row_ptr[block_row] + length);
        }
        let total = row_ptr[blocks];
        let mut col = vec![0u32; total];
        let mut val = vec![[[0.0f32; B]; B]; total];
        // Split the outputs at task boundaries, then fill the tasks in parallel.
        let mut tasks = Vec::new();
        let (mut col_rest, mut val_rest) = (col.as_mut_slice(), val.as_mut_slice());
        for first in (0..blocks).step_by(BLOCK_ROWS_PER_TASK) {
            let last = (first + BLOCK_ROWS_PER_TASK).min(blocks);
            let length = row_ptr[last] - row_ptr[first];
            let (c, c_rest) = col_rest.split_at_mut(length);
            let (v, v_rest) = val_rest.split_at_mut(length);
            tasks.push((first..last, c, v));
            (col_rest, val_rest) = (c_rest, v_rest);
        }
        tasks.into_par_iter().for_each(|(rows, cols, vals)| {
            let mut e = 0;
            for block_row in rows {
                let first = B * block_row;
                let start = a.row_ptr[first];
                let length = (a.row_ptr[first + 1] - start) / B;
                for k in 0..length {
                    cols[e] = a.col[start + B * k] / B as u32;
                    for (i, row) in vals[e].iter_mut().enumerate() {
                        let from = a.row_ptr[first + i] + B * k;
                        for (j, v) in row.iter_mut().enumerate() {
                            *v = a.val[from + j] as f32;
                        }
                    }
                    e += 1;
                }
            }
        });
        Some(BlockMatrix {
            blocks,
            row_ptr,
            col,
            val,
        })
    }

    /// `y = A x`, block rows in parallel, each summed in a fixed order (the result does not
    /// depend on the number of threads).
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

    /// Calls `update(y_i, (A x)_i)` for every row, block rows in parallel.
    fn for_each_row_product(
        &self,
        x: &[Real],
        y: &mut [Real],
        update: impl Fn(&mut Real, Real) + Sync,
    ) {
        debug_assert_eq!(y.len(), B * self.blocks);
        y.par_chunks_mut(B * BLOCK_ROWS_PER_TASK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let first = chunk * BLOCK_ROWS_PER_TASK;
                for (k, yb) in out.chunks_exact_mut(B).enumerate() {
                    let row = first + k;
                    let range = self.row_ptr[row]..self.row_ptr[row + 1];
                    // Blocks in pairs, each pair into its own accumulator, so that consecutive
                    // blocks do not wait on one chain of additions.
                    let cols = &self.col[range.clone()];
                    let vals = &self.val[range];
                    let mut acc = [[0.0 as Real; B]; 2];
                    let mut col_pairs = cols.chunks_exact(2);
                    let mut val_pairs = vals.chunks_exact(2);
                    for (c, v) in (&mut col_pairs).zip(&mut val_pairs) {
                        let t0 = block_times(&v[0], x_block::<B>(x, c[0]));
                        let t1 = block_times(&v[1], x_block::<B>(x, c[1]));
                        for a in 0..B {
                            acc[0][a] += t0[a];
                            acc[1][a] += t1[a];
                        }
                    }
                    for (&c, v) in col_pairs.remainder().iter().zip(val_pairs.remainder()) {
                        let t = block_times(v, x_block::<B>(x, c));
                        for (a, t) in acc[0].iter_mut().zip(t) {
                            *a += t;
                        }
                    }
                    for ((yi, a), b) in yb.iter_mut().zip(acc[0]).zip(acc[1]) {
                        update(yi, a + b);
                    }
                }
            });
    }
}

/// The `B` values of block `c` of `x`.
#[inline(always)]
fn x_block<const B: usize>(x: &[Real], c: u32) -> &[Real; B] {
    let start = B * c as usize;
    x[start..start + B].try_into().expect("a slice of B values")
}

/// One block times `B` values, in double precision.
#[inline(always)]
fn block_times<const B: usize>(block: &[[f32; B]; B], x: &[Real; B]) -> [Real; B] {
    let mut t = [0.0; B];
    for (ta, row) in t.iter_mut().zip(block) {
        let mut s = row[0] as Real * x[0];
        for b in 1..B {
            s += row[b] as Real * x[b];
        }
        *ta = s;
    }
    t
}
