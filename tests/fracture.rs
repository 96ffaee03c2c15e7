//! Members that break: closed forms for the load at each break (sequentially linear
//! analysis, event by event), collapse as a result, pieces that fall off. Tolerances are
//! stated where they are used.

use linkage::linkage::fracture::BreakingEquilibrium;
use linkage::linkage::{Body, Dimension, Failure, Material, Member, Schedule, Support};
use linkage::scene::{load_scene, run, Summary};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// E A of every member, N, and the tensile strength times the area, N.
const EA: f64 = 200e9 * 1e-4;
const FT_A: f64 = 250e6 * 1e-4;

/// Write `name.toml`, `name.nodes` and `name.links` into `dir` (materials `steel`, breaking
/// at 250 MPa in tension, and `strong`, unbreakable; E = 200 GPa, A = 1 cm²) and run the
/// scene into `dir/out`.
fn run_scene(
    dir: &Path,
    name: &str,
    steps: usize,
    nodes: &str,
    links: &str,
    rest: &str,
) -> Summary {
    std::fs::write(dir.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(dir.join(format!("{name}.links")), links).unwrap();
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
steps = {steps}
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
{rest}"#
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    run(&world, &dir.join("out"), &|| {}).expect("the run ends with a result")
}

fn step_file(dir: &Path, name: &str, step: usize) -> Option<serde_json::Value> {
    let text =
        std::fs::read_to_string(dir.join(format!("out/{name}/steps/{step:04}.json"))).ok()?;
    Some(serde_json::from_str(&text).unwrap())
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs()
}

/// A statically determinate triangle: node 1 pinned, node 2 on a roller, P down at the apex
/// (node 3) over 3 steps to 80 kN. The diagonals carry P/√2 in compression, the bottom chord
/// P/2 in tension (no compressive strength given): it breaks at P/2 = f_t A, P = 50 kN, load
/// factor 50/80 = 0.625, in step 2; then the roller slides: the structure collapses. Steps 0
/// and 1 are written; the run is a result, not an error.
#[test]
fn a_determinate_truss_breaks_at_the_hand_load_then_collapses() {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_scene(
        dir.path(),
        "determinate",
        3,
        "0 0\n2 0\n1 1\n",
        "1 2\n1 3\n2 3\n",
        r#"[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2]
fix = ["y"]
[[bodies.loads]]
nodes = [3]
force = [0.0, -80000.0]
"#,
    );
    let expected = 2.0 * FT_A / 80000.0;
    assert!((expected - 0.625).abs() < 1e-15);
    let collapse = summary.collapse.as_ref().expect("a collapse");
    assert_eq!((collapse.step, collapse.member), (2, 1));
    assert_eq!(collapse.body, "truss");
    // To 1e-9 relative: the load factor of a break is exact up to rounding.
    assert!(close(collapse.load_factor, expected, 1e-9), "{collapse:?}");
    assert_eq!(summary.breaks.len(), 1);
    assert_eq!((summary.breaks[0].step, summary.breaks[0].member), (2, 1));
    assert!(close(summary.breaks[0].load_factor, expected, 1e-9));
    // Steps 0 and 1 solved, and the collapse state written as step 2 (flagged).
    assert_eq!(
        summary.steps.len(),
        3,
        "steps 0 and 1 solved, step 2 the collapse"
    );
    assert!(summary.steps[2].collapse && !summary.steps[1].collapse);
    assert!(summary.failure.is_none());
    let step1 = step_file(dir.path(), "determinate", 1).expect("step 1 written");
    let body = &step1["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([]));
    assert_eq!(body["breaks"], serde_json::json!([]));
    // Below the strength at step 1 (P = 26.7 kN): the chord carries P/2.
    assert!(close(
        body["axial_forces"][0].as_f64().unwrap(),
        80000.0 / 3.0 / 2.0,
        1e-9
    ));
    // The collapse state is written as step 2: the chord broken, flagged.
    let step2 = step_file(dir.path(), "determinate", 2).expect("the collapse state written");
    assert_eq!(step2["bodies"][0]["broken"], serde_json::json!([1]));
    assert_eq!(step2["bodies"][0]["collapse"], serde_json::json!(true));
    let text = std::fs::read_to_string(dir.path().join("out/determinate/summary.json")).unwrap();
    assert!(text.contains("\"collapse\""));
}

/// Case 6 of issue 32, **a collapse taken for a fallen piece**. The symmetric three-bar truss:
/// node 1 held by a vertical bar (member 2, length 1) and two bars at 45° (members 1 and 3,
/// length √2), all pinned at the top, P = 3 f_t A down at node 1 over 40 steps. By
/// compatibility the vertical bar carries P/(1 + 1/√2), each inclined one half as much: the
/// vertical bar breaks first, at P₁ = f_t A (1 + 1/√2), load factor 0.5690, in step 23. The
/// two left must carry P alone, P/(2 cos 45°) each, beyond their strength from
/// P₂ = 2 cos 45° f_t A, load factor 2 cos 45°/3 = 0.4714 (a snap-back, below P₁): they are
/// symmetric and break together, in one event (their load factors tie to 1e-9). The joint,
/// loaded, is then held by nothing: the structure collapsed (before the fix member 1 broke
/// alone, the joint hanging by member 3 was removed as a piece that fell off with its load, and
/// 17 more steps reported max |u| = 0).
#[test]
fn a_collapse_taken_for_a_fallen_piece() {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_scene(
        dir.path(),
        "three_bar",
        40,
        "0 0\n-1 1\n0 1\n1 1\n",
        "1 2\n1 3\n1 4\n",
        &format!(
            r#"[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [1]
force = [0.0, {}]
"#,
            -3.0 * FT_A
        ),
    );
    let p1 = (1.0 + 1.0 / 2f64.sqrt()) / 3.0;
    let p2 = 2.0 * std::f64::consts::FRAC_PI_4.cos() / 3.0;
    let collapse = summary
        .collapse
        .as_ref()
        .expect("the run records a collapse");
    assert_eq!(collapse.step, 23);
    assert_eq!(collapse.body, "truss");
    assert!(summary.failure.is_none());
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(23, 2), (23, 1), (23, 3)]);
    // To 1e-9 relative: the load factors of the breaks.
    assert!(close(summary.breaks[0].load_factor, p1, 1e-9), "{breaks:?}");
    assert!(close(summary.breaks[1].load_factor, p2, 1e-9));
    assert!(close(summary.breaks[2].load_factor, p2, 1e-9));
    // The side bars tie to 1e-9: one event.
    assert!(
        (summary.breaks[1].load_factor - summary.breaks[2].load_factor).abs() <= 1e-9 * p2,
        "{:?}",
        summary.breaks
    );
    assert!(close(collapse.load_factor, p2, 1e-9), "{collapse:?}");
    // Steps 0 to 22 solved, the collapse state as step 23 (all three bars broken), nothing
    // after it; nothing fell off before it.
    assert_eq!(summary.steps.len(), 24);
    assert!(summary.steps[23].collapse && summary.steps[23].broken == Some(3));
    assert!(summary
        .steps
        .iter()
        .all(|s| s.warnings.iter().all(|w| !w.contains("fell off"))));
    let step22 = step_file(dir.path(), "three_bar", 22).unwrap();
    let body = &step22["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([]));
    // Below the strength at step 22 (P = 3 f_t A 22/40): the vertical bar carries P/(1 + 1/√2).
    let p = 3.0 * FT_A * 22.0 / 40.0;
    assert!(close(
        body["axial_forces"][1].as_f64().unwrap(),
        p / (1.0 + 1.0 / 2f64.sqrt()),
        1e-9
    ));
    // The collapse state is step 23, flagged, with all three bars broken; nothing after it.
    let step23 = step_file(dir.path(), "three_bar", 23).expect("the collapse state written");
    assert_eq!(step23["bodies"][0]["collapse"], serde_json::json!(true));
    assert_eq!(
        step23["bodies"][0]["broken"].as_array().map(Vec::len),
        Some(3)
    );
    assert!(step_file(dir.path(), "three_bar", 24).is_none());
}

/// The same truss made asymmetric (member 1 weaker by 1 %, so it breaks alone): after the
/// vertical bar, member 1 breaks, and the loaded joint hangs by member 3 alone, a mechanism
/// under load: a collapse at member 1's break, not a piece that fell off.
#[test]
fn a_loaded_node_hanging_by_a_mechanism_is_a_collapse() {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_scene(
        dir.path(),
        "hanging",
        40,
        "0 0\n-1 1\n0 1\n1 1\n",
        "1 2 weak\n1 3\n1 4\n",
        &format!(
            r#"[[bodies.supports]]
nodes = [2, 3, 4]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [1]
force = [0.0, {}]
[[materials]]
name = "weak"
youngs_modulus = 200e9
area = 1e-4
tensile_strength = 247.5e6
failure = "break"
"#,
            -3.0 * FT_A
        ),
    );
    let collapse = summary.collapse.as_ref().expect("a collapse");
    assert_eq!((collapse.step, collapse.member), (23, 1));
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(23, 2), (23, 1)]);
    // Member 1 alone carries P/(2 cos 45°) at its break: 0.99 × 2 cos 45° f_t A.
    let p = 0.99 * 2.0 * std::f64::consts::FRAC_PI_4.cos() / 3.0;
    assert!(close(collapse.load_factor, p, 1e-9), "{collapse:?}");
    // Steps 0 to 22, and the collapse state as step 23.
    assert_eq!(summary.steps.len(), 24);
    assert!(summary.steps[23].collapse);
}

