//! Coulomb friction (issue 13): stick with an elastic slip whose stiffness the scene sets, slip
//! at exactly μ times the normal force, a history committed step by step. Each test against a
//! closed form with its tolerance.

use linkage::contact::ContactError;
use linkage::scene::{load_scene, RunError, Simulation, StepResult, StepSummary};
use std::path::Path;

mod common;

/// A 2D body of two nodes 0.1 m apart on a floor (y = 0), each pressed down by 100 N from
/// step 1, node 1 pulled along x by the prescribed `travel` (m) on `schedule`; friction as
/// `contact` gives it. Stiff members (E A / L = 1e11 N/m) against a stick stiffness of 1e6
/// N/m: the pair moves as one.
fn pair_scene(dir: &Path, schedule: &[f64], travel: f64, contact: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("pair.nodes"), "0.0 0.0\n0.1 0.0\n").unwrap();
    std::fs::write(dir.join("pair.links"), "1 2\n").unwrap();
    let ones = vec!["1.0"; schedule.len()].join(", ");
    let schedule = schedule
        .iter()
        .map(|s| format!("{s:?}"))
        .collect::<Vec<_>>()
        .join(", ");
    let text = format!(
        r#"name = "pair"
steps = {steps}

[[materials]]
name = "stiff"
youngs_modulus = 1e12
area = 1e-2

[[bodies]]
name = "pair"
nodes = "pair.nodes"
links = "pair.links"
material = "stiff"

[[bodies.loads]]
nodes = [1, 2]
force = [0.0, -100.0]
schedule = [{ones}]

[[bodies.supports]]
nodes = [1]
fix = ["x"]
displacement = [{travel:?}, 0.0]
schedule = [{schedule}]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0]
normal = [0.0, 1.0]

{contact}
"#,
        steps = schedule.split(", ").count(),
    );
    let path = dir.join("pair.toml");
    std::fs::write(&path, text).unwrap();
    path
}

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

/// The x reaction of body 0 at a step, N: what pulls it.
fn pull(step: &StepResult) -> f64 {
    step.bodies[0].reactions.iter().map(|r| r.force[0]).sum()
}

const FRICTION: &str = "[contact]\nfriction = 0.5\nstick_stiffness = 1e6";

#[test]
fn a_pulled_block_holds_with_the_stick_stiffness_then_slides_at_exactly_mu_n() {
    let dir = tempfile::tempdir().unwrap();
    // Press at step 1, then pull 2e-5 m per step to 2e-4 m: the limit μ N = 100 N is reached
    // at 100 / (2 × 1e6) = 5e-5 m.
    let schedule: Vec<f64> = (0..=10).map(|k| k as f64 / 10.0).collect();
    let steps = run(&pair_scene(dir.path(), &schedule, 2e-4, FRICTION)).unwrap();
    for (k, (step, summary)) in steps.iter().enumerate().skip(1) {
        let u = 2e-4 * schedule[k - 1];
        let f = pull(step);
        let expected = (2e6 * u).min(100.0);
        // Sticking: the members' compliance (1e-5 of the stick's) is the difference.
        let tolerance = if 2e6 * u < 100.0 {
            1e-4 * 100.0
        } else {
            1e-9 * 100.0
        };
        assert!(
            (f - expected).abs() <= tolerance,
            "step {k}: pulled with {f} N at {u} m, expected {expected}"
        );
        if 2e6 * u > 100.0 {
            assert_eq!(summary.slipping, 2, "step {k}");
            for c in &step.bodies[0].contacts {
                assert_eq!(c.state, "slip");
                assert!((c.tangential_force[0] + 0.5 * c.normal_force).abs() < 1e-9 * 100.0);
                assert!((c.normal_force - 100.0).abs() < 1e-9 * 100.0);
                assert!((c.normal[1] - 1.0).abs() < 1e-15);
            }
        } else if u > 0.0 {
            assert_eq!(summary.sticking, 2, "step {k}");
        }
    }
    // The slip accumulated at the end: moved 2e-4 m, 5e-5 m of it elastic.
    let last = &steps.last().unwrap().0.bodies[0];
    for c in &last.contacts {
        assert!((c.slip[0] - 1.5e-4).abs() < 1e-9, "{:?}", c.slip);
    }
    // The same end reached in 3 steps: the same force, to round-off.
    let dir = tempfile::tempdir().unwrap();
    let few = run(&pair_scene(dir.path(), &[0.0, 0.5, 1.0], 2e-4, FRICTION)).unwrap();
    let (a, b) = (pull(&few.last().unwrap().0), pull(&steps.last().unwrap().0));
    assert!((a - b).abs() < 1e-9 * 100.0, "{a} against {b}");
}

