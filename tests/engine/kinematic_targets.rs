//! `World::set_target_transform`: a kinematic platform driven to a target
//! each step carries what rests on it; a teleported one does not.
//! Set `JANUS2D_REPORT=1` to print the drifts.

use janus2d::prelude::*;

#[path = "../../examples/moving_platform.rs"]
#[allow(dead_code)]
mod moving_platform;

const DT: Real = 1.0 / 60.0;
const RADIUS: Real = 2.0;
const OMEGA: Real = 1.0; // rad/s: 2 m/s, centripetal 2 m/s² (< μ g = 6)

fn circle_point(t: Real) -> Vec2 {
    Vec2::new(RADIUS * (OMEGA * t).cos(), 5.0 + RADIUS * (OMEGA * t).sin())
}

/// A kinematic platform (half 2 × 0.2) at the start of the circle with a
/// 0.5 m box resting on it; returns (world, platform, box).
fn scene() -> (World, BodyHandle, BodyHandle) {
    let mut w = World::new(WorldDef::default()).unwrap();
    let start = circle_point(0.0);
    let platform = w.create_body(&BodyDef::kinematic(start)).unwrap();
    w.create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.2))
        .unwrap();
    let b = w
        .create_body(&BodyDef::dynamic(start + Vec2::new(0.0, 0.45)))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.25, 0.25))
        .unwrap();
    // Let the box settle on the resting platform.
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    (w, platform, b)
}

/// Drives the platform around the circle for `steps`; returns the largest
/// distance of the box from its start offset on the platform.
fn drive(w: &mut World, platform: BodyHandle, b: BodyHandle, steps: usize, teleport: bool) -> Real {
    let offset0 = w.position(b).unwrap() - w.position(platform).unwrap();
    let mut worst: Real = 0.0;
    for k in 1..=steps {
        let target = circle_point(k as Real * DT);
        if teleport {
            w.set_transform(platform, target, 0.0).unwrap();
        } else {
            w.set_target_transform(platform, Transform::new(target, 0.0), DT)
                .unwrap();
        }
        w.step(DT).unwrap();
        let p = w.position(platform).unwrap();
        if !teleport {
            assert!(
                (p - target).length() < 1e-3,
                "platform off target at {k}: {p:?} vs {target:?}"
            );
        }
        let offset = w.position(b).unwrap() - p;
        worst = worst.max((offset - offset0).length());
    }
    worst
}

#[test]
fn box_on_a_platform_driven_around_a_circle_stays_on_it() {
    let (mut w, platform, b) = scene();
    // Two full turns.
    let steps = (2.0 * janus2d::base::math::TAU / (OMEGA * DT)).ceil() as usize;
    let worst = drive(&mut w, platform, b, steps, false);
    if std::env::var("JANUS2D_REPORT").is_ok() {
        eprintln!("rider drift over two turns: {worst:.5} m");
    }
    assert!(worst < 0.01, "box drifted {worst} m on the platform");
    // The box moved with the platform: it went round the circle too.
    let v = w.linear_velocity(b).unwrap();
    assert!((v.length() - RADIUS * OMEGA).abs() < 0.2, "box speed {v:?}");
}

#[test]
fn teleporting_platform_leaves_the_box_behind() {
    // The regression set_target_transform guards: set_transform teleports.
    let (mut w, platform, b) = scene();
    let worst = drive(&mut w, platform, b, 120, true);
    if std::env::var("JANUS2D_REPORT").is_ok() {
        eprintln!("teleported rider drift: {worst:.5} m");
    }
    assert!(
        worst > 0.5,
        "teleported platform carried the box ({worst} m)"
    );
}

#[test]
fn target_transform_reaches_a_turned_target_and_rejects_bad_input() {
    let mut w = World::new(WorldDef::default()).unwrap();
    let k = w.create_body(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
    w.create_shape(
        k,
        &ShapeDef::default(),
        Polygon::make_offset_box(0.5, 0.2, Vec2::new(1.0, 0.0), 0.0),
    )
    .unwrap();
    let target = Transform::new(Vec2::new(0.3, -0.2), 1.2);
    w.set_target_transform(k, target, DT).unwrap();
    w.step(DT).unwrap();
    let xf = w.transform(k).unwrap();
    assert!((xf.p - target.p).length() < 1e-4, "{xf:?}");
    assert!((xf.q.angle() - 1.2).abs() < 1e-4, "{xf:?}");

    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let before = w.state_hash();
    assert_eq!(
        w.set_target_transform(ground, target, DT),
        Err(WorldError::NotMovable)
    );
    assert_eq!(
        w.set_target_transform(k, Transform::new(Vec2::new(Real::NAN, 0.0), 0.0), DT),
        Err(WorldError::NonFinite("target"))
    );
    assert_eq!(
        w.set_target_transform(k, target, 0.0),
        Err(WorldError::InvalidTimeStep)
    );
    assert_eq!(w.state_hash(), before);
}

#[test]
fn moving_platform_example_carries_its_rider() {
    let r = moving_platform::run().unwrap();
    assert_eq!(r.steps, 377);
    assert!(r.max_drift < 0.01, "rider drifted {} m", r.max_drift);
    assert!(
        r.max_platform_error < 1e-3,
        "platform {} m off",
        r.max_platform_error
    );
}
