//! What can go wrong writing plots.

use std::path::PathBuf;

/// An error writing a plot or the data beside it.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// A file could not be written.
    #[error("cannot write {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The plotting library could not draw or encode a plot.
    #[error("cannot draw the plot {path}: {message}")]
    Draw {
        /// The file it was for.
        path: PathBuf,
        /// The library's message.
        message: String,
    },
}
