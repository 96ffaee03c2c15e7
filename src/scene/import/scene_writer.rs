//! `linkage import FILE --out DIR`: what a model file gives, written as the paper's files and
//! a scene, so that a user sees and edits what was read.
//!
//! - an `.inp` file: `DIR/<stem>.toml` with its materials, supports (by node lists) and loads,
//!   a runnable scene;
//! - an `.msh` file: the paper's files and `DIR/<stem>.toml` with the body and its groups as
//!   commented supports (a mesh has no material or supports: fill them in);
//! - a scene (`.toml`): every body with a `model` rewritten as paper files, its `group =`
//!   selectors as node lists and an INP's materials, supports and loads as scene entries;
//!   relative file names of the other entries made absolute. The written scene runs as the
//!   original does.

use crate::linkage::Dimension;
use crate::scene::import::{find_group, read_model, ImportedModel, ModelFileError};
use crate::scene::paper_files::{write_links, write_nodes, write_patches};
use crate::Real;
use nalgebra::Vector3;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// Why `linkage import` cannot write its files.
#[derive(Debug, thiserror::Error)]
pub enum ImportError {
    /// A problem in the model file.
    #[error(transparent)]
    Model(#[from] ModelFileError),
    /// A problem in the scene file given (or a model that cannot be written as a scene).
    #[error("{}: {message}", .path.display())]
    Scene {
        /// The scene or model file.
        path: PathBuf,
        /// What is wrong and what to do.
        message: String,
    },
    /// A file cannot be written.
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// What `linkage import` wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedScene {
    /// The scene file written.
    pub scene: PathBuf,
    /// Every file written (the paper's files, then the scene).
    pub files: Vec<PathBuf>,
    /// What the model files held but the scene does not use, with file and line.
    pub warnings: Vec<String>,
    /// Whether the scene runs as written (an MSH file alone needs a material and supports).
    pub complete: bool,
}

/// Write what `input` (an `.msh`, `.inp` or scene `.toml` file) gives into the folder `out`
/// (created if missing).
pub fn import_file(input: &Path, out: &Path) -> Result<ImportedScene, ImportError> {
    std::fs::create_dir_all(out).map_err(|source| ImportError::Write {
        path: out.to_path_buf(),
        source,
    })?;
    let extension = input
        .extension()
        .map(|e| e.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    if extension == "toml" {
        return import_scene(input, out);
    }
    let model = read_model(input)?;
    let stem = file_stem(input);
    let mut files = write_paper_files(&model, out, &stem, input)?;
    let (text, complete) = scene_of_model(&model, &stem, input)?;
    let scene = out.join(format!("{stem}.toml"));
    write_text(&scene, &text)?;
    files.push(scene.clone());
    Ok(ImportedScene {
        scene,
        files,
        warnings: model.warnings,
        complete,
    })
}

/// A name for files and scenes from a path: its stem with characters other than letters,
/// digits, `_`, `-` and `.` turned to `_`.
fn file_stem(path: &Path) -> String {
    let stem = path
        .file_stem()
        .map_or("model".into(), |s| s.to_string_lossy().into_owned());
    let stem: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "_-.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    match stem.trim_start_matches('.') {
        "" => "model".to_string(),
        s => s.to_string(),
    }
}

fn write_text(path: &Path, text: &str) -> Result<(), ImportError> {
    crate::scene::atomic_file::write_atomically(path, text.as_bytes()).map_err(|source| {
        ImportError::Write {
            path: path.to_path_buf(),
            source,
        }
    })
}

/// The names of each member's material in a links file: the model's, or `None` when some
/// member has none (then the scene's `material` names it).
fn member_names(model: &ImportedModel) -> Option<Vec<String>> {
    if model.member_materials.is_empty() || model.member_materials.iter().any(Option::is_none) {
        return None;
    }
    Some(
        model
            .member_materials
            .iter()
            .map(|m| model.materials[m.unwrap_or(0)].name.clone())
            .collect(),
    )
}

/// `DIR/<stem>.nodes`, `.links` (a material column when the model names materials) and, with
/// patches, `.patches`.
fn write_paper_files(
    model: &ImportedModel,
    out: &Path,
    stem: &str,
    source: &Path,
) -> Result<Vec<PathBuf>, ImportError> {
    let g = &model.geometry;
    let file = |ext: &str| out.join(format!("{stem}.{ext}"));
    let failed = |path: PathBuf| move |source| ImportError::Write { path, source };
    let names = member_names(model);
    write_nodes(&file("nodes"), g.dimension, &g.nodes).map_err(failed(file("nodes")))?;
    write_links(&file("links"), &g.members, names.as_deref()).map_err(|e| {
        if e.kind() == std::io::ErrorKind::InvalidInput {
            ImportError::Scene {
                path: source.to_path_buf(),
                message: format!("the model's materials cannot be written in a links file: {e}"),
            }
        } else {
            failed(file("links"))(e)
        }
    })?;
    let mut files = vec![file("nodes"), file("links")];
    if !g.patches.is_empty() {
        write_patches(&file("patches"), &g.patches).map_err(failed(file("patches")))?;
        files.push(file("patches"));
    }
    Ok(files)
}

/// A TOML array of 1-based node numbers.
fn node_list(nodes: &[usize]) -> String {
    let numbers: Vec<String> = nodes.iter().map(|n| (n + 1).to_string()).collect();
    format!("[{}]", numbers.join(", "))
}

/// A TOML array of `d` numbers, each in the shortest form that reads back the same.
fn numbers(v: &Vector3<Real>, d: usize) -> String {
    let parts: Vec<String> = (0..d).map(|k| format!("{:?}", v[k])).collect();
    format!("[{}]", parts.join(", "))
}

/// The directions a support holds, as a TOML array.
fn directions(fixed: &[bool; 3], d: usize) -> String {
    let names: Vec<String> = (0..d)
        .filter(|&k| fixed[k])
        .map(|k| format!("{:?}", ["x", "y", "z"][k]))
        .collect();
    format!("[{}]", names.join(", "))
}

/// The model's supports and loads as `[[bodies.supports]]` and `[[bodies.loads]]` text, nodes
/// with the same directions and values (the same force) in one entry.
fn supports_and_loads(model: &ImportedModel) -> String {
    let d = model.geometry.dimension.dofs_per_node();
    let mut text = String::new();
    // Nodes held alike: directions, displacement, nodes.
    let mut kinds: Vec<([bool; 3], Vector3<Real>, Vec<usize>)> = Vec::new();
    for s in &model.supports {
        match kinds
            .iter_mut()
            .find(|(f, u, _)| *f == s.fixed && *u == s.displacement)
        {
            Some((_, _, nodes)) => nodes.push(s.node),
            None => kinds.push((s.fixed, s.displacement, vec![s.node])),
        }
    }
    for (fixed, displacement, nodes) in &kinds {
        let _ = writeln!(text, "\n[[bodies.supports]]\nnodes = {}", node_list(nodes));
        let _ = writeln!(text, "fix = {}", directions(fixed, d));
        if *displacement != Vector3::zeros() {
            let _ = writeln!(text, "displacement = {}", numbers(displacement, d));
        }
    }
    let mut forces: Vec<(Vector3<Real>, Vec<usize>)> = Vec::new();
    for (node, force) in &model.loads {
        match forces.iter_mut().find(|(f, _)| f == force) {
            Some((_, nodes)) => nodes.push(*node),
            None => forces.push((*force, vec![*node])),
        }
    }
    for (force, nodes) in &forces {
        let _ = writeln!(
            text,
            "\n[[bodies.loads]]\nnodes = {}\nforce = {}",
            node_list(nodes),
            numbers(force, d)
        );
    }
    text
}

/// The scene text of a model file read alone, and whether it runs as written.
fn scene_of_model(
    model: &ImportedModel,
    stem: &str,
    source: &Path,
) -> Result<(String, bool), ImportError> {
    let mut text = format!(
        "# Written by `linkage import {}`: the body as the paper's files.\nname = \"{stem}\"\nsteps = 1\n",
        source.display()
    );
    let names = member_names(model);
    for m in &model.materials {
        let _ = write!(
            text,
            "\n[[materials]]\nname = \"{}\"\nyoungs_modulus = {:?}\narea = {:?}\n",
            m.name, m.youngs_modulus, m.area
        );
        if let Some(rho) = m.density {
            let _ = writeln!(text, "density = {rho:?}");
        }
    }
    let complete = names.is_some() && !model.supports.is_empty();
    if names.is_none() {
        if let (Some(why), false) = (&model.unassigned, model.materials.is_empty()) {
            return Err(ImportError::Scene {
                path: source.to_path_buf(),
                message: why.clone(),
            });
        }
        text.push_str(
            "\n# The model file gives no material: give the members' here (Pa, m²).\n[[materials]]\nname = \"material\"\n# youngs_modulus = 200e9\n# area = 1e-4\n",
        );
    }
    let _ = write!(
        text,
        "\n[[bodies]]\nname = \"{stem}\"\nnodes = \"{stem}.nodes\"\nlinks = \"{stem}.links\"\n"
    );
    if !model.geometry.patches.is_empty() {
        let _ = writeln!(text, "patches = \"{stem}.patches\"");
    }
    if names.is_none() {
        text.push_str("material = \"material\"\n");
    }
    text.push_str(&supports_and_loads(model));
    if !model.groups.is_empty() {
        text.push_str(
            "\n# The model file's groups as node lists, to support or load (uncomment and edit).\n",
        );
        for g in &model.groups {
            let fix = match model.geometry.dimension {
                Dimension::Two => "[\"x\", \"y\"]",
                Dimension::Three => "[\"x\", \"y\", \"z\"]",
            };
            let _ = writeln!(
                text,
                "# group {:?}:\n# [[bodies.supports]]\n# nodes = {}\n# fix = {fix}",
                g.name,
                node_list(&g.nodes)
            );
        }
    }
    Ok((text, complete))
}

/// The scene at `input` with each `model` body rewritten as paper files in `out`.
fn import_scene(input: &Path, out: &Path) -> Result<ImportedScene, ImportError> {
    let fail = |message: String| ImportError::Scene {
        path: input.to_path_buf(),
        message,
    };
    let text = std::fs::read_to_string(input)
        .map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    let mut scene: Table = text
        .parse()
        .map_err(|e: toml::de::Error| fail(e.to_string().trim_end().to_string()))?;
    let folder = input.parent().unwrap_or(Path::new("."));
    let folder = std::fs::canonicalize(if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    })
    .map_err(|e| fail(format!("cannot resolve the scene's folder: {e}")))?;
    absolute_paths(&mut scene, &folder);
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    let mut new_materials: Vec<Value> = Vec::new();
    let scene_materials: Vec<String> = scene
        .get("materials")
        .and_then(Value::as_array)
        .map(|a| {
            a.iter()
                .filter_map(|m| m.get("name").and_then(Value::as_str).map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let mut modelled = 0;
    if let Some(Value::Array(bodies)) = scene.get_mut("bodies") {
        for body in bodies.iter_mut() {
            let Some(table) = body.as_table_mut() else {
                continue;
            };
            let Some(Value::String(file)) = table.remove("model") else {
                continue;
            };
            modelled += 1;
            let name = table
                .get("name")
                .and_then(Value::as_str)
                .unwrap_or("body")
                .to_string();
            let path = folder.join(&file);
            let model = read_model(&path)?;
            let stem = file_stem(Path::new(&format!("{name}.x")));
            let own = !table.contains_key("material") && !model.materials.is_empty();
            let mut for_files = model.clone();
            if !own {
                for_files.member_materials.clear();
            }
            files.extend(write_paper_files(&for_files, out, &stem, &path)?);
            table.insert("nodes".into(), Value::String(format!("{stem}.nodes")));
            table.insert("links".into(), Value::String(format!("{stem}.links")));
            if !model.geometry.patches.is_empty() {
                table.insert("patches".into(), Value::String(format!("{stem}.patches")));
            }
            if own {
                if let Some(why) = &model.unassigned {
                    return Err(fail(format!("body '{name}': {why}")));
                }
                for m in &model.materials {
                    if scene_materials.contains(&m.name) {
                        return Err(fail(format!(
                            "body '{name}': the model defines material '{}', as does a [[materials]] entry: rename one",
                            m.name
                        )));
                    }
                    let mut entry = Table::new();
                    entry.insert("name".into(), Value::String(m.name.clone()));
                    entry.insert("youngs_modulus".into(), Value::Float(m.youngs_modulus));
                    entry.insert("area".into(), Value::Float(m.area));
                    if let Some(rho) = m.density {
                        entry.insert("density".into(), Value::Float(rho));
                    }
                    new_materials.push(Value::Table(entry));
                }
            }
            for key in ["supports", "loads", "pressures"] {
                if let Some(Value::Array(entries)) = table.get_mut(key) {
                    for entry in entries.iter_mut().filter_map(Value::as_table_mut) {
                        let Some(Value::String(group)) = entry.remove("group") else {
                            continue;
                        };
                        let g = find_group(&model.groups, &group).ok_or_else(|| {
                            fail(format!(
                                "body '{name}': `group` = {group:?} is not a group of {file}"
                            ))
                        })?;
                        let list = g.nodes.iter().map(|&n| Value::Integer(n as i64 + 1));
                        entry.insert("nodes".into(), Value::Array(list.collect()));
                    }
                }
            }
            prepend_model_entries(table, &model);
            warnings.extend(model.warnings.iter().map(|w| format!("body '{name}': {w}")));
        }
    }
    if modelled == 0 {
        return Err(fail(
            "no [[bodies]] entry has `model`: give a scene whose bodies read .msh or .inp files, or the model file itself".to_string(),
        ));
    }
    if !new_materials.is_empty() {
        let list = scene
            .entry("materials")
            .or_insert_with(|| Value::Array(Vec::new()));
        if let Value::Array(a) = list {
            a.extend(new_materials);
        }
    }
    let written =
        toml::to_string(&scene).map_err(|e| fail(format!("cannot write the scene: {e}")))?;
    let path = out.join(format!("{}.toml", file_stem(input)));
    let header = format!(
        "# Written by `linkage import {}`: its model files as the paper's files.\n",
        input.display()
    );
    write_text(&path, &format!("{header}{written}"))?;
    files.push(path.clone());
    Ok(ImportedScene {
        scene: path,
        files,
        warnings,
        complete: true,
    })
}

/// An INP model's supports and loads as the first `supports` and `loads` entries of `table`.
fn prepend_model_entries(table: &mut Table, model: &ImportedModel) {
    if model.supports.is_empty() && model.loads.is_empty() {
        return;
    }
    let text = supports_and_loads(model);
    // The same entries `scene_of_model` writes, read back as tables.
    let Ok(parsed) = format!("[[bodies]]\n{text}").parse::<Table>() else {
        return;
    };
    let Some(body) = parsed
        .get("bodies")
        .and_then(Value::as_array)
        .and_then(|b| b.first())
        .and_then(Value::as_table)
    else {
        return;
    };
    for key in ["supports", "loads"] {
        if let Some(Value::Array(new)) = body.get(key) {
            let mut entries = new.clone();
            if let Some(Value::Array(old)) = table.remove(key) {
                entries.extend(old);
            }
            table.insert(key.into(), Value::Array(entries));
        }
    }
}

/// Make the relative file names of a scene (the paper's files, `mesh.file`, `outline.file`,
/// obstacles' `file`) absolute against `folder`, so the scene written elsewhere still finds them.
fn absolute_paths(scene: &mut Table, folder: &Path) {
    let fix = |v: &mut Value| {
        if let Value::String(s) = v {
            if Path::new(s.as_str()).is_relative() {
                *s = folder.join(s.as_str()).to_string_lossy().into_owned();
            }
        }
    };
    if let Some(Value::Array(bodies)) = scene.get_mut("bodies") {
        for body in bodies.iter_mut().filter_map(Value::as_table_mut) {
            for key in ["nodes", "links", "patches"] {
                if let Some(v) = body.get_mut(key) {
                    fix(v);
                }
            }
            for key in ["mesh", "outline"] {
                if let Some(v) = body.get_mut(key).and_then(|t| t.get_mut("file")) {
                    fix(v);
                }
            }
        }
    }
    if let Some(Value::Array(obstacles)) = scene.get_mut("obstacles") {
        for o in obstacles.iter_mut().filter_map(Value::as_table_mut) {
            if let Some(v) = o.get_mut("file") {
                fix(v);
            }
        }
    }
}
