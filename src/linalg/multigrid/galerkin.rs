//! The Galerkin coarse matrix `PᵀAP`: the product `A P` (by full rows or by blocks of the
//! single-precision copy), then `Pᵀ (A P)` by aggregates.

use super::transfer::{
    AggregateRows, CoarseNumbering, RowAccumulator, RowChunk, MODES, ROWS_PER_TASK,
};
use crate::linalg::block_matrix::{BlockMatrix, BLOCK_ROWS_PER_TASK};
use crate::linalg::SymmetricCsr;
use crate::Real;
use rayon::prelude::*;

/// `A P` for the block copy `a` (block rows of `W` rows), in chunks of `W · BLOCK_ROWS_PER_TASK`
/// rows; each row of `A P` is then scaled by `scale(row)` and, when `add` is given, the row
/// of `add` is added. With the rows of one block sharing their pattern in `p` (true of the
/// tentative prolongator and of every product of this function), one aggregate lookup serves
/// a whole `W×W` block times `W×MODES` values.
pub(super) fn block_product<const W: usize>(
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

/// `A P` row by row, per aggregate, in chunks of `ROWS_PER_TASK` rows.
pub(super) fn product_by_rows(a: &SymmetricCsr, p: &AggregateRows, count: usize) -> Vec<RowChunk> {
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
pub(super) fn galerkin(
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
