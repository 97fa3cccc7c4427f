//! Joint-only hard cases of the scene definitions (`janus2d_testbed`): the stretched chain
//! and the 160-plank bridge (planks need no collision here).

use janus2d::prelude::*;
use janus2d_testbed::janus::Janus;
use janus2d_testbed::{hard, scenes};

const DT: Real = 1.0 / 60.0;

fn report() -> bool {
    std::env::var("JANUS2D_REPORT").is_ok()
}

fn max_speed(world: &World, bodies: &[BodyHandle]) -> Real {
    bodies
        .iter()
        .map(|b| world.linear_velocity(*b).unwrap().length())
        .fold(0.0, Real::max)
}

/// 40 circles r 0.25 (density 1: m = π r², I = m r²/2), rest spacing 1 but
/// placed 2 apart: 1 m of error at every joint; the first is hinged to a
/// static body; gravity on.
///
/// What this test holds: every joint is back within 1 cm before 10 s, and
/// the peak speed beats Box2D v3.1's 273 m/s (the hard case's own bound,
/// no more speed than the unstretched chain's whip, is
/// `hard_cases::stretched_chain_correction_adds_no_speed`). Measured (f32,
/// the chain solved directly at 500 Hz with its correction capped at 2 m/s
/// per joint): peak 68 m/s; the same chain built *without* stretch whips
/// its free end to about 67 m/s under gravity (a physical whip of a 40 m
/// chain released horizontally), see `unstretched_chain_whip_reference`.
#[test]
fn stretched_chain_recovers_within_10_seconds() {
    let (peak_speed, recovered_at, gap_at_10s) = run_chain(2.0);
    if report() {
        eprintln!(
            "stretched chain: all gaps <= 1 cm first at {recovered_at:?} s, gap at 10 s {gap_at_10s:.4} m, peak speed {peak_speed:.2} m/s"
        );
    }
    let t = recovered_at.expect("joints never came back within 1 cm");
    assert!(t < 10.0, "recovered only at {t} s");
    assert!(
        peak_speed < 273.0,
        "peak speed {peak_speed} m/s (Box2D: 273)"
    );
}

/// The unstretched chain under gravity: how fast the free end whips with no
/// initial error at all (the reference for the stretched chain's speed).
#[test]
fn unstretched_chain_whip_reference() {
    let (peak_speed, recovered_at, _) = run_chain(1.0);
    if report() {
        eprintln!("unstretched chain: peak speed {peak_speed:.2} m/s");
    }
    assert_eq!(recovered_at, Some(1.0 / 60.0), "no error to recover from");
    assert!(
        peak_speed > 20.0,
        "the physical whip exceeds 20 m/s: {peak_speed}"
    );
}

/// Runs the chain with link spacing `spacing` for 10 s; returns the peak
/// speed, the first time every gap is ≤ 1 cm, and the largest gap at 10 s.
fn run_chain(spacing: Real) -> (Real, Option<Real>, Real) {
    // The shared description: 40 non-colliding circles r 0.25 (density 1).
    let scene = scenes::build(
        &hard::chain_scene(janus2d::base::math::to_f64(spacing)),
        &scenes::shared_settings(),
    );
    let links = scene.bodies[1..].to_vec();
    let mut world = scene.world;
    let mut peak_speed: Real = 0.0;
    let mut recovered_at = None;
    for k in 0..600 {
        world.step(DT).unwrap();
        peak_speed = peak_speed.max(max_speed(&world, &links));
        if recovered_at.is_none() && world.max_joint_gap() <= 0.01 {
            recovered_at = Some((k + 1) as Real * DT);
        }
        assert!(world.events().non_finite_bodies.is_empty());
    }
    (peak_speed, recovered_at, world.max_joint_gap())
}

/// 160 planks half 0.5×0.125 (density 20), linear damping 0.1, hinged end to
/// end, both ends pinned.
#[test]
fn bridge_joint_gap_over_last_second() {
    let mut world = scenes::bridge(&scenes::shared_settings()).world;
    let planks: Vec<BodyHandle> = world
        .body_handles()
        .filter(|h| world.body_type(*h) == Ok(BodyType::Dynamic))
        .collect();
    let mut peak_gap_last: Real = 0.0;
    let mut peak_speed: Real = 0.0;
    for k in 0..600 {
        world.step(DT).unwrap();
        peak_speed = peak_speed.max(max_speed(&world, &planks));
        if k >= 540 {
            peak_gap_last = peak_gap_last.max(world.max_joint_gap());
        }
    }
    if report() {
        eprintln!(
            "bridge: peak gap over last second {peak_gap_last:.5} m, peak speed {peak_speed:.3} m/s"
        );
    }
    assert!(peak_gap_last <= 0.02, "bridge gap {peak_gap_last} m");
    assert!(
        planks
            .iter()
            .all(|b| world.position(*b).unwrap().is_finite())
    );
}

