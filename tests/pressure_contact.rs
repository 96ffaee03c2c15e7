//! Pressure loads in scenes with contact (issue 32, combination 5): a linear body's pressure is
//! nodal loads on its undeformed faces, a large body's follows its deformed faces in the
//! contact solver's residual and tangent as in its own Newton. Out of contact a scene with an
//! obstacle gives the run without it; pressed, the contact carries the pressure's resultant;
//! a breaking body under pressure is watched for self-contact, so its crack faces do not pass
//! through each other.

use linkage::contact::default_penalty;
use linkage::scene::{load_scene, run, Summary};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn step_file(out: &Path, name: &str, step: usize) -> Value {
    let text = std::fs::read_to_string(out.join(format!("{name}/steps/{step:04}.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn vector(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect()
}

/// The entries `key` (positions, displacements) of body 0 of a step file.
fn per_node(step: &Value, key: &str) -> Vec<Vec<f64>> {
    step["bodies"][0][key]
        .as_array()
        .unwrap()
        .iter()
        .map(vector)
        .collect()
}

/// Sum of the forces (N) of `key` (loads, reactions, contacts) of body 0 of a step file.
fn total(step: &Value, key: &str) -> [f64; 2] {
    let mut sum = [0.0; 2];
    for e in step["bodies"][0][key].as_array().unwrap() {
        let f = vector(&e["force"]);
        sum[0] += f[0];
        sum[1] += f[1];
    }
    sum
}

/// The largest force (N) among the loads, reactions and contacts of body 0 of a step file.
fn largest_force(step: &Value) -> f64 {
    ["loads", "reactions", "contacts"]
        .iter()
        .flat_map(|k| step["bodies"][0][*k].as_array().unwrap().iter())
        .map(|e| {
            let f = vector(&e["force"]);
            f[0].hypot(f[1])
        })
        .fold(0.0, f64::max)
}

/// Write `text` as `dir/name.toml` and run it into `dir/out_name`.
fn run_scene(dir: &Path, name: &str, text: &str) -> (Summary, PathBuf) {
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(&scene, text).unwrap();
    let out = dir.join(format!("out_{name}"));
    let summary =
        run(&load_scene(&scene).unwrap(), &out, &|| {}).unwrap_or_else(|e| panic!("{name}: {e}"));
    (summary, out)
}

/// A rubber plate 0.4 × 0.2 m of 4 × 2 crossed cells (E A = 1e3 N), kinematics `kinematics`,
/// under `pressure` N/m on its top edge over `steps` steps, with `supports` (TOML) and
/// `obstacle` (TOML, may be empty).
fn plate(kinematics: &str, pressure: f64, steps: usize, supports: &str, obstacle: &str) -> String {
    format!(
        r#"name = "plate"
steps = {steps}
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "plate"
rectangle = {{ width = 0.4, height = 0.2, cells = [4, 2] }}
kinematics = "{kinematics}"
{supports}
[[bodies.pressures]]
on_line = {{ point = [0.0, 0.2], direction = [1.0, 0.0] }}
pressure = {pressure}
{obstacle}
"#
    )
}

const CANTILEVER: &str = r#"[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [0.0, 1.0] }
fix = ["x", "y"]"#;

/// A floor (half-space, normal +y) through `y` (m).
fn floor(y: f64) -> String {
    format!(
        "[[obstacles]]\nname = \"floor\"\nshape = \"half_space\"\npoint = [0.0, {y}]\nnormal = [0.0, 1.0]\n"
    )
}

/// A cantilever plate (left edge held) bent down by 20 N/m on its top edge over 4 steps, with
/// a floor below its free end that the plate reaches between steps 2 and 3 (placed halfway
/// between the lowest point of steps 2 and 3 of the run without it). Linear (the pressure as
/// nodal loads on the undeformed edge) and large (the pressure follows the deformed edge, in
/// the contact solver's residual and tangent): while out of contact (steps 1 and 2) every
/// node's displacement agrees with the run without the floor to 1e-10 of the largest; once
/// pressed (steps 3 and 4) the plate touches the floor and loads, reactions and contact forces
/// balance to 1e-8 of the largest of them, and no node is below the floor by more than the
/// contact tolerance (no warning).
#[test]
fn a_cantilever_plate_under_pressure_agrees_with_the_run_without_the_floor_until_it_touches() {
    for kinematics in ["linear", "large"] {
        let dir = tempfile::tempdir().unwrap();
        let (free, free_out) = run_scene(
            dir.path(),
            "free",
            &plate(kinematics, 20.0, 4, CANTILEVER, ""),
        );
        assert!(free.failure.is_none());
        let lowest = |out: &Path, s: usize| {
            per_node(&step_file(out, "plate", s), "positions")
                .iter()
                .map(|p| p[1])
                .fold(f64::INFINITY, f64::min)
        };
        let (y2, y3) = (lowest(&free_out, 2), lowest(&free_out, 3));
        assert!(y3 < y2 && y2 < 0.0, "{kinematics}: {y2} {y3}");
        let gap = 0.5 * (y2 + y3);
        let (pressed, out) = run_scene(
            dir.path(),
            "pressed",
            &plate(kinematics, 20.0, 4, CANTILEVER, &floor(gap)),
        );
        assert!(pressed.failure.is_none());
        for s in 1..=4 {
            let step = step_file(&out, "plate", s);
            let u = per_node(&step, "displacements");
            let contacts = step["bodies"][0]["contacts"].as_array().unwrap().len();
            if s <= 2 {
                let u_free = per_node(&step_file(&free_out, "plate", s), "displacements");
                let largest = u_free.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
                let differs = u
                    .iter()
                    .flatten()
                    .zip(u_free.iter().flatten())
                    .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                eprintln!("{kinematics} step {s}: differs by {differs:.3e} m of {largest:.3e} m");
                assert_eq!(contacts, 0, "{kinematics} step {s}");
                assert!(
                    differs <= 1e-10 * largest,
                    "{kinematics} step {s}: {differs} of {largest}"
                );
            } else {
                assert!(contacts > 0, "{kinematics} step {s}");
                let (l, r, c) = (
                    total(&step, "loads"),
                    total(&step, "reactions"),
                    total(&step, "contacts"),
                );
                let largest = largest_force(&step);
                eprintln!("{kinematics} step {s}: loads {l:?} reactions {r:?} contacts {c:?} N");
                for k in 0..2 {
                    assert!(
                        (l[k] + r[k] + c[k]).abs() <= 1e-8 * largest,
                        "{kinematics} step {s}: {l:?} {r:?} {c:?}"
                    );
                }
                assert!(c[1] > 0.0);
                // No node beyond the contact tolerance (a warning would say "inside").
                assert!(pressed.steps[s].max_penetration > 0.0);
                assert!(
                    !pressed.steps[s]
                        .warnings
                        .iter()
                        .any(|w| w.contains("inside")),
                    "{:?}",
                    pressed.steps[s].warnings
                );
            }
            assert!(pressed.steps[s].residual <= 1e-9, "{:?}", pressed.steps[s]);
        }
    }
}

const SIDEWAYS: &str = r#"[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [0.0, 1.0] }
fix = ["x"]"#;

/// A plate held sideways only (its left edge in x) on a floor touching its bottom edge, pressed
/// down by 500 N/m on its top edge over 2 steps: vertically only the floor holds it, so the
/// floor's force is the pressure's resultant. Linear: p times the undeformed edge, 0.4 m (200 N
/// at step 2), to 1e-8. Large: the pressure follows the deformed edge, whose resultant is p
/// times the chord between its end nodes turned a quarter turn (the squeezed plate's edge is
/// longer than at rest); the loads written sum to it (1e-10) and the floor's force balances it
/// with the reactions (1e-8 of the resultant); the contact Newton converges (residual 1e-9 or
/// less).
#[test]
fn a_plate_pressed_onto_the_floor_by_its_pressure_rests_on_the_pressure_resultant() {
    for kinematics in ["linear", "large"] {
        let dir = tempfile::tempdir().unwrap();
        let (summary, out) = run_scene(
            dir.path(),
            "rests",
            &plate(kinematics, 500.0, 2, SIDEWAYS, &floor(0.0)),
        );
        assert!(summary.failure.is_none());
        for s in 1..=2 {
            let p = 500.0 * s as f64 / 2.0;
            let step = step_file(&out, "plate", s);
            let positions = per_node(&step, "positions");
            let (l, r, c) = (
                total(&step, "loads"),
                total(&step, "reactions"),
                total(&step, "contacts"),
            );
            eprintln!("{kinematics} step {s}: loads {l:?} reactions {r:?} contacts {c:?} N");
            // The top edge's end nodes (at rest (0, 0.2) and (0.4, 0.2)).
            let at = |x: f64| {
                step["bodies"][0]["loads"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|e| e["node"].as_u64().unwrap() as usize - 1)
                    .min_by(|&a, &b| {
                        let d = |n: usize| (positions[n][0] - x).abs();
                        d(a).total_cmp(&d(b))
                    })
                    .unwrap()
            };
            let (a, b) = (&positions[at(0.0)], &positions[at(0.4)]);
            let resultant = if kinematics == "linear" {
                [0.0, -p * 0.4]
            } else {
                // Inward normal of the edge (a to b, the body below): (chord) turned clockwise.
                [p * (b[1] - a[1]), -p * (b[0] - a[0])]
            };
            let size = resultant[0].hypot(resultant[1]);
            for k in 0..2 {
                assert!(
                    (l[k] - resultant[k]).abs() <= 1e-10 * size,
                    "{kinematics} step {s}: loads {l:?}, resultant {resultant:?}"
                );
                assert!(
                    (l[k] + r[k] + c[k]).abs() <= 1e-8 * size,
                    "{kinematics} step {s}: {l:?} {r:?} {c:?}"
                );
            }
            // Vertically the floor alone: its force is the resultant's.
            assert!(r[1].abs() <= 1e-10 * size, "{r:?}");
            assert!(
                (c[1] + resultant[1]).abs() <= 1e-8 * size,
                "{kinematics} step {s}: {c:?} against {resultant:?}"
            );
            if kinematics == "linear" {
                assert!((c[1] - 100.0 * s as f64).abs() <= 1e-8 * size, "{c:?}");
            } else {
                // The squeezed plate's top edge is longer than at rest: the pressure that
                // follows it pushes more than on the undeformed edge.
                let stretch = b[0] - a[0] - 0.4;
                eprintln!("the top edge is {stretch:.3e} m longer than at rest");
                assert!(stretch > 1e-6 && stretch < 0.01, "{a:?} {b:?}");
            }
            assert!(summary.steps[s].residual <= 1e-9, "{:?}", summary.steps[s]);
        }
    }
}

/// A beam of 5 × 2 crossed cells (0.5 × 0.2 m, E A = 1e5 N), both ends held, bent by a
/// following pressure on its top edge (large displacements): down at step 1, up at steps 2 and
/// 3 (schedule 1, −1, −2). The bottom member of the middle cell is weak: its tensile strength
/// is half the force it carries at step 1 without breaking (read from that run), so it breaks
/// in step 1, alone. Bent up, the crack it left closes: the body is watched
/// for self-contact (no obstacles, no `[contact]`), goes on with the contact solver, and the
/// crack's faces do not pass through each other: its ends come closer than at rest (along the
/// member) by at most the contact force over the default penalty, and the contact forces on its
/// two ends are equal and opposite (1e-9). With `[contact] self = false` the crack closes
/// through itself (more than ten times as far).
#[test]
fn a_breaking_beam_bent_by_a_following_pressure_closes_its_crack_without_passing_through() {
    let h = 0.1;
    let mut positions = Vec::new();
    for c in 0..=5 {
        for r in 0..=2 {
            positions.push([c as f64 * h, r as f64 * h]);
        }
    }
    let id = |c: usize, r: usize| c * 3 + r + 1;
    let mut links: Vec<(usize, usize)> = Vec::new();
    for c in 0..5 {
        for r in 0..2 {
            for pair in [
                (id(c, r), id(c + 1, r)),
                (id(c, r), id(c, r + 1)),
                (id(c, r), id(c + 1, r + 1)),
                (id(c + 1, r), id(c, r + 1)),
            ] {
                links.push(pair);
            }
        }
        links.push((id(c, 2), id(c + 1, 2)));
    }
    for r in 0..2 {
        links.push((id(5, r), id(5, r + 1)));
    }
    let weak = (id(2, 0), id(3, 0));
    let member = links.iter().position(|&l| l == weak).unwrap();
    let nodes: String = positions
        .iter()
        .map(|p| format!("{} {}\n", p[0], p[1]))
        .collect();
    let link_lines: String = links
        .iter()
        .map(|&(p, q)| {
            let m = if (p, q) == weak { "weak" } else { "strong" };
            format!("{p} {q} {m}\n")
        })
        .collect();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("b.nodes"), nodes).unwrap();
    std::fs::write(dir.path().join("b.links"), link_lines).unwrap();
    let scene = |strength: &str, contact: &str| {
        format!(
            r#"name = "b"
steps = 3
[[materials]]
name = "strong"
youngs_modulus = 1e9
area = 1e-4
[[materials]]
name = "weak"
youngs_modulus = 1e9
area = 1e-4
{strength}
[[bodies]]
name = "b"
nodes = "b.nodes"
links = "b.links"
material = "strong"
kinematics = "large"
[[bodies.supports]]
on_line = {{ point = [0.0, 0.0], direction = [0.0, 1.0] }}
fix = ["x", "y"]
[[bodies.supports]]
on_line = {{ point = [0.5, 0.0], direction = [0.0, 1.0] }}
fix = ["x", "y"]
[[bodies.pressures]]
on_line = {{ point = [0.0, 0.2], direction = [1.0, 0.0] }}
pressure = 2e3
schedule = [1.0, -1.0, -2.0]
{contact}
"#
        )
    };
    let (_, intact) = run_scene(dir.path(), "intact", &scene("", ""));
    let force = step_file(&intact, "b", 1)["bodies"][0]["axial_forces"][member]
        .as_f64()
        .unwrap();
    eprintln!("the weak member carries {force} N at step 1 unbroken");
    assert!(force > 0.0, "the bottom member is in tension: {force}");
    let strength = format!(
        "tensile_strength = {}\nfailure = \"break\"",
        0.5 * force / 1e-4
    );
    let mut closed = 0.0;
    for contact in ["", "[contact]\nself = false"] {
        let (summary, out) = run_scene(dir.path(), "broken", &scene(&strength, contact));
        assert!(summary.failure.is_none() && summary.collapse.is_none());
        assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
        let b = &summary.breaks[0];
        assert_eq!((b.step, b.member), (1, member + 1));
        // Broken within step 1 (at about half its pressure), alone.
        let step1 = step_file(&out, "b", 1);
        assert_eq!(
            step1["bodies"][0]["broken"],
            serde_json::json!([member + 1])
        );
        let self_on = contact.is_empty();
        let touched: Vec<usize> = summary
            .steps
            .iter()
            .filter(|s| s.warnings.iter().any(|w| w.contains("touches itself")))
            .map(|s| s.step)
            .collect();
        eprintln!("{contact:?}: switched to contact at {touched:?}");
        assert_eq!(touched.is_empty(), !self_on, "{:?}", summary.steps);
        let step = step_file(&out, "b", 3);
        let u = per_node(&step, "displacements");
        let (a, c) = (weak.0 - 1, weak.1 - 1);
        // The crack's closure along the broken member's axis (x), m.
        let closure = u[a][0] - u[c][0];
        let contacts = step["bodies"][0]["contacts"].as_array().unwrap();
        let on = |n: usize| {
            contacts
                .iter()
                .filter(|e| e["node"].as_u64().unwrap() as usize == n + 1)
                .map(|e| vector(&e["force"]))
                .fold([0.0, 0.0], |s, f| [s[0] + f[0], s[1] + f[1]])
        };
        let (fa, fc) = (on(a), on(c));
        let k = default_penalty(&load_scene(&dir.path().join("broken.toml")).unwrap().bodies[0]);
        eprintln!(
            "{contact:?}: the crack closes by {closure:.6e} m; contact forces {fa:?} {fc:?} N, penalty {k:.6e} N/m, F/k = {:.6e} m",
            fa[0].hypot(fa[1]) / k
        );
        if self_on {
            let size = fa[0].hypot(fa[1]);
            assert!(size > 0.0, "{contacts:?}");
            // The closed crack is the penalty spring: closed by F / k, no more.
            assert!(
                closure > 0.0 && closure <= size / k * (1.0 + 1e-6),
                "closure {closure} against F / k = {}",
                size / k
            );
            assert!(
                (fa[0] + fc[0]).abs() <= 1e-9 * size && (fa[1] + fc[1]).abs() <= 1e-9 * size,
                "{fa:?} {fc:?}"
            );
            closed = closure;
        } else {
            assert!(contacts.is_empty());
            // Through itself: ten times further than the penalty lets it.
            assert!(
                closure > 10.0 * closed,
                "closure {closure} against {closed}"
            );
        }
    }
}

/// Friction with a pressure (the pair F×P of *Features together*): the plate of
/// [`a_plate_pressed_onto_the_floor_by_its_pressure_rests_on_the_pressure_resultant`], large
/// displacements (the pressure following the deformed edge), on a floor with μ = 0.5. Pressed,
/// the lattice spreads sideways away from its held left edge and the floor's friction holds its
/// bottom back: the contacts carry a sideways force (at least 1 % of the resultant; exactly
/// none without friction) that the held edge's reactions balance (1e-8), every contact stays in
/// Coulomb's cone (|f_T| ≤ μ f_N, 1e-9), and vertically the floor still carries the following
/// pressure's resultant (1e-8), as without friction.
#[test]
fn a_following_pressure_presses_a_plate_onto_a_floor_whose_friction_holds_its_spread() {
    let mut sideways = Vec::new();
    for mu in [0.0, 0.5] {
        let dir = tempfile::tempdir().unwrap();
        let friction = format!("[contact]\nfriction = {mu}\n");
        let (summary, out) = run_scene(
            dir.path(),
            "rubs",
            &format!(
                "{}{friction}",
                plate("large", 500.0, 2, SIDEWAYS, &floor(0.0))
            ),
        );
        assert!(summary.failure.is_none());
        let step = step_file(&out, "plate", 2);
        let (l, r, c) = (
            total(&step, "loads"),
            total(&step, "reactions"),
            total(&step, "contacts"),
        );
        let size = l[0].hypot(l[1]);
        assert!(size > 199.0, "{l:?}");
        for k in 0..2 {
            assert!(
                (l[k] + r[k] + c[k]).abs() <= 1e-8 * size,
                "μ = {mu}: {l:?} {r:?} {c:?}"
            );
        }
        assert!(r[1].abs() <= 1e-10 * size, "μ = {mu}: {r:?}");
        assert!((c[1] + l[1]).abs() <= 1e-8 * size, "μ = {mu}: {c:?} {l:?}");
        for e in step["bodies"][0]["contacts"].as_array().unwrap() {
            let t = vector(&e["tangential_force"]);
            let n = e["normal_force"].as_f64().unwrap();
            assert!(
                t[0].hypot(t[1]) <= mu * n * (1.0 + 1e-9) + 1e-12 * size,
                "μ = {mu}: {e}"
            );
        }
        eprintln!("μ = {mu}: contacts {c:?} N, reactions {r:?} N, loads {l:?} N");
        sideways.push(c[0].abs() / size);
        assert!(summary.steps[2].residual <= 1e-9, "{:?}", summary.steps[2]);
    }
    assert!(sideways[0] <= 1e-10, "frictionless: {sideways:?}");
    assert!(sideways[1] >= 0.01, "with friction: {sideways:?}");
}
