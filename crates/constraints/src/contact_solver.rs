//! The contact solve in colours and lanes: the contact rows of
//! [`crate::contact_row`] run [`LANES`] contacts at a time, the overflow
//! one [`ContactConstraint`] at a time.
//!
//! ```text
//! build      (the collision pipeline, two passes over its contacts)
//!   colour   greedy: the first colour in which neither moving body
//!            already appears (static, kinematic and sleeping bodies take
//!            no colour: the solve never changes their state)
//!   push     each contact's lane data into the open chunk of its colour,
//!            structure of arrays; the overflow (a body in every colour, a
//!            portal copy whose contacts need the object-mass hook, or a
//!            light cluster's contact) as scalar ContactConstraints
//!
//!            colour 0: [c0 c3 c7 … ] [c12 … pad]     chunk = LANES lanes
//!            colour 1: [c1 c4 … pad]
//!            …
//!            overflow: c9 c40 …
//!
//! prepare    lane-wise: K (and the normal rows' 2×2 block), the mass-ratio
//!            softness, the approach speed;
//!            overflow scalar, then the object-mass hook on it, then the
//!            light clusters' groups (crate::contact_group)
//! warm start, solve (bias), relax (no bias), restitution
//!            colour by colour (solve and relax reversed on alternate
//!            sweeps), chunk by chunk: gather the lanes' body states (in
//!            f32 a quad at a time, then 4×4 transposes), the row code
//!            (ContactRows, the same as the overflow's) on lanes, scatter
//!            the velocities the same way; then the overflow, scalar,
//!            and each light cluster's group as one block
//! store      the impulses of every lane and overflow constraint go back to
//!            the pipeline's contacts, by contact index
//! ```
//!
//! Within a colour no dynamic body appears twice, so the lanes of a chunk
//! and the chunks of a colour are independent: the order inside a colour
//! does not change the result. A padding lane reads and writes the static
//! identity state 0 with zero masses and Jacobians, which leaves it as it
//! was; so does a lane on a static or kinematic body (its inverse masses are
//! zero, the velocity it writes back is the one it read).
//!
//! The lane type ([`crate::lane::Wide`]) is `wide::f32x8` (8 lanes) with
//! `f32` and `wide::f64x4` (4 lanes) with the `f64` feature: SIMD without
//! `unsafe`. A chunk (`WideContact`) is a data holder: the lanes' state
//! and contact indices and their rows in structure-of-arrays form.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintBatch, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::{PlannedStates, StatePlan, Team};

use crate::contact::{ContactConstraint, MAX_MANIFOLD_POINTS};
use crate::contact_group::{Groups, solve_group};
#[cfg(feature = "f64")]
use crate::contact_row::Delta;
use crate::contact_row::{ContactRows, Velocity};
use crate::lane::{Lane, Wide as W};

pub use crate::contact_row::BLOCK_CONDITION;
pub use crate::lane::LANES;

pub use janus2d_core::graph::COLOURS;

/// The largest factor by which a hooked contact's row may overstep its
/// copy's own response (dimensionless). A contact on a copy crossing a
/// portal builds its effective mass on the whole object's (heavier) mass
/// while its impulse acts on the copy alone until the portal rows share
/// it: within an iteration the copy answers `m_object / m_copy` times
/// harder than the row assumed, an over-relaxation. Gauss–Seidel over-
/// relaxed by 2 or more diverges, and a copy holding a small part of its
/// object under a pile of contacts did: a 200-body stream through a
/// portal reached 10⁷ m/s in one step. The object's inverse mass and
/// inertia are used down to the copy's divided by this factor.
pub const OBJECT_MASS_OVERRELAXATION: Real = 1.5;

/// A dynamic body that stands for a whole object (a copy crossing a
/// portal): its contacts build their effective masses on the object's
/// inverse mass and inertia, while their impulses still act on the copy
/// (see the portal stage's contact-modification hook). Body states carry
/// no masses: the object's are simply what these contacts load at prepare.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectMass {
    /// The copy.
    pub body: BodyHandle,
    /// Inverse mass of the whole object as seen from this copy, 1/kg.
    pub inv_mass: Real,
    /// Inverse rotational inertia of the whole object, 1/(kg·m²).
    pub inv_inertia: Real,
}

/// [`LANES`] contacts in structure-of-arrays form: their rows
/// ([`ContactRows`] on the wide lane type, what the warm start, the
/// velocity iterations and restitution read and write) and which bodies
/// and contacts the lanes hold.
#[derive(Clone, Debug)]
pub(crate) struct WideContact {
    /// State index of body a per lane (0: static identity or padding).
    state_a: [u32; LANES],
    /// State index of body b per lane.
    state_b: [u32; LANES],
    /// The pipeline's contact index per lane.
    contact: [u32; LANES],
    /// Number of lanes in use (the rest are padding).
    len: usize,
    /// 1 where the lane's manifold has a second point, else 0.
    second: W,
    /// Bit `k`: lane `k`'s body a is moved by the solve (dynamic and
    /// awake); bit `LANES + k`: its body b. The parallel stages write only
    /// these.
    moving: u32,
    /// The rows of the lanes' contacts.
    rows: ContactRows<W>,
}

/// A colour's chunks: the first `used` are this step's, the rest were an
/// earlier step's and wait to be reused. A chunk is over a kilobyte, and
/// writing a new one whole (zeroed, then moved into place) was a tenth of
/// the contact hand-off; a reused chunk has its header reset
/// ([`WideContact::reopen`]), its lanes overwritten as contacts are pushed
/// and the free lanes of a colour's last chunk cleared before the prepare
/// ([`Chunks::seal`]), which leaves it as a new chunk would be.
#[derive(Clone, Debug, Default)]
struct Chunks {
    all: Vec<WideContact>,
    used: usize,
    /// The chunks of this push block begin here ([`PUSH_BLOCK`]): none of
    /// an earlier block takes more lanes.
    block_start: usize,
}

impl std::ops::Deref for Chunks {
    type Target = [WideContact];
    fn deref(&self) -> &[WideContact] {
        &self.all[..self.used]
    }
}

impl std::ops::DerefMut for Chunks {
    fn deref_mut(&mut self) -> &mut [WideContact] {
        &mut self.all[..self.used]
    }
}

impl Chunks {
    /// No chunk in use (their memory kept).
    fn clear(&mut self) {
        self.used = 0;
        self.block_start = 0;
    }

    /// One more chunk in use, with no lane: a kept one reopened, or a new
    /// one.
    fn open(&mut self) {
        match self.all.get_mut(self.used) {
            Some(kept) => kept.reopen(),
            None => self.all.push(WideContact::empty()),
        }
        self.used += 1;
        // The colour's next kept chunk, written over the next pushes.
        if let Some(next) = self.all.get(self.used) {
            janus2d_core::hint::prefetch_all(next);
        }
    }

    /// The free lanes of the last chunk in use cleared (a reused chunk
    /// holds an earlier step's lanes there): call once the pushes are
    /// done.
    fn seal(&mut self) {
        if let Some(last) = self.last_mut() {
            last.clear_free_lanes();
        }
    }

    /// A new push block begins ([`PUSH_BLOCK`]): the last chunk is
    /// sealed and the block's first push opens a chunk of its own.
    fn begin_block(&mut self) {
        self.seal();
        self.block_start = self.used;
    }
}

