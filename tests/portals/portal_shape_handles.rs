//! Shape handles follow the object through a portal, as the body handle
//! does (issue 32, deliverable 2): after a crossing the user's shape
//! handle names the shape of the body that came out, keeps its material,
//! filter, flags and user data, and the contact and sensor events the
//! object makes on the far side carry it. Replaying every step's begin and
//! end events through the crossing rebuilds the touching set exactly.

use std::collections::BTreeSet;

use janus2d::prelude::*;
use janus2d::world::CollisionEvents;
use janus2d::{PortalDef, PortalEvent, PortalPairDef};

const DT: Real = 1.0 / 60.0;

/// A pair of shapes, the lower handle first.
type Pair = (ShapeHandle, ShapeHandle);

fn pair(a: ShapeHandle, b: ShapeHandle) -> Pair {
    if a <= b { (a, b) } else { (b, a) }
}

/// The world's touching pairs: (solid, sensor).
fn touching(world: &World) -> (BTreeSet<Pair>, BTreeSet<Pair>) {
    let (mut solid, mut sensor) = (BTreeSet::new(), BTreeSet::new());
    for c in world.contacts().filter(|c| c.touching) {
        let p = pair(c.shapes[0], c.shapes[1]);
        if c.sensor {
            sensor.insert(p);
        } else {
            solid.insert(p);
        }
    }
    (solid, sensor)
}

/// Replays one step's events on the touching sets: each end a pair that
/// touched, each begin one that did not.
fn replay(solid: &mut BTreeSet<Pair>, sensor: &mut BTreeSet<Pair>, e: &CollisionEvents) {
    for x in &e.contact_end {
        assert!(solid.remove(&pair(x.shape_a, x.shape_b)), "end of {x:?}");
    }
    for x in &e.contact_begin {
        assert!(solid.insert(pair(x.shape_a, x.shape_b)), "begin of {x:?}");
    }
    for x in &e.sensor_end {
        let p = pair(x.sensor_shape, x.visitor_shape);
        assert!(sensor.remove(&p), "sensor end of {x:?}");
    }
    for x in &e.sensor_begin {
        let p = pair(x.sensor_shape, x.visitor_shape);
        assert!(sensor.insert(p), "sensor begin of {x:?}");
    }
}

/// Begin and end events of solid contacts between `a` and `b` in a step.
fn count(e: &CollisionEvents, a: ShapeHandle, b: ShapeHandle) -> (usize, usize) {
    let p = pair(a, b);
    let begins = e
        .contact_begin
        .iter()
        .filter(|x| pair(x.shape_a, x.shape_b) == p)
        .count();
    let ends = e
        .contact_end
        .iter()
        .filter(|x| pair(x.shape_a, x.shape_b) == p)
        .count();
    (begins, ends)
}

/// The user's crate shape: a material, filter, flags and user data to
/// find again on the far side.
fn crate_def() -> ShapeDef {
    ShapeDef::default()
        .with_user_data(77)
        .with_friction(0.2)
        .with_restitution(0.05)
        .with_filter(Filter::new(0x2, u64::MAX))
        .with_material_id(9)
        .with_hit_events(true)
}

