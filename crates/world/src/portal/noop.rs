//! The portal stage without the `portals` feature: it holds nothing and
//! each of its step calls returns at once, so a world built without portals
//! pays for none of them. Its interface is the stage's: the same verbs
//! over the same stores.

use janus2d_constraints::{ObjectMass, PortalConstraint};
use janus2d_core::body::{BodyHandle, BodySet};

use super::clipping::{ContactClipping, NO_CLIPPING};
use crate::stores::Stores;

/// The no-op portal stage.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct PortalStage {
    /// Always empty: the solver's third batch.
    constraints: Vec<PortalConstraint>,
}

impl PortalStage {
    pub(crate) fn is_active(&self) -> bool {
        false
    }
    pub(crate) fn clipping(&self) -> &ContactClipping {
        &NO_CLIPPING
    }
    pub(crate) fn constraints(&self) -> &[PortalConstraint] {
        &self.constraints
    }
    pub(crate) fn constraints_mut(&mut self) -> &mut Vec<PortalConstraint> {
        &mut self.constraints
    }
    pub(crate) fn clone_aliases(&self) -> std::iter::Empty<(u32, u32)> {
        std::iter::empty()
    }
    pub(crate) fn counters_for_step(&self, _ran: bool) -> (usize, usize, usize) {
        (0, 0, 0)
    }
    pub(crate) fn keep_awake(&self) -> Vec<BodyHandle> {
        Vec::new()
    }
    pub(crate) fn build_clipping(
        &mut self,
        _bodies: &BodySet,
        _shapes: &crate::shapes::ShapeStore,
    ) {
    }
    pub(crate) fn involves(&self, _body: BodyHandle) -> bool {
        false
    }
    pub(crate) fn check(&self, _bodies: &BodySet) -> Result<(), String> {
        Ok(())
    }
    pub(crate) fn copies_carry_joints(&self, _joints: &crate::joints::JointSet) -> bool {
        false
    }
    pub(crate) fn object_masses(&self, _bodies: &BodySet, out: &mut Vec<ObjectMass>) {
        out.clear();
    }
    pub(crate) fn query_apertures(
        &self,
        _bodies: &BodySet,
        _owner: u32,
    ) -> Vec<crate::query::QueryAperture> {
        Vec::new()
    }
    /// Nothing crosses without portals.
    pub(crate) fn cross(&mut self, _stores: &mut Stores<'_>) {}
    /// No crossing or pair to end.
    pub(crate) fn forget_body(&mut self, _body: BodyHandle, _stores: &mut Stores<'_>) {}
}
