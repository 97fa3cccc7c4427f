//! The prismatic joint as an elevator: a 10 kg platform on a vertical slide
//! (limits 0 to 3 m) carries a 100 kg box set 0.3 m off centre; the motor
//! drives it up at 1 m/s with at most 5,000 N until the upper limit stops
//! it. Prints when it got there, how far it overshot, how far the platform
//! left its axis and turned (the rows the exact tree solve takes), and the
//! motor's force against the weight it lifts.
//! Run with `cargo run --release --example joint_prismatic`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;
const UPPER: Real = 3.0;

/// The platform's distance from the axis line and its translation along
/// it, m, from the two bodies' poses.
fn axis_errors(world: &World, joint: JointHandle) -> Result<(Real, Real), WorldError> {
    let base = world.joint(joint)?.def_base().clone();
    let xf_a = world.transform(base.body_a)?;
    let (anchor_a, anchor_b) = world.joint_anchors(joint)?;
    let axis = xf_a.q.rotate(base.local_frame_a.axis());
    let d = anchor_b - anchor_a;
    Ok((axis.perp().dot(d), axis.dot(d)))
}

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let start = Vec2::new(0.0, 1.0);
    let platform = world.create_body(&BodyDef::dynamic(start))?;
    // 2 m × 0.2 m at 25 kg/m² = 10 kg; a 1 m box at 100 kg/m² = 100 kg.
    let deck = ShapeDef::default().with_density(25.0);
    world.create_shape(platform, &deck, Polygon::make_box(1.0, 0.1))?;
    let load = world.create_body(&BodyDef::dynamic(Vec2::new(0.3, 1.6)))?;
    let crate_ = ShapeDef::default().with_density(100.0);
    world.create_shape(load, &crate_, Polygon::make_box(0.5, 0.5))?;
    // A vertical slide through the platform's centre (the frames' x axes
    // along +y), limits and motor by the builders.
    let base = world.joint_base_along(ground, platform, start, 0.5 * janus2d::base::math::PI)?;
    let def = PrismaticJointDef::from_base(base)
        .with_limits(0.0, UPPER)
        .with_motor(1.0, 5000.0);
    let lift = world.create_joint(&def.into())?;

    let (mut off_axis, mut overshoot, mut turn) = (0.0 as Real, 0.0 as Real, 0.0 as Real);
    let (mut reached, mut rising_force) = (None, 0.0);
    for step in 1..=300 {
        world.step(DT)?;
        let t = step as Real * DT;
        let (perp, translation) = axis_errors(&world, lift)?;
        off_axis = off_axis.max(perp.abs());
        overshoot = overshoot.max(translation - UPPER);
        turn = turn.max(world.angle(platform)?.abs());
        if reached.is_none() && translation >= UPPER - 1e-3 {
            reached = Some(t);
        }
        if step == 90 {
            rising_force = world.joint_of::<PrismaticJoint>(lift)?.motor_force();
            println!(
                "t = {t:.1} s: rising at {:.3} m/s, motor force {rising_force:.0} N",
                world.linear_velocity(platform)?.y
            );
        }
    }
    let weight = (world.mass(platform)? + world.mass(load)?) * -world.gravity().y;
    let (_, end) = axis_errors(&world, lift)?;
    println!(
        "platform reached the {UPPER} m limit at t = {:.2} s, overshoot {:.2} mm, off-axis {:.4} mm, \
         turned {:.2e} rad; rests at {end:.4} m",
        reached.unwrap_or(Real::NAN),
        1e3 * overshoot.max(0.0),
        1e3 * off_axis,
        turn
    );
    println!(
        "the motor lifted {rising_force:.0} N while rising (platform + load weigh {weight:.0} N); \
         at the limit the joint holds {:.0} N",
        world.joint_force(lift)?.y
    );
    Ok(())
}
