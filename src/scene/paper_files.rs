//! The paper's plain-text files: nodes (`x y` or `x y z` per line, m), links (`i j` per line,
//! 1-based node numbers, optionally a material name as a third column) and patches (`i j k`
//! per line, 1-based). Columns are separated by spaces or tabs, `#` starts a comment anywhere
//! on a line, and blank lines are ignored; the n-th data line is node (member, patch) n.

use crate::linkage::{check_members, Dimension, MemberProblem};
use crate::scene::atomic_file::write_atomically;
use crate::scene::link_lines;
use crate::Real;
use nalgebra::Vector3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A problem in one of the paper's files, with the file's path and, when it is about one
/// line, its 1-based line number. The message says what is wrong and how to fix it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PaperFileError {
    /// A problem on one line.
    #[error("{}:{line}: {message}", .path.display())]
    Line {
        /// The file.
        path: PathBuf,
        /// The line, 1-based as editors count.
        line: usize,
        /// What is wrong and what to do.
        message: String,
    },
    /// A problem with the file as a whole: it cannot be read, or it holds no data.
    #[error("{}: {message}", .path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong and what to do.
        message: String,
    },
}

/// One member as read from a links file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LinkRecord {
    /// The line it was read from, 1-based: for messages about this member.
    pub line: usize,
    /// Its end nodes, 0-based.
    pub nodes: [usize; 2],
    /// The material named in the third column, if any (shared by every record naming it: a
    /// links file names few materials on millions of lines).
    pub material: Option<Arc<str>>,
}

/// Parse the text of a nodes file: the dimension (2D for `x y` lines, 3D for `x y z`) and the
/// node positions in m (z = 0 in 2D). `path` only names the file in errors.
pub fn parse_nodes(
    text: &str,
    path: &Path,
) -> Result<(Dimension, Vec<Vector3<Real>>), PaperFileError> {
    let mut nodes = Vec::new();
    // The column count of the first node and its line, which every later node must match.
    let mut first: Option<(usize, usize)> = None;
    for item in data_lines(text, path) {
        let (line, columns) = item?;
        let count = columns.count;
        if !(2..=3).contains(&count) {
            return Err(line_error(
                path,
                line,
                format!("expected 2 or 3 coordinates (`x y` or `x y z`, in metres), found {count}"),
            ));
        }
        match first {
            None => first = Some((count, line)),
            Some((first_count, first_line)) if first_count != count => {
                return Err(line_error(
                    path,
                    line,
                    format!(
                        "line {line} has {count} coordinates but line {first_line} has {first_count}: \
                         a nodes file is all `x y` (2D) or all `x y z` (3D)"
                    ),
                ));
            }
            Some(_) => {}
        }
        let mut p = Vector3::zeros();
        for (d, token) in columns.first[..count].iter().enumerate() {
            p[d] = coordinate(token, path, line)?;
        }
        nodes.push(p);
    }
    match first {
        Some((2, _)) => Ok((Dimension::Two, nodes)),
        Some(_) => Ok((Dimension::Three, nodes)),
        None => Err(file_error(
            path,
            "no nodes: the file is empty or holds only comments; \
             write one node per line as `x y` (2D) or `x y z` (3D), in metres"
                .to_string(),
        )),
    }
}

/// Read a nodes file: see [`parse_nodes`].
pub fn read_nodes(path: &Path) -> Result<(Dimension, Vec<Vector3<Real>>), PaperFileError> {
    parse_nodes(&read_text(path)?, path)
}

/// Parse the text of a links file against the `nodes` (m) it joins: one [`LinkRecord`] per
/// member. Every member must join two different existing nodes that are not at the same
/// place, and no pair may be joined twice. `path` only names the file in errors.
pub fn parse_links(
    text: &str,
    path: &Path,
    nodes: &[Vector3<Real>],
) -> Result<Vec<LinkRecord>, PaperFileError> {
    let records = link_lines::parse(text, path, nodes.len())?;
    if records.is_empty() {
        return Err(file_error(
            path,
            "no members: the file is empty or holds only comments; \
             write one member per line as `i j` (1-based node numbers)"
                .to_string(),
        ));
    }
    check_members(nodes, records.iter().map(|r| r.nodes))
        .map_err(|problem| member_error(problem, &records, nodes.len(), path))?;
    Ok(records)
}

