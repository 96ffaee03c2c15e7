//! `linkage bench --cholmod`: the direct solver against CHOLMOD on the same `K_ff`.
//!
//! The lattice's free-free stiffness (lower triangle, CSC) and its load vector are written
//! to a NumPy `.npz`; `bench/cholmod_compare.py` (embedded here as [`COMPARE_SCRIPT`]) reads
//! it and times scikit-sparse's CHOLMOD. Our side times the same phases in this process:
//! ordering + symbolic analysis, numeric factorization, one solve.

use crate::linalg::cholesky::{CholeskyOptions, OrderingChoice, SparseCholesky};
use crate::linalg::SymmetricCsr;
use crate::linkage::generators::lattice_body;
use crate::linkage::{linear_member_block, DofMap, StiffnessAssembly};
use crate::scene::npz_archive::{NpzIn, NpzOut};
use crate::Real;
use std::time::Instant;

/// The Python script that times CHOLMOD on a system written by [`system_npz`].
pub const COMPARE_SCRIPT: &str = include_str!("../../bench/cholmod_compare.py");

/// A symmetric positive definite system `A x = b`, `A` by its lower triangle in CSC form.
#[derive(Clone, Debug, PartialEq)]
pub struct LowerSystem {
    /// Rows and columns.
    pub n: usize,
    /// Column starts, length `n + 1`.
    pub col_ptr: Vec<usize>,
    /// Row of each entry, ascending within a column, the diagonal first.
    pub row_idx: Vec<usize>,
    /// Entry values (N/m for a stiffness).
    pub values: Vec<Real>,
    /// Right-hand side, length `n` (N).
    pub rhs: Vec<Real>,
    /// Node of each row (`None`: order the rows themselves).
    pub groups: Option<Vec<usize>>,
}

/// `K_ff` and the load vector of [`lattice_body`]`(cells)`, assembled as `linkage run` does.
/// Returns the system and the lattice's member count.
pub fn lattice_system(cells: [usize; 3]) -> Result<(LowerSystem, usize), String> {
    let body = lattice_body(cells).map_err(|e| e.to_string())?;
    let dofs = DofMap::new(&body);
    let asm = StiffnessAssembly::new(&body, &dofs).map_err(|e| e.to_string())?;
    let mut values = Vec::new();
    asm.fill(&body, |m| linear_member_block(&body, m), &mut values);
    let mut rhs = vec![0.0; asm.n];
    for l in &body.loads {
        for k in 0..dofs.dofs_per_node {
            if let Some(i) = dofs.free_index(l.node, k) {
                rhs[i] += l.force[k];
            }
        }
    }
    let system = LowerSystem {
        n: asm.n,
        col_ptr: asm.col_ptr,
        row_idx: asm.row_idx,
        values,
        rhs,
        groups: Some(asm.groups),
    };
    Ok((system, body.members.len()))
}

/// The system as a NumPy `.npz`: `n` (scalar), `col_ptr`, `row_idx` (int64), `values`, `rhs`
/// (float64), the lower triangle in CSC form as `scipy.sparse.csc_matrix` reads it.
pub fn system_npz(s: &LowerSystem) -> std::io::Result<Vec<u8>> {
    let mut npz = NpzOut::new();
    npz.i64s("n", &[], [s.n])?;
    npz.i64s("col_ptr", &[s.col_ptr.len()], s.col_ptr.iter().copied())?;
    npz.i64s("row_idx", &[s.row_idx.len()], s.row_idx.iter().copied())?;
    npz.f64s("values", &[s.values.len()], &s.values)?;
    npz.f64s("rhs", &[s.rhs.len()], &s.rhs)?;
    npz.finish()
}

/// Reads back what [`system_npz`] wrote (without groups), checking the lengths.
pub fn read_system_npz(bytes: &[u8]) -> Result<LowerSystem, String> {
    let mut npz = NpzIn::new(bytes)?;
    let n = npz.usizes("n")?.scalar("n")?;
    let col_ptr = npz.usizes("col_ptr")?.list("col_ptr", Some(n + 1))?;
    let nnz = col_ptr.last().copied().unwrap_or(0);
    Ok(LowerSystem {
        n,
        row_idx: npz.usizes("row_idx")?.list("row_idx", Some(nnz))?,
        values: npz.f64s("values")?.list("values", Some(nnz))?,
        rhs: npz.f64s("rhs")?.list("rhs", Some(n))?,
        col_ptr,
        groups: None,
    })
}

