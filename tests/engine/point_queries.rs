//! The second week's queries: project point, per-shape ray cast and point
//! test, a sensor's overlaps, and the query filter's predicate; with their
//! typed errors and through portals.

use std::cell::Cell;
use std::collections::BTreeSet;

use janus2d::base::geometry::Aabb;
use janus2d::prelude::*;
use janus2d::world::query::QueryProblem;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn world() -> World {
    World::new(WorldDef::default()).unwrap()
}

fn fixed(world: &mut World, at: Vec2, angle: Real, shape: impl Into<Shape>) -> ShapeHandle {
    let b = world
        .create_body(&BodyDef::fixed(at).with_angle(angle))
        .unwrap();
    world.create_shape(b, &ShapeDef::default(), shape).unwrap()
}

fn close(a: Vec2, b: Vec2) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn project_point_on_a_box_gives_the_face_corner_and_inside_points() {
    let mut w = world();
    let s = fixed(&mut w, v(3.0, 0.0), 0.0, Polygon::make_box(1.0, 1.0));
    let f = QueryFilter::default();
    // In front of the left face (x = 2).
    let p = w.project_point(v(0.0, 0.5), 10.0, &f).unwrap().unwrap();
    assert_eq!(p.shape, s);
    assert!(close(p.point, v(2.0, 0.5)), "{p:?}");
    assert!(close(p.normal, v(-1.0, 0.0)));
    assert!((p.distance - 2.0).abs() < 1e-5 && !p.inside);
    // Off a corner: the corner (4, 1), √5 away.
    let p = w.project_point(v(5.0, 3.0), 10.0, &f).unwrap().unwrap();
    assert!(close(p.point, v(4.0, 1.0)));
    assert!((p.distance - (5.0 as Real).sqrt()).abs() < 1e-5);
    // Inside, nearest the right face (0.8 away; top 0.9, left 1.2).
    let p = w.project_point(v(3.2, 0.1), 10.0, &f).unwrap().unwrap();
    assert!(p.inside);
    assert!(close(p.point, v(4.0, 0.1)), "{p:?}");
    assert!((p.distance - 0.8).abs() < 1e-5);
    assert!(close(p.normal, v(1.0, 0.0)));
    // Beyond max_distance: nothing; just within it: the face.
    assert_eq!(w.project_point(v(0.0, 0.5), 1.99, &f).unwrap(), None);
    assert!(w.project_point(v(0.0, 0.5), 2.01, &f).unwrap().is_some());
    assert!(
        w.project_point(v(-1e3, 0.0), Real::INFINITY, &f)
            .unwrap()
            .is_some()
    );
    // The same on the shape alone.
    let q = w.shape_project_point(s, v(3.2, 0.1)).unwrap();
    assert!(q.inside && close(q.point, v(4.0, 0.1)));
}

