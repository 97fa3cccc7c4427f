//! The mouse joint as the testbed's drag: a pyramid of 55 boxes settles,
//! then the top box is grabbed at its centre (5 Hz, ζ 0.7, at most
//! 1,000 N) and the target is moved 2 m up over 2 s and 2 m sideways over
//! 1 s, then held; the target moves through `World::set_joint_def`. Prints
//! where the box ended against the target (it hangs below it by the
//! spring's sag `g / (2πf)²`), the largest pull against `max_force`, and
//! how far any other box moved.
//! Run with `cargo run --release --example joint_mouse`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;
const ROWS: usize = 10;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    // Unit boxes, row r (from the bottom) holding ROWS − r of them.
    let mut boxes = Vec::new();
    for row in 0..ROWS {
        for k in 0..ROWS - row {
            let x = k as Real - 0.5 * (ROWS - row - 1) as Real;
            let b = world.create_body(&BodyDef::dynamic(Vec2::new(x, 0.5 + row as Real)))?;
            world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
            boxes.push(b);
        }
    }
    for _ in 0..60 {
        world.step(DT)?;
    }
    let top = *boxes.last().expect("a pyramid");
    let others: Vec<(BodyHandle, Vec2)> = boxes[..boxes.len() - 1]
        .iter()
        .map(|&b| world.position(b).map(|p| (b, p)))
        .collect::<Result<_, _>>()?;
    // Grab the box at its centre: the target starts there, so nothing
    // pulls until it moves.
    let grab = world.position(top)?;
    let max_force = 1000.0;
    let mouse = world.create_joint(&MouseJointDef::new(ground, top, grab, max_force).into())?;

    let (mut target, mut pull, mut moved) = (grab, 0.0 as Real, 0.0 as Real);
    for step in 0..240 {
        if step < 120 {
            target.y += DT;
        } else if step < 180 {
            target.x += 2.0 * DT;
        }
        let mut def = world.joint_of::<MouseJoint>(mouse)?.def().clone();
        def.target = target;
        world.set_joint_def(mouse, def.into())?;
        world.step(DT)?;
        pull = pull.max(world.joint_force(mouse)?.length());
        for &(b, p0) in &others {
            moved = moved.max((world.position(b)? - p0).length());
        }
    }
    let at = world.position(top)?;
    let omega = janus2d::base::math::TAU * world.joint_of::<MouseJoint>(mouse)?.def().hertz;
    println!(
        "top box dragged from ({:.2}, {:.2}) to ({:.3}, {:.3}), {:.1} mm below the target (spring \
         sag g/(2πf)² = {:.1} mm), turned {:.1e} rad; largest pull {pull:.0} N (max_force {max_force} N)",
        grab.x,
        grab.y,
        at.x,
        at.y,
        1e3 * (target.y - at.y),
        1e3 * -world.gravity().y / (omega * omega),
        world.angle(top)?
    );
    println!(
        "the other {} boxes moved at most {:.2} mm",
        others.len(),
        1e3 * moved
    );
    Ok(())
}
