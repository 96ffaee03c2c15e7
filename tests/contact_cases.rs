//! Issue 32, "contact that converges and failures read right": one regression test per case,
//! each reproducing the case as described and asserting the right behaviour with numbers.

use linkage::contact::ContactError;
use linkage::scene::{load_scene, RunError, Simulation, StepResult, StepSummary};
use std::path::{Path, PathBuf};

mod common;

/// Every step of the scene at `path`, with its summary.
#[allow(clippy::result_large_err)]
fn run(path: &Path) -> Result<Vec<(StepResult, StepSummary)>, RunError> {
    let world = load_scene(path).unwrap();
    let mut sim = Simulation::new(&world).expect("builds");
    let mut steps = Vec::new();
    for k in 0..=world.steps {
        steps.push(sim.step(k)?);
    }
    Ok(steps)
}

/// Write `text` as `name` in `dir`.
fn scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A steel cube of 0.1 m (2 × 1 × 2 cells) resting on the floor y = 0 with no supports at
/// all: 400 N down on all its nodes from step 1, `push` N along x on its top from step 2 (half
/// at step 1), `friction` as the [contact] table's.
fn resting_block(dir: &Path, push: f64, contact: &str) -> PathBuf {
    scene(
        dir,
        "resting.toml",
        &format!(
            r#"name = "resting"
steps = 2

[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4

[[bodies]]
name = "block"
box_lattice = {{ size = [0.1, 0.1, 0.1], cells = [2, 1, 2] }}
material = "steel"

[[bodies.loads]]
inside = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0] }}
total_force = [0.0, -400.0, 0.0]
schedule = [1.0, 1.0]

[[bodies.loads]]
on_plane = {{ point = [0.0, 0.1, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [{push:?}, 0.0, 0.0]
schedule = [0.5, 1.0]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]

{contact}
"#
        ),
    )
}

/// Case 3, **a body resting on a floor without supports**: it was refused as a free rigid
/// body ("has no supports") before any contact was tried. With friction μ = 0.5 and a push of
/// 100 N < μ N = 200 N the contacts hold every rigid motion: it solves, the floor carries the
/// weight (Σ normal forces = 400 N, to 1e-9 relative) and friction the push (Σ tangential
/// forces = −100 N along x, 0 along z, to 1e-9 relative).
#[test]
fn a_body_resting_on_a_floor_without_supports_is_held_by_friction() {
    let dir = tempfile::tempdir().unwrap();
    let steps = run(&resting_block(
        dir.path(),
        100.0,
        "[contact]\nfriction = 0.5",
    ))
    .unwrap_or_else(|e| panic!("{e}"));
    let step = &steps.last().unwrap().0.bodies[0];
    let normal: f64 = step.contacts.iter().map(|c| c.normal_force).sum();
    let along = |k: usize| -> f64 { step.contacts.iter().map(|c| c.tangential_force[k]).sum() };
    assert!((normal - 400.0).abs() < 1e-9 * 400.0, "{normal}");
    assert!((along(0) + 100.0).abs() < 1e-9 * 400.0, "{}", along(0));
    assert!(along(2).abs() < 1e-9 * 400.0, "{}", along(2));
    assert!(along(1).abs() < 1e-9 * 400.0, "{}", along(1));
}

/// Case 3, the free half: the same block on a frictionless floor under its weight alone.
/// Nothing holds it along the floor or about the vertical: the run stops at step 1 naming
/// the free motions (slide along x and z, turn about y) and what to do.
#[test]
fn a_body_resting_on_a_frictionless_floor_without_supports_is_told_which_motions_are_free() {
    let dir = tempfile::tempdir().unwrap();
    let err = run(&resting_block(dir.path(), 0.0, "[contact]")).unwrap_err();
    let RunError::Contact {
        source:
            ContactError::Free {
                step,
                body,
                motions,
                push,
            },
        ..
    } = &err
    else {
        panic!("{err}");
    };
    assert_eq!(
        (*step, body.as_str(), motions.as_str(), push),
        (1, "block", "slide along x and z and turn about y", &None)
    );
    let message = err.to_string();
    assert!(
        message.contains(
            "step 1: body 'block' can slide along x and z and turn about y: nothing holds it there"
        ) && message.contains("add friction or a support"),
        "{message}"
    );
}

