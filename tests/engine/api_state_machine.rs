//! The API as a state machine: random sequences of every mutating call,
//! valid and invalid values mixed (NaN, ±inf, 1e30, −0.0, zero and negative
//! sizes, degenerate polygons, stale and foreign handles, η ≤ 0, coincident
//! portals). After every operation: no panic; an `Err` left the world
//! unchanged (state hash and counts); [`World::validate`] passes (which
//! includes every stored number being finite).
//!
//! The calls include issue 32's: chains, geometry setters (generic, per
//! kind, scaling), motion locks, enable/disable, gravity scale, damping
//! and fixed rotation, surface materials, friction and restitution, the
//! per-shape and per-body event switches, explosions, the point, shape and
//! sensor queries with a predicate filter, the mover casts and collisions,
//! the character controller, and the callbacks (a pre-solve hook writing
//! any value into the contact material, a pair filter, friction and
//! restitution callbacks).
//!
//! CI runs 48 cases of up to 48 operations, each from one of four
//! starting worlds (a ground box, the portal drop, a small pyramid, the
//! issue-32 world of every new per-body and per-shape state). A longer run:
//!
//! ```text
//! JANUS_STATE_MACHINE_CASES=5000 cargo test --release --test engine api_state_machine
//! ```

use janus2d::prelude::*;
use janus2d::world::{PortalDef, PortalPairDef, PortalPairHandle, SleepSettings};
use proptest::prelude::*;

/// A real: mostly ordinary, often special.
fn real() -> impl Strategy<Value = Real> {
    prop_oneof![
        6 => -10.0 as Real..10.0,
        1 => Just(Real::NAN),
        1 => Just(Real::INFINITY),
        1 => Just(Real::NEG_INFINITY),
        1 => Just(1e30 as Real),
        1 => Just(-1e30 as Real),
        1 => Just(-0.0 as Real),
        1 => Just(0.0 as Real),
        1 => Just(-1.0 as Real),
        1 => Just(1e-40 as Real),
        1 => Just(1e9 as Real),
    ]
}

/// A positive size, sometimes bad.
fn size() -> impl Strategy<Value = Real> {
    prop_oneof![6 => 0.05 as Real..2.0, 2 => real()]
}

fn vec2() -> impl Strategy<Value = Vec2> {
    (real(), real()).prop_map(|(x, y)| Vec2::new(x, y))
}

/// A mostly sane position (so that things meet), sometimes anything.
fn place() -> impl Strategy<Value = Vec2> {
    prop_oneof![
        5 => (-4.0 as Real..4.0, -1.0 as Real..6.0).prop_map(|(x, y)| Vec2::new(x, y)),
        1 => vec2(),
    ]
}

#[derive(Clone, Debug)]
enum Geometry {
    Circle(Vec2, Real),
    Box(Real, Real),
    Capsule(Vec2, Vec2, Real),
    Hull(Vec<Vec2>, Real),
    Segment(Vec2, Vec2),
    InwardBox(Real),
}

fn geometry() -> impl Strategy<Value = Geometry> {
    prop_oneof![
        (place(), size()).prop_map(|(c, r)| Geometry::Circle(c * 0.1, r)),
        (size(), size()).prop_map(|(a, b)| Geometry::Box(a, b)),
        (place(), place(), size()).prop_map(|(a, b, r)| Geometry::Capsule(a * 0.2, b * 0.2, r)),
        (proptest::collection::vec(place(), 0..10), size())
            .prop_map(|(p, r)| Geometry::Hull(p.iter().map(|v| *v * 0.3).collect(), r * 0.1)),
        (place(), place()).prop_map(|(a, b)| Geometry::Segment(a, b)),
        size().prop_map(Geometry::InwardBox),
    ]
}

