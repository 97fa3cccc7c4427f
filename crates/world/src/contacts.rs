//! The contact life cycle: persistent contacts between shapes, found by
//! shape pair and by body, awake or asleep.
//!
//! ```text
//! ContactSet
//!   awake          Vec<Contact>     what the narrowphase and constraint building visit
//!   sleeping       Vec<Contact>     contacts of sleeping islands (no per-step cost)
//!   place          contact id → (list, position)
//!   shape_pairs    shape slot → [(other shape slot, contact id)]
//!                  (is a pair new? the broadphase reports candidates
//!                  grouped by shape, so the list scanned stays in cache)
//!   body_contacts  body slot → [contact id]    (destroy, remove shape, wake walk these)
//!   pair_slots, body_slots  contact id → its position in those lists (O(1) removal)
//!
//! create ─▶ awake ──(island sleeps)──▶ sleeping ──(island wakes)──▶ awake
//!   └────────────── destroy (end event when it was touching) ◀──────────┘
//! ```
//!
//! Contacts keep a stable id for their whole life; their position in a list
//! changes when another one is removed (swap-remove) or when they sleep or
//! wake, always the same way for the same inputs.

use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::math::{Real, Rot, Transform, Vec2};
use smallvec::SmallVec;

use crate::shapes::ShapeHandle;

/// One manifold point with its warm-starting data.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactPointData {
    /// World point, m.
    pub point: Vec2,
    /// Anchor on a relative to a's centre of mass (world frame), m.
    pub anchor_a: Vec2,
    /// Anchor on b relative to b's centre of mass (world frame), m.
    pub anchor_b: Vec2,
    /// Separation when computed (negative: penetration), m.
    pub separation: Real,
    /// Feature id.
    pub id: u16,
    /// Accumulated normal impulse kept for the next step's warm start
    /// (what one substep applies), N·s.
    pub normal_impulse: Real,
    /// Accumulated tangent impulse kept for the warm start, N·s.
    pub tangent_impulse: Real,
    /// Normal impulse the last step applied in all, over every substep,
    /// warm start and restitution, N·s (0 when the contact was not solved
    /// in that step; kept while its bodies sleep). Divided by the step it
    /// is the mean contact force, N.
    pub total_normal_impulse: Real,
    /// Tangent (friction) impulse the last step applied in all, N·s, along
    /// `t = (n.y, −n.x)`.
    pub total_tangent_impulse: Real,
}

/// A persistent contact between two shapes whose fat boxes overlap.
///
/// Laid out in declaration order (`repr(C)`): what the narrowphase and
/// constraint building read every step first, the fields only events and
/// hooks read (id, shape handles, user material ids) last.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[repr(C)]
pub struct Contact {
    /// Shape a (lower slot index).
    pub shape_a: u32,
    /// Shape b.
    pub shape_b: u32,
    /// Body of shape a.
    pub body_a: BodyHandle,
    /// Body of shape b.
    pub body_b: BodyHandle,
    /// Unit normal from a to b.
    pub normal: Vec2,
    /// Points (the first `point_count` are valid).
    pub points: [ContactPointData; 2],
    /// Number of valid points.
    pub point_count: usize,
    /// Mixed friction.
    pub friction: Real,
    /// Mixed restitution.
    pub restitution: Real,
    /// Mixed tangent speed, m/s: the friction rows drive the bodies'
    /// relative tangent speed at the points to it (a conveyor belt; see
    /// `ShapeDef::tangent_speed`).
    pub tangent_speed: Real,
    /// The rolling row's bound per unit normal impulse, m (the larger
    /// rolling resistance times the larger rolling radius; 0: none).
    pub rolling_resistance: Real,
    /// True when the manifold has points.
    pub touching: bool,
    /// True when either shape is a sensor (events only).
    pub sensor: bool,
    /// True when either shape asked for hit events.
    pub hit_events: bool,
    /// Event switches of the pair (`event_flags` bits): whether both
    /// shapes report this contact's begin/end (or sensor) events, and
    /// which shape is the sensor.
    pub(crate) event_flags: u8,
    /// False when a filter (portal clipping, a disabled pair) suppresses it.
    pub enabled: bool,
    /// Whether each body read as static (static or asleep) at the last
    /// narrowphase; both true: the contact sleeps and is not solved.
    pub still: [bool; 2],
    /// What the narrowphase read of each body for this step's solve, so
    /// that constraint building gathers nothing again: its state index
    /// (0: static or asleep) and `[m⁻¹, I⁻¹]` (zero for state 0).
    pub(crate) solve_bodies: [(u32, [Real; 2]); 2],
    /// The poses and points the manifold was last computed at, for
    /// recycling it (see the narrowphase).
    pub(crate) recycle: RecycleCache,
    /// Stable id for the contact's whole life.
    pub id: u32,
    /// Handles of the two shapes (for events).
    pub shapes: [ShapeHandle; 2],
    /// The shapes' user material ids (`ShapeDef::user_material_id`), a's
    /// then b's.
    pub user_material_ids: [u64; 2],
}

/// What a contact keeps of the step its manifold was computed in, so that
/// the narrowphase can keep the points on the same material points while
/// the bodies move little relative to each other (recycling).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct RecycleCache {
    /// The cache holds a touching manifold.
    pub valid: bool,
    /// Rotation of body a then.
    pub q_a: Rot,
    /// Rotation of body b then.
    pub q_b: Rot,
    /// Pose of b's centre of mass in a's centre frame then (`x_a⁻¹ x_b`).
    pub relative: Transform,
    /// Separation of each point then, m. (The anchors then are the
    /// points' own: recycling keeps them.)
    pub separation: [Real; 2],
    /// When the manifold then was empty on a separating-axis test: that
    /// test's clearance, m, and `relative` is of the bodies' origins
    /// (`x_a⁻¹ x_b`), not their centres (the narrowphase's `keeps_empty`).
    /// Else 0. Not saved: a restored world tests its empty pairs again.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub clearance: Real,
}

impl Contact {
    /// The other body of the contact.
    #[inline]
    #[must_use]
    pub fn other(&self, body: BodyHandle) -> BodyHandle {
        if self.body_a == body {
            self.body_b
        } else {
            self.body_a
        }
    }

    /// The valid manifold points.
    #[inline]
    #[must_use]
    pub fn points(&self) -> &[ContactPointData] {
        &self.points[..self.point_count]
    }

