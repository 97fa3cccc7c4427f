//! Revolute joints with angle rows, [`LANES`] joints at a time.
//!
//! A ragdoll's revolute joints run a spring, a motor and two limits on the
//! relative angle besides their point block (Box2D's human: all four), and
//! one at a time they were a third of a ragdoll scene's step (rain). The
//! joints of one colour share no moving body, so [`LANES`] of them run
//! side by side on the wide lane type, with the row arithmetic the
//! one-joint solve runs ([`crate::joint_rows::angle_row`] for each angle
//! row, [`crate::joint_rows::point_equality_row`] for the point block of a
//! joint in no tree; a tree joint's point rows stay with the exact tree
//! solve, [`crate::joint_tree`]).
//!
//! A plain hinge (no angle row) stays one joint at a time: its point block
//! alone ran no faster in lanes (joint_grid: the gather, the build and the
//! impulses' round trip cost what the wide rows saved).
//!
//! ```text
//! prepare (after the colours)   each colour's revolute joints with angle rows, in solve order:
//!                                 colour 0: [j0 j2 j5 … j40] [j44 … pad]   chunk = LANES joints
//!                                 colour 1: [j1 j4 …]
//!                               the rest of the colour stays one joint at a time
//! solve, relax (each colour)    gather both states (4×4 transposes in f32), the
//!                               joint angles on the lanes (atan2_lanes and
//!                               wrap_angle_lanes: bit for bit what one joint's
//!                               Rot::relative_angle reads); spring, motor, lower, upper,
//!                               then the point block where the joint is in no
//!                               tree, on the lanes; scatter v, ω where the body moves
//! warm start (per body)         a lane joint's impulses, masses and arms read from
//!                               its lane's warm record (gathered once a substep),
//!                               not from the joint
//! store (end of the step)       the lanes' impulses back into the joints
//! ```
//!
//! A row a lane's joint has switched off leaves the lane's velocities and
//! impulse as they were (selects, not zero steps), and padding lanes are
//! never written, so each lane's result is bit for bit the one-joint solve
//! of the same joint: the joints of a colour are independent, and the
//! order within a colour does not change the state.

use janus2d_core::body::{BodyState, InvMass};
use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::{StatePlan, Team};

use crate::contact_solver::{Direct, LaneStates, PLAN_SLOTS, load, plan_slots, store_where};
use crate::joint::Joint;
use crate::joint_rows::{
    Bounds, PointTerms, SoftLanes, Terms, WarmSide, angle_row, point_equality_row,
};
use crate::lane::{LANES, Lane, V2, Velocity, Wide as W, atan2_lanes, wrap_angle_lanes};
use crate::parts::{MassLanes, PairMass, angular_correction_cap, arms_lanes};
use janus2d_core::softness::Softness;

/// Side a of a lane.
const A: usize = 0;
/// Side b of a lane.
const B: usize = 1;

/// No lane: a joint solved one at a time.
pub(crate) const NO_LANE: u32 = u32::MAX;

/// Fewest chunks of a colour that run on the team (fewer: on the caller).
const TEAM_CHUNKS: usize = 16;

/// What one revolute joint's Gauss–Seidel rows read this step, as its
/// prepare left them (`RevoluteJoint::lane`).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RevoluteLane {
    /// State indices of bodies a and b.
    pub(crate) state: [u32; 2],
    /// Inverse inertias of a and b, 1/(kg·m²).
    pub(crate) inv_inertia: [Real; 2],
    /// `θ_b − θ_a − θ_ref` at the start of the step, rad.
    pub(crate) delta_angle: Real,
    /// The spring or the limits read the joint angle.
    pub(crate) reads_angle: bool,
    /// The spring row is solved (switched on, and some body turns).
    pub(crate) spring: bool,
    /// The spring's softness.
    pub(crate) spring_softness: Softness,
    /// The spring's rest angle, rad.
    pub(crate) target_angle: Real,
    /// The motor row is solved.
    pub(crate) motor: bool,
    /// The motor's bias, `−speed`, rad/s.
    pub(crate) motor_bias: Real,
    /// The motor's largest impulse, `h · max torque`, N·m·s.
    pub(crate) motor_max: Real,
    /// The limit rows are solved.
    pub(crate) limit: bool,
    /// Lower and upper limits, rad.
    pub(crate) lower_angle: Real,
    pub(crate) upper_angle: Real,
    /// Effective masses of the spring, motor, lower and upper rows, kg·m².
    pub(crate) mass: [Real; 4],
    /// Their kept impulses, N·m·s.
    pub(crate) impulse: [Real; 4],
    /// The point rows are Gauss–Seidel rows (the joint is in no tree).
    pub(crate) point: bool,
    /// Inverse masses of a and b, 1/kg.
    pub(crate) inv_mass: [Real; 2],
    /// The anchors from the centres at the step's start, m.
    pub(crate) frames: [Vec2; 2],
    /// `c_b − c_a` at the step's start, m.
    pub(crate) delta_center: Vec2,
    /// The point rows' softness.
    pub(crate) point_softness: Softness,
    /// The point rows' kept impulse, N·s.
    pub(crate) point_impulse: Vec2,
}

