//! Sleeping: islands of bodies at rest leave the solver and cost nothing.
//!
//! ```text
//! after each step (when sleep is enabled):
//!   timers   every awake dynamic body: slow (|v| and |ω|·reach below the
//!            threshold) → sleep_time += dt, else 0
//!   islands  union–find over awake dynamic bodies joined by touching solid
//!            contacts, enabled joints and portal crossings
//!   sleep    an island whose every member has slept long enough leaves the
//!            solver arrays (BodySet::sleep); its contacts are skipped by
//!            the narrowphase and the solver
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

use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::math::Real;
use janus2d_core::union_find::{find, union};

use crate::world::World;

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

/// Sleeping islands and the union–find scratch space.
#[derive(Clone, Debug, Default)]
pub(crate) struct Islands {
    /// Island id of each body slot (`u32::MAX`: awake or never slept).
    island_of: Vec<u32>,
    /// Members of each sleeping island (empty: free slot).
    islands: Vec<Vec<BodyHandle>>,
    free: Vec<u32>,
    parent: Vec<u32>,
    min_time: Vec<Real>,
}

impl World {
    /// Wakes the island of `body` (no effect on awake or static bodies).
    pub fn wake_body(&mut self, body: BodyHandle) {
        if !self.pending_sleep_is_empty() {
            self.cancel_pending_sleep(body);
        }
        if !self.bodies().is_sleeping(body) {
            return;
        }
        let idx = body.index as usize;
        let island = self.islands.island_of.get(idx).copied().unwrap_or(u32::MAX);
        if island == u32::MAX {
            self.bodies_mut().wake(body);
            return;
        }
        let members = std::mem::take(&mut self.islands.islands[island as usize]);
        for m in &members {
            self.bodies_mut().wake(*m);
            if let Some(slot) = self.islands.island_of.get_mut(m.index as usize) {
                *slot = u32::MAX;
            }
        }
        self.islands.free.push(island);
    }

    /// True when the body sleeps.
    pub fn is_sleeping(&self, body: BodyHandle) -> bool {
        self.bodies().is_sleeping(body)
    }

    /// Number of sleeping bodies.
    pub fn sleeping_body_count(&self) -> usize {
        self.bodies().sleeping_count()
    }

    /// Number of awake dynamic and kinematic bodies.
    pub fn awake_body_count(&self) -> usize {
        self.bodies().moving_count()
    }

    /// Wakes every island in the list (collected by the narrowphase).
    pub(crate) fn wake_all(&mut self, bodies: &[BodyHandle]) {
        for b in bodies {
            self.wake_body(*b);
        }
    }

    /// Updates sleep timers and puts resting islands to sleep.
    pub(crate) fn update_sleep(&mut self, dt: Real) {
        let settings = self.sleep_settings;
        let tol2 = settings.linear_threshold * settings.linear_threshold;
        let n = self.bodies().sims.len();
        if n <= 1 {
            return; // nothing awake
        }
        // Timers (slot 0 is the static sentinel).
        for i in 1..n {
            let (handle, reach) = {
                let sim = &self.bodies().sims[i];
                (sim.handle, self.body_reach(sim.handle))
            };
            let st = self.bodies().states[i];
            let sim = &mut self.bodies_mut().sims[i];
            let slow = st.v.length_squared() <= tol2 && st.w * st.w * reach * reach <= tol2;
            if sim.body_type == BodyType::Dynamic && slow {
                sim.sleep_time += dt;
            } else {
                sim.sleep_time = 0.0;
            }
            let _ = handle;
        }
        // Union–find over awake bodies (state indices).
        let mut parent = std::mem::take(&mut self.islands.parent);
        parent.clear();
        parent.extend(0..n as u32);
        let index = |w: &World, b: BodyHandle| -> Option<u32> {
            let i = w.bodies().state_index(b)?;
            (i != 0 && w.bodies().sims[i as usize].body_type == BodyType::Dynamic).then_some(i)
        };
        for (a, b) in self.constraint_edges() {
            if let (Some(ia), Some(ib)) = (index(self, a), index(self, b)) {
                union(&mut parent, ia, ib);
            }
        }
        // A crossing keeps the object and its portal bodies awake.
        #[cfg(feature = "portals")]
        for k in 0..self.portals.crossings.len() {
            let c = &self.portals.crossings[k];
            let (entry, exit) = self.crossing_portal_bodies(c);
            for b in [c.original, c.clone, entry, exit] {
                if let Some(i) = index(self, b) {
                    self.bodies_mut().sims[i as usize].sleep_time = 0.0;
                }
            }
        }
        // Kinematic bodies and anything not dynamic never sleep; an island
        // touching a moving kinematic body stays awake through its speed.
        let mut min_time = std::mem::take(&mut self.islands.min_time);
        min_time.clear();
        min_time.resize(n, Real::MAX);
        for i in 1..n {
            let r = find(&mut parent, i as u32) as usize;
            let sim = &self.bodies().sims[i];
            let t = if sim.body_type == BodyType::Dynamic {
                sim.sleep_time
            } else {
                0.0
            };
            min_time[r] = min_time[r].min(t);
        }
        let mut groups: Vec<(u32, BodyHandle)> = Vec::new();
        for i in 1..n {
            let r = find(&mut parent, i as u32);
            let sim = &self.bodies().sims[i];
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
            self.sleep_island(members);
        }
        self.islands.parent = parent;
        self.islands.min_time = min_time;
    }

    fn sleep_island(&mut self, members: Vec<BodyHandle>) {
        let id = match self.islands.free.pop() {
            Some(id) => id,
            None => {
                self.islands.islands.push(Vec::new());
                (self.islands.islands.len() - 1) as u32
            }
        };
        for m in &members {
            self.bodies_mut().sleep(*m);
            let idx = m.index as usize;
            if self.islands.island_of.len() <= idx {
                self.islands.island_of.resize(idx + 1, u32::MAX);
            }
            self.islands.island_of[idx] = id;
        }
        self.islands.islands[id as usize] = members;
    }
}
