//! Shapes and bodies changed after creation: geometry setters and scaling,
//! shape offsets, motion locks, body enable/disable and chains. Each test
//! checks a number against what the change should give.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn world() -> World {
    World::new(WorldDef::default()).unwrap()
}

/// A static ground box whose top face is at y = 0.
fn ground(w: &mut World) -> (BodyHandle, ShapeHandle) {
    let g = w.create_body(&BodyDef::fixed(v(0.0, -0.5))).unwrap();
    let s = w
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))
        .unwrap();
    (g, s)
}

fn ball(w: &mut World, at: Vec2, r: Real) -> (BodyHandle, ShapeHandle) {
    let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, r).unwrap())
        .unwrap();
    (b, s)
}

fn run(w: &mut World, steps: usize) {
    for _ in 0..steps {
        w.step(DT).unwrap();
    }
}

// ----- geometry setters ------------------------------------------------------

#[test]
fn set_circle_grows_a_resting_ball_and_it_rises_by_the_radius_change() {
    let mut w = world();
    ground(&mut w);
    let (b, s) = ball(&mut w, v(0.0, 0.5), 0.5);
    run(&mut w, 60);
    let y0 = w.position(b).unwrap().y;
    assert!((y0 - 0.5).abs() < 0.02, "rests on its radius: {y0}");
    let m0 = w.mass(b).unwrap();
    w.set_circle(s, Circle::new(Vec2::ZERO, 1.0).unwrap())
        .unwrap();
    assert!(!w.is_sleeping(b).unwrap());
    // Mass from density: π r², ×4.
    assert!((w.mass(b).unwrap() / m0 - 4.0).abs() < 1e-4);
    run(&mut w, 60);
    let y1 = w.position(b).unwrap().y;
    assert!(((y1 - y0) - 0.5).abs() < 1e-3, "rose by {}", y1 - y0);
    w.validate().unwrap();
}

#[test]
fn set_polygon_on_the_static_ground_lifts_what_rests_on_it() {
    let mut w = world();
    let (_, gs) = ground(&mut w);
    let (b, _) = ball(&mut w, v(0.0, 0.5), 0.5);
    run(&mut w, 90);
    let y0 = w.position(b).unwrap().y;
    // The ground's top face goes from 0 to 0.25 (the body is at y = −0.5).
    w.set_polygon(gs, Polygon::make_offset_box(20.0, 0.5, v(0.0, 0.25), 0.0))
        .unwrap();
    run(&mut w, 60);
    let y1 = w.position(b).unwrap().y;
    assert!(((y1 - y0) - 0.25).abs() < 1e-3, "rose by {}", y1 - y0);
    w.validate().unwrap();
}

#[test]
fn degenerate_geometry_is_a_typed_error_and_changes_nothing() {
    let mut w = world();
    ground(&mut w);
    let b = w.create_body(&BodyDef::dynamic(v(0.0, 2.0))).unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    run(&mut w, 10);
    let hash = w.state_hash();
    let mass = w.mass(b).unwrap();
    // A flat "polygon": three points on a line.
    let mut flat = Polygon::make_box(0.5, 0.5);
    flat.vertices[2] = flat.vertices[1];
    assert!(matches!(
        w.set_polygon(s, flat),
        Err(WorldError::Geometry(_))
    ));
    assert!(matches!(
        w.set_circle(
            s,
            Circle {
                center: Vec2::ZERO,
                radius: -1.0
            }
        ),
        Err(WorldError::Geometry(_))
    ));
    assert_eq!(w.scale_shape(s, 0.0), Err(WorldError::OutOfRange("factor")));
    assert_eq!(
        w.scale_shape(s, Real::NAN),
        Err(WorldError::NonFinite("factor"))
    );
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.mass(b).unwrap(), mass);
    assert_eq!(
        w.shape(s).unwrap().geometry,
        Shape::Polygon(Polygon::make_box(0.5, 0.5))
    );
    w.validate().unwrap();
}

