//! The Box2D adapter: builds a [`SceneDesc`] into a Box2D v3 world through
//! `boxdd` 0.6 (safe bindings of Box2D 3.2.0-dev) and runs it behind the
//! [`Engine`] interface.
//!
//! | description                   | Box2D (boxdd)                                                     |
//! |-------------------------------|-------------------------------------------------------------------|
//! | `Settings::gravity`           | `b2WorldDef::gravity`                                             |
//! | `Settings::sleep`             | `b2WorldDef::enableSleep`                                         |
//! | `contact_hertz`, `contact_damping_ratio` | `b2WorldDef::contactHertz`, `contactDampingRatio`      |
//! | `contact_push_max_velocity`   | `b2WorldDef::contactSpeed` (3.2's name for the push-out cap)      |
//! | `joint_hertz`, `joint_damping_ratio` | per joint: `b2JointDef::constraintHertz`, `constraintDampingRatio` (3.2 has no world field) |
//! | `dt`, `substeps`              | `b2World_Step(dt, substeps)`                                      |
//! | `EngineOptions::threads`      | `b2WorldDef::workerCount` (> 1: Box2D's built-in scheduler)       |
//! | `BodyKind`                    | `b2_staticBody` / `b2_kinematicBody` / `b2_dynamicBody`           |
//! | `BodyDesc::angle`             | `b2BodyDef::rotation`                                             |
//! | `awake`, `sleep_threshold`    | `b2BodyDef::isAwake`, `sleepThreshold`                            |
//! | `BodyDesc::mass`              | `b2Body_SetMassData` (centre at the origin) after the shapes      |
//! | `ShapeDesc` material          | `b2ShapeDef::material` (friction, restitution), `density`         |
//! | `FilterDesc`                  | `b2Filter` (categoryBits, maskBits, groupIndex)                   |
//! | `hit_events`                  | `b2ShapeDef::enableHitEvents`                                     |
//! | `Geometry::Circle`            | `b2CreateCircleShape`                                             |
//! | `Geometry::Capsule`           | `b2CreateCapsuleShape`                                            |
//! | `Geometry::Box`               | `b2MakeBox` / `b2MakeOffsetBox` / `b2MakeRoundedBox` / `b2MakeOffsetRoundedBox` |
//! | `Geometry::Hull`              | `b2ComputeHull` + `b2MakePolygon(hull, radius)`                   |
//! | `Geometry::Segment`           | `b2CreateSegmentShape` (two-sided)                                |
//! | `Geometry::ChainLoop`         | `b2CreateChain`, `isLoop = true`, points in the given (clockwise) order, one material |
//! | `RevoluteDesc::local_a/b`     | `b2JointDef::localFrameA.p` / `localFrameB.p`                     |
//! | `reference_angle`             | `localFrameA.q = rot(reference)` (3.2 has no `referenceAngle`)    |
//! | `limit`, `motor`, `spring`    | `enableLimit`/`lowerAngle`/`upperAngle`, `enableMotor`/`motorSpeed`/`maxMotorTorque` (clamped to `f32::MAX`), `enableSpring`/`hertz`/`dampingRatio` |
//! | `JointDesc` frames            | `b2JointDef::localFrameA/B` (anchor and angle as given), `collideConnected`, the scene's constraint tuning |
//! | `JointDesc::Revolute`         | as `joints` above                                                 |
//! | `JointDesc::Weld`             | `b2WeldJointDef`: `linearHertz`, `linearDampingRatio`, `angularHertz`, `angularDampingRatio` (0 Hz: rigid) |
//! | `JointDesc::Prismatic`        | `b2PrismaticJointDef`: `enableLimit`/`lowerTranslation`/`upperTranslation`, `enableMotor`/`motorSpeed`/`maxMotorForce`, `enableSpring`/`hertz`/`dampingRatio`/`targetTranslation` |
//! | `JointDesc::Wheel`            | `b2WheelJointDef`: `enableSpring`/`hertz`/`dampingRatio` (no spring: `enableSpring = false`, Box2D's default is on), `enableLimit`/…, `enableMotor`/`motorSpeed`/`maxMotorTorque` |
//! | `JointDesc::Motor`, `Mouse`, `Filter` | not built (no peers scene uses them): the scene is refused |
//! | `JointDesc::Distance`         | `b2DistanceJointDef`: `length`, `enableSpring`/`hertz`/`dampingRatio`/`lowerSpringForce`/`upperSpringForce`, `enableLimit`/`minLength`/`maxLength`, `enableMotor`/`motorSpeed`/`maxMotorForce` (forces clamped to ±`f32::MAX`) |
//! | `Action::Spawn` / `Despawn`   | create the group's bodies then joints / `b2DestroyBody` each body |
//! | `Action::Target`              | `b2Body_SetTargetTransform(target, dt, wake = true)`              |
//! | [`Engine::body_count`]        | `b2World_GetCounters().bodyCount`                                 |
//! | [`Engine::awake_count`]       | `b2World_GetAwakeBodyCount`                                       |
//! | [`Engine::touching_count`]    | Σ over bodies of `b2Body_GetContactData` (touching only) ÷ 2      |
//! | [`Engine::stage_times`]       | `b2World_GetProfile` (the stage table is on `Box2d`'s `stage_times`) |
//!
//! Limits:
//!
//! - Box2D has no portals: a scene with portal pairs is refused at build.
//! - Angles become rotations through boxdd's `sin_cos`, not `b2MakeRot`'s
//!   approximation (the same to ~1e-7; every benchmark body starts at 0).
//! - Everything the description does not name keeps Box2D's defaults
//!   (continuous on, contact recycling on, per-body `enableSleep` on).
//! - Bodies are read through boxdd's `&mut World` capabilities, so the world
//!   sits in a `RefCell`: the adapter is neither `Send` nor `Sync`.

