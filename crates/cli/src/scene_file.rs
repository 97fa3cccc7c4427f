//! Scene files: a world described in JSON — settings, bodies with their
//! shapes, joints of every kind and portal pairs — read with `serde` into
//! the description structs below and built into a [`World`] through the
//! engine's definition structs (`BodyDef`, `ShapeDef`, the shapes, each
//! joint kind's definition on a `JointDefBase`, `PortalPairDef`).
//!
//! ```json
//! {
//!   "name": "hinge",
//!   "steps": 120,
//!   "settings": { "gravity": [0, -10], "substeps": 4 },
//!   "bodies": [
//!     { "id": "ground", "type": "static",
//!       "shapes": [ { "geometry": { "box": { "half": [10, 0.5] } } } ] },
//!     { "id": "bar", "position": [1, 2],
//!       "shapes": [ { "geometry": { "box": { "half": [1, 0.1] } }, "density": 2 } ] }
//!   ],
//!   "joints": [
//!     { "body_a": "ground", "body_b": "bar", "anchor": [0, 2] },
//!     { "type": "prismatic", "body_a": "ground", "body_b": "bar", "anchor": [1, 2],
//!       "axis": 1.5708, "limit": [0, 3], "motor": { "speed": 1, "max_force": 500 } }
//!   ]
//! }
//! ```
//!
//! | key | what | default |
//! |-----|------|---------|
//! | `name`, `steps`, `probe` | label; steps `janus2d run` takes; the body the summary reports | file name, 600, none |
//! | `settings` | `gravity` [x, y] m/s², `dt` s, `substeps`, `relax_iterations`, `sleep`, `contact_hertz`, `contact_damping_ratio`, `contact_push_max_velocity` m/s, `joint_hertz`, `joint_damping_ratio`, `restitution_threshold` m/s, `warm_starting` | the world's defaults, dt 1/60 |
//! | body | `id`, `type` (`static`, `kinematic`, `dynamic`), `position`, `angle`, `linear_velocity`, `angular_velocity`, `linear_damping`, `angular_damping`, `gravity_scale`, `fixed_rotation`, `motion_locks` {`x`, `y`, `rotation`}, `enabled`, `awake`, `move_events`, `mass` {`mass`, `inertia`, `center`}, `shapes`, `chains` | dynamic at the origin, nothing locked, enabled, mass from the shapes, move events on, no chains |
//! | shape | `geometry` (one of below), `offset` {`position`, `angle`} (where the geometry sits in the body frame), `density`, `friction`, `restitution`, `sensor`, `filter` {`category`, `mask`, `group`}, `rolling_resistance`, `tangent_speed` m/s, `friction_combine` and `restitution_combine` (`default`, `average`, `min`, `multiply`, `max`), `material` (user material id), `hit_events`, `contact_events`, `sensor_events`, `force_event_threshold` N | no offset, 1, 0.6, 0, false, collides with all, 0, 0, `default`, `default`, 0, false, true, true, none (never) |
//! | chain | a chain object on its body (`World::create_chain`): `points` (body frame), `loop`, `materials` (one for every segment, or one per segment: {`friction`, `restitution`, `rolling_resistance`, `tangent_speed`, `friction_combine`, `restitution_combine`, `material`}), `filter`, `user_data`, `hit_events`, `contact_events`, `sensor_events` | open, one default material, collides with all, 0, false, true, true |
//! | geometry | `circle` {`center`, `radius`}, `capsule` {`a`, `b`, `radius`}, `box` {`half`, `center`, `angle`, `radius`}, `polygon` {`points`, `radius`} (convex hull), `segment` {`a`, `b`}, `chain` {`points`, `closed`} (one-sided) | |
//! | joint | `type` (below), `body_a`, `body_b` (index or id), `anchor` (a world point at creation) or `anchor_a`/`anchor_b` (body frames; motor and filter joints may leave both out: the bodies' origins), `angle_a`/`angle_b` (the frames' angles in the body frames, rad), `collide_connected`, `force_threshold` N and `torque_threshold` N·m (joint events), `constraint_hertz`/`constraint_damping_ratio` (softness of the rigid rows), `user_data`, `draw_scale` | `revolute`; frames at angle 0; not colliding; thresholds ∞; the world's joint softness; 0; 1 |
//! | `revolute` | `reference_angle` (rad: θ_b − θ_a at angle 0), `limit` [lower, upper] rad, `motor` {`speed` rad/s, `max_torque` N·m}, `spring` {`hertz`, `damping_ratio`}, `target_angle` rad | a plain hinge |
//! | `prismatic` | `axis` (world angle at creation, rad: the slide axis; or frame a's `angle_a`), `limit` [lower, upper] m, `motor` {`speed` m/s, `max_force` N}, `spring` {`hertz`, `damping_ratio`}, `target_translation` m | a free slide along x, angle held |
//! | `weld` | `reference_angle`, `linear_spring` and `angular_spring` {`hertz`, `damping_ratio`} | rigid |
//! | `distance` | `length` m, `limit` [min, max] m, `spring` {`hertz`, `damping_ratio`} (a rope: `spring` at 0 Hz with `limit` [0, max]), `spring_force` [lower, upper] N (tension negative), `motor` {`speed` m/s, `max_force` N} | a rigid rod at the anchors' distance |
//! | `wheel` | `axis` (the suspension axis, world angle), `spring` {`hertz`, `damping_ratio`}, `limit` [lower, upper] m, `motor` {`speed` rad/s, `max_torque` N·m} | no spring (a free axis), no limits, no motor |
//! | `motor` | `linear_offset` [x, y] m (in a's joint frame), `angular_offset` rad, `max_force` N, `max_torque` N·m, `correction_factor` [0, 1] | offsets 0, 1 N, 1 N·m, 0.3 |
//! | `mouse` | `target` [x, y] m (world), `max_force` N (required), `spring` {`hertz`, `damping_ratio`} (the pull), `angular_spring` (angular damping) | target at `anchor`, 5 Hz / ζ 0.7, 0.5 Hz / ζ 0.1 |
//! | `filter` | none: the two bodies only stop colliding | |
//! | portal pair | `a`, `b`: {`body`, `anchor`, `direction`, `half_width`}; `eta`, `mass_model` (`same_material`, `energy_preserving`) | η = w_b / w_a |
//!
//! Unknown keys are errors, and so is a key the joint's `type` does not use
//! (`limit` on a weld). A file that does not parse or does not build
//! gives a [`SceneFileError`] naming the line, the column and the field
//! (`bodies[1].shapes[0].density`).

use std::fmt;

use glam::DVec2;
use janus2d_constraints::{
    DistanceJointDef, FilterJointDef, JointDef, JointDefBase, JointFrame, MotorJointDef,
    MouseJointDef, PrismaticJointDef, RevoluteJointDef, WeldJointDef, WheelJointDef,
};
use janus2d_core::body::{BodyDef, BodyHandle, BodyMass, BodyType, MotionLocks};
use janus2d_core::geometry::{Shape, make_chain};
use janus2d_core::math::{Real, Vec2, from_f64, to_f64};
use janus2d_testbed::desc::{self, Geometry, SceneDesc};
use janus2d_world::{ChainDef, Filter, ShapeDef, SurfaceMaterial, World, WorldDef};
use serde::{Deserialize, Serialize};

/// A whole scene file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// A label.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// Steps `janus2d run` takes by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    /// World settings.
    #[serde(default)]
    pub settings: SettingsFile,
    /// Bodies, in creation order.
    #[serde(default)]
    pub bodies: Vec<BodyFile>,
    /// Joints of any kind, created in order after the bodies.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointFile>,
    /// Portal pairs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub portals: Vec<PortalPairFile>,
    /// The body the summary reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<BodyRef>,
}

