//! Motion settings after creation (gravity scale, damping, fixed rotation),
//! the velocity of a body's point, and explosions: numbers against their
//! formulas, typed errors that change nothing, snapshots that keep them.

use janus2d::prelude::*;
use janus2d::world::ExplosionDef;

const DT: Real = 1.0 / 60.0;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn world_with_gravity(g: Vec2) -> World {
    World::new(WorldDef {
        gravity: g,
        ..WorldDef::default()
    })
    .unwrap()
}

fn dynamic_box(w: &mut World, at: Vec2, hx: Real, hy: Real) -> BodyHandle {
    let b = w.create_body(&BodyDef::dynamic(at)).unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(hx, hy))
        .unwrap();
    b
}

#[test]
fn gravity_scale_zero_keeps_the_velocity_and_two_doubles_the_fall() {
    let mut w = world_with_gravity(v(0.0, -10.0));
    let floating = w
        .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(v(1.5, 2.5)))
        .unwrap();
    let heavy = w.create_body(&BodyDef::dynamic(v(5.0, 0.0))).unwrap();
    w.set_gravity_scale(floating, 0.0).unwrap();
    w.set_gravity_scale(heavy, 2.0).unwrap();
    assert_eq!(w.gravity_scale(floating).unwrap(), 0.0);
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    // Bit for bit: nothing acts on the floating body.
    assert_eq!(w.linear_velocity(floating).unwrap(), v(1.5, 2.5));
    // 2 s at 2 g: v = −40 m/s.
    let vy = w.linear_velocity(heavy).unwrap().y;
    assert!((vy + 40.0).abs() < 1e-3, "{vy}");
    // Back to 1: the next second adds −10 m/s.
    w.set_gravity_scale(heavy, 1.0).unwrap();
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert!((w.linear_velocity(heavy).unwrap().y + 50.0).abs() < 2e-3);
}

#[test]
fn damping_set_after_creation_follows_the_substep_formula() {
    let mut w = world_with_gravity(Vec2::ZERO);
    let b = w
        .create_body(
            &BodyDef::dynamic(Vec2::ZERO)
                .with_velocity(v(4.0, 0.0))
                .with_angular_velocity(3.0),
        )
        .unwrap();
    w.set_linear_damping(b, 2.0).unwrap();
    w.set_angular_damping(b, 0.5).unwrap();
    assert_eq!(
        (w.linear_damping(b).unwrap(), w.angular_damping(b).unwrap()),
        (2.0, 0.5)
    );
    w.step(DT).unwrap();
    // Each of the n substeps of h = dt/n scales by 1/(1 + h c).
    let n = w.settings().substeps as Real;
    let h = DT / n;
    let expect_v = 4.0 * (1.0 / (1.0 + h * 2.0)).powf(n);
    let expect_w = 3.0 * (1.0 / (1.0 + h * 0.5)).powf(n);
    assert!((w.linear_velocity(b).unwrap().x - expect_v).abs() < 1e-5);
    assert!((w.angular_velocity(b).unwrap() - expect_w).abs() < 1e-5);
}

