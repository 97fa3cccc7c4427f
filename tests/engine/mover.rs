//! The character mover and controller: slopes, stairs, moving and one-way
//! platforms, tunnelling, the plane solver, typed errors. Each test prints
//! its measured figure beside its bound.

use janus2d::base::geometry::GeometryError;
use janus2d::prelude::*;
use janus2d::world::query::QueryProblem;
use janus2d::{PlaneResult, solve_planes};

const DT: Real = 1.0 / 60.0;
const G: Real = 10.0;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

/// A capsule 1 m tall, radius 0.25, its bottom at the reference point.
fn capsule() -> Capsule {
    Capsule::new(v(0.0, 0.25), v(0.0, 0.75), 0.25).unwrap()
}

/// A world with a floor whose top is y = 0 from x = −10 to 40.
fn world_with_floor() -> World {
    let mut world = World::new(WorldDef::default()).unwrap();
    fixed(&mut world, v(15.0, -0.5), Polygon::make_box(25.0, 0.5));
    world
}

fn fixed(world: &mut World, at: Vec2, polygon: Polygon) -> BodyHandle {
    let b = world.create_body(&BodyDef::fixed(at)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), polygon)
        .unwrap();
    b
}

/// A game loop: walk at `vx`, gravity while in the air; the positions.
fn walk(
    world: &World,
    cc: &mut CharacterController,
    start: Vec2,
    vx: Real,
    steps: usize,
) -> Vec<MoveResult> {
    let (mut p, mut vy) = (start, 0.0);
    let mut out = Vec::new();
    for _ in 0..steps {
        let r = cc
            .move_and_slide(world, &capsule(), p, v(vx, vy), DT, &QueryFilter::default())
            .unwrap();
        p = r.position;
        vy = if r.grounded { 0.0 } else { r.velocity.y } - G * DT;
        out.push(r);
    }
    out
}

/// A ramp rising to the right from its toe at (2, 0), `degrees` steep.
fn ramp(world: &mut World, degrees: Real) {
    let length: Real = 8.0;
    let h = length * degrees.to_radians().tan();
    let tri = Polygon::from_hull(&[v(0.0, 0.0), v(length, 0.0), v(length, h)], 0.0).unwrap();
    fixed(world, v(2.0, 0.0), tri);
}

#[test]
fn walks_up_a_30_degree_slope_and_not_a_60_degree_one() {
    let mut world = world_with_floor();
    ramp(&mut world, 30.0);
    let mut cc = CharacterController::new();
    let run = walk(&world, &mut cc, v(0.0, 0.01), 2.0, 180);
    let end = run.last().unwrap();
    // Resting on the slope: the bottom circle's centre is radius + skin off
    // the line y = (x − 2) tan 30°.
    let t = (30.0 as Real).to_radians();
    let on_slope = (end.position.x - 2.0) * t.tan() + (0.25 + cc.skin) / t.cos() - 0.25;
    let err = (end.position.y - on_slope).abs();
    println!(
        "30°: after 3 s x = {:.3} (bound > 5.5), y = {:.3}, off the slope line by {:.4} m (bound < 0.01), grounded {}",
        end.position.x, end.position.y, err, end.grounded
    );
    assert!(end.position.x > 5.5 && err < 0.01 && end.grounded);
    assert!(
        run.iter().skip(1).all(|r| r.grounded),
        "grounded all the way up"
    );

    let mut world = world_with_floor();
    ramp(&mut world, 60.0);
    let mut cc = CharacterController::new();
    let run = walk(&world, &mut cc, v(0.0, 0.01), 2.0, 180);
    let max_y = run.iter().map(|r| r.position.y).fold(Real::MIN, Real::max);
    let max_x = run.iter().map(|r| r.position.x).fold(Real::MIN, Real::max);
    // Touching the face: the bottom circle's centre (x, 0.26) is radius +
    // skin = 0.26 from the line y = √3 (x − 2), so x = 2 − 0.26 / √3.
    let touching = 2.0 - 0.26 / (3.0 as Real).sqrt();
    println!(
        "60°: highest y = {max_y:.4} m (bound < 0.02: standing is the 0.01 skin), furthest x = {max_x:.4} (bound ≤ {:.4}: touching + 1 mm)",
        touching + 0.001
    );
    assert!(max_y < 0.02 && max_x <= touching + 0.001);
}

/// A stair of height `h`: a box from x = 2 to 12.
fn stair(world: &mut World, h: Real) {
    fixed(world, v(7.0, 0.5 * h), Polygon::make_box(5.0, 0.5 * h));
}

