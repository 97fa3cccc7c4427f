//! Colours of the joints: their Gauss–Seidel rows on the team.
//!
//! The Gauss–Seidel rows of the joints (the equality rows of joints
//! outside a tree, and every joint's angle rows: springs, motors, limits)
//! are solved colour by colour. Two joints of one colour never share a
//! body that the solve moves (dynamic and awake); static, kinematic and
//! sleeping bodies take no colour (the solve reads their state and never
//! writes it). So the joints of a colour can run in any order, on any
//! thread, with the same result: one sweep of the colours in order.
//!
//! ```text
//!   joint  bodies (state)   moving   colour      solve (forward)         solve (reverse)
//!   j0     1 ─ 2            1, 2     0           colour 0: j0 j2 j5      overflow
//!   j1     2 ─ 3            2, 3     1           colour 1: j1 j4         colour 2: j3
//!   j2     3 ─ ground       3        0           colour 2: j3            colour 1: j1 j4
//!   j3     1 ─ 3            1, 3     2           overflow: (none)        colour 0: j0 j2 j5
//!   j4     4 ─ 1            4, 1     1
//!   j5     4 ─ kinematic    4        0           warm start, per moving body, joints in storage order:
//!                                                  body 1: j0 j3 j4   body 2: j0 j1
//!                                                  body 3: j1 j2 j3   body 4: j4 j5
//! ```
//!
//! | stage                  | unit of work                        | on the team                         |
//! |------------------------|-------------------------------------|-------------------------------------|
//! | prepare                | a joint (reads the bodies)          | blocks of joints                    |
//! | colouring              | all joints, when a key changed      | leader                              |
//! | warm start             | a moving body: its joints' impulses | blocks of bodies                    |
//! | solve, relax           | a colour's joints                   | blocks of a colour, colour by colour |
//! | overflow               | a joint                             | leader, after (reverse: before) the colours |
//! | restitution            | none (no joint kind has any)        | leader                              |
//!
//! - **Colouring** is greedy over the joints in storage order (the lowest
//!   colour in which neither moving body appears, [`ColourGraph`]), so it
//!   depends on the joints and the bodies only, never on the thread count;
//!   each colour keeps its joints in storage order. A joint whose moving
//!   bodies already use all [`COLOURS`] colours (a hub with more than 24
//!   joints) goes to the **overflow**, solved one by one on the leader
//!   after the colours; a reverse sweep (the solver alternates them) is the
//!   forward sequence backwards, so it starts with the overflow.
//! - **Recolouring** happens only when a joint's key changes: its state
//!   indices, which ends move, whether it is solved at all (enabled, not
//!   resting), or the state count. Creating, destroying, enabling or
//!   disabling a joint, waking or putting a body to sleep, changing a
//!   body's type all change a key; a step that changes none compares the
//!   keys (one pass) and keeps the colours, their solve order, their
//!   verified [`StatePlan`] and the warm start's body lists.
//! - **On the team** each colour's joints are split into blocks; a block
//!   reads and writes the body states through the plan (slot 0: body a,
//!   slot 1: body b, written only where the body moves). On one thread, or
//!   for a colour of one block, the joints run in order on the leader and
//!   write the same velocities: the state is bit-identical for any thread
//!   count.
//! - **The warm start needs no colours.** It only adds the kept impulses,
//!   and a body's velocity depends only on the order in which its own
//!   joints add theirs; so each moving body adds its joints' shares in
//!   storage order, body by body. That is bit for bit the warm start of
//!   the joints one after the other in storage order (before the colours
//!   the solver did exactly that), for any thread count. A colour-order
//!   warm start would change only the rounding, but the stretched chain
//!   (`janus2d_testbed::hard::stretched_chain`) is chaotic enough that its
//!   whip then peaked at 77 m/s instead of 64.5 (bound 70.35).
//!
//! The tree joints' point rows stay with the exact tree solve
//! ([`crate::joint_tree`], the solver's late pass); a tree joint without
//! angle rows (a plain hinge of a chain, a rope, a bridge) takes no colour:
//! its only Gauss–Seidel part is the warm start.

use janus2d_core::body::{BodySet, BodyState};
use janus2d_core::constraint::StepContext;
use janus2d_core::graph::{COLOURS, ColourGraph};
use janus2d_core::parallel::{CrossPlan, StatePlan, Team};
use smallvec::SmallVec;

use crate::contact_solver::ContactSolver;
use crate::joint::Joint;
use crate::joint_base::is_moving;
use crate::parts::{PairOf, WRITE_A, WRITE_B};
use crate::revolute_lanes::{NO_LANE, RevoluteLanes};

/// How many joints ahead a colour's solve asks for the joint record.
const JOINTS_AHEAD: usize = 2;

/// No position: a joint that is not solved (disabled or resting).
const NONE: u32 = u32::MAX;

/// Key flag: the joint is solved this step (enabled, not resting): its
/// warm start runs. Bits [`WRITE_A`] and [`WRITE_B`] say which ends move.
const ACTIVE: u32 = 4;

