//! The prismatic joint: property tests of its reported rows (`J` is the
//! derivative of `C` for the perpendicular, angle, spring and limit rows;
//! `K = J M⁻¹ Jᵀ` for every block, the perpendicular–angle 2×2 block
//! included; impulses along `Jᵀ` and the joint's own solve keep the total
//! linear and angular momentum), the elevator scene of the issue, and bad
//! input. The property harness is shared with the wheel joint
//! (`wheel.rs`): both are built on rows along an axis of body a.
//!
//! Along an axis the angular momentum is kept exactly even with `C ≠ 0`:
//! `J_a = [−n, −(r_a + d) × n]`, `J_b = [n, r_b × n]` give the angular
//! impulse about the origin `λ ((x_b + r_b) − (x_a + r_a) − d) × n = 0`.
//!
//! At least 256 cases each; masses and inertias in [1e-3, 1e3], centres of
//! mass off the body origins. Bounds are those of
//! `revolute_properties.rs`: small multiples of `EPS` times the size of the
//! terms, and `(8 eps / ε + 4 ε²) M` for the central difference.
//! `JANUS2D_REPORT=1` prints the worst error as a fraction of its bound
//! and the scene figures.

use super::joint_checks::*;
use janus2d::prelude::*;
use janus2d_constraints::{JointDefBase, JointError, JointFrame};
use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::constraint::{Constraint, ConstraintRows};
use janus2d_core::math::wrap_angle;
use janus2d_testbed::support::*;
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

// ----- the property harness (shared with wheel.rs) -------------------------

/// Two bodies, the frames' anchors, frame a's axis angle, and the joint
/// angle `θ_b − θ_a − θ_ref` away from ±π.
#[derive(Clone, Debug)]
pub(super) struct AxisCase {
    pub(super) a: BodySpec,
    pub(super) b: BodySpec,
    pub(super) anchor_a: Vec2,
    pub(super) anchor_b: Vec2,
    pub(super) axis_angle: Real,
    pub(super) reference: Real,
}

impl AxisCase {
    /// The shared base: frame a at `anchor_a` turned to the axis, frame b
    /// at `anchor_b` with the reference angle `φ_a − φ_b`.
    pub(super) fn base(&self, a: BodyHandle, b: BodyHandle) -> JointDefBase {
        JointDefBase::with_frames(
            a,
            b,
            JointFrame::new(self.anchor_a, self.axis_angle),
            JointFrame::new(self.anchor_b, self.axis_angle - self.reference),
        )
    }

