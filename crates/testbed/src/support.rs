//! Helpers shared by the constraint-level integration tests (the portal,
//! revolute and joint-tree property tests and the portal simulation tests):
//! body specifications built into a [`BodySet`], portal constraint cases,
//! random [`proptest`](mod@proptest) strategies for both, momentum sums in
//! f64, and a property runner ([`check`]) that reports the worst error as a
//! fraction of its bound.
//!
//! The tests take everything at once with `use janus2d_testbed::support::*;`.
//! Nothing here needs the `portals` feature: the portal constraint and the
//! portal map live in `janus2d-constraints`, which has no such feature.
//!
//! ```
//! use janus2d_core::body::BodySet;
//! use janus2d_core::math::Vec2;
//! use janus2d_testbed::support::{BodySpec, total_momentum};
//!
//! let mut set = BodySet::new();
//! let mut spec = BodySpec::dynamic(Vec2::new(1.0, 0.0), 2.0, 0.5);
//! spec.v = Vec2::new(0.0, 3.0);
//! let h = spec.create(&mut set);
//! let ([px, py, l], _scale) = total_momentum(&set, &[h]);
//! assert_eq!((px, py), (0.0, 6.0));
//! assert!((l - 6.0).abs() < 1e-6); // m (x vy − y vx)
//! ```

use janus2d_constraints::portal::{PortalConstraint, PortalConstraintDef};
use janus2d_constraints::portal_map::{
    BodyMotion, Portal, PortalBodyMotion, PortalFrame, PortalMap,
};
use janus2d_core::body::{BodyDef, BodyHandle, BodyMass, BodySet, BodyType};
use std::cell::Cell;

use janus2d_core::math::{EPSILON, Real, Rot, Transform, Vec2, cross, cross_sv};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestError, TestRunner};

/// Widens to f64 (identity under the `f64` feature).
pub fn d(x: Real) -> f64 {
    janus2d_core::math::to_f64(x)
}

/// A 2D vector widened to f64.
pub fn dv(v: Vec2) -> [f64; 2] {
    [d(v.x), d(v.y)]
}

/// Everything needed to create one body, about its centre of mass.
#[derive(Clone, Debug, PartialEq)]
pub struct BodySpec {
    /// Static, kinematic or dynamic.
    pub ty: BodyType,
    /// Centre of mass, m.
    pub center: Vec2,
    /// Angle, rad.
    pub angle: Real,
    /// Velocity of the centre of mass, m/s (ignored for static bodies).
    pub v: Vec2,
    /// Angular velocity, rad/s (ignored for static bodies).
    pub w: Real,
    /// Mass, kg (dynamic only).
    pub mass: Real,
    /// Rotational inertia about the centre, kg·m² (dynamic only).
    pub inertia: Real,
    /// Centre of mass in the body frame (dynamic only; other types rotate
    /// about their origin).
    pub local_center: Vec2,
    /// Locks rotation (dynamic only).
    pub fixed_rotation: bool,
}

impl BodySpec {
    /// A dynamic body with its centre at its origin.
    pub fn dynamic(center: Vec2, mass: Real, inertia: Real) -> BodySpec {
        BodySpec {
            ty: BodyType::Dynamic,
            center,
            angle: 0.0,
            v: Vec2::ZERO,
            w: 0.0,
            mass,
            inertia,
            local_center: Vec2::ZERO,
            fixed_rotation: false,
        }
    }

    /// A static body.
    pub fn fixed(center: Vec2, angle: Real) -> BodySpec {
        BodySpec {
            ty: BodyType::Static,
            angle,
            ..BodySpec::dynamic(center, 1.0, 1.0)
        }
    }

    /// A kinematic body.
    pub fn kinematic(center: Vec2, angle: Real, v: Vec2, w: Real) -> BodySpec {
        BodySpec {
            ty: BodyType::Kinematic,
            angle,
            v,
            w,
            ..BodySpec::dynamic(center, 1.0, 1.0)
        }
    }

    /// The local centre the engine will use (zero unless dynamic).
    pub fn effective_local_center(&self) -> Vec2 {
        if self.ty == BodyType::Dynamic {
            self.local_center
        } else {
            Vec2::ZERO
        }
    }

