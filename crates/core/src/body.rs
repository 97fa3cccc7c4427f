//! Rigid bodies and their storage, split by how often the solver touches them.
//!
//! ```text
//!                 handle (index, generation)
//!                          │
//!                          ▼
//!   records: Slots<BodyRecord> ── bookkeeping: generation (the slots'), where the body lives
//!                          │
//!          ┌───────────────┴────────────────┐
//!          ▼ moving (dynamic, kinematic)     ▼ static
//!   states[i]: BodyState   (hot)       static_sims[j]: BodySim
//!   sims[i]:   BodySim     (per step)  (state index 0: the shared
//!   i = 0 is the static sentinel        identity state)
//! ```
//!
//! | array          | touched                    | contents                                      |
//! |----------------|----------------------------|-----------------------------------------------|
//! | `states`       | every solver iteration     | v, ω, flags, position delta, rotation delta (32 bytes) |
//! | `sims`         | once per (sub)step         | transform, centre, forces, damping, limits, 1/m, 1/I |
//! | `records`      | on API calls               | generation, type, location, user data         |
//!
//! Slot 0 of `states` and `sims` is a sentinel with zero inverse mass and
//! zero velocity: every static body maps to it, so constraints read a static
//! body's state through the same code path as a moving body's, with no branch;
//! impulses written to it are multiplied by the zero inverse mass the
//! constraints loaded for it at prepare ([`BodySet::inv_masses_at`]).

use crate::math::{Real, Rot, Transform, Vec2, vec_is_finite};
use crate::slots::Slots;

/// Default maximum linear speed of a body, m/s (usual value 400 m/s, Box2D's
/// `4 m × 100` at unit length scale).
pub const DEFAULT_MAX_LINEAR_SPEED: Real = 400.0;

/// Default maximum rotation of a body per substep, radians (usual value
/// 0.25 π, as in Box2D).
pub const DEFAULT_MAX_ROTATION: Real = 0.25 * crate::math::PI;

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BodyType {
    /// Never moves; infinite mass.
    #[default]
    Static,
    /// Moves with a velocity set by the user; infinite mass; unaffected by forces.
    Kinematic,
    /// Moves under forces, gravity and constraints.
    Dynamic,
}

/// A generational handle to a body. A handle to a destroyed body is stale
/// and is rejected with a typed error; one from another world is foreign.
pub type BodyHandle = crate::handle::Handle<crate::handle::BodyTag>;

static NEXT_OWNER_ID: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(1);

/// A fresh id for a new body set or world (never 0).
pub fn next_owner_id() -> u32 {
    NEXT_OWNER_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Mass properties set directly on a body.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyMass {
    /// Mass, kg (> 0 for a dynamic body).
    pub mass: Real,
    /// Rotational inertia about the centre of mass, kg·m² (> 0 for a dynamic body
    /// unless `fixed_rotation`).
    pub rotational_inertia: Real,
    /// Centre of mass in the body frame, m.
    pub center: Vec2,
}

impl BodyMass {
    /// Mass properties with the centre of mass at the body origin.
    pub fn new(mass: Real, rotational_inertia: Real) -> Self {
        BodyMass {
            mass,
            rotational_inertia,
            center: Vec2::ZERO,
        }
    }
}

/// Which of a body's three motions are locked (Box2D v3.1's
/// `b2MotionLocks`): a locked axis behaves as if the body had infinite
/// mass along it. The rotation lock is the body's fixed rotation (its
/// inverse inertia is zero in every constraint); a linear lock zeroes that
/// component of the body's velocity wherever the solver integrates it, so
/// that the body never moves along the axis (constraints see its whole
/// mass, as Box2D's do).
///
/// ```
/// use janus2d_core::{BodyDef, MotionLocks, Vec2};
/// let def = BodyDef::dynamic(Vec2::ZERO).with_motion_locks(MotionLocks::X);
/// assert!(def.motion_locks.linear_x && !def.motion_locks.linear_y);
/// assert_eq!(MotionLocks::default(), MotionLocks::NONE);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MotionLocks {
    /// No motion along world x.
    pub linear_x: bool,
    /// No motion along world y.
    pub linear_y: bool,
    /// No rotation (the same as [`BodyDef::fixed_rotation`]).
    pub angular: bool,
}

impl MotionLocks {
    /// Nothing locked.
    ///
    /// ```
    /// use janus2d_core::body::MotionLocks;
    /// assert_eq!(MotionLocks::NONE, MotionLocks::default());
    /// ```
    pub const NONE: MotionLocks = MotionLocks {
        linear_x: false,
        linear_y: false,
        angular: false,
    };
    /// Only x translation locked.
    ///
    /// ```
    /// use janus2d_core::body::MotionLocks;
    /// assert!(MotionLocks::X.linear_x && !MotionLocks::X.linear_y && !MotionLocks::X.angular);
    /// ```
    pub const X: MotionLocks = MotionLocks {
        linear_x: true,
        linear_y: false,
        angular: false,
    };
    /// Only y translation locked.
    ///
    /// ```
    /// use janus2d_core::body::MotionLocks;
    /// assert!(MotionLocks::Y.linear_y && !MotionLocks::Y.linear_x);
    /// ```
    pub const Y: MotionLocks = MotionLocks {
        linear_x: false,
        linear_y: true,
        angular: false,
    };
    /// Only the rotation locked.
    ///
    /// ```
    /// use janus2d_core::body::MotionLocks;
    /// assert!(MotionLocks::ROTATION.angular && !MotionLocks::ROTATION.linear_x);
    /// ```
    pub const ROTATION: MotionLocks = MotionLocks {
        linear_x: false,
        linear_y: false,
        angular: true,
    };

    /// The [`BodyState`] flag bits of the linear locks.
    ///
    /// ```
    /// use janus2d_core::body::{BodyState, MotionLocks};
    /// assert_eq!(MotionLocks::X.linear_flags(), BodyState::LOCK_X);
    /// assert_eq!(MotionLocks::ROTATION.linear_flags(), 0);
    /// ```
    #[inline]
    #[must_use]
    pub fn linear_flags(self) -> u32 {
        (if self.linear_x { BodyState::LOCK_X } else { 0 })
            | (if self.linear_y { BodyState::LOCK_Y } else { 0 })
    }
}

/// Everything needed to create a body. Start from `BodyDef::default()` or a
/// constructor and change fields.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyDef {
    /// Static, kinematic or dynamic.
    pub body_type: BodyType,
    /// World position of the body origin, m.
    pub position: Vec2,
    /// World angle, rad.
    pub angle: Real,
    /// Linear velocity of the body origin, m/s.
    pub linear_velocity: Vec2,
    /// Angular velocity, rad/s.
    pub angular_velocity: Real,
    /// Linear damping, 1/s (usual 0).
    pub linear_damping: Real,
    /// Angular damping, 1/s (usual 0).
    pub angular_damping: Real,
    /// Multiplier of world gravity (usual 1).
    pub gravity_scale: Real,
    /// Maximum linear speed, m/s (usual 400).
    pub max_linear_speed: Real,
    /// Maximum rotation per substep, rad (usual π/4).
    pub max_rotation: Real,
    /// Mass set directly; `None` computes it from the body's shapes (a body
    /// without shapes then has 1 kg and 1 kg·m² about its origin).
    pub mass: Option<BodyMass>,
    /// Prevents rotation (infinite rotational inertia).
    pub fixed_rotation: bool,
    /// Locks x translation, y translation or rotation separately (usual
    /// none; see [`MotionLocks`]). A rotation lock here or
    /// `fixed_rotation` locks the rotation.
    pub motion_locks: MotionLocks,
    /// Starts awake (usual true); `false` creates the body asleep, as Box2D's
    /// `isAwake = false`: the world puts it to sleep before its next step
    /// (after its shapes are attached), and it costs nothing until something
    /// wakes it.
    pub awake: bool,
    /// A bullet (usual false): when fast, it is also swept against the
    /// shapes of other (non-bullet) dynamic and kinematic bodies, not only
    /// against static ones, so it cannot pass through a thin moving body
    /// (as Box2D's `isBullet`). Costs a time-of-impact search per fast step.
    pub bullet: bool,
    /// May fall asleep (usual true); `false` keeps it awake, and its island
    /// with it.
    pub enable_sleep: bool,
    /// Speed below which this body counts as at rest, m/s (`None`, usual:
    /// the world's sleep `linear_threshold`).
    pub sleep_threshold: Option<Real>,
    /// Opaque user value.
    pub user_data: u64,
    /// Report a body move event for this body after each step it moves
    /// (usual true, as Box2D's; the world gathers them only when its own
    /// switch is on: `WorldDef::enable_move_events` in `janus2d-world`).
    pub enable_move_events: bool,
}

