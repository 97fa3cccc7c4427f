//! The Rapier adapter (`rapier2d` 0.36, `f32`): builds a [`SceneDesc`] into
//! Rapier's sets and runs it behind the [`Engine`] interface, with the
//! settings that make Rapier's soft-step solver match Box2D v3's.
//!
//! # Settings
//!
//! | scene setting                     | `IntegrationParameters` (or elsewhere)                      |
//! |-----------------------------------|-------------------------------------------------------------|
//! | `dt`                              | `dt`                                                        |
//! | `substeps`                        | `num_solver_iterations` (one substep each), with `num_internal_pgs_iterations = 1` (biased) and `num_internal_stabilization_iterations = 1` (relax) |
//! | `contact_hertz`, `_damping_ratio` | `contact_softness` (30 Hz, ζ 10); `static_contact_softness` at twice the frequency (60 Hz, ζ 10), as Box2D's static softness |
//! | `contact_push_max_velocity`       | `normalized_max_corrective_velocity` (`length_unit` 1)      |
//! | `joint_hertz`, `_damping_ratio`   | each joint's `softness` (60 Hz, ζ 2); `warmstart_joints = true` |
//! | `gravity`                         | the `gravity` argument of `PhysicsPipeline::step`           |
//! | `sleep == false`                  | every body `can_sleep(false)`                               |
//! | materials                         | friction `GeometricMean`, restitution `Max`                 |
//!
//! # Description items
//!
//! | description                 | Rapier                                                        |
//! |-----------------------------|---------------------------------------------------------------|
//! | `BodyKind::Static`          | `RigidBodyBuilder::fixed`                                     |
//! | `BodyKind::Kinematic`       | `RigidBodyBuilder::kinematic_velocity_based`                  |
//! | `BodyKind::Dynamic`         | `RigidBodyBuilder::dynamic`                                   |
//! | `awake == false`            | `sleeping(true)` (only when the scene has sleep on)           |
//! | `sleep_threshold`           | the body's `activation.normalized_linear_threshold` (Rapier's per-body threshold, also on the farthest-point speed) |
//! | `linear_damping`            | `linear_damping`                                              |
//! | `mass: Some((m, I))`        | `additional_mass_properties(MassProperties::new(origin, m, I))`, shapes of density 0 |
//! | `Geometry::Circle`          | `ball`, offset by the collider's position                     |
//! | `Geometry::Capsule`         | `capsule_from_endpoints`                                      |
//! | `Geometry::Box`             | `cuboid` / `round_cuboid` (core half extents + radius), at the offset and angle |
//! | `Geometry::Hull`            | `convex_hull` / `round_convex_hull`                           |
//! | `Geometry::Segment`         | `segment` (two-sided, as Box2D's)                             |
//! | `Geometry::ChainLoop`       | `oriented_polyline` closed by the last-to-first edge: one-sided, the colliding side right of each edge as in Box2D |
//! | `FilterDesc` category, mask | `InteractionGroups(memberships = category, filter = mask)`, low 32 bits |
//! | `FilterDesc::group`         | a [`PhysicsHooks::filter_contact_pair`] hook on the shapes with a group (the filter packed in the collider's `user_data`) |
//! | `hit_events`                | ignored (the benchmark reads no events)                       |
//! | `RevoluteDesc` anchors      | `RevoluteJointBuilder::local_anchor1/2`                       |
//! | `reference_angle`           | the rotation of the joint's `local_frame1`: Rapier's joint angle is then `θb − θa − reference`, Box2D's |
//! | `limit`                     | `limits([lower, upper])` on that angle                        |
//! | `motor` alone               | a velocity motor: target speed, near-rigid damping, `max_force` = max torque (`f64::MAX` → `f32::MAX`) |
//! | `spring` (with or without a motor) | one acceleration-based position motor to angle 0 with stiffness (2πf)² and damping 2ζ·2πf, unbounded |
//! | `collide_connected == false`| `contacts_enabled(false)`                                     |
//! | `JointDesc` frames          | a `GenericJoint`'s `local_frame1/2` (anchor and angle as given), the scene's joint softness on its locked axes |
//! | `JointDesc::Weld`           | locked `LIN_X`, `LIN_Y`, `ANG_X`; a nonzero hertz frees that part and holds it with an acceleration-based position motor to 0 instead (stiffness (2πf)², damping 2ζ·2πf) |
//! | `JointDesc::Prismatic`      | locked `LIN_Y`, `ANG_X`; `LinX` limits; the spring (target translation) or else the motor on `LinX`, as the revolute's |
//! | `JointDesc::Wheel`          | locked `LIN_Y`; `LinX` limits and spring (position motor to 0); `AngX` velocity motor |
//! | `JointDesc::Motor`, `Mouse`, `Filter` | not built (no peers scene uses them): the scene is refused |
//! | `JointDesc::Distance`       | coupled `LIN_X`, `LIN_Y` (`LinX` is then the distance, as Rapier's rope and spring joints): no spring, limits [length, length]; a spring, a position motor to the length, max force = the larger spring force bound, with the length limits; the motor when there is no spring |
//! | `Action::Target`            | velocity = (target − current) / dt, angular likewise (wrapped) |
//! | `portals`                   | `build` fails: Rapier has no portals                          |
//! | `EngineOptions::threads`    | the step runs in a rayon pool of that many threads, built once in `build` (`parallel` feature; without it, one thread) |
//! | `touching_count`            | contact pairs with at least one solver contact (speculative ones included, as Box2D's manifold points) |
//! | `awake_count`               | non-fixed bodies not sleeping (kinematic ones included)       |
//!
//! # Limitations
//!
//! - **Chains.** Box2D's chain segments ignore contacts from behind; Rapier's
//!   oriented polyline instead clamps every contact normal into the edge's
//!   outward cone, so a body that got behind the loop is pushed back to the
//!   inside rather than let through.
//! - **Filters.** Rapier's groups are 32 bits: category and mask bits above
//!   bit 31 are dropped. Shapes with a positive group get all-pass
//!   interaction groups and leave the whole category/mask/group test to the
//!   hook (Rapier tests its groups before the hook, and a positive group
//!   must override the masks). Pairs with a hooked shape are never
//!   contact-recycled (Rapier's rule for hooks).
//! - **Ragdoll joints.** Box2D's joints carry a spring *and* a friction motor
//!   (speed 0, small max torque) at once; Rapier has one motor per axis. With
//!   a spring the motor is the spring (Box2D's soft constraint in
//!   acceleration form, which is the same bias rate and softness), and the
//!   friction motor is dropped: the spring's damping stands in for it.
//! - **Joint softness.** Rapier keeps a joint's softness in its relax pass
//!   too (only the bias is removed), where Box2D solves joints rigidly: at
//!   60 Hz, ζ 2 Rapier's joints behave as stiff springs under load and open
//!   wider than Box2D's (the hard cases' joint gaps), while Rapier's own
//!   default (1 MHz, ζ 1) is near-rigid in both passes.
//! - **Bodies created asleep.** Rapier makes the contacts of bodies created
//!   asleep at their first step, and a contact that starts wakes both sides:
//!   `smash`'s block wakes at step 1 (and sleeps again after 0.5 s), and it
//!   is then one touching island, which the projectile wakes whole. Box2D
//!   makes no contacts between sleeping bodies.
//! - **Velocities.** [`BodyReading::linear_velocity`] is the centre of mass's
//!   (Rapier's `linvel`), as Box2D's `b2Body_GetLinearVelocity` and the
//!   janus2d adapter report it.
//! - **Stage times.** Rapier's stage timers only run with its `profiler`
//!   feature, which this benchmark does not enable: then only `step` is
//!   reported (timed here around `PhysicsPipeline::step`) and every stage is
//!   `None`. If a build does enable `profiler`, the stages are read from
//!   `PhysicsPipeline::counters` (broad phase → pairs, narrow phase →
//!   collide, islands + sleep + constraint collection + assembly → setup,
//!   velocity resolution with its substep integration, restitution and
//!   writeback → solve, force and position update → integrate).

