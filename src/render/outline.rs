//! Each body's own colour in frames of several bodies: a band under its rim members (2D
//! line art), under all its members (3D line art) or its silhouette (shaded surfaces), so two
//! bodies pressed together read as two while the stress colours inside stay visible.

use crate::render::colour_scale::BODY_COLOURS;
use crate::render::deformed_body::DeformedBody;
use crate::render::{Layer, Primitive, Rgb, View};
use std::collections::HashMap;

/// The colour of body number `index` (0-based) in frames of several bodies.
pub fn body_colour(index: usize) -> Rgb {
    BODY_COLOURS[index % BODY_COLOURS.len()]
}

/// The intact members of `body` as lines `width` pixels wide in `colour` under everything
/// else ([`Layer::Behind`]): a band of the body's colour along the line art drawn on top. A
/// 2D body gets it along its rim only ([`rim_members`]: its outline and the faces of its
/// cracks), so its inside keeps the stress colours; a 3D body along all its members.
pub fn member_band(body: &DeformedBody, colour: Rgb, width: f32) -> Vec<Primitive> {
    let rim = (body.model.dimension == 2).then(|| rim_members(body));
    body.model
        .members
        .iter()
        .enumerate()
        .filter(|(j, _)| !body.broken[*j] && rim.as_ref().is_none_or(|r| r[*j]))
        .map(|(_, m)| Primitive::Line {
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

/// Whether each member of the 2D `body` lies on its rim: an intact member is inside when
/// intact members close triangles with it on both of its sides (in the undeformed shape), on
/// the rim otherwise (one side only, or no triangle: a bar of a truss). Broken members are
/// not on the rim; the intact members along a crack are.
pub fn rim_members(body: &DeformedBody) -> Vec<bool> {
    let members = &body.model.members;
    let n = body.undeformed.len();
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); n];
    let intact = |j: usize| !body.broken.get(j).copied().unwrap_or(false);
    for (j, m) in members.iter().enumerate() {
        let (a, b) = (m[0].wrapping_sub(1), m[1].wrapping_sub(1));
        if intact(j) && a < n && b < n && a != b {
            neighbours[a].push(b);
            neighbours[b].push(a);
        }
    }
    for list in &mut neighbours {
        list.sort_unstable();
        list.dedup();
    }
    members
        .iter()
        .enumerate()
        .map(|(j, m)| {
            let (a, b) = (m[0].wrapping_sub(1), m[1].wrapping_sub(1));
            if !intact(j) || a >= n || b >= n {
                return false;
            }
            let (pa, pb) = (body.undeformed[a], body.undeformed[b]);
            let d = pb - pa;
            let (mut left, mut right) = (false, false);
            for &c in &neighbours[a] {
                if c == b || neighbours[b].binary_search(&c).is_err() {
                    continue;
                }
                let e = body.undeformed[c] - pa;
                let side = d.x * e.y - d.y * e.x;
                // A node on the member's own line closes no triangle.
                let tiny = 1e-9 * d.norm_squared().max(e.norm_squared());
                if side > tiny {
                    left = true;
                } else if side < -tiny {
                    right = true;
                }
            }
            !(left && right)
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
