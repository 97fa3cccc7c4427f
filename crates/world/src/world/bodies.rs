//! Bodies: create, destroy, read, set, forces and impulses, kinematic
//! targets.

use super::*;
use crate::error::WorldError;
use crate::joints::JointHandle;
use janus2d_core::body::{BodyHandle, BodyLocation, BodyType};
use janus2d_core::math::Real;

impl World {
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
    ///
    /// Errors (nothing created): an invalid definition; a static body
    /// given a linear or angular velocity ([`WorldError::NotMovable`], as
    /// [`set_linear_velocity`](Self::set_linear_velocity) on one: a static
    /// body never moves, and the velocity would be silently dropped).
    pub fn create_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        janus2d_core::body::validate_body_def(def)?;
        if def.body_type == BodyType::Static
            && (def.linear_velocity != Vec2::ZERO || def.angular_velocity != 0.0)
        {
            return Err(WorldError::NotMovable);
        }
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
        let (portals, mut stores) = self.portals_and_stores();
        portals.forget_body(body, &mut stores);
        // A clone is already gone with its cancelled crossing.
        if self.bodies.contains(body) {
            self.destroy_body_unchecked(body);
        }
        self.disabled_joints.retain(|&(b, _)| b != body);
        Ok(())
    }

    /// Wakes every body that has a contact with `body` (its own list).
    pub(crate) fn wake_touching(&mut self, body: BodyHandle) {
        self.stores().wake_touching(body);
    }

    /// Destroys a live body (checked by the caller, crossings already
    /// ended; see `Stores::destroy_body`).
    pub(crate) fn destroy_body_unchecked(&mut self, body: BodyHandle) {
        self.stores().destroy_body(body);
    }

    /// `StaleBody`, or `ForeignHandle` for another world's handle.
    pub(crate) fn body_error(&self, body: BodyHandle) -> WorldError {
        self.check_body(body).err().unwrap_or(WorldError::StaleBody)
    }

    /// A live body that is kinematic or dynamic (`NotMovable` otherwise).
    pub(super) fn check_movable(&self, body: BodyHandle) -> Result<(), WorldError> {
        match self.body_type(body)? {
            BodyType::Static => Err(WorldError::NotMovable),
            _ => Ok(()),
        }
    }

    /// A live dynamic body (`NotDynamic` otherwise).
    pub(super) fn check_dynamic(&self, body: BodyHandle) -> Result<(), WorldError> {
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
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
        self.wake_island(body);
        if let Some(st) = self.bodies.state_mut(body) {
            st.w = w;
        }
        Ok(())
    }
}

impl World {
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
    /// a target rotation that is not unit length (`OutOfRange("target")`:
    /// `c² + s²` farther than
    /// [`UNIT_ROTATION_TOLERANCE`](janus2d_core::limits::UNIT_ROTATION_TOLERANCE)
    /// from 1; one within it is normalised), a `dt` outside
    /// [`TIME_STEP_RANGE`](janus2d_core::limits::TIME_STEP_RANGE), a static
    /// body ([`WorldError::NotMovable`]).
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
        let Some(q2) = target.q.to_unit() else {
            return Err(WorldError::OutOfRange("target"));
        };
        super::step::check_time_step(dt)?;
        if self.body_type(body)? == BodyType::Static {
            return Err(WorldError::NotMovable);
        }
        let sim = self.bodies.sim(body).ok_or_else(|| self.body_error(body))?;
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
        self.wake_island(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
            s.w = w;
        }
        Ok(())
    }
}

impl World {
    // ----- bodies --------------------------------------------------------

    /// True when the body is awake (moving bodies only: a static body is
    /// never awake).
    pub fn is_awake(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.check_body(body)?;
        Ok(matches!(
            self.bodies.location(body),
            Some(BodyLocation::Moving(_))
        ))
    }

