use crate::atomic_file::write_atomically;
use crate::render::{
    draw_frame, GifAnimation, RenderError, RenderOptions, RunExtent, StepSelection,
};
use crate::scene::{DrawResults, StoredRun, World};
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
}

/// The stored steps `selection` picks from `run`.
pub fn select_steps(run: &StoredRun, selection: &StepSelection) -> Result<Vec<usize>, RenderError> {
    Ok(match selection {
        StepSelection::All => run.steps.clone(),
        StepSelection::Last => run.steps.last().copied().into_iter().collect(),
        StepSelection::List(list) => {
            for &k in list {
                if !run.steps.contains(&k) {
                    return Err(RenderError::NoSuchStep {
                        step: k,
                        dir: run.dir.clone(),
                        stored: stored_list(&run.steps),
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
    options.check()?;
    let run = StoredRun::open(dir)?;
    let steps = select_steps(&run, &options.steps)?;
    let extent = RunExtent::measure(&run.model, &run.steps, options.magnification, |k| {
        run.read_step(k)
    })?;
    let mut report = RenderReport {
        steps: steps.clone(),
        magnification: extent.magnification,
        ..RenderReport::default()
    };
    if !options.png && !options.gif {
        return Ok(report);
    }
    let png_dir = dir.join("png");
    if options.png {
        std::fs::create_dir_all(&png_dir).map_err(|source| RenderError::Write {
            path: png_dir.clone(),
            source,
        })?;
    }
    let mut gif = if options.gif {
        Some(GifAnimation::new(options.width, options.height)?)
    } else {
        None
    };
    for (i, &k) in steps.iter().enumerate() {
        let result = run.read_step(k)?;
        let frame = draw_frame(&run.model, &result, &extent, options)?;
        if options.png {
            let path = png_dir.join(format!("{k:04}.png"));
            write_atomically(&path, &frame.png()?).map_err(|source| RenderError::Write {
                path: path.clone(),
                source,
            })?;
            report.frames.push(path);
        }
        if let Some(g) = gif.as_mut() {
            g.push(&frame, i + 1 == steps.len())?;
        }
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

/// Draws the pictures a scene asks for (`[output] png`, `gif`) during `linkage run`: pass it
/// to [`crate::scene::run_with`].
#[derive(Clone, Copy, Debug, Default)]
pub struct PictureWriter;

impl DrawResults for PictureWriter {
    fn draw(&self, world: &World, dir: &Path) -> Result<(), String> {
        render_run(dir, &RenderOptions::from_settings(&world.pictures))
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
}
