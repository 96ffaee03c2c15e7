//! Contact with rigid obstacles (issue 5): numbers that follow from the penalty law and from
//! equilibrium. Tolerances are stated where they are used.

use linkage::scene::{build_world, load_scene, Simulation, StepResult, StepSummary};
use std::path::{Path, PathBuf};

/// Solve every step of `world` in order; the results and summaries.
fn run_all(world: &linkage::scene::World) -> Vec<(StepResult, StepSummary)> {
    let mut sim = Simulation::new(world).expect("builds");
    (0..=world.steps)
        .map(|k| sim.step(k).expect("solves"))
        .collect()
}

/// A scene folder holding `files` (name, text); returns the folder and the scene path.
fn scene_with(files: &[(&str, &str)], scene: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    (dir, path)
}

/// Sum over the bodies of reactions, loads and contact forces (N), and the largest of them.
fn balance(result: &StepResult) -> ([f64; 3], f64) {
    let mut sum = [0.0; 3];
    let mut largest: f64 = 0.0;
    for b in &result.bodies {
        let forces = b
            .reactions
            .iter()
            .map(|r| &r.force)
            .chain(b.loads.iter().map(|l| &l.force))
            .chain(b.contacts.iter().map(|c| &c.force));
        for f in forces {
            let n = f.iter().map(|x| x * x).sum::<f64>().sqrt();
            largest = largest.max(n);
            for (k, x) in f.iter().enumerate() {
                sum[k] += x;
            }
        }
    }
    (sum, largest)
}

const BAR_NODES: &str = "0 0\n0 1\n";
const BAR_LINKS: &str = "1 2\n";

fn bar_on_floor(contact: &str) -> String {
    format!(
        r#"
name = "bar_on_floor"
steps = 2
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "bar"
nodes = "bar.nodes"
links = "bar.links"
# Held sideways only: vertically the floor alone holds it.
[[bodies.supports]]
nodes = [1, 2]
fix = ["x"]
[[bodies.loads]]
nodes = [2]
force = [0.0, -1000.0]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0]
normal = [0.0, 1.0]
{contact}
"#
    )
}

/// A vertical bar standing on a floor, pushed down by F at its top and held by nothing else
/// vertically: its foot sinks exactly F / k into the floor (k the penalty), the floor pushes
/// back with F, and the bar carries −F. Checked with the default penalty (100 E A / L) and an
/// explicit one, at both steps (F/2 and F).
#[test]
fn bar_pressed_onto_floor_sinks_force_over_penalty() {
    for (contact, k) in [
        ("", 100.0 * 200e9 * 1e-4 / 1.0),
        ("[contact]\npenalty = 1e6\n", 1e6),
    ] {
        let (_dir, path) = scene_with(
            &[("bar.nodes", BAR_NODES), ("bar.links", BAR_LINKS)],
            &bar_on_floor(contact),
        );
        let world = load_scene(&path).unwrap();
        for (result, summary) in run_all(&world).into_iter().skip(1) {
            let f = 1000.0 * result.load_factor;
            let bar = &result.bodies[0];
            assert_eq!(
                bar.contacts.len(),
                1,
                "only the foot touches: {:?}",
                bar.contacts
            );
            let c = &bar.contacts[0];
            assert_eq!((c.node, c.with.as_str()), (1, "floor"));
            // Exactly F / k: to round-off of the solve (1e-9 relative).
            assert!(
                (c.depth - f / k).abs() <= 1e-9 * f / k,
                "depth {} vs F/k {}",
                c.depth,
                f / k
            );
            assert!((c.force[1] - f).abs() <= 1e-9 * f && c.force[0].abs() <= 1e-9 * f);
            assert!((bar.axial_forces[0] + f).abs() <= 1e-9 * f);
            assert!((summary.max_penetration - f / k).abs() <= 1e-9 * f / k);
            assert!(summary.contact_iterations >= 1);
            // The foot's displacement is the penetration: the floor is at y = 0.
            assert!((bar.displacements[0][1] + f / k).abs() <= 1e-9 * f / k);
        }
    }
}

/// A flat block pressed from above by a ball that travels 1 cm down into it: every contact
/// force points along the radius from the ball's centre to the node (radial normals), away
/// from the centre, and its size is the penalty times the depth.
#[test]
fn ball_obstacle_gives_radial_contact_forces() {
    let scene = r#"
name = "ball_press"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "block"
rectangle = { width = 1.0, height = 0.2, cells = [40, 8] }
[[bodies.supports]]
on_line = { point = [0.0, 0.0], direction = [1.0, 0.0] }
fix = ["x", "y"]
[[obstacles]]
name = "ball"
shape = "ball"
center = [0.5, 0.5]
radius = 0.3
travel = [0.0, -0.01]
"#;
    let world = build_world(scene, Path::new("ball_press.toml")).unwrap();
    let k = 100.0 * mean_member_stiffness(&world.bodies[0]);
    for (result, summary) in run_all(&world).into_iter().skip(1) {
        let block = &result.bodies[0];
        let center = [0.5, 0.5 - 0.01 * result.load_factor];
        assert!(block.contacts.len() >= 3, "{:?}", block.contacts);
        for c in &block.contacts {
            let p = &block.positions[c.node - 1];
            let r = [p[0] - center[0], p[1] - center[1]];
            let rn = (r[0] * r[0] + r[1] * r[1]).sqrt();
            let f = &c.force;
            let fn_ = (f[0] * f[0] + f[1] * f[1]).sqrt();
            // Parallel to the radius and outward, to round-off.
            assert!(
                (f[0] * r[1] - f[1] * r[0]).abs() <= 1e-9 * fn_ * rn,
                "{c:?}"
            );
            assert!(f[0] * r[0] + f[1] * r[1] > 0.0, "{c:?}");
            // |f| = k · depth and depth = R − |x − c|.
            assert!((fn_ - k * c.depth).abs() <= 1e-9 * fn_);
            assert!((c.depth - (0.3 - rn)).abs() <= 1e-12);
        }
        let (sum, largest) = balance(&result);
        for s in sum {
            assert!(s.abs() <= 1e-8 * largest, "out of balance {sum:?}");
        }
        assert!(summary.residual <= 1e-8, "{summary:?}");
    }
}

