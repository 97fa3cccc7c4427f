//! The world: the public API, split by topic, over the stages of the
//! step.
//!
//! | file            | what                                                        |
//! |-----------------|-------------------------------------------------------------|
//! | `world/mod.rs`  | [`World`], [`WorldDef`], [`StepEvents`]; settings, sleep, continuous switch |
//! | `bodies.rs`     | bodies: create, destroy, read, set, forces, kinematic targets |
//! | `shapes.rs`     | shapes and their materials, contacts as read after the step  |
//! | `joints.rs`     | joints of every kind: create, destroy, typed reads, setters   |
//! | `queries.rs`    | scene queries (the logic is `crate::query`'s)               |
//! | `mover.rs`      | the character mover: cast and collide a capsule (the plane logic is `crate::mover`'s) |
//! | `events.rs`     | events and hooks: the pre-solve hook, user data              |
//! | `step.rs`       | [`World::step`]: the pipeline that calls the stages in order |
//! | `portals.rs`    | portal pairs: create, destroy, read (the logic is the portal stage's; with the `portals` feature) |
//! | `internal.rs`   | store-level operations over the borrowed stores, and where the portal stage's commands are applied |
//!
//!
//! ```text
//! World::step(dt)
//!   ├─ validate dt; bodies created asleep go to sleep (islands)
//!   ├─ portal clipping (portal stage; a no-op without portal pairs)
//!   ├─ broadphase: new pairs ─ narrowphase ─ wake touched islands ─ contact constraints
//!   ├─ solve_step (janus2d-core): prepare ─ substeps ─ restitution ─ store ─ finalize
//!   ├─ store impulses  ∥  continuous (fast bodies swept, moved back to
//!   │                     their time of impact) ─ move proxies
//!   ├─ portal crossings (the stage over the stores; its commands applied by `internal.rs`)
//!   ├─ islands: sleep timers, resting islands sleep
//!   └─ counters, events (non-finite bodies, contacts, sensors)
//! ```
//!
//! The stage table with each stage's data is in `docs/architecture.md`.
//!
//! Everything is created from definition structs with defaults and returns
//! a generational handle; every call that rejects its input leaves the world
//! unchanged.

use janus2d_constraints::{
    ContactSolver, Joint, JointDef, ObjectMass, RevoluteJoint, RevoluteJointDef, WeldJoint,
    WeldJointDef,
};
use janus2d_core::BodyMass;
use janus2d_core::body::{BodyDef, BodyHandle, BodySet, BodyType, validate_mass};
use janus2d_core::constraint::{ConstraintBatch, StepContext};
use janus2d_core::geometry::Shape;
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, vec_is_finite};
use janus2d_core::solver::{SolverProfile, SolverSettings, solve_step_on};
use janus2d_core::team_choice::TeamChoice;

use crate::collision::{Collision, CollisionCounters, CollisionEvents};
use crate::contacts::Contact;
use crate::error::WorldError;
use crate::islands::{Islands, SleepInput, SleepSettings};
use crate::joints::{JointHandle, JointSet};
use crate::portal::PortalStage;
use crate::shapes::{ShapeData, ShapeDef, ShapeHandle};
pub use events::BodyMoveEvent;

/// Default gravity, m/s² (usual (0, −10)).
pub const DEFAULT_GRAVITY: Vec2 = Vec2::new(0.0, -10.0);

/// Everything needed to create a world.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldDef {
    /// Gravity, m/s² (usual (0, −10)).
    pub gravity: Vec2,
    /// Solver accuracy and softness settings.
    pub solver: SolverSettings,
    /// When bodies fall asleep (on by default, as in Box2D and Rapier).
    pub sleep: SleepSettings,
    /// Continuous collision of fast bodies against static shapes, and of
    /// bullets against moving ones (on by default, as in Box2D; see
    /// the continuous stage).
    pub enable_continuous: bool,
    /// Approach speed above which a contact of a shape with hit events on
    /// reports a [`HitEvent`](crate::HitEvent), m/s (usual 1, as
    /// Box2D's `hitEventThreshold`).
    pub hit_event_threshold: Real,
    /// Gather body move events after each step (usual false): every body
    /// that moved and has `BodyDef::enable_move_events` gets a
    /// [`BodyMoveEvent`] in [`StepEvents::moves`]. Off by default, unlike
    /// Box2D's: a world that reads no move events pays nothing for them.
    pub enable_move_events: bool,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: DEFAULT_GRAVITY,
            solver: SolverSettings::default(),
            sleep: SleepSettings::default(),
            enable_continuous: true,
            hit_event_threshold: 1.0,
            enable_move_events: false,
        }
    }
}

