//! Re-runs over the same `--out` (issue 33, items 6 and 7): an edited nodes file is solved
//! again, `--png` on finished results draws them without solving, and `render --vtk` replaces
//! `vtk/` as a whole.

use std::path::Path;
use std::process::{Command, Output};

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

fn run(args: &[&str], out: &Path) -> Output {
    let o = linkage().args(args).arg("--out").arg(out).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The paper's square truss with its files, copied into `dir`.
fn square_in(dir: &Path) -> String {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    for f in ["paper_square.toml", "square.nodes", "square.links"] {
        std::fs::copy(scenes.join(f), dir.join(f)).unwrap();
    }
    dir.join("paper_square.toml").display().to_string()
}

#[test]
fn editing_a_nodes_file_solves_the_scene_again() {
    let dir = tempfile::tempdir().unwrap();
    let scene = square_in(dir.path());
    let out = dir.path().join("out");
    assert!(stdout(&run(&["run", &scene], &out)).starts_with("ok"));
    assert!(stdout(&run(&["run", &scene], &out)).starts_with("skip"));
    let before = std::fs::read(out.join("paper_square/steps/0001.json")).unwrap();
    // Move the loaded node 2 (the second "x y" line) up by 10 % of the side.
    let nodes = std::fs::read_to_string(dir.path().join("square.nodes")).unwrap();
    let mut lines: Vec<String> = nodes.lines().map(str::to_string).collect();
    let i = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .nth(1)
        .map(|(i, _)| i)
        .expect("node 2");
    assert_eq!(lines[i].trim(), "0.0 1.0");
    lines[i] = "0.0 1.1".to_string();
    std::fs::write(dir.path().join("square.nodes"), lines.join("\n") + "\n").unwrap();
    let again = stdout(&run(&["run", &scene], &out));
    assert!(again.starts_with("ok"), "{again}");
    assert_ne!(
        std::fs::read(out.join("paper_square/steps/0001.json")).unwrap(),
        before
    );
    assert!(stdout(&run(&["run", &scene], &out)).starts_with("skip"));
}

#[test]
fn png_on_a_finished_run_draws_the_stored_results_without_solving() {
    let dir = tempfile::tempdir().unwrap();
    let scene = square_in(dir.path());
    let out = dir.path().join("out");
    run(&["run", &scene], &out);
    let summary = std::fs::read(out.join("paper_square/summary.json")).unwrap();
    let drew = stdout(&run(&["run", &scene, "--png", "--vtk"], &out));
    assert!(drew.starts_with("drew"), "{drew}");
    assert!(out.join("paper_square/png/0000.png").is_file());
    assert!(out.join("paper_square/png/0001.png").is_file());
    assert!(out.join("paper_square/anim.gif").is_file());
    assert!(out.join("paper_square/vtk/paper_square.pvd").is_file());
    // Not solved again: the summary is the one written by the first run.
    assert_eq!(
        std::fs::read(out.join("paper_square/summary.json")).unwrap(),
        summary
    );
}

#[test]
fn render_vtk_replaces_the_vtk_folder_and_keeps_a_users_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = square_in(dir.path());
    let out = dir.path().join("out");
    run(&["run", &scene, "--vtk"], &out);
    let vtk = out.join("paper_square/vtk");
    std::fs::write(vtk.join("0099.vtu"), "stale").unwrap();
    std::fs::write(vtk.join("notes.txt"), "mine").unwrap();
    let results = out.join("paper_square");
    let o = linkage()
        .arg("render")
        .arg(&results)
        .args(["--vtk", "--no-png", "--no-gif"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        !vtk.join("0099.vtu").exists(),
        "an older file stayed beside the new ones"
    );
    assert!(vtk.join("0001.vtu").is_file() && vtk.join("paper_square.pvd").is_file());
    assert_eq!(
        std::fs::read_to_string(vtk.join("notes.txt")).unwrap(),
        "mine"
    );
    let hidden: Vec<_> = std::fs::read_dir(&results)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "{hidden:?}");
}