fn mean_member_stiffness(body: &linkage::linkage::Body) -> f64 {
    let sum: f64 = body
        .members
        .iter()
        .enumerate()
        .map(|(m, member)| {
            let mat = &body.materials[member.material];
            mat.youngs_modulus * mat.area / body.member_length(m)
        })
        .sum();
    sum / body.members.len() as f64
}

/// The bundled disk_on_floor scene: at every step the supports' reactions, the loads and the
/// floor's contact forces sum to zero (to 1e-8 of the largest), each contact force is the
/// penalty times its depth along +y, and no node is deeper than the tolerance (1% of the mean
/// member length).
#[test]
fn disk_on_floor_is_in_equilibrium() {
    let world = load_scene(Path::new("scenes/disk_on_floor.toml")).unwrap();
    let body = &world.bodies[0];
    let k = 100.0 * mean_member_stiffness(body);
    let mean_length: f64 = (0..body.members.len())
        .map(|m| body.member_length(m))
        .sum::<f64>()
        / body.members.len() as f64;
    let mut touched = 0;
    for (result, summary) in run_all(&world) {
        let (sum, largest) = balance(&result);
        for s in sum {
            assert!(
                s.abs() <= 1e-8 * largest.max(1e-300),
                "step {}: {sum:?}",
                result.step
            );
        }
        for c in &result.bodies[0].contacts {
            assert!(c.force[0].abs() <= 1e-9 * c.force[1]);
            assert!((c.force[1] - k * c.depth).abs() <= 1e-9 * c.force[1]);
            assert!(c.depth <= 0.01 * mean_length);
        }
        touched = touched.max(result.bodies[0].contacts.len());
        // The rubber disk is linear and strained past 5 % from step 1 (2 cm down on a 10 cm
        // radius): that warning is meant (docs/SCENES.md, *Warnings*); nothing else is said.
        assert!(
            summary.warnings.iter().all(|w| result.step == 1
                && w.contains("body 'disk': member")
                && w.contains("is strained")),
            "{:?}",
            summary.warnings
        );
    }
    assert!(
        touched >= 3,
        "the disk flattens onto several nodes: {touched}"
    );
}

/// Obstacles are checked like everything else: the file, the line and what to do.
#[test]
fn bad_obstacles_are_reported_with_line() {
    let base = r#"
name = "s"
[[materials]]
name = "m"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "disk"
disk = { radius = 0.1 }
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
"#;
    let cases = [
        (
            "[[obstacles]]\nname = \"disk\"\nshape = \"ball\"\ncenter = [0.0, 0.0]\nradius = 1.0\n",
            "distinct names",
        ),
        (
            "[[obstacles]]\nname = \"o\"\nshape = \"cone\"\n",
            "shape = \"cone\"",
        ),
        (
            "[[obstacles]]\nname = \"o\"\nshape = \"ball\"\ncenter = [0.0, 0.0, 1.0]\nradius = 1.0\n",
            "3 components",
        ),
        (
            "[[obstacles]]\nname = \"o\"\nshape = \"half_space\"\npoint = [0.0, 0.0]\nnormal = [0.0, 0.0]\n",
            "zero vector",
        ),
        ("[contact]\npenalty = -1.0\n", "penalty = -1"),
    ];
    for (extra, expected) in cases {
        let text = format!("{base}{extra}");
        let err = build_world(&text, Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains(expected), "{err}");
        assert!(
            err.starts_with("s.toml:1"),
            "names the file and line: {err}"
        );
    }
}

/// The bundled two_disks scene: two equal disks pressed together by equal and opposite forces,
/// held sideways by nothing but each other. At every loaded step the contact forces on each
/// disk sum to minus its applied load (to 1e-6 relative) and are equal and opposite between the
/// disks; no node is deeper than the tolerance (1% of the mean member length); the
/// displacements are mirror images about x = 0 (to 1e-6 of the largest); the contact zone is
/// centred on the line of centres (y = 0).
#[test]
fn two_disks_press_each_other_symmetrically() {
    let world = load_scene(Path::new("scenes/two_disks.toml")).unwrap();
    let body = &world.bodies[0];
    let mean_length: f64 = (0..body.members.len())
        .map(|m| body.member_length(m))
        .sum::<f64>()
        / body.members.len() as f64;
    for (result, summary) in run_all(&world).into_iter().skip(1) {
        let f = 400.0 * result.load_factor;
        let [left, right] = [&result.bodies[0], &result.bodies[1]];
        let sum = |b: &linkage::scene::BodyResult| {
            b.contacts
                .iter()
                .fold([0.0, 0.0], |s, c| [s[0] + c.force[0], s[1] + c.force[1]])
        };
        let (l, r) = (sum(left), sum(right));
        assert!(
            (l[0] + f).abs() <= 1e-6 * f && l[1].abs() <= 1e-6 * f,
            "left {l:?}, load {f}"
        );
        assert!(
            (r[0] - f).abs() <= 1e-6 * f && r[1].abs() <= 1e-6 * f,
            "right {r:?}"
        );
        assert!((l[0] + r[0]).abs() <= 1e-9 * f, "equal and opposite");
        // The summary's total per pair says the same.
        let pair = |body: &str| {
            summary
                .contact_forces
                .iter()
                .find(|p| p.body == body)
                .unwrap_or_else(|| panic!("a total for {body}: {:?}", summary.contact_forces))
                .clone()
        };
        let (pl, pr) = (pair("left"), pair("right"));
        assert_eq!((pl.with.as_str(), pr.with.as_str()), ("right", "left"));
        assert!((pl.force[0] - l[0]).abs() <= 1e-9 * f && (pr.force[0] - r[0]).abs() <= 1e-9 * f);
        for c in left.contacts.iter().chain(&right.contacts) {
            assert!(c.depth <= 0.01 * mean_length, "{c:?}");
        }
        assert!(summary.max_penetration <= 0.01 * mean_length);
        // Mirror images: node i of the left disk at (x, y) has its twin at (−x, y).
        let largest = left
            .displacements
            .iter()
            .map(|u| u[0].hypot(u[1]))
            .fold(0.0, f64::max);
        let nodes_l = &world.bodies[0].nodes;
        let nodes_r = &world.bodies[1].nodes;
        for (i, p) in nodes_l.iter().enumerate() {
            let j = nodes_r
                .iter()
                .position(|q| (q.x + p.x).abs() < 1e-12 && (q.y - p.y).abs() < 1e-12)
                .expect("a mirror twin");
            let (ul, ur) = (&left.displacements[i], &right.displacements[j]);
            assert!(
                (ul[0] + ur[0]).abs() <= 1e-6 * largest && (ul[1] - ur[1]).abs() <= 1e-6 * largest,
                "node {}: {ul:?} vs twin {}: {ur:?}",
                i + 1,
                j + 1
            );
        }
        // Centred on y = 0: the force-weighted mean height of the contact nodes.
        let (mut moment, mut total) = (0.0, 0.0);
        for c in &left.contacts {
            let p = &left.positions[c.node - 1];
            let size = c.force[0].hypot(c.force[1]);
            moment += size * p[1];
            total += size;
        }
        assert!(total > 0.0 && (moment / total).abs() <= 1e-9 * mean_length);
        if result.step == world.steps {
            assert!(left.contacts.len() >= 3, "a contact zone, not a point");
        }
    }
}

