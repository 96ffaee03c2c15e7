//! Contact benchmark (issues 5 and 13):
//! `cargo run --release --example bench_contact [--skip-pair] [--friction] [--cells N]`.
//!
//! 1. Contact query time: one query iteration against a deformable surface of about 10,000 and
//!    100,000 surface nodes: the oriented `TriMesh` rebuilt from the nodes, then every node of a
//!    second, overlapping surface of the same size projected on it (inside test, nearest patch).
//! 2. Two 3D boxes of about 20,000 nodes each pressed together (the lower one standing on its
//!    base, the upper one held vertically by contact alone): time per load step split into
//!    assembly, factorization, solves and contact queries, with Newton and contact iterations
//!    and the equilibrium residual; then the whole run (set-up and steps), wall and CPU time
//!    (the CPU time of the process, both cores: on a shared machine it shows the work apart
//!    from the waiting). Both bodies ask for the direct solver: above 30,000 free
//!    DOFs `auto` would pick conjugate gradients on the coupled system, and only bodies with a
//!    factorization are condensed.
//! 3. With `--friction` (the query timings are then left out): the same pair with μ = 0
//!    (frictionless) and then with Coulomb friction μ = 0.3, the upper box sheared 0.1 mm along x per step from step
//!    2 by its two held lines; the same phase times per step, with the sticking and slipping
//!    contacts. `--cells N` sets the boxes' cells per edge (default 27: 28³ = 21,952 nodes).

use linkage::contact::PatchSurface;
use linkage::linkage::{generators, Body, Material};
use linkage::scene::{build_world, Simulation};
use nalgebra::Vector3;
use std::path::Path;
use std::time::Instant;

fn slab(cells: usize) -> Body {
    let g = generators::box_lattice([1.0, 1.0, 1.0 / cells as f64], [cells, cells, 1])
        .expect("a valid lattice");
    Body::from_geometry("slab", g, Material::new("m", 1e7, 1e-4))
}

fn query(cells: usize) {
    let body = slab(cells);
    let surface = PatchSurface::of(&body)
        .expect("closed")
        .expect("has patches");
    let t = Instant::now();
    let (mesh, _) = surface.mesh(|n| body.nodes[n]).expect("a mesh");
    let build = t.elapsed().as_secs_f64();
    // The second surface: the same slab shifted half its thickness down, so half its nodes
    // are inside.
    let shift = Vector3::new(0.0, 0.0, -0.5 / cells as f64);
    let t = Instant::now();
    let mut inside = 0;
    for &n in &surface.nodes {
        if PatchSurface::inside(&mesh, &(body.nodes[n] - shift)).is_some() {
            inside += 1;
        }
    }
    let project = t.elapsed().as_secs_f64();
    println!(
        "query  {:>7} surface nodes, {:>7} patches: mesh {:.4} s + {} projections {:.4} s = {:.4} s per query iteration ({} inside)",
        surface.nodes.len(),
        surface.patches.len(),
        build,
        surface.nodes.len(),
        project,
        build + project,
        inside
    );
}

