//! Bad input gets a typed error at the API boundary and leaves the world
//! exactly as it was (checked through the state hash and counts).

use janus2d::base::body::BodyError;
use janus2d::constraints::JointError;
use janus2d::prelude::*;

fn world_with_two_bodies() -> (World, BodyHandle, BodyHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let a = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)).with_mass(1.0, 0.1))
        .unwrap();
    world
        .create_revolute_joint(&RevoluteJointDef::new(
            a,
            b,
            Vec2::ZERO,
            Vec2::new(-1.0, 0.0),
        ))
        .unwrap();
    world.step(1.0 / 60.0).unwrap();
    (world, a, b)
}

/// Runs `f` and checks the world's state hash and counts did not change.
fn unchanged(world: &mut World, f: impl FnOnce(&mut World)) {
    let (hash, bodies, joints) = (world.state_hash(), world.body_count(), world.joint_count());
    f(world);
    assert_eq!(world.state_hash(), hash);
    assert_eq!(world.body_count(), bodies);
    assert_eq!(world.joint_count(), joints);
}

#[test]
fn non_finite_body_values_are_rejected() {
    let (mut world, _, b) = world_with_two_bodies();
    unchanged(&mut world, |w| {
        let nan = Real::NAN;
        assert_eq!(
            w.create_body(&BodyDef::dynamic(Vec2::new(nan, 0.0))),
            Err(WorldError::Body(BodyError::NonFinite("position")))
        );
        assert_eq!(
            w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_angle(Real::INFINITY)),
            Err(WorldError::Body(BodyError::NonFinite("angle")))
        );
        assert!(w.set_linear_velocity(b, Vec2::new(0.0, nan)).is_err());
        assert!(w.apply_force_to_center(b, Vec2::new(nan, 1.0)).is_err());
        assert!(
            w.apply_linear_impulse(b, Vec2::ONE, Vec2::new(nan, 0.0))
                .is_err()
        );
        assert!(w.set_transform(b, Vec2::ZERO, nan).is_err());
    });
}

#[test]
fn non_positive_mass_or_inertia_is_rejected() {
    let (mut world, _, b) = world_with_two_bodies();
    unchanged(&mut world, |w| {
        assert_eq!(
            w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(0.0, 1.0)),
            Err(WorldError::Body(BodyError::NonPositiveMass))
        );
        assert_eq!(
            w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(-2.0, 1.0)),
            Err(WorldError::Body(BodyError::NonPositiveMass))
        );
        assert_eq!(
            w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 0.0)),
            Err(WorldError::Body(BodyError::NonPositiveInertia))
        );
        assert_eq!(
            w.set_mass(b, BodyMass::new(-1.0, 1.0)),
            Err(WorldError::Body(BodyError::NonPositiveMass))
        );
    });
}

#[test]
fn stale_and_foreign_handles_are_rejected() {
    let (mut world, a, b) = world_with_two_bodies();
    let extra = world.create_body(&BodyDef::dynamic(Vec2::ONE)).unwrap();
    world.destroy_body(extra).unwrap();
    let (mut other, foreign, _) = world_with_two_bodies();
    let foreign_joint = other.joint_handles()[0];
    unchanged(&mut world, |w| {
        assert_eq!(w.position(extra), Err(WorldError::StaleBody));
        assert_eq!(w.destroy_body(extra), Err(WorldError::StaleBody));
        // Another world's handle is its own error, not a stale one.
        assert_eq!(w.position(foreign), Err(WorldError::ForeignHandle));
        assert_eq!(w.destroy_body(foreign), Err(WorldError::ForeignHandle));
        assert_eq!(w.apply_torque(foreign, 1.0), Err(WorldError::ForeignHandle));
        assert_eq!(
            w.create_revolute_joint(&RevoluteJointDef::new(a, extra, Vec2::ZERO, Vec2::ZERO)),
            Err(WorldError::StaleBody)
        );
        assert_eq!(
            w.destroy_joint(foreign_joint),
            Err(WorldError::ForeignHandle)
        );
        assert_eq!(w.apply_torque(extra, 1.0), Err(WorldError::StaleBody));
    });
    // A destroyed joint's handle goes stale too.
    let j = world.joint_handles()[0];
    world.destroy_joint(j).unwrap();
    assert_eq!(world.destroy_joint(j), Err(WorldError::StaleJoint));
    assert!(world.position(b).is_ok());
    other.step(1.0 / 60.0).unwrap();
}

#[test]
fn joint_to_the_same_body_is_rejected() {
    let (mut world, _, b) = world_with_two_bodies();
    unchanged(&mut world, |w| {
        assert_eq!(
            w.create_revolute_joint(&RevoluteJointDef::new(b, b, Vec2::ZERO, Vec2::ZERO)),
            Err(WorldError::Joint(JointError::SameBody))
        );
        let a = w.body_handles().next().unwrap();
        assert_eq!(
            w.create_revolute_joint(
                &RevoluteJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO).with_limits(1.0, -1.0)
            ),
            Err(WorldError::Joint(JointError::InvalidLimits))
        );
    });
}

#[test]
fn bad_time_step_is_rejected() {
    let (mut world, _, _) = world_with_two_bodies();
    let steps = world.step_count();
    unchanged(&mut world, |w| {
        for dt in [0.0, -1.0 / 60.0, Real::NAN, Real::INFINITY] {
            assert_eq!(w.step(dt), Err(WorldError::InvalidTimeStep));
        }
    });
    assert_eq!(world.step_count(), steps);
}

#[test]
fn non_finite_gravity_is_rejected() {
    let def = WorldDef {
        gravity: Vec2::new(0.0, Real::NAN),
        ..Default::default()
    };
    assert!(matches!(
        World::new(def),
        Err(WorldError::NonFinite("gravity"))
    ));
    let (mut world, _, _) = world_with_two_bodies();
    assert!(world.set_gravity(Vec2::new(Real::INFINITY, 0.0)).is_err());
    assert_eq!(world.gravity(), Vec2::new(0.0, -10.0));
}

#[test]
fn body_that_goes_non_finite_is_reported_not_propagated() {
    // A huge force on a light body makes the velocity infinite (a force
    // sum that overflows is refused at the call).
    let (mut world, _, b) = world_with_two_bodies();
    world.set_mass(b, BodyMass::new(0.01, 0.1)).unwrap();
    let start = world.position(b).unwrap();
    world
        .apply_force_to_center(b, Vec2::new(Real::MAX, 0.0))
        .unwrap();
    assert!(matches!(
        world.apply_force_to_center(b, Vec2::new(Real::MAX, 0.0)),
        Err(WorldError::OutOfBounds { field: "force", .. })
    ));
    world.step(1.0 / 60.0).unwrap();
    assert_eq!(world.events().non_finite_bodies, vec![b]);
    let p = world.position(b).unwrap();
    assert!(p.is_finite());
    assert_eq!(p, start);
    assert_eq!(world.linear_velocity(b).unwrap(), Vec2::ZERO);
}
