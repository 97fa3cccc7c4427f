//! Tests of `janus2d_testbed::metrics`: each metric against a motion whose answer is
//! known in closed form. No timing here (that lives in the accuracy bench).

use janus2d::prelude::*;
use janus2d_testbed::metrics::{
    self, ExtraMetric, Tracker, TrackerConfig, cases, free_fall_energy_loss, kinetic_energy,
    potential_energy, total_energy,
};

const DT: Real = 1.0 / 60.0;

/// The shared settings with sleep off, as in every stability test: a body
/// at rest must stay measurable.
fn awake() -> WorldDef {
    let mut def = WorldDef::default();
    def.sleep.enabled = false;
    def
}

fn zero_gravity() -> World {
    World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..awake()
    })
    .unwrap()
}

fn run(tracker: &mut Tracker, world: &mut World, steps: usize) {
    for _ in 0..steps {
        tracker.step(world, DT).unwrap();
    }
}

/// A 2 kg body falls freely from y = 10 for 1 s (60 steps × 4 substeps).
/// The only energy it may lose is semi-implicit Euler's own
/// `240 · ½ m g² h²` = 0.4167 J, out of 100 J of kinetic energy at 1 s.
/// f32 bound on what remains: positions near 10 m round to ±5e-7 m and
/// speeds near 10 m/s to ±5e-7 m/s at each of 240 substeps; even all
/// rounding one way (≤ 1.2e-4 m, ≤ 1.2e-4 m/s) is ≤ 5e-3 J of the 200 J in
/// play, and accumulated at random it is well below the 2e-3 J asserted.
#[test]
fn free_fall_energy_drift_is_only_the_integrators() {
    let mut world = World::new(awake()).unwrap();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 10.0)).with_mass(2.0, 0.5))
        .unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(body)).unwrap();
    // E0 = −m g·c = 2 · 10 · 10 J.
    assert!((tracker.metrics().initial_energy - 200.0).abs() < 1e-4);
    run(&mut tracker, &mut world, 60);
    let m = tracker.metrics();
    let h = 1.0 / 240.0;
    let expected_loss = free_fall_energy_loss(2.0, 10.0, h, 240);
    assert!((expected_loss - 0.416_667).abs() < 1e-5, "{expected_loss}");
    let drift = m.energy_drift();
    assert!(
        (drift + expected_loss).abs() < 2e-3,
        "energy drift {drift} J, integrator's own {expected_loss} J"
    );
    // No energy was created at any step, and the error is small against
    // the motion: under 0.5 % of the kinetic energy at 1 s.
    assert!(m.max_energy_gain < 2e-3, "gain {}", m.max_energy_gain);
    assert!(
        m.relative_energy_error() < 5e-3,
        "{}",
        m.relative_energy_error()
    );
    assert!(
        (m.peak_kinetic_energy - 100.0).abs() < 0.5,
        "{}",
        m.peak_kinetic_energy
    );
    // Sink: after n substeps y0 − y = g h² n (n + 1) / 2 = 5.0208 m.
    let sink = 10.0 * h * h * 240.0 * 241.0 / 2.0;
    assert!(
        (m.max_sink - sink).abs() < 1e-3,
        "sink {} vs {sink}",
        m.max_sink
    );
    assert!((m.final_sink - sink).abs() < 1e-3);
    assert!(m.max_drift < 1e-6);
    assert!((m.peak_speed - 10.0).abs() < 1e-3, "speed {}", m.peak_speed);
    assert_eq!(m.steps, 60);
    assert!((m.time - 1.0).abs() < 1e-6);
}

/// Energies by hand: a spinning, moving, raised body in known gravity.
#[test]
fn energy_terms_match_hand_computation() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::new(0.0, -9.0),
        ..awake()
    })
    .unwrap();
    let def = BodyDef::dynamic(Vec2::new(1.0, 3.0))
        .with_mass(4.0, 0.5)
        .with_velocity(Vec2::new(3.0, 4.0))
        .with_angular_velocity(2.0);
    world.create_body(&def).unwrap();
    let mut floating = BodyDef::dynamic(Vec2::new(0.0, 100.0)).with_mass(7.0, 1.0);
    floating.gravity_scale = 0.0;
    world.create_body(&floating).unwrap();
    // Static bodies carry no energy.
    world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 50.0)))
        .unwrap();
    // ½·4·25 + ½·0.5·4 = 51 J; −m g·c = 4 · 9 · 3 = 108 J.
    assert!((kinetic_energy(&world) - 51.0).abs() < 1e-4);
    assert!((potential_energy(&world) - 108.0).abs() < 1e-4);
    assert!((total_energy(&world) - 159.0).abs() < 1e-4);
    assert!((metrics::max_speed(&world) - 5.0).abs() < 1e-5);
}