pub use crate::contact_row::PointImpulse;
pub use janus2d_core::contact_input::ContactLane;

/// Where a pushed contact lives in the solver: a lane of a colour's chunk,
/// or a place in the overflow. [`ContactSolver::push_all`] reports one per
/// contact, so that the pipeline can read each contact's impulses back in
/// its own order ([`ContactSolver::point_impulse_at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LanePlace {
    /// The colour ([`OVERFLOW`] for the overflow).
    pub colour: u8,
    /// The lane within its chunk (0 in the overflow).
    pub lane: u8,
    /// The chunk within its colour, or the index in the overflow.
    pub chunk: u32,
}

/// A step's contact constraints in their colours and lanes: the contact
/// batch's own data.
///
/// The pipeline gives each contact its colour from the persistent
/// [`ConstraintGraph`](janus2d_core::graph::ConstraintGraph) (or the
/// overflow), then [`ContactSolver::push`] (or `push_all`) writes it into
/// the open chunk of that colour, reading the contacts in order while the
/// open chunks (one per colour) stay in cache.
#[derive(Clone, Debug, Default)]
pub struct ContactSolver {
    /// Chunks per colour; the last chunk of a colour may have free lanes.
    colours: Vec<Chunks>,
    /// Contacts solved one by one (or in the coupled groups of light
    /// clusters, see [`crate::contact_group`]).
    overflow: Vec<ContactConstraint>,
    /// Per overflow contact: it builds on a portal object's masses.
    hooked: Vec<bool>,
    /// Per overflow contact: its sides' light clusters (`ContactLane::cluster`).
    clusters: Vec<[u32; 2]>,
    /// The coupled groups of the overflow's light clusters.
    groups: Groups,
    /// Number of contacts pushed since [`ContactSolver::begin`].
    len: usize,
    /// Scratch of [`ContactSolver::push_all`]: each push block's contacts
    /// per colour.
    block_counts: Vec<[u32; COLOURS]>,
    /// Which states each chunk reads and writes, one group per colour,
    /// verified at prepare (parallel stages only).
    plan: StatePlan<PLAN_SLOTS>,
}

/// How many chunks on [`ContactSolver::for_each_impulse_into`] asks for
/// the contacts it will write.
const CHUNKS_AHEAD: usize = 1;

/// The colour slot of the overflow (solved scalar, one contact at a time).
pub const OVERFLOW: u8 = COLOURS as u8;

impl ContactSolver {
    /// An empty solver.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of contacts in colour `colour` ([`OVERFLOW`] for the
    /// overflow, solved scalar).
    #[must_use]
    pub fn count_in(&self, colour: u8) -> usize {
        if colour >= OVERFLOW {
            return self.overflow.len();
        }
        self.colours
            .get(colour as usize)
            .map_or(0, |chunks| chunks.iter().map(|c| c.len).sum())
    }

    /// Number of contacts.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is no contact.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Drops every contact (the colours come from the caller's
    /// [`ConstraintGraph`](janus2d_core::graph::ConstraintGraph)).
    pub fn begin(&mut self) {
        self.colours.resize_with(COLOURS, Chunks::default);
        for chunks in &mut self.colours {
            chunks.clear();
        }
        self.overflow.clear();
        self.clusters.clear();
        self.len = 0;
    }

    /// Adds a contact to its colour ([`OVERFLOW`]: solved scalar).
    pub fn push(&mut self, colour: u8, lane: &ContactLane) -> LanePlace {
        self.push_with(colour, lane, lane.contact_index, lane.cluster)
    }

    /// [`ContactSolver::push`] with the contact's index and light clusters
    /// given apart from `lane` (whose own `contact_index` and `cluster`
    /// are not read): the caller pushes a staged lane as it is, with no
    /// copy to set them.
    pub fn push_with(
        &mut self,
        colour: u8,
        lane: &ContactLane,
        contact_index: u32,
        cluster: [u32; 2],
    ) -> LanePlace {
        if self.len > 0 && self.len.is_multiple_of(PUSH_BLOCK) {
            for chunks in &mut self.colours {
                chunks.begin_block();
            }
        }
        self.len += 1;
        if colour >= OVERFLOW {
            return self.push_overflow(lane, contact_index, cluster);
        }
        if self.colours.len() < COLOURS {
            self.colours.resize_with(COLOURS, Chunks::default);
        }
        let chunks = &mut self.colours[colour as usize];
        if chunks.used == chunks.block_start || chunks.last().is_none_or(|c| c.len == LANES) {
            chunks.open();
        }
        let index = chunks.len() - 1;
        let chunk = &mut chunks[index];
        let place = LanePlace {
            colour,
            lane: chunk.len as u8,
            chunk: index as u32,
        };
        chunk.push(
            lane,
            lane.point_count.min(MAX_MANIFOLD_POINTS),
            contact_index,
        );
        place
    }

    /// Appends a contact to the overflow (not counted in `len`).
    fn push_overflow(
        &mut self,
        lane: &ContactLane,
        contact_index: u32,
        cluster: [u32; 2],
    ) -> LanePlace {
        let count = lane.point_count.min(MAX_MANIFOLD_POINTS);
        let place = LanePlace {
            colour: OVERFLOW,
            lane: 0,
            chunk: self.overflow.len() as u32,
        };
        let mut c = ContactConstraint::new(
            lane.body_a,
            lane.body_b,
            lane.normal,
            &lane.points[..count],
            lane.friction,
            lane.restitution,
            contact_index,
        );
        c.set_surface(lane.tangent_speed, lane.rolling_resistance);
        c.state_a = lane.state_a;
        c.state_b = lane.state_b;
        self.overflow.push(c);
        self.clusters.push(cluster);
        place
    }

    /// Whether [`ContactSolver::push_all`] fills the chunks of `count`
    /// contacts in contact order on the caller (one thread, or fewer than
    /// `PARALLEL_PUSH`), as pushing them one by one with
    /// [`ContactSolver::push_with`] does.
    #[must_use]
    pub fn pushes_in_order(count: usize, team: &Team) -> bool {
        team.threads() == 1 || count < PARALLEL_PUSH
    }

