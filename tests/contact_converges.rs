//! Contact set-ups that must converge where users put them (issue 32, contact cases 1 and 2),
//! each reproduced as the issue describes it and checked with numbers.
//!
//! Case 1 (a block on a floor tilted 20°, μ = 0.4, its own weight) is reproduced here and NOT
//! fixed yet; its tests are ignored until it is. What was found:
//! - The block starts touching nothing (its nodes lie on the floor to round-off, below the
//!   depth that counts as inside), so its tangent is singular and it is moved by stabilised
//!   steps. Once the increment is cut small, the stabilised correction is smaller than the move
//!   cap and is taken as a Newton step with the (empty) contact set fixed: a rigid move cannot
//!   reduce that residual, so it stays at 0.93 (the weight's share in the free rigid motions)
//!   for all 30 iterations and at every cut.
//! - A half-space's contact normal came from the direction to the nearest point, which at a
//!   depth of 1e-10 m carries the coordinates' round-off as 1e-7 of a turn on a tilted floor
//!   (fixed: the plane's own normal, checked below).
//! - Moving such a body only until it first touches (tried: halving the stabilised move to the
//!   first new contact, and measuring friction's slip from there) removes the 0.93 stall, but
//!   the coupled Newton then stalls at a relative residual of 1e-5 (contacts flipping between
//!   stick and slip; the condensed path's holding of such contacts is not on the coupled path),
//!   and landing within an ordinary Newton step changed `two_disks` (it broke its symmetry), so
//!   it is not in.
//!
//! Case 2 (two balls from `scenes/ball.obj`, the right one pushed by 200 N, held sideways only)
//! did not fail as set up here (the left ball held at its far cap, the right one on the axes
//! across the load): it converges with the contact force at 200 N, in 18 Newton iterations;
//! supports that leave the right ball's rotations free make it a mechanism (case 3). Its tests
//! are ignored until the reported set-up is known. A close set-up does fail: two balls of
//! `ball.obj`'s kind, each held at its far cap, the upper pressed 4–10 mm onto the lower by a
//! prescribed displacement (tests/interrupts.rs's scene, spacing 0.007–0.02 m): from step 3 or
//! 4 on, at every cut, the relative residual falls to about 3e-8 in one iteration and then
//! creeps down 3 % per iteration (1.3e-8 after 30), above the stall bound (100 tolerances,
//! 1e-8), so the step is given up.

use linkage::linkage::generators::box_lattice;
use linkage::scene::{load_scene, StepResult, StepSummary};
use std::path::{Path, PathBuf};

/// A block's contact normals on a half-space tilted 20° are the floor's own normal to round-off
/// (they came from the direction to the nearest point, off by 1e-7 at a depth of 1e-10 m). The
/// block is solved in one step, as it converged before.
#[test]
fn a_tilted_floor_presses_along_its_own_normal() {
    let dir = tempfile::tempdir().unwrap();
    let tilted = Placement {
        angle: Some(20.0),
        digits: None,
        lift: 0.0,
    };
    let steps = run(&block_scene(dir.path(), "tilted", 20.0, &tilted, 1));
    let (s, c) = 20f64.to_radians().sin_cos();
    let body = &steps[1].0.bodies[0];
    assert!(!body.contacts.is_empty());
    let mut worst: f64 = 0.0;
    for contact in &body.contacts {
        let n = &contact.normal;
        worst = worst.max(((n[0] + s).powi(2) + (n[1] - c).powi(2) + n[2].powi(2)).sqrt());
    }
    assert!(worst < 1e-15, "a normal off by {worst:e}");
    // The weight is carried, to 1e-7 of it (measured 2e-9: the step's Newton stops at a
    // relative residual of 1e-8 here, within its stall rule).
    let (w, f) = weight_and_contact(&steps[1].0);
    let sum: Vec<f64> = (0..3).map(|q| w[q] + f[q]).collect();
    assert!(norm(&sum) <= 1e-7 * norm(&w), "{f:?} against {w:?}");
}

/// Standard gravity of the scenes, m/s².
const G: f64 = 9.81;
/// Friction coefficient of the block on its floor.
const MU: f64 = 0.4;

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

