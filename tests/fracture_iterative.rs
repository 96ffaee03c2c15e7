//! A piece breaking off a body solved by conjugate gradients (`solver = "iterative"`) in a
//! contact scene: it is removed from the solve like one of a directly solved body, and the run
//! goes on.

use linkage::scene::{load_scene, run};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

/// The pendant of `tests/fracture_contact.rs` (a triangle of strong members, nodes 1 (0, 0) and
/// 2 (2, 0) pinned, apex 3 (1, 1) pressed by a half-space 1 mm above it coming down 3 mm over 4
/// steps; node 4 (1, −1) hung below nodes 1 and 2 by two breaking members at 45°, pulled down by
/// up to 50 kN), its body solved iteratively. Members 4 and 5 break together at load factor
/// √2 f_t A / P = 0.7071 (1e-9: the break is found on contact states settled to the contact Newton's 1e-10),
/// node 4 is reported fallen in step 3 and the run goes on; at step 4 the press pushes `F = k K
/// (T − gap)/(k + K)` with K = E A/√2 and the reactions answer it, to 1e-6 (conjugate
/// gradients stop at 1e-10 of the force scale).
#[test]
fn a_piece_breaking_off_an_iteratively_solved_body_falls_off_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("p.nodes"), "0 0\n2 0\n1 1\n1 -1\n").unwrap();
    std::fs::write(
        d.join("p.links"),
        "1 2 strong\n1 3 strong\n2 3 strong\n1 4\n2 4\n",
    )
    .unwrap();
    let scene = d.join("p.toml");
    std::fs::write(
        &scene,
        r#"name = "pendant"
steps = 4
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
tensile_strength = 250e6
failure = "break"
[[materials]]
name = "strong"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "truss"
nodes = "p.nodes"
links = "p.links"
material = "steel"
solver = "iterative"
[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [4]
force = [0.0, -50000.0]
[contact]
penalty = 1e9
[[obstacles]]
name = "press"
shape = "half_space"
point = [0.0, 1.001]
normal = [0.0, -1.0]
travel = [0.0, -0.003]
"#,
    )
    .unwrap();
    let out = d.join("out");
    let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
    assert_eq!(summary.bodies[0].solver, "iterative");
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    assert_eq!(summary.steps.len(), 5);
    assert!(summary
        .steps
        .iter()
        .skip(1)
        .all(|s| s.linear_iterations > 0));
    // The hangers tie (to the contact search's 1e-8): they break together, in one event.
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(3, 4), (3, 5)], "{:?}", summary.breaks);
    for b in &summary.breaks {
        assert!(
            close(b.load_factor, 25e3 * 2f64.sqrt() / 50e3, 1e-9),
            "{}",
            b.load_factor
        );
    }
    let step = |s: usize| -> serde_json::Value {
        let text = std::fs::read_to_string(out.join(format!("pendant/steps/{s:04}.json"))).unwrap();
        serde_json::from_str(&text).unwrap()
    };
    assert_eq!(step(3)["bodies"][0]["fallen"], serde_json::json!([4]));
    assert!(summary.steps[3]
        .warnings
        .iter()
        .any(|w| w.contains("fell off")));
    let step4 = step(4);
    let body = &step4["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([4, 5]));
    assert_eq!(body["axial_forces"][3].as_f64().unwrap(), 0.0);
    assert_eq!(body["axial_forces"][4].as_f64().unwrap(), 0.0);
    let (ea, k, gap, travel) = (2e7, 1e9, 1e-3, 3e-3);
    let big_k = ea / 2f64.sqrt();
    let press = k * big_k * (travel - gap) / (k + big_k);
    let contacts = body["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    assert_eq!(contacts[0]["node"], 3);
    let fy = contacts[0]["force"][1].as_f64().unwrap();
    assert!(close(-fy, press, 1e-6), "{fy} against {press}");
    let mut sum = [0.0f64; 2];
    for r in body["reactions"].as_array().unwrap() {
        for k in 0..2 {
            sum[k] += r["force"][k].as_f64().unwrap();
        }
    }
    assert!(sum[0].abs() <= 1e-6 * press, "{sum:?}");
    assert!(close(sum[1], press, 1e-6), "{sum:?} against {press}");
}
