//! 3D bodies as shaded surfaces coloured by the mean stress of the members at each node.

use crate::render::colour_scale::{ColourScale, BLACK, GHOST_GREY, PLAIN_SURFACE};
use crate::render::cracks::crack_marks;
use crate::render::deformed_body::DeformedBody;
use crate::render::draw2d::line_widths;
use crate::render::outline::silhouette;
use crate::render::{Colouring, Layer, Mesh, MeshKind, Primitive, Rgb, View};
use crate::scene::ModelBody;
use crate::Real;
use nalgebra::Vector3;

/// Mean axial stress of the members at each node, Pa (0 at a node without members): the
/// value that colours a shaded surface.
pub fn node_stresses(model: &ModelBody, stresses: &[Real]) -> Vec<Real> {
    let n = model.nodes.len();
    let mut sum = vec![0.0; n];
    let mut count = vec![0u32; n];
    for (m, s) in model.members.iter().zip(stresses) {
        for &k in m {
            if let (Some(x), Some(c)) = (sum.get_mut(k - 1), count.get_mut(k - 1)) {
                *x += s;
                *c += 1;
            }
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| if c > 0 { s / c as Real } else { 0.0 })
        .collect()
}

/// The stress of the most stressed member at each node (the signed value of largest
/// magnitude), Pa (0 at a node without members): the value that colours a shaded surface with
/// [`Colouring::MaxStress`], so a peak the mean would hide shows.
pub fn node_peak_stresses(model: &ModelBody, stresses: &[Real]) -> Vec<Real> {
    let mut peak: Vec<Real> = vec![0.0; model.nodes.len()];
    for (m, &s) in model.members.iter().zip(stresses) {
        for &k in m {
            if let Some(p) = peak.get_mut(k.wrapping_sub(1)) {
                if s.abs() > p.abs() {
                    *p = s;
                }
            }
        }
    }
    peak
}

/// Cosine of the crease angle: adjacent patches meeting at more than 45° keep their own
/// normals there (the edges of a box stay sharp), flatter ones are shaded smoothly.
const CREASE_COS: Real = std::f64::consts::FRAC_1_SQRT_2;

/// Unit normals at the three corners of every triangle: at each corner, the area-weighted
/// mean of the normals of the triangles around that vertex that meet this one at less than
/// the crease angle (smooth shading across smooth surfaces, sharp edges where they are sharp).
pub fn corner_normals(
    positions: &[Vector3<Real>],
    triangles: &[[usize; 3]],
) -> Vec<[Vector3<Real>; 3]> {
    let face: Vec<Vector3<Real>> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = [positions[t[0]], positions[t[1]], positions[t[2]]];
            (b - a).cross(&(c - a))
        })
        .collect();
    let unit: Vec<Vector3<Real>> = face
        .iter()
        .map(|n| n.try_normalize(1e-300).unwrap_or_else(Vector3::z))
        .collect();
    // Triangles around each vertex (compressed rows).
    let mut start = vec![0usize; positions.len() + 1];
    for t in triangles {
        for &v in t {
            start[v + 1] += 1;
        }
    }
    for i in 0..positions.len() {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut around = vec![0usize; start[positions.len()]];
    for (k, t) in triangles.iter().enumerate() {
        for &v in t {
            around[fill[v]] = k;
            fill[v] += 1;
        }
    }
    triangles
        .iter()
        .enumerate()
        .map(|(k, t)| {
            t.map(|v| {
                let mut n = Vector3::zeros();
                for &s in &around[start[v]..start[v + 1]] {
                    if unit[s].dot(&unit[k]) >= CREASE_COS {
                        n += face[s];
                    }
                }
                n.try_normalize(1e-300).unwrap_or(unit[k])
            })
        })
        .collect()
}

/// A 3D body with patches: its surface shaded (coloured by the mean or the largest member
/// stress at the nodes, or plain), the undeformed members as a faint ghost behind, optionally
/// the members as a wireframe, and overloaded members as black lines on top (hidden where
/// behind the surface). Broken members are left out, and so are the patches they border,
/// so a crack shows as a gap, and each is marked by a short red line where it is not hidden.
/// `outline`: the body's own colour for its silhouette (frames of several bodies).
pub fn shaded_surface(
    body: &DeformedBody,
    view: &View,
    colouring: Colouring,
    node_scale: &ColourScale,
    wireframe: bool,
    ui: f32,
    outline: Option<Rgb>,
) -> Vec<Primitive> {
    let model = body.model;
    let (width, heavy, ghost) = line_widths(body, view, ui);
    let mut out = Vec::new();
    let members = &model.members;
    if members.len() <= 20_000 {
        for m in members {
            out.push(Primitive::Line {
                a: body.undeformed[m[0] - 1],
                b: body.undeformed[m[1] - 1],
                colour: GHOST_GREY,
                alpha: 0.3,
                width: ghost,
                layer: Layer::Behind,
                depth_test: false,
            });
        }
    }
    let broken_edges: std::collections::HashSet<(usize, usize)> = members
        .iter()
        .zip(&body.broken)
        .filter(|(_, b)| **b)
        .map(|(m, _)| (m[0].min(m[1]) - 1, m[0].max(m[1]) - 1))
        .collect();
    let triangles: Vec<[usize; 3]> = model
        .patches
        .iter()
        .map(|p| p.map(|k| k - 1))
        .filter(|t| {
            broken_edges.is_empty()
                || ![(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]
                    .iter()
                    .any(|&(a, b)| broken_edges.contains(&(a.min(b), a.max(b))))
        })
        .collect();
    let colours: Vec<Rgb> = match colouring {
        Colouring::Stress => node_stresses(model, &body.result.stresses)
            .iter()
            .map(|&s| node_scale.colour(s))
            .collect(),
        Colouring::MaxStress => node_peak_stresses(model, &body.result.stresses)
            .iter()
            .map(|&s| node_scale.colour(s))
            .collect(),
        Colouring::Plain => vec![PLAIN_SURFACE; body.positions.len()],
    };
    let rim = outline
        .map(|c| silhouette(body, &triangles, view, c, heavy))
        .unwrap_or_default();
    out.push(Primitive::Surface(Mesh {
        normals: corner_normals(&body.positions, &triangles),
        positions: body.positions.clone(),
        colours,
        triangles,
        kind: MeshKind::Body,
    }));
    let line = |j: usize, colour, alpha, width| {
        let m = members[j];
        Primitive::Line {
            a: body.positions[m[0] - 1],
            b: body.positions[m[1] - 1],
            colour,
            alpha,
            width,
            layer: Layer::Over,
            depth_test: true,
        }
    };
    let intact = |j: &usize| !body.broken[*j];
    if wireframe {
        for j in (0..members.len())
            .filter(intact)
            .filter(|&j| !body.overloaded[j])
        {
            out.push(line(j, Rgb(0.1, 0.1, 0.12), 0.45, width * 0.5));
        }
    }
    for j in (0..members.len())
        .filter(intact)
        .filter(|&j| body.overloaded[j])
    {
        out.push(line(j, BLACK, 1.0, heavy));
    }
    out.extend(rim);
    out.extend(crack_marks(body, heavy * 1.4, true));
    out
}
