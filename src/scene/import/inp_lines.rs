//! The keyword blocks of an Abaqus/CalculiX input file: `*INCLUDE`s followed, `**` comments
//! dropped, keyword lines split into a name and parameters, data lines into fields (a line
//! ending with a comma continues on the next).

use crate::scene::import::ModelFileError;
use std::path::{Path, PathBuf};

/// Where a line comes from: its file and 1-based line.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Place {
    /// The file (the main file or an `*INCLUDE`d one).
    pub(crate) path: PathBuf,
    /// 1-based line.
    pub(crate) line: usize,
}

impl Place {
    /// An error at this place.
    pub(crate) fn error(&self, message: impl Into<String>) -> ModelFileError {
        ModelFileError::at(&self.path, self.line, message)
    }

    /// `file:line`, for warnings.
    pub(crate) fn describe(&self) -> String {
        format!("{}:{}", self.path.display(), self.line)
    }
}

/// One keyword with its parameters and data lines.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Card {
    /// The keyword, upper case, single-spaced, without `*`: `SOLID SECTION`.
    pub(crate) keyword: String,
    /// Parameters, names upper case: `("ELSET", Some("TRUSS"))`, `("GENERATE", None)`.
    pub(crate) params: Vec<(String, Option<String>)>,
    /// The keyword line.
    pub(crate) place: Place,
    /// Data lines: their place and comma-separated fields, trimmed (empty fields dropped at
    /// the end of a line).
    pub(crate) data: Vec<(Place, Vec<String>)>,
}

impl Card {
    /// The value of parameter `name` (upper case).
    pub(crate) fn param(&self, name: &str) -> Option<&str> {
        self.params
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, v)| v.as_deref())
    }

    /// Whether parameter `name` is given (with or without a value).
    pub(crate) fn has(&self, name: &str) -> bool {
        self.params.iter().any(|(n, _)| n == name)
    }

    /// The value of a parameter the keyword needs, or an error saying so.
    pub(crate) fn required(&self, name: &str) -> Result<&str, ModelFileError> {
        self.param(name).filter(|v| !v.is_empty()).ok_or_else(|| {
            self.place.error(format!(
                "*{} needs {name}=...: add it to the keyword line",
                self.keyword
            ))
        })
    }
}

/// How deep `*INCLUDE`s may nest (a file including itself would never end).
const MAX_INCLUDE_DEPTH: usize = 16;

/// The cards of the input file `path`, with its `*INCLUDE, INPUT=...` files (relative to the
/// file that includes them) read in their place.
pub(crate) fn read_cards(path: &Path) -> Result<Vec<Card>, ModelFileError> {
    let mut cards = Vec::new();
    read_into(path, &mut cards, 0, None)?;
    Ok(cards)
}

fn read_into(
    path: &Path,
    cards: &mut Vec<Card>,
    depth: usize,
    from: Option<&Place>,
) -> Result<(), ModelFileError> {
    let text = std::fs::read(path).map_err(|e| match from {
        Some(place) => place.error(format!(
            "*INCLUDE: cannot read {}: {e} (INPUT= is relative to the including file's folder)",
            path.display()
        )),
        None => ModelFileError::at(path, 0, format!("cannot read the input file: {e}")),
    })?;
    let text = String::from_utf8_lossy(&text);
    let folder = path.parent().unwrap_or(Path::new("."));
    // A data line ending with a comma continues on the next line.
    let mut pending: Option<(Place, String)> = None;
    for (k, raw) in text.lines().enumerate() {
        let place = Place {
            path: path.to_path_buf(),
            line: k + 1,
        };
        let line = raw.trim();
        if line.is_empty() || line.starts_with("**") {
            continue;
        }
        if let Some(keyword_line) = line.strip_prefix('*') {
            if let Some((p, _)) = pending.take() {
                return Err(p.error(
                    "this data line ends with a comma but no data line follows: remove the comma or add the rest",
                ));
            }
            let card = parse_keyword(keyword_line, place.clone())?;
            if card.keyword == "INCLUDE" {
                if depth >= MAX_INCLUDE_DEPTH {
                    return Err(place.error(format!(
                        "*INCLUDEs nest deeper than {MAX_INCLUDE_DEPTH} files: does a file include itself?"
                    )));
                }
                let input = card.required("INPUT")?;
                let input = input.trim_matches(|c| c == '"' || c == '\'');
                read_into(&folder.join(input), cards, depth + 1, Some(&place))?;
            } else {
                cards.push(card);
            }
            continue;
        }
        let (place, line) = match pending.take() {
            Some((p, before)) => (p, format!("{before}{line}")),
            None => (place, line.to_string()),
        };
        if line.ends_with(',') {
            pending = Some((place, line));
            continue;
        }
        let Some(card) = cards.last_mut() else {
            return Err(place.error(
                "a data line before any *KEYWORD: an input file begins with a keyword such as *HEADING or *NODE",
            ));
        };
        let mut fields: Vec<String> = line.split(',').map(|f| f.trim().to_string()).collect();
        while fields.last().is_some_and(|f| f.is_empty()) {
            fields.pop();
        }
        card.data.push((place, fields));
    }
    if let Some((p, _)) = pending {
        return Err(p.error(
            "this data line ends with a comma but the file ends: remove the comma or add the rest",
        ));
    }
    Ok(())
}

/// `KEYWORD, NAME=VALUE, FLAG` (after the `*`).
fn parse_keyword(text: &str, place: Place) -> Result<Card, ModelFileError> {
    let mut parts = text.split(',');
    let keyword = parts
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .to_uppercase();
    if keyword.is_empty() {
        return Err(place.error("a `*` without a keyword: write *NODE, *ELEMENT, ..."));
    }
    let params = parts
        .map(str::trim)
        .filter(|p| !p.is_empty())
        .map(|p| match p.split_once('=') {
            Some((n, v)) => (n.trim().to_uppercase(), Some(v.trim().to_string())),
            None => (p.to_uppercase(), None),
        })
        .collect();
    Ok(Card {
        keyword,
        params,
        place,
        data: Vec::new(),
    })
}
