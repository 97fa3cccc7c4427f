//! The exact tree solve over joints of every kind with equality rows: a
//! chain hanging a 100:1 load through a revolute joint, a weld, a
//! prismatic joint, a rigid distance joint, a wheel joint and a revolute
//! joint again is one tree; every equality row (point, angle,
//! perpendicular, length) is solved at once. Against the same chain
//! solved by Gauss–Seidel (`direct_joints = false`), and momentum of a
//! free tree of the `General` rows (prismatic, wheel, distance).
//!
//! The chain: six links of 1 kg, 0.5 m apart, each hanging the next 0.1 m
//! to the side of its centre (so the angle rows carry torque), under a
//! static ceiling, the last one carrying a 100 kg box, g = 10 m/s², 4
//! substeps, 2 s at 60 Hz, sleep off. Each joint's error is read from
//! the world: the anchors' gap (revolute, weld), the perpendicular
//! offset from frame a's axis (prismatic, wheel), the length error
//! (distance), the angle error (weld, prismatic).

use janus2d::prelude::*;
use janus2d::{DistanceJointDef, PrismaticJointDef, SleepSettings, WheelJointDef};
use janus2d_core::solver::SolverSettings;

const LINK: Real = 0.5;

struct Chain {
    world: World,
    joints: Vec<(JointHandle, &'static str)>,
    bodies: Vec<BodyHandle>,
}

fn chain(direct: bool) -> Chain {
    let mut world = World::new(WorldDef {
        solver: SolverSettings {
            direct_joints: direct,
            ..SolverSettings::default()
        },
        sleep: SleepSettings {
            enabled: false,
            ..SleepSettings::default()
        },
        ..WorldDef::default()
    })
    .unwrap();
    let ceiling = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let kinds = [
        "revolute",
        "weld",
        "prismatic",
        "distance",
        "wheel",
        "revolute",
    ];
    let mut previous = ceiling;
    let mut joints = Vec::new();
    let mut bodies = Vec::new();
    for (i, kind) in kinds.iter().enumerate() {
        let y = -LINK * (i + 1) as Real;
        let mass = if i + 1 == kinds.len() { 100.0 } else { 1.0 };
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, y)).with_mass(mass, mass * 0.0067))
            .unwrap();
        let up = Vec2::new(0.0, 0.5 * LINK);
        // The next joint hangs 0.1 m to the side: the load's weight turns
        // the links, so the weld's and the prismatic joint's angle rows
        // carry a torque.
        let down = Vec2::new(0.1, -0.5 * LINK);
        // Anchor on the previous body: below its centre (the ceiling: its
        // origin minus half a link).
        let anchor_a = if previous == ceiling {
            Vec2::new(0.0, -0.5 * LINK)
        } else {
            down
        };
        let def: JointDef = match *kind {
            "revolute" => RevoluteJointDef::new(previous, b, anchor_a, up).into(),
            "weld" => WeldJointDef::new(previous, b, anchor_a, up).into(),
            // Horizontal axis: the load hangs on the perpendicular row.
            "prismatic" => PrismaticJointDef::new(previous, b, anchor_a, up, Vec2::X).into(),
            "distance" => DistanceJointDef::new(previous, b, Vec2::ZERO, Vec2::ZERO, LINK).into(),
            _ => WheelJointDef::new(previous, b, anchor_a, up, Vec2::X).into(),
        };
        joints.push((world.create_joint(&def).unwrap(), *kind));
        bodies.push(b);
        previous = b;
    }
    Chain {
        world,
        joints,
        bodies,
    }
}

/// The worst error of each joint's equality rows: linear (m) and angular
/// (rad).
fn errors(c: &Chain) -> (Real, Real) {
    let (mut linear, mut angular) = (0.0 as Real, 0.0 as Real);
    for &(j, kind) in &c.joints {
        let w = &c.world;
        let (pa, pb) = w.joint_anchors(j).unwrap();
        let d = pb - pa;
        let base = w.joint(j).unwrap().def_base().clone();
        let axis = w
            .transform(base.body_a)
            .unwrap()
            .q
            .rotate(base.local_frame_a.axis());
        let e = match kind {
            "revolute" | "weld" => d.length(),
            "prismatic" | "wheel" => axis.perp().dot(d).abs(),
            _ => (d.length() - LINK).abs(),
        };
        linear = linear.max(e);
        if matches!(kind, "weld" | "prismatic") {
            angular = angular.max(w.joint_angle(j).unwrap().abs());
        }
    }
    (linear, angular)
}

