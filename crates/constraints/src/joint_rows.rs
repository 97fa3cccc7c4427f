//! The Gauss–Seidel rows of every joint kind, and the one solve and warm
//! start that run them.
//!
//! A joint kind supplies its rows and nothing else: at each iteration it
//! reads the two bodies' positions (as deltas since the step's start), forms
//! each row's `C`, `J`, bias terms and impulse bounds, and hands the row to
//! [`RowSolve`], which owns the velocities and does the arithmetic. The warm
//! start works the same way through [`WarmSide`], one body at a time (the
//! colour stage warm-starts body by body). No kind touches a velocity.
//!
//! | row shape                     | rows | J (body a │ body b)                | solve            | warm share            |
//! |-------------------------------|------|------------------------------------|------------------|-----------------------|
//! | [`RowSolve::linear`]          | 1    | `−n, −s_a │ n, s_b` ([`AxisRow`])  | scalar           | [`WarmSide::linear`], [`WarmSide::linear_at_arms`] |
//! | [`RowSolve::angle`]           | 1    | `0, −σ │ 0, σ` (`σ = ±1`)          | scalar           | [`WarmSide::angle`]   |
//! | [`RowSolve::point`]           | 2    | `−I, −perp(r_a) │ I, perp(r_b)`    | 2×2 block        | [`WarmSide::point`]   |
//! | [`RowSolve::point_equality`]  | 2    | the same, bounded at prepare       | 2×2 block        | [`WarmSide::point`]   |
//! | [`RowSolve::linear_angle`]    | 2    | a linear row and the angle row     | 2×2 block        | its two rows' shares  |
//! | [`RowSolve::target`]          | 2    | `0, 0 │ I, perp(r_b)` (b only)     | 2×2 block        | [`WarmSide::target`]  |
//! | [`RowSolve::spin_b`]          | 1    | `0, 0 │ 0, 1` (b only)             | scalar           | [`WarmSide::spin_b`]  |
//!
//! **The update.** Every row takes the soft update of
//! [`soft_impulse`]: `Δλ = −s_m K⁻¹ (Ċ + b) − s_i λ`, with its
//! [`Terms`] (`b`, `s_m`, `s_i`), then accumulates under its [`Bounds`]:
//! a free sum, a clamp of the accumulated impulse (a motor's `±h·max`, a
//! limit's `[0, ∞)`, a force-bounded row), or for a point block a bound on
//! the accumulated impulse's length. The bias terms come from one of the
//! constructors of [`Terms`] (an equality that relaxes without feedback,
//! a spring, a speculative limit, a motor's target speed). Every kept
//! impulse is also held within
//! [`ROW_SPEED_BOUND`](crate::parts::ROW_SPEED_BOUND) of its row's
//! effective mass (bit for bit the plain sum below it), so rows that cannot
//! all hold stop growing instead of overflowing: in every iteration, except
//! the equality point blocks, whose joints hold the kept impulse within it
//! once a step, at prepare ([`RowSolve::point_equality`]).
//!
//! **Order.** A kind calls its rows in the order it wants them solved
//! (Box2D's: spring, motor, limits, then the rigid point), so the sequence
//! of rows is the kind's, the arithmetic of each is here.

use janus2d_core::body::{BodyState, InvMass};
use janus2d_core::math::{Real, Vec2, cross, cross_sv, solve22};
use janus2d_core::softness::Softness;

use crate::lane::{Lane, V2, Velocity};
use crate::parts::{
    AxisRow, MassLanes, PairMass, PointPart, apply_pair, apply_pair_lanes, bounded_sum_lanes,
    cap_lanes, clamp_length, clamp_length_lanes, cross_sv_lanes, effective_mass_lanes, row_bound,
    row_bound_lanes, row_bound_of_k, soft_impulse, solve22_lanes,
};

