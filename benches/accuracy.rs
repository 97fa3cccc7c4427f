//! The accuracy sweep: what each accuracy knob buys, and what it costs.
//!
//! ```text
//! cargo bench --bench accuracy                    # full sweep → docs/accuracy/
//! cargo bench --bench accuracy -- --quick         # short smoke run → target/accuracy-quick/
//! cargo bench --bench accuracy -- --out DIR       # write elsewhere
//! cargo bench --bench accuracy -- --scenes pyramid20,bridge --repeats 5
//! cargo bench --bench accuracy -- --large-steps 300
//! ```
//!
//! Every knob of `SolverSettings` is varied alone from the defaults
//! (4 substeps, relax 1, contacts 30 Hz, joints 60 Hz, joint trees solved
//! directly at 500 Hz, push-out 3 m/s, warm starting on) across the hard scenes; knobs a scene cannot feel (joint
//! hertz without joints, contact knobs without shapes) are skipped, and a
//! setting equal to the defaults is run once and shared by every curve.
//!
//! Timing: each `World::step` is timed alone (the metrics are computed
//! between steps, outside the clock) and step 0 is left out. The runs are
//! deterministic, so step k does the same work in every repeat (a fresh
//! world each). Two clocks, one per scene, because the machine is shared:
//!
//! * short steps (every scene but the large pyramid, < 2 ms): ms/step is the
//!   mean over steps 1..N−1 of each step's **wall-time minimum over the
//!   repeats**; a step far shorter than a scheduler slice mostly runs
//!   undisturbed, and the minimum drops the ones another process paused.
//! * long steps (the large pyramid, ~20 ms, one repeat): ms/step is the
//!   thread's **on-CPU time** over steps 1..N−1 (Linux
//!   `/proc/thread-self/schedstat`, which ticks every few ms: fine over a
//!   run of seconds) minus the time spent measuring, divided by N − 1; a
//!   busy machine stretches every long step's wall time, not its CPU time.
//!   Without that file it falls back to the wall clock.
//!
//! The CSV holds all three figures (`wall_ms_per_step`, `cpu_ms_per_step`,
//! and Box2D's own, the minimum over repeats of each run's mean wall time,
//! `ms_per_step_best_run`); `clock` says which one `ms_per_step` is. The
//! metrics come from the first repeat.
//!
//! Output in the out directory: `<scene>.csv` (one row per setting, every
//! metric of `janus2d_testbed::metrics`), `<scene>_<metric>.svg` (the metric
//! against ms/step, one curve per knob, drawn with `plotters`) and
//! `summary.md` (the tables and the cost per extra substep).

use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use janus2d::prelude::{Real, SolverMode, SolverSettings, WorldDef};
use janus2d_testbed::metrics::Metrics;
use janus2d_testbed::metrics::cases::{self, Case};
use janus2d_testbed::scenes::DT;
use plotters::prelude::*;

type Res<T> = Result<T, Box<dyn Error>>;

/// Command-line options.
struct Args {
    quick: bool,
    out: PathBuf,
    repeats: Option<usize>,
    large_steps: Option<usize>,
    scenes: Vec<String>,
}

fn parse_args() -> Args {
    let mut quick = false;
    let mut out = None;
    let mut repeats = None;
    let mut large_steps = None;
    let mut scenes = Vec::new();
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--quick" => quick = true,
            "--out" => out = Some(PathBuf::from(it.next().expect("--out DIR"))),
            "--repeats" => repeats = it.next().and_then(|v| v.parse().ok()),
            "--large-steps" => large_steps = it.next().and_then(|v| v.parse().ok()),
            "--scenes" => {
                let list = it.next().expect("--scenes a,b");
                scenes.extend(list.split(',').map(str::to_string));
            }
            "--bench" => {}
            "-h" | "--help" => {
                println!(
                    "accuracy sweep: [--quick] [--out DIR] [--repeats N] [--large-steps N] [--scenes a,b]"
                );
                std::process::exit(0);
            }
            other => panic!("unknown option {other} (try --help)"),
        }
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = out.unwrap_or_else(|| {
        if quick {
            root.join("target/accuracy-quick")
        } else {
            root.join("docs/accuracy")
        }
    });
    Args {
        quick,
        out,
        repeats,
        large_steps,
        scenes,
    }
}