impl Default for BodyDef {
    fn default() -> Self {
        BodyDef {
            body_type: BodyType::Static,
            position: Vec2::ZERO,
            angle: 0.0,
            linear_velocity: Vec2::ZERO,
            angular_velocity: 0.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            gravity_scale: 1.0,
            max_linear_speed: DEFAULT_MAX_LINEAR_SPEED,
            max_rotation: DEFAULT_MAX_ROTATION,
            mass: None,
            fixed_rotation: false,
            motion_locks: MotionLocks::NONE,
            awake: true,
            bullet: false,
            enable_sleep: true,
            sleep_threshold: None,
            user_data: 0,
            enable_move_events: true,
        }
    }
}

impl BodyDef {
    /// A dynamic body at `position`.
    pub fn dynamic(position: Vec2) -> Self {
        BodyDef {
            body_type: BodyType::Dynamic,
            position,
            ..Default::default()
        }
    }

    /// A static body at `position`.
    pub fn fixed(position: Vec2) -> Self {
        BodyDef {
            body_type: BodyType::Static,
            position,
            ..Default::default()
        }
    }

    /// A kinematic body at `position`.
    pub fn kinematic(position: Vec2) -> Self {
        BodyDef {
            body_type: BodyType::Kinematic,
            position,
            ..Default::default()
        }
    }

    /// Sets the mass properties directly (builder style).
    #[must_use]
    pub fn with_mass(mut self, mass: Real, rotational_inertia: Real) -> Self {
        self.mass = Some(BodyMass::new(mass, rotational_inertia));
        self
    }

    /// Locks or frees the rotation (builder style): a body with fixed
    /// rotation never turns.
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// let def = BodyDef::dynamic(Vec2::ZERO).with_fixed_rotation(true).with_user_data(7);
    /// assert!(def.fixed_rotation);
    /// assert_eq!(def.user_data, 7);
    /// ```
    #[must_use]
    pub fn with_fixed_rotation(mut self, fixed: bool) -> Self {
        self.fixed_rotation = fixed;
        self
    }

    /// Locks x translation, y translation or rotation (builder style; see
    /// [`MotionLocks`]).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, MotionLocks, Vec2};
    /// let def = BodyDef::dynamic(Vec2::ZERO).with_motion_locks(MotionLocks {
    ///     linear_x: true,
    ///     linear_y: false,
    ///     angular: true,
    /// });
    /// assert!(def.motion_locks.angular && def.motion_locks.linear_x);
    /// ```
    #[must_use]
    pub fn with_motion_locks(mut self, locks: MotionLocks) -> Self {
        self.motion_locks = locks;
        self
    }

    /// Sets the opaque user value (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_user_data(9).user_data, 9);
    /// ```
    #[must_use]
    pub fn with_user_data(mut self, value: u64) -> Self {
        self.user_data = value;
        self
    }

    /// Turns the body's move events on or off (builder style; see
    /// [`BodyDef::enable_move_events`]).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// let def = BodyDef::dynamic(Vec2::ZERO).with_move_events(false);
    /// assert!(!def.enable_move_events);
    /// ```
    #[must_use]
    pub fn with_move_events(mut self, on: bool) -> Self {
        self.enable_move_events = on;
        self
    }

    /// Sets the angle (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_angle(0.5).angle, 0.5);
    /// ```
    #[must_use]
    pub fn with_angle(mut self, angle: Real) -> Self {
        self.angle = angle;
        self
    }

    /// Sets the linear velocity (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::Y).linear_velocity, Vec2::Y);
    /// ```
    #[must_use]
    pub fn with_velocity(mut self, v: Vec2) -> Self {
        self.linear_velocity = v;
        self
    }

    /// Sets the angular velocity (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_angular_velocity(2.0).angular_velocity, 2.0);
    /// ```
    #[must_use]
    pub fn with_angular_velocity(mut self, w: Real) -> Self {
        self.angular_velocity = w;
        self
    }

    /// Sets the position (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_position(Vec2::X).position, Vec2::X);
    /// ```
    #[must_use]
    pub fn with_position(mut self, position: Vec2) -> Self {
        self.position = position;
        self
    }

    /// Sets the linear damping, 1/s (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// let def = BodyDef::dynamic(Vec2::ZERO)
    ///     .with_linear_damping(0.5)
    ///     .with_angular_damping(0.2)
    ///     .with_gravity_scale(0.0)
    ///     .with_awake(false)
    ///     .with_enable_sleep(true)
    ///     .with_sleep_threshold(Some(0.01))
    ///     .with_max_linear_speed(50.0);
    /// assert_eq!((def.linear_damping, def.angular_damping, def.gravity_scale), (0.5, 0.2, 0.0));
    /// assert!(!def.awake && def.enable_sleep);
    /// assert_eq!((def.sleep_threshold, def.max_linear_speed), (Some(0.01), 50.0));
    /// ```
    #[must_use]
    pub fn with_linear_damping(mut self, damping: Real) -> Self {
        self.linear_damping = damping;
        self
    }

    /// Sets the angular damping, 1/s (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_angular_damping(0.4).angular_damping, 0.4);
    /// ```
    #[must_use]
    pub fn with_angular_damping(mut self, damping: Real) -> Self {
        self.angular_damping = damping;
        self
    }

    /// Sets the gravity scale (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_gravity_scale(-1.0).gravity_scale, -1.0);
    /// ```
    #[must_use]
    pub fn with_gravity_scale(mut self, scale: Real) -> Self {
        self.gravity_scale = scale;
        self
    }

    /// Starts the body awake or asleep (builder style; see [`BodyDef::awake`]).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert!(!BodyDef::dynamic(Vec2::ZERO).with_awake(false).awake);
    /// ```
    #[must_use]
    pub fn with_awake(mut self, awake: bool) -> Self {
        self.awake = awake;
        self
    }

    /// Lets the body fall asleep or not (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert!(!BodyDef::dynamic(Vec2::ZERO).with_enable_sleep(false).enable_sleep);
    /// ```
    #[must_use]
    pub fn with_enable_sleep(mut self, on: bool) -> Self {
        self.enable_sleep = on;
        self
    }

    /// Sets the body's own rest speed, m/s, or `None` for the world's
    /// (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_sleep_threshold(Some(0.1)).sleep_threshold, Some(0.1));
    /// ```
    #[must_use]
    pub fn with_sleep_threshold(mut self, threshold: Option<Real>) -> Self {
        self.sleep_threshold = threshold;
        self
    }

    /// Sets the maximum linear speed, m/s (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_max_linear_speed(30.0).max_linear_speed, 30.0);
    /// ```
    #[must_use]
    pub fn with_max_linear_speed(mut self, speed: Real) -> Self {
        self.max_linear_speed = speed;
        self
    }

    /// Sets the maximum rotation per substep, rad (builder style).
    ///
    /// ```
    /// use janus2d_core::{BodyDef, Vec2};
    /// assert_eq!(BodyDef::dynamic(Vec2::ZERO).with_max_rotation(0.1).max_rotation, 0.1);
    /// ```
    #[must_use]
    pub fn with_max_rotation(mut self, rotation: Real) -> Self {
        self.max_rotation = rotation;
        self
    }

    /// Makes the body a bullet (builder style; see [`BodyDef::bullet`]).
    #[must_use]
    pub fn as_bullet(mut self) -> Self {
        self.bullet = true;
        self
    }
}

/// Invalid input at the body API boundary.
#[derive(Clone, Debug, PartialEq)]
pub enum BodyError {
    /// A value that must be finite is NaN or infinite (names the field).
    NonFinite(&'static str),
    /// A dynamic body with mass ≤ 0.
    NonPositiveMass,
    /// A dynamic, rotating body with rotational inertia ≤ 0.
    NonPositiveInertia,
    /// A value that must be ≥ 0 is negative (names the field).
    Negative(&'static str),
    /// The handle refers to a destroyed body or was never issued.
    StaleHandle,
    /// A finite value outside its stated range (see [`crate::limits`]):
    /// names the field and the range (for a magnitude, `min = -max`).
    OutOfBounds {
        /// The field at fault.
        field: &'static str,
        /// Smallest allowed value.
        min: Real,
        /// Largest allowed value.
        max: Real,
    },
}

impl std::fmt::Display for BodyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BodyError::NonFinite(field) => write!(f, "body field `{field}` is not finite"),
            BodyError::NonPositiveMass => write!(f, "dynamic body needs mass > 0"),
            BodyError::NonPositiveInertia => {
                write!(f, "dynamic rotating body needs rotational inertia > 0")
            }
            BodyError::Negative(field) => write!(f, "body field `{field}` is negative"),
            BodyError::StaleHandle => write!(f, "stale or foreign body handle"),
            BodyError::OutOfBounds { field, min, max } => {
                write!(f, "body field `{field}` must lie in [{min:e}, {max:e}]")
            }
        }
    }
}