#[test]
fn project_point_on_turned_rounded_and_curved_shapes() {
    let mut w = world();
    let quarter = janus2d::base::math::PI / 4.0;
    // A unit-half-width box turned 45°: its corner points along +x at x = 10 + √2.
    let turned = fixed(&mut w, v(10.0, 0.0), quarter, Polygon::make_box(1.0, 1.0));
    let p = w.shape_project_point(turned, v(13.0, 0.0)).unwrap();
    let corner = 10.0 + (2.0 as Real).sqrt();
    assert!(close(p.point, v(corner, 0.0)), "{p:?}");
    assert!((p.distance - (13.0 - corner)).abs() < 1e-5);
    // A rounded box: core half-width 1, radius 0.25: the face at x = 21.25.
    let rounded = fixed(
        &mut w,
        v(20.0, 0.0),
        0.0,
        Polygon::make_rounded_box(1.0, 1.0, 0.25),
    );
    let p = w.shape_project_point(rounded, v(23.0, 0.5)).unwrap();
    assert!(close(p.point, v(21.25, 0.5)) && (p.distance - 1.75).abs() < 1e-5);
    // Inside the rounding, outside the core: 0.1 under the surface.
    let p = w.shape_project_point(rounded, v(21.15, 0.0)).unwrap();
    assert!(p.inside && (p.distance - 0.1).abs() < 1e-5 && close(p.point, v(21.25, 0.0)));
    // A disc of radius 2 at (0, 10): from (0, 13), the top at (0, 12).
    let disc = fixed(
        &mut w,
        v(0.0, 10.0),
        0.0,
        Circle::new(Vec2::ZERO, 2.0).unwrap(),
    );
    let p = w.shape_project_point(disc, v(0.0, 13.0)).unwrap();
    assert!(close(p.point, v(0.0, 12.0)) && (p.distance - 1.0).abs() < 1e-5);
    // A capsule from (−1, 0) to (1, 0), radius 0.5, at (0, 20): from (3, 20).
    let cap = fixed(
        &mut w,
        v(0.0, 20.0),
        0.0,
        Capsule::new(v(-1.0, 0.0), v(1.0, 0.0), 0.5).unwrap(),
    );
    let p = w.shape_project_point(cap, v(3.0, 20.0)).unwrap();
    assert!(close(p.point, v(1.5, 20.0)) && (p.distance - 1.5).abs() < 1e-5);
    // A segment never holds a point: from above its middle, straight down.
    let seg = fixed(
        &mut w,
        v(0.0, 30.0),
        0.0,
        Segment::new(v(-1.0, 0.0), v(1.0, 0.0)).unwrap(),
    );
    let p = w.shape_project_point(seg, v(0.5, 30.7)).unwrap();
    assert!(!p.inside && close(p.point, v(0.5, 30.0)) && (p.distance - 0.7).abs() < 1e-5);
    assert!(close(p.normal, v(0.0, 1.0)));
}

#[test]
fn project_point_prefers_the_shape_holding_the_point_and_obeys_the_filter() {
    let mut w = world();
    // A big box holding (0, 0) 2 m deep; a small box 0.5 m off to the right.
    let big = fixed(&mut w, v(0.0, 0.0), 0.0, Polygon::make_box(2.0, 2.0));
    let small = fixed(&mut w, v(3.0, 0.0), 0.0, Polygon::make_box(0.5, 0.5));
    let f = QueryFilter::default();
    let p = w.project_point(v(1.9, 0.0), 5.0, &f).unwrap().unwrap();
    assert_eq!(p.shape, big, "inside beats a nearer outside surface");
    assert!(p.inside && (p.distance - 0.1).abs() < 1e-5);
    // Without the big box (predicate): the small box's face at x = 2.5.
    let not_big = |s: ShapeHandle| s != big;
    let p = w
        .project_point(v(1.9, 0.0), 5.0, &f.with_predicate(&not_big))
        .unwrap()
        .unwrap();
    assert_eq!(p.shape, small);
    assert!((p.distance - 0.6).abs() < 1e-5 && close(p.point, v(2.5, 0.0)));
    // Sensors are not seen.
    let zone = w.create_body(&BodyDef::fixed(v(10.0, 0.0))).unwrap();
    w.create_shape(
        zone,
        &ShapeDef::default().sensor(),
        Polygon::make_box(1.0, 1.0),
    )
    .unwrap();
    let p = w.project_point(v(10.0, 0.0), 5.0, &f).unwrap();
    assert!(p.is_none_or(|p| p.body != zone));
}

