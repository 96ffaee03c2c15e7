//! The furniture of a frame: its layout, the colour bar and the labels.

use crate::render::colour_scale::{
    colour_at, format_si, si_unit, BLACK, CONTACT_ORANGE, FORCE_BLUE, INK, OBSTACLE_FILL,
    SLIP_MAGENTA, STICK_GREEN, SUPPORT_TEAL,
};
use crate::render::text::{draw_text, text_width};
use crate::render::{pace_label, Frame, Rgb};
use crate::Real;
use tiny_skia::{FillRule, LineCap, Paint, PathBuilder, Rect, Stroke, Transform};

/// Where things go on a frame: the drawing's viewport and the size of the furniture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layout {
    /// Scale of text and marks: 1 at 720 pixels of frame height.
    pub ui: f32,
    /// The rectangle the model is fitted into: [x0, y0, x1, y1], pixels.
    pub viewport: [Real; 4],
    /// Whether a colour bar is drawn on the right.
    pub colour_bar: bool,
}

/// Scale of text, marks and line widths on a `width` × `height` frame: 1 at 1280 × 720,
/// never below 0.7 so that text stays readable on small frames.
pub fn ui_scale(width: u32, height: u32) -> f32 {
    (height.min(width.saturating_mul(9) / 16) as f32 / 720.0).max(0.7)
}

impl Layout {
    /// The layout of a `width` × `height` frame, with or without a colour bar.
    pub fn new(width: u32, height: u32, colour_bar: bool) -> Self {
        let ui = ui_scale(width, height);
        let (w, h) = (width as Real, height as Real);
        let u = ui as Real;
        let right = if colour_bar { 220.0 * u } else { 40.0 * u };
        let mut viewport = [40.0 * u, 100.0 * u, w - right, h - 60.0 * u];
        // A frame too small for the furniture: the drawing gets the whole frame.
        if viewport[2] - viewport[0] < 0.2 * w || viewport[3] - viewport[1] < 0.2 * h {
            viewport = [0.0, 0.0, w, h];
        }
        Layout {
            ui,
            viewport,
            colour_bar,
        }
    }
}

/// The text and scales around the drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct Caption {
    /// Scene name.
    pub scene: String,
    /// Step drawn.
    pub step: usize,
    /// Last stored step.
    pub last_step: usize,
    /// Load factor of the step.
    pub load_factor: Real,
    /// What the load factor is called: "load factor", or "step fraction" when it is not what
    /// the schedules say ([`crate::scene::load_name`]).
    pub load_name: &'static str,
    /// Time of the state drawn, s (a dynamic scene: the title shows it instead of the load
    /// factor).
    pub time: Option<Real>,
    /// The slow-down of the GIF the frame is in (a dynamic run, see
    /// [`crate::render::timed_delays`]): the title states it after the time.
    pub gif_slowdown: Option<Real>,
    /// Largest displacement at this step, m.
    pub max_displacement: Real,
    /// Overloaded members at this step.
    pub overloaded: usize,
    /// Broken members so far (`None`: nothing in the run can break).
    pub broken: Option<usize>,
    /// Whether the step is the state a structure collapsed in (the run's last: its title
    /// says so).
    pub collapse: bool,
    /// The member stress of largest magnitude at this step, Pa, and its ratio to that
    /// member's strength when it has one.
    pub peak_stress: Option<(Real, Option<Real>)>,
    /// Displacement magnification.
    pub magnification: Real,
    /// The magnification and colour range are shared by this many variants of a sweep
    /// (stated after the magnification); `None`: the run's own.
    pub shared_by: Option<usize>,
    /// Colour bar: (title, limit in Pa) when colouring by stress.
    pub stress_bar: Option<(String, Real)>,
    /// Largest applied force over the run, N (0: no force legend).
    pub max_force: Real,
    /// Largest contact force over the run, N (0: no contact legend).
    pub max_contact: Real,
    /// Whether the run has friction forces (their legend: sticking and slipping).
    pub friction: bool,
    /// Whether some body has supports (their legend).
    pub supports: bool,
    /// Whether the run has obstacles (their legend).
    pub obstacles: bool,
}

/// How a legend entry's sample is drawn.
enum Swatch {
    /// A thick line in a colour.
    Line(Rgb),
    /// A support mark.
    Support,
    /// A filled square in a colour.
    Block(Rgb),
    /// An arrow in a colour.
    Arrow(Rgb),
}