/// World settings (every key optional).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SettingsFile {
    /// Gravity, m/s².
    pub gravity: [f64; 2],
    /// Step, s.
    pub dt: f64,
    /// Substeps per step.
    pub substeps: u32,
    /// Relax iterations per substep.
    pub relax_iterations: u32,
    /// Sleeping on.
    pub sleep: bool,
    /// Contact stiffness, Hz.
    pub contact_hertz: f64,
    /// Contact damping ratio.
    pub contact_damping_ratio: f64,
    /// Contact push-out speed cap, m/s.
    pub contact_push_max_velocity: f64,
    /// Joint stiffness, Hz.
    pub joint_hertz: f64,
    /// Joint damping ratio.
    pub joint_damping_ratio: f64,
    /// Restitution threshold, m/s.
    pub restitution_threshold: f64,
    /// Warm starting on.
    pub warm_starting: bool,
}

impl Default for SettingsFile {
    /// The world's defaults ([`WorldDef::default`]) and a 1/60 s step.
    fn default() -> Self {
        let w = WorldDef::default();
        let s = &w.solver;
        SettingsFile {
            gravity: [to_f64(w.gravity.x), to_f64(w.gravity.y)],
            dt: 1.0 / 60.0,
            substeps: s.substeps,
            relax_iterations: s.relax_iterations,
            sleep: w.sleep.enabled,
            contact_hertz: to_f64(s.contact_hertz),
            contact_damping_ratio: to_f64(s.contact_damping_ratio),
            contact_push_max_velocity: to_f64(s.contact_push_max_velocity),
            joint_hertz: to_f64(s.joint_hertz),
            joint_damping_ratio: to_f64(s.joint_damping_ratio),
            restitution_threshold: to_f64(s.restitution_threshold),
            warm_starting: s.warm_starting,
        }
    }
}

/// Static, kinematic or dynamic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BodyKindFile {
    /// Never moves.
    Static,
    /// Moves by its velocity.
    Kinematic,
    /// Moved by forces and contacts (default).
    #[default]
    Dynamic,
}

/// Mass properties set directly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassFile {
    /// Mass, kg.
    pub mass: f64,
    /// Rotational inertia about the centre of mass, kg·m².
    pub inertia: f64,
    /// Centre of mass in the body frame, m.
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub center: [f64; 2],
}

/// A body and its shapes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyFile {
    /// A name joints, portals and the probe can refer to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub id: Option<String>,
    /// Static, kinematic or dynamic (default).
    #[serde(rename = "type", default)]
    pub kind: BodyKindFile,
    /// Origin, m.
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub position: [f64; 2],
    /// Angle, rad.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angle: f64,
    /// Velocity, m/s.
    #[serde(default, skip_serializing_if = "is_zero2")]
    pub linear_velocity: [f64; 2],
    /// Angular velocity, rad/s.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_velocity: f64,
    /// Linear damping, 1/s.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub linear_damping: f64,
    /// Angular damping, 1/s.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angular_damping: f64,
    /// Gravity scale.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub gravity_scale: f64,
    /// No rotation.
    #[serde(default, skip_serializing_if = "is_false")]
    pub fixed_rotation: bool,
    /// Created awake.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub awake: bool,
    /// Reports move events (`BodyDef::enable_move_events`).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub move_events: bool,
    /// Motion locks (`BodyDef::motion_locks`; default none).
    #[serde(default, skip_serializing_if = "LocksFile::is_none")]
    pub motion_locks: LocksFile,
    /// Enabled (default); `false` builds the body with its shapes and
    /// chains, then disables it (`World::set_body_enabled`).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub enabled: bool,
    /// Mass set directly (otherwise from the shapes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<MassFile>,
    /// Shapes.
    #[serde(default)]
    pub shapes: Vec<ShapeFile>,
    /// Chain objects (`World::create_chain`), created after the shapes.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub chains: Vec<ChainFile>,
}

/// Motion locks by axis (`janus2d_core::body::MotionLocks`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LocksFile {
    /// No motion along world x.
    #[serde(skip_serializing_if = "is_false")]
    pub x: bool,
    /// No motion along world y.
    #[serde(skip_serializing_if = "is_false")]
    pub y: bool,
    /// No rotation.
    #[serde(skip_serializing_if = "is_false")]
    pub rotation: bool,
}

impl LocksFile {
    /// Nothing locked.
    fn is_none(&self) -> bool {
        *self == LocksFile::default()
    }
}

/// Where a shape's geometry sits in its body's frame (`ShapeDef::offset`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OffsetFile {
    /// Translation, m.
    #[serde(skip_serializing_if = "is_zero2")]
    pub position: [f64; 2],
    /// Turn, rad.
    #[serde(skip_serializing_if = "is_zero")]
    pub angle: f64,
}

impl OffsetFile {
    /// The identity.
    fn is_identity(&self) -> bool {
        *self == OffsetFile::default()
    }
}

/// A surface material of a chain segment (`janus2d_world::SurfaceMaterial`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialFile {
    /// Friction.
    #[serde(default = "friction", skip_serializing_if = "is_friction")]
    pub friction: f64,
    /// Restitution.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub restitution: f64,
    /// Rolling resistance.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rolling_resistance: f64,
    /// Surface tangent speed, m/s.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tangent_speed: f64,
    /// Friction combine rule.
    #[serde(default, skip_serializing_if = "is_default_rule")]
    pub friction_combine: CombineFile,
    /// Restitution combine rule.
    #[serde(default, skip_serializing_if = "is_default_rule")]
    pub restitution_combine: CombineFile,
    /// The user's material id.
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub material: u64,
}

impl Default for MaterialFile {
    /// `SurfaceMaterial::default()`'s values.
    fn default() -> Self {
        MaterialFile {
            friction: 0.6,
            restitution: 0.0,
            rolling_resistance: 0.0,
            tangent_speed: 0.0,
            friction_combine: CombineFile::Default,
            restitution_combine: CombineFile::Default,
            material: 0,
        }
    }
}

impl MaterialFile {
    /// The engine's material.
    fn material(&self) -> SurfaceMaterial {
        SurfaceMaterial {
            friction: from_f64(self.friction),
            restitution: from_f64(self.restitution),
            rolling_resistance: from_f64(self.rolling_resistance),
            tangent_speed: from_f64(self.tangent_speed),
            friction_combine: self.friction_combine.rule(),
            restitution_combine: self.restitution_combine.rule(),
            user_material_id: self.material,
        }
    }
}

/// A chain object on a body (`janus2d_world::ChainDef`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChainFile {
    /// Points in the body frame, m.
    pub points: Vec<[f64; 2]>,
    /// A closed loop (the last point joins the first).
    #[serde(rename = "loop", default, skip_serializing_if = "is_false")]
    pub is_loop: bool,
    /// One material for every segment, or one per segment (default: one
    /// default material).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<MaterialFile>,
    /// Collision filter of every segment.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<FilterFile>,
    /// The chain's opaque user value.
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub user_data: u64,
    /// Hit events on the segments.
    #[serde(default, skip_serializing_if = "is_false")]
    pub hit_events: bool,
    /// Contact begin/end events on the segments.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub contact_events: bool,
    /// Sensor events on the segments.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub sensor_events: bool,
}

impl ChainFile {
    /// The engine's chain definition.
    #[must_use]
    pub fn chain_def(&self) -> ChainDef {
        let mut def = ChainDef::new(self.points.iter().map(|p| v2(*p)).collect())
            .with_loop(self.is_loop)
            .with_user_data(self.user_data);
        if !self.materials.is_empty() {
            def = def.with_segment_materials(
                self.materials.iter().map(MaterialFile::material).collect(),
            );
        }
        if let Some(f) = &self.filter {
            def = def.with_filter(f.filter());
        }
        def.enable_hit_events = self.hit_events;
        def.enable_contact_events = self.contact_events;
        def.enable_sensor_events = self.sensor_events;
        def
    }
}

/// A collision filter.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FilterFile {
    /// Categories the shape belongs to.
    pub category: u64,
    /// Categories it collides with.
    pub mask: u64,
    /// Group (positive: always collide, negative: never, 0: none).
    pub group: i32,
}

impl FilterFile {
    /// The engine's filter.
    fn filter(&self) -> Filter {
        Filter {
            category_bits: self.category,
            mask_bits: self.mask,
            group_index: self.group,
        }
    }
}