/// A row's soft terms: the velocity bias `b` (m/s or rad/s), the mass
/// scale `s_m` and the impulse scale `s_i` of [`Softness`]; one row's on
/// [`Real`], [`LANES`](crate::lane::LANES) rows' on the wide lane type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Terms<L = Real> {
    /// Velocity bias added to `Ċ`.
    pub(crate) bias: L,
    /// `s_m`, 1 for a rigid row.
    pub(crate) mass_scale: L,
    /// `s_i`, 0 for a rigid row.
    pub(crate) impulse_scale: L,
}

/// A [`Softness`] lane by lane: its bias rate (1/s), mass scale and
/// impulse scale.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SoftLanes<L> {
    pub(crate) bias_rate: L,
    pub(crate) mass_scale: L,
    pub(crate) impulse_scale: L,
}

impl<L: Lane> SoftLanes<L> {
    /// The same softness in every lane.
    #[inline(always)]
    pub(crate) fn splat(softness: Softness) -> Self {
        SoftLanes {
            bias_rate: L::splat(softness.bias_rate),
            mass_scale: L::splat(softness.mass_scale),
            impulse_scale: L::splat(softness.impulse_scale),
        }
    }
}

impl<L: Lane> Terms<L> {
    /// A rigid row without position feedback, in every lane.
    #[inline(always)]
    pub(crate) fn rigid() -> Self {
        Terms {
            bias: L::splat(0.0),
            mass_scale: L::splat(1.0),
            impulse_scale: L::splat(0.0),
        }
    }

    /// A soft row driving `c` to zero with `softness`, its feedback speed
    /// `bias_rate · c` capped at `±max_bias` (infinite for a spring, whose
    /// feedback is its force).
    #[inline(always)]
    pub(crate) fn soft_lanes(softness: SoftLanes<L>, c: L, max_bias: L) -> Self {
        Terms {
            bias: cap_lanes(softness.bias_rate * c, max_bias),
            mass_scale: softness.mass_scale,
            impulse_scale: softness.impulse_scale,
        }
    }

    /// A one-sided row `c ≥ 0` (a limit): speculative while apart (the gap
    /// closes in one step at most: bias `c / h`, rigid), soft when
    /// violated (only with `use_bias`; rigid in the relax pass), the
    /// violated row's feedback speed capped at `max_bias`.
    #[inline(always)]
    pub(crate) fn limit_lanes(
        c: L,
        softness: SoftLanes<L>,
        inv_h: L,
        use_bias: bool,
        max_bias: L,
    ) -> Self {
        let violated = if use_bias {
            Self::soft_lanes(softness, c, max_bias)
        } else {
            Self::rigid()
        };
        let apart = c.gt(L::splat(0.0));
        Terms {
            bias: L::select(apart, c * inv_h, violated.bias),
            mass_scale: L::select(apart, L::splat(1.0), violated.mass_scale),
            impulse_scale: L::select(apart, L::splat(0.0), violated.impulse_scale),
        }
    }
}

impl Terms {
    /// A rigid row without position feedback.
    pub(crate) const RIGID: Terms = Terms {
        bias: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// A soft row driving `c` to zero with `softness`, its feedback speed
    /// `bias_rate · c` capped at `±max_bias` (`Real::INFINITY` for a
    /// spring, whose feedback is its force).
    #[inline(always)]
    pub(crate) fn soft(softness: Softness, c: Real, max_bias: Real) -> Terms {
        Terms::soft_lanes(SoftLanes::splat(softness), c, max_bias)
    }

    /// An equality row: [`Terms::soft`] with `use_bias`, else rigid (the
    /// relax pass removes the feedback's velocity).
    #[inline(always)]
    pub(crate) fn equality(softness: Softness, c: Real, max_bias: Real, use_bias: bool) -> Terms {
        if use_bias {
            Terms::soft(softness, c, max_bias)
        } else {
            Terms::RIGID
        }
    }

    /// A one-sided row `c ≥ 0` (a limit): [`Terms::limit_lanes`] on one
    /// row.
    #[inline(always)]
    pub(crate) fn limit(
        c: Real,
        softness: Softness,
        inv_h: Real,
        use_bias: bool,
        max_bias: Real,
    ) -> Terms {
        Terms::limit_lanes(c, SoftLanes::splat(softness), inv_h, use_bias, max_bias)
    }

    /// A velocity row driving `Ċ` to `target` (a motor).
    #[inline(always)]
    pub(crate) fn motor(target: Real) -> Terms {
        Terms {
            bias: -target,
            ..Terms::RIGID
        }
    }
}

/// How a row's accumulated impulse `λ` takes a step `Δλ` (one row's on
/// [`Real`], lane by lane on the wide lane type).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Bounds<L = Real> {
    /// `λ += Δλ`, unbounded (an equality, a spring).
    Free,
    /// `λ = clamp(λ + Δλ, lower, upper)` (a motor `±h·max`, a limit
    /// `[0, ∞)`, a force-bounded spring); the applied step is the change.
    Clamp(L, L),
}

