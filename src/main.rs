//! The `linkage` command line: thin; it parses arguments and calls the library.

/// `println!` that never panics: a closed stdout (`linkage run ... | head -1`) drops the line,
/// and the command goes on to write its results in full, as it would with stdout open.
macro_rules! say {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($t)*);
    }};
}

mod batch_cli;
mod bench_cli;

use anyhow::{bail, Context, Result};
use bench_cli::{
    bench, bench_cholmod, bench_contact, bench_dynamics, bench_fracture, bench_gif, bench_large,
    bench_prepare, bench_read, bench_render, bench_run,
};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use linkage::linkage::Interrupt;
use linkage::render::{
    draw_with_shared_scale, Colouring, PictureWriter, Projection, RenderOptions, StepSelection,
    VariantPictures,
};
use linkage::scene::batch::{self, JobSettings, Ran, SlurmOptions};
use linkage::scene::load_scene;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

#[derive(Parser)]
#[command(
    name = "linkage",
    version,
    about = "Deformable bodies as linkage models (Ku & Ching 1991)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Solve scenes and write DIR/<scene>/summary.json and steps/NNNN.json.
    Run {
        /// Scene files (TOML).
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
        /// Output folder (created if missing; not a file).
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Scenes solved at once (default: the number of cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Also draw png/NNNN.png per stored step and anim.gif (as `[output] png = true`).
        #[arg(long)]
        png: bool,
        /// Write no anim.gif (PNG frames only), whatever the scenes' `[output]` asks.
        #[arg(long)]
        no_gif: bool,
        /// Also write vtk/NNNN.vtu per stored step and vtk/<scene>.pvd for ParaView.
        #[arg(long)]
        vtk: bool,
        /// Run only the I-th of N slices of the jobs (scenes and sweep variants), writing
        /// DIR/batch.part-I-of-N.csv; "slurm": I and N from the job array's variables.
        #[arg(long, value_name = "I/N|slurm")]
        shard: Option<String>,
        /// Run jobs whose complete results are already in DIR (they are skipped otherwise).
        #[arg(long)]
        rerun: bool,
    },
    // Batches: `collect` and `slurm` (sweeps and shards are options of `run`).
    /// Merge the shards' DIR/batch.part-I-of-N.csv into DIR/batch.csv; say which jobs are
    /// missing or failed.
    Collect {
        /// The --out folder of the sharded runs.
        dir: PathBuf,
    },
    /// Write DIR/linkage.sbatch, a Slurm job array whose tasks run the shards of SCENES, and
    /// DIR/linkage-collect.sbatch; print the sbatch commands.
    Slurm {
        /// Scene files (TOML).
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
        /// Output folder of the batch (and of the scripts).
        #[arg(long)]
        out: PathBuf,
        /// Array tasks (at most one per job; default: one per 8 jobs).
        #[arg(long)]
        tasks: Option<usize>,
        /// Wall-time limit per task, e.g. 01:00:00.
        #[arg(long)]
        time: Option<String>,
        /// Cores per task.
        #[arg(long, default_value_t = 1)]
        cpus_per_task: usize,
        /// Slurm partition.
        #[arg(long)]
        partition: Option<String>,
    },
    /// Draw a stored run again (png/NNNN.png, replacing the frames in png/; anim.gif; --vtk for
    /// ParaView files) without solving.
    Render(RenderArgs),
    /// Check scenes without solving and print model sizes.
    Check {
        /// Scene files (TOML).
        #[arg(required = true)]
        scenes: Vec<PathBuf>,
    },
    /// Write each body of a scene (generated or read) as the paper's files:
    /// DIR/<body>.nodes, DIR/<body>.links (with a material column) and DIR/<body>.patches.
    Export {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Write what a model file reads as (a gmsh .msh, an Abaqus/CalculiX .inp, or a scene
    /// whose bodies have `model =`) as the paper's files and a scene DIR/<stem>.toml, to see
    /// and edit.
    Import {
        /// A .msh (MSH 4.1), .inp or scene .toml file.
        input: PathBuf,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Prepare a body from a closed OBJ/STL mesh (3D) or an outline file (2D): write
    /// DIR/<stem>.nodes, .links (and .patches) and print the quality report.
    Prepare {
        /// A closed triangle mesh (.stl, .obj) or an outline (one "x y" per line, loops
        /// separated by a blank line; the first the outside, the others holes), m.
        input: PathBuf,
        /// Target member length, m.
        #[arg(long)]
        spacing: f64,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
    },
    /// Time assembly, ordering, factorization and solve on 3D box lattices.
    Bench {
        /// Lattice sizes in cells, e.g. 20x20x40 (default: a series up to over 1,000,000 members).
        #[arg(long = "cells", value_parser = parse_cells)]
        cells: Vec<[usize; 3]>,
        /// Solve with conjugate gradients and smoothed-aggregation multigrid instead of the
        /// direct solver.
        #[arg(long)]
        iterative: bool,
        /// With --iterative: precondition with block Jacobi instead of multigrid.
        #[arg(long, requires = "iterative")]
        jacobi: bool,
        /// With --large --iterative: start every conjugate-gradient solve from zero (to
        /// measure what warm starts save).
        #[arg(long, requires = "iterative")]
        cold: bool,
        /// Measure in this process instead of one child process per size (then the peak
        /// memory column is the running maximum).
        #[arg(long, hide = true)]
        in_process: bool,
        /// Large displacements instead: Newton iterations per step and time per iteration on
        /// a slender column lattice bent by a side force (default 16x16x150 cells, 520k members).
        #[arg(long)]
        large: bool,
        /// With --large: total side force, N (default: 2.5e5, bending the default column by about 40 % of its length).
        #[arg(long)]
        force: Option<f64>,
        /// With --large: load steps (default 5); with --contact: contact steps (default 2);
        /// with --dynamics: time steps (default 20, 3 of them before the lattice touches).
        #[arg(long)]
        steps: Option<usize>,
        /// Run a box lattice's scene end to end through `linkage run` instead (default
        /// 49x49x49 cells: 125,000 nodes, 1,558,396 members, read from the paper's files,
        /// multigrid solver): its phases (read, assemble, set-up, solve, write), wall time and
        /// the run's peak memory.
        #[arg(long)]
        run: bool,
        /// Time reading the paper's files (nodes, links, patches) of a box lattice instead
        /// (default 49x49x49 cells: 125,000 nodes, 1,558,396 members), best of 3.
        #[arg(long)]
        read: bool,
        /// Contact instead: a box lattice on a fixed floor pressed by a ball obstacle (default
        /// 45x45x45 cells, 1.2M members), solved iteratively (--direct: by the direct solver);
        /// model size, phases, time per contact step, peak memory.
        #[arg(long)]
        contact: bool,
        /// With --contact: solve the lattice with the direct solver.
        #[arg(long, requires = "contact")]
        direct: bool,
        /// Fracture instead: members of a 3D lattice (default 20x20x20 cells, 108,860 members)
        /// breaking one after another with the factorization kept and corrected, against one
        /// factorization and against refactoring at every break.
        #[arg(long)]
        fracture: bool,
        /// With --fracture: members to break (default 1000).
        #[arg(long, requires = "fracture")]
        breaks: Option<usize>,
        /// The direct solver against CHOLMOD instead: each lattice's K_ff (default 20x20x40 and
        /// 40x40x40 cells) ordered, factored and solved by ours and by CHOLMOD (scikit-sparse,
        /// METIS) alternately on the same matrix; prints both and the ratio.
        #[arg(long)]
        cholmod: bool,
        /// With --cholmod: repetitions of each side (the best counts).
        #[arg(long, requires = "cholmod", default_value_t = 3)]
        reps: usize,
        /// With --cholmod: the Python with numpy, scipy and scikit-sparse (default: the
        /// environment variable LINKAGE_CHOLMOD_PYTHON, else python3). With --dynamics: the
        /// Python with openseespy (default: LINKAGE_OPENSEES_PYTHON, else the venv
        /// target/opensees-venv next to this executable; without one OpenSees is not run).
        #[arg(long)]
        python: Option<PathBuf>,
        /// Dynamics instead, two benchmarks in one run: a 3D box lattice with density
        /// (default 20x20x20 cells, 108,860 members) dropped on a floor with contact
        /// (energy-momentum; model size, time per time step, steps per second, phases), then
        /// our Newmark against OpenSees on a 200x10-cell 2D cantilever (time per step of both,
        /// their ratio and the agreement of the tip histories to 1e-6).
        #[arg(long)]
        dynamics: bool,
        /// With --dynamics: a CI-size run (a 5x5x5-cell lattice, 8 time steps; the 10x1-cell
        /// cantilever).
        #[arg(long, requires = "dynamics")]
        quick: bool,
        /// Time drawing one frame of a shaded shell instead (see --patches, --size).
        #[arg(long)]
        render: bool,
        /// Time the GIF of a results folder's frames instead: a palette per frame (NeuQuant,
        /// as before) against one palette for the run encoded in parallel, same frames.
        #[arg(long, value_name = "DIR")]
        gif: Option<PathBuf>,
        /// Time preparing a body of over 1,000,000 members from a torus mesh instead
        /// (isosurface stuffing): time and peak memory.
        #[arg(long)]
        prepare: bool,
        /// With --render: surface patches of the shell.
        #[arg(long, default_value_t = 100_000)]
        patches: usize,
        /// With --render: frame size WIDTHxHEIGHT.
        #[arg(long, default_value = "1920x1080", value_parser = parse_size)]
        size: [u32; 2],
    },
}

#[derive(clap::Args)]
struct RenderArgs {
    /// A results folder written by `linkage run` (DIR/<scene name>).
    dir: PathBuf,
    /// Write png/, anim.gif, plots/ (and vtk/) into this folder instead of the results folder
    /// (created if missing; its png/ then holds the frames of this drawing only). Without it
    /// the report (index.html) of the batch folder holding DIR is written again too.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Frame width, pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    /// Frame height, pixels.
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Camera azimuth about +y, degrees from +z towards +x (default: 0 in 2D, 35 in 3D).
    #[arg(long, allow_hyphen_values = true)]
    azimuth: Option<f64>,
    /// Camera elevation, degrees (default: 0 in 2D, 25 in 3D).
    #[arg(long, allow_hyphen_values = true)]
    elevation: Option<f64>,
    /// Zoom over the view that fits the whole run.
    #[arg(long, default_value_t = 1.0)]
    zoom: f64,
    /// "orthographic" or "perspective" (default: orthographic in 2D, perspective in 3D).
    #[arg(long)]
    projection: Option<Projection>,
    /// Displacement magnification (default: automatic, 1 unless displacements are tiny).
    #[arg(long)]
    magnification: Option<f64>,
    /// "stress" (compression blue, tension red; 3D surfaces by the mean member stress at each
    /// node), "max-stress" (3D surfaces by the largest member stress at each node) or "plain".
    #[arg(long, default_value = "stress")]
    colour: Colouring,
    /// Draw the members over 3D surfaces.
    #[arg(long)]
    wireframe: bool,
    /// Steps to draw: "all", "last" or numbers and ranges like 0,3,5-8.
    #[arg(long, default_value = "all")]
    steps: StepSelection,
    /// Samples per pixel side for shaded surfaces (1-4).
    #[arg(long, default_value_t = 2)]
    supersampling: u32,
    /// Do not write PNG frames.
    #[arg(long)]
    no_png: bool,
    /// Do not write anim.gif.
    #[arg(long)]
    no_gif: bool,
    /// Also write the ParaView files (vtk/NNNN.vtu, vtk/<scene>.pvd).
    #[arg(long)]
    vtk: bool,
    /// With --vtk: write the arrays as ASCII text instead of compressed binary.
    #[arg(long, requires = "vtk")]
    vtk_ascii: bool,
    /// Also write anim.glb, the glTF 2.0 animation of the stored steps (Blender: File >
    /// Import > glTF 2.0).
    #[arg(long)]
    gltf: bool,
}

fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let bad = || format!("{s:?}: give the frame size as WIDTHxHEIGHT, e.g. 1920x1080");
    let (w, h) = s.split_once('x').ok_or_else(bad)?;
    Ok([w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?])
}

fn parse_cells(s: &str) -> Result<[usize; 3], String> {
    let parts: Vec<&str> = s.split('x').collect();
    let bad = || format!("{s:?}: give the cells as NXxNYxNZ, e.g. 20x20x40");
    if parts.len() != 3 {
        return Err(bad());
    }
    let mut out = [0; 3];
    for (o, p) in out.iter_mut().zip(parts) {
        *o = p.parse().map_err(|_| bad())?;
        if *o == 0 {
            return Err(bad());
        }
    }
    Ok(out)
}

/// Set by SIGINT or SIGTERM: every run stops where it is (between Newton and contact
/// iterations, fracture events, steps, frames and writers; see `Interrupt`) and removes its
/// staging folder; jobs not started do not start. A second signal exits at once (the next run
/// removes the staging folders that leaves).
static STOP: AtomicBool = AtomicBool::new(false);

/// Exit status of a run stopped by a signal: 128 + SIGINT, as shells report an interrupted
/// command, for SIGTERM too (the handler does not tell them apart).
const INTERRUPTED: u8 = 130;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Run {
            scenes,
            out,
            jobs,
            png,
            no_gif,
            vtk,
            shard,
            rerun,
        } => run_scenes(
            &scenes,
            &out,
            jobs,
            shard.as_deref(),
            JobSettings {
                png,
                no_gif,
                vtk,
                rerun,
            },
        ),
        Command::Collect { dir } => batch_cli::collect(&dir),
        Command::Slurm {
            scenes,
            out,
            tasks,
            time,
            cpus_per_task,
            partition,
        } => batch_cli::slurm(
            &scenes,
            &out,
            SlurmOptions {
                tasks,
                time,
                cpus_per_task,
                partition,
            },
        ),
        Command::Check { scenes } => check_scenes(&scenes),
        Command::Export { scene, out } => export(&scene, &out),
        Command::Import { input, out } => import(&input, &out),
        Command::Prepare {
            input,
            spacing,
            out,
        } => prepare(&input, spacing, &out),
        Command::Render(args) => render(&args),
        Command::Bench { gif: Some(dir), .. } => bench_gif(&dir),
        Command::Bench {
            read: true, cells, ..
        } => bench_read(cells),
        Command::Bench {
            run: true, cells, ..
        } => bench_run(cells),
        Command::Bench { prepare: true, .. } => bench_prepare(),
        Command::Bench {
            cholmod: true,
            cells,
            reps,
            python,
            ..
        } => bench_cholmod(cells, reps, python),
        Command::Bench {
            render: true,
            patches,
            size,
            ..
        } => bench_render(patches, size),
        Command::Bench {
            cells,
            fracture: true,
            breaks,
            ..
        } => bench_fracture(cells, breaks),
        Command::Bench {
            cells,
            dynamics: true,
            steps,
            quick,
            python,
            ..
        } => bench_dynamics(cells, steps, quick, python),
        Command::Bench {
            cells,
            contact: true,
            steps,
            direct,
            ..
        } => bench_contact(cells, steps, direct),
        Command::Bench {
            cells,
            large: true,
            force,
            steps,
            iterative,
            cold,
            ..
        } => bench_large(cells, force, steps, iterative, cold),
        Command::Bench {
            cells,
            iterative,
            jacobi,
            in_process,
            ..
        } => bench(cells, iterative, jacobi, in_process),
    };
    let interrupted = STOP.load(Ordering::SeqCst);
    match outcome {
        Ok(()) if interrupted => ExitCode::from(INTERRUPTED),
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            if interrupted {
                ExitCode::from(INTERRUPTED)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// Make SIGINT and SIGTERM stop the runs cleanly (see [`STOP`]); without a handler the runs
/// could not clean up, so say so and go on.
fn catch_signals() {
    // The handler runs on ctrlc's own thread, not in signal context, so it may print.
    if let Err(e) = ctrlc::set_handler(|| {
        if STOP.swap(true, Ordering::SeqCst) {
            // At once: `_exit` runs no exit handlers and flushes nothing that the other
            // threads, still solving or writing, may be using.
            // SAFETY: `_exit` only ends the process; it has no preconditions.
            unsafe { libc::_exit(i32::from(INTERRUPTED)) };
        }
        eprintln!(
            "interrupted: stopping now; no results of unfinished runs are kept (earlier results stay as they were); again to quit at once"
        );
    }) {
        eprintln!("warning: cannot catch SIGINT/SIGTERM ({e}): an interrupted run may leave a staging folder, removed by the next run");
    }
}

/// Create the folder `--out` names (and its parents); a path that is a file, or lies under
/// one, is refused with a message saying `--out` must be a folder.
fn create_out_folder(out: &Path) -> Result<()> {
    if let Some(file) = out.ancestors().find(|p| p.is_file()) {
        if file == out {
            bail!(
                "--out {}: is a file; --out must be a folder (it is created if missing)",
                out.display()
            );
        }
        bail!(
            "--out {}: {} is a file; --out must be a folder (it is created if missing)",
            out.display(),
            file.display()
        );
    }
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the output folder {}", out.display()))
}

fn run_scenes(
    scenes: &[PathBuf],
    out: &Path,
    jobs: Option<usize>,
    shard: Option<&str>,
    settings: JobSettings,
) -> Result<()> {
    catch_signals();
    let shard = shard.map(batch::Shard::parse).transpose()?;
    // Every sweep is expanded (and a wrong key named) before anything runs.
    let planned = batch::plan_jobs(scenes)?;
    create_out_folder(out)?;
    batch::write_variant_lists(&planned, out)?;
    if shard.is_some() {
        batch::write_job_list(&planned, out)?;
    }
    let mine: Vec<&batch::Job> = planned
        .iter()
        .enumerate()
        .filter(|(j, _)| shard.is_none_or(|s| s.takes(*j)))
        .map(|(_, job)| job)
        .collect();
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} steps {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let on_start = |world: &linkage::scene::World| {
        // Said before the run starts, so a user can stop it before it fills the disk.
        // The scene's own warnings (a far `nearest` point, a load on held directions) too.
        for w in world
            .warnings
            .iter()
            .cloned()
            .chain(linkage::scene::output_warning(world))
        {
            bar.suspend(|| eprintln!("warn  {}: {w}", world.name));
        }
        bar.inc_length(world.steps as u64 + 1);
    };
    let one_job = |job: &&batch::Job| {
        batch::run_job(
            job,
            out,
            settings,
            Some(&PictureWriter),
            &on_start,
            &|| bar.inc(1),
            Interrupt::on(&STOP),
        )
    };
    let work = || -> Vec<(Ran, batch::Row)> { mine.par_iter().map(one_job).collect() };
    let results = match jobs {
        Some(0) => bail!("--jobs 0: give 1 or more"),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .context("cannot start the worker threads")?
            .install(work),
        None => work(),
    };
    bar.finish_and_clear();
    let mut failed = 0;
    let mut written: Vec<(String, PathBuf)> = Vec::new();
    let mut rows = Vec::with_capacity(results.len());
    // The drawn variants of each sweep, redrawn below with one scale for all of them.
    let mut variants: Vec<(String, VariantPictures)> = Vec::new();
    for (job, (ran, row)) in mine.iter().zip(results) {
        rows.push(row);
        let path = &job.scene;
        let shown = match job.variant {
            Some(k) => format!("{} [{k}]", path.display()),
            None => path.display().to_string(),
        };
        if let (Some(_), Ran::Solved { world, .. } | Ran::Drawn { world }) = (job.variant, &ran) {
            let p = &world.pictures;
            if p.png || p.gif || p.gltf {
                variants.push((
                    job.name.clone(),
                    VariantPictures {
                        dir: job.folder(out),
                        options: RenderOptions {
                            step_fraction: world.plots.step_fraction,
                            ..RenderOptions::from_settings(p)
                        },
                        gltf: p.gltf,
                    },
                ));
            }
        }
        match ran {
            Ran::Drawn { .. } => say!(
                "drew  {shown} -> {}: from the complete results there, without solving (--rerun solves it again)",
                job.folder(out).display()
            ),
            Ran::Skipped => say!(
                "skip  {shown} -> {}: complete results there (--rerun runs it again)",
                job.folder(out).display()
            ),
            Ran::Solved {
                world,
                summary,
                seconds,
            } => {
                if let Some((_, first)) = written.iter().find(|(n, _)| *n == job.id()) {
                    say!(
                        "warn  {} and {} share the name '{}': {} holds whichever finished last",
                        first.display(),
                        path.display(),
                        world.name,
                        job.folder(out).display()
                    );
                }
                written.push((job.id(), path.clone()));
                let last = summary.steps.last();
                say!(
                    "ok    {shown} -> {}: {}; {:.3} s; max |u| {:.4e} m; {} overloaded; residual {:.1e}",
                    job.folder(out).display(),
                    world.describe_solved(summary.bodies.iter().map(|b| b.free_dofs).sum()),
                    seconds,
                    last.map_or(0.0, |s| s.max_displacement),
                    last.map_or(0, |s| s.overloaded),
                    summary.steps.iter().map(|s| s.residual).fold(0.0, f64::max),
                );
                let p = &summary.phases;
                say!(
                    "      phases: reading {:.3} s, assembly {:.3} s, ordering+symbolic {:.3} s, factorization {:.3} s, solve {:.3} s, contact_query {:.3} s, writing {:.3} s, drawing {:.3} s",
                    p.reading, p.assembly, p.symbolic, p.numeric, p.solve, p.contact_query, p.writing, p.drawing
                );
                // The summary's warnings (deep penetration, an unsettled contact set) matter
                // enough to show here, not only in summary.json.
                for step in &summary.steps {
                    for w in &step.warnings {
                        say!("warn  {}: {w}", world.name);
                    }
                }
                let teeth = summary.breaks.iter().filter(|b| b.tooth.is_some()).count();
                if summary.breaks.len() > teeth {
                    say!("      {} member(s) broke", summary.breaks.len() - teeth);
                }
                if teeth > 0 {
                    say!("      {teeth} softening tooth/teeth passed");
                }
                if let Some(c) = &summary.collapse {
                    // The collapse state is written as the last step when it is known.
                    let last = summary.steps.last().filter(|l| l.collapse).map_or_else(
                        || format!("steps 0-{} written", c.step.saturating_sub(1)),
                        |l| format!("steps 0-{} written, the last the state it collapsed in", l.step),
                    );
                    say!(
                        "      collapse: body '{}' at step {} (load factor {}): breaking member {} left its supported part a mechanism; {last}",
                        c.body, c.step, c.load_factor, c.member
                    );
                }
            }
            Ran::Failed(msg) => {
                failed += 1;
                // Errors name their file; prefix the scene when they name another one.
                if msg.starts_with(&path.display().to_string()) {
                    say!("FAIL  {msg}");
                } else {
                    say!("FAIL  {shown}: {msg}");
                }
            }
        }
    }
    // Each sweep's variants drawn again with one magnification and one colour range.
    let mut sweeps: Vec<&str> = Vec::new();
    for (name, _) in &variants {
        if !sweeps.contains(&name.as_str()) {
            sweeps.push(name);
        }
    }
    for name in sweeps {
        let group: Vec<VariantPictures> = variants
            .iter()
            .filter(|(n, _)| n == name)
            .map(|(_, v)| v.clone())
            .collect();
        match draw_with_shared_scale(&group, Interrupt::on(&STOP)) {
            Ok(Some(scale)) => say!("scale {name}: {}", scale.describe()),
            Ok(None) => {}
            Err(e) => {
                failed += 1;
                say!("FAIL  {name}: drawing the variants with one scale: {e}");
            }
        }
    }
    let table = out.join(match shard {
        Some(s) => s.part_name(),
        None => batch::TABLE.to_string(),
    });
    batch::write_table(&table, &rows)?;
    // A shard's rows are part of the batch: `linkage collect` writes the report of all.
    if shard.is_none() && (settings.png || linkage::render::report::has_pictures(out, &rows)) {
        let page = linkage::render::report::write_report(out, &rows)
            .with_context(|| format!("cannot write the report in {}", out.display()))?;
        say!("report {}", page.display());
    }
    if failed > 0 {
        let noun = if mine.iter().any(|j| j.variant.is_some()) {
            "job"
        } else {
            "scene"
        };
        bail!(
            "{failed} of {} {noun}{} failed",
            mine.len(),
            if mine.len() == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

fn check_scenes(scenes: &[PathBuf]) -> Result<()> {
    let mut failed = 0;
    // Every variant of a sweep is checked as it would run.
    let jobs = batch::plan_jobs(scenes)?;
    for job in &jobs {
        let path = &job.scene;
        let checked = match job.variant {
            None => load_scene(path).map_err(anyhow::Error::from),
            Some(_) => job
                .text
                .as_deref()
                .map_err(|e| anyhow::anyhow!("{e}"))
                .and_then(|text| {
                    linkage::scene::build_world(text, path)
                        .map_err(|e| anyhow::anyhow!(job.describe_error(&e.to_string())))
                }),
        }
        .and_then(|world| Ok(linkage::scene::check_world(&world)?));
        let shown = match job.variant {
            Some(k) => PathBuf::from(format!("{} [{k}]", path.display())),
            None => path.clone(),
        };
        match checked {
            Ok(report) => print_check(&shown, &report),
            Err(e) => {
                failed += 1;
                // As `linkage run` prints it: errors name their file; prefix the scene when
                // they name another one.
                let msg = e.to_string();
                if msg.starts_with(&path.display().to_string()) {
                    say!("FAIL  {msg}");
                } else {
                    say!("FAIL  {}: {msg}", shown.display());
                }
            }
        }
    }
    if failed > 0 {
        bail!(
            "{failed} of {} scene{} failed the check",
            jobs.len(),
            if jobs.len() == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

/// The report of one scene that passed `linkage check`: its size, per body its sizes and
/// solver, what only a run can tell, and warnings.
fn print_check(path: &Path, report: &linkage::scene::CheckReport) {
    say!("ok    {}: {}", path.display(), report.describe);
    for b in &report.bodies {
        say!(
            "      body '{}': {}D, {} nodes, {} members, {} patches, {} free DOFs, {} solver",
            b.name,
            b.dimension,
            b.nodes,
            b.members,
            b.patches,
            b.free_dofs,
            b.solver
        );
    }
    for f in &report.found {
        say!("      found: {f}");
    }
    for s in &report.solids {
        say!("      solid: {s}");
    }
    for note in &report.notes {
        say!("      not checked: {note}");
    }
    for w in &report.warnings {
        say!("warn  {}: {w}", path.display());
    }
}

fn prepare(input: &Path, spacing: f64, out: &Path) -> Result<()> {
    catch_signals();
    let body = linkage::scene::prepare_file(input, spacing, Interrupt::on(&STOP))
        .map_err(anyhow::Error::msg)?;
    create_out_folder(out)?;
    let stem = input
        .file_stem()
        .map_or("body".into(), |s| s.to_string_lossy().into_owned());
    let written = linkage::scene::write_prepared(out, &stem, &body)
        .with_context(|| format!("cannot write the prepared body into {}", out.display()))?;
    for path in written {
        say!("wrote {}", path.display());
    }
    say!("{}", body.report);
    // The lattice as a solid, for members of E A = 1 N: its moduli scale with E A.
    if body.geometry.dimension == linkage::linkage::Dimension::Three {
        let unit = linkage::linkage::Body::from_geometry(
            &stem,
            body.geometry.clone(),
            linkage::linkage::Material::new("unit", 1.0, 1.0),
        );
        match linkage::linkage::homogenize::effective_elasticity(&unit, body.report.reference) {
            Ok(s) => say!(
                "as a solid (uniaxial tests of the lattice): Young's modulus {:.4e} × E A per m² (x {:.4e}, y {:.4e}, z {:.4e}), Poisson's ratio {:.3}: for a solid of modulus E_c give members of modulus E the area E_c / (E × {:.4e}), or continuum_modulus = E_c",
                s.youngs_modulus,
                s.youngs_moduli[0],
                s.youngs_moduli[1],
                s.youngs_moduli[2],
                s.poisson_ratio,
                s.youngs_modulus
            ),
            Err(e) => say!("as a solid: {e}"),
        }
    }
    Ok(())
}

fn import(input: &Path, out: &Path) -> Result<()> {
    create_out_folder(out)?;
    let imported = linkage::scene::import::import_file(input, out)?;
    for path in &imported.files {
        println!("wrote {}", path.display());
    }
    for w in &imported.warnings {
        println!("warning: {w}");
    }
    if imported.complete {
        println!("run it: linkage run {}", imported.scene.display());
    } else {
        println!(
            "{} needs a material and supports before it runs: edit it (its groups are listed at the end), or give `linkage import` a scene whose body has model = {:?}",
            imported.scene.display(),
            input.file_name().unwrap_or_default()
        );
    }
    Ok(())
}

fn export(scene: &Path, out: &Path) -> Result<()> {
    use linkage::scene::paper_files::{write_links, write_nodes, write_patches};
    let world = load_scene(scene)?;
    create_out_folder(out)?;
    for body in &world.bodies {
        let file = |ext: &str| out.join(format!("{}.{ext}", body.name));
        let members: Vec<[usize; 2]> = body.members.iter().map(|m| m.nodes).collect();
        let names: Vec<String> = body
            .members
            .iter()
            .map(|m| body.materials[m.material].name.clone())
            .collect();
        let path = file("nodes");
        write_nodes(&path, body.dimension, &body.nodes)
            .with_context(|| format!("cannot write {}", path.display()))?;
        let path = file("links");
        write_links(&path, &members, Some(&names))
            .with_context(|| format!("cannot write {}", path.display()))?;
        if !body.patches.is_empty() {
            let path = file("patches");
            write_patches(&path, &body.patches)
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        say!(
            "wrote {}: {} nodes, {} members, {} patches",
            file("*").display(),
            body.nodes.len(),
            body.members.len(),
            body.patches.len()
        );
    }
    Ok(())
}

fn render(a: &RenderArgs) -> Result<()> {
    use linkage::render::gltf::write_gltf;
    use linkage::render::{draw_read_run_to, read_run_to_render, stored_time, RenderOptions};
    use linkage::scene::{write_vtk, VtkEncoding};
    catch_signals();
    // A published results folder always has its summary: without it the folder is not one.
    let summary = a.dir.join("summary.json");
    if !summary.is_file() {
        bail!(
            "{}: no summary.json: give a results folder written by `linkage run SCENE --out DIR` (DIR/<scene name>)",
            a.dir.display()
        );
    }
    let options = RenderOptions {
        width: a.width,
        height: a.height,
        azimuth: a.azimuth,
        elevation: a.elevation,
        zoom: a.zoom,
        projection: a.projection,
        magnification: a.magnification,
        colouring: a.colour,
        wireframe: a.wireframe,
        steps: a.steps.clone(),
        png: !a.no_png,
        gif: !a.no_gif,
        supersampling: a.supersampling,
        interrupt: Interrupt::on(&STOP),
        // Read from the results folder's plot settings by `draw_read_run_to`.
        step_fraction: false,
        // A sweep variant's shared scale is read from its folder by `render_run_to`.
        shared: None,
    };
    let out = a.out.clone().unwrap_or_else(|| a.dir.clone());
    if a.out.is_some() {
        create_out_folder(&out)?;
    }
    let t = Instant::now();
    // The stored steps are read once: the frames, the GLB, the VTK files, the plots and the
    // report's 3D view are all made from this reading.
    let run = read_run_to_render(&a.dir, &options)?;
    let report = draw_read_run_to(&run, &a.dir, &out, &options)?;
    let seconds = t.elapsed().as_secs_f64();
    if options.png || options.gif {
        say!(
            "drew {} step{} of {} in {:.2} s (displacements ×{}): {} PNG frame{} in {}{}",
            report.steps.len(),
            if report.steps.len() == 1 { "" } else { "s" },
            a.dir.display(),
            seconds,
            report.magnification,
            report.frames.len(),
            if report.frames.len() == 1 { "" } else { "s" },
            out.join("png").display(),
            report
                .gif
                .as_ref()
                .map(|g| format!(", {}", g.display()))
                .unwrap_or_default()
        );
    }
    if a.gltf {
        let g = write_gltf(&run, &out, report.magnification, stored_time)?;
        println!(
            "wrote {} ({} frame{} of {} stored step{}{}, displacements ×{})",
            g.path.display(),
            g.frames,
            if g.frames == 1 { "" } else { "s" },
            g.stored_steps,
            if g.stored_steps == 1 { "" } else { "s" },
            if g.frames < g.stored_steps {
                ": evenly spaced, the first and last kept"
            } else {
                ""
            },
            report.magnification
        );
    }
    if a.vtk {
        let encoding = if a.vtk_ascii {
            VtkEncoding::Ascii
        } else {
            VtkEncoding::Binary
        };
        let files = write_vtk(&run, &out, encoding, Interrupt::on(&STOP))?;
        say!(
            "wrote {} ParaView files in {}",
            files.len(),
            out.join("vtk").display()
        );
    }
    // The plots too, with the settings the run kept; the report when the folder is a job of
    // a batch folder and is drawn in place.
    let plots = linkage::render::redraw_plots_of(&a.dir, &out, &run)?;
    say!(
        "drew {} plot{} in {}",
        plots.len(),
        if plots.len() == 1 { "" } else { "s" },
        out.join(linkage::render::plots::PLOTS).display()
    );
    if a.out.is_none() {
        if let Some(page) = linkage::render::redraw_report_of(&a.dir, Some(&run))? {
            say!("report {}", page.display());
        }
    }
    Ok(())
}
