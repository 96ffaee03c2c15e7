//! One frame of one step: camera and view for the run's extent, then the bodies drawn.

use crate::render::colour_scale::{round_up, ColourScale};
use crate::render::deformed_body::DeformedBody;
use crate::render::draw2d::member_lines;
use crate::render::draw3d::shaded_surface;
use crate::render::markers::markers;
use crate::render::overlay::{draw_overlay, Caption, Layout};
use crate::render::{
    paint, Camera, Colouring, Frame, Lighting, Projection, RenderError, RenderOptions, RunExtent,
    View,
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
    }
}

/// The view a frame of `options` uses for a run of `extent`: world (m) to frame pixels.
pub fn view_for(options: &RenderOptions, extent: &RunExtent) -> View {
    let layout = Layout::new(
        options.width,
        options.height,
        options.colouring == Colouring::Stress,
    );
    camera_for(options, extent).fit(extent.min, extent.max, layout.viewport)
}

/// The pixel rectangle `[x0, y0, x1, y1]` the run is fitted into (inside the caption, the
/// magnification note and the colour bar).
pub fn viewport_for(options: &RenderOptions) -> [Real; 4] {
    Layout::new(
        options.width,
        options.height,
        options.colouring == Colouring::Stress,
    )
    .viewport
}

/// Draw one stored step of a run: the bodies (2D line art or shaded 3D surfaces), supports,
/// forces, the caption, the magnification and the colour bar. `extent` fixes the camera,
/// scales and colours over the whole run. Deterministic: the same input gives the same pixels.
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
    let stress = options.colouring == Colouring::Stress;
    let layout = Layout::new(options.width, options.height, stress);
    let view = view_for(options, extent);
    let member_scale = ColourScale::new(round_up(extent.stress_limit));
    let node_scale = ColourScale::new(round_up(extent.node_stress_limit));
    let mut primitives = Vec::new();
    let mut surfaces = false;
    let mut max_displacement: Real = 0.0;
    let mut overloaded = 0;
    for (m, r) in model.bodies.iter().zip(&step.bodies) {
        let body = DeformedBody::new(m, r, extent.magnification);
        for u in &r.displacements {
            max_displacement = max_displacement.max(u.iter().map(|x| x * x).sum::<Real>().sqrt());
        }
        overloaded += r.overloaded.len();
        let shaded = m.dimension == 3 && !m.patches.is_empty();
        if shaded {
            surfaces = true;
            primitives.extend(shaded_surface(
                &body,
                &view,
                options.colouring,
                &node_scale,
                options.wireframe,
                layout.ui,
            ));
        } else {
            primitives.extend(member_lines(
                &body,
                &view,
                options.colouring,
                &member_scale,
                layout.ui,
            ));
        }
        primitives.extend(markers(&body, extent, shaded));
    }
    paint(
        &primitives,
        &view,
        &mut frame,
        options.supersampling,
        &Lighting::default(),
    );
    let stress_bar = stress.then(|| {
        if surfaces {
            ("stress at nodes".to_string(), node_scale.limit)
        } else {
            ("axial stress".to_string(), member_scale.limit)
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
            max_displacement,
            overloaded,
            magnification: extent.magnification,
            stress_bar,
            max_force: extent.max_force,
            friction: extent.friction,
        },
    );
    Ok(frame)
}
