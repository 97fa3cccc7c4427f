//! The portal drop scene, headless: a 1 m box falls 5 m onto a floor portal
//! and comes out of a wall portal moving sideways. Prints a timeline of
//! positions, velocities and portal events.
//!
//! Run with `cargo run --release --example portal`.

use janus2d::prelude::*;
use janus2d::world::PortalEvent;
use janus2d_testbed::scenes::{self, DT};

fn main() -> Result<(), WorldError> {
    let (mut scene, _pair) = scenes::portal_drop(&WorldDef::default());
    let world = &mut scene.world;
    let body = scene.probe;
    println!(
        "janus2d portal drop: 1 m box falls 5 m onto a floor portal; the partner is on a wall facing +x"
    );
    println!(
        "{:>6} {:>9} {:>9} {:>9} {:>9} {:>7} {:>8}  events",
        "t [s]", "x", "y", "vx", "vy", "bodies", "|C| mm"
    );
    for step in 1..=150 {
        world.step(DT)?;
        let p = world.position(body)?;
        let v = world.linear_velocity(body)?;
        let dynamic = world
            .body_handles()
            .filter(|h| world.body_type(*h) == Ok(BodyType::Dynamic))
            .count();
        let events: Vec<String> = world
            .events()
            .portals
            .iter()
            .map(|e| match e {
                PortalEvent::CrossingStarted { .. } => {
                    "crossing started (clone created)".to_string()
                }
                PortalEvent::CrossingCompleted { .. } => {
                    "crossing completed (handover)".to_string()
                }
                PortalEvent::CrossingCancelled { .. } => "crossing cancelled".to_string(),
                PortalEvent::JointDisabled { .. } => "joint disabled".to_string(),
            })
            .collect();
        if step % 10 == 0 || !events.is_empty() || world.crossing_count() > 0 {
            println!(
                "{:>6.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>7} {:>8.3}  {}",
                step as Real * DT,
                p.x,
                p.y,
                v.x,
                v.y,
                dynamic,
                world.max_portal_error() * 1000.0,
                events.join(", ")
            );
        }
    }
    Ok(())
}
