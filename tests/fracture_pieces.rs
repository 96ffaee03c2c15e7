//! Pieces that a break cuts loose from a body under large displacements are decided as a
//! linear body decides them (issue 32 case 6): an unloaded piece falls off and the rest goes
//! on; a loaded piece still hanging on the rest by a mechanism is the structure's collapse.
//!
//! The body: a bar pulled apart along x (node 1 at the origin pinned, nodes 2 (−1, 0) and
//! 3 (1, 0) on rollers along x, members 1 (2–1) and 2 (1–3) strong, E A = 2e7 N), pulled by
//! P = 60 kN at nodes 2 and 3 outward over 10 steps, with a piece, node 4 at (0, 1), tied to
//! nodes 2, 1 and 3 by members 3, 4 and 5 (E A = 2e7 N, breaking at 100 MPa in tension,
//! f_t A = 10 kN). The bar's stretch pulls the diagonals 3 and 5 in tension and pushes the
//! vertical 4; the diagonals reach their strength together (mirror images) in step 7, and node
//! 4 is left on the vertical alone: a node on fewer members than its DOFs.

use linkage::scene::{load_scene, run, Summary};

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

/// Write `name.toml` with the body of the module documentation (`piece`: with node 4 and its
/// members, else the bar alone), `kinematics`, and `extra` appended, into `d`; run it into
/// `d/out`.
fn run_scene(
    d: &std::path::Path,
    name: &str,
    piece: bool,
    kinematics: &str,
    extra: &str,
) -> Summary {
    let (nodes, links) = if piece {
        (
            "0 0\n-1 0\n1 0\n0 1\n",
            "2 1 strong\n1 3 strong\n4 2 weak\n4 1 weak\n4 3 weak\n",
        )
    } else {
        ("0 0\n-1 0\n1 0\n", "2 1 strong\n1 3 strong\n")
    };
    std::fs::write(d.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(d.join(format!("{name}.links")), links).unwrap();
    let scene = d.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
steps = 10
[[materials]]
name = "strong"
youngs_modulus = 200e9
area = 1e-4
[[materials]]
name = "weak"
youngs_modulus = 200e9
area = 1e-4
tensile_strength = 100e6
failure = "break"
[[bodies]]
name = "piece"
nodes = "{name}.nodes"
links = "{name}.links"
material = "strong"
kinematics = "{kinematics}"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2, 3]
fix = ["y"]
[[bodies.loads]]
nodes = [2]
force = [-60000.0, 0.0]
[[bodies.loads]]
nodes = [3]
force = [60000.0, 0.0]
{extra}"#
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

fn numbers(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .flat_map(|x| match x.as_array() {
            Some(a) => a.iter().map(|y| y.as_f64().unwrap()).collect(),
            None => vec![x.as_f64().unwrap()],
        })
        .collect()
}

/// The piece is unloaded: when the diagonals break (step 7, in one event: equal load factors
/// to 1e-9) node 4 falls off with the vertical, as in the linear body (the same step, members
/// and fallen node; the load factor differs by the large displacements, 0.6863 against
/// 0.6869), and the run goes on to step 10 without a collapse. From the break's step on the
/// piece carries nothing, node 4 is held where it was made, and the rest is the bar alone:
/// its displacements and forces equal those of the same body without the piece to 1e-9
/// (the bar is determinate: N = λ P, each end moving λ P L/(E A) = 3 mm at step 10).
#[test]
fn an_unloaded_piece_of_a_large_body_falls_off_and_the_rest_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let large = run_scene(d, "large", true, "large", "");
    let linear = run_scene(d, "linear", true, "linear", "");
    let alone = run_scene(d, "alone", false, "large", "");
    assert!(alone.breaks.is_empty() && alone.steps.len() == 11);
    for summary in [&large, &linear] {
        assert!(summary.collapse.is_none(), "{:?}", summary.collapse);
        assert!(summary.failure.is_none());
        assert_eq!(summary.steps.len(), 11);
        let breaks: Vec<(usize, usize)> =
            summary.breaks.iter().map(|b| (b.step, b.member)).collect();
        assert_eq!(breaks, vec![(7, 3), (7, 5)], "{:?}", summary.breaks);
        assert!(close(
            summary.breaks[0].load_factor,
            summary.breaks[1].load_factor,
            1e-9
        ));
        let warned: Vec<&String> = summary.steps[7]
            .warnings
            .iter()
            .filter(|w| w.contains("fell off"))
            .collect();
        assert_eq!(warned.len(), 1, "{:?}", summary.steps[7].warnings);
        assert!(
            warned[0].contains("breaking member 5 left a piece of 1 node(s) (4)"),
            "{}",
            warned[0]
        );
    }
    assert!(close(
        large.breaks[0].load_factor,
        linear.breaks[0].load_factor,
        2e-3
    ));
    for step in 0..=10 {
        let with = &step_json(d, "large", step)["bodies"][0];
        let without = &step_json(d, "alone", step)["bodies"][0];
        let fallen = with.get("fallen").map(numbers);
        assert_eq!(fallen, (step == 7).then(|| vec![4.0]), "step {step}");
        if step < 7 {
            continue;
        }
        let (u, u0) = (
            numbers(&with["displacements"]),
            numbers(&without["displacements"]),
        );
        assert_eq!(
            &u[6..],
            &[0.0, 0.0],
            "step {step}: node 4 held where it was made"
        );
        for (a, b) in u[..6].iter().zip(&u0) {
            assert!(
                (a - b).abs() <= 1e-9 * 3e-3,
                "step {step}: {u:?} against {u0:?}"
            );
        }
        let (n, n0) = (
            numbers(&with["axial_forces"]),
            numbers(&without["axial_forces"]),
        );
        assert_eq!(&n[2..], &[0.0; 3], "step {step}: the piece carries nothing");
        let p = 6000.0 * step as f64;
        for (a, b) in n[..2].iter().zip(&n0) {
            assert!(
                close(*a, *b, 1e-9) && close(*a, p, 1e-9),
                "step {step}: {n:?}"
            );
        }
        let u_end = p * 1.0 / 2e7;
        assert!(
            close(u[2], -u_end, 1e-9) && close(u[4], u_end, 1e-9),
            "{u:?}"
        );
    }
}

