//! Islands and sleep: groups of bodies at rest leave the solver, and their
//! contacts leave the narrowphase, until something touches them.
//!
//! ```text
//! after each step (when sleep is enabled):
//!   timers   every awake dynamic body: slow (|v| and |ω|·reach below the
//!            threshold) → sleep_time += dt, else 0; keep-awake bodies
//!            (portal crossings) → 0
//!   islands  union–find over awake dynamic bodies joined by touching solid
//!            contacts and enabled joints
//!   sleep    an island whose every member rested long enough: its bodies
//!            leave the solver arrays (BodySet::sleep), its contacts move to
//!            the sleeping list (ContactSet::sleep_body)
//! wake (the whole island) when:
//!   an awake or kinematic body touches one of its bodies; a joint is
//!   created, destroyed or changed on one; any API call changes one
//!   (velocity, force, impulse, transform, mass, shapes)
//! ```
//!
//! | setting                    | unit | usual |
//! |----------------------------|------|-------|
//! | [`SleepSettings::linear_threshold`] | m/s  | 0.05  |
//! | [`SleepSettings::time_to_sleep`]    | s    | 0.5   |
//!
//! The stage owns the sleeping islands' membership, the bodies created
//! asleep that wait for the first step, and its scratch space; the world
//! passes it the bodies, shapes (for reach), contacts and joint edges.

use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::math::Real;
use janus2d_core::union_find::{find, union};

use crate::contacts::ContactSet;
use crate::error::WorldError;
use crate::shapes::ShapeStore;

/// When bodies fall asleep.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SleepSettings {
    /// Sleep on (default, as Box2D and Rapier) or off.
    pub enabled: bool,
    /// Speed below which a body counts as at rest, m/s (usual 0.05); the
    /// angular part counts as `|ω|` times the body's reach.
    pub linear_threshold: Real,
    /// How long a whole island must rest before it sleeps, s (usual 0.5).
    pub time_to_sleep: Real,
}

impl Default for SleepSettings {
    fn default() -> Self {
        SleepSettings {
            enabled: true,
            linear_threshold: 0.05,
            time_to_sleep: 0.5,
        }
    }
}

impl SleepSettings {
    /// Checks the settings: both values finite and not negative; the error
    /// names the field.
    ///
    /// ```
    /// use janus2d_world::{SleepSettings, WorldError};
    /// let bad = SleepSettings { time_to_sleep: -1.0, ..SleepSettings::default() };
    /// assert_eq!(bad.validate(), Err(WorldError::OutOfRange("time_to_sleep")));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        for (v, name) in [
            (self.linear_threshold, "linear_threshold"),
            (self.time_to_sleep, "time_to_sleep"),
        ] {
            if !v.is_finite() {
                return Err(WorldError::NonFinite(name));
            }
            if v < 0.0 {
                return Err(WorldError::OutOfRange(name));
            }
        }
        Ok(())
    }
}

/// Sleeping islands, bodies waiting to sleep, and the union–find scratch.
#[derive(Clone, Debug, Default)]
pub(crate) struct Islands {
    /// Island id of each body slot (`u32::MAX`: awake or never slept).
    island_of: Vec<u32>,
    /// Members of each sleeping island (empty: free slot).
    islands: Vec<Vec<BodyHandle>>,
    free: Vec<u32>,
    /// Bodies created with `awake = false`, put to sleep at the next step.
    pending: Vec<BodyHandle>,
    parent: Vec<u32>,
    min_time: Vec<Real>,
    groups: Vec<(u32, BodyHandle)>,
}

/// What the sleep update reads besides the bodies it changes.
pub(crate) struct SleepInput<'a> {
    pub(crate) dt: Real,
    pub(crate) settings: SleepSettings,
    pub(crate) shapes: &'a ShapeStore,
    /// Bodies that must not fall asleep this step (portal crossings).
    pub(crate) keep_awake: &'a [BodyHandle],
}

impl Islands {
    /// A body created asleep: it sleeps at the next step unless touched.
    pub(crate) fn push_pending(&mut self, body: BodyHandle) {
        self.pending.push(body);
    }

    /// Puts the bodies created asleep to sleep (when sleep is on).
    pub(crate) fn apply_pending(&mut self, enabled: bool, bodies: &mut BodySet) {
        if self.pending.is_empty() {
            return;
        }
        for b in std::mem::take(&mut self.pending) {
            if enabled {
                bodies.sleep(b);
            }
        }
    }

