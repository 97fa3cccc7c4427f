//! Apertures as geometry: a wall that carries a portal is held up by its
//! solid parts. A plank across an aperture rests, a box on the strip
//! between two close apertures rests, a box whose footprint is within the
//! aperture enters. Set `JANUS2D_REPORT=1` to print the figures.

use janus2d::base::geometry::LINEAR_SLOP;
use janus2d::prelude::*;
use janus2d::world::{PortalEvent, PortalPairDef};
use janus2d_testbed::support::{portal_def as portal, report, wall};

const DT: Real = 1.0 / 60.0;

fn dynamic_box(world: &mut World, pos: Vec2, hx: Real, hy: Real) -> BodyHandle {
    let b = world.create_body(&BodyDef::dynamic(pos)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(hx, hy))
        .unwrap();
    b
}

/// A floor 20 m wide with its top at y = 0 and a floor portal of
/// half-width `w` at each `x` of `apertures`, each linked to a wall portal
/// far away. Returns the world and the floor.
fn floor_with_apertures(apertures: &[Real], w: Real) -> (World, BodyHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let floor = wall(&mut world, Vec2::new(0.0, -0.5), 10.0, 0.5);
    for (k, &x) in apertures.iter().enumerate() {
        let exit = wall(
            &mut world,
            Vec2::new(-40.0 - 10.0 * k as Real, 5.0),
            0.5,
            5.0,
        );
        world
            .create_portal_pair(&PortalPairDef::new(
                portal(floor, Vec2::new(x, 0.5), Vec2::Y, w),
                portal(exit, Vec2::new(0.5, 0.0), Vec2::X, w),
            ))
            .unwrap();
    }
    (world, floor)
}

/// Depth of a body's lowest point below y = 0 (positive: sunk), m.
fn sink(world: &World, body: BodyHandle) -> Real {
    let xf = world.transform(body).unwrap();
    let mut low = Real::MAX;
    for s in world.body_shapes(body).unwrap() {
        let (lo, _) = world
            .shape(s)
            .unwrap()
            .geometry
            .support_extent(&xf, Vec2::Y);
        low = low.min(lo);
    }
    -low
}

/// Runs `steps`; returns the worst sink over the last half, the final
/// speed and whether any crossing started.
fn settle(world: &mut World, body: BodyHandle, steps: usize) -> (Real, Real, bool) {
    let (mut worst, mut started) = (0.0 as Real, false);
    for k in 0..steps {
        world.step(DT).unwrap();
        started |= world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::CrossingStarted { .. }));
        if k >= steps / 2 {
            worst = worst.max(sink(world, body));
        }
    }
    let speed = world.linear_velocity(body).unwrap().length();
    (worst, speed, started)
}

/// A 4 m plank whose left end lies 0.3 m over a 1 m aperture (its centre of
/// mass over solid floor) rests: held at its right end and at the lip.
#[test]
fn plank_with_one_end_over_an_aperture_rests() {
    let (mut world, _) = floor_with_apertures(&[0.0], 0.5);
    // Left end at x = −0.2, right end at x = 3.8.
    let plank = dynamic_box(&mut world, Vec2::new(1.8, 0.1 + 0.05), 2.0, 0.1);
    let (worst, speed, started) = settle(&mut world, plank, 240);
    let angle = world.angle(plank).unwrap();
    if report() {
        eprintln!(
            "plank, one end over the aperture: sink {:.2} mm, angle {angle:.5} rad, speed {speed:.5}",
            worst * 1000.0
        );
    }
    assert!(!started, "the plank began crossing");
    assert!(worst <= LINEAR_SLOP, "sink {worst} m");
    assert!(angle.abs() < 0.01, "tipped by {angle} rad");
    assert!(speed < 0.01, "still moving at {speed}");
}

/// A plank across the whole aperture (both ends on solid floor) rests,
/// dropped from 0.5 m.
#[test]
fn plank_across_an_aperture_rests() {
    let (mut world, _) = floor_with_apertures(&[0.0], 0.5);
    let plank = dynamic_box(&mut world, Vec2::new(0.3, 0.6), 2.0, 0.1);
    let (worst, speed, started) = settle(&mut world, plank, 240);
    if report() {
        eprintln!(
            "plank across the aperture: sink {:.2} mm, speed {speed:.5}",
            worst * 1000.0
        );
    }
    assert!(!started, "the plank began crossing");
    assert!(worst <= LINEAR_SLOP, "sink {worst} m");
    assert!(speed < 0.01);
}

