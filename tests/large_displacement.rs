//! Large displacements: geometrically exact members solved by Newton (issue 4). Every check
//! is against a closed form or an exact property, with its tolerance stated where it is used.

mod common;

use linkage::linkage::{
    Behaviour, Body, BodyError, BodySolver, Dimension, Kinematics, Material, Member,
    NewtonEquilibrium, NodalLoad, PathMethod, Schedule, SolveError, StepState, Support,
};
use linkage::scene::RunError;
use nalgebra::Vector3;

fn v(x: f64, y: f64) -> Vector3<f64> {
    Vector3::new(x, y, 0.0)
}

fn bar(body: &mut Body, a: usize, b: usize, material: usize) {
    body.members.push(Member {
        nodes: [a, b],
        material,
    });
}

fn load(node: usize, force: Vector3<f64>) -> NodalLoad {
    NodalLoad {
        node,
        force,
        schedule: Schedule::Linear,
    }
}

fn moved(node: usize, fixed: [bool; 3], displacement: Vector3<f64>) -> Support {
    Support {
        node,
        fixed,
        displacement,
        schedule: Schedule::Linear,
    }
}

/// Solve every step 1..=steps in order; return the states.
fn solve_all(body: &Body, steps: usize) -> Vec<StepState> {
    let mut solver = BodySolver::new(body).expect("solvable");
    (1..=steps)
        .map(|s| solver.solve_step(body, s, steps).expect("step converges"))
        .collect()
}

// ---------------------------------------------------------------- the shallow two-bar truss

/// Half span a, rise h, axial stiffness EA (E = 200 GPa, A = 1 cm²).
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

/// The limit point: dP/dw = 0 on the rising branch, by bisection on a central difference
/// slope (to 1e-13 in w; P is flat there, so its value is far more accurate).
fn von_mises_limit() -> (f64, f64) {
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
    let w = 0.5 * (lo + hi);
    (w, von_mises_load(w))
}

fn von_mises(load_factor: f64) -> Body {
    let mut body = Body::new("von_mises", Dimension::Two);
    body.materials.push(Material::new("steel", 200e9, 1e-4));
    body.nodes = vec![v(-A, 0.0), v(0.0, H), v(A, 0.0)];
    bar(&mut body, 0, 1, 0);
    bar(&mut body, 1, 2, 0);
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(Support::fixed(2, [true, true, false]));
    body.loads
        .push(load(1, v(0.0, -load_factor * von_mises_limit().1)));
    body.kinematics = Kinematics::Large;
    body
}

/// Under load control up to 95 % of the limit load, every step lies on the closed-form curve:
/// the applied load equals P(w) of the computed apex deflection to 1e-6 relative, and the
/// apex does not move sideways.
#[test]
fn von_mises_truss_follows_closed_form_under_load_control() {
    let body = von_mises(0.95);
    let (_, limit) = von_mises_limit();
    let steps = 5;
    for (k, s) in solve_all(&body, steps).iter().enumerate() {
        let applied = 0.95 * limit * (k + 1) as f64 / steps as f64;
        let w = -s.displacements[1].y;
        assert!(
            (von_mises_load(w) - applied).abs() <= 1e-6 * applied,
            "step {}: P(w) = {} against {applied}",
            k + 1,
            von_mises_load(w)
        );
        assert!(s.displacements[1].x.abs() <= 1e-9 * w);
        assert!(s.residual <= 1e-8);
        // Each bar carries N with 2 N sinθ = −P at the deformed angle.
        let l = (A * A + (H - w) * (H - w)).sqrt();
        let n = -applied * l / (2.0 * (H - w));
        assert!((s.axial_forces[0] - n).abs() <= 1e-6 * n.abs());
    }
}

// ---------------------------------------------------------------- exact kinematics

/// A single bar stretched to twice its length by a prescribed end displacement: engineering
/// strain ε = (2L − L)/L = 1, so N = EA (exact to 1e-12 relative), in one step or four.
#[test]
fn bar_stretched_to_twice_its_length() {
    for steps in [1, 4] {
        let l = 1.5;
        let mut body = Body::new("bar", Dimension::Two);
        body.materials.push(Material::new("rubber", 1e7, 1e-4));
        // Inclined, so the direction is exercised too.
        let dir = v(0.6, 0.8);
        body.nodes = vec![v(0.0, 0.0), dir * l];
        bar(&mut body, 0, 1, 0);
        body.supports.push(Support::fixed(0, [true, true, false]));
        body.supports.push(moved(1, [true, true, false], dir * l));
        body.kinematics = Kinematics::Large;
        let states = solve_all(&body, steps);
        let s = states.last().unwrap();
        let ea = 1e7 * 1e-4;
        assert!((s.strains[0] - 1.0).abs() <= 1e-12);
        assert!((s.axial_forces[0] - ea).abs() <= 1e-12 * ea);
        // The support at the far end pulls outward with N along the bar.
        let r = s.reactions.iter().find(|(n, _)| *n == 1).unwrap().1;
        assert!((r - dir * ea).norm() <= 1e-9 * ea);
    }
}

