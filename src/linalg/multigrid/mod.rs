//! Smoothed-aggregation algebraic multigrid: a preconditioner for conjugate gradients on large
//! linkages, with the rigid-body motions of the linkage as the near-null space.
//!
//! Nodes are grouped into aggregates (a node and its neighbours); on each aggregate the
//! rigid-body motions, orthonormalised, make the tentative prolongator `P₀`; one damped
//! Jacobi step smooths it, `P = (I − ω D⁻¹A) P₀`; the coarse matrix is `PᵀAP`. Levels repeat
//! until the matrix is small enough to factor. One V-cycle with Chebyshev smoothing (a fixed
//! polynomial in `D⁻¹A`, so the cycle is symmetric) is one application of the preconditioner.
//!
//! The smoother multiplies by a single-precision block copy of each level whose DOFs come in
//! uniform blocks (see [`BlockMatrix`]): a fixed symmetric matrix `Ã` within 2⁻²⁴ of `A`
//! entry by entry, so the cycle stays a symmetric positive definite preconditioner while
//! reading about a third of the memory per product; conjugate gradients keep multiplying by
//! `A` in double precision. The copy is taken when the hierarchy is built: a hierarchy kept
//! for a refilled matrix smooths with the values it was built for.

use crate::linalg::block_matrix::{BlockMatrix, BLOCK_ROWS_PER_TASK};
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::{dot, Preconditioner, SymmetricCsr};
use crate::Real;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Factor the level directly once it has at most this many unknowns.
const COARSE_SIZE: usize = 3000;
/// Rows per parallel task.
const ROWS_PER_TASK: usize = 1024;
/// Degree of the Chebyshev smoother.
const SMOOTHER_DEGREE: usize = 2;
/// The smoother damps eigenvalues of `D⁻¹A` in `[λmax / RATIO, 1.1 λmax]`.
const SMOOTHER_RATIO: Real = 20.0;

/// Near-null-space modes carried per aggregate: the 6 rigid-body motions in 3D (3 in 2D).
const MODES: usize = 6;

/// A transfer operator between a level and the next coarser one, stored by aggregate: row i
/// holds one `MODES`-value segment per aggregate it touches (the coarse DOFs of an aggregate
/// are consecutive, `rank[g]` of them from `offset[g]`). Working per aggregate instead of per
/// coarse DOF makes one index lookup serve six values.
#[derive(Clone, Debug, Default)]
struct AggregateRows {
    row_ptr: Vec<usize>,
    aggregate: Vec<u32>,
    value: Vec<[Real; MODES]>,
}

impl AggregateRows {
    fn rows(&self) -> usize {
        self.row_ptr.len() - 1
    }
}

/// The coarse DOFs of each aggregate: `offset[g]..offset[g] + rank[g]`.
#[derive(Clone, Debug, Default)]
struct CoarseNumbering {
    offset: Vec<usize>,
    rank: Vec<usize>,
}

/// For each aggregate, the (fine row, entry) pairs of the prolongator that touch it: the
/// transpose, for restriction and the Galerkin product.
fn by_aggregate(p: &AggregateRows, count: usize) -> (Vec<usize>, Vec<(u32, u32)>) {
    let mut start = vec![0usize; count + 1];
    for &g in &p.aggregate {
        start[g as usize + 1] += 1;
    }
    for g in 0..count {
        start[g + 1] += start[g];
    }
    let mut next = start.clone();
    let mut pairs = vec![(0u32, 0u32); p.aggregate.len()];
    for i in 0..p.rows() {
        for e in p.row_ptr[i]..p.row_ptr[i + 1] {
            let g = p.aggregate[e] as usize;
            pairs[next[g]] = (i as u32, e as u32);
            next[g] += 1;
        }
    }
    (start, pairs)
}

/// Rows built by one parallel task: their lengths, aggregates and value segments.
type RowChunk = (Vec<usize>, Vec<u32>, Vec<[Real; MODES]>);

/// Per-chunk rows, concatenated in chunk order.
fn concatenate(chunks: Vec<RowChunk>) -> AggregateRows {
    let nnz: usize = chunks.iter().map(|c| c.1.len()).sum();
    let mut m = AggregateRows {
        row_ptr: vec![0],
        aggregate: Vec::with_capacity(nnz),
        value: Vec::with_capacity(nnz),
    };
    for (lengths, aggregates, values) in chunks {
        for l in lengths {
            let last = m.row_ptr[m.row_ptr.len() - 1];
            m.row_ptr.push(last + l);
        }
        m.aggregate.extend(aggregates);
        m.value.extend(values);
    }
    m
}

