//! Each body's own colour in frames of several bodies: a band under its members (line art)
//! or its silhouette (shaded surfaces), so two bodies pressed together read as two.

use crate::render::colour_scale::BODY_COLOURS;
use crate::render::deformed_body::DeformedBody;
use crate::render::{Layer, Primitive, Rgb, View};
use std::collections::HashMap;

/// The colour of body number `index` (0-based) in frames of several bodies.
pub fn body_colour(index: usize) -> Rgb {
    BODY_COLOURS[index % BODY_COLOURS.len()]
}

/// The intact members of `body` as lines `width` pixels wide in `colour` under everything
/// else ([`Layer::Behind`]): a band of the body's colour along the line art drawn on top.
pub fn member_band(body: &DeformedBody, colour: Rgb, width: f32) -> Vec<Primitive> {
    body.model
        .members
        .iter()
        .zip(&body.broken)
        .filter(|(_, broken)| !**broken)
        .map(|(m, _)| Primitive::Line {
            a: body.at(m[0]),
            b: body.at(m[1]),
            colour,
            alpha: 1.0,
            width,
            layer: Layer::Behind,
            depth_test: false,
        })
        .collect()
}

/// The silhouette of the surface `triangles` (0-based into `body.positions`) seen through
/// `view`: the edges between a triangle facing the camera and one facing away, and the edges
/// of only one triangle (the rim of a shell or a crack), as depth-tested lines in `colour`.
pub fn silhouette(
    body: &DeformedBody,
    triangles: &[[usize; 3]],
    view: &View,
    colour: Rgb,
    width: f32,
) -> Vec<Primitive> {
    let p: Vec<[f32; 3]> = body.positions.iter().map(|x| view.project(x)).collect();
    let facing = |t: &[usize; 3]| {
        let [a, b, c] = t.map(|k| p[k]);
        // Pixel y points down: counter-clockwise from outside shows as clockwise.
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0.0
    };
    // Per edge: (triangles facing the camera, triangles in all).
    let mut edges: HashMap<(usize, usize), (u32, u32)> = HashMap::new();
    for t in triangles {
        if t.iter().any(|&k| k >= p.len()) {
            continue;
        }
        let front = facing(t) as u32;
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let e = edges.entry((a.min(b), a.max(b))).or_default();
            e.0 += front;
            e.1 += 1;
        }
    }
    let mut keys: Vec<(usize, usize)> = edges
        .iter()
        .filter(|(_, &(front, all))| all == 1 || (front > 0 && front < all))
        .map(|(k, _)| *k)
        .collect();
    keys.sort_unstable();
    keys.into_iter()
        .map(|(a, b)| Primitive::Line {
            a: body.positions[a],
            b: body.positions[b],
            colour,
            alpha: 1.0,
            width,
            layer: Layer::Over,
            depth_test: true,
        })
        .collect()
}