    /// Wakes the body's island (`true`) or puts it to sleep now (`false`,
    /// as Box2D's `b2Body_SetAwake`; it wakes again when touched). No effect
    /// on a static body.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// world.set_awake(b, false).unwrap();
    /// assert!(!world.is_awake(b).unwrap());
    /// world.step(1.0 / 60.0).unwrap();
    /// assert_eq!(world.position(b).unwrap(), Vec2::ZERO); // asleep: no fall
    /// world.set_awake(b, true).unwrap();
    /// assert!(world.is_awake(b).unwrap());
    /// ```
    pub fn set_awake(&mut self, body: BodyHandle, awake: bool) -> Result<(), WorldError> {
        self.check_body(body)?;
        if awake {
            self.wake_island(body);
        } else if let Some(BodyLocation::Moving(_)) = self.bodies.location(body) {
            self.islands
                .sleep_now(body, &mut self.bodies, &mut self.collision.contacts);
        }
        Ok(())
    }

    /// True when the body may fall asleep.
    pub fn body_enable_sleep(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.enable_sleep)
            .ok_or_else(|| self.body_error(body))
    }

    /// Lets the body fall asleep or not; `false` wakes it (and keeps its
    /// island awake).
    pub fn set_body_enable_sleep(&mut self, body: BodyHandle, on: bool) -> Result<(), WorldError> {
        self.check_body(body)?;
        if !on {
            self.wake_island(body);
        }
        if let Some(s) = self.bodies.sim_mut(body) {
            s.enable_sleep = on;
            s.sleep_time = 0.0;
        }
        Ok(())
    }

    /// The body's own rest speed, m/s (`None`: the world's).
    pub fn body_sleep_threshold(&self, body: BodyHandle) -> Result<Option<Real>, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.sleep_threshold)
            .ok_or_else(|| self.body_error(body))
    }

    /// Sets the body's own rest speed, m/s (finite, ≥ 0), or `None` for
    /// the world's.
    pub fn set_body_sleep_threshold(
        &mut self,
        body: BodyHandle,
        threshold: Option<Real>,
    ) -> Result<(), WorldError> {
        self.check_body(body)?;
        if let Some(t) = threshold {
            super::shapes::check_material(t, "sleep_threshold")?;
        }
        if let Some(s) = self.bodies.sim_mut(body) {
            s.sleep_threshold = threshold;
        }
        Ok(())
    }

    /// True when the body is a bullet ([`janus2d_core::BodyDef::bullet`]).
    pub fn is_bullet(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.bullet)
            .ok_or_else(|| self.body_error(body))
    }

    /// Makes the body a bullet or not.
    pub fn set_bullet(&mut self, body: BodyHandle, on: bool) -> Result<(), WorldError> {
        self.check_body(body)?;
        if let Some(s) = self.bodies.sim_mut(body) {
            s.bullet = on;
        }
        Ok(())
    }

    /// The body's opaque user value.
    pub fn body_user_data(&self, body: BodyHandle) -> Result<u64, WorldError> {
        self.bodies
            .record(body)
            .map(|r| r.user_data)
            .ok_or_else(|| self.body_error(body))
    }

    /// Sets the body's opaque user value.
    pub fn set_body_user_data(&mut self, body: BodyHandle, value: u64) -> Result<(), WorldError> {
        self.check_body(body)?;
        if let Some(r) = self.bodies.record_mut(body) {
            r.user_data = value;
        }
        Ok(())
    }

    /// True when the body's mass was set directly ([`BodyDef::mass`] or
    /// [`set_mass`](Self::set_mass)) and does not follow its shapes.
    ///
    /// [`BodyDef::mass`]: janus2d_core::BodyDef::mass
    pub fn has_mass_override(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.bodies
            .record(body)
            .map(|r| r.mass_override)
            .ok_or_else(|| self.body_error(body))
    }

    /// Drops a directly set mass: a dynamic body's mass, centre and inertia
    /// follow its shapes again (recomputed now).
    pub fn reset_mass_from_shapes(&mut self, body: BodyHandle) -> Result<(), WorldError> {
        self.check_body(body)?;
        if let Some(r) = self.bodies.record_mut(body) {
            r.mass_override = false;
        }
        if self.bodies.body_type(body) == Some(BodyType::Dynamic) {
            self.wake_island(body);
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    /// Changes a body's type (as Box2D's `b2Body_SetType`): its contacts end
    /// (end events; the bodies it touched wake), its shapes' proxies move
    /// to the static or the movable tree, and it joins or leaves the
    /// islands. A body that becomes dynamic gets its mass from its shapes; a
    /// directly set mass is dropped. One that becomes static stops.
    /// Errors: a stale handle; [`WorldError::PortalBody`] for a body that
    /// carries or is crossing a portal (the world is then unchanged).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, BodyType, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 5.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.set_body_type(b, BodyType::Dynamic).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.position(b).unwrap().y < 5.0); // it falls now
    /// assert!((world.mass(b).unwrap() - 1.0).abs() < 1e-6);
    /// ```
    pub fn set_body_type(&mut self, body: BodyHandle, ty: BodyType) -> Result<(), WorldError> {
        self.check_body(body)?;
        let old = self.bodies.body_type(body).ok_or(WorldError::StaleBody)?;
        if old == ty {
            return Ok(());
        }
        if self.portals.involves(body) {
            return Err(WorldError::PortalBody);
        }
        if self.bodies.is_disabled(body) {
            return Err(WorldError::DisabledBody);
        }
        self.wake_island(body);
        self.wake_touching(body);
        self.collision.remove_contacts_of(body);
        if old == BodyType::Dynamic {
            self.islands.remove_body(body);
        }
        self.bodies.set_body_type(body, ty)?;
        let joints: smallvec::SmallVec<[JointHandle; 4]> =
            self.joints.of_body(body).iter().copied().collect();
        if ty == BodyType::Dynamic {
            self.islands.add_body(body);
            self.update_mass_from_shapes(body);
        }
        for j in joints {
            let Ok((a, b)) = self.joints.bodies_of(j) else {
                continue;
            };
            let other = if a == body { b } else { a };
            self.wake_island(other);
            let enabled = self.joints.get(j).is_ok_and(|r| r.is_enabled());
            if ty == BodyType::Dynamic && enabled {
                self.islands.link(a, b, &self.bodies);
            } else {
                self.islands.note_removed(other);
            }
        }
        let xf = self
            .bodies
            .sim(body)
            .map_or(janus2d_core::math::Transform::IDENTITY, |s| s.transform);
        self.collision
            .reproxy_body(body, &xf, ty == BodyType::Static);
        Ok(())
    }

    /// The id of the island a dynamic body belongs to (bodies linked by
    /// touching contacts and joints sleep and wake together), or `None`
    /// for a static or kinematic body, or one not yet in an island (it
    /// joins one at its next step).
    #[must_use]
    pub fn island_id(&self, body: BodyHandle) -> Option<u32> {
        self.islands.island_id(body)
    }
}

/// An explosion ([`World::explode`], as Box2D's `b2ExplosionDef`): every
/// dynamic body's shape within `radius + falloff` of `position` gets an
/// outward impulse of `impulse_per_length` per metre of its width seen from
/// the centre, full within `radius` and fading linearly to 0 across
/// `falloff`.
///
/// ```
/// use janus2d_world::{ExplosionDef, ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default().with_gravity(Vec2::ZERO)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(2.0, 0.0))).unwrap();
/// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
/// let pushed = world.explode(&ExplosionDef::new(Vec2::ZERO, 3.0, 1.0)).unwrap();
/// assert_eq!(pushed, 1);
/// assert!(world.linear_velocity(b).unwrap().x > 0.0, "pushed away from the centre");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExplosionDef {
    /// Centre of the explosion, world, m.
    pub position: Vec2,
    /// Radius of full strength, m (≥ 0).
    pub radius: Real,
    /// Width of the band beyond `radius` over which the impulse falls to 0,
    /// m (≥ 0; usual 0).
    pub falloff: Real,
    /// Impulse per metre of projected width, N·s/m (negative: an implosion).
    pub impulse_per_length: Real,
    /// The shape categories it pushes (`shape.category & mask != 0`; usual all).
    pub mask_bits: u64,
}