#[test]
fn a_load_unload_cycle_traces_the_closed_hysteresis_loop_of_the_closed_form() {
    // Out to u = 5e-4 m, back to -5e-4 m and out again, 5e-5 m per step: the stick phase
    // after each reversal (2 μN / K = 1e-4 m) spans whole steps, so the trapezoids are exact.
    let mut schedule = vec![0.0];
    schedule.extend((1..=10).map(|k| k as f64 / 10.0));
    schedule.extend((1..=20).map(|k| 1.0 - k as f64 / 10.0));
    schedule.extend((1..=20).map(|k| -1.0 + k as f64 / 10.0));
    let dir = tempfile::tempdir().unwrap();
    let steps = run(&pair_scene(dir.path(), &schedule, 5e-4, FRICTION)).unwrap();
    let curve: Vec<(f64, f64)> = steps
        .iter()
        .skip(11)
        .map(|(s, _)| (s.bodies[0].displacements[0][0], pull(s)))
        .collect();
    // The closed loop from u_max back to u_max, by trapezoids: ∮ F du.
    let area: f64 = curve
        .windows(2)
        .map(|w| 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0))
        .sum::<f64>()
        .abs();
    let (mu_n, k, u_max) = (100.0, 2e6, 5e-4);
    let closed = 4.0 * mu_n * (u_max - mu_n / k);
    assert!(
        (area - closed).abs() < 1e-4 * closed,
        "loop area {area} J against 4 μN (u_max − μN/K) = {closed} J"
    );
    // Back where it started, the force too.
    let (first, last) = (curve[0], curve[curve.len() - 1]);
    assert!((first.1 - last.1).abs() < 1e-9 * mu_n && (first.0 - last.0).abs() < 1e-12);
}

#[test]
fn a_block_pushed_below_mu_n_is_held_and_above_it_is_reported_sliding() {
    let dir = tempfile::tempdir().unwrap();
    let held = run(&common::pushed_cube(dir.path(), 160.0, 0.1)).unwrap();
    let step = &held.last().unwrap().0.bodies[0];
    let friction: f64 = step.contacts.iter().map(|c| c.tangential_force[0]).sum();
    assert!((friction + 160.0).abs() < 1e-9 * 400.0, "{friction}");
    // Held: it moved no more than the elastic slip at the limit, μ f_N / k_t per node.
    let largest = step
        .displacements
        .iter()
        .map(|u| u[0].abs())
        .fold(0.0, f64::max);
    assert!(largest <= 0.5 * 400.0 / 1e6, "{largest}");
    let err = run(&common::pushed_cube(dir.path(), 240.0, 0.1)).unwrap_err();
    let RunError::Contact {
        source:
            ContactError::Sliding {
                step,
                body,
                load,
                capacity,
            },
        ..
    } = &err
    else {
        panic!("{err}");
    };
    assert_eq!((*step, body.as_str()), (2, "block"));
    assert!(
        (load - 240.0).abs() < 1e-9 * 240.0 && (capacity - 200.0).abs() < 1e-6,
        "{err}"
    );
    let message = err.to_string();
    assert!(message.contains("step 2: body 'block' slides"), "{message}");
}

#[test]
fn two_bodies_receive_equal_and_opposite_friction() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("pair.nodes"), "0.02 0.1\n0.12 0.1\n").unwrap();
    std::fs::write(dir.path().join("pair.links"), "1 2\n").unwrap();
    let text = r#"name = "two"
steps = 4

[[materials]]
name = "stiff"
youngs_modulus = 1e10
area = 1e-2

[[bodies]]
name = "base"
rectangle = { width = 0.2, height = 0.1, cells = [8, 4] }
material = "stiff"

