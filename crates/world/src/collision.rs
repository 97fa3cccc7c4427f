//! The collision pipeline: shapes, the broadphase, persistent contacts and
//! their manifolds, and contact and sensor events.
//!
//! ```text
//! step start ─ update_pairs: moved proxies → new shape pairs (sorted)
//!                 filter: same body, both non-dynamic, category/mask/group,
//!                 joints with collide_connected = false
//!            ─ narrowphase: for each contact
//!                 fat boxes apart → destroy (end event if touching)
//!                 manifold = collide(a, b); impulses carried by feature id
//!                 touching changed → begin/end event
//!            ─ constraints: one ContactConstraint per touching, solid contact
//! step end   ─ store impulses; recompute AABBs of moved bodies, move proxies
//! ```
//!
//! Contacts live in a `Vec` in creation order and are found by shape pair
//! through a hash map used only for lookups, never iterated: the order of
//! every loop is the same for the same inputs.

use std::collections::HashMap;

use janus2d_constraints::ContactPointInput;
use janus2d_constraints::contact::{ContactConstraint, mix_friction, mix_restitution};
use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::geometry::{Aabb, Manifold, Shape, collide};
use janus2d_core::math::{Real, Transform, Vec2};

use crate::broadphase::BroadPhase;

/// Speculative distance, m (usual 0.02 = 4 × linear slop): contact points
/// exist this far before touching.
pub const SPECULATIVE_DISTANCE: Real = 0.02;

/// Fattening margin of broadphase boxes, m (usual 0.1).
pub const AABB_MARGIN: Real = 0.1;

/// Which shapes collide: `a` and `b` collide when
/// `(a.category & b.mask) != 0 && (b.category & a.mask) != 0`, unless they
/// share a non-zero group index (positive: always collide; negative: never).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
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
    /// Whether two filters let their shapes collide.
    pub fn should_collide(&self, other: &Filter) -> bool {
        if self.group_index == other.group_index && self.group_index != 0 {
            return self.group_index > 0;
        }
        (self.mask_bits & other.category_bits) != 0 && (self.category_bits & other.mask_bits) != 0
    }
}

/// Everything needed to create a shape besides its geometry.
#[derive(Clone, Debug, PartialEq)]
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
    /// Opaque user value.
    pub user_data: u64,
}

impl Default for ShapeDef {
    fn default() -> Self {
        ShapeDef {
            density: 1.0,
            friction: 0.6,
            restitution: 0.0,
            filter: Filter::default(),
            is_sensor: false,
            user_data: 0,
        }
    }
}

impl ShapeDef {
    /// Sets the friction (builder style).
    pub fn with_friction(mut self, friction: Real) -> Self {
        self.friction = friction;
        self
    }

    /// Sets the density (builder style).
    pub fn with_density(mut self, density: Real) -> Self {
        self.density = density;
        self
    }

    /// Sets the restitution (builder style).
    pub fn with_restitution(mut self, restitution: Real) -> Self {
        self.restitution = restitution;
        self
    }
}

/// A generational handle to a shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ShapeHandle {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when issued.
    pub generation: u32,
    /// Id of the issuing world.
    pub owner: u32,
}

/// A shape attached to a body.
#[derive(Clone, Debug)]
pub struct ShapeData {
    /// The body it is attached to.
    pub body: BodyHandle,
    /// Geometry in the body frame.
    pub geometry: Shape,
    /// Material and filter.
    pub def: ShapeDef,
    /// Broadphase proxy.
    pub proxy: u32,
    /// Tight world box at the end of the last step.
    pub aabb: Aabb,
    /// Slot generation.
    generation: u32,
    alive: bool,
}

/// One manifold point with its warm-starting data.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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
    /// Normal impulse of the last step, N·s.
    pub normal_impulse: Real,
    /// Tangent impulse of the last step, N·s.
    pub tangent_impulse: Real,
}

