//! Body switches after creation: motion locks, and enabling or disabling
//! a body.

use super::*;
use crate::error::WorldError;
use crate::joints::JointHandle;
use janus2d_core::MotionLocks;
use janus2d_core::body::{BodyHandle, BodyState, BodyType};

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

impl World {
    /// True unless the body was disabled ([`set_body_enabled`](Self::set_body_enabled)).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    /// assert!(world.is_body_enabled(b).unwrap());
    /// ```
    pub fn is_body_enabled(&self, body: BodyHandle) -> Result<bool, WorldError> {
        self.check_body(body)?;
        Ok(!self.bodies.is_disabled(body))
    }

    /// Disables a body or enables it again (as Box2D's `b2Body_Disable` /
    /// `b2Body_Enable`). A disabled body leaves the simulation but keeps
    /// its state: its shapes leave the broadphase (queries, explosions
    /// and pairs no longer see them), its contacts end (end events for
    /// touching ones), the enabled joints that hold it are switched off
    /// for as long as it is disabled, and it leaves its island and the
    /// solver with its pose and velocities kept (it is stored with the
    /// sleeping bodies: [`is_sleeping`](Self::is_sleeping) says true, and
    /// nothing wakes it). Enabling puts it back: shapes in the broadphase
    /// (their pairs found at the next step), the joints it switched off
    /// on again when their other body is enabled, an island of its own,
    /// awake, moving on from the kept pose and velocities. Setting the
    /// current value does nothing.
    ///
    /// A joint created, or switched on, while one of its bodies is
    /// disabled acts on the other body as if the disabled one were static
    /// (it is not switched off for the disabled body's sake): switch such
    /// a joint on after enabling the body.
    ///
    /// Errors (the world unchanged): a stale or foreign handle; a body
    /// that carries or is crossing a portal ([`WorldError::PortalBody`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 5.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.set_body_enabled(b, false).unwrap();
    /// for _ in 0..60 {
    ///     world.step(1.0 / 60.0).unwrap();
    /// }
    /// assert_eq!(world.position(b).unwrap().y, 5.0);
    /// world.set_body_enabled(b, true).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.position(b).unwrap().y < 5.0);
    /// ```
    pub fn set_body_enabled(&mut self, body: BodyHandle, enabled: bool) -> Result<(), WorldError> {
        if self.is_body_enabled(body)? == enabled {
            return Ok(());
        }
        if self.portals.involves(body) {
            return Err(WorldError::PortalBody);
        }
        if enabled {
            self.enable_body(body);
        } else {
            self.disable_body(body);
        }
        Ok(())
    }

    /// Takes a live, enabled body out of the simulation (see
    /// [`set_body_enabled`](Self::set_body_enabled)).
    fn disable_body(&mut self, body: BodyHandle) {
        // Awake first: a sleeping island's contacts are not where the
        // removal walks, and the body must leave an awake island.
        self.wake_touching(body);
        self.wake_island(body);
        self.collision.remove_contacts_of(body);
        let joints: smallvec::SmallVec<[JointHandle; 4]> =
            self.joints.of_body(body).iter().copied().collect();
        for j in joints {
            let on = self.joints.get(j).is_ok_and(|x| x.is_enabled());
            if on {
                let switched = self.stores().switch_joint(j, false);
                if let Ok((a, b)) = switched {
                    let other = if a == body { b } else { a };
                    self.wake_island(other);
                    self.disabled_joints.push((body, j));
                }
            }
        }
        self.collision.drop_body_proxies(body);
        self.islands.remove_body(body);
        self.bodies.set_disabled(body, true);
    }

    /// Puts a disabled body back (see
    /// [`set_body_enabled`](Self::set_body_enabled)).
    fn enable_body(&mut self, body: BodyHandle) {
        self.bodies.set_disabled(body, false);
        let Some(sim) = self.bodies.sim(body) else {
            return;
        };
        let (xf, ty) = (sim.transform, sim.body_type);
        if ty == BodyType::Dynamic {
            self.islands.add_body(body);
        }
        self.collision
            .add_body_proxies(body, &xf, ty == BodyType::Static);
        let mine: Vec<JointHandle> = self
            .disabled_joints
            .iter()
            .filter(|(b, _)| *b == body)
            .map(|(_, j)| *j)
            .collect();
        self.disabled_joints.retain(|(b, _)| *b != body);
        for j in mine {
            let Ok(joint) = self.joints.get(j) else {
                continue;
            };
            let (a, b) = joint.bodies();
            let other = if a == body { b } else { a };
            if self.bodies.is_disabled(other) {
                // Its other body is still disabled: on when that one is.
                self.disabled_joints.push((other, j));
                continue;
            }
            if self.stores().switch_joint(j, true).is_ok() {
                self.wake_island(other);
            }
        }
        self.wake_island(body);
    }

    /// Checks the disabled bodies (for `World::validate`): every joint
    /// switched off for a disabled body names a live, disabled body, and
    /// is off if it is live.
    pub(crate) fn check_disabled(&self) -> Result<(), String> {
        for &(b, j) in &self.disabled_joints {
            if !self.bodies.is_disabled(b) {
                return Err(format!("joint {j:?} kept off for enabled body {b:?}"));
            }
            if self.joints.get(j).is_ok_and(|x| x.is_enabled()) {
                return Err(format!("joint {j:?} kept off for {b:?} is on"));
            }
        }
        for h in self.bodies.handles() {
            if self.bodies.is_disabled(h) && !self.bodies.is_sleeping(h) {
                let moving = self.bodies.body_type(h) != Some(BodyType::Static);
                if moving {
                    return Err(format!("disabled body {h:?} is in the solver"));
                }
            }
            if self.bodies.is_disabled(h) && self.islands.island_id(h).is_some() {
                return Err(format!("disabled body {h:?} is in an island"));
            }
            if self.bodies.is_disabled(h) && !self.collision.contacts.of_body(h).is_empty() {
                return Err(format!("disabled body {h:?} has contacts"));
            }
        }
        Ok(())
    }
}
