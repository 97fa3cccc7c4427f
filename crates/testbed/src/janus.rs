//! The janus2d adapter: builds a [`SceneDesc`] into a [`World`] and runs it
//! behind the [`Engine`] interface.
//!
//! | description            | janus2d                                      |
//! |------------------------|----------------------------------------------|
//! | `Geometry::Box`        | `Polygon::make_offset_box` / `make_rounded_box` |
//! | `Geometry::Hull`       | `Polygon::from_hull`                         |
//! | `Geometry::ChainLoop`  | `make_chain(points, true)`: one-sided segments |
//! | `FilterDesc`           | `Filter` (same bits and group rule)          |
//! | `BodyDesc::mass`       | `BodyDef::with_mass`                         |
//! | `sleep_threshold`      | `BodyDef::sleep_threshold`                   |
//! | `hit_events`           | `ShapeDef::enable_hit_events`                |
//! | `Action::Target`       | velocity = (target − current) / dt           |
//! | `JointDesc::Revolute`  | `RevoluteJointDef` (as `joints`)             |
//! | `JointDesc::Weld`      | `WeldJointDef::from_base` (frames as given) `.with_stiffness` |
//! | `JointDesc::Prismatic` | `PrismaticJointDef::from_base` (frame a's x axis: the slide axis) `.with_limits`, `.with_motor`, `.with_spring`, `.with_target_translation` |
//! | `JointDesc::Wheel`     | `WheelJointDef::from_base`, `enable_spring` = `spring.is_some()` (no spring: a free axis; janus2d's default is on), `.with_limits`, `.with_motor` |
//! | `JointDesc::Distance`  | `DistanceJointDef::from_base(length)` `.with_limits`, `.with_spring`, `.with_spring_force_range`, `.with_motor` |
//! | `JointDesc::Motor`     | `MotorJointDef::from_base` `.with_offset`, `.with_max_force`, `.with_max_torque`, `.with_correction_factor` |
//! | `JointDesc::Mouse`     | `MouseJointDef::from_base(target, max_force)` `.with_spring` (angular damping at its default) |
//! | `JointDesc::Filter`    | `FilterJointDef::from_base` |

use std::collections::BTreeMap;

use glam::DVec2;
use janus2d_constraints::{
    DistanceJointDef, FilterJointDef, JointDef, JointDefBase, JointFrame, MotorJointDef,
    MouseJointDef, PrismaticJointDef, RevoluteJointDef, WeldJointDef, WheelJointDef,
};
use janus2d_core::body::{BodyDef, BodyHandle, BodyType};
use janus2d_core::geometry::{Capsule, Circle, Polygon, Segment, Shape, make_chain};
use janus2d_core::math::{Real, Vec2, from_f64, to_f64, wrap_angle};
use janus2d_world::{Filter, JointHandle, ShapeDef, World, WorldDef, WorldError};

use crate::desc::*;
use crate::engine::{BodyReading, Engine, EngineOptions, StageTimes};

/// A description vector in janus2d's scalar.
#[must_use]
pub fn vec(p: DVec2) -> Vec2 {
    Vec2::new(p.x as Real, p.y as Real)
}

/// janus2d's world definition for the scene settings.
#[must_use]
pub fn world_def(settings: &Settings) -> WorldDef {
    let mut def = WorldDef {
        gravity: vec(settings.gravity),
        ..WorldDef::default()
    };
    def.sleep.enabled = settings.sleep;
    let s = &mut def.solver;
    s.substeps = settings.substeps;
    s.contact_hertz = settings.contact_hertz as Real;
    s.contact_damping_ratio = settings.contact_damping_ratio as Real;
    s.contact_push_max_velocity = settings.contact_push_max_velocity as Real;
    s.joint_hertz = settings.joint_hertz as Real;
    s.joint_damping_ratio = settings.joint_damping_ratio as Real;
    def
}

