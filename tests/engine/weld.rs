//! The weld joint: a rigid cantilever held by the direct tree solve (3-row
//! joints), against the same beam solved by Gauss–Seidel; the 3-row tree
//! solve's residual and momentum on random weld trees; a soft weld's
//! oscillation; bad input and the revolute-only setters.
//!
//! The beam: 10 boxes of 1 kg, 0.5 m × 0.5 m, welded end to end and to a
//! static wall at the origin, under g = 10 m/s², 2 s at 60 Hz with 4
//! substeps, sleep off (a sleeping beam is not solved). A directly solved
//! row's static error under a load is `K λ / (h ω²)`, `ω = 2π · 500 Hz`:
//! the largest angle error is the second weld's, between two boxes
//! (`K_θθ = 2 / I = 48`, no coupling to its point rows on a straight beam)
//! under the weight of the nine boxes past it (`τ = 202.5 N·m`),
//! `48 · 202.5 / ω² = 9.85e-4` rad. The property bounds are those of `joint_tree_properties.rs`
//! with three rows per joint.

use janus2d::prelude::*;
use janus2d_constraints::{JointError, JointForest, WeldJoint, WeldJointDef};
use janus2d_core::body::{BodySet, BodyType};
use janus2d_core::constraint::{Constraint, StepContext};
use janus2d_testbed::support::*;

use super::joint_tree_properties::{pin_momentum_error, residual_bound, solve_measured, velocity};
use proptest::prelude::*;

const LINKS: usize = 10;
const LENGTH: Real = 0.5;

struct Beam {
    world: World,
    boxes: Vec<BodyHandle>,
    welds: Vec<JointHandle>,
}

/// The cantilever beam along +x from a static wall at the origin.
fn beam(direct_joints: bool) -> Beam {
    let mut def = WorldDef::default();
    def.solver.substeps = 4;
    def.solver.direct_joints = direct_joints;
    def.sleep.enabled = false;
    let mut world = World::new(def).unwrap();
    let wall = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let inertia = (LENGTH * LENGTH + LENGTH * LENGTH) / 12.0;
    let half = Vec2::new(0.5 * LENGTH, 0.0);
    let (mut boxes, mut welds) = (Vec::new(), Vec::new());
    let mut prev = (wall, Vec2::ZERO);
    for k in 0..LINKS {
        let at = Vec2::new((k as Real + 0.5) * LENGTH, 0.0);
        let b = world
            .create_body(&BodyDef::dynamic(at).with_mass(1.0, inertia))
            .unwrap();
        let weld = world
            .create_weld_joint(&WeldJointDef::new(prev.0, b, prev.1, -half))
            .unwrap();
        boxes.push(b);
        welds.push(weld);
        prev = (b, half);
    }
    Beam {
        world,
        boxes,
        welds,
    }
}

/// Runs the beam 2 s; returns the tip's deflection (m, downwards) and the
/// largest joint gap (m) and angle error (rad).
fn run(beam: &mut Beam) -> (Real, Real, Real) {
    for _ in 0..120 {
        beam.world.step(1.0 / 60.0).unwrap();
    }
    let tip = *beam.boxes.last().unwrap();
    let t = beam.world.transform(tip).unwrap();
    let deflection = -t.apply(Vec2::new(0.5 * LENGTH, 0.0)).y;
    let (mut gap, mut angle): (Real, Real) = (0.0, 0.0);
    let mut prev_angle = 0.0;
    for (&h, &b) in beam.welds.iter().zip(&beam.boxes) {
        gap = gap.max(beam.world.joint_gap(h).unwrap());
        // θ_b − θ_a − θ_ref with θ_ref = 0 (the wall does not turn).
        let a = beam.world.angle(b).unwrap();
        angle = angle.max(janus2d_core::math::wrap_angle(a - prev_angle).abs());
        prev_angle = a;
    }
    (deflection, gap, angle)
}