/// A persistent contact between two shapes whose fat boxes overlap.
#[derive(Clone, Debug)]
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
    /// True when the manifold has points.
    pub touching: bool,
    /// True when either shape is a sensor (events only).
    pub sensor: bool,
    /// False when a filter (portal clipping, a disabled pair) suppresses it.
    pub enabled: bool,
    /// Whether each body read as static (static or asleep) at the last
    /// narrowphase; both true: the contact sleeps and is not solved.
    pub still: [bool; 2],
}

/// Two shapes that began or stopped touching.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShapePairEvent {
    /// One shape.
    pub shape_a: ShapeHandle,
    /// The other shape.
    pub shape_b: ShapeHandle,
}

/// Contact and sensor events of the last step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CollisionEvents {
    /// Solid contacts that began touching.
    pub contact_begin: Vec<ShapePairEvent>,
    /// Solid contacts that stopped touching (or whose shapes were destroyed).
    pub contact_end: Vec<ShapePairEvent>,
    /// Sensor overlaps that began.
    pub sensor_begin: Vec<ShapePairEvent>,
    /// Sensor overlaps that ended.
    pub sensor_end: Vec<ShapePairEvent>,
}

/// Counters of the last collision pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CollisionCounters {
    /// Shape pairs whose manifolds were computed.
    pub pairs_tested: usize,
    /// New pairs found by the broadphase.
    pub pairs_created: usize,
    /// Touching solid contacts.
    pub touching: usize,
    /// Proxies re-inserted in the broadphase.
    pub proxies_moved: usize,
    /// Contact rows built (normal + friction per point).
    pub contact_rows: usize,
    /// Contact constraints built with restitution > 0.
    pub restitution_contacts: usize,
}

/// A region where contact points are dropped: a portal's aperture.
///
/// ```text
///        lip        aperture (|t| < w)       lip
///   ─────────────●━━━━━━━━━━━━━━━━━━━━━●─────────────  wall surface, normal n
///                 points here are dropped
/// ```
///
/// - `Hole`: the aperture is a hole in the wall body that carries the portal:
///   contact points between that body and anything else are dropped when
///   they lie in the aperture's span (|t| < w), from in front of the surface
///   down to a depth of 2w behind it; the lips (|t| ≥ w) still collide.
/// - `Behind`: a crossing copy's points that lie behind its own portal
///   plane within the aperture are dropped (that part of the object is on
///   the other side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ApertureClip {
    /// The body whose contacts are clipped (the wall, or the crossing copy).
    pub body: BodyHandle,
    /// Aperture centre, world, m.
    pub point: Vec2,
    /// Outward unit normal, world.
    pub normal: Vec2,
    /// Half-width, m.
    pub half_width: Real,
    /// True for a hole in a wall, false for a crossing copy.
    pub hole: bool,
}

impl ApertureClip {
    #[inline]
    fn drops(&self, p: Vec2) -> bool {
        let d = p - self.point;
        let s = d.dot(self.normal);
        let t = janus2d_core::math::cross(self.normal, d);
        if t.abs() >= self.half_width {
            return false;
        }
        if self.hole {
            // The hole runs from the aperture surface into the wall, as
            // deep as the aperture is wide; speculative points in front of
            // the surface belong to it too.
            s > -2.0 * self.half_width
        } else {
            s < 0.0
        }
    }
}

/// Clipping that drops nothing (the narrowphase's input without portals).
pub static NO_CLIPPING: ContactClipping = ContactClipping {
    clips: Vec::new(),
    ignored_pairs: Vec::new(),
};

/// What the portal stage asks the narrowphase to drop.
#[derive(Clone, Debug, Default)]
pub struct ContactClipping {
    /// Aperture regions.
    pub clips: Vec<ApertureClip>,
    /// Pairs of bodies that never touch (a crossing copy and its twin).
    pub ignored_pairs: Vec<(BodyHandle, BodyHandle)>,
}

impl ContactClipping {
    /// True when nothing is clipped (the narrowphase then skips the check).
    pub fn is_empty(&self) -> bool {
        self.clips.is_empty() && self.ignored_pairs.is_empty()
    }