/// The guide's drop: a crate falls into a portal in the floor and flies
/// out of a wall portal (facing +x) over a ledge below the aperture,
/// with a sensor over the ledge. Returns the world, the crate, its
/// shape, the ledge's shape and the sensor's shape.
fn drop_scene() -> (World, BodyHandle, ShapeHandle, ShapeHandle, ShapeHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let floor = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))
        .unwrap();
    let wall = world
        .create_body(&BodyDef::fixed(Vec2::new(-20.0, 5.0)))
        .unwrap();
    world
        .create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))
        .unwrap();
    world
        .create_portal_pair(&PortalPairDef::new(
            PortalDef::new(floor, Vec2::new(0.0, 0.5), Vec2::Y, 1.0),
            PortalDef::new(wall, Vec2::new(0.5, 0.0), Vec2::X, 1.0),
        ))
        .unwrap();
    // The ledge: top at y = 3.5, below the aperture (y 4 to 6).
    let ledge = world
        .create_body(&BodyDef::fixed(Vec2::new(-14.5, 3.0)))
        .unwrap();
    let ledge_shape = world
        .create_shape(ledge, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))
        .unwrap();
    // A sensor zone over the ledge, away from the wall.
    let zone = world
        .create_body(&BodyDef::fixed(Vec2::new(-10.0, 5.0)))
        .unwrap();
    let sensor = world
        .create_shape(
            zone,
            &ShapeDef::default().sensor(),
            Polygon::make_box(5.0, 1.4),
        )
        .unwrap();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0)))
        .unwrap();
    let shape = world
        .create_shape(body, &crate_def(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    (world, body, shape, ledge_shape, sensor)
}

/// A crate slides along a floor into a wall portal (facing −x) and out of
/// another (facing +x) onto a second floor, which its clone touches while
/// it crosses. Returns the world, the crate, its shape and the far floor's
/// shape.
fn slide_scene() -> (World, BodyHandle, ShapeHandle, ShapeHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let floor_a = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(floor_a, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))
        .unwrap();
    let wall_a = world
        .create_body(&BodyDef::fixed(Vec2::new(5.5, 2.0)))
        .unwrap();
    world
        .create_shape(wall_a, &ShapeDef::default(), Polygon::make_box(0.5, 2.5))
        .unwrap();
    let floor_b = world
        .create_body(&BodyDef::fixed(Vec2::new(-25.0, -0.5)))
        .unwrap();
    let floor_b_shape = world
        .create_shape(floor_b, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))
        .unwrap();
    let wall_b = world
        .create_body(&BodyDef::fixed(Vec2::new(-30.5, 2.0)))
        .unwrap();
    world
        .create_shape(wall_b, &ShapeDef::default(), Polygon::make_box(0.5, 2.5))
        .unwrap();
    // Apertures from the floor (y = 0) up to y = 2.4.
    world
        .create_portal_pair(&PortalPairDef::new(
            PortalDef::new(wall_a, Vec2::new(-0.5, -0.9), -Vec2::X, 1.2),
            PortalDef::new(wall_b, Vec2::new(0.5, -0.9), Vec2::X, 1.2),
        ))
        .unwrap();
    let body = world
        .create_body(&BodyDef {
            linear_velocity: Vec2::new(8.0, 0.0),
            ..BodyDef::dynamic(Vec2::new(2.0, 0.5))
        })
        .unwrap();
    let shape = world
        .create_shape(
            body,
            &crate_def().with_friction(0.0),
            Polygon::make_box(0.5, 0.5),
        )
        .unwrap();
    (world, body, shape, floor_b_shape)
}

/// Steps the world once, replays the step's events on `sets` and checks
/// that they rebuild the world's touching pairs exactly.
fn step_and_replay(world: &mut World, sets: &mut (BTreeSet<Pair>, BTreeSet<Pair>)) {
    world.step(DT).unwrap();
    replay(&mut sets.0, &mut sets.1, &world.events().collision);
    assert_eq!(*sets, touching(world), "replayed events != touching pairs");
}

/// Steps until the crossing of `body` completes (at most `max` steps);
/// returns the step and the clone's shapes at the start.
fn until_completed(world: &mut World, body: BodyHandle, max: usize) -> (usize, Vec<ShapeHandle>) {
    let mut clone_shapes = Vec::new();
    let mut sets = touching(world);
    for step in 1..=max {
        step_and_replay(world, &mut sets);
        for e in &world.events().portals {
            match *e {
                PortalEvent::CrossingStarted { body: b, clone, .. } if b == body => {
                    clone_shapes = world.body_shapes(clone).unwrap();
                }
                PortalEvent::CrossingCompleted { body: b, .. } if b == body => {
                    return (step, clone_shapes);
                }
                _ => {}
            }
        }
    }
    panic!("no crossing completed in {max} steps");
}

#[test]
fn user_shape_handles_name_the_body_that_came_out() {
    let (mut world, body, shape, _) = slide_scene();
    // A second shape: a sensor with its own user data, off the centre.
    let probe = world
        .create_shape(
            body,
            &ShapeDef::default().sensor().with_user_data(78),
            Circle::new(Vec2::new(0.0, 0.2), 0.2).unwrap(),
        )
        .unwrap();
    let shapes_before = world.shape_count();
    let (step, clone_shapes) = until_completed(&mut world, body, 60);
    assert_eq!(step, 27);
    assert_eq!(clone_shapes.len(), 2);
    // The user's handles name the shapes of the body that came out.
    assert_eq!(world.shape_body(shape), Ok(body));
    assert_eq!(world.shape_body(probe), Ok(body));
    assert_eq!(world.body_shapes(body).unwrap(), vec![shape, probe]);
    // The clone's handles went with the body that was removed.
    for h in clone_shapes {
        assert_eq!(world.shape_body(h), Err(WorldError::StaleShape));
    }
    assert_eq!(world.shape_count(), shapes_before);
    // Material, filter, flags and user data are the user's.
    let def = &world.shape(shape).unwrap().def;
    assert_eq!(def.user_data, 77);
    assert_eq!(def.friction, 0.0);
    assert_eq!(def.restitution, 0.05);
    assert_eq!(def.filter.category_bits, 0x2);
    assert_eq!(def.user_material_id, 9);
    assert!(def.enable_hit_events && !def.is_sensor);
    let def = &world.shape(probe).unwrap().def;
    assert_eq!(def.user_data, 78);
    assert!(def.is_sensor);
    // The shapes are where the body is: out of the far wall (x < -28.5).
    let p = world.position(body).unwrap();
    assert!(p.x < -28.5, "{p:?}");
    let b = world.shape(shape).unwrap().aabb;
    let centre = (b.lower + b.upper) * 0.5;
    assert!((centre - p).length() < 1e-3, "{centre:?} vs {p:?}");
    let Shape::Circle(c) = world.shape(probe).unwrap().geometry else {
        panic!("the probe is a circle");
    };
    assert!((c.center - Vec2::new(0.0, 0.2)).length() < 1e-6);
    world.validate().unwrap();
    // The handle goes on working: setters reach the shape that came out.
    world.set_shape_user_data(shape, 5).unwrap();
    assert_eq!(world.shape_user_data(shape), Ok(5));
}

