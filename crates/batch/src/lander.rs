//! Gymnasium's LunarLander, the environment's whole step in Rust: the
//! engines' impulses from an action, the world's step, the observation,
//! the shaping reward, termination and the legs' ground contacts.
//!
//! A [`LanderBatch`] holds N landers, each a world of its own with its own
//! random number generator, and steps them in one parallel pass over the
//! landers (contiguous runs of landers per thread): no per-lander call
//! from the caller's side, and every lander's trajectory is the same bit
//! for bit on any number of threads.
//!
//! Units follow Gymnasium's `LunarLander-v3`: a 20 × 13.3 m view (600 ×
//! 400 pixels at 30 px/m), 50 steps per second, gravity −10 m/s². The
//! rules are those its documentation states; the bodies are janus2d's: a
//! hull polygon, two box legs on revolute joints whose motors, pushing
//! toward their inner limits, are the legs' springs.
//!
//! ```
//! use janus2d_batch::lander::{LanderActions, LanderBatch, LanderConfig};
//!
//! let mut batch = LanderBatch::new(4, LanderConfig::vector(1000), 7, 1).unwrap();
//! batch.reset_all(7).unwrap();
//! for _ in 0..50 {
//!     batch.step(LanderActions::Discrete(&[0, 1, 2, 3])).unwrap();
//! }
//! let first = batch.outcome(0).unwrap();
//! assert!(first.observation.iter().all(|v| v.is_finite()));
//! ```

use crate::BatchError;
use crate::crew::{Crew, Task};
use janus2d::base::math::to_f64;
use janus2d::{BodyDef, BodyHandle, Polygon, Real, RevoluteJointDef, Segment, ShapeDef, Vec2};
use janus2d::{World, WorldDef, WorldError};

/// Steps per second (the step is `1 / FPS` s).
pub const FPS: f64 = 50.0;
/// Pixels per metre of the view.
pub const PX: f64 = 30.0;
/// Width of the view, m.
pub const VIEW_W: f64 = 600.0 / PX;
/// Height of the view, m.
pub const VIEW_H: f64 = 400.0 / PX;
/// Height of the pad, m.
pub const PAD_Y: f64 = VIEW_H / 4.0;
/// Values in an observation.
pub const OBS_WIDTH: usize = 8;
/// Segments of the ground (`CHUNKS + 1` random heights).
pub const CHUNKS: usize = 11;
/// Random heights drawn for a terrain (the ground has `CHUNKS` points).
pub const TERRAIN_DRAWS: usize = CHUNKS + 1;

const MAIN_POWER: f64 = 13.0;
const SIDE_POWER: f64 = 0.6;
const START_PUSH: f64 = 1000.0;
const HULL: [(f64, f64); 6] = [
    (-14.0, 17.0),
    (-17.0, 0.0),
    (-17.0, -10.0),
    (17.0, -10.0),
    (17.0, 0.0),
    (14.0, 17.0),
];
const LEG_OUT: f64 = 20.0;
const LEG_DROP: f64 = 18.0;
const LEG_HALF_W: f64 = 2.0;
const LEG_HALF_H: f64 = 8.0;
const LEG_TORQUE: f64 = 40.0;
const SIDE_UP: f64 = 14.0;
const SIDE_OUT: f64 = 12.0;
const MAIN_DOWN: f64 = 4.0;

/// Contact category of the ground and scenery.
pub const GROUND_BITS: u64 = 0x0001;
/// Contact category of the hull (it meets only the ground).
pub const HULL_BITS: u64 = 0x0010;
/// Contact category of the legs (they meet only the ground).
pub const LEG_BITS: u64 = 0x0020;

#[cfg(feature = "portals")]
const ROOF_ABOVE_PAD: f64 = 3.0;
#[cfg(feature = "portals")]
const ROOF_HALF_T: f64 = 0.15;
#[cfg(feature = "portals")]
const PORTAL_HALF_W: f64 = 1.6;

/// How the landers of a batch are built and run.
#[derive(Clone, Debug, PartialEq)]
pub struct LanderConfig {
    /// `Box(-1, 1, (2,))` actions (main and side throttle) instead of
    /// `Discrete(4)` (nothing, left engine, main engine, right engine).
    pub continuous: bool,
    /// Gravity, m/s² (between −12 and 0, exclusive).
    pub gravity: f64,
    /// The portal variant: the pad inside a closed chamber, entered
    /// through a portal pair (needs the `portals` feature).
    pub portal: bool,
    /// The engines' random dispersion (Gymnasium's): on by default; off,
    /// the thrust is exactly along the engines' axes.
    pub dispersion: bool,
    /// Steps after which an episode is truncated (0: never; Gymnasium's
    /// time limit is 1000).
    pub max_episode_steps: u32,
    /// A lander whose episode ended is reset by its next step (the action
    /// is then ignored, the reward is 0 and its first observation is
    /// returned), as a Gymnasium vector environment's next-step autoreset.
    /// Off, it keeps stepping until [`LanderBatch::reset_all`].
    pub autoreset: bool,
    /// Gymnasium's wind: while neither leg touches the ground, a
    /// sideways force of `wind_power · tanh(sin(0.02 t) + sin(0.01 π t))`
    /// N and a torque of `turbulence_power` times the same function of
    /// another count (N·m) act on the hull, each count starting at a
    /// random integer in `[-9999, 9999)` drawn at the reset and going up
    /// by one a step. Off by default.
    pub enable_wind: bool,
    /// The wind's largest force, N (Gymnasium's default 15, recommended
    /// range 0 to 20).
    pub wind_power: f64,
    /// The turbulence's largest torque, N·m (Gymnasium's default 1.5,
    /// recommended range 0 to 2).
    pub turbulence_power: f64,
}

