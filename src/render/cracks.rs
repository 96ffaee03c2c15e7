//! Broken members as drawn: a short red mark at each broken member's place, so a crack
//! shows even where the gap it leaves is too narrow to see.

use crate::render::colour_scale::CRACK_RED;
use crate::render::deformed_body::DeformedBody;
use crate::render::{Layer, Primitive};

/// The part of a broken member's length its mark covers, centred on the member.
pub const CRACK_MARK: f64 = 0.5;

/// A red line over the middle [`CRACK_MARK`] of each broken member of `body` (between its
/// drawn, deformed ends), `width` pixels wide; `depth_test`: hidden where behind a surface
/// (3D bodies with patches).
pub fn crack_marks(body: &DeformedBody, width: f32, depth_test: bool) -> Vec<Primitive> {
    let lo = (1.0 - CRACK_MARK) / 2.0;
    body.model
        .members
        .iter()
        .zip(&body.broken)
        .filter(|(_, broken)| **broken)
        .map(|(m, _)| {
            let (a, b) = (body.at(m[0]), body.at(m[1]));
            Primitive::Line {
                a: a + (b - a) * lo,
                b: a + (b - a) * (1.0 - lo),
                colour: CRACK_RED,
                alpha: 1.0,
                width,
                layer: Layer::Over,
                depth_test,
            }
        })
        .collect()
}
