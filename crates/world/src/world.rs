//! The world: bodies, joints and the stepping loop.
//!
//! ```text
//! World::step(dt)
//!   ├─ validate dt; bodies created asleep go to sleep (islands)
//!   ├─ portal clipping (portal stage; a no-op without portal pairs)
//!   ├─ broadphase: new pairs ─ narrowphase ─ wake touched islands ─ contact constraints
//!   ├─ solve_step (janus2d-core): prepare ─ substeps ─ restitution ─ store ─ finalize
//!   ├─ store impulses  ∥  continuous (fast bodies swept, moved back to
//!   │                     their time of impact) ─ move proxies
//!   ├─ portal crossings (commands applied by the world)
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
    ContactSolver, Joint, JointDef, ObjectMass, RevoluteJoint, RevoluteJointDef,
};
use janus2d_core::BodyMass;
use janus2d_core::body::{BodyDef, BodyHandle, BodyLocation, BodySet, BodyType, validate_mass};
use janus2d_core::constraint::{ConstraintBatch, StepContext};
use janus2d_core::geometry::Shape;
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, vec_is_finite};
use janus2d_core::solver::{SolverProfile, SolverSettings, solve_step};

use crate::collision::{Collision, CollisionCounters, CollisionEvents};
use crate::contacts::Contact;
use crate::error::WorldError;
use crate::islands::{Islands, SleepInput, SleepSettings};
use crate::joints::{JointHandle, JointSet};
use crate::portal::PortalStage;
use crate::shapes::{ShapeData, ShapeDef, ShapeHandle};

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
    /// [`crate::continuous`]).
    pub enable_continuous: bool,
    /// Approach speed above which a contact of a shape with hit events on
    /// reports a [`HitEvent`](crate::contacts::HitEvent), m/s (usual 1, as
    /// Box2D's `hitEventThreshold`).
    pub hit_event_threshold: Real,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: DEFAULT_GRAVITY,
            solver: SolverSettings::default(),
            sleep: SleepSettings::default(),
            enable_continuous: true,
            hit_event_threshold: 1.0,
        }
    }
}

/// Events of the last step, read after `step`.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StepEvents {
    /// Bodies whose state went non-finite during the step. Each was put back
    /// at its start-of-step pose, at rest, instead of spreading NaN.
    pub non_finite_bodies: Vec<BodyHandle>,
    /// Contact and sensor begin/end events.
    pub collision: CollisionEvents,
}