/// A triangulated square turned by 90° about its corner node 1 by prescribing nodes 1 and 2:
/// nodes 3 and 4 follow as a rigid body, so `large` gives zero member forces (to 1e-9 of
/// EA) and the free nodes land on their rotated places, while `linear` stretches members.
#[test]
fn rigid_rotation_by_90_degrees_causes_no_force() {
    let mut body = Body::new("square", Dimension::Two);
    body.materials.push(Material::new("steel", 200e9, 1e-4));
    body.nodes = vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)];
    for (a, b) in [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)] {
        bar(&mut body, a, b, 0);
    }
    // Rotation by +90° about node 1: p ↦ (−p_y, p_x).
    let rotated = |p: Vector3<f64>| v(-p.y, p.x);
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(moved(
        1,
        [true, true, false],
        rotated(body.nodes[1]) - body.nodes[1],
    ));
    body.kinematics = Kinematics::Large;
    let steps = 6;
    let s = solve_all(&body, steps).pop().unwrap();
    let ea = 200e9 * 1e-4;
    for (m, n) in s.axial_forces.iter().enumerate() {
        assert!(n.abs() <= 1e-9 * ea, "member {}: {n}", m + 1);
    }
    for i in 2..4 {
        let place = body.nodes[i] + s.displacements[i];
        assert!(
            (place - rotated(body.nodes[i])).norm() <= 1e-9,
            "node {}",
            i + 1
        );
    }
    body.kinematics = Kinematics::Linear;
    let linear = solve_all(&body, 1).pop().unwrap();
    let largest = linear
        .axial_forces
        .iter()
        .fold(0.0f64, |m, n| m.max(n.abs()));
    assert!(
        largest > 0.1 * ea,
        "the linear model stretches members: {largest}"
    );
}

/// A slender cantilever truss (10 × 1 cells) under a tip load large enough to bend it far:
/// the end state does not depend on how many load steps lead there (to 1e-6 of the tip
/// deflection), and Newton converges quadratically near the solution.
#[test]
fn conservative_load_is_independent_of_the_steps_and_newton_is_quadratic() {
    let body = cantilever(Kinematics::Large);
    let one = solve_all(&body, 1).pop().unwrap();
    let eight = solve_all(&body, 8).pop().unwrap();
    let tip = body.nodes.len() - 1;
    let scale = eight.displacements[tip].norm();
    let linear = solve_all(&cantilever(Kinematics::Linear), 1).pop().unwrap();
    // The load is large: linear and large kinematics differ by far more than 10 %.
    assert!((linear.displacements[tip] - eight.displacements[tip]).norm() > 0.1 * scale);
    for (a, b) in one.displacements.iter().zip(&eight.displacements) {
        assert!((a - b).norm() <= 1e-6 * scale, "{a} vs {b}");
    }

    let mut newton = NewtonEquilibrium::new(&body).unwrap();
    newton.solve_step(&body, 1, 1).unwrap();
    let r = &newton.residual_history;
    eprintln!("relative residuals of the last increment: {r:?}");
    // Quadratic: once below 1e-2, each residual is at most about the square of the one
    // before (C r², C = 100), until round-off (1e-13) is reached.
    let mut checked = 0;
    for w in r.windows(2) {
        if w[0] < 1e-2 && w[0] > 1e-7 {
            assert!(w[1] <= 100.0 * w[0] * w[0], "{:e} -> {:e}", w[0], w[1]);
            checked += 1;
        }
    }
    assert!(checked >= 1, "no iteration in the quadratic range: {r:?}");
}

/// Steps after the first start from the load path extrapolated through the states already
/// converged (a secant, then a quadratic): Newton needs fewer tangent solves than from the
/// tangent predictor at the last state, and still meets its tolerance at every step (the
/// answer's independence of the step count is checked above).
#[test]
fn later_steps_start_from_the_extrapolated_path() {
    let body = cantilever(Kinematics::Large);
    let states = solve_all(&body, 8);
    let iterations: Vec<usize> = states.iter().map(|s| s.iterations).collect();
    eprintln!("Newton iterations per step: {iterations:?}");
    for s in &states {
        assert!(s.residual <= body.newton.tolerance, "{}", s.residual);
        assert_eq!(s.cuts, 0);
    }
    // Measured [4, 4, 3, 2, 3, 3, 3, 3]; the tangent predictor alone takes 4 at every step.
    assert!(iterations[2..].iter().all(|&n| n <= 3), "{iterations:?}");
    assert!(iterations.iter().sum::<usize>() <= 26, "{iterations:?}");
}

