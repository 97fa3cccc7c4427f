//! Error metrics: one place that measures how far a simulation strays from
//! the truth, used by the tests and by the accuracy sweep
//! (`cargo bench --bench accuracy`, see `docs/accuracy.md`).
//!
//! A [`Tracker`] is created once the scene is built (it records the start:
//! the probe body's position and the total energy) and then fed the world
//! after every step; [`Tracker::metrics`] returns the figures so far.
//!
//! ```
//! use janus2d_testbed::metrics::{Tracker, TrackerConfig};
//! use janus2d_core::body::BodyDef;
//! use janus2d_core::math::Vec2;
//! use janus2d_world::{World, WorldDef};
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let ball = world
//!     .create_body(&BodyDef::dynamic(Vec2::new(0.0, 10.0)).with_mass(1.0, 0.1))
//!     .unwrap();
//! let mut tracker = Tracker::new(&world, TrackerConfig::probe(ball)).unwrap();
//! for _ in 0..60 {
//!     tracker.step(&mut world, 1.0 / 60.0).unwrap();
//! }
//! let m = tracker.metrics();
//! assert!(m.max_sink > 4.9 && m.max_sink < 5.1); // ½ g t² = 5 m
//! assert!(m.max_drift < 1e-6);
//! ```
//!
//! # The metrics
//!
//! "Probe" is the one body the tracker follows ([`TrackerConfig::probe`]),
//! usually the top box of a stack; "late" figures cover only the steps that
//! end after [`TrackerConfig::late_from`] (e.g. the last second of a run).
//! Every maximum is taken over the recorded steps, sampled after each step.
//!
//! | metric (CSV column)      | unit | definition |
//! |--------------------------|------|------------|
//! | `max_penetration`        | m    | largest [`World::max_penetration`]: the most negative separation of any touching contact point |
//! | `late_max_penetration`   | m    | the same, over the late steps only |
//! | `max_sink`               | m    | largest `y0 − y` of the probe's origin (how far it sank below its start; ≥ 0) |
//! | `final_sink`             | m    | `y0 − y` of the probe after the last step (signed) |
//! | `max_drift`              | m    | largest `|x − x0|` of the probe's origin (sideways drift) |
//! | `final_drift`            | m    | `x − x0` of the probe after the last step (signed) |
//! | `max_joint_gap`          | m    | largest [`World::max_joint_gap`]: distance between the two world anchors of any joint |
//! | `late_max_joint_gap`     | m    | the same, over the late steps only |
//! | `initial_energy`         | J    | total energy `E0` when the tracker was created |
//! | `final_energy`           | J    | total energy after the last step |
//! | `max_energy_gain`        | J    | largest `E − E0` (≥ 0): energy the solver created |
//! | `max_energy_loss`        | J    | largest `E0 − E` (≥ 0): energy the solver (or damping, friction, collisions) removed |
//! | `peak_kinetic_energy`    | J    | largest kinetic energy of all bodies together |
//! | `relative_energy_error`  | 1    | `max(gain, loss) / peak_kinetic_energy`: meaningful in passive scenes only (no damping, friction or inelastic contact) |
//! | `peak_speed`             | m/s  | largest linear speed of any dynamic body |
//! | `late_peak_speed`        | m/s  | the same, over the late steps only |
//! | `late_probe_speed`       | m/s  | largest linear speed of the probe over the late steps |
//! | `collapse_time`          | s    | time of the first step, after the grace time, that ends with the probe outside its collapse box (empty: it never left) |
//! | `non_finite_steps`       | 1    | steps that reported a non-finite body (a blow-up the world contained) |
//!
//! Total energy `E` sums over dynamic bodies `½ m |v|² + ½ I ω² − m s (g · c)`,
//! with mass `m`, inertia `I` about the centre of mass `c`, velocities `v`,
//! `ω`, gravity `g` and the body's gravity scale `s`: see [`kinetic_energy`]
//! and [`potential_energy`]. It is summed in `f64`. Semi-implicit Euler,
//! which the solver uses, loses `½ m |g|² h` joules per second of free fall
//! (`h` = substep length): a sliver of energy that is *not* a solver error,
//! and that [`free_fall_energy_loss`] predicts.
//!
//! # Extension point: more metrics
//!
//! A metric the core list lacks plugs in as an [`ExtraMetric`]: it is
//! sampled after every step and the tracker keeps its peak and last value,
//! which [`Metrics::columns`] appends to the fixed columns, so the sweep
//! writes it to its CSV without any change. The portal figures plug in this
//! way: [`PortalMapError`] (`portal_c`, m: the largest `|x₂ − T(x₁)|` of any
//! crossing) and [`PortalMomentumError`] (`portal_eta_momentum`, relative:
//! `|p − p₀| / |p₀|` of the η-scaled momentum a crossing conserves);
//! [`cases::Case::tracker`] adds both when the world has portals. A
//! metric every scene needs should instead become a field of [`Metrics`],
//! updated in [`Tracker::record`] and listed in [`Metrics::columns`].

