//! The character controller through portals (issue 32, deliverable 1):
//! a character that walks into a wall portal comes out of its partner
//! scaled by η and moving η times as fast; one that falls into a floor
//! portal comes out of a wall portal moving sideways; the wall around an
//! aperture and its lips still stop it, and what lies in front of the
//! partner portal stops the part of it that has gone in. Each test prints
//! its measured figure beside its bound.

use janus2d::prelude::*;
use janus2d::{MoveResult, PortalDef, PortalPairDef};

const DT: Real = 1.0 / 60.0;
const G: Real = 10.0;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

/// A capsule 1 m tall, radius 0.25, its bottom at the reference point.
fn capsule() -> Capsule {
    Capsule::new(v(0.0, 0.25), v(0.0, 0.75), 0.25).unwrap()
}

fn fixed(world: &mut World, at: Vec2, half: Vec2) -> BodyHandle {
    let b = world.create_body(&BodyDef::fixed(at)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(half.x, half.y))
        .unwrap();
    b
}

/// A floor (top y = 0, x from −30 to 30); wall A on the right (face x = 5)
/// with an aperture from y = −0.2 to 2.2 (centre (5, 1), w = 1.2, facing
/// −x); wall B on the left (face x = −20) with its partner from y = 0.1 to
/// 4.9 (centre (−20, 2.5), w = 2.4, facing +x): η = 2, Q = identity. A
/// character walking on the floor at A comes out of B with its feet
/// 0.52 m up (2.5 + 2 (0.01 − 1)), beyond what it snaps down.
fn wall_to_wall() -> World {
    let mut w = World::new(WorldDef::default()).unwrap();
    fixed(&mut w, v(0.0, -0.5), v(30.0, 0.5));
    let a = fixed(&mut w, v(5.5, 2.5), v(0.5, 3.5));
    let b = fixed(&mut w, v(-20.5, 2.5), v(0.5, 3.5));
    w.create_portal_pair(&PortalPairDef::new(
        PortalDef::new(a, v(-0.5, -1.5), -Vec2::X, 1.2),
        PortalDef::new(b, v(0.5, 0.0), Vec2::X, 2.4),
    ))
    .unwrap();
    w
}

/// `T(x)` of the wall-to-wall pair.
fn t_wall(x: Vec2) -> Vec2 {
    v(-20.0, 2.5) + 2.0 * (x - v(5.0, 1.0))
}

/// One move of the game loop: the capsule and velocity the last move
/// returned, gravity added.
fn step(
    w: &World,
    cc: &mut CharacterController,
    capsule: &Capsule,
    p: Vec2,
    vel: Vec2,
    filter: &QueryFilter,
) -> MoveResult {
    cc.move_and_slide(w, capsule, p, vel - v(0.0, G * DT), DT, filter)
        .unwrap()
}

