//! The Python package `linkage`: scenes from files, dicts or numpy arrays, solved by the
//! library with the GIL released, results as numpy arrays. Node and member numbers are the
//! scene files' 1-based numbers; array row i is node (member) i + 1. No mechanics here: every
//! function converts and calls the library (see docs/PYTHON.md).

mod convert;
mod errors;
mod model;
mod results;
mod scene;
mod solve;

use pyo3::prelude::*;
use std::path::PathBuf;

/// Run the scene file `path` as `linkage run path --out out` does: writes `out/<scene name>/`
/// and returns its Results. `progress(done, total)` is called as steps are solved. Raises
/// SceneError for a scene that cannot be built (file and line), RunError when a step cannot
/// be solved, KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(signature = (path, out="out".into(), progress=None))]
fn run(
    py: Python<'_>,
    path: PathBuf,
    out: PathBuf,
    progress: Option<Py<PyAny>>,
) -> PyResult<results::Results> {
    scene::run_file(py, path, out, progress)
}

/// The number of solve threads still running: a run interrupted by Ctrl-C raises at once,
/// and its thread stops after the step it is in.
#[pyfunction]
fn running() -> usize {
    solve::RUNNING.load(std::sync::atomic::Ordering::SeqCst)
}

/// The module `linkage`.
#[pymodule]
#[pyo3(name = "linkage")]
fn linkage_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(running, m)?)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<model::Body>()?;
    m.add_class::<model::Material>()?;
    m.add_class::<results::Results>()?;
    m.add_class::<results::Step>()?;
    m.add_class::<results::Body>()?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("RunError", py.get_type::<errors::RunError>())?;
    m.add("ResultsError", py.get_type::<errors::ResultsError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
