//! Joints and portal rows solved together: while a crossing copy carries a
//! joint, the step's two batches (the graph of joints and contacts, the
//! portals) run as one
//! whose late pass repeats the exact joint trees and the stiff portal rows.
//!
//! ```text
//! late pass, per substep (solve and relax):
//!   trees ─ contacts' late ─ stiff portal rows          (as without joints)
//!   then COUPLING_PASSES × ( trees ─ stiff portal rows ) (block Gauss–Seidel)
//! ```
//!
//! Why: a rope's tension passes from one side to the other through the
//! portal rows of a crossing link, whose copies carry only their mass
//! shares. One late pass lets the portal rows have the last word; they move
//! the light copy, which opens the joint on it by about the velocity they
//! corrected times the substep, every substep. Alternating the two exact
//! blocks a few more times closes that (measured in `docs/portal.md`,
//! *Joints through portals*). Every other phase (and each phase's team
//! form, `*_on`) runs the two batches in the order the world uses
//! without coupling, so a world with no jointed crossing copy solves
//! exactly as before.

use janus2d_core::body::{BodySet, BodyState};
use janus2d_core::constraint::{ConstraintBatch, StepContext};
use janus2d_core::parallel::Team;

/// Extra (trees, portal rows) passes of the coupled late pass.
pub const COUPLING_PASSES: usize = 4;

/// The graph (joint and contact) batch and the portal batch run as one
/// (see the module docs).
pub(crate) struct CoupledBatches<'a> {
    /// The graph (joints and contacts), then the portals.
    pub(crate) batches: [&'a mut dyn ConstraintBatch; 2],
    /// Extra late passes of the trees and the portal rows.
    pub(crate) passes: usize,
}

impl ConstraintBatch for CoupledBatches<'_> {
    fn count(&self) -> usize {
        self.batches.iter().map(|b| b.count()).sum()
    }
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        for b in self.batches.iter_mut() {
            b.prepare(ctx, bodies);
        }
    }
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.warm_start(ctx, states);
        }
    }
    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.solve(ctx, states, use_bias, reverse);
        }
    }
    fn solve_late(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.solve_late(ctx, states, use_bias);
        }
        let [graph, portals] = &mut self.batches;
        if graph.count() == 0 || portals.count() == 0 {
            return;
        }
        for _ in 0..self.passes {
            graph.solve_late(ctx, states, use_bias);
            portals.solve_late(ctx, states, use_bias);
        }
    }
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.apply_restitution(ctx, states);
        }
    }
    fn store_impulses(&mut self) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.store_impulses();
        }
    }
    // The team stages forward to each batch's own, so the contacts keep
    // their colours spread over the team.
    fn prepare_on(&mut self, ctx: &StepContext, bodies: &BodySet, team: &Team) {
        for b in self.batches.iter_mut() {
            b.prepare_on(ctx, bodies, team);
        }
    }
    fn warm_start_on(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.warm_start_on(ctx, states, team);
        }
    }
    fn solve_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.solve_on(ctx, states, use_bias, reverse, team);
        }
    }
    fn solve_late_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.solve_late_on(ctx, states, use_bias, team);
        }
        let [graph, portals] = &mut self.batches;
        if graph.count() == 0 || portals.count() == 0 {
            return;
        }
        for _ in 0..self.passes {
            graph.solve_late_on(ctx, states, use_bias, team);
            portals.solve_late_on(ctx, states, use_bias, team);
        }
    }
    fn apply_restitution_on(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        for b in self.batches.iter_mut().filter(|b| b.count() > 0) {
            b.apply_restitution_on(ctx, states, team);
        }
    }
}
