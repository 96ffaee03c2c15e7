//! `[sweep]`: one scene file run many times with some of its values changed. The TOML tree is
//! expanded into variants before it is read as a [`crate::scene::spec::SceneSpec`], so a bad
//! key is named (with its line) before anything runs.

use crate::scene::SceneError;
use std::path::Path;
use toml::{Table, Value};

/// One variant of a scene: the values it sets and the scene text it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Variant {
    /// Each swept key (dotted path, as written in `[sweep]`) with this variant's value.
    pub values: Vec<(String, Value)>,
    /// The scene's TOML with the values set and `[sweep]` removed (the file's own text when the
    /// scene has no sweep).
    pub text: String,
}

/// How a sweep combines its keys' value lists.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepMode {
    /// Every combination; the last key varies fastest.
    Grid,
    /// The i-th value of every key together (all lists of one length).
    Zip,
}

/// The variants of scene `text` read from `path`: one (the text itself, no values) without a
/// `[sweep]`; otherwise one per combination, in order (k = 1 … n). Every swept key must name a
/// value written in the scene, and every value must have that value's type.
pub fn expand_sweep(text: &str, path: &Path) -> Result<Vec<Variant>, SceneError> {
    let mut table: Table = text
        .parse()
        .map_err(|e: toml::de::Error| SceneError::Parse {
            path: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
    let Some(sweep) = table.remove("sweep") else {
        return Ok(vec![Variant {
            values: Vec::new(),
            text: text.to_string(),
        }]);
    };
    let start = header_offset(text, "[sweep]");
    let at = |key: &str, message: String| SceneError::At {
        path: path.to_path_buf(),
        line: line_of_key(text, start, key),
        message: format!("[sweep] {message}"),
    };
    let Value::Table(sweep) = sweep else {
        return Err(at(
            "",
            "must be a table: write `[sweep]` with dotted keys under it".into(),
        ));
    };
    let mut mode = SweepMode::Grid;
    let mut keys: Vec<(String, Vec<Value>)> = Vec::new();
    for (key, value) in sweep {
        if key == "mode" {
            mode = match value.as_str() {
                Some("grid") => SweepMode::Grid,
                Some("zip") => SweepMode::Zip,
                _ => {
                    return Err(at(
                        "mode",
                        format!("mode = {value}: use \"grid\" (every combination, the default) or \"zip\" (the i-th values together)"),
                    ))
                }
            };
            continue;
        }
        let Value::Array(values) = value else {
            return Err(at(
                &key,
                format!("`{key}` = {value}: give a list of the values to run, e.g. `\"{key}\" = [{value}]`"),
            ));
        };
        if values.is_empty() {
            return Err(at(&key, format!("`{key}` = []: give at least one value")));
        }
        let current = find(&table, &key).map_err(|e| at(&key, format!("`{key}`: {e}")))?;
        for (i, v) in values.iter().enumerate() {
            if let Some(problem) = type_mismatch(current, v) {
                return Err(at(
                    &key,
                    format!(
                        "`{key}` value {} ({v}): {problem} (the scene has {current})",
                        i + 1
                    ),
                ));
            }
        }
        keys.push((key, values));
    }
    if keys.is_empty() {
        return Err(at(
            "",
            "has no keys to sweep: add e.g. `\"materials.steel.youngs_modulus\" = [70e9, 200e9]`"
                .into(),
        ));
    }
    let counts: Vec<usize> = match mode {
        SweepMode::Grid => keys.iter().map(|(_, v)| v.len()).collect(),
        SweepMode::Zip => vec![keys[0].1.len()],
    };
    if let Some(problem) = too_many_variants(&counts, text.len()) {
        return Err(at("", problem));
    }
    let combinations = match mode {
        SweepMode::Grid => grid(&keys),
        SweepMode::Zip => {
            let n = keys[0].1.len();
            if let Some((key, values)) = keys.iter().find(|(_, v)| v.len() != n) {
                return Err(at(
                    key,
                    format!(
                        "mode = \"zip\" takes the i-th values together, but `{}` has {n} values and `{key}` has {}: give every key as many",
                        keys[0].0,
                        values.len()
                    ),
                ));
            }
            (0..n).map(|i| vec![i; keys.len()]).collect()
        }
    };
    let mut variants = Vec::with_capacity(combinations.len());
    for picks in combinations {
        let mut scene = table.clone();
        let mut values = Vec::with_capacity(keys.len());
        for ((key, list), &i) in keys.iter().zip(&picks) {
            let slot = find_mut(&mut scene, key).map_err(|e| at(key, format!("`{key}`: {e}")))?;
            *slot = list[i].clone();
            values.push((key.clone(), list[i].clone()));
        }
        let text = toml::to_string(&scene).map_err(|e| SceneError::Parse {
            path: path.to_path_buf(),
            message: format!("[sweep]: cannot write a variant as TOML: {e}"),
        })?;
        variants.push(Variant { values, text });
    }
    Ok(variants)
}

/// Scene `text` (read from `path`) with each dotted key of `values` set to its value: the
/// variant a `[sweep]` giving each of these keys this one value makes (the same text, with
/// `[sweep]` removed), checked as a sweep is: every key must name a value written in the scene,
/// and every value must have that value's type. The Python package's `Scene.load(values=)`.
pub fn with_values(
    text: &str,
    path: &Path,
    values: &[(String, Value)],
) -> Result<Variant, SceneError> {
    let mut table: Table = text
        .parse()
        .map_err(|e: toml::de::Error| SceneError::Parse {
            path: path.to_path_buf(),
            message: e.to_string().trim_end().to_string(),
        })?;
    table.remove("sweep");
    let fail = |key: &str, message: String| SceneError::Parse {
        path: path.to_path_buf(),
        message: format!("values: `{key}`: {message}"),
    };
    for (key, value) in values {
        let current = find(&table, key).map_err(|e| fail(key, e))?;
        if let Some(problem) = type_mismatch(current, value) {
            return Err(fail(
                key,
                format!("{value}: {problem} (the scene has {current})"),
            ));
        }
        *find_mut(&mut table, key).map_err(|e| fail(key, e))? = value.clone();
    }
    let text = toml::to_string(&table).map_err(|e| SceneError::Parse {
        path: path.to_path_buf(),
        message: format!("values: cannot write the scene as TOML: {e}"),
    })?;
    Ok(Variant {
        values: values.to_vec(),
        text,
    })
}

/// Variants a sweep may make: each is a scene run into its own folder and a row of
/// `batch.csv`, and its scene text is held in memory while the batch is planned.
pub const MAX_VARIANTS: u64 = 1_000_000;

/// Bytes a variant takes besides its scene text while the batch is planned (its job, values and
/// folder name), and at least on disk once run (`summary.json`, the model and step 0).
pub const VARIANT_OVERHEAD_BYTES: u64 = 4096;

/// Why a sweep of `counts` values per key (a grid: their product; zip: one count) over a scene of
/// `text_bytes` cannot be planned: more than [`MAX_VARIANTS`] variants, or their scene texts
/// more than the machine's available memory; `None` when it fits. Checked before any variant is
/// made, with the memory and disk estimates in the message.
pub fn too_many_variants(counts: &[usize], text_bytes: usize) -> Option<String> {
    let n = counts
        .iter()
        .fold(1u128, |n, &c| n.saturating_mul(c as u128));
    let each = text_bytes as u64 + VARIANT_OVERHEAD_BYTES;
    let memory = n as f64 * each as f64;
    let available = crate::scene::fits_machine::available_memory();
    let over_memory = available.is_some_and(|have| memory > have as f64);
    if n <= MAX_VARIANTS as u128 && !over_memory {
        return None;
    }
    let shape = counts
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(" × ");
    let have = available.map_or_else(String::new, |b| {
        format!(" (the machine has {:.1} GB available)", b as f64 / 1e9)
    });
    Some(format!(
        "makes {n} variants ({shape} values): planning them would take about {:.3e} GB of memory{have} and their folders at least {:.3e} GB of disk; at most {MAX_VARIANTS} variants (and their scenes within the memory): sweep fewer values, or split the sweep into several scenes",
        memory / 1e9,
        n as f64 * VARIANT_OVERHEAD_BYTES as f64 / 1e9,
    ))
}

/// Every combination of one value per key, the last key fastest.
fn grid(keys: &[(String, Vec<Value>)]) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for (_, values) in keys {
        out = out
            .into_iter()
            .flat_map(|picks| {
                (0..values.len()).map(move |i| {
                    let mut p = picks.clone();
                    p.push(i);
                    p
                })
            })
            .collect();
    }
    out
}

/// The step of a path at `value`: a key of a table, a `name` or 1-based position in an array.
fn step<'a>(value: &'a Value, segment: &str, walked: &str) -> Result<&'a Value, String> {
    match value {
        Value::Table(t) => t
            .get(segment)
            .ok_or_else(|| missing_key(t, segment, walked)),
        Value::Array(a) => a
            .get(position(a, segment, walked)?)
            .ok_or_else(|| unreachable_position(a, segment, walked)),
        _ => Err(format!("`{walked}` is {value}, not a table or a list")),
    }
}