/// The pair of boxes with `n` cells per edge; with `Some(μ)` (0 for frictionless), sheared
/// from step 2 with Coulomb coefficient μ; with `None`, pressed only, frictionless. Returns
/// each step's wall time, s; with `against` (the frictionless run's), prints each step's
/// ratio to it.
fn pair(n: usize, friction: Option<f64>, against: &[f64]) -> Vec<f64> {
    let h = 0.1;
    let scene = format!(
        r#"
name = "bench_pair"
steps = {steps}
[[materials]]
name = "rubber"
youngs_modulus = 1e7
area = 1e-4
[[bodies]]
name = "lower"
box_lattice = {{ size = [0.2, {h}, 0.2], cells = [{n}, {n}, {n}] }}
solver = "direct"
[[bodies.supports]]
on_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }}
fix = ["x", "y", "z"]
[[bodies]]
name = "upper"
box_lattice = {{ size = [0.2, {h}, 0.2], cells = [{n}, {n}, {n}] }}
solver = "direct"
offset = [0.0, {h}, 0.0]
[[bodies.supports]]
on_line = {{ point = [0.0, {h}, 0.0], direction = [0.0, 1.0, 0.0] }}
fix = ["x", "z"]{shear}
[[bodies.supports]]
on_line = {{ point = [0.2, {h}, 0.2], direction = [0.0, 1.0, 0.0] }}
fix = ["x", "z"]{shear}
[[bodies.loads]]
on_plane = {{ point = [0.0, {top}, 0.0], normal = [0.0, 1.0, 0.0] }}
total_force = [0.0, -500.0, 0.0]
[contact]
{law}
"#,
        top = 2.0 * h,
        steps = STEPS,
        shear = if friction.is_some() { SHEAR } else { "" },
        law = friction.map_or(String::new(), |mu| format!("friction = {mu}")),
    );
    let world = build_world(&scene, Path::new("bench_pair.toml")).expect("a valid scene");
    let start = Instant::now();
    let cpu_start = cpu_seconds();
    let mut sim = Simulation::new(&world).expect("builds");
    let setup = start.elapsed().as_secs_f64();
    let cpu_setup = cpu_seconds().zip(cpu_start).map(|(a, b)| a - b);
    // Phase times of the contact solver so far: assembly (and residuals), ordering and
    // symbolic analysis, factorization (with the compliance), solves, contact queries.
    let phases = |sim: &Simulation| -> [f64; 5] {
        let c = sim.contact().expect("a contact scene");
        [
            c.times.assembly,
            c.times.symbolic,
            c.times.numeric,
            c.times.solve,
            c.query_seconds,
        ]
    };
    let condensed = sim.contact().is_some_and(|c| c.is_condensed());
    let candidates: Vec<usize> = (0..2)
        .filter_map(|b| sim.contact().and_then(|c| c.candidate_nodes(b)))
        .collect();
    let p0 = phases(&sim);
    println!(
        "pair{}   2 × {} nodes ({} free DOFs), {} load steps of 500/{} N, {} (candidate nodes {:?}): set-up {:.2} s (ordering+symbolic {:.2} s, factorization and compliance {:.2} s, load-pattern solves {:.2} s)",
        friction.map_or(String::new(), |mu| format!(" μ = {mu}")),
        world.bodies[0].nodes.len(),
        sim.contact()
            .map(|c| c.free_dofs(0) + c.free_dofs(1))
            .unwrap_or(0),
        STEPS,
        STEPS,
        if condensed { "condensed" } else { "coupled" },
        candidates,
        setup,
        p0[1],
        p0[2],
        p0[3]
    );
    if let Some(cpu) = cpu_setup {
        println!("       set-up CPU (both cores, this process) {cpu:.2} s");
    }
    let mut before = p0;
    let mut seconds_per_step = Vec::with_capacity(STEPS);
    for step in 0..=STEPS {
        let t = Instant::now();
        let (_, summary) = sim.step(step).expect("solves");
        let seconds = t.elapsed().as_secs_f64();
        let now = phases(&sim);
        let d: Vec<f64> = now.iter().zip(&before).map(|(a, b)| a - b).collect();
        before = now;
        if step == 0 {
            continue;
        }
        seconds_per_step.push(seconds);
        let ratio = against.get(step - 1).map_or(String::new(), |f| {
            format!(" ({:.1}× the frictionless step)", seconds / f)
        });
        println!(
            "       step {step}: {seconds:.2} s{ratio} = factorization {:.2} s + ordering {:.2} s + solves {:.2} s + contact queries {:.3} s + residuals {:.2} s + rest; {} Newton, {} contact iterations, residual {:.1e}, max penetration {:.2e} m{}",
            d[2],
            d[1],
            d[3],
            d[4],
            d[0],
            summary.iterations,
            summary.contact_iterations,
            summary.residual,
            summary.max_penetration,
            if friction.is_some() {
                format!("; {} sticking, {} slipping", summary.sticking, summary.slipping)
            } else {
                String::new()
            }
        );
    }
    let cpu = cpu_seconds()
        .zip(cpu_start)
        .map_or(String::new(), |(a, b)| format!(", CPU {:.2} s", a - b));
    println!(
        "       whole run (set-up and {STEPS} steps): {:.2} s{cpu}",
        start.elapsed().as_secs_f64()
    );
    if against.len() == seconds_per_step.len() && !against.is_empty() {
        let (a, b): (f64, f64) = (seconds_per_step.iter().sum(), against.iter().sum());
        println!(
            "       steps 1-{STEPS}: {a:.2} s against {b:.2} s frictionless: {:.1}×",
            a / b
        );
    }
    seconds_per_step
}

/// User plus system CPU time of this process so far, s (Linux `/proc/self/stat`; `None`
/// elsewhere): on a shared machine it shows the work apart from the waiting.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command name (which is in parentheses and may hold spaces).
    let rest = &stat[stat.rfind(')')? + 2..];
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    // The kernel's USER_HZ is 100 on every Linux the project runs on.
    Some(ticks / 100.0)
}

/// Load steps of the pair benchmark: the first includes the one-off factorizations.
const STEPS: usize = 4;

/// The held lines' shear with friction: 0.1 mm along x per step from step 2.
const SHEAR: &str = "\ndisplacement = [1e-4, 0.0, 0.0]\nschedule = [0.0, 1.0, 2.0, 3.0]";

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| args.iter().any(|a| a == name);
    // 28 × 28 × 28 = 21,952 nodes per box.
    let cells = match args.iter().position(|a| a == "--cells") {
        Some(i) => match args.get(i + 1).and_then(|v| v.parse::<usize>().ok()) {
            Some(c) if c > 0 => c,
            _ => {
                eprintln!("--cells takes a positive whole number of cells per edge");
                std::process::exit(2);
            }
        },
        None => 27,
    };
    if flag("--friction") {
        let frictionless = pair(cells, Some(0.0), &[]);
        pair(cells, Some(0.3), &frictionless);
        return;
    }
    // 2 (c + 1)² surface nodes: c = 70 gives 10,082; c = 223 gives 100,352.
    query(70);
    query(223);
    if !flag("--skip-pair") {
        pair(cells, None, &[]);
    }
}