#[test]
fn far_floor_contact_continues_under_the_user_handle() {
    let (mut world, body, shape, floor_b) = slide_scene();
    let mut sets = touching(&world);
    let (mut completed, mut clone_shape) = (0, None);
    let (mut user, mut clone) = ((0, 0), (0, 0));
    let mut user_begin_step = 0;
    for step in 1..=90 {
        step_and_replay(&mut world, &mut sets);
        let e = world.events();
        for p in &e.portals {
            match *p {
                PortalEvent::CrossingStarted { clone: c, .. } => {
                    clone_shape = Some(world.body_shapes(c).unwrap()[0]);
                }
                PortalEvent::CrossingCompleted { body: b, .. } if b == body => completed = step,
                _ => {}
            }
        }
        let (b, n) = count(&e.collision, shape, floor_b);
        if b > 0 {
            user_begin_step = step;
        }
        user = (user.0 + b, user.1 + n);
        if let Some(c) = clone_shape {
            let (b, n) = count(&e.collision, c, floor_b);
            clone = (clone.0 + b, clone.1 + n);
        }
    }
    assert_eq!(completed, 27);
    // The clone touched the far floor before the handover (one begin and
    // the end at the handover); the user's handle begins once, the step
    // after, and has not ended.
    assert_eq!(clone, (1, 1));
    assert_eq!(user, (1, 0));
    assert_eq!(user_begin_step, 28);
    assert!(sets.0.contains(&pair(shape, floor_b)));
}

#[test]
fn ground_contact_after_exit_begins_once_with_the_user_handle() {
    let (mut world, body, shape, ledge, _) = drop_scene();
    let mut sets = touching(&world);
    let (mut user, mut completed, mut landed) = ((0, 0), 0, 0);
    for step in 1..=150 {
        step_and_replay(&mut world, &mut sets);
        let e = world.events();
        if e.portals
            .iter()
            .any(|p| matches!(p, PortalEvent::CrossingCompleted { body: b, .. } if *b == body))
        {
            completed = step;
        }
        let (b, n) = count(&e.collision, shape, ledge);
        if b > 0 {
            landed = step;
        }
        user = (user.0 + b, user.1 + n);
    }
    // (It lands moving along +x: a speculative point begins touching once
    // its fall, not its whole speed, can close the gap within a step,
    // which is step 81; step 80 while the whole speed counted.)
    assert_eq!((completed, landed), (57, 81));
    assert_eq!(user, (1, 0));
    assert_eq!(world.shape_body(shape), Ok(body));
    let c = world
        .shape_contacts(shape)
        .unwrap()
        .filter(|c| c.touching && !c.sensor)
        .count();
    assert_eq!(c, 1);
}

#[test]
fn far_side_sensor_reports_the_user_shape_as_visitor() {
    let (mut world, _, shape, _, sensor) = drop_scene();
    let mut sets = touching(&world);
    let mut visitors = Vec::new();
    for _ in 0..150 {
        step_and_replay(&mut world, &mut sets);
        let e = &world.events().collision;
        for x in e.sensor_begin.iter().chain(&e.sensor_end) {
            assert_eq!(x.sensor_shape, sensor);
            visitors.push(x.visitor_shape);
        }
    }
    // One begin, with the user's handle, and the crate stays inside.
    assert_eq!(visitors, vec![shape]);
    assert!(sets.1.contains(&pair(sensor, shape)));
}