use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::math::{Real, Vec2, to_f64};
use janus2d_world::{World, WorldError};

/// What a [`Tracker`] follows and how it judges a collapse.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackerConfig {
    /// The body whose sink, drift, speed and collapse are tracked (`None`:
    /// those metrics stay zero or empty).
    pub probe: Option<BodyHandle>,
    /// Centre of the collapse box, m (`None`: the probe's start position).
    /// A stack built with gaps settles below its start: give its rest pose.
    pub rest_position: Option<Vec2>,
    /// Half extents of the collapse box around the rest position, m: the
    /// stack has collapsed once the probe's origin leaves this box.
    pub collapse_half_extents: Vec2,
    /// Collapse is not checked before this time, s (lets a stack settle).
    pub collapse_grace: Real,
    /// "Late" metrics cover the steps that end after this time, s.
    pub late_from: Real,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig {
            probe: None,
            rest_position: None,
            collapse_half_extents: Vec2::new(0.5, 0.5),
            collapse_grace: 0.0,
            late_from: 0.0,
        }
    }
}

impl TrackerConfig {
    /// Follows `probe`, with the default collapse box (half extents 0.5 m
    /// around its start, no grace) and every step counted as late.
    pub fn probe(probe: BodyHandle) -> Self {
        TrackerConfig {
            probe: Some(probe),
            ..TrackerConfig::default()
        }
    }

    /// Sets the collapse box: centre `rest` (m), half extents `half` (m),
    /// not checked before `grace` seconds.
    pub fn with_collapse_box(mut self, rest: Vec2, half: Vec2, grace: Real) -> Self {
        self.rest_position = Some(rest);
        self.collapse_half_extents = half;
        self.collapse_grace = grace;
        self
    }

    /// Sets the start of the late window, s.
    pub fn with_late_from(mut self, late_from: Real) -> Self {
        self.late_from = late_from;
        self
    }
}

/// A metric outside the fixed list, sampled after every step (the extension
/// point for portal `|C|` and η-momentum error; see the module docs).
pub trait ExtraMetric {
    /// Column name (snake case, no commas), e.g. `portal_c`.
    fn name(&self) -> &'static str;
    /// Unit, e.g. `m` or `1`.
    fn unit(&self) -> &'static str;
    /// The value after the current step, or `None` when it does not apply
    /// (e.g. no body is crossing a portal).
    fn measure(&mut self, world: &World) -> Option<f64>;
}

/// Portal constraint error `max |x₂ − T(x₁)|` over the crossings in
/// progress, m (`None` while nothing crosses).
#[cfg(feature = "portals")]
pub struct PortalMapError;

#[cfg(feature = "portals")]
impl ExtraMetric for PortalMapError {
    fn name(&self) -> &'static str {
        "portal_c"
    }
    fn unit(&self) -> &'static str {
        "m"
    }
    fn measure(&mut self, world: &World) -> Option<f64> {
        (world.crossing_count() > 0).then(|| to_f64(world.max_portal_error()))
    }
}