/// A piece breaking off a structure that goes on carrying load: a stable triangle of strong
/// members (nodes 1, 2 pinned, apex 3 loaded 10 kN sideways), and node 4 hung below nodes 1
/// and 2 by two breaking members at 45° (members 4 and 5), pulled down by P up to 50 kN over
/// 4 steps. Each hanger carries P/√2: they reach f_t A at P = √2 f_t A = 35.36 kN, load factor
/// 0.7071, in step 3; member 4 breaks (tie to the lower number), node 4 comes loose and
/// falls off; step 4 is solved with the triangle alone, which carries its own load as before.
#[test]
fn a_piece_that_breaks_off_is_reported_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let summary = run_scene(
        dir.path(),
        "pendant",
        4,
        "0 0\n2 0\n1 1\n1 -1\n",
        "1 2 strong\n1 3 strong\n2 3 strong\n1 4\n2 4\n",
        r#"[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [3]
force = [10000.0, 0.0]
[[bodies.loads]]
nodes = [4]
force = [0.0, -50000.0]
"#,
    );
    assert!(summary.collapse.is_none());
    assert_eq!(summary.steps.len(), 5);
    // The hangers are symmetric: they break together, in one event.
    let breaks: Vec<(usize, usize)> = summary.breaks.iter().map(|b| (b.step, b.member)).collect();
    assert_eq!(breaks, vec![(3, 4), (3, 5)]);
    for b in &summary.breaks {
        assert!(close(b.load_factor, FT_A * 2f64.sqrt() / 50000.0, 1e-9));
    }
    let step3 = step_file(dir.path(), "pendant", 3).unwrap();
    assert_eq!(step3["bodies"][0]["fallen"], serde_json::json!([4]));
    let step4 = step_file(dir.path(), "pendant", 4).unwrap();
    let body = &step4["bodies"][0];
    assert_eq!(body["broken"], serde_json::json!([4, 5]));
    assert!(body.get("fallen").is_none());
    // The triangle alone: 10 kN sideways at the apex; the reactions answer it exactly.
    let mut sum = [0.0f64; 2];
    for r in body["reactions"].as_array().unwrap() {
        for k in 0..2 {
            sum[k] += r["force"][k].as_f64().unwrap();
        }
    }
    assert!(
        (sum[0] + 10000.0).abs() < 1e-6 && sum[1].abs() < 1e-6,
        "{sum:?}"
    );
    assert_eq!(body["axial_forces"][3].as_f64().unwrap(), 0.0);
    assert_eq!(body["axial_forces"][4].as_f64().unwrap(), 0.0);
}

