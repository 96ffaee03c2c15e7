//! The reaction total against the load factor: the components of the sum of every support
//! reaction of every body at each stored step (with `[output] plot_node`). A component whose
//! sum is round-off at every step (the reactions cancel) is left out, not drawn as a curve of
//! round-off.

use crate::render::plots::{Chart, Series};
use crate::scene::RunResults;

/// A reaction total counts as round-off when it is at most this fraction of the sum of the
/// magnitudes of the reactions it adds up (f64 sums of a few thousand terms err by ~1e-13).
pub const CANCELLED: f64 = 1e-9;

/// The chart `reaction`: one series per direction (x, y and, in 3D, z), N, one point per
/// stored step; a direction whose total is round-off at every step ([`CANCELLED`]) is left
/// out, and the chart is `None` when every direction is.
/// `load`: what the load factor is called ([`crate::scene::load_name`]).
pub fn reaction(scene: &str, run: &RunResults, load: &str) -> Option<Chart> {
    let dimension = run
        .model
        .bodies
        .iter()
        .map(|b| b.dimension)
        .max()
        .unwrap_or(2)
        .clamp(2, 3);
    let mut series: Vec<Series> = ["x", "y", "z"][..dimension]
        .iter()
        .map(|a| Series::new(format!("R{a}")))
        .collect();
    let mut real = vec![false; dimension];
    for step in &run.steps {
        let mut total = [0.0; 3];
        let mut magnitude = [0.0; 3];
        for r in step.bodies.iter().flat_map(|b| &b.reactions) {
            for (i, f) in r.force.iter().enumerate().take(3) {
                total[i] += f;
                magnitude[i] += f.abs();
            }
        }
        for (i, s) in series.iter_mut().enumerate() {
            real[i] |= total[i].abs() > CANCELLED * magnitude[i];
            s.push(step.load_factor, total[i], format!("step {}", step.step));
        }
    }
    let series: Vec<Series> = series
        .into_iter()
        .zip(real)
        .filter_map(|(s, r)| r.then_some(s))
        .collect();
    if series.is_empty() {
        return None;
    }
    Some(Chart {
        name: "reaction".into(),
        title: format!("{scene}: total support reaction against {load}"),
        x_label: format!("{load} (-)"),
        y_label: "total reaction (N)".into(),
        columns: ("load_factor".into(), "reaction_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series,
    })
}
