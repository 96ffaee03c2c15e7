//! `linkage bench --dynamics`, first part: a 3D box lattice with density dropped (initial
//! velocity and gravity) on a floor (a half-space obstacle), energy–momentum with penalty
//! contact, run through [`DynamicSimulation`] one time step per stored state: the model size,
//! time per time step, steps per second and the phases (see `docs/PERFORMANCE.md`,
//! "Dynamics").

use crate::bench::lattice::peak_memory;
use crate::linkage::PhaseTimes;
use crate::scene::{build_world, DynamicSimulation};
use crate::Real;
use std::path::Path;
use std::time::Instant;

/// Cells per direction of the default lattice: 9,261 nodes, 108,860 members.
pub const CELLS: [usize; 3] = [20, 20, 20];
/// Cells of the `--quick` lattice (216 nodes, 1,940 members).
pub const QUICK_CELLS: [usize; 3] = [5, 5, 5];
/// Time steps of the default run.
pub const STEPS: usize = 20;
/// Time steps of the `--quick` run.
pub const QUICK_STEPS: usize = 8;
/// Time step, s.
pub const TIME_STEP: Real = 1e-4;
/// Speed the lattice is thrown down at, m/s.
pub const SPEED: Real = 1.0;
/// Time steps of free fall before the lowest nodes reach the floor.
pub const STEPS_BEFORE_CONTACT: usize = 3;

/// The scene: a rubber box lattice of `cells` cells of 1 cm (E = 10 MPa, A = 1 mm², ρ = 1000
/// kg/m³), thrown down at [`SPEED`] under gravity from a height it falls in
/// [`STEPS_BEFORE_CONTACT`] time steps and a half, onto the floor `y = 0` (penalty 1e4 N/m),
/// energy–momentum, `steps` time steps of [`TIME_STEP`], every step stored.
pub fn scene(cells: [usize; 3], steps: usize) -> String {
    let [x, y, z] = cells.map(|c| c as Real * 0.01);
    let gap = SPEED * TIME_STEP * (STEPS_BEFORE_CONTACT as Real + 0.5);
    let duration = TIME_STEP * steps as Real;
    format!(
        r#"name = "dropped_lattice"
gravity = [0.0, -9.81, 0.0]

[dynamics]
duration = {duration:e}
time_step = {TIME_STEP:e}
frames = {steps}
integrator = "energy_momentum"

[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-6
density = 1000.0

[[bodies]]
name = "lattice"
box_lattice = {{ size = [{x}, {y}, {z}], cells = [{}, {}, {}] }}
offset = [0.0, {gap:e}, 0.0]
velocity = [0.0, -{SPEED}, 0.0]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]

[contact]
penalty = 1e4
"#,
        cells[0], cells[1], cells[2],
    )
}

/// One time step.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeStepTiming {
    /// Time at its end, s.
    pub time: Real,
    /// Newton iterations, contact iterations, halvings of the time step.
    pub iterations: [usize; 3],
    /// Nodes in contact at the end.
    pub contacts: usize,
    /// Largest penetration, m.
    pub max_penetration: Real,
    /// Energy balance at the end (kinetic + strain + penalty − work of gravity), J.
    pub total_energy: Real,
    /// Wall time of the step, s.
    pub seconds: Real,
}

/// The whole measurement.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicsTiming {
    /// Cells per direction.
    pub cells: [usize; 3],
    /// Nodes, members and DOFs (every DOF free: nothing holds the body).
    pub sizes: [usize; 3],
    /// The linear solver the body got.
    pub solver: String,
    /// Building the world and the solvers, s.
    pub setup_seconds: Real,
    /// Per time step.
    pub steps: Vec<TimeStepTiming>,
    /// Time per phase over the time steps, s (assembly: internal forces, residuals and the
    /// tangent; symbolic: pattern analyses; numeric: factorizations; solve: substitutions).
    pub phases: PhaseTimes,
    /// Finding contacts (projecting nodes on the floor), s.
    pub query_seconds: Real,
    /// Peak resident memory of the process, bytes.
    pub peak_memory: u64,
}

impl DynamicsTiming {
    /// Wall time of all time steps, s.
    pub fn total_seconds(&self) -> Real {
        self.steps.iter().map(|s| s.seconds).sum()
    }