fn cantilever(kinematics: Kinematics) -> Body {
    // Nodes: bottom row 0..=10, top row 11..=21, at 0.1 m spacing; the left end clamped.
    let (cells, h) = (10, 0.1);
    let mut body = Body::new("cantilever", Dimension::Two);
    body.materials.push(Material::new("steel", 200e9, 1e-5));
    for row in 0..2 {
        for i in 0..=cells {
            body.nodes.push(v(i as f64 * h, row as f64 * h));
        }
    }
    let top = cells + 1;
    for i in 0..cells {
        bar(&mut body, i, i + 1, 0);
        bar(&mut body, top + i, top + i + 1, 0);
        bar(&mut body, i + 1, top + i + 1, 0);
        bar(&mut body, i, top + i + 1, 0);
    }
    bar(&mut body, 0, top, 0);
    body.supports.push(Support::fixed(0, [true, true, false]));
    body.supports.push(Support::fixed(top, [true, true, false]));
    body.loads.push(load(body.nodes.len() - 1, v(0.0, -6e3)));
    body.kinematics = kinematics;
    body
}

// ---------------------------------------------------------------- cables

/// A node held by a steel bar and a cable, pushed toward the cable's anchor: the cable goes
/// slack and carries exactly no force; the bar carries the whole load. Pulled the other way,
/// the two share it by stiffness.
#[test]
fn slack_cable_carries_no_force() {
    let build = |push: f64| {
        let mut body = Body::new("guy", Dimension::Two);
        body.materials.push(Material::new("steel", 200e9, 1e-4));
        let mut cable = Material::new("cable", 200e9, 1e-4);
        cable.behaviour = Behaviour::TensionOnly;
        body.materials.push(cable);
        body.nodes = vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0)];
        bar(&mut body, 0, 1, 0);
        bar(&mut body, 1, 2, 1);
        body.supports.push(Support::fixed(0, [true, true, false]));
        body.supports.push(Support::fixed(1, [false, true, false]));
        body.supports.push(Support::fixed(2, [true, true, false]));
        body.loads.push(load(1, v(push, 0.0)));
        body
    };
    // Pushing node 2 toward node 3 stretches the bar and shortens the cable.
    for kinematics in [Kinematics::Linear, Kinematics::Large] {
        let mut body = build(1000.0);
        body.kinematics = kinematics;
        let s = solve_all(&body, 2).pop().unwrap();
        assert_eq!(
            s.axial_forces[1], 0.0,
            "{kinematics:?}: the slack cable carries nothing"
        );
        assert!(s.strains[1] < 0.0);
        assert!((s.axial_forces[0] - 1000.0).abs() <= 1e-6 * 1000.0);
        let mut body = build(-1000.0);
        body.kinematics = kinematics;
        let s = solve_all(&body, 2).pop().unwrap();
        // Pulling back: the bar is compressed and the cable stretched, equal stiffness.
        assert!(
            (s.axial_forces[1] - 500.0).abs() <= 1e-4 * 500.0,
            "{kinematics:?}: {:?}",
            s.axial_forces
        );
        assert!((s.axial_forces[0] + 500.0).abs() <= 1e-4 * 500.0);
    }
}

/// A bad arc length (negative, zero, not finite) is refused before any solve, as a
/// [`BodyError::BadValue`] naming the body, the setting and what to give instead; so are
/// prescribed support displacements, which the arc-length method cannot scale.
#[test]
fn arc_length_path_setting_is_checked() {
    for length in [-1.0, 0.0, f64::NAN, f64::INFINITY] {
        let mut body = von_mises(1.0);
        body.newton.path = PathMethod::ArcLength { length };
        let err = BodySolver::new(&body)
            .err()
            .unwrap_or_else(|| panic!("arc_length = {length} was accepted"));
        let message = err.to_string();
        match err {
            SolveError::Body(BodyError::BadValue {
                body,
                what,
                problem,
            }) => {
                assert_eq!(body, "von_mises");
                assert_eq!(what, "[bodies.path]");
                assert!(
                    problem.contains(&format!("arc_length = {length}"))
                        && problem.contains("finite positive length in m"),
                    "{problem}"
                );
            }
            other => panic!("arc_length = {length}: expected a bad value, got {other:?}"),
        }
        assert!(
            message.starts_with("body 'von_mises': [bodies.path]: arc_length = "),
            "{message}"
        );
    }
    let mut body = von_mises(1.0);
    body.newton.path = PathMethod::ArcLength { length: 0.004 };
    body.supports[0] = moved(0, [true, true, false], v(0.0, -0.01));
    let err = BodySolver::new(&body)
        .err()
        .expect("prescribed displacements with an arc-length path are refused");
    let message = err.to_string();
    assert!(
        matches!(&err, SolveError::Body(BodyError::BadValue { body, .. }) if body == "von_mises"),
        "{err:?}"
    );
    assert!(
        message.contains("prescribed support displacements are not allowed")
            && message.contains("method = \"schedules\""),
        "{message}"
    );
}