/// One direct solve, timed by phase (wall seconds) with this process's CPU time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectTiming {
    /// Ordering and symbolic analysis, s.
    pub analyze: Real,
    /// Numeric factorization, s.
    pub factor: Real,
    /// One solve, s.
    pub solve: Real,
    /// CPU time of all threads over the three phases, s.
    pub cpu: Real,
    /// Relative residual ‖b − A x‖ / ‖b‖.
    pub residual: Real,
    /// Entries of L.
    pub nnz_l: usize,
    /// The two nested dissections the tree path chose from (`None` off the tree path).
    pub orderings: Option<OrderingChoice>,
    /// Flops of the factorization by its supernodes (`None` when simplicial).
    pub flops: Option<Real>,
}

impl DirectTiming {
    /// Ordering + factorization + solve, s.
    pub fn total(&self) -> Real {
        self.analyze + self.factor + self.solve
    }
}

/// Orders, factors and solves `s` with [`SparseCholesky`] and `options`, timing each phase;
/// `tree = false` analyses, factors and solves with faer as for a small body instead of the
/// tree path (the node graph's analysis, the tree-parallel factorization, the tree solves).
pub fn time_direct(
    s: &LowerSystem,
    options: CholeskyOptions,
    tree: bool,
) -> Result<DirectTiming, String> {
    let cpu0 = cpu_seconds();
    let t = Instant::now();
    let analyze_with = if tree {
        SparseCholesky::analyze_with
    } else {
        SparseCholesky::analyze_with_faers_loop
    };
    let mut c = analyze_with(s.n, &s.col_ptr, &s.row_idx, s.groups.as_deref(), options)
        .map_err(|e| e.to_string())?;
    let analyze = t.elapsed().as_secs_f64();
    let t = Instant::now();
    c.factorize(&s.values).map_err(|e| e.to_string())?;
    let factor = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut x = s.rhs.clone();
    c.solve_in_place(&mut x);
    let solve = t.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu0;
    let nnz_l = c.stats().nnz_l;
    let (orderings, flops) = (c.ordering_choice(), c.factor_flops());
    drop(c);
    Ok(DirectTiming {
        analyze,
        factor,
        solve,
        cpu,
        residual: relative_residual(s, &x),
        nnz_l,
        orderings,
        flops,
    })
}

/// ‖b − A x‖ / ‖b‖ with `A` the symmetric matrix of the lower triangle.
pub fn relative_residual(s: &LowerSystem, x: &[Real]) -> Real {
    let mut a = SymmetricCsr::from_lower(s.n, &s.col_ptr, &s.row_idx);
    a.refill(&s.values);
    let mut r = vec![0.0; s.n];
    a.residual(&s.rhs, x, &mut r);
    let norm = |v: &[Real]| v.iter().map(|x| x * x).sum::<Real>().sqrt();
    norm(&r) / norm(&s.rhs).max(Real::MIN_POSITIVE)
}

/// User + system CPU time of this process (all threads), s; 0 where unknown.
pub fn cpu_seconds() -> Real {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } != 0 {
        return 0.0;
    }
    let secs = |t: libc::timeval| t.tv_sec as Real + t.tv_usec as Real * 1e-6;
    secs(usage.ru_utime) + secs(usage.ru_stime)
}

/// The 1-minute load average (from /proc/loadavg), `None` where unknown.
pub fn load_average() -> Option<Real> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npz_round_trip_is_exact() {
        let (mut s, members) = lattice_system([2, 2, 2]).unwrap();
        // 54 cell edges, 72 face diagonals, 32 body diagonals.
        assert_eq!(members, 158);
        // Values that need all 17 digits survive.
        s.values[0] = 1.0 / 3.0;
        s.rhs[1] = -std::f64::consts::PI * 1e-300;
        let back = read_system_npz(&system_npz(&s).unwrap()).unwrap();
        assert_eq!(back, LowerSystem { groups: None, ..s });
    }

    #[test]
    fn direct_solve_of_a_small_lattice_has_a_tiny_residual() {
        let (s, _) = lattice_system([3, 3, 3]).unwrap();
        let t = time_direct(&s, CholeskyOptions::default(), true).unwrap();
        assert!(t.residual < 1e-12, "residual {}", t.residual);
        assert!(t.nnz_l >= s.row_idx.len());
        // A wrong answer gives a residual of order one.
        let x = vec![0.0; s.n];
        assert!((relative_residual(&s, &x) - 1.0).abs() < 1e-15);
    }
}
