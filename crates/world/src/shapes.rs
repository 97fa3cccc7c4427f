//! The shape store: shapes, their materials and filters, and which body
//! holds which shapes.
//!
//! ```text
//! ShapeStore
//!   slots        Slots<ShapeData>   shape handle → geometry, material, proxy, box
//!   body_shapes  body slot → [shape slot]   (creation order)
//! ```
//!
//! The store owns no contacts: the contact life cycle is in
//! [`contacts`](crate::contacts), pair finding in
//! [`broadphase`](crate::broadphase).

use janus2d_core::body::BodyHandle;
use janus2d_core::geometry::{Aabb, MassData, Shape};
use janus2d_core::handle::{Handle, ShapeTag};
use janus2d_core::material::CombineRule;
use janus2d_core::math::{Real, Transform, Vec2};
use janus2d_core::slots::Slots;
use smallvec::SmallVec;

use crate::error::WorldError;

/// A generational handle to a shape.
pub type ShapeHandle = Handle<ShapeTag>;

/// Which shapes collide: `a` and `b` collide when
/// `(a.category & b.mask) != 0 && (b.category & a.mask) != 0`, unless they
/// share a non-zero group index (positive: always collide; negative: never).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Filter {
    /// The categories this shape belongs to (usual 1).
    pub category_bits: u64,
    /// The categories this shape collides with (usual all).
    pub mask_bits: u64,
    /// Group override (usual 0: none).
    pub group_index: i32,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            category_bits: 1,
            mask_bits: u64::MAX,
            group_index: 0,
        }
    }
}

impl Filter {
    /// A filter in the categories `category_bits` that collides with the
    /// categories `mask_bits`, in no group.
    ///
    /// ```
    /// use janus2d_world::Filter;
    /// let f = Filter::new(0b10, 0b01).with_group(-3);
    /// assert_eq!((f.category_bits, f.mask_bits, f.group_index), (2, 1, -3));
    /// ```
    #[must_use]
    pub fn new(category_bits: u64, mask_bits: u64) -> Self {
        Filter {
            category_bits,
            mask_bits,
            group_index: 0,
        }
    }

    /// Sets the group index (builder style; see [`Filter`]).
    ///
    /// ```
    /// use janus2d_world::Filter;
    /// // Group −1: shapes of this group never collide with each other.
    /// assert_eq!(Filter::new(1, u64::MAX).with_group(-1).group_index, -1);
    /// ```
    #[must_use]
    pub fn with_group(mut self, group_index: i32) -> Self {
        self.group_index = group_index;
        self
    }

    /// The filter in the 16-bit form of the broadphase's pair search
    /// ([`FilterBits::of`](crate::dynamic_tree::FilterBits::of)).
    ///
    /// ```
    /// use janus2d_world::Filter;
    /// let debris = Filter::new(0b100, !0b100);
    /// assert!(!debris.bits().may_pair(debris.bits()));
    /// ```
    #[must_use]
    pub fn bits(&self) -> crate::dynamic_tree::FilterBits {
        crate::dynamic_tree::FilterBits::of(self.category_bits, self.mask_bits, self.group_index)
    }

    /// Whether two filters let their shapes collide.
    ///
    /// ```
    /// use janus2d_world::Filter;
    /// let a = Filter { group_index: -1, ..Filter::default() };
    /// assert!(!a.should_collide(&a));
    /// assert!(Filter::default().should_collide(&Filter::default()));
    /// ```
    #[must_use]
    pub fn should_collide(&self, other: &Filter) -> bool {
        if self.group_index == other.group_index && self.group_index != 0 {
            return self.group_index > 0;
        }
        (self.mask_bits & other.category_bits) != 0 && (self.category_bits & other.mask_bits) != 0
    }
}

