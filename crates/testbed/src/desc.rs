//! Scenes as data: what an engine adapter needs to build and step a scene,
//! with no engine type in it.
//!
//! ```text
//!  SceneDesc ── settings   gravity, dt, substeps, sleep, softness
//!            ├─ bodies[]   BodyDesc ── shapes[] ShapeDesc ── Geometry
//!            ├─ joints[]   RevoluteDesc (indices into bodies[])
//!            ├─ extra_joints[]  JointDesc: any kind (revolute, weld,
//!            │             prismatic, wheel, distance, motor, mouse,
//!            │             filter), built after joints[]
//!            ├─ script     per-step Actions: spawn / despawn a group,
//!            │             drive a kinematic body to a target
//!            ├─ probe      the body whose pose the sanity line reports
//!            ├─ container  where bodies must stay (loop, drum, ring)
//!            └─ reference  Box2D's figures after the last step
//! ```
//!
//! Every length is in metres, every angle in radians, every mass in kg,
//! every time in seconds. Values are `f64`; an adapter rounds them to its
//! engine's scalar once, when it builds.

use glam::DVec2;

/// Static, kinematic or dynamic.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// Never moves.
    Static,
    /// Moves by its velocity, pushes but is not pushed.
    Kinematic,
    /// Moved by forces and contacts.
    Dynamic,
}

/// Collision filter, as Box2D's: two shapes collide when each one's
/// category is in the other's mask, unless they share a group index
/// (positive: always collide, negative: never).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FilterDesc {
    /// Categories the shape belongs to.
    pub category: u64,
    /// Categories it collides with.
    pub mask: u64,
    /// Group override (0: none).
    pub group: i32,
}

impl Default for FilterDesc {
    fn default() -> Self {
        FilterDesc {
            category: 1,
            mask: u64::MAX,
            group: 0,
        }
    }
}

/// A shape's geometry in its body's frame.
#[derive(Clone, Debug, PartialEq)]
pub enum Geometry {
    /// A disc.
    Circle {
        /// Centre, m.
        center: DVec2,
        /// Radius, m.
        radius: f64,
    },
    /// Two centres and a radius.
    Capsule {
        /// First centre, m.
        a: DVec2,
        /// Second centre, m.
        b: DVec2,
        /// Radius, m.
        radius: f64,
    },
    /// A (possibly rounded, offset and turned) box: each engine's own
    /// box constructor.
    Box {
        /// Half extents of the core, m.
        half: DVec2,
        /// Centre in the body frame, m.
        center: DVec2,
        /// Turn in the body frame, rad.
        angle: f64,
        /// Rounding radius, m (0: sharp).
        radius: f64,
    },
    /// The convex hull of a few points (3 to 8), rounded by `radius`.
    Hull {
        /// Points, m (any order).
        points: Vec<DVec2>,
        /// Rounding radius, m.
        radius: f64,
    },
    /// A two-sided segment.
    Segment {
        /// First end, m.
        a: DVec2,
        /// Second end, m.
        b: DVec2,
    },
    /// A closed one-sided chain through `points`: listed clockwise, so
    /// each segment's colliding side faces the inside of the loop.
    ChainLoop {
        /// The loop's points, m.
        points: Vec<DVec2>,
    },
}

/// A shape on a body.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeDesc {
    /// Geometry in the body frame.
    pub geometry: Geometry,
    /// Density, kg/m².
    pub density: f64,
    /// Friction coefficient (mixed as `sqrt(μa μb)`).
    pub friction: f64,
    /// Restitution (mixed as `max`).
    pub restitution: f64,
    /// Collision filter.
    pub filter: FilterDesc,
    /// Box2D's hit events (an engine without them ignores the flag).
    pub hit_events: bool,
}

impl ShapeDesc {
    /// Density 1, friction 0.6, restitution 0, default filter.
    #[must_use]
    pub fn new(geometry: Geometry) -> Self {
        ShapeDesc {
            geometry,
            density: 1.0,
            friction: 0.6,
            restitution: 0.0,
            filter: FilterDesc::default(),
            hit_events: false,
        }
    }

    /// The same with another friction.
    #[must_use]
    pub fn friction(mut self, friction: f64) -> Self {
        self.friction = friction;
        self
    }

    /// The same with another density.
    #[must_use]
    pub fn density(mut self, density: f64) -> Self {
        self.density = density;
        self
    }
}

