//! Text in PNG and GIF frames: Noto Sans Mono, pre-rasterised at 16 px by
//! the `noto-sans-mono-bitmap` crate (one byte of coverage per pixel, so
//! the letters are anti-aliased), blended into the [`Raster`]'s pixmap.
//!
//! | call | what |
//! |------|------|
//! | [`Raster::text_at`] | a line of text with its top left corner at a pixel |
//! | [`Raster::overlay`] | lines in the picture's top left corner on a dark translucent box (the run's step, time, bodies, ms/step) |
//! | [`text_width`], [`LINE_HEIGHT`] | how much room text takes |
//!
//! Characters outside printable ASCII are drawn as `?`.

use janus2d_world::debug_draw::Color;
use noto_sans_mono_bitmap::{FontWeight, RasterHeight, get_raster, get_raster_width};

use crate::raster::Raster;

const WEIGHT: FontWeight = FontWeight::Regular;
const HEIGHT: RasterHeight = RasterHeight::Size16;

/// Height of a line of text, px.
pub const LINE_HEIGHT: u32 = 16;

/// Width of one character, px (the font is monospaced).
#[must_use]
pub fn char_width() -> u32 {
    get_raster_width(WEIGHT, HEIGHT) as u32
}

/// Width of `text` on one line, px.
#[must_use]
pub fn text_width(text: &str) -> u32 {
    char_width().saturating_mul(text.chars().count() as u32)
}

/// The overlay's text colour.
pub const OVERLAY_TEXT: Color = Color {
    r: 0.92,
    g: 0.92,
    b: 0.92,
    a: 1.0,
};

/// The overlay's backing box colour.
pub const OVERLAY_BACK: Color = Color {
    r: 0.0,
    g: 0.0,
    b: 0.0,
    a: 0.6,
};

/// Padding around the overlay's text, px.
const PAD: u32 = 4;

impl Raster {
    /// Draws `text` on one line with its top left corner at pixel `(x, y)`
    /// (which may be outside the picture: what falls outside is cut).
    pub fn text_at(&mut self, x: i32, y: i32, text: &str, color: Color) {
        let [r, g, b, a] = color.to_rgba8();
        let cw = i64::from(char_width());
        let (x, y) = (i64::from(x), i64::from(y));
        for (k, c) in text.chars().enumerate() {
            let c = if c == ' ' || c.is_ascii_graphic() {
                c
            } else {
                '?'
            };
            let Some(glyph) = get_raster(c, WEIGHT, HEIGHT) else {
                continue;
            };
            let x0 = x + k as i64 * cw;
            if x0 >= i64::from(self.camera.width) {
                break;
            }
            for (gy, row) in glyph.rows().enumerate() {
                for (gx, &coverage) in row.iter().enumerate() {
                    if coverage == 0 {
                        continue;
                    }
                    let alpha = u16::from(coverage) * u16::from(a) / 255;
                    self.blend(x0 + gx as i64, y + gy as i64, [r, g, b], alpha as u8);
                }
            }
        }
    }

    /// Draws `lines` in the picture's top left corner, white on a dark
    /// translucent box just large enough for them.
    pub fn overlay(&mut self, lines: &[String]) {
        if lines.is_empty() {
            return;
        }
        let w = lines.iter().map(|l| text_width(l)).max().unwrap_or(0) + 2 * PAD;
        let h = LINE_HEIGHT * lines.len() as u32 + 2 * PAD;
        let [r, g, b, a] = OVERLAY_BACK.to_rgba8();
        for y in 0..h.min(self.camera.height) {
            for x in 0..w.min(self.camera.width) {
                self.blend(i64::from(x), i64::from(y), [r, g, b], a);
            }
        }
        for (i, line) in lines.iter().enumerate() {
            let y = PAD + LINE_HEIGHT * i as u32;
            self.text_at(PAD as i32, y as i32, line, OVERLAY_TEXT);
        }
    }