    fn moved(&self, dirs: &[(Vec2, Real); 2], t: Real) -> AxisCase {
        AxisCase {
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

/// A joint of the kind under test on a case's bodies.
pub(super) struct Built {
    pub(super) set: BodySet,
    pub(super) a: BodyHandle,
    pub(super) b: BodyHandle,
    pub(super) joint: Joint,
}

/// What the harness needs of a kind: how to build it with every row on,
/// which rows have a position error (`C` rows; angle rows are wrapped),
/// and the rows with no position error (motors, `C = 0`).
pub(super) struct KindUnderTest {
    pub(super) name: &'static str,
    pub(super) build: fn(&AxisCase) -> Built,
    pub(super) rows: usize,
    pub(super) c_rows: &'static [usize],
    pub(super) angle_rows: &'static [usize],
    pub(super) velocity_rows: &'static [usize],
}

pub(super) fn axis_case(
    type_a: impl Strategy<Value = BodyType> + Clone,
) -> impl Strategy<Value = AxisCase> {
    (
        body_spec(type_a),
        body_spec(Just(BodyType::Dynamic)),
        vec2(2.0),
        vec2(2.0),
        real(-3.0, 3.0),
        real(-2.0, 2.0),
        real(-2.0, 2.0),
    )
        .prop_map(
            |(a, mut b, anchor_a, anchor_b, axis_angle, reference, angle)| {
                b.angle = a.angle + reference + angle;
                AxisCase {
                    a,
                    b,
                    anchor_a,
                    anchor_b,
                    axis_angle,
                    reference,
                }
            },
        )
}

pub(super) fn check_jacobian(kind: &KindUnderTest) {
    let dir = (vec2(1.0), real(-1.0, 1.0));
    check(
        &format!("{}: J = dC/dx for every position row", kind.name),
        (axis_case(any_type()), [dir.clone(), dir]),
        |(case, dirs)| {
            let built = (kind.build)(&case);
            let rows = built.joint.rows(&ctx(), &built.set);
            prop_assert_eq!(rows.rows.len(), kind.rows);
            let dir_of = |h: BodyHandle| if h == built.a { dirs[0] } else { dirs[1] };
            let plus = (kind.build)(&case.moved(&dirs, FD_STEP));
            let minus = (kind.build)(&case.moved(&dirs, -FD_STEP));
            let rp = plus.joint.rows(&ctx(), &plus.set);
            let rm = minus.joint.rows(&ctx(), &minus.set);
            let bound = fd_tolerance(case.c_magnitude());
            let mut worst = 0.0f64;
            for &i in kind.c_rows {
                let mut diff = rp.rows[i].c - rm.rows[i].c;
                if kind.angle_rows.contains(&i) {
                    diff = wrap_angle(diff);
                }
                let fd = d(diff) / (2.0 * d(FD_STEP));
                let jv = d(rows.row_velocity(i, dir_of));
                let err = (fd - jv).abs();
                prop_assert!(
                    err <= bound,
                    "row {i}: FD {fd} vs J δ {jv} (error {err:.3e} > {bound:.3e})"
                );
                worst = worst.max(err / bound);
            }
            for &i in kind.velocity_rows {
                prop_assert_eq!(rows.rows[i].c, 0.0);
            }
            Ok(worst)
        },
    );
}

pub(super) fn check_effective_mass(kind: &KindUnderTest, blocks: &'static [usize]) {
    check(
        &format!("{}: K = J M⁻¹ Jᵀ for every block", kind.name),
        axis_case(any_type()),
        |case| {
            let built = (kind.build)(&case);
            let rows = built.joint.rows(&ctx(), &built.set);
            let lens: Vec<usize> = rows.blocks.iter().map(|b| b.len).collect();
            // A static or kinematic a with a dynamic b: the block is regular.
            prop_assert_eq!(&lens[..], blocks);
            k_blocks_match(&rows)
        },
    );
}

fn conserved(
    before: ([f64; 3], f64),
    after: ([f64; 3], f64),
    applied: f64,
    what: &str,
) -> Result<f64, TestCaseError> {
    let scale = before.1 + after.1 + applied;
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

/// Size of the momentum the row impulses carry one by one,
/// `Σ_i Σ_bodies |λ_i| (|J_lin| (1 + |x|) + |J_ang|)`.
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

pub(super) fn check_momentum(kind: &KindUnderTest) {
    let one = (log_uniform(-3.0, 3.0), prop::bool::ANY).prop_map(|(m, s)| if s { m } else { -m });
    check(
        &format!(
            "{}: impulses along Jᵀ and the joint's solve keep p and L",
            kind.name
        ),
        (
            axis_case(Just(BodyType::Dynamic)),
            prop::collection::vec(one, 6),
        ),
        |(case, lambda)| {
            // Impulses along the reported Jacobian: Δv = M⁻¹ Jᵀ λ.
            let mut built = (kind.build)(&case);
            let rows = built.joint.rows(&ctx(), &built.set);
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
            let w1 = conserved(before, after, applied, "Jᵀ λ: (px, py, L)")?;
            // The joint's own impulses: warm start from the kept impulses
            // of one solve, then one more solve with and without bias.
            let mut built = (kind.build)(&case);
            let h = [built.a, built.b];
            let before = total_momentum(&built.set, &h);
            let ctx = ctx();
            built.joint.prepare(&ctx, &built.set);
            built.joint.solve(&ctx, &mut built.set.states, true);
            built.joint.warm_start(&ctx, &mut built.set.states);
            built.joint.solve(&ctx, &mut built.set.states, false);
            let after = total_momentum(&built.set, &h);
            let solved = built.joint.rows(&ctx, &built.set);
            let impulses: Vec<Real> = solved.rows.iter().map(|r| 3.0 * r.impulse).collect();
            let applied = applied_scale(&solved, &impulses, &built.set);
            let w2 = conserved(before, after, applied, "solve: (px, py, L)")?;
            Ok(w1.max(w2))
        },
    );
}

// ----- the prismatic joint's properties ------------------------------------

/// Row order with everything on: perpendicular, angle, spring, motor,
/// lower, upper.
fn build_prismatic(case: &AxisCase) -> Built {
    let mut set = BodySet::new();
    let a = case.a.create(&mut set);
    let b = case.b.create(&mut set);
    let def = PrismaticJointDef::from_base(case.base(a, b))
        .with_limits(-1.0, 1.0)
        .with_motor(0.5, 10.0)
        .with_spring(5.0, 0.7)
        .with_target_translation(0.2);
    def.validate().expect("valid joint");
    Built {
        set,
        a,
        b,
        joint: PrismaticJoint::new(def).into(),
    }
}

const PRISMATIC: KindUnderTest = KindUnderTest {
    name: "prismatic",
    build: build_prismatic,
    rows: 6,
    c_rows: &[0, 1, 2, 4, 5],
    angle_rows: &[1],
    velocity_rows: &[3],
};

#[test]
fn prismatic_jacobian_is_the_derivative_of_c() {
    check_jacobian(&PRISMATIC);
}

#[test]
fn prismatic_k_is_j_inverse_mass_j_transpose() {
    check_effective_mass(&PRISMATIC, &[2, 1, 1, 1, 1]);
}

#[test]
fn prismatic_impulses_keep_total_momentum() {
    check_momentum(&PRISMATIC);
}

/// The read-backs agree with the reported rows: the translation is the
/// lower limit row's `C` plus the lower limit, the perpendicular error
/// the first row's `C`, and the translation speed the axial row's `J v`.
#[test]
fn prismatic_read_backs_are_the_rows() {
    check(
        "prismatic: translation, perpendicular error and speed",
        axis_case(any_type()),
        |case| {
            let built = build_prismatic(&case);
            let j = built.joint.as_prismatic().unwrap();
            let rows = built.joint.rows(&ctx(), &built.set);
            let vel = |h: BodyHandle| {
                let st = built.set.state(h).unwrap();
                (st.v, st.w)
            };
            let scale = case.c_magnitude();
            let t = j.translation(&built.set);
            let e1 = (d(t) - d(rows.rows[4].c - 1.0)).abs() / (16.0 * EPS * scale);
            let e2 = (d(j.perpendicular_error(&built.set)) - d(rows.rows[0].c)).abs()
                / (16.0 * EPS * scale);
            let speed = d(j.translation_speed(&built.set));
            let e3 = (speed - d(rows.row_velocity(4, vel))).abs()
                / (16.0 * EPS * (1.0 + speed.abs()) * scale);
            let worst = e1.max(e2).max(e3);
            prop_assert!(worst <= 1.0, "read-backs off the rows: {e1} {e2} {e3}");
            Ok(worst)
        },
    );
}

trait AsPrismatic {
    fn as_prismatic(&self) -> Option<&PrismaticJoint>;
}

impl AsPrismatic for Joint {
    fn as_prismatic(&self) -> Option<&PrismaticJoint> {
        self.of()
    }
}

// ----- the elevator --------------------------------------------------------

/// What the elevator run measured.
#[derive(Debug)]
struct Elevator {
    /// Largest |perpendicular error| over the run, m.
    off_axis: Real,
    /// Largest translation past the upper limit, m.
    overshoot: Real,
    /// Largest |angle error|, rad.
    angle: Real,
    /// The translation at the end, m.
    end: Real,
    /// The platform's speed 1 s into the run, m/s.
    speed: Real,
    /// The joint's force on the platform at the end, N.
    force: Vec2,
}

const UPPER: Real = 3.0;

/// The elevator: a 10 kg platform (2 m × 0.2 m) on a vertical
/// prismatic joint to the static ground, its anchor at the platform's
/// centre, translation 0 at the start (1 m up), limits [0, 3] m; a 100 kg
/// box (1 m × 1 m) resting on it 0.3 m off centre (so the angle row
/// carries 30 N·m). The motor drives it up at 1 m/s with up to 5 kN
/// (the load weighs 1.1 kN); it reaches the upper limit after 3 s and is
/// held there, the motor still pushing, for 2 s more. Default world
/// (g = −10 m/s², 4 substeps), 60 Hz.
fn elevator() -> Elevator {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let start = Vec2::new(0.0, 1.0);
    let platform = world.create_body(&BodyDef::dynamic(start)).unwrap();
    // 2 m × 0.2 m at 25 kg/m² = 10 kg.
    world
        .create_shape(
            platform,
            &ShapeDef::default().with_density(25.0),
            Polygon::make_box(1.0, 0.1),
        )
        .unwrap();
    let load = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.3, 1.6)))
        .unwrap();
    world
        .create_shape(
            load,
            &ShapeDef::default().with_density(100.0),
            Polygon::make_box(0.5, 0.5),
        )
        .unwrap();
    assert!((world.mass(platform).unwrap() - 10.0).abs() < 1e-3);
    assert!((world.mass(load).unwrap() - 100.0).abs() < 1e-2);
    let def = PrismaticJointDef::new(ground, platform, start, Vec2::ZERO, Vec2::Y)
        .with_limits(0.0, UPPER)
        .with_motor(1.0, 5000.0);
    let joint = world.create_joint(&def.into()).unwrap();
    let mut out = Elevator {
        off_axis: 0.0,
        overshoot: 0.0,
        angle: 0.0,
        end: 0.0,
        speed: 0.0,
        force: Vec2::ZERO,
    };
    for step in 0..300 {
        world.step(1.0 / 60.0).unwrap();
        let (perp, t) = axis_errors(&world, joint);
        out.off_axis = out.off_axis.max(perp.abs());
        out.overshoot = out.overshoot.max(t - UPPER);
        out.angle = out.angle.max(world.angle(platform).unwrap().abs());
        if step == 59 {
            out.speed = world.linear_velocity(platform).unwrap().y;
        }
    }
    out.end = axis_errors(&world, joint).1;
    out.force = world.joint_force(joint).unwrap();
    out
}

/// A joint along an axis of body a (prismatic, wheel), measured from the
/// world's poses: the perpendicular error `perp · d` and the translation
/// `n · d` (m), `d` the anchors' separation, `n` frame a's x axis.
pub(super) fn axis_errors(world: &World, joint: JointHandle) -> (Real, Real) {
    let j = world.joint(joint).unwrap();
    let base = j.def_base();
    let ta = world.transform(base.body_a).unwrap();
    let tb = world.transform(base.body_b).unwrap();
    let d = tb.apply(base.local_frame_b.anchor) - ta.apply(base.local_frame_a.anchor);
    let n = ta.q.rotate(base.local_frame_a.axis());
    (n.perp().dot(d), n.dot(d))
}

/// Issue bound: off-axis error ≤ 1 mm throughout, limit overshoot ≤ 5 mm.
#[test]
fn prismatic_elevator_holds_its_axis_and_its_limit() {
    let e = elevator();
    if report() {
        eprintln!(
            "elevator: off-axis {:.3e} m, overshoot {:.3e} m, angle {:.3e} rad, \
             speed at 1 s {:.4} m/s, end translation {:.4} m, force {:?} N",
            e.off_axis, e.overshoot, e.angle, e.speed, e.end, e.force
        );
    }
    assert!(e.off_axis <= 1e-3, "off-axis error {} m", e.off_axis);
    assert!(e.overshoot <= 5e-3, "limit overshoot {} m", e.overshoot);
    // The motor drives it at 1 m/s, and the limit holds it at 3 m.
    assert!((e.speed - 1.0).abs() < 0.01, "speed {}", e.speed);
    assert!((e.end - UPPER).abs() < 5e-3, "end translation {}", e.end);
    // Held at the limit, the joint carries the platform and the load:
    // 110 kg under g = 10 m/s² is 1.1 kN up on the platform.
    assert!((e.force.y - 1100.0).abs() < 20.0, "force {:?}", e.force);
}

// ----- bad input -----------------------------------------------------------

#[test]
fn bad_prismatic_input_is_a_typed_error_and_changes_nothing() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0)))
        .unwrap();
    let good = PrismaticJointDef::new(ground, b, Vec2::new(0.0, 1.0), Vec2::ZERO, Vec2::Y);
    let joint = world.create_joint(&good.clone().into()).unwrap();
    world.step(1.0 / 60.0).unwrap();
    let state = |w: &World| (w.state_hash(), w.body_count(), w.joint_count());
    let before = state(&world);
    let def_before = world.joint(joint).unwrap().def();
    let mut nan = good.clone();
    nan.motor_speed = Real::NAN;
    assert_eq!(
        world.create_joint(&nan.into()),
        Err(WorldError::Joint(JointError::NonFinite))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_limits(1.0, -1.0).into()),
        Err(WorldError::Joint(JointError::InvalidLimits))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_motor(1.0, -10.0).into()),
        Err(WorldError::Joint(JointError::Negative))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_spring(-1.0, 0.5).into()),
        Err(WorldError::Joint(JointError::Negative))
    );
    assert!(matches!(
        world.create_joint(&good.clone().with_motor(1e12, 10.0).into()),
        Err(WorldError::OutOfBounds { .. })
    ));
    assert!(matches!(
        world.create_joint(&good.clone().with_limits(0.0, 1e12).into()),
        Err(WorldError::OutOfBounds { .. })
    ));
    let mut set = BodySet::new();
    let (a2, b2) = (
        set.create(&BodyDef::fixed(Vec2::ZERO)).unwrap(),
        set.create(&BodyDef::dynamic(Vec2::Y)).unwrap(),
    );
    assert_eq!(
        PrismaticJointDef::at_world(&set, a2, b2, Vec2::ZERO, Vec2::ZERO),
        Err(JointError::ZeroLength)
    );
    // Setters: the limits, a linear motor's force; the torque setter is
    // the wrong kind of motor.
    assert!(world.set_joint_limits(joint, 1.0, -1.0).is_err());
    assert!(world.set_joint_limits(joint, Real::NAN, 1.0).is_err());
    assert!(world.set_joint_max_motor_force(joint, -1.0).is_err());
    assert_eq!(
        world.set_joint_max_motor_torque(joint, 10.0),
        Err(WorldError::WrongJointKind)
    );
    assert!(world.set_joint_spring(joint, -1.0, 0.0).is_err());
    let mut wrong = def_before.clone();
    if let JointDef::Prismatic(d) = &mut wrong {
        d.max_motor_force = -1.0;
    }
    assert!(world.set_joint_def(joint, wrong).is_err());
    assert_eq!(state(&world), before);
    assert_eq!(world.joint(joint).unwrap().def(), def_before);
    // And the good setters take.
    world.set_joint_limits(joint, -0.5, 0.5).unwrap();
    world.set_joint_max_motor_force(joint, 100.0).unwrap();
    world.set_joint_motor_speed(joint, 0.5).unwrap();
    world.enable_joint_motor(joint, true).unwrap();
    world.enable_joint_limit(joint, true).unwrap();
    let d = world
        .joint_of::<PrismaticJoint>(joint)
        .unwrap()
        .def()
        .clone();
    assert!(d.enable_limit && d.enable_motor);
    assert_eq!(
        (d.lower_translation, d.upper_translation, d.max_motor_force),
        (-0.5, 0.5, 100.0)
    );
    assert_eq!(world.joint(joint).unwrap().kind(), JointKind::Prismatic);
}
