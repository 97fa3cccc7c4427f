//! The motor joint: its reported rows (`J` is the derivative of `C` for
//! the two linear rows and the angular row, `K = J M⁻¹ Jᵀ`, impulses along
//! `Jᵀ` and the joint's own solve keep the total linear momentum, and the
//! angular momentum up to `C × P`), a rider holding its offset on a
//! moving platform, a top-down car's drag, and bad input.
//!
//! Property cases as `revolute_properties.rs`: masses and inertias in
//! [1e-3, 1e3], centres of mass off the body origins, frames turned,
//! offsets up to 2 m; bounds are small multiples of `EPS` (the machine
//! epsilon of `Real`) times the size of the terms, except the central
//! difference (`eps/ε + ε²`).

use super::joint_checks::*;
use janus2d::prelude::*;
use janus2d::world::{WorldDef, WorldError};
use janus2d_constraints::{JointDefBase, JointError, JointFrame};
use janus2d_core::body::{BodySet, BodyType};
use janus2d_core::constraint::{Constraint, ConstraintRows};
use janus2d_core::math::wrap_angle;
use janus2d_testbed::support::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// A motor joint case: two bodies, turned frames, offsets, and the
/// angular error kept away from ±π.
#[derive(Clone, Debug)]
struct MotorCase {
    a: BodySpec,
    b: BodySpec,
    frame_a: JointFrame,
    frame_b: JointFrame,
    linear_offset: Vec2,
    angular_offset: Real,
}

struct Built {
    set: BodySet,
    a: BodyHandle,
    b: BodyHandle,
    joint: MotorJoint,
}

impl MotorCase {
    fn def(&self, a: BodyHandle, b: BodyHandle) -> MotorJointDef {
        MotorJointDef::from_base(JointDefBase::with_frames(a, b, self.frame_a, self.frame_b))
            .with_offset(self.linear_offset, self.angular_offset)
            .with_max_force(1e3)
            .with_max_torque(1e3)
            .with_correction_factor(0.7)
    }

    fn build(&self) -> Built {
        let mut set = BodySet::new();
        let a = self.a.create(&mut set);
        let b = self.b.create(&mut set);
        let def = self.def(a, b);
        def.validate().expect("valid joint");
        Built {
            set,
            a,
            b,
            joint: MotorJoint::new(def),
        }
    }

    fn moved(&self, dirs: &[(Vec2, Real); 2], t: Real) -> MotorCase {
        MotorCase {
            a: self.a.moved(dirs[0].0, dirs[0].1, t),
            b: self.b.moved(dirs[1].0, dirs[1].1, t),
            ..self.clone()
        }
    }

    /// The target point on a, in a's body frame.
    fn target_a(&self) -> Vec2 {
        self.frame_a.anchor + Rot::from_angle(self.frame_a.angle).rotate(self.linear_offset)
    }

    /// Size of the numbers whose rounding enters `C`.
    fn c_magnitude(&self) -> f64 {
        d(self.a.center.length() + self.b.center.length())
            + d((self.target_a() - self.a.effective_local_center()).length())
            + d((self.frame_b.anchor - self.b.effective_local_center()).length())
            + std::f64::consts::PI
    }

    /// Moves body b so that its anchor sits on the target (`C_p = 0`).
    fn on_target(mut self) -> MotorCase {
        let target = self.a.transform().apply(self.target_a());
        let anchor = self.b.transform().apply(self.frame_b.anchor);
        self.b.center += target - anchor;
        self
    }
}

const LINEAR_X: usize = 0;
const LINEAR_Y: usize = 1;
const ANGULAR: usize = 2;

fn motor_case(type_a: impl Strategy<Value = BodyType> + Clone) -> impl Strategy<Value = MotorCase> {
    (
        body_spec(type_a),
        body_spec(Just(BodyType::Dynamic)),
        (vec2(2.0), real(-3.0, 3.0)),
        (vec2(2.0), real(-3.0, 3.0)),
        vec2(2.0),
        real(-1.0, 1.0),
        real(-2.0, 2.0),
    )
        .prop_map(
            |(a, mut b, (anchor_a, phi_a), (anchor_b, phi_b), offset, angular_offset, error)| {
                // The angular error θb − θa − (φa − φb) − θoff is `error`,
                // away from ±π.
                b.angle = a.angle + (phi_a - phi_b) + angular_offset + error;
                MotorCase {
                    a,
                    b,
                    frame_a: JointFrame::new(anchor_a, phi_a),
                    frame_b: JointFrame::new(anchor_b, phi_b),
                    linear_offset: offset,
                    angular_offset,
                }
            },
        )
}