/// Everything needed to create a shape besides its geometry.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ShapeDef {
    /// Density, kg/m² (usual 1).
    pub density: Real,
    /// Friction coefficient (usual 0.6).
    pub friction: Real,
    /// Restitution (usual 0).
    pub restitution: Real,
    /// Collision filter.
    pub filter: Filter,
    /// A sensor only reports overlaps; it never pushes.
    pub is_sensor: bool,
    /// Report hit events for this shape's contacts (usual false): after a
    /// step, each contact that pushed with an approach speed above the
    /// world's `hit_event_threshold` gives a [`HitEvent`](crate::HitEvent).
    pub enable_hit_events: bool,
    /// Report contact begin and end events for this shape's solid
    /// contacts (usual true; Box2D's `enableContactEvents`): a pair
    /// reports them when both its shapes have them on.
    pub enable_contact_events: bool,
    /// Report sensor begin and end events for this shape (usual true;
    /// Box2D's `enableSensorEvents`), as the sensor or as the visitor: an
    /// overlap reports them when both its shapes have them on.
    pub enable_sensor_events: bool,
    /// Contact force above which this shape's contacts give a
    /// [`ContactForceEvent`](crate::ContactForceEvent), N (usual
    /// `Real::INFINITY`: never; Rapier's `contact_force_event_threshold`).
    /// A contact uses the smaller of its two shapes' thresholds. Not NaN,
    /// ≥ 0.
    pub force_event_threshold: Real,
    /// Opaque user value.
    pub user_data: u64,
    /// Rolling resistance (usual 0: none; Box2D v3.1's
    /// `rollingResistance`): a contact of a circle or capsule (or rounded
    /// polygon) gets an angular row that resists rolling, its torque
    /// bounded by `c · r · N` with `c` the larger of the two shapes'
    /// resistances, `r` the larger rolling radius and `N` the contact's
    /// normal force. On flat ground a disc rolling at `v₀` stops within
    /// `v₀² / (2 · ⅔ c g)`. Finite, ≥ 0.
    pub rolling_resistance: Real,
    /// Tangent speed of the surface, m/s (usual 0; a conveyor belt): the
    /// surface moves at this speed clockwise around the shape (on the top
    /// face of a box, towards +x), and friction drags what touches it
    /// along. Two shapes' speeds add up
    /// ([`mix_tangent_speed`](janus2d_core::material::mix_tangent_speed)).
    /// Finite, at most [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED) in
    /// size.
    pub tangent_speed: Real,
    /// How this shape's friction combines with the other shape's (usual
    /// [`CombineRule::Default`], `√(μ_a μ_b)`; the stronger rule of the
    /// two applies). A world's friction callback
    /// ([`World::set_friction_callback`](crate::World::set_friction_callback))
    /// replaces the rules.
    pub friction_combine: CombineRule,
    /// How this shape's restitution combines with the other shape's
    /// (usual [`CombineRule::Default`], `max(e_a, e_b)`).
    pub restitution_combine: CombineRule,
    /// The user's material id (usual 0): not used by the engine, passed to
    /// the friction and restitution callbacks and reported with the
    /// shape's contacts ([`Contact::user_material_ids`](crate::Contact),
    /// the pre-solve view) — a sound or particle effect per surface pair.
    pub user_material_id: u64,
    /// Where the geometry sits in the body frame (usual identity): the
    /// geometry given to [`World::create_shape`](crate::World::create_shape)
    /// is moved by this offset and turned by its angle before it is
    /// attached, for every kind (a circle's centre, a capsule's or
    /// segment's points, a polygon's vertices and normals). It is baked
    /// into the stored geometry: the shape's stored definition
    /// ([`ShapeData::def`]) has it back at the identity, and geometry
    /// setters take body-frame geometry as they are given.
    pub offset: Transform,
}

impl Default for ShapeDef {
    fn default() -> Self {
        ShapeDef {
            density: 1.0,
            friction: 0.6,
            restitution: 0.0,
            filter: Filter::default(),
            is_sensor: false,
            enable_hit_events: false,
            enable_contact_events: true,
            enable_sensor_events: true,
            force_event_threshold: Real::INFINITY,
            user_data: 0,
            rolling_resistance: 0.0,
            tangent_speed: 0.0,
            friction_combine: CombineRule::Default,
            restitution_combine: CombineRule::Default,
            user_material_id: 0,
            offset: Transform::IDENTITY,
        }
    }
}

impl ShapeDef {
    /// A sensor: it reports overlaps and never pushes (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// let def = ShapeDef::default().sensor().with_hit_events(false).with_user_data(3);
    /// assert!(def.is_sensor && !def.enable_hit_events);
    /// assert_eq!(def.user_data, 3);
    /// ```
    #[must_use]
    pub fn sensor(mut self) -> Self {
        self.is_sensor = true;
        self
    }