    /// Normal impulse the last step applied through all points, N·s.
    #[must_use]
    pub fn total_normal_impulse(&self) -> Real {
        self.points().iter().map(|p| p.total_normal_impulse).sum()
    }

    /// True when it pushes: touching, solid and enabled.
    #[inline]
    #[must_use]
    pub fn is_solid_touching(&self) -> bool {
        self.touching && !self.sensor && self.enabled
    }
}

/// Two shapes that stopped touching.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ShapePairEvent {
    /// One shape.
    pub shape_a: ShapeHandle,
    /// The other shape.
    pub shape_b: ShapeHandle,
}

/// The manifold of a contact when it began touching (what a
/// [`ContactBeginEvent`] carries): Box2D's `b2ContactBeginTouchEvent`
/// manifold.
///
/// ```
/// use janus2d_world::EventManifold;
/// let m = EventManifold::default();
/// assert!(m.points().is_empty());
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct EventManifold {
    /// Unit normal from shape a to shape b.
    pub normal: Vec2,
    /// World points (the first `point_count` are valid), m: each the
    /// mid-point between the two surfaces, as the solver uses it.
    pub points: [Vec2; 2],
    /// Separation at each point (negative: penetration), m.
    pub separations: [Real; 2],
    /// Number of valid points (1 or 2).
    pub point_count: usize,
    /// The two shapes' user material ids (`ShapeDef::user_material_id`),
    /// a's then b's, as [`Contact::user_material_ids`].
    pub user_material_ids: [u64; 2],
}

impl EventManifold {
    /// The valid points.
    #[must_use]
    pub fn points(&self) -> &[Vec2] {
        &self.points[..self.point_count.min(2)]
    }

    /// The manifold of a contact as it is now.
    pub(crate) fn of(c: &Contact) -> Self {
        let mut m = EventManifold {
            normal: c.normal,
            point_count: c.point_count.min(2),
            user_material_ids: c.user_material_ids,
            ..EventManifold::default()
        };
        for (k, p) in c.points().iter().enumerate().take(2) {
            m.points[k] = p.point;
            m.separations[k] = p.separation;
        }
        m
    }
}

/// Two solid shapes that began touching, with the manifold they began
/// with.
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
/// world.step(1.0 / 60.0).unwrap();
/// let begin = world.events().collision.contact_begin[0];
/// assert_eq!(begin.manifold.points().len(), 2);
/// assert!((begin.manifold.normal.y.abs() - 1.0).abs() < 1e-5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactBeginEvent {
    /// Shape a of the contact.
    pub shape_a: ShapeHandle,
    /// Shape b of the contact.
    pub shape_b: ShapeHandle,
    /// The manifold when the contact began touching.
    pub manifold: EventManifold,
}

/// A sensor overlap that began or ended, with the roles of its shapes.
/// (When both shapes are sensors, `sensor_shape` is the contact's shape
/// a.)
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::{Circle, Polygon};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let zone = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let sensor = world.create_shape(zone, &ShapeDef::default().sensor(), Polygon::make_box(2.0, 2.0)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
/// let ball = world.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.25).unwrap()).unwrap();
/// world.step(1.0 / 60.0).unwrap();
/// let e = world.events().collision.sensor_begin[0];
/// assert_eq!((e.sensor_shape, e.visitor_shape), (sensor, ball));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SensorEvent {
    /// The sensor shape.
    pub sensor_shape: ShapeHandle,
    /// The shape that entered or left it.
    pub visitor_shape: ShapeHandle,
}

/// A contact that pushed harder than its shapes' force threshold this
/// step (Rapier's `ContactForceEvent`; see
/// `ShapeDef::force_event_threshold`). Forces are the step's normal
/// impulses over the step's `dt`.
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::Polygon;
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(5.0, 0.5)).unwrap();
/// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
/// let def = ShapeDef::default().with_force_event_threshold(1.0);
/// world.create_shape(b, &def, Polygon::make_box(0.5, 0.5)).unwrap();
/// for _ in 0..30 {
///     world.step(1.0 / 60.0).unwrap();
/// }
/// // Resting: the ground carries the box's weight, m·g ≈ 9.8 N.
/// let f = world.events().collision.forces[0];
/// assert!((f.total_force_magnitude - 9.81).abs() < 0.5);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactForceEvent {
    /// Shape a of the contact.
    pub shape_a: ShapeHandle,
    /// Shape b of the contact.
    pub shape_b: ShapeHandle,
    /// Sum of the points' normal forces (on b, along the normal from a to
    /// b), N.
    pub total_force: Vec2,
    /// Its length, N (what the threshold is compared with).
    pub total_force_magnitude: Real,
    /// The largest force at one point, N.
    pub max_force_magnitude: Real,
    /// The unit normal of that point's force (the contact normal).
    pub max_force_direction: Vec2,
}

/// Contact and sensor events, read after the step.
///
/// Events of contacts that end because a body or shape was destroyed
/// between steps are kept and reported with the next step's.
///
/// **Switches.** A solid contact reports begin and end events only when
/// both shapes have `ShapeDef::enable_contact_events` (usual true), a
/// sensor overlap only when both have `ShapeDef::enable_sensor_events`
/// (usual true): a shape that turns them off hears nothing of its pairs.
/// A switch changed while a pair touches takes effect for the pair's next
/// change.
///
/// **The net change.** Each list holds every pair at most once: a pair
/// that began and ended touching between two reports (a contact found by
/// the narrowphase and then handed over at a portal, a resting contact
/// ended by `set_shape_filter` and found again by the next step) reports
/// nothing, and one that ended and began again reports nothing either. So
/// the touching solid pairs after a step are exactly those after the step
/// before, minus `contact_end`, plus `contact_begin` (in any order), and the
/// same for sensor overlaps with `sensor_end` and `sensor_begin`. Within a
/// list the order is the order the changes were found in, except that a
/// cancelled event's place is taken by the list's last one.
#[derive(Clone, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CollisionEvents {
    /// Solid contacts that began touching, with their manifolds.
    pub contact_begin: Vec<ContactBeginEvent>,
    /// Solid contacts that stopped touching (or whose shapes were destroyed).
    pub contact_end: Vec<ShapePairEvent>,
    /// Sensor overlaps that began.
    pub sensor_begin: Vec<SensorEvent>,
    /// Sensor overlaps that ended.
    pub sensor_end: Vec<SensorEvent>,
    /// Contacts of shapes with hit events on that pushed this step with an
    /// approach speed above the world's threshold, in contact order.
    pub hits: Vec<HitEvent>,
    /// Contacts of shapes with a finite `force_event_threshold` that
    /// pushed harder than it this step, in contact order.
    pub forces: Vec<ContactForceEvent>,
    /// Where each pair's begin or end event sits (not part of the value:
    /// not compared, not stored in snapshots, rebuilt when it does not
    /// cover the lists).
    #[cfg_attr(feature = "serde", serde(skip))]
    index: EventIndex,
}

