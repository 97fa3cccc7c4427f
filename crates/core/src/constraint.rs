//! The constraint trait: the place where rows are built.
//!
//! A constraint is a set of rows `C(x) = 0` (or `≥ 0`, or bounded impulses
//! for friction and motors). For each row it reports a Jacobian with a
//! **separate** linear and angular part for each body it touches (the
//! portal's linear parts are not negatives of each other, and it touches up
//! to four bodies), its position error `C`, its impulse bounds and its
//! accumulated impulse; rows that couple are grouped into blocks with their
//! effective mass `K = J M⁻¹ Jᵀ`, solved as one small system.
//!
//! Every constraint has the same stages:
//!
//! | stage                | when                      | what                                          |
//! |----------------------|---------------------------|-----------------------------------------------|
//! | `prepare`            | once per step             | anchors, K, softness from body data           |
//! | `warm_start`         | each substep              | apply last impulses                           |
//! | `solve(use_bias)`    | each substep              | velocity solve with position feedback         |
//! | `solve(!use_bias)`   | each substep ("relax")    | velocity solve without feedback               |
//! | `apply_restitution`  | once per step             | bounce (contacts only)                        |
//! | `store_impulses`     | once per step             | keep impulses for the next step's warm start  |
//!
//! The solver never calls a constraint through `dyn` per row: each
//! constraint type lives in its own `Vec`, and the [`ConstraintBatch`]
//! implementation for `Vec<C>` runs a monomorphic loop over it. `dyn` is used
//! once per type per stage. A type may replace its solve loop
//! ([`Constraint::solve_all`]), or its whole batch: contacts have their
//! own (`janus2d_constraints::contact_solver`, colours and SIMD lanes).

use smallvec::SmallVec;

use crate::body::{BodyHandle, BodySet, BodyState};
use crate::math::{Real, Vec2};
use crate::parallel::Team;
use crate::softness::Softness;

/// How the velocity solver treats position error.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum SolverMode {
    /// Box2D v3's soft step: substeps, soft constraints, relax iterations.
    #[default]
    SoftStep,
    /// Plain projected Gauss–Seidel with Baumgarte bias: one step, a number
    /// of velocity iterations, rigid rows. The cheap baseline.
    PgsBaumgarte,
}

/// Everything a constraint needs to know about the current step.
#[derive(Clone, Debug)]
pub struct StepContext {
    /// Time the solver's stages (the step's profile; true unless the world
    /// turned its stage timers off). The results do not depend on it.
    pub profile: bool,
    /// Step length, s.
    pub dt: Real,
    /// 1 / dt, 1/s.
    pub inv_dt: Real,
    /// Substep length, s.
    pub h: Real,
    /// 1 / h, 1/s.
    pub inv_h: Real,
    /// Number of substeps.
    pub substeps: u32,
    /// World gravity, m/s².
    pub gravity: Vec2,
    /// Softness of joint point rows.
    pub joint_softness: Softness,
    /// Softness of contact rows between two moving bodies.
    pub contact_softness: Softness,
    /// Softness of contact rows against a static body.
    pub static_softness: Softness,
    /// Maximum contact push-out speed, m/s (usual 3).
    pub contact_push_max_velocity: Real,
    /// Maximum correction speed of a Gauss–Seidel joint, m/s (usual
    /// `Real::MAX`: no cap).
    pub joint_max_correction_speed: Real,
    /// Restitution is applied only above this approach speed, m/s (usual 1).
    pub restitution_threshold: Real,
    /// Contact hertz, used where a constraint builds its own softness.
    pub contact_hertz: Real,
    /// Contact damping ratio.
    pub contact_damping_ratio: Real,
    /// Joint hertz.
    pub joint_hertz: Real,
    /// Joint damping ratio.
    pub joint_damping_ratio: Real,
    /// Warm starting on or off.
    pub warm_starting: bool,
    /// Soft step or PGS baseline.
    pub mode: SolverMode,
    /// False when no constraint of the step has restitution: the restitution
    /// stage is skipped (the world sets it from its contacts; usual true).
    pub restitution: bool,
    /// The finalize bounds each body's travel for continuous collision
    /// (`SolveReport::maybe_fast`); false when the world sweeps no body
    /// (continuous collision off, or no shapes), so the pass pays nothing
    /// for it (usual true).
    pub fast_bodies: bool,
    /// Largest stiffening factor of a contact between moving bodies
    /// (dimensionless, `≥ 1`; 1 in the PGS baseline), see
    /// [`SolverSettings::contact_mass_ratio_cap`](crate::solver::SolverSettings::contact_mass_ratio_cap).
    pub contact_mass_ratio_cap: Real,
    /// Largest stiffening factor of a joint's point rows (dimensionless,
    /// `≥ 1`), see
    /// [`SolverSettings::joint_mass_ratio_cap`](crate::solver::SolverSettings::joint_mass_ratio_cap).
    pub joint_mass_ratio_cap: Real,
    /// Joints forming a tree get their point rows solved directly (false in
    /// the PGS baseline), see
    /// [`SolverSettings::direct_joints`](crate::solver::SolverSettings::direct_joints).
    pub direct_joints: bool,
    /// Softness of the point rows solved directly.
    pub direct_joint_softness: Softness,
    /// Largest correction speed of a directly solved joint, m/s (usual 5).
    pub direct_joint_max_correction_speed: Real,
    /// Smallest mass spread of a free tree solved directly
    /// (dimensionless), see
    /// [`SolverSettings::direct_free_tree_mass_ratio`](crate::solver::SolverSettings::direct_free_tree_mass_ratio).
    pub direct_free_tree_mass_ratio: Real,
}