impl std::error::Error for BodyError {}

/// The solver's hot per-body state: everything a constraint reads or writes
/// in every iteration, 32 bytes in f32 (64 in f64), two to a cache line.
///
/// | field   | what                                      | bytes (f32) | bytes (f64) |
/// |---------|-------------------------------------------|-------------|-------------|
/// | `v`     | linear velocity of the centre of mass      | 0..8        | 0..16       |
/// | `w`     | angular velocity                          | 8..12       | 16..24      |
/// | `flags` | what the body is ([`BodyState::MOVES`]…)   | 12..16      | 24..28 (+4 padding) |
/// | `dp`    | displacement of the centre since the step began | 16..24 | 32..48      |
/// | `dq`    | rotation since the step began             | 24..32      | 48..64      |
///
/// The inverse mass and inertia are not here: constraints load them at
/// prepare (from the body's [`BodySim`], through
/// [`SolverBody::inv_masses`] or [`BodySet::inv_masses_at`]) and keep them
/// with their own data; the velocity integration reads them from the
/// colder `sims`. A constraint can so act with masses other than the
/// body's own (a portal copy's contacts use the whole object's).
///
/// The state is 32-byte aligned: a state never straddles two cache lines.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(not(feature = "f64"), derive(bytemuck::Pod, bytemuck::Zeroable))]
#[repr(C, align(32))]
pub struct BodyState {
    /// Linear velocity of the centre of mass, m/s.
    pub v: Vec2,
    /// Angular velocity, rad/s.
    pub w: Real,
    /// What the body is, for the solver: [`BodyState::MOVES`] or 0
    /// ([`BodySim::state_flags`]). Set when a body is made or changes type
    /// or mass, and at every step's prepare; 0 in the static identity
    /// state.
    pub flags: u32,
    /// Displacement of the centre of mass since the step began, m.
    pub dp: Vec2,
    /// Rotation since the step began.
    pub dq: Rot,
}

// The hot state is half a cache line in f32 (Box2D v3's body state is
// the same 32 bytes), one line in f64.
#[cfg(not(feature = "f64"))]
const _: () = assert!(std::mem::size_of::<BodyState>() == 32);
#[cfg(feature = "f64")]
const _: () = assert!(std::mem::size_of::<BodyState>() == 64);

impl BodyState {
    /// The state every static body reads: at rest, not moved, no flags.
    pub const IDENTITY: BodyState = BodyState {
        v: Vec2::ZERO,
        w: 0.0,
        flags: 0,
        dp: Vec2::ZERO,
        dq: Rot::IDENTITY,
    };

    /// Flag: constraint impulses move the body (a dynamic body: positive
    /// inverse mass or inverse inertia).
    pub const MOVES: u32 = 1;

    /// Flag: the body never moves along world x ([`MotionLocks::linear_x`]).
    pub const LOCK_X: u32 = 2;

    /// Flag: the body never moves along world y ([`MotionLocks::linear_y`]).
    pub const LOCK_Y: u32 = 4;

    /// Zeroes the velocity components the state's lock flags forbid (no
    /// effect without locks).
    #[inline(always)]
    pub fn apply_locks(&mut self) {
        if self.flags & (Self::LOCK_X | Self::LOCK_Y) != 0 {
            if self.flags & Self::LOCK_X != 0 {
                self.v.x = 0.0;
            }
            if self.flags & Self::LOCK_Y != 0 {
                self.v.y = 0.0;
            }
        }
    }

    /// True when constraint impulses move the body ([`BodyState::MOVES`]).
    #[inline(always)]
    #[must_use]
    pub fn moves(&self) -> bool {
        self.flags & Self::MOVES != 0
    }
}

/// A body's inverse mass and inverse rotational inertia as the solver
/// applies them: what a constraint loads at prepare and keeps (zero for
/// static, kinematic and sleeping bodies).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct InvMass {
    /// Inverse mass, 1/kg.
    pub inv_mass: Real,
    /// Inverse rotational inertia, 1/(kg·m²).
    pub inv_inertia: Real,
}

impl InvMass {
    /// Infinite mass and inertia: a body impulses do not move.
    pub const ZERO: InvMass = InvMass {
        inv_mass: 0.0,
        inv_inertia: 0.0,
    };

    /// True when both are zero (impulses do not move the body).
    #[inline(always)]
    #[must_use]
    pub fn is_zero(&self) -> bool {
        self.inv_mass == 0.0 && self.inv_inertia == 0.0
    }
}

/// Per-body data the solver touches once per step or substep.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodySim {
    /// Body origin and rotation.
    pub transform: Transform,
    /// World centre of mass, m.
    pub center: Vec2,
    /// World centre of mass at the start of the step, m.
    pub center0: Vec2,
    /// Rotation at the start of the step.
    pub rotation0: Rot,
    /// Centre of mass in the body frame, m.
    pub local_center: Vec2,
    /// Accumulated force for this step, N.
    pub force: Vec2,
    /// Accumulated torque for this step, N·m.
    pub torque: Real,
    /// Mass, kg (0 for static and kinematic).
    pub mass: Real,
    /// Rotational inertia about the centre, kg·m².
    pub inertia: Real,
    /// Inverse mass, 1/kg.
    pub inv_mass: Real,
    /// Inverse rotational inertia.
    pub inv_inertia: Real,
    /// Multiplier of world gravity.
    pub gravity_scale: Real,
    /// Linear damping, 1/s.
    pub linear_damping: Real,
    /// Angular damping, 1/s.
    pub angular_damping: Real,
    /// Maximum linear speed, m/s.
    pub max_linear_speed: Real,
    /// Maximum rotation per substep, rad.
    pub max_rotation: Real,
    /// How long the body has been slow enough to sleep, s.
    pub sleep_time: Real,
    /// The handle of the body this belongs to.
    pub handle: BodyHandle,
    /// Static, kinematic or dynamic.
    pub body_type: BodyType,
    /// Swept against moving bodies too when fast ([`BodyDef::bullet`]).
    pub bullet: bool,
    /// May fall asleep ([`BodyDef::enable_sleep`]).
    pub enable_sleep: bool,
    /// Own rest speed, m/s ([`BodyDef::sleep_threshold`]).
    pub sleep_threshold: Option<Real>,
    /// The linear motion locks (the rotation lock is the record's
    /// `fixed_rotation`): [`BodyState::LOCK_X`] and
    /// [`BodyState::LOCK_Y`] bits, 0 without locks.
    pub linear_locks: u32,
    /// How far the body may travel in a step before continuous collision
    /// sweeps it, m (the world sets it from the body's solid shapes: a
    /// fraction of the smallest one's extent); `Real::MAX` without a solid
    /// shape. See [`BodySim::is_fast`].
    pub fast_travel: Real,
    /// Largest distance from the body origin to the core of a solid
    /// shape, m (0 without one): a turn moves the shapes by about this
    /// times the rotation's chord.
    pub core_reach: Real,
}

impl BodySim {
    /// Whether the pose (origin, centre of mass, rotation) is finite with
    /// every coordinate within `max_coordinate`, m (the solver's finalize
    /// and [`BodySet::reset_escaped`] ask it).
    #[inline]
    #[must_use]
    pub fn pose_within(&self, max_coordinate: Real) -> bool {
        let inside = |p: Vec2| {
            vec_is_finite(p) && p.x.abs() <= max_coordinate && p.y.abs() <= max_coordinate
        };
        inside(self.transform.p) && inside(self.center) && self.transform.q.is_finite()
    }

    /// The [`BodyState::flags`] of this body's state.
    #[inline]
    #[must_use]
    pub fn state_flags(&self) -> u32 {
        // Only a dynamic body has a positive inverse mass or inertia.
        let moves =
            self.body_type == BodyType::Dynamic && (self.inv_mass > 0.0 || self.inv_inertia > 0.0);
        let locks = if self.body_type == BodyType::Dynamic {
            self.linear_locks
        } else {
            0
        };
        locks | if moves { BodyState::MOVES } else { 0 }
    }

    /// The inverse mass and inertia of this body.
    #[inline(always)]
    #[must_use]
    pub fn inv_masses(&self) -> InvMass {
        InvMass {
            inv_mass: self.inv_mass,
            inv_inertia: self.inv_inertia,
        }
    }