impl WorldDef {
    /// Sets the gravity, m/s² (builder style).
    ///
    /// ```
    /// use janus2d_world::WorldDef;
    /// use janus2d_core::Vec2;
    /// let def = WorldDef::default()
    ///     .with_gravity(Vec2::new(0.0, -9.81))
    ///     .with_continuous(false)
    ///     .with_hit_event_threshold(2.0);
    /// assert_eq!(def.gravity.y, -9.81);
    /// assert!(!def.enable_continuous);
    /// assert_eq!(def.hit_event_threshold, 2.0);
    /// ```
    #[must_use]
    pub fn with_gravity(mut self, gravity: Vec2) -> Self {
        self.gravity = gravity;
        self
    }

    /// Sets the solver settings (builder style).
    ///
    /// ```
    /// use janus2d_world::WorldDef;
    /// use janus2d_core::SolverSettings;
    /// let def = WorldDef::default().with_solver(SolverSettings { substeps: 8, ..SolverSettings::default() });
    /// assert_eq!(def.solver.substeps, 8);
    /// ```
    #[must_use]
    pub fn with_solver(mut self, solver: SolverSettings) -> Self {
        self.solver = solver;
        self
    }

    /// Sets the sleep settings (builder style).
    ///
    /// ```
    /// use janus2d_world::{SleepSettings, WorldDef};
    /// let def = WorldDef::default().with_sleep(SleepSettings { enabled: false, ..SleepSettings::default() });
    /// assert!(!def.sleep.enabled);
    /// ```
    #[must_use]
    pub fn with_sleep(mut self, sleep: SleepSettings) -> Self {
        self.sleep = sleep;
        self
    }

    /// Turns continuous collision on or off (builder style).
    ///
    /// ```
    /// use janus2d_world::WorldDef;
    /// assert!(!WorldDef::default().with_continuous(false).enable_continuous);
    /// ```
    #[must_use]
    pub fn with_continuous(mut self, on: bool) -> Self {
        self.enable_continuous = on;
        self
    }

    /// Sets the hit event approach speed threshold, m/s (builder style).
    ///
    /// ```
    /// use janus2d_world::WorldDef;
    /// assert_eq!(WorldDef::default().with_hit_event_threshold(0.5).hit_event_threshold, 0.5);
    /// ```
    #[must_use]
    pub fn with_hit_event_threshold(mut self, speed: Real) -> Self {
        self.hit_event_threshold = speed;
        self
    }

    /// Turns the gathering of body move events on or off (builder style;
    /// see [`WorldDef::enable_move_events`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default().with_move_events(true)).unwrap();
    /// let body = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0))).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// let moves = &world.events().moves;
    /// assert_eq!(moves.len(), 1);
    /// assert_eq!(moves[0].body, body);
    /// assert!(moves[0].transform.p.y < 4.0 && !moves[0].fell_asleep);
    /// ```
    #[must_use]
    pub fn with_move_events(mut self, on: bool) -> Self {
        self.enable_move_events = on;
        self
    }
}