[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [1.0, 0.0] }
fix = ["x", "y"]

[[bodies]]
name = "slider"
nodes = "pair.nodes"
links = "pair.links"
material = "stiff"

[[bodies.loads]]
nodes = [1, 2]
force = [0.0, -100.0]
schedule = [1.0, 1.0, 1.0, 1.0]

[[bodies.supports]]
nodes = [1]
fix = ["x"]
displacement = [1e-4, 0.0]
schedule = [0.0, 0.1, 0.5, 1.0]

[contact]
friction = 0.3

[[contact.pairs]]
between = ["slider", "base"]
friction = 0.4
stick_stiffness = 1e6
"#;
    let path = dir.path().join("two.toml");
    std::fs::write(&path, text).unwrap();
    let steps = run(&path).unwrap();
    for (k, (_, summary)) in steps.iter().enumerate().skip(1) {
        let on = |a: &str, b: &str| {
            summary
                .contact_forces
                .iter()
                .find(|p| p.body == a && p.with == b)
                .map(|p| p.force.clone())
                .unwrap_or_else(|| panic!("step {k}: no force on {a} from {b}"))
        };
        let (slider, base) = (on("slider", "base"), on("base", "slider"));
        for i in 0..2 {
            assert!(
                (slider[i] + base[i]).abs() < 1e-9 * 200.0,
                "step {k}: {slider:?} against {base:?}"
            );
        }
        assert!((slider[1] - 200.0).abs() < 1e-6 * 200.0, "{slider:?}");
    }
    // The last steps slide at the pair's μ = 0.4 (not the scene's 0.3).
    let (last, summary) = steps.last().unwrap();
    assert_eq!(summary.slipping, 2);
    for c in &last.bodies[1].contacts {
        let t = (c.tangential_force[0].powi(2) + c.tangential_force[1].powi(2)).sqrt();
        assert!(
            (t - 0.4 * c.normal_force).abs() < 1e-9 * 200.0,
            "node {}: {t} N against μ N = {}",
            c.node,
            0.4 * c.normal_force
        );
        assert!(c.tangential_force[0] < 0.0);
    }
}

#[test]
fn zero_friction_gives_the_frictionless_answer_exactly() {
    let schedule: Vec<f64> = (0..=4).map(|k| k as f64 / 4.0).collect();
    let dir = tempfile::tempdir().unwrap();
    let frictionless = run(&pair_scene(dir.path(), &schedule, 1e-4, "")).unwrap();
    for contact in [
        "[contact]\nfriction = 0.0",
        "[contact]\nfriction = 0.6\n\n[[contact.pairs]]\nbetween = [\"floor\", \"pair\"]\nfriction = 0.0",
    ] {
        let dir = tempfile::tempdir().unwrap();
        let zero = run(&pair_scene(dir.path(), &schedule, 1e-4, contact)).unwrap();
        for (a, b) in zero.iter().zip(&frictionless) {
            assert_eq!(a.0, b.0, "{contact}");
        }
    }
}

