//! Contact constraint building: the solver side of the hand-off from the
//! narrowphase.
//!
//! ```text
//! narrowphase ──Handoff { touching, scanned }──▶ build (each lane read
//!                                                 from its contact)
//!   pass 1   the contacts the solve takes (pre-solve hook, still bodies,
//!            portal copies), their graph keys and light-pair flags;
//!            each keeps its colour in the persistent ConstraintGraph
//!            (on threads: those whose colour holds are kept on the team,
//!            ConstraintGraph::keep_shared; the rest in order after)
//!   clusters light bodies under heavy ones (contact_group)
//!   push     lanes into the ContactSolver's colour chunks, the rest to
//!            its overflow; places kept for storing the impulses back
//! ```
//!
//! Where the solver pushes in contact order
//! (`ContactSolver::pushes_in_order`) and there was no light pair
//! last step, pass 1 also pushes each contact as it goes, while its
//! record is in cache; the chunks are those the push would fill, in the same
//! order.
//!
//! The builder owns what lives from step to step on the solver side: the
//! graph (kept in snapshots: a step continues from its colours), the
//! solved list and the lanes' places.

use janus2d_constraints::ObjectMass;
use janus2d_constraints::contact_group::{Clusters, ContactBodies, NO_CLUSTER, light_pair};
use janus2d_constraints::contact_solver::{ContactSolver, LanePlace, OVERFLOW, PointImpulse};
use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::contact_input::{ContactLane, ContactPointInput};
use janus2d_core::graph::{ConstraintGraph, NO_BODY};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::Team;

use crate::collision::ContactHandoff;
use crate::contacts::{Contact, ContactSet};
use crate::narrowphase::{PreSolve, PreSolveFn, solve_body};

/// Touching contacts from which constraint building's first pass runs on
/// threads (below, the tasks cost more than the pass).
const PARALLEL_BUILD: usize = 4096;

/// How many contacts ahead the build's serial pass asks for the graph
/// entry it will keep.
const GRAPH_AHEAD: usize = 8;

/// Asks, at the `i`-th of the `touching` contacts, for what the build
/// reads a few contacts on: the graph entry `GRAPH_AHEAD` contacts on (a
/// random read by id), and the contact record (whole) whose id that will
/// read, further on. Used by the build's serial and parallel passes alike.
#[inline]
fn read_ahead(touching: &[u32], awake: &[Contact], graph: &ConstraintGraph, i: usize) {
    if let Some(&ahead) = touching.get(i + 2 * GRAPH_AHEAD) {
        janus2d_core::hint::prefetch_all(&awake[ahead as usize]);
    }
    if let Some(&ahead) = touching.get(i + GRAPH_AHEAD) {
        graph.prefetch(awake[ahead as usize].id);
    }
}

/// What constraint building reads of one awake contact ([`lane_of`]): its
/// lane (the solver's input, state indices and inverse masses included)
/// and whether each body read as still.
#[derive(Clone, Copy, Debug)]
struct ContactRead {
    /// The solver's lane data (`contact_index` is set at push).
    lane: ContactLane,
    /// The contact's id (its key in the constraint graph).
    id: u32,
    /// [`Contact::still`].
    still: [bool; 2],
}

/// A contact's lane and stillness as the solve takes them, read from the
/// contact where the narrowphase left it (an earlier design copied this
/// out in the narrowphase, 160 bytes a contact written and read back).
#[inline]
fn lane_of(c: &Contact) -> ContactRead {
    let mut points = [ContactPointInput::default(); 2];
    for (input, p) in points.iter_mut().zip(&c.points[..c.point_count]) {
        *input = ContactPointInput {
            anchor_a: p.anchor_a,
            anchor_b: p.anchor_b,
            separation: p.separation,
            normal_impulse: p.normal_impulse,
            tangent_impulse: p.tangent_impulse,
        };
    }
    let [(state_a, [m_a, i_a]), (state_b, [m_b, i_b])] = c.solve_bodies;
    ContactRead {
        lane: ContactLane {
            body_a: c.body_a,
            body_b: c.body_b,
            state_a,
            state_b,
            inv_masses: [m_a, i_a, m_b, i_b],
            normal: c.normal,
            points,
            point_count: c.point_count,
            friction: c.friction,
            restitution: c.restitution,
            tangent_speed: c.tangent_speed,
            rolling_resistance: c.rolling_resistance,
            contact_index: 0,
            cluster: [NO_CLUSTER; 2],
        },
        id: c.id,
        still: c.still,
    }
}

