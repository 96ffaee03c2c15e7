//! The animated GIF of a run, built frame by frame in memory.

use crate::render::{Frame, RenderError};

/// An animated GIF built frame by frame in memory (each frame with its own 256-colour
/// palette, NeuQuant quantisation), looping forever.
pub struct GifAnimation {
    encoder: gif::Encoder<Vec<u8>>,
    width: u16,
    height: u16,
    frames: usize,
}

/// Seconds each frame shows, and the hold on the last frame (hundredths of a second).
const FRAME_DELAY: u16 = 50;
const LAST_FRAME_DELAY: u16 = 200;

fn encode_error(e: impl std::fmt::Display) -> RenderError {
    RenderError::Encode {
        what: "GIF".to_string(),
        message: e.to_string(),
    }
}

impl GifAnimation {
    /// An empty animation of `width` × `height` pixels (at most 65535 each).
    pub fn new(width: u32, height: u32) -> Result<Self, RenderError> {
        let (w, h) = (
            u16::try_from(width).map_err(encode_error)?,
            u16::try_from(height).map_err(encode_error)?,
        );
        let mut encoder = gif::Encoder::new(Vec::new(), w, h, &[]).map_err(encode_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(encode_error)?;
        Ok(GifAnimation {
            encoder,
            width: w,
            height: h,
            frames: 0,
        })
    }

    /// Append `frame` (same size as the animation); `last` holds it longer.
    pub fn push(&mut self, frame: &Frame, last: bool) -> Result<(), RenderError> {
        if frame.width() != self.width as u32 || frame.height() != self.height as u32 {
            return Err(encode_error(format!(
                "frame of {}×{} in an animation of {}×{}",
                frame.width(),
                frame.height(),
                self.width,
                self.height
            )));
        }
        let mut rgba = frame.rgba();
        dither(&mut rgba, self.width as usize);
        let mut f = gif::Frame::from_rgba_speed(self.width, self.height, &mut rgba, 10);
        f.delay = if last { LAST_FRAME_DELAY } else { FRAME_DELAY };
        self.encoder.write_frame(&f).map_err(encode_error)?;
        self.frames += 1;
        Ok(())
    }

    /// Frames so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// The GIF file's bytes.
    pub fn finish(self) -> Result<Vec<u8>, RenderError> {
        self.encoder.into_inner().map_err(encode_error)
    }
}

/// A light ordered (4×4 Bayer) dither of ±3 levels, so that 256 palette colours show smooth
/// shading as fine grain instead of bands. Deterministic.
fn dither(rgba: &mut [u8], width: usize) {
    const BAYER: [[i16; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
    for (i, px) in rgba.chunks_exact_mut(4).enumerate() {
        let (x, y) = (i % width, i / width);
        let d = (BAYER[y % 4][x % 4] * 2 - 15) * 2 / 5;
        for c in &mut px[..3] {
            // Leave pure white and black alone (background, text, overloaded members).
            if *c != 255 && *c != 0 {
                *c = (*c as i16 + d).clamp(0, 255) as u8;
            }
        }
    }
}
