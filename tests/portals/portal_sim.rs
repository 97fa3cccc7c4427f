//! Simulation tests of the portal constraint: bodies linked only by the
//! constraint, stepped with `solve_step` (no world, no collision), default
//! solver settings (4 substeps, joints 60 Hz / ζ 2, no correction-speed cap),
//! dt = 1/60 s, gravity 0.
//!
//! `JANUS2D_REPORT=1` prints the measured worst figures.

use janus2d_constraints::portal::PortalConstraint;
use janus2d_constraints::portal_map::Portal;
use janus2d_core::body::BodyType;
use janus2d_core::math::{EPSILON, PI, Real, TAU, Vec2, cross};
use janus2d_core::solver::{SolverSettings, solve_step};
use janus2d_testbed::support::report;
use janus2d_testbed::support::*;

const DT: Real = 1.0 / 60.0;

/// Relative tolerance of the momentum checks (the brief's figures).
#[cfg(feature = "f64")]
const MOMENTUM_TOL: f64 = 1e-10;
#[cfg(not(feature = "f64"))]
const MOMENTUM_TOL: f64 = 1e-5;

/// Position error bound, m.
const MAX_C: Real = 1.0e-3;

/// SplitMix64: a small deterministic generator for the random impulses.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> Real {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        (lo + (hi - lo) * u) as Real
    }
}

fn portal(anchor: Vec2, direction: Vec2, half_width: Real) -> Portal {
    Portal::new(anchor, direction, half_width).unwrap()
}

/// Same material on both sides: `m2 = η² m1`, `I2 = η⁴ I1`.
fn same_material_clone(body: &BodySpec, eta: Real) -> BodySpec {
    BodySpec {
        mass: eta * eta * body.mass,
        inertia: eta * eta * eta * eta * body.inertia,
        local_center: eta * body.local_center,
        ..body.clone()
    }
}

/// A body about to enter portal 1 and its exact clone behind portal 2.
fn case(a: BodySpec, b: BodySpec, same_ab: bool, eta: Real) -> PortalCase {
    let portal_a = portal(Vec2::new(0.8, 0.3), Vec2::new(1.0, 0.4), 1.0);
    let portal_b = portal(Vec2::new(-0.5, 0.6), Vec2::new(-0.3, 1.0), eta);
    let mut body = BodySpec::dynamic(Vec2::ZERO, 2.0, 0.4);
    body.local_center = Vec2::new(0.1, -0.05);
    body.angle = 0.3;
    let mut case = PortalCase {
        body,
        clone: BodySpec::dynamic(Vec2::ZERO, 1.0, 1.0),
        a,
        b,
        same_ab,
        portal_a,
        portal_b,
        eta,
    };
    // Half a metre in front of portal 1, moving in at 1 m/s and turning.
    let f1 = case.map().frame1;
    case.body.center = f1.point + 0.5 * f1.normal + 0.2 * f1.tangent;
    case.body.v = -1.0 * f1.normal + 0.3 * f1.tangent;
    case.body.w = 0.7;
    case.clone = same_material_clone(&case.body, eta);
    case.place_clone_exactly();
    case
}

fn step(built: &mut Built, batch: &mut Vec<PortalConstraint>, settings: &SolverSettings) {
    let ctx = settings.context(DT, Vec2::ZERO);
    let report = solve_step(settings, &ctx, &mut built.set, &mut [batch]);
    assert!(report.non_finite.is_empty());
}

