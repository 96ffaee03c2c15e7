//! The `linkage` command end to end: batches, exit codes, output files and their contract.

use std::path::Path;
use std::process::Command;

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

#[test]
fn run_writes_the_output_contract() {
    let out = tempfile::tempdir().unwrap();
    let status = linkage()
        .args([
            "run",
            "scenes/paper_square.toml",
            "scenes/paper_overload.toml",
            "--out",
        ])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok")).count(),
        2,
        "{stdout}"
    );

    let dir = out.path().join("paper_square");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["scene"], "paper_square");
    let steps = summary["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 2);
    for key in [
        "step",
        "load_factor",
        "iterations",
        "contact_iterations",
        "residual",
        "max_displacement",
        "overloaded",
        "max_penetration",
        "seconds",
    ] {
        assert!(steps[1].get(key).is_some(), "summary lacks {key}");
    }
    let step: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("steps/0001.json")).unwrap()).unwrap();
    assert_eq!(step["step"], 1);
    assert_eq!(step["load_factor"], 1.0);
    let body = &step["bodies"][0];
    assert_eq!(body["name"], "square");
    assert_eq!(body["displacements"].as_array().unwrap().len(), 4);
    assert_eq!(body["displacements"][0].as_array().unwrap().len(), 2);
    assert_eq!(body["axial_forces"].as_array().unwrap().len(), 6);
    assert_eq!(body["reactions"][0]["node"], 3);
    assert_eq!(body["loads"][0]["node"], 2);
    assert_eq!(body["loads"][0]["force"][0], 200.0);
    // positions = nodes + displacements (node 3 is pinned at the origin).
    assert_eq!(body["positions"][2][0], 0.0);
    assert!(body["contacts"].as_array().unwrap().is_empty());
    let zero: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("steps/0000.json")).unwrap()).unwrap();
    assert_eq!(zero["bodies"][0]["displacements"][0][0], 0.0);
    // All 11 steps of the overload scene are there, and no temporary files anywhere.
    assert_eq!(
        std::fs::read_dir(out.path().join("paper_overload/steps"))
            .unwrap()
            .count(),
        11
    );
    for entry in std::fs::read_dir(out.path()).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(!name.starts_with('.'), "left behind {name}");
    }
}