impl Bounds {
    /// A limit's bounds, `[0, ∞)`.
    pub(crate) const ONE_SIDED: Bounds = Bounds::Clamp(0.0, Real::INFINITY);

    /// `±max`.
    #[inline(always)]
    pub(crate) fn symmetric(max: Real) -> Bounds {
        Bounds::Clamp(-max, max)
    }
}

impl<L: Lane> Bounds<L> {
    /// Accumulates `lambda` into `impulse`, its size held within `max`
    /// ([`row_bound`]); returns the step to apply.
    #[inline(always)]
    fn accumulate(self, impulse: &mut L, lambda: L, max: L) -> L {
        match self {
            Bounds::Free => bounded_sum_lanes(impulse, lambda, max),
            Bounds::Clamp(lower, upper) => {
                // The bound folded into the clamp: one clamp per row.
                let old = *impulse;
                *impulse = (old + lambda).clamp_to(lower.at_least(-max), upper.at_most(max));
                *impulse - old
            }
        }
    }
}

/// An angle row `σ (ω_b − ω_a)` (`sign = σ = ±1`) of effective mass
/// `mass = 1 / (i_a⁻¹ + i_b⁻¹)` on the angular velocities `w = (ω_a, ω_b)`
/// of bodies of inverse inertias `inv_inertia = (i_a⁻¹, i_b⁻¹)`: the one
/// definition of the row, for one joint ([`RowSolve::angle`]) and for
/// [`LANES`](crate::lane::LANES) revolute joints at once
/// ([`crate::revolute_lanes`]).
#[inline(always)]
pub(crate) fn angle_row<L: Lane>(
    (w_a, w_b): (&mut L, &mut L),
    (inv_inertia_a, inv_inertia_b): (L, L),
    sign: Real,
    mass: L,
    t: Terms<L>,
    bounds: Bounds<L>,
    impulse: &mut L,
) {
    let sign = L::splat(sign);
    let c_dot = sign * (*w_b - *w_a);
    let lambda = soft_impulse(
        mass * t.mass_scale,
        c_dot + t.bias,
        t.impulse_scale,
        *impulse,
    );
    let step = sign * bounds.accumulate(impulse, lambda, row_bound_lanes(mass));
    *w_a -= inv_inertia_a * step;
    *w_b += inv_inertia_b * step;
}

/// One Gauss–Seidel iteration over a joint's rows: the two bodies' states
/// (velocities change, positions are read) and their inverse masses.
pub(crate) struct RowSolve {
    /// Body a.
    pub(crate) sa: BodyState,
    /// Body b.
    pub(crate) sb: BodyState,
    /// The bodies' inverse masses.
    pub(crate) m: PairMass,
}

/// The bound on a point block's accumulated impulse (N·s): `max_length`
/// (`Real::INFINITY` for none) or the row speed bound of its translation
/// `K`, whichever is smaller. Depends on the masses only, so a joint may
/// compute it at prepare.
#[inline(always)]
#[must_use]
pub(crate) fn point_bound(m: &PairMass, max_length: Real) -> Real {
    max_length.min(row_bound_of_k(m.a.inv_mass + m.b.inv_mass))
}

