//! What is drawn: lines, points and shaded meshes in model space, painted onto a frame.

use crate::render::{Frame, Lighting, RasterVertex, Rasteriser, Rgb, View};
use crate::Real;
use nalgebra::Vector3;
use tiny_skia::{FillRule, LineCap, Paint, PathBuilder, Pixmap, PixmapPaint, Stroke, Transform};

/// When a line is drawn relative to the shaded surfaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layer {
    /// Before the surfaces, which then cover it (the undeformed ghost).
    Behind,
    /// After the surfaces, on top.
    Over,
}

/// A triangle mesh to shade: positions (m), colours per vertex, triangles (0-based vertex
/// indices, counter-clockwise seen from outside) and unit outward normals per triangle corner.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// Vertex positions, m.
    pub positions: Vec<Vector3<Real>>,
    /// Unit normals at each triangle's corners (in the order of `triangles`).
    pub normals: Vec<[Vector3<Real>; 3]>,
    /// Vertex colours.
    pub colours: Vec<Rgb>,
    /// Triangles.
    pub triangles: Vec<[usize; 3]>,
    /// How it covers what is behind it.
    pub kind: MeshKind,
}

/// How a shaded mesh covers what lies behind it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshKind {
    /// Opaque (a body's surface): drawn first.
    #[default]
    Body,
    /// Opaque over the background and other obstacles, see-through
    /// ([`crate::render::raster::VEIL_ALPHA`]) where a body lies behind it, so it never hides
    /// one (a rigid obstacle).
    Obstacle,
    /// See-through everywhere ([`crate::render::raster::PLANE_ALPHA`]): a half-space seen
    /// from inside, whose plane would otherwise cover the bodies.
    Plane,
}

/// Something to draw, in world coordinates (m); sizes on the frame in pixels at 720 pixels
/// of frame height (scaled with the frame). A drawing is a list of these, painted in order
/// (surfaces first, see [`paint`]); new kinds of things (obstacles) add variants or reuse these.
#[derive(Clone, Debug, PartialEq)]
pub enum Primitive {
    /// A straight line.
    Line {
        /// Ends, m.
        a: Vector3<Real>,
        /// Ends, m.
        b: Vector3<Real>,
        /// Colour.
        colour: Rgb,
        /// Opacity, 0–1.
        alpha: f32,
        /// Width, pixels.
        width: f32,
        /// Before or after the surfaces.
        layer: Layer,
        /// Hide the parts behind a surface.
        depth_test: bool,
    },
    /// An arrow from `tail` to `tip` (a force).
    Arrow {
        /// Start, m.
        tail: Vector3<Real>,
        /// Point, m.
        tip: Vector3<Real>,
        /// Colour.
        colour: Rgb,
        /// Shaft width, pixels.
        width: f32,
        /// Skip it when its tail is behind a surface.
        depth_test: bool,
    },
    /// A support: a short bar across the held `direction` at node `at`, on the side the
    /// support pushes from, with hatching.
    Support {
        /// Node, m.
        at: Vector3<Real>,
        /// Unit held direction.
        direction: Vector3<Real>,
        /// Skip it when the node is behind a surface.
        depth_test: bool,
    },
    /// A node held in every direction (3D): a small black square.
    Clamp {
        /// Node, m.
        at: Vector3<Real>,
        /// Skip it when the node is behind a surface.
        depth_test: bool,
    },
    /// A shaded surface.
    Surface(Mesh),
    /// A filled region (a 2D obstacle): closed loops of points filled by the even-odd rule
    /// (holes stay empty) and outlined; painted first, under everything else.
    Region {
        /// Loops of points, m (the last point may repeat the first).
        loops: Vec<Vec<Vector3<Real>>>,
        /// Fill colour.
        fill: Rgb,
        /// Outline colour.
        edge: Rgb,
    },
}

/// Size of marks and arrow heads, pixels at 720 pixels of frame height.
const SUPPORT_SIZE: f32 = 24.0;