/// The four begin/end lists of [`CollisionEvents`], by number.
const CONTACT_BEGIN: u8 = 0;
const CONTACT_END: u8 = 1;
const SENSOR_BEGIN: u8 = 2;
const SENSOR_END: u8 = 3;

/// A pair of shapes in a fixed order, and whether it is a sensor pair.
type PairOfShapes = (ShapeHandle, ShapeHandle, bool);

/// Pair → (list, position) of the pairs' events in [`CollisionEvents`]:
/// looked up when an event is recorded, never iterated. Always equal as a
/// value (it only speeds up the lists it indexes).
///
/// During a pass that meets each pair at most once and starts with empty
/// lists (the narrowphase's, see [`CollisionEvents::begin_pass`]) no
/// event can undo another, so the pass appends without indexing
/// (`unindexed`); the next recorded event outside such a pass finds the
/// index short of the lists and rebuilds it.
#[derive(Clone, Default)]
struct EventIndex {
    /// Pair → (list, position).
    pairs: crate::key_map::KeyMap<PairOfShapes, (u8, u32)>,
    /// Inside such a pass: events are appended, not indexed.
    unindexed: bool,
}

impl PartialEq for EventIndex {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for EventIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "EventIndex({} pairs)", self.pairs.len())
    }
}

/// A contact that hit hard enough (see `ShapeDef::enable_hit_events` and
/// `WorldDef::hit_event_threshold`): its fastest-approaching point.
///
/// The contact was found before the step's solve, possibly while the
/// shapes were still apart (a speculative contact): `point` is the
/// manifold's point, the mid-point between the two surfaces then, which
/// for a fast body can lie well in front of the surface it hits.
/// `point_a` and `point_b` are the points on each shape's surface.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct HitEvent {
    /// Shape a of the contact.
    pub shape_a: ShapeHandle,
    /// Shape b of the contact.
    pub shape_b: ShapeHandle,
    /// World point of the contact point, m: the mid-point between the
    /// two surfaces when the contact was found (see the type docs).
    pub point: Vec2,
    /// The point on shape a's surface, m (`point − ½ s n`, `s` the
    /// point's separation then).
    pub point_a: Vec2,
    /// The point on shape b's surface, m (`point + ½ s n`): for a body
    /// hitting a wall that is b, where the wall's face is.
    pub point_b: Vec2,
    /// Unit normal from a to b.
    pub normal: Vec2,
    /// Speed at which the point approached along the normal before the
    /// solve, m/s (positive).
    pub approach_speed: Real,
}

/// Bits of [`Contact::event_flags`].
pub(crate) mod event_flags {
    /// Both shapes report contact (or, for a sensor pair, sensor) events.
    pub(crate) const REPORT: u8 = 1;
    /// The sensor of a sensor pair is shape b (else shape a).
    pub(crate) const SENSOR_IS_B: u8 = 2;

    /// The flags of a contact between shapes with these definitions.
    pub(crate) fn of(a: &crate::shapes::ShapeDef, b: &crate::shapes::ShapeDef) -> u8 {
        let report = if a.is_sensor || b.is_sensor {
            a.enable_sensor_events && b.enable_sensor_events
        } else {
            a.enable_contact_events && b.enable_contact_events
        };
        let mut flags = if report { REPORT } else { 0 };
        if b.is_sensor && !a.is_sensor {
            flags |= SENSOR_IS_B;
        }
        flags
    }
}

impl CollisionEvents {
    /// Takes the step's events out, leaving empty lists behind. The pair
    /// index stays (emptied, its allocation kept): it covers the lists
    /// this store fills next.
    pub(crate) fn take(&mut self) -> CollisionEvents {
        let mut out = std::mem::take(self);
        self.index = std::mem::take(&mut out.index);
        self.index.pairs.clear();
        out
    }

    /// Gives the allocations of an earlier step's events (`old`, read by
    /// the user and now replaced) back to the lists that are still empty,
    /// so a step does not grow its lists from nothing. The lists' contents
    /// are unchanged: a list that holds events (recorded between steps)
    /// keeps them.
    pub(crate) fn recycle(&mut self, old: CollisionEvents) {
        fn reuse<T>(list: &mut Vec<T>, mut old: Vec<T>) {
            if list.is_empty() && old.capacity() > list.capacity() {
                old.clear();
                *list = old;
            }
        }
        reuse(&mut self.contact_begin, old.contact_begin);
        reuse(&mut self.contact_end, old.contact_end);
        reuse(&mut self.sensor_begin, old.sensor_begin);
        reuse(&mut self.sensor_end, old.sensor_end);
        reuse(&mut self.hits, old.hits);
        reuse(&mut self.forces, old.forces);
    }

    /// Records a begin (`touching`) or end event of a contact, as the net
    /// change (type docs): an event that undoes the pair's pending opposite
    /// event removes it instead of being added. Contacts whose shapes turned
    /// the events off record nothing.
    pub(crate) fn push(&mut self, c: &Contact, touching: bool) {
        if c.event_flags & event_flags::REPORT == 0 {
            return;
        }
        let (this, opposite) = match (touching, c.sensor) {
            (true, false) => (CONTACT_BEGIN, CONTACT_END),
            (false, false) => (CONTACT_END, CONTACT_BEGIN),
            (true, true) => (SENSOR_BEGIN, SENSOR_END),
            (false, true) => (SENSOR_END, SENSOR_BEGIN),
        };
        if self.index.unindexed {
            // A pass of distinct pairs over empty lists: nothing to undo.
            self.append(c, this);
            return;
        }
        let key = pair_of_shapes(c.shapes[0], c.shapes[1], c.sensor);
        self.sync_index();
        match self.index.pairs.get(&key).copied() {
            Some((list, pos)) if list == opposite => {
                // The pair is back where it was at the last report.
                self.index.pairs.remove(&key);
                let pos = pos as usize;
                if let Some(moved) = self.swap_remove_at(list, pos) {
                    self.index.pairs.insert(moved, (list, pos as u32));
                }
            }
            // Already reported this way (touching alternates, so only
            // a decoded snapshot's lists could hold it): nothing to add.
            Some(_) => {}
            None => {
                let len = self.append(c, this);
                self.index.pairs.insert(key, (this, (len - 1) as u32));
            }
        }
    }

