//! What a run writes besides `summary.json` and the step files, into the staging folder before
//! it is published: `model.json` always, VTK files and pictures when asked for.

use crate::atomic_file::write_atomically;
use crate::scene::model_file::ModelFile;
use crate::scene::results::PhaseSeconds;
use crate::scene::simulation::RunError;
use crate::scene::stored_run::StoredRun;
use crate::scene::vtk::write_vtk;
use crate::scene::World;
use std::path::Path;
use std::time::Instant;

/// Draws pictures of a complete results folder (its `model.json` and step files written).
/// `scene` does not draw; `render` implements this (`linkage::render::PictureWriter`) and
/// the caller of [`crate::scene::run_with`] passes it in.
pub trait DrawResults: Sync {
    /// Draw the pictures `world.pictures` asks for into `dir`, writing each file atomically.
    /// The error is a complete sentence naming the file.
    fn draw(&self, world: &World, dir: &Path) -> Result<(), String>;
}

/// Write `model.json`, then VTK files and pictures as `world.pictures` asks, into `dir`.
pub(crate) fn write_extra_outputs(
    world: &World,
    dir: &Path,
    draw: Option<&dyn DrawResults>,
    phases: &mut PhaseSeconds,
) -> Result<(), RunError> {
    let t = Instant::now();
    let path = dir.join("model.json");
    let bytes = serde_json::to_vec(&ModelFile::new(world)).map_err(|e| RunError::Write {
        path: path.clone(),
        source: e.into(),
    })?;
    write_atomically(&path, &bytes).map_err(|source| RunError::Write {
        path: path.clone(),
        source,
    })?;
    if world.pictures.vtk {
        let stored = StoredRun::open(dir).map_err(|e| RunError::Draw {
            path: dir.to_path_buf(),
            message: e.to_string(),
        })?;
        write_vtk(&stored).map_err(|e| RunError::Draw {
            path: dir.join("vtk"),
            message: e.to_string(),
        })?;
    }
    phases.writing += t.elapsed().as_secs_f64();
    if let Some(draw) = draw.filter(|_| world.pictures.png || world.pictures.gif) {
        let t = Instant::now();
        draw.draw(world, dir).map_err(|message| RunError::Draw {
            path: dir.to_path_buf(),
            message,
        })?;
        phases.drawing += t.elapsed().as_secs_f64();
    }
    Ok(())
}