/// A body and its shapes.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDesc {
    /// Static, kinematic or dynamic.
    pub kind: BodyKind,
    /// Origin, m.
    pub position: DVec2,
    /// Angle, rad.
    pub angle: f64,
    /// Velocity of the origin, m/s.
    pub linear_velocity: DVec2,
    /// Angular velocity, rad/s.
    pub angular_velocity: f64,
    /// Linear damping, 1/s.
    pub linear_damping: f64,
    /// Created awake (false: asleep, as Box2D's `isAwake = false`).
    pub awake: bool,
    /// Box2D's per-body sleep threshold, m/s (an engine with one world
    /// threshold ignores it).
    pub sleep_threshold: f64,
    /// Mass and rotational inertia about the centre of mass set directly
    /// (kg, kg·m²); `None` computes them from the shapes.
    pub mass: Option<(f64, f64)>,
    /// Shapes.
    pub shapes: Vec<ShapeDesc>,
}

impl BodyDesc {
    fn of_kind(kind: BodyKind, position: DVec2) -> Self {
        BodyDesc {
            kind,
            position,
            angle: 0.0,
            linear_velocity: DVec2::ZERO,
            angular_velocity: 0.0,
            linear_damping: 0.0,
            awake: true,
            sleep_threshold: 0.05,
            mass: None,
            shapes: Vec::new(),
        }
    }

    /// A dynamic body at `position`.
    #[must_use]
    pub fn dynamic(position: DVec2) -> Self {
        Self::of_kind(BodyKind::Dynamic, position)
    }

    /// A static body at `position`.
    #[must_use]
    pub fn fixed(position: DVec2) -> Self {
        Self::of_kind(BodyKind::Static, position)
    }

    /// A kinematic body at `position`.
    #[must_use]
    pub fn kinematic(position: DVec2) -> Self {
        Self::of_kind(BodyKind::Kinematic, position)
    }

    /// The same with one more shape.
    #[must_use]
    pub fn with(mut self, shape: ShapeDesc) -> Self {
        self.shapes.push(shape);
        self
    }
}

/// A revolute joint between two bodies of the same list (the scene's
/// `bodies`, or a spawned group's).
#[derive(Clone, Debug, PartialEq)]
pub struct RevoluteDesc {
    /// Index of body a.
    pub body_a: usize,
    /// Index of body b.
    pub body_b: usize,
    /// Anchor in a's frame, m.
    pub local_a: DVec2,
    /// Anchor in b's frame, m.
    pub local_b: DVec2,
    /// `θ_b − θ_a` at joint angle zero, rad.
    pub reference_angle: f64,
    /// Angle limits (lower, upper), rad.
    pub limit: Option<(f64, f64)>,
    /// Motor (speed rad/s, max torque N·m).
    pub motor: Option<(f64, f64)>,
    /// Angular spring to angle 0 (Hz, damping ratio).
    pub spring: Option<(f64, f64)>,
    /// Whether the two bodies collide.
    pub collide_connected: bool,
}

impl RevoluteDesc {
    /// A plain hinge.
    #[must_use]
    pub fn new(body_a: usize, body_b: usize, local_a: DVec2, local_b: DVec2) -> Self {
        RevoluteDesc {
            body_a,
            body_b,
            local_a,
            local_b,
            reference_angle: 0.0,
            limit: None,
            motor: None,
            spring: None,
            collide_connected: false,
        }
    }
}

/// A joint's frame on one body: an origin (the joint's anchor) and an
/// angle, both in the body's frame. Box2D 3.2's `localFrameA/B`, janus2d's
/// `JointFrame`, Rapier's `local_frame1/2`: axes (prismatic, wheel) are the
/// frame's x axis on body a, held angles are the frames' relative angle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameDesc {
    /// Origin in the body's frame, m.
    pub anchor: DVec2,
    /// Angle in the body's frame, rad.
    pub angle: f64,
}

impl FrameDesc {
    /// A frame at `anchor`, angle 0.
    #[must_use]
    pub const fn at(anchor: DVec2) -> Self {
        FrameDesc { anchor, angle: 0.0 }
    }

    /// A frame at `anchor` turned by `angle`.
    #[must_use]
    pub const fn new(anchor: DVec2, angle: f64) -> Self {
        FrameDesc { anchor, angle }
    }

    /// The frame's x axis in the body's frame (a unit vector).
    #[must_use]
    pub fn axis(&self) -> DVec2 {
        DVec2::from_angle(self.angle)
    }
}

