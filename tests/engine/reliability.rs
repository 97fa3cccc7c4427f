//! Regression tests of issue 14's findings: each is named after what it
//! guards. Every rejected call leaves the world unchanged (state hash,
//! counts) and [`World::validate`] passes after every call.

use janus2d::base::body::BodyError;
use janus2d::base::geometry::GeometryError;
use janus2d::base::limits;
use janus2d::prelude::*;
use janus2d::world::SleepSettings;

const DT: Real = 1.0 / 60.0;

fn ground_and_box() -> (World, BodyHandle, BodyHandle) {
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 2.0)))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    world.step(DT).unwrap();
    (world, ground, b)
}

/// Runs `f` (which must fail) and checks nothing changed.
fn unchanged(
    world: &mut World,
    f: impl FnOnce(&mut World) -> Result<(), WorldError>,
) -> WorldError {
    let before = (
        world.state_hash(),
        world.body_count(),
        world.shape_count(),
        world.joint_count(),
        world.sleeping_body_count(),
    );
    let err = f(world).expect_err("the call must be refused");
    let after = (
        world.state_hash(),
        world.body_count(),
        world.shape_count(),
        world.joint_count(),
        world.sleeping_body_count(),
    );
    assert_eq!(before, after, "refused call {err:?} changed the world");
    world.validate().unwrap();
    err
}

fn out_of_bounds(field: &'static str) -> impl Fn(&WorldError) -> bool {
    move |e| match e {
        WorldError::OutOfBounds { field: f, .. } => *f == field,
        WorldError::Body(BodyError::OutOfBounds { field: f, .. }) => *f == field,
        _ => false,
    }
}

#[test]
fn huge_finite_shape_coordinates_never_reach_the_broadphase() {
    let (mut world, ground, b) = ground_and_box();
    let far = Vec2::new(3e38, 3e38);
    let e = unchanged(&mut world, |w| {
        let c = Capsule {
            center1: far,
            center2: far + Vec2::new(1e37, 0.0),
            radius: 1.0,
        };
        w.create_shape(b, &ShapeDef::default(), c).map(|_| ())
    });
    assert_eq!(
        e,
        WorldError::Geometry(GeometryError::ExtentTooLarge {
            max: limits::MAX_EXTENT
        })
    );
    let e = unchanged(&mut world, |w| {
        w.create_shape(
            ground,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 1e20).unwrap(),
        )
        .map(|_| ())
    });
    assert!(matches!(
        e,
        WorldError::Geometry(GeometryError::ExtentTooLarge { .. })
    ));
    let e = unchanged(&mut world, |w| {
        w.create_body(&BodyDef::dynamic(far)).map(|_| ())
    });
    assert!(out_of_bounds("position")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| w.set_transform(b, far, 0.0));
    assert!(out_of_bounds("transform")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| {
        w.set_target_transform(b, Transform::new(far, 0.0), DT)
    });
    assert!(out_of_bounds("target")(&e), "{e:?}");
    // At the limits themselves everything is accepted, steps and validates.
    let edge = Vec2::splat(limits::MAX_COORDINATE);
    let e_body = world.create_body(&BodyDef::fixed(edge)).unwrap();
    world
        .create_shape(
            e_body,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, limits::MAX_EXTENT).unwrap(),
        )
        .unwrap();
    let d_body = world.create_body(&BodyDef::dynamic(-edge)).unwrap();
    world
        .create_shape(
            d_body,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 1.0).unwrap(),
        )
        .unwrap();
    for _ in 0..3 {
        world.step(DT).unwrap();
        world.validate().unwrap();
    }
}

#[test]
fn a_pose_carried_out_of_the_world_is_reset_and_reported() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let start = Vec2::new(limits::MAX_COORDINATE, 0.0);
    let k = world
        .create_body(&BodyDef::kinematic(start).with_velocity(Vec2::new(limits::MAX_SPEED, 0.0)))
        .unwrap();
    world
        .create_shape(
            k,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 1.0).unwrap(),
        )
        .unwrap();
    let mut reported = None;
    for step in 0..1000 {
        let before = world.position(k).unwrap();
        world.step(DT).unwrap();
        world.validate().unwrap();
        if world.events().non_finite_bodies.contains(&k) {
            reported = Some(step);
            // Put back where the step started, at rest.
            assert_eq!(world.position(k).unwrap(), before);
            assert_eq!(world.linear_velocity(k).unwrap(), Vec2::ZERO);
            break;
        }
    }
    let step = reported.expect("the body leaving the world is reported");
    // 1e9 m more at 1e9 m/s: after about 60 steps.
    assert!((55..=65).contains(&step), "reported at step {step}");
}

/// A step of huge `dt` (1e30) once had to keep every number finite; since
/// issue 35 it is refused (`TIME_STEP_RANGE`), and the largest accepted
/// step keeps every number finite.
#[test]
fn a_step_of_huge_dt_keeps_every_number_finite() {
    let (mut world, _, b) = ground_and_box();
    let (min, max) = limits::TIME_STEP_RANGE;
    let e = unchanged(&mut world, |w| w.step(1e30));
    assert_eq!(
        e,
        WorldError::OutOfBounds {
            field: "dt",
            min,
            max
        }
    );
    world.step(max).unwrap();
    world.validate().unwrap();
    let p = world.position(b).unwrap();
    assert!(p.is_finite() && p.x.abs() <= 2.0 * limits::MAX_COORDINATE);
    assert!(p.y.abs() <= 2.0 * limits::MAX_COORDINATE, "{p:?}");
    world.step(DT).unwrap();
    world.validate().unwrap();
}

#[cfg(feature = "portals")]
#[test]
fn destroying_a_clone_cancels_its_crossing_and_leaves_a_valid_world() {
    let def = janus2d_testbed::scenes::shared_settings();
    let (mut scene, _) = janus2d_testbed::scenes::portal_drop(&def);
    let world = &mut scene.world;
    let mut crossing = None;
    for _ in 0..600 {
        world.step(DT).unwrap();
        crossing = world
            .body_handles()
            .find_map(|b| world.clone_of(b).map(|c| (b, c)));
        if crossing.is_some() {
            break;
        }
    }
    let (original, clone) = crossing.expect("a body starts a crossing");
    let bodies = world.body_count();
    assert_eq!(world.destroy_body(clone), Ok(()));
    assert_eq!(world.body_count(), bodies - 1);
    assert_eq!(world.position(clone), Err(WorldError::StaleBody));
    assert!(world.position(original).is_ok());
    assert_eq!(world.clone_of(original), None);
    world.validate().unwrap();
    // A second destroy of the same handle is a clean error.
    let e = unchanged(world, |w| w.destroy_body(clone));
    assert_eq!(e, WorldError::StaleBody);
    for _ in 0..30 {
        world.step(DT).unwrap();
        world.validate().unwrap();
    }
}

