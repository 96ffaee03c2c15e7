//! The block-Jacobi preconditioner: the inverse of each node's 2×2 or 3×3 diagonal block.

use crate::linalg::{Preconditioner, SymmetricCsr};
use crate::Real;
use nalgebra::{DMatrix, Matrix3};
use rayon::prelude::*;

/// Inverses of the diagonal blocks of `K_ff`, one block per node (its free DOFs, which are
/// consecutive). Better than point Jacobi for linkages: a node's directions are coupled by
/// every inclined member.
#[derive(Clone, Debug)]
pub struct BlockJacobi {
    /// First free DOF of each block, with a final entry `n`.
    starts: Vec<usize>,
    /// Inverse of each block, padded to 3×3.
    inverses: Vec<Matrix3<Real>>,
    /// Block of each free DOF.
    block_of: Vec<u32>,
}

/// A node block of `K_ff` that is not positive definite: nothing holds that node.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the diagonal block of free DOF {dof} is singular: nothing holds that node in some direction"
)]
pub struct SingularBlock {
    /// First free DOF of the block.
    pub dof: usize,
}

impl BlockJacobi {
    /// Blocks from `groups` (the node of every free DOF, DOFs of one node consecutive).
    pub fn new(matrix: &SymmetricCsr, groups: &[usize]) -> Result<Self, SingularBlock> {
        let mut starts = Vec::new();
        for (i, g) in groups.iter().enumerate() {
            if i == 0 || groups[i - 1] != *g {
                starts.push(i);
            }
        }
        starts.push(groups.len());
        let inverses = starts
            .par_windows(2)
            .map(|w| {
                let (s, e) = (w[0], w[1]);
                let size = e - s;
                let mut block = DMatrix::<Real>::zeros(size, size);
                for r in s..e {
                    let range = matrix.row_ptr[r]..matrix.row_ptr[r + 1];
                    for (&c, &v) in matrix.col[range.clone()].iter().zip(&matrix.val[range]) {
                        let c = c as usize;
                        if (s..e).contains(&c) {
                            block[(r - s, c - s)] = v;
                        }
                    }
                }
                let inverse = block.cholesky().ok_or(SingularBlock { dof: s })?.inverse();
                let mut padded = Matrix3::zeros();
                padded.view_mut((0, 0), (size, size)).copy_from(&inverse);
                Ok(padded)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut block_of = vec![0u32; groups.len()];
        for (b, w) in starts.windows(2).enumerate() {
            block_of[w[0]..w[1]].iter_mut().for_each(|x| *x = b as u32);
        }
        Ok(BlockJacobi {
            starts,
            inverses,
            block_of,
        })
    }

    /// `z = M⁻¹ r`, DOFs in parallel.
    pub fn apply_inverse(&self, r: &[Real], z: &mut [Real]) {
        z.par_chunks_mut(2048).enumerate().for_each(|(chunk, out)| {
            let first = chunk * 2048;
            for (k, zi) in out.iter_mut().enumerate() {
                let i = first + k;
                let b = self.block_of[i] as usize;
                let s = self.starts[b];
                let size = self.starts[b + 1] - s;
                let inv = &self.inverses[b];
                *zi = (0..size).map(|j| inv[(i - s, j)] * r[s + j]).sum();
            }
        });
    }
}

impl Preconditioner for BlockJacobi {
    fn apply(&mut self, _: &SymmetricCsr, r: &[Real], z: &mut [Real]) {
        self.apply_inverse(r, z);
    }
}
