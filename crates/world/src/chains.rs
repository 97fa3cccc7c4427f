//! Chains (Box2D's `b2ChainDef` / `b2CreateChain`): one handle for a
//! line or loop of one-sided segments on one body, each segment a
//! [`ChainSegment`](janus2d_core::geometry::ChainSegment) shape with its
//! ghost vertices and its own surface material.
//!
//! ```text
//! ChainSet
//!   slots   Slots<ChainData>   chain handle → [segment shape handle], loop flag, user data
//! ```
//!
//! The segment shapes live in the shape store like any other shape; the
//! chain only lists them. A segment shape is destroyed with its chain
//! ([`World::destroy_chain`](crate::World::destroy_chain)) or its body,
//! never alone: [`World::destroy_shape`](crate::World::destroy_shape)
//! refuses it with [`WorldError::ChainSegmentShape`].

use janus2d_core::handle::{ChainTag, Handle};
use janus2d_core::material::CombineRule;
use janus2d_core::math::{Real, Vec2, vec_is_finite};
use janus2d_core::slots::Slots;

use crate::error::WorldError;
use crate::shapes::{Filter, ShapeDef, ShapeHandle};

/// A generational handle to a chain ([`World::create_chain`](crate::World::create_chain)).
///
/// ```
/// use janus2d_world::{ChainDef, ChainHandle, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let g = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let chain: ChainHandle = world.create_chain(g, &ChainDef::new(vec![Vec2::ZERO, Vec2::X])).unwrap();
/// assert_eq!(world.chain_handles(), vec![chain]);
/// ```
pub type ChainHandle = Handle<ChainTag>;

/// The surface fields of a shape, one per chain segment (Box2D's
/// `b2SurfaceMaterial`): the same fields, meanings and limits as in
/// [`ShapeDef`].
///
/// ```
/// use janus2d_world::SurfaceMaterial;
/// let ice = SurfaceMaterial::default().with_friction(0.02).with_material_id(9);
/// assert_eq!((ice.friction, ice.restitution, ice.user_material_id), (0.02, 0.0, 9));
/// assert!(ice.validate().is_ok());
/// assert!(SurfaceMaterial::default().with_friction(-1.0).validate().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SurfaceMaterial {
    /// Friction coefficient (usual 0.6).
    pub friction: Real,
    /// Restitution (usual 0).
    pub restitution: Real,
    /// Rolling resistance (usual 0; see [`ShapeDef::rolling_resistance`]).
    pub rolling_resistance: Real,
    /// Tangent speed, m/s (usual 0; see [`ShapeDef::tangent_speed`]).
    pub tangent_speed: Real,
    /// Friction combine rule (usual [`CombineRule::Default`]).
    pub friction_combine: CombineRule,
    /// Restitution combine rule (usual [`CombineRule::Default`]).
    pub restitution_combine: CombineRule,
    /// The user's material id (usual 0; see [`ShapeDef::user_material_id`]).
    pub user_material_id: u64,
}

impl Default for SurfaceMaterial {
    fn default() -> Self {
        let d = ShapeDef::default();
        SurfaceMaterial {
            friction: d.friction,
            restitution: d.restitution,
            rolling_resistance: d.rolling_resistance,
            tangent_speed: d.tangent_speed,
            friction_combine: d.friction_combine,
            restitution_combine: d.restitution_combine,
            user_material_id: d.user_material_id,
        }
    }
}

impl SurfaceMaterial {
    /// Sets the friction (builder style).
    ///
    /// ```
    /// use janus2d_world::SurfaceMaterial;
    /// assert_eq!(SurfaceMaterial::default().with_friction(0.9).friction, 0.9);
    /// ```
    #[must_use]
    pub fn with_friction(mut self, friction: Real) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the restitution (builder style).
    ///
    /// ```
    /// use janus2d_world::SurfaceMaterial;
    /// assert_eq!(SurfaceMaterial::default().with_restitution(0.5).restitution, 0.5);
    /// ```
    #[must_use]
    pub fn with_restitution(mut self, restitution: Real) -> Self {
        self.restitution = restitution;
        self
    }

