//! Per-step profile: the time of each pipeline stage and counters that show
//! which stages did work.
//!
//! | field (time, s)  | stage                                              |
//! |------------------|----------------------------------------------------|
//! | `broadphase`     | new pairs from moved proxies; proxy updates        |
//! | `narrowphase`    | manifolds of every awake contact                   |
//! | `portals`        | clipping, crossings, handovers, weights            |
//! | `solver.*`       | the solver's stages ([`SolverProfile`]): prepare, integrate, warm start, solve, relax, restitution, finalize |
//! | `continuous`     | fast bodies swept to their time of impact          |
//! | `sleep`          | sleep timers and islands                           |
//!
//! A stage whose feature the scene lacks is not entered: its time is zero
//! and its counters stay zero (see [`StepCounters`]).

use janus2d_core::solver::SolverProfile;

/// Stage timings of the last step, seconds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepProfile {
    /// Broadphase (pair finding and proxy updates).
    pub broadphase: f64,
    /// Narrowphase (manifolds).
    pub narrowphase: f64,
    /// Portal stage.
    pub portals: f64,
    /// The solver's stages (prepare, integrate, warm start, solve, relax,
    /// restitution, finalize).
    pub solver: SolverProfile,
    /// Continuous collision (fast-body test, sweeps, moves back).
    pub continuous: f64,
    /// Sleep.
    pub sleep: f64,
    /// Whole step.
    pub total: f64,
}

/// Work counters of the last step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepCounters {
    /// The collision stages ran (the world has shapes).
    pub collision_ran: bool,
    /// Shape pairs whose manifolds were computed.
    pub pairs_tested: usize,
    /// New pairs found by the broadphase.
    pub pairs_created: usize,
    /// Broadphase proxies re-inserted.
    pub proxies_moved: usize,
    /// Touching solid contacts solved.
    pub contacts: usize,
    /// Contact rows (normal + friction per point).
    pub contact_rows: usize,
    /// Joint rows (revolute: 2 point rows plus limit, motor, spring rows; weld: 3).
    pub joint_rows: usize,
    /// Joint point rows solved directly, as joint trees (0: the tree solve
    /// did nothing this step).
    pub direct_joint_rows: usize,
    /// Portal constraint rows (3 per crossing).
    pub portal_rows: usize,
    /// The portal stage ran (the world has a portal pair).
    pub portal_stage_ran: bool,
    /// Bodies tested against apertures.
    pub portal_bodies_tested: usize,
    /// Crossings in progress.
    pub portal_crossings: usize,
    /// Contacts with restitution > 0 (the restitution pass runs only if > 0).
    pub restitution_contacts: usize,
    /// Bodies integrated with gravity (0 when gravity is zero).
    pub gravity_bodies: usize,
    /// Awake dynamic and kinematic bodies.
    pub awake_bodies: usize,
    /// Sleeping bodies.
    pub sleeping_bodies: usize,
    /// Fast bodies swept by continuous collision (0: no time-of-impact work).
    pub toi_bodies: usize,
    /// Time-of-impact searches run.
    pub toi_calls: usize,
    /// Bodies moved back to a time of impact.
    pub toi_hits: usize,
}

/// What the step's counters are gathered from.
pub(crate) struct CounterSources<'a> {
    pub(crate) collision_ran: bool,
    pub(crate) collision: CollisionCounters,
    pub(crate) contacts: usize,
    pub(crate) joint_rows: usize,
    pub(crate) direct_joint_rows: usize,
    pub(crate) portal_stage_ran: bool,
    /// Portal rows, bodies tested, crossings in progress.
    pub(crate) portals: (usize, usize, usize),
    pub(crate) gravity: bool,
    pub(crate) bodies: &'a janus2d_core::body::BodySet,
    pub(crate) continuous: crate::continuous::ContinuousCounters,
}

impl StepCounters {
    /// The counters of a step, from what each stage reported.
    pub(crate) fn gather(s: &CounterSources<'_>) -> StepCounters {
        let cc = s.collision;
        let ran = s.collision_ran;
        let (portal_rows, portal_bodies_tested, portal_crossings) = s.portals;
        StepCounters {
            collision_ran: ran,
            pairs_tested: cc.pairs_tested,
            pairs_created: cc.pairs_created,
            proxies_moved: cc.proxies_moved,
            contacts: s.contacts,
            contact_rows: if ran { cc.contact_rows } else { 0 },
            joint_rows: s.joint_rows,
            direct_joint_rows: s.direct_joint_rows,
            portal_rows,
            portal_stage_ran: s.portal_stage_ran,
            portal_bodies_tested,
            portal_crossings,
            restitution_contacts: if ran { cc.restitution_contacts } else { 0 },
            gravity_bodies: if s.gravity {
                s.bodies.moving_count()
            } else {
                0
            },
            awake_bodies: s.bodies.moving_count(),
            sleeping_bodies: s.bodies.sleeping_count(),
            toi_bodies: s.continuous.toi_bodies,
            toi_calls: s.continuous.toi_calls,
            toi_hits: s.continuous.toi_hits,
        }
    }
}

/// What the event gathering read in the last step: the per-point,
/// per-contact and per-body work of hit, contact force and body move
/// events. Each gathering runs only when something asks for it (a shape
/// with hit events on, a shape with a finite force threshold, move events
/// on), so a scene that turns them all off reads nothing (0 here). Contact
/// and sensor begin/end events cost no gathering: the contact update that
/// finds a pair's touching change tests the pair's flag and records it or
/// not.
///
/// Not state, as the timings: not serialized (a restored world reads 0
/// until it steps).
///
/// ```
/// use janus2d_world::{EventWork, World, WorldDef};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// world.step(1.0 / 60.0).unwrap();
/// assert_eq!(world.event_work(), EventWork::default());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EventWork {
    /// Solved contact points whose approach speed the hit-event gathering
    /// read (0 unless some shape has hit events on).
    pub hit_points_read: usize,
    /// Awake contacts the contact-force gathering read (0 unless some shape
    /// has a finite `force_event_threshold`).
    pub force_contacts_read: usize,
    /// Bodies the move-event gathering read (0 unless the world gathers
    /// move events).
    pub move_bodies_read: usize,
}

/// Counters of the last collision pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CollisionCounters {
    /// Shape pairs whose manifolds were computed.
    pub pairs_tested: usize,
    /// New pairs found by the broadphase.
    pub pairs_created: usize,
    /// Touching solid contacts.
    pub touching: usize,
    /// Proxies re-inserted in the broadphase.
    pub proxies_moved: usize,
    /// Contact rows built (normal + friction per point).
    pub contact_rows: usize,
    /// Contact constraints built with restitution > 0.
    pub restitution_contacts: usize,
}