/// The arc-length method traces the whole path of the shallow two-bar truss: up to the limit
/// point, down the falling branch through zero load (the bars flat) to negative loads, and
/// back up past the inverted position. Every traced point lies on the closed-form curve to
/// 1e-6 of the limit load; the tangent has one negative pivot exactly on the falling branch;
/// and the limit load, from a parabola through the three highest points, matches the closed
/// form to 1e-6.
#[test]
fn von_mises_truss_snap_through_by_arc_length() {
    let mut body = von_mises(1.0);
    let (w_limit, limit) = von_mises_limit();
    let steps = 80;
    body.newton.path = PathMethod::ArcLength { length: 0.004 };
    let states = solve_all(&body, steps);
    let mut trace = vec![(0.0, 0.0)];
    for (k, s) in states.iter().enumerate() {
        let w = -s.displacements[1].y;
        let lambda = s.load_factor.expect("arc length reports its load factor");
        assert!(
            (lambda * limit - von_mises_load(w)).abs() <= 1e-6 * limit,
            "step {}: w = {w}, λP = {}, P(w) = {}",
            k + 1,
            lambda * limit,
            von_mises_load(w)
        );
        // Unstable exactly between the two limit points (where dP/dw < 0).
        let slope = von_mises_load(w + 1e-7) - von_mises_load(w - 1e-7);
        if slope.abs() > 1e-6 * limit {
            assert_eq!(
                s.negative_pivots,
                usize::from(slope < 0.0),
                "step {}: w = {w}",
                k + 1
            );
        }
        trace.push((w, lambda));
    }
    let last = trace.last().unwrap();
    assert!(
        last.0 > 2.0 * H,
        "traced past the inverted position: w = {}",
        last.0
    );
    assert!(
        trace.iter().any(|&(w, l)| w > H && l < -0.5),
        "the falling branch reaches negative loads"
    );
    // Limit load: traced again with a ten times shorter arc up to just past the limit, then
    // the vertex of the parabola through the first local maximum of λ and its neighbours
    // (past the inverted position λ rises again without bound).
    body.newton.path = PathMethod::ArcLength { length: 0.0004 };
    let fine = solve_all(&body, 120);
    let trace: Vec<(f64, f64)> = fine
        .iter()
        .map(|s| (-s.displacements[1].y, s.load_factor.unwrap()))
        .collect();
    let top = (1..trace.len() - 1)
        .find(|&i| trace[i].1 >= trace[i - 1].1 && trace[i].1 >= trace[i + 1].1)
        .expect("a limit point");
    let [(x0, y0), (x1, y1), (x2, y2)] = [trace[top - 1], trace[top], trace[top + 1]];
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let a = (d12 - d01) / (x2 - x0);
    let b = d01 - a * (x0 + x1);
    let w_peak = -b / (2.0 * a);
    let peak = a * w_peak * w_peak + b * w_peak + (y0 - a * x0 * x0 - b * x0);
    eprintln!("limit: traced λ = {peak:.9} at w = {w_peak:.6}; closed form 1 at w = {w_limit:.6}");
    assert!((peak - 1.0).abs() <= 1e-6, "limit load {peak} against 1");
}

/// Under load control a load beyond the limit point has no nearby equilibrium: the step that
/// passes it fails after its halvings with an error naming the body, the step and the
/// residuals; the steps before it are written and summary.json states the failure.
#[test]
fn load_beyond_the_limit_point_stops_with_the_solved_steps_kept() {
    let dir = tempfile::tempdir().unwrap();
    // 9000 N: 1.18 times the limit load (7622 N).
    let scene = common::truss_scene(dir.path(), "overload.toml", "overload", 9000.0);
    let out = dir.path().join("out");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!run.status.success());
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        stdout.contains("body 'truss': step 4 did not converge, even with its load increment cut to 1/8 of the step (3 halvings deep, the most [bodies.newton] max_cuts allows;"),
        "{stdout}"
    );
    assert!(
        stdout.contains("relative residuals of the last attempt"),
        "{stdout}"
    );
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("overload/summary.json")).unwrap()).unwrap();
    let steps = summary["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4, "steps 0 to 3 were solved");
    assert!(summary["failure"].as_str().unwrap().contains("step 4"));
    for s in &steps[1..] {
        assert_eq!(s["cuts"], 0);
        assert!(s["iterations"].as_u64().unwrap() >= 2);
    }
    let step3: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("overload/steps/0003.json")).unwrap())
            .unwrap();
    assert_eq!(step3["step"], 3);
    assert_eq!(step3["bodies"][0]["name"], "truss");
    // The apex (node 2) went down under the downward load.
    assert!(
        step3["bodies"][0]["displacements"][1][1].as_f64().unwrap() < 0.0,
        "{}",
        step3["bodies"][0]["displacements"]
    );
    assert!(!out.join("overload/steps/0004.json").exists());

    // The library says the same as a typed error: the body, the step, the halvings, the
    // residuals of the last attempt.
    let world = linkage::scene::load_scene(&scene).unwrap();
    let again = dir.path().join("again");
    let err = linkage::scene::run(&world, &again, &|| {}).expect_err("step 4 cannot be solved");
    let message = err.to_string();
    let RunError::Stopped { results, source } = err else {
        panic!("expected a run stopped after its solved steps, got {err:?}");
    };
    // No earlier results: the solved steps are the scene's folder.
    assert_eq!(results, again.join("overload"));
    match *source {
        RunError::Solve {
            scene: file,
            source:
                SolveError::NotConverged {
                    body,
                    step,
                    depth,
                    history,
                    ..
                },
        } => {
            assert_eq!(file, scene);
            assert_eq!(body, "truss");
            assert_eq!(step, 4);
            assert_eq!(depth, 3);
            assert!(!history.is_empty(), "the last attempt's residuals");
        }
        other => panic!("expected a step that did not converge, got {other:?}"),
    }
    assert!(
        message.contains("overload.toml")
            && message.contains("Use more steps")
            && message.contains("method = \"arc_length\"")
            && message.contains("the steps solved before it are in"),
        "{message}"
    );
    assert!(again.join("overload/steps/0003.json").is_file());
    assert!(!again.join("overload/steps/0004.json").exists());
}

