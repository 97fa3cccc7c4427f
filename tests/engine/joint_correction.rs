//! How fast a joint corrects a position error (issue 35): a joint created
//! metres from satisfied, or turned far from its reference angle, pulls
//! its bodies together at a bounded speed in both solves (the exact tree
//! and Gauss–Seidel), instead of flinging them at hundreds or thousands of
//! m/s.

use janus2d::base::limits::MAX_SPEED;
use janus2d::constraints::JointKind;
use janus2d::constraints::parts::angular_correction_cap;
use janus2d::prelude::*;
use janus2d_testbed::support::joint_def_of_kind;

const DT: Real = 1.0 / 60.0;

/// The kinds with rigid position rows (motor, mouse and filter joints
/// correct through a force limit or not at all).
const RIGID_KINDS: [JointKind; 5] = [
    JointKind::Revolute,
    JointKind::Prismatic,
    JointKind::Weld,
    JointKind::Distance,
    JointKind::Wheel,
];

/// Half the distance between neighbouring boxes' centres, m: the joint
/// anchors sit this far from each box's centre.
const ARM: Real = 0.55;

/// A world solved directly (`direct`) or by Gauss–Seidel, a static pin and
/// `links` boxes (0.8 m, 0.64 kg) in a row joined by joints of `kind`
/// (limits of ±0.5 on each when `limits`): the pin's anchor `gap` m short
/// of the first box, each box turned `turn` rad from the one before. No
/// speed limit (`MAX_SPEED`), so the solve's own speeds show.
fn opened_chain(
    kind: JointKind,
    direct: bool,
    limits: bool,
    links: usize,
    gap: Real,
    turn: Real,
) -> World {
    let mut def = WorldDef::default();
    def.solver.direct_joints = direct;
    let mut world = World::new(def).unwrap();
    let pin = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let half = Vec2::new(ARM, 0.0);
    let mut previous = pin;
    for i in 0..links {
        let p = Vec2::new(2.0 * ARM * (i as Real + 1.0), 0.0);
        let body = BodyDef {
            angle: turn * (i as Real + 1.0),
            max_linear_speed: MAX_SPEED,
            ..BodyDef::dynamic(p)
        };
        let b = world.create_body(&body).unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.4, 0.4))
            .unwrap();
        let range = if kind == JointKind::Distance {
            (0.5, 1.5)
        } else {
            (-0.5, 0.5)
        };
        let mut def = joint_def_of_kind(kind, previous, b, half, limits.then_some(range), false);
        if i == 0 {
            def.base_mut().local_frame_a.anchor = half - Vec2::new(gap, 0.0);
        }
        world.create_joint(&def).unwrap();
        previous = b;
    }
    world
}

/// The fastest any body moves in any of `steps` steps, m/s: the larger
/// of its speed after the step and its displacement over the step divided
/// by the step (the soft step's relax takes the correction's speed off
/// the velocity, not off the motion it caused).
fn fastest(world: &mut World, steps: usize) -> Real {
    let mut worst: Real = 0.0;
    for _ in 0..steps {
        let bodies: Vec<BodyHandle> = world.body_handles().collect();
        let before: Vec<Vec2> = bodies.iter().map(|&b| world.position(b).unwrap()).collect();
        world.step(DT).unwrap();
        for (&b, p0) in bodies.iter().zip(before) {
            let moved = (world.position(b).unwrap() - p0).length() / DT;
            let v = world.linear_velocity(b).unwrap().length();
            worst = worst.max(moved).max(v);
        }
        world.validate().unwrap();
    }
    worst
}

/// The run of the tests, s (60 steps).
const STEPS: usize = 60;

/// Issue 35: one box hung from a static pin by each kind with rigid rows,
/// solved directly and by Gauss–Seidel, with and without limits, its
/// joint created 10 m open or turned 3 rad from its reference angle.
/// Whatever the joint's error, its feedback asks for at most the linear
/// correction cap `v` plus the angular cap `ω` at the anchor's arm, so no
/// box moves faster than `v + ω · ARM + g T` over the run `T` (87.3 m/s:
/// 50, 27.5 and 9.8). Uncapped, the Gauss–Seidel joints moved their box at
/// 190–420 m/s in the first step (every kind 10 m open), the tree's
/// turned weld at 98 m/s and its prismatic joint's violated limits at
/// 304 m/s.
#[test]
fn a_joint_created_far_from_satisfied_moves_its_body_no_faster_than_the_correction_caps() {
    let settings = SolverSettings::default();
    // The iterative rows' caps are the larger: a tree joint's limits and
    // axial rows stay iterative.
    let v = settings
        .joint_max_correction_speed
        .max(settings.direct_joint_max_correction_speed);
    let w = angular_correction_cap(v);
    let g = WorldDef::default().gravity.length();
    let bound = v + w * ARM + g * STEPS as Real * DT;
    for kind in RIGID_KINDS {
        for direct in [true, false] {
            for limits in [false, true] {
                for (gap, turn) in [(10.0, 0.0), (0.0, 3.0)] {
                    let mut world = opened_chain(kind, direct, limits, 1, gap, turn);
                    let fastest = fastest(&mut world, STEPS);
                    assert!(
                        fastest <= bound,
                        "{kind:?} (direct {direct}, limits {limits}, {gap} m open, \
                         turned {turn} rad): {fastest} m/s > {bound} m/s"
                    );
                }
            }
        }
    }
}

