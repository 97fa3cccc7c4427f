//! A 5 cm ball fired at 300 m/s at a 10 cm wall, headless, with and without
//! continuous collision, and a readout of where it ended. Run with
//! `cargo run --release --example bullet`.

use janus2d::prelude::*;

/// Where the ball went (the continuous-collision test reads it too).
pub struct Report {
    /// Front face of the wall, m (the ball starts left of it).
    pub wall_face: Real,
    /// Largest x the ball's centre reached with continuous collision, m.
    pub max_x_continuous: Real,
    /// The ball's x after the run with continuous collision, m.
    pub final_x_continuous: Real,
    /// The ball's x after the run without continuous collision, m.
    pub final_x_discrete: Real,
    /// Steps in which continuous collision moved the ball back.
    pub toi_hits: usize,
}

/// The ball's centre after `steps` steps of `dt`, the largest x it reached
/// and the TOI hits, with continuous collision on or off.
pub fn shoot(continuous: bool, dt: Real, steps: usize) -> Result<(Real, Real, usize), WorldError> {
    let mut world = World::new(WorldDef {
        enable_continuous: continuous,
        ..WorldDef::default()
    })?;
    // The wall: 10 cm thick (x from 0 to 0.1), 4 m tall, on the ground.
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(0.05, 2.0)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.05, 2.0))?;
    // The ball, 5 cm across, one step's travel (5 m at 1/60 s) from the wall.
    let speed: Real = 300.0;
    let start = Vec2::new(-0.5 * speed * dt, 1.0);
    let ball = world.create_body(&BodyDef::dynamic(start).with_velocity(Vec2::new(speed, 0.0)))?;
    world.create_shape(ball, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.025)?)?;
    let mut max_x = Real::MIN;
    let mut hits = 0;
    for _ in 0..steps {
        world.step(dt)?;
        max_x = max_x.max(world.position(ball)?.x);
        hits += world.counters().toi_hits;
    }
    Ok((world.position(ball)?.x, max_x, hits))
}

/// Fires the ball for half a second at 60 Hz both ways.
pub fn run() -> Result<Report, WorldError> {
    let dt: Real = 1.0 / 60.0;
    let (final_x_continuous, max_x_continuous, toi_hits) = shoot(true, dt, 30)?;
    let (final_x_discrete, _, _) = shoot(false, dt, 30)?;
    Ok(Report {
        wall_face: 0.0,
        max_x_continuous,
        final_x_continuous,
        final_x_discrete,
        toi_hits,
    })
}

#[allow(dead_code)]
fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "a 5 cm ball at 300 m/s against a 10 cm wall (face at x = {})",
        r.wall_face
    );
    println!(
        "continuous on:  furthest x = {:.4} m, final x = {:.4} m, moved back {} time(s)",
        r.max_x_continuous, r.final_x_continuous, r.toi_hits
    );
    println!(
        "continuous off: final x = {:.4} m ({})",
        r.final_x_discrete,
        if r.final_x_discrete > 0.1 {
            "through the wall"
        } else {
            "stopped"
        }
    );
    Ok(())
}
