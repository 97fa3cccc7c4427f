//! The portal constraint: a body and its clone held together through a pair
//! of portals carried by two portal bodies.
//!
//! # Derivation
//!
//! Four bodies: the body `1`, its clone `2`, portal body `A` carrying portal
//! 1 and portal body `B` carrying portal 2 (see [`crate::portal_map`] for the
//! map `T`, `Q` and `η`). Each portal body may be static, kinematic or
//! dynamic; `A` and `B` may be the same body. Every `x` is a centre of mass.
//!
//! ```text
//! n1 = R(θA) d1    t1 = perp(n1)    p1 = R(θA)(a1 − c_A)    P1 = xA + p1
//! n2 = R(θB) d2    t2 = perp(n2)    p2 = R(θB)(a2 − c_B)    P2 = xB + p2
//! r1 = x1 − xA     s1 = r1 − p1     r2 = x2 − xB            s2 = r2 − p2
//! ```
//!
//! (`a − c` is the anchor measured from the portal body's local centre.)
//!
//! **Position error (3 rows).**
//!
//! ```text
//! c0 = η (s1 · n1) + (s2 · n2)
//! c1 = η (s1 × n1) + (s2 × n2)
//! c2 = wrap((θ1 − α1) − (θ2 − α2) − π)
//! ```
//!
//! `(c0, −c1)` is `x2 − T(x1)` in the basis `(n2, t2)`.
//!
//! **Velocity error.** With `ṅ1 = ωA perp(n1)`, `ṗ1 = ωA perp(p1)` and the
//! velocities relative to the moving portal frames
//! `w1 = v1 − vA − ωA perp(r1)`, `w2 = v2 − vB − ωB perp(r2)`:
//!
//! ```text
//! c_dot0 = η (n1 · w1) + (n2 · w2)
//! c_dot1 = η (w1 × n1) + (w2 × n2)
//! c_dot2 = (ω1 − ωA) − (ω2 − ωB)
//! ```
//!
//! **Jacobian** `c_dot = J v`, each cell `linear | angular`:
//!
//! ```text
//! row │ body 1       │ clone 2    │ portal body A           │ portal body B
//! 0   │  η n1  │ 0   │  n2  │ 0   │ −η n1 │ −η (r1 × n1)    │ −n2 │ −(r2 × n2)
//! 1   │ −η t1  │ 0   │ −t2  │ 0   │  η t1 │  η (r1 · n1)    │  t2 │  (r2 · n2)
//! 2   │   0    │ +1  │  0   │ −1  │   0   │ −1              │  0  │ +1
//! ```
//!
//! **Impulses.** `λ = (λ0, λ1, λ2)` gives
//!
//! ```text
//! p1 = η (λ0 n1 − λ1 t1)      on body 1, angular +λ2
//! p2 = λ0 n2 − λ1 t2          on the clone, angular −λ2
//! −p1 at x1 on A: angular −(r1 × p1) − λ2
//! −p2 at x2 on B: angular −(r2 × p2) + λ2
//! ```
//!
//! so `p1 + η Qᵀ p2 = 0` (`Qᵀ n2 = −n1`, `Qᵀ t2 = −t1`), `I1 Δω1 + I2 Δω2 = 0`,
//! and with dynamic portal bodies the total linear momentum and the angular
//! momentum about any point are unchanged.
//!
//! **Effective mass** `K = J M⁻¹ Jᵀ`:
//!
//! ```text
//! k       = η² (inv_mass_1 + inv_mass_a) + inv_mass_2 + inv_mass_b
//! k_angle = inv_inertia_1 + inv_inertia_2
//! c_a     = (−η (r1 × n1), η (r1 · n1), −1)
//! c_b     = (−(r2 × n2),     (r2 · n2), +1)
//! K       = diag(k, k, k_angle) + inv_inertia_a c_a c_aᵀ + inv_inertia_b c_b c_bᵀ
//! ```
//!
//! When `A` and `B` are one dynamic body its two columns are added first:
//! the linear part becomes `(η² inv_mass_1 + inv_mass_2) I + inv_mass_ab G`
//! with `G` the Gram matrix of `(−η n1 − n2, η t1 + t2)`, and the angular
//! part `inv_inertia_ab (c_a + c_b)(c_a + c_b)ᵀ`. With static or kinematic
//! portal bodies `K = diag(η²/m1 + 1/m2, η²/m1 + 1/m2, 1/I1 + 1/I2)` for any
//! masses: the solve takes that diagonal fast path, and otherwise solves the
//! 3×3 block with [`solve_block`] (Jacobi-scaled `L D Lᵀ`, never NaN when
//! `K` is singular).
//!
//! **Soft solve.** With the joint [`Softness`] `(β, s_m, s_i)` and the
//! accumulated impulse `λ_acc`:
//!
//! ```text
//! bias = (clamp_length(β (c0, c1), v_max), β c2)      (v_max: joint correction speed)
//! λ    = −s_m K⁻¹ (c_dot + bias) − s_i λ_acc           (use_bias)
//! λ    = −K⁻¹ c_dot                                    (relax)
//! ```
//!
//! **Substeps.** Positions inside a step come from the states' deltas, as in
//! the revolute joint's parts: `r1 = (x1 − xA)₀ + dp1 − dpA`,
//! `p1 = dqA · p1₀`, `n1 = dqA · n1₀`, and the angle row adds the deltas'
//! angles to its start-of-step value:
//! `c2 = wrap(c2₀ + ∠dq1 − ∠dqA − ∠dq2 + ∠dqB)`.
//!
//! ```
//! use janus2d_constraints::portal::{PortalConstraint, PortalConstraintDef};
//! use janus2d_constraints::portal_map::{BodyMotion, Portal, PortalBodyMotion};
//! use janus2d_core::body::{BodyDef, BodySet};
//! use janus2d_core::math::{Vec2, vec_is_finite};
//! use janus2d_core::solver::{SolverSettings, solve_step};
//!
//! let mut bodies = BodySet::new();
//! let wall_a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
//! let wall_b = bodies.create(&BodyDef::fixed(Vec2::new(10.0, 0.0))).unwrap();
//! let portal_a = Portal::new(Vec2::ZERO, Vec2::X, 1.0).unwrap();
//! let portal_b = Portal::new(Vec2::ZERO, Vec2::Y, 1.0).unwrap();
//! let body = bodies
//!     .create(&BodyDef::dynamic(Vec2::new(0.5, 0.0)).with_velocity(Vec2::new(-1.0, 0.0)))
//!     .unwrap();
//! // Place the clone exactly with the portal map.
//! let map = PortalConstraintDef::map_for(&bodies, wall_a, wall_b, &portal_a, &portal_b, 1.0).unwrap();
//! let start = BodyMotion {
//!     center: Vec2::new(0.5, 0.0),
//!     angle: 0.0,
//!     linear_velocity: Vec2::new(-1.0, 0.0),
//!     angular_velocity: 0.0,
//! };
//! let rest = PortalBodyMotion::AT_REST;
//! let c = map.clone_state(&start, &rest, &rest);
//! let clone = bodies
//!     .create(&BodyDef::dynamic(c.center).with_angle(c.angle).with_velocity(c.linear_velocity))
//!     .unwrap();
//! let def = PortalConstraintDef {
//!     body,
//!     clone,
//!     portal_body_a: wall_a,
//!     portal_body_b: wall_b,
//!     portal_a,
//!     portal_b,
//!     eta: 1.0,
//! };
//! let mut portals = vec![PortalConstraint::new(def).unwrap()];
//! let settings = SolverSettings::default();
//! let ctx = settings.context(1.0 / 60.0, Vec2::ZERO);
//! for _ in 0..60 {
//!     solve_step(&settings, &ctx, &mut bodies, &mut [&mut portals]);
//! }
//! // In 1 s the body moved 1 m into portal 1 and the clone 1 m out of portal 2.
//! assert!(portals[0].position_error(&bodies) < 1e-3);
//! assert!((bodies.sim(clone).unwrap().center - Vec2::new(10.0, 0.5)).length() < 1e-2);
//! assert!(vec_is_finite(bodies.linear_velocity(clone).unwrap()));
//! ```

