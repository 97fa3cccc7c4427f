//! `memory`: each engine's peak resident memory on each scene, one fresh
//! process per measurement.
//!
//! ```text
//!  parent (memory)                     child (memory-one ENGINE SCENE STEPS)
//!  for scene:                          one-thread pool, scene description,
//!    memory-one none  SCENE 0   ──▶      ENGINE built (none: nothing),
//!    memory-one E     SCENE N   ──▶      N scripted steps,
//!  table: peak − baseline, ratios      prints "MEMORY peak_kib bodies touching"
//! ```
//!
//! The peak is the kernel's `VmHWM` (high-water mark of the resident set)
//! read from `/proc/self/status`. The baseline child does everything the
//! others do but build an engine, so peak − baseline is what the engine
//! itself touched.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::Command;

use janus2d_testbed::benchmarks;
use janus2d_testbed::engine::{Engine, EngineOptions, scripted_step};
use janus2d_testbed::janus::Janus;

use crate::Args;
use crate::box2d::Box2d;
use crate::rapier::Rapier;

/// The line a child prints, followed by peak kB, bodies and touching pairs.
const TAG: &str = "MEMORY";

/// One child's figures.
#[derive(Clone, Copy)]
struct Reading {
    peak_kib: u64,
    bodies: usize,
    touching: usize,
}

/// This process's peak resident set size in kB (`VmHWM`), from `/proc/self/status`.
fn peak_kib() -> Result<u64, String> {
    let status = std::fs::read_to_string("/proc/self/status")
        .map_err(|e| format!("read /proc/self/status: {e}"))?;
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|rest| rest.trim().trim_end_matches("kB").trim().parse().ok())
        .ok_or_else(|| "no VmHWM in /proc/self/status".to_string())
}

/// Builds `E` on `desc`, runs `steps` scripted steps and returns its body and touching counts.
fn run<E: Engine>(
    desc: &janus2d_testbed::desc::SceneDesc,
    steps: usize,
) -> Result<(usize, usize), String> {
    let mut engine = E::build(desc, EngineOptions { threads: 1 })?;
    let mut buf = Vec::new();
    for k in 0..steps {
        scripted_step(&mut engine, desc, k, &mut buf);
    }
    Ok((engine.body_count(), engine.touching_count()))
}

/// `memory-one ENGINE SCENE STEPS` (hidden): one measurement in this process; `none` builds no engine.
pub fn cmd_memory_one(args: &Args) {
    let [engine, scene, steps] = &args.names[..] else {
        eprintln!("usage: memory-one ENGINE|none SCENE STEPS");
        std::process::exit(2);
    };
    let Ok(steps) = steps.parse::<usize>() else {
        eprintln!("memory-one: STEPS must be a number, not {steps}");
        std::process::exit(2);
    };
    let Some(desc) = benchmarks::by_name(scene) else {
        eprintln!("unknown scene {scene}");
        std::process::exit(2);
    };
    let pool = crate::pool(1);
    let counts = pool.install(|| match engine.to_ascii_lowercase().as_str() {
        "none" => Ok((0, 0)),
        "janus2d" => run::<Janus>(&desc, steps),
        "box2d" => run::<Box2d>(&desc, steps),
        "rapier" => run::<Rapier>(&desc, steps),
        other => Err(format!("unknown engine {other}")),
    });
    let (bodies, touching) = match counts {
        Ok(c) => c,
        Err(e) => {
            eprintln!("{engine} {scene}: {e}");
            std::process::exit(3);
        }
    };
    match peak_kib() {
        Ok(peak) => println!("{TAG} {peak} {bodies} {touching}"),
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(3);
        }
    }
}