#[test]
fn rigid_weld_cantilever_stays_straight_in_the_tree() {
    let mut tree = beam(true);
    let (tree_sag, gap, angle) = run(&mut tree);
    for &h in &tree.welds {
        assert!(tree.world.weld_joint(h).unwrap().in_tree(), "weld in tree");
        assert!(tree.world.joint(h).unwrap().in_tree());
    }
    println!("tree: tip deflection {tree_sag:e} m, max gap {gap:e} m, max angle {angle:e} rad");
    assert!(gap < 1e-3, "gap {gap}");
    assert!(angle < 1e-3, "angle error {angle}");
    // At rest: the static error of the soft rows, no more.
    let omega = 2.0 * janus2d::base::math::PI * 500.0;
    let predicted = 48.0 * 202.5 / (omega * omega);
    assert!(
        (angle - predicted).abs() < 0.02 * predicted,
        "angle error {angle}, static error {predicted}"
    );
    // The root weld carries the beam: 10 kg under g = 10 m/s² (100 N up on
    // the first box) and the torque of its weight about the wall.
    let root = tree.world.weld_joint(tree.welds[0]).unwrap();
    let force = root.constraint_force();
    let torque = root.constraint_torque();
    println!("root weld: force {force:?} N, torque {torque} N·m");
    assert!((force.y - 100.0).abs() < 1.0, "root force {force:?}");
    // Σ m g x_k = 10 · 0.25 · (1 + 3 + … + 19) = 250 N·m about the anchor
    // (the weld's torque on the first box; its point force adds none there).
    assert!((torque - 250.0).abs() < 5.0, "root torque {torque}");
}

#[test]
fn gauss_seidel_weld_beam_sags_more_than_the_tree() {
    let (tree_sag, tree_gap, tree_angle) = run(&mut beam(true));
    let mut iterative = beam(false);
    let (gs_sag, gs_gap, gs_angle) = run(&mut iterative);
    assert!(
        iterative
            .welds
            .iter()
            .all(|&h| !iterative.world.weld_joint(h).unwrap().in_tree())
    );
    println!(
        "tip deflection: tree {tree_sag:e} m (gap {tree_gap:e}, angle {tree_angle:e}); \
         Gauss–Seidel {gs_sag:e} m (gap {gs_gap:e}, angle {gs_angle:e})"
    );
    assert!(gs_sag > tree_sag, "{gs_sag} <= {tree_sag}");
}

#[test]
fn soft_weld_is_iterative_and_oscillates() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let wall = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    // Welded at its centre of mass, so gravity gives no torque; released
    // 0.3 rad from the reference angle.
    let b = world
        .create_body(
            &BodyDef::dynamic(Vec2::new(1.0, 0.0))
                .with_mass(1.0, 0.1)
                .with_angle(0.3),
        )
        .unwrap();
    let def = WeldJointDef::new(wall, b, Vec2::new(1.0, 0.0), Vec2::ZERO)
        .with_stiffness(0.0, 0.0, 2.0, 0.1);
    let weld = world.create_weld_joint(&def).unwrap();
    let (mut lowest, mut highest_after): (Real, Real) = (Real::MAX, Real::MIN);
    let mut crossed = false;
    for _ in 0..90 {
        world.step(1.0 / 60.0).unwrap();
        let a = world.angle(b).unwrap();
        lowest = lowest.min(a);
        if lowest < 0.0 {
            crossed = true;
            highest_after = highest_after.max(a);
        }
        assert!(
            !world.joint(weld).unwrap().in_tree(),
            "a soft weld stays iterative"
        );
    }
    println!("soft weld: lowest angle {lowest} rad, highest after {highest_after} rad");
    assert!(crossed && lowest < -0.05, "no overshoot: lowest {lowest}");
    assert!(highest_after > 0.0, "no second swing: {highest_after}");
    // The point rows stay rigid.
    assert!(world.joint_gap(weld).unwrap() < 1e-3);
}

