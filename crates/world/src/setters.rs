//! Setters and getters of bodies, shapes and joints after creation.
//!
//! | what | getters | setters |
//! |------|---------|---------|
//! | type | [`World::body_type`] | [`World::set_body_type`] (proxies move between the static and movable trees) |
//! | sleep | [`World::is_awake`], [`World::body_enable_sleep`], [`World::body_sleep_threshold`] | [`World::set_awake`], [`World::set_body_enable_sleep`], [`World::set_body_sleep_threshold`] |
//! | continuous | [`World::is_bullet`] | [`World::set_bullet`] |
//! | mass | [`World::has_mass_override`] | [`World::set_mass`] (stays set), [`World::reset_mass_from_shapes`] |
//! | user data | [`World::body_user_data`], [`World::shape_user_data`], [`World::joint_user_data`] | `set_…_user_data` |
//! | shapes | [`World::shape_body`], [`World::body_shapes`] | friction, restitution, density (mass updated), filter, sensor |
//!
//! Every setter checks its input first: a stale handle or a bad value is a
//! typed [`WorldError`] and the world is unchanged.

use janus2d_constraints::contact::{mix_friction, mix_restitution};
use janus2d_core::body::{BodyHandle, BodyLocation, BodyType};
use janus2d_core::math::Real;

use crate::error::WorldError;
use crate::joints::JointHandle;
use crate::shapes::{Filter, ShapeHandle};
use crate::world::World;

/// A material value must be finite and ≥ 0.
fn check_material(v: Real, name: &'static str) -> Result<(), WorldError> {
    if !v.is_finite() {
        return Err(WorldError::NonFinite(name));
    }
    if v < 0.0 {
        return Err(WorldError::OutOfRange(name));
    }
    crate::shapes::check_material_limit(v, name)
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
            self.wake_body(body);
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
            self.wake_body(body);
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
            check_material(t, "sleep_threshold")?;
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
            let flags = s.state_flags();
            if let Some(st) = self.bodies.state_mut(body) {
                st.flags = flags;
            }
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
            self.wake_body(body);
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
        self.wake_body(body);
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
            self.wake_body(other);
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

    // ----- shapes --------------------------------------------------------

    fn shape_slot(&self, shape: ShapeHandle) -> Result<u32, WorldError> {
        self.collision.shapes.slot(shape, self.bodies.owner())
    }

    /// The body a shape is attached to.
    pub fn shape_body(&self, shape: ShapeHandle) -> Result<BodyHandle, WorldError> {
        let slot = self.shape_slot(shape)?;
        Ok(self.collision.shapes.at(slot).body)
    }

    /// The shape's opaque user value.
    pub fn shape_user_data(&self, shape: ShapeHandle) -> Result<u64, WorldError> {
        let slot = self.shape_slot(shape)?;
        Ok(self.collision.shapes.at(slot).def.user_data)
    }

    /// Sets the shape's opaque user value.
    pub fn set_shape_user_data(
        &mut self,
        shape: ShapeHandle,
        value: u64,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.at_mut(slot).def.user_data = value;
        Ok(())
    }

    /// Re-mixes the material of the shape's existing contacts.
    fn refresh_contact_materials(&mut self, slot: u32) {
        let body = self.collision.shapes.at(slot).body;
        let ids: smallvec::SmallVec<[u32; 8]> = self
            .collision
            .contacts
            .of_body(body)
            .iter()
            .copied()
            .collect();
        for id in ids {
            let Some(c) = self.collision.contacts.get(id) else {
                continue;
            };
            if c.shape_a != slot && c.shape_b != slot {
                continue;
            }
            let (a, b) = (c.shape_a, c.shape_b);
            let da = &self.collision.shapes.at(a).def;
            let db = &self.collision.shapes.at(b).def;
            let friction = mix_friction(da.friction, db.friction);
            let restitution = mix_restitution(da.restitution, db.restitution);
            if let Some(c) = self.collision.contacts.get_mut(id) {
                c.friction = friction;
                c.restitution = restitution;
            }
        }
    }

    /// Sets the shape's friction (finite, ≥ 0); its contacts use it from
    /// the next step.
    pub fn set_shape_friction(
        &mut self,
        shape: ShapeHandle,
        friction: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        check_material(friction, "friction")?;
        self.collision.shapes.at_mut(slot).def.friction = friction;
        self.refresh_contact_materials(slot);
        Ok(())
    }

    /// Sets the shape's restitution (finite, ≥ 0); its contacts use it from
    /// the next step.
    pub fn set_shape_restitution(
        &mut self,
        shape: ShapeHandle,
        restitution: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        check_material(restitution, "restitution")?;
        self.collision.shapes.at_mut(slot).def.restitution = restitution;
        self.refresh_contact_materials(slot);
        Ok(())
    }

    /// Sets the shape's density, kg/m² (finite, ≥ 0); a dynamic body whose
    /// mass follows its shapes gets its new mass, centre and inertia now.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.set_shape_density(s, 3.0).unwrap();
    /// assert!((world.mass(b).unwrap() - 3.0).abs() < 1e-5);
    /// ```
    pub fn set_shape_density(
        &mut self,
        shape: ShapeHandle,
        density: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        check_material(density, "density")?;
        crate::world::check_shape_mass(&self.collision.shapes.at(slot).geometry, density)?;
        let body = self.collision.shapes.at(slot).body;
        self.collision.shapes.at_mut(slot).def.density = density;
        let follows = self.bodies.record(body).is_some_and(|r| !r.mass_override);
        if follows && self.bodies.body_type(body) == Some(BodyType::Dynamic) {
            self.wake_body(body);
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    /// Ends the shape's contacts (end events for touching ones) and has the
    /// broadphase report its pairs again, under its new filter or sensor flag.
    fn repair_shape(&mut self, slot: u32) {
        let body = self.collision.shapes.at(slot).body;
        self.wake_body(body);
        let c = &mut self.collision;
        c.contacts.destroy_of_body(body, &mut c.events, |x| {
            x.shape_a == slot || x.shape_b == slot
        });
        let proxy = c.shapes.at(slot).proxy;
        c.broadphase.touch_proxy(proxy);
    }

    /// Sets the shape's collision filter; its pairs are filtered again at
    /// the next step.
    pub fn set_shape_filter(
        &mut self,
        shape: ShapeHandle,
        filter: Filter,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.at_mut(slot).def.filter = filter;
        self.repair_shape(slot);
        Ok(())
    }

    /// Makes the shape a sensor (it reports overlaps, never pushes) or a
    /// solid shape again.
    pub fn set_shape_sensor(
        &mut self,
        shape: ShapeHandle,
        is_sensor: bool,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        let body = self.collision.shapes.at(slot).body;
        self.collision.shapes.at_mut(slot).def.is_sensor = is_sensor;
        self.collision.shapes.refresh_extent(body.index as usize);
        self.repair_shape(slot);
        Ok(())
    }

    // ----- joints --------------------------------------------------------

    /// The joint's opaque user value (0 until set).
    pub fn joint_user_data(&self, joint: JointHandle) -> Result<u64, WorldError> {
        self.joints.user_data(joint)
    }

    /// Sets the joint's opaque user value.
    pub fn set_joint_user_data(
        &mut self,
        joint: JointHandle,
        value: u64,
    ) -> Result<(), WorldError> {
        self.joints.set_user_data(joint, value)
    }
}