/// The member of one data line of a links file (`line`, 1-based, with its `columns`), its
/// material shared through `names`: every check of a line and its message.
pub(crate) fn link_record(
    line: usize,
    columns: &Columns,
    names: &mut Vec<Arc<str>>,
    path: &Path,
    node_count: usize,
) -> Result<LinkRecord, PaperFileError> {
    let count = columns.count;
    if !(2..=3).contains(&count) {
        return Err(line_error(
            path,
            line,
            format!(
                "expected 2 node numbers and an optional material name \
                 (`i j` or `i j material`), found {count} columns"
            ),
        ));
    }
    let [i, j, material] = columns.first;
    Ok(LinkRecord {
        line,
        nodes: [
            node_number(i, node_count, path, line)?,
            node_number(j, node_count, path, line)?,
        ],
        material: (count == 3).then(|| shared_name(names, material)),
    })
}

/// `name` as held in `names`, added if new.
pub(crate) fn shared_name(names: &mut Vec<Arc<str>>, name: &str) -> Arc<str> {
    match names.iter().find(|n| &***n == name) {
        Some(shared) => shared.clone(),
        None => {
            let shared: Arc<str> = name.into();
            names.push(shared.clone());
            shared
        }
    }
}

/// Read a links file: see [`parse_links`].
pub fn read_links(path: &Path, nodes: &[Vector3<Real>]) -> Result<Vec<LinkRecord>, PaperFileError> {
    parse_links(&read_text(path)?, path, nodes)
}

/// Parse the text of a patches file: triangles as 0-based node triples, each naming three
/// different nodes among the `node_count` nodes. An empty file gives no patches.
/// `path` only names the file in errors.
pub fn parse_patches(
    text: &str,
    path: &Path,
    node_count: usize,
) -> Result<Vec<[usize; 3]>, PaperFileError> {
    let mut patches = Vec::new();
    for item in data_lines(text, path) {
        let (line, columns) = item?;
        if columns.count != 3 {
            return Err(line_error(
                path,
                line,
                format!(
                    "expected 3 node numbers (`i j k`, counter-clockwise seen from outside), found {} columns",
                    columns.count
                ),
            ));
        }
        let mut patch = [0; 3];
        for (slot, token) in patch.iter_mut().zip(columns.first) {
            let node = node_number(token, node_count, path, line)?;
            if node >= node_count {
                return Err(line_error(path, line, missing_node(node + 1, node_count)));
            }
            *slot = node;
        }
        let [a, b, c] = patch;
        if let Some(repeated) = [(a, b), (b, c), (a, c)]
            .iter()
            .find(|(p, q)| p == q)
            .map(|(p, _)| p)
        {
            return Err(line_error(
                path,
                line,
                format!(
                    "the patch repeats node {}: a patch needs three different nodes",
                    repeated + 1
                ),
            ));
        }
        patches.push(patch);
    }
    Ok(patches)
}

/// Read a patches file: see [`parse_patches`].
pub fn read_patches(path: &Path, node_count: usize) -> Result<Vec<[usize; 3]>, PaperFileError> {
    parse_patches(&read_text(path)?, path, node_count)
}

/// Write a nodes file atomically: `x y` (2D) or `x y z` (3D) per node, m, each number in the
/// shortest form that reads back to the same `f64`, so [`read_nodes`] returns `nodes` exactly.
/// Fails with `InvalidInput` for a non-finite coordinate or, in 2D, a node off z = 0, which
/// would not read back.
pub fn write_nodes(
    path: &Path,
    dimension: Dimension,
    nodes: &[Vector3<Real>],
) -> std::io::Result<()> {
    write_atomically(path, nodes_text(dimension, nodes)?.as_bytes())
}