/// What every joint kind of [`JointDesc`] shares (Box2D 3.2's joint
/// definition base): two bodies of the same list and a frame on each.
#[derive(Clone, Debug, PartialEq)]
pub struct JointBaseDesc {
    /// Index of body a.
    pub body_a: usize,
    /// Index of body b.
    pub body_b: usize,
    /// The joint's frame on body a.
    pub frame_a: FrameDesc,
    /// The joint's frame on body b.
    pub frame_b: FrameDesc,
    /// Whether the two bodies collide.
    pub collide_connected: bool,
}

impl JointBaseDesc {
    /// Frames at the given local anchors, angle 0, bodies not colliding.
    #[must_use]
    pub fn new(body_a: usize, body_b: usize, anchor_a: DVec2, anchor_b: DVec2) -> Self {
        JointBaseDesc {
            body_a,
            body_b,
            frame_a: FrameDesc::at(anchor_a),
            frame_b: FrameDesc::at(anchor_b),
            collide_connected: false,
        }
    }

    /// The same with both frames turned by `angle`: the axis of a prismatic
    /// or wheel joint is then `(cos, sin)(angle)` in a's frame, and the held
    /// relative angle is zero (right for two bodies created at the same
    /// angle).
    #[must_use]
    pub fn with_axis_angle(mut self, angle: f64) -> Self {
        self.frame_a.angle = angle;
        self.frame_b.angle = angle;
        self
    }
}

/// A weld joint: holds the frames together (anchors and angle), rigidly or
/// with springs.
#[derive(Clone, Debug, PartialEq)]
pub struct WeldDesc {
    /// Bodies and frames (held angle: the frames' relative angle).
    pub base: JointBaseDesc,
    /// Stiffness of the point rows, Hz (0: rigid).
    pub linear_hertz: f64,
    /// Damping ratio of the point rows.
    pub linear_damping_ratio: f64,
    /// Stiffness of the angle row, Hz (0: rigid).
    pub angular_hertz: f64,
    /// Damping ratio of the angle row.
    pub angular_damping_ratio: f64,
}

impl WeldDesc {
    /// A rigid weld at the given local anchors, holding angle 0.
    #[must_use]
    pub fn new(body_a: usize, body_b: usize, anchor_a: DVec2, anchor_b: DVec2) -> Self {
        WeldDesc {
            base: JointBaseDesc::new(body_a, body_b, anchor_a, anchor_b),
            linear_hertz: 0.0,
            linear_damping_ratio: 0.0,
            angular_hertz: 0.0,
            angular_damping_ratio: 0.0,
        }
    }

    /// True when both hertz are 0.
    #[must_use]
    pub fn is_rigid(&self) -> bool {
        self.linear_hertz == 0.0 && self.angular_hertz == 0.0
    }
}

/// A prismatic (slider) joint: b's frame slides along a's frame x axis, the
/// frames' relative angle held at 0.
#[derive(Clone, Debug, PartialEq)]
pub struct PrismaticDesc {
    /// Bodies and frames (the axis is frame a's x axis).
    pub base: JointBaseDesc,
    /// Translation limits (lower, upper), m.
    pub limit: Option<(f64, f64)>,
    /// Motor (speed m/s, max force N).
    pub motor: Option<(f64, f64)>,
    /// Spring along the axis (Hz, damping ratio) to `target_translation`.
    pub spring: Option<(f64, f64)>,
    /// The spring's rest translation, m.
    pub target_translation: f64,
}

impl PrismaticDesc {
    /// A free slider along `base`'s axis.
    #[must_use]
    pub fn new(base: JointBaseDesc) -> Self {
        PrismaticDesc {
            base,
            limit: None,
            motor: None,
            spring: None,
            target_translation: 0.0,
        }
    }
}

/// A wheel joint: b's frame origin stays on a's frame x axis (the
/// suspension axis), b turns freely; a spring along the axis and a
/// rotational motor.
#[derive(Clone, Debug, PartialEq)]
pub struct WheelDesc {
    /// Bodies and frames (the suspension axis is frame a's x axis).
    pub base: JointBaseDesc,
    /// Translation limits along the axis (lower, upper), m.
    pub limit: Option<(f64, f64)>,
    /// Rotational motor (speed rad/s of b relative to a, max torque N·m).
    pub motor: Option<(f64, f64)>,
    /// Suspension spring (Hz, damping ratio) to translation 0; `None`
    /// leaves the axis free.
    pub spring: Option<(f64, f64)>,
}

