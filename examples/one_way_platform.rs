//! A one-way platform, headless: a box thrown up from below passes through
//! a thin platform and lands on it, through a pre-solve hook
//! (`World::set_pre_solve`) that leaves out the platform's contacts with
//! bodies below it or moving up. Prints the heights (numbers). Run with
//! `cargo run --release --example one_way_platform`.

use janus2d::prelude::*;

/// What happened to the box (the pre-solve test reads it too).
pub struct Report {
    /// Highest centre height the box reached, m.
    pub peak: Real,
    /// Centre height at the end, m.
    pub end: Real,
    /// Top of the platform, m.
    pub platform_top: Real,
    /// Centre height over the last second (60 steps), m.
    pub last_second: Vec<Real>,
    /// Steps in which the hook left a platform contact out.
    pub skipped: usize,
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
    let skipped = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let count = skipped.clone();
    world.set_pre_solve(Some(Box::new(move |c| {
        let (normal, other_v) = if c.shape_a == top {
            (c.normal, c.velocity_b)
        } else if c.shape_b == top {
            (-c.normal, c.velocity_a)
        } else {
            return true;
        };
        let hold = normal.y > 0.7 && other_v.y <= 0.5;
        if !hold {
            count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        hold
    })));
    let mut peak = Real::MIN;
    let mut last_second = Vec::new();
    for i in 0..240 {
        world.step(1.0 / 60.0)?;
        let y = world.position(b)?.y;
        peak = peak.max(y);
        if i >= 180 {
            last_second.push(y);
        }
    }
    Ok(Report {
        peak,
        end: world.position(b)?.y,
        platform_top: 3.1,
        last_second,
        skipped: skipped.load(std::sync::atomic::Ordering::Relaxed),
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "one-way platform: box thrown up from y = 0.5 at 9 m/s rose to {:.2} m (through the platform, top at {:.2} m) and rests at {:.3} m on it",
        r.peak, r.platform_top, r.end
    );
    let (lo, hi) = r
        .last_second
        .iter()
        .fold((Real::MAX, Real::MIN), |(lo, hi), &y| {
            (lo.min(y), hi.max(y))
        });
    println!(
        "  the hook left the platform contact out in {} steps; over the last second the centre stayed in [{lo:.4}, {hi:.4}] m (rest {:.3} m)",
        r.skipped,
        r.platform_top + 0.25
    );
    Ok(())
}