/// Asks for the records of joints `ids` (whole) ahead of their reads:
/// lanes go in colour order, not storage order, so each is a random read
/// of several lines. A hint only.
#[inline]
fn prefetch_joints(joints: &[Joint], ids: impl Iterator<Item = u32>) {
    for j in ids {
        if let Some(joint) = joints.get(j as usize) {
            janus2d_core::hint::prefetch_all(joint);
        }
    }
}

/// What a lane joint's warm start reads, gathered once a substep
/// ([`RevoluteLanes::refresh_warm`]) so that the warm start, body by body,
/// reads no joint record (a random read of three lines per joint and
/// side in a ragdoll scene).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct LaneWarm {
    /// The angle rows' summed kept impulse, N·m·s.
    angle: Real,
    /// The point's kept impulse, N·s: the lane's where it solves the point
    /// rows, else the joint's (which its tree solve keeps).
    point: Vec2,
    /// The two bodies' inverse masses, as the joint loaded them.
    masses: PairMass,
    /// The anchors' arms from the centres at the step's start, m.
    frames: (Vec2, Vec2),
}

impl LaneWarm {
    /// Body `st`'s share (`side_b`: body b, else a) of the joint's warm
    /// start: the arithmetic of one joint's ([`WarmSide::hinge`]).
    #[inline(always)]
    pub(crate) fn warm_start_side(&self, st: &mut BodyState, side_b: bool) {
        WarmSide::new(st, self.masses, side_b).hinge(self.angle, self.frames, self.point);
    }
}

/// What a lane holds of its joint's impulses: the angle rows' (spring,
/// motor, lower, upper, N·m·s) and, where the lane solves the point rows,
/// the point's (N·s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LaneImpulses {
    pub(crate) angle: [Real; 4],
    pub(crate) point: Option<Vec2>,
}

/// [`LANES`] joints' rows in structure-of-arrays form: the angle rows'
/// settings, masses and impulses, and the point block's (used where
/// `point_on`).
#[derive(Clone, Debug, Default)]
struct WideRevolute {
    /// State index of body a, then b, per lane (0 for padding).
    state: [[u32; LANES]; 2],
    /// The joint's storage index per lane.
    joint: [u32; LANES],
    /// Lanes in use.
    len: usize,
    /// Bit `k`: lane `k`'s body a moves; bit `LANES + k`: its body b.
    moving: u32,
    /// Bit `k`: lane `k` reads the joint angle.
    reads_angle: u32,
    delta_angle: W,
    spring_on: W,
    spring_softness: SoftLanes<W>,
    target_angle: W,
    motor_on: W,
    motor_bias: W,
    motor_min: W,
    motor_max: W,
    limit_on: W,
    lower_angle: W,
    upper_angle: W,
    /// Spring, motor, lower, upper.
    mass: [W; 4],
    impulse: [W; 4],
    point_on: W,
    /// Inverse masses and inertias of a and b (the angle rows read the
    /// inertias).
    masses: MassLanes<W>,
    frames: (V2<W>, V2<W>),
    delta_center: V2<W>,
    point_softness: SoftLanes<W>,
    point_impulse: V2<W>,
}

