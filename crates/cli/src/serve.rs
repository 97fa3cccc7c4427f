//! `janus2d serve`: the scene runs in the native engine and its frames
//! stream to a page on `127.0.0.1` (HTTP and WebSocket through `axum`),
//! where a canvas draws them.
//!
//! ```text
//!  browser ── GET /[?scene=NAME]  the page (self-contained: no network
//!                                 needed) with the scene picked and its
//!                                 first frame as an inline SVG, so the page
//!                                 shows the scene before (or without) scripts
//!          ── GET /scenes  the built-in scene names (JSON)
//!          ══ /ws[?scene=NAME]  WebSocket: controls in, frames out
//!
//!  NAME: a built-in scene, or the served one (a scene file only when
//!  `janus2d serve` was given it).
//!
//!  per connection: a simulation thread ── frames (bounded channel: the
//!  page's pace throttles it) ──▶ the socket task ──▶ the page
//!                                 ◀── controls (pause, play, step, reset,
//!                                      scene, substeps, draw flags)
//! ```
//!
//! | message in (JSON)                     | effect                            |
//! |---------------------------------------|-----------------------------------|
//! | `{"cmd":"pause"}`, `{"cmd":"play"}`   | stop / go on stepping             |
//! | `{"cmd":"step"}`                      | one step (pauses)                 |
//! | `{"cmd":"reset"}`                     | the scene again from its start    |
//! | `{"cmd":"scene","name":"tumbler"}`    | another built-in scene            |
//! | `{"cmd":"substeps","n":8}`            | substeps from now on              |
//! | `{"cmd":"draw","flags":"+contacts"}`  | draw flags as `run --draw` takes  |
//! | `{"cmd":"knob","name":"contact_hertz","value":60}` | a solver setting, live ([`Control::Knob`]) |
//! | `{"cmd":"grab","x":1,"y":2}`, `drag`, `release` | pull a body by a mouse joint (5 Hz, ζ 0.7, at most 1000 g of force; [`Session::grab_joint`]) |
//! | `{"cmd":"spawn","x":1,"y":2}`         | drop a 1 m box there              |
//!
//! | message out                           | what                              |
//! |---------------------------------------|-----------------------------------|
//! | `{"type":"scene",…}`                  | name, bounds to fit, dt, substeps (after load and reset) |
//! | `{"type":"frame",…}`                  | step, time, counts, the stage profile (ms), the primitives ([`FrameRecorder`]) and, when `--fit` is not `once` and it is time, `fit`: the bounds to fit |
//! | `{"type":"error","message":…}`        | a control that failed (unknown scene, bad flags) |

use std::sync::Arc;
use std::sync::mpsc as std_mpsc;
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Query, State};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use janus2d_constraints::{MouseJoint, MouseJointDef};
use janus2d_core::body::{BodyDef, BodyHandle, BodyType};
use janus2d_core::geometry::{Aabb, Polygon, Shape};
use janus2d_core::math::{Real, Transform, Vec2, from_f64, to_f64};
use janus2d_world::debug_draw::{Color, DebugDraw};
use janus2d_world::{DrawOptions, JointHandle, ShapeDef, World};
use serde::Deserialize;
use serde_json::{Value, json};

use crate::catalog;
use crate::cli::parse_draw;
use crate::error::CliError;
use crate::runner::{self, Fit, Loaded};

/// The page (HTML, CSS and script in one file).
pub const PAGE: &str = include_str!("serve_page.html");

/// A control from the page.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "cmd", rename_all = "snake_case")]
pub enum Control {
    /// Stop stepping.
    Pause,
    /// Go on stepping.
    Play,
    /// One step, then pause.
    Step,
    /// The scene again from its start.
    Reset,
    /// Another built-in scene.
    Scene {
        /// Its name.
        name: String,
    },
    /// Substeps from now on.
    Substeps {
        /// How many (≥ 1).
        n: u32,
    },
    /// Draw flags, as `janus2d run --draw` takes them.
    Draw {
        /// The flags.
        flags: String,
    },
    /// An accuracy knob of the solver settings, live: `relax_iterations`,
    /// `contact_hertz`, `contact_damping_ratio`, `contact_push_max_velocity`,
    /// `joint_hertz`, `joint_damping_ratio`, `restitution_threshold`,
    /// `warm_starting` (0 or 1), or `gravity` (its y, m/s²).
    Knob {
        /// The setting.
        name: String,
        /// Its new value.
        value: f64,
    },
    /// Grabs the dynamic body under a world point (m): a mouse joint then
    /// pulls that point of it towards the drag target.
    Grab {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
    },
    /// Moves the drag target (m): the mouse joint's `target`.
    Drag {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
    },
    /// Lets the grabbed body go: the mouse joint is destroyed.
    Release,
    /// Drops a 1 m box at a world point (m).
    Spawn {
        /// x, m.
        x: f64,
        /// y, m.
        y: f64,
    },
}

