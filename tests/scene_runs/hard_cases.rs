//! Contact hard cases of the scene definitions (`janus2d_testbed`), at the shared settings
//! (4 substeps, sleep off), each with its bound. Box2D v3.1.1's figure at 4
//! substeps is quoted in each test's doc; set `JANUS2D_REPORT=1` to print
//! the measured figures.

use janus2d::prelude::*;
use janus2d_testbed::hard::{self, Figure};
use janus2d_testbed::janus::Janus;
use janus2d_testbed::scenes::{self, DT};

fn report() -> bool {
    std::env::var("JANUS2D_REPORT").is_ok()
}

/// Asserts every body is finite and none is below `floor` (centre height).
fn assert_sane(world: &World, floor: Real) {
    for h in world.body_handles() {
        if world.body_type(h).unwrap() != BodyType::Dynamic {
            continue;
        }
        let p = world.position(h).unwrap();
        assert!(p.is_finite(), "non-finite body {h:?}");
        assert!(p.y >= floor, "body {h:?} below ground: {p}");
    }
    assert!(world.events().non_finite_bodies.is_empty());
}

struct PyramidFigures {
    max_penetration: Real,
    sink: Real,
    drift: Real,
    last_second_speed: Real,
}

fn run_pyramid(base: usize, seconds: usize) -> PyramidFigures {
    run_pyramid_with(&scenes::shared_settings(), base, seconds)
}

fn run_pyramid_with(def: &WorldDef, base: usize, seconds: usize) -> PyramidFigures {
    let mut scene = scenes::large_pyramid(def, base);
    let top0 = scene.world.position(scene.probe).unwrap();
    let steps = seconds * 60;
    let mut f = PyramidFigures {
        max_penetration: 0.0,
        sink: 0.0,
        drift: 0.0,
        last_second_speed: 0.0,
    };
    for k in 0..steps {
        scene.world.step(DT).unwrap();
        f.max_penetration = f.max_penetration.max(scene.world.max_penetration());
        let p = scene.world.position(scene.probe).unwrap();
        f.sink = f.sink.max(top0.y - p.y);
        f.drift = f.drift.max((p.x - top0.x).abs());
        if k >= steps - 60 {
            f.last_second_speed = f
                .last_second_speed
                .max(scene.world.linear_velocity(scene.probe).unwrap().length());
        }
    }
    assert_sane(&scene.world, -0.01);
    f
}

/// Pyramid of base 20, 10 s: penetration ≤ 5 mm, top sinks ≤ 0.05 m, drifts ≤ 1 cm
/// [Box2D: 3.5 mm, 0.030 m, 0.8 mm].
#[test]
fn pyramid_20_stands_for_10_seconds() {
    let f = run_pyramid(20, 10);
    if report() {
        eprintln!(
            "pyramid 20: penetration {:.4} m, sink {:.4} m, drift {:.5} m",
            f.max_penetration, f.sink, f.drift
        );
    }
    assert!(
        f.max_penetration <= 0.005,
        "penetration {}",
        f.max_penetration
    );
    assert!(f.sink <= 0.05, "sink {}", f.sink);
    assert!(f.drift <= 0.01, "drift {}", f.drift);
}

/// Pyramid of base 100, 10 s: penetration ≤ 3 cm, sink ≤ 1 m, drift ≤ 5 cm,
/// top speed over the last second ≤ 0.01 m/s [Box2D: 2.1 cm, 0.73 m, 4 mm, 0.0004 m/s].
#[test]
fn large_pyramid_stands_for_10_seconds() {
    let f = run_pyramid(100, 10);
    if report() {
        eprintln!(
            "large pyramid: penetration {:.4} m, sink {:.4} m, drift {:.5} m, last-second speed {:.5} m/s",
            f.max_penetration, f.sink, f.drift, f.last_second_speed
        );
    }
    assert!(
        f.max_penetration <= 0.03,
        "penetration {}",
        f.max_penetration
    );
    assert!(f.sink <= 1.0, "sink {}", f.sink);
    assert!(f.drift <= 0.05, "drift {}", f.drift);
    assert!(f.last_second_speed <= 0.01, "speed {}", f.last_second_speed);
}

