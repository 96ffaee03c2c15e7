//! Contact set-ups that must converge where users put them (issue 32, contact cases 1 and 2).
//! The test here checks the tilted floor's contact normals; case 1 itself is NOT fixed yet,
//! and has no test until it is (`block_scene` below writes case 1's block, at
//! any angle, placement and number of steps). What was found:
//!
//! Case 1 (a block on a floor tilted 20°, μ = 0.4, its own weight, 2 steps) stalled, and is
//! fixed (`a_block_on_a_tilted_floor_below_its_sliding_angle_sticks`). Three causes:
//! - The block starts touching nothing (its nodes lie on the floor to round-off, below the
//!   depth that counts as inside), so it is moved by stabilised steps. Once the increment was
//!   cut small, the stabilised correction was below the move cap and taken as a Newton step
//!   with the (empty) contact set fixed: a rigid move cannot reduce that residual, so it stayed
//!   at 0.93. Now a stabilised correction whose line search finds no decrease ends the Newton,
//!   and the contacts are looked for again.
//! - The condensed path could not factor its contacts ("not positive definite"): the inertia
//!   relief of a body with several free rigid motions paired each motion with every other's
//!   `K⁻¹ q`, which left the compliance indefinite (the answers were right, as the error lay
//!   along the rigid motions, but the contact matrix could not be factored). It fell back to
//!   the coupled path, which does not hold contacts flipping between stick and slip.
//! - Newton then stalled at 1.1e-8 of the weight, just above 100 tolerances: the round-off of
//!   coordinates 0.22 m from the origin in penalties of 3.1e10 N/m. A stall below that
//!   round-off (`round_off_residual`) now counts as converged.
//! - (Earlier) a half-space's contact normal came from the direction to the nearest point,
//!   off by 1e-7 of a turn at a depth of 1e-10 m on a tilted floor (fixed: the plane's own
//!   normal, checked below).
//!
//! Case 2 (two balls from `scenes/ball.obj`, the right one pushed by 200 N, held sideways only)
//! and the pressed balls close to it are in tests/contact_balls.rs: the condensed Newton
//! converged only linearly there (its tangent leaves out the normals' turning), and now mixes
//! its iterates when it does.

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

/// Issue 32, contact case 1: a block resting on a floor tilted 20°, μ = 0.4, under its own
/// weight sticks (tan 20° = 0.364 < μ). It stalled at a relative residual of 0.93 at every cut
/// (its nodes start on the floor to round-off, so no contact held it and the stabilised move
/// was taken as a Newton step with the empty set), then, once let down onto the floor, at
/// 1.1e-8 (the round-off of its coordinates in the penalties), and the condensed path could
/// not factor its contacts (its compliance was indefinite with three free rigid motions).
/// Every variant solves at every step: other angles below atan μ, more steps, coordinates
/// written with 6 digits, the block lifted 0.3 µm, and the coupled path. Each carries its
/// weight (1e-7), and its displacements turned back agree with the same physics turned
/// (gravity tilted instead of the floor) to 1e-3 of the largest (the penalties' round-off
/// floor is 1e-8 of the load).
#[test]
fn a_block_on_a_tilted_floor_below_its_sliding_angle_sticks() {
    let dir = tempfile::tempdir().unwrap();
    let variants: [(f64, usize, Option<usize>, f64, bool); 8] = [
        (20.0, 2, None, 0.0, true),
        (20.0, 5, None, 0.0, true),
        (5.0, 3, None, 0.0, true),
        (15.0, 2, None, 0.0, true),
        (21.0, 2, None, 0.0, true),
        (20.0, 2, Some(6), 0.0, true),
        (20.0, 2, None, 3e-7, true),
        (20.0, 2, None, 0.0, false),
    ];
    // Beyond atan μ = 21.8° it slides, and is told so.
    let steep = Placement {
        angle: Some(23.0),
        digits: None,
        lift: 0.0,
    };
    let world = load_scene(&block_scene(dir.path(), "steep", 23.0, &steep, 2)).unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).expect("builds");
    sim.step(0).unwrap();
    let told = sim.step(1).map(|_| ()).unwrap_err().to_string();
    assert!(told.contains("slides"), "{told}");
    for (k, &(angle, steps, digits, lift, condense)) in variants.iter().enumerate() {
        let what = format!(
            "{angle}° in {steps} steps, digits {digits:?}, lift {lift} m, condense {condense}"
        );
        let tilted = Placement {
            angle: Some(angle),
            digits,
            lift,
        };
        let path = block_scene(dir.path(), &format!("tilted{k}"), angle, &tilted, steps);
        if !condense {
            let text = std::fs::read_to_string(&path).unwrap();
            std::fs::write(
                &path,
                text.replace("[contact]\n", "[contact]\ncondense = false\n"),
            )
            .unwrap();
        }
        let turned = Placement {
            angle: None,
            digits: None,
            lift: 0.0,
        };
        let reference = run(&block_scene(
            dir.path(),
            &format!("turned{k}"),
            angle,
            &turned,
            steps,
        ));
        let steps_run = run(&path);
        let (s, c) = angle.to_radians().sin_cos();
        for (step, ((r, _), (reference, _))) in steps_run.iter().zip(&reference).enumerate().skip(1)
        {
            let (w, f) = weight_and_contact(r);
            let sum: Vec<f64> = (0..3).map(|q| w[q] + f[q]).collect();
            assert!(
                norm(&sum) <= 1e-7 * norm(&w),
                "{what}, step {step}: {f:?} against {w:?}"
            );
            // Along the floor, the contacts carry W sin θ; across it, W cos θ.
            let along = f[0] * c + f[1] * s;
            let across = -f[0] * s + f[1] * c;
            let weight = norm(&w);
            assert!(
                (along - weight * s).abs() <= 1e-7 * weight,
                "{what}: along {along}"
            );
            assert!(
                (across - weight * c).abs() <= 1e-7 * weight,
                "{what}: across {across}"
            );
            // The displacements, turned back to the floor's frame, are the turned physics'.
            let mine = &r.bodies[0].displacements;
            let theirs = &reference.bodies[0].displacements;
            let largest = theirs.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
            let worst = mine
                .iter()
                .zip(theirs)
                .map(|(u, v)| {
                    let back = [u[0] * c + u[1] * s, -u[0] * s + u[1] * c, u[2]];
                    let d: Vec<f64> = (0..3).map(|q| back[q] - v[q]).collect();
                    norm(&d)
                })
                .fold(0.0, f64::max);
            // Coordinates written with d digits start off by up to half a unit of the d-th
            // digit of 0.22 m, which the block takes up as it settles.
            let written = digits.map_or(0.0, |d| 0.5 * 10f64.powi(1 - d as i32) * 0.22);
            // It sticks: it moves no more than its members and the contacts' stick
            // stiffness let it (7.4e-9 m at 20°, half its weight).
            assert!(
                largest < 1e-7 + lift + written,
                "{what}: moved {largest:e} m"
            );
            assert!(
                largest > 0.0 && worst <= 1e-3 * largest + lift + written,
                "{what}, step {step}: off by {worst:e} of {largest:e}"
            );
        }
    }
}
