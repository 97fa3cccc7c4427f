//! The mouse (target) joint: properties of its reported rows (`J` is the
//! derivative of `C`, `K = J M⁻¹ Jᵀ`, an impulse along `Jᵀ` is an external
//! impulse on body b at the grabbed point and leaves body a alone), the
//! issue's scene (a box dragged out of pyramid20), the spring's static
//! error and the force bound, a dynamic body a never pushed, the target
//! moved through `World::set_joint_def`, and bad input.
//!
//! Property bounds are those of `revolute_properties.rs`.

use super::joint_checks::*;
use janus2d::prelude::*;
use janus2d_constraints::{JointError, MouseJoint, MouseJointDef};
use janus2d_core::body::{BodySet, BodyType};
use janus2d_core::constraint::Constraint;
use janus2d_testbed::support::*;
use proptest::prelude::*;

// ----- properties -----------------------------------------------------------

#[derive(Clone, Debug)]
struct MouseCase {
    a: BodySpec,
    b: BodySpec,
    anchor_b: Vec2,
    target: Vec2,
    max_force: Real,
}

struct BuiltMouse {
    set: BodySet,
    a: BodyHandle,
    b: BodyHandle,
    joint: MouseJoint,
}

impl MouseCase {
    fn build(&self) -> BuiltMouse {
        let mut set = BodySet::new();
        let a = self.a.create(&mut set);
        let b = self.b.create(&mut set);
        let mut def = MouseJointDef::new(a, b, self.target, self.max_force);
        def.base.local_frame_b.anchor = self.anchor_b;
        def.validate().expect("valid joint");
        BuiltMouse {
            set,
            a,
            b,
            joint: MouseJoint::new(def),
        }
    }

    fn moved(&self, dirs: &[(Vec2, Real); 2], t: Real) -> MouseCase {
        MouseCase {
            a: self.a.moved(dirs[0].0, dirs[0].1, t),
            b: self.b.moved(dirs[1].0, dirs[1].1, t),
            ..self.clone()
        }
    }

    fn c_magnitude(&self) -> f64 {
        d(self.b.center.length())
            + d((self.anchor_b - self.b.effective_local_center()).length())
            + d(self.target.length())
    }
}

fn mouse_case(type_a: impl Strategy<Value = BodyType> + Clone) -> impl Strategy<Value = MouseCase> {
    (
        body_spec(type_a),
        body_spec(Just(BodyType::Dynamic)),
        vec2(2.0),
        vec2(5.0),
        log_uniform(-1.0, 4.0),
    )
        .prop_map(|(a, b, anchor_b, target, max_force)| MouseCase {
            a,
            b,
            anchor_b,
            target,
            max_force,
        })
}

#[test]
fn mouse_jacobian_is_the_derivative_of_c() {
    let dir = (vec2(1.0), real(-1.0, 1.0));
    check(
        "mouse: J = dC/dx for the point rows, J_a = 0",
        (mouse_case(any_type()), [dir.clone(), dir]),
        |(case, dirs)| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            prop_assert_eq!(rows.rows.len(), 3);
            prop_assert_eq!(rows.rows.len(), built.joint.row_count());
            let dir_of = |h: BodyHandle| if h == built.a { dirs[0] } else { dirs[1] };
            let plus = case.moved(&dirs, FD_STEP).build();
            let minus = case.moved(&dirs, -FD_STEP).build();
            let rp = plus.joint.rows(&ctx(), &plus.set);
            let rm = minus.joint.rows(&ctx(), &minus.set);
            let bound = fd_tolerance(case.c_magnitude());
            let mut worst = 0.0f64;
            for i in 0..2 {
                let fd = d(rp.rows[i].c - rm.rows[i].c) / (2.0 * d(FD_STEP));
                let jv = d(rows.row_velocity(i, dir_of));
                let err = (fd - jv).abs();
                prop_assert!(
                    err <= bound,
                    "row {i}: FD {fd} vs J δ {jv} (error {err:.3e} > {bound:.3e})"
                );
                worst = worst.max(err / bound);
            }
            // Body a has no entry in any row; the damping row has no C.
            for row in &rows.rows {
                let a = row.jacobian.iter().find(|e| e.body == built.a).unwrap();
                prop_assert_eq!((a.linear, a.angular), (Vec2::ZERO, 0.0));
            }
            prop_assert_eq!(rows.rows[2].c, 0.0);
            Ok(worst)
        },
    );
}