fn q(x: Real) -> Value {
    let v = (to_f64(x) * 1000.0).round() / 1000.0;
    json!(v)
}

fn hex(c: Color) -> String {
    let [r, g, b, a] = c.to_rgba8();
    if a == 255 {
        format!("#{r:02x}{g:02x}{b:02x}")
    } else {
        format!("#{r:02x}{g:02x}{b:02x}{a:02x}")
    }
}

/// A [`DebugDraw`] that records primitives as compact JSON arrays, world
/// coordinates rounded to the millimetre:
///
/// | primitive      | array                                          |
/// |----------------|------------------------------------------------|
/// | polygon        | `["p", colour, x0, y0, x1, y1, …]` (outline)   |
/// | solid polygon  | `["P", colour, radius, x0, y0, …]`             |
/// | circle         | `["c", colour, x, y, r]`                       |
/// | solid circle   | `["C", colour, x, y, r, axis x, axis y]`       |
/// | solid capsule  | `["K", colour, x1, y1, x2, y2, r]`             |
/// | segment        | `["L", colour, x1, y1, x2, y2]`                |
/// | point          | `["D", colour, x, y, size px]`                 |
/// | text           | `["T", colour, x, y, text]`                    |
#[derive(Default)]
pub struct FrameRecorder {
    /// The primitives so far.
    pub prims: Vec<Value>,
}

impl FrameRecorder {
    fn push(&mut self, kind: &str, color: Color, rest: impl IntoIterator<Item = Value>) {
        let mut v = vec![json!(kind), json!(hex(color))];
        v.extend(rest);
        self.prims.push(Value::Array(v));
    }
}

fn xy(points: &[Vec2]) -> Vec<Value> {
    points.iter().flat_map(|p| [q(p.x), q(p.y)]).collect()
}

impl DebugDraw for FrameRecorder {
    fn polygon(&mut self, vertices: &[Vec2], color: Color) {
        self.push("p", color, xy(vertices));
    }
    fn solid_polygon(&mut self, vertices: &[Vec2], radius: Real, color: Color) {
        let mut v = vec![q(radius)];
        v.extend(xy(vertices));
        self.push("P", color, v);
    }
    fn circle(&mut self, center: Vec2, radius: Real, color: Color) {
        self.push("c", color, [q(center.x), q(center.y), q(radius)]);
    }
    fn solid_circle(&mut self, center: Vec2, radius: Real, axis: Vec2, color: Color) {
        self.push(
            "C",
            color,
            [q(center.x), q(center.y), q(radius), q(axis.x), q(axis.y)],
        );
    }
    fn solid_capsule(&mut self, p1: Vec2, p2: Vec2, radius: Real, color: Color) {
        self.push("K", color, [q(p1.x), q(p1.y), q(p2.x), q(p2.y), q(radius)]);
    }
    fn segment(&mut self, p1: Vec2, p2: Vec2, color: Color) {
        self.push("L", color, [q(p1.x), q(p1.y), q(p2.x), q(p2.y)]);
    }
    fn point(&mut self, p: Vec2, size: f32, color: Color) {
        self.push("D", color, [q(p.x), q(p.y), json!(size)]);
    }
    fn text(&mut self, p: Vec2, text: &str, color: Color) {
        self.push("T", color, [q(p.x), q(p.y), json!(text)]);
    }
}

