//! A distance joint through a portal: two boxes joined by a rigid rod
//! fall into a floor portal and come out of a wall portal with η = 0.5
//! (and η = 1). When both ends have crossed, the world scales the joint's
//! anchors by η about each body's centre of mass, and the joint scales its
//! world-space lengths by η too (`DistanceJoint::carry_through_portal`): the rod
//! comes out η times as long and holds that length.
//!
//! The figure is the rod's worst length error `|gap − length|` over the
//! run, crossings included: the joint's two ends are always bodies on one
//! side (the originals on the entry side until both have crossed, then
//! the copies on the exit side), so the gap is a length in that side's
//! metres. Bound: 1 cm. The bodies fall freely (no load on the rod before or
//! after), so what is left is the crossing's transient: the rod is rigid
//! at the world's joint softness (60 Hz) and the rope of revolute links
//! through the same portals keeps its gaps through the map within 2 cm
//! under its own tension (`portal_joints.rs`); a free two-body rod must do
//! at least as well as one link of it.

use janus2d::prelude::*;
use janus2d::world::PortalEvent;
use janus2d_constraints::{DistanceJoint, DistanceJointDef};
use janus2d_testbed::portal_joints::jointed_portal_world;
use janus2d_testbed::support::report;

const DT: Real = 1.0 / 60.0;
const ROD: Real = 0.8;

struct Run {
    worst_error: Real,
    final_length: Real,
    def_length: Real,
    disabled: usize,
    out: bool,
}

fn rod_through(eta: Real) -> Run {
    let (mut world, _pair) = jointed_portal_world(eta);
    let make = |world: &mut World, y: Real| {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(20.0, y)).with_velocity(Vec2::new(0.0, -3.0)))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.2, 0.2))
            .unwrap();
        b
    };
    let (a, b) = (make(&mut world, 1.0), make(&mut world, 1.0 + ROD));
    let joint = world
        .create_joint(&DistanceJointDef::new(a, b, Vec2::ZERO, Vec2::ZERO, ROD).into())
        .unwrap();
    let mut r = Run {
        worst_error: 0.0,
        final_length: 0.0,
        def_length: 0.0,
        disabled: 0,
        out: false,
    };
    for _ in 0..240 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        r.disabled += world
            .events()
            .portals
            .iter()
            .filter(|e| matches!(e, PortalEvent::JointDisabled { .. }))
            .count();
        // The joint's two ends are always on one side (the world moves
        // both when both have crossed): its gap is a length in that
        // side's metres, during the crossings too.
        let length = world.joint_of::<DistanceJoint>(joint).unwrap().def().length;
        let gap = world.joint_gap(joint).unwrap();
        r.worst_error = r.worst_error.max((gap - length).abs());
        // Both out of the wall portal (x = −19.5, facing +x), no crossing.
        r.out |= world.crossing_count() == 0
            && [a, b].iter().all(|&h| world.position(h).unwrap().x < 0.0);
    }
    let j = world.joint_of::<DistanceJoint>(joint).unwrap();
    assert!(j.is_enabled());
    r.def_length = j.def().length;
    r.final_length = world.joint_gap(joint).unwrap();
    if report() {
        eprintln!(
            "distance rod η = {eta}: out {}, rest length {} (η · {ROD}), final length {}, worst error {:.3} mm, {} disabled",
            r.out,
            r.def_length,
            r.final_length,
            1e3 * r.worst_error,
            r.disabled
        );
    }
    r
}

fn check_rod(eta: Real) {
    let r = rod_through(eta);
    assert!(r.out, "the rod did not come out whole");
    assert_eq!(r.disabled, 0, "joint-disabled events");
    assert!(
        (r.def_length - eta * ROD).abs() <= 4.0 * Real::EPSILON * ROD,
        "rest length {} after the crossing, expected {}",
        r.def_length,
        eta * ROD
    );
    assert!(
        r.worst_error <= 0.01,
        "rod length error {} m (length {} vs {})",
        r.worst_error,
        r.final_length,
        r.def_length
    );
}

/// η = 0.5: the rod comes out half as long and holds it within 1 cm.
#[test]
fn distance_rod_through_a_half_scale_portal_keeps_its_scaled_length() {
    check_rod(0.5);
}

/// η = 1: the same rod, unscaled.
#[test]
fn distance_rod_through_a_portal_keeps_its_length() {
    check_rod(1.0);
}

/// η = 2: the rod comes out twice as long.
#[test]
fn distance_rod_through_a_double_scale_portal_keeps_its_scaled_length() {
    check_rod(2.0);
}
