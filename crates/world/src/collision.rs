//! The collision stage: shapes, the broadphase, persistent contacts, and
//! contact and sensor events.
//!
//! ```text
//! step start ─ update_pairs: moved proxies → new shape pairs (sorted)
//!                 filter: same body, both non-dynamic, category/mask/group,
//!                 joints with collide_connected = false (NoCollide)
//!            ─ narrowphase (narrowphase.rs): for each awake contact
//!                 fat boxes apart → destroy (end event if touching)
//!                 manifold = collide(a, b); impulses carried by feature id
//!                 touching changed → begin/end event
//!            ─ constraints: one ContactConstraint per touching, solid contact
//! step end   ─ store impulses; recompute AABBs of moved bodies, move proxies
//! ```
//!
//! | part | type | owns |
//! |------|------|------|
//! | shapes | [`ShapeStore`] | geometry, material, filter, proxy, box; body → shapes |
//! | pairs | [`BroadPhase`] | two dynamic trees, the move buffer |
//! | contacts | [`ContactSet`] | awake and sleeping contacts; pair and body indices |
//! | events | [`CollisionEvents`] | begin/end since the last step was read |
//!
//! Contacts are iterated in list order and found through indices used only
//! for lookups: the order of every loop is the same for the same inputs.

use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::geometry::Shape;
use janus2d_core::math::{Real, Transform, Vec2};
use janus2d_core::parallel::Team;

use crate::broadphase::{BroadPhase, BulkFinish};
pub use crate::contacts::CollisionEvents;
use crate::contacts::{Contact, ContactPointData, ContactSet};
use crate::dynamic_tree::TREE_REBUILD_PERIOD;
use crate::hooks::Hooks;
use crate::joints::NoCollide;
use crate::shapes::{ShapeData, ShapeDef, ShapeHandle, ShapeStore};

/// Fattening margin of broadphase boxes, m (0.1). One constant, defined
/// beside the tree.
pub use crate::dynamic_tree::DEFAULT_AABB_MARGIN as AABB_MARGIN;

use crate::broadphase::{bounded, proxy_margin};

pub use crate::profile::CollisionCounters;

/// Shapes, broadphase and contacts of a world.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct Collision {
    pub(crate) owner: u32,
    pub(crate) shapes: ShapeStore,
    pub(crate) broadphase: BroadPhase,
    pub(crate) contacts: ContactSet,
    /// Events since the last step was read.
    pub(crate) events: CollisionEvents,
    pub(crate) counters: CollisionCounters,
    pub(crate) narrowphase: crate::narrowphase::Narrowphase,
    candidates: Vec<(u32, u32)>,
    /// The chains: which shapes are segments of one chain.
    pub(crate) chains: crate::chains::ChainSet,
}

/// What the collision stage hands to contact building after the
/// narrowphase: the touching list, with the contact set and the
/// counters that building writes (the one plain hand-off between the
/// collision side and the solver side).
pub(crate) struct ContactHandoff<'a> {
    /// The narrowphase's touching list.
    pub(crate) narrow: crate::narrowphase::Handoff<'a>,
    /// The persistent contacts.
    pub(crate) contacts: &'a mut ContactSet,
    /// The step's counters (building adds its rows).
    pub(crate) counters: &'a mut CollisionCounters,
}

impl Collision {
    /// Whether the world has any shape (else the stage does nothing).
    #[inline]
    pub(crate) fn has_shapes(&self) -> bool {
        !self.shapes.is_empty()
    }

    /// The shapes (read by the portal stage's aperture clipping).
    #[inline]
    pub(crate) fn shape_store(&self) -> &ShapeStore {
        &self.shapes
    }

    /// Updates each existing contact of shape `slot` from its two shapes
    /// (`f(shape a, shape b, contact)`): what a shape setter does to the
    /// contacts it already has (event switches, mixed materials).
    pub(crate) fn update_contacts_of_shape(
        &mut self,
        slot: u32,
        mut f: impl FnMut(&ShapeData, &ShapeData, &mut Contact),
    ) {
        let body = self.shapes.at(slot).body;
        let ids: smallvec::SmallVec<[u32; 8]> =
            self.contacts.of_body(body).iter().copied().collect();
        for id in ids {
            let Some(c) = self.contacts.get_mut(id) else {
                continue;
            };
            if c.shape_a == slot || c.shape_b == slot {
                f(self.shapes.at(c.shape_a), self.shapes.at(c.shape_b), c);
            }
        }
    }

    /// The narrowphase over the pairs the broadphase holds: manifolds,
    /// impulses carried by feature, begin/end events, and in `wake` the
    /// sleeping bodies a new touch wakes. `beside`: the caller's serial
    /// work that reads nothing the narrowphase writes, run on the leader
    /// while the other threads start on the contacts.
    pub(crate) fn collide(
        &mut self,
        bodies: &BodySet,
        dt: Real,
        clipping: &crate::aperture::ContactClipping,
        wake: &mut Vec<BodyHandle>,
        team: &Team,
        beside: impl FnOnce(),
    ) {
        let input = crate::narrowphase::NarrowphaseInput {
            shapes: &self.shapes,
            broadphase: &self.broadphase,
            bodies,
            dt,
            clipping,
            unclipped: clipping.is_empty(),
        };
        self.narrowphase.run(
            &input,
            &mut self.contacts,
            &mut self.events,
            &mut self.counters,
            wake,
            team,
            beside,
        );
    }