#[test]
fn fixed_rotation_set_after_creation_stops_the_spin_and_gives_the_inertia_back() {
    let mut w = world_with_gravity(Vec2::ZERO);
    // A 2 × 1 box of density 1: m = 2, I = m (4 + 1) / 12 = 5/6.
    let b = dynamic_box(&mut w, Vec2::ZERO, 1.0, 0.5);
    assert!((w.rotational_inertia(b).unwrap() - 5.0 / 6.0).abs() < 1e-5);
    w.set_angular_velocity(b, 2.0).unwrap();
    w.set_fixed_rotation(b, true).unwrap();
    assert!(w.is_fixed_rotation(b).unwrap());
    assert_eq!(w.angular_velocity(b).unwrap(), 0.0);
    // A torque and an off-centre impulse turn nothing.
    w.apply_torque(b, 50.0).unwrap();
    w.apply_linear_impulse(b, v(0.0, 1.0), v(1.0, 0.0)).unwrap();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    assert_eq!(w.angle(b).unwrap(), 0.0);
    assert!(
        (w.linear_velocity(b).unwrap().y - 0.5).abs() < 1e-5,
        "1 N·s / 2 kg"
    );
    w.set_fixed_rotation(b, false).unwrap();
    assert!((w.rotational_inertia(b).unwrap() - 5.0 / 6.0).abs() < 1e-5);
    w.apply_angular_impulse(b, 5.0 / 6.0).unwrap();
    assert!((w.angular_velocity(b).unwrap() - 1.0).abs() < 1e-5);

    // A directly set mass (3 kg) keeps it; freed, the shapes' inertia
    // scaled by 3 / 2: 1.25 kg·m².
    let m = w
        .create_body(&BodyDef::dynamic(v(5.0, 0.0)).with_mass(3.0, 0.4))
        .unwrap();
    w.create_shape(m, &ShapeDef::default(), Polygon::make_box(1.0, 0.5))
        .unwrap();
    w.set_fixed_rotation(m, true).unwrap();
    assert_eq!(w.mass(m).unwrap(), 3.0);
    w.set_fixed_rotation(m, false).unwrap();
    assert!((w.rotational_inertia(m).unwrap() - 1.25).abs() < 1e-5);
    assert_eq!(w.mass(m).unwrap(), 3.0);

    // A directly set mass without shapes has no inertia to give back.
    let bare = w
        .create_body(
            &BodyDef::dynamic(v(-5.0, 0.0))
                .with_fixed_rotation(true)
                .with_mass(1.0, 0.0),
        )
        .unwrap();
    let before = w.state_hash();
    assert_eq!(
        w.set_fixed_rotation(bare, false),
        Err(WorldError::Body(
            janus2d::base::body::BodyError::NonPositiveInertia
        ))
    );
    assert!(w.is_fixed_rotation(bare).unwrap());
    assert_eq!(w.state_hash(), before);
    assert!(w.validate().is_ok());
}

#[test]
fn velocity_at_point_is_v_plus_omega_cross_r() {
    let mut w = world_with_gravity(Vec2::ZERO);
    let b = dynamic_box(&mut w, v(1.0, 2.0), 0.5, 0.5);
    w.set_linear_velocity(b, v(3.0, -1.0)).unwrap();
    w.set_angular_velocity(b, 2.0).unwrap();
    // r = (1, 1) from the centre: ω × r = 2 (−1, 1).
    let p = w.velocity_at_point(b, v(2.0, 3.0)).unwrap();
    assert!((p - v(1.0, 1.0)).length() < 1e-6, "{p:?}");
    assert_eq!(w.velocity_at_point(b, v(1.0, 2.0)).unwrap(), v(3.0, -1.0));
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    assert_eq!(
        w.velocity_at_point(ground, v(7.0, 7.0)).unwrap(),
        Vec2::ZERO
    );
    assert_eq!(
        w.velocity_at_point(b, v(Real::NAN, 0.0)),
        Err(WorldError::NonFinite("point"))
    );
}