use std::cell::RefCell;
use std::collections::BTreeMap;

use boxdd::shapes::{self, SurfaceMaterial};
use boxdd::{
    BodyId, BodyType, ChainDef, ConstraintTuning, DistanceJointDef, Filter, Foundation, JointBase,
    MassData, Polygon, Position, PrismaticJointDef, RevoluteJointDef, ShapeDef, Transform, Vec2,
    WeldJointDef, WheelJointDef, WorkerCount, World, WorldScalar, WorldTransform,
};
use janus2d_testbed::desc::{
    Action, BodyDesc, BodyKind, FilterDesc, FrameDesc, Geometry, JointBaseDesc, JointDesc,
    RevoluteDesc, SceneDesc, Settings, ShapeDesc,
};
use janus2d_testbed::engine::{BodyReading, Engine, EngineOptions, StageTimes};

/// A description vector as a Box2D local vector.
fn local(x: f64, y: f64) -> Vec2 {
    Vec2::new(x as f32, y as f32)
}

/// A description point as a Box2D world position.
fn position(x: f64, y: f64) -> Position {
    Position::new(x as WorldScalar, y as WorldScalar)
}

/// A description value in `f32`, `±f64::MAX`-like values clamped to
/// `±f32::MAX`.
fn clamped(x: f64) -> f32 {
    x.clamp(-f64::from(f32::MAX), f64::from(f32::MAX)) as f32
}

/// A description frame as a Box2D local transform.
fn frame(f: &FrameDesc) -> boxdd::Result<Transform> {
    Transform::from_pos_angle(local(f.anchor.x, f.anchor.y), f.angle as f32)
}

/// A boxdd error as the adapter's error text.
fn text(context: &str, e: boxdd::Error) -> String {
    format!("Box2D {context}: {e:?}")
}

/// A scene built in a Box2D world.
pub struct Box2d {
    /// The world (interior mutability: boxdd reads bodies through `&mut World`,
    /// the [`Engine`] readers take `&self`).
    world: RefCell<World>,
    /// Ids of the scene's initial bodies, by index, with their kind.
    bodies: Vec<(BodyId, BodyKind)>,
    /// Bodies of the live spawned groups, with their kind.
    groups: BTreeMap<usize, Vec<(BodyId, BodyKind)>>,
    /// Joint stiffness and damping ratio every joint is created with.
    joint_tuning: ConstraintTuning,
    /// Step, s.
    dt: f32,
    /// Substeps per step.
    substeps: i32,
}

