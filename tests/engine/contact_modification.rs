//! Contact modification: the pre-solve hook changes a contact's friction,
//! restitution and tangent speed for the step (or leaves it out), and the
//! custom pair filter keeps pairs from colliding.

use janus2d::prelude::*;
use janus2d_testbed::scenes::{self, DT};

fn world() -> World {
    World::new(scenes::shared_settings()).unwrap()
}

/// A static ground box of half width 50 whose top is at y = 0.
fn ground(world: &mut World) -> ShapeHandle {
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(50.0, 0.5))
        .unwrap()
}

/// A unit box at rest on the ground, pushed along +x by 3 N (friction 0.6
/// on 1 kg holds up to 5.9 N).
fn pushed_box(world: &mut World) -> BodyHandle {
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    b
}

fn push_for(world: &mut World, b: BodyHandle, steps: usize) {
    for _ in 0..steps {
        world.apply_force_to_center(b, Vec2::new(3.0, 0.0)).unwrap();
        world.step(DT).unwrap();
    }
}

/// Pushed with 3 N, a 1 kg box on ground of friction 0.6 sticks (it moves
/// less than 1 mm in a second); with a hook that sets the contact's
/// friction to 0 it slides off at a = F / m = 3 m/s² (v = 3 ± 0.1 m/s
/// after a second).
#[test]
fn a_hook_that_sets_friction_zero_lets_a_box_slide() {
    let mut w = world();
    ground(&mut w);
    let b = pushed_box(&mut w);
    push_for(&mut w, b, 60);
    assert!(w.position(b).unwrap().x.abs() < 1e-3, "sticks");
    w.set_pre_solve(Some(Box::new(|c| {
        c.friction = 0.0;
        true
    })));
    push_for(&mut w, b, 60);
    let v = w.linear_velocity(b).unwrap().x;
    assert!((v - 3.0).abs() < 0.1, "slides: {v}");
    // The contact's own friction is untouched (the hook's is per step).
    assert!((w.contacts().next().unwrap().friction - 0.6).abs() < 1e-6);
}

/// A hook that sets restitution 1 for one step bounces a falling ball
/// back to nearly the height it fell from; the tangent speed of the hook
/// carries a box as a belt does (2 ± 0.05 m/s).
#[test]
fn a_hook_sets_restitution_and_tangent_speed() {
    let mut w = world();
    ground(&mut w);
    let ball = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.5)))
        .unwrap();
    w.create_shape(
        ball,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    w.set_pre_solve(Some(Box::new(|c| {
        c.restitution = 1.0;
        true
    })));
    let mut peak_after_bounce = Real::MIN;
    let mut bounced = false;
    for _ in 0..120 {
        w.step(DT).unwrap();
        let v = w.linear_velocity(ball).unwrap().y;
        bounced |= v > 1.0;
        if bounced {
            peak_after_bounce = peak_after_bounce.max(w.position(ball).unwrap().y);
        }
    }
    assert!(bounced);
    assert!(
        peak_after_bounce > 2.3,
        "bounced back up to {peak_after_bounce}"
    );

    let mut w = world();
    let floor = ground(&mut w);
    let b = pushed_box(&mut w);
    w.set_pre_solve(Some(Box::new(move |c| {
        if c.shape_a == floor || c.shape_b == floor {
            // The floor's surface moving clockwise round it at 2 m/s
            // (whichever shape is a: `mix_tangent_speed`'s sign rule).
            c.tangent_speed = 2.0;
        }
        true
    })));
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let v = w.linear_velocity(b).unwrap().x;
    assert!((v - 2.0).abs() < 0.05, "carried at {v}");
}

#[allow(dead_code)]
#[path = "../../examples/one_way_platform.rs"]
mod one_way_platform;

