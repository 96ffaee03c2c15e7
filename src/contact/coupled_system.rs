//! One sparse system for all the bodies of a scene with contact: each body's `K_ff` on the
//! diagonal (its pattern computed once by [`StiffnessAssembly`]), plus the penalty blocks of
//! the active contacts, factored together.

use crate::linalg::cholesky::{CholeskyError, SparseCholesky};
use crate::linalg::SparseLdlt;
use crate::linkage::StiffnessAssembly;
use crate::Real;

/// The lower triangle (compressed columns) of the coupled tangent of all bodies, its
/// factorization, and where each body's entries land in it.
pub(crate) struct CoupledSystem {
    /// Rows and columns: the free DOFs of all bodies, body after body.
    pub n: usize,
    /// First global free DOF of each body.
    pub offsets: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Per body, the global place of each of its assembly's entries.
    places: Vec<Vec<usize>>,
    /// Values in the global pattern, N/m.
    pub values: Vec<Real>,
    /// Node of each row (the ordering keeps a node's DOFs together).
    groups: Vec<usize>,
    /// Analyzed at construction, or on the first factorization when `new` was told not to
    /// (bodies solved iteratively factor only when conjugate gradients cannot serve).
    cholesky: Option<SparseCholesky>,
    /// LDLᵀ on the same ordering, built the first time the tangent is indefinite.
    ldlt: Option<SparseLdlt>,
    /// Whether the last factorization is the LDLᵀ one.
    indefinite: bool,
}