/// η-scaled momentum error of crossings, relative:
/// `|p − p₀| / |p₀|` with `p = m₁ v₁ + η Qᵀ (m₂ v₂)` (the masses the solver
/// uses) and `p₀` its value when the crossing was first seen.
///
/// The portal constraint conserves `p` exactly (`P₁ + η Qᵀ P₂ = 0` for every
/// impulse, static portal bodies), so in a passive scene (no gravity or
/// contacts on the copies, static portals) with `η = 1` it measures the
/// solver's round-off; the straddle weighting also conserves it for `η = 1`.
/// For `η ≠ 1` the mass model scales momentum by design (`η⁴` for the same
/// material), so the figure is only meaningful at `η = 1`. `None` while
/// nothing crosses.
#[cfg(feature = "portals")]
#[derive(Default)]
pub struct PortalMomentumError {
    start: Vec<(BodyHandle, Vec2)>,
}

#[cfg(feature = "portals")]
impl ExtraMetric for PortalMomentumError {
    fn name(&self) -> &'static str {
        "portal_eta_momentum"
    }
    fn unit(&self) -> &'static str {
        "1"
    }
    fn measure(&mut self, world: &World) -> Option<f64> {
        let mut worst: Option<f64> = None;
        for c in world.portal_constraints() {
            let def = c.def();
            let q = world.portal_constraint_map(c).rotation();
            let (m1, v1) = (
                world.mass(def.body).ok()?,
                world.linear_velocity(def.body).ok()?,
            );
            let (m2, v2) = (
                world.mass(def.clone).ok()?,
                world.linear_velocity(def.clone).ok()?,
            );
            let p = m1 * v1 + def.eta * q.inv_rotate(m2 * v2);
            let p0 = match self.start.iter().find(|(b, _)| *b == def.body) {
                Some((_, p0)) => *p0,
                None => {
                    self.start.push((def.body, p));
                    p
                }
            };
            let e = to_f64((p - p0).length() / p0.length().max(Real::MIN_POSITIVE));
            worst = Some(worst.map_or(e, |w: f64| w.max(e)));
        }
        worst
    }
}

/// The peak and last value of an [`ExtraMetric`].
#[derive(Clone, Debug, PartialEq)]
pub struct ExtraValue {
    /// Column name.
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Largest value measured (`None`: never applied).
    pub peak: Option<f64>,
    /// Value after the last step that applied.
    pub last: Option<f64>,
}

/// The error figures of one run; see the module docs for the definitions.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Metrics {
    /// Steps recorded.
    pub steps: u64,
    /// Simulated time recorded, s.
    pub time: f64,
    /// Largest contact penetration, m.
    pub max_penetration: f64,
    /// Largest contact penetration over the late steps, m.
    pub late_max_penetration: f64,
    /// Largest sink of the probe below its start, m (≥ 0).
    pub max_sink: f64,
    /// Sink of the probe after the last step, m (signed).
    pub final_sink: f64,
    /// Largest sideways drift `|x − x0|` of the probe, m.
    pub max_drift: f64,
    /// Sideways displacement `x − x0` of the probe after the last step, m.
    pub final_drift: f64,
    /// Largest joint gap, m.
    pub max_joint_gap: f64,
    /// Largest joint gap over the late steps, m.
    pub late_max_joint_gap: f64,
    /// Total energy at the start, J.
    pub initial_energy: f64,
    /// Total energy after the last step, J.
    pub final_energy: f64,
    /// Largest `E − E0`, J (≥ 0).
    pub max_energy_gain: f64,
    /// Largest `E0 − E`, J (≥ 0).
    pub max_energy_loss: f64,
    /// Largest total kinetic energy, J.
    pub peak_kinetic_energy: f64,
    /// Largest speed of any dynamic body, m/s.
    pub peak_speed: f64,
    /// Largest speed of any dynamic body over the late steps, m/s.
    pub late_peak_speed: f64,
    /// Largest probe speed over the late steps, m/s.
    pub late_probe_speed: f64,
    /// Time the probe first left its collapse box, s (`None`: never).
    pub collapse_time: Option<f64>,
    /// Steps that reported a non-finite body.
    pub non_finite_steps: u64,
    /// Peaks of the [`ExtraMetric`]s, in the order they were added.
    pub extras: Vec<ExtraValue>,
}

