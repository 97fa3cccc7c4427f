//! Determinism: the same inputs give bit-identical state. The golden hashes
//! pin the exact arithmetic; a change that alters them must say why.

/// The three hinged chains of the testbed's support module (limits,
/// springs, motors), 500 steps.
fn build_and_run() -> u64 {
    let mut world = janus2d_testbed::support::hinged_chains();
    for _ in 0..500 {
        world.step(1.0 / 60.0).unwrap();
    }
    world.state_hash()
}

#[test]
fn determinism_hash_is_stable_across_runs() {
    let a = build_and_run();
    let b = build_and_run();
    assert_eq!(a, b);
}

#[test]
fn determinism_hash_matches_golden_value() {
    let hash = build_and_run();
    // Issue 12: the joints' Gauss–Seidel rows (here the chains' limits,
    // springs and motors) are solved colour by colour, not in storage order.
    // Issue 33: the chains hang from pins, so the large errors their
    // limits and motors open are corrected on pseudo-velocities
    // (`joint_tree::VELOCITY_CORRECTION_SPEED`).
    // Stop 47: the f32 build reads joint angles through its own atan2
    // (`math::solver_atan2`, within 3e-7 rad), not the C library's.
    #[cfg(not(feature = "f64"))]
    let golden: u64 = 0x1674_75df_04fa_e925;
    #[cfg(feature = "f64")]
    let golden: u64 = 0x29e3_04c0_0c68_24a6;
    assert_eq!(
        hash, golden,
        "state hash {hash:#018x} differs from the golden value"
    );
}

/// Pyramid 20 plus the portal drop, 120 steps: a hash of every body. Both
/// worlds are below [`janus2d::world::TEAM_MIN_WORK`], so they are put on
/// the team (`set_team_min_work(0)`) for the thread-count check to reach
/// the parallel stages.
fn contact_scene_hash() -> u64 {
    let def = janus2d_testbed::scenes::shared_settings();
    let mut pyramid = janus2d_testbed::scenes::large_pyramid(&def, 20);
    pyramid.world.set_team_min_work(0);
    for _ in 0..120 {
        pyramid.world.step(1.0 / 60.0).unwrap();
    }
    #[cfg(feature = "portals")]
    {
        let (mut drop, _) = janus2d_testbed::scenes::portal_drop(&def);
        drop.world.set_team_min_work(0);
        for _ in 0..90 {
            drop.world.step(1.0 / 60.0).unwrap();
        }
        return pyramid.world.state_hash() ^ drop.world.state_hash().rotate_left(17);
    }
    #[allow(unreachable_code)]
    pyramid.world.state_hash()
}

#[test]
fn contact_scene_hash_is_stable_across_runs() {
    assert_eq!(contact_scene_hash(), contact_scene_hash());
}

/// A world below [`janus2d::world::TEAM_MIN_WORK`] steps on the calling
/// thread alone; put on a 2-thread team it must end in the same state, bit
/// for bit (pyramid 20, about 610 work: 210 boxes and their contacts).
#[cfg(feature = "parallel")]
#[test]
fn small_world_stepped_alone_or_on_the_team_is_identical() {
    let run = |team_min_work: usize| {
        on_threads(2, || {
            let def = janus2d_testbed::scenes::shared_settings();
            let mut pyramid = janus2d_testbed::scenes::large_pyramid(&def, 20);
            pyramid.world.set_team_min_work(team_min_work);
            for _ in 0..60 {
                pyramid.world.step(1.0 / 60.0).unwrap();
            }
            let work = pyramid.world.awake_body_count() + pyramid.world.awake_contact_count();
            assert!(
                work < janus2d::world::TEAM_MIN_WORK,
                "pyramid 20 is a small world ({work} work)"
            );
            pyramid.world.state_hash()
        })
    };
    assert_eq!(run(janus2d::world::TEAM_MIN_WORK), run(0));
}