use janus2d_core::body::{BodyHandle, BodySet, BodySim, BodyState, BodyType, InvMass};
use janus2d_core::constraint::{
    Block, BodyJacobian, Constraint, ConstraintBatch, ConstraintRows, Row, SolverMode, StepContext,
};
use janus2d_core::math::{Mat3, PI, Real, Vec2, cross, cross_sv, wrap_angle};
use janus2d_core::softness::Softness;
use smallvec::SmallVec;

use crate::parts::{clamp_length, soft_impulse};
use crate::portal_map::{Portal, PortalError, PortalFrame, PortalMap, validate_eta};

/// Everything needed to create a portal constraint.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalConstraintDef {
    /// Body 1: the body that passes through portal 1.
    pub body: BodyHandle,
    /// Body 2: its clone, emerging from portal 2.
    pub clone: BodyHandle,
    /// Portal body A, carrying portal 1 (static, kinematic or dynamic).
    pub portal_body_a: BodyHandle,
    /// Portal body B, carrying portal 2 (may be the same body as A).
    pub portal_body_b: BodyHandle,
    /// Portal 1 in A's frame.
    pub portal_a: Portal,
    /// Portal 2 in B's frame.
    pub portal_b: Portal,
    /// Scale `η` from portal 1 to portal 2 (dimensionless, > 0; usual 1,
    /// or `w_b / w_a` for matched apertures).
    pub eta: Real,
}

