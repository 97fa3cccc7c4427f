//! Joints of every kind: create, destroy, typed reads and validated
//! setters (each leaves the joint unchanged on error and wakes its
//! bodies on success).

use super::*;
use crate::error::WorldError;
use crate::joints::JointHandle;
use janus2d_constraints::{JointDefBase, JointOfKind};
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
        self.wake_island(a);
        self.wake_island(b);
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

    /// A joint of kind `K` (`Err(WrongJointKind)` for another kind):
    /// `world.joint_of::<PrismaticJoint>(h)`.
    pub fn joint_of<K: JointOfKind>(&self, joint: JointHandle) -> Result<&K, WorldError> {
        self.joints.of(joint)
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
        self.wake_island(a);
        self.wake_island(b);
        Ok(())
    }

    /// Sets a joint's limits (`lower ≤ upper`); wakes its bodies. Angles
    /// (rad) of a revolute joint, translations (m) of a prismatic or wheel
    /// joint, lengths (m) of a distance joint; a kind without limits gets
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

    /// Turns a joint's limits on or off (a kind without limits gets
    /// `Err(WrongJointKind)` and is left unchanged).
    pub fn enable_joint_limit(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_limit(joint, on);
        self.wake_pair(r)
    }

    /// Sets a joint's motor speed: rad/s for an angular motor (revolute,
    /// wheel), m/s for a linear one (prismatic, distance); the kind's
    /// bounds apply. A kind without a motor gets `Err(WrongJointKind)` and
    /// is left unchanged.
    pub fn set_joint_motor_speed(
        &mut self,
        joint: JointHandle,
        speed: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_motor_speed(joint, speed);
        self.wake_pair(r)
    }

    /// Sets the largest torque of a joint's angular motor, N·m (finite, ≥ 0):
    /// revolute, wheel. A joint without an angular motor gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_max_motor_torque(
        &mut self,
        joint: JointHandle,
        torque: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_max_motor(joint, torque, false);
        self.wake_pair(r)
    }

    /// Sets the largest force of a joint's linear motor, N (finite, ≥ 0):
    /// prismatic, distance. A joint without a linear motor gets
    /// `Err(WrongJointKind)` and is left unchanged.
    pub fn set_joint_max_motor_force(
        &mut self,
        joint: JointHandle,
        force: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_max_motor(joint, force, true);
        self.wake_pair(r)
    }

    /// Replaces a joint's definition by `def` (any field but its bodies
    /// and `collide_connected`, which are fixed for its life), keeping its
    /// impulses; wakes its bodies. A definition of another kind, a change
    /// of bodies or an invalid value gets a typed error and changes
    /// nothing.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_constraints::{RevoluteJoint, RevoluteJointDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let bob = world.create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0))).unwrap();
    /// let pin = world
    ///     .create_joint(&RevoluteJointDef::new(ground, bob, Vec2::ZERO, Vec2::new(-1.0, 0.0)).into())
    ///     .unwrap();
    /// let mut def = world.joint_of::<RevoluteJoint>(pin).unwrap().def().clone();
    /// def.base.force_threshold = 400.0;
    /// world.set_joint_def(pin, def.into()).unwrap();
    /// assert_eq!(world.joint(pin).unwrap().def_base().force_threshold, 400.0);
    /// ```
    pub fn set_joint_def(&mut self, joint: JointHandle, def: JointDef) -> Result<(), WorldError> {
        let r = self.joints.set_def(joint, def);
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
    /// A kind without a spring gets `Err(WrongJointKind)` and is left
    /// unchanged.
    pub fn set_joint_spring(
        &mut self,
        joint: JointHandle,
        hertz: Real,
        damping_ratio: Real,
    ) -> Result<(), WorldError> {
        let r = self.joints.set_spring(joint, hertz, damping_ratio);
        self.wake_pair(r)
    }

    /// Turns a joint's spring on or off (a kind without a spring gets
    /// `Err(WrongJointKind)` and is left unchanged).
    pub fn enable_joint_spring(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let r = self.joints.enable_spring(joint, on);
        self.wake_pair(r)
    }

    /// Enables or disables a joint (one a portal disabled can be enabled
    /// again).
    pub fn set_joint_enabled(&mut self, joint: JointHandle, on: bool) -> Result<(), WorldError> {
        let (a, b) = self.switch_joint(joint, on)?;
        self.wake_island(a);
        self.wake_island(b);
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

    /// The base of a joint definition whose frames sit at the world point
    /// `point` (m) on both bodies, aligned with the world's axes at their
    /// current poses (the reference angle is their current relative
    /// angle): `RevoluteJointDef::from_base(world.joint_base_at(a, b, p)?)`.
    pub fn joint_base_at(
        &self,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
    ) -> Result<JointDefBase, WorldError> {
        self.joint_base_along(body_a, body_b, point, 0.0)
    }

    /// [`World::joint_base_at`] with the frames' x axes along the world
    /// angle `axis_angle` (rad): the axis of a prismatic or wheel joint.
    pub fn joint_base_along(
        &self,
        body_a: BodyHandle,
        body_b: BodyHandle,
        point: Vec2,
        axis_angle: Real,
    ) -> Result<JointDefBase, WorldError> {
        self.check_body(body_a)?;
        self.check_body(body_b)?;
        Ok(JointDefBase::at_world_frame(
            &self.bodies,
            body_a,
            body_b,
            point,
            axis_angle,
        )?)
    }

    /// A joint's two world anchors (frame a's and frame b's origins), m.
    pub fn joint_anchors(&self, joint: JointHandle) -> Result<(Vec2, Vec2), WorldError> {
        Ok(self.joints.get(joint)?.world_anchors(&self.bodies))
    }

    /// A joint's angle `θ_b − θ_a − reference` (rad, wrapped to `[−π, π]`;
    /// the reference is its frames' `φ_a − φ_b`), for any kind.
    pub fn joint_angle(&self, joint: JointHandle) -> Result<Real, WorldError> {
        let base = self.joints.get(joint)?.def_base();
        Ok(janus2d_constraints::joint_base::relative_angle(
            &self.bodies,
            base.body_a,
            base.body_b,
            base.reference_angle(),
        ))
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
