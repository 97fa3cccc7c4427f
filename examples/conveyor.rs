//! Conveyor belts, headless: two belts carry boxes, one through its
//! surface material (`ShapeDef::tangent_speed`), one through the
//! pre-solve hook (`PreSolve::tangent_speed`, switched off half-way); a
//! ball with rolling resistance rolls to a stop beside them. Prints the
//! speeds and distances (numbers). Run with `cargo run --release
//! --example conveyor`.

use janus2d::prelude::*;

/// What happened.
pub struct Report {
    /// Speed of the box on the material belt after 2 s, m/s.
    pub material_belt: Real,
    /// Speed of the box on the hooked belt after 2 s (the hook on), m/s.
    pub hooked_belt_on: Real,
    /// Its speed 3 s after the hook stopped the belt, m/s.
    pub hooked_belt_off: Real,
    /// Distance the ball rolled before it stopped, m.
    pub ball_distance: Real,
    /// Ball's speed at the end, m/s.
    pub ball_speed: Real,
}

/// Runs the scene for 5 s.
pub fn run() -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    // Belt 1: the material moves at 2 m/s (clockwise round the box: its
    // top towards +x).
    let g1 = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    let belt = ShapeDef::default().with_tangent_speed(2.0);
    world.create_shape(g1, &belt, Polygon::make_box(20.0, 0.5))?;
    // Belt 2, 5 m lower: a plain box whose speed the hook sets.
    let g2 = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -5.5)))?;
    let hooked = world.create_shape(g2, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    let on = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let switch = on.clone();
    world.set_pre_solve(Some(Box::new(move |c| {
        if (c.shape_a == hooked || c.shape_b == hooked)
            && switch.load(std::sync::atomic::Ordering::Relaxed)
        {
            c.tangent_speed = -1.0;
        }
        true
    })));
    let unit = Polygon::make_box(0.25, 0.25);
    let box1 = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.25)))?;
    world.create_shape(box1, &ShapeDef::default(), unit)?;
    let box2 = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, -4.75)))?;
    world.create_shape(box2, &ShapeDef::default(), unit)?;
    // A ball on a plain stretch of the first belt's level, well apart.
    let g3 = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -10.5)))?;
    world.create_shape(g3, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    let ball = world.create_body(
        &BodyDef::dynamic(Vec2::new(-15.0, -9.5))
            .with_velocity(Vec2::new(3.0, 0.0))
            .with_angular_velocity(-6.0),
    )?;
    let rolling = ShapeDef::default().with_rolling_resistance(0.1);
    world.create_shape(ball, &rolling, Circle::new(Vec2::ZERO, 0.5)?)?;
    let dt = 1.0 / 60.0;
    for _ in 0..120 {
        world.step(dt)?;
    }
    let material_belt = world.linear_velocity(box1)?.x;
    let hooked_belt_on = world.linear_velocity(box2)?.x;
    on.store(false, std::sync::atomic::Ordering::Relaxed);
    for _ in 0..180 {
        world.step(dt)?;
    }
    Ok(Report {
        material_belt,
        hooked_belt_on,
        hooked_belt_off: world.linear_velocity(box2)?.x,
        ball_distance: world.position(ball)?.x + 15.0,
        ball_speed: world.linear_velocity(ball)?.x,
    })
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "conveyor: the box on the material belt (tangent speed 2 m/s) moves at {:.3} m/s",
        r.material_belt
    );
    println!(
        "          the box on the hooked belt (-1 m/s) moves at {:.3} m/s, and {:.3} m/s 3 s after the hook stopped the belt",
        r.hooked_belt_on, r.hooked_belt_off
    );
    println!(
        "          the ball with rolling resistance 0.1 rolled {:.2} m from 3 m/s (predicted {:.2} m) and moves at {:.4} m/s",
        r.ball_distance,
        9.0 / (2.0 * 2.0 / 3.0 * 0.1 * 9.81),
        r.ball_speed
    );
    Ok(())
}
