//! Self-contact of breaking bodies in scenes solved body by body (no obstacles, no
//! `[contact]`): the body keeps its fast solver while nothing touches, and goes on with the
//! contact solver once a crack closes or a piece presses its own body.

use linkage::contact::{default_penalty, PENALTY_FACTOR};
use linkage::scene::{load_scene, run, Summary};
use serde_json::Value;
use std::path::Path;

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

fn switched(summary: &Summary) -> Vec<usize> {
    summary
        .steps
        .iter()
        .filter(|s| s.warnings.iter().any(|w| w.contains("touches itself")))
        .map(|s| s.step)
        .collect()
}

/// The chain of two bars of `tests/self_contact.rs`, 1 m each along x (E A / L = 1e5 N/m):
/// node 1 held, node 2 held in y, node 3 moved along x by 1 mm × [0.5, 1, 0, −1, −2]; the
/// second bar breaks in tension at 4e5 Pa (0.4 mm), i.e. at load factor 0.8 of step 2. `contact`
/// is the scene's `[contact]` table (empty: none).
fn chain_scene(dir: &Path, contact: &str) -> std::path::PathBuf {
    std::fs::write(dir.join("c.nodes"), "0 0\n1 0\n2 0\n").unwrap();
    std::fs::write(dir.join("c.links"), "1 2 strong\n2 3 weak\n").unwrap();
    let scene = dir.join("c.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "c"
steps = 5
[[materials]]
name = "strong"
youngs_modulus = 1e9
area = 1e-4
[[materials]]
name = "weak"
youngs_modulus = 1e9
area = 1e-4
tensile_strength = 4e5
failure = "break"
[[bodies]]
name = "chain"
nodes = "c.nodes"
links = "c.links"
material = "strong"
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [2]
fix = ["y"]
[[bodies.supports]]
nodes = [3]
fix = ["x", "y"]
displacement = [0.001, 0.0]
schedule = [0.5, 1.0, 0.0, -1.0, -2.0]
{contact}
"#
        ),
    )
    .unwrap();
    scene
}

/// Without obstacles and without `[contact]`, the broken bar's crack pushed shut carries the
/// series force of bar 1 (k₁ = 1e5 N/m) and the closed crack (the default penalty k = 100 ×
/// mean E A / L = 1e7 N/m): F = k k₁ |d| / (k₁ + k) and u₂ = k d / (k₁ + k), to 1e-9 (F =
/// 99.0099 N at d = −1 mm). The run stays on the body solver up to step 3 (the crack is open
/// or just shut: nothing presses) and goes on with contact from step 4, where the crack
/// closes; the break is recorded once, at load factor 0.8 (to 1e-12). With `[contact] self =
/// false` the same crack carries nothing.
#[test]
fn a_crack_pushed_shut_without_a_contact_table_carries_the_closed_form_force() {
    for contact in ["", "[contact]\nself = false"] {
        let dir = tempfile::tempdir().unwrap();
        let scene = chain_scene(dir.path(), contact);
        let out = dir.path().join("out");
        let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
        assert!(summary.failure.is_none() && summary.collapse.is_none());
        assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
        assert_eq!((summary.breaks[0].step, summary.breaks[0].member), (2, 2));
        assert!((summary.breaks[0].load_factor - 0.8).abs() < 1e-12);
        let self_on = contact.is_empty();
        if self_on {
            assert_eq!(switched(&summary), vec![4], "{:?}", summary.steps);
            // Steps 0-3 on the body solver, 4-5 with contact.
            assert_eq!(summary.steps[3].contact_iterations, 0);
            assert!(summary.steps[4].contact_iterations > 0);
        } else {
            assert!(switched(&summary).is_empty());
        }
        let (k1, k) = (1e5, PENALTY_FACTOR * 1e5);
        for (s, d3) in [(3usize, 0.0), (4, -1e-3), (5, -2e-3f64)] {
            let step = step_file(&out, "c", s);
            let body = &step["bodies"][0];
            assert_eq!(body["broken"], serde_json::json!([2]));
            let u2 = vector(&body["displacements"][1])[0];
            let f1 = body["axial_forces"][0].as_f64().unwrap();
            let closes = self_on && d3 < 0.0;
            let (u2_expected, force) = if closes {
                (k * d3 / (k1 + k), k * k1 * d3.abs() / (k1 + k))
            } else {
                (0.0, 0.0)
            };
            assert!(
                (u2 - u2_expected).abs() <= 1e-9 * u2_expected.abs().max(1e-3),
                "{contact:?} step {s}: u2 = {u2}, expected {u2_expected}"
            );
            assert!(
                (f1 + force).abs() <= 1e-9 * force.max(1.0),
                "{contact:?} step {s}: bar 1 carries {f1}, expected {}",
                -force
            );
            let contacts = body["contacts"].as_array().unwrap();
            if closes {
                let on = |n: u64| {
                    contacts
                        .iter()
                        .find(|c| c["node"] == n)
                        .map(|c| vector(&c["force"])[0])
                        .unwrap_or(0.0)
                };
                assert!((on(2) + force).abs() <= 1e-9 * force, "{contacts:?}");
                assert!((on(3) - force).abs() <= 1e-9 * force, "{contacts:?}");
            } else {
                assert!(contacts.is_empty(), "{contacts:?}");
            }
        }
    }
}