/// Accumulates `MODES`-value segments by aggregate for one row at a time.
struct RowAccumulator {
    place: Vec<u32>,
    aggregates: Vec<u32>,
    values: Vec<[Real; MODES]>,
}

impl RowAccumulator {
    fn new(count: usize) -> Self {
        RowAccumulator {
            place: vec![u32::MAX; count],
            aggregates: Vec::new(),
            values: Vec::new(),
        }
    }

    fn add(&mut self, g: u32, scale: Real, v: &[Real; MODES]) {
        let slot = &mut self.place[g as usize];
        if *slot == u32::MAX {
            *slot = self.aggregates.len() as u32;
            self.aggregates.push(g);
            self.values.push(v.map(|x| scale * x));
        } else {
            let target = &mut self.values[*slot as usize];
            for k in 0..MODES {
                target[k] += scale * v[k];
            }
        }
    }

    /// Move the row into the chunk's output and reset.
    fn finish(&mut self, out: &mut RowChunk) {
        out.0.push(self.aggregates.len());
        for &g in &self.aggregates {
            self.place[g as usize] = u32::MAX;
        }
        out.1.append(&mut self.aggregates);
        out.2.append(&mut self.values);
    }
}

/// The products a smoother needs from its level's matrix.
trait Product: Sync {
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
enum SmootherMatrix {
    Rows,
    Blocks2(BlockMatrix<2>),
    Blocks3(BlockMatrix<3>),
    Blocks6(BlockMatrix<6>),
}

impl SmootherMatrix {
    /// The block copy of `a` for blocks starting at `blocks` (with a final entry `n`), if
    /// they are uniform and the pattern allows it.
    fn new(a: &SymmetricCsr, blocks: &[usize]) -> Self {
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
    fn product<'a>(&'a self, rows: &'a SymmetricCsr) -> &'a dyn Product {
        match self {
            SmootherMatrix::Rows => rows,
            SmootherMatrix::Blocks2(m) => m,
            SmootherMatrix::Blocks3(m) => m,
            SmootherMatrix::Blocks6(m) => m,
        }
    }
}

/// Vectors one V-cycle needs on a level, kept between cycles.
#[derive(Default)]
struct Work {
    r: Vec<Real>,
    d: Vec<Real>,
    coarse_b: Vec<Real>,
    coarse_x: Vec<Real>,
}

/// The prolongator as the cycle uses it, in single precision (the Galerkin product used the
/// double-precision one): by fine rows for prolongation and by aggregates for restriction, so
/// that both read their values in order.
struct Transfer {
    /// Per fine row, its entries `row_ptr[i]..row_ptr[i + 1]` in `row_entries`.
    row_ptr: Vec<usize>,
    /// (aggregate, `MODES` values) of each entry by rows.
    row_entries: Vec<(u32, [f32; MODES])>,
    /// Per aggregate, its entries `aggregate_ptr[g]..aggregate_ptr[g + 1]` in `aggregate_entries`.
    aggregate_ptr: Vec<usize>,
    /// (fine row, `MODES` values) of each entry by aggregates.
    aggregate_entries: Vec<(u32, [f32; MODES])>,
}

impl Transfer {
    /// The single-precision copy of `p`, with its transpose `by_aggregate(p)`.
    fn new(p: &AggregateRows, transpose: &(Vec<usize>, Vec<(u32, u32)>)) -> Self {
        let single = |v: &[Real; MODES]| v.map(|x| x as f32);
        let row_entries = p
            .aggregate
            .par_iter()
            .zip(&p.value)
            .map(|(&g, v)| (g, single(v)))
            .collect();
        let (start, pairs) = transpose;
        let aggregate_entries = pairs
            .par_iter()
            .map(|&(i, e)| (i, single(&p.value[e as usize])))
            .collect();
        Transfer {
            row_ptr: p.row_ptr.clone(),
            row_entries,
            aggregate_ptr: start.clone(),
            aggregate_entries,
        }
    }
}

/// One level of the hierarchy: its smoother's matrix (full rows only when the smoother uses
/// them and the level is not the finest, which the caller owns), the smoother's data, and the
/// transfer to the next level.
struct Level {
    matrix: Option<SymmetricCsr>,
    smoother: SmootherMatrix,
    inverse_diagonal: Vec<Real>,
    lambda_max: Real,
    transfer: Transfer,
    numbering: CoarseNumbering,
}

impl Level {
    /// The smoother's product (`fine` is the finest matrix).
    fn product<'a>(&'a self, fine: &'a SymmetricCsr) -> &'a dyn Product {
        self.smoother.product(self.matrix.as_ref().unwrap_or(fine))
    }