    /// The contacts that began or stopped touching since the last call
    /// (for the islands).
    #[inline]
    pub(crate) fn take_touch_changes(&mut self) -> crate::contacts::TouchChanges {
        self.contacts.take_touch_changes()
    }

    /// Whether any contact is awake (the contact graph has work).
    #[inline]
    pub(crate) fn has_awake_contacts(&self) -> bool {
        !self.contacts.awake().is_empty()
    }

    /// Gives every shape's proxy the filter bits of its shape's filter
    /// again (a world decoded from a snapshot's bytes, whose trees carry
    /// none: see [`crate::dynamic_tree::FilterBits`]).
    #[cfg(feature = "serde")]
    pub(crate) fn refresh_filter_bits(&mut self) {
        let (shapes, broadphase) = (&mut self.shapes, &mut self.broadphase);
        for shape in shapes.entries_mut().iter().filter_map(|(_, s)| s.as_ref()) {
            broadphase.set_proxy_bits(shape.proxy, shape.def.filter.bits());
        }
    }

    /// The hand-off to contact building (after [`Collision::collide`]).
    #[inline]
    pub(crate) fn contact_handoff(&mut self) -> ContactHandoff<'_> {
        ContactHandoff {
            narrow: self.narrowphase.handoff(),
            contacts: &mut self.contacts,
            counters: &mut self.counters,
        }
    }

    /// Whether a solved contact has restitution this step.
    #[inline]
    pub(crate) fn has_restitution(&self) -> bool {
        self.counters.restitution_contacts > 0
    }

    /// Whether some shape asks for hit events.
    #[inline]
    pub(crate) fn has_hit_events(&self) -> bool {
        self.shapes.hit_event_shapes() > 0
    }

    /// Forgets the kept impulses of a body's contacts (a body reset for a
    /// non-finite state).
    #[inline]
    pub(crate) fn forget_impulses(&mut self, body: BodyHandle) {
        self.contacts.forget_impulses(body);
    }

    /// The step's counters.
    #[inline]
    pub(crate) fn counters(&self) -> CollisionCounters {
        self.counters
    }

    /// The events of the step, taken (the next step starts empty).
    #[inline]
    pub(crate) fn take_events(&mut self) -> CollisionEvents {
        self.events.take()
    }

    /// Copies the shapes' extents that changed since the last step into
    /// the bodies' per-step data, where the solve's finalize bounds each
    /// body's travel against them (`crate::continuous::publish_extents`).
    pub(crate) fn publish_extents(&mut self, bodies: &mut BodySet) {
        crate::continuous::publish_extents(&mut self.shapes, bodies);
    }

    /// Hands back the lists of the events the last step reported (the
    /// step is replacing them), so this step's events reuse their memory.
    pub(crate) fn recycle_events(&mut self, old: CollisionEvents) {
        self.events.recycle(old);
    }

    /// The shapes and the contacts, for the sleep stage (islands read the
    /// shapes' sensors and move contacts between awake and asleep).
    #[inline]
    pub(crate) fn sleep_parts(&mut self) -> (&ShapeStore, &mut ContactSet) {
        (&self.shapes, &mut self.contacts)
    }

    /// Empty pipeline for a world with owner id `owner`.
    pub(crate) fn new(owner: u32) -> Self {
        Collision {
            owner,
            shapes: ShapeStore::default(),
            broadphase: BroadPhase::with_margin(AABB_MARGIN),
            contacts: ContactSet::default(),
            events: CollisionEvents::default(),
            counters: CollisionCounters::default(),
            narrowphase: Default::default(),
            candidates: Vec::new(),
            chains: crate::chains::ChainSet::default(),
        }
    }

    /// Adds a shape (already validated) to a live body.
    pub(crate) fn add_shape(
        &mut self,
        bodies: &BodySet,
        body: BodyHandle,
        geometry: Shape,
        def: ShapeDef,
    ) -> ShapeHandle {
        let sim = bodies.sim(body).expect("live body");
        let aabb = geometry.compute_aabb(&sim.transform);
        let is_static = sim.body_type == BodyType::Static;
        let index = self.shapes.insert(ShapeData {
            body,
            geometry,
            def,
            proxy: 0,
            aabb,
        });
        // A disabled body's shapes stay out of the broadphase.
        let proxy = if bodies.is_disabled(body) {
            crate::broadphase::NO_PROXY
        } else {
            let margin = proxy_margin(&geometry, self.broadphase.margin());
            let bits = self.shapes.at(index).def.filter.bits();
            self.broadphase
                .create_proxy_filtered(bounded(aabb), index, is_static, margin, bits)
        };
        self.shapes.at_mut(index).proxy = proxy;
        self.shapes.handle_of(index, self.owner)
    }

    /// Gives every movable shape the broadphase's whole margin from now on
    /// instead of its size-based [`proxy_margin`]: a world with portals
    /// needs it. The portal stage (crossings, clipped manifolds) was built
    /// and checked with one 0.1 m margin for all; with size-based margins
    /// the portal stream completed 123 of its 200 crossings at 4 substeps
    /// instead of 194 and blew up at 1 and 16 substeps.
    #[cfg(feature = "portals")]
    pub(crate) fn use_uniform_margins(&mut self) {
        let shapes = &self.shapes;
        self.broadphase
            .use_uniform_margin(|s| bounded(shapes.at(s).aabb));
    }

    /// Checks shapes ↔ broadphase proxies (for `World::validate`): each
    /// shape's proxy is live, carries the shape's slot, sits in the tree
    /// of its body's type, and its fat box contains the shape's box at the
    /// body's current pose; no other proxy is live.
    pub(crate) fn check_proxies(&self, bodies: &BodySet) -> Result<(), String> {
        self.broadphase.check()?;
        let mut count = 0usize;
        let mut disabled_shapes = 0usize;
        for body in bodies.handles() {
            let Some(sim) = bodies.sim(body) else {
                continue;
            };
            let disabled = bodies.is_disabled(body);
            for &s in self.shapes.of_body(body) {
                let shape = self.shapes.at(s);
                if disabled {
                    if shape.proxy != crate::broadphase::NO_PROXY {
                        return Err(format!("shape {s} of a disabled body has a proxy"));
                    }
                    disabled_shapes += 1;
                    continue;
                }
                count += 1;
                if !self.broadphase.is_live(shape.proxy) {
                    return Err(format!("shape {s}: proxy {} is not live", shape.proxy));
                }
                if self.broadphase.payload(shape.proxy) != s {
                    return Err(format!("shape {s}: its proxy carries another shape"));
                }
                let is_static = sim.body_type == BodyType::Static;
                if self.broadphase.is_static(shape.proxy) != is_static {
                    return Err(format!("shape {s}: proxy in the wrong tree"));
                }
                let now = bounded(shape.geometry.compute_aabb(&sim.transform));
                if !self.broadphase.fat_aabb(shape.proxy).contains(&now) {
                    return Err(format!(
                        "shape {s}: proxy box {:?} does not contain the shape's {:?}",
                        self.broadphase.fat_aabb(shape.proxy),
                        now
                    ));
                }
            }
        }
        if count + disabled_shapes != self.shapes.len() || self.broadphase.proxy_count() != count {
            return Err(format!(
                "{} shapes, {count} on live bodies, {} proxies",
                self.shapes.len(),
                self.broadphase.proxy_count()
            ));
        }
        Ok(())
    }

    /// Removes a shape and its contacts (end events for touching ones).
    pub(crate) fn remove_shape(&mut self, index: u32) {
        let body = self.shapes.at(index).body;
        self.contacts.destroy_of_body(body, &mut self.events, |c| {
            c.shape_a == index || c.shape_b == index
        });
        let data = self.shapes.remove(index);
        self.broadphase.destroy_proxy(data.proxy);
    }

    /// Removes every contact between bodies `a` and `b` (a joint that does
    /// not collide its bodies was created).
    pub(crate) fn remove_contacts_between(&mut self, a: BodyHandle, b: BodyHandle) {
        self.contacts
            .destroy_of_body(a, &mut self.events, |c| c.other(a) == b);
    }

    /// Removes every contact of a body (end events for touching ones).
    pub(crate) fn remove_contacts_of(&mut self, body: BodyHandle) {
        self.contacts
            .destroy_of_body(body, &mut self.events, |_| true);
    }

    /// Makes the broadphase report every pair of a body's shapes again at
    /// the next pair update (a filter that kept them apart went).
    pub(crate) fn refind_pairs_of(&mut self, body: BodyHandle) {
        for &s in self.shapes.of_body(body) {
            self.broadphase.touch_proxy(self.shapes.at(s).proxy);
        }
    }

    /// Moves the shapes of two bodies whose identities were swapped (their
    /// contacts must be gone already) to their new owners. When the bodies
    /// have as many shapes (a portal crossing's two copies, the clone's
    /// shapes made in the order of the original's), each slot keeps its
    /// body, handle, material, filter, flags and user data, and takes its
    /// counterpart's geometry, box, proxy and density: the handles follow
    /// the object as the body handles do. Otherwise the lists are
    /// exchanged whole (the shapes keep their handles and change body).
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn swap_body_shapes(&mut self, a: BodyHandle, b: BodyHandle) {
        let (la, lb) = (
            smallvec::SmallVec::<[u32; 4]>::from_slice(self.shapes.of_body(a)),
            smallvec::SmallVec::<[u32; 4]>::from_slice(self.shapes.of_body(b)),
        );
        if la.len() == lb.len() {
            for (&i, &j) in la.iter().zip(&lb) {
                self.shapes.exchange_copies(i, j);
                self.broadphase.set_payload(self.shapes.at(i).proxy, i);
                self.broadphase.set_payload(self.shapes.at(j).proxy, j);
            }
        } else {
            self.shapes.swap_bodies(a, b);
        }
        // Proxies must report their pairs again under the new owners.
        self.refind_pairs_of(a);
        self.refind_pairs_of(b);
    }

    /// Finds new pairs among moved proxies and creates their contacts.
    /// The pair filter of `hooks` (if any) is asked about each new pair
    /// that passed the shapes' filters, in pair order; the material
    /// callbacks mix the new contacts' materials.
    pub(crate) fn update_pairs(
        &mut self,
        bodies: &BodySet,
        no_collide: &NoCollide,
        hooks: &mut Hooks,
        team: &Team,
    ) {
        let mut candidates = std::mem::take(&mut self.candidates);
        candidates.clear();
        // Only new pairs are kept, as the broadphase finds them (on the
        // threads with `parallel`): most pairs a moved proxy overlaps
        // already have a contact and are dropped before they are collected
        // and sorted. The contacts are created here in pair order.
        let (shapes, contacts) = (&self.shapes, &self.contacts);
        let keep = |a: u32, b: u32| {
            let (a, b) = crate::contacts::pair_key(a, b);
            !contacts.has_pair(a, b) && should_pair(shapes, bodies, no_collide, a, b)
        };
        self.broadphase.update_pairs(keep, &mut candidates, team);
        let mut created = 0;
        for &(a, b) in &candidates {
            let (a, b) = crate::contacts::pair_key(a, b);
            let (sa, sb) = (self.shapes.at(a), self.shapes.at(b));
            let shapes = [
                self.shapes.handle_of(a, self.owner),
                self.shapes.handle_of(b, self.owner),
            ];
            if let Some(filter) = hooks.pair_filter.as_mut()
                && !filter(shapes[0], shapes[1])
            {
                continue;
            }
            let mixed = hooks.mix(sa, sb);
            let contact = Contact {
                id: 0,
                shape_a: a,
                shape_b: b,
                shapes,
                body_a: sa.body,
                body_b: sb.body,
                normal: Vec2::ZERO,
                points: [ContactPointData::default(); 2],
                point_count: 0,
                friction: mixed.friction,
                restitution: mixed.restitution,
                tangent_speed: mixed.tangent_speed,
                rolling_resistance: mixed.rolling_resistance,
                user_material_ids: [sa.def.user_material_id, sb.def.user_material_id],
                touching: false,
                sensor: sa.def.is_sensor || sb.def.is_sensor,
                hit_events: sa.def.enable_hit_events || sb.def.enable_hit_events,
                event_flags: crate::contacts::event_flags::of(&sa.def, &sb.def),
                enabled: true,
                still: [false, false],
                solve_bodies: [(0, [0.0; 2]); 2],
                recycle: crate::contacts::RecycleCache::default(),
            };
            self.contacts.insert(contact);
            created += 1;
        }
        self.counters.pairs_created = created;
        self.candidates = candidates;
    }

    /// Hit events of the step: `approaches` reports the solved points that
    /// approached faster than the world's threshold and pushed (contact
    /// index, point, approach speed in m/s; the solver side's read-back);
    /// each contact with hit events on gets one event, at its fastest.
    /// Returns the points it read.
    pub(crate) fn collect_hits(
        &mut self,
        approaches: impl FnOnce(&mut dyn FnMut(u32, usize, Real)),
    ) -> usize {
        let mut best: Vec<(u32, usize, Real)> = Vec::new();
        let contacts = &self.contacts;
        let mut read = 0;
        approaches(&mut |index, point, speed| {
            read += 1;
            if !contacts.awake()[index as usize].hit_events {
                return;
            }
            // A contact's points come one after the other.
            match best.last_mut() {
                Some(b) if b.0 == index => {
                    if b.2 < speed {
                        *b = (index, point, speed);
                    }
                }
                _ => best.push((index, point, speed)),
            }
        });
        best.sort_unstable_by_key(|b| b.0);
        for (index, point, speed) in best {
            let c = &self.contacts.awake()[index as usize];
            let p = &c.points[point];
            let half = 0.5 * p.separation * c.normal;
            self.events.hits.push(crate::contacts::HitEvent {
                shape_a: c.shapes[0],
                shape_b: c.shapes[1],
                point: p.point,
                point_a: p.point - half,
                point_b: p.point + half,
                normal: c.normal,
                approach_speed: speed,
            });
        }
        read
    }

    /// Whether some shape has a finite force event threshold.
    #[inline]
    pub(crate) fn has_force_events(&self) -> bool {
        self.shapes.force_event_shapes() > 0
    }

    /// Contact force events of the step (the impulses stored): each awake
    /// solid touching contact whose total normal force, its points' step
    /// impulses over `dt`, exceeds the smaller of its shapes' thresholds,
    /// in contact order. Run only when some shape has a threshold. Returns
    /// the contacts it read.
    pub(crate) fn collect_forces(&mut self, dt: Real) -> usize {
        let inv_dt = 1.0 / dt;
        let mut read = 0;
        for c in self.contacts.awake() {
            read += 1;
            if !c.is_solid_touching() {
                continue;
            }
            let threshold = self
                .shapes
                .at(c.shape_a)
                .def
                .force_event_threshold
                .min(self.shapes.at(c.shape_b).def.force_event_threshold);
            if !threshold.is_finite() {
                continue;
            }
            let (mut total, mut max) = (0.0, 0.0);
            for p in c.points() {
                let f = p.total_normal_impulse * inv_dt;
                total += f;
                if f > max {
                    max = f;
                }
            }
            let total_force = total * c.normal;
            let magnitude = total_force.length();
            if magnitude > threshold {
                self.events.forces.push(crate::contacts::ContactForceEvent {
                    shape_a: c.shapes[0],
                    shape_b: c.shapes[1],
                    total_force,
                    total_force_magnitude: magnitude,
                    max_force_magnitude: max,
                    max_force_direction: c.normal,
                });
            }
        }
        read
    }

    /// The step's end for the pipeline: `advance` (continuous collision:
    /// it moves fast bodies, reading the shapes and the broadphase) runs,
    /// the shapes' boxes follow the new poses, and then the solved impulses
    /// go back into the contacts (`store`) while the leader moves the
    /// proxies that left their boxes (`beside`, the serial part of the
    /// proxy update: it shares no data with the contacts) and, when they
    /// are few, rebuilds the part of the tree they grew. When a quarter of
    /// the proxies or more moved, the whole tree is finished after the
    /// store: on a step whose count `step` is a multiple of
    /// [`TREE_REBUILD_PERIOD`] rebuilt, its spans on the team, on the
    /// others refitted in its shape ([`BroadPhase::finish_moves_with`]).
    /// Each on the step's team. Returns what `advance` returned.
    ///
    /// ```text
    /// team:    advance ─ boxes ─┬─ store (blocks of contacts) ──────┬─ whole tree (many moved):
    /// leader:                   └─ proxy moves, part of the tree ───┘  rebuilt 1 step in 8, else refitted
    /// ```
    pub(crate) fn end_step<R>(
        &mut self,
        bodies: &mut BodySet,
        step: u64,
        dt: Real,
        store: impl FnOnce(&mut ContactSet, &Team, &mut dyn FnMut()),
        advance: impl FnOnce(&mut BodySet, &ShapeStore, &BroadPhase, &Team) -> R,
        team: &Team,
    ) -> R {
        let out = advance(bodies, &self.shapes, &self.broadphase, team);
        let bodies = &*bodies;
        let mut moved = 0;
        if Self::boxes_by_slot(team, bodies, &self.shapes) {
            let order = Self::update_boxes(&mut self.shapes, &self.broadphase, bodies, dt, team);
            let (shapes, broadphase) = (&self.shapes, &mut self.broadphase);
            let mut beside = || moved = Self::move_proxies(&order, shapes, broadphase, bodies, dt);
            store(&mut self.contacts, team, &mut beside);
        } else {
            let (shapes, broadphase) = (&mut self.shapes, &mut self.broadphase);
            let mut beside =
                || moved = Self::update_proxies_by_body(shapes, broadphase, bodies, dt);
            store(&mut self.contacts, team, &mut beside);
        }
        // A batch of many moves left the whole tree to finish: rebuilt (its
        // spans on the team, now that the store is done) on every
        // TREE_REBUILD_PERIOD-th step, refitted in its shape on the others.
        let bulk = if step.is_multiple_of(TREE_REBUILD_PERIOD) {
            BulkFinish::Rebuild
        } else {
            BulkFinish::Refit
        };
        self.broadphase.finish_moves_with(team, bulk);
        self.counters.proxies_moved = moved;
        out
    }

    /// Whether the proxy update goes over the shape slots on the team
    /// ([`Collision::update_boxes`]) rather than over the moving bodies on
    /// the leader ([`Collision::update_proxies_by_body`]): with more than
    /// one thread, at least 1,024 moving bodies, and moving bodies at least
    /// half as many as the shapes. The pass by slot visits every shape,
    /// static or asleep ones too, so where most shapes do not move (a
    /// level's static geometry, a sleeping pile) the pass by body, whose
    /// cost follows the moving bodies alone, is cheaper. Both move the
    /// same proxies to the same boxes; only the order differs, and the
    /// tree and the pairs do not depend on it (see
    /// [`Collision::update_boxes`]).
    fn boxes_by_slot(team: &Team, bodies: &BodySet, shapes: &ShapeStore) -> bool {
        let moving = bodies.moving_count();
        team.threads() > 1 && moving >= 1024 && 2 * moving >= shapes.len()
    }

    /// Recomputes the boxes of the shapes of moving bodies and moves their
    /// proxies when they left their fat boxes, body by body in state order
    /// (each body's shapes in its list's order); returns the number moved.
    /// The pass for one thread and for worlds whose shapes mostly do not
    /// move ([`Collision::boxes_by_slot`]).
    fn update_proxies_by_body(
        shapes: &mut ShapeStore,
        broadphase: &mut BroadPhase,
        bodies: &BodySet,
        dt: Real,
    ) -> usize {
        let mut moved = 0;
        for (sim, state) in bodies.sims.iter().zip(&bodies.states).skip(1) {
            let sweep = dt * state.v;
            let n = shapes.of_body(sim.handle).len();
            for k in 0..n {
                let s = shapes.of_body(sim.handle)[k];
                let shape = shapes.at_mut(s);
                let tight = shape.geometry.compute_aabb(&sim.transform);
                shape.aabb = tight;
                if broadphase.move_proxy_in_batch_swept(shape.proxy, bounded(tight), sweep) {
                    moved += 1;
                }
            }
        }
        Self::finish_few_moves(broadphase);
        moved
    }

    /// Ends the batch of proxy moves here, beside the impulse store, when
    /// it moved few proxies; a batch of many is left for
    /// [`Collision::end_step`] to finish the whole tree (rebuilt on the
    /// team, or refitted).
    fn finish_few_moves(broadphase: &mut BroadPhase) {
        if !broadphase.moves_are_bulk() {
            broadphase.finish_moves();
        }
    }

    /// Recomputes the boxes of the shapes of moving bodies and lists the
    /// shapes whose proxies left their fat boxes, in the order
    /// [`Collision::move_proxies`] moves them. Touches only the shapes (and
    /// reads the broadphase; see [`Collision::end_step`]).
    ///
    /// A shape that travels more than half its fat margin in a step gets a
    /// swept box ([`BroadPhase::move_proxy_in_batch_swept`]), so pairs
    /// exist before it arrives; slower ones stay inside their fat box as in
    /// Box2D, so they are not re-inserted more often.
    ///
    /// ```text
    /// on the team, shape slots in blocks:  each live shape of a moving body:
    ///                                        tight box from its body's pose
    ///                                        keeps its boxes? (read only)
    /// here, in slot order:                 the shapes whose proxies move, moved
    /// ```
    ///
    /// The moves come in shape slot order, not in the order of the pass
    /// by body ([`Collision::update_proxies_by_body`]), and the tree comes
    /// out the same: a moved leaf's box does not depend on the others, its
    /// ancestors grow to the union of their moved leaves' boxes, and the
    /// rebuild that follows reads the tree, not the order of the moves.
    /// The move buffer holds the same proxies in another order; the pair
    /// update sorts it, and a snapshot writes it sorted. (Until stop 63
    /// the moves were sorted into body order, a sort on the leader while
    /// the team stored the impulses.) Before (stop 54), the team
    /// computed the boxes by body and the leader then wrote every shape's
    /// box and asked every proxy in body order: on many_pyramids (22,000
    /// bodies, two threads) that loop alone took 1.2–1.5 ms a step, more
    /// than the whole pass by body on one thread (0.8–1.6 ms); by slot the
    /// update takes 0.5–0.8 ms on two threads.
    fn update_boxes(
        shapes: &mut ShapeStore,
        broadphase: &BroadPhase,
        bodies: &BodySet,
        dt: Real,
        team: &Team,
    ) -> Vec<(u32, u32)> {
        const BLOCK: usize = 512;
        let entries = shapes.entries_mut();
        // Per shape slot: its body's state index when its proxy moves, else 0.
        let mut moves = vec![0u32; entries.len()];
        team.for_each_chunk_pair_mut(entries, &mut moves, BLOCK, |_, block, moving| {
            for ((_, entry), moving) in block.iter_mut().zip(moving) {
                let Some(shape) = entry else { continue };
                let i = bodies.state_index(shape.body).unwrap_or(0);
                if i == 0 {
                    // Static, asleep or disabled: not moved.
                    continue;
                }
                let tight = shape
                    .geometry
                    .compute_aabb(&bodies.sims[i as usize].transform);
                shape.aabb = tight;
                if !broadphase.keeps_boxes(
                    shape.proxy,
                    bounded(tight),
                    dt * bodies.states[i as usize].v,
                ) {
                    *moving = i;
                }
            }
        });
        // (body state index, shape slot), in slot order.
        moves
            .iter()
            .enumerate()
            .filter(|&(_, &i)| i != 0)
            .map(|(s, &i)| (i, s as u32))
            .collect()
    }

    /// Moves the proxies [`Collision::update_boxes`] listed (`order`: body
    /// state index, shape slot), then rebuilds the movable proxies' tree;
    /// returns the number moved.
    fn move_proxies(
        order: &[(u32, u32)],
        shapes: &ShapeStore,
        broadphase: &mut BroadPhase,
        bodies: &BodySet,
        dt: Real,
    ) -> usize {
        let mut moved = 0;
        for &(i, s) in order {
            let shape = shapes.at(s);
            let sweep = dt * bodies.states[i as usize].v;
            if broadphase.move_proxy_in_batch_swept(shape.proxy, bounded(shape.aabb), sweep) {
                moved += 1;
            }
        }
        Self::finish_few_moves(broadphase);
        moved
    }

    /// Moves a body's shape proxies to the tree of its (new) type: each is
    /// destroyed and created again, so its pairs are found afresh.
    pub(crate) fn reproxy_body(&mut self, body: BodyHandle, xf: &Transform, is_static: bool) {
        let n = self.shapes.of_body(body).len();
        for k in 0..n {
            let s = self.shapes.of_body(body)[k];
            let old = self.shapes.at(s).proxy;
            if old == crate::broadphase::NO_PROXY {
                // A disabled body's shape: no proxy until it is enabled.
                continue;
            }
            self.broadphase.destroy_proxy(old);
            self.make_proxy(s, xf, is_static);
        }
    }

    /// Takes a body's shapes out of the broadphase (a disabled body):
    /// their proxies become `NO_PROXY`.
    pub(crate) fn drop_body_proxies(&mut self, body: BodyHandle) {
        let n = self.shapes.of_body(body).len();
        for k in 0..n {
            let s = self.shapes.of_body(body)[k];
            self.broadphase.destroy_proxy(self.shapes.at(s).proxy);
            self.shapes.at_mut(s).proxy = crate::broadphase::NO_PROXY;
        }
    }

    /// Puts a body's shapes (without proxies) back into the broadphase at
    /// `xf` (an enabled body).
    pub(crate) fn add_body_proxies(&mut self, body: BodyHandle, xf: &Transform, is_static: bool) {
        let n = self.shapes.of_body(body).len();
        for k in 0..n {
            let s = self.shapes.of_body(body)[k];
            self.make_proxy(s, xf, is_static);
        }
    }

    /// Shape `s`'s box at `xf` and a new proxy for it.
    fn make_proxy(&mut self, s: u32, xf: &Transform, is_static: bool) {
        let shape = self.shapes.at(s);
        let aabb = shape.geometry.compute_aabb(xf);
        let margin = proxy_margin(&shape.geometry, self.broadphase.margin());
        let bits = shape.def.filter.bits();
        let proxy =
            self.broadphase
                .create_proxy_filtered(bounded(aabb), s, is_static, margin, bits);
        let shape = self.shapes.at_mut(s);
        shape.aabb = aabb;
        shape.proxy = proxy;
    }

    /// Recomputes one body's shape boxes now (after a teleport).
    pub(crate) fn refresh_body(&mut self, body: BodyHandle, xf: &Transform) {
        let n = self.shapes.of_body(body).len();
        for k in 0..n {
            let s = self.shapes.of_body(body)[k];
            let shape = self.shapes.at_mut(s);
            let aabb = shape.geometry.compute_aabb(xf);
            shape.aabb = aabb;
            let proxy = shape.proxy;
            self.broadphase.move_proxy(proxy, bounded(aabb));
            self.broadphase.touch_proxy(proxy);
        }
    }
}

