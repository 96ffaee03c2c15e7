//! The `linkage bench` commands: each runs one benchmark of `linkage::bench` and prints its
//! table.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

pub(crate) fn bench_contact(
    cells: Vec<[usize; 3]>,
    steps: Option<usize>,
    direct: bool,
) -> Result<()> {
    let cells = cells.first().copied().unwrap_or([45, 45, 45]);
    let solver = if direct { "direct" } else { "iterative" };
    say!("3D box lattice on a fixed floor pressed 2 mm by a ball obstacle ({solver} solver)");
    let t = linkage::bench::contact::measure_contact(cells, steps.unwrap_or(2), solver)
        .map_err(anyhow::Error::msg)?;
    for s in &t.steps {
        say!("{}", linkage::bench::contact::format_step(s));
    }
    say!("{}", linkage::bench::contact::format_summary(&t));
    Ok(())
}

/// `linkage bench --dynamics`: the dropped lattice, then ours against OpenSees, in one run.
pub(crate) fn bench_dynamics(
    cells: Vec<[usize; 3]>,
    steps: Option<usize>,
    quick: bool,
    python: Option<PathBuf>,
) -> Result<()> {
    use linkage::bench::{cholmod::load_average, dynamics, opensees};
    let load = || load_average().map_or("?".to_string(), |l| format!("{l:.2}"));
    say!("load average at start: {}", load());
    let lattice = cells.first().copied().unwrap_or(if quick {
        dynamics::QUICK_CELLS
    } else {
        dynamics::CELLS
    });
    let steps = steps.unwrap_or(if quick {
        dynamics::QUICK_STEPS
    } else {
        dynamics::STEPS
    });
    say!(
        "1. A 3D rubber box lattice thrown down at {} m/s under gravity onto a floor (half-space, \
         penalty contact), energy-momentum, time step {} ms, {} steps of free fall then contact",
        dynamics::SPEED,
        dynamics::TIME_STEP * 1e3,
        dynamics::STEPS_BEFORE_CONTACT
    );
    let t = dynamics::measure_dynamics(lattice, steps).map_err(anyhow::Error::msg)?;
    for (k, s) in t.steps.iter().enumerate() {
        say!("{}", dynamics::format_step(k + 1, s));
    }
    say!("{}", dynamics::format_summary(&t));
    let python = python
        .or_else(|| std::env::var_os("LINKAGE_OPENSEES_PYTHON").map(PathBuf::from))
        .or_else(opensees::venv_python);
    let (cells, run) = if quick {
        (opensees::QUICK_CELLS, opensees::QUICK_RUN)
    } else {
        (opensees::CELLS, opensees::RUN)
    };
    say!(
        "2. Newmark (1/4, 1/2), large displacements: a 2D lattice cantilever suddenly loaded at \
         its tip, ours against OpenSees (corotTruss, UmfPack, Newton, NormDispIncr 1e-12)"
    );
    if python.is_none() {
        say!(
            "no Python with openseespy found: OpenSees is not run, ours is timed alone. To \
             compare: {}",
            opensees::INSTALL
        );
    }
    let dir = tempfile_dir("linkage-bench-opensees")?;
    let compared = opensees::compare(cells, run, python.as_deref(), &dir);
    let _ = std::fs::remove_dir_all(&dir);
    let c = compared.map_err(anyhow::Error::msg)?;
    say!("{}", opensees::format_comparison(&c));
    say!("load average at end: {}", load());
    if let Some((_, d)) = c.theirs {
        if d > opensees::AGREEMENT {
            bail!(
                "ours and OpenSees differ by {d:.2e} of the peak tip displacement (at most {:e} expected)",
                opensees::AGREEMENT
            );
        }
    }
    Ok(())
}