/// One block of the solved contacts for the threads' impulse store: the
/// awake contacts it may write (from `first` on) and its solved contacts
/// with their places.
struct StorePart<'a> {
    /// The awake contacts from `first` to the next block's first solved one.
    contacts: &'a mut [Contact],
    /// Awake index of `contacts[0]`.
    first: usize,
    /// The block's solved contacts, in contact order.
    solved: &'a [SolvedContact],
    /// Their places.
    places: &'a [LanePlace],
}

/// A contact the solve takes this step, as the build's first pass found it.
#[derive(Clone, Copy, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct SolvedContact {
    /// Index in the awake list.
    index: u32,
    /// The contact's id (its key in the constraint graph).
    id: u32,
    /// The graph's body keys: each moving body's slot ([`NO_BODY`] for a
    /// body the solve does not move).
    keys: [u32; 2],
    /// State index of each body (0: static or asleep).
    state: [u32; 2],
    /// Whether the solve moves each body.
    moving: [bool; 2],
    /// A portal copy takes part: the object-mass hook, in the overflow.
    copy: bool,
    /// Inverse mass of each body, 1/kg (0 for one the solve does not move).
    #[cfg_attr(feature = "serde", serde(skip))]
    inv_mass: [Real; 2],
    /// The light cluster of each side (`contact_group`): with one, in the
    /// overflow, solved with the cluster's other contacts as one block.
    #[cfg_attr(feature = "serde", serde(skip))]
    cluster: [u32; 2],
    /// Its manifold's point count (two solver rows each).
    point_count: u8,
    /// Its restitution is positive.
    bouncy: bool,
    /// Its colour when the build's parallel pass found it kept
    /// ([`ConstraintGraph::keep_shared`]), else [`NOT_KEPT`] (not in
    /// snapshots: each build makes it afresh).
    #[cfg_attr(feature = "serde", serde(skip, default = "not_kept"))]
    kept: u8,
}

/// [`SolvedContact::kept`] of a contact whose colour comes from
/// [`ConstraintGraph::keep`].
const NOT_KEPT: u8 = u8::MAX;

/// [`NOT_KEPT`], for a decoded snapshot's solved contacts.
#[cfg(feature = "serde")]
fn not_kept() -> u8 {
    NOT_KEPT
}

/// Constraint building's state: the persistent constraint graph and the
/// buffers it reuses from step to step.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct ContactBuilder {
    /// The lanes a pre-solve hook changed this step, by solved position
    /// (empty without a hook; scratch).
    #[cfg_attr(feature = "serde", serde(skip))]
    hooked: Vec<ContactLane>,
    /// The contacts solved this step, in contact order.
    solved: Vec<SolvedContact>,
    /// Their colours, in the same order (the solver's `push_all` input).
    colours: Vec<u8>,
    /// Where the solver put each solved contact, in `solved` order.
    #[cfg_attr(feature = "serde", serde(skip))]
    places: Vec<LanePlace>,
    /// The awake contacts' count when `solved` and `places` were made
    /// (the threads' store checks that the list is the same).
    #[cfg_attr(feature = "serde", serde(skip))]
    built_for: usize,
    /// The persistent colours of the solved contacts (kept in snapshots:
    /// the colours are part of the state a step continues from).
    graph: ConstraintGraph,
    /// The light clusters of the solved contacts (scratch of the build).
    #[cfg_attr(feature = "serde", serde(skip))]
    clusters: Clusters,
    /// Their clusters, per solved contact (scratch of the build).
    #[cfg_attr(feature = "serde", serde(skip))]
    cluster_of: Vec<[u32; 2]>,
    /// State indices of the bodies no cluster may hold (scratch of the
    /// build).
    #[cfg_attr(feature = "serde", serde(skip))]
    excluded: Vec<u32>,
    /// Last step had a light pair (its contacts went through the light
    /// clusters): this step's build then pushes after the clusters are
    /// known rather than during its first pass. Only where the work is
    /// done depends on it, not the result.
    #[cfg_attr(feature = "serde", serde(skip))]
    had_light: bool,
}