/// shell_on_block and its moving variant: at every step the support reactions, the applied
/// force and the block's contact forces balance (to 1e-8 of the largest), and every contact
/// node lies on the block's top face (its y within the tolerance, 1% of the mean member length,
/// of the face, which rises with the block's travel in the moving variant).
#[test]
fn shell_on_block_balances_and_rests_on_the_face() {
    for (scene, top, rise) in [
        ("scenes/shell_on_block.toml", -0.2502, 0.0),
        ("scenes/shell_on_block_moving.toml", -0.25, 0.02),
    ] {
        let world = load_scene(Path::new(scene)).unwrap();
        let body = &world.bodies[0];
        let tolerance = 0.01
            * (0..body.members.len())
                .map(|m| body.member_length(m))
                .sum::<f64>()
            / body.members.len() as f64;
        let mut touched = false;
        for (result, summary) in run_all(&world) {
            let (sum, largest) = balance(&result);
            for s in sum {
                assert!(s.abs() <= 1e-8 * largest.max(1e-300), "{scene}: {sum:?}");
            }
            let face = top + rise * result.load_factor;
            let shell = &result.bodies[0];
            for c in &shell.contacts {
                let y = shell.positions[c.node - 1][1];
                assert!(
                    (y - face).abs() <= tolerance,
                    "{scene}: node {} at {y}",
                    c.node
                );
                assert!(c.force[1] > 0.0 && c.force[0] == 0.0 && c.force[2] == 0.0);
                touched = true;
            }
            assert!(summary.residual <= 1e-8, "{scene}: {summary:?}");
        }
        assert!(touched, "{scene}: the shell reaches the block");
    }
}

/// The bundled stack of three 3D boxes: the two upper boxes are held vertically by contact alone
/// and settle; at every step each interface carries the whole load (the summary's pair totals,
/// vertical part, to 1e-6), equal and opposite across it, and reactions, loads and contact
/// forces balance (to 1e-8 of the largest); the contact set settles (no warning: a node on the
/// edge between two patches keeps the patch it pressed on). On both the condensed and the
/// coupled path.
#[test]
fn stack_of_three_boxes_passes_the_load_down() {
    let mut world = load_scene(Path::new("scenes/stack.toml")).unwrap();
    let mut runs = run_all(&world);
    world.contact.condense = false;
    runs.extend(run_all(&world));
    for (result, summary) in runs.into_iter().filter(|(r, _)| r.step > 0) {
        assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
        let load = 500.0 * result.load_factor;
        let (sum, largest) = balance(&result);
        for s in sum {
            assert!(s.abs() <= 1e-8 * largest, "{sum:?}");
        }
        let total = |body: &str, with: &str| -> Vec<f64> {
            summary
                .contact_forces
                .iter()
                .find(|p| p.body == body && p.with == with)
                .unwrap_or_else(|| panic!("{body} on {with}: {:?}", summary.contact_forces))
                .force
                .clone()
        };
        for (upper, lower) in [("middle", "bottom"), ("top", "middle")] {
            let up = total(upper, lower);
            let down = total(lower, upper);
            assert!(
                (up[1] - load).abs() <= 1e-6 * load,
                "{upper} on {lower}: {up:?}"
            );
            for k in 0..3 {
                assert!((up[k] + down[k]).abs() <= 1e-9 * load, "equal and opposite");
            }
        }
        assert!(summary.residual <= 1e-9, "{summary:?}");
    }
}

/// Contact with large displacements: disk_on_floor with `kinematics = "large"` still balances
/// at every step (to 1e-8 of the largest force) and the floor pushes straight up.
#[test]
fn large_displacement_disk_on_floor_balances() {
    let text = std::fs::read_to_string("scenes/disk_on_floor.toml")
        .unwrap()
        .replace(
            "disk = { radius = 0.1, rings = 6, sectors = 32 }",
            "disk = { radius = 0.1, rings = 6, sectors = 32 }\nkinematics = \"large\"",
        );
    assert!(text.contains("kinematics = \"large\""));
    let world = build_world(&text, Path::new("scenes/disk_on_floor.toml")).unwrap();
    for (result, summary) in run_all(&world).into_iter().skip(1) {
        let (sum, largest) = balance(&result);
        for s in sum {
            assert!(s.abs() <= 1e-8 * largest, "{sum:?}");
        }
        assert!(!result.bodies[0].contacts.is_empty());
        for c in &result.bodies[0].contacts {
            assert!(c.force[0].abs() <= 1e-9 * c.force[1]);
        }
        assert!(summary.residual <= 1e-9);
    }
}