/// How a block's nodes are written: rotated by `angle` degrees about z (`None`: as generated),
/// with `digits` significant digits (`None`: every digit), moved `lift` m along the floor's
/// outward normal.
struct Placement {
    angle: Option<f64>,
    digits: Option<usize>,
    lift: f64,
}

/// A 0.2 × 0.1 × 0.1 m steel `box_lattice` of 4 × 2 × 2 cells (density 7850: 153.7 N) on a
/// half-space through the origin, held in z only (a slice: it rests on the floor, friction
/// μ = 0.4 holds it along), in `steps` steps. With `placement.angle = Some(θ)` the block's
/// nodes are turned by θ about z and the floor's normal with them, gravity pointing down
/// (the issue's case); with `None` the floor is y = 0 and gravity is turned by −`slope`
/// degrees instead (the same physics, turned back).
fn block_scene(dir: &Path, name: &str, slope: f64, placement: &Placement, steps: usize) -> PathBuf {
    let geometry = box_lattice([0.2, 0.1, 0.1], [4, 2, 2]).unwrap();
    let turn = placement.angle.unwrap_or(0.0).to_radians();
    let (s, c) = turn.sin_cos();
    let normal = [-s, c];
    let write = |v: f64| match placement.digits {
        Some(d) => format!("{:.*e}", d - 1, v),
        None => format!("{v:?}"),
    };
    let nodes: String = geometry
        .nodes
        .iter()
        .map(|p| {
            let x = p.x * c - p.y * s + placement.lift * normal[0];
            let y = p.x * s + p.y * c + placement.lift * normal[1];
            format!("{} {} {}\n", write(x), write(y), write(p.z))
        })
        .collect();
    let links: String = geometry
        .members
        .iter()
        .map(|[a, b]| format!("{} {}\n", a + 1, b + 1))
        .collect();
    let patches: String = geometry
        .patches
        .iter()
        .map(|[a, b, c]| format!("{} {} {}\n", a + 1, b + 1, c + 1))
        .collect();
    std::fs::write(dir.join(format!("{name}.nodes")), nodes).unwrap();
    std::fs::write(dir.join(format!("{name}.links")), links).unwrap();
    std::fs::write(dir.join(format!("{name}.patches")), patches).unwrap();
    let gravity = match placement.angle {
        Some(_) => [0.0, -G],
        None => {
            let t = slope.to_radians();
            [-G * t.sin(), -G * t.cos()]
        }
    };
    let text = format!(
        r#"name = "{name}"
steps = {steps}
gravity = [{gx:?}, {gy:?}, 0.0]

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
density = 7850.0

[[bodies]]
name = "block"
nodes = "{name}.nodes"
links = "{name}.links"
patches = "{name}.patches"

[[bodies.supports]]
inside = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0] }}
fix = ["z"]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0, 0.0]
normal = [{nx:?}, {ny:?}, 0.0]