    /// [`ContactSolver::push_with`] for many contacts at once: contact `i`
    /// goes into colour `colours[i]` with the lane data, index and
    /// clusters `lane(i)`, and its place into `places[i]`. The result is
    /// the one of pushing them in order; with the `parallel` feature and
    /// more than one thread the [`PUSH_BLOCK`]s are filled at once on
    /// `team`, each reading its contacts in order into chunks of its own.
    pub fn push_all<F>(&mut self, colours: &[u8], lane: F, places: &mut Vec<LanePlace>, team: &Team)
    where
        F: Fn(usize) -> (ContactLane, u32, [u32; 2]) + Sync,
    {
        // Each lane read where `lane` returned it (moved out of the tuple,
        // it went through a memcpy call whose loads waited on its stores:
        // 1.9% of smash's samples at one thread).
        let push = |solver: &mut Self, colour: u8, i: usize| {
            let read = lane(i);
            solver.push_with(colour, &read.0, read.1, read.2)
        };
        places.clear();
        if self.colours.len() < COLOURS {
            self.colours.resize_with(COLOURS, Chunks::default);
        }
        // One thread, few contacts, or contacts pushed already: push in
        // contact order on the caller, the open chunks (one per colour) in
        // cache.
        if Self::pushes_in_order(colours.len(), team) || self.len > 0 {
            for (i, &colour) in colours.iter().enumerate() {
                places.push(push(self, colour, i));
            }
            return;
        }
        // On the team: the overflow first, on the caller, then each push
        // block's contacts into chunks of its own, in blocks on the team;
        // the chunks are those the pushes in order make.
        let n = colours.len();
        let blocks = n.div_ceil(PUSH_BLOCK);
        // Each block's count per colour on the team, and whether it has
        // overflow contacts (a serial count was 1.2% of the leader's
        // samples in large_pyramid at two threads).
        let tallies = team.map_blocks(blocks, |b| {
            let mut count = [0u32; COLOURS];
            let mut overflow = false;
            for &colour in &colours[b * PUSH_BLOCK..((b + 1) * PUSH_BLOCK).min(n)] {
                if colour >= OVERFLOW {
                    overflow = true;
                } else {
                    count[colour as usize] += 1;
                }
            }
            (count, overflow)
        });
        let mut counts = std::mem::take(&mut self.block_counts);
        counts.clear();
        counts.extend(tallies.iter().map(|&(count, _)| count));
        places.resize(
            n,
            LanePlace {
                colour: OVERFLOW,
                lane: 0,
                chunk: 0,
            },
        );
        // The overflow's pushes in contact order, on the caller.
        for (b, _) in tallies.iter().enumerate().filter(|(_, t)| t.1) {
            let first = b * PUSH_BLOCK;
            for (i, &colour) in colours
                .iter()
                .enumerate()
                .take((first + PUSH_BLOCK).min(n))
                .skip(first)
            {
                if colour >= OVERFLOW {
                    let read = lane(i);
                    places[i] = self.push_overflow(&read.0, read.1, read.2);
                }
            }
        }
        self.len += n;
        // Block b's chunks of colour c come after those of the blocks
        // before it.
        let mut works: Vec<PushBlock<'_>> = places
            .chunks_mut(PUSH_BLOCK)
            .map(|places| PushBlock {
                places,
                chunks: std::array::from_fn(|_| &mut [][..]),
                first: [0; COLOURS],
            })
            .collect();
        for (c, chunks) in self.colours.iter_mut().enumerate() {
            let total: usize = counts.iter().map(|k| (k[c] as usize).div_ceil(LANES)).sum();
            if chunks.all.len() < total {
                chunks.all.resize_with(total, WideContact::empty);
            }
            chunks.used = total;
            chunks.block_start = total;
            let mut rest = &mut chunks.all[..total];
            let mut first = 0;
            for (work, k) in works.iter_mut().zip(&counts) {
                let (mine, tail) = rest.split_at_mut((k[c] as usize).div_ceil(LANES));
                rest = tail;
                work.first[c] = first;
                first += mine.len() as u32;
                work.chunks[c] = mine;
            }
        }
        team.for_each_chunk_mut(&mut works, 1, |b, work| {
            for work in work {
                work.fill(&colours[b * PUSH_BLOCK..], |i| lane(b * PUSH_BLOCK + i));
            }
        });
        self.block_counts = counts;
    }

    /// The impulses of point `point` of the contact at `place` (as
    /// [`ContactSolver::for_each_impulse`] reports them).
    #[must_use]
    #[inline]
    pub fn point_impulse_at(&self, place: LanePlace, point: usize) -> PointImpulse {
        if place.colour >= OVERFLOW {
            return self.overflow[place.chunk as usize].point_impulse(point);
        }
        let chunk = &self.colours[place.colour as usize][place.chunk as usize];
        let k = place.lane as usize;
        let rows = &chunk.rows;
        let (n, t) = (rows.impulse[point].lane(k), rows.impulse[point + 2].lane(k));
        PointImpulse {
            normal: n,
            tangent: t,
            total_normal: rows.step_base[point].lane(k) + n,
            total_tangent: rows.step_base[point + 2].lane(k) + t,
        }
    }

    /// Calls `store(contact_index, point, impulses)` for every point of
    /// every contact: the impulses to keep for the next step's warm start
    /// and the step's totals.
    pub fn for_each_impulse(&self, mut store: impl FnMut(u32, usize, PointImpulse)) {
        self.for_each_impulse_into(&mut (), |_, _| {}, |_, c, point, p| store(c, point, p));
    }

    /// [`ContactSolver::for_each_impulse`] into `target`, with
    /// `ahead(target, contact_index)` called for the contacts of the chunk
    /// `CHUNKS_AHEAD` on before a chunk's impulses are stored (chunks are in colour
    /// order, not contact order: the caller can ask for the lines it will
    /// write next).
    pub fn for_each_impulse_into<T>(
        &self,
        target: &mut T,
        ahead: impl Fn(&T, u32),
        mut store: impl FnMut(&mut T, u32, usize, PointImpulse),
    ) {
        for chunks in &self.colours {
            for (j, chunk) in chunks.iter().enumerate() {
                if let Some(next) = chunks.get(j + CHUNKS_AHEAD) {
                    for &c in &next.contact[..next.len] {
                        ahead(target, c);
                    }
                }
                let impulse = chunk.rows.impulse.map(W::to_array);
                let base = chunk.rows.step_base.map(W::to_array);
                chunk.for_each_point(|k, i| {
                    let (n, t) = (impulse[i][k], impulse[i + 2][k]);
                    let p = PointImpulse {
                        normal: n,
                        tangent: t,
                        total_normal: base[i][k] + n,
                        total_tangent: base[i + 2][k] + t,
                    };
                    store(target, chunk.contact[k], i, p);
                });
            }
        }
        for c in &self.overflow {
            for i in 0..c.point_count() {
                store(target, c.contact_index, i, c.point_impulse(i));
            }
        }
    }

    /// Calls `hit(contact_index, point, approach_speed)` for every point
    /// that approached faster than `threshold` (m/s) before the solve and
    /// pushed (a positive normal impulse increment).
    pub fn for_each_approach(&self, threshold: Real, mut hit: impl FnMut(u32, usize, Real)) {
        for chunk in self.colours.iter().flat_map(|chunks| chunks.iter()) {
            let approach = chunk.rows.relative_velocity.map(W::to_array);
            let pushed = chunk.rows.max_normal_impulse.map(W::to_array);
            chunk.for_each_point(|k, i| {
                let speed = -approach[i][k];
                if speed > threshold && pushed[i][k] > 0.0 {
                    hit(chunk.contact[k], i, speed);
                }
            });
        }
        for c in &self.overflow {
            for i in 0..c.point_count() {
                let speed = -c.rows.relative_velocity[i];
                if speed > threshold && c.rows.max_normal_impulse[i] > 0.0 {
                    hit(c.contact_index, i, speed);
                }
            }
        }
    }

    /// The contacts of the overflow, solved one by one.
    #[must_use]
    pub fn overflow(&self) -> &[ContactConstraint] {
        &self.overflow
    }

    /// Number of colour slots (the colours' chunk lists).
    pub(crate) fn colour_slots(&self) -> usize {
        self.colours.len()
    }

