//! Bad input gets a clear error naming the file and line, or the body, node and member, and
//! what to do — never a panic, a NaN or a partial file.

use linkage::scene::{load_scene, Simulation};
use std::path::PathBuf;

const MATERIAL: &str = "[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n";

/// A scene with the square's files (which may be replaced) in a fresh folder.
struct Case {
    dir: tempfile::TempDir,
}

impl Case {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("s.nodes"), "1 1\n0 1\n0 0\n1 0\n").unwrap();
        std::fs::write(dir.path().join("s.links"), "1 4\n1 2\n2 3\n3 4\n1 3\n2 4\n").unwrap();
        Case { dir }
    }
    fn file(&self, name: &str, text: &str) -> &Self {
        std::fs::write(self.dir.path().join(name), text).unwrap();
        self
    }
    fn scene(&self, body_extra: &str) -> PathBuf {
        let text = format!(
            "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\n{body_extra}"
        );
        let p = self.dir.path().join("scene.toml");
        std::fs::write(&p, text).unwrap();
        p
    }
    /// The error of loading and solving, as the CLI prints it.
    fn error(&self, body_extra: &str) -> String {
        let p = self.scene(body_extra);
        match load_scene(&p) {
            Err(e) => e.to_string(),
            Ok(world) => match Simulation::new(&world) {
                Err(e) => e.to_string(),
                Ok(_) => panic!("expected an error"),
            },
        }
    }
}

const SUPPORTS: &str = "[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n[[bodies.supports]]\nnodes = [4]\nfix = [\"y\"]\n";

fn assert_has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} lacks {p:?}");
    }
}

/// The case every other test spoils, as given, solves: the paper's square (Fig. 5), node 3
/// pinned, node 4 held in y, 200 N along x at node 2. The supports answer with the reactions
/// statics gives (moments about node 3: node 4 carries 200 N up, node 3 200 N down and 200 N
/// back), node 2 moves along the load, node 3 stays put.
#[test]
fn the_good_case_solves() {
    let c = Case::new();
    let world = load_scene(&c.scene(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = [200.0, 0.0]\n"
    )))
    .unwrap();
    assert_eq!(world.steps, 1);
    let mut sim = Simulation::new(&world).unwrap_or_else(|e| panic!("{e}"));
    let (step, summary) = sim.step(1).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!((step.step, step.load_factor), (1, 1.0));
    assert!(summary.residual <= 1e-9, "residual {}", summary.residual);
    assert_eq!(step.bodies.len(), 1);
    let body = &step.bodies[0];
    assert_eq!(body.name, "sq");
    assert_eq!(body.displacements.len(), 4);
    assert_eq!(body.axial_forces.len(), 6);
    assert!(body.axial_forces.iter().all(|f| f.is_finite()));
    assert_eq!(body.displacements[2], [0.0, 0.0], "node 3 is pinned");
    assert_eq!(body.displacements[3][1], 0.0, "node 4 is held in y");
    assert!(body.displacements[1][0] > 0.0, "{:?}", body.displacements);
    assert!(summary.max_displacement > 0.0);
    let reaction = |node: usize| {
        body.reactions
            .iter()
            .find(|r| r.node == node)
            .unwrap_or_else(|| panic!("a reaction at node {node}: {:?}", body.reactions))
            .force
            .clone()
    };
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * 200.0;
    let r3 = reaction(3);
    let r4 = reaction(4);
    assert!(
        close(r3[0], -200.0) && close(r3[1], -200.0),
        "node 3: {r3:?}"
    );
    assert!(close(r4[0], 0.0) && close(r4[1], 200.0), "node 4: {r4:?}");
    assert_eq!(body.loads.len(), 1);
    assert_eq!(
        (body.loads[0].node, &body.loads[0].force),
        (2, &vec![200.0, 0.0])
    );
}

#[test]
fn malformed_nodes_line() {
    let c = Case::new();
    c.file("s.nodes", "1 1\n0 1\n0 zero\n1 0\n");
    assert_has(&c.error(SUPPORTS), &["s.nodes:3", "zero"]);
    c.file("s.nodes", "1 1\n0 1 0\n0 0\n1 0\n");
    assert_has(&c.error(SUPPORTS), &["s.nodes:2", "3"]);
}

#[test]
fn malformed_links_line() {
    let c = Case::new();
    c.file("s.links", "1 4\n1\n");
    assert_has(&c.error(SUPPORTS), &["s.links:2"]);
}

#[test]
fn node_number_out_of_range() {
    let c = Case::new();
    c.file("s.links", "1 4\n1 2\n2 3\n3 9\n");
    assert_has(&c.error(SUPPORTS), &["s.links:4", "9"]);
}

#[test]
fn member_joining_a_node_to_itself() {
    let c = Case::new();
    c.file("s.links", "1 4\n2 2\n");
    assert_has(&c.error(SUPPORTS), &["s.links:2", "itself"]);
}

#[test]
fn zero_length_member() {
    let c = Case::new();
    c.file("s.nodes", "1 1\n0 1\n0 0\n1 0\n1 1\n");
    c.file("s.links", "1 4\n1 2\n2 3\n3 4\n1 3\n2 4\n1 5\n");
    assert_has(&c.error(SUPPORTS), &["s.links:7"]);
}

