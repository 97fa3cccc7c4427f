//! The API every joint kind shares: the definition base (frames,
//! per-joint softness, thresholds, user data), typed reads, whole-definition
//! and limit/motor/spring setters with typed errors that leave the world
//! unchanged, and the validator's check of joint definitions.

use janus2d::SleepSettings;
use janus2d::prelude::*;
use janus2d_constraints::JointError;

/// A 1 kg box hanging 1 m below a static pin, 4 substeps, sleep off.
pub(crate) fn pendulum(
    def_edit: impl FnOnce(&mut RevoluteJointDef),
) -> (World, BodyHandle, JointHandle) {
    let mut world = World::new(WorldDef {
        sleep: SleepSettings {
            enabled: false,
            ..SleepSettings::default()
        },
        ..WorldDef::default()
    })
    .unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let bob = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, -1.0)).with_mass(1.0, 0.1))
        .unwrap();
    let mut def = RevoluteJointDef::new(ground, bob, Vec2::ZERO, Vec2::new(0.0, 1.0));
    def_edit(&mut def);
    let j = world.create_joint(&def.into()).unwrap();
    (world, bob, j)
}

/// State hash, body and joint counts and the joint's definition: a
/// refused call must leave all of them as they were.
fn refused(
    world: &mut World,
    j: JointHandle,
    f: impl FnOnce(&mut World) -> Result<(), WorldError>,
) -> WorldError {
    let before = (
        world.state_hash(),
        world.body_count(),
        world.joint_count(),
        world.joint(j).unwrap().def(),
    );
    let e = f(world).expect_err("the call must be refused");
    let after = (
        world.state_hash(),
        world.body_count(),
        world.joint_count(),
        world.joint(j).unwrap().def(),
    );
    assert_eq!(before, after, "a refused call changed the world");
    e
}

#[test]
fn world_anchor_frames_put_both_anchors_on_the_point() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let a = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.0, 2.0)).with_angle(0.7))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(-3.0, 0.5)).with_angle(-1.9))
        .unwrap();
    let point = Vec2::new(0.25, 1.5);
    let base = world.joint_base_at(a, b, point).unwrap();
    let j = world
        .create_joint(&RevoluteJointDef::from_base(base).into())
        .unwrap();
    let (pa, pb) = world.joint_anchors(j).unwrap();
    assert!(
        (pa - point).length() < 1e-5 && (pb - point).length() < 1e-5,
        "{pa:?} {pb:?}"
    );
    // The frames hold the bodies' current relative angle: joint angle 0.
    let angle = world.joint_angle(j).unwrap();
    assert!(angle.abs() < 1e-5, "joint angle {angle}");
    let stale = BodyHandle::new(77, 0, 0);
    assert!(world.joint_base_at(a, stale, point).is_err());
    assert!(
        world
            .joint_base_at(a, b, Vec2::new(Real::NAN, 0.0))
            .is_err()
    );
}

#[test]
fn a_softer_joint_constraint_stretches_more() {
    // The same pendulum with the world's joint softness and with its own
    // 2 Hz: the soft one hangs lower by at least 1 cm after 1 s.
    let gap = |edit: fn(&mut RevoluteJointDef)| {
        let (mut world, _, j) = pendulum(edit);
        for _ in 0..60 {
            world.step(1.0 / 60.0).unwrap();
        }
        world.joint_gap(j).unwrap()
    };
    let stiff = gap(|_| {});
    let soft = gap(|d| {
        d.base.constraint_hertz = 2.0;
        d.base.constraint_damping_ratio = 1.0;
    });
    assert!(stiff < 1e-3, "default joint gap {stiff}");
    assert!(soft > stiff + 0.01, "soft {soft} vs default {stiff}");
}

#[test]
fn user_data_from_the_definition_is_kept() {
    let (mut world, _, j) = pendulum(|d| d.base.user_data = 42);
    assert_eq!(world.joint_user_data(j), Ok(42));
    // One value: the setter changes the definition the joint reports.
    world.set_joint_user_data(j, 7).unwrap();
    assert_eq!(world.joint_user_data(j), Ok(7));
    assert_eq!(world.joint(j).unwrap().def_base().user_data, 7);
}