/// The janus2d shapes of one geometry (a chain loop gives one segment per
/// edge).
pub fn shapes_of(geometry: &Geometry) -> Result<Vec<Shape>, WorldError> {
    Ok(match geometry {
        Geometry::Circle { center, radius } => {
            vec![Circle::new(vec(*center), *radius as Real)?.into()]
        }
        Geometry::Capsule { a, b, radius } => {
            vec![Capsule::new(vec(*a), vec(*b), *radius as Real)?.into()]
        }
        Geometry::Box {
            half,
            center,
            angle,
            radius,
        } => {
            if *radius > 0.0 && (*center != DVec2::ZERO || *angle != 0.0) {
                // No offset rounded box in the API: the hull of the turned core.
                let core = Polygon::make_offset_box(
                    half.x as Real,
                    half.y as Real,
                    vec(*center),
                    *angle as Real,
                );
                vec![Polygon::from_hull(&core.vertices[..core.count], *radius as Real)?.into()]
            } else if *radius > 0.0 {
                vec![
                    Polygon::make_rounded_box(half.x as Real, half.y as Real, *radius as Real)
                        .into(),
                ]
            } else {
                let p = Polygon::make_offset_box(
                    half.x as Real,
                    half.y as Real,
                    vec(*center),
                    *angle as Real,
                );
                vec![p.into()]
            }
        }
        Geometry::Hull { points, radius } => {
            let pts: Vec<Vec2> = points.iter().map(|p| vec(*p)).collect();
            vec![Polygon::from_hull(&pts, *radius as Real)?.into()]
        }
        Geometry::Segment { a, b } => vec![Segment::new(vec(*a), vec(*b))?.into()],
        Geometry::ChainLoop { points } => {
            let pts: Vec<Vec2> = points.iter().map(|p| vec(*p)).collect();
            make_chain(&pts, true)?
                .into_iter()
                .map(Shape::from)
                .collect()
        }
    })
}

/// janus2d's filter for a description's (the same bits and group rule).
#[must_use]
pub fn filter(f: &FilterDesc) -> Filter {
    Filter {
        category_bits: f.category,
        mask_bits: f.mask,
        group_index: f.group,
    }
}

fn shape_def(s: &ShapeDesc) -> ShapeDef {
    ShapeDef {
        density: s.density as Real,
        friction: s.friction as Real,
        restitution: s.restitution as Real,
        filter: filter(&s.filter),
        enable_hit_events: s.hit_events,
        ..ShapeDef::default()
    }
}

/// Creates one body and its shapes.
pub fn create_body(world: &mut World, b: &BodyDesc) -> Result<BodyHandle, WorldError> {
    let mut def = match b.kind {
        BodyKind::Static => BodyDef::fixed(vec(b.position)),
        BodyKind::Kinematic => BodyDef::kinematic(vec(b.position)),
        BodyKind::Dynamic => BodyDef::dynamic(vec(b.position)),
    };
    def.angle = b.angle as Real;
    def.linear_velocity = vec(b.linear_velocity);
    def.angular_velocity = b.angular_velocity as Real;
    def.linear_damping = b.linear_damping as Real;
    def.awake = b.awake;
    def.sleep_threshold = Some(b.sleep_threshold as Real);
    if let Some((m, i)) = b.mass {
        def = def.with_mass(m as Real, i as Real);
    }
    let h = world.create_body(&def)?;
    for s in &b.shapes {
        let sd = shape_def(s);
        for shape in shapes_of(&s.geometry)? {
            world.create_shape(h, &sd, shape)?;
        }
    }
    Ok(h)
}