#[test]
fn duplicate_member() {
    let c = Case::new();
    c.file("s.links", "1 4\n1 2\n2 3\n3 4\n1 3\n2 4\n4 1\n");
    assert_has(&c.error(SUPPORTS), &["s.links:7", "line 1"]);
}

#[test]
fn non_positive_or_non_finite_material() {
    let c = Case::new();
    for (key, value) in [
        ("youngs_modulus", "0.0"),
        ("youngs_modulus", "-1e9"),
        ("area", "nan"),
        ("area", "inf"),
    ] {
        let text = format!(
            "name = \"t\"\n[[materials]]\nname = \"steel\"\nyoungs_modulus = {}\narea = {}\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\n{SUPPORTS}",
            if key == "youngs_modulus" { value } else { "200e9" },
            if key == "area" { value } else { "1e-4" },
        );
        let p = c.dir.path().join("m.toml");
        std::fs::write(&p, text).unwrap();
        let msg = load_scene(&p).unwrap_err().to_string();
        // The line of the key itself, not the table's header.
        let line = if key == "youngs_modulus" { 4 } else { 5 };
        assert_has(&msg, &[&format!("m.toml:{line}"), key, "steel"]);
    }
}

#[test]
fn non_finite_coordinate() {
    let c = Case::new();
    c.file("s.nodes", "1 1\n0 inf\n0 0\n1 0\n");
    assert_has(&c.error(SUPPORTS), &["s.nodes:2"]);
    c.file("s.nodes", "1 1\n0 1\nNaN 0\n1 0\n");
    assert_has(&c.error(SUPPORTS), &["s.nodes:3"]);
}

#[test]
fn selector_matching_no_node() {
    let c = Case::new();
    let msg = c.error(
        "[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n[[bodies.supports]]\non_line = { point = [5.0, 0.0], direction = [0.0, 1.0] }\nfix = [\"y\"]\n",
    );
    assert_has(&msg, &["scene.toml:15", "`on_line` matches no node", "sq"]);
    let msg = c.error("[[bodies.supports]]\nnodes = [7]\nfix = [\"x\"]\n");
    assert_has(&msg, &["scene.toml:12", "node 7", "1 to 4"]);
}

#[test]
fn body_without_supports() {
    let c = Case::new();
    assert_has(&c.error(""), &["scene.toml:7", "no supports", "sq"]);
}

#[test]
fn mechanism_names_nodes_and_directions() {
    // The square without diagonals is a four-bar linkage: the top can sway in x.
    let c = Case::new();
    c.file("s.links", "1 4\n1 2\n2 3\n3 4\n");
    let msg = c.error(SUPPORTS);
    assert_has(&msg, &["mechanism", "sq", "1 (x", "2 (x"]);
    assert!(!msg.contains("singular matrix"));
}

#[test]
fn rigid_body_motion_is_named() {
    // Only a pin: the whole square can turn about node 3.
    let c = Case::new();
    let msg = c.error("[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n");
    assert_has(&msg, &["rigid-body motion", "sq", "Add supports"]);
}

#[test]
fn collinear_node_is_a_mechanism() {
    // Node 2 between two collinear members at 30°: nothing holds it across the line.
    let c = Case::new();
    let (s, co) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    c.file(
        "s.nodes",
        &format!("0 0\n{} {}\n{} {}\n", co, s, 2.0 * co, 2.0 * s),
    );
    c.file("s.links", "1 2\n2 3\n");
    let msg = c.error(
        "[[bodies.supports]]\nnodes = [1, 3]\nfix = [\"x\", \"y\"]\n[[bodies.loads]]\nnodes = [2]\nforce = [0.0, -10.0]\n",
    );
    assert_has(&msg, &["mechanism", "2 ("]);
}

#[test]
fn unknown_key_and_wrong_type_name_the_line() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforse = [1.0, 0.0]\n"
    ));
    assert_has(&msg, &["scene.toml", "line 19", "forse"]);
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = \"big\"\n"
    ));
    assert_has(&msg, &["scene.toml", "line 19", "force"]);
}

#[test]
fn wrong_vector_size_and_unknown_material() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = [1.0, 0.0, 0.0]\n"
    ));
    assert_has(&msg, &["scene.toml:19", "3 components", "2D"]);
    c.file("s.links", "1 4 copper\n1 2\n2 3\n3 4\n1 3\n2 4\n");
    assert_has(&c.error(SUPPORTS), &["s.links:1", "copper"]);
}

#[test]
fn schedule_length_must_match_steps() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = [1.0, 0.0]\nschedule = [0.5, 1.0]\n"
    ));
    assert_has(&msg, &["scene.toml:20", "2 factors", "1 steps"]);
}

#[test]
fn missing_files_are_named() {
    let c = Case::new();
    std::fs::remove_file(c.dir.path().join("s.links")).unwrap();
    assert_has(&c.error(SUPPORTS), &["s.links"]);
}

/// The error of loading a whole scene `text` written as `scene.toml` in the case's folder.
fn scene_error(c: &Case, text: &str) -> String {
    let p = c.dir.path().join("scene.toml");
    std::fs::write(&p, text).unwrap();
    match load_scene(&p) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("expected an error for\n{text}"),
    }
}

/// The square scene of [`Case::scene`] with `extra` appended, as text.
fn square_text(extra: &str) -> String {
    format!(
        "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\n{SUPPORTS}{extra}"
    )
}