    /// The body transform (origin and rotation).
    pub fn transform(&self) -> Transform {
        let q = Rot::from_angle(self.angle);
        Transform {
            p: self.center - q.rotate(self.effective_local_center()),
            q,
        }
    }

    /// The velocity field the body carries (zero for a static body).
    pub fn motion(&self) -> PortalBodyMotion {
        if self.ty == BodyType::Static {
            PortalBodyMotion {
                center: self.center,
                ..PortalBodyMotion::AT_REST
            }
        } else {
            PortalBodyMotion {
                center: self.center,
                linear_velocity: self.v,
                angular_velocity: self.w,
            }
        }
    }

    /// Position, angle and velocities about the centre.
    pub fn body_motion(&self) -> BodyMotion {
        BodyMotion {
            center: self.center,
            angle: self.angle,
            linear_velocity: self.v,
            angular_velocity: self.w,
        }
    }

    /// The pose moved along a direction `(dir_v, dir_w)` for a time `t`
    /// (velocities unchanged).
    pub fn moved(&self, dir_v: Vec2, dir_w: Real, t: Real) -> BodySpec {
        BodySpec {
            center: self.center + t * dir_v,
            angle: self.angle + t * dir_w,
            ..self.clone()
        }
    }

    /// Creates the body.
    pub fn create(&self, set: &mut BodySet) -> BodyHandle {
        let tf = self.transform();
        let moving = self.ty != BodyType::Static;
        let (v, w) = if moving {
            (self.v, self.w)
        } else {
            (Vec2::ZERO, 0.0)
        };
        // BodyDef takes the origin's velocity; the engine adds ω × (c − o).
        let v_origin = v - cross_sv(w, self.center - tf.p);
        let def = BodyDef {
            body_type: self.ty,
            position: tf.p,
            angle: self.angle,
            linear_velocity: v_origin,
            angular_velocity: w,
            mass: (self.ty == BodyType::Dynamic).then_some(BodyMass {
                mass: self.mass,
                rotational_inertia: self.inertia,
                center: self.local_center,
            }),
            fixed_rotation: self.ty == BodyType::Dynamic && self.fixed_rotation,
            max_linear_speed: 1.0e9,
            max_rotation: 1.0e9,
            ..BodyDef::default()
        };
        set.create(&def).expect("valid body")
    }
}

/// A portal constraint case: four bodies (A and B may be one), two portals
/// and a scale.
#[derive(Clone, Debug, PartialEq)]
pub struct PortalCase {
    /// Body 1.
    pub body: BodySpec,
    /// Body 2, the clone.
    pub clone: BodySpec,
    /// Portal body A.
    pub a: BodySpec,
    /// Portal body B (ignored when `same_ab`).
    pub b: BodySpec,
    /// A and B are one body (`a`).
    pub same_ab: bool,
    /// Portal 1 on A.
    pub portal_a: Portal,
    /// Portal 2 on B.
    pub portal_b: Portal,
    /// Scale.
    pub eta: Real,
}

/// A case built into bodies.
pub struct Built {
    /// The bodies.
    pub set: BodySet,
    /// Handles: body, clone, A, B.
    pub handles: [BodyHandle; 4],
    /// The constraint.
    pub constraint: PortalConstraint,
}

impl PortalCase {
    /// The spec of portal body B (A's when `same_ab`).
    pub fn b_spec(&self) -> &BodySpec {
        if self.same_ab { &self.a } else { &self.b }
    }

    /// The world map at the current poses.
    pub fn map(&self) -> PortalMap {
        PortalMap::new(
            PortalFrame::new(&self.a.transform(), &self.portal_a),
            PortalFrame::new(&self.b_spec().transform(), &self.portal_b),
            self.eta,
        )
        .expect("valid eta")
    }

    /// Puts the clone at the exact clone state of the body.
    pub fn place_clone_exactly(&mut self) {
        let state = self.map().clone_state(
            &self.body.body_motion(),
            &self.a.motion(),
            &self.b_spec().motion(),
        );
        self.clone.center = state.center;
        self.clone.angle = state.angle;
        self.clone.v = state.linear_velocity;
        self.clone.w = state.angular_velocity;
    }