#[test]
fn shape_ray_cast_sees_only_its_shape_and_shape_test_point_is_exact() {
    let mut w = world();
    let near = fixed(&mut w, v(2.0, 0.0), 0.0, Polygon::make_box(0.5, 0.5));
    let far = fixed(&mut w, v(5.0, 0.0), 0.0, Polygon::make_box(0.5, 0.5));
    let f = QueryFilter::default();
    let hit = w
        .shape_ray_cast(far, Vec2::ZERO, v(10.0, 0.0), &f)
        .unwrap()
        .unwrap();
    assert_eq!(hit.shape, far);
    assert!(close(hit.point, v(4.5, 0.0)) && (hit.fraction - 0.45).abs() < 1e-6);
    assert!(close(hit.normal, v(-1.0, 0.0)));
    let hit = w
        .shape_ray_cast(near, Vec2::ZERO, v(10.0, 0.0), &f)
        .unwrap()
        .unwrap();
    assert!((hit.fraction - 0.15).abs() < 1e-6);
    // A miss, a ray too short, and a filter that rejects the shape.
    assert_eq!(
        w.shape_ray_cast(far, v(0.0, 2.0), v(10.0, 0.0), &f)
            .unwrap(),
        None
    );
    assert_eq!(
        w.shape_ray_cast(far, Vec2::ZERO, v(4.0, 0.0), &f).unwrap(),
        None
    );
    assert_eq!(
        w.shape_ray_cast(far, Vec2::ZERO, v(10.0, 0.0), &f.with_mask(0b10))
            .unwrap(),
        None
    );
    // Point tests: inside, on the face, outside by 1 mm.
    assert!(w.shape_test_point(far, v(5.2, -0.3)).unwrap());
    assert!(w.shape_test_point(far, v(5.5, 0.0)).unwrap());
    assert!(!w.shape_test_point(far, v(5.501, 0.0)).unwrap());
    assert!(!w.shape_test_point(near, v(5.2, -0.3)).unwrap());
}

#[test]
fn the_predicate_filters_every_query_kind_and_sees_each_candidate() {
    let mut w = world();
    let shapes: Vec<ShapeHandle> = (1..=4)
        .map(|k| {
            fixed(
                &mut w,
                v(2.0 * k as Real, 0.0),
                0.0,
                Polygon::make_box(0.5, 0.5),
            )
        })
        .collect();
    let asked = Cell::new(0);
    let odd_only = |s: ShapeHandle| {
        asked.set(asked.get() + 1);
        s == shapes[1] || s == shapes[3]
    };
    let f = QueryFilter::default().with_predicate(&odd_only);
    // Rays: the first box seen is the second (face x = 3.5).
    let hit = w
        .cast_ray_closest(Vec2::ZERO, v(20.0, 0.0), &f)
        .unwrap()
        .unwrap();
    assert_eq!(hit.shape, shapes[1]);
    assert!((hit.fraction - 3.5 / 20.0).abs() < 1e-6);
    assert!(asked.get() >= 2);
    // Shape casts: a disc of radius 0.5 stops with its centre at x = 3.
    let disc = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
    let hit = w
        .cast_shape_closest(&disc, &Transform::IDENTITY, v(20.0, 0.0), &f)
        .unwrap()
        .unwrap();
    assert_eq!(hit.shape, shapes[1]);
    assert!((hit.fraction - 3.0 / 20.0).abs() < 1e-3);
    // Overlaps: a box over all four gives the two odd ones.
    let mut found = Vec::new();
    w.overlap_aabb(&Aabb::new(v(0.0, -1.0), v(10.0, 1.0)), &f, |o| {
        found.push(o.shape);
        true
    })
    .unwrap();
    assert_eq!(found, vec![shapes[1], shapes[3]]);
    let mut found = Vec::new();
    w.overlap_shape(&disc, &Transform::new(v(2.0, 0.0), 0.0), &f, |o| {
        found.push(o.shape);
        true
    })
    .unwrap();
    assert!(found.is_empty(), "the first box is rejected");
    let mut found = Vec::new();
    w.overlap_point(v(8.0, 0.0), &f, |o| {
        found.push(o.shape);
        true
    })
    .unwrap();
    assert_eq!(found, vec![shapes[3]]);
    // The predicate is asked only after the category test passes.
    asked.set(0);
    let masked = f.with_mask(0b10);
    assert_eq!(
        w.cast_ray_closest(Vec2::ZERO, v(20.0, 0.0), &masked)
            .unwrap(),
        None
    );
    assert_eq!(asked.get(), 0);
    // Filters compare their predicates by address.
    assert_eq!(f, f);
    assert_ne!(f, QueryFilter::default());
}

