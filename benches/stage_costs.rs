//! What the world's bookkeeping costs (run with
//! `cargo bench --bench stage_costs [-- STEPS]`):
//!
//! - `destroy_body` in a world of about 20,000 contacts (a 71 × 71 grid of
//!   touching balls, no gravity): the mean time of 200 calls;
//! - Box2D's `rain` scene: bodies awake at the end, and the mean time of a
//!   step that despawns and respawns a column of ragdolls beside the mean
//!   ordinary step (steps after the first 160). `DIRECT=0` turns the
//!   joint-tree solve off.
//! - Box2D's `large_pyramid` settled: the mean step once every body sleeps
//!   (sleep on) beside the mean step of the same settled pyramid with sleep
//!   off (the target: asleep costs at most 5% of awake).
//!
//! Timing lives here, never in tests; compare ratios within one run.
use janus2d::base::geometry::Circle;
use janus2d::prelude::{BodyDef, Real, Vec2};
use janus2d::world::{ShapeDef, World, WorldDef};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let steps: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
    // --- destroy_body in ~10k contacts
    let def = WorldDef {
        gravity: Vec2::ZERO,
        sleep: janus2d::world::SleepSettings {
            enabled: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut world = World::new(def).unwrap();
    let mut handles = Vec::new();
    let n = 71;
    for i in 0..n {
        for j in 0..n {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(
                    i as Real * 0.99,
                    j as Real * 0.99,
                )))
                .unwrap();
            world
                .create_shape(
                    b,
                    &ShapeDef::default(),
                    Circle::new(Vec2::ZERO, 0.5).unwrap(),
                )
                .unwrap();
            handles.push(b);
        }
    }
    world.step(1.0 / 60.0).unwrap();
    let contacts = world.contact_count();
    let k = 200;
    let t = Instant::now();
    for h in handles.iter().step_by(handles.len() / k).take(k) {
        world.destroy_body(*h).unwrap();
    }
    let per = t.elapsed().as_secs_f64() / k as f64;
    println!(
        "destroy_body: {contacts} contacts, {:.2} us per call",
        per * 1e6
    );
    // --- rain
    use janus2d_testbed::benchmarks::rain;
    use janus2d_testbed::engine::Engine;
    use janus2d_testbed::janus::Janus;
    let desc = rain();
    let mut wd = janus2d_testbed::janus::world_def(&desc.settings);
    if std::env::var("DIRECT").as_deref() == Ok("0") {
        wd.solver.direct_joints = false;
    }
    if let Some(hz) = std::env::var("DIRECT_HZ").ok().and_then(|s| s.parse().ok()) {
        wd.solver.direct_joint_hertz = hz;
    }
    let mut e = Janus::with_def(&desc, wd).unwrap();
    let mut buf = Vec::new();
    let (mut despawn, mut nd, mut ordinary, mut no) = (0.0, 0, 0.0, 0);
    for step in 0..steps {
        let t = Instant::now();
        janus2d_testbed::engine::scripted_step(&mut e, &desc, step, &mut buf);
        let dt = t.elapsed().as_secs_f64();
        if step % 100 == 99 {
            eprintln!("step {} awake {}", step + 1, e.awake_count());
        }
        let has_despawn = buf
            .iter()
            .any(|a| matches!(a, janus2d_testbed::desc::Action::Despawn { .. }));
        if has_despawn {
            despawn += dt;
            nd += 1;
        } else if step % 8 != 0 && step > 8 * 20 {
            ordinary += dt;
            no += 1;
        }
    }
    println!(
        "rain {steps} steps: bodies {} awake {} ; despawn step {:.3} ms ({nd}), ordinary {:.3} ms ({no}), ratio {:.2}",
        e.body_count(),
        e.awake_count(),
        despawn / nd.max(1) as f64 * 1e3,
        ordinary / no.max(1) as f64 * 1e3,
        (despawn / nd.max(1) as f64) / (ordinary / no.max(1) as f64)
    );
    settled_pyramid();
}

/// Mean ms/step of `large_pyramid` after `settle` steps, over `timed`
/// steps, with sleep on or off; and the awake body count at the end.
fn pyramid_after(sleep: bool, settle: usize, timed: usize) -> (f64, usize) {
    use janus2d_testbed::engine::Engine;
    use janus2d_testbed::janus::Janus;
    let desc = janus2d_testbed::benchmarks::by_name("large_pyramid").expect("a built-in scene");
    let mut wd = janus2d_testbed::janus::world_def(&desc.settings);
    wd.sleep.enabled = sleep;
    let mut e = Janus::with_def(&desc, wd).unwrap();
    for _ in 0..settle {
        e.step();
    }
    let t = Instant::now();
    for _ in 0..timed {
        e.step();
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / timed as f64;
    (ms, e.awake_count())
}

fn settled_pyramid() {
    let (settle, timed) = (600, 200);
    let (awake_ms, awake_n) = pyramid_after(false, settle, timed);
    let (asleep_ms, asleep_n) = pyramid_after(true, settle, timed);
    println!(
        "large_pyramid after {settle} steps: sleep off {awake_ms:.3} ms/step ({awake_n} awake), sleep on {asleep_ms:.4} ms/step ({asleep_n} awake): {:.1}% of awake",
        100.0 * asleep_ms / awake_ms
    );
}