/// One column of [`Metrics::columns`]: a metric's name, unit and value.
#[derive(Clone, Debug, PartialEq)]
pub struct Column {
    /// Column name (the field name, or the extra metric's name).
    pub name: &'static str,
    /// Unit.
    pub unit: &'static str,
    /// Value (`None`: empty, e.g. a stack that never collapsed).
    pub value: Option<f64>,
}

impl Metrics {
    /// Energy after the last step minus energy at the start, J (signed).
    pub fn energy_drift(&self) -> f64 {
        self.final_energy - self.initial_energy
    }

    /// The largest energy error relative to the motion's energy:
    /// `max(max_energy_gain, max_energy_loss) / peak_kinetic_energy`
    /// (0 when nothing moved).
    pub fn relative_energy_error(&self) -> f64 {
        let err = self.max_energy_gain.max(self.max_energy_loss);
        if self.peak_kinetic_energy > 0.0 {
            err / self.peak_kinetic_energy
        } else {
            0.0
        }
    }

    /// Every metric as a named column with its unit, fixed ones first in
    /// the order of the module docs' table, then the extras (peaks). The
    /// sweep writes exactly these columns.
    pub fn columns(&self) -> Vec<Column> {
        let c = |name, unit, value: f64| Column {
            name,
            unit,
            value: Some(value),
        };
        let mut cols = vec![
            c("max_penetration", "m", self.max_penetration),
            c("late_max_penetration", "m", self.late_max_penetration),
            c("max_sink", "m", self.max_sink),
            c("final_sink", "m", self.final_sink),
            c("max_drift", "m", self.max_drift),
            c("final_drift", "m", self.final_drift),
            c("max_joint_gap", "m", self.max_joint_gap),
            c("late_max_joint_gap", "m", self.late_max_joint_gap),
            c("initial_energy", "J", self.initial_energy),
            c("final_energy", "J", self.final_energy),
            c("max_energy_gain", "J", self.max_energy_gain),
            c("max_energy_loss", "J", self.max_energy_loss),
            c("peak_kinetic_energy", "J", self.peak_kinetic_energy),
            c("relative_energy_error", "1", self.relative_energy_error()),
            c("peak_speed", "m/s", self.peak_speed),
            c("late_peak_speed", "m/s", self.late_peak_speed),
            c("late_probe_speed", "m/s", self.late_probe_speed),
            Column {
                name: "collapse_time",
                unit: "s",
                value: self.collapse_time,
            },
            c("non_finite_steps", "1", self.non_finite_steps as f64),
        ];
        cols.extend(self.extras.iter().map(|e| Column {
            name: e.name,
            unit: e.unit,
            value: e.peak,
        }));
        cols
    }
}

/// Follows a world step by step and accumulates its [`Metrics`].
pub struct Tracker {
    config: TrackerConfig,
    start: Option<Vec2>,
    rest: Option<Vec2>,
    metrics: Metrics,
    extras: Vec<Box<dyn ExtraMetric>>,
}

impl Tracker {
    /// Starts tracking `world` as it is now: records the probe's position
    /// and the total energy. Fails if the probe is not a live body.
    pub fn new(world: &World, config: TrackerConfig) -> Result<Tracker, WorldError> {
        let start = match config.probe {
            Some(p) => Some(world.position(p)?),
            None => None,
        };
        let rest = config.rest_position.or(start);
        let energy = total_energy(world);
        let metrics = Metrics {
            initial_energy: energy,
            final_energy: energy,
            ..Metrics::default()
        };
        Ok(Tracker {
            config,
            start,
            rest,
            metrics,
            extras: Vec::new(),
        })
    }

    /// Adds a metric outside the fixed list (builder style).
    pub fn with_extra(mut self, extra: Box<dyn ExtraMetric>) -> Self {
        self.metrics.extras.push(ExtraValue {
            name: extra.name(),
            unit: extra.unit(),
            peak: None,
            last: None,
        });
        self.extras.push(extra);
        self
    }

