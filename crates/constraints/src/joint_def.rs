//! What every joint definition holds, whatever its kind: the two bodies,
//! a local frame on each, and the settings every kind shares.
//!
//! ```text
//!        body a                                   body b
//!   ┌──────────────┐                        ┌──────────────┐
//!   │   origin ·───┼──▶ local_frame_a        │  local_frame_b ◀──┼─· origin
//!   │              │    anchor (m), angle    │  anchor (m), angle│
//!   └──────────────┘    x axis = the joint's axis (prismatic, wheel)
//! ```
//!
//! A kind reads its geometry from the frames: the anchors are the frames'
//! origins; the joint angle is `(θ_b + φ_b) − (θ_a + φ_a)` with `φ` the
//! frames' angles (the *reference angle* is `φ_a − φ_b`); a prismatic or
//! wheel axis is frame a's x axis.
//!
//! | field | unit | default | meaning |
//! |-------|------|---------|---------|
//! | `body_a`, `body_b` | | | the two bodies (different) |
//! | `local_frame_a`, `local_frame_b` | m, rad | identity | anchor and angle in each body's frame (from its origin) |
//! | `collide_connected` | | false | the two bodies collide with each other |
//! | `user_data` | | 0 | an opaque value the world keeps for the joint |
//! | `constraint_hertz`, `constraint_damping_ratio` | Hz, 1 | 0, 0 | softness of the kind's rigid rows; 0 Hz: the world's joint softness |
//! | `force_threshold` | N | ∞ | a joint event when the force passes it |
//! | `torque_threshold` | N·m | ∞ | a joint event when the torque passes it |
//! | `draw_scale` | 1 | 1 | size of the joint's debug drawing |

use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, Rot, Vec2, vec_is_finite};
use janus2d_core::softness::Softness;

use crate::{JointError, check_anchor, check_spring};

/// A frame fixed on a body: an origin (the joint's anchor) and an angle,
/// both in the body's frame, measured from the body's origin.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointFrame {
    /// The frame's origin in the body's frame, m.
    pub anchor: Vec2,
    /// The frame's angle in the body's frame, rad.
    pub angle: Real,
}

impl JointFrame {
    /// The body's own frame (anchor at its origin, angle 0).
    pub const IDENTITY: JointFrame = JointFrame {
        anchor: Vec2::ZERO,
        angle: 0.0,
    };

    /// A frame at `anchor` (m), angle 0.
    #[must_use]
    pub const fn at(anchor: Vec2) -> Self {
        JointFrame { anchor, angle: 0.0 }
    }

    /// A frame at `anchor` (m) turned by `angle` (rad).
    #[must_use]
    pub const fn new(anchor: Vec2, angle: Real) -> Self {
        JointFrame { anchor, angle }
    }

    /// The frame's x axis in the body's frame (a unit vector).
    #[must_use]
    pub fn axis(&self) -> Vec2 {
        Rot::from_angle(self.angle).rotate(Vec2::X)
    }
}

/// The part of a joint definition every kind shares (Box2D 3.2's joint
/// definition base; see the module docs for the table of fields).
///
/// ```
/// use janus2d_constraints::{JointDefBase, JointFrame};
/// use janus2d_core::{BodyDef, BodySet, Vec2};
/// let mut bodies = BodySet::new();
/// let a = bodies.create(&BodyDef::fixed(Vec2::ZERO)).unwrap();
/// let b = bodies.create(&BodyDef::dynamic(Vec2::new(2.0, 0.0))).unwrap();
/// // From a world anchor: each body's frame at that point.
/// let base = JointDefBase::at_world_point(&bodies, a, b, Vec2::new(1.0, 0.0)).unwrap();
/// assert_eq!(base.local_frame_a.anchor, Vec2::new(1.0, 0.0));
/// assert_eq!(base.local_frame_b.anchor, Vec2::new(-1.0, 0.0));
/// assert_eq!(base.force_threshold, f32::INFINITY as _);
/// assert!(base.validate().is_ok());
/// ```
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct JointDefBase {
    /// First body.
    pub body_a: BodyHandle,
    /// Second body.
    pub body_b: BodyHandle,
    /// The joint's frame on body a (anchor and angle in a's frame).
    pub local_frame_a: JointFrame,
    /// The joint's frame on body b (anchor and angle in b's frame).
    pub local_frame_b: JointFrame,
    /// Whether the two bodies collide with each other (usual false).
    pub collide_connected: bool,
    /// An opaque value the world keeps for the joint
    /// (`World::joint_user_data`).
    pub user_data: u64,
    /// Stiffness of the kind's rigid rows, Hz (0: the world's joint
    /// softness, built on the mass ratio).
    pub constraint_hertz: Real,
    /// Damping ratio of the kind's rigid rows (dimensionless; used with a
    /// nonzero `constraint_hertz`).
    pub constraint_damping_ratio: Real,
    /// Force (N) above which the joint reports a joint event (∞: never).
    pub force_threshold: Real,
    /// Torque (N·m) above which the joint reports a joint event (∞: never).
    pub torque_threshold: Real,
    /// Size of the joint's debug drawing (1: the default size).
    pub draw_scale: Real,
}