/// Key flag: the joint has Gauss–Seidel rows this step (it is solved and
/// not a tree joint without angle rows): it takes a colour.
const COLOURED: u32 = 8;

/// Key flag: the joint may run in lanes ([`Joint::lane_candidate`]), so
/// that building the lanes reads no other joint.
const LANE: u32 = 16;

/// Fewest joints of a colour per block of a stage on the team: a block
/// costs an atomic claim, and a joint's solve about 20 ns.
const JOINTS_PER_BLOCK: usize = 64;

/// Body states per block of the warm start on the team.
const WARM_START_BLOCK: usize = 256;

/// The colouring of the joints and the order they are solved in.
/// See the module docs.
#[derive(Clone, Debug, Default)]
pub struct JointColours {
    /// Per joint: `[state a, state b, flags]` of this step (zeros for a
    /// joint that is not solved).
    keys: Vec<Key>,
    /// The keys and the state count of the last colouring.
    built_keys: Vec<Key>,
    built_states: usize,
    graph: ColourGraph,
    /// The solved joints (storage indices), colour by colour, each colour
    /// in storage order, then the overflow.
    order: Vec<u32>,
    /// Per entry of `order`: the ends its joint writes ([`WRITE_A`],
    /// [`WRITE_B`]).
    writes: Vec<u8>,
    /// Where each colour starts in `order`; entry `colours` is the start
    /// of the overflow, the last entry `order.len()`.
    starts: Vec<u32>,
    /// Per joint: its place in `order`, or [`NONE`].
    position: Vec<u32>,
    /// The states each colour's joints read and write, one group per
    /// colour, verified against `built_states`.
    plan: StatePlan<2>,
    /// The joints of a stage on the team, in solve order (an allocation
    /// kept from stage to stage).
    scratch: JointRefs,
    /// Per state: where its joints start in `body_joints`; the last entry
    /// is the total (the warm start's body lists).
    body_start: Vec<u32>,
    /// Per moving state, its solved joints in storage order, each as
    /// `joint << 1 | side` (side 1: the joint's body b).
    body_joints: Vec<u32>,
    /// The states that have a joint in `body_joints`, ascending.
    jointed: Vec<u32>,
    /// Per joint: its colour in the last colouring ([`COLOURS`]: the
    /// overflow; [`NO_COLOUR`]: none, not solved or no Gauss–Seidel rows).
    colour_of: Vec<u8>,
    /// Counts the colourings (a cache of what they give can tell it is
    /// stale).
    generation: u64,
    /// The colours' plan checked against the contacts' plan: a colour's
    /// joints and contacts then run as one job on the team.
    cross: CrossPlan,
    /// The revolute joints with angle rows, [`LANES`](crate::lane::LANES)
    /// at a time per colour ([`crate::revolute_lanes`]), from the batch's
    /// prepare to its store.
    lanes: RevoluteLanes,
    /// The colouring (`generation`) the lanes were built on: lanes of
    /// another are not used.
    lanes_generation: u64,
    /// Every joint one at a time (tests compare the lanes with it).
    pub(crate) lanes_off: bool,
    /// Coloured joints (overflow aside) that may run in lanes, at the last
    /// colouring.
    lane_candidates: usize,
    /// Per colour, whether a joint of it is solved one at a time beside the
    /// lanes, while the lanes are live (set by
    /// [`JointColours::build_lanes`]). A colour with none hands the team no
    /// joint part, and a stage with none takes no joint references
    /// (rain: the ragdolls' hinges, every coloured joint in lanes).
    scalar_in: Vec<bool>,
}

/// [`JointColours::colour_of`] of a joint that takes no colour.
const NO_COLOUR: u8 = u8::MAX;

impl JointColours {
    /// No joint coloured yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of colours in use.
    #[must_use]
    pub fn colour_count(&self) -> usize {
        self.starts.len().saturating_sub(2)
    }