#[test]
fn motor_jacobian_is_the_derivative_of_c() {
    let dir = (vec2(1.0), real(-1.0, 1.0));
    check(
        "motor: J = dC/dx for the linear and angular rows",
        (motor_case(any_type()), [dir.clone(), dir]),
        |(case, dirs)| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            prop_assert_eq!(rows.rows.len(), 3);
            let dir_of = |h: BodyHandle| if h == built.a { dirs[0] } else { dirs[1] };
            let plus = case.moved(&dirs, FD_STEP).build();
            let minus = case.moved(&dirs, -FD_STEP).build();
            let rp = plus.joint.rows(&ctx(), &plus.set);
            let rm = minus.joint.rows(&ctx(), &minus.set);
            let bound = fd_tolerance(case.c_magnitude());
            let mut worst = 0.0f64;
            for i in [LINEAR_X, LINEAR_Y, ANGULAR] {
                let diff = if i == ANGULAR {
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
            // The reported C is the joint's own error.
            let e = built.joint.linear_error(&built.set);
            let round = 64.0 * EPS * case.c_magnitude();
            let reported = Vec2::new(rows.rows[LINEAR_X].c, rows.rows[LINEAR_Y].c);
            prop_assert!(d((reported - e).length()) <= round, "C {reported} vs {e}");
            let angle = built.joint.angular_error(&built.set);
            prop_assert!(d(wrap_angle(rows.rows[ANGULAR].c - angle)).abs() <= round);
            Ok(worst)
        },
    );
}

#[test]
fn motor_k_is_j_inverse_mass_j_transpose() {
    check(
        "motor: K = J M⁻¹ Jᵀ for every block",
        motor_case(any_type()),
        |case| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            k_blocks_match(&rows)
        },
    );
}

/// `(px, py, L)` after against before: linear unchanged, `L` changed by
/// `C × P` (the linear impulse `P` acts at the target on a and at b's
/// anchor, `C` apart), within `CONSERVATION_TOL` of the terms' size.
fn momentum_change(
    before: ([f64; 3], f64),
    after: ([f64; 3], f64),
    c: [Real; 2],
    p: [Real; 2],
    applied: f64,
    what: &str,
) -> Result<f64, TestCaseError> {
    let expected = [
        before.0[0],
        before.0[1],
        before.0[2] + d(c[0]) * d(p[1]) - d(c[1]) * d(p[0]),
    ];
    let scale_l = (d(c[0]).abs() + d(c[1]).abs()) * (d(p[0]).abs() + d(p[1]).abs());
    let scale = before.1 + after.1 + scale_l + applied;
    let mut worst = 0.0f64;
    for i in 0..3 {
        let err = (after.0[i] - expected[i]).abs();
        let bound = CONSERVATION_TOL * scale;
        prop_assert!(
            err <= bound,
            "{what}[{i}]: {} -> {} (error {err:.3e} > {bound:.3e})",
            expected[i],
            after.0[i]
        );
        worst = worst.max(err / bound);
    }
    Ok(worst)
}

