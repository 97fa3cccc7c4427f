//! Joint events (`JointDefBase::force_threshold`, `torque_threshold`,
//! `world.events().joints`): a joint reports one event when its force or
//! torque passes its threshold, none while it stays below, and one again
//! only after falling back under it (one per crossing).
//!
//! g = 10 m/s², 60 Hz, 4 substeps, sleep off (a resting joint keeps its
//! last force, so the figures are the same with sleep on; off keeps the
//! runs independent of the sleep timer).

use janus2d::prelude::*;
use janus2d::world::WorldDef;
use janus2d_core::body::BodyMass;

const DT: Real = 1.0 / 60.0;

fn world() -> World {
    let mut def = WorldDef::default();
    def.sleep.enabled = false;
    World::new(def).unwrap()
}

/// A joint event as reported, with the step it came after.
#[derive(Debug)]
struct Seen {
    step: usize,
    joint: JointHandle,
    user_data: u64,
    force: Vec2,
    torque: Real,
}

/// Steps `steps` times; returns every joint event reported.
fn events(world: &mut World, steps: usize) -> Vec<Seen> {
    let mut out = Vec::new();
    for step in 0..steps {
        world.step(DT).unwrap();
        out.extend(world.events().joints.iter().map(|e| Seen {
            step,
            joint: e.joint,
            user_data: e.user_data,
            force: e.force,
            torque: e.torque,
        }));
    }
    out
}

/// A load hung at its centre of mass from a static hook by a revolute
/// joint with a 400 N force threshold: while it weighs 20 N (2 kg), 2 s
/// without an event; when it becomes a 1,287 N load (128.7 kg), exactly
/// one event over the next 2 s, carrying the joint's handle, its user
/// value and the force (1,287 N up on the load, within 0.5%). Lightened
/// back to 20 N it re-arms without an event, and the next 1,287 N load
/// reports one more.
#[test]
fn force_threshold_reports_one_event_per_crossing() {
    let mut world = world();
    let hook = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 5.0)))
        .unwrap();
    let load = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0)).with_mass(2.0, 0.5))
        .unwrap();
    let mut def = RevoluteJointDef::new(hook, load, Vec2::new(0.0, -1.0), Vec2::ZERO);
    def.base.force_threshold = 400.0;
    def.base.user_data = 7;
    let joint = world.create_revolute_joint(&def).unwrap();

    let light = events(&mut world, 120);
    let light_force = world.joint_force(joint).unwrap();
    assert!(light.is_empty(), "events under a 20 N load: {light:?}");
    assert!((light_force.y - 20.0).abs() < 0.1, "{light_force:?}");

    world.set_mass(load, BodyMass::new(128.7, 32.0)).unwrap();
    let heavy = events(&mut world, 120);
    println!(
        "20 N load: {} events (force {:.2} N); 1,287 N load: {} event(s) {:?}",
        light.len(),
        light_force.y,
        heavy.len(),
        heavy.iter().map(|e| (e.step, e.force)).collect::<Vec<_>>()
    );
    assert_eq!(heavy.len(), 1, "{heavy:?}");
    let e = &heavy[0];
    assert_eq!(e.step, 0, "reported after the first heavy step");
    assert_eq!(e.joint, joint);
    assert_eq!(e.user_data, 7);
    assert!(e.force.length() > 400.0);
    assert!((e.force.y - 1287.0).abs() < 0.005 * 1287.0, "{:?}", e.force);

    // One per crossing: back under the threshold re-arms it silently.
    world.set_mass(load, BodyMass::new(2.0, 0.5)).unwrap();
    assert!(events(&mut world, 60).is_empty());
    world.set_mass(load, BodyMass::new(128.7, 32.0)).unwrap();
    let again = events(&mut world, 60);
    assert_eq!(again.len(), 1, "{again:?}");
    assert_eq!(again[0].joint, joint);
}

/// A 1 m shelf of 20 kg welded to a wall at its end, with a 400 N·m
/// torque threshold (force threshold ∞): its own 200 N weight (100 N·m)
/// gives no event over 2 s; a 1,287 N box set down on it 0.8 m from the
/// wall (1,130 N·m with the shelf's once it rests) reports exactly one
/// event over 2 s, with a torque above 400 N·m, and the shelf holds it.
///
/// Dropped from 1 cm instead, the box sinks 2.4 mm into the shelf and the
/// contact's recovery lifts it for a step: the torque falls to 202 N·m
/// and crosses again, two events (one per crossing, as specified).
const SHELF_MASS: Real = 20.0;
const DROP: Real = 0.0;

#[test]
fn torque_threshold_reports_one_event_when_a_load_lands() {
    let mut world = world();
    let wall = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let shelf = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.5, 0.0)))
        .unwrap();
    world
        .create_shape(shelf, &ShapeDef::default(), Polygon::make_box(0.5, 0.05))
        .unwrap();
    world
        .set_mass(
            shelf,
            BodyMass::new(SHELF_MASS, SHELF_MASS * (1.0 + 0.01) / 12.0),
        )
        .unwrap();
    let mut def = WeldJointDef::new(wall, shelf, Vec2::ZERO, Vec2::new(-0.5, 0.0));
    def.base.torque_threshold = 400.0;
    let joint = world.create_weld_joint(&def).unwrap();

    let light = events(&mut world, 120);
    let light_torque = world.joint_torque(joint).unwrap();
    assert!(
        light.is_empty(),
        "events under the shelf's weight: {light:?}"
    );
    let own = SHELF_MASS * 10.0 * 0.5;
    assert!(
        (light_torque - own).abs() < 0.01 * own,
        "torque {light_torque}"
    );

    let load = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.8, 0.05 + 0.1 + DROP)))
        .unwrap();
    world
        .create_shape(load, &ShapeDef::default(), Polygon::make_box(0.1, 0.1))
        .unwrap();
    world
        .set_mass(load, BodyMass::new(128.7, 128.7 * 0.08 / 12.0))
        .unwrap();
    let heavy = events(&mut world, 120);
    let resting_torque = world.joint_torque(joint).unwrap();
    println!(
        "shelf: {} events under its own weight ({light_torque:.2} N·m); 1,287 N box: {} event(s) {:?}, \
         resting torque {resting_torque:.0} N·m",
        light.len(),
        heavy.len(),
        heavy.iter().map(|e| (e.step, e.torque)).collect::<Vec<_>>()
    );
    assert_eq!(heavy.len(), 1, "{heavy:?}");
    let e = &heavy[0];
    assert_eq!(e.joint, joint);
    assert!(e.torque.abs() > 400.0, "{}", e.torque);
    // 1,287 N × 0.8 m + 10 N·m, the box resting on the shelf.
    let resting = 1287.0 * 0.8 + own;
    assert!(
        (resting_torque - resting).abs() < 0.02 * resting,
        "{resting_torque}"
    );
    assert!((world.position(load).unwrap().x - 0.8).abs() < 0.01);
}