#[derive(Clone, Debug)]
enum Op {
    CreateBody {
        ty: u8,
        position: Vec2,
        velocity: Vec2,
        w: Real,
        mass: Option<(Real, Real)>,
        awake: bool,
        bullet: bool,
    },
    DestroyBody(usize),
    CreateShape {
        body: usize,
        geometry: Geometry,
        density: Real,
        friction: Real,
        sensor: bool,
    },
    DestroyShape(usize),
    /// A chain on a body: its points, loop flag, and 1 material or one
    /// per segment (`per_segment`, sometimes a wrong count).
    CreateChain {
        body: usize,
        points: Vec<Vec2>,
        is_loop: bool,
        materials: usize,
        friction: Real,
    },
    DestroyChain(usize),
    CreateJoint {
        kind: usize,
        a: usize,
        b: usize,
        anchor: Vec2,
        limits: Option<(Real, Real)>,
        collide: bool,
    },
    DestroyJoint(usize),
    CreatePortalPair {
        a: usize,
        b: usize,
        anchor: Vec2,
        half_width: Real,
        eta: Option<Real>,
        coincident: bool,
    },
    DestroyPortalPair(usize),
    SetVelocity(usize, Vec2, Real),
    SetTransform(usize, Vec2, Real),
    SetMass(usize, Real, Real),
    SetBodyType(usize, u8),
    Force(usize, Vec2),
    Impulse(usize, Vec2, Vec2),
    Torque(usize, Real),
    GravityScale(usize, Real),
    LinearDamping(usize, Real),
    AngularDamping(usize, Real),
    FixedRotation(usize, bool),
    MotionLocks(usize, u8),
    BodyEnabled(usize, bool),
    SetGeometry(usize, Geometry),
    ScaleShape(usize, Real),
    /// A shape's surface material: rolling resistance (0), tangent speed
    /// (1) or user material id (2).
    SurfaceMaterial(usize, u8, Real),
    Explode {
        position: Vec2,
        radius: Real,
        falloff: Real,
        impulse: Real,
    },
    /// A shape's event switch: contact (0), sensor (1), hit (2), force
    /// threshold (3, the value); a body's move events (4); the world's (5).
    EventSwitch(usize, u8, bool, Real),
    /// A shape's friction (0) or restitution (1).
    ShapeMixing(usize, u8, Real),
    /// The setter of the geometry's own kind (`set_circle`, `set_capsule`,
    /// `set_polygon`, `set_segment`); on a chain segment,
    /// `set_chain_segment` with its points moved by the vector.
    SetKindGeometry(usize, Geometry, Vec2),
    /// The mover: a capsule of `radius` at `at` cast by `translation`
    /// (all shapes, or a one-way predicate), collided with `margin`, and a
    /// character controller moving it for `dt`.
    Mover {
        at: Vec2,
        radius: Real,
        translation: Vec2,
        margin: Real,
        dt: Real,
        one_way: bool,
    },
    /// Callbacks: a pre-solve hook writing `value` into every material
    /// field and dropping every third contact (0), a pair filter (1),
    /// friction and restitution callbacks returning `value` (2), none (3).
    Hooks(u8, Real),
    /// Queries (they change nothing, errors included).
    Query(usize, Vec2, Real),
    Settings {
        hertz: Real,
        damping: Real,
        substeps: u32,
    },
    Gravity(Vec2),
    Sleep {
        enabled: bool,
        threshold: Real,
        time: Real,
    },
    Step(Real),
    /// Thirty steps of 1/60 s (bodies fall, touch, cross portals, sleep).
    StepMany,
    Snapshot,
    Restore,
}

