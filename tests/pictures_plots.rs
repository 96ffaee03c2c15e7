//! Plots that show what happened (issue 35, item 4), and `linkage render` drawing the plots
//! and the report again: the force an obstacle pushes with against its travel (a peak and a
//! fall), reaction totals that cancel left out, "step fraction" where the schedules do not
//! give the load factor.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(format!("{name}.toml"))
}

/// Run `linkage` with `args`; panics with the output when it fails. Returns stdout.
fn ok(args: &[&std::ffi::OsStr]) -> String {
    let o = linkage().args(args).output().unwrap();
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Run the bundled scene `name` with `--png --no-gif`-like settings into `out`.
fn run_png(name: &str, out: &Path) -> PathBuf {
    ok(&[
        "run".as_ref(),
        scene(name).as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--png".as_ref(),
    ]);
    out.join(name)
}

/// The points of `dir/plots/<name>.csv` (series, x, y), after checking its header.
fn points(dir: &Path, name: &str, columns: (&str, &str)) -> Vec<(String, f64, f64)> {
    let path = dir.join("plots").join(format!("{name}.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("series,{},{},label", columns.0, columns.1)
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.splitn(4, ',').collect();
            (
                f[0].trim_matches('"').to_string(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
            )
        })
        .collect()
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(
        &std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())),
    )
    .unwrap()
}