#[test]
fn repeated_node_in_a_selector_is_an_error() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2, 2]\nforce = [200.0, 0.0]\n"
    ));
    assert_has(
        &msg,
        &["scene.toml:18", "sq", "node 2 twice", "list each node once"],
    );
}

#[test]
fn obstacle_keys_of_another_shape_are_errors() {
    let c = Case::new();
    // Each shape with its own keys and one it does not take.
    let cases = [
        (
            "half_space",
            "point = [0.0, -1.0]\nnormal = [0.0, 1.0]\n",
            "radius = 1.0",
            "`point`, `normal`",
        ),
        (
            "cuboid",
            "center = [0.5, -2.0]\nhalf_extents = [1.0, 1.0]\n",
            "radius = 1.0",
            "`center`, `half_extents`, `rotation`",
        ),
        (
            "ball",
            "center = [0.5, -2.0]\nradius = 1.0\n",
            "half_extents = [1.0, 1.0]",
            "`center`, `radius`",
        ),
        (
            "cylinder",
            "center = [0.5, -2.0]\nradius = 1.0\nhalf_height = 1.0\n",
            "normal = [0.0, 1.0]",
            "`center`, `radius`, `half_height`, `rotation`",
        ),
        (
            "capsule",
            "center = [0.5, -2.0]\nradius = 1.0\nhalf_height = 1.0\n",
            "file = \"x.stl\"",
            "`center`, `radius`, `half_height`, `rotation`",
        ),
        (
            "mesh",
            "file = \"x.stl\"\n",
            "center = [0.0, 0.0]",
            "`file`",
        ),
    ];
    for (shape, keys, foreign, takes) in cases {
        let text = square_text(&format!(
            "[[obstacles]]\nname = \"o\"\nshape = \"{shape}\"\n{keys}{foreign}\n"
        ));
        let line = text.lines().position(|l| l == foreign).unwrap() + 1;
        let key = foreign.split(' ').next().unwrap();
        let msg = scene_error(&c, &text);
        assert_has(
            &msg,
            &[
                &format!("scene.toml:{line}:"),
                &format!("`{key}` does not apply to a {shape}"),
                takes,
            ],
        );
    }
}

#[test]
fn generator_keys_of_another_generator_are_errors() {
    let c = Case::new();
    for (generator, foreign) in [
        ("disk = { radius = 1.0, cells = [2, 2] }", "cells"),
        ("rectangle = { width = 1.0, height = 1.0, cells = [2, 2], radius = 1.0 }", "radius"),
        ("cylindrical_shell = { radius = 1.0, length = 2.0, rings = 3, sectors = 8, width = 1.0 }", "width"),
        ("box_lattice = { size = [1.0, 1.0, 1.0], cells = [1, 1, 1], rings = 2 }", "rings"),
    ] {
        let text = format!("name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"g\"\n{generator}\n");
        let msg = scene_error(&c, &text);
        let name = generator.split(' ').next().unwrap();
        assert_has(&msg, &["scene.toml", "line 9", &format!("{name}: unknown key `{foreign}`"), "expected"]);
    }
}

#[test]
fn empty_names_are_errors() {
    let c = Case::new();
    let text = square_text("").replace("name = \"sq\"", "name = \"\"");
    assert_has(
        &scene_error(&c, &text),
        &["scene.toml:8", "`name` is empty", "body"],
    );
    let text = square_text("").replace("name = \"steel\"", "name = \"\"");
    assert_has(
        &scene_error(&c, &text),
        &["scene.toml:3", "`name` is empty", "material"],
    );
    let text = square_text(
        "[[obstacles]]\nname = \"\"\nshape = \"half_space\"\npoint = [0.0, -1.0]\nnormal = [0.0, 1.0]\n",
    );
    assert_has(
        &scene_error(&c, &text),
        &["scene.toml:18", "`name` is empty", "obstacle"],
    );
}

#[test]
fn load_on_a_fixed_direction_is_an_error() {
    let c = Case::new();
    // Node 3 is pinned: a load there goes into the reaction.
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [3]\nforce = [200.0, 0.0]\n"
    ));
    assert_has(&msg, &["scene.toml:19", "sq", "node 3 in x", "reaction"]);
    // Node 4 is held in y only: a load along x is fine, one along y is not.
    c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [4]\nforce = [0.0, 5.0]\n"
    ));
    let p = c.scene(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [4]\nforce = [5.0, 0.0]\n"
    ));
    load_scene(&p).unwrap_or_else(|e| panic!("{e}"));
    // A line through supported and free nodes may load them all; one only through supported
    // nodes may not.
    let p = c.scene(&format!(
        "{SUPPORTS}[[bodies.loads]]\non_line = {{ point = [0.0, 0.0], direction = [0.0, 1.0] }}\nforce = [5.0, 0.0]\n"
    ));
    load_scene(&p).unwrap_or_else(|e| panic!("{e}"));
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\non_line = {{ point = [0.0, 0.0], direction = [1.0, 0.0] }}\nforce = [0.0, 5.0]\n"
    ));
    assert_has(&msg, &["scene.toml:19", "node 3 in y"]);
}

