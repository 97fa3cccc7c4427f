//! Joints and contacts in one colour sequence: the solver's graph batch.
//!
//! The joints are coloured greedily over their moving bodies
//! ([`JointColours`], again only when a joint's key changes); the contacts
//! keep their colours from step to step in the persistent
//! [`ConstraintGraph`](janus2d_core::graph::ConstraintGraph), which takes
//! none of the colours the joints hold on a body
//! ([`JointColours::reserve`] →
//! [`ConstraintGraph::set_reserved`](janus2d_core::graph::ConstraintGraph::set_reserved)),
//! as Box2D's graph holds both. So colour `c` holds joints and contacts
//! that share no moving body, and one velocity iteration is one sweep of
//! the colours:
//!
//! ```text
//!   forward (solve)                       reverse (alternate sweeps)
//!   colour 0:  joints₀ ∥ contacts₀        joint overflow
//!   colour 1:  joints₁ ∥ contacts₁        colour 23: joints₂₃ ∥ contacts₂₃
//!   …          (one job per colour:       …
//!   colour 23:  one wait for the team)    colour 0:  joints₀ ∥ contacts₀
//!   joint overflow                        contact overflow (+ light clusters)
//!   contact overflow (+ light clusters)
//! ```
//!
//! On the team a colour is one job whose blocks are its joints' blocks and
//! its contacts' chunks ([`Team::for_each_planned_pair`]), checked once
//! per step to share no written state
//! ([`CrossPlan`](janus2d_core::parallel::CrossPlan)); a short colour runs
//! on the leader, joints first. A step whose joints were coloured after
//! the contacts took theirs (a joint created or woken since the last step)
//! may hold a body in both halves of a colour: the check then fails and
//! the colour runs as two jobs, joints first, the order of the serial
//! sweep. Either way the states are bit-identical for any thread count.
//!
//! | stage            | joints                                   | contacts                           |
//! |------------------|------------------------------------------|------------------------------------|
//! | prepare          | rows, forest, colours (on a change)      | lanes, overflow, plan              |
//! | warm start       | per moving body (storage order)          | colour by colour, overflow         |
//! | solve, relax     | colour by colour, together with the contacts of the colour; then the overflows |
//! | late solve       | the exact trees                          | —                                  |
//! | restitution      | —                                        | colour by colour, overflow         |
//!
//! The warm start stays two passes: the joints' is per body and needs no
//! colours (see [`crate::joint_colour`]).

use janus2d_core::body::{BodySet, BodyState};
use janus2d_core::constraint::{ConstraintBatch, StepContext};
use janus2d_core::parallel::{PlannedGroup, Team};

use crate::contact_solver::{ContactBatch, Stage};
use crate::joint_colour::JointColours;
use crate::joint_solver::JointBatch;

/// The joints and the contacts of a step as one solver batch (see the
/// module docs).
pub struct GraphBatch<'a> {
    /// The joints: rows, tree solve, colours.
    pub joints: JointBatch<'a>,
    /// The contacts: chunks per colour and the overflow.
    pub contacts: ContactBatch<'a>,
}

