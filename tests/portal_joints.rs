//! Joints through portals: a rope of 20 revolute links poured through a
//! floor portal comes out of a wall portal whole, with η = 1 and η = 2, and
//! a ragdoll thrown through a portal keeps its joints; every joint's gap is
//! measured through the portal map
//! (`janus2d_testbed::portal_joints::gap_through_map`). Set
//! `JANUS2D_REPORT=1` to print the figures.
#![cfg(feature = "portals")]

use janus2d::prelude::*;
use janus2d::world::{PortalEvent, PortalPairHandle};
use janus2d_testbed::portal_joints::{
    EXIT_FACE_X, gap_through_map, jointed_portal_world, ragdoll, rope,
};
use janus2d_testbed::support::report;

const DT: Real = 1.0 / 60.0;

/// What a run through the portal measured.
#[derive(Debug, Default)]
struct Run {
    worst_gap: Real,
    disabled: usize,
    steps_to_through: Option<usize>,
}

/// Steps `world` for `steps` steps, measuring every joint's gap through the
/// map after each step and counting disabled-joint events; `through` says
/// when the object is wholly through.
fn run(
    world: &mut World,
    pair: PortalPairHandle,
    joints: &[JointHandle],
    steps: usize,
    through: impl Fn(&World) -> bool,
) -> Run {
    let mut r = Run::default();
    for step in 0..steps {
        world.step(DT).unwrap();
        r.disabled += world
            .portal_events()
            .iter()
            .filter(|e| matches!(e, PortalEvent::JointDisabled { .. }))
            .count();
        for &j in joints {
            r.worst_gap = r.worst_gap.max(gap_through_map(world, j, pair));
        }
        if r.steps_to_through.is_none() && through(world) {
            r.steps_to_through = Some(step + 1);
        }
    }
    r
}

fn rope_through(eta: Real) -> (Run, Real) {
    let (mut world, pair) = jointed_portal_world(eta);
    let (links, joints) = rope(&mut world, 20);
    let all_out = |w: &World| {
        w.crossing_count() == 0 && links.iter().all(|&b| w.position(b).unwrap().x < 0.0)
    };
    let r = run(&mut world, pair, &joints, 300, all_out);
    let first_x = world.position(links[0]).unwrap().x;
    if report() {
        eprintln!(
            "rope η = {eta}: worst gap through the map {:.2} mm, {} disabled, all 20 links out after {:?} steps, first link at x = {first_x:.2}",
            1e3 * r.worst_gap,
            r.disabled,
            r.steps_to_through
        );
    }
    for &j in &joints {
        assert!(world.revolute_joint(j).unwrap().enabled, "a joint was disabled");
    }
    (r, first_x)
}

fn check_rope(eta: Real) {
    let (r, first_x) = rope_through(eta);
    assert_eq!(r.disabled, 0, "joint-disabled events");
    assert!(r.steps_to_through.is_some(), "the rope did not come out whole");
    assert!(
        first_x > EXIT_FACE_X + 1.0,
        "the first link is at x = {first_x}, not beyond the exit portal"
    );
    assert!(r.worst_gap <= 0.02, "worst gap through the map {} m", r.worst_gap);
}

/// A rope of 20 links poured through a floor portal comes out of a wall
/// portal whole (η = 1): no joint disabled, every gap through the map ≤ 2 cm.
#[test]
fn rope_of_twenty_links_comes_out_whole_eta_1() {
    check_rope(1.0);
}

/// The same rope through a pair with η = 2 (the links come out twice as long).
#[test]
fn rope_of_twenty_links_comes_out_whole_eta_2() {
    check_rope(2.0);
}

/// A ragdoll (torso, head, two arms, two legs) thrown spinning into a floor
/// portal comes out of the wall portal with its joints: no joint disabled,
/// worst gap through the map ≤ 2 cm, every part on the exit side after.
#[test]
fn ragdoll_thrown_through_a_portal_keeps_its_joints() {
    let (mut world, pair) = jointed_portal_world(1.0);
    let (parts, joints) = ragdoll(&mut world, Vec2::new(19.5, 3.0), Vec2::new(0.5, -6.0), 1.5);
    let all_out = |w: &World| {
        w.crossing_count() == 0 && parts.iter().all(|&b| w.position(b).unwrap().x < 0.0)
    };
    let r = run(&mut world, pair, &joints, 240, all_out);
    if report() {
        eprintln!(
            "ragdoll: worst gap through the map {:.2} mm, {} disabled, all parts out after {:?} steps",
            1e3 * r.worst_gap,
            r.disabled,
            r.steps_to_through
        );
    }
    assert_eq!(r.disabled, 0, "joint-disabled events");
    assert!(r.steps_to_through.is_some(), "the ragdoll did not come out whole");
    assert!(r.worst_gap <= 0.02, "worst gap through the map {} m", r.worst_gap);
}