    /// Starts a pass that records each pair at most once (the
    /// narrowphase's): when the lists are empty, its events are appended
    /// without the pair index (see [`EventIndex`]) until
    /// [`end_pass`](Self::end_pass).
    pub(crate) fn begin_pass(&mut self) {
        self.index.unindexed = self.contact_begin.is_empty()
            && self.contact_end.is_empty()
            && self.sensor_begin.is_empty()
            && self.sensor_end.is_empty();
    }

    /// Ends the pass [`begin_pass`](Self::begin_pass) started: later
    /// events look their pair up again.
    pub(crate) fn end_pass(&mut self) {
        self.index.unindexed = false;
    }

    /// Appends the event of contact `c` to list `this`; returns the list's
    /// new length.
    fn append(&mut self, c: &Contact, this: u8) -> usize {
        match this {
            CONTACT_BEGIN => {
                self.contact_begin.push(ContactBeginEvent {
                    shape_a: c.shapes[0],
                    shape_b: c.shapes[1],
                    manifold: EventManifold::of(c),
                });
                self.contact_begin.len()
            }
            CONTACT_END => {
                self.contact_end.push(ShapePairEvent {
                    shape_a: c.shapes[0],
                    shape_b: c.shapes[1],
                });
                self.contact_end.len()
            }
            _ => {
                let b_is_sensor = c.event_flags & event_flags::SENSOR_IS_B != 0;
                let ev = SensorEvent {
                    sensor_shape: c.shapes[usize::from(b_is_sensor)],
                    visitor_shape: c.shapes[usize::from(!b_is_sensor)],
                };
                let list = if this == SENSOR_BEGIN {
                    &mut self.sensor_begin
                } else {
                    &mut self.sensor_end
                };
                list.push(ev);
                list.len()
            }
        }
    }

    /// Swap-removes the event at `pos` of list `list`; returns the pair
    /// of the event that moved into `pos`, if any.
    fn swap_remove_at(&mut self, list: u8, pos: usize) -> Option<PairOfShapes> {
        fn take<T: Copy>(
            v: &mut Vec<T>,
            pos: usize,
            key: impl Fn(&T) -> PairOfShapes,
        ) -> Option<PairOfShapes> {
            if pos >= v.len() {
                return None;
            }
            v.swap_remove(pos);
            v.get(pos).map(key)
        }
        match list {
            CONTACT_BEGIN => take(&mut self.contact_begin, pos, begin_key),
            CONTACT_END => take(&mut self.contact_end, pos, end_key),
            _ => {
                let v = if list == SENSOR_BEGIN {
                    &mut self.sensor_begin
                } else {
                    &mut self.sensor_end
                };
                take(v, pos, sensor_key)
            }
        }
    }

    /// Rebuilds the pair index when it does not cover the lists (after a
    /// snapshot is decoded, or if the lists were changed from outside).
    fn sync_index(&mut self) {
        let total = self.contact_begin.len()
            + self.contact_end.len()
            + self.sensor_begin.len()
            + self.sensor_end.len();
        if self.index.pairs.len() == total {
            return;
        }
        let mut index = crate::key_map::KeyMap::with_capacity_and_hasher(total, Default::default());
        let keyed = [
            (
                CONTACT_BEGIN,
                self.contact_begin.iter().map(begin_key).collect::<Vec<_>>(),
            ),
            (CONTACT_END, self.contact_end.iter().map(end_key).collect()),
            (
                SENSOR_BEGIN,
                self.sensor_begin.iter().map(sensor_key).collect(),
            ),
            (SENSOR_END, self.sensor_end.iter().map(sensor_key).collect()),
        ];
        for (list, keys) in keyed {
            for (pos, key) in keys.into_iter().enumerate() {
                index.insert(key, (list, pos as u32));
            }
        }
        self.index.pairs = index;
    }
}

/// The pair key of a begin event.
fn begin_key(e: &ContactBeginEvent) -> PairOfShapes {
    pair_of_shapes(e.shape_a, e.shape_b, false)
}

/// The pair key of an end event.
fn end_key(e: &ShapePairEvent) -> PairOfShapes {
    pair_of_shapes(e.shape_a, e.shape_b, false)
}

/// The pair key of a sensor event.
fn sensor_key(e: &SensorEvent) -> PairOfShapes {
    pair_of_shapes(e.sensor_shape, e.visitor_shape, true)
}

/// A pair of shapes in a fixed order (the lower handle first), with its
/// kind.
fn pair_of_shapes(a: ShapeHandle, b: ShapeHandle, sensor: bool) -> PairOfShapes {
    if a <= b {
        (a, b, sensor)
    } else {
        (b, a, sensor)
    }
}

/// Which list a contact id lives in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
enum Place {
    Free,
    Awake(u32),
    Sleeping(u32),
}

/// Ordered key of a pair of slot indices.
#[inline]
pub(crate) fn pair_key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

/// Body pairs whose solid contact began or stopped touching during a
/// step: what the contacts hand the islands (through the pipeline).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct TouchChanges {
    /// Pairs that began touching (they link islands).
    pub(crate) began: Vec<(BodyHandle, BodyHandle)>,
    /// Pairs that stopped touching or whose touching contact was destroyed
    /// (their islands may split).
    pub(crate) ended: Vec<(BodyHandle, BodyHandle)>,
}

