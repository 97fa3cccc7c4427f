//! The joints as one solver batch: prepare every joint, build the tree
//! solve and the colours from the prepared joints, then run the stages.
//!
//! | stage          | what runs                                                   |
//! |----------------|-------------------------------------------------------------|
//! | prepare        | each enabled joint's rows, forest pair and colour key in one pass (blocks on the team), then [`JointForest`] and [`JointColours`] |
//! | warm start     | [`JointColours`]: per moving body, its joints' shares in storage order |
//! | solve, relax   | [`JointColours`]: the Gauss–Seidel rows colour by colour     |
//! | late solve     | [`JointForest`]: the point rows of joint trees, exactly      |
//! | restitution    | nothing: no joint kind has restitution                      |
//! | store          | the lanes' impulses back into their joints (`revolute_lanes`); every other impulse stays in its joint |

use janus2d_core::body::{BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintBatch, StepContext};
use janus2d_core::parallel::Team;

use crate::joint::Joint;
use crate::joint_colour::{JointColours, key};
use crate::joint_tree::{JointForest, TreePolicy, moving_pair};

/// Rows of the joint prepare's blocks on the team.
const PREPARE_BLOCK: usize = 256;

/// Every joint of a world as the solver sees it: the joints, their tree
/// solve and their colours.
pub struct JointBatch<'a> {
    /// The joints, in storage order.
    pub joints: &'a mut Vec<Joint>,
    /// The direct solve of the trees among them.
    pub forest: &'a mut JointForest,
    /// The colours of their Gauss–Seidel rows.
    pub colours: &'a mut JointColours,
}

impl JointBatch<'_> {
    /// Each joint's rows, its pair of moving ends for the forest and its
    /// colour key, in one pass over the joints while each is in cache
    /// (blocks on the team: a joint's prepare reads the bodies and writes
    /// only itself); then the forest and the colours from those.
    fn prepare_all_on(&mut self, ctx: &StepContext, bodies: &BodySet, team: &Team) {
        let states = &bodies.states;
        let count = self.joints.len();
        let pairs = self.forest.pairs_for(count);
        let keys = self.colours.keys_for(count);
        team.for_each_chunk_triple_mut_beside(
            self.joints,
            pairs,
            keys,
            PREPARE_BLOCK,
            |_, block, pairs, keys| {
                for i in 0..block.len() {
                    // The definition a few joints on, boxed apart: its miss
                    // overlaps this joint's prepare (docs/performance.md).
                    if let Some(ahead) = block.get(i + PREFETCH_AHEAD) {
                        ahead.prefetch_def();
                    }
                    let j = &mut block[i];
                    if j.is_enabled() {
                        j.prepare(ctx, bodies);
                    }
                    pairs[i] = moving_pair(j, states);
                    keys[i] = key(j, states);
                }
            },
            || {},
        );
        if self
            .forest
            .update(self.joints, states.len(), TreePolicy::of(ctx))
        {
            // The rebuild moved joints into or out of trees, which decides
            // whether they have Gauss–Seidel rows: their keys again.
            self.colours.update_on(self.joints, states, team);
        } else {
            self.colours.recolour_if_changed(count, states.len());
        }
        self.colours
            .build_lanes(self.joints, ctx, states.len(), team);
    }
}

/// How many joints ahead the prepare asks for a definition's line.
const PREFETCH_AHEAD: usize = 4;

impl ConstraintBatch for JointBatch<'_> {
    fn count(&self) -> usize {
        self.joints.len()
    }
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        self.prepare_on(ctx, bodies, &Team::serial());
    }
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.warm_start_on(ctx, states, &Team::serial());
    }
    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        self.solve_on(ctx, states, use_bias, reverse, &Team::serial());
    }
    fn solve_late(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        self.forest.solve(ctx, self.joints, states, use_bias);
    }
    fn apply_restitution(&mut self, _ctx: &StepContext, _states: &mut [BodyState]) {
        // No joint kind has restitution rows.
    }
    fn store_impulses(&mut self) {
        // The angle rows solved in lanes hand theirs back; every other row
        // keeps its impulse in its joint.
        self.colours.store_lanes(self.joints);
    }
    fn prepare_on(&mut self, ctx: &StepContext, bodies: &BodySet, team: &Team) {
        self.prepare_all_on(ctx, bodies, team);
    }
    fn warm_start_on(&mut self, _ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        self.colours.warm_start(self.joints, states, team);
    }
    fn solve_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        self.colours
            .solve(ctx, self.joints, states, use_bias, reverse, team);
    }
    fn solve_late_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        self.forest
            .solve_on(ctx, self.joints, states, use_bias, team);
    }
    fn apply_restitution_on(
        &mut self,
        _ctx: &StepContext,
        _states: &mut [BodyState],
        _team: &Team,
    ) {
    }
}
