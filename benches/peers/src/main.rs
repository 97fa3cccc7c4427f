//! janus2d beside Box2D v3 (through `boxdd`) and Rapier (through
//! `rapier2d`), on the same scene descriptions, in one run.
//!
//! ```text
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- all            # ten scenes, 1 and 2 threads
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- all --steps 5 --repeats 1   # smoke (CI)
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- profile large_pyramid tumbler
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- hard           # hard cases, pass/fail per engine
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- sweep          # substeps 1, 2, 4, 8 per engine
//! cargo run --release --manifest-path benches/peers/Cargo.toml -- joints         # joint scenes: time ratios and accuracy
//! ```
//!
//! | command   | prints                                                                 |
//! |-----------|------------------------------------------------------------------------|
//! | `all`     | per scene and engine: ms/step, ratio to Box2D, touching, awake, bodies, probe pose, bodies outside the container; figures off Box2D's flagged |
//! | `profile` | per-stage ms/step side by side, averaged over the timed steps          |
//! | `hard`    | every hard case on every engine, measured by the shared metric code (`--substeps N`: at N substeps instead of 4) |
//! | `sweep`   | error against ms/step at 1, 2, 4, 8 substeps, per engine (CSV + SVG)   |
//! | `chart`   | `chart RUN.csv CHART.svg`: the ratio chart redrawn from an `all --csv` file |
//! | `joints`  | the joint scenes (weld cantilever, car, elevator, spring bridge): ms/step and ratios, each engine's accuracy figures side by side; an engine without the scene's joint kind shows `n/a` (`--substeps N`, `--md FILE`) |
//! | `memory`  | per scene and engine (one thread, a fresh child process each): peak resident memory (VmHWM) minus a baseline process, janus2d ÷ Box2D, bytes per body (`--csv`, default `docs/performance/memory.csv`) |
//!
//! Options: `--threads 1,2` (`all`, `profile`; `scaling` runs each count
//! given, one thread by default; `hard` and `sweep` run every engine on the
//! first count given, one thread by default), `--repeats N` (default 2), `--steps N`,
//! `--scenes a,b`, `--engines janus2d,box2d,rapier`, `--csv FILE`,
//! `--svg FILE` (bar chart of the ratios), `--out DIR` (sweep output).
//! Build with `--features simd-avx2` and `RUSTFLAGS="-C target-cpu=x86-64-v3"`
//! for Box2D's AVX2 build beside janus2d's x86-64-v3 build.

mod box2d;
mod manifolds;
mod memory;
mod rapier;

use std::fmt::Write as _;
use std::path::PathBuf;

use janus2d_testbed::benchmarks::{self, BOX2D_TEN};
use janus2d_testbed::engine::{EngineOptions, StageTimes};
use janus2d_testbed::hard::{self, Bound, Figure, HardCase};
use janus2d_testbed::janus::Janus;
use janus2d_testbed::joint_bench::{self, JointFigures, JointScene};
use janus2d_testbed::run::{Timing, time_scene};
use plotters::prelude::*;

use box2d::Box2d;
use rapier::Rapier;

/// Box2D first: the others are compared with its figures of the same run.
const ENGINES: [&str; 3] = ["Box2D", "janus2d", "Rapier"];

#[derive(Clone)]
struct Args {
    command: String,
    names: Vec<String>,
    threads: Vec<usize>,
    /// Whether `--threads` was on the command line (the hard cases, the
    /// sweep and the scaling run default to one thread).
    threads_given: bool,
    repeats: usize,
    steps: Option<usize>,
    substeps: Option<u32>,
    engines: Vec<String>,
    csv: Option<PathBuf>,
    svg: Option<PathBuf>,
    md: Option<PathBuf>,
    out: PathBuf,
}

impl Args {
    /// The scenes named on the command line, or Box2D's ten.
    fn scene_names(&self) -> Vec<String> {
        if self.names.is_empty() {
            BOX2D_TEN.iter().map(|s| s.to_string()).collect()
        } else {
            self.names.clone()
        }
    }
}