impl Default for JointDefBase {
    /// Two placeholder bodies (slot `u32::MAX`: set both before use;
    /// `validate` rejects a joint whose ends are the same body) and every
    /// other field at its default.
    fn default() -> Self {
        let none = BodyHandle::new(u32::MAX, 0, 0);
        JointDefBase::new(none, none)
    }
}

impl JointDefBase {
    /// The base of a joint between `body_a` and `body_b`, both frames at
    /// their body's origin, every setting at its default.
    #[must_use]
    pub fn new(body_a: BodyHandle, body_b: BodyHandle) -> Self {
        JointDefBase {
            body_a,
            body_b,
            local_frame_a: JointFrame::IDENTITY,
            local_frame_b: JointFrame::IDENTITY,
            collide_connected: false,
            user_data: 0,
            constraint_hertz: 0.0,
            constraint_damping_ratio: 0.0,
            force_threshold: Real::INFINITY,
            torque_threshold: Real::INFINITY,
            draw_scale: 1.0,
        }
    }

    /// The base with the two local anchors (frames at angle 0).
    #[must_use]
    pub fn with_anchors(
        body_a: BodyHandle,
        body_b: BodyHandle,
        anchor_a: Vec2,
        anchor_b: Vec2,
    ) -> Self {
        JointDefBase {
            local_frame_a: JointFrame::at(anchor_a),
            local_frame_b: JointFrame::at(anchor_b),
            ..JointDefBase::new(body_a, body_b)
        }
    }

    /// The base with the two local frames.
    #[must_use]
    pub fn with_frames(
        body_a: BodyHandle,
        body_b: BodyHandle,
        frame_a: JointFrame,
        frame_b: JointFrame,
    ) -> Self {
        JointDefBase {
            local_frame_a: frame_a,
            local_frame_b: frame_b,
            ..JointDefBase::new(body_a, body_b)
        }
    }

    /// The base whose frames sit at one world point, each aligned with
    /// the world's axes at the bodies' current poses (so the reference
    /// angle is the bodies' current relative angle). `Err(StaleBody)`-like
    /// [`JointError::UnknownBody`] for a body not in `bodies`.
    pub fn at_world_point(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
    ) -> Result<Self, JointError> {
        Self::at_world_frame(bodies, body_a, body_b, point, 0.0)
    }

    /// The base whose frames sit at one world point with their x axes
    /// along the world angle `axis_angle` (rad) at the bodies' current
    /// poses: a prismatic or wheel joint along that world axis.
    pub fn at_world_frame(
        bodies: &BodySet,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
        axis_angle: Real,
    ) -> Result<Self, JointError> {
        if !(vec_is_finite(point) && axis_angle.is_finite()) {
            return Err(JointError::NonFinite);
        }
        let frame = |body: BodyHandle| -> Result<JointFrame, JointError> {
            let xf = bodies.sim(body).ok_or(JointError::UnknownBody)?.transform;
            Ok(JointFrame::new(
                xf.apply_inv(point),
                axis_angle - xf.q.angle(),
            ))
        };
        Ok(JointDefBase::with_frames(
            body_a,
            body_b,
            frame(body_a)?,
            frame(body_b)?,
        ))
    }

    /// The reference angle `φ_a − φ_b`, rad: the joint angle is
    /// `θ_b − θ_a − reference`.
    #[must_use]
    pub fn reference_angle(&self) -> Real {
        self.local_frame_a.angle - self.local_frame_b.angle
    }

    /// The softness of a kind's rigid rows for a step: the joint's own
    /// (`constraint_hertz > 0`), else the world's joint softness built on
    /// the heavier end (`w_a`, `w_b`: the ends' inverse masses for linear
    /// rows, inverse inertias for angular rows; see
    /// `mass_ratio_softness`).
    #[must_use]
    pub fn rigid_softness(&self, ctx: &StepContext, w_a: Real, w_b: Real) -> Softness {
        if self.constraint_hertz > 0.0 {
            Softness::new(self.constraint_hertz, self.constraint_damping_ratio, ctx.h)
        } else {
            mass_ratio_softness(ctx, w_a, w_b)
        }
    }

