//! Model files made elsewhere: gmsh MSH 4.1 files written by gmsh itself (ASCII and binary,
//! `tests/models/make_msh.py`) and Abaqus/CalculiX INP trusses, read as bodies, checked
//! against the same models as the paper's files, against meshio's reading of the same
//! files and against closed forms; `linkage import`; errors with file and line.

mod common;

use linkage::linkage::prepare::enclosed_volume;
use linkage::scene::import::{import_file, read_model};
use linkage::scene::{load_scene, Simulation, World};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A model file of `tests/models/`.
fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/models")
        .join(name)
}

/// The displacements of every body at the last step, per node `[x, y(, z)]`, m.
fn solve(world: &World) -> Vec<Vec<Vec<f64>>> {
    let mut sim = Simulation::new(world).unwrap_or_else(|e| panic!("{e}"));
    let mut last = None;
    for step in 1..=world.steps {
        let (result, summary) = sim.step(step).unwrap_or_else(|e| panic!("{e}"));
        assert!(summary.residual <= 1e-9, "residual {}", summary.residual);
        last = Some(result);
    }
    last.unwrap()
        .bodies
        .into_iter()
        .map(|b| b.displacements)
        .collect()
}

/// The largest difference between two sets of displacements over the largest displacement.
fn relative_difference(a: &[Vec<Vec<f64>>], b: &[Vec<Vec<f64>>]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut largest: f64 = 0.0;
    let mut diff: f64 = 0.0;
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.len(), y.len(), "node counts differ");
        for (p, q) in x.iter().zip(y) {
            for (u, v) in p.iter().zip(q) {
                largest = largest.max(u.abs());
                diff = diff.max((u - v).abs());
            }
        }
    }
    assert!(largest > 0.0, "nothing moved");
    diff / largest
}

/// Write `text` as `dir/name` and return its path.
fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A scene of one body read from `file` with its groups `clamp` held and `load` pulled.
fn group_scene(dir: &Path, file: &Path, clamp: &str, load: &str, force: &str) -> PathBuf {
    let fix = if force.matches(',').count() == 1 {
        r#"["x", "y"]"#
    } else {
        r#"["x", "y", "z"]"#
    };
    write(
        dir,
        "scene.toml",
        &format!(
            r#"name = "from_gmsh"
[[materials]]
name = "aluminium"
youngs_modulus = 70e9
area = 1e-6

[[bodies]]
name = "part"
model = "{}"

[[bodies.supports]]
group = "{clamp}"
fix = {fix}

[[bodies.loads]]
group = "{load}"
total_force = {force}
"#,
            file.display()
        ),
    )
}

/// Solve the scene of `file` (groups `clamp`, `load`), then the scene `linkage import` writes
/// of it (the paper's files, node lists): the same displacements to 1e-12 of the largest.
fn agrees_with_its_paper_files(file: &str, clamp: &str, load: &str, force: &str) -> World {
    let dir = tempfile::tempdir().unwrap();
    let scene = group_scene(dir.path(), &model(file), clamp, load, force);
    let world = load_scene(&scene).unwrap_or_else(|e| panic!("{e}"));
    let from_model = solve(&world);
    let imported = import_file(&scene, &dir.path().join("imported")).unwrap();
    assert!(imported.complete);
    let paper = load_scene(&imported.scene).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(&imported.scene).unwrap();
    assert!(
        !text.contains("model =") && !text.contains("group ="),
        "{text}"
    );
    assert_eq!(paper.bodies[0].nodes, world.bodies[0].nodes);
    assert_eq!(paper.bodies[0].members, world.bodies[0].members);
    assert_eq!(paper.bodies[0].patches, world.bodies[0].patches);
    let difference = relative_difference(&from_model, &solve(&paper));
    assert!(difference <= 1e-12, "{file}: differs by {difference:e}");
    world
}