    /// Whether the body travelled far enough in the step for continuous
    /// collision to sweep it: `|Δc| + |Δq| · (core_reach + |local centre|)`
    /// beyond [`BodySim::fast_travel`], from the start pose (`center0`,
    /// `rotation0`) to the pose the solve wrote. A turn moves the covered
    /// region by the rotation's chord times the reach of the shapes' cores
    /// (their rounding turns in place), so a wheel spinning on its centre
    /// is not fast. A NaN travel counts as fast.
    #[must_use]
    pub fn is_fast(&self) -> bool {
        let threshold = self.fast_travel;
        if threshold == Real::MAX {
            return false; // no solid shape
        }
        let dc = self.center - self.center0;
        let (q, q0) = (self.transform.q, self.rotation0);
        let chord = Vec2::new(q.c - q0.c, q.s - q0.s);
        let arm = self.core_reach + self.local_center.length();
        let lin = dc.length_squared();
        let rot = chord.length_squared() * arm * arm;
        // |Δc| + |Δq| arm ≤ √(2 (|Δc|² + |Δq|² arm²)): most bodies need no root.
        if 2.0 * (lin + rot) <= threshold * threshold {
            return false;
        }
        // The negation of `≤`, so that a NaN travel counts as fast.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        let fast = !(lin.sqrt() + rot.sqrt() <= threshold);
        fast
    }

    /// A bound of [`BodySim::is_fast`] without a square root, for the
    /// solver's finalize ([`SolveReport::maybe_fast`](crate::solver::SolveReport::maybe_fast)): true whenever
    /// `is_fast` is, since `(a + b)² ≤ 2 (a² + b²)` twice gives
    /// `|Δc|² + |Δq|² · 2 (reach² + |local centre|²)` over a quarter of
    /// `fast_travel²`, with a factor of two to spare for rounding.
    ///
    /// ```
    /// use janus2d_core::body::{BodyDef, BodySet};
    /// use janus2d_core::math::Vec2;
    ///
    /// let mut bodies = BodySet::new();
    /// let h = bodies.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// let sim = bodies.sim_mut(h).unwrap();
    /// sim.fast_travel = 0.05; // m
    /// sim.center = Vec2::new(0.02, 0.0);
    /// assert!(!sim.may_be_fast()); // 2 cm of 5 cm: within half the limit
    /// sim.center = Vec2::new(0.04, 0.0);
    /// assert!(sim.may_be_fast() && !sim.is_fast());
    /// sim.center = Vec2::new(0.06, 0.0);
    /// assert!(sim.may_be_fast() && sim.is_fast());
    /// ```
    #[inline(always)]
    #[must_use]
    pub fn may_be_fast(&self) -> bool {
        let limit = self.fast_travel;
        if limit == Real::MAX {
            return false; // no solid shape
        }
        let (q, q0) = (self.transform.q, self.rotation0);
        let chord_sq = (q.c - q0.c) * (q.c - q0.c) + (q.s - q0.s) * (q.s - q0.s);
        let arm_sq = 2.0 * (self.core_reach * self.core_reach + self.local_center.length_squared());
        let lin_sq = (self.center - self.center0).length_squared();
        4.0 * (lin_sq + chord_sq * arm_sq) > limit * limit
    }

    fn sentinel() -> BodySim {
        BodySim {
            transform: Transform::IDENTITY,
            center: Vec2::ZERO,
            center0: Vec2::ZERO,
            rotation0: Rot::IDENTITY,
            local_center: Vec2::ZERO,
            force: Vec2::ZERO,
            torque: 0.0,
            mass: 0.0,
            inertia: 0.0,
            inv_mass: 0.0,
            inv_inertia: 0.0,
            gravity_scale: 0.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            max_linear_speed: 0.0,
            max_rotation: 0.0,
            sleep_time: 0.0,
            handle: BodyHandle::new(u32::MAX, 0, 0),
            body_type: BodyType::Static,
            bullet: false,
            enable_sleep: true,
            sleep_threshold: None,
            linear_locks: 0,
            fast_travel: Real::MAX,
            core_reach: 0.0,
        }
    }
}

/// Where a live body's data sits.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BodyLocation {
    /// Index into `sims`/`states` (≥ 1).
    Moving(u32),
    /// Index into `static_sims`.
    Static(u32),
    /// Index into `sleeping_sims`/`sleeping_states`: a dynamic or kinematic
    /// body whose island sleeps. The solver never sees it; constraints that
    /// reach it read the static identity state.
    Sleeping(u32),
}

impl BodyLocation {
    /// The state index the solver reads for a body here: its own for a
    /// moving body, 0 (the static identity) for a static or sleeping one.
    #[inline]
    #[must_use]
    pub fn state_index(self) -> u32 {
        match self {
            BodyLocation::Moving(i) => i,
            BodyLocation::Static(_) | BodyLocation::Sleeping(_) => 0,
        }
    }
}

/// Bookkeeping for one live body (its slot's generation is kept by the
/// [`Slots`] that hold the records).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodyRecord {
    /// Where the body lives.
    pub location: BodyLocation,
    /// Opaque user value.
    pub user_data: u64,
    /// True when the mass was set directly rather than from shapes.
    pub mass_override: bool,
    /// True when rotation is locked.
    pub fixed_rotation: bool,
    /// Reports move events ([`BodyDef::enable_move_events`]).
    pub enable_move_events: bool,
    /// True while the body is disabled (`World::set_body_enabled`): it is
    /// kept with the sleeping bodies, with its velocities, and
    /// [`BodySet::wake`] leaves it there.
    pub disabled: bool,
}

/// A body as the solver sees it during prepare: its state slot and its data.
#[derive(Clone, Copy, Debug)]
pub struct SolverBody<'a> {
    /// Index into the state array (0 for static bodies).
    pub state_index: u32,
    /// The body's per-step data.
    pub sim: &'a BodySim,
    /// The body's current state (velocities, position deltas).
    pub state: &'a BodyState,
    /// The body is asleep (state index 0, with a sleeping body's data).
    pub sleeping: bool,
}

impl SolverBody<'_> {
    /// The inverse mass and inertia the solve applies to the body: its own
    /// for a body with a state, zero for the static identity state 0
    /// (static, sleeping and stale bodies).
    #[inline(always)]
    #[must_use]
    pub fn inv_masses(&self) -> InvMass {
        if self.state_index == 0 {
            InvMass::ZERO
        } else {
            self.sim.inv_masses()
        }
    }
}

/// Storage of every body, with generational handles.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BodySet {
    owner: u32,
    records: Slots<BodyRecord>,
    /// Per-step data of moving bodies; index 0 is the static sentinel.
    pub sims: Vec<BodySim>,
    /// Hot state of moving bodies; index 0 is [`BodyState::IDENTITY`].
    pub states: Vec<BodyState>,
    /// Per-step data of static bodies.
    pub static_sims: Vec<BodySim>,
    /// Per-step data of sleeping bodies.
    pub sleeping_sims: Vec<BodySim>,
    /// States of sleeping bodies (kept for when they wake).
    pub sleeping_states: Vec<BodyState>,
    identity_sim: BodySim,
}

impl Default for BodySet {
    fn default() -> Self {
        Self::new()
    }
}

fn check_finite(v: Real, field: &'static str) -> Result<(), BodyError> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(BodyError::NonFinite(field))
    }
}

fn check_finite_vec(v: Vec2, field: &'static str) -> Result<(), BodyError> {
    if vec_is_finite(v) {
        Ok(())
    } else {
        Err(BodyError::NonFinite(field))
    }
}

/// `|v| ≤ max` for a finite `v` (the caller checked finiteness).
fn check_magnitude(v: Real, max: Real, field: &'static str) -> Result<(), BodyError> {
    if v.abs() <= max {
        Ok(())
    } else {
        Err(BodyError::OutOfBounds {
            field,
            min: -max,
            max,
        })
    }
}

/// A body position: finite, each coordinate within
/// [`MAX_COORDINATE`](crate::limits::MAX_COORDINATE).
pub fn check_position(p: Vec2, field: &'static str) -> Result<(), BodyError> {
    check_finite_vec(p, field)?;
    let max = crate::limits::MAX_COORDINATE;
    check_magnitude(p.x, max, field)?;
    check_magnitude(p.y, max, field)
}

/// A linear velocity: finite, its length within
/// [`MAX_SPEED`](crate::limits::MAX_SPEED).
pub fn check_velocity(v: Vec2, field: &'static str) -> Result<(), BodyError> {
    check_finite_vec(v, field)?;
    let max = crate::limits::MAX_SPEED;
    check_magnitude(v.x, max, field)?;
    check_magnitude(v.y, max, field)?;
    check_magnitude(v.length(), max, field)
}

/// An angular velocity: finite, within
/// [`MAX_ANGULAR_SPEED`](crate::limits::MAX_ANGULAR_SPEED).
pub fn check_angular_velocity(w: Real, field: &'static str) -> Result<(), BodyError> {
    check_finite(w, field)?;
    check_magnitude(w, crate::limits::MAX_ANGULAR_SPEED, field)
}