#[test]
fn steps_a_20_cm_stair_and_not_a_50_cm_one() {
    let mut world = world_with_floor();
    stair(&mut world, 0.2);
    let mut cc = CharacterController::new();
    let run = walk(&world, &mut cc, v(0.0, 0.01), 2.0, 180);
    let end = run.last().unwrap();
    let steps = run.iter().filter(|r| r.stepped).count();
    let above = end.position.y - 0.2;
    println!(
        "0.2 m stair: x = {:.3} (bound > 5.5), bottom {:.4} m above the top (bound 0..0.02), {} step(s)",
        end.position.x, above, steps
    );
    assert!(end.position.x > 5.5 && (0.0..0.02).contains(&above) && end.grounded);
    assert!(steps >= 1);

    let mut world = world_with_floor();
    stair(&mut world, 0.5);
    let mut cc = CharacterController::new();
    let run = walk(&world, &mut cc, v(0.0, 0.01), 2.0, 180);
    let max_y = run.iter().map(|r| r.position.y).fold(Real::MIN, Real::max);
    let max_x = run.iter().map(|r| r.position.x).fold(Real::MIN, Real::max);
    println!(
        "0.5 m stair: highest y = {max_y:.4} (bound < 0.02), furthest x = {max_x:.4} (bound ≤ 1.75)"
    );
    assert!(max_y < 0.02 && max_x <= 1.75);
    assert!(run.iter().all(|r| !r.stepped));
}

/// A kinematic platform 3 m wide moving at `velocity`; the character stands
/// on it for 2 s; the largest drift of its offset from the platform.
fn ride(velocity: Vec2) -> Real {
    let mut world = World::new(WorldDef::default()).unwrap();
    let platform = world.create_body(&BodyDef::kinematic(v(0.0, 5.0))).unwrap();
    world
        .create_shape(platform, &ShapeDef::default(), Polygon::make_box(1.5, 0.1))
        .unwrap();
    world.set_linear_velocity(platform, velocity).unwrap();
    let mut cc = CharacterController::new();
    let (mut p, mut vy) = (v(0.3, 5.1 + cc.skin), 0.0);
    // Placed on the platform: the first move finds the ground it stands on.
    let first = cc
        .move_and_slide(
            &world,
            &capsule(),
            p,
            Vec2::ZERO,
            DT,
            &QueryFilter::default(),
        )
        .unwrap();
    assert!(first.grounded);
    let mut offset0 = None;
    let mut drift: Real = 0.0;
    for _ in 0..120 {
        world.step(DT).unwrap();
        let r = cc
            .move_and_slide(
                &world,
                &capsule(),
                p,
                v(0.0, vy),
                DT,
                &QueryFilter::default(),
            )
            .unwrap();
        p = r.position;
        vy = if r.grounded { 0.0 } else { r.velocity.y } - G * DT;
        let offset = p - world.position(platform).unwrap();
        let o0 = *offset0.get_or_insert(offset);
        drift = drift.max((offset - o0).length());
        assert!(r.grounded, "stays on the platform: {r:?} {offset:?}");
    }
    drift
}

#[test]
fn rides_a_platform_moving_at_3_m_s_within_a_centimetre() {
    for (name, vel) in [
        ("right", v(3.0, 0.0)),
        ("up", v(0.0, 3.0)),
        ("down", v(0.0, -3.0)),
        ("diagonal", v(2.121, 2.121)),
    ] {
        let drift = ride(vel);
        println!("platform {name} at 3 m/s: drift {drift:.5} m (bound < 0.01)");
        assert!(drift < 0.01, "{name}: {drift}");
    }
}

#[test]
fn never_tunnels_a_5_cm_wall() {
    for speed in [20.0, 200.0] {
        let mut world = world_with_floor();
        fixed(&mut world, v(5.0, 1.0), Polygon::make_box(0.025, 1.0));
        let mut cc = CharacterController::new();
        let run = walk(&world, &mut cc, v(0.0, 0.01), speed, 60);
        let right_edge = run
            .iter()
            .map(|r| r.position.x + 0.25)
            .fold(Real::MIN, Real::max);
        let into = right_edge - 4.975;
        println!(
            "{speed} m/s ({:.2} m a step): deepest into the wall {into:.5} m (bound ≤ 0)",
            speed * DT
        );
        assert!(into <= 0.0);
    }
    // In the air, diagonally, straight at a thin static wall.
    let mut world = World::new(WorldDef::default()).unwrap();
    fixed(&mut world, v(5.0, 0.0), Polygon::make_box(0.025, 10.0));
    let mut cc = CharacterController::new();
    let mut p = v(0.0, 0.0);
    let mut deepest = Real::MIN;
    for _ in 0..30 {
        let r = cc
            .move_and_slide(
                &world,
                &capsule(),
                p,
                v(20.0, 5.0),
                DT,
                &QueryFilter::default(),
            )
            .unwrap();
        p = r.position;
        deepest = deepest.max(p.x + 0.25 - 4.975);
    }
    println!("in the air at (20, 5) m/s: deepest {deepest:.5} m (bound ≤ 0)");
    assert!(deepest <= 0.0);
}

