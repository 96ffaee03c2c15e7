//! Arc length against a fixed stop (issue 32, combination 3): one large-displacement body
//! followed along its arc-length path through its limit point and onto a rigid plane, the
//! plane's penalty force and stiffness in the body's residual and tangent. Every check is
//! against the closed form, the same body's path without the stop, or equilibrium, with its
//! tolerance stated where it is used.

use linkage::linkage::{
    stop_forces, Body, Dimension, Kinematics, Material, Member, NewtonEquilibrium, NodalLoad,
    PathMethod, Schedule, StepState, Stop, Support,
};
use linkage::scene::{load_scene, Simulation, StepResult};
use nalgebra::Vector3;
use std::path::Path;

fn v(x: f64, y: f64) -> Vector3<f64> {
    Vector3::new(x, y, 0.0)
}

/// Half span a, rise h (m), axial stiffness EA (N; E = 200 GPa, A = 1 cm²).
const A: f64 = 1.0;
const H: f64 = 0.1;
const EA: f64 = 200e9 * 1e-4;

/// Closed form of the von Mises truss with engineering strain: with the apex lowered by w,
/// each bar has length l = √(a² + (h − w)²) and force N = EA (l − L)/L; the downward apex
/// load in equilibrium is P = −2 N (h − w)/l.
fn von_mises_load(w: f64) -> f64 {
    let l0 = (A * A + H * H).sqrt();
    let l = (A * A + (H - w) * (H - w)).sqrt();
    -2.0 * EA * (l - l0) / l0 * (H - w) / l
}

