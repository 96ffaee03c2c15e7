//! The reaction total against the load factor: the components of the sum of every support
//! reaction of every body at each stored step (with `[output] plot_node`).

use crate::render::plots::{Chart, Series};
use crate::scene::RunResults;

/// The chart `reaction`: one series per direction (x, y and, in 3D, z), N, one point per
/// stored step.
pub fn reaction(scene: &str, run: &RunResults) -> Chart {
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
    for step in &run.steps {
        let mut total = [0.0; 3];
        for r in step.bodies.iter().flat_map(|b| &b.reactions) {
            for (t, f) in total.iter_mut().zip(&r.force) {
                *t += f;
            }
        }
        for (s, t) in series.iter_mut().zip(total) {
            s.push(step.load_factor, t, format!("step {}", step.step));
        }
    }
    Chart {
        name: "reaction".into(),
        title: format!("{scene}: total support reaction against load factor"),
        x_label: "load factor (-)".into(),
        y_label: "total reaction (N)".into(),
        columns: ("load_factor".into(), "reaction_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series,
    }
}
