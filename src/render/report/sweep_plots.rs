//! A sweep's key results against its swept values, on the batch page: for each scene swept
//! over a numeric key, one plot per key result (largest displacement, peak stress, stress
//! ratio, overloaded and broken members) against that key, one point per variant that ran,
//! one line per combination of the other keys' values.

use crate::render::plots::{Chart, PlotError, Series};
use crate::render::report::facts::swept_value;
use crate::render::report::html::{escape, link};
use crate::scene::batch::Row;
use std::path::Path;

/// The folder of the sweep plots in the batch folder.
pub const SWEEP_PLOTS: &str = "sweep_plots";

/// The key results plotted: (the row's column, the axis label).
const RESULTS: [(&str, &str); 5] = [
    ("max_displacement", "largest displacement (m)"),
    ("peak_stress", "peak member stress (Pa)"),
    ("stress_ratio", "largest stress / strength (-)"),
    ("overloaded", "overloaded members"),
    ("broken", "broken members"),
];

/// One plot written: the scene, the swept key, the result and the PNG's file name in
/// [`SWEEP_PLOTS`].
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPlot {
    /// The swept scene.
    pub scene: String,
    /// The swept key (dotted path).
    pub key: String,
    /// The result's column in `batch.csv`.
    pub result: String,
    /// `<stem>.png` in [`SWEEP_PLOTS`] (beside its SVG and CSV).
    pub png: String,
}

fn number(cell: &str) -> Option<f64> {
    cell.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

fn result_of(row: &Row, column: &str) -> Option<f64> {
    number(match column {
        "max_displacement" => &row.max_displacement,
        "peak_stress" => &row.peak_stress,
        "stress_ratio" => &row.stress_ratio,
        "overloaded" => &row.overloaded,
        "broken" => &row.broken,
        _ => return None,
    })
}

/// A file-name stem of `text`: letters and digits kept, anything else one `_`.
fn stem(text: &str) -> String {
    let mut out = String::new();
    for c in text.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c);
        } else if !out.ends_with('_') {
            out.push('_');
        }
    }
    out.trim_matches('_').to_string()
}

/// The charts of the sweeps among `rows` (the batch table, in batch order): for each scene
/// with variants and each swept key whose values are all numbers (at least two different),
/// one chart per key result some variant has. The variants that did not run are left out.
pub fn sweep_charts(rows: &[Row]) -> Vec<(SweepPlot, Chart)> {
    let mut scenes: Vec<&str> = Vec::new();
    for r in rows.iter().filter(|r| !r.values.is_empty()) {
        if !scenes.contains(&r.scene.as_str()) {
            scenes.push(&r.scene);
        }
    }
    let mut out = Vec::new();
    for scene in scenes {
        let variants: Vec<&Row> = rows
            .iter()
            .filter(|r| r.scene == scene && !r.values.is_empty())
            .collect();
        let keys: Vec<&String> = variants[0].values.iter().map(|(k, _)| k).collect();
        for (index, key) in keys.iter().enumerate() {
            let value = |r: &Row| {
                r.values
                    .iter()
                    .find(|(k, _)| k == *key)
                    .map(|(_, v)| v.clone())
            };
            let xs: Vec<Option<f64>> = variants
                .iter()
                .map(|r| value(r).and_then(|v| number(&v)))
                .collect();
            if xs.iter().any(Option::is_none) {
                continue;
            }
            let mut distinct: Vec<f64> = xs.iter().flatten().copied().collect();
            distinct.sort_by(f64::total_cmp);
            distinct.dedup();
            if distinct.len() < 2 {
                continue;
            }
            for (column, label) in RESULTS {
                let mut series: Vec<Series> = Vec::new();
                for (r, x) in variants.iter().zip(&xs) {
                    let Some(y) = result_of(r, column) else {
                        continue;
                    };
                    let others: Vec<String> = r
                        .values
                        .iter()
                        .filter(|(k, _)| k != *key)
                        .map(|(k, v)| format!("{} = {}", k, swept_value(k, v)))
                        .collect();
                    let name = if others.is_empty() {
                        scene.to_string()
                    } else {
                        others.join(", ")
                    };
                    let at = match series.iter().position(|s| s.name == name) {
                        Some(i) => i,
                        None => {
                            series.push(Series::new(name));
                            series.len() - 1
                        }
                    };
                    series[at].push(x.unwrap_or_default(), y, format!("job {}", r.job));
                }
                if series.is_empty() {
                    continue;
                }
                for s in &mut series {
                    let mut pairs: Vec<((f64, f64), String)> =
                        s.points.drain(..).zip(s.labels.drain(..)).collect();
                    pairs.sort_by(|a, b| a.0 .0.total_cmp(&b.0 .0));
                    for ((x, y), l) in pairs {
                        s.push(x, y, l);
                    }
                }
                let name = format!("{}.{}.{}", stem(scene), index + 1, column);
                let plot = SweepPlot {
                    scene: scene.to_string(),
                    key: key.to_string(),
                    result: column.to_string(),
                    png: format!("{name}.png"),
                };
                let chart = Chart {
                    name,
                    title: format!("{scene}: {label} against {key}"),
                    x_label: key.to_string(),
                    y_label: label.to_string(),
                    columns: (stem(key), column.to_string()),
                    log_y: false,
                    legend: series.len() > 1,
                    one_colour: false,
                    integer: (false, matches!(column, "overloaded" | "broken")),
                    series,
                };
                out.push((plot, chart));
            }
        }
    }
    out
}

