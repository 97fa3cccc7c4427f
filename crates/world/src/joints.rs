//! The joint set: joint slots and handles, per-type storage, each body's
//! joints, and which body pairs a joint keeps from colliding.
//!
//! ```text
//! JointSet
//!   slots        Slots<JointSlot>     handle → (JointKind, index in `joints`)
//!   joints       Vec<Joint>           solver form of every kind, dense (swap-remove)
//!   handles      Vec<JointHandle>     parallel to joints
//!   body_joints  body slot → [JointHandle]   (destroy body, portals walk these)
//!   no_collide   NoCollide            body pair → joints with collide_connected = false
//! ```
//!
//! A joint's bodies and `collide_connected` are fixed at creation; the
//! rest of its definition, limits, motor, spring and the enabled switch
//! change through validated setters that leave the joint unchanged on
//! error. The set never names a joint kind: typed reads go through
//! [`JointSet::of`] (`JointOfKind`), and the limit, motor and spring
//! setters through the definition's `limits_mut`, `motor_mut` and
//! `spring_mut` (`Err(WrongJointKind)` for a kind without one).

use crate::key_map::KeyMap;

pub use janus2d_constraints::JointKind;
use janus2d_constraints::{
    Joint, JointBatch, JointColours, JointDef, JointForest, JointOfKind, RevoluteJoint, WeldJoint,
};
use janus2d_core::body::{BodyHandle, BodySet};
use janus2d_core::handle::{Handle, JointTag};
use janus2d_core::math::Real;
use janus2d_core::parallel::Team;
use janus2d_core::slots::Slots;
use smallvec::SmallVec;

use crate::error::WorldError;

/// A generational handle to a joint.
pub type JointHandle = Handle<JointTag>;

/// Where a joint lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
struct JointSlot {
    kind: JointKind,
    index: u32,
}

/// A joint whose force or torque passed its threshold in the last step
/// (`JointDefBase::force_threshold`, `torque_threshold`): reported once per
/// crossing; the joint reports again only after falling back below both.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointEvent {
    /// The joint.
    pub joint: JointHandle,
    /// Its user value.
    pub user_data: u64,
    /// The force it applied to body b over the step, N.
    pub force: janus2d_core::math::Vec2,
    /// The torque it applied to body b over the step, N·m.
    pub torque: Real,
}

/// Body pairs (slot indices, ordered) that a joint with
/// `collide_connected = false` keeps from colliding, with how many such
/// joints join them.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NoCollide {
    #[cfg_attr(feature = "serde", serde(with = "crate::serde_maps::sorted_map"))]
    pairs: KeyMap<(u32, u32), u32>,
    /// `(clone, original)` body slots of the crossings in progress (set by
    /// the step from the portal stage; derived, so not in snapshots): a
    /// clone answers for its original, so the clones of two joined bodies
    /// do not collide with each other or with the other original.
    #[cfg_attr(feature = "serde", serde(skip))]
    aliases: Vec<(u32, u32)>,
}

impl NoCollide {
    /// True when a joint keeps `a` and `b` from colliding.
    #[inline]
    #[must_use]
    pub fn contains(&self, a: BodyHandle, b: BodyHandle) -> bool {
        if self.pairs.is_empty() {
            return false;
        }
        if self
            .pairs
            .contains_key(&crate::contacts::pair_key(a.index, b.index))
        {
            return true;
        }
        if self.aliases.is_empty() {
            return false;
        }
        let (ca, cb) = (self.original(a.index), self.original(b.index));
        (ca, cb) != (a.index, b.index)
            && ca != cb
            && self.pairs.contains_key(&crate::contacts::pair_key(ca, cb))
    }

    /// The original a clone's slot answers for (the slot itself when it
    /// is no clone).
    #[inline]
    fn original(&self, slot: u32) -> u32 {
        self.aliases
            .iter()
            .find(|(clone, _)| *clone == slot)
            .map_or(slot, |(_, original)| *original)
    }

