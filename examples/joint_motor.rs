//! The motor joint: a 50 kg rider (a 1 m box) is held by its feet 0.7 m
//! above a kinematic platform's origin, upright, by a motor joint of at
//! most 1,500 N and 2,000 N·m (correction factor 0.3, Box2D's default). It
//! starts 0.3 m off its target while the platform swings `x = 3 sin(ωt)` m
//! with a 4 s period (7.4 m/s² at the ends). Prints how long the drive
//! took to catch the rider, the worst offset and angle errors after that,
//! and the drive's force against its bound and the rider's weight.
//! Run with `cargo run --release --example joint_motor`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let platform = world.create_body(&BodyDef::kinematic(Vec2::ZERO))?;
    world.create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.1))?;
    let rider = world.create_body(&BodyDef::dynamic(Vec2::new(0.3, 1.2)))?;
    world.create_shape(rider, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
    world.set_mass(rider, BodyMass::new(50.0, 50.0 / 6.0))?;
    // Frame a at the platform's origin, frame b at the rider's feet; the
    // offset is taken in frame a.
    let feet = Vec2::new(0.0, -0.5);
    let offset = Vec2::new(0.0, 0.7);
    let max_force = 1500.0;
    let base = JointDefBase::with_anchors(platform, rider, Vec2::ZERO, feet);
    let def = MotorJointDef::from_base(base)
        .with_offset(offset, 0.0)
        .with_max_force(max_force)
        .with_max_torque(2000.0);
    let drive = world.create_joint(&def.into())?;

    let omega = janus2d::base::math::TAU / 4.0;
    let (mut caught, mut worst, mut worst_angle) = (None, 0.0 as Real, 0.0 as Real);
    let (mut peak, mut lift) = (0.0 as Real, (Real::MAX, Real::MIN));
    for step in 1..=480 {
        let t = step as Real * DT;
        let target = Vec2::new(3.0 * (omega * t).sin(), 0.0);
        world.set_target_transform(platform, Transform::new(target, 0.0), DT)?;
        world.step(DT)?;
        // Where the feet are against where the offset puts them.
        let want = world.transform(platform)?.apply(offset);
        let error = (world.transform(rider)?.apply(feet) - want).length();
        let angle = world.joint_angle(drive)?.abs();
        let force = world.joint_force(drive)?;
        peak = peak.max(force.length());
        if caught.is_none() && error < 0.01 && angle < 0.01 {
            caught = Some(t);
        }
        if t > 2.0 {
            worst = worst.max(error);
            worst_angle = worst_angle.max(angle);
            lift = (lift.0.min(force.y), lift.1.max(force.y));
        }
    }
    let weight = world.mass(rider)? * -world.gravity().y;
    println!(
        "rider first within 1 cm and 0.01 rad of its target at t = {:.2} s; after 2 s the worst \
         offset error is {:.4} mm and angle error {worst_angle:.1e} rad",
        caught.unwrap_or(Real::NAN),
        1e3 * worst
    );
    println!(
        "drive force: peak {peak:.0} N while catching (max_force {max_force} N); after 2 s it lifts \
         {:.1} to {:.1} N (weight {weight:.0} N); contacts on the rider: {}",
        lift.0,
        lift.1,
        world.body_contacts(rider)?.count()
    );
    Ok(())
}