/// Builds a vertical stack of `rows` 1 m boxes (0.1 m gaps, x alternating
/// ±0.01, μ 0.3) and returns the time at which it fell (top box more than
/// 0.5 m from its start sideways or down), or `None` if it stood `seconds`.
fn vertical_stack(rows: usize, seconds: usize) -> Option<Real> {
    let scene = scenes::vertical_stack(&scenes::shared_settings(), rows);
    let (mut world, top) = (scene.world, scene.probe);
    let expected_y = 0.5 + (rows - 1) as Real;
    for k in 0..seconds * 60 {
        world.step(DT).unwrap();
        let p = world.position(top).unwrap();
        if k > 120 && ((p.y - expected_y).abs() > 0.5 || p.x.abs() > 0.5) {
            return Some((k + 1) as Real * DT);
        }
    }
    assert_sane(&world, -0.01);
    None
}

/// 12 rows stand 60 s [Box2D: 15 rows fall at 9.5 s, 20 rows at 6.5 s].
#[test]
fn vertical_stack_of_12_stands_60_seconds() {
    let fell = vertical_stack(12, 60);
    assert_eq!(fell, None, "12-row stack fell at {fell:?} s");
}

/// 15 rows stand 60 s [Box2D v3.1: falls at 9.5 s].
#[test]
fn vertical_stack_of_15_stands_60_seconds() {
    let fell15 = vertical_stack(15, 60);
    assert_eq!(fell15, None, "15-row stack fell at {fell15:?} s");
}

/// 20 rows stand 60 s (Box2D v3.1: falls at 6.5 s; Box2D v3.2 and Rapier
/// stand). Built as the spec defines it (x −0.01 on even rows, ground μ 0.6
/// and half-width 100). With the manifolds rebuilt every step it fell at
/// 11.2 s (the two normal rows as one block; point by point 4.9 s); with
/// contact recycling (the narrowphase keeps a manifold's normal and anchors
/// while its bodies move little relative to each other) it stands.
#[test]
fn vertical_stack_of_20_stands_60_seconds() {
    let fell20 = vertical_stack(20, 60);
    if report() {
        eprintln!("vertical stack: 20 rows fell at {fell20:?} s (None: stood 60 s)");
    }
    assert_eq!(fell20, None, "20-row stack fell at {fell20:?} s");
}

/// Runs a shared hard case (`janus2d_testbed::hard`) on janus2d with the
/// metric code every engine of the peers benchmark is measured by, prints
/// its figures under `JANUS2D_REPORT`, and asserts its bounds.
fn assert_case(case: hard::HardCase) {
    let outcome = case.run::<Janus>().unwrap();
    if report() {
        let figures: Vec<String> = case
            .bounds
            .iter()
            .map(|b| {
                format!(
                    "{} {:.5}",
                    b.figure().name(),
                    outcome.figures.get(b.figure())
                )
            })
            .collect();
        eprintln!(
            "{}: {} [Box2D: {}]",
            case.name,
            figures.join(", "),
            case.box2d
        );
    }
    assert!(outcome.pass, "{}: {:?}", case.name, outcome.failed);
}

/// 2×2 box dropped from y = 4, μ 0.5: after 90 steps |x|, |y − 1|, |angle| < 0.01.
#[test]
fn single_box_comes_to_rest_on_the_ground() {
    assert_case(hard::single_box());
}

/// 15 dominoes (half 0.125×0.5, spacing 1, μ 0.6), the first pushed at its
/// top with an impulse (0.2, 0): all 15 topple.
#[test]
fn double_domino_all_topple() {
    assert_case(hard::double_domino());
}

/// 625 overlapping circles inside capsule walls, g = 0: no escape, no NaN,
/// max speed over the last second < 0.01 m/s.
#[test]
fn confined_circles_stay_inside_and_settle() {
    assert_case(hard::confined());
}

