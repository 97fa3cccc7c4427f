//! Property tests of the contact constraint's reported rows (normal and
//! friction rows of a 2-point manifold between two random bodies): `J` is
//! the derivative of the row's separation along its axis, `K = J M⁻¹ Jᵀ`,
//! and an impulse along `Jᵀ` keeps the total linear momentum and the
//! angular momentum about the origin (the two anchors of a point are the
//! same world point). At least 256 cases each; masses and inertias in
//! [1e-3, 1e3]. Bounds are relative: 1e-3 (f32, step 1e-3) / 1e-8 (f64,
//! step 1e-5) for the central difference, 1e-5 (f32) / 1e-12 (f64) for K
//! and momentum.
// `Real` is f32 or f64 by feature: casts to f64 are the identity in f64.
#![allow(clippy::unnecessary_cast)]

use janus2d_constraints::contact::{ContactConstraint, ContactPointInput};
use janus2d_core::body::{BodyDef, BodyHandle, BodySet};
use janus2d_core::constraint::{Constraint, ConstraintRows};
use janus2d_core::math::{Real, Rot, Vec2, cross};
use janus2d_core::solver::SolverSettings;
use proptest::prelude::*;

#[cfg(not(feature = "f64"))]
const TOL_FD: f64 = 1e-3;
#[cfg(feature = "f64")]
const TOL_FD: f64 = 1e-8;
/// Step of the central difference: truncation O(h²), rounding O(ε/h).
#[cfg(not(feature = "f64"))]
const FD_STEP: Real = 1e-3;
#[cfg(feature = "f64")]
const FD_STEP: Real = 1e-5;
#[cfg(not(feature = "f64"))]
const TOL: f64 = 1e-5;
#[cfg(feature = "f64")]
const TOL: f64 = 1e-12;

#[derive(Clone, Debug)]
struct Case {
    pos: [Vec2; 2],
    angle: [Real; 2],
    mass: [Real; 2],
    inertia: [Real; 2],
    normal_angle: Real,
    points: [Vec2; 2],
    lambda: [Real; 4],
}

fn real(lo: f64, hi: f64) -> impl Strategy<Value = Real> {
    (lo..hi).prop_map(|x| x as Real)
}

fn vec(r: f64) -> impl Strategy<Value = Vec2> {
    (real(-r, r), real(-r, r)).prop_map(|(x, y)| Vec2::new(x, y))
}

fn log_uniform() -> impl Strategy<Value = Real> {
    real(-3.0, 3.0).prop_map(|e| (10.0 as Real).powf(e))
}

fn case() -> impl Strategy<Value = Case> {
    (
        [vec(5.0), vec(5.0)],
        [real(-3.0, 3.0), real(-3.0, 3.0)],
        [log_uniform(), log_uniform()],
        [log_uniform(), log_uniform()],
        real(-3.1, 3.1),
        [vec(2.0), vec(2.0)],
        [
            real(-10.0, 10.0),
            real(-10.0, 10.0),
            real(-10.0, 10.0),
            real(-10.0, 10.0),
        ],
    )
        .prop_map(
            |(pos, angle, mass, inertia, normal_angle, points, lambda)| Case {
                pos,
                angle,
                mass,
                inertia,
                normal_angle,
                points,
                lambda,
            },
        )
}

struct Built {
    set: BodySet,
    bodies: [BodyHandle; 2],
    contact: ContactConstraint,
    normal: Vec2,
    /// Each point's anchor in each body's local frame (relative to its centre).
    local: [[Vec2; 2]; 2],
}

/// Two bodies and a contact whose points lie at `points` (world, relative
/// to the midpoint of the two centres).
fn build(c: &Case) -> Built {
    let mut set = BodySet::new();
    let bodies = [0, 1].map(|i| {
        set.create(
            &BodyDef::dynamic(c.pos[i])
                .with_angle(c.angle[i])
                .with_mass(c.mass[i], c.inertia[i]),
        )
        .unwrap()
    });
    let normal = Rot::from_angle(c.normal_angle).x_axis();
    let mid = 0.5 * (c.pos[0] + c.pos[1]);
    let inputs = c.points.map(|p| {
        let w = mid + p;
        ContactPointInput {
            anchor_a: w - c.pos[0],
            anchor_b: w - c.pos[1],
            separation: 0.0,
            normal_impulse: 0.0,
            tangent_impulse: 0.0,
        }
    });
    let local = [0, 1].map(|k| {
        [0, 1].map(|i| Rot::from_angle(c.angle[i]).inv_rotate(mid + c.points[k] - c.pos[i]))
    });
    let contact = ContactConstraint::new(bodies[0], bodies[1], normal, &inputs, 0.6, 0.0, 0);
    Built {
        set,
        bodies,
        contact,
        normal,
        local,
    }
}