    /// The configuration.
    pub fn config(&self) -> &TrackerConfig {
        &self.config
    }

    /// Steps the world by `dt` and records the result.
    pub fn step(&mut self, world: &mut World, dt: Real) -> Result<(), WorldError> {
        world.step(dt)?;
        self.record(world, dt)
    }

    /// Records the state after a step of length `dt` (s) that the caller
    /// took (so the caller can time the step alone).
    pub fn record(&mut self, world: &World, dt: Real) -> Result<(), WorldError> {
        let dt = to_f64(dt);
        let m = &mut self.metrics;
        m.steps += 1;
        m.time = m.steps as f64 * dt;
        // Half a step of tolerance: the step ending at `late_from` itself is
        // not late, whatever the rounding of `steps · dt`.
        let late = m.time > to_f64(self.config.late_from) + 0.5 * dt;

        let pen = to_f64(world.max_penetration());
        m.max_penetration = m.max_penetration.max(pen);
        let gap = to_f64(world.max_joint_gap());
        m.max_joint_gap = m.max_joint_gap.max(gap);

        let mut kinetic = 0.0;
        let mut potential = 0.0;
        let mut speed: f64 = 0.0;
        for_each_dynamic(world, |b| {
            kinetic += b.kinetic();
            potential += b.potential;
            speed = speed.max(b.speed);
        });
        let energy = kinetic + potential;
        m.final_energy = energy;
        m.max_energy_gain = m.max_energy_gain.max(energy - m.initial_energy);
        m.max_energy_loss = m.max_energy_loss.max(m.initial_energy - energy);
        m.peak_kinetic_energy = m.peak_kinetic_energy.max(kinetic);
        m.peak_speed = m.peak_speed.max(speed);
        if !world.events().non_finite_bodies.is_empty() {
            m.non_finite_steps += 1;
        }

        let mut probe_speed = 0.0;
        if let (Some(probe), Some(start)) = (self.config.probe, self.start) {
            let p = world.position(probe)?;
            let sink = to_f64(start.y - p.y);
            let drift = to_f64(p.x - start.x);
            m.final_sink = sink;
            m.final_drift = drift;
            m.max_sink = m.max_sink.max(sink);
            m.max_drift = m.max_drift.max(drift.abs());
            probe_speed = to_f64(world.linear_velocity(probe)?.length());
            if let Some(rest) = self.rest {
                let checked = m.time > to_f64(self.config.collapse_grace) + 0.5 * dt;
                let d = p - rest;
                let half = self.config.collapse_half_extents;
                let outside = !(d.x.abs() <= half.x && d.y.abs() <= half.y);
                if checked && outside && m.collapse_time.is_none() {
                    m.collapse_time = Some(m.time);
                }
            }
        }
        if late {
            m.late_max_penetration = m.late_max_penetration.max(pen);
            m.late_max_joint_gap = m.late_max_joint_gap.max(gap);
            m.late_peak_speed = m.late_peak_speed.max(speed);
            m.late_probe_speed = m.late_probe_speed.max(probe_speed);
        }
        for (extra, value) in self.extras.iter_mut().zip(m.extras.iter_mut()) {
            if let Some(v) = extra.measure(world) {
                value.last = Some(v);
                value.peak = Some(value.peak.map_or(v, |p| p.max(v)));
            }
        }
        Ok(())
    }

    /// The figures so far.
    pub fn metrics(&self) -> &Metrics {
        &self.metrics
    }

    /// The figures, consuming the tracker.
    pub fn into_metrics(self) -> Metrics {
        self.metrics
    }
}

/// One dynamic body's contribution, read through the public API.
struct BodyEnergy {
    mass: f64,
    inertia: f64,
    speed: f64,
    angular_speed: f64,
    potential: f64,
}

impl BodyEnergy {
    fn kinetic(&self) -> f64 {
        0.5 * self.mass * self.speed * self.speed
            + 0.5 * self.inertia * self.angular_speed * self.angular_speed
    }
}