    /// Per body state, the colours in which a contact lane moves it: bit
    /// `c` of `out[s]` (the overflow takes no colour).
    #[cfg(test)]
    pub(crate) fn moving_colours(&self, state_count: usize, out: &mut Vec<u32>) {
        out.clear();
        out.resize(state_count, 0);
        for (c, chunks) in self.colours.iter().enumerate() {
            for chunk in chunks.iter() {
                for k in 0..chunk.len {
                    for (side, states) in [&chunk.state_a, &chunk.state_b].into_iter().enumerate() {
                        let moving = chunk.moving & (1 << (side * LANES + k)) != 0;
                        if let Some(bits) = out.get_mut(states[k] as usize).filter(|_| moving) {
                            *bits |= 1 << c;
                        }
                    }
                }
            }
        }
    }

    /// True when a stage should spread the colours over `team`.
    pub(crate) fn wants_team(&self, team: &Team) -> bool {
        team.threads() > 1 && self.colours.iter().any(|c| c.len() > SERIAL_CHUNKS)
    }

    /// The plan of the colours' chunks (built at prepare on a team of more
    /// than one thread).
    pub(crate) fn plan(&self) -> &StatePlan<PLAN_SLOTS> {
        &self.plan
    }

    /// Colour `c`'s chunks and the plan whose group `c` they are, when the
    /// plan has that group; chunks per block for `team`.
    pub(crate) fn colour_group(
        &mut self,
        c: usize,
        team: &Team,
    ) -> (&StatePlan<PLAN_SLOTS>, &mut [WideContact], usize) {
        let chunks = self.colours.get_mut(c).map_or(&mut [][..], |v| &mut v[..]);
        let per_block = block_len(team, chunks.len());
        (&self.plan, chunks, per_block)
    }

    /// Runs `stage` over colour `c`'s chunks (on the team when the colour
    /// is long, see `colour_stage`).
    pub(crate) fn run_colour(
        &mut self,
        c: usize,
        stage: Stage,
        states: &mut [BodyState],
        team: &Team,
    ) {
        if let Some(chunks) = self.colours.get_mut(c) {
            colour_stage(team, &self.plan, c, chunks, states, stage);
        }
    }

    /// Whether colour `c` runs on the caller alone (short, or a serial
    /// team): see `colour_stage`.
    pub(crate) fn colour_is_short(&self, c: usize, team: &Team) -> bool {
        let chunks = self.colours.get(c).map_or(0, |chunks| chunks.len());
        team.threads() == 1 || chunks <= SERIAL_CHUNKS || c >= self.plan.group_count()
    }

    fn prepare(
        &mut self,
        ctx: &StepContext,
        bodies: &BodySet,
        objects: &[ObjectMass],
        team: &Team,
    ) {
        let states = &bodies.states[..];
        self.plan.clear();
        let planned = team.threads() > 1;
        for chunks in &mut self.colours {
            chunks.seal();
            let per_block = block_len(team, chunks.len());
            if planned {
                // Each chunk's item of the state plan (its colour a group)
                // written beside its prepare, on the team (a serial pass
                // after it was 1.2% of the leader's samples in
                // large_pyramid at two threads).
                let (slots, writes) = self.plan.push_groups([chunks.len()]);
                team.for_each_chunk_triple_mut_beside(
                    chunks,
                    slots,
                    writes,
                    per_block,
                    |_, block, slots, writes| {
                        for ((chunk, slots), writes) in block.iter_mut().zip(slots).zip(writes) {
                            chunk.prepare(ctx, states);
                            (*slots, *writes) =
                                (plan_slots(&chunk.state_a, &chunk.state_b), chunk.moving);
                        }
                    },
                    || {},
                );
            } else {
                team.for_each_chunk_mut(chunks, per_block, |_, block| {
                    for chunk in block {
                        chunk.prepare(ctx, states);
                    }
                });
            }
        }
        if planned {
            // A plan that does not hold (it always should: the colouring
            // keeps moving bodies apart) leaves the stages serial.
            let verified = self.plan.verify_on(states.len(), team);
            debug_assert!(verified, "a colour holds a moving body twice");
        }
        self.hooked.clear();
        for c in &mut self.overflow {
            c.prepare(ctx, bodies);
            if objects.is_empty() {
                self.hooked.push(false);
                continue;
            }
            let find = |body| objects.iter().find(|o| o.body == body);
            let (oa, ob) = (find(c.body_a), find(c.body_b));
            self.hooked.push(oa.is_some() || ob.is_some());
            if oa.is_some() || ob.is_some() {
                let [m_a, i_a, m_b, i_b] = c.applied_masses();
                // The object's masses, but never below the copy's own by
                // more than OBJECT_MASS_OVERRELAXATION (see there).
                let object = |m: Real, i: Real, o: &ObjectMass| {
                    (
                        o.inv_mass.max(m / OBJECT_MASS_OVERRELAXATION),
                        o.inv_inertia.max(i / OBJECT_MASS_OVERRELAXATION),
                    )
                };
                let (m_a, i_a) = oa.map_or((m_a, i_a), |o| object(m_a, i_a, o));
                let (m_b, i_b) = ob.map_or((m_b, i_b), |o| object(m_b, i_b, o));
                c.prepare_rows(ctx, bodies, [m_a, i_a, m_b, i_b]);
                // The object masses stand for the copy and its twin joined
                // by the portal rows, not for the copy alone: the two points
                // are solved one by one, not as one block.
                c.rows.block = false;
            }
        }
        self.groups.build(
            ctx,
            &mut self.overflow,
            &self.clusters,
            &self.hooked,
            states.len(),
        );
    }

    fn warm_start(&mut self, states: &mut [BodyState], team: &Team) {
        for (colour, chunks) in self.colours.iter_mut().enumerate() {
            colour_stage(team, &self.plan, colour, chunks, states, Stage::WarmStart);
        }
        for c in &mut self.overflow {
            c.apply_warm_start(states);
        }
    }

    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        let stage = Stage::solve(ctx, use_bias);
        let colours = self.colours.len();
        for k in 0..colours {
            let colour = if reverse { colours - 1 - k } else { k };
            self.run_colour(colour, stage, states, team);
        }
        self.solve_overflow(states, use_bias, ctx.inv_h, ctx.contact_push_max_velocity);
    }

    /// The overflow: its contacts one by one, then the coupled groups of
    /// light clusters ([`crate::contact_group`]).
    pub(crate) fn solve_overflow(
        &mut self,
        states: &mut [BodyState],
        use_bias: bool,
        inv_h: Real,
        push_max: Real,
    ) {
        let grouped = &self.groups.grouped;
        for (k, c) in self.overflow.iter_mut().enumerate() {
            if grouped.get(k).copied().unwrap_or(false) {
                continue;
            }
            // A portal copy's contact has no block (see `prepare`): its two
            // points in both orders, so a flat face is pushed evenly.
            let hooked = self.hooked.get(k).copied().unwrap_or(false);
            c.solve_with(states, use_bias, hooked, inv_h, push_max);
        }
        for g in &self.groups.groups {
            let solved = if use_bias {
                solve_group::<true>(g, &mut self.overflow, states, inv_h, push_max)
            } else {
                solve_group::<false>(g, &mut self.overflow, states, inv_h, push_max)
            };
            if !solved {
                for &k in g.members() {
                    self.overflow[k as usize].solve_with(states, use_bias, false, inv_h, push_max);
                }
            }
        }
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        let threshold = W::splat(ctx.restitution_threshold);
        let stage = Stage::Restitution { threshold };
        for (colour, chunks) in self.colours.iter_mut().enumerate() {
            colour_stage(team, &self.plan, colour, chunks, states, stage);
        }
        for c in &mut self.overflow {
            c.apply_restitution(ctx, states);
        }
    }
}