impl WideRevolute {
    /// A chunk of the joints `entries` names (`(storage index, writes)`:
    /// which ends of the lane's joint move, [`crate::parts::WRITE_A`] and
    /// [`crate::parts::WRITE_B`]; index `u32::MAX` for a padding lane),
    /// from their prepared state; `h` is the substep, s. Written in place
    /// (a chunk built on the stack and moved into its slot was a memmove
    /// of the whole chunk).
    fn fill(c: &mut Self, entries: &[(u32, u8)], joints: &[Joint], h: Real) {
        // Every lane off and zero; padding lanes name no joint.
        *c = WideRevolute {
            joint: [u32::MAX; LANES],
            ..WideRevolute::default()
        };
        // All bits set: a lane of a mask that holds.
        let on = |mask: &mut W, k: usize, yes: bool| {
            if yes {
                mask.set_lane(k, Real::from_bits(!0));
            }
        };
        let set_soft = |soft: &mut SoftLanes<W>, k: usize, s: Softness| {
            soft.bias_rate.set_lane(k, s.bias_rate);
            soft.mass_scale.set_lane(k, s.mass_scale);
            soft.impulse_scale.set_lane(k, s.impulse_scale);
        };
        let set_v2 = |v: &mut V2<W>, k: usize, x: Vec2| {
            v.x.set_lane(k, x.x);
            v.y.set_lane(k, x.y);
        };
        for &(j, writes) in entries {
            let Some(Joint::Revolute(r)) = joints.get(j as usize) else {
                continue;
            };
            let (k, l) = (c.len, r.lane(h));
            c.len += 1;
            c.state[A][k] = l.state[0];
            c.state[B][k] = l.state[1];
            c.joint[k] = j;
            c.moving |= u32::from(writes & crate::parts::WRITE_A != 0) << k;
            c.moving |= u32::from(writes & crate::parts::WRITE_B != 0) << (LANES + k);
            c.reads_angle |= u32::from(l.reads_angle) << k;
            c.delta_angle.set_lane(k, l.delta_angle);
            on(&mut c.spring_on, k, l.spring);
            set_soft(&mut c.spring_softness, k, l.spring_softness);
            c.target_angle.set_lane(k, l.target_angle);
            on(&mut c.motor_on, k, l.motor);
            c.motor_bias.set_lane(k, l.motor_bias);
            c.motor_min.set_lane(k, -l.motor_max);
            c.motor_max.set_lane(k, l.motor_max);
            on(&mut c.limit_on, k, l.limit);
            c.lower_angle.set_lane(k, l.lower_angle);
            c.upper_angle.set_lane(k, l.upper_angle);
            for i in 0..4 {
                c.mass[i].set_lane(k, l.mass[i]);
                c.impulse[i].set_lane(k, l.impulse[i]);
            }
            on(&mut c.point_on, k, l.point);
            c.masses.inv_mass_a.set_lane(k, l.inv_mass[0]);
            c.masses.inv_inertia_a.set_lane(k, l.inv_inertia[0]);
            c.masses.inv_mass_b.set_lane(k, l.inv_mass[1]);
            c.masses.inv_inertia_b.set_lane(k, l.inv_inertia[1]);
            set_v2(&mut c.frames.0, k, l.frames[0]);
            set_v2(&mut c.frames.1, k, l.frames[1]);
            set_v2(&mut c.delta_center, k, l.delta_center);
            set_soft(&mut c.point_softness, k, l.point_softness);
            set_v2(&mut c.point_impulse, k, l.point_impulse);
        }
    }

