//! Colours: the stress colour scale (compression blue, tension red) and the fixed colours of the drawing.

use crate::Real;

/// A colour with components from 0 to 1 (sRGB).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb(pub f32, pub f32, pub f32);

impl Rgb {
    /// From 8-bit components.
    pub const fn bytes(r: u8, g: u8, b: u8) -> Rgb {
        Rgb(r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0)
    }

    /// `self` blended towards `other` by `t` (0: self, 1: other).
    pub fn mix(self, other: Rgb, t: f32) -> Rgb {
        Rgb(
            self.0 + (other.0 - self.0) * t,
            self.1 + (other.1 - self.1) * t,
            self.2 + (other.2 - self.2) * t,
        )
    }

    /// Components scaled by `k`.
    pub fn scale(self, k: f32) -> Rgb {
        Rgb(self.0 * k, self.1 * k, self.2 * k)
    }

    /// As tiny-skia's colour with opacity `alpha` (0–1).
    pub fn with_alpha(self, alpha: f32) -> tiny_skia::Color {
        let c = |x: f32| x.clamp(0.0, 1.0);
        tiny_skia::Color::from_rgba(c(self.0), c(self.1), c(self.2), c(alpha))
            .unwrap_or(tiny_skia::Color::BLACK)
    }
}

/// Overloaded members: black, as in the paper.
pub const BLACK: Rgb = Rgb(0.0, 0.0, 0.0);
/// Applied forces: blue, as in the paper.
pub const FORCE_BLUE: Rgb = Rgb::bytes(16, 64, 220);
/// Contact forces.
pub const CONTACT_ORANGE: Rgb = Rgb::bytes(235, 120, 0);
/// Tangential force of a sticking contact.
pub const STICK_GREEN: Rgb = Rgb::bytes(0, 150, 70);
/// Tangential force of a slipping contact.
pub const SLIP_MAGENTA: Rgb = Rgb::bytes(200, 0, 140);
/// The undeformed shape.
pub const GHOST_GREY: Rgb = Rgb::bytes(150, 150, 150);
/// Obstacles in 2D: fill (a warm stone grey, apart from every stress colour) and outline.
pub const OBSTACLE_FILL: Rgb = Rgb::bytes(205, 196, 178);
/// Outline of a 2D obstacle.
pub const OBSTACLE_EDGE: Rgb = Rgb::bytes(120, 110, 92);
/// Obstacles in 3D: the shaded surface's colour.
pub const OBSTACLE_SURFACE: Rgb = Rgb::bytes(190, 180, 160);
/// Support marks: a dark teal, apart from the black of overloaded members.
pub const SUPPORT_TEAL: Rgb = Rgb::bytes(0, 112, 120);
/// Text.
pub const INK: Rgb = Rgb::bytes(30, 30, 34);
/// Members and surfaces with `Colouring::Plain`.
pub const PLAIN: Rgb = Rgb::bytes(96, 104, 118);
/// The mark of a broken member (a crack): brighter than the red end of the stress scale.
pub const CRACK_RED: Rgb = Rgb::bytes(240, 0, 0);
/// Each body's own colour (outline under its members, silhouette of its surface), by body
/// index in turn, so bodies pressed together read as separate; drawn only when a frame has
/// more than one body. Chosen apart from the stress scale, obstacles and arrows.
pub const BODY_COLOURS: [Rgb; 6] = [
    Rgb::bytes(120, 200, 140),
    Rgb::bytes(190, 150, 230),
    Rgb::bytes(240, 200, 80),
    Rgb::bytes(110, 200, 220),
    Rgb::bytes(230, 150, 190),
    Rgb::bytes(170, 170, 90),
];
/// Surfaces with `Colouring::Plain`.
pub const PLAIN_SURFACE: Rgb = Rgb::bytes(178, 190, 208);

