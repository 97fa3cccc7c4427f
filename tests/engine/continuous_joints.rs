//! Continuous collision keeps joints: a fast jointed body moved back to its
//! time of impact takes the bodies its joints reach back with it, so its
//! joints stay as the solve left them (issue "Stable at half the cost",
//! item 4).
//!
//! The rope: 20 links (0.1 m × 0.5 m boxes at the default density) hinged
//! end to end along a 30° slope, its low end 1 m above a static floor,
//! thrown down at 30 m/s (half a metre a step at 60 Hz, more than a
//! link's half width: every link is fast), 1 s; the links land one after
//! the other. The bound: every joint's gap at every step ≤ 1 cm.
//! Measured: 9.8 mm (f32 and f64), in a landing step in which nothing
//! moved back (a link stopped mid-step by its speculative contact: the
//! solve's own gap, 9–10.3 mm over variants of the closing); the steps
//! that move the rope back end within 0.8 mm, since the hinges are closed
//! after the move. The same rope without continuous collision reads 19 mm
//! (its links land a step later and harder). Before the group move back,
//! each landing link was moved back alone and its joints opened by what
//! its neighbours travelled after the impact: 59 mm; with the group move
//! back but no closing, 7.7 mm in the steps that moved it back.

use janus2d::prelude::*;

const LINKS: usize = 20;

/// The worst joint gap over the run, m, and the links' lowest point's
/// height at the end (above the floor's top at 0), m.
fn rope_drop(continuous: bool, speed: Real) -> (Real, Real) {
    let mut world = World::new(WorldDef {
        enable_continuous: continuous,
        ..WorldDef::default()
    })
    .unwrap();
    let floor = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(floor, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))
        .unwrap();
    let half = 0.25;
    let mut links: Vec<BodyHandle> = Vec::new();
    let mut joints = Vec::new();
    // Along a 30° slope, each link turned to lie along it: the low end
    // lands first and the rest follow link by link.
    let slope: Real = 30.0_f64.to_radians() as Real;
    let along = Vec2::new(-slope.cos(), slope.sin());
    for i in 0..LINKS {
        let at = Vec2::new(0.0, 1.0) + (2.0 * half * i as Real) * along;
        let b = world
            .create_body(
                &BodyDef::dynamic(at)
                    .with_angle(std::f64::consts::FRAC_PI_2 as Real - slope)
                    .with_velocity(Vec2::new(0.0, -speed)),
            )
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.05, half))
            .unwrap();
        if let Some(&prev) = links.last() {
            // The links' local y axes point up the slope: the next link
            // hangs at the previous one's +y end.
            let def = RevoluteJointDef::new(prev, b, Vec2::new(0.0, half), Vec2::new(0.0, -half));
            joints.push(world.create_joint(&def.into()).unwrap());
        }
        links.push(b);
    }
    let mut worst: Real = 0.0;
    for _ in 0..60 {
        world.step(1.0 / 60.0).unwrap();
        for &j in &joints {
            worst = worst.max(world.joint_gap(j).unwrap());
        }
    }
    let lowest = links
        .iter()
        .map(|&b| world.position(b).unwrap().y)
        .fold(Real::MAX, Real::min);
    (worst, lowest)
}

#[test]
fn a_rope_thrown_onto_the_floor_keeps_its_joints_with_continuous_collision() {
    let (on, lowest) = rope_drop(true, 30.0);
    let (off, lowest_off) = rope_drop(false, 30.0);
    if janus2d_testbed::support::report() {
        eprintln!(
            "rope at 30 m/s: worst gap {on:.3e} m with continuous collision ({lowest:.3} m lowest), \
             {off:.3e} m without ({lowest_off:.3} m lowest)"
        );
    }
    assert!(
        on <= 0.01,
        "worst joint gap {on} m with continuous collision"
    );
    // The links rest on the floor (centres 5 cm above it), not through it.
    assert!(lowest > 0.0, "a link ended at y = {lowest}");
}