/// How a plotted metric is read from the figures and drawn.
#[derive(Clone, Copy)]
enum Axis {
    /// Error on a log axis; values below the floor are drawn at the floor.
    Log { floor: f64 },
    /// Time the stack stood, s, on a linear axis up to the run's length.
    Standing,
}

/// One plot of a scene: a metric against ms/step.
struct PlotSpec {
    key: &'static str,
    label: &'static str,
    axis: Axis,
    get: fn(&Metrics) -> f64,
    /// The pass bound of `scenes.md` for this figure, drawn dashed.
    bound: Option<f64>,
}

impl PlotSpec {
    fn bound(mut self, bound: f64) -> Self {
        self.bound = Some(bound);
        self
    }
}

fn plot(key: &'static str, label: &'static str, floor: f64, get: fn(&Metrics) -> f64) -> PlotSpec {
    PlotSpec {
        key,
        label,
        axis: Axis::Log { floor },
        get,
        bound: None,
    }
}

/// A hard scene of the sweep.
struct SceneSpec {
    name: &'static str,
    title: String,
    build: Box<dyn Fn(&WorldDef) -> Case>,
    repeats: usize,
    clock: Clock,
    plots: Vec<PlotSpec>,
}

fn scene_specs(args: &Args) -> Vec<SceneSpec> {
    let q = args.quick;
    let reps = |full: usize| args.repeats.unwrap_or(if q { 1 } else { full });
    let large_steps = args.large_steps.unwrap_or(if q { 30 } else { 600 });
    let short = |full: usize, quick: usize| if q { quick } else { full };
    let pen = || {
        plot("max_penetration", "max penetration (m)", 1e-5, |m| {
            m.max_penetration
        })
    };
    let sink = || plot("max_sink", "top box sink (m)", 1e-5, |m| m.max_sink);
    let drift = || {
        plot("max_drift", "top box sideways drift (m)", 1e-6, |m| {
            m.max_drift
        })
    };
    let standing = || PlotSpec {
        key: "standing_time",
        label: "time the stack stood (s)",
        axis: Axis::Standing,
        get: |m| m.collapse_time.unwrap_or(m.time),
        bound: None,
    };
    let p20 = short(600, 120);
    let stack = short(60, 10);
    let joints = short(600, 120);
    vec![
        SceneSpec {
            name: "pyramid20",
            title: format!("pyramid 20 (210 boxes, {} s)", p20 / 60),
            build: Box::new(move |d| cases::pyramid(d, 20, p20, 0.5)),
            repeats: reps(3),
            clock: Clock::Wall,
            plots: vec![pen().bound(0.005), sink().bound(0.05), drift().bound(0.01)],
        },
        SceneSpec {
            name: "large_pyramid",
            title: format!(
                "large pyramid (5050 boxes, {:.1} s)",
                large_steps as f64 / 60.0
            ),
            build: Box::new(move |d| cases::pyramid(d, 100, large_steps, 1.5)),
            repeats: reps(1),
            clock: Clock::Cpu,
            plots: vec![
                pen().bound(0.03),
                sink().bound(1.0),
                drift().bound(0.05),
                plot(
                    "late_probe_speed",
                    "top box speed, last second (m/s)",
                    1e-5,
                    |m| m.late_probe_speed,
                )
                .bound(0.01),
            ],
        },
        SceneSpec {
            name: "stack15",
            title: format!("vertical stack, 15 rows ({stack} s)"),
            build: Box::new(move |d| cases::vertical_stack(d, 15, stack)),
            repeats: reps(5),
            clock: Clock::Wall,
            plots: vec![standing(), pen()],
        },
        SceneSpec {
            name: "stack20",
            title: format!("vertical stack, 20 rows ({stack} s)"),
            build: Box::new(move |d| cases::vertical_stack(d, 20, stack)),
            repeats: reps(5),
            clock: Clock::Wall,
            plots: vec![standing()],
        },
        SceneSpec {
            name: "ball_and_chain",
            title: format!("ball and chain (40 links, 670:1, {} s)", joints / 60),
            build: Box::new(move |d| cases::ball_and_chain(d).with_steps(joints)),
            repeats: reps(5),
            clock: Clock::Wall,
            plots: vec![
                plot("max_joint_gap", "peak joint gap (m)", 1e-5, |m| {
                    m.max_joint_gap
                })
                .bound(0.1),
                plot(
                    "relative_energy_error",
                    "energy error / peak kinetic energy",
                    1e-4,
                    |m| m.relative_energy_error(),
                ),
                plot("peak_speed", "peak speed (m/s)", 1e-2, |m| m.peak_speed),
            ],
        },
        #[cfg(feature = "portals")]
        SceneSpec {
            name: "portal_stream",
            title: format!("portal stream (200 shapes, {} s)", joints / 60),
            build: Box::new(move |d| cases::portal_stream(d, joints)),
            repeats: reps(3),
            clock: Clock::Wall,
            plots: vec![
                plot("portal_c", "peak portal error |C| (m)", 1e-7, |m| {
                    m.extras
                        .iter()
                        .find(|e| e.name == "portal_c")
                        .and_then(|e| e.peak)
                        .unwrap_or(0.0)
                })
                .bound(1e-3),
                pen(),
            ],
        },
        SceneSpec {
            name: "bridge",
            title: format!("bridge (160 planks, {} s)", joints / 60),
            build: Box::new(move |d| cases::bridge(d).with_steps(joints)),
            repeats: reps(5),
            clock: Clock::Wall,
            plots: vec![
                plot(
                    "late_max_joint_gap",
                    "joint gap, last second (m)",
                    1e-6,
                    |m| m.late_max_joint_gap,
                )
                .bound(0.02),
                plot("max_joint_gap", "peak joint gap (m)", 1e-6, |m| {
                    m.max_joint_gap
                }),
                plot("max_sink", "peak sag of the middle plank (m)", 1e-3, |m| {
                    m.max_sink
                }),
            ],
        },
    ]
}