/// A strut (compression-only) pulled carries nothing; pushed, it carries the load.
#[test]
fn compression_only_strut_carries_no_tension() {
    for (push, expect) in [(-800.0, -800.0), (800.0, 0.0)] {
        let mut body = Body::new("strut", Dimension::Two);
        body.materials.push(Material::new("steel", 200e9, 1e-4));
        let mut strut = Material::new("strut", 200e9, 1e-4);
        strut.behaviour = Behaviour::CompressionOnly;
        body.materials.push(strut);
        // Node 2 held by a strut to node 1 and a steel bar to node 3, loaded along x.
        body.nodes = vec![v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0)];
        bar(&mut body, 0, 1, 1);
        bar(&mut body, 1, 2, 0);
        body.supports.push(Support::fixed(0, [true, true, false]));
        body.supports.push(Support::fixed(1, [false, true, false]));
        body.supports.push(Support::fixed(2, [true, true, false]));
        // A push toward node 1 (−x) compresses the strut and stretches the bar equally.
        body.loads.push(load(1, v(2.0 * push, 0.0)));
        body.kinematics = Kinematics::Large;
        let s = solve_all(&body, 1).pop().unwrap();
        assert!(
            (s.axial_forces[0] - expect).abs() <= 1e-4 * 800.0,
            "{push}: {:?}",
            s.axial_forces
        );
        if expect == 0.0 {
            assert_eq!(s.axial_forces[0], 0.0);
        }
    }
}

/// The bundled snap-through scene through the scene driver: λ is reported as the step's
/// load factor, it turns negative on the falling branch, and the summary marks exactly the
/// steps between the limit points as unstable (one negative pivot).
#[test]
fn bundled_von_mises_scene_reports_load_factor_and_stability() {
    let world =
        linkage::scene::load_scene(std::path::Path::new("scenes/von_mises_truss.toml")).unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).unwrap();
    let (w_limit, _) = von_mises_limit();
    let mut unstable = 0;
    for step in 0..=world.steps {
        let (result, summary) = sim.step(step).unwrap();
        assert_eq!(result.load_factor, summary.load_factor);
        let w = -result.bodies[0].displacements[1][1];
        // Between the limit points w_limit and 2h − w_limit (by symmetry of P about w = h).
        let inside = w > w_limit + 1e-3 && w < 2.0 * H - w_limit - 1e-3;
        let outside = w < w_limit - 1e-3 || w > 2.0 * H - w_limit + 1e-3;
        if inside {
            assert_eq!(summary.negative_pivots, 1, "step {step}: w = {w}");
            unstable += 1;
        } else if outside {
            assert_eq!(summary.negative_pivots, 0, "step {step}: w = {w}");
        }
        assert_eq!(summary.cuts, 0);
    }
    assert!(unstable > 10);
}

/// New scene keys are checked like the others: the message names the file, the line or the
/// body, and what to write instead.
#[test]
fn bad_nonlinear_settings_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let here = std::env::current_dir().unwrap().join("scenes");
    let scene = |body_extra: &str, material_extra: &str| {
        let text = format!(
            "name = \"t\"\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n{material_extra}\n\
             [[bodies]]\nname = \"truss\"\nnodes = \"{}\"\nlinks = \"{}\"\n{body_extra}\n\
             [[bodies.supports]]\nnodes = [1, 3]\nfix = [\"x\", \"y\"]\n\
             [[bodies.loads]]\nnodes = [2]\nforce = [0.0, -1000.0]\n",
            here.join("von_mises.nodes").display(),
            here.join("von_mises.links").display()
        );
        let p = dir.path().join("scene.toml");
        std::fs::write(&p, text).unwrap();
        match linkage::scene::load_scene(&p) {
            Err(e) => e.to_string(),
            Ok(_) => "ok".to_string(),
        }
    };
    let e = scene("kinematics = \"huge\"", "");
    assert!(
        e.contains("scene.toml:") && e.contains("\"linear\"") && e.contains("\"large\""),
        "{e}"
    );
    let e = scene("", "behaviour = \"rope\"");
    assert!(
        e.contains("tension_only") && e.contains("compression_only"),
        "{e}"
    );
    let e = scene(
        "kinematics = \"large\"\n[bodies.path]\nmethod = \"arc_length\"",
        "",
    );
    assert!(e.contains("needs `arc_length`"), "{e}");
    let e = scene("[bodies.path]\nmethod = \"riks\"", "");
    assert!(
        e.contains("\"schedules\"") && e.contains("\"arc_length\""),
        "{e}"
    );
    let e = scene("[bodies.newton]\ntolerance = 0.0", "");
    assert!(e.contains("body 'truss'") && e.contains("tolerance"), "{e}");
    let e = scene("[bodies.newton]\nmax_iteration = 3", "");
    assert!(e.contains("unknown field"), "{e}");
    assert_eq!(
        scene("kinematics = \"large\"\n[bodies.newton]\nmax_cuts = 4", ""),
        "ok"
    );
}

