//! The pictures of a whole run: PNG frames and the GIF of its stored steps, drawn from its
//! results in memory (during `linkage run`) or read back from a results folder (`linkage render`).

use crate::render::gif::LAST_FRAME_DELAY;
use crate::render::gltf::write_gltf;
use crate::render::{
    draw_frame, stored_time, timed_delays, Frame, GifAnimation, RenderError, RenderOptions,
    RunExtent, SharedScale, StepSelection,
};
use crate::scene::atomic_file::write_atomically;
use crate::scene::publish::{publish_keeping, remove_stale, staging_dir};
use crate::scene::MIN_STEP_DIGITS;
use crate::scene::{DrawResults, PlotSettings, RunResults, StoredRun, World};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// What [`render_run`] wrote.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderReport {
    /// Steps drawn.
    pub steps: Vec<usize>,
    /// PNG frames written.
    pub frames: Vec<PathBuf>,
    /// The GIF, if written.
    pub gif: Option<PathBuf>,
    /// Displacement magnification used.
    pub magnification: f64,
    /// A dynamic run's GIF plays at its stored times slowed down this many times (1: real
    /// time; see [`crate::render::timed_delays`]); `None` for a quasi-static run or without
    /// GIF (fixed 0.5 s per frame).
    pub gif_slowdown: Option<f64>,
}

/// The stored steps `selection` picks from `run`.
pub fn select_steps(run: &StoredRun, selection: &StepSelection) -> Result<Vec<usize>, RenderError> {
    pick_steps(&run.steps, &run.dir, selection)
}

/// The steps `selection` picks from the `stored` ones of the results folder `dir`.
fn pick_steps(
    stored: &[usize],
    dir: &Path,
    selection: &StepSelection,
) -> Result<Vec<usize>, RenderError> {
    Ok(match selection {
        StepSelection::All => stored.to_vec(),
        StepSelection::Last => stored.last().copied().into_iter().collect(),
        StepSelection::List(list) => {
            for &k in list {
                if !stored.contains(&k) {
                    return Err(RenderError::NoSuchStep {
                        step: k,
                        dir: dir.to_path_buf(),
                        stored: stored_list(stored),
                    });
                }
            }
            list.clone()
        }
    })
}