    /// Sets the rolling resistance (builder style).
    ///
    /// ```
    /// use janus2d_world::SurfaceMaterial;
    /// assert_eq!(SurfaceMaterial::default().with_rolling_resistance(0.1).rolling_resistance, 0.1);
    /// ```
    #[must_use]
    pub fn with_rolling_resistance(mut self, rolling_resistance: Real) -> Self {
        self.rolling_resistance = rolling_resistance;
        self
    }

    /// Sets the tangent speed, m/s (builder style).
    ///
    /// ```
    /// use janus2d_world::SurfaceMaterial;
    /// assert_eq!(SurfaceMaterial::default().with_tangent_speed(2.0).tangent_speed, 2.0);
    /// ```
    #[must_use]
    pub fn with_tangent_speed(mut self, tangent_speed: Real) -> Self {
        self.tangent_speed = tangent_speed;
        self
    }

    /// Sets the user's material id (builder style).
    ///
    /// ```
    /// use janus2d_world::SurfaceMaterial;
    /// assert_eq!(SurfaceMaterial::default().with_material_id(4).user_material_id, 4);
    /// ```
    #[must_use]
    pub fn with_material_id(mut self, id: u64) -> Self {
        self.user_material_id = id;
        self
    }

    /// Writes the material into a shape definition.
    fn apply(&self, def: &mut ShapeDef) {
        def.friction = self.friction;
        def.restitution = self.restitution;
        def.rolling_resistance = self.rolling_resistance;
        def.tangent_speed = self.tangent_speed;
        def.friction_combine = self.friction_combine;
        def.restitution_combine = self.restitution_combine;
        def.user_material_id = self.user_material_id;
    }

    /// Checks the fields as [`ShapeDef::validate`] does (the error names
    /// the field).
    ///
    /// ```
    /// use janus2d_world::{SurfaceMaterial, WorldError};
    /// let bad = SurfaceMaterial::default().with_restitution(-0.5);
    /// assert_eq!(bad.validate(), Err(WorldError::OutOfRange("restitution")));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let mut def = ShapeDef::default();
        self.apply(&mut def);
        def.validate()
    }
}

/// Everything needed to create a chain (Box2D's `b2ChainDef`).
///
/// An open chain through `n` points has `n - 1` segments, a loop `n`
/// (the last joins the last point to the first). Segments are one-sided:
/// see [`ChainSegment`](janus2d_core::geometry::ChainSegment) for the side
/// convention (ground walked on from above runs right to left; a loop
/// given clockwise holds things inside it).
///
/// ```
/// use janus2d_world::{ChainDef, SurfaceMaterial};
/// use janus2d_core::Vec2;
/// let def = ChainDef::new(vec![Vec2::new(4.0, 0.0), Vec2::new(0.0, 0.0), Vec2::new(-4.0, 0.0)])
///     .with_material(SurfaceMaterial::default().with_friction(0.2));
/// assert_eq!(def.segment_count(), 2);
/// assert!(def.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ChainDef {
    /// The chain's points in the body frame, m.
    pub points: Vec<Vec2>,
    /// Whether the last point joins the first (usual false).
    pub is_loop: bool,
    /// One material for every segment, or one per segment in segment
    /// order (usual one default material).
    pub materials: Vec<SurfaceMaterial>,
    /// Collision filter of every segment.
    pub filter: Filter,
    /// Opaque user value of the chain (and of each segment shape).
    pub user_data: u64,
    /// Sensor events on the segments (usual true; see
    /// [`ShapeDef::enable_sensor_events`]).
    pub enable_sensor_events: bool,
    /// Contact begin/end events on the segments (usual true).
    pub enable_contact_events: bool,
    /// Hit events on the segments (usual false).
    pub enable_hit_events: bool,
}