    /// `x += P xc`.
    fn prolong_add(&self, coarse: &[Real], x: &mut [Real]) {
        let p = &self.transfer;
        let nb = &self.numbering;
        x.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(chunk, out)| {
                let first = chunk * ROWS_PER_TASK;
                for (k, xi) in out.iter_mut().enumerate() {
                    let i = first + k;
                    for (g, v) in &p.row_entries[p.row_ptr[i]..p.row_ptr[i + 1]] {
                        let g = *g as usize;
                        let c = &coarse[nb.offset[g]..nb.offset[g] + nb.rank[g]];
                        *xi += c.iter().zip(v).map(|(a, b)| a * *b as Real).sum::<Real>();
                    }
                }
            });
    }

    /// `bc = Pᵀ r`, aggregates in parallel.
    fn restrict(&self, r: &[Real], coarse: &mut [Real]) {
        let p = &self.transfer;
        let nb = &self.numbering;
        let sums: Vec<[Real; MODES]> = (0..nb.rank.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|g| {
                let mut acc = [0.0; MODES];
                for (i, v) in &p.aggregate_entries[p.aggregate_ptr[g]..p.aggregate_ptr[g + 1]] {
                    let ri = r[*i as usize];
                    for (a, v) in acc.iter_mut().zip(v) {
                        *a += *v as Real * ri;
                    }
                }
                acc
            })
            .collect();
        for (g, acc) in sums.iter().enumerate() {
            coarse[nb.offset[g]..nb.offset[g] + nb.rank[g]].copy_from_slice(&acc[..nb.rank[g]]);
        }
    }
}

/// The multigrid hierarchy: apply it with [`SmoothedAggregation::apply`].
pub struct SmoothedAggregation {
    levels: Vec<Level>,
    work: Vec<Work>,
    coarse: SparseCholesky,
    /// Unknowns per level, finest first (the last is factored).
    pub sizes: Vec<usize>,
}

/// Why the hierarchy could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MultigridError {
    /// A zero or negative diagonal entry: nothing holds that DOF.
    #[error(
        "free DOF {dof} has no stiffness of its own: nothing holds that node in that direction"
    )]
    NoStiffness {
        /// Free DOF.
        dof: usize,
    },
    /// The coarsest matrix could not be factored.
    #[error("the coarsest multigrid level could not be factored: {0}")]
    Coarse(String),
}

impl SmoothedAggregation {
    /// The hierarchy for `K_ff` of a body: `groups` is the node of each free DOF (a node's DOFs
    /// consecutive), `directions` the direction (0, 1, 2) of each free DOF, `nodes` the node
    /// positions (m), `dimension` 2 or 3.
    pub fn new(
        matrix: &SymmetricCsr,
        groups: &[usize],
        directions: &[usize],
        nodes: &[Vector3<Real>],
        dimension: usize,
    ) -> Result<Self, MultigridError> {
        Self::with_coarse_size(matrix, groups, directions, nodes, dimension, COARSE_SIZE)
    }