/// A unit cube as OBJ text: faces counter-clockwise seen from outside.
const CUBE_OBJ: &str = "\
v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// The cube of `CUBE_OBJ` as triangles (corners in m), each quad fanned as OBJ does.
fn cube_triangles() -> Vec<[[f32; 3]; 3]> {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for line in CUBE_OBJ.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices.push([0, 1, 2].map(|_| words.next().unwrap().parse().unwrap())),
            Some("f") => {
                let f: Vec<usize> = words.map(|w| w.parse::<usize>().unwrap() - 1).collect();
                for j in 1..f.len() - 1 {
                    triangles.push([vertices[f[0]], vertices[f[j]], vertices[f[j + 1]]]);
                }
            }
            _ => {}
        }
    }
    triangles
}

/// A 3D box lattice pressed 2 mm down by its top face onto the obstacle `obstacle` (its TOML
/// keys), a unit cube below it.
fn box_on_cube(obstacle: &str) -> String {
    format!(
        r#"
name = "box_on_cube"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "box"
box_lattice = {{ size = [0.2, 0.1, 0.2], cells = [2, 2, 2] }}
offset = [-0.1, 0.5, -0.1]
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.6, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
displacement = [0.0, -0.002, 0.0]
[[obstacles]]
name = "cube"
{obstacle}
"#
    )
}

/// Whether two runs' last steps have the same contacts (nodes, depths and forces) and
/// displacements, to `tolerance` of the largest.
fn same_answer(a: &linkage::scene::BodyResult, b: &linkage::scene::BodyResult, tolerance: f64) {
    assert_eq!(a.contacts.len(), 9, "the bottom face's 3 × 3 nodes");
    assert_eq!(a.contacts.len(), b.contacts.len());
    let largest = b
        .displacements
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    for (u, v) in a
        .displacements
        .iter()
        .flatten()
        .zip(b.displacements.iter().flatten())
    {
        assert!((u - v).abs() <= tolerance * largest);
    }
    let force = b.contacts.iter().map(|c| c.force[1]).fold(0.0, f64::max);
    for (c, d) in a.contacts.iter().zip(&b.contacts) {
        assert_eq!((c.node, &c.with), (d.node, &d.with));
        assert!((c.depth - d.depth).abs() <= tolerance * largest);
        for k in 0..3 {
            assert!((c.force[k] - d.force[k]).abs() <= tolerance * force);
        }
    }
}

/// A unit cube given as an OBJ triangle mesh (counter-clockwise seen from outside) acts exactly
/// like the same cube as a cuboid obstacle: a 3D box pressed onto it gets the same contacts and
/// displacements (to 1e-9 of the largest).
#[test]
fn mesh_obstacle_matches_the_cuboid() {
    let (_dir, mesh_path) = scene_with(
        &[("cube.obj", CUBE_OBJ)],
        &box_on_cube("shape = \"mesh\"\nfile = \"cube.obj\""),
    );
    let with_mesh = run_all(&load_scene(&mesh_path).unwrap());
    let cuboid = build_world(
        &box_on_cube(
            "shape = \"cuboid\"\ncenter = [0.0, 0.0, 0.0]\nhalf_extents = [0.5, 0.5, 0.5]",
        ),
        Path::new("box_on_cube.toml"),
    )
    .unwrap();
    let with_cuboid = run_all(&cuboid);
    same_answer(&with_mesh[2].0.bodies[0], &with_cuboid[2].0.bodies[0], 1e-9);
}

/// The cube's OBJ with every face listed clockwise (all facing in), or with one face turned
/// round, is turned outward as a whole and acts as the outward cube (to 1e-9 of the largest, as
/// the cuboid does: a reversed quad is fanned along its other diagonal); with a face missing it is refused at loading (so by `check` and `run` alike)
/// with an edge of the hole.
#[test]
fn inward_and_partly_flipped_meshes_are_turned_outward_and_open_ones_refused() {
    let (_dir, outward) = scene_with(
        &[("cube.obj", CUBE_OBJ)],
        &box_on_cube("shape = \"mesh\"\nfile = \"cube.obj\""),
    );
    let reference = run_all(&load_scene(&outward).unwrap());
    let turned = |keep: &dyn Fn(usize) -> bool| -> String {
        let mut face = 0;
        CUBE_OBJ
            .lines()
            .map(|line| match line.strip_prefix("f ") {
                Some(rest) => {
                    face += 1;
                    if keep(face) {
                        line.to_string()
                    } else {
                        let mut v: Vec<&str> = rest.split_whitespace().collect();
                        v.reverse();
                        format!("f {}", v.join(" "))
                    }
                }
                None => line.to_string(),
            })
            .collect::<Vec<_>>()
            .join("\n")
    };
    for (name, mesh) in [
        ("inward", turned(&|_| false)),
        ("one face flipped", turned(&|f| f != 3)),
    ] {
        let (_d, path) = scene_with(
            &[("cube.obj", &mesh)],
            &box_on_cube("shape = \"mesh\"\nfile = \"cube.obj\""),
        );
        let solved = run_all(&load_scene(&path).unwrap_or_else(|e| panic!("{name}: {e}")));
        same_answer(&solved[2].0.bodies[0], &reference[2].0.bodies[0], 1e-9);
    }
    let open: String = CUBE_OBJ
        .lines()
        .filter(|l| *l != "f 5 6 7 8")
        .collect::<Vec<_>>()
        .join("\n");
    let (_d, path) = scene_with(
        &[("cube.obj", &open)],
        &box_on_cube("shape = \"mesh\"\nfile = \"cube.obj\""),
    );
    let message = load_scene(&path).unwrap_err().to_string();
    assert!(
        message.contains("cube.obj")
            && message.contains("the mesh is open there")
            && message.contains("watertight"),
        "{message}"
    );
}

