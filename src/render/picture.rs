//! One frame of one step: camera and view for the run's extent, then the bodies drawn.

use crate::render::colour_scale::{round_up, ColourScale};
use crate::render::deformed_body::DeformedBody;
use crate::render::draw2d::member_lines;
use crate::render::draw3d::shaded_surface;
use crate::render::markers::markers;
use crate::render::obstacles::obstacle_primitives;
use crate::render::outline::body_colour;
use crate::render::overlay::{draw_overlay, Caption, Layout};
use crate::render::{
    paint, Camera, Colouring, Frame, Lighting, Primitive, Projection, RenderError, RenderOptions,
    RunExtent, View,
};
use crate::scene::{ModelFile, StepResult};
use crate::Real;

/// The camera `options` ask for, with the defaults of 2D (face on, orthographic) or 3D
/// (azimuth 35°, elevation 25°, perspective) runs.
pub fn camera_for(options: &RenderOptions, extent: &RunExtent) -> Camera {
    let (az, el, projection) = if extent.is_3d {
        (35.0, 25.0, Projection::Perspective)
    } else {
        (0.0, 0.0, Projection::Orthographic)
    };
    Camera {
        azimuth: options.azimuth.unwrap_or(az),
        elevation: options.elevation.unwrap_or(el),
        zoom: options.zoom,
        projection: options.projection.unwrap_or(projection),
        up: extent.up,
    }
}

/// The view a frame of `options` uses for a run of `extent`: world (m) to frame pixels.
pub fn view_for(options: &RenderOptions, extent: &RunExtent) -> View {
    let layout = Layout::new(options.width, options.height, colour_bar(options));
    camera_for(options, extent).fit(extent.min, extent.max, layout.viewport)
}

/// The pixel rectangle `[x0, y0, x1, y1]` the run is fitted into (inside the caption, the
/// magnification note and the colour bar).
pub fn viewport_for(options: &RenderOptions) -> [Real; 4] {
    Layout::new(options.width, options.height, colour_bar(options)).viewport
}

/// What a frame shows besides its primitives: the numbers of its caption.
struct FrameFacts {
    max_displacement: Real,
    overloaded: usize,
    broken: usize,
    /// The member stress of largest magnitude, Pa, and its ratio to that member's strength
    /// (`None` without a strength in that direction).
    peak: Option<(Real, Option<Real>)>,
    surfaces: bool,
}

/// The ratio of `stress` (Pa, tension positive) to the strength `[tension, compression]` in
/// its direction, if there is one.
fn strength_ratio(stress: Real, strength: Option<&[Option<Real>; 2]>) -> Option<Real> {
    let s = strength?;
    let limit = if stress >= 0.0 { s[0] } else { s[1] }?;
    (limit > 0.0).then(|| stress.abs() / limit)
}

/// What one stored step of a run is drawn with, in painting order: the obstacles (at their
/// place at this step), the bodies (2D line art or shaded 3D surfaces), supports and forces.
/// `extent` fixes the scales over the run. The caller checks `step` against `model`.
pub fn frame_primitives(
    model: &ModelFile,
    step: &StepResult,
    extent: &RunExtent,
    options: &RenderOptions,
) -> Vec<Primitive> {
    collect_frame(model, step, extent, options).0
}