    /// As [`SmoothedAggregation::new`], factoring the first level with at most `coarse_size`
    /// unknowns.
    pub fn with_coarse_size(
        matrix: &SymmetricCsr,
        groups: &[usize],
        directions: &[usize],
        nodes: &[Vector3<Real>],
        dimension: usize,
        coarse_size: usize,
    ) -> Result<Self, MultigridError> {
        // Near-null space: the rigid-body motions about the centroid (conditioning).
        let centre = nodes.iter().sum::<Vector3<Real>>() / nodes.len().max(1) as Real;
        let mut null_space = vec![[0.0; MODES]; matrix.n];
        for (i, row) in null_space.iter_mut().enumerate() {
            let p = nodes[groups[i]] - centre;
            let d = directions[i];
            row[d] = 1.0;
            if dimension == 2 {
                // Rotation about z: (−y, x).
                row[2] = if d == 0 { -p.y } else { p.x };
            } else {
                // Rotations about x, y, z: a × p.
                let rx = Vector3::new(0.0, -p.z, p.y);
                let ry = Vector3::new(p.z, 0.0, -p.x);
                let rz = Vector3::new(-p.y, p.x, 0.0);
                row[3] = rx[d];
                row[4] = ry[d];
                row[5] = rz[d];
            }
        }
        let mut starts: Vec<usize> = Vec::new();
        for (i, g) in groups.iter().enumerate() {
            if i == 0 || groups[i - 1] != *g {
                starts.push(i);
            }
        }
        starts.push(groups.len());

        let mut levels = Vec::new();
        let mut sizes = vec![matrix.n];
        let mut current: Option<SymmetricCsr> = None;
        let mut blocks = starts;
        loop {
            let a = current.as_ref().unwrap_or(matrix);
            if a.n <= coarse_size {
                break;
            }
            let inverse_diagonal = a
                .diagonal()
                .iter()
                .enumerate()
                .map(|(i, &d)| {
                    if d > 0.0 {
                        Ok(1.0 / d)
                    } else {
                        Err(MultigridError::NoStiffness { dof: i })
                    }
                })
                .collect::<Result<Vec<_>, _>>()?;
            let smoother = SmootherMatrix::new(a, &blocks);
            let lambda_max = largest_eigenvalue(smoother.product(a), &inverse_diagonal);
            let aggregates = aggregate(a, &blocks);
            let count = aggregates
                .iter()
                .copied()
                .max()
                .map_or(0, |m| m as usize + 1);
            if count * 2 > blocks.len() - 1 {
                // Aggregation no longer coarsens: factor this level.
                break;
            }
            let (tentative, numbering, coarse_null) =
                tentative_prolongator(&blocks, &aggregates, count, &null_space);
            let omega = 4.0 / (3.0 * lambda_max);
            let prolongator = match &smoother {
                SmootherMatrix::Blocks3(m) => concatenate(block_product(
                    m,
                    &tentative,
                    count,
                    |i| -omega * inverse_diagonal[i],
                    Some(&tentative),
                )),
                SmootherMatrix::Blocks6(m) => concatenate(block_product(
                    m,
                    &tentative,
                    count,
                    |i| -omega * inverse_diagonal[i],
                    Some(&tentative),
                )),
                _ => smooth_prolongator(a, &inverse_diagonal, omega, &tentative, count),
            };
            drop(tentative);
            let transpose = by_aggregate(&prolongator, count);
            let (ap, ap_rows_per_chunk, width) = match &smoother {
                SmootherMatrix::Blocks3(m) => (
                    block_product(m, &prolongator, count, |_| 1.0, None),
                    3 * BLOCK_ROWS_PER_TASK,
                    3,
                ),
                SmootherMatrix::Blocks6(m) => (
                    block_product(m, &prolongator, count, |_| 1.0, None),
                    6 * BLOCK_ROWS_PER_TASK,
                    6,
                ),
                _ => (product_by_rows(a, &prolongator, count), ROWS_PER_TASK, 1),
            };
            let coarse = galerkin(
                ap,
                ap_rows_per_chunk,
                width,
                &prolongator,
                &transpose,
                &numbering,
            );
            sizes.push(coarse.n);
            let mut coarse_blocks = numbering.offset.clone();
            coarse_blocks.push(coarse.n);
            let transfer = Transfer::new(&prolongator, &transpose);
            drop((prolongator, transpose));
            let own = current.take();
            levels.push(Level {
                matrix: match smoother {
                    SmootherMatrix::Rows => own,
                    _ => None,
                },
                smoother,
                inverse_diagonal,
                lambda_max,
                transfer,
                numbering,
            });
            current = Some(coarse);
            null_space = coarse_null;
            blocks = coarse_blocks;
        }
        let coarse_matrix = current.unwrap_or_else(|| matrix.clone());
        let (col_ptr, row_idx, values) = lower_triangle(&coarse_matrix);
        let coarse_groups: Vec<usize> = (0..blocks.len() - 1)
            .flat_map(|b| std::iter::repeat_n(b, blocks[b + 1] - blocks[b]))
            .collect();
        let mut coarse =
            SparseCholesky::analyze(coarse_matrix.n, &col_ptr, &row_idx, Some(&coarse_groups))
                .map_err(|e| MultigridError::Coarse(e.to_string()))?;
        coarse
            .factorize(&values)
            .map_err(|e| MultigridError::Coarse(e.to_string()))?;
        let work = (0..levels.len()).map(|_| Work::default()).collect();
        Ok(SmoothedAggregation {
            levels,
            work,
            coarse,
            sizes,
        })
    }

