//! Mouse picking, headless: what is under the cursor (a point overlap) and
//! what a ray from the camera meets first, with a short readout. Run with
//! `cargo run --release --example picking`.

use janus2d::prelude::*;

/// What the picking found (the queries test reads it too).
pub struct Report {
    /// The box the cursor is over.
    pub target: BodyHandle,
    /// The body `overlap_point` found under the cursor.
    pub picked_by_point: Option<BodyHandle>,
    /// The body a ray straight down from the camera hits first.
    pub picked_by_ray: Option<BodyHandle>,
    /// Fraction of the camera ray at the hit.
    pub ray_fraction: Real,
    /// True when a cursor 1 cm beside the ball picks nothing.
    pub missed_beside_ball: bool,
}

/// Builds a small scene, lets it settle, then picks.
pub fn run() -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))?;
    let mut boxes = Vec::new();
    for x in [-2.0, 0.0, 2.0] {
        let b = world.create_body(&BodyDef::dynamic(Vec2::new(x, 0.5)))?;
        world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
        boxes.push(b);
    }
    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(4.0, 0.5)))?;
    world.create_shape(ball, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5)?)?;
    for _ in 0..30 {
        world.step(1.0 / 60.0)?;
    }

    let filter = QueryFilter::default();
    let cursor = Vec2::new(0.2, 0.7);
    let mut picked_by_point = None;
    world.overlap_point(cursor, &filter, |o| {
        picked_by_point = Some(o.body);
        false
    })?;

    let camera = Vec2::new(cursor.x, 10.0);
    let hit = world.cast_ray_closest(camera, Vec2::new(0.0, -20.0), &filter)?;

    let ball_center = world.position(ball)?;
    let beside = ball_center + Vec2::new(0.51, 0.0);
    let mut beside_count = 0;
    world.overlap_point(beside, &filter, |_| {
        beside_count += 1;
        true
    })?;

    Ok(Report {
        target: boxes[1],
        picked_by_point,
        picked_by_ray: hit.map(|h| h.body),
        ray_fraction: hit.map_or(Real::NAN, |h| h.fraction),
        missed_beside_ball: beside_count == 0,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!("cursor over the middle box: {:?}", r.target);
    println!("overlap_point picked:       {:?}", r.picked_by_point);
    match r.picked_by_ray {
        Some(b) => println!(
            "camera ray hit:             {b:?} at fraction {:.4} (top face y = {:.3})",
            r.ray_fraction,
            10.0 - 20.0 * r.ray_fraction
        ),
        None => println!("camera ray hit nothing"),
    }
    println!(
        "1 cm beside the ball:       {}",
        if r.missed_beside_ball {
            "nothing (exact test)"
        } else {
            "a hit (wrong)"
        }
    );
    Ok(())
}