#[test]
fn a_directly_set_mass_stays_when_the_geometry_changes() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    w.set_mass(b, BodyMass::new(7.0, 2.0)).unwrap();
    w.set_polygon(s, Polygon::make_box(2.0, 2.0)).unwrap();
    assert_eq!(w.mass(b).unwrap(), 7.0);
    assert_eq!(w.rotational_inertia(b).unwrap(), 2.0);
    // Back to the shapes: 16 kg.
    w.reset_mass_from_shapes(b).unwrap();
    assert!((w.mass(b).unwrap() - 16.0).abs() < 1e-3);
}

#[test]
fn changing_the_kind_moves_the_centre_of_mass() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    // A capsule from (1, 0) to (3, 0): centre of mass at x = 2.
    w.set_capsule(s, Capsule::new(v(1.0, 0.0), v(3.0, 0.0), 0.25).unwrap())
        .unwrap();
    assert!((w.center_of_mass(b).unwrap() - v(2.0, 0.0)).length() < 1e-5);
    let area = 2.0 * 0.5 + janus2d::base::math::PI * 0.25 * 0.25;
    assert!((w.mass(b).unwrap() - area).abs() < 1e-4);
    // A segment has no mass: the body gets the unit fallback mass.
    w.set_segment(s, Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap())
        .unwrap();
    assert!((w.mass(b).unwrap() - 1.0).abs() < 1e-6);
    w.validate().unwrap();
}

#[test]
fn scale_shape_scales_mass_by_the_square_and_the_rest_height() {
    let mut w = world();
    ground(&mut w);
    let (b, s) = ball(&mut w, v(0.0, 0.3), 0.3);
    run(&mut w, 60);
    let m0 = w.mass(b).unwrap();
    let y0 = w.position(b).unwrap().y;
    w.scale_shape(s, 2.0).unwrap();
    assert!((w.mass(b).unwrap() / m0 - 4.0).abs() < 1e-4);
    run(&mut w, 60);
    let y1 = w.position(b).unwrap().y;
    assert!(((y1 - y0) - 0.3).abs() < 1e-3, "rose by {}", y1 - y0);
    w.validate().unwrap();
}

#[test]
fn geometry_changes_round_trip_snapshots() {
    let mut w = world();
    ground(&mut w);
    let (b, s) = ball(&mut w, v(0.0, 2.0), 0.5);
    run(&mut w, 5);
    w.set_circle(s, Circle::new(v(0.1, 0.0), 0.7).unwrap())
        .unwrap();
    let snap = w.snapshot();
    run(&mut w, 60);
    let after = w.state_hash();
    w.restore(&snap);
    assert_eq!(
        w.shape(s).unwrap().geometry,
        Shape::Circle(Circle::new(v(0.1, 0.0), 0.7).unwrap())
    );
    run(&mut w, 60);
    assert_eq!(w.state_hash(), after);
    assert!(w.position(b).unwrap().y < 1.0);
}

// ----- shape offsets -----------------------------------------------------

#[test]
fn shape_offsets_move_every_kind_in_the_body_frame() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(v(10.0, 0.0))).unwrap();
    let half_turn = janus2d::base::math::PI / 2.0;
    let def = ShapeDef::default().with_offset(v(0.0, 3.0), half_turn);
    let circle = w
        .create_shape(b, &def, Circle::new(v(1.0, 0.0), 0.5).unwrap())
        .unwrap();
    let capsule = w
        .create_shape(
            b,
            &def,
            Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.2).unwrap(),
        )
        .unwrap();
    let segment = w
        .create_shape(b, &def, Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap())
        .unwrap();
    let polygon = w
        .create_shape(b, &def, Polygon::make_box(2.0, 0.5))
        .unwrap();
    // The circle centre (1, 0) turned a quarter and moved up 3: (0, 4).
    let Shape::Circle(c) = w.shape(circle).unwrap().geometry else {
        panic!("circle")
    };
    assert!((c.center - v(0.0, 4.0)).length() < 1e-5);
    // The capsule and segment stand upright from y = 2 to y = 4.
    let Shape::Capsule(k) = w.shape(capsule).unwrap().geometry else {
        panic!("capsule")
    };
    assert!((k.center1 - v(0.0, 2.0)).length() < 1e-5);
    assert!((k.center2 - v(0.0, 4.0)).length() < 1e-5);
    let seg_box = w.shape(segment).unwrap().aabb;
    assert!((seg_box.lower.y - 2.0).abs() < 1e-5 && (seg_box.upper.y - 4.0).abs() < 1e-5);
    // The 4 × 1 box turned upright: 1 wide, 4 tall, centred on (10, 3).
    let pb = w.shape(polygon).unwrap().aabb;
    assert!(((pb.upper.x - pb.lower.x) - 1.0).abs() < 1e-4);
    assert!(((pb.upper.y - pb.lower.y) - 4.0).abs() < 1e-4);
    assert!(((pb.lower.y + pb.upper.y) / 2.0 - 3.0).abs() < 1e-4);
    // Baked: the stored definitions are back at the identity.
    assert_eq!(w.shape(polygon).unwrap().def.offset, Transform::IDENTITY);
    w.validate().unwrap();
}

