//! Changing a shape's geometry in place: one checked setter for any
//! kind, typed conveniences, and a uniform scale.
//!
//! A new geometry is validated first (the world is unchanged on error);
//! then the shape's contacts end (end events for touching ones), its
//! broadphase proxy is made again around the new box (so its pairs are
//! found at the next step and the narrowphase collides the new geometry),
//! the body's mass, centre and inertia follow its shapes unless its mass
//! was set directly, and the body wakes.

use super::*;
use crate::error::WorldError;
use crate::shapes::ShapeHandle;
use janus2d_core::body::BodyType;
use janus2d_core::geometry::{Capsule, ChainSegment, Circle, Polygon, Segment};
use janus2d_core::math::Real;

impl crate::collision::Collision {
    /// Gives live shape `slot` a new (validated) geometry on a body at
    /// pose `xf`: its contacts end, its proxy is made again (its pairs
    /// are found at the next pair update), its box and its body's extents
    /// follow.
    pub(crate) fn reshape(&mut self, slot: u32, geometry: Shape, xf: &Transform, is_static: bool) {
        let body = self.shapes.at(slot).body;
        self.contacts.destroy_of_body(body, &mut self.events, |c| {
            c.shape_a == slot || c.shape_b == slot
        });
        let old = self.shapes.at(slot).proxy;
        self.broadphase.destroy_proxy(old);
        let aabb = geometry.compute_aabb(xf);
        let proxy = if old == crate::broadphase::NO_PROXY {
            // A disabled body's shape: still no proxy.
            old
        } else {
            let margin = crate::broadphase::proxy_margin(&geometry, self.broadphase.margin());
            let bits = self.shapes.at(slot).def.filter.bits();
            self.broadphase.create_proxy_filtered(
                crate::broadphase::bounded(aabb),
                slot,
                is_static,
                margin,
                bits,
            )
        };
        let shape = self.shapes.at_mut(slot);
        shape.geometry = geometry;
        shape.aabb = aabb;
        shape.proxy = proxy;
        self.shapes.refresh_extent(body);
    }
}

impl World {
    /// Replaces a shape's geometry (any kind, the kind may change; body
    /// frame, as at creation). The shape keeps its handle, material and
    /// filter; its contacts end (end events for touching ones) and are
    /// found again at the next step against the new geometry; its body's
    /// mass, centre and inertia are recomputed from its shapes unless the
    /// mass was set directly ([`World::set_mass`]); the body wakes.
    ///
    /// Errors (the world unchanged): a stale or foreign handle; an invalid
    /// geometry ([`WorldError::Geometry`]); a mass beyond the largest body
    /// mass at the shape's density (`OutOfBounds("density")`); a body
    /// that carries or is crossing a portal
    /// ([`WorldError::PortalBody`]: its copies' shapes are scaled copies of
    /// these).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Circle, Polygon};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// assert!((world.mass(b).unwrap() - 1.0).abs() < 1e-6);
    /// world.set_shape_geometry(s, Polygon::make_box(1.0, 1.0)).unwrap();
    /// assert!((world.mass(b).unwrap() - 4.0).abs() < 1e-5);
    /// // A degenerate circle is a typed error; nothing changes.
    /// assert!(world.set_circle(s, Circle { center: Vec2::ZERO, radius: 0.0 }).is_err());
    /// assert!((world.mass(b).unwrap() - 4.0).abs() < 1e-5);
    /// ```
    pub fn set_shape_geometry(
        &mut self,
        shape: ShapeHandle,
        geometry: impl Into<Shape>,
    ) -> Result<(), WorldError> {
        let geometry = geometry.into();
        let slot = self.shape_slot(shape)?;
        geometry.validate()?;
        // A chain's segment stays a chain segment.
        if !matches!(geometry, Shape::ChainSegment(_))
            && self.collision.chains.chain_of_shape(shape).is_some()
        {
            return Err(WorldError::ChainSegmentShape);
        }
        let data = self.collision.shapes.at(slot);
        let body = data.body;
        check_shape_mass(&geometry, data.def.density)?;
        if self.portals.involves(body) {
            return Err(WorldError::PortalBody);
        }
        let sim = self.bodies.sim(body).ok_or(WorldError::StaleBody)?;
        let (xf, ty) = (sim.transform, sim.body_type);
        // Wake first: the contacts of a sleeping island are not in the
        // awake list the contact removal walks.
        self.wake_island(body);
        self.wake_shape_contacts_of(slot);
        self.collision
            .reshape(slot, geometry, &xf, ty == BodyType::Static);
        let follows = self.bodies.record(body).is_some_and(|r| !r.mass_override);
        if ty == BodyType::Dynamic && follows {
            self.update_mass_from_shapes(body);
        }
        Ok(())
    }