/// A free spinning body in zero gravity keeps its energy exactly.
#[test]
fn spinning_body_conserves_energy() {
    let mut world = zero_gravity();
    let body = world
        .create_body(
            &BodyDef::dynamic(Vec2::ZERO)
                .with_mass(1.0, 0.5)
                .with_angular_velocity(2.0),
        )
        .unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(body)).unwrap();
    assert!((tracker.metrics().initial_energy - 1.0).abs() < 1e-6);
    run(&mut tracker, &mut world, 120);
    let m = tracker.metrics();
    assert!(
        m.relative_energy_error() < 1e-5,
        "{}",
        m.relative_energy_error()
    );
    assert!(m.max_drift < 1e-6 && m.max_sink < 1e-6);
}

/// A body teleported 1 m sideways drifts 1 m; back the other way, the
/// maximum stays 1 m and the final value is signed.
#[test]
fn sideways_move_of_one_metre_is_drift_of_one_metre() {
    let mut world = zero_gravity();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::new(2.0, 3.0)))
        .unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(body)).unwrap();
    world.set_transform(body, Vec2::new(3.0, 3.0), 0.0).unwrap();
    tracker.step(&mut world, DT).unwrap();
    let m = tracker.metrics();
    assert!((m.max_drift - 1.0).abs() < 1e-6, "drift {}", m.max_drift);
    assert!((m.final_drift - 1.0).abs() < 1e-6);
    assert!(m.max_sink.abs() < 1e-6);
    world.set_transform(body, Vec2::new(1.5, 3.5), 0.0).unwrap();
    tracker.step(&mut world, DT).unwrap();
    let m = tracker.metrics();
    assert!((m.max_drift - 1.0).abs() < 1e-6);
    assert!((m.final_drift + 0.5).abs() < 1e-6);
    // Half a metre up is a sink of −0.5 m; the largest sink is still 0.
    assert!((m.final_sink + 0.5).abs() < 1e-6);
    assert!(m.max_sink.abs() < 1e-6);
}

/// At 1 m/s the probe leaves a box of half width 0.5 m at t = 0.5 s (the
/// step that ends there or the next, by rounding); with a 1 s grace the
/// collapse is the first step after the grace.
#[test]
fn collapse_time_is_when_the_probe_leaves_its_box() {
    for (grace, lo, hi) in [(0.0, 0.5, 0.5 + 1.5 * DT), (1.0, 61.0 * DT, 61.0 * DT)] {
        let mut world = zero_gravity();
        let body = world
            .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(1.0, 0.0)))
            .unwrap();
        let config =
            TrackerConfig::probe(body).with_collapse_box(Vec2::ZERO, Vec2::new(0.5, 0.5), grace);
        let mut tracker = Tracker::new(&world, config).unwrap();
        run(&mut tracker, &mut world, 120);
        let t = tracker.metrics().collapse_time.expect("left the box") as Real;
        assert!(
            t >= lo - 1e-5 && t <= hi + 1e-5,
            "grace {grace}: collapse at {t}"
        );
    }
    // A body at rest never collapses.
    let mut world = zero_gravity();
    let body = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(body)).unwrap();
    run(&mut tracker, &mut world, 60);
    assert_eq!(tracker.metrics().collapse_time, None);
}

/// Peak speed is 5 m/s for a body at (3, 4) m/s; the late window sees only
/// the steps after it opens.
#[test]
fn peak_and_late_speeds() {
    let mut world = zero_gravity();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(3.0, 4.0)))
        .unwrap();
    let config = TrackerConfig::probe(body).with_late_from(0.5);
    let mut tracker = Tracker::new(&world, config).unwrap();
    run(&mut tracker, &mut world, 30);
    assert_eq!(
        tracker.metrics().late_probe_speed,
        0.0,
        "step 30 ends at 0.5 s: not late"
    );
    world
        .set_linear_velocity(body, Vec2::new(0.0, 1.0))
        .unwrap();
    run(&mut tracker, &mut world, 30);
    let m = tracker.metrics();
    assert!((m.peak_speed - 5.0).abs() < 1e-5, "{}", m.peak_speed);
    assert!(
        (m.late_probe_speed - 1.0).abs() < 1e-6,
        "{}",
        m.late_probe_speed
    );
    assert!((m.late_peak_speed - 1.0).abs() < 1e-6);
}

