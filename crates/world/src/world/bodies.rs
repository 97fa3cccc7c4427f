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