fn fmt_number(v: Real) -> String {
    let s = if (v == v.round() && v.abs() < 1e6) || v.abs() >= 100.0 {
        format!("{v:.0}")
    } else if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    };
    s.replace('-', "−")
}

/// The caption's title line: the scene, then `t = 1.20 ms, shown 10× slower  ·  frame k of n`
/// for a dynamic run (the GIF's pace when it has one, see [`pace_label`]), else the step and
/// its load factor, and "collapsed" on the state a structure collapsed in.
pub fn title(c: &Caption) -> String {
    match c.time {
        Some(t) => {
            let pace = c
                .gif_slowdown
                .map_or(String::new(), |s| format!(", {}", pace_label(s)));
            format!(
                "{}  ·  t = {}{pace}  ·  frame {} of {}",
                c.scene,
                format_si(t, "s"),
                c.step,
                c.last_step
            )
        }
        None => format!(
            "{}  ·  step {} of {}  ·  {} {}{}",
            c.scene,
            c.step,
            c.last_step,
            c.load_name,
            fmt_load(c.load_factor),
            if c.collapse { "  ·  collapsed" } else { "" }
        ),
    }
}

/// Draw the caption (scene, step, load factor), the magnification, the stress colour bar
/// and the legend onto `frame`.
pub fn draw_overlay(frame: &mut Frame, layout: &Layout, c: &Caption) {
    let ui = layout.ui;
    let (w, h) = (frame.width() as f32, frame.height() as f32);
    let big = 26.0 * ui;
    let small = 17.0 * ui;
    let x = 40.0 * ui;
    let title = title(c);
    draw_text(&mut frame.pixmap, &title, x, 46.0 * ui, big, INK);
    let mut sub = format!("max |u| = {}", format_si(c.max_displacement, "m"));
    sub.push_str(&format!(
        "  ·  {} overloaded member{}",
        c.overloaded,
        if c.overloaded == 1 { "" } else { "s" }
    ));
    if let Some(n) = c.broken {
        sub.push_str(&format!("  ·  {n} broken"));
    }
    if let Some((peak, ratio)) = c.peak_stress {
        let signed = if peak > 0.0 {
            format!("+{}", format_si(peak, "Pa"))
        } else {
            format_si(peak, "Pa").replace('-', "−")
        };
        sub.push_str(&format!("  ·  peak member stress {signed}"));
        if let Some(r) = ratio {
            sub.push_str(&format!(" ({:.0}% of its strength)", 100.0 * r));
        }
    }
    draw_text(
        &mut frame.pixmap,
        &sub,
        x,
        76.0 * ui,
        small,
        Rgb(0.35, 0.35, 0.38),
    );
    let mag = if (c.magnification - 1.0).abs() < 1e-12 {
        "displacements to scale (×1)".to_string()
    } else {
        format!(
            "displacements drawn ×{}",
            fmt_magnification(c.magnification)
        )
    };
    let mag = match c.shared_by {
        Some(n) => format!("{mag}  ·  {}", shared_note(n, c.stress_bar.is_some())),
        None => mag,
    };
    draw_text(&mut frame.pixmap, &mag, x, h - 24.0 * ui, small, INK);

    if let Some((bar_title, limit)) = &c.stress_bar {
        let x0 = w - 200.0 * ui;
        let bw = 22.0 * ui;
        let top = 130.0 * ui;
        let bottom = (h - 330.0 * ui).max(top + 60.0 * ui);
        let (div, unit) = si_unit(*limit, "Pa");
        // "mean member stress at nodes": the quantity, then where and the unit below it.
        let (what, place) = match bar_title.split_once(" at ") {
            Some((what, place)) => (what.to_string(), format!("at {place} ({unit})")),
            None => (bar_title.clone(), format!("({unit})")),
        };
        draw_text(
            &mut frame.pixmap,
            &what,
            x0 - 10.0 * ui,
            top - 34.0 * ui,
            small,
            INK,
        );
        draw_text(
            &mut frame.pixmap,
            &place,
            x0 - 10.0 * ui,
            top - 14.0 * ui,
            small * 0.9,
            Rgb(0.35, 0.35, 0.38),
        );
        let rows = (bottom - top).ceil() as usize;
        for r in 0..rows {
            let t = 1.0 - r as f32 / (rows - 1).max(1) as f32;
            let mut paint = Paint::default();
            paint.set_color(colour_at(t).with_alpha(1.0));
            if let Some(rect) = Rect::from_xywh(x0, top + r as f32, bw, 1.0) {
                frame
                    .pixmap
                    .fill_rect(rect, &paint, Transform::identity(), None);
            }
        }
        let mut ink = Paint::default();
        ink.set_color(INK.with_alpha(1.0));
        ink.anti_alias = true;
        let mut pb = PathBuilder::new();
        if let Some(rect) = Rect::from_xywh(x0, top, bw, bottom - top) {
            pb.push_rect(rect);
        }
        for k in 0..5 {
            let y = top + (bottom - top) * k as f32 / 4.0;
            pb.move_to(x0 + bw, y);
            pb.line_to(x0 + bw + 6.0 * ui, y);
            let v = limit * (1.0 - k as Real / 2.0) / div;
            let label = if k == 2 {
                "0".to_string()
            } else if v > 0.0 {
                format!("+{}", fmt_number(v))
            } else {
                fmt_number(v)
            };
            draw_text(
                &mut frame.pixmap,
                &label,
                x0 + bw + 10.0 * ui,
                y + 6.0 * ui,
                small,
                INK,
            );
        }
        if let Some(path) = pb.finish() {
            let s = Stroke {
                width: 1.0 * ui,
                ..Stroke::default()
            };
            frame
                .pixmap
                .stroke_path(&path, &ink, &s, Transform::identity(), None);
        }
        let note = small * 0.85;
        let grey = Rgb(0.35, 0.35, 0.38);
        draw_text(
            &mut frame.pixmap,
            "tension",
            x0 + bw + 10.0 * ui + text_width("+0.00", small) + 8.0 * ui,
            top + 6.0 * ui,
            note,
            grey,
        );
        draw_text(
            &mut frame.pixmap,
            "compression",
            x0 - 10.0 * ui,
            bottom + 24.0 * ui,
            note,
            grey,
        );

        // Legend.
        let mut entries: Vec<(Swatch, String, Option<String>)> =
            vec![(Swatch::Line(BLACK), "overloaded".to_string(), None)];
        if c.supports {
            entries.push((Swatch::Support, "support".to_string(), None));
        }
        if c.obstacles {
            entries.push((Swatch::Block(OBSTACLE_FILL), "obstacle".to_string(), None));
        }
        if c.max_force > 0.0 {
            entries.push((
                Swatch::Arrow(FORCE_BLUE),
                "applied force".to_string(),
                Some(format!("(largest {})", format_si(c.max_force, "N"))),
            ));
        }
        if c.max_contact > 0.0 {
            entries.push((
                Swatch::Arrow(CONTACT_ORANGE),
                "contact force".to_string(),
                Some(format!("(largest {})", format_si(c.max_contact, "N"))),
            ));
        }
        if c.friction {
            for (label, colour) in [
                ("friction, sticking", STICK_GREEN),
                ("friction, slipping", SLIP_MAGENTA),
            ] {
                entries.push((Swatch::Arrow(colour), label.to_string(), None));
            }
        }
        let mut y = bottom + 58.0 * ui;
        let grey = Rgb(0.35, 0.35, 0.38);
        for (swatch, label, sub) in entries {
            draw_swatch(frame, &swatch, x0, y, ui);
            draw_text(
                &mut frame.pixmap,
                &label,
                x0 + 44.0 * ui,
                y + 6.0 * ui,
                small,
                INK,
            );
            y += 26.0 * ui;
            if let Some(sub) = sub {
                draw_text(
                    &mut frame.pixmap,
                    &sub,
                    x0 + 44.0 * ui,
                    y + 2.0 * ui,
                    small * 0.8,
                    grey,
                );
                y += 22.0 * ui;
            }
        }
    }
}