/// Paint `primitives` onto `frame` through `view`: first the regions, then the `Behind` lines, then all
/// surfaces together through one depth buffer (`supersampling`² samples per pixel), then the
/// rest in list order, depth-tested against the surfaces where asked.
pub fn paint(
    primitives: &[Primitive],
    view: &View,
    frame: &mut Frame,
    supersampling: u32,
    lighting: &Lighting,
) {
    let ui = crate::render::overlay::ui_scale(frame.width(), frame.height());
    let ss = supersampling.max(1) as usize;
    for p in primitives {
        if let Primitive::Region { loops, fill, edge } = p {
            draw_region(frame, view, loops, *fill, *edge, ui);
        }
    }
    for p in primitives {
        if let Primitive::Line {
            layer: Layer::Behind,
            ..
        } = p
        {
            draw_line(frame, view, None, ss, p, ui);
        }
    }
    let mut raster = None;
    if primitives
        .iter()
        .any(|p| matches!(p, Primitive::Surface(_)))
    {
        let mut r = Rasteriser::new(frame.width() as usize * ss, frame.height() as usize * ss);
        // Bodies first, so obstacles in front of them know to let them show through.
        for kind in [MeshKind::Body, MeshKind::Obstacle, MeshKind::Plane] {
            for p in primitives {
                if let Primitive::Surface(mesh) = p {
                    if mesh.kind == kind {
                        rasterise_mesh(&mut r, view, ss as f32, mesh, lighting);
                    }
                }
            }
        }
        let bytes = r.resolve(ss);
        if let Some(size) = tiny_skia::IntSize::from_wh(frame.width(), frame.height()) {
            if let Some(layer) = Pixmap::from_vec(bytes, size) {
                frame.pixmap.draw_pixmap(
                    0,
                    0,
                    layer.as_ref(),
                    &PixmapPaint::default(),
                    Transform::identity(),
                    None,
                );
            }
        }
        raster = Some(r);
    }
    for p in primitives {
        match p {
            Primitive::Line {
                layer: Layer::Over, ..
            } => draw_line(frame, view, raster.as_ref(), ss, p, ui),
            Primitive::Arrow {
                tail,
                tip,
                colour,
                width,
                depth_test,
            } => {
                let (t, h) = (view.project(tail), view.project(tip));
                if *depth_test && raster.is_some() {
                    // The visible parts of the shaft, and the head if its point shows.
                    let shaft = Primitive::Line {
                        a: *tail,
                        b: *tip,
                        colour: *colour,
                        alpha: 1.0,
                        width: *width,
                        layer: Layer::Over,
                        depth_test: true,
                    };
                    let Some((base, path)) = arrow_head(h, t, ui) else {
                        continue; // too short to see
                    };
                    draw_line_to(frame, view, raster.as_ref(), ss, &shaft, ui, Some(base));
                    if visible(raster.as_ref(), ss, view, h) {
                        let paint = paint_of(*colour, 1.0);
                        frame.pixmap.fill_path(
                            &path,
                            &paint,
                            FillRule::Winding,
                            Transform::identity(),
                            None,
                        );
                    }
                    continue;
                }
                draw_arrow(frame, t, h, *colour, *width * ui, ui);
            }
            Primitive::Support {
                at,
                direction,
                depth_test,
            } => {
                let p = view.project(at);
                if *depth_test && !visible(raster.as_ref(), ss, view, p) {
                    continue;
                }
                let step = 10.0 / view.pixels_per_metre().max(1e-300);
                let q = view.project(&(at + direction * step));
                draw_support(frame, p, q, ui);
            }
            Primitive::Clamp { at, depth_test } => {
                let p = view.project(at);
                if *depth_test && !visible(raster.as_ref(), ss, view, p) {
                    continue;
                }
                let h = 3.5 * ui;
                if let Some(rect) = tiny_skia::Rect::from_xywh(p[0] - h, p[1] - h, 2.0 * h, 2.0 * h)
                {
                    let paint = paint_of(crate::render::colour_scale::SUPPORT_TEAL, 1.0);
                    frame
                        .pixmap
                        .fill_rect(rect, &paint, Transform::identity(), None);
                }
            }
            _ => {}
        }
    }
}

fn rasterise_mesh(r: &mut Rasteriser, view: &View, ss: f32, mesh: &Mesh, lighting: &Lighting) {
    let projected: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| {
            let q = view.project(p);
            [q[0] * ss, q[1] * ss, q[2]]
        })
        .collect();
    let grey = Rgb(0.7, 0.7, 0.7);
    for (t, n) in mesh.triangles.iter().zip(&mesh.normals) {
        if t.iter().any(|&i| i >= projected.len()) {
            continue;
        }
        let vertex = |k: usize| {
            let i = t[k];
            let c = mesh.colours.get(i).copied().unwrap_or(grey);
            RasterVertex {
                position: projected[i],
                normal: view.to_camera(&n[k]),
                colour: [c.0, c.1, c.2],
            }
        };
        r.triangle_of(&[vertex(0), vertex(1), vertex(2)], lighting, mesh.kind);
    }
}

