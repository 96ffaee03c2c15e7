//! TEMPORARY dense stand-in with the final API, replaced by the sparse METIS/faer version.
#![allow(missing_docs)]

#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum CholeskyError {
    #[error("non-positive pivot at {dof}")]
    NonPositivePivot { dof: usize },
    #[error("nearly singular at {dof} ({ratio:e})")]
    NearlySingular { dof: usize, ratio: f64 },
    #[error("{0}")]
    InvalidInput(String),
}

pub struct CholeskyStats {
    pub n: usize,
    pub nnz_a: usize,
    pub nnz_l: usize,
    pub supernodal: bool,
}

pub struct SparseCholesky {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    l: Vec<f64>,
}

impl SparseCholesky {
    pub fn analyze(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        _groups: Option<&[usize]>,
    ) -> Result<Self, CholeskyError> {
        Ok(SparseCholesky {
            n,
            col_ptr: col_ptr.to_vec(),
            row_idx: row_idx.to_vec(),
            l: vec![],
        })
    }
    pub fn factorize(&mut self, values: &[f64]) -> Result<(), CholeskyError> {
        let n = self.n;
        let mut a = vec![0.0; n * n];
        for c in 0..n {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                a[self.row_idx[k] * n + c] = values[k];
                a[c * n + self.row_idx[k]] = values[k];
            }
        }
        for j in 0..n {
            let diag = a[j * n + j];
            let mut s = diag;
            for k in 0..j {
                s -= a[j * n + k] * a[j * n + k];
            }
            if s <= 0.0 {
                return Err(CholeskyError::NonPositivePivot { dof: j });
            }
            if s < 1e-12 * diag {
                return Err(CholeskyError::NearlySingular {
                    dof: j,
                    ratio: s / diag,
                });
            }
            let ljj = s.sqrt();
            a[j * n + j] = ljj;
            for i in j + 1..n {
                let mut s = a[i * n + j];
                for k in 0..j {
                    s -= a[i * n + k] * a[j * n + k];
                }
                a[i * n + j] = s / ljj;
            }
        }
        self.l = a;
        Ok(())
    }
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        let n = self.n;
        let l = &self.l;
        for i in 0..n {
            let mut s = rhs[i];
            for k in 0..i {
                s -= l[i * n + k] * rhs[k];
            }
            rhs[i] = s / l[i * n + i];
        }
        for i in (0..n).rev() {
            let mut s = rhs[i];
            for k in i + 1..n {
                s -= l[k * n + i] * rhs[k];
            }
            rhs[i] = s / l[i * n + i];
        }
    }
    pub fn stats(&self) -> CholeskyStats {
        CholeskyStats {
            n: self.n,
            nnz_a: self.row_idx.len(),
            nnz_l: self.n * (self.n + 1) / 2,
            supernodal: false,
        }
    }
}
