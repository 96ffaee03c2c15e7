//! The Chebyshev smoother: the products it takes from a level's matrix (full rows or a
//! single-precision block copy), the polynomial, and the Lanczos estimate of `λmax(D⁻¹A)`.

use super::cycle::Work;
use crate::linalg::block_matrix::BlockMatrix;
use crate::linalg::{dot, SymmetricCsr};
use crate::Real;
use rayon::prelude::*;

/// Degree of the Chebyshev smoother.
const SMOOTHER_DEGREE: usize = 2;
/// The smoother damps eigenvalues of `D⁻¹A` in `[λmax / RATIO, 1.1 λmax]`.
const SMOOTHER_RATIO: Real = 20.0;

/// The products a smoother needs from its level's matrix.
pub(super) trait Product: Sync {
    /// `y = A x`.
    fn multiply(&self, x: &[Real], y: &mut [Real]);
    /// `r = b − A x`.
    fn residual(&self, b: &[Real], x: &[Real], r: &mut [Real]);
    /// `r −= A x`.
    fn subtract_product(&self, x: &[Real], r: &mut [Real]);
}

impl Product for SymmetricCsr {
    fn multiply(&self, x: &[Real], y: &mut [Real]) {
        SymmetricCsr::multiply(self, x, y);
    }
    fn residual(&self, b: &[Real], x: &[Real], r: &mut [Real]) {
        SymmetricCsr::residual(self, b, x, r);
    }
    fn subtract_product(&self, x: &[Real], r: &mut [Real]) {
        SymmetricCsr::subtract_product(self, x, r);
    }
}

impl<const B: usize> Product for BlockMatrix<B> {
    fn multiply(&self, x: &[Real], y: &mut [Real]) {
        BlockMatrix::multiply(self, x, y);
    }
    fn residual(&self, b: &[Real], x: &[Real], r: &mut [Real]) {
        BlockMatrix::residual(self, b, x, r);
    }
    fn subtract_product(&self, x: &[Real], r: &mut [Real]) {
        BlockMatrix::subtract_product(self, x, r);
    }
}

/// The matrix a level's smoother multiplies by: a single-precision block copy when the level's
/// DOFs come in uniform blocks (3D or 2D nodes all free, aggregates all of full rank), else the
/// full rows in double precision.
pub(super) enum SmootherMatrix {
    Rows,
    Blocks2(BlockMatrix<2>),
    Blocks3(BlockMatrix<3>),
    Blocks6(BlockMatrix<6>),
}

impl SmootherMatrix {
    /// The block copy of `a` for blocks starting at `blocks` (with a final entry `n`), if
    /// they are uniform and the pattern allows it.
    pub(super) fn new(a: &SymmetricCsr, blocks: &[usize]) -> Self {
        let width = blocks.get(1).map_or(0, |b| b - blocks[0]);
        if blocks.windows(2).any(|w| w[1] - w[0] != width) {
            return SmootherMatrix::Rows;
        }
        let built = match width {
            2 => BlockMatrix::from_full_rows(a).map(SmootherMatrix::Blocks2),
            3 => BlockMatrix::from_full_rows(a).map(SmootherMatrix::Blocks3),
            6 => BlockMatrix::from_full_rows(a).map(SmootherMatrix::Blocks6),
            _ => None,
        };
        built.unwrap_or(SmootherMatrix::Rows)
    }

    /// The product to use: the block copy, or `rows` (the level's full rows).
    pub(super) fn product<'a>(&'a self, rows: &'a SymmetricCsr) -> &'a dyn Product {
        match self {
            SmootherMatrix::Rows => rows,
            SmootherMatrix::Blocks2(m) => m,
            SmootherMatrix::Blocks3(m) => m,
            SmootherMatrix::Blocks6(m) => m,
        }
    }
}