#[test]
fn static_portals_keep_eta_scaled_momentum_under_random_impulses() {
    let settings = SolverSettings::default();
    let mut worst_c: Real = 0.0;
    let mut worst_angle: Real = 0.0;
    let mut worst_p: f64 = 0.0;
    let mut worst_l: f64 = 0.0;
    for (n, eta) in [0.5, 1.0, 2.0].into_iter().enumerate() {
        let a = BodySpec::fixed(Vec2::new(-1.0, 0.5), 0.4);
        let b = BodySpec::fixed(Vec2::new(7.0, -2.0), -1.1);
        let case = case(a, b, false, eta);
        let mut built = case.build();
        let [body, clone, ..] = built.handles;
        let map = built.constraint.map(&built.set);
        let q = map.rotation();
        let mut batch = vec![built.constraint.clone()];
        let (mut expected, _) = scaled_momentum(&built.set, body, clone, &map);
        let mut rng = Rng(0x5eed + n as u64);
        for i in 0..1000 {
            if i % 5 == 0 {
                // A random impulse on either copy at a random point, giving
                // up to ~0.5 m/s and ~1 rad/s.
                let target = if rng.uniform(0.0, 1.0) < 0.5 {
                    body
                } else {
                    clone
                };
                let sim = *built.set.sim(target).unwrap();
                let j = 0.5 * sim.mass * Vec2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
                let r = 0.3 * Vec2::new(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
                let st = built.set.state_mut(target).unwrap();
                st.v += sim.inv_mass * j;
                st.w += sim.inv_inertia * cross(r, j);
                // What it adds to p1 + η Qᵀ p2 and to I1 ω1 + I2 ω2.
                let dp = if target == body {
                    j
                } else {
                    eta * q.inv_rotate(j)
                };
                expected[0] += d(dp.x);
                expected[1] += d(dp.y);
                expected[2] += d(cross(r, j));
            }
            step(&mut built, &mut batch, &settings);
            let (value, scale) = scaled_momentum(&built.set, body, clone, &map);
            let norm = expected[0].hypot(expected[1]);
            let ep = (value[0] - expected[0]).hypot(value[1] - expected[1]) / norm;
            let el = (value[2] - expected[2]).abs() / scale;
            worst_p = worst_p.max(ep);
            worst_l = worst_l.max(el);
            assert!(
                ep <= MOMENTUM_TOL,
                "η {eta}, step {i}: p1 + η Qᵀ p2 = {value:?}, impulses imply {expected:?} (relative {ep:.2e})"
            );
            assert!(
                el <= MOMENTUM_TOL,
                "η {eta}, step {i}: I1 ω1 + I2 ω2 = {}, impulses imply {} (relative {el:.2e})",
                value[2],
                expected[2]
            );
            let c = batch[0].error(&built.set);
            let gap = batch[0].position_error(&built.set);
            worst_c = worst_c.max(gap);
            worst_angle = worst_angle.max(c[2].abs());
            assert!(gap <= MAX_C, "η {eta}, step {i}: |C| = {gap} m");
        }
    }
    if report() {
        eprintln!(
            "static portals, random impulses: worst |C| {worst_c:.3e} m, worst |c2| {worst_angle:.3e} rad, \
             η-scaled momentum rel. error {worst_p:.3e}, I1ω1+I2ω2 rel. error {worst_l:.3e}"
        );
    }
}

/// Portal body A turns at +1 rad/s and B at −0.5 rad/s (kinematic, about
/// their centres, the portals off-centre so that their anchors move on
/// circles), for `steps` steps. `kinematic_body` prescribes body 1's motion
/// (it enters portal 1 at 0.3 m/s, turning at 0.3 rad/s); otherwise body 1
/// is dynamic and enters at 1 m/s. Returns the worst `|C|` (m) and `|c2|`
/// (rad) over the steps and the largest `|x1 − xA|` (m).
fn turning_portals(eta: Real, kinematic_body: bool, steps: usize) -> (Real, Real, Real) {
    let settings = SolverSettings::default();
    let a = BodySpec::kinematic(Vec2::new(0.0, 0.0), 0.0, Vec2::ZERO, 1.0);
    let b = BodySpec::kinematic(Vec2::new(6.0, 1.0), 0.5, Vec2::new(0.2, 0.0), -0.5);
    let mut case = case(a, b, false, eta);
    if kinematic_body {
        let f1 = case.map().frame1;
        case.body.ty = BodyType::Kinematic;
        case.body.local_center = Vec2::ZERO;
        case.body.center = f1.point + 0.5 * f1.normal;
        case.body.v = -0.3 * f1.normal;
        case.body.w = 0.3;
        case.clone = same_material_clone(&case.body, eta);
        case.clone.ty = BodyType::Dynamic;
        case.place_clone_exactly();
    }
    let mut built = case.build();
    let mut batch = vec![built.constraint.clone()];
    let [h1, _, ha, hb] = built.handles;
    let start_a = built.set.sim(ha).unwrap().transform.q;
    let (mut worst_c, mut worst_angle, mut reach): (Real, Real, Real) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        step(&mut built, &mut batch, &settings);
        worst_c = worst_c.max(batch[0].position_error(&built.set));
        worst_angle = worst_angle.max(batch[0].error(&built.set)[2].abs());
        let r1 = built.set.sim(h1).unwrap().center - built.set.sim(ha).unwrap().center;
        reach = reach.max(r1.length());
    }
    // The kinematic portal bodies really turned (their positions advance).
    let turned = start_a.relative_angle(built.set.sim(ha).unwrap().transform.q);
    let expected = janus2d_core::math::wrap_angle(steps as Real * DT);
    assert!(
        (turned - expected).abs() < 1e-3,
        "A turned {turned}, not {expected}"
    );
    assert_eq!(built.set.angular_velocity(hb), Some(-0.5));
    (worst_c, worst_angle, reach)
}