/// With the `parallel` feature the narrowphase runs on rayon: the result
/// must not depend on the number of threads.
#[cfg(feature = "parallel")]
#[test]
fn contact_scene_is_identical_for_any_thread_count() {
    let run = |threads: usize| on_threads(threads, contact_scene_hash);
    let one = run(1);
    assert_eq!(run(2), one);
    assert_eq!(run(4), one);
}

/// Benchmark scenes large enough that every parallel stage takes its
/// threaded path (colours of many chunks, more than 1,024 bodies, hundreds
/// of moved proxies and new pairs, joint colours of many blocks): tumbler,
/// rain (joints and spawning), the washer and the joint grid, `steps` steps
/// each, a hash per scene.
#[cfg(feature = "parallel")]
fn benchmark_scene_hashes(steps: usize) -> Vec<u64> {
    use janus2d_testbed::engine::Engine;
    let mut hashes = Vec::new();
    for name in ["tumbler", "rain", "washer", "joint_grid"] {
        let desc = janus2d_testbed::benchmarks::by_name(name).expect("a benchmark scene");
        let mut engine = janus2d_testbed::janus::Janus::new(&desc).expect("scene builds");
        let mut actions = Vec::new();
        for step in 0..steps {
            desc.script.actions(step, desc.settings.dt, &mut actions);
            for a in &actions {
                engine.apply(a);
            }
            engine.step();
        }
        hashes.push(engine.world.state_hash());
    }
    hashes
}

/// The whole step on the worker team (solver colours, integration, pair
/// search, proxy boxes, narrowphase): bit-identical for 1, 2 and 4 threads.
/// The 40 steps hold the solve's first timed trial
/// (`janus2d::base::team_choice`): two of its steps solve on the leader
/// alone, the rest on the team, and the state must not show which.
#[cfg(feature = "parallel")]
#[test]
fn benchmark_scenes_are_identical_for_any_thread_count() {
    use janus2d::base::team_choice::{FIRST_WAIT, TRIAL_STEPS};
    const { assert!(FIRST_WAIT + TRIAL_STEPS <= 40) };
    let run = |threads: usize| on_threads(threads, || benchmark_scene_hashes(40));
    let one = run(1);
    assert_eq!(run(2), one, "2 threads");
    assert_eq!(run(4), one, "4 threads");
}

/// The large pyramid's first steps (over 4,096 awake contacts from the
/// second step, so that the solver's push counts, its planned prepare and
/// the impulse store take their paths for many contacts on a team):
/// bit-identical for 1, 2 and 4 threads. The store writes the warm starts
/// the next steps begin from, so a point it misses changes the state.
#[cfg(feature = "parallel")]
#[test]
fn many_contacts_stored_on_threads_are_identical_for_any_thread_count() {
    use janus2d_testbed::engine::Engine;
    let run = |threads: usize| {
        on_threads(threads, || {
            let desc =
                janus2d_testbed::benchmarks::by_name("large_pyramid").expect("a benchmark scene");
            let mut engine = janus2d_testbed::janus::Janus::new(&desc).expect("scene builds");
            let mut contacts = 0;
            for _ in 0..8 {
                engine.step();
                contacts = contacts.max(engine.world.contacts().count());
            }
            (engine.world.state_hash(), contacts)
        })
    };
    let one = run(1);
    assert!(one.1 > 4096, "{} contacts", one.1);
    assert_eq!(run(2), one, "2 threads");
    assert_eq!(run(4), one, "4 threads");
}

