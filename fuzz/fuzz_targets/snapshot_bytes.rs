//! Snapshot bytes: `Snapshot::from_bytes` on any bytes never panics; a
//! world it accepts validates, and keeps validating through steps and API
//! calls (reads, wakes, velocities, impulses, joint read-back and
//! destruction, body destruction and creation, a ray cast); its own bytes
//! decode again.
//!
//! Input: a mode byte, then bytes. Mode even: the bytes are a payload and
//! the target writes a correct header in front of it (magic, version,
//! build, length, checksum), so mutations reach the decoder and the
//! validator instead of stopping at the checksum; mode odd: the bytes go
//! to `from_bytes` as they are (the header checks). The corpus in
//! `corpus/snapshot_bytes` is seeded from real snapshots' payloads.
#![no_main]

use janus2d::prelude::*;
use janus2d::world::Snapshot;
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

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        return;
    };
    let bytes = if mode % 2 == 0 {
        with_header(rest)
    } else {
        rest.to_vec()
    };
    let Ok(snapshot) = Snapshot::from_bytes(&bytes) else {
        return;
    };
    let world = snapshot.to_world();
    valid(&world, "as decoded");
    exercise(world, mode);
});