impl Default for FilterFile {
    fn default() -> Self {
        let f = Filter::default();
        FilterFile {
            category: f.category_bits,
            mask: f.mask_bits,
            group: f.group_index,
        }
    }
}

/// A shape's geometry in its body's frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum GeometryFile {
    /// A disc.
    Circle {
        /// Centre, m.
        #[serde(default)]
        center: [f64; 2],
        /// Radius, m.
        radius: f64,
    },
    /// A capsule.
    Capsule {
        /// First centre, m.
        a: [f64; 2],
        /// Second centre, m.
        b: [f64; 2],
        /// Radius, m.
        radius: f64,
    },
    /// A (possibly offset, turned, rounded) box.
    Box {
        /// Half extents, m.
        half: [f64; 2],
        /// Centre, m.
        #[serde(default, skip_serializing_if = "is_zero2")]
        center: [f64; 2],
        /// Turn, rad.
        #[serde(default, skip_serializing_if = "is_zero")]
        angle: f64,
        /// Rounding radius, m.
        #[serde(default, skip_serializing_if = "is_zero")]
        radius: f64,
    },
    /// The convex hull of 3 to 8 points.
    Polygon {
        /// Points, m.
        points: Vec<[f64; 2]>,
        /// Rounding radius, m.
        #[serde(default, skip_serializing_if = "is_zero")]
        radius: f64,
    },
    /// A two-sided segment.
    Segment {
        /// First end, m.
        a: [f64; 2],
        /// Second end, m.
        b: [f64; 2],
    },
    /// One-sided chain segments through `points` (colliding on the right
    /// of the direction of travel).
    Chain {
        /// Points, m.
        points: Vec<[f64; 2]>,
        /// A closed loop.
        #[serde(default)]
        closed: bool,
    },
}

/// A shape on a body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShapeFile {
    /// Geometry.
    pub geometry: GeometryFile,
    /// Where the geometry sits in the body frame (`ShapeDef::offset`;
    /// default none).
    #[serde(default, skip_serializing_if = "OffsetFile::is_identity")]
    pub offset: OffsetFile,
    /// Density, kg/m².
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub density: f64,
    /// Friction.
    #[serde(default = "friction", skip_serializing_if = "is_friction")]
    pub friction: f64,
    /// Restitution.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub restitution: f64,
    /// A sensor (overlap events only).
    #[serde(default, skip_serializing_if = "is_false")]
    pub sensor: bool,
    /// Collision filter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub filter: Option<FilterFile>,
    /// Rolling resistance (`ShapeDef::rolling_resistance`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rolling_resistance: f64,
    /// Surface tangent speed, m/s (`ShapeDef::tangent_speed`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tangent_speed: f64,
    /// Friction combine rule.
    #[serde(default, skip_serializing_if = "is_default_rule")]
    pub friction_combine: CombineFile,
    /// Restitution combine rule.
    #[serde(default, skip_serializing_if = "is_default_rule")]
    pub restitution_combine: CombineFile,
    /// The user's material id (`ShapeDef::user_material_id`).
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub material: u64,
    /// Hit events (`ShapeDef::enable_hit_events`).
    #[serde(default, skip_serializing_if = "is_false")]
    pub hit_events: bool,
    /// Contact begin/end events (`ShapeDef::enable_contact_events`).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub contact_events: bool,
    /// Sensor events (`ShapeDef::enable_sensor_events`).
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub sensor_events: bool,
    /// Contact force event threshold, N (`ShapeDef::force_event_threshold`;
    /// absent: never).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_event_threshold: Option<f64>,
}

/// A combine rule by name (`janus2d_core::material::CombineRule`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CombineFile {
    /// The property's default rule (friction `√(a b)`, restitution `max`).
    #[default]
    Default,
    /// `(a + b) / 2`.
    Average,
    /// `min(a, b)`.
    Min,
    /// `a · b`.
    Multiply,
    /// `max(a, b)`.
    Max,
}

impl CombineFile {
    /// The engine's rule.
    fn rule(self) -> janus2d_core::material::CombineRule {
        use janus2d_core::material::CombineRule as R;
        match self {
            CombineFile::Default => R::Default,
            CombineFile::Average => R::Average,
            CombineFile::Min => R::Min,
            CombineFile::Multiply => R::Multiply,
            CombineFile::Max => R::Max,
        }
    }
}

fn is_default_rule(x: &CombineFile) -> bool {
    *x == CombineFile::Default
}

/// A body named by its index in `bodies` or by its `id`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum BodyRef {
    /// Index into `bodies`.
    Index(usize),
    /// A body's `id`.
    Id(String),
}

/// A motor: a target speed and the largest torque (angular motors:
/// revolute, wheel) or force (linear motors: prismatic, distance).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorFile {
    /// Target speed, rad/s (angular) or m/s (linear).
    pub speed: f64,
    /// Torque cap, N·m (revolute, wheel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_torque: Option<f64>,
    /// Force cap, N (prismatic, distance).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_force: Option<f64>,
}

/// A spring: stiffness and damping ratio.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpringFile {
    /// Stiffness, Hz.
    pub hertz: f64,
    /// Damping ratio.
    pub damping_ratio: f64,
}

/// The joint types a file can hold (`type`; default `revolute`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JointKindFile {
    /// A hinge.
    #[default]
    Revolute,
    /// A slider along an axis.
    Prismatic,
    /// A weld (rigid or sprung).
    Weld,
    /// A rod, spring or rope between two points.
    Distance,
    /// A wheel on a suspension axis.
    Wheel,
    /// A pose drive of b relative to a.
    Motor,
    /// A pull of a point of b toward a world target.
    Mouse,
    /// No rows: the two bodies only stop colliding.
    Filter,
}

impl JointKindFile {
    /// The name a file spells it with.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            JointKindFile::Revolute => "revolute",
            JointKindFile::Prismatic => "prismatic",
            JointKindFile::Weld => "weld",
            JointKindFile::Distance => "distance",
            JointKindFile::Wheel => "wheel",
            JointKindFile::Motor => "motor",
            JointKindFile::Mouse => "mouse",
            JointKindFile::Filter => "filter",
        }
    }

    /// Whether a motor of this kind is linear (a force cap) rather than
    /// angular (a torque cap).
    fn linear_motor(self) -> bool {
        matches!(self, JointKindFile::Prismatic | JointKindFile::Distance)
    }
}

/// A joint of any kind. The keys every kind shares come first; the others
/// belong to the kinds named in their docs, and a key the joint's kind
/// does not use is an error naming it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointFile {
    /// The joint type (default `revolute`).
    #[serde(rename = "type", default)]
    pub kind: JointKindFile,
    /// Body a.
    pub body_a: BodyRef,
    /// Body b.
    pub body_b: BodyRef,
    /// The anchor as a world point at creation, m (or give both locals;
    /// motor and filter joints may leave both out: the bodies' origins).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<[f64; 2]>,
    /// Anchor in a's frame, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_a: Option<[f64; 2]>,
    /// Anchor in b's frame, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor_b: Option<[f64; 2]>,
    /// Angle of the joint's frame on a, in a's frame, rad (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_a: Option<f64>,
    /// Angle of the joint's frame on b, in b's frame, rad (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_b: Option<f64>,
    /// Prismatic, wheel: the axis as a world angle at creation, rad (both
    /// frames' x axes along it; instead of `angle_a`/`angle_b`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<f64>,
    /// Revolute, weld: `θ_b − θ_a` at joint angle zero, rad (frame a's
    /// angle; instead of `angle_a`/`angle_b`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub reference_angle: f64,
    /// Revolute, prismatic, wheel: [lower, upper] (rad or m); distance:
    /// [min, max] length, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit: Option<[f64; 2]>,
    /// Revolute, prismatic, wheel, distance: a motor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor: Option<MotorFile>,
    /// Revolute (angular), prismatic, wheel (along the axis; none: a free
    /// axis), distance (the length row), mouse (the pull): a spring.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring: Option<SpringFile>,
    /// Revolute: the angle the spring drives toward, rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_angle: Option<f64>,
    /// Prismatic: the translation the spring drives toward, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_translation: Option<f64>,
    /// Weld: the point rows' spring (none: rigid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_spring: Option<SpringFile>,
    /// Weld: the angle row's spring (none: rigid); mouse: the angular
    /// damping row (default 0.5 Hz, ζ 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_spring: Option<SpringFile>,
    /// Distance: rest length, m (default: the anchors' distance at
    /// creation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length: Option<f64>,
    /// Distance: the spring's force range [lower, upper], N (tension
    /// negative; default unbounded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spring_force: Option<[f64; 2]>,
    /// Motor joint: target position of b's anchor in a's joint frame, m
    /// (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_offset: Option<[f64; 2]>,
    /// Motor joint: target joint angle, rad (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_offset: Option<f64>,
    /// Motor joint (default 1), mouse (required): the largest force, N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_force: Option<f64>,
    /// Motor joint: the largest torque, N·m (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_torque: Option<f64>,
    /// Motor joint: the fraction of the pose error closed per substep, in
    /// [0, 1] (default 0.3).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correction_factor: Option<f64>,
    /// Mouse: the world point pulled toward, m (default: the anchor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<[f64; 2]>,
    /// Whether the two bodies collide.
    #[serde(default, skip_serializing_if = "is_false")]
    pub collide_connected: bool,
    /// Force above which the joint reports a joint event, N (default ∞).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_threshold: Option<f64>,
    /// Torque above which the joint reports a joint event, N·m (default ∞).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_threshold: Option<f64>,
    /// Stiffness of the kind's rigid rows, Hz (default 0: the world's
    /// joint softness).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint_hertz: Option<f64>,
    /// Damping ratio of the kind's rigid rows (with `constraint_hertz`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constraint_damping_ratio: Option<f64>,
    /// An opaque value the world keeps for the joint.
    #[serde(default, skip_serializing_if = "is_zero_u64")]
    pub user_data: u64,
    /// Size of the joint's debug drawing (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draw_scale: Option<f64>,
}

