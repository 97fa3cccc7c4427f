//! The distance joint twice: a rope (maximum length only) that lets a ball
//! fall slack until it goes taut and then swings it, and a spring (2 Hz,
//! ζ 0.05, length limits) that a weight bounces on. Prints when the rope
//! went taut against free fall, its worst stretch past its length and its
//! tension at the bottom of the swing against `m (g + v²/L)`; then the
//! spring's resting length and frequency against `L₀ + g/(2πf)²` and
//! `f √(1 − ζ²)`. Run with `cargo run --release --example joint_distance`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// A 5 kg ball 1.5 m beside the anchor on a 2 m rope.
fn rope() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let g = -world.gravity().y;
    let hook = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let side: Real = 1.5;
    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(side, 0.0)))?;
    let shape = ShapeDef::default().with_density(5.0 / (janus2d::base::math::PI * 0.04));
    world.create_shape(ball, &shape, Circle::new(Vec2::ZERO, 0.2)?)?;
    let max = 2.0;
    let rope = world
        .create_joint(&DistanceJointDef::rope(hook, ball, Vec2::ZERO, Vec2::ZERO, max).into())?;
    let (mut taut_at, mut stretch, mut bottom) = (None, 0.0 as Real, None);
    let mut last_x = side;
    for step in 1..=120 {
        world.step(DT)?;
        let length = world.joint_gap(rope)?;
        if taut_at.is_none() && world.joint_force(rope)?.length() > 0.0 {
            taut_at = Some(step as Real * DT);
        }
        stretch = stretch.max(length - max);
        // The bottom of the swing: the ball crosses under the hook.
        let x = world.position(ball)?.x;
        if bottom.is_none() && last_x > 0.0 && x <= 0.0 {
            let speed = world.linear_velocity(ball)?.length();
            let tension = world.joint_force(rope)?.length();
            bottom = Some((
                speed,
                tension,
                world.mass(ball)? * (g + speed * speed / length),
            ));
        }
        last_x = x;
    }
    let fall = (2.0 * (max * max - side * side).sqrt() / g).sqrt();
    let (speed, tension, expected) = bottom.unwrap_or((Real::NAN, Real::NAN, Real::NAN));
    println!(
        "rope: slack until t = {:.3} s (free fall to taut: {fall:.3} s), at most {:.2} mm past its \
         {max} m; at the bottom {speed:.2} m/s, tension {tension:.0} N (m (g + v²/L) = {expected:.0} N)",
        taut_at.unwrap_or(Real::NAN),
        1e3 * stretch.max(0.0)
    );
    Ok(())
}

/// A 1 kg weight hanging on a 1 m spring of 2 Hz, ζ 0.05, kept between
/// 0.5 and 1.5 m, let go at its rest length.
fn spring() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let g = -world.gravity().y;
    let hook = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let weight = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, -1.0)).with_mass(1.0, 0.01))?;
    let (hertz, zeta): (Real, Real) = (2.0, 0.05);
    let def = DistanceJointDef::new(hook, weight, Vec2::ZERO, Vec2::ZERO, 1.0)
        .with_spring(hertz, zeta)
        .with_limits(0.5, 1.5);
    let spring = world.create_joint(&def.into())?;
    // Times the length passes a maximum.
    let (mut peaks, mut prev, mut rising) = (Vec::new(), 1.0 as Real, true);
    for step in 1..=600 {
        world.step(DT)?;
        let length = world.joint_gap(spring)?;
        if rising && length < prev {
            peaks.push(step as Real * DT);
        }
        rising = length >= prev;
        prev = length;
    }
    let n = peaks.len().min(6) - 1;
    let frequency = n as Real / (peaks[n] - peaks[0]);
    let omega = janus2d::base::math::TAU * hertz;
    println!(
        "spring: rests at {:.4} m (L₀ + g/(2πf)² = {:.4} m), bounces at {frequency:.3} Hz \
         (f √(1 − ζ²) = {:.3} Hz), holds {:.2} N",
        world.joint_gap(spring)?,
        1.0 + g / (omega * omega),
        hertz * (1.0 - zeta * zeta).sqrt(),
        world.joint_force(spring)?.y
    );
    Ok(())
}

fn main() -> Result<(), WorldError> {
    rope()?;
    spring()
}
