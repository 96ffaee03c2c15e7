//! Issue 32, contact case 2: balls prepared from a mesh (`scenes/ball.obj`, a sphere of radius
//! 0.1 m), held against each other by contact only, solved on the condensed path.
//!
//! What was found: the condensed Newton takes each contact's normal and the weights of its
//! patch's corners as fixed over an iteration, so its tangent leaves out the penalty force
//! turning with the patch and sliding over its corners, a stiffness of the order of the contact
//! force over a member's length. These rubber balls (`E A` = 1,000 N or 100 N) are pressed with
//! forces of the same order, on one or two nodes of their faceted poles, and Newton converged
//! only linearly however fresh its factor: at a rate of 0.4 for the pushed ball (18 iterations,
//! each with a new factor), at 0.92–0.97 for the pressed balls (the relative residual creeping
//! from 3e-8 to 1.3e-8 in 30 iterations, above the stall bound: the step given up at every cut).
//! Such a Newton now keeps its factor and mixes its iterates (Anderson), which fits the few
//! directions the tangent gets wrong.

use linkage::scene::{load_scene, StepResult, StepSummary};
use std::path::{Path, PathBuf};

/// Every step of the scene at `path` with its summary; panics naming the failure.
fn run(path: &Path) -> Vec<(StepResult, StepSummary)> {
    let world = load_scene(path).unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).expect("builds");
    (0..=world.steps)
        .map(|k| {
            sim.step(k)
                .unwrap_or_else(|e| panic!("{}: step {k}: {e}", path.display()))
        })
        .collect()
}

/// `scenes/ball.obj` copied into `dir`.
fn ball_obj(dir: &Path) {
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ball.obj");
    std::fs::copy(obj, dir.join("ball.obj")).unwrap();
}