/// Every event of the last step, in one place, read after `step`
/// ([`World::events`]).
///
/// | field | what | switch |
/// |---|---|---|
/// | `collision.contact_begin` | solid contacts that began touching, with their manifold | `ShapeDef::enable_contact_events` (both shapes, usual on) |
/// | `collision.contact_end` | solid contacts that stopped touching | same |
/// | `collision.sensor_begin`, `sensor_end` | sensor overlaps, sensor and visitor shapes | `ShapeDef::enable_sensor_events` (both shapes, usual on) |
/// | `collision.hits` | contacts that hit faster than `WorldDef::hit_event_threshold` | `ShapeDef::enable_hit_events` (either shape, usual off) |
/// | `collision.forces` | contacts that pushed harder than a threshold | `ShapeDef::force_event_threshold` (usual ∞: off) |
/// | `moves` | bodies that moved, in body order | `WorldDef::enable_move_events` (usual off) and `BodyDef::enable_move_events` (usual on) |
/// | `portals` | portal crossings begun, completed, cancelled; joints disabled | always |
/// | `joints` | joints whose force or torque passed their thresholds | the joint's thresholds |
/// | `non_finite_bodies` | bodies reset from a non-finite state | always |
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.2))).unwrap();
/// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
/// let mut begins = 0;
/// for _ in 0..60 {
///     world.step(1.0 / 60.0).unwrap();
///     let events = world.events();
///     begins += events.collision.contact_begin.len();
///     assert!(events.moves.is_empty());
/// }
/// assert_eq!(begins, 1);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepEvents {
    /// Bodies whose state went non-finite during the step. Each was put back
    /// at its start-of-step pose, at rest, instead of spreading NaN.
    pub non_finite_bodies: Vec<BodyHandle>,
    /// Contact, sensor, hit and contact force events.
    pub collision: CollisionEvents,
    /// Joints whose force or torque passed their thresholds.
    pub joints: Vec<crate::joints::JointEvent>,
    /// Portal events: crossings begun, completed or cancelled, joints
    /// disabled. Events of calls between steps (`CrossingCancelled` and
    /// `JointDisabled` from `destroy_portal_pair` or from destroying a
    /// crossing's copy or a portal body) are reported with the next
    /// step's, first, as collision events are.
    #[cfg(feature = "portals")]
    pub portals: Vec<crate::PortalEvent>,
    /// Bodies that moved in the step (awake dynamic and kinematic bodies),
    /// in body (handle slot) order, when the world gathers them
    /// ([`WorldDef::enable_move_events`]) and the body reports them
    /// (`BodyDef::enable_move_events`).
    pub moves: Vec<BodyMoveEvent>,
}

/// The simulation world: it owns one value of each stage and calls them
/// in order, passing each what it reads.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct World {
    gravity: Vec2,
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_maps::SettingsDef"))]
    settings: SolverSettings,
    pub(crate) bodies: BodySet,
    pub(crate) joints: JointSet,
    pub(crate) collision: Collision,
    /// Contact constraint building: the persistent constraint graph (kept
    /// in snapshots) and the lanes' places.
    pub(crate) contact_builder: crate::contact_build::ContactBuilder,
    /// The step's contact constraints in their colours and lanes (the
    /// contact solve's own data; rebuilt at every step, so not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    contact_solver: ContactSolver,
    /// The contact-modification hook's data for this step (portal copies;
    /// rebuilt at every step, so not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    object_masses: Vec<ObjectMass>,
    pub(crate) portals: PortalStage,
    pub(crate) islands: Islands,
    continuous: crate::continuous::ContinuousStage,
    /// Approach speed above which hit events are reported, m/s.
    hit_event_threshold: Real,
    /// Body move events are gathered ([`WorldDef::enable_move_events`]).
    move_events: bool,
    /// The user's callbacks: pre-solve hook, pair filter, material mixing
    /// (not state: neither serialized nor copied into snapshots).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) hooks: crate::hooks::Hooks,
    pub(crate) sleep_settings: SleepSettings,
    /// Joints switched off because a body they hold was disabled, with
    /// the disabled body (switched back on when it is enabled and the
    /// joint's other body is enabled).
    pub(crate) disabled_joints: Vec<(BodyHandle, JointHandle)>,
    wake_list: Vec<BodyHandle>,
    events: StepEvents,
    /// Timings of the last step (not state: not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    step_profile: crate::profile::StepProfile,
    counters: crate::profile::StepCounters,
    /// What the event gathering read in the last step (a diagnostic, not
    /// state: not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    event_work: crate::profile::EventWork,
    /// The stage timers are off ([`World::set_profiling`]; not state: not
    /// serialized, so a restored world times its steps).
    #[cfg_attr(feature = "serde", serde(skip))]
    profiling_off: bool,
    /// The work below which a step runs on the calling thread alone
    /// ([`World::set_team_min_work`]; not state: not serialized, so a
    /// restored world has the default).
    #[cfg_attr(
        feature = "serde",
        serde(skip, default = "crate::world::step::default_team_min_work")
    )]
    team_min_work: usize,
    /// Whether the solve runs on the step's team or on the leader alone,
    /// chosen by timing both now and then ([`TeamChoice`]; not state: the
    /// result is the same either way, so not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    solve_team: TeamChoice,
    step_count: u64,
}