use std::collections::BTreeMap;
use std::time::Instant;

use janus2d_testbed::desc::{
    Action, BodyDesc, BodyKind, FilterDesc, FrameDesc, Geometry, JointDesc, RevoluteDesc,
    SceneDesc, ShapeDesc, v,
};
use janus2d_testbed::engine::{BodyReading, Engine, EngineOptions, StageTimes};
use rapier2d::prelude::*;

/// A Rapier vector from description components.
fn vec2(x: f64, y: f64) -> Vector {
    Vector::new(x as Real, y as Real)
}

/// A description value in Rapier's scalar, `f64::MAX`-like values clamped to
/// `f32::MAX`.
fn real(x: f64) -> Real {
    x.clamp(-(Real::MAX as f64), Real::MAX as f64) as Real
}

/// `x` wrapped into (−π, π].
fn wrap_angle(x: f64) -> f64 {
    x.sin().atan2(x.cos())
}

/// Damping of a velocity motor: large enough that its softness
/// `1 / (dt · damping)` is negligible, i.e. the motor is rigid up to its max
/// torque, as Box2D's.
const RIGID_MOTOR_DAMPING: Real = 1.0e9;

/// A Box2D filter packed into a collider's `user_data`: category in bits
/// 0–31, mask in bits 32–63, group in bits 64–95.
fn pack_filter(f: &FilterDesc) -> u128 {
    let category = f.category as u32 as u128;
    let mask = f.mask as u32 as u128;
    let group = f.group as u32 as u128;
    category | (mask << 32) | (group << 64)
}

