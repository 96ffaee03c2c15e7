//! A lattice as the solid it models: the homogenization against a hand calculation, and
//! `continuum_modulus` giving a cube (prepared from a mesh, or a `box_lattice`) the modulus it
//! asks for, measured by the real scene run of a uniaxial compression.

use linkage::linkage::homogenize::{continuum_volume, effective_elasticity};
use linkage::linkage::{Body, Dimension, Material, Member};
use linkage::scene::{build_world, run_in_memory};
use nalgebra::Vector3;
use std::path::Path;

/// A cube's side, m.
const SIDE: f64 = 0.1;
/// The shortening of the compressed cube, m (strain 1e-4).
const SHORTENING: f64 = 1e-5;

/// A cube cell of side `a` whose 12 edges are the only members: along z only the 4 vertical
/// edges carry the uniaxial load, so `E_z = F L / V = 4 (E A / a) a / a³ = 4 E A / a²` and
/// nothing couples the axes (ν = 0).
#[test]
fn a_cube_of_edges_has_the_hand_calculated_modulus() {
    let a = 0.2;
    let mut body = Body::new("cell", Dimension::Three);
    for k in 0..8 {
        body.nodes.push(Vector3::new(
            a * (k & 1) as f64,
            a * ((k >> 1) & 1) as f64,
            a * ((k >> 2) & 1) as f64,
        ));
    }
    for i in 0..8usize {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                body.members.push(Member {
                    nodes: [i, i | bit],
                    material: 0,
                });
            }
        }
    }
    body.materials = vec![Material::new("steel", 200e9, 1e-4)];
    let solid = effective_elasticity(&body, a * a * a).unwrap();
    let hand = 4.0 * 200e9 * 1e-4 / (a * a);
    for e in solid.youngs_moduli {
        assert!((e / hand - 1.0).abs() < 1e-9, "{e} against {hand}");
    }
    assert!(solid.poisson_ratio.abs() < 1e-9, "{solid:?}");
    // Without patches the solid is the bounding box.
    assert!((continuum_volume(&body) - a * a * a).abs() < 1e-15);
}

/// A closed cube of `SIDE` as OBJ text, faces outward.
fn cube_obj() -> String {
    let mut text = String::new();
    for k in 0..8 {
        text += &format!(
            "v {} {} {}\n",
            SIDE * (k & 1) as f64,
            SIDE * ((k >> 1) & 1) as f64,
            SIDE * ((k >> 2) & 1) as f64
        );
    }
    // Quads (1-based OBJ vertices), counter-clockwise seen from outside.
    for [a, b, c, d] in [
        [1, 3, 4, 2],
        [5, 6, 8, 7],
        [1, 2, 6, 5],
        [3, 7, 8, 4],
        [1, 5, 7, 3],
        [2, 4, 8, 6],
    ] {
        text += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
    }
    text
}

/// The scene of a cube of `geometry` (a body key) compressed along z: z held on the bottom
/// face, the top face moved down by `SHORTENING` in z only, the lateral faces free; the bottom
/// face's centre held in x and y and a node at its edge in y (the rigid motions only).
fn compression_scene(material: &str, geometry: &str) -> String {
    let h = SIDE / 2.0;
    format!(
        r#"name = "compressed_cube"
steps = 1

[[materials]]
name = "alu"
youngs_modulus = 70e9
{material}

[[bodies]]
name = "cube"
{geometry}

[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
fix = ["z"]

[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, {SIDE}], normal = [0.0, 0.0, 1.0] }}
fix = ["z"]
displacement = [0.0, 0.0, -{SHORTENING}]

[[bodies.supports]]
nearest = [{h}, {h}, 0.0]
fix = ["x", "y"]

[[bodies.supports]]
nearest = [{SIDE}, {h}, 0.0]
fix = ["y"]
"#
    )
}