impl JointFile {
    /// A joint of `kind` between two bodies, every other key left out.
    #[must_use]
    pub fn new(kind: JointKindFile, body_a: BodyRef, body_b: BodyRef) -> Self {
        JointFile {
            kind,
            body_a,
            body_b,
            anchor: None,
            anchor_a: None,
            anchor_b: None,
            angle_a: None,
            angle_b: None,
            axis: None,
            reference_angle: 0.0,
            limit: None,
            motor: None,
            spring: None,
            target_angle: None,
            target_translation: None,
            linear_spring: None,
            angular_spring: None,
            length: None,
            spring_force: None,
            linear_offset: None,
            angular_offset: None,
            max_force: None,
            max_torque: None,
            correction_factor: None,
            target: None,
            collide_connected: false,
            force_threshold: None,
            torque_threshold: None,
            constraint_hertz: None,
            constraint_damping_ratio: None,
            user_data: 0,
            draw_scale: None,
        }
    }

    /// The first key the joint's kind does not use, if any.
    fn unused_key(&self) -> Option<&'static str> {
        use JointKindFile as K;
        let k = self.kind;
        let keys: [(&'static str, bool, &[K]); 17] = [
            ("axis", self.axis.is_some(), &[K::Prismatic, K::Wheel]),
            (
                "reference_angle",
                self.reference_angle != 0.0,
                &[K::Revolute, K::Weld],
            ),
            (
                "limit",
                self.limit.is_some(),
                &[K::Revolute, K::Prismatic, K::Wheel, K::Distance],
            ),
            (
                "motor",
                self.motor.is_some(),
                &[K::Revolute, K::Prismatic, K::Wheel, K::Distance],
            ),
            (
                "spring",
                self.spring.is_some(),
                &[K::Revolute, K::Prismatic, K::Wheel, K::Distance, K::Mouse],
            ),
            ("target_angle", self.target_angle.is_some(), &[K::Revolute]),
            (
                "target_translation",
                self.target_translation.is_some(),
                &[K::Prismatic],
            ),
            ("linear_spring", self.linear_spring.is_some(), &[K::Weld]),
            (
                "angular_spring",
                self.angular_spring.is_some(),
                &[K::Weld, K::Mouse],
            ),
            ("length", self.length.is_some(), &[K::Distance]),
            ("spring_force", self.spring_force.is_some(), &[K::Distance]),
            ("linear_offset", self.linear_offset.is_some(), &[K::Motor]),
            ("angular_offset", self.angular_offset.is_some(), &[K::Motor]),
            ("max_force", self.max_force.is_some(), &[K::Motor, K::Mouse]),
            ("max_torque", self.max_torque.is_some(), &[K::Motor]),
            (
                "correction_factor",
                self.correction_factor.is_some(),
                &[K::Motor],
            ),
            ("target", self.target.is_some(), &[K::Mouse]),
        ];
        keys.iter()
            .find(|(_, given, kinds)| *given && !kinds.contains(&k))
            .map(|(key, _, _)| *key)
    }
}

/// One portal of a pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PortalFile {
    /// The body carrying it.
    pub body: BodyRef,
    /// Aperture centre in the body frame, m.
    pub anchor: [f64; 2],
    /// Outward normal in the body frame.
    pub direction: [f64; 2],
    /// Half the aperture width, m.
    pub half_width: f64,
}

/// How a clone's mass follows from the original's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MassModelFile {
    /// Same density (default).
    #[default]
    SameMaterial,
    /// Density times η⁻⁴ (kinetic energy kept).
    EnergyPreserving,
}

/// A linked pair of portals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PortalPairFile {
    /// Portal a.
    pub a: PortalFile,
    /// Portal b.
    pub b: PortalFile,
    /// Scale from a to b (default `w_b / w_a`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eta: Option<f64>,
    /// The clone mass model.
    #[serde(default, skip_serializing_if = "is_default_model")]
    pub mass_model: MassModelFile,
}

fn one() -> f64 {
    1.0
}
fn yes() -> bool {
    true
}
fn friction() -> f64 {
    0.6
}
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
fn is_one(x: &f64) -> bool {
    *x == 1.0
}
fn is_friction(x: &f64) -> bool {
    *x == 0.6
}
fn is_zero2(x: &[f64; 2]) -> bool {
    x[0] == 0.0 && x[1] == 0.0
}
fn is_zero_u64(x: &u64) -> bool {
    *x == 0
}
fn is_false(x: &bool) -> bool {
    !*x
}
fn is_true(x: &bool) -> bool {
    *x
}
fn is_default_model(m: &MassModelFile) -> bool {
    *m == MassModelFile::SameMaterial
}

/// What kind of problem a scene file has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// Not JSON (a missing comma, an unclosed brace).
    Syntax,
    /// JSON, but not a scene: an unknown or missing key, a wrong type.
    Data,
    /// A scene the engine rejects: a bad value, an unknown body reference.
    Invalid,
    /// The file could not be read.
    Io,
}

/// A bad scene file: where, which field, what.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SceneFileError {
    /// The file (as given), empty for text parsed directly.
    pub file: String,
    /// The kind of problem.
    pub kind: ErrorKind,
    /// Line, from 1 (0: unknown).
    pub line: usize,
    /// Column, from 1 (0: unknown).
    pub column: usize,
    /// The field, as a path: `bodies[1].shapes[0].density` (empty: the
    /// whole file).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for SceneFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let file = if self.file.is_empty() {
            "scene"
        } else {
            &self.file
        };
        write!(f, "{file}")?;
        if self.line > 0 {
            write!(f, ":{}:{}", self.line, self.column)?;
        }
        if !self.field.is_empty() {
            write!(f, ": field `{}`", self.field)?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for SceneFileError {}

/// A problem found while building, before it is located in the text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Invalid {
    /// The field path.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

fn invalid(field: impl Into<String>, message: impl fmt::Display) -> Invalid {
    Invalid {
        field: field.into(),
        message: message.to_string(),
    }
}

/// serde_json's message without its " at line L column C" tail.
fn strip_position(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(i) => &message[..i],
        None => message,
    }
}