/// The spec's case: ωA = 1, ωB = −0.5 rad/s for 10 s, |C| ≤ 1 mm. Body 1
/// follows a prescribed path through portal 1 and the constraint alone keeps
/// the dynamic clone on `T(x1)` while both portals turn. (With the seed's
/// sign slip in the `s · n` velocity row, this case gives |C| of 2.6, 5.3
/// and 11 cm for η = 0.5, 1, 2.)
#[test]
fn kinematic_portal_bodies_turning_keep_the_clone_in_place() {
    let mut figures = Vec::new();
    for eta in [0.5, 1.0, 2.0] {
        let (c, angle, reach) = turning_portals(eta, true, 600);
        figures.push((eta, c, angle, reach));
        assert!(c <= MAX_C, "η {eta}: worst |C| = {c} m over 10 s");
        assert!(angle <= 1e-3, "η {eta}: worst |c2| = {angle} rad");
    }
    if report() {
        for (eta, c, angle, reach) in figures {
            eprintln!(
                "turning kinematic portals, 10 s, η {eta}: worst |C| {c:.3e} m, |c2| {angle:.3e} rad (body within {reach:.2} m of A)"
            );
        }
    }
}

/// Both copies dynamic under the same turning portals, for the 2 s a body
/// takes to pass through. (Left for 10 s, the pair runs away like a bead on
/// a spinning rod: the kinematic portals pump energy in, the distance grows
/// as e^(≈0.8 t) for η = 1, and |C|, which follows the acceleration, grows
/// with it; see docs/portal.md.)
#[test]
fn dynamic_copies_pass_through_turning_portals() {
    let mut figures = Vec::new();
    for eta in [0.5, 1.0, 2.0] {
        let (c, angle, reach) = turning_portals(eta, false, 120);
        figures.push((eta, c, angle, reach));
        assert!(c <= MAX_C, "η {eta}: worst |C| = {c} m over 2 s");
        assert!(angle <= 1e-3, "η {eta}: worst |c2| = {angle} rad");
    }
    if report() {
        for (eta, c, angle, reach) in figures {
            eprintln!(
                "turning kinematic portals, dynamic copies, 2 s, η {eta}: worst |C| {c:.3e} m, |c2| {angle:.3e} rad (body within {reach:.2} m of A)"
            );
        }
    }
}

/// Runs the dynamic-portal-body scene for 1000 steps, with the portal
/// constraint or (`with_portal == false`) as free flight, and returns the
/// worst linear momentum error relative to `|P0|`, the worst angular
/// momentum error (about the origin) relative to `|L0|`, the worst of both
/// relative to the size of the terms, and the worst `|C|`.
fn dynamic_portal_scene(same_ab: bool, eta: Real, with_portal: bool) -> (f64, f64, f64, Real) {
    let settings = SolverSettings::default();
    let mut a = BodySpec::dynamic(Vec2::new(-1.0, 0.5), 5.0, 3.0);
    a.v = Vec2::new(0.3, -0.2);
    a.w = 0.8;
    a.local_center = Vec2::new(0.2, 0.1);
    let mut b = BodySpec::dynamic(Vec2::new(7.0, -2.0), 3.0, 1.5);
    b.v = Vec2::new(-0.1, 0.4);
    b.w = -0.5;
    // The whole scene also drifts at ~1 m/s, so that the totals are not
    // small differences of large terms.
    let drift = Vec2::new(0.3, 1.0);
    a.v += drift;
    b.v += drift;
    let mut case = case(a, b, same_ab, eta);
    case.body.v += drift;
    case.place_clone_exactly();
    let mut built = case.build();
    let h = built.handles;
    let mut batch = if with_portal {
        vec![built.constraint.clone()]
    } else {
        Vec::new()
    };
    let (p0, _) = total_momentum(&built.set, &h);
    let (mut worst_p, mut worst_l, mut worst_terms) = (0.0f64, 0.0f64, 0.0f64);
    let mut worst_c: Real = 0.0;
    for _ in 0..1000 {
        step(&mut built, &mut batch, &settings);
        let (p, scale) = total_momentum(&built.set, &h);
        let dp = (p[0] - p0[0]).hypot(p[1] - p0[1]);
        let dl = (p[2] - p0[2]).abs();
        worst_p = worst_p.max(dp / p0[0].hypot(p0[1]));
        worst_l = worst_l.max(dl / p0[2].abs());
        worst_terms = worst_terms.max(dp / scale).max(dl / scale);
        if with_portal {
            worst_c = worst_c.max(batch[0].position_error(&built.set));
        }
    }
    (worst_p, worst_l, worst_terms, worst_c)
}