/// The `scene` message for a loaded scene.
#[must_use]
pub fn scene_message(scene: &Loaded) -> String {
    let b = janus2d_render::scene_bounds(scene.world());
    json!({
        "type": "scene",
        "name": scene.name,
        "bounds": [q(b.lower.x), q(b.lower.y), q(b.upper.x), q(b.upper.y)],
        "dt": to_f64(scene.dt),
        "substeps": scene.world().settings().substeps,
        "bodies": scene.world().body_count(),
        "settings": {
            "relax_iterations": scene.world().settings().relax_iterations,
            "contact_hertz": to_f64(scene.world().settings().contact_hertz),
            "contact_damping_ratio": to_f64(scene.world().settings().contact_damping_ratio),
            "joint_hertz": to_f64(scene.world().settings().joint_hertz),
            "joint_damping_ratio": to_f64(scene.world().settings().joint_damping_ratio),
            "contact_push_max_velocity": to_f64(scene.world().settings().contact_push_max_velocity),
            "gravity": to_f64(scene.world().gravity().y),
        },
    })
    .to_string()
}

/// The `frame` message: counts, the stage profile and the primitives.
#[must_use]
pub fn frame_message(scene: &Loaded, step: usize, draw: &DrawOptions, running: bool) -> String {
    frame_message_fit(scene, step, draw, running, None)
}

/// The `frame` message with the bounds the page fits its camera to, if
/// given.
#[must_use]
pub fn frame_message_fit(
    scene: &Loaded,
    step: usize,
    draw: &DrawOptions,
    running: bool,
    fit: Option<Aabb>,
) -> String {
    let w = scene.world();
    let mut rec = FrameRecorder::default();
    w.debug_draw(&mut rec, draw);
    let p = w.profile();
    let s = &p.solver;
    let ms = |x: f64| (x * 1e6).round() / 1e3;
    json!({
        "type": "frame",
        "step": step,
        "time": step as f64 * to_f64(scene.dt),
        "running": running,
        "bodies": w.body_count(),
        "awake": w.awake_body_count(),
        "contacts": w.touching_contact_count(),
        "profile": {
            "broadphase": ms(p.broadphase),
            "narrowphase": ms(p.narrowphase),
            "portals": ms(p.portals),
            "solver": ms(s.prepare + s.integrate + s.warm_start + s.solve + s.relax + s.restitution + s.finalize),
            "sleep": ms(p.sleep),
            "total": ms(p.total),
        },
        "prims": rec.prims,
        "fit": fit.map(|b| json!([q(b.lower.x), q(b.lower.y), q(b.upper.x), q(b.upper.y)])),
    })
    .to_string()
}

fn error_message(e: impl std::fmt::Display) -> String {
    json!({"type": "error", "message": e.to_string()}).to_string()
}

/// One page's simulation: applies controls, steps while running, and
/// hands a frame per tick to `send` (which returns false once the page
/// is gone).
pub struct Session {
    name: String,
    scene: Loaded,
    step: usize,
    running: bool,
    draw: DrawOptions,
    /// The drag in progress.
    grab: Option<Grab>,
    /// When the page's camera fits the scene again.
    fit: Fit,
    /// The union of the scene's boxes so far (`Fit::Grow`).
    seen: Option<Aabb>,
}

/// A drag in progress: a mouse joint from a static body made for the drag
/// (no shapes, at the world origin) to the grabbed body. Both go on
/// release, so a drag leaves the scene's bodies and joints as they were.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Grab {
    /// The grabbed body (the joint's body b).
    body: BodyHandle,
    /// The static body the joint hangs from (its body a).
    ground: BodyHandle,
    /// The mouse joint.
    joint: JointHandle,
}

/// Drag spring frequency, Hz.
const GRAB_HERTZ: Real = 5.0;
/// Drag spring damping ratio.
const GRAB_DAMPING: Real = 0.7;
/// Largest drag force per kilogram, N/kg (1000 g).
const GRAB_MAX_ACCEL: f64 = 1000.0 * 9.81;

fn point(x: f64, y: f64) -> Result<Vec2, CliError> {
    if x.is_finite() && y.is_finite() {
        Ok(Vec2::new(from_f64(x), from_f64(y)))
    } else {
        Err(CliError::Invalid("a point must be finite".into()))
    }
}

