//! What a job of the batch left on disk for the report: its results folder, summary, frames,
//! plots and animation.

use crate::render::plots::PLOTS;
use crate::scene::batch::Row;
use crate::scene::publish::FAILED_SUFFIX;
use crate::scene::Summary;
use std::path::{Path, PathBuf};

/// The files of one job that the report shows, all relative to its results folder.
#[derive(Clone, Debug, Default)]
pub struct JobFiles {
    /// The results folder's path segments under `DIR` (`["beam", "2"]`; a run that stopped
    /// beside complete results: `["beam.failed"]`); empty when there is none.
    pub folder: Vec<String>,
    /// Its `summary.json`, when it reads.
    pub summary: Option<Summary>,
    /// `png/NNNN.png` file names, in step order.
    pub frames: Vec<String>,
    /// `plots/<name>.png` stems, in the order the run writes them.
    pub plots: Vec<String>,
    /// Whether `anim.gif` is there.
    pub gif: bool,
    /// The batch folder `DIR` (messages name paths relative to it).
    pub batch: PathBuf,
}

/// The order plots are shown in (the order `plot_run` writes them); others after, by name.
const PLOT_ORDER: [&str; 5] = [
    "load_displacement",
    "reaction",
    "contact_forces",
    "residuals",
    "breaks",
];

impl JobFiles {
    /// What is on disk for `row` in the batch folder `out`: for a failed job its
    /// `<job>.failed` folder when there is one, else `<job>`.
    pub fn find(out: &Path, row: &Row) -> JobFiles {
        let segments: Vec<String> = row.job.split('/').map(str::to_string).collect();
        let mut failed = segments.clone();
        if let Some(last) = failed.last_mut() {
            last.push_str(FAILED_SUFFIX);
        }
        let candidates = if row.status.starts_with("failed") {
            vec![failed, segments]
        } else {
            vec![segments]
        };
        let Some(folder) = candidates
            .into_iter()
            .find(|s| !row.job.is_empty() && join(out, s).join("summary.json").is_file())
        else {
            return JobFiles {
                batch: out.to_path_buf(),
                ..JobFiles::default()
            };
        };
        let dir = join(out, &folder);
        let summary = std::fs::read(dir.join("summary.json"))
            .ok()
            .and_then(|b| serde_json::from_slice::<Summary>(&b).ok());
        let mut frames = names_in(&dir.join("png"), |n| {
            n.strip_suffix(".png")
                .is_some_and(|s| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
        });
        frames.sort_by_key(|n| (n.len(), n.clone()));
        let mut plots: Vec<String> = names_in(&dir.join(PLOTS), |n| n.ends_with(".png"))
            .into_iter()
            .map(|n| n.trim_end_matches(".png").to_string())
            .collect();
        plots.sort_by_key(|p| {
            (
                PLOT_ORDER
                    .iter()
                    .position(|o| o == p)
                    .unwrap_or(PLOT_ORDER.len()),
                p.clone(),
            )
        });
        JobFiles {
            batch: out.to_path_buf(),
            gif: dir.join("anim.gif").is_file(),
            folder,
            summary,
            frames,
            plots,
        }
    }

    /// The link segments from `DIR` to `file` of this job's folder.
    pub fn batch_path<'a>(&'a self, file: &[&'a str]) -> Vec<&'a str> {
        self.folder
            .iter()
            .map(String::as_str)
            .chain(file.iter().copied())
            .collect()
    }

    /// The path of the job's folder under `out`.
    pub fn dir(&self, out: &Path) -> PathBuf {
        join(out, &self.folder)
    }
}

fn join(out: &Path, segments: &[String]) -> PathBuf {
    segments.iter().fold(out.to_path_buf(), |p, s| p.join(s))
}

/// The names of the files in `dir` that `keep` accepts (none when it does not read).
fn names_in(dir: &Path, keep: impl Fn(&str) -> bool) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter(|n| keep(n))
        .collect()
}