    /// Mean wall time of a time step, s.
    pub fn seconds_per_step(&self) -> Real {
        self.total_seconds() / self.steps.len().max(1) as Real
    }
}

/// Build and run the scene of [`scene`], timing each time step.
pub fn measure_dynamics(cells: [usize; 3], steps: usize) -> Result<DynamicsTiming, String> {
    let t = Instant::now();
    let world = build_world(&scene(cells, steps), Path::new("dropped_lattice.toml"))
        .map_err(|e| e.to_string())?;
    let mut sim = DynamicSimulation::new(&world).map_err(|e| e.to_string())?;
    let size = &sim.sizes()[0];
    let (sizes, solver) = (
        [size.nodes, size.members, world.bodies[0].dof_count()],
        size.solver.clone(),
    );
    let (phases_before, query_before) = (sim.times(), sim.query_seconds());
    sim.step(0).map_err(|e| e.to_string())?;
    let setup_seconds = t.elapsed().as_secs_f64();
    let mut timings = Vec::with_capacity(steps);
    for frame in 1..=steps {
        let t = Instant::now();
        let (result, summary) = sim.step(frame).map_err(|e| e.to_string())?;
        let seconds = t.elapsed().as_secs_f64();
        let energy = summary.dynamics.as_ref();
        timings.push(TimeStepTiming {
            time: result.time.unwrap_or(0.0),
            iterations: [summary.iterations, summary.contact_iterations, summary.cuts],
            contacts: result.bodies[0].contacts.len(),
            max_penetration: summary.max_penetration,
            total_energy: energy.map_or(0.0, |e| e.total_energy),
            seconds,
        });
    }
    let after = sim.times();
    let phases = PhaseTimes {
        assembly: after.assembly - phases_before.assembly,
        symbolic: after.symbolic - phases_before.symbolic,
        numeric: after.numeric - phases_before.numeric,
        solve: after.solve - phases_before.solve,
    };
    Ok(DynamicsTiming {
        cells,
        sizes,
        solver,
        setup_seconds,
        steps: timings,
        phases,
        query_seconds: sim.query_seconds() - query_before,
        peak_memory: peak_memory(),
    })
}

/// One line per time step.
pub fn format_step(k: usize, s: &TimeStepTiming) -> String {
    let [newton, contact, cuts] = s.iterations;
    format!(
        "step {k:>3} (t = {:.2} ms): {newton:>2} Newton, {contact:>2} contact iterations, {cuts} halvings; {:>5} contacts, max penetration {:.2e} m, energy balance {:+.4e} J; {:.3} s",
        s.time * 1e3,
        s.contacts,
        s.max_penetration,
        s.total_energy,
        s.seconds
    )
}

/// The model, the time per step and the phases.
pub fn format_summary(t: &DynamicsTiming) -> String {
    let n = t.steps.len().max(1) as Real;
    let newton: usize = t.steps.iter().map(|s| s.iterations[0]).sum();
    let contact: usize = t.steps.iter().map(|s| s.iterations[1]).sum();
    let in_contact = t.steps.iter().filter(|s| s.contacts > 0).count();
    let per = |x: Real| x / n * 1e3;
    format!(
        "{}x{}x{} cells: {} nodes, {} members, {} DOFs, solver {}; set-up {:.2} s; {} time steps ({} in contact): {:.1} ms per time step, {:.2} steps per second; Newton iterations per step {:.2}, contact iterations per step {:.2}\n\
         phases per time step: contact detection {:.1} ms, assembly {:.1} ms, analysis {:.1} ms, factorization {:.1} ms, solves {:.1} ms, other {:.1} ms; peak memory {:.0} MB",
        t.cells[0],
        t.cells[1],
        t.cells[2],
        t.sizes[0],
        t.sizes[1],
        t.sizes[2],
        t.solver,
        t.setup_seconds,
        t.steps.len(),
        in_contact,
        t.seconds_per_step() * 1e3,
        1.0 / t.seconds_per_step().max(1e-12),
        newton as Real / n,
        contact as Real / n,
        per(t.query_seconds),
        per(t.phases.assembly),
        per(t.phases.symbolic),
        per(t.phases.numeric),
        per(t.phases.solve),
        per(t.total_seconds()
            - t.query_seconds
            - t.phases.assembly
            - t.phases.symbolic
            - t.phases.numeric
            - t.phases.solve),
        t.peak_memory as f64 / 1e6
    )
}