/// Parses a scene file's text; `file` names it in errors.
pub fn parse(text: &str, file: &str) -> Result<SceneFile, SceneFileError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let parsed: Result<SceneFile, _> = serde_path_to_error::deserialize(&mut de);
    let scene = parsed.map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let kind = match inner.classify() {
            serde_json::error::Category::Data => ErrorKind::Data,
            _ => ErrorKind::Syntax,
        };
        SceneFileError {
            file: file.to_owned(),
            kind,
            line: inner.line(),
            column: inner.column(),
            field: if path == "." { String::new() } else { path },
            message: strip_position(&inner.to_string()).to_owned(),
        }
    })?;
    de.end().map_err(|e| SceneFileError {
        file: file.to_owned(),
        kind: ErrorKind::Syntax,
        line: e.line(),
        column: e.column(),
        field: String::new(),
        message: strip_position(&e.to_string()).to_owned(),
    })?;
    Ok(scene)
}

/// A scene file built into a world.
pub struct Built {
    /// The world.
    pub world: World,
    /// Step, s.
    pub dt: Real,
    /// The file's steps, if it gives them.
    pub steps: Option<usize>,
    /// Handles of the file's bodies, by index.
    pub bodies: Vec<BodyHandle>,
    /// The probe body.
    pub probe: Option<BodyHandle>,
}

fn v2(p: [f64; 2]) -> Vec2 {
    Vec2::new(from_f64(p[0]), from_f64(p[1]))
}

fn d2(p: [f64; 2]) -> DVec2 {
    DVec2::new(p[0], p[1])
}

fn finite(field: &str, values: &[f64]) -> Result<(), Invalid> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(invalid(field, "not a finite number"))
    }
}

impl SettingsFile {
    /// The world definition and step these settings give.
    pub fn world_def(&self) -> Result<(WorldDef, Real), Invalid> {
        finite("settings.gravity", &self.gravity)?;
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(invalid("settings.dt", "the step must be finite and > 0"));
        }
        let mut def = WorldDef {
            gravity: v2(self.gravity),
            ..WorldDef::default()
        };
        def.sleep.enabled = self.sleep;
        let s = &mut def.solver;
        s.substeps = self.substeps;
        s.relax_iterations = self.relax_iterations;
        s.contact_hertz = from_f64(self.contact_hertz);
        s.contact_damping_ratio = from_f64(self.contact_damping_ratio);
        s.contact_push_max_velocity = from_f64(self.contact_push_max_velocity);
        s.joint_hertz = from_f64(self.joint_hertz);
        s.joint_damping_ratio = from_f64(self.joint_damping_ratio);
        s.restitution_threshold = from_f64(self.restitution_threshold);
        s.warm_starting = self.warm_starting;
        def.solver.validate().map_err(|e| {
            invalid(
                "settings",
                format!("{}", janus2d_world::WorldError::from(e)),
            )
        })?;
        Ok((def, from_f64(self.dt)))
    }
}

impl GeometryFile {
    /// The engine shapes of this geometry (a chain gives one per segment).
    pub fn shapes(&self) -> Result<Vec<Shape>, String> {
        let pts = |p: &[[f64; 2]]| -> Vec<Vec2> { p.iter().map(|q| v2(*q)).collect() };
        let geometry = match self {
            GeometryFile::Chain { points, closed } => {
                return make_chain(&pts(points), *closed)
                    .map(|c| c.into_iter().map(Shape::from).collect())
                    .map_err(|e| e.to_string());
            }
            GeometryFile::Circle { center, radius } => Geometry::Circle {
                center: d2(*center),
                radius: *radius,
            },
            GeometryFile::Capsule { a, b, radius } => Geometry::Capsule {
                a: d2(*a),
                b: d2(*b),
                radius: *radius,
            },
            GeometryFile::Box {
                half,
                center,
                angle,
                radius,
            } => {
                if !(half[0] > 0.0 && half[1] > 0.0) {
                    return Err("half extents must be > 0".into());
                }
                Geometry::Box {
                    half: d2(*half),
                    center: d2(*center),
                    angle: *angle,
                    radius: *radius,
                }
            }
            GeometryFile::Polygon { points, radius } => {
                if !(3..=janus2d_core::geometry::MAX_POLYGON_VERTICES).contains(&points.len()) {
                    return Err(format!(
                        "a polygon needs 3 to {} points",
                        janus2d_core::geometry::MAX_POLYGON_VERTICES
                    ));
                }
                Geometry::Hull {
                    points: points.iter().map(|p| d2(*p)).collect(),
                    radius: *radius,
                }
            }
            GeometryFile::Segment { a, b } => Geometry::Segment {
                a: d2(*a),
                b: d2(*b),
            },
        };
        janus2d_testbed::janus::shapes_of(&geometry).map_err(|e| e.to_string())
    }
}

impl SceneFile {
    fn resolve(&self, r: &BodyRef, field: &str) -> Result<usize, Invalid> {
        match r {
            BodyRef::Index(i) if *i < self.bodies.len() => Ok(*i),
            BodyRef::Index(i) => Err(invalid(
                field,
                format!("body {i} does not exist ({} bodies)", self.bodies.len()),
            )),
            BodyRef::Id(id) => self
                .bodies
                .iter()
                .position(|b| b.id.as_deref() == Some(id.as_str()))
                .ok_or_else(|| invalid(field, format!("no body has the id `{id}`"))),
        }
    }

    /// Builds the scene into a new world; the error names the field.
    pub fn build(&self) -> Result<Built, Invalid> {
        let (def, dt) = self.settings.world_def()?;
        let mut world = World::new(def).map_err(|e| invalid("settings", e))?;
        for (i, b) in self.bodies.iter().enumerate() {
            if let Some(id) = &b.id
                && self.bodies[..i].iter().any(|o| o.id.as_ref() == Some(id))
            {
                return Err(invalid(
                    format!("bodies[{i}].id"),
                    format!("`{id}` is used twice"),
                ));
            }
        }
        let mut bodies = Vec::with_capacity(self.bodies.len());
        for (i, b) in self.bodies.iter().enumerate() {
            let f = |k: &str| format!("bodies[{i}].{k}");
            finite(&f("position"), &b.position)?;
            finite(&f("linear_velocity"), &b.linear_velocity)?;
            let mut bd = BodyDef {
                body_type: match b.kind {
                    BodyKindFile::Static => BodyType::Static,
                    BodyKindFile::Kinematic => BodyType::Kinematic,
                    BodyKindFile::Dynamic => BodyType::Dynamic,
                },
                position: v2(b.position),
                angle: from_f64(b.angle),
                linear_velocity: v2(b.linear_velocity),
                angular_velocity: from_f64(b.angular_velocity),
                linear_damping: from_f64(b.linear_damping),
                angular_damping: from_f64(b.angular_damping),
                gravity_scale: from_f64(b.gravity_scale),
                fixed_rotation: b.fixed_rotation,
                motion_locks: MotionLocks {
                    linear_x: b.motion_locks.x,
                    linear_y: b.motion_locks.y,
                    angular: b.motion_locks.rotation,
                },
                awake: b.awake,
                enable_move_events: b.move_events,
                ..BodyDef::default()
            };
            if let Some(m) = &b.mass {
                finite(&f("mass"), &[m.mass, m.inertia, m.center[0], m.center[1]])?;
                bd.mass = Some(BodyMass {
                    center: v2(m.center),
                    ..BodyMass::new(from_f64(m.mass), from_f64(m.inertia))
                });
            }
            let h = world
                .create_body(&bd)
                .map_err(|e| invalid(format!("bodies[{i}]"), e))?;
            for (k, s) in b.shapes.iter().enumerate() {
                let field = format!("bodies[{i}].shapes[{k}]");
                let sd = ShapeDef {
                    density: from_f64(s.density),
                    friction: from_f64(s.friction),
                    restitution: from_f64(s.restitution),
                    is_sensor: s.sensor,
                    filter: s
                        .filter
                        .as_ref()
                        .map_or_else(Filter::default, FilterFile::filter),
                    rolling_resistance: from_f64(s.rolling_resistance),
                    tangent_speed: from_f64(s.tangent_speed),
                    friction_combine: s.friction_combine.rule(),
                    restitution_combine: s.restitution_combine.rule(),
                    user_material_id: s.material,
                    enable_hit_events: s.hit_events,
                    enable_contact_events: s.contact_events,
                    enable_sensor_events: s.sensor_events,
                    force_event_threshold: s.force_event_threshold.map_or(Real::INFINITY, from_f64),
                    ..ShapeDef::default()
                };
                finite(
                    &format!("{field}.offset"),
                    &[s.offset.position[0], s.offset.position[1], s.offset.angle],
                )?;
                let sd = sd.with_offset(v2(s.offset.position), from_f64(s.offset.angle));
                let shapes = s
                    .geometry
                    .shapes()
                    .map_err(|e| invalid(format!("{field}.geometry"), e))?;
                for shape in shapes {
                    world
                        .create_shape(h, &sd, shape)
                        .map_err(|e| invalid(field.clone(), e))?;
                }
            }
            for (k, c) in b.chains.iter().enumerate() {
                let field = format!("bodies[{i}].chains[{k}]");
                finite(&format!("{field}.points"), &c.points.concat())?;
                world
                    .create_chain(h, &c.chain_def())
                    .map_err(|e| invalid(field, e))?;
            }
            if !b.enabled {
                world
                    .set_body_enabled(h, false)
                    .map_err(|e| invalid(f("enabled"), e))?;
            }
            bodies.push(h);
        }
        for (j, jf) in self.joints.iter().enumerate() {
            self.build_joint(j, jf, &mut world, &bodies)?;
        }
        self.build_portals(&mut world, &bodies)?;
        let probe = match &self.probe {
            Some(r) => Some(bodies[self.resolve(r, "probe")?]),
            None => None,
        };
        Ok(Built {
            world,
            dt,
            steps: self.steps,
            bodies,
            probe,
        })
    }

