//! Scenes the test binaries share.

use std::path::{Path, PathBuf};

/// The bundled von Mises truss under load control, named `name`, with `force` N down at its
/// apex, in `dir/file`: 7622 N is its limit load, so 5000 N solves its 4 steps and 9000 N
/// fails at step 4 (at most 3 halvings of an increment).
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
