//! Newton's relative residual after each iteration of the nonlinear steps, on a log scale.

use crate::render::plots::{Chart, Series};
use crate::scene::Summary;

/// The chart `residuals`: one series per nonlinear step (its last increment's iterations, as
/// `summary.json` lists them), the iterations numbered on from step to step so the steps sit
/// side by side; `None` when no step is nonlinear.
pub fn residuals(summary: &Summary) -> Option<Chart> {
    let mut series = Vec::new();
    let mut count = 0usize;
    for step in summary.steps.iter().filter(|s| !s.residuals.is_empty()) {
        let mut s = Series::new(format!("step {}", step.step));
        for (i, &r) in step.residuals.iter().enumerate() {
            count += 1;
            s.push(
                count as f64,
                r,
                format!("step {} iteration {}", step.step, i + 1),
            );
        }
        series.push(s);
    }
    if series.is_empty() {
        return None;
    }
    Some(Chart {
        name: "residuals".into(),
        title: format!("{}: Newton residuals, step after step", summary.scene),
        x_label: "Newton iteration (numbered on over the steps)".into(),
        y_label: "relative residual (-), log scale".into(),
        columns: ("iteration".into(), "relative_residual".into()),
        log_y: true,
        legend: false,
        one_colour: true,
        integer: (true, false),
        series,
    })
}
