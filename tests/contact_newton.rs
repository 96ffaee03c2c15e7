//! One Newton for bodies and contact (issue 11, item 4): contact steps cut their increments as
//! body steps do, and bodies in contact scenes may be solved by multigrid conjugate gradients.
//! Tolerances are stated where they are used.

use linkage::linkage::SolverChoice;
use linkage::scene::{build_world, load_scene, Simulation, StepResult, StepSummary, World};
use std::path::Path;

/// Solve every step of `world` in order; the results and summaries.
fn run_all(world: &World) -> Vec<(StepResult, StepSummary)> {
    let mut sim = Simulation::new(world).expect("builds");
    (0..=world.steps)
        .map(|k| sim.step(k).expect("solves"))
        .collect()
}

/// The largest difference between two results' displacements, relative to the largest
/// displacement of `b`.
fn displacement_difference(a: &StepResult, b: &StepResult) -> f64 {
    let all = |r: &StepResult| -> Vec<f64> {
        r.bodies
            .iter()
            .flat_map(|b| b.displacements.iter().flatten().copied())
            .collect()
    };
    let (x, y) = (all(a), all(b));
    let largest = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    x.iter()
        .zip(&y)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / largest
}

/// The total contact force on every body, N, summed over its contacts.
fn total_contact_force(result: &StepResult) -> Vec<[f64; 3]> {
    result
        .bodies
        .iter()
        .map(|b| {
            let mut sum = [0.0; 3];
            for c in &b.contacts {
                for (k, f) in c.force.iter().enumerate() {
                    sum[k] += f;
                }
            }
            sum
        })
        .collect()
}

/// The largest difference of the total contact forces, relative to the largest component.
fn force_difference(a: &StepResult, b: &StepResult) -> f64 {
    let (fa, fb) = (total_contact_force(a), total_contact_force(b));
    let largest = fb.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    fa.iter()
        .flatten()
        .zip(fb.iter().flatten())
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / largest
}

/// A rubber block with large displacements, pressed 4 cm (20% of its height) by a flat plate
/// (a half-space facing down: its penalty tangent is exact, so Newton converges
/// quadratically) that travels down in `steps` steps, with `newton` the `[bodies.newton]`
/// table.
fn pressed_block(steps: usize, newton: &str) -> String {
    format!(
        r#"
name = "pressed_block"
steps = {steps}
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "block"
rectangle = {{ width = 0.6, height = 0.2, cells = [24, 8] }}
kinematics = "large"
[bodies.newton]
{newton}
[[bodies.supports]]
on_line = {{ point = [0.0, 0.0], direction = [1.0, 0.0] }}
fix = ["x", "y"]
[[obstacles]]
name = "plate"
shape = "half_space"
point = [0.0, 0.2]
normal = [0.0, -1.0]
travel = [0.0, -0.04]
"#
    )
}

/// The press in one step with 3 Newton iterations per increment cannot be done at once: the
/// step is cut (cuts > 0), and its answer is that of the same press in 16 steps (frictionless
/// elastic contact does not depend on the path) to 1e-7 of the largest displacement and of
/// the total contact force.
#[test]
fn a_contact_step_too_large_for_one_newton_is_cut_and_matches_many_steps() {
    let one = build_world(
        &pressed_block(1, "max_iterations = 3"),
        Path::new("pressed_block.toml"),
    )
    .unwrap();
    let many = build_world(&pressed_block(16, ""), Path::new("pressed_block.toml")).unwrap();
    let cut = run_all(&one);
    let (last, summary) = cut.last().unwrap();
    assert!(summary.cuts > 0, "{summary:?}");
    let reference = run_all(&many);
    let (expected, reference_summary) = reference.last().unwrap();
    assert_eq!(reference_summary.cuts, 0, "{reference_summary:?}");
    assert!(!last.bodies[0].contacts.is_empty());
    let du = displacement_difference(last, expected);
    let df = force_difference(last, expected);
    println!(
        "cuts {} (iterations {}), displacement difference {du:e}, force difference {df:e}",
        summary.cuts, summary.iterations
    );
    assert!(du <= 1e-7, "{du:e}");
    assert!(df <= 1e-7, "{df:e}");
}

