//! Surface materials: tangent speed (a conveyor belt), rolling resistance,
//! friction and restitution combine rules and callbacks, the user material
//! id, and bad material input (typed error, world unchanged).

use janus2d::prelude::*;
use janus2d_testbed::scenes::{self, DT};

fn world() -> World {
    World::new(scenes::shared_settings()).unwrap()
}

/// A static ground box of half width 50 whose top is at y = 0.
fn ground(world: &mut World, def: &ShapeDef) -> (BodyHandle, ShapeHandle) {
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    let s = world
        .create_shape(g, def, Polygon::make_box(50.0, 0.5))
        .unwrap();
    (g, s)
}

fn unit_box(world: &mut World, x: Real, def: &ShapeDef) -> BodyHandle {
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(x, 0.5)))
        .unwrap();
    world
        .create_shape(b, def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    b
}

/// A box resting on a belt of tangent speed 2 m/s is carried along at
/// 2 ± 0.05 m/s (towards +x: the top face of a box moves clockwise),
/// whichever of the two shapes is shape a of the contact.
#[test]
fn a_box_on_a_belt_reaches_the_belt_speed() {
    for belt_first in [true, false] {
        let mut w = world();
        let belt = ShapeDef::default().with_tangent_speed(2.0);
        let b = if belt_first {
            ground(&mut w, &belt);
            unit_box(&mut w, 0.0, &ShapeDef::default())
        } else {
            let b = unit_box(&mut w, 0.0, &ShapeDef::default());
            ground(&mut w, &belt);
            b
        };
        for _ in 0..120 {
            w.step(DT).unwrap();
        }
        let v = w.linear_velocity(b).unwrap();
        assert!(
            (v.x - 2.0).abs() < 0.05 && v.y.abs() < 0.05,
            "belt first {belt_first}: {v:?}"
        );
        let c = w.contacts().next().unwrap();
        assert_eq!(c.tangent_speed, 2.0);
    }
}

/// A belt's speed set at run time reverses the box (it wakes too).
#[test]
fn a_belt_speed_set_later_moves_a_resting_box() {
    let mut w = world();
    let (_, belt) = ground(&mut w, &ShapeDef::default());
    let b = unit_box(&mut w, 0.0, &ShapeDef::default());
    for _ in 0..240 {
        w.step(DT).unwrap();
    }
    assert!(w.linear_velocity(b).unwrap().x.abs() < 1e-3);
    w.set_shape_tangent_speed(belt, -1.0).unwrap();
    for _ in 0..120 {
        w.step(DT).unwrap();
    }
    let v = w.linear_velocity(b).unwrap();
    assert!((v.x + 1.0).abs() < 0.05, "{v:?}");
}

/// A disc rolling at 3 m/s on flat ground with rolling resistance 0.1
/// stops within the distance the resistance predicts,
/// `v₀² / (2 · ⅔ c g)` = 6.88 m (and after at least 90 % of it); without
/// resistance it rolls on at nearly 3 m/s over the same time.
#[test]
fn rolling_resistance_stops_a_ball_within_the_predicted_distance() {
    let (v0, r, c, g) = (3.0 as Real, 0.5 as Real, 0.1 as Real, 9.81 as Real);
    let decel = 2.0 / 3.0 * c * g;
    let predicted = v0 * v0 / (2.0 * decel);
    let run = |resistance: Real| {
        let mut w = world();
        ground(&mut w, &ShapeDef::default());
        let ball = w
            .create_body(
                &BodyDef::dynamic(Vec2::new(0.0, r))
                    .with_velocity(Vec2::new(v0, 0.0))
                    .with_angular_velocity(-v0 / r),
            )
            .unwrap();
        let def = ShapeDef::default().with_rolling_resistance(resistance);
        w.create_shape(ball, &def, Circle::new(Vec2::ZERO, r).unwrap())
            .unwrap();
        // Twice the predicted time to stop.
        let steps = (2.0 * v0 / decel / DT) as usize;
        for _ in 0..steps {
            w.step(DT).unwrap();
        }
        (
            w.position(ball).unwrap().x,
            w.linear_velocity(ball).unwrap().x,
        )
    };
    let (x, v) = run(c);
    println!("stopped at {x:.3} m (predicted {predicted:.3} m), v = {v:.4}");
    assert!(v.abs() < 0.01, "stopped: {v}");
    assert!(
        x <= 1.05 * predicted && x >= 0.9 * predicted,
        "{x} vs {predicted}"
    );
    let (x, v) = run(0.0);
    assert!(v > 0.95 * v0, "rolls on: {v}");
    assert!(x > 2.0 * predicted, "{x}");
}