/// janus2d's definition of a revolute description, bodies from `handles`.
#[must_use]
pub fn revolute_def(j: &RevoluteDesc, handles: &[BodyHandle]) -> RevoluteJointDef {
    let mut def = RevoluteJointDef::new(
        handles[j.body_a],
        handles[j.body_b],
        vec(j.local_a),
        vec(j.local_b),
    );
    def = def
        .with_reference_angle(j.reference_angle as Real)
        .with_collide_connected(j.collide_connected);
    if let Some((lo, hi)) = j.limit {
        def = def.with_limits(lo as Real, hi as Real);
    }
    if let Some((speed, torque)) = j.motor {
        def = def.with_motor(speed as Real, cap(torque));
    }
    if let Some((hz, zeta)) = j.spring {
        def = def.with_spring(hz as Real, zeta as Real);
    }
    def
}

/// Creates one revolute joint between bodies of `handles`.
pub fn create_joint(
    world: &mut World,
    j: &RevoluteDesc,
    handles: &[BodyHandle],
) -> Result<JointHandle, WorldError> {
    world.create_revolute_joint(&revolute_def(j, handles))
}

/// janus2d's frame of a description's.
fn frame(f: &FrameDesc) -> JointFrame {
    JointFrame::new(vec(f.anchor), f.angle as Real)
}

/// janus2d's shared joint definition of a description's, bodies from
/// `handles`.
fn base_def(b: &JointBaseDesc, handles: &[BodyHandle]) -> JointDefBase {
    let mut base = JointDefBase::new(handles[b.body_a], handles[b.body_b]);
    base.local_frame_a = frame(&b.frame_a);
    base.local_frame_b = frame(&b.frame_b);
    base.collide_connected = b.collide_connected;
    base
}

/// A force or torque cap of a description (N or N·m, possibly `f64::MAX`)
/// in janus2d's scalar, clamped to its largest finite value.
fn cap(x: f64) -> Real {
    from_f64(x.min(to_f64(Real::MAX)))
}

/// janus2d's definition of a joint description of any kind but the
/// revolute's own fields (see [`create_joint`]), bodies from `handles`.
#[must_use]
pub fn joint_def(j: &JointDesc, handles: &[BodyHandle]) -> JointDef {
    match j {
        JointDesc::Revolute(r) => revolute_def(r, handles).into(),
        JointDesc::Weld(w) => WeldJointDef::from_base(base_def(&w.base, handles))
            .with_stiffness(
                w.linear_hertz as Real,
                w.linear_damping_ratio as Real,
                w.angular_hertz as Real,
                w.angular_damping_ratio as Real,
            )
            .into(),
        JointDesc::Prismatic(p) => {
            let mut def = PrismaticJointDef::from_base(base_def(&p.base, handles))
                .with_target_translation(p.target_translation as Real);
            if let Some((lo, hi)) = p.limit {
                def = def.with_limits(lo as Real, hi as Real);
            }
            if let Some((speed, force)) = p.motor {
                def = def.with_motor(speed as Real, cap(force));
            }
            if let Some((hz, zeta)) = p.spring {
                def = def.with_spring(hz as Real, zeta as Real);
            }
            def.into()
        }
        JointDesc::Wheel(w) => {
            let mut def = WheelJointDef::from_base(base_def(&w.base, handles));
            def.enable_spring = false;
            if let Some((hz, zeta)) = w.spring {
                def = def.with_spring(hz as Real, zeta as Real);
            }
            if let Some((lo, hi)) = w.limit {
                def = def.with_limits(lo as Real, hi as Real);
            }
            if let Some((speed, torque)) = w.motor {
                def = def.with_motor(speed as Real, cap(torque));
            }
            def.into()
        }
        JointDesc::Distance(d) => {
            // The description's unbounded range is (f64::MIN, f64::MAX):
            // the definition's is ±∞ (in f32 the casts round there anyway).
            let bound = |x: f64| {
                if x >= f64::MAX {
                    Real::INFINITY
                } else if x <= f64::MIN {
                    Real::NEG_INFINITY
                } else {
                    x as Real
                }
            };
            let (lower, upper) = d.spring_force;
            let mut def = DistanceJointDef::from_base(base_def(&d.base, handles), d.length as Real)
                .with_spring_force_range(bound(lower), bound(upper));
            if let Some((lo, hi)) = d.limit {
                def = def.with_limits(lo as Real, hi as Real);
            }
            if let Some((hz, zeta)) = d.spring {
                def = def.with_spring(hz as Real, zeta as Real);
            }
            if let Some((speed, force)) = d.motor {
                def = def.with_motor(speed as Real, cap(force));
            }
            def.into()
        }
        JointDesc::Motor(m) => MotorJointDef::from_base(base_def(&m.base, handles))
            .with_offset(vec(m.linear_offset), m.angular_offset as Real)
            .with_max_force(cap(m.max_force))
            .with_max_torque(cap(m.max_torque))
            .with_correction_factor(m.correction_factor as Real)
            .into(),
        JointDesc::Mouse(m) => {
            MouseJointDef::from_base(base_def(&m.base, handles), vec(m.target), cap(m.max_force))
                .with_spring(m.hertz as Real, m.damping_ratio as Real)
                .into()
        }
        JointDesc::Filter(f) => FilterJointDef::from_base(base_def(&f.base, handles)).into(),
    }
}

