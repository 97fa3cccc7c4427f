//! Property tests of the revolute joint's reported rows: `J` is the
//! derivative of `C` (point, spring and limit rows), `K = J M⁻¹ Jᵀ`, and
//! impulses along `Jᵀ` (and the joint's own solve) keep the total linear
//! momentum, and the angular momentum about the origin when the anchors
//! coincide. (With the anchors apart, `C ≠ 0`, the point impulse `P` acts
//! at two different points and the angular momentum changes by exactly
//! `C × P`; that is checked too.)
//!
//! At least 256 cases each (`PROPTEST_CASES` raises it); masses and
//! inertias in [1e-3, 1e3], centres of mass off the body origins. Bounds
//! are small multiples of the machine epsilon `EPS` of `Real` times the
//! size of the terms, except the central difference (`eps/ε + ε²`).
//! `JANUS2D_REPORT=1` prints the worst error as a fraction of its bound.

use super::joint_checks::*;
use janus2d_constraints::revolute::{RevoluteJoint, RevoluteJointDef};
use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::constraint::{Constraint, ConstraintRows};
use janus2d_core::math::{Real, Vec2, wrap_angle};
use janus2d_testbed::support::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// A joint case: two bodies, local anchors, a reference angle and limits
/// around the current joint angle, with spring and motor on (all rows).
#[derive(Clone, Debug)]
struct JointCase {
    a: BodySpec,
    b: BodySpec,
    anchor_a: Vec2,
    anchor_b: Vec2,
    reference: Real,
    lower: Real,
    upper: Real,
}

struct BuiltJoint {
    set: BodySet,
    a: BodyHandle,
    b: BodyHandle,
    joint: RevoluteJoint,
}

impl JointCase {
    fn build(&self) -> BuiltJoint {
        let mut set = BodySet::new();
        let a = self.a.create(&mut set);
        let b = self.b.create(&mut set);
        let def = RevoluteJointDef::new(a, b, self.anchor_a, self.anchor_b)
            .with_limits(self.lower, self.upper)
            .with_motor(0.5, 10.0)
            .with_spring(5.0, 0.7)
            .with_reference_angle(self.reference);
        def.validate().expect("valid joint");
        BuiltJoint {
            set,
            a,
            b,
            joint: RevoluteJoint::new(def),
        }
    }

    fn moved(&self, dirs: &[(Vec2, Real); 2], t: Real) -> JointCase {
        JointCase {
            a: self.a.moved(dirs[0].0, dirs[0].1, t),
            b: self.b.moved(dirs[1].0, dirs[1].1, t),
            ..self.clone()
        }
    }

    /// Size of the numbers whose rounding enters `C`.
    fn c_magnitude(&self) -> f64 {
        d(self.a.center.length() + self.b.center.length())
            + d((self.anchor_a - self.a.effective_local_center()).length())
            + d((self.anchor_b - self.b.effective_local_center()).length())
            + std::f64::consts::PI
    }
}

/// Row order of the joint with everything enabled.
const POINT_X: usize = 0;
const POINT_Y: usize = 1;
const SPRING: usize = 2;
const MOTOR: usize = 3;
const LOWER: usize = 4;
const UPPER: usize = 5;

fn joint_case(type_a: impl Strategy<Value = BodyType> + Clone) -> impl Strategy<Value = JointCase> {
    (
        body_spec(type_a),
        body_spec(Just(BodyType::Dynamic)),
        vec2(2.0),
        vec2(2.0),
        real(-2.0, 2.0),
        real(-2.0, 2.0),
        real(0.05, 1.0),
        real(0.05, 1.0),
    )
        .prop_map(
            |(a, mut b, anchor_a, anchor_b, angle, reference, below, above)| {
                // The joint angle θb − θa − ref is `angle`, away from ±π.
                b.angle = a.angle + reference + angle;
                JointCase {
                    a,
                    b,
                    anchor_a,
                    anchor_b,
                    reference,
                    lower: angle - below,
                    upper: angle + above,
                }
            },
        )
}

#[test]
fn revolute_jacobian_is_the_derivative_of_c() {
    let dir = (vec2(1.0), real(-1.0, 1.0));
    check(
        "revolute: J = dC/dx for point, spring and limit rows",
        (joint_case(any_type()), [dir.clone(), dir]),
        |(case, dirs)| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            prop_assert_eq!(rows.rows.len(), 6);
            let dir_of = |h: BodyHandle| if h == built.a { dirs[0] } else { dirs[1] };
            let plus = case.moved(&dirs, FD_STEP).build();
            let minus = case.moved(&dirs, -FD_STEP).build();
            let rp = plus.joint.rows(&ctx(), &plus.set);
            let rm = minus.joint.rows(&ctx(), &minus.set);
            let bound = fd_tolerance(case.c_magnitude());
            let mut worst = 0.0f64;
            for i in [POINT_X, POINT_Y, SPRING, LOWER, UPPER] {
                let diff = if i >= SPRING {
                    wrap_angle(rp.rows[i].c - rm.rows[i].c)
                } else {
                    rp.rows[i].c - rm.rows[i].c
                };
                let fd = d(diff) / (2.0 * d(FD_STEP));
                let jv = d(rows.row_velocity(i, dir_of));
                let err = (fd - jv).abs();
                prop_assert!(
                    err <= bound,
                    "row {i}: FD {fd} vs J δ {jv} (error {err:.3e} > {bound:.3e})"
                );
                worst = worst.max(err / bound);
            }
            // The motor row is a velocity row: no position error.
            prop_assert_eq!(rows.rows[MOTOR].c, 0.0);
            Ok(worst)
        },
    );
}

