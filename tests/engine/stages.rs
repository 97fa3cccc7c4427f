//! The stages' own bookkeeping: sleeping contacts leave the awake list,
//! per-body adjacency ends the right contacts, joint setters validate, and
//! a ragdoll falls asleep with the joint-tree solve on.

use janus2d::prelude::*;
use janus2d::world::{JointKind, WorldError};
use janus2d_testbed::benchmarks::{rain, rain_group};
use janus2d_testbed::desc::{Action, Script};
use janus2d_testbed::janus::{Janus, world_def};
use janus2d_testbed::scenes::DT;
use janus2d_testbed::support::wall;

fn stack_on_ground(n: usize) -> (World, BodyHandle, Vec<BodyHandle>) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let g = wall(&mut world, Vec2::new(0.0, -1.0), 20.0, 1.0);
    let boxes = (0..n)
        .map(|i| unit_box(&mut world, Vec2::new(0.0, 0.5 + i as Real)))
        .collect();
    (world, g, boxes)
}

/// A dynamic 1 m box at `at`.
fn unit_box(world: &mut World, at: Vec2) -> BodyHandle {
    let b = world.create_body(&BodyDef::dynamic(at)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    b
}

#[test]
fn sleeping_island_contacts_leave_the_awake_list_and_come_back_on_wake() {
    let (mut world, _, boxes) = stack_on_ground(3);
    for _ in 0..240 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 3, "the stack sleeps");
    assert_eq!(
        world.contact_count(),
        3,
        "ground–box and two box–box contacts"
    );
    assert_eq!(world.awake_contact_count(), 0, "none is visited per step");
    world.step(DT).unwrap();
    assert_eq!(
        world.counters().pairs_tested,
        0,
        "the narrowphase sees none"
    );
    world
        .apply_linear_impulse(boxes[2], Vec2::new(0.0, 0.1), Vec2::ZERO)
        .unwrap();
    assert_eq!(world.sleeping_body_count(), 0);
    assert_eq!(world.awake_contact_count(), 3, "the island's contacts woke");
    world.step(DT).unwrap();
    assert_eq!(world.counters().pairs_tested, 3);
}

#[test]
fn destroying_a_body_ends_its_contacts_only_and_reports_them_next_step() {
    let (mut world, _, boxes) = stack_on_ground(3);
    world.step(DT).unwrap();
    assert_eq!(world.touching_contact_count(), 3);
    let top = boxes[2];
    let top_shape = world.body_shapes(top).unwrap()[0];
    world.destroy_body(top).unwrap();
    assert_eq!(world.contact_count(), 2, "only the top box's contact ended");
    world.step(DT).unwrap();
    let ends = &world.events().collision.contact_end;
    assert_eq!(ends.len(), 1, "the end event survives until the step");
    assert!(ends[0].shape_a == top_shape || ends[0].shape_b == top_shape);
    assert_eq!(world.touching_contact_count(), 2);
}

#[test]
fn joint_with_collide_connected_false_ends_only_its_pair() {
    let (mut world, _, boxes) = stack_on_ground(3);
    world.step(DT).unwrap();
    assert_eq!(world.contact_count(), 3);
    let def = RevoluteJointDef::new(
        boxes[0],
        boxes[1],
        Vec2::new(0.0, 0.5),
        Vec2::new(0.0, -0.5),
    );
    let j = world.create_revolute_joint(&def).unwrap();
    assert_eq!(world.contact_count(), 2, "the jointed pair's contact ended");
    assert_eq!(world.joints().of_body(boxes[0]), &[j]);
    assert_eq!(world.joints().kind(j), Ok(JointKind::Revolute));
    world.destroy_body(boxes[1]).unwrap();
    assert_eq!(world.joint_count(), 0, "the joint went with its body");
    assert!(world.joints().of_body(boxes[0]).is_empty());
}

#[test]
fn joint_setters_reject_bad_values_and_leave_the_joint_unchanged() {
    let (mut world, _, boxes) = stack_on_ground(2);
    let def = RevoluteJointDef::new(
        boxes[0],
        boxes[1],
        Vec2::new(0.0, 0.5),
        Vec2::new(0.0, -0.5),
    );
    let j = world.create_revolute_joint(&def).unwrap();
    let before = world.revolute_joint(j).unwrap().def().clone();
    assert_eq!(
        world.set_joint_max_motor_torque(j, -1.0),
        Err(WorldError::OutOfRange("max_motor_torque"))
    );
    assert_eq!(
        world.set_joint_limits(j, 1.0, -1.0),
        Err(WorldError::OutOfRange("limits"))
    );
    assert_eq!(
        world.set_joint_motor_speed(j, Real::NAN),
        Err(WorldError::NonFinite("motor_speed"))
    );
    assert_eq!(
        world.set_joint_spring(j, -2.0, 0.5),
        Err(WorldError::OutOfRange("spring"))
    );
    assert_eq!(world.revolute_joint(j).unwrap().def(), &before);
    world.set_joint_limits(j, -0.5, 0.25).unwrap();
    world.enable_joint_limit(j, true).unwrap();
    world.set_joint_max_motor_torque(j, 10.0).unwrap();
    world.enable_joint_motor(j, true).unwrap();
    let d = &world.revolute_joint(j).unwrap().def();
    assert_eq!((d.lower_angle, d.upper_angle), (-0.5, 0.25));
    assert!(d.enable_limit && d.enable_motor && d.max_motor_torque == 10.0);
    assert_eq!(world.revolute_joint(j).unwrap().row_count(), 2 + 2 + 1);
    world.set_joint_enabled(j, false).unwrap();
    assert!(!world.revolute_joint(j).unwrap().is_enabled());
    world.set_joint_enabled(j, true).unwrap();
    assert!(
        world.revolute_joint(j).unwrap().is_enabled(),
        "enabled again"
    );
}