impl Box2d {
    /// Box2D's world for the scene settings, with `threads` workers.
    fn create_world(settings: &Settings, threads: usize) -> Result<World, String> {
        let foundation = Foundation::initialize_default().map_err(|e| text("foundation", e))?;
        let workers = WorkerCount::new(threads.clamp(1, usize::from(WorkerCount::MAX)) as u32)
            .map_err(|e| text("worker count", e))?;
        let def = foundation
            .world_builder()
            .gravity(local(settings.gravity.x, settings.gravity.y))
            .contact_hertz(settings.contact_hertz as f32)
            .contact_damping_ratio(settings.contact_damping_ratio as f32)
            .contact_speed(settings.contact_push_max_velocity as f32)
            .enable_sleep(settings.sleep)
            .worker_count(workers)
            .build()
            .map_err(|e| text("world definition", e))?;
        foundation.create_world(def).map_err(|e| text("world", e))
    }

    /// The shape definition of a shape description.
    fn shape_def(s: &ShapeDesc) -> Result<ShapeDef, String> {
        ShapeDef::builder()
            .material(Self::material(s)?)
            .density(s.density as f32)
            .filter(Self::filter(&s.filter))
            .enable_hit_events(s.hit_events)
            .build()
            .map_err(|e| text("shape definition", e))
    }

    /// Friction and restitution of a shape description.
    fn material(s: &ShapeDesc) -> Result<SurfaceMaterial, String> {
        SurfaceMaterial::default()
            .with_friction(s.friction as f32)
            .and_then(|m| m.with_restitution(s.restitution as f32))
            .map_err(|e| text("material", e))
    }

    /// The Box2D filter of a filter description.
    fn filter(f: &FilterDesc) -> Filter {
        Filter {
            category_bits: f.category,
            mask_bits: f.mask,
            group_index: f.group,
        }
    }

    /// The polygon of a (possibly offset, turned, rounded) box, with Box2D's
    /// own constructor for each case.
    fn box_polygon(
        hx: f64,
        hy: f64,
        cx: f64,
        cy: f64,
        angle: f64,
        radius: f64,
    ) -> boxdd::Result<Polygon> {
        let (hx, hy, radius) = (hx as f32, hy as f32, radius as f32);
        let centred = cx == 0.0 && cy == 0.0 && angle == 0.0;
        match (centred, radius > 0.0) {
            (true, false) => shapes::box_polygon(hx, hy),
            (true, true) => shapes::rounded_box_polygon(hx, hy, radius),
            (false, rounded) => {
                let xf = Transform::from_pos_angle(local(cx, cy), angle as f32)?;
                if rounded {
                    shapes::offset_rounded_box_polygon(hx, hy, radius, xf)
                } else {
                    shapes::offset_box_polygon(hx, hy, xf)
                }
            }
        }
    }