    /// One V-cycle from a zero guess for `A x = b` on `level` (`fine` is the finest matrix).
    fn cycle(&mut self, level: usize, fine: &SymmetricCsr, b: &[Real], x: &mut [Real]) {
        if level == self.levels.len() {
            x.copy_from_slice(b);
            self.coarse.solve_in_place(x);
            return;
        }
        let mut w = std::mem::take(&mut self.work[level]);
        let n = b.len();
        for v in [&mut w.r, &mut w.d] {
            v.resize(n, 0.0);
        }
        let coarse_n = self.sizes[level + 1];
        w.coarse_b.resize(coarse_n, 0.0);
        w.coarse_x.resize(coarse_n, 0.0);
        {
            let lv = &self.levels[level];
            let a = lv.product(fine);
            chebyshev(a, &lv.inverse_diagonal, lv.lambda_max, b, x, &mut w, true);
            a.residual(b, x, &mut w.r);
            lv.restrict(&w.r, &mut w.coarse_b);
        }
        self.cycle(level + 1, fine, &w.coarse_b, &mut w.coarse_x);
        let lv = &self.levels[level];
        lv.prolong_add(&w.coarse_x, x);
        chebyshev(
            lv.product(fine),
            &lv.inverse_diagonal,
            lv.lambda_max,
            b,
            x,
            &mut w,
            false,
        );
        self.work[level] = w;
    }
}