    /// Turns the shape's hit events on or off (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert!(ShapeDef::default().with_hit_events(true).enable_hit_events);
    /// ```
    #[must_use]
    pub fn with_hit_events(mut self, on: bool) -> Self {
        self.enable_hit_events = on;
        self
    }

    /// Turns the shape's contact begin/end events on or off (builder
    /// style; see [`ShapeDef::enable_contact_events`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// let def = ShapeDef::default()
    ///     .with_contact_events(false)
    ///     .with_sensor_events(false)
    ///     .with_force_event_threshold(50.0);
    /// assert!(!def.enable_contact_events && !def.enable_sensor_events);
    /// assert_eq!(def.force_event_threshold, 50.0);
    /// ```
    #[must_use]
    pub fn with_contact_events(mut self, on: bool) -> Self {
        self.enable_contact_events = on;
        self
    }

    /// Turns the shape's sensor events on or off (builder style; see
    /// [`ShapeDef::enable_sensor_events`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert!(!ShapeDef::default().with_sensor_events(false).enable_sensor_events);
    /// ```
    #[must_use]
    pub fn with_sensor_events(mut self, on: bool) -> Self {
        self.enable_sensor_events = on;
        self
    }

    /// Sets the contact force event threshold, N (builder style; see
    /// [`ShapeDef::force_event_threshold`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_force_event_threshold(20.0).force_event_threshold, 20.0);
    /// ```
    #[must_use]
    pub fn with_force_event_threshold(mut self, force: Real) -> Self {
        self.force_event_threshold = force;
        self
    }

    /// Sets the opaque user value (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_user_data(11).user_data, 11);
    /// ```
    #[must_use]
    pub fn with_user_data(mut self, value: u64) -> Self {
        self.user_data = value;
        self
    }

    /// Sets the collision filter (builder style).
    ///
    /// ```
    /// use janus2d_world::{Filter, ShapeDef};
    /// let def = ShapeDef::default()
    ///     .with_filter(Filter::new(0b10, !0b100))
    ///     .with_sensor(true);
    /// assert_eq!(def.filter.category_bits, 2);
    /// assert!(def.is_sensor);
    /// ```
    #[must_use]
    pub fn with_filter(mut self, filter: Filter) -> Self {
        self.filter = filter;
        self
    }

    /// Makes the shape a sensor or not (builder style; [`sensor`](Self::sensor)
    /// is `with_sensor(true)`).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert!(ShapeDef::default().with_sensor(true).is_sensor);
    /// ```
    #[must_use]
    pub fn with_sensor(mut self, on: bool) -> Self {
        self.is_sensor = on;
        self
    }

    /// Sets the friction (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_friction(0.2).friction, 0.2);
    /// ```
    #[must_use]
    pub fn with_friction(mut self, friction: Real) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the density (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_density(3.0).density, 3.0);
    /// ```
    #[must_use]
    pub fn with_density(mut self, density: Real) -> Self {
        self.density = density;
        self
    }

    /// Sets the restitution (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_restitution(0.5).restitution, 0.5);
    /// ```
    #[must_use]
    pub fn with_restitution(mut self, restitution: Real) -> Self {
        self.restitution = restitution;
        self
    }

    /// Sets the rolling resistance (builder style; see
    /// [`ShapeDef::rolling_resistance`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// use janus2d_core::material::CombineRule;
    /// let def = ShapeDef::default()
    ///     .with_rolling_resistance(0.05)
    ///     .with_tangent_speed(2.0)
    ///     .with_friction_combine(CombineRule::Max)
    ///     .with_restitution_combine(CombineRule::Min)
    ///     .with_material_id(7);
    /// assert_eq!((def.rolling_resistance, def.tangent_speed), (0.05, 2.0));
    /// assert_eq!(def.friction_combine, CombineRule::Max);
    /// assert_eq!(def.restitution_combine, CombineRule::Min);
    /// assert_eq!(def.user_material_id, 7);
    /// assert!(def.validate().is_ok());
    /// ```
    #[must_use]
    pub fn with_rolling_resistance(mut self, rolling_resistance: Real) -> Self {
        self.rolling_resistance = rolling_resistance;
        self
    }