#[test]
fn jumps_up_through_a_one_way_platform_and_lands_on_it() {
    let one_way = ShapeDef {
        filter: Filter {
            category_bits: 0b10,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    for bits in [0b10, 0] {
        let mut world = world_with_floor();
        let ledge = world.create_body(&BodyDef::fixed(v(0.0, 2.0))).unwrap();
        world
            .create_shape(ledge, &one_way, Polygon::make_box(2.0, 0.1))
            .unwrap();
        let mut cc = CharacterController::new().with_one_way_bits(bits);
        let (mut p, mut vy) = (v(0.0, 0.01), 9.0); // a jump 4 m high
        let mut top = Real::MIN;
        for _ in 0..180 {
            let r = cc
                .move_and_slide(
                    &world,
                    &capsule(),
                    p,
                    v(0.0, vy),
                    DT,
                    &QueryFilter::default(),
                )
                .unwrap();
            p = r.position;
            top = top.max(p.y);
            vy = if r.grounded { 0.0 } else { r.velocity.y } - G * DT;
        }
        if bits != 0 {
            let above = p.y - 2.1;
            println!(
                "one-way: highest {top:.3} (bound > 2.1), rests {above:.4} m above the ledge (bound 0..0.02)"
            );
            assert!(top > 2.1 && (0.0..0.02).contains(&above));
        } else {
            // A solid ledge: the head (1 m up) stops under it, y ≤ 0.9.
            println!(
                "solid ledge: highest {top:.4} (bound ≤ 0.9), ends on the floor at {:.4}",
                p.y
            );
            assert!(top <= 0.9 && p.y < 0.02);
        }
    }
}

#[test]
fn snaps_down_stairs_and_slopes() {
    // Three 0.15 m steps down (tops 0.45, 0.3, 0.15, 0), 1 m wide each,
    // then a 20° slope down from x = 3 to 5.
    let mut world = World::new(WorldDef::default()).unwrap();
    fixed(&mut world, v(-5.0, 0.4), Polygon::make_box(5.0, 0.05));
    for k in 0..3 {
        let top = 0.3 - 0.15 * k as Real;
        fixed(
            &mut world,
            v(0.5 + k as Real, top - 0.05),
            Polygon::make_box(0.5, 0.05),
        );
    }
    let t = (20.0 as Real).to_radians();
    let tri = Polygon::from_hull(&[v(0.0, 0.0), v(0.0, 2.0 * t.tan()), v(2.0, 0.0)], 0.0).unwrap();
    fixed(&mut world, v(3.0, -2.0 * t.tan()), tri);
    let mut cc = CharacterController::new();
    let run = walk(&world, &mut cc, v(-1.0, 0.46), 1.5, 200);
    let airborne = run.iter().filter(|r| !r.grounded).count();
    let snaps = run.iter().filter(|r| r.snapped).count();
    println!(
        "down 3 steps and a 20° slope at 1.5 m/s: {airborne} frames off the ground (bound 0), {snaps} snaps, end x = {:.3}",
        run.last().unwrap().position.x
    );
    assert_eq!(airborne, 0);
    assert!(snaps >= 3);
    // Off: the same walk leaves the ground at each step.
    let mut cc = CharacterController::new().with_snap_to_ground(None);
    let run = walk(&world, &mut cc, v(-1.0, 0.46), 1.5, 200);
    let airborne = run.iter().filter(|r| !r.grounded).count();
    println!("without snapping: {airborne} frames off the ground (bound > 0)");
    assert!(airborne > 0);
}

#[test]
fn cast_and_collide_mover_read_the_world() {
    let mut world = world_with_floor();
    let crate_body = world.create_body(&BodyDef::dynamic(v(3.0, 0.5))).unwrap();
    world
        .create_shape(
            crate_body,
            &ShapeDef::default(),
            Polygon::make_box(0.5, 0.5),
        )
        .unwrap();
    let mover = Capsule::new(v(0.0, 0.3), v(0.0, 0.8), 0.25).unwrap();
    let f = QueryFilter::default();
    // A dynamic box stops the cast at its face, x = 2.5, less the radius.
    let cast = world.cast_mover(&mover, v(10.0, 0.0), &f).unwrap();
    let x = cast.fraction * 10.0;
    println!("cast to a dynamic box: stops at {x:.5} (bound 2.249..2.25)");
    assert!((2.249..=2.25).contains(&x));
    assert_eq!(cast.hit.unwrap().body, crate_body);
    // Touching the floor (5 cm above it): moving along it is not stopped.
    let along = world.cast_mover(&mover, v(-3.0, 0.0), &f).unwrap();
    assert_eq!((along.fraction, along.hit), (1.0, None));
    // A filter that leaves the box out.
    let f2 = QueryFilter::default().excluding(crate_body);
    assert_eq!(
        world
            .cast_mover(&mover, v(10.0, 0.0), &f2)
            .unwrap()
            .fraction,
        1.0
    );
    // Planes: the floor within 6 cm.
    let mut planes: Vec<PlaneResult> = Vec::new();
    world
        .collide_mover(&mover, 0.06, &f, |p| {
            planes.push(*p);
            true
        })
        .unwrap();
    assert_eq!(planes.len(), 1);
    assert!((planes[0].separation - 0.05).abs() < 1e-4, "{planes:?}");
    let mut cp = [planes[0].plane(0.0)];
    let s = solve_planes(v(1.0, -1.0), &mut cp);
    assert!((s.translation - v(1.0, -0.05)).length() < 1e-4, "{s:?}");
}

#[test]
fn bad_mover_input_is_a_typed_error() {
    let world = world_with_floor();
    let f = QueryFilter::default();
    let mut cc = CharacterController::new();
    let nan = cc.move_and_slide(&world, &capsule(), v(Real::NAN, 0.0), Vec2::X, DT, &f);
    assert_eq!(nan, Err(WorldError::NonFinite("position")));
    let nanv = cc.move_and_slide(
        &world,
        &capsule(),
        Vec2::ZERO,
        v(0.0, Real::INFINITY),
        DT,
        &f,
    );
    assert_eq!(nanv, Err(WorldError::NonFinite("velocity")));
    let negative = Capsule {
        center1: Vec2::ZERO,
        center2: Vec2::Y,
        radius: -0.25,
    };
    let shape_err = WorldError::BadQuery {
        field: "mover",
        problem: QueryProblem::Shape(GeometryError::NonPositiveRadius),
    };
    assert_eq!(
        cc.move_and_slide(&world, &negative, Vec2::ZERO, Vec2::X, DT, &f),
        Err(shape_err.clone())
    );
    assert_eq!(
        world.cast_mover(&negative, Vec2::X, &f).map(|_| ()),
        Err(shape_err.clone())
    );
    assert_eq!(
        world.collide_mover(&negative, 0.0, &f, |_| true),
        Err(shape_err)
    );
    assert_eq!(
        cc.move_and_slide(&world, &capsule(), Vec2::ZERO, Vec2::X, 0.0, &f),
        Err(WorldError::InvalidTimeStep)
    );
    assert!(matches!(
        world.cast_mover(&capsule(), v(Real::NAN, 0.0), &f),
        Err(WorldError::BadQuery {
            field: "translation",
            ..
        })
    ));
    assert_eq!(
        world.collide_mover(&capsule(), -1.0, &f, |_| true),
        Err(WorldError::OutOfRange("margin"))
    );
    let mut steep = CharacterController::new().with_max_slope(2.0);
    assert_eq!(
        steep.move_and_slide(&world, &capsule(), Vec2::ZERO, Vec2::X, DT, &f),
        Err(WorldError::OutOfRange("max_slope"))
    );
    let mut nan_step = CharacterController::new().with_autostep(Some(Autostep {
        max_height: Real::NAN,
        min_width: 0.1,
    }));
    assert_eq!(
        nan_step.move_and_slide(&world, &capsule(), Vec2::ZERO, Vec2::X, DT, &f),
        Err(WorldError::OutOfRange("max_height"))
    );
}

#[test]
fn the_mover_is_deterministic() {
    let run = || {
        let mut world = world_with_floor();
        stair(&mut world, 0.2);
        let mut cc = CharacterController::new();
        walk(&world, &mut cc, v(0.0, 0.01), 2.5, 120)
            .iter()
            .map(|r| (r.position.x.to_bits(), r.position.y.to_bits()))
            .collect::<Vec<_>>()
    };
    assert_eq!(run(), run());
}