/// `Σ_i Σ_bodies |λ_i| (|J_lin| (1 + |x|) + |J_ang|)`: the momentum the
/// row impulses carry one by one.
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
fn motor_impulses_keep_total_momentum() {
    let one = (log_uniform(-3.0, 3.0), prop::bool::ANY).prop_map(|(m, s)| if s { m } else { -m });
    check(
        "motor: impulses along Jᵀ and the joint's solve keep p, and L up to C × P",
        (
            motor_case(Just(BodyType::Dynamic)),
            prop::bool::ANY,
            [one.clone(), one.clone(), one],
        ),
        |(case, on_target, lambda)| {
            let case = if on_target { case.on_target() } else { case };
            let mut built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            let c = [rows.rows[LINEAR_X].c, rows.rows[LINEAR_Y].c];
            if on_target {
                let bound = 64.0 * EPS * case.c_magnitude();
                prop_assert!(d(c[0]).hypot(d(c[1])) <= bound, "off target: {c:?}");
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
            // The solve's impulses stay within the drive's bounds.
            let (f, t) = (ctx.h * 1e3, ctx.h * 1e3);
            prop_assert!(
                p.length() <= f * (1.0 + 4.0 * Real::EPSILON),
                "|P| {}",
                p.length()
            );
            prop_assert!(built.joint.angular_impulse().abs() <= t);
            Ok(w1.max(w2))
        },
    );
}

// ----- scenes ----------------------------------------------------------------

const DT: Real = 1.0 / 60.0;

/// A motor joint's errors in a world: b's anchor minus its target (m,
/// world frame) and `θ_b − θ_a − θ_ref − θ_off` (rad), from the bodies'
/// transforms (as `MotorJoint::linear_error` and `angular_error`).
pub(crate) fn motor_error(world: &World, joint: JointHandle) -> (Vec2, Real) {
    let def = &world.joint_of::<MotorJoint>(joint).unwrap().def();
    let (a, b) = (def.base.body_a, def.base.body_b);
    let (ta, tb) = (world.transform(a).unwrap(), world.transform(b).unwrap());
    let linear = tb.apply(def.base.local_frame_b.anchor) - ta.apply(def.target_anchor_a());
    let angular =
        wrap_angle(ta.q.relative_angle(tb.q) - def.base.reference_angle() - def.angular_offset);
    (linear, angular)
}

/// A rider (a 1 m box of 50 kg) held by its feet 0.7 m above a kinematic
/// platform's origin (its centre 1.2 m), upright, by a motor joint of `max_force` 1,500 N and
/// `max_torque` 2,000 N·m (correction factor 0.3, Box2D's default), starting
/// 0.3 m off its target. The torque covers the saturated force at the feet
/// (1,500 N × 0.5 m) plus the weight's (250 N·m at 90°): with 500 N·m the
/// angular drive saturates while the rider is caught, and a saturated
/// drive is bang-bang — the rider rocks ±1.3 rad for 4 s before it holds. The platform swings `x = 3 sin(ω t)` m with a
/// 4 s period (peak acceleration 7.4 m/s²), g = 10 m/s², 4 substeps.
/// The largest force the drive needs is `m (g + a)`-ish,
/// `50 · √(10² + 7.4²) = 622 N` — under `max_force`, so the drive is
/// never saturated once on target. After 2 s of settling, the offset error
/// stays ≤ 1 cm over the rest of the 8 s run (1.5 periods); the force
/// never exceeds `max_force` (the read-back is the last substep's).
#[test]
fn motor_joint_keeps_its_offset_on_a_moving_platform() {
    let mut def = WorldDef::default();
    def.solver.substeps = 4;
    let mut world = World::new(def).unwrap();
    let platform = world.create_body(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
    world
        .create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.1))
        .unwrap();
    let rider = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.3, 1.2)))
        .unwrap();
    world
        .create_shape(rider, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    world
        .set_mass(rider, janus2d::BodyMass::new(50.0, 50.0 / 6.0))
        .unwrap();
    // The rider's feet (0.5 m under its centre) 0.7 m above the
    // platform's origin.
    let offset = Vec2::new(0.0, 0.7);
    let feet = Vec2::new(0.0, -0.5);
    let max_force = 1500.0;
    let base = JointDefBase::with_anchors(platform, rider, Vec2::ZERO, feet);
    let joint = world
        .create_joint(
            &MotorJointDef::from_base(base)
                .with_offset(offset, 0.0)
                .with_max_force(max_force)
                .with_max_torque(2000.0)
                .into(),
        )
        .unwrap();
    let omega = janus2d::base::math::TAU / 4.0;
    // The drive saturates while it catches the platform, which starts at
    // its top speed (4.7 m/s); it is on target within 1.5 s.
    const SETTLE: Real = 2.0;
    let (mut worst_error, mut worst_angle): (Real, Real) = (0.0, 0.0);
    let (mut peak_force, mut settled_force): (Real, Real) = (0.0, 0.0);
    for step in 1..=480 {
        let t = step as Real * DT;
        let target = Transform::new(Vec2::new(3.0 * (omega * t).sin(), 0.0), 0.0);
        world.set_target_transform(platform, target, DT).unwrap();
        world.step(DT).unwrap();
        let force = world.joint_force(joint).unwrap().length();
        peak_force = peak_force.max(force);
        if t > SETTLE {
            settled_force = settled_force.max(force);
            let (linear, angular) = motor_error(&world, joint);
            worst_error = worst_error.max(linear.length());
            worst_angle = worst_angle.max(angular.abs());
        }
    }
    let moved = world.position(platform).unwrap().x;
    println!(
        "rider on a moving platform: worst offset error {:.2e} mm (bound 10 mm), \
         worst angle error {worst_angle:.2e} rad, peak force {peak_force:.0} N while settling, \
         {settled_force:.0} N after (max_force {max_force} N), platform at x = {moved:.2} m",
        1e3 * worst_error
    );
    assert!(worst_error <= 0.01, "offset error {worst_error} m");
    assert!(worst_angle <= 0.01, "angle error {worst_angle} rad");
    assert!(
        peak_force <= max_force * (1.0 + 1e-4),
        "force {peak_force} N above max_force"
    );
    // The drive carried the rider, not a contact.
    assert_eq!(world.body_contacts(rider).unwrap().count(), 0);
}

