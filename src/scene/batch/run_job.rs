//! One job of a batch: skipped when its complete results are there, else built and run; either
//! way its row of the table, read from the published folder.

use crate::linkage::Interrupt;
use crate::scene::batch::jobs::Job;
use crate::scene::batch::row::{complete_summary, job_row};
use crate::scene::batch::table::Row;
use crate::scene::{
    build_world_until, run_into, write_vtk, DrawResults, RunError, RunResults, Summary, World,
};
use std::path::Path;

/// What running a job did.
#[derive(Debug)]
pub enum Ran {
    /// Its complete results were there already (not asked to `rerun`).
    Skipped,
    /// Its complete results were there already, and the pictures or VTK files asked for
    /// (`--png`, `--vtk`) were drawn from them without solving.
    Drawn {
        /// The world whose results were drawn.
        world: Box<World>,
    },
    /// It ran and every step was solved.
    Solved {
        /// The world it ran.
        world: Box<World>,
        /// Its summary (boxed: it is large beside the other variants).
        summary: Box<Summary>,
        /// Wall time of building and running it, s.
        seconds: f64,
    },
    /// It could not be built or run: why (naming the scene file, and the variant of a sweep).
    Failed(String),
}

/// How a batch runs its jobs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct JobSettings {
    /// Draw PNG frames and `anim.gif` (as `[output] png = true`).
    pub png: bool,
    /// Write no `anim.gif`, whatever the scene or `png` asks (the CLI's `--no-gif`).
    pub no_gif: bool,
    /// Write the ParaView files.
    pub vtk: bool,
    /// Run jobs whose complete results are already there.
    pub rerun: bool,
}

/// Run `job` into `out` (unless its complete results are there and `settings.rerun` is off) and
/// make its row. `on_start` sees the world before it runs (for progress and warnings);
/// `on_step` and `draw` are [`run_into`]'s; `stop` becomes the world's interrupt
/// ([`World::set_interrupt`]): once raised the job stops where it is and fails as interrupted.
pub fn run_job(
    job: &Job,
    out: &Path,
    settings: JobSettings,
    draw: Option<&dyn DrawResults>,
    on_start: &(dyn Fn(&World) + Sync),
    on_step: &(dyn Fn() + Sync),
    stop: Interrupt,
) -> (Ran, Row) {
    let folder = job.folder(out);
    let text = match &job.text {
        Ok(text) => text,
        Err(why) => {
            return (
                Ran::Failed(why.clone()),
                job_row(job, format!("failed: {why}"), None, None),
            )
        }
    };
    // Asked to stop before this job began (the jobs of a batch start one after another).
    if stop.is_raised() {
        let why = RunError::Interrupted {
            scene: job.scene.clone(),
            step: 0,
        }
        .to_string();
        return (
            Ran::Failed(why.clone()),
            job_row(job, format!("failed: {why}"), None, None),
        );
    }
    let started = std::time::Instant::now();
    let built = build_world_until(text, &job.scene, stop).map_err(|e| {
        let message = e.to_string();
        job.describe_error(&message)
    });
    let mut world = match built {
        // Asked to stop while the world was built (meshes prepared): it does not run, and a
        // preparation cut short is no error of the scene.
        _ if stop.is_raised() => {
            let why = RunError::Interrupted {
                scene: job.scene.clone(),
                step: 0,
            }
            .to_string();
            return (
                Ran::Failed(why.clone()),
                job_row(job, format!("failed: {why}"), None, None),
            );
        }
        Ok(world) => world,
        Err(why) => {
            return (
                Ran::Failed(why.clone()),
                job_row(job, format!("failed: {why}"), None, None),
            )
        }
    };
    if settings.png {
        world.pictures.ask_png();
    }
    if settings.no_gif {
        world.pictures.gif = false;
    }
    world.pictures.vtk |= settings.vtk;
    world.set_interrupt(stop);
    if let Some(summary) = (!settings.rerun)
        .then(|| complete_summary(&folder, &world))
        .flatten()
    {
        let row = |status| job_row(job, status, Some(&folder), Some(&world));
        if !settings.png && !settings.vtk {
            return (Ran::Skipped, row("ok".into()));
        }
        // Asked for pictures: drawn from the stored results, not solved again.
        return match draw_stored(&world, &summary, &folder, draw) {
            Ok(()) => {
                let row = row("ok".into());
                (
                    Ran::Drawn {
                        world: Box::new(world),
                    },
                    row,
                )
            }
            Err(why) => (Ran::Failed(why.clone()), row(format!("failed: {why}"))),
        };
    }
    let parent = job.parent(out);
    if let Err(e) = std::fs::create_dir_all(&parent) {
        let why = format!("cannot create {}: {e}", parent.display());
        return (
            Ran::Failed(why.clone()),
            job_row(job, format!("failed: {why}"), None, None),
        );
    }
    // Refused before anything of the run is allocated.
    let keeps = crate::scene::writers::keeps_steps(&world, draw);
    if let Some(why) = crate::scene::fits_machine::refusal(&world, &parent, keeps) {
        let why = format!("{}: {why}", job.scene.display());
        return (
            Ran::Failed(why.clone()),
            job_row(job, format!("failed: {why}"), None, None),
        );
    }
    on_start(&world);
    match run_into(&world, &parent, &job.folder_name(), on_step, draw) {
        Ok(summary) => {
            let row = job_row(job, "ok".into(), Some(&folder), Some(&world));
            let seconds = started.elapsed().as_secs_f64();
            (
                Ran::Solved {
                    world: Box::new(world),
                    summary: Box::new(summary),
                    seconds,
                },
                row,
            )
        }
        Err(e) => {
            let results = match &e {
                RunError::Stopped { results, .. } => Some(results.clone()),
                _ => None,
            };
            let why = e.to_string();
            let row = job_row(
                job,
                format!("failed: {why}"),
                results.as_deref(),
                Some(&world),
            );
            (Ran::Failed(why), row)
        }
    }
}

/// Draw what `world.pictures` asks for (VTK files; PNG frames, the GIF and plots by `draw`)
/// from the complete results in `folder` (their `summary`), each folder and file replaced
/// atomically. The error names the folder.
fn draw_stored(
    world: &World,
    summary: &Summary,
    folder: &Path,
    draw: Option<&dyn DrawResults>,
) -> Result<(), String> {
    let run = RunResults::read(folder).map_err(|e| e.to_string())?;
    if world.pictures.vtk {
        write_vtk(&run, folder, world.pictures.vtk_encoding, world.interrupt())
            .map_err(|e| e.to_string())?;
    }
    if let Some(draw) = draw.filter(|_| world.pictures.png || world.pictures.gif) {
        // An interrupted drawing says so itself (and keeps the pictures as they were).
        let failed = |e: Box<dyn std::error::Error + Send + Sync>| e.to_string();
        draw.draw(world, &run, folder).map_err(failed)?;
        draw.plot(world, &run, summary, folder).map_err(failed)?;
    }
    Ok(())
}
