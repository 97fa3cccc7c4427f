//! Snapshot and restore: a world restored from a snapshot continues with
//! bit-identical states (same state hash) on the determinism scenes and the
//! hard cases, and passes `World::validate` on the way.
//!
//! CI runs each scene for a few dozen steps after the snapshot; the full
//! check (1,000 steps after it, every hard case):
//!
//! ```text
//! cargo test --release --test engine -- --ignored snapshot::
//! ```

use janus2d::prelude::*;
use janus2d_testbed::{hard, scenes};

const DT: Real = 1.0 / 60.0;

/// The three hinged chains of `tests/scene_runs/determinism.rs`.
fn chains() -> World {
    janus2d_testbed::support::hinged_chains()
}

/// Steps `world` `warm` times, snapshots, steps the original `after`
/// times, restores the snapshot into a fresh world and steps it as many
/// times: the hashes agree (and differ from the snapshot's unless the
/// scene is at rest).
fn continues_bit_exactly(name: &str, mut world: World, warm: usize, after: usize) {
    for _ in 0..warm {
        world.step(DT).unwrap();
    }
    world.validate().unwrap_or_else(|e| panic!("{name}: {e}"));
    let saved = world.snapshot();
    assert_eq!(saved.state_hash(), world.state_hash());
    for _ in 0..after {
        world.step(DT).unwrap();
    }
    let mut restored = saved.to_world();
    assert_eq!(restored.step_count(), world.step_count() - after as u64);
    for k in 0..after {
        restored.step(DT).unwrap();
        if k % 16 == 0 {
            restored
                .validate()
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
    assert_eq!(
        restored.state_hash(),
        world.state_hash(),
        "{name}: the restored world diverged"
    );
    // Restoring in place (onto the world that ran on) gives the same again.
    world.restore(&saved);
    assert_eq!(world.state_hash(), saved.state_hash());
    for _ in 0..after {
        world.step(DT).unwrap();
    }
    assert_eq!(
        restored.state_hash(),
        world.state_hash(),
        "{name}: in place"
    );
}

fn hard_case_world(case: &hard::HardCase) -> World {
    scenes::build(&case.desc, &scenes::shared_settings()).world
}

#[test]
fn restored_snapshot_continues_bit_exactly_on_the_determinism_scenes() {
    continues_bit_exactly("chains", chains(), 40, 80);
    continues_bit_exactly(
        "every joint kind",
        janus2d_testbed::support::every_joint_kind_world(),
        40,
        60,
    );
    let def = scenes::shared_settings();
    continues_bit_exactly("pyramid 20", scenes::large_pyramid(&def, 20).world, 40, 60);
    #[cfg(feature = "portals")]
    {
        // Through the drop: crossings start, go on and complete after
        // the snapshot.
        let (drop, _) = scenes::portal_drop(&def);
        continues_bit_exactly("portal drop", drop.world, 30, 90);
    }
}

#[test]
fn restored_snapshot_continues_bit_exactly_on_the_small_hard_cases() {
    for case in [
        hard::single_box(),
        hard::vertical_stack(12),
        hard::double_domino(),
        hard::confined(),
        hard::high_mass_ratio_1(),
        hard::high_mass_ratio_drop(false),
        hard::bridge(),
        hard::ball_and_chain(),
    ] {
        continues_bit_exactly(case.name, hard_case_world(&case), 20, 40);
    }
}

/// The full run: 1,000 steps after the snapshot on every determinism scene
/// and every hard case (minutes in release).
#[test]
#[ignore = "long: cargo test --release --test engine -- --ignored snapshot::"]
fn restored_snapshot_continues_bit_exactly_for_1000_steps_everywhere() {
    let def = scenes::shared_settings();
    continues_bit_exactly("chains", chains(), 100, 1000);
    continues_bit_exactly(
        "pyramid 20",
        scenes::large_pyramid(&def, 20).world,
        100,
        1000,
    );
    #[cfg(feature = "portals")]
    {
        let (drop, _) = scenes::portal_drop(&def);
        continues_bit_exactly("portal drop", drop.world, 30, 1000);
    }
    for case in hard::all() {
        continues_bit_exactly(case.name, hard_case_world(&case), 100, 1000);
    }
}

/// A snapshot keeps the pre-solve hook out: restore leaves the world's own.
#[test]
fn restore_keeps_the_pre_solve_hook_of_the_world() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.2)))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let saved = world.snapshot();
    // Every contact ignored: the box falls through the ground.
    world.set_pre_solve(Some(Box::new(|_| false)));
    world.restore(&saved);
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(world.position(b).unwrap().y < 0.0, "the hook was lost");
}

/// With the `serde` feature: a snapshot through bytes continues bit-exactly;
/// truncated, corrupted and wrong-version bytes are typed errors.
#[cfg(feature = "serde")]
mod bytes {
    use super::*;
    use janus2d::world::{SNAPSHOT_VERSION, Snapshot, SnapshotError};

    fn small_world() -> World {
        let def = scenes::shared_settings();
        let mut world = scenes::large_pyramid(&def, 4).world;
        for _ in 0..20 {
            world.step(DT).unwrap();
        }
        world
    }