#[test]
fn mouse_k_is_j_inverse_mass_j_transpose() {
    check(
        "mouse: K = J M⁻¹ Jᵀ for every block",
        mouse_case(any_type()),
        |case| {
            let built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            let mut worst = 0.0f64;
            let mut covered = 0;
            for block in &rows.blocks {
                covered += block.len;
                for p in 0..block.len {
                    for q in 0..block.len {
                        let (i, j) = (block.first_row + p, block.first_row + q);
                        let jmj = d(rows.jmj(i, j));
                        let e = &rows.rows[i].jacobian[1];
                        let scale =
                            d(e.inv_mass) + d(e.inv_inertia) * d(e.angular.abs()).max(1.0).powi(2);
                        let bound = 32.0 * EPS * scale;
                        let err = (d(block.k[p][q]) - jmj).abs();
                        prop_assert!(
                            err <= bound,
                            "K[{i}][{j}] = {} vs {jmj} (error {err:.3e} > {bound:.3e})",
                            block.k[p][q]
                        );
                        worst = worst.max(err / bound);
                    }
                }
            }
            prop_assert_eq!(covered, rows.rows.len());
            Ok(worst)
        },
    );
}

#[cfg(feature = "f64")]
const MOMENTUM_TOL: f64 = 1e-12;
#[cfg(not(feature = "f64"))]
const MOMENTUM_TOL: f64 = 1e-5;

/// Body b's momentum `(px, py, L about the origin)` in f64 and its scale.
fn momentum_of(set: &BodySet, h: BodyHandle) -> ([f64; 3], f64) {
    total_momentum(set, &[h])
}