#[test]
fn bad_weld_input_is_a_typed_error_and_changes_nothing() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let wall = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)))
        .unwrap();
    let good = WeldJointDef::new(wall, b, Vec2::new(1.0, 0.0), Vec2::ZERO);
    let weld = world.create_weld_joint(&good).unwrap();
    let counts = |w: &World| (w.body_count(), w.joint_count());
    let before = counts(&world);
    let mut nan = good.clone();
    nan.base.local_frame_a.anchor.x = Real::NAN;
    assert_eq!(
        world.create_weld_joint(&nan),
        Err(WorldError::Joint(JointError::NonFinite))
    );
    let negative = good.clone().with_stiffness(0.0, 0.0, -2.0, 0.0);
    assert_eq!(
        world.create_joint(&negative.into()),
        Err(WorldError::Joint(JointError::Negative))
    );
    let same = WeldJointDef::new(b, b, Vec2::ZERO, Vec2::ZERO);
    assert_eq!(
        world.create_weld_joint(&same),
        Err(WorldError::Joint(JointError::SameBody))
    );
    let far = WeldJointDef::new(wall, b, Vec2::new(1e12, 0.0), Vec2::ZERO);
    assert!(matches!(
        world.create_weld_joint(&far),
        Err(WorldError::OutOfBounds { .. })
    ));
    assert_eq!(counts(&world), before);
    // The revolute-only setters: WrongJointKind, the weld unchanged.
    let def = world.joint(weld).unwrap().def();
    let wrong = Err(WorldError::WrongJointKind);
    assert_eq!(world.set_joint_limits(weld, -0.5, 0.5), wrong);
    assert_eq!(world.enable_joint_limit(weld, true), wrong);
    assert_eq!(world.set_joint_motor_speed(weld, 1.0), wrong);
    assert_eq!(world.set_joint_max_motor_torque(weld, 10.0), wrong);
    assert_eq!(world.enable_joint_motor(weld, true), wrong);
    assert_eq!(world.set_joint_spring(weld, 1.0, 0.5), wrong);
    assert_eq!(world.enable_joint_spring(weld, true), wrong);
    assert!(world.revolute_joint(weld).is_err());
    assert_eq!(world.joint(weld).unwrap().def(), def);
    assert_eq!(world.joint(weld).unwrap().kind(), JointKind::Weld);
    assert_eq!(counts(&world), before);
}

/// A tree mixing both row counts: a rigid arm of three welded boxes
/// swinging on a revolute pin from the horizontal. Every joint is solved
/// by the tree (2-row and 3-row joints meet in the body pivots) and the
/// arm stays rigid through the swing.
#[test]
fn welded_arm_on_a_revolute_pin_is_one_tree() {
    let mut def = WorldDef::default();
    def.solver.substeps = 4;
    def.sleep.enabled = false;
    let mut world = World::new(def).unwrap();
    let pin = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let inertia = 2.0 * LENGTH * LENGTH / 12.0;
    let half = Vec2::new(0.5 * LENGTH, 0.0);
    let mut boxes = Vec::new();
    for k in 0..3 {
        let at = Vec2::new((k as Real + 0.5) * LENGTH, 0.0);
        boxes.push(
            world
                .create_body(&BodyDef::dynamic(at).with_mass(1.0, inertia))
                .unwrap(),
        );
    }
    let hinge = world
        .create_revolute_joint(&RevoluteJointDef::new(pin, boxes[0], Vec2::ZERO, -half))
        .unwrap();
    let welds: Vec<JointHandle> = (1..3)
        .map(|k| {
            world
                .create_weld_joint(&WeldJointDef::new(boxes[k - 1], boxes[k], half, -half))
                .unwrap()
        })
        .collect();
    let (mut gap, mut angle): (Real, Real) = (0.0, 0.0);
    for _ in 0..120 {
        world.step(1.0 / 60.0).unwrap();
        gap = gap.max(world.max_joint_gap());
        for k in 1..3 {
            let rel = world.angle(boxes[k]).unwrap() - world.angle(boxes[k - 1]).unwrap();
            angle = angle.max(janus2d_core::math::wrap_angle(rel).abs());
        }
        assert!(world.joint(hinge).unwrap().in_tree());
        assert!(welds.iter().all(|&w| world.joint(w).unwrap().in_tree()));
    }
    let swing = world.angle(boxes[0]).unwrap();
    println!("welded arm: max gap {gap:e} m, max weld angle {angle:e} rad, arm angle {swing}");
    // It swings (the hinge turns freely) while the welds hold.
    assert!(swing.abs() > 0.1, "arm angle {swing}");
    assert!(gap < 1e-3, "gap {gap}");
    assert!(angle < 1e-3, "weld angle {angle}");
}

// ----- the 3-row tree solve on random weld trees --------------------------

/// A random weld tree: 2–10 dynamic bodies (masses and inertias in
/// [0.1, 1e3]), each welded to an earlier one or to the static pin, and
/// the bias switch.
#[derive(Clone, Debug)]
struct WeldCase {
    bodies: Vec<BodySpec>,
    /// Per body: its parent (0: the pin, k: body k−1) and the anchors.
    links: Vec<(usize, Vec2, Vec2)>,
    use_bias: bool,
}