[contact]
friction = {MU:?}
"#,
        gx = gravity[0],
        gy = gravity[1],
        nx = normal[0],
        ny = normal[1],
    );
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The total applied load (the block's weight) and contact force on the block at a step, N.
fn weight_and_contact(step: &StepResult) -> ([f64; 3], [f64; 3]) {
    let body = &step.bodies[0];
    let mut w = [0.0; 3];
    for l in &body.loads {
        for (a, b) in w.iter_mut().zip(&l.force) {
            *a += b;
        }
    }
    let mut f = [0.0; 3];
    for cf in &body.contacts {
        for (a, b) in f.iter_mut().zip(&cf.force) {
            *a += b;
        }
    }
    (w, f)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// The checks of a block at rest on its slope at every step of `steps`: the contacts carry
/// the weight (to 1e-6 of it), their tangential part is below μ times their normal part,
/// and the nodes on the floor moved along the slope by no more than the elastic slip of the
/// most loaded contact, μ f_N / k_t, a few times over (the contacts near the block's ends
/// slip a little: the block's own shear; sliding would be unbounded). Returns the largest
/// displacement along the slope of a node on the floor, m, at the last step.
fn assert_sticks(steps: &[(StepResult, StepSummary)], slope_deg: f64, frame: f64) -> f64 {
    let t = frame.to_radians();
    // Slope direction (up) and outward normal of the floor, in the scene's frame.
    let (along, normal) = ([t.cos(), t.sin(), 0.0], [-t.sin(), t.cos(), 0.0]);
    let mut largest = 0.0;
    for (step, summary) in steps.iter().skip(1) {
        let (w, f) = weight_and_contact(step);
        let sum: Vec<f64> = (0..3).map(|q| w[q] + f[q]).collect();
        assert!(
            norm(&sum) <= 1e-6 * norm(&w),
            "step {}: contact {f:?} against the weight {w:?}",
            step.step
        );
        // The weight's part along the slope over its part into it is tan θ < μ.
        let fa: f64 = (0..3).map(|q| f[q] * along[q]).sum();
        let fnn: f64 = (0..3).map(|q| f[q] * normal[q]).sum();
        let ratio = fa.abs() / fnn;
        assert!(
            (ratio - slope_deg.to_radians().tan()).abs() < 1e-6,
            "step {}: tangential over normal {ratio}",
            step.step
        );
        assert!(summary.sticking > 0, "step {}: nothing sticks", step.step);
        let body = &step.bodies[0];
        // Penalty k = f_N / depth (the stick stiffness is the penalty by default).
        let limit = body
            .contacts
            .iter()
            .filter(|c| c.depth > 0.0)
            .map(|c| MU * c.depth)
            .fold(0.0, f64::max);
        largest = body
            .contacts
            .iter()
            .map(|c| {
                let u = &body.displacements[c.node - 1];
                (0..3).map(|q| u[q] * along[q]).sum::<f64>().abs()
            })
            .fold(0.0, f64::max);
        assert!(
            largest <= 5.0 * limit,
            "step {}: a node on the floor moved {largest:e} m along the slope, the elastic slip is {limit:e} m",
            step.step
        );
    }
    largest
}

/// Issue 32 contact case 1, as reported: a steel box lattice resting on a half-space tilted
/// 20°, μ = 0.4 (tan 20° = 0.364 < μ), under its own weight, in 2 steps. It did not
/// converge (the relative residual stuck at 0.93 through 30 iterations and every cut). It
/// sticks: the answer is that of the same block on a level floor under gravity turned by
/// −20°, turned by 20° (to 1e-6 of the largest displacement).
///
/// Not fixed yet (see the module doc): ignored until it is.
#[test]
#[ignore = "issue 32 contact case 1 is not fixed yet: the run stalls (see the module doc)"]
fn block_on_a_tilted_floor_with_friction_below_its_sliding_angle() {
    let dir = tempfile::tempdir().unwrap();
    let tilted = Placement {
        angle: Some(20.0),
        digits: None,
        lift: 0.0,
    };
    let level = Placement {
        angle: None,
        digits: None,
        lift: 0.0,
    };
    let a = run(&block_scene(dir.path(), "tilted", 20.0, &tilted, 2));
    let b = run(&block_scene(dir.path(), "level", 20.0, &level, 2));
    assert_sticks(&a, 20.0, 20.0);
    assert_sticks(&b, 20.0, 0.0);
    let (s, c) = 20f64.to_radians().sin_cos();
    for ((sa, _), (sb, _)) in a.iter().zip(&b).skip(1) {
        let (ua, ub) = (&sa.bodies[0].displacements, &sb.bodies[0].displacements);
        let scale = ub.iter().map(|u| norm(u.as_slice())).fold(0.0, f64::max);
        assert!(scale > 0.0);
        for (n, (x, y)) in ua.iter().zip(ub).enumerate() {
            let turned = [y[0] * c - y[1] * s, y[0] * s + y[1] * c, y[2]];
            let d: Vec<f64> = (0..3).map(|q| x[q] - turned[q]).collect();
            assert!(
                norm(&d) <= 1e-6 * scale,
                "step {} node {}: {x:?} tilted, {turned:?} turned from level",
                sa.step,
                n + 1
            );
        }
    }
}

/// Case 1's variants: other angles below atan μ = 21.8°, node coordinates written with 6
/// digits (the nodes then sit up to 5e-7 m off the floor, either side), and the block lifted
/// 0.3 µm above it; in 1, 2 and 4 steps. Each sticks and balances its weight.
#[test]
#[ignore = "issue 32 contact case 1 is not fixed yet: the run stalls (see the module doc)"]
fn block_on_a_tilted_floor_variants_stick() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (10.0, None, 0.0, 2),
        (15.0, None, 0.0, 4),
        (21.0, None, 0.0, 2),
        (20.0, None, 0.0, 1),
        (20.0, Some(6), 0.0, 2),
        (20.0, None, 3e-7, 2),
        (20.0, None, 3e-7, 1),
    ];
    for (k, &(angle, digits, lift, steps)) in cases.iter().enumerate() {
        let placement = Placement {
            angle: Some(angle),
            digits,
            lift,
        };
        let name = format!("variant{k}");
        let steps = run(&block_scene(dir.path(), &name, angle, &placement, steps));
        let moved = assert_sticks(&steps, angle, angle);
        eprintln!(
            "{name}: {angle}° digits {digits:?} lift {lift:e}: largest slip along {moved:e} m"
        );
    }
}

