//! Running a scene: load it (built-in or file), step it, write frames,
//! a CSV of every step and a summary.
//!
//! ```text
//! load(scene) ─▶ Loaded ─ run(options) ─┬─ per step: script actions, World::step,
//!                                        │   events printed (first few), CSV row,
//!                                        │   a frame every k steps (PNG / GIF)
//!                                        ├─ a progress bar once the run passes 1 s
//!                                        └─ Summary: bodies, contacts, ms/step,
//!                                            the mean per-stage profile, counters
//! ```

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use janus2d_core::body::BodyHandle;
use janus2d_core::geometry::Aabb;
use janus2d_core::math::{Real, to_f64};
use janus2d_render::{Camera, GifWriter, Raster, scene_bounds};
use janus2d_testbed::desc::{Action, SceneDesc};
use janus2d_testbed::janus::Janus;
use janus2d_world::{DrawOptions, StepCounters, World};

use crate::catalog;
use crate::error::CliError;
use crate::scene_file;

/// How a loaded scene is stepped.
enum Driver {
    /// A built-in description (its script, if any, runs before each step).
    Described {
        janus: Box<Janus>,
        desc: Box<SceneDesc>,
        actions: Vec<Action>,
    },
    /// A world from a scene file.
    Plain(Box<World>),
}

/// A scene ready to run.
pub struct Loaded {
    /// Its name.
    pub name: String,
    /// Where it came from: `built-in benchmark`, or the file.
    pub source: String,
    driver: Driver,
    /// Step, s.
    pub dt: Real,
    /// Steps it runs by default.
    pub steps: usize,
    /// The body the summary reports (and the camera follows).
    pub probe: Option<BodyHandle>,
    /// What the probe is.
    pub probe_label: String,
}

/// Steps of a scene file that gives none.
pub const DEFAULT_FILE_STEPS: usize = 600;

impl Loaded {
    /// The world.
    #[must_use]
    pub fn world(&self) -> &World {
        match &self.driver {
            Driver::Described { janus, .. } => &janus.world,
            Driver::Plain(w) => w,
        }
    }

    /// The world, to change.
    pub fn world_mut(&mut self) -> &mut World {
        match &mut self.driver {
            Driver::Described { janus, .. } => &mut janus.world,
            Driver::Plain(w) => w,
        }
    }

    /// Step `step` (from 0): the script's actions, then the world's step.
    pub fn step(&mut self, step: usize) -> Result<(), CliError> {
        let dt = self.dt;
        match &mut self.driver {
            Driver::Described {
                janus,
                desc,
                actions,
            } => {
                desc.script.actions(step, desc.settings.dt, actions);
                for a in actions.iter() {
                    janus.try_apply(a)?;
                }
                janus.world.step(dt)?;
            }
            Driver::Plain(w) => w.step(dt)?,
        }
        Ok(())
    }

    /// A built-in description built with its own settings.
    pub fn from_desc(
        name: &str,
        source: &str,
        desc: SceneDesc,
        steps: usize,
    ) -> Result<Self, CliError> {
        let janus = Janus::new(&desc)?;
        let probe = janus.probe(&desc);
        Ok(Loaded {
            name: name.to_owned(),
            source: source.to_owned(),
            dt: desc.settings.dt as Real,
            steps,
            probe,
            probe_label: desc.probe_label.to_owned(),
            driver: Driver::Described {
                janus: Box::new(janus),
                desc: Box::new(desc),
                actions: Vec::new(),
            },
        })
    }
}

