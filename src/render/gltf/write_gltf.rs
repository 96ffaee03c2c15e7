//! Writing `anim.glb` of a run's results.

use crate::render::animated_run::{AnimatedRun, FrameBudget};
use crate::render::gltf::document::gltf_of_run;
use crate::render::RenderError;
use crate::scene::atomic_file::write_atomically;
use crate::scene::RunResults;
use crate::Real;
use std::path::{Path, PathBuf};

/// The file name of the animation in a results folder.
pub const GLTF_FILE: &str = "anim.glb";

/// The frames a GLB holds at most: the weights of its morph targets grow as frames² per body
/// (KhronosGroup/glTF #2175), and its deltas as frames × vertices (24 bytes each: position
/// and colour); longer or larger runs keep evenly spaced stored steps.
pub const GLTF_BUDGET: FrameBudget = FrameBudget {
    max_frames: 250,
    max_vertex_frames: 4 << 20,
};

/// What [`write_gltf`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct GltfReport {
    /// The file.
    pub path: PathBuf,
    /// Stored steps of the run.
    pub stored_steps: usize,
    /// Frames (morph targets, keyframes) in the file: fewer than the stored steps when
    /// decimated to [`GLTF_BUDGET`].
    pub frames: usize,
    /// Bytes written.
    pub bytes: usize,
}

/// Write `dir/anim.glb` (atomically) of `run`, displacements drawn `magnification` times
/// larger (as in the pictures), times from `time_of` when the run has them (else 10 stored
/// steps per second).
pub fn write_gltf(
    run: &RunResults,
    dir: &Path,
    magnification: Real,
    time_of: impl Fn(&crate::scene::StepResult) -> Option<Real>,
) -> Result<GltfReport, RenderError> {
    let animation = AnimatedRun::of_run(run, magnification, GLTF_BUDGET, time_of);
    let bytes = gltf_of_run(&animation);
    let path = dir.join(GLTF_FILE);
    write_atomically(&path, &bytes).map_err(|source| RenderError::Write {
        path: path.clone(),
        source,
    })?;
    Ok(GltfReport {
        path,
        stored_steps: animation.stored_steps,
        frames: animation.frames.len(),
        bytes: bytes.len(),
    })
}
