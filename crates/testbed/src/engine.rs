//! What an engine adapter offers: build a [`SceneDesc`], apply its script,
//! step, and read back what the shared metric code and the sanity line
//! need. janus2d's adapter is [`crate::janus::Janus`]; the peers benchmark
//! (`benches/peers`) adds Box2D's and Rapier's.
//!
//! Bodies are addressed by their index in the scene's `bodies`; bodies a
//! script spawned are only seen through [`Engine::dynamic_states`].

use glam::DVec2;

use crate::desc::{Action, SceneDesc};

/// Position, angle and velocities of one body.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyReading {
    /// Origin, m.
    pub position: DVec2,
    /// Angle, rad.
    pub angle: f64,
    /// Velocity of the origin, m/s.
    pub linear_velocity: DVec2,
    /// Angular velocity, rad/s.
    pub angular_velocity: f64,
}

/// One step's time by stage, milliseconds. Stages an engine does not report
/// separately are `None`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// New pairs and broadphase upkeep.
    pub pairs: Option<f64>,
    /// Narrowphase (manifolds).
    pub collide: Option<f64>,
    /// Solver setup (islands, colouring, constraint building).
    pub setup: Option<f64>,
    /// Constraint prepare.
    pub prepare: Option<f64>,
    /// Velocity and position integration.
    pub integrate: Option<f64>,
    /// Warm start.
    pub warm_start: Option<f64>,
    /// Biased solve.
    pub solve: Option<f64>,
    /// Relax iterations.
    pub relax: Option<f64>,
    /// Restitution.
    pub restitution: Option<f64>,
    /// Storing impulses.
    pub store: Option<f64>,
    /// Finalize (transforms, proxies, continuous).
    pub finalize: Option<f64>,
    /// Sleep islands.
    pub sleep: Option<f64>,
    /// The whole step.
    pub step: f64,
}

impl StageTimes {
    /// The stages as (name, value), in pipeline order.
    #[must_use]
    pub fn named(&self) -> [(&'static str, Option<f64>); 13] {
        [
            ("pairs", self.pairs),
            ("collide", self.collide),
            ("setup", self.setup),
            ("prepare", self.prepare),
            ("integrate", self.integrate),
            ("warm start", self.warm_start),
            ("solve", self.solve),
            ("relax", self.relax),
            ("restitution", self.restitution),
            ("store", self.store),
            ("finalize", self.finalize),
            ("sleep", self.sleep),
            ("step", Some(self.step)),
        ]
    }

    /// Adds `other` stage by stage (a stage missing in either stays `None`
    /// only if missing in both).
    pub fn accumulate(&mut self, other: &StageTimes) {
        fn add(a: &mut Option<f64>, b: Option<f64>) {
            if let Some(b) = b {
                *a = Some(a.unwrap_or(0.0) + b);
            }
        }
        add(&mut self.pairs, other.pairs);
        add(&mut self.collide, other.collide);
        add(&mut self.setup, other.setup);
        add(&mut self.prepare, other.prepare);
        add(&mut self.integrate, other.integrate);
        add(&mut self.warm_start, other.warm_start);
        add(&mut self.solve, other.solve);
        add(&mut self.relax, other.relax);
        add(&mut self.restitution, other.restitution);
        add(&mut self.store, other.store);
        add(&mut self.finalize, other.finalize);
        add(&mut self.sleep, other.sleep);
        self.step += other.step;
    }

    /// Every stage divided by `n`.
    #[must_use]
    pub fn scaled(&self, n: f64) -> StageTimes {
        let s = |x: Option<f64>| x.map(|x| x / n);
        StageTimes {
            pairs: s(self.pairs),
            collide: s(self.collide),
            setup: s(self.setup),
            prepare: s(self.prepare),
            integrate: s(self.integrate),
            warm_start: s(self.warm_start),
            solve: s(self.solve),
            relax: s(self.relax),
            restitution: s(self.restitution),
            store: s(self.store),
            finalize: s(self.finalize),
            sleep: s(self.sleep),
            step: self.step / n,
        }
    }
}

/// Options every adapter honours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineOptions {
    /// Worker threads (1: single thread).
    pub threads: usize,
}

impl Default for EngineOptions {
    fn default() -> Self {
        EngineOptions { threads: 1 }
    }
}

/// An engine that can run the scene descriptions.
pub trait Engine: Sized {
    /// The engine's name in tables.
    const NAME: &'static str;

    /// Builds the scene. `Err` if the engine cannot express it (a portal
    /// scene on an engine without portals).
    fn build(desc: &SceneDesc, options: EngineOptions) -> Result<Self, String>;

    /// Applies one scripted action (before the step it belongs to).
    fn apply(&mut self, action: &Action);

    /// Advances one step of the scene's dt with its substeps.
    fn step(&mut self);

    /// State of a body of the scene's initial `bodies` (None once gone).
    fn state(&self, body: usize) -> Option<BodyReading>;

    /// State of every dynamic body now in the world (spawned ones too).
    fn dynamic_states(&self, out: &mut Vec<BodyReading>);

    /// Bodies in the world (static ones included).
    fn body_count(&self) -> usize;

    /// Awake dynamic and kinematic bodies.
    fn awake_count(&self) -> usize;

    /// Shape pairs whose manifold has at least one point.
    fn touching_count(&self) -> usize;

    /// The last step's time by stage, as the engine itself measured it.
    fn stage_times(&self) -> StageTimes;
}

/// Applies `desc`'s script for `step` and steps once.
pub fn scripted_step<E: Engine>(
    engine: &mut E,
    desc: &SceneDesc,
    step: usize,
    buf: &mut Vec<Action>,
) {
    desc.script.actions(step, desc.settings.dt, buf);
    for action in buf.iter() {
        engine.apply(action);
    }
    engine.step();
}