/// The index in array `a` that `segment` names: the table whose `name` it is, else a 1-based
/// position.
fn position(a: &[Value], segment: &str, walked: &str) -> Result<usize, String> {
    if let Some(i) = a
        .iter()
        .position(|v| v.get("name").and_then(Value::as_str) == Some(segment))
    {
        return Ok(i);
    }
    match segment.parse::<usize>() {
        Ok(k) if k >= 1 && k <= a.len() => Ok(k - 1),
        _ => Err(unreachable_position(a, segment, walked)),
    }
}

fn unreachable_position(a: &[Value], segment: &str, walked: &str) -> String {
    let names: Vec<&str> = a
        .iter()
        .filter_map(|v| v.get("name").and_then(Value::as_str))
        .collect();
    if names.is_empty() {
        format!(
            "`{walked}` has {} entr{} and no entry '{segment}': number them from 1",
            a.len(),
            if a.len() == 1 { "y" } else { "ies" }
        )
    } else {
        format!(
            "`{walked}` has no entry named '{segment}' (names: {})",
            names.join(", ")
        )
    }
}

fn missing_key(t: &Table, segment: &str, walked: &str) -> String {
    let keys: Vec<&str> = t.keys().map(String::as_str).collect();
    let place = if walked.is_empty() {
        "the scene".to_string()
    } else {
        format!("`{walked}`")
    };
    format!(
        "{place} has no key `{segment}` (it has: {}); a swept value must be written in the scene",
        keys.join(", ")
    )
}