    /// Sets the `(clone, original)` slot pairs of the crossings in
    /// progress.
    pub(crate) fn set_aliases(&mut self, aliases: impl Iterator<Item = (u32, u32)>) {
        self.aliases.clear();
        self.aliases.extend(aliases);
    }

    fn add(&mut self, a: BodyHandle, b: BodyHandle) {
        *self
            .pairs
            .entry(crate::contacts::pair_key(a.index, b.index))
            .or_insert(0) += 1;
    }

    fn remove(&mut self, a: BodyHandle, b: BodyHandle) {
        let key = crate::contacts::pair_key(a.index, b.index);
        if let Some(n) = self.pairs.get_mut(&key) {
            *n -= 1;
            if *n == 0 {
                self.pairs.remove(&key);
            }
        }
    }
}

/// Every joint of a world.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointSet {
    owner: u32,
    slots: Slots<JointSlot>,
    joints: Vec<Joint>,
    /// By joint (as `joints`): the slots (`BodyHandle::index`) of its
    /// bodies a and b. The colouring keys, the contacts' colour
    /// reservation and the driven bodies read them for every joint at
    /// every step; from here they stream, where the definitions are a
    /// dependent load each (the measurement is in docs/performance.md).
    body_slots: Vec<[u32; 2]>,
    handles: Vec<JointHandle>,
    body_joints: Vec<SmallVec<[JointHandle; 2]>>,
    pub(crate) no_collide: NoCollide,
    /// The joint forest of the last step (direct point-row solve). Not in
    /// snapshot bytes: it is derived from the joints and built again from
    /// them at the next step (the same build, so the continuation is
    /// unchanged), and bytes crafted past the checksum then cannot hand
    /// the tree solve an index out of range.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) forest: JointForest,
    /// The colours of the joints' Gauss–Seidel rows (derived like the
    /// forest, and like it not in snapshot bytes).
    #[cfg_attr(feature = "serde", serde(skip))]
    pub(crate) colours: JointColours,
    /// The colours the joints hold, by body slot, for the contacts' graph
    /// to leave free ([`JointSet::refresh_reserved`]; derived).
    #[cfg_attr(feature = "serde", serde(skip))]
    reserved: Vec<u32>,
    /// The colouring (generation, joint count) `reserved` was made from.
    #[cfg_attr(feature = "serde", serde(skip))]
    reserved_for: Option<(u64, usize)>,
}

impl JointSet {
    /// The body pairs the joints keep from colliding (`collide_connected =
    /// false`), for the pair filter.
    #[inline]
    pub(crate) fn no_collide(&self) -> &NoCollide {
        &self.no_collide
    }

    /// Clones answer for their originals in the no-collide pairs (set every
    /// step: crossings come and go).
    #[inline]
    pub(crate) fn set_clone_aliases(&mut self, aliases: impl Iterator<Item = (u32, u32)>) {
        self.no_collide.set_aliases(aliases);
    }

    /// An empty set for world `owner`.
    #[must_use]
    pub fn new(owner: u32) -> Self {
        JointSet {
            owner,
            ..JointSet::default()
        }
    }

    /// The owner id the set issues joint handles with (the world's).
    #[inline]
    pub(crate) fn owner(&self) -> u32 {
        self.owner
    }

