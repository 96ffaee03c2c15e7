//! The lines of a links file parsed fast: a links file of a large model has millions of
//! lines, nearly all of the plain form `i j` or `i j material`. Those are read in one pass
//! over their bytes, on all cores (the file cut at line ends); any other line goes through
//! the general checks of [`paper_files::link_record`], so every error and its line number is
//! the same as line by line.

use crate::scene::paper_files::{
    self, ascii_columns, comma_error, shared_name, text_columns, LinkRecord, PaperFileError,
};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Arc;

/// Below this many bytes a links file is parsed in one piece.
const PARALLEL_BYTES: usize = 1 << 20;

/// Every member of the links file `text`, in file order, or the error of its first bad line.
/// Node numbers are turned 0-based but not checked against `node_count` (the caller's member
/// check names those).
pub(crate) fn parse(
    text: &str,
    path: &Path,
    node_count: usize,
) -> Result<Vec<LinkRecord>, PaperFileError> {
    // A byte-order mark, as some Windows editors write, is not part of the first number.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let pieces = if text.len() < PARALLEL_BYTES {
        1
    } else {
        4 * rayon::current_num_threads()
    };
    let chunks = line_chunks(text, pieces);
    let parts: Vec<Result<Vec<LinkRecord>, PaperFileError>> = chunks
        .par_iter()
        .map(|&(first_line, chunk)| parse_chunk(chunk, first_line, path, node_count))
        .collect();
    let mut records = Vec::with_capacity(parts.iter().flatten().map(Vec::len).sum());
    for part in parts {
        records.extend(part?);
    }
    Ok(records)
}

/// `text` cut into about `pieces` runs of whole lines, each with the 1-based number of its
/// first line.
fn line_chunks(text: &str, pieces: usize) -> Vec<(usize, &str)> {
    let bytes = text.as_bytes();
    let target = bytes.len().div_ceil(pieces.max(1)).max(1);
    let mut chunks = Vec::with_capacity(pieces);
    let (mut start, mut line) = (0, 1);
    while start < bytes.len() {
        let mut end = (start + target).min(bytes.len());
        // Past the next line end (a `\n` is never inside a UTF-8 character).
        end += bytes[end..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len() - end, |p| p + 1);
        let chunk = &text[start..end];
        chunks.push((line, chunk));
        line += chunk.bytes().filter(|&b| b == b'\n').count();
        start = end;
    }
    chunks
}

/// The members of the lines of `chunk`, whose first line is `first_line` of the file.
fn parse_chunk(
    chunk: &str,
    first_line: usize,
    path: &Path,
    node_count: usize,
) -> Result<Vec<LinkRecord>, PaperFileError> {
    // About 10 bytes a line in a lattice's file: reserve once rather than grow.
    let mut records = Vec::with_capacity(chunk.len() / 10 + 1);
    let mut names: Vec<Arc<str>> = Vec::new();
    for (k, raw) in chunk.lines().enumerate() {
        let line = first_line + k;
        if let Some(record) = plain_link(raw, line, &mut names) {
            records.push(record);
            continue;
        }
        let columns = if raw.is_ascii() {
            ascii_columns(raw)
        } else {
            text_columns(raw)
        }
        .ok_or_else(|| comma_error(path, line))?;
        if columns.count > 0 {
            records.push(paper_files::link_record(
                line, &columns, &mut names, path, node_count,
            )?);
        }
    }
    Ok(records)
}

/// The member of a plain line: two node numbers (digits, at least 1) and an optional ASCII
/// material name, separated by ASCII whitespace, maybe followed by a `#` comment. `None` for
/// any other line (blank, a comment alone, or anything [`paper_files::link_record`] must
/// judge).
fn plain_link(raw: &str, line: usize, names: &mut Vec<Arc<str>>) -> Option<LinkRecord> {
    let bytes = raw.as_bytes();
    let mut tokens: [(usize, usize); 3] = [(0, 0); 3];
    let mut count = 0;
    let mut start = None;
    let mut end = bytes.len();
    for (k, &b) in bytes.iter().enumerate() {
        match b {
            b'#' => {
                end = k;
                break;
            }
            b' ' | b'\t' | b'\x0b' | b'\x0c' | b'\r' => {
                if let Some(s) = start.take() {
                    *tokens.get_mut(count)? = (s, k);
                    count += 1;
                }
            }
            b',' => return None,
            b if !b.is_ascii() => return None,
            _ => {
                start.get_or_insert(k);
            }
        }
    }
    if let Some(s) = start {
        *tokens.get_mut(count)? = (s, end);
        count += 1;
    }
    if count < 2 {
        return None;
    }
    let node = |(s, e): (usize, usize)| -> Option<usize> {
        let digits = &bytes[s..e];
        if digits.len() >= 19 || !digits.iter().all(u8::is_ascii_digit) {
            return None;
        }
        digits
            .iter()
            .fold(0usize, |n, &b| n * 10 + usize::from(b - b'0'))
            .checked_sub(1)
    };
    let nodes = [node(tokens[0])?, node(tokens[1])?];
    let material = (count == 3).then(|| shared_name(names, &raw[tokens[2].0..tokens[2].1]));
    Some(LinkRecord {
        line,
        nodes,
        material,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::paper_files::data_lines;

    /// The records line by line through the general path alone.
    fn general(text: &str) -> Result<Vec<LinkRecord>, PaperFileError> {
        let path = Path::new("t.links");
        let mut names = Vec::new();
        let mut records = Vec::new();
        for item in data_lines(text, path) {
            let (line, columns) = item?;
            records.push(paper_files::link_record(
                line, &columns, &mut names, path, 10,
            )?);
        }
        Ok(records)
    }

    #[test]
    fn chunks_cover_the_text_at_line_ends_with_their_line_numbers() {
        let text = "1 2\n3 4 steel\n\n# c\n5 6\n7 8";
        for pieces in 1..8 {
            let chunks = line_chunks(text, pieces);
            assert_eq!(chunks.iter().map(|c| c.1).collect::<String>(), text);
            for (first, chunk) in &chunks {
                let before = &text[..text.find(chunk).unwrap_or(0)];
                assert_eq!(*first, 1 + before.matches('\n').count());
            }
        }
    }

    #[test]
    fn the_same_records_and_errors_as_the_general_path() {
        let path = Path::new("t.links");
        let good =
            "\u{feff}1 2\n2\t3 steel # a, comment\r\n\n  # only\n3 4   rubber\n4 5 stéel\n0007 8\n";
        let bad = [
            "1 2\n3, 4\n",
            "1 2\n3 4 5 6\n",
            "1 2\n0 4\n",
            "1 2\n-1 4\n",
            "1 2\n1.5 4\n",
            "1 2\n3e0 4\n",
            "1 2\nx 4\n",
            "1 2\n3\n",
            "1 2\n99999999999999999999999 4\n",
            "1\u{3000}2\n",
            "1 2\u{a0}3\n",
        ];
        for text in std::iter::once(good).chain(bad) {
            for pieces in [1, 3] {
                let chunks = line_chunks(text.strip_prefix('\u{feff}').unwrap_or(text), pieces);
                let fast: Result<Vec<LinkRecord>, PaperFileError> = chunks
                    .iter()
                    .map(|&(first, chunk)| parse_chunk(chunk, first, path, 10))
                    .collect::<Result<Vec<_>, _>>()
                    .map(|parts| parts.into_iter().flatten().collect());
                assert_eq!(fast, general(text), "{text:?} in {pieces} pieces");
            }
        }
        assert_eq!(parse(good, path, 10).map(|r| r.len()), Ok(5));
    }
}
