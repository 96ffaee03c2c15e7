//! `linkage bench --render`: the time to draw one frame of a shaded, bent cylindrical shell.

use crate::linkage::generators::cylindrical_shell;
use crate::render::{draw_frame, RenderOptions, RunExtent};
use crate::scene::{BodyResult, ModelBody, ModelFile, NodeForce, StepResult, SupportedNode};
use crate::Real;
use std::time::Instant;

/// One measured frame of `linkage bench --render`.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderTiming {
    /// Surface patches drawn.
    pub patches: usize,
    /// Members of the body.
    pub members: usize,
    /// Frame pixels (width × height).
    pub pixels: usize,
    /// Frame width and height, pixels.
    pub size: [u32; 2],
    /// Drawing the frame (surface, lines, marks, text), s: the best of the repeats.
    pub draw: Real,
    /// Encoding it as PNG, s.
    pub png: Real,
}

/// A cantilever tube (the paper's Fig. 7 shell) of `sectors` × (`rings` − 1) × 2 patches,
/// bent by an analytic deflection, as stored results: for the rendering benchmark and tests.
pub fn bent_shell(rings: usize, sectors: usize) -> Result<(ModelFile, Vec<StepResult>), String> {
    let g = cylindrical_shell(0.25, 2.0, rings, sectors).map_err(|e| e.to_string())?;
    let model = ModelFile {
        scene: "bench_shell".to_string(),
        obstacles: Vec::new(),
        up: None,
        bodies: vec![ModelBody {
            name: "shell".to_string(),
            dimension: 3,
            nodes: g.nodes.iter().map(|p| vec![p.x, p.y, p.z]).collect(),
            members: g.members.iter().map(|m| [m[0] + 1, m[1] + 1]).collect(),
            patches: g.patches.iter().map(|p| p.map(|k| k + 1)).collect(),
            supports: (0..sectors)
                .map(|k| SupportedNode {
                    node: k + 1,
                    fix: vec!["x".into(), "y".into(), "z".into()],
                })
                .collect(),
            member_materials: Vec::new(),
            strengths: Vec::new(),
        }],
    };
    let step = |k: usize, factor: Real| {
        // Cantilever bending: v(x) = -c x² (3L - x), rotation of the cross-sections.
        let c = 0.02 * factor;
        let disp: Vec<[Real; 3]> = g
            .nodes
            .iter()
            .map(|p| {
                let v = -c * p.x * p.x * (6.0 - p.x) / 8.0;
                let slope = -c * (12.0 * p.x - 3.0 * p.x * p.x) / 8.0;
                [-p.y * slope, v, 0.0]
            })
            .collect();
        let pos = |i: usize| {
            nalgebra::Vector3::new(
                g.nodes[i].x + disp[i][0],
                g.nodes[i].y + disp[i][1],
                g.nodes[i].z + disp[i][2],
            )
        };
        let stresses: Vec<Real> = g
            .members
            .iter()
            .map(|m| {
                let l0 = (g.nodes[m[0]] - g.nodes[m[1]]).norm();
                let l = (pos(m[0]) - pos(m[1])).norm();
                70e9 * (l - l0) / l0
            })
            .collect();
        let end = g.nodes.len() - sectors;
        StepResult {
            step: k,
            load_factor: factor,
            time: None,
            bodies: vec![BodyResult {
                name: "shell".to_string(),
                displacements: disp.iter().map(|d| d.to_vec()).collect(),
                positions: (0..g.nodes.len())
                    .map(|i| pos(i).as_slice().to_vec())
                    .collect(),
                axial_forces: stresses.iter().map(|s| s * 2e-5).collect(),
                strains: stresses.iter().map(|s| s / 70e9).collect(),
                overloaded: Vec::new(),
                stresses,
                reactions: Vec::new(),
                loads: (end..g.nodes.len())
                    .map(|i| NodeForce {
                        node: i + 1,
                        force: vec![0.0, -2000.0 * factor / sectors as Real, 0.0],
                    })
                    .collect(),
                contacts: Vec::new(),
                fracture: None,
                velocities: Vec::new(),
            }],
        }
    };
    Ok((model, vec![step(0, 0.0), step(1, 1.0)]))
}