/// Every contact of a world, awake or asleep, with per-body adjacency.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactSet {
    /// Awake contacts (the narrowphase and constraint building visit these).
    pub(crate) awake: Vec<Contact>,
    /// Contacts whose bodies are all asleep or static.
    pub(crate) sleeping: Vec<Contact>,
    place: Vec<Place>,
    free_ids: Vec<u32>,
    shape_pairs: Vec<SmallVec<[(u32, u32); 4]>>,
    body_contacts: Vec<SmallVec<[u32; 4]>>,
    /// Body pairs whose solid contact began touching since the islands
    /// last read them (they link islands).
    began: Vec<(BodyHandle, BodyHandle)>,
    /// Body pairs whose solid contact stopped touching or was destroyed
    /// while touching (their islands may split).
    ended: Vec<(BodyHandle, BodyHandle)>,
    /// By contact id: its bodies and whether it touches solidly, kept as
    /// contacts come, go and begin or stop touching, so that an island
    /// split walks a body's links without reading the contacts themselves
    /// (junkyard: half of the sleep stage was that read).
    links: Vec<ContactLink>,
    /// By contact id: its position in the pair list of shape a and of
    /// shape b, so that destroying it scans neither list (a large shape,
    /// washer's drum or a ground, lists thousands of contacts). Kept beside
    /// the contacts, not in them: fixing the slot of the entry a removal
    /// moves then touches this small array, not another contact.
    pair_slots: Vec<[u32; 2]>,
    /// By contact id: its position in the contact list of body a and of
    /// body b, so that destroying it neither scans nor shifts those lists
    /// (a static container lists thousands: spinner spent 5% of its step
    /// there).
    body_slots: Vec<[u32; 2]>,
}

/// What an island split needs of a contact (see [`ContactSet::links_of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct ContactLink {
    /// Body a, body b.
    bodies: [BodyHandle; 2],
    /// Touching, not a sensor, enabled.
    solid: bool,
}

impl ContactSet {
    /// The body pairs whose solid contact began or stopped touching since
    /// the last call, handed to the islands by the pipeline.
    pub(crate) fn take_touch_changes(&mut self) -> TouchChanges {
        TouchChanges {
            began: std::mem::take(&mut self.began),
            ended: std::mem::take(&mut self.ended),
        }
    }

    /// Number of contacts, awake and asleep.
    #[must_use]
    pub fn len(&self) -> usize {
        self.awake.len() + self.sleeping.len()
    }

    /// The awake contacts, in list order.
    #[must_use]
    pub fn awake(&self) -> &[Contact] {
        &self.awake
    }

    /// Every contact: awake ones first, then sleeping ones.
    pub fn iter(&self) -> impl Iterator<Item = &Contact> {
        self.awake.iter().chain(&self.sleeping)
    }