    /// Creates one body and its shapes (and its mass override).
    fn create_body(world: &mut World, b: &BodyDesc) -> Result<BodyId, String> {
        let kind = match b.kind {
            BodyKind::Static => BodyType::Static,
            BodyKind::Kinematic => BodyType::Kinematic,
            BodyKind::Dynamic => BodyType::Dynamic,
        };
        let def = world
            .body_builder()
            .body_type(kind)
            .position(position(b.position.x, b.position.y))
            .angle(b.angle as f32)
            .linear_velocity(local(b.linear_velocity.x, b.linear_velocity.y))
            .angular_velocity(b.angular_velocity as f32)
            .linear_damping(b.linear_damping as f32)
            .awake(b.awake)
            .sleep_threshold(b.sleep_threshold as f32)
            .build()
            .map_err(|e| text("body definition", e))?;
        let id = world.create_body(def).map_err(|e| text("body", e))?;
        let mut body = world.body(id).map_err(|e| text("body", e))?;
        for s in &b.shapes {
            let def = Self::shape_def(s)?;
            let made = match &s.geometry {
                Geometry::Circle { center, radius } => {
                    shapes::circle(local(center.x, center.y), *radius as f32)
                        .and_then(|c| body.create_circle(&def, &c))
                        .map(drop)
                }
                Geometry::Capsule { a, b, radius } => {
                    shapes::capsule(local(a.x, a.y), local(b.x, b.y), *radius as f32)
                        .and_then(|c| body.create_capsule(&def, &c))
                        .map(drop)
                }
                Geometry::Box {
                    half,
                    center,
                    angle,
                    radius,
                } => Self::box_polygon(half.x, half.y, center.x, center.y, *angle, *radius)
                    .and_then(|p| body.create_polygon(&def, &p))
                    .map(drop),
                Geometry::Hull { points, radius } => shapes::polygon_from_points(
                    points.iter().map(|p| local(p.x, p.y)),
                    *radius as f32,
                )
                .and_then(|p| body.create_polygon(&def, &p))
                .map(drop),
                Geometry::Segment { a, b } => shapes::segment(local(a.x, a.y), local(b.x, b.y))
                    .and_then(|g| body.create_segment(&def, &g))
                    .map(drop),
                Geometry::ChainLoop { points } => ChainDef::builder()
                    .points(points.iter().map(|p| local(p.x, p.y)))
                    .is_loop(true)
                    .filter(def.filter())
                    .single_material(&def.material())
                    .build()
                    .and_then(|chain| body.create_chain(&chain))
                    .map(drop),
            };
            made.map_err(|e| text("shape", e))?;
        }
        if let Some((mass, inertia)) = b.mass {
            let data = MassData::new(mass as f32, Vec2::ZERO, inertia as f32)
                .map_err(|e| text("mass data", e))?;
            body.set_mass_data(data).map_err(|e| text("mass data", e))?;
        }
        Ok(id)
    }

    /// Creates one revolute joint between bodies of `ids`.
    fn create_joint(
        world: &mut World,
        j: &RevoluteDesc,
        ids: &[(BodyId, BodyKind)],
        tuning: ConstraintTuning,
    ) -> Result<(), String> {
        let (a, b) = (ids[j.body_a].0, ids[j.body_b].0);
        // Box2D 3.2 has no reference angle: the joint angle is
        // (θb + angle(frame b)) − (θa + angle(frame a)), so frame a turned by
        // the reference angle gives θb − θa − reference.
        let base = world
            .joint_base(a, b)
            .and_then(|base| {
                Ok(base
                    .with_local_frames(
                        Transform::from_pos_angle(
                            local(j.local_a.x, j.local_a.y),
                            j.reference_angle as f32,
                        )?,
                        Transform::from_pos_angle(local(j.local_b.x, j.local_b.y), 0.0)?,
                    )
                    .with_collide_connected(j.collide_connected)
                    .with_constraint_tuning(tuning))
            })
            .map_err(|e| text("joint base", e))?;
        let mut def = RevoluteJointDef::new(base);
        if let Some((lower, upper)) = j.limit {
            def = def
                .enable_limit(true)
                .lower_angle(lower as f32)
                .upper_angle(upper as f32);
        }
        if let Some((speed, torque)) = j.motor {
            def = def
                .enable_motor(true)
                .motor_speed(speed as f32)
                .max_motor_torque(torque.min(f64::from(f32::MAX)) as f32);
        }
        if let Some((hertz, damping_ratio)) = j.spring {
            def = def
                .enable_spring(true)
                .hertz(hertz as f32)
                .damping_ratio(damping_ratio as f32);
        }
        world
            .create_revolute_joint(&def)
            .map(drop)
            .map_err(|e| text("revolute joint", e))
    }

