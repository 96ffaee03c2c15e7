//! `[output] format = "npz"`: the same results as JSON, to the last bit, read back by our readers
//! and by NumPy; `linkage render` draws the same frames from either. The JSON compared with a
//! run's `.npz` is made from the same results in memory, as the JSON writer makes it: two runs
//! of a scene may differ in the last bits when threads share the solver's sums differently.
//!
//! The NumPy test uses the venv of tests/vtk.rs (`target/meshio-venv`: meshio brings numpy),
//! made when missing; without python3 or PyPI it is skipped with a message.

mod common;

use linkage::scene::{
    build_world, load_scene, run_with, DrawResults, ResultFormat, RunResults, World,
};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// Keeps the run's results as they were in memory when its files were written.
#[derive(Default)]
struct Capture(Mutex<Option<RunResults>>);

impl DrawResults for Capture {
    fn draw(
        &self,
        _: &World,
        run: &RunResults,
        _: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        *self.0.lock().unwrap() = Some(run.clone());
        Ok(())
    }
}

/// `scene` loaded and run as `format` into `out/<format>/<name>`; the results in memory.
fn run_as(scene: &str, format: ResultFormat, out: &Path) -> (World, PathBuf, RunResults) {
    let mut world = load_scene(Path::new(scene)).unwrap();
    world.output.format = format;
    // Pictures asked for, so the results in memory reach the capture (which draws nothing).
    world.pictures.png = true;
    let out = out.join(format.extension());
    let capture = Capture::default();
    run_with(&world, &out, &|| {}, Some(&capture)).unwrap();
    let dir = out.join(&world.name);
    let run = capture.0.into_inner().unwrap().unwrap();
    (world, dir, run)
}

/// An `.npz` run of `scene` and the JSON folder of the same results (the solver's last bits
/// may differ between two runs when threads share the work differently): `model.json` and
/// `steps/NNNN.json` serialized as the JSON writer does (`serde_json::to_vec`), `summary.json`
/// copied.
fn npz_run_and_its_json(scene: &str, out: &Path) -> (World, PathBuf, PathBuf) {
    let (world, npz, run) = run_as(scene, ResultFormat::Npz, out);
    let json = out.join("twin").join(&world.name);
    std::fs::create_dir_all(json.join("steps")).unwrap();
    std::fs::copy(npz.join("summary.json"), json.join("summary.json")).unwrap();
    let write = |f: &str, bytes: Vec<u8>| std::fs::write(json.join(f), bytes).unwrap();
    write("model.json", serde_json::to_vec(&run.model).unwrap());
    for step in &run.steps {
        write(
            &format!("steps/{}.json", run.stem(step.step)),
            serde_json::to_vec(step).unwrap(),
        );
    }
    (world, npz, json)
}

fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    names
}

/// Every number of a run, floats in full (Debug prints the shortest string that reads back to
/// the same bits, and -0.0 as such).
fn bits(run: &RunResults) -> String {
    format!("{:?}", run)
}

const SCENES: [&str; 3] = [
    "scenes/paper_overload.toml", // 2D, overloaded members, reactions, loads
    "scenes/shell_on_block.toml", // 3D, patches, an obstacle, contacts
    "scenes/two_disks.toml",      // two bodies pressing on each other
];

#[test]
fn both_formats_read_back_equal_to_the_results_in_memory_bit_for_bit() {
    let out = tempfile::tempdir().unwrap();
    for scene in SCENES {
        for format in [ResultFormat::Json, ResultFormat::Npz] {
            let (world, dir, in_memory) = run_as(scene, format, out.path());
            let ext = format.extension();
            let mut files = listing(&dir);
            files.retain(|f| f != "png" && f != "anim.gif");
            assert_eq!(
                files,
                [
                    format.model_file(),
                    "plot_settings.json",
                    "steps",
                    "summary.json"
                ]
            );
            let steps = listing(&dir.join("steps"));
            assert_eq!(steps.len(), world.steps + 1);
            assert!(steps.iter().all(|s| s.ends_with(ext)), "{steps:?}");
            let read = RunResults::read(&dir).unwrap();
            let (a, b) = (bits(&read), bits(&in_memory));
            let first = a.split(", ").zip(b.split(", ")).find(|(x, y)| x != y);
            assert!(a == b, "{scene} as {ext}: read {first:?} in memory");
            if scene.contains("block") || scene.contains("disks") {
                let contacts: usize = read
                    .steps
                    .iter()
                    .flat_map(|s| &s.bodies)
                    .map(|b| b.contacts.len())
                    .sum();
                assert!(contacts > 0, "{scene} has contacts to compare");
            }
        }
    }
}