#[test]
fn a_disk_pressed_and_pushed_sideways_sticks_inside_and_slips_at_the_edges_mirrored() {
    let scene = |push: f64| {
        format!(
            r#"name = "disk"
steps = 2

[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4

[[bodies]]
name = "disk"
disk = {{ radius = 0.1, rings = 24, sectors = 256 }}

[[bodies.supports]]
inside = {{ min = [-0.2, 0.06], max = [0.2, 0.2] }}
fix = ["y"]
displacement = [0.0, -0.01]
schedule = [1.0, 1.0]

[[bodies.supports]]
inside = {{ min = [-0.2, 0.06], max = [0.2, 0.2] }}
fix = ["x"]
displacement = [{push:?}, 0.0]
schedule = [0.0, 1.0]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.1]
normal = [0.0, 1.0]

[contact]
friction = 0.5
"#
        )
    };
    let solve = |push: f64| {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("disk.toml");
        std::fs::write(&path, scene(push)).unwrap();
        run(&path).unwrap().pop().unwrap().0.bodies.remove(0)
    };
    // The disk's top cap lowered 1 cm, then moved 15 mm sideways, held rigidly (it cannot
    // roll): Cattaneo's set-up, tangential load Q at about 0.5 μ P.
    let (right, left) = (solve(0.015), solve(-0.015));
    let origin = |b: &linkage::scene::BodyResult, node: usize| {
        b.positions[node - 1][0] - b.displacements[node - 1][0]
    };
    // Along x: stick inside, slip at both edges, one run of sticking nodes.
    let mut along: Vec<(f64, &str)> = right
        .contacts
        .iter()
        .map(|c| (origin(&right, c.node), c.state.as_str()))
        .collect();
    along.sort_by(|a, b| a.0.total_cmp(&b.0));
    let states: String = along.iter().map(|(_, s)| &s[1..2]).collect();
    let trimmed = states.trim_matches('l');
    assert!(
        states.starts_with('l')
            && states.ends_with('l')
            && !trimmed.is_empty()
            && !trimmed.contains('l'),
        "states along x: {states}"
    );
    let normal: f64 = right.contacts.iter().map(|c| c.normal_force).sum();
    let q: f64 = right.contacts.iter().map(|c| c.tangential_force[0]).sum();
    assert!(q < 0.0 && -q < 0.5 * normal, "{q} {normal}");
    // Mirrored load, mirrored answer: the node at −x has the state and the mirrored force of
    // the node at +x.
    for c in &right.contacts {
        let x = origin(&right, c.node);
        let y = right.positions[c.node - 1][1] - right.displacements[c.node - 1][1];
        let twin = left
            .contacts
            .iter()
            .find(|d| {
                (origin(&left, d.node) + x).abs() < 1e-9
                    && (left.positions[d.node - 1][1] - left.displacements[d.node - 1][1] - y).abs()
                        < 1e-9
            })
            .unwrap_or_else(|| panic!("no mirror of node {} at x = {x}", c.node));
        assert_eq!(c.state, twin.state, "node {} at x = {x}", c.node);
        let scale = 1e-9 * normal;
        assert!((c.tangential_force[0] + twin.tangential_force[0]).abs() < scale);
        assert!((c.normal_force - twin.normal_force).abs() < scale);
    }
    // The stick zone's half width against Cattaneo's c/a = sqrt(1 − Q/μP), to 0.15 (about 2
    // node spacings of the 25 nodes in contact).
    let spans = |s: &[(f64, &str)]| s[s.len() - 1].0 - s[0].0;
    let sticking: Vec<(f64, &str)> = along
        .iter()
        .filter(|(_, s)| *s == "stick")
        .copied()
        .collect();
    let ratio = spans(&sticking) / spans(&along);
    let closed = (1.0 + q / (0.5 * normal)).sqrt();
    println!(
        "stick zone: {} of {} contact nodes, c/a = {ratio:.3}; Cattaneo's sqrt(1 − Q/μP) = {closed:.3}",
        trimmed.len(),
        states.len(),
    );
    assert!(
        (ratio - closed).abs() < 0.15,
        "c/a {ratio} against {closed}"
    );
}

#[test]
fn a_block_on_a_slope_holds_while_tan_theta_is_below_mu_and_slides_above() {
    // The bundled block_on_slope.toml with its weight tilted by θ: held at 20° and 26°
    // (tan 0.488 < μ = 0.5), reported sliding at 30° (tan 0.577 > μ) at step 1, the first
    // with the weight (half of it: the weight ramps over two steps).
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/block_on_slope.toml"),
    )
    .unwrap();
    for (degrees, holds) in [(20.0f64, true), (26.0, true), (30.0, false)] {
        let t = degrees.to_radians();
        let scene = text.replace(
            "total_force = [342.020143325669, -939.692620785908, 0.0]",
            &format!(
                "total_force = [{:?}, {:?}, 0.0]",
                1e3 * t.sin(),
                -1e3 * t.cos()
            ),
        );
        assert_ne!(scene, text);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("slope.toml");
        std::fs::write(&path, scene).unwrap();
        match run(&path) {
            Ok(steps) => {
                assert!(holds, "{degrees}°: held");
                let b = &steps.last().unwrap().0.bodies[0];
                let along: f64 = b.contacts.iter().map(|c| c.tangential_force[0]).sum();
                assert!(
                    (along + 1e3 * t.sin()).abs() < 1e-9 * 1e3,
                    "{degrees}°: {along}"
                );
                assert!(b.contacts.iter().any(|c| c.state == "stick"));
            }
            Err(e) => {
                assert!(!holds, "{degrees}°: {e}");
                let RunError::Contact {
                    source:
                        ContactError::Sliding {
                            step,
                            body,
                            load,
                            capacity,
                        },
                    ..
                } = &e
                else {
                    panic!("{degrees}°: {e}");
                };
                assert_eq!((*step, body.as_str()), (1, "block"));
                // Half the weight at step 1 of 2.
                assert!((load - 0.5e3 * t.sin()).abs() < 1e-6, "{e}");
                assert!((capacity - 0.5 * 0.5e3 * t.cos()).abs() < 1e-6, "{e}");
            }
        }
    }
}