impl ExplosionDef {
    /// An explosion at `position` of full strength within `radius`, pushing
    /// `impulse_per_length` N·s per metre of width, no falloff, every
    /// category.
    ///
    /// ```
    /// use janus2d_world::ExplosionDef;
    /// use janus2d_core::Vec2;
    /// let e = ExplosionDef::new(Vec2::ZERO, 2.0, 5.0).with_falloff(1.0).with_mask(0b10);
    /// assert_eq!((e.radius, e.falloff, e.impulse_per_length, e.mask_bits), (2.0, 1.0, 5.0, 2));
    /// ```
    #[must_use]
    pub fn new(position: Vec2, radius: Real, impulse_per_length: Real) -> Self {
        ExplosionDef {
            position,
            radius,
            falloff: 0.0,
            impulse_per_length,
            mask_bits: u64::MAX,
        }
    }

    /// Sets the falloff band, m (builder style).
    ///
    /// ```
    /// use janus2d_world::ExplosionDef;
    /// use janus2d_core::Vec2;
    /// let e = ExplosionDef::new(Vec2::ZERO, 1.0, 2.0).with_falloff(0.5);
    /// assert_eq!(e.falloff, 0.5);
    /// assert!(ExplosionDef::new(Vec2::ZERO, 1.0, 2.0).with_falloff(-1.0).validate().is_err());
    /// ```
    #[must_use]
    pub fn with_falloff(mut self, falloff: Real) -> Self {
        self.falloff = falloff;
        self
    }