fn collect_frame(
    model: &ModelFile,
    step: &StepResult,
    extent: &RunExtent,
    options: &RenderOptions,
) -> (Vec<Primitive>, FrameFacts) {
    let layout = Layout::new(options.width, options.height, colour_bar(options));
    let view = view_for(options, extent);
    let member_scale = ColourScale::new(round_up(extent.stress_limit));
    let node_scale = ColourScale::new(round_up(node_limit(options, extent)));
    let mut primitives = obstacle_primitives(model, step.step, extent.is_3d, &view);
    let mut facts = FrameFacts {
        max_displacement: 0.0,
        overloaded: 0,
        broken: 0,
        peak: None,
        surfaces: false,
    };
    let several = model.bodies.len() > 1;
    for (index, (m, r)) in model.bodies.iter().zip(&step.bodies).enumerate() {
        let body = DeformedBody::new(m, r, extent.magnification);
        let outline = several.then(|| body_colour(index));
        for u in &r.displacements {
            facts.max_displacement = facts
                .max_displacement
                .max(u.iter().map(|x| x * x).sum::<Real>().sqrt());
        }
        facts.overloaded += r.overloaded.len();
        facts.broken += body.broken.iter().filter(|b| **b).count();
        for (j, &s) in r.stresses.iter().enumerate() {
            if body.broken.get(j).copied().unwrap_or(false) {
                continue;
            }
            if facts.peak.is_none_or(|(p, _)| s.abs() > p.abs()) {
                facts.peak = Some((s, strength_ratio(s, m.strengths.get(j))));
            }
        }
        let shaded = m.dimension == 3 && !m.patches.is_empty();
        if shaded {
            facts.surfaces = true;
            primitives.extend(shaded_surface(
                &body,
                &view,
                options.colouring,
                &node_scale,
                options.wireframe,
                layout.ui,
                outline,
            ));
        } else {
            primitives.extend(member_lines(
                &body,
                &view,
                options.colouring,
                &member_scale,
                layout.ui,
                outline,
            ));
        }
        primitives.extend(markers(&body, extent, shaded));
    }
    (primitives, facts)
}

/// Whether the colouring of `options` has a colour bar.
fn colour_bar(options: &RenderOptions) -> bool {
    options.colouring != Colouring::Plain
}

/// The largest value the surface colours of `options` reach over the run, Pa.
fn node_limit(options: &RenderOptions, extent: &RunExtent) -> Real {
    match options.colouring {
        Colouring::MaxStress => extent.node_peak_limit,
        _ => extent.node_stress_limit,
    }
}

/// Draw one stored step of a run: the obstacles, the bodies (2D line art or shaded 3D
/// surfaces), supports, forces, the caption, the magnification and the colour bar. `extent`
/// fixes the camera, scales and colours over the whole run. Deterministic: the same input
/// gives the same pixels.
pub fn draw_frame(
    model: &ModelFile,
    step: &StepResult,
    extent: &RunExtent,
    options: &RenderOptions,
) -> Result<Frame, RenderError> {
    options.check()?;
    if let Some(problem) = model.problem().or_else(|| model.step_problem(step)) {
        return Err(RenderError::Option {
            message: format!("step {} cannot be drawn: {problem}", step.step),
        });
    }
    let mut frame = Frame::new(options.width, options.height)?;
    let layout = Layout::new(options.width, options.height, colour_bar(options));
    let view = view_for(options, extent);
    let (primitives, facts) = collect_frame(model, step, extent, options);
    paint(
        &primitives,
        &view,
        &mut frame,
        options.supersampling,
        &Lighting::default(),
    );
    let stress_bar = colour_bar(options).then(|| {
        if facts.surfaces {
            let title = match options.colouring {
                Colouring::MaxStress => "largest member stress at nodes",
                _ => "mean member stress at nodes",
            };
            (
                title.to_string(),
                ColourScale::new(round_up(node_limit(options, extent))).limit,
            )
        } else {
            (
                "member axial stress".to_string(),
                ColourScale::new(round_up(extent.stress_limit)).limit,
            )
        }
    });
    draw_overlay(
        &mut frame,
        &layout,
        &Caption {
            scene: model.scene.clone(),
            step: step.step,
            last_step: extent.last_step,
            load_factor: step.load_factor,
            load_name: crate::scene::load_name(options.step_fraction),
            time: step.time,
            gif_slowdown: extent.gif_slowdown,
            max_displacement: facts.max_displacement,
            overloaded: facts.overloaded,
            broken: (facts.broken > 0 || step.bodies.iter().any(|b| b.fracture.is_some()))
                .then_some(facts.broken),
            collapse: step
                .bodies
                .iter()
                .any(|b| b.fracture.as_ref().is_some_and(|f| f.collapse)),
            peak_stress: facts.peak,
            magnification: extent.magnification,
            shared_by: extent.shared_by,
            stress_bar,
            max_force: extent.max_force,
            max_contact: extent.max_contact,
            friction: extent.friction,
            supports: model.bodies.iter().any(|b| !b.supports.is_empty()),
            obstacles: !model.obstacles.is_empty(),
        },
    );
    Ok(frame)
}
