//! Headless benchmark of the standard scenes on janus2d alone, timed as
//! Box2D's benchmark program does (a fresh world per repeat, step 0
//! untimed, steps 1..N−1 timed as one block, the minimum over repeats),
//! with the scenes built from the shared descriptions
//! (`janus2d_testbed::benchmarks`). For Box2D and Rapier in the same run use
//! the peers benchmark: `cargo run --release --manifest-path
//! benches/peers/Cargo.toml -- all`.
//!
//! ```text
//! cargo bench --bench scenes -- large_pyramid            # 3 repeats
//! cargo bench --bench scenes -- all -r 1 --csv           # every scene, CSV
//! cargo bench --bench scenes -- pyramid20 -s 100         # other step count
//! cargo bench --bench scenes -- tumbler --no-sleep --substeps 8
//! ```

use janus2d_testbed::benchmarks::{self, NAMES};
use janus2d_testbed::engine::EngineOptions;
use janus2d_testbed::janus::Janus;
use janus2d_testbed::run::time_scene;

struct Args {
    scenes: Vec<String>,
    steps: Option<usize>,
    repeats: usize,
    csv: bool,
    substeps: Option<u32>,
    sleep: Option<bool>,
}

fn parse_args() -> Args {
    let mut args = Args {
        scenes: Vec::new(),
        steps: None,
        repeats: 3,
        csv: false,
        substeps: None,
        sleep: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "-s" | "--steps" => args.steps = it.next().and_then(|v| v.parse().ok()),
            "-r" | "--repeats" => {
                args.repeats = it.next().and_then(|v| v.parse().ok()).expect("--repeats N")
            }
            "--substeps" => args.substeps = it.next().and_then(|v| v.parse().ok()),
            "--csv" => args.csv = true,
            "--sleep" => args.sleep = Some(true),
            "--no-sleep" => args.sleep = Some(false),
            "--bench" => {}
            "all" => args.scenes.extend(NAMES.iter().map(|s| s.to_string())),
            name if !name.starts_with('-') => args.scenes.push(name.to_string()),
            other => panic!("unknown option {other}"),
        }
    }
    if args.scenes.is_empty() {
        args.scenes.push("large_pyramid".to_string());
    }
    args
}

fn main() {
    let args = parse_args();
    if args.csv {
        println!("scene,bodies,contacts,steps,repeats,min_total_ms,ms_per_step");
    } else {
        println!(
            "janus2d scenes: single thread, dt=1/60, scene settings (sleep as Box2D's benchmark)"
        );
    }
    for name in &args.scenes {
        let Some(mut desc) = benchmarks::by_name(name) else {
            eprintln!("unknown scene {name}; known: {}", NAMES.join(", "));
            std::process::exit(2);
        };
        if cfg!(not(feature = "portals")) && !desc.portals.is_empty() {
            continue;
        }
        if let Some(n) = args.substeps {
            desc.settings.substeps = n;
        }
        if let Some(s) = args.sleep {
            desc.settings.sleep = s;
        }
        let t = time_scene::<Janus>(&desc, EngineOptions::default(), args.repeats, args.steps)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let s = &t.sanity;
        if args.csv {
            println!(
                "{name},{},{},{},{},{:.1},{:.3}",
                s.bodies,
                s.touching,
                t.timed_steps + 1,
                args.repeats,
                t.total_ms,
                t.ms_per_step()
            );
        } else {
            println!(
                "janus2d {name}: steps={} repeats={} min_total_ms={:.1} ms_per_step={:.3}",
                t.timed_steps + 1,
                args.repeats,
                t.total_ms,
                t.ms_per_step()
            );
            let probe = s.probe.map_or(String::new(), |p| {
                format!(
                    " {} ({:.3}, {:.3}) angle {:.3}",
                    desc.probe_label, p.position.x, p.position.y, p.angle
                )
            });
            println!(
                "  sanity: bodies={} awake={} touching={}{probe}",
                s.bodies, s.awake, s.touching
            );
            // Box2D's reference figures hold after the scene's full run only.
            for flag in s.flags(&desc).into_iter().filter(|_| args.steps.is_none()) {
                println!("  differs from Box2D: {flag}");
            }
        }
    }
}
