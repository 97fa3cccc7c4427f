//! Snapshot bytes: `Snapshot::from_bytes` on any bytes never panics; a
//! world it accepts validates, and keeps validating through steps and API
//! calls (reads, wakes, velocities, impulses, joint read-back and
//! destruction, body destruction and creation, a ray cast; and issue 32's:
//! motion locks, fixed rotation, gravity scale, damping, enable/disable,
//! velocity at a point, geometry scaling, surface materials, friction and
//! restitution, event switches, a chain created and one destroyed, an
//! explosion, the point, shape and sensor queries, the mover casts and
//! collisions and the character controller); its own bytes decode again.
//!
//! Input: a mode byte, then bytes. Mode even: the bytes are a payload and
//! the target writes a correct header in front of it (magic, version,
//! build, length, checksum), so mutations reach the decoder and the
//! validator instead of stopping at the checksum; mode odd: the bytes go
//! to `from_bytes` as they are (the header checks). The corpus in
//! `corpus/snapshot_bytes` is seeded from real snapshots' payloads.
#![no_main]

use janus2d::prelude::*;
use janus2d::world::{CharacterController, ExplosionDef, Snapshot, SnapshotError};
use libfuzzer_sys::fuzz_target;

const DT: Real = 1.0 / 60.0;
/// Header bytes: magic (4), version (2), real size, portals, length (8),
/// checksum (8).
const HEADER: usize = 24;

fn fnv(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in bytes {
        h ^= u64::from(*b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// `payload` behind a correct header of this build (its first 8 bytes
/// taken from an empty world's snapshot).
fn with_header(payload: &[u8]) -> Vec<u8> {
    let template = World::new(WorldDef::default())
        .expect("the default world")
        .snapshot()
        .to_bytes();
    let mut out = Vec::with_capacity(HEADER + payload.len());
    out.extend_from_slice(&template[..8]);
    out.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&fnv(payload).to_le_bytes());
    out.extend_from_slice(payload);
    out
}

fn valid(world: &World, what: &str) {
    if let Err(e) = world.validate() {
        panic!("{what}: {e}");
    }
}

/// Steps and API calls on a decoded world, validating as it goes.
fn exercise(mut world: World, seed: u8) {
    for _ in 0..3 {
        let _ = world.step(DT);
        valid(&world, "after a step");
    }
    let bodies: Vec<BodyHandle> = world.body_handles().take(16).collect();
    for (k, &b) in bodies.iter().enumerate() {
        let _ = world.linear_velocity(b);
        let _ = world.is_sleeping(b);
        let _ = world.wake_body(b);
        if (k + usize::from(seed)) % 3 == 0 {
            let _ = world.set_linear_velocity(b, Vec2::new(1.0, -2.0));
            let _ = world.apply_linear_impulse(b, Vec2::new(0.5, 0.5), Vec2::ZERO);
        }
    }
    for &j in world.joint_handles().to_vec().iter().take(16) {
        let force = world.joint_force(j);
        let torque = world.joint_torque(j);
        if let (Ok(f), Ok(t)) = (force, torque) {
            assert!(f.is_finite() && t.is_finite(), "joint read-back {f:?} {t}");
        }
    }
    valid(&world, "after the calls");
    issue32_calls(&mut world, &bodies, seed);
    valid(&world, "after issue 32's calls");
    let _ = world.step(DT);
    valid(&world, "after a step");
    if let Some(&j) = world.joint_handles().first() {
        let _ = world.destroy_joint(j);
    }
    if let Some(&b) = bodies.get(usize::from(seed) % bodies.len().max(1)) {
        let _ = world.destroy_body(b);
    }
    if let Ok(b) = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0))) {
        let _ = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5));
    }
    let _ = world.cast_ray_closest(
        Vec2::new(-20.0, 1.0),
        Vec2::new(40.0, 0.0),
        &QueryFilter::default(),
    );
    for _ in 0..2 {
        let _ = world.step(DT);
        valid(&world, "after destroying and creating");
    }
    let again = world.snapshot().to_bytes();
    if let Err(e) = Snapshot::from_bytes(&again) {
        panic!("a world's own bytes do not decode: {e}");
    }
}