/// Draw one frame of a shell with about `patches` patches (at least 2 × 3 × 1) at
/// `width` × `height` with the default options, `repeats` times; report the best time.
pub fn render_benchmark(
    patches: usize,
    width: u32,
    height: u32,
    repeats: usize,
) -> Result<RenderTiming, String> {
    // 2 · sectors · (rings − 1) patches with rings − 1 ≈ 1.25 · sectors (a long tube).
    let sectors = ((patches as Real / 2.5).sqrt().round() as usize).max(3);
    let rings = (patches / (2 * sectors)).max(1) + 1;
    let (model, steps) = bent_shell(rings, sectors)?;
    let options = RenderOptions {
        width,
        height,
        ..RenderOptions::default()
    };
    let extent = RunExtent::measure(&model, &[0, 1], None, |k| Ok::<_, String>(steps[k].clone()))?;
    let mut best = Real::INFINITY;
    let mut frame = None;
    for _ in 0..repeats.max(1) {
        let t = Instant::now();
        let f = draw_frame(&model, &steps[1], &extent, &options).map_err(|e| e.to_string())?;
        best = best.min(t.elapsed().as_secs_f64());
        frame = Some(f);
    }
    let t = Instant::now();
    if let Some(f) = &frame {
        f.png().map_err(|e| e.to_string())?;
    }
    let png = t.elapsed().as_secs_f64();
    Ok(RenderTiming {
        patches: model.bodies[0].patches.len(),
        members: model.bodies[0].members.len(),
        pixels: width as usize * height as usize,
        size: [width, height],
        draw: best,
        png,
    })
}

/// Seconds to build the GIF of the same frames two ways (see [`gif_benchmark`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GifTiming {
    /// Frames in the animation.
    pub frames: usize,
    /// Drawing the frames (in parallel), s.
    pub draw: Real,
    /// A palette per frame by NeuQuant (speed 10), frames one after another: how the GIF was
    /// made before the shared palette, s.
    pub per_frame_palette: Real,
    /// One palette for the run, frames indexed and compressed in parallel
    /// ([`crate::render::GifAnimation`]), s.
    pub shared_palette: Real,
    /// Size of each GIF, bytes: (per-frame palettes, shared palette).
    pub bytes: (usize, usize),
}

/// Draw every stored step of the results folder `dir` and time building its GIF with a
/// palette per frame (NeuQuant per frame, sequential, as before) against the shared palette
/// encoded in parallel, on the same frames in one process.
pub fn gif_benchmark(dir: &std::path::Path) -> Result<GifTiming, String> {
    use crate::render::{Frame, GifAnimation};
    use rayon::prelude::*;
    let run = crate::scene::RunResults::read(dir).map_err(|e| e.to_string())?;
    let options = RenderOptions::default();
    let extent = RunExtent::of_run(&run, None);
    let t = Instant::now();
    let frames: Vec<Frame> = run
        .steps
        .par_iter()
        .map(|s| draw_frame(&run.model, s, &extent, &options).map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    let draw = t.elapsed().as_secs_f64();
    let (w, h) = (options.width as u16, options.height as u16);

    let t = Instant::now();
    let mut old = gif::Encoder::new(Vec::new(), w, h, &[]).map_err(|e| e.to_string())?;
    for f in &frames {
        let mut rgba = f.rgba();
        let frame = gif::Frame::from_rgba_speed(w, h, &mut rgba, 10);
        old.write_frame(&frame).map_err(|e| e.to_string())?;
    }
    let old = old.into_inner().map_err(|e| e.to_string())?;
    let per_frame_palette = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let n = frames.len();
    let samples: Vec<&Frame> = [0, n / 2, n.saturating_sub(1)]
        .iter()
        .filter_map(|&i| frames.get(i))
        .collect();
    let mut new =
        GifAnimation::new(options.width, options.height, &samples).map_err(|e| e.to_string())?;
    let encoded = frames
        .par_iter()
        .map(|f| new.encode(f))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    for (i, e) in encoded.into_iter().enumerate() {
        new.push_encoded(e, i + 1 == n).map_err(|e| e.to_string())?;
    }
    let new = new.finish().map_err(|e| e.to_string())?;
    let shared_palette = t.elapsed().as_secs_f64();
    Ok(GifTiming {
        frames: n,
        draw,
        per_frame_palette,
        shared_palette,
        bytes: (old.len(), new.len()),
    })
}