/// A bundle of ten parallel members (length 1 m, E A = 2e7 N) of graded tensile strengths
/// f_i = 105 + 10 i MPa (i = 0..9), pulled by a prescribed displacement growing to 1 mm over
/// 20 steps: the stress at step s is 10 s MPa, so member i breaks halfway through step 11 + i
/// (fraction 0.5 exactly) and the total force at step s is (members with f_i ≥ 10 s MPa)
/// × E A × δ_s, δ_s = s × 0.05 mm.
#[test]
fn a_graded_bundle_follows_the_closed_form_force_curve() {
    let mut body = Body::new("bundle", Dimension::Two);
    let count = 10;
    for i in 0..count {
        body.nodes.push(Vector3::new(i as f64, 0.0, 0.0));
        body.nodes.push(Vector3::new(i as f64, 1.0, 0.0));
        let mut m = Material::new(&format!("m{i}"), 200e9, 1e-4);
        m.tensile_strength = Some((105.0 + 10.0 * i as f64) * 1e6);
        m.failure = Failure::Break;
        body.materials.push(m);
        body.members.push(Member {
            nodes: [2 * i, 2 * i + 1],
            material: i,
        });
        body.supports
            .push(Support::fixed(2 * i, [true, true, false]));
        body.supports.push(Support {
            node: 2 * i + 1,
            fixed: [true, true, false],
            displacement: Vector3::new(0.0, 1e-3, 0.0),
            schedule: Schedule::Linear,
        });
    }
    let steps = 20;
    let mut eq = BreakingEquilibrium::new(&body).unwrap();
    for s in 1..=steps {
        let state = eq.solve_step(&body, s, steps).unwrap();
        let delta = s as f64 * 0.05e-3;
        let intact = (0..count)
            .filter(|&i| 105.0 + 10.0 * i as f64 >= 10.0 * s as f64)
            .count();
        let total: f64 = state
            .reactions
            .iter()
            .filter(|(n, _)| n % 2 == 1)
            .map(|(_, r)| r.y)
            .sum();
        // To 1e-9 of the largest force of the bundle.
        let expected = intact as f64 * EA * delta;
        assert!(
            (total - expected).abs() <= 1e-9 * count as f64 * EA * 1e-3,
            "step {s}: {total} N against {expected} N"
        );
        let fracture = state.fracture.unwrap();
        if (11..11 + count).contains(&s) {
            assert_eq!(fracture.breaks.len(), 1, "step {s}");
            assert_eq!(fracture.breaks[0].member, s - 11);
            assert!((fracture.breaks[0].fraction - 0.5).abs() < 1e-9);
        } else {
            assert!(fracture.breaks.is_empty(), "step {s}");
        }
    }
}