/// Two balls of radius 0.1 m prepared from `scenes/ball.obj` (`mesh` bodies of `spacing`),
/// side by side along x touching at the origin (their faceted surfaces leave a gap of about
/// 0.5 mm): the left one held at its far cap (x < −0.19 m), the right one pushed towards it
/// by `push` N at its far node and held sideways only, on the axes across the load (its
/// nodes on the x axis in y and z, on the y axis in z): along x only the contact holds it.
fn balls_scene(dir: &Path, name: &str, spacing: f64, push: f64, steps: usize) -> PathBuf {
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ball.obj");
    std::fs::copy(obj, dir.join("ball.obj")).unwrap();
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

/// The checks of the pushed ball at every step: the contact force on it along x balances the
/// push at that step (to 1e-6), and Newton needed at most `most` iterations per step.
fn assert_pushed(steps: &[(StepResult, StepSummary)], push: f64, most: usize) {
    let n = steps.len() - 1;
    for (step, summary) in steps.iter().skip(1) {
        let expected = push * step.step as f64 / n as f64;
        let right = step.bodies.iter().find(|b| b.name == "right").unwrap();
        let fx: f64 = right.contacts.iter().map(|c| c.force[0]).sum();
        assert!(
            (fx - expected).abs() <= 1e-6 * expected,
            "step {}: contact force {fx} N along x against the push {expected} N",
            step.step
        );
        assert!(
            summary.iterations <= most,
            "step {}: {} Newton iterations ({} contact iterations)",
            step.step,
            summary.iterations,
            summary.contact_iterations
        );
    }
}

/// Issue 32, contact case 2: a body held along its load only by contact, two balls from a
/// mesh, the right one pushed by 200 N: it did not converge in 30 iterations (the residual
/// grew for 17, then fell quadratically), and in 10 steps gave no result in 90 s. It lands on
/// the other ball and converges in a few iterations, with a contact force of 200 N.
#[test]
#[ignore = "issue 32 contact case 2: not reproduced as described, and 18 iterations today (see the module doc)"]
fn a_body_held_along_its_load_only_by_contact() {
    let dir = tempfile::tempdir().unwrap();
    let steps = run(&balls_scene(dir.path(), "balls", 0.025, 200.0, 1));
    assert_pushed(&steps, 200.0, 12);
    let steps = run(&balls_scene(dir.path(), "balls10", 0.025, 200.0, 10));
    assert_pushed(&steps, 200.0, 12);
}

/// Case 2's variants: another push (20 N, 800 N) and another spacing (0.02, 0.04 m).
#[test]
#[ignore = "issue 32 contact case 2: not reproduced as described (see the module doc)"]
fn a_body_held_along_its_load_only_by_contact_variants() {
    let dir = tempfile::tempdir().unwrap();
    for (k, &(spacing, push)) in [(0.025, 20.0), (0.025, 800.0), (0.02, 200.0), (0.04, 200.0)]
        .iter()
        .enumerate()
    {
        let steps = run(&balls_scene(dir.path(), &format!("v{k}"), spacing, push, 1));
        assert_pushed(&steps, push, 12);
    }
}
