//! Sweeps, the batch table, shards, `linkage collect` and resumed batches, end to end.

mod common;

use common::{assert_same_results, table_without_seconds};
use linkage::scene::{expand_sweep, SceneError};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn linkage(args: &[&str], out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The paper's square (Fig. 5) named `sq`, 2 steps, with Young's modulus `e` (Pa) and the force
/// `f` (N, x) at node 2, and `extra` appended (a `[sweep]`).
fn square(e: &str, f: &str, extra: &str) -> String {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    format!(
        r#"name = "sq"
steps = 2

[[materials]]
name = "steel"
youngs_modulus = {e}
area = 1e-4
strength = 250e6

[[bodies]]
name = "square"
nodes = "{}"
links = "{}"
material = "steel"

[[bodies.supports]]
nodes = [3]
fix = ["x", "y"]

[[bodies.supports]]
nodes = [4]
fix = ["y"]

[[bodies.loads]]
nodes = [2]
force = [{f}, 0.0]
{extra}"#,
        scenes.join("square.nodes").display(),
        scenes.join("square.links").display(),
    )
}

const GRID: &str = r#"
[sweep]
"materials.steel.youngs_modulus" = [70e9, 200e9]
"bodies.square.loads.1.force" = [[100.0, 0.0], [200.0, 0.0], [400.0, 0.0]]
"#;

fn write(dir: &Path, file: &str, text: &str) -> PathBuf {
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_grid_of_two_by_three_gives_six_variants_equal_to_six_hand_written_scenes() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "sq.toml", &square("200e9", "200.0", GRID));
    let out = dir.path().join("out");
    let o = linkage(&["run", scene.to_str().unwrap()], &out);
    assert!(o.status.success(), "{}", text(&o));
    // Grid order: the last key varies fastest.
    let mut k = 0;
    for e in ["70e9", "200e9"] {
        for f in ["100.0", "200.0", "400.0"] {
            k += 1;
            let hand = write(dir.path(), &format!("hand{k}.toml"), &square(e, f, ""));
            let hand_out = dir.path().join(format!("hand{k}"));
            let o = linkage(&["run", hand.to_str().unwrap()], &hand_out);
            assert!(o.status.success(), "{}", text(&o));
            assert_same_results(&out.join("sq").join(k.to_string()), &hand_out.join("sq"));
        }
    }
    assert!(!out.join("sq").join("7").exists());
    let variants: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("sq/variants.json")).unwrap()).unwrap();
    assert_eq!(variants.as_array().unwrap().len(), 6);
    assert_eq!(variants[4]["folder"], "sq/5");
    assert_eq!(
        variants[4]["values"]["materials.steel.youngs_modulus"],
        200e9
    );
    assert_eq!(
        variants[4]["values"]["bodies.square.loads.1.force"],
        serde_json::json!([200.0, 0.0])
    );
    // The table: one row per variant with its values; the linear square's displacement goes
    // as F / E (tolerance 1e-12 relative); the peak stress is the stored step's stress of
    // largest magnitude, and its ratio that over the strength 250 MPa.
    let rows = table_without_seconds(&out.join("batch.csv"));
    assert_eq!(rows.len(), 6);
    let cell = |r: &linkage::scene::batch::Row, key: &str| {
        r.values.iter().find(|(k, _)| k == key).unwrap().1.clone()
    };
    assert_eq!(rows[0].job, "sq/1");
    assert_eq!(
        cell(&rows[0], "materials.steel.youngs_modulus"),
        "70000000000.0"
    );
    assert_eq!(
        cell(&rows[2], "bodies.square.loads.1.force"),
        "[400.0, 0.0]"
    );
    let u = |r: &linkage::scene::batch::Row| r.max_displacement.parse::<f64>().unwrap();
    let expected = (400.0 / 70e9) / (200.0 / 200e9);
    assert!((u(&rows[2]) / u(&rows[4]) - expected).abs() < 1e-12 * expected);
    let step: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("sq/5/steps/0002.json")).unwrap()).unwrap();
    let stresses: Vec<f64> = step["bodies"][0]["stresses"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_f64().unwrap())
        .collect();
    let hand = stresses
        .iter()
        .copied()
        .fold(0.0, |a: f64, s| if s.abs() > a.abs() { s } else { a });
    let peak: f64 = rows[4].peak_stress.parse().unwrap();
    assert_eq!(peak, hand);
    let ratio: f64 = rows[4].stress_ratio.parse().unwrap();
    assert!((ratio - hand.abs() / 250e6).abs() < 1e-15);
    // The summary's last step carries the same peak; results written before it did (no such
    // fields) give the same row, read back from the step file when the batch skips them.
    let summary_path = out.join("sq/5/summary.json");
    let mut summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&summary_path).unwrap()).unwrap();
    let last = summary["steps"].as_array_mut().unwrap().last_mut().unwrap();
    assert_eq!(last["peak_stress"].as_f64(), Some(hand));
    assert!((last["stress_ratio"].as_f64().unwrap() - hand.abs() / 250e6).abs() < 1e-15);
    let old = last.as_object_mut().unwrap();
    old.remove("peak_stress");
    old.remove("stress_ratio");
    std::fs::write(&summary_path, serde_json::to_vec(&summary).unwrap()).unwrap();
    let o = linkage(&["run", scene.to_str().unwrap()], &out);
    assert!(o.status.success(), "{}", text(&o));
    let again = table_without_seconds(&out.join("batch.csv"));
    assert_eq!(again[4].peak_stress, rows[4].peak_stress);
    assert_eq!(again[4].stress_ratio, rows[4].stress_ratio);
    for r in &rows {
        assert_eq!(
            (r.status.as_str(), r.nodes.as_str(), r.members.as_str()),
            ("ok", "4", "6")
        );
        assert_eq!(
            (r.steps.as_str(), r.overloaded.as_str(), r.broken.as_str()),
            ("2", "0", "")
        );
    }
}

