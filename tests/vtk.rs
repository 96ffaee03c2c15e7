//! ParaView files read back by a real VTK reader (Python's meshio): geometry, cells and the
//! arrays carry the values of the step files.
//!
//! meshio is installed on first use into a venv under `target/` (PyPI must be reachable);
//! `.ci/run` installs it before the tests.

mod common;

use linkage::scene::{load_scene, run, StepResult};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A Python with meshio (see [`common::python_with_meshio`]); a test fails when it cannot be
/// made.
fn meshio_python() -> PathBuf {
    common::python_with_meshio().unwrap_or_else(|e| panic!("{e}"))
}

const READ: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
print(json.dumps({
    "points": m.points.tolist(),
    "cells": [[c.type, c.data.tolist()] for c in m.cells],
    "point_data": {k: v.tolist() for k, v in m.point_data.items()},
    "cell_data": {k: [a.tolist() for a in v] for k, v in m.cell_data.items()},
}))
"#;

fn read_vtu(python: &Path, file: &Path) -> Value {
    let o = Command::new(python)
        .args(["-c", READ])
        .arg(file)
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "meshio cannot read {}: {}",
        file.display(),
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).unwrap()
}

fn run_with_vtk(scene: &str, out: &Path) -> PathBuf {
    let mut world = load_scene(Path::new(scene)).unwrap();
    world.pictures.vtk = true;
    run(&world, out, &|| {}).unwrap();
    out.join(&world.name)
}