/// Breaking members under large displacements are followed (tests/fracture_large.rs), but
/// not along an arc-length path (its search moves the load, which the arc length sets): such
/// a body is refused, naming it and the path.
#[test]
fn an_arc_length_body_with_breaking_members_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.nodes"), "0 0\n2 0\n1 1\n").unwrap();
    std::fs::write(dir.path().join("t.links"), "1 2\n1 3\n2 3\n").unwrap();
    let scene = dir.path().join("t.toml");
    std::fs::write(
        &scene,
        r#"name = "t"
[[materials]]
name = "glass"
youngs_modulus = 70e9
area = 1e-4
strength = 50e6
failure = "break"
[[bodies]]
name = "pane"
nodes = "t.nodes"
links = "t.links"
material = "glass"
kinematics = "large"
[bodies.path]
method = "arc_length"
arc_length = 0.01
[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [3]
force = [0.0, -1.0]
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let err = run(&world, &dir.path().join("out"), &|| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("'pane'") && err.contains("arc-length"),
        "{err}"
    );
    // failure = "break" without a strength is an error naming the material.
    let text = std::fs::read_to_string(&scene)
        .unwrap()
        .replace("strength = 50e6\n", "");
    std::fs::write(&scene, text).unwrap();
    let err = load_scene(&scene).unwrap_err().to_string();
    assert!(err.contains("glass") && err.contains("strength"), "{err}");
}

/// Scattered strengths (Weibull modulus 6, seed 7) on a 2D lattice pulled by a prescribed
/// displacement: one thread and two give byte-identical step files and the same breaks.
#[test]
fn the_same_seed_gives_byte_identical_results_on_one_and_two_threads() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scatter.toml");
    std::fs::write(
        &scene,
        r#"name = "scatter"
steps = 4
[[materials]]
name = "rock"
youngs_modulus = 30e9
area = 1e-4
tensile_strength = 3e6
failure = "break"
scatter = { weibull_modulus = 6.0, seed = 7 }
[[bodies]]
name = "slab"
rectangle = { width = 2.0, height = 1.0, cells = [16, 8] }
material = "rock"
[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [0.0, 1.0] }
fix = ["x", "y"]
[[bodies.supports]]
on_line = { point = [2.0, 0.0], direction = [0.0, 1.0] }
fix = ["x", "y"]
displacement = [0.0002, 0.0]
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let run_on = |threads: usize| {
        let out = dir.path().join(format!("out{threads}"));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let summary = pool.install(|| run(&world, &out, &|| {}).unwrap());
        let mut files = Vec::new();
        for step in 0..summary.steps.len() {
            files.push(std::fs::read(out.join(format!("scatter/steps/{step:04}.json"))).unwrap());
        }
        (summary.breaks, summary.collapse, files)
    };
    let one = run_on(1);
    let two = run_on(2);
    assert!(!one.0.is_empty(), "members break");
    assert_eq!(one.0, two.0);
    assert_eq!(one.1, two.1);
    assert_eq!(one.2, two.2);
}

#[test]
fn a_collapse_is_a_result_in_the_batch_table_with_the_members_broken() {
    let out = tempfile::tempdir().unwrap();
    let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_fracture.toml");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(out.path())
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let table = std::fs::read_to_string(out.path().join("batch.csv")).unwrap();
    let mut lines = table.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let row = lines.next().unwrap();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap();
    // The status holds commas inside quotes: the broken column is read from the end.
    assert!(row.contains("\"collapsed: body 'solid' at step 3"), "{row}");
    let summary: serde_json::Value = serde_json::from_slice(
        &std::fs::read(out.path().join("paper_fracture/summary.json")).unwrap(),
    )
    .unwrap();
    let broken_last = summary["steps"].as_array().unwrap().last().unwrap()["broken"].clone();
    assert!(column("broken") > column("status"));
    assert!(
        row.contains(&format!(",{broken_last},")),
        "{row} should hold broken = {broken_last}"
    );
}

/// Softening material of the tests below: E = 30 GPa, A = 1 cm², f_t = 3 MPa, G_f = 100 J/m².
const SOFT_E: f64 = 30e9;
const SOFT_A: f64 = 1e-4;
const SOFT_FT: f64 = 3e6;
const SOFT_GF: f64 = 100.0;

/// Run a 2D bar along x, its nodes at `xs` (m), its first member of the softening material
/// with `teeth` teeth (none: brittle), the others of `stiff` (E = 30 GPa, A = 1 cm², not
/// breaking), node 1 held, the last node pulled `travel` m along x over `steps` steps, every
/// node held in y.
fn run_softening_bar(
    dir: &Path,
    name: &str,
    xs: &[f64],
    teeth: Option<usize>,
    travel: f64,
    steps: usize,
) -> Summary {
    let nodes: String = xs.iter().map(|x| format!("{x} 0\n")).collect();
    let links: String = (1..xs.len())
        .map(|i| {
            if i == 1 {
                "1 2\n".to_string()
            } else {
                format!("{i} {} stiff\n", i + 1)
            }
        })
        .collect();
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(dir.join(format!("{name}.links")), links).unwrap();
    let softening = teeth.map_or(String::new(), |n| {
        format!("softening = {{ fracture_energy = {SOFT_GF}, teeth = {n} }}")
    });
    let last = xs.len();
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
steps = {steps}
[[materials]]
name = "soft"
youngs_modulus = {SOFT_E:e}
area = {SOFT_A:e}
tensile_strength = {SOFT_FT:e}
failure = "break"
{softening}
[[materials]]
name = "stiff"
youngs_modulus = {SOFT_E:e}
area = {SOFT_A:e}
[[bodies]]
name = "bar"
nodes = "{name}.nodes"
links = "{name}.links"
material = "soft"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
{}[[bodies.supports]]
nodes = [{last}]
fix = ["x", "y"]
displacement = [{travel:e}, 0.0]
"#,
            if last > 2 {
                let middle: Vec<String> = (2..last).map(|n| n.to_string()).collect();
                format!(
                    "[[bodies.supports]]\nnodes = [{}]\nfix = [\"y\"]\n",
                    middle.join(", ")
                )
            } else {
                String::new()
            }
        ),
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    run(&world, &dir.join("out"), &|| {}).expect("the run ends with a result")
}