/// An impulse along `Jᵀ` (random `λ`) and the joint's own solve change
/// body b's momentum by exactly an impulse `P` at the grabbed point,
/// `ΔL = (x_b + r_b) × P + λ_θ`, and leave body a's velocities untouched
/// (bit for bit) even when a is dynamic; the solve's impulse is at most
/// `max_force · h` long.
#[test]
fn mouse_impulses_act_on_b_only_at_the_grabbed_point() {
    let one = (log_uniform(-3.0, 3.0), prop::bool::ANY).prop_map(|(m, s)| if s { m } else { -m });
    check(
        "mouse: Jᵀ λ is an external impulse on b at the anchor; a untouched",
        (
            mouse_case(Just(BodyType::Dynamic)),
            [one.clone(), one.clone(), one],
        ),
        |(case, lambda)| {
            let mut worst = 0.0f64;
            let check_change = |set: &BodySet,
                                before: ([f64; 3], f64),
                                p: [f64; 2],
                                l: f64,
                                what: &str|
             -> Result<f64, proptest::test_runner::TestCaseError> {
                let after = momentum_of(set, case_b(set));
                let point = {
                    let h = case_b(set);
                    let xf = set.sim(h).unwrap().transform;
                    let anchor = xf.apply(case.anchor_b);
                    [d(anchor.x), d(anchor.y)]
                };
                let expected = [
                    before.0[0] + p[0],
                    before.0[1] + p[1],
                    before.0[2] + point[0] * p[1] - point[1] * p[0] + l,
                ];
                let scale = before.1
                    + after.1
                    + (p[0].abs() + p[1].abs()) * (1.0 + point[0].abs() + point[1].abs())
                    + l.abs();
                let mut w = 0.0f64;
                for i in 0..3 {
                    let err = (after.0[i] - expected[i]).abs();
                    let bound = MOMENTUM_TOL * scale;
                    prop_assert!(err <= bound, "{what}[{i}]: error {err:.3e} > {bound:.3e}");
                    w = w.max(err / bound);
                }
                Ok(w)
            };
            // Impulses along the reported Jacobian.
            let mut built = case.build();
            let rows = built.joint.rows(&ctx(), &built.set);
            let va = *built.set.state(built.a).unwrap();
            let before = momentum_of(&built.set, built.b);
            for (i, row) in rows.rows.iter().enumerate() {
                for e in &row.jacobian {
                    let st = built.set.state_mut(e.body).unwrap();
                    st.v += e.inv_mass * lambda[i] * e.linear;
                    st.w += e.inv_inertia * lambda[i] * e.angular;
                }
            }
            let a_after = built.set.state(built.a).unwrap();
            prop_assert_eq!((a_after.v, a_after.w), (va.v, va.w));
            worst = worst.max(check_change(
                &built.set,
                before,
                [d(lambda[0]), d(lambda[1])],
                d(lambda[2]),
                "Jᵀ λ",
            )?);
            // The joint's own warm start and solves.
            let mut built = case.build();
            let va = *built.set.state(built.a).unwrap();
            let before = momentum_of(&built.set, built.b);
            let ctx = ctx();
            built.joint.prepare(&ctx, &built.set);
            built.joint.warm_start(&ctx, &mut built.set.states);
            built.joint.solve(&ctx, &mut built.set.states, true);
            built.joint.solve(&ctx, &mut built.set.states, false);
            let a_after = built.set.state(built.a).unwrap();
            prop_assert_eq!((a_after.v, a_after.w), (va.v, va.w));
            let p = built.joint.linear_impulse();
            let max = ctx.h * case.max_force;
            prop_assert!(
                d(p.length()) <= d(max) * (1.0 + 4.0 * EPS),
                "impulse {} > {}",
                p.length(),
                max
            );
            worst = worst.max(check_change(
                &built.set,
                before,
                [d(p.x), d(p.y)],
                d(built.joint.angular_impulse()),
                "solve",
            )?);
            Ok(worst)
        },
    );
}

/// Body b of a two-body set built by [`MouseCase::build`] (the second).
fn case_b(set: &BodySet) -> BodyHandle {
    set.handles().nth(1).expect("two bodies")
}

// ----- scenes ---------------------------------------------------------------

const DT: Real = 1.0 / 60.0;

/// A 2 kg box held at its centre: it settles `g / ω²` below the target
/// (the spring `k = m ω²` holds `m g`; 5 Hz: 10.1 mm), the force read-back
/// is its weight; with a 10 N bound it cannot hold its 20 N weight and
/// falls at `g − 10/2 = 5 m/s²`.
#[test]
fn mouse_settles_at_its_static_error_and_bounds_its_force() {
    let run = |max_force: Real| {
        let mut w = World::new(WorldDef::default()).unwrap();
        let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let b = w
            .create_body(&BodyDef::dynamic(Vec2::new(1.0, 1.0)).with_mass(2.0, 0.1))
            .unwrap();
        let def = MouseJointDef::new(ground, b, Vec2::new(3.0, 1.0), max_force);
        let j = w.create_joint(&def.into()).unwrap();
        for _ in 0..180 {
            w.step(DT).unwrap();
        }
        (w, b, j)
    };
    let (w, b, j) = run(1000.0);
    let p = w.position(b).unwrap();
    let sag = 10.0 / (2.0 * janus2d::base::math::PI * 5.0).powi(2);
    let force = w.joint_force(j).unwrap();
    println!("mouse: box at {p:?} (target (3, 1), sag {sag}), force {force:?}");
    assert!((p - Vec2::new(3.0, 1.0 - sag)).length() < 5e-4, "{p:?}");
    assert!((force - Vec2::new(0.0, 20.0)).length() < 0.05, "{force:?}");
    let m = w.joint_of::<MouseJoint>(j).unwrap();
    assert!((m.def().target - Vec2::new(3.0, 1.0)).length() == 0.0);
    // 10 N at most: falls at 5 m/s² (the pull always at its bound).
    let (w, b, j) = run(10.0);
    let force = w.joint_force(j).unwrap();
    let v = w.linear_velocity(b).unwrap();
    println!("mouse 10 N: force {force:?}, velocity {v:?} after 3 s");
    assert!((force.length() - 10.0).abs() < 1e-3, "{force:?}");
    assert!(v.y < -10.0, "{v:?}");
}

