//! Arc length against a fixed stop (issue 32, combination 3): one large-displacement body
//! followed along its arc-length path through its limit point and onto a rigid plane, the
//! plane's penalty force and stiffness in the body's residual and tangent. Every check is
//! against the closed form, the same body's path without the stop, or equilibrium, with its
//! tolerance stated where it is used.

use linkage::linkage::{
    stop_forces, Body, Dimension, Kinematics, Material, Member, NewtonEquilibrium, NodalLoad,
    PathMethod, Schedule, StepState, Stop, Support,
};
use nalgebra::Vector3;

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