impl ChainDef {
    /// An open chain through `points` with one default material.
    ///
    /// ```
    /// use janus2d_world::ChainDef;
    /// use janus2d_core::Vec2;
    /// let def = ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)]);
    /// assert!(!def.is_loop && def.materials.len() == 1);
    /// ```
    #[must_use]
    pub fn new(points: Vec<Vec2>) -> Self {
        ChainDef {
            points,
            is_loop: false,
            materials: vec![SurfaceMaterial::default()],
            filter: Filter::default(),
            user_data: 0,
            enable_sensor_events: true,
            enable_contact_events: true,
            enable_hit_events: false,
        }
    }

    /// Makes the chain a loop or not (builder style).
    ///
    /// ```
    /// use janus2d_world::ChainDef;
    /// use janus2d_core::Vec2;
    /// let def = ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)]).with_loop(true);
    /// assert_eq!(def.segment_count(), 3);
    /// ```
    #[must_use]
    pub fn with_loop(mut self, is_loop: bool) -> Self {
        self.is_loop = is_loop;
        self
    }

    /// One material for every segment (builder style).
    ///
    /// ```
    /// use janus2d_world::{ChainDef, SurfaceMaterial};
    /// use janus2d_core::Vec2;
    /// let def = ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])
    ///     .with_material(SurfaceMaterial::default().with_friction(0.1));
    /// assert_eq!(def.materials, vec![SurfaceMaterial::default().with_friction(0.1)]);
    /// ```
    #[must_use]
    pub fn with_material(mut self, material: SurfaceMaterial) -> Self {
        self.materials = vec![material];
        self
    }

    /// One material per segment, in segment order (builder style; the
    /// count must be the segment count, see [`validate`](Self::validate)).
    ///
    /// ```
    /// use janus2d_world::{ChainDef, SurfaceMaterial};
    /// use janus2d_core::Vec2;
    /// let ice = SurfaceMaterial::default().with_friction(0.0);
    /// let def = ChainDef::new(vec![Vec2::new(2.0, 0.0), Vec2::ZERO, Vec2::new(-2.0, 0.0)])
    ///     .with_segment_materials(vec![ice, SurfaceMaterial::default()]);
    /// assert!(def.validate().is_ok());
    /// ```
    #[must_use]
    pub fn with_segment_materials(mut self, materials: Vec<SurfaceMaterial>) -> Self {
        self.materials = materials;
        self
    }

    /// Sets the collision filter of every segment (builder style).
    ///
    /// ```
    /// use janus2d_world::{ChainDef, Filter};
    /// use janus2d_core::Vec2;
    /// let def = ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)]).with_filter(Filter::new(2, 1));
    /// assert_eq!(def.filter.category_bits, 2);
    /// ```
    #[must_use]
    pub fn with_filter(mut self, filter: Filter) -> Self {
        self.filter = filter;
        self
    }

    /// Sets the opaque user value (builder style).
    ///
    /// ```
    /// use janus2d_world::ChainDef;
    /// use janus2d_core::Vec2;
    /// assert_eq!(ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)]).with_user_data(5).user_data, 5);
    /// ```
    #[must_use]
    pub fn with_user_data(mut self, value: u64) -> Self {
        self.user_data = value;
        self
    }

    /// The number of segments the points make (0 when too few).
    ///
    /// ```
    /// use janus2d_world::ChainDef;
    /// use janus2d_core::Vec2;
    /// let pts = vec![Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0)];
    /// assert_eq!(ChainDef::new(pts.clone()).segment_count(), 2);
    /// assert_eq!(ChainDef::new(pts).with_loop(true).segment_count(), 3);
    /// ```
    #[must_use]
    pub fn segment_count(&self) -> usize {
        let n = self.points.len();
        match (self.is_loop, n) {
            (true, n) if n >= 3 => n,
            (false, n) if n >= 2 => n - 1,
            _ => 0,
        }
    }