fn op() -> impl Strategy<Value = Op> {
    let pick = || 0usize..64;
    prop_oneof![
        4 => (0u8..3, place(), prop_oneof![3 => Just(Vec2::ZERO), 1 => vec2()], real(),
              proptest::option::weighted(0.3, (real(), real())), any::<bool>(), any::<bool>())
            .prop_map(|(ty, position, velocity, w, mass, awake, bullet)| Op::CreateBody {
                ty, position, velocity, w, mass, awake: awake || ty == 0, bullet,
            }),
        1 => pick().prop_map(Op::DestroyBody),
        4 => (pick(), geometry(), prop_oneof![3 => Just(1.0 as Real), 1 => real()], prop_oneof![3 => Just(0.6 as Real), 1 => real()], proptest::bool::weighted(0.1))
            .prop_map(|(body, geometry, density, friction, sensor)| Op::CreateShape { body, geometry, density, friction, sensor }),
        1 => pick().prop_map(Op::DestroyShape),
        2 => (pick(), prop_oneof![4 => proptest::collection::vec((-4.0 as Real..4.0, -1.0 as Real..6.0).prop_map(|(x, y)| Vec2::new(x, y)), 2..7), 1 => proptest::collection::vec(place(), 0..7)],
              any::<bool>(), prop_oneof![4 => Just(1usize), 1 => 0usize..8], prop_oneof![3 => Just(0.6 as Real), 1 => real()])
            .prop_map(|(body, points, is_loop, materials, friction)| Op::CreateChain { body, points, is_loop, materials, friction }),
        1 => pick().prop_map(Op::DestroyChain),
        2 => (any::<usize>(), pick(), pick(), place(), proptest::option::weighted(0.3, (real(), real())), any::<bool>())
            .prop_map(|(kind, a, b, anchor, limits, collide)| Op::CreateJoint { kind, a, b, anchor, limits, collide }),
        1 => pick().prop_map(Op::DestroyJoint),
        1 => (pick(), pick(), place(), size(), proptest::option::weighted(0.5, real()), proptest::bool::weighted(0.2))
            .prop_map(|(a, b, anchor, half_width, eta, coincident)| Op::CreatePortalPair { a, b, anchor, half_width, eta, coincident }),
        1 => pick().prop_map(Op::DestroyPortalPair),
        2 => (pick(), vec2(), real()).prop_map(|(b, v, w)| Op::SetVelocity(b, v, w)),
        1 => (pick(), place(), real()).prop_map(|(b, p, a)| Op::SetTransform(b, p, a)),
        1 => (pick(), real(), real()).prop_map(|(b, m, i)| Op::SetMass(b, m, i)),
        1 => (pick(), 0u8..3).prop_map(|(b, t)| Op::SetBodyType(b, t)),
        1 => (pick(), vec2()).prop_map(|(b, f)| Op::Force(b, f)),
        1 => (pick(), vec2(), place()).prop_map(|(b, i, p)| Op::Impulse(b, i, p)),
        1 => (pick(), real()).prop_map(|(b, t)| Op::Torque(b, t)),
        1 => (pick(), real()).prop_map(|(b, g)| Op::GravityScale(b, g)),
        1 => (pick(), real()).prop_map(|(b, c)| Op::LinearDamping(b, c)),
        1 => (pick(), real()).prop_map(|(b, c)| Op::AngularDamping(b, c)),
        1 => (pick(), any::<bool>()).prop_map(|(b, f)| Op::FixedRotation(b, f)),
        1 => (pick(), 0u8..8).prop_map(|(b, l)| Op::MotionLocks(b, l)),
        1 => (pick(), any::<bool>()).prop_map(|(b, e)| Op::BodyEnabled(b, e)),
        1 => (pick(), geometry()).prop_map(|(s, g)| Op::SetGeometry(s, g)),
        1 => (pick(), prop_oneof![3 => Just(1.5 as Real), 1 => real()]).prop_map(|(s, f)| Op::ScaleShape(s, f)),
        1 => (pick(), 0u8..3, real()).prop_map(|(s, which, v)| Op::SurfaceMaterial(s, which, v)),
        1 => (place(), size(), size(), real())
            .prop_map(|(position, radius, falloff, impulse)| Op::Explode { position, radius, falloff, impulse }),
        1 => (pick(), place(), real()).prop_map(|(s, p, d)| Op::Query(s, p, d)),
        2 => (pick(), 0u8..6, any::<bool>(), real()).prop_map(|(s, w, on, v)| Op::EventSwitch(s, w, on, v)),
        1 => (pick(), 0u8..2, real()).prop_map(|(s, w, v)| Op::ShapeMixing(s, w, v)),
        1 => (pick(), geometry(), vec2()).prop_map(|(s, g, d)| Op::SetKindGeometry(s, g, d * 0.1)),
        2 => (place(), prop_oneof![3 => Just(0.25 as Real), 1 => size()], vec2(), prop_oneof![3 => Just(0.01 as Real), 1 => real()],
              prop_oneof![3 => Just(1.0 as Real / 60.0), 1 => real()], any::<bool>())
            .prop_map(|(at, radius, translation, margin, dt, one_way)| Op::Mover { at, radius, translation, margin, dt, one_way }),
        1 => (0u8..4, prop_oneof![2 => Just(0.3 as Real), 1 => real()]).prop_map(|(k, v)| Op::Hooks(k, v)),
        1 => (prop_oneof![3 => Just(30.0 as Real), 1 => real()], prop_oneof![3 => Just(10.0 as Real), 1 => real()], prop_oneof![3 => Just(4u32), 1 => 0u32..12])
            .prop_map(|(hertz, damping, substeps)| Op::Settings { hertz, damping, substeps }),
        1 => prop_oneof![3 => Just(Vec2::new(0.0, -10.0)), 1 => vec2()].prop_map(Op::Gravity),
        1 => (any::<bool>(), prop_oneof![2 => Just(0.05 as Real), 1 => real()], prop_oneof![2 => Just(0.5 as Real), 1 => real()])
            .prop_map(|(enabled, threshold, time)| Op::Sleep { enabled, threshold, time }),
        8 => prop_oneof![6 => Just(1.0 as Real / 60.0), 1 => Just(1.0 as Real / 240.0), 1 => Just(0.1 as Real), 1 => real()].prop_map(Op::Step),
        2 => Just(Op::StepMany),
        1 => Just(Op::Snapshot),
        1 => Just(Op::Restore),
    ]
}