    fn apply(&self, c: &mut Contact) {
        if self
            .ignored_pairs
            .iter()
            .any(|&(x, y)| (c.body_a == x && c.body_b == y) || (c.body_a == y && c.body_b == x))
        {
            c.point_count = 0;
            return;
        }
        let mut k = 0;
        while k < c.point_count {
            let p = c.points[k].point;
            let dropped = self.clips.iter().any(|clip| {
                let involved = c.body_a == clip.body || c.body_b == clip.body;
                involved && clip.drops(p)
            });
            if dropped {
                c.points[k] = c.points[c.point_count - 1];
                c.point_count -= 1;
            } else {
                k += 1;
            }
        }
    }
}

/// Shapes, broadphase and contacts of a world.
pub struct Collision {
    owner: u32,
    /// Shape slots.
    pub shapes: Vec<ShapeData>,
    shape_free: Vec<u32>,
    /// Shape slots per body slot index (in creation order).
    pub body_shapes: Vec<Vec<u32>>,
    /// The broadphase.
    pub broadphase: BroadPhase,
    /// Persistent contacts.
    pub contacts: Vec<Contact>,
    pair_index: HashMap<(u32, u32), u32>,
    /// Body pairs (slot indices, ordered) connected by a joint that does not
    /// collide its bodies, with the number of such joints.
    pub no_collide_pairs: HashMap<(u32, u32), u32>,
    /// Events of the last step.
    pub events: CollisionEvents,
    /// Counters of the last step.
    pub counters: CollisionCounters,
    new_pairs: Vec<(u32, u32)>,
    scratch: Vec<ContactUpdate>,
}

/// Phase-1 result of the narrowphase for one contact.
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one per contact in a reused buffer; no boxing
enum ContactUpdate {
    /// Both bodies asleep or static: keep the contact as it is.
    Asleep,
    /// The fat boxes separated: destroy the contact.
    Separated,
    /// The new manifold, with what phase 2 needs of the two bodies.
    Manifold(Computed),
}

/// A computed manifold and the body data phase 2 needs.
#[derive(Clone, Debug)]
struct Computed {
    manifold: Manifold,
    /// Body origin minus centre of mass, per body (world frame), m.
    offset: [Vec2; 2],
    /// Whether each body reads as static (static or asleep).
    still: [bool; 2],
}

fn pair_key(a: u32, b: u32) -> (u32, u32) {
    if a < b { (a, b) } else { (b, a) }
}