/// The cube as a binary STL (whose 80-byte header begins with `solid`, as many exporters write
/// it: the file's size tells it from ASCII) gives the same answer as the cube as an ASCII STL:
/// the same 9 contacts, depths, forces and displacements (to 1e-12 of the largest: the corners
/// are the same numbers, ±0.5, in f32 and in text). A binary file cut short is reported with
/// the triangle cut and both sizes.
#[test]
fn binary_stl_mesh_matches_the_ascii_one() {
    let triangles = cube_triangles();
    assert_eq!(triangles.len(), 12);
    let mut ascii = String::from("solid cube\n");
    let mut binary = b"solid cube, binary".to_vec();
    binary.resize(80, 0);
    binary.extend((triangles.len() as u32).to_le_bytes());
    for t in &triangles {
        ascii.push_str("  facet normal 0 0 0\n    outer loop\n");
        binary.extend([0u8; 12]);
        for c in t {
            ascii.push_str(&format!("      vertex {} {} {}\n", c[0], c[1], c[2]));
            for x in c {
                binary.extend(x.to_le_bytes());
            }
        }
        binary.extend([0u8; 2]);
        ascii.push_str("    endloop\n  endfacet\n");
    }
    ascii.push_str("endsolid cube\n");
    assert_eq!(binary.len(), 84 + 50 * 12);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("ascii.stl"), &ascii).unwrap();
    std::fs::write(dir.path().join("binary.stl"), &binary).unwrap();
    std::fs::write(dir.path().join("cut.stl"), &binary[..84 + 50 * 7 + 30]).unwrap();
    let run = |file: &str| {
        let path = dir.path().join(format!("{file}.toml"));
        let text = box_on_cube(&format!("shape = \"mesh\"\nfile = \"{file}.stl\""));
        std::fs::write(&path, text).unwrap();
        load_scene(&path).map(|w| run_all(&w))
    };
    let from_ascii = run("ascii").unwrap();
    let from_binary = run("binary").unwrap();
    same_answer(
        &from_binary[2].0.bodies[0],
        &from_ascii[2].0.bodies[0],
        1e-12,
    );
    let err = run("cut").map(|_| ()).unwrap_err().to_string();
    for part in [
        "cut.stl",
        "12 triangles",
        "684 bytes",
        "464 bytes",
        "triangle 8",
    ] {
        assert!(err.contains(part), "{part:?} in {err}");
    }
}

/// Bad contact input is reported before anything is solved: a missing mesh file names the file,
/// and a 3D body whose patches face both ways names the edge where they disagree.
#[test]
fn bad_mesh_file_and_inconsistent_patches_are_reported() {
    let base = r#"
name = "s"
[[materials]]
name = "m"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "box"
nodes = "box.nodes"
links = "box.links"
patches = "box.patches"
[[bodies.supports]]
nodes = [1, 2, 3]
fix = ["x", "y", "z"]
"#;
    // A tetrahedron; its last patch is listed clockwise.
    let nodes = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    let links = "1 2\n1 3\n1 4\n2 3\n2 4\n3 4\n";
    let patches = "1 3 2\n1 2 4\n2 3 4\n1 4 3\n";
    let broken = "1 3 2\n1 2 4\n2 3 4\n1 3 4\n";
    let files = |p: &'static str| {
        [
            ("box.nodes", nodes),
            ("box.links", links),
            ("box.patches", p),
        ]
    };
    let missing =
        format!("{base}[[obstacles]]\nname = \"o\"\nshape = \"mesh\"\nfile = \"nowhere.obj\"\n");
    let (_dir, path) = scene_with(&files(patches), &missing);
    let err = load_scene(&path).unwrap_err().to_string();
    assert!(
        err.contains("nowhere.obj") && err.contains("cannot read"),
        "{err}"
    );

    let with_contact = format!("{base}[contact]\n");
    let (_dir, path) = scene_with(&files(patches), &with_contact);
    let world = load_scene(&path).unwrap();
    if let Err(e) = Simulation::new(&world) {
        panic!("a consistent closed surface is refused: {e}");
    }
    let (_dir, path) = scene_with(&files(broken), &with_contact);
    let world = load_scene(&path).unwrap();
    let err = match Simulation::new(&world) {
        Ok(_) => panic!("inconsistent patches must be reported"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("body 'box'") && err.contains("counter-clockwise"),
        "{err}"
    );
}

/// Linear bodies factored once and condensed on their contact candidates give the answer of
/// the coupled solve (every body's stiffness and the penalties factored together) on every
/// bundled contact scene: displacements to 1e-6 of the largest (both stop at an out-of-balance
/// of 1e-10 of the forces; the penalties, a hundred times the member stiffness, amplify that
/// into the displacements), the same contacts at the end.
/// The stack is left out: where two boxes meet face to face, a node lies on the edge between
/// two patches of the other box and may press on either; both are equilibria of the penalty
/// model, the two paths pick differently, and the answers differ by 1e-4 of the largest
/// displacement. `stack_of_three_boxes_passes_the_load_down` checks its balance on each path.
#[test]
fn condensed_and_coupled_solves_agree_on_the_bundled_scenes() {
    for (scene, tolerance) in [
        ("scenes/two_disks.toml", 1e-6),
        ("scenes/disk_on_floor.toml", 1e-6),
        ("scenes/shell_on_block.toml", 1e-6),
        ("scenes/shell_on_block_moving.toml", 1e-6),
    ] {
        let mut world = load_scene(Path::new(scene)).unwrap();
        assert!(world.bodies.iter().all(|b| !b.is_nonlinear()), "{scene}");
        let condensed = run_all(&world);
        world.contact.condense = false;
        let coupled = run_all(&world);
        for ((a, _), (b, _)) in condensed.iter().zip(&coupled) {
            let largest = b
                .bodies
                .iter()
                .flat_map(|body| &body.displacements)
                .flat_map(|u| u.iter())
                .fold(0.0_f64, |m, x| m.max(x.abs()));
            for (ba, bb) in a.bodies.iter().zip(&b.bodies) {
                for (ua, ub) in ba.displacements.iter().zip(&bb.displacements) {
                    for (x, y) in ua.iter().zip(ub) {
                        assert!(
                            (x - y).abs() <= tolerance * largest,
                            "{scene} step {}: {x} vs {y} (largest {largest})",
                            a.step
                        );
                    }
                }
                let nodes = |c: &[linkage::scene::ContactForce]| -> Vec<usize> {
                    c.iter().map(|c| c.node).collect()
                };
                assert_eq!(nodes(&ba.contacts), nodes(&bb.contacts), "{scene}");
            }
        }
    }
}