#[test]
fn huge_coordinates_are_reported_as_overflow() {
    let c = Case::new();
    c.file("s.nodes", "1e308 1\n0 1\n0 0\n1 0\n");
    let msg = c.error(SUPPORTS);
    assert_has(
        &msg,
        &["scene.toml:9", "s.nodes", "node 1", "too large to square"],
    );
    assert!(!msg.contains("same place"), "{msg}");
    // Generated coordinates that overflow when squared.
    let text = format!(
        "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"g\"\ndisk = {{ radius = 1e300 }}\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n"
    );
    let msg = scene_error(&c, &text);
    assert_has(&msg, &["g", "too large to square"]);
    assert!(!msg.contains("same place"), "{msg}");
}

#[test]
fn axial_stiffness_out_of_range_names_the_material() {
    let c = Case::new();
    let text = square_text("").replace(
        "youngs_modulus = 200e9\narea = 1e-4",
        "youngs_modulus = 1e308\narea = 1e308",
    );
    assert_has(
        &scene_error(&c, &text),
        &["scene.toml:4", "steel", "E A = inf"],
    );
    // E A finite, E A / L not: tiny members.
    c.file("s.nodes", "1e-9 1e-9\n0 1e-9\n0 0\n1e-9 0\n");
    let text = square_text("").replace(
        "youngs_modulus = 200e9\narea = 1e-4",
        "youngs_modulus = 1e200\narea = 1e100",
    );
    assert_has(&scene_error(&c, &text), &["steel", "E A / L", "member 1"]);
}

#[test]
fn overflowing_load_is_reported_at_input() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = [1e308, 1e308]\n"
    ));
    assert_has(&msg, &["scene.toml:19", "sq", "`force` overflows"]);
    assert!(!msg.contains("condition"), "{msg}");
}

#[test]
fn strength_is_named_as_written() {
    let c = Case::new();
    let text = square_text("").replace("area = 1e-4", "area = 1e-4\nstrength = -5");
    let msg = scene_error(&c, &text);
    assert_has(&msg, &["scene.toml:6", "strength = -5", "steel"]);
    assert!(!msg.contains("tensile_strength"), "{msg}");
}

#[test]
fn errors_point_at_the_key_not_the_header() {
    let c = Case::new();
    let text = square_text("[output]\nevery = 1\nwidth = 3\n");
    assert_has(&scene_error(&c, &text), &["scene.toml:19", "width = 3"]);
    let text = square_text("[output]\nevery = 0\n");
    assert_has(&scene_error(&c, &text), &["scene.toml:18", "every = 0"]);
    let text = square_text("").replace("area = 1e-4", "area = 1e-4\nbehaviour = \"rubber\"");
    assert_has(&scene_error(&c, &text), &["scene.toml:6", "rubber"]);
    let text = square_text("")
        .replace("steps", "x")
        .replace("name = \"t\"", "name = \"t\"\nsteps = 0");
    assert_has(&scene_error(&c, &text), &["scene.toml:2", "steps = 0"]);
}

#[test]
fn missing_nodes_file_names_the_scene_line() {
    let c = Case::new();
    std::fs::remove_file(c.dir.path().join("s.nodes")).unwrap();
    assert_has(
        &c.error(SUPPORTS),
        &[
            "scene.toml:9",
            "`nodes`",
            "s.nodes",
            "relative to the folder",
        ],
    );
}

#[test]
fn links_errors_start_with_the_scene() {
    // `check` and `run` print the same message when it starts with the scene file.
    let c = Case::new();
    c.file("s.links", "1 4\n1 2\n2 3\n3 9\n");
    let p = c.scene(SUPPORTS);
    let msg = load_scene(&p).unwrap_err().to_string();
    assert!(
        msg.starts_with(&format!("{}:10: body 'sq': ", p.display())),
        "{msg}"
    );
    assert_has(&msg, &["s.links:4", "9"]);
}

#[test]
fn rotation_in_2d_is_one_angle_with_or_without_brackets() {
    let c = Case::new();
    let shapes: Vec<String> = ["45.0", "[45.0]", "45"]
        .iter()
        .map(|r| {
            let p = c.dir.path().join("r.toml");
            std::fs::write(
                &p,
                square_text(&format!(
                    "[[obstacles]]\nname = \"o\"\nshape = \"cuboid\"\ncenter = [0.5, -2.0]\nhalf_extents = [1.0, 0.5]\nrotation = {r}\n"
                )),
            )
            .unwrap();
            let world = load_scene(&p).unwrap_or_else(|e| panic!("rotation = {r}: {e}"));
            format!("{:?}", world.obstacles[0].shape)
        })
        .collect();
    assert_eq!(shapes[0], shapes[1]);
    assert_eq!(shapes[0], shapes[2]);
    let text = square_text(
        "[[obstacles]]\nname = \"o\"\nshape = \"cuboid\"\ncenter = [0.5, -2.0]\nhalf_extents = [1.0, 0.5]\nrotation = [1.0, 2.0]\n",
    );
    assert_has(
        &scene_error(&c, &text),
        &["scene.toml:22", "`rotation` has 2 components"],
    );
}

// ---------------------------------------------------------------- mesh obstacles

/// A closed unit cube as OBJ text, counter-clockwise seen from outside.
const CUBE_OBJ: &str = "\
v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// One ASCII STL facet with `corners` (each `x y z` text).
fn facet(corners: &[&str]) -> String {
    let mut s = "facet normal 0 0 1\nouter loop\n".to_string();
    for c in corners {
        s += &format!("vertex {c}\n");
    }
    s + "endloop\nendfacet\n"
}