fn for_each_dynamic(world: &World, mut f: impl FnMut(&BodyEnergy)) {
    let g = world.gravity();
    for h in world.body_handles() {
        if !matches!(world.body_type(h), Ok(BodyType::Dynamic)) {
            continue;
        }
        let (Ok(mass), Ok(inertia), Ok(v), Ok(w), Ok(c)) = (
            world.mass(h),
            world.rotational_inertia(h),
            world.linear_velocity(h),
            world.angular_velocity(h),
            world.center_of_mass(h),
        ) else {
            continue;
        };
        let scale = world.gravity_scale(h).unwrap_or(1.0);
        let mass = to_f64(mass);
        let height = to_f64(g.x) * to_f64(c.x) + to_f64(g.y) * to_f64(c.y);
        f(&BodyEnergy {
            mass,
            inertia: to_f64(inertia),
            speed: to_f64(v.length()),
            angular_speed: to_f64(w),
            potential: -mass * to_f64(scale) * height,
        });
    }
}

/// Total kinetic energy of the dynamic bodies, J: `Σ ½ m |v|² + ½ I ω²`.
pub fn kinetic_energy(world: &World) -> f64 {
    let mut e = 0.0;
    for_each_dynamic(world, |b| e += b.kinetic());
    e
}

/// Total gravitational potential energy of the dynamic bodies, J:
/// `Σ −m s (g · c)` (zero at the origin; `s` is the body's gravity scale).
pub fn potential_energy(world: &World) -> f64 {
    let mut e = 0.0;
    for_each_dynamic(world, |b| e += b.potential);
    e
}

/// Kinetic plus potential energy, J.
pub fn total_energy(world: &World) -> f64 {
    kinetic_energy(world) + potential_energy(world)
}

/// The largest linear speed of any dynamic body, m/s.
pub fn max_speed(world: &World) -> f64 {
    let mut s: f64 = 0.0;
    for_each_dynamic(world, |b| s = s.max(b.speed));
    s
}

/// Energy that semi-implicit Euler removes from a body of mass `mass` (kg)
/// in free fall under gravity of magnitude `gravity` (m/s²) over `substeps`
/// substeps of length `h` (s): `substeps · ½ m g² h²` J. Each substep sets
/// `v' = v − g h`, then `y' = y + h v'`, so `E' − E = −½ m g² h²` exactly.
pub fn free_fall_energy_loss(mass: f64, gravity: f64, h: f64, substeps: u64) -> f64 {
    substeps as f64 * 0.5 * mass * gravity * gravity * h * h
}

/// The hard scenes of the scene definitions (`janus2d_testbed`) that the accuracy sweep
/// runs, each built exactly as `tests/scene_runs/hard_cases.rs` and
/// `tests/scene_runs/joint_scenes.rs` build them, with the probe and tracker settings
/// that measure them.
pub mod cases {
    use janus2d_core::body::BodyHandle;
    use janus2d_core::math::{Real, Vec2};
    use janus2d_world::{World, WorldDef};

    use super::{Tracker, TrackerConfig};
    use crate::scenes::{self, DT};

    /// A built hard scene with what measures it.
    pub struct Case {
        /// The world.
        pub world: World,
        /// The tracked body.
        pub probe: BodyHandle,
        /// What the probe is.
        pub probe_label: &'static str,
        /// Steps of length [`DT`] the case runs.
        pub steps: usize,
        /// How to track it (probe, collapse box, late window).
        pub config: TrackerConfig,
    }

    impl Case {
        /// A tracker for this case, started now (with the portal error
        /// metric when the world has portals).
        pub fn tracker(&self) -> Tracker {
            let tracker =
                Tracker::new(&self.world, self.config.clone()).expect("the probe is live");
            #[cfg(feature = "portals")]
            if self.world.portal_pair_count() > 0 {
                return tracker
                    .with_extra(Box::new(super::PortalMapError))
                    .with_extra(Box::new(super::PortalMomentumError::default()));
            }
            tracker
        }

        /// Runs `steps` steps instead, with the late window moved to the
        /// new last second (for short runs).
        pub fn with_steps(mut self, steps: usize) -> Case {
            self.steps = steps;
            self.config.late_from = late_from_last_second(steps);
            self
        }
    }

