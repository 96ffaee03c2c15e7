//! The load-step driver: solve every body at every step and write the results.

use crate::atomic_file::write_atomically;
use crate::contact::{ContactError, ContactSolver, NodeContact};
use crate::linkage::{Body, BodySolver, PhaseTimes, SolveError};
use crate::scene::extra_outputs::{write_extra_outputs, DrawResults};
use crate::scene::results::{
    BodyResult, BodySize, ContactForce, PairForce, PhaseSeconds, StepResult, StepSummary, Summary,
};
use crate::scene::World;
use crate::Real;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// A world ready to step: each body's stiffness assembled and factored once.
pub struct Simulation<'w> {
    /// The scene being run.
    pub world: &'w World,
    /// One solver per body, in scene order: linear superposition, or Newton for a nonlinear body
    /// (empty in a scene with contact).
    pub equilibria: Vec<BodySolver>,
    /// All bodies solved together with their contacts, in a scene with obstacles or `[contact]`.
    pub contact: Option<Mutex<ContactSolver>>,
}

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A body could not be solved.
    #[error("{scene}: {source}")]
    Solve {
        /// Scene file.
        scene: PathBuf,
        /// What went wrong.
        source: SolveError,
    },
    /// The bodies in contact could not be solved.
    #[error("{scene}: {source}")]
    Contact {
        /// Scene file.
        scene: PathBuf,
        /// What went wrong.
        source: ContactError,
    },
    /// A result file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// File or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Pictures or VTK files could not be made.
    #[error("{path}: {message}")]
    Draw {
        /// Results folder or file.
        path: PathBuf,
        /// What went wrong and what to do.
        message: String,
    },
}