/// Validates a body definition without creating anything.
pub fn validate_body_def(def: &BodyDef) -> Result<(), BodyError> {
    check_position(def.position, "position")?;
    check_finite(def.angle, "angle")?;
    check_velocity(def.linear_velocity, "linear_velocity")?;
    check_angular_velocity(def.angular_velocity, "angular_velocity")?;
    check_finite(def.linear_damping, "linear_damping")?;
    check_finite(def.angular_damping, "angular_damping")?;
    check_finite(def.gravity_scale, "gravity_scale")?;
    check_magnitude(
        def.gravity_scale,
        crate::limits::MAX_GRAVITY_SCALE,
        "gravity_scale",
    )?;
    check_finite(def.max_linear_speed, "max_linear_speed")?;
    check_finite(def.max_rotation, "max_rotation")?;
    if def.linear_damping < 0.0 {
        return Err(BodyError::Negative("linear_damping"));
    }
    if def.angular_damping < 0.0 {
        return Err(BodyError::Negative("angular_damping"));
    }
    if def.max_linear_speed < 0.0 {
        return Err(BodyError::Negative("max_linear_speed"));
    }
    check_magnitude(
        def.max_linear_speed,
        crate::limits::MAX_SPEED,
        "max_linear_speed",
    )?;
    if def.max_rotation < 0.0 {
        return Err(BodyError::Negative("max_rotation"));
    }
    if let Some(t) = def.sleep_threshold {
        check_finite(t, "sleep_threshold")?;
        if t < 0.0 {
            return Err(BodyError::Negative("sleep_threshold"));
        }
    }
    if let Some(m) = def.mass {
        validate_mass(
            def.body_type,
            &m,
            def.fixed_rotation || def.motion_locks.angular,
        )?;
    }
    Ok(())
}

/// Validates mass properties for a body of the given type: a dynamic
/// body's mass within [`MASS_RANGE`](crate::limits::MASS_RANGE), its
/// rotational inertia (unless `fixed_rotation`) within
/// [`INERTIA_RANGE`](crate::limits::INERTIA_RANGE), the centre within
/// [`MAX_EXTENT`](crate::limits::MAX_EXTENT) of the origin.
pub fn validate_mass(
    body_type: BodyType,
    m: &BodyMass,
    fixed_rotation: bool,
) -> Result<(), BodyError> {
    check_finite(m.mass, "mass")?;
    check_finite(m.rotational_inertia, "rotational_inertia")?;
    check_finite_vec(m.center, "center")?;
    if body_type == BodyType::Dynamic {
        if m.mass <= 0.0 {
            return Err(BodyError::NonPositiveMass);
        }
        if !fixed_rotation && m.rotational_inertia <= 0.0 {
            return Err(BodyError::NonPositiveInertia);
        }
        let (lo, hi) = crate::limits::MASS_RANGE;
        if !crate::limits::in_range(m.mass, (lo, hi)) {
            return Err(BodyError::OutOfBounds {
                field: "mass",
                min: lo,
                max: hi,
            });
        }
        let (lo, hi) = crate::limits::INERTIA_RANGE;
        if !fixed_rotation && !crate::limits::in_range(m.rotational_inertia, (lo, hi)) {
            return Err(BodyError::OutOfBounds {
                field: "rotational_inertia",
                min: lo,
                max: hi,
            });
        }
        let max = crate::limits::MAX_EXTENT;
        check_magnitude(m.center.x, max, "center")?;
        check_magnitude(m.center.y, max, "center")?;
    }
    Ok(())
}

impl BodySet {
    /// An empty set (holding only the static sentinel).
    pub fn new() -> Self {
        BodySet {
            owner: next_owner_id(),
            records: Slots::default(),
            sims: vec![BodySim::sentinel()],
            states: vec![BodyState::IDENTITY],
            static_sims: Vec::new(),
            sleeping_sims: Vec::new(),
            sleeping_states: Vec::new(),
            identity_sim: BodySim::sentinel(),
        }
    }

    /// The id stamped on every handle this set issues.
    pub fn owner(&self) -> u32 {
        self.owner
    }

    /// Number of live bodies.
    pub fn len(&self) -> usize {
        self.sims.len() - 1 + self.static_sims.len() + self.sleeping_sims.len()
    }

    /// Number of sleeping bodies.
    pub fn sleeping_count(&self) -> usize {
        self.sleeping_sims.len()
    }

    /// Puts a moving body to sleep: it leaves the solver's arrays (at rest)
    /// until [`BodySet::wake`]. No effect on static or sleeping bodies.
    pub fn sleep(&mut self, handle: BodyHandle) {
        let Some(BodyLocation::Moving(i)) = self.location(handle) else {
            return;
        };
        let i = i as usize;
        let sim = self.sims.swap_remove(i);
        let mut state = self.states.swap_remove(i);
        if i < self.sims.len() {
            let moved = self.sims[i].handle;
            self.records.live_mut(moved.index).location = BodyLocation::Moving(i as u32);
        }
        state.v = Vec2::ZERO;
        state.w = 0.0;
        state.dp = Vec2::ZERO;
        state.dq = Rot::IDENTITY;
        self.sleeping_sims.push(sim);
        self.sleeping_states.push(state);
        self.records.live_mut(handle.index).location =
            BodyLocation::Sleeping((self.sleeping_sims.len() - 1) as u32);
    }

    /// Wakes a sleeping body (back into the solver's arrays, timer reset).
    /// No effect on other bodies.
    pub fn wake(&mut self, handle: BodyHandle) {
        let Some(BodyLocation::Sleeping(j)) = self.location(handle) else {
            return;
        };
        if self.records.live(handle.index).disabled {
            return;
        }
        let j = j as usize;
        let mut sim = self.sleeping_sims.swap_remove(j);
        let state = self.sleeping_states.swap_remove(j);
        if j < self.sleeping_sims.len() {
            let moved = self.sleeping_sims[j].handle;
            self.records.live_mut(moved.index).location = BodyLocation::Sleeping(j as u32);
        }
        sim.sleep_time = 0.0;
        self.sims.push(sim);
        self.states.push(state);
        self.records.live_mut(handle.index).location =
            BodyLocation::Moving((self.sims.len() - 1) as u32);
    }

    /// Disables a live body (or enables it again): a disabled moving body
    /// leaves the solver's arrays for the sleeping ones with its
    /// velocities kept (unlike [`BodySet::sleep`]), and stays there until
    /// enabled; a static body only records the flag. Enabling brings a
    /// moving body back into the solver.
    pub fn set_disabled(&mut self, handle: BodyHandle, disabled: bool) {
        let Some(loc) = self.location(handle) else {
            return;
        };
        if disabled {
            if let BodyLocation::Moving(i) = loc {
                let i = i as usize;
                let sim = self.sims.swap_remove(i);
                let mut state = self.states.swap_remove(i);
                if i < self.sims.len() {
                    let moved = self.sims[i].handle;
                    self.records.live_mut(moved.index).location = BodyLocation::Moving(i as u32);
                }
                state.dp = Vec2::ZERO;
                state.dq = Rot::IDENTITY;
                self.sleeping_sims.push(sim);
                self.sleeping_states.push(state);
                self.records.live_mut(handle.index).location =
                    BodyLocation::Sleeping((self.sleeping_sims.len() - 1) as u32);
            }
            self.records.live_mut(handle.index).disabled = true;
        } else {
            self.records.live_mut(handle.index).disabled = false;
            self.wake(handle);
        }
    }

    /// True when the body is disabled ([`BodySet::set_disabled`]).
    pub fn is_disabled(&self, handle: BodyHandle) -> bool {
        self.record(handle).is_some_and(|r| r.disabled)
    }

    /// True when the body sleeps.
    pub fn is_sleeping(&self, handle: BodyHandle) -> bool {
        matches!(self.location(handle), Some(BodyLocation::Sleeping(_)))
    }

    /// True when there are no bodies.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Number of moving (dynamic or kinematic) bodies.
    pub fn moving_count(&self) -> usize {
        self.sims.len() - 1
    }