    /// Sets the surface's tangent speed, m/s (builder style; see
    /// [`ShapeDef::tangent_speed`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// // A conveyor belt moving its surface at 2 m/s.
    /// assert_eq!(ShapeDef::default().with_tangent_speed(2.0).tangent_speed, 2.0);
    /// ```
    #[must_use]
    pub fn with_tangent_speed(mut self, tangent_speed: Real) -> Self {
        self.tangent_speed = tangent_speed;
        self
    }

    /// Sets the friction combine rule (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// use janus2d_core::material::CombineRule;
    /// assert_eq!(ShapeDef::default().with_friction_combine(CombineRule::Min).friction_combine, CombineRule::Min);
    /// ```
    #[must_use]
    pub fn with_friction_combine(mut self, rule: CombineRule) -> Self {
        self.friction_combine = rule;
        self
    }

    /// Sets the restitution combine rule (builder style).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// use janus2d_core::material::CombineRule;
    /// assert_eq!(ShapeDef::default().with_restitution_combine(CombineRule::Multiply).restitution_combine, CombineRule::Multiply);
    /// ```
    #[must_use]
    pub fn with_restitution_combine(mut self, rule: CombineRule) -> Self {
        self.restitution_combine = rule;
        self
    }

    /// Sets the user's material id (builder style; see
    /// [`ShapeDef::user_material_id`]).
    ///
    /// ```
    /// use janus2d_world::ShapeDef;
    /// assert_eq!(ShapeDef::default().with_material_id(42).user_material_id, 42);
    /// ```
    #[must_use]
    pub fn with_material_id(mut self, id: u64) -> Self {
        self.user_material_id = id;
        self
    }

    /// Places the geometry at `position`, turned by `angle` (rad), in the
    /// body frame (builder style; see [`ShapeDef::offset`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::{Circle, Shape};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let def = ShapeDef::default().with_offset(Vec2::new(2.0, 0.0), 0.0);
    /// let s = world.create_shape(b, &def, Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
    /// assert!(matches!(world.shape(s).unwrap().geometry, Shape::Circle(c) if c.center == Vec2::new(2.0, 0.0)));
    /// // The body's centre of mass follows the offset geometry.
    /// assert!((world.center_of_mass(b).unwrap().x - 2.0).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn with_offset(mut self, position: Vec2, angle: Real) -> Self {
        self.offset = Transform::new(position, angle);
        self
    }

    /// Checks the material: density, friction, restitution and rolling
    /// resistance finite and not negative, the tangent speed finite and
    /// within [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED); the error
    /// names the field.
    ///
    /// ```
    /// use janus2d_world::{ShapeDef, WorldError};
    /// let bad = ShapeDef::default().with_friction(-1.0);
    /// assert_eq!(bad.validate(), Err(WorldError::OutOfRange("friction")));
    /// let bad = ShapeDef::default().with_rolling_resistance(-0.1);
    /// assert_eq!(bad.validate(), Err(WorldError::OutOfRange("rolling_resistance")));
    /// let bad = ShapeDef::default().with_tangent_speed(janus2d_core::math::Real::NAN);
    /// assert_eq!(bad.validate(), Err(WorldError::NonFinite("tangent_speed")));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        for (v, name) in [
            (self.density, "density"),
            (self.friction, "friction"),
            (self.restitution, "restitution"),
            (self.rolling_resistance, "rolling_resistance"),
        ] {
            if !v.is_finite() {
                return Err(WorldError::NonFinite(name));
            }
            if v < 0.0 {
                return Err(WorldError::OutOfRange(name));
            }
        }
        check_material_limit(self.friction, "friction")?;
        check_material_limit(self.restitution, "restitution")?;
        check_force_threshold(self.force_event_threshold)?;
        check_tangent_speed(self.tangent_speed)?;
        check_offset(&self.offset)
    }
}

/// A force event threshold: not NaN, ≥ 0 (infinity: off).
pub(crate) fn check_force_threshold(v: Real) -> Result<(), WorldError> {
    if v.is_nan() {
        return Err(WorldError::NonFinite("force_event_threshold"));
    }
    if v < 0.0 {
        return Err(WorldError::OutOfRange("force_event_threshold"));
    }
    Ok(())
}

