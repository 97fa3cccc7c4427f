//! Portal edge cases and the portal API: the accepted range of η, crossings
//! that always end, the pair's current map and which side a body is on.

use janus2d::constraints::PortalError;
use janus2d::prelude::*;
use janus2d::world::{CrossingRole, MassModel, PlaneSide, PortalEvent, PortalPairDef, PortalSide};
use janus2d_testbed::scenes::{self, DT};
use janus2d_testbed::support::{portal_def as portal, wall};

/// Steps the portal drop until its box is crossing; returns the clone.
fn until_crossing(world: &mut World, body: BodyHandle) -> BodyHandle {
    for _ in 0..200 {
        world.step(DT).unwrap();
        if let Some(clone) = world.clone_of(body) {
            return clone;
        }
    }
    panic!("never started crossing");
}

/// η outside [ETA_MIN, ETA_MAX] (given, or from the widths) is refused with
/// a typed error and nothing is created; the ends of the range are accepted.
#[test]
fn eta_outside_its_range_is_a_typed_error_at_creation() {
    use janus2d::constraints::portal_map::{ETA_MAX, ETA_MIN};
    let mut world = World::new(WorldDef::default()).unwrap();
    let a = wall(&mut world, Vec2::ZERO, 1.0, 1.0);
    let b = wall(&mut world, Vec2::new(10.0, 0.0), 1.0, 1.0);
    let pa = portal(a, Vec2::new(0.0, 1.0), Vec2::Y, 0.5);
    let pb = portal(b, Vec2::new(0.0, 1.0), Vec2::Y, 0.5);
    for eta in [1e30, 1e3, 100.5, 1e-3, 0.009] {
        let r = world.create_portal_pair(&PortalPairDef::new(pa, pb).with_eta(eta));
        assert_eq!(
            r,
            Err(WorldError::Portal(PortalError::ScaleOutOfRange)),
            "η {eta}"
        );
    }
    for eta in [0.0, -1.0, Real::NAN, Real::INFINITY] {
        let r = world.create_portal_pair(&PortalPairDef::new(pa, pb).with_eta(eta));
        assert_eq!(r, Err(WorldError::Portal(PortalError::InvalidScale)));
    }
    // η from the widths: 0.5 mm against 0.5 m is η = 1e3.
    let tiny = portal(b, Vec2::new(0.0, 1.0), Vec2::Y, 5e-4);
    assert_eq!(
        world.create_portal_pair(&PortalPairDef::new(pa, tiny)),
        Err(WorldError::Portal(PortalError::ScaleOutOfRange))
    );
    assert_eq!(world.portal_pair_count(), 0);
    for eta in [ETA_MIN, ETA_MAX, 1.0] {
        let pair = world
            .create_portal_pair(&PortalPairDef::new(pa, pb).with_eta(eta))
            .unwrap();
        assert!((world.portal_map(pair).unwrap().eta - eta).abs() <= 1e-6 * eta);
        world.destroy_portal_pair(pair).unwrap();
    }
}

/// A crossing whose original loses its shape mid-crossing ends (the clone
/// goes), and one whose original only changed its shapes starts again.
#[test]
fn crossing_ends_when_the_original_shape_is_destroyed_mid_crossing() {
    for add_another in [false, true] {
        let (mut scene, _) = scenes::portal_drop(&WorldDef::default());
        let (world, body) = (&mut scene.world, scene.probe);
        let clone = until_crossing(world, body);
        let shape = world.body_shapes(body).unwrap()[0];
        world.destroy_shape(shape).unwrap();
        if add_another {
            world
                .create_shape(
                    body,
                    &ShapeDef::default(),
                    Circle::new(Vec2::ZERO, 0.4).unwrap(),
                )
                .unwrap();
        }
        world.step(DT).unwrap();
        assert!(
            world.position(clone).is_err(),
            "the old clone is left (add {add_another}): {:?}",
            world.events().portals
        );
        if add_another {
            // It crosses again with its new shape; the new clone is a circle.
            let clone = world.clone_of(body).expect("crossing restarted");
            let shapes = world.body_shapes(clone).unwrap();
            assert_eq!(shapes.len(), 1);
            assert!(matches!(
                world.shape(shapes[0]).unwrap().geometry,
                Shape::Circle(_)
            ));
        } else {
            assert_eq!(world.crossing_count(), 0);
        }
        for _ in 0..120 {
            world.step(DT).unwrap();
        }
        assert_eq!(world.crossing_count(), 0, "a crossing hangs");
        assert!(world.position(body).unwrap().is_finite());
    }
}