pub(crate) fn bench_fracture(cells: Vec<[usize; 3]>, breaks: Option<usize>) -> Result<()> {
    let cells = cells.first().copied().unwrap_or([20, 20, 20]);
    let breaks = breaks.unwrap_or(1000);
    say!("3D box lattice pulled at its top face, members breaking one after another in one load step");
    let t = linkage::bench::fracture::measure_fracture(cells, breaks, 10)
        .map_err(anyhow::Error::msg)?;
    say!("{}", linkage::bench::fracture::format_fracture(&t));
    let split =
        linkage::bench::fracture::measure_solve_split(cells, 20).map_err(anyhow::Error::msg)?;
    say!("{}", linkage::bench::fracture::format_solve_split(&split));
    Ok(())
}

pub(crate) fn bench_large(
    cells: Vec<[usize; 3]>,
    force: Option<f64>,
    steps: Option<usize>,
    iterative: bool,
    cold: bool,
) -> Result<()> {
    use linkage::linkage::{SolverChoice, SolverSettings};
    let cells = cells.first().copied().unwrap_or([16, 16, 150]);
    let force = force.unwrap_or(2.5e5);
    let steps = steps.unwrap_or(5);
    let mut solver = SolverSettings {
        choice: if iterative {
            SolverChoice::Iterative
        } else {
            SolverChoice::Direct
        },
        ..Default::default()
    };
    solver.iterative.warm_start = !cold;
    let how = match (iterative, cold) {
        (false, _) => "sparse LLᵀ, METIS order, refactored every iteration",
        (true, false) => "multigrid conjugate gradients, warm-started",
        (true, true) => "multigrid conjugate gradients, cold starts",
    };
    say!("3D column lattice, bottom clamped, top pushed sideways; large displacements by Newton ({how})");
    let t = linkage::bench::large::measure_large(cells, force, steps, solver)
        .map_err(anyhow::Error::msg)?;
    for s in &t.steps {
        say!("{}", linkage::bench::large::format_step(s));
    }
    say!("{}", linkage::bench::large::format_summary(&t));
    Ok(())
}

const DEFAULT_BENCH: [[usize; 3]; 6] = [
    [10, 10, 10],
    [20, 20, 20],
    [20, 20, 40],
    [30, 30, 30],
    [40, 40, 40],
    [43, 43, 43],
];

pub(crate) fn bench(
    cells: Vec<[usize; 3]>,
    iterative: bool,
    jacobi: bool,
    in_process: bool,
) -> Result<()> {
    let sizes = if cells.is_empty() {
        DEFAULT_BENCH.to_vec()
    } else {
        cells
    };
    let what = if iterative && jacobi {
        "block-Jacobi conjugate gradients to 1e-10"
    } else if iterative {
        "smoothed-aggregation multigrid conjugate gradients to 1e-10"
    } else {
        "direct sparse Cholesky (METIS order)"
    };
    say!("3D box lattices: 26-neighbour cells, bottom face fixed, top face loaded; {what}");
    if iterative {
        say!("{}", linkage::bench::lattice::ITERATIVE_HEADER);
    } else {
        say!("{}", linkage::bench::lattice::HEADER);
    }
    for c in sizes {
        if in_process && iterative {
            let t = linkage::bench::lattice::measure_iterative(c, !jacobi)
                .map_err(anyhow::Error::msg)?;
            say!("{}", linkage::bench::lattice::format_iterative_row(&t));
        } else if in_process {
            let t = linkage::bench::lattice::measure_lattice(c).map_err(anyhow::Error::msg)?;
            say!("{}", linkage::bench::lattice::format_row(&t));
        } else {
            // One child per size, so the peak memory column is that size's own.
            let exe = std::env::current_exe().context("cannot find the linkage executable")?;
            let mut args = vec!["bench".to_string(), "--in-process".to_string()];
            if iterative {
                args.push("--iterative".to_string());
            }
            if jacobi {
                args.push("--jacobi".to_string());
            }
            args.extend(["--cells".to_string(), format!("{}x{}x{}", c[0], c[1], c[2])]);
            let output = std::process::Command::new(exe)
                .args(&args)
                .output()
                .context("cannot start the benchmark child process")?;
            if !output.status.success() {
                bail!(
                    "benchmark of {c:?} failed: {}",
                    String::from_utf8_lossy(&output.stderr)
                );
            }
            let text = String::from_utf8_lossy(&output.stdout);
            if let Some(row) = text.lines().last() {
                say!("{row}");
            }
        }
    }
    Ok(())
}