/// The sample of a legend entry at (`x`, `y`), 34 × `ui` pixels wide.
fn draw_swatch(frame: &mut Frame, swatch: &Swatch, x: f32, y: f32, ui: f32) {
    let paint_of = |colour: Rgb| {
        let mut paint = Paint::default();
        paint.set_color(colour.with_alpha(1.0));
        paint.anti_alias = true;
        paint
    };
    let line = |frame: &mut Frame, colour: Rgb, a: (f32, f32), b: (f32, f32), width: f32| {
        let mut pb = PathBuilder::new();
        pb.move_to(a.0, a.1);
        pb.line_to(b.0, b.1);
        if let Some(path) = pb.finish() {
            let s = Stroke {
                width,
                line_cap: LineCap::Round,
                ..Stroke::default()
            };
            frame
                .pixmap
                .stroke_path(&path, &paint_of(colour), &s, Transform::identity(), None);
        }
    };
    match swatch {
        Swatch::Line(colour) => line(frame, *colour, (x, y), (x + 34.0 * ui, y), 5.0 * ui),
        Swatch::Support => {
            line(
                frame,
                SUPPORT_TEAL,
                (x + 4.0 * ui, y - 4.0 * ui),
                (x + 30.0 * ui, y - 4.0 * ui),
                3.2 * ui,
            );
            for k in 0..4 {
                let sx = x + (7.0 + 6.5 * k as f32) * ui;
                line(
                    frame,
                    SUPPORT_TEAL,
                    (sx, y - 4.0 * ui),
                    (sx - 5.0 * ui, y + 5.0 * ui),
                    1.4 * ui,
                );
            }
        }
        Swatch::Block(colour) => {
            if let Some(rect) = Rect::from_xywh(x, y - 8.0 * ui, 34.0 * ui, 16.0 * ui) {
                frame
                    .pixmap
                    .fill_rect(rect, &paint_of(*colour), Transform::identity(), None);
            }
        }
        Swatch::Arrow(colour) => legend_arrow(frame, x, y, ui, *colour),
    }
}