    /// Wakes the island of `body`: its bodies return to the solver and its
    /// contacts to the narrowphase. No effect on awake or static bodies.
    pub(crate) fn wake(
        &mut self,
        body: BodyHandle,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
    ) {
        if !self.pending.is_empty() {
            // A body created asleep that the user touched stays awake.
            self.pending.retain(|b| *b != body);
        }
        if !bodies.is_sleeping(body) {
            return;
        }
        let island = self
            .island_of
            .get(body.index as usize)
            .copied()
            .unwrap_or(u32::MAX);
        if island == u32::MAX {
            bodies.wake(body);
            contacts.wake_body(body);
            return;
        }
        let members = std::mem::take(&mut self.islands[island as usize]);
        for m in &members {
            bodies.wake(*m);
            if let Some(slot) = self.island_of.get_mut(m.index as usize) {
                *slot = u32::MAX;
            }
        }
        for m in &members {
            contacts.wake_body(*m);
        }
        self.free.push(island);
    }

    /// Updates sleep timers and puts resting islands to sleep.
    pub(crate) fn update(
        &mut self,
        input: &SleepInput<'_>,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
        joint_edges: impl Iterator<Item = (BodyHandle, BodyHandle)>,
    ) {
        let settings = input.settings;
        let tol2 = settings.linear_threshold * settings.linear_threshold;
        let n = bodies.sims.len();
        if n <= 1 {
            return; // nothing awake
        }
        // Timers (slot 0 is the static sentinel).
        for i in 1..n {
            let (handle, center) = (bodies.sims[i].handle, bodies.sims[i].center);
            let reach = input.shapes.reach(handle, center);
            let st = bodies.states[i];
            let sim = &mut bodies.sims[i];
            let slow = st.v.length_squared() <= tol2 && st.w * st.w * reach * reach <= tol2;
            if sim.body_type == BodyType::Dynamic && slow {
                sim.sleep_time += input.dt;
            } else {
                sim.sleep_time = 0.0;
            }
        }
        for &b in input.keep_awake {
            if let Some(i) = dynamic_index(bodies, b) {
                bodies.sims[i as usize].sleep_time = 0.0;
            }
        }
        // Union–find over awake dynamic bodies (state indices).
        let mut parent = std::mem::take(&mut self.parent);
        parent.clear();
        parent.extend(0..n as u32);
        let contact_edges = contacts
            .awake()
            .iter()
            .filter(|c| c.is_solid_touching())
            .map(|c| (c.body_a, c.body_b));
        for (a, b) in joint_edges.chain(contact_edges) {
            if let (Some(ia), Some(ib)) = (dynamic_index(bodies, a), dynamic_index(bodies, b)) {
                union(&mut parent, ia, ib);
            }
        }
        // Kinematic bodies and anything not dynamic never sleep; an island
        // touching a moving kinematic body stays awake through its speed.
        let mut min_time = std::mem::take(&mut self.min_time);
        min_time.clear();
        min_time.resize(n, Real::MAX);
        for i in 1..n {
            let r = find(&mut parent, i as u32) as usize;
            let sim = &bodies.sims[i];
            let t = if sim.body_type == BodyType::Dynamic {
                sim.sleep_time
            } else {
                0.0
            };
            min_time[r] = min_time[r].min(t);
        }
        let mut groups = std::mem::take(&mut self.groups);
        groups.clear();
        for i in 1..n {
            let r = find(&mut parent, i as u32);
            let sim = &bodies.sims[i];
            if sim.body_type == BodyType::Dynamic && min_time[r as usize] >= settings.time_to_sleep
            {
                groups.push((r, sim.handle));
            }
        }
        groups.sort();
        let mut k = 0;
        while k < groups.len() {
            let root = groups[k].0;
            let mut members = Vec::new();
            while k < groups.len() && groups[k].0 == root {
                members.push(groups[k].1);
                k += 1;
            }
            self.sleep_island(members, bodies, contacts);
        }
        self.parent = parent;
        self.min_time = min_time;
        self.groups = groups;
    }

    fn sleep_island(
        &mut self,
        members: Vec<BodyHandle>,
        bodies: &mut BodySet,
        contacts: &mut ContactSet,
    ) {
        let id = match self.free.pop() {
            Some(id) => id,
            None => {
                self.islands.push(Vec::new());
                (self.islands.len() - 1) as u32
            }
        };
        for m in &members {
            bodies.sleep(*m);
            let idx = m.index as usize;
            if self.island_of.len() <= idx {
                self.island_of.resize(idx + 1, u32::MAX);
            }
            self.island_of[idx] = id;
        }
        for m in &members {
            contacts.sleep_body(*m, bodies);
        }
        self.islands[id as usize] = members;
    }

    /// Forgets a body that is being destroyed (it must be awake).
    pub(crate) fn forget(&mut self, body: BodyHandle) {
        self.pending.retain(|b| *b != body);
        if let Some(slot) = self.island_of.get_mut(body.index as usize) {
            *slot = u32::MAX;
        }
    }
}

/// The state index of an awake dynamic body.
fn dynamic_index(bodies: &BodySet, b: BodyHandle) -> Option<u32> {
    let i = bodies.state_index(b)?;
    (i != 0 && bodies.sims[i as usize].body_type == BodyType::Dynamic).then_some(i)
}