    /// Creates a body. Bad input returns an error and changes nothing.
    pub fn create(&mut self, def: &BodyDef) -> Result<BodyHandle, BodyError> {
        validate_body_def(def)?;
        // The location is set once the body's data is placed below.
        let (index, generation) = self.records.insert(BodyRecord {
            location: BodyLocation::Static(u32::MAX),
            user_data: def.user_data,
            mass_override: def.mass.is_some(),
            fixed_rotation: def.fixed_rotation || def.motion_locks.angular,
            enable_move_events: def.enable_move_events,
            disabled: false,
        });
        let handle = BodyHandle::new(index, generation, self.owner);
        let transform = Transform::new(def.position, def.angle);
        let mass = def.mass.unwrap_or(BodyMass::new(1.0, 1.0));
        let mut sim = BodySim {
            transform,
            center: transform.p,
            center0: transform.p,
            rotation0: transform.q,
            local_center: Vec2::ZERO,
            force: Vec2::ZERO,
            torque: 0.0,
            mass: 0.0,
            inertia: 0.0,
            inv_mass: 0.0,
            inv_inertia: 0.0,
            gravity_scale: def.gravity_scale,
            linear_damping: def.linear_damping,
            angular_damping: def.angular_damping,
            max_linear_speed: def.max_linear_speed,
            max_rotation: def.max_rotation,
            sleep_time: 0.0,
            handle,
            body_type: def.body_type,
            bullet: def.bullet,
            enable_sleep: def.enable_sleep,
            sleep_threshold: def.sleep_threshold,
            linear_locks: def.motion_locks.linear_flags(),
            fast_travel: Real::MAX,
            core_reach: 0.0,
        };
        let location = if def.body_type == BodyType::Static {
            self.static_sims.push(sim);
            BodyLocation::Static((self.static_sims.len() - 1) as u32)
        } else {
            let state = BodyState {
                v: def.linear_velocity,
                w: def.angular_velocity,
                flags: sim.state_flags(),
                ..BodyState::IDENTITY
            };
            sim.center = transform.p;
            self.sims.push(sim);
            self.states.push(state);
            BodyLocation::Moving((self.sims.len() - 1) as u32)
        };
        self.records.live_mut(index).location = location;
        if def.body_type == BodyType::Dynamic {
            self.apply_mass(handle, mass, def.fixed_rotation || def.motion_locks.angular);
            // Velocity given for the origin: keep it for the centre (same when
            // the centre is at the origin; otherwise add ω × r).
            if let BodyLocation::Moving(i) = self.records.live(index).location {
                let sim = &self.sims[i as usize];
                let r = sim.center - sim.transform.p;
                let st = &mut self.states[i as usize];
                st.v += crate::math::cross_sv(st.w, r);
            }
        }
        Ok(handle)
    }

    /// Sets mass properties on a live body (no validation: call
    /// [`validate_mass`] first). Keeps the origin fixed and moves the centre.
    pub fn apply_mass(&mut self, handle: BodyHandle, m: BodyMass, fixed_rotation: bool) {
        let Some(loc) = self.location(handle) else {
            return;
        };
        // A disabled body is kept with the sleeping ones: its mass follows
        // too.
        let (sim, state) = match loc {
            BodyLocation::Moving(i) => (&mut self.sims[i as usize], &mut self.states[i as usize]),
            BodyLocation::Sleeping(j) => (
                &mut self.sleeping_sims[j as usize],
                &mut self.sleeping_states[j as usize],
            ),
            BodyLocation::Static(_) => return,
        };
        if sim.body_type != BodyType::Dynamic {
            return;
        }
        sim.mass = m.mass;
        sim.inv_mass = 1.0 / m.mass;
        sim.inertia = if fixed_rotation {
            0.0
        } else {
            m.rotational_inertia
        };
        sim.inv_inertia = if fixed_rotation || m.rotational_inertia <= 0.0 {
            0.0
        } else {
            1.0 / m.rotational_inertia
        };
        sim.local_center = m.center;
        sim.center = sim.transform.apply(m.center);
        sim.center0 = sim.center;
        state.flags = sim.state_flags();
    }

    /// Removes a body's data from the array `loc` names (the last entry
    /// moves into its place) and returns it; its record is left to the
    /// caller. A static body's state is the identity.
    fn take(&mut self, loc: BodyLocation) -> (BodySim, BodyState) {
        match loc {
            BodyLocation::Moving(i) => {
                let i = i as usize;
                let sim = self.sims.swap_remove(i);
                let state = self.states.swap_remove(i);
                if i < self.sims.len() {
                    let moved = self.sims[i].handle;
                    self.records.live_mut(moved.index).location = BodyLocation::Moving(i as u32);
                }
                (sim, state)
            }
            BodyLocation::Static(j) => {
                let j = j as usize;
                let sim = self.static_sims.swap_remove(j);
                if j < self.static_sims.len() {
                    let moved = self.static_sims[j].handle;
                    self.records.live_mut(moved.index).location = BodyLocation::Static(j as u32);
                }
                (sim, BodyState::IDENTITY)
            }
            BodyLocation::Sleeping(j) => {
                let j = j as usize;
                let sim = self.sleeping_sims.swap_remove(j);
                let state = self.sleeping_states.swap_remove(j);
                if j < self.sleeping_sims.len() {
                    let moved = self.sleeping_sims[j].handle;
                    self.records.live_mut(moved.index).location = BodyLocation::Sleeping(j as u32);
                }
                (sim, state)
            }
        }
    }

    /// Puts back every moving body whose pose (origin, rotation or centre)
    /// is not finite or has a coordinate beyond `max_coordinate` back at its
    /// start-of-step pose (`center0`, `rotation0`), at rest, and appends
    /// its handle to `out`. Run after a solve: the solver's own check sees
    /// velocities and deltas, this one the pose they produced.
    pub fn reset_escaped(&mut self, max_coordinate: Real, out: &mut Vec<BodyHandle>) {
        let BodySet { sims, states, .. } = self;
        for (sim, state) in sims.iter_mut().zip(states.iter_mut()).skip(1) {
            if sim.pose_within(max_coordinate) {
                continue;
            }
            sim.center = sim.center0;
            sim.transform.q = sim.rotation0;
            sim.transform.p = sim.center - sim.transform.q.rotate(sim.local_center);
            state.v = Vec2::ZERO;
            state.w = 0.0;
            state.dp = Vec2::ZERO;
            state.dq = Rot::IDENTITY;
            if !out.contains(&sim.handle) {
                out.push(sim.handle);
            }
        }
    }

    /// Checks the set's own invariants (for `World::validate`): records ↔
    /// arrays (each live record's location holds a sim with its handle,
    /// static bodies in the static array and nowhere else, every array
    /// entry owned by a live record), the sentinel state, and every stored
    /// number finite with a dynamic body's inverse mass `1 / mass`. The
    /// error says what is wrong.
    pub fn check_invariants(&self) -> Result<(), String> {
        if self.sims.len() != self.states.len() || self.sims.is_empty() {
            return Err("sims and states differ in length".into());
        }
        if self.sleeping_sims.len() != self.sleeping_states.len() {
            return Err("sleeping sims and states differ in length".into());
        }
        if self.states[0] != BodyState::IDENTITY {
            return Err("the static sentinel state is not the identity".into());
        }
        self.records
            .check()
            .map_err(|e| format!("body slots: {e}"))?;
        let mut live = 0usize;
        for (index, record) in self.records.iter() {
            live += 1;
            let handle = BodyHandle::new(index, self.records.generation(index), self.owner);
            let (sim, is_static) = match record.location {
                BodyLocation::Moving(i) if i >= 1 => (self.sims.get(i as usize), false),
                BodyLocation::Moving(_) => (None, false),
                BodyLocation::Static(j) => (self.static_sims.get(j as usize), true),
                BodyLocation::Sleeping(j) => (self.sleeping_sims.get(j as usize), false),
            };
            let Some(sim) = sim else {
                return Err(format!(
                    "body {index}: location {:?} out of its array",
                    record.location
                ));
            };
            if sim.handle != handle {
                return Err(format!(
                    "body {index}: its array entry belongs to {:?}",
                    sim.handle
                ));
            }
            if is_static != (sim.body_type == BodyType::Static) {
                return Err(format!(
                    "body {index}: type {:?} in the wrong array",
                    sim.body_type
                ));
            }
        }
        if live != self.len() {
            return Err(format!(
                "{live} live records but {} array entries",
                self.len()
            ));
        }
        let moving = self.sims.iter().zip(&self.states).skip(1);
        let sleeping = self.sleeping_sims.iter().zip(&self.sleeping_states);
        let statics = self.static_sims.iter().map(|s| (s, &BodyState::IDENTITY));
        for (sim, state) in moving.chain(sleeping).chain(statics) {
            let reals = [
                sim.torque,
                sim.mass,
                sim.inertia,
                sim.inv_mass,
                sim.inv_inertia,
                sim.gravity_scale,
                sim.linear_damping,
                sim.angular_damping,
                sim.max_linear_speed,
                sim.max_rotation,
                sim.sleep_time,
                state.w,
            ];
            let vecs = [
                sim.transform.p,
                sim.center,
                sim.center0,
                sim.local_center,
                sim.force,
                state.v,
                state.dp,
            ];
            let finite = reals.iter().all(|x| x.is_finite())
                && vecs.iter().all(|v| vec_is_finite(*v))
                && sim.transform.q.is_finite()
                && sim.rotation0.is_finite()
                && state.dq.is_finite();
            if !finite {
                return Err(format!(
                    "body {:?}: a stored number is not finite",
                    sim.handle
                ));
            }
            if !(sim.transform.q.is_unit() && sim.rotation0.is_unit()) {
                return Err(format!(
                    "body {:?}: rotation not of unit length",
                    sim.handle
                ));
            }
            // The centre of mass is where the transform puts the local
            // centre (every step's finalize sets `p = c − q r`; creation and
            // mass changes set `c = p + q r`), to the rounding of the
            // largest term. A decoded body whose local centre disagreed
            // kept a sane centre and threw its origin out at the next step.
            let expected = sim.transform.p + sim.transform.q.rotate(sim.local_center);
            // (Components, not lengths: a length squares, and overflows.)
            let size =
                1.0 + sim.transform.p.abs().max_element() + sim.local_center.abs().max_element();
            if (sim.center - expected).abs().max_element() > 1e-5 * size {
                return Err(format!(
                    "body {:?}: centre of mass {:?} is not where its transform puts it ({expected:?})",
                    sim.handle, sim.center
                ));
            }
            if !(sim.max_linear_speed >= 0.0
                && sim.max_linear_speed <= crate::limits::MAX_SPEED
                && sim.max_rotation >= 0.0
                && sim.linear_damping >= 0.0
                && sim.angular_damping >= 0.0
                && sim.gravity_scale.abs() <= crate::limits::MAX_GRAVITY_SCALE
                && sim
                    .sleep_threshold
                    .is_none_or(|t| t.is_finite() && t >= 0.0))
            {
                return Err(format!("body {:?}: a setting out of its range", sim.handle));
            }
            if sim.linear_locks & !(BodyState::LOCK_X | BodyState::LOCK_Y) != 0 {
                return Err(format!(
                    "body {:?}: linear lock bits {:#x}",
                    sim.handle, sim.linear_locks
                ));
            }
            let fixed = self.record(sim.handle).is_some_and(|r| r.fixed_rotation);
            if sim.body_type == BodyType::Dynamic && fixed && sim.inv_inertia != 0.0 {
                return Err(format!(
                    "dynamic body {:?}: fixed rotation with inverse inertia {}",
                    sim.handle, sim.inv_inertia
                ));
            }
            if sim.body_type == BodyType::Dynamic && !(sim.mass > 0.0 && sim.inv_mass > 0.0) {
                return Err(format!(
                    "dynamic body {:?}: mass {} inverse {}",
                    sim.handle, sim.mass, sim.inv_mass
                ));
            }
        }
        Ok(())
    }