/// The simulation world: it owns one value of each stage and calls them
/// in order, passing each what it reads.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct World {
    gravity: Vec2,
    #[cfg_attr(feature = "serde", serde(with = "crate::snapshot::SettingsDef"))]
    settings: SolverSettings,
    pub(crate) bodies: BodySet,
    pub(crate) joints: JointSet,
    pub(crate) collision: Collision,
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
    /// The user's pre-solve hook, if any (called per touching contact).
    #[cfg_attr(feature = "serde", serde(skip))]
    pre_solve: Option<crate::narrowphase::PreSolveFn>,
    pub(crate) sleep_settings: SleepSettings,
    wake_list: Vec<BodyHandle>,
    events: StepEvents,
    /// Timings of the last step (not state: not serialized).
    #[cfg_attr(feature = "serde", serde(skip))]
    step_profile: crate::profile::StepProfile,
    counters: crate::profile::StepCounters,
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
            contact_solver: ContactSolver::new(),
            object_masses: Vec::new(),
            portals: PortalStage::default(),
            islands: Islands::default(),
            continuous: crate::continuous::ContinuousStage::new(def.enable_continuous),
            hit_event_threshold: def.hit_event_threshold,
            pre_solve: None,
            sleep_settings: def.sleep,
            wake_list: Vec::new(),
            joints: JointSet::new(bodies.owner()),
            bodies,
            events: StepEvents::default(),
            step_profile: crate::profile::StepProfile::default(),
            counters: crate::profile::StepCounters::default(),
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

    // ----- bodies -----------------------------------------------------------

    /// Creates a body.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0)).with_mass(1.0, 0.1)).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.position(ball).unwrap().y < 4.0);
    /// ```
    ///
    /// A kinematic body given a velocity is created awake even with
    /// `awake: false` (a sleeping kinematic body would never move).
    pub fn create_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        let handle = self.insert_body(def)?;
        let moving_kinematic = def.body_type == BodyType::Kinematic
            && (def.linear_velocity != Vec2::ZERO || def.angular_velocity != 0.0);
        if !def.awake && def.body_type != BodyType::Static && !moving_kinematic {
            self.islands.push_pending(handle);
        }
        Ok(handle)
    }

    /// Destroys a body, its shapes (their contacts end, with end events)
    /// and every joint attached to it; the bodies it touched wake up.
    ///
    /// Walks the body's own contacts and joints, never the whole world.
    /// Destroying a portal clone cancels its crossing (which destroys the
    /// clone; the original stays).
    pub fn destroy_body(&mut self, body: BodyHandle) -> Result<(), WorldError> {
        self.check_body(body)?;
        self.portal_forget_body(body);
        // A clone is already gone with its cancelled crossing.
        if self.bodies.contains(body) {
            self.destroy_body_unchecked(body);
        }
        Ok(())
    }

    /// Wakes every body that has a contact with `body` (its own list).
    pub(crate) fn wake_touching(&mut self, body: BodyHandle) {
        let touching: smallvec::SmallVec<[BodyHandle; 8]> = self
            .collision
            .contacts
            .of_body(body)
            .iter()
            .filter_map(|&id| self.collision.contacts.get(id))
            .map(|c| c.other(body))
            .collect();
        self.wake_all(&touching);
    }

    /// Destroys a live body (checked by the caller, crossings already
    /// ended).
    pub(crate) fn destroy_body_unchecked(&mut self, body: BodyHandle) {
        self.wake_touching(body);
        self.wake_body(body);
        let attached: smallvec::SmallVec<[JointHandle; 4]> =
            self.joints.of_body(body).iter().copied().collect();
        for h in attached {
            self.remove_joint(h);
        }
        let shapes: smallvec::SmallVec<[u32; 4]> = self
            .collision
            .shapes
            .of_body(body)
            .iter()
            .copied()
            .collect();
        for s in shapes {
            self.collision.remove_shape(s);
        }
        self.islands.remove_body(body);
        let destroyed = self.bodies.destroy(body);
        debug_assert!(destroyed.is_ok(), "checked by the caller");
    }

    /// `StaleBody`, or `ForeignHandle` for another world's handle.
    pub(crate) fn body_error(&self, body: BodyHandle) -> WorldError {
        self.check_body(body).err().unwrap_or(WorldError::StaleBody)
    }

    /// A live body that is kinematic or dynamic (`NotMovable` otherwise).
    fn check_movable(&self, body: BodyHandle) -> Result<(), WorldError> {
        match self.body_type(body)? {
            BodyType::Static => Err(WorldError::NotMovable),
            _ => Ok(()),
        }
    }

    /// A live dynamic body (`NotDynamic` otherwise).
    fn check_dynamic(&self, body: BodyHandle) -> Result<(), WorldError> {
        match self.body_type(body)? {
            BodyType::Dynamic => Ok(()),
            _ => Err(WorldError::NotDynamic),
        }
    }

    pub(crate) fn check_body(&self, body: BodyHandle) -> Result<(), WorldError> {
        self.bodies
            .check(body)
            .map(|_| ())
            .map_err(|e| WorldError::of_handle(e, WorldError::StaleBody))
    }

    /// Body origin and rotation.
    pub fn transform(&self, body: BodyHandle) -> Result<Transform, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.transform)
            .ok_or_else(|| self.body_error(body))
    }

    /// Body origin, m.
    pub fn position(&self, body: BodyHandle) -> Result<Vec2, WorldError> {
        self.transform(body).map(|t| t.p)
    }

    /// Body angle, rad, in `[-π, π]`.
    pub fn angle(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.transform(body).map(|t| t.q.angle())
    }

    /// World centre of mass, m.
    pub fn center_of_mass(&self, body: BodyHandle) -> Result<Vec2, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.center)
            .ok_or_else(|| self.body_error(body))
    }

    /// Linear velocity of the centre of mass, m/s.
    pub fn linear_velocity(&self, body: BodyHandle) -> Result<Vec2, WorldError> {
        self.bodies
            .linear_velocity(body)
            .ok_or_else(|| self.body_error(body))
    }

    /// Angular velocity, rad/s.
    pub fn angular_velocity(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .angular_velocity(body)
            .ok_or_else(|| self.body_error(body))
    }

    /// Mass, kg (0 for static and kinematic bodies).
    pub fn mass(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.mass)
            .ok_or_else(|| self.body_error(body))
    }

    /// Rotational inertia about the centre of mass, kg·m².
    pub fn rotational_inertia(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.inertia)
            .ok_or_else(|| self.body_error(body))
    }

    /// Body type.
    pub fn body_type(&self, body: BodyHandle) -> Result<BodyType, WorldError> {
        self.bodies
            .body_type(body)
            .ok_or_else(|| self.body_error(body))
    }

    /// Sets the linear velocity of a moving body's centre of mass.
    /// Errors: non-finite, or faster than
    /// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED); a static body
    /// ([`WorldError::NotMovable`]).
    pub fn set_linear_velocity(&mut self, body: BodyHandle, v: Vec2) -> Result<(), WorldError> {
        janus2d_core::body::check_velocity(v, "linear_velocity")?;
        self.check_movable(body)?;
        self.wake_body(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
        }
        Ok(())
    }

    /// Sets the angular velocity of a moving body. Errors: non-finite, or
    /// above [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED);
    /// a static body ([`WorldError::NotMovable`]).
    pub fn set_angular_velocity(&mut self, body: BodyHandle, w: Real) -> Result<(), WorldError> {
        janus2d_core::body::check_angular_velocity(w, "angular_velocity")?;
        self.check_movable(body)?;
        self.wake_body(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.w = w;
        }
        Ok(())
    }

    /// Moves a body (teleport): origin and angle.
    pub fn set_transform(
        &mut self,
        body: BodyHandle,
        position: Vec2,
        angle: Real,
    ) -> Result<(), WorldError> {
        if !vec_is_finite(position) || !angle.is_finite() {
            return Err(WorldError::NonFinite("transform"));
        }
        janus2d_core::body::check_position(position, "transform")?;
        self.check_body(body)?;
        self.wake_body(body);
        let sim = self.bodies.sim_mut(body).ok_or(WorldError::StaleBody)?;
        sim.transform = Transform {
            p: position,
            q: Rot::from_angle(angle),
        };
        sim.center = sim.transform.apply(sim.local_center);
        sim.center0 = sim.center;
        sim.rotation0 = sim.transform.q;
        let xf = sim.transform;
        self.collision.refresh_body(body, &xf);
        Ok(())
    }

    /// Sets the mass properties of a dynamic body directly. The mass stays
    /// set when shapes are added, removed or changed, until
    /// [`reset_mass_from_shapes`](Self::reset_mass_from_shapes).
    pub fn set_mass(&mut self, body: BodyHandle, mass: BodyMass) -> Result<(), WorldError> {
        let ty = self.body_type(body)?;
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        validate_mass(ty, &mass, fixed)?;
        if ty != BodyType::Dynamic {
            return Err(WorldError::NotDynamic);
        }
        self.wake_body(body);
        self.bodies.apply_mass(body, mass, fixed);
        if let Some(r) = self.bodies.record_mut(body) {
            r.mass_override = true;
        }
        Ok(())
    }

    /// Adds a force (N) at a world point for the next step.
    pub fn apply_force(
        &mut self,
        body: BodyHandle,
        force: Vec2,
        point: Vec2,
    ) -> Result<(), WorldError> {
        if !vec_is_finite(force) || !vec_is_finite(point) {
            return Err(WorldError::NonFinite("force"));
        }
        self.check_dynamic(body)?;
        let sim = self.bodies.sim(body).ok_or(WorldError::StaleBody)?;
        let (f, t) = (
            sim.force + force,
            sim.torque + cross(point - sim.center, force),
        );
        if !(vec_is_finite(f) && t.is_finite()) {
            return Err(accumulated("force"));
        }
        self.wake_body(body);
        let sim = self.bodies.sim_mut(body).ok_or(WorldError::StaleBody)?;
        sim.force = f;
        sim.torque = t;
        Ok(())
    }

    /// Adds a force (N) at the centre of mass for the next step.
    pub fn apply_force_to_center(
        &mut self,
        body: BodyHandle,
        force: Vec2,
    ) -> Result<(), WorldError> {
        let c = self.center_of_mass(body)?;
        self.apply_force(body, force, c)
    }

    /// Adds a torque (N·m) for the next step.
    pub fn apply_torque(&mut self, body: BodyHandle, torque: Real) -> Result<(), WorldError> {
        if !torque.is_finite() {
            return Err(WorldError::NonFinite("torque"));
        }
        self.check_dynamic(body)?;
        let sim = self.bodies.sim(body).ok_or(WorldError::StaleBody)?;
        if !(sim.torque + torque).is_finite() {
            return Err(accumulated("torque"));
        }
        self.wake_body(body);
        let sim = self.bodies.sim_mut(body).ok_or(WorldError::StaleBody)?;
        sim.torque += torque;
        Ok(())
    }

    /// Applies a linear impulse (N·s) at a world point, changing velocity now.
    pub fn apply_linear_impulse(
        &mut self,
        body: BodyHandle,
        impulse: Vec2,
        point: Vec2,
    ) -> Result<(), WorldError> {
        if !vec_is_finite(impulse) || !vec_is_finite(point) {
            return Err(WorldError::NonFinite("impulse"));
        }
        self.check_dynamic(body)?;
        let sim = self.bodies.sim(body).ok_or(WorldError::StaleBody)?;
        let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
        let (v0, w0) = (self.linear_velocity(body)?, self.angular_velocity(body)?);
        let v = v0 + im * impulse;
        let w = w0 + ii * cross(point - c, impulse);
        check_resulting_velocity(v, w)?;
        self.wake_body(body);
        if let Some(st) = self.bodies.state_mut(body) {
            st.v = v;
            st.w = w;
        }
        Ok(())
    }

    /// Applies an angular impulse (N·m·s), changing angular velocity now.
    pub fn apply_angular_impulse(
        &mut self,
        body: BodyHandle,
        impulse: Real,
    ) -> Result<(), WorldError> {
        if !impulse.is_finite() {
            return Err(WorldError::NonFinite("impulse"));
        }
        self.check_dynamic(body)?;
        let ii = self
            .bodies
            .sim(body)
            .ok_or(WorldError::StaleBody)?
            .inv_inertia;
        let v = self.linear_velocity(body)?;
        let w = self.angular_velocity(body)? + ii * impulse;
        check_resulting_velocity(v, w)?;
        self.wake_body(body);
        if let Some(st) = self.bodies.state_mut(body) {
            st.w = w;
        }
        Ok(())
    }

    // ----- joints -----------------------------------------------------------

    /// Creates a joint of any kind. Its bodies and `collide_connected` are
    /// fixed for its life; with `collide_connected = false` the contacts
    /// between its bodies end (walking one body's contacts). A bad
    /// definition or a stale body gets a typed error and changes nothing.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_constraints::RevoluteJointDef;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let bob = world.create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
    /// let def = RevoluteJointDef::new(ground, bob, Vec2::ZERO, Vec2::new(-1.0, 0.0));
    /// let pin = world.create_joint(&def.into()).unwrap();
    /// assert!(world.revolute_joint(pin).is_ok());
    /// ```
    pub fn create_joint(&mut self, def: &JointDef) -> Result<JointHandle, WorldError> {
        def.validate()?;
        crate::joints::check_joint_limits(def)?;
        let (a, b) = def.bodies();
        self.check_body(a)?;
        self.check_body(b)?;
        self.wake_body(a);
        self.wake_body(b);
        let handle = self.joints.insert(def);
        self.islands.link(a, b, &self.bodies);
        if !def.collide_connected() {
            self.collision.remove_contacts_between(a, b);
        }
        Ok(handle)
    }

    /// Creates a revolute joint ([`World::create_joint`] with
    /// [`JointDef::Revolute`]).
    pub fn create_revolute_joint(
        &mut self,
        def: &RevoluteJointDef,
    ) -> Result<JointHandle, WorldError> {
        self.create_joint(&JointDef::Revolute(def.clone()))
    }

    /// Removes a live joint, waking its bodies.
    fn remove_joint(&mut self, joint: JointHandle) {
        if let Ok((a, b, freed)) = self.joints.remove(joint) {
            if freed {
                // Their proxies may not move again for a long time: the
                // broadphase looks for their pairs at the next step.
                self.collision.refind_pairs_of(a);
                self.collision.refind_pairs_of(b);
            }
            self.wake_body(a);
            self.wake_body(b);
            self.islands.note_removed(a);
        }
    }

    /// Destroys a joint.
    pub fn destroy_joint(&mut self, joint: JointHandle) -> Result<(), WorldError> {
        self.joints.kind(joint)?;
        self.remove_joint(joint);
        Ok(())
    }

    /// A joint of any kind.
    pub fn joint(&self, joint: JointHandle) -> Result<&Joint, WorldError> {
        self.joints.get(joint)
    }

    /// A revolute joint (`Err(WrongJointKind)` for another kind).
    pub fn revolute_joint(&self, joint: JointHandle) -> Result<&RevoluteJoint, WorldError> {
        self.joints.revolute(joint)
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

    /// Every field copied but the pre-solve hook (a snapshot's world).
    pub(crate) fn copy_state(&self) -> World {
        World {
            gravity: self.gravity,
            settings: self.settings.clone(),
            bodies: self.bodies.clone(),
            joints: self.joints.clone(),
            collision: self.collision.clone(),
            contact_solver: self.contact_solver.clone(),
            object_masses: self.object_masses.clone(),
            portals: self.portals.clone(),
            islands: self.islands.clone(),
            continuous: self.continuous.clone(),
            hit_event_threshold: self.hit_event_threshold,
            pre_solve: None,
            sleep_settings: self.sleep_settings,
            wake_list: self.wake_list.clone(),
            events: self.events.clone(),
            step_profile: self.step_profile.clone(),
            counters: self.counters,
            step_count: self.step_count,
        }
    }

    /// Force the joint applied to its body b over the last solved step, N
    /// (body a got the opposite); kept while its bodies sleep.
    pub fn joint_force(&self, joint: JointHandle) -> Result<Vec2, WorldError> {
        Ok(self.joints.get(joint)?.constraint_force())
    }

    /// Torque about the joint axis (springs, motors, limits) applied to
    /// body b over the last solved step, N·m; kept while its bodies sleep.
    pub fn joint_torque(&self, joint: JointHandle) -> Result<Real, WorldError> {
        Ok(self.joints.get(joint)?.constraint_torque())
    }

    /// The joints (read access: handles, per-body lists, kinds).
    pub fn joints(&self) -> &JointSet {
        &self.joints
    }

    fn wake_pair(
        &mut self,
        bodies: Result<(BodyHandle, BodyHandle), WorldError>,
    ) -> Result<(), WorldError> {
        let (a, b) = bodies?;
        self.wake_body(a);
        self.wake_body(b);
        Ok(())
    }

    /// Sets a joint's angle limits, rad (`lower ≤ upper`); wakes its bodies.
    pub fn set_joint_limits(
        &mut self,
        joint: JointHandle,
        lower: Real,
        upper: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_limits(joint, lower, upper);
        self.wake_pair(r)
    }

    /// Turns a joint's limit on or off.
    pub fn enable_joint_limit(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_limit(joint, on);
        self.wake_pair(r)
    }

    /// Sets a joint's motor speed, rad/s.
    pub fn set_joint_motor_speed(
        &mut self,
        joint: JointHandle,
        speed: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_motor_speed(joint, speed);
        self.wake_pair(r)
    }

    /// Sets a joint's largest motor torque, N·m (≥ 0).
    pub fn set_joint_max_motor_torque(
        &mut self,
        joint: JointHandle,
        torque: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_max_motor_torque(joint, torque);
        self.wake_pair(r)
    }

    /// Turns a joint's motor on or off.
    pub fn enable_joint_motor(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_motor(joint, on);
        self.wake_pair(r)
    }

    /// Sets a joint's spring: stiffness, Hz, and damping ratio (both ≥ 0).
    pub fn set_joint_spring(
        &mut self,
        joint: JointHandle,
        hertz: Real,
        damping_ratio: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_spring(joint, hertz, damping_ratio);
        self.wake_pair(r)
    }

    /// Turns a joint's spring on or off.
    pub fn enable_joint_spring(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_spring(joint, on);
        self.wake_pair(r)
    }

    /// Enables or disables a joint (one a portal disabled can be enabled
    /// again).
    pub fn set_joint_enabled(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let (a, b) = self.switch_joint(joint, on)?;
        self.wake_body(a);
        self.wake_body(b);
        Ok(())
    }

    /// Enables or disables a joint and tells the islands (linked when on,
    /// a removed link when off); wakes nothing.
    fn switch_joint(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        let (a, b) = self.joints.set_enabled(joint, on)?;
        if on {
            self.islands.link(a, b, &self.bodies);
        } else {
            self.islands.note_removed(a);
        }
        Ok((a, b))
    }

    /// Distance between a joint's two world anchors, m.
    pub fn joint_gap(&self, joint: JointHandle) -> Result<Real, WorldError> {
        Ok(self.joints.get(joint)?.gap(&self.bodies))
    }

    /// Handles of every joint, in storage order.
    pub fn joint_handles(&self) -> &[JointHandle] {
        self.joints.handles()
    }

    /// The largest joint gap in the world, m.
    pub fn max_joint_gap(&self) -> Real {
        self.joints
            .iter()
            .map(|(_, j)| j.gap(&self.bodies))
            .fold(0.0, Real::max)
    }

    // ----- shapes -----------------------------------------------------------

    /// Attaches a shape to a body. A dynamic body without directly set mass
    /// gets its mass, centre and inertia from its shapes.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// assert!((world.mass(b).unwrap() - 1.0).abs() < 1e-6);
    /// ```
    pub fn create_shape(
        &mut self,
        body: BodyHandle,
        def: &ShapeDef,
        geometry: impl Into<Shape>,
    ) -> Result<ShapeHandle, WorldError> {
        let geometry = geometry.into();
        self.check_body(body)?;
        let ty = self.bodies.body_type(body).unwrap_or(BodyType::Static);
        def.validate()?;
        geometry.validate()?;
        check_shape_mass(&geometry, def.density)?;
        let mass_override = self
            .bodies
            .record(body)
            .map(|r| r.mass_override)
            .unwrap_or(true);
        let has_area = geometry.area() > 0.0;
        if ty == BodyType::Dynamic
            && !mass_override
            && has_area
            && def.density <= 0.0
            && self.collision.shapes.mass_of(body).mass <= 0.0
        {
            return Err(WorldError::OutOfRange("density"));
        }
        // Wakes a sleeping island; a body created asleep stays pending.
        if self.bodies.is_sleeping(body) {
            self.wake_body(body);
        }
        let handle = self
            .collision
            .add_shape(&self.bodies, body, geometry, def.clone());
        if ty == BodyType::Dynamic && !mass_override {
            self.update_mass_from_shapes(body);
        }
        Ok(handle)
    }

    /// Removes a shape (its contacts end; the body's mass is recomputed).
    pub fn destroy_shape(&mut self, shape: ShapeHandle) -> Result<(), WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        let body = self.collision.shapes.at(slot).body;
        self.wake_body(body);
        self.collision.remove_shape(slot);
        let mass_override = self
            .bodies
            .record(body)
            .map(|r| r.mass_override)
            .unwrap_or(true);
        if self.bodies.body_type(body) == Some(BodyType::Dynamic) && !mass_override {
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    /// A shape: its body, geometry, material and box.
    pub fn shape(&self, shape: ShapeHandle) -> Result<&ShapeData, WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        Ok(self.collision.shapes.at(slot))
    }

    /// The shapes of a body, in creation order.
    pub fn body_shapes(&self, body: BodyHandle) -> Result<Vec<ShapeHandle>, WorldError> {
        self.check_body(body)?;
        let owner = self.bodies.owner();
        Ok(self
            .collision
            .shapes
            .of_body(body)
            .iter()
            .map(|&s| self.collision.shapes.handle_of(s, owner))
            .collect())
    }

    pub(crate) fn update_mass_from_shapes(&mut self, body: BodyHandle) {
        let md = self.collision.shapes.mass_of(body);
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        let mass = if md.mass > 0.0 {
            BodyMass {
                mass: md.mass,
                rotational_inertia: md.rotational_inertia,
                center: md.center,
            }
        } else {
            BodyMass::new(1.0, 1.0)
        };
        let inertia_ok = fixed || mass.rotational_inertia > 0.0;
        let mass = if inertia_ok {
            mass
        } else {
            BodyMass {
                rotational_inertia: mass.mass * 1e-3,
                ..mass
            }
        };
        // Mass from shapes is clamped into the stated ranges (a tiny
        // density must not give an infinite inverse mass).
        let mass = BodyMass {
            mass: janus2d_core::limits::clamp_to(mass.mass, janus2d_core::limits::MASS_RANGE),
            rotational_inertia: janus2d_core::limits::clamp_to(
                mass.rotational_inertia,
                janus2d_core::limits::INERTIA_RANGE,
            ),
            center: mass.center,
        };
        self.bodies.apply_mass(body, mass, fixed);
    }

    /// Number of live shapes.
    pub fn shape_count(&self) -> usize {
        self.collision.shapes.len()
    }

    /// Every contact, awake ones first, then those of sleeping islands.
    pub fn contacts(&self) -> impl Iterator<Item = &Contact> {
        self.collision.contacts.iter()
    }

    /// The touching solid contacts of a body, in the order of its contact
    /// list: normal (from the contact's `body_a` to `body_b`), points with
    /// separation, and the impulses of the last step (kept impulses and the
    /// step totals, [`ContactPointData`](crate::contacts::ContactPointData)).
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// use janus2d_core::math::Real;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// // The ground carries the box: m g over the step.
    /// let push: Real = world.body_contacts(b).unwrap().map(|c| c.total_normal_impulse()).sum();
    /// let weight_impulse = world.mass(b).unwrap() * 9.81 / 60.0;
    /// assert!((push - weight_impulse).abs() < 0.02 * weight_impulse);
    /// ```
    pub fn body_contacts(
        &self,
        body: BodyHandle,
    ) -> Result<impl Iterator<Item = &Contact> + '_, WorldError> {
        self.check_body(body)?;
        let contacts = &self.collision.contacts;
        Ok(contacts
            .of_body(body)
            .iter()
            .filter_map(|&id| contacts.get(id))
            .filter(|c| c.touching && !c.sensor))
    }

    /// The touching solid contacts of one shape (as
    /// [`World::body_contacts`]).
    pub fn shape_contacts(
        &self,
        shape: ShapeHandle,
    ) -> Result<impl Iterator<Item = &Contact> + '_, WorldError> {
        let body = self.shape(shape)?.body;
        Ok(self
            .body_contacts(body)?
            .filter(move |c| c.shapes.contains(&shape)))
    }

    /// Number of contacts (awake and asleep).
    pub fn contact_count(&self) -> usize {
        self.collision.contacts.len()
    }

    /// Number of awake contacts (what the narrowphase visits).
    pub fn awake_contact_count(&self) -> usize {
        self.collision.contacts.awake().len()
    }

    /// Bodies whose shapes' fat boxes overlap `aabb` (each once, sorted).
    pub fn bodies_in_box(&self, aabb: &janus2d_core::geometry::Aabb) -> Vec<BodyHandle> {
        let mut out = Vec::new();
        let shapes = &self.collision.shapes;
        self.collision.broadphase.query(aabb, |_, payload| {
            out.push(shapes.at(payload).body);
            true
        });
        out.sort();
        out.dedup();
        out
    }

    /// Counters of the last collision pass.
    pub fn collision_counters(&self) -> CollisionCounters {
        self.collision.counters
    }

    /// Number of touching solid contacts after the last step.
    pub fn touching_contact_count(&self) -> usize {
        self.contact_solver.len()
    }

    /// The most negative separation of any touching contact point, m
    /// (0 when nothing penetrates).
    pub fn max_penetration(&self) -> Real {
        let mut worst: Real = 0.0;
        for c in self.collision.contacts.iter() {
            if c.is_solid_touching() {
                for p in &c.points[..c.point_count] {
                    worst = worst.max(-p.separation);
                }
            }
        }
        worst
    }

    // ----- scene queries (logic in query.rs) ---------------------------------

    fn query_context(&self, filter: &crate::query::QueryFilter) -> crate::query::QueryContext<'_> {
        let owner = self.bodies.owner();
        crate::query::QueryContext {
            shapes: &self.collision.shapes,
            broadphase: &self.collision.broadphase,
            bodies: &self.bodies,
            owner,
            apertures: if filter.through_portals {
                self.portals.query_apertures(&self.bodies, owner)
            } else {
                Vec::new()
            },
        }
    }

    /// Casts the ray `origin + s · translation`, `s ∈ [0, 1]`, and hands
    /// every hit to `callback`, nearest first; the callback returns `-1` to
    /// ignore the hit, `0` to stop, a fraction to clip the ray, `1` to go
    /// on (see [`crate::query`]). Errors: a non-finite origin or
    /// translation, a zero translation ([`WorldError::BadQuery`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// for x in [2.0, 4.0] {
    ///     let b = world.create_body(&BodyDef::fixed(Vec2::new(x, 0.0))).unwrap();
    ///     world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// }
    /// let mut fractions = Vec::new();
    /// world.cast_ray_with(Vec2::ZERO, Vec2::new(10.0, 0.0), &QueryFilter::default(), |hit| {
    ///     fractions.push(hit.fraction);
    ///     1.0 // go on: every hit
    /// }).unwrap();
    /// assert_eq!(fractions.len(), 2);
    /// assert!((fractions[0] - 0.15).abs() < 1e-6 && (fractions[1] - 0.35).abs() < 1e-6);
    /// ```
    pub fn cast_ray_with<F: FnMut(&crate::query::RayHit) -> Real>(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::cast_ray(&ctx, origin, translation, filter, callback)
    }

    /// The nearest hit of the ray `origin + s · translation`, `s ∈ [0, 1]`,
    /// or `None`. Errors as [`cast_ray_with`](Self::cast_ray_with).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Circle;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 5.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 1.0).unwrap()).unwrap();
    /// let hit = world
    ///     .cast_ray_closest(Vec2::ZERO, Vec2::new(0.0, 10.0), &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// assert_eq!(hit.body, b);
    /// assert!((hit.point - Vec2::new(0.0, 4.0)).length() < 1e-5);
    /// assert!((hit.normal - Vec2::new(0.0, -1.0)).length() < 1e-5);
    /// ```
    pub fn cast_ray_closest(
        &self,
        origin: Vec2,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::RayHit>, WorldError> {
        let mut best = None;
        self.cast_ray_with(origin, translation, filter, |hit| {
            best = Some(*hit);
            hit.fraction
        })?;
        Ok(best)
    }

    /// Sweeps `shape`, placed by `transform`, along `translation` and hands
    /// every shape it meets to `callback` (nearest first, same return rule
    /// as [`cast_ray_with`](Self::cast_ray_with)). A hit's point and normal
    /// are on the surface of the shape hit; shapes the swept shape already
    /// overlaps at the start are hits at fraction 0. Errors: an invalid
    /// shape, a non-finite transform or translation, a zero translation.
    pub fn cast_shape_with<F: FnMut(&crate::query::RayHit) -> Real>(
        &self,
        shape: &Shape,
        transform: &Transform,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::cast_shape(&ctx, shape, transform, translation, filter, callback)
    }

    /// The first shape that `shape`, placed by `transform` and swept along
    /// `translation`, meets, or `None`. Errors as
    /// [`cast_shape_with`](Self::cast_shape_with).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Transform, Vec2};
    /// use janus2d_core::geometry::{Circle, Polygon, Shape};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let wall = world.create_body(&BodyDef::fixed(Vec2::new(6.0, 0.0))).unwrap();
    /// world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(1.0, 1.0)).unwrap();
    /// let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
    /// let hit = world
    ///     .cast_shape_closest(&ball, &Transform::IDENTITY, Vec2::new(10.0, 0.0), &QueryFilter::default())
    ///     .unwrap()
    ///     .unwrap();
    /// // The ball's centre stops at x = 4.5, touching the face at x = 5.
    /// assert!((hit.fraction - 0.45).abs() < 1e-3);
    /// assert!((hit.normal - Vec2::new(-1.0, 0.0)).length() < 1e-3);
    /// ```
    pub fn cast_shape_closest(
        &self,
        shape: &Shape,
        transform: &Transform,
        translation: Vec2,
        filter: &crate::query::QueryFilter,
    ) -> Result<Option<crate::query::RayHit>, WorldError> {
        let mut best = None;
        self.cast_shape_with(shape, transform, translation, filter, |hit| {
            best = Some(*hit);
            hit.fraction
        })?;
        Ok(best)
    }

    /// Hands `callback` every shape whose surface meets `aabb` (exact: a
    /// fat box that meets it is not enough), in shape slot order, until it
    /// returns `false`. Errors: a non-finite or inverted box.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Aabb, Circle};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// let near = Aabb::new(Vec2::new(0.51, -0.1), Vec2::new(1.0, 0.1)); // 1 cm off the ball
    /// let mut found = 0;
    /// world.overlap_aabb(&near, &QueryFilter::default(), |_| { found += 1; true }).unwrap();
    /// assert_eq!(found, 0);
    /// ```
    pub fn overlap_aabb<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        aabb: &janus2d_core::geometry::Aabb,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_aabb(&ctx, aabb, filter, callback)
    }

    /// Hands `callback` every shape that touches or overlaps `shape` placed
    /// by `transform`, in shape slot order, until it returns `false`.
    /// Errors: an invalid shape or a non-finite transform.
    pub fn overlap_shape<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        shape: &Shape,
        transform: &Transform,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_shape(&ctx, shape, transform, filter, callback)
    }

    /// Hands `callback` every solid shape that contains `point` (segments
    /// and chain segments never do), in shape slot order, until it returns
    /// `false`: what is under the mouse. Errors: a non-finite point.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(1.0, 1.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// let mut picked = None;
    /// world.overlap_point(Vec2::new(1.2, 0.7), &QueryFilter::default(), |o| {
    ///     picked = Some(o.body);
    ///     false // the first is enough
    /// }).unwrap();
    /// assert_eq!(picked, Some(b));
    /// ```
    pub fn overlap_point<F: FnMut(crate::query::ShapeOverlap) -> bool>(
        &self,
        point: Vec2,
        filter: &crate::query::QueryFilter,
        callback: F,
    ) -> Result<(), WorldError> {
        let ctx = self.query_context(filter);
        crate::query::overlap_point(&ctx, point, filter, callback)
    }

    /// Distance between the surfaces of two shapes at their bodies' current
    /// poses, their closest points and the unit normal from `a` to `b`
    /// (distance 0 when they touch or overlap). Errors: a stale or foreign
    /// shape handle.
    pub fn shape_distance(
        &self,
        a: ShapeHandle,
        b: ShapeHandle,
    ) -> Result<janus2d_core::geometry::DistanceOutput, WorldError> {
        let owner = self.bodies.owner();
        let sa = self.collision.shapes.slot(a, owner)?;
        let sb = self.collision.shapes.slot(b, owner)?;
        let ctx = self.query_context(&crate::query::QueryFilter::default());
        Ok(crate::query::distance_between(&ctx, sa, sb))
    }

    // ----- kinematic targets ---------------------------------------------------

    /// Sets the velocities that bring a kinematic (or dynamic) body from its
    /// pose to `target` (body origin and rotation) in one step of `dt`, so
    /// that what rests on it is carried along (as Box2D's
    /// `b2Body_SetTargetTransform`; unlike [`set_transform`](Self::set_transform),
    /// which teleports). The centre of mass moves by `target_center − center`
    /// exactly; the angular velocity is chosen so that the solver's substep
    /// rotation lands on the target angle (the shorter way round). The
    /// velocities stay until set again. Wakes the body.
    ///
    /// Errors: a stale handle, a non-finite target (`NonFinite("target")`),
    /// a `dt` that is not finite and positive, a static body
    /// ([`WorldError::NotMovable`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Transform, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let platform = world.create_body(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
    /// let target = Transform::new(Vec2::new(0.1, 0.05), 0.02);
    /// world.set_target_transform(platform, target, 1.0 / 60.0).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// let xf = world.transform(platform).unwrap();
    /// assert!((xf.p - target.p).length() < 1e-5);
    /// assert!((xf.q.angle() - 0.02).abs() < 1e-5);
    /// ```
    pub fn set_target_transform(
        &mut self,
        body: BodyHandle,
        target: Transform,
        dt: Real,
    ) -> Result<(), WorldError> {
        if !(vec_is_finite(target.p) && target.q.is_finite()) {
            return Err(WorldError::NonFinite("target"));
        }
        janus2d_core::body::check_position(target.p, "target")?;
        if target.q.c == 0.0 && target.q.s == 0.0 {
            return Err(WorldError::OutOfRange("target"));
        }
        if !(dt.is_finite() && dt > 0.0) {
            return Err(WorldError::InvalidTimeStep);
        }
        if self.body_type(body)? == BodyType::Static {
            return Err(WorldError::NotMovable);
        }
        let sim = self.bodies.sim(body).ok_or_else(|| self.body_error(body))?;
        let q2 = target.q.normalize();
        let center2 = q2.rotate(sim.local_center) + target.p;
        let v = (center2 - sim.center) / dt;
        let delta = sim.transform.q.relative_angle(q2);
        // Each substep turns by atan(h ω) (first-order, normalised): choose ω
        // so that the substeps add up to `delta`.
        let ctx = self.step_context(dt);
        let per_substep = delta / ctx.substeps.max(1) as Real;
        let w = if per_substep.abs() < 1.0 {
            per_substep.tan() * ctx.inv_h
        } else {
            delta / dt
        };
        janus2d_core::body::check_velocity(v, "target")?;
        janus2d_core::body::check_angular_velocity(w, "target")?;
        self.wake_body(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
            s.w = w;
        }
        Ok(())
    }

    // ----- sleep --------------------------------------------------------------

    /// Wakes the island of `body` (no effect on awake or static bodies).
    pub fn wake_body(&mut self, body: BodyHandle) {
        self.islands
            .wake(body, &mut self.bodies, &mut self.collision.contacts);
    }

    /// Wakes every island in the list.
    fn wake_all(&mut self, bodies: &[BodyHandle]) {
        for b in bodies {
            self.wake_body(*b);
        }
    }

    /// True when the body sleeps.
    pub fn is_sleeping(&self, body: BodyHandle) -> bool {
        self.bodies.is_sleeping(body)
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

    // ----- stepping ---------------------------------------------------------

    /// The step context the solver uses for a step of `dt`: the contact
    /// and iterative joint stiffness are capped at a quarter of the
    /// substep rate ([`MAX_HERTZ_FRACTION`](janus2d_core::limits::MAX_HERTZ_FRACTION),
    /// as Box2D caps its contact hertz): a stiffer soft row cannot be
    /// resolved by the substeps (and `1e30` Hz would give no softness).
    pub fn step_context(&self, dt: Real) -> StepContext {
        let substeps = match self.settings.mode {
            janus2d_core::SolverMode::SoftStep => self.settings.substeps.max(1),
            janus2d_core::SolverMode::PgsBaumgarte => 1,
        };
        let cap = janus2d_core::limits::MAX_HERTZ_FRACTION * substeps as Real / dt;
        if self.settings.contact_hertz <= cap && self.settings.joint_hertz <= cap {
            return self.settings.context(dt, self.gravity);
        }
        let capped = SolverSettings {
            contact_hertz: self.settings.contact_hertz.min(cap),
            joint_hertz: self.settings.joint_hertz.min(cap),
            ..self.settings.clone()
        };
        capped.context(dt, self.gravity)
    }

    /// Advances the world by `dt` seconds (finite, > 0).
    pub fn step(&mut self, dt: Real) -> Result<(), WorldError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(WorldError::InvalidTimeStep);
        }
        let mut ctx = self.step_context(dt);
        let start = std::time::Instant::now();
        let mut t = start;
        let mut lap = || {
            let now = std::time::Instant::now();
            let d = now.duration_since(t).as_secs_f64();
            t = now;
            d
        };
        let mut sp = crate::profile::StepProfile::default();
        self.islands
            .apply_pending(self.sleep_settings.enabled, &mut self.bodies);
        let has_shapes = !self.collision.shapes.is_empty();
        let has_portals = self.portals.is_active();
        if has_portals {
            self.portals
                .build_clipping(&self.bodies, &self.collision.shapes);
            sp.portals += lap();
        }
        if has_shapes {
            self.collision
                .update_pairs(&self.bodies, &self.joints.no_collide);
            sp.broadphase += lap();
            let mut wake = std::mem::take(&mut self.wake_list);
            wake.clear();
            let c = &mut self.collision;
            let input = crate::narrowphase::NarrowphaseInput {
                shapes: &c.shapes,
                broadphase: &c.broadphase,
                bodies: &self.bodies,
                dt,
                clipping: self.portals.clipping(),
                unclipped: self.portals.clipping().is_empty(),
            };
            c.narrowphase.run(
                &input,
                &mut c.contacts,
                &mut c.events,
                &mut c.counters,
                &mut wake,
            );
            self.wake_all(&wake);
            let woke = !wake.is_empty();
            self.wake_list = wake;
            self.islands
                .read_contact_changes(&mut self.collision.contacts, &self.bodies);
            self.portals
                .object_masses(&self.bodies, &mut self.object_masses);
            crate::narrowphase::build_constraints(
                &mut self.collision.narrowphase,
                &mut self.collision.contacts,
                &self.bodies,
                woke,
                &self.object_masses,
                self.joints.driven_bodies(),
                self.pre_solve.as_mut(),
                &mut self.contact_solver,
                &mut self.collision.counters,
            );
            sp.narrowphase += lap();
        } else {
            self.contact_solver.begin();
        }
        // No restitution anywhere: no restitution pass.
        ctx.restitution = has_shapes && self.collision.counters.restitution_contacts > 0;
        let couple = has_portals && self.portals.copies_carry_joints(&self.joints);
        let mut joints = self.joints.batch();
        let mut contacts = janus2d_constraints::ContactBatch {
            solver: &mut self.contact_solver,
            object_masses: &self.object_masses,
        };
        let mut portals = janus2d_constraints::PortalBatch {
            constraints: self.portals.constraints_mut(),
        };
        let passes = if couple {
            crate::portal::coupling::COUPLING_PASSES
        } else {
            0
        };
        let mut report = if passes > 0 {
            let mut coupled = crate::portal::coupling::CoupledBatches {
                batches: [&mut joints, &mut contacts, &mut portals],
                passes,
            };
            let mut batches: [&mut dyn ConstraintBatch; 1] = [&mut coupled];
            solve_step(&self.settings, &ctx, &mut self.bodies, &mut batches)
        } else {
            let mut batches: [&mut dyn ConstraintBatch; 3] =
                [&mut joints, &mut contacts, &mut portals];
            solve_step(&self.settings, &ctx, &mut self.bodies, &mut batches)
        };
        // The solver checks velocities and deltas; a pose they carried out
        // of the world (or to inf) is put back here, before any box is
        // computed from it.
        // (The solve's finalize checked the poses as it wrote them.)
        if !report.poses_inside {
            self.bodies
                .reset_escaped(janus2d_core::solver::POSE_LIMIT, &mut report.non_finite);
        }
        lap();
        if has_shapes {
            // The impulses go back into the contacts beside continuous
            // collision and the proxy update (`Collision::end_step`).
            let continuous = &mut self.continuous;
            let (no_collide, clipping) = (&self.joints.no_collide, self.portals.clipping());
            let continuous_time = self.collision.end_step(
                &self.contact_solver,
                &mut self.bodies,
                dt,
                |bodies, shapes, broadphase| {
                    let start = std::time::Instant::now();
                    let input = crate::continuous::ContinuousInput {
                        shapes,
                        broadphase,
                        no_collide,
                        clipping,
                    };
                    continuous.run(bodies, &input);
                    start.elapsed().as_secs_f64()
                },
            );
            if self.collision.shapes.hit_event_shapes() > 0 {
                self.collision
                    .collect_hits(&self.contact_solver, self.hit_event_threshold);
            }
            let both = lap();
            sp.continuous += continuous_time;
            sp.broadphase += both - continuous_time;
        }
        if has_portals {
            self.portal_crossings();
            sp.portals += lap();
        } else {
            self.portals.clear_events();
        }
        if self.sleep_settings.enabled {
            let keep_awake = self.portals.keep_awake();
            let input = SleepInput {
                dt,
                settings: self.sleep_settings,
                shapes: &self.collision.shapes,
                keep_awake: &keep_awake,
            };
            self.islands.update(
                &input,
                &mut self.bodies,
                &mut self.collision.contacts,
                &self.joints,
            );
            sp.sleep += lap();
        }
        sp.solver = report.profile;
        sp.total = start.elapsed().as_secs_f64();
        self.counters = crate::profile::StepCounters::gather(&crate::profile::CounterSources {
            collision_ran: has_shapes,
            collision: self.collision.counters,
            contacts: self.contact_solver.len(),
            joint_rows: self.joints.row_count(),
            direct_joint_rows: self.joints.direct_row_count(),
            portal_stage_ran: has_portals,
            portals: self.portals.counters_for_step(has_portals),
            gravity: self.gravity != Vec2::ZERO,
            bodies: &self.bodies,
            continuous: self.continuous.counters(),
        });
        self.step_profile = sp;
        self.events = StepEvents {
            non_finite_bodies: report.non_finite,
            collision: std::mem::take(&mut self.collision.events),
        };
        self.step_count += 1;
        Ok(())
    }

    /// Draws the world through `draw`: shapes, joints, contacts, boxes,
    /// islands, portals… as `options` says (see [`crate::debug_draw`]).
    /// Reads only; costs nothing when not called.
    pub fn debug_draw(
        &self,
        draw: &mut (impl crate::debug_draw::DebugDraw + ?Sized),
        options: &crate::debug_draw::DrawOptions,
    ) {
        let island_of = |body| self.islands.island_id(body);
        crate::debug_draw::draw_world(self, &island_of, draw, options);
    }

    /// The world-level part of [`World::validate`]: gravity and settings
    /// within their limits, the contact solver's colours adding up.
    pub(crate) fn check_world_values(&self) -> Result<(), String> {
        check_gravity(self.gravity).map_err(|e| e.to_string())?;
        check_settings(&self.settings).map_err(|e| e.to_string())?;
        self.sleep_settings.validate().map_err(|e| e.to_string())?;
        let coloured: usize = (0..janus2d_core::graph::COLOURS as u8)
            .map(|k| self.contact_solver.count_in(k))
            .sum::<usize>()
            + self.contact_solver.overflow().len();
        if coloured != self.contact_solver.len() {
            return Err(format!(
                "{coloured} contacts in colours, {} in the solver",
                self.contact_solver.len()
            ));
        }
        Ok(())
    }

    /// A hash of every body's transform and velocity bits, in handle order:
    /// equal hashes mean bit-identical states (see [`crate::hash`]).
    pub fn state_hash(&self) -> u64 {
        crate::hash::state_hash(&self.bodies)
    }
}