fn legend_arrow(frame: &mut Frame, x: f32, y: f32, ui: f32, colour: Rgb) {
    let mut paint = Paint::default();
    paint.set_color(colour.with_alpha(1.0));
    paint.anti_alias = true;
    let mut pb = PathBuilder::new();
    pb.move_to(x, y);
    pb.line_to(x + 22.0 * ui, y);
    if let Some(path) = pb.finish() {
        let s = Stroke {
            width: 3.0 * ui,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        frame
            .pixmap
            .stroke_path(&path, &paint, &s, Transform::identity(), None);
    }
    let mut pb = PathBuilder::new();
    pb.move_to(x + 34.0 * ui, y);
    pb.line_to(x + 21.0 * ui, y - 5.5 * ui);
    pb.line_to(x + 21.0 * ui, y + 5.5 * ui);
    pb.close();
    if let Some(path) = pb.finish() {
        frame.pixmap.fill_path(
            &path,
            &paint,
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

fn fmt_load(f: Real) -> String {
    let s = format!("{f:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() || s == "-" {
        "0".to_string()
    } else {
        s.replace('-', "−")
    }
}

/// What a frame says of a scale shared by `n` variants of a sweep (`colours`: the frame has a
/// stress colour bar).
pub fn shared_note(n: usize, colours: bool) -> String {
    if colours {
        format!("magnification and colour range shared by the sweep's {n} variants")
    } else {
        format!("magnification shared by the sweep's {n} variants")
    }
}

fn fmt_magnification(m: Real) -> String {
    if m >= 1.0 && m == m.round() {
        format!("{m:.0}")
    } else {
        format!("{m:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caption(time: Option<Real>, gif_slowdown: Option<Real>) -> Caption {
        Caption {
            scene: "drop".to_string(),
            step: 3,
            last_step: 60,
            load_factor: 0.05,
            load_name: "load factor",
            time,
            gif_slowdown,
            max_displacement: 0.0,
            overloaded: 0,
            broken: None,
            collapse: false,
            peak_stress: None,
            magnification: 1.0,
            shared_by: None,
            stress_bar: None,
            max_force: 0.0,
            max_contact: 0.0,
            friction: false,
            supports: false,
            obstacles: false,
        }
    }

    #[test]
    fn a_dynamic_frame_title_states_its_time_and_the_gif_pace() {
        assert_eq!(
            title(&caption(Some(1.2e-3), Some(1000.0))),
            "drop  ·  t = 1.20 ms, shown 1,000× slower  ·  frame 3 of 60"
        );
        assert_eq!(
            title(&caption(Some(0.5), Some(1.0))),
            "drop  ·  t = 500 ms, real time  ·  frame 3 of 60"
        );
        // PNG frames without a GIF: the time alone.
        assert_eq!(
            title(&caption(Some(1.2e-3), None)),
            "drop  ·  t = 1.20 ms  ·  frame 3 of 60"
        );
        // A quasi-static run: the load factor.
        assert_eq!(
            title(&caption(None, None)),
            "drop  ·  step 3 of 60  ·  load factor 0.05"
        );
    }

    #[test]
    fn a_collapse_frame_title_says_collapsed() {
        let c = Caption {
            collapse: true,
            ..caption(None, None)
        };
        assert_eq!(
            title(&c),
            "drop  ·  step 3 of 60  ·  load factor 0.05  ·  collapsed"
        );
    }
}