fn parse_args() -> Args {
    let mut args = Args {
        command: "all".into(),
        names: Vec::new(),
        threads: vec![1, 2],
        threads_given: false,
        repeats: 2,
        steps: None,
        substeps: None,
        engines: ENGINES.iter().map(|s| s.to_string()).collect(),
        csv: None,
        svg: None,
        md: None,
        out: PathBuf::from("docs/accuracy"),
    };
    let list = |s: Option<String>| -> Vec<String> {
        s.unwrap_or_default()
            .split(',')
            .filter(|x| !x.is_empty())
            .map(str::to_string)
            .collect()
    };
    let mut it = std::env::args().skip(1);
    let mut first = true;
    while let Some(a) = it.next() {
        match a.as_str() {
            "--threads" => {
                args.threads_given = true;
                args.threads = list(it.next())
                    .iter()
                    .map(|t| t.parse().expect("--threads 1,2"))
                    .collect()
            }
            "--repeats" | "-r" => {
                args.repeats = it.next().and_then(|v| v.parse().ok()).expect("--repeats N")
            }
            "--steps" | "-s" => args.steps = it.next().and_then(|v| v.parse().ok()),
            "--substeps" => args.substeps = it.next().and_then(|v| v.parse().ok()),
            "--scenes" => args.names = list(it.next()),
            "--engines" => args.engines = list(it.next()),
            "--csv" => args.csv = it.next().map(PathBuf::from),
            "--svg" => args.svg = it.next().map(PathBuf::from),
            "--md" => args.md = it.next().map(PathBuf::from),
            "--out" => args.out = it.next().map(PathBuf::from).expect("--out DIR"),
            cmd if first
                && matches!(
                    cmd,
                    "all"
                        | "profile"
                        | "hard"
                        | "sweep"
                        | "chart"
                        | "joints"
                        | "scaling"
                        | "memory"
                        | "memory-one"
                        | "manifolds"
                ) =>
            {
                args.command = cmd.into()
            }
            name if !name.starts_with('-') => args.names.push(name.into()),
            other => {
                eprintln!("unknown option {other}");
                std::process::exit(2);
            }
        }
        first = false;
    }
    args.engines = args
        .engines
        .iter()
        .filter_map(|e| {
            ENGINES
                .iter()
                .find(|k| k.eq_ignore_ascii_case(e))
                .map(|k| k.to_string())
        })
        .collect();
    args
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
}

/// Times one scene on one engine with `threads` workers.
fn time_on(
    engine: &str,
    desc: &janus2d_testbed::desc::SceneDesc,
    threads: usize,
    args: &Args,
) -> Result<Timing, String> {
    let options = EngineOptions { threads };
    pool(threads).install(|| match engine {
        "janus2d" => time_scene::<Janus>(desc, options, args.repeats, args.steps),
        "Box2D" => time_scene::<Box2d>(desc, options, args.repeats, args.steps),
        _ => time_scene::<Rapier>(desc, options, args.repeats, args.steps),
    })
}

struct Row {
    scene: String,
    engine: String,
    threads: usize,
    timing: Timing,
    flags: Vec<String>,
}

fn cmd_all(args: &Args) {
    let names = args.scene_names();
    println!(
        "peers: {} | repeats {} | steps {} | threads {:?} | build: {}",
        args.engines.join(", "),
        args.repeats,
        args.steps
            .map_or("scene's own".to_string(), |s| s.to_string()),
        args.threads,
        build_label()
    );
    println!(
        "{:<14} {:<8} {:>3} {:>10} {:>9} {:>7} {:>8} {:>7} {:>7}  {:<30} {:>7}  flags",
        "scene",
        "engine",
        "thr",
        "total ms",
        "ms/step",
        "×Box2D",
        "touching",
        "awake",
        "bodies",
        "probe (x, y, angle)",
        "outside"
    );
    let mut rows: Vec<Row> = Vec::new();
    for name in &names {
        let Some(desc) = benchmarks::by_name(name) else {
            eprintln!("unknown scene {name}");
            std::process::exit(2);
        };
        for &threads in &args.threads {
            let first = rows.len();
            for engine in &args.engines {
                let timing = match time_on(engine, &desc, threads, args) {
                    Ok(t) => t,
                    Err(e) => {
                        println!("{name:<14} {engine:<8} {threads:>3}  skipped: {e}");
                        continue;
                    }
                };
                // Box2D's row is checked against its stored figures (they
                // hold after the scene's full run only); the others against
                // Box2D's row of this run, when there is one.
                let box2d_now = rows[first..]
                    .iter()
                    .find(|r| r.engine == "Box2D")
                    .map(|r| r.timing.sanity.as_reference());
                let flags = match box2d_now {
                    Some(reference) if engine != "Box2D" => timing.sanity.flags_against(&reference),
                    _ if args.steps.is_none() => timing.sanity.flags(&desc),
                    _ => Vec::new(),
                };
                rows.push(Row {
                    scene: name.clone(),
                    engine: engine.clone(),
                    threads,
                    timing,
                    flags,
                });
            }
            for r in &rows[first..] {
                let ratio = ratio_of(&rows, name, threads, &r.engine, "Box2D")
                    .map_or(String::new(), |x| format!("{x:.2}"));
                let s = &r.timing.sanity;
                let probe = s.probe.map_or("-".to_string(), |p| {
                    format!("({:.3}, {:.3}, {:.3})", p.position.x, p.position.y, p.angle)
                });
                println!(
                    "{name:<14} {:<8} {threads:>3} {:>10.1} {:>9.3} {ratio:>7} {:>8} {:>7} {:>7}  {probe:<30} {:>7}  {}",
                    r.engine,
                    r.timing.total_ms,
                    r.timing.ms_per_step(),
                    s.touching,
                    s.awake,
                    s.bodies,
                    s.outside.map_or("-".to_string(), |n| n.to_string()),
                    if r.flags.is_empty() {
                        String::new()
                    } else {
                        format!("DIFFERS: {}", r.flags.join("; "))
                    }
                );
            }
        }
    }
    print_ratios(&rows, &names, &args.threads);
    if let Some(path) = &args.csv {
        let mut csv = String::from(
            "scene,engine,threads,total_ms,ms_per_step,touching,awake,bodies,probe_x,probe_y,probe_angle,outside,flags\n",
        );
        for r in &rows {
            let s = &r.timing.sanity;
            let p = s.probe.unwrap_or_default();
            let _ = writeln!(
                csv,
                "{},{},{},{:.2},{:.4},{},{},{},{:.4},{:.4},{:.4},{},{}",
                r.scene,
                r.engine,
                r.threads,
                r.timing.total_ms,
                r.timing.ms_per_step(),
                s.touching,
                s.awake,
                s.bodies,
                p.position.x,
                p.position.y,
                p.angle,
                s.outside.map_or(String::new(), |n| n.to_string()),
                r.flags.join("; ")
            );
        }
        std::fs::write(path, csv).expect("write csv");
        println!("wrote {}", path.display());
    }
    if let Some(path) = &args.md {
        std::fs::write(path, markdown_table(&rows)).expect("write markdown");
        println!("wrote {}", path.display());
    }
    if let Some(path) = &args.svg {
        bar_chart(&rows, &names, &args.threads, path).expect("draw chart");
        println!("wrote {}", path.display());
    }
}