/// The error of a 3D scene whose mesh obstacle reads `file` with `bytes`.
fn mesh_error(file: &str, bytes: &[u8]) -> String {
    let c = Case::new();
    std::fs::write(c.dir.path().join(file), bytes).unwrap();
    let text = format!(
        "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"b\"\nbox_lattice = {{ size = [0.2, 0.2, 0.2], cells = [1, 1, 1] }}\noffset = [0.0, 2.0, 0.0]\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\", \"z\"]\n[[obstacles]]\nname = \"m\"\nshape = \"mesh\"\nfile = \"{file}\"\n"
    );
    scene_error(&c, &text)
}

#[test]
fn ascii_stl_facet_with_two_or_four_vertices_names_its_line() {
    let good = facet(&["0 0 0", "1 0 0", "0 1 0"]);
    for (corners, count) in [
        (&["0 0 0", "1 0 0"][..], 2),
        (&["0 0 0", "1 0 0", "0 1 0", "1 1 0"], 4),
    ] {
        // The bad facet is the second: it starts on line 9 (after `solid` and 7 lines). The
        // scene line is that of `file`.
        let text = format!("solid t\n{good}{}endsolid t\n", facet(corners));
        let msg = mesh_error("m.stl", text.as_bytes());
        assert_has(
            &msg,
            &[
                "scene.toml:17: obstacle 'm': `file`: ",
                "m.stl:9:",
                &format!("has {count} vertices"),
                "exactly 3",
            ],
        );
    }
    // A facet cut short at the end of the file.
    let msg = mesh_error(
        "m.stl",
        format!("solid t\n{good}facet normal 0 0 1\nouter loop\nvertex 0 0 0\n").as_bytes(),
    );
    assert_has(&msg, &["m.stl:9:", "not closed by `endfacet`"]);
}

#[test]
fn obj_vertex_with_two_or_four_coordinates_or_a_word_names_its_line() {
    for (line, expect) in [
        ("v 1 2", "a vertex has 2 numbers"),
        ("v 1 2 3 1", "a vertex has 4 numbers"),
        ("v 1 two 3", "\"two\" is not a number"),
    ] {
        let text = CUBE_OBJ.replacen("v 0.5 -0.5 -0.5", line, 1);
        assert_has(
            &mesh_error("m.obj", text.as_bytes()),
            &["obstacle 'm'", "m.obj:2:", expect],
        );
    }
}

#[test]
fn extra_tokens_in_an_ascii_stl_name_their_line() {
    let good = facet(&["0 0 0", "1 0 0", "0 1 0"]);
    for (from, to, line) in [
        ("vertex 1 0 0", "vertex 1 0 0 7", 5),
        ("facet normal 0 0 1", "facet normal 0 0 1 0", 2),
        ("endloop", "endloop now", 7),
        ("outer loop", "outer", 3),
    ] {
        let text = format!("solid t\n{}endsolid t\n", good.replacen(from, to, 1));
        let msg = mesh_error("m.stl", text.as_bytes());
        assert_has(&msg, &[&format!("m.stl:{line}:"), "words: write it as"]);
    }
    // A line out of place.
    let text = format!(
        "solid t\n{}endsolid t\n",
        good.replacen("outer loop\n", "", 1)
    );
    assert_has(
        &mesh_error("m.stl", text.as_bytes()),
        &["m.stl:3:", "`vertex` is out of place", "`outer loop`"],
    );
}

#[test]
fn nan_and_inf_coordinates_name_their_line() {
    for word in ["nan", "inf", "-inf", "NaN"] {
        let obj = CUBE_OBJ.replacen("v 0.5 0.5 -0.5", &format!("v 0.5 {word} -0.5"), 1);
        assert_has(
            &mesh_error("m.obj", obj.as_bytes()),
            &["m.obj:3:", "not a finite number"],
        );
        let stl = format!(
            "solid t\n{}endsolid t\n",
            facet(&["0 0 0", &format!("1 {word} 0"), "0 1 0"])
        );
        assert_has(
            &mesh_error("m.stl", stl.as_bytes()),
            &["m.stl:5:", "not a finite number"],
        );
    }
    // Finite but too large to compute with.
    let obj = CUBE_OBJ.replacen("v 0.5 0.5 -0.5", "v 0.5 1e200 -0.5", 1);
    assert_has(
        &mesh_error("m.obj", obj.as_bytes()),
        &["m.obj:3:", "1e200", "beyond ±1e100 m"],
    );
}

/// A binary STL of `triangles` (corners in m).
fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let mut out = vec![b' '; 80];
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend([0u8; 12]);
        for c in t {
            for x in c {
                out.extend(x.to_le_bytes());
            }
        }
        out.extend([0u8; 2]);
    }
    out
}

#[test]
fn binary_stl_with_nan_or_a_degenerate_triangle_names_the_triangle() {
    let mut t = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ];
    t[1][1][2] = f32::NAN;
    assert_has(
        &mesh_error("m.stl", &binary_stl(&t)),
        &[
            "obstacle 'm'",
            "m.stl",
            "triangle 2 (of 2), corner 2",
            "not finite",
        ],
    );
    t[1] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    assert_has(
        &mesh_error("m.stl", &binary_stl(&t)),
        &["triangle 2 (of 2)", "zero area"],
    );
    assert_has(
        &mesh_error("m.stl", &binary_stl(&[])),
        &["m.stl", "no triangles"],
    );
}

