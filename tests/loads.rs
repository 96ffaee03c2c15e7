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

#[test]
fn gravity_follows_its_own_schedule_and_a_bad_one_is_named() {
    let scheduled = SCENE.replace(
        "gravity = [0.0, -9.81, 0.0]",
        "gravity = [0.0, -9.81, 0.0]\ngravity_schedule = [1.0, 0.5]",
    );
    let world = build_world(&scheduled, Path::new("heavy_box.toml")).unwrap();
    let body = &world.bodies[0];
    assert!(!body.loads.is_empty());
    for l in &body.loads {
        assert_eq!(l.schedule.factor(1, 2), 1.0);
        assert_eq!(l.schedule.factor(2, 2), 0.5);
    }
    let short = SCENE.replace(
        "gravity = [0.0, -9.81, 0.0]",
        "gravity = [0.0, -9.81, 0.0]\ngravity_schedule = [1.0]",
    );
    let e = build_world(&short, Path::new("heavy_box.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gravity_schedule has 1 factors"), "{e}");
    let alone = SCENE.replace(
        "gravity = [0.0, -9.81, 0.0]",
        "gravity_schedule = [1.0, 1.0]",
    );
    let e = build_world(&alone, Path::new("heavy_box.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("without gravity"), "{e}");
}

const PLATE: &str = r#"
name = "pressed_plate"
steps = 1

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "plate"
rectangle = { width = 0.4, height = 0.2, cells = [4, 2] }

[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [1.0, 0.0] }
fix = ["x", "y"]

[[bodies.pressures]]
on_line = { point = [0.0, 0.2], direction = [1.0, 0.0] }
pressure = 500.0
schedule = [0.5]
"#;

#[test]
fn a_2d_pressure_on_one_edge_sums_to_p_times_its_length_and_on_the_boundary_to_zero() {
    // 500 N/m on the top edge, 0.4 m long: 200 N downward (into the plate), on the edge's 5
    // nodes, with the pressure's own schedule.
    let world = build_world(PLATE, Path::new("pressed_plate.toml")).unwrap();
    let loads = &world.bodies[0].loads;
    assert_eq!(loads.len(), 5);
    let total: nalgebra::Vector3<f64> = loads.iter().map(|l| l.force).sum();
    assert!((total.y + 200.0).abs() < 1e-12, "{total:?}");
    assert!(total.x.abs() < 1e-12);
    assert_eq!(loads[0].schedule.factor(1, 1), 0.5);
    // The whole boundary (12 segments, the diagonals inside are not boundary): zero.
    let all = PLATE.replace(
        "on_line = { point = [0.0, 0.2], direction = [1.0, 0.0] }\npressure",
        "inside = { min = [-1.0, -1.0], max = [1.0, 1.0] }\npressure",
    );
    let world = build_world(&all, Path::new("pressed_plate.toml")).unwrap();
    let total: nalgebra::Vector3<f64> = world.bodies[0].loads.iter().map(|l| l.force).sum();
    assert!(total.norm() < 1e-12, "a closed boundary: {total:?}");
    // The corner node gets half of each of its two 0.1 m sides' 50 N, inward.
    let corner = world.bodies[0].loads.iter().find(|l| l.node == 0).unwrap();
    assert!(
        (corner.force - nalgebra::Vector3::new(25.0, 25.0, 0.0)).norm() < 1e-12,
        "{corner:?}"
    );
    // A line with no boundary segment on it: named.
    let none = PLATE.replace("[0.0, 0.2], direction", "[0.0, 0.1], direction");
    let e = build_world(&none, Path::new("pressed_plate.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no boundary segment"), "{e}");
}

#[test]
fn a_large_body_keeps_its_pressure_following_in_a_contact_scene_too() {
    let large = PLATE.replace(
        "rectangle = { width = 0.4, height = 0.2, cells = [4, 2] }",
        "rectangle = { width = 0.4, height = 0.2, cells = [4, 2] }\nkinematics = \"large\"",
    );
    let world = build_world(&large, Path::new("pressed_plate.toml")).unwrap();
    let body = &world.bodies[0];
    assert!(body.loads.is_empty());
    assert_eq!(body.pressures.len(), 1);
    assert_eq!(body.pressures[0].faces.len(), 4);
    let out = tempfile::tempdir().unwrap();
    // Solved: the step file's loads are the pressure's at half value on the deformed edge:
    // their y parts sum to p/2 times the edge's deformed length along x (to round-off).
    linkage::scene::run(&world, out.path(), &|| {}).unwrap();
    let step: linkage::scene::StepResult = serde_json::from_slice(
        &std::fs::read(out.path().join("pressed_plate/steps/0001.json")).unwrap(),
    )
    .unwrap();
    let b = &step.bodies[0];
    let total: f64 = b.loads.iter().map(|l| l.force[1]).sum();
    let xs: Vec<f64> = b.loads.iter().map(|l| b.positions[l.node - 1][0]).collect();
    let extent =
        xs.iter().cloned().fold(f64::MIN, f64::max) - xs.iter().cloned().fold(f64::MAX, f64::min);
    assert!((total + 250.0 * extent).abs() < 1e-9, "{total} {extent}");
    assert!((total + 100.0).abs() < 1e-4, "{total}");
    assert_eq!(step.bodies[0].loads.len(), 5);
    // With a floor that it does not reach, the contact solver takes the following pressure
    // too: the same loads on the same deformed edge (1e-10 of their size).
    let contact = format!(
        "{large}\n[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, -0.1]\nnormal = [0.0, 1.0]\n"
    );
    let world = build_world(&contact, Path::new("pressed_plate.toml")).unwrap();
    let with_floor = tempfile::tempdir().unwrap();
    linkage::scene::run(&world, with_floor.path(), &|| {}).unwrap();
    let in_contact_scene: linkage::scene::StepResult = serde_json::from_slice(
        &std::fs::read(with_floor.path().join("pressed_plate/steps/0001.json")).unwrap(),
    )
    .unwrap();
    let c = &in_contact_scene.bodies[0];
    assert!(c.contacts.is_empty());
    assert_eq!(c.loads.len(), b.loads.len());
    for (x, y) in c.loads.iter().zip(&b.loads) {
        assert_eq!(x.node, y.node);
        for k in 0..x.force.len() {
            assert!(
                (x.force[k] - y.force[k]).abs() <= 1e-10 * 100.0,
                "{x:?} {y:?}"
            );
        }
    }
}
