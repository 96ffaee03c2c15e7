//! What a run writes, handed its results in memory: each step file as the step is solved, then
//! `model.json`, VTK files and pictures into the staging folder before it is published.

use crate::scene::atomic_file::write_atomically;
use crate::scene::model_file::ModelFile;
use crate::scene::results::{PhaseSeconds, StepResult};
use crate::scene::run_error::RunError;
use crate::scene::run_results::{step_digits, step_stem, RunResults};
use crate::scene::vtk::write_vtk;
use crate::scene::World;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Draws pictures of a run's results. `scene` does not draw; `render` implements this
/// (`linkage::render::PictureWriter`) and the caller of [`crate::scene::run_with`] passes it in.
pub trait DrawResults: Sync {
    /// Draw the pictures `world.pictures` asks for of `run` into the results folder `dir`,
    /// writing each file atomically. The error's message is a complete sentence naming the file.
    fn draw(
        &self,
        world: &World,
        run: &RunResults,
        dir: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>>;
}

/// Whether the writers after the load steps (VTK files, pictures by `draw`) need the stored
/// steps kept in memory.
pub(crate) fn keeps_steps(world: &World, draw: Option<&dyn DrawResults>) -> bool {
    world.pictures.vtk || (draw.is_some() && (world.pictures.png || world.pictures.gif))
}

/// Write `value` as JSON to `path` (atomically; `pretty`: indented); returns the bytes.
pub(crate) fn write_json(
    path: &Path,
    value: &impl Serialize,
    pretty: bool,
) -> Result<Vec<u8>, RunError> {
    let bytes = if pretty {
        serde_json::to_vec_pretty(value)
    } else {
        serde_json::to_vec(value)
    }
    .map_err(|e| RunError::Write {
        path: path.to_path_buf(),
        source: e.into(),
    })?;
    write_atomically(path, &bytes).map_err(|source| RunError::Write {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(bytes)
}

/// What a reader of the file `path` holding `bytes` (just written) gets. serde_json's default
/// float parsing is not always correctly rounded (`0.12499999999999999` reads as `0.125`), so
/// the writers after the loop take the numbers as the files give them, parsed from memory:
/// the numbers `linkage render` reads, so pictures and VTK files do not depend on whether they
/// were made during the run or from the folder afterwards.
fn read_back<T: DeserializeOwned>(path: &Path, bytes: &[u8]) -> Result<T, RunError> {
    serde_json::from_slice(bytes).map_err(|e| RunError::Write {
        path: path.to_path_buf(),
        source: e.into(),
    })
}

/// Write `steps_dir/NNNN.json` of `result` (the step number padded to `digits`, see
/// [`step_digits`]); with `keep`, return the step as the file gives it back (see
/// [`read_back`]) for the writers after the loop.
pub(crate) fn write_step(
    steps_dir: &Path,
    result: &StepResult,
    digits: usize,
    keep: bool,
) -> Result<Option<StepResult>, RunError> {
    let path = steps_dir.join(format!("{}.json", step_stem(result.step, digits)));
    let bytes = write_json(&path, result, false)?;
    keep.then(|| read_back(&path, &bytes)).transpose()
}

/// Write `model.json` of `world`, then VTK files and pictures as `world.pictures` asks, into
/// `dir`, from the stored `steps` (kept when [`keeps_steps`] says they are needed).
pub(crate) fn write_after_steps(
    world: &World,
    steps: Vec<StepResult>,
    dir: &Path,
    draw: Option<&dyn DrawResults>,
    phases: &mut PhaseSeconds,
) -> Result<(), RunError> {
    let t = Instant::now();
    let path = dir.join("model.json");
    let bytes = write_json(&path, &ModelFile::new(world), false)?;
    let drawing = draw.filter(|_| world.pictures.png || world.pictures.gif);
    if !world.pictures.vtk && drawing.is_none() {
        phases.writing += t.elapsed().as_secs_f64();
        return Ok(());
    }
    let run = RunResults {
        model: read_back(&path, &bytes)?,
        steps,
        digits: step_digits(world.steps),
    };
    if world.pictures.vtk {
        write_vtk(&run, dir, world.pictures.vtk_encoding).map_err(|e| RunError::Draw {
            path: dir.join("vtk"),
            source: Box::new(e),
        })?;
    }
    phases.writing += t.elapsed().as_secs_f64();
    if let Some(draw) = drawing {
        let t = Instant::now();
        draw.draw(world, &run, dir)
            .map_err(|source| RunError::Draw {
                path: dir.to_path_buf(),
                source,
            })?;
        phases.drawing += t.elapsed().as_secs_f64();
    }
    Ok(())
}