/// The colour of a solved contact: its colour in the persistent graph
/// (kept from last step while its moving bodies stay the same), or the
/// overflow for a portal copy's contact (it keeps its place in the graph).
#[inline]
fn colour_of(graph: &mut ConstraintGraph, s: &SolvedContact) -> u8 {
    let colour = if s.kept == NOT_KEPT {
        graph.keep(s.id, s.keys)
    } else {
        s.kept
    };
    kept_colour(s, colour)
}

/// The colour a solved contact is pushed with, given its graph colour
/// `colour` ([`OVERFLOW`] for a portal copy's contact).
#[inline]
fn kept_colour(s: &SolvedContact, colour: u8) -> u8 {
    if s.copy {
        OVERFLOW
    } else {
        colour.min(OVERFLOW)
    }
}

/// What the build counts of the solved contacts, in the serial pass or
/// per block of the parallel one.
#[derive(Clone, Copy, Default)]
struct Tally {
    /// Solver rows (two per point).
    rows: usize,
    /// Contacts with restitution.
    bouncy: usize,
    /// A light pair (`light_pair`, neither body excluded) is met: the
    /// light clusters are looked for.
    light: bool,
}

impl Tally {
    /// Counts `s`; true when it is the first light pair met (a light body
    /// against a heavy one, neither in `excluded`).
    #[inline]
    fn count(&mut self, s: &SolvedContact, excluded: &[u32]) -> bool {
        self.rows += 2 * usize::from(s.point_count);
        self.bouncy += usize::from(s.bouncy);
        let first_light = !self.light
            && light_pair(s.moving, s.inv_mass)
            && !excluded.contains(&s.state[0])
            && !excluded.contains(&s.state[1]);
        self.light |= first_light;
        first_light
    }

    /// Adds a block's counts.
    fn add(&mut self, other: Tally) {
        self.rows += other.rows;
        self.bouncy += other.bouncy;
        self.light |= other.light;
    }
}

/// What the build's parallel pass finds in one block of the solved
/// contacts (see `ContactBuilder::build`).
#[derive(Default)]
struct BuildPart {
    /// The block's colours (the overflow, for now, for a fresh contact).
    colours: Vec<u8>,
    /// The block's counts.
    tally: Tally,
    /// Contacts whose graph colour was kept.
    kept: usize,
    /// Positions in `solved` of the contacts that take a colour afresh.
    fresh: Vec<u32>,
    /// A still pair was met (the block was left unfinished).
    still: bool,
}

impl ContactBuilder {
    /// Checks the persistent constraint graph (every body's colour bits
    /// are its contacts' colours; no colour holds a body twice).
    pub(crate) fn check_graph(&self) -> Result<(), String> {
        self.graph
            .check()
            .map_err(|e| format!("constraint graph: {e}"))
    }
}