    /// The storage indices of the joints of colour `colour`, in solve
    /// order; `colour == colour_count()` gives the overflow.
    #[must_use]
    pub fn joints_in(&self, colour: usize) -> &[u32] {
        match (self.starts.get(colour), self.starts.get(colour + 1)) {
            (Some(&a), Some(&b)) => &self.order[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Number of joints in the overflow (solved one by one on the leader).
    #[must_use]
    pub fn overflow_len(&self) -> usize {
        self.joints_in(self.colour_count()).len()
    }

    /// Reads every joint's key (call after the joints' `prepare`) and
    /// colours the joints again if a key or the state count changed since
    /// the last colouring.
    pub fn update(&mut self, joints: &[Joint], states: &[BodyState]) {
        self.update_on(joints, states, &Team::serial());
    }

    /// [`JointColours::update`] with the keys read in blocks on the step's
    /// team (a colouring, when needed, runs on the caller).
    pub fn update_on(&mut self, joints: &[Joint], states: &[BodyState], team: &Team) {
        const BLOCK: usize = 1024;
        self.keys.resize(joints.len(), [0; 3]);
        team.for_each_chunk_mut(&mut self.keys, BLOCK, |i, block| {
            for (k, j) in block.iter_mut().zip(&joints[i * BLOCK..]) {
                *k = key(j, states);
            }
        });
        self.recolour_if_changed(joints.len(), states.len());
    }

    /// [`JointColours::update`] before the joints' prepare: the state
    /// indices read from `bodies` (where the prepare will load them), not
    /// from the joints (where the last prepare left them). The contacts'
    /// graph reads the result ([`JointColours::reserve`]); the prepare then
    /// finds the same keys and keeps the colours. `body_slots[k]`: the
    /// slots of joint `k`'s bodies a and b (the joint store keeps them, so
    /// that this pass over every joint reads no definition).
    pub fn update_from(&mut self, joints: &[Joint], body_slots: &[[u32; 2]], bodies: &BodySet) {
        self.keys.clear();
        self.keys
            .extend(joints.iter().zip(body_slots).map(|(j, &[a, b])| {
                let index = |slot| bodies.state_index_at(slot).unwrap_or(0);
                key_at(j, index(a), index(b), &bodies.states)
            }));
        self.recolour_if_changed(joints.len(), bodies.states.len());
    }

    /// The buffer of this step's keys, one per joint, for a caller that
    /// fills it with [`key`] in its own pass over the joints (the batch's
    /// prepare does, while each joint is in cache) before
    /// [`JointColours::recolour_if_changed`].
    pub(crate) fn keys_for(&mut self, joint_count: usize) -> &mut [Key] {
        self.keys.resize(joint_count, [0; 3]);
        &mut self.keys
    }

    /// Colours the joints again when this step's keys (in `keys`) or the
    /// state count differ from the last colouring's.
    pub(crate) fn recolour_if_changed(&mut self, joint_count: usize, state_count: usize) {
        if self.keys == self.built_keys
            && state_count == self.built_states
            && self.position.len() == joint_count
        {
            return;
        }
        std::mem::swap(&mut self.keys, &mut self.built_keys);
        self.built_states = state_count;
        self.recolour();
    }

    /// Greedy colouring of the joints in storage order, then the solve
    /// order (a counting sort by colour, stable) and the plan.
    fn recolour(&mut self) {
        self.generation += 1;
        let keys = &self.built_keys;
        self.graph.reset(self.built_states);
        // The colour of each joint (COLOURS: overflow), reusing `position`.
        let mut counts = [0u32; COLOURS + 1];
        let mut lane_candidates = 0;
        self.position.clear();
        self.colour_of.clear();
        for k in keys {
            let flags = k[2];
            if flags & COLOURED == 0 {
                self.position.push(NONE);
                self.colour_of.push(NO_COLOUR);
                continue;
            }
            let a = (flags & u32::from(WRITE_A) != 0).then_some(k[0]);
            let b = (flags & u32::from(WRITE_B) != 0).then_some(k[1]);
            let colour = self.graph.assign(a, b).unwrap_or(COLOURS);
            counts[colour] += 1;
            if colour < COLOURS && flags & LANE != 0 {
                lane_candidates += 1;
            }
            self.position.push(colour as u32);
            self.colour_of.push(colour as u8);
        }
        self.lane_candidates = lane_candidates;
        // Greedy colours are contiguous (colour c is taken only where c − 1
        // is blocked), so this is the number of non-empty colours.
        let used = counts[..COLOURS]
            .iter()
            .rposition(|&n| n > 0)
            .map_or(0, |c| c + 1);
        self.starts.clear();
        let mut start = 0;
        for c in (0..used).chain([COLOURS]) {
            self.starts.push(start);
            start += counts[c];
        }
        self.starts.push(start);
        let mut fill: SmallVec<[u32; COLOURS + 1]> = self.starts[..=used].into();
        self.order.clear();
        self.order.resize(start as usize, 0);
        self.writes.clear();
        self.writes.resize(start as usize, 0);
        for (i, (place, k)) in self.position.iter_mut().zip(keys).enumerate() {
            if *place == NONE {
                continue;
            }
            let slot = if *place as usize == COLOURS {
                used
            } else {
                *place as usize
            };
            let p = fill[slot];
            fill[slot] += 1;
            self.order[p as usize] = i as u32;
            self.writes[p as usize] = (k[2] & u32::from(WRITE_A | WRITE_B)) as u8;
            *place = p;
        }
        self.plan.clear();
        for c in 0..used {
            self.plan.begin_group();
            for p in self.starts[c]..self.starts[c + 1] {
                let k = keys[self.order[p as usize] as usize];
                self.plan
                    .push([k[0], k[1]], u32::from(self.writes[p as usize]));
            }
        }
        // A plan that does not hold (it always should: the colouring keeps
        // moving bodies apart) leaves the stages on the leader.
        let verified = self.plan.verify(self.built_states);
        debug_assert!(verified, "a joint colour holds a moving body twice");
        // The warm start's lists: every moving end's joints, storage order.
        self.body_start.clear();
        self.body_start.resize(self.built_states + 1, 0);
        for k in keys {
            for (side, bit) in [WRITE_A, WRITE_B].into_iter().enumerate() {
                if k[2] & u32::from(bit) != 0 {
                    self.body_start[k[side] as usize + 1] += 1;
                }
            }
        }
        self.jointed.clear();
        for s in 0..self.built_states {
            if self.body_start[s + 1] > 0 {
                self.jointed.push(s as u32);
            }
            self.body_start[s + 1] += self.body_start[s];
        }
        self.body_joints.clear();
        self.body_joints
            .resize(self.body_start[self.built_states] as usize, 0);
        let mut fill = self.body_start[..self.built_states].to_vec();
        for (i, k) in keys.iter().enumerate() {
            for (side, bit) in [WRITE_A, WRITE_B].into_iter().enumerate() {
                if k[2] & u32::from(bit) != 0 {
                    let f = &mut fill[k[side] as usize];
                    self.body_joints[*f as usize] = (i as u32) << 1 | side as u32;
                    *f += 1;
                }
            }
        }
    }

    /// The warm start: every moving body takes the kept impulses of its
    /// joints, in storage order, body by body (blocks of bodies on the
    /// team). The same arithmetic, in the same order per body, as the
    /// joints' warm starts one after the other in storage order; no
    /// colours needed (a body writes only itself).
    pub(crate) fn warm_start(&mut self, joints: &[Joint], states: &mut [BodyState], team: &Team) {
        if self.position.len() != joints.len() || states.len() != self.built_states {
            self.update(joints, states);
        }
        if self.lanes_live() {
            self.lanes.refresh_warm(joints, team);
        }
        let (start, list) = (&self.body_start[..], &self.body_joints[..]);
        let lanes = self.lanes_live().then_some(&self.lanes);
        let body = |s: usize, st: &mut BodyState| {
            // A copy in registers, its velocities written back once.
            let mut local = *st;
            for &e in &list[start[s] as usize..start[s + 1] as usize] {
                let (j, side_b) = ((e >> 1) as usize, e & 1 == 1);
                // A lane joint's angle rows keep their impulses in its lane,
                // which has gathered all its warm start reads.
                if let Some(lanes) = lanes {
                    let lane = lanes.lane_of(j);
                    if lane != NO_LANE {
                        lanes.warm(lane).warm_start_side(&mut local, side_b);
                        continue;
                    }
                }
                joints[j].warm_start_side(&mut local, side_b);
            }
            st.v = local.v;
            st.w = local.w;
        };
        if team.threads() == 1 || list.len() < 2 * WARM_START_BLOCK {
            for &s in &self.jointed {
                body(s as usize, &mut states[s as usize]);
            }
            return;
        }
        team.for_each_chunk_mut(states, WARM_START_BLOCK, |i, block| {
            let first = i * WARM_START_BLOCK;
            for (k, st) in block.iter_mut().enumerate() {
                body(first + k, st);
            }
        });
    }

    /// After the colours' update beside the colours of `contacts` (the
    /// graph batch's prepare, after the contacts' own): on a team of
    /// several threads, the two plans checked against each other
    /// ([`CrossPlan`]). The contacts took their colours around the joints'
    /// ([`JointColours::reserve`]), so a colour's joints and contacts can
    /// run as one job.
    pub(crate) fn check_beside(
        &mut self,
        joints: &[Joint],
        states: &[BodyState],
        contacts: &ContactSolver,
        team: &Team,
    ) {
        if team.threads() > 1 && !joints.is_empty() && !contacts.is_empty() {
            self.cross.verify(&self.plan, contacts.plan(), states.len());
        }
    }

    /// Counts the colourings: a value that changes whenever
    /// [`JointColours::reserve`] would give something else.
    #[must_use]
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The colours the joints hold, by body slot (`BodyHandle::index`):
    /// bit `c` of `out[k]` when a joint of colour `c` moves body slot `k`.
    /// The contacts' persistent graph takes none of them
    /// ([`ConstraintGraph::set_reserved`](janus2d_core::graph::ConstraintGraph::set_reserved)),
    /// so that joints and contacts share the colours as Box2D's graph
    /// does. From the last colouring; `body_slots` as in
    /// [`JointColours::update_from`], for the joints as they were then.
    pub fn reserve(&self, body_slots: &[[u32; 2]], out: &mut Vec<u32>) {
        out.clear();
        for ((&[a, b], &colour), k) in body_slots.iter().zip(&self.colour_of).zip(&self.built_keys)
        {
            if (colour as usize) >= COLOURS {
                continue;
            }
            for (slot, bit) in [(a, WRITE_A), (b, WRITE_B)] {
                if k[2] & u32::from(bit) != 0 {
                    let slot = slot as usize;
                    if out.len() <= slot {
                        out.resize(slot + 1, 0);
                    }
                    out[slot] |= 1 << colour;
                }
            }
        }
    }

    /// The check of the colours' plan against the contacts' (see
    /// [`JointColours::update_around`]).
    pub(crate) fn cross(&self) -> &CrossPlan {
        &self.cross
    }

    /// Which ends each joint of segment `s` writes, in solve order.
    pub(crate) fn segment_writes(&self, s: usize) -> &[u8] {
        match (self.starts.get(s), self.starts.get(s + 1)) {
            (Some(&a), Some(&b)) => &self.writes[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Colours the joints if they changed since the last colouring (a
    /// stage called without the batch's prepare).
    pub(crate) fn ensure_coloured(&mut self, joints: &[Joint], states: &[BodyState]) {
        if self.position.len() != joints.len() || states.len() != self.built_states {
            self.update(joints, states);
        }
    }

    /// True when a stage should spread the colours over `team`: more than
    /// one thread and a colour of more than one block.
    pub(crate) fn wants_team(&self, team: &Team) -> bool {
        team.threads() > 1
            && (0..self.colour_count()).any(|c| self.joints_in(c).len() > JOINTS_PER_BLOCK)
    }

    /// Joints per block for a colour of `len` joints on `team`: about four
    /// blocks per thread, at least [`JOINTS_PER_BLOCK`].
    pub(crate) fn block_len(len: usize, team: &Team) -> usize {
        len.div_ceil(4 * team.threads()).max(JOINTS_PER_BLOCK)
    }

    /// The plan of the colours' states (group `c`: colour `c`).
    pub(crate) fn plan(&self) -> &StatePlan<2> {
        &self.plan
    }

    /// Solves segment `s` (colour `s`, or the overflow for
    /// `s == colour_count()`) on the caller, in solve order.
    pub(crate) fn solve_segment(
        &mut self,
        s: usize,
        ctx: &StepContext,
        joints: &mut [Joint],
        states: &mut [BodyState],
        use_bias: bool,
    ) {
        let (Some(&start), Some(&end)) = (self.starts.get(s), self.starts.get(s + 1)) else {
            return;
        };
        let lanes = self.lanes_live();
        if lanes {
            self.lanes
                .solve_colour(s, ctx, states, use_bias, &Team::serial());
        }
        for p in start as usize..end as usize {
            if lanes && self.lanes.lane_of(self.order[p] as usize) != NO_LANE {
                continue;
            }
            // The joint a few places on: colour order is not storage order.
            if let Some(j) = self
                .order
                .get(p + JOINTS_AHEAD)
                .and_then(|&ahead| joints.get(ahead as usize))
            {
                janus2d_core::hint::prefetch(j);
            }
            let j = &mut joints[self.order[p] as usize];
            let mut pair = PairOf::new(states, j.base().state_a, j.base().state_b, self.writes[p]);
            j.solve_pair(ctx, &mut pair, use_bias);
        }
    }

    /// The solved joints in solve order, for a stage on the team
    /// ([`JointColours::parts`] cuts it by colour; hand it back with
    /// [`JointColours::put_refs`]).
    ///
    /// Empty when no colour has a joint solved one at a time
    /// ([`JointColours::any_scalar`]; cut it with [`JointColours::parts`]).
    pub(crate) fn take_refs<'j>(&mut self, joints: &'j mut [Joint]) -> Vec<Option<&'j mut Joint>> {
        let mut refs = self.scratch.take();
        if !self.any_scalar() {
            return refs;
        }
        refs.resize_with(self.order.len(), || None);
        let lanes = self.lanes_live();
        for (i, (j, &p)) in joints.iter_mut().zip(&self.position).enumerate() {
            if p != NONE && !(lanes && self.lanes.lane_of(i) != NO_LANE) {
                refs[p as usize] = Some(j);
            }
        }
        refs
    }

    /// Joints solved in lanes this step (0 outside a step).
    #[cfg(test)]
    pub(crate) fn lane_joints(&self) -> usize {
        if self.lanes_live() {
            self.lanes.joint_count()
        } else {
            0
        }
    }

    /// Whether this step's lanes are live and built on the current
    /// colouring.
    #[inline]
    fn lanes_live(&self) -> bool {
        self.lanes.is_live() && self.lanes_generation == self.generation
    }

    /// Builds the lanes of this step (after the joints' prepare and the
    /// colouring; [`crate::revolute_lanes`]).
    pub(crate) fn build_lanes(
        &mut self,
        joints: &mut [Joint],
        ctx: &StepContext,
        state_count: usize,
        team: &Team,
    ) {
        self.store_lanes(joints);
        if self.lanes_off || self.lane_candidates == 0 {
            return;
        }
        let colours = self.colour_count();
        let (starts, keys) = (&self.starts, &self.built_keys);
        self.lanes.build(
            joints,
            (0..colours).map(|c| (starts[c] as usize, starts[c + 1] as usize)),
            &self.order,
            &self.writes,
            |j| keys[j][2] & LANE != 0,
            ctx,
            state_count,
            team,
        );
        self.lanes_generation = self.generation;
        let lanes = &self.lanes;
        self.scalar_in.clear();
        self.scalar_in.extend((0..colours).map(|c| {
            self.order[starts[c] as usize..starts[c + 1] as usize]
                .iter()
                .any(|&j| lanes.lane_of(j as usize) == NO_LANE)
        }));
    }

    /// Whether colour `colour` has a joint solved one at a time (beside
    /// its lanes, if any): a stage on the team takes it from
    /// [`JointColours::take_refs`]'s part of the colour. False beyond the
    /// colours (the overflow is solved by [`JointColours::solve_segment`]).
    #[inline]
    pub(crate) fn has_scalar(&self, colour: usize) -> bool {
        if colour >= self.colour_count() {
            return false;
        }
        if self.lanes_live() {
            self.scalar_in.get(colour).copied().unwrap_or(true)
        } else {
            !self.joints_in(colour).is_empty()
        }
    }

    /// Whether any colour has a joint solved one at a time
    /// ([`JointColours::has_scalar`]): else a stage on the team needs no
    /// [`JointColours::take_refs`].
    pub(crate) fn any_scalar(&self) -> bool {
        (0..self.colour_count()).any(|c| self.has_scalar(c))
    }

    /// The solved joints' references for a stage on the team, cut by
    /// colour (`refs` from [`JointColours::take_refs`], or empty parts
    /// when no colour has a joint solved one at a time).
    pub(crate) fn parts<'r, 'j>(
        &self,
        refs: &'r mut [Option<&'j mut Joint>],
    ) -> SmallVec<[&'r mut [Option<&'j mut Joint>]; COLOURS + 1]> {
        if refs.is_empty() {
            let mut parts = SmallVec::new();
            parts.resize_with(self.colour_count() + 1, Default::default);
            return parts;
        }
        self.split(refs)
    }

    /// One iteration of colour `colour`'s lanes (before the colour's other
    /// joints and contacts: they share no moving body).
    pub(crate) fn solve_lanes(
        &mut self,
        colour: usize,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        if self.lanes_live() {
            self.lanes.solve_colour(colour, ctx, states, use_bias, team);
        }
    }

    /// Writes the lanes' impulses back into the joints and ends the lanes
    /// (the batch's store; lanes of an older colouring are dropped).
    pub(crate) fn store_lanes(&mut self, joints: &mut [Joint]) {
        if self.lanes_live() {
            self.lanes.store(joints);
        } else {
            self.lanes.discard();
        }
    }

    /// Keeps the allocation of `refs` for the next stage.
    pub(crate) fn put_refs(&mut self, refs: Vec<Option<&mut Joint>>) {
        self.scratch.put(refs);
    }

    /// `refs` (from [`JointColours::take_refs`]) cut into its segments:
    /// colour by colour, then the overflow.
    pub(crate) fn split<'r, 'j>(
        &self,
        refs: &'r mut [Option<&'j mut Joint>],
    ) -> SmallVec<[&'r mut [Option<&'j mut Joint>]; COLOURS + 1]> {
        let mut parts = SmallVec::new();
        let mut rest = refs;
        for s in 0..self.colour_count() + 1 {
            let len = (self.starts[s + 1] - self.starts[s]) as usize;
            let (part, tail) = std::mem::take(&mut rest).split_at_mut(len);
            parts.push(part);
            rest = tail;
        }
        parts
    }

    /// One velocity iteration of the joints' Gauss–Seidel rows, colour by
    /// colour (`reverse`: the overflow first, then the colours from the
    /// last), each colour's joints spread over `team`.
    pub(crate) fn solve(
        &mut self,
        ctx: &StepContext,
        joints: &mut [Joint],
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        self.ensure_coloured(joints, states);
        let segments = self.colour_count() + 1;
        if !self.wants_team(team) {
            for s in 0..segments {
                let s = if reverse { segments - 1 - s } else { s };
                self.solve_segment(s, ctx, joints, states, use_bias);
            }
            return;
        }
        // The overflow on the caller: first on a reverse sweep, last on a
        // forward one.
        let overflow = segments - 1;
        if reverse {
            self.solve_segment(overflow, ctx, joints, states, use_bias);
        }
        let mut refs = self.take_refs(joints);
        {
            let mut parts = self.parts(&mut refs);
            for k in 0..overflow {
                let s = if reverse { overflow - 1 - k } else { k };
                self.solve_lanes(s, ctx, states, use_bias, team);
                if !self.has_scalar(s) {
                    continue;
                }
                let part = &mut *parts[s];
                let per_block = Self::block_len(part.len(), team);
                if part.len() <= per_block {
                    let writes = &self.writes[self.starts[s] as usize..];
                    for (j, &w) in part.iter_mut().zip(writes) {
                        let Some(j) = j else { continue };
                        let mut pair = PairOf::new(states, j.base().state_a, j.base().state_b, w);
                        j.solve_pair(ctx, &mut pair, use_bias);
                    }
                    continue;
                }
                team.for_each_planned(&self.plan, s, part, states, per_block, |j, view| {
                    if let Some(j) = j {
                        j.solve_pair(ctx, view, use_bias);
                    }
                });
            }
        }
        self.put_refs(refs);
        if !reverse {
            self.solve_segment(overflow, ctx, joints, states, use_bias);
        }
    }
}

/// A joint's colouring key: its state indices and which ends move (see
/// [`JointColours::update`]).
type Key = [u32; 3];

#[inline]
pub(crate) fn key(j: &Joint, states: &[BodyState]) -> Key {
    let base = j.base();
    key_at(j, base.state_a, base.state_b, states)
}

/// [`key`] with the bodies on state indices `a` and `b`.
#[inline]
fn key_at(j: &Joint, a: u32, b: u32, states: &[BodyState]) -> Key {
    let base = j.base();
    if !base.enabled || (a == 0 && b == 0) {
        return [0; 3];
    }
    let coloured = if j.has_iterative_rows() { COLOURED } else { 0 };
    let lane = if j.lane_candidate() { LANE } else { 0 };
    let flags = ACTIVE
        | coloured
        | lane
        | if is_moving(states, a) {
            u32::from(WRITE_A)
        } else {
            0
        }
        | if is_moving(states, b) {
            u32::from(WRITE_B)
        } else {
            0
        };
    [a, b, flags]
}

/// The allocation of a stage's joint references, kept empty between
/// stages (a reference cannot outlive its stage; the buffer can).
#[derive(Default)]
struct JointRefs(Vec<Option<&'static mut Joint>>);

impl JointRefs {
    /// The buffer, empty, for references of any lifetime.
    fn take<'a>(&mut self) -> Vec<Option<&'a mut Joint>> {
        let mut v = std::mem::take(&mut self.0);
        v.clear();
        // An empty vector converts in place (same element layout).
        v.into_iter().map(|_| None).collect()
    }

    /// Keeps the buffer of `v` for the next stage.
    fn put(&mut self, mut v: Vec<Option<&mut Joint>>) {
        v.clear();
        self.0 = v.into_iter().map(|_| None).collect();
    }
}

impl Clone for JointRefs {
    fn clone(&self) -> Self {
        JointRefs::default()
    }
}

impl std::fmt::Debug for JointRefs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("JointRefs")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::joint_solver::JointBatch;
    use crate::joint_tree::JointForest;
    use crate::revolute::{RevoluteJoint, RevoluteJointDef};
    use janus2d_core::body::{BodyDef, BodyHandle, BodySet};
    use janus2d_core::constraint::{Constraint, ConstraintBatch};
    use janus2d_core::math::{Real, Vec2};
    use janus2d_core::solver::SolverSettings;

    /// An `n × n` grid of bodies, each joined to its right and lower
    /// neighbour (a grid has loops: no joint is in a tree), the top row
    /// pinned to a static body; plus a hub with `spokes` motor joints and a
    /// plain two-link chain (a tree without angle rows).
    fn grid(n: usize, spokes: usize) -> (BodySet, Vec<Joint>, BodyHandle) {
        let mut set = BodySet::new();
        let ground = set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let v = |x: usize, y: usize| Vec2::new(x as Real, -(y as Real));
        let mut ids = Vec::new();
        for y in 0..n {
            for x in 0..n {
                let def = BodyDef::dynamic(v(x, y)).with_angular_velocity(0.1 * x as Real);
                ids.push(set.create(&def).unwrap());
            }
        }
        let mut joints: Vec<Joint> = Vec::new();
        let join =
            |a, b, la: Vec2, lb: Vec2| RevoluteJoint::new(RevoluteJointDef::new(a, b, la, lb));
        let half = 0.5;
        for y in 0..n {
            for x in 0..n {
                let id = ids[y * n + x];
                if x + 1 < n {
                    let d = Vec2::new(half, 0.0);
                    joints.push(Joint::from(join(id, ids[y * n + x + 1], d, -d)));
                }
                if y + 1 < n {
                    let d = Vec2::new(0.0, -half);
                    let mut j = join(id, ids[(y + 1) * n + x], d, -d);
                    if x % 3 == 0 {
                        j.def.enable_limit = true;
                        j.def.lower_angle = -0.2;
                        j.def.upper_angle = 0.2;
                    }
                    joints.push(Joint::from(j));
                }
                if y == 0 {
                    joints.push(Joint::from(join(ground, id, v(x, 0), Vec2::ZERO)));
                }
            }
        }
        let hub = set.create(&BodyDef::dynamic(Vec2::new(0.0, 50.0))).unwrap();
        for k in 0..spokes {
            let b = set
                .create(&BodyDef::dynamic(Vec2::new(k as Real, 52.0)))
                .unwrap();
            // A tree, with a motor: angle rows, so coloured.
            let mut j = join(hub, b, Vec2::ZERO, Vec2::new(0.0, -2.0));
            j.def.enable_motor = true;
            j.def.max_motor_torque = 1.0;
            joints.push(Joint::from(j));
        }
        let c0 = set.create(&BodyDef::dynamic(Vec2::new(0.0, 60.0))).unwrap();
        let c1 = set.create(&BodyDef::dynamic(Vec2::new(1.0, 60.0))).unwrap();
        joints.push(Joint::from(join(
            ground,
            c0,
            Vec2::new(0.0, 60.0),
            Vec2::ZERO,
        )));
        joints.push(Joint::from(join(
            c0,
            c1,
            Vec2::new(0.5, 0.0),
            Vec2::new(-0.5, 0.0),
        )));
        (set, joints, hub)
    }

    fn prepared(n: usize, spokes: usize) -> (BodySet, Vec<Joint>, JointColours, StepContext) {
        let (set, mut joints, _) = grid(n, spokes);
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::new(0.0, -10.0));
        let mut forest = JointForest::default();
        let mut colours = JointColours::new();
        let mut batch = JointBatch {
            joints: &mut joints,
            forest: &mut forest,
            colours: &mut colours,
        };
        batch.prepare(&ctx, &set);
        (set, joints, colours, ctx)
    }