/// The table as Markdown (for docs/performance.md).
fn markdown_table(rows: &[Row]) -> String {
    let mut md = String::from(
        "| scene | engine | threads | ms/step | ÷ Box2D | touching | awake | bodies | probe (x, y, angle) | outside | differs from Box2D |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let s = &r.timing.sanity;
        let ratio = ratio_of(rows, &r.scene, r.threads, &r.engine, "Box2D")
            .map_or(String::new(), |x| format!("{x:.2}"));
        let probe = s.probe.map_or("–".to_string(), |p| {
            format!("({:.3}, {:.3}, {:.3})", p.position.x, p.position.y, p.angle)
        });
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {ratio} | {} | {} | {} | {probe} | {} | {} |",
            r.scene,
            r.engine,
            r.threads,
            r.timing.ms_per_step(),
            s.touching,
            s.awake,
            s.bodies,
            s.outside.map_or("–".to_string(), |n| n.to_string()),
            r.flags.join("; ")
        );
    }
    md
}

fn build_label() -> String {
    let avx2 = cfg!(feature = "simd-avx2");
    let v3 = cfg!(target_feature = "avx2");
    format!(
        "Box2D {}, janus2d/Rapier {}",
        if avx2 {
            "AVX2 (simd-avx2)"
        } else {
            "SSE2 (default)"
        },
        if v3 { "x86-64-v3" } else { "x86-64 (default)" }
    )
}

fn ratio_of(rows: &[Row], scene: &str, threads: usize, engine: &str, peer: &str) -> Option<f64> {
    let get = |e: &str| {
        rows.iter()
            .find(|r| r.scene == scene && r.threads == threads && r.engine == e)
            .map(|r| r.timing.ms_per_step())
    };
    Some(get(engine)? / get(peer)?)
}

fn print_ratios(rows: &[Row], names: &[String], threads: &[usize]) {
    println!("\nratios (ms/step, one run): janus2d ÷ Box2D, janus2d ÷ Rapier, Rapier ÷ Box2D");
    for &t in threads {
        let mut logs = [0.0f64; 3];
        let mut n = [0usize; 3];
        for name in names {
            let r = [
                ratio_of(rows, name, t, "janus2d", "Box2D"),
                ratio_of(rows, name, t, "janus2d", "Rapier"),
                ratio_of(rows, name, t, "Rapier", "Box2D"),
            ];
            let fmt = |x: Option<f64>| x.map_or("   -".to_string(), |x| format!("{x:.2}"));
            println!(
                "  {t} thr  {name:<14} {:>6} {:>6} {:>6}",
                fmt(r[0]),
                fmt(r[1]),
                fmt(r[2])
            );
            for k in 0..3 {
                if let Some(x) = r[k] {
                    logs[k] += x.ln();
                    n[k] += 1;
                }
            }
        }
        let g = |k: usize| {
            if n[k] > 0 {
                format!("{:.2}", (logs[k] / n[k] as f64).exp())
            } else {
                "-".into()
            }
        };
        println!(
            "  {t} thr  {:<14} {:>6} {:>6} {:>6}",
            "geometric mean",
            g(0),
            g(1),
            g(2)
        );
    }
}

