//! Events in one place (issue 32, deliverable 3): contact begin with its
//! manifold, per-shape switches, sensor roles, body move events, contact
//! force events and portal events, all read from `World::events`.

use janus2d::prelude::*;
use janus2d_testbed::scenes::{self, DT};

/// A world with the shared settings (gravity (0, −10)).
fn world_with(def: WorldDef) -> World {
    World::new(def).unwrap()
}

/// A static ground box of half width 50 whose top is at y = 0; its shape.
fn ground(world: &mut World) -> ShapeHandle {
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(50.0, 0.5))
        .unwrap()
}

/// A dynamic 1 m box (1 kg) with its bottom at `bottom`; body and shape.
fn unit_box(world: &mut World, x: Real, bottom: Real, def: &ShapeDef) -> (BodyHandle, ShapeHandle) {
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(x, bottom + 0.5)))
        .unwrap();
    let s = world
        .create_shape(b, def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    (b, s)
}

/// A box dropped 0.5 m onto the ground: one contact begin, whose manifold
/// has the normal (0, 1) (ground → box) within 1e-5 and two points whose
/// box-side surface points are within 1 cm of the box's bottom corners
/// when the contact was found (the mid-points themselves within
/// 0 ≤ s < 5 cm above the ground top, y = s/2), carrying the shapes' user
/// material ids.
#[test]
fn a_landing_box_begins_one_contact_with_its_manifold() {
    let mut world = world_with(scenes::shared_settings());
    let floor = ground(&mut world);
    world.set_shape_user_material_id(floor, 3).unwrap();
    let def = ShapeDef::default().with_material_id(9);
    let (_, s) = unit_box(&mut world, 0.0, 0.5, &def);
    let body = world.shape_body(s).unwrap();
    let mut begins = Vec::new();
    let mut before = Vec2::ZERO;
    for _ in 0..120 {
        let start = world.position(body).unwrap();
        world.step(DT).unwrap();
        let found = &world.events().collision.contact_begin;
        if !found.is_empty() {
            before = start;
        }
        begins.extend(found.iter().copied());
    }
    assert_eq!(begins.len(), 1, "{begins:?}");
    let b = begins[0];
    assert_eq!((b.shape_a, b.shape_b), (floor, s));
    let m = b.manifold;
    assert!(
        (m.normal - Vec2::new(0.0, 1.0)).length() < 1e-5,
        "normal {:?}",
        m.normal
    );
    assert_eq!(m.points().len(), 2);
    // The points are the mid-points between the surfaces when the
    // contact was found (speculatively, before the box reached the
    // ground): moved by half the separation along the normal they are
    // the box's bottom corners at the start of that step.
    let mut on_box: Vec<Vec2> = (0..2)
        .map(|k| m.points[k] + 0.5 * m.separations[k] * m.normal)
        .collect();
    on_box.sort_by(|p, q| p.x.total_cmp(&q.x));
    for (p, dx) in on_box.iter().zip([-0.5, 0.5]) {
        let corner = before + Vec2::new(dx, -0.5);
        assert!(
            (*p - corner).length() < 0.01,
            "point {p:?}, corner {corner:?}"
        );
    }
    for k in 0..2 {
        // Found within the speculative distance: ahead of the ground in
        // the f32 build (2.2 cm), 8 mm into it in the f64 build, whose
        // first manifold comes one step later.
        assert!(m.separations[k].abs() < 0.05, "{m:?}");
        assert!(
            (m.points[k].y - 0.5 * m.separations[k]).abs() < 1e-4,
            "{m:?}"
        );
    }
    assert_eq!(m.user_material_ids, [3, 9]);
}

/// A box whose shape turns contact events off lands and rests (its centre
/// at 0.5 ± 1 cm) with no begin or end event; turning them off with the
/// setter on a resting box keeps its destruction silent too.
#[test]
fn contact_events_turned_off_on_a_shape_report_nothing() {
    let mut world = world_with(scenes::shared_settings());
    ground(&mut world);
    let quiet = ShapeDef::default().with_contact_events(false);
    let (b, _) = unit_box(&mut world, 0.0, 0.5, &quiet);
    let (b2, s2) = unit_box(&mut world, 3.0, 0.5, &ShapeDef::default());
    let (mut begins, mut ends) = (0, 0);
    let count = |w: &World, body: BodyHandle| {
        let e = &w.events().collision;
        let of = |s: ShapeHandle| w.shape_body(s).ok() == Some(body);
        (
            e.contact_begin
                .iter()
                .filter(|e| of(e.shape_a) || of(e.shape_b))
                .count(),
            e.contact_end
                .iter()
                .filter(|e| of(e.shape_a) || of(e.shape_b))
                .count(),
        )
    };
    let mut loud_begins = 0;
    for _ in 0..120 {
        world.step(DT).unwrap();
        let (bb, ee) = count(&world, b);
        begins += bb;
        ends += ee;
        loud_begins += count(&world, b2).0;
    }
    assert_eq!((begins, ends), (0, 0));
    assert_eq!(loud_begins, 1, "the box with events on reports its begin");
    assert!((world.position(b).unwrap().y - 0.5).abs() < 0.01);
    // Off on the second box now: its end (destroyed) is not reported.
    world.set_shape_contact_events(s2, false).unwrap();
    world.destroy_body(b2).unwrap();
    world.step(DT).unwrap();
    assert!(world.events().collision.contact_end.is_empty());
}