/// A flat square plate, 1 m × 1 m in the x-z plane at y = 0, whose contact surface is one
/// layer of patches (an open shell, facing +y): 4 × 4 cells of 0.25 m, stiffened by a second
/// layer of nodes at y = `stiffener` (every pair of corners of a cell joined, as in a box
/// lattice), so that it carries a force across its plane. Its files (nodes, links, patches).
fn plate_files(stiffener: f64) -> (String, String, String) {
    let n = 5;
    let index = |i: usize, j: usize, layer: usize| layer * n * n + j * n + i + 1;
    let mut nodes = String::new();
    for (layer, y) in [0.0, stiffener].into_iter().enumerate() {
        let _ = layer;
        for j in 0..n {
            for i in 0..n {
                nodes.push_str(&format!("{} {y} {}\n", 0.25 * i as f64, 0.25 * j as f64));
            }
        }
    }
    let mut links = std::collections::BTreeSet::new();
    let mut patches = String::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let corners: Vec<usize> = (0..8)
                .map(|k| index(i + (k & 1), j + ((k >> 1) & 1), k >> 2))
                .collect();
            for a in 0..8 {
                for b in a + 1..8 {
                    links.insert((corners[a], corners[b]));
                }
            }
            // Counter-clockwise seen from +y (x right, z toward the viewer: x, then -z).
            let (p00, p10, p01, p11) = (
                index(i, j, 0),
                index(i + 1, j, 0),
                index(i, j + 1, 0),
                index(i + 1, j + 1, 0),
            );
            patches.push_str(&format!("{p00} {p11} {p10}\n{p00} {p01} {p11}\n"));
        }
    }
    let links = links.iter().map(|(a, b)| format!("{a} {b}\n")).collect();
    (nodes, links, patches)
}

