//! Events and hooks: what the last step reported, its profile and
//! counters, and the callbacks (pre-solve hook, pair filter, friction and
//! restitution callbacks; see `crate::hooks`).

use super::*;

/// A body that moved in the last step (Box2D's `b2BodyMoveEvent`): see
/// [`WorldDef::enable_move_events`] and [`StepEvents::moves`].
///
/// ```
/// use janus2d_world::{World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// let mut world = World::new(WorldDef::default().with_move_events(true)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_user_data(7)).unwrap();
/// world.step(1.0 / 60.0).unwrap();
/// let m = world.events().moves[0];
/// assert_eq!((m.body, m.user_data, m.fell_asleep), (b, 7, false));
/// assert!(m.transform.p.y < 0.0, "it fell");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyMoveEvent {
    /// The body.
    pub body: BodyHandle,
    /// Its transform after the step.
    pub transform: Transform,
    /// Its user value (`BodyDef::user_data`).
    pub user_data: u64,
    /// True when it fell asleep at the end of this step (reported once:
    /// a sleeping body does not move, so the next steps list it no more).
    pub fell_asleep: bool,
}

impl World {
    /// Every event of the last step (see [`StepEvents`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.events().collision.contact_begin.is_empty());
    /// ```
    pub fn events(&self) -> &StepEvents {
        &self.events
    }

    /// The move events of the step just solved: every awake dynamic or
    /// kinematic body that reports them, in body slot order (their
    /// `fell_asleep` is set after the sleep stage).
    pub(super) fn gather_moves(&self) -> Vec<BodyMoveEvent> {
        let mut out: Vec<BodyMoveEvent> = self
            .bodies
            .sims
            .iter()
            .skip(1)
            .filter_map(|sim| {
                let record = self.bodies.record(sim.handle)?;
                record.enable_move_events.then_some(BodyMoveEvent {
                    body: sim.handle,
                    transform: sim.transform,
                    user_data: record.user_data,
                    fell_asleep: false,
                })
            })
            .collect();
        out.sort_unstable_by_key(|m| m.body.index);
        out
    }

    /// Whether the world gathers body move events
    /// ([`WorldDef::enable_move_events`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// assert!(!World::new(WorldDef::default()).unwrap().move_events_enabled());
    /// assert!(World::new(WorldDef::default().with_move_events(true)).unwrap().move_events_enabled());
    /// ```
    pub fn move_events_enabled(&self) -> bool {
        self.move_events
    }

    /// Turns the gathering of body move events on or off (see
    /// [`WorldDef::enable_move_events`]); from the next step.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let a = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// world.set_move_events(true);
    /// world.set_body_move_events(a, false).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// let moved: Vec<_> = world.events().moves.iter().map(|m| m.body).collect();
    /// assert_eq!(moved, vec![b]);
    /// assert!(world.move_events_enabled() && !world.body_move_events(a).unwrap());
    /// ```
    pub fn set_move_events(&mut self, on: bool) {
        self.move_events = on;
    }

    /// Whether the body reports move events (`BodyDef::enable_move_events`).
    /// Errors: a stale handle.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let quiet = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_move_events(false)).unwrap();
    /// assert_eq!(world.body_move_events(quiet), Ok(false));
    /// world.set_body_move_events(quiet, true).unwrap();
    /// assert_eq!(world.body_move_events(quiet), Ok(true));
    /// ```
    pub fn body_move_events(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.check_body(body)?;
        Ok(self
            .bodies
            .record(body)
            .is_some_and(|r| r.enable_move_events))
    }

    /// Turns the body's move events on or off (`BodyDef::enable_move_events`;
    /// example at [`World::set_move_events`]). Errors: a stale handle.
    pub fn set_body_move_events(&mut self, body: BodyHandle, on: bool) -> Result<(), WorldError> {
        self.check_body(body)?;
        if let Some(r) = self.bodies.record_mut(body) {
            r.enable_move_events = on;
        }
        Ok(())
    }

