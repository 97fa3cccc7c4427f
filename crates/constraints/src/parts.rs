//! Reusable constraint parts: point, angle and axis rows' geometry and
//! kept impulses, and the soft update every soft row shares.
//!
//! Joints are assembled from these parts, in the spirit of Jolt's
//! constraint parts. A part holds what its rows keep between iterations
//! (arms at the step's start, effective mass, accumulated impulse); the
//! joints' rows are solved and warm-started by the crate's one row solve
//! (`joint_rows`), which every kind hands its rows to.
//!
//! | part          | rows | C                                         | J (body a │ body b)                          |
//! |---------------|------|-------------------------------------------|----------------------------------------------|
//! | [`PointPart`] | 2    | `(x_b + r_b) − (x_a + r_a)`               | `−I, −perp(r_a) │ I, perp(r_b)`                |
//! | [`AnglePart`] | 1    | `θ_b − θ_a − θ_ref`                       | `0, −1 │ 0, 1`                                |
//! | [`AxisPart`]  | 1    | the kind's (`n · d`, `‖d‖ − L`, …)        | `−n, −s_a │ n, s_b` ([`AxisRow`], built by the kind) |
//!
//! **The soft update.** Every soft row (the joints' rows, the portal rows, the
//! contact rows of [`crate::contact_row`]) takes the step of
//! [`Softness`](janus2d_core::softness::Softness): `Δλ = −s_m K⁻¹ (Ċ + b) − s_i λ`, written once in
//! [`soft_impulse`]. The caller forms the product `s_m K⁻¹ (Ċ + b)` as its
//! row needs it (a 2×2 or 3×3 solve scaled by `s_m`, or a scalar effective
//! mass times `s_m` times the velocity error).
//!
//! Positions during a step are tracked as deltas: `r = dq · r₀`, and the
//! centre offset is `Δc + dp_b − dp_a`, so `C` is refreshed every substep
//! without recomputing transforms.
//!
//! All parts read velocities from the hot [`BodyState`] and inverse masses
//! from the [`PairMass`] their constraint loaded at prepare. A static body
//! is the shared identity state (slot 0), whose zero inverse mass makes
//! every impulse on it vanish without a branch.

use janus2d_core::body::{BodyState, InvMass};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::parallel::PlannedStates;

use crate::lane::{Lane, V2, Velocity};

/// The inverse masses of a constraint's two bodies (a, b), loaded at
/// prepare ([`SolverBody::inv_masses`](janus2d_core::body::SolverBody::inv_masses)):
/// the solve reads them with the constraint's own data, not from the
/// bodies' states.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PairMass {
    /// Body a.
    pub a: InvMass,
    /// Body b.
    pub b: InvMass,
}

impl PairMass {
    /// Two bodies impulses do not move.
    pub const ZERO: PairMass = PairMass {
        a: InvMass::ZERO,
        b: InvMass::ZERO,
    };
}

/// The soft update of one row, `Δλ = −(scale · x) − s_i λ`, with
/// `scale · x = s_m K⁻¹ (Ċ + b)` split as the row forms it: `scale = s_m`,
/// `x = K⁻¹ (Ċ + b)` after a block solve, or `scale = s_m m`,
/// `x = Ċ + b` for a row of effective mass `m = K⁻¹` (module docs).
/// `impulse_scale` is `s_i`, `accumulated` the accumulated impulse `λ`.
/// Lane-generic: one row on [`Real`], or [`LANES`](crate::lane::LANES)
/// rows at once, the same in each lane (the negation by the sign bit,
/// [`Lane::flip_sign`]).
#[inline(always)]
pub fn soft_impulse<L: Lane>(scale: L, x: L, impulse_scale: L, accumulated: L) -> L {
    (scale * x).flip_sign() - impulse_scale * accumulated
}

/// Reads the velocity part of two states.
#[inline(always)]
pub fn load_pair(states: &[BodyState], a: u32, b: u32) -> (BodyState, BodyState) {
    (states[a as usize], states[b as usize])
}

