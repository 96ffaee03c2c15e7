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

/// Breaking members with friction are followed (tests/fracture_large.rs), but not along an
/// arc-length path: refused with an error naming the body and what to change, before anything
/// is solved.
#[test]
fn breaking_members_on_an_arc_length_path_with_contact_are_refused_by_name() {
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
[bodies.path]
method = "arc_length"
arc_length = 0.001
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
        text.contains("body 'truss'") && text.contains("arc-length"),
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

/// Write and run a 2D contact scene of steel members (E A = 2e7 N, f_t A = 25 kN, breaking;
/// `strong`: the same, not breaking), penalty 1e9 N/m.
fn run_contact_scene(
    d: &std::path::Path,
    name: &str,
    nodes: &str,
    links: &str,
    rest: &str,
) -> linkage::scene::Summary {
    std::fs::write(d.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(d.join(format!("{name}.links")), links).unwrap();
    let scene = d.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
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
nodes = "{name}.nodes"
links = "{name}.links"
material = "steel"
[contact]
penalty = 1e9
{rest}"#
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    run(&world, &d.join("out"), &|| {}).expect("a result")
}

fn step_json(d: &std::path::Path, name: &str, step: usize) -> serde_json::Value {
    let text = std::fs::read_to_string(d.join(format!("out/{name}/steps/{step:04}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A piece cut loose that no contact holds falls off, in a contact scene: a triangle of strong
/// members (nodes 1 (0, 0) and 2 (2, 0) pinned, apex 3 (1, 1)) pressed at its apex by a
/// half-space 1 mm above it coming down 3 mm over 4 steps, and node 4 (1, −1) hung below
/// nodes 1 and 2 by two breaking members at 45° (members 4 and 5), pulled down by P up to
/// 50 kN. Each hanger carries P/√2 whatever the press does (their other ends are pinned): they
/// reach f_t A at P = √2 f_t A, load factor 0.7071 (to 1e-9), in step 3; both break in one
/// event (they tie) and node 4, left on no member, is reported fallen and removed, and the run
/// goes on (the press still drives the triangle). At step 4 the triangle alone carries the press: the apex's vertical stiffness is
/// K = E A/√2 (two bars at 45°), so the press pushes `F = k K (T − gap)/(k + K)` (1e-9), the
/// reactions answer it, and the fallen node's load is gone.
#[test]
fn a_piece_cut_loose_that_no_contact_holds_falls_off_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let summary = run_contact_scene(
        d,
        "pendant",
        "0 0\n2 0\n1 1\n1 -1\n",
        "1 2 strong\n1 3 strong\n2 3 strong\n1 4\n2 4\n",
        r#"[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [4]
force = [0.0, -50000.0]
[[obstacles]]
name = "press"
shape = "half_space"
point = [0.0, 1.001]
normal = [0.0, -1.0]
travel = [0.0, -0.003]
"#,
    );
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    assert_eq!(summary.steps.len(), 5);
    // The hangers are symmetric: they break together, in one event, as without contact.
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(3, 4), (3, 5)], "{:?}", summary.breaks);
    let expected = 25e3 * 2f64.sqrt() / 50e3;
    for b in &summary.breaks {
        assert!(close(b.load_factor, expected, 1e-9), "{}", b.load_factor);
    }
    assert_eq!(
        step_json(d, "pendant", 3)["bodies"][0]["fallen"],
        serde_json::json!([4])
    );
    assert!(summary.steps[3]
        .warnings
        .iter()
        .any(|w| w.contains("fell off")));
    let step4 = step_json(d, "pendant", 4);
    let body = &step4["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([4, 5]));
    assert!(body.get("fallen").is_none());
    assert_eq!(body["axial_forces"][3].as_f64().unwrap(), 0.0);
    assert_eq!(body["axial_forces"][4].as_f64().unwrap(), 0.0);
    let (ea, k, gap, travel) = (2e7, 1e9, 1e-3, 3e-3);
    let big_k = ea / 2f64.sqrt();
    let press = k * big_k * (travel - gap) / (k + big_k);
    let contacts = body["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    assert_eq!(contacts[0]["node"], 3);
    let fy = contacts[0]["force"][1].as_f64().unwrap();
    assert!(close(-fy, press, 1e-9), "{fy} against {press}");
    let mut sum = [0.0f64; 2];
    for r in body["reactions"].as_array().unwrap() {
        for k in 0..2 {
            sum[k] += r["force"][k].as_f64().unwrap();
        }
    }
    let loads: f64 = body["loads"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["force"][1].as_f64().unwrap().abs())
        .sum();
    assert_eq!(loads, 0.0, "the fallen node's load is dropped");
    assert!(sum[0].abs() <= 1e-9 * press, "{sum:?}");
    assert!(close(sum[1], press, 1e-9), "{sum:?} against {press}");
}

/// A piece cut loose that rests on an obstacle is held: node 3 (1, −1) hung below the pinned
/// nodes 1 (0, 0) and 2 (2, 0) by two breaking members (tension only), 0.1 mm above a floor,
/// pulled by (H, −V) = (40, −20) kN times the load factor over 4 steps. It reaches the floor
/// early; member 1 (stretched by H) breaks in step 4. Node 3 is then left on member 2 and its
/// floor contact: a determinate node, held, not fallen. At the last step member 2 pushes
/// `−√2 H` and the floor `V + H` (1e-9).
#[test]
fn a_piece_cut_loose_that_rests_on_an_obstacle_is_held() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let summary = run_contact_scene(
        d,
        "resting",
        "0 0\n2 0\n1 -1\n",
        "1 3\n2 3\n",
        r#"[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [3]
force = [40000.0, -20000.0]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -1.0001]
normal = [0.0, 1.0]
"#,
    );
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
    assert_eq!(summary.breaks[0].member, 1);
    let last = step_json(d, "resting", 4);
    let body = &last["bodies"][0];
    assert!(body.get("fallen").is_none(), "{body}");
    assert_eq!(body["broken"], serde_json::json!([1]));
    let n2 = body["axial_forces"][1].as_f64().unwrap();
    assert!(close(n2, -2f64.sqrt() * 40e3, 1e-9), "{n2}");
    let contacts = body["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    let r = contacts[0]["normal_force"].as_f64().unwrap();
    assert!(close(r, 60e3, 1e-9), "{r}");
}

/// Write `name.toml` (2D, steel E A = 2e7 N breaking at `strength` = 250 MPa, `strong`: the
/// same, not breaking; `soft`: E A = 1e6 N, not breaking) with `nodes`, `links` and `rest`
/// into `d`, and run it into `d/out`.
fn run_truss(
    d: &std::path::Path,
    name: &str,
    steps: usize,
    strength: &str,
    (nodes, links): (&str, &str),
    rest: &str,
) -> linkage::scene::Summary {
    std::fs::write(d.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(d.join(format!("{name}.links")), links).unwrap();
    let scene = d.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
steps = {steps}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
{strength} = 250e6
failure = "break"
[[materials]]
name = "strong"
youngs_modulus = 200e9
area = 1e-4
[[materials]]
name = "soft"
youngs_modulus = 200e9
area = 5e-6
[[bodies]]
name = "truss"
nodes = "{name}.nodes"
links = "{name}.links"
material = "steel"
{rest}"#
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    run(&world, &d.join("out"), &|| {}).expect("a result")
}

/// The indeterminate three-bar truss of `tests/fracture.rs` (node 1 at the origin held by a
/// vertical bar, member 2, and two bars at 45°, members 1 and 3, from (−1, 1), (0, 1), (1, 1);
/// P down at node 1 over 2 steps to 100 kN; f_t A = 25 kN) in a scene with contact: a
/// `[contact]` table and a floor 5 m below that it never reaches. Member 2 breaks at
/// P₁ = f_t A (1 + 1/√2) = 42.68 kN; the two left carry P/√2 each and are beyond their strength
/// from P₂ = √2 f_t A = 35.36 kN: the snap-back. Members 1 and 3 tie there and break in one
/// event, at the LOWER load factor, and the loaded joint is held by nothing: the structure
/// collapsed (case 6 of issue 32), as without contact. The load factors equal the closed form
/// and the run without contact to 1e-9 (no contact: every settle is linear and the secant lands
/// on the strength exactly, up to rounding).
#[test]
fn the_three_bar_truss_snaps_back_in_a_scene_with_contact_as_without() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let truss = ("0 0\n-1 1\n0 1\n1 1\n", "1 2\n1 3\n1 4\n");
    let loads = r#"[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [1]
force = [0.0, -100000.0]
"#;
    let contact = format!(
        r#"{loads}
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -5.0]
normal = [0.0, 1.0]
[contact]
penalty = 1e9
"#
    );
    let with = run_truss(d, "three_bar", 2, "tensile_strength", truss, &contact);
    let without = run_truss(d, "three_bar_alone", 2, "tensile_strength", truss, loads);
    let (fta, p) = (25e3, 100e3);
    let p1 = fta * (1.0 + 1.0 / 2f64.sqrt());
    let p2 = fta * 2f64.sqrt();
    for summary in [&with, &without] {
        assert!(summary.failure.is_none());
        let collapse = summary.collapse.as_ref().expect("a collapse");
        assert_eq!(collapse.step, 1);
        assert!(close(collapse.load_factor, p2 / p, 1e-9), "{collapse:?}");
        let breaks: Vec<(usize, usize)> =
            summary.breaks.iter().map(|b| (b.step, b.member)).collect();
        assert_eq!(breaks, vec![(1, 2), (1, 1), (1, 3)], "{:?}", summary.breaks);
        assert!(close(summary.breaks[0].load_factor, p1 / p, 1e-9));
        assert!(close(summary.breaks[1].load_factor, p2 / p, 1e-9));
        assert!(close(summary.breaks[2].load_factor, p2 / p, 1e-9));
        assert!(summary.breaks[1].load_factor < summary.breaks[0].load_factor);
    }
    // Step 0, then the state it collapsed in, flagged, with contact as without: at the load the
    // step reached (P₁, the first break's), the truss without its vertical bar (the two side
    // bars carry P₁/√2 each: node 1 sinks √2 P₁/(E A) = 3.0178 mm), every member
    // shown broken.
    let u1 = p1 * 2f64.sqrt() / 2e7;
    for (summary, name) in [(&with, "three_bar"), (&without, "three_bar_alone")] {
        assert_eq!(summary.steps.len(), 2, "{:?}", summary.steps);
        assert!(summary.steps[1].collapse && !summary.steps[0].collapse);
        // Its out-of-balance (the broken members' load is on) is not a solve that stopped short.
        assert!(
            !summary.steps[1]
                .warnings
                .iter()
                .any(|w| w.contains("out-of-balance")),
            "{name}: {:?}",
            summary.steps[1].warnings
        );
        assert_eq!(summary.steps[1].step, 1);
        assert_eq!(summary.steps[1].broken, Some(3));
        let last = step_json(d, name, 1);
        assert_eq!(
            last["load_factor"].as_f64(),
            Some(summary.steps[1].load_factor)
        );
        let body = &last["bodies"][0];
        assert_eq!(body["collapse"].as_bool(), Some(true), "{body}");
        let mut broken: Vec<u64> = body["broken"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m.as_u64().unwrap())
            .collect();
        broken.sort_unstable();
        assert_eq!(broken, vec![1, 2, 3]);
        let forces: Vec<f64> = body["axial_forces"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f.as_f64().unwrap())
            .collect();
        assert_eq!(forces, vec![0.0; 3]);
        let uy = body["displacements"][0][1].as_f64().unwrap();
        assert!(close(uy, -u1, 1e-9), "{name}: {uy} against {}", -u1);
        assert!(step_json(d, name, 0)["bodies"][0].get("collapse").is_none());
    }
    assert_eq!(with.steps[1].load_factor, without.steps[1].load_factor);
    assert_eq!(
        with.collapse.as_ref().map(|c| (c.step, c.member)),
        without.collapse.as_ref().map(|c| (c.step, c.member))
    );
    for (a, b) in with.breaks.iter().zip(&without.breaks) {
        assert!(close(a.load_factor, b.load_factor, 1e-9), "{a:?} {b:?}");
    }
}

/// A snap-back under obstacle travel, with contact carrying the load: the three-bar truss
/// (node 1 at the origin, members 1 and 2 breaking in compression at f_c A = 25 kN, member 3
/// at 45° to (1, 1) strong; node 1 held in x) pushed up through a soft member (member 4 to
/// node 5 at (0, −0.5), held in x: k_s = E A/L = 2e6 N/m) by a half-space `gap` = 1 mm below
/// node 5 rising T = 30 mm over 4 steps; penalty k = 1e9 N/m. The press force is
/// `F = (λ T − gap)/(1/k + 1/k_s + 1/K)` and node 1 rises `u = F/K`, K the truss's stiffness
/// at node 1: E A (1 + 1/√2) intact, then E A/√2 without the vertical bar. The vertical bar
/// carries E A u and breaks at u* = f_c A/(E A) = 1.25 mm, travel factor λ* = 0.7877 (step
/// 4); then each inclined bar carries E A u/2, and at λ* u jumps past 2 u*: member 1 is
/// beyond its strength, which it reaches at u = 2 u* and λ** = 0.7073: a snap-back below
/// even the step's start (0.75), recorded there. Then node 1 rests on member 3 alone
/// (K'' = E A/(2√2)), which carries −√2 F at the last step. Tolerance 1e-9: the contact set
/// does not change between the settles that find the breaks, so the secant is exact.
#[test]
fn a_snap_back_under_obstacle_travel_with_contact_carrying_the_load() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let summary = run_truss(
        d,
        "pushed",
        4,
        "compressive_strength",
        (
            "0 0\n-1 1\n0 1\n1 1\n0 -0.5\n",
            "1 2\n1 3\n1 4 strong\n1 5 soft\n",
        ),
        r#"[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [1, 5]
fix = ["x"]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.501]
normal = [0.0, 1.0]
travel = [0.0, 0.03]
[contact]
penalty = 1e9
"#,
    );
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    let (ea, fca, k, ks, gap, travel) = (2e7, 25e3, 1e9, 2e6, 1e-3, 0.03);
    let r2 = 2f64.sqrt();
    let lambda =
        |big_k: f64, u: f64| (gap + big_k * u * (1.0 / k + 1.0 / ks + 1.0 / big_k)) / travel;
    let first = lambda(ea * (1.0 + 1.0 / r2), fca / ea);
    let second = lambda(ea / r2, 2.0 * fca / ea);
    assert!(
        second < 0.75 && 0.75 < first && first < 1.0,
        "{first} {second}"
    );
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(4, 2), (4, 1)], "{:?}", summary.breaks);
    let (b1, b2) = (summary.breaks[0].load_factor, summary.breaks[1].load_factor);
    assert!(close(b1, first, 1e-9), "{b1} against {first}");
    assert!(close(b2, second, 1e-9), "{b2} against {second}");
    let body = &step_json(d, "pushed", 4)["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([2, 1]));
    let k3 = ea / (2.0 * r2);
    let press = (travel - gap) / (1.0 / k + 1.0 / ks + 1.0 / k3);
    let forces: Vec<f64> = body["axial_forces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!((forces[0], forces[1]), (0.0, 0.0));
    assert!(close(forces[2], -r2 * press, 1e-9), "{forces:?}");
    assert!(close(forces[3], -press, 1e-9), "{forces:?}");
}
