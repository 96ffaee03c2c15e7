//! Text on frames, set in the bundled DejaVu Sans.

use crate::render::Rgb;
use std::sync::OnceLock;
use tiny_skia::Pixmap;

/// DejaVu Sans cut down to ASCII and a few symbols (licence: `assets/fonts/LICENSE-DejaVu.txt`):
/// the frames' and the plots' font.
pub(crate) const FONT_FILE: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans-subset.ttf");

fn font() -> &'static fontdue::Font {
    static FONT: OnceLock<fontdue::Font> = OnceLock::new();
    FONT.get_or_init(|| {
        fontdue::Font::from_bytes(FONT_FILE, fontdue::FontSettings::default())
            .expect("the bundled font parses (checked by a test)")
    })
}

/// Width of `text` set at `size` pixels per em, pixels.
pub fn text_width(text: &str, size: f32) -> f32 {
    let f = font();
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        if let Some(p) = prev {
            w += f.horizontal_kern(p, c, size).unwrap_or(0.0);
        }
        w += f.metrics(c, size).advance_width;
        prev = Some(c);
    }
    w
}

/// Draw `text` anti-aliased onto `pixmap` with its baseline starting at (`x`, `baseline`),
/// `size` pixels per em, in `colour`.
pub fn draw_text(pixmap: &mut Pixmap, text: &str, x: f32, baseline: f32, size: f32, colour: Rgb) {
    let f = font();
    let (w, h) = (pixmap.width() as i32, pixmap.height() as i32);
    let data = pixmap.data_mut();
    let mut pen = x;
    let mut prev = None;
    let rgb = [colour.0, colour.1, colour.2].map(|c| c.clamp(0.0, 1.0) * 255.0);
    for c in text.chars() {
        if let Some(p) = prev {
            pen += f.horizontal_kern(p, c, size).unwrap_or(0.0);
        }
        let (m, bitmap) = f.rasterize(c, size);
        let left = pen.round() as i32 + m.xmin;
        let top = baseline.round() as i32 - m.height as i32 - m.ymin;
        for gy in 0..m.height as i32 {
            let y = top + gy;
            if y < 0 || y >= h {
                continue;
            }
            for gx in 0..m.width as i32 {
                let x = left + gx;
                if x < 0 || x >= w {
                    continue;
                }
                let a = bitmap[(gy * m.width as i32 + gx) as usize] as f32 / 255.0;
                if a <= 0.0 {
                    continue;
                }
                let o = ((y * w + x) * 4) as usize;
                // Source over, premultiplied.
                for k in 0..3 {
                    let d = data[o + k] as f32;
                    data[o + k] = (rgb[k] * a + d * (1.0 - a)).round() as u8;
                }
                let d = data[o + 3] as f32;
                data[o + 3] = (255.0 * a + d * (1.0 - a)).round() as u8;
            }
        }
        pen += m.advance_width;
        prev = Some(c);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bundled_font_draws_ink() {
        let mut p = Pixmap::new(80, 30).unwrap();
        p.fill(tiny_skia::Color::WHITE);
        draw_text(&mut p, "σ 1.0 MPa ×", 2.0, 20.0, 14.0, Rgb(0.0, 0.0, 0.0));
        let dark = p.pixels().iter().filter(|c| c.red() < 100).count();
        assert!(dark > 30, "{dark}");
        assert!(text_width("MPa", 14.0) > 20.0);
    }
}