/// The same body from gmsh's ASCII and binary files: the same members, nodes within 1e-15 m
/// (gmsh writes ASCII coordinates with 16 digits, which may miss a double's last bit).
fn same_body(a: &linkage::linkage::Body, b: &linkage::linkage::Body) {
    assert_eq!(a.members, b.members);
    assert_eq!(a.nodes.len(), b.nodes.len());
    for (p, q) in a.nodes.iter().zip(&b.nodes) {
        assert!((p - q).norm() <= 1e-15, "{p:?} against {q:?}");
    }
}

/// The plate with a hole (2D triangles, gmsh ASCII and binary): its clamp and tip curves as
/// groups, the same displacements as its paper files (1e-12), ASCII and binary the same body.
#[test]
fn gmsh_plate_with_a_hole_runs_and_agrees_with_its_paper_files() {
    let ascii = agrees_with_its_paper_files("plate_hole.msh", "clamp", "tip", "[1000.0, 0.0]");
    let binary =
        agrees_with_its_paper_files("plate_hole_binary.msh", "clamp", "tip", "[1000.0, 0.0]");
    let (a, b) = (&ascii.bodies[0], &binary.bodies[0]);
    assert_eq!(a.dimension, linkage::linkage::Dimension::Two);
    assert!(a.patches.is_empty());
    same_body(a, b);
    assert_eq!(a.supports.len(), b.supports.len());
    // The clamp is the curve x = 0, the load the curve x = 0.2 m.
    assert!(!a.supports.is_empty());
    assert!(a.supports.iter().all(|s| a.nodes[s.node].x.abs() < 1e-12));
    assert!(a
        .loads
        .iter()
        .all(|l| (a.nodes[l.node].x - 0.2).abs() < 1e-12));
    let total: f64 = a.loads.iter().map(|l| l.force.x).sum();
    assert!((total - 1000.0).abs() < 1e-9, "total load {total}");
}

/// The L bracket (tetrahedra, gmsh ASCII and binary): the same displacements as its paper
/// files (1e-12); its patches are the outward boundary of the tetrahedra, enclosing the
/// bracket's volume 6.4e-5 m³ (1e-12 relative: the faces are planar).
#[test]
fn gmsh_bracket_runs_and_agrees_with_its_paper_files() {
    let ascii = agrees_with_its_paper_files("bracket.msh", "clamp", "load", "[0.0, 0.0, -500.0]");
    let binary =
        agrees_with_its_paper_files("bracket_binary.msh", "clamp", "load", "[0.0, 0.0, -500.0]");
    let (a, b) = (&ascii.bodies[0], &binary.bodies[0]);
    same_body(a, b);
    assert_eq!(a.patches, b.patches);
    let volume = enclosed_volume(&a.nodes, &a.patches);
    assert!(
        (volume - 6.4e-5).abs() <= 1e-12 * 6.4e-5,
        "volume {volume:e}"
    );
    // Closed: every patch edge is shared by exactly two patches, once each way.
    let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
    for p in &a.patches {
        for k in 0..3 {
            *edges.entry((p[k], p[(k + 1) % 3])).or_default() += 1;
        }
    }
    assert!(edges
        .iter()
        .all(|(&(i, j), &n)| n == 1 && edges.get(&(j, i)) == Some(&1)));
    assert!(a.supports.iter().all(|s| a.nodes[s.node].x.abs() < 1e-12));
    assert!(a
        .loads
        .iter()
        .all(|l| (a.nodes[l.node].z - 0.08).abs() < 1e-12));
}

/// A point by the bits of its coordinates.
type Point = [u64; 3];

/// An edge by its two points, sorted.
type Edge = [Point; 2];