/// The (category, mask, group) packed by [`pack_filter`].
fn unpack_filter(data: u128) -> (u32, u32, i32) {
    (data as u32, (data >> 32) as u32, (data >> 64) as u32 as i32)
}

/// Box2D's group rule as a contact-pair filter: two shapes of the same
/// non-zero group never collide (negative) or always collide (positive);
/// otherwise each one's category must be in the other's mask. Installed only
/// on the colliders whose shape has a group.
#[derive(Clone, Copy, Debug, Default)]
pub struct GroupFilter;

impl PhysicsHooks for GroupFilter {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let c1 = context.colliders.get(context.collider1)?;
        let c2 = context.colliders.get(context.collider2)?;
        let (cat1, mask1, group1) = unpack_filter(c1.user_data);
        let (cat2, mask2, group2) = unpack_filter(c2.user_data);
        let collide = if group1 == group2 && group1 != 0 {
            group1 > 0
        } else {
            cat1 & mask2 != 0 && cat2 & mask1 != 0
        };
        collide.then(SolverFlags::default)
    }
}

/// Rapier's integration parameters for the scene settings (the table in the
/// module documentation).
#[must_use]
pub fn integration_parameters(desc: &SceneDesc) -> IntegrationParameters {
    let s = &desc.settings;
    IntegrationParameters {
        dt: s.dt as Real,
        num_solver_iterations: s.substeps.max(1) as usize,
        num_internal_pgs_iterations: 1,
        num_internal_stabilization_iterations: 1,
        contact_softness: SpringCoefficients::new(
            s.contact_hertz as Real,
            s.contact_damping_ratio as Real,
        ),
        static_contact_softness: SpringCoefficients::new(
            2.0 * s.contact_hertz as Real,
            s.contact_damping_ratio as Real,
        ),
        normalized_max_corrective_velocity: s.contact_push_max_velocity as Real,
        warmstart_joints: true,
        length_unit: 1.0,
        ..IntegrationParameters::default()
    }
}

/// The collider builder of one shape's geometry, in the body frame.
fn collider_of(geometry: &Geometry) -> Result<ColliderBuilder, String> {
    Ok(match geometry {
        Geometry::Circle { center, radius } => {
            ColliderBuilder::ball(*radius as Real).translation(vec2(center.x, center.y))
        }
        Geometry::Capsule { a, b, radius } => {
            ColliderBuilder::capsule_from_endpoints(vec2(a.x, a.y), vec2(b.x, b.y), *radius as Real)
        }
        Geometry::Box {
            half,
            center,
            angle,
            radius,
        } => {
            let builder = if *radius > 0.0 {
                ColliderBuilder::round_cuboid(half.x as Real, half.y as Real, *radius as Real)
            } else {
                ColliderBuilder::cuboid(half.x as Real, half.y as Real)
            };
            builder.position(Pose::new(vec2(center.x, center.y), *angle as Real))
        }
        Geometry::Hull { points, radius } => {
            let pts: Vec<Vector> = points.iter().map(|p| vec2(p.x, p.y)).collect();
            let builder = if *radius > 0.0 {
                ColliderBuilder::round_convex_hull(&pts, *radius as Real)
            } else {
                ColliderBuilder::convex_hull(&pts)
            };
            builder.ok_or_else(|| format!("degenerate hull {points:?}"))?
        }
        Geometry::Segment { a, b } => ColliderBuilder::segment(vec2(a.x, a.y), vec2(b.x, b.y)),
        Geometry::ChainLoop { points } => {
            if points.len() < 3 {
                return Err(format!("a chain loop needs 3 points, got {}", points.len()));
            }
            let n = points.len() as u32;
            let vertices: Vec<Vector> = points.iter().map(|p| vec2(p.x, p.y)).collect();
            let indices: Vec<[u32; 2]> = (0..n).map(|i| [i, (i + 1) % n]).collect();
            ColliderBuilder::oriented_polyline(vertices, Some(indices))
        }
    })
}

