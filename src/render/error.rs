//! Why pictures could not be made.

use crate::scene::StoredRunError;
use std::path::PathBuf;

/// Why pictures could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The results folder could not be read.
    #[error(transparent)]
    Read(#[from] StoredRunError),
    /// A render option that cannot be used.
    #[error("{message}")]
    Option {
        /// What is wrong and what to give instead.
        message: String,
    },
    /// A step that is not stored was asked for.
    #[error("step {step} is not stored in {dir} (stored: {stored}): choose stored steps, or run the scene again with [output] every = 1")]
    NoSuchStep {
        /// The step asked for.
        step: usize,
        /// The results folder.
        dir: PathBuf,
        /// The stored steps, as text.
        stored: String,
    },
    /// The drawing was asked to stop ([`crate::linkage::Interrupt`]) before `dir`'s frames were
    /// all drawn: nothing of it is kept (`png/` and `anim.gif` stay as they were).
    #[error("{dir}: drawing interrupted: png/ and anim.gif left as they were")]
    Interrupted {
        /// The folder being drawn into.
        dir: PathBuf,
    },
    /// A picture could not be encoded.
    #[error("cannot encode the {what}: {message}")]
    Encode {
        /// "PNG" or "GIF".
        what: String,
        /// The encoder's message.
        message: String,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// File or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}