#[test]
fn face_naming_vertex_zero_or_one_not_defined_names_its_line() {
    for (face, expect) in [
        ("f 0 4 3 2", "vertex 0: OBJ vertex numbers start at 1"),
        (
            "f 1 4 3 9",
            "face names vertex 9, but only 8 are defined above it",
        ),
        ("f 1 -9 3", "face names vertex -9"),
        ("f 1 4", "a face has 2 vertices"),
        ("f 1 4 x", "\"x\" is not a vertex number"),
    ] {
        let text = CUBE_OBJ.replacen("f 1 4 3 2", face, 1);
        assert_has(&mesh_error("m.obj", text.as_bytes()), &["m.obj:9:", expect]);
    }
}

#[test]
fn zero_area_triangle_names_its_line() {
    // A repeated corner, and corners on one line (vertex 9 midway between 1 and 2).
    let text = CUBE_OBJ.replacen("f 1 4 3 2", "f 1 4 3 2\nf 1 1 2", 1);
    assert_has(
        &mesh_error("m.obj", text.as_bytes()),
        &["m.obj:10:", "repeats a corner", "zero-area"],
    );
    let text = format!("{CUBE_OBJ}v 0 -0.5 -0.5\nf 1 2 9\n");
    assert_has(
        &mesh_error("m.obj", text.as_bytes()),
        &["m.obj:16:", "zero area", "lie on one line"],
    );
}

#[test]
fn empty_mesh_is_an_error() {
    assert_has(
        &mesh_error("m.obj", b"# nothing\nv 0 0 0\n"),
        &["m.obj", "no triangles"],
    );
    assert_has(&mesh_error("m.obj", b""), &["m.obj", "no triangles"]);
    assert_has(
        &mesh_error("m.stl", b"solid t\nendsolid t\n"),
        &["m.stl", "no triangles"],
    );
}

// ---------------------------------------------------------------- overflowing geometry

/// The error of the square scene with `obstacle` (the keys after `name`), and its line.
fn obstacle_error(obstacle: &str) -> (String, String) {
    let c = Case::new();
    let text = square_text(&format!("[[obstacles]]\nname = \"o\"\n{obstacle}\n"));
    (scene_error(&c, &text), text)
}

/// The 1-based line of `text` that starts with `start`.
fn line_of(text: &str, start: &str) -> usize {
    text.lines().position(|l| l.starts_with(start)).unwrap() + 1
}

#[test]
fn ball_of_radius_1e155_is_an_input_error() {
    let (msg, text) = obstacle_error("shape = \"ball\"\ncenter = [0.5, -3.0]\nradius = 1e155");
    let line = line_of(&text, "radius");
    assert_has(
        &msg,
        &[
            &format!("scene.toml:{line}:"),
            "obstacle 'o'",
            "`radius` = 1e155 m",
            "beyond ±1e100 m",
            "give lengths in metres",
        ],
    );
    // A centre far away too.
    let (msg, text) = obstacle_error("shape = \"ball\"\ncenter = [0.5, -1e200]\nradius = 1.0");
    assert_has(
        &msg,
        &[
            &format!("scene.toml:{}:", line_of(&text, "center")),
            "`center`",
            "beyond",
        ],
    );
}

#[test]
fn rotation_of_1e308_degrees_is_an_input_error() {
    let (msg, text) = obstacle_error(
        "shape = \"cuboid\"\ncenter = [0.5, -3.0]\nhalf_extents = [1.0, 1.0]\nrotation = 1e308",
    );
    assert_has(
        &msg,
        &[
            &format!("scene.toml:{}:", line_of(&text, "rotation")),
            "obstacle 'o'",
            "1e308 degrees",
            "within ±1e6",
            "modulo 360",
        ],
    );
    // Up to the bound it is an angle like any other.
    let c = Case::new();
    let text = square_text("[[obstacles]]\nname = \"o\"\nshape = \"cuboid\"\ncenter = [0.5, -3.0]\nhalf_extents = [1.0, 1.0]\nrotation = 720.5\n");
    std::fs::write(c.dir.path().join("scene.toml"), text).unwrap();
    assert!(load_scene(&c.dir.path().join("scene.toml")).is_ok());
}

#[test]
fn travel_of_1e308_is_an_input_error() {
    let (msg, text) = obstacle_error(
        "shape = \"half_space\"\npoint = [0.0, -1.0]\nnormal = [0.0, 1.0]\ntravel = [0.0, 1e308]",
    );
    assert_has(
        &msg,
        &[
            &format!("scene.toml:{}:", line_of(&text, "travel")),
            "obstacle 'o'",
            "`travel`",
            "beyond ±1e100 m",
        ],
    );
    // A travel within bounds whose schedule multiplies it past them.
    let (msg, _) = obstacle_error(
        "shape = \"half_space\"\npoint = [0.0, -1.0]\nnormal = [0.0, 1.0]\ntravel = [0.0, 1e90]\nschedule = [1e20]",
    );
    assert_has(&msg, &["`travel`", "largest `schedule` factor"]);
}