    #[test]
    fn snapshot_bytes_round_trip_continues_bit_exactly() {
        let mut scenes_to_check = vec![
            ("chains", chains()),
            ("pyramid 4", small_world()),
            (
                "every joint kind",
                janus2d_testbed::support::every_joint_kind_world(),
            ),
        ];
        #[cfg(feature = "portals")]
        scenes_to_check.push((
            "portal drop",
            scenes::portal_drop(&scenes::shared_settings()).0.world,
        ));
        for (name, mut world) in scenes_to_check {
            for _ in 0..30 {
                world.step(DT).unwrap();
            }
            let bytes = world.snapshot().to_bytes();
            let mut restored = Snapshot::from_bytes(&bytes).unwrap().to_world();
            assert_eq!(restored.state_hash(), world.state_hash(), "{name}");
            // Encoding the decoded world gives the same bytes (nothing lost).
            let again = restored.snapshot().to_bytes();
            assert!(
                again == bytes,
                "{name}: {} bytes re-encode to {}",
                bytes.len(),
                again.len()
            );
            for _ in 0..60 {
                world.step(DT).unwrap();
                restored.step(DT).unwrap();
            }
            assert_eq!(
                restored.state_hash(),
                world.state_hash(),
                "{name}: diverged"
            );
            restored.validate().unwrap();
        }
    }

    /// Bytes written here, read by a fresh process (this test binary run
    /// again with `JANUS_SNAPSHOT_CHILD` set), stepped 60 times there: the
    /// child's state hash equals this process's continuation.
    #[test]
    fn snapshot_bytes_continue_bit_exactly_in_a_fresh_process() {
        const NAME: &str =
            "snapshot::bytes::snapshot_bytes_continue_bit_exactly_in_a_fresh_process";
        if let Ok(path) = std::env::var("JANUS_SNAPSHOT_CHILD") {
            let bytes = std::fs::read(&path).unwrap();
            let mut world = Snapshot::from_bytes(&bytes).unwrap().to_world();
            for _ in 0..60 {
                world.step(DT).unwrap();
            }
            std::fs::write(format!("{path}.hash"), world.state_hash().to_string()).unwrap();
            return;
        }
        #[cfg(feature = "portals")]
        let mut world = scenes::portal_drop(&scenes::shared_settings()).0.world;
        #[cfg(not(feature = "portals"))]
        let mut world = small_world();
        for _ in 0..40 {
            world.step(DT).unwrap();
        }
        let path =
            std::env::temp_dir().join(format!("janus2d-snapshot-{}.bin", std::process::id()));
        std::fs::write(&path, world.snapshot().to_bytes()).unwrap();
        let status = std::process::Command::new(std::env::current_exe().unwrap())
            .args([NAME, "--exact", "--test-threads", "1"])
            .env("JANUS_SNAPSHOT_CHILD", &path)
            .status()
            .unwrap();
        assert!(status.success());
        for _ in 0..60 {
            world.step(DT).unwrap();
        }
        let hash_path = format!("{}.hash", path.display());
        let child: u64 = std::fs::read_to_string(&hash_path)
            .unwrap()
            .parse()
            .unwrap();
        let _ = std::fs::remove_file(&path);
        let _ = std::fs::remove_file(&hash_path);
        assert_eq!(child, world.state_hash());
    }

    #[test]
    fn truncated_snapshot_bytes_are_a_typed_error() {
        let bytes = small_world().snapshot().to_bytes();
        for len in 0..bytes.len() {
            match Snapshot::from_bytes(&bytes[..len]) {
                Err(SnapshotError::Truncated { found, .. }) => assert_eq!(found, len),
                other => panic!("{len} bytes: {other:?}"),
            }
        }
    }

    #[test]
    fn corrupted_snapshot_bytes_are_a_typed_error() {
        let bytes = small_world().snapshot().to_bytes();
        // Every byte flipped in turn (header and payload).
        for k in 0..bytes.len() {
            let mut bad = bytes.clone();
            bad[k] ^= 0x5a;
            assert!(Snapshot::from_bytes(&bad).is_err(), "byte {k} flipped");
        }
        // A payload changed with its checksum fixed up still cannot panic:
        // garbage decodes to an error or to a world that fails validation.
        let mut bad = bytes.clone();
        for b in bad.iter_mut().skip(40).step_by(7) {
            *b = b.wrapping_mul(31).wrapping_add(7);
        }
        let payload = &bad[24..];
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in payload {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        bad[16..24].copy_from_slice(&h.to_le_bytes());
        assert!(matches!(
            Snapshot::from_bytes(&bad),
            Err(SnapshotError::Decode(_) | SnapshotError::Invalid(_))
        ));
    }

    #[test]
    fn wrong_version_snapshot_bytes_are_a_typed_error() {
        let mut bytes = small_world().snapshot().to_bytes();
        bytes[4..6].copy_from_slice(&(SNAPSHOT_VERSION + 1).to_le_bytes());
        assert_eq!(
            Snapshot::from_bytes(&bytes).unwrap_err(),
            SnapshotError::WrongVersion {
                found: SNAPSHOT_VERSION + 1,
                expected: SNAPSHOT_VERSION
            }
        );
        assert_eq!(
            Snapshot::from_bytes(b"not a snapshot at all, no").unwrap_err(),
            SnapshotError::BadMagic
        );
    }
}