/// The collider of one shape (`massless`: density 0, the body's mass is set
/// directly).
fn collider(shape: &ShapeDesc, massless: bool) -> Result<Collider, String> {
    let f = &shape.filter;
    let mut builder = collider_of(&shape.geometry)?
        .density(if massless { 0.0 } else { shape.density as Real })
        .friction(shape.friction as Real)
        .friction_combine_rule(CoefficientCombineRule::GeometricMean)
        .restitution(shape.restitution as Real)
        .restitution_combine_rule(CoefficientCombineRule::Max)
        .user_data(pack_filter(f));
    builder = if f.group > 0 {
        // The hook decides everything (a positive group overrides the masks).
        builder.collision_groups(InteractionGroups::all())
    } else {
        builder.collision_groups(InteractionGroups::new(
            Group::from(f.category as u32),
            Group::from(f.mask as u32),
            InteractionTestMode::And,
        ))
    };
    if f.group != 0 {
        builder = builder.active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS);
    }
    Ok(builder.build())
}

/// The revolute joint of a description (body a is Rapier's body 1).
fn revolute(j: &RevoluteDesc, softness: SpringCoefficients<Real>) -> RevoluteJoint {
    let mut builder = RevoluteJointBuilder::new()
        .local_anchor1(vec2(j.local_a.x, j.local_a.y))
        .local_anchor2(vec2(j.local_b.x, j.local_b.y))
        .contacts_enabled(j.collide_connected)
        .softness(softness);
    if let Some((lower, upper)) = j.limit {
        builder = builder.limits([lower as Real, upper as Real]);
    }
    match (j.spring, j.motor) {
        (Some((hertz, zeta)), _) => {
            // Box2D's soft spring in acceleration form: k = ω², c = 2ζω.
            let omega = 2.0 * std::f64::consts::PI * hertz;
            builder = builder
                .motor_model(MotorModel::AccelerationBased)
                .motor_position(0.0, real(omega * omega), real(2.0 * zeta * omega))
                .motor_max_force(Real::MAX);
        }
        (None, Some((speed, max_torque))) => {
            builder = builder
                .motor_model(MotorModel::AccelerationBased)
                .motor_velocity(speed as Real, RIGID_MOTOR_DAMPING)
                .motor_max_force(real(max_torque));
        }
        (None, None) => {}
    }
    let mut joint = builder.build();
    // Rapier's joint angle is that of frame 2 relative to frame 1: turning
    // frame 1 by the reference angle makes it Box2D's θb − θa − reference.
    joint.data.local_frame1.rotation = Rotation::new(j.reference_angle as Real);
    joint
}

/// An acceleration-based position motor to `target` on `axis` with Box2D's
/// soft spring (k = ω², c = 2ζω, ω = 2πf).
fn spring_motor(
    builder: GenericJointBuilder,
    axis: JointAxis,
    target: f64,
    (hertz, zeta): (f64, f64),
    max_force: f64,
) -> GenericJointBuilder {
    let omega = 2.0 * std::f64::consts::PI * hertz;
    builder
        .motor_model(axis, MotorModel::AccelerationBased)
        .motor_position(
            axis,
            real(target),
            real(omega * omega),
            real(2.0 * zeta * omega),
        )
        .motor_max_force(axis, real(max_force))
}

/// A rigid velocity motor on `axis` up to `max_force`, as the revolute's.
fn velocity_motor(
    builder: GenericJointBuilder,
    axis: JointAxis,
    (speed, max_force): (f64, f64),
) -> GenericJointBuilder {
    builder
        .motor_model(axis, MotorModel::AccelerationBased)
        .motor_velocity(axis, speed as Real, RIGID_MOTOR_DAMPING)
        .motor_max_force(axis, real(max_force))
}