fn rows(b: &Built) -> ConstraintRows {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    b.contact.rows(&ctx, &b.set)
}

/// Separation of point `k` along `axis` for body poses `(x, θ)`.
fn separation(local: &[Vec2; 2], axis: Vec2, x: [Vec2; 2], th: [Real; 2]) -> f64 {
    let pa = x[0] + Rot::from_angle(th[0]).rotate(local[0]);
    let pb = x[1] + Rot::from_angle(th[1]).rotate(local[1]);
    (pb - pa).dot(axis) as f64
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256.max(ProptestConfig::default().cases),
        rng_seed: janus2d_testbed::support::named_seed("contact_properties", ProptestConfig::default().rng_seed),
        ..ProptestConfig::default()
    })]

    #[test]
    fn contact_jacobian_is_the_derivative_of_the_separation(c in case(), v in [vec(1.0), vec(1.0)], w in [real(-1.0, 1.0), real(-1.0, 1.0)]) {
        let b = build(&c);
        let r = rows(&b);
        let tangent = Vec2::new(b.normal.y, -b.normal.x);
        // Rows: normal rows of both points, then friction rows of both.
        for (row, (k, axis)) in [(0usize, b.normal), (1, b.normal), (0, tangent), (1, tangent)].iter().enumerate() {
            let jv: f64 = r.rows[row].jacobian.iter().enumerate().map(|(i, e)| (e.linear.dot(v[i]) + e.angular * w[i]) as f64).sum();
            let h = FD_STEP;
            let at = |s: Real| separation(&b.local[*k], *axis, [c.pos[0] + s * v[0], c.pos[1] + s * v[1]], [c.angle[0] + s * w[0], c.angle[1] + s * w[1]]);
            let fd = (at(h) - at(-h)) / (2.0 * h as f64);
            let scale = 1.0 + (v[0].length() + v[1].length() + 5.0 * (w[0].abs() + w[1].abs())) as f64;
            let bound = TOL_FD * scale;
            prop_assert!((jv - fd).abs() <= bound, "row {row}: J v = {jv}, dC/dt = {fd}");
        }
    }

    #[test]
    fn contact_reported_k_is_j_minv_jt(c in case()) {
        let b = build(&c);
        let r = rows(&b);
        for block in &r.blocks {
            let i = block.first_row;
            let k = block.k[0][0] as f64;
            let jmj = r.jmj(i, i) as f64;
            prop_assert!((k - jmj).abs() <= TOL * jmj.abs().max(1.0), "row {i}: K {k} vs J M⁻¹ Jᵀ {jmj}");
        }
    }

    #[test]
    fn contact_impulse_keeps_linear_and_angular_momentum(c in case()) {
        let b = build(&c);
        let r = rows(&b);
        // Momentum change of an impulse λ along Jᵀ: ΔP = Σ λ J_lin, and the
        // angular momentum about the origin ΔL = Σ λ (x × J_lin + J_ang).
        let centers = [c.pos[0], c.pos[1]];
        let (mut dp, mut dl, mut size) = (Vec2::ZERO, 0.0f64, 0.0f64);
        for (row, lambda) in r.rows.iter().zip(c.lambda) {
            for (i, e) in row.jacobian.iter().enumerate() {
                assert_eq!(e.body, b.bodies[i]);
                let p = lambda * e.linear;
                dp += p;
                let l = (cross(centers[i], p) + lambda * e.angular) as f64;
                dl += l;
                size += l.abs() + p.length() as f64;
            }
        }
        prop_assert!((dp.length() as f64) <= TOL * size.max(1.0), "linear momentum changed by {dp}");
        prop_assert!(dl.abs() <= TOL * 10.0 * size.max(1.0), "angular momentum changed by {dl}");
    }
}