/// Fewest chunks of a colour per block of a parallel stage (4 chunks: 32
/// contacts in f32).
const CHUNKS_PER_BLOCK: usize = 4;

/// Chunks of a colour up to which a velocity stage runs it on the leader
/// alone: a chunk's stage takes about 0.1 µs, handing a colour to the team
/// and waiting for it about 1–2 µs, so a colour of a few dozen chunks is
/// done sooner alone (tumbler, 2,000 bodies in colours of about 25
/// chunks: 0.96 ms of solver per step on 2 threads against 0.61 on one
/// when every colour of more than 4 chunks went to the team).
const SERIAL_CHUNKS: usize = 32;

/// Contacts from which [`ContactSolver::push_all`] fills the chunks on
/// threads (fewer are pushed in order on the caller: the lists and tasks
/// cost more than the filling).
const PARALLEL_PUSH: usize = 4096;

/// Contacts per push block: every [`PUSH_BLOCK`] contacts pushed, each
/// colour begins a new chunk, so that the blocks can be filled at once on
/// a team and the chunks are the same for every thread count (a
/// block's partly filled last chunks cost at most a chunk per colour in
/// use, about 1 % more chunks).
pub const PUSH_BLOCK: usize = 4096;

/// One push block's share of [`ContactSolver::push_all`]: its places, and
/// per colour its chunks and the index of the first of them.
struct PushBlock<'a> {
    places: &'a mut [LanePlace],
    chunks: [&'a mut [WideContact]; COLOURS],
    first: [u32; COLOURS],
}

impl PushBlock<'_> {
    /// Pushes the block's contacts (`colours[j]`, `lane(j)` for the j-th)
    /// into its chunks in order; the overflow's were placed already.
    fn fill(&mut self, colours: &[u8], lane: impl Fn(usize) -> (ContactLane, u32, [u32; 2])) {
        let mut pushed = [0usize; COLOURS];
        for (j, (place, &colour)) in self.places.iter_mut().zip(colours).enumerate() {
            if colour >= OVERFLOW {
                continue;
            }
            let c = colour as usize;
            let k = pushed[c];
            pushed[c] += 1;
            let (at, lane_k) = (k / LANES, k % LANES);
            let chunks = &mut *self.chunks[c];
            if lane_k == 0 {
                chunks[at].reopen();
                // The colour's next chunk, written over the next pushes.
                if let Some(next) = chunks.get(at + 1) {
                    janus2d_core::hint::prefetch_all(next);
                }
            }
            // Read in place: moved out of the tuple, the lane was copied
            // through a call to `memcpy` whose stores the push's loads
            // then waited on (many_pyramids at two threads: 5% of the
            // step).
            let read = lane(j);
            let lane = &read.0;
            chunks[at].push(lane, lane.point_count.min(MAX_MANIFOLD_POINTS), read.1);
            *place = LanePlace {
                colour,
                lane: lane_k as u8,
                chunk: self.first[c] + at as u32,
            };
        }
        for chunks in &mut self.chunks {
            if let Some(last) = chunks.last_mut() {
                last.clear_free_lanes();
            }
        }
    }
}

/// Chunks per block for `chunks` chunks on `team`: about four blocks per
/// thread (each claim is an atomic increment on a shared line), at least
/// [`CHUNKS_PER_BLOCK`].
fn block_len(team: &Team, chunks: usize) -> usize {
    chunks.div_ceil(4 * team.threads()).max(CHUNKS_PER_BLOCK)
}

/// A velocity stage of the contact chunks.
#[derive(Clone, Copy)]
pub(crate) enum Stage {
    WarmStart,
    Solve {
        use_bias: bool,
        inv_h: Real,
        push_max: Real,
    },
    Restitution {
        threshold: W,
    },
}

impl Stage {
    /// The solve (`use_bias`) or relax stage of a step.
    pub(crate) fn solve(ctx: &StepContext, use_bias: bool) -> Self {
        Stage::Solve {
            use_bias,
            inv_h: ctx.inv_h,
            push_max: ctx.contact_push_max_velocity,
        }
    }
}

impl WideContact {
    #[inline(always)]
    pub(crate) fn run<S: LaneStates>(&mut self, stage: Stage, states: &mut S) {
        match stage {
            Stage::WarmStart => self.warm_start(states),
            Stage::Solve {
                use_bias: true,
                inv_h,
                push_max,
            } => self.solve::<S, true>(states, inv_h, push_max),
            Stage::Solve {
                use_bias: false,
                inv_h,
                push_max,
            } => self.solve::<S, false>(states, inv_h, push_max),
            Stage::Restitution { threshold } => self.apply_restitution(states, threshold),
        }
    }
}

/// One stage over the chunks of colour `colour`.
///
/// On a serial team (or a short colour) the chunks run in order here. On a
/// team of several threads they run in blocks on the team, each reading
/// and writing the states through the verified plan: within a colour no
/// moving body appears twice, so every chunk sees the same states either
/// way and the results are bit-identical.
fn colour_stage(
    team: &Team,
    plan: &StatePlan<PLAN_SLOTS>,
    colour: usize,
    chunks: &mut [WideContact],
    states: &mut [BodyState],
    stage: Stage,
) {
    if team.threads() == 1 || chunks.len() <= SERIAL_CHUNKS || colour >= plan.group_count() {
        for chunk in chunks.iter_mut() {
            let mut direct = Direct {
                index: [chunk.state_a, chunk.state_b],
                states: &mut *states,
            };
            chunk.run(stage, &mut direct);
        }
        return;
    }
    let per_block = block_len(team, chunks.len());
    team.for_each_planned(plan, colour, chunks, states, per_block, |chunk, view| {
        chunk.run(stage, view)
    });
}

/// Side a of a lane (its first body).
const A: usize = 0;
/// Side b of a lane.
const B: usize = 1;

/// The body states as the lanes of one chunk see them: the state of side
/// `side` (a or b) of lane `k`, and its velocities written back.
pub(crate) trait LaneStates {
    fn load(&self, side: usize, k: usize) -> BodyState;
    fn store(&mut self, side: usize, k: usize, v: Vec2, w: Real);
    /// Writes the state's first quad, `[v.x, v.y, ω, flags]`: its
    /// velocities, and flags as they were read.
    #[cfg(not(feature = "f64"))]
    #[inline(always)]
    fn store_head(&mut self, side: usize, k: usize, head: wide::f32x4) {
        let [x, y, w, _] = head.to_array();
        self.store(side, k, Vec2::new(x, y), w);
    }
}

/// The serial view: the whole state slice and the chunk's state indices.
/// Lanes on the identity state, on a static or on a kinematic body write
/// what they read.
pub(crate) struct Direct<'s> {
    pub(crate) states: &'s mut [BodyState],
    pub(crate) index: [[u32; LANES]; 2],
}

impl LaneStates for Direct<'_> {
    #[inline(always)]
    fn load(&self, side: usize, k: usize) -> BodyState {
        self.states[self.index[side][k] as usize]
    }
    #[inline(always)]
    fn store(&mut self, side: usize, k: usize, v: Vec2, w: Real) {
        let s = &mut self.states[self.index[side][k] as usize];
        s.v = v;
        s.w = w;
    }
    #[cfg(not(feature = "f64"))]
    #[inline(always)]
    fn store_head(&mut self, side: usize, k: usize, head: wide::f32x4) {
        let s = &mut self.states[self.index[side][k] as usize];
        // A state is 32-byte aligned: its first quad is an aligned f32x4.
        bytemuck::cast_mut::<BodyState, [wide::f32x4; 2]>(s)[0] = head;
    }
}

