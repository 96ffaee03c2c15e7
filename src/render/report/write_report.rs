//! Writing the report of a batch: `DIR/index.html` and a page per job with results.

use crate::render::report::batch_page::batch_page;
use crate::render::report::job_files::JobFiles;
use crate::render::report::scene_page::scene_page;
use crate::scene::atomic_file::write_atomically;
use crate::scene::batch::Row;
use std::path::{Path, PathBuf};

/// The report's file name, in `DIR` and in each job's results folder.
pub const REPORT: &str = "index.html";

/// Write `out/index.html` for the batch of `rows` (in batch order, skipped jobs included: their
/// rows are read from their results) and `index.html` in each job's results folder, each
/// atomically. Returns the batch page's path.
pub fn write_report(out: &Path, rows: &[Row]) -> std::io::Result<PathBuf> {
    let jobs: Vec<(&Row, JobFiles)> = rows.iter().map(|r| (r, JobFiles::find(out, r))).collect();
    for (row, files) in &jobs {
        if !files.folder.is_empty() {
            write_atomically(
                &files.dir(out).join(REPORT),
                scene_page(row, files).as_bytes(),
            )?;
        }
    }
    // Named after its scenes, not its folder, so two runs of one batch give the same page.
    let mut scenes: Vec<&str> = Vec::new();
    for r in rows {
        let name = if r.scene.is_empty() { &r.job } else { &r.scene };
        if !scenes.contains(&name.as_str()) {
            scenes.push(name);
        }
    }
    let title = match scenes.len() {
        0 => "linkage: an empty batch".to_string(),
        1..=4 => format!("linkage: {}", scenes.join(", ")),
        n => format!("linkage: {} and {} more", scenes[..3].join(", "), n - 3),
    };
    let path = out.join(REPORT);
    write_atomically(&path, batch_page(&title, &jobs).as_bytes())?;
    Ok(path)
}

/// Whether any job of `rows` has pictures in `out` (frames, an animation or plots): then a
/// batch run without `--png` (its scenes asked for pictures, or they were skipped) or
/// `linkage collect` writes the report too.
pub fn has_pictures(out: &Path, rows: &[Row]) -> bool {
    rows.iter().any(|r| {
        let f = JobFiles::find(out, r);
        f.gif || !f.frames.is_empty() || !f.plots.is_empty()
    })
}
