//! `anim.glb`, the glTF 2.0 animation of a run: the Khronos validator (npm `gltf-validator`,
//! installed under `target/npm` when missing; `.ci/run` installs it first) reports no errors
//! on the file of a 3D contact scene with a moving obstacle (`[output] gltf = true`), a 2D
//! contact scene and a fracture scene (`linkage render DIR --gltf`); each body has one morph
//! target and the animation one keyframe per stored step; the last target's deltas are the
//! last step's displacements. Under `CI=true` a missing validator fails; elsewhere the
//! validator's part is skipped with the reason.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn required() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

fn linkage() -> Command {
    Command::new(env!("CARGO_BIN_EXE_linkage"))
}

/// The folder holding `node_modules/gltf-validator`, installed there when missing.
fn validator() -> Result<PathBuf, String> {
    let prefix = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/npm");
    if prefix
        .join("node_modules/gltf-validator/package.json")
        .is_file()
    {
        return Ok(prefix);
    }
    let o = Command::new("npm")
        .args(["install", "--no-audit", "--no-fund", "--prefix"])
        .arg(&prefix)
        .arg("gltf-validator")
        .output()
        .map_err(|e| format!("cannot run npm ({e}): install Node.js and npm"))?;
    if o.status.success() && prefix.join("node_modules/gltf-validator").is_dir() {
        Ok(prefix)
    } else {
        Err(format!(
            "npm could not install gltf-validator into {}: {}",
            prefix.display(),
            String::from_utf8_lossy(&o.stderr)
        ))
    }
}

/// The validator's report of `glb`: (errors, warnings, the messages of the errors).
fn validate(prefix: &Path, glb: &Path) -> (u64, u64, String) {
    let script = "const v = require('gltf-validator'); const fs = require('fs');\
        v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[1])), {maxIssues: 50})\
        .then(r => console.log(JSON.stringify(r.issues)))\
        .catch(e => { console.error(e); process.exit(2); });";
    let o = Command::new("node")
        .arg("-e")
        .arg(script)
        .arg(glb)
        .env("NODE_PATH", prefix.join("node_modules"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let issues: Value = serde_json::from_slice(&o.stdout).unwrap();
    let errors: Vec<&Value> = issues["messages"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["severity"] == 0)
        .collect();
    (
        issues["numErrors"].as_u64().unwrap(),
        issues["numWarnings"].as_u64().unwrap(),
        format!("{errors:?}"),
    )
}

/// The JSON chunk of a GLB file, after checking its header.
fn glb_json(bytes: &[u8]) -> Value {
    let word =
        |at: usize| u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8) as usize, bytes.len());
    assert_eq!(&bytes[16..20], b"JSON");
    let n = word(12) as usize;
    serde_json::from_slice(&bytes[20..20 + n]).unwrap()
}

/// Run `scene` (its text with `extra` appended) into `out`; the results folder.
fn run(out: &Path, scene: &str, extra: &str) -> PathBuf {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let text = std::fs::read_to_string(scenes.join(format!("{scene}.toml"))).unwrap();
    // The scene's files beside it, so its relative names resolve.
    for e in std::fs::read_dir(&scenes).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with(scene) && !name.ends_with(".toml") {
            std::fs::copy(e.path(), out.join(&name)).unwrap();
        }
    }
    let path = out.join(format!("{scene}.toml"));
    std::fs::write(&path, format!("{text}\n{extra}")).unwrap();
    let o = linkage()
        .arg("run")
        .arg(&path)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    out.join(scene)
}

