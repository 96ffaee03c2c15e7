//! Sharp obstacle features (issue 11, item 1): a node inside a polyhedral obstacle is pushed out
//! through the face (edge, corner) it crossed, and an obstacle's sharp edge between the nodes of
//! a coarse body still presses its patches (2D: boundary segments). Each set-up is symmetric:
//! the answer must be too, on the condensed and the coupled path alike.

use linkage::scene::{load_scene, BodyResult, Simulation, StepResult};
use std::collections::HashMap;
use std::path::PathBuf;

/// The last step of the scene `scene` (with `files` beside it), solved condensed (the default)
/// or coupled (`[contact] condense = false`).
fn last_step(files: &[(&str, &str)], scene: &str, condense: bool) -> StepResult {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path: PathBuf = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let mut world = load_scene(&path).unwrap();
    world.contact.condense = condense;
    let mut sim = Simulation::new(&world).expect("builds");
    let mut last = None;
    for k in 0..=world.steps {
        last = Some(sim.step(k).expect("solves").0);
    }
    last.unwrap()
}

/// The total contact force the body receives, N.
fn total(body: &BodyResult) -> [f64; 3] {
    let mut f = [0.0; 3];
    for c in &body.contacts {
        for (k, x) in c.force.iter().enumerate() {
            f[k] += x;
        }
    }
    f
}

/// Sideways over vertical (y) of a force.
fn sideways_ratio(f: &[f64; 3]) -> f64 {
    (f[0] * f[0] + f[2] * f[2]).sqrt() / f[1].abs()
}

/// The largest difference between the displacements of the nodes mirrored about the plane
/// `axis` = `at` (m), relative to the largest displacement.
fn mirror_error(body: &BodyResult, axis: usize, at: f64) -> f64 {
    reflection_error(body, &[axis], at)
}

/// As [`mirror_error`], reflecting every axis of `axes` about `at` (two axes: a half turn).
fn reflection_error(body: &BodyResult, axes: &[usize], at: f64) -> f64 {
    let origin: Vec<Vec<f64>> = body
        .positions
        .iter()
        .zip(&body.displacements)
        .map(|(p, u)| p.iter().zip(u).map(|(p, u)| p - u).collect())
        .collect();
    let key = |x: &[f64]| -> Vec<i64> { x.iter().map(|v| (v * 1e7).round() as i64).collect() };
    let index: HashMap<Vec<i64>, usize> = origin
        .iter()
        .enumerate()
        .map(|(i, x)| (key(x), i))
        .collect();
    let largest = body
        .displacements
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst: f64 = 0.0;
    for (i, x) in origin.iter().enumerate() {
        let mut m = x.clone();
        for &axis in axes {
            m[axis] = 2.0 * at - x[axis];
        }
        let j = *index.get(&key(&m)).expect("the lattice is symmetric");
        for k in 0..x.len() {
            let sign = if axes.contains(&k) { -1.0 } else { 1.0 };
            worst = worst.max((body.displacements[i][k] - sign * body.displacements[j][k]).abs());
        }
    }
    worst / largest
}

/// The largest difference between two runs' displacements, relative to the largest.
fn paths_differ(a: &BodyResult, b: &BodyResult) -> f64 {
    let largest = b
        .displacements
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    a.displacements
        .iter()
        .flatten()
        .zip(b.displacements.iter().flatten())
        .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()))
        / largest
}

/// A triangular prism, ridge down along z at x = `ridge`, y = 0.1 from z = −0.05 to 0.25, its
/// faces at 45°, 5 cm high.
fn wedge_obj(ridge: f64) -> String {
    let (l, r) = (ridge - 0.05, ridge + 0.05);
    format!(
        "v {ridge} 0.1 -0.05\nv {l} 0.15 -0.05\nv {r} 0.15 -0.05\n\
         v {ridge} 0.1 0.25\nv {l} 0.15 0.25\nv {r} 0.15 0.25\n\
         f 1 2 3\nf 4 6 5\nf 1 4 5 2\nf 1 3 6 4\nf 2 5 6 3\n"
    )
}