/// Whether shapes `a` and `b` (slot indices) may have a contact: on
/// different bodies, passing each other's filter, one of them dynamic,
/// and their bodies not jointed with collision off.
fn should_pair(
    shapes: &ShapeStore,
    bodies: &BodySet,
    no_collide: &NoCollide,
    a: u32,
    b: u32,
) -> bool {
    let (sa, sb) = (shapes.at(a), shapes.at(b));
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
    !no_collide.contains(sa.body, sb.body)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broadphase::AABB_MARGIN_FRACTION;
    use crate::{World, WorldDef};
    use janus2d_core::body::BodyDef;
    use janus2d_core::geometry::{Aabb, Polygon, SPECULATIVE_DISTANCE};

    /// The fat box and margin of the only shape of `body`.
    fn fat_of(world: &World, body: BodyHandle) -> (Aabb, Aabb, Real) {
        let c = &world.collision;
        let s = c.shapes.of_body(body)[0];
        let shape = c.shapes.at(s);
        let proxy = shape.proxy;
        (
            shape.aabb,
            c.broadphase.fat_aabb(proxy),
            c.broadphase.proxy_margin(proxy),
        )
    }

    /// A world decoded from a snapshot's bytes, whose trees carry no
    /// filter bits, takes its shapes' again: 40 overlapping boxes of a
    /// category that refuses itself leave nothing to search, and the
    /// tree's unions hold.
    #[cfg(feature = "serde")]
    #[test]
    fn decoded_snapshots_take_their_shapes_filter_bits_again() {
        let mut world = World::new(WorldDef::default()).unwrap();
        let refusing = ShapeDef {
            filter: crate::Filter::new(2, !2),
            ..ShapeDef::default()
        };
        for i in 0..40 {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(0.3 * i as Real, 0.0)))
                .unwrap();
            world
                .create_shape(b, &refusing, Polygon::make_box(0.5, 0.5))
                .unwrap();
        }
        world.step(1.0 / 60.0).unwrap();
        let tree = |w: &World| w.collision.broadphase.dynamic_tree().clone();
        assert!(!tree(&world).may_pair_within());
        let bytes = world.snapshot().to_bytes();
        let decoded = crate::Snapshot::from_bytes(&bytes).unwrap().to_world();
        tree(&decoded).validate();
        // (Without the refresh every node decodes to `FilterBits::ALL`,
        // which pairs with anything.)
        assert!(!tree(&decoded).may_pair_within(), "bits set again");
        assert_eq!(world.state_hash(), decoded.state_hash());
    }

    fn body_with_box(world: &mut World, x: Real, half: Real) -> BodyHandle {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, 0.0)))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(half, half))
            .unwrap();
        b
    }

    #[test]
    fn small_shapes_get_fat_margins_sized_by_their_extent() {
        let mut world = World::new(WorldDef::default()).unwrap();
        let small = body_with_box(&mut world, 0.0, 0.1);
        let large = body_with_box(&mut world, 5.0, 0.5);
        let (tight, fat, margin) = fat_of(&world, small);
        // 0.02 m speculative + 0.125 × 0.1·√2 m.
        let want = SPECULATIVE_DISTANCE + AABB_MARGIN_FRACTION * (0.02 as Real).sqrt();
        assert!((margin - want).abs() < 1e-6, "margin {margin}, want {want}");
        assert!((fat.lower.x - (tight.lower.x - want)).abs() < 1e-5);
        assert!((fat.upper.y - (tight.upper.y + want)).abs() < 1e-5);
        // A box of half-width 0.5 reaches the whole 0.1 m.
        let (tight, fat, margin) = fat_of(&world, large);
        assert_eq!(margin, AABB_MARGIN);
        assert!((fat.upper.x - (tight.upper.x + AABB_MARGIN)).abs() < 1e-5);
    }

    #[cfg(feature = "portals")]
    #[test]
    fn portal_pair_gives_every_shape_the_full_margin() {
        use crate::{PortalDef, PortalPairDef};
        let mut world = World::new(WorldDef::default()).unwrap();
        let small = body_with_box(&mut world, 0.0, 0.1);
        // A neighbour 0.15 m away: beyond two sized margins (2 × 0.038 m),
        // within two full ones (2 × 0.1 m).
        let neighbour = body_with_box(&mut world, 0.35, 0.1);
        let proxy_of = |world: &World, body| {
            let c = &world.collision;
            c.shapes.at(c.shapes.of_body(body)[0]).proxy
        };
        let overlap = |world: &World| {
            world
                .collision
                .broadphase
                .test_overlap(proxy_of(world, small), proxy_of(world, neighbour))
        };
        assert!(fat_of(&world, small).2 < AABB_MARGIN);
        assert!(!overlap(&world));
        let floor = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let wall = world
            .create_body(&BodyDef::fixed(Vec2::new(10.0, 0.0)))
            .unwrap();
        let at = |body| PortalDef {
            body,
            anchor: Vec2::ZERO,
            direction: Vec2::Y,
            half_width: 0.5,
        };
        world
            .create_portal_pair(&PortalPairDef::new(at(floor), at(wall)))
            .unwrap();
        // The shape made before the pair and one made after it.
        let later = body_with_box(&mut world, 3.0, 0.1);
        for body in [small, later] {
            let (tight, fat, margin) = fat_of(&world, body);
            assert_eq!(margin, AABB_MARGIN);
            assert!((fat.lower.y - (tight.lower.y - AABB_MARGIN)).abs() < 1e-5);
        }
        // The pair test reads the full margins at once, before any move.
        assert!(overlap(&world));
        assert!(world.validate().is_ok());
    }

    /// A body built shape by shape widens its kept extents by each new
    /// shape only; the result is what a recount of its shapes gives, to
    /// the bit, and a removed shape recounts.
    #[test]
    fn extents_widened_shape_by_shape_equal_a_recount() {
        use janus2d_core::geometry::{Capsule, Circle};
        let mut world = World::new(WorldDef::default()).unwrap();
        let body = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0)))
            .unwrap();
        let def = ShapeDef::default();
        let mut last = None;
        for k in 0..6 {
            let x = k as Real * 0.7 - 1.5;
            last = Some(
                match k % 3 {
                    0 => world.create_shape(
                        body,
                        &def,
                        Polygon::make_offset_box(0.2, 0.4, Vec2::new(x, 0.1), 0.3),
                    ),
                    1 => world.create_shape(
                        body,
                        &def,
                        Circle::new(Vec2::new(x, -0.2), 0.3).unwrap(),
                    ),
                    _ => world.create_shape(
                        body,
                        &def,
                        Capsule::new(Vec2::new(x, 0.5), Vec2::new(x + 0.4, 0.9), 0.1).unwrap(),
                    ),
                }
                .unwrap(),
            );
            let kept = world.collision.shapes.extent_of(body);
            world.collision.shapes.refresh_extent(body);
            let recount = world.collision.shapes.extent_of(body);
            assert_eq!(kept, recount, "after shape {k}");
            assert!(kept.max_extent > 0.0 && kept.min_extent < Real::MAX);
        }
        let before = world.collision.shapes.extent_of(body);
        world.destroy_shape(last.unwrap()).unwrap();
        let after = world.collision.shapes.extent_of(body);
        assert!(
            after.max_extent < before.max_extent,
            "{after:?} vs {before:?}"
        );
    }
}
