//! Events and hooks: what the last step reported, its profile and
//! counters, and the pre-solve hook.

use super::*;

impl World {
    /// Events of the last step.
    pub fn events(&self) -> &StepEvents {
        &self.events
    }

    /// Stage timings of the solver in the last step.
    pub fn solver_profile(&self) -> &SolverProfile {
        &self.step_profile.solver
    }

    /// Stage timings of the last step (every pipeline stage).
    pub fn profile(&self) -> &crate::profile::StepProfile {
        &self.step_profile
    }

    /// Work counters of the last step.
    pub fn counters(&self) -> crate::profile::StepCounters {
        self.counters
    }

    /// Sets (or with `None` removes) the pre-solve hook: called after the
    /// narrowphase for every touching solid contact, in contact order; a
    /// `false` leaves that contact out of this step's solve (one-way
    /// platforms, conveyor rules). Without a hook the step makes no call.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// // Contacts whose normal points down (from a to b) are ignored.
    /// world.set_pre_solve(Some(Box::new(|c| c.normal.y >= 0.0)));
    /// world.step(1.0 / 60.0).unwrap();
    /// ```
    pub fn set_pre_solve(&mut self, hook: Option<crate::narrowphase::PreSolveFn>) {
        self.pre_solve = hook;
    }

    /// Takes the pre-solve hook out (restore keeps it across).
    pub(crate) fn take_pre_solve(&mut self) -> Option<crate::narrowphase::PreSolveFn> {
        self.pre_solve.take()
    }
}