/// One softening member of length L = 0.1 m pulled by its end through 5 teeth. Tooth i has
/// the strength σᵢ = f_t (1 − i/5) by definition; the member reaches it at the elongation δᵢ
/// recorded as the event's load factor times the travel. Since the elongation is prescribed,
/// the force is `kᵢ δ` between events with `kᵢ = σᵢ A / δᵢ`: every step's axial force follows
/// that saw-tooth (1e-9), and the energy the drops release, `Σ ½ (kᵢ − kᵢ₊₁) δᵢ²` from the
/// recorded events alone, is G_f A = 0.01 J (1e-9). The first tooth is the brittle strength:
/// δ₀ = f_t L / E exactly. The breaks list the teeth 1–4 with `tooth`, the last break without;
/// `broken` holds the member only after it.
#[test]
fn a_softening_member_follows_its_saw_tooth_and_dissipates_the_fracture_energy() {
    let dir = tempfile::tempdir().unwrap();
    let (l, n, steps) = (0.1, 5usize, 80usize);
    // The last tooth's strain is below G_f/(L f_t) · 2 (a saw-tooth dissipates less than
    // its line's area): travel to 1.5 times that.
    // (Not a round multiple of δ₀: a tooth exactly at a step's end would be taken in the
    // next step, at fraction 0.)
    let travel = 1.537 * 2.0 * SOFT_GF / SOFT_FT;
    let summary = run_softening_bar(dir.path(), "one", &[0.0, l], Some(n), travel, steps);
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    let events = &summary.breaks;
    assert_eq!(events.len(), n, "{events:?}");
    for (i, e) in events.iter().enumerate() {
        assert_eq!(e.member, 1);
        assert_eq!(e.tooth, (i + 1 < n).then_some(i + 1));
    }
    let delta: Vec<f64> = events.iter().map(|e| e.load_factor * travel).collect();
    assert!(close(delta[0], SOFT_FT * l / SOFT_E, 1e-9));
    let sigma = |i: usize| SOFT_FT * (1.0 - i as f64 / n as f64);
    let k = |i: usize| {
        if i < n {
            sigma(i) * SOFT_A / delta[i]
        } else {
            0.0
        }
    };
    assert!(close(k(0), SOFT_E * SOFT_A / l, 1e-9));
    let dissipated: f64 = (0..n)
        .map(|i| 0.5 * (k(i) - k(i + 1)) * delta[i] * delta[i])
        .sum();
    assert!(
        close(dissipated, SOFT_GF * SOFT_A, 1e-9),
        "{dissipated} J against G_f A = {} J",
        SOFT_GF * SOFT_A
    );
    // Teeth in different steps, so each step file can be checked against the saw-tooth.
    let steps_with_events: std::collections::BTreeSet<usize> =
        events.iter().map(|e| e.step).collect();
    assert_eq!(steps_with_events.len(), n);
    for s in 0..=steps {
        let d = travel * s as f64 / steps as f64;
        let passed = delta.iter().filter(|&&di| di <= d).count();
        let expected = k(passed) * d;
        let file = step_file(dir.path(), "one", s).unwrap();
        let body = &file["bodies"][0];
        let force = body["axial_forces"][0].as_f64().unwrap();
        assert!(
            (force - expected).abs() <= 1e-9 * SOFT_FT * SOFT_A,
            "step {s}: {force} N against {expected} N"
        );
        let broken = body["broken"].as_array().unwrap().len();
        assert_eq!(broken, usize::from(passed == n), "step {s}");
    }
}