/// meshio's reading of `file`: its points and cells by type, as JSON.
fn meshio_reading(file: &Path) -> serde_json::Value {
    let python = common::python_with_meshio().unwrap_or_else(|e| panic!("{e}"));
    let out = Command::new(python)
        .args([
            "-c",
            "import json, sys, meshio\n\
             m = meshio.read(sys.argv[1])\n\
             print(json.dumps({'points': m.points.tolist(), \
             'cells': [[c.type, c.data.tolist()] for c in m.cells]}))",
        ])
        .arg(file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "meshio cannot read {}: {}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The edges (as pairs of coordinates' bits) of meshio's cells, and the tetrahedra's faces
/// used once; our nodes must be exactly meshio's points that cells use.
fn edges_by_coordinates(reading: &serde_json::Value) -> (HashSet<Edge>, usize, HashSet<Point>) {
    let points: Vec<Point> = reading["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [0, 1, 2].map(|k| p[k].as_f64().unwrap().to_bits()))
        .collect();
    let mut edges = HashSet::new();
    let mut used = HashSet::new();
    let mut faces: HashMap<Vec<usize>, usize> = HashMap::new();
    for cell in reading["cells"].as_array().unwrap() {
        let pairs: &[[usize; 2]] = match cell[0].as_str().unwrap() {
            "line" => &[[0, 1]],
            "triangle" => &[[0, 1], [1, 2], [2, 0]],
            "tetra" => &[[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]],
            _ => &[],
        };
        for c in cell[1].as_array().unwrap() {
            let n: Vec<usize> = c
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as usize)
                .collect();
            for &[i, j] in pairs {
                let mut e = [points[n[i]], points[n[j]]];
                e.sort();
                edges.insert(e);
                used.insert(points[n[i]]);
                used.insert(points[n[j]]);
            }
            if cell[0] == "tetra" {
                for skip in 0..4 {
                    let mut f: Vec<usize> = (0..4).filter(|&k| k != skip).map(|k| n[k]).collect();
                    f.sort();
                    *faces.entry(f).or_default() += 1;
                }
            }
        }
    }
    let boundary = faces.values().filter(|&&c| c == 1).count();
    (edges, boundary, used)
}

/// gmsh's files as meshio reads them: the same nodes (bit for bit), the same member edges,
/// as many patches as the tetrahedra have boundary faces.
#[test]
fn gmsh_files_read_as_meshio_reads_them() {
    for file in [
        "plate_hole.msh",
        "plate_hole_binary.msh",
        "bracket.msh",
        "bracket_binary.msh",
    ] {
        let ours = read_model(&model(file)).unwrap_or_else(|e| panic!("{e}"));
        let (edges, boundary, used) = edges_by_coordinates(&meshio_reading(&model(file)));
        let g = &ours.geometry;
        let bits = |n: usize| [0, 1, 2].map(|k| g.nodes[n][k].to_bits());
        let nodes: HashSet<Point> = (0..g.nodes.len()).map(bits).collect();
        assert_eq!(nodes.len(), g.nodes.len(), "{file}: nodes repeat");
        assert_eq!(nodes, used, "{file}: nodes differ from meshio's");
        let ours_edges: HashSet<Edge> = g
            .members
            .iter()
            .map(|&[a, b]| {
                let mut e = [bits(a), bits(b)];
                e.sort();
                e
            })
            .collect();
        assert_eq!(ours_edges.len(), g.members.len(), "{file}: members repeat");
        assert_eq!(
            ours_edges, edges,
            "{file}: members differ from meshio's edges"
        );
        if file.starts_with("bracket") {
            assert_eq!(g.patches.len(), boundary, "{file}");
        }
    }
}

/// The space truss of `tests/models/space_truss.inp` written by hand as the paper's files: 20
/// nodes at x = 0..4 m on the corners (0, 0), (0.5, 0), (0.5, 0.5), (0, 0.5) of the section;
/// chords, rings, face diagonals and ring diagonals in the file's element order.
fn space_truss_scene(dir: &Path) -> PathBuf {
    let corners = [(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)];
    let mut nodes = String::new();
    for i in 0..5 {
        for (y, z) in corners {
            nodes += &format!("{i}.0 {y} {z}\n");
        }
    }
    let mut links = String::new();
    let node = |i: usize, k: usize| 4 * i + k + 1;
    for i in 0..4 {
        for k in 0..4 {
            links += &format!("{} {} chord\n", node(i, k), node(i + 1, k));
        }
    }
    for i in 0..5 {
        for k in 0..4 {
            links += &format!("{} {} web\n", node(i, k), node(i, (k + 1) % 4));
        }
    }
    for i in 0..4 {
        for k in 0..4 {
            links += &format!("{} {} web\n", node(i, k), node(i + 1, (k + 1) % 4));
        }
    }
    for i in 0..5 {
        links += &format!("{} {} web\n", node(i, 0), node(i, 2));
    }
    write(dir, "truss.nodes", &nodes);
    write(dir, "truss.links", &links);
    write(
        dir,
        "truss.toml",
        r#"name = "truss"
[[materials]]
name = "chord"
youngs_modulus = 2.1e11
area = 1e-3
[[materials]]
name = "web"
youngs_modulus = 2.1e11
area = 4e-4
[[bodies]]
name = "truss"
nodes = "truss.nodes"
links = "truss.links"
[[bodies.supports]]
nodes = [1, 2, 3, 4]
fix = ["x", "y", "z"]
[[bodies.loads]]
nodes = [17, 18, 19, 20]
force = [0.0, 0.0, -1000.0]
[[bodies.loads]]
nodes = [17]
force = [250.0, 0.0, 0.0]
"#,
    )
}

/// A scene whose one body is the model file `file`.
fn model_scene(dir: &Path, file: &Path) -> PathBuf {
    write(
        dir,
        "model.toml",
        &format!(
            "name = \"model\"\n[[bodies]]\nname = \"truss\"\nmodel = \"{}\"\n",
            file.display()
        ),
    )
}

/// The INP space truss (`*NSET` with `GENERATE` and a continued line, `*ELSET, GENERATE`, two
/// sections of one material, `*BOUNDARY` by set with `ENCASTRE`, `*CLOAD` by set and node):
/// the same displacements as the truss written as a scene by hand, to 1e-12; the ignored
/// output requests are reported with their lines.
#[test]
fn inp_space_truss_gives_the_displacements_of_the_same_scene() {
    let dir = tempfile::tempdir().unwrap();
    let by_hand = load_scene(&space_truss_scene(dir.path())).unwrap_or_else(|e| panic!("{e}"));
    let from_inp = load_scene(&model_scene(dir.path(), &model("space_truss.inp")))
        .unwrap_or_else(|e| panic!("{e}"));
    let (a, b) = (&by_hand.bodies[0], &from_inp.bodies[0]);
    assert_eq!(a.nodes, b.nodes);
    let ends = |body: &linkage::linkage::Body| -> Vec<[usize; 2]> {
        body.members.iter().map(|m| m.nodes).collect()
    };
    assert_eq!(ends(a), ends(b));
    let area = |body: &linkage::linkage::Body| -> Vec<f64> {
        body.members
            .iter()
            .map(|m| body.materials[m.material].area)
            .collect()
    };
    assert_eq!(area(a), area(b));
    let names: Vec<&str> = b.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["STEEL_CHORDS", "STEEL_WEB"]);
    let difference = relative_difference(&solve(&by_hand), &solve(&from_inp));
    assert!(difference <= 1e-12, "differs by {difference:e}");
    let found = from_inp.found.join("\n");
    assert!(
        found.contains("space_truss.inp:109: *NODE PRINT is ignored"),
        "{found}"
    );
    assert!(
        found.contains("space_truss.inp:111: *EL PRINT is ignored"),
        "{found}"
    );
}

/// The tripod of `tests/models/tripod.inp` (lower-case keywords, nodes in an `*INCLUDE`d file,
/// a generated set of pinned feet): the apex of legs of length L = √5 m at sin θ = 2/√5 under
/// P = 1e4 N goes down by w = P L / (3 E A sin²θ) (statics of three equal legs), to 1e-12.
#[test]
fn inp_tripod_apex_moves_as_the_closed_form() {
    let dir = tempfile::tempdir().unwrap();
    let world = load_scene(&model_scene(dir.path(), &model("tripod.inp")))
        .unwrap_or_else(|e| panic!("{e}"));
    let u = solve(&world);
    let (p, e, a) = (1e4, 2e11, 1e-4);
    let length = 5f64.sqrt();
    let sin = 2.0 / length;
    let w = p * length / (3.0 * e * a * sin * sin);
    let apex = &u[0][3];
    assert!(
        (apex[2] + w).abs() <= 1e-12 * w,
        "apex {apex:?}, closed form {w:e}"
    );
    assert!(
        apex[0].abs() <= 1e-12 * w && apex[1].abs() <= 1e-12 * w,
        "{apex:?}"
    );
}

/// meshio reads the same nodes and members (T3D2 as `line` cells) from the INP file.
#[test]
fn meshio_reads_the_same_nodes_and_members_from_the_inp() {
    let ours = read_model(&model("space_truss.inp")).unwrap_or_else(|e| panic!("{e}"));
    let reading = meshio_reading(&model("space_truss.inp"));
    let points: Vec<Vec<f64>> = reading["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            p.as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect()
        })
        .collect();
    let nodes: Vec<Vec<f64>> = ours
        .geometry
        .nodes
        .iter()
        .map(|p| p.iter().copied().collect())
        .collect();
    assert_eq!(nodes, points);
    let lines: Vec<[usize; 2]> = reading["cells"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c[0] == "line")
        .flat_map(|c| c[1].as_array().unwrap().clone())
        .map(|c| [0, 1].map(|k| c[k].as_u64().unwrap() as usize))
        .collect();
    assert_eq!(lines, ours.geometry.members);
}