/// Dynamic portal bodies (A and B distinct, then one body carrying both
/// portals), 1000 steps: total linear momentum within 1e-5 (f32) / 1e-10
/// (f64) of `|P0|`, and |C| ≤ 1 mm.
///
/// Angular momentum about the origin: with f64 it stays within 1e-10 of
/// `|L0|`. With f32 it is checked relative to the size of its terms
/// (`Σ |m x × v| + |I ω|`), where round-off comes from: storing positions
/// in f32 (ulp ≈ 1e-6 m at 10 m) changes `Σ x × m v` a little every step,
/// so that free flight of the same bodies with no constraint at all drifts
/// by up to ≈ 3e-4 of `|L0|` in the scene where A and B are one body (whose
/// `|L0|` is small next to its terms). Relative to `|L0|` the f32 figure is
/// reported, not asserted: the 1e-5 bound is not met by f32 storage itself.
#[test]
fn dynamic_portal_bodies_conserve_total_momentum() {
    let mut results = Vec::new();
    for same_ab in [false, true] {
        for eta in [0.5, 1.0, 2.0] {
            let (p, l, terms, c) = dynamic_portal_scene(same_ab, eta, true);
            let (_, l_free, _, _) = dynamic_portal_scene(same_ab, eta, false);
            results.push((same_ab, eta, p, l, l_free, terms, c));
        }
    }
    if report() {
        for (same_ab, eta, p, l, l_free, terms, c) in &results {
            eprintln!(
                "dynamic portal bodies, 1000 steps, one body {same_ab}, η {eta}: |C| {c:.3e} m, \
                 linear {p:.3e}, angular {l:.3e} (free flight {l_free:.3e}), relative to the terms {terms:.3e}"
            );
        }
    }
    for (same_ab, eta, p, l, l_free, terms, c) in results {
        let _ = (l, l_free);
        assert!(
            p <= MOMENTUM_TOL,
            "one body {same_ab}, η {eta}: linear momentum drifted by {p:.3e} of |P0|"
        );
        assert!(
            terms <= MOMENTUM_TOL,
            "one body {same_ab}, η {eta}: momentum drifted by {terms:.3e} of its terms"
        );
        #[cfg(feature = "f64")]
        assert!(
            l <= MOMENTUM_TOL,
            "one body {same_ab}, η {eta}: angular momentum drifted by {l:.3e} of |L0| (free flight {l_free:.3e})"
        );
        assert!(c <= MAX_C, "one body {same_ab}, η {eta}: |C| = {c} m");
    }
}

