//! Snapshot and restore: a copy of everything the next step depends on.
//!
//! | held in a [`Snapshot`]                        | why the next step needs it                     |
//! |-----------------------------------------------|------------------------------------------------|
//! | bodies (poses, velocities, masses, sleep timers, slots and generations) | the state itself, and which handles are live |
//! | shapes, broadphase trees and proxies, move buffer | pairs found next step, in the same order    |
//! | contacts with their warm-start impulses and feature ids, pair index | warm starting, begin/end events |
//! | joints, their accumulated impulses, the joint forest | warm starting, the direct solve          |
//! | islands, pending sleepers, sleep settings     | who sleeps when                                |
//! | portal pairs, crossings, clones, constraints  | crossings in progress                          |
//! | settings, gravity, step count, last events, counters | the same step, and the same reads       |
//!
//! The pre-solve hook (a closure the user owns) is not part of a snapshot:
//! [`World::restore`] keeps the hook the world has. A snapshot keeps the
//! world's owner id, so handles issued by the world it was taken from
//! resolve in the restored world (and in no other).

use crate::world::World;

/// A copy of a world's whole simulation state (see [`crate::snapshot`]).
pub struct Snapshot {
    pub(crate) world: Box<World>,
}

impl Clone for Snapshot {
    fn clone(&self) -> Self {
        Snapshot {
            world: Box::new(self.world.copy_state()),
        }
    }
}

impl std::fmt::Debug for Snapshot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Snapshot")
            .field("bodies", &self.world.body_count())
            .field("step_count", &self.world.step_count())
            .finish()
    }
}

impl Snapshot {
    /// The state hash of the world the snapshot holds.
    #[must_use]
    pub fn state_hash(&self) -> u64 {
        self.world.state_hash()
    }

    /// A world continuing from the snapshot (no pre-solve hook).
    #[must_use]
    pub fn to_world(&self) -> World {
        self.world.copy_state()
    }
}

impl World {
    /// A copy of everything the next step depends on; continuing from
    /// [`restore`](Self::restore) gives bit-identical states.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// let saved = world.snapshot();
    /// for _ in 0..30 { world.step(1.0 / 60.0).unwrap(); }
    /// let after = world.state_hash();
    /// world.restore(&saved);
    /// for _ in 0..30 { world.step(1.0 / 60.0).unwrap(); }
    /// assert_eq!(world.state_hash(), after);
    /// ```
    #[must_use]
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            world: Box::new(self.copy_state()),
        }
    }

    /// Puts the world back to `snapshot` (every stage, the step count and
    /// the last events); the pre-solve hook stays as it is.
    pub fn restore(&mut self, snapshot: &Snapshot) {
        let hook = self.take_pre_solve();
        *self = snapshot.world.copy_state();
        self.set_pre_solve(hook);
    }
}
