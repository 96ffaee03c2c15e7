//! Writing the report of a batch: `DIR/index.html` and a page per job with results.

use crate::render::report::batch_page::batch_page;
use crate::render::report::html::escape;
use crate::render::report::job_files::JobFiles;
use crate::render::report::scene_page::scene_page;
use crate::render::report::sweep_plots::{sweep_section, write_sweep_plots};
use crate::render::viewer::{viewer_data, viewer_section, VIEWER_BUDGET};
use crate::render::{stored_time, AnimatedRun, RunExtent, SharedScale};
use crate::scene::atomic_file::write_atomically;
use crate::scene::batch::Row;
use crate::scene::{PlotSettings, RunResults};
use std::path::{Path, PathBuf};

/// The report's file name, in `DIR` and in each job's results folder.
pub const REPORT: &str = "index.html";

/// Write `out/index.html` for the batch of `rows` (in batch order, skipped jobs included: their
/// rows are read from their results) and `index.html` in each job's results folder, each
/// atomically. Returns the batch page's path.
pub fn write_report(out: &Path, rows: &[Row]) -> std::io::Result<PathBuf> {
    write_report_of(out, rows, None)
}

/// [`write_report`], with the page of job `only` alone written again when it is given (the
/// others kept as they are: `linkage render` of one job's folder), its 3D view made from the
/// job's stored steps when they are given (read once by `linkage render`), else read again.
pub fn write_report_of(
    out: &Path,
    rows: &[Row],
    only: Option<(&str, Option<&RunResults>)>,
) -> std::io::Result<PathBuf> {
    let jobs: Vec<(&Row, JobFiles)> = rows.iter().map(|r| (r, JobFiles::find(out, r))).collect();
    for (row, files) in &jobs {
        if !files.folder.is_empty() && only.is_none_or(|(j, _)| j == row.job) {
            let dir = files.dir(out);
            let mut viewer = viewer_of(&dir, only.and_then(|(_, run)| run));
            if let Some(scale) = SharedScale::read(&dir) {
                viewer.insert_str(0, &shared_note(&scale));
            }
            write_atomically(
                &dir.join(REPORT),
                scene_page(row, files, &viewer).as_bytes(),
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
    let sweeps = write_sweep_plots(out, rows).map_err(std::io::Error::other)?;
    let mut after = String::new();
    // One note per sweep whose variants share a scale (read from its first variant that has
    // one).
    let mut noted: Vec<&str> = Vec::new();
    for (row, files) in &jobs {
        if row.values.is_empty() || files.folder.is_empty() || noted.contains(&row.scene.as_str()) {
            continue;
        }
        if let Some(scale) = SharedScale::read(&files.dir(out)) {
            noted.push(row.scene.as_str());
            after.push_str(&format!(
                "<h2>{}: one scale for all variants</h2>\n{}",
                escape(&row.scene),
                shared_note(&scale)
            ));
        }
    }
    after.push_str(&sweep_section(&sweeps));
    let path = out.join(REPORT);
    write_atomically(&path, batch_page(&title, &jobs, &after).as_bytes())?;
    Ok(path)
}

/// The note saying that a sweep's variants share `scale`.
fn shared_note(scale: &SharedScale) -> String {
    let mut text = scale.describe();
    if let Some(first) = text.get(..1) {
        text.replace_range(..1, &first.to_uppercase());
    }
    format!("<p class=\"note shared-scale\">{}.</p>\n", escape(&text))
}

/// The 3D view of the results in `dir` (`run`, its stored steps, when given, else read
/// back; decimated to [`VIEWER_BUDGET`], displacements magnified as the pictures do by
/// default, or by the magnification a sweep's variants share), or a note why there is none.
fn viewer_of(dir: &Path, run: Option<&RunResults>) -> String {
    let read;
    let run = match run {
        Some(run) => Ok(run),
        None => {
            read = RunResults::read(dir);
            read.as_ref()
        }
    };
    match run {
        Ok(run) => {
            // A sweep variant's view has the magnification the variants share.
            let magnification = SharedScale::read(dir).map_or_else(
                || RunExtent::of_run(run, None).magnification,
                |s| s.magnification,
            );
            let mut animation = AnimatedRun::of_run(run, magnification, VIEWER_BUDGET, stored_time);
            animation.load_name = PlotSettings::read(dir).load_name();
            viewer_section(&viewer_data(&animation))
        }
        Err(e) => format!(
            "<h2>3D view</h2>\n<p class=\"note\">No 3D view: {}</p>\n",
            escape(&e.to_string())
        ),
    }
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