impl GraphBatch<'_> {
    /// One velocity iteration over the shared colours (`reverse`: the
    /// overflows first, then the colours from the last).
    fn solve_colours(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        team: &Team,
    ) {
        let joints = &mut **self.joints.joints;
        let colours = &mut *self.joints.colours;
        let contacts = &mut *self.contacts.solver;
        colours.ensure_coloured(joints, states);
        let stage = Stage::solve(ctx, use_bias);
        let joint_colours = colours.colour_count();
        let slots = joint_colours.max(contacts.colour_slots());
        let (inv_h, push_max) = (ctx.inv_h, ctx.contact_push_max_velocity);
        // The joints' overflow closes a forward sweep and opens a reverse
        // one; the contacts' overflow (and light clusters) always comes
        // after the colours, as the contact solve alone has it.
        let joint_overflow = joint_colours;
        if reverse {
            colours.solve_segment(joint_overflow, ctx, joints, states, use_bias);
        }
        if !colours.wants_team(team) && !contacts.wants_team(team) {
            // Every colour on the caller: its joints, then its contacts.
            for k in 0..slots {
                let c = if reverse { slots - 1 - k } else { k };
                if c < joint_colours {
                    colours.solve_segment(c, ctx, joints, states, use_bias);
                }
                contacts.run_colour(c, stage, states, team);
            }
        } else {
            let mut refs = colours.take_refs(joints);
            {
                let mut parts = colours.parts(&mut refs);
                for k in 0..slots {
                    let c = if reverse { slots - 1 - k } else { k };
                    if c < joint_colours {
                        colours.solve_lanes(c, ctx, states, use_bias, team);
                    }
                    let joint_part: &mut [Option<&mut crate::Joint>] = if colours.has_scalar(c) {
                        &mut *parts[c]
                    } else {
                        &mut []
                    };
                    let joint_block = JointColours::block_len(joint_part.len(), team);
                    let joints_short = joint_part.len() <= joint_block;
                    let solve_joint = |j: &mut Option<&mut crate::Joint>,
                                       view: &mut janus2d_core::parallel::PlannedStates<'_, 2>| {
                        if let Some(j) = j {
                            j.solve_pair(ctx, view, use_bias);
                        }
                    };
                    if joints_short && contacts.colour_is_short(c, team) {
                        // Both short: on the caller, joints first.
                        for (j, &w) in joint_part.iter_mut().zip(colours.segment_writes(c)) {
                            let Some(j) = j else { continue };
                            let (a, b) = (j.base().state_a, j.base().state_b);
                            let mut pair = crate::parts::PairOf::new(states, a, b, w);
                            j.solve_pair(ctx, &mut pair, use_bias);
                        }
                        contacts.run_colour(c, stage, states, team);
                        continue;
                    }
                    if joint_part.is_empty() {
                        contacts.run_colour(c, stage, states, team);
                        continue;
                    }
                    let (plan, chunks, chunk_block) = contacts.colour_group(c, team);
                    if chunks.is_empty() || c >= plan.group_count() {
                        team.for_each_planned(
                            colours.plan(),
                            c,
                            joint_part,
                            states,
                            joint_block,
                            solve_joint,
                        );
                        contacts.run_colour(c, stage, states, team);
                        continue;
                    }
                    team.for_each_planned_pair(
                        colours.cross(),
                        PlannedGroup {
                            plan: colours.plan(),
                            group: c,
                            items: joint_part,
                            per_block: joint_block,
                        },
                        PlannedGroup {
                            plan,
                            group: c,
                            items: chunks,
                            per_block: chunk_block,
                        },
                        states,
                        solve_joint,
                        |chunk, view| chunk.run(stage, view),
                    );
                }
            }
            colours.put_refs(refs);
        }
        if !reverse {
            colours.solve_segment(joint_overflow, ctx, joints, states, use_bias);
        }
        contacts.solve_overflow(states, use_bias, inv_h, push_max);
    }
}