    /// One iteration of the lanes' rows, in the one-joint order: spring,
    /// motor, lower, upper, then the point block where the joint is in no
    /// tree.
    #[inline(always)]
    fn solve<S: LaneStates>(&mut self, states: &mut S, rows: &LaneContext) {
        let (vel_a, delta_a, flags_a) = load(states, A);
        let (vel_b, delta_b, flags_b) = load(states, B);
        // The joint angle on every lane, with the arithmetic of one joint's
        // read (`Rot::relative_angle`, `wrap_angle`; lane versions that
        // agree bit for bit): q = q_a⁻¹ q_b, θ = wrap(Δθ + atan2(q_s, q_c)).
        // Only the spring and the limits read it, and where they are off
        // their rows are selected away. (One joint at a time, the angle
        // was a third of this solve in rain.)
        let angle = if self.reads_angle != 0 {
            let q_c = delta_a.q_c * delta_b.q_c + delta_a.q_s * delta_b.q_s;
            let q_s = delta_a.q_c * delta_b.q_s - delta_a.q_s * delta_b.q_c;
            wrap_angle_lanes(self.delta_angle + atan2_lanes(q_s, q_c))
        } else {
            W::splat(0.0)
        };
        let (mut w_a, mut w_b) = (vel_a.w, vel_b.w);
        let inv_inertia = (self.masses.inv_inertia_a, self.masses.inv_inertia_b);
        // Each row on copies, kept where the lane's joint solves it.
        let mut row = |on: W, sign: Real, i: usize, t: Terms<W>, bounds: Bounds<W>| {
            let (mut a, mut b, mut impulse) = (w_a, w_b, self.impulse[i]);
            angle_row(
                (&mut a, &mut b),
                inv_inertia,
                sign,
                self.mass[i],
                t,
                bounds,
                &mut impulse,
            );
            w_a = W::select(on, a, w_a);
            w_b = W::select(on, b, w_b);
            self.impulse[i] = W::select(on, impulse, self.impulse[i]);
        };
        let infinity = W::splat(Real::INFINITY);
        let spring = Terms::soft_lanes(self.spring_softness, angle - self.target_angle, infinity);
        row(self.spring_on, 1.0, 0, spring, Bounds::Free);
        let motor = Terms {
            bias: self.motor_bias,
            ..Terms::rigid()
        };
        row(
            self.motor_on,
            1.0,
            1,
            motor,
            Bounds::Clamp(self.motor_min, self.motor_max),
        );
        let one_sided = Bounds::Clamp(W::splat(0.0), infinity);
        let lower = Terms::limit_lanes(
            angle - self.lower_angle,
            rows.limit_softness,
            rows.inv_h,
            rows.use_bias,
            rows.max_bias,
        );
        row(self.limit_on, 1.0, 2, lower, one_sided);
        let upper = Terms::limit_lanes(
            self.upper_angle - angle,
            rows.limit_softness,
            rows.inv_h,
            rows.use_bias,
            rows.max_bias,
        );
        row(self.limit_on, -1.0, 3, upper, one_sided);
        // The point rows, where the joint is in no tree.
        let mut vel = [Velocity { w: w_a, ..vel_a }, Velocity { w: w_b, ..vel_b }];
        if W::any(self.point_on) {
            let (r_a, r_b, c) = arms_lanes(
                self.frames,
                self.delta_center,
                ((delta_a.q_c, delta_a.q_s), (delta_b.q_c, delta_b.q_s)),
                (
                    V2::new(delta_a.dp_x, delta_a.dp_y),
                    V2::new(delta_b.dp_x, delta_b.dp_y),
                ),
            );
            let t =
                PointTerms::equality_lanes(self.point_softness, c, rows.max_speed, rows.use_bias);
            let (mut solved, mut impulse) = (vel, self.point_impulse);
            point_equality_row(&mut solved, &self.masses, (r_a, r_b), t, &mut impulse);
            let on = self.point_on;
            // (In place: an array `map` here was a 192-byte copy through
            // memmove, 1% of rain.)
            for (v, solved) in vel.iter_mut().zip(solved) {
                *v = Velocity::select(on, solved, *v);
            }
            self.point_impulse = V2::select(on, impulse, self.point_impulse);
        }
        let lanes = (1 << LANES) - 1;
        store_where(states, A, &vel[A], flags_a, self.moving & lanes);
        store_where(states, B, &vel[B], flags_b, (self.moving >> LANES) & lanes);
    }

    /// Lane `k`'s kept impulses.
    fn impulses(&self, k: usize) -> LaneImpulses {
        let point = (self.point_on.lane(k).to_bits() != 0)
            .then(|| Vec2::new(self.point_impulse.x.lane(k), self.point_impulse.y.lane(k)));
        LaneImpulses {
            angle: self.impulse.map(|i| i.lane(k)),
            point,
        }
    }
}

/// What every lane's rows read from the step.
struct LaneContext {
    limit_softness: SoftLanes<W>,
    inv_h: W,
    max_bias: W,
    /// The point rows' largest feedback speed, m/s.
    max_speed: W,
    use_bias: bool,
}

