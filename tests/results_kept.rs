//! A run never loses results: failed re-runs, a user's files, signals, killed runs, and runs of
//! one name finishing together.

mod common;

use linkage::scene::{load_scene, run, RunError};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

/// Names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The truss scene that solves (5000 N), loaded from `dir` and run once into `out`.
fn solved_truss(dir: &Path, out: &Path) -> linkage::scene::World {
    let good = load_scene(&common::truss_scene(dir, "good.toml", "truss", 5000.0)).unwrap();
    run(&good, out, &|| {}).unwrap();
    good
}

#[test]
fn a_failed_rerun_leaves_the_complete_results_and_puts_its_own_beside_them() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let good = solved_truss(dir.path(), &out);
    let complete = out.join("truss");
    let before = std::fs::read(complete.join("steps/0004.json")).unwrap();

    let bad = load_scene(&common::truss_scene(
        dir.path(),
        "bad.toml",
        "truss",
        9000.0,
    ))
    .unwrap();
    let err = run(&bad, &out, &|| {}).expect_err("step 4 cannot be solved");
    let RunError::Stopped { results, source } = &err else {
        panic!("expected a stopped run, got {err:?}");
    };
    assert_eq!(*results, out.join("truss.failed"));
    assert!(matches!(**source, RunError::Solve { .. }), "{source:?}");
    assert!(err.to_string().contains("truss.failed"), "{err}");
    // The complete results are untouched.
    assert_eq!(
        std::fs::read(complete.join("steps/0004.json")).unwrap(),
        before
    );
    assert!(summary(&complete).get("failure").is_none());
    assert_eq!(summary(&complete)["steps"].as_array().unwrap().len(), 5);
    // The failed run kept step 0 and the steps it solved, and says why it stopped.
    let failed = summary(&results.clone());
    assert!(failed["failure"].as_str().unwrap().contains("step 4"));
    assert_eq!(failed["steps"].as_array().unwrap().len(), 4);
    assert!(results.join("steps/0000.json").is_file() && results.join("steps/0003.json").is_file());
    assert!(!results.join("steps/0004.json").exists());
    assert_eq!(listing(&out), vec!["truss", "truss.failed"]);

    // A good run replaces the complete results, and leaves the failed ones alone.
    run(&good, &out, &|| {}).unwrap();
    assert_eq!(listing(&out), vec!["truss", "truss.failed"]);
}

#[test]
fn a_users_files_in_the_results_folder_survive_a_rerun() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let good = solved_truss(dir.path(), &out);
    let folder = out.join("truss");
    std::fs::write(folder.join("notes.txt"), "the second design").unwrap();
    // (`plots/` is linkage's own since runs draw plots: a user's folder has another name.)
    std::fs::create_dir(folder.join("analysis")).unwrap();
    std::fs::write(folder.join("analysis/u.csv"), "1,2").unwrap();
    run(&good, &out, &|| {}).unwrap();
    assert_eq!(
        std::fs::read_to_string(folder.join("notes.txt")).unwrap(),
        "the second design"
    );
    assert_eq!(
        std::fs::read_to_string(folder.join("analysis/u.csv")).unwrap(),
        "1,2"
    );
    assert!(folder.join("steps/0004.json").is_file());
    assert_eq!(listing(&out), vec!["truss"]);
}

#[test]
fn a_stale_staging_folder_of_a_dead_process_is_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // Process ids stop at 2^22: this one never ran, as if killed by SIGKILL.
    let stale = out.join(".truss.partial-4194305-0");
    std::fs::create_dir_all(stale.join("steps")).unwrap();
    std::fs::write(stale.join("steps/0000.json"), "{}").unwrap();
    let other = out.join(".other.partial-4194305-0");
    std::fs::create_dir_all(&other).unwrap();
    let scene = common::truss_scene(dir.path(), "good.toml", "truss", 5000.0);
    let status = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    assert!(!stale.exists());
    // Another scene's leftovers are its own next run's to remove.
    assert!(other.exists());
    assert_eq!(
        listing(&out),
        vec![".other.partial-4194305-0", "batch.csv", "truss"]
    );
}

/// A scene that takes many seconds: a 12×12×12-cell lattice written at each of 3000 steps.
fn slow_scene(dir: &Path) -> PathBuf {
    let scene = dir.join("slow.toml");
    std::fs::write(
        &scene,
        r#"name = "slow"
steps = 3000
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-6
[[bodies]]
name = "box"
box_lattice = { size = [0.12, 0.12, 0.12], cells = [12, 12, 12] }
material = "steel"
[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }
fix = ["x", "y", "z"]
[[bodies.loads]]
on_plane = { point = [0.0, 0.0, 0.12], normal = [0.0, 0.0, 1.0] }
force = [0.0, 0.0, -1.0]
"#,
    )
    .unwrap();
    scene
}

/// Run the slow scene, send `signal` once its staging folder holds a step, and check that the
/// run stops with a message, status 130 and no staging folder, and earlier results untouched.
fn stops_cleanly_on(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    // Earlier complete results of the same scene, which the interrupted run must not touch.
    let earlier = out.join("slow");
    std::fs::create_dir_all(&earlier).unwrap();
    std::fs::write(earlier.join("summary.json"), "{\"steps\": []}").unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(slow_scene(dir.path()))
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    let staging_step = || {
        listing(&out)
            .iter()
            .filter(|n| n.starts_with(".slow.partial-"))
            .any(|n| out.join(n).join("steps/0001.json").exists())
    };
    while !staging_step() {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the run never wrote step 1"
        );
        assert!(child.try_wait().unwrap().is_none(), "the run ended early");
        std::thread::sleep(Duration::from_millis(20));
    }
    let killed = Command::new("kill")
        .arg(format!("-{signal}"))
        .arg(child.id().to_string())
        .status()
        .unwrap();
    assert!(killed.success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(130), "{output:?}");
    let stderr = String::from_utf8_lossy(&output.stderr);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stderr.contains("interrupted: stopping"), "{stderr}");
    assert!(
        stdout.contains("interrupted at step") && stdout.contains("no results written"),
        "{stdout}"
    );
    // The batch table says the run failed.
    assert_eq!(
        listing(&out),
        vec!["batch.csv", "slow"],
        "only the earlier results stay"
    );
    assert_eq!(
        std::fs::read_to_string(earlier.join("summary.json")).unwrap(),
        "{\"steps\": []}"
    );
}

#[test]
fn sigint_stops_a_run_cleanly() {
    stops_cleanly_on("INT");
}

#[test]
fn sigterm_stops_a_run_cleanly() {
    stops_cleanly_on("TERM");
}

#[test]
fn fifty_pairs_of_concurrent_runs_of_one_name_all_succeed() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let here = std::env::current_dir().unwrap();
    let scene = here.join("scenes/paper_square.toml");
    for pair in 0..50 {
        let spawn = || {
            Command::new(env!("CARGO_BIN_EXE_linkage"))
                .arg("run")
                .arg(&scene)
                .arg("--out")
                .arg(&out)
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        };
        let (a, b) = (spawn(), spawn());
        for child in [a, b] {
            let output = child.wait_with_output().unwrap();
            assert!(output.status.success(), "pair {pair}: {output:?}");
        }
    }
    // One process running the same name twice, side by side.
    let output = Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success(), "{output:?}");
    assert_eq!(listing(&out), vec!["batch.csv", "paper_square"]);
    assert!(summary(&out.join("paper_square")).get("failure").is_none());
}