/// The value at dotted `key` of `table`.
fn find<'a>(table: &'a Table, key: &str) -> Result<&'a Value, String> {
    let mut segments = key.split('.');
    let first = segments.next().unwrap_or_default();
    let mut value = table
        .get(first)
        .ok_or_else(|| missing_key(table, first, ""))?;
    let mut walked = first.to_string();
    for segment in segments {
        value = step(value, segment, &walked)?;
        walked = format!("{walked}.{segment}");
    }
    Ok(value)
}

/// The value at dotted `key` of `table`, to replace it ([`find`] has checked it is there).
fn find_mut<'a>(table: &'a mut Table, key: &str) -> Result<&'a mut Value, String> {
    let mut segments = key.split('.');
    let first = segments.next().unwrap_or_default();
    let missing = missing_key(table, first, "");
    let mut value = table.get_mut(first).ok_or(missing)?;
    for segment in segments {
        value = match value {
            Value::Table(t) => t
                .get_mut(segment)
                .ok_or_else(|| format!("no key `{segment}`"))?,
            Value::Array(a) => {
                let i = position(a, segment, key)?;
                &mut a[i]
            }
            _ => return Err(format!("no `{segment}`")),
        };
    }
    Ok(value)
}

/// Why `new` cannot replace `current`, if it cannot: a different kind of value (an integer may
/// replace a float; lists are compared by their first elements, tables by kind).
fn type_mismatch(current: &Value, new: &Value) -> Option<String> {
    let ok = match (current, new) {
        (Value::Float(_), Value::Float(_) | Value::Integer(_)) => true,
        (Value::Array(a), Value::Array(b)) => match (a.first(), b.first()) {
            (Some(x), Some(y)) => return type_mismatch(x, y).map(|p| format!("in the list: {p}")),
            _ => true,
        },
        (a, b) => std::mem::discriminant(a) == std::mem::discriminant(b),
    };
    (!ok).then(|| format!("a {} cannot replace a {}", kind(new), kind(current)))
}

/// The TOML name of a value's type.
fn kind(v: &Value) -> &'static str {
    match v {
        Value::String(_) => "string",
        Value::Integer(_) => "integer",
        Value::Float(_) => "float",
        Value::Boolean(_) => "boolean",
        Value::Datetime(_) => "date",
        Value::Array(_) => "list",
        Value::Table(_) => "table",
    }
}

/// Byte offset of the line starting with `header` (0 without one).
fn header_offset(text: &str, header: &str) -> usize {
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        if line.trim_start().starts_with(header) {
            return offset;
        }
        offset += line.len();
    }
    0
}