#[test]
fn huge_generated_or_offset_bodies_are_input_errors() {
    let c = Case::new();
    let body = |geometry: &str| {
        format!(
        "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"g\"\n{geometry}\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n"
    )
    };
    let msg = scene_error(
        &c,
        &body("rectangle = { width = 1e155, height = 1.0, cells = [1, 1] }"),
    );
    assert_has(
        &msg,
        &["body 'g'", "`rectangle` places node", "too large to square"],
    );
    let msg = scene_error(&c, &body("disk = { radius = 1.0 }\noffset = [1e200, 0.0]"));
    assert_has(
        &msg,
        &["scene.toml:", "body 'g'", "`offset`", "beyond ±1e100 m"],
    );
}

#[test]
fn absurd_step_counts_are_refused_before_anything_is_allocated() {
    // 2^32 load steps: the summary lines alone would take some 1 TB of memory, the step files
    // 54 TB of disk. Refused with the estimate and what the machine has; nothing is written.
    let case = Case::new();
    let text = format!(
        "name = \"t\"\nsteps = 4294967296\n{MATERIAL}\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\n[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n[[bodies.supports]]\nnodes = [4]\nfix = [\"y\"]\n[[bodies.loads]]\nnodes = [2]\nforce = [200.0, 0.0]\n"
    );
    let scene = case.dir.path().join("huge.toml");
    std::fs::write(&scene, text).unwrap();
    let out = case.dir.path().join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert_has(
        &stdout,
        &["huge.toml", "GB of memory", "available", "fewer load steps"],
    );
    assert!(!out.join("t").exists());
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Issue 33, item 4: a generator of 10⁹ cells is refused before anything is allocated, with
/// the generator's key, its parameters, the counts, the memory estimate (at least 144 B per
/// node and 56 B + d² · 16 B per member, `scene::fits_machine`) and what the machine has. By
/// hand: 1000³ box cells make 1001³ ≈ 1.003e9 nodes and 1.301e10 members, at least 2.747e3 GB;
/// 31623² rectangle cells make 1.000e9 nodes and 4.000e9 members, at least 6.240e2 GB.
#[test]
fn generators_of_a_billion_cells_are_refused_with_a_memory_estimate_before_allocating() {
    let c = Case::new();
    let body = |geometry: &str| {
        format!(
            "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"g\"\n{geometry}\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n"
        )
    };
    let cases = [
        (
            "box_lattice = { size = [1.0, 1.0, 1.0], cells = [1000, 1000, 1000] }",
            vec![
                "`box_lattice` with cells = [1000, 1000, 1000]",
                "1.003e9 nodes",
                "1.301e10 members",
                "at least 2.747e3 GB of memory",
            ],
        ),
        (
            "rectangle = { width = 1.0, height = 1.0, cells = [31623, 31623] }",
            vec![
                "`rectangle` with cells = [31623, 31623]",
                "1.000e9 nodes",
                "4.000e9 members",
                "at least 6.240e2 GB of memory",
            ],
        ),
        (
            "disk = { radius = 1.0, rings = 31623, sectors = 31623 }",
            vec!["`disk` with rings = 31623, sectors = 31623", "GB of memory"],
        ),
        (
            "cylindrical_shell = { radius = 1.0, length = 1.0, rings = 31623, sectors = 31623 }",
            vec![
                "`cylindrical_shell` with rings = 31623, sectors = 31623",
                "GB of memory",
            ],
        ),
    ];
    for (geometry, parts) in &cases {
        let started = std::time::Instant::now();
        let msg = scene_error(&c, &body(geometry));
        assert!(started.elapsed().as_secs_f64() < 2.0, "{geometry}: slow");
        assert_has(
            &msg,
            &[
                "scene.toml:",
                "body 'g'",
                "GB available",
                "give fewer cells",
            ],
        );
        assert_has(&msg, parts);
    }
    // `linkage run` refuses it the same way and writes nothing.
    let scene = c.dir.path().join("huge.toml");
    std::fs::write(&scene, body(cases[0].0)).unwrap();
    let out = c.dir.path().join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(o.status.code(), Some(1), "{stdout}");
    assert_has(&stdout, &["huge.toml", "`box_lattice`", "GB of memory"]);
    assert!(!out.join("t").exists());
    // A size that fits is built as before.
    std::fs::write(
        &scene,
        body("box_lattice = { size = [1.0, 1.0, 1.0], cells = [2, 2, 2] }"),
    )
    .unwrap();
    assert!(load_scene(&scene).is_ok());
}

#[test]
fn a_body_check_made_before_solving_points_at_the_key_not_the_body_header() {
    // Node 5 belongs to no member: the error is about the links, so it names the line of
    // `links = "s.links"` (line 10), not `[[bodies]]` (line 7).
    let c = Case::new();
    c.file("s.nodes", "1 1\n0 1\n0 0\n1 0\n2 2\n");
    let e = c.error(SUPPORTS);
    assert_has(&e, &["scene.toml:10:", "node 5"]);
}

/// Issue 33, item 7: an unknown key inside a generator names the generator (inline tables and
/// `[bodies.<generator>]` tables), the line and column, and the keys it takes.
#[test]
fn generator_key_errors_name_the_generator() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "box_lattice = { size = [1.0, 1.0, 1.0], cell = [3, 3, 3] }",
            "box_lattice: unknown key `cell`, expected",
            "`cells`",
        ),
        (
            "rectangle = { width = 1.0, height = 0.1, cell = [10, 1] }",
            "rectangle: unknown key `cell`, expected",
            "`cells`",
        ),
        (
            "disk = { radius = 1.0, ring = 3 }",
            "disk: unknown key `ring`, expected",
            "`rings`",
        ),
        (
            "[bodies.cylindrical_shell]\nradius = 1.0\nlenght = 2.0",
            "cylindrical_shell: unknown key `lenght`, expected",
            "`length`",
        ),
    ];
    for (body, named, valid) in cases {
        let line = if body.starts_with('[') {
            "line 11"
        } else {
            "line 9"
        };
        let text = format!("name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"b\"\n{body}\n");
        let path = dir.path().join("gen.toml");
        std::fs::write(&path, &text).unwrap();
        let message = load_scene(&path).unwrap_err().to_string();
        assert_has(&message, &["gen.toml", line, named, valid]);
    }
    // A key outside a generator is not given one.
    let text = format!("name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"b\"\nnodez = \"s.nodes\"\n");
    let path = dir.path().join("gen.toml");
    std::fs::write(&path, &text).unwrap();
    let message = load_scene(&path).unwrap_err().to_string();
    assert!(!message.contains(": unknown key"), "{message}");
}