    /// Puts the clone's angle so that the angle row's error is `c2`.
    pub fn set_angle_error(&mut self, c2: Real) {
        let map = self.map();
        // c2 = (θ1 − α1) − (θ2 − α2) − π
        self.clone.angle =
            self.body.angle - map.frame1.angle + map.frame2.angle - janus2d_core::math::PI - c2;
    }

    /// Creates the bodies and the constraint.
    pub fn build(&self) -> Built {
        let mut set = BodySet::new();
        let a = self.a.create(&mut set);
        let b = if self.same_ab {
            a
        } else {
            self.b.create(&mut set)
        };
        let body = self.body.create(&mut set);
        let clone = self.clone.create(&mut set);
        let constraint = PortalConstraint::new(PortalConstraintDef {
            body,
            clone,
            portal_body_a: a,
            portal_body_b: b,
            portal_a: self.portal_a,
            portal_b: self.portal_b,
            eta: self.eta,
        })
        .expect("valid portal definition");
        Built {
            set,
            handles: [body, clone, a, b],
            constraint,
        }
    }

    /// The case with every body moved along its direction for time `t`
    /// (`dirs` in the order body, clone, A, B).
    pub fn moved(&self, dirs: &[(Vec2, Real); 4], t: Real) -> PortalCase {
        PortalCase {
            body: self.body.moved(dirs[0].0, dirs[0].1, t),
            clone: self.clone.moved(dirs[1].0, dirs[1].1, t),
            a: self.a.moved(dirs[2].0, dirs[2].1, t),
            b: self.b.moved(dirs[3].0, dirs[3].1, t),
            ..self.clone()
        }
    }
}

/// Total linear momentum and angular momentum about the origin of the
/// given bodies (each once), in f64, plus the sum of the magnitudes of the
/// terms (the scale round-off is relative to).
pub fn total_momentum(set: &BodySet, handles: &[BodyHandle]) -> ([f64; 3], f64) {
    let mut seen: Vec<BodyHandle> = Vec::new();
    let mut p = [0.0f64; 3];
    let mut scale = 0.0f64;
    for &h in handles {
        if seen.contains(&h) {
            continue;
        }
        seen.push(h);
        let sim = set.sim(h).unwrap();
        if sim.body_type != BodyType::Dynamic {
            continue;
        }
        let st = set.state(h).unwrap();
        let m = d(sim.mass);
        let i = d(sim.inertia);
        let [x, y] = dv(sim.center);
        let [vx, vy] = dv(st.v);
        let w = d(st.w);
        p[0] += m * vx;
        p[1] += m * vy;
        let l = m * (x * vy - y * vx) + i * w;
        p[2] += l;
        scale += m * (vx.abs() + vy.abs())
            + m * (x.abs() * vy.abs() + y.abs() * vx.abs())
            + (i * w).abs();
    }
    (p, scale)
}

/// `p1 + η Qᵀ p2` and `I1 ω1 + I2 ω2` in f64, plus the scale of the terms.
pub fn scaled_momentum(
    set: &BodySet,
    body: BodyHandle,
    clone: BodyHandle,
    map: &PortalMap,
) -> ([f64; 3], f64) {
    let q = map.rotation();
    let (qc, qs) = (d(q.c), d(q.s));
    let eta = d(map.eta);
    let part = |h: BodyHandle| {
        let sim = set.sim(h).unwrap();
        let st = set.state(h).unwrap();
        let m = d(sim.mass);
        let [vx, vy] = dv(st.v);
        (m * vx, m * vy, d(sim.inertia) * d(st.w))
    };
    let (p1x, p1y, l1) = part(body);
    let (p2x, p2y, l2) = part(clone);
    // Qᵀ p2
    let (qx, qy) = (qc * p2x + qs * p2y, -qs * p2x + qc * p2y);
    let value = [p1x + eta * qx, p1y + eta * qy, l1 + l2];
    let scale = p1x.abs() + p1y.abs() + eta * (p2x.abs() + p2y.abs()) + l1.abs() + l2.abs();
    (value, scale)
}

/// Log-uniform values between `10^lo` and `10^hi`.
pub fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = Real> + Clone {
    (lo..hi).prop_map(|u| 10f64.powf(u) as Real)
}

