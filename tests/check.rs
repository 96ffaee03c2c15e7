//! `linkage check` rejects what `linkage run` rejects before its first step, with the same
//! message, and warns as the run does about a run that would write more than 1 GB.

use std::path::Path;
use std::process::{Command, Output};

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

const STEEL: &str = "[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n";

/// Write `files` (name, text) into `dir`, the scene `scene.toml` among them.
fn write(dir: &Path, files: &[(&str, &str)]) {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
}

fn out(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// The FAIL line of `output`.
fn fail_line(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .find(|l| l.starts_with("FAIL"))
        .unwrap_or_else(|| panic!("no FAIL line: {}", out(output)))
        .to_string()
}

/// `check` and `run` of the scene `text` (with `files` beside it) both fail with the same
/// message, which contains every one of `expected`.
fn both_reject(text: &str, files: &[(&str, &str)], expected: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), files);
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    let run = linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(!check.status.success(), "check passed: {}", out(&check));
    assert!(!run.status.success(), "run passed: {}", out(&run));
    let (c, r) = (fail_line(&check), fail_line(&run));
    assert_eq!(c, r, "check and run differ");
    // Refused before anything is solved: no results, not even a partial folder (only the
    // batch table, whose row says the scene failed).
    let written: Vec<_> = std::fs::read_dir(dir.path().join("out"))
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| !p.ends_with("batch.csv"))
                .collect()
        })
        .unwrap_or_default();
    assert!(written.is_empty(), "the run wrote {written:?}");
    for e in expected {
        assert!(c.contains(e), "{e:?} not in {c}");
    }
}

const SQUARE_NODES: &str = "0 0\n1 0\n1 1\n0 1\n";

#[test]
fn a_mechanism() {
    both_reject(
        &format!("name = \"m\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"square\"\nnodes = \"sq.nodes\"\nlinks = \"sq.links\"\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n[[bodies.supports]]\nnodes = [2]\nfix = [\"y\"]\n[[bodies.loads]]\nnodes = [3]\nforce = [100.0, 0.0]\n"),
        &[("sq.nodes", SQUARE_NODES), ("sq.links", "1 2\n2 3\n3 4\n4 1\n")],
        &["body 'square' is a mechanism", "nodes 3 (x), 4 (x)"],
    );
}

#[test]
fn supports_leaving_a_rigid_motion_free() {
    both_reject(
        &format!("name = \"f\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"disk\"\ndisk = {{ radius = 0.1 }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\"]\n"),
        &[],
        &["body 'disk'", "rigid-body motion free"],
    );
}

const TET_NODES: &str = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
const TET_LINKS: &str = "1 2\n1 3\n1 4\n2 3\n2 4\n3 4\n";

#[test]
fn patches_facing_both_ways() {
    both_reject(
        &format!("name = \"p\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"tet\"\nnodes = \"tet.nodes\"\nlinks = \"tet.links\"\npatches = \"tet.patches\"\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1, 2, 3]\nfix = [\"x\", \"y\", \"z\"]\n[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, 0.0, -1.0]\nnormal = [0.0, 0.0, 1.0]\n"),
        &[
            ("tet.nodes", TET_NODES),
            ("tet.links", TET_LINKS),
            ("tet.patches", "1 3 2\n1 2 4\n2 3 4\n1 3 4\n"),
        ],
        &["body 'tet'", "face opposite sides"],
    );
}

#[test]
fn a_block_starting_3_cm_inside_a_half_space() {
    both_reject(
        &format!("name = \"s\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"block\"\nbox_lattice = {{ size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [27]\nfix = [\"x\", \"y\", \"z\"]\n[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, 0.0, 0.03]\nnormal = [0.0, 0.0, 1.0]\n"),
        &[],
        &[
            "body 'block' starts inside obstacle 'floor'",
            "node 1 is 3.000e-2 m deep",
            "move body 'block' (or obstacle 'floor') by at least 3.000e-2 m along [0.000, 0.000, 1.000]",
        ],
    );
}