impl World {
    /// A new empty world. Rejects non-finite gravity.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let world = World::new(WorldDef::default()).unwrap();
    /// assert_eq!(world.body_count(), 0);
    /// ```
    pub fn new(def: WorldDef) -> Result<World, WorldError> {
        check_gravity(def.gravity)?;
        check_settings(&def.solver)?;
        def.sleep.validate()?;
        if def.hit_event_threshold.is_nan() {
            return Err(WorldError::NonFinite("hit_event_threshold"));
        }
        if def.hit_event_threshold < 0.0 {
            return Err(WorldError::OutOfRange("hit_event_threshold"));
        }
        let bodies = BodySet::new();
        Ok(World {
            gravity: def.gravity,
            settings: def.solver,
            collision: Collision::new(bodies.owner()),
            contact_builder: Default::default(),
            contact_solver: ContactSolver::new(),
            object_masses: Vec::new(),
            portals: PortalStage::default(),
            islands: Islands::default(),
            continuous: crate::continuous::ContinuousStage::new(def.enable_continuous),
            hit_event_threshold: def.hit_event_threshold,
            move_events: def.enable_move_events,
            hooks: crate::hooks::Hooks::default(),
            sleep_settings: def.sleep,
            disabled_joints: Vec::new(),
            wake_list: Vec::new(),
            joints: JointSet::new(bodies.owner()),
            bodies,
            events: StepEvents::default(),
            step_profile: crate::profile::StepProfile::default(),
            counters: crate::profile::StepCounters::default(),
            event_work: crate::profile::EventWork::default(),
            profiling_off: false,
            team_min_work: TEAM_MIN_WORK,
            solve_team: TeamChoice::default(),
            step_count: 0,
        })
    }

    /// Gravity, m/s².
    pub fn gravity(&self) -> Vec2 {
        self.gravity
    }

    /// Sets gravity (rejects non-finite values and a length above
    /// [`MAX_GRAVITY`](janus2d_core::limits::MAX_GRAVITY)).
    pub fn set_gravity(&mut self, gravity: Vec2) -> Result<(), WorldError> {
        check_gravity(gravity)?;
        self.gravity = gravity;
        Ok(())
    }

    /// The solver settings.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Replaces the solver settings (validated: every real finite and not
    /// negative, damping ratios at most
    /// [`MAX_DAMPING_RATIO`](janus2d_core::limits::MAX_DAMPING_RATIO); the
    /// contact and iterative joint stiffness are capped at a quarter of
    /// the substep rate at each step, see [`World::step_context`]).
    pub fn set_settings(&mut self, settings: SolverSettings) -> Result<(), WorldError> {
        check_settings(&settings)?;
        self.settings = settings;
        Ok(())
    }

    /// The body storage (the solver's arrays; internal to the engine).
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn bodies(&self) -> &BodySet {
        &self.bodies
    }

