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

/// Two bars side by side, each its own body (a 1 m bar along x, pinned at its left end and
/// held in y at its right end): bar `a` pulled by 1 kN, bar `b` by the swept force.
const TWO_BARS: &str = r#"name = "bars"
steps = 2

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "a"
nodes = "a.nodes"
links = "bar.links"
material = "steel"

[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]

[[bodies.supports]]
nodes = [2]
fix = ["y"]

[[bodies.loads]]
nodes = [2]
force = [1000.0, 0.0]

[[bodies]]
name = "b"
nodes = "b.nodes"
links = "bar.links"
material = "steel"

[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]

[[bodies.supports]]
nodes = [2]
fix = ["y"]

[[bodies.loads]]
nodes = [2]
force = [1000.0, 0.0]

[output]
png = true
gif = false
width = 480
height = 270

[sweep]
"bodies.b.loads.1.force" = [[1000.0, 0.0], [4000.0, 0.0]]
"#;

#[test]
fn a_sweeps_variants_share_one_magnification_and_one_colour_range() {
    use linkage::render::{view_for, ColourScale, RenderOptions, RunExtent, SharedScale};
    use linkage::scene::RunResults;
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("a.nodes"), "0 0\n1 0\n").unwrap();
    std::fs::write(tmp.path().join("b.nodes"), "0 0.5\n1 0.5\n").unwrap();
    std::fs::write(tmp.path().join("bar.links"), "1 2\n").unwrap();
    let file = tmp.path().join("bars.toml");
    std::fs::write(&file, TWO_BARS).unwrap();
    let out = tmp.path().join("out");
    let said = ok(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let dirs = [out.join("bars/1"), out.join("bars/2")];
    let runs: Vec<RunResults> = dirs.iter().map(|d| RunResults::read(d).unwrap()).collect();
    // Their own scales differ: bar b stretches 50 µm or 200 µm (F L / E A), so the automatic
    // factors are 2000 and 500; its stress is 10 or 40 MPa.
    let own: Vec<RunExtent> = runs.iter().map(|r| RunExtent::of_run(r, None)).collect();
    assert_eq!(
        (own[0].magnification, own[1].magnification),
        (2000.0, 500.0)
    );
    assert!((own[0].stress_limit - 1e7).abs() < 1e-3 && (own[1].stress_limit - 4e7).abs() < 1e-3);
    // One scale, kept in both folders: the smaller factor, the larger stress range.
    let scales: Vec<SharedScale> = dirs.iter().map(|d| SharedScale::read(d).unwrap()).collect();
    assert_eq!(scales[0], scales[1]);
    let scale = &scales[0];
    assert_eq!(scale.magnification, 500.0);
    assert_eq!(scale.variants, 2);
    assert!((scale.stress_limit - 4e7).abs() < 1e-3, "{scale:?}");
    assert!(said.contains(&scale.describe()), "{said}");
    assert!(scale.describe().contains("×500"), "{}", scale.describe());
    // The report states it.
    let report = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(report.contains("one scale for all variants"), "{report}");
    assert!(report.contains("displacements drawn ×500"), "{report}");
    // Pixels: bar a carries 10 MPa in both variants and is drawn in the same colour, the one
    // 10 MPa has on the shared range (−40 to +40 MPa), not the full red of its own range.
    let o = RenderOptions {
        width: 480,
        height: 270,
        ..RenderOptions::default()
    };
    let want = ColourScale::new(4e7).colour(1e7);
    let mut seen = Vec::new();
    for (dir, run) in dirs.iter().zip(&runs) {
        let ext = scale.extent_of(run);
        assert_eq!(ext.shared_by, Some(2));
        let view = view_for(&o, &ext);
        let step = run.steps.last().unwrap();
        let a = &step.bodies[0];
        let at = |n: usize| {
            let p = &run.model.bodies[0].nodes[n];
            let u = &a.displacements[n];
            nalgebra::Vector3::new(p[0] + 500.0 * u[0], p[1] + 500.0 * u[1], 0.0)
        };
        assert!((a.stresses[0] - 1e7).abs() < 1.0, "{}", a.stresses[0]);
        let mid = view.project(&((at(0) + at(1)) / 2.0));
        let png = tiny_skia::Pixmap::decode_png(
            &std::fs::read(dir.join(format!("png/{}.png", run.stem(step.step)))).unwrap(),
        )
        .unwrap();
        let px = png.pixel(mid[0] as u32, mid[1] as u32).unwrap();
        let rgb = [px.red(), px.green(), px.blue()].map(|c| c as f32 / 255.0);
        eprintln!(
            "{}: bar a at {mid:?} is {rgb:?}, want {want:?}",
            dir.display()
        );
        assert!(
            (rgb[0] - want.0).abs() < 0.03
                && (rgb[1] - want.1).abs() < 0.03
                && (rgb[2] - want.2).abs() < 0.03,
            "{rgb:?} against {want:?}"
        );
        seen.push(rgb);
    }
    for k in 0..3 {
        assert!((seen[0][k] - seen[1][k]).abs() <= 2.0 / 255.0, "{seen:?}");
    }
}