/// Slots per chunk in the parallel stages' plan: both bodies of every lane.
pub(crate) const PLAN_SLOTS: usize = 2 * LANES;

/// A chunk's item of a state plan: its lanes' states on side a, then on
/// side b.
#[inline]
pub(crate) fn plan_slots(a: &[u32; LANES], b: &[u32; LANES]) -> [u32; PLAN_SLOTS] {
    let mut slots = [0; PLAN_SLOTS];
    slots[..LANES].copy_from_slice(a);
    slots[LANES..].copy_from_slice(b);
    slots
}

/// The parallel view: the chunk's slots of the verified plan (slot `k`:
/// body a of lane `k`, slot `LANES + k`: body b); only moving bodies are
/// written.
impl LaneStates for PlannedStates<'_, PLAN_SLOTS> {
    #[inline(always)]
    fn load(&self, side: usize, k: usize) -> BodyState {
        self.get(side * LANES + k)
    }
    #[inline(always)]
    fn store(&mut self, side: usize, k: usize, v: Vec2, w: Real) {
        self.set_velocity(side * LANES + k, v, w);
    }
}

/// The lanes' velocities and position deltas on side `side`.
#[cfg(feature = "f64")]
#[inline(always)]
pub(crate) fn load<S: LaneStates>(states: &S, side: usize) -> (Velocity<W>, Delta<W>, ()) {
    let mut v_x = [0.0; LANES];
    let mut v_y = [0.0; LANES];
    let mut w = [0.0; LANES];
    let mut dp_x = [0.0; LANES];
    let mut dp_y = [0.0; LANES];
    let mut q_c = [0.0; LANES];
    let mut q_s = [0.0; LANES];
    for k in 0..LANES {
        let s = states.load(side, k);
        v_x[k] = s.v.x;
        v_y[k] = s.v.y;
        w[k] = s.w;
        dp_x[k] = s.dp.x;
        dp_y[k] = s.dp.y;
        q_c[k] = s.dq.c;
        q_s[k] = s.dq.s;
    }
    (
        Velocity {
            v_x: W::from(v_x),
            v_y: W::from(v_y),
            w: W::from(w),
        },
        Delta {
            dp_x: W::from(dp_x),
            dp_y: W::from(dp_y),
            q_c: W::from(q_c),
            q_s: W::from(q_s),
        },
        (),
    )
}

/// The lanes' velocities only (the warm start needs no position deltas).
#[cfg(feature = "f64")]
#[inline(always)]
fn load_velocity<S: LaneStates>(states: &S, side: usize) -> (Velocity<W>, ()) {
    let mut v_x = [0.0; LANES];
    let mut v_y = [0.0; LANES];
    let mut w = [0.0; LANES];
    for k in 0..LANES {
        let s = states.load(side, k);
        v_x[k] = s.v.x;
        v_y[k] = s.v.y;
        w[k] = s.w;
    }
    (
        Velocity {
            v_x: W::from(v_x),
            v_y: W::from(v_y),
            w: W::from(w),
        },
        (),
    )
}

/// Writes the lanes' velocities back.
#[cfg(feature = "f64")]
#[inline(always)]
fn store<S: LaneStates>(states: &mut S, side: usize, v: &Velocity<W>, _flags: ()) {
    store_where(states, side, v, (), u32::MAX);
}

/// Writes the velocities of the lanes whose bit is set in `lanes` back
/// (bit `k`: lane `k`).
#[cfg(feature = "f64")]
#[inline(always)]
pub(crate) fn store_where<S: LaneStates>(
    states: &mut S,
    side: usize,
    v: &Velocity<W>,
    _flags: (),
    lanes: u32,
) {
    let (v_x, v_y, w) = (v.v_x.to_array(), v.v_y.to_array(), v.w.to_array());
    for k in 0..LANES {
        if lanes & (1 << k) != 0 {
            states.store(side, k, Vec2::new(v_x[k], v_y[k]), w[k]);
        }
    }
}

/// With `f32`, a [`BodyState`] is two aligned quads of four numbers,
/// `[v.x, v.y, ω, flags | dp.x, dp.y, dq.c, dq.s]`: the lanes' states are
/// read a quad at a time and turned into lanes by 4×4 transposes (as Box2D
/// gathers its bodies), not number by number.
#[cfg(not(feature = "f64"))]
mod quads {
    use super::LaneStates;
    use crate::contact_row::{Delta, Velocity};
    use crate::lane::{LANES, Wide as W};
    use wide::f32x4;

    /// Side `side`'s states as quads, lanes 0–3 then 4–7: the velocity
    /// quads `[v.x, v.y, ω, flags]` and the delta quads.
    #[inline(always)]
    fn quads<S: LaneStates>(states: &S, side: usize, deltas: bool) -> [[[f32x4; 4]; 2]; 2] {
        let mut q = [[[f32x4::ZERO; 4]; 2]; 2];
        for k in 0..LANES {
            let [head, tail]: [f32x4; 2] = bytemuck::cast(states.load(side, k));
            q[0][k / 4][k % 4] = head;
            if deltas {
                q[1][k / 4][k % 4] = tail;
            }
        }
        q
    }

    /// Two quads as the lanes 0–3 and 4–7 of one wide number.
    #[inline(always)]
    fn join(lo: f32x4, hi: f32x4) -> W {
        bytemuck::cast([lo, hi])
    }

    /// The lanes' velocities and position deltas on side `side`.
    #[inline(always)]
    pub(crate) fn load<S: LaneStates>(states: &S, side: usize) -> (Velocity<W>, Delta<W>, W) {
        let [v, d] = quads(states, side, true);
        let (v0, v1) = (f32x4::transpose(v[0]), f32x4::transpose(v[1]));
        let (d0, d1) = (f32x4::transpose(d[0]), f32x4::transpose(d[1]));
        (
            Velocity {
                v_x: join(v0[0], v1[0]),
                v_y: join(v0[1], v1[1]),
                w: join(v0[2], v1[2]),
            },
            Delta {
                dp_x: join(d0[0], d1[0]),
                dp_y: join(d0[1], d1[1]),
                q_c: join(d0[2], d1[2]),
                q_s: join(d0[3], d1[3]),
            },
            join(v0[3], v1[3]),
        )
    }

    /// The lanes' velocities only (the warm start needs no position
    /// deltas).
    #[inline(always)]
    pub(super) fn load_velocity<S: LaneStates>(states: &S, side: usize) -> (Velocity<W>, W) {
        let [v, _] = quads(states, side, false);
        let (v0, v1) = (f32x4::transpose(v[0]), f32x4::transpose(v[1]));
        let v = Velocity {
            v_x: join(v0[0], v1[0]),
            v_y: join(v0[1], v1[1]),
            w: join(v0[2], v1[2]),
        };
        (v, join(v0[3], v1[3]))
    }