    /// Every live body's handle, in slot order.
    pub fn body_handles(&self) -> impl Iterator<Item = BodyHandle> + '_ {
        self.bodies.handles()
    }

    /// The body's gravity scale (dimensionless).
    pub fn gravity_scale(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.gravity_scale)
            .ok_or_else(|| self.body_error(body))
    }

    /// Number of live bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Number of live joints.
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// Steps taken so far.
    pub fn step_count(&self) -> u64 {
        self.step_count
    }

    // ----- sleep --------------------------------------------------------------

    /// Wakes the island of `body` (no effect on awake or static bodies).
    /// Errors: a stale or foreign handle (the world unchanged).
    pub fn wake_body(&mut self, body: BodyHandle) -> Result<(), WorldError> {
        self.check_body(body)?;
        self.wake_island(body);
        Ok(())
    }

    /// Wakes the island of `body`, a handle known to be live (or
    /// harmlessly stale: nothing happens).
    pub(crate) fn wake_island(&mut self, body: BodyHandle) {
        self.stores().wake_body(body);
    }

    /// Wakes every island in the list.
    pub(super) fn wake_all(&mut self, bodies: &[BodyHandle]) {
        for b in bodies {
            self.wake_island(*b);
        }
    }

    /// True when the body sleeps. Errors: a stale or foreign handle.
    pub fn is_sleeping(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.check_body(body)?;
        Ok(self.bodies.is_sleeping(body))
    }

    /// Number of sleeping bodies.
    pub fn sleeping_body_count(&self) -> usize {
        self.bodies.sleeping_count()
    }

    /// Number of awake dynamic and kinematic bodies.
    pub fn awake_body_count(&self) -> usize {
        self.bodies.moving_count()
    }

    /// The sleep settings.
    pub fn sleep_settings(&self) -> SleepSettings {
        self.sleep_settings
    }

    /// Changes the sleep settings (validated); turning sleep off wakes
    /// every body.
    pub fn set_sleep_settings(&mut self, settings: SleepSettings) -> Result<(), WorldError> {
        settings.validate()?;
        if !settings.enabled {
            let sleeping: Vec<BodyHandle> =
                self.bodies.sleeping_sims.iter().map(|s| s.handle).collect();
            self.wake_all(&sleeping);
        }
        self.sleep_settings = settings;
        Ok(())
    }

    // ----- continuous collision ---------------------------------------------

    /// True when continuous collision is on ([`WorldDef::enable_continuous`]).
    pub fn continuous_enabled(&self) -> bool {
        self.continuous.enabled
    }

    /// Turns continuous collision on or off from the next step.
    pub fn set_continuous_enabled(&mut self, on: bool) {
        self.continuous.enabled = on;
    }

    /// Every field copied but the callbacks (a snapshot's world).
    pub(crate) fn copy_state(&self) -> World {
        World {
            gravity: self.gravity,
            settings: self.settings.clone(),
            bodies: self.bodies.clone(),
            joints: self.joints.clone(),
            collision: self.collision.clone(),
            contact_builder: self.contact_builder.clone(),
            contact_solver: self.contact_solver.clone(),
            object_masses: self.object_masses.clone(),
            portals: self.portals.clone(),
            islands: self.islands.clone(),
            continuous: self.continuous.clone(),
            hit_event_threshold: self.hit_event_threshold,
            move_events: self.move_events,
            hooks: crate::hooks::Hooks::default(),
            sleep_settings: self.sleep_settings,
            disabled_joints: self.disabled_joints.clone(),
            wake_list: self.wake_list.clone(),
            events: self.events.clone(),
            step_profile: self.step_profile.clone(),
            counters: self.counters,
            event_work: self.event_work,
            profiling_off: self.profiling_off,
            team_min_work: self.team_min_work,
            solve_team: self.solve_team.clone(),
            step_count: self.step_count,
        }
    }
}

mod bodies;
mod body_state;
mod chains;
pub use bodies::ExplosionDef;
mod events;
mod internal;
mod joints;
mod mover;
#[cfg(feature = "portals")]
mod portals;
mod queries;
mod shape_edit;
mod shapes;
mod step;
pub use step::TEAM_MIN_WORK;
/// Gravity: finite, its length at most
/// [`MAX_GRAVITY`](janus2d_core::limits::MAX_GRAVITY).
pub(super) fn check_gravity(gravity: Vec2) -> Result<(), WorldError> {
    if !vec_is_finite(gravity) {
        return Err(WorldError::NonFinite("gravity"));
    }
    let max = janus2d_core::limits::MAX_GRAVITY;
    if gravity.x.abs() > max || gravity.y.abs() > max || gravity.length() > max {
        return Err(WorldError::OutOfBounds {
            field: "gravity",
            min: 0.0,
            max,
        });
    }
    Ok(())
}