/// A unit box placed 0.1 m deep in the ground (g = 0): the first step sees
/// the full 0.1 m, the push-out (≤ 3 m/s) clears it, and by the last second
/// only the resting overlap (linear slop, 5 mm) may remain.
#[test]
fn penetration_is_seen_then_resolved() {
    let mut world = zero_gravity();
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 1.0))
        .unwrap();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.4)))
        .unwrap();
    world
        .create_shape(body, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(body).with_late_from(1.0)).unwrap();
    run(&mut tracker, &mut world, 120);
    let m = tracker.metrics();
    assert!(
        m.max_penetration > 0.09 && m.max_penetration < 0.1001,
        "max penetration {}",
        m.max_penetration
    );
    assert!(
        m.late_max_penetration < 0.006,
        "late {}",
        m.late_max_penetration
    );
    assert!(
        m.final_sink < -0.09,
        "pushed up by about 0.1 m: {}",
        m.final_sink
    );
}

/// A joint created 0.5 m apart (g = 0): its gap is the worst on the first
/// step and closes afterwards.
#[test]
fn joint_gap_peaks_first_then_closes() {
    let mut world = zero_gravity();
    let pin = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let bob = world
        .create_body(&BodyDef::dynamic(Vec2::new(1.5, 0.0)).with_mass(1.0, 0.1))
        .unwrap();
    world
        .create_revolute_joint(&RevoluteJointDef::new(
            pin,
            bob,
            Vec2::ZERO,
            Vec2::new(-1.0, 0.0),
        ))
        .unwrap();
    let before = world.max_joint_gap();
    assert!((before - 0.5).abs() < 1e-6);
    let mut tracker = Tracker::new(&world, TrackerConfig::probe(bob).with_late_from(1.0)).unwrap();
    tracker.step(&mut world, DT).unwrap();
    let first = world.max_joint_gap();
    assert_eq!(tracker.metrics().max_joint_gap as Real, first);
    assert!(first < 0.5 && first > 0.0, "{first}");
    run(&mut tracker, &mut world, 119);
    let m = tracker.metrics();
    assert_eq!(m.max_joint_gap as Real, first);
    assert!(
        m.late_max_joint_gap < 1e-3,
        "late gap {}",
        m.late_max_joint_gap
    );
}

struct StepCounter(f64);

impl ExtraMetric for StepCounter {
    fn name(&self) -> &'static str {
        "step_counter"
    }
    fn unit(&self) -> &'static str {
        "1"
    }
    fn measure(&mut self, _world: &World) -> Option<f64> {
        self.0 += 1.0;
        // Applies on every other step only.
        (self.0 as u64 % 2 == 1).then_some(self.0)
    }
}

/// An extra metric's peak is kept and appears as the last column.
#[test]
fn extra_metric_becomes_a_column() {
    let mut world = zero_gravity();
    world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let mut tracker = Tracker::new(&world, TrackerConfig::default())
        .unwrap()
        .with_extra(Box::new(StepCounter(0.0)));
    run(&mut tracker, &mut world, 10);
    let m = tracker.metrics();
    assert_eq!(m.extras[0].peak, Some(9.0));
    assert_eq!(m.extras[0].last, Some(9.0));
    let cols = m.columns();
    let last = cols.last().unwrap();
    assert_eq!(
        (last.name, last.unit, last.value),
        ("step_counter", "1", Some(9.0))
    );
    assert!(
        cols.iter()
            .any(|c| c.name == "collapse_time" && c.value.is_none())
    );
    let names: Vec<_> = cols.iter().map(|c| c.name).collect();
    let mut unique = names.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "column names are unique");
}

