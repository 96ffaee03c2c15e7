//! Plots written with the pictures of a run (`--png`): which plots each kind of scene gets and
//! the points each shows, read back from the CSV written beside it and compared with
//! `summary.json` and the step files; `[output] plot_node` and its bad values.

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

/// Run `scenes` with `--png` into `out`; panics with the output when the run fails.
fn run_png(scenes: &[PathBuf], out: &Path) {
    let o = linkage()
        .arg("run")
        .args(scenes)
        .arg("--out")
        .arg(out)
        .arg("--png")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn summary(dir: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

/// The rows of `plots/<name>.csv` as (series, x, y, label), after checking the header.
fn points(dir: &Path, name: &str, columns: (&str, &str)) -> Vec<(String, f64, f64, String)> {
    let path = dir.join("plots").join(format!("{name}.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    for ext in ["png", "svg"] {
        let p = dir.join("plots").join(format!("{name}.{ext}"));
        assert!(
            std::fs::metadata(&p).is_ok_and(|m| m.len() > 1000),
            "{} missing or empty",
            p.display()
        );
    }
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("series,{},{},label", columns.0, columns.1)
    );
    lines
        .map(|l| {
            // Series names here have no commas; labels may (`step 3, body ...`).
            let f: Vec<&str> = l.splitn(4, ',').collect();
            (
                f[0].to_string(),
                f[1].parse().unwrap(),
                f[2].parse().unwrap(),
                f[3].trim_matches('"').to_string(),
            )
        })
        .collect()
}

fn plot_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join("plots"))
        .unwrap()
        .flatten()
        .filter_map(|e| e.file_name().to_str().map(str::to_string))
        .filter_map(|n| n.strip_suffix(".csv").map(str::to_string))
        .collect();
    names.sort();
    names
}

#[test]
fn a_linear_scene_gets_its_load_displacement_curve_one_point_per_step() {
    let out = tempfile::tempdir().unwrap();
    run_png(&[scene("paper_overload")], out.path());
    let dir = out.path().join("paper_overload");
    let s = summary(&dir);
    let steps = s["steps"].as_array().unwrap();
    let p = points(
        &dir,
        "load_displacement",
        ("max_displacement_m", "load_factor"),
    );
    assert_eq!(
        p.len(),
        steps.len(),
        "one point per solved step, step 0 too"
    );
    assert_eq!(p.len(), 11);
    for (point, step) in p.iter().zip(steps) {
        // Written in shortest round-trip form: the very numbers of summary.json.
        assert_eq!(point.1, step["max_displacement"].as_f64().unwrap());
        assert_eq!(point.2, step["load_factor"].as_f64().unwrap());
        assert_eq!(point.3, format!("step {}", step["step"]));
    }
    // Linear, no contact, no fracture: no other plot.
    assert_eq!(plot_names(&dir), ["load_displacement"]);
}

#[test]
fn a_nonlinear_scene_gets_its_newton_residuals_one_point_per_iteration() {
    let out = tempfile::tempdir().unwrap();
    run_png(&[scene("cable_net")], out.path());
    let dir = out.path().join("cable_net");
    let s = summary(&dir);
    let residuals: Vec<(u64, f64)> = s["steps"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|st| {
            let k = st["step"].as_u64().unwrap();
            st["residuals"]
                .as_array()
                .into_iter()
                .flatten()
                .map(move |r| (k, r.as_f64().unwrap()))
        })
        .filter(|(_, r)| *r > 0.0)
        .collect();
    assert!(
        residuals.len() >= 6,
        "{} Newton iterations",
        residuals.len()
    );
    let p = points(&dir, "residuals", ("iteration", "relative_residual"));
    assert_eq!(p.len(), residuals.len());
    for (i, (point, (k, r))) in p.iter().zip(&residuals).enumerate() {
        assert_eq!(point.0, format!("step {k}"));
        assert_eq!(
            point.1,
            (i + 1) as f64,
            "iterations numbered on over the steps"
        );
        assert_eq!(point.2, *r);
    }
    assert_eq!(plot_names(&dir), ["load_displacement", "residuals"]);
}

#[test]
fn a_contact_scene_gets_the_total_force_of_each_pair_at_every_step() {
    let out = tempfile::tempdir().unwrap();
    run_png(&[scene("disk_on_floor")], out.path());
    let dir = out.path().join("disk_on_floor");
    let s = summary(&dir);
    let steps = s["steps"].as_array().unwrap();
    let p = points(&dir, "contact_forces", ("step", "contact_force_N"));
    // One pair, the disk on the floor: one point per solved step.
    assert!(p.iter().all(|q| q.0 == "disk from floor"), "{p:?}");
    assert_eq!(p.len(), steps.len());
    for (point, step) in p.iter().zip(steps) {
        let expected = step["contact_forces"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|c| c["body"] == "disk" && c["with"] == "floor")
            .map_or(0.0, |c| {
                c["force"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|f| f.as_f64().unwrap().powi(2))
                    .sum::<f64>()
                    .sqrt()
            });
        assert_eq!(point.1, step["step"].as_f64().unwrap());
        assert!((point.2 - expected).abs() <= 1e-12 * expected.max(1.0));
    }
    assert!(p.last().unwrap().2 > 0.0, "the disk presses on the floor");
    assert!(plot_names(&dir).contains(&"contact_forces".to_string()));
}