/// Issue 33, item 4: absurd sizes besides `steps` are refused with a message before anything is
/// allocated or written: `[dynamics]` frames and time steps, a mesh spacing of 1e-9 m, and a
/// sweep grid of 10¹² variants (four keys of 1,000 values; `sweep.rs` holds the 10⁶ × 10⁶ grid).
#[test]
fn absurd_frames_spacings_and_sweeps_are_refused_before_allocating() {
    let case = Case::new();
    let run = |name: &str, text: &str| {
        let scene = case.dir.path().join(name);
        std::fs::write(&scene, text).unwrap();
        let out = case.dir.path().join("out");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_linkage"))
            .arg("run")
            .arg(&scene)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert_ne!(o.status.code(), Some(0), "{name}: {said}");
        assert!(o.status.code().is_some(), "{name}: killed: {said}");
        // Only the failed row of batch.csv.
        let left: Vec<String> = std::fs::read_dir(&out)
            .map(|r| {
                r.flatten()
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        assert!(
            left.iter().all(|n| n == "batch.csv"),
            "{name} wrote {left:?}: {said}"
        );
        said
    };
    let dynamics = |settings: &str| {
        format!("name = \"t\"\n[dynamics]\n{settings}\n[[materials]]\nname = \"rubber\"\nyoungs_modulus = 1e7\narea = 1e-3\ndensity = 1000.0\n[[bodies]]\nname = \"c\"\nrectangle = {{ width = 1.0, height = 0.1, cells = [10, 1] }}\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\"]\n")
    };
    let said = run(
        "frames.toml",
        &dynamics("duration = 1.5\ntime_step = 1.5e-9\nframes = 1000000000"),
    );
    assert_has(
        &said,
        &["frames.toml", "GB of memory", "available", "fewer frames"],
    );
    let said = run(
        "time_step.toml",
        &dynamics("duration = 1.5\ntime_step = 1e-15\nframes = 10"),
    );
    assert_has(
        &said,
        &[
            "time_step.toml:4",
            "`time_step`",
            "steps",
            "longer time step",
        ],
    );
    let said = run(
        "more_frames.toml",
        &dynamics("duration = 1.5\ntime_step = 0.005\nframes = 4000000000"),
    );
    assert_has(
        &said,
        &["more_frames.toml:5", "`frames`", "at most 300 frames"],
    );
    std::fs::write(
        case.dir.path().join("cube.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n",
    )
    .unwrap();
    let said = run(
        "spacing.toml",
        &format!("name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"cube\"\nmesh = {{ file = \"cube.obj\", spacing = 1e-9 }}\n[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\", \"z\"]\n"),
    );
    // (1 m / 1e-9 m)³ cells: about 1.4e28 members, 5.1e21 GB while preparing.
    assert_has(
        &said,
        &[
            "spacing.toml:9",
            "body 'cube'",
            "spacing = 0.000000001 m",
            "e28 members",
            "e21 GB while preparing",
            "give a spacing of at least",
        ],
    );
    let values = |first: f64, step: f64| {
        (0..1000)
            .map(|k| format!("{:?}", first + step * k as f64))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let sweep = format!(
        "name = \"t\"\n{MATERIAL}\n[[bodies]]\nname = \"sq\"\nnodes = \"s.nodes\"\nlinks = \"s.links\"\n[[bodies.supports]]\nnodes = [3]\nfix = [\"x\", \"y\"]\n[[bodies.loads]]\nnodes = [2]\nforce = [200.0, 0.0]\n[sweep]\n\"materials.1.youngs_modulus\" = [{}]\n\"materials.1.area\" = [{}]\n\"bodies.1.loads.1.force.1\" = [{}]\n\"bodies.1.loads.1.force.2\" = [{}]\n",
        values(1e9, 1e6),
        values(1e-4, 1e-8),
        values(1.0, 1.0),
        values(-1.0, -1.0)
    );
    let said = run("sweep.toml", &sweep);
    assert_has(
        &said,
        &[
            "sweep.toml:17",
            "[sweep] makes 1000000000000 variants",
            "1000 × 1000 × 1000 × 1000",
            "GB of memory",
            "GB of disk",
            "at most 1000000 variants",
        ],
    );
}