/// Moreland's "cool to warm" diverging map, with its middle darkened so that unstressed
/// members stay visible on white: (position, colour).
const DIVERGING: [(f32, Rgb); 5] = [
    (0.0, Rgb::bytes(40, 60, 175)),
    (0.25, Rgb::bytes(110, 150, 235)),
    (0.5, Rgb::bytes(185, 185, 190)),
    (0.75, Rgb::bytes(235, 130, 100)),
    (1.0, Rgb::bytes(170, 10, 35)),
];

/// A symmetric diverging scale for a signed quantity: `-limit` blue, 0 grey, `+limit` red.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColourScale {
    /// The magnitude at the ends of the scale (same unit as the values; > 0).
    pub limit: Real,
}

impl ColourScale {
    /// A scale reaching `limit` at both ends (a zero or non-finite limit becomes 1).
    pub fn new(limit: Real) -> Self {
        ColourScale {
            limit: if limit.is_finite() && limit > 0.0 {
                limit
            } else {
                1.0
            },
        }
    }

    /// Position of `value` on the scale, 0 (−limit) to 1 (+limit), clamped.
    pub fn position(&self, value: Real) -> f32 {
        ((value / self.limit * 0.5 + 0.5) as f32).clamp(0.0, 1.0)
    }

    /// The colour of `value`.
    pub fn colour(&self, value: Real) -> Rgb {
        colour_at(self.position(value))
    }
}

/// The smallest round number (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten) at
/// least `v` (> 0), so that a colour bar's ticks read well.
pub fn round_up(v: Real) -> Real {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let decade = 10f64.powf(v.log10().floor());
    [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .iter()
        .map(|k| k * decade)
        .find(|&r| r >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * decade)
}

/// The diverging map at position `t` (0–1).
pub fn colour_at(t: f32) -> Rgb {
    let t = t.clamp(0.0, 1.0);
    for w in DIVERGING.windows(2) {
        let (t0, c0) = w[0];
        let (t1, c1) = w[1];
        if t <= t1 {
            return c0.mix(c1, (t - t0) / (t1 - t0));
        }
    }
    DIVERGING[DIVERGING.len() - 1].1
}

/// A value range in a readable unit: the SI prefix so that `limit` reads between 1 and 1000.
/// Returns (divisor, prefixed unit), e.g. (1e6, "MPa").
pub fn si_unit(limit: Real, unit: &str) -> (Real, String) {
    let prefixes = [
        (1e12, "T"),
        (1e9, "G"),
        (1e6, "M"),
        (1e3, "k"),
        (1.0, ""),
        (1e-3, "m"),
        (1e-6, "µ"),
        (1e-9, "n"),
    ];
    for (f, p) in prefixes {
        if limit.abs() >= f {
            return (f, format!("{p}{unit}"));
        }
    }
    (1e-9, format!("n{unit}"))
}

/// `value` in `unit` with an SI prefix and 3 significant digits, e.g. "1.23 mm".
pub fn format_si(value: Real, unit: &str) -> String {
    if value == 0.0 || !value.is_finite() {
        return format!("{value} {unit}");
    }
    let (f, u) = si_unit(value, unit);
    let v = value / f;
    let digits = if v.abs() >= 100.0 {
        0
    } else if v.abs() >= 10.0 {
        1
    } else {
        2
    };
    format!("{v:.digits$} {u}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tension_is_red_compression_blue_zero_grey() {
        let s = ColourScale::new(10.0);
        let t = s.colour(10.0);
        let c = s.colour(-10.0);
        let z = s.colour(0.0);
        assert!(t.0 > 0.5 && t.2 < 0.3, "{t:?}");
        assert!(c.2 > 0.5 && c.0 < 0.3, "{c:?}");
        assert!((z.0 - z.2).abs() < 0.05);
    }

    #[test]
    fn si_formatting() {
        assert_eq!(format_si(0.00123, "m"), "1.23 mm");
        assert_eq!(format_si(4.0e6, "Pa"), "4.00 MPa");
        assert_eq!(format_si(250.0, "N"), "250 N");
        assert_eq!(format_si(0.0, "m"), "0 m");
    }
}