/// Three members in series (0.1 m each), the first softening (5 teeth), pulled at the far end:
/// the middle nodes are free, so each tooth goes through the Woodbury update of the factored
/// K. The bar's force is `F = δ / (1/kᵢ + 2/k)` with `kᵢ` the softening member's stiffness at
/// its tooth and k = E A / L of the others; the member reaches tooth i's strength σᵢ at
/// `δᵢ = σᵢ A (1/kᵢ + 2/k)`, with `kᵢ` from the member's own teeth (their elongations, found
/// by the one-member case through `saw_tooth`). Every event's load factor and every step's
/// force to 1e-9.
#[test]
fn a_softening_member_in_series_passes_its_teeth_at_the_hand_loads() {
    use linkage::linkage::fracture::saw_tooth;
    let dir = tempfile::tempdir().unwrap();
    let (l, n, steps) = (0.1, 5usize, 60usize);
    let teeth = saw_tooth(SOFT_E, SOFT_FT, l, SOFT_GF, n).unwrap();
    let k = SOFT_E * SOFT_A / l;
    let ki = |i: usize| teeth.get(i).map_or(0.0, |t| t.stiffness_factor * k);
    let compliance = |i: usize| 1.0 / ki(i) + 2.0 / k;
    let delta: Vec<f64> = (0..n)
        .map(|i| teeth[i].tensile_strength * SOFT_A * compliance(i))
        .collect();
    let travel = 1.237 * delta[n - 1];
    let summary = run_softening_bar(
        dir.path(),
        "series",
        &[0.0, l, 2.0 * l, 3.0 * l],
        Some(n),
        travel,
        steps,
    );
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    let events = &summary.breaks;
    assert_eq!(events.len(), n, "{events:?}");
    for (i, e) in events.iter().enumerate() {
        assert_eq!((e.member, e.tooth), (1, (i + 1 < n).then_some(i + 1)));
        assert!(
            close(e.load_factor * travel, delta[i], 1e-9),
            "tooth {i}: {} m against {} m",
            e.load_factor * travel,
            delta[i]
        );
    }
    for s in 0..=steps {
        let d = travel * s as f64 / steps as f64;
        let passed = delta.iter().filter(|&&di| di <= d).count();
        let expected = if passed == n {
            0.0
        } else {
            d / compliance(passed)
        };
        let file = step_file(dir.path(), "series", s).unwrap();
        let forces = file["bodies"][0]["axial_forces"]
            .as_array()
            .unwrap()
            .clone();
        for f in forces {
            let f = f.as_f64().unwrap();
            assert!(
                (f - expected).abs() <= 1e-9 * SOFT_FT * SOFT_A,
                "step {s}: {f} N against {expected} N"
            );
        }
    }
}

/// One tooth is the brittle member: the same run with `teeth = 1` and without softening gives
/// byte-identical step files and the same summary breaks.
#[test]
fn one_tooth_is_exactly_brittle() {
    let dir = tempfile::tempdir().unwrap();
    let xs = [0.0, 0.1, 0.2];
    let travel = 3.1e-5;
    let a = run_softening_bar(&dir.path().join("a"), "bar", &xs, Some(1), travel, 4);
    let b = run_softening_bar(&dir.path().join("b"), "bar", &xs, None, travel, 4);
    assert_eq!(a.breaks, b.breaks);
    assert_eq!(a.breaks.len(), 1);
    assert_eq!(a.breaks[0].tooth, None);
    for s in 0..=4 {
        let read = |d: &str| {
            std::fs::read(dir.path().join(format!("{d}/out/bar/steps/{s:04}.json"))).unwrap()
        };
        assert_eq!(read("a"), read("b"), "step {s}");
    }
}

/// A fracture energy below what a member dissipates breaking at once, f_t² L/(2E), is refused
/// naming the body and the member: with L = 0.1 m that least is 15 J/m².
#[test]
fn too_little_fracture_energy_is_refused_naming_the_member() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("brittle.toml");
    std::fs::write(dir.path().join("b.nodes"), "0 0\n0.1 0\n").unwrap();
    std::fs::write(dir.path().join("b.links"), "1 2\n").unwrap();
    std::fs::write(
        &scene,
        r#"name = "brittle"
[[materials]]
name = "soft"
youngs_modulus = 30e9
area = 1e-4
tensile_strength = 3e6
failure = "break"
softening = { fracture_energy = 14.0, teeth = 4 }
[[bodies]]
name = "bar"
nodes = "b.nodes"
links = "b.links"
material = "soft"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2]
fix = ["x", "y"]
displacement = [1e-4, 0.0]
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let err = run(&world, &dir.path().join("out"), &|| {}).unwrap_err();
    let text = format!("{err:#}");
    assert!(
        text.contains("body 'bar'") && text.contains("member 1"),
        "{text}"
    );
    assert!(text.contains("fracture_energy = 14 J/m²"), "{text}");
}

/// The bundled softening variant of paper_fracture: until its first event the solid is the
/// brittle one, so its first tooth is passed at paper_fracture's first break (same member, load
/// factor to 1e-12); every member then passes its teeth 1, 2, 3 in order before it breaks, and
/// the solid collapses in step 3 as the brittle one does, by breaking member 77.
#[test]
fn the_softening_variant_of_paper_fracture_passes_its_teeth_then_collapses() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let out = tempfile::tempdir().unwrap();
    let brittle = run(
        &load_scene(&root.join("paper_fracture.toml")).unwrap(),
        out.path(),
        &|| {},
    )
    .unwrap();
    let soft = run(
        &load_scene(&root.join("paper_fracture_softening.toml")).unwrap(),
        out.path(),
        &|| {},
    )
    .unwrap();
    let (first, b) = (&soft.breaks[0], &brittle.breaks[0]);
    assert_eq!(
        (first.step, first.member, first.tooth),
        (b.step, b.member, Some(1))
    );
    assert!(close(first.load_factor, b.load_factor, 1e-12));
    for member in [1, 77] {
        let teeth: Vec<Option<usize>> = soft
            .breaks
            .iter()
            .filter(|e| e.member == member)
            .map(|e| e.tooth)
            .collect();
        assert_eq!(
            teeth,
            vec![Some(1), Some(2), Some(3), None],
            "member {member}"
        );
    }
    assert_eq!(soft.breaks.len(), 8);
    let collapse = soft.collapse.as_ref().expect("a collapse");
    assert_eq!((collapse.step, collapse.member), (3, 77));
}