/// Loads `scene`: a path to an existing file (or any name ending in
/// `.json`) is a scene file, anything else a built-in name.
pub fn load(scene: &str) -> Result<Loaded, CliError> {
    let path = Path::new(scene);
    if path.is_file() || scene.ends_with(".json") {
        let (file, built) = scene_file::load_file(path)?;
        let name = if file.name.is_empty() {
            path.file_stem()
                .map_or_else(|| scene.to_owned(), |s| s.to_string_lossy().into_owned())
        } else {
            file.name.clone()
        };
        return Ok(Loaded {
            name,
            source: scene.to_owned(),
            dt: built.dt,
            steps: built.steps.unwrap_or(DEFAULT_FILE_STEPS),
            probe: built.probe,
            probe_label: match &file.probe {
                Some(scene_file::BodyRef::Id(id)) => id.clone(),
                Some(scene_file::BodyRef::Index(i)) => format!("body {i}"),
                None => String::new(),
            },
            driver: Driver::Plain(Box::new(built.world)),
        });
    }
    let e = catalog::find(scene)?;
    let source = format!("built-in {}", e.group);
    Loaded::from_desc(e.name, &source, e.build(), e.steps)
}

/// How the camera of the pictures fits the scene (`--fit`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Fit {
    /// Once, on the first frame: the view never moves (unless it follows
    /// the probe).
    #[default]
    Once,
    /// On every frame: the view zooms with the scene.
    Each,
    /// On every frame, over everything seen so far: the view only ever
    /// zooms out, so bodies spawned later (the rain scene's ragdolls) stay
    /// in the picture and settled ones do not jump.
    Grow,
    /// Again every this many steps (≥ 1).
    Every(usize),
}

impl std::str::FromStr for Fit {
    type Err = CliError;

    /// `once`, `each`, `grow`, or a number of steps `N` (≥ 1).
    fn from_str(s: &str) -> Result<Fit, CliError> {
        match s.trim() {
            "once" => Ok(Fit::Once),
            "each" => Ok(Fit::Each),
            "grow" => Ok(Fit::Grow),
            n => match n.parse::<usize>() {
                Ok(k) if k >= 1 => Ok(Fit::Every(k)),
                _ => Err(CliError::Invalid(format!(
                    "--fit `{s}`: expected once, each, grow or a number of steps (at least 1)"
                ))),
            },
        }
    }
}

/// Pictures a run writes.
#[derive(Clone, Debug, PartialEq)]
pub enum Frames {
    /// None.
    None,
    /// PNG files named by step, `frame_00000.png`, `frame_00001.png`, …
    /// (zero-padded to five digits, or to the last step's digits) in this
    /// folder.
    Png(PathBuf),
    /// One GIF file.
    Gif(PathBuf),
    /// SVG files named by step as the PNG ones, `frame_00000.svg`, … in
    /// this folder.
    Svg(PathBuf),
}

/// How to run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Steps (the scene's own by default).
    pub steps: Option<usize>,
    /// Substeps (the scene's own by default).
    pub substeps: Option<u32>,
    /// Worker threads of the step: collision and solver (a pool of exactly this many).
    pub threads: usize,
    /// Pictures.
    pub frames: Frames,
    /// A frame every this many steps (PNG 1, GIF 2 by default).
    pub every: Option<usize>,
    /// Picture size, px.
    pub size: (u32, u32),
    /// The camera follows the probe instead of staying on the scene.
    pub follow: bool,
    /// When the camera fits the scene again.
    pub fit: Fit,
    /// What the pictures show.
    pub draw: DrawOptions,
    /// PNG and GIF frames carry a line of text in their top left corner:
    /// step, time, bodies and the mean ms/step since the previous frame.
    pub overlay: bool,
    /// Print the per-stage profile table and the counters.
    pub profile: bool,
    /// One CSV row per step.
    pub csv: Option<PathBuf>,
    /// A progress bar on runs past one second (on a terminal).
    pub progress: bool,
    /// Most events printed as they happen.
    pub max_events: usize,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            steps: None,
            substeps: None,
            threads: 1,
            frames: Frames::None,
            every: None,
            size: (640, 360),
            follow: false,
            fit: Fit::Once,
            draw: DrawOptions::default(),
            overlay: false,
            profile: false,
            csv: None,
            progress: true,
            max_events: 8,
        }
    }
}