impl RowSolve {
    /// A linear row ([`AxisRow`]) with its terms and bounds.
    #[inline(always)]
    pub(crate) fn linear(&mut self, row: &AxisRow, t: Terms, bounds: Bounds, impulse: &mut Real) {
        let c_dot = row.c_dot(&self.sa, &self.sb);
        let lambda = soft_impulse(
            t.mass_scale * row.mass,
            c_dot + t.bias,
            t.impulse_scale,
            *impulse,
        );
        let step = bounds.accumulate(impulse, lambda, row_bound(row.mass));
        row.apply(&mut self.sa, &mut self.sb, &self.m, step);
    }

    /// An angle row `σ (ω_b − ω_a)` (`sign = σ = ±1`) of effective mass
    /// `mass = 1 / (i_a⁻¹ + i_b⁻¹)`.
    #[inline(always)]
    pub(crate) fn angle(
        &mut self,
        sign: Real,
        mass: Real,
        t: Terms,
        bounds: Bounds,
        impulse: &mut Real,
    ) {
        let inv_inertia = (self.m.a.inv_inertia, self.m.b.inv_inertia);
        angle_row(
            (&mut self.sa.w, &mut self.sb.w),
            inv_inertia,
            sign,
            mass,
            t,
            bounds,
            impulse,
        );
    }

    /// The point block at arms `r_a`, `r_b` (m), its bias a vector;
    /// `bound` bounds the accumulated impulse's length (N·s; from
    /// [`point_bound`], which a joint may keep from its prepare).
    #[inline(always)]
    pub(crate) fn point(
        &mut self,
        r_a: Vec2,
        r_b: Vec2,
        t: PointTerms,
        bound: Real,
        impulse: &mut Vec2,
    ) {
        let lambda = self.point_step(r_a, r_b, t, *impulse);
        let sum = *impulse + lambda;
        let step = if sum.length_squared() <= bound * bound {
            *impulse = sum;
            lambda
        } else {
            let old = *impulse;
            *impulse = clamp_length(sum, bound);
            *impulse - old
        };
        apply_pair(&mut self.sa, &mut self.sb, &self.m, r_a, r_b, step, 0.0);
    }

    /// The point block of an equality (a revolute or weld joint's rigid
    /// point): [`RowSolve::point`] with a free sum. Its kept impulse is held
    /// within [`point_bound`] once a step instead, at the joint's prepare
    /// ([`PointPart::hold_within`]): within a step the sum grows by a few
    /// iterations' steps at most, and across steps it stays bounded, so rows
    /// that cannot all hold still never overflow (the check in the
    /// iteration cost the joint grid measurably: docs/performance.md).
    #[inline(always)]
    pub(crate) fn point_equality(
        &mut self,
        r_a: Vec2,
        r_b: Vec2,
        t: PointTerms,
        impulse: &mut Vec2,
    ) {
        let mut vel = [Velocity::of(&self.sa), Velocity::of(&self.sb)];
        let mut p = V2::from(*impulse);
        point_equality_row(
            &mut vel,
            &MassLanes::of(&self.m),
            (r_a.into(), r_b.into()),
            t,
            &mut p,
        );
        *impulse = p.into();
        vel[0].store(&mut self.sa);
        vel[1].store(&mut self.sb);
    }

    /// The point block's soft step `Δλ` for the kept impulse `impulse`.
    #[inline(always)]
    fn point_step(&self, r_a: Vec2, r_b: Vec2, t: PointTerms, impulse: Vec2) -> Vec2 {
        point_step_lanes(
            &[Velocity::of(&self.sa), Velocity::of(&self.sb)],
            &MassLanes::of(&self.m),
            (r_a.into(), r_b.into()),
            t,
            impulse.into(),
        )
        .into()
    }