    /// Mixes `rgb` at opacity `alpha` (0–255) into the pixel `(x, y)`, if it
    /// is in the picture.
    fn blend(&mut self, x: i64, y: i64, rgb: [u8; 3], alpha: u8) {
        let (w, h) = (i64::from(self.camera.width), i64::from(self.camera.height));
        if x < 0 || y < 0 || x >= w || y >= h || alpha == 0 {
            return;
        }
        let i = (y * w + x) as usize;
        let Some(px) = self.pixmap_mut().pixels_mut().get_mut(i) else {
            return;
        };
        // Premultiplied source over premultiplied destination.
        let sa = u32::from(alpha);
        let over = |s: u8, d: u8| -> u8 {
            ((u32::from(s) * sa + u32::from(d) * (255 - sa) + 127) / 255) as u8
        };
        let out_a = ((sa * 255 + u32::from(px.alpha()) * (255 - sa) + 127) / 255) as u8;
        let (r, g, b) = (
            over(rgb[0], px.red()),
            over(rgb[1], px.green()),
            over(rgb[2], px.blue()),
        );
        if let Some(c) = tiny_skia::PremultipliedColorU8::from_rgba(
            r.min(out_a),
            g.min(out_a),
            b.min(out_a),
            out_a,
        ) {
            *px = c;
        }
    }
}

/// Splits `items` into lines no wider than `width` px (an item wider than
/// that gets a line of its own), joined by two spaces.
#[must_use]
pub fn wrap(items: &[String], width: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for item in items {
        match lines.last_mut() {
            Some(line) if text_width(line) + text_width(item) + 2 * char_width() <= width => {
                line.push_str("  ");
                line.push_str(item);
            }
            _ => lines.push(item.clone()),
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Camera;
    use janus2d_core::math::Vec2;

    fn lit(r: &Raster) -> usize {
        let bg = crate::raster::BACKGROUND.to_rgba8();
        r.rgba()
            .chunks_exact(4)
            .filter(|p| (i32::from(p[0]) - i32::from(bg[0])).abs() > 40)
            .count()
    }

    #[test]
    fn text_lights_pixels_where_it_is_drawn() {
        let mut r = Raster::new(Camera::new(Vec2::ZERO, 10.0, 120, 40)).unwrap();
        r.text_at(2, 2, "step 42", OVERLAY_TEXT);
        let n = lit(&r);
        assert!(n > 40, "{n} px lit");
        // Only inside the text's box.
        let rgba = r.rgba();
        for y in 0..40usize {
            for x in 0..120usize {
                let inside =
                    (2..2 + text_width("step 42") as usize).contains(&x) && (2..18).contains(&y);
                if !inside {
                    assert_eq!(
                        rgba[4 * (y * 120 + x)],
                        crate::raster::BACKGROUND.to_rgba8()[0]
                    );
                }
            }
        }
        // Off the picture and odd characters: no panic, nothing drawn.
        let mut r = Raster::new(Camera::new(Vec2::ZERO, 10.0, 20, 20)).unwrap();
        r.text_at(-500, 900, "é ✓", OVERLAY_TEXT);
        r.text_at(i32::MAX - 3, i32::MIN, "abc", OVERLAY_TEXT);
        assert_eq!(lit(&r), 0);
    }

    #[test]
    fn the_overlay_covers_only_its_corner() {
        let mut r = Raster::new(Camera::new(Vec2::ZERO, 10.0, 200, 100)).unwrap();
        r.overlay(&["step 1".into(), "t 0.017 s".into()]);
        let rgba = r.rgba();
        let bg = crate::raster::BACKGROUND.to_rgba8();
        // Far corner untouched; the box darkened the top left.
        assert_eq!(rgba[4 * (99 * 200 + 199)..][..3], bg[..3]);
        assert!(rgba[0] < bg[0]);
        // Tiny pictures do not panic.
        let mut tiny = Raster::new(Camera::new(Vec2::ZERO, 10.0, 3, 2)).unwrap();
        tiny.overlay(&["a long line of text".into()]);
    }

    #[test]
    fn wrap_fits_the_width() {
        let items: Vec<String> = ["step 120", "t 2.000 s", "bodies 5051", "12.3 ms/step"]
            .map(String::from)
            .to_vec();
        assert_eq!(wrap(&items, 10_000).len(), 1);
        let narrow = wrap(&items, text_width("bodies 5051  ") + 4);
        assert_eq!(narrow.len(), 4);
        assert_eq!(wrap(&items, 0).len(), 4);
    }
}
