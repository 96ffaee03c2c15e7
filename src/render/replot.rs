//! `linkage render` draws a run's plots and report again from its results folder: the plots
//! from `summary.json`, the stored steps and the plot settings kept beside them
//! ([`crate::scene::PLOT_SETTINGS`]), the report when the folder is a job of a batch folder
//! with its `table.csv`.

use crate::render::plots::{plot_run, PlotError, WrittenPlot};
use crate::render::report::write_report_of;
use crate::scene::batch::{parse_table, TABLE};
use crate::scene::{PlotSettings, RunResults, StoredRunError, Summary};
use std::path::{Path, PathBuf};

/// Why the plots or the report could not be drawn again.
#[derive(Debug, thiserror::Error)]
pub enum ReplotError {
    /// `summary.json` could not be read.
    #[error("{path}: cannot read the run's summary ({message}): run the scene again")]
    Summary {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The stored steps could not be read.
    #[error(transparent)]
    Read(#[from] StoredRunError),
    /// A plot could not be drawn or written.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// The batch's `table.csv` does not read, or the report could not be written.
    #[error("{path}: cannot write the report again: {message}")]
    Report {
        /// `table.csv` or the report.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// The summary of the results folder `dir`.
pub fn read_summary(dir: &Path) -> Result<Summary, ReplotError> {
    let path = dir.join("summary.json");
    let bytes = std::fs::read(&path).map_err(|e| ReplotError::Summary {
        path: path.clone(),
        message: e.to_string(),
    })?;
    serde_json::from_slice(&bytes).map_err(|e| ReplotError::Summary {
        path,
        message: e.to_string(),
    })
}

/// Draw the plots of the results folder `dir` again into `out/plots/` (`out` may be `dir`),
/// with the plot settings the run kept (the default ones for a folder written before they
/// were kept).
pub fn redraw_plots(dir: &Path, out: &Path) -> Result<Vec<WrittenPlot>, ReplotError> {
    redraw_plots_of(dir, out, &RunResults::read(dir)?)
}

/// [`redraw_plots`] of `run`, the stored steps of `dir` read already (`linkage render`
/// reads them once for the frames, the GLB, the VTK files, the plots and the report).
pub fn redraw_plots_of(
    dir: &Path,
    out: &Path,
    run: &RunResults,
) -> Result<Vec<WrittenPlot>, ReplotError> {
    let summary = read_summary(dir)?;
    let settings = PlotSettings::read(dir);
    Ok(plot_run(&summary, run, &settings, out)?)
}

/// Write the report again when the results folder `dir` is a job of a batch folder: the
/// folder above it (or above its variant folder) holding the batch's `table.csv` with a row
/// for it: the batch page and this job's page (the other jobs' pages are kept). Returns the
/// batch page's path, or `None` when `dir` belongs to no batch folder.
pub fn redraw_report(dir: &Path) -> Result<Option<PathBuf>, ReplotError> {
    redraw_report_of(dir, None)
}

/// [`redraw_report`], the 3D view of `dir`'s page made from `run` when given (the stored
/// steps of `dir` read already), else from the steps read again.
pub fn redraw_report_of(
    dir: &Path,
    run: Option<&RunResults>,
) -> Result<Option<PathBuf>, ReplotError> {
    let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
    for out in dir.ancestors().skip(1).take(2) {
        let table = out.join(TABLE);
        let Ok(text) = std::fs::read_to_string(&table) else {
            continue;
        };
        let rows = parse_table(&text).map_err(|message| ReplotError::Report {
            path: table.clone(),
            message,
        })?;
        let Ok(job) = dir.strip_prefix(out) else {
            continue;
        };
        let job = job.to_string_lossy().replace('\\', "/");
        if !rows.iter().any(|r| r.job == job) {
            continue;
        }
        let page =
            write_report_of(out, &rows, Some((&job, run))).map_err(|e| ReplotError::Report {
                path: out.join(crate::render::report::REPORT),
                message: e.to_string(),
            })?;
        return Ok(Some(page));
    }
    Ok(None)
}