/// Write the sweep plots of `rows` into `out/`[`SWEEP_PLOTS`] (PNG, SVG and CSV each).
pub fn write_sweep_plots(out: &Path, rows: &[Row]) -> Result<Vec<SweepPlot>, PlotError> {
    let charts = sweep_charts(rows);
    if charts.is_empty() {
        return Ok(Vec::new());
    }
    let dir = out.join(SWEEP_PLOTS);
    std::fs::create_dir_all(&dir).map_err(|source| PlotError::Write {
        path: dir.clone(),
        source,
    })?;
    charts
        .into_iter()
        .map(|(plot, chart)| chart.write(&dir).map(|_| plot))
        .collect()
}

/// The batch page's section of the sweep plots (empty without any).
pub fn sweep_section(plots: &[SweepPlot]) -> String {
    let mut html = String::new();
    let mut scene = None;
    for p in plots {
        if scene != Some(&p.scene) {
            if scene.is_some() {
                html.push_str("</div>\n");
            }
            html.push_str(&format!(
                "<h2>{}: key results against the swept values</h2>\n<div>\n",
                escape(&p.scene)
            ));
            scene = Some(&p.scene);
        }
        let src = link(&[SWEEP_PLOTS, &p.png]);
        html.push_str(&format!(
            "<figure class=\"plot\"><a href=\"{src}\"><img src=\"{src}\" alt=\"{} against {}\"></a>\
             <figcaption>{} against {}</figcaption></figure>\n",
            escape(&p.result),
            escape(&p.key),
            escape(&p.result),
            escape(&p.key)
        ));
    }
    if scene.is_some() {
        html.push_str("</div>\n");
    }
    html
}

#[cfg(test)]
mod tests {
    use super::*;

    fn variant(k: usize, e: &str, f: &str, u: &str) -> Row {
        Row {
            job: format!("sq/{k}"),
            scene: "sq".into(),
            variant: k.to_string(),
            values: vec![
                ("materials.steel.youngs_modulus".into(), e.into()),
                ("bodies.square.loads.1.force.1".into(), f.into()),
            ],
            status: "ok".into(),
            max_displacement: u.into(),
            ..Row::default()
        }
    }

    #[test]
    fn each_result_against_each_numeric_key_one_line_per_other_value() {
        let rows = vec![
            variant(1, "70e9", "100.0", "3e-6"),
            variant(2, "70e9", "200.0", "6e-6"),
            variant(3, "200e9", "100.0", "1.05e-6"),
            variant(4, "200e9", "200.0", "2.1e-6"),
        ];
        let charts = sweep_charts(&rows);
        // Two keys, one result present (largest displacement).
        assert_eq!(charts.len(), 2);
        let (plot, chart) = &charts[0];
        assert_eq!(plot.key, "materials.steel.youngs_modulus");
        assert_eq!(plot.png, "sq.1.max_displacement.png");
        assert_eq!(chart.series.len(), 2);
        assert_eq!(chart.series[0].name, "bodies.square.loads.1.force.1 = 100");
        assert_eq!(chart.series[0].points, vec![(70e9, 3e-6), (200e9, 1.05e-6)]);
        let (_, by_force) = &charts[1];
        assert_eq!(
            by_force.series[1].name,
            "materials.steel.youngs_modulus = 200 GPa"
        );
        assert_eq!(
            by_force.series[1].points,
            vec![(100.0, 1.05e-6), (200.0, 2.1e-6)]
        );
    }

    #[test]
    fn list_values_and_a_single_value_make_no_plot() {
        let mut rows = vec![
            variant(1, "70e9", "100.0", "1"),
            variant(2, "70e9", "100.0", "2"),
        ];
        rows[1].values[1].1 = "[1.0, 2.0]".into();
        assert!(sweep_charts(&rows).is_empty());
    }
}