/// With one Newton iteration per increment and one halving allowed, the press cannot be done:
/// the error says how far the increment was cut.
#[test]
fn a_contact_step_that_cannot_be_cut_enough_reports_the_depth() {
    let world = build_world(
        &pressed_block(1, "max_iterations = 1\nmax_cuts = 1"),
        Path::new("pressed_block.toml"),
    )
    .unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    sim.step(0).unwrap();
    let message = match sim.step(1) {
        Ok((_, summary)) => panic!("solved: {summary:?}"),
        Err(e) => e.to_string(),
    };
    assert!(
        message.contains("step 1: equilibrium with contact did not converge, even with its increment cut to 1/2 of the step (1 halvings deep, the most [bodies.newton] max_cuts allows;"),
        "{message}"
    );
}

/// A 3D box lattice (`cells`) on a fixed floor pressed by a ball, all of it linear.
fn ball_on_box(cells: [usize; 3], solver: &str) -> String {
    format!(
        r#"
name = "ball_on_box"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "box"
box_lattice = {{ size = [0.4, 0.1, 0.4], cells = [{}, {}, {}] }}
solver = "{solver}"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[obstacles]]
name = "ball"
shape = "ball"
center = [0.2, 0.25, 0.2]
radius = 0.15
travel = [0.0, -0.006, 0.0]
"#,
        cells[0], cells[1], cells[2]
    )
}

/// A box lattice of 1,445 nodes pressed by a ball, solved by multigrid conjugate gradients,
/// agrees with the direct solver (condensed, and coupled) to 1e-6 of the largest displacement
/// and of the total contact force at every step; the sizes and the summary say "iterative"
/// and count conjugate-gradient iterations.
#[test]
fn a_box_pressed_by_a_ball_solved_iteratively_agrees_with_direct() {
    let cells = [16, 4, 16];
    let path = Path::new("ball_on_box.toml");
    let iterative = build_world(&ball_on_box(cells, "iterative"), path).unwrap();
    let sim = Simulation::new(&iterative).unwrap();
    assert_eq!(sim.sizes()[0].solver, "iterative");
    assert!(!sim.contact().unwrap().is_condensed());
    drop(sim);
    let direct = build_world(&ball_on_box(cells, "direct"), path).unwrap();
    assert_eq!(
        Simulation::new(&direct).unwrap().sizes()[0].solver,
        "direct"
    );
    let mut coupled = direct.clone();
    coupled.contact.condense = false;
    let a = run_all(&iterative);
    for reference in [run_all(&direct), run_all(&coupled)] {
        for ((x, sx), (y, _)) in a.iter().zip(&reference).skip(1) {
            assert!(!x.bodies[0].contacts.is_empty());
            let du = displacement_difference(x, y);
            let df = force_difference(x, y);
            println!(
                "step {}: {} CG iterations, displacement difference {du:e}, force difference {df:e}",
                x.step, sx.linear_iterations
            );
            assert!(sx.linear_iterations > 0, "{sx:?}");
            assert!(du <= 1e-6 && df <= 1e-6, "step {}: {du:e} {df:e}", x.step);
        }
    }
}