#[test]
fn angle_offset_of_two_pi_does_not_spin_the_body() {
    let settings = SolverSettings::default();
    // Worst total rotation / |δ| (δ ≠ 0) and worst total rotation (δ = 0).
    let mut worst_spin: Real = 0.0;
    let mut worst_w: Real = 0.0;
    // (θ1, direction angle of portal 1, of portal 2): the unwrapped angle
    // error (θ1 − α1) − (θ2 − α2) − π of the exact clone is +2π, then −2π.
    for (k, theta1, phi1, phi2) in [(1.0, 3.0, -0.5, 3.0), (-1.0, -1.0, 1.0, -1.0)] {
        for delta in [0.0, 0.05, -0.05] {
            let a = BodySpec::fixed(Vec2::ZERO, 0.0);
            let b = BodySpec::fixed(Vec2::new(8.0, 0.0), 0.0);
            let dir = |phi: Real| Vec2::new(phi.cos(), phi.sin());
            let mut case = PortalCase {
                body: BodySpec::dynamic(Vec2::new(0.0, 0.0), 1.0, 0.2),
                clone: BodySpec::dynamic(Vec2::ZERO, 1.0, 0.2),
                a,
                b,
                same_ab: false,
                portal_a: portal(Vec2::ZERO, dir(phi1), 1.0),
                portal_b: portal(Vec2::ZERO, dir(phi2), 1.0),
                eta: 1.0,
            };
            case.body.angle = theta1;
            case.body.center = 0.5 * dir(phi1);
            case.place_clone_exactly();
            case.clone.angle += delta;
            let mut built = case.build();
            // The angles the engine reads, and the unwrapped error.
            let [h1, h2, ..] = built.handles;
            let read = |h| built.set.sim(h).unwrap().transform.q.angle();
            let raw = (read(h1) - phi1) - (read(h2) - phi2) - PI;
            assert!(
                (raw - k * TAU + delta).abs() < 1e-3,
                "the case must start at ±2π: raw {raw}"
            );
            let mut batch = vec![built.constraint.clone()];
            // Rotation actually integrated (the relax pass removes the
            // bias velocity, so ω after a step does not show it).
            let (mut turned1, mut turned2): (Real, Real) = (0.0, 0.0);
            let q = |set: &janus2d_core::body::BodySet, h| set.sim(h).unwrap().transform.q;
            for _ in 0..120 {
                let (q1, q2) = (q(&built.set, h1), q(&built.set, h2));
                step(&mut built, &mut batch, &settings);
                turned1 += q1.relative_angle(q(&built.set, h1));
                turned2 += q2.relative_angle(q(&built.set, h2));
            }
            let spin = turned1.abs() + turned2.abs();
            if delta == 0.0 {
                worst_w = worst_w.max(spin);
            } else {
                worst_spin = worst_spin.max(spin / delta.abs());
            }
            // Closing δ takes |δ| of relative rotation, shared by the two
            // (equal inertias): never a turn of 2π.
            assert!(
                spin <= delta.abs() + 1e-3,
                "k {k}, δ {delta}: the bodies turned {turned1} and {turned2} rad"
            );
            let c2 = batch[0].error(&built.set)[2];
            assert!(c2.abs() <= 1e-3, "k {k}, δ {delta}: angle error left {c2}");
            if delta == 0.0 {
                // Nothing to correct: only the round-off of reading 240
                // relative angles (a few ε each).
                let bound = 240.0 * 4.0 * EPSILON;
                assert!(spin <= bound, "no offset, yet the bodies turned {spin} rad");
            }
        }
    }
    if report() {
        eprintln!(
            "±2π angle offset: with δ = ±0.05 rad the bodies turn {worst_spin:.4} |δ| in total; with δ = 0 they turn {worst_w:.3e} rad"
        );
    }
}

/// Guards the test setup: the static case really has static portal bodies
/// (the fast path) and the dynamic case the block solve.
#[test]
fn cases_exercise_both_solve_paths() {
    let ctx = SolverSettings::default().context(DT, Vec2::ZERO);
    use janus2d_core::constraint::Constraint;
    let a = BodySpec::fixed(Vec2::new(-1.0, 0.5), 0.4);
    let b = BodySpec::kinematic(Vec2::new(7.0, -2.0), 0.0, Vec2::ZERO, 1.0);
    let mut built = case(a, b, false, 1.0).build();
    built.constraint.prepare(&ctx, &built.set);
    assert!(built.constraint.uses_fast_path());
    let a = BodySpec::dynamic(Vec2::new(-1.0, 0.5), 5.0, 3.0);
    let mut built = case(a.clone(), a, true, 1.0).build();
    built.constraint.prepare(&ctx, &built.set);
    assert!(!built.constraint.uses_fast_path());
    assert_eq!(
        built.set.body_type(built.handles[2]),
        Some(BodyType::Dynamic)
    );
}