/// Chebyshev smoothing of `A x = b` with the Jacobi-scaled polynomial on
/// `[λmax / RATIO, 1.1 λmax]`, using `w.r` and `w.d`. When `zero_start`, x is zero on
/// entry and is overwritten.
fn chebyshev(
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
fn largest_eigenvalue(a: &dyn Product, inverse_diagonal: &[Real]) -> Real {
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

/// Greedy aggregation of blocks (nodes, or the previous level's aggregates) on the block
/// graph of `a`: first, a block whose neighbours are all free takes them all; then left-over
/// blocks join a neighbouring aggregate; the rest group with their free neighbours.
fn aggregate(a: &SymmetricCsr, blocks: &[usize]) -> Vec<u32> {
    let count = blocks.len() - 1;
    let mut block_of = vec![0u32; a.n];
    for b in 0..count {
        block_of[blocks[b]..blocks[b + 1]]
            .iter_mut()
            .for_each(|x| *x = b as u32);
    }
    // The pattern holds whole blocks, so the first row of a block meets every neighbouring
    // block, in ascending order.
    let neighbours: Vec<Vec<u32>> = (0..count)
        .into_par_iter()
        .map(|b| {
            let r = blocks[b];
            let mut list: Vec<u32> = Vec::new();
            for &c in &a.col[a.row_ptr[r]..a.row_ptr[r + 1]] {
                let nb = block_of[c as usize];
                if nb as usize != b && list.last() != Some(&nb) {
                    list.push(nb);
                }
            }
            list
        })
        .collect();
    const FREE: u32 = u32::MAX;
    let mut agg = vec![FREE; count];
    let mut next = 0u32;
    for b in 0..count {
        if agg[b] == FREE && neighbours[b].iter().all(|&nb| agg[nb as usize] == FREE) {
            agg[b] = next;
            for &nb in &neighbours[b] {
                agg[nb as usize] = next;
            }
            next += 1;
        }
    }
    let first_pass = agg.clone();
    for b in 0..count {
        if agg[b] == FREE {
            if let Some(&nb) = neighbours[b]
                .iter()
                .find(|&&nb| first_pass[nb as usize] != FREE)
            {
                agg[b] = first_pass[nb as usize];
            }
        }
    }
    for b in 0..count {
        if agg[b] == FREE {
            agg[b] = next;
            for &nb in &neighbours[b] {
                if agg[nb as usize] == FREE {
                    agg[nb as usize] = next;
                }
            }
            next += 1;
        }
    }
    agg
}

/// The tentative prolongator: on each aggregate, the near-null-space rows orthonormalised
/// (modified Gram–Schmidt, dependent columns dropped). Returns it, the coarse numbering and
/// the coarse near-null space (the R factors).
fn tentative_prolongator(
    blocks: &[usize],
    aggregates: &[u32],
    count: usize,
    null_space: &[[Real; MODES]],
) -> (AggregateRows, CoarseNumbering, Vec<[Real; MODES]>) {
    let n = null_space.len();
    let mut dofs_of: Vec<Vec<usize>> = vec![Vec::new(); count];
    for (b, &g) in aggregates.iter().enumerate() {
        dofs_of[g as usize].extend(blocks[b]..blocks[b + 1]);
    }
    // Per aggregate: Q as rows of MODES (zero-padded past the rank), R rows, rank.
    type QAndR = (Vec<[Real; MODES]>, Vec<[Real; MODES]>);
    let per_aggregate: Vec<QAndR> = dofs_of
        .par_iter()
        .map(|dofs| {
            let mut q: Vec<Vec<Real>> = Vec::with_capacity(MODES);
            let mut r: Vec<[Real; MODES]> = Vec::with_capacity(MODES);
            let mut coefficients = [[0.0; MODES]; MODES];
            for k in 0..MODES {
                let mut v: Vec<Real> = dofs.iter().map(|&i| null_space[i][k]).collect();
                let original = v.iter().map(|x| x * x).sum::<Real>().sqrt();
                if original == 0.0 {
                    continue;
                }
                for (j, qj) in q.iter().enumerate() {
                    let c: Real = qj.iter().zip(&v).map(|(a, b)| a * b).sum();
                    v.iter_mut().zip(qj).for_each(|(x, y)| *x -= c * y);
                    coefficients[j][k] = c;
                }
                let norm = v.iter().map(|x| x * x).sum::<Real>().sqrt();
                if norm > 1e-10 * original && q.len() < dofs.len() {
                    v.iter_mut().for_each(|x| *x /= norm);
                    coefficients[q.len()][k] = norm;
                    q.push(v);
                }
            }
            r.extend_from_slice(&coefficients[..q.len()]);
            let q_rows = (0..dofs.len())
                .map(|i| {
                    let mut row = [0.0; MODES];
                    for (j, col) in q.iter().enumerate() {
                        row[j] = col[i];
                    }
                    row
                })
                .collect();
            (q_rows, r)
        })
        .collect();
    let mut numbering = CoarseNumbering {
        offset: Vec::with_capacity(count),
        rank: Vec::with_capacity(count),
    };
    let mut next = 0;
    for (_, r) in &per_aggregate {
        numbering.offset.push(next);
        numbering.rank.push(r.len());
        next += r.len();
    }
    let mut p = AggregateRows {
        row_ptr: (0..=n).collect(),
        aggregate: vec![0; n],
        value: vec![[0.0; MODES]; n],
    };
    for (g, dofs) in dofs_of.iter().enumerate() {
        for (local, &i) in dofs.iter().enumerate() {
            p.aggregate[i] = g as u32;
            p.value[i] = per_aggregate[g].0[local];
        }
    }
    let coarse_null = per_aggregate.into_iter().flat_map(|(_, r)| r).collect();
    (p, numbering, coarse_null)
}

/// `P = (I − ω D⁻¹ A) P₀`, row by row.
fn smooth_prolongator(
    a: &SymmetricCsr,
    inverse_diagonal: &[Real],
    omega: Real,
    tentative: &AggregateRows,
    count: usize,
) -> AggregateRows {
    let chunks = (0..a.n.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .map(|chunk| {
            let mut acc = RowAccumulator::new(count);
            let mut out = (Vec::new(), Vec::new(), Vec::new());
            let rows = chunk * ROWS_PER_TASK..((chunk + 1) * ROWS_PER_TASK).min(a.n);
            for (i, inverse) in rows.clone().zip(&inverse_diagonal[rows]) {
                for k in tentative.row_ptr[i]..tentative.row_ptr[i + 1] {
                    acc.add(tentative.aggregate[k], 1.0, &tentative.value[k]);
                }
                let scale = -omega * inverse;
                for e in a.row_ptr[i]..a.row_ptr[i + 1] {
                    let j = a.col[e] as usize;
                    for k in tentative.row_ptr[j]..tentative.row_ptr[j + 1] {
                        acc.add(
                            tentative.aggregate[k],
                            scale * a.val[e],
                            &tentative.value[k],
                        );
                    }
                }
                acc.finish(&mut out);
            }
            out
        })
        .collect();
    concatenate(chunks)
}

/// `A P` for the block copy `a` (block rows of `W` rows), in chunks of `W · BLOCK_ROWS_PER_TASK`
/// rows; each row of `A P` is then scaled by `scale(row)` and, when `add` is given, the row
/// of `add` is added. With the rows of one block sharing their pattern in `p` (true of the
/// tentative prolongator and of every product of this function), one aggregate lookup serves
/// a whole `W×W` block times `W×MODES` values.
fn block_product<const W: usize>(
    a: &BlockMatrix<W>,
    p: &AggregateRows,
    count: usize,
    scale: impl Fn(usize) -> Real + Sync,
    add: Option<&AggregateRows>,
) -> Vec<RowChunk> {
    (0..a.blocks.div_ceil(BLOCK_ROWS_PER_TASK))
        .into_par_iter()
        .map(|chunk| {
            let mut place = vec![u32::MAX; count];
            let mut touched: Vec<u32> = Vec::new();
            let mut sums: Vec<[[Real; MODES]; W]> = Vec::new();
            let mut out: RowChunk = (Vec::new(), Vec::new(), Vec::new());
            let rows =
                chunk * BLOCK_ROWS_PER_TASK..((chunk + 1) * BLOCK_ROWS_PER_TASK).min(a.blocks);
            for block_row in rows {
                let range = a.row_ptr[block_row]..a.row_ptr[block_row + 1];
                for (&c, block) in a.col[range.clone()].iter().zip(&a.val[range]) {
                    let base = W * c as usize;
                    let first = p.row_ptr[base];
                    let length = p.row_ptr[base + 1] - first;
                    for k in 0..length {
                        let g = p.aggregate[first + k];
                        let slot = &mut place[g as usize];
                        if *slot == u32::MAX {
                            *slot = touched.len() as u32;
                            touched.push(g);
                            sums.push([[0.0; MODES]; W]);
                        }
                        let target = &mut sums[*slot as usize];
                        for (b, row_b) in (0..W).map(|b| (b, &p.value[p.row_ptr[base + b] + k])) {
                            for (t, block_row_a) in target.iter_mut().zip(block) {
                                let v = block_row_a[b] as Real;
                                for (x, y) in t.iter_mut().zip(row_b) {
                                    *x += v * y;
                                }
                            }
                        }
                    }
                }
                for (i, row) in (W * block_row..W * block_row + W).enumerate() {
                    let factor = scale(row);
                    for s in sums.iter_mut() {
                        s[i].iter_mut().for_each(|x| *x *= factor);
                    }
                    if let Some(add) = add {
                        for e in add.row_ptr[row]..add.row_ptr[row + 1] {
                            let g = add.aggregate[e];
                            let slot = &mut place[g as usize];
                            if *slot == u32::MAX {
                                *slot = touched.len() as u32;
                                touched.push(g);
                                sums.push([[0.0; MODES]; W]);
                            }
                            let target = &mut sums[*slot as usize][i];
                            for (x, y) in target.iter_mut().zip(&add.value[e]) {
                                *x += y;
                            }
                        }
                    }
                }
                for i in 0..W {
                    out.0.push(touched.len());
                    out.1.extend_from_slice(&touched);
                    out.2.extend(sums.iter().map(|s| s[i]));
                }
                for &g in &touched {
                    place[g as usize] = u32::MAX;
                }
                touched.clear();
                sums.clear();
            }
            out
        })
        .collect()
}

/// The Galerkin coarse matrix `PᵀAP`, as full rows.
/// `A P` row by row, per aggregate, in chunks of `ROWS_PER_TASK` rows.
fn product_by_rows(a: &SymmetricCsr, p: &AggregateRows, count: usize) -> Vec<RowChunk> {
    (0..a.n.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .map(|chunk| {
            let mut acc = RowAccumulator::new(count);
            let mut out = (Vec::new(), Vec::new(), Vec::new());
            for i in chunk * ROWS_PER_TASK..((chunk + 1) * ROWS_PER_TASK).min(a.n) {
                for e in a.row_ptr[i]..a.row_ptr[i + 1] {
                    let j = a.col[e] as usize;
                    for k in p.row_ptr[j]..p.row_ptr[j + 1] {
                        acc.add(p.aggregate[k], a.val[e], &p.value[k]);
                    }
                }
                acc.finish(&mut out);
            }
            out
        })
        .collect()
}

/// The Galerkin coarse matrix `PᵀAP`, as full rows, from `ap` = `A P` in chunks of
/// `rows_per_chunk` rows, whose rows come in blocks of `width` rows sharing their pattern
/// in `P` and in `A P` (kept in its chunks: joining them would hold `A P` twice at the peak
/// of the set-up).
fn galerkin(
    ap: Vec<RowChunk>,
    rows_per_chunk: usize,
    width: usize,
    p: &AggregateRows,
    transpose: &(Vec<usize>, Vec<(u32, u32)>),
    numbering: &CoarseNumbering,
) -> SymmetricCsr {
    let count = numbering.rank.len();
    // Where each row of AP starts in its chunk.
    let ap_starts: Vec<Vec<usize>> = ap
        .par_iter()
        .map(|(lengths, _, _)| {
            let mut starts = Vec::with_capacity(lengths.len() + 1);
            starts.push(0);
            for l in lengths {
                starts.push(starts[starts.len() - 1] + l);
            }
            starts
        })
        .collect();
    // Block row g of PᵀAP = Σ over fine rows i touching g of P[i, g]ᵀ · AP[i, :].
    let (start, pairs) = transpose;
    const GROUPS_PER_TASK: usize = 64;
    let rows: Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> = (0..count.div_ceil(GROUPS_PER_TASK))
        .into_par_iter()
        .map(|chunk| {
            let mut place = vec![u32::MAX; count];
            let mut touched: Vec<u32> = Vec::new();
            let mut blocks: Vec<[[Real; MODES]; MODES]> = Vec::new();
            let mut out = (Vec::new(), Vec::new(), Vec::new());
            for g in chunk * GROUPS_PER_TASK..((chunk + 1) * GROUPS_PER_TASK).min(count) {
                // The rows of one block, consecutive here, share their pattern in AP.
                for group in pairs[start[g]..start[g + 1]].chunks(width) {
                    // Per row of the group: its chunk of AP, where its row starts there, and
                    // its entry of P.
                    let mut rows = [(0usize, 0usize, 0usize); MODES];
                    for (slot, &(i, e)) in rows.iter_mut().zip(group) {
                        let (chunk, local) =
                            (i as usize / rows_per_chunk, i as usize % rows_per_chunk);
                        *slot = (chunk, ap_starts[chunk][local], e as usize);
                    }
                    let rows = &rows[..group.len()];
                    let (chunk, first, _) = rows[0];
                    let length =
                        ap_starts[chunk][(group[0].0 as usize % rows_per_chunk) + 1] - first;
                    let pattern = &ap[chunk].1[first..first + length];
                    for (k, &h) in pattern.iter().enumerate() {
                        let slot = &mut place[h as usize];
                        if *slot == u32::MAX {
                            *slot = touched.len() as u32;
                            touched.push(h);
                            blocks.push([[0.0; MODES]; MODES]);
                        }
                        let block = &mut blocks[*slot as usize];
                        for &(chunk, first, e) in rows {
                            let av = &ap[chunk].2[first + k];
                            debug_assert_eq!(ap[chunk].1[first + k], h);
                            for (row, &pt) in block.iter_mut().zip(&p.value[e]) {
                                for (x, &y) in row.iter_mut().zip(av) {
                                    *x += pt * y;
                                }
                            }
                        }
                    }
                }
                let mut order: Vec<usize> = (0..touched.len()).collect();
                order.sort_unstable_by_key(|&k| touched[k]);
                // t is the row inside every block of this block row, not an index into `blocks`.
                #[allow(clippy::needless_range_loop)]
                for t in 0..numbering.rank[g] {
                    let mut length = 0;
                    for &k in &order {
                        let h = touched[k] as usize;
                        let rank = numbering.rank[h];
                        let first = numbering.offset[h] as u32;
                        out.1.extend(first..first + rank as u32);
                        out.2.extend_from_slice(&blocks[k][t][..rank]);
                        length += rank;
                    }
                    out.0.push(length);
                }
                for &h in &touched {
                    place[h as usize] = u32::MAX;
                }
                touched.clear();
                blocks.clear();
            }
            out
        })
        .collect();
    drop(ap);
    drop(ap_starts);
    let n: usize = numbering.rank.iter().sum();
    let nnz: usize = rows.iter().map(|c| c.1.len()).sum();
    let mut row_ptr = Vec::with_capacity(n + 1);
    row_ptr.push(0);
    let mut col = Vec::with_capacity(nnz);
    let mut val = Vec::with_capacity(nnz);
    for (lengths, c, v) in rows {
        for l in lengths {
            row_ptr.push(row_ptr[row_ptr.len() - 1] + l);
        }
        col.extend(c);
        val.extend(v);
    }
    SymmetricCsr::from_rows(n, row_ptr, col, val)
}

/// The lower triangle of a symmetric full-row matrix in compressed columns (column c holds
/// the row-c entries with column ≥ c).
fn lower_triangle(a: &SymmetricCsr) -> (Vec<usize>, Vec<usize>, Vec<Real>) {
    let mut col_ptr = vec![0usize];
    let mut row_idx = Vec::new();
    let mut values = Vec::new();
    for r in 0..a.n {
        for k in a.row_ptr[r]..a.row_ptr[r + 1] {
            let c = a.col[k] as usize;
            if c >= r {
                row_idx.push(c);
                values.push(a.val[k]);
            }
        }
        col_ptr.push(row_idx.len());
    }
    (col_ptr, row_idx, values)
}

impl Preconditioner for SmoothedAggregation {
    /// `z = M⁻¹ r`: one V-cycle from a zero guess.
    fn apply(&mut self, fine: &SymmetricCsr, r: &[Real], z: &mut [Real]) {
        self.cycle(0, fine, r, z);
    }
}