#[test]
fn degenerate_masses_and_inertias_are_refused() {
    let (mut world, _, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(1e-40, 1.0))
            .map(|_| ())
    });
    assert!(out_of_bounds("mass")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| {
        w.create_body(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 1e-42))
            .map(|_| ())
    });
    assert!(out_of_bounds("rotational_inertia")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| w.set_mass(b, BodyMass::new(1e30, 1.0)));
    assert!(out_of_bounds("mass")(&e), "{e:?}");
    // The limits themselves are accepted.
    let (lo, _) = limits::MASS_RANGE;
    let (ilo, _) = limits::INERTIA_RANGE;
    world.set_mass(b, BodyMass::new(lo, ilo)).unwrap();
    world.step(DT).unwrap();
    world.validate().unwrap();
}

#[test]
fn a_shape_whose_mass_overflows_is_refused() {
    let (mut world, _, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        let def = ShapeDef {
            density: 1e38,
            ..ShapeDef::default()
        };
        w.create_shape(b, &def, Circle::new(Vec2::ZERO, 1e6).unwrap())
            .map(|_| ())
    });
    assert!(out_of_bounds("density")(&e), "{e:?}");
    let s = world.body_shapes(b).unwrap()[0];
    let e = unchanged(&mut world, |w| w.set_shape_density(s, 1e38));
    assert!(
        out_of_bounds("density")(&e) || out_of_bounds("rotational_inertia")(&e),
        "{e:?}"
    );
}

#[test]
fn a_tiny_density_gives_a_clamped_finite_mass_and_the_body_falls() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 5.0)))
        .unwrap();
    let def = ShapeDef {
        density: 1e-40,
        ..ShapeDef::default()
    };
    world
        .create_shape(b, &def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    assert_eq!(world.mass(b).unwrap(), limits::MASS_RANGE.0);
    for _ in 0..30 {
        world.step(DT).unwrap();
    }
    world.validate().unwrap();
    assert!(world.position(b).unwrap().y < 4.0);
    assert!(!world.is_sleeping(b).unwrap());
}

#[test]
fn infinite_contact_stiffness_or_damping_is_refused() {
    let (mut world, _, _) = ground_and_box();
    for (s, name) in [
        (
            SolverSettings {
                contact_hertz: Real::INFINITY,
                ..SolverSettings::default()
            },
            "contact_hertz",
        ),
        (
            SolverSettings {
                contact_damping_ratio: Real::INFINITY,
                ..SolverSettings::default()
            },
            "contact_damping_ratio",
        ),
        (
            SolverSettings {
                joint_hertz: Real::INFINITY,
                ..SolverSettings::default()
            },
            "joint_hertz",
        ),
    ] {
        let e = unchanged(&mut world, |w| w.set_settings(s.clone()));
        assert_eq!(e, WorldError::NonFinite(name));
        assert!(
            World::new(WorldDef {
                solver: s,
                ..WorldDef::default()
            })
            .is_err()
        );
    }
    let e = unchanged(&mut world, |w| {
        w.set_settings(SolverSettings {
            contact_damping_ratio: 1e30,
            ..SolverSettings::default()
        })
    });
    assert!(out_of_bounds("contact_damping_ratio")(&e), "{e:?}");
}

#[test]
fn contact_stiffness_above_a_quarter_of_the_substep_rate_is_capped() {
    let stack = |hertz: Real| {
        let mut world = World::new(WorldDef {
            solver: SolverSettings {
                contact_hertz: hertz,
                ..SolverSettings::default()
            },
            ..WorldDef::default()
        })
        .unwrap();
        let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        world
            .create_shape(ground, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))
            .unwrap();
        let mut top = ground;
        for i in 0..3 {
            top = world
                .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0 + i as Real)))
                .unwrap();
            world
                .create_shape(top, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
                .unwrap();
        }
        for _ in 0..120 {
            world.step(DT).unwrap();
        }
        world.validate().unwrap();
        (world.step_context(DT), world.position(top).unwrap().y)
    };
    // 4 substeps at 60 Hz: 240 Hz, a quarter is 60 Hz.
    let (capped, y_huge) = stack(1e30);
    let (at_cap, y_cap) = stack(60.0);
    assert_eq!(capped.contact_softness, at_cap.contact_softness);
    assert_eq!(capped.static_softness, at_cap.static_softness);
    assert_eq!(y_huge, y_cap);
    // The stack stands (it sank 0.36 m before the cap).
    assert!((y_huge - 3.0).abs() < 0.02, "top at {y_huge}");
}

#[test]
fn negative_time_to_sleep_is_refused() {
    let (mut world, _, _) = ground_and_box();
    let bad = SleepSettings {
        time_to_sleep: -1.0,
        ..SleepSettings::default()
    };
    let e = unchanged(&mut world, |w| w.set_sleep_settings(bad));
    assert_eq!(e, WorldError::OutOfRange("time_to_sleep"));
    assert!(
        World::new(WorldDef {
            sleep: bad,
            ..WorldDef::default()
        })
        .is_err()
    );
}

#[test]
fn huge_gravity_is_refused_and_the_largest_allowed_moves_bodies() {
    let (mut world, _, _) = ground_and_box();
    let e = unchanged(&mut world, |w| w.set_gravity(Vec2::new(0.0, -1e22)));
    assert!(out_of_bounds("gravity")(&e), "{e:?}");
    assert!(
        World::new(WorldDef {
            gravity: Vec2::new(1e22, 0.0),
            ..WorldDef::default()
        })
        .is_err()
    );
    let mut world = World::new(WorldDef {
        gravity: Vec2::new(0.0, -limits::MAX_GRAVITY),
        ..WorldDef::default()
    })
    .unwrap();
    let b = world
        .create_body(&BodyDef {
            max_linear_speed: limits::MAX_SPEED,
            ..BodyDef::dynamic(Vec2::ZERO)
        })
        .unwrap();
    world.step(DT).unwrap();
    // v = g dt exactly in the first step (no cap reached, not zeroed).
    let v = world.linear_velocity(b).unwrap().y;
    assert!(
        (v + limits::MAX_GRAVITY * DT).abs() < 1e-3 * limits::MAX_GRAVITY * DT,
        "v = {v}"
    );
}