impl PortalConstraintDef {
    /// Checks the definition's own values and that the body and its clone
    /// are distinct from each other and from the portal bodies.
    pub fn validate(&self) -> Result<(), PortalError> {
        self.portal_a.validate()?;
        self.portal_b.validate()?;
        validate_eta(self.eta)?;
        let portal_bodies = [self.portal_body_a, self.portal_body_b];
        if self.body == self.clone
            || portal_bodies.contains(&self.body)
            || portal_bodies.contains(&self.clone)
        {
            return Err(PortalError::SameBody);
        }
        Ok(())
    }

    /// The world-space portal map for portal bodies in `bodies` (their
    /// current transforms). Stale handles read as the identity transform.
    pub fn map_for(
        bodies: &BodySet,
        portal_body_a: BodyHandle,
        portal_body_b: BodyHandle,
        portal_a: &Portal,
        portal_b: &Portal,
        eta: Real,
    ) -> Result<PortalMap, PortalError> {
        portal_a.validate()?;
        portal_b.validate()?;
        let a = bodies.solver_body(portal_body_a).sim;
        let b = bodies.solver_body(portal_body_b).sim;
        PortalMap::new(
            PortalFrame::new(&a.transform, portal_a),
            PortalFrame::new(&b.transform, portal_b),
            eta,
        )
    }
}

/// State indices of the four bodies, in the order body, clone, A, B.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalIndices {
    /// Body 1.
    pub body: u32,
    /// Body 2 (the clone).
    pub clone: u32,
    /// Portal body A.
    pub a: u32,
    /// Portal body B.
    pub b: u32,
}

/// The inverse masses of the four bodies, in the order body, clone, A, B,
/// loaded at prepare (zero for a body on the static identity state).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalMasses {
    /// Body 1.
    pub body: InvMass,
    /// Body 2 (the clone).
    pub clone: InvMass,
    /// Portal body A.
    pub a: InvMass,
    /// Portal body B.
    pub b: InvMass,
}

/// One side of the portal (a body and the portal body it passes through)
/// at the start of the step, in world axes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalRowSide {
    /// Portal anchor relative to the portal body's centre, `p₀`, m.
    pub frame: Vec2,
    /// Portal normal `n₀` (unit).
    pub normal: Vec2,
    /// Body centre relative to the portal body's centre, `r₀ = (x − x_P)₀`, m.
    pub delta_center: Vec2,
}

impl PortalRowSide {
    /// The start-of-step side for `body` passing through `portal` on
    /// `portal_body`.
    pub fn new(body: &BodySim, portal_body: &BodySim, portal: &Portal) -> PortalRowSide {
        let frame = PortalFrame::new(&portal_body.transform, portal);
        PortalRowSide {
            frame: frame.point - portal_body.center,
            normal: frame.normal,
            delta_center: body.center - portal_body.center,
        }
    }

    /// The side's geometry after the bodies moved by their deltas.
    #[inline(always)]
    pub fn current(&self, body: &BodyState, portal_body: &BodyState) -> SideGeometry {
        let r = self.delta_center + (body.dp - portal_body.dp);
        let p = portal_body.dq.rotate(self.frame);
        let n = portal_body.dq.rotate(self.normal);
        SideGeometry {
            r,
            s: r - p,
            n,
            t: n.perp(),
        }
    }
}

/// World geometry of one side at the current positions.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SideGeometry {
    /// `r = x − x_P`: body centre relative to the portal body's centre, m.
    pub r: Vec2,
    /// `s = x − P`: body centre relative to the portal anchor, m.
    pub s: Vec2,
    /// Portal normal `n` (unit).
    pub n: Vec2,
    /// Portal tangent `t = perp(n)`.
    pub t: Vec2,
}

impl SideGeometry {
    /// The geometry of `x` against a world portal frame carried by a portal
    /// body centred at `portal_center`.
    pub fn from_frame(x: Vec2, portal_center: Vec2, frame: &PortalFrame) -> SideGeometry {
        SideGeometry {
            r: x - portal_center,
            s: x - frame.point,
            n: frame.normal,
            t: frame.tangent,
        }
    }
}

/// One body's cell of a Jacobian row: `linear | angular`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JacobianCell {
    /// Multiplies the centre-of-mass velocity.
    pub linear: Vec2,
    /// Multiplies the angular velocity.
    pub angular: Real,
}

/// The geometry of both sides and the scale: everything `J` and `K` need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PortalGeometry {
    /// Side 1 (body 1 against portal 1 on A).
    pub side1: SideGeometry,
    /// Side 2 (the clone against portal 2 on B).
    pub side2: SideGeometry,
    /// Scale `η`.
    pub eta: Real,
}

impl PortalGeometry {
    /// The linear rows' error `(c0, c1)`, m.
    #[inline(always)]
    pub fn linear_error(&self) -> (Real, Real) {
        let (g1, g2, eta) = (&self.side1, &self.side2, self.eta);
        (
            eta * g1.s.dot(g1.n) + g2.s.dot(g2.n),
            eta * cross(g1.s, g1.n) + cross(g2.s, g2.n),
        )
    }

