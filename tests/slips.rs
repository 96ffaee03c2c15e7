//! Slips that used to pass in silence (issue 33, item 5): each is warned about, in the step's
//! warnings of `summary.json` and by `linkage run`, and by `linkage check` when it is known
//! before solving. Each test is named after its case.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

fn out(o: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// `text` written to `dir/scene.toml`.
fn write_scene(dir: &Path, text: &str) -> PathBuf {
    let scene = dir.join("scene.toml");
    std::fs::write(&scene, text).unwrap();
    scene
}

/// `linkage run scene --out dir/out`, which must succeed; its output and `summary.json`.
fn run_ok(dir: &Path, scene: &Path, name: &str) -> (Output, serde_json::Value) {
    let results = dir.join("out");
    let run = linkage()
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(&results)
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", out(&run));
    let summary = read_json(&results.join(name).join("summary.json"));
    (run, summary)
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// Every warning of the run, with its step.
fn warnings(summary: &serde_json::Value) -> Vec<(usize, String)> {
    summary["steps"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|s| {
            let step = s["step"].as_u64().unwrap() as usize;
            s["warnings"]
                .as_array()
                .cloned()
                .unwrap_or_default()
                .into_iter()
                .map(move |w| (step, w.as_str().unwrap().to_string()))
        })
        .collect()
}

fn assert_has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} lacks {p:?}");
    }
}

/// The 24 m bridge: a 2D truss of 8 × 1 cells, 24 m × 3 m (nodes 1–9 along the bottom, 10–18
/// along the top), pinned at node 1 and held in y at node 9, 10 kN down at the top middle
/// (node 14, chosen by `load_at`), with the modulus `e` (Pa) and A = 0.01 m².
fn bridge(e: &str, load_at: &str) -> String {
    format!(
        r#"name = "bridge"
[[materials]]
name = "steel"
youngs_modulus = {e}
area = 0.01
[[bodies]]
name = "bridge"
rectangle = {{ width = 24.0, height = 3.0, cells = [8, 1] }}
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [9]
fix = ["y"]
[[bodies.loads]]
{load_at}
force = [0.0, -1e4]
"#
    )
}

/// `youngs_modulus = 200` (meant 200e9) on the 24 m bridge: the run succeeds, but step 1 warns
/// once: it names the member of largest |strain| in the step file and that strain (to the
/// 0.001 % printed), suggests 200e9 and `kinematics = "large"`; `linkage run` prints it. With
/// 200e9 Pa the strains are about 1e-6 (10 kN on 0.01 m² at 200 GPa: σ/E ≈ 5e-6): no warning.
#[test]
fn a_youngs_modulus_of_200_on_a_24_m_bridge_warns_of_its_unit() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &bridge("200", "nodes = [14]"));
    let (run, summary) = run_ok(dir.path(), &scene, "bridge");
    let found = warnings(&summary);
    assert_eq!(found.len(), 1, "{found:?}");
    let (step, w) = &found[0];
    assert_eq!(*step, 1);
    let result = read_json(&dir.path().join("out/bridge/steps/0001.json"));
    let strains: Vec<f64> = result["bodies"][0]["strains"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (member, strain) = strains
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .unwrap();
    assert!(strain.abs() > 0.05, "{strain}");
    assert_has(
        w,
        &[
            "step 1: body 'bridge'",
            &format!("member {} is strained {:.3} %", member + 1, 100.0 * strain),
            "youngs_modulus = 200 Pa: did you mean 200e9",
            "kinematics = \"large\"",
        ],
    );
    assert!(
        String::from_utf8_lossy(&run.stdout).contains(&format!("warn  bridge: {w}")),
        "{}",
        out(&run)
    );
    // The modulus meant: strains of a few 1e-6, no warning.
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &bridge("200e9", "nodes = [14]"));
    let (_, summary) = run_ok(dir.path(), &scene, "bridge");
    assert_eq!(warnings(&summary), []);
}