#[test]
fn an_offset_circle_swings_the_centre_of_mass() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let def = ShapeDef::default().with_offset(v(1.5, -0.5), 0.3);
    w.create_shape(b, &def, Circle::new(Vec2::ZERO, 0.5).unwrap())
        .unwrap();
    assert!((w.center_of_mass(b).unwrap() - v(1.5, -0.5)).length() < 1e-6);
    // Inertia about the centre of mass: ½ m r², the offset adds nothing.
    let m = w.mass(b).unwrap();
    assert!((w.rotational_inertia(b).unwrap() - 0.5 * m * 0.25).abs() < 1e-5);
}

#[test]
fn a_bad_offset_is_a_typed_error_and_creates_nothing() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let nan = ShapeDef::default().with_offset(v(Real::NAN, 0.0), 0.0);
    assert_eq!(
        w.create_shape(b, &nan, Polygon::make_box(0.5, 0.5)),
        Err(WorldError::NonFinite("offset"))
    );
    let far = ShapeDef::default().with_offset(v(1e9, 0.0), 0.0);
    assert!(matches!(
        w.create_shape(b, &far, Polygon::make_box(0.5, 0.5)),
        Err(WorldError::OutOfBounds {
            field: "offset",
            ..
        })
    ));
    let skew = ShapeDef {
        offset: Transform {
            p: Vec2::ZERO,
            q: Rot { c: 2.0, s: 0.0 },
        },
        ..ShapeDef::default()
    };
    assert_eq!(
        w.create_shape(b, &skew, Polygon::make_box(0.5, 0.5)),
        Err(WorldError::OutOfRange("offset"))
    );
    assert_eq!(w.shape_count(), 0);
}

// ----- motion locks ----------------------------------------------------------

/// A 1 × 1 box at `at` under gravity with `locks`, and a heavy ball coming
/// at it from the left at 12 m/s, level with its centre.
fn box_hit_sideways(locks: MotionLocks) -> (World, BodyHandle, BodyHandle) {
    let mut w = world();
    let b = w
        .create_body(&BodyDef::dynamic(v(0.0, 10.0)).with_motion_locks(locks))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let bullet = w
        .create_body(&BodyDef::dynamic(v(-3.0, 10.0)).with_velocity(v(12.0, 0.0)))
        .unwrap();
    w.create_shape(
        bullet,
        &ShapeDef::default().with_density(5.0),
        Circle::new(Vec2::ZERO, 0.3).unwrap(),
    )
    .unwrap();
    (w, b, bullet)
}

#[test]
fn an_x_locked_box_hit_sideways_falls_straight_down() {
    let (mut w, b, bullet) = box_hit_sideways(MotionLocks::X);
    let x0 = w.position(b).unwrap().x;
    let mut hit = false;
    for _ in 0..60 {
        w.step(DT).unwrap();
        hit |= w.body_contacts(b).unwrap().count() > 0;
        assert!((w.position(b).unwrap().x - x0).abs() < 1e-6);
        assert_eq!(w.linear_velocity(b).unwrap().x, 0.0);
    }
    assert!(hit, "the ball reached the box");
    // Free fall along y all the while: 10 m/s after 1 s.
    assert!((w.linear_velocity(b).unwrap().y + 10.0).abs() < 0.05);
    // The ball bounced back off the box as off a wall.
    assert!(w.linear_velocity(bullet).unwrap().x < 1.0);
    w.validate().unwrap();
}

