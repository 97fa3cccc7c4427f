//! Body switches after creation: motion locks, and enabling or disabling
//! a body.

use super::*;
use crate::error::WorldError;
use janus2d_core::MotionLocks;
use janus2d_core::body::{BodyHandle, BodyState};

impl World {
    /// The body's motion locks ([`MotionLocks`]; the rotation lock is its
    /// fixed rotation).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, MotionLocks, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world
    ///     .create_body(&BodyDef::dynamic(Vec2::ZERO).with_motion_locks(MotionLocks::Y))
    ///     .unwrap();
    /// assert_eq!(world.motion_locks(b).unwrap(), MotionLocks::Y);
    /// ```
    pub fn motion_locks(&self, body: BodyHandle) -> Result<MotionLocks, WorldError> {
        let sim = self.bodies.sim(body).ok_or_else(|| self.body_error(body))?;
        let angular = self.is_fixed_rotation(body)?;
        Ok(MotionLocks {
            linear_x: sim.linear_locks & BodyState::LOCK_X != 0,
            linear_y: sim.linear_locks & BodyState::LOCK_Y != 0,
            angular,
        })
    }

    /// Locks or frees x translation, y translation and rotation (as Box2D
    /// v3.1's `b2Body_SetMotionLocks`). A locked linear axis: the body's
    /// velocity along it is zeroed now and wherever the solver integrates
    /// it, so the body never moves along it (it acts on what it touches
    /// as if its mass were infinite along that axis). The rotation lock is
    /// [`set_fixed_rotation`](Self::set_fixed_rotation). Locks act on
    /// dynamic bodies (a kinematic or static body keeps them for when it
    /// becomes dynamic). Wakes the body.
    ///
    /// Errors (the world unchanged): a stale or foreign handle; changing
    /// the locks of a body that carries or is crossing a portal
    /// ([`WorldError::PortalBody`]); those of
    /// [`set_fixed_rotation`](Self::set_fixed_rotation).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, MotionLocks, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world
    ///     .create_body(&BodyDef::dynamic(Vec2::ZERO).with_velocity(Vec2::new(3.0, 0.0)))
    ///     .unwrap();
    /// world.set_motion_locks(b, MotionLocks::Y).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// // Gravity cannot pull it down; it keeps sliding along x.
    /// assert_eq!(world.position(b).unwrap().y, 0.0);
    /// assert!((world.position(b).unwrap().x - 3.0).abs() < 1e-4);
    /// ```
    pub fn set_motion_locks(
        &mut self,
        body: BodyHandle,
        locks: MotionLocks,
    ) -> Result<(), WorldError> {
        let now = self.motion_locks(body)?;
        if now == locks {
            return Ok(());
        }
        if self.portals.involves(body) {
            return Err(WorldError::PortalBody);
        }
        // The one step that can fail comes first.
        self.set_fixed_rotation(body, locks.angular)?;
        self.wake_island(body);
        let flags = locks.linear_flags();
        let Some(sim) = self.bodies.sim_mut(body) else {
            return Err(WorldError::StaleBody);
        };
        sim.linear_locks = flags;
        let state_flags = sim.state_flags();
        if let Some(st) = self.bodies.state_mut(body) {
            st.flags = state_flags;
            st.apply_locks();
        }
        Ok(())
    }
}