pub(crate) fn bench_read(cells: Vec<[usize; 3]>) -> Result<()> {
    let dir = tempfile_dir("linkage-bench-read")?;
    say!("Reading the paper's files of a box lattice (links with a material column), best of 3");
    say!(
        "{:>12} {:>8} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "cells",
        "nodes",
        "members",
        "links MB",
        "nodes s",
        "links s",
        "check s",
        "patch s",
        "Mlines/s"
    );
    let sizes = if cells.is_empty() {
        vec![[49, 49, 49]]
    } else {
        cells
    };
    let measured = sizes.into_iter().try_for_each(|c| -> Result<()> {
        let t = linkage::bench::read::measure_read(c, &dir, 3).map_err(anyhow::Error::msg)?;
        say!(
            "{:>12} {:>8} {:>9} {:>9.1} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.1}",
            format!("{}x{}x{}", c[0], c[1], c[2]),
            t.nodes,
            t.members,
            t.links_bytes as f64 / 1e6,
            t.nodes_seconds,
            t.links_seconds,
            t.check_seconds,
            t.patches_seconds,
            t.members as f64 / t.links_seconds / 1e6
        );
        Ok(())
    });
    // The lattice's files are scratch: removed whether or not the measurement succeeded.
    let _ = std::fs::remove_dir_all(&dir);
    measured
}

/// `linkage bench --run`: a box lattice's scene (from the paper's files, multigrid solver, one
/// load step) through `linkage run` in a child process, so that the peak memory is the run's.
pub(crate) fn bench_run(cells: Vec<[usize; 3]>) -> Result<()> {
    let cells = cells.first().copied().unwrap_or([49, 49, 49]);
    let dir = tempfile_dir("linkage-bench-run")?;
    let measured = run_lattice_scene(cells, &dir);
    // The lattice's files and results are scratch: removed whether or not the run succeeded.
    let _ = std::fs::remove_dir_all(&dir);
    measured
}

fn run_lattice_scene(c: [usize; 3], dir: &std::path::Path) -> Result<()> {
    let files = linkage::bench::read::write_lattice_files(c, dir).map_err(anyhow::Error::msg)?;
    let top = c[2] as f64 * 0.01;
    let scene = dir.join("lattice.toml");
    std::fs::write(
        &scene,
        format!(
            "name = \"lattice\"\nsteps = 1\n\n[[materials]]\nname = \"steel\"\nyoungs_modulus = 200e9\narea = 1e-4\n\n\
             [[bodies]]\nname = \"box\"\nnodes = \"lattice.nodes\"\nlinks = \"lattice.links\"\npatches = \"lattice.patches\"\nsolver = \"iterative\"\n\n\
             [[bodies.supports]]\non_plane = {{ point = [0.0, 0.0, 0.0], normal = [0.0, 0.0, 1.0] }}\nfix = [\"x\", \"y\", \"z\"]\n\n\
             [[bodies.loads]]\non_plane = {{ point = [0.0, 0.0, {top}], normal = [0.0, 0.0, 1.0] }}\ntotal_force = [0.0, 0.0, -1000.0]\n"
        ),
    )
    .with_context(|| format!("writing {}", scene.display()))?;
    let exe = std::env::current_exe().context("cannot find the linkage executable")?;
    let out = dir.join("out");
    let started = std::time::Instant::now();
    let output = std::process::Command::new(exe)
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&out)
        .output()
        .context("cannot start `linkage run`")?;
    let wall = started.elapsed().as_secs_f64();
    if !output.status.success() {
        bail!(
            "`linkage run` of the {}x{}x{} lattice failed: {}{}",
            c[0],
            c[1],
            c[2],
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    let peak = children_peak_memory();
    let path = out.join("lattice").join("summary.json");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let summary: linkage::scene::Summary =
        serde_json::from_str(&text).with_context(|| format!("reading {}", path.display()))?;
    let p = &summary.phases;
    let [nodes, members, _] = files.counts;
    let links_mb = std::fs::metadata(&files.links).map_or(0, |m| m.len()) as f64 / 1e6;
    say!("A box lattice through `linkage run` (paper's files, multigrid solver, 1 load step), in a child process");
    say!(
        "{:>10} {:>8} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "cells",
        "nodes",
        "members",
        "links MB",
        "read s",
        "assem s",
        "set-up s",
        "solve s",
        "write s",
        "wall s",
        "peak MB"
    );
    say!(
        "{:>10} {:>8} {:>9} {:>9.1} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.0}",
        format!("{}x{}x{}", c[0], c[1], c[2]),
        nodes,
        members,
        links_mb,
        p.reading,
        p.assembly,
        p.symbolic,
        p.solve,
        p.writing,
        wall,
        peak as f64 / 1e6
    );
    say!("(set-up: the matrix in full rows and the multigrid hierarchy; solve: conjugate gradients; peak: the child's largest resident set, MB of 10^6 bytes)");
    Ok(())
}

/// The largest resident set of the child processes waited for, bytes (0 where unknown).
fn children_peak_memory() -> u64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut usage) } != 0 {
        return 0;
    }
    // Linux reports ru_maxrss in kilobytes.
    (usage.ru_maxrss.max(0) as u64) * 1024
}

