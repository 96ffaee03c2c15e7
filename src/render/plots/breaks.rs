//! Members broken against the load factor at which each broke.

use crate::render::plots::{Chart, Series};
use crate::scene::Summary;

/// The chart `breaks`: one point per break in the order they happened, at the load factor of
/// the break and the number of members broken so far (all bodies); `None` without breaks. A
/// softening member's teeth are not breaks: it counts when its last tooth breaks it. `load`:
/// what the load factor is called ([`crate::scene::load_name`]).
pub fn breaks(summary: &Summary, load: &str) -> Option<Chart> {
    let broken: Vec<_> = summary
        .breaks
        .iter()
        .filter(|b| b.tooth.is_none())
        .collect();
    if broken.is_empty() {
        return None;
    }
    let mut s = Series::new("broken members");
    for (k, b) in broken.into_iter().enumerate() {
        s.push(
            b.load_factor,
            (k + 1) as f64,
            format!("step {}, body '{}' member {}", b.step, b.body, b.member),
        );
    }
    Some(Chart {
        name: "breaks".into(),
        title: format!("{}: members broken against {load}", summary.scene),
        x_label: format!("{load} at the break (-)"),
        y_label: "members broken (count)".into(),
        columns: ("load_factor".into(), "broken_members".into()),
        log_y: false,
        legend: false,
        one_colour: false,
        integer: (false, true),
        series: vec![s],
    })
}
