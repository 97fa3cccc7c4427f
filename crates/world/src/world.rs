//! The world: bodies, joints and the stepping loop.
//!
//! ```text
//! World::step(dt)
//!   ├─ validate dt
//!   ├─ solve_step (janus2d-core): prepare ─ substeps ─ restitution ─ store ─ finalize
//!   └─ events: non-finite bodies (reset and reported)
//! ```
//!
//! Everything is created from definition structs with defaults and returns
//! a generational handle; every call that rejects its input leaves the world
//! unchanged.

use janus2d_constraints::{ContactConstraint, RevoluteJoint, RevoluteJointDef};
use janus2d_core::BodyMass;
use janus2d_core::body::{BodyDef, BodyHandle, BodyLocation, BodySet, BodyType, validate_mass};
use janus2d_core::constraint::{ConstraintBatch, StepContext};
use janus2d_core::geometry::{MassData, Shape};
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross, vec_is_finite};
use janus2d_core::solver::{SolverProfile, SolverSettings, solve_step};

use crate::collision::{Collision, CollisionCounters, CollisionEvents, ShapeDef, ShapeHandle};
use crate::error::WorldError;

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
    pub sleep: crate::sleep::SleepSettings,
}

impl Default for WorldDef {
    fn default() -> Self {
        WorldDef {
            gravity: DEFAULT_GRAVITY,
            solver: SolverSettings::default(),
            sleep: crate::sleep::SleepSettings::default(),
        }
    }
}

/// A generational handle to a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct JointHandle {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when issued.
    pub generation: u32,
    /// Id of the world that issued it (a foreign handle is rejected).
    pub owner: u32,
}

/// Events of the last step, read after `step`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StepEvents {
    /// Bodies whose state went non-finite during the step. Each was put back
    /// at its start-of-step pose, at rest, instead of spreading NaN.
    pub non_finite_bodies: Vec<BodyHandle>,
    /// Contact and sensor begin/end events.
    pub collision: CollisionEvents,
}

/// The simulation world.
pub struct World {
    gravity: Vec2,
    settings: SolverSettings,
    bodies: BodySet,
    revolute: Vec<RevoluteJoint>,
    /// The joint forest of the last step (direct point-row solve).
    joint_forest: janus2d_constraints::JointForest,
    revolute_handles: Vec<JointHandle>,
    /// Joint handle slots → index into `revolute`.
    joint_slots: janus2d_core::slots::Slots<u32>,
    collision: Collision,
    contact_constraints: Vec<ContactConstraint>,
    #[cfg(feature = "portals")]
    pub(crate) portals: crate::portals::Portals,
    pub(crate) islands: crate::sleep::Islands,
    pub(crate) sleep_settings: crate::sleep::SleepSettings,
    wake_list: Vec<BodyHandle>,
    /// Bodies created with `awake = false`, put to sleep at the next step.
    pending_sleep: Vec<BodyHandle>,
    events: StepEvents,
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
        if !vec_is_finite(def.gravity) {
            return Err(WorldError::NonFinite("gravity"));
        }
        validate_settings(&def.solver)?;
        let bodies = BodySet::new();
        Ok(World {
            gravity: def.gravity,
            settings: def.solver,
            collision: Collision::new(bodies.owner()),
            contact_constraints: Vec::new(),
            #[cfg(feature = "portals")]
            portals: crate::portals::Portals::default(),
            islands: crate::sleep::Islands::default(),
            sleep_settings: def.sleep,
            wake_list: Vec::new(),
            pending_sleep: Vec::new(),
            bodies,
            revolute: Vec::new(),
            joint_forest: Default::default(),
            revolute_handles: Vec::new(),
            joint_slots: janus2d_core::slots::Slots::default(),
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

    /// Sets gravity (rejects non-finite values).
    pub fn set_gravity(&mut self, gravity: Vec2) -> Result<(), WorldError> {
        if !vec_is_finite(gravity) {
            return Err(WorldError::NonFinite("gravity"));
        }
        self.gravity = gravity;
        Ok(())
    }

    /// The solver settings.
    pub fn settings(&self) -> &SolverSettings {
        &self.settings
    }

    /// Replaces the solver settings (validated).
    pub fn set_settings(&mut self, settings: SolverSettings) -> Result<(), WorldError> {
        validate_settings(&settings)?;
        self.settings = settings;
        Ok(())
    }

    /// Read access to the body storage (for metrics and tests).
    pub fn bodies(&self) -> &BodySet {
        &self.bodies
    }

    /// Number of live bodies.
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Number of live joints.
    pub fn joint_count(&self) -> usize {
        self.revolute.len()
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
    pub fn create_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        let handle = self.bodies.create(def)?;
        if !def.awake && def.body_type != BodyType::Static {
            self.pending_sleep.push(handle);
        }
        Ok(handle)
    }

    /// Destroys a body and every joint attached to it.
    pub fn destroy_body(&mut self, body: BodyHandle) -> Result<(), WorldError> {
        if !self.bodies.contains(body) {
            return Err(WorldError::StaleBody);
        }
        #[cfg(feature = "portals")]
        self.portals_forget_body(body);
        let touching: Vec<BodyHandle> = self
            .collision
            .contacts
            .iter()
            .filter(|c| c.body_a == body || c.body_b == body)
            .map(|c| if c.body_a == body { c.body_b } else { c.body_a })
            .collect();
        self.wake_all(&touching);
        self.wake_body(body);
        let attached: Vec<JointHandle> = self
            .revolute
            .iter()
            .zip(&self.revolute_handles)
            .filter(|(j, _)| j.def.body_a == body || j.def.body_b == body)
            .map(|(_, h)| *h)
            .collect();
        for h in attached {
            self.destroy_joint(h)?;
        }
        let shapes = self
            .collision
            .body_shapes
            .get(body.index as usize)
            .cloned()
            .unwrap_or_default();
        for s in shapes {
            self.collision.remove_shape(s);
        }
        self.bodies.destroy(body)?;
        Ok(())
    }

    fn check_body(&self, body: BodyHandle) -> Result<(), WorldError> {
        if self.bodies.contains(body) {
            Ok(())
        } else {
            Err(WorldError::StaleBody)
        }
    }

    /// Body origin and rotation.
    pub fn transform(&self, body: BodyHandle) -> Result<Transform, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.transform)
            .ok_or(WorldError::StaleBody)
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
            .ok_or(WorldError::StaleBody)
    }