    /// Destroys a body; its slot's generation makes old handles stale.
    pub fn destroy(&mut self, handle: BodyHandle) -> Result<(), BodyError> {
        let loc = self.location(handle).ok_or(BodyError::StaleHandle)?;
        self.take(loc);
        self.records.remove(handle.index, handle.generation);
        Ok(())
    }

    /// Exchanges the identities of two live bodies: afterwards handle `a`
    /// refers to what was body `b` (its pose, velocity, mass, user data) and
    /// `b` to what was `a`. Used when an object hands over through a portal,
    /// so the user's handle follows the object.
    pub fn swap_identity(&mut self, a: BodyHandle, b: BodyHandle) -> Result<(), BodyError> {
        let la = self.location(a).ok_or(BodyError::StaleHandle)?;
        let lb = self.location(b).ok_or(BodyError::StaleHandle)?;
        let (ia, ib) = (a.index, b.index);
        let ra = self.records.live(ia).clone();
        let rb = self.records.live(ib).clone();
        *self.records.live_mut(ia) = BodyRecord { location: lb, ..rb };
        *self.records.live_mut(ib) = BodyRecord { location: la, ..ra };
        let set_handle = |set: &mut BodySet, loc: BodyLocation, h: BodyHandle| match loc {
            BodyLocation::Moving(i) => set.sims[i as usize].handle = h,
            BodyLocation::Static(j) => set.static_sims[j as usize].handle = h,
            BodyLocation::Sleeping(j) => set.sleeping_sims[j as usize].handle = h,
        };
        set_handle(self, lb, a);
        set_handle(self, la, b);
        Ok(())
    }

    /// Changes a live body's type, moving its data between the moving and
    /// static arrays. A body that stops being dynamic loses its mass (0, as
    /// every static and kinematic body); one that becomes static stops; one
    /// that becomes dynamic gets 1 kg and 1 kg·m² about its origin until
    /// the caller sets its mass ([`BodySet::apply_mass`]). A sleeping body
    /// comes back awake. Velocities of a body that keeps moving are kept.
    pub fn set_body_type(&mut self, handle: BodyHandle, ty: BodyType) -> Result<(), BodyError> {
        let loc = self.location(handle).ok_or(BodyError::StaleHandle)?;
        let (mut sim, mut state) = self.take(loc);
        sim.body_type = ty;
        sim.sleep_time = 0.0;
        sim.force = Vec2::ZERO;
        sim.torque = 0.0;
        sim.mass = 0.0;
        sim.inertia = 0.0;
        sim.inv_mass = 0.0;
        sim.inv_inertia = 0.0;
        sim.local_center = Vec2::ZERO;
        sim.center = sim.transform.p;
        sim.center0 = sim.center;
        sim.rotation0 = sim.transform.q;
        state.flags = sim.state_flags();
        state.dp = Vec2::ZERO;
        state.dq = Rot::IDENTITY;
        let location = if ty == BodyType::Static {
            self.static_sims.push(sim);
            BodyLocation::Static((self.static_sims.len() - 1) as u32)
        } else {
            self.sims.push(sim);
            self.states.push(state);
            BodyLocation::Moving((self.sims.len() - 1) as u32)
        };
        let record = self.records.live_mut(handle.index);
        record.location = location;
        record.mass_override = false;
        if ty == BodyType::Dynamic {
            let fixed = record.fixed_rotation;
            self.apply_mass(handle, BodyMass::new(1.0, 1.0), fixed);
        }
        Ok(())
    }

    /// Where a live body lives, or `None` for a stale handle.
    #[inline]
    pub fn location(&self, handle: BodyHandle) -> Option<BodyLocation> {
        if handle.owner != self.owner {
            return None;
        }
        self.records
            .get(handle.index, handle.generation)
            .map(|r| r.location)
    }

    /// Where a body lives, or why its handle does not resolve.
    pub fn check(&self, handle: BodyHandle) -> Result<BodyLocation, crate::handle::HandleError> {
        if handle.owner != self.owner {
            return Err(crate::handle::HandleError::Foreign);
        }
        self.location(handle)
            .ok_or(crate::handle::HandleError::Stale)
    }

    /// True when the handle refers to a live body.
    pub fn contains(&self, handle: BodyHandle) -> bool {
        self.location(handle).is_some()
    }

    /// The record of a live body.
    pub fn record(&self, handle: BodyHandle) -> Option<&BodyRecord> {
        if handle.owner != self.owner {
            return None;
        }
        self.records.get(handle.index, handle.generation)
    }

    /// The mutable record of a live body (user data, mass override).
    pub fn record_mut(&mut self, handle: BodyHandle) -> Option<&mut BodyRecord> {
        self.location(handle)?;
        self.records.get_mut(handle.index, handle.generation)
    }

    /// The per-step data of a live body.
    pub fn sim(&self, handle: BodyHandle) -> Option<&BodySim> {
        match self.location(handle)? {
            BodyLocation::Moving(i) => self.sims.get(i as usize),
            BodyLocation::Static(j) => self.static_sims.get(j as usize),
            BodyLocation::Sleeping(j) => self.sleeping_sims.get(j as usize),
        }
    }

    /// Mutable per-step data of a live body.
    pub fn sim_mut(&mut self, handle: BodyHandle) -> Option<&mut BodySim> {
        match self.location(handle)? {
            BodyLocation::Moving(i) => self.sims.get_mut(i as usize),
            BodyLocation::Static(j) => self.static_sims.get_mut(j as usize),
            BodyLocation::Sleeping(j) => self.sleeping_sims.get_mut(j as usize),
        }
    }

    /// The hot state of a body (the identity state for a static body).
    pub fn state(&self, handle: BodyHandle) -> Option<&BodyState> {
        match self.location(handle)? {
            BodyLocation::Moving(i) => self.states.get(i as usize),
            BodyLocation::Static(_) => Some(&self.states[0]),
            BodyLocation::Sleeping(j) => self.sleeping_states.get(j as usize),
        }
    }

    /// Mutable hot state of a moving body (`None` for static bodies).
    pub fn state_mut(&mut self, handle: BodyHandle) -> Option<&mut BodyState> {
        match self.location(handle)? {
            BodyLocation::Moving(i) => self.states.get_mut(i as usize),
            BodyLocation::Static(_) => None,
            BodyLocation::Sleeping(j) => self.sleeping_states.get_mut(j as usize),
        }
    }