/// Body a dynamic (a free 1 kg box, no gravity): the mouse pulls body b
/// across 2 m and a never moves.
#[test]
fn mouse_never_pushes_a_dynamic_body_a() {
    let mut def = WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    };
    def.sleep.enabled = false;
    let mut w = World::new(def).unwrap();
    let a = w
        .create_body(&BodyDef::dynamic(Vec2::new(-1.0, 0.0)).with_mass(1.0, 0.1))
        .unwrap();
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 0.1))
        .unwrap();
    let mut def = MouseJointDef::new(a, b, Vec2::new(2.0, 0.0), 100.0);
    def.base.local_frame_b.anchor = Vec2::new(0.1, 0.1);
    w.create_joint(&def.into()).unwrap();
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let pa = w.position(a).unwrap();
    let pb = w.position(b).unwrap();
    println!("dynamic a: a at {pa:?}, b at {pb:?}");
    assert_eq!(pa, Vec2::new(-1.0, 0.0));
    assert_eq!(w.linear_velocity(a).unwrap(), Vec2::ZERO);
    assert_eq!(w.angular_velocity(a).unwrap(), 0.0);
    assert!(pb.x > 1.5, "b did not follow: {pb:?}");
}

/// The scene: pyramid20 (the testbed's `pyramid(20)`: 210 unit
/// boxes of 1 kg on a static ground, 4 substeps) settles for 1 s; then a
/// mouse joint (max force 1000 N = 100 times the box's weight, 5 Hz, 0.7)
/// grabs the top box at its centre and drags it out: the target rises at
/// 1 m/s for 2 s, then moves sideways at 2 m/s for 1 s, and holds 1 s.
/// Bound: no other box moves more than 5 cm from where it was when the
/// drag started.
#[test]
fn mouse_drags_a_box_out_of_pyramid20() {
    use janus2d_testbed::benchmarks::pyramid;
    use janus2d_testbed::janus::Janus;
    let desc = pyramid(20);
    let mut scene = Janus::new(&desc).unwrap();
    let top = scene.probe(&desc).unwrap();
    for _ in 0..60 {
        scene.world.step(DT).unwrap();
    }
    let others: Vec<BodyHandle> = scene
        .bodies
        .iter()
        .copied()
        .filter(|&h| h != top && scene.world.body_type(h).unwrap() == BodyType::Dynamic)
        .collect();
    assert_eq!(others.len(), 209);
    let start: Vec<Vec2> = others
        .iter()
        .map(|&h| scene.world.position(h).unwrap())
        .collect();
    let ground = scene.bodies[0];
    let grab = scene.world.position(top).unwrap();
    let mouse = scene
        .world
        .create_joint(&MouseJointDef::new(ground, top, grab, 1000.0).into())
        .unwrap();
    let mut worst: Real = 0.0;
    let mut target = grab;
    for step in 0..240 {
        if step < 120 {
            target.y += DT;
        } else if step < 180 {
            target.x += 2.0 * DT;
        }
        let mut def = scene
            .world
            .joint_of::<MouseJoint>(mouse)
            .unwrap()
            .def()
            .clone();
        def.target = target;
        scene.world.set_joint_def(mouse, def.into()).unwrap();
        scene.world.step(DT).unwrap();
        for (&h, &p0) in others.iter().zip(&start) {
            worst = worst.max((scene.world.position(h).unwrap() - p0).length());
        }
    }
    let p = scene.world.position(top).unwrap();
    let m = scene.world.joint_of::<MouseJoint>(mouse).unwrap();
    let to_target = (p - m.def().target).length();
    println!(
        "pyramid20 drag: top box from {grab:?} to {p:?} (target {target:?}, {to_target:.4} m off); worst other box moved {:.3} mm",
        1e3 * worst
    );
    assert!(
        p.y > grab.y + 1.5 && p.x > grab.x + 1.5,
        "not dragged out: {p:?}"
    );
    assert!(to_target < 0.05, "{to_target} m from the target");
    assert!(worst <= 0.05, "another box moved {worst} m");
}