#[test]
fn zip_mode_takes_the_ith_values_together() {
    let dir = tempfile::tempdir().unwrap();
    let zip = r#"
[sweep]
mode = "zip"
"materials.steel.youngs_modulus" = [70e9, 200e9, 100e9]
"bodies.square.loads.1.force" = [[100.0, 0.0], [200.0, 0.0], [400.0, 0.0]]
"steps" = [1, 2, 3]
"#;
    let scene = write(dir.path(), "sq.toml", &square("200e9", "200.0", zip));
    let variants = expand_sweep(&std::fs::read_to_string(&scene).unwrap(), &scene).unwrap();
    assert_eq!(variants.len(), 3);
    let out = dir.path().join("out");
    let o = linkage(&["run", scene.to_str().unwrap()], &out);
    assert!(o.status.success(), "{}", text(&o));
    let rows = table_without_seconds(&out.join("batch.csv"));
    assert_eq!(rows.len(), 3);
    for (r, steps) in rows.iter().zip(["1", "2", "3"]) {
        assert_eq!(r.steps, steps);
    }
    let hand = write(
        dir.path(),
        "hand.toml",
        &square("100e9", "400.0", "").replace("steps = 2", "steps = 3"),
    );
    let hand_out = dir.path().join("hand");
    assert!(linkage(&["run", hand.to_str().unwrap()], &hand_out)
        .status
        .success());
    assert_same_results(&out.join("sq/3"), &hand_out.join("sq"));
}

/// The error of `[sweep]` `body` in the square scene, checked to name `names` and its line.
fn sweep_error(body: &str, names: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(
        dir.path(),
        "bad.toml",
        &square("200e9", "200.0", &format!("\n[sweep]\n{body}\n")),
    );
    let text_of = std::fs::read_to_string(&scene).unwrap();
    let err = expand_sweep(&text_of, &scene).unwrap_err();
    let message = err.to_string();
    for n in names {
        assert!(
            message.contains(n),
            "{body:?}: {message:?} should name {n:?}"
        );
    }
    let SceneError::At { line, .. } = err else {
        panic!("{body:?}: {message}");
    };
    let sweep_line = text_of.lines().position(|l| l == "[sweep]").unwrap() + 1;
    assert!(line > sweep_line, "{body:?}: line {line} in {message}");
    // Nothing runs: the CLI fails before creating the output folder.
    let out = dir.path().join("out");
    let o = linkage(&["run", scene.to_str().unwrap()], &out);
    assert!(!o.status.success());
    assert!(text(&o).contains(names[0]), "{}", text(&o));
    assert!(!out.exists(), "{body:?} wrote {}", out.display());
}

