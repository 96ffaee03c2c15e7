//! Our Newmark against OpenSees on the same truss: a 2D lattice cantilever (10 × 1 cells,
//! both diagonals) with the lumped masses ρAL/2, suddenly loaded at its tip, large
//! displacements. OpenSees (openseespy, from a venv under `target/`, see
//! [`common::python_with_openseespy`]) runs `corotTruss` elements with the same nodal masses,
//! `integrator('Newmark', 0.5, 0.25)`, `algorithm('Newton')`, `test('NormDispIncr', 1e-12, 50)`.
//!
//! The two solve the same discrete equations: `corotTruss` has our large-kinematics member,
//! engineering strain `(l − L)/L`, force `E A (l − L)/L` along the current chord, constant
//! area (OpenSees's `CorotTruss::update` and `getResistingForce`). The load (tip deflection
//! about a quarter of the span, the chord shortening 2 % of it) is where the measure matters:
//! the same run with linear kinematics is off by far more than the tolerance.

mod common;

use linkage::linkage::dynamics::{lumped_mass, BodyMotion, Newmark, RayleighDamping};
use linkage::linkage::generators::rectangle;
use linkage::linkage::{
    Body, Dimension, Kinematics, Material, Member, NodalLoad, Schedule, Support,
};
use nalgebra::Vector3;
use serde_json::json;
use std::process::Command;
use std::time::Instant;

/// E = 1 GPa, A = 1 cm², ρ = 1000 kg/m³; the span 1 m, the depth 0.1 m.
const E: f64 = 1e9;
const AREA: f64 = 1e-4;
const RHO: f64 = 1000.0;

/// The cantilever of `cells` × 1 cells, held at its two left nodes, `force` N down at its
/// upper right node; its lumped mass per DOF (kg); the tip node.
fn cantilever(cells: usize, depth_cells: usize, kinematics: Kinematics) -> (Body, Vec<f64>, usize) {
    let g = rectangle(1.0, 0.1, cells, depth_cells).unwrap();
    let mut body = Body::new("cantilever", Dimension::Two);
    body.materials.push(Material::new("steel", E, AREA));
    body.nodes = g.nodes;
    body.members = g
        .members
        .into_iter()
        .map(|nodes| Member { nodes, material: 0 })
        .collect();
    for j in 0..=depth_cells {
        body.supports
            .push(Support::fixed(j * (cells + 1), [true, true, false]));
    }
    let tip = (cells + 1) * (depth_cells + 1) - 1;
    body.loads.push(NodalLoad {
        node: tip,
        force: Vector3::new(0.0, -200.0 * (depth_cells as f64), 0.0),
        schedule: Schedule::Factors(vec![1.0]),
    });
    body.kinematics = kinematics;
    body.newton.tolerance = 1e-13;
    let mass = lumped_mass(&body, &[Some(RHO)]).unwrap();
    (body, mass, tip)
}

/// Our Newmark ¼, ½ run: the tip's (ux, uy) after each of `steps` steps of `h` s, and the
/// wall time per step (s).
fn ours(body: &Body, mass: &[f64], tip: usize, h: f64, steps: usize) -> (Vec<[f64; 2]>, f64) {
    let duration = h * steps as f64;
    let start = Instant::now();
    let mut m = BodyMotion::new(
        body,
        mass.to_vec(),
        vec![0.0; body.dof_count()],
        RayleighDamping::default(),
    )
    .unwrap();
    m.balance_initial_acceleration(body, duration);
    let mut history = Vec::with_capacity(steps);
    for k in 0..steps {
        m.step(body, &Newmark::default(), k as f64 * h, h, duration)
            .unwrap_or_else(|e| panic!("step {}: {e:?}", k + 1));
        history.push([m.motion.u[2 * tip], m.motion.u[2 * tip + 1]]);
    }
    (history, start.elapsed().as_secs_f64() / steps as f64)
}