/// The piece carries a load (1 kN down at node 4): when the diagonals break (step 7, in one
/// event) the loaded node hangs on the rest by the vertical alone, a mechanism under load (with
/// large displacements it is balanced on the vertical strut: solved, but with a negative
/// pivot). That is the structure's collapse, with large displacements as with linear ones
/// (issue 32 case 6), not a piece that fell off: the same step, members and member named;
/// steps 0-6 written; the load factors agree to 2e-3 (0.6979 against 0.6985).
#[test]
fn a_loaded_piece_hanging_by_a_mechanism_is_a_collapse_of_a_large_body() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let load = "[[bodies.loads]]\nnodes = [4]\nforce = [0.0, -1000.0]\n";
    let large = run_scene(d, "large", true, "large", load);
    let linear = run_scene(d, "linear", true, "linear", load);
    for summary in [&large, &linear] {
        assert!(summary.failure.is_none());
        let collapse = summary.collapse.as_ref().expect("a collapse");
        assert_eq!((collapse.step, collapse.member), (7, 5), "{collapse:?}");
        let breaks: Vec<(usize, usize)> =
            summary.breaks.iter().map(|b| (b.step, b.member)).collect();
        assert_eq!(breaks, vec![(7, 3), (7, 5)], "{:?}", summary.breaks);
        assert!(summary
            .steps
            .iter()
            .all(|l| l.warnings.iter().all(|w| !w.contains("fell off"))));
    }
    assert_eq!(large.steps.len(), 7, "steps 0-6");
    assert!(close(
        large.collapse.as_ref().unwrap().load_factor,
        linear.collapse.as_ref().unwrap().load_factor,
        2e-3
    ));
}