    /// The bodies that `body`'s solid touching contacts link it to, in the
    /// body's contact order.
    pub(crate) fn links_of(&self, body: BodyHandle) -> impl Iterator<Item = BodyHandle> + '_ {
        self.of_body(body).iter().filter_map(move |&id| {
            let link = self.links.get(id as usize)?;
            link.solid.then(|| {
                if link.bodies[0] == body {
                    link.bodies[1]
                } else {
                    link.bodies[0]
                }
            })
        })
    }

    /// Calls `f` with the two bodies of every touching solid contact, in
    /// contact-id order: one pass over the compact link array, for an
    /// island split over a large share of the world.
    pub(crate) fn for_each_solid_link(&self, mut f: impl FnMut(BodyHandle, BodyHandle)) {
        for link in &self.links {
            if link.solid {
                f(link.bodies[0], link.bodies[1]);
            }
        }
    }

    /// The number of link slots (live and free contact ids): the length
    /// of the pass [`for_each_solid_link`](Self::for_each_solid_link) makes.
    pub(crate) fn link_slots(&self) -> usize {
        self.links.len()
    }

    /// True when shapes `a` and `b` (slots) have a contact.
    #[must_use]
    pub fn has_pair(&self, a: u32, b: u32) -> bool {
        let list = |s: u32| {
            self.shape_pairs
                .get(s as usize)
                .map_or(&[][..], |l| l.as_slice())
        };
        let (la, lb) = (list(a), list(b));
        // Scan the shorter list (a ground shape may touch hundreds).
        let (short, other) = if la.len() <= lb.len() {
            (la, b)
        } else {
            (lb, a)
        };
        short.iter().any(|&(s, _)| s == other)
    }

    /// Ids of the contacts of a body.
    #[inline]
    #[must_use]
    pub fn of_body(&self, body: BodyHandle) -> &[u32] {
        self.body_contacts
            .get(body.index as usize)
            .map_or(&[], |l| l.as_slice())
    }

    /// The contact with id `id`.
    #[must_use]
    pub fn get(&self, id: u32) -> Option<&Contact> {
        match *self.place.get(id as usize)? {
            Place::Free => None,
            Place::Awake(i) => self.awake.get(i as usize),
            Place::Sleeping(i) => self.sleeping.get(i as usize),
        }
    }

    /// Forgets the kept impulses of `body`'s contacts (a body reset for a
    /// non-finite state starts again from rest, not from the impulses that
    /// carried it there).
    pub(crate) fn forget_impulses(&mut self, body: BodyHandle) {
        let ids: SmallVec<[u32; 4]> = SmallVec::from_slice(self.of_body(body));
        for id in ids {
            if let Some(c) = self.get_mut(id) {
                for p in &mut c.points {
                    p.normal_impulse = 0.0;
                    p.tangent_impulse = 0.0;
                    p.total_normal_impulse = 0.0;
                    p.total_tangent_impulse = 0.0;
                }
            }
        }
    }

    /// Mutable access to the contact with id `id`.
    pub(crate) fn get_mut(&mut self, id: u32) -> Option<&mut Contact> {
        match *self.place.get(id as usize)? {
            Place::Free => None,
            Place::Awake(i) => self.awake.get_mut(i as usize),
            Place::Sleeping(i) => self.sleeping.get_mut(i as usize),
        }
    }

    /// Checks the set against bodies and shapes (for `World::validate`):
    /// ids ↔ places ↔ lists, the per-shape pair lists (each contact listed
    /// once under each of its shapes, naming the other), shapes live and on the contact's bodies, each
    /// contact listed under both bodies and the body lists holding only
    /// contacts of that body, no sleeping contact with an awake body, and
    /// every point, normal and impulse finite.
    pub(crate) fn check(
        &self,
        bodies: &janus2d_core::body::BodySet,
        shapes: &crate::shapes::ShapeStore,
    ) -> Result<(), String> {
        use janus2d_core::body::BodyLocation;
        let listed: usize = self.shape_pairs.iter().map(|l| l.len()).sum();
        if listed != 2 * self.len() {
            return Err(format!(
                "{listed} shape pair entries for {} contacts",
                self.len()
            ));
        }
        let lists = [(true, &self.awake), (false, &self.sleeping)];
        for (awake, list) in lists {
            for (i, c) in list.iter().enumerate() {
                let expected = if awake {
                    Place::Awake(i as u32)
                } else {
                    Place::Sleeping(i as u32)
                };
                if self.place.get(c.id as usize) != Some(&expected) {
                    return Err(format!("contact {}: place is not {expected:?}", c.id));
                }
                let link = ContactLink {
                    bodies: [c.body_a, c.body_b],
                    solid: c.is_solid_touching(),
                };
                if self.links.get(c.id as usize) != Some(&link) {
                    return Err(format!("contact {}: its island link is stale", c.id));
                }
                if c.shape_a >= c.shape_b {
                    return Err(format!("contact {}: shapes out of order", c.id));
                }
                for (side, (shape, other)) in [(c.shape_a, c.shape_b), (c.shape_b, c.shape_a)]
                    .into_iter()
                    .enumerate()
                {
                    let list = self
                        .shape_pairs
                        .get(shape as usize)
                        .map_or(&[][..], |l| l.as_slice());
                    if list.iter().filter(|&&e| e == (other, c.id)).count() != 1 {
                        return Err(format!(
                            "contact {}: not listed once under shape {shape}",
                            c.id
                        ));
                    }
                    let slot = self.pair_slots.get(c.id as usize).map(|s| s[side] as usize);
                    if slot.and_then(|k| list.get(k)) != Some(&(other, c.id)) {
                        return Err(format!(
                            "contact {}: its slot under shape {shape} is stale",
                            c.id
                        ));
                    }
                }
                for (slot, body) in [(c.shape_a, c.body_a), (c.shape_b, c.body_b)] {
                    if !bodies.contains(body) {
                        return Err(format!("contact {}: body {body:?} is not live", c.id));
                    }
                    if !shapes.of_body(body).contains(&slot) {
                        return Err(format!("contact {}: shape {slot} is not on {body:?}", c.id));
                    }
                    if self.of_body(body).iter().filter(|&&k| k == c.id).count() != 1 {
                        return Err(format!("contact {}: not listed once under {body:?}", c.id));
                    }
                }
                for (side, body) in [c.body_a, c.body_b].into_iter().enumerate() {
                    let slot = self.body_slots.get(c.id as usize).map(|s| s[side] as usize);
                    if slot.and_then(|k| self.of_body(body).get(k)) != Some(&c.id) {
                        return Err(format!(
                            "contact {}: its slot under {body:?} is stale",
                            c.id
                        ));
                    }
                }
                if !awake {
                    for body in [c.body_a, c.body_b] {
                        if matches!(bodies.location(body), Some(BodyLocation::Moving(_))) {
                            return Err(format!(
                                "sleeping contact {} has awake body {body:?}",
                                c.id
                            ));
                        }
                    }
                }
                let finite = janus2d_core::math::vec_is_finite(c.normal)
                    && c.friction.is_finite()
                    && c.restitution.is_finite()
                    && c.tangent_speed.is_finite()
                    && c.rolling_resistance.is_finite()
                    && c.rolling_resistance >= 0.0
                    && c.point_count <= 2
                    // Both slots, the unused one too: recycling copies it
                    // (a decoded NaN there reached the recycling cache).
                    && c.points.iter().all(|p| {
                        janus2d_core::math::vec_is_finite(p.point)
                            && janus2d_core::math::vec_is_finite(p.anchor_a)
                            && janus2d_core::math::vec_is_finite(p.anchor_b)
                            && p.separation.is_finite()
                            && p.normal_impulse.is_finite()
                            && p.tangent_impulse.is_finite()
                            && p.total_normal_impulse.is_finite()
                            && p.total_tangent_impulse.is_finite()
                    });
                if !finite {
                    return Err(format!("contact {}: a stored number is not finite", c.id));
                }
                // A manifold's normal is a unit vector (a decoded one of
                // length 1.7e38 spun its body to 1e35 rad/s in one step),
                // within 1 % (rotations of unit length within
                // `UNIT_ROTATION_TOLERANCE` turn it), and the mixed
                // materials are within the shapes' limits.
                let n2 = c.normal.length_squared();
                if (c.point_count > 0 && (n2 - 1.0).abs() > 0.01)
                    || !(0.0..=janus2d_core::limits::MAX_FRICTION).contains(&c.friction)
                    || !(0.0..=janus2d_core::limits::MAX_RESTITUTION).contains(&c.restitution)
                {
                    return Err(format!(
                        "contact {}: normal {:?}, friction {}, restitution {}",
                        c.id, c.normal, c.friction, c.restitution
                    ));
                }
                // The recycling cache feeds the next narrowphase: a NaN
                // separation kept there became a touching point's (a
                // decoded snapshot, found by the snapshot fuzz target).
                // Its rotations within 1 % of unit length, as the normal:
                // bodies' rotations may be off by `UNIT_ROTATION_TOLERANCE`,
                // and the relative one composes two of them.
                let r = &c.recycle;
                let near_unit =
                    |q: janus2d_core::math::Rot| (q.c * q.c + q.s * q.s - 1.0).abs() <= 0.01;
                if r.valid
                    && !(near_unit(r.q_a)
                        && near_unit(r.q_b)
                        && near_unit(r.relative.q)
                        && janus2d_core::math::vec_is_finite(r.relative.p)
                        && r.separation.iter().all(|s| s.is_finite()))
                {
                    return Err(format!(
                        "contact {}: its recycling cache is not finite or not of unit rotations",
                        c.id
                    ));
                }
            }
        }
        for (b, list) in self.body_contacts.iter().enumerate() {
            for &id in list {
                match self.get(id) {
                    Some(c) if c.body_a.index as usize == b || c.body_b.index as usize == b => {}
                    _ => return Err(format!("body slot {b} lists contact {id}, not its own")),
                }
            }
        }
        let free = self.place.iter().filter(|p| **p == Place::Free).count();
        if free != self.free_ids.len() {
            return Err(format!(
                "{free} free places, {} free ids",
                self.free_ids.len()
            ));
        }
        let mut seen = vec![false; self.place.len()];
        for &id in &self.free_ids {
            let i = id as usize;
            if self.place.get(i) != Some(&Place::Free) || seen[i] {
                return Err(format!("free contact id {id} is not a free place once"));
            }
            seen[i] = true;
        }
        Ok(())
    }

    /// Adds an awake contact (its `id` is assigned here); returns the id.
    pub fn insert(&mut self, mut c: Contact) -> u32 {
        let id = match self.free_ids.pop() {
            Some(id) => id,
            None => {
                self.place.push(Place::Free);
                (self.place.len() - 1) as u32
            }
        };
        c.id = id;
        let link = ContactLink {
            bodies: [c.body_a, c.body_b],
            solid: c.is_solid_touching(),
        };
        if self.links.len() <= id as usize {
            self.links.resize(id as usize + 1, link);
        }
        self.links[id as usize] = link;
        if self.pair_slots.len() <= id as usize {
            self.pair_slots.resize(id as usize + 1, [0; 2]);
        }
        for (side, (shape, other)) in [(c.shape_a, c.shape_b), (c.shape_b, c.shape_a)]
            .into_iter()
            .enumerate()
        {
            let s = shape as usize;
            if self.shape_pairs.len() <= s {
                self.shape_pairs.resize(s + 1, SmallVec::new());
            }
            self.pair_slots[id as usize][side] = self.shape_pairs[s].len() as u32;
            self.shape_pairs[s].push((other, id));
        }
        if self.body_slots.len() <= id as usize {
            self.body_slots.resize(id as usize + 1, [0; 2]);
        }
        for (side, body) in [c.body_a, c.body_b].into_iter().enumerate() {
            let b = body.index as usize;
            if self.body_contacts.len() <= b {
                self.body_contacts.resize(b + 1, SmallVec::new());
            }
            self.body_slots[id as usize][side] = self.body_contacts[b].len() as u32;
            self.body_contacts[b].push(id);
        }
        self.place[id as usize] = Place::Awake(self.awake.len() as u32);
        self.awake.push(c);
        id
    }

    /// Takes contact `id` out of its list (swap-remove), fixing the place of
    /// the contact that moved into its position. Inlined, so that a caller
    /// that drops the record ([`ContactSet::destroy`]) costs one move, the
    /// last record into the hole, not a second one out.
    #[inline(always)]
    fn unlink(&mut self, id: u32) -> Option<Contact> {
        let (list, i) = match *self.place.get(id as usize)? {
            Place::Free => return None,
            Place::Awake(i) => (&mut self.awake, i as usize),
            Place::Sleeping(i) => (&mut self.sleeping, i as usize),
        };
        let awake = matches!(self.place[id as usize], Place::Awake(_));
        let c = list.swap_remove(i);
        if let Some(moved) = list.get(i) {
            self.place[moved.id as usize] = if awake {
                Place::Awake(i as u32)
            } else {
                Place::Sleeping(i as u32)
            };
        }
        self.place[id as usize] = Place::Free;
        Some(c)
    }

    /// Destroys contact `id`; an end event when it was touching.
    pub fn destroy(&mut self, id: u32, events: &mut CollisionEvents) {
        // What the destroy needs of the record, read where it lies; the
        // record itself is dropped by the unlink (a contact is hundreds of
        // bytes: spinner destroys 1,800 a step).
        let Some(c) = self.get(id) else {
            return;
        };
        let (shapes, pair, touching, solid) = (
            [c.shape_a, c.shape_b],
            (c.body_a, c.body_b),
            c.touching,
            c.is_solid_touching(),
        );
        if touching {
            events.push(c, false);
        }
        self.unlink(id);
        if let Some(link) = self.links.get_mut(id as usize) {
            link.solid = false;
        }
        let slots = self.pair_slots.get(id as usize).copied();
        for (side, shape) in shapes.into_iter().enumerate() {
            let Some(list) = self.shape_pairs.get_mut(shape as usize) else {
                continue;
            };
            let k = match slots.map(|s| s[side] as usize) {
                Some(k) if list.get(k).is_some_and(|&(_, x)| x == id) => k,
                // Not where insert put it (only a decoded snapshot's lists
                // could be; `check` reports them): find it.
                _ => match list.iter().position(|&(_, x)| x == id) {
                    Some(k) => k,
                    None => continue,
                },
            };
            list.swap_remove(k);
            // The last entry moved into k: its contact's slot there. A
            // contact's shape a is the smaller slot (pairs are created
            // ordered), so the entry itself says which side this list is.
            if let Some(&(other, moved)) = list.get(k)
                && let Some(slot) = self.pair_slots.get_mut(moved as usize)
            {
                slot[usize::from(shape > other)] = k as u32;
            }
        }
        let slots = self.body_slots.get(id as usize).copied();
        for (side, body) in [pair.0, pair.1].into_iter().enumerate() {
            let b = body.index as usize;
            let Some(list) = self.body_contacts.get_mut(b) else {
                continue;
            };
            let k = match slots.map(|s| s[side] as usize) {
                Some(k) if list.get(k) == Some(&id) => k,
                _ => match list.iter().position(|&x| x == id) {
                    Some(k) => k,
                    None => continue,
                },
            };
            list.swap_remove(k);
            // The last entry moved into k: its contact's slot for this
            // body (its link says which side the body is).
            if let Some(&moved) = list.get(k)
                && let Some(link) = self.links.get(moved as usize)
                && let Some(slot) = self.body_slots.get_mut(moved as usize)
            {
                slot[usize::from(link.bodies[0].index as usize != b)] = k as u32;
            }
        }
        self.free_ids.push(id);
        if solid {
            self.ended.push(pair);
        }
    }

    /// Records that a solid contact between two bodies began (`true`) or
    /// stopped touching, for the islands.
    pub(crate) fn note_touch_change(
        &mut self,
        id: u32,
        pair: (BodyHandle, BodyHandle),
        touching: bool,
    ) {
        if let Some(link) = self.links.get_mut(id as usize) {
            link.solid = touching;
        }
        if touching {
            self.began.push(pair);
        } else {
            self.ended.push(pair);
        }
    }

    /// Destroys the awake contact at position `i` (narrowphase: fat boxes
    /// apart).
    pub(crate) fn destroy_awake_at(&mut self, i: usize, events: &mut CollisionEvents) {
        let id = self.awake[i].id;
        self.destroy(id, events);
    }

    /// Destroys the contacts of `body` that `pred` selects.
    pub fn destroy_of_body(
        &mut self,
        body: BodyHandle,
        events: &mut CollisionEvents,
        mut pred: impl FnMut(&Contact) -> bool,
    ) {
        let ids: SmallVec<[u32; 8]> = self
            .of_body(body)
            .iter()
            .copied()
            .filter(|&id| self.get(id).is_some_and(&mut pred))
            .collect();
        for id in ids {
            self.destroy(id, events);
        }
    }

    /// Moves the awake contacts of a body that just fell asleep whose other
    /// body is static or asleep too into the sleeping list.
    pub fn sleep_body(&mut self, body: BodyHandle, bodies: &BodySet) {
        let n = self.of_body(body).len();
        for k in 0..n {
            let id = self.body_contacts[body.index as usize][k];
            let Place::Awake(_) = self.place[id as usize] else {
                continue;
            };
            let c = self.get(id).expect("listed contact");
            let other = c.other(body);
            if bodies.state_index(other).unwrap_or(0) != 0 {
                continue; // the other body still moves
            }
            let mut c = self.unlink(id).expect("listed contact");
            c.still = [true, true];
            self.place[id as usize] = Place::Sleeping(self.sleeping.len() as u32);
            self.sleeping.push(c);
        }
    }

    /// Moves the awake contact at position `i`, whose bodies are both still
    /// (asleep, or asleep and static), into the sleeping list, as
    /// [`ContactSet::sleep_body`] does when a body falls asleep: a contact
    /// found between bodies that were created asleep. The last awake
    /// contact moves to `i`.
    pub(crate) fn sleep_awake_at(&mut self, i: usize) {
        let id = self.awake[i].id;
        let mut c = self.unlink(id).expect("listed contact");
        c.still = [true, true];
        self.place[id as usize] = Place::Sleeping(self.sleeping.len() as u32);
        self.sleeping.push(c);
    }

    /// Moves the sleeping contacts of a body that woke back to the awake
    /// list (appended, in the body's list order).
    pub fn wake_body(&mut self, body: BodyHandle) {
        let n = self.of_body(body).len();
        for k in 0..n {
            let id = self.body_contacts[body.index as usize][k];
            let Place::Sleeping(_) = self.place[id as usize] else {
                continue;
            };
            let mut c = self.unlink(id).expect("listed contact");
            c.still = [false, false];
            self.place[id as usize] = Place::Awake(self.awake.len() as u32);
            self.awake.push(c);
        }
    }

    /// Mutable access to the awake contact at position `i`.
    #[inline]
    pub(crate) fn awake_mut(&mut self, i: usize) -> &mut Contact {
        &mut self.awake[i]
    }

    /// The awake contacts, mutable in place (the narrowphase's phase 1:
    /// the list's order and length do not change).
    #[inline]
    pub(crate) fn awake_slice_mut(&mut self) -> &mut [Contact] {
        &mut self.awake
    }
}