/// A plate (see `plate_files`) fixed at its rim, and a small 3D box (0.18 × 0.1 × 0.18 m)
/// starting `gap` (m) from its patches on the side `side` (+1 above, −1 below, the plate's
/// stiffening layer on the other side), held sideways and pushed toward the plate by a total
/// force F = 1000 N: held by contact alone. Its nodes are placed off the plate's patch edges (a
/// node on an edge between two patches may flip between them, see `stack.toml`), and no plate
/// node lies under it (which would press on the box's own closed surface and hold it: only the
/// shell can).
fn box_on_shell(side: f64, gap: f64) -> String {
    let (box_y, face_y) = if side > 0.0 {
        (gap, gap + 0.1)
    } else {
        (-0.1 - gap, -0.1 - gap)
    };
    format!(
        r#"
name = "box_on_shell"
steps = 2
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "plate"
nodes = "plate.nodes"
links = "plate.links"
patches = "plate.patches"
material = "steel"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
fix = ["x", "y", "z"]
[[bodies.supports]]
on_plane = {{ point = [1.0, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}
fix = ["x", "y", "z"]
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
fix = ["x", "y", "z"]
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 1.0], normal = [0.0, 0.0, 1.0] }}
fix = ["x", "y", "z"]
[[bodies]]
name = "box"
box_lattice = {{ size = [0.18, 0.1, 0.18], cells = [2, 1, 2] }}
offset = [0.54, {box_y}, 0.28]
material = "steel"
[[bodies.supports]]
inside = {{ min = [-1.0, -1.0, -1.0], max = [2.0, 2.0, 2.0] }}
fix = ["x", "z"]
[[bodies.loads]]
on_plane = {{ point = [0.0, {face_y}, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [0.0, {force}, 0.0]
[contact]
"#,
        force = -1000.0 * side,
    )
}

/// Open shells are two-sided contact targets. A box pushed onto a flat open shell (one layer of
/// patches facing +y) from above, and the same from below with the force reversed (the nodes
/// then cross the patches from behind): both on the condensed path (linear bodies factored
/// once) and the coupled one. At each step (F/2, F): the plate receives F from the box (1e-6
/// relative) and the box minus that (1e-9), reactions, loads and contact forces balance (1e-8
/// of the largest), and every box node stays on the side it started on (no node farther
/// across the patches than the penetration tolerance, 1% of the box's mean member length).
/// Without the shell as a target the box, held by nothing else, would fly through it. The box
/// starts 1 mm from the shell, or resting on it (its face's nodes on the patches take the side
/// of the box's other nodes).
#[test]
fn box_pressed_on_an_open_shell_from_either_side_is_held() {
    for (side, gap) in [(1.0, 1e-3), (-1.0, 1e-3), (1.0, 0.0), (-1.0, 0.0)] {
        let (nodes, links, patches) = plate_files(-0.1 * side);
        let (_dir, path) = scene_with(
            &[
                ("plate.nodes", &nodes),
                ("plate.links", &links),
                ("plate.patches", &patches),
            ],
            &box_on_shell(side, gap),
        );
        let mut world = load_scene(&path).unwrap();
        let tolerance = linkage::contact::penetration_tolerance(&world.bodies[1]);
        for condense in [true, false] {
            world.contact.condense = condense;
            let runs = run_all(&world);
            let start = &runs[0].0.bodies[1];
            for (result, summary) in runs.iter().skip(1) {
                let what = format!(
                    "side {side}, gap {gap}, condense {condense}, step {}",
                    result.step
                );
                let load = 1000.0 * result.load_factor;
                let total = |body: &str, with: &str| -> Vec<f64> {
                    summary
                        .contact_forces
                        .iter()
                        .find(|p| p.body == body && p.with == with)
                        .unwrap_or_else(|| panic!("{what}: {:?}", summary.contact_forces))
                        .force
                        .clone()
                };
                let (on_plate, on_box) = (total("plate", "box"), total("box", "plate"));
                assert!(
                    (on_plate[1] + side * load).abs() <= 1e-6 * load,
                    "{what}: {on_plate:?}"
                );
                for k in 0..3 {
                    assert!((on_plate[k] + on_box[k]).abs() <= 1e-9 * load, "{what}");
                }
                let (sum, largest) = balance(result);
                for s in sum {
                    assert!(s.abs() <= 1e-8 * largest, "{what}: {sum:?}");
                }
                let moved = &result.bodies[1];
                for (x0, x) in start.positions.iter().zip(&moved.positions) {
                    assert!(x0[1] * side >= 0.0, "{what}: starts on its side");
                    assert!(x[1] * side > -tolerance, "{what}: {x:?} crossed the shell");
                }
                assert!(
                    summary.max_penetration > 0.0 && summary.max_penetration <= tolerance,
                    "{what}: {}",
                    summary.max_penetration
                );
                assert!(
                    summary.warnings.is_empty(),
                    "{what}: {:?}",
                    summary.warnings
                );
            }
        }
    }
}

/// A box held sideways, 0.9 m above a floor and pushed down by 1000 N: at first none of its
/// nodes is near enough the floor to be a contact candidate of the condensed path; it falls,
/// its bottom nodes reach the floor, the candidates widen to them, and the answer is the coupled
/// solve's (displacements to 1e-6 of the largest) with the floor carrying the whole load (1e-6).
#[test]
fn contacts_beyond_the_candidates_widen_them() {
    let scene = r#"
name = "falling_box"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "box"
box_lattice = { size = [1.0, 1.0, 1.0], cells = [4, 4, 4] }
material = "rubber"
[[bodies.supports]]
on_line = { point = [0.0, 0.0, 0.0], direction = [0.0, 1.0, 0.0] }
fix = ["x", "z"]
[[bodies.supports]]
on_line = { point = [1.0, 0.0, 1.0], direction = [0.0, 1.0, 0.0] }
fix = ["x", "z"]
[[bodies.loads]]
on_plane = { point = [0.0, 1.0, 0.0], normal = [0.0, 1.0, 0.0] }
total_force = [0.0, -1000.0, 0.0]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.9, 0.0]
normal = [0.0, 1.0, 0.0]
[contact]
max_iterations = 100
"#;
    let mut world = build_world(scene, Path::new("falling_box.toml")).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let before = sim
        .contact()
        .and_then(|c| c.candidate_nodes(0))
        .expect("condensed");
    assert_eq!(before, 0, "nothing is near the floor at first");
    let condensed: Vec<_> = (0..=world.steps).map(|k| sim.step(k).unwrap()).collect();
    let after = sim
        .contact()
        .and_then(|c| c.candidate_nodes(0))
        .expect("still condensed");
    assert!(
        after >= 25,
        "the bottom face joined the candidates: {after}"
    );
    world.contact.condense = false;
    let coupled = run_all(&world);
    for ((a, _), (b, _)) in condensed.iter().zip(&coupled).skip(1) {
        let f = 1000.0 * a.load_factor;
        let floor: f64 = a.bodies[0].contacts.iter().map(|c| c.force[1]).sum();
        assert!(
            (floor - f).abs() <= 1e-6 * f,
            "floor carries {floor} of {f}"
        );
        let largest = b.bodies[0]
            .displacements
            .iter()
            .flat_map(|u| u.iter())
            .fold(0.0_f64, |m, x| m.max(x.abs()));
        for (ua, ub) in a.bodies[0]
            .displacements
            .iter()
            .zip(&b.bodies[0].displacements)
        {
            for (x, y) in ua.iter().zip(ub) {
                assert!((x - y).abs() <= 1e-6 * largest, "{x} vs {y}");
            }
        }
    }
}

/// Two boxes of 4 × 4 × 4 cells (the lower on its base, the upper held sideways on two
/// vertical lines and pushed down by 1000 N), the upper `gap` above the lower.
fn stacked_boxes(gap: f64) -> String {
    format!(
        r#"
name = "stacked_boxes"
steps = 2
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "lower"
box_lattice = {{ size = [1.0, 1.0, 1.0], cells = [4, 4, 4] }}
solver = "direct"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[bodies]]
name = "upper"
box_lattice = {{ size = [1.0, 1.0, 1.0], cells = [4, 4, 4] }}
solver = "direct"
offset = [0.0, {top}, 0.0]
[[bodies.supports]]
on_line = {{ point = [0.0, {top}, 0.0], direction = [0.0, 1.0, 0.0] }}
fix = ["x", "z"]
[[bodies.supports]]
on_line = {{ point = [1.0, {top}, 1.0], direction = [0.0, 1.0, 0.0] }}
fix = ["x", "z"]
[[bodies.loads]]
on_plane = {{ point = [0.0, {load}, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [0.0, -1000.0, 0.0]
[contact]
max_iterations = 100
"#,
        top = 1.0 + gap,
        load = 2.0 + gap,
    )
}

/// Boxes face to face: the condensed path's candidates of each are its 5 × 5 touching face and,
/// as the other body's nodes at the face's edge press the side patches there, the 16 nodes of
/// the side row next to the face; the rows farther down are not candidates.
#[test]
fn candidates_are_the_touching_face_and_its_patches() {
    let world = build_world(&stacked_boxes(0.0), Path::new("stacked.toml")).unwrap();
    let sim = Simulation::new(&world).unwrap();
    for body in 0..2 {
        let candidates = sim
            .contact()
            .and_then(|c| c.candidate_nodes(body))
            .expect("condensed");
        assert_eq!(candidates, 25 + 16, "body {body}");
    }
}

/// The disks of `scenes/two_disks.toml` with the left one 1 cm farther left (more than the
/// candidates' margin of a quarter member, less than two members): no node is a candidate at
/// first; the disks, held only by contact along x, move together, touch, the candidates of
/// both grow to the nodes the contacts reach, and the answer is the coupled solve's at every
/// step (displacements to 1e-6 of the largest; 2.5e-9 seen).
#[test]
fn contacts_between_bodies_beyond_the_candidates_widen_them() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two_disks.toml"),
    )
    .unwrap();
    let apart = text
        .replace("offset = [-0.1, 0.0]", "offset = [-0.11, 0.0]")
        .replace("nearest = [-0.2, 0.0]", "nearest = [-0.21, 0.0]");
    assert_ne!(apart, text, "the scene moved the left disk");
    let mut world = build_world(&apart, Path::new("two_disks_apart.toml")).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let count = |sim: &Simulation, body: usize| {
        sim.contact()
            .and_then(|c| c.candidate_nodes(body))
            .expect("condensed")
    };
    assert_eq!((count(&sim, 0), count(&sim, 1)), (0, 0), "nothing is near");
    let condensed: Vec<_> = (0..=world.steps).map(|k| sim.step(k).unwrap()).collect();
    for body in 0..2 {
        assert!(count(&sim, body) >= 3, "body {body} grew to its contacts");
    }
    world.contact.condense = false;
    let coupled = run_all(&world);
    for ((a, _), (b, _)) in condensed.iter().zip(&coupled).skip(1) {
        for body in 0..2 {
            let largest = b.bodies[body]
                .displacements
                .iter()
                .flat_map(|u| u.iter())
                .fold(0.0_f64, |m, x| m.max(x.abs()));
            assert!(largest > 0.005, "the disks moved together: {largest} m");
            for (ua, ub) in a.bodies[body]
                .displacements
                .iter()
                .zip(&b.bodies[body].displacements)
            {
                for (x, y) in ua.iter().zip(ub) {
                    assert!((x - y).abs() <= 1e-6 * largest, "body {body}: {x} vs {y}");
                }
            }
        }
    }
}

/// The bar of `bar_pressed_onto_floor_sinks_force_over_penalty` pushed into the floor by a
/// prescribed displacement d of its top instead of a force: the bar (k = E A / L) and the
/// penalty κ act in series, so the foot sinks p = d k / (k + κ) and the floor pushes back with
/// κ p, at every step (to 1e-9), on the condensed path and on the coupled one.
#[test]
fn bar_pushed_by_a_prescribed_displacement_shares_it_with_the_penalty() {
    let scene = r#"
name = "bar_pushed"
steps = 2
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "bar"
nodes = "bar.nodes"
links = "bar.links"
material = "steel"
[[bodies.supports]]
nodes = [1]
fix = ["x"]
[[bodies.supports]]
nodes = [2]
fix = ["x", "y"]
displacement = [0.0, -1e-3]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0]
normal = [0.0, 1.0]
[contact]
penalty = 1e6
"#;
    let (_dir, path) = scene_with(&[("bar.nodes", BAR_NODES), ("bar.links", BAR_LINKS)], scene);
    let (k, kappa) = (200e9 * 1e-4 / 1.0, 1e6);
    for condense in [true, false] {
        let mut world = load_scene(&path).unwrap();
        world.contact.condense = condense;
        for (result, _) in run_all(&world).into_iter().skip(1) {
            let d = 1e-3 * result.load_factor;
            let p = d * k / (k + kappa);
            let bar = &result.bodies[0];
            assert_eq!(bar.contacts.len(), 1, "{:?}", bar.contacts);
            let c = &bar.contacts[0];
            assert!(
                (c.depth - p).abs() <= 1e-9 * p,
                "condense {condense}: depth {} vs {p}",
                c.depth
            );
            assert!(
                (c.force[1] - kappa * p).abs() <= 1e-9 * kappa * p,
                "force {:?}",
                c.force
            );
        }
    }
}

