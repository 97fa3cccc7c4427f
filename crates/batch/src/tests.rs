//! Unit tests of the batch: copies, determinism across thread counts,
//! batched reads and writes, errors.

use super::*;
use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// A ground, a stack of three boxes and a pendulum on a motor: contacts
/// and a joint in every world.
fn template() -> (World, Vec<BodyHandle>, JointHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))
        .unwrap();
    let mut bodies = Vec::new();
    for i in 0..3 {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(
                0.1 * i as Real,
                0.5 + 1.1 * i as Real,
            )))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        bodies.push(b);
    }
    let arm = world
        .create_body(&BodyDef::dynamic(Vec2::new(5.0, 3.0)))
        .unwrap();
    world
        .create_shape(arm, &ShapeDef::default(), Polygon::make_box(0.8, 0.1))
        .unwrap();
    let base = world
        .joint_base_at(ground, arm, Vec2::new(4.2, 3.0))
        .unwrap();
    let joint = world
        .create_joint(
            &RevoluteJointDef::from_base(base)
                .with_motor(0.0, 50.0)
                .into(),
        )
        .unwrap();
    bodies.push(arm);
    (world, bodies, joint)
}

/// Different pushes per world, so the worlds' states differ.
fn push_all(batch: &mut WorldBatch, bodies: &[BodyHandle]) {
    let n = batch.len();
    let mut v = vec![0.0; n * bodies.len() * VELOCITY_WIDTH];
    for (i, row) in v.chunks_mut(bodies.len() * VELOCITY_WIDTH).enumerate() {
        row[0] = 0.3 * i as Real;
        row[2] = -0.2 * i as Real;
    }
    batch.write_velocities(bodies, &v).unwrap();
}

#[test]
fn copies_start_identical_and_step_like_the_template() {
    let (mut world, bodies, _) = template();
    let mut batch = WorldBatch::new(&world, 4).unwrap();
    for _ in 0..30 {
        world.step(DT).unwrap();
    }
    batch.step_many(DT, 30).unwrap();
    let hashes = batch.state_hashes();
    assert_eq!(hashes.len(), 4);
    assert!(hashes.iter().all(|&h| h == world.state_hash()));
    let mut state = vec![0.0; 4 * bodies.len() * STATE_WIDTH];
    batch.read_state(&bodies, &mut state).unwrap();
    let top = world.position(bodies[2]).unwrap();
    assert_eq!(state[2 * STATE_WIDTH].to_bits(), top.x.to_bits());
    assert_eq!(state[2 * STATE_WIDTH + 1].to_bits(), top.y.to_bits());
}

#[test]
fn states_are_the_same_bits_for_one_two_and_four_threads() {
    let (world, bodies, joint) = template();
    let mut runs = Vec::new();
    for threads in [1, 2, 4] {
        let mut batch = WorldBatch::with_threads(&world, 16, threads).unwrap();
        push_all(&mut batch, &bodies);
        let speeds: Vec<Real> = (0..16).map(|i| i as Real * 0.25 - 2.0).collect();
        batch.set_motor_speeds(&[joint], &speeds).unwrap();
        batch.step_many(DT, 90).unwrap();
        let mut state = vec![0.0; 16 * bodies.len() * STATE_WIDTH];
        batch.read_state(&bodies, &mut state).unwrap();
        let bits: Vec<_> = state.iter().map(|x| x.to_bits()).collect();
        runs.push((batch.state_hashes(), bits));
    }
    assert_eq!(runs[0], runs[1]);
    assert_eq!(runs[0], runs[2]);
    // The pushes made the worlds differ from one another.
    let hashes = &runs[0].0;
    assert!(hashes.windows(2).all(|w| w[0] != w[1]));
}

#[test]
fn set_threads_mid_run_changes_nothing() {
    let (world, bodies, _) = template();
    let mut a = WorldBatch::with_threads(&world, 8, 1).unwrap();
    let mut b = WorldBatch::with_threads(&world, 8, 2).unwrap();
    push_all(&mut a, &bodies);
    push_all(&mut b, &bodies);
    a.step_many(DT, 20).unwrap();
    b.step_many(DT, 20).unwrap();
    b.set_threads(1).unwrap();
    assert_eq!(b.threads(), 1);
    a.step_many(DT, 20).unwrap();
    b.step_many(DT, 20).unwrap();
    assert_eq!(a.state_hashes(), b.state_hashes());
}

