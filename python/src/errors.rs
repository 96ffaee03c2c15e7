//! The package's exceptions and how the library's errors become them: the message is the
//! one the CLI prints (file, line, body, node or member; what to do).

use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

create_exception!(
    linkage,
    SceneError,
    PyValueError,
    "A scene that cannot be built: the message names the file and line (and the body, node or member) and says what to do, as `linkage check` does."
);
create_exception!(
    linkage,
    RunError,
    PyRuntimeError,
    "A run that stopped: a step that could not be solved, a result file that could not be written. `results` holds the steps solved before it (None when there are none)."
);
create_exception!(
    linkage,
    ResultsError,
    PyOSError,
    "A results folder that cannot be read (missing, torn, or not written by `linkage run`)."
);

/// A scene error as [`SceneError`].
pub fn scene_error(e: &linkage::scene::SceneError) -> PyErr {
    SceneError::new_err(e.to_string())
}

/// A run's error: [`RunError`], or `KeyboardInterrupt` for a run stopped by the stop flag.
pub fn run_error(e: &linkage::scene::RunError) -> PyErr {
    match e {
        linkage::scene::RunError::Interrupted { .. } => PyKeyboardInterrupt::new_err(e.to_string()),
        other => RunError::new_err(other.to_string()),
    }
}

/// A stored run's error as [`ResultsError`].
pub fn results_error(e: &linkage::scene::StoredRunError) -> PyErr {
    ResultsError::new_err(e.to_string())
}