fn bar_chart(
    rows: &[Row],
    names: &[String],
    threads: &[usize],
    path: &PathBuf,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (960, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let series: Vec<(String, usize, &str, RGBColor)> = threads
        .iter()
        .flat_map(|&t| {
            [
                (
                    format!("janus2d ÷ Box2D, {t} thr"),
                    t,
                    "Box2D",
                    if t == 1 {
                        RGBColor(31, 119, 180)
                    } else {
                        RGBColor(158, 202, 225)
                    },
                ),
                (
                    format!("janus2d ÷ Rapier, {t} thr"),
                    t,
                    "Rapier",
                    if t == 1 {
                        RGBColor(214, 39, 40)
                    } else {
                        RGBColor(252, 174, 145)
                    },
                ),
            ]
        })
        .collect();
    let max = rows
        .iter()
        .filter_map(|r| ratio_of(rows, &r.scene, r.threads, "janus2d", "Box2D"))
        .chain(
            rows.iter()
                .filter_map(|r| ratio_of(rows, &r.scene, r.threads, "janus2d", "Rapier")),
        )
        .fold(1.5f64, f64::max);
    let groups = names.len();
    let width = series.len() as f64 + 1.0;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "janus2d time per step relative to its peers (< 1: janus2d faster)",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(60)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..groups as f64 * width, 0.0..max * 1.4)?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc("ratio of ms/step")
        .draw()?;
    for (gi, name) in names.iter().enumerate() {
        let x = gi as f64 * width + width / 2.0;
        chart.draw_series(std::iter::once(Text::new(
            name.clone(),
            (x - 0.4 * width, -0.05 * max),
            ("sans-serif", 12),
        )))?;
    }
    for (si, (label, t, peer, color)) in series.iter().enumerate() {
        let bars: Vec<_> = names
            .iter()
            .enumerate()
            .filter_map(|(gi, name)| {
                let r = ratio_of(rows, name, *t, "janus2d", peer)?;
                let x0 = gi as f64 * width + 0.5 + si as f64;
                Some(Rectangle::new([(x0, 0.0), (x0 + 0.9, r)], color.filled()))
            })
            .collect();
        let c = *color;
        chart
            .draw_series(bars)?
            .label(label.clone())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], c.filled()));
    }
    chart.draw_series(LineSeries::new(
        [(0.0, 1.0), (groups as f64 * width, 1.0)],
        BLACK.stroke_width(1),
    ))?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    root.present()?;
    Ok(())
}

/// `chart CSV SVG`: redraws the ratio chart from a CSV that `all --csv`
/// wrote, without running anything.
fn cmd_chart(args: &Args) {
    let [csv, svg] = &args.names[..] else {
        eprintln!("usage: chart RUN.csv CHART.svg");
        std::process::exit(2);
    };
    let text = std::fs::read_to_string(csv).expect("read csv");
    let mut rows = Vec::new();
    let mut names: Vec<String> = Vec::new();
    let mut threads: Vec<usize> = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (Some(scene), Some(engine), Some(t), Some(ms)) =
            (f.first(), f.get(1), f.get(2), f.get(4))
        else {
            continue;
        };
        let (Ok(t), Ok(ms)) = (t.parse::<usize>(), ms.parse::<f64>()) else {
            continue;
        };
        if !names.iter().any(|n| n == scene) {
            names.push(scene.to_string());
        }
        if !threads.contains(&t) {
            threads.push(t);
        }
        rows.push(Row {
            scene: scene.to_string(),
            engine: engine.to_string(),
            threads: t,
            timing: Timing {
                total_ms: ms,
                timed_steps: 1,
                ..Timing::default()
            },
            flags: Vec::new(),
        });
    }
    bar_chart(&rows, &names, &threads, &PathBuf::from(svg)).expect("draw chart");
    println!("wrote {svg}");
}

/// The scenes of the scaling run: the large pyramid at 5, 10, 20, 30,
/// 40, 50, 100 and 200 rows, and many_pyramids at 1/4, 1/2, 1 and 2 times its count
/// (5, 10, 20 and 40 rows of 20 pyramids).
fn scaling_scenes() -> Vec<(&'static str, usize, janus2d_testbed::desc::SceneDesc)> {
    let mut out = Vec::new();
    for rows in [5, 10, 20, 30, 40, 50, 100, 200] {
        out.push(("large_pyramid", rows, benchmarks::pyramid(rows)));
    }
    for rows in [5, 10, 20, 40] {
        out.push((
            "many_pyramids",
            rows,
            benchmarks::many_pyramids_of(rows, 20),
        ));
    }
    out
}