/// `linkage import space_truss.inp` writes a scene that `linkage run` solves to the
/// displacements of the body read with `model =` (1e-12), and prints the ignored keywords.
#[test]
fn linkage_import_writes_a_scene_that_runs() {
    let dir = tempfile::tempdir().unwrap();
    let exe = env!("CARGO_BIN_EXE_linkage");
    let out = Command::new(exe)
        .args(["import"])
        .arg(model("space_truss.inp"))
        .arg("--out")
        .arg(dir.path().join("imported"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("*NODE PRINT is ignored"), "{stdout}");
    let scene = dir.path().join("imported/space_truss.toml");
    let run = Command::new(exe)
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let step: serde_json::Value = serde_json::from_slice(
        &std::fs::read(dir.path().join("out/space_truss/steps/0001.json")).unwrap(),
    )
    .unwrap();
    let ran: Vec<Vec<f64>> =
        serde_json::from_value(step["bodies"][0]["displacements"].clone()).unwrap();
    let direct = solve(&load_scene(&model_scene(dir.path(), &model("space_truss.inp"))).unwrap());
    let difference = relative_difference(&direct, &[ran]);
    assert!(difference <= 1e-12, "differs by {difference:e}");
}

/// Bad INP input: the message names the file and line and says what to do.
#[test]
fn inp_errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let head = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n";
    let cases = [
        ("*ELEMENT, TYPE=B31\n1, 1, 2\n", 5, "B31 is a beam"),
        ("*ELEMENT, TYPE=T3D2\n1, 1, 9\n", 6, "names node 9"),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*BOUNDARY\nFEET, 1, 3\n",
            8,
            "\"FEET\" is neither",
        ),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*CLOAD\n2, 5, 1.0\n",
            8,
            "no moments",
        ),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*STEP\n*STATIC\n*END STEP\n*STEP\n",
            10,
            "a second *STEP",
        ),
        ("*INCLUDE, INPUT=missing.inp\n", 5, "cannot read"),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*SOLID SECTION, ELSET=BARS, MATERIAL=STEEL\n1e-4\n",
            7,
            "ELSET=BARS: no such element set",
        ),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*NSET, NSET=A, GENERATE\n3, 1\n",
            8,
            "GENERATE 3, 1, 1",
        ),
        (
            "*ELEMENT, TYPE=T3D2\n1, 1, 2\n*NODE\n4, 1, x, 0\n",
            8,
            "y of node 4 is \"x\"",
        ),
    ];
    for (k, (tail, line, words)) in cases.iter().enumerate() {
        let path = write(dir.path(), &format!("bad{k}.inp"), &format!("{head}{tail}"));
        let message = read_model(&path).unwrap_err().to_string();
        let at = format!("bad{k}.inp:{line}: ");
        assert!(
            message.contains(&at) && message.contains(words),
            "case {k}: {message}"
        );
    }
    // Through a scene: the scene line of `model` and the file's own line.
    let path = write(
        dir.path(),
        "beam.inp",
        &format!("{head}*ELEMENT, TYPE=B31\n1, 1, 2\n"),
    );
    let message = load_scene(&model_scene(dir.path(), &path))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("model.toml:") && message.contains("beam.inp:5:"),
        "{message}"
    );
}

