//! The condensed contact path cuts its own increments (issue 32, combination 2): a linear body
//! pressed far by a ball, with too few Newton iterations for the whole step, is crossed in
//! halved increments on the condensed path, which it keeps for the rest of the run, and the
//! answer is the coupled path's. Tolerances are stated where they are used.

use linkage::scene::{build_world, Simulation, StepResult, StepSummary, World};
use std::path::Path;

/// A linear 3D box lattice (0.4 × 0.1 × 0.4 m, 8 × 2 × 8 cells) on a fixed floor, pressed
/// `travel` m by a ball of radius 0.15 m in one step, with `newton` its `[bodies.newton]`.
fn ball_pressed_far(travel: f64, newton: &str) -> String {
    format!(
        r#"
name = "ball_pressed_far"
steps = 1
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "box"
box_lattice = {{ size = [0.4, 0.1, 0.4], cells = [8, 2, 8] }}
[bodies.newton]
{newton}
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[obstacles]]
name = "ball"
shape = "ball"
center = [0.2, 0.25, 0.2]
radius = 0.15
travel = [0.0, -{travel}, 0.0]
"#
    )
}

/// Steps 0 and 1 of `world`: the results, summaries and whether the contact solver was still
/// on the condensed path after each.
fn run(world: &World) -> Vec<(StepResult, StepSummary, bool)> {
    let mut sim = Simulation::new(world).expect("builds");
    (0..=world.steps)
        .map(|k| {
            let (r, s) = sim.step(k).expect("solves");
            (r, s, sim.contact().unwrap().is_condensed())
        })
        .collect()
}

/// The largest difference of two results' displacements relative to the largest of `b`'s,
/// and of their contact forces relative to the largest contact force component of `b`.
fn differences(a: &StepResult, b: &StepResult) -> (f64, f64) {
    let relative = |x: Vec<f64>, y: Vec<f64>| {
        assert_eq!(x.len(), y.len());
        let largest = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter()
            .zip(&y)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
            / largest
    };
    let u = |r: &StepResult| -> Vec<f64> {
        r.bodies[0]
            .displacements
            .iter()
            .flatten()
            .copied()
            .collect()
    };
    let f = |r: &StepResult| -> Vec<f64> {
        let mut c: Vec<(usize, Vec<f64>)> = r.bodies[0]
            .contacts
            .iter()
            .map(|c| (c.node, c.force.clone()))
            .collect();
        c.sort_by_key(|(n, _)| *n);
        c.into_iter().flat_map(|(_, f)| f).collect()
    };
    (relative(u(a), u(b)), relative(f(a), f(b)))
}

/// A ball pressed 30 mm into the linear box in one step with 5 Newton iterations per
/// increment: the whole step does not converge; the condensed path halves it (11 halvings in
/// all; with 6 iterations it needed 6 halvings until the condensed Newton mixed the iterates
/// of a linear convergence, and now needs none),
/// stays condensed to the end, reports the cuts, and agrees with the coupled path (condensing
/// off, default Newton, no cut) to 1e-8 of the largest displacement and of the largest contact
/// force, contact by contact.
#[test]
fn a_linear_body_pressed_far_is_cut_on_the_condensed_path() {
    let path = Path::new("ball_pressed_far.toml");
    let world = build_world(&ball_pressed_far(0.03, "max_iterations = 5"), path).unwrap();
    let mut coupled = build_world(&ball_pressed_far(0.03, ""), path).unwrap();
    coupled.contact.condense = false;
    let cut = run(&world);
    let reference = run(&coupled);
    let (result, summary, condensed) = &cut[1];
    let (expected, reference_summary, _) = &reference[1];
    assert!(*condensed, "the run left the condensed path");
    assert!(cut.iter().all(|s| s.2), "condensed at every step");
    assert!(summary.cuts > 0, "{summary:?}");
    assert_eq!(reference_summary.cuts, 0, "{reference_summary:?}");
    assert!(result.bodies[0].contacts.len() > 1, "the ball presses");
    let (du, df) = differences(result, expected);
    println!(
        "condensed: {} cuts, {} iterations; coupled: {} iterations; displacement difference {du:e}, contact force difference {df:e}",
        summary.cuts, summary.iterations, reference_summary.iterations
    );
    assert!(du <= 1e-8, "{du:e}");
    assert!(df <= 1e-8, "{df:e}");
}
