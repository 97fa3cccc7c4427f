//! Store-level operations: each does one thing to the world's structure
//! over [`Stores`] (the bodies, joints, collision stage and islands
//! borrowed together), with no checks and no `Result` where the caller
//! passes handles it knows live. The world's own methods call them, and
//! the portal stage reaches them through the stores it is handed: its
//! commands ([`PortalCommand`]) are applied here, at once and in order.

use super::*;
#[cfg(feature = "portals")]
use crate::portal::PortalCommand;
use crate::stores::Stores;

impl World {
    /// The structure stores borrowed together.
    pub(crate) fn stores(&mut self) -> Stores<'_> {
        Stores {
            bodies: &mut self.bodies,
            joints: &mut self.joints,
            collision: &mut self.collision,
            islands: &mut self.islands,
        }
    }

    /// The portal stage beside the stores it reads and changes (for the
    /// stage's verbs: the crossing stage, ending a body's crossings, the
    /// pair API).
    pub(crate) fn portals_and_stores(&mut self) -> (&mut PortalStage, Stores<'_>) {
        let stores = Stores {
            bodies: &mut self.bodies,
            joints: &mut self.joints,
            collision: &mut self.collision,
            islands: &mut self.islands,
        };
        (&mut self.portals, stores)
    }

    /// Creates a body (see [`Stores::insert_body`]).
    pub(crate) fn insert_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        self.stores().insert_body(def)
    }
}