/// Which scenes a knob can make a difference in.
#[derive(Clone, Copy, PartialEq)]
enum Needs {
    Anything,
    Joints,
    Shapes,
}

/// One knob and the values it takes.
struct Knob {
    name: &'static str,
    needs: Needs,
    color: RGBColor,
    values: Vec<(f64, String, SolverSettings)>,
}

fn knobs() -> Vec<Knob> {
    let base = SolverSettings::default();
    let vary = |values: &[f64], set: &dyn Fn(&mut SolverSettings, f64)| {
        values
            .iter()
            .map(|&v| {
                let mut s = base.clone();
                set(&mut s, v);
                (v, format!("{v}"), s)
            })
            .collect::<Vec<_>>()
    };
    // A switch: off (0) and on (1).
    let on_off = |set: &dyn Fn(&mut SolverSettings, bool)| {
        [(0.0, false), (1.0, true)]
            .into_iter()
            .map(|(v, on)| {
                let mut s = base.clone();
                set(&mut s, on);
                (v, if on { "on" } else { "off" }.to_string(), s)
            })
            .collect::<Vec<_>>()
    };
    vec![
        Knob {
            name: "substeps",
            needs: Needs::Anything,
            color: RGBColor(31, 119, 180),
            values: vary(&[1.0, 2.0, 4.0, 8.0, 16.0], &|s, v| s.substeps = v as u32),
        },
        Knob {
            name: "relax_iterations",
            needs: Needs::Anything,
            color: RGBColor(255, 127, 14),
            values: vary(&[0.0, 1.0, 2.0, 4.0], &|s, v| s.relax_iterations = v as u32),
        },
        Knob {
            name: "pgs_velocity_iterations",
            needs: Needs::Anything,
            color: RGBColor(214, 39, 40),
            values: vary(&[4.0, 8.0, 16.0, 32.0], &|s, v| {
                s.mode = SolverMode::PgsBaumgarte;
                s.velocity_iterations = v as u32;
            }),
        },
        Knob {
            name: "contact_hertz",
            needs: Needs::Shapes,
            color: RGBColor(44, 160, 44),
            // Above the default the cap at a fraction of the substep rate is
            // lifted, so that the knob sets the stiffness the contacts
            // solve with (at 4 substeps the cap is 30 Hz).
            values: vary(&[15.0, 30.0, 60.0, 120.0], &|s, v| {
                s.contact_hertz = v as Real;
                if s.contact_hertz > SolverSettings::default().contact_hertz {
                    s.contact_hertz_fraction = Real::INFINITY;
                }
            }),
        },
        Knob {
            name: "joint_hertz",
            needs: Needs::Joints,
            color: RGBColor(148, 103, 189),
            values: vary(&[15.0, 30.0, 60.0, 120.0], &|s, v| {
                s.joint_hertz = v as Real;
                if s.joint_hertz > SolverSettings::default().joint_hertz {
                    s.joint_hertz_fraction = Real::INFINITY;
                }
            }),
        },
        Knob {
            name: "push_out_speed",
            needs: Needs::Shapes,
            color: RGBColor(140, 86, 75),
            values: vary(&[1.0, 3.0, 10.0], &|s, v| {
                s.contact_push_max_velocity = v as Real
            }),
        },
        Knob {
            name: "contact_mass_ratio_cap",
            needs: Needs::Shapes,
            color: RGBColor(23, 190, 207),
            values: vary(&[1.0, 1.3, 2.0], &|s, v| {
                s.contact_mass_ratio_cap = v as Real
            }),
        },
        Knob {
            name: "joint_mass_ratio_cap",
            needs: Needs::Joints,
            color: RGBColor(188, 189, 34),
            values: vary(&[1.0, 1.3, 2.0], &|s, v| s.joint_mass_ratio_cap = v as Real),
        },
        Knob {
            name: "direct_joints",
            needs: Needs::Joints,
            color: RGBColor(0, 0, 0),
            values: on_off(&|s, on| s.direct_joints = on),
        },
        Knob {
            name: "direct_joint_hertz",
            needs: Needs::Joints,
            color: RGBColor(227, 119, 194),
            values: vary(&[120.0, 240.0, 500.0, 1000.0], &|s, v| {
                s.direct_joint_hertz = v as Real
            }),
        },
        Knob {
            name: "warm_starting",
            needs: Needs::Anything,
            color: RGBColor(127, 127, 127),
            values: on_off(&|s, on| s.warm_starting = on),
        },
    ]
}

