//! `linkage bench --large`: Newton iterations per step and time per iteration of the
//! large-displacement solve on a slender 3D box lattice bent far by a side load, against the
//! linear solve of the same body (see `docs/PERFORMANCE.md`, "Large displacements").

use crate::bench::lattice::peak_memory;
use crate::linkage::generators::loaded_lattice;
use crate::linkage::{Body, Equilibrium, Kinematics, NewtonEquilibrium, SolverSettings};
use crate::Real;
use nalgebra::Vector3;
use std::time::Instant;

/// A steel column of `cells` unit cells (0.01 m each, members of 1 mm²), its bottom face
/// clamped, its top face pushed sideways (+x) by `force` N in total.
pub fn column_body(cells: [usize; 3], force: Real) -> Result<Body, String> {
    loaded_lattice("column", cells, Vector3::new(force, 0.0, 0.0)).map_err(|e| e.to_string())
}

/// One load step of the large-displacement solve.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonStepTiming {
    /// Step number.
    pub step: usize,
    /// Newton iterations (each a tangent refill, a numeric factorization and a solve).
    pub iterations: usize,
    /// Halvings of the increment.
    pub cuts: usize,
    /// Relative residual at convergence.
    pub residual: Real,
    /// Conjugate-gradient iterations of the step (0 with the direct solver).
    pub linear_iterations: usize,
    /// Largest displacement, m.
    pub max_displacement: Real,
    /// Wall time of the step, s.
    pub seconds: Real,
}

/// The whole measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct LargeTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Nodes, members, free DOFs.
    pub nodes: usize,
    /// Members.
    pub members: usize,
    /// Free DOFs.
    pub free_dofs: usize,
    /// Entries of the factor.
    pub factor_entries: usize,
    /// Total side force, N.
    pub force: Real,
    /// Linear solve (assembly, ordering, factorization, solve), s.
    pub linear_seconds: Real,
    /// Displacement of the tip (the node the linear model moves most), linear model, m.
    pub linear_tip: Vector3<Real>,
    /// Displacement of the same node under large kinematics, m.
    pub large_tip: Vector3<Real>,
    /// Setup of the Newton solve (pattern, ordering, symbolic and first factorization), s.
    pub setup_seconds: Real,
    /// Per step.
    pub steps: Vec<NewtonStepTiming>,
    /// Seconds in tangent refills and internal forces, numeric factorizations and solves.
    pub assembly: Real,
    /// Numeric factorizations, s.
    pub numeric: Real,
    /// Solves, s.
    pub solve: Real,
    /// Peak resident memory, bytes.
    pub peak_memory: u64,
}

/// Solve the column linearly, then with large kinematics in `steps` load steps, with the
/// linear solver `solver`.
pub fn measure_large(
    cells: [usize; 3],
    force: Real,
    steps: usize,
    solver: SolverSettings,
) -> Result<LargeTiming, String> {
    let mut body = column_body(cells, force)?;
    body.solver = solver;
    let t = Instant::now();
    let (linear_tip_vec, tip) = {
        let eq = Equilibrium::new(&body).map_err(|e| e.to_string())?;
        let state = eq.solve_step(&body, 1, 1).map_err(|e| e.to_string())?;
        let tip = (0..body.nodes.len())
            .max_by(|&a, &b| {
                state.displacements[a]
                    .norm()
                    .total_cmp(&state.displacements[b].norm())
            })
            .unwrap_or(0);
        (state.displacements[tip], tip)
    };
    let linear_seconds = t.elapsed().as_secs_f64();
    body.kinematics = Kinematics::Large;
    let t = Instant::now();
    let mut newton = NewtonEquilibrium::new(&body).map_err(|e| e.to_string())?;
    let setup_seconds = t.elapsed().as_secs_f64();
    let mut timings = Vec::new();
    let mut last = None;
    for step in 1..=steps {
        let t = Instant::now();
        let state = newton
            .solve_step(&body, step, steps)
            .map_err(|e| e.to_string())?;
        let line = NewtonStepTiming {
            step,
            iterations: state.iterations,
            cuts: state.cuts,
            residual: state.residual,
            linear_iterations: state.linear_iterations,
            max_displacement: state
                .displacements
                .iter()
                .map(|u| u.norm())
                .fold(0.0, Real::max),
            seconds: t.elapsed().as_secs_f64(),
        };
        eprintln!("{}", format_step(&line));
        timings.push(line);
        last = Some(state);
    }
    let last = last.ok_or("give at least one step")?;
    Ok(LargeTiming {
        cells,
        nodes: body.nodes.len(),
        members: body.members.len(),
        free_dofs: newton.assembly.n,
        factor_entries: newton.factor_entries,
        force,
        linear_seconds,
        linear_tip: linear_tip_vec,
        large_tip: last.displacements[tip],
        setup_seconds,
        steps: timings,
        assembly: newton.times.assembly,
        numeric: newton.times.numeric,
        solve: newton.times.solve,
        peak_memory: peak_memory(),
    })
}

/// One line per step.
pub fn format_step(s: &NewtonStepTiming) -> String {
    format!(
        "step {:>3}: {:>2} Newton iterations, {} cuts, {} CG iterations, residual {:.1e}, max |u| {:.4} m, {:.2} s ({:.2} s per iteration)",
        s.step,
        s.iterations,
        s.cuts,
        s.linear_iterations,
        s.residual,
        s.max_displacement,
        s.seconds,
        s.seconds / s.iterations.max(1) as Real
    )
}

/// The summary printed at the end.
pub fn format_summary(t: &LargeTiming) -> String {
    let iterations: usize = t.steps.iter().map(|s| s.iterations).sum();
    let newton: Real = t.steps.iter().map(|s| s.seconds).sum();
    format!(
        "{}x{}x{} cells: {} nodes, {} members, {} free DOFs, nnz(L) {}, side force {} N\n\
         linear solve: {:.2} s, tip u = ({:.4}, {:.4}, {:.4}) m\n\
         large: setup {:.2} s; {} steps, {} Newton iterations ({:.2} per step), {:.2} s, {:.2} s per iteration \
         (refill + internal forces {:.2} s, numeric factorization {:.2} s, solves {:.2} s in total)\n\
         tip u = ({:.4}, {:.4}, {:.4}) m: |u_linear − u_large| / |u_large| = {:.0} %; peak memory {:.0} MB",
        t.cells[0],
        t.cells[1],
        t.cells[2],
        t.nodes,
        t.members,
        t.free_dofs,
        t.factor_entries,
        t.force,
        t.linear_seconds,
        t.linear_tip.x,
        t.linear_tip.y,
        t.linear_tip.z,
        t.setup_seconds,
        t.steps.len(),
        iterations,
        iterations as Real / t.steps.len().max(1) as Real,
        newton,
        newton / iterations.max(1) as Real,
        t.assembly,
        t.numeric,
        t.solve,
        t.large_tip.x,
        t.large_tip.y,
        t.large_tip.z,
        100.0 * (t.linear_tip - t.large_tip).norm() / t.large_tip.norm().max(Real::MIN_POSITIVE),
        t.peak_memory as f64 / 1048576.0
    )
}