/// A square frame without a diagonal, its base held and its top pushed sideways and down
/// toward a floor it never reaches: it sways (a mechanism), and the error names the swaying
/// nodes rather than saying only that no contact held the body.
#[test]
fn a_mechanism_in_a_contact_scene_is_named() {
    let scene = r#"
name = "mech"
steps = 1
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "frame"
nodes = "sq.nodes"
links = "sq.links"
material = "steel"
[[bodies.supports]]
nodes = [1, 2]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [3]
force = [100.0, -1000.0]
[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, -0.5]
normal = [0.0, 1.0]
"#;
    let (_dir, path) = scene_with(
        &[
            ("sq.nodes", "0 0\n1 0\n1 1\n0 1\n"),
            ("sq.links", "1 2\n2 3\n3 4\n4 1\n"),
        ],
        scene,
    );
    let world = load_scene(&path).unwrap();
    let mut sim = Simulation::new(&world).unwrap();
    let error = (0..=world.steps)
        .find_map(|k| sim.step(k).err().map(|e| e.to_string()))
        .expect("the frame cannot be solved");
    assert!(
        error.contains("body 'frame' is a mechanism") && error.contains("nodes 3 (x), 4 (x)"),
        "{error}"
    );
}

/// Gravity with contact (a pair of the table in docs/SCENES.md): the bar above standing on
/// the floor, loaded by nothing but its own weight (ρ = 7850 kg/m³, g = 9.81 m/s², W = ρ A L g
/// lumped half to each end) and the top node's held sideways only: the floor pushes back with
/// the whole weight W, its foot sinks W/k (k the penalty), and the bar carries −W/2 (its top
/// node's half of the weight), to 1e-9, at both steps (W/2, then W).
#[test]
fn a_bar_standing_on_the_floor_under_its_own_weight() {
    let scene = bar_on_floor("[contact]\npenalty = 1e6\n")
        .replace(
            "[[bodies.loads]]\nnodes = [2]\nforce = [0.0, -1000.0]\n",
            "",
        )
        .replace("steps = 2\n", "steps = 2\ngravity = [0.0, -9.81]\n")
        .replace("area = 1e-4\n", "area = 1e-4\ndensity = 7850\n");
    let (_dir, path) = scene_with(
        &[("bar.nodes", BAR_NODES), ("bar.links", BAR_LINKS)],
        &scene,
    );
    let world = load_scene(&path).unwrap();
    let k = 1e6;
    for (result, _) in run_all(&world).into_iter().skip(1) {
        let w = 7850.0 * 1e-4 * 1.0 * 9.81 * result.load_factor;
        let bar = &result.bodies[0];
        assert_eq!(bar.contacts.len(), 1, "{:?}", bar.contacts);
        let c = &bar.contacts[0];
        assert!(
            (c.force[1] - w).abs() <= 1e-9 * w,
            "{} against {w}",
            c.force[1]
        );
        assert!((c.depth - w / k).abs() <= 1e-9 * w / k, "{}", c.depth);
        assert!(
            (bar.axial_forces[0] + w / 2.0).abs() <= 1e-9 * w,
            "{}",
            bar.axial_forces[0]
        );
    }
}