/// A 10 kg bob hanging at rest from a pin under g = 10 m/s²: the joint
/// reads 100 N upwards on the bob (per step, not per substep), at 4 and 8
/// substeps, with and without the tree solve, and still once it sleeps.
#[test]
fn joint_read_back_is_the_force_over_the_step_and_holds_after_sleep() {
    for (substeps, direct) in [(4, true), (8, true), (4, false)] {
        let mut def = WorldDef {
            gravity: Vec2::new(0.0, -10.0),
            ..WorldDef::default()
        };
        def.solver.substeps = substeps;
        def.solver.direct_joints = direct;
        let mut world = World::new(def).unwrap();
        let pin = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let bob = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, -1.0)).with_mass(10.0, 0.1))
            .unwrap();
        let joint = world
            .create_revolute_joint(&RevoluteJointDef::new(
                pin,
                bob,
                Vec2::ZERO,
                Vec2::new(0.0, 1.0),
            ))
            .unwrap();
        for _ in 0..60 {
            world.step(1.0 / 60.0).unwrap();
        }
        let f = world.joint_force(joint).unwrap();
        assert!(
            (f.y - 100.0).abs() < 1.0 && f.x.abs() < 1.0,
            "{substeps} substeps, direct {direct}: {f}"
        );
        for _ in 0..120 {
            world.step(1.0 / 60.0).unwrap();
        }
        assert!(world.is_sleeping(bob).unwrap(), "the bob sleeps");
        let f = world.joint_force(joint).unwrap();
        assert!((f.y - 100.0).abs() < 1.0, "asleep: {f}");
        assert!(world.joint_torque(joint).unwrap().abs() < 1e-3);
    }
}

/// One member of the stretched-chain family at `substeps`: (its peak
/// speed, its unstretched twin's, its late joint gap).
fn family_figures(case: &hard::ChainFamilyCase, substeps: u32) -> (f64, f64, f64) {
    let run = |desc: &janus2d_testbed::desc::SceneDesc| {
        let mut desc = desc.clone();
        desc.settings.substeps = substeps;
        let case = hard::HardCase {
            name: "stretched_chain_family",
            desc,
            steps: 600,
            bounds: vec![],
            rest: None,
            box2d: "",
        };
        case.run::<Janus>().unwrap().figures
    };
    let stretched = run(&case.stretched);
    let unstretched = run(&case.unstretched);
    (
        stretched.get(hard::Figure::PeakSpeed),
        unstretched.get(hard::Figure::PeakSpeed),
        stretched.get(hard::Figure::LateJointGap),
    )
}

/// The stretched-chain family (`hard::stretched_chain_family`: lying,
/// hanging, 45°; 1.5×, 2×, 3×; 20 and 40 links; circles and capsules) at
/// 1, 2, 4 and 8 substeps (`JANUS2D_SUBSTEPS=a,b` picks): each member's
/// peak speed beside its bound (the unstretched twin's peak + 5%, at least
/// 3 m/s hanging) and its late joint gap (bound 1 cm). A report:
/// `cargo test --release --test scene_runs -- --ignored --nocapture stretched_chain_family_report`.
#[test]
#[ignore = "report: the stretched-chain family at 1, 2, 4, 8 substeps"]
fn stretched_chain_family_report() {
    let substeps: Vec<u32> = std::env::var("JANUS2D_SUBSTEPS")
        .ok()
        .map(|v| v.split(',').filter_map(|s| s.parse().ok()).collect())
        .unwrap_or_else(|| vec![1, 2, 4, 8]);
    for &n in &substeps {
        let mut passed = 0;
        let family = hard::stretched_chain_family();
        for case in &family {
            let (peak, twin, late_gap) = family_figures(case, n);
            let bound = case.speed_bound(twin);
            let pass = peak <= bound && late_gap <= 0.01;
            passed += usize::from(pass);
            eprintln!(
                "{n} substeps {:<26} {} peak {peak:8.2} m/s (bound {bound:7.2}, twin {twin:7.2}) late gap {late_gap:.4} m",
                case.name,
                if pass { "pass" } else { "FAIL" },
            );
        }
        eprintln!("{n} substeps: {passed} of {} pass", family.len());
    }
}

/// The members of the stretched-chain family that miss their bounds at
/// `substeps`, with their figures.
fn family_misses(substeps: u32) -> Vec<String> {
    let mut misses = Vec::new();
    for case in hard::stretched_chain_family() {
        let (peak, twin, late_gap) = family_figures(&case, substeps);
        let bound = case.speed_bound(twin);
        if report() {
            eprintln!(
                "{substeps} substeps {:<26} peak {peak:.2} m/s (bound {bound:.2}) late gap {late_gap:.4} m",
                case.name
            );
        }
        if peak > bound || late_gap > 0.01 {
            misses.push(format!(
                "{}: peak {peak:.2} m/s (bound {bound:.2}), late gap {late_gap:.4} m",
                case.name
            ));
        }
    }
    misses
}

/// Issue 33: a chain stretched and released from rest gains no speed from
/// its correction, in any pose. All 36 members of the family (lying,
/// hanging, 45°; 1.5×, 2×, 3×; 20 and 40 links; circles and capsules) at
/// 4 substeps: peak speed within 5% of the same chain built unstretched
/// (hanging: at most 3 m/s, the unstretched chain does not move), every
/// joint within 1 cm over the last second. Measured (f32): hanging chains
/// peak at 0.8–2.1 m/s; before the correction pass moved the large errors
/// on pseudo-velocities, 4 of 36 passed and hanging chains reached
/// 13–48 m/s.
#[test]
fn stretched_chain_family_gains_no_speed_from_its_correction_at_4_substeps() {
    let misses = family_misses(4);
    assert!(misses.is_empty(), "{misses:#?}");
}

/// Issue 33: the same family at 8 substeps (before the correction pass: 1
/// of 36).
#[test]
fn stretched_chain_family_gains_no_speed_from_its_correction_at_8_substeps() {
    let misses = family_misses(8);
    assert!(misses.is_empty(), "{misses:#?}");
}