#[test]
fn rain_ragdoll_falls_asleep_with_the_joint_tree_solve_on() {
    for direct in [true, false] {
        let mut desc = rain();
        desc.script = Script::None;
        let mut def = world_def(&desc.settings);
        def.solver.direct_joints = direct;
        let mut e = Janus::with_def(&desc, def).unwrap();
        let (bodies, joints) = rain_group(0, 0, 1);
        e.try_apply(&Action::Spawn {
            id: 0,
            bodies,
            joints,
        })
        .unwrap();
        for _ in 0..360 {
            e.world.step(DT).unwrap();
        }
        assert_eq!(
            e.world.awake_body_count(),
            0,
            "direct_joints = {direct}: the ragdoll sleeps within 6 s"
        );
    }
}

/// The top box is carried away to (5, 0.5) and kept moving along the
/// ground at 1 m/s for two seconds.
fn carry_off_and_push(world: &mut World, top: BodyHandle) {
    world.set_transform(top, Vec2::new(5.0, 0.5), 0.0).unwrap();
    for _ in 0..120 {
        world.set_linear_velocity(top, Vec2::new(1.0, 0.0)).unwrap();
        world.step(DT).unwrap();
    }
}

#[test]
fn island_splits_when_bodies_part_so_the_resting_one_sleeps() {
    let (mut world, _, boxes) = stack_on_ground(2);
    let (low, high) = (boxes[0], boxes[1]);
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    carry_off_and_push(&mut world, high);
    assert!(
        !world.is_sleeping(high).unwrap(),
        "the pushed box stays awake"
    );
    assert!(
        world.is_sleeping(low).unwrap(),
        "the box left behind sleeps: its island split from the moving one"
    );
}

/// A stack of three on the ground whose top box is carried off and kept
/// moving, beside `far` boxes resting on a ground of their own: after
/// two seconds, the islands of the low, middle and top box.
fn three_part_after_the_top_leaves(far: usize) -> [(bool, Option<u32>); 3] {
    let (mut world, _, boxes) = stack_on_ground(3);
    wall(&mut world, Vec2::new(200.0, -1.0), 150.0, 1.0);
    for i in 0..far {
        unit_box(&mut world, Vec2::new(60.0 + 1.5 * i as Real, 0.5));
    }
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    let high = boxes[2];
    carry_off_and_push(&mut world, high);
    let read = |b: BodyHandle| (world.is_sleeping(b).unwrap(), world.island_id(b));
    [read(boxes[0]), read(boxes[1]), read(high)]
}

/// The split reads the links in one pass over the contact set when the
/// island is a fair share of the world (no other boxes), and from each
/// member's own contacts when it is small beside many others (150 boxes
/// resting elsewhere): both must cut exactly the link that went.
#[test]
fn island_split_keeps_touching_bodies_together_read_either_way() {
    for far in [0, 150] {
        let [(low_asleep, low), (mid_asleep, mid), (high_asleep, high)] =
            three_part_after_the_top_leaves(far);
        assert!(
            low_asleep && mid_asleep,
            "{far} far boxes: the stack left sleeps"
        );
        assert!(!high_asleep, "{far} far boxes: the pushed box stays awake");
        assert!(
            low.is_some(),
            "{far} far boxes: dynamic bodies have islands"
        );
        assert_eq!(
            low, mid,
            "{far} far boxes: the touching pair stays one island"
        );
        assert_ne!(
            low, high,
            "{far} far boxes: the box carried off has its own"
        );
    }
}

/// A ball drifting at 0.08 m/s in zero gravity: above the world's 0.05 m/s
/// threshold it never sleeps; with its own threshold of 0.1 m/s it sleeps
/// once it has been slow for `time_to_sleep`.
fn drifting_ball(threshold: Option<Real>) -> (World, BodyHandle) {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let def = BodyDef {
        linear_velocity: Vec2::new(0.08, 0.0),
        sleep_threshold: threshold,
        ..BodyDef::dynamic(Vec2::ZERO)
    };
    let b = world.create_body(&def).unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.25).unwrap(),
        )
        .unwrap();
    (world, b)
}

#[test]
fn per_body_sleep_threshold_decides_when_a_slow_body_sleeps() {
    let (mut world, _) = drifting_ball(None);
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 0, "0.08 m/s > 0.05 m/s");
    let (mut world, _) = drifting_ball(Some(0.1));
    for _ in 0..29 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 0, "not yet 0.5 s");
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 1, "slow for 0.5 s: asleep");
}

#[test]
fn negative_or_nan_sleep_threshold_is_refused() {
    let mut world = World::new(WorldDef::default()).unwrap();
    for bad in [-0.1, Real::NAN] {
        let def = BodyDef {
            sleep_threshold: Some(bad),
            ..BodyDef::dynamic(Vec2::ZERO)
        };
        assert!(world.create_body(&def).is_err(), "{bad}");
    }
    assert_eq!(world.body_count(), 0, "nothing created");
}