    /// A linear row and the angle row solved as one 2×2 block (a
    /// prismatic joint's rigid rows): `K` couples them through the row's
    /// angular entries.
    #[inline(always)]
    pub(crate) fn linear_angle(
        &mut self,
        row: &AxisRow,
        (t_linear, t_angle): (Terms, Terms),
        (linear_impulse, angle_impulse): (&mut Real, &mut Real),
    ) {
        let m = self.m;
        let (i_a, i_b) = (m.a.inv_inertia, m.b.inv_inertia);
        let c_dot_linear = row.c_dot(&self.sa, &self.sb);
        let c_dot_angle = self.sb.w - self.sa.w;
        let k11 = m.a.inv_mass + m.b.inv_mass + i_a * row.s_a * row.s_a + i_b * row.s_b * row.s_b;
        let k12 = i_a * row.s_a + i_b * row.s_b;
        let k22 = i_a + i_b;
        let x = solve22(
            k11,
            k12,
            k22,
            Vec2::new(c_dot_linear + t_linear.bias, c_dot_angle + t_angle.bias),
        );
        let d_linear = soft_impulse(
            t_linear.mass_scale,
            x.x,
            t_linear.impulse_scale,
            *linear_impulse,
        );
        let d_angle = soft_impulse(
            t_angle.mass_scale,
            x.y,
            t_angle.impulse_scale,
            *angle_impulse,
        );
        // A coupled block: one bound for both rows from its smallest
        // eigenvalue, `λ_min ≥ det K / tr K` (an exact solve of a velocity
        // error below the bound speed never reaches it, however badly
        // the block is conditioned).
        let det = k11 * k22 - k12 * k12;
        let bound = if det > 0.0 {
            row_bound_of_k(det / (k11 + k22))
        } else {
            Real::INFINITY
        };
        let d_linear = Bounds::Free.accumulate(linear_impulse, d_linear, bound);
        let d_angle = Bounds::Free.accumulate(angle_impulse, d_angle, bound);
        row.apply(&mut self.sa, &mut self.sb, &m, d_linear);
        self.sa.w -= i_a * d_angle;
        self.sb.w += i_b * d_angle;
    }

    /// A point of body b held toward a target (`c = x_b + r_b − t`, m)
    /// with `softness`, body a untouched; the accumulated impulse's
    /// length bounded by `max_length` (N·s).
    #[inline(always)]
    pub(crate) fn target(
        &mut self,
        r_b: Vec2,
        c: Vec2,
        softness: Softness,
        max_length: Real,
        impulse: &mut Vec2,
    ) {
        let m_b = self.m.b;
        let sb = &mut self.sb;
        let c_dot = sb.v + cross_sv(sb.w, r_b);
        let only_b = PairMass {
            a: InvMass::ZERO,
            b: m_b,
        };
        let (k11, k12, k22) = PointPart::effective_mass(&only_b, Vec2::ZERO, r_b);
        let x = solve22(k11, k12, k22, c_dot + softness.bias_rate * c);
        let lambda = Vec2::new(
            soft_impulse(softness.mass_scale, x.x, softness.impulse_scale, impulse.x),
            soft_impulse(softness.mass_scale, x.y, softness.impulse_scale, impulse.y),
        );
        let old = *impulse;
        let bound = max_length.min(row_bound_of_k(m_b.inv_mass));
        *impulse = clamp_length(old + lambda, bound);
        let p = *impulse - old;
        sb.v += m_b.inv_mass * p;
        sb.w += m_b.inv_inertia * cross(r_b, p);
    }

    /// Body b's spin damped toward `ω_b = 0` with `softness` (no position
    /// term), body a untouched.
    #[inline(always)]
    pub(crate) fn spin_b(&mut self, softness: Softness, impulse: &mut Real) {
        let i_b = self.m.b.inv_inertia;
        if i_b > 0.0 {
            let lambda = soft_impulse(
                softness.mass_scale / i_b,
                self.sb.w,
                softness.impulse_scale,
                *impulse,
            );
            let step = Bounds::Free.accumulate(impulse, lambda, row_bound_of_k(i_b));
            self.sb.w += i_b * step;
        }
    }
}

/// A point block's soft terms: the velocity bias (a vector, m/s), the
/// mass scale `s_m` and the impulse scale `s_i`; one block's on [`Real`],
/// lane by lane on the wide lane type.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PointTerms<L = Real> {
    /// Velocity bias added to `Ċ`.
    pub(crate) bias: V2<L>,
    /// `s_m`.
    pub(crate) mass_scale: L,
    /// `s_i`.
    pub(crate) impulse_scale: L,
}