#[test]
fn hand_built_polygon_with_inward_normals_is_refused() {
    let (mut world, _, b) = ground_and_box();
    let mut p = Polygon::make_box(0.5, 0.5);
    for k in 0..p.count {
        p.normals[k] = -p.normals[k];
    }
    let e = unchanged(&mut world, |w| {
        w.create_shape(b, &ShapeDef::default(), p).map(|_| ())
    });
    assert_eq!(
        e,
        WorldError::Geometry(GeometryError::BadNormal { edge: 0 })
    );
    let mut p = Polygon::make_box(0.5, 0.5);
    p.centroid = Vec2::new(5.0, 0.0);
    let e = unchanged(&mut world, |w| {
        w.create_shape(b, &ShapeDef::default(), p).map(|_| ())
    });
    assert_eq!(e, WorldError::Geometry(GeometryError::CentroidOutside));
}

#[test]
fn zero_length_capsule_literal_is_refused() {
    let (mut world, _, b) = ground_and_box();
    let c = Capsule {
        center1: Vec2::ZERO,
        center2: Vec2::ZERO,
        radius: 0.5,
    };
    let e = unchanged(&mut world, |w| {
        w.create_shape(b, &ShapeDef::default(), c).map(|_| ())
    });
    assert_eq!(e, WorldError::Geometry(GeometryError::DegenerateSegment));
    let core = Polygon::make_capsule(Vec2::ZERO, Vec2::ZERO, 0.5);
    let e = unchanged(&mut world, |w| {
        w.create_shape(b, &ShapeDef::default(), core).map(|_| ())
    });
    assert_eq!(e, WorldError::Geometry(GeometryError::DegenerateSegment));
}

#[test]
fn kinematic_body_created_asleep_with_a_velocity_moves() {
    let mut world = World::new(WorldDef::default()).unwrap();
    let k = world
        .create_body(&BodyDef {
            awake: false,
            ..BodyDef::kinematic(Vec2::ZERO).with_velocity(Vec2::new(1.0, 0.0))
        })
        .unwrap();
    world
        .create_shape(k, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(!world.is_sleeping(k).unwrap());
    assert!((world.position(k).unwrap().x - 1.0).abs() < 1e-4);
    // Without a velocity, `awake: false` still creates it asleep.
    let still = world
        .create_body(&BodyDef {
            awake: false,
            ..BodyDef::kinematic(Vec2::ZERO)
        })
        .unwrap();
    world.step(DT).unwrap();
    assert!(world.is_sleeping(still).unwrap());
    world.validate().unwrap();
}

/// An API call under test.
type Call = Box<dyn Fn(&mut World) -> Result<(), WorldError>>;

#[test]
fn velocity_and_force_calls_on_static_bodies_are_refused() {
    let (mut world, ground, _) = ground_and_box();
    let one = Vec2::new(1.0, 0.0);
    let cases: [(&str, Call, WorldError); 7] = [
        (
            "linear velocity",
            Box::new(move |w| w.set_linear_velocity(ground, one)),
            WorldError::NotMovable,
        ),
        (
            "angular velocity",
            Box::new(move |w| w.set_angular_velocity(ground, 1.0)),
            WorldError::NotMovable,
        ),
        (
            "force",
            Box::new(move |w| w.apply_force(ground, one, Vec2::ZERO)),
            WorldError::NotDynamic,
        ),
        (
            "force at centre",
            Box::new(move |w| w.apply_force_to_center(ground, one)),
            WorldError::NotDynamic,
        ),
        (
            "torque",
            Box::new(move |w| w.apply_torque(ground, 1.0)),
            WorldError::NotDynamic,
        ),
        (
            "impulse",
            Box::new(move |w| w.apply_linear_impulse(ground, one, Vec2::ZERO)),
            WorldError::NotDynamic,
        ),
        (
            "angular impulse",
            Box::new(move |w| w.apply_angular_impulse(ground, 1.0)),
            WorldError::NotDynamic,
        ),
    ];
    for (what, call, expected) in cases {
        let e = unchanged(&mut world, |w| call(w));
        assert_eq!(e, expected, "{what}");
    }
    // Forces on a kinematic body do nothing: refused too.
    let k = world.create_body(&BodyDef::kinematic(Vec2::ZERO)).unwrap();
    let e = unchanged(&mut world, |w| w.apply_force_to_center(k, one));
    assert_eq!(e, WorldError::NotDynamic);
    world.set_linear_velocity(k, one).unwrap();
}

#[test]
fn huge_velocities_are_refused_with_the_limit() {
    let (mut world, _, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        w.set_linear_velocity(b, Vec2::new(1e30, 0.0))
    });
    assert_eq!(
        e,
        WorldError::Body(BodyError::OutOfBounds {
            field: "linear_velocity",
            min: -limits::MAX_SPEED,
            max: limits::MAX_SPEED
        })
    );
    let e = unchanged(&mut world, |w| w.set_angular_velocity(b, -1e30));
    assert!(out_of_bounds("angular_velocity")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| {
        w.create_body(&BodyDef {
            max_linear_speed: 1e30,
            ..BodyDef::dynamic(Vec2::ZERO)
        })
        .map(|_| ())
    });
    assert!(out_of_bounds("max_linear_speed")(&e), "{e:?}");
    assert!(e.to_string().contains("1e9"), "{e}");
}

/// Found by the `hull` fuzz target: a thin hull 3 km from its body origin
/// lost its area to rounding in `validate` (which summed cross products
/// about the origin) and was refused although `from_hull` built it.
#[test]
fn a_hull_far_from_the_body_origin_passes_validation() {
    let points = [
        Vec2::new(3156.3293, 3156.3293),
        Vec2::new(3157.9607, 3156.3293),
        Vec2::new(3156.3293, 3156.3591),
    ];
    let p = Polygon::from_hull(&points, 0.0).unwrap();
    assert_eq!(Shape::Polygon(p).validate(), Ok(()));
    let far = [
        Vec2::new(-413252.72, -411206.25),
        Vec2::new(-411206.25, -411206.25),
        Vec2::new(0.0, -411200.0),
    ];
    let p = Polygon::from_hull(&far, 0.0).unwrap();
    assert_eq!(Shape::Polygon(p).validate(), Ok(()));
}

/// Found by the `hull` fuzz target: a sliver reaching 2e5 m has its
/// centroid on its long edges to within the rounding of such coordinates;
/// `validate` allows for that rounding.
#[test]
fn a_far_reaching_sliver_hull_passes_validation() {
    let points = [
        Vec2::new(-0.024015777, -0.022949569),
        Vec2::new(0.0, -0.023925781),
        Vec2::new(131362.94, 205089.13),
    ];
    let p = Polygon::from_hull(&points, 0.0).unwrap();
    assert_eq!(Shape::Polygon(p).validate(), Ok(()));
}