/// A joint between a crossing body and its own clone would hold the two
/// copies of one object together across the map: it is disabled and
/// reported, and the crossing ends.
#[test]
fn crossing_ends_when_original_and_clone_are_jointed() {
    let (mut scene, _) = scenes::portal_drop(&WorldDef::default());
    let (world, body) = (&mut scene.world, scene.probe);
    let clone = until_crossing(world, body);
    let joint = world
        .create_revolute_joint(&RevoluteJointDef::new(body, clone, Vec2::ZERO, Vec2::ZERO))
        .unwrap();
    let mut disabled = false;
    let mut ended_at = None;
    for step in 0..240 {
        world.step(DT).unwrap();
        disabled |= world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::JointDisabled { joint: j, .. } if *j == joint));
        if world.crossing_count() == 0 {
            ended_at = Some(step);
            break;
        }
    }
    assert!(ended_at.is_some(), "the jointed crossing never ended");
    assert!(disabled, "no joint-disabled event");
    assert!(world.position(body).unwrap().is_finite());
}

/// `portal_map` gives the pair's map now: T takes portal a's centre to
/// portal b's, Q takes n_a to −n_b, η as built; it follows a turning
/// kinematic portal body.
#[test]
fn portal_map_follows_the_portal_bodies() {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    };
    let mut world = World::new(def).unwrap();
    let a = wall(&mut world, Vec2::ZERO, 2.0, 0.5);
    let b = world
        .create_body(&BodyDef {
            body_type: BodyType::Kinematic,
            position: Vec2::new(10.0, 0.0),
            angular_velocity: 1.0,
            ..Default::default()
        })
        .unwrap();
    let pair = world
        .create_portal_pair(
            &PortalPairDef::new(
                portal(a, Vec2::new(0.0, 0.5), Vec2::Y, 1.0),
                portal(b, Vec2::new(1.0, 0.0), Vec2::X, 1.0),
            )
            .with_eta(2.0)
            .with_mass_model(MassModel::EnergyPreserving),
        )
        .unwrap();
    let (_, def) = world.portal_pairs().next().unwrap();
    assert_eq!(def.mass_model, MassModel::EnergyPreserving);
    for step in 0..30 {
        let theta = world.angle(b).unwrap();
        let map = world.portal_map(pair).unwrap();
        let p_b = Vec2::new(10.0, 0.0) + Rot::from_angle(theta).rotate(Vec2::X);
        let n_b = Rot::from_angle(theta).rotate(Vec2::X);
        assert!(
            (map.map_point(Vec2::new(0.0, 0.5)) - p_b).length() < 1e-4,
            "step {step}"
        );
        assert!((map.rotation().rotate(Vec2::Y) + n_b).length() < 1e-5);
        assert_eq!(map.eta, 2.0);
        // A point 1 m in front of portal a maps 2 m behind portal b.
        let y = map.map_point(Vec2::new(0.3, 1.5));
        assert!(((y - p_b).dot(n_b) + 2.0).abs() < 1e-4);
        world.step(DT).unwrap();
    }
    assert!(
        world.angle(b).unwrap() > 0.4,
        "the portal body did not turn"
    );
    // Stale handles are refused.
    world.destroy_portal_pair(pair).unwrap();
    assert_eq!(world.portal_map(pair).err(), Some(WorldError::StalePortal));
}

/// `portal_side` tells where a body is against each portal of a pair and
/// its part in a crossing, through the whole portal drop.
#[test]
fn portal_side_follows_a_crossing() {
    let (mut scene, pair) = scenes::portal_drop(&WorldDef::default());
    let (world, body) = (&mut scene.world, scene.probe);
    let side = world.portal_side(body, pair).unwrap();
    assert_eq!(
        side,
        PortalSide {
            a: PlaneSide::Front,
            b: PlaneSide::Front,
            within: [true, true],
            crossing: CrossingRole::None,
        }
    );
    let clone = until_crossing(world, body);
    let s = world.portal_side(body, pair).unwrap();
    assert_eq!(s.a, PlaneSide::Straddling);
    assert!(s.within[0]);
    assert_eq!(s.crossing, CrossingRole::Original { entry: 0 });
    let s = world.portal_side(clone, pair).unwrap();
    assert_eq!(s.b, PlaneSide::Straddling);
    assert_eq!(s.crossing, CrossingRole::Clone { entry: 0 });
    for _ in 0..120 {
        world.step(DT).unwrap();
        if world.crossing_count() == 0 {
            break;
        }
    }
    // Through: in front of the exit wall's portal, no longer crossing.
    let s = world.portal_side(body, pair).unwrap();
    assert_eq!(s.b, PlaneSide::Front);
    assert_eq!(s.crossing, CrossingRole::None);
    assert!(
        world.portal_side(clone, pair).is_err(),
        "stale clone accepted"
    );
}