#[test]
fn without_locks_the_same_hit_pushes_the_box_sideways() {
    let (mut w, b, _) = box_hit_sideways(MotionLocks::NONE);
    run(&mut w, 60);
    assert!(
        w.position(b).unwrap().x > 1.0,
        "{}",
        w.position(b).unwrap().x
    );
}

#[test]
fn a_y_locked_box_slides_on_without_falling() {
    let mut w = world();
    let b = w
        .create_body(
            &BodyDef::dynamic(v(0.0, 3.0))
                .with_velocity(v(2.0, 0.0))
                .with_motion_locks(MotionLocks::Y),
        )
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    // A ball dropped on it does not push it down.
    let (ball_b, _) = ball(&mut w, v(1.0, 5.0), 0.25);
    run(&mut w, 60);
    assert_eq!(w.position(b).unwrap().y, 3.0);
    assert!((w.position(b).unwrap().x - 2.0).abs() < 0.05);
    assert!(w.position(ball_b).unwrap().y > 3.0, "the ball rests on top");
    w.validate().unwrap();
}

#[test]
fn a_rotation_lock_is_fixed_rotation_and_locks_set_later_take_hold() {
    let mut w = world();
    let b = w
        .create_body(&BodyDef::dynamic(v(0.0, 3.0)).with_angular_velocity(2.0))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    w.set_motion_locks(b, MotionLocks::ROTATION).unwrap();
    assert!(w.is_fixed_rotation(b).unwrap());
    assert_eq!(w.angular_velocity(b).unwrap(), 0.0);
    run(&mut w, 30);
    assert_eq!(w.angle(b).unwrap(), 0.0);
    // Lock y too: the fall stops where it is.
    let locks = MotionLocks {
        linear_y: true,
        ..MotionLocks::ROTATION
    };
    w.set_motion_locks(b, locks).unwrap();
    assert_eq!(w.motion_locks(b).unwrap(), locks);
    let y = w.position(b).unwrap().y;
    run(&mut w, 30);
    assert_eq!(w.position(b).unwrap().y, y);
    // Freed: it falls again.
    w.set_motion_locks(b, MotionLocks::NONE).unwrap();
    assert!(!w.is_fixed_rotation(b).unwrap());
    run(&mut w, 30);
    assert!(w.position(b).unwrap().y < y - 1.0);
    // Locks survive a snapshot.
    w.set_motion_locks(b, MotionLocks::X).unwrap();
    let snap = w.snapshot();
    let mut copy = snap.to_world();
    assert_eq!(copy.motion_locks(b).unwrap(), MotionLocks::X);
    copy.step(DT).unwrap();
    w.step(DT).unwrap();
    assert_eq!(copy.state_hash(), w.state_hash());
    w.validate().unwrap();
}

// ----- enable / disable ----------------------------------------------------

#[test]
fn a_disabled_box_does_not_fall_and_resumes_from_its_kept_state() {
    let mut w = world();
    ground(&mut w);
    let b = w
        .create_body(&BodyDef::dynamic(v(0.0, 5.0)).with_velocity(v(1.0, 0.0)))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    run(&mut w, 30);
    let (p, vel) = (w.position(b).unwrap(), w.linear_velocity(b).unwrap());
    assert!((vel.y + 5.0).abs() < 0.01, "half a second of fall: {vel:?}");
    w.set_body_enabled(b, false).unwrap();
    assert!(!w.is_body_enabled(b).unwrap());
    run(&mut w, 60);
    assert_eq!(w.position(b).unwrap(), p);
    assert_eq!(w.linear_velocity(b).unwrap(), vel);
    // Out of the broadphase: a query finds nothing there.
    let probe = janus2d::geometry::Aabb::new(p - v(1.0, 1.0), p + v(1.0, 1.0));
    assert!(w.bodies_in_box(&probe).is_empty());
    w.validate().unwrap();
    // Enabled: one step on from the kept velocity (−5 − g·dt).
    w.set_body_enabled(b, true).unwrap();
    w.step(DT).unwrap();
    let v1 = w.linear_velocity(b).unwrap();
    assert!(
        (v1.x - 1.0).abs() < 1e-5 && (v1.y - (vel.y - 10.0 * DT)).abs() < 1e-4,
        "{v1:?}"
    );
    assert!(w.position(b).unwrap().y < p.y);
    assert_eq!(w.bodies_in_box(&probe), vec![b]);
    w.validate().unwrap();
}

