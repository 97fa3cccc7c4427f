//! # janus2d-render
//!
//! Pictures of a janus2d world, drawn through the world's
//! [`DebugDraw`](janus2d_world::debug_draw::DebugDraw) trait: PNG frames
//! painted with `tiny-skia`, SVG documents, and GIF clips of a run. The
//! engine crates do not depend on this one.
//!
//! | module     | what                                                              |
//! |------------|-------------------------------------------------------------------|
//! | [`camera`] | [`Camera`]: fit a box or the scene, follow a body, world ↔ pixels  |
//! | [`raster`] | [`Raster`]: a `DebugDraw` into a pixmap, saved as PNG              |
//! | [`svg`]    | [`Svg`]: a `DebugDraw` writing SVG elements                        |
//! | [`clip`]   | [`GifWriter`]: frames of a run as one looping GIF (a palette made from the first frame) |
//! | [`text`]   | text in PNG / GIF frames: labels and the run's overlay ([`Raster::overlay`]) |
//!
//! ```
//! use janus2d_render::{Camera, Raster};
//! use janus2d_world::{DrawOptions, ShapeDef, World, WorldDef};
//! use janus2d_core::{BodyDef, Vec2};
//! use janus2d_core::geometry::Polygon;
//!
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
//! world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
//! let mut picture = Raster::new(Camera::fit_world(&world, 64, 64)).unwrap();
//! picture.draw_world(&world, &DrawOptions::default());
//! let png = picture.encode_png().unwrap();
//! assert_eq!(&png[1..4], b"PNG");
//! ```

pub mod camera;
pub mod clip;
pub mod raster;
pub mod svg;
pub mod text;

pub use camera::{Camera, scene_bounds};
pub use clip::GifWriter;
pub use raster::Raster;
pub use svg::Svg;

use janus2d_core::math::{Real, Vec2};

/// What can go wrong while making a picture.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RenderError {
    /// A picture size that cannot be made (zero, too large for the format,
    /// or a frame of the wrong size for its clip).
    Size {
        /// Width, px.
        width: u32,
        /// Height, px.
        height: u32,
    },
    /// The encoder (PNG or GIF) failed.
    Encode(String),
    /// A file could not be written.
    Io {
        /// The file.
        path: String,
        /// What the system said.
        message: String,
    },
}

impl RenderError {
    /// An I/O error on `path`.
    #[must_use]
    pub fn io(path: &std::path::Path, e: &std::io::Error) -> RenderError {
        RenderError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

impl std::fmt::Display for RenderError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RenderError::Size { width, height } => {
                write!(f, "cannot make a picture of {width} x {height} px")
            }
            RenderError::Encode(m) => write!(f, "encoding failed: {m}"),
            RenderError::Io { path, message } => write!(f, "cannot write {path}: {message}"),
        }
    }
}

impl std::error::Error for RenderError {}