    /// Box2D's joint base of a description's: bodies from `ids`, frames as
    /// given, the scene's constraint tuning.
    fn joint_base(
        world: &World,
        b: &JointBaseDesc,
        ids: &[(BodyId, BodyKind)],
        tuning: ConstraintTuning,
    ) -> Result<JointBase, String> {
        let (a, bb) = (ids[b.body_a].0, ids[b.body_b].0);
        world
            .joint_base(a, bb)
            .and_then(|base| {
                Ok(base
                    .with_local_frames(frame(&b.frame_a)?, frame(&b.frame_b)?)
                    .with_collide_connected(b.collide_connected)
                    .with_constraint_tuning(tuning))
            })
            .map_err(|e| text("joint base", e))
    }

    /// Creates one joint of any kind between bodies of `ids`.
    fn create_any_joint(
        world: &mut World,
        j: &JointDesc,
        ids: &[(BodyId, BodyKind)],
        tuning: ConstraintTuning,
    ) -> Result<(), String> {
        let made = match j {
            JointDesc::Revolute(r) => return Self::create_joint(world, r, ids, tuning),
            JointDesc::Weld(w) => {
                let def = WeldJointDef::new(Self::joint_base(world, &w.base, ids, tuning)?)
                    .linear_hertz(w.linear_hertz as f32)
                    .linear_damping_ratio(w.linear_damping_ratio as f32)
                    .angular_hertz(w.angular_hertz as f32)
                    .angular_damping_ratio(w.angular_damping_ratio as f32);
                world.create_weld_joint(&def)
            }
            JointDesc::Prismatic(p) => {
                let mut def =
                    PrismaticJointDef::new(Self::joint_base(world, &p.base, ids, tuning)?)
                        .enable_limit(p.limit.is_some())
                        .enable_motor(p.motor.is_some())
                        .enable_spring(p.spring.is_some())
                        .translation(p.target_translation as f32);
                if let Some((lower, upper)) = p.limit {
                    def = def
                        .lower_translation(lower as f32)
                        .upper_translation(upper as f32);
                }
                if let Some((speed, force)) = p.motor {
                    def = def
                        .motor_speed(speed as f32)
                        .max_motor_force(clamped(force));
                }
                if let Some((hertz, zeta)) = p.spring {
                    def = def.hertz(hertz as f32).damping_ratio(zeta as f32);
                }
                world.create_prismatic_joint(&def)
            }
            JointDesc::Wheel(w) => {
                let mut def = WheelJointDef::new(Self::joint_base(world, &w.base, ids, tuning)?)
                    .enable_limit(w.limit.is_some())
                    .enable_motor(w.motor.is_some())
                    .enable_spring(w.spring.is_some());
                if let Some((lower, upper)) = w.limit {
                    def = def
                        .lower_translation(lower as f32)
                        .upper_translation(upper as f32);
                }
                if let Some((speed, torque)) = w.motor {
                    def = def
                        .motor_speed(speed as f32)
                        .max_motor_torque(clamped(torque));
                }
                if let Some((hertz, zeta)) = w.spring {
                    def = def.hertz(hertz as f32).damping_ratio(zeta as f32);
                }
                world.create_wheel_joint(&def)
            }
            JointDesc::Distance(d) => {
                let mut def = DistanceJointDef::new(Self::joint_base(world, &d.base, ids, tuning)?)
                    .length(d.length as f32)
                    .enable_limit(d.limit.is_some())
                    .enable_motor(d.motor.is_some())
                    .enable_spring(d.spring.is_some())
                    .lower_spring_force(clamped(d.spring_force.0))
                    .upper_spring_force(clamped(d.spring_force.1));
                if let Some((min, max)) = d.limit {
                    def = def.min_length(min as f32).max_length(max as f32);
                }
                if let Some((speed, force)) = d.motor {
                    def = def
                        .motor_speed(speed as f32)
                        .max_motor_force(clamped(force));
                }
                if let Some((hertz, zeta)) = d.spring {
                    def = def.hertz(hertz as f32).damping_ratio(zeta as f32);
                }
                world.create_distance_joint(&def)
            }
            JointDesc::Motor(_) | JointDesc::Mouse(_) | JointDesc::Filter(_) => {
                return Err(format!(
                    "the Box2D adapter has no {} joint (no peers scene uses one)",
                    j.kind_name()
                ));
            }
        };
        made.map(drop)
            .map_err(|e| text(&format!("{} joint", j.kind_name()), e))
    }