/// Whether the world point `p` lies in `shape` of a body at `xf`.
fn contains(shape: &Shape, xf: &Transform, p: Vec2) -> bool {
    let l = xf.apply_inv(p);
    let near_segment = |a: Vec2, b: Vec2, r: Real| {
        let d = b - a;
        let t = ((l - a).dot(d) / d.length_squared().max(Real::EPSILON)).clamp(0.0, 1.0);
        (a + t * d).distance(l) <= r
    };
    match shape {
        Shape::Circle(c) => c.center.distance(l) <= c.radius,
        Shape::Capsule(c) => near_segment(c.center1, c.center2, c.radius),
        Shape::Polygon(poly) => {
            (0..poly.count).all(|i| poly.normals[i].dot(l - poly.vertices[i]) <= poly.radius)
        }
        Shape::Segment(_) | Shape::ChainSegment(_) => false,
    }
}

/// The dynamic body with a shape under `p`, if any.
pub fn body_at(world: &World, p: Vec2) -> Option<BodyHandle> {
    let probe = Aabb::new(p - Vec2::splat(0.01), p + Vec2::splat(0.01));
    world.bodies_in_box(&probe).into_iter().find(|&b| {
        world.body_type(b) == Ok(BodyType::Dynamic)
            && world.transform(b).is_ok_and(|xf| {
                world
                    .body_shapes(b)
                    .unwrap_or_default()
                    .iter()
                    .any(|&s| world.shape(s).is_ok_and(|d| contains(&d.geometry, &xf, p)))
            })
    })
}

impl Session {
    /// A session on the scene called `name` (built-in or file).
    pub fn new(name: &str) -> Result<Session, CliError> {
        Ok(Session {
            name: name.to_owned(),
            scene: runner::load(name)?,
            step: 0,
            running: true,
            draw: DrawOptions::default(),
            grab: None,
            fit: Fit::Once,
            seen: None,
        })
    }

    /// A session whose page camera fits the scene as `fit` says (as
    /// `janus2d run --fit`).
    pub fn with_fit(name: &str, fit: Fit) -> Result<Session, CliError> {
        let mut s = Session::new(name)?;
        s.fit = fit;
        Ok(s)
    }

    /// The bounds the page fits now, if `fit` says it is time.
    fn fit_bounds(&mut self) -> Option<Aabb> {
        let world = self.scene.world();
        match self.fit {
            Fit::Once => None,
            Fit::Each => Some(janus2d_render::scene_bounds(world)),
            Fit::Grow => {
                let b = janus2d_render::scene_bounds(world);
                let all = self.seen.map_or(b, |s| s.union(&b));
                self.seen = Some(all);
                Some(all)
            }
            Fit::Every(n) => (self.step > 0 && self.step.is_multiple_of(n))
                .then(|| janus2d_render::scene_bounds(world)),
        }
    }

    /// The grabbed body, if any.
    #[must_use]
    pub fn grabbed(&self) -> Option<BodyHandle> {
        self.grab.map(|g| g.body)
    }

    /// The mouse joint of the drag in progress, if any.
    #[must_use]
    pub fn grab_joint(&self) -> Option<JointHandle> {
        self.grab.map(|g| g.joint)
    }

    /// Starts a drag at `p`: a static body at the origin and a mouse joint
    /// from it to the dynamic body under `p` (grabbed at `p`, target `p`,
    /// 5 Hz, ζ 0.7, at most 1000 g × its mass). Nothing under `p`: no drag.
    fn grab_at(&mut self, p: Vec2) -> Result<(), CliError> {
        self.release();
        let world = self.scene.world_mut();
        let Some(body) = body_at(world, p) else {
            return Ok(());
        };
        let max_force = world.mass(body)? * from_f64(GRAB_MAX_ACCEL);
        let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
        let made = world.joint_base_at(ground, body, p).and_then(|base| {
            let def =
                MouseJointDef::from_base(base, p, max_force).with_spring(GRAB_HERTZ, GRAB_DAMPING);
            world.create_joint(&def.into())
        });
        match made {
            Ok(joint) => {
                self.grab = Some(Grab {
                    body,
                    ground,
                    joint,
                });
                Ok(())
            }
            Err(e) => {
                let _ = world.destroy_body(ground);
                Err(e.into())
            }
        }
    }

    /// Moves the drag's target to `p` (and frame a's anchor with it, so
    /// the joint is drawn from the target to the grabbed point). A drag
    /// whose joint is gone (its body destroyed) ends.
    fn drag_to(&mut self, p: Vec2) -> Result<(), CliError> {
        let Some(g) = self.grab else {
            return Ok(());
        };
        let world = self.scene.world_mut();
        let Ok(j) = world.joint_of::<MouseJoint>(g.joint) else {
            self.release();
            return Ok(());
        };
        let mut def = j.def().clone().with_target(p);
        def.base.local_frame_a.anchor = p;
        world.set_joint_def(g.joint, def.into())?;
        Ok(())
    }