/// Case 7 of issue 32, **failure that the results hide**: a plate with a round hole (the
/// bundled outline, members of about 2 cm) of a brittle material, held on its left edge and
/// pulled by 1 mm on its right one over 20 steps: members break beside the hole from where the
/// stress concentrates until the cracks cross the plate. Every step is in equilibrium; the run
/// says that the plate failed, once, at the first step it carries less than half its peak
/// load, with the peak and the capacity left as the step files' reactions give them (the pull
/// on the right edge, to 0.05 percentage points as written with one decimal).
#[test]
fn failure_that_the_results_hide() {
    let dir = tempfile::tempdir().unwrap();
    let scene = brittle_plate(
        dir.path(),
        "[[bodies.supports]]\non_line = { point = [0.4, 0.0], direction = [0.0, 1.0] }\nfix = [\"x\", \"y\"]\ndisplacement = [0.001, 0.0]\n",
    );
    let world = load_scene(&scene).unwrap();
    let summary = run(&world, &dir.path().join("out"), &|| {}).expect("a result");
    assert!(summary.collapse.is_none() && summary.failure.is_none());
    assert_eq!(summary.steps.len(), 21);
    // The pull each step carries: the norm of the reactions summed over the right edge.
    let pulls: Vec<f64> = (0..=20)
        .map(|s| {
            let step = step_file(dir.path(), "plate", s).unwrap();
            let mut sum = [0.0f64; 2];
            for r in step["bodies"][0]["reactions"].as_array().unwrap() {
                let n = r["node"].as_u64().unwrap() as usize - 1;
                if (world.bodies[0].nodes[n].x - 0.4).abs() < 1e-9 {
                    for (k, v) in sum.iter_mut().enumerate() {
                        *v += r["force"][k].as_f64().unwrap();
                    }
                }
            }
            sum[0].hypot(sum[1])
        })
        .collect();
    let told: Vec<(usize, &String)> = summary
        .steps
        .iter()
        .flat_map(|s| s.warnings.iter().map(move |w| (s.step, w)))
        .filter(|(_, w)| w.contains("of its peak load"))
        .collect();
    assert_eq!(told.len(), 1, "{told:?} {pulls:?}");
    let (step, w) = told[0];
    let (peak_step, peak) = pulls[..=step]
        .iter()
        .copied()
        .enumerate()
        .fold((0, 0.0), |b, (s, p)| if p > b.1 { (s, p) } else { b });
    assert!(pulls[step] < 0.5 * peak);
    assert!(pulls[peak_step..step].iter().all(|&p| p >= 0.5 * peak));
    let percent = 100.0 * pulls[step] / peak;
    let said: f64 = w
        .split("carries ")
        .nth(1)
        .and_then(|r| r.split(" %").next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("{w}"));
    assert!((said - percent).abs() <= 0.05 + 1e-9, "{w}: {percent}");
    assert!(w.contains(&format!("at step {peak_step})")), "{w}");
    assert!(w.contains("it has failed"), "{w}");
}