/// The limit load: dP/dw = 0 on the rising branch, by bisection on a central difference.
fn von_mises_limit() -> f64 {
    let slope = |w: f64| (von_mises_load(w + 1e-7) - von_mises_load(w - 1e-7)) / 2e-7;
    let (mut lo, mut hi) = (0.0, H);
    while hi - lo > 1e-13 {
        let mid = 0.5 * (lo + hi);
        if slope(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    von_mises_load(0.5 * (lo + hi))
}

/// The truss with its limit load as the reference load at the apex (node 2), on an
/// arc-length path of 4 mm per step, Newton to 1e-10.
fn von_mises() -> Body {
    let mut body = Body::new("von_mises", Dimension::Two);
    body.materials.push(Material::new("steel", 200e9, 1e-4));
    body.nodes = vec![v(-A, 0.0), v(0.0, H), v(A, 0.0)];
    for nodes in [[0, 1], [1, 2]] {
        body.members.push(Member { nodes, material: 0 });
    }
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(Support::fixed(2, [true, true, false]));
    body.loads.push(NodalLoad {
        node: 1,
        force: v(0.0, -von_mises_limit()),
        schedule: Schedule::Linear,
    });
    body.kinematics = Kinematics::Large;
    body.newton.path = PathMethod::ArcLength { length: 0.004 };
    body.newton.tolerance = 1e-10;
    body
}

/// The apex's stop: a floor `W_STOP` below the apex (50 mm below the supports, normal up),
/// 1e6 N/m of depth.
const W_STOP: f64 = 0.15;
const K_STOP: f64 = 1e6;

fn floor() -> Stop {
    Stop {
        name: "floor".to_string(),
        point: v(0.0, H - W_STOP),
        normal: v(0.0, 1.0),
        stiffness: K_STOP,
    }
}

/// Solve steps 1..=steps; each state with the stop's total force then, N.
fn trace(body: &Body, stops: Vec<Stop>, steps: usize) -> Vec<(StepState, Vector3<f64>)> {
    let mut newton = NewtonEquilibrium::new(body).expect("builds");
    newton.set_stops(stops);
    (1..=steps)
        .map(|k| {
            let state = newton.solve_step(body, k, steps).expect("step converges");
            let pushed = stop_forces(body, newton.stops(), newton.displacement())
                .into_iter()
                .map(|(f, _)| f)
                .sum();
            (state, pushed)
        })
        .collect()
}

/// The shallow two-bar truss on an arc-length path: the load factor rises to the limit load
/// (1 to 2e-3: the traced point nearest the limit) and falls on the snap-through branch
/// through zero (the bars flat) to negative loads, the same path as without the floor (to
/// 1e-12 of the limit load) and on the closed form (to 1e-6) until the apex reaches the floor
/// 150 mm down (past the flat position); from there on the floor carries: the
/// load factor rises again, every point lies on the closed form with the floor's spring,
/// `λ P_lim = P(w) + k (w − w_stop)` (to 1e-6 of the limit load), the floor's force is
/// `k (w − w_stop)` up, and the supports, the load and the floor balance to 1e-8 of the load.
#[test]
fn von_mises_truss_pressed_through_its_limit_point_onto_a_stop_by_arc_length() {
    let body = von_mises();
    let limit = von_mises_limit();
    let steps = 60;
    let free = trace(&body, Vec::new(), steps);
    let held = trace(&body, vec![floor()], steps);
    let mut peak: f64 = 0.0;
    let mut fell = false;
    let mut touched = None;
    for (k, ((s, pushed), (f, _))) in held.iter().zip(&free).enumerate() {
        let w = -s.displacements[1].y;
        let lambda = s.load_factor.expect("arc length reports its load factor");
        let load = lambda * limit;
        if w <= W_STOP {
            // Not touching: the path without the floor.
            assert_eq!(pushed.norm(), 0.0, "step {}", k + 1);
            let lambda_free = f.load_factor.unwrap();
            assert!(
                (lambda - lambda_free).abs() <= 1e-12,
                "step {}: {lambda} {lambda_free}",
                k + 1
            );
            assert!(
                (load - von_mises_load(w)).abs() <= 1e-6 * limit,
                "step {}: w = {w}, λP = {load}, P(w) = {}",
                k + 1,
                von_mises_load(w)
            );
            fell |= lambda < peak - 0.01;
            peak = peak.max(lambda);
            continue;
        }
        touched.get_or_insert(k);
        // On the floor: the closed form with the floor's spring.
        let spring = K_STOP * (w - W_STOP);
        assert!(
            (pushed - v(0.0, spring)).norm() <= 1e-9 * spring,
            "step {}: {pushed} against {spring}",
            k + 1
        );
        assert!(
            (load - (von_mises_load(w) + spring)).abs() <= 1e-6 * limit,
            "step {}: w = {w}, λP = {load}, P(w) + k (w − w_stop) = {}",
            k + 1,
            von_mises_load(w) + spring
        );
        // Supports, load and floor balance.
        let reactions: Vector3<f64> = s.reactions.iter().map(|(_, r)| r).sum();
        let applied: Vector3<f64> = s.loads.iter().map(|(_, f)| f).sum();
        let sum = reactions + applied + pushed;
        assert!(
            sum.norm() <= 1e-8 * applied.norm(),
            "step {}: reactions {reactions} + load {applied} + floor {pushed} = {sum}",
            k + 1
        );
        assert_eq!(s.negative_pivots, 0, "step {}: held by the floor", k + 1);
    }
    let touched = touched.expect("the apex reaches the floor");
    let before = held[touched - 1].0.load_factor.unwrap();
    let last = held.last().unwrap().0.load_factor.unwrap();
    println!(
        "peak λ {peak:.6}, fell {fell}, floor reached at step {}, λ {before:.4} there, {last:.4} at step {steps}",
        touched + 1
    );
    assert!((peak - 1.0).abs() <= 2e-3, "limit load {peak}");
    assert!(fell, "the load factor falls past the limit point");
    assert!(before < 0.99 * peak, "{before} {peak}");
    assert!(
        last > peak,
        "the floor carries: λ {last} beyond the limit {peak}"
    );
}

/// The scene file of the truss above against the floor: the same nodes, load (the closed-form
/// limit load, written to round trip), arc length, tolerance and penalty; `extra` is appended.
fn von_mises_scene(dir: &Path, steps: usize, extra: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("t.nodes"), format!("-{A} 0\n0 {H}\n{A} 0\n")).unwrap();
    std::fs::write(dir.join("t.links"), "1 2\n2 3\n").unwrap();
    let scene = dir.join("floor.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "floor"
steps = {steps}
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "von_mises"
nodes = "t.nodes"
links = "t.links"
kinematics = "large"
[bodies.newton]
tolerance = 1e-10
[bodies.path]
method = "arc_length"
arc_length = 0.004
[[bodies.supports]]
nodes = [1, 3]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [2]
force = [0.0, {}]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, {}]
normal = [0.0, 1.0]
{extra}
[contact]
penalty = {K_STOP:e}
"#,
            -von_mises_limit(),
            H - W_STOP,
        ),
    )
    .unwrap();
    scene
}