/// Issue 35: chains of four boxes solved exactly (every row in the tree:
/// no limits), the first joint 10 m open or every link turned 3 rad from
/// the one before. Each joint's linear feedback is capped at the tree's
/// correction speed `v` and its angle feedback at `ω`, so the outermost box
/// (at most `n · 2 ARM` from the pin) moves no faster than the caps added
/// along the chain, `n v + n ω (n · 2 ARM) + g T` (53 m/s: 8, 35.2, 9.8).
/// With the angle rows uncapped the turned prismatic chain's rails swung
/// its sliders at 1,400 m/s, and the turned welds moved at 111 m/s.
#[test]
fn a_tree_chain_started_far_from_its_reference_angles_moves_no_faster_than_its_caps_add_up() {
    let settings = SolverSettings::default();
    let v = settings.direct_joint_max_correction_speed;
    let w = angular_correction_cap(v);
    let g = WorldDef::default().gravity.length();
    let n = 4;
    let reach = n as Real * 2.0 * ARM;
    let bound = n as Real * (v + w * reach) + g * STEPS as Real * DT;
    for kind in RIGID_KINDS {
        for (gap, turn) in [(10.0, 0.0), (0.0, 3.0)] {
            let mut world = opened_chain(kind, true, false, n, gap, turn);
            let fastest = fastest(&mut world, STEPS);
            assert!(
                fastest <= bound,
                "{kind:?} chain ({gap} m open, turned {turn} rad): {fastest} m/s > {bound} m/s"
            );
        }
    }
}

/// Issue 35 (found by the random-operation soak): a slider created with
/// its body far down the rail, beyond its limits, on a kinematic base.
/// The limit rows' lever on the slider `(r_a + d) × n` grows with the
/// anchors' separation `d`; with the limits solved before the rigid block
/// the two fought (the limit turning the body, the angle row turning it
/// back) and their impulses grew each step: at 24–30 m the slider reached
/// 400 m/s and ended 260 m away. Now it comes back within its limits, no
/// faster than the correction cap plus a fall along the whole separation,
/// `v + √(2 g |d|)`.
#[test]
fn a_prismatic_joint_created_far_beyond_its_limits_returns_within_them_without_diverging() {
    let settings = SolverSettings::default();
    let g = WorldDef::default().gravity.length();
    let (lower, upper) = (-1.24, 0.37);
    for (gap, axis_angle) in [
        (24.0 as Real, 0.5 as Real),
        (24.0, 2.5),
        (30.0, 0.5),
        (30.0, 2.5),
    ] {
        let mut def = WorldDef::default();
        def.solver.direct_joints = false;
        let mut world = World::new(def).unwrap();
        let base = world.create_body(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
        let slider = BodyDef {
            max_linear_speed: MAX_SPEED,
            ..BodyDef::dynamic(gap * Vec2::new(0.6, 0.8))
        };
        let slider = world.create_body(&slider).unwrap();
        world
            .create_shape(
                slider,
                &ShapeDef::default().with_density(5.0),
                Polygon::make_box(0.5, 0.4),
            )
            .unwrap();
        let axis = Vec2::new(axis_angle.cos(), axis_angle.sin());
        let joint = PrismaticJointDef::new(
            slider,
            base,
            Vec2::new(0.46, 0.14),
            Vec2::new(0.1, 0.85),
            axis,
        )
        .with_limits(lower, upper);
        let joint = world.create_joint(&joint.into()).unwrap();
        let separation = world.joint_gap(joint).unwrap();
        let fastest = fastest(&mut world, 400);
        let bound = settings.joint_max_correction_speed + (2.0 * g * separation).sqrt();
        assert!(
            fastest <= bound,
            "{gap} m, axis at {axis_angle} rad: {fastest} m/s > {bound} m/s"
        );
        // Perpendicular and angle rows met: the anchors are |t| apart.
        let end = world.joint_gap(joint).unwrap();
        assert!(
            end <= upper.abs().max(lower.abs()) + 0.01,
            "{gap} m, axis at {axis_angle} rad: anchors {end} m apart"
        );
    }
}