    /// The Jacobian: three rows, columns body 1, clone, A, B.
    pub fn jacobian(&self) -> [[JacobianCell; 4]; 3] {
        let (g1, g2, eta) = (&self.side1, &self.side2, self.eta);
        let (r1, n1, t1) = (g1.r, g1.n, g1.t);
        let (r2, n2, t2) = (g2.r, g2.n, g2.t);
        let cell = |linear, angular| JacobianCell { linear, angular };
        [
            [
                cell(eta * n1, 0.0),
                cell(n2, 0.0),
                cell(-eta * n1, -eta * cross(r1, n1)),
                cell(-n2, -cross(r2, n2)),
            ],
            [
                cell(-eta * t1, 0.0),
                cell(-t2, 0.0),
                cell(eta * t1, eta * r1.dot(n1)),
                cell(t2, r2.dot(n2)),
            ],
            [
                cell(Vec2::ZERO, 1.0),
                cell(Vec2::ZERO, -1.0),
                cell(Vec2::ZERO, -1.0),
                cell(Vec2::ZERO, 1.0),
            ],
        ]
    }

    /// The velocity error `c_dot = J v` from the four states.
    #[inline(always)]
    pub fn c_dot(
        &self,
        s1: &BodyState,
        s2: &BodyState,
        sa: &BodyState,
        sb: &BodyState,
    ) -> [Real; 3] {
        let (g1, g2, eta) = (&self.side1, &self.side2, self.eta);
        let w1 = s1.v - sa.v - cross_sv(sa.w, g1.r);
        let w2 = s2.v - sb.v - cross_sv(sb.w, g2.r);
        [
            eta * g1.n.dot(w1) + g2.n.dot(w2),
            eta * cross(w1, g1.n) + cross(w2, g2.n),
            (s1.w - sa.w) - (s2.w - sb.w),
        ]
    }

    /// The effective mass `K = J M⁻¹ Jᵀ` in closed form. `merged_ab` says
    /// that A and B are the same body (their columns add); the inverse
    /// masses of B are then ignored in favour of A's.
    pub fn effective_mass(&self, m: &PortalMasses, merged_ab: bool) -> Mat3 {
        let (s1, s2, sa, sb) = (&m.body, &m.clone, &m.a, &m.b);
        let (g1, g2, eta) = (&self.side1, &self.side2, self.eta);
        let (r1, n1, t1) = (g1.r, g1.n, g1.t);
        let (r2, n2, t2) = (g2.r, g2.n, g2.t);
        let (inv_mass_1, inv_mass_2) = (s1.inv_mass, s2.inv_mass);
        let k_angle = s1.inv_inertia + s2.inv_inertia;
        let c_a = [-eta * cross(r1, n1), eta * r1.dot(n1), -1.0];
        let c_b = [-cross(r2, n2), r2.dot(n2), 1.0];
        let mut k: Mat3 = [[0.0; 3]; 3];
        if merged_ab {
            let (inv_mass_ab, inv_inertia_ab) = (sa.inv_mass, sa.inv_inertia);
            let lin = [-eta * n1 - n2, eta * t1 + t2];
            let k_lin = eta * eta * inv_mass_1 + inv_mass_2;
            for i in 0..2 {
                for j in 0..2 {
                    k[i][j] = inv_mass_ab * lin[i].dot(lin[j]);
                }
                k[i][i] += k_lin;
            }
            let c_ab = [c_a[0] + c_b[0], c_a[1] + c_b[1], c_a[2] + c_b[2]];
            for i in 0..3 {
                for j in 0..3 {
                    k[i][j] += inv_inertia_ab * c_ab[i] * c_ab[j];
                }
            }
        } else {
            let (inv_mass_a, inv_mass_b) = (sa.inv_mass, sb.inv_mass);
            let (inv_inertia_a, inv_inertia_b) = (sa.inv_inertia, sb.inv_inertia);
            let k_lin = eta * eta * (inv_mass_1 + inv_mass_a) + inv_mass_2 + inv_mass_b;
            for i in 0..3 {
                for j in 0..3 {
                    k[i][j] = inv_inertia_a * c_a[i] * c_a[j] + inv_inertia_b * c_b[i] * c_b[j];
                }
            }
            k[0][0] += k_lin;
            k[1][1] += k_lin;
        }
        k[2][2] += k_angle;
        k
    }