/// A rubber block 0.2 × 0.1 × 0.2 m of `cells`, fixed at y = 0, pressed by `obstacle` (its keys).
fn block_scene(cells: [usize; 3], obstacle: &str) -> String {
    format!(
        r#"
name = "sharp"
# Two steps: the second starts from contacts whose crossings were committed.
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "block"
box_lattice = {{ size = [0.2, 0.1, 0.2], cells = [{}, {}, {}] }}
material = "rubber"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[obstacles]]
name = "press"
{obstacle}
"#,
        cells[0], cells[1], cells[2]
    )
}

const WEDGE: &str = "shape = \"mesh\"\nfile = \"wedge.obj\"\ntravel = [0.0, -0.008, 0.0]";

/// Both paths on one scene: the results, and how far they differ.
fn both(files: &[(&str, &str)], scene: &str) -> (BodyResult, BodyResult, f64) {
    let condensed = last_step(files, scene, true).bodies.remove(0);
    let coupled = last_step(files, scene, false).bodies.remove(0);
    let differ = paths_differ(&condensed, &coupled);
    (condensed, coupled, differ)
}

/// The wedge pressed 8 mm into the block with its ridge over the middle line of nodes: those
/// nodes crossed the ridge edge and are pushed up along the mean of the two faces' normals, so
/// the block is pressed straight down (it got as much sideways as down before:
/// [−1965.9, −1965.9, 0] N), and the answer is mirror-symmetric.
#[test]
fn wedge_ridge_over_the_middle_line_presses_straight_down() {
    let obj = wedge_obj(0.1);
    let (condensed, coupled, differ) = both(&[("wedge.obj", &obj)], &block_scene([8, 4, 8], WEDGE));
    for body in [&condensed, &coupled] {
        let f = total(body);
        eprintln!(
            "wedge: force {f:?}, sideways/vertical {:.2e}, mirror {:.2e}",
            sideways_ratio(&f),
            mirror_error(body, 0, 0.1)
        );
        assert!(f[1] < -100.0, "pressed down: {f:?}");
        assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
        assert!(mirror_error(body, 0, 0.1) < 1e-9);
    }
    eprintln!("wedge: paths differ by {differ:.2e}");
    assert!(differ < 1e-7, "condensed and coupled differ by {differ:e}");
}

/// A plate exactly the size of the block's top face (4 × 4 cells, the issue's 16 rim nodes)
/// pressed 1 cm down: the rim nodes of the face started on the plate's edges and moved into
/// its bottom face, not through its side faces: they are pressed down or free, never sideways
/// (they got e.g. [0, 0, −4.2] N before).
#[test]
fn flush_plate_presses_its_rim_nodes_down() {
    let plate = "shape = \"cuboid\"\ncenter = [0.1, 0.125, 0.1]\nhalf_extents = [0.1, 0.025, 0.1]\ntravel = [0.0, -0.01, 0.0]";
    // In one step the rim nodes stay pressed under the plate's edges; in two they slide out
    // from under it in the first (frictionless) and are free beside it in the second.
    for steps in [1, 2] {
        let scene = block_scene([4, 2, 4], plate).replace("steps = 2", &format!("steps = {steps}"));
        let (condensed, coupled, differ) = both(&[], &scene);
        for body in [&condensed, &coupled] {
            let f = total(body);
            let (x, z) = (mirror_error(body, 0, 0.1), mirror_error(body, 2, 0.1));
            eprintln!(
                "plate: force {f:?}, sideways/vertical {:.2e}, mirror x {x:.2e} z {z:.2e}",
                sideways_ratio(&f)
            );
            assert!(f[1] < -100.0, "{f:?}");
            assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
            assert!(x < 1e-9 && z < 1e-9);
            let mut rim = 0;
            for c in &body.contacts {
                // Results number nodes from 1.
                let (p, u) = (&body.positions[c.node - 1], &body.displacements[c.node - 1]);
                let o: Vec<f64> = p.iter().zip(u).map(|(p, u)| p - u).collect();
                // Every contact force of the plate is vertical: no side face was crossed.
                assert!(
                    c.force[0].abs() + c.force[2].abs() <= 1e-9 * f[1].abs(),
                    "node {} gets {:?}",
                    c.node,
                    c.force
                );
                let on_rim = [o[0], o[2]]
                    .iter()
                    .any(|v| v.abs() < 1e-9 || (v - 0.2).abs() < 1e-9);
                if on_rim && (o[1] - 0.1).abs() < 1e-9 {
                    rim += 1;
                    assert!(
                        c.force[1] < 0.0,
                        "rim node {} pressed down: {:?}",
                        c.node,
                        c.force
                    );
                }
            }
            eprintln!("plate, {steps} steps: {rim} of 16 rim nodes in contact, force {f:?}");
        }
        eprintln!("plate, {steps} steps: paths differ by {differ:.2e}");
        assert!(differ < 1e-7, "{differ:e}");
    }
}