impl ContactBuilder {
    /// Builds the contact constraints of touching solid awake contacts, in
    /// their colours.
    ///
    /// Colours come from the persistent [`ConstraintGraph`]: a contact keeps
    /// its colour while it is solved and its moving bodies stay the same.
    /// Contacts with one moving body (against the ground) take colours from
    /// [`janus2d_core::graph::STATIC_FIRST`] up, after the pairs of moving
    /// bodies, so each Gauss–Seidel sweep ends near the ground: the support a
    /// stack stands on has the last word (Box2D v3 likewise keeps static
    /// contacts out of its first graph colours).
    ///
    /// Whether a body reads as static was noted by the narrowphase
    /// ([`Contact::still`]); a contact whose two bodies are still is skipped.
    /// When islands were woken after the narrowphase (`woke`), contacts that
    /// read still are checked again.
    pub(crate) fn build(
        &mut self,
        from: ContactHandoff<'_>,
        bodies: &BodySet,
        woke: bool,
        objects: &[ObjectMass],
        driven: impl Iterator<Item = u32>,
        mut pre_solve: Option<&mut PreSolveFn>,
        reserved: &[u32],
        solver: &mut ContactSolver,
        team: &Team,
    ) {
        let ContactHandoff {
            narrow: handoff,
            contacts,
            counters,
        } = from;
        let solved = &mut self.solved;
        // Lanes a pre-solve hook changed, by solved position (only with a
        // hook: the push reads the rest from the contacts).
        let hooked = &mut self.hooked;
        hooked.clear();
        // The contacts to look at: those the narrowphase found touching, then
        // any woken (appended) since.
        let n = contacts.awake().len();
        let scanned = handoff.scanned.min(n);
        let woken = scanned..n;
        // A light pair with a body a motor turns or a portal object's body
        // makes no cluster: every cluster it marks touches that body and is
        // blocked (`Clusters::assign`), so without another light pair the
        // clusters are all empty and are not looked for (spinner: its paddle).
        // A body a motor turns and a portal object's bodies take no part in a
        // light cluster (`Clusters::assign`).
        let excluded = &mut self.excluded;
        excluded.clear();
        // Read only when a contact could make a cluster (a joint-only
        // scene scans no joint here).
        if !handoff.touching.is_empty() || !woken.is_empty() {
            for slot in driven.chain(objects.iter().map(|o| o.body.index)) {
                if let Some(i) = bodies.state_index_at(slot).filter(|&i| i != 0) {
                    excluded.push(i);
                }
            }
        }
        let candidates = handoff.touching.iter().map(|&k| k as usize).chain(woken);
        if woke {
            // Woken bodies have new state indices, and woken contacts were not
            // read by this step's narrowphase: read their bodies again. A
            // wake appends states and contacts and moves none, so a contact
            // the narrowphase read between two awake bodies (both state
            // indices set) reads the same states still: only those with a
            // static, sleeping or woken side are read again (smash wakes
            // boxes on most steps; this pass read every contact).
            for k in candidates.clone() {
                let [(state_a, _), (state_b, _)] = contacts.awake()[k].solve_bodies;
                if k < scanned && state_a != 0 && state_b != 0 {
                    continue;
                }
                let c = contacts.awake_mut(k);
                if c.still == [true, true] {
                    c.still = [
                        bodies.state_index(c.body_a) == Some(0),
                        bodies.state_index(c.body_b) == Some(0),
                    ];
                }
                c.solve_bodies = [
                    solve_body(&bodies.solver_body(c.body_a)),
                    solve_body(&bodies.solver_body(c.body_b)),
                ];
            }
        }
        // The state index of a body (0: static or asleep) and whether the
        // solve moves it (dynamic and awake), as the narrowphase read them.
        let state_of = |(i, [m, inertia]): (u32, [Real; 2])| -> (u32, bool) {
            (i, i != 0 && (m > 0.0 || inertia > 0.0))
        };
        // A portal copy: its contacts take the object-mass hook, in the overflow.
        let is_copy = |body: BodyHandle| objects.iter().any(|o| o.body == body);
        // The joints' colours stay theirs: a contact takes none of them on
        // a body a joint moves in it (the solve runs a colour's joints and
        // contacts as one job).
        let graph = &mut self.graph;
        graph.set_reserved(reserved);
        graph.begin_step();
        let colours = &mut self.colours;
        colours.clear();
        let places = &mut self.places;
        places.clear();
        let mut tally = Tally::default();
        // Each solved contact once: its colour (pushed to `colours` and
        // returned), the counters, and whether it is the first contact
        // between a light body and a heavy one with neither body excluded
        // (then the light clusters are looked for below).
        let mut take = |s: &SolvedContact, graph: &mut ConstraintGraph| -> (u8, bool) {
            let colour = colour_of(graph, s);
            colours.push(colour);
            (colour, tally.count(s, excluded))
        };
        // Pass 1: the solved contacts, in contact order, each given its
        // colour from the persistent graph, keyed by the bodies' slots (a
        // contact keeps last step's colour while its moving bodies stay the
        // same; the contacts not solved this step leave it), and counted.
        solver.begin();
        let awake = contacts.awake();
        solved.clear();
        let key = |moving: bool, body: BodyHandle| if moving { body.index } else { NO_BODY };
        let entry = |k: usize, record: &ContactRead| {
            let lane = &record.lane;
            let [m_a, i_a, m_b, i_b] = lane.inv_masses;
            let (ia, moving_a) = state_of((lane.state_a, [m_a, i_a]));
            let (ib, moving_b) = state_of((lane.state_b, [m_b, i_b]));
            let copy = !objects.is_empty() && (is_copy(lane.body_a) || is_copy(lane.body_b));
            SolvedContact {
                index: k as u32,
                id: record.id,
                keys: [key(moving_a, lane.body_a), key(moving_b, lane.body_b)],
                state: [ia, ib],
                moving: [moving_a, moving_b],
                copy,
                inv_mass: [m_a, m_b],
                cluster: [NO_CLUSTER; 2],
                point_count: lane.point_count as u8,
                bouncy: lane.restitution > 0.0,
                kept: NOT_KEPT,
            }
        };
        // With threads, no hook and nothing woken since the narrowphase, the
        // entries are made on the team (order kept): on two threads this pass was
        // most of what the leader did alone between the narrowphase and the
        // solve.
        let parallel = pre_solve.is_none()
            && !woke
            && scanned == n
            && team.threads() > 1
            && handoff.touching.len() >= PARALLEL_BUILD;
        let mut pushed = false;
        if parallel {
            // Written in place: each block of `solved` from its own
            // contacts. A contact whose bodies are both still is marked and
            // dropped after (phase 1 leaves none in `touching`, so the drop
            // is a check).
            const STILL: u32 = u32::MAX;
            const BLOCK: usize = 1024;
            let touching = handoff.touching;
            // Made where they stay (no serial fill of `solved` first),
            // each keeping its colour here when it can: only the contacts
            // that take a colour afresh go through the graph in order.
            let shared = &*graph;
            team.extend_mapped(solved, touching.len(), BLOCK, |i| {
                read_ahead(touching, awake, shared, i);
                let k = touching[i] as usize;
                let record = &lane_of(&awake[k]);
                let mut s = entry(k, record);
                if record.still == [true, true] {
                    s.index = STILL;
                } else if let Some(colour) = shared.keep_shared(s.id, s.keys) {
                    s.kept = colour;
                }
                s
            });
            // Per block of `solved`, on the team: the colours of the
            // contacts that kept theirs, the counters, whether a light pair
            // is met, and which contacts take a colour afresh; only those go
            // through the graph, in contact order, on the leader. (A serial
            // pass over every contact here was about 4% of the leader's
            // samples in large_pyramid at two threads.)
            let (part_of, light_of) = (&*solved, &*excluded);
            let parts = team.map_blocks(solved.len().div_ceil(BLOCK), |b| {
                let first = b * BLOCK;
                let part = &part_of[first..(first + BLOCK).min(part_of.len())];
                let mut out = BuildPart::default();
                out.colours.reserve(part.len());
                for (j, s) in part.iter().enumerate() {
                    if s.index == STILL {
                        out.still = true;
                        break;
                    }
                    out.tally.count(s, light_of);
                    if s.kept == NOT_KEPT {
                        out.fresh.push((first + j) as u32);
                        out.colours.push(OVERFLOW);
                    } else {
                        out.kept += 1;
                        out.colours.push(kept_colour(s, s.kept));
                    }
                }
                out
            });
            if parts.iter().any(|p| p.still) {
                // (Phase 1 leaves no still pair in `touching`: a check.)
                solved.retain(|s| s.index != STILL);
                let mut kept = 0;
                for s in solved.iter() {
                    kept += usize::from(s.kept != NOT_KEPT);
                    take(s, graph);
                }
                graph.note_kept(kept);
            } else {
                let mut kept = 0;
                for p in &parts {
                    colours.extend_from_slice(&p.colours);
                    tally.add(p.tally);
                    kept += p.kept;
                }
                for &i in parts.iter().flat_map(|p| &p.fresh) {
                    colours[i as usize] = colour_of(graph, &solved[i as usize]);
                }
                graph.note_kept(kept);
            }
        } else {
            // Serial: each contact is also pushed into its colour's chunk
            // here, while its record is in cache (read once, not
            // again by `push_all` below), unless a light pair could put it
            // in a cluster (then all go through `push_all` after the
            // clusters are known). Last step's clusters predict this
            // step's; a light pair met while pushing starts the push over.
            // The chunks are those `push_all` fills on one thread, in the
            // same order.
            let mut fused = !self.had_light
                && ContactSolver::pushes_in_order(handoff.touching.len() + (n - scanned), team);
            let touching = handoff.touching;
            for (i, k) in candidates.enumerate() {
                read_ahead(touching, awake, graph, i);
                let mut record = lane_of(&awake[k]);
                let [sa, sb] = record.still;
                if (sa && sb) || (k >= scanned && !awake[k].is_solid_touching()) {
                    continue;
                }
                if let Some(hook) = pre_solve.as_mut() {
                    let c = &awake[k];
                    let velocity = |b| bodies.state(b).map_or(Vec2::ZERO, |s| s.v);
                    let mut separations = [0.0; 2];
                    let mut points = [Vec2::ZERO; 2];
                    for ((s, x), p) in separations
                        .iter_mut()
                        .zip(points.iter_mut())
                        .zip(&c.points[..c.point_count])
                    {
                        *s = p.separation;
                        *x = p.point;
                    }
                    let lane = &record.lane;
                    let mut view = PreSolve {
                        shape_a: c.shapes[0],
                        shape_b: c.shapes[1],
                        body_a: c.body_a,
                        body_b: c.body_b,
                        user_material_ids: c.user_material_ids,
                        normal: c.normal,
                        points,
                        separations,
                        point_count: c.point_count,
                        velocity_a: velocity(c.body_a),
                        velocity_b: velocity(c.body_b),
                        friction: lane.friction,
                        restitution: lane.restitution,
                        tangent_speed: lane.tangent_speed,
                        rolling_resistance: lane.rolling_resistance,
                    };
                    if !hook(&mut view) {
                        continue;
                    }
                    view.apply_to(&mut record.lane);
                    hooked.push(record.lane);
                }
                let s = entry(k, &record);
                let (colour, first_light) = take(&s, graph);
                if first_light && fused {
                    fused = false;
                    solver.begin();
                    places.clear();
                }
                if fused {
                    places.push(solver.push_with(colour, &record.lane, s.index, s.cluster));
                }
                solved.push(s);
            }
            pushed = fused;
        }
        graph.sweep();
        self.had_light = tally.light;
        // Light clusters (`contact_group`): their contacts go to the overflow
        // this step (keeping their place in the graph), where the solver takes
        // each cluster's contacts as one block.
        let cluster_of = &mut self.cluster_of;
        cluster_of.clear();
        if tally.light {
            self.clusters.assign(
                bodies.states.len(),
                solved.len(),
                |k| {
                    let s = &solved[k];
                    ContactBodies {
                        state: s.state,
                        moving: s.moving,
                        inv_mass: s.inv_mass,
                    }
                },
                excluded,
                cluster_of,
            );
            for ((s, ids), colour) in solved
                .iter_mut()
                .zip(cluster_of.iter())
                .zip(colours.iter_mut())
            {
                s.cluster = *ids;
                if *ids != [NO_CLUSTER; 2] {
                    *colour = OVERFLOW;
                }
            }
        }
        // Pass 2 (unless pass 1 pushed them): each contact into its colour,
        // in contact order.
        let (solved, hooked) = (&*solved, &*hooked);
        if !pushed {
            solver.push_all(
                colours,
                |i| {
                    let s = &solved[i];
                    // (With a hook every solved contact's lane is listed.)
                    let lane = hooked
                        .get(i)
                        .copied()
                        .unwrap_or_else(|| lane_of(&awake[s.index as usize]).lane);
                    (lane, s.index, s.cluster)
                },
                places,
                team,
            );
        }
        self.built_for = n;
        counters.contact_rows = tally.rows;
        counters.restitution_contacts = tally.bouncy;
    }

