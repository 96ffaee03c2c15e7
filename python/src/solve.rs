//! Running a world from Python: the solve runs on its own thread, in a rayon pool of its own,
//! with the GIL released, while the calling thread watches for Ctrl-C
//! (`Python::check_signals`) and reports progress.
//!
//! On Ctrl-C the call raises `KeyboardInterrupt` at once (within [`WATCH`]) and sets the
//! library's stop flag; the solve thread finishes the step it is in and stops there
//! ([`linkage::scene::RunError::Interrupted`]: a run with `out=` removes its staging folder,
//! leaving earlier results untouched).

use crate::errors::run_error;
use crate::results::Results;
use linkage::linkage::Interrupt;
use linkage::render::PictureWriter;
use linkage::scene::{run_in_memory, run_with, RunError, World};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::Duration;

/// Solve threads still running, those stopping after an interrupt included.
pub static RUNNING: AtomicUsize = AtomicUsize::new(0);

/// Counts a solve thread in [`RUNNING`] while it lives.
struct Running;

impl Running {
    fn start() -> Self {
        RUNNING.fetch_add(1, Ordering::SeqCst);
        Running
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.fetch_sub(1, Ordering::SeqCst);
    }
}

/// How often the calling thread looks for Ctrl-C and reports progress.
const WATCH: Duration = Duration::from_millis(50);

/// What the solve thread hands back: the results, or why there are none.
type Solved = Result<Results, Box<RunFailure>>;

/// A run that stopped: the library's error and, in memory, the steps solved before it.
pub struct RunFailure {
    error: RunError,
    results: Option<Results>,
}

/// Solve `world` (into `out/<name>/` when `out` is given, as `linkage run` does, pictures
/// included; else in memory), calling `progress(done, total)` with the steps solved so far.
pub fn run_world(
    py: Python<'_>,
    world: Arc<World>,
    out: Option<PathBuf>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Results> {
    // The library's interrupt is a handle on a flag that lives as long as the process: one
    // byte per run, leaked on purpose (a solve thread still stopping may outlive this call).
    let stop: &'static AtomicBool = Box::leak(Box::new(AtomicBool::new(false)));
    let done = Arc::new(AtomicUsize::new(0));
    let total = world.steps + 1;
    let (send, receive) = mpsc::channel::<Solved>();
    {
        let done = done.clone();
        let running = Running::start();
        std::thread::Builder::new()
            .name(format!("linkage {}", world.name))
            .spawn(move || {
                let _running = running;
                // The world the solve reads carries the interrupt (every body's Newton
                // settings): a copy when the scene object still holds the world.
                let mut world = Arc::unwrap_or_clone(world);
                world.set_interrupt(Interrupt::on(stop));
                // A thread pool of its own (as many threads as rayon's global one would have):
                // the library's parallel loops and faer's kernels of two solves started from
                // two Python threads then run side by side instead of queueing in one pool.
                let solved = match rayon::ThreadPoolBuilder::new().build() {
                    Ok(pool) => pool.install(|| solve(&world, out, &done)),
                    Err(_) => solve(&world, out, &done),
                };
                let _ = send.send(solved);
            })
            .map_err(|e| {
                pyo3::exceptions::PyOSError::new_err(format!("cannot start the solve thread: {e}"))
            })?;
    }
    let mut reported = 0;
    let report = |py: Python<'_>, reported: &mut usize| -> PyResult<()> {
        let now = done.load(Ordering::Relaxed);
        if now != *reported {
            *reported = now;
            if let Some(callback) = &progress {
                callback.call1(py, (now, total))?;
            }
        }
        Ok(())
    };
    // The receiver moves into the watch loop (it is Send, not Sync); the rest is borrowed.
    let (report_ref, stop_ref, reported_ref) = (&report, stop, &mut reported);
    let outcome: Result<Solved, PyErr> = py.detach(move || loop {
        match receive.recv_timeout(WATCH) {
            Ok(solved) => return Ok(solved),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                let watched = Python::attach(|py| {
                    py.check_signals()?;
                    report_ref(py, reported_ref)
                });
                if let Err(e) = watched {
                    stop_ref.store(true, Ordering::Relaxed);
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                return Err(pyo3::exceptions::PyRuntimeError::new_err(
                    "the solve thread ended without a result (it panicked: please report this)",
                ))
            }
        }
    });
    let solved = outcome?;
    report(py, &mut reported)?;
    solved.map_err(|failure| {
        let failure = *failure;
        let err = run_error(&failure.error);
        if let Some(results) = failure.results {
            let _ = err.value(py).setattr("results", Py::new(py, results).ok());
        } else if err.is_instance_of::<crate::errors::RunError>(py) {
            let _ = err.value(py).setattr("results", py.None());
        }
        err
    })
}

/// The solve itself, on the solve thread.
fn solve(world: &World, out: Option<PathBuf>, done: &AtomicUsize) -> Solved {
    let on_step = || {
        done.fetch_add(1, Ordering::Relaxed);
    };
    match out {
        Some(out) => {
            let fail = |error| {
                Box::new(RunFailure {
                    error,
                    results: None,
                })
            };
            std::fs::create_dir_all(&out).map_err(|source| {
                fail(RunError::Write {
                    path: out.clone(),
                    source,
                })
            })?;
            run_with(world, &out, &on_step, Some(&PictureWriter)).map_err(fail)?;
            let folder = out.join(&world.name);
            Results::read(folder.clone()).map_err(|e| {
                fail(RunError::Draw {
                    path: folder,
                    source: e.to_string().into(),
                })
            })
        }
        None => match run_in_memory(world, &on_step) {
            Ok((summary, steps, None)) => Ok(Results::new(steps, Some(summary), None)),
            Ok((summary, steps, Some(error))) => Err(Box::new(RunFailure {
                error,
                results: Some(Results::new(steps, Some(summary), None)),
            })),
            Err(error) => Err(Box::new(RunFailure {
                error,
                results: None,
            })),
        },
    }
}
