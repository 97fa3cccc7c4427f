//! The standard scenes built into janus2d worlds, for the tests, examples,
//! benchmarks and the accuracy sweep. Every builder takes the caller's
//! [`WorldDef`] (solver knobs, sleep, gravity) and builds the scene's
//! description ([`crate::benchmarks`], [`crate::hard`]) into it, so each
//! scene is defined once.
//!
//! | builder              | bodies  | what it stresses                        |
//! |----------------------|---------|-----------------------------------------|
//! | [`large_pyramid`]    | 5,051   | deep stacking, solver convergence       |
//! | [`many_pyramids`]    | 22,001  | many islands, broadphase, cache         |
//! | [`joint_grid`]       | 10,000  | 19,800 joints                           |
//! | [`tumbler`]          | 2,027   | a motor-driven drum, constant motion    |
//! | [`smash`]            | 9,601   | a fast projectile into a block, g = 0   |
//! | [`spinner`]          | 6,078   | a paddle in a one-sided loop, mixed shapes |
//! | [`by_name`]          |         | any of [`NAMES`] (rain, junkyard, compounds, washer too) |

use janus2d_core::body::BodyHandle;
use janus2d_core::math::{Real, Vec2};
use janus2d_world::{World, WorldDef};

use crate::benchmarks;
use crate::desc::SceneDesc;
use crate::hard;
use crate::janus::Janus;

pub use crate::benchmarks::NAMES;

/// Shared step length of every scene, s (1/60).
pub const DT: Real = 1.0 / 60.0;

/// A built scene.
pub struct Scene {
    /// The world.
    pub world: World,
    /// The body whose motion the scene reports.
    pub probe: BodyHandle,
    /// What the probe is.
    pub probe_label: &'static str,
    /// Steps Box2D's benchmark runs for this scene.
    pub steps: usize,
    /// Handles of the description's bodies, by index.
    pub bodies: Vec<BodyHandle>,
}

/// The shared settings: the default world (gravity (0, −10), 4 substeps,
/// contacts 30 Hz / ζ 10, joints 60 Hz / ζ 2, push-out 3 m/s) with **sleep
/// off**, as the hard cases and most benchmark scenes require.
#[must_use]
pub fn shared_settings() -> WorldDef {
    crate::janus::world_def(&crate::desc::Settings::default())
}

/// Builds a description into a world made from `def`.
///
/// # Panics
/// If the description does not build (the standard ones always do).
#[must_use]
pub fn build(desc: &SceneDesc, def: &WorldDef) -> Scene {
    scene_of(
        Janus::with_def(desc, def.clone()).expect("a standard scene builds"),
        desc,
    )
}

fn scene_of(built: Janus, desc: &SceneDesc) -> Scene {
    let probe = desc.probe.map_or(built.bodies[0], |p| built.bodies[p]);
    Scene {
        world: built.world,
        probe,
        probe_label: desc.probe_label,
        steps: desc.steps,
        bodies: built.bodies,
    }
}

/// A pyramid of `base` rows of unit boxes; `base = 100` is `large_pyramid`,
/// `base = 20` the hard case "pyramid 20".
#[must_use]
pub fn large_pyramid(def: &WorldDef, base: usize) -> Scene {
    build(&benchmarks::pyramid(base), def)
}

/// 20 × 20 pyramids of base 10 on 20 ground segments.
#[must_use]
pub fn many_pyramids(def: &WorldDef) -> Scene {
    build(&benchmarks::many_pyramids(), def)
}

/// `n × n` jointed circles (gravity as `def` says).
#[must_use]
pub fn joint_grid(def: &WorldDef, n: usize) -> Scene {
    build(&benchmarks::joint_grid(n, 1.0), def)
}

/// The motor-driven drum.
#[must_use]
pub fn tumbler(def: &WorldDef) -> Scene {
    build(&benchmarks::tumbler(), def)
}

/// The projectile into a sleeping block; gravity zero whatever `def` says.
#[must_use]
pub fn smash(def: &WorldDef) -> Scene {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..def.clone()
    };
    build(&benchmarks::smash(), &def)
}

/// The paddle in a one-sided loop.
#[must_use]
pub fn spinner(def: &WorldDef) -> Scene {
    build(&benchmarks::spinner(), def)
}

/// A benchmark scene of [`NAMES`] by name, built into `def`. Scenes with a
/// per-step script (rain, junkyard) need [`Janus`] to run it.
#[must_use]
pub fn by_name(name: &str, def: &WorldDef) -> Option<Scene> {
    let desc = benchmarks::by_name(name)?;
    if cfg!(not(feature = "portals")) && !desc.portals.is_empty() {
        return None;
    }
    let def = WorldDef {
        gravity: crate::janus::vec(desc.settings.gravity),
        ..def.clone()
    };
    Some(build(&desc, &def))
}

/// The portal "drop" scene and its pair.
#[cfg(feature = "portals")]
#[must_use]
pub fn portal_drop(def: &WorldDef) -> (Scene, janus2d_world::PortalPairHandle) {
    let desc = benchmarks::portal_drop();
    let built = Janus::with_def(&desc, def.clone()).expect("the portal drop builds");
    let pair = built.portals[0];
    (scene_of(built, &desc), pair)
}

/// The portal stream (`with_portal`) or the same through a hole.
#[must_use]
pub fn portal_stream(def: &WorldDef, with_portal: bool) -> Scene {
    build(&benchmarks::stream(with_portal), def)
}

/// The hard case "vertical stack" of `rows` boxes. Probe: the top box.
#[must_use]
pub fn vertical_stack(def: &WorldDef, rows: usize) -> Scene {
    build(&hard::vertical_stack_scene(rows), def)
}

/// The hard case "ball and chain". Probe: the ball.
#[must_use]
pub fn ball_and_chain(def: &WorldDef) -> Scene {
    build(&hard::ball_and_chain_scene(), def)
}

/// The hard case "bridge". Probe: the middle plank.
#[must_use]
pub fn bridge(def: &WorldDef) -> Scene {
    build(&hard::bridge_scene(), def)
}