/// Everything the test issued: live and stale handles alike, and a few
/// handles of another world.
struct Issued {
    bodies: Vec<BodyHandle>,
    shapes: Vec<ShapeHandle>,
    joints: Vec<JointHandle>,
    pairs: Vec<PortalPairHandle>,
    chains: Vec<ChainHandle>,
    foreign_chain: ChainHandle,
    foreign_body: BodyHandle,
    foreign_shape: ShapeHandle,
    foreign_joint: JointHandle,
}

fn pick<T: Copy>(list: &[T], k: usize, foreign: T) -> T {
    if list.is_empty() || k % 16 == 15 {
        foreign
    } else {
        list[k % list.len()]
    }
}

fn fingerprint(w: &World) -> (u64, usize, usize, usize, usize, usize, usize, usize) {
    (
        w.state_hash(),
        w.chain_count(),
        w.body_count(),
        w.shape_count(),
        w.joint_count(),
        w.contact_count(),
        w.sleeping_body_count(),
        w.portal_pair_count(),
    )
}

fn body_type(t: u8) -> BodyType {
    match t % 3 {
        0 => BodyType::Static,
        1 => BodyType::Kinematic,
        _ => BodyType::Dynamic,
    }
}

fn shape_of(g: &Geometry) -> Option<Shape> {
    Some(match g {
        Geometry::Circle(c, r) => Shape::Circle(Circle {
            center: *c,
            radius: *r,
        }),
        Geometry::Box(a, b) => Shape::Polygon(Polygon::try_make_box(*a, *b).ok()?),
        Geometry::Capsule(a, b, r) => Shape::Capsule(Capsule {
            center1: *a,
            center2: *b,
            radius: *r,
        }),
        Geometry::Hull(p, r) => Shape::Polygon(Polygon::from_hull(p, *r).ok()?),
        Geometry::Segment(a, b) => Shape::Segment(Segment {
            point1: *a,
            point2: *b,
        }),
        Geometry::InwardBox(h) => {
            let mut p = Polygon::try_make_box(*h, *h).ok()?;
            for n in p.normals.iter_mut() {
                *n = -*n;
            }
            Shape::Polygon(p)
        }
    })
}

