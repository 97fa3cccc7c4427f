//! The filter joint: two overlapping bodies it joins never collide (they
//! fall through each other and come to rest overlapping), against the
//! same scene without it (pushed apart, stacked); destroying it lets them
//! collide again; with `collide_connected` true it does nothing; it adds
//! no rows and reads back no force.

use janus2d::prelude::*;
use janus2d::world::{WorldDef, WorldError};
use janus2d_constraints::JointError;

const DT: Real = 1.0 / 60.0;

/// A ground, a 1 m box `a` resting on it (centre y = 0.5) and a 1 m box
/// `b` created overlapping `a` by 0.6 m (centre y = 0.9), both dynamic,
/// g = 10 m/s².
fn scene() -> (World, BodyHandle, BodyHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    world
        .create_shape(
            ground,
            &ShapeDef::default(),
            Polygon::make_offset_box(5.0, 0.5, Vec2::new(0.0, -0.5), 0.0),
        )
        .unwrap();
    let make = |world: &mut World, y: Real| {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, y)))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        b
    };
    let a = make(&mut world, 0.5);
    let b = make(&mut world, 0.9);
    (world, a, b)
}

/// Touching contacts between `a` and `b` after the last step.
fn contacts_between(world: &World, a: BodyHandle, b: BodyHandle) -> usize {
    world
        .contacts()
        .filter(|c| {
            c.touching && ((c.body_a, c.body_b) == (a, b) || (c.body_a, c.body_b) == (b, a))
        })
        .count()
}

/// Runs `steps` steps; returns the largest number of touching contacts
/// between `a` and `b` seen after a step.
fn run(world: &mut World, a: BodyHandle, b: BodyHandle, steps: usize) -> usize {
    let mut most = 0;
    for _ in 0..steps {
        world.step(DT).unwrap();
        most = most.max(contacts_between(world, a, b));
    }
    most
}

/// With a filter joint, `b` falls through `a` onto the ground: no contact
/// between them over 2 s, and they end overlapping by the whole box
/// (1 m). Without it, `b` is pushed out and rests on `a` (overlap 0).
#[test]
fn filter_joint_lets_overlapping_bodies_pass_through_each_other() {
    let (mut world, a, b) = scene();
    let joint = world
        .create_joint(&FilterJointDef::new(a, b).into())
        .unwrap();
    let touching = run(&mut world, a, b, 120);
    let overlap = 1.0 - (world.position(b).unwrap().y - world.position(a).unwrap().y).abs();
    let rows = world.joints().row_count();
    println!(
        "filter: {touching} contacts between the pair (0), overlap {overlap:.4} m (1), \
         {rows} joint rows (0)"
    );
    assert_eq!(touching, 0);
    assert!(overlap > 0.99, "overlap {overlap} m");
    assert_eq!(world.joint(joint).unwrap().row_count(), 0);
    assert_eq!(rows, 0);
    assert_eq!(world.joint_force(joint).unwrap(), Vec2::ZERO);
    assert_eq!(world.joint_torque(joint).unwrap(), 0.0);
    assert!(world.events().joints.is_empty());

    // The control: no joint, the pair collides and ends stacked.
    let (mut control, ca, cb) = scene();
    let touching = run(&mut control, ca, cb, 120);
    let gap = control.position(cb).unwrap().y - control.position(ca).unwrap().y;
    println!("control: {touching} contacts, centres {gap:.3} m apart (1)");
    assert!(touching > 0);
    assert!((gap - 1.0).abs() < 0.05, "centres {gap} m apart");
}

/// Destroying the filter joint lets the pair collide again: a contact
/// appears and the solver pushes them apart (centres ≥ 0.95 m apart 2 s
/// later, 1 m boxes).
#[test]
fn destroying_the_filter_joint_restores_collision() {
    let (mut world, a, b) = scene();
    let joint = world
        .create_joint(&FilterJointDef::new(a, b).into())
        .unwrap();
    assert_eq!(run(&mut world, a, b, 10), 0);
    world.destroy_joint(joint).unwrap();
    let touching = run(&mut world, a, b, 120);
    let gap = (world.position(b).unwrap() - world.position(a).unwrap()).length();
    println!("after destroy: {touching} contacts between the pair, centres {gap:.3} m apart");
    assert!(touching > 0);
    assert!(gap > 0.95, "still overlapping: centres {gap} m apart");
}

/// A filter joint with `collide_connected` true is accepted and does
/// nothing: the pair collides as without it.
#[test]
fn filter_joint_with_collide_connected_does_nothing() {
    let (mut world, a, b) = scene();
    let mut def = FilterJointDef::new(a, b);
    def.base.collide_connected = true;
    world.create_joint(&def.into()).unwrap();
    let touching = run(&mut world, a, b, 120);
    let gap = world.position(b).unwrap().y - world.position(a).unwrap().y;
    assert!(touching > 0);
    assert!((gap - 1.0).abs() < 0.05, "centres {gap} m apart");
}

#[test]
fn bad_filter_input_is_a_typed_error_and_changes_nothing() {
    let (mut world, a, b) = scene();
    let counts = |w: &World| (w.body_count(), w.joint_count());
    let before = counts(&world);
    assert_eq!(
        world.create_joint(&FilterJointDef::new(a, a).into()),
        Err(WorldError::Joint(JointError::SameBody))
    );
    let mut nan = FilterJointDef::new(a, b);
    nan.base.local_frame_a.anchor.y = Real::NAN;
    assert_eq!(
        world.create_joint(&nan.into()),
        Err(WorldError::Joint(JointError::NonFinite))
    );
    assert_eq!(counts(&world), before);
    let joint = world
        .create_joint(&FilterJointDef::new(a, b).into())
        .unwrap();
    assert_eq!(world.joint(joint).unwrap().kind(), JointKind::Filter);
    assert!(world.joint_of::<FilterJoint>(joint).is_ok());
    assert_eq!(
        world.set_joint_motor_speed(joint, 1.0),
        Err(WorldError::WrongJointKind)
    );
    // `collide_connected` is fixed for the joint's life.
    let mut flipped = FilterJointDef::new(a, b);
    flipped.base.collide_connected = true;
    assert_eq!(
        world.set_joint_def(joint, flipped.into()),
        Err(WorldError::Joint(JointError::FixedField))
    );
}