/// `scaling`: ms per step and µs per body per step of each engine on the
/// scaling scenes, in one run, on one thread (or on each count of
/// `--threads` when given; the chart plots one thread); prints a table, writes
/// `--csv` (default `docs/performance/scaling.csv`) and `--svg` (default
/// `docs/performance/scaling.svg`). `--steps` (default 120) timed steps
/// each, best of `--repeats`.
fn cmd_scaling(args: &Args) {
    let steps = args.steps.unwrap_or(120);
    // `--scenes large_pyramid,many_pyramids:10` picks families or sizes.
    let scenes: Vec<_> = scaling_scenes()
        .into_iter()
        .filter(|(family, size, _)| {
            args.names.is_empty()
                || args
                    .names
                    .iter()
                    .any(|n| n == family || *n == format!("{family}:{size}"))
        })
        .collect();
    let thread_counts = if args.threads_given {
        args.threads.clone()
    } else {
        vec![1]
    };
    println!(
        "scaling: {} | {} steps, best of {} | threads {:?}",
        args.engines.join(", "),
        steps,
        args.repeats,
        thread_counts
    );
    println!(
        "{:<14} {:>5} {:>7} {:>3} {}",
        "family",
        "size",
        "bodies",
        "thr",
        args.engines
            .iter()
            .map(|e| format!("{:>10} {:>8}", format!("{e} ms"), "µs/body"))
            .collect::<Vec<_>>()
            .join(" ")
            + "  janus2d ÷ Box2D"
    );
    // (family, size, bodies, engine, ms per step), one thread only: the
    // chart plots the cost per body of one thread.
    let mut points: Vec<(&str, usize, usize, String, f64)> = Vec::new();
    let mut csv = String::from("family,size,bodies,threads,engine,ms_per_step,us_per_body\n");
    for (family, size, desc) in &scenes {
        let bodies = desc
            .bodies
            .iter()
            .filter(|b| b.kind == janus2d_testbed::desc::BodyKind::Dynamic)
            .count();
        for &threads in &thread_counts {
            let mut line = format!("{family:<14} {size:>5} {bodies:>7} {threads:>3}");
            let mut ms_of = std::collections::BTreeMap::new();
            for engine in &args.engines {
                let ms = match time_on(
                    engine,
                    desc,
                    threads,
                    &Args {
                        steps: Some(steps),
                        ..args.clone()
                    },
                ) {
                    Ok(t) => t.ms_per_step(),
                    Err(e) => {
                        eprintln!("{engine} {family} {size}: {e}");
                        f64::NAN
                    }
                };
                let per_body = 1e3 * ms / bodies.max(1) as f64;
                let _ = write!(line, " {ms:>10.3} {per_body:>8.3}");
                let _ = writeln!(
                    csv,
                    "{family},{size},{bodies},{threads},{engine},{ms:.4},{per_body:.4}"
                );
                ms_of.insert(engine.clone(), ms);
                if threads == 1 {
                    points.push((family, *size, bodies, engine.clone(), ms));
                }
            }
            if let (Some(j), Some(b)) = (ms_of.get("janus2d"), ms_of.get("Box2D")) {
                let _ = write!(line, "  {:.2}", j / b);
            }
            println!("{line}");
        }
    }
    let csv_path = args
        .csv
        .clone()
        .unwrap_or_else(|| PathBuf::from("docs/performance/scaling.csv"));
    let svg_path = args
        .svg
        .clone()
        .unwrap_or_else(|| PathBuf::from("docs/performance/scaling.svg"));
    if let Err(e) = std::fs::write(&csv_path, csv) {
        eprintln!("write {}: {e}", csv_path.display());
    }
    match scaling_chart(&points, &svg_path) {
        Ok(()) => println!("wrote {} and {}", csv_path.display(), svg_path.display()),
        Err(e) => eprintln!("chart: {e}"),
    }
}