/// One body's part of one Jacobian row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyJacobian {
    /// The body.
    pub body: BodyHandle,
    /// Linear part, multiplies the centre-of-mass velocity.
    pub linear: Vec2,
    /// Angular part, multiplies the angular velocity.
    pub angular: Real,
    /// Inverse mass used by the constraint (0 for static or kinematic).
    pub inv_mass: Real,
    /// Inverse rotational inertia used by the constraint.
    pub inv_inertia: Real,
}

/// One row of a constraint.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The Jacobian, one entry per body the row touches.
    pub jacobian: SmallVec<[BodyJacobian; 4]>,
    /// Position error `C` (0 for pure velocity rows like friction or motors).
    pub c: Real,
    /// The row's softness for the current substep.
    pub softness: Softness,
    /// Lower impulse bound (`-∞` for an equality).
    pub lower: Real,
    /// Upper impulse bound (`+∞` for an equality).
    pub upper: Real,
    /// Impulse accumulated this step (used to warm start the next).
    pub impulse: Real,
}

/// A group of coupled rows solved together, with its effective mass.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// Index of the first row of the block in [`ConstraintRows::rows`].
    pub first_row: usize,
    /// Number of rows (1 to 3).
    pub len: usize,
    /// Effective mass `K = J M⁻¹ Jᵀ` of the block, row-major, `len × len`
    /// used.
    pub k: [[Real; 3]; 3],
}

/// What a constraint reports about itself: rows, blocks and their K.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ConstraintRows {
    /// All rows.
    pub rows: SmallVec<[Row; 4]>,
    /// Blocks of coupled rows, covering the rows in order.
    pub blocks: SmallVec<[Block; 4]>,
}

impl ConstraintRows {
    /// Computes `J M⁻¹ Jᵀ` for rows `i` and `j` from the reported Jacobians,
    /// merging entries that refer to the same body.
    pub fn jmj(&self, i: usize, j: usize) -> Real {
        let mut sum = 0.0;
        for a in &self.rows[i].jacobian {
            for b in &self.rows[j].jacobian {
                if a.body == b.body {
                    sum +=
                        a.inv_mass * a.linear.dot(b.linear) + a.inv_inertia * a.angular * b.angular;
                }
            }
        }
        sum
    }

    /// `J v` of row `i` given a velocity lookup.
    pub fn row_velocity(&self, i: usize, vel: impl Fn(BodyHandle) -> (Vec2, Real)) -> Real {
        self.rows[i]
            .jacobian
            .iter()
            .map(|e| {
                let (v, w) = vel(e.body);
                e.linear.dot(v) + e.angular * w
            })
            .sum()
    }
}