/// Bad MSH input and bad groups: file and line named.
#[test]
fn msh_and_group_errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let plate = std::fs::read_to_string(model("plate_hole.msh")).unwrap();
    let old = write(
        dir.path(),
        "old.msh",
        &plate.replacen("4.1 0 8", "2.2 0 8", 1),
    );
    let message = read_model(&old).unwrap_err().to_string();
    assert!(message.contains("old.msh:2: MSH version 2.2"), "{message}");
    // A second-order element type in the first element block.
    let first_block = plate.find("$Elements\n").unwrap() + "$Elements\n".len();
    let block_line = plate[..first_block].matches('\n').count() + 2;
    let header_end = first_block + plate[first_block..].find('\n').unwrap() + 1;
    let block_end = header_end + plate[header_end..].find('\n').unwrap();
    let words: Vec<&str> = plate[header_end..block_end].split_whitespace().collect();
    let changed = format!(
        "{}{} {} 9 {}{}",
        &plate[..header_end],
        words[0],
        words[1],
        words[3],
        &plate[block_end..]
    );
    let second = write(dir.path(), "second.msh", &changed);
    let message = read_model(&second).unwrap_err().to_string();
    assert!(
        message.contains(&format!("second.msh:{block_line}: element type 9")),
        "{message}"
    );
    let scene = group_scene(
        dir.path(),
        &model("plate_hole.msh"),
        "clamps",
        "tip",
        "[1.0, 0.0]",
    );
    let message = load_scene(&scene).unwrap_err().to_string();
    assert!(
        message.contains("scene.toml:12:")
            && message.contains("\"clamps\" is not a group")
            && message.contains("\"clamp\", \"tip\", \"plate\""),
        "{message}"
    );
}

