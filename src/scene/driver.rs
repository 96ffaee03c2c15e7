//! The load-step driver: step a [`Simulation`] through a world's load steps and hand each
//! result to the writers, in a staging folder published when complete.

use crate::contact::ContactError;
use crate::linkage::SolveError;
use crate::scene::results::{PhaseSeconds, Summary};
use crate::scene::run_error::RunError;
use crate::scene::simulation::Simulation;
use crate::scene::writers::{keeps_steps, write_after_steps, write_json, write_step, DrawResults};
use crate::scene::World;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// Run `world` and write `out/<name>/` (summary.json and steps/NNNN.json). The folder is
/// built under a temporary name and renamed when complete, so an interrupted or failed run
/// leaves no partial results (and an earlier complete run stays until replaced).
/// `on_step` is called after each solved step (for progress bars). Also writes `model.json`
/// and the VTK files `world.pictures` asks for; pictures need [`run_with`].
pub fn run(world: &World, out: &Path, on_step: &(dyn Fn() + Sync)) -> Result<Summary, RunError> {
    run_with(world, out, on_step, None)
}

/// [`run`], and the pictures `world.pictures` asks for, drawn by `draw` from the complete
/// results in memory before the folder is published (time in `phases.drawing`).
pub fn run_with(
    world: &World,
    out: &Path,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    let final_dir = out.join(&world.name);
    // Unique per run, so two runs of one name in a batch never share a staging folder.
    static RUNS: AtomicUsize = AtomicUsize::new(0);
    let staging = out.join(format!(
        ".{}.partial-{}-{}",
        world.name,
        std::process::id(),
        RUNS.fetch_add(1, Ordering::Relaxed)
    ));
    let result = run_in(world, &staging, &final_dir, on_step, draw);
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    result
}

/// The run of [`run_with`], written into `staging` and moved to `final_dir` when complete.
fn run_in(
    world: &World,
    staging: &Path,
    final_dir: &Path,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    let write_err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| RunError::Write { path, source }
    };
    let started = Instant::now();
    let mut simulation = Simulation::new(world)?;
    let setup = started.elapsed().as_secs_f64();
    if staging.exists() {
        std::fs::remove_dir_all(staging).map_err(write_err(staging))?;
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
    // The stored steps stay in memory only for the writers after the loop that need them.
    let keep = keeps_steps(world, draw);
    let mut kept = Vec::new();
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
            kept.extend(write_step(&steps_dir, &result, keep)?);
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
    write_after_steps(world, kept, staging, draw, &mut summary.phases)?;
    write_json(&staging.join("summary.json"), &summary, true)?;
    replace_dir(staging, final_dir).map_err(write_err(final_dir))?;
    match stopped {
        Some(e) => Err(e),
        None => Ok(summary),
    }
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