    /// Applies the impulse `lambda` to the four states (in place: static
    /// bodies share slot 0; when A and B share a state its two columns are
    /// added first).
    #[inline(always)]
    pub fn apply(
        &self,
        states: &mut [BodyState],
        ix: PortalIndices,
        m: &PortalMasses,
        lambda: [Real; 3],
    ) {
        let (g1, g2, eta) = (&self.side1, &self.side2, self.eta);
        let p1 = eta * (lambda[0] * g1.n - lambda[1] * g1.t);
        let p2 = lambda[0] * g2.n - lambda[1] * g2.t;
        let l = lambda[2];
        let s = &mut states[ix.body as usize];
        s.v += m.body.inv_mass * p1;
        s.w += m.body.inv_inertia * l;
        let s = &mut states[ix.clone as usize];
        s.v += m.clone.inv_mass * p2;
        s.w -= m.clone.inv_inertia * l;
        if ix.a == ix.b {
            // One portal body carries both portals: its columns add, and
            // the angular impulses ∓λ2 cancel exactly instead of being
            // applied one after the other (which would lose precision).
            let s = &mut states[ix.a as usize];
            s.v -= m.a.inv_mass * (p1 + p2);
            s.w -= m.a.inv_inertia * (cross(g1.r, p1) + cross(g2.r, p2));
        } else {
            let s = &mut states[ix.a as usize];
            s.v -= m.a.inv_mass * p1;
            s.w -= m.a.inv_inertia * (cross(g1.r, p1) + l);
            let s = &mut states[ix.b as usize];
            s.v -= m.b.inv_mass * p2;
            s.w -= m.b.inv_inertia * (cross(g2.r, p2) - l);
        }
    }
}

/// Relative pivot tolerance of the block solve (dimensionless, usual
/// `16 ε`): see [`janus2d_core::math::PIVOT_TOLERANCE`].
pub const PIVOT_TOLERANCE: Real = janus2d_core::math::PIVOT_TOLERANCE;

/// Solves `k x = b` for the symmetric positive semi-definite portal block,
/// never NaN: [`janus2d_core::math::solve33_psd`] (Jacobi-scaled `L D Lᵀ`
/// with a pivot tolerance relative to each row's own diagonal, so a light,
/// turning portal body — a badly conditioned but regular `K`, pivot ratios
/// around `1e-5` in the property tests — stays solvable).
pub fn solve_block(k: &Mat3, b: [Real; 3]) -> [Real; 3] {
    janus2d_core::math::solve33_psd(k, b)
}

/// The portal rows as a part: start-of-step geometry, the scale and the
/// accumulated impulse, with the warm start and solve stages.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalPart {
    /// Side 1 at the start of the step.
    pub side1: PortalRowSide,
    /// Side 2 at the start of the step.
    pub side2: PortalRowSide,
    /// Scale `η`.
    pub eta: Real,
    /// The angle row's error `c2` at the start of the step, rad.
    pub angle: Real,
    /// Accumulated impulse `(λ0, λ1, λ2)`: N·s, N·s, N·m·s.
    pub impulse: [Real; 3],
}

impl PortalPart {
    /// The geometry at the current (sub)step positions.
    #[inline(always)]
    pub fn geometry(&self, states: &[BodyState], ix: PortalIndices) -> PortalGeometry {
        let (s1, s2, sa, sb) = load(states, ix);
        PortalGeometry {
            side1: self.side1.current(&s1, &sa),
            side2: self.side2.current(&s2, &sb),
            eta: self.eta,
        }
    }

    /// The position error `c` at the current (sub)step positions.
    #[inline(always)]
    pub fn error(&self, g: &PortalGeometry, states: &[BodyState], ix: PortalIndices) -> [Real; 3] {
        let (s1, s2, sa, sb) = load(states, ix);
        let (c0, c1) = g.linear_error();
        // (θ1 − θA) − (θ2 − θB) has changed by the deltas' angles.
        let q_1a = sa.dq.inv_mul(s1.dq);
        let q_2b = sb.dq.inv_mul(s2.dq);
        let c2 = wrap_angle(self.angle + q_2b.relative_angle(q_1a));
        [c0, c1, c2]
    }

    /// Applies the accumulated impulse at the current positions.
    #[inline(always)]
    pub fn warm_start(&self, states: &mut [BodyState], ix: PortalIndices, m: &PortalMasses) {
        let g = self.geometry(states, ix);
        g.apply(states, ix, m, self.impulse);
    }