#[test]
fn a_failing_scene_fails_the_batch_but_not_the_others_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(
        &bad,
        "name = \"bad\"\n[[materials]]\nname = \"s\"\nyoungs_modulus = 1e9\narea = 1e-4\n[[bodies]]\nname = \"b\"\nrectangle = { width = 1.0, height = 1.0, cells = [2, 2] }\n[[bodies.supports]]\nnearest = [0.0, 0.0]\nfix = [\"x\", \"y\"]\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let result = linkage()
        .args(["run", "scenes/paper_square.toml"])
        .arg(&bad)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!result.status.success());
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(
        stdout.contains("FAIL") && stdout.contains("bad.toml") && stdout.contains("rigid-body"),
        "{stdout}"
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("paper_square/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["scene"], "paper_square");
    assert_eq!(summary["steps"].as_array().unwrap().len(), 2);
    assert!(!out.join("bad").exists(), "a failed scene leaves no output");
    // The results of the scene that solved, and the batch table.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 2);
    assert!(out.join("batch.csv").is_file());
}

#[test]
fn output_every_and_last_only() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string("scenes/paper_overload.toml").unwrap();
    let scene = dir.path().join("o.toml");
    std::fs::write(&scene, format!("{src}\n[output]\nevery = 4\n")).unwrap();
    let out = dir.path().join("out");
    assert!(linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .status()
        .unwrap()
        .success());
    let mut names: Vec<String> = std::fs::read_dir(out.join("paper_overload/steps"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["0000.json", "0004.json", "0008.json", "0010.json"]);
    std::fs::write(&scene, format!("{src}\n[output]\nlast_only = true\n")).unwrap();
    assert!(linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .status()
        .unwrap()
        .success());
    assert_eq!(
        std::fs::read_dir(out.join("paper_overload/steps"))
            .unwrap()
            .count(),
        2
    );
    // The summary still has every step.
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("paper_overload/summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["steps"].as_array().unwrap().len(), 11);
}

/// `linkage check` reads the scenes and prints their sizes, and solves nothing: a scene whose
/// fourth step cannot be solved (a load past the truss's limit point, which `linkage run`
/// reports as a failure) passes the check, the working folder stays empty (no results folder,
/// no `batch.csv`), and no timings or residuals are printed.
#[test]
fn check_prints_sizes_without_solving() {
    let here = std::env::current_dir().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let unsolvable = dir.path().join("overload.toml");
    std::fs::write(
        &unsolvable,
        format!(
            "name = \"overload\"\nsteps = 4\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n[[bodies]]\nname = \"truss\"\nnodes = \"{}\"\nlinks = \"{}\"\nkinematics = \"large\"\n[bodies.newton]\nmax_cuts = 3\n[[bodies.supports]]\nnodes = [1, 3]\nfix = [\"x\", \"y\"]\n[[bodies.loads]]\nnodes = [2]\nforce = [0.0, -9000.0]\n",
            here.join("scenes/von_mises.nodes").display(),
            here.join("scenes/von_mises.links").display()
        ),
    )
    .unwrap();
    // Run from an empty folder, so anything check writes shows.
    let cwd = dir.path().join("cwd");
    std::fs::create_dir(&cwd).unwrap();
    let result = linkage()
        .current_dir(&cwd)
        .arg("check")
        .arg(here.join("scenes/paper_shell.toml"))
        .arg(here.join("scenes/paper_square.toml"))
        .arg(&unsolvable)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&result.stdout);
    assert!(
        result.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&result.stderr)
    );
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok")).count(),
        3,
        "{stdout}"
    );
    assert!(stdout.contains("4 nodes, 6 members"), "{stdout}");
    let shell = linkage::scene::load_scene(Path::new("scenes/paper_shell.toml")).unwrap();
    let (nodes, members) = (shell.bodies[0].nodes.len(), shell.bodies[0].members.len());
    assert!(
        stdout.contains(&format!("{nodes} nodes, {members} members")),
        "paper_shell's {nodes} nodes and {members} members: {stdout}"
    );
    assert!(stdout.contains("overload.toml"), "{stdout}");
    for solved in [" s;", "residual", "phases", "max |u|", "did not converge"] {
        assert!(
            !stdout.contains(solved),
            "check solved ({solved:?}): {stdout}"
        );
    }
    assert_eq!(
        std::fs::read_dir(&cwd).unwrap().count(),
        0,
        "check wrote into the working folder"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "check wrote beside the scene"
    );
    // The same scene does not solve: the check above passed without trying.
    let run = linkage()
        .current_dir(&cwd)
        .arg("run")
        .arg(&unsolvable)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(
        String::from_utf8_lossy(&run.stdout).contains("step 4 did not converge"),
        "{}",
        String::from_utf8_lossy(&run.stdout)
    );
    let missing = linkage()
        .args(["check", "scenes/nope.toml"])
        .output()
        .unwrap();
    assert!(!missing.status.success());
    assert!(String::from_utf8_lossy(&missing.stdout).contains("nope.toml"));
}

#[test]
fn export_writes_the_papers_files_that_read_back_the_same_body() {
    let dir = tempfile::tempdir().unwrap();
    let files = dir.path().join("files");
    let result = linkage()
        .args(["export", "scenes/paper_shell.toml", "--out"])
        .arg(&files)
        .output()
        .unwrap();
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    let original = linkage::scene::load_scene(Path::new("scenes/paper_shell.toml")).unwrap();
    // The same scene, reading the exported files instead of generating.
    let src = std::fs::read_to_string("scenes/paper_shell.toml").unwrap();
    let from_files = src.replace(
        "cylindrical_shell = { radius = 0.25, length = 2.0, rings = 17, sectors = 24 }",
        "nodes = \"files/shell.nodes\"\nlinks = \"files/shell.links\"\npatches = \"files/shell.patches\"",
    );
    assert_ne!(src, from_files);
    let scene = dir.path().join("again.toml");
    std::fs::write(&scene, from_files).unwrap();
    let again = linkage::scene::load_scene(&scene).unwrap();
    assert_eq!(again.bodies, original.bodies);
}