fn apply(
    w: &mut World,
    issued: &mut Issued,
    saved: &mut Option<janus2d::world::Snapshot>,
    op: &Op,
) -> Result<(), WorldError> {
    let fb = issued.foreign_body;
    let body = |k: usize, i: &Issued| pick(&i.bodies, k, fb);
    match op {
        Op::CreateBody {
            ty,
            position,
            velocity,
            w: aw,
            mass,
            awake,
            bullet,
        } => {
            let def = BodyDef {
                body_type: body_type(*ty),
                position: *position,
                linear_velocity: *velocity,
                angular_velocity: *aw,
                mass: mass.map(|(m, i)| BodyMass::new(m, i)),
                awake: *awake,
                bullet: *bullet,
                ..BodyDef::default()
            };
            let h = w.create_body(&def)?;
            issued.bodies.push(h);
            Ok(())
        }
        Op::DestroyBody(k) => w.destroy_body(body(*k, issued)),
        Op::CreateShape {
            body: k,
            geometry,
            density,
            friction,
            sensor,
        } => {
            let def = ShapeDef {
                density: *density,
                friction: *friction,
                is_sensor: *sensor,
                ..ShapeDef::default()
            };
            let Some(shape) = shape_of(geometry) else {
                return Err(WorldError::OutOfRange("constructor refused"));
            };
            let h = w.create_shape(body(*k, issued), &def, shape)?;
            issued.shapes.push(h);
            Ok(())
        }
        Op::DestroyShape(k) => w.destroy_shape(pick(&issued.shapes, *k, issued.foreign_shape)),
        Op::CreateChain {
            body: k,
            points,
            is_loop,
            materials,
            friction,
        } => {
            let material = SurfaceMaterial::default().with_friction(*friction);
            let def = ChainDef::new(points.clone())
                .with_loop(*is_loop)
                .with_segment_materials(vec![material; *materials]);
            let h = w.create_chain(body(*k, issued), &def)?;
            issued.chains.push(h);
            issued.shapes.extend_from_slice(w.chain_segments(h)?);
            Ok(())
        }
        Op::DestroyChain(k) => w.destroy_chain(pick(&issued.chains, *k, issued.foreign_chain)),
        Op::CreateJoint {
            kind,
            a,
            b,
            anchor,
            limits,
            collide,
        } => {
            let kinds = janus2d_constraints::JointKind::ALL;
            let def = janus2d_testbed::support::joint_def_of_kind(
                kinds[*kind % kinds.len()],
                body(*a, issued),
                body(*b, issued),
                *anchor,
                *limits,
                *collide,
            );
            let h = w.create_joint(&def)?;
            issued.joints.push(h);
            Ok(())
        }
        Op::DestroyJoint(k) => w.destroy_joint(pick(&issued.joints, *k, issued.foreign_joint)),
        Op::CreatePortalPair {
            a,
            b,
            anchor,
            half_width,
            eta,
            coincident,
        } => {
            let pa = PortalDef {
                body: body(*a, issued),
                anchor: *anchor,
                direction: Vec2::new(0.0, 1.0),
                half_width: *half_width,
            };
            let pb = if *coincident {
                pa
            } else {
                PortalDef {
                    body: body(*b, issued),
                    anchor: -*anchor,
                    direction: Vec2::new(1.0, 0.0),
                    half_width: 1.0,
                }
            };
            let mut def = PortalPairDef::new(pa, pb);
            def.eta = *eta;
            let h = w.create_portal_pair(&def)?;
            issued.pairs.push(h);
            Ok(())
        }
        Op::DestroyPortalPair(k) => match issued.pairs.get(*k % issued.pairs.len().max(1)) {
            Some(p) => w.destroy_portal_pair(*p),
            None => Err(WorldError::StalePortal),
        },
        Op::SetVelocity(k, v, aw) => {
            let b = body(*k, issued);
            if k % 2 == 0 {
                w.set_linear_velocity(b, *v)
            } else {
                w.set_angular_velocity(b, *aw)
            }
        }
        Op::SetTransform(k, p, a) => w.set_transform(body(*k, issued), *p, *a),
        Op::SetMass(k, m, i) => w.set_mass(body(*k, issued), BodyMass::new(*m, *i)),
        Op::SetBodyType(k, t) => w.set_body_type(body(*k, issued), body_type(*t)),
        Op::Force(k, f) => w.apply_force_to_center(body(*k, issued), *f),
        Op::Impulse(k, i, p) => w.apply_linear_impulse(body(*k, issued), *i, *p),
        Op::Torque(k, t) => w.apply_torque(body(*k, issued), *t),
        Op::GravityScale(k, g) => w.set_gravity_scale(body(*k, issued), *g),
        Op::LinearDamping(k, c) => w.set_linear_damping(body(*k, issued), *c),
        Op::AngularDamping(k, c) => w.set_angular_damping(body(*k, issued), *c),
        Op::FixedRotation(k, f) => w.set_fixed_rotation(body(*k, issued), *f),
        Op::MotionLocks(k, l) => w.set_motion_locks(
            body(*k, issued),
            MotionLocks {
                linear_x: l & 1 != 0,
                linear_y: l & 2 != 0,
                angular: l & 4 != 0,
            },
        ),
        Op::BodyEnabled(k, e) => w.set_body_enabled(body(*k, issued), *e),
        Op::SetGeometry(k, g) => {
            let Some(shape) = shape_of(g) else {
                return Err(WorldError::OutOfRange("constructor refused"));
            };
            w.set_shape_geometry(pick(&issued.shapes, *k, issued.foreign_shape), shape)
        }
        Op::ScaleShape(k, f) => w.scale_shape(pick(&issued.shapes, *k, issued.foreign_shape), *f),
        Op::SurfaceMaterial(k, which, v) => {
            let s = pick(&issued.shapes, *k, issued.foreign_shape);
            match which {
                0 => w.set_shape_rolling_resistance(s, *v),
                1 => w.set_shape_tangent_speed(s, *v),
                _ => w.set_shape_user_material_id(
                    s,
                    u64::from(v.is_sign_negative()) << 40 | (v.abs() as u64),
                ),
            }
        }
        Op::Explode {
            position,
            radius,
            falloff,
            impulse,
        } => w
            .explode(&ExplosionDef::new(*position, *radius, *impulse).with_falloff(*falloff))
            .map(|_| ()),
        Op::EventSwitch(k, which, on, v) => {
            let s = pick(&issued.shapes, *k, issued.foreign_shape);
            match which {
                0 => w.set_shape_contact_events(s, *on),
                1 => w.set_shape_sensor_events(s, *on),
                2 => w.set_shape_hit_events(s, *on),
                3 => w.set_shape_force_event_threshold(s, *v),
                4 => w.set_body_move_events(body(*k, issued), *on),
                _ => {
                    w.set_move_events(*on);
                    Ok(())
                }
            }
        }
        Op::ShapeMixing(k, which, v) => {
            let s = pick(&issued.shapes, *k, issued.foreign_shape);
            if *which == 0 {
                w.set_shape_friction(s, *v)
            } else {
                w.set_shape_restitution(s, *v)
            }
        }
        Op::SetKindGeometry(k, g, d) => {
            let s = pick(&issued.shapes, *k, issued.foreign_shape);
            if let Ok(data) = w.shape(s)
                && let Shape::ChainSegment(mut c) = data.geometry
            {
                for p in [
                    &mut c.ghost1,
                    &mut c.segment.point1,
                    &mut c.segment.point2,
                    &mut c.ghost2,
                ] {
                    *p += *d;
                }
                return w.set_chain_segment(s, c);
            }
            match shape_of(g) {
                Some(Shape::Circle(c)) => w.set_circle(s, c),
                Some(Shape::Capsule(c)) => w.set_capsule(s, c),
                Some(Shape::Polygon(p)) => w.set_polygon(s, p),
                Some(Shape::Segment(x)) => w.set_segment(s, x),
                _ => Err(WorldError::OutOfRange("constructor refused")),
            }
        }
        Op::Mover {
            at,
            radius,
            translation,
            margin,
            dt,
            one_way,
        } => {
            let mover = Capsule {
                center1: *at - Vec2::new(0.0, 0.25),
                center2: *at + Vec2::new(0.0, 0.25),
                radius: *radius,
            };
            let up = |h: &janus2d::world::RayHit| h.normal.y > 0.5;
            let odd = |s: ShapeHandle| s.index % 2 == 1;
            let f = if *one_way {
                QueryFilter::default().with_predicate(&odd)
            } else {
                QueryFilter::default()
            };
            let cast = if *one_way {
                w.cast_mover_with(&mover, *translation, &f, up)
            } else {
                w.cast_mover(&mover, *translation, &f)
            };
            if let Ok(c) = &cast {
                prop_assert_real(c.fraction)?;
            }
            let mut planes = Vec::new();
            let collided = w.collide_mover(&mover, *margin, &f, |p| {
                planes.push(janus2d::world::CollisionPlane::new(p.normal, p.separation));
                planes.len() < 8
            });
            if collided.is_ok() {
                let solved = janus2d::world::solve_planes(*translation, &mut planes);
                let clipped = janus2d::world::clip_vector(*translation, &planes);
                let _ = (solved, clipped);
            }
            let mut cc = janus2d::world::CharacterController::new()
                .with_snap_to_ground(Some(0.1))
                .with_autostep(Some(janus2d::world::Autostep::default()));
            let moved = cc.move_and_slide(w, &mover, *at, *translation, *dt, &f);
            if let Ok(m) = &moved {
                prop_assert_real(m.position.x + m.position.y)?;
            }
            cast.and(collided).and(moved).map(|_| ())
        }
        Op::Hooks(which, v) => {
            let v = *v;
            match which {
                0 => w.set_pre_solve(Some(Box::new(move |c| {
                    c.friction = v;
                    c.restitution = v;
                    c.tangent_speed = v;
                    c.rolling_resistance = v;
                    (c.shape_a.index + c.shape_b.index) % 3 != 0
                }))),
                1 => w.set_pair_filter(Some(Box::new(|a, b| (a.index ^ b.index) % 4 != 1))),
                2 => {
                    w.set_friction_callback(Some(Box::new(move |a, _, b, _| v * (a + b))));
                    w.set_restitution_callback(Some(Box::new(
                        move |_, ma, _, mb| {
                            if ma == mb { v } else { -v }
                        },
                    )));
                }
                _ => {
                    w.set_pre_solve(None);
                    w.set_pair_filter(None);
                    w.set_friction_callback(None);
                    w.set_restitution_callback(None);
                }
            }
            Ok(())
        }
        Op::Query(k, p, d) => {
            let shape = pick(&issued.shapes, *k, issued.foreign_shape);
            let f = QueryFilter::default();
            let _ = w.project_point(*p, *d, &f);
            let _ = w.shape_project_point(shape, *p);
            let _ = w.shape_test_point(shape, *p);
            let _ = w.shape_ray_cast(shape, *p, Vec2::new(*d, 1.0), &f.through_portals());
            let _ = w.sensor_overlaps(shape);
            let _ = w.velocity_at_point(body(*k, issued), *p);
            w.sensor_overlaps(shape).map(|_| ())
        }
        Op::Settings {
            hertz,
            damping,
            substeps,
        } => w.set_settings(SolverSettings {
            contact_hertz: *hertz,
            contact_damping_ratio: *damping,
            substeps: *substeps,
            ..SolverSettings::default()
        }),
        Op::Gravity(g) => w.set_gravity(*g),
        Op::Sleep {
            enabled,
            threshold,
            time,
        } => w.set_sleep_settings(SleepSettings {
            enabled: *enabled,
            linear_threshold: *threshold,
            time_to_sleep: *time,
        }),
        Op::Step(dt) => w.step(*dt),
        Op::StepMany => {
            for _ in 0..30 {
                w.step(1.0 / 60.0)?;
            }
            Ok(())
        }
        Op::Snapshot => {
            *saved = Some(w.snapshot());
            Ok(())
        }
        Op::Restore => {
            if let Some(s) = saved {
                w.restore(s);
            }
            Ok(())
        }
    }
}

