//! Guide step 7 (docs/guide.md): joints. A rope bridge of ten planks
//! pinned end to end (revolute joints) between two posts, which the player
//! walks across; a drawbridge hinged at its foot whose motor lowers it
//! against a limit; and a crate hung by a weld that breaks: the weld's
//! force threshold raises a joint event and the game destroys the joint.
//! Every kind is made from a `JointDef` through `World::create_joint`
//! (docs/joints.md). Run with `cargo run --example guide_07_joints`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(30.0, 0.5))?;

    // The bridge: from (0, 3) to (10, 3), ten 1 m planks; each joint pins
    // two neighbours at the point they share (given in world coordinates).
    let posts = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    world.create_shape(
        posts,
        &ShapeDef::default(),
        Polygon::make_offset_box(1.0, 1.5, Vec2::new(-1.0, 1.5), 0.0),
    )?;
    world.create_shape(
        posts,
        &ShapeDef::default(),
        Polygon::make_offset_box(1.0, 1.5, Vec2::new(11.0, 1.5), 0.0),
    )?;
    let mut previous = posts;
    for i in 0..10 {
        let plank = world.create_body(&BodyDef::dynamic(Vec2::new(i as Real + 0.5, 2.95)))?;
        world.create_shape(
            plank,
            &ShapeDef::default().with_density(20.0),
            Polygon::make_box(0.5, 0.05),
        )?;
        let base = world.joint_base_at(previous, plank, Vec2::new(i as Real, 3.0))?;
        world.create_joint(&RevoluteJointDef::from_base(base).into())?;
        previous = plank;
    }
    let last = world.joint_base_at(previous, posts, Vec2::new(10.0, 3.0))?;
    world.create_joint(&RevoluteJointDef::from_base(last).into())?;

    // The drawbridge: a 4 m deck standing up at x = 14, hinged at its foot,
    // its motor turning it down to lie flat (limit: a quarter turn).
    let deck = world.create_body(&BodyDef::dynamic(Vec2::new(14.0, 2.0)))?;
    world.create_shape(deck, &ShapeDef::default(), Polygon::make_box(0.1, 2.0))?;
    let hinge = world.joint_base_at(ground, deck, Vec2::new(14.0, 0.0))?;
    let drawbridge = RevoluteJointDef::from_base(hinge)
        .with_limits(-std::f32::consts::FRAC_PI_2 as Real, 0.0)
        .with_motor(-1.0, 2000.0);
    let drawbridge = world.create_joint(&drawbridge.into())?;

    // A 40 kg crate welded under a beam; the weld reports forces above 600 N.
    let beam = world.create_body(&BodyDef::fixed(Vec2::new(20.0, 6.0)))?;
    world.create_shape(beam, &ShapeDef::default(), Polygon::make_box(1.0, 0.1))?;
    let crate_ = world.create_body(&BodyDef::dynamic(Vec2::new(20.0, 5.4)))?;
    world.create_shape(
        crate_,
        &ShapeDef::default().with_density(40.0),
        Polygon::make_box(0.5, 0.5),
    )?;
    let mut base = world.joint_base_at(beam, crate_, Vec2::new(20.0, 5.9))?;
    base.force_threshold = 600.0;
    let weld = world.create_joint(&WeldJointDef::from_base(base).into())?;

    // The player, who walks right over the bridge.
    let player = world.create_body(&BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(-1.0, 3.8))
    })?;
    let capsule = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default().with_density(30.0), capsule)?;

    let mut lowest: Real = 3.0;
    for step in 1..=240 {
        let t = step as Real * DT;
        let v = world.linear_velocity(player)?;
        world.set_linear_velocity(player, Vec2::new(if t < 3.0 { 4.0 } else { 0.0 }, v.y))?;
        if step >= 120 {
            // From t = 2 s a load hangs on the crate: 1,000 N down.
            world.apply_force_to_center(crate_, Vec2::new(0.0, -1000.0))?;
        }
        world.step(DT)?;
        let p = world.position(player)?;
        if (0.0..10.0).contains(&p.x) {
            lowest = lowest.min(p.y - 0.8);
        }
        // Joint events name the joint; break it.
        let broken: Vec<_> = world
            .events()
            .joints
            .iter()
            .map(|e| (e.joint, e.force.length()))
            .collect();
        for (joint, force) in broken {
            if joint == weld {
                println!("t = {t:.2} s: the weld feels {force:.0} N > 600 N and breaks");
                world.destroy_joint(joint)?;
            }
        }
    }
    println!("the bridge sagged to y = {lowest:.2} under the player (posts at 3.00)");
    println!(
        "the player crossed it and stands at x = {:.2}",
        world.position(player)?.x
    );
    println!(
        "the drawbridge turned to {:.2} rad (limit -1.57)",
        world.joint_angle(drawbridge)?
    );
    println!("the crate is at y = {:.2}", world.position(crate_)?.y);
    Ok(())
}
