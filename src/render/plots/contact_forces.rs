//! The total contact force of each pair (a body and the obstacle or body it touches) against
//! the step.

use crate::render::plots::{Chart, Series};
use crate::scene::Summary;

/// The chart `contact_forces`: per pair, the magnitude of the total force the body receives
/// (N) at every solved step (0 where the pair does not touch); `None` when no pair ever
/// touches.
pub fn contact_forces(summary: &Summary) -> Option<Chart> {
    let mut pairs: Vec<(&str, &str)> = Vec::new();
    for p in summary.steps.iter().flat_map(|s| &s.contact_forces) {
        if !pairs.contains(&(p.body.as_str(), p.with.as_str())) {
            pairs.push((&p.body, &p.with));
        }
    }
    if pairs.is_empty() {
        return None;
    }
    let series = pairs
        .iter()
        .map(|&(body, with)| {
            let mut s = Series::new(format!("{body} from {with}"));
            for step in &summary.steps {
                let force = step
                    .contact_forces
                    .iter()
                    .find(|p| p.body == body && p.with == with)
                    .map_or(0.0, |p| p.force.iter().map(|f| f * f).sum::<f64>().sqrt());
                s.push(step.step as f64, force, format!("step {}", step.step));
            }
            s
        })
        .collect();
    Some(Chart {
        name: "contact_forces".into(),
        title: format!("{}: total contact force per pair", summary.scene),
        x_label: "step".into(),
        y_label: "contact force |F| (N)".into(),
        columns: ("step".into(), "contact_force_N".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (true, false),
        series,
    })
}