/// The wedge's ridge between two node lines of a coarse block (5 cells of 4 cm across, the
/// ridge mid-cell): no node is inside the wedge (its faces are 2 cm above the ridge at the
/// nearest nodes, the press is 8 mm), yet the ridge presses the top patches: the block gets a
/// vertical force of the size a finer block (its node line under the ridge) gets, it is not
/// pushed sideways, and it is as symmetric as its patches are (under a half turn).
#[test]
fn wedge_ridge_between_node_lines_still_presses_a_coarse_block() {
    let obj = wedge_obj(0.1);
    let (coarse, coupled, differ) = both(&[("wedge.obj", &obj)], &block_scene([5, 2, 5], WEDGE));
    let fine = last_step(
        &[("wedge.obj", &obj)],
        &block_scene([10, 4, 10], WEDGE),
        true,
    )
    .bodies
    .remove(0);
    let ff = total(&fine);
    // A block as coarse with a node line under the ridge (4 cells of 5 cm across).
    let on_line =
        total(&last_step(&[("wedge.obj", &obj)], &block_scene([4, 2, 5], WEDGE), true).bodies[0]);
    for body in [&coarse, &coupled] {
        let f = total(body);
        // The patches' diagonals all run one way, so the block with its patches is symmetric
        // under a half turn about the vertical line x = z = 0.1, not under a mirror in x.
        let mirror = mirror_error(body, 0, 0.1);
        let turn = reflection_error(body, &[0, 2], 0.1);
        eprintln!(
            "coarse: force {f:?} (finer block {ff:?}), sideways/vertical {:.2e}, mirror {mirror:.2e}, half turn {turn:.2e}",
            sideways_ratio(&f)
        );
        assert!(f[1] < 0.0 && ff[1] < 0.0);
        // The size of the force of a ridge over a node line, of as coarse a block or of a finer.
        let (fine_ratio, line_ratio) = (f[1] / ff[1], f[1] / on_line[1]);
        eprintln!("coarse / fine {fine_ratio:.3}, coarse / coarse over a line {line_ratio:.3}");
        assert!(
            (0.4..2.5).contains(&fine_ratio),
            "coarse / fine = {fine_ratio}"
        );
        assert!(
            (0.5..2.0).contains(&line_ratio),
            "coarse / over a line = {line_ratio}"
        );
        assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
        assert!(turn < 1e-9, "{turn}");
        assert!(
            body.contacts.iter().all(|c| c.with == "press"),
            "{:?}",
            body.contacts
        );
    }
    eprintln!("coarse: paths differ by {differ:.2e}");
    assert!(differ < 1e-7, "{differ:e}");
}

/// A 2D rubber block 0.2 × 0.1 m of `cells`, fixed at y = 0, pressed 4 mm by a square of half
/// side 5 cm turned 45° about z, its lower corner (a cuboid's edge along z) at x = 0.1.
fn square_on_block(cells: [usize; 2]) -> String {
    let centre = 0.1 + 0.05 * 2f64.sqrt();
    format!(
        r#"
name = "sharp2d"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "block"
rectangle = {{ width = 0.2, height = 0.1, cells = [{}, {}] }}
material = "rubber"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0], normal = [0.0, 1.0] }}
fix = ["x", "y"]
[[obstacles]]
name = "press"
shape = "cuboid"
center = [0.1, {centre}]
half_extents = [0.05, 0.05]
rotation = 45.0
travel = [0.0, -0.004]
"#,
        cells[0], cells[1]
    )
}