/// Which clock a scene's ms/step comes from.
#[derive(Clone, Copy, PartialEq)]
enum Clock {
    /// Wall time of each step, each step's minimum over the repeats: for
    /// steps far shorter than a scheduler slice (a few ms), where most
    /// steps run undisturbed in at least one repeat.
    Wall,
    /// This thread's on-CPU time over the whole run (Linux schedstat, which
    /// ticks every few ms): for long steps, which a busy machine slows
    /// down in every repeat; the time spent measuring is subtracted.
    Cpu,
}

/// One measured setting.
#[derive(Clone)]
struct Run {
    settings: SolverSettings,
    steps: usize,
    repeats: usize,
    /// The figure plotted: `cpu_ms_per_step` for [`Clock::Cpu`] scenes
    /// (when the clock is available), else `wall_ms_per_step`.
    ms_per_step: f64,
    /// Which clock `ms_per_step` is.
    clock: &'static str,
    /// Mean over steps 1..N−1 of each step's wall-time minimum over the
    /// repeats.
    wall_ms_per_step: f64,
    /// On-CPU time of steps 1..N−1 divided by N − 1, minimum over repeats.
    cpu_ms_per_step: Option<f64>,
    /// Box2D's figure: the minimum over repeats of the whole run's mean
    /// wall time.
    ms_per_step_best_run: f64,
    metrics: Metrics,
}

/// On-CPU time of the calling thread, from `/proc/thread-self/schedstat`
/// (its first field, ns). The file is opened by, and only valid for, the
/// thread that measures.
struct CpuClock {
    file: Option<std::fs::File>,
}

impl CpuClock {
    fn new() -> CpuClock {
        let mut clock = CpuClock {
            file: std::fs::File::open("/proc/thread-self/schedstat").ok(),
        };
        if clock.now_ms().is_none() {
            clock.file = None;
        }
        clock
    }

    fn now_ms(&mut self) -> Option<f64> {
        use std::io::{Read, Seek, SeekFrom};
        let file = self.file.as_mut()?;
        file.seek(SeekFrom::Start(0)).ok()?;
        let mut text = String::new();
        file.read_to_string(&mut text).ok()?;
        let ns: u64 = text.split_whitespace().next()?.parse().ok()?;
        Some(ns as f64 * 1e-6)
    }
}

/// One point of a knob's curve.
struct Row {
    knob: &'static str,
    value: f64,
    label: String,
    run: usize,
}

/// The shared settings of `scenes.md` with `settings`: sleep off, as in
/// every stability test.
fn sweep_def(settings: &SolverSettings) -> WorldDef {
    let mut def = WorldDef {
        solver: settings.clone(),
        ..WorldDef::default()
    };
    def.sleep.enabled = false;
    def
}