/// Case 4, **a block pushed at exactly μN**: pushed by 200 N = μ N (μ = 0.5, N = 400 N) the
/// block is at the edge of sliding. It is solved at the limit: friction carries the push, Σ
/// tangential = −200 N = −μ Σ normal (to 1e-9 relative), every contact at μ times its normal
/// force; 1.01 μ N is reported sliding, and 0.99 μ N pushed on its base sticks (friction
/// carries the push, to 1e-9 relative). Not yet: 0.99 μ N pushed at its top, where the
/// tipping moment leaves the back contacts slipping and the front ones sticking, does not
/// converge (the stick/slip split does not settle). (A step at the edge that does not
/// settle is told "is at the edge of sliding" rather than "did not converge".)
#[test]
fn a_block_pushed_at_exactly_mu_n_is_solved_at_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let edge = run(&common::pushed_cube(dir.path(), 200.0, 0.1)).unwrap_or_else(|e| panic!("{e}"));
    let step = &edge.last().unwrap().0.bodies[0];
    let along: f64 = step.contacts.iter().map(|c| c.tangential_force[0]).sum();
    let normal: f64 = step.contacts.iter().map(|c| c.normal_force).sum();
    assert!((normal - 400.0).abs() < 1e-9 * 400.0, "{normal}");
    assert!((along + 200.0).abs() < 1e-9 * 400.0, "{along}");
    for c in &step.contacts {
        let t = c.tangential_force.iter().map(|f| f * f).sum::<f64>().sqrt();
        assert!((t - 0.5 * c.normal_force).abs() < 1e-9 * 400.0, "{c:?}");
    }
    let err = run(&common::pushed_cube(dir.path(), 202.0, 0.1)).unwrap_err();
    assert!(
        matches!(
            &err,
            RunError::Contact {
                source: ContactError::Sliding { .. },
                ..
            }
        ) && err.to_string().contains("step 2: body 'block' slides"),
        "{err}"
    );
    // 0.99 μ N on its base (no tipping moment: every contact presses with 100 N) sticks.
    let held = run(&common::pushed_cube(dir.path(), 198.0, 0.0)).unwrap_or_else(|e| panic!("{e}"));
    let step = &held.last().unwrap().0.bodies[0];
    let friction: f64 = step.contacts.iter().map(|c| c.tangential_force[0]).sum();
    assert!((friction + 198.0).abs() < 1e-9 * 400.0, "{friction}");
    assert!(step.contacts.iter().all(|c| c.state == "stick"));
}

/// Case 4, **a frictionless block on a slope**: the bundled block_on_slope.toml (its 1 kN
/// weight tilted 20° along x, held in z) without friction was told "a load pushes it away
/// from every surface". It is told it slides along x, pushed by the weight's part along the
/// floor, 1 kN · sin 20° / 2 at step 1 (half the weight), to 1e-6 relative, and that nothing
/// resists it.
#[test]
fn a_frictionless_block_on_a_slope_is_told_it_slides_along_the_surface() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/block_on_slope.toml"),
    )
    .unwrap();
    let frictionless = text.replace("friction = 0.5", "");
    assert_ne!(frictionless, text);
    let dir = tempfile::tempdir().unwrap();
    let err = run(&scene(dir.path(), "slope.toml", &frictionless)).unwrap_err();
    let RunError::Contact {
        source: ContactError::Free {
            step, body, push, ..
        },
        ..
    } = &err
    else {
        panic!("{err}");
    };
    assert_eq!((*step, body.as_str()), (1, "block"));
    let (direction, force) = push.as_ref().unwrap_or_else(|| panic!("{err}"));
    assert_eq!(direction, "along x");
    let along = 0.5e3 * 20f64.to_radians().sin();
    assert!((force - along).abs() < 1e-6 * along, "{err}");
    let message = err.to_string();
    assert!(
        message.contains("step 1: body 'block' slides along x")
            && message.contains("nothing resists that motion"),
        "{message}"
    );
}
