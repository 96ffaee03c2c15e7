//! The `linkage` command line: thin; it parses arguments and calls the library.

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use linkage::scene::{load_scene, run, Summary, World};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
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
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Scenes solved at once (default: the number of cores).
        #[arg(long)]
        jobs: Option<usize>,
    },
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
        /// Measure in this process instead of one child process per size (then the peak
        /// memory column is the running maximum).
        #[arg(long, hide = true)]
        in_process: bool,
    },
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let outcome = match cli.command {
        Command::Run { scenes, out, jobs } => run_scenes(&scenes, &out, jobs),
        Command::Check { scenes } => check_scenes(&scenes),
        Command::Export { scene, out } => export(&scene, &out),
        Command::Bench {
            cells,
            iterative,
            jacobi,
            in_process,
        } => bench(cells, iterative, jacobi, in_process),
    };
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn describe(world: &World) -> String {
    let nodes: usize = world.bodies.iter().map(|b| b.nodes.len()).sum();
    let members: usize = world.bodies.iter().map(|b| b.members.len()).sum();
    let patches: usize = world.bodies.iter().map(|b| b.patches.len()).sum();
    let dofs: usize = world.bodies.iter().map(|b| b.dof_count()).sum();
    format!(
        "{} bod{}, {nodes} nodes, {members} members, {patches} patches, {dofs} DOFs, {} step{}",
        world.bodies.len(),
        if world.bodies.len() == 1 { "y" } else { "ies" },
        world.steps,
        if world.steps == 1 { "" } else { "s" }
    )
}

fn run_scenes(scenes: &[PathBuf], out: &Path, jobs: Option<usize>) -> Result<()> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the output folder {}", out.display()))?;
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} steps {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    let one_scene = |path: &PathBuf| -> Result<(World, Summary, f64)> {
        let t = Instant::now();
        let world = load_scene(path)?;
        bar.inc_length(world.steps as u64 + 1);
        let summary = run(&world, out, &|| bar.inc(1))?;
        Ok((world, summary, t.elapsed().as_secs_f64()))
    };
    let work =
        || -> Vec<Result<(World, Summary, f64)>> { scenes.par_iter().map(one_scene).collect() };
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
    for (path, result) in scenes.iter().zip(results) {
        match result {
            Ok((world, summary, seconds)) => {
                if let Some((_, first)) = written.iter().find(|(n, _)| *n == world.name) {
                    println!(
                        "warn  {} and {} share the name '{}': {} holds whichever finished last",
                        first.display(),
                        path.display(),
                        world.name,
                        out.join(&world.name).display()
                    );
                }
                written.push((world.name.clone(), path.clone()));
                let last = summary.steps.last();
                println!(
                    "ok    {} -> {}: {}; {:.3} s; max |u| {:.4e} m; {} overloaded; residual {:.1e}",
                    path.display(),
                    out.join(&world.name).display(),
                    describe(&world),
                    seconds,
                    last.map_or(0.0, |s| s.max_displacement),
                    last.map_or(0, |s| s.overloaded),
                    summary.steps.iter().map(|s| s.residual).fold(0.0, f64::max),
                );
                let p = &summary.phases;
                println!(
                    "      phases: assembly {:.3} s, ordering+symbolic {:.3} s, factorization {:.3} s, solve {:.3} s, writing {:.3} s",
                    p.assembly, p.symbolic, p.numeric, p.solve, p.writing
                );
            }
            Err(e) => {
                failed += 1;
                // Errors name their file; prefix the scene when they name another one.
                let msg = e.to_string();
                if msg.starts_with(&path.display().to_string()) {
                    println!("FAIL  {msg}");
                } else {
                    println!("FAIL  {}: {msg}", path.display());
                }
            }
        }
    }
    if failed > 0 {
        bail!(
            "{failed} of {} scene{} failed",
            scenes.len(),
            if scenes.len() == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

fn check_scenes(scenes: &[PathBuf]) -> Result<()> {
    let mut failed = 0;
    for path in scenes {
        match load_scene(path) {
            Ok(world) => println!("ok    {}: {}", path.display(), describe(&world)),
            Err(e) => {
                failed += 1;
                println!("FAIL  {e}");
            }
        }
    }
    if failed > 0 {
        bail!(
            "{failed} of {} scene{} failed the check",
            scenes.len(),
            if scenes.len() == 1 { "" } else { "s" }
        );
    }
    Ok(())
}

fn export(scene: &Path, out: &Path) -> Result<()> {
    use linkage::linkage::paper_files::{write_links, write_nodes, write_patches};
    let world = load_scene(scene)?;
    std::fs::create_dir_all(out)
        .with_context(|| format!("cannot create the output folder {}", out.display()))?;
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
        println!(
            "wrote {}: {} nodes, {} members, {} patches",
            file("*").display(),
            body.nodes.len(),
            body.members.len(),
            body.patches.len()
        );
    }
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

fn bench(cells: Vec<[usize; 3]>, iterative: bool, jacobi: bool, in_process: bool) -> Result<()> {
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
    println!("3D box lattices: 26-neighbour cells, bottom face fixed, top face loaded; {what}");
    if iterative {
        println!("{}", linkage::bench::ITERATIVE_HEADER);
    } else {
        println!("{}", linkage::bench::HEADER);
    }
    for c in sizes {
        if in_process && iterative {
            let t = linkage::bench::measure_iterative(c, !jacobi).map_err(anyhow::Error::msg)?;
            println!("{}", linkage::bench::format_iterative_row(&t));
        } else if in_process {
            let t = linkage::bench::measure_lattice(c).map_err(anyhow::Error::msg)?;
            println!("{}", linkage::bench::format_row(&t));
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
                println!("{row}");
            }
        }
    }
    Ok(())
}