/// Whether the projected point `p` is in front of (or on) the surfaces.
fn visible(raster: Option<&Rasteriser>, ss: usize, view: &View, p: [f32; 3]) -> bool {
    let Some(r) = raster else { return true };
    let (x, y) = (p[0] * ss as f32, p[1] * ss as f32);
    let mut deepest = f32::NEG_INFINITY;
    for dy in [-1.5f32, 0.0, 1.5] {
        for dx in [-1.5f32, 0.0, 1.5] {
            deepest = deepest.max(r.depth_at(x + dx, y + dy));
        }
    }
    p[2] <= deepest + view.depth_epsilon()
}

fn stroke(width: f32) -> Stroke {
    Stroke {
        width,
        line_cap: LineCap::Round,
        ..Stroke::default()
    }
}

fn paint_of(colour: Rgb, alpha: f32) -> Paint<'static> {
    let mut paint = Paint::default();
    paint.set_color(colour.with_alpha(alpha));
    paint.anti_alias = true;
    paint
}

fn stroke_segments(
    frame: &mut Frame,
    segments: &[([f32; 2], [f32; 2])],
    paint: &Paint,
    width: f32,
) {
    let mut pb = PathBuilder::new();
    for (a, b) in segments {
        pb.move_to(a[0], a[1]);
        pb.line_to(b[0], b[1]);
    }
    if let Some(path) = pb.finish() {
        frame
            .pixmap
            .stroke_path(&path, paint, &stroke(width), Transform::identity(), None);
    }
}

fn draw_line(
    frame: &mut Frame,
    view: &View,
    raster: Option<&Rasteriser>,
    ss: usize,
    p: &Primitive,
    ui: f32,
) {
    draw_line_to(frame, view, raster, ss, p, ui, None);
}