    /// Turns the shape's contact begin/end events on or off
    /// ([`ShapeDef::enable_contact_events`]); its existing contacts
    /// follow for their next change. Errors: a stale handle.
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.set_shape_contact_events(s, false).unwrap();
    /// world.set_shape_sensor_events(s, false).unwrap();
    /// world.set_shape_hit_events(s, true).unwrap();
    /// world.set_shape_force_event_threshold(s, 100.0).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.events().collision.contact_begin.is_empty());
    /// let def = &world.shape(s).unwrap().def;
    /// assert!(!def.enable_contact_events && def.enable_hit_events);
    /// assert_eq!(def.force_event_threshold, 100.0);
    /// ```
    pub fn set_shape_contact_events(
        &mut self,
        shape: ShapeHandle,
        on: bool,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.at_mut(slot).def.enable_contact_events = on;
        self.refresh_event_flags(slot);
        Ok(())
    }

    /// Turns the shape's sensor events on or off
    /// ([`ShapeDef::enable_sensor_events`]; example at
    /// [`World::set_shape_contact_events`]). Errors: a stale handle.
    pub fn set_shape_sensor_events(
        &mut self,
        shape: ShapeHandle,
        on: bool,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.at_mut(slot).def.enable_sensor_events = on;
        self.refresh_event_flags(slot);
        Ok(())
    }

    /// Turns the shape's hit events on or off
    /// ([`ShapeDef::enable_hit_events`]; example at
    /// [`World::set_shape_contact_events`]). Errors: a stale handle.
    pub fn set_shape_hit_events(&mut self, shape: ShapeHandle, on: bool) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.set_hit_events(slot, on);
        self.collision.update_contacts_of_shape(slot, |a, b, c| {
            c.hit_events = a.def.enable_hit_events || b.def.enable_hit_events;
        });
        Ok(())
    }

    /// Sets the shape's contact force event threshold, N
    /// ([`ShapeDef::force_event_threshold`]; infinity turns them off;
    /// example at [`World::set_shape_contact_events`]). Errors: a stale
    /// handle, a NaN or negative threshold (the world unchanged).
    pub fn set_shape_force_event_threshold(
        &mut self,
        shape: ShapeHandle,
        force: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        crate::shapes::check_force_threshold(force)?;
        self.collision.shapes.set_force_event_threshold(slot, force);
        Ok(())
    }

    /// Recomputes the event switches of the shape's existing contacts.
    fn refresh_event_flags(&mut self, slot: u32) {
        self.collision.update_contacts_of_shape(slot, |a, b, c| {
            c.event_flags = crate::contacts::event_flags::of(&a.def, &b.def);
        });
    }

    /// Stage timings of the solver in the last step.
    pub fn solver_profile(&self) -> &SolverProfile {
        &self.step_profile.solver
    }

    /// Stage timings of the last step (every pipeline stage); all zero
    /// while the stage timers are off ([`World::set_profiling`]) but for
    /// the step's total.
    pub fn profile(&self) -> &crate::profile::StepProfile {
        &self.step_profile
    }

    /// Turns the stage timers on (the default) or off. Each timed stage
    /// reads the clock; in a world of a few bodies those reads were 7% of
    /// a step (the Python lander's profile), so a program stepping many
    /// small worlds may turn them off. The results do not depend on it.
    /// Not in a snapshot's bytes: a world read back from bytes times its
    /// stages.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// world.set_profiling(false);
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(!world.is_profiling());
    /// assert_eq!(world.profile().solver.solve, 0.0);
    /// ```
    pub fn set_profiling(&mut self, on: bool) {
        self.profiling_off = !on;
    }

    /// Whether the stage timers are on ([`World::set_profiling`]).
    #[must_use]
    pub fn is_profiling(&self) -> bool {
        !self.profiling_off
    }

    /// Work counters of the last step.
    pub fn counters(&self) -> crate::profile::StepCounters {
        self.counters
    }

    /// What the event gathering read in the last step (see
    /// [`EventWork`](crate::EventWork)): all 0 in a scene that asks for no
    /// hit, force or move events.
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let floor = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// let forces = ShapeDef::default().with_force_event_threshold(1.0);
    /// world.create_shape(b, &forces, Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// // One shape with a force threshold: the gathering reads the contact.
    /// assert_eq!(world.event_work().force_contacts_read, 1);
    /// assert_eq!(world.event_work().hit_points_read, 0);
    /// ```
    pub fn event_work(&self) -> crate::profile::EventWork {
        self.event_work
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