    #[test]
    fn a_colour_never_holds_a_moving_body_twice() {
        let (set, joints, colours, _) = prepared(12, 30);
        assert!(colours.colour_count() >= 2);
        let mut seen = 0;
        for c in 0..colours.colour_count() {
            let mut bodies = std::collections::HashSet::new();
            for &i in colours.joints_in(c) {
                let j = &joints[i as usize];
                for s in [j.base().state_a, j.base().state_b] {
                    let st = &set.states[s as usize];
                    if s != 0 && st.moves() {
                        assert!(bodies.insert(s), "state {s} twice in colour {c}");
                    }
                }
            }
            // Each colour in storage order.
            assert!(colours.joints_in(c).windows(2).all(|w| w[0] < w[1]));
            seen += colours.joints_in(c).len();
        }
        // The hub's 30 spokes: 24 colours, 6 in the overflow.
        assert_eq!(colours.overflow_len(), 6);
        // Every joint but the plain chain's two (its warm start only).
        assert_eq!(seen + colours.overflow_len(), joints.len() - 2);
        assert!(joints[joints.len() - 2..].iter().all(|j| j.in_tree()));
    }

    #[test]
    fn recolours_only_when_a_key_changes() {
        let (set, mut joints, mut colours, _) = prepared(6, 0);
        let order = colours.order.clone();
        colours.update(&joints, &set.states);
        assert_eq!(colours.order, order, "same keys, same order");
        joints[0].set_enabled(false);
        colours.update(&joints, &set.states);
        assert_eq!(
            colours.order.len() + 1,
            order.len(),
            "a disabled joint is not solved"
        );
        assert!(!colours.order.contains(&0));
    }

