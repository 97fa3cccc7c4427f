//! GIF clips: [`Raster`] frames written one by one with the `gif` crate.
//!
//! Every frame uses one fixed global palette, a 6 × 6 × 6 colour cube
//! (index `36 r + 6 g + b`, each level a sixth of the range), so colours do
//! not flicker between frames and no frame is quantised on its own. A pixel
//! whose index did not change since the previous frame is written as the
//! transparent index 216 (the frame keeps what was there), which leaves the
//! still parts of a scene — the ground, a sleeping pile — out of every frame
//! after the first and keeps clips small.

use std::io::Write;

use gif::{DisposalMethod, Encoder, Frame, Repeat};

use crate::RenderError;
use crate::raster::Raster;

/// Colours of the cube (6 levels per channel).
const LEVELS: usize = 6;
/// The transparent index ("unchanged").
const UNCHANGED: u8 = (LEVELS * LEVELS * LEVELS) as u8;

fn palette() -> Vec<u8> {
    let mut p = Vec::with_capacity(3 * 256);
    for r in 0..LEVELS {
        for g in 0..LEVELS {
            for b in 0..LEVELS {
                for c in [r, g, b] {
                    p.push((c * 255 / (LEVELS - 1)) as u8);
                }
            }
        }
    }
    // The transparent entry and padding to 256.
    while p.len() < 3 * 256 {
        p.push(0);
    }
    p
}

fn index_of(r: u8, g: u8, b: u8) -> u8 {
    let q = |c: u8| (u16::from(c) * (LEVELS as u16 - 1) + 127) / 255;
    (q(r) * 36 + q(g) * 6 + q(b)) as u8
}

/// A GIF being written frame by frame.
pub struct GifWriter<W: Write> {
    encoder: Encoder<W>,
    width: u16,
    height: u16,
    delay_cs: u16,
    previous: Option<Vec<u8>>,
    frames: usize,
}

impl<W: Write> GifWriter<W> {
    /// A looping GIF of `width × height` pixels showing each frame for
    /// `delay_cs` hundredths of a second (2 gives 50 frames per second).
    /// Errors on a size above 65,535 px.
    pub fn new(out: W, width: u32, height: u32, delay_cs: u16) -> Result<Self, RenderError> {
        let size = RenderError::Size { width, height };
        let w = u16::try_from(width).map_err(|_| size.clone())?;
        let h = u16::try_from(height).map_err(|_| size)?;
        let mut encoder =
            Encoder::new(out, w, h, &palette()).map_err(|e| RenderError::Encode(e.to_string()))?;
        encoder
            .set_repeat(Repeat::Infinite)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        Ok(GifWriter {
            encoder,
            width: w,
            height: h,
            delay_cs,
            previous: None,
            frames: 0,
        })
    }

    /// Appends a frame; the picture must have the GIF's size.
    pub fn add(&mut self, raster: &Raster) -> Result<(), RenderError> {
        let (w, h) = (raster.camera.width, raster.camera.height);
        if (w, h) != (u32::from(self.width), u32::from(self.height)) {
            return Err(RenderError::Size {
                width: w,
                height: h,
            });
        }
        let rgba = raster.rgba();
        let indices: Vec<u8> = rgba
            .chunks_exact(4)
            .map(|p| index_of(p[0], p[1], p[2]))
            .collect();
        let pixels = match &self.previous {
            Some(prev) => indices
                .iter()
                .zip(prev)
                .map(|(&i, &p)| if i == p { UNCHANGED } else { i })
                .collect(),
            None => indices.clone(),
        };
        let mut frame = Frame {
            width: self.width,
            height: self.height,
            delay: self.delay_cs,
            dispose: DisposalMethod::Keep,
            transparent: self.previous.as_ref().map(|_| UNCHANGED),
            ..Frame::default()
        };
        frame.buffer = std::borrow::Cow::Owned(pixels);
        self.encoder
            .write_frame(&frame)
            .map_err(|e| RenderError::Encode(e.to_string()))?;
        self.previous = Some(indices);
        self.frames += 1;
        Ok(())
    }

    /// Frames written so far.
    #[must_use]
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Finishes the file and gives back the writer.
    pub fn finish(self) -> Result<W, RenderError> {
        self.encoder
            .into_inner()
            .map_err(|e| RenderError::Encode(e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_round_trips_the_cube() {
        let p = palette();
        assert_eq!(p.len(), 768);
        for i in 0..216usize {
            let (r, g, b) = (p[3 * i], p[3 * i + 1], p[3 * i + 2]);
            assert_eq!(index_of(r, g, b) as usize, i);
        }
    }
}