    /// Pushes only the categories in `mask_bits` (builder style).
    #[must_use]
    pub fn with_mask(mut self, mask_bits: u64) -> Self {
        self.mask_bits = mask_bits;
        self
    }

    /// Checks the definition: a finite position within the world's extent,
    /// finite non-negative radius and falloff, a finite impulse; the error
    /// names the field.
    pub fn validate(&self) -> Result<(), WorldError> {
        janus2d_core::body::check_position(self.position, "position")?;
        super::shapes::check_material(self.radius, "radius")?;
        super::shapes::check_material(self.falloff, "falloff")?;
        if !self.impulse_per_length.is_finite() {
            return Err(WorldError::NonFinite("impulse_per_length"));
        }
        Ok(())
    }
}

/// Width of `shape` (body frame) along the unit direction `line`, m.
fn projected_width(shape: &Shape, line: Vec2) -> Real {
    match shape {
        Shape::Circle(c) => 2.0 * c.radius,
        Shape::Capsule(c) => 2.0 * c.radius + (c.center2 - c.center1).dot(line).abs(),
        Shape::Segment(s) => (s.point2 - s.point1).dot(line).abs(),
        Shape::ChainSegment(c) => (c.segment.point2 - c.segment.point1).dot(line).abs(),
        Shape::Polygon(p) => {
            let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
            for v in &p.vertices[..p.count] {
                let s = v.dot(line);
                lo = lo.min(s);
                hi = hi.max(s);
            }
            hi - lo + 2.0 * p.radius
        }
    }
}

impl World {
    // ----- motion settings after creation ------------------------------------

    /// The body and, while it crosses a portal, its other copy: settings
    /// that the crossing copies share are set on both.
    fn with_crossing_copy(&self, body: BodyHandle) -> smallvec::SmallVec<[BodyHandle; 2]> {
        #[cfg_attr(not(feature = "portals"), allow(unused_mut))]
        let mut out = smallvec::smallvec![body];
        #[cfg(feature = "portals")]
        for c in &self.portals.crossings {
            if c.original == body {
                out.push(c.clone);
            } else if c.clone == body {
                out.push(c.original);
            }
        }
        out
    }

    /// Sets the body's gravity scale (dimensionless; 0 floats, −1 falls up),
    /// read by [`gravity_scale`](Self::gravity_scale); wakes the body. A
    /// body crossing a portal and its copy get the same scale.
    ///
    /// Errors (the world unchanged): a stale or foreign handle, a
    /// non-finite scale, a magnitude above
    /// [`MAX_GRAVITY_SCALE`](janus2d_core::limits::MAX_GRAVITY_SCALE)
    /// ([`WorldError::OutOfBounds`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(1.0, 2.0))).unwrap();
    /// world.set_gravity_scale(b, 0.0).unwrap();
    /// for _ in 0..60 { world.step(1.0 / 60.0).unwrap(); }
    /// assert_eq!(world.linear_velocity(b).unwrap(), Vec2::new(1.0, 2.0));
    /// assert_eq!(world.gravity_scale(b).unwrap(), 0.0);
    /// ```
    pub fn set_gravity_scale(&mut self, body: BodyHandle, scale: Real) -> Result<(), WorldError> {
        self.check_body(body)?;
        if !scale.is_finite() {
            return Err(WorldError::NonFinite("gravity_scale"));
        }
        let max = janus2d_core::limits::MAX_GRAVITY_SCALE;
        if scale.abs() > max {
            return Err(WorldError::OutOfBounds {
                field: "gravity_scale",
                min: -max,
                max,
            });
        }
        for b in self.with_crossing_copy(body) {
            self.wake_island(b);
            if let Some(s) = self.bodies.sim_mut(b) {
                s.gravity_scale = scale;
            }
        }
        Ok(())
    }

