//! The HTML report of a batch: `DIR/index.html` with a row per job and a page per job with
//! every frame; plain HTML and CSS with relative links, read from disk without a network.

pub use self::sweep_plots::{sweep_charts, write_sweep_plots, SweepPlot, SWEEP_PLOTS};
pub use self::write_report::{has_pictures, write_report, write_report_of, REPORT};

mod batch_page;
mod facts;
mod html;
mod job_files;
mod scene_page;
mod sweep_plots;
mod write_report;