/// Three pyramids of base 10 with 2 m boxes on a segment, heavy single top
/// boxes (100, 200, 300 times denser, 2 m higher): no box ends more than
/// 0.5 m sideways, penetration over the last second ≤ 6 cm [Box2D: stands,
/// 4.4 cm]. Measured with the block solve of the normal rows: 0.32 m,
/// 3.8 cm (point by point a pyramid gave way, 1.04 m).
#[test]
fn high_mass_ratio_1_pyramids_hold_heavy_tops() {
    assert_case(hard::high_mass_ratio_1());
}

/// Two 1 m boxes at x = ±9 on a ground segment, a 20 m box (400:1) dropped
/// from y = 26: no body below ground, resting penetration over the last
/// second ≤ 0.1 m [Box2D: 0.082 m].
#[test]
fn high_mass_ratio_2_big_box_on_small_boxes_segment_ground() {
    assert_case(hard::high_mass_ratio_drop(false));
}

/// As ratio 2 with a thick static box as ground: penetration ≤ 0.1 m [Box2D: 0.082 m].
#[test]
fn high_mass_ratio_3_big_box_on_small_boxes_box_ground() {
    assert_case(hard::high_mass_ratio_drop(true));
}

/// 40 capsule links (half-length 0.5, r 0.125, density 20) from a static pin
/// and a ball r 8 (density 20, ≈ 670:1) at the end, swinging down: no
/// explosion, peak joint gap ≤ 0.1 m [Box2D: 0.24 m].
///
/// The chain is a tree of joints, so its point rows are solved exactly
/// (`janus2d_constraints::joint_tree`, 500 Hz): measured 6 mm in f32
/// (0.022 m at 240 Hz).
/// Solved by Gauss–Seidel instead (`direct_joints = false`) the gap is the
/// soft joint's static deflection `F / (ρ ω² m_eff)` under the ball's pull
/// through 3 kg links, 0.22 m; `ball_and_chain_gauss_seidel_reference`
/// keeps that figure honest.
#[test]
fn ball_and_chain_peak_gap() {
    let (world, peak_gap) = run_ball_and_chain(&scenes::shared_settings());
    let bodies: Vec<BodyHandle> = world.body_handles().collect();
    if report() {
        eprintln!("ball and chain: peak joint gap {peak_gap:.4} m");
    }
    assert!(
        peak_gap <= 0.1,
        "peak gap {peak_gap} (bound 0.1 m, Box2D: 0.24 m)"
    );
    assert!(
        world
            .joint_handles()
            .iter()
            .all(|j| world.revolute_joint(*j).unwrap().in_tree())
    );
    assert!(
        bodies
            .iter()
            .all(|b| world.position(*b).unwrap().is_finite())
    );
}

/// Runs the ball and chain for 10 s; returns the world and the peak gap.
fn run_ball_and_chain(def: &WorldDef) -> (World, Real) {
    let mut world = scenes::ball_and_chain(def).world;
    let mut peak_gap: Real = 0.0;
    for _ in 0..600 {
        world.step(DT).unwrap();
        peak_gap = peak_gap.max(world.max_joint_gap());
    }
    (world, peak_gap)
}

/// The same scene with every joint left to Gauss–Seidel: the gap the direct
/// solve removes. Holds the iterative path at Box2D's 0.24 m and shows it
/// cannot meet 0.1 m (if it ever does, the tree solve's reason to exist
/// should be re-measured).
#[test]
fn ball_and_chain_gauss_seidel_reference() {
    let mut def = scenes::shared_settings();
    def.solver.direct_joints = false;
    let (world, peak_gap) = run_ball_and_chain(&def);
    if report() {
        eprintln!("ball and chain, Gauss–Seidel joints: peak joint gap {peak_gap:.4} m");
    }
    assert!(
        world
            .joint_handles()
            .iter()
            .all(|j| !world.revolute_joint(*j).unwrap().in_tree())
    );
    assert!(peak_gap <= 0.24, "peak gap {peak_gap} (Box2D: 0.24 m)");
    assert!(peak_gap > 0.1, "peak gap {peak_gap}");
}