    /// One soft iteration. `fast` selects the diagonal `K` (both portal
    /// bodies static or kinematic); `merged_ab` says A and B are one body.
    #[inline(always)]
    pub fn solve(
        &mut self,
        states: &mut [BodyState],
        ix: PortalIndices,
        m: &PortalMasses,
        softness: Softness,
        max_correction: Real,
        use_bias: bool,
        fast: bool,
        merged_ab: bool,
    ) {
        let g = self.geometry(states, ix);
        let (s1, s2, sa, sb) = load(states, ix);
        let c_dot = g.c_dot(&s1, &s2, &sa, &sb);
        let (bias, mass_scale, impulse_scale) = if use_bias {
            let c = self.error(&g, states, ix);
            let lin = clamp_length(softness.bias_rate * Vec2::new(c[0], c[1]), max_correction);
            (
                [lin.x, lin.y, softness.bias_rate * c[2]],
                softness.mass_scale,
                softness.impulse_scale,
            )
        } else {
            ([0.0; 3], 1.0, 0.0)
        };
        let rhs = [c_dot[0] + bias[0], c_dot[1] + bias[1], c_dot[2] + bias[2]];
        let x = if fast {
            let eta = self.eta;
            let k = eta * eta * m.body.inv_mass + m.clone.inv_mass;
            let k_angle = m.body.inv_inertia + m.clone.inv_inertia;
            let inv = |k: Real| if k > 0.0 { 1.0 / k } else { 0.0 };
            [rhs[0] * inv(k), rhs[1] * inv(k), rhs[2] * inv(k_angle)]
        } else {
            let k = g.effective_mass(m, merged_ab);
            solve_block(&k, rhs)
        };
        let mut lambda = [0.0; 3];
        for i in 0..3 {
            lambda[i] = soft_impulse(mass_scale, x[i], impulse_scale, self.impulse[i]);
            self.impulse[i] += lambda[i];
        }
        g.apply(states, ix, m, lambda);
    }
}

#[inline(always)]
fn load(states: &[BodyState], ix: PortalIndices) -> (BodyState, BodyState, BodyState, BodyState) {
    (
        states[ix.body as usize],
        states[ix.clone as usize],
        states[ix.a as usize],
        states[ix.b as usize],
    )
}

/// A portal constraint in solver form.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalConstraint {
    def: PortalConstraintDef,
    /// False when the constraint is disabled (skipped by the solver).
    pub enabled: bool,
    ix: PortalIndices,
    /// The four bodies' inverse masses, loaded at prepare.
    masses: PortalMasses,
    part: PortalPart,
    /// Both portal bodies have zero inverse mass and inertia: `K` is diagonal.
    fast: bool,
    /// A and B are one moving body: their columns add.
    merged_ab: bool,
}

impl PortalConstraint {
    /// A constraint from a definition (validated here; the portal
    /// directions are normalised).
    pub fn new(def: PortalConstraintDef) -> Result<PortalConstraint, PortalError> {
        def.validate()?;
        let def = PortalConstraintDef {
            portal_a: def.portal_a.normalized(),
            portal_b: def.portal_b.normalized(),
            ..def
        };
        Ok(PortalConstraint {
            part: PortalPart {
                eta: def.eta,
                ..PortalPart::default()
            },
            def,
            enabled: true,
            ix: PortalIndices::default(),
            masses: PortalMasses::default(),
            fast: true,
            merged_ab: false,
        })
    }

    /// The definition (with normalised directions).
    pub fn def(&self) -> &PortalConstraintDef {
        &self.def
    }

    /// The accumulated impulse `(λ0, λ1, λ2)` of the last step: N·s, N·s, N·m·s.
    pub fn impulse(&self) -> [Real; 3] {
        self.part.impulse
    }

    /// Sets the accumulated impulse (applied by the next warm start; used
    /// to carry warm starting over when a constraint is rebuilt).
    pub fn set_impulse(&mut self, impulse: [Real; 3]) {
        self.part.impulse = impulse;
    }

    /// The portal map at the portal bodies' current transforms.
    pub fn map(&self, bodies: &BodySet) -> PortalMap {
        let a = bodies.solver_body(self.def.portal_body_a).sim;
        let b = bodies.solver_body(self.def.portal_body_b).sim;
        PortalMap {
            frame1: PortalFrame::new(&a.transform, &self.def.portal_a),
            frame2: PortalFrame::new(&b.transform, &self.def.portal_b),
            eta: self.def.eta,
        }
    }

    /// The position error `(c0, c1, c2)` at the bodies' current transforms
    /// (m, m, rad).
    pub fn error(&self, bodies: &BodySet) -> [Real; 3] {
        let b1 = bodies.solver_body(self.def.body).sim;
        let b2 = bodies.solver_body(self.def.clone).sim;
        self.map(bodies).error(
            b1.center,
            b1.transform.q.angle(),
            b2.center,
            b2.transform.q.angle(),
        )
    }

    /// `|x2 − T(x1)| = |(c0, c1)|`, m.
    pub fn position_error(&self, bodies: &BodySet) -> Real {
        let c = self.error(bodies);
        Vec2::new(c[0], c[1]).length()
    }

    /// The position error at the current substep positions (the states'
    /// deltas since `prepare`), as the solver sees it.
    pub fn substep_error(&self, states: &[BodyState]) -> [Real; 3] {
        let g = self.part.geometry(states, self.ix);
        self.part.error(&g, states, self.ix)
    }

    /// True when the solve uses the diagonal fast path (both portal bodies
    /// have zero inverse mass and inertia). Set by `prepare`.
    pub fn uses_fast_path(&self) -> bool {
        self.fast
    }