fn weld_case() -> impl Strategy<Value = WeldCase> {
    (2usize..=10)
        .prop_flat_map(|n| {
            let body = body_spec(Just(BodyType::Dynamic))
                .prop_flat_map(|b| (Just(b), log_uniform(-1.0, 3.0), log_uniform(-1.0, 3.0)));
            (
                prop::collection::vec(body, n),
                prop::collection::vec((0usize..1000, vec2(1.5), vec2(1.5)), n),
                any::<bool>(),
            )
        })
        .prop_map(|(bodies, links, use_bias)| WeldCase {
            bodies: bodies
                .into_iter()
                .map(|(mut b, m, i)| {
                    b.mass = m;
                    b.inertia = i;
                    b
                })
                .collect(),
            links: links
                .into_iter()
                .enumerate()
                .map(|(k, (p, a, b))| (p % (k + 1), a, b))
                .collect(),
            use_bias,
        })
}

struct Built {
    set: BodySet,
    bodies: Vec<BodyHandle>,
    joints: Vec<Joint>,
    pinned: Vec<bool>,
}

fn build(case: &WeldCase, ctx: &StepContext) -> Built {
    let mut set = BodySet::new();
    let pin = BodySpec::fixed(Vec2::new(0.5, -0.5), 0.3).create(&mut set);
    let bodies: Vec<BodyHandle> = case.bodies.iter().map(|b| b.create(&mut set)).collect();
    let mut joints = Vec::new();
    let mut pinned = Vec::new();
    for (k, &(parent, anchor_parent, anchor_child)) in case.links.iter().enumerate() {
        let p = if parent == 0 { pin } else { bodies[parent - 1] };
        let def = WeldJointDef::new(p, bodies[k], anchor_parent, anchor_child)
            .with_reference_angle(0.1 * k as Real);
        let mut j = Joint::from(WeldJoint::new(def));
        j.prepare(ctx, &set);
        joints.push(j);
        pinned.push(parent == 0);
    }
    Built {
        set,
        bodies,
        joints,
        pinned,
    }
}

fn weld(j: &Joint) -> &WeldJoint {
    j.as_weld().expect("a weld joint")
}

/// One solve satisfies every weld's three soft rows exactly:
/// `J v' + b + Γ λ' = 0` (bias: `b` the velocity solve's share of `β C`)
/// or `J v' + Γ Δλ = 0` (relax), with the full 3×3 `K` in `Γ = K / a2`,
/// on the tree's spring masses (`spring_ks`).
#[test]
fn weld_tree_solve_satisfies_every_soft_row() {
    check("weld tree residual", weld_case(), |case| {
        let (worst, bound) = weld_tree_residual(&case)?;
        prop_assert!(worst <= bound, "residual {worst:e} > {bound:e}");
        Ok(worst / bound)
    });
}

/// A case the property test met once in the f64 build: two bodies whose
/// inertia spread is extreme (995 kg with 0.13 kg·m² hung 1.8 m off a
/// 92 kg body) with the bias on. Its residual, 2.5e-6, is the same on the
/// code before the joint kinds; it exceeded the bound until the bound
/// took the lever arm in (see `weld_tree_residual`).
#[test]
fn weld_tree_residual_of_a_light_inertia_under_a_long_arm() {
    // The figures as the f64 run printed them, rounded to f32 in that build.
    let body =
        |mass: f64, inertia: f64| BodySpec::dynamic(Vec2::ZERO, mass as Real, inertia as Real);
    let v = |x: f64, y: f64| Vec2::new(x as Real, y as Real);
    let case = WeldCase {
        bodies: vec![body(92.240_438, 144.022_87), body(995.063_35, 0.130_313_58)],
        links: vec![
            (0, v(-0.523_266_3, 0.0), v(-1.170_456_6, 0.0)),
            (1, v(0.441_738_7, 0.0), v(1.156_770_8, -1.345_968_9)),
        ],
        use_bias: true,
    };
    let (worst, bound) = weld_tree_residual(&case).unwrap();
    assert!(worst <= bound, "residual {worst:e} > {bound:e}");
}

