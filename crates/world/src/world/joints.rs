//! Joints of every kind: create, destroy, typed reads and validated
//! setters (each leaves the joint unchanged on error and wakes its
//! bodies on success).

use super::*;
use crate::error::WorldError;
use crate::joints::JointHandle;
use janus2d_core::body::BodyHandle;
use janus2d_core::math::Real;

impl World {
    // ----- joints -----------------------------------------------------------

    /// Creates a joint of any kind. Its bodies and `collide_connected` are
    /// fixed for its life; with `collide_connected = false` the contacts
    /// between its bodies end (walking one body's contacts). A bad
    /// definition or a stale body gets a typed error and changes nothing.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_constraints::RevoluteJointDef;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let bob = world.create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
    /// let def = RevoluteJointDef::new(ground, bob, Vec2::ZERO, Vec2::new(-1.0, 0.0));
    /// let pin = world.create_joint(&def.into()).unwrap();
    /// assert!(world.revolute_joint(pin).is_ok());
    /// ```
    pub fn create_joint(&mut self, def: &JointDef) -> Result<JointHandle, WorldError> {
        def.validate()?;
        let (a, b) = def.bodies();
        self.check_body(a)?;
        self.check_body(b)?;
        self.wake_body(a);
        self.wake_body(b);
        let handle = self.joints.insert(def);
        self.islands.link(a, b, &self.bodies);
        if !def.collide_connected() {
            self.collision.remove_contacts_between(a, b);
        }
        Ok(handle)
    }

    /// Creates a revolute joint ([`World::create_joint`] with
    /// [`JointDef::Revolute`]).
    pub fn create_revolute_joint(
        &mut self,
        def: &RevoluteJointDef,
    ) -> Result<JointHandle, WorldError> {
        self.create_joint(&JointDef::Revolute(def.clone()))
    }

    /// Creates a weld joint ([`World::create_joint`] with
    /// [`JointDef::Weld`]).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_constraints::WeldJointDef;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let beam = world.create_body(&BodyDef::dynamic(Vec2::new(0.5, 0.0))).unwrap();
    /// let def = WeldJointDef::new(ground, beam, Vec2::ZERO, Vec2::new(-0.5, 0.0));
    /// let weld = world.create_weld_joint(&def).unwrap();
    /// assert!(world.weld_joint(weld).is_ok());
    /// assert!(world.revolute_joint(weld).is_err());
    /// ```
    pub fn create_weld_joint(&mut self, def: &WeldJointDef) -> Result<JointHandle, WorldError> {
        self.create_joint(&JointDef::Weld(def.clone()))
    }

    /// Removes a live joint, waking its bodies.
    pub(super) fn remove_joint(&mut self, joint: JointHandle) {
        self.stores().remove_joint(joint);
    }

    /// Destroys a joint.
    pub fn destroy_joint(&mut self, joint: JointHandle) -> Result<(), WorldError> {
        self.joints.kind(joint)?;
        self.remove_joint(joint);
        Ok(())
    }

    /// A joint of any kind.
    pub fn joint(&self, joint: JointHandle) -> Result<&Joint, WorldError> {
        self.joints.get(joint)
    }

    /// A revolute joint (`Err(WrongJointKind)` for another kind).
    pub fn revolute_joint(&self, joint: JointHandle) -> Result<&RevoluteJoint, WorldError> {
        self.joints.revolute(joint)
    }

    /// A weld joint (`Err(WrongJointKind)` for another kind).
    pub fn weld_joint(&self, joint: JointHandle) -> Result<&WeldJoint, WorldError> {
        self.joints.weld(joint)
    }

    /// Force the joint applied to its body b over the last solved step, N
    /// (body a got the opposite); kept while its bodies sleep.
    pub fn joint_force(&self, joint: JointHandle) -> Result<Vec2, WorldError> {
        Ok(self.joints.get(joint)?.constraint_force())
    }

    /// Torque about the joint axis (springs, motors, limits) applied to
    /// body b over the last solved step, N·m; kept while its bodies sleep.
    pub fn joint_torque(&self, joint: JointHandle) -> Result<Real, WorldError> {
        Ok(self.joints.get(joint)?.constraint_torque())
    }

    /// The joints (read access: handles, per-body lists, kinds).
    pub fn joints(&self) -> &JointSet {
        &self.joints
    }

    pub(super) fn wake_pair(
        &mut self,
        bodies: Result<(BodyHandle, BodyHandle), WorldError>,
    ) -> Result<(), WorldError> {
        let (a, b) = bodies?;
        self.wake_body(a);
        self.wake_body(b);
        Ok(())
    }

    /// Sets a joint's angle limits, rad (`lower ≤ upper`); wakes its bodies.
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_limits(
        &mut self,
        joint: JointHandle,
        lower: Real,
        upper: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_limits(joint, lower, upper);
        self.wake_pair(r)
    }

    /// Turns a joint's limit on or off.
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn enable_joint_limit(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_limit(joint, on);
        self.wake_pair(r)
    }

    /// Sets a joint's motor speed, rad/s.
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_motor_speed(
        &mut self,
        joint: JointHandle,
        speed: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_motor_speed(joint, speed);
        self.wake_pair(r)
    }

    /// Sets a joint's largest motor torque, N·m (≥ 0).
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_max_motor_torque(
        &mut self,
        joint: JointHandle,
        torque: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_max_motor_torque(joint, torque);
        self.wake_pair(r)
    }

    /// Turns a joint's motor on or off.
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn enable_joint_motor(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_motor(joint, on);
        self.wake_pair(r)
    }

    /// Sets a joint's spring: stiffness, Hz, and damping ratio (both ≥ 0).
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_spring(
        &mut self,
        joint: JointHandle,
        hertz: Real,
        damping_ratio: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_spring(joint, hertz, damping_ratio);
        self.wake_pair(r)
    }

    /// Turns a joint's spring on or off.
    /// A revolute joint's; a joint of another kind gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn enable_joint_spring(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_spring(joint, on);
        self.wake_pair(r)
    }

    /// Enables or disables a joint (one a portal disabled can be enabled
    /// again).
    pub fn set_joint_enabled(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let (a, b) = self.switch_joint(joint, on)?;
        self.wake_body(a);
        self.wake_body(b);
        Ok(())
    }

    /// Enables or disables a joint and tells the islands (see
    /// `Stores::switch_joint`); wakes nothing.
    pub(super) fn switch_joint(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        self.stores().switch_joint(joint, on)
    }

    /// Distance between a joint's two world anchors, m.
    pub fn joint_gap(&self, joint: JointHandle) -> Result<Real, WorldError> {
        Ok(self.joints.get(joint)?.gap(&self.bodies))
    }

    /// Handles of every joint, in storage order.
    pub fn joint_handles(&self) -> &[JointHandle] {
        self.joints.handles()
    }

    /// The largest joint gap in the world, m.
    pub fn max_joint_gap(&self) -> Real {
        self.joints
            .iter()
            .map(|(_, j)| j.gap(&self.bodies))
            .fold(0.0, Real::max)
    }
}

impl World {
    // ----- joints --------------------------------------------------------

    /// The joint's opaque user value (0 until set).
    pub fn joint_user_data(&self, joint: JointHandle) -> Result<u64, WorldError> {
        self.joints.user_data(joint)
    }

    /// Sets the joint's opaque user value.
    pub fn set_joint_user_data(
        &mut self,
        joint: JointHandle,
        value: u64,
    ) -> Result<(), WorldError> {
        self.joints.set_user_data(joint, value)
    }
}