/// Mean time of each stage, ms per step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageMs {
    /// Broadphase.
    pub broadphase: f64,
    /// Narrowphase.
    pub narrowphase: f64,
    /// Portal stage.
    pub portals: f64,
    /// Solver prepare.
    pub prepare: f64,
    /// Integration.
    pub integrate: f64,
    /// Warm start.
    pub warm_start: f64,
    /// Solve.
    pub solve: f64,
    /// Relax.
    pub relax: f64,
    /// Restitution.
    pub restitution: f64,
    /// Finalize.
    pub finalize: f64,
    /// Sleep.
    pub sleep: f64,
    /// The whole step.
    pub total: f64,
}

impl StageMs {
    fn of(world: &World) -> StageMs {
        let p = world.profile();
        let s = &p.solver;
        StageMs {
            broadphase: p.broadphase * 1e3,
            narrowphase: p.narrowphase * 1e3,
            portals: p.portals * 1e3,
            prepare: s.prepare * 1e3,
            integrate: s.integrate * 1e3,
            warm_start: s.warm_start * 1e3,
            solve: s.solve * 1e3,
            relax: s.relax * 1e3,
            restitution: s.restitution * 1e3,
            finalize: s.finalize * 1e3,
            sleep: p.sleep * 1e3,
            total: p.total * 1e3,
        }
    }

    /// The stages as (name, ms), in pipeline order (total last).
    #[must_use]
    pub fn named(&self) -> [(&'static str, f64); 12] {
        [
            ("broadphase", self.broadphase),
            ("narrowphase", self.narrowphase),
            ("portals", self.portals),
            ("prepare", self.prepare),
            ("integrate", self.integrate),
            ("warm start", self.warm_start),
            ("solve", self.solve),
            ("relax", self.relax),
            ("restitution", self.restitution),
            ("finalize", self.finalize),
            ("sleep", self.sleep),
            ("total", self.total),
        ]
    }

    fn add(&mut self, o: &StageMs) {
        let mut v = self.named();
        for (a, b) in v.iter_mut().zip(o.named()) {
            a.1 += b.1;
        }
        *self = StageMs::from_values(v.map(|x| x.1));
    }

    fn from_values(v: [f64; 12]) -> StageMs {
        StageMs {
            broadphase: v[0],
            narrowphase: v[1],
            portals: v[2],
            prepare: v[3],
            integrate: v[4],
            warm_start: v[5],
            solve: v[6],
            relax: v[7],
            restitution: v[8],
            finalize: v[9],
            sleep: v[10],
            total: v[11],
        }
    }

    fn scaled(&self, k: f64) -> StageMs {
        StageMs::from_values(self.named().map(|x| x.1 * k))
    }
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Steps taken.
    pub steps: usize,
    /// Simulated time, s.
    pub simulated: f64,
    /// Wall time of the steps alone, s.
    pub wall: f64,
    /// Bodies at the end.
    pub bodies: usize,
    /// Awake bodies at the end.
    pub awake: usize,
    /// Sleeping bodies at the end.
    pub sleeping: usize,
    /// Joints at the end.
    pub joints: usize,
    /// Touching solid contacts at the end.
    pub contacts: usize,
    /// Crossings started, completed, cancelled over the run.
    pub crossings: [usize; 3],
    /// Steps in which a body went non-finite (and was reset).
    pub non_finite_steps: usize,
    /// Mean time per stage, ms per step.
    pub mean: StageMs,
    /// Counters of the last step.
    pub counters: StepCounters,
    /// The probe's label, position and angle at the end.
    pub probe: Option<(String, [f64; 2], f64)>,
    /// Frames written.
    pub frames: usize,
}

impl Summary {
    /// Mean wall time of a step, ms.
    #[must_use]
    pub fn ms_per_step(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.wall * 1e3 / self.steps as f64
        }
    }
}

struct Pictures {
    raster: Raster,
    gif: Option<GifWriter<std::io::BufWriter<std::fs::File>>>,
    dir: Option<PathBuf>,
    svg: bool,
    written: usize,
    /// Digits of the step in a frame's file name.
    digits: usize,
}

/// What a frame's overlay says.
struct Caption {
    step: usize,
    time: f64,
    bodies: usize,
    /// Mean wall time of the steps since the previous frame (none on the
    /// first frame).
    ms_per_step: Option<f64>,
}

