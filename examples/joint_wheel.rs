//! The wheel joint as a car: a 50 kg chassis on two 5 kg wheels (r = 0.4 m)
//! on wheel joints with vertical suspensions (5 Hz, ζ 0.7, travel ±0.25 m);
//! the rear wheel's motor turns at −30 rad/s (12 m/s at the rim) with at
//! most 150 N·m. The road is flat with a bump standing 5 cm proud every
//! 10 m. Prints when the car reached 10 m/s and its top speed, how far a
//! wheel left its axis (the perpendicular row, which the exact tree solve
//! takes), the suspension travel used and the bumps crossed.
//! Run with `cargo run --release --example joint_wheel`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;
const RADIUS: Real = 0.4;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let road = world.create_body(&BodyDef::fixed(Vec2::new(100.0, -0.5)))?;
    world.create_shape(road, &ShapeDef::default(), Polygon::make_box(110.0, 0.5))?;
    let bumps: Vec<Real> = (1..=7).map(|k| 10.0 * k as Real).collect();
    for &x in &bumps {
        let bump = world.create_body(&BodyDef::fixed(Vec2::new(x, -0.25)))?;
        world.create_shape(bump, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.3)?)?;
    }
    let chassis = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.9)))?;
    // 2.5 m × 0.5 m at 40 kg/m² = 50 kg.
    let body = ShapeDef::default().with_density(40.0);
    world.create_shape(chassis, &body, Polygon::make_box(1.25, 0.25))?;
    let tyre = ShapeDef::default().with_density(10.0).with_friction(0.9);
    let mut joints = Vec::new();
    for (x, driven) in [(-1.0, true), (1.0, false)] {
        let hub = Vec2::new(x, RADIUS);
        let wheel = world.create_body(&BodyDef::dynamic(hub))?;
        world.create_shape(wheel, &tyre, Circle::new(Vec2::ZERO, RADIUS)?)?;
        // The suspension axis is frame a's x axis: turned to +y.
        let base = world.joint_base_along(chassis, wheel, hub, 0.5 * janus2d::base::math::PI)?;
        let mut def = WheelJointDef::from_base(base)
            .with_spring(5.0, 0.7)
            .with_limits(-0.25, 0.25);
        if driven {
            def = def.with_motor(-30.0, 150.0);
        }
        joints.push(world.create_joint(&def.into())?);
    }

    let (mut off_axis, mut travel) = (0.0 as Real, (Real::MAX, Real::MIN));
    let (mut at_10, mut top) = (None, 0.0 as Real);
    for step in 1..=480 {
        world.step(DT)?;
        let t = step as Real * DT;
        for &j in &joints {
            let base = world.joint(j)?.def_base().clone();
            let axis = world
                .transform(chassis)?
                .q
                .rotate(base.local_frame_a.axis());
            let (a, b) = world.joint_anchors(j)?;
            off_axis = off_axis.max(axis.perp().dot(b - a).abs());
            let along = axis.dot(b - a);
            travel = (travel.0.min(along), travel.1.max(along));
        }
        let speed = world.linear_velocity(chassis)?.x;
        top = top.max(speed);
        if at_10.is_none() && speed >= 10.0 {
            at_10 = Some(t);
        }
        if step % 120 == 0 {
            println!(
                "t = {t:.0} s: x = {:6.2} m, {speed:5.2} m/s",
                world.position(chassis)?.x
            );
        }
    }
    let x = world.position(chassis)?.x;
    let crossed = bumps.iter().filter(|&&b| b < x - 1.5).count();
    let when = at_10.map_or("never".to_string(), |t| format!("t = {t:.2} s"));
    println!(
        "10 m/s at {when}, top speed {top:.2} m/s; {crossed} bumps crossed; wheels at most {:.3} mm \
         off their axes; suspension travel {:+.3} to {:+.3} m (limits ±0.25 m)",
        1e3 * off_axis,
        travel.0,
        travel.1
    );
    Ok(())
}
