//! One job of a batch: skipped when its complete results are there, else built and run; either
//! way its row of the table, read from the published folder.

use crate::scene::batch::jobs::Job;
use crate::scene::batch::row::{complete_summary, job_row};
use crate::scene::batch::table::Row;
use crate::scene::{build_world, run_into, DrawResults, RunError, Summary, World};
use std::path::Path;
use std::sync::atomic::AtomicBool;

/// What running a job did.
#[derive(Debug)]
pub enum Ran {
    /// Its complete results were there already (not asked to `rerun`).
    Skipped,
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
/// `on_step`, `draw` and `stop` are [`run_into`]'s.
pub fn run_job(
    job: &Job,
    out: &Path,
    settings: JobSettings,
    draw: Option<&dyn DrawResults>,
    on_start: &(dyn Fn(&World) + Sync),
    on_step: &(dyn Fn() + Sync),
    stop: &AtomicBool,
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
    let started = std::time::Instant::now();
    let built = build_world(text, &job.scene).map_err(|e| {
        let message = e.to_string();
        job.describe_error(&message)
    });
    let mut world = match built {
        Ok(world) => world,
        Err(why) => {
            return (
                Ran::Failed(why.clone()),
                job_row(job, format!("failed: {why}"), None, None),
            )
        }
    };
    if !settings.rerun && complete_summary(&folder, &world).is_some() {
        let row = job_row(job, "ok".into(), Some(&folder), Some(&world));
        return (Ran::Skipped, row);
    }
    if settings.png {
        world.pictures.ask_png();
    }
    if settings.no_gif {
        world.pictures.gif = false;
    }
    world.pictures.vtk |= settings.vtk;
    on_start(&world);
    let parent = job.parent(out);
    if let Err(e) = std::fs::create_dir_all(&parent) {
        let why = format!("cannot create {}: {e}", parent.display());
        return (
            Ran::Failed(why.clone()),
            job_row(job, format!("failed: {why}"), None, None),
        );
    }
    match run_into(&world, &parent, &job.folder_name(), on_step, draw, stop) {
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