/// `notched_beam` pressed by a named support on the two top nodes at midspan (moved down
/// 0.35 mm over the steps, as the cylinder travels) instead of the cylinder, with `extra`
/// in its `[output]`.
fn pressed_beam(dir: &Path, output: &str) -> PathBuf {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(scenes.join("notched_beam.toml")).unwrap();
    let body = text.split("[[obstacles]]").next().unwrap();
    let body = body
        .replace("name = \"notched_beam\"", "name = \"pressed_beam\"")
        .replace(
            "\"notched_beam.nodes\"",
            &format!(
                "{:?}",
                scenes.join("notched_beam.nodes").display().to_string()
            ),
        )
        .replace(
            "\"notched_beam.links\"",
            &format!(
                "{:?}",
                scenes.join("notched_beam.links").display().to_string()
            ),
        );
    let path = dir.join("pressed_beam.toml");
    std::fs::write(
        &path,
        format!(
            "{body}\n[[bodies.supports]]\nname = \"press\"\ninside = {{ min = [0.38, 0.19], max = [0.42, 0.21] }}\nfix = [\"y\"]\ndisplacement = [0.0, -0.00035]\n\n[output]\n{output}\n"
        ),
    )
    .unwrap();
    path
}

#[test]
fn the_notched_beam_pressed_by_a_named_support_plots_its_force_with_a_peak_and_a_fall() {
    let tmp = tempfile::tempdir().unwrap();
    let file = pressed_beam(tmp.path(), "plot = { support = \"press\" }");
    let out = tmp.path().join("out");
    // Without pictures: the plot settings are kept, and `render` draws the plots from them.
    ok(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let dir = out.join("pressed_beam");
    assert!(!dir.join("plots").exists());
    let settings = json(&dir.join("plot_settings.json"));
    assert_eq!(settings["place"]["label"], "support 'press'");
    assert_eq!(settings["place"]["nodes"].as_array().unwrap().len(), 2);
    ok(&[
        "render".as_ref(),
        dir.as_os_str(),
        "--no-gif".as_ref(),
        "--steps".as_ref(),
        "last".as_ref(),
    ]);
    let p = points(&dir, "load_displacement", ("displacement_m", "force_N"));
    // From the step files: the press's reactions (y) summed, and its nodes' displacement.
    let nodes: Vec<u64> = settings["place"]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_u64().unwrap() + 1)
        .collect();
    let mut stored: Vec<PathBuf> = std::fs::read_dir(dir.join("steps"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    stored.sort();
    assert_eq!(p.len(), stored.len(), "one point per stored step");
    let mut largest: f64 = 0.0;
    for ((name, x, f), file) in p.iter().zip(&stored) {
        assert_eq!(name, "support 'press'");
        let step = json(file);
        let body = &step["bodies"][0];
        let ry: f64 = body["reactions"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| nodes.contains(&r["node"].as_u64().unwrap()))
            .map(|r| r["force"][1].as_f64().unwrap())
            .sum();
        // The press pushes down (−y), the beam pushes it up: along the press, −ry, and the
        // plot signs it so that the peak is positive.
        if ry.abs() > largest.abs() {
            largest = ry;
        }
        let uy: f64 = nodes
            .iter()
            .map(|&n| body["displacements"][n as usize - 1][1].as_f64().unwrap())
            .sum::<f64>()
            / nodes.len() as f64;
        assert!((x + uy).abs() < 1e-15, "displacement {x} against {uy}");
        let k = step["step"].as_f64().unwrap();
        assert!((x - 0.35e-3 * k / 20.0).abs() < 1e-12, "step {k}: {x}");
        assert!(
            (f.abs() - ry.abs()).abs() <= 1e-9 * ry.abs().max(1.0),
            "{f} against {ry}"
        );
    }
    let (peak_at, peak) = p
        .iter()
        .enumerate()
        .map(|(i, q)| (i, q.2))
        .fold((0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a });
    let last = p.last().unwrap().2;
    eprintln!(
        "peak {peak:.1} N at point {peak_at} of {}, last {last:.1} N; forces {:?}",
        p.len(),
        p.iter().map(|q| q.2.round()).collect::<Vec<_>>()
    );
    // The peak is the largest reaction of the press, to 1e-9.
    assert!(
        (peak - largest.abs()).abs() <= 1e-9 * largest.abs(),
        "{peak} against {largest}"
    );
    assert!(peak > 1000.0, "{peak} N");
    assert!(p[0].2.abs() < 1e-9 * peak, "nothing pushes at step 0");
    assert!(
        peak_at > 0 && peak_at + 1 < p.len(),
        "the peak is inside the run"
    );
    assert!(last < 0.7 * peak, "the fall: last {last} N, peak {peak} N");
}

#[test]
fn a_plot_of_an_unknown_support_is_an_error_naming_the_file_and_line() {
    let tmp = tempfile::tempdir().unwrap();
    for (output, says) in [
        (
            "plot = { support = \"pul\" }",
            "no support of that name; the scene's named supports: 'press'",
        ),
        ("plot = { body = \"beam\", nodes = [0] }", "from 1 to"),
        ("plot = { support = \"press\", nodes = [1] }", "not both"),
    ] {
        let file = pressed_beam(tmp.path(), output);
        let o = linkage().arg("check").arg(&file).output().unwrap();
        let err = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!o.status.success(), "{output}: {err}");
        assert!(err.contains("pressed_beam.toml:"), "{output}: {err}");
        assert!(err.contains(says), "{output}: {err}");
    }
}

#[test]
fn a_node_set_plot_of_the_paper_square_shows_its_load_against_its_displacement() {
    // The paper's square, 200 N in +x at node 2: the force at node 2 (its load) along the
    // axis of the largest force (x) against node 2's x displacement.
    let tmp = tempfile::tempdir().unwrap();
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for f in ["square.nodes", "square.links"] {
        std::fs::copy(scenes.join(f), tmp.path().join(f)).unwrap();
    }
    let text = std::fs::read_to_string(scenes.join("paper_square.toml")).unwrap();
    let file = tmp.path().join("square.toml");
    std::fs::write(
        &file,
        format!("{text}\n[output]\nplot = {{ body = \"square\", nodes = [2] }}\n"),
    )
    .unwrap();
    let out = tmp.path().join("out");
    ok(&[
        "run".as_ref(),
        file.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--png".as_ref(),
    ]);
    let dir = out.join("paper_square");
    let p = points(&dir, "load_displacement", ("displacement_m", "force_N"));
    assert_eq!(p.len(), 2);
    let last = json(&dir.join("steps/0001.json"));
    let ux = last["bodies"][0]["displacements"][1][0].as_f64().unwrap();
    assert_eq!(p[0].0, "node 2 of body 'square'");
    assert!(p[0].1.abs() < 1e-15 && p[0].2.abs() < 1e-9, "{:?}", p[0]);
    assert!((p[1].1 - ux).abs() <= 1e-15, "{} against {ux}", p[1].1);
    assert!((p[1].2 - 200.0).abs() <= 1e-9, "{}", p[1].2);
}
