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
        assert_has(&msg, &["m.toml:2", key, "steel"]);
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
    assert_has(&msg, &["scene.toml:14", "matches no node", "sq"]);
    let msg = c.error("[[bodies.supports]]\nnodes = [7]\nfix = [\"x\"]\n");
    assert_has(&msg, &["scene.toml:11", "node 7", "1 to 4"]);
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
    assert_has(&msg, &["scene.toml:17", "3 components", "2D"]);
    c.file("s.links", "1 4 copper\n1 2\n2 3\n3 4\n1 3\n2 4\n");
    assert_has(&c.error(SUPPORTS), &["s.links:1", "copper"]);
}

#[test]
fn schedule_length_must_match_steps() {
    let c = Case::new();
    let msg = c.error(&format!(
        "{SUPPORTS}[[bodies.loads]]\nnodes = [2]\nforce = [1.0, 0.0]\nschedule = [0.5, 1.0]\n"
    ));
    assert_has(&msg, &["scene.toml:17", "2 factors", "1 steps"]);
}

#[test]
fn missing_files_are_named() {
    let c = Case::new();
    std::fs::remove_file(c.dir.path().join("s.links")).unwrap();
    assert_has(&c.error(SUPPORTS), &["s.links"]);
}