/// The stored steps of the results folder `dir`.
fn stored_steps(dir: &Path) -> Vec<Value> {
    let mut names: Vec<PathBuf> = std::fs::read_dir(dir.join("steps"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    names.sort();
    names
        .iter()
        .map(|p| serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap())
        .collect()
}

/// Check the GLB of results folder `dir`; returns its JSON.
fn check(dir: &Path, validator: &Result<PathBuf, String>) -> Value {
    let glb = dir.join("anim.glb");
    let bytes = std::fs::read(&glb).unwrap();
    let doc = glb_json(&bytes);
    let steps = stored_steps(dir);
    let n = steps.len();
    assert!(n >= 3, "{}: {n} steps", dir.display());
    let accessors = doc["accessors"].as_array().unwrap();
    let count = |a: &Value| {
        accessors[a.as_u64().unwrap() as usize]["count"]
            .as_u64()
            .unwrap()
    };
    for mesh in doc["meshes"].as_array().unwrap() {
        if let Some(targets) = mesh["primitives"][0]["targets"].as_array() {
            assert_eq!(targets.len(), n, "one morph target per stored step");
            assert_eq!(mesh["weights"].as_array().unwrap().len(), n);
        }
    }
    let animation = &doc["animations"][0];
    for s in animation["samplers"].as_array().unwrap() {
        assert_eq!(
            count(&s["input"]) as usize,
            n,
            "one keyframe per stored step"
        );
        assert_eq!(s["interpolation"], "STEP");
    }
    for c in animation["channels"].as_array().unwrap() {
        let s = &animation["samplers"][c["sampler"].as_u64().unwrap() as usize];
        if c["target"]["path"] == "weights" {
            assert_eq!(count(&s["output"]) as usize, n * n, "weights: frames²");
        }
    }
    // The first body's last morph target moves its vertices by the last step's displacements
    // times the magnification the frames used (the asset's extras say which: contact scenes
    // take the largest that crosses nothing): its POSITION bounds are theirs, within the
    // rounding of two float32 positions (4 ε times the largest coordinate).
    let magnification = doc["asset"]["extras"]["magnification"].as_f64().unwrap();
    assert!(magnification >= 1.0, "magnification {magnification}");
    let mesh = &doc["meshes"][0];
    let target = &mesh["primitives"][0]["targets"][n - 1]["POSITION"];
    let a = &accessors[target.as_u64().unwrap() as usize];
    let last = &steps[n - 1]["bodies"][0]["displacements"];
    let d = last[0].as_array().unwrap().len();
    for k in 0..d {
        let values: Vec<f64> = last
            .as_array()
            .unwrap()
            .iter()
            .map(|u| u[k].as_f64().unwrap())
            .collect();
        let hi = magnification * values.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let lo = magnification * values.iter().cloned().fold(f64::INFINITY, f64::min);
        let size = steps[n - 1]["bodies"][0]["positions"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|p| {
                p.as_array()
                    .unwrap()
                    .iter()
                    .map(|x| x.as_f64().unwrap().abs())
            })
            .fold(0.0, f64::max);
        let tol = 4.0 * f64::from(f32::EPSILON) * (size + hi.abs().max(lo.abs()));
        let (amax, amin) = (a["max"][k].as_f64().unwrap(), a["min"][k].as_f64().unwrap());
        assert!(
            (amax - hi).abs() <= tol && (amin - lo).abs() <= tol,
            "{}: component {k}: target [{amin}, {amax}], displacements [{lo}, {hi}]",
            dir.display()
        );
    }
    match validator {
        Ok(prefix) => {
            let (errors, warnings, messages) = validate(prefix, &glb);
            assert_eq!(errors, 0, "{}: {messages}", glb.display());
            eprintln!("{}: no errors, {warnings} warnings", glb.display());
        }
        Err(why) => {
            assert!(!required(), "CI=true: {why}");
            eprintln!("validator skipped: {why}");
        }
    }
    doc
}

#[test]
fn the_glb_of_a_3d_contact_a_2d_and_a_fracture_scene_validates_with_a_target_per_step() {
    let out = tempfile::tempdir().unwrap();
    let validator = validator();
    // A 3D shell pressed by a rising block, the key in the scene.
    let shell = run(
        out.path(),
        "shell_on_block_moving",
        "[output]\ngltf = true\n",
    );
    let doc = check(&shell, &validator);
    // The block is a node moved by translation, keyed at every step.
    let nodes = doc["nodes"].as_array().unwrap();
    let block = nodes.iter().position(|n| n["name"] == "block").unwrap();
    let moves = doc["animations"][0]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .any(|c| c["target"]["node"] == block && c["target"]["path"] == "translation");
    assert!(moves, "the block's translation is animated");
    assert_eq!(doc["meshes"][0]["primitives"][0]["mode"], 4, "a surface");
    // A 2D disk on a floor and the notched beam that breaks, drawn again by `render --gltf`.
    for scene in ["disk_on_floor", "notched_beam"] {
        let dir = run(out.path(), scene, "");
        assert!(!dir.join("anim.glb").exists());
        let o = linkage()
            .arg("render")
            .arg(&dir)
            .args(["--gltf", "--no-png", "--no-gif"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{o:?}");
        let said = String::from_utf8_lossy(&o.stdout);
        assert!(said.contains("anim.glb"), "{said}");
        let doc = check(&dir, &validator);
        assert_eq!(doc["meshes"][0]["primitives"][0]["mode"], 1, "2D: lines");
    }
}

/// `q` (`[x, y, z, w]`) applied to `v`: v + 2w (q × v) + 2 q × (q × v).
fn turn(q: &Value, v: [f64; 3]) -> [f64; 3] {
    let q: Vec<f64> = q
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let axis = [q[0], q[1], q[2]];
    let t = cross(axis, v).map(|c| 2.0 * c);
    let u = cross(axis, t);
    [0, 1, 2].map(|i| v[i] + q[3] * t[i] + u[i])
}

#[test]
fn a_z_up_scene_stands_upright_in_the_glb() {
    let out = tempfile::tempdir().unwrap();
    let dir = run(out.path(), "wedge_split", "");
    let o = linkage()
        .arg("render")
        .arg(&dir)
        .args(["--gltf", "--no-png", "--no-gif"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{o:?}");
    let doc = glb_json(&std::fs::read(dir.join("anim.glb")).unwrap());
    let nodes = doc["nodes"].as_array().unwrap();
    // One root over every other node, turned so that the scene's up (+z) is glTF's +y.
    let scene_nodes = doc["scenes"][0]["nodes"].as_array().unwrap();
    assert_eq!(scene_nodes.len(), 1);
    let root = &nodes[scene_nodes[0].as_u64().unwrap() as usize];
    assert_eq!(root["children"].as_array().unwrap().len(), nodes.len() - 1);
    let up = turn(&root["rotation"], [0.0, 0.0, 1.0]);
    assert!(
        up[0].abs() < 1e-6 && (up[1] - 1.0).abs() < 1e-6 && up[2].abs() < 1e-6,
        "+z turns to {up:?}"
    );
    // A rotation: lengths kept, +x stays +x.
    let x = turn(&root["rotation"], [1.0, 0.0, 0.0]);
    assert!((x[0] - 1.0).abs() < 1e-6, "{x:?}");
}