/// Uniform reals.
pub fn real(lo: f64, hi: f64) -> impl Strategy<Value = Real> + Clone {
    (lo..hi).prop_map(|u| u as Real)
}

/// Vectors with components in `[-r, r]`.
pub fn vec2(r: f64) -> impl Strategy<Value = Vec2> + Clone {
    (-r..r, -r..r).prop_map(|(x, y)| Vec2::new(x as Real, y as Real))
}

/// A random body of a type drawn from `ty`: centre in ±5 m, any angle,
/// speed components ±2 m/s, ω ±1.5 rad/s, mass and inertia in
/// `[1e-3, 1e3]` (six orders of magnitude), local centre ±0.5 m.
pub fn body_spec(
    ty: impl Strategy<Value = BodyType> + Clone,
) -> impl Strategy<Value = BodySpec> + Clone {
    (
        ty,
        vec2(5.0),
        real(-std::f64::consts::PI, std::f64::consts::PI),
        vec2(2.0),
        real(-1.5, 1.5),
        log_uniform(-3.0, 3.0),
        log_uniform(-3.0, 3.0),
        vec2(0.5),
    )
        .prop_map(
            |(ty, center, angle, v, w, mass, inertia, local_center)| BodySpec {
                ty,
                center,
                angle,
                v: if ty == BodyType::Static {
                    Vec2::ZERO
                } else {
                    v
                },
                w: if ty == BodyType::Static { 0.0 } else { w },
                mass,
                inertia,
                local_center,
                fixed_rotation: false,
            },
        )
}

/// A random portal: anchor ±2 m, any direction (given at a random length),
/// half-width 0.1–3 m.
pub fn portal() -> impl Strategy<Value = Portal> + Clone {
    (
        vec2(2.0),
        real(-std::f64::consts::PI, std::f64::consts::PI),
        real(0.2, 5.0),
        real(0.1, 3.0),
    )
        .prop_map(|(anchor, a, len, w)| {
            Portal::new(anchor, len * Vec2::new(a.cos(), a.sin()), w).expect("valid portal")
        })
}

/// Any portal body type.
pub fn any_type() -> impl Strategy<Value = BodyType> + Clone {
    prop_oneof![
        Just(BodyType::Static),
        Just(BodyType::Kinematic),
        Just(BodyType::Dynamic)
    ]
}

/// Static or kinematic (zero inverse mass).
pub fn massless_type() -> impl Strategy<Value = BodyType> + Clone {
    prop_oneof![Just(BodyType::Static), Just(BodyType::Kinematic)]
}

/// A random case: the body and its clone dynamic, the portal bodies of
/// the given types (A and B one body with probability 1/4), η in [0.1, 10]
/// (log-uniform), the clone anywhere and its angle error `c2` in ±3 rad.
pub fn portal_case(
    portal_type: impl Strategy<Value = BodyType> + Clone,
) -> impl Strategy<Value = PortalCase> + Clone {
    (
        body_spec(Just(BodyType::Dynamic)),
        body_spec(Just(BodyType::Dynamic)),
        body_spec(portal_type.clone()),
        body_spec(portal_type),
        prop::bool::weighted(0.25),
        portal(),
        portal(),
        log_uniform(-1.0, 1.0),
        real(-3.0, 3.0),
    )
        .prop_map(
            |(body, clone, a, b, same_ab, portal_a, portal_b, eta, c2)| {
                let mut case = PortalCase {
                    body,
                    clone,
                    a,
                    b,
                    same_ab,
                    portal_a,
                    portal_b,
                    eta,
                };
                case.set_angle_error(c2);
                case
            },
        )
}

/// Machine epsilon of `Real`, as f64.
#[allow(clippy::unnecessary_cast)] // `Real` is f64 with the feature (a const: no fn call)
pub const EPS: f64 = EPSILON as f64;

/// A static body with one box shape of half extents `hx`, `hy` centred at
/// `center`: the walls and floors of the portal tests.
pub fn wall(world: &mut janus2d_world::World, center: Vec2, hx: Real, hy: Real) -> BodyHandle {
    let b = world
        .create_body(&BodyDef::fixed(center))
        .expect("a wall at a finite place");
    world
        .create_shape(
            b,
            &janus2d_world::ShapeDef::default(),
            janus2d_core::geometry::Polygon::make_box(hx, hy),
        )
        .expect("a wall of positive size");
    b
}