    /// Builds joint `j` of the file into `world` (bodies from `bodies`);
    /// the error names the key.
    fn build_joint(
        &self,
        j: usize,
        jf: &JointFile,
        world: &mut World,
        bodies: &[BodyHandle],
    ) -> Result<(), Invalid> {
        use JointKindFile as K;
        let f = |k: &str| format!("joints[{j}].{k}");
        let kind = jf.kind.name();
        if let Some(key) = jf.unused_key() {
            return Err(invalid(f(key), format!("a {kind} joint has no `{key}`")));
        }
        let a = self.resolve(&jf.body_a, &f("body_a"))?;
        let b = self.resolve(&jf.body_b, &f("body_b"))?;
        let (ha, hb) = (bodies[a], bodies[b]);
        let xa = world.transform(ha).map_err(|e| invalid(f("body_a"), e))?;
        let xb = world.transform(hb).map_err(|e| invalid(f("body_b"), e))?;

        // Every number finite, every cap and spring non-negative.
        let opt = |x: Option<f64>| x.into_iter().collect::<Vec<_>>();
        let pair = |x: Option<[f64; 2]>| x.map_or_else(Vec::new, Vec::from);
        let spring = |s: &Option<SpringFile>| {
            s.as_ref()
                .map_or_else(Vec::new, |s| vec![s.hertz, s.damping_ratio])
        };
        let numbers: [(&str, Vec<f64>, bool); 29] = [
            ("anchor", pair(jf.anchor), false),
            ("anchor_a", pair(jf.anchor_a), false),
            ("anchor_b", pair(jf.anchor_b), false),
            ("angle_a", opt(jf.angle_a), false),
            ("angle_b", opt(jf.angle_b), false),
            ("axis", opt(jf.axis), false),
            ("reference_angle", vec![jf.reference_angle], false),
            ("limit", pair(jf.limit), false),
            (
                "motor.speed",
                opt(jf.motor.as_ref().map(|m| m.speed)),
                false,
            ),
            (
                "motor.max_torque",
                opt(jf.motor.as_ref().and_then(|m| m.max_torque)),
                true,
            ),
            (
                "motor.max_force",
                opt(jf.motor.as_ref().and_then(|m| m.max_force)),
                true,
            ),
            ("spring", spring(&jf.spring), true),
            ("target_angle", opt(jf.target_angle), false),
            ("target_translation", opt(jf.target_translation), false),
            ("linear_spring", spring(&jf.linear_spring), true),
            ("angular_spring", spring(&jf.angular_spring), true),
            ("length", opt(jf.length), true),
            ("spring_force", pair(jf.spring_force), false),
            ("linear_offset", pair(jf.linear_offset), false),
            ("angular_offset", opt(jf.angular_offset), false),
            ("max_force", opt(jf.max_force), true),
            ("max_torque", opt(jf.max_torque), true),
            ("correction_factor", opt(jf.correction_factor), true),
            ("target", pair(jf.target), false),
            ("force_threshold", opt(jf.force_threshold), true),
            ("torque_threshold", opt(jf.torque_threshold), true),
            ("constraint_hertz", opt(jf.constraint_hertz), true),
            (
                "constraint_damping_ratio",
                opt(jf.constraint_damping_ratio),
                true,
            ),
            ("draw_scale", opt(jf.draw_scale), true),
        ];
        for (key, values, non_negative) in &numbers {
            finite(&f(key), values)?;
            if *non_negative && values.iter().any(|v| *v < 0.0) {
                return Err(invalid(f(key), "must be ≥ 0"));
            }
        }
        if let Some([lo, hi]) = jf.limit
            && lo > hi
        {
            return Err(invalid(f("limit"), "lower > upper"));
        }
        if let Some([lo, hi]) = jf.spring_force
            && lo > hi
        {
            return Err(invalid(f("spring_force"), "lower > upper"));
        }
        if let Some(m) = &jf.motor {
            let (want, other, unit) = if jf.kind.linear_motor() {
                (
                    m.max_force,
                    "max_torque",
                    "a linear motor: give `max_force` (N)",
                )
            } else {
                (
                    m.max_torque,
                    "max_force",
                    "an angular motor: give `max_torque` (N·m)",
                )
            };
            let given_other = if jf.kind.linear_motor() {
                m.max_torque.is_some()
            } else {
                m.max_force.is_some()
            };
            if given_other {
                return Err(invalid(
                    f(&format!("motor.{other}")),
                    format!("a {kind} joint's motor is {unit}"),
                ));
            }
            if want.is_none() {
                return Err(invalid(
                    f("motor"),
                    format!("a {kind} joint's motor is {unit}"),
                ));
            }
        }

        // The frames: anchors, then angles.
        let (la, lb) = match (jf.anchor, jf.anchor_a, jf.anchor_b) {
            (Some(p), None, None) => (xa.apply_inv(v2(p)), xb.apply_inv(v2(p))),
            (None, Some(la), Some(lb)) => (v2(la), v2(lb)),
            (None, None, None) if matches!(jf.kind, K::Motor | K::Filter) => {
                (Vec2::ZERO, Vec2::ZERO)
            }
            _ => {
                return Err(invalid(
                    format!("joints[{j}]"),
                    "give `anchor` (a world point) or both `anchor_a` and `anchor_b`",
                ));
            }
        };
        let angles_given = jf.angle_a.is_some() || jf.angle_b.is_some();
        let (phi_a, phi_b) = if let Some(axis) = jf.axis {
            if angles_given {
                return Err(invalid(
                    f("axis"),
                    "give `axis` or `angle_a`/`angle_b`, not both",
                ));
            }
            let axis = from_f64(axis);
            (axis - xa.q.angle(), axis - xb.q.angle())
        } else if jf.reference_angle != 0.0 {
            if angles_given {
                return Err(invalid(
                    f("reference_angle"),
                    "give `reference_angle` or `angle_a`/`angle_b`, not both",
                ));
            }
            (from_f64(jf.reference_angle), 0.0)
        } else {
            (
                from_f64(jf.angle_a.unwrap_or(0.0)),
                from_f64(jf.angle_b.unwrap_or(0.0)),
            )
        };
        let mut base = JointDefBase::with_frames(
            ha,
            hb,
            JointFrame::new(la, phi_a),
            JointFrame::new(lb, phi_b),
        );
        base.collide_connected = jf.collide_connected;
        base.user_data = jf.user_data;
        if let Some(x) = jf.force_threshold {
            base.force_threshold = from_f64(x);
        }
        if let Some(x) = jf.torque_threshold {
            base.torque_threshold = from_f64(x);
        }
        if let Some(x) = jf.constraint_hertz {
            base.constraint_hertz = from_f64(x);
        }
        if let Some(x) = jf.constraint_damping_ratio {
            base.constraint_damping_ratio = from_f64(x);
        }
        if let Some(x) = jf.draw_scale {
            base.draw_scale = from_f64(x);
        }

        let cap = |x: f64| from_f64(x.min(to_f64(Real::MAX)));
        let limit = jf.limit.map(|[lo, hi]| (from_f64(lo), from_f64(hi)));
        let motor = jf.motor.as_ref().map(|m| {
            let max = m.max_force.or(m.max_torque).unwrap_or(0.0);
            (from_f64(m.speed), cap(max))
        });
        let spring = |s: &Option<SpringFile>| {
            s.as_ref()
                .map(|s| (from_f64(s.hertz), from_f64(s.damping_ratio)))
        };
        let def: JointDef = match jf.kind {
            K::Revolute => {
                let mut d = RevoluteJointDef::from_base(base);
                if let Some((lo, hi)) = limit {
                    d = d.with_limits(lo, hi);
                }
                if let Some((speed, max)) = motor {
                    d = d.with_motor(speed, max);
                }
                if let Some((hz, zeta)) = spring(&jf.spring) {
                    d = d.with_spring(hz, zeta);
                }
                if let Some(t) = jf.target_angle {
                    d = d.with_target_angle(from_f64(t));
                }
                d.into()
            }
            K::Weld => {
                let (lh, lz) = spring(&jf.linear_spring).unwrap_or((0.0, 0.0));
                let (ah, az) = spring(&jf.angular_spring).unwrap_or((0.0, 0.0));
                WeldJointDef::from_base(base)
                    .with_stiffness(lh, lz, ah, az)
                    .into()
            }
            K::Prismatic => {
                let mut d = PrismaticJointDef::from_base(base)
                    .with_target_translation(from_f64(jf.target_translation.unwrap_or(0.0)));
                if let Some((lo, hi)) = limit {
                    d = d.with_limits(lo, hi);
                }
                if let Some((speed, max)) = motor {
                    d = d.with_motor(speed, max);
                }
                if let Some((hz, zeta)) = spring(&jf.spring) {
                    d = d.with_spring(hz, zeta);
                }
                d.into()
            }
            K::Wheel => {
                let mut d = WheelJointDef::from_base(base);
                d.enable_spring = false;
                if let Some((hz, zeta)) = spring(&jf.spring) {
                    d = d.with_spring(hz, zeta);
                }
                if let Some((lo, hi)) = limit {
                    d = d.with_limits(lo, hi);
                }
                if let Some((speed, max)) = motor {
                    d = d.with_motor(speed, max);
                }
                d.into()
            }
            K::Distance => {
                let length = match jf.length {
                    Some(l) => from_f64(l),
                    None => (xb.apply(lb) - xa.apply(la)).length(),
                };
                let mut d = DistanceJointDef::from_base(base, length);
                if let Some([lo, hi]) = jf.spring_force {
                    d = d.with_spring_force_range(from_f64(lo), from_f64(hi));
                }
                if let Some((lo, hi)) = limit {
                    d = d.with_limits(lo, hi);
                }
                if let Some((hz, zeta)) = spring(&jf.spring) {
                    d = d.with_spring(hz, zeta);
                }
                if let Some((speed, max)) = motor {
                    d = d.with_motor(speed, max);
                }
                d.into()
            }
            K::Motor => {
                let mut d = MotorJointDef::from_base(base).with_offset(
                    jf.linear_offset.map_or(Vec2::ZERO, v2),
                    from_f64(jf.angular_offset.unwrap_or(0.0)),
                );
                if let Some(x) = jf.max_force {
                    d = d.with_max_force(cap(x));
                }
                if let Some(x) = jf.max_torque {
                    d = d.with_max_torque(cap(x));
                }
                if let Some(x) = jf.correction_factor {
                    d = d.with_correction_factor(from_f64(x));
                }
                d.into()
            }
            K::Mouse => {
                let target = match (jf.target, jf.anchor) {
                    (Some(t), _) | (None, Some(t)) => v2(t),
                    (None, None) => {
                        return Err(invalid(
                            format!("joints[{j}]"),
                            "a mouse joint needs `target` (or a world `anchor`)",
                        ));
                    }
                };
                let Some(max_force) = jf.max_force else {
                    return Err(invalid(
                        format!("joints[{j}]"),
                        "a mouse joint needs `max_force` (N)",
                    ));
                };
                let mut d = MouseJointDef::from_base(base, target, cap(max_force));
                if let Some((hz, zeta)) = spring(&jf.spring) {
                    d = d.with_spring(hz, zeta);
                }
                if let Some((hz, zeta)) = spring(&jf.angular_spring) {
                    d = d.with_angular_damping(hz, zeta);
                }
                d.into()
            }
            K::Filter => FilterJointDef::from_base(base).into(),
        };
        world
            .create_joint(&def)
            .map(drop)
            .map_err(|e| invalid(format!("joints[{j}]"), format!("{kind} joint: {e}")))
    }