#[test]
fn revolute_k_is_j_inverse_mass_j_transpose() {
    check(
        "revolute: K = J M⁻¹ Jᵀ for every block",
        joint_case(any_type()),
        |case| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            k_blocks_match(&rows)
        },
    );
}

fn conserved(
    before: ([f64; 3], f64),
    after: ([f64; 3], f64),
    what: &str,
) -> Result<f64, TestCaseError> {
    let scale = before.1 + after.1;
    let mut worst = 0.0f64;
    for i in 0..3 {
        let err = (after.0[i] - before.0[i]).abs();
        let bound = CONSERVATION_TOL * scale;
        prop_assert!(
            err <= bound,
            "{what}[{i}]: {} -> {} (error {err:.3e} > {bound:.3e})",
            before.0[i],
            after.0[i]
        );
        worst = worst.max(err / bound);
    }
    Ok(worst)
}

impl JointCase {
    /// Moves body b so that the two anchors coincide (`C = 0`).
    fn with_coincident_anchors(mut self) -> JointCase {
        let anchor = self.a.transform().apply(self.anchor_a);
        let tb = self.b.transform();
        let offset = anchor - tb.apply(self.anchor_b);
        self.b.center += offset;
        self
    }
}

/// `(px, py, L)` changes: linear unchanged; `L` changes by `C × P`.
fn momentum_change(
    before: ([f64; 3], f64),
    after: ([f64; 3], f64),
    c: [Real; 2],
    p: [Real; 2],
    applied: f64,
    what: &str,
) -> Result<f64, TestCaseError> {
    let expected_l = d(c[0]) * d(p[1]) - d(c[1]) * d(p[0]);
    let shifted = (
        [before.0[0], before.0[1], before.0[2] + expected_l],
        before.1,
    );
    // The prediction's own round-off is relative to |C| |P|.
    let scale_l = (d(c[0]).abs() + d(c[1]).abs()) * (d(p[0]).abs() + d(p[1]).abs());
    conserved((shifted.0, shifted.1 + scale_l + applied), after, what)
}

/// Size of the momentum the row impulses carry one by one,
/// `Σ_i Σ_bodies |λ_i| (|J_lin| (1 + |x|) + |J_ang|)`: rows are applied in
/// turn, so large impulses that cancel between rows (a motor against a
/// limit) leave round-off of their own size.
fn applied_scale(rows: &ConstraintRows, lambda: &[Real], set: &BodySet) -> f64 {
    let mut scale = 0.0;
    for (row, &l) in rows.rows.iter().zip(lambda) {
        for e in &row.jacobian {
            let x = d(set.sim(e.body).unwrap().center.length());
            scale += d(l.abs()) * (d(e.linear.length()) * (1.0 + x) + d(e.angular.abs()));
        }
    }
    scale
}

#[test]
fn revolute_impulses_keep_total_momentum() {
    let one = (log_uniform(-3.0, 3.0), prop::bool::ANY).prop_map(|(m, s)| if s { m } else { -m });
    check(
        "revolute: impulses along Jᵀ and the joint's solve keep p, and L up to C × P",
        (
            joint_case(Just(BodyType::Dynamic)),
            prop::bool::ANY,
            [
                one.clone(),
                one.clone(),
                one.clone(),
                one.clone(),
                one.clone(),
                one,
            ],
        ),
        |(case, coincide, lambda)| {
            let case = if coincide {
                case.with_coincident_anchors()
            } else {
                case
            };
            // Impulses along the reported Jacobian: Δv = M⁻¹ Jᵀ λ.
            let mut built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            let c = [rows.rows[POINT_X].c, rows.rows[POINT_Y].c];
            if coincide {
                let bound = 64.0 * EPS * case.c_magnitude();
                prop_assert!(d(c[0]).hypot(d(c[1])) <= bound, "anchors apart: {c:?}");
            }
            let h = [built.a, built.b];
            let before = total_momentum(&built.set, &h);
            for (i, row) in rows.rows.iter().enumerate() {
                for e in &row.jacobian {
                    let st = built.set.state_mut(e.body).unwrap();
                    st.v += e.inv_mass * lambda[i] * e.linear;
                    st.w += e.inv_inertia * lambda[i] * e.angular;
                }
            }
            let after = total_momentum(&built.set, &h);
            let applied = applied_scale(&rows, &lambda, &built.set);
            let w1 = momentum_change(
                before,
                after,
                c,
                [lambda[0], lambda[1]],
                applied,
                "Jᵀ λ: (px, py, L)",
            )?;
            // The joint's own impulses: one solve from the random velocities.
            let mut built = case.build();
            let h = [built.a, built.b];
            let before = total_momentum(&built.set, &h);
            let ctx = ctx();
            built.joint.prepare(&ctx, &built.set);
            built.joint.solve(&ctx, &mut built.set.states, true);
            let after = total_momentum(&built.set, &h);
            let p = built.joint.linear_impulse();
            let solved = built.joint.rows(&ctx, &built.set);
            let impulses: Vec<Real> = solved.rows.iter().map(|r| r.impulse).collect();
            let applied = applied_scale(&solved, &impulses, &built.set);
            let w2 = momentum_change(before, after, c, [p.x, p.y], applied, "solve: (px, py, L)")?;
            Ok(w1.max(w2))
        },
    );
}
