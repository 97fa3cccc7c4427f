//! The API as a byte-coded sequence of calls (bodies, shapes, joints,
//! portal pairs, chains, velocities, transforms, masses, types, forces, settings,
//! steps, snapshot and restore; issue 32's motion locks, fixed rotation,
//! gravity scale, damping, enable/disable, geometry setters and scaling,
//! surface materials, event switches, explosions, point/shape/sensor
//! queries with a predicate, mover casts and collisions, the character
//! controller, callbacks), valid and invalid values mixed. After each
//! call: no panic, an `Err` left the world unchanged, `World::validate`
//! passes.
#![no_main]

use janus2d::base::geometry::{Capsule, Circle, Polygon, Segment, Shape};
use janus2d::prelude::*;
use janus2d::world::{
    CharacterController, CollisionPlane, ExplosionDef, PortalDef, PortalPairDef, PortalPairHandle,
    SleepSettings, Snapshot, clip_vector, solve_planes,
};
use libfuzzer_sys::fuzz_target;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let (b, rest) = self.0.split_first().map_or((0, &[][..]), |(b, r)| (*b, r));
        self.0 = rest;
        b
    }
    fn real(&mut self) -> Real {
        match self.byte() {
            0 => Real::NAN,
            1 => Real::INFINITY,
            2 => Real::NEG_INFINITY,
            3 => 1e30,
            4 => -1e30,
            5 => -0.0,
            6 => 0.0,
            7 => 1e-40,
            8 => 1e9,
            9 => -1.0,
            b => (Real::from(b) - 132.0) / 16.0,
        }
    }
    fn vec(&mut self) -> Vec2 {
        Vec2::new(self.real(), self.real())
    }
}

struct Issued {
    bodies: Vec<BodyHandle>,
    shapes: Vec<ShapeHandle>,
    joints: Vec<JointHandle>,
    pairs: Vec<PortalPairHandle>,
    chains: Vec<ChainHandle>,
    foreign: BodyHandle,
}

fn pick<T: Copy>(list: &[T], k: u8, foreign: T) -> T {
    if list.is_empty() || k == 255 {
        foreign
    } else {
        list[k as usize % list.len()]
    }
}

fn body_type(t: u8) -> BodyType {
    [BodyType::Static, BodyType::Kinematic, BodyType::Dynamic][(t % 3) as usize]
}

fn shape(b: &mut Bytes) -> Option<Shape> {
    Some(match b.byte() % 6 {
        0 => Shape::Circle(Circle {
            center: b.vec() * 0.1,
            radius: b.real(),
        }),
        1 => Shape::Polygon(Polygon::try_make_box(b.real(), b.real()).ok()?),
        2 => Shape::Capsule(Capsule {
            center1: b.vec() * 0.2,
            center2: b.vec() * 0.2,
            radius: b.real(),
        }),
        3 => {
            let n = (b.byte() % 9) as usize;
            let pts: Vec<Vec2> = (0..n).map(|_| b.vec() * 0.3).collect();
            Shape::Polygon(Polygon::from_hull(&pts, b.real().abs() * 0.1).ok()?)
        }
        4 => Shape::Segment(Segment {
            point1: b.vec(),
            point2: b.vec(),
        }),
        _ => {
            let mut p = Polygon::make_box(0.5, 0.5);
            let k = (b.byte() % 4) as usize;
            p.normals[k] = b.vec();
            Shape::Polygon(p)
        }
    })
}

fn fingerprint(w: &World) -> [u64; 8] {
    [
        w.chain_count() as u64,
        w.state_hash(),
        w.body_count() as u64,
        w.shape_count() as u64,
        w.joint_count() as u64,
        w.contact_count() as u64,
        w.sleeping_body_count() as u64,
        w.portal_pair_count() as u64,
    ]
}

