//! The one error of a model file: the file, the line and what is wrong.

use std::path::PathBuf;

/// A problem in a model file (MSH or INP): the file, the 1-based line (for a binary MSH
/// section, the line its header is on, the byte in the message) and what is wrong and what
/// to do.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}: {message}", .path.display())]
pub struct ModelFileError {
    /// The file (an `*INCLUDE`d file when the problem is in it).
    pub path: PathBuf,
    /// 1-based line (0 when the file cannot be read at all).
    pub line: usize,
    /// What is wrong and what to do.
    pub message: String,
}

impl ModelFileError {
    /// An error at `line` of `path`.
    pub fn at(path: &std::path::Path, line: usize, message: impl Into<String>) -> Self {
        ModelFileError {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }
}
