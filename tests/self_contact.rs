//! Self-contact (`[contact] self`): the arms of a U pushed together touch and do not pass
//! through each other; a crack that opened and is pushed shut carries contact; a nonsense value
//! of the key is a clear error.

use linkage::scene::{load_scene, run};
use serde_json::Value;
use std::path::Path;

/// Nodes and links of a lattice of square cells of side `h` (m) with both diagonals, one cell
/// per `(column, row)` of `cells`, the cell's lower left corner at `(x0 + column h, row h)`.
/// Returns the node lines (1-based numbering by first use), the link lines and the node
/// positions.
fn lattice(cells: &[(i32, i32)], h: f64, x0: f64) -> (String, String, Vec<[f64; 2]>) {
    let mut keys: Vec<(i32, i32)> = Vec::new();
    let mut links: Vec<(usize, usize)> = Vec::new();
    let id = |k: (i32, i32), keys: &mut Vec<(i32, i32)>| -> usize {
        match keys.iter().position(|&q| q == k) {
            Some(i) => i + 1,
            None => {
                keys.push(k);
                keys.len()
            }
        }
    };
    for &(c, r) in cells {
        let a = id((c, r), &mut keys);
        let b = id((c + 1, r), &mut keys);
        let cc = id((c + 1, r + 1), &mut keys);
        let d = id((c, r + 1), &mut keys);
        for (p, q) in [(a, b), (b, cc), (d, cc), (a, d), (a, cc), (b, d)] {
            let key = (p.min(q), p.max(q));
            if !links.contains(&key) {
                links.push(key);
            }
        }
    }
    let positions: Vec<[f64; 2]> = keys
        .iter()
        .map(|&(c, r)| [x0 + c as f64 * h, r as f64 * h])
        .collect();
    let nodes = positions
        .iter()
        .map(|p| format!("{} {}\n", p[0], p[1]))
        .collect();
    let links = links.iter().map(|(p, q)| format!("{p} {q}\n")).collect();
    (nodes, links, positions)
}

/// A U of crossed cells of side 0.1 m, mirror-symmetric about x = 0: a base 8 cells wide and 2
/// high, two arms 2 cells wide and 6 high; the gap between the arms is 0.4 m.
fn u_shape() -> (String, String, Vec<[f64; 2]>) {
    let mut cells = Vec::new();
    for c in 0..8 {
        for r in 0..2 {
            cells.push((c, r));
        }
    }
    for r in 2..8 {
        for c in [0, 1, 6, 7] {
            cells.push((c, r));
        }
    }
    lattice(&cells, 0.1, -0.4)
}

fn nodes_where(positions: &[[f64; 2]], pick: impl Fn(&[f64; 2]) -> bool) -> String {
    let list: Vec<String> = positions
        .iter()
        .enumerate()
        .filter(|(_, p)| pick(p))
        .map(|(i, _)| (i + 1).to_string())
        .collect();
    list.join(", ")
}

/// The U scene: base bottom held, the 3 top nodes of each arm pushed inward by `force` N each;
/// `self_line` the `[contact]` line on self-contact.
fn u_scene(dir: &Path, self_line: &str, force: f64) -> std::path::PathBuf {
    let (nodes, links, p) = u_shape();
    std::fs::write(dir.join("u.nodes"), nodes).unwrap();
    std::fs::write(dir.join("u.links"), links).unwrap();
    let bottom = nodes_where(&p, |q| q[1].abs() < 1e-9);
    let left_top = nodes_where(&p, |q| (q[1] - 0.8).abs() < 1e-9 && q[0] < 0.0);
    let right_top = nodes_where(&p, |q| (q[1] - 0.8).abs() < 1e-9 && q[0] > 0.0);
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
[[bodies]]
name = "u"
nodes = "u.nodes"
links = "u.links"
material = "m"
[[bodies.supports]]
nodes = [{bottom}]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [{left_top}]
force = [{force}, 0.0]
[[bodies.loads]]
nodes = [{right_top}]
force = [{minus}, 0.0]
[contact]
{self_line}
"#,
            minus = -force
        ),
    )
    .unwrap();
    scene
}

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