/// The generic joint of a non-revolute description (body a is Rapier's
/// body 1): frames as given, the table in the module documentation.
fn generic(j: &JointDesc, softness: SpringCoefficients<Real>) -> Option<GenericJoint> {
    let base = j.base()?;
    let pose = |f: &FrameDesc| Pose::new(vec2(f.anchor.x, f.anchor.y), f.angle as Real);
    let start = |locked: JointAxesMask| {
        GenericJointBuilder::new(locked)
            .local_frame1(pose(&base.frame_a))
            .local_frame2(pose(&base.frame_b))
            .contacts_enabled(base.collide_connected)
            .softness(softness)
    };
    let limit = |b: GenericJointBuilder, axis, limit: Option<(f64, f64)>| match limit {
        Some((lo, hi)) => b.limits(axis, [lo as Real, hi as Real]),
        None => b,
    };
    Some(match j {
        JointDesc::Revolute(_)
        | JointDesc::Motor(_)
        | JointDesc::Mouse(_)
        | JointDesc::Filter(_) => return None,
        JointDesc::Weld(w) => {
            let mut locked = JointAxesMask::empty();
            if w.linear_hertz == 0.0 {
                locked |= JointAxesMask::LIN_AXES;
            }
            if w.angular_hertz == 0.0 {
                locked |= JointAxesMask::ANG_X;
            }
            let mut b = start(locked);
            if w.linear_hertz > 0.0 {
                let spring = (w.linear_hertz, w.linear_damping_ratio);
                for axis in [JointAxis::LinX, JointAxis::LinY] {
                    b = spring_motor(b, axis, 0.0, spring, f64::MAX);
                }
            }
            if w.angular_hertz > 0.0 {
                let spring = (w.angular_hertz, w.angular_damping_ratio);
                b = spring_motor(b, JointAxis::AngX, 0.0, spring, f64::MAX);
            }
            b.build()
        }
        JointDesc::Prismatic(p) => {
            let mut b = start(JointAxesMask::LIN_Y | JointAxesMask::ANG_X);
            b = limit(b, JointAxis::LinX, p.limit);
            match (p.spring, p.motor) {
                (Some(spring), _) => {
                    b = spring_motor(b, JointAxis::LinX, p.target_translation, spring, f64::MAX)
                }
                (None, Some(motor)) => b = velocity_motor(b, JointAxis::LinX, motor),
                (None, None) => {}
            }
            b.build()
        }
        JointDesc::Wheel(w) => {
            let mut b = limit(start(JointAxesMask::LIN_Y), JointAxis::LinX, w.limit);
            if let Some(spring) = w.spring {
                b = spring_motor(b, JointAxis::LinX, 0.0, spring, f64::MAX);
            }
            if let Some(motor) = w.motor {
                b = velocity_motor(b, JointAxis::AngX, motor);
            }
            b.build()
        }
        JointDesc::Distance(d) => {
            let mut b = start(JointAxesMask::empty()).coupled_axes(JointAxesMask::LIN_AXES);
            match (d.spring, d.motor) {
                (None, _) => b = b.limits(JointAxis::LinX, [d.length as Real; 2]),
                (Some(spring), _) => {
                    let max_force = d.spring_force.0.abs().max(d.spring_force.1.abs());
                    b = limit(b, JointAxis::LinX, d.limit);
                    b = spring_motor(b, JointAxis::LinX, d.length, spring, max_force);
                }
            }
            if let (None, Some(motor)) = (d.spring, d.motor) {
                b = velocity_motor(b, JointAxis::LinX, motor);
            }
            b.build()
        }
    })
}

/// A scene built in Rapier's sets.
pub struct Rapier {
    pipeline: PhysicsPipeline,
    params: IntegrationParameters,
    gravity: Vector,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    hooks: GroupFilter,
    /// Handles of the scene's initial bodies, by index.
    initial: Vec<RigidBodyHandle>,
    /// Bodies of the live spawned groups.
    groups: BTreeMap<usize, Vec<RigidBodyHandle>>,
    joint_softness: SpringCoefficients<Real>,
    sleep: bool,
    dt: f64,
    last_step_ms: f64,
    #[cfg(feature = "parallel")]
    pool: rapier2d::rayon::ThreadPool,
}

