//! Simple pendulum: small-angle period and energy of a frictionless swing.

use janus2d::prelude::*;

const G: Real = 10.0;
const L: Real = 1.0;

/// A point-like bob (tiny inertia) on a hinge at the origin, released at
/// `angle0` from the vertical.
fn pendulum(angle0: Real, substeps: u32) -> (World, BodyHandle) {
    let mut def = WorldDef::default();
    def.solver.substeps = substeps;
    let mut world = World::new(def).unwrap();
    let pivot = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let pos = Vec2::new(L * angle0.sin(), -L * angle0.cos());
    let bob = world
        .create_body(&BodyDef::dynamic(pos).with_mass(1.0, 1e-4))
        .unwrap();
    world
        .create_revolute_joint(&RevoluteJointDef::new(pivot, bob, Vec2::ZERO, -pos))
        .unwrap();
    (world, bob)
}

fn energy(world: &World, bob: BodyHandle) -> Real {
    let v = world.linear_velocity(bob).unwrap();
    let w = world.angular_velocity(bob).unwrap();
    let m = world.mass(bob).unwrap();
    let i = world.rotational_inertia(bob).unwrap();
    0.5 * m * v.length_squared() + 0.5 * i * w * w + m * G * world.center_of_mass(bob).unwrap().y
}

/// Measures the period from successive upward zero crossings of x.
fn measured_period(world: &mut World, bob: BodyHandle, dt: Real, seconds: Real) -> Real {
    let mut crossings = Vec::new();
    let mut prev_x = world.position(bob).unwrap().x;
    let steps = (seconds / dt) as usize;
    for k in 0..steps {
        world.step(dt).unwrap();
        let x = world.position(bob).unwrap().x;
        if prev_x < 0.0 && x >= 0.0 {
            // Linear interpolation of the crossing time.
            let t = (k as Real + (-prev_x) / (x - prev_x)) * dt;
            crossings.push(t);
        }
        prev_x = x;
    }
    assert!(
        crossings.len() >= 3,
        "too few crossings: {}",
        crossings.len()
    );
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as Real
}

#[test]
fn pendulum_small_angle_period_within_one_percent() {
    let (mut world, bob) = pendulum(0.05, 4);
    let period = measured_period(&mut world, bob, 1.0 / 60.0, 20.0);
    let expected = 2.0 * janus2d::base::math::PI * (L / G).sqrt();
    let err = (period - expected).abs() / expected;
    if std::env::var("JANUS2D_REPORT").is_ok() {
        eprintln!(
            "pendulum period {period:.5} s, expected {expected:.5} s, error {:.4}%",
            err * 100.0
        );
    }
    assert!(err < 0.01, "period {period} vs {expected}: error {err}");
}

#[test]
fn pendulum_energy_does_not_grow_over_60_seconds() {
    // Released at 1 rad. Symplectic integration makes the instantaneous
    // energy oscillate by O(h ω E) within a swing, so compare the peak energy
    // of the first 10 s with the peak of the last 10 s: no secular growth.
    let (mut world, bob) = pendulum(1.0, 4);
    let e0 = energy(&world, bob);
    let swing = G * L * (1.0 - (1.0 as Real).cos()); // m g L (1 − cos θ0), J
    let (mut first_peak, mut last_peak) = (Real::MIN, Real::MIN);
    let steps = 60 * 60;
    for k in 0..steps {
        world.step(1.0 / 60.0).unwrap();
        let e = energy(&world, bob);
        if k < 600 {
            first_peak = first_peak.max(e);
        }
        if k >= steps - 600 {
            last_peak = last_peak.max(e);
        }
        // Within-swing oscillation stays below 1% of the swing energy.
        assert!(e - e0 <= 0.01 * swing, "step {k}: energy {e} vs start {e0}");
    }
    if std::env::var("JANUS2D_REPORT").is_ok() {
        eprintln!(
            "pendulum energy: start {e0:.5}, peak first 10 s {first_peak:.5}, peak last 10 s {last_peak:.5}"
        );
    }
    assert!(
        last_peak <= first_peak + 1e-4 * swing,
        "energy grew: {first_peak} -> {last_peak}"
    );
    let gap = world.max_joint_gap();
    assert!(gap < 1e-3, "joint gap {gap}");
}
