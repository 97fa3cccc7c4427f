//! A plank across a portal's aperture, headless: a 4 m plank dropped so
//! that one end lies over a 1 m floor portal rests on the solid floor and
//! the lip (the wall collides as its solid parts), while a 0.6 m box
//! dropped beside it falls into the aperture and comes out of a wall
//! portal. Run with `cargo run --release --example portal_plank`.

use janus2d::prelude::*;
use janus2d::world::{PortalDef, PortalEvent, PortalPairDef};

/// What happened (the portal aperture test reads it too).
pub struct Report {
    /// Deepest the plank's lowest point went below the floor in its last
    /// second, m.
    pub plank_sink: Real,
    /// The plank's angle at the end, rad.
    pub plank_angle: Real,
    /// Whether the plank ever began a crossing.
    pub plank_crossed: bool,
    /// Whether the box went through.
    pub box_through: bool,
    /// The box's position at the end, m.
    pub box_end: Vec2,
}

/// Lowest point of a body's shapes along +y, m.
fn lowest(world: &World, body: BodyHandle) -> Result<Real, WorldError> {
    let xf = world.transform(body)?;
    let mut low = Real::MAX;
    for s in world.body_shapes(body)? {
        low = low.min(world.shape(s)?.geometry.support_extent(&xf, Vec2::Y).0);
    }
    Ok(low)
}

/// Drops the plank and the box and runs 3 s.
pub fn run() -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    // Floor with its top at y = 0; a wall far to the left.
    let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(-30.0, 5.0)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))?;
    let at = |body, anchor, direction| PortalDef {
        body,
        anchor,
        direction,
        half_width: 0.5,
    };
    world.create_portal_pair(&PortalPairDef::new(
        at(floor, Vec2::new(0.0, 0.5), Vec2::Y),
        at(wall, Vec2::new(0.5, 0.0), Vec2::X),
    ))?;
    // The plank: x from 0.3 (over the aperture, which spans ±0.5) to 4.3,
    // 0.2 m thick, dropped from 0.3 m.
    let plank = world.create_body(&BodyDef::dynamic(Vec2::new(2.3, 0.4)))?;
    world.create_shape(plank, &ShapeDef::default(), Polygon::make_box(2.0, 0.1))?;
    // The box: 0.6 m, over the rest of the aperture (x from −0.45 to
    // 0.15), dropped from 1 m.
    let b = world.create_body(&BodyDef::dynamic(Vec2::new(-0.15, 1.3)))?;
    world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))?;
    let (mut plank_sink, mut plank_crossed, mut box_through) = (0.0 as Real, false, false);
    for step in 0..180 {
        world.step(1.0 / 60.0)?;
        for e in &world.events().portals {
            match *e {
                PortalEvent::CrossingStarted { body, .. } if body == plank => plank_crossed = true,
                PortalEvent::CrossingCompleted { body, .. } if body == b => box_through = true,
                _ => {}
            }
        }
        if step >= 120 {
            plank_sink = plank_sink.max(-lowest(&world, plank)?);
        }
    }
    Ok(Report {
        plank_sink,
        plank_angle: world.angle(plank)?,
        plank_crossed,
        box_through,
        box_end: world.position(b)?,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "plank with one end over a 1 m aperture: rests {:.3} mm into the floor at {:.5} rad (crossing begun: {})",
        r.plank_sink * 1000.0,
        r.plank_angle,
        r.plank_crossed
    );
    println!(
        "0.6 m box over the aperture: went through {}, now at ({:.2}, {:.2}), out of the wall portal at x = -29.5",
        r.box_through, r.box_end.x, r.box_end.y
    );
    Ok(())
}