/// `joint_grid` with N = 40 and doubled gravity: peak joint gap ≤ 0.2 m [Box2D: 0.20 m].
#[test]
fn joint_grid_40_peak_gap() {
    let def = WorldDef {
        gravity: Vec2::new(0.0, -20.0),
        ..scenes::shared_settings()
    };
    let mut scene = scenes::joint_grid(&def, 40);
    let mut peak_gap: Real = 0.0;
    for _ in 0..600 {
        scene.world.step(DT).unwrap();
        peak_gap = peak_gap.max(scene.world.max_joint_gap());
    }
    if report() {
        eprintln!("joint grid 40: peak joint gap {peak_gap:.4} m");
    }
    assert!(peak_gap <= 0.2, "peak gap {peak_gap}");
    assert_sane(&scene.world, -1000.0);
    // A grid is full of loops: its joints stay Gauss–Seidel (a stiff exact
    // tree mixed with soft loop rows diverged here at 240 Hz).
    let w = &scene.world;
    assert!(
        w.joint_handles()
            .iter()
            .all(|j| !w.revolute_joint(*j).unwrap().in_tree())
    );
}

/// Every shared hard case on janus2d (and the 1000:1 mass-ratio bob and
/// chain) at 1, 2, 4 and 8 substeps: prints each
/// case's bounded figures and whether it passes, and asserts that nothing
/// goes non-finite. A report, not a bound (the bounds are for 4 substeps);
/// minutes of work, so ignored: run it with
/// `cargo test --test scene_runs -- --ignored --nocapture hard_cases_by_substeps`
/// (`JANUS2D_CASES=a,b` picks cases, `JANUS2D_SUBSTEPS=1,2` substep counts).
#[test]
#[ignore = "report: every hard case at 1, 2, 4, 8 substeps (minutes)"]
fn hard_cases_by_substeps() {
    let pick = |var: &str| {
        std::env::var(var)
            .ok()
            .map(|s| s.split(',').map(str::to_owned).collect::<Vec<_>>())
    };
    let names = pick("JANUS2D_CASES");
    let substeps: Vec<u32> = pick("JANUS2D_SUBSTEPS")
        .map(|v| v.iter().filter_map(|s| s.parse().ok()).collect())
        .unwrap_or_else(|| vec![1, 2, 4, 8]);
    // The 1000:1 mass-ratio joint cases (their own tests below) too.
    let cases = hard::all().into_iter().chain([
        hard::mass_ratio_chain(1, 1000.0),
        hard::mass_ratio_chain(20, 1000.0),
    ]);
    for mut case in cases {
        if names
            .as_ref()
            .is_some_and(|n| !n.iter().any(|n| n == case.name))
        {
            continue;
        }
        for &n in &substeps {
            case.desc.settings.substeps = n;
            let outcome = case.run::<Janus>().unwrap();
            let figures: Vec<String> = case
                .bounds
                .iter()
                .map(|b| {
                    format!(
                        "{} {:.4}",
                        b.figure().name(),
                        outcome.figures.get(b.figure())
                    )
                })
                .collect();
            eprintln!(
                "{:<20} {n} substeps: {} {}  (peak speed {:.2} m/s, penetration {:.4} m)",
                case.name,
                if outcome.pass { "pass" } else { "FAIL" },
                figures.join(", "),
                outcome.figures.get(hard::Figure::PeakSpeed),
                outcome.figures.get(hard::Figure::Penetration),
            );
            assert_eq!(
                outcome.figures.get(hard::Figure::NonFinite),
                0.0,
                "{} at {n}",
                case.name
            );
        }
    }
}