/// A modulus given in MPa (`youngs_modulus = 2000`, 2 GPa meant as 2000e6) is told so; the
/// same bridge with large kinematics is not watched (its strains may be large by design).
#[test]
fn a_youngs_modulus_in_mpa_is_told_and_a_large_body_is_not_watched() {
    let dir = tempfile::tempdir().unwrap();
    // 1 N on a bridge of E A = 20 N: chord forces of about 2 N (the moment 1 N × 24 m / 4 over
    // the 3 m depth), strains of about 10 %.
    let text = bridge("2000", "nodes = [14]").replace("force = [0.0, -1e4]", "force = [0.0, -1.0]");
    let scene = write_scene(dir.path(), &text);
    let (_, summary) = run_ok(dir.path(), &scene, "bridge");
    let found = warnings(&summary);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_has(&found[0].1, &["did you mean 2000e6 (a modulus in MPa"]);
    // The same bridge with large kinematics: the same strains, meant, so no warning.
    let world = linkage::scene::build_world(
        &text.replace("rectangle = {", "kinematics = \"large\"\nrectangle = {"),
        &dir.path().join("large.toml"),
    )
    .unwrap();
    let mut sim = linkage::scene::Simulation::new(&world).unwrap();
    sim.step(0).unwrap();
    let (_, line) = sim.step(1).unwrap();
    assert!(
        line.warnings.iter().all(|w| !w.contains("strained")),
        "{:?}",
        line.warnings
    );
}

/// `nearest = [12, 300]` (meant `[12, 3]`) on the 24 m bridge picks node 14 at (12, 3),
/// 297 m away: `linkage check` warns with the scene line of `nearest`, the point, the node
/// and the distance (297.0000 m); the run puts the same warning in step 0's warnings.
/// `[12, 3]` itself does not warn.
#[test]
fn a_nearest_point_of_12_300_on_the_bridge_warns_with_the_node_and_distance() {
    let dir = tempfile::tempdir().unwrap();
    let text = bridge("200e9", "nearest = [12.0, 300.0]");
    let scene = write_scene(dir.path(), &text);
    let line = text.lines().position(|l| l.starts_with("nearest")).unwrap() + 1;
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(check.status.success(), "{}", out(&check));
    let stdout = String::from_utf8_lossy(&check.stdout).into_owned();
    let w = stdout
        .lines()
        .find_map(|l| l.strip_prefix(&format!("warn  {}: ", scene.display())))
        .unwrap_or_else(|| panic!("no warning: {stdout}"))
        .to_string();
    assert_has(
        &w,
        &[
            &format!("scene.toml:{line}: body 'bridge': load: "),
            "`nearest` = [12.0, 300.0] picks node 14 at [12.0, 3.0] m, 297.0000 m away",
            "a tenth of the body's size",
        ],
    );
    let (_, summary) = run_ok(dir.path(), &scene, "bridge");
    assert_eq!(warnings(&summary), [(0, w)]);
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &bridge("200e9", "nearest = [12.0, 3.0]"));
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(
        !String::from_utf8_lossy(&check.stdout).contains("warn"),
        "{}",
        out(&check)
    );
}

/// A load on a selector partly on held directions: 900 N down shared (`total_force`) by the
/// left edge of a 2 × 2 plate (nodes 1, 4, 7), whose node 1 is pinned. Before, accepted in
/// silence; now `linkage check` says node 1 loses its 300 N (in y) to the reaction and the
/// free nodes 4 and 7 carry 600 N of the 900 N. The step's reactions agree: node 1 answers
/// the 300 N put on it plus its share of holding the plate (the solve's own balance, to 1e-9).
#[test]
fn a_load_on_a_line_through_a_pinned_node_says_which_node_loses_it() {
    let dir = tempfile::tempdir().unwrap();
    let text = r#"name = "plate"
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "plate"
rectangle = { width = 2.0, height = 2.0, cells = [2, 2] }
[[bodies.supports]]
nodes = [1]
fix = ["x", "y"]
[[bodies.supports]]
nodes = [3]
fix = ["y"]
[[bodies.loads]]
on_line = { point = [0.0, 0.0], direction = [0.0, 1.0] }
total_force = [0.0, -900.0]
"#;
    let scene = write_scene(dir.path(), text);
    let check = linkage().arg("check").arg(&scene).output().unwrap();
    assert!(check.status.success(), "{}", out(&check));
    let stdout = String::from_utf8_lossy(&check.stdout).into_owned();
    let w = stdout
        .lines()
        .find_map(|l| l.strip_prefix(&format!("warn  {}: ", scene.display())))
        .unwrap_or_else(|| panic!("no warning: {stdout}"))
        .to_string();
    assert_has(
        &w,
        &[
            "body 'plate': load: ",
            "`total_force` puts [0.0, -300.0] N on each of 3 nodes",
            "1 of them (node 1)",
            "[0.0, -300.0] N of the [0.0, -900.0] N in all goes straight into the reactions",
            "the free nodes carry [0.0, -600.0] N",
        ],
    );
    let (_, summary) = run_ok(dir.path(), &scene, "plate");
    assert_eq!(warnings(&summary), [(0, w)]);
    // Statics of what is left: the free 600 N at x = 0 are answered by node 1 (pinned, at
    // x = 0) and node 3 (x = 2): moments about node 1 give node 3 nothing; node 1 answers
    // 600 N of them plus the 300 N put on it: 900 N up in all.
    let result = read_json(&dir.path().join("out/plate/steps/0001.json"));
    let reactions = result["bodies"][0]["reactions"].as_array().unwrap();
    let at = |node: u64| {
        reactions
            .iter()
            .find(|r| r["node"].as_u64() == Some(node))
            .map(|r| r["force"][1].as_f64().unwrap())
            .unwrap()
    };
    assert!((at(1) - 900.0).abs() <= 1e-9 * 900.0, "{reactions:?}");
    assert!(at(3).abs() <= 1e-9 * 900.0, "{reactions:?}");
}