/// Writes back the velocities of two states (positions are untouched).
#[inline(always)]
pub fn store_pair(states: &mut [BodyState], a: u32, b: u32, sa: &BodyState, sb: &BodyState) {
    let ta = &mut states[a as usize];
    ta.v = sa.v;
    ta.w = sa.w;
    let tb = &mut states[b as usize];
    tb.v = sb.v;
    tb.w = sb.w;
}

/// Write mask of a [`PairOf`]: body a's state is written back.
pub(crate) const WRITE_A: u8 = 1;
/// Write mask of a [`PairOf`]: body b's state is written back.
pub(crate) const WRITE_B: u8 = 2;
/// Write mask of a [`PairOf`]: both states are written back.
pub(crate) const BOTH: u8 = WRITE_A | WRITE_B;

/// The two body states of a two-body constraint, as one stage sees them:
/// read both, write back the velocities of those it may write.
pub(crate) trait PairStates {
    /// The states of body a and body b.
    fn load(&self) -> (BodyState, BodyState);
    /// Writes back the velocities (positions are untouched).
    fn store(&mut self, sa: &BodyState, sb: &BodyState);
}

/// A pair in the whole state slice: its two indices and the states it
/// writes back ([`BOTH`]: [`store_pair`]; the colour stages write only the
/// bodies they move, as their parallel form must).
pub(crate) struct PairOf<'s> {
    states: &'s mut [BodyState],
    a: u32,
    b: u32,
    writes: u8,
}

impl<'s> PairOf<'s> {
    #[inline(always)]
    pub(crate) fn new(states: &'s mut [BodyState], a: u32, b: u32, writes: u8) -> Self {
        PairOf {
            states,
            a,
            b,
            writes,
        }
    }
}

impl PairStates for PairOf<'_> {
    #[inline(always)]
    fn load(&self) -> (BodyState, BodyState) {
        load_pair(self.states, self.a, self.b)
    }
    #[inline(always)]
    fn store(&mut self, sa: &BodyState, sb: &BodyState) {
        if self.writes & WRITE_A != 0 {
            let t = &mut self.states[self.a as usize];
            t.v = sa.v;
            t.w = sa.w;
        }
        if self.writes & WRITE_B != 0 {
            let t = &mut self.states[self.b as usize];
            t.v = sb.v;
            t.w = sb.w;
        }
    }
}

/// A pair's slots of a verified [`StatePlan`](janus2d_core::parallel::StatePlan)
/// (slot 0: body a, slot 1: body b), for the stages on the team; the plan's
/// write mask says which velocities go back.
impl PairStates for PlannedStates<'_, 2> {
    #[inline(always)]
    fn load(&self) -> (BodyState, BodyState) {
        (self.get(0), self.get(1))
    }
    #[inline(always)]
    fn store(&mut self, sa: &BodyState, sb: &BodyState) {
        self.set_velocity(0, sa.v, sa.w);
        self.set_velocity(1, sb.v, sb.w);
    }
}

/// Applies a linear impulse `p` at arms `r_a`, `r_b` (equal and opposite)
/// plus an angular impulse `l` (positive on b).
#[inline(always)]
pub fn apply_pair(
    sa: &mut BodyState,
    sb: &mut BodyState,
    m: &PairMass,
    r_a: Vec2,
    r_b: Vec2,
    p: Vec2,
    l: Real,
) {
    let mut vel = [Velocity::of(sa), Velocity::of(sb)];
    apply_pair_lanes(
        &mut vel,
        &MassLanes::of(m),
        r_a.into(),
        r_b.into(),
        p.into(),
        l,
    );
    vel[0].store(sa);
    vel[1].store(sb);
}

/// `a × b`, lane by lane.
#[inline(always)]
pub(crate) fn cross_lanes<L: Lane>(a: V2<L>, b: V2<L>) -> L {
    a.x * b.y - a.y * b.x
}