/// The reported set-up: two balls of rubber (E = 1e7 Pa, A = 1e-4 m²) from `ball.obj` at a
/// spacing of `spacing` m, side by side along x and touching at the origin (their faceted
/// surfaces leave a gap of about 0.5 mm): the left one held at its far cap (x < −0.19 m), the
/// right one pushed towards it by `push` N at its far node and held sideways only, on the axes
/// across the load (its nodes on the x axis in y and z, on the y axis in z): along x only the
/// contact holds it. In `steps` steps.
fn pushed_scene(dir: &Path, name: &str, spacing: f64, push: f64, steps: usize) -> PathBuf {
    ball_obj(dir);
    let text = format!(
        r#"name = "{name}"
steps = {steps}

[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4

[[bodies]]
name = "left"
mesh = {{ file = "ball.obj", spacing = {spacing:?} }}
offset = [-0.1, 0.0, 0.0]

[[bodies.supports]]
inside = {{ min = [-1.0, -1.0, -1.0], max = [-0.19, 1.0, 1.0] }}
fix = ["x", "y", "z"]

[[bodies]]
name = "right"
mesh = {{ file = "ball.obj", spacing = {spacing:?} }}
offset = [0.1, 0.0, 0.0]

[[bodies.supports]]
on_line = {{ point = [0.1, 0.0, 0.0], direction = [1.0, 0.0, 0.0] }}
fix = ["y", "z"]

[[bodies.supports]]
on_line = {{ point = [0.1, 0.0, 0.0], direction = [0.0, 1.0, 0.0] }}
fix = ["z"]

[[bodies.loads]]
nearest = [0.2, 0.0, 0.0]
force = [{load:?}, 0.0, 0.0]

[contact]
"#,
        load = -push,
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The variant of the interrupt tests' scene, at twice its size: two balls of rubber
/// (E = 1e7 Pa, A = 1e-5 m²) from `ball.obj` at a spacing of `spacing` m, the lower centred at
/// the origin and held at its bottom cap (y < −0.09 m), the upper centred 0.2 m above it and
/// pressed `press` m down onto it by a prescribed displacement of its top cap (y > 0.29 m), in
/// `steps` steps.
fn pressed_scene(dir: &Path, name: &str, spacing: f64, press: f64, steps: usize) -> PathBuf {
    ball_obj(dir);
    let text = format!(
        r#"name = "{name}"
steps = {steps}

[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-5

[[bodies]]
name = "lower"
mesh = {{ file = "ball.obj", spacing = {spacing:?} }}

[[bodies.supports]]
inside = {{ min = [-0.2, -0.2, -0.2], max = [0.2, -0.09, 0.2] }}
fix = ["x", "y", "z"]

[[bodies]]
name = "upper"
mesh = {{ file = "ball.obj", spacing = {spacing:?} }}
offset = [0.0, 0.2, 0.0]

[[bodies.supports]]
inside = {{ min = [-0.2, 0.29, -0.2], max = [0.2, 0.4, 0.2] }}
fix = ["x", "y", "z"]
displacement = [0.0, {down:?}, 0.0]

[contact]
"#,
        down = -press,
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The sum of the contact forces on body `name` at `step`, N.
fn contact_force(step: &StepResult, name: &str) -> [f64; 3] {
    let body = step.bodies.iter().find(|b| b.name == name).unwrap();
    let mut f = [0.0; 3];
    for c in &body.contacts {
        for (a, b) in f.iter_mut().zip(&c.force) {
            *a += b;
        }
    }
    f
}

/// The sum of the support reactions of body `name` at `step`, N.
fn reaction(step: &StepResult, name: &str) -> [f64; 3] {
    let body = step.bodies.iter().find(|b| b.name == name).unwrap();
    let mut f = [0.0; 3];
    for r in &body.reactions {
        for (a, b) in f.iter_mut().zip(&r.force) {
            *a += b;
        }
    }
    f
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The checks of the pushed right ball at every step: the contact force on it along x balances
/// the push at that step (to 1e-6 of it); it is along x, its y and z parts within `sideways`
/// of it (the faceted surfaces are not symmetric about the axis: pressed lightly the contact is
/// on a tilted facet, 0.18 of the force sideways at 20 N; at 200 N, 2e-5); the left ball gets
/// the opposite force (to 1e-9 of it). Returns the Newton iterations per step.
fn assert_pushed(steps: &[(StepResult, StepSummary)], push: f64, sideways: f64) -> Vec<usize> {
    let n = steps.len() - 1;
    let mut iterations = Vec::new();
    for (step, summary) in steps.iter().skip(1) {
        let expected = push * step.step as f64 / n as f64;
        let right = contact_force(step, "right");
        let left = contact_force(step, "left");
        assert!(
            (right[0] - expected).abs() <= 1e-6 * expected,
            "step {}: contact force {right:?} N against the push {expected} N",
            step.step
        );
        assert!(
            right[1].abs().max(right[2].abs()) <= sideways * expected,
            "step {}: contact force {right:?} N is not along the push",
            step.step
        );
        let sum: Vec<f64> = (0..3).map(|q| right[q] + left[q]).collect();
        assert!(
            norm(&sum) <= 1e-9 * expected,
            "step {}: {right:?} on the right, {left:?} on the left",
            step.step
        );
        iterations.push(summary.iterations);
    }
    iterations
}

/// Issue 32, contact case 2, as reported: a ball held along its load only by contact, pushed
/// by 200 N onto another. Newton converged only linearly (rate 0.4: 18 iterations, 13 of them
/// after the contact was found, each with a new factor); now 9: two stabilised moves to the
/// contact, then a quadratic-like fall (1.6e-4, 1.9e-5, 3.6e-6, 1.8e-7, 6e-8, 1.4e-9 and below
/// the tolerance of 1e-10). At most 10 allowed. In 10 steps (each step's load is a tenth of
/// the push): 11 to 20 iterations a step before, now at most 10 after the first step (measured
/// 7–10); the first step, which finds the contact, 16 (19 before).
#[test]
fn a_ball_held_along_its_load_only_by_contact_converges_in_a_few_iterations() {
    let dir = tempfile::tempdir().unwrap();
    let steps = run(&pushed_scene(dir.path(), "pushed", 0.025, 200.0, 1));
    let iterations = assert_pushed(&steps, 200.0, 1e-4);
    assert!(iterations[0] <= 10, "{iterations:?} Newton iterations");
    let steps = run(&pushed_scene(dir.path(), "pushed10", 0.025, 200.0, 10));
    let iterations = assert_pushed(&steps, 200.0, 0.2);
    assert!(
        iterations[0] <= 18 && iterations[1..].iter().all(|&k| k <= 11),
        "{iterations:?} Newton iterations per step"
    );
}

/// Case 2's variants: a push of 20 N (16 iterations, 19 before) and a coarser mesh (spacing
/// 0.04 m: 1 cut; it did not converge before, even cut 10 times).
#[test]
fn a_ball_held_along_its_load_only_by_contact_variants_converge() {
    let dir = tempfile::tempdir().unwrap();
    let steps = run(&pushed_scene(dir.path(), "push20", 0.025, 20.0, 1));
    let iterations = assert_pushed(&steps, 20.0, 0.2);
    assert!(iterations[0] <= 18, "{iterations:?} Newton iterations");
    let steps = run(&pushed_scene(dir.path(), "coarse", 0.04, 200.0, 1));
    assert_pushed(&steps, 200.0, 0.2);
}

/// The checks of the pressed balls at every step: solved (a step Newton cannot solve is an
/// error, see `run`); the contact forces on the two balls equal and opposite (to 1e-9 of
/// them); each ball's contact force balanced by its supports' reactions (to 1e-6 of it, or of
/// 1 N before they touch: the
/// Newton tolerance is 1e-10 of the force scale, with the stall rule's 100 tolerances); the
/// contact force mostly along the press (its x and z parts within 30 % of it: the icosphere
/// has no vertex at its poles, the contact is on tilted facets, measured up to 21 % sideways).
/// Returns the vertical contact force on the upper ball per
/// step, N (positive: pushed up).
fn assert_pressed(steps: &[(StepResult, StepSummary)]) -> Vec<f64> {
    let mut pressed = Vec::new();
    for (step, _) in steps.iter().skip(1) {
        let upper = contact_force(step, "upper");
        let lower = contact_force(step, "lower");
        let size = norm(&upper);
        let sum: Vec<f64> = (0..3).map(|q| upper[q] + lower[q]).collect();
        assert!(
            norm(&sum) <= 1e-9 * size,
            "step {}: {upper:?} on the upper ball, {lower:?} on the lower",
            step.step
        );
        for (name, contact) in [("upper", upper), ("lower", lower)] {
            let r = reaction(step, name);
            let out: Vec<f64> = (0..3).map(|q| r[q] + contact[q]).collect();
            assert!(
                norm(&out) <= 1e-6 * size.max(1.0),
                "step {}: the {name} ball's supports hold {r:?} N against the contact's {contact:?} N",
                step.step
            );
        }
        if size > 0.0 {
            assert!(
                upper[0].abs().max(upper[2].abs()) <= 0.3 * upper[1],
                "step {}: contact force {upper:?} N on the upper ball",
                step.step
            );
        }
        pressed.push(upper[1]);
    }
    pressed
}

/// The pressed balls that failed (the interrupt tests' scene at twice its size): at a spacing
/// of 0.04 m pressed 20 mm in 6 steps, from step 3 on (the residual creeping 3 % per
/// iteration); pressed 16 mm in 8 steps, at step 6. Every step is solved now. The contact
/// force does not grow steadily with the press: where the touching node slides off a tilted
/// facet the balls settle on others (at 20 mm in 6 steps, step 4: the sideways part falls from
/// 1.8 N to 0.003 N while the vertical part stays at 12.2–12.3 N); 30 N at the last step.
#[test]
fn balls_pressed_onto_each_other_converge_at_every_step() {
    let dir = tempfile::tempdir().unwrap();
    for (name, spacing, press, steps, last) in [
        ("deep", 0.04, 0.02, 6, 29.9869),
        ("eight", 0.04, 0.016, 8, 19.3123),
    ] {
        let steps = run(&pressed_scene(dir.path(), name, spacing, press, steps));
        let pressed = assert_pressed(&steps);
        let end = *pressed.last().unwrap();
        assert!(
            pressed[0] > 0.0 && (end - last).abs() <= 1e-3 * last,
            "{name}: contact forces {pressed:?} N, {last} N measured at the last step"
        );
    }
}

/// The pressed balls at finer spacings: 0.035 m pressed 10 mm in 5 steps (it failed at step 4)
/// and 0.03 m pressed 12 mm in 6 steps (it failed at step 6); and a shallow press that
/// converged before and must still (0.04 m, 8 mm).
#[test]
fn balls_pressed_onto_each_other_at_finer_spacings_converge() {
    let dir = tempfile::tempdir().unwrap();
    for (name, spacing, press, steps) in [
        ("fine", 0.035, 0.01, 5),
        ("finer", 0.03, 0.012, 6),
        ("shallow", 0.04, 0.008, 6),
    ] {
        let steps = run(&pressed_scene(dir.path(), name, spacing, press, steps));
        let pressed = assert_pressed(&steps);
        assert!(
            pressed.last().is_some_and(|&f| f > 0.0),
            "{name}: contact forces {pressed:?} N"
        );
    }
}