    /// Steps a few substeps' worth of stages on `team`: warm start, solve,
    /// relax (reversed), and returns the bits of every velocity.
    fn run_stages(team: &Team) -> Vec<u64> {
        let (mut set, mut joints, mut colours, ctx) = prepared(24, 30);
        for j in &mut joints {
            j.tree_point_mut().unwrap().impulse = Vec2::new(0.01, -0.02);
        }
        for flip in [false, true, false] {
            let states = &mut set.states;
            colours.warm_start(&joints, states, team);
            colours.solve(&ctx, &mut joints, states, true, flip, team);
            colours.solve(&ctx, &mut joints, states, false, !flip, team);
        }
        set.states
            .iter()
            .flat_map(|s| [s.v.x, s.v.y, s.w])
            .map(|x| janus2d_core::math::to_f64(x).to_bits())
            .collect()
    }

    #[test]
    fn the_team_gives_the_serial_result() {
        let serial = run_stages(&Team::serial());
        let team = janus2d_core::parallel::with_team(run_stages);
        assert_eq!(team, serial);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            let team = janus2d_core::parallel::with_threads(threads, run_stages).unwrap();
            assert_eq!(team, serial, "{threads} threads");
        }
    }

    /// The warm start body by body is bit for bit the joints' warm starts
    /// one after the other in storage order.
    #[test]
    fn the_warm_start_by_body_is_the_storage_order_warm_start() {
        let (set, mut joints, mut colours, ctx) = prepared(9, 30);
        // The impulses set below are the joints' own: no lanes hold them.
        colours.store_lanes(&mut joints);
        for (k, j) in joints.iter_mut().enumerate() {
            let x = k as Real;
            let point = j.tree_point_mut().unwrap();
            point.impulse = Vec2::new(0.013 * x.sin(), -0.021 * x.cos());
            point.frame_a = Vec2::new(0.5 + 0.01 * x.cos(), 0.02 * x.sin());
        }
        let mut expected = set.states.clone();
        for s in expected.iter_mut() {
            s.dq = janus2d_core::math::Rot::from_angle(0.3);
        }
        let mut states = expected.clone();
        for j in joints.iter_mut() {
            j.warm_start(&ctx, &mut expected);
        }
        colours.warm_start(&joints, &mut states, &Team::serial());
        let bits = |s: &[BodyState]| -> Vec<u64> {
            s.iter()
                .flat_map(|s| [s.v.x, s.v.y, s.w])
                .map(|x| janus2d_core::math::to_f64(x).to_bits())
                .collect()
        };
        assert_eq!(bits(&states), bits(&expected));
    }
}