/// A bar of 5 × 2 crossed square cells (side 0.1 m, E = 1e9 Pa, A = 1e-4 m²) whose middle
/// column of cells (x from 0.2 to 0.3 m) is joined by weak members (tensile strength 1e5 Pa);
/// left end held, right end moved along x by 2 mm × [1, 0, −1]. Returns the scene and the node
/// positions.
fn split_bar(dir: &Path, contact: &str) -> (std::path::PathBuf, Vec<[f64; 2]>) {
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
            for (p, q) in [
                (id(c, r), id(c + 1, r)),
                (id(c, r), id(c, r + 1)),
                (id(c, r), id(c + 1, r + 1)),
                (id(c + 1, r), id(c, r + 1)),
            ] {
                links.push((p, q));
            }
        }
        links.push((id(c, 2), id(c + 1, 2)));
    }
    for r in 0..2 {
        links.push((id(5, r), id(5, r + 1)));
    }
    let x = |n: usize| positions[n - 1][0];
    let crosses = |p: usize, q: usize| {
        let (a, b) = (x(p).min(x(q)), x(p).max(x(q)));
        (a - 0.2).abs() < 1e-9 && (b - 0.3).abs() < 1e-9
    };
    let nodes: String = positions
        .iter()
        .map(|p| format!("{} {}\n", p[0], p[1]))
        .collect();
    let links: String = links
        .iter()
        .map(|&(p, q)| {
            let m = if crosses(p, q) { "weak" } else { "strong" };
            format!("{p} {q} {m}\n")
        })
        .collect();
    std::fs::write(dir.join("b.nodes"), nodes).unwrap();
    std::fs::write(dir.join("b.links"), links).unwrap();
    let scene = dir.join("b.toml");
    std::fs::write(
        &scene,
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
tensile_strength = 1e5
failure = "break"
[[bodies]]
name = "bar"
nodes = "b.nodes"
links = "b.links"
material = "strong"
[[bodies.supports]]
nodes = [1, 2, 3]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [16, 17, 18]
fix = ["x", "y"]
displacement = [0.002, 0.0]
schedule = [1.0, 0.0, -1.0]
{contact}
"#
        ),
    )
    .unwrap();
    (scene, positions)
}