impl WheelDesc {
    /// A wheel free along `base`'s axis, no motor.
    #[must_use]
    pub fn new(base: JointBaseDesc) -> Self {
        WheelDesc {
            base,
            limit: None,
            motor: None,
            spring: None,
        }
    }
}

/// A distance joint between the two frame origins: a rigid rod at `length`
/// without a spring, a spring to `length` with one; either way held within
/// `limit`.
#[derive(Clone, Debug, PartialEq)]
pub struct DistanceDesc {
    /// Bodies and anchors (frame angles unused).
    pub base: JointBaseDesc,
    /// Rest length, m.
    pub length: f64,
    /// Length limits (min, max), m (a rope: max only, min 0).
    pub limit: Option<(f64, f64)>,
    /// Spring (Hz, damping ratio) to `length`; `None`: rigid.
    pub spring: Option<(f64, f64)>,
    /// The spring's force range (lower, upper), N: tension is positive
    /// (Box2D's `lowerSpringForce`, `upperSpringForce`).
    pub spring_force: (f64, f64),
    /// Motor along the line (speed m/s, max force N).
    pub motor: Option<(f64, f64)>,
}

impl DistanceDesc {
    /// A rigid rod of `length` between the anchors.
    #[must_use]
    pub fn new(base: JointBaseDesc, length: f64) -> Self {
        DistanceDesc {
            base,
            length,
            limit: None,
            spring: None,
            spring_force: (f64::MIN, f64::MAX),
            motor: None,
        }
    }
}

/// A motor joint: drives b's frame toward an offset pose in a's frame
/// with a bounded force and torque (a character on a platform, a top-down
/// car).
#[derive(Clone, Debug, PartialEq)]
pub struct MotorJointDesc {
    /// Bodies and frames (frame a: the frame the offsets are taken in;
    /// frame b's anchor: the driven point).
    pub base: JointBaseDesc,
    /// Target position of b's frame anchor in a's joint frame, m.
    pub linear_offset: DVec2,
    /// Target joint angle, rad.
    pub angular_offset: f64,
    /// Largest force, N.
    pub max_force: f64,
    /// Largest torque, N·m.
    pub max_torque: f64,
    /// Fraction of the pose error closed per substep, in [0, 1].
    pub correction_factor: f64,
}

impl MotorJointDesc {
    /// A motor joint holding offset zero (b's anchor on a's), Box2D's
    /// defaults: 1 N, 1 N·m, correction 0.3.
    #[must_use]
    pub fn new(base: JointBaseDesc) -> Self {
        MotorJointDesc {
            base,
            linear_offset: DVec2::ZERO,
            angular_offset: 0.0,
            max_force: 1.0,
            max_torque: 1.0,
            correction_factor: 0.3,
        }
    }
}

/// A mouse (target) joint: pulls b's frame anchor toward a world target
/// through a spring of bounded force; body a is only the reference end
/// (usually a static ground).
#[derive(Clone, Debug, PartialEq)]
pub struct MouseJointDesc {
    /// Bodies and frames (frame b's anchor: the grabbed point).
    pub base: JointBaseDesc,
    /// The world point pulled toward, m.
    pub target: DVec2,
    /// Spring stiffness, Hz.
    pub hertz: f64,
    /// Spring damping ratio.
    pub damping_ratio: f64,
    /// Largest pulling force, N.
    pub max_force: f64,
}

impl MouseJointDesc {
    /// Pulls `base`'s frame b anchor toward `target` with at most
    /// `max_force`, Box2D's spring (5 Hz, ζ 0.7).
    #[must_use]
    pub fn new(base: JointBaseDesc, target: DVec2, max_force: f64) -> Self {
        MouseJointDesc {
            base,
            target,
            hertz: 5.0,
            damping_ratio: 0.7,
            max_force,
        }
    }
}

/// A filter joint: no rows, only stops its two bodies colliding.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterJointDesc {
    /// Bodies (frames only drawn).
    pub base: JointBaseDesc,
}