/// Creates one joint of any kind between bodies of `handles` (the world's
/// error for a definition it refuses; nothing is created then).
pub fn create_any_joint(
    world: &mut World,
    j: &JointDesc,
    handles: &[BodyHandle],
) -> Result<JointHandle, WorldError> {
    match j {
        JointDesc::Revolute(r) => create_joint(world, r, handles),
        _ => world.create_joint(&joint_def(j, handles)),
    }
}

/// A scene built in a janus2d world.
pub struct Janus {
    /// The world.
    pub world: World,
    /// Handles of the scene's initial bodies, by index.
    pub bodies: Vec<BodyHandle>,
    /// Handles of the scene's initial joints, by index: `joints`, then
    /// `extra_joints`.
    pub joints: Vec<JointHandle>,
    /// Handles of the scene's portal pairs, by index.
    #[cfg(feature = "portals")]
    pub portals: Vec<janus2d_world::PortalPairHandle>,
    /// Bodies of the live spawned groups.
    groups: BTreeMap<usize, Vec<BodyHandle>>,
    dt: Real,
}

impl Janus {
    /// Builds `desc` into a world made from `def` as given (the caller's
    /// gravity, solver and sleep settings; [`world_def`] gives the scene's).
    pub fn with_def(desc: &SceneDesc, def: WorldDef) -> Result<Janus, WorldError> {
        let mut world = World::new(def)?;
        let mut bodies = Vec::with_capacity(desc.bodies.len());
        for b in &desc.bodies {
            bodies.push(create_body(&mut world, b)?);
        }
        let mut joints = Vec::with_capacity(desc.joints.len());
        for j in &desc.joints {
            joints.push(create_joint(&mut world, j, &bodies)?);
        }
        for j in &desc.extra_joints {
            joints.push(create_any_joint(&mut world, j, &bodies)?);
        }
        #[cfg(feature = "portals")]
        let mut portals = Vec::new();
        #[cfg(feature = "portals")]
        for p in &desc.portals {
            use janus2d_world::{PortalDef, PortalPairDef};
            let portal =
                |(body, anchor, direction, half_width): (usize, DVec2, DVec2, f64)| PortalDef {
                    body: bodies[body],
                    anchor: vec(anchor),
                    direction: vec(direction),
                    half_width: half_width as Real,
                };
            portals.push(
                world.create_portal_pair(&PortalPairDef::new(portal(p.entry), portal(p.exit)))?,
            );
        }
        #[cfg(not(feature = "portals"))]
        if !desc.portals.is_empty() {
            return Err(WorldError::NonFinite("portals need the `portals` feature"));
        }
        Ok(Janus {
            world,
            bodies,
            joints,
            #[cfg(feature = "portals")]
            portals,
            groups: BTreeMap::new(),
            dt: desc.settings.dt as Real,
        })
    }