    /// Writes the lanes' velocities back: 4×4 transposes into one quad
    /// per lane, `[v.x, v.y, ω, flags]`, with the flags it read.
    #[inline(always)]
    pub(super) fn store<S: LaneStates>(states: &mut S, side: usize, v: &Velocity<W>, flags: W) {
        store_where(states, side, v, flags, u32::MAX);
    }

    /// Writes the velocities of the lanes whose bit is set in `lanes`
    /// back (bit `k`: lane `k`), by the same transposes.
    #[inline(always)]
    pub(crate) fn store_where<S: LaneStates>(
        states: &mut S,
        side: usize,
        v: &Velocity<W>,
        flags: W,
        lanes: u32,
    ) {
        let split = |x: W| -> [f32x4; 2] { bytemuck::cast(x) };
        let (v_x, v_y, w, f) = (split(v.v_x), split(v.v_y), split(v.w), split(flags));
        for half in 0..2 {
            let q = f32x4::transpose([v_x[half], v_y[half], w[half], f[half]]);
            for (i, &q) in q.iter().enumerate() {
                if lanes & (1 << (4 * half + i)) != 0 {
                    states.store_head(side, 4 * half + i, q);
                }
            }
        }
    }
}
#[cfg(not(feature = "f64"))]
pub(crate) use quads::{load, store_where};
#[cfg(not(feature = "f64"))]
use quads::{load_velocity, store};
/// The lanes' velocities from the state slice (prepare).
#[inline(always)]
fn gather_velocity(states: &[BodyState], index: &[u32; LANES]) -> Velocity<W> {
    let mut v_x = [0.0; LANES];
    let mut v_y = [0.0; LANES];
    let mut w = [0.0; LANES];
    for k in 0..LANES {
        let s = &states[index[k] as usize];
        v_x[k] = s.v.x;
        v_y[k] = s.v.y;
        w[k] = s.w;
    }
    Velocity {
        v_x: W::from(v_x),
        v_y: W::from(v_y),
        w: W::from(w),
    }
}

impl WideContact {
    /// The zero chunk: every lane a padding lane.
    fn empty() -> Self {
        WideContact {
            state_a: [0; LANES],
            state_b: [0; LANES],
            contact: [u32::MAX; LANES],
            len: 0,
            second: W::splat(0.0),
            moving: 0,
            rows: ContactRows::empty(),
        }
    }

    /// A kept chunk made ready for this step's lanes: no lane in use, every
    /// lane's header as in [`WideContact::empty`], no surface rows. The
    /// rows' lanes are overwritten by [`WideContact::push`], or cleared by
    /// [`WideContact::clear_free_lanes`].
    fn reopen(&mut self) {
        self.state_a = [0; LANES];
        self.state_b = [0; LANES];
        self.contact = [u32::MAX; LANES];
        self.len = 0;
        self.second = W::splat(0.0);
        self.moving = 0;
        self.rows.surface = None;
    }

    /// Calls `f(lane, point)` for each point of each lane in use (a lane's
    /// second point where its manifold has one).
    #[inline]
    fn for_each_point(&self, mut f: impl FnMut(usize, usize)) {
        let second = self.second.to_array();
        for (k, &two) in second.iter().enumerate().take(self.len) {
            f(k, 0);
            if two > 0.0 {
                f(k, 1);
            }
        }
    }

    /// The lanes from `len` on as a new chunk's: every row input zero
    /// (what the prepare computes the rest from).
    fn clear_free_lanes(&mut self) {
        for k in self.len..LANES {
            self.rows.clear_lane(k);
        }
    }

    /// Writes contact `contact_index` into the next free lane
    /// ([`ContactRows::set_lane`]).
    fn push(&mut self, lane: &ContactLane, count: usize, contact_index: u32) {
        let k = self.len;
        self.len += 1;
        self.state_a[k] = lane.state_a;
        self.state_b[k] = lane.state_b;
        let [m_a, i_a, m_b, i_b] = lane.inv_masses;
        if lane.state_a != 0 && (m_a > 0.0 || i_a > 0.0) {
            self.moving |= 1 << k;
        }
        if lane.state_b != 0 && (m_b > 0.0 || i_b > 0.0) {
            self.moving |= 1 << (LANES + k);
        }
        self.contact[k] = contact_index;
        self.second.set_lane(k, if count > 1 { 1.0 } else { 0.0 });
        self.rows.set_lane(
            k,
            lane.normal,
            &lane.points[..count],
            lane.friction,
            lane.restitution,
            lane.inv_masses,
        );
        self.rows
            .set_surface(k, lane.tangent_speed, lane.rolling_resistance);
    }

    /// [`ContactRows::prepare`] on the lanes, with the masses the impulses
    /// act with.
    fn prepare(&mut self, ctx: &StepContext, states: &[BodyState]) {
        let a = gather_velocity(states, &self.state_a);
        let b = gather_velocity(states, &self.state_b);
        let r = &self.rows;
        let k_masses = [r.inv_mass_a, r.inv_inertia_a, r.inv_mass_b, r.inv_inertia_b];
        let keep = [W::splat(1.0), self.second];
        self.rows.prepare(ctx, k_masses, keep, &a, &b);
    }

    /// [`ContactRows::restitution`] on the lanes (nothing where no lane
    /// has restitution).
    fn apply_restitution<S: LaneStates>(&mut self, states: &mut S, threshold: W) {
        if !self.rows.has_restitution() {
            return;
        }
        let (mut a, flags_a) = load_velocity(states, A);
        let (mut b, flags_b) = load_velocity(states, B);
        self.rows.restitution(&mut a, &mut b, threshold);
        store(states, A, &a, flags_a);
        store(states, B, &b, flags_b);
    }

    /// [`ContactRows::warm_start`] on the lanes, side a then side b.
    #[inline(always)]
    fn warm_start<S: LaneStates>(&mut self, states: &mut S) {
        let push = self.rows.warm_start();
        let (mut a, flags_a) = load_velocity(states, A);
        self.rows.push_a(&push, &mut a);
        store(states, A, &a, flags_a);
        let (mut b, flags_b) = load_velocity(states, B);
        self.rows.push_b(&push, &mut b);
        store(states, B, &b, flags_b);
    }

    /// One velocity iteration on every lane ([`ContactRows::solve`]).
    #[inline(always)]
    fn solve<S: LaneStates, const USE_BIAS: bool>(
        &mut self,
        states: &mut S,
        inv_h: Real,
        push_max: Real,
    ) {
        let (mut a, da, flags_a) = load(states, A);
        let (mut b, db, flags_b) = load(states, B);
        let (inv_h, push_max) = (W::splat(inv_h), W::splat(push_max));
        self.rows
            .solve::<USE_BIAS, false>(&mut a, &da, &mut b, &db, inv_h, push_max);
        store(states, A, &a, flags_a);
        store(states, B, &b, flags_b);
    }
}

/// The contact constraints of a step, in their colours, as one batch for
/// the solver.
pub struct ContactBatch<'a> {
    /// The constraints and their packed form.
    pub solver: &'a mut ContactSolver,
    /// The contact-modification hook's data: bodies whose contacts build
    /// their effective masses on a whole object's mass (portal copies; the
    /// pipeline puts their contacts in the overflow).
    pub object_masses: &'a [ObjectMass],
}