/// µs per body per step against bodies (log scale), one line per family
/// and engine.
fn scaling_chart(
    points: &[(&str, usize, usize, String, f64)],
    path: &PathBuf,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (960, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let per_body = |p: &(&str, usize, usize, String, f64)| 1e3 * p.4 / p.2.max(1) as f64;
    let max_y = points
        .iter()
        .map(per_body)
        .filter(|v| v.is_finite())
        .fold(0.1f64, f64::max);
    let (min_x, max_x) = points.iter().fold((f64::MAX, 1.0f64), |(lo, hi), p| {
        (lo.min(p.2 as f64), hi.max(p.2 as f64))
    });
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "cost per body as the scene grows (one thread; flat or falling: the cost grows no faster than the scene)",
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d((min_x * 0.8..max_x * 1.25).log_scale(), 0.0..max_y * 1.15)?;
    chart
        .configure_mesh()
        .x_desc("dynamic bodies")
        .y_desc("µs per body per step")
        .draw()?;
    let colour = |engine: &str| match engine {
        "Box2D" => RGBColor(31, 119, 180),
        "janus2d" => RGBColor(44, 160, 44),
        _ => RGBColor(214, 39, 40),
    };
    for family in ["large_pyramid", "many_pyramids"] {
        for engine in ENGINES {
            let line: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.0 == family && p.3 == engine && p.4.is_finite())
                .map(|p| (p.2 as f64, per_body(p)))
                .collect();
            if line.is_empty() {
                continue;
            }
            let c = colour(engine);
            let style = if family == "large_pyramid" {
                ShapeStyle::from(&c).stroke_width(2)
            } else {
                ShapeStyle::from(&c.mix(0.5)).stroke_width(2)
            };
            chart
                .draw_series(LineSeries::new(line.clone(), style))?
                .label(format!("{engine}, {family}"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            chart.draw_series(
                line.iter()
                    .map(|&(x, y)| Circle::new((x, y), 3, c.filled())),
            )?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

fn cmd_profile(args: &Args) {
    let names: Vec<String> = if args.names.is_empty() {
        ["large_pyramid", "many_pyramids", "tumbler"]
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        args.names.clone()
    };
    let threads = args.threads.first().copied().unwrap_or(1);
    for name in &names {
        let Some(desc) = benchmarks::by_name(name) else {
            eprintln!("unknown scene {name}");
            std::process::exit(2);
        };
        let mut columns: Vec<(String, StageTimes)> = Vec::new();
        for engine in &args.engines {
            if let Ok(t) = time_on(engine, &desc, threads, args) {
                columns.push((engine.clone(), t.stages));
            }
        }
        println!(
            "\n{name}: ms per step by stage, {threads} thread(s), averaged over the timed steps (each engine's own profile)"
        );
        print!("{:<12}", "stage");
        for (e, _) in &columns {
            print!(" {e:>9}");
        }
        println!();
        for (i, (stage, _)) in StageTimes::default().named().iter().enumerate() {
            print!("{stage:<12}");
            for (_, st) in &columns {
                match st.named()[i].1 {
                    Some(x) => print!(" {x:>9.3}"),
                    None => print!(" {:>9}", "-"),
                }
            }
            println!();
        }
    }
    println!(
        "\nStages an engine does not time apart are '-'; janus2d's collide includes the portal stage, its setup lives in prepare."
    );
}

/// Runs a hard case on one engine in a pool of `threads` threads (the
/// first `--threads` figure, 1 by default), so every engine's ms/step is
/// measured on the same thread count: janus2d steps on the pool it runs
/// in, and the machine's global pool would give it every core.
fn run_case(engine: &str, case: &HardCase, threads: usize) -> Result<hard::Outcome, String> {
    fn on<E: janus2d_testbed::engine::Engine>(
        case: &HardCase,
        threads: usize,
    ) -> Result<hard::Outcome, String> {
        let mut built = E::build(&case.desc, EngineOptions { threads })?;
        Ok(case.measure(&mut built))
    }
    pool(threads).install(|| match engine {
        "janus2d" => on::<Janus>(case, threads),
        "Box2D" => on::<Box2d>(case, threads),
        _ => on::<Rapier>(case, threads),
    })
}

/// The thread count of the hard cases and the sweep: the first of
/// `--threads` when given, else 1.
fn case_threads(args: &Args) -> usize {
    if args.threads_given {
        args.threads.first().copied().unwrap_or(1)
    } else {
        1
    }
}

fn cmd_hard(args: &Args) {
    let cases: Vec<HardCase> = hard::all()
        .into_iter()
        .filter(|c| args.names.is_empty() || args.names.iter().any(|n| n == c.name))
        .map(|mut c| {
            if let Some(n) = args.substeps {
                c.desc.settings.substeps = n;
            }
            c
        })
        .collect();
    let mut passes = vec![0usize; args.engines.len()];
    let mut failed: Vec<Vec<&str>> = vec![Vec::new(); args.engines.len()];
    println!(
        "hard cases: {} substeps, 1/60 s, sleep off, {} thread(s); one metric code for every engine",
        args.substeps.unwrap_or(4),
        case_threads(args)
    );
    for case in &cases {
        println!("\n{} [Box2D v3.1: {}]", case.name, case.box2d);
        for (k, engine) in args.engines.iter().enumerate() {
            match run_case(engine, case, case_threads(args)) {
                Ok(o) => {
                    if o.pass {
                        passes[k] += 1;
                    } else {
                        failed[k].push(case.name);
                    }
                    let figures: Vec<String> = case
                        .bounds
                        .iter()
                        .map(|b| {
                            let f = b.figure();
                            let op = match b {
                                Bound::AtMost(_, v) => format!("≤ {}", (v * 1e4).round() / 1e4),
                                Bound::AtLeast(_, v) => format!("≥ {}", (v * 1e4).round() / 1e4),
                            };
                            format!("{} {:.4} ({op})", f.name(), o.figures.get(f))
                        })
                        .collect();
                    println!(
                        "  {engine:<8} {}  {}  peak speed {:.2} m/s, penetration {:.4} m",
                        if o.pass { "pass" } else { "FAIL" },
                        figures.join(", "),
                        o.figures.get(Figure::PeakSpeed),
                        o.figures.get(Figure::Penetration)
                    );
                }
                Err(e) => println!("  {engine:<8} skipped: {e}"),
            }
        }
    }
    println!("\npassed of {}:", cases.len());
    for (k, engine) in args.engines.iter().enumerate() {
        let fails = if failed[k].is_empty() {
            String::new()
        } else {
            format!("   fails: {}", failed[k].join(", "))
        };
        println!("  {engine:<8} {}{fails}", passes[k]);
    }
}

/// One engine's sweep curve: (ms/step, error, substeps) per point.
type Curve = (String, Vec<(f64, f64, u32)>);

/// One sweep scene: the hard case and the figure its curve plots.
struct SweepScene {
    case: HardCase,
    figure: Figure,
    label: &'static str,
}

fn cmd_sweep(args: &Args) {
    let mut scenes = vec![
        SweepScene {
            case: hard::large_pyramid(),
            figure: Figure::Sink,
            label: "top-box sink, m",
        },
        SweepScene {
            case: hard::pyramid20(),
            figure: Figure::Sink,
            label: "top-box sink, m",
        },
        SweepScene {
            case: hard::vertical_stack(15),
            figure: Figure::StandTime,
            label: "time the stack stands, s",
        },
        SweepScene {
            case: hard::vertical_stack(20),
            figure: Figure::StandTime,
            label: "time the stack stands, s",
        },
        SweepScene {
            case: hard::bridge(),
            figure: Figure::LateJointGap,
            label: "joint gap over the last second, m",
        },
        SweepScene {
            case: hard::ball_and_chain(),
            figure: Figure::JointGap,
            label: "peak joint gap, m",
        },
    ];
    // Every other hard case too, on its first bound's figure: the cost of
    // accuracy for each case reads off one table (issue 33).
    for case in hard::all() {
        if scenes.iter().any(|s| s.case.name == case.name) {
            continue;
        }
        let figure = case.bounds[0].figure();
        scenes.push(SweepScene {
            case,
            figure,
            label: figure.name(),
        });
    }
    let substeps = [1u32, 2, 4, 8];
    std::fs::create_dir_all(&args.out).expect("out dir");
    let mut csv = String::from("scene,engine,substeps,ms_per_step,figure,value,pass\n");
    for s in scenes
        .iter()
        .filter(|s| args.names.is_empty() || args.names.iter().any(|n| n == s.case.name))
    {
        let mut curves: Vec<Curve> = Vec::new();
        for engine in &args.engines {
            let mut points = Vec::new();
            for &n in &substeps {
                let mut case = s.case.clone();
                case.desc.settings.substeps = n;
                if let Some(steps) = args.steps {
                    case.steps = steps;
                }
                match run_case(engine, &case, case_threads(args)) {
                    Ok(o) => {
                        let value = o.figures.get(s.figure);
                        println!(
                            "{:<18} {engine:<8} substeps {n}: {:.3} ms/step, {} {value:.4}{}",
                            s.case.name,
                            o.step_ms,
                            s.figure.name(),
                            if o.pass { "" } else { "  (fails its bound)" }
                        );
                        let _ = writeln!(
                            csv,
                            "{},{engine},{n},{:.4},{},{value:.6},{}",
                            s.case.name,
                            o.step_ms,
                            s.figure.name(),
                            o.pass
                        );
                        points.push((o.step_ms, value, n));
                    }
                    Err(e) => println!("{} {engine}: {e}", s.case.name),
                }
            }
            curves.push((engine.clone(), points));
        }
        let path = args.out.join(format!("peers_{}.svg", s.case.name));
        if let Err(e) = sweep_chart(&path, s, &curves) {
            eprintln!("chart {}: {e}", path.display());
        }
    }
    let path = args.out.join("peers.csv");
    std::fs::write(&path, csv).expect("write csv");
    println!("wrote {} and peers_<scene>.svg", path.display());
}

fn sweep_chart(
    path: &PathBuf,
    s: &SweepScene,
    curves: &[Curve],
) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::new(path, (720, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    // Errors span orders of magnitude: a log axis, floored at 1e-4.
    const FLOOR: f64 = 1e-4;
    let pts = curves.iter().flat_map(|(_, p)| p.iter());
    let (mut x1, mut y0, mut y1) = (0.0f64, f64::MAX, FLOOR);
    for &(x, y, _) in pts {
        x1 = x1.max(x);
        y0 = y0.min(y.max(FLOOR));
        y1 = y1.max(y);
    }
    let y0 = y0.min(y1) * 0.5;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "{}: {} against ms/step (substeps 1, 2, 4, 8)",
                s.case.name, s.label
            ),
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..x1 * 1.1 + 1e-6, (y0..y1 * 2.0).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("ms per step")
        .y_desc(s.label)
        .draw()?;
    let colors = [
        RGBColor(31, 119, 180),
        RGBColor(255, 127, 14),
        RGBColor(44, 160, 44),
    ];
    for (k, (engine, points)) in curves.iter().enumerate() {
        let c = colors[k % 3];
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|p| (p.0, p.1.max(FLOOR))),
                c.stroke_width(2),
            ))?
            .label(engine.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], c.stroke_width(2)));
        chart.draw_series(points.iter().map(|p| {
            EmptyElement::at((p.0, p.1.max(FLOOR)))
                + Circle::new((0, 0), 3, c.filled())
                + Text::new(format!("{}", p.2), (5, -12), ("sans-serif", 11))
        }))?;
    }
    chart
        .configure_series_labels()
        .border_style(BLACK)
        .background_style(WHITE.mix(0.8))
        .draw()?;
    root.present()?;
    Ok(())
}