/// The one-way platform through the hook: a box thrown up from below
/// passes through the platform (its peak is above the top), then lands
/// and stays on it: over the last second its centre stays within 1 cm of
/// resting height (half its size above the top).
#[test]
fn a_hook_that_disables_one_side_makes_a_one_way_platform() {
    let r = one_way_platform::run().unwrap();
    let rest = r.platform_top + 0.25;
    assert!(r.peak > r.platform_top + 0.5, "rose through: {}", r.peak);
    assert!(
        r.last_second.iter().all(|y| (y - rest).abs() < 0.01),
        "stays on top: {:?} .. {:?}",
        r.last_second.iter().copied().fold(Real::MAX, Real::min),
        r.last_second.iter().copied().fold(Real::MIN, Real::max)
    );
}

/// The pair filter keeps a box from colliding with the floor: it falls
/// through, neither shape reports a contact, and no contact begins; with
/// the filter removed and the box placed above the floor again, it lands.
#[test]
fn the_pair_filter_stops_a_pair_colliding() {
    let mut w = world();
    let floor = ground(&mut w);
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0)))
        .unwrap();
    let ghost = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let asked = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let count = asked.clone();
    w.set_pair_filter(Some(Box::new(move |a, b| {
        count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        !((a == floor && b == ghost) || (a == ghost && b == floor))
    })));
    let mut began = 0;
    for _ in 0..60 {
        w.step(DT).unwrap();
        began += w.events().collision.contact_begin.len();
        assert_eq!(w.shape_contacts(ghost).unwrap().count(), 0);
        assert_eq!(w.shape_contacts(floor).unwrap().count(), 0);
    }
    assert_eq!(began, 0);
    assert_eq!(w.contact_count(), 0);
    assert!(asked.load(std::sync::atomic::Ordering::Relaxed) > 0);
    assert!(w.position(b).unwrap().y < -2.0, "fell through");
    w.set_pair_filter(None);
    w.set_transform(b, Vec2::new(0.0, 1.0), 0.0).unwrap();
    w.set_linear_velocity(b, Vec2::ZERO).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!((w.position(b).unwrap().y - 0.5).abs() < 0.02, "lands");
    assert_eq!(w.validate(), Ok(()));
}

/// Hook answers that are not finite change nothing; the hooks survive a
/// restore (they are not state) and a snapshot holds none.
#[test]
fn bad_hook_values_are_ignored_and_hooks_survive_restore() {
    let mut w = world();
    ground(&mut w);
    let b = pushed_box(&mut w);
    w.set_pre_solve(Some(Box::new(|c| {
        c.friction = Real::NAN;
        c.tangent_speed = Real::INFINITY;
        true
    })));
    let saved = w.snapshot();
    push_for(&mut w, b, 60);
    assert!(w.position(b).unwrap().x.abs() < 1e-3, "friction kept");
    w.set_pre_solve(Some(Box::new(|c| {
        c.friction = 0.0;
        true
    })));
    w.restore(&saved);
    push_for(&mut w, b, 60);
    assert!(w.linear_velocity(b).unwrap().x > 2.9, "the hook stayed");
}

#[allow(dead_code)]
#[path = "../../examples/conveyor.rs"]
mod conveyor;

/// The conveyor example: the material belt carries its box at 2 ± 0.05
/// m/s, the hooked belt at −1 ± 0.05 m/s and, once the hook stops it,
/// not at all (friction brings the box to rest within 0.05 m/s); the ball
/// with rolling resistance has stopped.
#[test]
fn the_conveyor_example_moves_boxes_at_the_belt_speeds() {
    let r = conveyor::run().unwrap();
    assert!((r.material_belt - 2.0).abs() < 0.05, "{}", r.material_belt);
    assert!(
        (r.hooked_belt_on + 1.0).abs() < 0.05,
        "{}",
        r.hooked_belt_on
    );
    assert!(r.hooked_belt_off.abs() < 0.05, "{}", r.hooked_belt_off);
    assert!(
        r.ball_speed.abs() < 0.01 && r.ball_distance > 5.0,
        "{} {}",
        r.ball_speed,
        r.ball_distance
    );
}