/// The corner over the middle node of the 2D block's top (8 cells across): that node crossed
/// the corner and is pushed straight up; symmetric, both paths alike.
#[test]
fn rotated_cuboid_edge_over_a_node_of_a_2d_block_presses_straight_down() {
    let (condensed, coupled, differ) = both(&[], &square_on_block([8, 4]));
    for body in [&condensed, &coupled] {
        let f = total(body);
        let mirror = mirror_error(body, 0, 0.1);
        eprintln!(
            "2D over a node: force {f:?}, sideways/vertical {:.2e}, mirror {mirror:.2e}",
            sideways_ratio(&f)
        );
        assert!(f[1] < -10.0, "{f:?}");
        assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
        assert!(mirror < 1e-9, "{mirror}");
    }
    eprintln!("2D over a node: paths differ by {differ:.2e}");
    assert!(differ < 1e-7, "{differ:e}");
}

/// The corner between two boundary nodes of the 2D block's top (7 cells across, the corner
/// mid-segment): no node is inside the square, yet its corner presses the segment, shared
/// equally by its ends, with about the force of the corner over a node.
#[test]
fn rotated_cuboid_edge_between_nodes_of_a_2d_block_still_presses() {
    let over = total(&last_step(&[], &square_on_block([8, 4]), true).bodies[0]);
    let (condensed, coupled, differ) = both(&[], &square_on_block([7, 4]));
    for body in [&condensed, &coupled] {
        let f = total(body);
        let mirror = mirror_error(body, 0, 0.1);
        eprintln!(
            "2D between nodes: force {f:?} (over a node {over:?}), sideways/vertical {:.2e}, mirror {mirror:.2e}",
            sideways_ratio(&f)
        );
        let ratio = f[1] / over[1];
        assert!((0.3..3.0).contains(&ratio), "between / over = {ratio}");
        assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
        assert!(mirror < 1e-9, "{mirror}");
        assert_eq!(
            body.contacts.len(),
            2,
            "the segment's two ends: {:?}",
            body.contacts
        );
    }
    eprintln!("2D between nodes: paths differ by {differ:.2e}");
    assert!(differ < 1e-7, "{differ:e}");
}

/// A cylinder (axis vertical) pressed 1 cm down on the block with its bottom rim exactly over
/// four nodes of the top face (the midpoints of its edges, radius 0.1 about the face's centre):
/// those nodes start on the rim and move into the cap, not through the side, so they are
/// pressed down (the nearest point put them on the side: sideways forces), the block is pressed
/// straight down, and the answer is mirror-symmetric in x and z on both paths.
#[test]
fn cylinder_rim_over_nodes_presses_them_down() {
    let cylinder = "shape = \"cylinder\"\ncenter = [0.1, 0.125, 0.1]\nradius = 0.1\nhalf_height = 0.025\ntravel = [0.0, -0.01, 0.0]";
    for steps in [1, 2] {
        let scene =
            block_scene([4, 2, 4], cylinder).replace("steps = 2", &format!("steps = {steps}"));
        let (condensed, coupled, differ) = both(&[], &scene);
        for body in [&condensed, &coupled] {
            let f = total(body);
            let (x, z) = (mirror_error(body, 0, 0.1), mirror_error(body, 2, 0.1));
            eprintln!(
                "cylinder: force {f:?}, sideways/vertical {:.2e}, mirror x {x:.2e} z {z:.2e}",
                sideways_ratio(&f)
            );
            assert!(f[1] < -100.0, "{f:?}");
            assert!(sideways_ratio(&f) < 1e-6, "{f:?}");
            assert!(x < 1e-9 && z < 1e-9);
            let mut rim = 0;
            for c in &body.contacts {
                let (p, u) = (&body.positions[c.node - 1], &body.displacements[c.node - 1]);
                let o: Vec<f64> = p.iter().zip(u).map(|(p, u)| p - u).collect();
                let r = ((o[0] - 0.1).powi(2) + (o[2] - 0.1).powi(2)).sqrt();
                if (r - 0.1).abs() < 1e-9 && (o[1] - 0.1).abs() < 1e-9 {
                    rim += 1;
                    assert!(
                        c.force[0].abs() + c.force[2].abs() <= 1e-9 * c.force[1].abs()
                            && c.force[1] < 0.0,
                        "rim node {} gets {:?}",
                        c.node,
                        c.force
                    );
                }
            }
            eprintln!("cylinder, {steps} steps: {rim} of the 4 nodes on the rim in contact");
        }
        eprintln!("cylinder: paths differ by {differ:.2e}");
        assert!(differ < 1e-7, "{differ:e}");
    }
}