/// Issue 32's setters and queries on a decoded world, each followed by
/// the validator.
fn issue32_calls(world: &mut World, bodies: &[BodyHandle], seed: u8) {
    let s = usize::from(seed);
    for (k, &b) in bodies.iter().enumerate() {
        let locks = MotionLocks {
            linear_x: (k + s) % 3 == 0,
            linear_y: (k + s) % 5 == 0,
            angular: (k + s) % 2 == 0,
        };
        let _ = world.set_motion_locks(b, locks);
        let _ = world.set_gravity_scale(b, 0.5 + (k % 3) as Real);
        let _ = world.set_linear_damping(b, 0.1);
        let _ = world.set_fixed_rotation(b, k % 4 == 1);
        let _ = world.set_body_move_events(b, k % 2 == 0);
        if let Ok(v) = world.velocity_at_point(b, Vec2::new(1.0, 1.0)) {
            assert!(v.is_finite(), "velocity at a point {v:?}");
        }
        if (k + s) % 4 == 0 {
            let _ = world.set_body_enabled(b, false);
            valid(world, "after disabling a body");
            if k % 8 == 0 {
                let _ = world.set_body_enabled(b, true);
                valid(world, "after enabling a body");
            }
        }
        let shapes = world.body_shapes(b).unwrap_or_default();
        for (j, &sh) in shapes.iter().take(4).enumerate() {
            match (j + s + k) % 6 {
                0 => drop(world.scale_shape(sh, 1.25)),
                1 => drop(world.set_shape_rolling_resistance(sh, 0.2)),
                2 => drop(world.set_shape_tangent_speed(sh, 1.0)),
                3 => drop(world.set_shape_friction(sh, 0.1)),
                4 => drop(world.set_shape_hit_events(sh, true)),
                _ => drop(world.set_shape_force_event_threshold(sh, 1.0)),
            }
            let _ = world.set_shape_contact_events(sh, j % 2 == 0);
            let _ = world.set_shape_user_material_id(sh, k as u64);
            let _ = world.shape_test_point(sh, Vec2::ZERO);
            let _ = world.shape_project_point(sh, Vec2::new(0.5, 2.0));
            let _ = world.shape_ray_cast(
                sh,
                Vec2::new(-5.0, 1.0),
                Vec2::new(10.0, 0.0),
                &QueryFilter::default(),
            );
            let _ = world.sensor_overlaps(sh);
            valid(world, "after a shape call");
        }
    }
    world.set_move_events(seed % 2 == 0);
    if let Some(&c) = world.chain_handles().first() {
        let _ = world.destroy_chain(c);
        valid(world, "after destroying a chain");
    }
    if let Some(&b) = bodies.first() {
        let points = vec![
            Vec2::new(3.0, -1.0),
            Vec2::new(0.0, -1.2),
            Vec2::new(-3.0, -1.0),
        ];
        let material = SurfaceMaterial::default().with_rolling_resistance(0.1);
        let _ = world.create_chain(b, &ChainDef::new(points).with_material(material));
        valid(world, "after creating a chain");
    }
    let _ = world.explode(&ExplosionDef::new(Vec2::new(0.0, 1.0), 3.0, 2.0).with_falloff(1.0));
    valid(world, "after an explosion");
    let _ = world.project_point(Vec2::new(0.0, 5.0), 10.0, &QueryFilter::default());
    let mover = Capsule::new(Vec2::new(0.0, 2.75), Vec2::new(0.0, 3.25), 0.25).expect("a capsule");
    if let Ok(cast) = world.cast_mover(&mover, Vec2::new(3.0, -6.0), &QueryFilter::default()) {
        assert!(
            cast.fraction.is_finite(),
            "mover fraction {}",
            cast.fraction
        );
    }
    let _ = world.collide_mover(&mover, 0.05, &QueryFilter::default(), |p| {
        p.separation.is_finite()
    });
    let mut cc = CharacterController::new().with_snap_to_ground(Some(0.1));
    if let Ok(m) = cc.move_and_slide(
        world,
        &mover,
        Vec2::ZERO,
        Vec2::new(2.0, -1.0),
        DT,
        &QueryFilter::default(),
    ) {
        assert!(
            m.position.is_finite() && m.velocity.is_finite(),
            "controller {m:?}"
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let bytes = if mode % 2 == 0 {
        with_header(rest)
    } else {
        rest.to_vec()
    };
    let snapshot = match Snapshot::from_bytes(&bytes) {
        Ok(snapshot) => snapshot,
        Err(SnapshotError::Decode(e)) if expect_decode() => {
            panic!("JANUS_FUZZ_EXPECT_DECODE: the payload does not decode ({e}): a stale corpus")
        }
        Err(_) => return,
    };
    let world = snapshot.to_world();
    valid(&world, "as decoded");
    exercise(world, mode);
});

/// `JANUS_FUZZ_EXPECT_DECODE` is set: CI's run over the committed seeds
/// and carried regression inputs, each of which must decode in the
/// current format (refused by the validator is fine; undecodable means
/// the corpus was not rewritten after a format change).
fn expect_decode() -> bool {
    static EXPECT: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *EXPECT.get_or_init(|| std::env::var_os("JANUS_FUZZ_EXPECT_DECODE").is_some())
}