/// The split bar's two pieces, pulled apart (step 1: all 7 weak members break in tension),
/// brought back (step 2: nothing touches) and pushed 2 mm into each other (step 3): with
/// self-contact (no `[contact]` table) the closed crack holds them apart: every bridge's
/// closure is within the penalty bound (its contact force / k, and the whole push / k), the
/// forces the left piece receives from the right are equal and opposite to those the right
/// receives (1e-9 of their size) and balance the left support's reactions (1e-9); the set-up
/// is mirror-symmetric about y = 0.1 m and so is the answer (1e-9 of the largest
/// displacement). With `[contact] self = false` the right piece moves through the crack
/// rigidly (closure 2 mm, nothing carried).
#[test]
fn two_pieces_of_a_broken_body_pushed_together_do_not_pass_through() {
    for contact in ["", "[contact]\nself = false"] {
        let dir = tempfile::tempdir().unwrap();
        let (scene, p) = split_bar(dir.path(), contact);
        let out = dir.path().join("out");
        let world = load_scene(&scene).unwrap();
        let summary = run(&world, &out, &|| {}).expect("a result");
        assert!(summary.failure.is_none() && summary.collapse.is_none());
        assert_eq!(summary.breaks.len(), 7, "{:?}", summary.breaks);
        assert!(summary.breaks.iter().all(|b| b.step == 1));
        let self_on = contact.is_empty();
        assert_eq!(switched(&summary), if self_on { vec![3] } else { vec![] });
        let step = step_file(&out, "b", 3);
        let body = &step["bodies"][0];
        let u: Vec<Vec<f64>> = body["displacements"]
            .as_array()
            .unwrap()
            .iter()
            .map(vector)
            .collect();
        // 100 × mean E A / L: 27 members of 0.1 m, 20 diagonals of 0.1 √2 m.
        let k = PENALTY_FACTOR * 1e6 * (27.0 + 20.0 / 2f64.sqrt()) / 47.0;
        assert!((k - default_penalty(&world.bodies[0])).abs() <= 1e-9 * k);
        let left = |n: usize| p[n][0] < 0.25;
        let contacts = body["contacts"].as_array().unwrap();
        let (mut on_left, mut on_right) = (0.0, 0.0);
        for c in contacts {
            let n = c["node"].as_u64().unwrap() as usize - 1;
            let f = vector(&c["force"])[0];
            if left(n) {
                on_left += f;
            } else {
                on_right += f;
            }
        }
        // Closure of each horizontal bridge (nodes at x = 0.2 and 0.3, same y).
        let closure: Vec<f64> = (0..3).map(|r| u[6 + r][0] - u[9 + r][0]).collect();
        if !self_on {
            assert!(contacts.is_empty());
            for c in &closure {
                assert!((c - 0.002).abs() < 1e-12, "{closure:?}");
            }
            continue;
        }
        let push = -on_left;
        assert!(push > 0.0, "{contacts:?}");
        assert!(
            (on_left + on_right).abs() <= 1e-9 * push,
            "{on_left} vs {on_right}"
        );
        let reactions: f64 = body["reactions"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| left(r["node"].as_u64().unwrap() as usize - 1))
            .map(|r| vector(&r["force"])[0])
            .sum();
        assert!(
            (reactions - push).abs() <= 1e-9 * push,
            "{reactions} vs {push}"
        );
        let penetration = summary.steps[3].max_penetration;
        assert!(penetration > 0.0 && penetration <= push / k * (1.0 + 1e-9));
        for c in &closure {
            assert!(
                *c <= push / k * (1.0 + 1e-9),
                "{closure:?}, bound {}",
                push / k
            );
        }
        let umax = u.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        for (n, q) in p.iter().enumerate() {
            let mirror = p
                .iter()
                .position(|r| (r[0] - q[0]).abs() < 1e-9 && (r[1] + q[1] - 0.2).abs() < 1e-9)
                .unwrap();
            assert!((u[n][0] - u[mirror][0]).abs() <= 1e-9 * umax);
            assert!((u[n][1] + u[mirror][1]).abs() <= 1e-9 * umax);
        }
    }
}

/// `paper_fracture` breaks and collapses without anything touching: it stays on the body
/// solver (no step goes over to contact), so its results are those of the event-by-event
/// solver alone.
#[test]
fn a_breaking_body_that_touches_nothing_stays_on_the_body_solver() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/paper_fracture.toml");
    let summary = run(&load_scene(&scene).unwrap(), dir.path(), &|| {}).expect("a result");
    assert!(summary.collapse.is_some());
    assert!(switched(&summary).is_empty());
    assert!(summary.steps.iter().all(|s| s.contact_iterations == 0));
}

/// `self` of the wrong type in a scene without obstacles is still refused, naming the file
/// and the key.
#[test]
fn self_of_the_wrong_type_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = chain_scene(dir.path(), "[contact]\nself = 1");
    let err = format!("{:#}", load_scene(&scene).unwrap_err());
    assert!(err.contains("c.toml") && err.contains("self"), "{err}");
}