/// Found by the API state machine: an impulse of 1e30 N·s at 1e30 m gave
/// an infinite angular velocity.
#[test]
fn an_impulse_whose_velocity_overflows_is_refused() {
    let (mut world, _, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        w.apply_linear_impulse(b, Vec2::new(1e30, 0.0), Vec2::new(1e30, 1e30))
    });
    assert!(out_of_bounds("impulse")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| w.apply_angular_impulse(b, 1e30));
    assert!(out_of_bounds("impulse")(&e), "{e:?}");
    // A torque sum that would overflow: the first is kept, the second refused.
    world.apply_torque(b, Real::MAX).unwrap();
    let e = unchanged(&mut world, |w| w.apply_torque(b, Real::MAX));
    assert!(out_of_bounds("torque")(&e), "{e:?}");
}

/// Found by the API state machine: a joint anchored 1e9 m from its body
/// made the joint rows overflow.
#[test]
fn a_joint_anchor_beyond_the_shape_extent_is_refused() {
    let (mut world, ground, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        w.create_revolute_joint(&RevoluteJointDef::new(
            ground,
            b,
            Vec2::new(1e9, 0.0),
            Vec2::ZERO,
        ))
        .map(|_| ())
    });
    assert!(out_of_bounds("local_frame_a.anchor")(&e), "{e:?}");
    let j = world
        .create_revolute_joint(&RevoluteJointDef::new(ground, b, Vec2::ZERO, Vec2::ZERO))
        .unwrap();
    let e = unchanged(&mut world, |w| w.set_joint_spring(j, 1e30, 1.0));
    assert!(out_of_bounds("hertz")(&e), "{e:?}");
    let e = unchanged(&mut world, |w| w.set_joint_motor_speed(j, 1e30));
    assert!(out_of_bounds("motor_speed")(&e), "{e:?}");
}

/// Found by the API state machine: a friction of 1e30 made the friction
/// impulse bound overflow.
#[test]
fn friction_and_restitution_above_their_limits_are_refused() {
    let (mut world, _, b) = ground_and_box();
    let e = unchanged(&mut world, |w| {
        w.create_shape(
            b,
            &ShapeDef::default().with_friction(1e30),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .map(|_| ())
    });
    assert!(out_of_bounds("friction")(&e), "{e:?}");
    let s = world.body_shapes(b).unwrap()[0];
    let e = unchanged(&mut world, |w| w.set_shape_restitution(s, 1e30));
    assert!(out_of_bounds("restitution")(&e), "{e:?}");
}

#[cfg(feature = "portals")]
mod portals {
    use super::*;
    use janus2d::world::{PortalDef, PortalPairDef};

    fn pair_on(a: BodyHandle, b: BodyHandle, half_a: Real) -> PortalPairDef {
        PortalPairDef::new(
            PortalDef {
                body: a,
                anchor: Vec2::new(0.5, 0.0),
                direction: Vec2::new(0.0, 1.0),
                half_width: half_a,
            },
            PortalDef {
                body: b,
                anchor: Vec2::new(-0.5, 0.0),
                direction: Vec2::new(1.0, 0.0),
                half_width: 1.0,
            },
        )
    }

    #[test]
    fn a_portal_scale_outside_its_range_is_refused() {
        let (mut world, ground, b) = ground_and_box();
        for eta in [1e-4, 1e4] {
            let mut def = pair_on(ground, b, 1.0);
            def.eta = Some(eta);
            let e = unchanged(&mut world, |w| w.create_portal_pair(&def).map(|_| ()));
            // The portal map's own range check answers first (the same
            // range as `limits::ETA_RANGE`).
            assert!(
                matches!(
                    e,
                    WorldError::Portal(janus2d::constraints::PortalError::ScaleOutOfRange)
                ) || out_of_bounds("eta")(&e),
                "{e:?}"
            );
        }
    }

    /// Found by the API state machine: a portal placed on a crossing's
    /// clone outlived the clone (destroyed when the crossing ended).
    #[test]
    fn a_portal_on_a_crossing_copy_is_refused() {
        let def = janus2d_testbed::scenes::shared_settings();
        let (mut scene, _) = janus2d_testbed::scenes::portal_drop(&def);
        let world = &mut scene.world;
        let mut crossing = None;
        for _ in 0..600 {
            world.step(DT).unwrap();
            crossing = world
                .body_handles()
                .find_map(|b| world.clone_of(b).map(|c| (b, c)));
            if crossing.is_some() {
                break;
            }
        }
        let (original, clone) = crossing.expect("a body starts a crossing");
        let other = world
            .body_handles()
            .find(|&b| b != original && b != clone)
            .unwrap();
        for body in [original, clone] {
            let e = unchanged(world, |w| {
                w.create_portal_pair(&pair_on(body, other, 1.0)).map(|_| ())
            });
            assert_eq!(e, WorldError::PortalBody);
        }
    }

    /// Found by the API state machine: two portals on one box of a small
    /// pyramid (η = 20) make the boxes explode; the solve's non-finite
    /// impulses are no longer kept for warm starting, so the world stays
    /// valid (every stored number finite).
    #[test]
    fn exploding_portal_contacts_store_no_non_finite_impulses() {
        let def = janus2d_testbed::scenes::shared_settings();
        let mut world = janus2d_testbed::scenes::large_pyramid(&def, 4).world;
        let b: Vec<BodyHandle> = world.body_handles().collect();
        world
            .create_portal_pair(&pair_on(b[5], b[5], 0.05))
            .unwrap();
        for _ in 0..60 {
            world.step(DT).unwrap();
            world.validate().unwrap();
        }
        for c in world.contacts() {
            for p in &c.points[..c.point_count] {
                assert!(p.normal_impulse.is_finite() && p.tangent_impulse.is_finite());
            }
        }
    }
}

/// Issue 35: snapshot bytes whose payload was changed (length and checksum
/// recomputed) are an error or a world that steps, is destroyed piece by
/// piece and validates without a panic.
#[cfg(feature = "serde")]
mod snapshot_bytes {
    use super::*;
    use janus2d::constraints::JointKind;
    use janus2d::world::{Snapshot, SnapshotError};
    use janus2d_testbed::support::joint_def_of_kind;

    /// A small world with every joint kind, a sleeping stack, an island
    /// that lost a body and contacts.
    pub(super) fn small_mixed_world() -> World {
        let mut world = World::new(WorldDef::default()).unwrap();
        let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        world
            .create_shape(ground, &ShapeDef::default(), Polygon::make_box(30.0, 0.5))
            .unwrap();
        for (k, &kind) in JointKind::ALL.iter().enumerate() {
            let mut previous = ground;
            for i in 0..3 {
                let p = Vec2::new(-20.0 + 5.0 * k as Real + 1.1 * i as Real, 4.0);
                let b = world.create_body(&BodyDef::dynamic(p)).unwrap();
                world
                    .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.4, 0.4))
                    .unwrap();
                let limits = (kind != JointKind::Distance).then_some((-0.5, 0.5));
                let def = joint_def_of_kind(kind, previous, b, Vec2::new(0.55, 0.0), limits, false);
                world.create_joint(&def).unwrap();
                previous = b;
            }
        }
        let mut stack = Vec::new();
        for i in 0..4 {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(25.0, 1.0 + i as Real)))
                .unwrap();
            world
                .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
                .unwrap();
            stack.push(b);
        }
        for _ in 0..90 {
            world.step(DT).unwrap();
        }
        world.destroy_body(stack[3]).unwrap();
        world.step(DT).unwrap();
        world
    }

    fn fnv(bytes: &[u8]) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in bytes {
            h ^= u64::from(*b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        h
    }

    /// Steps, API calls and destruction of everything on a decoded world.
    fn exercise(mut world: World) {
        for _ in 0..3 {
            let _ = world.step(DT);
        }
        let bodies: Vec<BodyHandle> = world.body_handles().collect();
        for &b in &bodies {
            let _ = world.is_sleeping(b);
            let _ = world.wake_body(b);
        }
        let _ = world.step(DT);
        for &j in world.joint_handles().to_vec().iter().step_by(2) {
            let _ = world.joint_force(j);
            let _ = world.destroy_joint(j);
        }
        let _ = world.step(DT);
        for &b in bodies.iter().step_by(3) {
            let _ = world.destroy_body(b);
        }
        let _ = world.step(DT);
        let _ = world.cast_ray_closest(
            Vec2::new(-30.0, 2.0),
            Vec2::new(60.0, 0.0),
            &QueryFilter::default(),
        );
        for &b in &bodies {
            let _ = world.destroy_body(b);
        }
        let _ = world.step(DT);
    }

    #[test]
    fn tampered_snapshot_payloads_never_panic() {
        let count: usize = std::env::var("JANUS_TAMPER_COUNT")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1500);
        let bytes = small_mixed_world().snapshot().to_bytes();
        let payload_len = bytes.len() - 24;
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (mut accepted, mut panics) = (0usize, Vec::new());
        for round in 0..count {
            let mut bad = bytes.clone();
            let edits = 1 + (next() % 3) as usize;
            for _ in 0..edits {
                let k = 24 + (next() as usize) % payload_len;
                bad[k] = match next() % 4 {
                    0 => bad[k] ^ (1 << (next() % 8)),
                    1 => bad[k].wrapping_add(1),
                    2 => bad[k].wrapping_sub(1),
                    _ => next() as u8,
                };
            }
            let h = fnv(&bad[24..]);
            bad[16..24].copy_from_slice(&h.to_le_bytes());
            let outcome = std::panic::catch_unwind(|| match Snapshot::from_bytes(&bad) {
                Ok(snapshot) => {
                    exercise(snapshot.to_world());
                    true
                }
                Err(SnapshotError::Decode(_) | SnapshotError::Invalid(_)) => false,
                Err(e) => panic!("unexpected error {e:?}"),
            });
            match outcome {
                Ok(ok) => accepted += usize::from(ok),
                Err(_) => panics.push(round),
            }
        }
        assert!(
            accepted > 0,
            "no tampered snapshot was accepted: the test exercises nothing"
        );
        assert!(
            panics.is_empty(),
            "{} of {count} tampered snapshots panicked: rounds {:?}",
            panics.len(),
            &panics[..panics.len().min(20)]
        );
    }

    #[test]
    fn snapshot_bytes_after_the_stated_payload_are_refused() {
        let mut bytes = small_mixed_world().snapshot().to_bytes();
        assert!(Snapshot::from_bytes(&bytes).is_ok());
        bytes.push(0);
        assert!(matches!(
            Snapshot::from_bytes(&bytes),
            Err(SnapshotError::TrailingBytes { extra: 1 })
        ));
    }
}

