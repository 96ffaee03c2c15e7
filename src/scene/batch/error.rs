//! What can go wrong planning, sharding, collecting or scripting a batch.

use std::path::PathBuf;

/// Why a batch command cannot go on. Every variant names its file or argument.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// A scene whose `[sweep]` is wrong (the message names the key and line).
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// `--shard` or the scheduler's array variables.
    #[error("--shard {given}: {problem}")]
    Shard {
        /// What was given (the argument, or the variables read).
        given: String,
        /// What is wrong and what to do.
        problem: String,
    },
    /// A file that cannot be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A file that is not what a batch writes.
    #[error("{path}: {problem}")]
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong and what to do.
        problem: String,
    },
    /// An argument of `linkage slurm` that cannot go into a job script.
    #[error("{argument}: {problem}")]
    Argument {
        /// The option, e.g. `--time`.
        argument: &'static str,
        /// What is wrong and what to do.
        problem: String,
    },
}

/// A closure making [`BatchError::Io`] for `path`.
pub(crate) fn io_at(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> BatchError {
    let path = path.to_path_buf();
    move |source| BatchError::Io { path, source }
}