/// The mass-ratio cases at ratios 10 to 1e5 (`RATIOS=a,b` picks): prints each
/// figure and whether it passes (the bounds are for 1000:1, see the tests
/// below). Ignored: `cargo test --test scene_runs -- --ignored --nocapture
/// mass_ratio_sweep`.
#[test]
#[ignore = "report: mass-ratio cases over ratios 10 to 1e5"]
fn mass_ratio_sweep() {
    for ratio in std::env::var("RATIOS")
        .ok()
        .map(|v| {
            v.split(',')
                .filter_map(|s| s.parse().ok())
                .collect::<Vec<f64>>()
        })
        .unwrap_or_else(|| vec![10.0, 100.0, 500.0, 700.0, 1000.0, 2000.0, 5000.0, 1e4, 1e5])
    {
        for case in [
            hard::mass_ratio_stack(ratio),
            hard::mass_ratio_chain(1, ratio),
            hard::mass_ratio_chain(20, ratio),
        ] {
            let outcome = case.run::<Janus>().unwrap();
            let f = case.bounds[0].figure();
            eprintln!(
                "{:<18} {ratio:>8}: {} {} {:.5}, {} {:.3}",
                case.name,
                if outcome.pass { "pass" } else { "FAIL" },
                f.name(),
                outcome.figures.get(f),
                Figure::PeakSpeed.name(),
                outcome.figures.get(Figure::PeakSpeed)
            );
        }
    }
}

/// Pyramid of base 100 at 2 substeps, 10 s: stands (top drifts ≤ 0.5 m,
/// top speed over the last second ≤ 0.05 m/s) and the top sinks ≤ 3 m
/// [Box2D v3.1 at 2 substeps: sinks 2.9 m and stands]. The contacts solve at
/// 1/8 of the substep rate, 15 Hz (`SolverSettings::effective_hertz`); at
/// 30 Hz the pyramid collapsed (sink 38 m).
#[test]
fn large_pyramid_stands_at_2_substeps() {
    let mut def = scenes::shared_settings();
    def.solver.substeps = 2;
    let f = run_pyramid_with(&def, 100, 10);
    if report() {
        eprintln!(
            "large pyramid, 2 substeps: sink {:.4} m, drift {:.4} m, last-second speed {:.5} m/s",
            f.sink, f.drift, f.last_second_speed
        );
    }
    assert!(f.sink <= 3.0, "sink {}", f.sink);
    assert!(f.drift <= 0.5, "drift {}", f.drift);
    assert!(f.last_second_speed <= 0.05, "speed {}", f.last_second_speed);
}

/// 40 circles with 1 m of error at every joint: every joint back within
/// 1 cm over the last second of 10 s, and no more speed than the chain
/// reaches by swinging alone (the whip, 67 m/s + 5%). The tree's
/// correction is capped at 2 m/s per joint at 500 Hz.
#[test]
fn stretched_chain_correction_adds_no_speed() {
    assert_case(hard::stretched_chain());
}

/// A bob of 1000:1 on a single light link (1 m, 1 kg), swinging down from
/// horizontal: both joints within 1 cm over 10 s. Measured 0.13 mm with the
/// tree's springs built on the heavy mass (`joint_tree::HEAVY_TREE_RATIO`);
/// 3 mm on the link's own mass (500 Hz), which first failed at 5000:1.
#[test]
fn mass_ratio_bob_1000_to_1_keeps_joints_within_1_cm() {
    assert_case(hard::mass_ratio_chain(1, 1000.0));
}

/// The bob at 10,000:1 (issue 33's ratio): both joints within 1 cm over
/// 10 s. Measured 0.27 mm; on the link's own mass 3.0 cm (its spring's
/// stretch under the 1e5 N load, three times that at the bottom of the
/// swing).
#[test]
fn mass_ratio_bob_10000_to_1_keeps_joints_within_1_cm() {
    assert_case(hard::mass_ratio_chain(1, 10_000.0));
}

/// A 1000:1 load at the end of a 20-link chain of light links, swinging
/// down from horizontal: every joint within 1 cm (measured 0.2 mm; on the
/// links' own masses 6.8 mm, first failing at 2000:1). Without the tree
/// solve's geometric stiffness term the middle joints opened to 1.75 m
/// as the chain swung taut (its zig-zag mode, integrated explicitly,
/// grew).
#[test]
fn mass_ratio_chain_1000_to_1_keeps_joints_within_1_cm() {
    assert_case(hard::mass_ratio_chain(20, 1000.0));
}