/// `s × v = s · perp(v)`, lane by lane.
#[inline(always)]
pub(crate) fn cross_sv_lanes<L: Lane>(s: L, v: V2<L>) -> V2<L> {
    V2::new(s.flip_sign() * v.y, s * v.x)
}

/// `v` turned by the rotation `(cos, sin)`, lane by lane.
#[inline(always)]
pub(crate) fn rotate_lanes<L: Lane>((c, s): (L, L), v: V2<L>) -> V2<L> {
    V2::new(c * v.x - s * v.y, s * v.x + c * v.y)
}

/// Two bodies' inverse masses (1/kg) and inertias (1/(kg·m²)) per lane.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct MassLanes<L> {
    pub(crate) inv_mass_a: L,
    pub(crate) inv_inertia_a: L,
    pub(crate) inv_mass_b: L,
    pub(crate) inv_inertia_b: L,
}

impl MassLanes<Real> {
    #[inline(always)]
    pub(crate) fn of(m: &PairMass) -> Self {
        MassLanes {
            inv_mass_a: m.a.inv_mass,
            inv_inertia_a: m.a.inv_inertia,
            inv_mass_b: m.b.inv_mass,
            inv_inertia_b: m.b.inv_inertia,
        }
    }
}

/// [`apply_pair`] lane by lane: the impulse `p` at arms `r_a`, `r_b` (equal
/// and opposite) plus the angular impulse `l` (positive on b).
#[inline(always)]
pub(crate) fn apply_pair_lanes<L: Lane>(
    [a, b]: &mut [Velocity<L>; 2],
    m: &MassLanes<L>,
    r_a: V2<L>,
    r_b: V2<L>,
    p: V2<L>,
    l: L,
) {
    a.set_v(a.v().sub(p.scale(m.inv_mass_a)));
    a.w -= m.inv_inertia_a * (cross_lanes(r_a, p) + l);
    b.set_v(b.v().add(p.scale(m.inv_mass_b)));
    b.w += m.inv_inertia_b * (cross_lanes(r_b, p) + l);
}

/// A point block's `K = J M⁻¹ Jᵀ` as `(k11, k12, k22)`, lane by lane
/// ([`PointPart::effective_mass`]).
#[inline(always)]
pub(crate) fn effective_mass_lanes<L: Lane>(m: &MassLanes<L>, r_a: V2<L>, r_b: V2<L>) -> (L, L, L) {
    let (m_a, m_b) = (m.inv_mass_a, m.inv_mass_b);
    let (i_a, i_b) = (m.inv_inertia_a, m.inv_inertia_b);
    let k11 = m_a + m_b + r_a.y * r_a.y * i_a + r_b.y * r_b.y * i_b;
    let k12 = r_a.y.flip_sign() * r_a.x * i_a - r_b.y * r_b.x * i_b;
    let k22 = m_a + m_b + r_a.x * r_a.x * i_a + r_b.x * r_b.x * i_b;
    (k11, k12, k22)
}

/// `K⁻¹ b` of a 2×2 symmetric `K`, lane by lane; zero where `K` is
/// singular (as [`janus2d_core::math::solve22`], bit for bit).
#[inline(always)]
pub(crate) fn solve22_lanes<L: Lane>(k11: L, k12: L, k22: L, b: V2<L>) -> V2<L> {
    let eps = L::splat(janus2d_core::math::EPSILON);
    let det = k11 * k22 - k12 * k12;
    let singular =
        (eps * (k11.abs() * k22.abs()).at_least(eps)).ge(det.abs()) | det.eq(L::splat(0.0));
    let inv_det = L::splat(1.0) / det;
    let x = V2::new(
        inv_det * (k22 * b.x - k12 * b.y),
        inv_det * (k11 * b.y - k12 * b.x),
    );
    V2::select(singular, V2::zero(), x)
}