/// Total linear momentum (kg·m/s) and angular momentum about the origin
/// (kg·m²/s) of a world's dynamic bodies, read through the public API.
#[must_use]
pub fn world_momentum(world: &janus2d_world::World) -> (Vec2, Real) {
    let (mut p, mut l) = (Vec2::ZERO, 0.0 as Real);
    for h in world.body_handles() {
        if world.body_type(h) != Ok(BodyType::Dynamic) {
            continue;
        }
        let (Ok(m), Ok(v), Ok(x), Ok(i), Ok(w)) = (
            world.mass(h),
            world.linear_velocity(h),
            world.center_of_mass(h),
            world.rotational_inertia(h),
            world.angular_velocity(h),
        ) else {
            continue;
        };
        p += m * v;
        l += m * cross(x, v) + i * w;
    }
    (p, l)
}

/// The free-slab portal scene of the momentum tests: gravity 0, sleep off
/// (a sleeping island is put at rest, a deliberate loss of momentum), two
/// dynamic slabs (0.5 × 3 m, density 20) at the origin and at (20, 5),
/// each carrying one portal of half-width 1 on its face (the first facing
/// −x, the second +x). Returns the world, the two slabs and the pair.
#[cfg(feature = "portals")]
#[must_use]
pub fn free_slab_portals() -> (
    janus2d_world::World,
    BodyHandle,
    BodyHandle,
    janus2d_world::PortalPairHandle,
) {
    use janus2d_core::geometry::Polygon;
    use janus2d_world::{PortalPairDef, ShapeDef, World, WorldDef};
    let mut def = WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    };
    def.sleep.enabled = false;
    let mut world = World::new(def).expect("a valid world");
    let slab = |world: &mut World, p: Vec2| {
        let b = world.create_body(&BodyDef::dynamic(p)).expect("a slab");
        world
            .create_shape(
                b,
                &ShapeDef::default().with_density(20.0),
                Polygon::make_box(0.25, 1.5),
            )
            .expect("a slab shape");
        b
    };
    let a = slab(&mut world, Vec2::ZERO);
    let b = slab(&mut world, Vec2::new(20.0, 5.0));
    let pair = world
        .create_portal_pair(&PortalPairDef::new(
            portal_def(a, Vec2::new(-0.25, 0.0), -Vec2::X, 1.0),
            portal_def(b, Vec2::new(0.25, 0.0), Vec2::X, 1.0),
        ))
        .expect("a valid portal pair");
    (world, a, b, pair)
}

/// A portal on `body` at `anchor` (body frame), facing `direction`, with
/// half-width `half_width`.
#[cfg(feature = "portals")]
#[must_use]
pub fn portal_def(
    body: BodyHandle,
    anchor: Vec2,
    direction: Vec2,
    half_width: Real,
) -> janus2d_world::PortalDef {
    janus2d_world::PortalDef::new(body, anchor, direction, half_width)
}

/// The determinism scene: three chains of 12 hinged bodies from a static
/// ground, one with joint limits, one with springs, one with motors
/// (`tests/scene_runs/determinism.rs` pins its state hash after 500 steps; the
/// snapshot tests continue it from a copy).
#[must_use]
pub fn hinged_chains() -> janus2d_world::World {
    use janus2d_constraints::RevoluteJointDef;
    let mut world =
        janus2d_world::World::new(janus2d_world::WorldDef::default()).expect("the default world");
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::ZERO))
        .expect("a static ground");
    for chain in 0..3 {
        let x0 = 20.0 * chain as Real;
        let mut prev = ground;
        for i in 0..12 {
            let pos = Vec2::new(x0 + i as Real + 0.5, 0.3 * chain as Real);
            let b = world
                .create_body(&BodyDef::dynamic(pos).with_mass(1.0 + 0.1 * i as Real, 0.1))
                .expect("a link");
            let anchor_a = if i == 0 {
                Vec2::new(x0, 0.3 * chain as Real)
            } else {
                Vec2::new(0.5, 0.0)
            };
            let mut def = RevoluteJointDef::new(prev, b, anchor_a, Vec2::new(-0.5, 0.0));
            def = match chain {
                0 => def.with_limits(-0.4, 0.4),
                1 => def.with_spring(4.0, 0.3),
                _ => def.with_motor(1.0 + 0.1 * i as Real, 20.0),
            };
            world.create_revolute_joint(&def).expect("a hinge");
            prev = b;
        }
    }
    world
}

