//! A box thrown at a grazing angle into a floor portal, headless: 0.2 m,
//! at 10° below the horizontal and 60 m/s, aimed near the aperture's near
//! lip. It crosses in the step it reaches the aperture (no speculative
//! contact computed over the lip stops it) and leaves the wall portal at
//! its entry speed along the mapped direction. Gravity is off, so the exit
//! velocity should be exactly `Q` applied to the entry velocity. Run with
//! `cargo run --release --example portal_grazing`.

use janus2d::prelude::*;
use janus2d::world::{PortalDef, PortalEvent, PortalPairDef};

/// What happened (the grazing test reads it too).
pub struct Report {
    /// Entry speed, m/s.
    pub entry_speed: Real,
    /// Exit velocity, m/s.
    pub exit_velocity: Vec2,
    /// The mapped entry direction `Q d` (unit).
    pub expected_direction: Vec2,
    /// Steps from the throw to the end of the crossing (None: never).
    pub crossed_at: Option<usize>,
}

/// Throws the box and runs until it is through (at most 1 s).
pub fn run() -> Result<Report, WorldError> {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    };
    let mut world = World::new(def)?;
    let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(30.0, 0.5))?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(-60.0, 10.0)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 10.0))?;
    let at = |body, anchor, direction| PortalDef {
        body,
        anchor,
        direction,
        half_width: 1.5,
    };
    world.create_portal_pair(&PortalPairDef::new(
        at(floor, Vec2::new(0.0, 0.5), Vec2::Y),
        at(wall, Vec2::new(0.5, 0.0), Vec2::X),
    ))?;
    let angle = (10.0 as Real).to_radians();
    let speed: Real = 60.0;
    let dir = Vec2::new(angle.cos(), -angle.sin());
    // The centre reaches the floor plane at x = −0.8: the box clears the
    // near lip (x = −1.5) by 2 cm as its bottom reaches the plane.
    let start = Vec2::new(-0.8, 0.0) - dir * 4.0;
    let b = world.create_body(&BodyDef::dynamic(start).with_velocity(dir * speed))?;
    world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.1, 0.1))?;
    let mut crossed_at = None;
    for step in 0..60 {
        world.step(1.0 / 60.0)?;
        if world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::CrossingCompleted { .. }))
        {
            crossed_at = Some(step);
            break;
        }
    }
    Ok(Report {
        entry_speed: speed,
        exit_velocity: world.linear_velocity(b)?,
        // Q turns the floor's −y (in) into the wall's +x (out): (c, −s) ↦ (s, c).
        expected_direction: Vec2::new(angle.sin(), angle.cos()),
        crossed_at,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    let v = r.exit_velocity;
    let off = r
        .expected_direction
        .perp_dot(v)
        .atan2(r.expected_direction.dot(v));
    match r.crossed_at {
        Some(step) => println!(
            "grazing throw at 10°, {:.0} m/s: through after {} steps, out at {:.3} m/s ({:+.4}% of the entry speed), {:.4}° off the mapped direction",
            r.entry_speed,
            step + 1,
            v.length(),
            (v.length() / r.entry_speed - 1.0) * 100.0,
            off.to_degrees()
        ),
        None => println!("grazing throw: the box never went through (velocity {v})"),
    }
    Ok(())
}