/// A joint of any kind, as Box2D 3.2 has them.
#[derive(Clone, Debug, PartialEq)]
pub enum JointDesc {
    /// A hinge.
    Revolute(RevoluteDesc),
    /// A weld.
    Weld(WeldDesc),
    /// A slider.
    Prismatic(PrismaticDesc),
    /// A wheel on a suspension axis.
    Wheel(WheelDesc),
    /// A rod, spring or rope between two points.
    Distance(DistanceDesc),
    /// A pose drive of b relative to a.
    Motor(MotorJointDesc),
    /// A pull toward a world target.
    Mouse(MouseJointDesc),
    /// No collision between two bodies.
    Filter(FilterJointDesc),
}

impl JointDesc {
    /// The kind's name (`revolute`, `weld`, `prismatic`, `wheel`,
    /// `distance`, `motor`, `mouse`, `filter`: the scene files' `type`).
    #[must_use]
    pub fn kind_name(&self) -> &'static str {
        match self {
            JointDesc::Revolute(_) => "revolute",
            JointDesc::Weld(_) => "weld",
            JointDesc::Prismatic(_) => "prismatic",
            JointDesc::Wheel(_) => "wheel",
            JointDesc::Distance(_) => "distance",
            JointDesc::Motor(_) => "motor",
            JointDesc::Mouse(_) => "mouse",
            JointDesc::Filter(_) => "filter",
        }
    }

    /// The shared part, for every kind but the revolute (which keeps its
    /// own fields).
    #[must_use]
    pub fn base(&self) -> Option<&JointBaseDesc> {
        match self {
            JointDesc::Revolute(_) => None,
            JointDesc::Weld(j) => Some(&j.base),
            JointDesc::Prismatic(j) => Some(&j.base),
            JointDesc::Wheel(j) => Some(&j.base),
            JointDesc::Distance(j) => Some(&j.base),
            JointDesc::Motor(j) => Some(&j.base),
            JointDesc::Mouse(j) => Some(&j.base),
            JointDesc::Filter(j) => Some(&j.base),
        }
    }

    /// Indices of body a and body b.
    #[must_use]
    pub fn bodies(&self) -> (usize, usize) {
        match (self, self.base()) {
            (JointDesc::Revolute(j), _) => (j.body_a, j.body_b),
            (_, Some(b)) => (b.body_a, b.body_b),
            (_, None) => unreachable!("every kind but the revolute has a base"),
        }
    }

    /// The local anchors on a and b, m.
    #[must_use]
    pub fn anchors(&self) -> (DVec2, DVec2) {
        match (self, self.base()) {
            (JointDesc::Revolute(j), _) => (j.local_a, j.local_b),
            (_, Some(b)) => (b.frame_a.anchor, b.frame_b.anchor),
            (_, None) => unreachable!("every kind but the revolute has a base"),
        }
    }

    /// Whether the two bodies collide.
    #[must_use]
    pub fn collide_connected(&self) -> bool {
        match (self, self.base()) {
            (JointDesc::Revolute(j), _) => j.collide_connected,
            (_, Some(b)) => b.collide_connected,
            (_, None) => unreachable!("every kind but the revolute has a base"),
        }
    }
}

impl From<RevoluteDesc> for JointDesc {
    fn from(j: RevoluteDesc) -> Self {
        JointDesc::Revolute(j)
    }
}

impl From<WeldDesc> for JointDesc {
    fn from(j: WeldDesc) -> Self {
        JointDesc::Weld(j)
    }
}

impl From<PrismaticDesc> for JointDesc {
    fn from(j: PrismaticDesc) -> Self {
        JointDesc::Prismatic(j)
    }
}

impl From<WheelDesc> for JointDesc {
    fn from(j: WheelDesc) -> Self {
        JointDesc::Wheel(j)
    }
}

impl From<DistanceDesc> for JointDesc {
    fn from(j: DistanceDesc) -> Self {
        JointDesc::Distance(j)
    }
}

impl From<MotorJointDesc> for JointDesc {
    fn from(j: MotorJointDesc) -> Self {
        JointDesc::Motor(j)
    }
}

impl From<MouseJointDesc> for JointDesc {
    fn from(j: MouseJointDesc) -> Self {
        JointDesc::Mouse(j)
    }
}

impl From<FilterJointDesc> for JointDesc {
    fn from(j: FilterJointDesc) -> Self {
        JointDesc::Filter(j)
    }
}

/// World settings a scene runs with.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Gravity, m/s².
    pub gravity: DVec2,
    /// Step, s.
    pub dt: f64,
    /// Substeps per step.
    pub substeps: u32,
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
}