/// A ball falls through a static sensor box: one sensor begin and one
/// sensor end, each naming the sensor shape and the ball as the visitor,
/// whichever shape was created first. With sensor events off on the ball,
/// none.
#[test]
fn sensor_events_name_the_sensor_and_the_visitor_in_both_orders() {
    for sensor_first in [true, false] {
        for visitor_on in [true, false] {
            let mut world = world_with(scenes::shared_settings());
            let zone = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
            let ball_def = ShapeDef::default().with_sensor_events(visitor_on);
            let make_sensor = |w: &mut World| {
                w.create_shape(
                    zone,
                    &ShapeDef::default().sensor(),
                    Polygon::make_box(1.0, 1.0),
                )
                .unwrap()
            };
            let make_ball = |w: &mut World| {
                let b = w
                    .create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.0)))
                    .unwrap();
                w.create_shape(b, &ball_def, Circle::new(Vec2::ZERO, 0.25).unwrap())
                    .unwrap()
            };
            let (sensor, ball) = if sensor_first {
                let s = make_sensor(&mut world);
                (s, make_ball(&mut world))
            } else {
                let b = make_ball(&mut world);
                (make_sensor(&mut world), b)
            };
            let (mut begins, mut ends) = (Vec::new(), Vec::new());
            for _ in 0..90 {
                world.step(DT).unwrap();
                let e = &world.events().collision;
                begins.extend(e.sensor_begin.iter().copied());
                ends.extend(e.sensor_end.iter().copied());
            }
            let what = format!("sensor first {sensor_first}, visitor on {visitor_on}");
            assert!(world.position(world.shape_body(ball).unwrap()).unwrap().y < -2.0);
            if !visitor_on {
                assert!(begins.is_empty() && ends.is_empty(), "{what}");
                continue;
            }
            assert_eq!((begins.len(), ends.len()), (1, 1), "{what}");
            for e in [begins[0], ends[0]] {
                assert_eq!(e.sensor_shape, sensor, "{what}");
                assert_eq!(e.visitor_shape, ball, "{what}");
            }
        }
    }
}

/// Move events (world switch on): while two boxes settle, each step lists
/// exactly the two of them in body order (not the ground, not a body with
/// move events off); the step a box falls asleep lists it once with
/// `fell_asleep`, and later steps list nothing. With the world switch off,
/// no step lists anything.
#[test]
fn move_events_list_exactly_the_bodies_that_moved() {
    let mut world = world_with(WorldDef::default().with_move_events(true));
    ground(&mut world);
    let (a, _) = unit_box(&mut world, 0.0, 0.01, &ShapeDef::default());
    let (b, _) = unit_box(&mut world, 3.0, 0.01, &ShapeDef::default());
    let (silent, _) = unit_box(&mut world, 6.0, 0.01, &ShapeDef::default());
    world.set_body_move_events(silent, false).unwrap();
    world.set_body_user_data(b, 42).unwrap();
    let mut reported_asleep: Vec<BodyHandle> = Vec::new();
    let mut steps_after = 0;
    for step in 0..600 {
        world.step(DT).unwrap();
        let moves = &world.events().moves;
        let expected: Vec<BodyHandle> = [a, b]
            .into_iter()
            .filter(|h| !reported_asleep.contains(h))
            .collect();
        let listed: Vec<BodyHandle> = moves.iter().map(|m| m.body).collect();
        assert_eq!(listed, expected, "step {step}");
        if expected.is_empty() {
            steps_after += 1;
        }
        for m in moves {
            assert_eq!(m.transform.p, world.position(m.body).unwrap());
            assert_eq!(m.user_data, if m.body == b { 42 } else { 0 });
            if m.fell_asleep {
                assert!(world.is_sleeping(m.body).unwrap(), "step {step}");
                reported_asleep.push(m.body);
            } else {
                assert!(!world.is_sleeping(m.body).unwrap(), "step {step}");
            }
        }
    }
    reported_asleep.sort();
    assert_eq!(reported_asleep, vec![a, b], "each reported asleep once");
    assert!(steps_after > 10, "{steps_after} steps with nothing listed");
    // Off: a falling box is not listed.
    world.set_move_events(false);
    world.wake_body(a).unwrap();
    world.set_linear_velocity(a, Vec2::new(0.0, 3.0)).unwrap();
    world.step(DT).unwrap();
    assert!(world.events().moves.is_empty());
}