/// Pushed by 1500 N on each of its 3 top nodes, an arm alone would move its tip inward by
/// about 0.3 m, past the middle (x = 0, 0.2 m away). With `self = true` the arms meet at the
/// middle and stay apart: no node of the left arm beyond x = 0 by more than the contact
/// tolerance (1% of the mean member length), the summary's largest penetration within the
/// penalty's `F / k` for the total push and the tolerance; the contact forces the left half
/// receives are equal and opposite to those of the right half (1e-9 of their size); and the
/// mirror-symmetric set-up gives a mirror-symmetric answer (every node's displacement against
/// its mirror node's, 1e-9 of the largest). With `self = false` the same loads push the arms
/// through each other.
#[test]
fn the_arms_of_a_u_pushed_together_touch_and_do_not_pass_through() {
    let (_, _, p) = u_shape();
    let force = 1500.0;
    // Without self-contact: the left arm's tip passes the middle.
    let dir = tempfile::tempdir().unwrap();
    let scene = u_scene(dir.path(), "self = false", force);
    let out = dir.path().join("out");
    let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
    assert!(summary.failure.is_none());
    let step = step_file(&out, "u", 4);
    let positions = step["bodies"][0]["positions"].as_array().unwrap();
    let deepest_left = (0..p.len())
        .filter(|&i| p[i][0] < 0.0)
        .map(|i| vector(&positions[i])[0])
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!("self = false: the left arm reaches x = {deepest_left} m");
    assert!(
        deepest_left > 0.02,
        "without self-contact the left arm reaches only x = {deepest_left}"
    );

    // With self-contact.
    let dir = tempfile::tempdir().unwrap();
    let scene = u_scene(dir.path(), "self = true", force);
    let out = dir.path().join("out");
    let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
    assert!(summary.failure.is_none());
    let last = summary.steps.last().unwrap();
    assert!(last.warnings.is_empty(), "{:?}", last.warnings);
    let step = step_file(&out, "u", 4);
    let body = &step["bodies"][0];
    let positions: Vec<Vec<f64>> = body["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(vector)
        .collect();
    let u: Vec<Vec<f64>> = body["displacements"]
        .as_array()
        .unwrap()
        .iter()
        .map(vector)
        .collect();
    // Mean member length (0.1 and 0.1 √2 in equal numbers... counted from the links).
    let (_, links, _) = u_shape();
    let lengths: Vec<f64> = links
        .lines()
        .map(|l| {
            let ij: Vec<usize> = l.split_whitespace().map(|s| s.parse().unwrap()).collect();
            let (a, b) = (p[ij[0] - 1], p[ij[1] - 1]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        })
        .collect();
    let tolerance = 0.01 * lengths.iter().sum::<f64>() / lengths.len() as f64;
    let deepest_left = (0..p.len())
        .filter(|&i| p[i][0] < 0.0)
        .map(|i| positions[i][0])
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!(
        "self = true: the left arm reaches x = {deepest_left} m, penetration {} m, tolerance {tolerance} m, {} contact entries",
        last.max_penetration,
        body["contacts"].as_array().unwrap().len()
    );
    assert!(
        deepest_left <= tolerance && deepest_left > -0.01,
        "the left arm reaches x = {deepest_left} (tolerance {tolerance})"
    );
    // The default penalty k = 100 × mean(E A / L); the push is 3 × 1500 N per arm.
    let ea = 1e9 * 1e-4;
    let k = 100.0 * lengths.iter().map(|l| ea / l).sum::<f64>() / lengths.len() as f64;
    assert!(
        last.max_penetration > 0.0
            && last.max_penetration <= 3.0 * force / k
            && last.max_penetration <= tolerance,
        "penetration {} against F/k = {} and tolerance {tolerance}",
        last.max_penetration,
        3.0 * force / k
    );
    // Contact forces of the two halves: equal and opposite.
    let (mut left, mut right) = ([0.0; 2], [0.0; 2]);
    let contacts = body["contacts"].as_array().unwrap();
    assert!(!contacts.is_empty());
    for c in contacts {
        assert_eq!(c["with"], "u");
        let node = c["node"].as_u64().unwrap() as usize - 1;
        let f = vector(&c["force"]);
        let side = if p[node][0] < 0.0 {
            &mut left
        } else {
            &mut right
        };
        side[0] += f[0];
        side[1] += f[1];
    }
    let size = left[0].hypot(left[1]);
    eprintln!("contact force on the left half {left:?} N, on the right half {right:?} N");
    assert!(
        size > 100.0,
        "the arms press on each other with {size} N only"
    );
    assert!(
        (left[0] + right[0]).abs() <= 1e-9 * size && (left[1] + right[1]).abs() <= 1e-9 * size,
        "left {left:?} right {right:?}"
    );
    // Mirror symmetry: u_x(mirror) = −u_x, u_y(mirror) = u_y.
    let largest = u.iter().map(|v| v[0].hypot(v[1])).fold(0.0, f64::max);
    for (i, q) in p.iter().enumerate() {
        let m = p
            .iter()
            .position(|r| (r[0] + q[0]).abs() < 1e-9 && (r[1] - q[1]).abs() < 1e-9)
            .expect("a mirror node");
        assert!(
            (u[i][0] + u[m][0]).abs() <= 1e-9 * largest
                && (u[i][1] - u[m][1]).abs() <= 1e-9 * largest,
            "node {} at {q:?}: {:?} against its mirror {}: {:?}",
            i + 1,
            u[i],
            m + 1,
            u[m]
        );
    }
}

/// A chain of two bars along x, 1 m each (E A = 1e5 N, so k₁ = 1e5 N/m): node 1 held, node 2
/// held along y, node 3 moved along x by a prescribed displacement d on the schedule 0.5, 1,
/// 0, −1, −2 of 1 mm. Bar 2 (tensile strength 0.4 MPa: 40 N) breaks at d = 0.8 mm in step 2
/// (the bars carry `k₁ d / 2`). Node 3 then comes back; at step 4 it is 1 mm left of its rest
/// place and the crack of bar 2 has closed by 1 mm plus node 2's move: the broken bar's ends
/// press on each other with the penalty k = 1e6 N/m. Node 2 balances bar 1 against it:
/// `u₂ = −k |d| / (k₁ + k)`, the force `k k₁ |d| / (k₁ + k)` (90.909 N at d = −1 mm, twice at
/// −2 mm), to 1e-9. Without self-contact the broken bar carries nothing (node 2 stays put and
/// the crack faces pass through each other by |d|).
#[test]
fn a_crack_pushed_shut_carries_contact_with_the_penalty_of_its_faces() {
    for self_on in [None, Some(true), Some(false)] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("c.nodes"), "0 0\n1 0\n2 0\n").unwrap();
        std::fs::write(d.join("c.links"), "1 2 strong\n2 3 weak\n").unwrap();
        let line = match self_on {
            None => String::new(),
            Some(v) => format!("self = {v}"),
        };
        let scene = d.join("c.toml");
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
[contact]
penalty = 1e6
{line}
"#
            ),
        )
        .unwrap();
        let out = d.join("out");
        let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
        assert!(summary.failure.is_none() && summary.collapse.is_none());
        assert_eq!(summary.breaks.len(), 1, "{:?}", summary.breaks);
        assert_eq!((summary.breaks[0].step, summary.breaks[0].member), (2, 2));
        assert!((summary.breaks[0].load_factor - 0.8).abs() < 1e-8);
        let (k1, k) = (1e5, 1e6);
        for (s, d3) in [(3usize, 0.0), (4, -1e-3), (5, -2e-3f64)] {
            let step = step_file(&out, "c", s);
            let body = &step["bodies"][0];
            let u2 = vector(&body["displacements"][1])[0];
            let f1 = body["axial_forces"][0].as_f64().unwrap();
            let closes = self_on != Some(false) && d3 < 0.0;
            let (u2_expected, force) = if closes {
                (k * d3 / (k1 + k), k * k1 * d3.abs() / (k1 + k))
            } else {
                (0.0, 0.0)
            };
            assert!(
                (u2 - u2_expected).abs() <= 1e-9 * u2_expected.abs().max(1e-3),
                "self {self_on:?} step {s}: u2 = {u2}, expected {u2_expected}"
            );
            assert!(
                (f1 + force).abs() <= 1e-9 * force.max(1.0),
                "self {self_on:?} step {s}: bar 1 carries {f1}, expected {}",
                -force
            );
            let contacts = body["contacts"].as_array().unwrap();
            if closes {
                // Node 2 receives the push to the left, node 3 the push to the right.
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

/// `self = "yes"` is not a boolean: the error names the file, the line and the key.
#[test]
fn self_with_a_nonsense_value_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let scene = u_scene(dir.path(), "self = \"yes\"", 1.0);
    let err = format!("{:#}", load_scene(&scene).unwrap_err());
    assert!(
        err.contains("u.toml") && err.contains("self") && err.contains("bool"),
        "{err}"
    );
}

/// Two cubes of 2 × 2 × 2 crossed cells (side 0.1 m, every cell's 8 corners joined pairwise)
/// as ONE body, side by side along x with a gap of 0.04 m; outward surface patches. Returns
/// the node, link and patch lines and the node positions.
fn two_cubes() -> (String, String, String, Vec<[f64; 3]>) {
    let (n, h, gap) = (2usize, 0.1, 0.04);
    let side = n + 1;
    let per_cube = side * side * side;
    let id =
        |cube: usize, i: usize, j: usize, l: usize| cube * per_cube + i + side * (j + side * l);
    let mut positions = Vec::new();
    for cube in 0..2 {
        let x0 = cube as f64 * (n as f64 * h + gap);
        for l in 0..side {
            for j in 0..side {
                for i in 0..side {
                    positions.push([x0 + i as f64 * h, j as f64 * h, l as f64 * h]);
                }
            }
        }
    }
    let mut links: Vec<(usize, usize)> = Vec::new();
    let mut patches: Vec<[usize; 3]> = Vec::new();
    for cube in 0..2 {
        for l in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let corners: Vec<usize> = (0..8)
                        .map(|c| id(cube, i + (c & 1), j + ((c >> 1) & 1), l + ((c >> 2) & 1)))
                        .collect();
                    for a in 0..8 {
                        for b in a + 1..8 {
                            let key = (corners[a].min(corners[b]), corners[a].max(corners[b]));
                            if !links.contains(&key) {
                                links.push(key);
                            }
                        }
                    }
                }
            }
        }
        // Each face: its outward axis, the side (0 or n) and in-plane axes (u, v) with
        // u × v outward, so each quad's corners run counter-clockwise seen from outside.
        for (axis, at, u, v) in [
            (0, n, 1, 2),
            (0, 0, 2, 1),
            (1, n, 2, 0),
            (1, 0, 0, 2),
            (2, n, 0, 1),
            (2, 0, 1, 0),
        ] {
            for a in 0..n {
                for b in 0..n {
                    let corner = |da: usize, db: usize| {
                        let mut c = [0usize; 3];
                        c[axis] = at;
                        c[u] = a + da;
                        c[v] = b + db;
                        id(cube, c[0], c[1], c[2]) + 1
                    };
                    let (p, q, r, s) = (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    patches.push([p, q, r]);
                    patches.push([p, r, s]);
                }
            }
        }
    }
    let nodes = positions
        .iter()
        .map(|p| format!("{} {} {}\n", p[0], p[1], p[2]))
        .collect();
    let links = links
        .iter()
        .map(|(p, q)| format!("{} {}\n", p + 1, q + 1))
        .collect();
    let patches = patches
        .iter()
        .map(|t| format!("{} {} {}\n", t[0], t[1], t[2]))
        .collect();
    (nodes, links, patches, positions)
}

