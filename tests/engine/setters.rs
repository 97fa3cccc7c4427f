//! Setters and getters after creation (issue 13, item 6): sleep switches,
//! awake state, bullets, user data, a hand-set mass that stays set, shape
//! materials, density, filter and sensor, shape → body, fallible shape
//! helpers. Bad input is a typed error and changes nothing.

use janus2d::base::geometry::GeometryError;
use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn world() -> World {
    World::new(WorldDef::default()).unwrap()
}

fn ground(world: &mut World) -> (BodyHandle, ShapeHandle) {
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    let s = world
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))
        .unwrap();
    (g, s)
}

fn crate_at(world: &mut World, p: Vec2, def: &ShapeDef) -> (BodyHandle, ShapeHandle) {
    let b = world.create_body(&BodyDef::dynamic(p)).unwrap();
    let s = world
        .create_shape(b, def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    (b, s)
}

#[test]
fn hand_set_mass_survives_new_shapes_until_reset() {
    let mut w = world();
    let (b, _) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    w.set_mass(b, BodyMass::new(7.0, 2.0)).unwrap();
    assert!(w.has_mass_override(b).unwrap());
    w.create_shape(
        b,
        &ShapeDef::default(),
        Circle::new(Vec2::new(2.0, 0.0), 0.5).unwrap(),
    )
    .unwrap();
    assert_eq!(
        w.mass(b).unwrap(),
        7.0,
        "a new shape must not overwrite set_mass"
    );
    w.reset_mass_from_shapes(b).unwrap();
    assert!(!w.has_mass_override(b).unwrap());
    let expected = 1.0 + janus2d::base::math::PI * 0.25; // box 1 m² + disc π/4 m²
    assert!(
        (w.mass(b).unwrap() - expected).abs() < 1e-4,
        "{}",
        w.mass(b).unwrap()
    );
}

#[test]
fn shape_density_setter_updates_mass_and_rejects_bad_values() {
    let mut w = world();
    let (b, s) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    w.set_shape_density(s, 2.5).unwrap();
    assert!((w.mass(b).unwrap() - 2.5).abs() < 1e-5);
    assert_eq!(
        w.set_shape_density(s, -1.0),
        Err(WorldError::OutOfRange("density"))
    );
    assert_eq!(
        w.set_shape_density(s, Real::NAN),
        Err(WorldError::NonFinite("density"))
    );
    assert!(
        (w.mass(b).unwrap() - 2.5).abs() < 1e-5,
        "unchanged after errors"
    );
    assert_eq!(w.shape(s).unwrap().def.density, 2.5);
}

#[test]
fn friction_setter_reaches_existing_contacts_so_a_box_slides() {
    // A box pushed along the ground: with friction 0.6 it stops, with the
    // friction set to 0 on both shapes it keeps nearly all its speed.
    let run = |frictionless: bool| {
        let mut w = world();
        let (_, gs) = ground(&mut w);
        let (b, s) = crate_at(&mut w, Vec2::new(0.0, 0.5), &ShapeDef::default());
        for _ in 0..30 {
            w.step(DT).unwrap();
        }
        if frictionless {
            w.set_shape_friction(s, 0.0).unwrap();
            w.set_shape_friction(gs, 0.0).unwrap();
        }
        w.set_linear_velocity(b, Vec2::new(3.0, 0.0)).unwrap();
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        w.linear_velocity(b).unwrap().x
    };
    assert!(run(false) < 0.1);
    assert!(run(true) > 2.9);
    let mut w = world();
    let (_, s) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    assert_eq!(
        w.set_shape_friction(s, -0.1),
        Err(WorldError::OutOfRange("friction"))
    );
    assert_eq!(w.shape(s).unwrap().def.friction, 0.6);
    assert_eq!(
        w.set_shape_restitution(s, Real::INFINITY),
        Err(WorldError::NonFinite("restitution"))
    );
}

#[test]
fn restitution_setter_makes_a_resting_ball_bounce() {
    let mut w = world();
    let (_, gs) = ground(&mut w);
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0)))
        .unwrap();
    let s = w
        .create_shape(
            b,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.25).unwrap(),
        )
        .unwrap();
    // The contact exists (speculative) before the ball lands.
    for _ in 0..40 {
        w.step(DT).unwrap();
    }
    w.set_shape_restitution(s, 0.9).unwrap();
    w.set_shape_restitution(gs, 0.9).unwrap();
    let mut max_up: Real = 0.0;
    for _ in 0..120 {
        w.step(DT).unwrap();
        max_up = max_up.max(w.linear_velocity(b).unwrap().y);
    }
    assert!(max_up > 3.0, "bounced up at {max_up} m/s");
}