// ----- the target and bad input ---------------------------------------------

/// The target moved through `World::set_joint_def` wakes a sleeping body
/// and the joint pulls it there; bad values are typed errors that change
/// nothing.
#[test]
fn mouse_target_moves_through_set_joint_def_and_bad_input_is_rejected() {
    let mut w = World::new(WorldDef::default()).unwrap();
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0)).with_mass(1.0, 0.1))
        .unwrap();
    let def = MouseJointDef::new(ground, b, Vec2::new(0.0, 1.0), 500.0).with_spring(5.0, 1.0);
    let j = w.create_joint(&def.clone().into()).unwrap();
    // Zero gravity for the body: held where it is until it sleeps.
    w.set_gravity(Vec2::ZERO).unwrap();
    for _ in 0..240 {
        w.step(DT).unwrap();
    }
    assert!(!w.is_awake(b).unwrap(), "the held body fell asleep");
    let (hash, bodies, joints) = (w.state_hash(), w.body_count(), w.joint_count());
    let before = w.joint(j).unwrap().def();
    let err = |e| Err(WorldError::Joint(e));
    let with = |f: &dyn Fn(&mut MouseJointDef)| {
        let mut d = def.clone();
        f(&mut d);
        JointDef::from(d)
    };
    assert_eq!(
        w.set_joint_def(j, with(&|d| d.target.x = Real::NAN)),
        err(JointError::NonFinite)
    );
    assert_eq!(
        w.set_joint_def(j, with(&|d| d.max_force = -1.0)),
        err(JointError::Negative)
    );
    assert_eq!(
        w.set_joint_def(j, with(&|d| d.hertz = -5.0)),
        err(JointError::Negative)
    );
    assert!(matches!(
        w.set_joint_def(j, with(&|d| d.target.y = 1e12)),
        Err(WorldError::OutOfBounds { .. })
    ));
    assert_eq!(
        w.create_joint(&with(&|d| d.max_force = Real::NAN))
            .map(|_| ()),
        err(JointError::NonFinite)
    );
    assert_eq!(
        w.create_joint(&MouseJointDef::new(b, b, Vec2::ZERO, 1.0).into())
            .map(|_| ()),
        err(JointError::SameBody)
    );
    // The mouse has no limits, motor or spring setters.
    assert_eq!(
        w.set_joint_limits(j, 0.0, 1.0),
        Err(WorldError::WrongJointKind)
    );
    assert_eq!(
        w.set_joint_motor_speed(j, 1.0),
        Err(WorldError::WrongJointKind)
    );
    assert_eq!(
        w.set_joint_spring(j, 1.0, 1.0),
        Err(WorldError::WrongJointKind)
    );
    assert_eq!(w.joint(j).unwrap().def(), before);
    assert_eq!(
        (w.state_hash(), w.body_count(), w.joint_count()),
        (hash, bodies, joints)
    );
    assert!(!w.is_awake(b).unwrap());
    // A new target wakes the body and the joint pulls it there.
    w.set_joint_def(j, with(&|d| d.target = Vec2::new(1.0, 2.0)))
        .unwrap();
    assert!(w.is_awake(b).unwrap());
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let p = w.position(b).unwrap();
    println!("mouse target moved: body at {p:?}");
    assert!((p - Vec2::new(1.0, 2.0)).length() < 1e-3, "{p:?}");
}