impl Collision {
    /// Empty pipeline for a world with owner id `owner`.
    pub fn new(owner: u32) -> Self {
        Collision {
            owner,
            shapes: Vec::new(),
            shape_free: Vec::new(),
            body_shapes: Vec::new(),
            broadphase: BroadPhase::with_margin(AABB_MARGIN),
            contacts: Vec::new(),
            pair_index: HashMap::new(),
            no_collide_pairs: HashMap::new(),
            events: CollisionEvents::default(),
            counters: CollisionCounters::default(),
            new_pairs: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Number of live shapes.
    pub fn shape_count(&self) -> usize {
        self.shapes.len() - self.shape_free.len()
    }

    /// The handle of shape slot `index`.
    pub fn handle_of(&self, index: u32) -> ShapeHandle {
        ShapeHandle {
            index,
            generation: self.shapes[index as usize].generation,
            owner: self.owner,
        }
    }

    /// The slot of a live shape.
    pub fn slot(&self, handle: ShapeHandle) -> Option<u32> {
        let s = self.shapes.get(handle.index as usize)?;
        (s.alive && s.generation == handle.generation && handle.owner == self.owner)
            .then_some(handle.index)
    }

    /// Adds a shape (already validated) to a live body.
    pub fn add_shape(
        &mut self,
        bodies: &BodySet,
        body: BodyHandle,
        geometry: Shape,
        def: ShapeDef,
    ) -> ShapeHandle {
        let sim = bodies.sim(body).expect("live body");
        let aabb = geometry.compute_aabb(&sim.transform);
        let is_static = sim.body_type == BodyType::Static;
        let index = match self.shape_free.pop() {
            Some(i) => i,
            None => {
                self.shapes.push(ShapeData {
                    body,
                    geometry,
                    def: def.clone(),
                    proxy: 0,
                    aabb,
                    generation: 0,
                    alive: false,
                });
                (self.shapes.len() - 1) as u32
            }
        };
        let proxy = self.broadphase.create_proxy(aabb, index, is_static);
        let s = &mut self.shapes[index as usize];
        s.body = body;
        s.geometry = geometry;
        s.def = def;
        s.proxy = proxy;
        s.aabb = aabb;
        s.generation = s.generation.wrapping_add(1);
        s.alive = true;
        let b = body.index as usize;
        if self.body_shapes.len() <= b {
            self.body_shapes.resize(b + 1, Vec::new());
        }
        self.body_shapes[b].push(index);
        self.handle_of(index)
    }

    /// Removes a shape and every contact it has (end events for touching ones).
    pub fn remove_shape(&mut self, index: u32) {
        let mut k = 0;
        while k < self.contacts.len() {
            let c = &self.contacts[k];
            if c.shape_a == index || c.shape_b == index {
                self.destroy_contact(k);
            } else {
                k += 1;
            }
        }
        let s = &mut self.shapes[index as usize];
        s.alive = false;
        let proxy = s.proxy;
        let body = s.body.index as usize;
        self.broadphase.destroy_proxy(proxy);
        if let Some(list) = self.body_shapes.get_mut(body) {
            list.retain(|&i| i != index);
        }
        self.shape_free.push(index);
    }

    fn destroy_contact(&mut self, k: usize) {
        let c = self.contacts.swap_remove(k);
        self.pair_index.remove(&pair_key(c.shape_a, c.shape_b));
        if k < self.contacts.len() {
            let moved = &self.contacts[k];
            self.pair_index
                .insert(pair_key(moved.shape_a, moved.shape_b), k as u32);
        }
        if c.touching {
            let ev = ShapePairEvent {
                shape_a: self.handle_of(c.shape_a),
                shape_b: self.handle_of(c.shape_b),
            };
            if c.sensor {
                self.events.sensor_end.push(ev);
            } else {
                self.events.contact_end.push(ev);
            }
        }
    }

    /// Removes every contact between bodies `a` and `b` (a joint that does
    /// not collide its bodies was created).
    pub fn remove_contacts_between(&mut self, a: BodyHandle, b: BodyHandle) {
        let mut k = 0;
        while k < self.contacts.len() {
            let c = &self.contacts[k];
            if (c.body_a == a && c.body_b == b) || (c.body_a == b && c.body_b == a) {
                self.destroy_contact(k);
            } else {
                k += 1;
            }
        }
    }

    /// Removes every contact of a body (end events for touching ones).
    pub fn remove_contacts_of(&mut self, body: BodyHandle) {
        let mut k = 0;
        while k < self.contacts.len() {
            let c = &self.contacts[k];
            if c.body_a == body || c.body_b == body {
                self.destroy_contact(k);
            } else {
                k += 1;
            }
        }
    }

    /// Exchanges the shape lists of two bodies whose identities were swapped
    /// (their contacts must be gone already).
    pub fn swap_body_shapes(&mut self, a: BodyHandle, b: BodyHandle) {
        let (ia, ib) = (a.index as usize, b.index as usize);
        let n = ia.max(ib) + 1;
        if self.body_shapes.len() < n {
            self.body_shapes.resize(n, Vec::new());
        }
        self.body_shapes.swap(ia, ib);
        for &s in &self.body_shapes[ia] {
            self.shapes[s as usize].body = a;
        }
        for &s in &self.body_shapes[ib] {
            self.shapes[s as usize].body = b;
        }
        // Proxies must report their pairs again under the new owners.
        for &s in self.body_shapes[ia].iter().chain(&self.body_shapes[ib]) {
            self.broadphase.touch_proxy(self.shapes[s as usize].proxy);
        }
    }

    fn should_pair(&self, bodies: &BodySet, a: u32, b: u32) -> bool {
        let (sa, sb) = (&self.shapes[a as usize], &self.shapes[b as usize]);
        if sa.body == sb.body {
            return false;
        }
        if !sa.def.filter.should_collide(&sb.def.filter) {
            return false;
        }
        let ta = bodies.body_type(sa.body).unwrap_or(BodyType::Static);
        let tb = bodies.body_type(sb.body).unwrap_or(BodyType::Static);
        if ta != BodyType::Dynamic && tb != BodyType::Dynamic {
            return false;
        }
        if !self.no_collide_pairs.is_empty()
            && self
                .no_collide_pairs
                .contains_key(&pair_key(sa.body.index, sb.body.index))
        {
            return false;
        }
        true
    }

    /// Finds new pairs among moved proxies and creates their contacts.
    pub fn update_pairs(&mut self, bodies: &BodySet) {
        let mut new_pairs = std::mem::take(&mut self.new_pairs);
        new_pairs.clear();
        {
            let shapes = &self.shapes;
            let _ = shapes;
        }
        // Collect candidate pairs first (filtering needs &self).
        let mut candidates = Vec::new();
        self.broadphase.update_pairs(|_, _| true, &mut candidates);
        for (a, b) in candidates.drain(..) {
            let key = pair_key(a, b);
            if self.pair_index.contains_key(&key) {
                continue;
            }
            if self.should_pair(bodies, key.0, key.1) {
                new_pairs.push(key);
            }
        }
        self.counters.pairs_created = new_pairs.len();
        for &(a, b) in &new_pairs {
            let (sa, sb) = (&self.shapes[a as usize], &self.shapes[b as usize]);
            let contact = Contact {
                shape_a: a,
                shape_b: b,
                body_a: sa.body,
                body_b: sb.body,
                normal: Vec2::ZERO,
                points: [ContactPointData::default(); 2],
                point_count: 0,
                friction: mix_friction(sa.def.friction, sb.def.friction),
                restitution: mix_restitution(sa.def.restitution, sb.def.restitution),
                touching: false,
                sensor: sa.def.is_sensor || sb.def.is_sensor,
                enabled: true,
                still: [false, false],
            };
            self.pair_index.insert((a, b), self.contacts.len() as u32);
            self.contacts.push(contact);
        }
        self.new_pairs = new_pairs;
    }

    /// Updates every contact's manifold; destroys contacts whose fat boxes
    /// separated; records begin/end events.
    ///
    /// The speculative distance of a pair grows with how far the two bodies
    /// can approach within `dt`: `d = d₀ + dt (|v_b − v_a| + |ω_a| R_a + |ω_b| R_b)`
    /// with `R` the reach of a shape's box from its body's centre, so a
    /// fast body gets its contact points before it would overshoot.
    ///
    /// Contacts between two bodies that are both static or asleep are
    /// skipped; a touching contact between a sleeping body and an awake one
    /// lists the sleeping body in `wake`.
    pub fn narrowphase(
        &mut self,
        bodies: &BodySet,
        dt: Real,
        clipping: &ContactClipping,
        wake: &mut Vec<BodyHandle>,
    ) {
        // Phase 1: every contact's new manifold, independently (in parallel
        // with the `parallel` feature: the results do not depend on the
        // thread count, since each contact is computed alone).
        let mut results = std::mem::take(&mut self.scratch);
        results.clear();
        {
            let this = &*self;
            let compute = |c: &Contact| this.update_of(c, bodies, dt);
            #[cfg(feature = "parallel")]
            {
                use rayon::prelude::*;
                self.contacts
                    .par_iter()
                    .map(compute)
                    .collect_into_vec(&mut results);
            }
            #[cfg(not(feature = "parallel"))]
            results.extend(self.contacts.iter().map(compute));
        }
        // Phase 2, in contact order: destroy, store, events.
        let clip = !clipping.is_empty();
        let mut k = 0;
        let mut tested = 0;
        let mut touching_count = 0;
        while k < self.contacts.len() {
            let update = match results[k] {
                ContactUpdate::Asleep => {
                    self.contacts[k].still = [true, true];
                    k += 1;
                    continue;
                }
                ContactUpdate::Separated => {
                    self.destroy_contact(k);
                    results.swap_remove(k);
                    continue;
                }
                ContactUpdate::Manifold(ref m) => m,
            };
            tested += 1;
            let c = &mut self.contacts[k];
            let was_touching = c.touching;
            update_manifold(c, &update.manifold, update.offset);
            c.still = update.still;
            if clip {
                clipping.apply(c);
            }
            let touching = c.point_count > 0;
            c.touching = touching;
            if touching && (update.still[0] || update.still[1]) {
                let other = if update.still[0] { c.body_a } else { c.body_b };
                if bodies.is_sleeping(other) {
                    wake.push(other);
                    // Woken before the solve: it moves this step.
                    c.still = [false, false];
                }
            }
            if touching {
                touching_count += 1;
            }
            if touching != was_touching {
                let sensor = c.sensor;
                let ev = ShapePairEvent {
                    shape_a: self.handle_of(self.contacts[k].shape_a),
                    shape_b: self.handle_of(self.contacts[k].shape_b),
                };
                match (touching, sensor) {
                    (true, false) => self.events.contact_begin.push(ev),
                    (false, false) => self.events.contact_end.push(ev),
                    (true, true) => self.events.sensor_begin.push(ev),
                    (false, true) => self.events.sensor_end.push(ev),
                }
            }
            k += 1;
        }
        self.scratch = results;
        self.counters.pairs_tested = tested;
        self.counters.touching = touching_count;
    }

    /// The new manifold of one contact (phase 1 of the narrowphase).
    fn update_of(&self, c: &Contact, bodies: &BodySet, dt: Real) -> ContactUpdate {
        let body_a = bodies.solver_body(c.body_a);
        let body_b = bodies.solver_body(c.body_b);
        if body_a.state_index == 0 && body_b.state_index == 0 {
            // Both asleep (or asleep and static): nothing moves.
            return ContactUpdate::Asleep;
        }
        let sa = &self.shapes[c.shape_a as usize];
        let sb = &self.shapes[c.shape_b as usize];
        if !self.broadphase.test_overlap(sa.proxy, sb.proxy) {
            return ContactUpdate::Separated;
        }
        let (sim_a, sim_b) = (body_a.sim, body_b.sim);
        let reach = |aabb: &Aabb, center: Vec2| {
            (aabb.lower - center)
                .abs()
                .max((aabb.upper - center).abs())
                .length()
        };
        let approach = (body_b.state.v - body_a.state.v).length()
            + body_a.state.w.abs() * reach(&sa.aabb, sim_a.center)
            + body_b.state.w.abs() * reach(&sb.aabb, sim_b.center);
        let speculative = SPECULATIVE_DISTANCE + dt * approach;
        ContactUpdate::Manifold(Computed {
            manifold: collide(
                &sa.geometry,
                &sim_a.transform,
                &sb.geometry,
                &sim_b.transform,
                speculative,
            ),
            offset: [
                sim_a.transform.p - sim_a.center,
                sim_b.transform.p - sim_b.center,
            ],
            still: [body_a.state_index == 0, body_b.state_index == 0],
        })
    }

    /// Builds the contact constraints of touching solid contacts.
    ///
    /// Contacts between two moving bodies come first and contacts with a
    /// static body last, so each Gauss–Seidel sweep ends on the ground: the
    /// support a stack stands on has the last word (as Box2D v3 keeps
    /// static contacts out of its first graph color).
    ///
    /// Whether a body reads as static was noted by the narrowphase
    /// ([`Contact::still`]); a contact whose two bodies are still sleeps.
    /// When islands were woken after the narrowphase (`woke`), contacts
    /// that slept are checked again.
    pub fn build_constraints(
        &mut self,
        bodies: &BodySet,
        woke: bool,
        out: &mut Vec<ContactConstraint>,
    ) {
        out.clear();
        if woke {
            for c in self.contacts.iter_mut().filter(|c| c.still == [true, true]) {
                c.still = [
                    bodies.state_index(c.body_a) == Some(0),
                    bodies.state_index(c.body_b) == Some(0),
                ];
            }
        }
        let (mut rows, mut bouncy) = (0, 0);
        for pass in [false, true] {
            self.build_pass(pass, out, &mut rows, &mut bouncy);
        }
        self.counters.contact_rows = rows;
        self.counters.restitution_contacts = bouncy;
    }

    fn build_pass(
        &self,
        static_pass: bool,
        out: &mut Vec<ContactConstraint>,
        rows: &mut usize,
        bouncy: &mut usize,
    ) {
        for (k, c) in self.contacts.iter().enumerate() {
            if !c.touching || c.sensor || !c.enabled {
                continue;
            }
            let [sa, sb] = c.still;
            if (sa && sb) || (sa || sb) != static_pass {
                continue;
            }
            *rows += 2 * c.point_count;
            *bouncy += usize::from(c.restitution > 0.0);
            let mut inputs = [ContactPointInput::default(); 2];
            for (input, p) in inputs.iter_mut().zip(&c.points[..c.point_count]) {
                *input = ContactPointInput {
                    anchor_a: p.anchor_a,
                    anchor_b: p.anchor_b,
                    separation: p.separation,
                    normal_impulse: p.normal_impulse,
                    tangent_impulse: p.tangent_impulse,
                };
            }
            out.push(ContactConstraint::new(
                c.body_a,
                c.body_b,
                c.normal,
                &inputs[..c.point_count],
                c.friction,
                c.restitution,
                k as u32,
            ));
        }
    }

    /// Copies solved impulses back into the contacts (for warm starting).
    pub fn store_impulses(&mut self, constraints: &[ContactConstraint]) {
        for cc in constraints {
            let c = &mut self.contacts[cc.contact_index as usize];
            for i in 0..cc.point_count() {
                let (n, t) = cc.impulses(i);
                c.points[i].normal_impulse = n;
                c.points[i].tangent_impulse = t;
            }
        }
    }

    /// Recomputes the boxes of the shapes of moving bodies and moves their
    /// proxies when they left their fat boxes.
    ///
    /// A fast body's proxy box covers the shape now and where its velocity
    /// takes it within `dt`, so pairs exist before it arrives.
    pub fn update_proxies(&mut self, bodies: &BodySet, dt: Real) {
        let mut moved = 0;
        for (sim, state) in bodies.sims.iter().zip(&bodies.states).skip(1) {
            let b = sim.handle.index as usize;
            let Some(list) = self.body_shapes.get(b) else {
                continue;
            };
            // Only a body that travels more than half the fat margin in a
            // step gets a swept box: slower ones stay inside their fat box
            // as in Box2D, so they are not re-inserted more often.
            let sweep = dt * state.v;
            let fast = sweep.length_squared() > (0.5 * AABB_MARGIN) * (0.5 * AABB_MARGIN);
            for &s in list {
                let shape = &mut self.shapes[s as usize];
                let mut aabb = shape.geometry.compute_aabb(&sim.transform);
                shape.aabb = aabb;
                if fast {
                    aabb = Aabb::new(
                        aabb.lower + sweep.min(Vec2::ZERO),
                        aabb.upper + sweep.max(Vec2::ZERO),
                    );
                }
                if self.broadphase.move_proxy(shape.proxy, aabb) {
                    moved += 1;
                }
            }
        }
        self.counters.proxies_moved = moved;
    }

    /// Recomputes one body's shape boxes now (after a teleport).
    pub fn refresh_body(&mut self, body: BodyHandle, xf: &Transform) {
        if let Some(list) = self.body_shapes.get(body.index as usize) {
            for &s in list {
                let shape = &mut self.shapes[s as usize];
                let aabb = shape.geometry.compute_aabb(xf);
                shape.aabb = aabb;
                self.broadphase.move_proxy(shape.proxy, aabb);
                self.broadphase.touch_proxy(shape.proxy);
            }
        }
    }
}

/// Replaces a contact's manifold, carrying impulses over by feature id and
/// converting anchors from body origins to centres of mass.
fn update_manifold(c: &mut Contact, m: &Manifold, offset: [Vec2; 2]) {
    let old = c.points;
    let old_count = c.point_count;
    c.normal = m.normal;
    c.point_count = m.point_count;
    let [off_a, off_b] = offset;
    for i in 0..m.point_count {
        let mp = &m.points[i];
        let mut p = ContactPointData {
            point: mp.point,
            anchor_a: mp.anchor_a + off_a,
            anchor_b: mp.anchor_b + off_b,
            separation: mp.separation,
            id: mp.id,
            normal_impulse: 0.0,
            tangent_impulse: 0.0,
        };
        if let Some(o) = old[..old_count].iter().find(|o| o.id == mp.id) {
            p.normal_impulse = o.normal_impulse;
            p.tangent_impulse = o.tangent_impulse;
        }
        c.points[i] = p;
    }
}

/// Checks a shape given by its public fields: finite coordinates, positive
/// radii, and a polygon that is convex, counter-clockwise and has area.
pub fn validate_geometry(shape: &Shape) -> Result<(), janus2d_core::geometry::GeometryError> {
    use janus2d_core::geometry::GeometryError as E;
    use janus2d_core::math::{cross, vec_is_finite};
    let finite = |pts: &[Vec2]| pts.iter().all(|p| vec_is_finite(*p));
    match shape {
        Shape::Circle(c) => {
            if !finite(&[c.center]) || !c.radius.is_finite() {
                return Err(E::NonFinite);
            }
            if c.radius <= 0.0 {
                return Err(E::NonPositiveRadius);
            }
        }
        Shape::Capsule(c) => {
            if !finite(&[c.center1, c.center2]) || !c.radius.is_finite() {
                return Err(E::NonFinite);
            }
            if c.radius <= 0.0 {
                return Err(E::NonPositiveRadius);
            }
        }
        Shape::Segment(s) => {
            if !finite(&[s.point1, s.point2]) {
                return Err(E::NonFinite);
            }
            if (s.point2 - s.point1).length() <= janus2d_core::geometry::shapes::WELD_DISTANCE {
                return Err(E::DegenerateSegment);
            }
        }
        Shape::ChainSegment(c) => {
            if !finite(&[c.ghost1, c.segment.point1, c.segment.point2, c.ghost2]) {
                return Err(E::NonFinite);
            }
            if (c.segment.point2 - c.segment.point1).length()
                <= janus2d_core::geometry::shapes::WELD_DISTANCE
            {
                return Err(E::DegenerateSegment);
            }
        }
        Shape::Polygon(p) => {
            let n = p.count;
            if n > janus2d_core::geometry::shapes::MAX_POLYGON_VERTICES {
                return Err(E::TooManyVertices { count: n });
            }
            if !finite(&p.vertices[..n]) || !finite(&p.normals[..n]) || !p.radius.is_finite() {
                return Err(E::NonFinite);
            }
            if p.radius < 0.0 {
                return Err(E::NegativeRadius);
            }
            if n == 2 {
                // A capsule core: needs a radius and a length.
                if p.radius <= 0.0 {
                    return Err(E::NonPositiveRadius);
                }
                return Ok(());
            }
            if n < 3 {
                return Err(E::TooFewPoints {
                    found: n,
                    needed: 3,
                });
            }
            let mut area2 = 0.0;
            for i in 0..n {
                let a = p.vertices[i];
                let b = p.vertices[(i + 1) % n];
                let c = p.vertices[(i + 2) % n];
                if cross(b - a, c - b) <= 0.0 {
                    return Err(E::DegeneratePolygon);
                }
                area2 += cross(a, b);
            }
            if area2 <= 0.0 {
                return Err(E::DegeneratePolygon);
            }
        }
    }
    Ok(())
}
