//! PNG frames: a [`DebugDraw`] that paints into a `tiny-skia` pixmap.
//!
//! | primitive        | painted as                                              |
//! |------------------|---------------------------------------------------------|
//! | solid polygon    | fill at half opacity + outline; a rounded polygon's outline is its edges pushed out by the radius joined by arcs ([`crate::rounded_outline`]) |
//! | solid circle     | disc + outline + a radius along the body's x axis       |
//! | solid capsule    | as a rounded two-vertex polygon                         |
//! | polygon, circle, segment | 1 px outlines / lines                           |
//! | point            | a filled square of the given size, px                   |
//! | text             | 16 px Noto Sans Mono, its top left corner at the point ([`crate::text`]) |
//!
//! Coordinates go through the [`Camera`]; everything is anti-aliased.

use std::path::Path;

use janus2d_core::math::{Real, Vec2};
use janus2d_world::World;
use janus2d_world::debug_draw::{Color, DebugDraw, DrawOptions};
use tiny_skia::{FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform};

use crate::RenderError;
use crate::camera::Camera;

/// The default background: near black.
pub const BACKGROUND: Color = Color {
    r: 0.11,
    g: 0.11,
    b: 0.13,
    a: 1.0,
};

/// Opacity of shape fills (outlines are opaque).
pub const FILL_ALPHA: f32 = 0.5;

/// A picture being painted.
pub struct Raster {
    pixmap: Pixmap,
    /// The view.
    pub camera: Camera,
    /// The colour [`Raster::clear`] paints.
    pub background: Color,
}

fn paint(c: Color) -> Paint<'static> {
    let [r, g, b, a] = c.to_rgba8();
    let mut p = Paint::default();
    p.set_color_rgba8(r, g, b, a);
    p.anti_alias = true;
    p
}

fn stroke(width: f32) -> Stroke {
    Stroke {
        width: width.max(0.0),
        line_cap: LineCap::Round,
        line_join: LineJoin::Round,
        ..Stroke::default()
    }
}

impl Raster {
    /// A picture of the camera's size, cleared to [`BACKGROUND`].
    pub fn new(camera: Camera) -> Result<Raster, RenderError> {
        let pixmap = Pixmap::new(camera.width, camera.height).ok_or(RenderError::Size {
            width: camera.width,
            height: camera.height,
        })?;
        let mut r = Raster {
            pixmap,
            camera,
            background: BACKGROUND,
        };
        r.clear();
        Ok(r)
    }

    /// Paints the whole picture in the background colour.
    pub fn clear(&mut self) {
        let [r, g, b, a] = self.background.to_rgba8();
        self.pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, a));
    }

    /// Clears, then draws `world` as `options` says, culled to the view.
    pub fn draw_world(&mut self, world: &World, options: &DrawOptions) {
        self.clear();
        let options = DrawOptions {
            bounds: Some(self.camera.visible_box()),
            ..*options
        };
        world.debug_draw(self, &options);
    }

    /// The pixels.
    #[must_use]
    pub fn pixmap(&self) -> &Pixmap {
        &self.pixmap
    }

    /// The pixels, to change (the text module blends into them).
    pub(crate) fn pixmap_mut(&mut self) -> &mut Pixmap {
        &mut self.pixmap
    }

    /// The picture as straight (not premultiplied) RGBA bytes, row by row.
    #[must_use]
    pub fn rgba(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixmap.data().len());
        for p in self.pixmap.pixels() {
            let c = p.demultiply();
            out.extend([c.red(), c.green(), c.blue(), c.alpha()]);
        }
        out
    }

    /// The picture as a PNG file's bytes.
    pub fn encode_png(&self) -> Result<Vec<u8>, RenderError> {
        self.pixmap
            .encode_png()
            .map_err(|e| RenderError::Encode(e.to_string()))
    }

    /// Writes the picture as a PNG file.
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        let bytes = self.encode_png()?;
        std::fs::write(path, bytes).map_err(|e| RenderError::io(path, &e))
    }

    fn xy(&self, p: Vec2) -> (f32, f32) {
        self.camera.to_screen(p)
    }

    fn path_of(&self, vertices: &[Vec2], close: bool) -> Option<tiny_skia::Path> {
        let mut pb = PathBuilder::new();
        let (first, rest) = vertices.split_first()?;
        let (x, y) = self.xy(*first);
        pb.move_to(x, y);
        for v in rest {
            let (x, y) = self.xy(*v);
            pb.line_to(x, y);
        }
        if close {
            pb.close();
        }
        pb.finish()
    }

    fn stroke_path(&mut self, path: &tiny_skia::Path, width: f32, color: Color) {
        self.pixmap.stroke_path(
            path,
            &paint(color),
            &stroke(width),
            Transform::identity(),
            None,
        );
    }

    fn fill_path(&mut self, path: &tiny_skia::Path, color: Color) {
        self.pixmap.fill_path(
            path,
            &paint(color),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }

    fn disc(&mut self, center: Vec2, radius_px: f32) -> Option<tiny_skia::Path> {
        let (x, y) = self.xy(center);
        PathBuilder::from_circle(x, y, radius_px.max(0.5))
    }
}

impl DebugDraw for Raster {
    fn polygon(&mut self, vertices: &[Vec2], color: Color) {
        if let Some(path) = self.path_of(vertices, true) {
            self.stroke_path(&path, 1.0, color);
        }
    }

    fn solid_polygon(&mut self, vertices: &[Vec2], radius: Real, color: Color) {
        let fill = color.with_alpha(color.a * FILL_ALPHA);
        let path = if radius > 0.0 {
            self.path_of(&crate::rounded_outline(vertices, radius, 4), true)
        } else {
            self.path_of(vertices, true)
        };
        let Some(path) = path else {
            return;
        };
        self.fill_path(&path, fill);
        self.stroke_path(&path, 1.0, color);
    }

    fn circle(&mut self, center: Vec2, radius: Real, color: Color) {
        let r = self.camera.pixels(radius);
        if let Some(path) = self.disc(center, r) {
            self.stroke_path(&path, 1.0, color);
        }
    }

    fn solid_circle(&mut self, center: Vec2, radius: Real, axis: Vec2, color: Color) {
        let r = self.camera.pixels(radius);
        if let Some(path) = self.disc(center, r) {
            self.fill_path(&path, color.with_alpha(color.a * FILL_ALPHA));
            self.stroke_path(&path, 1.0, color);
        }
        self.segment(center, center + radius * axis, color);
    }

    fn solid_capsule(&mut self, p1: Vec2, p2: Vec2, radius: Real, color: Color) {
        self.solid_polygon(&[p1, p2], radius, color);
    }

    fn segment(&mut self, p1: Vec2, p2: Vec2, color: Color) {
        if let Some(path) = self.path_of(&[p1, p2], false) {
            self.stroke_path(&path, 1.0, color);
        }
    }

    fn text(&mut self, p: Vec2, text: &str, color: Color) {
        let (x, y) = self.xy(p);
        if x.is_finite() && y.is_finite() {
            self.text_at(x as i32, y as i32, text, color);
        }
    }

    fn point(&mut self, p: Vec2, size: f32, color: Color) {
        let (x, y) = self.xy(p);
        let s = size.max(1.0);
        if let Some(rect) = tiny_skia::Rect::from_xywh(x - 0.5 * s, y - 0.5 * s, s, s) {
            self.pixmap
                .fill_rect(rect, &paint(color), Transform::identity(), None);
        }
    }
}