    /// Ends the drag: the mouse joint and its static body go.
    fn release(&mut self) {
        if let Some(g) = self.grab.take() {
            let world = self.scene.world_mut();
            let _ = world.destroy_joint(g.joint);
            let _ = world.destroy_body(g.ground);
        }
    }

    fn knob(&mut self, name: &str, value: f64) -> Result<(), CliError> {
        let bad = || CliError::Invalid(format!("knob `{name}` = {value}: out of range"));
        if !value.is_finite() {
            return Err(bad());
        }
        let world = self.scene.world_mut();
        if name == "gravity" {
            let g = world.gravity();
            return world
                .set_gravity(Vec2::new(g.x, from_f64(value)))
                .map_err(|_| bad());
        }
        let mut s = world.settings().clone();
        let v = from_f64(value);
        match name {
            "relax_iterations" if value >= 0.0 => s.relax_iterations = value as u32,
            "contact_hertz" => s.contact_hertz = v,
            "contact_damping_ratio" => s.contact_damping_ratio = v,
            "contact_push_max_velocity" => s.contact_push_max_velocity = v,
            "joint_hertz" => s.joint_hertz = v,
            "joint_damping_ratio" => s.joint_damping_ratio = v,
            "restitution_threshold" => s.restitution_threshold = v,
            "warm_starting" => s.warm_starting = value != 0.0,
            "relax_iterations" => return Err(bad()),
            other => return Err(CliError::Invalid(format!("no knob `{other}`"))),
        }
        world
            .set_settings(s)
            .map_err(|e| CliError::Invalid(format!("knob `{name}`: {e}")))
    }

    /// The scene.
    #[must_use]
    pub fn scene(&self) -> &Loaded {
        &self.scene
    }

    /// Steps taken since the scene was loaded.
    #[must_use]
    pub fn step_count(&self) -> usize {
        self.step
    }

    /// Whether it steps on each tick.
    #[must_use]
    pub fn running(&self) -> bool {
        self.running
    }

    /// Applies a control; a new scene message to send when the scene
    /// changed.
    pub fn apply(&mut self, c: Control) -> Result<Option<String>, CliError> {
        match c {
            Control::Pause => self.running = false,
            Control::Play => self.running = true,
            Control::Step => {
                self.running = false;
                self.advance()?;
            }
            Control::Reset => {
                self.grab = None;
                self.scene = runner::load(&self.name)?;
                self.step = 0;
                self.seen = None;
                return Ok(Some(scene_message(&self.scene)));
            }
            Control::Scene { name } => {
                let scene = runner::load(&name)?;
                self.grab = None;
                self.scene = scene;
                self.name = name;
                self.step = 0;
                self.seen = None;
                return Ok(Some(scene_message(&self.scene)));
            }
            Control::Substeps { n } => {
                let mut s = self.scene.world().settings().clone();
                s.substeps = n;
                self.scene
                    .world_mut()
                    .set_settings(s)
                    .map_err(|e| CliError::Invalid(format!("substeps {n}: {e}")))?;
            }
            Control::Draw { flags } => self.draw = parse_draw(&flags)?,
            Control::Knob { name, value } => self.knob(&name, value)?,
            Control::Grab { x, y } => self.grab_at(point(x, y)?)?,
            Control::Drag { x, y } => self.drag_to(point(x, y)?)?,
            Control::Release => self.release(),
            Control::Spawn { x, y } => {
                let p = point(x, y)?;
                let world = self.scene.world_mut();
                let b = world.create_body(&BodyDef::dynamic(p))?;
                world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
            }
        }
        Ok(None)
    }

    /// One step.
    pub fn advance(&mut self) -> Result<(), CliError> {
        if let Some(g) = self.grab
            && self.scene.world().joint(g.joint).is_err()
        {
            // The grabbed body went (a script destroyed it), its joint with it.
            self.release();
        }
        self.scene.step(self.step)?;
        self.step += 1;
        Ok(())
    }

