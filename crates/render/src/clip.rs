//! GIF clips: [`Raster`] frames written one by one with the `gif` crate.
//!
//! Every frame uses one global palette made from the first frame, so
//! colours do not flicker between frames and no frame is quantised on its
//! own:
//!
//! | indices   | what |
//! |-----------|------|
//! | 0–63      | a 4 × 4 × 4 colour cube: the fallback for colours the first frame did not have |
//! | 64–254    | the first frame's colours: all of them when there are at most 191, else 191 found by median cut (weighted by pixel count) |
//! | 255       | transparent: "unchanged" |
//!
//! A pixel takes the nearest palette colour (a cache keeps each colour's
//! answer), so a scene's few fills, outlines, background and their
//! anti-aliased edges keep their exact colours: no banding from a coarse
//! fixed palette. A pixel whose index did not change since the previous
//! frame, or whose shown colour is within 8 levels per channel of its new
//! one, is written as the transparent index (the frame keeps what was
//! there), which leaves the still parts of a scene — the ground, a
//! sleeping pile — out of every frame after the first and keeps clips
//! small.

use std::collections::HashMap;
use std::io::Write;

use gif::{DisposalMethod, Encoder, Frame, Repeat};

use crate::RenderError;
use crate::raster::Raster;

/// Levels per channel of the fallback cube.
const CUBE: usize = 4;
/// Entries of the fallback cube.
const CUBE_LEN: usize = CUBE * CUBE * CUBE;
/// Entries made from the first frame.
const ADAPTIVE: usize = 255 - CUBE_LEN;
/// The transparent index ("unchanged").
const UNCHANGED: u8 = 255;

/// A pixel whose shown colour is within this much (each channel, of 255)
/// of its new colour is left as it was.
const STILL: u8 = 8;

/// An RGB colour packed as `0xRRGGBB`.
type Rgb = u32;

fn pack(r: u8, g: u8, b: u8) -> Rgb {
    (u32::from(r) << 16) | (u32::from(g) << 8) | u32::from(b)
}

fn unpack(c: Rgb) -> [u8; 3] {
    [(c >> 16) as u8, (c >> 8) as u8, c as u8]
}

/// The palette of a clip and the nearest-colour lookup.
struct Palette {
    /// 256 RGB entries.
    colours: Vec<[u8; 3]>,
    /// Colour → index, filled as colours are met.
    cache: HashMap<Rgb, u8>,
}

impl Palette {
    /// The cube, then the colours of `first` (RGBA bytes).
    fn from_frame(first: &[u8]) -> Palette {
        let mut colours: Vec<[u8; 3]> = Vec::with_capacity(256);
        for r in 0..CUBE {
            for g in 0..CUBE {
                for b in 0..CUBE {
                    colours.push([r, g, b].map(|c| (c * 255 / (CUBE - 1)) as u8));
                }
            }
        }
        let mut counts: HashMap<Rgb, u32> = HashMap::new();
        for p in first.chunks_exact(4) {
            *counts.entry(pack(p[0], p[1], p[2])).or_insert(0) += 1;
        }
        // Sorted: the palette does not depend on the map's order.
        let mut seen: Vec<(Rgb, u32)> = counts.into_iter().collect();
        seen.sort_unstable();
        colours.extend(median_cut(seen, ADAPTIVE));
        while colours.len() < 256 {
            colours.push([0, 0, 0]);
        }
        Palette {
            colours,
            cache: HashMap::new(),
        }
    }

    /// The flat RGB bytes the encoder takes.
    fn bytes(&self) -> Vec<u8> {
        self.colours.iter().flatten().copied().collect()
    }

    /// The nearest entry (below the transparent one) to `c`.
    fn index(&mut self, c: Rgb) -> u8 {
        if let Some(&i) = self.cache.get(&c) {
            return i;
        }
        let [r, g, b] = unpack(c).map(i32::from);
        let mut best = (i32::MAX, 0u8);
        for (i, e) in self.colours[..UNCHANGED as usize].iter().enumerate() {
            let (dr, dg, db) = (
                r - i32::from(e[0]),
                g - i32::from(e[1]),
                b - i32::from(e[2]),
            );
            // Weighted towards green, as the eye is.
            let d = 2 * dr * dr + 4 * dg * dg + 3 * db * db;
            if d < best.0 {
                best = (d, i as u8);
            }
        }
        self.cache.insert(c, best.1);
        best.1
    }
}

