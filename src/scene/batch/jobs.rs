//! The jobs of a batch: every scene, or every variant of a scene's `[sweep]`, in a stable order
//! (the scenes as given, variants k = 1 … n), so shards of one batch agree on them.

use crate::scene::atomic_file::write_atomically;
use crate::scene::batch::error::{io_at, BatchError};
use crate::scene::sweep::{expand_sweep, value_cell};
use crate::scene::SceneError;
use std::path::{Path, PathBuf};

/// The list of a sharded batch's job names, `DIR/batch.jobs.json`, so `linkage collect` knows
/// which are missing.
pub const JOB_LIST: &str = "batch.jobs.json";

/// The list of a sweep's variants and their values, `DIR/<scene>/variants.json`.
pub const VARIANT_LIST: &str = "variants.json";

/// One run of a batch.
#[derive(Clone, Debug)]
pub struct Job {
    /// The scene file.
    pub scene: PathBuf,
    /// The scene's `name` (the file's stem when the file cannot be read or parsed).
    pub name: String,
    /// k (1-based) of a sweep's variant; `None` for a scene without `[sweep]`.
    pub variant: Option<usize>,
    /// The swept keys with this variant's values.
    pub values: Vec<(String, toml::Value)>,
    /// The scene text to run, or why the scene file cannot be read.
    pub text: Result<String, String>,
}

impl Job {
    /// `<scene>` or `<scene>/<k>`: the job's name and its results folder under `DIR`.
    pub fn id(&self) -> String {
        match self.variant {
            Some(k) => format!("{}/{k}", self.name),
            None => self.name.clone(),
        }
    }

    /// The folder the run publishes its results folder in: `DIR` or `DIR/<scene>` (a variant).
    pub fn parent(&self, out: &Path) -> PathBuf {
        match self.variant {
            Some(_) => out.join(&self.name),
            None => out.to_path_buf(),
        }
    }

    /// The results folder's own name: `<scene>` or `<k>`.
    pub fn folder_name(&self) -> String {
        match self.variant {
            Some(k) => k.to_string(),
            None => self.name.clone(),
        }
    }

    /// The results folder, `DIR/<scene>` or `DIR/<scene>/<k>`.
    pub fn folder(&self, out: &Path) -> PathBuf {
        self.parent(out).join(self.folder_name())
    }

    /// A scene error `message` of this job as the user should read it: a variant's names the
    /// file, the variant and its values, without the line (which would point into the
    /// variant's generated text); a scene's is `message` itself.
    pub fn describe_error(&self, message: &str) -> String {
        let Some(k) = self.variant else {
            return message.to_string();
        };
        let path = self.scene.display().to_string();
        let rest = message
            .strip_prefix(&path)
            .map(|r| {
                r.trim_start_matches(|c: char| c == ':' || c.is_ascii_digit())
                    .trim_start()
            })
            .unwrap_or(message);
        let values: Vec<String> = self
            .value_cells()
            .iter()
            .map(|(key, v)| format!("{key} = {v}"))
            .collect();
        format!(
            "{path}: [sweep] variant {k} ({}): {rest}",
            values.join(", ")
        )
    }

    /// The swept values as table cells.
    pub fn value_cells(&self) -> Vec<(String, String)> {
        self.values
            .iter()
            .map(|(k, v)| (k.clone(), value_cell(v)))
            .collect()
    }
}

/// The jobs of `scenes`, in order. A scene that cannot be read becomes a job that fails (as
/// `linkage run` reports it, with the others run); a wrong `[sweep]` is an error before
/// anything runs.
pub fn plan_jobs(scenes: &[PathBuf]) -> Result<Vec<Job>, BatchError> {
    let mut jobs = Vec::new();
    for path in scenes {
        let stem = path.file_stem().map_or_else(
            || path.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        let text = match std::fs::read_to_string(path) {
            Ok(text) => text,
            Err(source) => {
                let e = SceneError::Read {
                    path: path.clone(),
                    source,
                };
                jobs.push(Job {
                    scene: path.clone(),
                    name: stem,
                    variant: None,
                    values: Vec::new(),
                    text: Err(e.to_string()),
                });
                continue;
            }
        };
        let name = text
            .parse::<toml::Table>()
            .ok()
            .and_then(|t| t.get("name").and_then(|n| n.as_str().map(str::to_string)))
            .unwrap_or(stem);
        let variants = match expand_sweep(&text, path) {
            Ok(v) => v,
            // A file that is not TOML is reported when its job builds the scene, as before.
            Err(SceneError::Parse { .. }) => {
                jobs.push(Job {
                    scene: path.clone(),
                    name,
                    variant: None,
                    values: Vec::new(),
                    text: Ok(text),
                });
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        let sweep = variants.first().is_some_and(|v| !v.values.is_empty());
        for (k, v) in variants.into_iter().enumerate() {
            jobs.push(Job {
                scene: path.clone(),
                name: name.clone(),
                variant: sweep.then_some(k + 1),
                values: v.values,
                text: Ok(v.text),
            });
        }
    }
    Ok(jobs)
}

/// Write `DIR/<scene>/variants.json` for every swept scene of `jobs`: per variant its folder
/// and values (atomically; every shard writes the same).
pub fn write_variant_lists(jobs: &[Job], out: &Path) -> Result<(), BatchError> {
    let mut i = 0;
    while i < jobs.len() {
        let first = &jobs[i];
        let same: Vec<&Job> = jobs[i..]
            .iter()
            .take_while(|j| j.scene == first.scene && j.variant.is_some())
            .collect();
        i += same.len().max(1);
        if same.is_empty() {
            continue;
        }
        let list: Vec<serde_json::Value> = same
            .iter()
            .map(|j| {
                let values: serde_json::Map<String, serde_json::Value> = j
                    .values
                    .iter()
                    .map(|(k, v)| (k.clone(), serde_json::to_value(v).unwrap_or_default()))
                    .collect();
                serde_json::json!({
                    "variant": j.variant,
                    "folder": j.id(),
                    "values": values,
                })
            })
            .collect();
        let dir = first.parent(out);
        std::fs::create_dir_all(&dir).map_err(io_at(&dir))?;
        let path = dir.join(VARIANT_LIST);
        let mut text = serde_json::to_string_pretty(&list).unwrap_or_default();
        text.push('\n');
        write_atomically(&path, text.as_bytes()).map_err(io_at(&path))?;
    }
    Ok(())
}

/// Write `DIR/batch.jobs.json`: every job's name, in order (atomically).
pub fn write_job_list(jobs: &[Job], out: &Path) -> Result<(), BatchError> {
    let ids: Vec<String> = jobs.iter().map(Job::id).collect();
    let path = out.join(JOB_LIST);
    let mut text = serde_json::to_string_pretty(&ids).unwrap_or_default();
    text.push('\n');
    write_atomically(&path, text.as_bytes()).map_err(io_at(&path))
}
