//! Shapes, their materials and filters, and the contacts between them
//! as read after the step.

use super::*;
use crate::error::WorldError;
use crate::shapes::{Filter, ShapeHandle};
use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::math::Real;

impl World {
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
        // The offset is baked into the geometry (and the stored definition
        // keeps the identity).
        let (geometry, def) = if def.offset == Transform::IDENTITY {
            (geometry, std::borrow::Cow::Borrowed(def))
        } else {
            let q = def.offset.q.to_unit().unwrap_or(Rot::IDENTITY);
            let moved = geometry.transformed(&Transform { p: def.offset.p, q });
            moved.validate()?;
            let mut stored = def.clone();
            stored.offset = Transform::IDENTITY;
            (moved, std::borrow::Cow::Owned(stored))
        };
        let def = def.as_ref();
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
            self.wake_island(body);
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
    ///
    /// A chain's segment shape is refused with
    /// [`WorldError::ChainSegmentShape`]: it goes with its chain
    /// ([`World::destroy_chain`]).
    pub fn destroy_shape(&mut self, shape: ShapeHandle) -> Result<(), WorldError> {
        let slot = self.collision.shapes.slot(shape, self.bodies.owner())?;
        if self.collision.chains.chain_of_shape(shape).is_some() {
            return Err(WorldError::ChainSegmentShape);
        }
        let body = self.collision.shapes.at(slot).body;
        self.wake_island(body);
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

    /// Sets a body's mass from its shapes (see `Stores::mass_from_shapes`).
    pub(crate) fn update_mass_from_shapes(&mut self, body: BodyHandle) {
        self.stores().mass_from_shapes(body);
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
}

/// A material value must be finite and ≥ 0.
pub(super) fn check_material(v: Real, name: &'static str) -> Result<(), WorldError> {
    if !v.is_finite() {
        return Err(WorldError::NonFinite(name));
    }
    if v < 0.0 {
        return Err(WorldError::OutOfRange(name));
    }
    crate::shapes::check_material_limit(v, name)
}

impl World {
    // ----- shapes --------------------------------------------------------

    pub(super) fn shape_slot(&self, shape: ShapeHandle) -> Result<u32, WorldError> {
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

    /// Re-mixes the material of every contact (a material callback was
    /// set or removed).
    pub(super) fn refresh_all_contact_materials(&mut self) {
        let ids: Vec<u32> = self.collision.contacts.iter().map(|c| c.id).collect();
        for id in ids {
            let Some(c) = self.collision.contacts.get(id) else {
                continue;
            };
            let (sa, sb) = (
                self.collision.shapes.at(c.shape_a),
                self.collision.shapes.at(c.shape_b),
            );
            let mixed = self.hooks.mix(sa, sb);
            if let Some(c) = self.collision.contacts.get_mut(id) {
                c.friction = mixed.friction;
                c.restitution = mixed.restitution;
            }
        }
    }

    /// Re-mixes the material of the shape's existing contacts.
    pub(super) fn refresh_contact_materials(&mut self, slot: u32) {
        let hooks = &self.hooks;
        self.collision.update_contacts_of_shape(slot, |sa, sb, c| {
            let mixed = hooks.mix(sa, sb);
            c.friction = mixed.friction;
            c.restitution = mixed.restitution;
            c.tangent_speed = mixed.tangent_speed;
            c.rolling_resistance = mixed.rolling_resistance;
            c.user_material_ids = [sa.def.user_material_id, sb.def.user_material_id];
        });
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

    /// Sets the shape's rolling resistance (finite, ≥ 0; see
    /// [`ShapeDef::rolling_resistance`](crate::ShapeDef)); its contacts
    /// use it from the next step. A bad value is a typed error and
    /// changes nothing.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef, WorldError};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Circle;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// world.set_shape_rolling_resistance(s, 0.1).unwrap();
    /// assert_eq!(world.shape(s).unwrap().def.rolling_resistance, 0.1);
    /// assert_eq!(
    ///     world.set_shape_rolling_resistance(s, -1.0),
    ///     Err(WorldError::OutOfRange("rolling_resistance"))
    /// );
    /// ```
    pub fn set_shape_rolling_resistance(
        &mut self,
        shape: ShapeHandle,
        rolling_resistance: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        check_material(rolling_resistance, "rolling_resistance")?;
        self.collision.shapes.at_mut(slot).def.rolling_resistance = rolling_resistance;
        self.refresh_contact_materials(slot);
        Ok(())
    }

    /// Sets the shape's surface tangent speed, m/s (a conveyor belt; see
    /// [`ShapeDef::tangent_speed`](crate::ShapeDef)); its contacts use it
    /// from the next step and the shape's body wakes (so that what rests
    /// on a sleeping belt moves). Finite, at most
    /// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED) in size.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let belt = world.create_shape(g, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// world.set_shape_tangent_speed(belt, -1.5).unwrap();
    /// assert_eq!(world.shape(belt).unwrap().def.tangent_speed, -1.5);
    /// ```
    pub fn set_shape_tangent_speed(
        &mut self,
        shape: ShapeHandle,
        tangent_speed: Real,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        crate::shapes::check_tangent_speed(tangent_speed)?;
        self.collision.shapes.at_mut(slot).def.tangent_speed = tangent_speed;
        self.refresh_contact_materials(slot);
        self.wake_shape_contacts(slot);
        Ok(())
    }

    /// Sets the shape's user material id (see
    /// [`ShapeDef::user_material_id`](crate::ShapeDef)); its contacts
    /// report it (and the material callbacks see it) from now on.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(g, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
    /// world.set_shape_user_material_id(s, 42).unwrap();
    /// assert_eq!(world.shape(s).unwrap().def.user_material_id, 42);
    /// ```
    pub fn set_shape_user_material_id(
        &mut self,
        shape: ShapeHandle,
        id: u64,
    ) -> Result<(), WorldError> {
        let slot = self.shape_slot(shape)?;
        self.collision.shapes.at_mut(slot).def.user_material_id = id;
        self.refresh_contact_materials(slot);
        Ok(())
    }

    /// Wakes the bodies touching shape `slot` (and its own).
    fn wake_shape_contacts(&mut self, slot: u32) {
        let body = self.collision.shapes.at(slot).body;
        let others: smallvec::SmallVec<[BodyHandle; 8]> = self
            .collision
            .contacts
            .of_body(body)
            .iter()
            .filter_map(|&id| self.collision.contacts.get(id))
            .filter(|c| c.shape_a == slot || c.shape_b == slot)
            .map(|c| c.other(body))
            .collect();
        for b in others {
            self.wake_island(b);
        }
        self.wake_island(body);
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
            self.wake_island(body);
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    /// Ends the shape's contacts (end events for touching ones) and has the
    /// broadphase report its pairs again, under its new filter or sensor flag.
    pub(super) fn repair_shape(&mut self, slot: u32) {
        let body = self.collision.shapes.at(slot).body;
        self.wake_island(body);
        let c = &mut self.collision;
        c.contacts.destroy_of_body(body, &mut c.events, |x| {
            x.shape_a == slot || x.shape_b == slot
        });
        let shape = c.shapes.at(slot);
        let (proxy, bits) = (shape.proxy, shape.def.filter.bits());
        c.broadphase.set_proxy_bits(proxy, bits);
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
        self.collision.shapes.refresh_extent(body);
        self.repair_shape(slot);
        Ok(())
    }
}