/// The worst residual of one tree solve of `case` over its welds' rows
/// and its bound ([`residual_bound`](super::joint_tree_properties::residual_bound)).
fn weld_tree_residual(case: &WeldCase) -> Result<(f64, f64), TestCaseError> {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    let soft = ctx.direct_joint_softness;
    let mut b = build(case, &ctx);
    let m = solve_measured(
        &ctx,
        (&mut b.joints, &mut b.set),
        &case.bodies,
        3,
        case.use_bias,
    )?;
    for rows in &m.before {
        prop_assert_eq!(rows.rows.len(), 3);
        prop_assert_eq!(rows.blocks[0].len, 3);
    }
    let mut worst: f64 = 0.0;
    for ((j, rows), k) in b.joints.iter().zip(&m.before).zip(&m.ks) {
        let after = j.rows(&ctx, &b.set);
        let w = weld(j);
        let lambda = [
            d(w.linear_impulse().x),
            d(w.linear_impulse().y),
            d(w.angular_impulse()),
        ];
        let bias = if case.use_bias {
            // The point rows: the velocity solve's share of the feedback
            // (the tree hangs from the pin, the welds start with no
            // impulse: `joint_tree::VELOCITY_CORRECTION_SPEED`); the rest
            // moves the bodies in the correction pass.
            let c = Vec2::new(rows.rows[0].c, rows.rows[1].c);
            let bias = soft.bias_rate * c;
            let len = bias.length();
            let share = janus2d_constraints::joint_tree::VELOCITY_CORRECTION_SPEED;
            let bias = if len > share {
                bias * (share / len)
            } else {
                bias
            };
            // The angle row's feedback stays whole, capped at the
            // correction speed in rad/s.
            let cap = ctx.direct_joint_max_correction_speed;
            let angle_cap = janus2d_constraints::parts::angular_correction_cap(cap);
            let angle = (soft.bias_rate * rows.rows[2].c).clamp(-angle_cap, angle_cap);
            [d(bias.x), d(bias.y), d(angle)]
        } else {
            [0.0; 3]
        };
        for i in 0..3 {
            let c_dot = d(after.row_velocity(i, |h| velocity(&b.set, h)));
            let held = m.compliance * (0..3).map(|c| k[i][c] * lambda[c]).sum::<f64>();
            worst = worst.max((c_dot + bias[i] + held).abs());
        }
    }
    // The rows' K mixes m⁻¹ with r² I⁻¹: the elimination's rounding grows
    // with the longest lever arm too. Without this factor the bound failed
    // in about one f64 run in fifteen, on the code before the joint kinds
    // as after (the case of the test below: 2.5e-6 against 1.5e-6).
    let lever = case
        .links
        .iter()
        .flat_map(|(_, a, b)| [d(a.length_squared()), d(b.length_squared())])
        .fold(0.0f64, f64::max);
    // A heavy tree's springs, `stiffening` times stiffer, regularise the
    // system that much less (see `residual_bound`).
    let bound = residual_bound(&case.bodies, b.joints.len(), m.stiffening, lever, m.scale);
    Ok((worst, bound))
}

/// One solve changes the bodies' total linear momentum by exactly the
/// impulses the pin takes (the angle rows carry no linear impulse).
#[test]
fn weld_tree_solve_changes_momentum_only_through_the_pin() {
    let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
    check("weld tree momentum", weld_case(), |case| {
        let mut b = build(&case, &ctx);
        let v0: Vec<(Vec2, Real)> = b.bodies.iter().map(|h| velocity(&b.set, *h)).collect();
        let mut forest = JointForest::default();
        forest.build(&mut b.joints, &b.set.states, true);
        prop_assert_eq!(forest.tree_joint_count(), b.joints.len());
        forest.solve(&ctx, &mut b.joints, &mut b.set.states, case.use_bias);
        let pin = b
            .joints
            .iter()
            .zip(&b.pinned)
            .filter(|(_, pinned)| **pinned);
        let (err, scale) = pin_momentum_error(
            &b.set,
            &b.bodies,
            &v0,
            |k| d(case.bodies[k].mass),
            pin.map(|(j, _)| weld(j).linear_impulse()),
        );
        let bound = 64.0 * EPS * scale * (b.joints.len() as f64);
        prop_assert!(err <= bound, "momentum error {err:e} > {bound:e}");
        Ok(err / bound)
    });
}