impl<L: Lane> PointTerms<L> {
    /// An equality block: with `use_bias`, the feedback `bias_rate · c`
    /// with its length capped at `max_length` (m/s), else rigid.
    #[inline(always)]
    pub(crate) fn equality_lanes(
        softness: SoftLanes<L>,
        c: V2<L>,
        max_length: L,
        use_bias: bool,
    ) -> Self {
        if use_bias {
            PointTerms {
                bias: clamp_length_lanes(c.scale(softness.bias_rate), max_length),
                mass_scale: softness.mass_scale,
                impulse_scale: softness.impulse_scale,
            }
        } else {
            PointTerms {
                bias: V2::zero(),
                mass_scale: L::splat(1.0),
                impulse_scale: L::splat(0.0),
            }
        }
    }
}

impl PointTerms {
    /// An equality block ([`PointTerms::equality_lanes`] on one block).
    #[inline(always)]
    pub(crate) fn equality(
        softness: Softness,
        c: Vec2,
        max_length: Real,
        use_bias: bool,
    ) -> PointTerms {
        PointTerms::equality_lanes(SoftLanes::splat(softness), c.into(), max_length, use_bias)
    }

    /// A rigid block whose feedback is `bias_rate · c` (1/s × m), uncapped.
    #[inline(always)]
    pub(crate) fn feedback(bias_rate: Real, c: Vec2) -> PointTerms {
        PointTerms {
            bias: (bias_rate * c).into(),
            mass_scale: 1.0,
            impulse_scale: 0.0,
        }
    }
}

/// The point block's soft step `Δλ` for the kept impulse `impulse`, lane
/// by lane: `Ċ = (v_b + ω_b × r_b) − (v_a + ω_a × r_a)`,
/// `Δλ = −s_m K⁻¹ (Ċ + b) − s_i λ`.
#[inline(always)]
pub(crate) fn point_step_lanes<L: Lane>(
    [a, b]: &[Velocity<L>; 2],
    m: &MassLanes<L>,
    (r_a, r_b): (V2<L>, V2<L>),
    t: PointTerms<L>,
    impulse: V2<L>,
) -> V2<L> {
    let c_dot = b
        .v()
        .add(cross_sv_lanes(b.w, r_b))
        .sub(a.v().add(cross_sv_lanes(a.w, r_a)));
    let (k11, k12, k22) = effective_mass_lanes(m, r_a, r_b);
    let x = solve22_lanes(k11, k12, k22, c_dot.add(t.bias));
    V2::new(
        soft_impulse(t.mass_scale, x.x, t.impulse_scale, impulse.x),
        soft_impulse(t.mass_scale, x.y, t.impulse_scale, impulse.y),
    )
}

/// The point block of an equality, lane by lane: the soft step, added to
/// the kept impulse without a bound (held once a step at prepare, see
/// [`RowSolve::point_equality`]) and applied at the arms. The one
/// definition for one joint and for [`crate::revolute_lanes`].
#[inline(always)]
pub(crate) fn point_equality_row<L: Lane>(
    vel: &mut [Velocity<L>; 2],
    m: &MassLanes<L>,
    arms: (V2<L>, V2<L>),
    t: PointTerms<L>,
    impulse: &mut V2<L>,
) {
    let lambda = point_step_lanes(vel, m, arms, t, *impulse);
    *impulse = impulse.add(lambda);
    apply_pair_lanes(vel, m, arms.0, arms.1, lambda, L::splat(0.0));
}

/// One body's share of a joint's warm start: the kept impulses of the
/// joint's rows applied to that body alone, at its current pose, in the
/// kind's order (`side_b`: body b, else body a).
pub(crate) struct WarmSide<'s> {
    st: &'s mut BodyState,
    m: PairMass,
    side_b: bool,
}

impl<'s> WarmSide<'s> {
    /// Body `st`'s share (`side_b`: body b, else body a) of a joint on
    /// bodies of inverse masses `m`.
    #[inline(always)]
    pub(crate) fn new(st: &'s mut BodyState, m: PairMass, side_b: bool) -> Self {
        WarmSide { st, m, side_b }
    }