impl LaneContext {
    fn of(ctx: &StepContext, use_bias: bool) -> Self {
        LaneContext {
            limit_softness: SoftLanes::splat(ctx.joint_softness),
            inv_h: W::splat(ctx.inv_h),
            max_bias: W::splat(angular_correction_cap(ctx.joint_max_correction_speed)),
            max_speed: W::splat(ctx.joint_max_correction_speed),
            use_bias,
        }
    }
}

/// The lane joints of one step, colour by colour (see the module docs).
/// Live from the joints' prepare to the step's store.
#[derive(Clone, Debug, Default)]
pub(crate) struct RevoluteLanes {
    chunks: Vec<WideRevolute>,
    /// Where each colour's chunks start; the last entry is the total.
    starts: Vec<u32>,
    /// Per joint (storage index): `chunk · LANES + lane`, or [`NO_LANE`].
    /// Empty while no lanes are live.
    lane_of: Vec<u32>,
    /// The chunks' states, one group per colour (verified for a team of
    /// several threads).
    plan: StatePlan<PLAN_SLOTS>,
    /// Scratch of the build: each lane's joint (storage index, or
    /// `u32::MAX` for padding) and the ends it writes.
    pending: Vec<(u32, u8)>,
    /// Per lane, what its joint's warm start adds (refreshed before each
    /// warm start, [`RevoluteLanes::refresh_warm`]): one line read per
    /// joint and body instead of the chunk's scattered lanes.
    warm: Vec<[LaneWarm; LANES]>,
}

/// Chunks per block of [`RevoluteLanes::refresh_warm`] on a team.
const WARM_BLOCK: usize = 128;

impl RevoluteLanes {
    /// This step's chunks.
    fn live_chunks(&self) -> &[WideRevolute] {
        let count = self.starts.last().map_or(0, |&n| n as usize);
        &self.chunks[..count.min(self.chunks.len())]
    }

    /// Joints in lanes.
    #[cfg(test)]
    pub(crate) fn joint_count(&self) -> usize {
        self.live_chunks().iter().map(|c| c.len).sum()
    }

    /// Whether lanes are live (built and not yet stored).
    #[inline]
    pub(crate) fn is_live(&self) -> bool {
        !self.lane_of.is_empty()
    }

    /// The lane of joint `j`, or [`NO_LANE`].
    #[inline]
    pub(crate) fn lane_of(&self, j: usize) -> u32 {
        self.lane_of.get(j).copied().unwrap_or(NO_LANE)
    }

