//! Building the hierarchy: aggregation, the tentative prolongator from the near-null space,
//! its smoothing, the Galerkin levels, and the factored coarsest level.

use super::cycle::{Level, Work};
use super::galerkin::{block_chunks, block_product, galerkin, product_by_rows, ROWS_PER_BAND};
use super::smoother::{largest_eigenvalue, SmootherMatrix};
use super::transfer::{
    by_aggregate, concatenate, AggregateRows, CoarseNumbering, RowAccumulator, Transfer, MODES,
    ROWS_PER_TASK,
};
use crate::linalg::block_matrix::BLOCK_ROWS_PER_TASK;
use crate::linalg::cholesky::SparseCholesky;
use crate::linalg::SymmetricCsr;
use crate::Real;
use rayon::prelude::*;
use std::borrow::Cow;

/// Factor the level directly once it has at most this many unknowns.
const COARSE_SIZE: usize = 3000;

/// The multigrid hierarchy: apply it with [`Preconditioner::apply`](crate::linalg::Preconditioner::apply).
pub struct SmoothedAggregation {
    pub(super) levels: Vec<Level>,
    pub(super) work: Vec<Work>,
    pub(super) coarse: SparseCholesky,
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
    /// The hierarchy for the matrix `matrix`: `groups` is the node of each DOF (a node's DOFs
    /// consecutive), `near_null_space` one row of [`MODES`] values per DOF, the modes the
    /// matrix nearly annihilates (for a linkage, its rigid-body motions; unused modes zero).
    pub fn new(
        matrix: &SymmetricCsr,
        groups: &[usize],
        near_null_space: &[[Real; MODES]],
    ) -> Result<Self, MultigridError> {
        Self::with_coarse_size(matrix, groups, near_null_space, COARSE_SIZE)
    }

    /// As [`SmoothedAggregation::new`], factoring the first level with at most `coarse_size`
    /// unknowns.
    pub fn with_coarse_size(
        matrix: &SymmetricCsr,
        groups: &[usize],
        near_null_space: &[[Real; MODES]],
        coarse_size: usize,
    ) -> Result<Self, MultigridError> {
        Self::with_band_rows(matrix, groups, near_null_space, coarse_size, ROWS_PER_BAND)
    }

    /// As [`SmoothedAggregation::with_coarse_size`], forming each Galerkin product in bands of
    /// about `rows_per_band` fine rows: less memory, a little repeated work at the bands'
    /// edges, the same hierarchy to the last bit.
    pub fn with_band_rows(
        matrix: &SymmetricCsr,
        groups: &[usize],
        near_null_space: &[[Real; MODES]],
        coarse_size: usize,
        rows_per_band: usize,
    ) -> Result<Self, MultigridError> {
        debug_assert_eq!(
            near_null_space.len(),
            matrix.n,
            "one near-null-space row per DOF"
        );
        debug_assert_eq!(groups.len(), matrix.n, "one group per DOF");
        // Each level's near-null space: the caller's on the finest, the R factors below.
        let mut null_space = Cow::Borrowed(near_null_space);
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
                    0..block_chunks(m),
                )),
                SmootherMatrix::Blocks6(m) => concatenate(block_product(
                    m,
                    &tentative,
                    count,
                    |i| -omega * inverse_diagonal[i],
                    Some(&tentative),
                    0..block_chunks(m),
                )),
                _ => smooth_prolongator(a, &inverse_diagonal, omega, &tentative, count),
            };
            drop(tentative);
            let transpose = by_aggregate(&prolongator, count);
            let p = &prolongator;
            let coarse = match &smoother {
                SmootherMatrix::Blocks3(m) => galerkin(
                    &|chunks| block_product(m, p, count, |_| 1.0, None, chunks),
                    block_chunks(m),
                    3 * BLOCK_ROWS_PER_TASK,
                    3,
                    p,
                    &transpose,
                    &numbering,
                    rows_per_band,
                ),
                SmootherMatrix::Blocks6(m) => galerkin(
                    &|chunks| block_product(m, p, count, |_| 1.0, None, chunks),
                    block_chunks(m),
                    6 * BLOCK_ROWS_PER_TASK,
                    6,
                    p,
                    &transpose,
                    &numbering,
                    rows_per_band,
                ),
                _ => galerkin(
                    &|chunks| product_by_rows(a, p, count, chunks),
                    a.n.div_ceil(ROWS_PER_TASK),
                    ROWS_PER_TASK,
                    1,
                    p,
                    &transpose,
                    &numbering,
                    rows_per_band,
                ),
            };
            sizes.push(coarse.n);
            let mut coarse_blocks = numbering.offset.clone();
            coarse_blocks.push(coarse.n);
            let transfer = Transfer::new(&prolongator, &transpose, numbering);
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
            });
            current = Some(coarse);
            null_space = Cow::Owned(coarse_null);
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
