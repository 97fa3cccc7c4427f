//! The wheel joint: property tests of its reported rows (the harness of
//! `prismatic.rs`: `J` is the derivative of `C` for the perpendicular,
//! spring and limit rows, `K = J M⁻¹ Jᵀ`, impulses along `Jᵀ` and the
//! joint's own solve keep the total linear and angular momentum), the car
//! scene of the issue, and bad input. `JANUS2D_REPORT=1` prints the
//! figures.

use janus2d::prelude::*;
use janus2d_constraints::JointError;
use janus2d_core::body::BodySet;
use janus2d_testbed::support::report;

use super::prismatic::{
    AxisCase, Built, KindUnderTest, axis_errors, check_effective_mass, check_jacobian,
    check_momentum,
};

// ----- properties ----------------------------------------------------------

/// Row order with everything on: perpendicular, spring, motor, lower,
/// upper.
fn build_wheel(case: &AxisCase) -> Built {
    let mut set = BodySet::new();
    let a = case.a.create(&mut set);
    let b = case.b.create(&mut set);
    let def = WheelJointDef::from_base(case.base(a, b))
        .with_spring(5.0, 0.7)
        .with_motor(-3.0, 20.0)
        .with_limits(-0.5, 0.5);
    def.validate().expect("valid joint");
    Built {
        set,
        a,
        b,
        joint: WheelJoint::new(def).into(),
    }
}

const WHEEL: KindUnderTest = KindUnderTest {
    name: "wheel",
    build: build_wheel,
    rows: 5,
    c_rows: &[0, 1, 3, 4],
    angle_rows: &[],
    velocity_rows: &[2],
};

#[test]
fn wheel_jacobian_is_the_derivative_of_c() {
    check_jacobian(&WHEEL);
}

#[test]
fn wheel_k_is_j_inverse_mass_j_transpose() {
    check_effective_mass(&WHEEL, &[1, 1, 1, 1, 1]);
}

#[test]
fn wheel_impulses_keep_total_momentum() {
    check_momentum(&WHEEL);
}

// ----- the car -------------------------------------------------------------

/// Wheel radius, m.
const RADIUS: Real = 0.4;
/// The speed the motor is set for at the rim, m/s: 11 m/s, so that the
/// car (its wheels rolling with some slip over the bumps) reaches the
/// issue's 10 m/s.
const TARGET: Real = 11.0;

/// What the car run measured.
#[derive(Debug)]
struct Car {
    /// Largest |perpendicular error| of either wheel joint, m.
    off_axis: Real,
    /// Largest chassis speed along x, m/s.
    top_speed: Real,
    /// Chassis speed along x at the end, m/s.
    end_speed: Real,
    /// Suspension travel range seen (min, max translation), m.
    travel: (Real, Real),
    /// Chassis x at the end, m.
    distance: Real,
    /// Bumps passed (their x below the chassis's at the end).
    bumps_passed: usize,
}

const BUMPS: [Real; 7] = [10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0];

/// The car: a 50 kg chassis (2.5 m × 0.5 m) on two 5 kg wheels
/// (circles, r = 0.4 m, friction 0.9) 2 m apart, each on a wheel joint
/// with a vertical suspension (5 Hz, damping 0.7, travel ±0.25 m); the
/// rear wheel's motor turns at −27.5 rad/s (11 m/s at the rim) with up to
/// 150 N·m. The ground is flat with seven bumps (circles r = 0.3 m sunk
/// to stand 5 cm proud) every 10 m from x = 10 m. Default world
/// (g = −10 m/s², 4 substeps) but for `continuous`, 8 s at 60 Hz.
fn car(continuous: bool) -> Car {
    let def = WorldDef {
        enable_continuous: continuous,
        ..WorldDef::default()
    };
    let mut world = World::new(def).unwrap();
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(240.0, -0.5)))
        .unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(250.0, 0.5))
        .unwrap();
    for x in BUMPS {
        let bump = world
            .create_body(&BodyDef::fixed(Vec2::new(x, -0.25)))
            .unwrap();
        world
            .create_shape(
                bump,
                &ShapeDef::default(),
                Circle::new(Vec2::ZERO, 0.3).unwrap(),
            )
            .unwrap();
    }
    let chassis = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.9)))
        .unwrap();
    // 2.5 m × 0.5 m at 40 kg/m² = 50 kg.
    world
        .create_shape(
            chassis,
            &ShapeDef::default().with_density(40.0),
            Polygon::make_box(1.25, 0.25),
        )
        .unwrap();
    let wheel_shape = ShapeDef::default().with_density(10.0).with_friction(0.9);
    let mut joints = Vec::new();
    for (x, motor) in [(-1.0, true), (1.0, false)] {
        let wheel = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, RADIUS)))
            .unwrap();
        world
            .create_shape(
                wheel,
                &wheel_shape,
                Circle::new(Vec2::ZERO, RADIUS).unwrap(),
            )
            .unwrap();
        let mut def = WheelJointDef::new(
            chassis,
            wheel,
            Vec2::new(x, RADIUS - 0.9),
            Vec2::ZERO,
            Vec2::Y,
        )
        .with_spring(5.0, 0.7)
        .with_limits(-0.25, 0.25);
        if motor {
            def = def.with_motor(-TARGET / RADIUS, 150.0);
        }
        joints.push(world.create_joint(&def.into()).unwrap());
    }
    let mut out = Car {
        off_axis: 0.0,
        top_speed: 0.0,
        end_speed: 0.0,
        travel: (Real::MAX, Real::MIN),
        distance: 0.0,
        bumps_passed: 0,
    };
    for _ in 0..480 {
        world.step(1.0 / 60.0).unwrap();
        for &j in &joints {
            let (perp, t) = axis_errors(&world, j);
            out.off_axis = out.off_axis.max(perp.abs());
            out.travel = (out.travel.0.min(t), out.travel.1.max(t));
        }
        out.top_speed = out.top_speed.max(world.linear_velocity(chassis).unwrap().x);
    }
    out.end_speed = world.linear_velocity(chassis).unwrap().x;
    out.distance = world.position(chassis).unwrap().x;
    out.bumps_passed = BUMPS.iter().filter(|&&x| x < out.distance - 1.5).count();
    out
}