impl Rapier {
    /// Creates one body and its colliders.
    fn create_body(&mut self, b: &BodyDesc) -> Result<RigidBodyHandle, String> {
        let builder = match b.kind {
            BodyKind::Static => RigidBodyBuilder::fixed(),
            BodyKind::Kinematic => RigidBodyBuilder::kinematic_velocity_based(),
            BodyKind::Dynamic => RigidBodyBuilder::dynamic(),
        };
        let mut builder = builder
            .translation(vec2(b.position.x, b.position.y))
            .rotation(b.angle as Real)
            .linvel(vec2(b.linear_velocity.x, b.linear_velocity.y))
            .angvel(b.angular_velocity as Real)
            .linear_damping(b.linear_damping as Real)
            .can_sleep(self.sleep)
            .sleeping(self.sleep && !b.awake);
        if let Some((mass, inertia)) = b.mass {
            builder = builder.additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                mass as Real,
                inertia as Real,
            ));
        }
        let mut body = builder.build();
        if self.sleep {
            body.activation_mut().normalized_linear_threshold = b.sleep_threshold as Real;
        }
        let handle = self.bodies.insert(body);
        for s in &b.shapes {
            let c = collider(s, b.mass.is_some())?;
            self.colliders
                .insert_with_parent(c, handle, &mut self.bodies);
        }
        Ok(handle)
    }

    /// Creates one joint between bodies of `handles`.
    fn create_joint(
        &mut self,
        j: &RevoluteDesc,
        handles: &[RigidBodyHandle],
    ) -> Result<(), String> {
        let (Some(&a), Some(&b)) = (handles.get(j.body_a), handles.get(j.body_b)) else {
            return Err(format!(
                "joint between missing bodies {} and {}",
                j.body_a, j.body_b
            ));
        };
        self.impulse_joints
            .insert(a, b, revolute(j, self.joint_softness), true);
        Ok(())
    }

    /// Creates one joint of any kind between bodies of `handles`.
    fn create_any_joint(
        &mut self,
        j: &JointDesc,
        handles: &[RigidBodyHandle],
    ) -> Result<(), String> {
        let joint = match j {
            JointDesc::Revolute(r) => return self.create_joint(r, handles),
            other => generic(other, self.joint_softness)
                .ok_or_else(|| format!("no generic joint for a {}", other.kind_name()))?,
        };
        let (a, b) = j.bodies();
        let (Some(&a), Some(&b)) = (handles.get(a), handles.get(b)) else {
            return Err(format!("joint between missing bodies {a} and {b}"));
        };
        self.impulse_joints.insert(a, b, joint, true);
        Ok(())
    }

    /// Applies one action; errors are the description's.
    pub fn try_apply(&mut self, action: &Action) -> Result<(), String> {
        match action {
            Action::Spawn { id, bodies, joints } => {
                let mut handles = Vec::with_capacity(bodies.len());
                for b in bodies {
                    handles.push(self.create_body(b)?);
                }
                for j in joints {
                    self.create_joint(j, &handles)?;
                }
                self.groups.insert(*id, handles);
            }
            Action::Despawn { id } => {
                for h in self.groups.remove(id).unwrap_or_default() {
                    self.bodies.remove(
                        h,
                        &mut self.islands,
                        &mut self.colliders,
                        &mut self.impulse_joints,
                        &mut self.multibody_joints,
                        &mut self.soft_bodies,
                        true,
                    );
                }
            }
            Action::Target {
                body,
                position,
                angle,
            } => {
                let h = *self
                    .initial
                    .get(*body)
                    .ok_or_else(|| format!("no body {body}"))?;
                let rb = self
                    .bodies
                    .get_mut(h)
                    .ok_or_else(|| format!("body {body} is gone"))?;
                let p = rb.translation();
                let linvel = vec2(
                    (position.x - p.x as f64) / self.dt,
                    (position.y - p.y as f64) / self.dt,
                );
                let turn = wrap_angle(*angle - rb.rotation().angle() as f64);
                rb.set_linvel(linvel, true);
                rb.set_angvel((turn / self.dt) as Real, true);
            }
        }
        Ok(())
    }

    /// Rapier's own stage times of the last step, if its `profiler` feature
    /// made its timers run.
    fn counter_stages(&self, step: f64) -> StageTimes {
        let c = &self.pipeline.counters;
        if c.step_time_ms() <= 0.0 {
            return StageTimes {
                step,
                ..StageTimes::default()
            };
        }
        StageTimes {
            pairs: Some(c.cd.broad_phase_time.time_ms() + c.cd.final_broad_phase_time.time_ms()),
            collide: Some(c.cd.narrow_phase_time.time_ms()),
            setup: Some(
                c.stages.island_construction_time.time_ms()
                    + c.stages.island_constraints_collection_time.time_ms()
                    + c.solver.velocity_assembly_time.time_ms(),
            ),
            integrate: Some(c.stages.update_time.time_ms()),
            solve: Some(c.solver.velocity_resolution_time.time_ms()),
            step,
            ..StageTimes::default()
        }
    }
}

