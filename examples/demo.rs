//! The main job: three scenes simulated headless, with a short readout of
//! what happened in each. Run with `cargo run --release --example demo`.
//!
//! 1. A pyramid of 210 boxes settles on the ground (contacts, stacking).
//! 2. The tumbler: a motor turns a drum full of 2,025 small boxes.
//! 3. The portal drop: a box falls into a floor portal and flies out of a wall.

use std::time::Instant;

use janus2d::prelude::*;
use janus2d_testbed::scenes::{self, DT};

fn main() -> Result<(), WorldError> {
    println!("janus2d demo: dt = 1/60 s, 4 substeps, headless\n");

    // 1. Pyramid.
    let mut def = WorldDef::default();
    def.sleep.enabled = false;
    let mut s = scenes::large_pyramid(&def, 20);
    let top0 = s.world.position(s.probe)?;
    let t0 = Instant::now();
    let mut penetration: Real = 0.0;
    for _ in 0..300 {
        s.world.step(DT)?;
        penetration = penetration.max(s.world.max_penetration());
    }
    let top = s.world.position(s.probe)?;
    println!(
        "1. pyramid of {} boxes, 5 s simulated in {:.0} ms",
        s.world.body_count() - 1,
        t0.elapsed().as_secs_f64() * 1e3
    );
    println!(
        "   top box {:.3} m -> {:.3} m (sank {:.1} mm, drifted {:.2} mm); {} contacts; worst penetration {:.2} mm",
        top0.y,
        top.y,
        (top0.y - top.y) * 1e3,
        (top.x - top0.x).abs() * 1e3,
        s.world.touching_contact_count(),
        penetration * 1e3
    );

    // 2. Tumbler (sleep on, as Box2D's benchmark runs it).
    let mut s = scenes::tumbler(&WorldDef::default());
    let t0 = Instant::now();
    for _ in 0..180 {
        s.world.step(DT)?;
    }
    println!(
        "2. tumbler: {} bodies, 3 s simulated in {:.0} ms; drum turned {:.1} deg (motor 25 deg/s); {} contacts, {} bodies asleep",
        s.world.body_count(),
        t0.elapsed().as_secs_f64() * 1e3,
        s.world.angle(s.probe)?.to_degrees(),
        s.world.touching_contact_count(),
        s.world.sleeping_body_count()
    );

    // 3. Portal drop.
    #[cfg(feature = "portals")]
    {
        use janus2d::world::PortalEvent;
        let (mut s, _) = scenes::portal_drop(&WorldDef::default());
        println!(
            "3. portal drop: a 1 m box falls 5 m onto a floor portal; the partner is on a wall facing +x"
        );
        for step in 1..=90 {
            let v_before = s.world.linear_velocity(s.probe)?;
            s.world.step(DT)?;
            for e in &s.world.events().portals {
                let t = step as Real * DT;
                match e {
                    PortalEvent::CrossingStarted { .. } => {
                        println!(
                            "   t = {t:.3} s: enters the floor portal at {:.2} m/s; clone created",
                            v_before.length()
                        )
                    }
                    PortalEvent::CrossingCompleted { body, .. } => {
                        let v = s.world.linear_velocity(*body)?;
                        println!(
                            "   t = {t:.3} s: through; the same handle now flies at ({:.2}, {:.2}) m/s from {}",
                            v.x,
                            v.y,
                            s.world.position(*body)?
                        )
                    }
                    other => println!("   t = {t:.3} s: {other:?}"),
                }
            }
        }
        println!("   bodies now: {} (floor, wall, box)", s.world.body_count());
    }
    Ok(())
}