    /// Linear velocity of the centre of mass, m/s.
    pub fn linear_velocity(&self, body: BodyHandle) -> Result<Vec2, WorldError> {
        self.bodies
            .linear_velocity(body)
            .ok_or(WorldError::StaleBody)
    }

    /// Angular velocity, rad/s.
    pub fn angular_velocity(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .angular_velocity(body)
            .ok_or(WorldError::StaleBody)
    }

    /// Mass, kg (0 for static and kinematic bodies).
    pub fn mass(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.mass)
            .ok_or(WorldError::StaleBody)
    }

    /// Rotational inertia about the centre of mass, kg·m².
    pub fn rotational_inertia(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.inertia)
            .ok_or(WorldError::StaleBody)
    }

    /// Body type.
    pub fn body_type(&self, body: BodyHandle) -> Result<BodyType, WorldError> {
        self.bodies.body_type(body).ok_or(WorldError::StaleBody)
    }

    /// Sets the linear velocity of a moving body's centre of mass.
    pub fn set_linear_velocity(&mut self, body: BodyHandle, v: Vec2) -> Result<(), WorldError> {
        if !vec_is_finite(v) {
            return Err(WorldError::NonFinite("linear_velocity"));
        }
        self.wake_body(body);
        self.check_body(body)?;
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
        }
        Ok(())
    }

    /// Sets the angular velocity of a moving body.
    pub fn set_angular_velocity(&mut self, body: BodyHandle, w: Real) -> Result<(), WorldError> {
        if !w.is_finite() {
            return Err(WorldError::NonFinite("angular_velocity"));
        }
        self.wake_body(body);
        self.check_body(body)?;
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

    /// Sets the mass properties of a dynamic body directly.
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
        self.wake_body(body);
        let sim = self.bodies.sim_mut(body).ok_or(WorldError::StaleBody)?;
        if sim.body_type == BodyType::Dynamic {
            sim.force += force;
            sim.torque += cross(point - sim.center, force);
        }
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
        self.wake_body(body);
        let sim = self.bodies.sim_mut(body).ok_or(WorldError::StaleBody)?;
        if sim.body_type == BodyType::Dynamic {
            sim.torque += torque;
        }
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
        self.wake_body(body);
        let loc = self.bodies.location(body).ok_or(WorldError::StaleBody)?;
        if let BodyLocation::Moving(i) = loc {
            let sim = &self.bodies.sims[i as usize];
            if sim.body_type == BodyType::Dynamic {
                let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
                let st = &mut self.bodies.states[i as usize];
                st.v += im * impulse;
                st.w += ii * cross(point - c, impulse);
            }
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
        self.wake_body(body);
        let loc = self.bodies.location(body).ok_or(WorldError::StaleBody)?;
        if let BodyLocation::Moving(i) = loc {
            let ii = self.bodies.sims[i as usize].inv_inertia;
            self.bodies.states[i as usize].w += ii * impulse;
        }
        Ok(())
    }

    // ----- joints -----------------------------------------------------------

    /// Creates a revolute joint.
    pub fn create_revolute_joint(
        &mut self,
        def: &RevoluteJointDef,
    ) -> Result<JointHandle, WorldError> {
        def.validate()?;
        self.check_body(def.body_a)?;
        self.check_body(def.body_b)?;
        self.wake_body(def.body_a);
        self.wake_body(def.body_b);
        let (index, generation) = self.joint_slots.insert(self.revolute.len() as u32);
        let handle = JointHandle {
            index,
            generation,
            owner: self.bodies.owner(),
        };
        self.revolute.push(RevoluteJoint::new(def.clone()));
        self.revolute_handles.push(handle);
        if !def.collide_connected {
            let key = body_pair_key(def.body_a, def.body_b);
            *self.collision.no_collide_pairs.entry(key).or_insert(0) += 1;
            self.collision
                .remove_contacts_between(def.body_a, def.body_b);
        }
        Ok(handle)
    }

    fn joint_index(&self, joint: JointHandle) -> Result<usize, WorldError> {
        if joint.owner != self.bodies.owner() {
            return Err(WorldError::StaleJoint);
        }
        self.joint_slots
            .get(joint.index, joint.generation)
            .map(|&i| i as usize)
            .ok_or(WorldError::StaleJoint)
    }

    /// Destroys a joint.
    pub fn destroy_joint(&mut self, joint: JointHandle) -> Result<(), WorldError> {
        let i = self.joint_index(joint)?;
        let (a, b) = (self.revolute[i].def.body_a, self.revolute[i].def.body_b);
        self.wake_body(a);
        self.wake_body(b);
        let def = &self.revolute[i].def;
        if !def.collide_connected {
            let key = body_pair_key(def.body_a, def.body_b);
            if let Some(n) = self.collision.no_collide_pairs.get_mut(&key) {
                *n -= 1;
                if *n == 0 {
                    self.collision.no_collide_pairs.remove(&key);
                }
            }
        }
        self.revolute.swap_remove(i);
        self.revolute_handles.swap_remove(i);
        if i < self.revolute.len() {
            let moved = self.revolute_handles[i];
            if let Some(slot) = self.joint_slots.at_mut(moved.index) {
                *slot = i as u32;
            }
        }
        self.joint_slots.remove(joint.index, joint.generation);
        Ok(())
    }

    /// A revolute joint.
    pub fn revolute_joint(&self, joint: JointHandle) -> Result<&RevoluteJoint, WorldError> {
        let i = self.joint_index(joint)?;
        Ok(&self.revolute[i])
    }

    /// Mutable access to a revolute joint's settings (motor speed, limits, …).
    pub fn revolute_joint_def_mut(
        &mut self,
        joint: JointHandle,
    ) -> Result<&mut RevoluteJointDef, WorldError> {
        let i = self.joint_index(joint)?;
        let (a, b) = (self.revolute[i].def.body_a, self.revolute[i].def.body_b);
        self.wake_body(a);
        self.wake_body(b);
        Ok(&mut self.revolute[i].def)
    }

    /// Distance between a joint's two world anchors, m.
    pub fn joint_gap(&self, joint: JointHandle) -> Result<Real, WorldError> {
        Ok(self.revolute_joint(joint)?.gap(&self.bodies))
    }

    /// Handles of every joint, in storage order.
    pub fn joint_handles(&self) -> &[JointHandle] {
        &self.revolute_handles
    }

    /// The largest joint gap in the world, m.
    pub fn max_joint_gap(&self) -> Real {
        self.revolute
            .iter()
            .map(|j| j.gap(&self.bodies))
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
        let ty = self.body_type(body)?;
        validate_shape_def(def)?;
        crate::collision::validate_geometry(&geometry)?;
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
            && !self.has_mass_from_shapes(body)
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
        let slot = self.collision.slot(shape).ok_or(WorldError::StaleShape)?;
        let body = self.collision.shapes[slot as usize].body;
        self.wake_body(body);
        self.collision.remove_shape(slot);
        let mass_override = self
            .bodies
            .record(body)
            .map(|r| r.mass_override)
            .unwrap_or(true);
        if self.body_type(body)? == BodyType::Dynamic && !mass_override {
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    fn has_mass_from_shapes(&self, body: BodyHandle) -> bool {
        self.shape_mass(body).mass > 0.0
    }

    fn shape_mass(&self, body: BodyHandle) -> MassData {
        let mut total = MassData::default();
        let mut first = Vec2::ZERO;
        let mut second: Real = 0.0;
        if let Some(list) = self.collision.body_shapes.get(body.index as usize) {
            for &s in list {
                let shape = &self.collision.shapes[s as usize];
                if shape.def.density <= 0.0 {
                    continue;
                }
                let md = shape.geometry.compute_mass(shape.def.density);
                total.mass += md.mass;
                first += md.mass * md.center;
                second += md.rotational_inertia + md.mass * md.center.length_squared();
            }
        }
        if total.mass > 0.0 {
            total.center = first / total.mass;
            total.rotational_inertia =
                (second - total.mass * total.center.length_squared()).max(0.0);
        }
        total
    }

    fn update_mass_from_shapes(&mut self, body: BodyHandle) {
        let md = self.shape_mass(body);
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
        self.bodies.apply_mass(body, mass, fixed);
    }

    /// Number of live shapes.
    pub fn shape_count(&self) -> usize {
        self.collision.shape_count()
    }

    /// The collision pipeline (shapes, contacts) for reading.
    pub fn collision(&self) -> &Collision {
        &self.collision
    }

    /// Counters of the last collision pass.
    pub fn collision_counters(&self) -> CollisionCounters {
        self.collision.counters
    }

    /// Number of touching solid contacts after the last step.
    pub fn touching_contact_count(&self) -> usize {
        self.contact_constraints.len()
    }

    /// The most negative separation of any touching contact point, m
    /// (0 when nothing penetrates).
    pub fn max_penetration(&self) -> Real {
        let mut worst: Real = 0.0;
        for c in &self.collision.contacts {
            if c.touching && !c.sensor && c.enabled {
                for p in &c.points[..c.point_count] {
                    worst = worst.max(-p.separation);
                }
            }
        }
        worst
    }

    // ----- helpers for the portal and sleep stages ----------------------------

    pub(crate) fn pending_sleep_is_empty(&self) -> bool {
        self.pending_sleep.is_empty()
    }

    /// A body created asleep that the user touched before the first step
    /// stays awake.
    pub(crate) fn cancel_pending_sleep(&mut self, body: BodyHandle) {
        self.pending_sleep.retain(|b| *b != body);
    }

    /// Mutable body storage (crate-internal).
    pub(crate) fn bodies_mut(&mut self) -> &mut BodySet {
        &mut self.bodies
    }

    /// The sleep settings.
    pub fn sleep_settings(&self) -> crate::sleep::SleepSettings {
        self.sleep_settings
    }

    /// Changes the sleep settings; turning sleep off wakes every body.
    pub fn set_sleep_settings(&mut self, settings: crate::sleep::SleepSettings) {
        if !settings.enabled {
            let sleeping: Vec<BodyHandle> =
                self.bodies.sleeping_sims.iter().map(|s| s.handle).collect();
            self.wake_all(&sleeping);
        }
        self.sleep_settings = settings;
    }

    /// How far a body's shapes reach from its centre of mass, m.
    pub(crate) fn body_reach(&self, body: BodyHandle) -> Real {
        let Some(sim) = self.bodies.sim(body) else {
            return 0.0;
        };
        let Some(list) = self.collision.body_shapes.get(body.index as usize) else {
            return 0.0;
        };
        list.iter()
            .map(|&s| {
                let a = &self.collision.shapes[s as usize].aabb;
                (a.lower - sim.center)
                    .abs()
                    .max((a.upper - sim.center).abs())
                    .length()
            })
            .fold(0.0, Real::max)
    }

    /// Pairs of bodies held together by enabled joints or touching solid
    /// contacts (the edges of the island graph).
    pub(crate) fn constraint_edges(&self) -> impl Iterator<Item = (BodyHandle, BodyHandle)> + '_ {
        let joints = self
            .revolute
            .iter()
            .filter(|j| j.enabled)
            .map(|j| (j.def.body_a, j.def.body_b));
        let contacts = self
            .collision
            .contacts
            .iter()
            .filter(|c| c.touching && !c.sensor && c.enabled)
            .map(|c| (c.body_a, c.body_b));
        joints.chain(contacts)
    }

    #[cfg(feature = "portals")]
    /// Sets a dynamic body's mass properties without touching its velocity.
    pub(crate) fn apply_mass_keep_velocity(&mut self, body: BodyHandle, mass: BodyMass) {
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        self.bodies.apply_mass(body, mass, fixed);
    }

    #[cfg(feature = "portals")]
    /// Joints attached to a body, in storage order.
    pub(crate) fn joints_attached_to(&self, body: BodyHandle) -> Vec<JointHandle> {
        self.revolute
            .iter()
            .zip(&self.revolute_handles)
            .filter(|(j, _)| j.enabled && (j.def.body_a == body || j.def.body_b == body))
            .map(|(_, h)| *h)
            .collect()
    }

    #[cfg(feature = "portals")]
    /// Disables a joint (the solver skips it; it stays until destroyed).
    pub(crate) fn disable_joint(&mut self, joint: JointHandle) {
        if let Ok(i) = self.joint_index(joint) {
            self.revolute[i].enabled = false;
        }
    }

    #[cfg(feature = "portals")]
    /// Exchanges two bodies' identities (see `BodySet::swap_identity`),
    /// moving their shapes along and dropping their contacts.
    pub(crate) fn swap_body_identity(&mut self, a: BodyHandle, b: BodyHandle) {
        self.collision.remove_contacts_of(a);
        self.collision.remove_contacts_of(b);
        if self.bodies.swap_identity(a, b).is_ok() {
            self.collision.swap_body_shapes(a, b);
        }
    }

    // ----- stepping ---------------------------------------------------------

    /// The step context the solver uses for a step of `dt`.
    pub fn step_context(&self, dt: Real) -> StepContext {
        self.settings.context(dt, self.gravity)
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
        let mut counters = crate::profile::StepCounters::default();
        self.collision.events = CollisionEvents::default();
        if !self.pending_sleep.is_empty() {
            let pending = std::mem::take(&mut self.pending_sleep);
            if self.sleep_settings.enabled {
                for b in pending {
                    self.bodies.sleep(b);
                }
            }
        }
        let has_shapes = self.collision.shape_count() > 0;
        #[cfg(feature = "portals")]
        let has_portals = self.portals.is_active();
        #[cfg(not(feature = "portals"))]
        let has_portals = false;
        #[cfg(feature = "portals")]
        if has_portals {
            self.portal_clipping();
            sp.portals += lap();
        }
        if has_shapes {
            self.collision.update_pairs(&self.bodies);
            sp.broadphase += lap();
            let mut wake = std::mem::take(&mut self.wake_list);
            wake.clear();
            #[cfg(feature = "portals")]
            let clipping = &self.portals.clipping;
            #[cfg(not(feature = "portals"))]
            let clipping = &crate::collision::NO_CLIPPING;
            self.collision
                .narrowphase(&self.bodies, dt, clipping, &mut wake);
            self.wake_all(&wake);
            let woke = !wake.is_empty();
            self.wake_list = wake;
            self.collision
                .build_constraints(&self.bodies, woke, &mut self.contact_constraints);
            #[cfg(feature = "portals")]
            if has_portals {
                let mut cs = std::mem::take(&mut self.contact_constraints);
                self.apply_object_masses(&mut cs);
                self.contact_constraints = cs;
            }
            sp.narrowphase += lap();
        } else {
            self.contact_constraints.clear();
        }
        // No restitution anywhere: no restitution pass.
        ctx.restitution = has_shapes && self.collision.counters.restitution_contacts > 0;
        let mut revolute = janus2d_constraints::RevoluteBatch {
            joints: &mut self.revolute,
            forest: &mut self.joint_forest,
        };
        #[cfg(feature = "portals")]
        let mut batches: [&mut dyn ConstraintBatch; 3] = [
            &mut revolute,
            &mut self.contact_constraints,
            &mut self.portals.constraints,
        ];
        #[cfg(not(feature = "portals"))]
        let mut batches: [&mut dyn ConstraintBatch; 2] =
            [&mut revolute, &mut self.contact_constraints];
        let report = solve_step(&self.settings, &ctx, &mut self.bodies, &mut batches);
        lap();
        if has_shapes {
            self.collision.store_impulses(&self.contact_constraints);
            self.collision.update_proxies(&self.bodies, dt);
            sp.broadphase += lap();
        }
        #[cfg(feature = "portals")]
        if has_portals {
            self.portal_stage();
            sp.portals += lap();
        } else {
            self.portals.events.clear();
        }
        if self.sleep_settings.enabled {
            self.update_sleep(dt);
            sp.sleep += lap();
        }
        sp.solver = report.profile;
        sp.total = start.elapsed().as_secs_f64();
        // Counters.
        let cc = self.collision.counters;
        counters.collision_ran = has_shapes;
        counters.pairs_tested = cc.pairs_tested;
        counters.pairs_created = cc.pairs_created;
        counters.proxies_moved = cc.proxies_moved;
        counters.contacts = self.contact_constraints.len();
        counters.contact_rows = if has_shapes { cc.contact_rows } else { 0 };
        counters.restitution_contacts = if has_shapes {
            cc.restitution_contacts
        } else {
            0
        };
        counters.joint_rows = self
            .revolute
            .iter()
            .filter(|j| j.enabled)
            .map(|j| {
                2 + 2 * j.def.enable_limit as usize
                    + j.def.enable_motor as usize
                    + j.def.enable_spring as usize
            })
            .sum();
        counters.direct_joint_rows = 2 * self.joint_forest.tree_joint_count();
        counters.portal_stage_ran = has_portals;
        #[cfg(feature = "portals")]
        {
            counters.portal_rows = 3 * self.portals.constraints.len();
            counters.portal_bodies_tested = if has_portals {
                self.portals.counters.bodies_tested
            } else {
                0
            };
            counters.portal_crossings = self.portals.crossings.len();
        }
        counters.gravity_bodies = if self.gravity == Vec2::ZERO {
            0
        } else {
            self.bodies.moving_count()
        };
        counters.awake_bodies = self.bodies.moving_count();
        counters.sleeping_bodies = self.bodies.sleeping_count();
        self.counters = counters;
        self.step_profile = sp;
        self.events = StepEvents {
            non_finite_bodies: report.non_finite,
            collision: std::mem::take(&mut self.collision.events),
        };
        self.step_count += 1;
        Ok(())
    }

    /// A hash of every body's transform and velocity bits, in handle order:
    /// equal hashes mean bit-identical states.
    pub fn state_hash(&self) -> u64 {
        let mut h = Fnv::new();
        for handle in self.bodies.handles() {
            let sim = self.bodies.sim(handle).expect("live handle");
            let st = self.bodies.state(handle).expect("live handle");
            h.write_u32(handle.index);
            for x in [
                sim.transform.p.x,
                sim.transform.p.y,
                sim.transform.q.c,
                sim.transform.q.s,
                st.v.x,
                st.v.y,
                st.w,
            ] {
                h.write_real(x);
            }
        }
        h.finish()
    }
}

fn body_pair_key(a: BodyHandle, b: BodyHandle) -> (u32, u32) {
    if a.index < b.index {
        (a.index, b.index)
    } else {
        (b.index, a.index)
    }
}

fn validate_shape_def(def: &ShapeDef) -> Result<(), WorldError> {
    for (v, name) in [
        (def.density, "density"),
        (def.friction, "friction"),
        (def.restitution, "restitution"),
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

fn validate_settings(s: &SolverSettings) -> Result<(), WorldError> {
    let reals = [
        s.baumgarte,
        s.contact_hertz,
        s.contact_damping_ratio,
        s.contact_push_max_velocity,
        s.joint_hertz,
        s.joint_damping_ratio,
        s.joint_max_correction_speed,
        s.restitution_threshold,
        s.contact_mass_ratio_cap,
        s.joint_mass_ratio_cap,
        s.direct_joint_hertz,
        s.direct_joint_max_correction_speed,
    ];
    if reals.iter().any(|x| x.is_nan()) {
        return Err(WorldError::NonFinite("solver settings"));
    }
    if reals.iter().any(|x| *x < 0.0) {
        return Err(WorldError::OutOfRange("solver settings"));
    }
    if s.substeps == 0
        || s.substeps > 1024
        || s.velocity_iterations > 1024
        || s.relax_iterations > 1024
    {
        return Err(WorldError::OutOfRange("iteration counts"));
    }
    Ok(())
}

/// FNV-1a, 64 bit: a small, stable hash for determinism checks.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn write_bytes(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.write_bytes(&v.to_le_bytes());
    }
    fn write_real(&mut self, v: Real) {
        self.write_bytes(&v.to_bits().to_le_bytes());
    }
    fn finish(&self) -> u64 {
        self.0
    }
}
