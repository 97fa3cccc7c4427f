//! The collision API: mass from shapes, filters, sensors, contact events,
//! `collide_connected`, and bad shape input (typed error, world unchanged).
//! (The one-way platform through the pre-solve hook: `contact_modification`.)

use janus2d::base::geometry::GeometryError;
use janus2d::prelude::*;
use janus2d_testbed::scenes::{self, DT};

fn world() -> World {
    World::new(scenes::shared_settings()).unwrap()
}

fn ground(world: &mut World) -> BodyHandle {
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    world
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(20.0, 1.0))
        .unwrap();
    g
}

fn boxed(world: &mut World, pos: Vec2, def: &ShapeDef) -> BodyHandle {
    let b = world.create_body(&BodyDef::dynamic(pos)).unwrap();
    world
        .create_shape(b, def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    b
}

#[test]
fn mass_center_and_inertia_come_from_several_shapes() {
    let mut w = world();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    // Two unit squares side by side, density 2: a 2×1 box of mass 4.
    let sd = ShapeDef::default().with_density(2.0);
    w.create_shape(
        b,
        &sd,
        Polygon::make_offset_box(0.5, 0.5, Vec2::new(-0.5, 0.0), 0.0),
    )
    .unwrap();
    w.create_shape(
        b,
        &sd,
        Polygon::make_offset_box(0.5, 0.5, Vec2::new(1.5, 0.0), 0.0),
    )
    .unwrap();
    let m = w.mass(b).unwrap();
    let c = w.center_of_mass(b).unwrap();
    // Squares at x = −0.5 and 1.5: centre at 0.5; I = Σ (m/12)(1+1) + m d².
    let inertia = 2.0 * (2.0 * 2.0 / 12.0 + 2.0 * 1.0);
    assert!((m - 4.0).abs() < 1e-5, "mass {m}");
    assert!((c - Vec2::new(0.5, 0.0)).length() < 1e-5, "centre {c}");
    assert!((w.rotational_inertia(b).unwrap() - inertia).abs() < 1e-4);
}

#[test]
fn filter_masks_out_a_pair() {
    let mut w = world();
    ground(&mut w);
    let ghost = ShapeDef {
        filter: Filter {
            category_bits: 2,
            mask_bits: !1,
            group_index: 0,
        },
        ..ShapeDef::default()
    };
    let b = boxed(&mut w, Vec2::new(0.0, 2.0), &ghost);
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    // It falls through the ground (category 1, which it masks out).
    assert!(w.position(b).unwrap().y < -3.0);
}

#[test]
fn negative_group_never_collides() {
    let mut w = world();
    ground(&mut w);
    let group = ShapeDef {
        filter: Filter {
            group_index: -3,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    let a = boxed(&mut w, Vec2::new(0.0, 0.5), &group);
    let b = boxed(&mut w, Vec2::new(0.0, 0.9), &group); // overlapping a
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    // b sank onto the ground through a: both rest at y ≈ 0.5.
    assert!((w.position(a).unwrap().y - 0.5).abs() < 0.02);
    assert!((w.position(b).unwrap().y - 0.5).abs() < 0.02);
}

#[test]
fn sensor_reports_overlap_and_never_pushes() {
    let mut w = world();
    let trigger = w.create_body(&BodyDef::fixed(Vec2::new(0.0, 2.0))).unwrap();
    let sensor = ShapeDef {
        is_sensor: true,
        ..ShapeDef::default()
    };
    w.create_shape(trigger, &sensor, Polygon::make_box(2.0, 0.5))
        .unwrap();
    let ball = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 5.0)))
        .unwrap();
    w.create_shape(
        ball,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.25).unwrap(),
    )
    .unwrap();
    let (mut begins, mut ends) = (0, 0);
    let mut v_min: Real = 0.0;
    for _ in 0..120 {
        w.step(DT).unwrap();
        begins += w.events().collision.sensor_begin.len();
        ends += w.events().collision.sensor_end.len();
        assert!(w.events().collision.contact_begin.is_empty());
        v_min = v_min.min(w.linear_velocity(ball).unwrap().y);
    }
    assert_eq!((begins, ends), (1, 1));
    // Free fall for 2 s: the sensor never slowed it.
    assert!((v_min + 20.0).abs() < 0.05, "{v_min}");
}

#[test]
fn contact_begin_and_end_events() {
    let mut w = world();
    ground(&mut w);
    let b = boxed(&mut w, Vec2::new(0.0, 2.0), &ShapeDef::default());
    let mut begin = 0;
    for _ in 0..90 {
        w.step(DT).unwrap();
        begin += w.events().collision.contact_begin.len();
    }
    assert_eq!(begin, 1);
    w.apply_linear_impulse(b, Vec2::new(0.0, 10.0), w.center_of_mass(b).unwrap())
        .unwrap();
    let mut end = 0;
    for _ in 0..10 {
        w.step(DT).unwrap();
        end += w.events().collision.contact_end.len();
    }
    assert_eq!(end, 1);
}

