//! Members that break in a scene with contact: a truss pressed by a rigid half-space through a
//! prescribed travel breaks its member at the load computed by hand, and stays symmetric.

use linkage::scene::{load_scene, run};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs()
}

/// The three-bar truss upside down: node 1 at the origin hangs from nodes 2, 3, 4 at
/// (−1, 1), (0, 1), (1, 1) (held) on member 2 (vertical, length 1) and members 1 and 3 (at 45°,
/// length √2); E A = 2e7 N, compressive strength 250 MPa (f_c A = 25 kN). A half-space below
/// node 1, `gap` = 1 mm under it, rises by `travel` = 3 mm over 5 steps; the penalty is
/// k = 1e9 N/m. Node 1 rises by `u = k (λ T − gap) / (k + K)` with the truss's stiffness
/// `K = E A (1 + 1/√2)` (the vertical bar E A, each inclined one E A/√2 · cos² 45°); the
/// vertical bar carries `E A u` and breaks at `u* = f_c A / (E A)`, the travel factor
/// `λ* = (gap + u* (k + K)/k) / T` = 0.7642 (step 4). Then `K' = E A/√2`: at the last step
/// node 1 is at `k (T − gap)/(k + K')` and each inclined bar pushes `E A u / 2` (below
/// its strength: that needs u = 2.5 mm). Tolerance 1e-8 relative: the contact Newton's
/// residual is 1e-10 and the critical load is found to [`AT_STRENGTH`] = 1e-8 of the strength.
#[test]
fn a_truss_pressed_by_a_half_space_breaks_at_the_hand_load_and_stays_symmetric() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.nodes"), "0 0\n-1 1\n0 1\n1 1\n").unwrap();
    std::fs::write(d.join("t.links"), "1 2\n1 3\n1 4\n").unwrap();
    let scene = d.join("pressed.toml");
    std::fs::write(
        &scene,
        r#"name = "pressed"
steps = 5
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
compressive_strength = 250e6
failure = "break"
[[bodies]]
name = "truss"
nodes = "t.nodes"
links = "t.links"
material = "steel"
[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.001]
normal = [0.0, 1.0]
travel = [0.0, 0.003]
[contact]
penalty = 1e9
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let summary = run(&world, &d.join("out"), &|| {}).expect("a result");
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    let (ea, fca, k, gap, travel) = (2e7, 25e3, 1e9, 1e-3, 3e-3);
    let big_k = ea * (1.0 + 1.0 / 2f64.sqrt());
    let u_star = fca / ea;
    let lambda = (gap + u_star * (k + big_k) / k) / travel;
    assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
    let b = &summary.breaks[0];
    assert_eq!((b.step, b.member, b.tooth), (4, 2, None));
    assert!(
        close(b.load_factor, lambda, 1e-8),
        "{} against {lambda}",
        b.load_factor
    );
    let text = std::fs::read_to_string(d.join("out/pressed/steps/0005.json")).unwrap();
    let step: serde_json::Value = serde_json::from_str(&text).unwrap();
    let body = &step["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([2]));
    let u = k * (travel - gap) / (k + ea / 2f64.sqrt());
    let forces: Vec<f64> = body["axial_forces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(forces[1], 0.0);
    assert!(close(forces[0], -ea * u / 2.0, 1e-8), "{forces:?}");
    // Symmetry: both inclined bars alike, node 1 straight up.
    assert!(close(forces[2], forces[0], 1e-9), "{forces:?}");
    let ux = body["displacements"][0][0].as_f64().unwrap();
    assert!(ux.abs() <= 1e-9 * u, "{ux}");
    let step4: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(d.join("out/pressed/steps/0004.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(step4["bodies"][0]["breaks"][0]["member"], 2);
}

/// Breaking members with friction are not supported yet: refused with an error naming the body
/// and what to change, before anything is solved.
#[test]
fn breaking_members_with_friction_are_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.nodes"), "0 0\n-1 1\n0 1\n1 1\n").unwrap();
    std::fs::write(d.join("t.links"), "1 2\n1 3\n1 4\n").unwrap();
    let scene = d.join("rough.toml");
    std::fs::write(
        &scene,
        r#"name = "rough"
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
compressive_strength = 250e6
failure = "break"
[[bodies]]
name = "truss"
nodes = "t.nodes"
links = "t.links"
material = "steel"
[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.001]
normal = [0.0, 1.0]
travel = [0.0, 0.003]
[contact]
friction = 0.3
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let err = run(&world, &d.join("out"), &|| {}).unwrap_err();
    let text = format!("{err:#}");
    assert!(
        text.contains("body 'truss'") && text.contains("friction"),
        "{text}"
    );
    assert!(!d.join("out/rough").exists());
}

/// Softening under contact: a triangle, A = (−1, 0) pinned, B = (1, 0) on a roller, apex
/// C = (0, 1), pressed down at C by a half-space `gap` = 1 mm above it through `travel`; the
/// tie AB (length 2) softens in 3 teeth (f_t = 25 MPa, G_f = 20 kJ/m²), the diagonals do not
/// break; E A = 2e7 N, penalty k = 1e9 N/m. The truss is determinate: the tie carries P/2 and
/// C sinks `δ = P (√2/(E A) + 1/(4 kᵢ))` (unit load: each diagonal n = 1/√2 over √2 m, the tie
/// n = 1/2 at its tooth's stiffness kᵢ). Tooth i is reached at `Pᵢ = 2 σᵢ A`, so at the travel
/// factor `λᵢ = (gap + Pᵢ/k + Pᵢ (√2/(E A) + 1/(4 kᵢ))) / travel`, kᵢ and σᵢ from the tie's
/// teeth. Teeth 1 and 2 are passed there (1e-8), and the last breaks the tie there; then the
/// truss is a mechanism the press folds, and it carries nothing.
#[test]
fn a_softening_tie_under_contact_passes_its_teeth_at_the_hand_loads_then_breaks() {
    use linkage::linkage::fracture::saw_tooth;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (e, a, ft, gf, n, k, gap) = (200e9, 1e-4, 25e6, 20000.0, 3usize, 1e9, 1e-3);
    let ea = e * a;
    let teeth = saw_tooth(e, ft, 2.0, gf, n).unwrap();
    let lambda_of = |i: usize, travel: f64| {
        let ki = teeth[i].stiffness_factor * ea / 2.0;
        let p = 2.0 * teeth[i].tensile_strength * a;
        (gap + p / k + p * (2f64.sqrt() / ea + 1.0 / (4.0 * ki))) / travel
    };
    // Past the last tooth's load by a third.
    let travel = 1.37 * lambda_of(n - 1, 1.0);
    std::fs::write(d.join("t.nodes"), "-1 0\n1 0\n0 1\n").unwrap();
    std::fs::write(d.join("t.links"), "1 2\n1 3 strong\n2 3 strong\n").unwrap();
    let scene = d.join("tie.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "tie"
steps = 7
[[materials]]
name = "steel"
youngs_modulus = {e:e}
area = {a:e}
tensile_strength = {ft:e}
failure = "break"
softening = {{ fracture_energy = {gf}, teeth = {n} }}
[[materials]]
name = "strong"
youngs_modulus = {e:e}
area = {a:e}
[[bodies]]
name = "truss"
nodes = "t.nodes"
links = "t.links"
material = "steel"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2]
fix = ["y"]
[[obstacles]]
name = "press"
shape = "half_space"
point = [0.0, {}]
normal = [0.0, -1.0]
travel = [0.0, {}]
[contact]
penalty = {k:e}
"#,
            1.0 + gap,
            -travel
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let summary = run(&world, &d.join("out"), &|| {}).expect("a result");
    assert_eq!(summary.breaks.len(), n, "{:?}", summary.breaks);
    for (i, b) in summary.breaks.iter().enumerate() {
        assert_eq!((b.member, b.tooth), (1, (i + 1 < n).then_some(i + 1)));
        let expected = lambda_of(i, travel);
        assert!(
            close(b.load_factor, expected, 1e-8),
            "tooth {i}: {} against {expected}",
            b.load_factor
        );
    }
    // With the tie gone the truss is a mechanism that the press folds without resistance
    // (linear kinematics, frictionless contact): the last step carries nothing. (It is not
    // reported as a collapse: the coupled solve finds that force-free state.)
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    let last: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("out/tie/steps/0007.json")).unwrap())
            .unwrap();
    let body = &last["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([1]));
    let p0 = 2.0 * ft * a;
    for f in body["axial_forces"].as_array().unwrap() {
        assert!(f.as_f64().unwrap().abs() <= 1e-6 * p0, "{f}");
    }
}