/// A shape offset: finite, its position within
/// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT) of the body origin,
/// its rotation of unit length (within
/// [`UNIT_ROTATION_TOLERANCE`](janus2d_core::limits::UNIT_ROTATION_TOLERANCE)).
pub(crate) fn check_offset(xf: &Transform) -> Result<(), WorldError> {
    if !(janus2d_core::math::vec_is_finite(xf.p) && xf.q.is_finite()) {
        return Err(WorldError::NonFinite("offset"));
    }
    let max = janus2d_core::limits::MAX_EXTENT;
    if xf.p.x.abs() > max || xf.p.y.abs() > max {
        return Err(WorldError::OutOfBounds {
            field: "offset",
            min: -max,
            max,
        });
    }
    if xf.q.to_unit().is_none() {
        return Err(WorldError::OutOfRange("offset"));
    }
    Ok(())
}

/// A tangent speed: finite, at most
/// [`MAX_SPEED`](janus2d_core::limits::MAX_SPEED) in size.
pub(crate) fn check_tangent_speed(v: Real) -> Result<(), WorldError> {
    if !v.is_finite() {
        return Err(WorldError::NonFinite("tangent_speed"));
    }
    let max = janus2d_core::limits::MAX_SPEED;
    if v.abs() > max {
        return Err(WorldError::OutOfBounds {
            field: "tangent_speed",
            min: -max,
            max,
        });
    }
    Ok(())
}

/// Friction and restitution within
/// [`MAX_FRICTION`](janus2d_core::limits::MAX_FRICTION) and
/// [`MAX_RESTITUTION`](janus2d_core::limits::MAX_RESTITUTION) (other names
/// pass).
pub(crate) fn check_material_limit(v: Real, name: &'static str) -> Result<(), WorldError> {
    let max = match name {
        "friction" => janus2d_core::limits::MAX_FRICTION,
        "restitution" => janus2d_core::limits::MAX_RESTITUTION,
        _ => return Ok(()),
    };
    if v > max {
        return Err(WorldError::OutOfBounds {
            field: name,
            min: 0.0,
            max,
        });
    }
    Ok(())
}

/// A shape attached to a body.
///
/// Laid out in declaration order (`repr(C)`): the proxy, box, body and
/// geometry the narrowphase reads for every contact first, the definition
/// (read when a pair is made and by the API) last.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct ShapeData {
    /// Broadphase proxy.
    pub proxy: u32,
    /// Tight world box at the end of the last step.
    pub aabb: Aabb,
    /// The body it is attached to.
    pub body: BodyHandle,
    /// Geometry in the body frame.
    pub geometry: Shape,
    /// Material and filter.
    pub def: ShapeDef,
}

/// The size figures of a body's solid shapes that continuous collision
/// reads (kept up to date as shapes come and go).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyExtent {
    /// Smallest [`min_extent`](janus2d_core::geometry::ShapeExtent::min_extent)
    /// of the body's solid shapes, m (`Real::MAX` without one).
    pub min_extent: Real,
    /// Largest distance from the body origin to the surface of a solid
    /// shape, m (0 without one).
    pub max_extent: Real,
    /// Largest distance from the body origin to the core of a solid shape
    /// ([`core_reach`](janus2d_core::geometry::ShapeExtent::core_reach)),
    /// m (0 without one).
    pub core_reach: Real,
}

/// Fraction of a body's smallest extent it may travel in one step before it
/// counts as fast for continuous collision (dimensionless; usual 0.5,
/// Box2D's safety factor).
pub const FAST_FRACTION: Real = 0.5;

impl BodyExtent {
    /// How far a body with these extents may travel in a step before it
    /// counts as fast, m: [`FAST_FRACTION`] of its smallest solid extent,
    /// at least the linear slop; `Real::MAX` without a solid shape.
    #[must_use]
    pub fn fast_travel(&self) -> Real {
        if self.min_extent == Real::MAX {
            return Real::MAX;
        }
        (FAST_FRACTION * self.min_extent).max(janus2d_core::geometry::LINEAR_SLOP)
    }

    /// Widens the extents by a solid shape's (a sensor adds nothing).
    fn take_in(&mut self, shape: &ShapeData) {
        if shape.def.is_sensor {
            return;
        }
        let x = janus2d_core::geometry::shape_extent(&shape.geometry, Vec2::ZERO);
        self.min_extent = self.min_extent.min(x.min_extent);
        self.max_extent = self.max_extent.max(x.max_extent);
        self.core_reach = self.core_reach.max(x.core_reach);
    }
}

