//! A kinematic platform driven round a circle with `set_target_transform`,
//! carrying a box, simulated headless with a short readout. Run with
//! `cargo run --release --example moving_platform`.

use janus2d::prelude::*;

/// What the ride did (the kinematic-target test reads it too).
pub struct Report {
    /// Largest distance of the box from where it started on the platform, m.
    pub max_drift: Real,
    /// Largest distance of the platform from its target after a step, m.
    pub max_platform_error: Real,
    /// Steps simulated.
    pub steps: usize,
}

/// One full turn of radius 2 m in 2π s at 60 Hz.
pub fn run() -> Result<Report, WorldError> {
    let dt: Real = 1.0 / 60.0;
    let path = |t: Real| Vec2::new(2.0 * t.cos(), 5.0 + 2.0 * t.sin());
    let mut world = World::new(WorldDef::default())?;
    let platform = world.create_body(&BodyDef::kinematic(path(0.0)))?;
    world.create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.2))?;
    let rider = world.create_body(&BodyDef::dynamic(path(0.0) + Vec2::new(0.5, 0.45)))?;
    world.create_shape(rider, &ShapeDef::default(), Polygon::make_box(0.25, 0.25))?;
    for _ in 0..30 {
        world.step(dt)?;
    }
    let offset0 = world.position(rider)? - world.position(platform)?;
    let steps = (janus2d::base::math::TAU / dt).ceil() as usize;
    let (mut max_drift, mut max_platform_error): (Real, Real) = (0.0, 0.0);
    for k in 1..=steps {
        let target = path(k as Real * dt);
        world.set_target_transform(platform, Transform::new(target, 0.0), dt)?;
        world.step(dt)?;
        let p = world.position(platform)?;
        max_platform_error = max_platform_error.max((p - target).length());
        let offset = world.position(rider)? - p;
        max_drift = max_drift.max((offset - offset0).length());
        if k % 60 == 0 {
            println!(
                "t = {:4.1} s  platform ({:6.3}, {:6.3})  rider offset ({:6.3}, {:6.3})",
                k as Real * dt,
                p.x,
                p.y,
                offset.x,
                offset.y
            );
        }
    }
    Ok(Report {
        max_drift,
        max_platform_error,
        steps,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "{} steps: the rider moved at most {:.4} m on the platform; the platform was at most {:.2e} m off its target",
        r.steps, r.max_drift, r.max_platform_error
    );
    Ok(())
}