#[cfg(test)]
mod event_list_tests {
    use super::*;

    fn pair(i: u32) -> ShapePairEvent {
        ShapePairEvent {
            shape_a: ShapeHandle::new(i, 0, 1),
            shape_b: ShapeHandle::new(i + 1, 0, 1),
        }
    }

    #[test]
    fn recycled_event_lists_keep_what_they_hold_and_take_the_old_memory() {
        let mut old = CollisionEvents::default();
        old.contact_end.extend((0..64).map(pair));
        old.sensor_end.reserve(32);
        let capacity = old.contact_end.capacity();
        let mut events = CollisionEvents::default();
        // An end event recorded between steps (a destroyed shape).
        events.contact_end.push(pair(100));
        events.recycle(old);
        // The list that held an event keeps exactly it.
        assert_eq!(events.contact_end, vec![pair(100)]);
        // The empty lists got the old allocations, emptied.
        assert!(events.sensor_end.is_empty());
        assert!(events.sensor_end.capacity() >= 32);
        let mut again = CollisionEvents::default();
        again.recycle(CollisionEvents {
            contact_end: (0..64).map(pair).collect(),
            ..CollisionEvents::default()
        });
        assert!(again.contact_end.is_empty());
        assert!(again.contact_end.capacity() >= capacity.min(64));
    }