/// The text [`write_nodes`] writes: [`parse_nodes`] reads `nodes` back from it exactly.
pub fn nodes_text(dimension: Dimension, nodes: &[Vector3<Real>]) -> std::io::Result<String> {
    let d = dimension.dofs_per_node();
    let mut text = String::with_capacity(nodes.len() * 16 * d);
    for (n, p) in nodes.iter().enumerate() {
        if let Some(v) = p.iter().find(|v| !v.is_finite()) {
            return Err(invalid_input(format!(
                "node {} has the coordinate {v}: only finite numbers can be written",
                n + 1
            )));
        }
        if dimension == Dimension::Two && p.z != 0.0 {
            return Err(invalid_input(format!(
                "node {} has z = {:?} but the body is 2D: a 2D nodes file has no z",
                n + 1,
                p.z
            )));
        }
        // `{:?}` is Rust's shortest round-trip form (`0.1`, `1e-7`, `-0.0`).
        let _ = match dimension {
            Dimension::Two => writeln!(text, "{:?} {:?}", p.x, p.y),
            Dimension::Three => writeln!(text, "{:?} {:?} {:?}", p.x, p.y, p.z),
        };
    }
    Ok(text)
}

/// Write a links file atomically: `i j` per member (1-based node numbers), or `i j material`
/// when `materials` gives one name per member. Fails with `InvalidInput` when the names do not
/// match the members one to one, or a name is empty or holds whitespace, `#` or `,`, which
/// would not read back.
pub fn write_links(
    path: &Path,
    members: &[[usize; 2]],
    materials: Option<&[String]>,
) -> std::io::Result<()> {
    write_atomically(path, links_text(members, materials)?.as_bytes())
}

/// The text [`write_links`] writes (`members` 0-based; written 1-based).
pub fn links_text(members: &[[usize; 2]], materials: Option<&[String]>) -> std::io::Result<String> {
    if let Some(names) = materials {
        if names.len() != members.len() {
            return Err(invalid_input(format!(
                "{} material names for {} members: give one name per member",
                names.len(),
                members.len()
            )));
        }
        if let Some((m, name)) = names.iter().enumerate().find(|(_, name)| {
            name.is_empty() || name.contains(|c: char| c.is_whitespace() || c == '#' || c == ',')
        }) {
            return Err(invalid_input(format!(
                "member {}: material name {name:?} cannot be written in a links file: \
                 names are one word without `#` or `,`",
                m + 1
            )));
        }
    }
    let mut text = String::with_capacity(members.len() * 16);
    for (m, [a, b]) in members.iter().enumerate() {
        let _ = match materials {
            Some(names) => writeln!(text, "{} {} {}", a + 1, b + 1, names[m]),
            None => writeln!(text, "{} {}", a + 1, b + 1),
        };
    }
    Ok(text)
}

/// Write a patches file atomically: `i j k` per patch, 1-based node numbers, in the order given
/// (keep them counter-clockwise seen from outside).
pub fn write_patches(path: &Path, patches: &[[usize; 3]]) -> std::io::Result<()> {
    let mut text = String::with_capacity(patches.len() * 24);
    for [a, b, c] in patches {
        let _ = writeln!(text, "{} {} {}", a + 1, b + 1, c + 1);
    }
    write_atomically(path, text.as_bytes())
}

/// The whitespace-separated columns of one data line: how many, and the first three.
pub(crate) struct Columns<'a> {
    /// How many columns the line has.
    pub(crate) count: usize,
    /// The first three of them.
    pub(crate) first: [&'a str; 3],
}

/// The data lines of `text` with their 1-based line numbers: comments stripped, blank lines
/// skipped, a comma reported as an error (it would otherwise surface as a puzzling
/// "not a number").
pub(crate) fn data_lines<'a>(
    text: &'a str,
    path: &'a Path,
) -> impl Iterator<Item = Result<(usize, Columns<'a>), PaperFileError>> + 'a {
    // A byte-order mark, as some Windows editors write, is not part of the first number.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.lines().enumerate().filter_map(move |(index, raw)| {
        let line = index + 1;
        let columns = if raw.is_ascii() {
            ascii_columns(raw)
        } else {
            text_columns(raw)
        };
        match columns {
            Some(columns) => (columns.count > 0).then_some(Ok((line, columns))),
            None => Some(Err(comma_error(path, line))),
        }
    })
}

/// The error of a line with a comma, which would otherwise surface as a puzzling "not a
/// number".
pub(crate) fn comma_error(path: &Path, line: usize) -> PaperFileError {
    line_error(
        path,
        line,
        "found a comma: separate the columns with spaces or tabs, not commas \
         (and write decimals with a point: 0.5)"
            .to_string(),
    )
}