    /// A kept angle impulse `λ` (N·m·s, positive on b).
    #[inline(always)]
    pub(crate) fn angle(&mut self, lambda: Real) {
        if self.side_b {
            self.st.w += self.m.b.inv_inertia * lambda;
        } else {
            self.st.w -= self.m.a.inv_inertia * lambda;
        }
    }

    /// A revolute joint's share: the angle rows' summed kept impulse
    /// `angle` (N·m·s), then the point's `p` (N·s) at the body's current
    /// arm from `frames` (the anchors' arms at the step's start). One
    /// joint's warm start and its lane's (`revolute_lanes::LaneWarm`) both
    /// run it.
    #[inline(always)]
    pub(crate) fn hinge(&mut self, angle: Real, frames: (Vec2, Vec2), p: Vec2) {
        self.angle(angle);
        self.point(frames, p);
    }

    /// A kept impulse `λ` along a linear row stored at the last solve.
    #[inline(always)]
    pub(crate) fn linear(&mut self, row: &AxisRow, lambda: Real) {
        row.apply_side(self.st, &self.m, lambda, self.side_b);
    }

    /// A kept impulse `λ` along a direction `n` through the anchors, the
    /// angular entry `r × n` at the body's current arm.
    #[inline(always)]
    pub(crate) fn linear_at_arms(&mut self, n: Vec2, frames: (Vec2, Vec2), lambda: Real) {
        let (frame, s_sign, inv) = if self.side_b {
            (frames.1, 1.0, self.m.b)
        } else {
            (frames.0, -1.0, self.m.a)
        };
        let r = self.st.dq.rotate(frame);
        self.st.v += (s_sign * lambda * inv.inv_mass) * n;
        self.st.w += s_sign * inv.inv_inertia * lambda * cross(r, n);
    }

    /// A kept point impulse `p` (N·s, on b; `−p` on a) at the body's
    /// current arm (`frames`: the anchors from the centres at the step's
    /// start).
    #[inline(always)]
    pub(crate) fn point(&mut self, frames: (Vec2, Vec2), p: Vec2) {
        let st = &mut *self.st;
        if self.side_b {
            let m_b = &self.m.b;
            let r_b = st.dq.rotate(frames.1);
            st.v += m_b.inv_mass * p;
            st.w += m_b.inv_inertia * (cross(r_b, p) + 0.0);
        } else {
            let m_a = &self.m.a;
            let r_a = st.dq.rotate(frames.0);
            st.v -= m_a.inv_mass * p;
            st.w -= m_a.inv_inertia * (cross(r_a, p) + 0.0);
        }
    }

    /// A kept target impulse `p` on body b at its current arm.
    #[inline(always)]
    pub(crate) fn target(&mut self, frame_b: Vec2, p: Vec2) {
        if self.side_b {
            let m_b = &self.m.b;
            let r_b = self.st.dq.rotate(frame_b);
            self.st.v += m_b.inv_mass * p;
            self.st.w += m_b.inv_inertia * cross(r_b, p);
        }
    }

    /// A kept spin impulse `λ` on body b.
    #[inline(always)]
    pub(crate) fn spin_b(&mut self, lambda: Real) {
        if self.side_b {
            self.st.w += self.m.b.inv_inertia * lambda;
        }
    }
}

#[cfg(test)]
mod tests {
    use janus2d_core::body::{BodyDef, BodySet};
    use janus2d_core::constraint::Constraint;
    use janus2d_core::math::{Real, Vec2};
    use janus2d_core::solver::SolverSettings;

    use crate::joint::{Joint, JointDef};
    use crate::{
        DistanceJointDef, MotorJointDef, MouseJointDef, PrismaticJointDef, RevoluteJointDef,
        WeldJointDef, WheelJointDef,
    };