fn run(direct: bool) -> (Real, Real, usize) {
    let mut c = chain(direct);
    let (mut linear, mut angular) = (0.0 as Real, 0.0 as Real);
    for step in 0..120 {
        c.world.step(1.0 / 60.0).unwrap();
        if step >= 60 {
            let (l, a) = errors(&c);
            linear = linear.max(l);
            angular = angular.max(a);
        }
    }
    let in_tree = c
        .joints
        .iter()
        .filter(|(j, _)| c.world.joint(*j).unwrap().in_tree())
        .count();
    let _ = &c.bodies;
    (linear, angular, in_tree)
}

#[test]
fn a_chain_of_every_equality_kind_is_one_exact_tree() {
    let (tree_linear, tree_angular, in_tree) = run(true);
    let (gs_linear, gs_angular, gs_in_tree) = run(false);
    if janus2d_testbed::support::report() {
        eprintln!(
            "mixed chain, 100:1: tree {tree_linear:.3e} m / {tree_angular:.3e} rad ({in_tree} joints in the tree), \
             Gauss–Seidel {gs_linear:.3e} m / {gs_angular:.3e} rad"
        );
    }
    assert_eq!(in_tree, 6, "every joint in the tree");
    assert_eq!(gs_in_tree, 0);
    // A directly solved row's static error under a force F is K F / ω²
    // with ω = 2π · 500 Hz (the direct joint softness; see weld.rs). The
    // worst row is the prismatic joint's perpendicular row: its arms turn
    // both 1 kg links (K ≈ 21 /kg) under the 1,000 N load, 2.1 mm
    // (measured 2.8 mm, f32); the point rows read 1 mm and less.
    assert!(tree_linear < 5e-3, "tree linear error {tree_linear} m");
    assert!(tree_angular < 1e-3, "tree angle error {tree_angular} rad");
    assert!(
        tree_linear * 20.0 < gs_linear,
        "tree {tree_linear} m not twenty times below Gauss–Seidel {gs_linear} m"
    );
}

/// Linear and angular momentum of a free tree (no static body, no
/// gravity) of prismatic, wheel and distance joints over one step from
/// random-looking velocities: the `General` rows' impulses are internal.
#[test]
fn a_free_tree_of_general_rows_keeps_its_momentum() {
    let mut def = WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    };
    // Every tree direct: this short free tree of like masses would
    // otherwise be left to Gauss–Seidel (direct_free_tree_mass_ratio).
    def.solver.direct_free_tree_mass_ratio = 0.0;
    let mut world = World::new(def).unwrap();
    let mut bodies = Vec::new();
    for i in 0..4 {
        let p = Vec2::new(0.7 * i as Real, 0.2 * (i % 2) as Real);
        let b = world
            .create_body(
                &BodyDef::dynamic(p)
                    .with_mass(1.0 + i as Real, 0.1 + 0.05 * i as Real)
                    .with_angle(0.3 * i as Real),
            )
            .unwrap();
        world
            .set_linear_velocity(b, Vec2::new(1.0 - 0.6 * i as Real, 0.4 * i as Real - 0.5))
            .unwrap();
        world
            .set_angular_velocity(b, 2.0 - 1.3 * i as Real)
            .unwrap();
        bodies.push(b);
    }
    let h = Vec2::new(0.35, 0.0);
    let defs: [JointDef; 3] = [
        PrismaticJointDef::new(bodies[0], bodies[1], h, -h, Vec2::new(1.0, 0.3)).into(),
        WheelJointDef::new(bodies[1], bodies[2], h, -h, Vec2::Y).into(),
        DistanceJointDef::new(bodies[2], bodies[3], h, -h, 0.1).into(),
    ];
    for d in &defs {
        world.create_joint(d).unwrap();
    }
    let momentum = |w: &World| {
        use janus2d_testbed::support::d;
        let (mut p, mut l) = ([0.0f64; 2], 0.0f64);
        for &b in &bodies {
            let m = d(w.mass(b).unwrap());
            let v = w.linear_velocity(b).unwrap();
            let x = w.center_of_mass(b).unwrap();
            p[0] += m * d(v.x);
            p[1] += m * d(v.y);
            l += m * (d(x.x) * d(v.y) - d(x.y) * d(v.x))
                + d(w.rotational_inertia(b).unwrap()) * d(w.angular_velocity(b).unwrap());
        }
        (p, l)
    };
    let (p0, l0) = momentum(&world);
    world.step(1.0 / 60.0).unwrap();
    assert!(
        world.joints().iter().all(|(_, j)| j.in_tree()),
        "all in the tree"
    );
    let (p1, l1) = momentum(&world);
    let scale = 10.0;
    let tol = 1e3 * janus2d_testbed::support::d(Real::EPSILON) * scale;
    assert!(
        (p1[0] - p0[0]).abs() < tol && (p1[1] - p0[1]).abs() < tol,
        "{p0:?} -> {p1:?}"
    );
    assert!((l1 - l0).abs() < tol, "{l0} -> {l1}");
}