/// The sweep's hard scenes are built as the spec says.
#[test]
fn hard_cases_are_built_as_specified() {
    let def = awake();
    let chain = cases::ball_and_chain(&def);
    assert_eq!(
        (chain.world.body_count(), chain.world.joint_count()),
        (42, 41)
    );
    // Ball r 8, density 20: m = 20 π 64.
    let ball_mass = chain.world.mass(chain.probe).unwrap();
    assert!((ball_mass - 20.0 * janus2d::base::math::PI * 64.0).abs() < 0.5);
    let bridge = cases::bridge(&def);
    assert_eq!(
        (bridge.world.body_count(), bridge.world.joint_count()),
        (161, 161)
    );
    assert_eq!(
        bridge.world.position(bridge.probe).unwrap(),
        Vec2::new(0.5, 0.0)
    );
    let stack = cases::vertical_stack(&def, 15, 60);
    assert_eq!((stack.world.body_count(), stack.steps), (16, 3600));
    // Row 14 is even: x = −0.01 (the spec's offsets); y to rounding of
    // the f64 description.
    let top = stack.world.position(stack.probe).unwrap();
    assert!(
        (top - Vec2::new(-0.01, 0.55 + 1.1 * 14.0)).length() < 1e-5,
        "top box at {top}"
    );
    let pyramid = cases::pyramid(&def, 20, 600, 0.5);
    assert_eq!(pyramid.world.body_count(), 211);
    assert!((pyramid.config.late_from - 9.0).abs() < 1e-5);
}

/// A short stack settles and stands: its top sinks by the gaps it closes
/// (3 rows: 0.05 m above the ground, then 2 × 0.1 m: 0.25 m, plus a few
/// millimetres of resting overlap), nothing collapses, energy only leaves.
#[test]
fn short_stack_stands_and_loses_energy() {
    let mut case = cases::vertical_stack(&awake(), 3, 5);
    let mut tracker = case.tracker();
    run(&mut tracker, &mut case.world, case.steps);
    let m = tracker.metrics();
    assert_eq!(m.collapse_time, None);
    assert!(
        m.final_sink > 0.25 && m.final_sink < 0.27,
        "sink {}",
        m.final_sink
    );
    assert!(m.max_energy_gain < 1e-3, "gain {}", m.max_energy_gain);
    assert!(
        m.late_probe_speed < 0.01,
        "late speed {}",
        m.late_probe_speed
    );
    assert_eq!(m.non_finite_steps, 0);
}

/// The portal metrics: a box pushed through an η = 1 pair of static portals
/// with gravity off keeps its η-scaled momentum (to f32 round-off) and the
/// constraint error stays below a millimetre.
#[cfg(feature = "portals")]
#[test]
fn portal_metrics_measure_a_passive_crossing() {
    use janus2d::world::{PortalDef, PortalPairDef};
    use janus2d_testbed::metrics::{ExtraMetric, PortalMapError, PortalMomentumError};
    let mut world = zero_gravity();
    let wall = |world: &mut World, p: Vec2| {
        let b = world.create_body(&BodyDef::fixed(p)).unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 3.0))
            .unwrap();
        b
    };
    let (a, b) = (
        wall(&mut world, Vec2::new(0.5, 0.0)),
        wall(&mut world, Vec2::new(-0.5, 20.0)),
    );
    let portal = |body, anchor, direction| PortalDef {
        body,
        anchor,
        direction,
        half_width: 1.0,
    };
    world
        .create_portal_pair(&PortalPairDef::new(
            portal(a, Vec2::new(-0.5, 0.0), -Vec2::X),
            portal(b, Vec2::new(0.5, 0.0), Vec2::X),
        ))
        .unwrap();
    let body = world
        .create_body(&BodyDef::dynamic(Vec2::new(-2.0, 0.2)).with_velocity(Vec2::new(3.0, 0.0)))
        .unwrap();
    world
        .create_shape(body, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
        .unwrap();
    let (mut c, mut p) = (PortalMapError, PortalMomentumError::default());
    let (mut worst_c, mut worst_p, mut seen) = (0.0f64, 0.0f64, 0);
    for _ in 0..90 {
        world.step(1.0 / 60.0).unwrap();
        if let (Some(ec), Some(ep)) = (c.measure(&world), p.measure(&world)) {
            worst_c = worst_c.max(ec);
            worst_p = worst_p.max(ep);
            seen += 1;
        }
    }
    assert!(seen > 3, "the box never straddled");
    assert!(worst_c < 1e-3, "|C| {worst_c}");
    #[cfg(not(feature = "f64"))]
    let tol = 1e-5;
    #[cfg(feature = "f64")]
    let tol = 1e-12;
    assert!(worst_p < tol, "η-momentum error {worst_p}");
}