/// Model files cut short anywhere give an error naming the file (never a panic, never a
/// body from half a file): 60 cuts through each file.
#[test]
fn truncated_model_files_give_errors() {
    let dir = tempfile::tempdir().unwrap();
    for file in ["plate_hole.msh", "bracket_binary.msh", "space_truss.inp"] {
        let bytes = std::fs::read(model(file)).unwrap();
        // The last section's end: cuts before it lose data.
        let end = if file.ends_with(".msh") {
            bytes
                .windows(12)
                .rposition(|w| w == b"$EndElements")
                .unwrap()
        } else {
            bytes.windows(6).rposition(|w| w == b"*CLOAD").unwrap()
        };
        for k in 0..60 {
            let cut = end * k / 60;
            let path = dir.path().join(format!("cut.{}", &file[file.len() - 3..]));
            std::fs::write(&path, &bytes[..cut]).unwrap();
            match read_model(&path) {
                Err(e) => assert!(e.to_string().contains("cut."), "{file} cut at {cut}: {e}"),
                Ok(m) if file.ends_with(".inp") => {
                    // An INP file cut between keywords is a smaller valid model.
                    assert!(m.geometry.members.len() <= 57)
                }
                Ok(_) => panic!("{file} cut at byte {cut} of {} read as a body", bytes.len()),
            }
        }
    }
}
