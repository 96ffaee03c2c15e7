//! Scenes the test binaries share.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The bundled von Mises truss under load control, named `name`, with `force` N down at its
/// apex, in `dir/file`: 7622 N is its limit load, so 5000 N solves its 4 steps and 9000 N
/// fails at step 4 (at most 3 halvings of an increment).
#[allow(dead_code)] // not every test binary runs the truss
pub fn truss_scene(dir: &Path, file: &str, name: &str, force: f64) -> PathBuf {
    let here = std::env::current_dir().unwrap().join("scenes");
    let scene = dir.join(file);
    std::fs::write(
        &scene,
        format!(
            r#"name = "{name}"
steps = 4
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "truss"
nodes = "{}"
links = "{}"
kinematics = "large"
[bodies.newton]
max_cuts = 3
[[bodies.supports]]
nodes = [1, 3]
fix = ["x", "y"]
[[bodies.loads]]
nodes = [2]
force = [0.0, {}]
"#,
            here.join("von_mises.nodes").display(),
            here.join("von_mises.links").display(),
            -force
        ),
    )
    .unwrap();
    scene
}

/// A Python with meshio (and so numpy): `target/meshio-venv`, created and filled when missing
/// (`.ci/run` installs it first); the error says why it cannot be made here.
#[allow(dead_code)] // not every test binary reads with Python
pub fn python_with_meshio() -> Result<PathBuf, String> {
    python_with("meshio-venv", "meshio, numpy", "meshio")
}

/// A Python with openseespy (OpenSees in its wheel): `target/opensees-venv`, created and filled
/// when missing (`.ci/run` installs it first); the error says why it cannot be made here.
#[allow(dead_code)] // not every test binary runs OpenSees
pub fn python_with_openseespy() -> Result<PathBuf, String> {
    python_with("opensees-venv", "openseespy.opensees", "openseespy")
}

/// The Python of the venv `target/<venv>` where `import <imports>` works, made with
/// `pip install <package>` from PyPI when missing.
#[allow(dead_code)]
fn python_with(venv: &str, imports: &str, package: &str) -> Result<PathBuf, String> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("target")
        .join(venv);
    let python = venv.join("bin/python");
    let has = |py: &Path| {
        Command::new(py)
            .args(["-c", &format!("import {imports}")])
            .output()
            .map(|o| o.status.success())
            .unwrap_or(false)
    };
    if has(&python) {
        return Ok(python);
    }
    let made = Command::new("python3")
        .args(["-m", "venv"])
        .arg(&venv)
        .output()
        .map_err(|e| format!("cannot run python3 ({e}): install python3 (3.9 or later)"))?;
    if !made.status.success() {
        return Err(format!(
            "cannot create a Python venv at {}: {}\n\
             install python3 with its venv module (Debian: apt-get install python3-venv)",
            venv.display(),
            String::from_utf8_lossy(&made.stderr)
        ));
    }
    let pip = Command::new(&python)
        .args(["-m", "pip", "install", "--quiet", package])
        .output()
        .map_err(|e| format!("cannot run the venv's python: {e}"))?;
    if pip.status.success() && has(&python) {
        Ok(python)
    } else {
        Err(format!(
            "cannot install {package} from PyPI into {} (or import {imports} from it): {}\n\
             check the network, or install it yourself: {} -m pip install {package}",
            venv.display(),
            String::from_utf8_lossy(&pip.stderr),
            python.display()
        ))
    }
}

/// The files under `root`, relative and sorted.
#[allow(dead_code)] // used by the batch tests
pub fn files_under(root: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap().flatten() {
            let path = entry.path();
            if path.is_dir() {
                walk(root, &path, out);
            } else {
                out.push(path.strip_prefix(root).unwrap().to_path_buf());
            }
        }
    }
    let mut out = Vec::new();
    walk(root, root, &mut out);
    out.sort();
    out
}

/// Assert that two results folders hold the same files, byte for byte, except the timing
/// fields of summary.json (`seconds` per step and `phases`), which differ between runs (as
/// `.ci/same_outputs.py` compares them).
#[allow(dead_code)] // used by the batch tests
pub fn assert_same_results(a: &Path, b: &Path) {
    fn strip(v: serde_json::Value) -> serde_json::Value {
        match v {
            serde_json::Value::Object(m) => m
                .into_iter()
                .filter(|(k, _)| k != "seconds" && k != "phases")
                .map(|(k, v)| (k, strip(v)))
                .collect(),
            serde_json::Value::Array(a) => a.into_iter().map(strip).collect(),
            v => v,
        }
    }
    let files = files_under(a);
    assert_eq!(files, files_under(b), "{} and {}", a.display(), b.display());
    assert!(!files.is_empty(), "{} is empty", a.display());
    for f in files {
        let (x, y) = (
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(b.join(&f)).unwrap(),
        );
        if f.file_name().is_some_and(|n| n == "summary.json") {
            let parse = |bytes: &[u8]| strip(serde_json::from_slice(bytes).unwrap());
            assert_eq!(parse(&x), parse(&y), "{}", f.display());
        } else {
            assert!(
                x == y,
                "{} differs between {} and {}",
                f.display(),
                a.display(),
                b.display()
            );
        }
    }
}

/// The rows of a `batch.csv` without its `seconds` column (wall times differ between runs).
#[allow(dead_code)] // used by the batch tests
pub fn table_without_seconds(path: &Path) -> Vec<linkage::scene::batch::Row> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut rows = linkage::scene::batch::parse_table(&text).unwrap();
    for r in &mut rows {
        r.seconds.clear();
    }
    rows
}

/// A 3D cube of one cell (E = 1e12 Pa) on a floor, pressed by 400 N and pushed along x by
/// `push` N on its nodes at height `at` (m; 0.1 is its top), half of it at step 1 of 2, all
/// its nodes held in z, μ = 0.5 (stick stiffness 1e6 N/m): `dir/pushed.toml`.
#[allow(dead_code)] // not every test binary pushes the cube
pub fn pushed_cube(dir: &Path, push: f64, at: f64) -> PathBuf {
    let path = dir.join("pushed.toml");
    std::fs::write(
        &path,
        format!(
            r#"name = "pushed"
steps = 2

[[materials]]
name = "stiff"
youngs_modulus = 1e12
area = 1e-2

[[bodies]]
name = "block"
box_lattice = {{ size = [0.1, 0.1, 0.1], cells = [1, 1, 1] }}
material = "stiff"

[[bodies.supports]]
inside = {{ min = [-1.0, -1.0, -1.0], max = [1.0, 1.0, 1.0] }}
fix = ["z"]

[[bodies.loads]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [0.0, -400.0, 0.0]
schedule = [1.0, 1.0]

[[bodies.loads]]
on_plane = {{ point = [0.0, {at:?}, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [{push:?}, 0.0, 0.0]
schedule = [0.5, 1.0]

[[obstacles]]
name = "floor"
shape = "half_space"
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]

[contact]
friction = 0.5
stick_stiffness = 1e6
"#
        ),
    )
    .unwrap();
    path
}