/// Compares every field of a step's `.npz` with its `.json`, bit for bit (floats as their
/// int64 bit patterns, so -0.0 and 0.0 differ), shapes and dtypes included; prints the number
/// of values compared.
const COMPARE: &str = r#"
import json, sys
import numpy as np
npz, js = sys.argv[1], sys.argv[2]
s = np.load(npz)
j = json.load(open(js))
count = 0
def same(key, want, dtype, shape=None):
    global count
    got = s[key]
    want = np.asarray(want, dtype=dtype)
    if shape is not None:
        want = want.reshape(shape)
    assert got.dtype == want.dtype, (key, got.dtype, want.dtype)
    assert got.shape == want.shape, (key, got.shape, want.shape)
    if dtype == np.float64:
        assert np.array_equal(got.view(np.int64), want.view(np.int64)), key
    else:
        assert np.array_equal(got, want), key
    count += got.size
same("step", j["step"], np.int64)
same("load_factor", j["load_factor"], np.float64)
assert list(s["bodies"]) == [b["name"] for b in j["bodies"]]
for k, b in enumerate(j["bodies"], start=1):
    p = f"body{k}_"
    d = s[p + "displacements"].shape[1]
    for f in ["displacements", "positions"]:
        same(p + f, b[f], np.float64, (-1, d))
    for f in ["axial_forces", "strains", "stresses"]:
        same(p + f, b[f], np.float64)
    same(p + "overloaded", b["overloaded"], np.int64)
    for f in ["reactions", "loads"]:
        same(p + f + "_node", [r["node"] for r in b[f]], np.int64)
        same(p + f + "_force", [r["force"] for r in b[f]], np.float64, (-1, d))
    c = b["contacts"]
    same(p + "contacts_node", [x["node"] for x in c], np.int64)
    assert list(s[p + "contacts_with"]) == [x["with"] for x in c]
    same(p + "contacts_depth", [x["depth"] for x in c], np.float64)
    same(p + "contacts_force", [x["force"] for x in c], np.float64, (-1, d))
    # Every field of the JSON body is in the archive.
    for f in b:
        assert f == "name" or any(n.startswith(p + f) for n in s.files), f
print(count)
"#;

#[test]
fn numpy_reads_the_npz_steps_equal_to_the_json_steps_to_the_last_bit() {
    let python = match common::python_with_meshio() {
        Ok(p) => p,
        Err(why) => {
            eprintln!("skipped: no Python with numpy ({why})");
            return;
        }
    };
    let out = tempfile::tempdir().unwrap();
    for scene in SCENES {
        let (world, npz, json) = npz_run_and_its_json(scene, out.path());
        for k in 0..=world.steps {
            let name = |ext: &str| format!("steps/{k:04}.{ext}");
            let o = Command::new(&python)
                .args(["-c", COMPARE])
                .arg(npz.join(name("npz")))
                .arg(json.join(name("json")))
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "{scene} step {k}: {}",
                String::from_utf8_lossy(&o.stderr)
            );
            let count: usize = String::from_utf8_lossy(&o.stdout).trim().parse().unwrap();
            assert!(count > 0);
        }
    }
}