/// Displacement control passes the limit point without arc length: the apex of the two-bar
/// truss pushed down 0.3 m in 30 steps (x left free); the support force at the apex follows
/// the closed-form curve through its maximum, zero and negative branch to 1e-6 of the limit
/// load.
#[test]
fn von_mises_truss_under_displacement_control() {
    let mut body = von_mises(0.0);
    body.loads.clear();
    body.supports
        .push(moved(1, [false, true, false], v(0.0, -0.3)));
    let (_, limit) = von_mises_limit();
    let steps = 30;
    for (k, s) in solve_all(&body, steps).iter().enumerate() {
        let w = 0.3 * (k + 1) as f64 / steps as f64;
        assert!((-s.displacements[1].y - w).abs() <= 1e-15);
        let push = -s.reactions.iter().find(|(n, _)| *n == 1).unwrap().1.y;
        assert!(
            (push - von_mises_load(w)).abs() <= 1e-6 * limit,
            "step {}: {push} against {}",
            k + 1,
            von_mises_load(w)
        );
    }
}

/// Loading, unloading to zero and reloading: an elastic body returns to its undeformed state
/// when the load is removed (to 1e-9 of the loaded deflection; the relative tests keep the
/// largest load carried so far as their scale, so a zero load still converges), and a
/// reloaded state equals the state reached directly (to 1e-6).
#[test]
fn unloading_returns_to_the_undeformed_state() {
    let mut body = cantilever(Kinematics::Large);
    body.loads[0].schedule = Schedule::Factors(vec![1.0, 0.0, 0.5]);
    let states = solve_all(&body, 3);
    let tip = body.nodes.len() - 1;
    let loaded = states[0].displacements[tip].norm();
    for (i, u) in states[1].displacements.iter().enumerate() {
        assert!(u.norm() <= 1e-9 * loaded, "node {}: {u}", i + 1);
    }
    assert!(states[1].residual <= 1e-8);
    body.loads[0].schedule = Schedule::Factors(vec![0.5]);
    let direct = solve_all(&body, 1).pop().unwrap();
    let scale = direct.displacements[tip].norm();
    for (a, b) in states[2].displacements.iter().zip(&direct.displacements) {
        assert!((a - b).norm() <= 1e-6 * scale);
    }
}

// ---------------------------------------------------------------- instability warnings

/// The bundled von Mises truss under load control in `dir/vm.toml`: `steps` steps to `factor`
/// times its limit load (7622 N) at the apex, following `schedule` when given, with the
/// `[bodies.path]` lines `path`.
fn von_mises_scene(
    dir: &std::path::Path,
    steps: usize,
    factor: f64,
    schedule: Option<&[f64]>,
    path: &str,
) -> std::path::PathBuf {
    let here = std::env::current_dir().unwrap().join("scenes");
    let schedule = schedule.map_or(String::new(), |s| format!("schedule = {s:?}\n"));
    let scene = dir.join("vm.toml");
    std::fs::write(
        &scene,
        format!(
            "name = \"vm\"\nsteps = {steps}\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n\
             [[bodies]]\nname = \"truss\"\nnodes = \"{}\"\nlinks = \"{}\"\nkinematics = \"large\"\n{path}\n\
             [[bodies.supports]]\nnodes = [1, 3]\nfix = [\"x\", \"y\"]\n\
             [[bodies.loads]]\nnodes = [2]\nforce = [0.0, {}]\n{schedule}",
            here.join("von_mises.nodes").display(),
            here.join("von_mises.links").display(),
            -factor * 7622.0
        ),
    )
    .unwrap();
    scene
}

/// Every step's warnings of the scene at `path`, solved step by step (step, warning).
fn warnings_of(path: &std::path::Path) -> Vec<(usize, String)> {
    let world = linkage::scene::load_scene(path).unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).unwrap();
    let mut out = Vec::new();
    for step in 0..=world.steps {
        let (_, summary) = sim.step(step).unwrap();
        out.extend(summary.warnings.into_iter().map(|w| (step, w)));
    }
    out
}