/// Steps 1..=steps of a scene, as written; the error as its text.
fn run_scene(scene: &Path, steps: usize) -> Result<Vec<StepResult>, String> {
    let world = load_scene(scene).expect("the scene reads");
    let text = |e: linkage::scene::RunError| format!("{e:#}");
    let mut sim = Simulation::new(&world).map_err(text)?;
    (1..=steps)
        .map(|k| sim.step(k).map(|(r, _)| r).map_err(text))
        .collect()
}

/// The same truss from a scene file with a `half_space` obstacle: routed to the body's own
/// Newton with the floor as a stop, the path rises to the limit load, falls, and rises on the
/// floor; every step agrees with the library path above (λ and the apex, 1e-9), and the
/// written contact force on the floor (per node and in the summary's totals) balances the
/// supports' reactions and the load (1e-8 of the load).
#[test]
fn von_mises_truss_scene_with_a_half_space_follows_the_arc_length_onto_the_floor() {
    let dir = tempfile::tempdir().unwrap();
    let steps = 60;
    let scene = von_mises_scene(dir.path(), steps, "");
    let world = load_scene(&scene).expect("the scene reads");
    let mut sim = Simulation::new(&world).expect("routed to the body's own Newton");
    let library = trace(&von_mises(), vec![floor()], steps);
    let (mut peak, mut fell, mut touched): (f64, bool, Option<usize>) = (0.0, false, None);
    // The largest differences from the library path (λ, apex in m) and off balance (N / N).
    let (mut d_lambda, mut d_apex, mut off): (f64, f64, f64) = (0.0, 0.0, 0.0);
    // The default penetration tolerance: 1% of the bars' length.
    let tolerance = 0.01 * (A * A + H * H).sqrt();
    for (k, (state, pushed)) in library.iter().enumerate() {
        let (result, summary) = sim.step(k + 1).expect("step solves");
        let lambda = state.load_factor.unwrap();
        assert!(
            (result.load_factor - lambda).abs() <= 1e-9
                && (summary.load_factor - lambda).abs() <= 1e-9,
            "step {}: λ {} against {lambda}",
            k + 1,
            result.load_factor
        );
        d_lambda = d_lambda.max((result.load_factor - lambda).abs());
        let body = &result.bodies[0];
        let w = -body.displacements[1][1];
        d_apex = d_apex.max((w + state.displacements[1].y).abs());
        assert!(
            (w + state.displacements[1].y).abs() <= 1e-9,
            "step {}: apex {w} against {}",
            k + 1,
            -state.displacements[1].y
        );
        let written: Vector3<f64> = body
            .contacts
            .iter()
            .map(|c| {
                assert_eq!((c.node, c.with.as_str()), (2, "floor"));
                v(c.force[0], c.force[1])
            })
            .sum();
        let reactions: Vector3<f64> = body
            .reactions
            .iter()
            .map(|r| v(r.force[0], r.force[1]))
            .sum();
        let applied: Vector3<f64> = body.loads.iter().map(|r| v(r.force[0], r.force[1])).sum();
        let balance = -(reactions + applied);
        off = off.max((written - balance).norm() / applied.norm().max(1.0));
        assert!(
            (written - balance).norm() <= 1e-8 * applied.norm().max(1.0),
            "step {}: floor {written} against supports and load {balance}",
            k + 1
        );
        assert!((written - pushed).norm() <= 1e-9 * pushed.norm().max(1.0));
        if pushed.norm() > 0.0 {
            touched.get_or_insert(k);
            assert_eq!(summary.contact_forces.len(), 1, "step {}", k + 1);
            let total = &summary.contact_forces[0];
            assert_eq!(
                (total.body.as_str(), total.with.as_str()),
                ("von_mises", "floor")
            );
            assert!((v(total.force[0], total.force[1]) - written).norm() <= 1e-9 * written.norm());
            assert!((summary.max_penetration - (w - W_STOP)).abs() <= 1e-12);
            assert_eq!(summary.slipping, 1, "frictionless: the apex slips");
            // Deeper than the contact solver's tolerance: its warning.
            let warned = summary.warnings.iter().any(|w| {
                w.contains("node 2 of body 'von_mises' is") && w.contains("inside 'floor'")
            });
            assert_eq!(
                warned,
                w - W_STOP > tolerance,
                "step {}: {:?}",
                k + 1,
                summary.warnings
            );
        } else {
            assert!(body.contacts.is_empty() && summary.contact_forces.is_empty());
            fell |= lambda < peak - 0.01;
            peak = peak.max(lambda);
        }
    }
    let touched = touched.expect("the apex reaches the floor");
    let last = library.last().unwrap().0.load_factor.unwrap();
    println!(
        "scene: peak λ {peak:.6}, floor reached at step {}, λ {last:.4} at step {steps}; from the library path at most {d_lambda:.1e} in λ, {d_apex:.1e} m at the apex; floor against supports and load {off:.1e} of the load",
        touched + 1
    );
    assert!((peak - 1.0).abs() <= 2e-3 && fell && last > peak);
}