impl ConstraintBatch for GraphBatch<'_> {
    fn count(&self) -> usize {
        self.joints.count() + self.contacts.count()
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
        self.solve_colours(ctx, states, use_bias, reverse, &Team::serial());
    }
    fn solve_late(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool) {
        self.joints.solve_late(ctx, states, use_bias);
    }
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.contacts.apply_restitution(ctx, states);
    }
    fn store_impulses(&mut self) {
        // The lanes' impulses go back into their joints; the pipeline
        // reads the contacts' back from the solver.
        self.joints.store_impulses();
    }
    fn prepare_on(&mut self, ctx: &StepContext, bodies: &BodySet, team: &Team) {
        self.contacts.prepare_on(ctx, bodies, team);
        self.joints.prepare_on(ctx, bodies, team);
        let (colours, contacts) = (&mut *self.joints.colours, &*self.contacts.solver);
        colours.check_beside(self.joints.joints, &bodies.states, contacts, team);
    }
    fn warm_start_on(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        if self.joints.count() > 0 {
            self.joints.warm_start_on(ctx, states, team);
        }
        if self.contacts.count() > 0 {
            self.contacts.warm_start_on(ctx, states, team);
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
        self.solve_colours(ctx, states, use_bias, reverse, team);
    }
    fn solve_late_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        team: &Team,
    ) {
        if self.joints.count() > 0 {
            self.joints.solve_late_on(ctx, states, use_bias, team);
        }
    }
    fn apply_restitution_on(&mut self, ctx: &StepContext, states: &mut [BodyState], team: &Team) {
        if self.contacts.count() > 0 {
            self.contacts.apply_restitution_on(ctx, states, team);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact_solver::{ContactLane, ContactSolver};
    use crate::joint::Joint;
    use crate::joint_tree::JointForest;
    use crate::revolute::{RevoluteJoint, RevoluteJointDef};
    use crate::{ContactPointInput, ObjectMass};
    use janus2d_core::body::{BodyDef, BodyHandle};
    use janus2d_core::graph::ConstraintGraph;
    use janus2d_core::math::{Real, Vec2};
    use janus2d_core::solver::SolverSettings;

    /// The pieces of a graph batch over a row of `n` bodies.
    struct Row {
        set: BodySet,
        contacts: ContactSolver,
        joints: Vec<Joint>,
        forest: JointForest,
        colours: JointColours,
    }

    /// A row of `n` bodies: motor joints between bodies 6k + 2 and 6k + 4
    /// and between 6k + 3 and 6k + 5 (angle rows: every joint takes a
    /// colour), coloured first; then contacts
    /// between bodies 6k and 6k + 1 and between 12k and 12k + 3, coloured
    /// in the persistent graph around the joints' colours, as the world
    /// does.
    fn row(n: usize) -> Row {
        let mut set = BodySet::new();
        let ids: Vec<BodyHandle> = (0..n)
            .map(|i| {
                let def = BodyDef::dynamic(Vec2::new(i as Real, 0.0))
                    .with_angular_velocity(0.01 * i as Real);
                set.create(&def).unwrap()
            })
            .collect();
        let mut joints = Vec::new();
        for i in (0..n - 2).filter(|i| matches!(i % 6, 2 | 3)) {
            let mut def = RevoluteJointDef::new(
                ids[i],
                ids[i + 2],
                Vec2::new(1.0, 0.0),
                Vec2::new(-1.0, 0.0),
            );
            def.enable_motor = true;
            def.max_motor_torque = 2.0;
            def.motor_speed = 0.5;
            joints.push(Joint::from(RevoluteJoint::new(def)));
        }
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        let (mut forest, mut colours) = (JointForest::default(), JointColours::new());
        JointBatch {
            joints: &mut joints,
            forest: &mut forest,
            colours: &mut colours,
        }
        .prepare(&ctx, &set);
        let mut reserved = Vec::new();
        let body_slots: Vec<[u32; 2]> = joints
            .iter()
            .map(|j| {
                let (a, b) = j.bodies();
                [a.index, b.index]
            })
            .collect();
        colours.reserve(&body_slots, &mut reserved);
        let mut graph = ConstraintGraph::new();
        graph.set_reserved(&reserved);
        graph.begin_step();
        let state = |h: BodyHandle| set.state_index(h).unwrap();
        let mut contacts = ContactSolver::new();
        contacts.begin();
        let mut index = 0;
        for (gap, every) in [(1, 6), (3, 12)] {
            for i in (0..n - gap).filter(|i| i % every == 0) {
                let (a, b) = (ids[i], ids[i + gap]);
                let colour = graph.keep(index, [a.index, b.index]);
                let point = ContactPointInput {
                    anchor_a: Vec2::new(0.5, 0.0),
                    anchor_b: Vec2::new(-0.5, 0.0),
                    separation: -0.01,
                    normal_impulse: 0.02,
                    tangent_impulse: 0.001,
                };
                let lane = ContactLane {
                    body_a: a,
                    body_b: b,
                    state_a: state(a),
                    state_b: state(b),
                    inv_masses: [1.0, 2.0, 1.0, 2.0],
                    normal: Vec2::X,
                    points: [point; crate::contact::MAX_MANIFOLD_POINTS],
                    point_count: 1,
                    friction: 0.6,
                    restitution: 0.0,
                    tangent_speed: 0.0,
                    rolling_resistance: 0.0,
                    contact_index: index,
                    cluster: [crate::contact_group::NO_CLUSTER; 2],
                };
                index += 1;
                contacts.push(colour, &lane);
            }
        }
        graph.sweep();
        Row {
            set,
            contacts,
            joints,
            forest,
            colours,
        }
    }

    /// Prepares the row's graph batch on `team`, runs three substeps'
    /// stages and returns the bits of every velocity, the colours, and
    /// whether the colours ran as one job each (the plans checked together).
    fn run_stages(team: &Team) -> (Vec<u64>, Vec<Vec<u32>>, bool) {
        let Row {
            mut set,
            mut contacts,
            mut joints,
            mut forest,
            mut colours,
        } = row(3000);
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::new(0.0, -10.0));
        let objects: [ObjectMass; 0] = [];
        let mut batch = GraphBatch {
            joints: JointBatch {
                joints: &mut joints,
                forest: &mut forest,
                colours: &mut colours,
            },
            contacts: ContactBatch {
                solver: &mut contacts,
                object_masses: &objects,
            },
        };
        crate::test_support::three_substeps(&mut batch, &ctx, &mut set, team);
        let bits = set
            .states
            .iter()
            .flat_map(|s| [s.v.x, s.v.y, s.w])
            .map(|x| janus2d_core::math::to_f64(x).to_bits())
            .collect();
        let by_colour = (0..=colours.colour_count())
            .map(|c| colours.joints_in(c).to_vec())
            .collect();
        // A colour of several blocks of both joints and contacts.
        let shared = (0..colours.colour_count())
            .any(|c| colours.joints_in(c).len() > 64 && contacts.count_in(c as u8) > 8 * 32);
        let paired = shared
            && colours
                .cross()
                .holds(colours.plan(), contacts.plan(), set.states.len());
        (bits, by_colour, paired)
    }

    /// The contacts take colours around the joints': within a colour no
    /// moving body carries both a joint and a contact (nor two joints).
    #[test]
    fn a_colour_holds_a_moving_body_once_across_joints_and_contacts() {
        let Row {
            set,
            contacts,
            joints,
            colours,
            ..
        } = row(400);
        let mut occupied = Vec::new();
        contacts.moving_colours(set.states.len(), &mut occupied);
        assert!(colours.colour_count() >= 1);
        let mut shared = 0;
        for c in 0..colours.colour_count() {
            let mut seen = std::collections::HashSet::new();
            for &i in colours.joints_in(c) {
                let base = joints[i as usize].base();
                for s in [base.state_a, base.state_b] {
                    assert_eq!(occupied[s as usize] & (1 << c), 0, "state {s}, colour {c}");
                    assert!(seen.insert(s), "state {s} twice in colour {c}");
                }
            }
            if !colours.joints_in(c).is_empty() && contacts.count_in(c as u8) > 0 {
                shared += 1;
            }
        }
        // The two kinds do share colours (on different bodies).
        assert!(shared > 0);
        assert_eq!(colours.overflow_len(), 0);
        assert_eq!(contacts.count_in(crate::contact_solver::OVERFLOW), 0);
    }

    /// One job per colour on the team (joints and contacts together) gives
    /// the serial sweep's states, bit for bit, for 1, 2 and 4 threads.
    #[test]
    fn the_graph_batch_on_the_team_gives_the_serial_result() {
        let (bits, colours, _) = run_stages(&Team::serial());
        // Colours of more than one block of joints.
        assert!(colours.iter().any(|c| c.len() > 64));
        let (team_bits, team_colours, _) = janus2d_core::parallel::with_team(run_stages);
        assert_eq!((team_bits, team_colours), (bits.clone(), colours.clone()));
        #[cfg(feature = "parallel")]
        for threads in [2, 4] {
            let (team_bits, team_colours, paired) =
                janus2d_core::parallel::with_threads(threads, run_stages).unwrap();
            assert!(paired, "{threads} threads: one job per colour");
            assert_eq!(team_bits, bits, "{threads} threads");
            assert_eq!(team_colours, colours, "{threads} threads");
        }
    }
}