/// A mouse joint to the ground pulling the last link of a pinned chain
/// (200 N toward a point above its end), and a filter joint between two
/// of its links, leave the chain one exact tree (before, any joint the
/// tree could not take made its whole component iterative): every
/// revolute joint is in the tree, and over 2 s of swinging the worst pin
/// gap is under a fifth of the same chain's under Gauss–Seidel (measured,
/// f32: 1.01 mm against 8.46 mm; the tree's is the direct softness's
/// static error under the swing's loads).
#[test]
fn a_mouse_or_filter_joint_leaves_a_chain_in_the_tree() {
    let (tree, in_tree) = pulled_chain(true);
    let (gs, _) = pulled_chain(false);
    if janus2d_testbed::support::report() {
        eprintln!("pulled chain: worst pin gap tree {tree:.3e} m, Gauss–Seidel {gs:.3e} m");
    }
    assert!(in_tree, "every pin in the tree");
    assert!(tree * 5.0 < gs, "tree {tree} m, Gauss–Seidel {gs} m");
}

/// The worst pin gap over 2 s and whether every pin ended in the tree.
fn pulled_chain(direct: bool) -> (Real, bool) {
    use janus2d::{FilterJointDef, MouseJointDef};
    let mut world = World::new(WorldDef {
        solver: SolverSettings {
            direct_joints: direct,
            ..SolverSettings::default()
        },
        sleep: SleepSettings {
            enabled: false,
            ..SleepSettings::default()
        },
        ..WorldDef::default()
    })
    .unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let mut previous = ground;
    let mut pins = Vec::new();
    let mut links = Vec::new();
    for i in 0..6 {
        let at = Vec2::new(0.5 * i as Real + 0.25, 0.0);
        let b = world
            .create_body(&BodyDef::dynamic(at).with_mass(1.0, 0.02))
            .unwrap();
        let anchor_a = if previous == ground {
            Vec2::ZERO
        } else {
            Vec2::new(0.25, 0.0)
        };
        let pin = RevoluteJointDef::new(previous, b, anchor_a, Vec2::new(-0.25, 0.0));
        pins.push(world.create_joint(&pin.into()).unwrap());
        links.push(b);
        previous = b;
    }
    let mouse = MouseJointDef::new(ground, links[5], Vec2::new(3.0, 1.0), 200.0);
    world.create_joint(&mouse.into()).unwrap();
    let filter = FilterJointDef::new(links[1], links[3]);
    world.create_joint(&filter.into()).unwrap();
    let mut worst: Real = 0.0;
    for _ in 0..120 {
        world.step(1.0 / 60.0).unwrap();
        for &p in &pins {
            worst = worst.max(world.joint_gap(p).unwrap());
        }
    }
    let in_tree = pins.iter().all(|&p| world.joint(p).unwrap().in_tree());
    (worst, in_tree)
}