/// Solver settings: every real finite (`inf` Hz or an infinite damping
/// ratio give NaN softness), the damping ratios at most
/// [`MAX_DAMPING_RATIO`](janus2d_core::limits::MAX_DAMPING_RATIO)
/// (`OutOfBounds`), then [`SolverSettings::validate`]'s stated ranges.
pub(crate) fn check_settings(s: &SolverSettings) -> Result<(), WorldError> {
    let reals = [
        (s.baumgarte, "baumgarte"),
        (s.contact_hertz, "contact_hertz"),
        (s.contact_damping_ratio, "contact_damping_ratio"),
        (s.contact_push_max_velocity, "contact_push_max_velocity"),
        (s.joint_hertz, "joint_hertz"),
        (s.joint_damping_ratio, "joint_damping_ratio"),
        (s.joint_max_correction_speed, "joint_max_correction_speed"),
        (s.restitution_threshold, "restitution_threshold"),
        (s.contact_mass_ratio_cap, "contact_mass_ratio_cap"),
        (s.joint_mass_ratio_cap, "joint_mass_ratio_cap"),
        (s.direct_joint_hertz, "direct_joint_hertz"),
        (
            s.direct_joint_max_correction_speed,
            "direct_joint_max_correction_speed",
        ),
    ];
    // (direct_free_tree_mass_ratio may be ∞: no free tree solved directly;
    // SolverSettings::validate rejects NaN.)
    for (v, name) in reals {
        if !v.is_finite() {
            return Err(WorldError::NonFinite(name));
        }
    }
    let max = janus2d_core::limits::MAX_DAMPING_RATIO;
    for (v, name) in [
        (s.contact_damping_ratio, "contact_damping_ratio"),
        (s.joint_damping_ratio, "joint_damping_ratio"),
    ] {
        if v > max {
            return Err(WorldError::OutOfBounds {
                field: name,
                min: 0.0,
                max,
            });
        }
    }
    // Then every stated range (NaN, negative, beyond its largest value).
    s.validate()?;
    Ok(())
}

/// The mass a shape adds at `density` must be at most the largest body
/// mass, [`MASS_RANGE`](janus2d_core::limits::MASS_RANGE)`.1` (a radius of
/// 1e6 m at a density of 1e38 overflows); the error names `density` and
/// the largest density this shape may have. Within the extent limit the
/// inertia is then finite (at most about 1e29 kg·m²).
pub(crate) fn check_shape_mass(geometry: &Shape, density: Real) -> Result<(), WorldError> {
    let area = geometry.area();
    if density <= 0.0 || area <= 0.0 {
        return Ok(());
    }
    let md = geometry.compute_mass(density);
    let (_, max_mass) = janus2d_core::limits::MASS_RANGE;
    if !(md.mass.is_finite() && md.mass <= max_mass && md.rotational_inertia.is_finite()) {
        return Err(WorldError::OutOfBounds {
            field: "density",
            min: 0.0,
            max: max_mass / area,
        });
    }
    Ok(())
}

/// A force or torque whose sum for the step would not be finite.
pub(super) fn accumulated(field: &'static str) -> WorldError {
    WorldError::OutOfBounds {
        field,
        min: -Real::MAX,
        max: Real::MAX,
    }
}

/// The velocity an impulse gives must stay within
/// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED) and
/// [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED); the
/// error names `impulse` and the speed limit.
pub(super) fn check_resulting_velocity(v: Vec2, w: Real) -> Result<(), WorldError> {
    let to_impulse = |e: janus2d_core::body::BodyError| match e {
        janus2d_core::body::BodyError::OutOfBounds { min, max, .. } => WorldError::OutOfBounds {
            field: "impulse",
            min,
            max,
        },
        _ => WorldError::NonFinite("impulse"),
    };
    janus2d_core::body::check_velocity(v, "impulse").map_err(to_impulse)?;
    janus2d_core::body::check_angular_velocity(w, "impulse").map_err(to_impulse)
}
