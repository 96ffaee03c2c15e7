//! The load–displacement curve: the load factor against the largest displacement of any node
//! at each solved step, or against one node's displacement (`[output] plot_node`) at each
//! stored step.

use crate::render::plots::{Chart, Series};
use crate::scene::{PlotNode, RunResults, Summary};

/// The chart `load_displacement`: one point per solved step (`node` = `None`, from the
/// summary) or per stored step (`node`: its displacement magnitude, m, from the step results).
/// `load`: what the load factor is called ([`crate::scene::load_name`]).
pub fn load_displacement(
    summary: &Summary,
    run: &RunResults,
    node: Option<&PlotNode>,
    load: &str,
) -> Chart {
    let (series, x_label, column) = match node {
        None => {
            let mut s = Series::new("largest displacement");
            for step in &summary.steps {
                s.push(
                    step.max_displacement,
                    step.load_factor,
                    format!("step {}", step.step),
                );
            }
            (
                s,
                "largest displacement |u| (m)".to_string(),
                "max_displacement_m",
            )
        }
        Some(n) => {
            let name = format!("body '{}' node {}", n.body, n.node + 1);
            let mut s = Series::new(name.clone());
            for step in &run.steps {
                let u = step
                    .bodies
                    .iter()
                    .find(|b| b.name == n.body)
                    .and_then(|b| b.displacements.get(n.node));
                if let Some(u) = u {
                    let magnitude = u.iter().map(|c| c * c).sum::<f64>().sqrt();
                    s.push(magnitude, step.load_factor, format!("step {}", step.step));
                }
            }
            (
                s,
                format!("displacement |u| of {name} (m)"),
                "displacement_m",
            )
        }
    };
    Chart {
        name: "load_displacement".into(),
        title: format!("{}: {load} against displacement", summary.scene),
        x_label,
        y_label: format!("{load} (-)"),
        columns: (column.into(), "load_factor".into()),
        log_y: false,
        legend: true,
        one_colour: false,
        integer: (false, false),
        series: vec![series],
    }
}
