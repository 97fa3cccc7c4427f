//! The world's structure stores borrowed together, for a stage that reads
//! them and asks for changes to them.
//!
//! [`Stores`] is what the portal stage is handed at each call: it reads
//! bodies, shapes, joints and islands through the fields, writes masses,
//! velocities and joint impulses in place, and asks for every change of
//! structure (a body created or destroyed, a shape added, a joint
//! re-pointed or disabled, two bodies' identities swapped, a body woken)
//! through the store-level operations the world defines on it in
//! `world/internal.rs`, which apply each one at once.

use janus2d_core::body::BodySet;

use crate::collision::Collision;
use crate::islands::Islands;
use crate::joints::JointSet;

/// Mutable borrows of the world's bodies, joints, collision stage and
/// islands (the world's other fields are not touched by a structural
/// change).
pub(crate) struct Stores<'a> {
    /// The bodies.
    pub(crate) bodies: &'a mut BodySet,
    /// The joints.
    pub(crate) joints: &'a mut JointSet,
    /// Shapes, broadphase and contacts.
    pub(crate) collision: &'a mut Collision,
    /// Islands and sleep.
    pub(crate) islands: &'a mut Islands,
}