    fn geometry_now(&self, bodies: &BodySet) -> PortalGeometry {
        let map = self.map(bodies);
        let sim = |h| bodies.solver_body(h).sim;
        PortalGeometry {
            side1: SideGeometry::from_frame(
                sim(self.def.body).center,
                sim(self.def.portal_body_a).center,
                &map.frame1,
            ),
            side2: SideGeometry::from_frame(
                sim(self.def.clone).center,
                sim(self.def.portal_body_b).center,
                &map.frame2,
            ),
            eta: self.def.eta,
        }
    }
}

/// Stiffness of the late portal pass, Hz: the substep rate at 60 Hz × 4.
/// Its own constant rather than the direct joints' (those are solved
/// exactly and stand far stiffer springs, 500 Hz; portal rows that stiff in
/// Gauss–Seidel let a blocked straddling body slide off its crossing).
pub const PORTAL_STIFF_HERTZ: Real = 240.0;

impl PortalConstraint {
    /// The late, stiff pass ([`PortalBatch`]): one more solve of the rows
    /// after every other batch in the same sweep, at [`PORTAL_STIFF_HERTZ`]
    /// with the joint damping ratio, so that the contacts pushing a copy
    /// cannot leave the two copies apart.
    pub fn solve_stiff(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        if !self.enabled {
            return;
        }
        let stiff = Softness::new(PORTAL_STIFF_HERTZ, ctx.joint_damping_ratio, ctx.h);
        self.part.solve(
            states,
            self.ix,
            &self.masses,
            stiff,
            ctx.joint_max_correction_speed,
            use_bias,
            self.fast,
            self.merged_ab,
        );
    }
}

/// The portal constraints as the solver's batch.
///
/// | stage | what |
/// |-------|------|
/// | `solve` | the soft solve of every constraint (joint softness), with the other batches |
/// | `solve_late` | in the soft step, a second solve at [`PORTAL_STIFF_HERTZ`], after the contacts: the portal rows have the last word, as the exact joint tree does |
///
/// A contact that presses one copy hard (the portal bodies landing, a
/// stack on a straddling body, a copy pressed into a wall) then leaves
/// `|C|` under a millimetre instead of the soft rows' few millimetres.
#[derive(Debug)]
pub struct PortalBatch<'a> {
    /// The constraints, one per crossing.
    pub constraints: &'a mut Vec<PortalConstraint>,
}

impl ConstraintBatch for PortalBatch<'_> {
    fn count(&self) -> usize {
        self.constraints.count()
    }
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        self.constraints.prepare(ctx, bodies);
    }
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.constraints.warm_start(ctx, states);
    }
    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        ConstraintBatch::solve(self.constraints, ctx, states, use_bias, reverse);
    }
    fn solve_late(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        if ctx.mode != SolverMode::SoftStep {
            return;
        }
        for c in self.constraints.iter_mut() {
            c.solve_stiff(ctx, states, use_bias);
        }
    }
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.constraints.apply_restitution(ctx, states);
    }
    fn store_impulses(&mut self) {
        self.constraints.store_impulses();
    }
}

