//! The load–displacement curve of a scene loaded by a moving obstacle (`[output]
//! plot_obstacle`): the force the bodies receive from the obstacle against its travel, so a
//! peak and a softening branch show.

use crate::render::plots::{Chart, Series};
use crate::scene::{RunResults, Summary};

/// The chart `load_displacement` for the obstacle `name`: one point per solved step, x = the
/// obstacle's travel along its direction of travel e (unit vector of its last offset minus
/// its first), m; y = F·e, N, where F is the sum over the bodies of the contact force each
/// receives from it (the summary's `contact_forces`). `None` when the run has no obstacle of
/// that name or it does not move (then there is no direction to plot along).
pub fn obstacle_force(summary: &Summary, run: &RunResults, name: &str) -> Option<Chart> {
    let obstacle = run.model.obstacles.iter().find(|o| o.name == name)?;
    let first = *obstacle.offsets.first()?;
    let last = *obstacle.offsets.last()?;
    let d: Vec<f64> = (0..3).map(|i| last[i] - first[i]).collect();
    let length = d.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let e: Vec<f64> = d.iter().map(|x| x / length).collect();
    let mut series = Series::new(format!("obstacle '{name}'"));
    for step in &summary.steps {
        let Some(offset) = obstacle.offsets.get(step.step) else {
            continue;
        };
        let travel: f64 = (0..3).map(|i| (offset[i] - first[i]) * e[i]).sum();
        let force: f64 = step
            .contact_forces
            .iter()
            .filter(|p| p.with == name)
            .map(|p| p.force.iter().zip(&e).map(|(f, e)| f * e).sum::<f64>())
            .sum();
        series.push(travel, force, format!("step {}", step.step));
    }
    Some(Chart {
        name: "load_displacement".into(),
        title: format!("{}: force from '{name}' against its travel", summary.scene),
        x_label: format!("travel of '{name}' (m)"),
        y_label: format!("force from '{name}' along its travel (N)"),
        columns: ("travel_m".into(), "force_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series: vec![series],
    })
}