/// A world using every per-body and per-shape state issue 32 added, for
/// the snapshot, fuzz-seed and state-machine tests: a chain object with
/// three segment materials (friction, rolling resistance, tangent speed,
/// combine rules, material ids) on the ground; a rolling ball (rolling
/// resistance, hit events, a contact force threshold); an x- and
/// rotation-locked box with an offset turned geometry; a y-locked box
/// sliding; a disabled body (offset capsule) hinged to an enabled one (the
/// joint kept off); a sensor with sensor events off on one visitor; move
/// events on. Returned after `steps` steps of 1/60 s.
#[must_use]
pub fn issue32_world(steps: usize) -> janus2d_world::World {
    use janus2d_constraints::RevoluteJointDef;
    use janus2d_core::body::MotionLocks;
    use janus2d_core::geometry::{Capsule, Circle, Polygon};
    use janus2d_core::material::CombineRule;
    use janus2d_world::{ChainDef, ShapeDef, SurfaceMaterial, World, WorldDef};
    let v = Vec2::new;
    let mut world =
        World::new(WorldDef::default().with_move_events(true)).expect("the default world");
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::ZERO))
        .expect("ground");
    let materials = vec![
        SurfaceMaterial::default()
            .with_friction(0.2)
            .with_material_id(7),
        SurfaceMaterial {
            friction_combine: CombineRule::Max,
            ..SurfaceMaterial::default()
                .with_friction(0.9)
                .with_rolling_resistance(0.3)
        },
        SurfaceMaterial {
            restitution_combine: CombineRule::Min,
            ..SurfaceMaterial::default()
                .with_tangent_speed(1.5)
                .with_restitution(0.2)
                .with_material_id(9)
        },
    ];
    let points = vec![v(12.0, 0.0), v(4.0, 0.0), v(-2.0, 0.0), v(-12.0, 0.0)];
    world
        .create_chain(
            ground,
            &ChainDef::new(points).with_segment_materials(materials),
        )
        .expect("the ground chain");
    let ball = world
        .create_body(&BodyDef {
            linear_velocity: v(-4.0, 0.0),
            ..BodyDef::dynamic(v(8.0, 0.6))
        })
        .expect("ball");
    let def = ShapeDef::default()
        .with_rolling_resistance(0.1)
        .with_friction_combine(CombineRule::Average)
        .with_hit_events(true)
        .with_force_event_threshold(5.0)
        .with_material_id(3);
    world
        .create_shape(ball, &def, Circle::new(Vec2::ZERO, 0.5).expect("a circle"))
        .expect("ball shape");
    let locks = MotionLocks {
        linear_x: true,
        linear_y: false,
        angular: true,
    };
    let slider = world
        .create_body(&BodyDef::dynamic(v(-6.0, 3.0)).with_motion_locks(locks))
        .expect("slider");
    world
        .create_shape(
            slider,
            &ShapeDef::default().with_offset(v(0.3, 0.0), 0.4),
            Polygon::make_box(0.4, 0.3),
        )
        .expect("slider shape");
    let hover = world
        .create_body(&BodyDef {
            linear_velocity: v(2.0, 0.0),
            ..BodyDef::dynamic(v(-1.0, 1.5)).with_motion_locks(MotionLocks::Y)
        })
        .expect("hover");
    world
        .create_shape(
            hover,
            &ShapeDef::default().with_tangent_speed(0.5),
            Polygon::make_box(0.25, 0.25),
        )
        .expect("hover shape");
    let held = world
        .create_body(&BodyDef::dynamic(v(2.0, 4.0)))
        .expect("held");
    world
        .create_shape(held, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
        .expect("held shape");
    let off = world
        .create_body(&BodyDef::dynamic(v(3.0, 4.0)))
        .expect("off");
    let capsule = Capsule::new(v(-0.4, 0.0), v(0.4, 0.0), 0.2).expect("a capsule");
    world
        .create_shape(
            off,
            &ShapeDef::default().with_offset(v(0.0, 0.3), 0.2),
            capsule,
        )
        .expect("off shape");
    world
        .create_revolute_joint(&RevoluteJointDef::new(
            held,
            off,
            v(0.5, 0.0),
            v(-0.5, -0.3),
        ))
        .expect("a hinge");
    world.set_body_enabled(off, false).expect("disable");
    let sensor = world
        .create_body(&BodyDef::fixed(v(-3.0, 1.0)))
        .expect("sensor body");
    world
        .create_shape(
            sensor,
            &ShapeDef::default().sensor(),
            Polygon::make_box(1.0, 1.0),
        )
        .expect("sensor");
    let visitor = world
        .create_body(&BodyDef::dynamic(v(-3.0, 8.0)))
        .expect("visitor");
    world
        .create_shape(
            visitor,
            &ShapeDef::default().with_sensor_events(true),
            Circle::new(Vec2::ZERO, 0.2).expect("a circle"),
        )
        .expect("visitor shape");
    let quiet = world
        .create_body(&BodyDef::dynamic(v(-2.5, 8.0)))
        .expect("quiet visitor");
    world
        .create_shape(
            quiet,
            &ShapeDef::default()
                .with_sensor_events(false)
                .with_contact_events(false),
            Circle::new(Vec2::ZERO, 0.2).expect("a circle"),
        )
        .expect("quiet shape");
    for _ in 0..steps {
        world.step(1.0 / 60.0).expect("a step");
    }
    world
}