#[test]
fn render_draws_the_same_frames_from_npz_as_from_json() {
    let out = tempfile::tempdir().unwrap();
    for scene in ["scenes/paper_overload.toml", "scenes/shell_on_block.toml"] {
        let mut frames = Vec::new();
        let (_, npz, json) = npz_run_and_its_json(scene, out.path());
        for dir in [json, npz] {
            let o = Command::new(env!("CARGO_BIN_EXE_linkage"))
                .arg("render")
                .arg(&dir)
                .args(["--width", "240", "--height", "160", "--vtk"])
                .output()
                .unwrap();
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
            let pngs: Vec<Vec<u8>> = listing(&dir.join("png"))
                .iter()
                .map(|f| read(&format!("png/{f}")))
                .collect();
            assert!(!pngs.is_empty());
            frames.push((pngs, read("anim.gif"), read("vtk/0001.vtu")));
        }
        assert!(frames[0] == frames[1], "{scene}: frames differ");
    }
}

#[test]
fn a_folder_with_both_models_or_a_torn_step_is_a_clear_error() {
    let out = tempfile::tempdir().unwrap();
    let (_, npz, json) = npz_run_and_its_json("scenes/paper_square.toml", out.path());

    // A step file cut short: the file and the array are named.
    let step = npz.join("steps/0001.npz");
    let bytes = std::fs::read(&step).unwrap();
    std::fs::write(&step, &bytes[..bytes.len() / 2]).unwrap();
    let e = RunResults::read(&npz).unwrap_err().to_string();
    assert!(e.contains("0001.npz") && e.contains("linkage run"), "{e}");
    // An array of the wrong length: named.
    let mut edited = bytes.clone();
    let find = |from: usize, what: &[u8]| {
        from + edited[from..]
            .windows(what.len())
            .position(|w| w == what)
            .unwrap()
    };
    let entry = find(0, b"body1_positions.npy");
    let at = find(entry, b"'shape': (") + b"'shape': (".len();
    edited[at] = if edited[at] == b'9' { b'8' } else { b'9' };
    std::fs::write(&step, &edited).unwrap();
    let e = RunResults::read(&npz).unwrap_err().to_string();
    assert!(e.contains("0001.npz") && e.contains("array 'body1_"), "{e}");

    // Both model files, or a step of the other format.
    std::fs::copy(json.join("model.json"), npz.join("model.json")).unwrap();
    let e = RunResults::read(&npz).unwrap_err().to_string();
    assert!(e.contains("model.json") && e.contains("model.npz"), "{e}");
    std::fs::remove_file(npz.join("model.json")).unwrap();
    std::fs::write(&step, &bytes).unwrap();
    std::fs::copy(json.join("steps/0000.json"), npz.join("steps/0000.json")).unwrap();
    let e = RunResults::read(&npz).unwrap_err().to_string();
    assert!(e.contains("0000.json") && e.contains("NNNN.npz"), "{e}");
    std::fs::remove_file(npz.join("steps/0000.json")).unwrap();
    std::fs::remove_file(npz.join("model.npz")).unwrap();
    let e = RunResults::read(&npz).unwrap_err().to_string();
    assert!(e.contains("neither model.json nor model.npz"), "{e}");
}

#[test]
fn the_format_key_is_checked_and_large_models_default_to_npz() {
    let scene = |output: &str, cells: usize| {
        format!(
            r#"
name = "lattice"
steps = 1
[[materials]]
name = "steel"
youngs_modulus = 200e9
area = 1e-4
[[bodies]]
name = "block"
box_lattice = {{ size = [1.0, 1.0, 1.0], cells = [{cells}, {cells}, {cells}] }}
material = "steel"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}
fix = ["x", "y", "z"]
{output}
"#
        )
    };
    let path = Path::new("scene.toml");
    let e = build_world(&scene("[output]\nformat = \"csv\"", 2), path)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("[output] format = \"csv\"") && e.contains("\"npz\""),
        "{e}"
    );
    let small = build_world(&scene("", 2), path).unwrap();
    assert_eq!(small.output.format, ResultFormat::Json);
    // 22³ cells: well over 100,000 members.
    let large = build_world(&scene("", 22), path).unwrap();
    let members: usize = large.bodies.iter().map(|b| b.members.len()).sum();
    assert!(members > 100_000, "{members}");
    assert_eq!(large.output.format, ResultFormat::Npz);
    let asked = build_world(&scene("[output]\nformat = \"json\"", 22), path).unwrap();
    assert_eq!(asked.output.format, ResultFormat::Json);
}