#[test]
fn sensor_overlaps_equal_the_set_the_sensor_events_build_over_a_run() {
    let mut w = world();
    let ground = w.create_body(&BodyDef::fixed(v(0.0, -0.5))).unwrap();
    w.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))
        .unwrap();
    let zone = w.create_body(&BodyDef::fixed(v(0.0, 2.0))).unwrap();
    let sensor = w
        .create_shape(
            zone,
            &ShapeDef::default().sensor(),
            Polygon::make_box(1.5, 1.0),
        )
        .unwrap();
    // Balls thrown across the zone at different heights and speeds.
    let mut balls = Vec::new();
    for k in 0..6 {
        let b = w
            .create_body(
                &BodyDef::dynamic(v(-6.0 - k as Real, 1.0 + 0.5 * k as Real))
                    .with_velocity(v(4.0 + k as Real, 3.0)),
            )
            .unwrap();
        balls.push(
            w.create_shape(
                b,
                &ShapeDef::default(),
                Circle::new(Vec2::ZERO, 0.2).unwrap(),
            )
            .unwrap(),
        );
    }
    let mut from_events: BTreeSet<ShapeHandle> = BTreeSet::new();
    let (mut begins, mut ends) = (0, 0);
    for step in 0..240 {
        w.step(1.0 / 60.0).unwrap();
        let ev = &w.events().collision;
        for e in &ev.sensor_end {
            if e.sensor_shape == sensor {
                let other = e.visitor_shape;
                assert!(from_events.remove(&other), "step {step}: end without begin");
                ends += 1;
            }
        }
        for e in &ev.sensor_begin {
            if e.sensor_shape == sensor {
                let other = e.visitor_shape;
                assert!(from_events.insert(other), "step {step}: begin twice");
                begins += 1;
            }
        }
        let now = w.sensor_overlaps(sensor).unwrap();
        assert_eq!(
            now,
            from_events.iter().copied().collect::<Vec<_>>(),
            "step {step}"
        );
        // And from each ball's side: the sensor while it is inside.
        for &b in &balls {
            let inside = from_events.contains(&b);
            assert_eq!(w.sensor_overlaps(b).unwrap() == vec![sensor], inside);
        }
    }
    assert!(begins >= 3 && ends >= 3, "{begins} begins, {ends} ends");
}