fn measure(spec: &SceneSpec, settings: &SolverSettings, clock: &mut CpuClock) -> Run {
    let def = sweep_def(settings);
    let repeats = spec.repeats.max(1);
    let mut best_run = f64::INFINITY;
    let mut best_cpu: Option<f64> = None;
    let mut best_step: Vec<f64> = Vec::new();
    let mut first = None;
    for _ in 0..repeats {
        let mut case = (spec.build)(&def);
        let mut tracker = case.tracker();
        let n = case.steps.max(2) - 1;
        best_step.resize(case.steps, f64::INFINITY);
        let mut total = 0.0;
        let mut measuring = 0.0;
        let mut cpu_start = None;
        for k in 0..case.steps {
            if k == 1 {
                cpu_start = clock.now_ms();
            }
            let t0 = Instant::now();
            case.world.step(DT).expect("valid step");
            let t1 = Instant::now();
            tracker.record(&case.world, DT).expect("live probe");
            let took = (t1 - t0).as_secs_f64() * 1e3;
            if k > 0 {
                total += took;
                best_step[k] = best_step[k].min(took);
                measuring += t1.elapsed().as_secs_f64() * 1e3;
            }
        }
        if let (Some(start), Some(end)) = (cpu_start, clock.now_ms()) {
            let cpu = (end - start - measuring).max(0.0) / n as f64;
            best_cpu = Some(best_cpu.map_or(cpu, |b: f64| b.min(cpu)));
        }
        best_run = best_run.min(total / n as f64);
        first.get_or_insert_with(|| tracker.into_metrics());
    }
    let steps = best_step.len();
    let wall: f64 = best_step.iter().skip(1).sum::<f64>() / (steps.max(2) - 1) as f64;
    let (ms_per_step, clock_name) = match (spec.clock, best_cpu) {
        (Clock::Cpu, Some(cpu)) => (cpu, "cpu"),
        _ => (wall, "wall"),
    };
    Run {
        settings: settings.clone(),
        steps,
        repeats,
        ms_per_step,
        clock: clock_name,
        wall_ms_per_step: wall,
        cpu_ms_per_step: best_cpu,
        ms_per_step_best_run: best_run,
        metrics: first.expect("at least one repeat"),
    }
}

fn main() -> Res<()> {
    let args = parse_args();
    std::fs::create_dir_all(&args.out)?;
    let started = Instant::now();
    let mut summary = String::new();
    writeln!(summary, "# Accuracy sweep: results")?;
    writeln!(summary)?;
    writeln!(
        summary,
        "Written by `cargo bench --bench accuracy{}`; see `docs/accuracy.md` for how to read it. \
         Single thread; ms/step is on-CPU time for the large pyramid, else each step's wall-time minimum over the repeats (see the bench's docs).",
        if args.quick { " -- --quick" } else { "" }
    )?;
    let specs = scene_specs(&args);
    let mut clock = CpuClock::new();
    for spec in &specs {
        if !args.scenes.is_empty() && !args.scenes.iter().any(|s| s == spec.name) {
            continue;
        }
        let scene_start = Instant::now();
        let probe = (spec.build)(&sweep_def(&SolverSettings::default()));
        let has_joints = probe.world.joint_count() > 0;
        let has_shapes = probe.world.shape_count() > 0;
        let probe_label = probe.probe_label;
        drop(probe);
        let mut runs: Vec<Run> = Vec::new();
        let mut rows: Vec<Row> = Vec::new();
        for knob in knobs() {
            let felt = match knob.needs {
                Needs::Anything => true,
                Needs::Joints => has_joints,
                Needs::Shapes => has_shapes,
            };
            if !felt {
                continue;
            }
            for (value, label, settings) in knob.values {
                let run = match runs.iter().position(|r| r.settings == settings) {
                    Some(i) => i,
                    None => {
                        let r = measure(spec, &settings, &mut clock);
                        eprintln!(
                            "[{:>14}] {:<24} {:>4}: {:8.3} ms/step  pen {:.2e}  sink {:.2e}  drift {:.2e}  gap {:.2e}  collapse {:?}",
                            spec.name,
                            knob.name,
                            label,
                            r.ms_per_step,
                            r.metrics.max_penetration,
                            r.metrics.max_sink,
                            r.metrics.max_drift,
                            r.metrics.max_joint_gap,
                            r.metrics.collapse_time
                        );
                        runs.push(r);
                        runs.len() - 1
                    }
                };
                rows.push(Row {
                    knob: knob.name,
                    value,
                    label,
                    run,
                });
            }
        }
        write_csv(
            &args.out.join(format!("{}.csv", spec.name)),
            spec,
            &rows,
            &runs,
        )?;
        for p in &spec.plots {
            let path = args.out.join(format!("{}_{}.svg", spec.name, p.key));
            draw_plot(&path, spec, p, &rows, &runs)?;
        }
        write_summary(&mut summary, spec, probe_label, &rows, &runs)?;
        eprintln!(
            "[{:>14}] {} settings in {:.1} s",
            spec.name,
            runs.len(),
            scene_start.elapsed().as_secs_f64()
        );
    }
    let total = started.elapsed().as_secs_f64();
    writeln!(summary)?;
    writeln!(summary, "Whole sweep: {total:.0} s wall time.")?;
    std::fs::write(args.out.join("summary.md"), &summary)?;
    println!("{summary}");
    println!("wrote {}", args.out.display());
    Ok(())
}

