//! `linkage bench --dynamics`, second part: our Newmark against OpenSees on the same truss, a
//! 2D lattice cantilever (both diagonals in every cell) with the lumped masses ρAL/2, suddenly
//! loaded at its tip, large displacements. OpenSees (openseespy) runs
//! `bench/opensees_newmark_truss.py` (embedded here as [`SCRIPT`]): `corotTruss` elements with
//! the same nodal masses, `integrator('Newmark', 0.5, 0.25)`, `algorithm('Newton')`,
//! `test('NormDispIncr', 1e-12, 50)`.
//!
//! The two solve the same discrete equations: `corotTruss` has our large-kinematics member,
//! engineering strain `(l − L)/L`, force `E A (l − L)/L` along the current chord, constant
//! area (OpenSees's `CorotTruss::update` and `getResistingForce`), so the tip histories agree
//! to the Newton tolerances ([`AGREEMENT`] of the largest tip displacement is asked).

use crate::linkage::dynamics::{lumped_mass, BodyMotion, Newmark, RayleighDamping};
use crate::linkage::generators::rectangle;
use crate::linkage::{Body, Dimension, Kinematics, Material, Member, NodalLoad, Schedule, Support};
use crate::Real;
use nalgebra::Vector3;
use std::path::Path;
use std::process::Command;
use std::time::Instant;

/// OpenSees's side of the comparison: reads the JSON model, prints the tip history and its
/// wall time per step as one JSON line.
pub const SCRIPT: &str = include_str!("../../bench/opensees_newmark_truss.py");

/// Young's modulus, Pa.
pub const E: Real = 1e9;
/// Member area, m².
pub const AREA: Real = 1e-4;
/// Density, kg/m³.
pub const RHO: Real = 1000.0;
/// The largest difference of the tip histories allowed, relative to the largest tip
/// displacement.
pub const AGREEMENT: Real = 1e-6;
/// The benchmark's cantilever: cells along and across (8,210 members, 4,422 DOFs).
pub const CELLS: [usize; 2] = [200, 10];
/// The `--quick` cantilever (10 × 1 cells, 51 members).
pub const QUICK_CELLS: [usize; 2] = [10, 1];
/// Time step (s) and steps of the benchmark.
pub const RUN: (Real, usize) = (2e-5, 50);
/// Time step (s) and steps of the `--quick` run.
pub const QUICK_RUN: (Real, usize) = (2e-4, 400);

/// The cantilever: a 1 m × 0.1 m rectangle of `cells` cells (along, across), E = [`E`], A =
/// [`AREA`], held at its left nodes, 200 N per cell across down at its upper right node from
/// t = 0, Newton tolerance 1e-13; its lumped mass per DOF (kg, ρ = [`RHO`]); the tip node.
pub fn cantilever(
    cells: [usize; 2],
    kinematics: Kinematics,
) -> Result<(Body, Vec<Real>, usize), String> {
    let [along, across] = cells;
    let g = rectangle(1.0, 0.1, along, across).map_err(|e| e.to_string())?;
    let mut body = Body::new("cantilever", Dimension::Two);
    body.materials.push(Material::new("steel", E, AREA));
    body.nodes = g.nodes;
    body.members = g
        .members
        .into_iter()
        .map(|nodes| Member { nodes, material: 0 })
        .collect();
    for j in 0..=across {
        body.supports
            .push(Support::fixed(j * (along + 1), [true, true, false]));
    }
    let tip = (along + 1) * (across + 1) - 1;
    body.loads.push(NodalLoad {
        node: tip,
        force: Vector3::new(0.0, -200.0 * across as Real, 0.0),
        schedule: Schedule::Factors(vec![1.0]),
    });
    body.kinematics = kinematics;
    body.newton.tolerance = 1e-13;
    let mass = lumped_mass(&body, &[Some(RHO)]).map_err(|e| e.to_string())?;
    Ok((body, mass, tip))
}

/// A tip history: the tip's (ux, uy) after each step, m.
pub type TipHistory = Vec<[Real; 2]>;

/// Our Newmark ¼, ½ run of `steps` steps of `h` s from the balanced initial acceleration: the
/// tip's history and the wall time per step (s, the set-up included).
pub fn ours(
    body: &Body,
    mass: &[Real],
    tip: usize,
    (h, steps): (Real, usize),
) -> Result<(TipHistory, Real), String> {
    let duration = h * steps as Real;
    let start = Instant::now();
    let mut m = BodyMotion::new(
        body,
        mass.to_vec(),
        vec![0.0; body.dof_count()],
        RayleighDamping::default(),
    )
    .map_err(|e| e.to_string())?;
    m.balance_initial_acceleration(body, duration);
    let mut history = Vec::with_capacity(steps);
    for k in 0..steps {
        m.step(body, &Newmark::default(), k as Real * h, h, duration)
            .map_err(|e| format!("our step {}: {}", k + 1, e.reason))?;
        history.push([m.motion.u[2 * tip], m.motion.u[2 * tip + 1]]);
    }
    Ok((
        history,
        start.elapsed().as_secs_f64() / steps.max(1) as Real,
    ))
}