#[test]
fn filter_setter_lets_a_box_fall_through_the_ground() {
    let mut w = world();
    ground(&mut w);
    let (b, s) = crate_at(&mut w, Vec2::new(0.0, 0.5), &ShapeDef::default());
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    assert!(w.position(b).unwrap().y > 0.45);
    w.set_shape_filter(
        s,
        Filter {
            mask_bits: 0,
            ..Filter::default()
        },
    )
    .unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!(w.position(b).unwrap().y < -1.0, "filtered out: it falls");
    assert_eq!(w.shape(s).unwrap().def.filter.mask_bits, 0);
}

#[test]
fn sensor_setter_lets_a_box_fall_into_a_ground_made_sensor() {
    let mut w = world();
    let (_, gs) = ground(&mut w);
    let (b, _) = crate_at(&mut w, Vec2::new(0.0, 0.5), &ShapeDef::default());
    w.set_shape_sensor(gs, true).unwrap();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    let y = w.position(b).unwrap().y;
    assert!(y < 0.0, "fell into the sensor: {y}");
    assert!(w.shape(gs).unwrap().def.is_sensor);
}

#[test]
fn set_awake_sleeps_and_wakes_and_enable_sleep_keeps_awake() {
    let mut w = world();
    ground(&mut w);
    let (b, _) = crate_at(&mut w, Vec2::new(0.0, 3.0), &ShapeDef::default());
    w.set_awake(b, false).unwrap();
    assert!(!w.is_awake(b).unwrap());
    w.step(DT).unwrap();
    assert_eq!(w.position(b).unwrap().y, 3.0, "asleep in mid-air");
    w.set_awake(b, true).unwrap();
    w.step(DT).unwrap();
    assert!(w.position(b).unwrap().y < 3.0);
    // Resting with sleep disabled: awake after 3 s; enabled: asleep.
    w.set_body_enable_sleep(b, false).unwrap();
    assert!(!w.body_enable_sleep(b).unwrap());
    for _ in 0..180 {
        w.step(DT).unwrap();
    }
    assert!(w.is_awake(b).unwrap());
    w.set_body_enable_sleep(b, true).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!(!w.is_awake(b).unwrap());
    let (g, _) = ground(&mut w);
    assert!(!w.is_awake(g).unwrap(), "static bodies are never awake");
}

#[test]
fn sleep_threshold_per_body() {
    // A box sliding at 0.5 m/s on frictionless ice: above the world's
    // threshold (0.05 m/s) it stays awake; with its own threshold of 1 m/s
    // it falls asleep within a second.
    let run = |threshold: Option<Real>| {
        let mut w = World::new(WorldDef {
            gravity: Vec2::ZERO,
            ..WorldDef::default()
        })
        .unwrap();
        let b = w
            .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(0.5, 0.0)))
            .unwrap();
        w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        w.set_body_sleep_threshold(b, threshold).unwrap();
        assert_eq!(w.body_sleep_threshold(b).unwrap(), threshold);
        for _ in 0..60 {
            w.step(DT).unwrap();
        }
        w.is_awake(b).unwrap()
    };
    assert!(run(None));
    assert!(!run(Some(1.0)));
    let mut w = world();
    let (b, _) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    assert_eq!(
        w.set_body_sleep_threshold(b, Some(-1.0)),
        Err(WorldError::OutOfRange("sleep_threshold"))
    );
    assert_eq!(w.body_sleep_threshold(b).unwrap(), None);
}