    #[cfg(feature = "portals")]
    fn build_portals(&self, world: &mut World, bodies: &[BodyHandle]) -> Result<(), Invalid> {
        use janus2d_world::{MassModel, PortalDef, PortalPairDef};
        for (p, pf) in self.portals.iter().enumerate() {
            let portal = |side: &PortalFile, name: &str| -> Result<PortalDef, Invalid> {
                let field = format!("portals[{p}].{name}");
                let i = self.resolve(&side.body, &format!("{field}.body"))?;
                finite(
                    &field,
                    &[
                        side.anchor[0],
                        side.anchor[1],
                        side.direction[0],
                        side.direction[1],
                        side.half_width,
                    ],
                )?;
                Ok(PortalDef {
                    body: bodies[i],
                    anchor: v2(side.anchor),
                    direction: v2(side.direction),
                    half_width: from_f64(side.half_width),
                })
            };
            let def = PortalPairDef {
                portal_a: portal(&pf.a, "a")?,
                portal_b: portal(&pf.b, "b")?,
                eta: pf.eta.map(from_f64),
                mass_model: match pf.mass_model {
                    MassModelFile::SameMaterial => MassModel::SameMaterial,
                    MassModelFile::EnergyPreserving => MassModel::EnergyPreserving,
                },
            };
            world
                .create_portal_pair(&def)
                .map_err(|e| invalid(format!("portals[{p}]"), e))?;
        }
        Ok(())
    }

    #[cfg(not(feature = "portals"))]
    fn build_portals(&self, _world: &mut World, _bodies: &[BodyHandle]) -> Result<(), Invalid> {
        if self.portals.is_empty() {
            Ok(())
        } else {
            Err(invalid("portals", "portals need the `portals` feature"))
        }
    }