fn state_of(rb: &RigidBody) -> BodyReading {
    let p = rb.translation();
    let w = rb.linvel();
    BodyReading {
        position: v(p.x as f64, p.y as f64),
        angle: rb.rotation().angle() as f64,
        linear_velocity: v(w.x as f64, w.y as f64),
        angular_velocity: rb.angvel() as f64,
    }
}

impl Engine for Rapier {
    const NAME: &'static str = "Rapier";

    fn build(desc: &SceneDesc, options: EngineOptions) -> Result<Self, String> {
        if !desc.portals.is_empty() {
            return Err("Rapier has no portals".to_string());
        }
        let s = &desc.settings;
        #[cfg(feature = "parallel")]
        let pool = rapier2d::rayon::ThreadPoolBuilder::new()
            .num_threads(options.threads.max(1))
            .thread_name(|i| format!("rapier-peer-{i}"))
            .build()
            .map_err(|e| format!("rayon pool: {e}"))?;
        #[cfg(not(feature = "parallel"))]
        let _ = options;
        let mut r = Rapier {
            pipeline: PhysicsPipeline::new(),
            params: integration_parameters(desc),
            gravity: vec2(s.gravity.x, s.gravity.y),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
            hooks: GroupFilter,
            initial: Vec::with_capacity(desc.bodies.len()),
            groups: BTreeMap::new(),
            joint_softness: SpringCoefficients::new(
                s.joint_hertz as Real,
                s.joint_damping_ratio as Real,
            ),
            sleep: s.sleep,
            dt: s.dt,
            last_step_ms: 0.0,
            #[cfg(feature = "parallel")]
            pool,
        };
        for b in &desc.bodies {
            let h = r.create_body(b)?;
            r.initial.push(h);
        }
        let initial = r.initial.clone();
        for j in &desc.joints {
            r.create_joint(j, &initial)?;
        }
        for j in &desc.extra_joints {
            r.create_any_joint(j, &initial)?;
        }
        Ok(r)
    }

    fn apply(&mut self, action: &Action) {
        if let Err(e) = self.try_apply(action) {
            panic!("scripted action: {e}");
        }
    }

    fn step(&mut self) {
        let Rapier {
            pipeline,
            params,
            gravity,
            islands,
            broad_phase,
            narrow_phase,
            bodies,
            colliders,
            impulse_joints,
            multibody_joints,
            soft_bodies,
            ccd,
            hooks,
            ..
        } = self;
        // FnMut: called in place on one thread, moved into the pool otherwise.
        #[cfg_attr(feature = "parallel", allow(unused_mut))]
        let mut run = || {
            pipeline.step(
                *gravity,
                params,
                islands,
                broad_phase,
                narrow_phase,
                bodies,
                colliders,
                impulse_joints,
                multibody_joints,
                soft_bodies,
                ccd,
                &*hooks,
                &(),
            );
        };
        let start = Instant::now();
        #[cfg(feature = "parallel")]
        self.pool.install(run);
        #[cfg(not(feature = "parallel"))]
        run();
        self.last_step_ms = start.elapsed().as_secs_f64() * 1e3;
    }

    fn state(&self, body: usize) -> Option<BodyReading> {
        self.bodies.get(*self.initial.get(body)?).map(state_of)
    }

    fn dynamic_states(&self, out: &mut Vec<BodyReading>) {
        out.clear();
        out.extend(
            self.bodies
                .iter()
                .filter(|(_, rb)| rb.is_dynamic())
                .map(|(_, rb)| state_of(rb)),
        );
    }

    fn body_count(&self) -> usize {
        self.bodies.len()
    }

    fn awake_count(&self) -> usize {
        self.bodies
            .iter()
            .filter(|(_, rb)| !rb.is_fixed() && !rb.is_sleeping())
            .count()
    }

    fn touching_count(&self) -> usize {
        self.narrow_phase
            .contact_pairs()
            .filter(|pair| pair.has_any_active_contact())
            .count()
    }

    fn stage_times(&self) -> StageTimes {
        self.counter_stages(self.last_step_ms)
    }
}
