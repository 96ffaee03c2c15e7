//! The load-step driver: step a [`Simulation`] through a world's load steps and hand each
//! result to the writers, in a staging folder published when complete.

use crate::scene::check::output_warning;
use crate::scene::peak_stress::peak_stress;
use crate::scene::publish::{destination, publish, remove_stale, staging_dir};
use crate::scene::results::{PhaseSeconds, StepResult, Summary, SummaryBreak};
use crate::scene::run_error::RunError;
use crate::scene::run_results::step_digits;
use crate::scene::step_writer::StepWriter;
use crate::scene::stepper::Stepper;
use crate::scene::writers::{keeps_steps, write_after_steps, write_json, write_model, DrawResults};
use crate::scene::World;
use std::path::Path;
use std::time::Instant;

/// Run `world` and write `out/<name>/` (summary.json and steps/NNNN.json). The folder is
/// built under a staging name and put in place when complete (see [`crate::scene::publish`]):
/// an interrupted run leaves nothing, a run whose step after step 0 cannot be solved keeps step
/// 0 and the steps solved before it (beside earlier complete results, never over them), and
/// files a user keeps in the folder survive a re-run. `on_step` is called after each solved
/// step (for progress bars). Also writes `model.json` and the VTK files `world.pictures` asks
/// for; pictures need [`run_with`].
pub fn run(world: &World, out: &Path, on_step: &(dyn Fn() + Sync)) -> Result<Summary, RunError> {
    run_with(world, out, on_step, None)
}

/// [`run`], and the pictures `world.pictures` asks for, drawn by `draw` from the complete
/// results in memory before the folder is published (time in `phases.drawing`).
///
/// Once the world's interrupt is raised ([`World::set_interrupt`]: the CLI raises it on SIGINT
/// and SIGTERM) the run stops where it is (between Newton or contact iterations, fracture
/// events, steps, frames and writers), removes its staging folder, leaves earlier results as
/// they were and returns [`RunError::Interrupted`].
pub fn run_with(
    world: &World,
    out: &Path,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    run_into(world, out, &world.name, on_step, draw)
}

/// [`run_with`], writing `out/<folder>/` instead of `out/<name>/` (a sweep's variant `k` of
/// scene `s` is `DIR/s/k/`, its summary still naming the scene `s`).
pub fn run_into(
    world: &World,
    out: &Path,
    folder: &str,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    let final_dir = out.join(folder);
    remove_stale(out, folder);
    let staging = staging_dir(out, folder);
    let result = run_in(world, &staging, &final_dir, on_step, draw);
    if staging.exists() {
        let _ = std::fs::remove_dir_all(&staging);
    }
    result
}

/// The run of [`run_with`], written into `staging` and published when complete or stopped.
fn run_in(
    world: &World,
    staging: &Path,
    final_dir: &Path,
    on_step: &(dyn Fn() + Sync),
    draw: Option<&dyn DrawResults>,
) -> Result<Summary, RunError> {
    let stop = world.interrupt();
    // Whatever a step or a writer returns once the stop is asked for (an interrupted Newton, a
    // drawing cut short), the run was interrupted.
    let interrupted = |step: usize| RunError::Interrupted {
        scene: world.source.clone(),
        step,
    };
    let write_err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| RunError::Write { path, source }
    };
    if staging.exists() {
        std::fs::remove_dir_all(staging).map_err(write_err(staging))?;
    }
    let steps_dir = staging.join("steps");
    std::fs::create_dir_all(&steps_dir).map_err(write_err(&steps_dir))?;
    // The model file depends on nothing solved: it is written while the steps are solved and
    // written, which on a million-member body takes half a second off the run's wall time.
    std::thread::scope(|scope| {
        let started = Instant::now();
        let mut simulation =
            Stepper::new(world).map_err(|e| if stop.is_raised() { interrupted(0) } else { e })?;
        let setup = started.elapsed().as_secs_f64();
        // Not before the set-up: that is where the run's memory peaks.
        let model_file = scope.spawn(|| write_model(world, staging));
        let mut summary = start_summary(world, &simulation);
        // The stored steps stay in memory only for the writers after the loop that need them.
        let keep = keeps_steps(world, draw);
        // Every file name of the run has enough digits for its last step, so they sort.
        let digits = step_digits(world.steps);
        let writer = StepWriter::start(scope, world, &steps_dir, digits, keep);
        let stepped = solve_steps(
            &mut simulation,
            &mut summary,
            setup,
            on_step,
            &mut |result| writer.write(result),
        );
        let finished = writer.finish();
        let stopped = stepped?;
        let (kept, writing) = finished?;
        let last = summary.steps.len().saturating_sub(1);
        if stop.is_raised() {
            return Err(interrupted(last));
        }
        summary.phases.writing += writing;
        add_solver_times(&mut summary, &simulation);
        let (model, model_seconds) = model_file
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
        summary.phases.writing += model_seconds;
        write_after_steps(world, model, kept, staging, draw, &mut summary).map_err(|e| {
            if stop.is_raised() {
                interrupted(last)
            } else {
                e
            }
        })?;
        write_json(&staging.join("summary.json"), &summary, true)?;
        // Asked to stop while drawing or writing: nothing is published.
        if stop.is_raised() {
            return Err(interrupted(last));
        }
        let target = destination(final_dir, stopped.is_none());
        publish(staging, &target).map_err(write_err(&target))?;
        match stopped {
            Some(e) => Err(RunError::Stopped {
                results: target,
                source: Box::new(e),
            }),
            None => Ok(summary),
        }
    })
}