impl Default for BodyExtent {
    fn default() -> Self {
        BodyExtent {
            min_extent: Real::MAX,
            max_extent: 0.0,
            core_reach: 0.0,
        }
    }
}

/// Shapes of a world, in generational slots, with each body's list.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ShapeStore {
    slots: Slots<ShapeData>,
    body_shapes: Vec<SmallVec<[u32; 2]>>,
    /// Per body slot, the extents of its solid shapes.
    body_extents: Vec<BodyExtent>,
    /// Bodies whose extents changed since the step last copied them into
    /// their per-step data (`take_extent_changes`), in order of change.
    extent_changes: Vec<BodyHandle>,
    /// Number of live shapes with hit events on (the hit pass runs only
    /// when some shape asks for it).
    hit_event_shapes: usize,
    /// Number of live shapes with a finite force event threshold (the
    /// force pass runs only when some shape has one).
    force_event_shapes: usize,
}

impl ShapeStore {
    /// Number of live shapes with hit events on.
    #[must_use]
    pub fn hit_event_shapes(&self) -> usize {
        self.hit_event_shapes
    }

    /// Number of live shapes with a finite force event threshold.
    #[must_use]
    pub fn force_event_shapes(&self) -> usize {
        self.force_event_shapes
    }

    /// Turns a live shape's hit events on or off, keeping the count.
    pub(crate) fn set_hit_events(&mut self, index: u32, on: bool) {
        let def = &mut self.slots.live_mut(index).def;
        self.hit_event_shapes -= usize::from(def.enable_hit_events);
        def.enable_hit_events = on;
        self.hit_event_shapes += usize::from(on);
    }

    /// Sets a live shape's force event threshold (checked), keeping the
    /// count.
    pub(crate) fn set_force_event_threshold(&mut self, index: u32, force: Real) {
        let def = &mut self.slots.live_mut(index).def;
        self.force_event_shapes -= usize::from(def.force_event_threshold.is_finite());
        def.force_event_threshold = force;
        self.force_event_shapes += usize::from(force.is_finite());
    }

    /// Number of live shapes.
    #[must_use]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when there is no shape.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Asks the cache for shape `index`'s record ahead of a read (the
    /// narrowphase, a few contacts on).
    #[inline(always)]
    pub(crate) fn prefetch(&self, index: u32) {
        self.slots.prefetch(index);
    }

    /// The shape in live slot `index`.
    #[inline]
    #[must_use]
    pub fn at(&self, index: u32) -> &ShapeData {
        self.slots.live(index)
    }

    /// Every shape slot by index as `(generation, shape)` (`None`: free),
    /// for the proxy update's pass on the team ([`Slots::entries_mut`]).
    #[inline]
    pub(crate) fn entries_mut(&mut self) -> &mut [(u32, Option<ShapeData>)] {
        self.slots.entries_mut()
    }

    /// Mutable access to live slot `index`.
    #[inline]
    pub fn at_mut(&mut self, index: u32) -> &mut ShapeData {
        self.slots.live_mut(index)
    }

    /// The slot of a live shape, or why the handle does not resolve.
    pub fn slot(&self, handle: ShapeHandle, owner: u32) -> Result<u32, WorldError> {
        self.slots
            .resolve(handle, owner)
            .map(|_| handle.index)
            .map_err(|e| WorldError::of_handle(e, WorldError::StaleShape))
    }

    /// The handle of live slot `index`.
    #[must_use]
    pub fn handle_of(&self, index: u32, owner: u32) -> ShapeHandle {
        self.slots.handle(index, owner)
    }

    /// The shape slots of a body, in creation order.
    #[inline]
    #[must_use]
    pub fn of_body(&self, body: BodyHandle) -> &[u32] {
        self.body_shapes
            .get(body.index as usize)
            .map_or(&[], |l| l.as_slice())
    }

    /// The extents of a body's solid shapes (see [`BodyExtent`]).
    #[inline]
    #[must_use]
    pub fn extent_of(&self, body: BodyHandle) -> BodyExtent {
        self.body_extents
            .get(body.index as usize)
            .copied()
            .unwrap_or_default()
    }