/// The run line gives the DOFs and the free ones, the free count being the summary's
/// `free_dofs` summed over the bodies, and the phases line has every phase of the summary,
/// `contact_query` among them.
#[test]
fn run_line_gives_the_free_dofs_of_the_summary_and_every_phase() {
    let out = tempfile::tempdir().unwrap();
    let o = linkage()
        .args(["run", "scenes/paper_square.toml", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    let summary: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out.path().join("paper_square/summary.json")).unwrap(),
    )
    .unwrap();
    let free: u64 = summary["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["free_dofs"].as_u64().unwrap())
        .sum();
    // The square: 4 nodes in 2D, node 3 pinned, node 4 held in y.
    assert_eq!(free, 5);
    assert!(stdout.contains("8 DOFs (5 free)"), "{stdout}");
    let phases = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("phases:"))
        .unwrap();
    for key in summary["phases"].as_object().unwrap().keys() {
        let shown = match key.as_str() {
            "symbolic" => "ordering+symbolic",
            "numeric" => "factorization",
            k => k,
        };
        assert!(phases.contains(shown), "{key} missing: {phases}");
    }
}

/// `--out` naming a file (or a path under one) says that `--out` must be a folder, not "File
/// exists (os error 17)"; nothing is written.
#[test]
fn out_naming_a_file_says_it_must_be_a_folder() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("results.txt");
    std::fs::write(&file, "mine").unwrap();
    for (out, command) in [
        (file.clone(), "run"),
        (file.join("sub"), "run"),
        (file.clone(), "export"),
    ] {
        let o = linkage()
            .args([command, "scenes/paper_square.toml", "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(!o.status.success());
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            err.contains("--out must be a folder") && err.contains("is a file"),
            "{err}"
        );
        assert!(!err.contains("os error"), "{err}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");
    }
}

/// `model.json` has a closed surface's patches outward even when the patches file gives them
/// facing in (the tetrahedron's four faces, each counter-clockwise seen from inside).
#[test]
fn model_json_has_closed_surfaces_outward() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.nodes"), "0 0 0\n1 0 0\n0 1 0\n0 0 1\n").unwrap();
    std::fs::write(d.join("t.links"), "1 2\n1 3\n1 4\n2 3\n2 4\n3 4\n").unwrap();
    std::fs::write(d.join("t.patches"), "1 2 3\n1 4 2\n1 3 4\n2 4 3\n").unwrap();
    let scene = d.join("t.toml");
    std::fs::write(
        &scene,
        r#"name = "tetra"
steps = 1

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "t"
nodes = "t.nodes"
links = "t.links"
patches = "t.patches"
material = "steel"

[[bodies.supports]]
nodes = [1]
fix = ["x", "y", "z"]

[[bodies.supports]]
nodes = [2]
fix = ["y", "z"]

[[bodies.supports]]
nodes = [3]
fix = ["z"]

[[bodies.loads]]
nodes = [4]
force = [10.0, 0.0, 0.0]
"#,
    )
    .unwrap();
    let o = linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(d.join("out"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stdout));
    let model: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("out/tetra/model.json")).unwrap()).unwrap();
    let patches: Vec<[usize; 3]> =
        serde_json::from_value(model["bodies"][0]["patches"].clone()).unwrap();
    assert_eq!(patches, [[1, 3, 2], [1, 2, 4], [1, 4, 3], [2, 3, 4]]);
}