    /// Creates bodies, then the joints between them (indices into `bodies`).
    fn create_group(
        world: &mut World,
        bodies: &[BodyDesc],
        joints: &[RevoluteDesc],
        tuning: ConstraintTuning,
    ) -> Result<Vec<(BodyId, BodyKind)>, String> {
        let mut ids = Vec::with_capacity(bodies.len());
        for b in bodies {
            ids.push((Self::create_body(world, b)?, b.kind));
        }
        for j in joints {
            Self::create_joint(world, j, &ids, tuning)?;
        }
        Ok(ids)
    }

    /// Applies one action; errors are Box2D's.
    pub fn try_apply(&mut self, action: &Action) -> Result<(), String> {
        let world = self.world.get_mut();
        match action {
            Action::Spawn { id, bodies, joints } => {
                let ids = Self::create_group(world, bodies, joints, self.joint_tuning)?;
                self.groups.insert(*id, ids);
            }
            Action::Despawn { id } => {
                for (body, _) in self.groups.remove(id).unwrap_or_default() {
                    world
                        .body(body)
                        .and_then(|b| b.destroy())
                        .map_err(|e| text("destroy body", e))?;
                }
            }
            Action::Target {
                body,
                position: target,
                angle,
            } => {
                let (id, _) = *self
                    .bodies
                    .get(*body)
                    .ok_or_else(|| format!("Box2D target: no body {body}"))?;
                let xf =
                    WorldTransform::from_pos_angle(position(target.x, target.y), *angle as f32)
                        .map_err(|e| text("target transform", e))?;
                world
                    .body(id)
                    .and_then(|mut b| b.set_target_transform(xf, self.dt, true))
                    .map_err(|e| text("target transform", e))?;
            }
        }
        Ok(())
    }

    /// Every live body id: the initial ones, then the spawned groups'.
    fn all_bodies(&self) -> impl Iterator<Item = &(BodyId, BodyKind)> {
        self.bodies.iter().chain(self.groups.values().flatten())
    }

    /// State of one body (None if it is gone).
    fn state_of(world: &mut World, id: BodyId) -> Option<BodyReading> {
        let body = world.body(id).ok()?;
        let p = body.position().ok()?;
        let v = body.linear_velocity().ok()?;
        let mut s = BodyReading {
            angle: f64::from(body.rotation().ok()?.angle()),
            angular_velocity: f64::from(body.angular_velocity().ok()?),
            ..BodyReading::default()
        };
        s.position.x = f64::from(p.x);
        s.position.y = f64::from(p.y);
        s.linear_velocity.x = f64::from(v.x);
        s.linear_velocity.y = f64::from(v.y);
        Some(s)
    }
}

impl Engine for Box2d {
    const NAME: &'static str = "Box2D";

    fn build(desc: &SceneDesc, options: EngineOptions) -> Result<Self, String> {
        if !desc.portals.is_empty() {
            return Err(format!(
                "Box2D has no portals ({} has {})",
                desc.name,
                desc.portals.len()
            ));
        }
        let s = &desc.settings;
        let mut world = Self::create_world(s, options.threads)?;
        let joint_tuning =
            ConstraintTuning::new(s.joint_hertz as f32, s.joint_damping_ratio as f32)
                .map_err(|e| text("joint tuning", e))?;
        let bodies = Self::create_group(&mut world, &desc.bodies, &desc.joints, joint_tuning)?;
        for j in &desc.extra_joints {
            Self::create_any_joint(&mut world, j, &bodies, joint_tuning)?;
        }
        Ok(Box2d {
            world: RefCell::new(world),
            bodies,
            groups: BTreeMap::new(),
            joint_tuning,
            dt: s.dt as f32,
            substeps: s.substeps.max(1) as i32,
        })
    }

    fn apply(&mut self, action: &Action) {
        if let Err(e) = self.try_apply(action) {
            panic!("scripted action: {e}");
        }
    }