    /// Checks the definition: at least 2 points (3 for a loop), every
    /// point finite and within [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT),
    /// no segment shorter than [`WELD_DISTANCE`](janus2d_core::geometry::WELD_DISTANCE),
    /// one material or one per segment, each valid.
    ///
    /// | problem | error |
    /// |---|---|
    /// | too few points | `Geometry(TooFewPoints { found, needed })` |
    /// | a non-finite point | `NonFinite("points")` |
    /// | a point beyond `MAX_EXTENT` | `OutOfBounds { field: "points", .. }` |
    /// | a zero-length segment | `Geometry(DegenerateSegment)` |
    /// | material count not 1 nor the segment count | `OutOfRange("materials")` |
    /// | a bad material | the field's error, as [`ShapeDef::validate`] |
    ///
    /// ```
    /// use janus2d_world::{ChainDef, WorldError};
    /// use janus2d_core::Vec2;
    /// use janus2d_core::geometry::GeometryError;
    /// let one = ChainDef::new(vec![Vec2::ZERO]);
    /// assert_eq!(one.validate(), Err(WorldError::Geometry(GeometryError::TooFewPoints { found: 1, needed: 2 })));
    /// let flat = ChainDef::new(vec![Vec2::ZERO, Vec2::ZERO]);
    /// assert_eq!(flat.validate(), Err(WorldError::Geometry(GeometryError::DegenerateSegment)));
    /// ```
    pub fn validate(&self) -> Result<(), WorldError> {
        let n = self.points.len();
        let needed = if self.is_loop { 3 } else { 2 };
        if n < needed {
            return Err(WorldError::Geometry(
                janus2d_core::geometry::GeometryError::TooFewPoints { found: n, needed },
            ));
        }
        let max = janus2d_core::limits::MAX_EXTENT;
        for p in &self.points {
            if !vec_is_finite(*p) {
                return Err(WorldError::NonFinite("points"));
            }
            if p.x.abs() > max || p.y.abs() > max {
                return Err(WorldError::OutOfBounds {
                    field: "points",
                    min: -max,
                    max,
                });
            }
        }
        let segments = self.segment_count();
        if self.materials.len() != 1 && self.materials.len() != segments {
            return Err(WorldError::OutOfRange("materials"));
        }
        for m in &self.materials {
            m.validate()?;
        }
        // Zero-length segments (make_chain's own check).
        janus2d_core::geometry::make_chain(&self.points, self.is_loop)?;
        Ok(())
    }

    /// The shape definition of segment `i` (its material, the chain's
    /// filter, events and user data).
    pub(crate) fn segment_def(&self, i: usize) -> ShapeDef {
        let mut def = ShapeDef::default()
            .with_filter(self.filter)
            .with_user_data(self.user_data)
            .with_contact_events(self.enable_contact_events)
            .with_sensor_events(self.enable_sensor_events)
            .with_hit_events(self.enable_hit_events);
        let m = self
            .materials
            .get(i)
            .or_else(|| self.materials.first())
            .copied()
            .unwrap_or_default();
        m.apply(&mut def);
        def
    }
}

/// A chain as stored: its segment shapes in segment order.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct ChainData {
    /// The segment shapes, in segment order.
    pub(crate) segments: Vec<ShapeHandle>,
    /// Whether the chain is a loop.
    pub(crate) is_loop: bool,
    /// The opaque user value.
    pub(crate) user_data: u64,
}

/// The world's chains.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct ChainSet {
    pub(crate) slots: Slots<ChainData>,
}

impl ChainSet {
    /// The chain a segment shape belongs to, if any (a scan: chains are
    /// few, and a world without chains pays one length test).
    pub(crate) fn chain_of_shape(&self, shape: ShapeHandle) -> Option<u32> {
        if self.slots.is_empty() {
            return None;
        }
        self.slots
            .iter()
            .find(|(_, c)| c.segments.contains(&shape))
            .map(|(i, _)| i)
    }
}