/// The 1000:1 chain at 2 substeps (half the default cost): every joint
/// within 1 cm over the 10 s. With the heavy springs' cap at 300× (as at 4
/// substeps) it diverged from about 6 s (5.4 m gaps, 212 m/s); the cap
/// scaled by the substep (`joint_tree::heavy_spring_factor`, 75×) holds
/// it to 0.7 mm, and 2,000:1 and 5,000:1 too (they diverged as well).
#[test]
fn mass_ratio_chain_1000_to_1_holds_its_joints_at_2_substeps() {
    for ratio in [1000.0, 5000.0] {
        let mut case = hard::mass_ratio_chain(20, ratio);
        case.desc.settings.substeps = 2;
        assert_case(case);
    }
}

/// The 20-link chain at 10,000:1: every joint within 1 cm. Measured 0.2
/// mm with the springs built on 300 times a link's mass
/// (`joint_tree::HEAVY_SPRING_FACTOR`); on the links' own it diverged
/// (9.2 km), and with no cap on the factor it diverged from 2000:1.
#[test]
fn mass_ratio_chain_10000_to_1_keeps_joints_within_1_cm() {
    assert_case(hard::mass_ratio_chain(20, 10_000.0));
}

/// The 20-link chain at 10:1, below the heavy-tree ratio (its springs on
/// the links' own masses): every joint within 1 cm (measured 8.3 mm).
#[test]
fn mass_ratio_chain_10_to_1_keeps_joints_within_1_cm() {
    assert_case(hard::mass_ratio_chain(20, 10.0));
}

/// The light box under a 10,000:1 box: it moves ≤ 5 cm sideways
/// (measured 0.05 mm, as at 1000:1: the coupled group below).
#[test]
fn mass_ratio_stack_10000_to_1_light_box_not_squeezed_out() {
    assert_case(hard::mass_ratio_stack(10_000.0));
}

/// A light box under a 1000:1 heavy box (0.1 m off centre) on the ground:
/// the light box moves ≤ 5 cm sideways. Measured 0.23 mm (penetration
/// 0.7 mm): the light box's contacts are solved as one coupled block with
/// springs built on the heavy box's mass (`contact_group`); no ratio from
/// 10:1 to 1e5:1 fails (1e5:1: 3.3 mm). Before: both soft contacts gave
/// under the load (penetration 31 cm), the pair tilted and the light box
/// moved 8.2 cm (first failing at 700:1).
#[test]
fn mass_ratio_stack_1000_to_1_light_box_not_squeezed_out() {
    assert_case(hard::mass_ratio_stack(1000.0));
}

/// Two light boxes (1 m, 1 kg) stacked on the ground under a 1000:1 box
/// 0.1 m off centre, 10 s: no box ends more than 5 cm sideways, and late
/// penetration ≤ 1 cm. The two light boxes form one light cluster, solved
/// as one coupled group (`contact_group`): measured 0.09 mm sideways at
/// the end (0.6 mm at most), late penetration 0.85 mm. With a group per light body (neither box is light
/// on its own: each touches the other) the heavy box sank through both
/// and threw them 4 m sideways.
#[test]
fn two_light_boxes_under_a_1000_to_1_box_hold_as_one_cluster() {
    use janus2d_testbed::desc::{BodyDesc, SceneDesc, ShapeDesc, square};
    let v = glam::DVec2::new;
    let mut d = SceneDesc::new("light_cluster_stack", 600);
    d.add(BodyDesc::fixed(v(0.0, -1.0)).with(ShapeDesc::new(square(50.0, 1.0)).friction(0.6)));
    for y in [0.5, 1.5] {
        d.add(BodyDesc::dynamic(v(0.0, y)).with(ShapeDesc::new(square(0.5, 0.5)).friction(0.6)));
    }
    d.add(
        BodyDesc::dynamic(v(0.1, 2.51)).with(
            ShapeDesc::new(square(0.5, 0.5))
                .friction(0.6)
                .density(1000.0),
        ),
    );
    assert_case(hard::HardCase {
        name: "light_cluster_stack",
        desc: d,
        steps: 600,
        bounds: vec![
            hard::Bound::AtMost(hard::Figure::MaxSideways, 0.05),
            hard::Bound::AtMost(hard::Figure::LatePenetration, 0.01),
        ],
        rest: None,
        box2d: "",
    });
}