fn measure_joint_scene(engine: &str, scene: &JointScene) -> Result<JointFigures, String> {
    match engine {
        "janus2d" => scene.measure::<Janus>(),
        "Box2D" => scene.measure::<Box2d>(),
        _ => scene.measure::<Rapier>(),
    }
}

/// One joint scene on one engine: the timing and the figures (either may
/// be missing: the engine has no such joint).
struct JointRow {
    engine: String,
    ms_per_step: Option<f64>,
    figures: Result<JointFigures, String>,
}

/// `joints`: every joint scene on every engine, timed as `all` times
/// (best of the repeats, one thread) and measured in a separate untimed
/// run, then a summary with the ratios and the figures side by side.
fn cmd_joints(args: &Args) {
    let threads = args.threads.first().copied().unwrap_or(1);
    let scenes: Vec<JointScene> = joint_bench::all()
        .into_iter()
        .filter(|s| args.names.is_empty() || args.names.iter().any(|n| n == s.name))
        .map(|mut s| {
            if let Some(n) = args.substeps {
                s.desc.settings.substeps = n;
            }
            if let Some(n) = args.steps {
                s.desc.steps = n;
            }
            s
        })
        .collect();
    println!(
        "joint scenes: {} substeps, 1/60 s, sleep off | {threads} thread(s) | ms/step best of {} repeats | figures from one untimed run, read after every step | build: {}",
        args.substeps.unwrap_or(4),
        args.repeats,
        build_label()
    );
    let mut table: Vec<(String, Vec<JointRow>)> = Vec::new();
    for scene in &scenes {
        let mut rows = Vec::new();
        for engine in &args.engines {
            let timing = time_on(engine, &scene.desc, threads, args);
            let figures = measure_joint_scene(engine, scene);
            let ms = timing.as_ref().ok().map(Timing::ms_per_step);
            match (&timing, &figures) {
                (Ok(_), Ok(f)) => {
                    let shown: Vec<String> = scene
                        .figures
                        .iter()
                        .zip(&f.values)
                        .map(|(n, v)| format!("{n} {}", figure_text(*v)))
                        .collect();
                    println!(
                        "{:<16} {engine:<8} {:>9.4} ms/step  {}",
                        scene.name,
                        ms.unwrap_or_default(),
                        shown.join(", ")
                    );
                }
                (Err(e), _) | (_, Err(e)) => {
                    println!("{:<16} {engine:<8}       n/a  {e}", scene.name)
                }
            }
            rows.push(JointRow {
                engine: engine.clone(),
                ms_per_step: ms,
                figures,
            });
        }
        table.push((scene.name.to_string(), rows));
    }
    let summary = joints_summary(&scenes, &table);
    println!("\n{summary}");
    if let Some(path) = &args.md {
        std::fs::write(path, &summary).expect("write markdown");
        println!("wrote {}", path.display());
    }
}