impl Constraint for PortalConstraint {
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let d = &self.def;
        let b1 = bodies.solver_body(d.body);
        let b2 = bodies.solver_body(d.clone);
        let a = bodies.solver_body(d.portal_body_a);
        let b = bodies.solver_body(d.portal_body_b);
        self.ix = PortalIndices {
            body: b1.state_index,
            clone: b2.state_index,
            a: a.state_index,
            b: b.state_index,
        };
        self.part.side1 = PortalRowSide::new(b1.sim, a.sim, &d.portal_a);
        self.part.side2 = PortalRowSide::new(b2.sim, b.sim, &d.portal_b);
        self.part.eta = d.eta;
        let alpha1 = self.part.side1.normal.y.atan2(self.part.side1.normal.x);
        let alpha2 = self.part.side2.normal.y.atan2(self.part.side2.normal.x);
        let theta1 = b1.sim.transform.q.angle();
        let theta2 = b2.sim.transform.q.angle();
        self.part.angle = wrap_angle((theta1 - alpha1) - (theta2 - alpha2) - PI);
        self.masses = PortalMasses {
            body: b1.inv_masses(),
            clone: b2.inv_masses(),
            a: a.inv_masses(),
            b: b.inv_masses(),
        };
        self.fast = self.masses.a.is_zero() && self.masses.b.is_zero();
        self.merged_ab = a.state_index == b.state_index
            && a.state_index != 0
            && a.sim.body_type == BodyType::Dynamic;
        // A kept impulse that went non-finite (its bodies were reset for
        // it) starts again from zero: warm-started, it would make the same
        // bodies non-finite at every step.
        if !ctx.warm_starting || !self.part.impulse.iter().all(|x| x.is_finite()) {
            self.part.impulse = [0.0; 3];
        }
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        self.part.warm_start(states, self.ix, &self.masses);
    }

    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        self.part.solve(
            states,
            self.ix,
            &self.masses,
            ctx.joint_softness,
            ctx.joint_max_correction_speed,
            use_bias,
            self.fast,
            self.merged_ab,
        );
    }

    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows {
        let d = &self.def;
        let handles = [d.body, d.clone, d.portal_body_a, d.portal_body_b];
        let masses = handles.map(|h| bodies.solver_body(h).inv_masses());
        let g = self.geometry_now(bodies);
        let jacobian = g.jacobian();
        let c = self.error(bodies);
        let mut out = ConstraintRows::default();
        for (i, cells) in jacobian.iter().enumerate() {
            let mut entries: SmallVec<[BodyJacobian; 4]> = SmallVec::new();
            for (k, cell) in cells.iter().enumerate() {
                if let Some(e) = entries.iter_mut().find(|e| e.body == handles[k]) {
                    e.linear += cell.linear;
                    e.angular += cell.angular;
                } else {
                    entries.push(BodyJacobian {
                        body: handles[k],
                        linear: cell.linear,
                        angular: cell.angular,
                        inv_mass: masses[k].inv_mass,
                        inv_inertia: masses[k].inv_inertia,
                    });
                }
            }
            out.rows.push(Row {
                jacobian: entries,
                c: c[i],
                softness: ctx.joint_softness,
                lower: Real::NEG_INFINITY,
                upper: Real::INFINITY,
                impulse: self.part.impulse[i],
            });
        }
        let merged_ab = d.portal_body_a == d.portal_body_b;
        let [body, clone, a, b] = masses;
        let k = g.effective_mass(&PortalMasses { body, clone, a, b }, merged_ab);
        out.blocks.push(Block {
            first_row: 0,
            len: 3,
            k,
        });
        out
    }

    fn is_enabled(&self) -> bool {
        self.enabled
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use janus2d_core::body::BodyDef;

    fn setup(portal_type: BodyType) -> (BodySet, PortalConstraint) {
        let mut bodies = BodySet::new();
        let mk = |p: Vec2| match portal_type {
            BodyType::Static => BodyDef::fixed(p),
            BodyType::Kinematic => BodyDef::kinematic(p),
            BodyType::Dynamic => BodyDef::dynamic(p).with_mass(3.0, 0.7),
        };
        let a = bodies.create(&mk(Vec2::new(0.0, 0.0))).unwrap();
        let b = bodies.create(&mk(Vec2::new(5.0, 1.0))).unwrap();
        let body = bodies
            .create(&BodyDef::dynamic(Vec2::new(0.3, 0.2)).with_mass(2.0, 0.5))
            .unwrap();
        let clone = bodies
            .create(&BodyDef::dynamic(Vec2::new(5.2, 1.9)).with_mass(8.0, 4.0))
            .unwrap();
        let def = PortalConstraintDef {
            body,
            clone,
            portal_body_a: a,
            portal_body_b: b,
            portal_a: Portal::new(Vec2::new(0.1, 0.0), Vec2::X, 1.0).unwrap(),
            portal_b: Portal::new(Vec2::new(0.0, 0.2), Vec2::new(1.0, 1.0), 2.0).unwrap(),
            eta: 2.0,
        };
        (bodies, PortalConstraint::new(def).unwrap())
    }

    #[test]
    fn validation_rejects_shared_bodies_and_bad_scale() {
        let (_, c) = setup(BodyType::Static);
        let mut def = c.def().clone();
        def.clone = def.body;
        assert_eq!(def.validate(), Err(PortalError::SameBody));
        let mut def = c.def().clone();
        def.portal_body_b = def.clone;
        assert_eq!(def.validate(), Err(PortalError::SameBody));
        let mut def = c.def().clone();
        def.eta = 0.0;
        assert_eq!(
            PortalConstraint::new(def).unwrap_err(),
            PortalError::InvalidScale
        );
    }

    #[test]
    fn reported_k_matches_jacobian_for_every_portal_body_type() {
        for t in [BodyType::Static, BodyType::Kinematic, BodyType::Dynamic] {
            let (bodies, c) = setup(t);
            let ctx =
                janus2d_core::solver::SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
            let rows = c.rows(&ctx, &bodies);
            let k = rows.blocks[0].k;
            for i in 0..3 {
                for j in 0..3 {
                    let jmj = rows.jmj(i, j);
                    assert!(
                        (k[i][j] - jmj).abs() <= 1e-5 * (1.0 + jmj.abs()),
                        "{t:?} K[{i}][{j}] = {} vs {jmj}",
                        k[i][j]
                    );
                }
            }
        }
    }

    #[test]
    fn singular_block_is_finite() {
        let k: Mat3 = [[1.0, 1.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]];
        let x = solve_block(&k, [1.0, 2.0, 3.0]);
        assert!(x.iter().all(|v| v.is_finite()));
        let x = solve_block(&[[0.0; 3]; 3], [1.0, 2.0, 3.0]);
        assert_eq!(x, [0.0; 3]);
    }
}