/// Case 7 of issue 32, **failure that the results hide**, under force control: the same
/// brittle plate with a hole pulled by 20 kN on its right edge over 20 steps. At step 7 the
/// first members beside the hole reach their strength and a cascade of breaks crosses the
/// plate until it is a mechanism: a collapse. The collapse state used not to be written, so
/// the last frame (step 6) showed none of the 23 broken members. The state it collapsed in
/// is the run's last stored step: every member the run broke shown broken (the displacements
/// at the load the cascade reached), flagged as the collapse in summary.json's step line and
/// the step file, and drawn (its frame's title says "collapsed": a unit test of the overlay).
#[test]
fn failure_that_the_results_hide_under_force_control() {
    let dir = tempfile::tempdir().unwrap();
    let scene = brittle_plate(
        dir.path(),
        "[[bodies.loads]]\non_line = { point = [0.4, 0.0], direction = [0.0, 1.0] }\ntotal_force = [20000.0, 0.0]\n",
    );
    let world = load_scene(&scene).unwrap();
    let summary = run(&world, &dir.path().join("out"), &|| {}).expect("a result");
    let collapse = summary.collapse.as_ref().expect("a collapse");
    assert!(summary.failure.is_none());
    // Every break is of the collapse step (a cascade from the first).
    assert!(summary.breaks.len() > 2, "{:?}", summary.breaks);
    assert!(summary.breaks.iter().all(|b| b.step == collapse.step));
    // The collapse step is the last line of the summary, flagged, and the last step stored.
    assert_eq!(summary.steps.len(), collapse.step + 1);
    let line = summary.steps.last().unwrap();
    assert_eq!(line.step, collapse.step);
    assert!(line.collapse && !summary.steps[..collapse.step].iter().any(|l| l.collapse));
    assert_eq!(line.broken, Some(summary.breaks.len()));
    let last = step_file(dir.path(), "plate", collapse.step).expect("the collapse step written");
    assert!(step_file(dir.path(), "plate", collapse.step + 1).is_none());
    assert_eq!(last["load_factor"].as_f64(), Some(line.load_factor));
    // The body's fracture keys are written flat in its entry.
    let fracture = &last["bodies"][0];
    assert_eq!(fracture["collapse"].as_bool(), Some(true));
    let mut broken: Vec<u64> = fracture["broken"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m.as_u64().unwrap())
        .collect();
    broken.sort_unstable();
    let mut expected: Vec<u64> = summary.breaks.iter().map(|b| b.member as u64).collect();
    expected.sort_unstable();
    assert_eq!(broken, expected);
    // The step before: nothing broken, not flagged.
    let before = step_file(dir.path(), "plate", collapse.step - 1).unwrap();
    assert!(before["bodies"][0]["collapse"].is_null());
    assert!(before["bodies"][0]["broken"].as_array().unwrap().is_empty());
}

/// Gravity with fracture (a pair of the table in docs/SCENES.md): a vertical bar (node 1 held
/// at (0, 1), node 2 below it at the origin held sideways, length 1 m, ρ = 7850 kg/m³, g = 9.81 m/s², its
/// weight W = ρ A L g at full value from step 1 on) with P up to 40 kN down at node 2 over 4
/// steps. Node 2 carries half the weight, so the bar carries N = λ P + W/2 and breaks at
/// λ* = (f_t A − W/2)/P in step 3 (to 1e-9); node 2 is then held by nothing along its load:
/// the structure collapsed.
#[test]
fn a_bar_breaks_under_its_weight_and_a_growing_load_at_the_hand_load() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("g.nodes"), "0 1\n0 0\n").unwrap();
    std::fs::write(d.join("g.links"), "1 2\n").unwrap();
    let scene = d.join("g.toml");
    std::fs::write(
        &scene,
        r#"name = "g"
steps = 4
gravity = [0.0, -9.81]
gravity_schedule = [1.0, 1.0, 1.0, 1.0]
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
density = 7850
tensile_strength = 250e6
failure = "break"
[[bodies]]
name = "bar"
nodes = "g.nodes"
links = "g.links"
material = "steel"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2]
fix = ["x"]
[[bodies.loads]]
nodes = [2]
force = [0.0, -40000.0]
"#,
    )
    .unwrap();
    let world = load_scene(&scene).unwrap();
    let summary = run(&world, &d.join("out"), &|| {}).expect("a result");
    let weight = 7850.0 * 1e-4 * 1.0 * 9.81;
    let expected = (FT_A - weight / 2.0) / 40000.0;
    assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
    assert_eq!((summary.breaks[0].step, summary.breaks[0].member), (3, 1));
    let collapse = summary.collapse.as_ref().expect("a collapse");
    assert_eq!((collapse.step, collapse.member), (3, 1));
    // Steps 0 to 2, and the collapse state as step 3.
    assert_eq!(summary.steps.len(), 4);
    assert!(summary.steps[3].collapse);
    assert!(
        close(summary.breaks[0].load_factor, expected, 1e-9),
        "{} against {expected}",
        summary.breaks[0].load_factor
    );
    // Before the break the bar carries λ P + W/2 (step 2: λ = 1/2).
    let step2 = step_file(d, "g", 2).unwrap();
    let n = step2["bodies"][0]["axial_forces"][0].as_f64().unwrap();
    assert!(close(n, 20000.0 + weight / 2.0, 1e-12), "{n}");
}

/// Issue 32 case 7's plate: the bundled plate with a hole (members of about 2 cm) of a brittle
/// material (E = 200 GPa, A = 1e-5 m², 100 MPa, breaking), held on its left edge, 20 steps,
/// pulled on its right edge as `right` (TOML) says: `dir/plate.toml`.
fn brittle_plate(dir: &Path, right: &str) -> PathBuf {
    let here = std::env::current_dir()
        .unwrap()
        .join("scenes/plate_with_hole.txt");
    let scene = dir.join("plate.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "plate"
steps = 20
[[materials]]
name = "brittle"
youngs_modulus = 200e9
area = 1e-5
tensile_strength = 100e6
failure = "break"
[[bodies]]
name = "plate"
outline = {{ file = "{}", spacing = 0.02 }}
material = "brittle"
[[bodies.supports]]
on_line = {{ point = [0.0, 0.0], direction = [0.0, 1.0] }}
fix = ["x"]
[[bodies.supports]]
nearest = [0.0, 0.0]
fix = ["y"]
{right}"#,
            here.display()
        ),
    )
    .unwrap();
    scene
}