    /// A contact between shapes `i` and `i + 1` that reports its events.
    fn reporting_contact(i: u32) -> Contact {
        Contact {
            id: 0,
            shape_a: i,
            shape_b: i + 1,
            shapes: [ShapeHandle::new(i, 0, 1), ShapeHandle::new(i + 1, 0, 1)],
            body_a: BodyHandle::new(i, 0, 1),
            body_b: BodyHandle::new(i + 1, 0, 1),
            normal: Vec2::ZERO,
            points: [ContactPointData::default(); 2],
            point_count: 0,
            friction: 0.6,
            restitution: 0.0,
            tangent_speed: 0.0,
            rolling_resistance: 0.0,
            user_material_ids: [0, 0],
            touching: false,
            sensor: false,
            hit_events: false,
            event_flags: event_flags::REPORT,
            enabled: true,
            still: [false, false],
            solve_bodies: [(0, [0.0; 2]); 2],
            recycle: RecycleCache::default(),
        }
    }

    #[test]
    fn an_event_after_the_narrowphase_pass_still_undoes_the_pass_event() {
        let mut events = CollisionEvents::default();
        events.begin_pass();
        for i in [1, 5, 9] {
            events.push(&reporting_contact(i), true);
        }
        events.end_pass();
        // The pass appended without indexing.
        assert_eq!(events.contact_begin.len(), 3);
        assert_eq!(events.index.pairs.len(), 0);
        // A shape destroyed later in the step ends the second contact: the
        // index is rebuilt and the pair's begin goes instead of an end
        // being added.
        events.push(&reporting_contact(5), false);
        let pairs: Vec<u32> = events
            .contact_begin
            .iter()
            .map(|e| e.shape_a.index)
            .collect();
        assert_eq!(pairs, vec![1, 9]);
        assert!(events.contact_end.is_empty());
        assert_eq!(events.index.pairs.len(), 2);
    }

    #[test]
    fn a_pass_over_lists_holding_events_still_nets_them_out() {
        let mut events = CollisionEvents::default();
        // Recorded between steps: contact 3 ended (a destroyed shape's).
        events.push(&reporting_contact(3), false);
        events.begin_pass();
        // It touches again in the pass: the pending end is undone.
        events.push(&reporting_contact(3), true);
        events.push(&reporting_contact(7), true);
        events.end_pass();
        assert!(events.contact_end.is_empty());
        assert_eq!(events.contact_begin.len(), 1);
        assert_eq!(events.contact_begin[0].shape_a.index, 7);
    }

    #[test]
    fn taking_the_events_leaves_an_index_that_covers_the_empty_lists() {
        let mut events = CollisionEvents::default();
        events.contact_end.push(pair(1));
        events.sync_index();
        assert_eq!(events.index.pairs.len(), 1);
        let out = events.take();
        assert_eq!(out.contact_end, vec![pair(1)]);
        assert!(events.contact_end.is_empty());
        assert_eq!(events.index.pairs.len(), 0);
    }
}