/// A 1 m box on the 0.6 m strip between two floor apertures (each 1.8 m
/// wide) rests on the two lips.
#[test]
fn box_on_a_strip_between_two_portals_rests() {
    let (mut world, _) = floor_with_apertures(&[-1.2, 1.2], 0.9);
    let b = dynamic_box(&mut world, Vec2::new(0.0, 0.55), 0.5, 0.5);
    let (worst, speed, started) = settle(&mut world, b, 240);
    let x = world.position(b).unwrap().x;
    if report() {
        eprintln!(
            "box on the strip: sink {:.2} mm, drift {x:.5} m, speed {speed:.5}",
            worst * 1000.0
        );
    }
    assert!(!started, "the box began crossing");
    assert!(worst <= LINEAR_SLOP, "sink {worst} m");
    assert!(x.abs() < 0.01, "slid to {x}");
    assert!(speed < 0.01);
}

/// A 0.8 m box whose footprint is within a 1 m aperture falls in and
/// comes out of the wall portal.
#[test]
fn box_within_an_aperture_enters() {
    let (mut world, _) = floor_with_apertures(&[0.0], 0.5);
    let b = dynamic_box(&mut world, Vec2::new(0.05, 1.0), 0.4, 0.4);
    let mut completed = false;
    for _ in 0..120 {
        world.step(DT).unwrap();
        completed |= world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::CrossingCompleted { .. }));
        if completed {
            break;
        }
    }
    assert!(completed, "the box never went through");
    assert!(world.position(b).unwrap().x < -35.0, "not at the exit wall");
}

/// Reference: the same plank on a floor without portals sinks by the
/// solver's resting penetration (printed with the figures).
#[test]
fn plank_on_a_plain_floor_rests() {
    let (mut world, _) = floor_with_apertures(&[], 0.5);
    let plank = dynamic_box(&mut world, Vec2::new(1.8, 0.15), 2.0, 0.1);
    let (worst, speed, _) = settle(&mut world, plank, 240);
    if report() {
        eprintln!(
            "plank on a plain floor: sink {:.2} mm, speed {speed:.5}",
            worst * 1000.0
        );
    }
    assert!(worst <= LINEAR_SLOP, "sink {worst} m");
}

/// A body at two portals: a 3 m plank slides (no friction) along a floor
/// into a wall portal whose lower lip is at floor level; just in front of
/// the wall the floor has a second aperture (another pair), 1 m wide, from
/// x = −0.8 to 0.2 (it reaches under the wall). While
/// the plank crosses the wall portal its part left in front of the wall
/// lies wholly over the floor aperture: a body crosses one portal at a
/// time, so that aperture is solid floor to it and holds it (the plank
/// never sinks into it, never starts a second crossing), and it comes out
/// of the exit portal whole.
#[test]
fn body_at_two_portals_is_held_by_the_second_wall() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let floor = wall(&mut world, Vec2::new(0.0, -0.5), 10.0, 0.5);
    let entry_wall = wall(&mut world, Vec2::new(0.5, 5.0), 0.5, 5.0);
    let exit_wall = wall(&mut world, Vec2::new(30.5, 5.0), 0.5, 5.0);
    wall(&mut world, Vec2::new(41.0, -0.5), 10.0, 0.5); // the exit floor
    let far_wall = wall(&mut world, Vec2::new(-40.5, 5.0), 0.5, 5.0);
    world
        .create_portal_pair(&PortalPairDef::new(
            portal(entry_wall, Vec2::new(-0.5, -4.5), -Vec2::X, 0.6),
            portal(exit_wall, Vec2::new(0.5, -4.5), Vec2::X, 0.6),
        ))
        .unwrap();
    let second = world
        .create_portal_pair(&PortalPairDef::new(
            portal(floor, Vec2::new(-0.3, 0.5), Vec2::Y, 0.5),
            portal(far_wall, Vec2::new(0.5, 0.0), Vec2::X, 0.5),
        ))
        .unwrap();
    let plank = world
        .create_body(&BodyDef::dynamic(Vec2::new(-5.0, 0.15)).with_velocity(Vec2::new(4.0, 0.0)))
        .unwrap();
    world
        .create_shape(
            plank,
            &ShapeDef::default().with_friction(0.0),
            Polygon::make_box(1.5, 0.15),
        )
        .unwrap();
    let (mut worst, mut over_second, mut completed) = (0.0 as Real, 0, false);
    for _ in 0..240 {
        world.step(DT).unwrap();
        for e in &world.events().portals {
            match e {
                PortalEvent::CrossingStarted { pair, .. } => {
                    assert_ne!(*pair, second, "a second crossing started")
                }
                PortalEvent::CrossingCompleted { .. } => completed = true,
                _ => {}
            }
        }
        if world.crossing_count() > 0 {
            worst = worst.max(sink(&world, plank));
            let xf = world.transform(plank).unwrap();
            let s = world.body_shapes(plank).unwrap()[0];
            let (lo, _) = world
                .shape(s)
                .unwrap()
                .geometry
                .support_extent(&xf, Vec2::X);
            if lo > -0.8 {
                over_second += 1;
                // Held by the floor (the second wall) as solid: a touching
                // contact between the plank and the floor carries it.
                let held = world.contacts().any(|c| {
                    c.touching
                        && ((c.body_a == plank && c.body_b == floor)
                            || (c.body_a == floor && c.body_b == plank))
                });
                assert!(held, "not held by the floor over the second aperture");
            }
        }
        if completed {
            break;
        }
    }
    if report() {
        eprintln!(
            "two portals: worst sink over the second aperture {:.2} mm ({over_second} steps with only the aperture under it)",
            worst * 1000.0
        );
    }
    assert!(
        over_second > 3,
        "the scene never put the plank over the aperture alone"
    );
    assert!(completed, "the plank never came out");
    assert!(
        worst <= LINEAR_SLOP,
        "sank {worst} m into the second aperture"
    );
    // Half a second on, sliding on the exit floor at its speed.
    for _ in 0..30 {
        world.step(DT).unwrap();
    }
    let p = world.position(plank).unwrap();
    let v = world.linear_velocity(plank).unwrap();
    if report() {
        eprintln!("two portals: out at {p}, velocity {v}");
    }
    assert!(p.x > 31.0 && p.y.abs() < 0.3, "not out of the exit: {p}");
    assert!(
        (v.x - 4.0).abs() < 0.2 && v.y.abs() < 0.05,
        "exit velocity {v}"
    );
}

