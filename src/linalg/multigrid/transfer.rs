//! The prolongator and its transpose: rows stored by aggregate, built in parallel chunks, and
//! the single-precision copy the V-cycle prolongs and restricts with.

use crate::Real;
use rayon::prelude::*;

/// Rows per parallel task.
pub(super) const ROWS_PER_TASK: usize = 1024;

/// Near-null-space modes carried per aggregate: the 6 rigid-body motions in 3D (3 in 2D, the
/// other rows zero), so a near-null-space row has this many values.
pub const MODES: usize = 6;

/// A transfer operator between a level and the next coarser one, stored by aggregate: row i
/// holds one `MODES`-value segment per aggregate it touches (the coarse DOFs of an aggregate
/// are consecutive, `rank[g]` of them from `offset[g]`). Working per aggregate instead of per
/// coarse DOF makes one index lookup serve six values.
#[derive(Clone, Debug, Default)]
pub(super) struct AggregateRows {
    pub(super) row_ptr: Vec<usize>,
    pub(super) aggregate: Vec<u32>,
    pub(super) value: Vec<[Real; MODES]>,
}

impl AggregateRows {
    pub(super) fn rows(&self) -> usize {
        self.row_ptr.len() - 1
    }
}

/// The coarse DOFs of each aggregate: `offset[g]..offset[g] + rank[g]`.
#[derive(Clone, Debug, Default)]
pub(super) struct CoarseNumbering {
    pub(super) offset: Vec<usize>,
    pub(super) rank: Vec<usize>,
}

/// For each aggregate, the (fine row, entry) pairs of the prolongator that touch it: the
/// transpose, for restriction and the Galerkin product.
pub(super) fn by_aggregate(p: &AggregateRows, count: usize) -> (Vec<usize>, Vec<(u32, u32)>) {
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
pub(super) type RowChunk = (Vec<usize>, Vec<u32>, Vec<[Real; MODES]>);

/// Per-chunk rows, concatenated in chunk order.
pub(super) fn concatenate(chunks: Vec<RowChunk>) -> AggregateRows {
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
pub(super) struct RowAccumulator {
    place: Vec<u32>,
    aggregates: Vec<u32>,
    values: Vec<[Real; MODES]>,
}

impl RowAccumulator {
    pub(super) fn new(count: usize) -> Self {
        RowAccumulator {
            place: vec![u32::MAX; count],
            aggregates: Vec::new(),
            values: Vec::new(),
        }
    }

    pub(super) fn add(&mut self, g: u32, scale: Real, v: &[Real; MODES]) {
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
    pub(super) fn finish(&mut self, out: &mut RowChunk) {
        out.0.push(self.aggregates.len());
        for &g in &self.aggregates {
            self.place[g as usize] = u32::MAX;
        }
        out.1.append(&mut self.aggregates);
        out.2.append(&mut self.values);
    }
}

/// The prolongator as the cycle uses it, in single precision (the Galerkin product used the
/// double-precision one): by fine rows for prolongation and by aggregates for restriction, so
/// that both read their values in order.
pub(super) struct Transfer {
    /// Per fine row, its entries `row_ptr[i]..row_ptr[i + 1]` in `row_entries`.
    row_ptr: Vec<usize>,
    /// (aggregate, `MODES` values) of each entry by rows.
    row_entries: Vec<(u32, [f32; MODES])>,
    /// Per aggregate, its entries `aggregate_ptr[g]..aggregate_ptr[g + 1]` in `aggregate_entries`.
    aggregate_ptr: Vec<usize>,
    /// (fine row, `MODES` values) of each entry by aggregates.
    aggregate_entries: Vec<(u32, [f32; MODES])>,
    /// The coarse DOFs of each aggregate.
    numbering: CoarseNumbering,
}

impl Transfer {
    /// The single-precision copy of `p`, with its transpose `by_aggregate(p)` and the coarse
    /// numbering of its aggregates.
    pub(super) fn new(
        p: &AggregateRows,
        transpose: &(Vec<usize>, Vec<(u32, u32)>),
        numbering: CoarseNumbering,
    ) -> Self {
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
            numbering,
        }
    }

    /// `x += P xc`.
    pub(super) fn prolong_add(&self, coarse: &[Real], x: &mut [Real]) {
        let p = self;
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
    pub(super) fn restrict(&self, r: &[Real], coarse: &mut [Real]) {
        let p = self;
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