/// Issue 35: a force whose velocity step overflows `|v|²` (1e30 N on a
/// 1 kg box) leaves the body at its speed limit along the force, not at
/// rest with its velocity erased.
#[test]
fn a_force_whose_speed_overflows_is_clamped_to_the_speed_limit_not_erased() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    world.set_linear_velocity(b, Vec2::new(3.0, 0.0)).unwrap();
    world
        .apply_force_to_center(b, Vec2::new(1e30, 0.0))
        .unwrap();
    world.step(DT).unwrap();
    let v = world.linear_velocity(b).unwrap();
    let max = BodyDef::default().max_linear_speed;
    assert!((v.x - max).abs() <= 1e-3 * max && v.y == 0.0, "{v:?}");
    assert!(world.position(b).unwrap().x > 1.0);
    world.validate().unwrap();
}

/// Issue 35: every joint kind hung far from its anchors (the first joint
/// of each chain tens of metres out, so the joint tree pulls hard): after
/// each step no body is faster than `max_linear_speed` (the solve and relax
/// reached 436 m/s at the first step, 7e5 m/s at the third) and every
/// joint's read-back is finite (it went to inf and NaN).
#[test]
fn max_linear_speed_and_finite_joint_read_back_hold_after_every_step() {
    let mut world = janus2d_testbed::support::every_joint_kind_world();
    let max = BodyDef::default().max_linear_speed;
    for step in 0..120 {
        world.step(DT).unwrap();
        let bodies: Vec<BodyHandle> = world.body_handles().collect();
        for b in bodies {
            let v = world.linear_velocity(b).unwrap().length();
            assert!(v <= max * (1.0 + 1e-5), "step {step}: {b:?} at {v} m/s");
        }
        for &j in world.joint_handles() {
            let (f, t) = (
                world.joint_force(j).unwrap(),
                world.joint_torque(j).unwrap(),
            );
            assert!(
                f.is_finite() && t.is_finite(),
                "step {step}: {j:?} {f:?} {t}"
            );
        }
        world.validate().unwrap();
    }
}

