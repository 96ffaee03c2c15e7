//! The Galerkin coarse matrix `PᵀAP`: the product `A P` (by full rows or by blocks of the
//! single-precision copy), then `Pᵀ (A P)` by aggregates.

use super::transfer::{
    AggregateRows, CoarseNumbering, RowAccumulator, RowChunk, MODES, ROWS_PER_TASK,
};
use crate::linalg::block_matrix::{BlockMatrix, BLOCK_ROWS_PER_TASK};
use crate::linalg::SymmetricCsr;
use crate::Real;
use rayon::prelude::*;
use std::ops::Range;

/// `A P` for the block copy `a` (block rows of `W` rows), in chunks of `W · BLOCK_ROWS_PER_TASK`
/// rows, for the chunks `chunks` only (all: `0..block_chunks(a)`); each row of `A P` is then scaled by `scale(row)` and, when `add` is given, the row
/// of `add` is added. With the rows of one block sharing their pattern in `p` (true of the
/// tentative prolongator and of every product of this function), one aggregate lookup serves
/// a whole `W×W` block times `W×MODES` values.
pub(super) fn block_product<const W: usize>(
    a: &BlockMatrix<W>,
    p: &AggregateRows,
    count: usize,
    scale: impl Fn(usize) -> Real + Sync,
    add: Option<&AggregateRows>,
    chunks: Range<usize>,
) -> Vec<RowChunk> {
    chunks
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
            // Grown by doubling: the slack would outlive the chunk in the band held.
            out.0.shrink_to_fit();
            out.1.shrink_to_fit();
            out.2.shrink_to_fit();
            out
        })
        .collect()
}

/// The chunks of [`block_product`] for `a`.
pub(super) fn block_chunks<const W: usize>(a: &BlockMatrix<W>) -> usize {
    a.blocks.div_ceil(BLOCK_ROWS_PER_TASK)
}

/// `A P` row by row, per aggregate, in chunks of `ROWS_PER_TASK` rows, for the chunks `chunks`
/// only (all: `0..a.n.div_ceil(ROWS_PER_TASK)`).
pub(super) fn product_by_rows(
    a: &SymmetricCsr,
    p: &AggregateRows,
    count: usize,
    chunks: Range<usize>,
) -> Vec<RowChunk> {
    chunks
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
            // Grown by doubling: the slack would outlive the chunk in the band held.
            out.0.shrink_to_fit();
            out.1.shrink_to_fit();
            out.2.shrink_to_fit();
            out
        })
        .collect()
}

/// `A P` for the chunks of rows given (see [`block_product`], [`product_by_rows`]).
pub(super) type ProductChunks<'a> = dyn Fn(Range<usize>) -> Vec<RowChunk> + Sync + 'a;

/// Fine rows of `A` per band of the Galerkin product (see [`galerkin`]): a seventh of `A P` of
/// a 367,500-DOF lattice at a time keeps its set-up near the solve's own memory.
pub(super) const ROWS_PER_BAND: usize = 50_000;

/// The Galerkin coarse matrix `PᵀAP`, as full rows. `A P` (`product`, in chunks of
/// `rows_per_chunk` rows, `chunk_count` in all, rows in blocks of `width` rows sharing their
/// pattern in `P` and in `A P`) is the largest array of the set-up, several times the coarse
/// matrix: for a large `A` it is formed in up to 8 bands of about `rows_per_band` fine rows,
/// for the coarse rows of one band at a time and only the fine rows they need, and dropped
/// before the next. Each coarse row is summed in the same order whatever the bands, so the
/// result does not depend on them.
#[allow(clippy::too_many_arguments)]
pub(super) fn galerkin(
    product: &ProductChunks,
    chunk_count: usize,
    rows_per_chunk: usize,
    width: usize,
    p: &AggregateRows,
    transpose: &(Vec<usize>, Vec<(u32, u32)>),
    numbering: &CoarseNumbering,
    rows_per_band: usize,
) -> SymmetricCsr {
    let count = numbering.rank.len();
    let fine_rows = p.rows();
    let bands = (fine_rows / rows_per_band.max(1))
        .clamp(1, 8)
        .min(count.max(1));
    let (start, pairs) = transpose;
    let mut rows = Vec::new();
    for band in 0..bands {
        let coarse = band * count / bands..(band + 1) * count / bands;
        // The fine rows these coarse rows touch (each aggregate's pairs ascend by row).
        let touched = coarse
            .clone()
            .filter(|&g| start[g] < start[g + 1])
            .map(|g| {
                (
                    pairs[start[g]].0 as usize,
                    pairs[start[g + 1] - 1].0 as usize,
                )
            });
        let Some((low, high)) = touched.reduce(|(a, b), (c, d)| (a.min(c), b.max(d))) else {
            continue;
        };
        let chunks = low / rows_per_chunk..(high / rows_per_chunk + 1).min(chunk_count);
        let ap = product(chunks.clone());
        rows.extend(galerkin_rows(
            &ap,
            chunks.start,
            coarse,
            rows_per_chunk,
            width,
            p,
            transpose,
            numbering,
        ));
    }
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

/// The full rows `coarse` of `PᵀAP`, from `ap` = the chunks of `A P` from `first_chunk` on
/// (each `rows_per_chunk` rows), in tasks of consecutive coarse rows.
#[allow(clippy::too_many_arguments)]
fn galerkin_rows(
    ap: &[RowChunk],
    first_chunk: usize,
    coarse: Range<usize>,
    rows_per_chunk: usize,
    width: usize,
    p: &AggregateRows,
    transpose: &(Vec<usize>, Vec<(u32, u32)>),
    numbering: &CoarseNumbering,
) -> Vec<(Vec<usize>, Vec<u32>, Vec<Real>)> {
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
    coarse
        .clone()
        .step_by(GROUPS_PER_TASK)
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|task_first| {
            let mut place = vec![u32::MAX; count];
            let mut touched: Vec<u32> = Vec::new();
            let mut blocks: Vec<[[Real; MODES]; MODES]> = Vec::new();
            let mut out = (Vec::new(), Vec::new(), Vec::new());
            for g in task_first..(task_first + GROUPS_PER_TASK).min(coarse.end) {
                // The rows of one block, consecutive here, share their pattern in AP.
                for group in pairs[start[g]..start[g + 1]].chunks(width) {
                    // Per row of the group: its chunk of AP, where its row starts there, and
                    // its entry of P.
                    let mut rows = [(0usize, 0usize, 0usize); MODES];
                    for (slot, &(i, e)) in rows.iter_mut().zip(group) {
                        let (chunk, local) = (
                            i as usize / rows_per_chunk - first_chunk,
                            i as usize % rows_per_chunk,
                        );
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
            // Grown by doubling: the slack would outlive the chunk in the band held.
            out.0.shrink_to_fit();
            out.1.shrink_to_fit();
            out.2.shrink_to_fit();
            out
        })
        .collect()
}