    /// The bodies whose extents changed since the last call, oldest first
    /// (a body may be listed more than once).
    pub(crate) fn take_extent_changes(&mut self) -> Vec<BodyHandle> {
        std::mem::take(&mut self.extent_changes)
    }

    /// Recomputes the extents of `body` from its solid shapes, and lists
    /// it among the changes the step copies into its per-step data.
    pub(crate) fn refresh_extent(&mut self, body: BodyHandle) {
        let b = self.note_extent_change(body);
        let mut e = BodyExtent::default();
        if let Some(list) = self.body_shapes.get(b) {
            for &s in list {
                e.take_in(self.slots.live(s));
            }
        }
        self.body_extents[b] = e;
    }

    /// Adds the new shape `index` to the extents of `body`: a body built
    /// shape by shape (a ground of thousands of pieces) costs one shape's
    /// extent per shape, not its whole list again. The extents are minima
    /// and maxima, so the result is the recomputed one to the bit.
    fn extend_extent(&mut self, body: BodyHandle, index: u32) {
        let b = self.note_extent_change(body);
        let mut e = self.body_extents[b];
        e.take_in(self.slots.live(index));
        self.body_extents[b] = e;
    }

    /// Lists `body` among the extent changes and makes room for its
    /// extents; returns its slot index.
    fn note_extent_change(&mut self, body: BodyHandle) -> usize {
        if self.extent_changes.last() != Some(&body) {
            self.extent_changes.push(body);
        }
        let b = body.index as usize;
        if self.body_extents.len() <= b {
            self.body_extents.resize(b + 1, BodyExtent::default());
        }
        b
    }

    /// Checks the store against the bodies (for `World::validate`): every
    /// live shape's body is live and lists it, every body list holds live
    /// shapes of that body once, the geometry is valid, material and box
    /// finite, and the hit-event count matches.
    pub(crate) fn check(&self, bodies: &janus2d_core::body::BodySet) -> Result<(), String> {
        self.slots
            .check()
            .map_err(|e| format!("shape slots: {e}"))?;
        let (mut hits, mut forces) = (0, 0);
        for (index, shape) in self.slots.iter() {
            hits += usize::from(shape.def.enable_hit_events);
            forces += usize::from(shape.def.force_event_threshold.is_finite());
            if !bodies.contains(shape.body) {
                return Err(format!("shape {index}: body {:?} is not live", shape.body));
            }
            let listed = self
                .of_body(shape.body)
                .iter()
                .filter(|&&s| s == index)
                .count();
            if listed != 1 {
                return Err(format!(
                    "shape {index}: listed {listed} times under its body"
                ));
            }
            // Portal clones carry scaled copies: cores may be short.
            if let Err(e) = shape.geometry.validate_scaled() {
                return Err(format!("shape {index}: geometry invalid: {e}"));
            }
            let a = &shape.aabb;
            let finite = janus2d_core::math::vec_is_finite(a.lower)
                && janus2d_core::math::vec_is_finite(a.upper)
                && a.lower.x <= a.upper.x
                && a.lower.y <= a.upper.y;
            if !finite || shape.def.validate().is_err() {
                return Err(format!("shape {index}: box or material invalid"));
            }
        }
        if hits != self.hit_event_shapes {
            return Err(format!(
                "{hits} hit-event shapes, counted {}",
                self.hit_event_shapes
            ));
        }
        if forces != self.force_event_shapes {
            return Err(format!(
                "{forces} force-event shapes, counted {}",
                self.force_event_shapes
            ));
        }
        for (b, list) in self.body_shapes.iter().enumerate() {
            for &s in list {
                match self.slots.at(s) {
                    Some(shape) if shape.body.index as usize == b => {}
                    _ => return Err(format!("body slot {b} lists shape {s}, not its own")),
                }
            }
        }
        // The bodies' copies of their extents (what the solve's finalize
        // reads) match the store's, but for changes the next step copies.
        let mut pending = self.extent_changes.clone();
        pending.sort_unstable();
        for body in bodies.handles() {
            if pending.binary_search(&body).is_ok() {
                continue;
            }
            let e = self.extent_of(body);
            let Some(sim) = bodies.sim(body) else {
                continue;
            };
            let travel = e.fast_travel();
            if sim.fast_travel.to_bits() != travel.to_bits()
                || sim.core_reach.to_bits() != e.core_reach.to_bits()
            {
                return Err(format!(
                    "body {body:?}: kept extents ({}, {}) are not its shapes' ({travel}, {})",
                    sim.fast_travel, sim.core_reach, e.core_reach
                ));
            }
        }
        Ok(())
    }

