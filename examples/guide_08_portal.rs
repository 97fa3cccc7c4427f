//! Guide step 8 (docs/guide.md): a portal. Two openings on two bodies make
//! a pair; a body that enters one gets a clone at the other, the two move
//! as one while the body straddles, and when it is through, the same
//! handle names the body that came out. Here a crate falls into a portal
//! in the floor and flies out of a wall, and a ray looks through the pair.
//! Needs the `portals` feature (on by default). Run with `cargo run
//! --example guide_08_portal`.

use janus2d::prelude::*;
use janus2d::{PortalDef, PortalEvent, PortalPairDef};

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(-20.0, 5.0)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))?;

    // Each portal: the body it is cut into, its centre and outward
    // direction in that body's frame, and its half width. The floor's top
    // faces +y; the wall's right face faces +x.
    let pair = world.create_portal_pair(&PortalPairDef::new(
        PortalDef {
            body: floor,
            anchor: Vec2::new(0.0, 0.5),
            direction: Vec2::Y,
            half_width: 1.0,
        },
        PortalDef {
            body: wall,
            anchor: Vec2::new(0.5, 0.0),
            direction: Vec2::X,
            half_width: 1.0,
        },
    ))?;

    // A target on the wall's side, in line with the portal.
    let target = world.create_body(&BodyDef::fixed(Vec2::new(-6.0, 6.0)))?;
    world.create_shape(target, &ShapeDef::default(), Polygon::make_box(0.25, 2.0))?;

    let crate_ = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0)))?;
    world.create_shape(crate_, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;

    for step in 1..=90 {
        world.step(1.0 / 60.0)?;
        for event in &world.events().portals {
            match event {
                PortalEvent::CrossingStarted { body, clone, .. } => {
                    let who = if *body == crate_ {
                        "the crate"
                    } else {
                        "a body"
                    };
                    println!(
                        "step {step}: {who} enters the floor portal; its clone {clone:?} appears at the wall"
                    )
                }
                PortalEvent::CrossingCompleted { body, .. } => {
                    let who = if *body == crate_ {
                        "the crate"
                    } else {
                        "a body"
                    };
                    println!(
                        "step {step}: {who} is through; the handle now names the body at the wall"
                    )
                }
                other => println!("step {step}: {other:?}"),
            }
        }
    }
    let p = world.position(crate_)?;
    let v = world.linear_velocity(crate_)?;
    println!(
        "the crate is at ({:.2}, {:.2}) moving ({:.1}, {:.1}) m/s: out of the wall",
        p.x, p.y, v.x, v.y
    );

    // A ray down into the floor portal continues out of the wall, along +x.
    let through = QueryFilter::default().through_portals();
    let down = world.cast_ray_closest(Vec2::new(0.3, 3.0), Vec2::new(0.0, -40.0), &through)?;
    if let Some(hit) = down {
        println!(
            "a ray cast down into the floor portal hits the target: {} at ({:.2}, {:.2}), through {} portal",
            hit.body == target,
            hit.point.x,
            hit.point.y,
            hit.portal_hops
        );
    }
    // The pair's map takes a point that went into the floor portal to where
    // it comes out of the wall (η scales distances; 1 here).
    let map = world.portal_map(pair)?;
    let out = map.map_point(Vec2::new(0.0, -0.5));
    println!(
        "half a metre into the floor portal, (0, -0.5), comes out at ({:.2}, {:.2}), half a metre out of the wall (η = {})",
        out.x, out.y, map.eta
    );
    Ok(())
}