/// A figure as printed: 4 decimals, `never` for NaN.
fn figure_text(v: f64) -> String {
    if v.is_nan() {
        "never".into()
    } else {
        format!("{v:.4}")
    }
}

/// The summary table (Markdown): per scene and figure, janus2d ÷ Box2D and
/// ÷ Rapier time ratios and the three engines' figures; `n/a` where an
/// engine could not build the scene.
fn joints_summary(scenes: &[JointScene], table: &[(String, Vec<JointRow>)]) -> String {
    fn get<'a>(rows: &'a [JointRow], e: &str) -> Option<&'a JointRow> {
        rows.iter().find(|r| r.engine == e)
    }
    let ratio = |rows: &[JointRow], peer: &str| match (
        get(rows, "janus2d").and_then(|r| r.ms_per_step),
        get(rows, peer).and_then(|r| r.ms_per_step),
    ) {
        (Some(a), Some(b)) => format!("{:.2}", a / b),
        _ => "n/a".into(),
    };
    let mut md = String::from(
        "| scene | janus2d ÷ Box2D | janus2d ÷ Rapier | figure | janus2d | Box2D | Rapier |\n|---|---|---|---|---|---|---|\n",
    );
    for (scene, (name, rows)) in scenes.iter().zip(table) {
        for (k, figure) in scene.figures.iter().enumerate() {
            let value = |e: &str| {
                get(rows, e)
                    .and_then(|r| r.figures.as_ref().ok())
                    .and_then(|f| f.values.get(k).copied())
                    .map_or("n/a".to_string(), figure_text)
            };
            let (n, rb, rr) = if k == 0 {
                (name.as_str(), ratio(rows, "Box2D"), ratio(rows, "Rapier"))
            } else {
                ("", String::new(), String::new())
            };
            let _ = writeln!(
                md,
                "| {n} | {rb} | {rr} | {figure} | {} | {} | {} |",
                value("janus2d"),
                value("Box2D"),
                value("Rapier")
            );
        }
    }
    md
}

fn main() {
    let args = parse_args();
    match args.command.as_str() {
        "profile" => cmd_profile(&args),
        "hard" => cmd_hard(&args),
        "sweep" => cmd_sweep(&args),
        "chart" => cmd_chart(&args),
        "joints" => cmd_joints(&args),
        "scaling" => cmd_scaling(&args),
        "memory" => memory::cmd_memory(&args),
        "manifolds" => manifolds::cmd_manifolds(&args),
        "memory-one" => memory::cmd_memory_one(&args),
        _ => cmd_all(&args),
    }
}