    /// Number of joints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.slots.len()
    }

    /// True when there is no joint.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Handles of every joint, in storage order.
    #[must_use]
    pub fn handles(&self) -> &[JointHandle] {
        &self.handles
    }

    /// The joints attached to a body.
    #[must_use]
    pub fn of_body(&self, body: BodyHandle) -> &[JointHandle] {
        self.body_joints
            .get(body.index as usize)
            .map_or(&[], |l| l.as_slice())
    }

    /// Forgets the kept impulses of `body`'s joints: each starts again as
    /// when created from its definition (enabled or not as it was), so a
    /// body reset for a non-finite state is not driven there again by its
    /// joints' warm start.
    pub(crate) fn forget_impulses(&mut self, body: BodyHandle) {
        for j in self.of_body(body).to_vec() {
            if let Ok(joint) = self.get_mut(j) {
                let enabled = joint.is_enabled();
                *joint = Joint::new(joint.def());
                joint.set_enabled(enabled);
            }
        }
    }

    /// Checks the set against the bodies (for `World::validate`): handles
    /// ↔ slots ↔ storage, each joint's definition valid and of its slot's
    /// kind, each joint's bodies live and listing it, every
    /// body list holding live joints of that body, no-collide counts.
    pub(crate) fn check(&self, bodies: &janus2d_core::body::BodySet) -> Result<(), String> {
        if self.handles.len() != self.slots.len()
            || self.joints.len() != self.slots.len()
            || self.body_slots.len() != self.slots.len()
        {
            return Err(format!(
                "{} handles, {} slots, {} joints, {} body slot pairs",
                self.handles.len(),
                self.slots.len(),
                self.joints.len(),
                self.body_slots.len()
            ));
        }
        self.slots
            .check()
            .map_err(|e| format!("joint slots: {e}"))?;
        if self.slots.len() != self.handles.len() {
            return Err(format!(
                "{} live joint slots, {} joints",
                self.slots.len(),
                self.handles.len()
            ));
        }
        let mut no_collide: KeyMap<(u32, u32), u32> = KeyMap::default();
        for (k, &h) in self.handles.iter().enumerate() {
            let slot = self.slot(h).map_err(|e| format!("joint handle {k}: {e}"))?;
            if slot.index as usize != k {
                return Err(format!("joint {k}: its slot points at {}", slot.index));
            }
            let j = &self.joints[k];
            j.def()
                .validate()
                .map_err(|e| format!("joint {k}: its definition does not validate: {e}"))?;
            if self.slots.live(h.index).kind != j.kind() {
                return Err(format!("joint {k}: its slot names another kind"));
            }
            let (force, torque) = (j.constraint_force(), j.constraint_torque());
            if !(force.x.is_finite() && force.y.is_finite() && torque.is_finite()) {
                return Err(format!(
                    "joint {k}: read-back {force:?}, {torque} not finite"
                ));
            }
            let inv_h = j.base().inv_h();
            if !(inv_h.is_finite() && inv_h >= 0.0) {
                return Err(format!("joint {k}: step rate {inv_h}"));
            }
            let (a, b) = j.bodies();
            if self.body_slots[k] != [a.index, b.index] {
                return Err(format!(
                    "joint {k}: its kept body slots are not its bodies'"
                ));
            }
            for body in [a, b] {
                if !bodies.contains(body) {
                    return Err(format!("joint {k}: body {body:?} is not live"));
                }
                if !self.of_body(body).contains(&h) {
                    return Err(format!("joint {k}: not listed under body {body:?}"));
                }
            }
            if !j.collide_connected() {
                *no_collide
                    .entry(crate::contacts::pair_key(a.index, b.index))
                    .or_insert(0) += 1;
            }
        }
        for (b, list) in self.body_joints.iter().enumerate() {
            for h in list {
                let (ja, jb) = self
                    .bodies_of(*h)
                    .map_err(|e| format!("body slot {b} lists a dead joint: {e}"))?;
                if ja.index as usize != b && jb.index as usize != b {
                    return Err(format!("body slot {b} lists a joint of other bodies"));
                }
            }
        }
        if no_collide != self.no_collide.pairs {
            return Err("no-collide pairs differ from the joints'".into());
        }
        Ok(())
    }

    fn slot(&self, joint: JointHandle) -> Result<JointSlot, WorldError> {
        self.slots
            .resolve(joint, self.owner)
            .copied()
            .map_err(|e| WorldError::of_handle(e, WorldError::StaleJoint))
    }

    /// A joint's opaque user value (its definition's `base.user_data`).
    pub fn user_data(&self, joint: JointHandle) -> Result<u64, WorldError> {
        Ok(self.get(joint)?.def_base().user_data)
    }

    /// Sets a joint's opaque user value.
    pub(crate) fn set_user_data(
        &mut self,
        joint: JointHandle,
        value: u64,
    ) -> Result<(), WorldError> {
        let j = self.get_mut(joint)?;
        let mut def = j.def();
        def.base_mut().user_data = value;
        j.set_def(def)?;
        Ok(())
    }

    /// A joint, of any kind.
    pub fn get(&self, joint: JointHandle) -> Result<&Joint, WorldError> {
        let s = self.slot(joint)?;
        Ok(&self.joints[s.index as usize])
    }

    fn get_mut(&mut self, joint: JointHandle) -> Result<&mut Joint, WorldError> {
        let s = self.slot(joint)?;
        Ok(&mut self.joints[s.index as usize])
    }

    /// A joint of kind `K` (`Err(WrongJointKind)` for a joint of another
    /// kind).
    pub fn of<K: JointOfKind>(&self, joint: JointHandle) -> Result<&K, WorldError> {
        self.get(joint)?.of::<K>().ok_or(WorldError::WrongJointKind)
    }

    /// A revolute joint (`Err(WrongJointKind)` for a joint of another kind).
    pub fn revolute(&self, joint: JointHandle) -> Result<&RevoluteJoint, WorldError> {
        self.of(joint)
    }

    /// A weld joint (`Err(WrongJointKind)` for a joint of another kind).
    pub fn weld(&self, joint: JointHandle) -> Result<&WeldJoint, WorldError> {
        self.of(joint)
    }

    /// Every joint in storage order (parallel to [`JointSet::handles`]).
    pub fn iter(&self) -> impl Iterator<Item = (JointHandle, &Joint)> + '_ {
        self.handles.iter().copied().zip(&self.joints)
    }

    /// The solver's view of the joints: the joints, their forest and
    /// colours.
    pub(crate) fn batch(&mut self) -> JointBatch<'_> {
        JointBatch {
            joints: &mut self.joints,
            forest: &mut self.forest,
            colours: &mut self.colours,
        }
    }

    /// The type of a joint.
    pub fn kind(&self, joint: JointHandle) -> Result<JointKind, WorldError> {
        self.slot(joint).map(|s| s.kind)
    }

    /// The two bodies of a joint.
    pub fn bodies_of(&self, joint: JointHandle) -> Result<(BodyHandle, BodyHandle), WorldError> {
        Ok(self.get(joint)?.bodies())
    }

    /// Adds a joint (its definition validated and its bodies checked by
    /// the caller).
    pub(crate) fn insert(&mut self, def: &JointDef) -> JointHandle {
        let (index, generation) = self.slots.insert(JointSlot {
            kind: def.kind(),
            index: self.joints.len() as u32,
        });
        let handle = JointHandle::new(index, generation, self.owner);
        self.joints.push(Joint::new(def.clone()));
        self.handles.push(handle);
        let (a, b) = def.bodies();
        self.body_slots.push([a.index, b.index]);
        for body in [a, b] {
            let i = body.index as usize;
            if self.body_joints.len() <= i {
                self.body_joints.resize(i + 1, SmallVec::new());
            }
            self.body_joints[i].push(handle);
        }
        if !def.collide_connected() {
            self.no_collide.add(a, b);
        }
        handle
    }

    /// Removes a joint; returns its two bodies.
    pub(crate) fn remove(
        &mut self,
        joint: JointHandle,
    ) -> Result<(BodyHandle, BodyHandle, bool), WorldError> {
        let s = self.slot(joint)?;
        let i = s.index as usize;
        let j = &self.joints[i];
        let ((a, b), collide) = (j.bodies(), j.collide_connected());
        if !collide {
            self.no_collide.remove(a, b);
        }
        for body in [a, b] {
            if let Some(list) = self.body_joints.get_mut(body.index as usize)
                && let Some(k) = list.iter().position(|h| *h == joint)
            {
                list.remove(k);
            }
        }
        self.joints.swap_remove(i);
        self.body_slots.swap_remove(i);
        self.handles.swap_remove(i);
        if i < self.joints.len() {
            let moved = self.handles[i];
            if let Some(slot) = self.slots.at_mut(moved.index) {
                slot.index = i as u32;
            }
        }
        self.slots.remove(joint.index, joint.generation);
        // The pair may collide again once no joint keeps it apart.
        let freed = !collide && !self.no_collide.contains(a, b);
        Ok((a, b, freed))
    }

    /// Moves one end of a joint from body `from` to body `to`, with the
    /// local anchor `anchor` in `to`'s frame (the portal stage's re-pointing
    /// of a joint to the other copy of a crossing object). Updates the
    /// body lists and the no-collide pairs; returns the joint's bodies
    /// before and after, or `None` when `from` is not one of its ends.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn repoint(
        &mut self,
        joint: JointHandle,
        from: BodyHandle,
        to: BodyHandle,
        anchor: janus2d_core::math::Vec2,
    ) -> Option<((BodyHandle, BodyHandle), (BodyHandle, BodyHandle))> {
        let i = self.slot(joint).ok()?.index as usize;
        let j = &mut self.joints[i];
        let old = j.bodies();
        if !j.repoint(from, to, anchor) {
            return None;
        }
        let new = j.bodies();
        let collide = j.collide_connected();
        self.body_slots[i] = [new.0.index, new.1.index];
        if let Some(list) = self.body_joints.get_mut(from.index as usize)
            && let Some(k) = list.iter().position(|h| *h == joint)
        {
            list.remove(k);
        }
        let b = to.index as usize;
        if self.body_joints.len() <= b {
            self.body_joints.resize(b + 1, SmallVec::new());
        }
        self.body_joints[b].push(joint);
        if !collide {
            self.no_collide.remove(old.0, old.1);
            self.no_collide.add(new.0, new.1);
        }
        Some((old, new))
    }

    /// A joint, mutable (the portal stage carries its impulses through).
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn joint_mut(&mut self, joint: JointHandle) -> Result<&mut Joint, WorldError> {
        self.get_mut(joint)
    }

    /// Changes a joint's definition through `edit`, keeping the change
    /// only when the result validates. Returns the joint's bodies (to
    /// wake).
    fn edit(
        &mut self,
        joint: JointHandle,
        edit: impl FnOnce(&mut JointDef) -> Result<(), WorldError>,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        let j = self.get_mut(joint)?;
        let mut def = j.def();
        edit(&mut def)?;
        j.set_def(def)?;
        Ok(j.bodies())
    }

    /// Replaces a joint's definition by one of the same kind and bodies.
    pub(crate) fn set_def(
        &mut self,
        joint: JointHandle,
        def: JointDef,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        if self.kind(joint)? != def.kind() {
            return Err(WorldError::WrongJointKind);
        }
        self.edit(joint, |d| {
            *d = def;
            Ok(())
        })
    }

    /// Sets the limits (rad for an angle, m for a translation or length;
    /// `lower ≤ upper`, both finite).
    pub(crate) fn set_limits(
        &mut self,
        joint: JointHandle,
        lower: Real,
        upper: Real,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        if !(lower.is_finite() && upper.is_finite()) {
            return Err(WorldError::NonFinite("limits"));
        }
        if lower > upper {
            return Err(WorldError::OutOfRange("limits"));
        }
        self.edit(joint, |d| {
            let l = d.limits_mut().ok_or(WorldError::WrongJointKind)?;
            *l.lower = lower;
            *l.upper = upper;
            Ok(())
        })
    }

    /// Turns the limit on or off.
    pub(crate) fn enable_limit(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        self.edit(joint, |d| {
            *d.limits_mut().ok_or(WorldError::WrongJointKind)?.enable = on;
            Ok(())
        })
    }

    /// Colours the joints over `bodies` if a joint's key changed since
    /// the last colouring (the same colouring the solve's prepare keeps),
    /// and the colours they hold by body slot from it: what the contacts'
    /// persistent graph leaves free ([`JointSet::reserved`]). Everything it
    /// reads is in a snapshot, so a restored world reserves the same.
    pub(crate) fn refresh_reserved(&mut self, bodies: &BodySet) {
        if self.joints.is_empty() {
            self.reserved.clear();
            self.reserved_for = None;
            return;
        }
        self.colours
            .update_from(&self.joints, &self.body_slots, bodies);
        let made_from = (self.colours.generation(), self.joints.len());
        if self.reserved_for != Some(made_from) {
            self.colours.reserve(&self.body_slots, &mut self.reserved);
            self.reserved_for = Some(made_from);
        }
    }

    /// The colours the joints hold, by body slot, as of
    /// [`JointSet::refresh_reserved`].
    pub(crate) fn reserved(&self) -> &[u32] {
        &self.reserved
    }

    /// The slots of the bodies an enabled motor (of nonzero torque) turns:
    /// both bodies of each such joint, in joint order. The light clusters
    /// leave them out (`janus2d_constraints::contact_group`).
    pub(crate) fn driven_bodies(&self) -> impl Iterator<Item = u32> + '_ {
        self.joints
            .iter()
            .zip(&self.body_slots)
            .filter(|(j, _)| j.is_enabled() && j.is_driven())
            .flat_map(|(_, slots)| *slots)
    }

    /// Sets the motor speed (rad/s for an angular motor, m/s for a
    /// linear one; the kind's validation bounds it).
    pub(crate) fn set_motor_speed(
        &mut self,
        joint: JointHandle,
        speed: Real,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        if !speed.is_finite() {
            return Err(WorldError::NonFinite("motor_speed"));
        }
        self.edit(joint, |d| {
            *d.motor_mut().ok_or(WorldError::WrongJointKind)?.speed = speed;
            Ok(())
        })
    }

    /// Sets the motor's largest torque (N·m, `linear` false) or force (N,
    /// `linear` true), ≥ 0; a motor of the other sort is
    /// `Err(WrongJointKind)`.
    pub(crate) fn set_max_motor(
        &mut self,
        joint: JointHandle,
        max: Real,
        linear: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        let field = if linear {
            "max_motor_force"
        } else {
            "max_motor_torque"
        };
        if !max.is_finite() {
            return Err(WorldError::NonFinite(field));
        }
        if max < 0.0 {
            return Err(WorldError::OutOfRange(field));
        }
        self.edit(joint, |d| {
            let m = d.motor_mut().ok_or(WorldError::WrongJointKind)?;
            if m.linear != linear {
                return Err(WorldError::WrongJointKind);
            }
            *m.max = max;
            Ok(())
        })
    }

    /// Turns the motor on or off.
    pub(crate) fn enable_motor(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        self.edit(joint, |d| {
            *d.motor_mut().ok_or(WorldError::WrongJointKind)?.enable = on;
            Ok(())
        })
    }

    /// Sets the spring's stiffness, Hz, and damping ratio (both ≥ 0).
    pub(crate) fn set_spring(
        &mut self,
        joint: JointHandle,
        hertz: Real,
        damping_ratio: Real,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        if !(hertz.is_finite() && damping_ratio.is_finite()) {
            return Err(WorldError::NonFinite("spring"));
        }
        if hertz < 0.0 || damping_ratio < 0.0 {
            return Err(WorldError::OutOfRange("spring"));
        }
        self.edit(joint, |d| {
            let sp = d.spring_mut().ok_or(WorldError::WrongJointKind)?;
            *sp.hertz = hertz;
            *sp.damping_ratio = damping_ratio;
            Ok(())
        })
    }

    /// Turns the spring on or off.
    pub(crate) fn enable_spring(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        self.edit(joint, |d| {
            *d.spring_mut().ok_or(WorldError::WrongJointKind)?.enable = on;
            Ok(())
        })
    }

    /// Enables or disables a joint (a disabled joint stays until destroyed
    /// and is skipped by the solver and the islands).
    pub(crate) fn set_enabled(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        let j = self.get_mut(joint)?;
        j.set_enabled(on);
        Ok(j.bodies())
    }

    /// The joints' part of a step's end, in one pass over them (each pass
    /// reads every joint from memory):
    ///
    /// - every joint whose read-back is no longer finite starts afresh
    ///   (as [`forget_impulses`](Self::forget_impulses)): its kept
    ///   impulses overflowed, and warm starting from them would carry its
    ///   bodies off; so `joint_force` and `joint_torque` stay finite for
    ///   any accepted step;
    /// - the rows of the enabled joints and of the last tree solve are
    ///   counted ([`row_count`](Self::row_count),
    ///   [`direct_row_count`](Self::direct_row_count));
    /// - the step's joint events (see [`JointEvent`]) are gathered, in
    ///   storage order.
    ///
    /// On `team` in blocks of [`END_BLOCK`] joints, the blocks' findings
    /// joined in storage order (joint_grid at two threads: this pass over
    /// 19,800 joints was about 3% of the leader's samples, the other thread
    /// waiting).
    pub(crate) fn end_step(&mut self, team: &Team) -> JointStepEnd {
        let n = self.joints.len();
        if team.threads() == 1 || n < 2 * END_BLOCK {
            return end_block(&mut self.joints, &self.handles);
        }
        let handles = &self.handles[..];
        let blocks = team.map_chunks_mut(&mut self.joints, END_BLOCK, |b, joints| {
            let first = b * END_BLOCK;
            end_block(joints, &handles[first..first + joints.len()])
        });
        let mut end = JointStepEnd::default();
        for found in blocks {
            end.rows += found.rows;
            end.direct_rows += found.direct_rows;
            end.events.extend(found.events);
        }
        end
    }

    /// Rows every enabled joint adds to the solver.
    #[must_use]
    pub fn row_count(&self) -> usize {
        self.joints
            .iter()
            .filter(|j| j.is_enabled())
            .map(Joint::row_count)
            .sum()
    }

    /// Rows the tree solve took in the last step.
    #[must_use]
    pub fn direct_row_count(&self) -> usize {
        self.joints
            .iter()
            .filter(|j| j.in_tree())
            .map(Joint::tree_row_count)
            .sum()
    }
}