impl Caption {
    fn items(&self) -> Vec<String> {
        let mut items = vec![
            format!("step {}", self.step),
            format!("t {:.3} s", self.time),
            format!("bodies {}", self.bodies),
        ];
        if let Some(ms) = self.ms_per_step {
            items.push(format!("{ms:.3} ms/step"));
        }
        items
    }
}

impl Pictures {
    fn new(
        frames: &Frames,
        camera: Camera,
        delay_cs: u16,
        last_step: usize,
    ) -> Result<Option<Pictures>, CliError> {
        let (gif, dir) = match frames {
            Frames::None => return Ok(None),
            Frames::Png(dir) | Frames::Svg(dir) => {
                std::fs::create_dir_all(dir).map_err(|e| CliError::io(dir, &e))?;
                (None, Some(dir.clone()))
            }
            Frames::Gif(path) => {
                let f = std::fs::File::create(path).map_err(|e| CliError::io(path, &e))?;
                let w = GifWriter::new(
                    std::io::BufWriter::new(f),
                    camera.width,
                    camera.height,
                    delay_cs,
                )?;
                (Some(w), None)
            }
        };
        Ok(Some(Pictures {
            raster: Raster::new(camera)?,
            gif,
            dir,
            svg: matches!(frames, Frames::Svg(_)),
            written: 0,
            digits: last_step.to_string().len().max(5),
        }))
    }

    /// The frame of step `caption.step`, with the overlay when `overlay`.
    fn shoot(
        &mut self,
        world: &World,
        draw: &DrawOptions,
        caption: &Caption,
        overlay: bool,
    ) -> Result<(), CliError> {
        let name = |ext: &str| format!("frame_{:0w$}.{ext}", caption.step, w = self.digits);
        if self.svg {
            if let Some(dir) = &self.dir {
                let mut svg = janus2d_render::Svg::new(self.raster.camera);
                svg.draw_world(world, draw);
                svg.save(&dir.join(name("svg")))?;
            }
            self.written += 1;
            return Ok(());
        }
        self.raster.draw_world(world, draw);
        if overlay {
            let lines = janus2d_render::text::wrap(&caption.items(), self.raster.camera.width);
            self.raster.overlay(&lines);
        }
        if let Some(g) = &mut self.gif {
            g.add(&self.raster)?;
        }
        if let Some(dir) = &self.dir {
            self.raster.save_png(&dir.join(name("png")))?;
        }
        self.written += 1;
        Ok(())
    }

    fn finish(self) -> Result<usize, CliError> {
        if let Some(g) = self.gif {
            let mut w = g.finish()?;
            w.flush().map_err(|e| CliError::Io {
                path: "gif".into(),
                message: e.to_string(),
            })?;
        }
        Ok(self.written)
    }
}

const CSV_HEADER: &str = "step,time_s,bodies,awake,touching,crossings,total_ms,broadphase_ms,narrowphase_ms,portals_ms,prepare_ms,integrate_ms,warm_start_ms,solve_ms,relax_ms,restitution_ms,finalize_ms,sleep_ms";

fn io_err(what: &str) -> impl Fn(std::io::Error) -> CliError + '_ {
    move |e| CliError::Io {
        path: what.to_owned(),
        message: e.to_string(),
    }
}

/// Runs `scene` as `options` says, printing what happened to `out`.
pub fn run<W: Write + Send>(
    scene: &mut Loaded,
    options: &RunOptions,
    out: &mut W,
) -> Result<Summary, CliError> {
    if options.threads == 0 {
        return Err(CliError::Invalid("--threads must be at least 1".into()));
    }
    if options.threads > 1 && cfg!(not(feature = "parallel")) {
        return Err(CliError::Invalid(format!(
            "--threads {} needs the parallel feature (on by default): build without `--no-default-features`",
            options.threads
        )));
    }
    // Always inside a pool of exactly `threads` (the world's parallel
    // narrowphase would otherwise use rayon's global pool, one thread per core).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads)
        .build()
        .map_err(|e| CliError::Invalid(format!("cannot start {} threads: {e}", options.threads)))?;
    pool.install(|| run_here(scene, options, out))
}