fn call(
    w: &mut World,
    i: &mut Issued,
    saved: &mut Option<Snapshot>,
    b: &mut Bytes,
) -> Result<(), WorldError> {
    let f = i.foreign;
    match b.byte() % 31 {
        0 | 1 => {
            let ty = body_type(b.byte());
            let def = BodyDef {
                body_type: ty,
                position: b.vec(),
                linear_velocity: if b.byte().is_multiple_of(2) {
                    Vec2::ZERO
                } else {
                    b.vec()
                },
                angular_velocity: b.real(),
                mass: if b.byte().is_multiple_of(4) {
                    Some(BodyMass::new(b.real(), b.real()))
                } else {
                    None
                },
                awake: !b.byte().is_multiple_of(4),
                bullet: b.byte().is_multiple_of(4),
                ..BodyDef::default()
            };
            i.bodies.push(w.create_body(&def)?);
            Ok(())
        }
        2 => w.destroy_body(pick(&i.bodies, b.byte(), f)),
        3 | 4 => {
            let body = pick(&i.bodies, b.byte(), f);
            let def = ShapeDef {
                density: b.real(),
                friction: b.real(),
                ..ShapeDef::default()
            };
            let s = shape(b).ok_or(WorldError::OutOfRange("constructor"))?;
            i.shapes.push(w.create_shape(body, &def, s)?);
            Ok(())
        }
        5 => match i.shapes.get(b.byte() as usize % i.shapes.len().max(1)) {
            Some(s) => w.destroy_shape(*s),
            None => Err(WorldError::StaleShape),
        },
        6 => {
            let (ba, bb) = (pick(&i.bodies, b.byte(), f), pick(&i.bodies, b.byte(), f));
            let anchor = b.vec();
            // Every kind, picked by a byte; limits where the kind has them.
            let mut def: JointDef = match b.byte() % 8 {
                0 => RevoluteJointDef::new(ba, bb, anchor, -anchor).into(),
                1 => PrismaticJointDef::new(ba, bb, anchor, -anchor, b.vec()).into(),
                2 => WeldJointDef::new(ba, bb, anchor, -anchor).into(),
                3 => DistanceJointDef::new(ba, bb, anchor, -anchor, b.real()).into(),
                4 => WheelJointDef::new(ba, bb, anchor, -anchor, b.vec()).into(),
                5 => MotorJointDef::new(ba, bb)
                    .with_offset(anchor, b.real())
                    .into(),
                6 => MouseJointDef::new(ba, bb, anchor, b.real()).into(),
                _ => FilterJointDef::new(ba, bb).into(),
            };
            if b.byte().is_multiple_of(2)
                && let Some(l) = def.limits_mut()
            {
                *l.enable = true;
                *l.lower = b.real();
                *l.upper = b.real();
            }
            i.joints.push(w.create_joint(&def)?);
            Ok(())
        }
        7 => match i.joints.get(b.byte() as usize % i.joints.len().max(1)) {
            Some(j) => w.destroy_joint(*j),
            None => Err(WorldError::StaleJoint),
        },
        8 => {
            let pa = PortalDef {
                body: pick(&i.bodies, b.byte(), f),
                anchor: b.vec(),
                direction: b.vec(),
                half_width: b.real(),
            };
            let pb = if b.byte().is_multiple_of(4) {
                pa
            } else {
                PortalDef {
                    body: pick(&i.bodies, b.byte(), f),
                    anchor: b.vec(),
                    direction: b.vec(),
                    half_width: b.real(),
                }
            };
            let mut def = PortalPairDef::new(pa, pb);
            if b.byte().is_multiple_of(2) {
                def.eta = Some(b.real());
            }
            i.pairs.push(w.create_portal_pair(&def)?);
            Ok(())
        }
        9 => match i.pairs.get(b.byte() as usize % i.pairs.len().max(1)) {
            Some(p) => w.destroy_portal_pair(*p),
            None => Err(WorldError::StalePortal),
        },
        10 => w.set_linear_velocity(pick(&i.bodies, b.byte(), f), b.vec()),
        11 => w.set_angular_velocity(pick(&i.bodies, b.byte(), f), b.real()),
        12 => w.set_transform(pick(&i.bodies, b.byte(), f), b.vec(), b.real()),
        13 => w.set_mass(
            pick(&i.bodies, b.byte(), f),
            BodyMass::new(b.real(), b.real()),
        ),
        14 => w.set_body_type(pick(&i.bodies, b.byte(), f), body_type(b.byte())),
        15 => match b.byte() % 3 {
            0 => w.apply_force_to_center(pick(&i.bodies, b.byte(), f), b.vec()),
            1 => w.apply_linear_impulse(pick(&i.bodies, b.byte(), f), b.vec(), b.vec()),
            _ => w.apply_torque(pick(&i.bodies, b.byte(), f), b.real()),
        },
        16 => match b.byte() % 3 {
            0 => w.set_settings(SolverSettings {
                contact_hertz: b.real(),
                contact_damping_ratio: b.real(),
                joint_hertz: b.real(),
                substeps: u32::from(b.byte() % 10),
                ..SolverSettings::default()
            }),
            1 => w.set_gravity(b.vec()),
            _ => w.set_sleep_settings(SleepSettings {
                enabled: b.byte().is_multiple_of(2),
                linear_threshold: b.real(),
                time_to_sleep: b.real(),
            }),
        },
        17 => {
            *saved = Some(w.snapshot());
            Ok(())
        }
        20 => {
            let body = pick(&i.bodies, b.byte(), f);
            let n = (b.byte() % 7) as usize;
            let points: Vec<Vec2> = (0..n).map(|_| b.vec()).collect();
            let per_segment = b.byte() % 3;
            let material = SurfaceMaterial::default().with_friction(b.real());
            let count = match per_segment {
                0 => 1,
                1 => n.saturating_sub(1),
                _ => n,
            };
            let def = ChainDef::new(points)
                .with_loop(b.byte().is_multiple_of(2))
                .with_segment_materials(vec![material; count]);
            let chain = w.create_chain(body, &def)?;
            i.chains.push(chain);
            i.shapes.extend_from_slice(w.chain_segments(chain)?);
            Ok(())
        }
        21 => match i.chains.get(b.byte() as usize % i.chains.len().max(1)) {
            Some(c) => w.destroy_chain(*c),
            None => Err(WorldError::StaleChain),
        },
        18 => {
            if let Some(s) = saved {
                w.restore(s);
            }
            Ok(())
        }
        22 => {
            let body = pick(&i.bodies, b.byte(), f);
            match b.byte() % 5 {
                0 => {
                    let l = b.byte();
                    w.set_motion_locks(
                        body,
                        MotionLocks {
                            linear_x: l & 1 != 0,
                            linear_y: l & 2 != 0,
                            angular: l & 4 != 0,
                        },
                    )
                }
                1 => w.set_fixed_rotation(body, b.byte().is_multiple_of(2)),
                2 => w.set_gravity_scale(body, b.real()),
                3 => w.set_linear_damping(body, b.real()),
                _ => w.set_angular_damping(body, b.real()),
            }
        }
        23 => w.set_body_enabled(pick(&i.bodies, b.byte(), f), b.byte().is_multiple_of(2)),
        24 => {
            let s = i
                .shapes
                .get(b.byte() as usize % i.shapes.len().max(1))
                .copied();
            let Some(s) = s else {
                return Err(WorldError::StaleShape);
            };
            if b.byte().is_multiple_of(2) {
                w.scale_shape(s, b.real())
            } else {
                match shape(b) {
                    Some(Shape::Circle(c)) => w.set_circle(s, c),
                    Some(Shape::Capsule(c)) => w.set_capsule(s, c),
                    Some(Shape::Polygon(p)) => w.set_polygon(s, p),
                    Some(Shape::Segment(x)) => w.set_segment(s, x),
                    Some(other) => w.set_shape_geometry(s, other),
                    None => Err(WorldError::OutOfRange("constructor refused")),
                }
            }
        }
        25 | 26 => {
            let s = i
                .shapes
                .get(b.byte() as usize % i.shapes.len().max(1))
                .copied();
            let Some(s) = s else {
                return Err(WorldError::StaleShape);
            };
            match b.byte() % 10 {
                0 => w.set_shape_rolling_resistance(s, b.real()),
                1 => w.set_shape_tangent_speed(s, b.real()),
                2 => w.set_shape_user_material_id(s, u64::from(b.byte())),
                3 => w.set_shape_friction(s, b.real()),
                4 => w.set_shape_restitution(s, b.real()),
                5 => w.set_shape_contact_events(s, b.byte().is_multiple_of(2)),
                6 => w.set_shape_sensor_events(s, b.byte().is_multiple_of(2)),
                7 => w.set_shape_hit_events(s, b.byte().is_multiple_of(2)),
                8 => w.set_shape_force_event_threshold(s, b.real()),
                _ => {
                    w.set_body_move_events(pick(&i.bodies, b.byte(), f), b.byte().is_multiple_of(2))
                }
            }
        }
        27 => w
            .explode(&ExplosionDef::new(b.vec(), b.real(), b.real()).with_falloff(b.real()))
            .map(|_| ()),
        28 => {
            let s = i
                .shapes
                .get(b.byte() as usize % i.shapes.len().max(1))
                .copied();
            let p = b.vec();
            let odd = |h: ShapeHandle| h.index % 2 == 1;
            let filter = QueryFilter::default().with_predicate(&odd);
            let _ = w.project_point(p, b.real(), &filter);
            let _ = w.velocity_at_point(pick(&i.bodies, b.byte(), f), p);
            if let Some(s) = s {
                let _ = w.shape_project_point(s, p);
                let _ = w.shape_test_point(s, p);
                let _ = w.shape_ray_cast(s, p, b.vec(), &filter);
                let _ = w.sensor_overlaps(s);
            }
            Ok(())
        }
        29 => {
            let at = b.vec();
            let mover = Capsule {
                center1: at - Vec2::new(0.0, 0.25),
                center2: at + Vec2::new(0.0, 0.25),
                radius: b.real(),
            };
            let translation = b.vec();
            let filter = QueryFilter::default();
            if let Ok(c) = w.cast_mover(&mover, translation, &filter) {
                assert!(c.fraction.is_finite(), "mover fraction {}", c.fraction);
            }
            let mut planes = Vec::new();
            let _ = w.collide_mover(&mover, b.real(), &filter, |p| {
                planes.push(CollisionPlane::new(p.normal, p.separation));
                planes.len() < 8
            });
            let solved = solve_planes(translation, &mut planes);
            let clipped = clip_vector(translation, &planes);
            let _ = (solved, clipped);
            let mut cc = CharacterController::new().with_snap_to_ground(Some(0.1));
            if let Ok(m) = cc.move_and_slide(w, &mover, at, translation, b.real(), &filter) {
                assert!(m.position.is_finite(), "controller {m:?}");
            }
            Ok(())
        }
        30 => {
            let v = b.real();
            match b.byte() % 4 {
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
                    w.set_restitution_callback(Some(Box::new(move |_, _, _, _| v)));
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
        _ => {
            let dt = match b.byte() % 6 {
                0 => b.real(),
                1 => 1.0 / 240.0,
                2 => 0.1,
                _ => 1.0 / 60.0,
            };
            w.step(dt)
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut other = World::new(WorldDef::default()).unwrap();
    let foreign = other.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let mut w = World::new(WorldDef::default()).unwrap();
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    w.create_shape(ground, &ShapeDef::default(), Polygon::make_box(8.0, 0.5))
        .unwrap();
    let mut issued = Issued {
        bodies: vec![ground],
        shapes: Vec::new(),
        joints: Vec::new(),
        pairs: Vec::new(),
        chains: Vec::new(),
        foreign,
    };
    let mut saved = None;
    let mut b = Bytes(data);
    let mut n = 0;
    while !b.0.is_empty() && n < 256 {
        n += 1;
        let before = fingerprint(&w);
        let r = call(&mut w, &mut issued, &mut saved, &mut b);
        if let Err(e) = &r {
            assert_eq!(fingerprint(&w), before, "error {e:?} changed the world");
        }
        if let Err(e) = w.validate() {
            panic!("after call {n} ({r:?}): {e}");
        }
    }
});