/// Chebyshev smoothing of `A x = b` with the Jacobi-scaled polynomial on
/// `[λmax / RATIO, 1.1 λmax]`, using `w.r` and `w.d`. When `zero_start`, x is zero on
/// entry and is overwritten.
pub(super) fn chebyshev(
    a: &dyn Product,
    inverse_diagonal: &[Real],
    lambda_max: Real,
    b: &[Real],
    x: &mut [Real],
    w: &mut Work,
    zero_start: bool,
) {
    let upper = 1.1 * lambda_max;
    let lower = lambda_max / SMOOTHER_RATIO;
    let theta = 0.5 * (upper + lower);
    let delta = 0.5 * (upper - lower);
    let sigma = theta / delta;
    let mut rho = 1.0 / sigma;
    let (r, d) = (&mut w.r, &mut w.d);
    if zero_start {
        // x = d = D⁻¹ b / θ, r = b.
        r.copy_from_slice(b);
        d.par_iter_mut()
            .zip(x.par_iter_mut())
            .zip(b.par_iter().zip(inverse_diagonal))
            .for_each(|((di, xi), (bi, inv))| {
                *di = bi * inv / theta;
                *xi = *di;
            });
    } else {
        a.residual(b, x, r);
        d.par_iter_mut()
            .zip(x.par_iter_mut())
            .zip(r.par_iter().zip(inverse_diagonal))
            .for_each(|((di, xi), (ri, inv))| {
                *di = ri * inv / theta;
                *xi += *di;
            });
    }
    for _ in 1..SMOOTHER_DEGREE {
        a.subtract_product(d, r);
        let rho_next = 1.0 / (2.0 * sigma - rho);
        let (c1, c2) = (rho_next * rho, 2.0 * rho_next / delta);
        d.par_iter_mut()
            .zip(x.par_iter_mut())
            .zip(r.par_iter().zip(inverse_diagonal))
            .for_each(|((di, xi), (ri, inv))| {
                *di = c1 * *di + c2 * inv * ri;
                *xi += *di;
            });
        rho = rho_next;
    }
}

/// λmax of `D⁻¹A` by 10 Lanczos steps on the similar symmetric `D^-½ A D^-½`: Lanczos finds
/// the extreme eigenvalue far faster than power iteration, and an estimate that is too low
/// would let the Chebyshev smoother amplify the highest modes.
pub(super) fn largest_eigenvalue(a: &dyn Product, inverse_diagonal: &[Real]) -> Real {
    let n = inverse_diagonal.len();
    let scale: Vec<Real> = inverse_diagonal.iter().map(|d| d.sqrt()).collect();
    let mut v: Vec<Real> = (0..n)
        .map(|i| 1.0 + ((i * 7919) % 17) as Real / 17.0)
        .collect();
    let norm = dot(&v, &v).sqrt();
    v.iter_mut().for_each(|x| *x /= norm);
    let mut previous = vec![0.0; n];
    let mut scaled = vec![0.0; n];
    let mut w = vec![0.0; n];
    let (mut alphas, mut betas) = (Vec::new(), Vec::new());
    let mut beta = 0.0;
    for _ in 0..10.min(n) {
        scaled
            .par_iter_mut()
            .zip(&v)
            .zip(&scale)
            .for_each(|((s, x), d)| *s = x * d);
        a.multiply(&scaled, &mut w);
        w.par_iter_mut().zip(&scale).for_each(|(x, d)| *x *= d);
        let alpha = dot(&w, &v);
        w.par_iter_mut()
            .zip(v.par_iter().zip(&previous))
            .for_each(|(x, (vi, pi))| *x -= alpha * vi + beta * pi);
        alphas.push(alpha);
        beta = dot(&w, &w).sqrt();
        if beta <= 1e-12 * alpha.abs() {
            break;
        }
        betas.push(beta);
        std::mem::swap(&mut previous, &mut v);
        v.par_iter_mut().zip(&w).for_each(|(x, y)| *x = y / beta);
    }
    let k = alphas.len();
    let t = nalgebra::DMatrix::from_fn(k, k, |i, j| {
        if i == j {
            alphas[i]
        } else if i + 1 == j || j + 1 == i {
            betas[i.min(j)]
        } else {
            0.0
        }
    });
    let lambda = t.symmetric_eigenvalues().max();
    lambda.max(Real::MIN_POSITIVE)
}