/// Runs `memory-one ENGINE SCENE STEPS` as a fresh child of this binary and reads its line.
fn measure(engine: &str, scene: &str, steps: usize) -> Result<Reading, String> {
    let exe = std::env::current_exe().map_err(|e| format!("current_exe: {e}"))?;
    let output = Command::new(exe)
        .args(["memory-one", engine, scene, &steps.to_string()])
        .output()
        .map_err(|e| format!("spawn: {e}"))?;
    if !output.status.success() {
        return Err(format!(
            "child {}: {}",
            output.status,
            String::from_utf8_lossy(&output.stderr).trim()
        ));
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    let line = stdout
        .lines()
        .find_map(|l| l.strip_prefix(TAG))
        .ok_or_else(|| format!("no {TAG} line in the child's output"))?;
    let f: Vec<&str> = line.split_whitespace().collect();
    let parsed = |i: usize| f.get(i).and_then(|x| x.parse::<u64>().ok());
    match (parsed(0), parsed(1), parsed(2)) {
        (Some(peak_kib), Some(bodies), Some(touching)) => Ok(Reading {
            peak_kib,
            bodies: bodies as usize,
            touching: touching as usize,
        }),
        _ => Err(format!("unreadable line {TAG}{line}")),
    }
}

/// Kilobytes above the baseline (negative if the child's peak is below it).
fn above(r: &Reading, baseline_kib: u64) -> i64 {
    r.peak_kib as i64 - baseline_kib as i64
}

/// `memory`: peak resident memory above a baseline process for each scene and engine (one
/// thread, a fresh process each), as MiB, janus2d ÷ Box2D and bytes per body; writes `--csv`
/// (default `docs/performance/memory.csv`).
pub fn cmd_memory(args: &Args) {
    let names = args.scene_names();
    let csv_path = args
        .csv
        .clone()
        .unwrap_or_else(|| PathBuf::from("docs/performance/memory.csv"));
    println!(
        "memory: {} | steps {} | one thread, one process per scene and engine | peak RSS (VmHWM) − baseline",
        args.engines.join(", "),
        args.steps
            .map_or("scene's own".to_string(), |s| s.to_string()),
    );
    let mut header = format!("{:<14} {:>8}", "scene", "base MiB");
    for e in &args.engines {
        let _ = write!(header, " {:>11}", format!("{e} MiB"));
    }
    let _ = write!(header, " {:>8}", "j÷Box2D");
    for e in &args.engines {
        let _ = write!(header, " {:>13}", format!("{e} B/body"));
    }
    println!("{header}");
    let mut csv = String::from("scene,engine,peak_kib,baseline_kib,bodies,touching\n");
    let mut logs = (0.0f64, 0usize);
    for name in &names {
        let Some(desc) = benchmarks::by_name(name) else {
            eprintln!("unknown scene {name}");
            std::process::exit(2);
        };
        let steps = args.steps.unwrap_or(desc.steps);
        let baseline = match measure("none", name, 0) {
            Ok(r) => r.peak_kib,
            Err(e) => {
                println!("{name:<14} baseline failed: {e}");
                continue;
            }
        };
        let readings: Vec<(String, Option<Reading>)> = args
            .engines
            .iter()
            .map(|engine| {
                let r = measure(engine, name, steps);
                if let Err(e) = &r {
                    eprintln!("{name} {engine}: {e}");
                }
                (engine.clone(), r.ok())
            })
            .collect();
        let of = |e: &str| {
            readings
                .iter()
                .find(|(engine, _)| engine == e)
                .and_then(|(_, r)| *r)
        };
        let mut line = format!("{name:<14} {:>8.1}", baseline as f64 / 1024.0);
        for (_, r) in &readings {
            match r {
                Some(r) => {
                    let _ = write!(line, " {:>11.1}", above(r, baseline) as f64 / 1024.0);
                }
                None => {
                    let _ = write!(line, " {:>11}", "-");
                }
            }
        }
        let ratio = match (of("janus2d"), of("Box2D")) {
            (Some(j), Some(b)) if above(&b, baseline) > 0 => {
                let x = above(&j, baseline) as f64 / above(&b, baseline) as f64;
                if x > 0.0 {
                    logs.0 += x.ln();
                    logs.1 += 1;
                }
                format!("{x:.2}")
            }
            _ => "-".to_string(),
        };
        let _ = write!(line, " {ratio:>8}");
        for (_, r) in &readings {
            match r {
                Some(r) if r.bodies > 0 => {
                    let per_body = above(r, baseline) as f64 * 1024.0 / r.bodies as f64;
                    let _ = write!(line, " {per_body:>13.0}");
                }
                _ => {
                    let _ = write!(line, " {:>13}", "-");
                }
            }
        }
        println!("{line}");
        for (engine, r) in &readings {
            if let Some(r) = r {
                let _ = writeln!(
                    csv,
                    "{name},{engine},{},{baseline},{},{}",
                    r.peak_kib, r.bodies, r.touching
                );
            }
        }
    }
    if logs.1 > 0 {
        println!(
            "janus2d ÷ Box2D, geometric mean over {} scenes: {:.2}",
            logs.1,
            (logs.0 / logs.1 as f64).exp()
        );
    }
    // (Run from elsewhere than the repository's root, the default folder
    // may not exist: made, or the failure reported after the table.)
    if let Some(dir) = csv_path.parent().filter(|d| !d.as_os_str().is_empty()) {
        let _ = std::fs::create_dir_all(dir);
    }
    match std::fs::write(&csv_path, csv) {
        Ok(()) => println!("wrote {}", csv_path.display()),
        Err(e) => eprintln!("could not write {}: {e}", csv_path.display()),
    }
}