/// The columns of a line of any text: up to a `#`, split at Unicode whitespace; `None` if
/// that part holds a comma.
pub(crate) fn text_columns(raw: &str) -> Option<Columns<'_>> {
    let content = raw.split('#').next().unwrap_or_default();
    if content.contains(',') {
        return None;
    }
    let mut columns = Columns {
        count: 0,
        first: [""; 3],
    };
    for token in content.split_whitespace() {
        if let Some(slot) = columns.first.get_mut(columns.count) {
            *slot = token;
        }
        columns.count += 1;
    }
    Some(columns)
}

/// [`text_columns`] of an ASCII line in one pass over its bytes (the files of large models
/// are millions of such lines). ASCII whitespace here is what `char::is_whitespace` calls
/// whitespace among ASCII characters, so both give the same columns.
pub(crate) fn ascii_columns(raw: &str) -> Option<Columns<'_>> {
    let bytes = raw.as_bytes();
    let mut columns = Columns {
        count: 0,
        first: [""; 3],
    };
    let mut start = None;
    let mut end = bytes.len();
    for (k, &b) in bytes.iter().enumerate() {
        match b {
            b'#' => {
                end = k;
                break;
            }
            b',' => return None,
            b' ' | b'\t' | b'\n' | b'\x0b' | b'\x0c' | b'\r' => {
                if let Some(s) = start.take() {
                    push_column(&mut columns, &raw[s..k]);
                }
            }
            _ => {
                start.get_or_insert(k);
            }
        }
    }
    if let Some(s) = start {
        push_column(&mut columns, &raw[s..end]);
    }
    Some(columns)
}

/// Count a column, keeping the first three.
fn push_column<'a>(columns: &mut Columns<'a>, token: &'a str) {
    if let Some(slot) = columns.first.get_mut(columns.count) {
        *slot = token;
    }
    columns.count += 1;
}

/// A coordinate, m: a finite number.
fn coordinate(token: &str, path: &Path, line: usize) -> Result<Real, PaperFileError> {
    match token.parse::<Real>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(line_error(
            path,
            line,
            format!("coordinate {token} is not a finite number: give coordinates in metres, like 0.25 or -1.5e-3"),
        )),
        Err(_) => Err(line_error(
            path,
            line,
            format!("'{token}' is not a number: give coordinates in metres, like 0.25 or -1.5e-3"),
        )),
    }
}

/// A 1-based node number as written, turned 0-based. Numbers past `node_count` are returned
/// as they are (0-based) for the caller to report; 0 and numbers too large to hold are
/// reported here, as they have no 0-based index.
fn node_number(
    token: &str,
    node_count: usize,
    path: &Path,
    line: usize,
) -> Result<usize, PaperFileError> {
    // Plain digits, the case of every valid line, without the general parse.
    let bytes = token.as_bytes();
    if !bytes.is_empty() && bytes.len() < 19 && bytes.iter().all(u8::is_ascii_digit) {
        let n = bytes
            .iter()
            .fold(0usize, |n, &b| n * 10 + usize::from(b - b'0'));
        if let Some(index) = n.checked_sub(1) {
            return Ok(index);
        }
    }
    let error = |message: String| line_error(path, line, message);
    if let Ok(n) = token.parse::<usize>() {
        return match n.checked_sub(1) {
            Some(index) => Ok(index),
            None => Err(error(missing_node(0, node_count))),
        };
    }
    let digits = token.strip_prefix('+').unwrap_or(token);
    if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(error(format!(
            "node {digits} does not exist: the nodes file has {node_count} nodes (numbers start at 1)"
        )));
    }
    Err(error(match token.parse::<Real>() {
        Ok(_) if token.starts_with('-') => {
            format!("node number {token} is negative: node numbers start at 1")
        }
        Ok(v) if v.fract() != 0.0 => {
            format!("node number {token} is not a whole number: node numbers are 1, 2, 3, ...")
        }
        Ok(_) => format!(
            "node number {token} is written as a decimal: write it as a whole number, like 3"
        ),
        Err(_) => {
            format!("'{token}' is not a node number: node numbers are whole numbers starting at 1")
        }
    }))
}

/// "node n does not exist" for a 1-based node number.
fn missing_node(number: usize, node_count: usize) -> String {
    format!(
        "node {number} does not exist: the nodes file has {node_count} nodes (numbers start at 1)"
    )
}