/// A top-down car (no gravity): a 10 kg body sliding at 5 m/s on a motor
/// joint to the ground with both offsets 0, correction factor 0 and
/// `max_force` 20 N is braked like friction: 2 m/s² until it stops,
/// 3 m/s after 1 s, at rest after 2.5 s, 6.25 m from where it started.
#[test]
fn motor_joint_to_the_ground_is_a_friction_drag() {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    };
    let mut world = World::new(def).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let car = world
        .create_body(
            &BodyDef::dynamic(Vec2::ZERO)
                .with_mass(10.0, 1.0)
                .with_velocity(Vec2::new(5.0, 0.0))
                .with_angular_velocity(2.0),
        )
        .unwrap();
    let joint = world
        .create_joint(
            &MotorJointDef::new(ground, car)
                .with_max_force(20.0)
                .with_max_torque(1.0)
                .with_correction_factor(0.0)
                .into(),
        )
        .unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    let v1 = world.linear_velocity(car).unwrap();
    let w1 = world.angular_velocity(car).unwrap();
    let force = world.joint_force(joint).unwrap();
    for _ in 0..120 {
        world.step(DT).unwrap();
    }
    let v3 = world.linear_velocity(car).unwrap();
    let x3 = world.position(car).unwrap().x;
    println!(
        "drag: v after 1 s {v1:?} m/s (3), ω {w1} rad/s (1), force {force:?} N (−20), \
         v after 3 s {v3:?}, stopped at x = {x3} m (6.25)"
    );
    assert!((v1.x - 3.0).abs() < 1e-3 && v1.y.abs() < 1e-6, "{v1:?}");
    // 1 N·m on 1 kg·m²: 2 rad/s brakes to 1 rad/s in 1 s.
    assert!((w1 - 1.0).abs() < 1e-3, "ω {w1}");
    assert!((force.x + 20.0).abs() < 1e-3, "{force:?}");
    assert!(v3.length() < 1e-4, "still moving: {v3:?}");
    assert!((x3 - 6.25).abs() < 0.05, "stopped at {x3}");
}

#[test]
fn bad_motor_input_is_a_typed_error_and_changes_nothing() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)))
        .unwrap();
    let good = MotorJointDef::new(ground, b).with_max_force(100.0);
    let joint = world.create_joint(&good.clone().into()).unwrap();
    let counts = |w: &World| (w.body_count(), w.joint_count());
    let before = counts(&world);
    let bad: Vec<(MotorJointDef, WorldError)> = vec![
        (
            good.clone().with_offset(Vec2::new(Real::NAN, 0.0), 0.0),
            WorldError::Joint(JointError::NonFinite),
        ),
        (
            good.clone().with_offset(Vec2::ZERO, Real::INFINITY),
            WorldError::Joint(JointError::NonFinite),
        ),
        (
            good.clone().with_max_force(-1.0),
            WorldError::Joint(JointError::Negative),
        ),
        (
            good.clone().with_max_torque(Real::NAN),
            WorldError::Joint(JointError::NonFinite),
        ),
        (
            MotorJointDef::new(b, b),
            WorldError::Joint(JointError::SameBody),
        ),
    ];
    for (def, err) in bad {
        assert_eq!(world.create_joint(&def.clone().into()), Err(err.clone()));
        assert_eq!(world.set_joint_def(joint, def.into()), Err(err));
    }
    for def in [
        good.clone().with_correction_factor(1.5),
        good.clone().with_offset(Vec2::new(1e12, 0.0), 0.0),
    ] {
        assert!(matches!(
            world.create_joint(&def.clone().into()),
            Err(WorldError::OutOfBounds { .. })
        ));
        assert!(matches!(
            world.set_joint_def(joint, def.into()),
            Err(WorldError::OutOfBounds { .. })
        ));
    }
    assert_eq!(counts(&world), before);
    assert_eq!(world.joint(joint).unwrap().def(), good.clone().into());
    // The motor joint has no limits, speed motor or spring: the generic
    // setters refuse it; its force, torque and offsets change through
    // `set_joint_def`.
    let wrong = Err(WorldError::WrongJointKind);
    assert_eq!(world.set_joint_limits(joint, -0.5, 0.5), wrong);
    assert_eq!(world.set_joint_motor_speed(joint, 1.0), wrong);
    assert_eq!(world.set_joint_max_motor_force(joint, 10.0), wrong);
    assert_eq!(world.set_joint_spring(joint, 1.0, 0.5), wrong);
    assert_eq!(world.joint(joint).unwrap().def(), good.clone().into());
    let moved = good.with_offset(Vec2::new(0.5, 0.0), 0.25);
    world.set_joint_def(joint, moved.clone().into()).unwrap();
    assert_eq!(world.joint_of::<MotorJoint>(joint).unwrap().def(), &moved);
    assert_eq!(world.joint(joint).unwrap().kind(), JointKind::Motor);
}
