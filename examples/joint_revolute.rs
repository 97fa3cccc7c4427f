//! The revolute joint, twice: a motorised arm lifted against gravity to its
//! upper angle limit (when it gets there, by how much it overshoots, and
//! the torque the joint holds it with against the statics `m g (L/2) cos θ`),
//! and a pendulum whose period is set beside `2π √(L/g) (1 + θ₀²/16)`.
//! Run with `cargo run --release --example joint_revolute`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// A 1 m, 2 kg arm pinned at one end to the ground, its motor turning at
/// 1 rad/s with at most 40 N·m, limits [−0.2, 1.0] rad.
fn arm() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let arm = world.create_body(&BodyDef::dynamic(Vec2::new(0.5, 0.0)))?;
    // 1 m × 0.1 m at 20 kg/m² = 2 kg.
    let shape = ShapeDef::default().with_density(20.0);
    world.create_shape(arm, &shape, Polygon::make_box(0.5, 0.05))?;
    let (lower, upper) = (-0.2, 1.0);
    let def = RevoluteJointDef::from_base(world.joint_base_at(ground, arm, Vec2::ZERO)?)
        .with_limits(lower, upper)
        .with_motor(1.0, 40.0);
    let pin = world.create_joint(&def.into())?;
    let (mut reached, mut overshoot, mut gap): (Option<Real>, Real, Real) = (None, 0.0, 0.0);
    for step in 1..=180 {
        world.step(DT)?;
        let angle = world.joint_angle(pin)?;
        if reached.is_none() && angle >= upper - 1e-3 {
            reached = Some(step as Real * DT);
        }
        overshoot = overshoot.max(angle - upper);
        gap = gap.max(world.joint_gap(pin)?);
    }
    let angle = world.joint_angle(pin)?;
    let statics = world.mass(arm)? * -world.gravity().y * 0.5 * angle.cos();
    println!(
        "arm: reached the {upper:.1} rad limit at t = {:.2} s, overshoot {:.2} mrad, pin gap at most \
         {:.3} mm; the joint holds it with {:.2} N·m (m g L/2 cos θ = {statics:.2} N·m)",
        reached.unwrap_or(Real::NAN),
        1e3 * overshoot.max(0.0),
        1e3 * gap,
        world.joint_torque(pin)?,
    );
    Ok(())
}

/// A 1 kg bob on a 2 m massless rod, let go 0.1 rad from the vertical.
fn pendulum() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let length: Real = 2.0;
    let start = 0.1 as Real;
    let at = Vec2::new(length * start.sin(), -length * start.cos());
    let bob = world.create_body(&BodyDef::dynamic(at).with_mass(1.0, 1e-3))?;
    let pin = world.create_joint(&RevoluteJointDef::new(ground, bob, Vec2::ZERO, -at).into())?;
    // Upward crossings of x = 0 (moving +x), interpolated within the step.
    let (mut crossings, mut last_x, mut gap) = (Vec::new(), at.x, 0.0 as Real);
    for step in 1..=720 {
        world.step(DT)?;
        let x = world.position(bob)?.x;
        if last_x < 0.0 && x >= 0.0 {
            crossings.push((step as Real - x / (x - last_x)) * DT);
        }
        last_x = x;
        gap = gap.max(world.joint_gap(pin)?);
    }
    let periods = crossings.len().saturating_sub(1);
    let period = (crossings[periods] - crossings[0]) / periods as Real;
    // The small-angle period with the first correction for the amplitude.
    let ideal = janus2d::base::math::TAU
        * (length / -world.gravity().y).sqrt()
        * (1.0 + start * start / 16.0);
    println!(
        "pendulum: period {period:.4} s over {periods} swings (2π √(L/g) (1 + θ₀²/16) = \
         {ideal:.4} s), \
         pin gap at most {:.3} mm",
        1e3 * gap
    );
    Ok(())
}

fn main() -> Result<(), WorldError> {
    arm()?;
    pendulum()
}