/// Two boxes of 5³ nodes pressed together with μ = 0.3 (the contact benchmark's pair, small),
/// then the upper one sheared 0.1 mm along x per step by two held lines. At the shear's onset
/// every contact's trial force is far beyond μ N and Newton's full steps turn the tangential
/// forces back and forth; the condensed Newton holds such contacts sticking until it has
/// converged and then lets go those beyond μ N (`FrictionHistory::held`). It must cross every
/// step whole on the condensed path (no cut, no fall to the coupled path; before this, step 2
/// was cut and fell to the coupled path), to an equilibrium (residual at most 1e-9) carrying
/// the load (1e-6), equal and opposite between the bodies (1e-9), with the coupled path's
/// normal totals (1e-6).
#[test]
fn a_sheared_pair_converges_whole_steps_on_the_condensed_path_to_the_exact_law() {
    let scene = include_str!("common/sheared_pair.toml");
    let mut world =
        linkage::scene::build_world(scene, Path::new("sheared_pair.toml")).expect("a valid scene");
    let mut sim = Simulation::new(&world).expect("builds");
    assert!(sim.contact().is_some_and(|c| c.is_condensed()));
    let mut condensed = Vec::new();
    for k in 0..=world.steps {
        let (result, summary) = sim.step(k).expect("solves");
        assert!(
            sim.contact().is_some_and(|c| c.is_condensed()),
            "step {k} left the condensed path"
        );
        assert_eq!(summary.cuts, 0, "step {k} was cut");
        condensed.push((result, summary));
    }
    for (k, (_, sa)) in condensed.iter().enumerate().skip(1) {
        if k >= 2 {
            // Sheared: the interface slips at its edges and sticks inside.
            assert!(sa.slipping > 0 && sa.sticking > 0, "step {k}: {sa:?}");
        }
        assert!(sa.residual <= 1e-9, "step {k}: residual {}", sa.residual);
        // The pair carries the applied 500 N × the step's factor, to 1e-6.
        let load = 500.0 * sa.load_factor;
        let [p, q] = &sa.contact_forces[..] else {
            panic!("step {k}: {:?}", sa.contact_forces)
        };
        assert!(
            (p.force[1].abs() - load).abs() <= 1e-6 * load,
            "step {k}: {:?} against the load {load} N",
            p.force
        );
        // Equal and opposite between the bodies, to 1e-9 of the load.
        for (x, y) in p.force.iter().zip(&q.force) {
            assert!((x + y).abs() <= 1e-9 * load, "step {k}: {x} against {y}");
        }
    }
    // The coupled path (the exact law at every iterate) crosses the same steps to equilibria
    // of the same kind, compared by their totals: friction's answer depends on the path (the
    // coupled path cuts step 2; the counts of contacts differ by one or two), and the
    // symmetric pair may break its symmetry opposite ways on the two paths.
    world.contact.condense = false;
    let mut sim = Simulation::new(&world).expect("builds");
    for (k, (_, sa)) in condensed.iter().enumerate() {
        let (_, sb) = sim.step(k).expect("solves");
        for (pa, pb) in sa.contact_forces.iter().zip(&sb.contact_forces) {
            assert!(
                (pa.force[1] - pb.force[1]).abs() <= 1e-6 * pa.force[1].abs(),
                "step {k}: {:?} against {:?}",
                pa.force,
                pb.force
            );
        }
    }
}