    /// Checks the shared values: two different bodies, finite frames
    /// within [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT), a
    /// non-negative and bounded constraint softness, non-negative (non-NaN)
    /// thresholds, a finite positive draw scale.
    pub fn validate(&self) -> Result<(), JointError> {
        if self.body_a == self.body_b {
            return Err(JointError::SameBody);
        }
        let finite = vec_is_finite(self.local_frame_a.anchor)
            && vec_is_finite(self.local_frame_b.anchor)
            && self.local_frame_a.angle.is_finite()
            && self.local_frame_b.angle.is_finite()
            && self.constraint_hertz.is_finite()
            && self.constraint_damping_ratio.is_finite()
            && !self.force_threshold.is_nan()
            && !self.torque_threshold.is_nan()
            && self.draw_scale.is_finite();
        if !finite {
            return Err(JointError::NonFinite);
        }
        if self.constraint_hertz < 0.0
            || self.constraint_damping_ratio < 0.0
            || self.force_threshold < 0.0
            || self.torque_threshold < 0.0
            || self.draw_scale <= 0.0
        {
            return Err(JointError::Negative);
        }
        check_anchor(self.local_frame_a.anchor, "local_frame_a.anchor")?;
        check_anchor(self.local_frame_b.anchor, "local_frame_b.anchor")?;
        let max_angle = janus2d_core::limits::MAX_EXTENT;
        if self.local_frame_a.angle.abs() > max_angle || self.local_frame_b.angle.abs() > max_angle
        {
            return Err(JointError::OutOfBounds {
                field: "local_frame angle",
                min: -max_angle,
                max: max_angle,
            });
        }
        check_spring(self.constraint_hertz, self.constraint_damping_ratio)
    }

    /// The world anchors of the two frames at the bodies' current poses, m.
    #[must_use]
    pub fn world_anchors(&self, bodies: &BodySet) -> (Vec2, Vec2) {
        world_anchors(
            bodies,
            (self.body_a, self.local_frame_a.anchor),
            (self.body_b, self.local_frame_b.anchor),
        )
    }

    /// The frame on `body`, mutable (`None` when `body` is neither end).
    pub fn frame_on_mut(&mut self, body: BodyHandle) -> Option<&mut JointFrame> {
        if self.body_a == body {
            Some(&mut self.local_frame_a)
        } else if self.body_b == body {
            Some(&mut self.local_frame_b)
        } else {
            None
        }
    }
}

/// A kind's limits as a setter edits them (see `JointDef::limits_mut`).
pub struct LimitsMut<'a> {
    /// The switch.
    pub enable: &'a mut bool,
    /// Lower limit (rad for an angle, m for a translation or length).
    pub lower: &'a mut Real,
    /// Upper limit (same unit).
    pub upper: &'a mut Real,
}

/// A kind's motor as a setter edits it (see `JointDef::motor_mut`).
pub struct MotorMut<'a> {
    /// The switch.
    pub enable: &'a mut bool,
    /// Target speed (rad/s for an angular motor, m/s for a linear one).
    pub speed: &'a mut Real,
    /// Largest torque (N·m, angular) or force (N, linear).
    pub max: &'a mut Real,
    /// True for a linear motor (force), false for an angular one (torque).
    pub linear: bool,
}

/// A kind's spring as a setter edits it (see `JointDef::spring_mut`).
pub struct SpringMut<'a> {
    /// The switch.
    pub enable: &'a mut bool,
    /// Stiffness, Hz.
    pub hertz: &'a mut Real,
    /// Damping ratio (dimensionless).
    pub damping_ratio: &'a mut Real,
}

/// What a kind's definition offers the world's generic setters: its
/// shared base and, when it has them, its limits, motor and spring.
pub trait KindDef: Clone + Into<crate::JointDef> {
    /// The shared part.
    fn base(&self) -> &JointDefBase;
    /// The shared part, mutable.
    fn base_mut(&mut self) -> &mut JointDefBase;
    /// Checks the definition (base and the kind's own values).
    fn validate(&self) -> Result<(), JointError>;
    /// The limits, when the kind has them.
    fn limits_mut(&mut self) -> Option<LimitsMut<'_>> {
        None
    }
    /// The motor, when the kind has one.
    fn motor_mut(&mut self) -> Option<MotorMut<'_>> {
        None
    }
    /// The spring, when the kind has one.
    fn spring_mut(&mut self) -> Option<SpringMut<'_>> {
        None
    }
}

/// The world points of two local anchors: `anchor_a` on `body_a`, `anchor_b`
/// on `body_b` (each in its body's frame, from the body's origin), m. Every
/// kind's `world_anchors` and gap read.
#[must_use]
pub fn world_anchors(
    bodies: &BodySet,
    (body_a, anchor_a): (BodyHandle, Vec2),
    (body_b, anchor_b): (BodyHandle, Vec2),
) -> (Vec2, Vec2) {
    let a = bodies.solver_body(body_a).sim;
    let b = bodies.solver_body(body_b).sim;
    (a.transform.apply(anchor_a), b.transform.apply(anchor_b))
}

/// The world's joint softness built on the heavier end, for a joint's
/// rigid rows: with `w_a`, `w_b` the two ends' inverse masses (point rows)
/// or inverse inertias (angle rows), `ρ = min((w_a + w_b) / min(w_a, w_b),
/// ρ_max)`, and `ρ_max` when one end does not move
/// ([`Softness::with_mass_ratio`]).
#[must_use]
pub(crate) fn mass_ratio_softness(ctx: &StepContext, w_a: Real, w_b: Real) -> Softness {
    let w_heavy = w_a.min(w_b);
    let rho = if w_heavy > 0.0 {
        ((w_a + w_b) / w_heavy).min(ctx.joint_mass_ratio_cap)
    } else {
        ctx.joint_mass_ratio_cap
    };
    ctx.joint_softness.with_mass_ratio(rho)
}