/// One of every shape kind at (0, 10), each on its own static body.
fn one_of_every_shape_kind() -> World {
    let mut world = World::new(WorldDef::default()).unwrap();
    let shapes: [Shape; 6] = [
        Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap()),
        Shape::Capsule(Capsule::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), 0.5).unwrap()),
        Shape::Polygon(Polygon::make_box(0.5, 0.5)),
        Shape::Polygon(Polygon::make_rounded_box(0.5, 0.5, 0.25)),
        Shape::Segment(Segment::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0)).unwrap()),
        // Going +x: its front faces −y, towards the rays from below.
        Shape::ChainSegment(
            make_chain(&[Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0)], false).unwrap()[0],
        ),
    ];
    for shape in shapes {
        let b = world
            .create_body(&BodyDef::fixed(Vec2::new(0.0, 10.0)))
            .unwrap();
        world.create_shape(b, &ShapeDef::default(), shape).unwrap();
    }
    world
}

/// Issue 35: a ray of translation ≥ ~1e20 against a circle gave a hit
/// with a NaN point and fraction (`b² − |d|² c` overflowed to ∞ − ∞).
/// Every shape kind, every magnitude of translation and origin the
/// queries accept: every hit finite, the fraction in `[0, 1]`.
#[test]
fn circle_ray_casts_at_huge_translations_stay_finite() {
    let filter = QueryFilter::default();
    // The case: a circle of radius 0.5 at (0, 10).
    let mut world = World::new(WorldDef::default()).unwrap();
    let b = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 10.0)))
        .unwrap();
    world
        .create_shape(
            b,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .unwrap();
    let hit = world
        .cast_ray_closest(Vec2::ZERO, Vec2::new(0.0, 1e20), &filter)
        .unwrap()
        .expect("the ray meets the shapes above");
    assert!(hit.fraction > 0.0 && hit.fraction < 1e-18, "{hit:?}");
    assert!((hit.point - Vec2::new(0.0, 9.5)).length() < 1e-3, "{hit:?}");
    let world = one_of_every_shape_kind();
    let mut checked = 0;
    for e in -38..=38 {
        let len = (10.0 as Real).powi(e);
        for dir in [
            Vec2::new(0.0, 1.0),
            Vec2::new(1e-3, 1.0),
            Vec2::new(-1.0, 1.0),
        ] {
            for origin in [
                Vec2::ZERO,
                Vec2::new(0.0, 9.0),
                Vec2::new(0.0, -1e20),
                Vec2::new(0.0, -3e38),
                Vec2::new(-3e38, -3e38),
            ] {
                let t = dir * len;
                if !t.is_finite() || t.length_squared() == 0.0 {
                    continue; // refused: not finite, or too short to have a direction
                }
                world
                    .cast_ray_with(origin, t, &filter, |h| {
                        assert!(
                            h.point.is_finite() && h.normal.is_finite() && h.fraction.is_finite(),
                            "{origin:?} + {t:?}: {h:?}"
                        );
                        assert!((0.0..=1.0).contains(&h.fraction), "{h:?}");
                        assert!((h.normal.length() - 1.0).abs() < 1e-3, "{h:?}");
                        checked += 1;
                        1.0
                    })
                    .unwrap();
            }
        }
    }
    assert!(checked > 100, "{checked} hits");
}

/// Every joint's force and torque read-back is finite.
fn joint_read_back_finite(world: &World, what: &str) {
    for &j in world.joint_handles() {
        let f = world.joint_force(j).unwrap();
        let t = world.joint_torque(j).unwrap();
        assert!(f.is_finite() && t.is_finite(), "{what}: {j:?} {f:?} {t}");
    }
}

/// Issue 35: `joint_force`/`joint_torque` were ±∞ after
/// `step(f32::MIN_POSITIVE)` and NaN after `step(1e10)` (NaN persisting
/// for 100 normal steps). The smallest and the largest accepted steps
/// keep the read-back finite; a step outside `TIME_STEP_RANGE` is refused.
#[test]
fn joint_read_back_stays_finite_at_the_smallest_and_largest_dt() {
    let mut world = janus2d_testbed::support::every_joint_kind_world();
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    let (min, max) = limits::TIME_STEP_RANGE;
    for dt in [min, DT, max, min, max, DT] {
        world.step(dt).unwrap();
        world.validate().unwrap();
        joint_read_back_finite(&world, &format!("after a step of {dt:e}"));
    }
    for dt in [
        Real::MIN_POSITIVE,
        1e-30,
        0.5 * min,
        1.5 * max,
        1e10,
        Real::MAX,
    ] {
        let e = unchanged(&mut world, |w| w.step(dt));
        assert_eq!(
            e,
            WorldError::OutOfBounds {
                field: "dt",
                min,
                max
            }
        );
    }
    for _ in 0..100 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        joint_read_back_finite(&world, "after a normal step");
    }
}

/// Issue 35: query transforms took non-unit rotations (`Rot { c: 2, s: 0 }`
/// scaled the cast shape, `Rot { 0, 0 }` collapsed it, `Rot { 1e30, 0 }`
/// hit at fraction 0 at (−2.5e29, −2.5e29)), and `set_target_transform`
/// treated `(1e20, 1e20)` and `(1e-20, 1e-20)` as no rotation. A rotation
/// within `UNIT_ROTATION_TOLERANCE` of unit length is normalised, any
/// other refused with the world unchanged.
#[test]
fn query_and_target_rotations_must_be_unit_length() {
    use janus2d::world::QueryProblem;
    let (mut world, _, b) = ground_and_box();
    let filter = QueryFilter::default();
    let ball = Shape::Circle(Circle::new(Vec2::new(0.5, 0.0), 0.25).unwrap());
    let at = |q: Rot| Transform {
        p: Vec2::new(0.0, 6.0),
        q,
    };
    let down = Vec2::new(0.0, -10.0);
    for q in [
        Rot { c: 2.0, s: 0.0 },
        Rot { c: 0.0, s: 0.0 },
        Rot { c: 1e30, s: 0.0 },
        Rot { c: 1e20, s: 1e20 },
        Rot { c: 1e-20, s: 1e-20 },
        Rot { c: 0.99, s: 0.0 },
    ] {
        let e = world.cast_shape_closest(&ball, &at(q), down, &filter);
        let refused = WorldError::BadQuery {
            field: "transform",
            problem: QueryProblem::NotUnitRotation,
        };
        assert_eq!(e, Err(refused.clone()), "{q:?}");
        let e = world.overlap_shape(&ball, &at(q), &filter, |_| true);
        assert_eq!(e, Err(refused), "{q:?}");
        let e = unchanged(&mut world, |w| {
            w.set_target_transform(
                b,
                Transform {
                    p: Vec2::new(0.0, 2.0),
                    q,
                },
                DT,
            )
        });
        assert_eq!(e, WorldError::OutOfRange("target"), "{q:?}");
    }
    // Within the tolerance: normalised, the same hit as the unit rotation.
    let unit = world
        .cast_shape_closest(&ball, &at(Rot::IDENTITY), down, &filter)
        .unwrap()
        .unwrap();
    let near = world
        .cast_shape_closest(&ball, &at(Rot { c: 1.0004, s: 0.0 }), down, &filter)
        .unwrap()
        .unwrap();
    assert_eq!(unit, near);
    // A target turned by π/4 given as (0.7074, 0.7074): the body turns π/4.
    let k = world
        .create_body(&BodyDef::kinematic(Vec2::new(5.0, 5.0)))
        .unwrap();
    let q = Rot {
        c: 0.7074,
        s: 0.7074,
    };
    world
        .set_target_transform(
            k,
            Transform {
                p: Vec2::new(5.0, 5.0),
                q,
            },
            DT,
        )
        .unwrap();
    world.step(DT).unwrap();
    let angle = world.transform(k).unwrap().q.angle();
    assert!(
        (angle - std::f32::consts::FRAC_PI_4 as Real).abs() < 1e-4,
        "{angle}"
    );
}

