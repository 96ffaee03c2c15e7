//! Every plot of one run, written to `plots/` of its results folder.

use crate::render::plots::{
    breaks, contact_force_time, contact_forces, energies, load_displacement, obstacle_force,
    place_force, reaction, residuals, PlotError, WrittenPlot,
};
use crate::scene::{PlotSettings, RunResults, Summary};
use std::path::Path;

/// The folder of a run's plots, in its results folder.
pub const PLOTS: &str = "plots";

/// Write the plots of the run with `summary` and stored steps `run` into `dir/plots/`: always
/// the load–displacement curve (the force from `settings.obstacle` against its travel when
/// it names a moving obstacle, the force at `settings.place` against its displacement when
/// it is given; and with `settings.node` the reaction total); the contact
/// forces when a pair touched, the Newton residuals when a step was nonlinear, the breaks when
/// members broke; for a dynamic scene the energies against time, and the total contact force
/// against time when something touched. Each as PNG, SVG and the CSV of its points, written atomically.
pub fn plot_run(
    summary: &Summary,
    run: &RunResults,
    settings: &PlotSettings,
    dir: &Path,
) -> Result<Vec<WrittenPlot>, PlotError> {
    let plots = dir.join(PLOTS);
    std::fs::create_dir_all(&plots).map_err(|source| PlotError::Write {
        path: plots.clone(),
        source,
    })?;
    let by_obstacle = settings
        .obstacle
        .as_deref()
        .and_then(|name| obstacle_force(summary, run, name));
    let by_place = settings
        .place
        .as_ref()
        .and_then(|place| place_force(&summary.scene, run, place));
    let load = settings.load_name();
    let mut charts = vec![by_obstacle
        .or(by_place)
        .unwrap_or_else(|| load_displacement(summary, run, settings.node.as_ref(), load))];
    if settings.node.is_some() {
        charts.extend(reaction(&summary.scene, run, load));
    }
    charts.extend(contact_forces(summary));
    charts.extend(residuals(summary));
    charts.extend(breaks(summary, load));
    charts.extend(energies(summary));
    charts.extend(contact_force_time(summary));
    charts.iter().map(|c| c.write(&plots)).collect()
}