    /// The inverse mass and inertia the solve applies to the body with
    /// state index `i` (zero for the static identity state 0; the moving
    /// body's own otherwise, from `sims`).
    #[inline(always)]
    #[must_use]
    pub fn inv_masses_at(&self, i: u32) -> InvMass {
        if i == 0 {
            InvMass::ZERO
        } else {
            self.sims[i as usize].inv_masses()
        }
    }

    /// The state index (0 for static bodies) of a live body.
    pub fn state_index(&self, handle: BodyHandle) -> Option<u32> {
        self.location(handle).map(BodyLocation::state_index)
    }

    /// [`state_index`](Self::state_index) of the body in live slot `slot`
    /// (a handle's `index`), for a store that keeps its bodies' slots
    /// rather than their handles (the joints); `None` for a free slot.
    #[inline]
    #[must_use]
    pub fn state_index_at(&self, slot: u32) -> Option<u32> {
        self.records.at(slot).map(|r| r.location.state_index())
    }

    /// A body as the solver sees it, or the static identity for a stale handle.
    pub fn solver_body(&self, handle: BodyHandle) -> SolverBody<'_> {
        match self.location(handle) {
            Some(BodyLocation::Moving(i)) => SolverBody {
                state_index: i,
                sim: &self.sims[i as usize],
                state: &self.states[i as usize],
                sleeping: false,
            },
            Some(BodyLocation::Static(j)) => SolverBody {
                state_index: 0,
                sim: &self.static_sims[j as usize],
                state: &self.states[0],
                sleeping: false,
            },
            Some(BodyLocation::Sleeping(j)) => SolverBody {
                state_index: 0,
                sim: &self.sleeping_sims[j as usize],
                state: &self.states[0],
                sleeping: true,
            },
            None => SolverBody {
                state_index: 0,
                sim: &self.identity_sim,
                state: &self.states[0],
                sleeping: false,
            },
        }
    }

    /// [`BodySet::solver_body`] with a guess of the body's state index
    /// (`hint`, as read in an earlier step): when the moving body at `hint`
    /// is this body, its record is not looked up (a random read per body
    /// saved where the narrowphase visits every contact); otherwise, or
    /// for `hint == 0`, the record says where the body is. The same answer
    /// either way.
    #[inline]
    pub fn solver_body_hinted(&self, handle: BodyHandle, hint: u32) -> SolverBody<'_> {
        if hint != 0
            && let Some(sim) = self.sims.get(hint as usize)
            && sim.handle == handle
        {
            return SolverBody {
                state_index: hint,
                sim,
                state: &self.states[hint as usize],
                sleeping: false,
            };
        }
        self.solver_body(handle)
    }

    /// Asks for the lines [`BodySet::solver_body_hinted`] reads for state
    /// index `hint` (its sim and state), a few contacts before the
    /// narrowphase reads them: a hint only, nothing is read or changed.
    #[inline]
    pub fn prefetch_hinted(&self, hint: u32) {
        if let (Some(sim), Some(state)) =
            (self.sims.get(hint as usize), self.states.get(hint as usize))
        {
            crate::hint::prefetch_all(sim);
            crate::hint::prefetch(state);
        }
    }

    /// Handles of all live bodies in slot order (deterministic).
    pub fn handles(&self) -> impl Iterator<Item = BodyHandle> + '_ {
        self.records
            .iter()
            .map(|(i, _)| self.records.handle(i, self.owner))
    }

    /// The body type of a live body.
    pub fn body_type(&self, handle: BodyHandle) -> Option<BodyType> {
        self.sim(handle).map(|s| s.body_type)
    }

    /// Linear velocity of the centre of mass.
    pub fn linear_velocity(&self, handle: BodyHandle) -> Option<Vec2> {
        self.state(handle).map(|s| s.v)
    }

    /// Angular velocity.
    pub fn angular_velocity(&self, handle: BodyHandle) -> Option<Real> {
        self.state(handle).map(|s| s.w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_handle_is_rejected_after_slot_reuse() {
        let mut set = BodySet::new();
        let a = set.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
        set.destroy(a).unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::ONE)).unwrap();
        assert_eq!(a.index, b.index);
        assert!(set.sim(a).is_none());
        assert_eq!(set.destroy(a), Err(BodyError::StaleHandle));
        assert_eq!(set.sim(b).unwrap().transform.p, Vec2::ONE);
    }

    #[test]
    fn swap_remove_keeps_locations_consistent() {
        let mut set = BodySet::new();
        let hs: Vec<_> = (0..5)
            .map(|i| {
                set.create(&BodyDef::dynamic(Vec2::new(i as Real, 0.0)))
                    .unwrap()
            })
            .collect();
        set.destroy(hs[1]).unwrap();
        for (i, h) in hs.iter().enumerate() {
            if i == 1 {
                continue;
            }
            assert_eq!(set.sim(*h).unwrap().transform.p.x, i as Real);
        }
        assert_eq!(set.moving_count(), 4);
    }

    #[test]
    fn foreign_handle_is_rejected() {
        let mut a = BodySet::new();
        let mut b = BodySet::new();
        let ha = a.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
        let _hb = b.create(&BodyDef::dynamic(Vec2::ONE)).unwrap();
        assert!(b.sim(ha).is_none());
        assert_eq!(b.destroy(ha), Err(BodyError::StaleHandle));
        assert_eq!(b.len(), 1);
    }

    #[test]
    fn swap_identity_moves_the_handle_to_the_other_body() {
        let mut set = BodySet::new();
        let a = set.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::new(3.0, 0.0))).unwrap();
        set.swap_identity(a, b).unwrap();
        assert_eq!(set.sim(a).unwrap().transform.p, Vec2::new(3.0, 0.0));
        assert_eq!(set.sim(b).unwrap().transform.p, Vec2::ZERO);
        assert_eq!(set.sim(a).unwrap().handle, a);
        set.destroy(b).unwrap();
        assert_eq!(set.sim(a).unwrap().transform.p, Vec2::new(3.0, 0.0));
        assert_eq!(set.len(), 1);
    }

    #[test]
    fn sleep_and_wake_round_trip() {
        let mut set = BodySet::new();
        let a = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(2.0, 1.0))
            .unwrap();
        let b = set.create(&BodyDef::dynamic(Vec2::ONE)).unwrap();
        set.sleep(a);
        assert!(set.is_sleeping(a));
        assert_eq!(set.moving_count(), 1);
        assert_eq!(set.len(), 2);
        assert_eq!(set.solver_body(a).state_index, 0);
        assert_eq!(set.sim(b).unwrap().transform.p, Vec2::ONE);
        set.wake(a);
        assert!(!set.is_sleeping(a));
        assert_eq!(set.sim(a).unwrap().mass, 2.0);
        assert_eq!(set.sim(a).unwrap().inv_mass, 0.5);
        assert!(set.state(a).unwrap().moves());
        assert_eq!(set.moving_count(), 2);
    }

    #[test]
    fn state_flags_follow_the_body() {
        let mut set = BodySet::new();
        let flags = |set: &BodySet, h| set.state(h).unwrap().flags;
        let d = set.create(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
        let bullet = set
            .create(&BodyDef::dynamic(Vec2::ONE).as_bullet())
            .unwrap();
        let locked = set
            .create(&BodyDef {
                fixed_rotation: true,
                ..BodyDef::dynamic(Vec2::ONE)
            })
            .unwrap();
        let k = set.create(&BodyDef::kinematic(Vec2::ONE)).unwrap();
        let s = set.create(&BodyDef::fixed(Vec2::ONE)).unwrap();
        assert_eq!(flags(&set, d), BodyState::MOVES);
        assert_eq!(flags(&set, bullet), BodyState::MOVES);
        assert_eq!(flags(&set, locked), BodyState::MOVES, "it still translates");
        assert_eq!(flags(&set, k), 0, "impulses do not move a kinematic body");
        assert_eq!(flags(&set, s), 0, "a static body reads the identity state");
        assert_eq!(BodyState::IDENTITY.flags, 0);
        set.set_body_type(d, BodyType::Kinematic).unwrap();
        assert_eq!(flags(&set, d), 0);
        set.set_body_type(k, BodyType::Dynamic).unwrap();
        assert!(set.state(k).unwrap().moves());
        assert_eq!(set.solver_body(k).inv_masses().inv_mass, 1.0);
        assert_eq!(set.solver_body(s).inv_masses(), InvMass::ZERO);
        set.sleep(k);
        assert_eq!(set.solver_body(k).inv_masses(), InvMass::ZERO, "asleep");
    }

    #[test]
    fn bad_mass_is_rejected() {
        let mut set = BodySet::new();
        let def = BodyDef::dynamic(Vec2::ZERO).with_mass(-1.0, 1.0);
        assert_eq!(set.create(&def), Err(BodyError::NonPositiveMass));
        assert!(set.is_empty());
    }
}