/// The two cubes of [`two_cubes`] as one body: each held on its outer face, the 9 nodes of
/// each inner face pushed towards the other cube by `force` N each; `self_line` the
/// `[contact]` line on self-contact.
fn cubes_scene(dir: &Path, self_line: &str, force: f64) -> std::path::PathBuf {
    let (nodes, links, patches, p) = two_cubes();
    std::fs::write(dir.join("c.nodes"), nodes).unwrap();
    std::fs::write(dir.join("c.links"), links).unwrap();
    std::fs::write(dir.join("c.patches"), patches).unwrap();
    let near = |x: f64| move |q: &[f64; 3]| (q[0] - x).abs() < 1e-9;
    let outer: Vec<String> = [0.0, 0.44]
        .iter()
        .flat_map(|&x| {
            p.iter()
                .enumerate()
                .filter(move |(_, q)| near(x)(q))
                .map(|(i, _)| (i + 1).to_string())
        })
        .collect();
    let list = |x: f64| -> String {
        p.iter()
            .enumerate()
            .filter(|(_, q)| near(x)(q))
            .map(|(i, _)| (i + 1).to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let scene = dir.join("c.toml");
    std::fs::write(
        &scene,
        format!(
            r#"name = "cubes"
steps = 4
[[materials]]
name = "m"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "pair"
nodes = "c.nodes"
links = "c.links"
patches = "c.patches"
material = "m"
[[bodies.supports]]
nodes = [{outer}]
fix = ["x", "y", "z"]
[[bodies.loads]]
nodes = [{left}]
force = [{force}, 0.0, 0.0]
[[bodies.loads]]
nodes = [{right}]
force = [{minus}, 0.0, 0.0]
[contact]
{self_line}
"#,
            outer = outer.join(", "),
            left = list(0.2),
            right = list(0.24),
            minus = -force
        ),
    )
    .unwrap();
    scene
}

/// 3D: two pieces of one body (two cubes, each held on its outer face) whose inner faces are
/// pushed towards each other. Without self-contact the faces pass through each other (each
/// moves past the middle plane x = 0.22 m); with `self = true` they meet there and stay apart
/// (no node of the left cube beyond the middle by more than 1 mm), the contact forces on the
/// two cubes are equal and opposite (1e-9 of their size), and the set-up's mirror symmetry
/// about the middle plane holds in the answer to 1e-3 of the largest displacement (see below
/// why not to round-off).
#[test]
fn two_pieces_of_one_3d_body_pressed_together_touch_and_do_not_pass_through() {
    let (_, _, _, p) = two_cubes();
    let force = 500.0;
    let middle = 0.22;
    let dir = tempfile::tempdir().unwrap();
    let scene = cubes_scene(dir.path(), "self = false", force);
    let out = dir.path().join("out");
    let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
    assert!(summary.failure.is_none());
    let step = step_file(&out, "cubes", 4);
    let positions = step["bodies"][0]["positions"].as_array().unwrap();
    let deepest_left = (0..p.len())
        .filter(|&i| p[i][0] < middle)
        .map(|i| vector(&positions[i])[0])
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!("self = false: the left cube reaches x = {deepest_left} m");
    assert!(
        deepest_left > middle + 0.005,
        "without self-contact the left cube reaches only x = {deepest_left}"
    );

    let dir = tempfile::tempdir().unwrap();
    let scene = cubes_scene(dir.path(), "self = true", force);
    let out = dir.path().join("out");
    let summary = run(&load_scene(&scene).unwrap(), &out, &|| {}).expect("a result");
    assert!(summary.failure.is_none());
    let last = summary.steps.last().unwrap();
    assert!(last.warnings.is_empty(), "{:?}", last.warnings);
    let step = step_file(&out, "cubes", 4);
    let body = &step["bodies"][0];
    let positions: Vec<Vec<f64>> = body["positions"]
        .as_array()
        .unwrap()
        .iter()
        .map(vector)
        .collect();
    let u: Vec<Vec<f64>> = body["displacements"]
        .as_array()
        .unwrap()
        .iter()
        .map(vector)
        .collect();
    // Members of 0.1, 0.1 √2 and 0.1 √3 m: the tolerance is 1% of their mean, at least 1 mm.
    let tolerance = 0.001;
    let deepest_left = (0..p.len())
        .filter(|&i| p[i][0] < middle)
        .map(|i| positions[i][0])
        .fold(f64::NEG_INFINITY, f64::max);
    eprintln!("self = true: the left cube reaches x = {deepest_left} m");
    assert!(
        deepest_left < middle + tolerance,
        "the left cube passed the middle: x = {deepest_left}"
    );
    assert!(deepest_left > middle - 0.02, "the cubes did not meet");
    // Contact forces on each cube: equal and opposite.
    let mut on = [[0.0f64; 3]; 2];
    let contacts = body["contacts"].as_array().unwrap();
    assert!(!contacts.is_empty());
    for c in contacts {
        let node = c["node"].as_u64().unwrap() as usize - 1;
        let f = vector(&c["force"]);
        let side = usize::from(p[node][0] > middle);
        for k in 0..3 {
            on[side][k] += f[k];
        }
    }
    let size = on[0][0].abs();
    eprintln!(
        "contact force on the left cube {:?}, on the right {:?}",
        on[0], on[1]
    );
    assert!(
        size > 0.1 * 9.0 * force,
        "the contact carries only {size} N"
    );
    for k in 0..3 {
        assert!((on[0][k] + on[1][k]).abs() <= 1e-9 * size, "{on:?}");
    }
    // Mirror symmetry about x = middle: node i of the left cube mirrors node mirror(i) of the
    // right one (i, j, l) -> (2 - i, j, l); its x displacement is opposite, y and z the same.
    let largest = u
        .iter()
        .map(|d| d.iter().map(|c| c * c).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    // The faces' nodes meet the other face's patch corners, where several patches tie: each
    // node presses the first of them in patch order, which is not mirror-symmetric, so the
    // answer is symmetric to 1.4e-4 of the largest displacement here, not to round-off.
    let mut worst = 0.0f64;
    for i in 0..27 {
        let (a, j, l) = (i % 3, (i / 3) % 3, i / 9);
        let m = 27 + (2 - a) + 3 * (j + 3 * l);
        worst = worst
            .max((u[i][0] + u[m][0]).abs())
            .max((u[i][1] - u[m][1]).abs())
            .max((u[i][2] - u[m][2]).abs());
    }
    eprintln!(
        "mirror symmetry to {} of the largest displacement",
        worst / largest
    );
    assert!(worst <= 1e-9 * largest, "mirror symmetry broken by {worst}");
}