#[test]
fn a_disk_starting_inside_a_ball() {
    both_reject(
        &format!("name = \"b\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"disk\"\ndisk = {{ radius = 0.1, rings = 2, sectors = 8 }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n[[obstacles]]\nname = \"ball\"\nshape = \"ball\"\ncenter = [0.15, 0.0]\nradius = 0.1\n"),
        &[],
        &[
            "body 'disk' starts inside obstacle 'ball'",
            "node 10 is 5.000e-2 m deep",
            "along [-1.000, 0.000]",
        ],
    );
}

#[test]
fn a_2d_and_a_3d_body_in_one_contact_scene() {
    both_reject(
        &format!("name = \"x\"\nsteps = 1\n{STEEL}[contact]\n[[bodies]]\nname = \"disk\"\ndisk = {{ radius = 0.1 }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n[[bodies]]\nname = \"block\"\nbox_lattice = {{ size = [0.1, 0.1, 0.1], cells = [1, 1, 1] }}\nmaterial = \"steel\"\noffset = [0.0, 0.0, 0.5]\n[[bodies.supports]]\nnodes = [1, 2, 3, 4]\nfix = [\"x\", \"y\", \"z\"]\n"),
        &[],
        &["body 'disk' is 2D and body 'block' is 3D"],
    );
}

/// A run of a million steps warns in `check` and in the run's summary (here a run that stops
/// at step 1, keeping step 0 and the summary, so the test is fast) with the same words.
#[test]
fn a_run_that_would_write_more_than_1_gb() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    // Held sideways only and pulled away from the floor: step 1 cannot be solved.
    std::fs::write(
        &scene,
        format!("name = \"big\"\nsteps = 1000000\n{STEEL}[[bodies]]\nname = \"disk\"\ndisk = {{ radius = 0.1 }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\"]\n[[bodies.loads]]\nnodes = [1]\nforce = [0.0, 100.0]\n[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, -0.2]\nnormal = [0.0, 1.0]\n"),
    )
    .unwrap();
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(check.status.success(), "{}", out(&check));
    let stdout = String::from_utf8_lossy(&check.stdout);
    let warning = stdout
        .lines()
        .find_map(|l| l.strip_prefix(&format!("warn  {}: ", scene.display())))
        .unwrap_or_else(|| panic!("no warning: {stdout}"))
        .to_string();
    assert!(warning.contains("GB"), "{warning}");
    assert!(warning.contains("[output] every = "), "{warning}");
    let results = dir.path().join("out");
    let run = linkage()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&results)
        .output()
        .unwrap();
    assert!(!run.status.success(), "{}", out(&run));
    // The run says it before its first step, not only in the summary it ends with.
    assert!(
        String::from_utf8_lossy(&run.stderr).contains(&format!("warn  big: {warning}")),
        "{}",
        out(&run)
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(results.join("big/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["steps"][0]["warnings"][0], warning.as_str());
    // The same scene with last_only writes two steps: no warning.
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, format!("{text}[output]\nlast_only = true\n")).unwrap();
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(check.status.success(), "{}", out(&check));
    assert!(
        !String::from_utf8_lossy(&check.stdout).contains("warn"),
        "{}",
        out(&check)
    );
}

/// Every bundled scene passes the check: none starts with a node inside an obstacle or another
/// body beyond the tolerance (those resting on a surface start touching it).
#[test]
fn bundled_scenes_pass_the_check() {
    let scenes: Vec<_> = std::fs::read_dir("scenes")
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    let check = linkage().arg("check").args(&scenes).output().unwrap();
    assert!(check.status.success(), "{}", out(&check));
    let stdout = String::from_utf8_lossy(&check.stdout);
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok")).count(),
        scenes.len(),
        "{stdout}"
    );
    // The one scene warned about: paper_shell_large's inflation loads, one per generatrix,
    // take in its node on the fixed ring, whose share goes into the reactions (meant: the
    // warning says so, docs/SCENES.md, *Warnings*).
    let warned: Vec<&str> = stdout.lines().filter(|l| l.contains("warn")).collect();
    assert_eq!(warned.len(), 24, "{stdout}");
    for w in warned {
        assert!(w.contains("paper_shell_large.toml:"), "{w}");
        assert!(
            w.contains("held by a support in a direction it pushes"),
            "{w}"
        );
    }
}

