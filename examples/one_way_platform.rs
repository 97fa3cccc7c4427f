//! A one-way platform, headless: a box thrown up from below passes through
//! a thin platform and lands on it, through a pre-solve hook
//! (`World::set_pre_solve`). Run with `cargo run --release --example
//! one_way_platform`.

use janus2d::prelude::*;

/// What happened to the box (the pre-solve test reads it too).
pub struct Report {
    /// Highest centre height the box reached, m.
    pub peak: Real,
    /// Centre height at the end, m.
    pub end: Real,
    /// Top of the platform, m.
    pub platform_top: Real,
}

/// Throws a box up through a platform at y = 3 and lets it land on it.
pub fn run() -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))?;
    let platform = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 3.0)))?;
    let top = world.create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.1))?;
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)).with_velocity(Vec2::new(0.0, 9.0)))?;
    world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.25, 0.25))?;
    // The platform holds only what comes down onto it from above: the
    // normal from the platform to the other body points up, and the other
    // body is not moving up through it.
    world.set_pre_solve(Some(Box::new(move |c| {
        let (normal, other_v) = if c.shape_a == top {
            (c.normal, c.velocity_b)
        } else if c.shape_b == top {
            (-c.normal, c.velocity_a)
        } else {
            return true;
        };
        normal.y > 0.7 && other_v.y <= 0.5
    })));
    let mut peak = Real::MIN;
    for _ in 0..240 {
        world.step(1.0 / 60.0)?;
        peak = peak.max(world.position(b)?.y);
    }
    Ok(Report {
        peak,
        end: world.position(b)?.y,
        platform_top: 3.1,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "one-way platform: box thrown up from y = 0.5 at 9 m/s rose to {:.2} m (through the platform, top at {:.2} m) and rests at {:.3} m on it",
        r.peak, r.platform_top, r.end
    );
    Ok(())
}
