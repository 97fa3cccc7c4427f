//! Guide step 10 (docs/guide.md): drawing a frame. `World::debug_draw`
//! walks the world and calls a `DebugDraw` you implement (polygons,
//! circles, capsules, segments, points) with the `DrawOptions` you choose;
//! a game draws with its own renderer this way. The `render` feature (on by
//! default) brings `janus2d::render`, which draws the same calls into a PNG
//! (`Raster`), an SVG (`Svg`) or a GIF clip (`GifWriter`), through a
//! `Camera` that fits the scene. Run with `cargo run --example
//! guide_10_draw`; it writes target/guide/frame.png, frame.svg and
//! clip.gif.

use janus2d::prelude::*;
use janus2d::render::{Camera, GifWriter, Raster, RenderError, Svg};
use janus2d::{Color, DebugDraw, DrawOptions};

/// A renderer of your own: here it only counts what it is asked to draw.
#[derive(Default)]
struct Counter {
    polygons: usize,
    circles: usize,
    capsules: usize,
    segments: usize,
}

impl DebugDraw for Counter {
    fn polygon(&mut self, _vertices: &[Vec2], _color: Color) {
        self.polygons += 1;
    }
    fn solid_polygon(&mut self, _vertices: &[Vec2], _radius: Real, _color: Color) {
        self.polygons += 1;
    }
    fn circle(&mut self, _center: Vec2, _radius: Real, _color: Color) {
        self.circles += 1;
    }
    fn solid_circle(&mut self, _center: Vec2, _radius: Real, _axis: Vec2, _color: Color) {
        self.circles += 1;
    }
    fn solid_capsule(&mut self, _p1: Vec2, _p2: Vec2, _radius: Real, _color: Color) {
        self.capsules += 1;
    }
    fn segment(&mut self, _p1: Vec2, _p2: Vec2, _color: Color) {
        self.segments += 1;
    }
    fn point(&mut self, _p: Vec2, _size: f32, _color: Color) {}
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(8.0, 0.5))?;
    for i in 0..6 {
        let b = world.create_body(&BodyDef::dynamic(Vec2::new(
            -2.5 + i as Real,
            1.0 + 0.8 * i as Real,
        )))?;
        world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.4, 0.4))?;
    }
    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(3.0, 6.0)))?;
    world.create_shape(ball, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5)?)?;
    let player = world.create_body(&BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(-5.0, 0.8))
    })?;
    let capsule = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default(), capsule)?;

    // Your own renderer: the shapes, plus the contact points.
    let options = DrawOptions {
        contacts: true,
        ..DrawOptions::default()
    };
    for _ in 0..30 {
        world.step(1.0 / 60.0)?;
    }
    let mut counter = Counter::default();
    world.debug_draw(&mut counter, &options);
    println!(
        "debug_draw asked for {} polygons, {} circles, {} capsules, {} segments",
        counter.polygons, counter.circles, counter.capsules, counter.segments
    );

    // The render crate: a 320 x 200 PNG and an SVG of the same frame.
    let out = std::path::Path::new("target/guide");
    std::fs::create_dir_all(out)?;
    let camera = Camera::fit_world(&world, 320, 200);
    let mut png = Raster::new(camera)?;
    png.draw_world(&world, &DrawOptions::default());
    png.save_png(&out.join("frame.png"))?;
    let mut svg = Svg::new(camera);
    svg.draw_world(&world, &DrawOptions::default());
    svg.save(&out.join("frame.svg"))?;

    // A GIF clip of the next second, one frame in three (5 cs a frame).
    let file = std::fs::File::create(out.join("clip.gif"))?;
    let mut gif = GifWriter::new(std::io::BufWriter::new(file), 320, 200, 5)?;
    for step in 1..=60 {
        world.step(1.0 / 60.0)?;
        if step % 3 == 0 {
            let mut frame = Raster::new(camera)?;
            frame.draw_world(&world, &DrawOptions::default());
            gif.add(&frame)?;
        }
    }
    let frames = gif.frames();
    gif.finish()?;
    let sizes: Result<Vec<u64>, RenderError> = ["frame.png", "frame.svg", "clip.gif"]
        .iter()
        .map(|f| {
            std::fs::metadata(out.join(f))
                .map(|m| m.len())
                .map_err(|e| RenderError::io(&out.join(f), &e))
        })
        .collect();
    println!(
        "wrote target/guide/frame.png, frame.svg and clip.gif ({frames} frames): {:?} bytes",
        sizes?
    );
    Ok(())
}