#[test]
fn a_fracture_scene_gets_one_point_per_break_at_its_load_factor() {
    let out = tempfile::tempdir().unwrap();
    run_png(&[scene("paper_fracture")], out.path());
    let dir = out.path().join("paper_fracture");
    let s = summary(&dir);
    let breaks = s["breaks"].as_array().unwrap();
    assert!(!breaks.is_empty());
    let p = points(&dir, "breaks", ("load_factor", "broken_members"));
    assert_eq!(p.len(), breaks.len());
    for (k, (point, b)) in p.iter().zip(breaks).enumerate() {
        assert_eq!(point.1, b["load_factor"].as_f64().unwrap());
        assert_eq!(point.2, (k + 1) as f64);
        assert_eq!(
            point.3,
            format!(
                "step {}, body '{}' member {}",
                b["step"],
                b["body"].as_str().unwrap(),
                b["member"]
            )
        );
    }
}

/// A softening scene: its teeth are recorded in `breaks` but are not breaks; the plot counts
/// a member when its last tooth breaks it, and the report says breaks and teeth apart.
#[test]
fn softening_teeth_are_not_counted_as_breaks() {
    let out = tempfile::tempdir().unwrap();
    run_png(&[scene("notched_beam")], out.path());
    let dir = out.path().join("notched_beam");
    let s = summary(&dir);
    let all = s["breaks"].as_array().unwrap();
    let broke: Vec<&Value> = all.iter().filter(|b| b.get("tooth").is_none()).collect();
    let teeth = all.len() - broke.len();
    assert!(
        !broke.is_empty() && teeth > 0,
        "{} breaks, {teeth} teeth",
        broke.len()
    );
    let p = points(&dir, "breaks", ("load_factor", "broken_members"));
    assert_eq!(p.len(), broke.len());
    for (k, (point, b)) in p.iter().zip(&broke).enumerate() {
        assert_eq!(point.1, b["load_factor"].as_f64().unwrap());
        assert_eq!(point.2, (k + 1) as f64);
    }
    let report = std::fs::read_to_string(out.path().join("index.html")).unwrap();
    assert!(
        report.contains(&format!(
            "({} broke in all), {teeth} softening teeth passed",
            broke.len()
        )),
        "{report}"
    );
}

/// `scenes/paper_square.toml` with `[output]` lines `extra`, written into `dir`.
fn square_with(dir: &Path, extra: &str) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(src.join("paper_square.toml")).unwrap();
    for f in ["square.nodes", "square.links"] {
        if src.join(f).exists() {
            std::fs::copy(src.join(f), dir.join(f)).unwrap();
        }
    }
    let path = dir.join("square.toml");
    std::fs::write(&path, format!("{text}\n[output]\n{extra}\n")).unwrap();
    path
}

#[test]
fn plot_node_plots_that_nodes_displacement_and_the_reaction_total() {
    let out = tempfile::tempdir().unwrap();
    let path = square_with(out.path(), "plot_node = 2");
    run_png(&[path], out.path());
    let dir = out.path().join("paper_square");
    let p = points(&dir, "load_displacement", ("displacement_m", "load_factor"));
    let stored: Vec<Value> = std::fs::read_dir(dir.join("steps"))
        .unwrap()
        .flatten()
        .map(|e| serde_json::from_slice(&std::fs::read(e.path()).unwrap()).unwrap())
        .collect();
    assert_eq!(p.len(), stored.len());
    let mut stored = stored;
    stored.sort_by_key(|s| s["step"].as_u64());
    for (point, step) in p.iter().zip(&stored) {
        let u = &step["bodies"][0]["displacements"][1];
        let magnitude = u
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap().powi(2))
            .sum::<f64>()
            .sqrt();
        assert_eq!(point.0, "body 'square' node 2");
        assert!((point.1 - magnitude).abs() <= 1e-15 * magnitude.max(1e-30));
    }
    assert!(p.last().unwrap().1 > 0.0);
    // The reaction total: x per stored step; the supports answer the 200 N in x. The y
    // reactions cancel (no load in y): that total is round-off and left out.
    let r = points(&dir, "reaction", ("load_factor", "reaction_N"));
    assert_eq!(r.len(), stored.len());
    assert!(r.iter().all(|q| q.0 == "Rx"), "{r:?}");
    let last_x = r.iter().rfind(|q| q.0 == "Rx").unwrap().2;
    assert!((last_x + 200.0).abs() < 1e-9, "{last_x}");
}

#[test]
fn a_bad_plot_node_is_named_with_its_scene_line() {
    let out = tempfile::tempdir().unwrap();
    for (value, expect) in [
        ("plot_node = 0", "node numbers start at 1"),
        ("plot_node = 5", "body 'square' has 4 nodes"),
        (
            "plot_node = 2\nplot_body = \"disk\"",
            "no body of that name",
        ),
    ] {
        let path = square_with(out.path(), value);
        let text = std::fs::read_to_string(&path).unwrap();
        let key = if value.contains("plot_body") {
            "plot_body"
        } else {
            "plot_node"
        };
        let line = text.lines().position(|l| l.starts_with(key)).unwrap() + 1;
        let o = linkage()
            .arg("run")
            .arg(&path)
            .arg("--out")
            .arg(out.path().join("out"))
            .output()
            .unwrap();
        assert!(!o.status.success());
        let said =
            String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
        assert!(
            said.contains(&format!("square.toml:{line}: [output] {key} ="))
                && said.contains(expect),
            "{said}"
        );
    }
}
