//! The command line's arguments (`clap` derive) and what each command does.
//!
//! | command | what |
//! |---------|------|
//! | `janus2d list` | the built-in scenes, by group, with their bodies and steps |
//! | `janus2d run SCENE [--steps N] [--substeps N] [--threads N] [--png DIR \| --gif FILE \| --svg DIR] [--every K] [--size WxH] [--follow] [--fit once\|each\|grow\|N] [--draw FLAGS] [--overlay] [--profile] [--csv FILE]` | runs a built-in scene or a scene file, prints what happened and a summary |
//! | `janus2d export SCENE [-o FILE]` | writes a built-in scene (one without a script) as a scene file |
//! | `janus2d serve [SCENE] [--port P] [--fit once\|each\|grow\|N]` | runs the scene and streams it to a page on `http://127.0.0.1:P/` ([`crate::serve`]) |

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};
use janus2d_world::DrawOptions;

use crate::catalog;
use crate::error::CliError;
use crate::runner::{self, Frames, RunOptions};
use crate::scene_file::SceneFile;

/// janus2d: run the physics engine's scenes headless, with pictures.
#[derive(Debug, Parser)]
#[command(name = "janus2d", version, about)]
pub struct Cli {
    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// List the built-in scenes.
    List,
    /// Run a built-in scene or a JSON scene file.
    Run(RunArgs),
    /// Run a scene and show it on a page at http://127.0.0.1:PORT/.
    Serve {
        /// A built-in scene or a scene file.
        #[arg(default_value = "portal_drop")]
        scene: String,
        /// The port (0: any free one).
        #[arg(long, default_value_t = 8080)]
        port: u16,
        /// When the page's camera fits the scene: `once` (at the start and
        /// on reset), `each` frame, `grow` (only zooms out) or every N
        /// steps. Zooming or panning by hand stops it; a double-click
        /// fits again.
        #[arg(long, default_value = "once")]
        fit: String,
    },
    /// Write a built-in scene as a JSON scene file.
    Export {
        /// The built-in scene.
        scene: String,
        /// The file (standard output without it).
        #[arg(short, long)]
        out: Option<PathBuf>,
    },
}

/// `janus2d run`'s arguments.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// A built-in scene (`janus2d list`) or a scene file (`.json`).
    pub scene: String,
    /// Steps to run (the scene's own by default).
    #[arg(long)]
    pub steps: Option<usize>,
    /// Substeps per step (the scene's own by default).
    #[arg(long)]
    pub substeps: Option<u32>,
    /// Worker threads of the step (above 1 needs the `parallel` feature,
    /// on by default).
    #[arg(long, default_value_t = 1)]
    pub threads: usize,
    /// Write a PNG frame into this folder every `--every` steps.
    #[arg(long, conflicts_with = "gif")]
    pub png: Option<PathBuf>,
    /// Write the run as a looping GIF.
    #[arg(long, conflicts_with = "svg")]
    pub gif: Option<PathBuf>,
    /// Write an SVG frame into this folder every `--every` steps.
    #[arg(long, conflicts_with = "png")]
    pub svg: Option<PathBuf>,
    /// A frame every K steps (PNG 1, GIF 2).
    #[arg(long)]
    pub every: Option<usize>,
    /// Picture size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "640x360")]
    pub size: String,
    /// The camera follows the scene's probe body.
    #[arg(long)]
    pub follow: bool,
    /// When the camera fits the scene: `once` (the first frame), `each`
    /// frame, `grow` (every frame, over all seen so far: it only zooms
    /// out, so bodies spawned later stay in view) or every N steps.
    #[arg(long, default_value = "once")]
    pub fit: String,
    /// What the pictures show: `default`, `all`, `none`, or a comma list
    /// of shapes, sleep, islands, joints, contacts, normals, impulses,
    /// aabbs, transforms, portals, apertures, crossings (`+flag` adds to
    /// the default, `-flag` removes).
    #[arg(long)]
    pub draw: Option<String>,
    /// Write step, time, bodies and ms/step on PNG and GIF frames.
    #[arg(long)]
    pub overlay: bool,
    /// Print the per-stage profile table and the last step's counters.
    #[arg(long)]
    pub profile: bool,
    /// Write one CSV row per step (counts and stage times).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub no_progress: bool,
}

/// `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    let bad = || CliError::Invalid(format!("--size `{s}`: expected WIDTHxHEIGHT, e.g. 640x360"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(CliError::Invalid(format!(
            "--size `{s}`: 1 to 8192 pixels each way"
        )));
    }
    Ok((w, h))
}