/// Under load control, 10 steps to 1.2 times the limit load: step 9 passes the limit and
/// Newton lands on the inverted branch (the apex drops from 0.03 m to 0.21 m, 21 times the
/// step before's change for the same load change). The run says so in summary.json and on the
/// command line, naming the step and the arc-length method; no other step warns.
#[test]
fn load_controlled_von_mises_truss_past_its_limit_warns() {
    let dir = tempfile::tempdir().unwrap();
    let scene = von_mises_scene(dir.path(), 10, 1.2, None, "");
    let out = dir.path().join("out");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let stdout = String::from_utf8_lossy(&run.stdout);
    let warned: Vec<&str> = stdout.lines().filter(|l| l.starts_with("warn")).collect();
    assert_eq!(warned.len(), 1, "{stdout}");
    for part in [
        "warn  vm: step 9: body 'truss': the displacements jumped",
        "snapped through past a limit point",
        "[bodies.path] method = \"arc_length\"",
    ] {
        assert!(warned[0].contains(part), "{part:?} in {}", warned[0]);
    }
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("vm/summary.json")).unwrap()).unwrap();
    for s in summary["steps"].as_array().unwrap() {
        let w = s["warnings"].as_array().map_or(0, |w| w.len());
        assert_eq!(w, usize::from(s["step"] == 9), "step {}", s["step"]);
    }
    let w9 = summary["steps"][9]["warnings"][0].as_str().unwrap();
    assert!(
        w9.starts_with("step 9: body 'truss'") && w9.contains("arc_length"),
        "{w9}"
    );
}

/// The same truss traced by the arc-length method (the bundled scene, through both limit
/// points and one negative pivot between them) is not warned about: that path is the point.
#[test]
fn arc_length_von_mises_truss_does_not_warn() {
    let warnings = warnings_of(std::path::Path::new("scenes/von_mises_truss.toml"));
    assert!(warnings.is_empty(), "{warnings:?}");
    let dir = tempfile::tempdir().unwrap();
    let scene = von_mises_scene(
        dir.path(),
        20,
        1.2,
        None,
        "[bodies.path]\nmethod = \"arc_length\"\narc_length = 0.02",
    );
    let warnings = warnings_of(&scene);
    assert!(warnings.is_empty(), "{warnings:?}");
}

/// Ordinary nonlinear paths do not warn: the truss softening up to 95 % of its limit, the
/// same truss loaded by a schedule that jumps 50 times (the displacement follows the load),
/// the stiffening cable net, and a linear scene.
#[test]
fn ordinary_nonlinear_and_linear_scenes_do_not_warn() {
    let dir = tempfile::tempdir().unwrap();
    let softening = von_mises_scene(dir.path(), 5, 0.95, None, "");
    assert!(warnings_of(&softening).is_empty());
    let jumping = von_mises_scene(dir.path(), 3, 0.6, Some(&[0.01, 0.02, 1.0]), "");
    assert!(warnings_of(&jumping).is_empty());
    for scene in ["scenes/cable_net.toml", "scenes/paper_overload.toml"] {
        let warnings = warnings_of(std::path::Path::new(scene));
        assert!(warnings.is_empty(), "{scene}: {warnings:?}");
    }
}

/// A straight two-bar column held sideways at its middle node by a soft bar (1000 N/m)
/// buckles at 500 N of compression (the bars' geometric stiffness −2P/L cancels the spring);
/// under load control it stays straight, an unstable equilibrium whose tangent has one
/// negative pivot: every step past 500 N warns, naming it.
#[test]
fn buckled_column_under_load_control_warns_of_negative_pivots() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("c.nodes"), "0 0\n1 0\n2 0\n1 1\n").unwrap();
    std::fs::write(dir.path().join("c.links"), "1 2\n2 3\n2 4 soft\n").unwrap();
    let scene = dir.path().join("c.toml");
    std::fs::write(
        &scene,
        "name = \"c\"\nsteps = 4\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n\
         [[materials]]\nname = \"soft\"\nyoungs_modulus = 1e7\narea = 1e-4\n\
         [[bodies]]\nname = \"column\"\nnodes = \"c.nodes\"\nlinks = \"c.links\"\nmaterial = \"steel\"\nkinematics = \"large\"\n\
         [[bodies.supports]]\nnodes = [1, 4]\nfix = [\"x\", \"y\"]\n\
         [[bodies.supports]]\nnodes = [3]\nfix = [\"y\"]\n\
         [[bodies.loads]]\nnodes = [3]\nforce = [-1200.0, 0.0]\n",
    )
    .unwrap();
    let warnings = warnings_of(&scene);
    // 300, 600, 900, 1200 N: steps 2 to 4 are past 500 N.
    let steps: Vec<usize> = warnings.iter().map(|(s, _)| *s).collect();
    assert_eq!(steps, [2, 3, 4], "{warnings:?}");
    for (step, w) in &warnings {
        assert!(
            w.starts_with(&format!("step {step}: body 'column': the tangent stiffness at the solved state has 1 negative pivot"))
                && w.contains("method = \"arc_length\""),
            "{w}"
        );
    }
}