    /// Stores a shape and lists it under its body; returns its slot.
    pub fn insert(&mut self, data: ShapeData) -> u32 {
        let data_body = data.body;
        let b = data.body.index as usize;
        self.hit_event_shapes += usize::from(data.def.enable_hit_events);
        self.force_event_shapes += usize::from(data.def.force_event_threshold.is_finite());
        let (index, _) = self.slots.insert(data);
        if self.body_shapes.len() <= b {
            self.body_shapes.resize(b + 1, SmallVec::new());
        }
        self.body_shapes[b].push(index);
        self.extend_extent(data_body, index);
        index
    }

    /// Removes live slot `index` from the store and its body's list.
    pub fn remove(&mut self, index: u32) -> ShapeData {
        let generation = self.slots.generation(index);
        let data = self
            .slots
            .remove(index, generation)
            .expect("slot index handed out by this store");
        self.hit_event_shapes -= usize::from(data.def.enable_hit_events);
        self.force_event_shapes -= usize::from(data.def.force_event_threshold.is_finite());
        if let Some(list) = self.body_shapes.get_mut(data.body.index as usize) {
            list.retain(|i| *i != index);
        }
        self.refresh_extent(data.body);
        data
    }

    /// Exchanges the shape lists of two bodies whose identities were swapped.
    pub fn swap_bodies(&mut self, a: BodyHandle, b: BodyHandle) {
        let (ia, ib) = (a.index as usize, b.index as usize);
        let n = ia.max(ib) + 1;
        if self.body_shapes.len() < n {
            self.body_shapes.resize(n, SmallVec::new());
        }
        self.body_shapes.swap(ia, ib);
        for k in 0..self.body_shapes[ia].len() {
            let s = self.body_shapes[ia][k];
            self.slots.live_mut(s).body = a;
        }
        for k in 0..self.body_shapes[ib].len() {
            let s = self.body_shapes[ib][k];
            self.slots.live_mut(s).body = b;
        }
        self.refresh_extent(a);
        self.refresh_extent(b);
    }

    /// Exchanges what two live slots hold of their copies of one shape
    /// (geometry, world box, broadphase proxy and density), leaving each
    /// slot its body, its handle and the rest of its definition (material,
    /// filter, flags, user data): after a portal crossing the user's
    /// handle names the shape of the copy that goes on. The caller gives
    /// the proxies their new payloads.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn exchange_copies(&mut self, i: u32, j: u32) {
        if i == j {
            return;
        }
        let a = self.slots.live(i).clone();
        let b = self.slots.live_mut(j);
        let b_old = (
            std::mem::replace(&mut b.geometry, a.geometry),
            std::mem::replace(&mut b.aabb, a.aabb),
            std::mem::replace(&mut b.proxy, a.proxy),
            std::mem::replace(&mut b.def.density, a.def.density),
        );
        let a = self.slots.live_mut(i);
        (a.geometry, a.aabb, a.proxy, a.def.density) = b_old;
        let (bi, bj) = (self.slots.live(i).body, self.slots.live(j).body);
        self.refresh_extent(bi);
        self.refresh_extent(bj);
    }

    /// The mass, centre (body frame) and inertia about the centre of a
    /// body's shapes with positive density.
    #[must_use]
    pub fn mass_of(&self, body: BodyHandle) -> MassData {
        MassData::combine(self.of_body(body).iter().filter_map(|&s| {
            let shape = self.at(s);
            (shape.def.density > 0.0).then(|| shape.geometry.compute_mass(shape.def.density))
        }))
    }

    /// How far a body's shapes reach from a point (its centre of mass), m.
    #[must_use]
    pub fn reach(&self, body: BodyHandle, center: Vec2) -> Real {
        self.of_body(body)
            .iter()
            .map(|&s| self.at(s).aabb.reach_from(center))
            .fold(0.0, Real::max)
    }
}