/// Internal operations the portal stage uses: each does exactly one
/// thing to a live body, with no checks and no `Result` (the stage only
/// passes handles it knows to be live).
#[cfg_attr(not(feature = "portals"), allow(dead_code))]
impl World {
    /// Sets a dynamic body's mass properties without touching its velocity.
    pub(crate) fn apply_mass_keep_velocity(&mut self, body: BodyHandle, mass: BodyMass) {
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        self.bodies.apply_mass(body, mass, fixed);
    }

    /// Creates a body (validated by `BodySet::create`) in an island of its
    /// own when dynamic; `create_body` adds the asleep-at-creation rule.
    pub(crate) fn insert_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        let handle = self.bodies.create(def)?;
        if def.body_type == BodyType::Dynamic {
            self.islands.add_body(handle);
        }
        Ok(handle)
    }

    /// Adds an impulse at a world point to a dynamic body now (no checks).
    pub(crate) fn push_body(
        &mut self,
        body: BodyHandle,
        impulse: Vec2,
        point: Vec2,
        angular: Real,
    ) {
        self.wake_body(body);
        if let Some(BodyLocation::Moving(i)) = self.bodies.location(body) {
            let sim = &self.bodies.sims[i as usize];
            if sim.body_type == BodyType::Dynamic {
                let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
                let st = &mut self.bodies.states[i as usize];
                st.v += im * impulse;
                st.w += ii * cross(point - c, impulse);
                st.w += ii * angular;
            }
        }
    }

    /// Sets a moving body's velocity (no checks).
    pub(crate) fn set_velocity_unchecked(&mut self, body: BodyHandle, v: Vec2, w: Real) {
        self.wake_body(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
            s.w = w;
        }
    }

    /// Attaches a shape whose geometry and material are known to be valid
    /// (a portal clone's scaled copy); the body's mass is left as it is.
    pub(crate) fn add_shape_unchecked(&mut self, body: BodyHandle, def: ShapeDef, geometry: Shape) {
        self.collision.add_shape(&self.bodies, body, geometry, def);
    }

    /// The enabled joints attached to a body, in the body's list order.
    pub(crate) fn joints_attached_to(&self, body: BodyHandle) -> Vec<JointHandle> {
        self.joints
            .of_body(body)
            .iter()
            .copied()
            .filter(|h| self.joints.get(*h).is_ok_and(Joint::is_enabled))
            .collect()
    }

    /// Disables a joint (the solver skips it; it stays until destroyed).
    pub(crate) fn disable_joint(&mut self, joint: JointHandle) {
        let switched = self.switch_joint(joint, false);
        debug_assert!(switched.is_ok(), "the portal stage passes live joints");
    }

    /// Moves one end of a joint from body `from` to body `to` with the
    /// local anchor `anchor` in `to`'s frame (the portal stage re-points
    /// joints to the copy of a crossing object on their other body's side):
    /// the islands link the new pair, a no-collide joint ends its new
    /// pair's contacts, and the new bodies wake.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn repoint_joint(
        &mut self,
        joint: JointHandle,
        from: BodyHandle,
        to: BodyHandle,
        anchor: Vec2,
    ) {
        let Some((old, new)) = self.joints.repoint(joint, from, to, anchor) else {
            return;
        };
        let (enabled, collide) = self
            .joints
            .get(joint)
            .map_or((false, true), |j| (j.is_enabled(), j.collide_connected()));
        if !collide {
            self.collision.remove_contacts_between(new.0, new.1);
            let freed = !self.joints.no_collide.contains(old.0, old.1);
            if freed {
                self.collision.refind_pairs_of(old.0);
                self.collision.refind_pairs_of(old.1);
            }
        }
        self.islands.note_removed(old.0);
        if enabled {
            self.wake_body(new.0);
            self.wake_body(new.1);
            self.islands.link(new.0, new.1, &self.bodies);
        }
    }

    /// Exchanges two bodies' identities (see `BodySet::swap_identity`),
    /// moving their shapes along and dropping their contacts.
    pub(crate) fn swap_body_identity(&mut self, a: BodyHandle, b: BodyHandle) {
        self.collision.remove_contacts_of(a);
        self.collision.remove_contacts_of(b);
        if self.bodies.swap_identity(a, b).is_ok() {
            self.collision.swap_body_shapes(a, b);
            self.islands.swap_bodies(a, b);
            // The shapes' tight boxes follow their new bodies' poses now
            // (the narrowphase culls pairs by them).
            for body in [a, b] {
                if let Some(xf) = self.bodies.sim(body).map(|s| s.transform) {
                    self.collision.refresh_body(body, &xf);
                }
            }
        }
    }

    /// Read access to the collision stage (portal stage).
    pub(crate) fn collision_ref(&self) -> &Collision {
        &self.collision
    }
}

/// Gravity: finite, its length at most
/// [`MAX_GRAVITY`](janus2d_core::limits::MAX_GRAVITY).
fn check_gravity(gravity: Vec2) -> Result<(), WorldError> {
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

/// Solver settings: [`SolverSettings::validate`], then every real finite
/// (`inf` Hz or an infinite damping ratio give NaN softness) and the
/// damping ratios at most
/// [`MAX_DAMPING_RATIO`](janus2d_core::limits::MAX_DAMPING_RATIO).
pub(crate) fn check_settings(s: &SolverSettings) -> Result<(), WorldError> {
    s.validate()?;
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
fn accumulated(field: &'static str) -> WorldError {
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
fn check_resulting_velocity(v: Vec2, w: Real) -> Result<(), WorldError> {
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