impl Stores<'_> {
    /// Wakes the island of `body` (no effect on awake or static bodies).
    pub(crate) fn wake_body(&mut self, body: BodyHandle) {
        self.islands
            .wake(body, self.bodies, &mut self.collision.contacts);
    }

    /// Creates a body (validated by `BodySet::create`) in an island of its
    /// own when dynamic; `World::create_body` adds the asleep-at-creation
    /// rule.
    pub(crate) fn insert_body(&mut self, def: &BodyDef) -> Result<BodyHandle, WorldError> {
        let handle = self.bodies.create(def)?;
        if def.body_type == BodyType::Dynamic {
            self.islands.add_body(handle);
        }
        Ok(handle)
    }

    /// Sets a body's mass properties from its shapes (a unit mass when
    /// they have none; clamped into the stated ranges).
    pub(crate) fn mass_from_shapes(&mut self, body: BodyHandle) {
        let md = self.collision.shapes.mass_of(body);
        let fixed = self
            .bodies
            .record(body)
            .map(|r| r.fixed_rotation)
            .unwrap_or(false);
        let mass = if md.mass > 0.0 {
            BodyMass {
                mass: md.mass,
                rotational_inertia: md.rotational_inertia,
                center: md.center,
            }
        } else {
            BodyMass::new(1.0, 1.0)
        };
        let inertia_ok = fixed || mass.rotational_inertia > 0.0;
        let mass = if inertia_ok {
            mass
        } else {
            BodyMass {
                rotational_inertia: mass.mass * 1e-3,
                ..mass
            }
        };
        // Mass from shapes is clamped into the stated ranges (a tiny
        // density must not give an infinite inverse mass).
        let mass = BodyMass {
            mass: janus2d_core::limits::clamp_to(mass.mass, janus2d_core::limits::MASS_RANGE),
            rotational_inertia: janus2d_core::limits::clamp_to(
                mass.rotational_inertia,
                janus2d_core::limits::INERTIA_RANGE,
            ),
            center: mass.center,
        };
        self.bodies.apply_mass(body, mass, fixed);
    }

    /// Wakes every body that has a contact with `body` (its own list).
    pub(crate) fn wake_touching(&mut self, body: BodyHandle) {
        let touching: smallvec::SmallVec<[BodyHandle; 8]> = self
            .collision
            .contacts
            .of_body(body)
            .iter()
            .filter_map(|&id| self.collision.contacts.get(id))
            .map(|c| c.other(body))
            .collect();
        for b in touching {
            self.wake_body(b);
        }
    }

    /// Destroys a live body (checked by the caller, crossings already
    /// ended).
    pub(crate) fn destroy_body(&mut self, body: BodyHandle) {
        self.wake_touching(body);
        self.wake_body(body);
        let attached: smallvec::SmallVec<[JointHandle; 4]> =
            self.joints.of_body(body).iter().copied().collect();
        for h in attached {
            self.remove_joint(h);
        }
        self.forget_chains_of(body);
        let shapes: smallvec::SmallVec<[u32; 4]> = self
            .collision
            .shapes
            .of_body(body)
            .iter()
            .copied()
            .collect();
        for s in shapes {
            self.collision.remove_shape(s);
        }
        self.islands.remove_body(body);
        let destroyed = self.bodies.destroy(body);
        debug_assert!(destroyed.is_ok(), "checked by the caller");
    }

    /// Drops the chains whose segments are on `body` (their shapes go
    /// with the body's).
    pub(crate) fn forget_chains_of(&mut self, body: BodyHandle) {
        let c = &mut *self.collision;
        if c.chains.slots.is_empty() {
            return;
        }
        let owner = c.owner;
        let doomed: Vec<(u32, u32)> = c
            .chains
            .slots
            .iter()
            .filter(|(_, chain)| {
                chain.segments.iter().any(|&s| {
                    c.shapes
                        .slot(s, owner)
                        .is_ok_and(|slot| c.shapes.at(slot).body == body)
                })
            })
            .map(|(i, _)| (i, c.chains.slots.generation(i)))
            .collect();
        for (i, g) in doomed {
            c.chains.slots.remove(i, g);
        }
    }

    /// Removes a live joint, waking its bodies.
    pub(crate) fn remove_joint(&mut self, joint: JointHandle) {
        if let Ok((a, b, freed)) = self.joints.remove(joint) {
            if freed {
                // Their proxies may not move again for a long time: the
                // broadphase looks for their pairs at the next step.
                self.collision.refind_pairs_of(a);
                self.collision.refind_pairs_of(b);
            }
            self.wake_body(a);
            self.wake_body(b);
            self.islands.note_removed(a);
        }
    }

    /// Enables or disables a joint and tells the islands (linked when on,
    /// a removed link when off); wakes nothing.
    pub(crate) fn switch_joint(
        &mut self,
        joint: JointHandle,
        on: bool,
    ) -> Result<(BodyHandle, BodyHandle), WorldError> {
        let (a, b) = self.joints.set_enabled(joint, on)?;
        if on {
            self.islands.link(a, b, self.bodies);
        } else {
            self.islands.note_removed(a);
        }
        Ok((a, b))
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
            self.islands.link(new.0, new.1, self.bodies);
        }
    }

    /// Exchanges two bodies' identities (see `BodySet::swap_identity`),
    /// moving their shapes' handles along (see
    /// `Collision::swap_body_shapes`) and dropping their contacts.
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
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

    /// Applies one command of the portal stage, at once.
    #[cfg(feature = "portals")]
    pub(crate) fn apply(&mut self, command: PortalCommand) {
        match command {
            PortalCommand::Wake(body) => self.wake_body(body),
            PortalCommand::AddShape {
                body,
                def,
                geometry,
            } => {
                // A clone's scaled copy of a valid shape: valid, and the
                // body's mass is left as it is.
                self.collision.add_shape(self.bodies, body, geometry, def);
            }
            PortalCommand::MassFromShapes(body) => self.mass_from_shapes(body),
            PortalCommand::DisableJoint(joint) => {
                let switched = self.switch_joint(joint, false);
                debug_assert!(switched.is_ok(), "the portal stage passes live joints");
            }
            PortalCommand::RepointJoint {
                joint,
                from,
                to,
                anchor,
            } => self.repoint_joint(joint, from, to, anchor),
            PortalCommand::SwapIdentity(a, b) => self.swap_body_identity(a, b),
            PortalCommand::DestroyBody(body) => self.destroy_body(body),
        }
    }
}