    /// Builds `desc` with its own settings.
    pub fn new(desc: &SceneDesc) -> Result<Janus, WorldError> {
        Self::with_def(desc, world_def(&desc.settings))
    }

    /// Handle of the scene's probe body.
    #[must_use]
    pub fn probe(&self, desc: &SceneDesc) -> Option<BodyHandle> {
        desc.probe.map(|i| self.bodies[i])
    }

    /// Applies one action; errors are the world's.
    pub fn try_apply(&mut self, action: &Action) -> Result<(), WorldError> {
        match action {
            Action::Spawn { id, bodies, joints } => {
                let mut handles = Vec::with_capacity(bodies.len());
                for b in bodies {
                    handles.push(create_body(&mut self.world, b)?);
                }
                for j in joints {
                    create_joint(&mut self.world, j, &handles)?;
                }
                self.groups.insert(*id, handles);
            }
            Action::Despawn { id } => {
                for h in self.groups.remove(id).unwrap_or_default() {
                    self.world.destroy_body(h)?;
                }
            }
            Action::Target {
                body,
                position,
                angle,
            } => {
                let h = self.bodies[*body];
                let xf = self.world.transform(h)?;
                let v = (vec(*position) - xf.p) / self.dt;
                let w = wrap_angle(*angle as Real - self.world.angle(h)?) / self.dt;
                self.world.set_linear_velocity(h, v)?;
                self.world.set_angular_velocity(h, w)?;
            }
        }
        Ok(())
    }
}

fn state_of(world: &World, h: BodyHandle) -> Option<BodyReading> {
    let p = world.position(h).ok()?;
    let v = world.linear_velocity(h).ok()?;
    Some(BodyReading {
        position: DVec2::new(to_f64(p.x), to_f64(p.y)),
        angle: to_f64(world.angle(h).ok()?),
        linear_velocity: DVec2::new(to_f64(v.x), to_f64(v.y)),
        angular_velocity: to_f64(world.angular_velocity(h).ok()?),
    })
}

impl Engine for Janus {
    const NAME: &'static str = "janus2d";

    fn build(desc: &SceneDesc, _options: EngineOptions) -> Result<Self, String> {
        Janus::new(desc).map_err(|e| format!("{e:?}"))
    }

    fn apply(&mut self, action: &Action) {
        self.try_apply(action).expect("scripted action");
    }

    fn step(&mut self) {
        self.world.step(self.dt).expect("step");
    }

    fn state(&self, body: usize) -> Option<BodyReading> {
        state_of(&self.world, *self.bodies.get(body)?)
    }

    fn dynamic_states(&self, out: &mut Vec<BodyReading>) {
        out.clear();
        for h in self.world.body_handles() {
            if self.world.body_type(h) == Ok(BodyType::Dynamic) {
                out.extend(state_of(&self.world, h));
            }
        }
    }

    fn body_count(&self) -> usize {
        self.world.body_count()
    }

    fn awake_count(&self) -> usize {
        self.world.counters().awake_bodies
    }

    fn touching_count(&self) -> usize {
        self.world.touching_contact_count()
    }

    fn stage_times(&self) -> StageTimes {
        let p = self.world.profile();
        let ms = |s: f64| Some(s * 1e3);
        StageTimes {
            pairs: ms(p.broadphase),
            collide: ms(p.narrowphase + p.portals),
            setup: None,
            prepare: ms(p.solver.prepare),
            integrate: ms(p.solver.integrate),
            warm_start: ms(p.solver.warm_start),
            solve: ms(p.solver.solve),
            relax: ms(p.solver.relax),
            restitution: ms(p.solver.restitution),
            store: None,
            finalize: ms(p.solver.finalize),
            sleep: ms(p.sleep),
            step: p.total * 1e3,
        }
    }
}
