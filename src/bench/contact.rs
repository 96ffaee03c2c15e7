//! `linkage bench --contact`: a 3D box lattice on a fixed floor pressed by a ball obstacle, its
//! body solved by the chosen solver in the contact solver: model size, phases, time per contact
//! step and peak memory (see `docs/PERFORMANCE.md`, "Contact").

use crate::bench::lattice::peak_memory;
use crate::linkage::PhaseTimes;
use crate::scene::{build_world, Simulation};
use crate::Real;
use std::path::Path;
use std::time::Instant;

/// One contact step.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactStepTiming {
    /// Step number.
    pub step: usize,
    /// Newton iterations, contact iterations, halvings, conjugate-gradient iterations.
    pub iterations: [usize; 4],
    /// Nodes in contact at the end.
    pub contacts: usize,
    /// Largest penetration, m, and relative residual.
    pub max_penetration: Real,
    /// Relative residual at the end.
    pub residual: Real,
    /// Wall time of the step, s.
    pub seconds: Real,
}

/// The whole measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Nodes, members and free DOFs.
    pub sizes: [usize; 3],
    /// The solver the body got ("direct" or "iterative").
    pub solver: String,
    /// Building the world and the contact solver, s.
    pub setup_seconds: Real,
    /// Per step (step 0 left out).
    pub steps: Vec<ContactStepTiming>,
    /// Time per phase over the run, s, and in contact queries.
    pub phases: PhaseTimes,
    /// Contact queries, s.
    pub query_seconds: Real,
    /// Peak resident memory of the process, bytes.
    pub peak_memory: u64,
}

/// The scene: a rubber box lattice of `cells` cells of 1 cm, its bottom face fixed, pressed 2
/// mm deep in `steps` steps by a ball of a third of its width at the middle of its top face;
/// `solver` is "direct", "iterative" or "auto".
pub fn scene(cells: [usize; 3], steps: usize, solver: &str) -> String {
    let [x, y, z] = cells.map(|c| c as Real * 0.01);
    let radius = x.min(z) / 3.0;
    format!(
        r#"name = "ball_on_lattice"
steps = {steps}
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-6
[[bodies]]
name = "lattice"
box_lattice = {{ size = [{x}, {y}, {z}], cells = [{}, {}, {}] }}
solver = "{solver}"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[obstacles]]
name = "ball"
shape = "ball"
center = [{}, {}, {}]
radius = {radius}
travel = [0.0, -0.002, 0.0]
"#,
        cells[0],
        cells[1],
        cells[2],
        x / 2.0,
        y + radius,
        z / 2.0
    )
}

/// Build and run the scene of [`scene`], timing each step.
pub fn measure_contact(
    cells: [usize; 3],
    steps: usize,
    solver: &str,
) -> Result<ContactTiming, String> {
    let t = Instant::now();
    let world = build_world(
        &scene(cells, steps, solver),
        Path::new("ball_on_lattice.toml"),
    )
    .map_err(|e| e.to_string())?;
    let mut sim = Simulation::new(&world).map_err(|e| e.to_string())?;
    let setup_seconds = t.elapsed().as_secs_f64();
    let size = &sim.sizes()[0];
    let (sizes, solver) = (
        [size.nodes, size.members, size.free_dofs],
        size.solver.clone(),
    );
    let mut timings = Vec::with_capacity(steps);
    for step in 0..=steps {
        let t = Instant::now();
        let (result, summary) = sim.step(step).map_err(|e| e.to_string())?;
        if step == 0 {
            continue;
        }
        timings.push(ContactStepTiming {
            step,
            iterations: [
                summary.iterations,
                summary.contact_iterations,
                summary.cuts,
                summary.linear_iterations,
            ],
            contacts: result.bodies[0].contacts.len(),
            max_penetration: summary.max_penetration,
            residual: summary.residual,
            seconds: t.elapsed().as_secs_f64(),
        });
    }
    let (phases, query_seconds) = sim
        .contact()
        .map_or((PhaseTimes::default(), 0.0), |c| (c.times, c.query_seconds));
    Ok(ContactTiming {
        cells,
        sizes,
        solver,
        setup_seconds,
        steps: timings,
        phases,
        query_seconds,
        peak_memory: peak_memory(),
    })
}

/// One line per step.
pub fn format_step(s: &ContactStepTiming) -> String {
    let [newton, contact, cuts, cg] = s.iterations;
    format!(
        "step {:>3}: {newton:>3} Newton, {contact:>2} contact iterations, {cuts} cuts, {cg:>5} CG iterations; {:>5} contacts, max penetration {:.3e} m, residual {:.1e}; {:.2} s",
        s.step, s.contacts, s.max_penetration, s.residual, s.seconds
    )
}

/// The model and the totals.
pub fn format_summary(t: &ContactTiming) -> String {
    let per_step = t.steps.iter().map(|s| s.seconds).sum::<Real>() / t.steps.len().max(1) as Real;
    format!(
        "{}x{}x{} cells: {} nodes, {} members, {} free DOFs, solver {}; setup {:.2} s, {:.2} s per contact step; phases: assembly {:.2} s, ordering+symbolic {:.2} s, factorization {:.2} s, solve {:.2} s, contact_query {:.2} s; peak memory {:.0} MB",
        t.cells[0],
        t.cells[1],
        t.cells[2],
        t.sizes[0],
        t.sizes[1],
        t.sizes[2],
        t.solver,
        t.setup_seconds,
        per_step,
        t.phases.assembly,
        t.phases.symbolic,
        t.phases.numeric,
        t.phases.solve,
        t.query_seconds,
        t.peak_memory as f64 / 1048576.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_small_ball_press_is_measured() {
        let t = measure_contact([6, 3, 6], 2, "iterative").unwrap();
        assert_eq!(t.solver, "iterative");
        assert_eq!(t.steps.len(), 2);
        assert!(t.steps.iter().all(|s| s.contacts > 0 && s.residual < 1e-8));
        assert!(format_summary(&t).contains("solver iterative"));
    }
}