/// The open tube of `cylindrical_shell` (radius 0.1 m, length 0.4 m, 5 rings of 16 nodes, E A =
/// 2e7 N), clamped at both end rings, as scene text with `rest` (obstacles, loads) after it.
fn tube_scene(rest: &str) -> String {
    let ends: Vec<String> = (1..=16).chain(65..=80).map(|n| n.to_string()).collect();
    format!(
        r#"name = "tube"
steps = 1
[[materials]]
name = "steel"
youngs_modulus = 2e11
area = 1e-4
[[bodies]]
name = "tube"
cylindrical_shell = {{ radius = 0.1, length = 0.4, rings = 5, sectors = 16 }}
[[bodies.supports]]
nodes = [{}]
fix = ["x", "y", "z"]
{rest}
"#,
        ends.join(", ")
    )
}

/// A narrow pyramid (a closed OBJ mesh) whose apex is at `apex` and whose axis runs from the
/// apex along `axis` (unit) for 0.08 m to a square base of half width 0.01 m, its sides along
/// `e_x` and `e_x × axis`.
fn pyramid_obj(apex: [f64; 3], axis: [f64; 3]) -> String {
    let side = [0.0, -axis[2], axis[1]];
    let mut text = format!("v {} {} {}\n", apex[0], apex[1], apex[2]);
    for (a, b) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
        let v: Vec<f64> = (0..3)
            .map(|k| {
                let e_x = if k == 0 { 1.0 } else { 0.0 };
                apex[k] + 0.08 * axis[k] + 0.01 * (a * e_x + b * side[k])
            })
            .collect();
        text += &format!("v {} {} {}\n", v[0], v[1], v[2]);
    }
    text + "f 1 2 3\nf 1 3 4\nf 1 4 5\nf 1 5 2\nf 2 5 4 3\n"
}