/// What [`JointSet::end_step`] gathered.
#[derive(Debug, Default)]
pub(crate) struct JointStepEnd {
    /// Rows of the enabled joints.
    pub(crate) rows: usize,
    /// Rows the tree solve took in the last step.
    pub(crate) direct_rows: usize,
    /// The threshold crossings, in storage order.
    pub(crate) events: Vec<JointEvent>,
}

/// Joints per block of [`JointSet::end_step`] on a team.
const END_BLOCK: usize = 1024;

/// [`JointSet::end_step`] over `joints` (with their `handles`), in order.
fn end_block(joints: &mut [Joint], handles: &[JointHandle]) -> JointStepEnd {
    let mut end = JointStepEnd::default();
    for (j, &handle) in joints.iter_mut().zip(handles) {
        // One read of the kind's impulses serves the finiteness test and
        // the thresholds.
        let (mut force, mut torque) = j.read_back();
        if !(force.x.is_finite() & force.y.is_finite() & torque.is_finite()) {
            let enabled = j.is_enabled();
            *j = Joint::new(j.def());
            j.set_enabled(enabled);
            (force, torque) = j.read_back();
        }
        if j.is_enabled() {
            end.rows += j.prepared_row_count();
        }
        if j.in_tree() {
            end.direct_rows += j.tree_row_count();
        }
        if j.check_thresholds_of(force, torque) {
            end.events.push(JointEvent {
                joint: handle,
                user_data: j.def_base().user_data,
                force,
                torque,
            });
        }
    }
    end
}