/// At most `k` colours standing for `seen` (colour, pixel count): all of
/// them when there are no more than `k`, else the weighted means of the
/// boxes of a median cut (the box with the widest channel range times
/// pixels is split at its weighted median along that channel).
fn median_cut(seen: Vec<(Rgb, u32)>, k: usize) -> Vec<[u8; 3]> {
    if seen.len() <= k {
        return seen.into_iter().map(|(c, _)| unpack(c)).collect();
    }
    let range = |b: &[(Rgb, u32)]| -> (usize, u32) {
        let mut lo = [255u8; 3];
        let mut hi = [0u8; 3];
        for (c, _) in b {
            let v = unpack(*c);
            for ch in 0..3 {
                lo[ch] = lo[ch].min(v[ch]);
                hi[ch] = hi[ch].max(v[ch]);
            }
        }
        (0..3)
            .map(|ch| (ch, u32::from(hi[ch] - lo[ch])))
            .max_by_key(|&(_, r)| r)
            .unwrap_or((0, 0))
    };
    let mut boxes: Vec<Vec<(Rgb, u32)>> = vec![seen];
    while boxes.len() < k {
        // The box most worth splitting: widest range, weighted by pixels.
        let pick = boxes
            .iter()
            .enumerate()
            .filter(|(_, b)| b.len() > 1)
            .max_by_key(|(_, b)| {
                let pixels: u64 = b.iter().map(|&(_, n)| u64::from(n)).sum();
                u64::from(range(b).1) * (pixels + 1)
            })
            .map(|(i, _)| i);
        let Some(i) = pick else {
            break;
        };
        let mut b = boxes.swap_remove(i);
        let (ch, _) = range(&b);
        b.sort_unstable_by_key(|&(c, _)| (unpack(c)[ch], c));
        let total: u64 = b.iter().map(|&(_, n)| u64::from(n)).sum();
        let mut acc = 0u64;
        let mut cut = 1;
        for (j, &(_, n)) in b.iter().enumerate() {
            acc += u64::from(n);
            if 2 * acc >= total {
                cut = (j + 1).clamp(1, b.len() - 1);
                break;
            }
        }
        let upper = b.split_off(cut);
        boxes.push(b);
        boxes.push(upper);
    }
    boxes
        .iter()
        .map(|b| {
            let mut sum = [0u64; 3];
            let mut n = 0u64;
            for &(c, w) in b {
                let v = unpack(c);
                for ch in 0..3 {
                    sum[ch] += u64::from(v[ch]) * u64::from(w);
                }
                n += u64::from(w);
            }
            sum.map(|s| (s + n / 2).checked_div(n).unwrap_or(0) as u8)
        })
        .collect()
}

/// A GIF being written frame by frame. The file's header and palette are
/// written with the first frame.
pub struct GifWriter<W: Write> {
    state: State<W>,
    width: u16,
    height: u16,
    delay_cs: u16,
    previous: Option<Vec<u8>>,
    frames: usize,
}

enum State<W: Write> {
    /// No frame yet: the palette is not known.
    Waiting(W),
    /// Writing.
    Writing(Box<Encoder<W>>, Box<Palette>),
    /// Between the two (only while a call runs, or after an error).
    Gone,
}

fn encode_err(e: impl std::fmt::Display) -> RenderError {
    RenderError::Encode(e.to_string())
}

fn start<W: Write>(out: W, w: u16, h: u16, palette: &Palette) -> Result<Encoder<W>, RenderError> {
    let mut encoder = Encoder::new(out, w, h, &palette.bytes()).map_err(encode_err)?;
    encoder.set_repeat(Repeat::Infinite).map_err(encode_err)?;
    Ok(encoder)
}