impl Default for Settings {
    /// The shared settings: gravity (0, −10), 1/60 s, 4 substeps, sleep
    /// off, contacts 30 Hz / ζ 10, push-out 3 m/s, joints 60 Hz / ζ 2.
    fn default() -> Self {
        Settings {
            gravity: DVec2::new(0.0, -10.0),
            dt: 1.0 / 60.0,
            substeps: 4,
            sleep: false,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            contact_push_max_velocity: 3.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
        }
    }
}

/// One thing a script does before a step.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Create a group of bodies and joints (joint indices are into the
    /// group's own `bodies`). The adapter remembers the group by `id`.
    Spawn {
        /// Group id (unique among live groups).
        id: usize,
        /// Bodies.
        bodies: Vec<BodyDesc>,
        /// Joints between them.
        joints: Vec<RevoluteDesc>,
    },
    /// Destroy every body (and so joint) of a live group.
    Despawn {
        /// Group id.
        id: usize,
    },
    /// Drive a kinematic body so that it reaches this pose by the end of
    /// the step (velocity = (target − current) / dt, as Box2D's
    /// `b2Body_SetTargetTransform`).
    Target {
        /// Index into the scene's bodies.
        body: usize,
        /// Target origin, m.
        position: DVec2,
        /// Target angle, rad.
        angle: f64,
    },
}

/// Per-step script of a scene.
#[derive(Clone, Debug, PartialEq)]
pub enum Script {
    /// Nothing happens between steps.
    None,
    /// Box2D's `rain`: every 8th step, a column of `rows` groups of
    /// `group_size` ragdolls; once `columns` are down, the oldest column
    /// is destroyed and spawned again.
    Rain {
        /// Rows of groups (one per ground row).
        rows: usize,
        /// Columns.
        columns: usize,
        /// Ragdolls per group.
        group_size: usize,
    },
    /// Box2D's `junkyard`: body `body` is driven to x = amplitude ·
    /// sin(rate · t), y = 0, angle 0.
    Pusher {
        /// The kinematic body.
        body: usize,
        /// Amplitude, m.
        amplitude: f64,
        /// Angular rate, rad/s.
        rate: f64,
    },
}

impl Script {
    /// The actions to apply before step `step` (0-based) of length `dt`.
    pub fn actions(&self, step: usize, dt: f64, out: &mut Vec<Action>) {
        out.clear();
        match *self {
            Script::None => {}
            Script::Rain {
                rows,
                columns,
                group_size,
            } => {
                if step & 7 != 0 {
                    return;
                }
                let k = step / 8;
                let column = if k < columns {
                    k
                } else {
                    (k - columns) % columns
                };
                for row in 0..rows {
                    let id = row * columns + column;
                    if k >= columns {
                        out.push(Action::Despawn { id });
                    }
                    let (bodies, joints) = crate::benchmarks::rain_group(row, column, group_size);
                    out.push(Action::Spawn { id, bodies, joints });
                }
            }
            Script::Pusher {
                body,
                amplitude,
                rate,
            } => {
                let t = dt * step as f64;
                out.push(Action::Target {
                    body,
                    position: DVec2::new(amplitude * (rate * t).sin(), 0.0),
                    angle: 0.0,
                });
            }
        }
    }
}

/// The region bodies should stay in, in the frame of one body (or the
/// world): "bodies outside the container" is a sanity figure.
#[derive(Clone, Debug, PartialEq)]
pub struct Container {
    /// Body whose frame the region is in (`None`: the world).
    pub body: Option<usize>,
    /// The region.
    pub region: Region,
}

/// A container's region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Region {
    /// A disc.
    Disc {
        /// Centre, m.
        center: DVec2,
        /// Radius, m.
        radius: f64,
    },
    /// An axis-aligned box.
    Rect {
        /// Centre, m.
        center: DVec2,
        /// Half extents, m.
        half: DVec2,
    },
}

impl Region {
    /// Whether the local point lies inside.
    #[must_use]
    pub fn contains(&self, p: DVec2) -> bool {
        match *self {
            Region::Disc { center, radius } => (p - center).length_squared() <= radius * radius,
            Region::Rect { center, half } => {
                let d = (p - center).abs();
                d.x <= half.x && d.y <= half.y
            }
        }
    }
}