/// The 1-based line of `key` in the table starting at byte `start` of `text` (the table's own
/// line when the key is not found there).
fn line_of_key(text: &str, start: usize, key: &str) -> usize {
    let first = text[..start.min(text.len())].matches('\n').count() + 1;
    if key.is_empty() {
        return first;
    }
    for (k, raw) in text[start.min(text.len())..].lines().enumerate() {
        let line = raw.trim_start();
        if k > 0 && line.starts_with('[') {
            break;
        }
        if let Some((name, _)) = line.split_once('=') {
            if name.trim().trim_matches('"').trim_matches('\'') == key {
                return first + k;
            }
        }
    }
    first
}

/// A swept value as a table cell: strings without quotes, everything else as TOML writes it.
pub fn value_cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"name = "s"
steps = 1

[[materials]]
name = "steel"
youngs_modulus = 200e9

[[bodies]]
name = "beam"

[[bodies.loads]]
nodes = [2]
force = [1.0, 2.0]

[sweep]
"bodies.beam.loads.1.force.2" = [5, 6.5]
"materials.steel.youngs_modulus" = [1e9]
"#;

    #[test]
    fn values_give_the_text_of_the_sweep_variant_with_those_values() {
        let variants = expand_sweep(SCENE, Path::new("s.toml")).unwrap();
        let values = vec![
            ("bodies.beam.loads.1.force.2".to_string(), Value::Float(6.5)),
            (
                "materials.steel.youngs_modulus".to_string(),
                Value::Float(1e9),
            ),
        ];
        let set = with_values(SCENE, Path::new("s.toml"), &values).unwrap();
        assert_eq!(set.text, variants[1].text);
        assert_eq!(set.values, values);
        let wrong = [(
            "materials.steel.youngs_modulus".to_string(),
            Value::String("x".into()),
        )];
        let e = with_values(SCENE, Path::new("s.toml"), &wrong)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("s.toml: values: `materials.steel.youngs_modulus`"),
            "{e}"
        );
        assert!(e.contains("a string cannot replace a float"), "{e}");
        let missing = [("materials.alu.area".to_string(), Value::Float(1.0))];
        let e = with_values(SCENE, Path::new("s.toml"), &missing)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no entry named 'alu'"), "{e}");
    }

    #[test]
    fn paths_walk_names_positions_and_list_elements() {
        let variants = expand_sweep(SCENE, Path::new("s.toml")).unwrap();
        assert_eq!(variants.len(), 2);
        let second: Table = variants[1].text.parse().unwrap();
        let body = &second["bodies"][0];
        assert_eq!(body["loads"][0]["force"][1].as_float(), Some(6.5));
        // An integer may replace a float.
        let first: Table = variants[0].text.parse().unwrap();
        assert_eq!(
            first["bodies"][0]["loads"][0]["force"][1].as_integer(),
            Some(5)
        );
        assert_eq!(
            second["materials"][0]["youngs_modulus"].as_float(),
            Some(1e9)
        );
        assert!(!second.contains_key("sweep"));
        assert_eq!(
            variants[1].values[0],
            ("bodies.beam.loads.1.force.2".to_string(), Value::Float(6.5))
        );
    }

    #[test]
    fn a_scene_without_sweep_is_one_variant_of_its_own_text() {
        let text = "name = \"s\"\n# a comment kept\n";
        let v = expand_sweep(text, Path::new("s.toml")).unwrap();
        assert_eq!(
            v,
            vec![Variant {
                values: vec![],
                text: text.to_string()
            }]
        );
    }

    #[test]
    fn a_grid_of_a_million_by_a_million_is_refused_with_its_estimates() {
        let problem = too_many_variants(&[1_000_000, 1_000_000], 1000).unwrap();
        // 1e12 variants × (1000 + 4096) B = 5.096e15 B = 5.096e6 GB; on disk 4.096e6 GB.
        for part in [
            "1000000000000 variants",
            "1000000 × 1000000",
            "5.096e6 GB of memory",
            "4.096e6 GB of disk",
            "at most 1000000",
        ] {
            assert!(problem.contains(part), "{part:?} in {problem}");
        }
        assert!(too_many_variants(&[100, 100], 1000).is_none());
        assert!(too_many_variants(&[1000, 1001], 1000).is_some());
        assert!(too_many_variants(&[usize::MAX, usize::MAX, usize::MAX], 10).is_some());
    }

    #[test]
    fn a_grid_has_every_combination_the_last_key_fastest() {
        let keys = vec![
            ("a".to_string(), vec![Value::Integer(1), Value::Integer(2)]),
            ("b".to_string(), vec![Value::Integer(1); 3]),
        ];
        let g = grid(&keys);
        assert_eq!(g.len(), 6);
        assert_eq!(g[..4], [vec![0, 0], vec![0, 1], vec![0, 2], vec![1, 0]]);
    }
}