/// The contact's friction for shapes of friction 0.2 and 0.8 under each
/// rule: default √(0.2 · 0.8) = 0.4, average 0.5, min 0.2, multiply 0.16,
/// max 0.8; the stronger rule of the two shapes wins; restitution's
/// default is the larger value.
#[test]
fn combine_rules_give_the_documented_values() {
    let contact_of = |a: ShapeDef, b: ShapeDef| {
        let mut w = world();
        ground(&mut w, &a);
        unit_box(&mut w, 0.0, &b);
        w.step(DT).unwrap();
        let c = w.contacts().next().unwrap();
        (c.friction, c.restitution)
    };
    let close = |x: Real, y: Real| (x - y).abs() < 1e-6;
    let low = ShapeDef::default().with_friction(0.2).with_restitution(0.1);
    let high = ShapeDef::default().with_friction(0.8).with_restitution(0.5);
    let (f, e) = contact_of(low.clone(), high.clone());
    assert!(close(f, 0.4), "default friction {f}");
    assert!(close(e, 0.5), "default restitution {e}");
    for (rule, friction, restitution) in [
        (CombineRule::Average, 0.5, 0.3),
        (CombineRule::Min, 0.2, 0.1),
        (CombineRule::Multiply, 0.16, 0.05),
        (CombineRule::Max, 0.8, 0.5),
    ] {
        // The rule on one shape only: it beats the other's default.
        let a = low
            .clone()
            .with_friction_combine(rule)
            .with_restitution_combine(rule);
        let (f, e) = contact_of(a, high.clone());
        assert!(close(f, friction), "{rule:?}: friction {f}");
        assert!(close(e, restitution), "{rule:?}: restitution {e}");
    }
    // Min against Max: Max is the stronger rule.
    let (f, _) = contact_of(
        low.clone().with_friction_combine(CombineRule::Min),
        high.clone().with_friction_combine(CombineRule::Max),
    );
    assert!(close(f, 0.8), "max wins: {f}");
}

/// The friction callback decides by the shapes' user material ids, is
/// applied to existing contacts when set, and a NaN answer falls back to
/// the combine rules. Contacts report the material ids.
#[test]
fn friction_callback_mixes_by_material_id() {
    const ICE: u64 = 7;
    let mut w = world();
    ground(&mut w, &ShapeDef::default().with_material_id(ICE));
    unit_box(&mut w, 0.0, &ShapeDef::default().with_material_id(3));
    w.step(DT).unwrap();
    let c = w.contacts().next().unwrap();
    assert_eq!(c.user_material_ids, [ICE, 3]);
    assert!((c.friction - 0.6).abs() < 1e-6);
    w.set_friction_callback(Some(Box::new(|a, ma, b, mb| {
        if ma == ICE || mb == ICE {
            0.05
        } else {
            a.max(b)
        }
    })));
    assert_eq!(w.contacts().next().unwrap().friction, 0.05);
    w.set_friction_callback(Some(Box::new(|_, _, _, _| Real::NAN)));
    assert!((w.contacts().next().unwrap().friction - 0.6).abs() < 1e-6);
    w.set_restitution_callback(Some(Box::new(|_, _, _, _| 1e9)));
    assert_eq!(
        w.contacts().next().unwrap().restitution,
        janus2d::limits::MAX_RESTITUTION
    );
    w.set_restitution_callback(None);
    w.set_friction_callback(None);
    assert_eq!(w.contacts().next().unwrap().restitution, 0.0);
    assert_eq!(w.validate(), Ok(()));
}