/// Box2D's figures after the last step (native 3.2.0-dev, single thread),
/// for the sanity check: a run that differs by more than the tolerance is
/// flagged.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reference {
    /// Touching contact pairs.
    pub touching: Option<f64>,
    /// Awake bodies.
    pub awake: Option<f64>,
    /// Bodies in the world.
    pub bodies: Option<f64>,
    /// Probe position (x, y), m.
    pub probe_position: Option<DVec2>,
    /// Probe angle, rad.
    pub probe_angle: Option<f64>,
}

/// Relative tolerance of the count figures (touching, awake, bodies).
pub const COUNT_TOLERANCE: f64 = 0.10;
/// Tolerance of the probe position, m.
pub const POSITION_TOLERANCE: f64 = 0.25;
/// Tolerance of the probe angle, rad.
pub const ANGLE_TOLERANCE: f64 = 0.05;

/// A portal pair (janus2d only: the other engines have no portals).
#[derive(Clone, Debug, PartialEq)]
pub struct PortalDesc {
    /// Entry: body index, anchor in its frame, direction (outward normal),
    /// half width.
    pub entry: (usize, DVec2, DVec2, f64),
    /// Exit, as the entry.
    pub exit: (usize, DVec2, DVec2, f64),
}

/// A scene.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneDesc {
    /// Name (as `janus2d list` and the benchmarks print it).
    pub name: &'static str,
    /// Steps Box2D's benchmark runs.
    pub steps: usize,
    /// World settings.
    pub settings: Settings,
    /// Bodies present at the start.
    pub bodies: Vec<BodyDesc>,
    /// Revolute joints present at the start (indices into `bodies`): the
    /// benchmarks', the hard cases' and what the command line's scene
    /// export reads.
    pub joints: Vec<RevoluteDesc>,
    /// Joints of any kind present at the start (indices into `bodies`),
    /// created after `joints`. An engine without a kind refuses the scene
    /// at build.
    pub extra_joints: Vec<JointDesc>,
    /// Per-step script.
    pub script: Script,
    /// The body the sanity line reports.
    pub probe: Option<usize>,
    /// What the probe is.
    pub probe_label: &'static str,
    /// Where bodies must stay.
    pub container: Option<Container>,
    /// Box2D's figures.
    pub reference: Reference,
    /// Portal pairs (janus2d only).
    pub portals: Vec<PortalDesc>,
}

impl SceneDesc {
    /// An empty scene with the shared settings.
    #[must_use]
    pub fn new(name: &'static str, steps: usize) -> Self {
        SceneDesc {
            name,
            steps,
            settings: Settings::default(),
            bodies: Vec::new(),
            joints: Vec::new(),
            extra_joints: Vec::new(),
            script: Script::None,
            probe: None,
            probe_label: "",
            container: None,
            reference: Reference::default(),
            portals: Vec::new(),
        }
    }

    /// Adds a body; returns its index.
    pub fn add(&mut self, body: BodyDesc) -> usize {
        self.bodies.push(body);
        self.bodies.len() - 1
    }

    /// Adds a revolute joint.
    pub fn join(&mut self, joint: RevoluteDesc) {
        self.joints.push(joint);
    }

    /// Adds a joint of any kind (to `extra_joints`).
    pub fn join_any(&mut self, joint: impl Into<JointDesc>) {
        self.extra_joints.push(joint.into());
    }

    /// Every joint at the start: `joints`, then `extra_joints`.
    pub fn all_joints(&self) -> impl Iterator<Item = JointDesc> + '_ {
        self.joints
            .iter()
            .cloned()
            .map(JointDesc::Revolute)
            .chain(self.extra_joints.iter().cloned())
    }

    /// Dynamic bodies at the start.
    #[must_use]
    pub fn dynamic_count(&self) -> usize {
        self.bodies
            .iter()
            .filter(|b| b.kind == BodyKind::Dynamic)
            .count()
    }
}

/// A box geometry centred on the body origin.
#[must_use]
pub fn square(hx: f64, hy: f64) -> Geometry {
    Geometry::Box {
        half: DVec2::new(hx, hy),
        center: DVec2::ZERO,
        angle: 0.0,
        radius: 0.0,
    }
}

/// A box geometry offset from the body origin.
#[must_use]
pub fn offset_box(hx: f64, hy: f64, center: DVec2) -> Geometry {
    Geometry::Box {
        half: DVec2::new(hx, hy),
        center,
        angle: 0.0,
        radius: 0.0,
    }
}

/// `DVec2::new`, short.
#[must_use]
pub const fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}