/// The error for a problem [`check_members`] found, at the line of the member it names.
fn member_error(
    problem: MemberProblem,
    records: &[LinkRecord],
    node_count: usize,
    path: &Path,
) -> PaperFileError {
    let record = &records[problem.member()];
    let [a, b] = record.nodes.map(|n| n + 1);
    let message = match problem {
        MemberProblem::NodeOutOfRange { node, .. } => missing_node(node + 1, node_count),
        MemberProblem::SelfMember { node, .. } => format!(
            "the member joins node {} to itself: a member needs two different nodes",
            node + 1
        ),
        MemberProblem::ZeroLength { length, .. } => format!(
            "the member joins nodes {a} and {b}, which are at the same place (length {length:e} m): \
             move one of them in the nodes file, or merge them"
        ),
        MemberProblem::TooLarge { .. } => format!(
            "the member joins nodes {a} and {b}, but the coordinates are too large to square \
             (lengths overflow past 1e308): give coordinates in metres, below about 1e150"
        ),
        MemberProblem::Duplicate { first, .. } => format!(
            "the member joins nodes {a} and {b}, as line {} already does: remove one of the two lines \
             (to stiffen a link, give it a material with a larger area)",
            records[first].line
        ),
    };
    line_error(path, record.line, message)
}

fn read_text(path: &Path) -> Result<String, PaperFileError> {
    std::fs::read_to_string(path)
        .map_err(|e| file_error(path, format!("cannot read the file: {e}")))
}

pub(crate) fn line_error(path: &Path, line: usize, message: String) -> PaperFileError {
    PaperFileError::Line {
        path: path.to_path_buf(),
        line,
        message,
    }
}

fn file_error(path: &Path, message: String) -> PaperFileError {
    PaperFileError::File {
        path: path.to_path_buf(),
        message,
    }
}