#[test]
fn walking_into_a_wall_portal_comes_out_of_the_other_scaled_by_eta() {
    let w = wall_to_wall();
    let through = QueryFilter::default().through_portals();
    let mut cc = CharacterController::new();
    let (mut cap, mut p, mut vel) = (capsule(), v(2.0, 0.01), v(3.0, 0.0));
    let mut crossed = None;
    for i in 0..200 {
        let r = step(&w, &mut cc, &cap, p, vel, &through);
        if !r.crossings.is_empty() {
            crossed = Some((i, p, r));
            break;
        }
        assert!(
            r.grounded,
            "walking on the floor before the portal (step {i})"
        );
        (cap, p, vel) = (r.capsule, r.position, r.velocity);
    }
    let (i, before, r) = crossed.expect("the character crossed the portal");
    // The step that crossed: the centre (before + (0, 0.5)) reaches x = 5 at
    // u of the step's 3·dt, the rest goes on at twice the speed. The
    // velocity given, (3, −g·dt), comes out as 2 (3, −g·dt), less its
    // downward part if it still stands on the near floor (seen through the
    // portal by the part of it not yet out).
    let d = 3.0 * DT;
    let u = (5.0 - before.x) / d;
    let centre = before + v(u * d, 0.5);
    let expected = t_wall(centre) - 2.0 * v(0.0, 0.5) + v(2.0 * (1.0 - u) * d, 0.0);
    let err = (r.position - expected).length();
    let out_velocity = if r.grounded {
        v(6.0, 0.0)
    } else {
        v(6.0, -2.0 * G * DT)
    };
    let speed_err = (r.velocity - out_velocity).length() / out_velocity.length();
    println!(
        "crossed at step {i}: position {} (mapped {expected}, error {err:.2e} m, bound 0.01), \
         velocity {} (mapped {out_velocity}, error {:.2}%, bound 1%), scale {}",
        r.position,
        r.velocity,
        100.0 * speed_err,
        r.scale
    );
    assert_eq!(r.crossings.len(), 1);
    assert_eq!(
        (r.crossings[0].entered, r.crossings[0].bodies.len()),
        (0, 2)
    );
    assert!(err < 0.01, "{err}");
    assert!(speed_err < 0.01, "{speed_err}");
    assert!((r.scale - 2.0).abs() < 1e-5 && (r.capsule.radius - 0.5).abs() < 1e-5);
    assert!((r.capsule.center2 - r.capsule.center1 - v(0.0, 1.0)).length() < 1e-5);
    // It goes on at 6 m/s: out of the aperture, down its 0.52 m, and along
    // the floor of the far room.
    (cap, p, vel) = (r.capsule, r.position, r.velocity);
    let mut last = None;
    for _ in 0..60 {
        let r = step(&w, &mut cc, &cap, p, vel, &through);
        assert!(r.crossings.is_empty(), "no second crossing");
        (cap, p, vel) = (r.capsule, r.position, r.velocity);
        last = Some(r);
    }
    let r = last.unwrap();
    let speed_err = (r.velocity.x - 6.0).abs() / 6.0;
    println!(
        "a second later: at {}, grounded {}, vx {} (bound 6 ± 1%)",
        r.position, r.grounded, r.velocity.x
    );
    assert!(r.grounded && r.position.y.abs() < 0.03, "{r:?}");
    assert!(speed_err < 0.01, "{speed_err}");
    assert!(r.position.x > -20.0 + 4.5, "{}", r.position.x);
}

#[test]
fn falling_through_a_floor_portal_comes_out_of_a_wall_portal() {
    // A floor (top y = 0, x from 5 to 15) with an aperture at (10, 0) (w =
    // 0.6, facing up); its partner on the left wall (face x = −20, centre (−20, 2),
    // facing +x): η = 1, Q = R(90°) takes the fall (0, −1) to (1, 0).
    let mut w = World::new(WorldDef::default()).unwrap();
    let floor = fixed(&mut w, v(10.0, -0.5), v(5.0, 0.5));
    let wall = fixed(&mut w, v(-20.5, 3.0), v(0.5, 3.0));
    fixed(&mut w, v(-10.0, -0.5), v(10.0, 0.5)); // the far room's floor
    w.create_portal_pair(&PortalPairDef::new(
        PortalDef::new(floor, v(0.0, 0.5), Vec2::Y, 0.6),
        PortalDef::new(wall, v(0.5, -1.0), Vec2::X, 0.6),
    ))
    .unwrap();
    let through = QueryFilter::default().through_portals();
    let mut cc = CharacterController::new();
    let (mut cap, mut p, mut vel) = (capsule(), v(10.0, 2.0), Vec2::ZERO);
    let mut crossed = None;
    for i in 0..200 {
        let r = step(&w, &mut cc, &cap, p, vel, &through);
        if !r.crossings.is_empty() {
            crossed = Some((i, p, vel - v(0.0, G * DT), r));
            break;
        }
        assert!(
            !r.grounded,
            "the floor is open over the aperture (step {i})"
        );
        (cap, p, vel) = (r.capsule, r.position, r.velocity);
    }
    let (i, before, fall, r) = crossed.expect("the character fell through");
    // The centre (before + (0, 0.5)) reaches y = 0 at u of the step's fall;
    // it comes out at T = (−20, 2) + Q (x − (10, 0)) and the rest of the fall
    // goes on along +x.
    let d = fall.y * DT;
    let u = (before.y + 0.5) / -d;
    let centre = before + v(0.0, 0.5 + u * d);
    let q = |x: Vec2| v(-x.y, x.x);
    let expected =
        v(-20.0, 2.0) + q(centre - v(10.0, 0.0)) - v(0.0, 0.5) + q(v(0.0, (1.0 - u) * d));
    let err = (r.position - expected).length();
    let speed = -fall.y;
    let speed_err = (r.velocity - v(speed, 0.0)).length() / speed;
    println!(
        "crossed at step {i}, falling at {speed:.3} m/s: position {} (mapped {expected}, \
         error {err:.2e} m, bound 0.01), velocity {} (error {:.3}%, bound 1%)",
        r.position,
        r.velocity,
        100.0 * speed_err
    );
    assert_eq!(r.crossings.len(), 1);
    assert!(err < 0.01, "{err}");
    assert!(speed_err < 0.01, "{speed_err}");
    assert!((r.scale - 1.0).abs() < 1e-6 && (r.capsule.radius - 0.25).abs() < 1e-6);
    assert!(r.velocity.x > 3.0, "it leaves the wall moving out of it");
    // It flies out of the wall and lands on the far room's floor.
    (cap, p, vel) = (r.capsule, r.position, r.velocity);
    for _ in 0..120 {
        let r = step(&w, &mut cc, &cap, p, vel, &through);
        (cap, p, vel) = (r.capsule, r.position, r.velocity);
    }
    println!("two seconds later at {p}");
    assert!(
        p.x > -20.0 + 1.0 && p.y.abs() < 0.03,
        "landed in front of the wall: {p}"
    );
}

