//! What the collision side hands the solver for one contact: a plain
//! record of the manifold, the bodies and the mixed material, built by the
//! narrowphase while the contact is in cache and read by contact building
//! (the solver side turns it into rows). Defined here, below both sides, so
//! the collision stage needs nothing of the constraints crate.
//!
//! | type | holds |
//! |------|-------|
//! | [`ContactPointInput`] | one manifold point: anchors, separation, kept impulses |
//! | [`ContactLane`] | the bodies (handles, state indices, inverse masses), normal, points, material (friction, restitution, tangent speed, rolling resistance), the contact's index and light clusters |

use crate::body::BodyHandle;
use crate::math::{Real, Vec2};

/// Maximum points per manifold.
pub const MAX_MANIFOLD_POINTS: usize = 2;

/// No cluster (a side that is static, or not in a light cluster).
pub const NO_CLUSTER: u32 = u32::MAX;

/// One point of a contact, as the collision pipeline hands it over.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPointInput {
    /// Anchor on a relative to a's centre of mass (world frame), m.
    pub anchor_a: Vec2,
    /// Anchor on b relative to b's centre of mass (world frame), m.
    pub anchor_b: Vec2,
    /// Separation along the normal when the manifold was computed, m.
    pub separation: Real,
    /// Normal impulse kept from the last step (warm start), N·s.
    pub normal_impulse: Real,
    /// Tangent impulse kept from the last step (warm start), N·s.
    pub tangent_impulse: Real,
}

/// What the collision pipeline hands over for one contact: everything a
/// lane (or an overflow constraint) is built from.
#[derive(Clone, Copy, Debug)]
pub struct ContactLane {
    /// Body a.
    pub body_a: BodyHandle,
    /// Body b.
    pub body_b: BodyHandle,
    /// State index of body a (0: static or asleep).
    pub state_a: u32,
    /// State index of body b.
    pub state_b: u32,
    /// Inverse masses and inertias `[m_a⁻¹, i_a⁻¹, m_b⁻¹, i_b⁻¹]` the
    /// impulses act with (0 for a static, kinematic or sleeping body).
    pub inv_masses: [Real; 4],
    /// Unit normal from a to b.
    pub normal: Vec2,
    /// The manifold's points (the first `point_count`).
    pub points: [ContactPointInput; MAX_MANIFOLD_POINTS],
    /// Number of points (1 or 2).
    pub point_count: usize,
    /// Mixed friction.
    pub friction: Real,
    /// Mixed restitution.
    pub restitution: Real,
    /// Target relative tangent speed of the friction rows, m/s (a
    /// conveyor belt; 0: none). See
    /// [`mix_tangent_speed`](crate::material::mix_tangent_speed).
    pub tangent_speed: Real,
    /// Bound of the rolling row per unit normal impulse, m (rolling
    /// resistance × rolling radius; 0: no rolling row). See
    /// [`mix_rolling_resistance`](crate::material::mix_rolling_resistance).
    pub rolling_resistance: Real,
    /// The pipeline's index of the contact (impulses are stored back by it).
    pub contact_index: u32,
    /// The light cluster of each side (the light clusters of `janus2d_constraints::contact_group`,
    /// [`NO_CLUSTER`] for none): a
    /// contact with a side in a cluster goes to the overflow and is solved
    /// with the cluster's other contacts as one block.
    pub cluster: [u32; 2],
}