/// The outline of a convex polygon (counter-clockwise `vertices`) rounded
/// by `radius`: each edge pushed out by `radius` along its normal, the
/// corners joined by arcs of about `arc_segments` pieces per quarter turn.
/// Two vertices give a capsule's outline, one a circle.
#[must_use]
pub fn rounded_outline(vertices: &[Vec2], radius: Real, arc_segments: usize) -> Vec<Vec2> {
    let n = vertices.len();
    if n == 0 {
        return Vec::new();
    }
    let normal = |i: usize| -> Vec2 {
        let d = vertices[(i + 1) % n] - vertices[i];
        let len = d.length();
        if len > 0.0 {
            Vec2::new(d.y, -d.x) / len
        } else {
            Vec2::X
        }
    };
    let per_quarter = arc_segments.max(1) as Real;
    let mut out = Vec::with_capacity(n * (arc_segments + 2));
    for i in 0..n {
        // Edge i → i+1 pushed out, then the arc around vertex i+1.
        let (a, b) = (vertices[i], vertices[(i + 1) % n]);
        let (n0, n1) = if n == 1 {
            (Vec2::X, Vec2::X)
        } else {
            (normal(i), normal((i + 1) % n))
        };
        out.push(a + radius * n0);
        out.push(b + radius * n0);
        let a0 = n0.y.atan2(n0.x);
        let mut turn = n1.y.atan2(n1.x) - a0;
        let tau = std::f64::consts::TAU as Real;
        while turn <= 0.0 {
            turn += tau;
        }
        if n > 2 && turn > tau - 1e-4 {
            continue; // collinear edges: no corner
        }
        let pieces = ((turn / (0.5 * std::f64::consts::PI as Real)) * per_quarter)
            .ceil()
            .max(1.0) as usize;
        for k in 1..pieces {
            let t = a0 + turn * k as Real / pieces as Real;
            out.push(b + radius * Vec2::new(t.cos(), t.sin()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use janus2d_core::body::BodyDef;
    use janus2d_core::geometry::Polygon;
    use janus2d_world::{DrawOptions, ShapeDef, World, WorldDef};

    fn boxes(n: usize) -> World {
        let mut world = World::new(WorldDef::default()).unwrap();
        for i in 0..n {
            let b = world
                .create_body(&BodyDef::fixed(Vec2::new(3.0 * i as Real, 0.0)))
                .unwrap();
            world
                .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
                .unwrap();
        }
        world
    }

    fn lit_pixels(r: &Raster) -> usize {
        let bg = raster::BACKGROUND.to_rgba8();
        r.rgba()
            .chunks_exact(4)
            .filter(|p| {
                p.iter()
                    .zip(bg)
                    .any(|(&a, b)| (i32::from(a) - i32::from(b)).abs() > 8)
            })
            .count()
    }

    #[test]
    fn a_box_covers_its_area_in_pixels() {
        let world = boxes(1);
        // 20 px per metre: the 1 m box is 20 × 20 = 400 px.
        let cam = Camera::new(Vec2::ZERO, 20.0, 100, 100);
        let mut r = Raster::new(cam).unwrap();
        r.draw_world(&world, &DrawOptions::default());
        let lit = lit_pixels(&r) as f64;
        // Anti-aliased edges add at most a pixel ring around it.
        assert!((400.0..=22.0 * 22.0).contains(&lit), "{lit} px lit");
        // The centre pixel is the static body colour at half opacity over
        // the background: 0.5 · 0.9 + 0.5 · 0.11 of green.
        let px = r.pixmap().pixel(50, 50).unwrap().demultiply();
        assert!((i32::from(px.green()) - 129).abs() <= 2, "{px:?}");
        assert!(px.green() > px.red() && px.green() > px.blue(), "{px:?}");
        // A pixel well outside the box is the background.
        let out = r.pixmap().pixel(5, 5).unwrap().demultiply();
        assert_eq!(
            [out.red(), out.green(), out.blue()],
            raster::BACKGROUND.to_rgba8()[..3]
        );
    }

    #[test]
    fn rounded_outline_has_the_rounded_area() {
        let sq = [
            Vec2::new(-0.5, -0.5),
            Vec2::new(0.5, -0.5),
            Vec2::new(0.5, 0.5),
            Vec2::new(-0.5, 0.5),
        ];
        let o = rounded_outline(&sq, 0.1, 8);
        let area: Real = (0..o.len())
            .map(|i| janus2d_core::math::cross(o[i], o[(i + 1) % o.len()]))
            .sum::<Real>()
            * 0.5;
        let exact = 1.0 + 4.0 * 0.1 + std::f64::consts::PI as Real * 0.01;
        assert!((area - exact).abs() < 2e-3, "{area} vs {exact}");
        // A capsule: two ends.
        let c = rounded_outline(&[Vec2::ZERO, Vec2::X], 0.5, 4);
        let area: Real = (0..c.len())
            .map(|i| janus2d_core::math::cross(c[i], c[(i + 1) % c.len()]))
            .sum::<Real>()
            * 0.5;
        let exact = 1.0 + std::f64::consts::PI as Real * 0.25;
        assert!((area - exact).abs() < 0.05, "{area} vs {exact}");
    }

    #[test]
    fn svg_has_one_polygon_per_box() {
        for n in [1, 4, 9] {
            let world = boxes(n);
            let mut svg = Svg::new(Camera::fit_world(&world, 300, 200));
            svg.draw_world(&world, &DrawOptions::default());
            let doc = svg.finish();
            assert_eq!(doc.matches("<polygon").count(), n);
            assert!(doc.starts_with("<svg") && doc.ends_with("</svg>\n"));
        }
    }

    #[test]
    fn the_fitted_camera_shows_every_body() {
        let desc = janus2d_testbed::benchmarks::by_name("pyramid20").unwrap();
        let built = janus2d_testbed::janus::Janus::new(&desc).unwrap();
        let world = &built.world;
        for (w, h) in [(640, 360), (200, 600)] {
            let cam = Camera::fit_world(world, w, h);
            let view = cam.visible_box();
            for b in world.body_handles() {
                if world.body_type(b) == Ok(janus2d_core::body::BodyType::Dynamic) {
                    for s in world.body_shapes(b).unwrap() {
                        let bx = world.shape(s).unwrap().aabb;
                        assert!(view.contains(&bx), "{bx:?} outside {view:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn gif_has_one_frame_per_add() {
        let mut world = boxes(2);
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(1.5, 3.0)))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
            .unwrap();
        let cam = Camera::fit_world(&world, 80, 60);
        let mut r = Raster::new(cam).unwrap();
        let mut gif = GifWriter::new(Vec::new(), 80, 60, 4).unwrap();
        for _ in 0..7 {
            r.draw_world(&world, &DrawOptions::default());
            gif.add(&r).unwrap();
            world.step(1.0 / 60.0).unwrap();
        }
        assert_eq!(gif.frames(), 7);
        let bytes = gif.finish().unwrap();
        let mut opts = gif::DecodeOptions::new();
        opts.set_color_output(gif::ColorOutput::Indexed);
        let mut dec = opts.read_info(&bytes[..]).unwrap();
        let mut frames = 0;
        while dec.read_next_frame().unwrap().is_some() {
            frames += 1;
        }
        assert_eq!(frames, 7);
        // The wrong size is a typed error, not a panic.
        let small = Raster::new(Camera::new(Vec2::ZERO, 1.0, 10, 10)).unwrap();
        let mut gif = GifWriter::new(Vec::new(), 80, 60, 4).unwrap();
        assert!(matches!(gif.add(&small), Err(RenderError::Size { .. })));
        assert!(GifWriter::new(Vec::new(), 70_000, 10, 4).is_err());
    }

    #[test]
    fn png_round_trip_has_the_camera_size() {
        let world = boxes(3);
        let mut r = Raster::new(Camera::fit_world(&world, 120, 90)).unwrap();
        r.draw_world(&world, &DrawOptions::all());
        let png = r.encode_png().unwrap();
        let back = tiny_skia::Pixmap::decode_png(&png).unwrap();
        assert_eq!((back.width(), back.height()), (120, 90));
        assert!(lit_pixels(&r) > 0);
        assert!(
            Raster::new(Camera::new(Vec2::ZERO, 1.0, 0, 0)).is_ok(),
            "clamped to 1 px"
        );
    }
}
