//! Why a run stopped: the one error type of the load-step driver and its writers.

use crate::contact::ContactError;
use crate::linkage::SolveError;
use std::path::PathBuf;

/// Why a run stopped.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A body could not be solved.
    #[error("{scene}: {source}")]
    Solve {
        /// Scene file.
        scene: PathBuf,
        /// What went wrong.
        source: SolveError,
    },
    /// The bodies in contact could not be solved.
    #[error("{scene}: {source}")]
    Contact {
        /// Scene file.
        scene: PathBuf,
        /// What went wrong.
        source: ContactError,
    },
    /// A result file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// File or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A step could not be solved after step 0: the steps solved before it were written to
    /// `results` (beside earlier complete results of the scene, never over them).
    #[error("{source}; the steps solved before it are in {}", results.display())]
    Stopped {
        /// The folder holding step 0 up to the last solved step and the summary.
        results: PathBuf,
        /// Why the step failed.
        source: Box<RunError>,
    },
    /// A break made a structure a mechanism: a result, not a failure. The driver records it
    /// in the summary and ends the run there with the steps before it written, and the
    /// collapse step itself when its state is known (`written`).
    #[error("body '{}' collapsed at step {} (load factor {}): breaking member {} left its supported part a mechanism", .collapse.body, .collapse.step, .collapse.load_factor, .collapse.member)]
    Collapse {
        /// The collapse.
        collapse: crate::scene::results::Collapse,
        /// The breaks of the collapse step, the last one included.
        breaks: Vec<crate::scene::results::SummaryBreak>,
        /// The collapse step as written, when the state it collapsed in is known: the run's
        /// last stored step, flagged `collapse`.
        written: Option<Box<(crate::scene::StepResult, crate::scene::StepSummary)>>,
    },
    /// The run was asked to stop (SIGINT, SIGTERM) before it finished; nothing was written.
    #[error("{scene}: interrupted at step {step}: no results written (earlier results of the scene are untouched)")]
    Interrupted {
        /// Scene file.
        scene: PathBuf,
        /// The step being solved, drawn or written when it stopped.
        step: usize,
    },
    /// Pictures or VTK files could not be made.
    #[error("{path}: {source}")]
    Draw {
        /// Results folder or file.
        path: PathBuf,
        /// What went wrong and what to do: the writer's own error (a
        /// [`crate::scene::VtkError`], or the picture writer's).
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}
