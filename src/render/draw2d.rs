//! 2D bodies as line art: members coloured by stress, overloaded members black, the undeformed ghost.

use crate::render::colour_scale::{ColourScale, BLACK, GHOST_GREY, PLAIN};
use crate::render::cracks::crack_marks;
use crate::render::deformed_body::DeformedBody;
use crate::render::outline::member_band;
use crate::render::{Colouring, Layer, Primitive, Rgb, View};
use crate::Real;

/// Line widths, pixels at 720 pixels of frame height: (member, overloaded member, ghost).
/// `ui`: the frame's scale (see `overlay::ui_scale`).
pub fn line_widths(body: &DeformedBody, view: &View, ui: f32) -> (f32, f32, f32) {
    // Thinner lines for finer meshes: a tenth of the typical member's length on screen.
    let mut lengths: Vec<f32> = body
        .model
        .members
        .iter()
        .map(|m| {
            let a = view.project(&body.undeformed[m[0] - 1]);
            let b = view.project(&body.undeformed[m[1] - 1]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        })
        .collect();
    lengths.sort_by(|a, b| a.total_cmp(b));
    let typical = lengths.get(lengths.len() / 2).copied().unwrap_or(50.0);
    let w = (typical / ui * 0.045).clamp(0.6, 3.2);
    (w, (w * 2.0).max(2.5), (w * 0.6).max(0.5))
}

/// The members of a body as lines: the undeformed shape as a faint ghost behind, members
/// coloured by axial stress (or plain), overloaded members black and thicker on top, as in
/// the paper's Fig. 6; broken members are left out, so a crack shows as a gap, and marked
/// by a short red line. `outline`: the body's own colour as a band under its rim (2D) or its members (frames
/// of several bodies). Used for 2D bodies and for 3D bodies without patches (then drawn
/// back to front).
pub fn member_lines(
    body: &DeformedBody,
    view: &View,
    colouring: Colouring,
    scale: &ColourScale,
    ui: f32,
    outline: Option<Rgb>,
) -> Vec<Primitive> {
    let (width, heavy, ghost) = line_widths(body, view, ui);
    let members = &body.model.members;
    let mut out = Vec::with_capacity(2 * members.len());
    let mut order: Vec<usize> = (0..members.len()).collect();
    if body.model.dimension == 3 {
        let depth = |j: usize| {
            let m = members[j];
            view.project(&((body.positions[m[0] - 1] + body.positions[m[1] - 1]) / 2.0))[2]
        };
        order.sort_by(|&a, &b| depth(b).total_cmp(&depth(a)));
    }
    if members.len() <= 20_000 {
        for m in members {
            out.push(Primitive::Line {
                a: body.undeformed[m[0] - 1],
                b: body.undeformed[m[1] - 1],
                colour: GHOST_GREY,
                alpha: 0.45,
                width: ghost,
                layer: Layer::Behind,
                depth_test: false,
            });
        }
    }
    if let Some(colour) = outline {
        out.extend(member_band(body, colour, heavy * 2.5));
    }
    let stress = |j: usize| body.result.stresses.get(j).copied().unwrap_or(0.0) as Real;
    let line = |j: usize, colour, width| {
        let m = members[j];
        Primitive::Line {
            a: body.positions[m[0] - 1],
            b: body.positions[m[1] - 1],
            colour,
            alpha: 1.0,
            width,
            layer: Layer::Over,
            depth_test: false,
        }
    };
    let intact = |j: &&usize| !body.broken[**j];
    for &j in order
        .iter()
        .filter(intact)
        .filter(|&&j| !body.overloaded[j])
    {
        let colour = match colouring {
            Colouring::Stress | Colouring::MaxStress => scale.colour(stress(j)),
            Colouring::Plain => PLAIN,
        };
        out.push(line(j, colour, width));
    }
    for &j in order.iter().filter(intact).filter(|&&j| body.overloaded[j]) {
        out.push(line(j, BLACK, heavy));
    }
    out.extend(crack_marks(body, heavy * 1.4, false));
    out
}