/// A 2D plate 2 m × 0.5 m of 8 × 2 cells (top nodes 0.25 m apart), its bottom held, pressed
/// from above by `obstacle` lowered by `travel` (m, in y).
fn pressed_plate(obstacle: &str) -> String {
    format!(
        r#"name = "pressed"
steps = 2
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "plate"
rectangle = {{ width = 2.0, height = 0.5, cells = [8, 2] }}
[[bodies.supports]]
on_line = {{ point = [0.0, 0.0], direction = [1.0, 0.0] }}
fix = ["x", "y"]
[[obstacles]]
name = "press"
{obstacle}
"#
    )
}

/// A ball obstacle (radius 5 m) pressing the plate: at the 0.25 m spacing its surface is
/// 0.25²/(2·5) = 6.25 mm above the next top nodes when it touches the middle one, and it goes
/// 4 mm in, so the middle top node (23, at x = 1) carries the whole force: warned at the last
/// step (the full load), naming node 23, the share (100 %) and the pair's force, equal to the
/// step file's contact force (to the 4 digits printed). A flat press (a half-space) shares
/// the force over the top nodes: no warning.
#[test]
fn a_ball_pressing_a_mesh_body_through_one_node_warns_that_the_result_depends_on_the_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        &pressed_plate(
            "shape = \"ball\"\ncenter = [1.0, 5.501]\nradius = 5.0\ntravel = [0.0, -0.005]",
        ),
    );
    let (_, summary) = run_ok(dir.path(), &scene, "pressed");
    let found = warnings(&summary);
    assert_eq!(found.len(), 1, "{found:?}");
    let (step, w) = &found[0];
    assert_eq!(*step, 2);
    let result = read_json(&dir.path().join("out/pressed/steps/0002.json"));
    let contacts = result["bodies"][0]["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), 1, "{contacts:?}");
    assert_eq!(contacts[0]["node"], 23);
    let force = contacts[0]["normal_force"].as_f64().unwrap();
    assert!(force > 0.0);
    assert_has(
        w,
        &[
            "step 2: body 'plate': node 23 carries 100 % of the contact force with 'press'",
            &format!("({force:.4e} of {force:.4e} N)"),
            "depends on the mesh; refine",
        ],
    );
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(
        dir.path(),
        &pressed_plate(
            "shape = \"half_space\"\npoint = [0.0, 0.501]\nnormal = [0.0, -1.0]\ntravel = [0.0, -0.002]",
        ),
    );
    let (_, summary) = run_ok(dir.path(), &scene, "pressed");
    assert_eq!(warnings(&summary), []);
    let result = read_json(&dir.path().join("out/pressed/steps/0002.json"));
    let touching = result["bodies"][0]["contacts"].as_array().unwrap().len();
    assert!(touching >= 3, "{touching}");
}

/// A column four cells across (nodes 0.1 m apart, 1 m tall) pressed on its top by a
/// half-space: its five top nodes share the force (none carries most of it); and the bundled
/// disk on the floor, whose contact spreads over several nodes by the last step (one node
/// touches first), does not warn of its contact either.
#[test]
fn a_contact_shared_by_several_nodes_and_the_disk_on_the_floor_do_not_warn() {
    let dir = tempfile::tempdir().unwrap();
    let text = pressed_plate(
        "shape = \"half_space\"\npoint = [0.0, 1.001]\nnormal = [0.0, -1.0]\ntravel = [0.0, -0.002]",
    )
    .replace(
        "rectangle = { width = 2.0, height = 0.5, cells = [8, 2] }",
        "rectangle = { width = 0.4, height = 1.0, cells = [4, 4] }",
    );
    let scene = write_scene(dir.path(), &text);
    let (_, summary) = run_ok(dir.path(), &scene, "pressed");
    assert_eq!(warnings(&summary), []);
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/disk_on_floor.toml");
    let (_, summary) = run_ok(dir.path(), &here, "disk_on_floor");
    // Its one warning is of its strains (a linear rubber disk squeezed 2 cm), not its contact.
    let found = warnings(&summary);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_has(&found[0].1, &["body 'disk': member", "is strained"]);
}