/// A 1 kg box dropped from 1 m (4.5 m/s at impact) with a force threshold
/// of 50 N: a force event whose largest point force exceeds m·g = 10 N
/// (the impact pushes far harder than the weight); with the threshold at
/// 5000 N, none. No shape with a threshold: no event and no pass.
#[test]
fn a_dropped_box_gives_a_contact_force_event_above_its_threshold() {
    let run = |threshold: Real| {
        let mut world = world_with(scenes::shared_settings());
        ground(&mut world);
        let def = ShapeDef::default().with_force_event_threshold(threshold);
        let (b, s) = unit_box(&mut world, 0.0, 1.0, &def);
        let mass = world.mass(b).unwrap();
        let mut events = Vec::new();
        for _ in 0..90 {
            world.step(DT).unwrap();
            events.extend(world.events().collision.forces.iter().copied());
        }
        (events, mass, s)
    };
    let (events, mass, s) = run(50.0);
    assert!((mass - 1.0).abs() < 1e-5);
    assert!(!events.is_empty());
    let max = events
        .iter()
        .map(|e| e.max_force_magnitude)
        .fold(0.0, Real::max);
    assert!(max > mass * 10.0, "max force {max} N");
    for e in &events {
        assert!(e.shape_b == s || e.shape_a == s);
        assert!(e.total_force_magnitude > 50.0);
        assert!((e.total_force.length() - e.total_force_magnitude).abs() < 1e-3);
        assert!(e.total_force.y > 0.0, "the ground pushes the box up");
    }
    assert!(run(5000.0).0.is_empty());
    assert!(run(Real::INFINITY).0.is_empty());
}

/// A hit event of a fast ball against a wall: `point` is the speculative
/// mid-point, in front of the wall; the point on the wall's surface
/// (`point_a`, the wall being shape a) is on its face, x = 10 ± 1 cm.
#[test]
fn a_hit_reports_the_point_on_the_wall_face() {
    let mut world = world_with(scenes::shared_settings().with_gravity(Vec2::ZERO));
    let wall = world
        .create_body(&BodyDef::fixed(Vec2::new(10.5, 0.0)))
        .unwrap();
    world
        .create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))
        .unwrap();
    let ball = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default().with_hit_events(true),
            Circle::new(Vec2::ZERO, 0.25).unwrap(),
        )
        .unwrap();
    world
        .set_linear_velocity(ball, Vec2::new(60.0, 0.0))
        .unwrap();
    let mut hits = Vec::new();
    for _ in 0..30 {
        world.step(DT).unwrap();
        hits.extend(world.events().collision.hits.iter().copied());
    }
    assert!(!hits.is_empty());
    let h = hits[0];
    assert!((h.point_a.x - 10.0).abs() < 0.01, "wall face: {h:?}");
    assert!(h.point.x <= h.point_a.x + 1e-4);
    assert!(h.approach_speed > 50.0);
}

/// A box falling through the portal drop scene's floor portal: the
/// crossing's start and completion are in `StepEvents::portals`, the same
/// list the deprecated `portal_events` reads.
#[cfg(feature = "portals")]
#[test]
fn portal_crossing_events_are_step_events() {
    use janus2d::world::PortalEvent;
    let (mut scene, _pair) = scenes::portal_drop(&WorldDef::default());
    let (mut started, mut completed) = (0, 0);
    for _ in 0..150 {
        scene.world.step(DT).unwrap();
        let events = scene.world.events();
        #[allow(deprecated)]
        let alias = scene.world.portal_events();
        assert_eq!(alias, events.portals.as_slice());
        for e in &events.portals {
            match e {
                PortalEvent::CrossingStarted { body, .. } if *body == scene.probe => started += 1,
                PortalEvent::CrossingCompleted { body, .. } if *body == scene.probe => {
                    completed += 1
                }
                _ => {}
            }
        }
    }
    assert_eq!((started, completed), (1, 1));
}