fn step(dir: &Path, k: usize) -> StepResult {
    serde_json::from_slice(&std::fs::read(dir.join(format!("steps/{k:04}.json"))).unwrap()).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn vtu_files_parse_with_meshio_and_carry_the_step_values() {
    let python = meshio_python();
    let out = tempfile::tempdir().unwrap();

    // 2D: members as lines, overloaded flags, loads and reactions as point data.
    let dir = run_with_vtk("scenes/paper_overload.toml", out.path());
    let model: Value =
        serde_json::from_slice(&std::fs::read(dir.join("model.json")).unwrap()).unwrap();
    let r = step(&dir, 10);
    let b = &r.bodies[0];
    let v = read_vtu(&python, &dir.join("vtk/0010.vtu"));
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), b.positions.len());
    for (p, q) in points.iter().zip(&b.positions) {
        assert_eq!(f(&p[0]), q[0]);
        assert_eq!(f(&p[1]), q[1]);
        assert_eq!(f(&p[2]), 0.0);
    }
    let cells = v["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 1);
    assert_eq!(cells[0][0], "line");
    let lines = cells[0][1].as_array().unwrap();
    let members = model["bodies"][0]["members"].as_array().unwrap();
    assert_eq!(lines.len(), members.len());
    for (l, m) in lines.iter().zip(members) {
        assert_eq!(l[0].as_u64().unwrap() + 1, m[0].as_u64().unwrap());
        assert_eq!(l[1].as_u64().unwrap() + 1, m[1].as_u64().unwrap());
    }
    let cd = &v["cell_data"];
    for (j, s) in b.stresses.iter().enumerate() {
        assert_eq!(f(&cd["stress"][0][j]), *s);
        assert_eq!(f(&cd["axial_force"][0][j]), b.axial_forces[j]);
        let flagged = cd["overloaded"][0][j].as_i64().unwrap() == 1;
        assert_eq!(flagged, b.overloaded.contains(&(j + 1)), "member {}", j + 1);
    }
    assert!(!b.overloaded.is_empty());
    let pd = &v["point_data"];
    for (n, u) in b.displacements.iter().enumerate() {
        assert_eq!(f(&pd["displacement"][n][0]), u[0]);
        assert_eq!(f(&pd["displacement"][n][1]), u[1]);
    }
    for l in &b.loads {
        assert_eq!(f(&pd["applied_force"][l.node - 1][0]), l.force[0]);
    }
    for reaction in &b.reactions {
        assert_eq!(f(&pd["reaction"][reaction.node - 1][1]), reaction.force[1]);
    }
    // The collection plays the steps with the load factor as time.
    let pvd = std::fs::read_to_string(dir.join("vtk/paper_overload.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 11);
    assert!(pvd.contains("timestep=\"0.5\" group=\"\" part=\"0\" file=\"0005.vtu\""));

    // 3D: patches as triangles with the mean stress of their edge members.
    let dir = run_with_vtk("scenes/paper_shell.toml", out.path());
    let model: Value =
        serde_json::from_slice(&std::fs::read(dir.join("model.json")).unwrap()).unwrap();
    let r = step(&dir, 4);
    let b = &r.bodies[0];
    let v = read_vtu(&python, &dir.join("vtk/0004.vtu"));
    let cells = v["cells"].as_array().unwrap();
    let types: Vec<&str> = cells.iter().map(|c| c[0].as_str().unwrap()).collect();
    assert_eq!(types, ["line", "triangle"]);
    let patches = model["bodies"][0]["patches"].as_array().unwrap();
    let members: Vec<[u64; 2]> = model["bodies"][0]["members"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| [m[0].as_u64().unwrap(), m[1].as_u64().unwrap()])
        .collect();
    assert_eq!(cells[1][1].as_array().unwrap().len(), patches.len());
    let p = &patches[5];
    let nodes: Vec<u64> = (0..3).map(|k| p[k].as_u64().unwrap()).collect();
    let mut sum = 0.0;
    let mut count = 0;
    for k in 0..3 {
        let (a, c) = (nodes[k], nodes[(k + 1) % 3]);
        if let Some(j) = members
            .iter()
            .position(|m| (m[0] == a && m[1] == c) || (m[0] == c && m[1] == a))
        {
            sum += b.stresses[j];
            count += 1;
        }
    }
    assert_eq!(count, 3);
    let got = f(&v["cell_data"]["stress"][1][5]);
    assert!(
        (got - sum / 3.0).abs() <= 1e-9 * got.abs().max(1.0),
        "{got}"
    );
    assert_eq!(v["cell_data"]["overloaded"][1][5].as_i64().unwrap(), 0);
    assert_eq!(v["points"][7][2].as_f64().unwrap(), b.positions[7][2]);
}

#[test]
fn a_falling_load_plays_by_step_number_in_paraview() {
    // ParaView needs increasing times: with a load that falls, the .pvd uses step numbers.
    let text = r#"
name = "falling"
steps = 3
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "bar"
rectangle = { width = 1.0, height = 0.5, cells = [2, 1] }
[[bodies.supports]]
nearest = [0.0, 0.0]
fix = ["x", "y"]
[[bodies.supports]]
nearest = [1.0, 0.0]
fix = ["y"]
[[bodies.loads]]
nearest = [1.0, 0.5]
force = [100.0, 0.0]
schedule = [1.0, 0.5, 0.25]
[output]
vtk = true
"#;
    let out = tempfile::tempdir().unwrap();
    let world = linkage::scene::build_world(text, &out.path().join("s.toml")).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let pvd = std::fs::read_to_string(out.path().join("falling/vtk/falling.pvd")).unwrap();
    for k in 0..=3 {
        assert!(
            pvd.contains(&format!(
                "timestep=\"{k}\" group=\"\" part=\"0\" file=\"{k:04}.vtu\""
            )),
            "{pvd}"
        );
    }
}

const READ_FIELD: &str = r#"
import json, sys, meshio
m = meshio.read(sys.argv[1])
print(json.dumps({k: v.tolist() for k, v in m.field_data.items()}))
"#;

fn field_data(python: &Path, file: &Path) -> Value {
    let o = Command::new(python)
        .args(["-c", READ_FIELD])
        .arg(file)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

fn point(v: &Value) -> [f64; 3] {
    [f(&v[0]), f(&v[1]), f(&v[2])]
}

#[test]
fn obstacles_are_drawn_where_contact_sees_them() {
    let python = meshio_python();
    let out = tempfile::tempdir().unwrap();

    // The press block of shell_on_block_moving at the last step: 8 corners at
    // centre + travel ± half extents, 12 triangles, all of obstacle 1 ("block").
    let dir = run_with_vtk("scenes/shell_on_block_moving.toml", out.path());
    let v = read_vtu(&python, &dir.join("vtk/obstacles_0004.vtu"));
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), 8);
    let centre = [1.93, -0.35 + 0.02, 0.0];
    let half = [0.15, 0.1, 0.3];
    for signs in 0..8 {
        let corner: Vec<f64> = (0..3)
            .map(|k| {
                let s = if signs & (1 << k) == 0 { -1.0 } else { 1.0 };
                centre[k] + s * half[k]
            })
            .collect();
        let found = points.iter().any(|p| {
            let p = point(p);
            (0..3).all(|k| (p[k] - corner[k]).abs() <= 1e-12)
        });
        assert!(found, "corner {corner:?} not among {points:?}");
    }
    let cells = v["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 1);
    assert_eq!(cells[0][0], "triangle");
    assert_eq!(cells[0][1].as_array().unwrap().len(), 12);
    let ids = v["cell_data"]["obstacle"][0].as_array().unwrap();
    assert!(ids.iter().all(|i| i.as_i64() == Some(1)));
    assert_eq!(
        field_data(&python, &dir.join("vtk/obstacles_0004.vtu"))["block"][0],
        1
    );
    // Step 0: the block where the scene puts it.
    let v0 = read_vtu(&python, &dir.join("vtk/obstacles_0000.vtu"));
    let lowest = v0["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| point(p)[1])
        .fold(f64::INFINITY, f64::min);
    assert!((lowest - (-0.45)).abs() <= 1e-12, "{lowest}");
    // The collection holds the bodies as part 0 and the obstacles as part 1.
    let pvd = std::fs::read_to_string(dir.join("vtk/shell_on_block_moving.pvd")).unwrap();
    assert_eq!(pvd.matches("part=\"1\"").count(), 5, "{pvd}");
    assert!(
        pvd.contains("part=\"1\" file=\"obstacles_0004.vtu\""),
        "{pvd}"
    );
    // The bodies' file has the shell only.
    let bodies = read_vtu(&python, &dir.join("vtk/0004.vtu"));
    let r = step(&dir, 4);
    assert_eq!(
        bodies["points"].as_array().unwrap().len(),
        r.bodies[0].positions.len()
    );

    // A ball pressed on a plate (3D) with a floor: every vertex of the ball at its radius
    // from its centre moved by the travel; the floor a square in its plane.
    let text = r#"
name = "ball_press"
steps = 2
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "plate"
box_lattice = { size = [1.0, 0.1, 1.0], cells = [4, 1, 4] }
[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
fix = ["x", "y", "z"]
[[obstacles]]
name = "ball"
shape = "ball"
center = [0.5, 0.4, 0.5]
radius = 0.25
travel = [0.1, -0.05, 0.2]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.5, 0.0]
normal = [0.0, 1.0, 0.0]
[output]
vtk = true
"#;
    let world = linkage::scene::build_world(text, &out.path().join("b.toml")).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let file = out.path().join("ball_press/vtk/obstacles_0002.vtu");
    let v = read_vtu(&python, &file);
    let ids: Vec<i64> = v["cell_data"]["obstacle"][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i.as_i64().unwrap())
        .collect();
    let conn = v["cells"][0][1].as_array().unwrap();
    assert_eq!(v["cells"][0][0], "triangle");
    let centre = [0.6, 0.35, 0.7];
    let mut ball_vertices = std::collections::BTreeSet::new();
    let mut floor_vertices = std::collections::BTreeSet::new();
    for (t, id) in conn.iter().zip(&ids) {
        for i in t.as_array().unwrap() {
            let i = i.as_u64().unwrap();
            if *id == 1 {
                ball_vertices.insert(i);
            } else {
                assert_eq!(*id, 2);
                floor_vertices.insert(i);
            }
        }
    }
    assert_eq!(ids.iter().filter(|i| **i == 2).count(), 2);
    let points = v["points"].as_array().unwrap();
    assert!(ball_vertices.len() > 400, "{}", ball_vertices.len());
    for &i in &ball_vertices {
        let p = point(&points[i as usize]);
        let r =
            ((p[0] - centre[0]).powi(2) + (p[1] - centre[1]).powi(2) + (p[2] - centre[2]).powi(2))
                .sqrt();
        assert!((r - 0.25).abs() <= 1e-9, "vertex {i} at {r}");
    }
    assert_eq!(floor_vertices.len(), 4);
    for &i in &floor_vertices {
        assert_eq!(point(&points[i as usize])[1], -0.5);
    }
    let names = field_data(&python, &file);
    assert_eq!(
        (names["ball"][0].as_i64(), names["floor"][0].as_i64()),
        (Some(1), Some(2))
    );
}

#[test]
fn obstacles_of_a_2d_scene_are_their_cut_by_the_plane() {
    let python = meshio_python();
    let text = r#"
name = "disk_on_floor"
steps = 1
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "bar"
rectangle = { width = 1.0, height = 0.5, cells = [2, 1] }
[[bodies.supports]]
nearest = [0.0, 0.0]
fix = ["x", "y"]
[[obstacles]]
name = "disk"
shape = "ball"
center = [0.5, 1.0]
radius = 0.3
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.1]
normal = [0.0, 1.0]
[output]
vtk = true
"#;
    let out = tempfile::tempdir().unwrap();
    let world = linkage::scene::build_world(text, &out.path().join("s.toml")).unwrap();
    run(&world, out.path(), &|| {}).unwrap();
    let v = read_vtu(
        &python,
        &out.path().join("disk_on_floor/vtk/obstacles_0001.vtu"),
    );
    assert_eq!(v["cells"].as_array().unwrap().len(), 1);
    assert_eq!(v["cells"][0][0], "line");
    let ids = v["cell_data"]["obstacle"][0].as_array().unwrap();
    let points = v["points"].as_array().unwrap();
    let mut disk_segments = 0;
    for (l, id) in v["cells"][0][1].as_array().unwrap().iter().zip(ids) {
        for i in l.as_array().unwrap() {
            let p = point(&points[i.as_u64().unwrap() as usize]);
            assert_eq!(p[2], 0.0);
            if id.as_i64() == Some(1) {
                // On a chord of the circle: within its sagitta inside.
                let r = ((p[0] - 0.5).powi(2) + (p[1] - 1.0).powi(2)).sqrt();
                assert!((0.3 * 0.98..=0.3 + 1e-12).contains(&r), "{r}");
            } else {
                assert!((p[1] + 0.1).abs() <= 1e-12, "{p:?}");
            }
        }
        disk_segments += usize::from(id.as_i64() == Some(1));
    }
    assert!(disk_segments >= 16, "{disk_segments}");
}

/// The same run's ParaView files in both encodings: the binary ones (the default) are
/// compressed, far smaller, and meshio reads the same arrays from them as from ASCII, to the
/// last bit; the obstacles' file too.
#[test]
fn binary_and_ascii_files_carry_the_same_arrays() {
    let python = meshio_python();
    let out = tempfile::tempdir().unwrap();
    let mut sizes = Vec::new();
    let mut read = Vec::new();
    for (k, encoding) in [
        linkage::scene::VtkEncoding::Binary,
        linkage::scene::VtkEncoding::Ascii,
    ]
    .into_iter()
    .enumerate()
    {
        let mut world = load_scene(Path::new("scenes/shell_on_block_moving.toml")).unwrap();
        world.pictures.vtk = true;
        world.pictures.vtk_encoding = encoding;
        let root = out.path().join(k.to_string());
        run(&world, &root, &|| {}).unwrap();
        let dir = root.join(&world.name);
        let body = dir.join("vtk/0004.vtu");
        let obstacles = dir.join("vtk/obstacles_0004.vtu");
        let text = std::fs::read(&body).unwrap();
        let appended = String::from_utf8_lossy(&text).contains("format=\"appended\"");
        assert_eq!(appended, encoding == linkage::scene::VtkEncoding::Binary);
        sizes.push(text.len());
        read.push((read_vtu(&python, &body), read_vtu(&python, &obstacles)));
    }
    assert_eq!(read[0], read[1], "binary and ASCII arrays differ");
    assert!(
        sizes[0] * 2 < sizes[1],
        "binary {} bytes against ASCII {}",
        sizes[0],
        sizes[1]
    );
}

#[test]
fn each_member_carries_its_material_in_model_json_and_the_vtk_cells() {
    // The composite beam: steel members and aluminium members in one body, named per member
    // by the links file's third column.
    let python = meshio_python();
    let out = tempfile::tempdir().unwrap();
    let world = load_scene(Path::new("scenes/composite_beam.toml")).unwrap();
    let body = &world.bodies[0];
    let names: Vec<&str> = body
        .members
        .iter()
        .map(|m| body.materials[m.material].name.as_str())
        .collect();
    assert!(names.contains(&"steel") && names.contains(&"aluminium"));
    let dir = run_with_vtk("scenes/composite_beam.toml", out.path());
    let model: Value =
        serde_json::from_slice(&std::fs::read(dir.join("model.json")).unwrap()).unwrap();
    let recorded: Vec<&str> = model["bodies"][0]["member_materials"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(recorded, names);
    // VTK: the number of the name in order of first appearance.
    let first = names[0];
    let v = read_vtu(&python, &dir.join("vtk/0005.vtu"));
    let numbers = v["cell_data"]["material"][0].as_array().unwrap();
    assert_eq!(numbers.len(), names.len());
    for (n, name) in numbers.iter().zip(&names) {
        let expected = if *name == first { 1 } else { 2 };
        assert_eq!(n.as_i64().unwrap(), expected, "{name}");
    }
}