/// A new empty folder under the system's temporary folder, named after `prefix` and this
/// process.
fn tempfile_dir(prefix: &str) -> Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("{prefix}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

pub(crate) fn bench_render(patches: usize, size: [u32; 2]) -> Result<()> {
    let t = linkage::bench::render::render_benchmark(patches, size[0], size[1], 3)
        .map_err(anyhow::Error::msg)?;
    say!("Rendering: one frame of a bent cylindrical shell, shaded and stress-coloured (supersampling 2x2), best of 3");
    say!(
        "{:>9} {:>9} {:>11} {:>10} {:>10}",
        "patches",
        "members",
        "pixels",
        "draw s",
        "PNG s"
    );
    say!(
        "{:>9} {:>9} {:>11} {:>10.3} {:>10.3}",
        t.patches,
        t.members,
        format!("{}x{}", t.size[0], t.size[1]),
        t.draw,
        t.png
    );
    Ok(())
}

pub(crate) fn bench_gif(dir: &Path) -> Result<()> {
    let t = linkage::bench::render::gif_benchmark(dir).map_err(anyhow::Error::msg)?;
    say!(
        "GIF of {} ({} frames of 1280x720, drawn in {:.3} s):",
        dir.display(),
        t.frames,
        t.draw
    );
    say!(
        "  a palette per frame (NeuQuant), sequential: {:.3} s, {} bytes",
        t.per_frame_palette,
        t.bytes.0
    );
    say!(
        "  one palette for the run, frames in parallel: {:.3} s, {} bytes",
        t.shared_palette,
        t.bytes.1
    );
    say!(
        "  speed-up: {:.1}x",
        t.per_frame_palette / t.shared_palette.max(1e-12)
    );
    Ok(())
}

pub(crate) fn bench_prepare() -> Result<()> {
    use linkage::bench::prepare::{measure_prepare, RADIUS, SPACING, TUBE};
    let t = measure_prepare(SPACING).map_err(anyhow::Error::msg)?;
    say!(
        "Preparing a torus (radius {RADIUS} m, tube {TUBE} m, {} triangles) at spacing {SPACING} m: isosurface stuffing",
        t.triangles
    );
    say!("{}", t.report);
    say!(
        "prepare {:.3} s, peak memory {:.0} MB",
        t.seconds,
        t.peak_memory as f64 / 1e6
    );
    Ok(())
}

/// `linkage bench --cholmod`: ordering + factorization + solve of each lattice's `K_ff` by
/// our direct solver and by CHOLMOD (scikit-sparse, run by `python`), alternately `reps`
/// times on the same matrix; prints every repetition, the best of each and their ratio.
pub(crate) fn bench_cholmod(
    cells: Vec<[usize; 3]>,
    reps: usize,
    python: Option<PathBuf>,
) -> Result<()> {
    let python = python
        .or_else(|| std::env::var_os("LINKAGE_CHOLMOD_PYTHON").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("python3"));
    let python = python.as_path();
    use linkage::bench::cholmod::{
        lattice_system, load_average, system_npz, time_direct, COMPARE_SCRIPT,
    };
    use linkage::linalg::ordering::{MetisOptions, SECOND_ORDERING};
    let sizes = if cells.is_empty() {
        vec![[20, 20, 40], [40, 40, 40]]
    } else {
        cells
    };
    let reps = reps.max(1);
    let dir = tempfile_dir("linkage-cholmod")?;
    let outcome = (|| -> Result<()> {
        let script = dir.join("cholmod_compare.py");
        linkage::scene::atomic_file::write_atomically(&script, COMPARE_SCRIPT.as_bytes())
            .with_context(|| format!("writing {}", script.display()))?;
        let load = |l: Option<f64>| l.map_or("?".to_string(), |l| format!("{l:.2}"));
        say!(
            "Direct solve of the same K_ff: ours (METIS on the node graph, faer, {} threads) \
             against CHOLMOD (scikit-sparse, METIS, supernodal), alternately, best of {reps}",
            rayon::current_num_threads()
        );
        say!("load average at start: {}", load(load_average()));
        say!(
            "{:<10} {:>3} {:>9} | {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} | {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} | {:>6} {:>5}",
            "cells", "rep", "free DOFs",
            "analyze", "factor", "solve", "total", "CPU", "resid",
            "analyze", "factor", "solve", "total", "CPU", "resid",
            "ratio", "load"
        );
        for c in sizes {
            let (system, _members) = lattice_system(c).map_err(anyhow::Error::msg)?;
            let file = dir.join(format!("system-{}x{}x{}.npz", c[0], c[1], c[2]));
            let bytes = system_npz(&system).context("encoding the system")?;
            linkage::scene::atomic_file::write_atomically(&file, &bytes)
                .with_context(|| format!("writing {}", file.display()))?;
            drop(bytes);
            let name = format!("{}x{}x{}", c[0], c[1], c[2]);
            let mut ours_best: Option<linkage::bench::cholmod::DirectTiming> = None;
            let mut theirs_best: Option<CholmodTiming> = None;
            let mut plain_best: Option<linkage::bench::cholmod::DirectTiming> = None;
            let mut fills = (0, None);
            for rep in 1..=reps {
                let ours =
                    time_direct(&system, Default::default(), true).map_err(anyhow::Error::msg)?;
                let theirs = run_cholmod(python, &script, &file, rep == 1)?;
                let plain =
                    time_direct(&system, Default::default(), false).map_err(anyhow::Error::msg)?;
                if rep == 1 {
                    fills = (ours.nnz_l, theirs.nnz_l);
                    if let Some(o) = ours.orderings {
                        let (first, second) = (MetisOptions::default(), SECOND_ORDERING);
                        let (kept, other) = match o.second_chosen {
                            true => (second, first),
                            false => (first, second),
                        };
                        say!(
                            "{name}: analysis: ordering {kept} kept, {:.4e} flops (nnz(L) {}) \
                             against {other}'s {:.4e} ({}) on the node graph; supernodal flops {}",
                            o.chosen.flops,
                            o.chosen.entries,
                            o.other.flops,
                            o.other.entries,
                            ours.flops.map_or("?".to_string(), |f| format!("{f:.4e}")),
                        );
                    }
                }
                say!(
                    "{:<10} {:>3} {:>9} | {:>7.3}s {:>7.3}s {:>7.3}s {:>7.3}s {:>6.2}s {:>8.1e} | {:>7.3}s {:>7.3}s {:>7.3}s {:>7.3}s {:>6.2}s {:>8.1e} | {:>6.3} {:>5}",
                    name, rep, system.n,
                    ours.analyze, ours.factor, ours.solve, ours.total(), ours.cpu, ours.residual,
                    theirs.analyze, theirs.factor, theirs.solve, theirs.total(), theirs.cpu, theirs.residual,
                    ours.total() / theirs.total(),
                    load(load_average())
                );
                say!(
                    "{:<10} {:>3} {:>9} | {:>7.3}s {:>7.3}s {:>7.3}s {:>7.3}s {:>6.2}s {:>8.1e} | faer's own supernode loop: {:.3} of CHOLMOD",
                    "", "", "",
                    plain.analyze, plain.factor, plain.solve, plain.total(), plain.cpu, plain.residual,
                    plain.total() / theirs.total(),
                );
                if ours.residual.max(plain.residual) > 1e-10 || theirs.residual > 1e-10 {
                    bail!(
                        "{name}: residual too large (ours {:.1e}, CHOLMOD {:.1e})",
                        ours.residual,
                        theirs.residual
                    );
                }
                if plain_best.is_none_or(|b| plain.total() < b.total()) {
                    plain_best = Some(plain);
                }
                if ours_best.is_none_or(|b| ours.total() < b.total()) {
                    ours_best = Some(ours);
                }
                if theirs_best
                    .as_ref()
                    .is_none_or(|b| theirs.total() < b.total())
                {
                    theirs_best = Some(theirs);
                }
            }
            if let (Some(p), Some(t)) = (plain_best, theirs_best.as_ref()) {
                say!(
                    "{name}: best with faer's own supernode loop {:.3} s (analyze {:.3} + factor {:.3} + solve {:.3}): ratio {:.3}",
                    p.total(), p.analyze, p.factor, p.solve, p.total() / t.total()
                );
            }
            if let (Some(o), Some(t)) = (ours_best, theirs_best) {
                say!(
                    "{name}: best ours {:.3} s (analyze {:.3} + factor {:.3} + solve {:.3}), \
                     best CHOLMOD {:.3} s (analyze {:.3} + factor {:.3} + solve {:.3}): \
                     ratio {:.3}; factor+solve alone {:.3}; nnz(L) ours {} CHOLMOD {}",
                    o.total(),
                    o.analyze,
                    o.factor,
                    o.solve,
                    t.total(),
                    t.analyze,
                    t.factor,
                    t.solve,
                    o.total() / t.total(),
                    (o.factor + o.solve) / (t.factor + t.solve),
                    fills.0,
                    fills.1.map_or("?".to_string(), |n| n.to_string()),
                );
            }
        }
        say!("load average at end: {}", load(load_average()));
        Ok(())
    })();
    let _ = std::fs::remove_dir_all(&dir);
    outcome
}

/// CHOLMOD's phases as `bench/cholmod_compare.py` reports them.
#[derive(serde::Deserialize)]
struct CholmodTiming {
    analyze: f64,
    factor: f64,
    solve: f64,
    cpu: f64,
    residual: f64,
    nnz_l: Option<usize>,
}

impl CholmodTiming {
    fn total(&self) -> f64 {
        self.analyze + self.factor + self.solve
    }
}

/// Runs the comparison script on one system file and reads its JSON line.
fn run_cholmod(python: &Path, script: &Path, file: &Path, fill: bool) -> Result<CholmodTiming> {
    let mut command = std::process::Command::new(python);
    command.arg(script).arg(file);
    if fill {
        command.arg("fill");
    }
    let output = command.output().with_context(|| {
        format!(
            "cannot start {} (pass a Python with scikit-sparse by --python or \
             LINKAGE_CHOLMOD_PYTHON; docs/PERFORMANCE.md says how to install it)",
            python.display()
        )
    })?;
    if !output.status.success() {
        bail!(
            "the CHOLMOD comparison failed ({}): {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&output.stdout);
    let line = text.lines().last().unwrap_or_default();
    serde_json::from_str(line)
        .with_context(|| format!("cannot read the CHOLMOD script's output {line:?}"))
}