#[test]
fn explode_gives_each_shape_the_impulse_the_formula_predicts() {
    let mut w = world_with_gravity(Vec2::ZERO);
    let (ipl, radius, falloff) = (3.0, 4.0, 2.0);
    // A disc r = 0.5 with its nearest point 3.5 m out: full strength,
    // J = 3 × 2 r = 3 N·s along +x, no turn.
    let near = w.create_body(&BodyDef::dynamic(v(4.0, 0.0))).unwrap();
    w.create_shape(
        near,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    // The same disc 5 m out (nearest point): in the falloff band,
    // s = (4 + 2 − 5) / 2 = 0.5, J = 1.5 N·s along −y.
    let banded = w.create_body(&BodyDef::dynamic(v(0.0, -5.5))).unwrap();
    w.create_shape(
        banded,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    // A 1 × 2 box at (−4, 0.5): its right face x = −3.5 faces the centre
    // off its middle: nearest point (−3.5, 0), width across 2, J = 6 N·s
    // along −x, 0.5 m below the centre: a turn of ΔL = r × J.
    let boxed = dynamic_box(&mut w, v(-4.0, 0.5), 0.5, 1.0);
    // Out of reach, static, or masked out: untouched.
    let far = w.create_body(&BodyDef::dynamic(v(0.0, 7.0))).unwrap();
    w.create_shape(
        far,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    let wall = w.create_body(&BodyDef::fixed(v(2.0, 2.0))).unwrap();
    w.create_shape(
        wall,
        &ShapeDef::default(),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    let other_category = w.create_body(&BodyDef::dynamic(v(-2.0, -2.0))).unwrap();
    let mut cat2 = ShapeDef::default();
    cat2.filter.category_bits = 0b10;
    w.create_shape(other_category, &cat2, Circle::new(Vec2::ZERO, 0.5).unwrap())
        .unwrap();
    w.set_awake(near, false).unwrap();
    let def = ExplosionDef::new(Vec2::ZERO, radius, ipl)
        .with_falloff(falloff)
        .with_mask(0b1);
    assert_eq!(w.explode(&def).unwrap(), 3);
    let m_disc = w.mass(near).unwrap();
    assert!(
        w.is_awake(near).unwrap(),
        "the explosion wakes what it pushes"
    );
    let vn = w.linear_velocity(near).unwrap();
    assert!((vn - v(3.0 / m_disc, 0.0)).length() < 1e-5, "{vn:?}");
    assert!(w.angular_velocity(near).unwrap().abs() < 1e-6);
    let vb = w.linear_velocity(banded).unwrap();
    assert!((vb - v(0.0, -1.5 / m_disc)).length() < 1e-5, "{vb:?}");
    let (m_box, i_box) = (w.mass(boxed).unwrap(), w.rotational_inertia(boxed).unwrap());
    let vx = w.linear_velocity(boxed).unwrap();
    assert!((vx - v(-6.0 / m_box, 0.0)).length() < 1e-5, "{vx:?}");
    // r = (−3.5, 0) − (−4, 0.5) = (0.5, −0.5); r × (−6, 0) = −(−0.5)(−6) = −3.
    assert!((w.angular_velocity(boxed).unwrap() + 3.0 / i_box).abs() < 1e-4);
    for b in [far, other_category] {
        assert_eq!(w.linear_velocity(b).unwrap(), Vec2::ZERO);
    }
}

#[test]
fn bad_setter_and_explosion_input_is_a_typed_error_and_changes_nothing() {
    let mut w = world_with_gravity(v(0.0, -10.0));
    let b = dynamic_box(&mut w, v(0.0, 1.0), 0.5, 0.5);
    let gone = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    w.destroy_body(gone).unwrap();
    w.step(DT).unwrap();
    let before = w.state_hash();
    let max = janus2d::base::limits::MAX_GRAVITY_SCALE;
    assert_eq!(
        w.set_gravity_scale(b, Real::NAN),
        Err(WorldError::NonFinite("gravity_scale"))
    );
    assert_eq!(
        w.set_gravity_scale(b, 2.0 * max),
        Err(WorldError::OutOfBounds {
            field: "gravity_scale",
            min: -max,
            max
        })
    );
    assert_eq!(w.set_gravity_scale(gone, 1.0), Err(WorldError::StaleBody));
    assert_eq!(
        w.set_linear_damping(b, -0.1),
        Err(WorldError::OutOfRange("linear_damping"))
    );
    assert_eq!(
        w.set_angular_damping(b, Real::INFINITY),
        Err(WorldError::NonFinite("angular_damping"))
    );
    assert_eq!(w.set_fixed_rotation(gone, true), Err(WorldError::StaleBody));
    assert_eq!(w.linear_damping(gone), Err(WorldError::StaleBody));
    assert_eq!(w.is_fixed_rotation(gone), Err(WorldError::StaleBody));
    let e = |p| ExplosionDef::new(p, 1.0, 1.0);
    assert!(w.explode(&e(v(Real::NAN, 0.0))).is_err());
    assert_eq!(
        w.explode(&ExplosionDef::new(Vec2::ZERO, -1.0, 1.0)),
        Err(WorldError::OutOfRange("radius"))
    );
    assert_eq!(
        w.explode(&e(Vec2::ZERO).with_falloff(-1.0)),
        Err(WorldError::OutOfRange("falloff"))
    );
    assert_eq!(
        w.explode(&ExplosionDef::new(Vec2::ZERO, 1.0, Real::INFINITY)),
        Err(WorldError::NonFinite("impulse_per_length"))
    );
    // An impulse past the speed limit: nothing is pushed.
    assert!(matches!(
        w.explode(&ExplosionDef::new(Vec2::ZERO, 5.0, 1e30)),
        Err(WorldError::OutOfBounds {
            field: "impulse",
            ..
        })
    ));
    assert_eq!(w.gravity_scale(b).unwrap(), 1.0);
    assert_eq!(w.linear_damping(b).unwrap(), 0.0);
    assert_eq!(w.state_hash(), before);
    assert!(w.validate().is_ok());
}

#[test]
fn the_settings_survive_a_snapshot_and_the_continuation_is_identical() {
    let mut w = world_with_gravity(v(0.0, -10.0));
    let ground = w.create_body(&BodyDef::fixed(v(0.0, -0.5))).unwrap();
    w.create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))
        .unwrap();
    let b = dynamic_box(&mut w, v(0.0, 2.0), 0.5, 0.5);
    w.set_gravity_scale(b, 0.5).unwrap();
    w.set_linear_damping(b, 0.3).unwrap();
    w.set_angular_damping(b, 0.7).unwrap();
    w.set_fixed_rotation(b, true).unwrap();
    let saved = w.snapshot();
    for _ in 0..40 {
        w.step(DT).unwrap();
    }
    let after = w.state_hash();
    let mut copy = saved.to_world();
    assert_eq!(copy.gravity_scale(b).unwrap(), 0.5);
    assert_eq!(copy.linear_damping(b).unwrap(), 0.3);
    assert_eq!(copy.angular_damping(b).unwrap(), 0.7);
    assert!(copy.is_fixed_rotation(b).unwrap());
    for _ in 0..40 {
        copy.step(DT).unwrap();
    }
    assert_eq!(copy.state_hash(), after);
    #[cfg(feature = "serde")]
    {
        let bytes = saved.to_bytes();
        let decoded = janus2d::world::Snapshot::from_bytes(&bytes).unwrap();
        let mut again = decoded.to_world();
        assert_eq!(again.gravity_scale(b).unwrap(), 0.5);
        assert!(again.is_fixed_rotation(b).unwrap());
        for _ in 0..40 {
            again.step(DT).unwrap();
        }
        assert_eq!(again.state_hash(), after);
    }
}

#[cfg(feature = "portals")]
#[test]
fn fixed_rotation_of_a_portal_body_is_refused() {
    use janus2d::world::{PortalDef, PortalPairDef};
    let mut w = world_with_gravity(v(0.0, -10.0));
    let a = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b2 = w.create_body(&BodyDef::kinematic(v(10.0, 0.0))).unwrap();
    w.create_portal_pair(&PortalPairDef::new(
        PortalDef::new(a, Vec2::ZERO, Vec2::Y, 1.0),
        PortalDef::new(b2, Vec2::ZERO, Vec2::Y, 1.0),
    ))
    .unwrap();
    assert_eq!(w.set_fixed_rotation(b2, true), Err(WorldError::PortalBody));
    assert!(!w.is_fixed_rotation(b2).unwrap());
}