/// The cube's modulus as the run measures it: the force on the top face over the section,
/// over the strain; and the world's computed elasticity as a solid.
fn measured_modulus(dir: &Path, material: &str, geometry: &str) -> (f64, f64, f64) {
    std::fs::write(dir.join("cube.obj"), cube_obj()).unwrap();
    let path = dir.join("cube.toml");
    let text = compression_scene(material, geometry);
    std::fs::write(&path, &text).unwrap();
    let world = build_world(&text, &path).unwrap();
    let solid = world.solids["cube"];
    let (_, steps, failure) = run_in_memory(&world, &|| {}).unwrap();
    assert!(failure.is_none(), "{failure:?}");
    let (first, last) = (&steps[0].bodies[0], &steps[steps.len() - 1].bodies[0]);
    let top: f64 = last
        .reactions
        .iter()
        .filter(|r| (first.positions[r.node - 1][2] - SIDE).abs() < 1e-9)
        .map(|r| r.force[2])
        .sum();
    let bottom: f64 = last
        .reactions
        .iter()
        .filter(|r| first.positions[r.node - 1][2].abs() < 1e-9)
        .map(|r| r.force[2])
        .sum();
    assert!(
        (top + bottom).abs() < 1e-6 * top.abs(),
        "top {top} N, bottom {bottom} N"
    );
    let modulus = -top / (SIDE * SIDE) / (SHORTENING / SIDE);
    (modulus, solid.youngs_modulus, solid.poisson_ratio)
}

#[test]
fn a_cube_prepared_from_a_mesh_with_continuum_modulus_has_it_at_two_spacings() {
    let dir = tempfile::tempdir().unwrap();
    for spacing in [SIDE / 4.0, SIDE / 6.0] {
        let (measured, computed, poisson) = measured_modulus(
            dir.path(),
            "continuum_modulus = 70e9",
            &format!(r#"mesh = {{ file = "cube.obj", spacing = {spacing} }}"#),
        );
        eprintln!("mesh cube, spacing {spacing}: run {measured:.6e} Pa ({:+.2e} relative), uniaxial tests {computed:.6e} Pa, nu {poisson:.4}", measured / 70e9 - 1.0);
        assert!((computed / 70e9 - 1.0).abs() < 1e-9, "{computed}");
        assert!(
            (measured / 70e9 - 1.0).abs() < 0.02,
            "spacing {spacing}: {measured} Pa"
        );
        assert!((0.1..0.35).contains(&poisson), "{poisson}");
    }
}

#[test]
fn a_box_lattice_with_continuum_modulus_has_it_at_two_spacings() {
    let dir = tempfile::tempdir().unwrap();
    for cells in [4, 6] {
        let (measured, computed, poisson) = measured_modulus(
            dir.path(),
            "continuum_modulus = 70e9",
            &format!("box_lattice = {{ size = [{SIDE}, {SIDE}, {SIDE}], cells = [{cells}, {cells}, {cells}] }}"),
        );
        eprintln!("box_lattice, {cells} cells: run {measured:.6e} Pa ({:+.2e} relative), uniaxial tests {computed:.6e} Pa, nu {poisson:.4}", measured / 70e9 - 1.0);
        assert!((computed / 70e9 - 1.0).abs() < 1e-9, "{computed}");
        assert!(
            (measured / 70e9 - 1.0).abs() < 0.02,
            "{cells} cells: {measured} Pa"
        );
        assert!((0.2..0.4).contains(&poisson), "{poisson}");
    }
}

#[test]
fn area_and_continuum_modulus_together_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cube.toml");
    let text = compression_scene(
        "area = 1e-4\ncontinuum_modulus = 70e9",
        "box_lattice = { size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }",
    );
    let e = build_world(&text, &path).unwrap_err().to_string();
    assert!(
        e.contains("cube.toml:7") && e.contains("either `area`") && e.contains("not both"),
        "{e}"
    );
    let text = compression_scene(
        "",
        "box_lattice = { size = [0.1, 0.1, 0.1], cells = [2, 2, 2] }",
    );
    let e = build_world(&text, &path).unwrap_err().to_string();
    assert!(e.contains("give `area`"), "{e}");
}

#[test]
fn continuum_modulus_on_a_plane_body_is_refused_at_its_material() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plane.toml");
    let text = r#"name = "plane"
[[materials]]
name = "alu"
youngs_modulus = 70e9
continuum_modulus = 70e9

[[bodies]]
name = "plate"
rectangle = { width = 1.0, height = 0.5, cells = [4, 2] }
material = "alu"

[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
"#;
    let e = build_world(text, &path).unwrap_err().to_string();
    assert!(
        e.contains("plane.toml:10") && e.contains("is 2D") && e.contains("give it an `area`"),
        "{e}"
    );
}