/// The draw flags of `--draw`.
pub fn parse_draw(s: &str) -> Result<DrawOptions, CliError> {
    let mut o = match s {
        "default" | "" => return Ok(DrawOptions::default()),
        "all" => return Ok(DrawOptions::all()),
        "none" => return Ok(DrawOptions::none()),
        _ if s.starts_with(['+', '-']) => DrawOptions::default(),
        _ => DrawOptions::none(),
    };
    for item in s.split(',').map(str::trim).filter(|i| !i.is_empty()) {
        let (on, name) = match item.strip_prefix('-') {
            Some(rest) => (false, rest),
            None => (true, item.strip_prefix('+').unwrap_or(item)),
        };
        let flag = match name {
            "shapes" => &mut o.shapes,
            "sleep" => &mut o.sleep,
            "islands" => &mut o.islands,
            "joints" => &mut o.joints,
            "contacts" => &mut o.contacts,
            "normals" => &mut o.contact_normals,
            "impulses" => &mut o.contact_impulses,
            "aabbs" => &mut o.aabbs,
            "transforms" => &mut o.transforms,
            "portals" => &mut o.portals,
            "apertures" => &mut o.apertures,
            "crossings" => &mut o.crossings,
            other => {
                return Err(CliError::Invalid(format!(
                    "--draw: unknown flag `{other}` (shapes, sleep, islands, joints, contacts, normals, impulses, aabbs, transforms, portals, apertures, crossings)"
                )));
            }
        };
        *flag = on;
    }
    Ok(o)
}

impl RunArgs {
    /// The run options these arguments give.
    pub fn options(&self) -> Result<RunOptions, CliError> {
        let frames = match (&self.png, &self.gif, &self.svg) {
            (Some(d), _, _) => Frames::Png(d.clone()),
            (None, Some(g), _) => Frames::Gif(g.clone()),
            (None, None, Some(d)) => Frames::Svg(d.clone()),
            (None, None, None) => Frames::None,
        };
        if self.every == Some(0) {
            return Err(CliError::Invalid("--every must be at least 1".into()));
        }
        Ok(RunOptions {
            steps: self.steps,
            substeps: self.substeps,
            threads: self.threads,
            frames,
            every: self.every,
            size: parse_size(&self.size)?,
            follow: self.follow,
            fit: self.fit.parse()?,
            draw: match &self.draw {
                Some(d) => parse_draw(d)?,
                None => DrawOptions::default(),
            },
            overlay: self.overlay,
            profile: self.profile,
            csv: self.csv.clone(),
            progress: !self.no_progress,
            ..RunOptions::default()
        })
    }
}

/// Prints the built-in scenes.
pub fn list<W: Write>(out: &mut W) -> std::io::Result<()> {
    let entries: Vec<&catalog::Entry> = catalog::entries().collect();
    let width = entries.iter().map(|e| e.name.len()).max().unwrap_or(4);
    let mut group = "";
    for e in entries {
        if e.group != group {
            group = e.group;
            writeln!(out, "{group}:")?;
        }
        writeln!(
            out,
            "  {:<width$}  {:>5} steps  {}",
            e.name,
            e.steps,
            e.about()
        )?;
    }
    writeln!(
        out,
        "or a scene file: janus2d run path/to/scene.json (see crates/cli/scenes/)"
    )
}

/// Runs one parsed command line, printing to `out`.
pub fn execute<W: Write + Send>(cli: &Cli, out: &mut W) -> Result<(), CliError> {
    let io = |e: std::io::Error| CliError::Io {
        path: "output".into(),
        message: e.to_string(),
    };
    match &cli.command {
        Command::List => list(out).map_err(io),
        Command::Run(args) => {
            let options = args.options()?;
            let mut scene = runner::load(&args.scene)?;
            runner::run(&mut scene, &options, out).map(|_| ())
        }
        Command::Serve { scene, port, fit } => {
            let fit = fit.parse()?;
            crate::serve::serve_fit(scene, *port, fit, |addr| {
                let _ = writeln!(
                    out,
                    "janus2d serve {scene}: open http://{addr}/ (Ctrl-C stops)"
                );
                let _ = out.flush();
            })
        }
        Command::Export { scene, out: file } => {
            let e = catalog::find(scene)?;
            let text = SceneFile::from_desc(&e.build())
                .map_err(CliError::Invalid)?
                .to_json();
            match file {
                Some(p) => std::fs::write(p, text + "\n").map_err(|e| CliError::io(p, &e)),
                None => writeln!(out, "{text}").map_err(io),
            }
        }
    }
}