/// Whether `JANUS2D_REPORT` is set: the tests then print their measured
/// worst figures.
pub fn report() -> bool {
    std::env::var("JANUS2D_REPORT").is_ok()
}

/// The seed a property named `name` draws its cases from: `seed` if it is
/// fixed (`PROPTEST_RNG_SEED` set), else one fixed by the name (FNV-1a),
/// so a run is the same on every machine. For `proptest!` blocks:
/// `rng_seed: named_seed("name", ProptestConfig::default().rng_seed)`.
#[must_use]
pub fn named_seed(name: &str, seed: RngSeed) -> RngSeed {
    match seed {
        RngSeed::Random => RngSeed::Fixed(name.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })),
        fixed => fixed,
    }
}

/// Runs a property over at least 256 cases (more if `PROPTEST_CASES` asks;
/// no failure persistence); the closure returns the measured error as a
/// fraction of its bound (≤ 1 passes), and the worst fraction is printed
/// under `JANUS2D_REPORT`.
///
/// The cases come from a seed fixed by the property's name, so a run is
/// the same on every machine and CI fails only when the code changes;
/// `PROPTEST_RNG_SEED=N` draws another set (with a larger
/// `PROPTEST_CASES`, the way to look for rare failures).
///
/// # Panics
///
/// When a case fails (with the minimal failing input) or the runner gives up.
pub fn check<S: Strategy>(
    name: &str,
    strategy: S,
    f: impl Fn(S::Value) -> Result<f64, TestCaseError>,
) where
    S::Value: std::fmt::Debug,
{
    let mut config = Config::default();
    config.cases = config.cases.max(256);
    config.failure_persistence = None;
    config.rng_seed = named_seed(name, config.rng_seed);
    let cases = config.cases;
    let mut runner = TestRunner::new(config);
    let worst = Cell::new(0.0f64);
    let result = runner.run(&strategy, |v| {
        let r = f(v)?;
        if r > worst.get() {
            worst.set(r);
        }
        Ok(())
    });
    match result {
        Ok(()) => {}
        Err(TestError::Fail(why, value)) => {
            panic!("{name}: {why}\nminimal failing input: {value:#?}")
        }
        Err(e) => panic!("{name}: {e}"),
    }
    if report() {
        eprintln!(
            "{name}: {cases} cases, worst error / bound = {:.3e}",
            worst.get()
        );
    }
}

