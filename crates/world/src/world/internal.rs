//! One-thing operations on live bodies, shapes and joints that the portal
//! stage applies (no checks, no `Result`: it passes handles it knows live).

use super::*;

/// Internal operations the portal stage uses: each does exactly one
/// thing to a live body, with no checks and no `Result` (the stage only
/// passes handles it knows to be live).
#[cfg_attr(not(feature = "portals"), allow(dead_code))]
impl World {
    /// Sets a dynamic body's mass properties without touching its velocity.
    pub(crate) fn apply_mass_keep_velocity(&mut self, body: BodyHandle, mass: BodyMass) {
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        self.bodies.apply_mass(body, mass, fixed);
    }

    /// Creates a body (validated by `BodySet::create`) in an island of its
    /// own when dynamic; `create_body` adds the asleep-at-creation rule.
    pub(crate) fn insert_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        let handle = self.bodies.create(def)?;
        if def.body_type == BodyType::Dynamic {
            self.islands.add_body(handle);
        }
        Ok(handle)
    }

    /// Adds an impulse at a world point to a dynamic body now (no checks).
    pub(crate) fn push_body(
        &mut self,
        body: BodyHandle,
        impulse: Vec2,
        point: Vec2,
        angular: Real,
    ) {
        self.wake_body(body);
        if let Some(BodyLocation::Moving(i)) = self.bodies.location(body) {
            let sim = &self.bodies.sims[i as usize];
            if sim.body_type == BodyType::Dynamic {
                let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
                let st = &mut self.bodies.states[i as usize];
                st.v += im * impulse;
                st.w += ii * cross(point - c, impulse);
                st.w += ii * angular;
            }
        }
    }

    /// Sets a moving body's velocity (no checks).
    pub(crate) fn set_velocity_unchecked(&mut self, body: BodyHandle, v: Vec2, w: Real) {
        self.wake_body(body);
        if let Some(s) = self.bodies.state_mut(body) {
            s.v = v;
            s.w = w;
        }
    }

    /// Attaches a shape whose geometry and material are known to be valid
    /// (a portal clone's scaled copy); the body's mass is left as it is.
    pub(crate) fn add_shape_unchecked(&mut self, body: BodyHandle, def: ShapeDef, geometry: Shape) {
        self.collision.add_shape(&self.bodies, body, geometry, def);
    }

    /// The enabled joints attached to a body, in the body's list order.
    pub(crate) fn joints_attached_to(&self, body: BodyHandle) -> Vec<JointHandle> {
        self.joints
            .of_body(body)
            .iter()
            .copied()
            .filter(|h| self.joints.get(*h).is_ok_and(Joint::is_enabled))
            .collect()
    }

    /// Disables a joint (the solver skips it; it stays until destroyed).
    pub(crate) fn disable_joint(&mut self, joint: JointHandle) {
        let switched = self.switch_joint(joint, false);
        debug_assert!(switched.is_ok(), "the portal stage passes live joints");
    }

    /// Moves one end of a joint from body `from` to body `to` with the
    /// local anchor `anchor` in `to`'s frame (the portal stage re-points
    /// joints to the copy of a crossing object on their other body's side):
    /// the islands link the new pair, a no-collide joint ends its new
    /// pair's contacts, and the new bodies wake.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn repoint_joint(
        &mut self,
        joint: JointHandle,
        from: BodyHandle,
        to: BodyHandle,
        anchor: Vec2,
    ) {
        let Some((old, new)) = self.joints.repoint(joint, from, to, anchor) else {
            return;
        };
        let (enabled, collide) = self
            .joints
            .get(joint)
            .map_or((false, true), |j| (j.is_enabled(), j.collide_connected()));
        if !collide {
            self.collision.remove_contacts_between(new.0, new.1);
            let freed = !self.joints.no_collide.contains(old.0, old.1);
            if freed {
                self.collision.refind_pairs_of(old.0);
                self.collision.refind_pairs_of(old.1);
            }
        }
        self.islands.note_removed(old.0);
        if enabled {
            self.wake_body(new.0);
            self.wake_body(new.1);
            self.islands.link(new.0, new.1, &self.bodies);
        }
    }

    /// Exchanges two bodies' identities (see `BodySet::swap_identity`),
    /// moving their shapes along and dropping their contacts.
    pub(crate) fn swap_body_identity(&mut self, a: BodyHandle, b: BodyHandle) {
        self.collision.remove_contacts_of(a);
        self.collision.remove_contacts_of(b);
        if self.bodies.swap_identity(a, b).is_ok() {
            self.collision.swap_body_shapes(a, b);
            self.islands.swap_bodies(a, b);
            // The shapes' tight boxes follow their new bodies' poses now
            // (the narrowphase culls pairs by them).
            for body in [a, b] {
                if let Some(xf) = self.bodies.sim(body).map(|s| s.transform) {
                    self.collision.refresh_body(body, &xf);
                }
            }
        }
    }

    /// Read access to the collision stage (portal stage).
    pub(crate) fn collision_ref(&self) -> &Collision {
        &self.collision
    }
}
