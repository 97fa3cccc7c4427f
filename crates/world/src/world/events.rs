//! Events and hooks: what the last step reported, its profile and
//! counters, and the callbacks (pre-solve hook, pair filter, friction and
//! restitution callbacks; see `crate::hooks`).

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
    /// narrowphase for every touching solid contact, in contact order, on
    /// the stepping thread. Through its view ([`PreSolve`](crate::PreSolve))
    /// it may change the contact's friction, restitution, tangent speed
    /// and rolling resistance for this step (a conveyor, ice under one
    /// body); a `false` leaves the contact out of this step's solve
    /// (one-way platforms). Without a hook the step makes no call. Not
    /// state: snapshots and scene files do not hold it, and
    /// [`World::restore`] keeps the world's own.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// // Contacts whose normal points down (from a to b) are ignored, the
    /// // others slide without friction this step.
    /// world.set_pre_solve(Some(Box::new(|c| {
    ///     c.friction = 0.0;
    ///     c.normal.y >= 0.0
    /// })));
    /// world.step(1.0 / 60.0).unwrap();
    /// ```
    pub fn set_pre_solve(&mut self, hook: Option<crate::narrowphase::PreSolveFn>) {
        self.hooks.pre_solve = hook;
    }

    /// Sets (or with `None` removes) the custom pair filter (Box2D's
    /// `b2CustomFilterFcn`): asked with the two shapes whenever the
    /// broadphase finds a new pair that passed the shapes' category, mask
    /// and group filter; `false` makes no contact between them (no
    /// contact, no events, no push). It is asked in pair order, on the
    /// stepping thread. Contacts that exist when it is set are kept:
    /// call [`World::set_shape_filter`] (with the shape's own filter) to
    /// have a shape's pairs asked again. Not state: snapshots and scene
    /// files do not hold it.
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let floor = world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// let ghost = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// // The ghost passes through the floor.
    /// world.set_pair_filter(Some(Box::new(move |a, b| !(a == ghost || b == ghost))));
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// assert!(world.position(b).unwrap().y < -1.0);
    /// assert_eq!(world.shape_contacts(floor).unwrap().count(), 0);
    /// ```
    pub fn set_pair_filter(&mut self, filter: Option<crate::hooks::PairFilterFn>) {
        self.hooks.pair_filter = filter;
    }

    /// Sets (or with `None` removes) the friction callback (Box2D's
    /// `b2FrictionCallback`): a contact's friction is
    /// `callback(μ_a, material_a, μ_b, material_b)` instead of the shapes'
    /// combine rules (`ShapeDef::friction_combine`), with the shapes'
    /// user material ids (`ShapeDef::user_material_id`). Existing contacts
    /// are mixed again now. A result that is not finite falls back to the
    /// combine rules; it is clamped to
    /// `[0, MAX_FRICTION]`. Not state: snapshots and scene files do not
    /// hold it.
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// const ICE: u64 = 1;
    /// // Ice against anything: no friction; else the smaller value.
    /// world.set_friction_callback(Some(Box::new(|a, ma, b, mb| {
    ///     if ma == ICE || mb == ICE { 0.0 } else { a.min(b) }
    /// })));
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let ice = ShapeDef::default().with_material_id(ICE);
    /// world.create_shape(ground, &ice, Polygon::make_box(5.0, 0.5)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// let c = world.contacts().next().unwrap();
    /// assert_eq!(c.friction, 0.0);
    /// assert_eq!(c.user_material_ids, [ICE, 0]);
    /// ```
    pub fn set_friction_callback(&mut self, callback: Option<crate::hooks::MixFn>) {
        self.hooks.friction = callback;
        self.refresh_all_contact_materials();
    }

    /// Sets (or with `None` removes) the restitution callback (Box2D's
    /// `b2RestitutionCallback`), as [`World::set_friction_callback`] for
    /// restitution (clamped to `[0, MAX_RESTITUTION]`).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// world.set_restitution_callback(Some(Box::new(|a, _, b, _| 0.5 * (a + b))));
    /// world.set_restitution_callback(None);
    /// ```
    pub fn set_restitution_callback(&mut self, callback: Option<crate::hooks::MixFn>) {
        self.hooks.restitution = callback;
        self.refresh_all_contact_materials();
    }
}