fn invalid_input(message: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, message)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path() -> &'static Path {
        Path::new("body.txt")
    }

    /// The message of a `Line` error, after checking that it is on `line`.
    fn line_message(e: PaperFileError, line: usize) -> String {
        let text = e.to_string();
        match e {
            PaperFileError::Line { line: l, .. } => {
                assert_eq!(l, line, "{text}");
                assert!(text.starts_with(&format!("body.txt:{line}: ")), "{text}");
                text
            }
            PaperFileError::File { .. } => panic!("expected a line error, got {text}"),
        }
    }

    fn square() -> Vec<Vector3<Real>> {
        parse_nodes("0 0\n1 0\n1 1\n0 1\n", path()).unwrap().1
    }

    /// A fresh folder for one test's files.
    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("linkage-paper-files-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn nodes_with_comments_blank_lines_and_tabs() {
        let text = "# the paper's square\n\n0 0   # node 1\n1.5\t0\n  1.5 2e-1\n\n";
        let (dim, nodes) = parse_nodes(text, path()).unwrap();
        assert_eq!(dim, Dimension::Two);
        assert_eq!(
            nodes,
            vec![
                Vector3::new(0.0, 0.0, 0.0),
                Vector3::new(1.5, 0.0, 0.0),
                Vector3::new(1.5, 0.2, 0.0)
            ]
        );
        let (dim, nodes) = parse_nodes("\u{feff}1 2 3\r\n4 5 6\r\n", path()).unwrap();
        assert_eq!(dim, Dimension::Three);
        assert_eq!(nodes[1], Vector3::new(4.0, 5.0, 6.0));
    }

    #[test]
    fn nodes_line_with_wrong_column_count() {
        let e = parse_nodes("0 0\n1\n", path()).unwrap_err();
        let m = line_message(e, 2);
        assert!(
            m.contains("expected 2 or 3 coordinates") && m.contains("found 1"),
            "{m}"
        );
        let m = line_message(parse_nodes("1 2 3 4\n", path()).unwrap_err(), 1);
        assert!(m.contains("found 4"), "{m}");
    }

    #[test]
    fn nodes_mixing_2d_and_3d_lines() {
        let text = "0 0\n1 0\n\n# c\n1 1\n0 1\n0 1 2\n";
        let m = line_message(parse_nodes(text, path()).unwrap_err(), 7);
        assert!(
            m.contains("line 7 has 3 coordinates but line 1 has 2"),
            "{m}"
        );
    }

    #[test]
    fn nodes_non_number_and_non_finite() {
        let m = line_message(parse_nodes("0 0\n1 x1\n", path()).unwrap_err(), 2);
        assert!(m.contains("'x1' is not a number"), "{m}");
        for bad in ["NaN", "inf", "-infinity", "1e400"] {
            let m = line_message(
                parse_nodes(&format!("0 0\n1 {bad}\n"), path()).unwrap_err(),
                2,
            );
            assert!(
                m.contains(&format!("coordinate {bad} is not a finite number")),
                "{m}"
            );
        }
    }

    #[test]
    fn nodes_with_commas_say_so() {
        let m = line_message(parse_nodes("0 0\n1,0\n", path()).unwrap_err(), 2);
        assert!(m.contains("comma") && m.contains("spaces or tabs"), "{m}");
        // A comma inside a comment is fine.
        assert!(parse_nodes("0 0 # x, y\n", path()).is_ok());
    }

    #[test]
    fn empty_nodes_file_is_refused() {
        for text in ["", "\n\n", "# only a comment\n   \n"] {
            let e = parse_nodes(text, path()).unwrap_err();
            assert!(matches!(e, PaperFileError::File { .. }));
            let m = e.to_string();
            assert!(
                m.starts_with("body.txt: no nodes") && m.contains("`x y`"),
                "{m}"
            );
        }
    }

    #[test]
    fn links_with_materials_and_comments() {
        let text = "# square\n3 4\n1 2 steel # top\n\n1 3\n2 4 rubber\n";
        let links = parse_links(text, path(), &square()).unwrap();
        assert_eq!(
            links,
            vec![
                LinkRecord {
                    line: 2,
                    nodes: [2, 3],
                    material: None
                },
                LinkRecord {
                    line: 3,
                    nodes: [0, 1],
                    material: Some("steel".into())
                },
                LinkRecord {
                    line: 5,
                    nodes: [0, 2],
                    material: None
                },
                LinkRecord {
                    line: 6,
                    nodes: [1, 3],
                    material: Some("rubber".into())
                },
            ]
        );
    }

    #[test]
    fn links_wrong_column_count() {
        let m = line_message(parse_links("1 2\n3\n", path(), &square()).unwrap_err(), 2);
        assert!(
            m.contains("expected 2 node numbers") && m.contains("found 1"),
            "{m}"
        );
        let m = line_message(
            parse_links("1 2 steel extra\n", path(), &square()).unwrap_err(),
            1,
        );
        assert!(m.contains("found 4 columns"), "{m}");
    }

    #[test]
    fn links_node_beyond_the_count_or_zero() {
        let nodes: Vec<_> = (0..9).map(|i| Vector3::new(i as Real, 0.0, 0.0)).collect();
        let m = line_message(parse_links("1 2\n3 12\n", path(), &nodes).unwrap_err(), 2);
        assert!(
            m.contains("node 12 does not exist: the nodes file has 9 nodes (numbers start at 1)"),
            "{m}"
        );
        let m = line_message(parse_links("1 2\n\n0 3\n", path(), &nodes).unwrap_err(), 3);
        assert!(m.contains("node 0 does not exist"), "{m}");
        let m = line_message(
            parse_links("1 99999999999999999999999\n", path(), &nodes).unwrap_err(),
            1,
        );
        assert!(
            m.contains("node 99999999999999999999999 does not exist"),
            "{m}"
        );
    }

    #[test]
    fn links_negative_fractional_and_non_numbers() {
        let nodes = square();
        let m = line_message(parse_links("1 2\n-3 4\n", path(), &nodes).unwrap_err(), 2);
        assert!(m.contains("node number -3 is negative"), "{m}");
        let m = line_message(parse_links("2.5 4\n", path(), &nodes).unwrap_err(), 1);
        assert!(m.contains("node number 2.5 is not a whole number"), "{m}");
        let m = line_message(parse_links("3.0 4\n", path(), &nodes).unwrap_err(), 1);
        assert!(m.contains("node number 3.0 is written as a decimal"), "{m}");
        let m = line_message(parse_links("1 two\n", path(), &nodes).unwrap_err(), 1);
        assert!(m.contains("'two' is not a node number"), "{m}");
        let m = line_message(parse_links("1, 2\n", path(), &nodes).unwrap_err(), 1);
        assert!(m.contains("comma"), "{m}");
    }

    #[test]
    fn links_self_member() {
        let m = line_message(parse_links("1 2\n4 4\n", path(), &square()).unwrap_err(), 2);
        assert!(m.contains("joins node 4 to itself"), "{m}");
    }

    #[test]
    fn links_zero_length_member() {
        let nodes = parse_nodes("0 0\n1 0\n1 0\n", path()).unwrap().1;
        let m = line_message(
            parse_links("1 2\n1 3\n2 3\n", path(), &nodes).unwrap_err(),
            3,
        );
        assert!(
            m.contains("joins nodes 2 and 3, which are at the same place"),
            "{m}"
        );
    }

    #[test]
    fn links_duplicate_member_names_the_first_line() {
        let text = "1 2\n2 3\n# c\n\n3 4\n1 3\n2 4\n4 3 steel\n";
        let m = line_message(parse_links(text, path(), &square()).unwrap_err(), 8);
        assert!(
            m.contains("joins nodes 4 and 3, as line 5 already does"),
            "{m}"
        );
    }

    #[test]
    fn empty_links_file_is_refused() {
        let e = parse_links("# nothing\n", path(), &square()).unwrap_err();
        assert!(matches!(e, PaperFileError::File { .. }));
        assert!(e.to_string().contains("no members"), "{e}");
    }

    #[test]
    fn patches_parse_and_errors() {
        let patches = parse_patches("1 2 3 # one\n\n1 3 4\n", path(), 4).unwrap();
        assert_eq!(patches, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(parse_patches("", path(), 4).unwrap().is_empty());
        let m = line_message(parse_patches("1 2 3\n1 2\n", path(), 4).unwrap_err(), 2);
        assert!(
            m.contains("expected 3 node numbers") && m.contains("found 2"),
            "{m}"
        );
        let m = line_message(parse_patches("1 2 3\n1 2 12\n", path(), 9).unwrap_err(), 2);
        assert!(
            m.contains("node 12 does not exist: the nodes file has 9 nodes"),
            "{m}"
        );
        let m = line_message(parse_patches("0 2 3\n", path(), 9).unwrap_err(), 1);
        assert!(m.contains("node 0 does not exist"), "{m}");
        let m = line_message(parse_patches("1 2 3\n3 4 3\n", path(), 9).unwrap_err(), 2);
        assert!(m.contains("repeats node 3"), "{m}");
        let m = line_message(parse_patches("1 -2 3\n", path(), 9).unwrap_err(), 1);
        assert!(m.contains("negative"), "{m}");
        let m = line_message(parse_patches("1 2 3.5\n", path(), 9).unwrap_err(), 1);
        assert!(m.contains("not a whole number"), "{m}");
    }

    #[test]
    fn missing_file_names_the_path_and_the_io_error() {
        let dir = scratch("missing");
        let p = dir.join("nope.nodes");
        let e = read_nodes(&p).unwrap_err();
        let m = e.to_string();
        assert!(matches!(e, PaperFileError::File { .. }));
        assert!(
            m.contains("nope.nodes") && m.contains("cannot read the file"),
            "{m}"
        );
        assert!(read_links(&p, &square()).is_err());
        assert!(read_patches(&p, 3).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn nodes_round_trip_exactly() {
        let dir = scratch("nodes");
        let awkward = [
            0.1 + 0.2,
            -0.0,
            1e-300,
            5e-324,
            -1.7976931348623157e308,
            std::f64::consts::PI,
            123456789.125,
            1.0 / 3.0,
        ];
        let nodes3: Vec<Vector3<Real>> = awkward
            .iter()
            .zip(awkward.iter().rev())
            .map(|(&a, &b)| Vector3::new(a, b, a * 0.7))
            .collect();
        let p = dir.join("n3.nodes");
        write_nodes(&p, Dimension::Three, &nodes3).unwrap();
        let (dim, back) = read_nodes(&p).unwrap();
        assert_eq!(dim, Dimension::Three);
        let bits = |v: &[Vector3<Real>]| -> Vec<u64> {
            v.iter()
                .flat_map(|p| p.iter().map(|c| c.to_bits()).collect::<Vec<_>>())
                .collect()
        };
        assert_eq!(bits(&back), bits(&nodes3));

        let nodes2: Vec<Vector3<Real>> =
            nodes3.iter().map(|p| Vector3::new(p.x, p.y, 0.0)).collect();
        let p = dir.join("n2.nodes");
        write_nodes(&p, Dimension::Two, &nodes2).unwrap();
        let (dim, back) = read_nodes(&p).unwrap();
        assert_eq!(dim, Dimension::Two);
        assert_eq!(bits(&back), bits(&nodes2));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn nodes_that_would_not_read_back_are_not_written() {
        let dir = scratch("bad-nodes");
        let p = dir.join("x.nodes");
        let e =
            write_nodes(&p, Dimension::Three, &[Vector3::new(0.0, Real::NAN, 0.0)]).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("node 1"), "{e}");
        let e = write_nodes(
            &p,
            Dimension::Two,
            &[Vector3::zeros(), Vector3::new(0.0, 0.0, 1.0)],
        )
        .unwrap_err();
        assert!(e.to_string().contains("node 2 has z = 1.0"), "{e}");
        assert!(!p.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn links_and_patches_round_trip() {
        let dir = scratch("links");
        let nodes = square();
        let members = vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2], [1, 3]];
        let p = dir.join("a.links");
        write_links(&p, &members, None).unwrap();
        let back = read_links(&p, &nodes).unwrap();
        assert_eq!(back.iter().map(|r| r.nodes).collect::<Vec<_>>(), members);
        assert!(back.iter().all(|r| r.material.is_none()));
        assert_eq!(
            back.iter().map(|r| r.line).collect::<Vec<_>>(),
            (1..=6).collect::<Vec<_>>()
        );

        let names: Vec<String> = ["steel", "steel", "rubber", "steel", "diag_1", "diag-2"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        write_links(&p, &members, Some(&names)).unwrap();
        let back = read_links(&p, &nodes).unwrap();
        assert_eq!(back.iter().map(|r| r.nodes).collect::<Vec<_>>(), members);
        assert_eq!(
            back.into_iter()
                .map(|r| r.material.unwrap().to_string())
                .collect::<Vec<_>>(),
            names
        );

        let patches = vec![[0, 1, 2], [0, 2, 3]];
        let p = dir.join("a.patches");
        write_patches(&p, &patches).unwrap();
        assert_eq!(read_patches(&p, 4).unwrap(), patches);
        write_patches(&p, &[]).unwrap();
        assert!(read_patches(&p, 4).unwrap().is_empty());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn material_names_that_would_not_read_back_are_not_written() {
        let dir = scratch("bad-links");
        let p = dir.join("x.links");
        let members = [[0, 1], [1, 2]];
        let e = write_links(&p, &members, Some(&["a".to_string()])).unwrap_err();
        assert!(
            e.to_string().contains("1 material names for 2 members"),
            "{e}"
        );
        for bad in ["", "two words", "a#b", "a,b"] {
            let names = ["ok".to_string(), bad.to_string()];
            let e = write_links(&p, &members, Some(&names)).unwrap_err();
            assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
            assert!(e.to_string().contains("member 2"), "{e}");
        }
        assert!(!p.exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_generated_shell_round_trips_through_the_three_files() {
        let dir = scratch("shell");
        let g = crate::linkage::generators::cylindrical_shell(0.5, 2.0, 5, 9).unwrap();
        let (n, l, t) = (
            dir.join("s.nodes"),
            dir.join("s.links"),
            dir.join("s.patches"),
        );
        write_nodes(&n, g.dimension, &g.nodes).unwrap();
        write_links(&l, &g.members, None).unwrap();
        write_patches(&t, &g.patches).unwrap();
        let (dimension, nodes) = read_nodes(&n).unwrap();
        let members: Vec<[usize; 2]> = read_links(&l, &nodes)
            .unwrap()
            .into_iter()
            .map(|r| r.nodes)
            .collect();
        let patches = read_patches(&t, nodes.len()).unwrap();
        let back = crate::linkage::Geometry {
            dimension,
            nodes,
            members,
            patches,
        };
        assert_eq!(back, g);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