#[test]
fn every_bad_key_is_an_error_naming_it_before_anything_runs() {
    sweep_error(
        r#""materials.iron.youngs_modulus" = [1e9]"#,
        &["materials.iron.youngs_modulus", "'iron'", "steel"],
    );
    sweep_error(
        r#""materials.steel.poisson" = [0.3]"#,
        &["materials.steel.poisson", "`poisson`"],
    );
    sweep_error(
        r#""gravity" = [9.81]"#,
        &["`gravity`", "the scene has no key"],
    );
    sweep_error(
        r#""bodies.square.loads.2.force" = [[1.0, 0.0]]"#,
        &["bodies.square.loads.2.force", "1 entry"],
    );
    sweep_error(
        r#""bodies.square.supports.0.fix" = [["x"]]"#,
        &["bodies.square.supports.0.fix", "from 1"],
    );
    sweep_error(
        r#""materials.steel.youngs_modulus" = ["stiff"]"#,
        &[
            "materials.steel.youngs_modulus",
            "string cannot replace a float",
        ],
    );
    sweep_error(
        r#""steps" = [2.5]"#,
        &["`steps`", "float cannot replace a integer"],
    );
    sweep_error(
        r#""bodies.square.loads.1.force" = [100.0]"#,
        &["bodies.square.loads.1.force", "float cannot replace a list"],
    );
    sweep_error(
        r#""bodies.square.loads.1.force" = [["a", "b"]]"#,
        &["bodies.square.loads.1.force", "in the list"],
    );
    sweep_error(
        r#""materials.steel.area.x" = [1.0]"#,
        &["materials.steel.area.x", "not a table or a list"],
    );
    sweep_error(
        r#""materials.steel.area" = 1e-4"#,
        &["materials.steel.area", "give a list"],
    );
    sweep_error(
        r#""materials.steel.area" = []"#,
        &["materials.steel.area", "at least one"],
    );
    sweep_error("mode = \"random\"\n\"steps\" = [1]", &["mode", "\"zip\""]);
    sweep_error(
        "mode = \"zip\"\n\"steps\" = [1, 2]\n\"materials.steel.area\" = [1e-4]",
        &["materials.steel.area", "2 values"],
    );
}

/// The table of `out/batch.csv` (or of `collect`) with each row's job.
fn jobs_of(rows: &[linkage::scene::batch::Row]) -> Vec<String> {
    rows.iter().map(|r| r.job.clone()).collect()
}

#[test]
fn three_shards_cover_every_job_once_and_collect_gives_the_unsharded_table() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "sq.toml", &square("200e9", "200.0", GRID));
    let square = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_square.toml");
    let missing = dir.path().join("missing.toml");
    let args = [
        scene.to_str().unwrap(),
        square.to_str().unwrap(),
        missing.to_str().unwrap(),
    ];
    let whole = dir.path().join("whole");
    let o = linkage(&[&["run"][..], &args].concat(), &whole);
    assert!(!o.status.success(), "the missing scene fails the batch");
    let expected = table_without_seconds(&whole.join("batch.csv"));
    assert_eq!(
        jobs_of(&expected),
        [
            "sq/1",
            "sq/2",
            "sq/3",
            "sq/4",
            "sq/5",
            "sq/6",
            "paper_square",
            "missing"
        ]
    );
    assert!(
        expected[7].status.starts_with("failed: "),
        "{:?}",
        expected[7]
    );
    let sharded = dir.path().join("sharded");
    let mut seen: Vec<String> = Vec::new();
    for i in 1..=3 {
        let shard = format!("{i}/3");
        let _ = linkage(
            &[&["run"][..], &args, &["--shard", &shard]].concat(),
            &sharded,
        );
        let part = table_without_seconds(&sharded.join(format!("batch.part-{i}-of-3.csv")));
        seen.extend(jobs_of(&part));
        if i == 2 {
            // Two of three parts: collect names the jobs of the third as missing.
            let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
                .arg("collect")
                .arg(&sharded)
                .output()
                .unwrap();
            assert!(!o.status.success());
            for job in ["sq/3", "sq/6"] {
                assert!(
                    text(&o).contains(&format!("missing  {job}")),
                    "{}",
                    text(&o)
                );
            }
        }
    }
    seen.sort();
    let mut all = jobs_of(&expected);
    all.sort();
    assert_eq!(seen, all, "every job exactly once");
    let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("collect")
        .arg(&sharded)
        .output()
        .unwrap();
    assert!(!o.status.success(), "a failed job is reported");
    assert!(text(&o).contains("FAIL  missing: failed: "), "{}", text(&o));
    assert!(!text(&o).contains("missing  "), "{}", text(&o));
    assert_eq!(table_without_seconds(&sharded.join("batch.csv")), expected);
    for k in 1..=6 {
        assert_same_results(
            &whole.join(format!("sq/{k}")),
            &sharded.join(format!("sq/{k}")),
        );
    }
}