fn describe(scene: &Loaded, steps: usize, threads: usize) -> String {
    let w = scene.world();
    let s = w.settings();
    let mut line = format!(
        "janus2d run {} ({}): {} bodies, {} joints",
        scene.name,
        scene.source,
        w.body_count(),
        w.joint_count()
    );
    #[cfg(feature = "portals")]
    if w.portal_pair_count() > 0 {
        let n = w.portal_pair_count();
        line.push_str(&format!(
            ", {n} portal pair{}",
            if n == 1 { "" } else { "s" }
        ));
    }
    line.push_str(&format!(
        "; {steps} steps of {:.4} s, {} substeps, sleep {}, {threads} thread{}",
        to_f64(scene.dt),
        s.substeps,
        if w.sleep_settings().enabled {
            "on"
        } else {
            "off"
        },
        if threads == 1 { "" } else { "s" }
    ));
    line
}

fn run_here<W: Write>(
    scene: &mut Loaded,
    options: &RunOptions,
    out: &mut W,
) -> Result<Summary, CliError> {
    let steps = options.steps.unwrap_or(scene.steps);
    if let Some(n) = options.substeps {
        let mut s = scene.world().settings().clone();
        s.substeps = n;
        scene
            .world_mut()
            .set_settings(s)
            .map_err(|e| CliError::Invalid(format!("--substeps {n}: {e}")))?;
    }
    let (width, height) = options.size;
    if width == 0 || height == 0 {
        return Err(CliError::Invalid("--size must be at least 1x1".into()));
    }
    if options.follow && scene.probe.is_none() {
        return Err(CliError::Invalid(format!(
            "scene `{}` has no probe body to follow",
            scene.name
        )));
    }
    let stdout_err = io_err("output");
    writeln!(out, "{}", describe(scene, steps, options.threads)).map_err(&stdout_err)?;

    let every = options
        .every
        .unwrap_or(match options.frames {
            Frames::Gif(_) => 2,
            _ => 1,
        })
        .max(1);
    let delay_cs = ((every as f64 * to_f64(scene.dt) * 100.0).round() as u16).max(2);
    let mut camera = Camera::fit_world(scene.world(), width, height);
    let mut pictures = Pictures::new(&options.frames, camera, delay_cs, steps)?;
    let mut csv = match &options.csv {
        Some(p) => {
            let f = std::fs::File::create(p).map_err(|e| CliError::io(p, &e))?;
            let mut w = std::io::BufWriter::new(f);
            writeln!(w, "{CSV_HEADER}").map_err(|e| CliError::io(p, &e))?;
            Some((w, p.clone()))
        }
        None => None,
    };
    // The union of the scene's boxes so far (`--fit grow`).
    let mut seen: Option<Aabb> = None;
    let mut aim = |camera: &mut Camera, scene: &Loaded, step: usize| {
        let world = scene.world();
        match options.fit {
            Fit::Once => {}
            Fit::Each => *camera = Camera::fit_world(world, width, height),
            Fit::Grow => {
                let b = scene_bounds(world);
                let all = seen.map_or(b, |s| s.union(&b));
                seen = Some(all);
                *camera = Camera::fit(&all, width, height, 0.05);
            }
            Fit::Every(n) => {
                if step > 0 && step.is_multiple_of(n) {
                    *camera = Camera::fit_world(world, width, height);
                }
            }
        }
        if options.follow
            && let Some(p) = scene.probe
        {
            camera.follow(scene.world(), p);
        }
    };
    if let Some(pics) = &mut pictures {
        aim(&mut camera, scene, 0);
        pics.raster.camera = camera;
        let caption = Caption {
            step: 0,
            time: 0.0,
            bodies: scene.world().body_count(),
            ms_per_step: None,
        };
        pics.shoot(scene.world(), &options.draw, &caption, options.overlay)?;
    }
    // Wall time of the steps since the last frame, and how many.
    let mut since_frame = (0.0f64, 0usize);

    let start = Instant::now();
    let mut bar: Option<indicatif::ProgressBar> = None;
    let mut wall = 0.0;
    let mut sum = StageMs::default();
    #[cfg_attr(not(feature = "portals"), allow(unused_mut))]
    let mut crossings = [0usize; 3];
    let mut non_finite_steps = 0;
    let mut printed = 0usize;
    let mut unprinted = 0usize;
    for step in 0..steps {
        let t0 = Instant::now();
        scene.step(step)?;
        let took = t0.elapsed().as_secs_f64();
        wall += took;
        since_frame = (since_frame.0 + took, since_frame.1 + 1);
        let world = scene.world();
        sum.add(&StageMs::of(world));
        let time = (step + 1) as f64 * to_f64(scene.dt);
        let mut events: Vec<String> = Vec::new();
        if !world.events().non_finite_bodies.is_empty() {
            non_finite_steps += 1;
            events.push(format!(
                "{} bodies went non-finite and were reset",
                world.events().non_finite_bodies.len()
            ));
        }
        #[cfg(feature = "portals")]
        for e in &world.events().portals {
            use janus2d_world::PortalEvent;
            events.push(match e {
                PortalEvent::CrossingStarted { body, clone, .. } => {
                    crossings[0] += 1;
                    format!(
                        "body {} enters a portal; clone {} created",
                        body.index, clone.index
                    )
                }
                PortalEvent::CrossingCompleted { body, .. } => {
                    crossings[1] += 1;
                    let v = world.linear_velocity(*body).unwrap_or_default();
                    format!(
                        "body {} is through, moving at ({:.2}, {:.2}) m/s",
                        body.index, v.x, v.y
                    )
                }
                PortalEvent::CrossingCancelled { body, .. } => {
                    crossings[2] += 1;
                    format!("body {} backed out of a portal", body.index)
                }
                PortalEvent::JointDisabled { joint, .. } => {
                    format!("joint {} would span a portal: disabled", joint.index)
                }
            });
        }
        for e in events {
            if printed < options.max_events {
                if let Some(b) = &bar {
                    b.suspend(|| writeln!(out, "  t = {time:7.3} s  {e}"))
                        .map_err(&stdout_err)?;
                } else {
                    writeln!(out, "  t = {time:7.3} s  {e}").map_err(&stdout_err)?;
                }
                printed += 1;
            } else {
                unprinted += 1;
            }
        }
        if let Some((w, p)) = &mut csv {
            let m = StageMs::of(world);
            let c = world.counters();
            let mut row = format!(
                "{},{time:.6},{},{},{},{}",
                step + 1,
                world.body_count(),
                c.awake_bodies,
                world.touching_contact_count(),
                c.portal_crossings
            );
            let named = m.named();
            row.push_str(&format!(",{:.4}", m.total));
            for (_, v) in &named[..named.len() - 1] {
                row.push_str(&format!(",{v:.4}"));
            }
            writeln!(w, "{row}").map_err(|e| CliError::io(p, &e))?;
        }
        if let Some(pics) = &mut pictures
            && (step + 1) % every == 0
        {
            aim(&mut camera, scene, step + 1);
            pics.raster.camera = camera;
            let caption = Caption {
                step: step + 1,
                time,
                bodies: scene.world().body_count(),
                ms_per_step: Some(since_frame.0 * 1e3 / since_frame.1.max(1) as f64),
            };
            pics.shoot(scene.world(), &options.draw, &caption, options.overlay)?;
            since_frame = (0.0, 0);
        }
        if options.progress
            && bar.is_none()
            && start.elapsed().as_secs_f64() > 1.0
            && step + 1 < steps
        {
            let b = indicatif::ProgressBar::new(steps as u64).with_position(step as u64 + 1);
            if let Ok(style) =
                indicatif::ProgressStyle::with_template("  {bar:40} {pos}/{len} steps, {eta} left")
            {
                b.set_style(style);
            }
            bar = Some(b);
        }
        if let Some(b) = &bar {
            b.set_position(step as u64 + 1);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if unprinted > 0 {
        writeln!(out, "  … and {unprinted} more events").map_err(&stdout_err)?;
    }
    if let Some((mut w, p)) = csv {
        w.flush().map_err(|e| CliError::io(&p, &e))?;
    }
    let frames = match pictures {
        Some(p) => p.finish()?,
        None => 0,
    };
    let world = scene.world();
    let counters = world.counters();
    let probe = scene.probe.and_then(|p| {
        let x = world.position(p).ok()?;
        let a = world.angle(p).ok()?;
        Some((
            scene.probe_label.clone(),
            [to_f64(x.x), to_f64(x.y)],
            to_f64(a),
        ))
    });
    let summary = Summary {
        scene: scene.name.clone(),
        steps,
        simulated: steps as f64 * to_f64(scene.dt),
        wall,
        bodies: world.body_count(),
        awake: counters.awake_bodies,
        sleeping: world.sleeping_body_count(),
        joints: world.joint_count(),
        contacts: world.touching_contact_count(),
        crossings,
        non_finite_steps,
        mean: if steps > 0 {
            sum.scaled(1.0 / steps as f64)
        } else {
            sum
        },
        counters,
        probe,
        frames,
    };
    print_summary(&summary, options, out).map_err(&stdout_err)?;
    Ok(summary)
}

/// Prints the summary (and with `options.profile` the stage table and the
/// last step's counters).
pub fn print_summary<W: Write>(
    s: &Summary,
    options: &RunOptions,
    out: &mut W,
) -> std::io::Result<()> {
    writeln!(
        out,
        "done: {} steps ({:.2} s simulated) in {:.1} ms, {:.3} ms/step",
        s.steps,
        s.simulated,
        s.wall * 1e3,
        s.ms_per_step()
    )?;
    writeln!(
        out,
        "  bodies {} (awake {}, asleep {}, static {}), joints {}, touching contacts {}",
        s.bodies,
        s.awake,
        s.sleeping,
        // Static bodies are neither awake nor asleep.
        s.bodies.saturating_sub(s.awake + s.sleeping),
        s.joints,
        s.contacts
    )?;
    if s.crossings.iter().any(|&c| c > 0) {
        writeln!(
            out,
            "  portal crossings: {} started, {} completed, {} cancelled",
            s.crossings[0], s.crossings[1], s.crossings[2]
        )?;
    }
    if s.non_finite_steps > 0 {
        writeln!(
            out,
            "  steps with non-finite bodies: {}",
            s.non_finite_steps
        )?;
    }
    if let Some((label, p, a)) = &s.probe {
        writeln!(
            out,
            "  {label} at ({:.3}, {:.3}) m, angle {a:.3} rad",
            p[0], p[1]
        )?;
    }
    if s.frames > 0 {
        writeln!(out, "  frames written: {}", s.frames)?;
    }
    let m = &s.mean;
    let solver =
        m.prepare + m.integrate + m.warm_start + m.solve + m.relax + m.restitution + m.finalize;
    writeln!(
        out,
        "  ms/step by stage: broadphase {:.3}, narrowphase {:.3}, portals {:.3}, solver {:.3}, sleep {:.3}, step {:.3}",
        m.broadphase, m.narrowphase, m.portals, solver, m.sleep, m.total
    )?;
    if options.profile {
        writeln!(out, "  {:<12} {:>10} {:>7}", "stage", "ms/step", "share")?;
        for (name, v) in m.named() {
            let share = if m.total > 0.0 {
                100.0 * v / m.total
            } else {
                0.0
            };
            writeln!(out, "  {name:<12} {v:>10.4} {share:>6.1}%")?;
        }
        let c = &s.counters;
        writeln!(
            out,
            "  last step: {} pairs tested, {} new pairs, {} proxies moved, {} contacts ({} rows), {} joint rows ({} direct), {} portal rows, {} crossings, {} awake, {} asleep",
            c.pairs_tested,
            c.pairs_created,
            c.proxies_moved,
            c.contacts,
            c.contact_rows,
            c.joint_rows,
            c.direct_joint_rows,
            c.portal_rows,
            c.portal_crossings,
            c.awake_bodies,
            c.sleeping_bodies
        )?;
    }
    Ok(())
}
