//! The animated GIF of a run: one palette for all frames, frames indexed and compressed on
//! any thread, written in order.

use crate::render::{Frame, RenderError};
use rayon::prelude::*;

/// Seconds each frame shows, and the hold on the last frame (hundredths of a second).
const FRAME_DELAY: u16 = 50;
pub(crate) const LAST_FRAME_DELAY: u16 = 200;

/// Bits per channel of the colour look-up table (32³ cells).
const LUT_BITS: u32 = 5;

/// At most this many pixels train the palette (spread evenly over the sample frames).
const TRAINING_PIXELS: usize = 100_000;

fn encode_error(e: impl std::fmt::Display) -> RenderError {
    RenderError::Encode {
        what: "GIF".to_string(),
        message: e.to_string(),
    }
}

/// The 256 colours of an animation, computed once (NeuQuant over sample frames) instead of
/// per frame, and a look-up table from colour to palette index (NeuQuant's nearest colour of
/// each cell's centre), so that indexing a frame is
/// one table look-up per pixel.
pub struct GifPalette {
    /// RGB bytes of the 256 colours.
    colours: Vec<u8>,
    /// Palette index of each 5-bit-per-channel colour cell.
    lut: Vec<u8>,
    /// Palette indices of pure white and pure black (exact: background, text, overloaded
    /// members).
    white: u8,
    black: u8,
}

impl GifPalette {
    /// The palette of `samples` (frames that show the colours of the run: its first, middle
    /// and last ones). Pure white and pure black are always in it (background, text).
    /// Deterministic: the same frames give the same palette.
    pub fn of_frames(samples: &[&Frame]) -> GifPalette {
        let total: usize = samples.iter().map(|f| f.pixmap.data().len() / 4).sum();
        let stride = total.div_ceil(TRAINING_PIXELS).max(1);
        let mut pixels = Vec::with_capacity(4 * (total / stride + 1));
        for f in samples {
            for px in f.pixmap.data().chunks_exact(4).step_by(stride) {
                pixels.extend_from_slice(&[px[0], px[1], px[2], 255]);
            }
        }
        if pixels.is_empty() {
            pixels.extend_from_slice(&[255, 255, 255, 255]);
        }
        let quant = color_quant::NeuQuant::new(10, 256, &pixels);
        let mut colours = quant.color_map_rgb();
        colours.resize(256 * 3, 0);
        let mut exact = [0u8; 2];
        for (slot, colour) in exact.iter_mut().zip([[255u8, 255, 255], [0, 0, 0]]) {
            let k = quant.index_of(&[colour[0], colour[1], colour[2], 255]);
            colours[3 * k..3 * k + 3].copy_from_slice(&colour);
            *slot = k as u8;
        }
        let [white, black] = exact;
        let cells = 1usize << (3 * LUT_BITS);
        let shift = 8 - LUT_BITS;
        let centre = 1u32 << (shift - 1);
        let lut = (0..cells)
            .into_par_iter()
            .map(|cell| {
                let channel = |k: u32| {
                    (((cell >> (k * LUT_BITS)) as u32 & ((1 << LUT_BITS) - 1)) << shift | centre)
                        as i32
                };
                let (r, g, b) = (channel(2), channel(1), channel(0));
                quant.index_of(&[r as u8, g as u8, b as u8, 255]) as u8
            })
            .collect();
        GifPalette {
            colours,
            lut,
            white,
            black,
        }
    }