    /// Builds the lanes: for each colour, its segment of `order` (joint
    /// storage indices, with the ends each writes in `writes`), the joints
    /// `candidate` names (revolute joints with angle rows, solved: read
    /// from the colouring's keys, so that this pass reads no joint), in
    /// order, [`LANES`] to a chunk; then the chunks filled from their
    /// joints on the team. Stores lanes still live first.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        &mut self,
        joints: &mut [Joint],
        segments: impl Iterator<Item = (usize, usize)>,
        order: &[u32],
        writes: &[u8],
        candidate: impl Fn(usize) -> bool,
        ctx: &StepContext,
        states: usize,
        team: &Team,
    ) {
        self.store(joints);
        self.starts.clear();
        self.plan.clear();
        self.lane_of.clear();
        self.lane_of.resize(joints.len(), NO_LANE);
        // Which joint each lane takes, colour by colour (each colour's last
        // chunk padded).
        let entries = &mut self.pending;
        entries.clear();
        for (start, end) in segments {
            self.starts.push((entries.len() / LANES) as u32);
            for p in start..end {
                let j = order[p] as usize;
                if candidate(j) {
                    self.lane_of[j] = entries.len() as u32;
                    entries.push((j as u32, writes[p]));
                }
            }
            while !entries.len().is_multiple_of(LANES) {
                entries.push((u32::MAX, 0));
            }
        }
        let count = entries.len() / LANES;
        self.starts.push(count as u32);
        if count == 0 {
            self.lane_of.clear();
            return;
        }
        // Chunks are kept from step to step (each is filled whole).
        if self.chunks.len() < count {
            self.chunks.resize_with(count, WideRevolute::default);
        }
        let (entries, joints, h) = (&*entries, &*joints, ctx.h);
        let fill = |c: usize, chunk: &mut WideRevolute| {
            let first = c * LANES;
            // The next chunk's joints (colour order is not storage order:
            // each is a random read of several lines).
            let next = entries.get(first + LANES..first + 2 * LANES);
            prefetch_joints(joints, next.unwrap_or(&[]).iter().map(|&(j, _)| j));
            WideRevolute::fill(chunk, &entries[first..first + LANES], joints, h);
        };
        let chunks = &mut self.chunks[..count];
        if team.threads() > 1 {
            // Each chunk's item of the state plan (a group per colour, in
            // chunk order) written beside its fill, on the team.
            let colours = self.starts.windows(2).map(|s| (s[1] - s[0]) as usize);
            let (slots, writes) = self.plan.push_groups(colours);
            team.for_each_chunk_triple_mut_beside(
                chunks,
                slots,
                writes,
                16,
                |i, block, slots, writes| {
                    for (k, ((chunk, slots), writes)) in
                        block.iter_mut().zip(slots).zip(writes).enumerate()
                    {
                        fill(16 * i + k, chunk);
                        (*slots, *writes) =
                            (plan_slots(&chunk.state[A], &chunk.state[B]), chunk.moving);
                    }
                },
                || {},
            );
            let verified = self.plan.verify_on(states, team);
            debug_assert!(verified, "a lane colour holds a moving body twice");
        } else {
            team.for_each_chunk_mut(chunks, 16, |i, block| {
                for (k, chunk) in block.iter_mut().enumerate() {
                    fill(16 * i + k, chunk);
                }
            });
        }
    }

    /// One iteration of colour `colour`'s lanes.
    pub(crate) fn solve_colour(
        &mut self,
        colour: usize,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        if !self.is_live() {
            return;
        }
        let (Some(&start), Some(&end)) = (self.starts.get(colour), self.starts.get(colour + 1))
        else {
            return;
        };
        let chunks = &mut self.chunks[start as usize..end as usize];
        if chunks.is_empty() {
            return;
        }
        let rows = LaneContext::of(ctx, use_bias);
        // On the caller: one thread, a short colour, or lanes built for one
        // thread (no plan: a prepare on another team).
        if team.threads() == 1 || chunks.len() < TEAM_CHUNKS || colour >= self.plan.group_count() {
            for chunk in chunks.iter_mut() {
                let mut direct = Direct {
                    index: chunk.state,
                    states: &mut *states,
                };
                chunk.solve(&mut direct, &rows);
            }
            return;
        }
        let per_block = chunks.len().div_ceil(4 * team.threads()).max(4);
        team.for_each_planned(
            &self.plan,
            colour,
            chunks,
            states,
            per_block,
            |chunk, view| chunk.solve(view, &rows),
        );
    }

    /// Sums each lane's angle impulses (`spring + motor + lower − upper`,
    /// as the joint sums its own) and copies its point impulse, for the
    /// warm start that follows.
    ///
    /// On `team` in blocks of [`WARM_BLOCK`] chunks (rain at two threads:
    /// this pass, four times a step, was about 1.7% of the leader's samples
    /// while the other thread waited).
    pub(crate) fn refresh_warm(&mut self, joints: &[Joint], team: &Team) {
        let chunks = &self.chunks[..self.starts.last().map_or(0, |&n| n as usize)];
        // Each chunk's lanes written in place (made as an array and moved
        // into the list, they were copied through a call to `memcpy` whose
        // loads waited on the array's stores: 1.4% of rain's samples).
        let fill = |c: usize, out: &mut [LaneWarm; LANES]| {
            let chunk = &chunks[c];
            // The next chunk's tree joints, whose point impulses are read
            // from their records (random reads).
            if let Some(next) = chunks.get(c + 1) {
                for k in 0..next.len {
                    if next.point_on.lane(k).to_bits() == 0
                        && let Some(j) = joints.get(next.joint[k] as usize)
                    {
                        janus2d_core::hint::prefetch(j);
                    }
                }
            }
            let [spring, motor, lower, upper] = chunk.impulse;
            let angle = (spring + motor + lower - upper).to_array();
            let m = &chunk.masses;
            for (k, out) in out.iter_mut().enumerate() {
                if k >= chunk.len {
                    *out = LaneWarm::default();
                    continue;
                }
                let point = if chunk.point_on.lane(k).to_bits() != 0 {
                    Vec2::new(chunk.point_impulse.x.lane(k), chunk.point_impulse.y.lane(k))
                } else {
                    match joints.get(chunk.joint[k] as usize) {
                        Some(Joint::Revolute(r)) => r.point.impulse,
                        _ => Vec2::ZERO,
                    }
                };
                *out = LaneWarm {
                    angle: angle[k],
                    point,
                    masses: PairMass {
                        a: InvMass {
                            inv_mass: m.inv_mass_a.lane(k),
                            inv_inertia: m.inv_inertia_a.lane(k),
                        },
                        b: InvMass {
                            inv_mass: m.inv_mass_b.lane(k),
                            inv_inertia: m.inv_inertia_b.lane(k),
                        },
                    },
                    frames: (
                        Vec2::new(chunk.frames.0.x.lane(k), chunk.frames.0.y.lane(k)),
                        Vec2::new(chunk.frames.1.x.lane(k), chunk.frames.1.y.lane(k)),
                    ),
                };
            }
        };
        // Fewer chunks than two blocks: one block, which runs on the caller.
        let per_block = if chunks.len() < 2 * WARM_BLOCK {
            chunks.len().max(1)
        } else {
            WARM_BLOCK
        };
        // (Kept entries are overwritten whole.)
        self.warm.resize(chunks.len(), [LaneWarm::default(); LANES]);
        team.for_each_chunk_mut(&mut self.warm, per_block, |b, block| {
            for (j, out) in block.iter_mut().enumerate() {
                fill(b * per_block + j, out);
            }
        });
    }

    /// Lane `lane`'s warm start, as the last [`RevoluteLanes::refresh_warm`]
    /// found it.
    #[inline]
    pub(crate) fn warm(&self, lane: u32) -> LaneWarm {
        let lane = lane as usize;
        self.warm[lane / LANES][lane % LANES]
    }

    /// Ends the lanes without writing their impulses anywhere (lanes of a
    /// colouring that is no longer the joints').
    pub(crate) fn discard(&mut self) {
        self.lane_of.clear();
        self.starts.clear();
    }

    /// Writes the lanes' impulses back into their joints and ends the
    /// lanes (the end of a step, or before new lanes).
    pub(crate) fn store(&mut self, joints: &mut [Joint]) {
        if !self.is_live() {
            return;
        }
        let chunks = self.live_chunks();
        for (c, chunk) in chunks.iter().enumerate() {
            // The next chunk's joints (random reads, as in the fill).
            let next = chunks.get(c + 1).map_or(&[][..], |n| &n.joint[..n.len]);
            prefetch_joints(joints, next.iter().copied());
            for k in 0..chunk.len {
                if let Some(Joint::Revolute(r)) = joints.get_mut(chunk.joint[k] as usize) {
                    r.set_lane_impulses(chunk.impulses(k));
                }
            }
        }
        self.discard();
    }
}

