//! Reading the values of an MSH 4.1 section from its bytes, the same calls for ASCII
//! (whitespace-separated words) and binary (little-endian `int` = 4 bytes, `size_t` = 8,
//! `double` = 8) files; every error names the file and line (binary: the byte too).

use crate::scene::import::ModelFileError;
use crate::Real;
use std::path::Path;

/// A position in an MSH file's bytes, reading ASCII words or binary values.
pub(crate) struct MshCursor<'a> {
    /// The file, for errors.
    pub(crate) path: &'a Path,
    /// All its bytes.
    pub(crate) bytes: &'a [u8],
    /// The next byte to read.
    pub(crate) pos: usize,
    /// Binary sections (`$MeshFormat` file-type 1).
    pub(crate) binary: bool,
    /// The section being read (`$Nodes`), for errors.
    pub(crate) section: &'static str,
}

impl<'a> MshCursor<'a> {
    /// The 1-based line of byte `at`.
    pub(crate) fn line_of(&self, at: usize) -> usize {
        self.bytes[..at.min(self.bytes.len())]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1
    }

    /// An error at the current position.
    pub(crate) fn error(&self, message: impl Into<String>) -> ModelFileError {
        let message = message.into();
        let message = if self.binary && !self.section.is_empty() {
            format!("{message} (binary {}, byte {})", self.section, self.pos)
        } else if !self.section.is_empty() {
            format!("{message} (in {})", self.section)
        } else {
            message
        };
        ModelFileError::at(self.path, self.line_of(self.pos), message)
    }

    /// Skip the whitespace before the next ASCII value (binary: nothing), so that the
    /// position names the value's line.
    pub(crate) fn skip_space(&mut self) {
        if !self.binary {
            while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
                self.pos += 1;
            }
        }
    }

    /// The bytes left.
    pub(crate) fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    /// The next line as text without its end (`None` at the end of the file).
    pub(crate) fn line(&mut self) -> Option<&'a str> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let rest = &self.bytes[self.pos..];
        let end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        self.pos += (end + 1).min(rest.len());
        let text = std::str::from_utf8(&rest[..end]).unwrap_or("");
        Some(text.trim_end_matches('\r'))
    }

    /// The next whitespace-separated word of an ASCII section.
    fn word(&mut self, what: &str) -> Result<&'a str, ModelFileError> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        while self.pos < self.bytes.len() && !self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error(format!(
                "the file ends where {what} should be: it is cut short; write it again from gmsh"
            )));
        }
        let word = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("?");
        if word.starts_with('$') {
            self.pos = start;
            return Err(self.error(format!(
                "{word} comes where {what} should be: the section has fewer values than its counts say"
            )));
        }
        Ok(word)
    }

    /// `N` bytes of a binary section.
    fn take<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ModelFileError> {
        match self.bytes.get(self.pos..self.pos + N) {
            Some(b) => {
                self.pos += N;
                let mut out = [0u8; N];
                out.copy_from_slice(b);
                Ok(out)
            }
            None => Err(self.error(format!(
                "the file ends where {what} should be: it is cut short; write it again from gmsh"
            ))),
        }
    }

    /// A count or tag (`size_t`).
    pub(crate) fn size(&mut self, what: &str) -> Result<usize, ModelFileError> {
        if self.binary {
            let v = u64::from_le_bytes(self.take::<8>(what)?);
            return usize::try_from(v)
                .map_err(|_| self.error(format!("{what} = {v} is too large")));
        }
        let word = self.word(what)?;
        word.parse::<usize>().map_err(|_| {
            self.error(format!(
                "{what} is {word:?}: give a whole number of 0 or more"
            ))
        })
    }

    /// An `int` (dimensions, entity tags, element types, physical tags).
    pub(crate) fn int(&mut self, what: &str) -> Result<i64, ModelFileError> {
        if self.binary {
            return Ok(i32::from_le_bytes(self.take::<4>(what)?) as i64);
        }
        let word = self.word(what)?;
        word.parse::<i64>()
            .map_err(|_| self.error(format!("{what} is {word:?}: give a whole number")))
    }

    /// A `double`, finite.
    pub(crate) fn double(&mut self, what: &str) -> Result<Real, ModelFileError> {
        let v = if self.binary {
            f64::from_le_bytes(self.take::<8>(what)?)
        } else {
            let word = self.word(what)?;
            word.parse::<Real>()
                .map_err(|_| self.error(format!("{what} is {word:?}: give a number")))?
        };
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(format!("{what} is {v}: give finite numbers")))
        }
    }

    /// After a section's values: only whitespace up to `$End...` on its own line.
    pub(crate) fn end(&mut self, end: &str) -> Result<(), ModelFileError> {
        while self.pos < self.bytes.len() && self.bytes[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let at = self.pos;
        match self.line() {
            Some(l) if l.trim() == end => Ok(()),
            Some(l) => {
                self.pos = at;
                Err(self.error(format!(
                    "{:?} comes where {end} should be: the section has more values than its counts say",
                    l.chars().take(40).collect::<String>()
                )))
            }
            None => Err(self.error(format!("the file ends before {end}: it is cut short"))),
        }
    }
}