/// A definition of joint kind `kind` between `a` and `b` with anchors
/// `anchor` on a and `−anchor` on b, its limits (where the kind has them)
/// at `limits`, for the API state machine, the fuzz target and the
/// determinism scene: every kind through one call. The values are
/// whatever the caller passes, so a bad `anchor` or `limits` reaches the
/// kind's validation.
#[must_use]
pub fn joint_def_of_kind(
    kind: janus2d_constraints::JointKind,
    a: BodyHandle,
    b: BodyHandle,
    anchor: Vec2,
    limits: Option<(Real, Real)>,
    collide_connected: bool,
) -> janus2d_constraints::JointDef {
    use janus2d_constraints::*;
    let mut def: JointDef = match kind {
        JointKind::Revolute => RevoluteJointDef::new(a, b, anchor, -anchor).into(),
        JointKind::Prismatic => {
            PrismaticJointDef::new(a, b, anchor, -anchor, Vec2::new(1.0, 0.5)).into()
        }
        JointKind::Weld => WeldJointDef::new(a, b, anchor, -anchor).into(),
        // Between the bodies' origins, at their separation when the anchors
        // meet (`2 |anchor|`).
        JointKind::Distance => DistanceJointDef::new(
            a,
            b,
            Vec2::ZERO,
            Vec2::ZERO,
            (2.0 * anchor.length()).max(0.1),
        )
        .into(),
        JointKind::Wheel => WheelJointDef::new(a, b, anchor, -anchor, Vec2::Y).into(),
        JointKind::Motor => MotorJointDef::new(a, b).with_offset(anchor, 0.25).into(),
        JointKind::Mouse => MouseJointDef::new(a, b, anchor, 500.0).into(),
        JointKind::Filter => FilterJointDef::new(a, b).into(),
    };
    if let (Some((lower, upper)), Some(l)) = (limits, def.limits_mut()) {
        *l.enable = true;
        *l.lower = lower;
        *l.upper = upper;
    }
    def.base_mut().collide_connected = collide_connected;
    def
}

/// A scene holding every joint kind: per kind, 16 chains of 4 boxes
/// (0.8 m, 1.1 m apart) side by side in four rows, each chain hung from a
/// static frame at its first box's left side and each box joined to the
/// one before at their facing sides, with limits on every other joint
/// where the kind has them (a mouse joint's target is its box's start);
/// every joint starts satisfied, nothing overlaps. 512 joints, so the
/// joint prepare and colours take their blocked paths on the team.
pub fn every_joint_kind_world() -> janus2d_world::World {
    use janus2d_constraints::{JointDef, JointKind};
    use janus2d_core::geometry::Polygon;
    use janus2d_world::{ShapeDef, World, WorldDef};
    let mut world = World::new(WorldDef::default()).unwrap();
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    world
        .create_shape(
            ground,
            &ShapeDef::default(),
            Polygon::make_offset_box(90.0, 0.5, Vec2::new(0.0, -0.5), 0.0),
        )
        .unwrap();
    let half = Vec2::new(0.55, 0.0);
    for (k, &kind) in JointKind::ALL.iter().enumerate() {
        for chain in 0..16 {
            let x = -88.0 + 22.0 * k as Real + 5.5 * (chain % 4) as Real;
            let y = 3.0 + 2.0 * (chain / 4) as Real;
            let mut previous = ground;
            for i in 0..4 {
                let p = Vec2::new(x + 1.1 * i as Real, y);
                let b = world.create_body(&BodyDef::dynamic(p)).unwrap();
                world
                    .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.4, 0.4))
                    .unwrap();
                // Angles or translations of ±0.5; a distance joint's lengths.
                let range = if kind == JointKind::Distance {
                    (0.5, 1.5)
                } else {
                    (-0.5, 0.5)
                };
                let limits = (i % 2 == 0).then_some(range);
                let mut def = joint_def_of_kind(kind, previous, b, half, limits, false);
                if previous == ground {
                    // The frame on the ground at the box's left side (a
                    // distance joint's anchors are the bodies' origins:
                    // one box to the left).
                    let reach = if kind == JointKind::Distance {
                        2.0 * half
                    } else {
                        half
                    };
                    def.base_mut().local_frame_a.anchor = p - reach;
                }
                if let JointDef::Mouse(m) = &mut def {
                    m.target = p;
                }
                world.create_joint(&def).unwrap();
                previous = b;
            }
        }
    }
    world
}
