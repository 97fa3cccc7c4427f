//! Portal pairs: create, destroy, read (with the `portals` feature). The
//! logic is the portal stage's (`crate::portal`); each method passes it
//! the stores it reads or changes.

use super::*;
use crate::aperture::ContactClipping;
use crate::portal::{PortalCounters, PortalEvent, PortalPairDef, PortalPairHandle, PortalSide};
use janus2d_constraints::PortalConstraint;
use janus2d_constraints::portal_map::PortalMap;

impl World {
    /// Creates a linked pair of portals.
    ///
    /// Rejects stale body handles, non-finite values, a zero direction, a
    /// non-positive half-width, an anchor coordinate or a half-width beyond
    /// the shape limit [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT)
    /// ([`WorldError::OutOfBounds`], field `anchor` or `half_width`),
    /// `η ≤ 0` and an `η` outside
    /// [`ETA_RANGE`](janus2d_core::limits::ETA_RANGE); a body that is
    /// crossing a portal ([`WorldError::PortalBody`]).
    pub fn create_portal_pair(
        &mut self,
        def: &PortalPairDef,
    ) -> Result<PortalPairHandle, WorldError> {
        self.portals
            .create_pair(def, &self.bodies, &mut self.collision)
    }

    /// Destroys a portal pair, cancelling every crossing in progress through it.
    pub fn destroy_portal_pair(&mut self, pair: PortalPairHandle) -> Result<(), WorldError> {
        let (portals, mut stores) = self.portals_and_stores();
        portals.destroy_pair(pair, &mut stores)
    }

    /// Number of live portal pairs.
    pub fn portal_pair_count(&self) -> usize {
        self.portals.pairs.len()
    }

    /// Number of crossings in progress (each has one clone and one constraint).
    pub fn crossing_count(&self) -> usize {
        self.portals.crossings.len()
    }

    /// Portal events of the last step: the same list as
    /// [`StepEvents::portals`](crate::StepEvents::portals), kept for the
    /// callers written before every event moved into
    /// [`World::events`].
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert!(world.events().portals.is_empty());
    /// ```
    #[deprecated(since = "0.2.0", note = "read `world.events().portals`")]
    pub fn portal_events(&self) -> &[PortalEvent] {
        &self.events.portals
    }

    /// Portal counters of the last step.
    pub fn portal_counters(&self) -> PortalCounters {
        self.portals.counters
    }

    /// The portal constraints of the crossings in progress.
    pub fn portal_constraints(&self) -> &[PortalConstraint] {
        &self.portals.constraints
    }

    /// The pair's map from portal a to portal b at the portal bodies'
    /// present poses: `T(x) = P_b + η Q (x − P_a)` ([`PortalMap::map_point`]),
    /// `Q` ([`PortalMap::rotation`]) and `η`. Its
    /// [`inverse`](PortalMap::inverse) maps b to a.
    pub fn portal_map(&self, pair: PortalPairHandle) -> Result<PortalMap, WorldError> {
        self.portals.map(pair, &self.bodies)
    }

    /// Where `body` is against the two portals of `pair` (from its shapes'
    /// extents; a body without shapes reads as at its centre of mass) and
    /// its part in a crossing through the pair.
    ///
    /// Errors: a stale or foreign body or pair handle.
    pub fn portal_side(
        &self,
        body: BodyHandle,
        pair: PortalPairHandle,
    ) -> Result<PortalSide, WorldError> {
        self.check_body(body)?;
        self.portals
            .side(body, pair, &self.bodies, &self.collision.shapes)
    }

    /// The current map (T, Q, η) of a crossing's portal constraint, at the
    /// portal bodies' present poses.
    pub fn portal_constraint_map(&self, constraint: &PortalConstraint) -> PortalMap {
        constraint.map(&self.bodies)
    }

    /// Every live portal pair with its definition as the world holds it:
    /// directions normalised, `eta` set to the pair's scale (read-only,
    /// for drawing and tools).
    pub fn portal_pairs(&self) -> impl Iterator<Item = (PortalPairHandle, PortalPairDef)> + '_ {
        self.portals.pair_defs(self.bodies.owner())
    }

    /// The aperture clipping the last step's narrowphase applied: the hole
    /// of each portal and the half-space behind each crossing copy
    /// (read-only, for drawing).
    pub fn portal_clipping(&self) -> &ContactClipping {
        self.portals.clipping()
    }

    /// The clone of `body` while it crosses, if any.
    pub fn clone_of(&self, body: BodyHandle) -> Option<BodyHandle> {
        self.portals.clone_of(body)
    }

    /// Largest portal constraint error `|x₂ − T(x₁)|` over crossings, m.
    pub fn max_portal_error(&self) -> Real {
        self.portals.max_error(&self.bodies)
    }
}
