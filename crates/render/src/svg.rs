//! SVG pictures: a [`DebugDraw`] that writes SVG elements.
//!
//! | primitive        | element                                                       |
//! |------------------|---------------------------------------------------------------|
//! | solid polygon    | `<polygon>` filled at half opacity with an outline (a rounded one through its rounded outline, [`crate::rounded_outline`]) |
//! | polygon          | `<polygon>` outline, no fill                                  |
//! | solid circle     | `<circle>` filled + `<line>` along the body's x axis          |
//! | circle           | `<circle>` outline                                            |
//! | solid capsule    | `<line>` with round caps as wide as the capsule               |
//! | segment          | `<line>`                                                      |
//! | point            | `<rect>` of the point's size                                  |
//! | text             | `<text>` (escaped)                                            |
//!
//! Coordinates are the [`Camera`]'s pixels, with two decimals.

use std::fmt::Write as _;
use std::path::Path;

use janus2d_core::math::{Real, Vec2};
use janus2d_world::World;
use janus2d_world::debug_draw::{Color, DebugDraw, DrawOptions};

use crate::RenderError;
use crate::camera::Camera;
use crate::raster::{BACKGROUND, FILL_ALPHA};

/// An SVG picture being written.
pub struct Svg {
    /// The view.
    pub camera: Camera,
    /// The background colour (`None`: transparent).
    pub background: Option<Color>,
    body: String,
}

fn rgb(c: Color) -> String {
    let [r, g, b, _] = c.to_rgba8();
    format!("rgb({r},{g},{b})")
}

fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            c => out.push(c),
        }
    }
    out
}

impl Svg {
    /// An empty picture of the camera's size on [`BACKGROUND`].
    #[must_use]
    pub fn new(camera: Camera) -> Svg {
        Svg {
            camera,
            background: Some(BACKGROUND),
            body: String::new(),
        }
    }

    /// Draws `world` as `options` says (added to what is already drawn),
    /// culled to the view.
    pub fn draw_world(&mut self, world: &World, options: &DrawOptions) {
        let options = DrawOptions {
            bounds: Some(self.camera.visible_box()),
            ..*options
        };
        world.debug_draw(self, &options);
    }

    /// The whole document.
    #[must_use]
    pub fn finish(&self) -> String {
        let (w, h) = (self.camera.width, self.camera.height);
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n"
        );
        if let Some(bg) = self.background {
            let _ = writeln!(
                s,
                "<rect width=\"{w}\" height=\"{h}\" fill=\"{}\"/>",
                rgb(bg)
            );
        }
        s.push_str(&self.body);
        s.push_str("</svg>\n");
        s
    }

    /// Writes the document to a file.
    pub fn save(&self, path: &Path) -> Result<(), RenderError> {
        std::fs::write(path, self.finish()).map_err(|e| RenderError::io(path, &e))
    }

    fn points(&self, vertices: &[Vec2]) -> String {
        let mut s = String::new();
        for v in vertices {
            let (x, y) = self.camera.to_screen(*v);
            let _ = write!(s, "{x:.2},{y:.2} ");
        }
        s.pop();
        s
    }
}

impl DebugDraw for Svg {
    fn polygon(&mut self, vertices: &[Vec2], color: Color) {
        let pts = self.points(vertices);
        let _ = writeln!(
            self.body,
            "<polygon points=\"{pts}\" fill=\"none\" stroke=\"{}\" stroke-opacity=\"{}\"/>",
            rgb(color),
            color.a
        );
    }

    fn solid_polygon(&mut self, vertices: &[Vec2], radius: Real, color: Color) {
        let pts = if radius > 0.0 {
            self.points(&crate::rounded_outline(vertices, radius, 4))
        } else {
            self.points(vertices)
        };
        let _ = writeln!(
            self.body,
            "<polygon points=\"{pts}\" fill=\"{c}\" fill-opacity=\"{}\" stroke=\"{c}\" stroke-opacity=\"{}\"/>",
            color.a * FILL_ALPHA,
            color.a,
            c = rgb(color),
        );
    }

    fn circle(&mut self, center: Vec2, radius: Real, color: Color) {
        let (x, y) = self.camera.to_screen(center);
        let r = self.camera.pixels(radius);
        let _ = writeln!(
            self.body,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{r:.2}\" fill=\"none\" stroke=\"{}\"/>",
            rgb(color)
        );
    }

    fn solid_circle(&mut self, center: Vec2, radius: Real, axis: Vec2, color: Color) {
        let (x, y) = self.camera.to_screen(center);
        let r = self.camera.pixels(radius);
        let _ = writeln!(
            self.body,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"{r:.2}\" fill=\"{c}\" fill-opacity=\"{}\" stroke=\"{c}\"/>",
            color.a * FILL_ALPHA,
            c = rgb(color)
        );
        self.segment(center, center + radius * axis, color);
    }

    fn solid_capsule(&mut self, p1: Vec2, p2: Vec2, radius: Real, color: Color) {
        let (x1, y1) = self.camera.to_screen(p1);
        let (x2, y2) = self.camera.to_screen(p2);
        let w = 2.0 * self.camera.pixels(radius);
        let _ = writeln!(
            self.body,
            "<line x1=\"{x1:.2}\" y1=\"{y1:.2}\" x2=\"{x2:.2}\" y2=\"{y2:.2}\" stroke=\"{}\" stroke-opacity=\"{}\" stroke-width=\"{w:.2}\" stroke-linecap=\"round\"/>",
            rgb(color),
            color.a * FILL_ALPHA
        );
    }

    fn segment(&mut self, p1: Vec2, p2: Vec2, color: Color) {
        let (x1, y1) = self.camera.to_screen(p1);
        let (x2, y2) = self.camera.to_screen(p2);
        let _ = writeln!(
            self.body,
            "<line x1=\"{x1:.2}\" y1=\"{y1:.2}\" x2=\"{x2:.2}\" y2=\"{y2:.2}\" stroke=\"{}\" stroke-opacity=\"{}\"/>",
            rgb(color),
            color.a
        );
    }

    fn point(&mut self, p: Vec2, size: f32, color: Color) {
        let (x, y) = self.camera.to_screen(p);
        let s = size.max(1.0);
        let _ = writeln!(
            self.body,
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{s:.2}\" height=\"{s:.2}\" fill=\"{}\"/>",
            x - 0.5 * s,
            y - 0.5 * s,
            rgb(color)
        );
    }

    fn text(&mut self, p: Vec2, text: &str, color: Color) {
        let (x, y) = self.camera.to_screen(p);
        let _ = writeln!(
            self.body,
            "<text x=\"{x:.2}\" y=\"{y:.2}\" font-family=\"monospace\" font-size=\"12\" fill=\"{}\">{}</text>",
            rgb(color),
            escape(text)
        );
    }
}
