//! Headless benchmark of the standard scenes, timed as Box2D's benchmark
//! program does: a fresh world per repeat, step 0 untimed, steps 1..N−1 timed
//! as one block, the minimum over repeats reported.
//!
//! ```text
//! cargo bench --bench scenes -- large_pyramid            # 3 repeats
//! cargo bench --bench scenes -- all -r 1 --csv           # every scene, CSV
//! cargo bench --bench scenes -- pyramid20 -s 100         # other step count
//! cargo bench --bench scenes -- large_pyramid --sleep --warmup 600 -s 120   # settled, asleep
//! ```
//!
//! Put the numbers beside Box2D's from the same run:
//! `python3 ../shared/anchors/box2d_scenes.py large_pyramid`.

use std::time::Instant;

use janus2d::prelude::*;
use janus2d::scenes::{self, DT};

struct Args {
    scenes: Vec<String>,
    steps: usize,
    repeats: usize,
    csv: bool,
    substeps: Option<u32>,
    sleep: Option<bool>,
    warmup: usize,
}

fn parse_args() -> Args {
    let mut args = Args {
        scenes: Vec::new(),
        steps: 0,
        repeats: 3,
        csv: false,
        substeps: None,
        sleep: None,
        warmup: 0,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "-s" | "--steps" => {
                args.steps = it.next().and_then(|v| v.parse().ok()).expect("--steps N")
            }
            "-r" | "--repeats" => {
                args.repeats = it.next().and_then(|v| v.parse().ok()).expect("--repeats N")
            }
            "--substeps" => args.substeps = it.next().and_then(|v| v.parse().ok()),
            "--csv" => args.csv = true,
            "--sleep" => args.sleep = Some(true),
            "--no-sleep" => args.sleep = Some(false),
            "--warmup" => args.warmup = it.next().and_then(|v| v.parse().ok()).expect("--warmup N"),
            "--bench" => {}
            "all" => args
                .scenes
                .extend(scenes::NAMES.iter().map(|s| s.to_string())),
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
    let mut def = WorldDef::default();
    if let Some(n) = args.substeps {
        def.solver.substeps = n;
    }
    if args.csv {
        println!("scene,bodies,contacts,steps,repeats,min_total_ms,ms_per_step");
    } else {
        println!(
            "janus2d scenes: single thread, dt=1/60, {} substeps",
            def.solver.substeps
        );
    }
    for name in &args.scenes {
        // Sleep as scenes.md says: off except in `tumbler`, `spinner` and `smash`,
        // unless the command line says otherwise.
        let mut def = def.clone();
        def.sleep.enabled = args
            .sleep
            .unwrap_or(matches!(name.as_str(), "tumbler" | "spinner" | "smash"));
        let mut best = f64::MAX;
        let mut runs = Vec::new();
        let mut summary = String::new();
        let mut bodies = 0;
        let mut contacts = 0;
        let mut steps = 0;
        for _ in 0..args.repeats.max(1) {
            let mut scene =
                scenes::by_name(name, &def).unwrap_or_else(|| panic!("unknown scene {name}"));
            steps = if args.steps > 1 {
                args.steps
            } else {
                scene.steps
            };
            let start = scene.world.position(scene.probe).unwrap();
            for _ in 0..args.warmup {
                scene.world.step(DT).unwrap();
            }
            scene.world.step(DT).unwrap();
            let t0 = Instant::now();
            for _ in 1..steps {
                scene.world.step(DT).unwrap();
            }
            let ms = t0.elapsed().as_secs_f64() * 1000.0;
            runs.push(ms);
            best = best.min(ms);
            bodies = scene.world.body_count();
            contacts = scene.world.touching_contact_count();
            let end = scene.world.position(scene.probe).unwrap();
            let angle = scene.world.angle(scene.probe).unwrap();
            summary = format!(
                "  sanity {name}: bodies={bodies} contacts={contacts} sleeping={} {}: ({:.4}, {:.4}) -> ({:.4}, {:.4}) angle={:.4} rad",
                scene.world.sleeping_body_count(),
                scene.probe_label,
                start.x,
                start.y,
                end.x,
                end.y,
                angle
            );
        }
        let per_step = best / (steps - 1) as f64;
        if args.csv {
            println!(
                "{name},{bodies},{contacts},{steps},{},{best:.1},{per_step:.3}",
                args.repeats
            );
        } else {
            let runs: Vec<String> = runs.iter().map(|r| format!("{r:.1}")).collect();
            println!(
                "janus2d {name}: steps={steps} repeats={} min_total_ms={best:.1} ms_per_step={per_step:.3} runs_ms=[{}]",
                args.repeats,
                runs.join(", ")
            );
            println!("{summary}");
        }
    }
}