    /// The file of a built-in description (settings, bodies, joints,
    /// portals, probe). A scene with a per-step script cannot be written
    /// as a file.
    pub fn from_desc(d: &SceneDesc) -> Result<SceneFile, String> {
        if !matches!(d.script, desc::Script::None) {
            return Err(format!(
                "`{}` has a per-step script, which a scene file cannot hold",
                d.name
            ));
        }
        let s = &d.settings;
        let w = WorldDef::default();
        let settings = SettingsFile {
            gravity: [s.gravity.x, s.gravity.y],
            dt: s.dt,
            substeps: s.substeps,
            relax_iterations: w.solver.relax_iterations,
            sleep: s.sleep,
            contact_hertz: s.contact_hertz,
            contact_damping_ratio: s.contact_damping_ratio,
            contact_push_max_velocity: s.contact_push_max_velocity,
            joint_hertz: s.joint_hertz,
            joint_damping_ratio: s.joint_damping_ratio,
            ..SettingsFile::default()
        };
        let a2 = |p: DVec2| [p.x, p.y];
        let bodies = d
            .bodies
            .iter()
            .map(|b| BodyFile {
                id: None,
                kind: match b.kind {
                    desc::BodyKind::Static => BodyKindFile::Static,
                    desc::BodyKind::Kinematic => BodyKindFile::Kinematic,
                    desc::BodyKind::Dynamic => BodyKindFile::Dynamic,
                },
                position: a2(b.position),
                angle: b.angle,
                linear_velocity: a2(b.linear_velocity),
                angular_velocity: b.angular_velocity,
                linear_damping: b.linear_damping,
                angular_damping: 0.0,
                gravity_scale: 1.0,
                fixed_rotation: false,
                motion_locks: LocksFile::default(),
                enabled: true,
                awake: b.awake,
                move_events: true,
                mass: b.mass.map(|(mass, inertia)| MassFile {
                    mass,
                    inertia,
                    center: [0.0, 0.0],
                }),
                shapes: b
                    .shapes
                    .iter()
                    .map(|s| ShapeFile {
                        geometry: match &s.geometry {
                            Geometry::Circle { center, radius } => GeometryFile::Circle {
                                center: a2(*center),
                                radius: *radius,
                            },
                            Geometry::Capsule { a, b, radius } => GeometryFile::Capsule {
                                a: a2(*a),
                                b: a2(*b),
                                radius: *radius,
                            },
                            Geometry::Box {
                                half,
                                center,
                                angle,
                                radius,
                            } => GeometryFile::Box {
                                half: a2(*half),
                                center: a2(*center),
                                angle: *angle,
                                radius: *radius,
                            },
                            Geometry::Hull { points, radius } => GeometryFile::Polygon {
                                points: points.iter().map(|p| a2(*p)).collect(),
                                radius: *radius,
                            },
                            Geometry::Segment { a, b } => GeometryFile::Segment {
                                a: a2(*a),
                                b: a2(*b),
                            },
                            Geometry::ChainLoop { points } => GeometryFile::Chain {
                                points: points.iter().map(|p| a2(*p)).collect(),
                                closed: true,
                            },
                        },
                        offset: OffsetFile::default(),
                        density: s.density,
                        friction: s.friction,
                        restitution: s.restitution,
                        sensor: false,
                        filter: (s.filter != desc::FilterDesc::default()).then_some(FilterFile {
                            category: s.filter.category,
                            mask: s.filter.mask,
                            group: s.filter.group,
                        }),
                        rolling_resistance: 0.0,
                        tangent_speed: 0.0,
                        friction_combine: CombineFile::Default,
                        restitution_combine: CombineFile::Default,
                        material: 0,
                        hit_events: s.hit_events,
                        contact_events: true,
                        sensor_events: true,
                        force_event_threshold: None,
                    })
                    .collect(),
                chains: Vec::new(),
            })
            .collect();
        let joints = d.all_joints().map(|j| joint_file(&j)).collect();
        let side = |(body, anchor, direction, half_width): (usize, DVec2, DVec2, f64)| PortalFile {
            body: BodyRef::Index(body),
            anchor: a2(anchor),
            direction: a2(direction),
            half_width,
        };
        let portals = d
            .portals
            .iter()
            .map(|p| PortalPairFile {
                a: side(p.entry),
                b: side(p.exit),
                eta: None,
                mass_model: MassModelFile::SameMaterial,
            })
            .collect();
        Ok(SceneFile {
            name: d.name.to_owned(),
            steps: Some(d.steps),
            settings,
            bodies,
            joints,
            portals,
            probe: d.probe.map(BodyRef::Index),
        })
    }

    /// The file as pretty JSON.
    #[must_use]
    pub fn to_json(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

/// The file form of a built-in joint description (local anchors and frame
/// angles, so the file builds the same definition).
fn joint_file(j: &desc::JointDesc) -> JointFile {
    use desc::JointDesc as D;
    let a2 = |p: DVec2| [p.x, p.y];
    let pair = |(x, y): (f64, f64)| [x, y];
    let spring = |(hertz, damping_ratio): (f64, f64)| SpringFile {
        hertz,
        damping_ratio,
    };
    let angular = |(speed, max): (f64, f64)| MotorFile {
        speed,
        max_torque: Some(max),
        max_force: None,
    };
    let linear = |(speed, max): (f64, f64)| MotorFile {
        speed,
        max_torque: None,
        max_force: Some(max),
    };
    let kind = match j {
        D::Revolute(_) => JointKindFile::Revolute,
        D::Weld(_) => JointKindFile::Weld,
        D::Prismatic(_) => JointKindFile::Prismatic,
        D::Wheel(_) => JointKindFile::Wheel,
        D::Distance(_) => JointKindFile::Distance,
        D::Motor(_) => JointKindFile::Motor,
        D::Mouse(_) => JointKindFile::Mouse,
        D::Filter(_) => JointKindFile::Filter,
    };
    let (a, b) = j.bodies();
    let (anchor_a, anchor_b) = j.anchors();
    let mut f = JointFile::new(kind, BodyRef::Index(a), BodyRef::Index(b));
    f.anchor_a = Some(a2(anchor_a));
    f.anchor_b = Some(a2(anchor_b));
    f.collide_connected = j.collide_connected();
    if let Some(base) = j.base() {
        let angle = |x: f64| (x != 0.0).then_some(x);
        f.angle_a = angle(base.frame_a.angle);
        f.angle_b = angle(base.frame_b.angle);
    }
    match j {
        D::Revolute(r) => {
            f.reference_angle = r.reference_angle;
            f.limit = r.limit.map(pair);
            f.motor = r.motor.map(angular);
            f.spring = r.spring.map(spring);
        }
        D::Weld(w) => {
            let (lh, lz, ah, az) = (
                w.linear_hertz,
                w.linear_damping_ratio,
                w.angular_hertz,
                w.angular_damping_ratio,
            );
            f.linear_spring = (lh != 0.0 || lz != 0.0).then(|| spring((lh, lz)));
            f.angular_spring = (ah != 0.0 || az != 0.0).then(|| spring((ah, az)));
        }
        D::Prismatic(p) => {
            f.limit = p.limit.map(pair);
            f.motor = p.motor.map(linear);
            f.spring = p.spring.map(spring);
            f.target_translation = (p.target_translation != 0.0).then_some(p.target_translation);
        }
        D::Wheel(w) => {
            f.limit = w.limit.map(pair);
            f.motor = w.motor.map(angular);
            f.spring = w.spring.map(spring);
        }
        D::Distance(d) => {
            f.length = Some(d.length);
            f.limit = d.limit.map(pair);
            f.motor = d.motor.map(linear);
            f.spring = d.spring.map(spring);
            f.spring_force = (d.spring_force != (f64::MIN, f64::MAX)).then(|| pair(d.spring_force));
        }
        D::Motor(m) => {
            f.linear_offset = Some(a2(m.linear_offset));
            f.angular_offset = Some(m.angular_offset);
            f.max_force = Some(m.max_force);
            f.max_torque = Some(m.max_torque);
            f.correction_factor = Some(m.correction_factor);
        }
        D::Mouse(m) => {
            f.target = Some(a2(m.target));
            f.spring = Some(spring((m.hertz, m.damping_ratio)));
            f.max_force = Some(m.max_force);
        }
        D::Filter(_) => {}
    }
    f
}

/// Parses and builds a scene file's text; every error carries the line,
/// column and field (`file` names the file in errors).
pub fn load(text: &str, file: &str) -> Result<(SceneFile, Built), SceneFileError> {
    let scene = parse(text, file)?;
    match scene.build() {
        Ok(built) => Ok((scene, built)),
        Err(e) => {
            let (line, column) = crate::locate::locate(text, &e.field).unwrap_or((0, 0));
            Err(SceneFileError {
                file: file.to_owned(),
                kind: ErrorKind::Invalid,
                line,
                column,
                field: e.field,
                message: e.message,
            })
        }
    }
}

/// Reads, parses and builds a scene file.
pub fn load_file(path: &std::path::Path) -> Result<(SceneFile, Built), SceneFileError> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SceneFileError {
        file: name.clone(),
        kind: ErrorKind::Io,
        line: 0,
        column: 0,
        field: String::new(),
        message: e.to_string(),
    })?;
    load(&text, &name)
}