/// A U of crossed square cells (side 0.1 m, mirror-symmetric about x = 0): a base 8 cells wide
/// and 2 high, two arms 2 cells wide and 6 high, 0.4 m apart; the base's bottom held, the 3
/// top nodes of each arm pushed inward by 1500 N each over 4 steps (an arm alone would pass the
/// middle). Its material breaks, at a strength no member reaches. `contact` is the scene's
/// `[contact]` table (empty: none).
fn u_scene(dir: &Path, contact: &str) -> std::path::PathBuf {
    let mut keys: Vec<(i32, i32)> = Vec::new();
    let mut links: Vec<(usize, usize)> = Vec::new();
    let mut id = |k: (i32, i32)| -> usize {
        match keys.iter().position(|&q| q == k) {
            Some(i) => i + 1,
            None => {
                keys.push(k);
                keys.len()
            }
        }
    };
    let mut cells: Vec<(i32, i32)> = (0..8).flat_map(|c| (0..2).map(move |r| (c, r))).collect();
    cells.extend((2..8).flat_map(|r| [0, 1, 6, 7].map(|c| (c, r))));
    for (c, r) in cells {
        let (a, b, cc, d) = (
            id((c, r)),
            id((c + 1, r)),
            id((c + 1, r + 1)),
            id((c, r + 1)),
        );
        for (p, q) in [(a, b), (b, cc), (d, cc), (a, d), (a, cc), (b, d)] {
            let key = (p.min(q), p.max(q));
            if !links.contains(&key) {
                links.push(key);
            }
        }
    }
    let p: Vec<[f64; 2]> = keys
        .iter()
        .map(|&(c, r)| [-0.4 + c as f64 * 0.1, r as f64 * 0.1])
        .collect();
    let pick = |f: &dyn Fn(&[f64; 2]) -> bool| -> String {
        let list: Vec<String> = (0..p.len())
            .filter(|&i| f(&p[i]))
            .map(|i| (i + 1).to_string())
            .collect();
        list.join(", ")
    };
    let bottom = pick(&|q| q[1].abs() < 1e-9);
    let left = pick(&|q| (q[1] - 0.8).abs() < 1e-9 && q[0] < 0.0);
    let right = pick(&|q| (q[1] - 0.8).abs() < 1e-9 && q[0] > 0.0);
    let nodes: String = p.iter().map(|q| format!("{} {}\n", q[0], q[1])).collect();
    let links: String = links.iter().map(|(a, b)| format!("{a} {b}\n")).collect();
    std::fs::write(dir.join("u.nodes"), nodes).unwrap();
    std::fs::write(dir.join("u.links"), links).unwrap();
    let scene = dir.join("u.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "u"
steps = 4
[[materials]]
name = "m"
youngs_modulus = 1e9
area = 1e-4
strength = 1e15
failure = "break"
[[bodies]]
name = "u"
nodes = "u.nodes"
links = "u.links"
material = "m"
[[bodies.supports]]
nodes = [{bottom}]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [{left}]
force = [1500.0, 0.0]
[[bodies.loads]]
nodes = [{right}]
force = [-1500.0, 0.0]
{contact}
"#
        ),
    )
    .unwrap();
    scene
}

/// The arms of a breaking U (no member breaks) pushed onto each other, in a scene without
/// `[contact]`: its own surface holds them (the surface rule, not a crack). Up to the step at
/// whose end they first touch it is solved by the body solver, and matches the contact
/// solver's answer of the same scene with `[contact] self = true` (1e-9 of the largest
/// displacement); from that step on it is solved with contact, the steps before solved again
/// to reach its start, so its step files are byte-identical to that scene's.
#[test]
fn a_breaking_body_folded_onto_its_own_surface_goes_on_with_contact() {
    let dir = tempfile::tempdir().unwrap();
    let runs: Vec<(std::path::PathBuf, Summary)> = ["", "[contact]\nself = true"]
        .iter()
        .enumerate()
        .map(|(k, contact)| {
            let d = dir.path().join(k.to_string());
            std::fs::create_dir_all(&d).unwrap();
            let scene = u_scene(&d, contact);
            let out = d.join("out");
            let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
            (out, summary)
        })
        .collect();
    let (watched, contact) = (&runs[0], &runs[1]);
    assert!(watched.1.breaks.is_empty());
    let from = switched(&watched.1);
    assert_eq!(from.len(), 1, "{:?}", watched.1.steps);
    let from = from[0];
    assert!(from >= 1);
    let last = step_file(&contact.0, "u", 4);
    assert!(!last["bodies"][0]["contacts"].as_array().unwrap().is_empty());
    for s in 0..=4 {
        let read = |out: &Path| std::fs::read(out.join(format!("u/steps/{s:04}.json"))).unwrap();
        if s >= from {
            assert!(read(&watched.0) == read(&contact.0), "step {s} differs");
            continue;
        }
        let displacements = |out: &Path| -> Vec<f64> {
            step_file(out, "u", s)["bodies"][0]["displacements"]
                .as_array()
                .unwrap()
                .iter()
                .flat_map(vector)
                .collect()
        };
        let (a, b) = (displacements(&watched.0), displacements(&contact.0));
        let umax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (x, y) in a.iter().zip(&b) {
            assert!(
                (x - y).abs() <= 1e-9 * umax.max(1e-300),
                "step {s}: {x} vs {y}"
            );
        }
    }
}