/// [`clamp_length`] lane by lane.
#[inline(always)]
pub(crate) fn clamp_length_lanes<L: Lane>(v: V2<L>, max: L) -> V2<L> {
    let len2 = v.x * v.x + v.y * v.y;
    let over = len2.gt(max * max);
    // The root and the division only where some lane is over (on one
    // vector: only when it is).
    if !L::any(over) {
        return v;
    }
    V2::select(over, v.scale(max / len2.sqrt()), v)
}

/// The lever arm, m, at which an angular correction speed is compared
/// with the linear one (1 m): a joint's angle error is fed back at most at
/// [`angular_correction_cap`]`(max)` rad/s where its linear errors are fed
/// back at most at `max` m/s, so a point 1 m from the axis of the
/// correction moves no faster than the linear cap allows.
///
/// Without an angular cap a rigid angle row (a weld's, a prismatic
/// joint's, a violated angle limit) corrects an error of θ rad at
/// `bias_rate · θ`: a prismatic chain whose links start 3 rad from their
/// reference angle turned at hundreds of rad/s in the exact tree solve
/// (500 Hz), and its rails swung the sliding bodies out at over 1,000 m/s.
pub const CORRECTION_ARM: Real = 1.0;

/// The largest angular correction speed, rad/s, that goes with the
/// linear correction cap `max` (m/s): `max / CORRECTION_ARM`.
#[inline(always)]
#[must_use]
pub fn angular_correction_cap(max: Real) -> Real {
    max / CORRECTION_ARM
}

/// `v` limited to `[−max, max]`, and unchanged inside it (bit for bit). Never
/// panics: a NaN `v` stays NaN and a NaN `max` leaves `v` as it is (unlike
/// `Real::clamp`, which panics on NaN bounds).
#[inline(always)]
#[must_use]
pub fn cap(v: Real, max: Real) -> Real {
    cap_lanes(v, max)
}

/// [`cap`] lane by lane: `v` limited to `[−max, max]` (`max > 0`, or
/// infinite), unchanged inside it.
#[inline(always)]
#[must_use]
pub(crate) fn cap_lanes<L: Lane>(v: L, max: L) -> L {
    L::select(v.gt(max), max, L::select(v.lt(-max), -max, v))
}

/// The speed change, m/s (rad/s for an angle row), beyond which no
/// joint row's accumulated impulse grows (Gauss–Seidel and tree rows): a
/// row holds `|λ| ≤ m_eff · ROW_SPEED_BOUND`, with `m_eff` the row's
/// effective mass (for a point block, the bound of its linear part,
/// `1 / (m_a⁻¹ + m_b⁻¹)`; for a coupled block, its smallest eigenvalue's).
///
/// Rows that cannot all hold (a body jointed rigidly to two kinematic
/// bodies moving apart, a crossing copy's joint far from satisfied) make
/// the kept impulses grow step after step, without bound, until they
/// overflow and the body is reset for a non-finite state, again and
/// again. The bound stops that growth at an impulse no consistent row set
/// needs: it changes a body's speed by a thousand times the default speed
/// limit (400 m/s), far beyond what any step of a scene the limits allow
/// asks of one row (the benchmark scenes' states are bit-identical with
/// it). A tree joint is bounded by its own bodies' masses, so a tree whose
/// exact solve needs more (a light link carrying some 5 million times its
/// mass) would be held there.
pub const ROW_SPEED_BOUND: Real = 4.0e5;

/// `m_eff · ROW_SPEED_BOUND`, or no bound for a row no body moves along
/// (`m_eff = 0`).
#[inline(always)]
pub(crate) fn row_bound(mass: Real) -> Real {
    row_bound_lanes(mass)
}

/// [`row_bound`] lane by lane.
#[inline(always)]
pub(crate) fn row_bound_lanes<L: Lane>(mass: L) -> L {
    L::select(
        mass.gt(L::splat(0.0)),
        mass * L::splat(ROW_SPEED_BOUND),
        L::splat(Real::INFINITY),
    )
}