#[test]
fn a_box_resting_on_a_disabled_ground_falls() {
    let mut w = world();
    let (g, _) = ground(&mut w);
    let b = w.create_body(&BodyDef::dynamic(v(0.0, 0.5))).unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    run(&mut w, 120);
    assert!(w.is_sleeping(b).unwrap(), "asleep on the ground");
    let y0 = w.position(b).unwrap().y;
    assert!((y0 - 0.5).abs() < 0.02);
    w.set_body_enabled(g, false).unwrap();
    assert_eq!(w.contact_count(), 0);
    // The contact's end is reported with the next step's events.
    w.step(DT).unwrap();
    assert_eq!(w.events().collision.contact_end.len(), 1);
    // One second of free fall from rest: 5 m.
    run(&mut w, 59);
    let fall = y0 - w.position(b).unwrap().y;
    assert!((fall - 5.0).abs() < 0.1, "fell {fall}");
    // The ground back: it catches nothing above it now, and is hit again
    // by what falls on it.
    w.set_body_enabled(g, true).unwrap();
    let c = w.create_body(&BodyDef::dynamic(v(3.0, 0.6))).unwrap();
    w.create_shape(c, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    run(&mut w, 60);
    assert!((w.position(c).unwrap().y - 0.5).abs() < 0.02);
    w.validate().unwrap();
}

#[test]
fn joints_to_a_disabled_body_stop_acting_until_it_is_enabled() {
    let mut w = world();
    let anchor = w.create_body(&BodyDef::fixed(v(0.0, 10.0))).unwrap();
    let bob = w.create_body(&BodyDef::dynamic(v(0.0, 8.0))).unwrap();
    w.create_shape(
        bob,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.25).unwrap(),
    )
    .unwrap();
    let j = w
        .create_joint(&DistanceJointDef::new(anchor, bob, Vec2::ZERO, Vec2::ZERO, 2.0).into())
        .unwrap();
    run(&mut w, 30);
    assert!((w.position(bob).unwrap().y - 8.0).abs() < 0.01, "hangs");
    w.set_body_enabled(anchor, false).unwrap();
    assert!(!w.joint(j).unwrap().is_enabled());
    run(&mut w, 30);
    // Half a second of free fall: 1.25 m.
    let y = w.position(bob).unwrap().y;
    assert!((8.0 - y - 1.25).abs() < 0.05, "{y}");
    w.set_body_enabled(anchor, true).unwrap();
    assert!(w.joint(j).unwrap().is_enabled());
    run(&mut w, 120);
    // The joint holds it again near 2 m below the anchor (free, it would
    // be 20 m lower by now).
    let d = (w.position(bob).unwrap() - v(0.0, 10.0)).length();
    assert!((d - 2.0).abs() < 0.3, "{d}");
    w.validate().unwrap();
}

#[test]
fn disabled_state_round_trips_snapshots_and_blocks_type_changes() {
    let mut w = world();
    ground(&mut w);
    let (b, _) = ball(&mut w, v(0.0, 3.0), 0.5);
    w.set_body_enabled(b, false).unwrap();
    assert_eq!(
        w.set_body_type(b, BodyType::Kinematic),
        Err(WorldError::DisabledBody)
    );
    let snap = w.snapshot();
    let mut copy = snap.to_world();
    assert!(!copy.is_body_enabled(b).unwrap());
    copy.validate().unwrap();
    copy.set_body_enabled(b, true).unwrap();
    w.set_body_enabled(b, true).unwrap();
    run(&mut w, 30);
    run(&mut copy, 30);
    assert_eq!(w.state_hash(), copy.state_hash());
    assert!(w.position(b).unwrap().y < 3.0);
    // Destroying a disabled body leaves a valid world.
    w.set_body_enabled(b, false).unwrap();
    w.destroy_body(b).unwrap();
    w.validate().unwrap();
}
