//! Generational handles: one scheme for bodies, shapes, joints and portal
//! pairs.
//!
//! ```text
//! Handle<K> = (index, generation, owner)
//!   index       slot in the issuing store
//!   generation  the slot's generation when issued (a reused slot bumps it)
//!   owner       id of the issuing world: another world's handle is foreign
//! ```
//!
//! | alias | kind marker | issued by |
//! |-------|-------------|-----------|
//! | [`BodyHandle`](crate::body::BodyHandle) | [`BodyTag`] | `World::create_body` |
//! | `ShapeHandle` | [`ShapeTag`] | `World::create_shape` |
//! | `JointHandle` | [`JointTag`] | `World::create_revolute_joint` |
//! | `PortalPairHandle` | [`PortalPairTag`] | `World::create_portal_pair` |
//! | `ChainHandle` | [`ChainTag`] | `World::create_chain` |
//!
//! Handles of different kinds are different types, so a shape handle can
//! never be passed where a body is expected.

use std::cmp::Ordering;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::marker::PhantomData;

/// A generational handle to something of kind `K` in one world.
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(bound = ""))]
pub struct Handle<K> {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot when the handle was issued.
    pub generation: u32,
    /// Id of the world that issued the handle.
    pub owner: u32,
    #[cfg_attr(feature = "serde", serde(skip))]
    kind: PhantomData<fn() -> K>,
}

impl<K> Handle<K> {
    /// A handle to slot `index` of generation `generation` in world `owner`.
    #[must_use]
    pub const fn new(index: u32, generation: u32, owner: u32) -> Self {
        Handle {
            index,
            generation,
            owner,
            kind: PhantomData,
        }
    }
}

/// Why a handle does not resolve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandleError {
    /// What it referred to was removed (or it never existed).
    Stale,
    /// It was issued by another world.
    Foreign,
}

/// Marker of body handles.
#[derive(Clone, Copy, Debug)]
pub enum BodyTag {}
/// Marker of shape handles.
#[derive(Clone, Copy, Debug)]
pub enum ShapeTag {}
/// Marker of joint handles.
#[derive(Clone, Copy, Debug)]
pub enum JointTag {}
/// Marker of portal pair handles.
#[derive(Clone, Copy, Debug)]
pub enum PortalPairTag {}
/// Marker of chain handles.
#[derive(Clone, Copy, Debug)]
pub enum ChainTag {}

impl<K> Clone for Handle<K> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<K> Copy for Handle<K> {}
impl<K> PartialEq for Handle<K> {
    fn eq(&self, other: &Self) -> bool {
        self.key() == other.key()
    }
}
impl<K> Eq for Handle<K> {}
impl<K> Hash for Handle<K> {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.key().hash(state);
    }
}
impl<K> PartialOrd for Handle<K> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<K> Ord for Handle<K> {
    /// By index, then generation, then owner.
    fn cmp(&self, other: &Self) -> Ordering {
        self.key().cmp(&other.key())
    }
}
impl<K> fmt::Debug for Handle<K> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Handle({}v{}@{})",
            self.index, self.generation, self.owner
        )
    }
}

impl<K> Handle<K> {
    fn key(&self) -> (u32, u32, u32) {
        (self.index, self.generation, self.owner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn handles_order_by_index_then_generation() {
        let a = Handle::<BodyTag>::new(1, 2, 7);
        let b = Handle::<BodyTag>::new(2, 1, 7);
        let c = Handle::<BodyTag>::new(1, 3, 7);
        assert!(a < b && a < c && c < b);
        assert_eq!(a, Handle::new(1, 2, 7));
        assert_ne!(a, Handle::new(1, 2, 8));
    }
}