    /// Wakes the bodies touching shape `slot` (before its contacts go).
    fn wake_shape_contacts_of(&mut self, slot: u32) {
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
    }

    /// Makes the shape a circle ([`set_shape_geometry`](Self::set_shape_geometry)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Circle, Shape};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// world.set_circle(s, Circle::new(Vec2::ZERO, 1.0).unwrap()).unwrap();
    /// assert!(matches!(world.shape(s).unwrap().geometry, Shape::Circle(c) if c.radius == 1.0));
    /// ```
    pub fn set_circle(&mut self, shape: ShapeHandle, circle: Circle) -> Result<(), WorldError> {
        self.set_shape_geometry(shape, circle)
    }

    /// Makes the shape a capsule ([`set_shape_geometry`](Self::set_shape_geometry)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Capsule, Circle};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// let capsule = Capsule::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0), 0.5).unwrap();
    /// world.set_capsule(s, capsule).unwrap();
    /// assert!(world.mass(b).unwrap() > 2.0);
    /// ```
    pub fn set_capsule(&mut self, shape: ShapeHandle, capsule: Capsule) -> Result<(), WorldError> {
        self.set_shape_geometry(shape, capsule)
    }

    /// Makes the shape a convex (possibly rounded) polygon
    /// ([`set_shape_geometry`](Self::set_shape_geometry)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.set_polygon(s, Polygon::make_rounded_box(0.4, 0.4, 0.1)).unwrap();
    /// assert!(world.mass(b).unwrap() < 1.0);
    /// ```
    pub fn set_polygon(&mut self, shape: ShapeHandle, polygon: Polygon) -> Result<(), WorldError> {
        self.set_shape_geometry(shape, polygon)
    }

    /// Makes the shape a two-sided segment
    /// ([`set_shape_geometry`](Self::set_shape_geometry)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Segment;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let s = world
    ///     .create_shape(g, &ShapeDef::default(), Segment::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0)).unwrap())
    ///     .unwrap();
    /// world.set_segment(s, Segment::new(Vec2::new(-5.0, 0.0), Vec2::new(5.0, 0.0)).unwrap()).unwrap();
    /// assert_eq!(world.shape(s).unwrap().aabb.upper.x, 5.0);
    /// ```
    pub fn set_segment(&mut self, shape: ShapeHandle, segment: Segment) -> Result<(), WorldError> {
        self.set_shape_geometry(shape, segment)
    }

    /// Makes the shape a one-sided chain segment
    /// ([`set_shape_geometry`](Self::set_shape_geometry)); the one setter
    /// a chain's segments accept.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::make_chain;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let segs = make_chain(&[Vec2::new(1.0, 0.0), Vec2::new(-1.0, 0.0)], false).unwrap();
    /// let s = world.create_shape(g, &ShapeDef::default(), segs[0]).unwrap();
    /// let lower = make_chain(&[Vec2::new(1.0, -0.5), Vec2::new(-1.0, -0.5)], false).unwrap();
    /// world.set_chain_segment(s, lower[0]).unwrap();
    /// assert_eq!(world.shape(s).unwrap().aabb.lower.y, -0.5);
    /// ```
    pub fn set_chain_segment(
        &mut self,
        shape: ShapeHandle,
        segment: ChainSegment,
    ) -> Result<(), WorldError> {
        self.set_shape_geometry(shape, segment)
    }

    /// Scales a shape by `factor` about its body's origin (every point
    /// `x` of the body frame goes to `factor · x`, radii are multiplied by
    /// `factor`, areas by `factor²`), through
    /// [`set_shape_geometry`](Self::set_shape_geometry): scaling every
    /// shape of a body by the same factor scales the whole object.
    ///
    /// Errors (the world unchanged): a non-finite factor
    /// (`NonFinite("factor")`), one not above 0 (`OutOfRange("factor")`),
    /// and those of [`set_shape_geometry`](Self::set_shape_geometry) (a
    /// scaled geometry too small or too large to be valid).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let s = world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.scale_shape(s, 3.0).unwrap();
    /// assert!((world.mass(b).unwrap() - 9.0).abs() < 1e-4);
    /// ```
    pub fn scale_shape(&mut self, shape: ShapeHandle, factor: Real) -> Result<(), WorldError> {
        if !factor.is_finite() {
            return Err(WorldError::NonFinite("factor"));
        }
        if factor <= 0.0 {
            return Err(WorldError::OutOfRange("factor"));
        }
        let slot = self.shape_slot(shape)?;
        let scaled = self
            .collision
            .shapes
            .at(slot)
            .geometry
            .scaled(factor, Vec2::ZERO);
        self.set_shape_geometry(shape, scaled)
    }
}