#[test]
fn a_box_falls_as_free_fall_says() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 100.0)))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let mut batch = WorldBatch::with_threads(&world, 3, 2).unwrap();
    batch.step_many(DT, 60).unwrap();
    let mut state = vec![0.0; 3 * STATE_WIDTH];
    batch.read_state(&[b], &mut state).unwrap();
    for row in state.chunks(STATE_WIDTH) {
        // Semi-implicit Euler: v after 60 steps is exactly -10 m/s (to
        // rounding), the drop is g t² / 2 plus half a step's worth.
        assert!((row[4] + 10.0).abs() < 1e-3, "vy {}", row[4]);
        let drop = 100.0 - row[1];
        assert!((drop - 5.0).abs() < 0.1, "drop {drop}");
    }
}

#[test]
fn forces_and_impulses_change_momentum_by_what_was_applied() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let mass = world.mass(b).unwrap();
    let mut batch = WorldBatch::new(&world, 2).unwrap();
    // World 0: 2 N·s impulse at the centre; world 1: 6 N for one step.
    batch
        .apply_impulses(&[b], &[2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .unwrap();
    batch
        .apply_forces(&[b], &[0.0, 0.0, 0.0, 0.0, 6.0, 0.0])
        .unwrap();
    batch.step(DT).unwrap();
    let mut state = vec![0.0; 2 * STATE_WIDTH];
    batch.read_state(&[b], &mut state).unwrap();
    assert!(
        (state[3] * mass - 2.0).abs() < 1e-4,
        "px {}",
        state[3] * mass
    );
    assert!(state[4].abs() < 1e-6);
    assert!((state[STATE_WIDTH + 4] * mass - 6.0 * DT).abs() < 1e-4);
    assert!(state[STATE_WIDTH + 3].abs() < 1e-6);
}

#[test]
fn motors_turn_their_joint_at_the_speed_set() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let wheel = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    world
        .create_shape(
            wheel,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .unwrap();
    let base = world.joint_base_at(ground, wheel, Vec2::ZERO).unwrap();
    let joint = world
        .create_joint(
            &RevoluteJointDef::from_base(base)
                .with_motor(0.0, 1000.0)
                .into(),
        )
        .unwrap();
    let mut batch = WorldBatch::with_threads(&world, 3, 2).unwrap();
    batch.set_motor_speeds(&[joint], &[1.0, -2.0, 3.0]).unwrap();
    batch.step_many(DT, 30).unwrap();
    let mut out = vec![0.0; 3 * 2];
    batch.read_joint_angles(&[joint], &mut out).unwrap();
    for (i, speed) in [1.0, -2.0, 3.0].into_iter().enumerate() {
        assert!(
            (out[2 * i + 1] - speed).abs() < 1e-3,
            "speed {}",
            out[2 * i + 1]
        );
        // Half a second at that speed (the motor is stiff: the first
        // step already reaches it).
        assert!(
            (out[2 * i] - 0.5 * speed).abs() < 0.05,
            "angle {}",
            out[2 * i]
        );
    }
}

#[test]
fn contacts_and_sleep_are_read_per_world() {
    let (world, bodies, _) = template();
    let mut batch = WorldBatch::new(&world, 2).unwrap();
    // Lift world 1's bottom box 5 m up: it is in the air after a step.
    let mut poses = vec![0.0; 2 * 3];
    poses[0] = 0.0;
    poses[1] = 0.5;
    poses[3] = 0.0;
    poses[4] = 5.5;
    batch.write_poses(&bodies[..1], &poses).unwrap();
    batch.step(DT).unwrap();
    let mut counts = vec![0; 2];
    batch
        .read_contact_counts(&bodies[..1], &mut counts)
        .unwrap();
    assert!(counts[0] >= 1, "the bottom box rests on the ground");
    assert_eq!(counts[1], 0, "the lifted box touches nothing");
    let mut awake = vec![false; 2];
    batch.read_awake(&bodies[..1], &mut awake).unwrap();
    assert_eq!(awake, vec![true, true]);
}

#[test]
fn reset_returns_to_the_template() {
    let (world, bodies, _) = template();
    let start = world.state_hash();
    let mut batch = WorldBatch::with_threads(&world, 3, 2).unwrap();
    push_all(&mut batch, &bodies);
    batch.step_many(DT, 10).unwrap();
    batch.reset_where(&[true, false, true]).unwrap();
    let h = batch.state_hashes();
    assert_eq!(h[0], start);
    assert_ne!(h[1], start);
    assert_eq!(h[2], start);
    batch.reset(1).unwrap();
    assert_eq!(batch.state_hashes()[1], start);
    assert_eq!(
        batch.reset(3),
        Err(BatchError::WorldIndex { index: 3, len: 3 })
    );
}

#[test]
fn a_world_built_by_the_same_code_shares_the_handles() {
    let (world, bodies, _) = template();
    let mut batch = WorldBatch::new(&world, 2).unwrap();
    // Same code, a new world (another id): handles resolve by slot.
    let (other, _, _) = template();
    let other_top = other.position(bodies[2]);
    assert_eq!(other_top, Err(WorldError::ForeignHandle));
    batch.set_world(1, other).unwrap();
    let mut state = vec![0.0; 2 * STATE_WIDTH];
    batch.read_state(&bodies[2..3], &mut state).unwrap();
    assert_eq!(state[1], state[STATE_WIDTH + 1]);
    assert!((state[1] - 2.7).abs() < 1e-6);
}

#[test]
fn errors_are_typed_and_leave_the_batch_usable() {
    let (world, bodies, joint) = template();
    assert_eq!(WorldBatch::new(&world, 0).unwrap_err(), BatchError::Empty);
    assert!(matches!(
        WorldBatch::with_threads(&world, 2, 0),
        Err(BatchError::Threads(_))
    ));
    let mut batch = WorldBatch::new(&world, 2).unwrap();
    let mut short = vec![0.0; 5];
    assert_eq!(
        batch.read_state(&bodies, &mut short),
        Err(BatchError::Length {
            what: "out",
            expected: 2 * bodies.len() * STATE_WIDTH,
            found: 5
        })
    );
    assert_eq!(
        batch.step(0.0),
        Err(BatchError::World {
            index: 0,
            error: WorldError::InvalidTimeStep
        })
    );
    // A NaN speed in world 1 only: world 1 is named.
    assert!(matches!(
        batch.set_motor_speeds(&[joint], &[1.0, Real::NAN]),
        Err(BatchError::World { index: 1, .. })
    ));
    // A body destroyed in world 0 is stale there, and only there.
    batch.world_mut(0).unwrap().destroy_body(bodies[0]).unwrap();
    let mut state = vec![0.0; 2 * STATE_WIDTH];
    assert_eq!(
        batch.read_state(&bodies[..1], &mut state),
        Err(BatchError::World {
            index: 0,
            error: WorldError::StaleBody
        })
    );
    batch.step(DT).unwrap();
    assert!(batch.world(2).is_err());
    assert!(!batch.is_empty());
}

#[test]
fn rays_find_the_ground_at_the_height_of_each_world() {
    let (world, bodies, _) = template();
    let mut batch = WorldBatch::new(&world, 2).unwrap();
    // World 1's bottom box moves away; world 0's stays at x = 0.
    batch
        .write_poses(&bodies[..1], &[0.0, 0.5, 0.0, 10.0, 0.5, 0.0])
        .unwrap();
    // Straight down from (0, 10), 20 m: both worlds meet the stack's top
    // box (centre 2.7, top face at 3.2; it has not moved, no step taken).
    let rays = [0.0, 10.0, 0.0, -20.0, 0.0, 10.0, 0.0, -20.0];
    let mut out = vec![0.0; 2];
    batch
        .cast_rays(&rays, &QueryFilter::default(), &mut out)
        .unwrap();
    assert!((out[0] - (10.0 - 3.2) / 20.0).abs() < 1e-4, "{}", out[0]);
    // A ray upward finds nothing: fraction 1.
    let up = [0.0, 10.0, 0.0, 5.0, 0.0, 10.0, 0.0, 5.0];
    batch
        .cast_rays(&up, &QueryFilter::default(), &mut out)
        .unwrap();
    assert_eq!(out, vec![1.0, 1.0]);
    let mut bad = vec![0.0; 2];
    assert!(matches!(
        batch.cast_rays(&rays[..4], &QueryFilter::default(), &mut bad),
        Err(BatchError::Length { what: "rays", .. })
    ));
}