/// A constraint type. Implemented by contacts, joints and portals.
pub trait Constraint {
    /// Computes anchors, effective masses and softness for the step. Reads
    /// body data through `bodies`; stores state indices for the solve.
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet);

    /// Applies the impulses kept from the last step.
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]);

    /// One velocity iteration; `use_bias` selects position feedback (the
    /// main solve) or none (relax).
    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool);

    /// Applies restitution once after the substeps (contacts only).
    fn apply_restitution(&mut self, _ctx: &StepContext, _states: &mut [BodyState]) {}

    /// Keeps impulses for the next step's warm start.
    fn store_impulses(&mut self) {}

    /// Reports rows, Jacobians, K, C and impulses at the bodies' current
    /// positions (for tests, diagnostics and error metrics).
    fn rows(&self, ctx: &StepContext, bodies: &BodySet) -> ConstraintRows;

    /// False for a disabled constraint: the batch skips it.
    fn is_enabled(&self) -> bool {
        true
    }

    /// Solves every enabled constraint of `items` once, in storage order or
    /// (`reverse`) the opposite order: the batch's solve stage. A type may
    /// override it with a loop of its own (to hoist `use_bias` and the step
    /// constants out of the loop).
    fn solve_all(
        items: &mut [Self],
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) where
        Self: Sized,
    {
        if reverse {
            for c in items.iter_mut().rev() {
                if c.is_enabled() {
                    c.solve(ctx, states, use_bias);
                }
            }
        } else {
            for c in items.iter_mut() {
                if c.is_enabled() {
                    c.solve(ctx, states, use_bias);
                }
            }
        }
    }
}

/// A homogeneous collection of constraints driven by the solver: one
/// dynamic call per stage, a monomorphic loop inside.
///
/// The solver calls the `*_on` stages, which receive the step's worker
/// [`Team`]; their defaults run the serial stage on the leader. A batch
/// whose data splits into independent blocks (the contact colours)
/// overrides them to spread the blocks over the team.
pub trait ConstraintBatch: Send {
    /// Number of constraints.
    fn count(&self) -> usize;
    /// Prepare every constraint.
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet);
    /// Warm start every constraint.
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]);
    /// Solve every constraint once, in storage order or (`reverse`) the
    /// opposite order.
    fn solve(&mut self, ctx: &StepContext, states: &mut [BodyState], use_bias: bool, reverse: bool);
    /// A second solve pass that runs after every batch's `solve` in the same
    /// sweep (usual: nothing). The exact joint-tree solve runs here, so the
    /// joints it solves have the last word after the contacts.
    fn solve_late(&mut self, _ctx: &StepContext, _states: &mut [BodyState], _use_bias: bool) {}
    /// Restitution for every constraint.
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]);
    /// Store impulses of every constraint.
    fn store_impulses(&mut self);
    /// [`ConstraintBatch::prepare`] on the step's team.
    fn prepare_on(&mut self, ctx: &StepContext, bodies: &BodySet, _team: &Team) {
        self.prepare(ctx, bodies);
    }
    /// [`ConstraintBatch::warm_start`] on the step's team.
    fn warm_start_on(&mut self, ctx: &StepContext, states: &mut [BodyState], _team: &Team) {
        self.warm_start(ctx, states);
    }
    /// [`ConstraintBatch::solve`] on the step's team.
    fn solve_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
        _team: &Team,
    ) {
        self.solve(ctx, states, use_bias, reverse);
    }
    /// [`ConstraintBatch::solve_late`] on the step's team.
    fn solve_late_on(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        _team: &Team,
    ) {
        self.solve_late(ctx, states, use_bias);
    }
    /// [`ConstraintBatch::apply_restitution`] on the step's team.
    fn apply_restitution_on(&mut self, ctx: &StepContext, states: &mut [BodyState], _team: &Team) {
        self.apply_restitution(ctx, states);
    }
}

impl<C: Constraint + Send> ConstraintBatch for Vec<C> {
    fn count(&self) -> usize {
        self.len()
    }
    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        for c in self.iter_mut() {
            if c.is_enabled() {
                c.prepare(ctx, bodies);
            }
        }
    }
    fn warm_start(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        for c in self.iter_mut() {
            if c.is_enabled() {
                c.warm_start(ctx, states);
            }
        }
    }
    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        C::solve_all(self, ctx, states, use_bias, reverse);
    }
    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        for c in self.iter_mut() {
            if c.is_enabled() {
                c.apply_restitution(ctx, states);
            }
        }
    }
    fn store_impulses(&mut self) {
        for c in self.iter_mut() {
            if c.is_enabled() {
                c.store_impulses();
            }
        }
    }
}