impl ConstraintBatch for ContactBatch<'_> {
    fn count(&self) -> usize {
        self.solver.len()
    }

    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        self.solver
            .prepare(ctx, bodies, self.object_masses, &Team::serial());
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        self.solver.warm_start(states, &Team::serial());
    }

    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        self.solver
            .solve(ctx, states, use_bias, reverse, &Team::serial());
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.solver.apply_restitution(ctx, states, &Team::serial());
    }

    fn store_impulses(&mut self) {}

    fn prepare_on(&mut self, ctx: &StepContext, bodies: &BodySet, team: &Team) {
        self.solver.prepare(ctx, bodies, self.object_masses, team);
    }

    fn warm_start_on(&mut self, _ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        self.solver.warm_start(states, team);
    }

    fn solve_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        self.solver.solve(ctx, states, use_bias, reverse, team);
    }

    fn apply_restitution_on(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        self.solver.apply_restitution(ctx, states, team);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ContactPointInput;
    use janus2d_core::body::BodyDef;
    use janus2d_core::math::{Vec2, to_f64};
    use janus2d_core::solver::SolverSettings;

    /// Contact `i` between bodies `2i` and `2i + 1` of `set`, with
    /// `points` points carrying `impulse` and, when `surface`, a tangent
    /// speed and rolling resistance.
    fn lane(set: &BodySet, i: usize, points: usize, impulse: Real, surface: bool) -> ContactLane {
        let handle = |k: usize| set.handles().nth(k).unwrap();
        let (a, b) = (handle(2 * i), handle(2 * i + 1));
        let point = |y: Real| ContactPointInput {
            anchor_a: Vec2::new(0.5, y),
            anchor_b: Vec2::new(-0.5, y),
            separation: -0.01 * (1 + i % 3) as Real,
            normal_impulse: impulse,
            tangent_impulse: 0.1 * impulse,
        };
        ContactLane {
            body_a: a,
            body_b: b,
            state_a: set.state_index(a).unwrap(),
            state_b: set.state_index(b).unwrap(),
            inv_masses: [1.0, 2.0, 0.5, 1.5],
            normal: Vec2::new(1.0, 0.1 * i as Real).normalize(),
            points: [point(0.25), point(-0.25)],
            point_count: points,
            friction: 0.3 + 0.05 * i as Real,
            restitution: 0.0,
            tangent_speed: if surface { 0.7 } else { 0.0 },
            rolling_resistance: if surface { 0.02 } else { 0.0 },
            contact_index: i as u32,
            cluster: [crate::contact_group::NO_CLUSTER; 2],
        }
    }

    /// Pushes `lanes` into colour 0 of `solver` (after `begin`), runs a
    /// substep's stages and returns the bits of every velocity and kept
    /// impulse.
    fn step(solver: &mut ContactSolver, set: &BodySet, lanes: &[ContactLane]) -> Vec<u64> {
        solver.begin();
        for l in lanes {
            solver.push(0, l);
        }
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::new(0.0, -10.0));
        let team = Team::serial();
        solver.prepare(&ctx, set, &[], &team);
        let mut states = set.states.clone();
        solver.warm_start(&mut states, &team);
        solver.solve(&ctx, &mut states, true, false, &team);
        solver.solve(&ctx, &mut states, false, true, &team);
        let mut bits: Vec<u64> = states
            .iter()
            .flat_map(|s| [s.v.x, s.v.y, s.w])
            .map(|x| to_f64(x).to_bits())
            .collect();
        solver.for_each_impulse(|c, point, p| {
            bits.push(u64::from(c) << 8 | point as u64);
            for x in [p.normal, p.tangent, p.total_normal, p.total_tangent] {
                bits.push(to_f64(x).to_bits());
            }
        });
        bits
    }

    /// A chunk kept from an earlier step (two-point lanes with surface
    /// rows, in more chunks than now) and reused for one-point lanes
    /// solves exactly as a new chunk: its second points, free lanes and
    /// surface rows hold nothing of the earlier lanes.
    #[test]
    fn a_reused_chunk_solves_as_a_new_one() {
        let mut set = BodySet::new();
        for k in 0..8 * LANES {
            let def =
                BodyDef::dynamic(Vec2::new(k as Real, 0.0)).with_angular_velocity(0.1 * k as Real);
            set.create(&def).unwrap();
        }
        let earlier: Vec<_> = (0..3 * LANES)
            .map(|i| lane(&set, i, 2, 5.0, true))
            .collect();
        let now: Vec<_> = (0..LANES + 3)
            .map(|i| lane(&set, i, 1, 0.02, false))
            .collect();
        let mut reused = ContactSolver::new();
        let first = step(&mut reused, &set, &earlier);
        let again = step(&mut reused, &set, &now);
        let fresh = step(&mut ContactSolver::new(), &set, &now);
        assert_eq!(again, fresh);
        // The earlier lanes did act (the test would notice stale rows).
        assert_ne!(first[..3 * 8 * LANES], fresh[..3 * 8 * LANES]);
    }

    /// Pushes `count` one-point contacts (contact `i` between bodies `2i`
    /// and `2i + 1`, in colour `i % 5`, every 97th in the overflow) with
    /// `push_all` on `team`; returns the places and, in the chunks' order,
    /// each lane's contact, point and kept normal impulse.
    fn push_all_on(
        set: &BodySet,
        count: usize,
        team: &Team,
    ) -> (Vec<LanePlace>, Vec<(u32, usize, u64)>) {
        let lanes: Vec<_> = (0..count)
            .map(|i| lane(set, i, 1, 0.5 + i as Real, false))
            .collect();
        let colours: Vec<u8> = (0..count)
            .map(|i| if i % 97 == 0 { OVERFLOW } else { (i % 5) as u8 })
            .collect();
        let mut solver = ContactSolver::new();
        solver.begin();
        let mut places = Vec::new();
        solver.push_all(
            &colours,
            |i| (lanes[i], i as u32, lanes[i].cluster),
            &mut places,
            team,
        );
        assert_eq!(solver.len(), count);
        let mut order = Vec::new();
        solver.for_each_impulse(|c, point, p| order.push((c, point, to_f64(p.normal).to_bits())));
        (places, order)
    }

    /// `push_all` on a team fills the push blocks at once into the chunks
    /// that pushing the contacts one by one makes: the same places and
    /// the same lanes in every chunk, for 2 and 4 threads.
    #[test]
    fn pushing_on_a_team_makes_the_chunks_of_pushing_in_order() {
        let count = 2 * PUSH_BLOCK + 777;
        let mut set = BodySet::new();
        for k in 0..2 * count {
            set.create(&BodyDef::dynamic(Vec2::new(k as Real, 0.0)))
                .unwrap();
        }
        let (places, order) = push_all_on(&set, count, &Team::serial());
        // A block's last chunks stay partly filled: more chunks than the
        // colours' contacts would fill alone.
        let chunk_count = |colour: u8| {
            places
                .iter()
                .filter(|p| p.colour == colour)
                .map(|p| p.chunk)
                .max()
                .map_or(0, |c| c + 1) as usize
        };
        let in_colour = |colour: u8| places.iter().filter(|p| p.colour == colour).count();
        assert!(chunk_count(0) > in_colour(0).div_ceil(LANES));
        assert_eq!(order.len(), count);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            let on_team = janus2d_core::parallel::with_threads(threads, |team| {
                push_all_on(&set, count, team)
            })
            .unwrap();
            assert_eq!(
                on_team,
                (places.clone(), order.clone()),
                "{threads} threads"
            );
        }
    }
}