/// The snapshot bytes of two benchmark scenes whose proxies mostly move
/// (tumbler, washer: on two threads the proxy update goes by shape slot,
/// on one by body, so their move buffers fill in different orders), each
/// world continued from one snapshot of its first state (so the handles'
/// owner is the same), after 40 steps: the same bytes for 1, 2 and 4
/// threads. The state hash covers the bodies; the bytes also cover the
/// contacts, both trees and the broadphase's move buffer, which a
/// snapshot writes sorted.
#[cfg(all(feature = "parallel", feature = "serde"))]
#[test]
fn benchmark_snapshots_are_identical_for_any_thread_count() {
    use janus2d::prelude::BodyType;
    let starts: Vec<_> = ["tumbler", "washer"]
        .into_iter()
        .map(|name| {
            let desc = janus2d_testbed::benchmarks::by_name(name).expect("a benchmark scene");
            let mut engine = janus2d_testbed::janus::Janus::new(&desc).expect("scene builds");
            // Destroying every fifth body moves later bodies' states into
            // the holes, so state order is no longer shape slot order.
            for (k, &body) in engine.bodies.iter().enumerate() {
                if k % 5 == 2 && engine.world.body_type(body) == Ok(BodyType::Dynamic) {
                    engine.world.destroy_body(body).expect("a live body");
                }
            }
            (engine.world.snapshot().to_bytes(), desc.settings.dt)
        })
        .collect();
    let bytes = || {
        let mut out = Vec::new();
        for (start, dt) in &starts {
            let start = janus2d::world::Snapshot::from_bytes(start).expect("a snapshot's bytes");
            let mut world = start.to_world();
            for _ in 0..40 {
                world.step(*dt as janus2d::prelude::Real).unwrap();
            }
            out.push(world.snapshot().to_bytes());
        }
        out
    };
    let one = on_threads(1, bytes);
    for threads in [2, 4] {
        let other = on_threads(threads, bytes);
        for (k, (a, b)) in one.iter().zip(&other).enumerate() {
            assert_same_bytes(a, b, &format!("scene {k}, {threads} threads"));
        }
    }
}

/// A world restored from a snapshot continues as the original does, its
/// broadphase tree included: washer (most proxies move, so most steps
/// refit the tree and one in `TREE_REBUILD_PERIOD` rebuilds it) saved at
/// step 13 and decoded, then both stepped 20 more (past two rebuild
/// steps): the same snapshot bytes. A choice between refit and rebuild
/// kept outside the snapshot would give the restored world another tree.
#[cfg(feature = "serde")]
#[test]
fn a_restored_world_continues_with_the_original_tree() {
    const { assert!(janus2d::world::dynamic_tree::TREE_REBUILD_PERIOD <= 10) };
    let desc = janus2d_testbed::benchmarks::by_name("washer").expect("a benchmark scene");
    let mut original = janus2d_testbed::janus::Janus::new(&desc)
        .expect("scene builds")
        .world;
    let dt = desc.settings.dt as janus2d::prelude::Real;
    for _ in 0..13 {
        original.step(dt).unwrap();
    }
    let bytes = original.snapshot().to_bytes();
    let mut restored = janus2d::world::Snapshot::from_bytes(&bytes)
        .expect("a snapshot's bytes")
        .to_world();
    for _ in 0..20 {
        original.step(dt).unwrap();
        restored.step(dt).unwrap();
    }
    assert_same_bytes(
        &original.snapshot().to_bytes(),
        &restored.snapshot().to_bytes(),
        "restored",
    );
}

/// Asserts two snapshots' bytes are the same, naming the first payload
/// byte that differs (bytes 16..24 of the header are the payload's
/// checksum, so they differ whenever the payload does).
#[cfg(feature = "serde")]
fn assert_same_bytes(a: &[u8], b: &[u8], what: &str) {
    let first = a.iter().zip(b).skip(24).position(|(x, y)| x != y);
    assert!(
        a == b,
        "{what}: {} bytes against {}, first payload difference at {:?}",
        b.len(),
        a.len(),
        first.map(|p| p + 24)
    );
}

