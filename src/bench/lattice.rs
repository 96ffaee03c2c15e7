//! `linkage bench`: the phases of the linear solve on 3D box lattices of growing size.

use crate::linkage::generators::lattice_body;
use crate::linkage::Equilibrium;
use crate::Real;
use std::time::Instant;

/// One measured lattice.
#[derive(Clone, Debug, PartialEq)]
pub struct LatticeTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Nodes.
    pub nodes: usize,
    /// Members.
    pub members: usize,
    /// Free DOFs.
    pub free_dofs: usize,
    /// Entries of the lower triangle of `K_ff`.
    pub matrix_entries: usize,
    /// Entries of the Cholesky factor.
    pub factor_entries: usize,
    /// Generating the lattice, s.
    pub generate: Real,
    /// Assembly of `K_ff`, s.
    pub assembly: Real,
    /// Ordering and symbolic factorization, s.
    pub symbolic: Real,
    /// Numeric factorization, s.
    pub numeric: Real,
    /// Triangular solve, s.
    pub solve: Real,
    /// Relative equilibrium residual of the answer.
    pub residual: Real,
    /// Peak resident memory of the process, bytes (0 where unknown).
    pub peak_memory: u64,
}

/// Generate, assemble, factor and solve one lattice, timing each phase.
pub fn measure_lattice(cells: [usize; 3]) -> Result<LatticeTiming, String> {
    let t = Instant::now();
    let mut body = lattice_body(cells).map_err(|e| e.to_string())?;
    body.solver.choice = crate::linkage::SolverChoice::Direct;
    let generate = t.elapsed().as_secs_f64();
    let eq = Equilibrium::new(&body).map_err(|e| e.to_string())?;
    let state = eq.solve_step(&body, 1, 1).map_err(|e| e.to_string())?;
    Ok(LatticeTiming {
        cells,
        nodes: body.nodes.len(),
        members: body.members.len(),
        free_dofs: eq.free_dofs,
        matrix_entries: eq.matrix_entries,
        factor_entries: eq.factor_entries,
        generate,
        assembly: eq.times.assembly,
        symbolic: eq.times.symbolic,
        numeric: eq.times.numeric,
        solve: eq.times.solve,
        residual: state.residual,
        peak_memory: peak_memory(),
    })
}

/// Peak resident set size of this process (VmHWM), bytes; 0 where /proc is unavailable.
pub fn peak_memory() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map(|kb| kb * 1024)
        .unwrap_or(0)
}

/// The table header printed by `linkage bench`.
pub const HEADER: &str = "cells        nodes    members   free DOFs   nnz(K_ff)     nnz(L)  generate  assembly  symbolic   numeric     solve     total  residual   peak MB";

/// One table row.
pub fn format_row(t: &LatticeTiming) -> String {
    let total = t.assembly + t.symbolic + t.numeric + t.solve;
    format!(
        "{:<10} {:>8} {:>10} {:>11} {:>11} {:>10} {:>8.3}s {:>8.3}s {:>8.3}s {:>8.3}s {:>8.3}s {:>8.3}s {:>9.1e} {:>9.0}",
        format!("{}x{}x{}", t.cells[0], t.cells[1], t.cells[2]),
        t.nodes,
        t.members,
        t.free_dofs,
        t.matrix_entries,
        t.factor_entries,
        t.generate,
        t.assembly,
        t.symbolic,
        t.numeric,
        t.solve,
        total,
        t.residual,
        t.peak_memory as f64 / 1048576.0
    )
}

/// One lattice solved by block-Jacobi conjugate gradients to a relative residual of 1e-10.
#[derive(Clone, Debug, PartialEq)]
pub struct IterativeTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Members.
    pub members: usize,
    /// Free DOFs.
    pub free_dofs: usize,
    /// Pattern, fill and full-row copy, s.
    pub assembly: Real,
    /// Preconditioner set-up, s.
    pub setup: Real,
    /// Conjugate-gradient iterations.
    pub iterations: usize,
    /// Iteration time, s.
    pub solve: Real,
    /// True relative residual.
    pub residual: Real,
    /// Peak resident memory, bytes.
    pub peak_memory: u64,
}

/// Assemble a lattice and solve it with conjugate gradients preconditioned by smoothed
/// aggregation (`multigrid`) or block Jacobi, timing each phase.
pub fn measure_iterative(cells: [usize; 3], multigrid: bool) -> Result<IterativeTiming, String> {
    use crate::linalg::{
        conjugate_gradient, BlockJacobi, CgSettings, Preconditioner, SmoothedAggregation,
        SymmetricCsr,
    };
    use crate::linkage::{linear_member_block, DofMap, StiffnessAssembly};
    let body = lattice_body(cells).map_err(|e| e.to_string())?;
    let t = Instant::now();
    let dofs = DofMap::new(&body);
    let asm = StiffnessAssembly::new(&body, &dofs).map_err(|e| e.to_string())?;
    let mut values = Vec::new();
    asm.fill(&body, |m| linear_member_block(&body, m), &mut values);
    let mut csr = SymmetricCsr::from_lower(asm.n, &asm.col_ptr, &asm.row_idx);
    csr.refill(&values);
    drop(values);
    let assembly = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut m: Box<dyn Preconditioner> = if multigrid {
        let near_null_space = crate::linkage::rigid_modes::rigid_body_rows(&body.nodes, &dofs);
        Box::new(
            SmoothedAggregation::new(&csr, &asm.groups, &near_null_space)
                .map_err(|e| e.to_string())?,
        )
    } else {
        Box::new(BlockJacobi::new(&csr, &asm.groups).map_err(|e| e.to_string())?)
    };
    let setup = t.elapsed().as_secs_f64();
    let d = dofs.dofs_per_node;
    let mut b = vec![0.0; asm.n];
    for l in &body.loads {
        for k in 0..d {
            if let Some(i) = dofs.free_index(l.node, k) {
                b[i] += l.force[k];
            }
        }
    }
    let mut x = vec![0.0; asm.n];
    let t = Instant::now();
    let report = conjugate_gradient(&csr, m.as_mut(), &b, &mut x, CgSettings::default());
    Ok(IterativeTiming {
        cells,
        members: body.members.len(),
        free_dofs: asm.n,
        assembly,
        setup,
        iterations: report.iterations,
        solve: t.elapsed().as_secs_f64(),
        residual: report.residual,
        peak_memory: peak_memory(),
    })
}

/// The iterative table header.
pub const ITERATIVE_HEADER: &str =
    "cells         members   free DOFs  assembly     setup  iterations     solve  residual   peak MB";

/// One iterative table row.
pub fn format_iterative_row(t: &IterativeTiming) -> String {
    format!(
        "{:<10} {:>10} {:>11} {:>8.3}s {:>8.3}s {:>11} {:>8.3}s {:>9.1e} {:>9.0}",
        format!("{}x{}x{}", t.cells[0], t.cells[1], t.cells[2]),
        t.members,
        t.free_dofs,
        t.assembly,
        t.setup,
        t.iterations,
        t.solve,
        t.residual,
        t.peak_memory as f64 / 1048576.0
    )
}