/// A mover or controller result that is not finite is an error of the
/// engine (its inputs were accepted).
fn prop_assert_real(x: Real) -> Result<(), WorldError> {
    if x.is_finite() {
        Ok(())
    } else {
        panic!("an accepted mover query gave {x}")
    }
}

fn cases() -> u32 {
    std::env::var("JANUS_STATE_MACHINE_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(48)
}

/// Operations run and accepted, over every case (printed at the end).
static RAN: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static ACCEPTED: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static STEPS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static CHAINS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
/// Accepted event switches, friction/restitution setters, per-kind
/// geometry setters and mover/controller queries (hooks are always
/// accepted).
static SWITCHES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static MIXING: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static KIND_GEOMETRY: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
static MOVERS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// The world a case starts from: a ground box, the portal drop scene, a
/// small pyramid, or the issue-32 world (with their bodies among the
/// issued handles).
fn start(scene: u8) -> World {
    let def = janus2d_testbed::scenes::shared_settings();
    match scene % 4 {
        0 => {
            let mut world = World::new(WorldDef::default()).unwrap();
            let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
            world
                .create_shape(ground, &ShapeDef::default(), Polygon::make_box(8.0, 0.5))
                .unwrap();
            world
        }
        1 => janus2d_testbed::scenes::portal_drop(&def).0.world,
        2 => janus2d_testbed::scenes::large_pyramid(&def, 4).world,
        _ => janus2d_testbed::support::issue32_world(0),
    }
}

fn run(scene: u8, ops: &[Op]) -> Result<(), TestCaseError> {
    use std::sync::atomic::Ordering::Relaxed;
    let mut other = World::new(WorldDef::default()).unwrap();
    let fb = other.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let fb2 = other.create_body(&BodyDef::dynamic(Vec2::ONE)).unwrap();
    let fs = other
        .create_shape(
            fb,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .unwrap();
    let fj = other
        .create_revolute_joint(&RevoluteJointDef::new(fb, fb2, Vec2::ZERO, Vec2::ZERO))
        .unwrap();
    let ground = other.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let fc = other
        .create_chain(
            ground,
            &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)]),
        )
        .unwrap();
    let mut issued = Issued {
        chains: Vec::new(),
        foreign_chain: fc,
        bodies: Vec::new(),
        shapes: Vec::new(),
        joints: Vec::new(),
        pairs: Vec::new(),
        foreign_body: fb,
        foreign_shape: fs,
        foreign_joint: fj,
    };
    let mut world = start(scene);
    issued.bodies.extend(world.body_handles());
    for b in issued.bodies.clone() {
        issued.shapes.extend(world.body_shapes(b).unwrap());
    }
    issued.joints.extend(world.joint_handles().iter().copied());
    issued.chains.extend(world.chain_handles());
    issued.pairs.extend(world.portal_pairs().map(|(h, _)| h));
    let mut saved = None;
    for (i, op) in ops.iter().enumerate() {
        let before = fingerprint(&world);
        let result = apply(&mut world, &mut issued, &mut saved, op);
        RAN.fetch_add(1, Relaxed);
        if result.is_ok() {
            ACCEPTED.fetch_add(1, Relaxed);
            if matches!(op, Op::Step(_)) {
                STEPS.fetch_add(1, Relaxed);
            }
            let counter = match op {
                Op::CreateChain { .. } => Some(&CHAINS),
                Op::EventSwitch(..) => Some(&SWITCHES),
                Op::ShapeMixing(..) => Some(&MIXING),
                Op::SetKindGeometry(..) => Some(&KIND_GEOMETRY),
                Op::Mover { .. } => Some(&MOVERS),
                _ => None,
            };
            if let Some(c) = counter {
                c.fetch_add(1, Relaxed);
            }
        }
        if let Err(e) = &result {
            prop_assert_eq!(
                fingerprint(&world),
                before,
                "op {} {:?} failed with {:?} and changed the world",
                i,
                op,
                e
            );
        }
        if let Err(e) = world.validate() {
            return Err(TestCaseError::fail(format!(
                "after op {i} {op:?} ({result:?}): {e}"
            )));
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        rng_seed: janus2d_testbed::support::named_seed("api_state_machine", ProptestConfig::default().rng_seed),
        ..ProptestConfig::default()
    })]

    /// Random API sequences never panic, never change the world on an
    /// error, and always leave a valid world.
    #[test]
    fn api_sequences_keep_the_world_valid(
        scene in 0u8..4,
        ops in proptest::collection::vec(op(), 1..48),
    ) {
        run(scene, &ops)?;
    }
}

/// Runs after the property (alphabetical order is not guaranteed, so it
/// only reports): the operation counts of this process.
#[test]
fn z_report_counts() {
    use std::sync::atomic::Ordering::Relaxed;
    eprintln!(
        "state machine: {} operations, {} accepted, {} steps, {} chains created, \
         {} event switches, {} friction/restitution, {} per-kind geometry, {} mover queries accepted",
        RAN.load(Relaxed),
        ACCEPTED.load(Relaxed),
        STEPS.load(Relaxed),
        CHAINS.load(Relaxed),
        SWITCHES.load(Relaxed),
        MIXING.load(Relaxed),
        KIND_GEOMETRY.load(Relaxed),
        MOVERS.load(Relaxed)
    );
}