/// The bundled two_disks scene (each disk held sideways only by the other) with the left disk
/// solved iteratively agrees with the direct coupled solve to 1e-6 of the largest displacement
/// and of the contact forces; the sizes name each body's solver.
#[test]
fn two_disks_with_one_iterative_body_agree_with_direct() {
    let direct = load_scene(Path::new("scenes/two_disks.toml")).unwrap();
    let mut mixed = direct.clone();
    mixed.bodies[0].solver.choice = SolverChoice::Iterative;
    let sim = Simulation::new(&mixed).unwrap();
    let solvers: Vec<String> = sim.sizes().into_iter().map(|s| s.solver).collect();
    assert_eq!(solvers, ["iterative", "direct"]);
    drop(sim);
    let mut coupled = direct.clone();
    coupled.contact.condense = false;
    let a = run_all(&mixed);
    let b = run_all(&coupled);
    for ((x, sx), (y, _)) in a.iter().zip(&b).skip(1) {
        let du = displacement_difference(x, y);
        let df = force_difference(x, y);
        println!(
            "step {}: {} CG iterations, displacement difference {du:e}, force difference {df:e}",
            x.step, sx.linear_iterations
        );
        assert!(du <= 1e-6 && df <= 1e-6, "step {}: {du:e} {df:e}", x.step);
    }
}

/// A slender 2D lattice column (1 m × 2 cm, 50 cells) with large displacements, its foot
/// fixed, pressed `travel` m down by a flat plate on its top.
fn pressed_column(travel: f64) -> String {
    format!(
        r#"
name = "pressed_column"
steps = 1
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "column"
rectangle = {{ width = 0.02, height = 1.0, cells = [1, 50] }}
kinematics = "large"
[[bodies.supports]]
on_line = {{ point = [0.0, 0.0], direction = [1.0, 0.0] }}
fix = ["x", "y"]
[[obstacles]]
name = "plate"
shape = "half_space"
point = [0.0, 1.0]
normal = [0.0, -1.0]
travel = [0.0, -{travel}]
"#
    )
}

/// The column pressed beyond its buckling load stays straight (the symmetric path Newton
/// follows) with an indefinite tangent: it is factored by LDLᵀ and its negative pivot counted
/// (1 at 2 mm; none at 0.5 mm, below the buckling load), and the plate's force balances the
/// reaction at the foot to 1e-8.
#[test]
fn a_column_buckling_under_contact_counts_its_negative_pivot() {
    for (travel, negative) in [(0.0005, 0), (0.002, 1)] {
        let world = build_world(&pressed_column(travel), Path::new("pressed_column.toml")).unwrap();
        let steps = run_all(&world);
        let (result, summary) = steps.last().unwrap();
        assert_eq!(summary.negative_pivots, negative, "{travel}: {summary:?}");
        let body = &result.bodies[0];
        let contact: f64 = body.contacts.iter().map(|c| c.force[1]).sum();
        let reaction: f64 = body.reactions.iter().map(|r| r.force[1]).sum();
        assert!(contact < 0.0, "{contact}");
        assert!(
            (contact + reaction).abs() <= 1e-8 * contact.abs(),
            "{contact} {reaction}"
        );
    }
}

/// The large-displacement press of `pressed_block` solved iteratively agrees with the direct
/// solve to 1e-6 of the largest displacement and of the contact force.
#[test]
fn a_nonlinear_body_in_contact_solved_iteratively_agrees_with_direct() {
    let scene = pressed_block(4, "");
    let direct = build_world(&scene, Path::new("pressed_block.toml")).unwrap();
    let iterative = build_world(
        &scene.replace(
            "kinematics = \"large\"",
            "kinematics = \"large\"\nsolver = \"iterative\"",
        ),
        Path::new("pressed_block.toml"),
    )
    .unwrap();
    assert_eq!(
        Simulation::new(&iterative).unwrap().sizes()[0].solver,
        "iterative"
    );
    let a = run_all(&iterative);
    let b = run_all(&direct);
    for ((x, sx), (y, _)) in a.iter().zip(&b).skip(1) {
        let du = displacement_difference(x, y);
        let df = force_difference(x, y);
        println!(
            "step {}: {} CG iterations, displacement difference {du:e}, force difference {df:e}",
            x.step, sx.linear_iterations
        );
        assert!(sx.linear_iterations > 0);
        assert!(du <= 1e-6 && df <= 1e-6, "step {}: {du:e} {df:e}", x.step);
    }
}