#[test]
fn user_data_and_shape_body_round_trip() {
    let mut w = world();
    let (g, gs) = ground(&mut w);
    let (b, s) = crate_at(&mut w, Vec2::new(0.0, 2.0), &ShapeDef::default());
    w.set_body_user_data(b, 42).unwrap();
    w.set_shape_user_data(s, 7).unwrap();
    assert_eq!(w.body_user_data(b).unwrap(), 42);
    assert_eq!(w.shape_user_data(s).unwrap(), 7);
    assert_eq!(w.shape_body(s).unwrap(), b);
    assert_eq!(w.shape_body(gs).unwrap(), g);
    assert_eq!(w.body_shapes(b).unwrap(), vec![s]);
    let j = w
        .create_revolute_joint(&RevoluteJointDef::new(
            g,
            b,
            Vec2::new(0.0, 2.0),
            Vec2::ZERO,
        ))
        .unwrap();
    assert_eq!(w.joint_user_data(j).unwrap(), 0);
    w.set_joint_user_data(j, 99).unwrap();
    assert_eq!(w.joint_user_data(j).unwrap(), 99);
    w.destroy_joint(j).unwrap();
    assert_eq!(w.joint_user_data(j), Err(WorldError::StaleJoint));
    w.destroy_body(b).unwrap();
    assert_eq!(w.body_user_data(b), Err(WorldError::StaleBody));
    assert_eq!(w.set_shape_user_data(s, 1), Err(WorldError::StaleShape));
    assert_eq!(w.shape_body(s), Err(WorldError::StaleShape));
}

#[test]
fn bullet_flag_round_trips() {
    let mut w = world();
    let (b, _) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    assert!(!w.is_bullet(b).unwrap());
    w.set_bullet(b, true).unwrap();
    assert!(w.is_bullet(b).unwrap());
}

#[test]
fn fallible_shape_helpers_return_errors_instead_of_panicking() {
    assert_eq!(
        Polygon::try_make_box(0.0, 1.0),
        Err(GeometryError::DegeneratePolygon)
    );
    assert_eq!(
        Polygon::try_make_box(Real::NAN, 1.0),
        Err(GeometryError::NonFinite)
    );
    assert_eq!(
        Polygon::try_make_rounded_box(1.0, 1.0, -0.1),
        Err(GeometryError::NegativeRadius)
    );
    assert_eq!(
        Polygon::try_make_offset_box(1.0, 1.0, Vec2::new(Real::INFINITY, 0.0), 0.0),
        Err(GeometryError::NonFinite)
    );
    assert_eq!(
        Polygon::try_make_capsule(Vec2::ZERO, Vec2::ZERO, 0.5),
        Err(GeometryError::DegenerateSegment)
    );
    assert_eq!(
        Polygon::try_make_capsule(Vec2::ZERO, Vec2::X, 0.0),
        Err(GeometryError::NonPositiveRadius)
    );
    let b = Polygon::try_make_offset_box(0.5, 0.25, Vec2::new(1.0, 0.0), 0.3).unwrap();
    assert_eq!(
        b,
        Polygon::make_offset_box(0.5, 0.25, Vec2::new(1.0, 0.0), 0.3)
    );
    assert!((Shape::Polygon(Polygon::try_make_box(0.5, 0.25).unwrap()).area() - 0.5).abs() < 1e-6);
}

#[test]
fn set_body_type_static_to_dynamic_falls_and_moves_its_proxies() {
    let mut w = world();
    ground(&mut w);
    let b = w.create_body(&BodyDef::fixed(Vec2::new(0.0, 3.0))).unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let static_count = |w: &World| {
        w.body_handles()
            .filter(|h| w.body_type(*h) == Ok(BodyType::Static))
            .count()
    };
    let statics = static_count(&w);
    w.set_body_type(b, BodyType::Dynamic).unwrap();
    assert_eq!(w.body_type(b).unwrap(), BodyType::Dynamic);
    assert_eq!(static_count(&w), statics - 1);
    assert!(w.is_awake(b).unwrap());
    assert!((w.mass(b).unwrap() - 1.0).abs() < 1e-6);
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let y = w.position(b).unwrap().y;
    assert!((y - 0.5).abs() < 0.02, "landed on the ground: {y}");
    // A ray still finds it (its new proxy is in the movable tree).
    let hit = w
        .cast_ray_closest(
            Vec2::new(-5.0, 0.5),
            Vec2::new(10.0, 0.0),
            &QueryFilter::default(),
        )
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, b);
}