    /// The body's linear damping, 1/s.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_linear_damping(0.5)).unwrap();
    /// assert_eq!(world.linear_damping(b), Ok(0.5));
    /// world.set_linear_damping(b, 2.0).unwrap();
    /// assert_eq!(world.linear_damping(b), Ok(2.0));
    /// ```
    pub fn linear_damping(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.linear_damping)
            .ok_or_else(|| self.body_error(body))
    }

    /// The body's angular damping, 1/s.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_angular_damping(0.3)).unwrap();
    /// assert_eq!(world.angular_damping(b), Ok(0.3));
    /// ```
    pub fn angular_damping(&self, body: BodyHandle) -> Result<Real, WorldError> {
        self.bodies
            .sim(body)
            .map(|s| s.angular_damping)
            .ok_or_else(|| self.body_error(body))
    }

    /// Sets the body's linear damping, 1/s (as
    /// [`BodyDef::linear_damping`](janus2d_core::BodyDef::linear_damping):
    /// each step scales the velocity by `1 / (1 + h c)`); wakes the body. A
    /// body crossing a portal and its copy get the same damping.
    ///
    /// Errors (the world unchanged): a stale or foreign handle, a non-finite
    /// (`NonFinite("linear_damping")`) or negative
    /// (`OutOfRange("linear_damping")`) value.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, WorldError};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef { gravity: Vec2::ZERO, ..WorldDef::default() }).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(4.0, 0.0))).unwrap();
    /// world.set_linear_damping(b, 1.0).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.linear_velocity(b).unwrap().x < 4.0);
    /// assert_eq!(world.set_linear_damping(b, -1.0), Err(WorldError::OutOfRange("linear_damping")));
    /// assert_eq!(world.linear_damping(b).unwrap(), 1.0);
    /// ```
    pub fn set_linear_damping(
        &mut self,
        body: BodyHandle,
        damping: Real,
    ) -> Result<(), WorldError> {
        self.check_body(body)?;
        super::shapes::check_material(damping, "linear_damping")?;
        for b in self.with_crossing_copy(body) {
            self.wake_island(b);
            if let Some(s) = self.bodies.sim_mut(b) {
                s.linear_damping = damping;
            }
        }
        Ok(())
    }

    /// Sets the body's angular damping, 1/s (as
    /// [`set_linear_damping`](Self::set_linear_damping), for the spin).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_angular_velocity(3.0)).unwrap();
    /// world.set_angular_damping(b, 2.0).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.angular_velocity(b).unwrap() < 3.0);
    /// ```
    pub fn set_angular_damping(
        &mut self,
        body: BodyHandle,
        damping: Real,
    ) -> Result<(), WorldError> {
        self.check_body(body)?;
        super::shapes::check_material(damping, "angular_damping")?;
        for b in self.with_crossing_copy(body) {
            self.wake_island(b);
            if let Some(s) = self.bodies.sim_mut(b) {
                s.angular_damping = damping;
            }
        }
        Ok(())
    }

    /// True when the body's rotation is fixed ([`BodyDef::fixed_rotation`](janus2d_core::BodyDef::fixed_rotation)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_fixed_rotation(true)).unwrap();
    /// assert_eq!(world.is_fixed_rotation(b), Ok(true));
    /// world.set_fixed_rotation(b, false).unwrap();
    /// assert_eq!(world.is_fixed_rotation(b), Ok(false));
    /// ```
    pub fn is_fixed_rotation(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .ok_or_else(|| self.body_error(body))
    }

    /// Fixes or frees a body's rotation (as Box2D's
    /// `b2Body_SetFixedRotation`): fixing zeroes its rotational inertia's
    /// inverse and its angular velocity; freeing gives back the inertia of
    /// its shapes. A body whose mass was set directly keeps its mass and
    /// centre; freed, it gets its shapes' inertia about that centre scaled by
    /// its mass over theirs. Wakes a dynamic body.
    ///
    /// Errors (the world unchanged): a stale or foreign handle; a body that
    /// carries or is crossing a portal ([`WorldError::PortalBody`]: the
    /// crossing's mass split is fixed when it starts); freeing a body with
    /// a directly set mass whose shapes have no rotational inertia
    /// (`Body(NonPositiveInertia)`).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO).with_angular_velocity(2.0)).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(1.0, 0.5)).unwrap();
    /// let inertia = world.rotational_inertia(b).unwrap();
    /// world.set_fixed_rotation(b, true).unwrap();
    /// assert!(world.is_fixed_rotation(b).unwrap());
    /// assert_eq!(world.angular_velocity(b).unwrap(), 0.0);
    /// world.set_fixed_rotation(b, false).unwrap();
    /// assert!((world.rotational_inertia(b).unwrap() - inertia).abs() < 1e-6);
    /// ```
    pub fn set_fixed_rotation(&mut self, body: BodyHandle, fixed: bool) -> Result<(), WorldError> {
        self.check_body(body)?;
        if self.is_fixed_rotation(body)? == fixed {
            return Ok(());
        }
        if self.portals.involves(body) {
            return Err(WorldError::PortalBody);
        }
        let dynamic = self.body_type(body)? == BodyType::Dynamic;
        let overridden = self.has_mass_override(body)?;
        // A directly set mass keeps its mass and centre; the inertia is
        // worked out before anything changes.
        let kept = if dynamic && overridden {
            let sim = self.bodies.sim(body).ok_or(WorldError::StaleBody)?;
            let inertia = if fixed {
                0.0
            } else {
                let md = self.collision.shapes.mass_of(body);
                if !(md.mass > 0.0 && md.rotational_inertia > 0.0) {
                    return Err(WorldError::Body(
                        janus2d_core::body::BodyError::NonPositiveInertia,
                    ));
                }
                let shift = (md.center - sim.local_center).length_squared();
                janus2d_core::limits::clamp_to(
                    (md.rotational_inertia + md.mass * shift) * sim.mass / md.mass,
                    janus2d_core::limits::INERTIA_RANGE,
                )
            };
            Some(BodyMass {
                mass: sim.mass,
                rotational_inertia: inertia,
                center: sim.local_center,
            })
        } else {
            None
        };
        if let Some(r) = self.bodies.record_mut(body) {
            r.fixed_rotation = fixed;
        }
        if !dynamic {
            return Ok(());
        }
        self.wake_island(body);
        match kept {
            Some(mass) => self.bodies.apply_mass(body, mass, fixed),
            None => self.update_mass_from_shapes(body),
        }
        if fixed && let Some(s) = self.bodies.state_mut(body) {
            s.w = 0.0;
        }
        Ok(())
    }

    /// The velocity of the body's material point at world `point`, m/s:
    /// `v + ω × (point − centre of mass)` (as Box2D's
    /// `b2Body_GetWorldPointVelocity`; zero for a static body).
    ///
    /// Errors: a stale or foreign handle, a non-finite point
    /// (`NonFinite("point")`).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let wheel = world
    ///     .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(1.0, 0.0)).with_angular_velocity(2.0))
    ///     .unwrap();
    /// // 0.5 m above the centre: 1 − 2 · 0.5 = 0 along x (rolling without slip).
    /// let top = world.velocity_at_point(wheel, Vec2::new(0.0, 0.5)).unwrap();
    /// assert!((top - Vec2::new(0.0, 0.0)).length() < 1e-6);
    /// ```
    pub fn velocity_at_point(&self, body: BodyHandle, point: Vec2) -> Result<Vec2, WorldError> {
        self.check_body(body)?;
        if !vec_is_finite(point) {
            return Err(WorldError::NonFinite("point"));
        }
        let c = self.center_of_mass(body)?;
        let v = self.linear_velocity(body)?;
        let w = self.angular_velocity(body)?;
        Ok(v + janus2d_core::math::cross_sv(w, point - c))
    }

    /// Applies an explosion (as Box2D's `b2World_Explode`): each shape of a
    /// dynamic body whose surface is within `radius + falloff` of the centre
    /// (sensors and shapes outside `mask_bits` excepted) gets the impulse
    /// `impulse_per_length · w · s` along the direction from the centre to
    /// its nearest point `p`, applied at `p`, where `w` is the shape's width
    /// across that direction and `s` is 1 within `radius`, falling linearly
    /// to 0 at `radius + falloff`. A shape holding the centre is pushed from
    /// its centroid outward (along +x when the centroid is the centre). The
    /// bodies pushed wake. Returns the number of shapes pushed. Acts on the
    /// shapes where they are: both copies of a body crossing a portal may be
    /// pushed, nothing goes through apertures.
    ///
    /// Errors (nothing pushed): an invalid definition
    /// ([`ExplosionDef::validate`]); an impulse that would take a body past
    /// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED) or
    /// [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED).
    ///
    /// ```
    /// use janus2d_world::{ExplosionDef, World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Circle;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(3.0, 0.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// let pushed = world.explode(&ExplosionDef::new(Vec2::ZERO, 4.0, 2.0)).unwrap();
    /// assert_eq!(pushed, 1);
    /// // 2 N·s/m × 1 m of width = 2 N·s on m = π 0.5² kg, along +x.
    /// let m = world.mass(b).unwrap();
    /// assert!((world.linear_velocity(b).unwrap().x - 2.0 / m).abs() < 1e-4);
    /// ```
    pub fn explode(&mut self, def: &ExplosionDef) -> Result<usize, WorldError> {
        def.validate()?;
        let reach = def.radius + def.falloff;
        let half = Vec2::new(reach, reach);
        let aabb = janus2d_core::geometry::Aabb::new(def.position - half, def.position + half);
        let mut slots = Vec::new();
        self.collision.broadphase.query(&aabb, |_, slot| {
            slots.push(slot);
            true
        });
        slots.sort_unstable();
        slots.dedup();
        // Each body's new velocities, worked out before anything changes.
        let mut pushes: Vec<(BodyHandle, Vec2, Real)> = Vec::new();
        let mut count = 0;
        for slot in slots {
            let data = self.collision.shapes.at(slot);
            if data.def.is_sensor || data.def.filter.category_bits & def.mask_bits == 0 {
                continue;
            }
            if self.bodies.body_type(data.body) != Some(BodyType::Dynamic) {
                continue;
            }
            let Some(sim) = self.bodies.sim(data.body) else {
                continue;
            };
            let xf = sim.transform;
            let (q, _, signed) =
                crate::query::project_local(&data.geometry, xf.apply_inv(def.position));
            let distance = signed.max(0.0);
            if distance > reach {
                continue;
            }
            let at = if signed > 0.0 {
                xf.apply(q)
            } else {
                xf.apply(data.geometry.centroid())
            };
            let d = at - def.position;
            let direction = if d.length_squared() > 1e-12 {
                d.normalize()
            } else {
                Vec2::X
            };
            let scale = if distance <= def.radius {
                1.0
            } else {
                ((reach - distance) / def.falloff).clamp(0.0, 1.0)
            };
            let across = xf.q.inv_rotate(Vec2::new(-direction.y, direction.x));
            let magnitude =
                def.impulse_per_length * projected_width(&data.geometry, across) * scale;
            let impulse = magnitude * direction;
            let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
            let (dv, dw) = (im * impulse, ii * cross(at - c, impulse));
            match pushes.iter_mut().find(|p| p.0 == data.body) {
                Some(p) => {
                    p.1 += dv;
                    p.2 += dw;
                }
                None => {
                    let v = self.linear_velocity(data.body)?;
                    let w = self.angular_velocity(data.body)?;
                    pushes.push((data.body, v + dv, w + dw));
                }
            }
            count += 1;
        }
        for &(_, v, w) in &pushes {
            check_resulting_velocity(v, w)?;
        }
        for (body, v, w) in pushes {
            self.wake_island(body);
            if let Some(s) = self.bodies.state_mut(body) {
                s.v = v;
                s.w = w;
            }
        }
        Ok(count)
    }
}