/// `row_bound` of a row whose `K` is `k` (1/kg or 1/(kg·m²)).
#[inline(always)]
pub(crate) fn row_bound_of_k(k: Real) -> Real {
    if k > 0.0 {
        ROW_SPEED_BOUND / k
    } else {
        Real::INFINITY
    }
}

/// `λ += Δλ` with `|λ| ≤ bound` ([`ROW_SPEED_BOUND`]); returns the step
/// to apply. Within the bound (every consistent row) it is the plain sum,
/// bit for bit.
#[inline(always)]
pub(crate) fn bounded_sum(impulse: &mut Real, lambda: Real, bound: Real) -> Real {
    bounded_sum_lanes(impulse, lambda, bound)
}

/// [`bounded_sum`] lane by lane.
#[inline(always)]
pub(crate) fn bounded_sum_lanes<L: Lane>(impulse: &mut L, lambda: L, bound: L) -> L {
    let sum = *impulse + lambda;
    let inside = bound.ge(sum.abs());
    let old = *impulse;
    *impulse = L::select(inside, sum, cap_lanes(sum, bound));
    L::select(inside, lambda, *impulse - old)
}

/// Clamps the length of a bias velocity to `max` (m/s).
#[inline(always)]
pub fn clamp_length(v: Vec2, max: Real) -> Vec2 {
    clamp_length_lanes(v.into(), max).into()
}

/// Two rows that hold an anchor on body a at an anchor on body b.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PointPart {
    /// Anchor on a relative to a's centre at the start of the step (world frame), m.
    pub frame_a: Vec2,
    /// Anchor on b relative to b's centre at the start of the step (world frame), m.
    pub frame_b: Vec2,
    /// `c_b − c_a` at the start of the step, m.
    pub delta_center: Vec2,
    /// Accumulated impulse, N·s.
    pub impulse: Vec2,
}

impl PointPart {
    /// Current arms and separation `C` (m) from the states' deltas.
    #[inline(always)]
    pub fn arms(&self, sa: &BodyState, sb: &BodyState) -> (Vec2, Vec2, Vec2) {
        let (r_a, r_b, c) = arms_lanes(
            (self.frame_a.into(), self.frame_b.into()),
            self.delta_center.into(),
            ((sa.dq.c, sa.dq.s), (sb.dq.c, sb.dq.s)),
            (sa.dp.into(), sb.dp.into()),
        );
        (r_a.into(), r_b.into(), c.into())
    }

    /// Holds the kept impulse's length within `bound` (N·s), unchanged bit
    /// for bit inside it: the once-a-step bound of an equality point block
    /// (`RowSolve::point_equality`), at the joint's prepare.
    #[inline(always)]
    pub fn hold_within(&mut self, bound: Real) {
        self.impulse = clamp_length(self.impulse, bound);
    }

    /// The 2×2 effective mass `K = J M⁻¹ Jᵀ` as `(k11, k12, k22)`.
    #[inline(always)]
    pub fn effective_mass(m: &PairMass, r_a: Vec2, r_b: Vec2) -> (Real, Real, Real) {
        effective_mass_lanes(&MassLanes::of(m), r_a.into(), r_b.into())
    }
}

/// [`PointPart::arms`] lane by lane: the arms at the bodies' rotations
/// since the step began (`dq`) from the frames at its start, and
/// `C = (dp_b − dp_a) + (r_b − r_a) + Δc`.
#[inline(always)]
pub(crate) fn arms_lanes<L: Lane>(
    (frame_a, frame_b): (V2<L>, V2<L>),
    delta_center: V2<L>,
    (dq_a, dq_b): ((L, L), (L, L)),
    (dp_a, dp_b): (V2<L>, V2<L>),
) -> (V2<L>, V2<L>, V2<L>) {
    let r_a = rotate_lanes(dq_a, frame_a);
    let r_b = rotate_lanes(dq_b, frame_b);
    let c = dp_b.sub(dp_a).add(r_b.sub(r_a)).add(delta_center);
    (r_a, r_b, c)
}