#[test]
fn set_body_type_dynamic_to_static_holds_a_box_in_the_air() {
    let mut w = world();
    let (shelf, _) = crate_at(&mut w, Vec2::new(0.0, 3.0), &ShapeDef::default());
    let (rider, _) = crate_at(&mut w, Vec2::new(0.0, 4.0), &ShapeDef::default());
    w.step(DT).unwrap();
    w.set_body_type(shelf, BodyType::Static).unwrap();
    assert_eq!(w.mass(shelf).unwrap(), 0.0);
    assert_eq!(w.linear_velocity(shelf).unwrap(), Vec2::ZERO);
    let y0 = w.position(shelf).unwrap().y;
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    assert_eq!(
        w.position(shelf).unwrap().y,
        y0,
        "a static body does not move"
    );
    let gap = w.position(rider).unwrap().y - y0;
    assert!((gap - 1.0).abs() < 0.02, "the rider rests on it: {gap}");
    assert!(w.contact_count() >= 1);
}

#[test]
fn set_body_type_kinematic_ignores_gravity_and_keeps_its_velocity() {
    let mut w = world();
    let (b, _) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    w.set_linear_velocity(b, Vec2::new(1.0, 0.0)).unwrap();
    w.set_body_type(b, BodyType::Kinematic).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    let p = w.position(b).unwrap();
    assert!((p.x - 1.0).abs() < 1e-3 && p.y.abs() < 1e-6, "{p}");
    assert_eq!(w.mass(b).unwrap(), 0.0);
}

#[test]
fn set_body_type_makes_a_jointed_anchor_swing() {
    // A pendulum hung from a static anchor body; the anchor made dynamic
    // falls with the bob (the joint links their islands).
    let mut w = world();
    let anchor = w
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 10.0)))
        .unwrap();
    w.create_shape(anchor, &ShapeDef::default(), Polygon::make_box(0.1, 0.1))
        .unwrap();
    let (bob, _) = crate_at(&mut w, Vec2::new(1.0, 10.0), &ShapeDef::default());
    w.create_revolute_joint(&RevoluteJointDef::new(
        anchor,
        bob,
        Vec2::ZERO,
        Vec2::new(-1.0, 0.0),
    ))
    .unwrap();
    for _ in 0..10 {
        w.step(DT).unwrap();
    }
    assert_eq!(w.position(anchor).unwrap().y, 10.0, "pinned while static");
    w.set_body_type(anchor, BodyType::Dynamic).unwrap();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    assert!(w.position(anchor).unwrap().y < 9.0, "the anchor falls");
    assert!(w.max_joint_gap() < 0.05, "{}", w.max_joint_gap());
}

#[test]
fn set_body_type_rejects_stale_handles_and_same_type_is_a_no_op() {
    let mut w = world();
    let (b, _) = crate_at(&mut w, Vec2::ZERO, &ShapeDef::default());
    w.set_body_type(b, BodyType::Dynamic).unwrap();
    w.destroy_body(b).unwrap();
    assert_eq!(
        w.set_body_type(b, BodyType::Static),
        Err(WorldError::StaleBody)
    );
}

#[cfg(feature = "portals")]
#[test]
fn set_body_type_of_a_portal_body_is_refused() {
    use janus2d::world::{PortalDef, PortalPairDef};
    let mut w = world();
    let (a, _) = ground(&mut w);
    let b = w
        .create_body(&BodyDef::fixed(Vec2::new(30.0, 0.0)))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))
        .unwrap();
    let portal = |body, anchor, direction| PortalDef {
        body,
        anchor,
        direction,
        half_width: 1.0,
    };
    w.create_portal_pair(&PortalPairDef::new(
        portal(a, Vec2::new(0.0, 0.5), Vec2::Y),
        portal(b, Vec2::new(0.5, 0.0), Vec2::X),
    ))
    .unwrap();
    assert_eq!(
        w.set_body_type(a, BodyType::Dynamic),
        Err(WorldError::PortalBody)
    );
    assert_eq!(w.body_type(a).unwrap(), BodyType::Static, "unchanged");
}