impl CoupledSystem {
    /// The pattern of `assemblies` on the diagonal (body order) plus the entries `extra`
    /// (global free DOF pairs, either order: contacts between bodies); `node_offsets[b]` is the
    /// first global node of body b (the ordering keeps the DOFs of a node together). The
    /// pattern is analyzed at once when `analyze`, else on the first factorization.
    pub(crate) fn new(
        assemblies: &[&StiffnessAssembly],
        node_offsets: &[usize],
        extra: &[(usize, usize)],
        analyze: bool,
    ) -> Result<Self, CholeskyError> {
        let mut offsets = Vec::with_capacity(assemblies.len());
        let mut n = 0;
        for a in assemblies {
            offsets.push(n);
            n += a.n;
        }
        let mut columns: Vec<Vec<usize>> = Vec::with_capacity(n);
        let mut groups = Vec::with_capacity(n);
        for ((a, &offset), &node_offset) in assemblies.iter().zip(&offsets).zip(node_offsets) {
            for c in 0..a.n {
                columns.push(
                    a.row_idx[a.col_ptr[c]..a.col_ptr[c + 1]]
                        .iter()
                        .map(|r| r + offset)
                        .collect(),
                );
                groups.push(a.groups[c] + node_offset);
            }
        }
        for &(r, c) in extra {
            let (r, c) = (r.max(c), r.min(c));
            if c < n && r < n {
                columns[c].push(r);
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        for mut rows in columns {
            rows.sort_unstable();
            rows.dedup();
            row_idx.extend(rows);
            col_ptr.push(row_idx.len());
        }
        let mut places = Vec::with_capacity(assemblies.len());
        for (a, &offset) in assemblies.iter().zip(&offsets) {
            let mut place = Vec::with_capacity(a.nnz());
            for c in 0..a.n {
                let gc = c + offset;
                let rows = &row_idx[col_ptr[gc]..col_ptr[gc + 1]];
                for &r in &a.row_idx[a.col_ptr[c]..a.col_ptr[c + 1]] {
                    let k = rows.binary_search(&(r + offset)).map_err(|_| {
                        CholeskyError::InvalidInput("a body entry left the pattern".to_string())
                    })?;
                    place.push(col_ptr[gc] + k);
                }
            }
            places.push(place);
        }
        let cholesky = if n > 0 && analyze {
            Some(SparseCholesky::analyze(
                n,
                &col_ptr,
                &row_idx,
                Some(&groups),
            )?)
        } else {
            None
        };
        Ok(CoupledSystem {
            n,
            offsets,
            values: vec![0.0; row_idx.len()],
            col_ptr,
            row_idx,
            places,
            groups,
            cholesky,
            ldlt: None,
            indefinite: false,
        })
    }

    /// The lower triangle's column starts.
    pub(crate) fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// The lower triangle's row of each entry.
    pub(crate) fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Whether entry (`r`, `c`) (either order) is in the pattern.
    pub(crate) fn contains(&self, r: usize, c: usize) -> bool {
        let (r, c) = (r.max(c), r.min(c));
        self.row_idx[self.col_ptr[c]..self.col_ptr[c + 1]]
            .binary_search(&r)
            .is_ok()
    }

    /// Set the values to the bodies' tangents (`local[b]` in body b's assembly pattern).
    pub(crate) fn fill(&mut self, local: &[Vec<Real>]) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
        for (place, values) in self.places.iter().zip(local) {
            for (&p, &v) in place.iter().zip(values) {
                self.values[p] += v;
            }
        }
    }

    /// Add `v` to entry (`r`, `c`) of the symmetric matrix, global free DOFs. Give every entry
    /// of a symmetric contribution: entries above the diagonal are skipped (their mirror is
    /// stored). Returns false if the entry is not in the pattern.
    pub(crate) fn add(&mut self, r: usize, c: usize, v: Real) -> bool {
        if r < c {
            return true;
        }
        let range = self.col_ptr[c]..self.col_ptr[c + 1];
        match self.row_idx[range.clone()].binary_search(&r) {
            Ok(k) => {
                self.values[range.start + k] += v;
                true
            }
            Err(_) => false,
        }
    }

    /// Add `relative` times the largest diagonal entry to every diagonal entry.
    pub(crate) fn stabilise(&mut self, relative: Real) {
        let diagonal: Vec<usize> = (0..self.n)
            .filter_map(|c| {
                let range = self.col_ptr[c]..self.col_ptr[c + 1];
                self.row_idx[range.clone()]
                    .binary_search(&c)
                    .ok()
                    .map(|k| range.start + k)
            })
            .collect();
        let largest = diagonal
            .iter()
            .map(|&p| self.values[p].abs())
            .fold(0.0, Real::max);
        for p in diagonal {
            self.values[p] += relative * largest;
        }
    }

    /// Factor the current values (LLᵀ).
    pub(crate) fn factorize(&mut self) -> Result<(), CholeskyError> {
        self.indefinite = false;
        if self.cholesky.is_none() && self.n > 0 {
            self.cholesky = Some(SparseCholesky::analyze(
                self.n,
                &self.col_ptr,
                &self.row_idx,
                Some(&self.groups),
            )?);
        }
        match self.cholesky.as_mut() {
            Some(c) => c.factorize(&self.values),
            None => Ok(()),
        }
    }

    /// Factor the current values by LDLᵀ (an indefinite tangent, after LLᵀ failed on it) on
    /// the ordering of the LLᵀ. Returns the number of negative pivots.
    pub(crate) fn factorize_indefinite(&mut self) -> Result<usize, CholeskyError> {
        self.indefinite = false;
        let Some(cholesky) = self.cholesky.as_ref() else {
            return Ok(0);
        };
        if self.ldlt.is_none() {
            self.ldlt = Some(SparseLdlt::with_ordering_of(
                cholesky,
                &self.col_ptr,
                &self.row_idx,
            )?);
        }
        let Some(ldlt) = self.ldlt.as_mut() else {
            return Ok(0);
        };
        let negative = ldlt.factorize(&self.values)?;
        self.indefinite = true;
        Ok(negative)
    }

    /// Solve with the last factorization (LLᵀ or LDLᵀ), in place.
    pub(crate) fn solve_in_place(&mut self, rhs: &mut [Real]) {
        if self.indefinite {
            if let Some(l) = self.ldlt.as_mut() {
                l.solve_in_place(rhs);
                return;
            }
        }
        if let Some(c) = self.cholesky.as_mut() {
            c.solve_in_place(rhs);
        }
    }

    /// The body and its free index of a global free DOF.
    pub(crate) fn locate(&self, global: usize) -> (usize, usize) {
        let body = self.offsets.partition_point(|&o| o <= global) - 1;
        (body, global - self.offsets[body])
    }
}
