//! The user's callbacks and how a contact's material is mixed.
//!
//! | callback | set with | asked |
//! |----------|----------|-------|
//! | pre-solve ([`PreSolveFn`]) | `World::set_pre_solve` | each step, per touching solid contact, before the solve |
//! | pair filter ([`PairFilterFn`]) | `World::set_pair_filter` | when the broadphase finds a new pair, after the category/group filter |
//! | friction, restitution ([`MixFn`]) | `World::set_friction_callback`, `World::set_restitution_callback` | when a contact is created or its shapes' materials change |
//!
//! Callbacks are not state: snapshots neither hold nor restore them
//! (`World::restore` keeps the world's own), and scene files do not list
//! them.

use janus2d_core::geometry::Shape;
use janus2d_core::limits::{MAX_FRICTION, MAX_RESTITUTION};
use janus2d_core::material::{Property, combine, mix_rolling_resistance, mix_tangent_speed};
use janus2d_core::math::Real;

use crate::narrowphase::PreSolveFn;
use crate::shapes::{ShapeData, ShapeHandle};

/// A custom pair filter (Box2D's `b2CustomFilterFcn`): asked with the two
/// shapes when the broadphase finds a new pair that passed the shapes'
/// category, mask and group filter (and the joints' no-collide pairs);
/// `false` makes no contact between them. A pair it turned down is asked
/// again when the broadphase reports it again (a shape moved out of its
/// fattened box); existing contacts are not asked again.
///
/// ```
/// use janus2d_world::{PairFilterFn, ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// world.create_shape(b, &ShapeDef::default().with_user_data(1), Polygon::make_box(0.5, 0.5)).unwrap();
/// // Nothing collides: the box falls through the ground.
/// let never: PairFilterFn = Box::new(|_, _| false);
/// world.set_pair_filter(Some(never));
/// for _ in 0..60 { world.step(1.0 / 60.0).unwrap(); }
/// assert_eq!(world.contact_count(), 0);
/// assert!(world.position(b).unwrap().y < -1.0);
/// ```
pub type PairFilterFn = Box<dyn FnMut(ShapeHandle, ShapeHandle) -> bool + Send>;

/// A friction or restitution callback (Box2D's `b2FrictionCallback`,
/// `b2RestitutionCallback`): `(value_a, user_material_id_a, value_b,
/// user_material_id_b) → mixed`, in place of the shapes' combine rules.
/// A result that is not finite falls back to the combine rules; it is
/// clamped to `[0, MAX_FRICTION]` (or `[0, MAX_RESTITUTION]`).
///
/// ```
/// use janus2d_world::{MixFn, ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(ground, &ShapeDef::default().with_material_id(1), Polygon::make_box(5.0, 0.5)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// world.create_shape(b, &ShapeDef::default().with_material_id(2), Polygon::make_box(0.5, 0.5)).unwrap();
/// // Material pair (1, 2) is ice, whatever the shapes' frictions.
/// let ice: MixFn = Box::new(|fa, ma, fb, mb| if ma.min(mb) == 1 && ma.max(mb) == 2 { 0.01 } else { (fa * fb).sqrt() });
/// world.set_friction_callback(Some(ice));
/// world.step(1.0 / 60.0).unwrap();
/// assert_eq!(world.contacts().next().unwrap().friction, 0.01);
/// ```
pub type MixFn = Box<dyn Fn(Real, u64, Real, u64) -> Real + Send>;

/// The world's callbacks (none by default).
#[derive(Default)]
pub(crate) struct Hooks {
    pub(crate) pre_solve: Option<PreSolveFn>,
    pub(crate) pair_filter: Option<PairFilterFn>,
    pub(crate) friction: Option<MixFn>,
    pub(crate) restitution: Option<MixFn>,
}

impl std::fmt::Debug for Hooks {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Hooks")
            .field("pre_solve", &self.pre_solve.is_some())
            .field("pair_filter", &self.pair_filter.is_some())
            .field("friction", &self.friction.is_some())
            .field("restitution", &self.restitution.is_some())
            .finish()
    }
}

/// A contact's mixed material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Mixed {
    pub(crate) friction: Real,
    pub(crate) restitution: Real,
    pub(crate) tangent_speed: Real,
    pub(crate) rolling_resistance: Real,
}

/// The radius a shape rolls on (Box2D's): a circle's or a capsule's
/// radius, a polygon's rounding; 0 for segments.
fn rolling_radius(shape: &Shape) -> Real {
    match shape {
        Shape::Circle(c) => c.radius,
        Shape::Capsule(c) => c.radius,
        Shape::Polygon(p) => p.radius,
        Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
    }
}

impl Hooks {
    /// The material of a contact between shapes `a` and `b`: the
    /// callbacks where set, else the shapes' combine rules; the surface
    /// terms by their fixed rules (`janus2d_core::material`).
    pub(crate) fn mix(&self, a: &ShapeData, b: &ShapeData) -> Mixed {
        let (da, db) = (&a.def, &b.def);
        // (Multiply may pass the limit a shape's own value keeps to.)
        let by_rule = |property, x, rule_x, y, rule_y, max: Real| {
            combine(property, x, rule_x, y, rule_y).min(max)
        };
        let callback = |hook: &Option<MixFn>, x: Real, y: Real, max: Real| {
            hook.as_ref()
                .map(|f| f(x, da.user_material_id, y, db.user_material_id))
                .filter(|v| v.is_finite())
                .map(|v| v.clamp(0.0, max))
        };
        let friction = callback(&self.friction, da.friction, db.friction, MAX_FRICTION)
            .unwrap_or_else(|| {
                by_rule(
                    Property::Friction,
                    da.friction,
                    da.friction_combine,
                    db.friction,
                    db.friction_combine,
                    MAX_FRICTION,
                )
            });
        let restitution = callback(
            &self.restitution,
            da.restitution,
            db.restitution,
            MAX_RESTITUTION,
        )
        .unwrap_or_else(|| {
            by_rule(
                Property::Restitution,
                da.restitution,
                da.restitution_combine,
                db.restitution,
                db.restitution_combine,
                MAX_RESTITUTION,
            )
        });
        let rolling_resistance = if da.rolling_resistance > 0.0 || db.rolling_resistance > 0.0 {
            mix_rolling_resistance(
                da.rolling_resistance,
                rolling_radius(&a.geometry),
                db.rolling_resistance,
                rolling_radius(&b.geometry),
            )
        } else {
            0.0
        };
        Mixed {
            friction,
            restitution,
            tangent_speed: mix_tangent_speed(da.tangent_speed, db.tangent_speed),
            rolling_resistance,
        }
    }
}