#[allow(dead_code)]
#[path = "../../examples/portal_plank.rs"]
mod portal_plank;

/// The plank example: the plank rests within the slop, level, never
/// crossing; the box beside it goes through and leaves the wall portal.
#[test]
fn plank_example_rests_and_the_box_goes_through() {
    let r = portal_plank::run().unwrap();
    assert!(r.plank_sink <= LINEAR_SLOP, "sink {}", r.plank_sink);
    assert!(r.plank_angle.abs() < 0.01, "angle {}", r.plank_angle);
    assert!(!r.plank_crossed);
    assert!(r.box_through);
    // Out of the wall portal (x = −29.5, facing +x) and fallen below it.
    assert!(
        r.box_end.x > -29.5 && r.box_end.y < -5.0,
        "box at {}",
        r.box_end
    );
}

/// A ball wider than the aperture (1.4 m across a 1 m aperture) has one
/// contact point, over the aperture: it rests on the two lips instead
/// (points where its footprint meets the lips), never starts a crossing.
#[test]
fn ball_wider_than_the_aperture_rests_on_the_lips() {
    let (mut world, _) = floor_with_apertures(&[0.0], 0.5);
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.05, 1.0)))
        .unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.7).unwrap(),
        )
        .unwrap();
    let (_, speed, started) = settle(&mut world, ball, 240);
    // Resting on the lip corners at x = ±0.5: centre at √(0.7² − 0.5²) up.
    let rest = (0.7 as Real * 0.7 - 0.25).sqrt();
    let p = world.position(ball).unwrap();
    if report() {
        eprintln!("wide ball: rests at {p} (on the lips: y = {rest:.4}), speed {speed:.5}");
    }
    assert!(!started, "the ball began crossing");
    assert!(speed < 0.01, "still moving at {speed}");
    assert!(
        p.y > rest - LINEAR_SLOP && p.y < rest + LINEAR_SLOP,
        "not on the lips: {p}"
    );
}

/// A ball that fits (0.8 m in a 1 m aperture) falls in.
#[test]
fn ball_within_the_aperture_enters() {
    let (mut world, _) = floor_with_apertures(&[0.0], 0.5);
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.05, 1.0)))
        .unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.4).unwrap(),
        )
        .unwrap();
    let mut completed = false;
    for _ in 0..120 {
        world.step(DT).unwrap();
        completed |= world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::CrossingCompleted { .. }));
        if completed {
            break;
        }
    }
    assert!(completed, "the ball never went through");
    assert!(
        world.position(ball).unwrap().x < -35.0,
        "not at the exit wall"
    );
}