fn csv_field(v: Option<f64>) -> String {
    v.map(|x| format!("{x:.6e}")).unwrap_or_default()
}

fn write_csv(path: &Path, spec: &SceneSpec, rows: &[Row], runs: &[Run]) -> Res<()> {
    let mut s = String::new();
    let cols = runs[rows[0].run].metrics.columns();
    write!(
        s,
        "scene,knob,value,label,is_default,mode,substeps,relax_iterations,velocity_iterations,\
         contact_hertz,joint_hertz,contact_push_max_velocity,warm_starting,steps,repeats,clock,ms_per_step,\
         wall_ms_per_step,cpu_ms_per_step,ms_per_step_best_run"
    )?;
    for c in &cols {
        let unit = c.unit.replace('/', "_per_");
        write!(s, ",{}_{}", c.name, unit)?;
    }
    writeln!(s)?;
    let default = SolverSettings::default();
    for row in rows {
        let r = &runs[row.run];
        let st = &r.settings;
        write!(
            s,
            "{},{},{},{},{},{:?},{},{},{},{},{},{},{},{},{},{},{:.4},{:.4},{},{:.4}",
            spec.name,
            row.knob,
            row.value,
            row.label,
            *st == default,
            st.mode,
            st.substeps,
            st.relax_iterations,
            st.velocity_iterations,
            st.contact_hertz,
            st.joint_hertz,
            st.contact_push_max_velocity,
            st.warm_starting,
            r.steps,
            r.repeats,
            r.clock,
            r.ms_per_step,
            r.wall_ms_per_step,
            r.cpu_ms_per_step
                .map(|c| format!("{c:.4}"))
                .unwrap_or_default(),
            r.ms_per_step_best_run
        )?;
        for c in r.metrics.columns() {
            write!(s, ",{}", csv_field(c.value))?;
        }
        writeln!(s)?;
    }
    std::fs::write(path, s)?;
    Ok(())
}

/// The summary columns of a scene: its plotted metrics.
fn write_summary(
    out: &mut String,
    spec: &SceneSpec,
    probe: &str,
    rows: &[Row],
    runs: &[Run],
) -> Res<()> {
    writeln!(out)?;
    writeln!(out, "## {} — probe: {probe}", spec.title)?;
    writeln!(out)?;
    write!(out, "| knob | value | ms/step |")?;
    for p in &spec.plots {
        write!(out, " {} |", p.label)?;
    }
    writeln!(out)?;
    write!(out, "|---|---|---|")?;
    for _ in &spec.plots {
        write!(out, "---|")?;
    }
    writeln!(out)?;
    let default = SolverSettings::default();
    for row in rows {
        let r = &runs[row.run];
        let mark = if r.settings == default {
            " (default)"
        } else {
            ""
        };
        write!(
            out,
            "| {} | {}{mark} | {:.3} |",
            row.knob, row.label, r.ms_per_step
        )?;
        for p in &spec.plots {
            let v = (p.get)(&r.metrics);
            match p.axis {
                Axis::Standing if r.metrics.collapse_time.is_none() => {
                    write!(out, " stood {v:.0} |")?
                }
                Axis::Standing => write!(out, " fell at {v:.2} |")?,
                Axis::Log { .. } => write!(out, " {v:.3e} |")?,
            }
        }
        writeln!(out)?;
    }
    let sub: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.knob == "substeps")
        .map(|r| (r.value, runs[r.run].ms_per_step))
        .collect();
    if sub.len() >= 2 {
        let n = sub.len() as f64;
        let mx = sub.iter().map(|p| p.0).sum::<f64>() / n;
        let my = sub.iter().map(|p| p.1).sum::<f64>() / n;
        let sxy: f64 = sub.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
        let sxx: f64 = sub.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
        let slope = sxy / sxx;
        let intercept = my - slope * mx;
        let steps: Vec<String> = sub
            .windows(2)
            .map(|w| {
                let per = (w[1].1 - w[0].1) / (w[1].0 - w[0].0);
                format!("{}→{}: {per:.3}", w[0].0, w[1].0)
            })
            .collect();
        writeln!(out)?;
        writeln!(
            out,
            "Cost per extra substep (least squares over 1–16): {slope:.3} ms/step; \
             fixed part (collision, prepare, finalize): {intercept:.3} ms/step. \
             Between neighbours, ms/step per added substep: {}.",
            steps.join(", ")
        )?;
    }
    Ok(())
}