/// An arc-length body against a moving obstacle is refused before anything is solved, naming
/// the body, the obstacle, the reason and the remedy.
#[test]
fn an_arc_length_body_against_a_moving_obstacle_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let scene = von_mises_scene(
        dir.path(),
        4,
        "[[obstacles]]\nname = \"press\"\nshape = \"half_space\"\npoint = [0.0, 0.3]\nnormal = [0.0, -1.0]\ntravel = [0.0, -0.1]\n",
    );
    let text = run_scene(&scene, 1).unwrap_err();
    assert!(
        text.contains("body 'von_mises'")
            && text.contains("obstacle 'press' moves")
            && text.contains(
                "a moving obstacle sets the path's time, which the arc length sets itself"
            )
            && text.contains("method = \"schedules\""),
        "{text}"
    );
}

/// An arc-length body against a ball is refused: only half-spaces are stops so far.
#[test]
fn an_arc_length_body_against_a_ball_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let scene = von_mises_scene(
        dir.path(),
        4,
        "[[obstacles]]\nname = \"ball\"\nshape = \"ball\"\ncenter = [0.0, 0.5]\nradius = 0.1\n",
    );
    let text = run_scene(&scene, 1).unwrap_err();
    assert!(
        text.contains("body 'von_mises'")
            && text.contains("obstacle 'ball' is not a half-space: only half-spaces are stops of an arc-length body so far"),
        "{text}"
    );
}

/// An arc-length body with friction, beside another body, or with self-contact on is refused
/// with the reason.
#[test]
fn an_arc_length_body_with_friction_another_body_or_self_contact_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let scene = von_mises_scene(dir.path(), 4, "");
    let text = std::fs::read_to_string(&scene).unwrap();
    std::fs::write(&scene, format!("{text}friction = 0.3\n")).unwrap();
    let e = run_scene(&scene, 1).unwrap_err();
    assert!(
        e.contains("body 'von_mises'")
            && e.contains("friction's history needs increments in the load's time"),
        "{e}"
    );
    let other = text.replace(
        "[[obstacles]]",
        "[[bodies]]\nname = \"other\"\nnodes = \"t.nodes\"\nlinks = \"t.links\"\noffset = [0.0, 1.0]\n[[bodies.supports]]\nnodes = [1, 3]\nfix = [\"x\", \"y\"]\n[[obstacles]]",
    );
    std::fs::write(&scene, other).unwrap();
    let e = run_scene(&scene, 1).unwrap_err();
    assert!(
        e.contains("body 'von_mises'")
            && e.contains("the arc length is one body's constraint; the contact solver advances by load control"),
        "{e}"
    );
    std::fs::write(&scene, format!("{text}self = true\n")).unwrap();
    let e = run_scene(&scene, 1).unwrap_err();
    assert!(
        e.contains("body 'von_mises'")
            && e.contains("self-contact is on")
            && e.contains("[contact] self = false"),
        "{e}"
    );
}
