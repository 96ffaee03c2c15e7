//! Loads that real parts carry: self-weight from a material's density under the scene's
//! gravity, lumped to the nodes.

use linkage::scene::build_world;
use std::path::Path;

const SCENE: &str = r#"
name = "heavy_box"
steps = 2
gravity = [0.0, -9.81, 0.0]

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
density = 7850.0

[[bodies]]
name = "box"
box_lattice = { size = [0.3, 0.2, 0.1], cells = [3, 2, 1] }

[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
fix = ["x", "y", "z"]
"#;

#[test]
fn self_weight_sums_to_rho_g_times_the_members_volume() {
    let world = build_world(SCENE, Path::new("heavy_box.toml")).unwrap();
    let body = &world.bodies[0];
    let volume: f64 = body
        .members
        .iter()
        .map(|m| 1e-4 * (body.nodes[m.nodes[1]] - body.nodes[m.nodes[0]]).norm())
        .sum();
    let total: nalgebra::Vector3<f64> = body.loads.iter().map(|l| l.force).sum();
    let expected = -7850.0 * 9.81 * volume;
    assert!(
        (total.y - expected).abs() < 1e-12 * expected.abs(),
        "{total:?} {expected}"
    );
    assert_eq!(total.x, 0.0);
    assert_eq!(total.z, 0.0);
    // Every node with a member carries weight; half at step 1 of 2, like any load.
    assert_eq!(body.loads.len(), body.nodes.len());
    assert_eq!(body.loads[0].schedule.factor(1, 2), 0.5);
}

#[test]
fn a_bad_density_or_gravity_is_named() {
    let bad = SCENE.replace("density = 7850.0", "density = -1.0");
    let e = build_world(&bad, Path::new("heavy_box.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("density = -1"), "{e}");
    let bad = SCENE.replace("gravity = [0.0, -9.81, 0.0]", "gravity = [0.0, -9.81]");
    let e = build_world(&bad, Path::new("heavy_box.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gravity"), "{e}");
    // Without gravity, density adds nothing: the scene's loads are its own.
    let none = SCENE.replace("gravity = [0.0, -9.81, 0.0]", "");
    assert!(build_world(&none, Path::new("heavy_box.toml"))
        .unwrap()
        .bodies[0]
        .loads
        .is_empty());
}

const PRESSED: &str = r#"
name = "pressed_box"
steps = 2

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "box"
box_lattice = { size = [0.3, 0.2, 0.1], cells = [3, 2, 2] }

[[bodies.supports]]
on_plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
fix = ["x", "y", "z"]

[[bodies.pressures]]
on_plane = { point = [0.0, 0.2, 0.0], normal = [0.0, 1.0, 0.0] }
pressure = 1e5
"#;

#[test]
fn a_pressure_on_one_face_of_a_box_sums_to_p_times_its_area() {
    let world = build_world(PRESSED, Path::new("pressed_box.toml")).unwrap();
    let total: nalgebra::Vector3<f64> = world.bodies[0].loads.iter().map(|l| l.force).sum();
    // 1e5 Pa on the 0.3 m × 0.1 m top face: 3000 N downward.
    assert!((total.y + 3000.0).abs() < 1e-9, "{total:?}");
    assert!(total.x.abs() < 1e-9 && total.z.abs() < 1e-9);
    let everywhere = PRESSED.replace(
        "on_plane = { point = [0.0, 0.2, 0.0], normal = [0.0, 1.0, 0.0] }\npressure",
        "inside = { min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0] }\npressure",
    );
    let world = build_world(&everywhere, Path::new("pressed_box.toml")).unwrap();
    let total: nalgebra::Vector3<f64> = world.bodies[0].loads.iter().map(|l| l.force).sum();
    assert!(total.norm() < 1e-9, "a closed surface: {total:?}");
    let none = PRESSED.replace("[0.0, 0.2, 0.0], normal", "[0.0, 0.1, 0.0], normal");
    let e = build_world(&none, Path::new("pressed_box.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("pressure") && e.contains("no patch"), "{e}");
}