/// A closed unit cube (OBJ, counter-clockwise seen from outside) and a box lattice above it.
const CUBE_OBJ: &str = "\
v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

fn box_over_mesh() -> String {
    format!("name = \"m\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"block\"\nbox_lattice = {{ size = [0.1, 0.1, 0.1], cells = [1, 1, 1] }}\nmaterial = \"steel\"\noffset = [0.0, 1.0, 0.0]\n[[bodies.supports]]\nnodes = [1, 2, 3, 4, 5, 6, 7, 8]\nfix = [\"x\", \"y\", \"z\"]\n[[obstacles]]\nname = \"cube\"\nshape = \"mesh\"\nfile = \"cube.obj\"\n")
}

#[test]
fn an_open_mesh_is_refused_naming_an_edge() {
    // The top face (y = 0.5, two triangles) left out.
    let open = CUBE_OBJ.replace("f 3 4 8 7\n", "");
    both_reject(
        &box_over_mesh(),
        &[("cube.obj", &open)],
        &[
            "obstacle 'cube'",
            "cube.obj",
            "the edge from vertex",
            "the mesh is open there",
            "add the missing faces",
        ],
    );
}

#[test]
fn check_says_which_mesh_faces_it_turned() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(&scene, box_over_mesh()).unwrap();
    // Faces 3 and 4 (the two triangles of `f 5 6 7 8`) flipped: one quad listed clockwise;
    // then the whole cube listed clockwise.
    let flipped = CUBE_OBJ.replace("f 5 6 7 8", "f 8 7 6 5");
    let inward: String = CUBE_OBJ
        .lines()
        .map(|l| match l.strip_prefix("f ") {
            Some(f) => format!("f {}\n", f.split(' ').rev().collect::<Vec<_>>().join(" ")),
            None => format!("{l}\n"),
        })
        .collect();
    for (mesh, expected) in [
        (&flipped, "cube.obj disagreed with their neighbours or faced inward and were turned outward: faces 3, 4"),
        (&inward, "all 12 faces of"),
    ] {
        std::fs::write(dir.path().join("cube.obj"), mesh).unwrap();
        let check = linkage().arg("check").arg(&scene).output().unwrap();
        assert!(check.status.success(), "{}", out(&check));
        let text = out(&check);
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("found: obstacle 'cube'"))
            .unwrap_or_else(|| panic!("no found line: {text}"));
        assert!(
            line.contains(expected) && line.contains("turned outward"),
            "{line}"
        );
    }
    // An outward cube: nothing to say.
    std::fs::write(dir.path().join("cube.obj"), CUBE_OBJ).unwrap();
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(!out(&check).contains("found:"), "{}", out(&check));
}

#[test]
fn overflowing_geometry_is_refused_before_anything_is_written() {
    let disk = format!("name = \"g\"\nsteps = 1\n{STEEL}[[bodies]]\nname = \"disk\"\ndisk = {{ radius = 0.1 }}\nmaterial = \"steel\"\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n[[obstacles]]\nname = \"o\"\n");
    for (obstacle, key, expected) in [
        ("shape = \"ball\"\ncenter = [0.0, -5.0]\nradius = 1e155\n", "radius", "`radius` = 1e155 m"),
        ("shape = \"cuboid\"\ncenter = [0.0, -5.0]\nhalf_extents = [1.0, 1.0]\nrotation = 1e308\n", "rotation", "1e308 degrees"),
        ("shape = \"half_space\"\npoint = [0.0, -1.0]\nnormal = [0.0, 1.0]\ntravel = [0.0, 1e308]\n", "travel", "`travel` = 1e308 m"),
    ] {
        let text = format!("{disk}{obstacle}");
        let line = text.lines().position(|l| l.starts_with(key)).unwrap() + 1;
        both_reject(&text, &[], &[&format!("scene.toml:{line}:"), "obstacle 'o'", expected]);
    }
    // NaN in a mesh.
    let nan = CUBE_OBJ.replace("v 0.5 0.5 0.5", "v 0.5 nan 0.5");
    both_reject(
        &box_over_mesh(),
        &[("cube.obj", &nan)],
        &["cube.obj:7:", "\"nan\" is not a finite number"],
    );
}