/// A value for an axis label: plain decimals from 0.01 to 1000, else
/// scientific.
fn number(v: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if (0.01..1000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

/// A time-per-step label with as many decimals as the range needs.
fn x_label(v: f64, x_max: f64) -> String {
    match x_max {
        m if m >= 20.0 => format!("{v:.0}"),
        m if m >= 2.0 => format!("{v:.1}"),
        m if m >= 0.2 => format!("{v:.2}"),
        _ => format!("{v:.3}"),
    }
}

fn draw_plot(path: &Path, spec: &SceneSpec, p: &PlotSpec, rows: &[Row], runs: &[Run]) -> Res<()> {
    let y_of = |r: &Run| {
        let v = (p.get)(&r.metrics);
        match p.axis {
            Axis::Log { floor } if !v.is_finite() => floor,
            Axis::Log { floor } => v.max(floor),
            Axis::Standing => v,
        }
    };
    let default = SolverSettings::default();
    let x_max = rows
        .iter()
        .map(|r| runs[r.run].ms_per_step)
        .fold(0.0, f64::max)
        * 1.1;
    let ys: Vec<f64> = rows.iter().map(|r| y_of(&runs[r.run])).collect();
    let bound = p.bound.into_iter();
    let y_lo = ys
        .iter()
        .copied()
        .chain(bound.clone())
        .fold(f64::INFINITY, f64::min);
    let y_hi = ys.iter().copied().chain(bound).fold(0.0, f64::max);

    // One curve per knob, in the order the knobs were run.
    let knob_list = knobs();
    // (ms/step, value, label, is the defaults' point) per knob.
    type Point = (f64, f64, String, bool);
    let mut curves: Vec<(&'static str, RGBColor, Vec<Point>)> = Vec::new();
    for knob in &knob_list {
        let pts: Vec<_> = rows
            .iter()
            .filter(|r| r.knob == knob.name)
            .map(|r| {
                let run = &runs[r.run];
                (
                    run.ms_per_step,
                    y_of(run),
                    r.label.clone(),
                    run.settings == default,
                )
            })
            .collect();
        if !pts.is_empty() {
            curves.push((knob.name, knob.color, pts));
        }
    }
    let default_point = rows
        .iter()
        .map(|r| &runs[r.run])
        .find(|r| r.settings == default)
        .map(|r| (r.ms_per_step, y_of(r)));

    let root = SVGBackend::new(path, (1100, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (plot_area, legend_area) = root.split_horizontally(860);
    let mut builder = ChartBuilder::on(&plot_area);
    builder
        .caption(format!("{}: {}", spec.title, p.label), ("sans-serif", 19))
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(74);

    macro_rules! draw_curves {
        ($chart:ident) => {{
            if let Some(bound) = p.bound {
                $chart.draw_series(DashedLineSeries::new(
                    [(0.0, bound), (x_max, bound)],
                    8,
                    5,
                    BLACK.mix(0.6).stroke_width(1),
                ))?;
            }
            for (_, color, pts) in &curves {
                let color = *color;
                $chart.draw_series(LineSeries::new(
                    pts.iter().map(|p| (p.0, p.1)),
                    color.stroke_width(2),
                ))?;
                $chart.draw_series(pts.iter().map(|(x, y, label, is_default)| {
                    // The defaults' point is marked once, by the ring.
                    let text = if *is_default {
                        String::new()
                    } else {
                        label.clone()
                    };
                    EmptyElement::at((*x, *y))
                        + Circle::new((0, 0), 4, color.filled())
                        + Text::new(text, (5, -15), ("sans-serif", 12).into_font().color(&color))
                }))?;
            }
            if let Some((x, y)) = default_point {
                $chart.draw_series(std::iter::once(Circle::new(
                    (x, y),
                    8,
                    BLACK.stroke_width(2),
                )))?;
            }
        }};
    }

    match p.axis {
        Axis::Log { floor } => {
            let lo = y_lo.max(floor) / 2.0;
            let hi = (y_hi * 2.0).max(lo * 10.0);
            let mut chart = builder.build_cartesian_2d(0.0..x_max, (lo..hi).log_scale())?;
            chart
                .configure_mesh()
                .x_desc("ms per step")
                .y_desc(p.label)
                .y_labels(7)
                .y_label_formatter(&|v| number(*v))
                .x_label_formatter(&|v| x_label(*v, x_max))
                .light_line_style(WHITE.mix(0.0))
                .draw()?;
            draw_curves!(chart);
        }
        Axis::Standing => {
            let hi = runs.iter().map(|r| r.metrics.time).fold(0.0, f64::max) * 1.08;
            let mut chart = builder.build_cartesian_2d(0.0..x_max, 0.0..hi)?;
            chart
                .configure_mesh()
                .x_desc("ms per step")
                .y_desc(p.label)
                .x_label_formatter(&|v| x_label(*v, x_max))
                .light_line_style(WHITE.mix(0.0))
                .draw()?;
            draw_curves!(chart);
        }
    }

    // The legend, beside the plot: knob, colour, the values it takes.
    let font = ("sans-serif", 13).into_font();
    let small = ("sans-serif", 11).into_font().color(&RGBColor(90, 90, 90));
    let mut y = 52;
    for (name, color, pts) in &curves {
        let color = *color;
        legend_area.draw(&PathElement::new(
            vec![(4, y), (28, y)],
            color.stroke_width(3),
        ))?;
        legend_area.draw(&Text::new(name.to_string(), (34, y - 8), font.clone()))?;
        let values: Vec<&str> = pts.iter().map(|p| p.2.as_str()).collect();
        legend_area.draw(&Text::new(values.join(", "), (34, y + 8), small.clone()))?;
        y += 37;
    }
    legend_area.draw(&Circle::new((16, y), 7, BLACK.stroke_width(2)))?;
    legend_area.draw(&Text::new("defaults", (34, y - 8), font.clone()))?;
    let d = &default;
    let lines = [
        format!(
            "{} substeps, relax {}, contacts {} Hz,",
            d.substeps, d.relax_iterations, d.contact_hertz
        ),
        format!(
            "joints {} Hz, push-out {} m/s,",
            d.joint_hertz, d.contact_push_max_velocity
        ),
        format!(
            "mass-ratio caps {}/{}, warm {}",
            d.contact_mass_ratio_cap,
            d.joint_mass_ratio_cap,
            if d.warm_starting { "on" } else { "off" }
        ),
    ];
    for (i, line) in lines.into_iter().enumerate() {
        legend_area.draw(&Text::new(line, (34, y + 8 + 13 * i as i32), small.clone()))?;
    }
    y += 13;
    y += 56;
    if let Some(bound) = p.bound {
        legend_area.draw(&PathElement::new(
            vec![(4, y), (10, y)],
            BLACK.mix(0.6).stroke_width(1),
        ))?;
        legend_area.draw(&PathElement::new(
            vec![(16, y), (22, y)],
            BLACK.mix(0.6).stroke_width(1),
        ))?;
        legend_area.draw(&Text::new(
            format!("pass bound of scenes.md ({})", number(bound)),
            (34, y - 7),
            small.clone(),
        ))?;
        y += 30;
    }
    let note = match p.axis {
        Axis::Log { floor } => format!("lower is better; values < {floor:.0e} drawn at it"),
        Axis::Standing => "higher is better; top = never fell".to_string(),
    };
    legend_area.draw(&Text::new(note, (4, y), small.clone()))?;
    let timing = match spec.clock {
        Clock::Cpu => "x: on-CPU ms per step",
        Clock::Wall => "x: ms per step, each step's min over repeats",
    };
    legend_area.draw(&Text::new(timing, (4, y + 16), small))?;
    root.present()?;
    Ok(())
}