impl Default for LanderConfig {
    fn default() -> Self {
        LanderConfig {
            continuous: false,
            gravity: -10.0,
            portal: false,
            dispersion: true,
            max_episode_steps: 0,
            autoreset: false,
            enable_wind: false,
            wind_power: 15.0,
            turbulence_power: 1.5,
        }
    }
}

impl LanderConfig {
    /// A vector environment's configuration: autoreset on, episodes
    /// truncated after `max_episode_steps`.
    #[must_use]
    pub fn vector(max_episode_steps: u32) -> Self {
        LanderConfig {
            max_episode_steps,
            autoreset: true,
            ..LanderConfig::default()
        }
    }

    fn validate(&self) -> Result<(), BatchError> {
        if !(self.gravity > -12.0 && self.gravity < 0.0) {
            return Err(BatchError::Config(format!(
                "gravity {}: between -12 and 0 (exclusive)",
                self.gravity
            )));
        }
        if !(self.wind_power.is_finite() && self.turbulence_power.is_finite()) {
            return Err(BatchError::Config(format!(
                "wind_power {} and turbulence_power {} must be finite",
                self.wind_power, self.turbulence_power
            )));
        }
        if self.portal && !cfg!(feature = "portals") {
            return Err(BatchError::Config(
                "the portal variant needs the `portals` feature".into(),
            ));
        }
        Ok(())
    }
}

/// The actions of every lander for one step.
#[derive(Clone, Copy, Debug)]
pub enum LanderActions<'a> {
    /// One action per lander: 0 nothing, 1 left engine, 2 main engine,
    /// 3 right engine.
    Discrete(&'a [i64]),
    /// Two values per lander, each in `[-1, 1]`: main throttle (off at
    /// or below 0, 50 to 100 % above), side throttle (off within ±0.5;
    /// below −0.5 the left engine, above 0.5 the right one).
    Continuous(&'a [f64]),
}

/// One lander's action.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Action {
    Discrete(i64),
    Continuous(f64, f64),
}

impl Action {
    fn noop(continuous: bool) -> Action {
        if continuous {
            Action::Continuous(-1.0, 0.0)
        } else {
            Action::Discrete(0)
        }
    }

    /// `(m_power, side_dir, s_power)`: the main throttle, the side
    /// engine's direction (−1, 0, 1) and its throttle.
    fn throttles(self) -> (f64, f64, f64) {
        match self {
            Action::Discrete(a) => {
                let m = if a == 2 { 1.0 } else { 0.0 };
                let dir = match a {
                    1 => -1.0,
                    3 => 1.0,
                    _ => 0.0,
                };
                (m, dir, dir.abs())
            }
            Action::Continuous(main, side) => {
                let main = main.clamp(-1.0, 1.0);
                let side = side.clamp(-1.0, 1.0);
                let m = if main > 0.0 {
                    (main.clamp(0.0, 1.0) + 1.0) * 0.5
                } else {
                    0.0
                };
                let dir = if side.abs() > 0.5 { side.signum() } else { 0.0 };
                let s = if dir != 0.0 {
                    side.abs().clamp(0.5, 1.0)
                } else {
                    0.0
                };
                (m, dir, s)
            }
        }
    }
}