/// Issue 35: a shape cast with translation `(1, −f32::MAX)` (any length
/// beyond ~1.8e19, whose square overflows) missed the box right below.
/// A ball 5.25 m above the ground box meets it at any length of cast.
#[test]
fn shape_casts_at_huge_translations_meet_the_shape_below() {
    let (world, ground, _) = ground_and_box();
    let filter = QueryFilter::default();
    let ball = Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap());
    let start = Transform::new(Vec2::new(3.0, 6.0), 0.0);
    for t in [
        Vec2::new(0.0, -10.0),
        Vec2::new(1e-3, -1e6),
        Vec2::new(0.0, -1e20),
        Vec2::new(0.0, -1e30),
        Vec2::new(1.0, -Real::MAX),
        Vec2::new(0.0, -Real::MAX),
    ] {
        let hit = world
            .cast_shape_closest(&ball, &start, t, &filter)
            .unwrap()
            .unwrap_or_else(|| panic!("{t:?} misses the ground"));
        assert_eq!(hit.body, ground);
        let travelled = hit.fraction * t.y.abs();
        assert!((travelled - 5.25).abs() < 1e-3, "{t:?}: {hit:?}");
        assert!(hit.point.is_finite() && hit.normal.is_finite());
        assert!((hit.point - Vec2::new(3.0, 0.5)).length() < 1e-3, "{hit:?}");
    }
}

/// Issue 35: portal definitions had no magnitude limits (half-width 1e30
/// or `f32::MAX`, anchor (1e30, 0.5) accepted; with half-width 1e30 every
/// resting body fell through). Anchor coordinates and half-widths are
/// within the shape limit `MAX_EXTENT`.
#[cfg(feature = "portals")]
#[test]
fn portal_geometry_beyond_the_shape_limits_is_refused() {
    use janus2d::world::{PortalDef, PortalPairDef};
    let (mut world, ground, _) = ground_and_box();
    let wall = world
        .create_body(&BodyDef::fixed(Vec2::new(20.0, 0.0)))
        .unwrap();
    let max = limits::MAX_EXTENT;
    let at = |body, anchor, half_width| PortalDef {
        body,
        anchor,
        direction: Vec2::Y,
        half_width,
    };
    for (a, field) in [
        (at(ground, Vec2::new(0.0, 0.5), 1e30), "half_width"),
        (at(ground, Vec2::new(0.0, 0.5), Real::MAX), "half_width"),
        (at(ground, Vec2::new(0.0, 0.5), 2.0 * max), "half_width"),
        (at(ground, Vec2::new(1e30, 0.5), 0.5), "anchor"),
        (at(ground, Vec2::new(0.0, -2.0 * max), 0.5), "anchor"),
    ] {
        let b = at(wall, Vec2::ZERO, a.half_width.min(1.0));
        for def in [PortalPairDef::new(a, b), PortalPairDef::new(b, a)] {
            let def = def.with_eta(1.0);
            let e = unchanged(&mut world, |w| w.create_portal_pair(&def).map(|_| ()));
            let min = if field == "anchor" { -max } else { 0.0 };
            assert_eq!(e, WorldError::OutOfBounds { field, min, max }, "{def:?}");
        }
    }
    // At the limits themselves: accepted.
    let def = PortalPairDef::new(
        at(ground, Vec2::new(max, 0.5), max),
        at(wall, Vec2::new(0.0, -max), 1.0),
    )
    .with_eta(1.0);
    world.create_portal_pair(&def).unwrap();
    world.step(DT).unwrap();
    world.validate().unwrap();
}

/// Issue 35: `max_motor_torque = ∞` was accepted. The joint motors'
/// largest torque and force are finite, on creation and through the
/// setters.
#[test]
fn infinite_motor_torques_and_forces_are_refused() {
    use janus2d::constraints::{JointError, JointKind};
    use janus2d_testbed::support::joint_def_of_kind;
    let (mut world, ground, b) = ground_and_box();
    for kind in [
        JointKind::Revolute,
        JointKind::Wheel,
        JointKind::Prismatic,
        JointKind::Distance,
    ] {
        let mut def = joint_def_of_kind(kind, ground, b, Vec2::new(0.5, 0.0), None, false);
        let linear = matches!(kind, JointKind::Prismatic | JointKind::Distance);
        {
            let m = def.motor_mut().unwrap();
            *m.enable = true;
            *m.speed = 1.0;
            *m.max = Real::INFINITY;
        }
        let e = unchanged(&mut world, |w| w.create_joint(&def).map(|_| ()));
        assert_eq!(e, WorldError::Joint(JointError::NonFinite), "{kind:?}");
        *def.motor_mut().unwrap().max = 10.0;
        let j = world.create_joint(&def).unwrap();
        let e = unchanged(&mut world, |w| {
            if linear {
                w.set_joint_max_motor_force(j, Real::INFINITY)
            } else {
                w.set_joint_max_motor_torque(j, Real::INFINITY)
            }
        });
        let field = if linear {
            "max_motor_force"
        } else {
            "max_motor_torque"
        };
        assert_eq!(e, WorldError::NonFinite(field), "{kind:?}");
        world.destroy_joint(j).unwrap();
    }
}