/// Draw a line primitive; `end`: stop at this projected point instead of at `b`.
fn draw_line_to(
    frame: &mut Frame,
    view: &View,
    raster: Option<&Rasteriser>,
    ss: usize,
    p: &Primitive,
    ui: f32,
    end: Option<[f32; 3]>,
) {
    let Primitive::Line {
        a,
        b,
        colour,
        alpha,
        width,
        depth_test,
        ..
    } = p
    else {
        return;
    };
    let pa = view.project(a);
    let pb = end.unwrap_or_else(|| view.project(b));
    let paint = paint_of(*colour, *alpha);
    let width = (*width * ui).max(0.5);
    if !depth_test || raster.is_none() {
        stroke_segments(frame, &[([pa[0], pa[1]], [pb[0], pb[1]])], &paint, width);
        return;
    }
    // Split into pieces of a few pixels; keep the runs of visible pieces.
    let len = ((pb[0] - pa[0]).powi(2) + (pb[1] - pa[1]).powi(2)).sqrt();
    let n = ((len / 4.0).ceil() as usize).clamp(1, 4096);
    let at = |t: f32| {
        [
            pa[0] + (pb[0] - pa[0]) * t,
            pa[1] + (pb[1] - pa[1]) * t,
            pa[2] + (pb[2] - pa[2]) * t,
        ]
    };
    let mut runs = Vec::new();
    let mut start: Option<f32> = None;
    for k in 0..n {
        let t0 = k as f32 / n as f32;
        let mid = (k as f32 + 0.5) / n as f32;
        let seen = visible(raster, ss, view, at(mid));
        match (seen, start) {
            (true, None) => start = Some(t0),
            (false, Some(s)) => {
                runs.push((s, t0));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        runs.push((s, 1.0));
    }
    let segments: Vec<([f32; 2], [f32; 2])> = runs
        .iter()
        .map(|&(s, e)| {
            let (p, q) = (at(s), at(e));
            ([p[0], p[1]], [q[0], q[1]])
        })
        .collect();
    stroke_segments(frame, &segments, &paint, width);
}

/// The head of an arrow pointing at `tip` from `tail` (projected): where the shaft stops
/// and the filled triangle; `None` when the arrow is too short to see.
fn arrow_head(tip: [f32; 3], tail: [f32; 3], ui: f32) -> Option<([f32; 3], tiny_skia::Path)> {
    let (dx, dy) = (tip[0] - tail[0], tip[1] - tail[1]);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 1.5 || !len.is_finite() {
        return None;
    }
    let (ux, uy) = (dx / len, dy / len);
    let head = (14.0 * ui).min(len * 0.45);
    let half = head * 0.4;
    let base = [tip[0] - ux * head, tip[1] - uy * head];
    let mut pb = PathBuilder::new();
    pb.move_to(tip[0], tip[1]);
    pb.line_to(base[0] - uy * half, base[1] + ux * half);
    pb.line_to(base[0] + uy * half, base[1] - ux * half);
    pb.close();
    let t = head / len;
    let shaft_end = [
        base[0] + ux * 0.5,
        base[1] + uy * 0.5,
        tip[2] + (tail[2] - tip[2]) * t,
    ];
    pb.finish().map(|p| (shaft_end, p))
}

fn draw_arrow(frame: &mut Frame, tail: [f32; 3], tip: [f32; 3], colour: Rgb, width: f32, ui: f32) {
    let Some((base, path)) = arrow_head(tip, tail, ui) else {
        return;
    };
    let paint = paint_of(colour, 1.0);
    stroke_segments(
        frame,
        &[([tail[0], tail[1]], [base[0], base[1]])],
        &paint,
        width,
    );
    frame.pixmap.fill_path(
        &path,
        &paint,
        FillRule::Winding,
        Transform::identity(),
        None,
    );
}

/// A support mark at `p` for the held direction pointing from `p` to `q` (projected).
fn draw_support(frame: &mut Frame, p: [f32; 3], q: [f32; 3], ui: f32) {
    let size = SUPPORT_SIZE * ui;
    let paint = paint_of(crate::render::colour_scale::SUPPORT_TEAL, 1.0);
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let len = (dx * dx + dy * dy).sqrt();
    if len < 0.2 * 10.0 || !len.is_finite() {
        // Held along the line of sight: a small ring.
        let mut pb = PathBuilder::new();
        pb.push_circle(p[0], p[1], size * 0.3);
        if let Some(path) = pb.finish() {
            frame.pixmap.stroke_path(
                &path,
                &paint,
                &stroke(1.6 * ui),
                Transform::identity(),
                None,
            );
        }
        return;
    }
    let (ux, uy) = (dx / len, dy / len);
    // The bar sits on the far side of the held direction, across it.
    let c = [p[0] - ux * size * 0.35, p[1] - uy * size * 0.35];
    let (px, py) = (-uy, ux);
    let h = size * 0.6;
    let a = [c[0] - px * h, c[1] - py * h];
    let b = [c[0] + px * h, c[1] + py * h];
    let mut segments = vec![(a, b)];
    for k in 0..4 {
        let t = -h + (k as f32 + 0.5) * (2.0 * h / 4.0);
        let s = [c[0] + px * t, c[1] + py * t];
        let e = [
            s[0] - ux * size * 0.35 - px * size * 0.3,
            s[1] - uy * size * 0.35 - py * size * 0.3,
        ];
        segments.push((s, e));
    }
    stroke_segments(frame, &segments[..1], &paint, 3.2 * ui);
    stroke_segments(frame, &segments[1..], &paint, 1.4 * ui);
}

/// A filled region: `loops` (world points) filled even-odd in `fill`, outlined in `edge`.
fn draw_region(
    frame: &mut Frame,
    view: &View,
    loops: &[Vec<Vector3<Real>>],
    fill: Rgb,
    edge: Rgb,
    ui: f32,
) {
    let mut pb = PathBuilder::new();
    for l in loops {
        for (i, p) in l.iter().enumerate() {
            let q = view.project(p);
            if i == 0 {
                pb.move_to(q[0], q[1]);
            } else {
                pb.line_to(q[0], q[1]);
            }
        }
        pb.close();
    }
    let Some(path) = pb.finish() else { return };
    frame.pixmap.fill_path(
        &path,
        &paint_of(fill, 1.0),
        FillRule::EvenOdd,
        Transform::identity(),
        None,
    );
    frame.pixmap.stroke_path(
        &path,
        &paint_of(edge, 1.0),
        &stroke(1.5 * ui),
        Transform::identity(),
        None,
    );
}