    /// The palette index of every pixel of `frame`, after a light ordered (4×4 Bayer) dither
    /// of ±3 levels so that smooth shading shows as fine grain instead of bands (pure white
    /// and black are left alone).
    pub fn index(&self, frame: &Frame) -> Vec<u8> {
        const BAYER: [[i16; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];
        let width = frame.width() as usize;
        let shift = 8 - LUT_BITS;
        frame
            .pixmap
            .data()
            .chunks_exact(4)
            .enumerate()
            .map(|(i, px)| {
                match px[..3] {
                    [255, 255, 255] => return self.white,
                    [0, 0, 0] => return self.black,
                    _ => {}
                }
                let (x, y) = (i % width, i / width);
                let d = (BAYER[y % 4][x % 4] * 2 - 15) * 2 / 5;
                // Frames are opaque: premultiplied bytes are the colour.
                let c = |v: u8| {
                    let v = if v == 255 || v == 0 {
                        v
                    } else {
                        (v as i16 + d).clamp(0, 255) as u8
                    };
                    (v >> shift) as usize
                };
                self.lut[(c(px[0]) << (2 * LUT_BITS)) | (c(px[1]) << LUT_BITS) | c(px[2])]
            })
            .collect()
    }

    /// RGB bytes of the 256 colours.
    pub fn colours(&self) -> &[u8] {
        &self.colours
    }
}

/// One frame indexed in the palette and LZW-compressed, ready to be appended.
pub struct EncodedFrame(gif::Frame<'static>);

/// An animated GIF built in memory with one global palette, looping forever. Frames are
/// encoded with [`GifAnimation::encode`] (on any thread, in any order) and appended in order
/// with [`GifAnimation::push_encoded`].
pub struct GifAnimation {
    encoder: gif::Encoder<Vec<u8>>,
    palette: GifPalette,
    width: u16,
    height: u16,
    frames: usize,
}

impl GifAnimation {
    /// An empty animation of `width` × `height` pixels (at most 65535 each) whose palette is
    /// computed from `samples` (see [`GifPalette::of_frames`]).
    pub fn new(width: u32, height: u32, samples: &[&Frame]) -> Result<Self, RenderError> {
        let (w, h) = (
            u16::try_from(width).map_err(encode_error)?,
            u16::try_from(height).map_err(encode_error)?,
        );
        let palette = GifPalette::of_frames(samples);
        let mut encoder =
            gif::Encoder::new(Vec::new(), w, h, palette.colours()).map_err(encode_error)?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(encode_error)?;
        Ok(GifAnimation {
            encoder,
            palette,
            width: w,
            height: h,
            frames: 0,
        })
    }

    /// `frame` (the animation's size) indexed in the palette and compressed.
    pub fn encode(&self, frame: &Frame) -> Result<EncodedFrame, RenderError> {
        if frame.width() != self.width as u32 || frame.height() != self.height as u32 {
            return Err(encode_error(format!(
                "frame of {}×{} in an animation of {}×{}",
                frame.width(),
                frame.height(),
                self.width,
                self.height
            )));
        }
        let mut f = gif::Frame::from_indexed_pixels(
            self.width,
            self.height,
            self.palette.index(frame),
            None,
        );
        f.make_lzw_pre_encoded();
        Ok(EncodedFrame(f))
    }

    /// Append an encoded frame; `last` holds it longer.
    pub fn push_encoded(&mut self, frame: EncodedFrame, last: bool) -> Result<(), RenderError> {
        self.push_encoded_for(frame, if last { LAST_FRAME_DELAY } else { FRAME_DELAY })
    }

    /// Append an encoded frame shown for `delay` hundredths of a second (a dynamic run's
    /// real time to the next frame, see [`crate::render::timed_delays`]).
    pub fn push_encoded_for(&mut self, frame: EncodedFrame, delay: u16) -> Result<(), RenderError> {
        let mut f = frame.0;
        f.delay = delay;
        self.encoder
            .write_lzw_pre_encoded_frame(&f)
            .map_err(encode_error)?;
        self.frames += 1;
        Ok(())
    }

    /// Encode and append `frame`; `last` holds it longer.
    pub fn push(&mut self, frame: &Frame, last: bool) -> Result<(), RenderError> {
        let encoded = self.encode(frame)?;
        self.push_encoded(encoded, last)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_keeps_white_and_black_exact_and_maps_colours_near() {
        let mut f = Frame::new(64, 32).unwrap();
        // Left half a red, a strip black.
        for y in 0..32 {
            for x in 0..32 {
                let o = 4 * (y * 64 + x);
                f.pixmap.data_mut()[o..o + 4].copy_from_slice(&[200, 30, 40, 255]);
            }
            let o = 4 * (y * 64 + 40);
            f.pixmap.data_mut()[o..o + 4].copy_from_slice(&[0, 0, 0, 255]);
        }
        let p = GifPalette::of_frames(&[&f]);
        let idx = p.index(&f);
        let colour = |i: usize| &p.colours()[3 * idx[i] as usize..3 * idx[i] as usize + 3];
        assert_eq!(colour(63), &[255, 255, 255]);
        assert_eq!(colour(40), &[0, 0, 0]);
        let red = colour(0);
        // Within the dither (±3) and the table's cell (±2) of the colour, per channel.
        for (c, want) in red.iter().zip([200, 30, 40]) {
            assert!((*c as i32 - want).abs() <= 8, "{red:?}");
        }
    }
}