/// Issue 35: `baumgarte = 1e30` was accepted (bodies were reset). Every
/// solver setting is within its stated range (`SolverSettings::validate`).
#[test]
fn solver_settings_beyond_their_ranges_are_refused() {
    let (mut world, _, _) = ground_and_box();
    let d = SolverSettings::default;
    for (s, name) in [
        (
            SolverSettings {
                baumgarte: 1e30,
                ..d()
            },
            "baumgarte",
        ),
        (
            SolverSettings {
                baumgarte: 1.5,
                ..d()
            },
            "baumgarte",
        ),
        (
            SolverSettings {
                direct_joint_hertz: 1e30,
                ..d()
            },
            "direct_joint_hertz",
        ),
        (
            SolverSettings {
                contact_push_max_velocity: 1e30,
                ..d()
            },
            "contact_push_max_velocity",
        ),
        (
            SolverSettings {
                restitution_threshold: 1e30,
                ..d()
            },
            "restitution_threshold",
        ),
        (
            SolverSettings {
                direct_joint_max_correction_speed: 1e30,
                ..d()
            },
            "direct_joint_max_correction_speed",
        ),
        (
            SolverSettings {
                contact_mass_ratio_cap: 1e30,
                ..d()
            },
            "contact_mass_ratio_cap",
        ),
        (
            SolverSettings {
                joint_mass_ratio_cap: 1e30,
                ..d()
            },
            "joint_mass_ratio_cap",
        ),
    ] {
        let e = unchanged(&mut world, |w| w.set_settings(s.clone()));
        assert_eq!(e, WorldError::OutOfRange(name));
        let def = WorldDef {
            solver: s,
            ..WorldDef::default()
        };
        assert!(World::new(def).is_err(), "{name}");
    }
    // The ends of the ranges are accepted, and the documented unbounded
    // values (no hertz cap, no Gauss–Seidel correction cap).
    world
        .set_settings(SolverSettings {
            baumgarte: 1.0,
            contact_hertz_fraction: Real::INFINITY,
            joint_max_correction_speed: Real::MAX,
            ..d()
        })
        .unwrap();
    world.step(DT).unwrap();
    world.validate().unwrap();
}

/// Issue 35: a static body created with a velocity was accepted and the
/// velocity silently dropped. It is refused as setting a static body's
/// velocity is (`NotMovable`).
#[test]
fn a_static_body_created_with_a_velocity_is_refused() {
    let (mut world, _, _) = ground_and_box();
    for def in [
        BodyDef::fixed(Vec2::ZERO).with_velocity(Vec2::new(3.0, 0.0)),
        BodyDef {
            angular_velocity: 1.0,
            ..BodyDef::fixed(Vec2::ZERO)
        },
    ] {
        let e = unchanged(&mut world, |w| w.create_body(&def).map(|_| ()));
        assert_eq!(e, WorldError::NotMovable);
    }
    let nan = BodyDef::fixed(Vec2::ZERO).with_velocity(Vec2::new(Real::NAN, 0.0));
    let e = unchanged(&mut world, |w| w.create_body(&nan).map(|_| ()));
    assert!(matches!(e, WorldError::Body(_)), "{e:?}");
}

/// Issue 35: portal events pushed by calls between steps (destroying a
/// crossing's clone, its original or the portal pair: `CrossingCancelled`)
/// were cleared by the next step before anyone read them, and "started −
/// completed − cancelled = crossing_count" failed. They are reported with
/// the next step's events, first, and the count adds up after every step.
#[cfg(feature = "portals")]
#[test]
fn portal_events_of_calls_between_steps_are_reported_with_the_next_step() {
    use janus2d::world::PortalEvent;
    let def = janus2d_testbed::scenes::shared_settings();
    // (what is destroyed mid-crossing: 0 the clone, 1 the original, 2 the pair)
    for what in 0..3 {
        let (mut scene, _) = janus2d_testbed::scenes::portal_drop(&def);
        let world = &mut scene.world;
        let mut open: i64 = 0;
        let mut count = |world: &World| {
            for e in &world.events().portals {
                match e {
                    PortalEvent::CrossingStarted { .. } => open += 1,
                    PortalEvent::CrossingCompleted { .. }
                    | PortalEvent::CrossingCancelled { .. } => open -= 1,
                    PortalEvent::JointDisabled { .. } => {}
                }
            }
            assert_eq!(open, world.crossing_count() as i64, "case {what}");
        };
        let mut crossing = None;
        for _ in 0..600 {
            world.step(DT).unwrap();
            count(world);
            crossing = world
                .body_handles()
                .find_map(|b| world.clone_of(b).map(|c| (b, c)));
            if crossing.is_some() {
                break;
            }
        }
        let (original, clone) = crossing.expect("a body starts a crossing");
        let pair = world.portal_pairs().next().unwrap().0;
        match what {
            0 => world.destroy_body(clone).unwrap(),
            1 => world.destroy_body(original).unwrap(),
            _ => world.destroy_portal_pair(pair).unwrap(),
        }
        assert_eq!(world.crossing_count(), 0);
        world.step(DT).unwrap();
        let cancelled = world
            .events()
            .portals
            .iter()
            .filter(|e| matches!(e, PortalEvent::CrossingCancelled { pair: p, .. } if *p == pair))
            .count();
        assert!(cancelled >= 1, "case {what}: {:?}", world.events().portals);
        assert!(
            matches!(
                world.events().portals[0],
                PortalEvent::CrossingCancelled { .. }
            ),
            "case {what}: the call's events come first: {:?}",
            world.events().portals
        );
        count(world);
        for _ in 0..120 {
            world.step(DT).unwrap();
            count(world);
            world.validate().unwrap();
        }
    }
}

/// Issue 35: `is_sleeping` and `wake_body` accepted stale handles
/// silently. Both refuse a destroyed body's handle (and another world's),
/// the world unchanged.
#[test]
fn is_sleeping_and_wake_body_reject_stale_handles() {
    let (mut world, _, b) = ground_and_box();
    let gone = world
        .create_body(&BodyDef::dynamic(Vec2::new(5.0, 5.0)))
        .unwrap();
    world.destroy_body(gone).unwrap();
    assert_eq!(world.is_sleeping(gone), Err(WorldError::StaleBody));
    let e = unchanged(&mut world, |w| w.wake_body(gone));
    assert_eq!(e, WorldError::StaleBody);
    let mut other = World::new(WorldDef::default()).unwrap();
    let foreign = other.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    assert_eq!(world.is_sleeping(foreign), Err(WorldError::ForeignHandle));
    let e = unchanged(&mut world, |w| w.wake_body(foreign));
    assert_eq!(e, WorldError::ForeignHandle);
    assert_eq!(world.is_sleeping(b), Ok(false));
    assert_eq!(world.wake_body(b), Ok(()));
}