#[test]
fn the_notched_beam_plots_the_cylinder_force_against_its_travel_with_a_peak_and_a_fall() {
    let out = tempfile::tempdir().unwrap();
    let dir = run_png("notched_beam", out.path());
    let p = points(&dir, "load_displacement", ("travel_m", "force_N"));
    let summary = json(&dir.join("summary.json"));
    let steps = summary["steps"].as_array().unwrap();
    assert_eq!(p.len(), steps.len(), "one point per solved step");
    // The travel: 0.35 mm at the last of 20 steps, a linear ramp (`travel` of the scene).
    for ((_, x, _), s) in p.iter().zip(steps) {
        let k = s["step"].as_f64().unwrap();
        assert!(
            (x - 0.35e-3 * k / 20.0).abs() < 1e-12,
            "step {k}: travel {x}"
        );
    }
    // The force: the summary's contact force of the cylinder on the beam, downwards.
    for ((name, _, f), s) in p.iter().zip(steps) {
        assert_eq!(name, "obstacle 'cylinder'");
        let fy: f64 = s["contact_forces"]
            .as_array()
            .map(|pairs| {
                pairs
                    .iter()
                    .filter(|q| q["with"] == "cylinder")
                    .map(|q| q["force"][1].as_f64().unwrap())
                    .sum()
            })
            .unwrap_or(0.0);
        assert!(
            (f + fy).abs() <= 1e-9 * fy.abs().max(1.0),
            "{f} against {fy}"
        );
    }
    let (peak_at, peak) = p
        .iter()
        .enumerate()
        .map(|(i, q)| (i, q.2))
        .fold((0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    let last = p.last().unwrap().2;
    eprintln!(
        "peak {peak:.1} N at step {peak_at} of {}, last {last:.1} N; forces {:?}",
        p.len() - 1,
        p.iter().map(|q| q.2.round()).collect::<Vec<_>>()
    );
    assert!(p[0].2.abs() < 1e-9, "nothing pushes at step 0: {}", p[0].2);
    assert!(
        peak_at > 0 && peak_at + 1 < p.len(),
        "the peak is inside the run"
    );
    assert!(peak > 1000.0, "{peak} N");
    assert!(last < 0.7 * peak, "the fall: last {last} N, peak {peak} N");
    // The beam balances the push: the support reactions of the last stored step sum to it.
    let mut stored: Vec<PathBuf> = std::fs::read_dir(dir.join("steps"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    stored.sort();
    let last_step = json(stored.last().unwrap());
    let ry: f64 = last_step["bodies"][0]["reactions"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["force"][1].as_f64().unwrap())
        .sum();
    assert!(
        (ry - last).abs() <= 1e-6 * peak,
        "reactions {ry} N against the push {last} N"
    );
    // No loads: the load factor is the step fraction, and the plots say so.
    assert_eq!(json(&dir.join("plot_settings.json"))["step_fraction"], true);
    let svg = std::fs::read_to_string(dir.join("plots/breaks.svg")).unwrap();
    assert!(svg.contains("step fraction at the break"), "{svg}");
    assert!(!svg.contains("load factor"));
}

#[test]
fn one_linear_load_keeps_the_name_load_factor() {
    let out = tempfile::tempdir().unwrap();
    let dir = run_png("paper_overload", out.path());
    assert_eq!(
        json(&dir.join("plot_settings.json"))["step_fraction"],
        false
    );
    let svg = std::fs::read_to_string(dir.join("plots/load_displacement.svg")).unwrap();
    assert!(svg.contains("load factor (-)"));
    assert!(!svg.contains("step fraction"));
}

/// paper_square with two loads on different schedules: the load factor written is then the
/// step fraction, and the plots call it so.
#[test]
fn loads_on_different_schedules_are_plotted_against_the_step_fraction() {
    let out = tempfile::tempdir().unwrap();
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for f in ["square.nodes", "square.links"] {
        std::fs::copy(src.join(f), out.path().join(f)).unwrap();
    }
    let text = std::fs::read_to_string(src.join("paper_square.toml")).unwrap();
    assert!(text.contains("\nsteps = 1\n"));
    let steps = 4;
    let text = text.replace("\nsteps = 1\n", "\nsteps = 4\n");
    let schedule: Vec<String> = (1..=steps)
        .map(|k| format!("{}", (k as f64 / steps as f64).powi(2)))
        .collect();
    let path = out.path().join("square.toml");
    let load = format!(
        "[[bodies.loads]]\nnodes = [2]\nforce = [0.0, 1.0]\nschedule = [{}]\n",
        schedule.join(", ")
    );
    std::fs::write(&path, format!("{text}\n{load}\n[output]\nplot_node = 2\n")).unwrap();
    ok(&[
        "run".as_ref(),
        path.as_os_str(),
        "--out".as_ref(),
        out.path().as_os_str(),
        "--png".as_ref(),
    ]);
    let dir = out.path().join("paper_square");
    assert_eq!(json(&dir.join("plot_settings.json"))["step_fraction"], true);
    let summary = json(&dir.join("summary.json"));
    for s in summary["steps"].as_array().unwrap() {
        let k = s["step"].as_f64().unwrap();
        assert!((s["load_factor"].as_f64().unwrap() - k / steps as f64).abs() < 1e-15);
    }
    for name in ["load_displacement", "reaction"] {
        let svg = std::fs::read_to_string(dir.join(format!("plots/{name}.svg"))).unwrap();
        assert!(svg.contains("step fraction (-)"), "{name}");
        assert!(!svg.contains("load factor"), "{name}");
    }
}

#[test]
fn render_draws_the_plots_and_the_report_again_with_the_stored_plot_settings() {
    let out = tempfile::tempdir().unwrap();
    let dir = run_png("notched_beam", out.path());
    let plots = dir.join("plots");
    let before = std::fs::read(plots.join("load_displacement.csv")).unwrap();
    let report = out.path().join("index.html");
    let page = dir.join("index.html");
    assert!(report.is_file() && page.is_file());
    std::fs::remove_dir_all(&plots).unwrap();
    std::fs::remove_file(&report).unwrap();
    std::fs::remove_file(&page).unwrap();
    let said = ok(&[
        "render".as_ref(),
        dir.as_os_str(),
        "--no-gif".as_ref(),
        "--steps".as_ref(),
        "last".as_ref(),
    ]);
    // The same load–displacement points (the cylinder's push: the plot settings were kept).
    assert_eq!(
        std::fs::read(plots.join("load_displacement.csv")).unwrap(),
        before
    );
    assert!(plots.join("breaks.png").is_file());
    assert!(said.contains("plots"), "{said}");
    // The report: the batch page and the scene's page, linking the plots.
    assert!(report.is_file(), "{said}");
    let text = std::fs::read_to_string(&page).unwrap();
    assert!(text.contains("plots/load_displacement.png"), "{text}");
    // Drawn elsewhere (--out): the plots go there, the report is left alone.
    let other = out.path().join("elsewhere");
    std::fs::remove_file(&report).unwrap();
    ok(&[
        "render".as_ref(),
        dir.as_os_str(),
        "--out".as_ref(),
        other.as_os_str(),
        "--no-gif".as_ref(),
        "--steps".as_ref(),
        "last".as_ref(),
    ]);
    assert_eq!(
        std::fs::read(other.join("plots/load_displacement.csv")).unwrap(),
        before
    );
    assert!(!report.exists());
}
