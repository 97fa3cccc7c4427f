//! A weld-joined pair through a portal: the two boxes of the prismatic
//! test (`portal_prismatic.rs`), welded rigidly at their facing sides'
//! centres, fall into the floor portal of
//! `janus2d_testbed::portal_joints::jointed_portal_world` and come out of
//! the wall portal at η = 0.5, the exit turned a quarter turn. The weld
//! follows them (re-pointed to the exit copies, its point impulse turned
//! and scaled by 1/η, its angle impulse kept) and keeps holding, in the
//! tree solve and in Gauss–Seidel: its gap and angle error stay bounded.
//!
//! The bound: 1 mm of gap, as the hinged pair's in `portal_joints.rs`
//! and the prismatic pair's here; 2 mrad of angle (a 1 mm slip over the
//! boxes' 0.4 m half height is 2.5 mrad). `JANUS2D_REPORT=1` prints the
//! figures.

use janus2d::prelude::*;
use janus2d::world::PortalEvent;
use janus2d_testbed::portal_joints::jointed_portal_world;
use janus2d_testbed::support::report;

use super::portal_prismatic::{ETA, falling_pair};

/// Worst gap (m) and angle error (rad) over 2.5 s, joint-disabled events,
/// crossings completed.
fn weld_through(direct_joints: bool) -> (Real, Real, usize, usize) {
    let (mut world, _) = jointed_portal_world(ETA);
    let mut settings = world.settings().clone();
    settings.direct_joints = direct_joints;
    world.set_settings(settings).unwrap();
    let (lower, upper) = falling_pair(&mut world);
    let def = WeldJointDef::new(lower, upper, Vec2::new(0.0, 0.4), Vec2::new(0.0, -0.4));
    let joint = world.create_joint(&def.into()).unwrap();
    let (mut gap, mut angle, mut disabled, mut completed) = (0.0 as Real, 0.0 as Real, 0, 0);
    for _ in 0..150 {
        world.step(1.0 / 60.0).unwrap();
        world.validate().unwrap();
        for e in &world.events().portals {
            match e {
                PortalEvent::JointDisabled { .. } => disabled += 1,
                PortalEvent::CrossingCompleted { .. } => completed += 1,
                _ => {}
            }
        }
        gap = gap.max(world.joint_gap(joint).unwrap());
        angle = angle.max(world.joint_angle(joint).unwrap().abs());
    }
    (gap, angle, disabled, completed)
}

#[test]
fn weld_pair_through_a_scaled_turned_portal_stays_welded() {
    for direct in [true, false] {
        let (gap, angle, disabled, completed) = weld_through(direct);
        if report() {
            eprintln!(
                "weld pair through η = {ETA} (tree {direct}): worst gap {gap:.3e} m, angle {angle:.3e} rad, \
                 {disabled} disabled, {completed} crossings"
            );
        }
        assert_eq!(disabled, 0, "joint-disabled events");
        assert_eq!(completed, 2, "both boxes cross");
        assert!(gap <= 1e-3, "tree {direct}: worst gap {gap} m");
        assert!(angle <= 2e-3, "tree {direct}: worst angle {angle} rad");
    }
}