#[test]
fn the_wall_around_an_aperture_and_its_lips_stop_the_character() {
    let w = wall_to_wall();
    let through = QueryFilter::default().through_portals();
    let mut cc = CharacterController::new();
    // Stopped at the face x = 5 less its radius and skin: x = 4.74.
    let stop: Real = 5.0 - 0.25 - cc.skin;
    for (start_y, what) in [
        (3.0, "above the aperture (y 3 to 4)"),
        (1.8, "across the top lip (y 1.8 to 2.8)"),
    ] {
        let mut p = v(3.0, start_y);
        let mut crossings = 0;
        for _ in 0..60 {
            let r = cc
                .move_and_slide(&w, &capsule(), p, v(3.0, 0.0), DT, &through)
                .unwrap();
            crossings += r.crossings.len();
            p = r.position;
        }
        println!("{what}: stopped at x = {} (bound {stop} ± 1e-3)", p.x);
        assert_eq!(crossings, 0, "{what}");
        assert!((p.x - stop).abs() < 1e-3, "{what}: {}", p.x);
    }
    // Without through_portals the aperture is a wall too.
    let mut p = v(3.0, 0.01);
    for _ in 0..60 {
        let r = cc
            .move_and_slide(
                &w,
                &capsule(),
                p,
                v(3.0, -G * DT),
                DT,
                &QueryFilter::default(),
            )
            .unwrap();
        assert!(r.crossings.is_empty());
        p = r.position;
    }
    println!("portals off: stopped at x = {} (bound {stop} ± 1e-3)", p.x);
    assert!((p.x - stop).abs() < 1e-3, "{}", p.x);
}

#[test]
fn what_stands_in_front_of_the_partner_stops_the_part_that_went_in() {
    // A block 0.3 m in front of the exit (x from −19.7 to −19): the part of
    // the character past x = 5 appears twice as large past x = −20, so the
    // character (radius 0.25 + skin) stops when 2 (x + 0.26 − 5) = 0.3,
    // its centre at x = 4.89, before it crosses.
    let mut w = wall_to_wall();
    let block = fixed(&mut w, v(-19.35, 2.0), v(0.35, 2.0));
    let through = QueryFilter::default().through_portals();
    let mut cc = CharacterController::new();
    let mut p = v(3.0, 0.01);
    let mut last = None;
    for _ in 0..90 {
        let r = cc
            .move_and_slide(&w, &capsule(), p, v(3.0, -G * DT), DT, &through)
            .unwrap();
        assert!(r.crossings.is_empty(), "the block keeps it from crossing");
        p = r.position;
        last = Some(r);
    }
    let r = last.unwrap();
    let expected = 5.0 - 0.26 + 0.15;
    println!(
        "stopped at x = {} (bound {expected} ± 2e-3), velocity {}",
        p.x, r.velocity
    );
    assert!((p.x - expected).abs() < 2e-3, "{}", p.x);
    assert!(
        r.contacts
            .iter()
            .any(|c| c.body == block && c.normal.x < -0.99),
        "the block is among what it touches, its normal mapped back: {:?}",
        r.contacts
    );
    assert!(
        r.velocity.x.abs() < 1e-3,
        "the walk is clipped: {}",
        r.velocity
    );
}