    /// A probe that swings freely has no collapse box.
    fn no_collapse(config: TrackerConfig) -> TrackerConfig {
        TrackerConfig {
            collapse_half_extents: Vec2::new(Real::INFINITY, Real::INFINITY),
            ..config
        }
    }

    /// A case whose probe swings freely, run for `steps`, late window the
    /// last second.
    fn swinging(scene: scenes::Scene, steps: usize) -> Case {
        Case {
            config: no_collapse(TrackerConfig::probe(scene.probe))
                .with_late_from(late_from_last_second(steps)),
            world: scene.world,
            probe: scene.probe,
            probe_label: scene.probe_label,
            steps,
        }
    }

    fn late_from_last_second(steps: usize) -> Real {
        (steps as Real * DT - 1.0).max(0.0)
    }

    /// The pyramid of `base` rows ([`scenes::large_pyramid`]: base 20 is
    /// "pyramid 20", base 100 "large pyramid") run for `steps` steps. Probe:
    /// the top box; collapse box half extents (0.5, `sink_allowance`) around
    /// its start; late window: the last second.
    pub fn pyramid(def: &WorldDef, base: usize, steps: usize, sink_allowance: Real) -> Case {
        let scene = scenes::large_pyramid(def, base);
        let start = scene.world.position(scene.probe).expect("live probe");
        let config = TrackerConfig::probe(scene.probe)
            .with_collapse_box(start, Vec2::new(0.5, sink_allowance), 0.0)
            .with_late_from(late_from_last_second(steps));
        Case {
            world: scene.world,
            probe: scene.probe,
            probe_label: "top box",
            steps,
            config,
        }
    }

    /// The vertical stack of `rows` 1 m boxes (0.1 m gaps, x alternating
    /// ±0.01, μ 0.3) on a ground box, run for `seconds`. Probe: the top box;
    /// collapse: its origin more than 0.5 m from (0, rest height) after a 2 s
    /// grace, as in `tests/scene_runs/hard_cases.rs`.
    pub fn vertical_stack(def: &WorldDef, rows: usize, seconds: usize) -> Case {
        let scene = scenes::vertical_stack(def, rows);
        let steps = seconds * 60;
        let rest = Vec2::new(0.0, 0.5 + (rows - 1) as Real);
        let config = TrackerConfig::probe(scene.probe)
            .with_collapse_box(rest, Vec2::new(0.5, 0.5), 2.0)
            .with_late_from(late_from_last_second(steps));
        Case {
            world: scene.world,
            probe: scene.probe,
            probe_label: scene.probe_label,
            steps,
            config,
        }
    }

    /// Ball and chain: 40 capsule links (half-length 0.5, r 0.125, density
    /// 20) from a static pin at (0, 40) and a ball r 8 (density 20) jointed
    /// to the last link, released horizontally; 10 s. Probe: the ball (no
    /// collapse box: it swings).
    pub fn ball_and_chain(def: &WorldDef) -> Case {
        let scene = scenes::ball_and_chain(def);
        let steps = scene.steps;
        swinging(scene, steps)
    }

    /// Portal stream ([`scenes::portal_stream`]): 200 mixed shapes pour
    /// through a floor portal and out of a wall portal; `steps` steps.
    /// Probe: the last shape (no collapse box). The tracker adds
    /// [`PortalMapError`](super::PortalMapError).
    #[cfg(feature = "portals")]
    pub fn portal_stream(def: &WorldDef, steps: usize) -> Case {
        swinging(scenes::portal_stream(def, true), steps)
    }

    /// Bridge: 160 planks half 0.5×0.125 (density 20, mass set directly,
    /// linear damping 0.1, no shapes) hinged end to end, both ends pinned;
    /// 10 s. Probe: the middle plank (its sink is the sag; no collapse box).
    pub fn bridge(def: &WorldDef) -> Case {
        let scene = scenes::bridge(def);
        let steps = scene.steps;
        swinging(scene, steps)
    }
}