/// The testbed's every-joint-kind scene
/// ([`janus2d_testbed::support::every_joint_kind_world`]: 512 joints, so
/// the joint prepare and colours take their blocked paths on the team),
/// 120 steps: the hash of the final state.
fn every_joint_kind_hash() -> u64 {
    let mut world = janus2d_testbed::support::every_joint_kind_world();
    // Put on the team whatever its size (see `contact_scene_hash`).
    world.set_team_min_work(0);
    for _ in 0..120 {
        world.step(1.0 / 60.0).unwrap();
    }
    assert_eq!(world.validate(), Ok(()));
    world.state_hash()
}

#[test]
fn every_joint_kind_is_stable_across_runs() {
    assert_eq!(every_joint_kind_hash(), every_joint_kind_hash());
}

/// Every joint kind on the worker team: bit-identical for 1, 2 and 4
/// threads.
#[cfg(feature = "parallel")]
#[test]
fn every_joint_kind_is_identical_for_any_thread_count() {
    let run = |threads: usize| on_threads(threads, every_joint_kind_hash);
    let one = run(1);
    assert_eq!(run(2), one, "2 threads");
    assert_eq!(run(4), one, "4 threads");
}

/// The joints' end-of-step pass (threshold events, row counts) runs in
/// blocks on the team when a world has many joints: 50 hanging chains of
/// 50 links (2,500 revolute joints, 1 kg links, g = 10 m/s²), each joint
/// with a 250 N force threshold, so the upper half of every chain reports
/// an event as the chains take their weight. The events (handles, user
/// values, force and torque bits, in order) and the row counts are the
/// same for 1, 2 and 4 threads, and there are events to compare.
#[cfg(feature = "parallel")]
#[test]
fn joint_events_are_identical_for_any_thread_count() {
    use janus2d::prelude::*;
    let run = |threads: usize| {
        on_threads(threads, || {
            let mut def = janus2d::world::WorldDef::default();
            def.sleep.enabled = false;
            def.gravity = Vec2::new(0.0, -10.0);
            let mut world = World::new(def).unwrap();
            for chain in 0..50 {
                let x = 3.0 * chain as Real;
                let mut above = world
                    .create_body(&BodyDef::fixed(Vec2::new(x, 0.0)))
                    .unwrap();
                for link in 0..50 {
                    let y = -0.5 - link as Real;
                    let body = world
                        .create_body(&BodyDef::dynamic(Vec2::new(x, y)).with_mass(1.0, 0.1))
                        .unwrap();
                    let anchor_above = if link == 0 {
                        Vec2::ZERO
                    } else {
                        Vec2::new(0.0, -0.5)
                    };
                    let mut joint =
                        RevoluteJointDef::new(above, body, anchor_above, Vec2::new(0.0, 0.5));
                    joint.base.force_threshold = 250.0;
                    joint.base.user_data = (chain * 50 + link) as u64;
                    world.create_revolute_joint(&joint).unwrap();
                    above = body;
                }
            }
            let mut seen = Vec::new();
            let mut rows = Vec::new();
            for _ in 0..30 {
                world.step(1.0 / 60.0).unwrap();
                for e in &world.events().joints {
                    // (Handles carry their world's owner id: the
                    // user value names the joint across worlds.)
                    seen.push((
                        e.user_data,
                        e.force.x.to_bits(),
                        e.force.y.to_bits(),
                        e.torque.to_bits(),
                    ));
                }
                let c = world.counters();
                rows.push((c.joint_rows, c.direct_joint_rows));
            }
            (seen, rows)
        })
    };
    let one = run(1);
    assert!(
        one.0.len() >= 50 * 20,
        "the upper links of every chain report: {} events",
        one.0.len()
    );
    for threads in [2, 4] {
        let other = run(threads);
        assert!(
            other == one,
            "{threads} threads: {} events against {}",
            other.0.len(),
            one.0.len()
        );
    }
}

/// `f` run on a rayon pool of `threads` threads (the world's team is made
/// from the pool it is stepped on).
#[cfg(feature = "parallel")]
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