fn report_car(what: &str, c: &Car) {
    if report() {
        eprintln!(
            "car ({what}): off-axis {:.3e} m, top speed {:.3} m/s, end speed {:.3} m/s, \
             travel [{:.3}, {:.3}] m, {:.1} m, {} bumps passed",
            c.off_axis,
            c.top_speed,
            c.end_speed,
            c.travel.0,
            c.travel.1,
            c.distance,
            c.bumps_passed
        );
    }
}

/// Issue bound: wheels within 1 cm of their axes throughout, and the
/// motor brings the car to 10 m/s over the bumps (and not past its rim
/// speed), with the continuous stage off; the next test runs it on.
#[test]
fn car_on_wheel_joints_holds_its_wheels_and_reaches_ten_metres_a_second() {
    let c = car(false);
    report_car("continuous off", &c);
    assert!(c.bumps_passed >= 4, "{} bumps passed", c.bumps_passed);
    assert!(c.off_axis <= 0.01, "perpendicular error {} m", c.off_axis);
    assert!(c.top_speed >= 10.0, "top speed {} m/s", c.top_speed);
    assert!(c.top_speed <= TARGET, "top speed {} m/s", c.top_speed);
}

/// The same car in the default world (continuous collision on). Before
/// the continuous stage measured a turn by the reach of the shapes' cores
/// (a circle turning on its centre sweeps nothing new), a wheel spinning
/// at 25 rad/s counted as fast and was moved back to its time of impact
/// with a bump without its chassis: 13.2 cm of perpendicular error for a
/// step. Guards that the wheels are no longer rewound apart from the car.
#[test]
fn car_with_continuous_collision_holds_its_wheels() {
    let c = car(true);
    report_car("continuous on", &c);
    assert!(c.off_axis <= 0.01, "perpendicular error {} m", c.off_axis);
    assert!(c.top_speed >= 10.0, "top speed {} m/s", c.top_speed);
}

// ----- bad input -----------------------------------------------------------

#[test]
fn bad_wheel_input_is_a_typed_error_and_changes_nothing() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let chassis = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0)))
        .unwrap();
    let wheel = world
        .create_body(&BodyDef::dynamic(Vec2::new(-1.0, 0.4)))
        .unwrap();
    let good = WheelJointDef::new(chassis, wheel, Vec2::new(-1.0, -0.6), Vec2::ZERO, Vec2::Y);
    let joint = world.create_joint(&good.clone().into()).unwrap();
    world.step(1.0 / 60.0).unwrap();
    let state = |w: &World| (w.state_hash(), w.body_count(), w.joint_count());
    let before = state(&world);
    let def_before = world.joint(joint).unwrap().def();
    let mut nan = good.clone();
    nan.damping_ratio = Real::NAN;
    assert_eq!(
        world.create_joint(&nan.into()),
        Err(WorldError::Joint(JointError::NonFinite))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_limits(0.1, -0.1).into()),
        Err(WorldError::Joint(JointError::InvalidLimits))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_motor(1.0, -10.0).into()),
        Err(WorldError::Joint(JointError::Negative))
    );
    assert_eq!(
        world.create_joint(&good.clone().with_spring(-1.0, 0.7).into()),
        Err(WorldError::Joint(JointError::Negative))
    );
    assert!(matches!(
        world.create_joint(&good.clone().with_motor(1e12, 10.0).into()),
        Err(WorldError::OutOfBounds { .. })
    ));
    assert!(world.set_joint_limits(joint, 0.2, -0.2).is_err());
    assert!(world.set_joint_max_motor_torque(joint, -1.0).is_err());
    assert_eq!(
        world.set_joint_max_motor_force(joint, 10.0),
        Err(WorldError::WrongJointKind)
    );
    assert!(world.set_joint_spring(joint, 1.0, -0.5).is_err());
    assert_eq!(state(&world), before);
    assert_eq!(world.joint(joint).unwrap().def(), def_before);
    // And the good setters take.
    world.set_joint_limits(joint, -0.2, 0.2).unwrap();
    world.enable_joint_limit(joint, true).unwrap();
    world.set_joint_max_motor_torque(joint, 30.0).unwrap();
    world.enable_joint_motor(joint, true).unwrap();
    world.set_joint_spring(joint, 4.0, 0.5).unwrap();
    let d = world.joint_of::<WheelJoint>(joint).unwrap().def().clone();
    assert!(d.enable_limit && d.enable_motor && d.enable_spring);
    assert_eq!(
        (d.max_motor_torque, d.hertz, d.damping_ratio),
        (30.0, 4.0, 0.5)
    );
    assert_eq!(world.joint(joint).unwrap().kind(), JointKind::Wheel);
}
