//! One picture: an RGBA pixmap, and its PNG encoding.

use crate::render::{RenderError, Rgb};
use tiny_skia::{Color, Pixmap};

/// One picture: an RGBA pixmap with a white background.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The pixels (premultiplied RGBA, tiny-skia's layout).
    pub pixmap: Pixmap,
}

impl Frame {
    /// A white frame of `width` × `height` pixels.
    pub fn new(width: u32, height: u32) -> Result<Self, RenderError> {
        let mut pixmap = Pixmap::new(width, height).ok_or_else(|| RenderError::Option {
            message: format!(
                "frame size {width}×{height}: give a width and height of at least 1 pixel"
            ),
        })?;
        pixmap.fill(Color::WHITE);
        Ok(Frame { pixmap })
    }

    /// Width, pixels.
    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    /// Height, pixels.
    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// The colour at pixel (x, y) (the frame is opaque).
    pub fn rgb(&self, x: u32, y: u32) -> Option<Rgb> {
        self.pixmap.pixel(x, y).map(|p| {
            let c = p.demultiply();
            Rgb::bytes(c.red(), c.green(), c.blue())
        })
    }

    /// RGBA bytes, row by row (straight alpha).
    pub fn rgba(&self) -> Vec<u8> {
        self.pixmap.clone().take_demultiplied()
    }

    /// The frame as a PNG file.
    pub fn png(&self) -> Result<Vec<u8>, RenderError> {
        self.pixmap.encode_png().map_err(|e| RenderError::Encode {
            what: "PNG".to_string(),
            message: e.to_string(),
        })
    }
}