#[test]
fn whole_definition_setter_validates_and_keeps_the_world_on_error() {
    let (mut world, bob, j) = pendulum(|_| {});
    let def = world.revolute_joint(j).unwrap().def().clone();
    // Another kind.
    let weld = WeldJointDef::new(def.base.body_a, def.base.body_b, Vec2::ZERO, Vec2::ZERO);
    let e = refused(&mut world, j, |w| w.set_joint_def(j, weld.into()));
    assert_eq!(e, WorldError::WrongJointKind);
    // Other bodies.
    let mut moved = def.clone();
    moved.base.body_a = bob;
    let e = refused(&mut world, j, |w| w.set_joint_def(j, moved.into()));
    assert_eq!(e, WorldError::Joint(JointError::SameBody));
    let other = world.create_body(&BodyDef::fixed(Vec2::ONE)).unwrap();
    let mut moved = def.clone();
    moved.base.body_a = other;
    let e = refused(&mut world, j, |w| w.set_joint_def(j, moved.into()));
    assert_eq!(e, WorldError::Joint(JointError::FixedField));
    // Bad values.
    let mut nan = def.clone();
    nan.base.force_threshold = Real::NAN;
    let e = refused(&mut world, j, |w| w.set_joint_def(j, nan.into()));
    assert_eq!(e, WorldError::Joint(JointError::NonFinite));
    let mut negative = def.clone();
    negative.base.torque_threshold = -1.0;
    let e = refused(&mut world, j, |w| w.set_joint_def(j, negative.into()));
    assert_eq!(e, WorldError::Joint(JointError::Negative));
    // A good change lands.
    let good = def.with_limits(-0.25, 0.5);
    world.set_joint_def(j, good.into()).unwrap();
    let now = &world.revolute_joint(j).unwrap().def();
    assert!(now.enable_limit);
    assert_eq!((now.lower_angle, now.upper_angle), (-0.25, 0.5));
    assert_eq!(world.validate(), Ok(()));
}

#[test]
fn kind_setters_refuse_kinds_without_the_feature() {
    let (mut world, _, pin) = pendulum(|_| {});
    let (a, b) = world.joints().bodies_of(pin).unwrap();
    let weld = world
        .create_joint(&WeldJointDef::new(a, b, Vec2::ZERO, Vec2::new(0.0, 1.0)).into())
        .unwrap();
    for e in [
        refused(&mut world, weld, |w| w.set_joint_limits(weld, -1.0, 1.0)),
        refused(&mut world, weld, |w| w.set_joint_motor_speed(weld, 1.0)),
        refused(&mut world, weld, |w| w.set_joint_spring(weld, 1.0, 0.5)),
        refused(&mut world, weld, |w| w.enable_joint_motor(weld, true)),
        // A revolute motor is angular: a force is the wrong unit.
        refused(&mut world, pin, |w| w.set_joint_max_motor_force(pin, 10.0)),
    ] {
        assert_eq!(e, WorldError::WrongJointKind);
    }
    assert_eq!(
        refused(&mut world, pin, |w| w.set_joint_limits(pin, 1.0, -1.0)),
        WorldError::OutOfRange("limits")
    );
    assert!(world.joint_of::<WeldJoint>(pin).is_err());
    assert!(world.joint_of::<RevoluteJoint>(pin).is_ok());
    world.set_joint_max_motor_torque(pin, 5.0).unwrap();
    assert_eq!(
        world.revolute_joint(pin).unwrap().def().max_motor_torque,
        5.0
    );
}

#[test]
fn reference_angle_is_the_difference_of_the_frames() {
    let (mut world, _, j) = pendulum(|d| {
        d.base.local_frame_a.angle = 0.5;
        d.base.local_frame_b.angle = 0.2;
    });
    world.step(1.0 / 60.0).unwrap();
    // θ_b − θ_a = 0 at rest, so the joint angle is −(φ_a − φ_b) = −0.3.
    let angle = world.joint_angle(j).unwrap();
    assert!((angle + 0.3).abs() < 1e-3, "joint angle {angle}");
}

/// Every kind's definition has a `Default` (placeholder bodies, refused as
/// one body) that validates once its bodies are set: struct-update syntax
/// works as for Box2D's `b2Default…JointDef`.
#[test]
fn every_default_definition_validates_once_its_bodies_are_set() {
    use janus2d::{
        DistanceJointDef, FilterJointDef, MotorJointDef, MouseJointDef, PrismaticJointDef,
        WheelJointDef,
    };
    let mut world = World::new(WorldDef::default()).unwrap();
    let a = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::X)).unwrap();
    let defaults: Vec<JointDef> = vec![
        RevoluteJointDef::default().into(),
        PrismaticJointDef::default().into(),
        WeldJointDef::default().into(),
        DistanceJointDef::default().into(),
        WheelJointDef::default().into(),
        MotorJointDef::default().into(),
        MouseJointDef::default().into(),
        FilterJointDef::default().into(),
    ];
    assert_eq!(defaults.len(), janus2d::JointKind::ALL.len());
    for mut def in defaults {
        assert_eq!(
            def.validate(),
            Err(JointError::SameBody),
            "{:?}",
            def.kind()
        );
        def.base_mut().body_a = a;
        def.base_mut().body_b = b;
        assert_eq!(def.validate(), Ok(()), "{:?}", def.kind());
        world.create_joint(&def).unwrap();
    }
    world.step(1.0 / 60.0).unwrap();
    assert_eq!(world.validate(), Ok(()));
}