#[test]
fn new_queries_reject_bad_input_with_typed_errors_and_change_nothing() {
    let mut w = world();
    let s = fixed(&mut w, v(3.0, 0.0), 0.0, Polygon::make_box(1.0, 1.0));
    let b = w.create_body(&BodyDef::dynamic(v(0.0, 3.0))).unwrap();
    let gone = w
        .create_shape(
            b,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .unwrap();
    w.destroy_shape(gone).unwrap();
    w.step(1.0 / 60.0).unwrap();
    let before = w.state_hash();
    let f = QueryFilter::default();
    let bad = |field, problem| WorldError::BadQuery { field, problem };
    assert_eq!(
        w.project_point(v(Real::NAN, 0.0), 1.0, &f),
        Err(bad("point", QueryProblem::NonFinite))
    );
    assert_eq!(
        w.project_point(Vec2::ZERO, -1.0, &f),
        Err(bad("max_distance", QueryProblem::Negative))
    );
    assert_eq!(
        w.project_point(Vec2::ZERO, Real::NAN, &f),
        Err(bad("max_distance", QueryProblem::NonFinite))
    );
    assert_eq!(
        w.shape_ray_cast(s, Vec2::ZERO, Vec2::ZERO, &f),
        Err(bad("translation", QueryProblem::ZeroLength))
    );
    assert_eq!(
        w.shape_ray_cast(s, v(0.0, Real::INFINITY), Vec2::X, &f),
        Err(bad("origin", QueryProblem::NonFinite))
    );
    assert_eq!(
        w.shape_test_point(s, v(Real::NAN, 0.0)),
        Err(bad("point", QueryProblem::NonFinite))
    );
    assert_eq!(
        w.shape_project_point(s, v(Real::NAN, 0.0)),
        Err(bad("point", QueryProblem::NonFinite))
    );
    assert_eq!(
        w.shape_test_point(gone, Vec2::ZERO),
        Err(WorldError::StaleShape)
    );
    assert_eq!(
        w.shape_ray_cast(gone, Vec2::ZERO, Vec2::X, &f),
        Err(WorldError::StaleShape)
    );
    assert_eq!(
        w.shape_project_point(gone, Vec2::ZERO),
        Err(WorldError::StaleShape)
    );
    assert_eq!(w.sensor_overlaps(gone), Err(WorldError::StaleShape));
    let other = world();
    let mut other = other;
    let foreign = fixed(&mut other, Vec2::ZERO, 0.0, Polygon::make_box(1.0, 1.0));
    assert_eq!(w.sensor_overlaps(foreign), Err(WorldError::ForeignHandle));
    assert_eq!(w.state_hash(), before);
    assert!(w.validate().is_ok());
}

#[cfg(feature = "portals")]
mod through_portals {
    use super::*;
    use janus2d::world::{PortalDef, PortalPairDef};

    /// Wall A (face x = 5, aperture at (5, 0), half-width 1, facing −x);
    /// wall B (face x = 20.5 at y = 10, half-width 2, facing +x): η = 2.
    /// A target box behind the exit at (25, 11).
    fn scene() -> (World, ShapeHandle, ShapeHandle) {
        let mut w = world();
        let wall_a = fixed(&mut w, v(5.5, 0.0), 0.0, Polygon::make_box(0.5, 3.0));
        let wall_b = fixed(&mut w, v(20.0, 10.0), 0.0, Polygon::make_box(0.5, 3.0));
        let (a, b) = (w.shape(wall_a).unwrap().body, w.shape(wall_b).unwrap().body);
        w.create_portal_pair(&PortalPairDef::new(
            PortalDef::new(a, v(-0.5, 0.0), -Vec2::X, 1.0),
            PortalDef::new(b, v(0.5, 0.0), Vec2::X, 2.0),
        ))
        .unwrap();
        let target = fixed(&mut w, v(25.0, 11.0), 0.0, Polygon::make_box(0.5, 0.5));
        (w, wall_a, target)
    }

    #[test]
    fn shape_ray_cast_follows_the_ray_through_an_aperture() {
        let (w, wall_a, target) = scene();
        let (origin, d) = (v(0.0, 0.5), v(10.0, 0.0));
        let plain = QueryFilter::default();
        let through = plain.through_portals();
        // Without portals the target is not on the line; through them it is
        // hit at (24.5, 11), fraction 0.5 + 0.4 · 0.5 = 0.7.
        assert_eq!(w.shape_ray_cast(target, origin, d, &plain).unwrap(), None);
        let hit = w
            .shape_ray_cast(target, origin, d, &through)
            .unwrap()
            .unwrap();
        assert!((hit.point - v(24.5, 11.0)).length() < 1e-4, "{hit:?}");
        assert!((hit.fraction - 0.7).abs() < 1e-5);
        assert_eq!(hit.portal_hops, 1);
        // The wall is hit at its face without portals, and not in its hole
        // with them.
        let wall = w
            .shape_ray_cast(wall_a, origin, d, &plain)
            .unwrap()
            .unwrap();
        assert!((wall.fraction - 0.5).abs() < 1e-6);
        assert_eq!(w.shape_ray_cast(wall_a, origin, d, &through).unwrap(), None);
        // Beside the aperture (y = 1.5 > 1) the wall stops even a ray through portals.
        let lip = w
            .shape_ray_cast(wall_a, v(0.0, 1.5), d, &through)
            .unwrap()
            .unwrap();
        assert!((lip.fraction - 0.5).abs() < 1e-6);
    }
}