impl<'w> Simulation<'w> {
    /// Assemble and factor every body of `world`.
    pub fn new(world: &'w World) -> Result<Self, RunError> {
        if world.has_contact() {
            let solver = ContactSolver::new(&world.bodies, &world.obstacles, world.contact)
                .map_err(|source| RunError::Contact {
                    scene: world.source.clone(),
                    source,
                })?;
            return Ok(Simulation {
                world,
                equilibria: Vec::new(),
                contact: Some(Mutex::new(solver)),
            });
        }
        let equilibria = world
            .bodies
            .iter()
            .map(BodySolver::new)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|source| RunError::Solve {
                scene: world.source.clone(),
                source,
            })?;
        Ok(Simulation {
            world,
            equilibria,
            contact: None,
        })
    }

    /// The result of `step` (0..=steps) and its summary line (without the time).
    pub fn step(&self, step: usize) -> Result<(StepResult, StepSummary), RunError> {
        let world = self.world;
        let mut result = StepResult {
            step,
            load_factor: world.load_factor(step),
            bodies: Vec::with_capacity(world.bodies.len()),
        };
        let mut summary = StepSummary {
            step,
            load_factor: result.load_factor,
            iterations: 0,
            cuts: 0,
            negative_pivots: 0,
            residuals: Vec::new(),
            contact_iterations: 0,
            linear_iterations: 0,
            residual: 0.0,
            max_displacement: 0.0,
            overloaded: 0,
            max_penetration: 0.0,
            seconds: 0.0,
            warnings: Vec::new(),
            contact_forces: Vec::new(),
        };
        if let Some(contact) = &self.contact {
            let solved = contact
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .solve_step(&world.bodies, &world.obstacles, step, world.steps)
                .map_err(|source| RunError::Contact {
                    scene: world.source.clone(),
                    source,
                })?;
            summary.iterations = solved.newton_iterations;
            summary.contact_iterations = solved.contact_iterations;
            summary.max_penetration = solved.max_penetration;
            summary.warnings = solved.warnings;
            for (body, totals) in world.bodies.iter().zip(&solved.totals) {
                let d = body.dimension.dofs_per_node();
                for (with, force) in totals {
                    summary.contact_forces.push(PairForce {
                        body: body.name.clone(),
                        with: with.clone(),
                        force: force.as_slice()[..d].to_vec(),
                    });
                }
            }
            for ((body, state), contacts) in world
                .bodies
                .iter()
                .zip(&solved.states)
                .zip(&solved.contacts)
            {
                summary.residual = summary.residual.max(state.residual);
                summary.overloaded += state.overloaded.len();
                summary.max_displacement = state
                    .displacements
                    .iter()
                    .map(|u| u.norm())
                    .fold(summary.max_displacement, Real::max);
                let mut written = BodyResult::new(body, state);
                written.contacts = contact_forces(body, contacts);
                result.bodies.push(written);
            }
            return Ok((result, summary));
        }
        for (body, eq) in world.bodies.iter().zip(&self.equilibria) {
            let state =
                eq.solve_step(body, step, world.steps)
                    .map_err(|source| RunError::Solve {
                        scene: world.source.clone(),
                        source,
                    })?;
            summary.residual = summary.residual.max(state.residual);
            if state.iterations > summary.iterations {
                summary.residuals = state.residual_history.clone();
            }
            summary.iterations = summary.iterations.max(state.iterations);
            summary.cuts += state.cuts;
            summary.linear_iterations += state.linear_iterations;
            summary.negative_pivots += state.negative_pivots;
            if let Some(lambda) = state.load_factor {
                // The path (arc length) decided this body's load factor.
                result.load_factor = lambda;
                summary.load_factor = lambda;
            }
            summary.overloaded += state.overloaded.len();
            summary.max_displacement = state
                .displacements
                .iter()
                .map(|u| u.norm())
                .fold(summary.max_displacement, Real::max);
            result.bodies.push(BodyResult::new(body, &state));
        }
        Ok((result, summary))
    }

    /// Model sizes for the summary.
    pub fn sizes(&self) -> Vec<BodySize> {
        let contact = self
            .contact
            .as_ref()
            .map(|c| c.lock().unwrap_or_else(|poisoned| poisoned.into_inner()));
        self.world
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| BodySize {
                name: b.name.clone(),
                dimension: b.dimension.dofs_per_node(),
                nodes: b.nodes.len(),
                members: b.members.len(),
                patches: b.patches.len(),
                free_dofs: match (&contact, self.equilibria.get(i)) {
                    (Some(c), _) => c.free_dofs(i),
                    (None, Some(eq)) => eq.free_dofs(),
                    (None, None) => 0,
                },
                solver: match (&contact, self.equilibria.get(i)) {
                    (Some(_), _) => "direct".to_string(),
                    (None, Some(eq)) => eq.solver_used().to_string(),
                    (None, None) => String::new(),
                },
            })
            .collect()
    }

    /// Time spent so far in each phase, s, summed over the bodies, and in contact queries.
    fn times(&self) -> (PhaseTimes, Real) {
        if let Some(c) = &self.contact {
            let c = c.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            return (c.times, c.query_seconds);
        }
        let mut sum = PhaseTimes::default();
        for eq in &self.equilibria {
            let t = eq.times();
            sum.assembly += t.assembly;
            sum.symbolic += t.symbolic;
            sum.numeric += t.numeric;
            sum.solve += t.solve;
        }
        (sum, 0.0)
    }
}

/// Run `world` and write `out/<name>/` (summary.json and steps/NNNN.json). The folder is
/// built under a temporary name and renamed when complete, so an interrupted or failed run
/// leaves no partial results (and an earlier complete run stays until replaced).
/// `on_step` is called after each solved step (for progress bars). Also writes `model.json`
/// and the VTK files `world.pictures` asks for; pictures need [`run_with`].
pub fn run(world: &World, out: &Path, on_step: &(dyn Fn() + Sync)) -> Result<Summary, RunError> {
    run_with(world, out, on_step, None)
}