/// Bad material input is a typed error naming the field, and the world is
/// unchanged (no shape created, the same state).
#[test]
fn bad_material_input_is_a_typed_error() {
    let mut w = world();
    let (_, floor) = ground(&mut w, &ShapeDef::default());
    let b = unit_box(&mut w, 0.0, &ShapeDef::default());
    w.step(DT).unwrap();
    let (shapes, hash) = (w.shape_count(), w.state_hash());
    let circle = || Circle::new(Vec2::ZERO, 0.5).unwrap();
    let cases = [
        (
            ShapeDef::default().with_friction(Real::NAN),
            WorldError::NonFinite("friction"),
        ),
        (
            ShapeDef::default().with_rolling_resistance(-0.1),
            WorldError::OutOfRange("rolling_resistance"),
        ),
        (
            ShapeDef::default().with_rolling_resistance(Real::INFINITY),
            WorldError::NonFinite("rolling_resistance"),
        ),
        (
            ShapeDef::default().with_tangent_speed(Real::NAN),
            WorldError::NonFinite("tangent_speed"),
        ),
    ];
    for (def, error) in cases {
        assert_eq!(w.create_shape(b, &def, circle()), Err(error));
    }
    assert!(matches!(
        w.set_shape_tangent_speed(floor, 1e30),
        Err(WorldError::OutOfBounds {
            field: "tangent_speed",
            ..
        })
    ));
    assert_eq!(
        w.set_shape_rolling_resistance(floor, -1.0),
        Err(WorldError::OutOfRange("rolling_resistance"))
    );
    assert_eq!(
        w.set_shape_friction(floor, Real::NAN),
        Err(WorldError::NonFinite("friction"))
    );
    assert_eq!(w.shape_count(), shapes);
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.shape(floor).unwrap().def.tangent_speed, 0.0);
    assert_eq!(w.validate(), Ok(()));
}

/// Surface materials are state: a snapshot restores them, and the steps
/// after a restore repeat bit for bit (the belt and a rolling ball).
#[test]
fn snapshot_restores_surface_materials() {
    let mut w = world();
    let belt = ShapeDef::default()
        .with_tangent_speed(1.5)
        .with_friction_combine(CombineRule::Max)
        .with_material_id(9);
    ground(&mut w, &belt);
    unit_box(&mut w, 0.0, &ShapeDef::default());
    let ball = w
        .create_body(&BodyDef::dynamic(Vec2::new(5.0, 0.5)).with_angular_velocity(-4.0))
        .unwrap();
    w.create_shape(
        ball,
        &ShapeDef::default().with_rolling_resistance(0.2),
        Circle::new(Vec2::ZERO, 0.5).unwrap(),
    )
    .unwrap();
    for _ in 0..10 {
        w.step(DT).unwrap();
    }
    let saved = w.snapshot();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    let after = w.state_hash();
    w.restore(&saved);
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    assert_eq!(w.state_hash(), after);
    #[cfg(feature = "serde")]
    {
        let bytes = w.snapshot().to_bytes();
        let back = janus2d::Snapshot::from_bytes(&bytes).unwrap();
        let mut copy = world();
        copy.restore(&back);
        let floor = copy.contacts().next().unwrap().shapes[0];
        let def = &copy.shape(floor).unwrap().def;
        assert_eq!(def.tangent_speed, 1.5);
        assert_eq!(def.friction_combine, CombineRule::Max);
        assert_eq!(def.user_material_id, 9);
    }
    assert_eq!(w.validate(), Ok(()));
}