/// Solve `world` in memory: the summary and the steps its `[output]` stores (step 0, every
/// k-th, the last), as [`run_with`] would write them, with nothing written. A step after step
/// 0 that cannot be solved ends the run as it does there: the summary's `failure` says why and
/// the error comes back beside the steps solved before it.
pub fn run_in_memory(
    world: &World,
    on_step: &(dyn Fn() + Sync),
) -> Result<(Summary, Vec<StepResult>, Option<RunError>), RunError> {
    let started = Instant::now();
    let stop = world.interrupt();
    let mut simulation = Stepper::new(world).map_err(|e| {
        if stop.is_raised() {
            RunError::Interrupted {
                scene: world.source.clone(),
                step: 0,
            }
        } else {
            e
        }
    })?;
    let setup = started.elapsed().as_secs_f64();
    let mut summary = start_summary(world, &simulation);
    let mut steps = Vec::new();
    let stopped = solve_steps(
        &mut simulation,
        &mut summary,
        setup,
        on_step,
        &mut |result| {
            steps.push(result);
            true
        },
    )?;
    add_solver_times(&mut summary, &simulation);
    Ok((summary, steps, stopped))
}

/// The summary of a run about to be solved with `simulation`: no steps yet.
fn start_summary(world: &World, simulation: &Stepper) -> Summary {
    Summary {
        scene: world.name.clone(),
        steps: Vec::with_capacity(world.steps + 1),
        bodies: simulation.sizes(),
        phases: PhaseSeconds {
            reading: world.build_seconds,
            ..Default::default()
        },
        failure: None,
        scene_digest: world.scene_digest.clone(),
        prepared: world.prepared.clone(),
        breaks: Vec::new(),
        collapse: None,
    }
}

/// Add the solvers' time (assembly, factorizations, solves, contact queries) to the summary.
fn add_solver_times(summary: &mut Summary, simulation: &Stepper) {
    let (times, query) = simulation.times();
    summary.phases.assembly += times.assembly;
    summary.phases.symbolic += times.symbolic;
    summary.phases.numeric += times.numeric;
    summary.phases.solve += times.solve;
    summary.phases.contact_query += query;
}

/// Solve steps 0..=steps of the simulation's world in order, each one's line into `summary`
/// (`setup` s counted in step 1's time), handing the steps the world's `[output]` writes to
/// `store` (which answers false to stop: its writer failed) and calling `on_step` after each.
/// Stops once the world's interrupt is raised ([`RunError::Interrupted`]). A collapse ends the run
/// as a result; a step after step 0 that cannot be solved ends it with the summary's `failure`
/// set and the error returned as `Ok(Some(..))`; step 0's error is returned as `Err`.
fn solve_steps(
    simulation: &mut Stepper,
    summary: &mut Summary,
    setup: f64,
    on_step: &(dyn Fn() + Sync),
    store: &mut dyn FnMut(StepResult) -> bool,
) -> Result<Option<RunError>, RunError> {
    let world = simulation.world();
    let stop = world.interrupt();
    let interrupted = |step: usize| RunError::Interrupted {
        scene: world.source.clone(),
        step,
    };
    for step in 0..=world.steps {
        if stop.is_raised() {
            return Err(interrupted(step));
        }
        let t = Instant::now();
        let (result, mut line) = match simulation.step(step) {
            Ok(solved) => solved,
            Err(_) if stop.is_raised() => return Err(interrupted(step)),
            // A collapse is a result: the summary records it and the run ends there, published
            // as a complete run.
            Err(RunError::Collapse {
                collapse,
                breaks,
                written,
            }) if step > 0 => {
                summary.breaks.extend(breaks);
                summary.collapse = Some(collapse);
                // The state it collapsed in, when known, is the run's last stored step
                // (whatever the [output] stride: it is where the run ends).
                if let Some(written) = written {
                    let (result, mut line) = *written;
                    line.seconds = t.elapsed().as_secs_f64() + if step == 1 { setup } else { 0.0 };
                    (line.peak_stress, line.stress_ratio) = peak_stress(&result, Some(world));
                    summary.steps.push(line);
                    store(result);
                    on_step();
                }
                break;
            }
            // A step after step 0 that cannot be solved ends the run, but the steps before it
            // are kept and the summary says why it stopped.
            Err(e) if step > 0 => {
                summary.failure = Some(failure_text(&e));
                return Ok(Some(e));
            }
            Err(e) => return Err(e),
        };
        line.seconds = t.elapsed().as_secs_f64() + if step == 1 { setup } else { 0.0 };
        for b in &result.bodies {
            let Some(f) = &b.fracture else { continue };
            summary.breaks.extend(f.breaks.iter().map(|r| SummaryBreak {
                step,
                body: b.name.clone(),
                member: r.member,
                load_factor: r.load_factor,
                tooth: r.tooth,
                time: r.time,
            }));
        }
        if step == 0 {
            line.warnings.extend(world.warnings.iter().cloned());
            line.warnings.extend(output_warning(world));
        }
        (line.peak_stress, line.stress_ratio) = peak_stress(&result, Some(world));
        summary.steps.push(line);
        // A writer stopped by an error: its finish returns the error.
        if world.output.writes(step, world.steps) && !store(result) {
            break;
        }
        on_step();
    }
    Ok(None)
}

/// The summary's `failure`: why the step failed, without the scene file the error names.
fn failure_text(e: &RunError) -> String {
    match e {
        RunError::Solve { source, .. } => source.to_string(),
        RunError::Contact { source, .. } => source.to_string(),
        other => other.to_string(),
    }
}