#[cfg(test)]
mod tests {
    use janus2d_core::body::{BodyDef, BodyHandle, BodySet};
    use janus2d_core::constraint::ConstraintBatch;
    use janus2d_core::math::{Real, Vec2};
    use janus2d_core::parallel::Team;
    use janus2d_core::solver::SolverSettings;

    use crate::joint::Joint;
    use crate::joint_colour::JointColours;
    use crate::joint_solver::JointBatch;
    use crate::joint_tree::JointForest;
    use crate::revolute::{RevoluteJoint, RevoluteJointDef};

    /// A ring of `n` bodies joined in a loop (no tree: point rows in the
    /// lanes) and a chain of `n` hanging from a static pin (an anchored
    /// tree: angle rows only in the lanes); every joint with limits, a
    /// spring and a motor, as a ragdoll's. Runs three substeps' stages on
    /// `team` and returns the bits of every velocity and of every joint's
    /// kept impulses after the store.
    fn run(lanes_off: bool, team: &Team, n: usize) -> Vec<u64> {
        let mut set = BodySet::new();
        let ground = set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let body = |set: &mut BodySet, i: usize, y: Real| -> BodyHandle {
            let def = BodyDef::dynamic(Vec2::new(i as Real, y))
                .with_angular_velocity(0.37 * (i % 7) as Real - 1.0);
            set.create(&def).unwrap()
        };
        let ring: Vec<_> = (0..n).map(|i| body(&mut set, i, 0.0)).collect();
        let chain: Vec<_> = (0..n).map(|i| body(&mut set, i, -5.0)).collect();
        let hinge = |a, b, k: usize| {
            let def = RevoluteJointDef::new(a, b, Vec2::new(0.5, 0.02), Vec2::new(-0.5, 0.0))
                .with_limits(-0.3 - 0.01 * (k % 5) as Real, 0.4)
                .with_spring(5.0, 0.5)
                .with_motor(0.0, 0.05 + 0.01 * (k % 3) as Real);
            Joint::from(RevoluteJoint::new(def))
        };
        let mut joints = Vec::new();
        for i in 0..n {
            joints.push(hinge(ring[i], ring[(i + 1) % n], i));
        }
        joints.push(hinge(ground, chain[0], n));
        for i in 1..n {
            joints.push(hinge(chain[i - 1], chain[i], i));
        }
        // Some joints with one row kind only.
        if let Joint::Revolute(r) = &mut joints[3] {
            r.def.enable_limit = false;
            r.def.enable_spring = false;
        }
        if let Joint::Revolute(r) = &mut joints[n + 5] {
            r.def.enable_motor = false;
        }
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::new(0.0, -10.0));
        let (mut forest, mut colours) = (JointForest::default(), JointColours::new());
        colours.lanes_off = lanes_off;
        let mut batch = JointBatch {
            joints: &mut joints,
            forest: &mut forest,
            colours: &mut colours,
        };
        crate::test_support::three_substeps(&mut batch, &ctx, &mut set, team);
        assert_eq!(
            batch.colours.lane_joints() == 2 * n,
            !lanes_off,
            "every joint in a lane"
        );
        batch.store_impulses();
        assert_eq!(batch.colours.lane_joints(), 0, "the store ends the lanes");
        let in_tree = joints.iter().filter(|j| j.base().in_tree).count();
        assert!(
            in_tree >= n && in_tree < 2 * n,
            "the chain is a tree, the ring is not"
        );
        let bits_of = |x: Real| janus2d_core::math::to_f64(x).to_bits();
        let mut bits: Vec<u64> = set
            .states
            .iter()
            .flat_map(|s| [s.v.x, s.v.y, s.w])
            .map(bits_of)
            .collect();
        for j in &joints {
            let Joint::Revolute(r) = j else { continue };
            let p = r.linear_impulse();
            for x in [p.x, p.y, r.motor_impulse(), r.constraint_torque()] {
                bits.push(bits_of(x));
            }
        }
        bits
    }

    /// The lanes give the one-joint solve's states and impulses bit for
    /// bit: angle rows alone (tree joints) and angle and point rows
    /// (a loop), every row kind switched on and off; on the team too.
    #[test]
    fn revolute_lanes_match_the_one_joint_solve_bit_for_bit() {
        let one_at_a_time = run(true, &Team::serial(), 200);
        let lanes = run(false, &Team::serial(), 200);
        assert_eq!(lanes, one_at_a_time);
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            let team =
                janus2d_core::parallel::with_threads(threads, |t| run(false, t, 200)).unwrap();
            assert_eq!(team, one_at_a_time, "{threads} threads");
        }
    }

    /// More lane chunks than two blocks of the warm start's refresh
    /// ([`WARM_BLOCK`]), so that its blocks run on the team: the same bits
    /// as the one-joint solve.
    #[cfg(feature = "parallel")]
    #[test]
    fn revolute_lanes_of_many_blocks_match_on_the_team() {
        let n = super::LANES * super::WARM_BLOCK + 50;
        let one_at_a_time = run(true, &Team::serial(), n);
        for threads in [2, 4] {
            let team = janus2d_core::parallel::with_threads(threads, |t| run(false, t, n)).unwrap();
            assert_eq!(team, one_at_a_time, "{threads} threads");
        }
    }
}