/// OpenSees's run of the same body with `python` (openseespy importable): the tip's history
/// and its wall time per step (s, measured by the script around `analyze`). `scratch` is a
/// folder for the model and the script.
pub fn opensees(
    python: &Path,
    scratch: &Path,
    body: &Body,
    mass: &[Real],
    tip: usize,
    (h, steps): (Real, usize),
) -> Result<(TipHistory, Real), String> {
    let model = serde_json::json!({
        "nodes": body.nodes.iter().map(|p| [p.x, p.y]).collect::<Vec<_>>(),
        "members": body.members.iter().map(|m| m.nodes).collect::<Vec<_>>(),
        "E": E,
        "A": AREA,
        "mass": mass.iter().step_by(2).collect::<Vec<_>>(),
        "fixed": body.supports.iter().map(|s| s.node).collect::<Vec<_>>(),
        "loads": body.loads.iter().map(|l| serde_json::json!([l.node, l.force.x, l.force.y])).collect::<Vec<_>>(),
        "h": h,
        "steps": steps,
        "watched": tip,
        "system": "UmfPack",
    });
    let file = scratch.join("model.json");
    std::fs::write(&file, model.to_string())
        .map_err(|e| format!("writing {}: {e}", file.display()))?;
    let script = scratch.join("opensees_newmark_truss.py");
    std::fs::write(&script, SCRIPT).map_err(|e| format!("writing {}: {e}", script.display()))?;
    let out = Command::new(python)
        .arg(&script)
        .arg(&file)
        .output()
        .map_err(|e| format!("cannot start {}: {e}", python.display()))?;
    if !out.status.success() {
        return Err(format!(
            "OpenSees failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        ));
    }
    // OpenSees prints its own lines (e.g. "Process 0 Terminating"): the JSON is the line that
    // opens with a brace.
    let text = String::from_utf8_lossy(&out.stdout);
    let line = text
        .lines()
        .find(|l| l.starts_with('{'))
        .ok_or_else(|| format!("no JSON line from OpenSees in its output: {text}"))?;
    #[derive(serde::Deserialize)]
    struct Output {
        history: TipHistory,
        seconds_per_step: Real,
    }
    let o: Output = serde_json::from_str(line)
        .map_err(|e| format!("cannot read OpenSees's output line {line:?}: {e}"))?;
    if o.history.len() != steps {
        return Err(format!(
            "OpenSees gave {} steps of the {steps} asked",
            o.history.len()
        ));
    }
    Ok((o.history, o.seconds_per_step))
}

/// The largest tip displacement of a history, m.
pub fn peak(history: &[[Real; 2]]) -> Real {
    history
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, Real::max)
}

/// The largest difference of two tip histories of the same length over the whole run,
/// relative to the largest tip displacement of `reference`.
pub fn difference(a: &[[Real; 2]], reference: &[[Real; 2]]) -> Real {
    a.iter()
        .zip(reference)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0, Real::max)
        / peak(reference)
}

/// The Python of `target/opensees-venv` next to this executable's `target/release` (where
/// `.ci/run` and the tests put openseespy), if it exists.
pub fn venv_python() -> Option<std::path::PathBuf> {
    let exe = std::env::current_exe().ok()?;
    exe.ancestors()
        .map(|dir| dir.join("opensees-venv/bin/python"))
        .find(|p| p.is_file())
}

/// How to make a Python with openseespy, for the message when there is none.
pub const INSTALL: &str = "python3 -m venv target/opensees-venv && target/opensees-venv/bin/python -m pip install openseespy (it links the system's libblas.so.3: apt-get install libblas3), then pass --python target/opensees-venv/bin/python or set LINKAGE_OPENSEES_PYTHON";

/// One comparison: model size, both times per step and the agreement of the tip histories.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Cells along and across.
    pub cells: [usize; 2],
    /// Members and DOFs.
    pub sizes: [usize; 2],
    /// Time step (s) and steps.
    pub run: (Real, usize),
    /// Our wall time per step, s.
    pub ours: Real,
    /// OpenSees's wall time per step, s, and the tip histories' difference relative to the
    /// peak tip displacement (`None` without a Python with openseespy).
    pub theirs: Option<(Real, Real)>,
    /// The largest tip displacement of our run, m.
    pub peak: Real,
}

/// Build the cantilever of `cells`, run ours and (with `python`) OpenSees over `run`.
pub fn compare(
    cells: [usize; 2],
    run: (Real, usize),
    python: Option<&Path>,
    scratch: &Path,
) -> Result<Comparison, String> {
    let (body, mass, tip) = cantilever(cells, Kinematics::Large)?;
    let theirs = python
        .map(|py| opensees(py, scratch, &body, &mass, tip, run))
        .transpose()?;
    let (mine, my_time) = ours(&body, &mass, tip, run)?;
    Ok(Comparison {
        cells,
        sizes: [body.members.len(), body.dof_count()],
        run,
        ours: my_time,
        theirs: theirs.map(|(h, t)| (t, difference(&mine, &h))),
        peak: peak(&mine),
    })
}

/// The comparison's line.
pub fn format_comparison(c: &Comparison) -> String {
    let head = format!(
        "{}x{} cells: {} members, {} DOFs, {} steps of {} µs: ours {:.3} ms per step",
        c.cells[0],
        c.cells[1],
        c.sizes[0],
        c.sizes[1],
        c.run.1,
        c.run.0 * 1e6,
        c.ours * 1e3
    );
    match c.theirs {
        Some((t, d)) => format!(
            "{head}, OpenSees {:.3} ms per step: ratio OpenSees / ours {:.2}; tip histories differ by {d:.1e} of the peak {:.4} m ({})",
            t * 1e3,
            t / c.ours.max(1e-12),
            c.peak,
            if d <= AGREEMENT { "agree to 1e-6" } else { "DO NOT AGREE to 1e-6" }
        ),
        None => format!("{head} (OpenSees not run)"),
    }
}