    /// The current frame message.
    #[must_use]
    pub fn frame(&self) -> String {
        frame_message(&self.scene, self.step, &self.draw, self.running)
    }

    /// The current frame message as the loop sends it: with the bounds to
    /// fit when `--fit` says it is time.
    pub fn next_frame(&mut self) -> String {
        let fit = self.fit_bounds();
        frame_message_fit(&self.scene, self.step, &self.draw, self.running, fit)
    }

    /// The loop of a connection's thread: controls in, a frame per tick
    /// out, until either side goes.
    pub fn run(
        mut self,
        controls: &std_mpsc::Receiver<Control>,
        mut send: impl FnMut(String) -> bool,
    ) {
        if !send(scene_message(&self.scene)) {
            return;
        }
        let tick = Duration::from_secs_f64(to_f64(self.scene.dt).clamp(0.001, 0.1));
        loop {
            let start = Instant::now();
            loop {
                match controls.try_recv() {
                    Ok(c) => match self.apply(c) {
                        Ok(Some(msg)) => {
                            if !send(msg) {
                                return;
                            }
                        }
                        Ok(None) => {}
                        Err(e) => {
                            if !send(error_message(e)) {
                                return;
                            }
                        }
                    },
                    Err(std_mpsc::TryRecvError::Empty) => break,
                    Err(std_mpsc::TryRecvError::Disconnected) => return,
                }
            }
            if self.running
                && let Err(e) = self.advance()
            {
                self.running = false;
                if !send(error_message(e)) {
                    return;
                }
            }
            if !send(self.next_frame()) {
                return;
            }
            if let Some(rest) = tick.checked_sub(start.elapsed()) {
                std::thread::sleep(rest);
            }
        }
    }
}

struct AppState {
    scene: String,
    fit: Fit,
}

/// `?scene=NAME` on the page and the WebSocket.
#[derive(Debug, Default, Deserialize)]
struct SceneQuery {
    scene: Option<String>,
}

impl AppState {
    /// The scene a request asks for: a built-in one or the served one;
    /// anything else (a path) gets the served one.
    fn pick(&self, q: &SceneQuery) -> String {
        match &q.scene {
            Some(n) if *n == self.scene || catalog::find(n).is_ok() => n.clone(),
            _ => self.scene.clone(),
        }
    }
}

/// `<`, `>`, `&` and quotes escaped.
fn html_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// Size of the page's first-frame picture, px (it scales to the stage).
pub const STILL_SIZE: (u32, u32) = (1000, 620);

/// The page for `scene`: the picker lists the built-in scenes (and
/// `scene` when it is a file) with `scene` selected, and the stage shows
/// its first frame as an inline SVG drawn here, so the page shows the
/// scene with scripts off, and before the first frame arrives over the
/// WebSocket.
pub fn page_html(scene: &str) -> Result<String, CliError> {
    let loaded = runner::load(scene)?;
    let world = loaded.world();
    let (w, h) = STILL_SIZE;
    let camera = janus2d_render::Camera::fit(&janus2d_render::scene_bounds(world), w, h, 0.05);
    let mut svg = janus2d_render::Svg::new(camera);
    svg.draw_world(world, &DrawOptions::default());
    let mut options = String::new();
    let mut listed = false;
    for e in catalog::entries() {
        let selected = e.name == scene;
        listed |= selected;
        options.push_str(&format!(
            "<option value=\"{n}\"{sel}>{n}</option>",
            n = html_escape(e.name),
            sel = if selected { " selected" } else { "" }
        ));
    }
    if !listed {
        options.push_str(&format!(
            "<option value=\"{n}\" selected>{n}</option>",
            n = html_escape(scene)
        ));
    }
    let status = format!(
        "{}: {} bodies, step 0\nconnecting…",
        loaded.name,
        world.body_count()
    );
    // A JSON string is a JS string; `</` closed so it cannot end the script.
    let served = json!(scene).to_string().replace("</", "<\\/");
    Ok(PAGE
        .replacen("{{OPTIONS}}", &options, 1)
        .replacen("{{STILL}}", &svg.finish(), 1)
        .replacen("{{STATUS}}", &html_escape(&status), 1)
        .replacen("{{SCENE}}", &served, 1))
}