/// One row on the relative angle of two bodies (springs, motors, limits).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AnglePart {
    /// Effective mass `1 / (1/I_a + 1/I_b)`, kg·m².
    pub mass: Real,
    /// Accumulated impulse, N·m·s.
    pub impulse: Real,
}

impl AnglePart {
    /// Sets the effective mass from the two bodies' inverse inertias.
    #[inline(always)]
    pub fn prepare(&mut self, m: &PairMass) {
        let k = m.a.inv_inertia + m.b.inv_inertia;
        self.mass = if k > 0.0 { 1.0 / k } else { 0.0 };
    }
}

/// One row along a direction `n` between two bodies, at the current
/// substep: `J = [−n, −s_a │ n, s_b]` (`s_a`, `s_b` the angular entries
/// the kind derives: `(r_a + d) × n` and `r_b × n` for an axis fixed in
/// body a, `r_a × n` and `r_b × n` for a direction along the anchors'
/// line), with its effective mass `1 / K`, `K = J M⁻¹ Jᵀ`. Built by the
/// kind every iteration from the states' deltas; used by [`AxisPart`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AxisRow {
    /// The row's direction (unit), world frame.
    pub n: Vec2,
    /// Angular entry on body a (the row pushes a by `−n` and turns it by `−s_a`).
    pub s_a: Real,
    /// Angular entry on body b.
    pub s_b: Real,
    /// Effective mass `1 / K` (0 when neither body moves along the row), kg.
    pub mass: Real,
}

impl AxisRow {
    /// The row `J = [−n, −s_a │ n, s_b]` with its effective mass.
    #[inline(always)]
    #[must_use]
    pub fn new(m: &PairMass, n: Vec2, s_a: Real, s_b: Real) -> AxisRow {
        let k =
            m.a.inv_mass + m.b.inv_mass + m.a.inv_inertia * s_a * s_a + m.b.inv_inertia * s_b * s_b;
        AxisRow {
            n,
            s_a,
            s_b,
            mass: if k > 0.0 { 1.0 / k } else { 0.0 },
        }
    }

    /// The row's `K = J M⁻¹ Jᵀ` (`1 / mass`, or 0).
    #[inline(always)]
    #[must_use]
    pub fn k(&self) -> Real {
        if self.mass > 0.0 {
            1.0 / self.mass
        } else {
            0.0
        }
    }

    /// `Ċ = J v`.
    #[inline(always)]
    #[must_use]
    pub fn c_dot(&self, sa: &BodyState, sb: &BodyState) -> Real {
        self.n.dot(sb.v - sa.v) + self.s_b * sb.w - self.s_a * sa.w
    }

    /// Applies the impulse `λ Jᵀ`.
    #[inline(always)]
    pub fn apply(&self, sa: &mut BodyState, sb: &mut BodyState, m: &PairMass, lambda: Real) {
        let p = lambda * self.n;
        sa.v -= m.a.inv_mass * p;
        sa.w -= m.a.inv_inertia * lambda * self.s_a;
        sb.v += m.b.inv_mass * p;
        sb.w += m.b.inv_inertia * lambda * self.s_b;
    }

    /// One body's share of `λ Jᵀ` (`side_b`: body b, else body a): the
    /// arithmetic of [`AxisRow::apply`] on that body alone.
    #[inline(always)]
    pub fn apply_side(&self, st: &mut BodyState, m: &PairMass, lambda: Real, side_b: bool) {
        let p = lambda * self.n;
        if side_b {
            st.v += m.b.inv_mass * p;
            st.w += m.b.inv_inertia * lambda * self.s_b;
        } else {
            st.v -= m.a.inv_mass * p;
            st.w -= m.a.inv_inertia * lambda * self.s_a;
        }
    }
}

/// The accumulated impulse of one [`AxisRow`], which the kind builds each
/// iteration (the row's solve is `joint_rows`' `RowSolve::linear`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AxisPart {
    /// Accumulated impulse, N·s.
    pub impulse: Real,
}