/// A sharp obstacle point pressing an open shell, from outside and from inside (an open shell
/// has no inside: the point presses the patch it crossed since the last solved state, from
/// either side). The apex of a narrow pyramid (a mesh obstacle's vertex) lies over the middle
/// of the ring segment between nodes 33 and 34 (ring 2 of the clamped tube, the middle ring;
/// sectors 0 and 1), 1 µm off the shell along the segment's radial normal n (the flat cell's
/// normal, at 11.25°), and travels 5 µm along −n (from outside) or +n (from inside, the pyramid
/// in the tube). Before, the point passed through the shell between its nodes, nothing held it
/// and nothing said so. Now: the shell takes the force F = 4 µm / (c + 1/k), with c the
/// shell's compliance for a force at the segment's middle, half on each node (from the run
/// with that load and no obstacle), and k the shell's penalty; to 1e-4 (the patch's normal
/// turns as the shell dents, by the dent over a member, ~1e-5 rad). The supports react with F
/// (1e-8). The dent is symmetric about the middle ring's plane (x = 0.2 m) and about the plane
/// through the axis and the segment's middle (1e-4 of the largest displacement), and the
/// dents from outside and inside are opposite (1e-4). The same on the condensed and the
/// coupled path.
#[test]
fn a_pyramid_apex_pressing_an_open_tube_between_nodes_dents_it_from_either_side() {
    let phi = std::f64::consts::PI / 16.0;
    let n = [0.0, phi.cos(), phi.sin()];
    let radius = 0.1 * phi.cos();
    let middle = [0.2, radius * n[1], radius * n[2]];
    let (gap, travel) = (1e-6, 5e-6);
    // The compliance: 1 N at the segment's middle along −n, half on each node.
    let load = format!(
        "[[bodies.loads]]\nnodes = [33, 34]\nforce = [0.0, {}, {}]\n",
        -0.5 * n[1],
        -0.5 * n[2]
    );
    let unit = last_step(&[], &tube_scene(&load), true);
    let u = &unit.bodies[0].displacements;
    let c = -(0..3).map(|k| (u[32][k] + u[33][k]) * n[k]).sum::<f64>() / 2.0;
    assert!(c > 0.0, "{c}");
    let world = load_scene_text(&tube_scene(""));
    let k = linkage::contact::default_penalty(&world.bodies[0]);
    let expected = (travel - gap) / (c + 1.0 / k);
    eprintln!("compliance {c:.6e} m/N, penalty {k:.6e} N/m: F = {expected:.6e} N");
    let mut dents: Vec<Vec<Vec<f64>>> = Vec::new();
    for outside in [true, false] {
        let s = if outside { 1.0 } else { -1.0 };
        let apex: [f64; 3] = std::array::from_fn(|k| middle[k] + s * gap * n[k]);
        let axis: [f64; 3] = std::array::from_fn(|k| s * n[k]);
        let obj = pyramid_obj(apex, axis);
        let obstacle = format!(
            "[[obstacles]]\nname = \"pyramid\"\nshape = \"mesh\"\nfile = \"pyramid.obj\"\ntravel = [0.0, {}, {}]\n",
            -s * travel * n[1],
            -s * travel * n[2]
        );
        let scene = tube_scene(&obstacle);
        let mut results = Vec::new();
        for condense in [true, false] {
            let step = last_step(&[("pyramid.obj", &obj)], &scene, condense);
            let body = step.bodies[0].clone();
            let f = total(&body);
            let along = -s * (0..3).map(|k| f[k] * n[k]).sum::<f64>();
            let reacted: Vec<f64> = (0..3)
                .map(|k| body.reactions.iter().map(|r| r.force[k]).sum::<f64>())
                .collect();
            eprintln!(
                "outside {outside} condense {condense}: contact force {f:?} N ({along:.6e} N along ∓n), reactions {reacted:?} N, {} contact entries",
                body.contacts.len()
            );
            assert!(
                body.contacts.iter().all(|e| e.with == "pyramid"),
                "{:?}",
                body.contacts
            );
            assert!(
                (along - expected).abs() <= 1e-4 * expected,
                "outside {outside} condense {condense}: {along} against {expected}"
            );
            for kk in 0..3 {
                assert!(
                    (f[kk] + reacted[kk]).abs() <= 1e-8 * expected,
                    "{f:?} {reacted:?}"
                );
            }
            // Symmetry: ring r ↔ 4 − r with u_x turned; sector s ↔ 1 − s reflected in the
            // plane through the axis and n (normal t = (0, −sin φ, cos φ)).
            let u = &body.displacements;
            let largest = u.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let t = [0.0, -phi.sin(), phi.cos()];
            let (mut across_x, mut across_n) = (0.0f64, 0.0f64);
            for r in 0..5 {
                for q in 0..16 {
                    let i = r * 16 + q;
                    let j = (4 - r) * 16 + q;
                    across_x = across_x
                        .max((u[i][0] + u[j][0]).abs())
                        .max((u[i][1] - u[j][1]).abs())
                        .max((u[i][2] - u[j][2]).abs());
                    let m = r * 16 + (17 - q) % 16;
                    let dot: f64 = (0..3).map(|kk| u[i][kk] * t[kk]).sum();
                    for kk in 0..3 {
                        let reflected = u[i][kk] - 2.0 * dot * t[kk];
                        across_n = across_n.max((reflected - u[m][kk]).abs());
                    }
                }
            }
            eprintln!(
                "  symmetry: across x = 0.2 {:.3e}, across the plane of n {:.3e}",
                across_x / largest,
                across_n / largest
            );
            assert!(across_x <= 1e-4 * largest && across_n <= 1e-4 * largest);
            results.push(body);
        }
        assert!(paths_differ(&results[0], &results[1]) <= 1e-6);
        dents.push(results.swap_remove(0).displacements);
    }
    let largest = dents[0]
        .iter()
        .flatten()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let opposite = dents[0]
        .iter()
        .flatten()
        .zip(dents[1].iter().flatten())
        .fold(0.0f64, |m, (a, b)| m.max((a + b).abs()));
    eprintln!(
        "dents from outside and inside differ from opposite by {:.3e}",
        opposite / largest
    );
    assert!(opposite <= 1e-4 * largest);
}

/// The world of scene text `text` (no files beside it).
fn load_scene_text(text: &str) -> linkage::scene::World {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, text).unwrap();
    load_scene(&path).unwrap()
}