    /// Copies solved impulses back into the contacts (for warm starting).
    /// Touches only the contacts: `beside` (the proxy moves and the tree
    /// rebuild, `Collision::end_step`) runs on the leader while the team
    /// stores, or first on one thread.
    pub(crate) fn store_impulses(
        &self,
        contacts: &mut ContactSet,
        solver: &ContactSolver,
        team: &Team,
        beside: &mut dyn FnMut(),
    ) {
        // A non-finite impulse (a solve that blew up) is not kept for warm
        // starting: the contact starts cold next step instead of carrying
        // NaN into it.
        let finite = |x: Real| if x.is_finite() { x } else { 0.0 };
        let keep = |p: &mut crate::contacts::ContactPointData, impulse: PointImpulse| {
            p.normal_impulse = finite(impulse.normal);
            p.tangent_impulse = finite(impulse.tangent);
            p.total_normal_impulse = finite(impulse.total_normal);
            p.total_tangent_impulse = finite(impulse.total_tangent);
        };
        let (solved, places) = (&self.solved[..], &self.places[..]);
        let n = contacts.awake().len();
        if team.threads() > 1 && n > 4096 && self.built_for == n && places.len() == solved.len() {
            // On the team, in contact order: each solved contact written
            // once, in place, reading its lanes from the chunks. `solved`
            // is in contact order, so each block of it writes only the
            // contacts from its first one's to the next block's first one's
            // (the serial pass that spread the places over every awake
            // contact first was 1.3% of the leader's samples in
            // large_pyramid at two threads). (On one thread the scatter
            // below measured faster: 6.8% of many_pyramids' samples against
            // 10.2% for this gather.)
            const BLOCK: usize = 1024;
            let mut parts = Vec::with_capacity(solved.len().div_ceil(BLOCK));
            let mut rest = contacts.awake_slice_mut();
            let mut first = 0;
            for (b, block) in solved.chunks(BLOCK).enumerate() {
                let end = solved
                    .get((b + 1) * BLOCK)
                    .map_or(first + rest.len(), |s| s.index as usize);
                // (Clamped: out of contact order, a block writes nothing
                // rather than panic; the debug check below names it.)
                let len = end.saturating_sub(first).min(rest.len());
                let (mine, tail) = std::mem::take(&mut rest).split_at_mut(len);
                parts.push(StorePart {
                    contacts: mine,
                    first,
                    solved: block,
                    places: &places[b * BLOCK..b * BLOCK + block.len()],
                });
                rest = tail;
                first += len;
            }
            team.for_each_chunk_mut_beside(
                &mut parts,
                1,
                |_, parts| {
                    for part in parts {
                        for (s, place) in part.solved.iter().zip(part.places) {
                            let c = (s.index as usize)
                                .checked_sub(part.first)
                                .and_then(|i| part.contacts.get_mut(i));
                            debug_assert!(c.is_some(), "solved contacts out of contact order");
                            if let Some(c) = c {
                                for k in 0..c.point_count {
                                    keep(&mut c.points[k], solver.point_impulse_at(*place, k));
                                }
                            }
                        }
                    }
                },
                beside,
            );
            return;
        }
        beside();
        solver.for_each_impulse_into(
            contacts,
            |contacts, index| {
                if let Some(c) = contacts.awake().get(index as usize) {
                    janus2d_core::hint::prefetch_all(&c.points);
                }
            },
            |contacts, index, point, impulse| {
                keep(
                    &mut contacts.awake_mut(index as usize).points[point],
                    impulse,
                );
            },
        );
    }
}