/// Case 8 of issue 32, **a snap-through passed in silence**: the von Mises truss under load
/// control to twice its limit load (0.999 of it: step 5 just short of the limit point) in 10
/// steps. Step 5 ends near the limit point (apex 0.041 m down), step 6 on the far branch (0.218 m: 8.8 times the step before's change, below the
/// jump ratio of 10), every solved state stable (0 negative pivots). The tangent between the
/// two states has a negative pivot: step 6 warns that a limit point was passed within it, and
/// no other step warns. Step 6's state is the closed form's far-branch equilibrium at 1.2
/// times the limit load (to 1e-6 of the load).
#[test]
fn a_snap_through_passed_in_silence() {
    let dir = tempfile::tempdir().unwrap();
    // Twice 0.999 of the closed-form limit load (7622 N rounds it up: step 5 would be past it).
    let (w_limit, p_limit) = von_mises_limit();
    let factor = 2.0 * 0.999 * p_limit / 7622.0;
    let scene = von_mises_scene(dir.path(), 10, factor, None, "");
    let world = linkage::scene::load_scene(&scene).unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).unwrap();
    let mut warnings = Vec::new();
    let mut apex = Vec::new();
    for step in 0..=world.steps {
        let (result, summary) = sim.step(step).unwrap();
        assert_eq!(summary.negative_pivots, 0, "step {step}");
        apex.push(-result.bodies[0].displacements[1][1]);
        warnings.extend(summary.warnings.into_iter().map(|w| (step, w)));
    }
    // Step 5 just short of the limit point (apex 0.042 m down), step 6 on the far branch.
    assert!(apex[5] < w_limit && apex[5] > 0.038, "{apex:?}");
    assert!((apex[6] - 0.218).abs() < 2e-3, "{apex:?}");
    // Step 6 of 10: 0.6 of the full load, 1.2 times 0.999 of the limit load.
    let p6 = 0.6 * factor * 7622.0;
    assert!(
        (von_mises_load(apex[6]) - p6).abs() < 1e-6 * p6,
        "{} against {p6}",
        von_mises_load(apex[6])
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let (step, w) = &warnings[0];
    assert_eq!(*step, 6);
    for part in [
        "step 6: body 'truss': a limit point was passed within the step",
        "negative pivot",
        "[bodies.path] method = \"arc_length\"",
    ] {
        assert!(w.contains(part), "{part:?} in {w}");
    }
}

/// Gravity with large displacements (a pair of the table in docs/SCENES.md): a V of two bars
/// (nodes (−1, 1) and (1, 1) held, (0, 0) free, E A = 2e7 N, ρ = 7850 kg/m³) under its own
/// weight alone, about 31 N: the large-kinematics body and the linear one agree to 1e-5 of
/// the displacement (the difference is of the order of the strain, 1e-6), and both carry the
/// closed form N = (W/2)/(2 cos 45°) = W/(2√2) per bar (the free node's half of the two bars'
/// weight W), to 1e-5.
#[test]
fn a_large_body_under_its_own_weight_agrees_with_the_linear_one() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("v.nodes"), "-1 1\n1 1\n0 0\n").unwrap();
    std::fs::write(dir.path().join("v.links"), "1 3\n2 3\n").unwrap();
    let mut answers = Vec::new();
    for kinematics in ["linear", "large"] {
        let scene = dir.path().join(format!("{kinematics}.toml"));
        std::fs::write(
            &scene,
            format!(
                "name = \"v\"\nsteps = 1\ngravity = [0.0, -9.81]\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\ndensity = 7850\n\
                 [[bodies]]\nname = \"v\"\nnodes = \"v.nodes\"\nlinks = \"v.links\"\nkinematics = \"{kinematics}\"\n\
                 [[bodies.supports]]\nnodes = [1, 2]\nfix = [\"x\", \"y\"]\n"
            ),
        )
        .unwrap();
        let world = linkage::scene::load_scene(&scene).unwrap();
        let mut sim = linkage::scene::Simulation::new(&world).unwrap();
        sim.step(0).unwrap();
        let (result, _) = sim.step(1).unwrap();
        let body = &result.bodies[0];
        answers.push((body.displacements[2][1], body.axial_forces.clone()));
    }
    let weight = 2.0 * 7850.0 * 1e-4 * 2f64.sqrt() * 9.81;
    let n = weight / 2.0 / 2f64.sqrt();
    let (linear, large) = (&answers[0], &answers[1]);
    assert!(linear.0 < 0.0);
    assert!(
        (large.0 - linear.0).abs() <= 1e-5 * linear.0.abs(),
        "{answers:?}"
    );
    for forces in [&linear.1, &large.1] {
        for f in forces {
            assert!((f - n).abs() <= 1e-5 * n, "{f} against {n}");
        }
    }
}