    fn step(&mut self) {
        let (dt, substeps) = (self.dt, self.substeps);
        let done = self.world.get_mut().step(dt, substeps).expect("Box2D step");
        if let Some(e) = done.post_step_error() {
            panic!("Box2D step: {e:?}");
        }
    }

    fn state(&self, body: usize) -> Option<BodyReading> {
        let (id, _) = *self.bodies.get(body)?;
        Self::state_of(&mut self.world.borrow_mut(), id)
    }

    fn dynamic_states(&self, out: &mut Vec<BodyReading>) {
        out.clear();
        let mut world = self.world.borrow_mut();
        for &(id, kind) in self.all_bodies() {
            if kind == BodyKind::Dynamic {
                out.extend(Self::state_of(&mut world, id));
            }
        }
    }

    /// `b2World_GetCounters().bodyCount` (every live body, statics too).
    fn body_count(&self) -> usize {
        match self.world.borrow().counters() {
            Ok(c) => c.body_count.max(0) as usize,
            Err(_) => self.all_bodies().count(),
        }
    }

    /// `b2World_GetAwakeBodyCount`: the bodies of the awake solver set
    /// (dynamic and kinematic).
    fn awake_count(&self) -> usize {
        self.world
            .borrow()
            .awake_body_count()
            .map_or(0, |n| n.max(0) as usize)
    }

    /// Touching shape pairs, asleep ones included. `b2Counters::contactCount`
    /// counts every contact (shape pairs whose fat AABBs overlap, touching or
    /// not), so this counts `b2Body_GetContactData` instead, which returns
    /// only contacts with `b2_contactTouchingFlag` (manifold point count > 0):
    /// summed over every body (statics included) each pair is seen from both
    /// of its bodies, hence the halving.
    fn touching_count(&self) -> usize {
        let mut world = self.world.borrow_mut();
        let mut ends = 0usize;
        for &(id, _) in self.all_bodies() {
            if let Ok(body) = world.body(id) {
                ends += body.contact_data().map_or(0, |c| c.len());
            }
        }
        ends / 2
    }

    /// `b2World_GetProfile` (ms) of the last step:
    ///
    /// | stage       | b2Profile                                  |
    /// |-------------|--------------------------------------------|
    /// | pairs       | `pairs` (b2UpdateBroadPhasePairs)          |
    /// | collide     | `collide`                                  |
    /// | setup       | `solverSetup`                              |
    /// | prepare     | `prepareConstraints`                       |
    /// | integrate   | `integrateVelocities + integratePositions` |
    /// | warm start  | `warmStart`                                |
    /// | solve       | `solveImpulses`                            |
    /// | relax       | `relaxImpulses`                            |
    /// | restitution | `applyRestitution`                         |
    /// | store       | `storeImpulses`                            |
    /// | finalize    | `transforms + refit + bullets` (finalize bodies, enlarge proxies, continuous) |
    /// | sleep       | `splitIslands + sleepIslands`              |
    /// | step        | `step`                                     |
    ///
    /// `jointEvents`, `hitEvents`, `sensorHits` and `sensors` have no stage
    /// of their own (they stay in `step`); `solve` and `constraints` are
    /// totals of the stages above.
    fn stage_times(&self) -> StageTimes {
        let Ok(p) = self.world.borrow().profile() else {
            return StageTimes::default();
        };
        let ms = |x: f32| Some(f64::from(x));
        StageTimes {
            pairs: ms(p.pairs),
            collide: ms(p.collide),
            setup: ms(p.solver_setup),
            prepare: ms(p.prepare_constraints),
            integrate: ms(p.integrate_velocities + p.integrate_positions),
            warm_start: ms(p.warm_start),
            solve: ms(p.solve_impulses),
            relax: ms(p.relax_impulses),
            restitution: ms(p.apply_restitution),
            store: ms(p.store_impulses),
            finalize: ms(p.transforms + p.refit + p.bullets),
            sleep: ms(p.split_islands + p.sleep_islands),
            step: f64::from(p.step),
        }
    }
}