/// A closed unit cube as OBJ text with its top face (`f 5 6 7 8`) left out: open along the
/// top edges.
const OPEN_CUBE_OBJ: &str = "\
v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

/// The open-mesh message of a body prepared from an open mesh said "a mesh obstacle must be
/// closed": it now names the body and says a body's mesh must be closed; the same mesh as an
/// obstacle still says an obstacle's must.
#[test]
fn an_open_mesh_body_is_told_its_mesh_must_be_closed_not_an_obstacles() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("open.obj"), OPEN_CUBE_OBJ).unwrap();
    let body = r#"name = "t"
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "cube"
mesh = { file = "open.obj", spacing = 0.3 }
"#;
    let scene = write_scene(dir.path(), body);
    let msg = linkage::scene::load_scene(&scene).unwrap_err().to_string();
    assert_has(
        &msg,
        &[
            "body 'cube'",
            "open.obj",
            "the mesh is open there",
            "the mesh of a body must be closed",
        ],
    );
    assert!(!msg.contains("obstacle"), "{msg}");
    let obstacle = format!(
        "{}[[bodies.supports]]\nnodes = [1]\nfix = [\"x\", \"y\", \"z\"]\n[[obstacles]]\nname = \"lid\"\nshape = \"mesh\"\nfile = \"open.obj\"\n",
        body.replace(
            "mesh = { file = \"open.obj\", spacing = 0.3 }",
            "box_lattice = { size = [0.2, 0.2, 0.2], cells = [1, 1, 1] }\noffset = [0.0, 2.0, 0.0]"
        )
    );
    let scene = write_scene(dir.path(), &obstacle);
    let msg = linkage::scene::load_scene(&scene).unwrap_err().to_string();
    assert_has(
        &msg,
        &[
            "obstacle 'lid'",
            "the mesh is open there",
            "a mesh obstacle is a solid",
        ],
    );
    assert!(!msg.contains("body"), "{msg}");
}

/// A 24 m × 3 m rectangle of four nodes.
fn four_node_bridge() -> linkage::linkage::Body {
    use linkage::linkage::{Body, Dimension};
    let mut body = Body::new("bridge", Dimension::Two);
    body.nodes = [[0.0, 0.0], [24.0, 0.0], [24.0, 3.0], [0.0, 3.0]]
        .iter()
        .map(|p| nalgebra::Vector3::new(p[0], p[1], 0.0))
        .collect();
    body
}

fn nearest(p: [f64; 2]) -> linkage::scene::spec::SelectorSpec {
    linkage::scene::spec::SelectorSpec {
        nodes: None,
        nearest: Some(p.to_vec()),
        inside: None,
        on_line: None,
        on_plane: None,
        tolerance: None,
        group: None,
    }
}

/// The bound of the far-`nearest` warning: `[23, 3]`, 1 m from node 3, is within a tenth of
/// the diagonal √(24² + 3²) = 24.19 m: not warned; a point 0.1 % inside 2.419 m from node 3
/// is not warned, one 0.1 % beyond it is.
#[test]
fn a_nearest_point_within_a_tenth_of_the_body_does_not_warn() {
    use linkage::scene::{far_nearest_warning, select_nodes, FAR_NEAREST};
    let body = four_node_bridge();
    let near = nearest([23.0, 3.0]);
    let picked = select_nodes(&near, &body).unwrap();
    assert_eq!(picked, [2]);
    assert_eq!(far_nearest_warning(&near, &body, &picked), None);
    let bound = FAR_NEAREST * body.size();
    assert!((bound - 0.1 * (24.0f64 * 24.0 + 9.0).sqrt()).abs() < 1e-12);
    for (dy, warns) in [(0.999 * bound, false), (1.001 * bound, true)] {
        let s = nearest([24.0, 3.0 + dy]);
        let p = select_nodes(&s, &body).unwrap();
        assert_eq!(p, [2]);
        assert_eq!(far_nearest_warning(&s, &body, &p).is_some(), warns, "{dy}");
    }
}