    /// Every kind with every row it has switched on, between two moving
    /// bodies of different masses.
    fn every_kind(set: &mut BodySet) -> Vec<(&'static str, JointDef)> {
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(2.0, 0.5))
            .unwrap();
        let b = set
            .create(&BodyDef::dynamic(Vec2::new(1.0, 0.3)).with_mass(1.0, 0.2))
            .unwrap();
        for (h, v, w) in [
            (a, Vec2::new(0.3, -0.2), 0.4),
            (b, Vec2::new(-0.5, 0.1), -0.7),
        ] {
            let i = set.state_index(h).unwrap() as usize;
            set.states[i].v = v;
            set.states[i].w = w;
        }
        let (pa, pb) = (Vec2::new(0.5, 0.1), Vec2::new(-0.5, -0.2));
        vec![
            (
                "revolute",
                RevoluteJointDef::new(a, b, pa, pb)
                    .with_limits(-0.01, 0.01)
                    .with_motor(0.5, 3.0)
                    .with_spring(4.0, 0.3)
                    .into(),
            ),
            ("weld", WeldJointDef::new(a, b, pa, pb).into()),
            (
                "motor",
                MotorJointDef::new(a, b)
                    .with_offset(Vec2::new(0.2, 0.0), 0.1)
                    .with_max_force(50.0)
                    .with_max_torque(5.0)
                    .into(),
            ),
            (
                "prismatic",
                PrismaticJointDef::new(a, b, pa, pb, Vec2::new(0.6, 0.8))
                    .with_limits(-0.05, 0.05)
                    .with_motor(0.3, 20.0)
                    .with_spring(3.0, 0.5)
                    .into(),
            ),
            (
                "wheel",
                WheelJointDef::new(a, b, pa, pb, Vec2::new(0.0, 1.0))
                    .with_limits(-0.05, 0.05)
                    .with_motor(2.0, 4.0)
                    .with_spring(5.0, 0.7)
                    .into(),
            ),
            (
                "distance",
                DistanceJointDef::new(a, b, pa, pb, 0.8)
                    .with_limits(0.7, 0.9)
                    .with_motor(0.2, 10.0)
                    .into(),
            ),
            (
                "mouse",
                MouseJointDef::new(a, b, Vec2::new(1.2, 0.5), 30.0)
                    .with_angular_damping(2.0, 0.5)
                    .into(),
            ),
        ]
    }

    /// The warm start applies `M⁻¹ Jᵀ λ` of the rows the joint reports
    /// (`Constraint::rows`: Jacobians and kept impulses), for every kind:
    /// the per-body shares the kinds hand to `WarmSide` are the reported
    /// rows' impulses, nothing more and nothing else.
    #[test]
    fn the_warm_start_applies_the_reported_rows_kept_impulses() {
        let mut set = BodySet::new();
        let kinds = every_kind(&mut set);
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        for (name, def) in kinds {
            let mut joint = Joint::new(def);
            joint.prepare(&ctx, &set);
            // Iterations at the step's start (no position change) leave
            // kept impulses on the rows.
            let mut scratch = set.states.clone();
            for _ in 0..4 {
                joint.solve(&ctx, &mut scratch, true);
            }
            let rows = joint.rows(&ctx, &set);
            let kept: Real = rows.rows.iter().map(|r| r.impulse.abs()).sum();
            assert!(kept > 1e-4, "{name}: the iterations kept no impulse");
            let mut expected = set.states.clone();
            for row in &rows.rows {
                for e in &row.jacobian {
                    let i = set.state_index(e.body).unwrap() as usize;
                    expected[i].v += e.inv_mass * row.impulse * e.linear;
                    expected[i].w += e.inv_inertia * row.impulse * e.angular;
                }
            }
            let mut warmed = set.states.clone();
            joint.warm_start(&ctx, &mut warmed);
            let tol = 64.0 * Real::EPSILON * (1.0 + kept);
            for (i, (w, x)) in warmed.iter().zip(&expected).enumerate() {
                let dv = (w.v - x.v).length();
                let dw = (w.w - x.w).abs();
                assert!(
                    dv <= tol && dw <= tol,
                    "{name}: body {i} warm-started to v {:?} w {} where the rows give v {:?} w {}",
                    w.v,
                    w.w,
                    x.v,
                    x.w
                );
            }
        }
    }
}