async fn page(State(state): State<Arc<AppState>>, Query(q): Query<SceneQuery>) -> Response {
    let scene = state.pick(&q);
    match tokio::task::spawn_blocking(move || page_html(&scene)).await {
        Ok(Ok(html)) => Html(html).into_response(),
        Ok(Err(e)) => (
            axum::http::StatusCode::INTERNAL_SERVER_ERROR,
            format!("error: {e}"),
        )
            .into_response(),
        Err(e) => (
            axum::http::StatusCode::INTERNAL_SERVER_ERROR,
            format!("error: {e}"),
        )
            .into_response(),
    }
}

async fn scenes() -> Response {
    let names: Vec<String> = catalog::entries().map(|e| e.name.to_owned()).collect();
    axum::Json(json!({ "scenes": names })).into_response()
}

async fn ws(
    ws: WebSocketUpgrade,
    State(state): State<Arc<AppState>>,
    Query(q): Query<SceneQuery>,
) -> Response {
    let scene = state.pick(&q);
    let fit = state.fit;
    ws.on_upgrade(move |socket| connection(socket, scene, fit))
}

async fn connection(mut socket: WebSocket, scene: String, fit: Fit) {
    let session = match Session::with_fit(&scene, fit) {
        Ok(s) => s,
        Err(e) => {
            let _ = socket.send(Message::Text(error_message(e).into())).await;
            return;
        }
    };
    let (control_tx, control_rx) = std_mpsc::channel::<Control>();
    let (frame_tx, mut frame_rx) = tokio::sync::mpsc::channel::<String>(2);
    let sim = std::thread::spawn(move || {
        session.run(&control_rx, |msg| frame_tx.blocking_send(msg).is_ok());
    });
    loop {
        tokio::select! {
            incoming = socket.recv() => match incoming {
                Some(Ok(Message::Text(text))) => {
                    match serde_json::from_str::<Control>(text.as_str()) {
                        Ok(c) => {
                            if control_tx.send(c).is_err() {
                                break;
                            }
                        }
                        Err(e) => {
                            let msg = error_message(format!("bad control: {e}"));
                            if socket.send(Message::Text(msg.into())).await.is_err() {
                                break;
                            }
                        }
                    }
                }
                Some(Ok(Message::Close(_))) | None | Some(Err(_)) => break,
                Some(Ok(_)) => {}
            },
            frame = frame_rx.recv() => match frame {
                Some(f) => {
                    if socket.send(Message::Text(f.into())).await.is_err() {
                        break;
                    }
                }
                None => break,
            },
        }
    }
    drop(control_tx);
    drop(frame_rx);
    let _ = tokio::task::spawn_blocking(move || sim.join()).await;
}

/// The routes: the page, the scene list, the WebSocket.
pub fn app(scene: &str) -> Router {
    app_fit(scene, Fit::Once)
}

/// The routes, the page's camera fitting the scene as `fit` says.
pub fn app_fit(scene: &str, fit: Fit) -> Router {
    Router::new()
        .route("/", get(page))
        .route("/scenes", get(scenes))
        .route("/ws", get(ws))
        .with_state(Arc::new(AppState {
            scene: scene.to_owned(),
            fit,
        }))
}

/// Serves the page for `scene` on `127.0.0.1:port` (0: any free port)
/// until the process ends; `ready` gets the address once bound.
pub fn serve(
    scene: &str,
    port: u16,
    ready: impl FnOnce(std::net::SocketAddr),
) -> Result<(), CliError> {
    serve_fit(scene, port, Fit::Once, ready)
}

/// [`serve`] with the page's camera fitting the scene as `fit` says.
pub fn serve_fit(
    scene: &str,
    port: u16,
    fit: Fit,
    ready: impl FnOnce(std::net::SocketAddr),
) -> Result<(), CliError> {
    // Fail before binding on a scene that does not load.
    runner::load(scene)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .map_err(|e| CliError::Invalid(format!("cannot start the server: {e}")))?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind(("127.0.0.1", port))
            .await
            .map_err(|e| CliError::Invalid(format!("cannot listen on 127.0.0.1:{port}: {e}")))?;
        let addr = listener
            .local_addr()
            .map_err(|e| CliError::Invalid(e.to_string()))?;
        ready(addr);
        axum::serve(listener, app_fit(scene, fit))
            .await
            .map_err(|e| CliError::Invalid(format!("server: {e}")))
    })
}