fn stored_list(steps: &[usize]) -> String {
    if steps.len() > 12 {
        format!(
            "{} steps from {} to {}",
            steps.len(),
            steps[0],
            steps[steps.len() - 1]
        )
    } else {
        steps
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Draw the stored run in `dir` (`DIR/<scene>`): `png/NNNN.png` per selected step and
/// `anim.gif` of them, as `options` ask; each file is written atomically. The camera, the
/// magnification, the force scale and the colour range are fixed over all stored steps.
pub fn render_run(dir: &Path, options: &RenderOptions) -> Result<RenderReport, RenderError> {
    render_run_to(dir, dir, options)
}

/// Draw the stored run in `dir` as [`render_run`] does, writing `out/png/NNNN.png` and
/// `out/anim.gif` instead (`out` is created if missing; its `png/` then holds this drawing's
/// frames only).
pub fn render_run_to(
    dir: &Path,
    out: &Path,
    options: &RenderOptions,
) -> Result<RenderReport, RenderError> {
    let run = read_run_to_render(dir, options)?;
    draw_read_run_to(&run, dir, out, options)
}

/// The stored run in `dir` read once for drawing (and for whatever else `linkage render`
/// writes of it: the GLB, the VTK files, the plots and the report's 3D view), after
/// `options` and its step selection are checked; stops between step files when
/// `options.interrupt` is raised.
pub fn read_run_to_render(dir: &Path, options: &RenderOptions) -> Result<RunResults, RenderError> {
    options.check()?;
    let stored = StoredRun::open(dir)?;
    // The selection is checked before the steps are read.
    select_steps(&stored, &options.steps)?;
    Ok(stored.read_all_until(options.interrupt)?)
}

/// Draw `run`, read from the results folder `dir` ([`read_run_to_render`]), into `out` as
/// [`render_run_to`] does (with the plot settings `dir` kept).
pub fn draw_read_run_to(
    run: &RunResults,
    dir: &Path,
    out: &Path,
    options: &RenderOptions,
) -> Result<RenderReport, RenderError> {
    // A sweep variant's frames keep the scale the sweep's variants share, unless another
    // magnification is asked for.
    let shared = match (&options.shared, options.magnification) {
        (Some(s), _) => Some(s.clone()),
        (None, None) => SharedScale::read(dir),
        (None, Some(_)) => None,
    };
    let options = &RenderOptions {
        step_fraction: options.step_fraction || PlotSettings::read(dir).step_fraction,
        shared,
        ..options.clone()
    };
    if out != dir {
        std::fs::create_dir_all(out).map_err(|source| RenderError::Write {
            path: out.to_path_buf(),
            source,
        })?;
    }
    draw_run(run, out, options)
}

/// Draw `run` into the folder `dir` as [`render_run`] does: `png/NNNN.png` per step
/// `options.steps` selects and `anim.gif` of them, as `options` ask (with the scale of
/// `options.shared` when given).
pub fn draw_run(
    run: &RunResults,
    dir: &Path,
    options: &RenderOptions,
) -> Result<RenderReport, RenderError> {
    options.check()?;
    let steps = pick_steps(&run.step_numbers(), dir, &options.steps)?;
    let extent = match &options.shared {
        Some(scale) => scale.extent_of(run),
        None => RunExtent::of_run(run, options.magnification),
    };
    let report = RenderReport {
        steps: steps.clone(),
        magnification: extent.magnification,
        ..RenderReport::default()
    };
    if !options.png && !options.gif {
        return Ok(report);
    }
    // The frames are drawn into a staging folder that then replaces `png/` as a whole, so
    // `png/` holds this drawing's frames only (a user's other files in it are kept).
    let png_dir = staging_dir(dir, "png");
    if options.png {
        remove_stale(dir, "png");
        std::fs::create_dir_all(&png_dir).map_err(|source| RenderError::Write {
            path: png_dir.clone(),
            source,
        })?;
    }
    let drawn = draw_frames(run, dir, options, &steps, &extent, &png_dir, report);
    if png_dir.exists() {
        let _ = std::fs::remove_dir_all(&png_dir);
    }
    drawn
}

/// Whether `name` is a frame's file name (`NNNN.png`, any number of digits from 4).
fn is_frame(name: &std::ffi::OsStr) -> bool {
    name.to_str()
        .and_then(|n| n.strip_suffix(".png"))
        .is_some_and(|stem| {
            stem.len() >= MIN_STEP_DIGITS && stem.bytes().all(|b| b.is_ascii_digit())
        })
}

/// The first, middle and last of `steps` (without repeats): the frames the GIF's palette is
/// computed from (the colours grow with the load).
fn palette_steps(steps: &[usize]) -> Vec<usize> {
    let mut picked = Vec::new();
    for i in [0, steps.len() / 2, steps.len().saturating_sub(1)] {
        if let Some(&k) = steps.get(i) {
            if !picked.contains(&k) {
                picked.push(k);
            }
        }
    }
    picked
}

/// The drawing of [`draw_run`]: frames into the staging folder `png_dir`, published as
/// `dir/png` when all are drawn, and the GIF. Frames are drawn, encoded and written in
/// parallel, a batch at a time (memory stays bounded); the GIF is appended in step order, so
/// the files do not depend on the number of threads.
fn draw_frames(
    run: &RunResults,
    dir: &Path,
    options: &RenderOptions,
    steps: &[usize],
    extent: &RunExtent,
    png_dir: &Path,
    mut report: RenderReport,
) -> Result<RenderReport, RenderError> {
    let final_png = dir.join("png");
    // A dynamic run's frames show for their real time to the next (or a stated slow-down,
    // which each frame's title then states).
    let timing = if options.gif {
        let times: Option<Vec<f64>> = steps
            .iter()
            .map(|&k| run.step(k).and_then(stored_time))
            .collect();
        times.and_then(|t| timed_delays(&t, LAST_FRAME_DELAY))
    } else {
        None
    };
    report.gif_slowdown = timing.as_ref().map(|(_, s)| *s);
    let extent = &RunExtent {
        gif_slowdown: report.gif_slowdown,
        ..extent.clone()
    };
    let draw = |k: usize| -> Result<Frame, RenderError> {
        let result = run.step(k).ok_or_else(|| RenderError::NoSuchStep {
            step: k,
            dir: dir.to_path_buf(),
            stored: stored_list(&run.step_numbers()),
        })?;
        draw_frame(&run.model, result, extent, options)
    };
    // The palette's frames are drawn first and kept for their own turn.
    let mut kept: Vec<(usize, Frame)> = Vec::new();
    let stopped = || {
        if options.interrupt.is_raised() {
            Err(RenderError::Interrupted {
                dir: dir.to_path_buf(),
            })
        } else {
            Ok(())
        }
    };
    let gif = if options.gif {
        stopped()?;
        kept = palette_steps(steps)
            .into_par_iter()
            .map(|k| draw(k).map(|f| (k, f)))
            .collect::<Result<_, _>>()?;
        let samples: Vec<&Frame> = kept.iter().map(|(_, f)| f).collect();
        Some(GifAnimation::new(options.width, options.height, &samples)?)
    } else {
        None
    };
    let batch = (2 * rayon::current_num_threads()).max(4);
    let mut gif = gif;
    for (b, chunk) in steps.chunks(batch).enumerate() {
        stopped()?;
        let done = chunk
            .par_iter()
            .map(|&k| {
                let owned;
                let frame = match kept.iter().find(|(s, _)| *s == k) {
                    Some((_, f)) => f,
                    None => {
                        owned = draw(k)?;
                        &owned
                    }
                };
                let mut name = None;
                if options.png {
                    let file = format!("{}.png", run.stem(k));
                    let path = png_dir.join(&file);
                    write_atomically(&path, &frame.png()?)
                        .map_err(|source| RenderError::Write { path, source })?;
                    name = Some(file);
                }
                let encoded = gif.as_ref().map(|g| g.encode(frame)).transpose()?;
                Ok((name, encoded))
            })
            .collect::<Result<Vec<_>, RenderError>>()?;
        for (i, (name, encoded)) in done.into_iter().enumerate() {
            if let Some(name) = name {
                report.frames.push(final_png.join(name));
            }
            if let (Some(g), Some(e)) = (gif.as_mut(), encoded) {
                let index = b * batch + i;
                match &timing {
                    Some((delays, _)) => g.push_encoded_for(e, delays[index])?,
                    None => g.push_encoded(e, index + 1 == steps.len())?,
                }
            }
        }
    }
    stopped()?;
    if options.png {
        publish_keeping(png_dir, &final_png, &is_frame).map_err(|source| RenderError::Write {
            path: final_png.clone(),
            source,
        })?;
    }
    if let Some(g) = gif {
        let path = dir.join("anim.gif");
        write_atomically(&path, &g.finish()?).map_err(|source| RenderError::Write {
            path: path.clone(),
            source,
        })?;
        report.gif = Some(path);
    }
    Ok(report)
}

/// Draws the pictures a scene asks for (`[output] png`, `gif`) and its glTF animation
/// (`[output] gltf`) during `linkage run`: pass it
/// to [`crate::scene::run_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct PictureWriter;

impl DrawResults for PictureWriter {
    fn draw(
        &self,
        world: &World,
        run: &RunResults,
        dir: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        let options = RenderOptions {
            interrupt: world.interrupt(),
            step_fraction: world.plots.step_fraction,
            ..RenderOptions::from_settings(&world.pictures)
        };
        let drawn = draw_run(run, dir, &options)?;
        if world.pictures.gltf {
            write_gltf(run, dir, drawn.magnification, stored_time)?;
        }
        Ok(())
    }

    fn plot(
        &self,
        world: &World,
        run: &RunResults,
        summary: &crate::scene::Summary,
        dir: &Path,
    ) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
        // Kept so that `linkage render` draws the same plots again.
        world.plots.write(dir)?;
        crate::render::plots::plot_run(summary, run, &world.plots, dir)?;
        Ok(())
    }
}