#[test]
fn a_resumed_batch_skips_finished_jobs_and_reruns_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write(dir.path(), "sq.toml", &square("200e9", "200.0", GRID));
    let out = dir.path().join("out");
    let run = |extra: &[&str]| {
        let o = linkage(
            &[&["run", scene.to_str().unwrap()][..], extra].concat(),
            &out,
        );
        assert!(o.status.success(), "{}", text(&o));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    run(&[]);
    let first = table_without_seconds(&out.join("batch.csv"));
    let kept = std::fs::read(out.join("sq/1/summary.json")).unwrap();
    // A task killed mid-batch: variant 2 never published, variant 3 lost its summary (written
    // last), variant 4 left only a failed run's summary.
    std::fs::remove_dir_all(out.join("sq/2")).unwrap();
    std::fs::remove_file(out.join("sq/3/summary.json")).unwrap();
    let s4 = out.join("sq/4/summary.json");
    let mut failed: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&s4).unwrap()).unwrap();
    failed["failure"] = "step 2: did not converge".into();
    std::fs::write(&s4, serde_json::to_vec(&failed).unwrap()).unwrap();
    let stdout = run(&[]);
    for k in [1, 5, 6] {
        assert!(
            stdout.contains(&format!("skip  {} [{k}]", scene.display())),
            "{stdout}"
        );
    }
    for k in [2, 3, 4] {
        assert!(
            stdout.contains(&format!("ok    {} [{k}]", scene.display())),
            "{stdout}"
        );
    }
    assert_eq!(
        std::fs::read(out.join("sq/1/summary.json")).unwrap(),
        kept,
        "skipped, not rewritten"
    );
    assert_eq!(table_without_seconds(&out.join("batch.csv")), first);
    let stdout = run(&["--rerun"]);
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok    ")).count(),
        6,
        "{stdout}"
    );
    assert_eq!(table_without_seconds(&out.join("batch.csv")), first);
    // An edited scene is run again: the summary's scene_digest no longer matches.
    let edited = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("area = 1e-4", "area = 2e-4");
    std::fs::write(&scene, edited).unwrap();
    let stdout = run(&[]);
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok    ")).count(),
        6,
        "{stdout}"
    );
    let u = |rows: &[linkage::scene::batch::Row]| rows[0].max_displacement.parse::<f64>().unwrap();
    let halved = u(&table_without_seconds(&out.join("batch.csv"))) / u(&first);
    assert!((halved - 0.5).abs() < 1e-12, "{halved}");
}

#[test]
fn a_variant_that_cannot_be_built_fails_alone_and_check_checks_every_variant() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = "\n[sweep]\n\"materials.steel.youngs_modulus\" = [200e9, -1.0]\n";
    let scene = write(dir.path(), "sq.toml", &square("200e9", "200.0", sweep));
    let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("check")
        .arg(&scene)
        .output()
        .unwrap();
    assert!(!o.status.success());
    let said = text(&o);
    assert!(
        said.contains(&format!("ok    {} [1]", scene.display())),
        "{said}"
    );
    let fail = format!(
        "FAIL  {}: [sweep] variant 2 (materials.steel.youngs_modulus = -1.0): ",
        scene.display()
    );
    assert!(said.contains(&fail), "{said}");
    let out = dir.path().join("out");
    let o = linkage(&["run", scene.to_str().unwrap()], &out);
    assert!(!o.status.success());
    assert!(text(&o).contains(&fail), "{}", text(&o));
    assert!(text(&o).contains("1 of 2 jobs failed"), "{}", text(&o));
    assert!(out.join("sq/1/summary.json").is_file());
    assert!(!out.join("sq/2").exists());
    let rows = table_without_seconds(&out.join("batch.csv"));
    assert_eq!(rows[0].status, "ok");
    assert!(rows[1].status.starts_with("failed: "), "{:?}", rows[1]);
    assert!(rows[1].status.contains("youngs_modulus"), "{:?}", rows[1]);
}