/// SplitMix64: a small, fast generator with a 64-bit state, one per
/// lander (so a lander's draws do not depend on the others').
#[derive(Clone, Debug)]
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[low, high)`.
    fn uniform(&mut self, low: f64, high: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        low + (high - low) * unit
    }
}

/// The seed of lander `index` of a batch reset with `seed`.
fn lander_seed(seed: u64, index: usize) -> u64 {
    let mut mix = SplitMix64(seed ^ (index as u64).wrapping_mul(0xD1B5_4A32_D192_ED03));
    mix.next_u64()
}

/// What one step of one lander returned.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LanderOutcome {
    /// Gymnasium's 8 values: position (x, y, scaled to the view), velocity
    /// (scaled), angle, angular velocity (scaled), legs on the ground.
    pub observation: [f32; OBS_WIDTH],
    /// The step's reward.
    pub reward: f64,
    /// The lander crashed, left the view or came to rest.
    pub terminated: bool,
    /// The episode reached `max_episode_steps` without terminating.
    pub truncated: bool,
}

/// The bodies of one lander world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LanderBodies {
    /// The static ground.
    pub ground: BodyHandle,
    /// The hull.
    pub hull: BodyHandle,
    /// The legs, left then right.
    pub legs: [BodyHandle; 2],
    /// The pad's ends, x in m.
    pub pad: (f64, f64),
}

/// The ground's points (x, y) from `TERRAIN_DRAWS` random heights: the
/// middle chunks flat at the pad's height, each height averaged with its
/// neighbours (the first with the last draw, as the Python version did).
#[must_use]
pub fn terrain(draws: &[f64; TERRAIN_DRAWS]) -> ([f64; CHUNKS], [f64; CHUNKS]) {
    let mut h = *draws;
    let mid = CHUNKS / 2;
    for v in &mut h[mid - 2..mid + 3] {
        *v = PAD_Y;
    }
    let mut xs = [0.0; CHUNKS];
    let mut ys = [0.0; CHUNKS];
    for i in 0..CHUNKS {
        xs[i] = VIEW_W / (CHUNKS - 1) as f64 * i as f64;
        let before = if i == 0 {
            h[TERRAIN_DRAWS - 1]
        } else {
            h[i - 1]
        };
        ys[i] = (before + h[i] + h[i + 1]) / 3.0;
    }
    (xs, ys)
}

fn v2(x: f64, y: f64) -> Vec2 {
    Vec2::new(x as Real, y as Real)
}

/// A shape definition: the Rust defaults but for the given fields.
fn shape_def(
    density: Option<f64>,
    friction: Option<f64>,
    restitution: Option<f64>,
    category: u64,
    mask: Option<u64>,
) -> ShapeDef {
    let mut def = ShapeDef::default();
    if let Some(d) = density {
        def.density = d as Real;
    }
    if let Some(f) = friction {
        def.friction = f as Real;
    }
    if let Some(r) = restitution {
        def.restitution = r as Real;
    }
    def.filter.category_bits = category;
    if let Some(m) = mask {
        def.filter.mask_bits = m;
    }
    def
}

/// Builds a lander world on the terrain of `draws`: the ground, the
/// portal scenery when `portal`, the hull at the top of the view and its
/// legs. Every build creates its bodies in the same order.
pub fn build_lander_world(
    draws: &[f64; TERRAIN_DRAWS],
    gravity: f64,
    portal: bool,
) -> Result<(World, LanderBodies), WorldError> {
    let mut world = World::new(WorldDef {
        gravity: v2(0.0, gravity),
        ..WorldDef::default()
    })?;
    // Nobody reads a lander world's stage timings; their clock reads were
    // 7% of its step.
    world.set_profiling(false);
    let (xs, ys) = terrain(draws);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let ground_def = shape_def(None, Some(0.1), None, GROUND_BITS, None);
    for i in 0..CHUNKS - 1 {
        let seg = Segment::new(v2(xs[i], ys[i]), v2(xs[i + 1], ys[i + 1]))?;
        world.create_shape(ground, &ground_def, seg)?;
    }
    let mid = CHUNKS / 2;
    let pad = (xs[mid - 1], xs[mid + 1]);
    if portal {
        add_portal_scenery(&mut world, ground, &ground_def, pad)?;
    }

    let (x0, y0) = (VIEW_W / 2.0, VIEW_H);
    let hull = world.create_body(&BodyDef::dynamic(v2(x0, y0)))?;
    let points: Vec<Vec2> = HULL.iter().map(|&(x, y)| v2(x / PX, y / PX)).collect();
    let hull_def = shape_def(
        Some(5.0),
        Some(0.1),
        Some(0.0),
        HULL_BITS,
        Some(GROUND_BITS),
    );
    world.create_shape(hull, &hull_def, Polygon::from_hull(&points, 0.0)?)?;
    let mut legs = [hull; 2];
    for (k, side) in [-1.0f64, 1.0].into_iter().enumerate() {
        // The pin is at the hull's centre; the leg hangs LEG_OUT to the
        // side and LEG_DROP below it.
        let (lx, ly) = (x0 - side * LEG_OUT / PX, y0 - LEG_DROP / PX);
        let leg = world.create_body(&BodyDef::dynamic(v2(lx, ly)))?;
        let leg_def = shape_def(Some(1.0), None, Some(0.0), LEG_BITS, Some(GROUND_BITS));
        let leg_box = Polygon::try_make_offset_box(
            (LEG_HALF_W / PX) as Real,
            (LEG_HALF_H / PX) as Real,
            Vec2::ZERO,
            0.0,
        )?;
        world.create_shape(leg, &leg_def, leg_box)?;
        // Each leg swings out between 0.4 and 0.9 rad; the motor, pushing
        // toward the inner limit, is its spring.
        let (lower, upper) = if side < 0.0 { (0.4, 0.9) } else { (-0.9, -0.4) };
        let base = world.joint_base_at(hull, leg, v2(x0, y0))?;
        let def = RevoluteJointDef::from_base(base)
            .with_motor((0.3 * side) as Real, LEG_TORQUE as Real)
            .with_limits(lower, upper);
        world.create_joint(&def.into())?;
        legs[k] = leg;
    }
    Ok((
        world,
        LanderBodies {
            ground,
            hull,
            legs,
            pad,
        },
    ))
}

/// The portal variant's scenery: walls at the pad's ends and a roof
/// whose underside carries portal B, and a slab left of the chamber whose
/// top carries portal A.
#[cfg(feature = "portals")]
fn add_portal_scenery(
    world: &mut World,
    ground: BodyHandle,
    ground_def: &ShapeDef,
    pad: (f64, f64),
) -> Result<(), WorldError> {
    use janus2d::{PortalDef, PortalPairDef};
    let (left, right) = pad;
    let mid = 0.5 * (left + right);
    let half = 0.5 * (right - left);
    let roof_y = PAD_Y + ROOF_ABOVE_PAD;
    for x in [left - 0.2, right + 0.2] {
        world.create_shape(
            ground,
            ground_def,
            Segment::new(v2(x, PAD_Y), v2(x, roof_y))?,
        )?;
    }
    let roof = world.create_body(&BodyDef::fixed(v2(mid, roof_y)))?;
    let roof_box =
        Polygon::try_make_offset_box((half + 0.4) as Real, ROOF_HALF_T as Real, Vec2::ZERO, 0.0)?;
    world.create_shape(roof, ground_def, roof_box)?;
    let entry_x = if left > 4.0 {
        0.5 * (left + 0.0)
    } else {
        (left - 3.0).max(2.0)
    };
    let entry_x = entry_x.min(VIEW_W / 2.0 - half - 2.5);
    let slab = world.create_body(&BodyDef::fixed(v2(entry_x, PAD_Y + 0.8)))?;
    let slab_box = Polygon::try_make_offset_box(
        (PORTAL_HALF_W + 0.3) as Real,
        ROOF_HALF_T as Real,
        Vec2::ZERO,
        0.0,
    )?;
    world.create_shape(slab, ground_def, slab_box)?;
    world.create_portal_pair(&PortalPairDef::new(
        PortalDef::new(
            slab,
            v2(0.0, ROOF_HALF_T),
            v2(0.0, 1.0),
            PORTAL_HALF_W as Real,
        ),
        PortalDef::new(
            roof,
            v2(0.0, -ROOF_HALF_T),
            v2(0.0, -1.0),
            PORTAL_HALF_W as Real,
        ),
    ))?;
    Ok(())
}

#[cfg(not(feature = "portals"))]
fn add_portal_scenery(
    _world: &mut World,
    _ground: BodyHandle,
    _ground_def: &ShapeDef,
    _pad: (f64, f64),
) -> Result<(), WorldError> {
    Ok(())
}

/// One lander: its world, bodies, generator and episode state.
pub struct LanderEnv {
    world: World,
    bodies: LanderBodies,
    rng: SplitMix64,
    prev_shaping: f64,
    steps: u32,
    needs_reset: bool,
    portal_crossings: u32,
    last: LanderOutcome,
    /// The wind's and the turbulence's step counts (with `enable_wind`).
    wind_idx: i64,
    torque_idx: i64,
}

impl std::fmt::Debug for LanderEnv {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LanderEnv")
            .field("bodies", &self.bodies)
            .field("steps", &self.steps)
            .field("last", &self.last)
            .finish()
    }
}

/// Gymnasium's wind function of a step count, between −1 and 1:
/// `tanh(sin(2 k t) + sin(π k t))`, `k = 0.01` (never periodic).
fn gust(t: i64) -> f64 {
    let t = t as f64;
    ((0.02 * t).sin() + (std::f64::consts::PI * 0.01 * t).sin()).tanh()
}

/// Gymnasium's potential: distance to the pad, speed and tilt cost, 10
/// points a leg on the ground.
fn shaping(obs: &[f32; OBS_WIDTH]) -> f64 {
    let o = obs.map(f64::from);
    -100.0 * o[0].hypot(o[1]) - 100.0 * o[2].hypot(o[3]) - 100.0 * o[4].abs()
        + 10.0 * o[6]
        + 10.0 * o[7]
}

impl LanderEnv {
    /// A lander on the terrain drawn from `seed`, reset (its first
    /// observation in [`last`](Self::last)).
    pub fn new(config: &LanderConfig, seed: u64) -> Result<LanderEnv, WorldError> {
        let mut rng = SplitMix64(seed);
        let draws = Self::draw_terrain(&mut rng);
        let push = Self::draw_push(&mut rng);
        let (world, bodies) = build_lander_world(&draws, config.gravity, config.portal)?;
        let mut env = LanderEnv {
            world,
            bodies,
            rng,
            prev_shaping: 0.0,
            steps: 0,
            needs_reset: false,
            portal_crossings: 0,
            last: LanderOutcome::default(),
            wind_idx: 0,
            torque_idx: 0,
        };
        env.start(config, push)?;
        Ok(env)
    }

    fn draw_terrain(rng: &mut SplitMix64) -> [f64; TERRAIN_DRAWS] {
        let mut d = [0.0; TERRAIN_DRAWS];
        for v in &mut d {
            *v = rng.uniform(0.0, VIEW_H / 2.0);
        }
        d
    }

    fn draw_push(rng: &mut SplitMix64) -> [f64; 2] {
        [
            rng.uniform(-START_PUSH, START_PUSH),
            rng.uniform(-START_PUSH, START_PUSH),
        ]
    }

    /// Reseeds the lander's generator with `seed` and starts a new
    /// episode on new terrain.
    pub fn reseed(&mut self, config: &LanderConfig, seed: u64) -> Result<(), WorldError> {
        self.rng = SplitMix64(seed);
        self.reset(config)
    }

    /// A new episode: new terrain, a random push, one step with the
    /// engines off (its observation is the first, reward 0).
    pub fn reset(&mut self, config: &LanderConfig) -> Result<(), WorldError> {
        let draws = Self::draw_terrain(&mut self.rng);
        let push = Self::draw_push(&mut self.rng);
        self.reset_with(config, &draws, push)
    }

    /// A new episode on the terrain of `draws` (random heights, as
    /// [`terrain`] takes them) with the initial push `push` (N, applied
    /// for the first step).
    pub fn reset_with(
        &mut self,
        config: &LanderConfig,
        draws: &[f64; TERRAIN_DRAWS],
        push: [f64; 2],
    ) -> Result<(), WorldError> {
        let (world, bodies) = build_lander_world(draws, config.gravity, config.portal)?;
        self.world = world;
        self.bodies = bodies;
        self.start(config, push)
    }

    fn start(&mut self, config: &LanderConfig, push: [f64; 2]) -> Result<(), WorldError> {
        if config.enable_wind {
            // Gymnasium draws the counts after the push, with the reset.
            self.wind_idx = self.rng.uniform(-9999.0, 9999.0).floor() as i64;
            self.torque_idx = self.rng.uniform(-9999.0, 9999.0).floor() as i64;
        }
        // No leg is down before the first step (the wind blows in it).
        self.last = LanderOutcome::default();
        let f = v2(push[0], push[1]);
        if f != Vec2::ZERO {
            self.world.apply_force_to_center(self.bodies.hull, f)?;
        }
        self.steps = 0;
        self.needs_reset = false;
        self.portal_crossings = 0;
        self.advance(config, Action::noop(config.continuous), true)
    }

    /// The lander's world.
    #[must_use]
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The bodies of the lander's world.
    #[must_use]
    pub fn bodies(&self) -> LanderBodies {
        self.bodies
    }

    /// What the last step (or reset) returned.
    #[must_use]
    pub fn last(&self) -> LanderOutcome {
        self.last
    }

    /// Steps taken in this episode (the reset's step not counted).
    #[must_use]
    pub fn episode_steps(&self) -> u32 {
        self.steps
    }

    /// Portal crossings the hull completed in this episode (portal
    /// variant).
    #[must_use]
    pub fn portal_crossings(&self) -> u32 {
        self.portal_crossings
    }

    /// One environment step: a reset instead when the last episode ended
    /// and the configuration autoresets.
    fn act(&mut self, config: &LanderConfig, action: Action) -> Result<(), WorldError> {
        if self.needs_reset && config.autoreset {
            return self.reset(config);
        }
        self.advance(config, action, false)
    }

    fn advance(
        &mut self,
        config: &LanderConfig,
        action: Action,
        fresh: bool,
    ) -> Result<(), WorldError> {
        let hull = self.bodies.hull;
        let legs_down = self.last.observation[6] > 0.0 || self.last.observation[7] > 0.0;
        if config.enable_wind && !legs_down {
            let wind = gust(self.wind_idx) * config.wind_power;
            self.wind_idx += 1;
            self.world.apply_force_to_center(hull, v2(wind, 0.0))?;
            let torque = gust(self.torque_idx) * config.turbulence_power;
            self.torque_idx += 1;
            self.world.apply_torque(hull, torque as Real)?;
        }
        let (m_power, side_dir, s_power) = action.throttles();
        let (j0, j1) = {
            let a = self.rng.uniform(-1.0, 1.0) / PX;
            let b = self.rng.uniform(-1.0, 1.0) / PX;
            if config.dispersion {
                (a, b)
            } else {
                (0.0, 0.0)
            }
        };
        if m_power > 0.0 || s_power > 0.0 {
            let angle = to_f64(self.world.angle(hull)?);
            let p = self.world.position(hull)?;
            let (cx, cy) = (to_f64(p.x), to_f64(p.y));
            let (s, c) = angle.sin_cos();
            let up = (-s, c);
            let right = (c, s);
            // Main engine: thrust along the hull's up axis, a little off
            // its line (the dispersion), from a point below the centre.
            let k = MAIN_DOWN / PX + 2.0 * j0;
            let lever = (k * up.0 + j1 * right.0, k * up.1 + j1 * right.1);
            let gain = MAIN_POWER * m_power;
            let imp = v2(lever.0 * gain, lever.1 * gain);
            if imp != Vec2::ZERO {
                let at = v2(cx - lever.0, cy - lever.1);
                self.world.apply_linear_impulse(hull, imp, at)?;
            }
            // Side engine: a sideways push high on the hull, so it also
            // turns it. As in Gymnasium, action 1 (the left engine) pushes
            // left from right of the centre: the lander turns
            // counterclockwise; action 3 is the mirror image.
            let offset = -side_dir * (SIDE_OUT / PX) + 3.0 * j1;
            let gain = -SIDE_POWER * s_power;
            let imp = v2(
                (right.0 * offset + j0 * up.0) * gain,
                (right.1 * offset + j0 * up.1) * gain,
            );
            if imp != Vec2::ZERO {
                let at = v2(
                    cx + right.0 * offset + up.0 * (SIDE_UP / PX),
                    cy + right.1 * offset + up.1 * (SIDE_UP / PX),
                );
                self.world.apply_linear_impulse(hull, imp, at)?;
            }
        }
        self.world.step_serial((1.0 / FPS) as Real)?;
        #[cfg(feature = "portals")]
        if config.portal {
            for e in &self.world.events().portals {
                if let janus2d::PortalEvent::CrossingCompleted { body, .. } = e
                    && *body == hull
                {
                    self.portal_crossings += 1;
                }
            }
        }

        let obs = self.observe()?;
        let shaping = shaping(&obs);
        let mut reward = shaping - self.prev_shaping;
        self.prev_shaping = shaping;
        reward -= 0.30 * m_power;
        reward -= 0.03 * s_power;
        let crashed = self.world.body_contacts(hull)?.next().is_some();
        let out = crashed || f64::from(obs[0]).abs() >= 1.0;
        let rest = !self.world.is_awake(hull)? && !out;
        if out {
            reward = -100.0;
        } else if rest {
            reward = 100.0;
        }
        let mut terminated = out || rest;
        let mut truncated = false;
        if fresh {
            reward = 0.0;
            terminated = false;
        } else {
            self.steps += 1;
            truncated = config.max_episode_steps > 0
                && self.steps >= config.max_episode_steps
                && !terminated;
        }
        self.needs_reset = terminated || truncated;
        self.last = LanderOutcome {
            observation: obs,
            reward,
            terminated,
            truncated,
        };
        Ok(())
    }

    fn observe(&self) -> Result<[f32; OBS_WIDTH], WorldError> {
        let w = &self.world;
        let hull = self.bodies.hull;
        let p = w.position(hull)?;
        let v = w.linear_velocity(hull)?;
        let (x, y) = (to_f64(p.x), to_f64(p.y));
        let (vx, vy) = (to_f64(v.x), to_f64(v.y));
        let leg = |k: usize| -> Result<f32, WorldError> {
            let touching = w.body_contacts(self.bodies.legs[k])?.next().is_some();
            Ok(if touching { 1.0 } else { 0.0 })
        };
        Ok([
            ((x - VIEW_W / 2.0) / (VIEW_W / 2.0)) as f32,
            ((y - (PAD_Y + LEG_DROP / PX)) / (VIEW_H / 2.0)) as f32,
            (vx * (VIEW_W / 2.0) / FPS) as f32,
            (vy * (VIEW_H / 2.0) / FPS) as f32,
            to_f64(w.angle(hull)?) as f32,
            (20.0 * to_f64(w.angular_velocity(hull)?) / FPS) as f32,
            leg(0)?,
            leg(1)?,
        ])
    }
}

/// N landers stepped together: one call steps every lander (its action,
/// the world's step, its observation and reward). On one thread the
/// landers step on the calling thread; on `t` threads they are cut into
/// `t` contiguous runs, the caller steps the first and `t − 1` helper
/// threads of the batch's own crew the others (see the `crew` module:
/// a few microseconds of hand-off per call, where a rayon pool's was some
/// 50 µs on the 2-core machine here).
pub struct LanderBatch {
    config: LanderConfig,
    /// The landers in runs, one per thread, in order.
    runs: Vec<Vec<LanderEnv>>,
    /// Landers per run (the last may hold fewer).
    run_len: usize,
    count: usize,
    crew: Option<Crew<LanderEnv>>,
    threads: usize,
}

impl std::fmt::Debug for LanderBatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LanderBatch")
            .field("config", &self.config)
            .field("landers", &self.count)
            .field("threads", &self.threads)
            .finish()
    }
}

/// The operation of one call, for every lander of a run.
#[derive(Clone)]
enum Op {
    Step(OwnedActions),
    Reseed(u64),
}

#[derive(Clone)]
enum OwnedActions {
    Discrete(Vec<i64>),
    Continuous(Vec<f64>),
}

impl Op {
    /// The part of the operation for landers `from..to`.
    fn part(&self, from: usize, to: usize) -> Op {
        match self {
            Op::Step(OwnedActions::Discrete(a)) => {
                Op::Step(OwnedActions::Discrete(a[from..to].to_vec()))
            }
            Op::Step(OwnedActions::Continuous(a)) => {
                Op::Step(OwnedActions::Continuous(a[2 * from..2 * to].to_vec()))
            }
            Op::Reseed(seed) => Op::Reseed(*seed),
        }
    }

    /// Applies the operation to a run whose first lander is lander
    /// `offset` of the batch (its part of the actions starts at 0).
    fn apply(
        &self,
        config: &LanderConfig,
        offset: usize,
        run: &mut [LanderEnv],
    ) -> Option<(usize, WorldError)> {
        for (k, env) in run.iter_mut().enumerate() {
            let result = match self {
                Op::Step(OwnedActions::Discrete(a)) => env.act(config, Action::Discrete(a[k])),
                Op::Step(OwnedActions::Continuous(a)) => {
                    env.act(config, Action::Continuous(a[2 * k], a[2 * k + 1]))
                }
                Op::Reseed(seed) => env.reseed(config, lander_seed(*seed, offset + k)),
            };
            if let Err(e) = result {
                return Some((offset + k, e));
            }
        }
        None
    }
}

impl LanderBatch {
    /// `count` landers seeded from `seed` (reset: their first
    /// observations are in [`outcome`](Self::outcome)), stepped on
    /// `threads` threads.
    pub fn new(
        count: usize,
        config: LanderConfig,
        seed: u64,
        threads: usize,
    ) -> Result<LanderBatch, BatchError> {
        if count == 0 {
            return Err(BatchError::Empty);
        }
        config.validate()?;
        let mut envs = Vec::with_capacity(count);
        for i in 0..count {
            let env = LanderEnv::new(&config, lander_seed(seed, i))
                .map_err(|error| BatchError::World { index: i, error })?;
            envs.push(env);
        }
        let mut batch = LanderBatch {
            config,
            runs: vec![envs],
            run_len: count,
            count,
            crew: None,
            threads: 1,
        };
        batch.set_threads(threads)?;
        Ok(batch)
    }

    /// Landers in the batch.
    #[must_use]
    pub fn len(&self) -> usize {
        self.count
    }

    /// Always false: a batch holds at least one lander.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The configuration.
    #[must_use]
    pub fn config(&self) -> &LanderConfig {
        &self.config
    }

    /// Threads the batch steps on.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Steps on `threads` threads from now on (one: on the calling
    /// thread alone). The landers' trajectories do not depend on it.
    pub fn set_threads(&mut self, threads: usize) -> Result<(), BatchError> {
        if threads == 0 {
            return Err(BatchError::Threads(
                "the thread count must be at least 1".into(),
            ));
        }
        self.check_whole()?;
        let crew = if threads > 1 {
            Some(Crew::new(threads - 1).map_err(|e| BatchError::Threads(e.to_string()))?)
        } else {
            None
        };
        let all: Vec<LanderEnv> = self.runs.drain(..).flatten().collect();
        self.run_len = self.count.div_ceil(threads);
        let mut rest = all.into_iter();
        self.runs = (0..threads)
            .map(|_| rest.by_ref().take(self.run_len).collect())
            .collect();
        self.crew = crew;
        self.threads = threads;
        Ok(())
    }

    /// A helper's panic loses its run of landers: refuse to go on.
    fn check_whole(&self) -> Result<(), BatchError> {
        let held: usize = self.runs.iter().map(Vec::len).sum();
        if held == self.count {
            Ok(())
        } else {
            Err(BatchError::Threads(
                "a helper thread panicked and its landers are lost".into(),
            ))
        }
    }

    /// Lander `index`.
    pub fn env(&self, index: usize) -> Result<&LanderEnv, BatchError> {
        let len = self.count;
        self.runs
            .get(index / self.run_len)
            .and_then(|run| run.get(index % self.run_len))
            .ok_or(BatchError::WorldIndex { index, len })
    }

    /// What lander `index`'s last step (or reset) returned.
    pub fn outcome(&self, index: usize) -> Result<LanderOutcome, BatchError> {
        self.env(index).map(LanderEnv::last)
    }

    /// Every lander's last outcome, in order.
    pub fn outcomes(&self) -> impl Iterator<Item = LanderOutcome> + '_ {
        self.runs.iter().flatten().map(LanderEnv::last)
    }

    /// Reseeds every lander from `seed` (lander `i` gets its own stream)
    /// and starts new episodes.
    pub fn reset_all(&mut self, seed: u64) -> Result<(), BatchError> {
        self.run(Op::Reseed(seed))
    }

    /// Starts a new episode of lander `index` on the terrain of `draws`
    /// with the initial push `push` (for comparisons with another
    /// implementation of the same rules).
    pub fn reset_with(
        &mut self,
        index: usize,
        draws: &[f64; TERRAIN_DRAWS],
        push: [f64; 2],
    ) -> Result<(), BatchError> {
        let len = self.count;
        let run_len = self.run_len;
        let env = self
            .runs
            .get_mut(index / run_len)
            .and_then(|run| run.get_mut(index % run_len))
            .ok_or(BatchError::WorldIndex { index, len })?;
        env.reset_with(&self.config, draws, push)
            .map_err(|error| BatchError::World { index, error })
    }

    /// Steps every lander with its action (autoresetting those whose
    /// episode ended when the configuration says so). Actions are checked
    /// first: a bad one changes nothing.
    pub fn step(&mut self, actions: LanderActions<'_>) -> Result<(), BatchError> {
        let n = self.count;
        let owned = match actions {
            LanderActions::Discrete(a) => {
                if self.config.continuous {
                    return Err(BatchError::Action {
                        index: 0,
                        why: "continuous landers take two floats per lander".into(),
                    });
                }
                check_len("actions", a.len(), n)?;
                if let Some(i) = a.iter().position(|&v| !(0..4).contains(&v)) {
                    return Err(BatchError::Action {
                        index: i,
                        why: format!("action {} is not in Discrete(4)", a[i]),
                    });
                }
                OwnedActions::Discrete(a.to_vec())
            }
            LanderActions::Continuous(a) => {
                if !self.config.continuous {
                    return Err(BatchError::Action {
                        index: 0,
                        why: "discrete landers take one integer per lander".into(),
                    });
                }
                check_len("actions", a.len(), 2 * n)?;
                if let Some(i) = a
                    .iter()
                    .position(|v| !(v.is_finite() && (-1.0..=1.0).contains(v)))
                {
                    return Err(BatchError::Action {
                        index: i / 2,
                        why: format!("action value {} is not in [-1, 1]", a[i]),
                    });
                }
                OwnedActions::Continuous(a.to_vec())
            }
        };
        self.run(Op::Step(owned))
    }

    /// Runs `op` on every lander: the helpers take runs 1.., the caller
    /// run 0; the error is the lowest-index lander's.
    fn run(&mut self, op: Op) -> Result<(), BatchError> {
        self.check_whole()?;
        let mut first: Option<(usize, WorldError)> = None;
        let mut keep = |e: Option<(usize, WorldError)>| {
            if let Some((i, error)) = e
                && first.as_ref().is_none_or(|(j, _)| i < *j)
            {
                first = Some((i, error));
            }
        };
        match &self.crew {
            None => {
                for (r, run) in self.runs.iter_mut().enumerate() {
                    keep(op.apply(&self.config, r * self.run_len, run));
                }
            }
            Some(crew) => {
                let mut posted = Vec::with_capacity(crew.len());
                for k in 0..crew.len() {
                    let run = std::mem::take(&mut self.runs[k + 1]);
                    if run.is_empty() {
                        continue;
                    }
                    let offset = (k + 1) * self.run_len;
                    let part = op.part(offset, offset + run.len());
                    let config = self.config.clone();
                    let task: Task<LanderEnv> =
                        Box::new(move |run: &mut [LanderEnv]| part.apply(&config, offset, run));
                    crew.post(k, run, task);
                    posted.push(k);
                }
                let own = self.runs[0].len();
                keep(op.part(0, own).apply(&self.config, 0, &mut self.runs[0]));
                let mut panic = None;
                for k in posted {
                    match crew.collect(k) {
                        Ok((run, e)) => {
                            self.runs[k + 1] = run;
                            keep(e);
                        }
                        Err(payload) => panic = panic.or(Some(payload)),
                    }
                }
                if let Some(payload) = panic {
                    std::panic::resume_unwind(payload);
                }
            }
        }
        match first {
            Some((index, error)) => Err(BatchError::World { index, error }),
            None => Ok(()),
        }
    }
}

fn check_len(what: &'static str, found: usize, expected: usize) -> Result<(), BatchError> {
    if found == expected {
        Ok(())
    } else {
        Err(BatchError::Length {
            what,
            expected,
            found,
        })
    }
}

#[cfg(test)]
#[path = "lander_tests.rs"]
mod tests;