/// [`run`], and the pictures `world.pictures` asks for, drawn by `draw` from the complete
/// results in the folder before it is published (time in `phases.drawing`).
pub fn run_with(
    world: &World,
    out: &Path,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    let write_err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| RunError::Write { path, source }
    };
    let final_dir = out.join(&world.name);
    // Unique per run, so two runs of one name in a batch never share a staging folder.
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let staging = out.join(format!(
        ".{}.partial-{}-{}",
        world.name,
        std::process::id(),
        RUNS.fetch_add(1, Ordering::Relaxed)
    ));
    let result = (|| {
        let started = Instant::now();
        let simulation = Simulation::new(world)?;
        let setup = started.elapsed().as_secs_f64();
        if staging.exists() {
            std::fs::remove_dir_all(&staging).map_err(write_err(&staging))?;
        }
        let steps_dir = staging.join("steps");
        std::fs::create_dir_all(&steps_dir).map_err(write_err(&steps_dir))?;
        let mut summary = Summary {
            scene: world.name.clone(),
            steps: Vec::with_capacity(world.steps + 1),
            bodies: simulation.sizes(),
            phases: PhaseSeconds::default(),
            failure: None,
        };
        let mut stopped = None;
        for step in 0..=world.steps {
            let t = Instant::now();
            let (result, mut line) = match simulation.step(step) {
                Ok(solved) => solved,
                // A nonlinear step that cannot be solved ends the run, but the steps before it
                // are kept and the summary says why it stopped.
                Err(RunError::Solve {
                    scene,
                    source: source @ SolveError::NotConverged { .. },
                }) => {
                    summary.failure = Some(source.to_string());
                    stopped = Some(RunError::Solve { scene, source });
                    break;
                }
                Err(RunError::Contact {
                    scene,
                    source: source @ ContactError::NotConverged { .. },
                }) => {
                    summary.failure = Some(source.to_string());
                    stopped = Some(RunError::Contact { scene, source });
                    break;
                }
                Err(e) => return Err(e),
            };
            line.seconds = t.elapsed().as_secs_f64() + if step == 1 { setup } else { 0.0 };
            if world.output.writes(step, world.steps) {
                let t = Instant::now();
                let path = steps_dir.join(format!("{step:04}.json"));
                let bytes = serde_json::to_vec(&result).map_err(|e| RunError::Write {
                    path: path.clone(),
                    source: e.into(),
                })?;
                write_atomically(&path, &bytes).map_err(write_err(&path))?;
                summary.phases.writing += t.elapsed().as_secs_f64();
            }
            summary.steps.push(line);
            on_step();
        }
        let (times, query) = simulation.times();
        summary.phases.assembly += times.assembly;
        summary.phases.symbolic += times.symbolic;
        summary.phases.numeric += times.numeric;
        summary.phases.solve += times.solve;
        summary.phases.contact_query += query;
        write_extra_outputs(world, &staging, draw, &mut summary.phases)?;
        let path = staging.join("summary.json");
        let bytes = serde_json::to_vec_pretty(&summary).map_err(|e| RunError::Write {
            path: path.clone(),
            source: e.into(),
        })?;
        write_atomically(&path, &bytes).map_err(write_err(&path))?;
        replace_dir(&staging, &final_dir).map_err(write_err(&final_dir))?;
        match stopped {
            Some(e) => Err(e),
            None => Ok(summary),
        }
    })();
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    result
}

/// The written form of a body's contacts: 1-based nodes, one force component per dimension.
fn contact_forces(body: &Body, contacts: &[NodeContact]) -> Vec<ContactForce> {
    let d = body.dimension.dofs_per_node();
    contacts
        .iter()
        .map(|c| ContactForce {
            node: c.node + 1,
            with: c.with.clone(),
            depth: c.depth,
            force: c.force.as_slice()[..d].to_vec(),
        })
        .collect()
}

/// Put the complete folder `from` at `to`, replacing an earlier one.
fn replace_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    if to.exists() {
        let old = to.with_file_name(format!(
            ".{}.old-{}",
            to.file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default(),
            std::process::id()
        ));
        std::fs::rename(to, &old)?;
        std::fs::rename(from, to)?;
        std::fs::remove_dir_all(&old)
    } else {
        std::fs::rename(from, to)
    }
}