/// OpenSees's run of the same body (tests/opensees/newmark_truss.py): the tip's history and
/// its wall time per step (s).
fn opensees(body: &Body, mass: &[f64], tip: usize, h: f64, steps: usize) -> (Vec<[f64; 2]>, f64) {
    let python = common::python_with_openseespy().unwrap_or_else(|e| panic!("{e}"));
    let dir = tempfile::tempdir().unwrap();
    let model = json!({
        "nodes": body.nodes.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
        "members": body.members.iter().map(|m| m.nodes).collect::<Vec<_>>(),
        "E": E,
        "A": AREA,
        "mass": mass.iter().step_by(2).collect::<Vec<_>>(),
        "fixed": body.supports.iter().map(|s| s.node).collect::<Vec<_>>(),
        "loads": body.loads.iter().map(|l| json!([l.node, l.force.x, l.force.y])).collect::<Vec<_>>(),
        "h": h,
        "steps": steps,
        "watched": tip,
        "system": "UmfPack",
    });
    let file = dir.path().join("model.json");
    std::fs::write(&file, model.to_string()).unwrap();
    let script =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/opensees/newmark_truss.py");
    let out = Command::new(&python)
        .arg(&script)
        .arg(&file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "OpenSees failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // OpenSees prints its own lines (e.g. "Process 0 Terminating"): the JSON is the line that
    // opens with a brace.
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with('{'))
        .unwrap_or_else(|| panic!("no JSON from OpenSees: {text}"));
    let v: serde_json::Value = serde_json::from_str(line).unwrap();
    let history = v["history"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()])
        .collect();
    (history, v["seconds_per_step"].as_f64().unwrap())
}

/// The largest difference of two tip histories over the whole run, relative to the largest
/// tip displacement of `reference`.
fn difference(a: &[[f64; 2]], reference: &[[f64; 2]]) -> f64 {
    assert_eq!(a.len(), reference.len());
    let peak = reference
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    a.iter()
        .zip(reference)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, f64::max)
        / peak
}

/// 400 steps of 0.2 ms (about 1.5 periods of the first mode, the tip swinging down 0.27 m and
/// back): ours and OpenSees agree to 1e-6 of the largest tip displacement at every step, and
/// the same run with linear kinematics differs from OpenSees by more than 1 %.
#[test]
fn newmark_cantilever_agrees_with_opensees_corot_truss() {
    let (h, steps) = (2e-4, 400);
    let (body, mass, tip) = cantilever(10, 1, Kinematics::Large);
    let (theirs, their_time) = opensees(&body, &mass, tip, h, steps);
    let (mine, my_time) = ours(&body, &mass, tip, h, steps);
    let peak = theirs.iter().map(|p| p[0].hypot(p[1])).fold(0.0, f64::max);
    assert!(peak > 0.2, "the tip must move far: {peak} m");
    let large = difference(&mine, &theirs);
    let (linear_body, _, _) = cantilever(10, 1, Kinematics::Linear);
    let (linear, _) = ours(&linear_body, &mass, tip, h, steps);
    let small = difference(&linear, &theirs);
    eprintln!(
        "OpenSees comparison: peak tip displacement {peak:.4} m; large kinematics differ by {large:.2e} of it, linear by {small:.2e}; {:.1} µs per step ours, {:.1} µs OpenSees",
        my_time * 1e6,
        their_time * 1e6
    );
    assert!(
        large < 1e-6,
        "ours differs from OpenSees by {large:e} of the peak"
    );
    assert!(
        small > 1e-2,
        "linear kinematics should not agree: {small:e}"
    );
}

/// The benchmark (`cargo test --release --test opensees -- --ignored --nocapture`): the same
/// cantilever of 200 × 10 cells (8,210 members, 4,422 DOFs), 50 steps, time per step ours and
/// OpenSees's in one run.
#[test]
#[ignore]
fn newmark_cantilever_time_per_step_against_opensees() {
    let (h, steps) = (2e-5, 50);
    let (body, mass, tip) = cantilever(200, 10, Kinematics::Large);
    let (theirs, their_time) = opensees(&body, &mass, tip, h, steps);
    let (mine, my_time) = ours(&body, &mass, tip, h, steps);
    eprintln!(
        "OpenSees benchmark: {} members, {} DOFs, {steps} steps: {:.2} ms per step ours, {:.2} ms OpenSees (ratio {:.2}); tips differ by {:.1e} of the peak",
        body.members.len(),
        body.dof_count(),
        my_time * 1e3,
        their_time * 1e3,
        their_time / my_time,
        difference(&mine, &theirs)
    );
}
