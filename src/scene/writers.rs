//! What a run writes, handed its results in memory: each step file (JSON or `.npz`) as the step
//! is solved, then `model.json` (or `model.npz`), VTK files and pictures into the staging folder before it is published.

use crate::scene::atomic_file::write_atomically;
use crate::scene::model_file::ModelFile;
use crate::scene::npz_files::{model_npz, step_npz};
use crate::scene::result_format::ResultFormat;
use crate::scene::results::{StepResult, Summary};
use crate::scene::run_error::RunError;
use crate::scene::run_results::{step_digits, step_stem, RunResults};
use crate::scene::vtk::write_vtk;
use crate::scene::World;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// Draws pictures of a run's results. `scene` does not draw; `render` implements this
/// (`linkage::render::PictureWriter`) and the caller of [`crate::scene::run_with`] passes it in.
pub trait DrawResults: Sync {
    /// Draw the pictures (and the glTF animation) `world.pictures` asks for of `run` into the
    /// results folder `dir`,
    /// writing each file atomically. The error's message is a complete sentence naming the file.
    fn draw(
        &self,
        world: &World,
        run: &RunResults,
        dir: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>>;

    /// Draw the plots of the run's process (`summary`: every solved step; `run`: the stored
    /// ones) into `dir`, after [`DrawResults::draw`]; by default none.
    fn plot(
        &self,
        _world: &World,
        _run: &RunResults,
        _summary: &Summary,
        _dir: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        Ok(())
    }
}

/// Whether the writers after the load steps (VTK files, pictures by `draw`) need the stored
/// steps kept in memory.
pub(crate) fn keeps_steps(world: &World, draw: Option<&dyn DrawResults>) -> bool {
    world.pictures.vtk || (draw.is_some() && draws(world))
}

/// Whether `world` asks [`DrawResults::draw`] for anything: pictures or the glTF animation.
fn draws(world: &World) -> bool {
    world.pictures.png || world.pictures.gif || world.pictures.gltf
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

/// Write `steps_dir/NNNN.json` (or `.npz`, as `world.output.format` says) of `result` (the
/// step number padded to `digits`, see [`step_digits`]); with `keep`, return it for the writers
/// after the loop. Both formats give back exactly the numbers in memory (JSON: shortest
/// round-trip digits, parsed by serde_json with `float_roundtrip`; `.npz`: the bits), so
/// pictures and VTK files are the same whether made during the run or by `linkage render`.
pub(crate) fn write_step(
    world: &World,
    steps_dir: &Path,
    result: StepResult,
    digits: usize,
    keep: bool,
) -> Result<Option<StepResult>, RunError> {
    let format = world.output.format;
    let name = format!("{}.{}", step_stem(result.step, digits), format.extension());
    let path = steps_dir.join(name);
    match format {
        ResultFormat::Json => {
            write_json(&path, &result, false)?;
        }
        ResultFormat::Npz => {
            let dimensions: Vec<usize> = world
                .bodies
                .iter()
                .map(|b| b.dimension.dofs_per_node())
                .collect();
            write_bytes(&path, step_npz(&result, &dimensions))?;
        }
    }
    Ok(keep.then_some(result))
}

/// Write `bytes` (or the error of making them) to `path`, atomically.
fn write_bytes(path: &Path, bytes: std::io::Result<Vec<u8>>) -> Result<(), RunError> {
    let err = |source| RunError::Write {
        path: path.to_path_buf(),
        source,
    };
    write_atomically(path, &bytes.map_err(err)?).map_err(err)
}

/// Write `model.json` (or `model.npz`) of `world` into `dir` and return it with the seconds
/// spent. It depends on nothing solved, so the driver writes it while the steps are solved.
/// The plot settings ([`crate::scene::PLOT_SETTINGS`]) are kept beside it in every run, with
/// pictures or without, so `linkage render DIR` draws the plots the scene asks for.
pub(crate) fn write_model(world: &World, dir: &Path) -> Result<(ModelFile, f64), RunError> {
    let t = Instant::now();
    world.plots.write(dir).map_err(|source| RunError::Write {
        path: dir.join(crate::scene::PLOT_SETTINGS),
        source,
    })?;
    let path = dir.join(world.output.format.model_file());
    let model = ModelFile::new(world);
    match world.output.format {
        ResultFormat::Json => {
            write_json(&path, &model, false)?;
        }
        ResultFormat::Npz => write_bytes(&path, model_npz(&model))?,
    }
    Ok((model, t.elapsed().as_secs_f64()))
}

/// Write the VTK files, pictures and plots `world.pictures` asks for into `dir`, from `model`
/// (written by [`write_model`]), the stored `steps` (kept when [`keeps_steps`] says they are
/// needed) and `summary` (its phases get the time spent).
pub(crate) fn write_after_steps(
    world: &World,
    model: ModelFile,
    steps: Vec<StepResult>,
    dir: &Path,
    draw: Option<&dyn DrawResults>,
    summary: &mut Summary,
) -> Result<(), RunError> {
    let phases = &mut summary.phases;
    let t = Instant::now();
    let drawing = draw.filter(|_| draws(world));
    if !world.pictures.vtk && drawing.is_none() {
        phases.writing += t.elapsed().as_secs_f64();
        return Ok(());
    }
    let run = RunResults {
        model,
        steps,
        digits: step_digits(world.steps),
    };
    if world.pictures.vtk {
        write_vtk(&run, dir, world.pictures.vtk_encoding, world.interrupt()).map_err(|e| {
            RunError::Draw {
                path: dir.join("vtk"),
                source: Box::new(e),
            }
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
        draw.plot(world, &run, summary, dir)
            .map_err(|source| RunError::Draw {
                path: dir.to_path_buf(),
                source,
            })?;
        summary.phases.drawing += t.elapsed().as_secs_f64();
    }
    Ok(())
}