impl<W: Write> GifWriter<W> {
    /// A looping GIF of `width × height` pixels showing each frame for
    /// `delay_cs` hundredths of a second (2 gives 50 frames per second).
    /// Errors on a size above 65,535 px.
    pub fn new(out: W, width: u32, height: u32, delay_cs: u16) -> Result<Self, RenderError> {
        let size = RenderError::Size { width, height };
        let w = u16::try_from(width).map_err(|_| size.clone())?;
        let h = u16::try_from(height).map_err(|_| size.clone())?;
        if w == 0 || h == 0 {
            return Err(size);
        }
        Ok(GifWriter {
            state: State::Waiting(out),
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
        let (mut encoder, mut palette) = match std::mem::replace(&mut self.state, State::Gone) {
            State::Waiting(out) => {
                let palette = Palette::from_frame(&rgba);
                let encoder = start(out, self.width, self.height, &palette)?;
                (Box::new(encoder), Box::new(palette))
            }
            State::Writing(e, p) => (e, p),
            State::Gone => return Err(encode_err("the GIF failed earlier")),
        };
        let mut indices: Vec<u8> = rgba
            .chunks_exact(4)
            .map(|p| palette.index(pack(p[0], p[1], p[2])))
            .collect();
        let pixels = match &self.previous {
            Some(prev) => {
                let mut pixels = Vec::with_capacity(indices.len());
                for ((i, &p), px) in indices.iter_mut().zip(prev).zip(rgba.chunks_exact(4)) {
                    // Unchanged: the same entry, or one the eye cannot tell
                    // from the new colour (a sub-pixel shift of a still edge).
                    let shown = palette.colours[usize::from(p)];
                    let close = (0..3).all(|c| px[c].abs_diff(shown[c]) <= STILL);
                    if *i == p || close {
                        *i = p;
                        pixels.push(UNCHANGED);
                    } else {
                        pixels.push(*i);
                    }
                }
                pixels
            }
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
        encoder.write_frame(&frame).map_err(encode_err)?;
        self.state = State::Writing(encoder, palette);
        self.previous = Some(indices);
        self.frames += 1;
        Ok(())
    }

    /// Frames written so far.
    #[must_use]
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Finishes the file and gives back the writer (a clip without a
    /// frame is a header with the cube palette and no image).
    pub fn finish(self) -> Result<W, RenderError> {
        match self.state {
            State::Waiting(out) => {
                let palette = Palette::from_frame(&[]);
                start(out, self.width, self.height, &palette)?
                    .into_inner()
                    .map_err(encode_err)
            }
            State::Writing(encoder, _) => encoder.into_inner().map_err(encode_err),
            State::Gone => Err(encode_err("the GIF failed earlier")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_few_colours_are_kept_exactly() {
        let frame: Vec<u8> = [
            [28u8, 28, 33, 255],
            [230, 128, 128, 255],
            [115, 78, 81, 255],
        ]
        .iter()
        .cycle()
        .take(300)
        .flatten()
        .copied()
        .collect();
        let mut p = Palette::from_frame(&frame);
        assert_eq!(p.colours.len(), 256);
        for c in [[28u8, 28, 33], [230, 128, 128], [115, 78, 81]] {
            let i = p.index(pack(c[0], c[1], c[2]));
            assert_eq!(p.colours[i as usize], c);
            assert_ne!(i, UNCHANGED);
        }
        // A colour the frame did not have: the nearest of the cube or the frame's.
        let i = p.index(pack(255, 0, 0));
        assert_eq!(p.colours[i as usize], [255, 0, 0]);
    }

    #[test]
    fn many_colours_are_cut_to_the_palette() {
        // A smooth gradient of 4096 colours.
        let mut frame = Vec::new();
        for i in 0..4096u32 {
            frame.extend([(i % 64 * 4) as u8, (i / 64 * 4) as u8, 128, 255]);
        }
        let mut p = Palette::from_frame(&frame);
        assert_eq!(p.colours.len(), 256);
        // Every colour lands near itself: much finer than the 4-level cube's
        // 85 steps.
        let mut worst = 0;
        for px in frame.chunks_exact(4) {
            let i = p.index(pack(px[0], px[1], px[2])) as usize;
            let e = p.colours[i];
            let d = (0..3)
                .map(|c| (i32::from(px[c]) - i32::from(e[c])).abs())
                .max()
                .unwrap_or(0);
            worst = worst.max(d);
        }
        assert!(worst <= 16, "worst channel error {worst}");
        // Empty frames make a palette too.
        assert_eq!(Palette::from_frame(&[]).colours.len(), 256);
        assert!(median_cut(Vec::new(), 4).is_empty());
    }
}