#[test]
fn collide_connected_false_suppresses_contacts() {
    for collide in [false, true] {
        let mut w = world();
        ground(&mut w);
        let a = boxed(&mut w, Vec2::new(0.0, 0.5), &ShapeDef::default());
        let b = boxed(&mut w, Vec2::new(0.0, 1.2), &ShapeDef::default()); // overlaps a
        let mut def = RevoluteJointDef::new(a, b, Vec2::new(0.0, 0.35), Vec2::new(0.0, -0.35));
        def.base.collide_connected = collide;
        w.create_revolute_joint(&def).unwrap();
        w.step(DT).unwrap();
        let touching = w.contacts().any(|c| {
            c.touching && ((c.body_a == a && c.body_b == b) || (c.body_a == b && c.body_b == a))
        });
        assert_eq!(touching, collide, "collide_connected = {collide}");
    }
}

#[test]
fn bad_shapes_are_rejected_and_the_world_is_unchanged() {
    let mut w = world();
    ground(&mut w);
    let b = boxed(&mut w, Vec2::new(0.0, 2.0), &ShapeDef::default());
    w.step(DT).unwrap();
    let (hash, shapes, mass) = (w.state_hash(), w.shape_count(), w.mass(b).unwrap());
    let sd = ShapeDef::default();
    // Degenerate polygons.
    let p = |pts: &[Vec2]| Polygon::from_hull(pts, 0.0);
    assert!(matches!(
        p(&[Vec2::ZERO, Vec2::X]),
        Err(GeometryError::TooFewPoints { .. })
    ));
    assert_eq!(
        p(&[Vec2::ZERO, Vec2::X, 2.0 * Vec2::X]),
        Err(GeometryError::CollinearPoints)
    );
    assert_eq!(
        p(&[Vec2::ZERO, Vec2::new(Real::NAN, 0.0), Vec2::Y]),
        Err(GeometryError::NonFinite)
    );
    // A hand-made polygon with no area, through the world API.
    let mut flat = Polygon::make_box(1.0, 1.0);
    for v in &mut flat.vertices[..flat.count] {
        v.y = 0.0;
    }
    assert!(matches!(
        w.create_shape(b, &sd, flat),
        Err(WorldError::Geometry(_))
    ));
    let mut nan = Polygon::make_box(1.0, 1.0);
    nan.vertices[0].x = Real::NAN;
    assert_eq!(
        w.create_shape(b, &sd, nan),
        Err(WorldError::Geometry(GeometryError::NonFinite))
    );
    // Radii.
    assert_eq!(
        Circle::new(Vec2::ZERO, 0.0),
        Err(GeometryError::NonPositiveRadius)
    );
    let bad_circle = Circle {
        center: Vec2::ZERO,
        radius: -1.0,
    };
    assert_eq!(
        w.create_shape(b, &sd, bad_circle),
        Err(WorldError::Geometry(GeometryError::NonPositiveRadius))
    );
    // Non-positive density on a dynamic body with no mass set and no other mass.
    let empty = w
        .create_body(&BodyDef::dynamic(Vec2::new(5.0, 5.0)))
        .unwrap();
    let hash_with_empty = w.state_hash();
    assert_eq!(
        w.create_shape(
            empty,
            &ShapeDef::default().with_density(0.0),
            Polygon::make_box(0.5, 0.5)
        ),
        Err(WorldError::OutOfRange("density"))
    );
    assert_eq!(
        w.create_shape(
            b,
            &ShapeDef::default().with_density(Real::NAN),
            Polygon::make_box(0.5, 0.5)
        ),
        Err(WorldError::NonFinite("density"))
    );
    assert_eq!(w.state_hash(), hash_with_empty);
    w.destroy_body(empty).unwrap();
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.shape_count(), shapes);
    assert_eq!(w.mass(b).unwrap(), mass);
}

/// A ball dropped from 1.8 m (its bottom) hits the ground at
/// √(2 g h) ≈ 5.9 m/s: one hit event of about that speed, with the normal
/// along y; resting afterwards gives none; without the flag, none at all.
#[test]
fn hit_events_report_the_approach_speed_of_a_hard_landing_only() {
    for flag in [true, false] {
        let mut world = World::new(WorldDef::default()).unwrap();
        let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        world
            .create_shape(g, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))
            .unwrap();
        let ball = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.55)))
            .unwrap();
        let def = ShapeDef {
            enable_hit_events: flag,
            ..ShapeDef::default()
        };
        world
            .create_shape(ball, &def, Circle::new(Vec2::ZERO, 0.25).unwrap())
            .unwrap();
        let mut hits = Vec::new();
        for _ in 0..180 {
            world.step(1.0 / 60.0).unwrap();
            hits.extend(world.events().collision.hits.iter().copied());
        }
        if !flag {
            assert!(hits.is_empty(), "no flag, no hits: {hits:?}");
            continue;
        }
        assert_eq!(hits.len(), 1, "one landing: {hits:?}");
        let expected = (2.0 * 9.81 * 1.8 as Real).sqrt();
        let h = hits[0];
        assert!(
            (h.approach_speed - expected).abs() < 0.3,
            "approach {} vs {expected}",
            h.approach_speed
        );
        assert!(h.normal.y.abs() > 0.99 && h.point.y.abs() < 0.6);
    }
}
