//! Fast, grazing entries: a small box thrown at a floor portal at shallow
//! angles and high speeds, aimed across the aperture's width, crosses in
//! the step its motion takes it in (no speculative contact from the start
//! of the step stops it over a lip) and comes out at its entry speed, along
//! Q applied to its entry direction. Gravity is off so that the exit
//! velocity is exactly the mapped entry velocity.
//!
//! The CI grid is small; the full grid (angles 10° to 80°, speeds 5 to
//! 100 m/s, entry points across the feasible width) runs with
//! `cargo test --release --test portals -- --ignored portal_grazing::`.
//! Set `JANUS2D_REPORT=1` to print the worst errors.

use janus2d::prelude::*;
use janus2d::world::{PortalDef, PortalEvent, PortalPairDef};
use janus2d_testbed::support::{report, wall};

const DT: Real = 1.0 / 60.0;
/// Half-width of both apertures, m.
const W: Real = 1.5;
/// Half size of the thrown box, m.
const H: Real = 0.1;

/// The outcome of one throw.
#[derive(Debug)]
struct Throw {
    crossed: bool,
    speed_error: Real,
    angle_error_deg: Real,
}

/// Throws the box at `angle_deg` below the horizontal at `speed`, its
/// centre aimed at `x_c` on the floor plane; the floor portal (normal +y)
/// leads to a wall portal facing +x, so Q turns (c, −s) into (s, c).
fn throw(angle_deg: Real, speed: Real, x_c: Real) -> Throw {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    };
    let mut world = World::new(def).unwrap();
    let floor = wall(&mut world, Vec2::new(0.0, -0.5), 30.0, 0.5);
    let exit = wall(&mut world, Vec2::new(-60.0, 10.0), 0.5, 10.0);
    let at = |body, anchor, direction| PortalDef {
        body,
        anchor,
        direction,
        half_width: W,
    };
    world
        .create_portal_pair(&PortalPairDef::new(
            at(floor, Vec2::new(0.0, 0.5), Vec2::Y),
            at(exit, Vec2::new(0.5, 0.0), Vec2::X),
        ))
        .unwrap();
    let a = angle_deg.to_radians();
    let dir = Vec2::new(a.cos(), -a.sin());
    // Start a few steps of travel (at least 1.5 m) before the plane.
    let lead = (4.0 * speed * DT).max(1.5);
    let start = Vec2::new(x_c, 0.0) - dir * lead;
    let body = world
        .create_body(&BodyDef::dynamic(start).with_velocity(dir * speed))
        .unwrap();
    world
        .create_shape(body, &ShapeDef::default(), Polygon::make_box(H, H))
        .unwrap();
    let mut crossed = false;
    for _ in 0..40 {
        world.step(DT).unwrap();
        if world
            .events()
            .portals
            .iter()
            .any(|e| matches!(e, PortalEvent::CrossingCompleted { .. }))
        {
            crossed = true;
            break;
        }
        if world.crossing_count() == 0 && world.position(body).unwrap().y < -2.0 * H {
            break; // behind the floor without crossing
        }
    }
    // Through means out of the wall portal at x = −59.5, in front of it.
    crossed &= world.position(body).unwrap().x > -59.5;
    let v = world.linear_velocity(body).unwrap();
    let expected = Vec2::new(dir.y.abs(), dir.x); // Q (c, −s) = (s, c)
    let angle_error_deg = expected
        .perp_dot(v)
        .atan2(expected.dot(v))
        .to_degrees()
        .abs();
    Throw {
        crossed,
        speed_error: (v.length() - speed).abs() / speed,
        angle_error_deg,
    }
}

/// Entry points of the centre for which the whole box fits through the
/// aperture at `angle_deg` (the box never touches either lip), `n` of them
/// from one end of that range to the other.
fn entry_points(angle_deg: Real, n: usize) -> Vec<Real> {
    let cot = 1.0 / angle_deg.to_radians().tan();
    // A 1 cm margin keeps the box off the lips themselves.
    let reach = W - H * (1.0 + cot) - 0.01;
    assert!(reach > 0.0, "the box cannot fit at {angle_deg} deg");
    (0..n)
        .map(|k| -reach + 2.0 * reach * k as Real / (n - 1).max(1) as Real)
        .collect()
}

/// Runs the grid; panics with the failing throws, else returns the worst
/// speed and angle errors.
fn sweep(angles: &[Real], speeds: &[Real], points: usize) -> (Real, Real) {
    let (mut worst_speed, mut worst_angle) = (0.0 as Real, 0.0 as Real);
    let mut failures = Vec::new();
    for &angle in angles {
        for &speed in speeds {
            for x_c in entry_points(angle, points) {
                let t = throw(angle, speed, x_c);
                if !t.crossed || t.speed_error > 0.01 || t.angle_error_deg > 0.5 {
                    failures.push(format!("{angle} deg, {speed} m/s, x {x_c:.3}: {t:?}"));
                }
                if t.crossed {
                    worst_speed = worst_speed.max(t.speed_error);
                    worst_angle = worst_angle.max(t.angle_error_deg);
                }
            }
        }
    }
    if report() {
        eprintln!(
            "grazing sweep ({} angles × {} speeds × {points} points): worst speed error {:.4}%, worst angle error {:.4} deg, {} failures",
            angles.len(),
            speeds.len(),
            worst_speed * 100.0,
            worst_angle,
            failures.len()
        );
    }
    assert!(
        failures.is_empty(),
        "{} throws failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    (worst_speed, worst_angle)
}

/// CI grid: 10° and 30°, 20 and 100 m/s, three entry points.
#[test]
fn grazing_fast_entries_cross_at_their_speed_and_mapped_direction() {
    sweep(&[10.0, 30.0], &[20.0, 100.0], 3);
}

/// The full grid. Run with
/// `cargo test --release --test portals -- --ignored portal_grazing::`.
#[test]
#[ignore]
fn grazing_entries_full_grid() {
    sweep(
        &[10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 80.0],
        &[5.0, 10.0, 20.0, 40.0, 60.0, 80.0, 100.0],
        9,
    );
}

// The example keeps its name inside this module of the same name.
#[allow(dead_code, clippy::module_inception)]
#[path = "../../examples/portal_grazing.rs"]
mod portal_grazing;

/// The grazing example: through within a few steps, out within 1% of the
/// entry speed and 0.5° of the mapped direction.
#[test]
fn grazing_example_crosses_at_its_speed() {
    let r = portal_grazing::run().unwrap();
    let v = r.exit_velocity;
    let off = r
        .expected_direction
        .perp_dot(v)
        .atan2(r.expected_direction.dot(v))
        .to_degrees();
    assert!(r.crossed_at.is_some_and(|s| s < 10), "{:?}", r.crossed_at);
    assert!(
        (v.length() - r.entry_speed).abs() <= 0.01 * r.entry_speed,
        "{v}"
    );
    assert!(off.abs() <= 0.5, "{off} deg");
}
