//! The step solver: Box2D v3's soft step, and a plain PGS baseline.
//!
//! ```text
//! soft step (SolverMode::SoftStep), h = dt / substeps
//!
//!   prepare bodies ─ prepare constraints (anchors, K, softness)
//!   repeat substeps times:
//!   │   integrate velocities   v += h (g + F/m), damping, speed caps
//!   │   warm start             apply the accumulated impulses
//!   │   solve (bias)           soft rows: push towards C = 0
//!   │   integrate positions    dp += h v, dq ← dq ⊕ h ω
//!   │   relax × n (no bias)    remove the velocity the bias added
//!   restitution ─ store impulses ─ finalize transforms
//!
//! PGS baseline (SolverMode::PgsBaumgarte), one step of length dt
//!
//!   prepare ─ integrate velocities ─ warm start
//!   ─ solve (Baumgarte bias β C / dt) × velocity_iterations
//!   ─ integrate positions ─ restitution ─ store ─ finalize
//! ```
//!
//! The constraints only see [`BodyState`]s (hot data): slot 0 is the static
//! identity state, which the solver resets after every step. Inverse masses
//! are not in the states: each constraint loads its bodies' at prepare, and
//! the velocity integration reads them from the bodies' `sims`.

use std::time::Instant;

use crate::body::{BodyHandle, BodySet, BodyState, BodyType};
use crate::constraint::{ConstraintBatch, SolverMode, StepContext};
use crate::math::{Real, Vec2, vec_is_finite};
use crate::parallel::{Team, with_team};
use crate::softness::Softness;

/// Default largest stiffening factor of a contact between two moving
/// bodies (dimensionless, usual 1.3; 1 gives Box2D v3's contacts). See
/// [`SolverSettings::contact_mass_ratio_cap`].
pub const DEFAULT_CONTACT_MASS_RATIO_CAP: Real = 1.3;

/// Default largest stiffening factor of a joint's point rows
/// (dimensionless, usual 1.3; 1 gives Box2D v3's joints). See
/// [`SolverSettings::joint_mass_ratio_cap`].
pub const DEFAULT_JOINT_MASS_RATIO_CAP: Real = 1.3;

/// Default largest contact stiffness as a fraction of the substep rate
/// (dimensionless, 1/8: 30 Hz at 240 Hz substeps). See
/// [`SolverSettings::contact_hertz_fraction`].
pub const CONTACT_HERTZ_PER_SUBSTEP_RATE: Real = 0.125;

/// Default largest joint stiffness (Gauss–Seidel rows) as a fraction of
/// the substep rate (dimensionless, 1/4: 60 Hz at 240 Hz substeps). See
/// [`SolverSettings::joint_hertz_fraction`].
pub const JOINT_HERTZ_PER_SUBSTEP_RATE: Real = 0.25;

/// Default stiffness of the point rows solved directly, Hz (usual 500).
/// See [`SolverSettings::direct_joint_hertz`].
pub const DEFAULT_DIRECT_JOINT_HERTZ: Real = 500.0;

/// Largest `contact_mass_ratio_cap` and `joint_mass_ratio_cap` (1e3): the
/// factor multiplies a row's effective mass; the defaults are 1.3 and a
/// joint grid already diverges near 2.
pub const MAX_MASS_RATIO_CAP: Real = 1e3;

/// Accuracy and softness settings of the solver. Every knob that trades
/// accuracy for time lives here.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverSettings {
    /// Soft step (default) or the PGS-with-Baumgarte baseline.
    pub mode: SolverMode,
    /// Substeps per step (soft step), usual 4.
    pub substeps: u32,
    /// Relax iterations per substep (soft step), usual 1.
    pub relax_iterations: u32,
    /// Velocity iterations (PGS baseline), usual 8.
    pub velocity_iterations: u32,
    /// Baumgarte factor β of the PGS baseline (dimensionless), usual 0.2.
    pub baumgarte: Real,
    /// Contact stiffness, Hz (usual 30; at most `contact_hertz_fraction`
    /// of the substep rate is used, see [`SolverSettings::effective_hertz`]).
    pub contact_hertz: Real,
    /// Largest contact stiffness as a fraction of the substep rate
    /// (dimensionless, usual 1/8; `Real::INFINITY`: no cap). A contact
    /// spring much stiffer than the substep rate overshoots with one
    /// iteration per substep: the base-100 pyramid collapses at 2 substeps
    /// with 30 Hz contacts and stands with 15 Hz (Box2D softens its contacts
    /// the same way when substeps are few). At 4 substeps and 1/60 s the
    /// cap is 30 Hz: raise it to use stiffer contacts there.
    pub contact_hertz_fraction: Real,
    /// Contact damping ratio (usual 10).
    pub contact_damping_ratio: Real,
    /// Maximum contact push-out speed, m/s (usual 3).
    pub contact_push_max_velocity: Real,
    /// Joint stiffness, Hz (usual 60; at most `joint_hertz_fraction` of
    /// the substep rate is used, see [`SolverSettings::effective_hertz`]).
    pub joint_hertz: Real,
    /// Largest stiffness of Gauss–Seidel joint rows as a fraction of the
    /// substep rate (dimensionless, usual 1/4; `Real::INFINITY`: no cap):
    /// the 40×40 joint grid diverges at 2 substeps with 60 Hz joints and
    /// holds (1.4 m peak gap) at 30 Hz. Joint trees use
    /// `direct_joint_hertz` uncapped (an exact solve is stable at any
    /// stiffness).
    pub joint_hertz_fraction: Real,
    /// Joint damping ratio (usual 2).
    pub joint_damping_ratio: Real,
    /// Maximum correction speed of a joint solved by Gauss–Seidel, m/s
    /// (usual 50; `Real::MAX`: no cap). A rigid row's position feedback
    /// `β C` is capped here, a violated limit's too, and angle rows at the
    /// same number in rad/s (`janus2d_constraints::parts::CORRECTION_ARM`);
    /// springs are not capped. Uncapped, a joint created 10 m open pulled
    /// its body at 240 m/s, and a prismatic chain with violated limits
    /// diverged; low caps loosen large Gauss–Seidel meshes (5 m/s raised the
    /// 40×40 joint grid's peak gap from 0.17 to 0.32 m; the 100×100
    /// `joint_grid` benchmark's largest feedback is 39 m/s, below the cap).
    /// Joint trees use `direct_joint_max_correction_speed` instead.
    pub joint_max_correction_speed: Real,
    /// Restitution threshold, m/s (usual 1).
    pub restitution_threshold: Real,
    /// Warm starting on (default) or off.
    pub warm_starting: bool,
    /// Mass-ratio-aware contact stiffness (dimensionless, usual 1.3, `≤ 1`
    /// switches it off). A contact between two moving bodies builds its
    /// soft spring on the effective mass of the *heavier* side at the point
    /// (`1 / min(k_a, k_b)`, `k = 1/m + (r × n)²/I` of one body) instead of
    /// the pair's (`1 / (k_a + k_b)`), so a light body under a heavy one
    /// deflects as if on the ground. The factor `ρ = (k_a + k_b) / min(k_a,
    /// k_b)` is capped here: with one iteration per substep stiffer rows
    /// make deep pyramids jitter and heavy-topped ones collapse. Contacts
    /// with a static body keep their own (twice as stiff) softness.
    pub contact_mass_ratio_cap: Real,
    /// Mass-ratio-aware joint stiffness (dimensionless, usual 1.3, `≤ 1`
    /// switches it off): a joint's point rows build their spring on the
    /// heavier body's mass, `ρ = (1/m_a + 1/m_b) / min(1/m_a, 1/m_b)`
    /// (the cap itself against a static or kinematic body), capped here for
    /// the same stability reason (a cloth-like joint grid diverges near 2).
    pub joint_mass_ratio_cap: Real,
    /// Direct (exact) solve of the joints' point rows wherever the joints
    /// form a tree (usual true; soft step only). The point rows of joints
    /// that close a loop stay iterative. See `janus2d_constraints::joint_tree`.
    pub direct_joints: bool,
    /// Stiffness of the point rows in the direct joint solve, Hz (usual
    /// 500). A joint's static stretch under a load is `F K / ω²` per unit
    /// effective mass, so the stiffness sets how heavy a load a light link
    /// holds: a 1 m link of 1 kg swinging a bob from horizontal stays within
    /// 1 cm up to a 3,000:1 bob at 500 Hz (1,000:1: 3 mm; at 240 Hz
    /// 1,000:1 stretched it 1.3 cm); the 670:1 ball and chain's peak gap is
    /// 6 mm (240 Hz: 2.2 cm). An exact solve is stable at any stiffness,
    /// but its rounding grows with it (at 1000 Hz the tree solve's momentum
    /// property failed in f32).
    pub direct_joint_hertz: Real,
    /// Largest position-correction speed of one directly solved joint, m/s
    /// (usual 2). The exact solve corrects every joint of a chain at once,
    /// so the speeds add up along it: uncapped, a chain stretched by 1 m at
    /// each of 40 joints flings its end at 600 m/s; at 2 m/s (500 Hz) it
    /// peaks at 68 m/s, about the 67 m/s the same chain reaches by swinging
    /// alone (5 m/s: 138 m/s), and every joint is back within 1 cm. The
    /// tree's angle rows (a rigid weld's, a prismatic joint's) are capped
    /// at the same number in rad/s: uncapped at 500 Hz, a prismatic chain
    /// started 3 rad from its reference angles flung its sliders at over
    /// 1,000 m/s. Iterative joints keep `joint_max_correction_speed`.
    pub direct_joint_max_correction_speed: Real,
    /// Smallest spread of masses (heaviest ÷ lightest moving body,
    /// dimensionless, usual [`DEFAULT_DIRECT_FREE_TREE_MASS_RATIO`]) at
    /// which a short joint tree held by no fixed end (a ragdoll) still
    /// takes the direct solve; below it, and if its longest path is at
    /// most `2 × substeps` joints (the Gauss–Seidel sweeps of a step: a
    /// solve and a relax per substep, so an impulse crosses the tree
    /// within the step), the tree's joints are solved by Gauss–Seidel like
    /// any other. The direct solve is for light links carrying heavy loads
    /// and for long chains; a short free tree of like masses (a ragdoll)
    /// holds as well under Gauss–Seidel at a fraction of the cost. A tree
    /// held by a static, kinematic or sleeping body always takes it (a
    /// hanging chain stretches under Gauss–Seidel at any mass ratio), and
    /// so does a longer one (a thrown rope). Figures in
    /// docs/architecture.md. `≤ 1`: every tree; `∞`: no short free tree.
    pub direct_free_tree_mass_ratio: Real,
}

/// See [`SolverSettings::direct_free_tree_mass_ratio`].
pub const DEFAULT_DIRECT_FREE_TREE_MASS_RATIO: Real = 10.0;

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            mode: SolverMode::SoftStep,
            substeps: 4,
            relax_iterations: 1,
            velocity_iterations: 8,
            baumgarte: 0.2,
            contact_hertz: 30.0,
            contact_hertz_fraction: CONTACT_HERTZ_PER_SUBSTEP_RATE,
            contact_damping_ratio: 10.0,
            contact_push_max_velocity: 3.0,
            joint_hertz: 60.0,
            joint_hertz_fraction: JOINT_HERTZ_PER_SUBSTEP_RATE,
            joint_damping_ratio: 2.0,
            joint_max_correction_speed: 50.0,
            restitution_threshold: 1.0,
            warm_starting: true,
            contact_mass_ratio_cap: DEFAULT_CONTACT_MASS_RATIO_CAP,
            joint_mass_ratio_cap: DEFAULT_JOINT_MASS_RATIO_CAP,
            direct_joints: true,
            direct_joint_hertz: DEFAULT_DIRECT_JOINT_HERTZ,
            direct_joint_max_correction_speed: 2.0,
            direct_free_tree_mass_ratio: DEFAULT_DIRECT_FREE_TREE_MASS_RATIO,
        }
    }
}

/// A solver setting that is out of its range, named by its field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// The field is NaN (or infinite where its range is finite).
    NonFinite(&'static str),
    /// The field is outside its stated range (see
    /// [`SolverSettings::validate`]).
    OutOfRange(&'static str),
}

impl SolverSettings {
    /// Checks every field against its stated range; the error names the
    /// first field that is wrong: NaN (or ∞ where the range is finite) is
    /// `NonFinite`, a value outside its range `OutOfRange`.
    ///
    /// | field                                   | range                                   |
    /// |-----------------------------------------|-----------------------------------------|
    /// | `substeps`                              | 1 … 1024                                |
    /// | `velocity_iterations`, `relax_iterations` | 0 … 1024                              |
    /// | `baumgarte`                             | 0 … 1 (β > 1 overshoots every error)    |
    /// | `contact_hertz`, `joint_hertz`          | 0 … `Real::MAX` (a world caps them at [`MAX_HERTZ_FRACTION`](crate::limits::MAX_HERTZ_FRACTION) of the substep rate) |
    /// | `direct_joint_hertz`                    | 0 … [`MAX_SPRING_HERTZ`](crate::limits::MAX_SPRING_HERTZ) (1e6 Hz) |
    /// | `contact_damping_ratio`, `joint_damping_ratio` | 0 … [`MAX_DAMPING_RATIO`](crate::limits::MAX_DAMPING_RATIO) (1e4) |
    /// | `contact_push_max_velocity`, `restitution_threshold`, `direct_joint_max_correction_speed` | 0 … [`MAX_SPEED`](crate::limits::MAX_SPEED) (1e9 m/s) |
    /// | `joint_max_correction_speed`            | 0 … `Real::MAX` (`Real::MAX`: no cap)   |
    /// | `contact_mass_ratio_cap`, `joint_mass_ratio_cap` | 0 … [`MAX_MASS_RATIO_CAP`] (1e3) |
    /// | `contact_hertz_fraction`, `joint_hertz_fraction` | ≥ 0, `∞` allowed (no cap)      |
    /// | `direct_free_tree_mass_ratio`           | ≥ 0, `∞` allowed (no free tree direct)  |
    ///
    /// ```
    /// use janus2d_core::solver::{SettingsError, SolverSettings};
    /// let bad = SolverSettings { contact_hertz: -1.0, ..SolverSettings::default() };
    /// assert_eq!(bad.validate(), Err(SettingsError::OutOfRange("contact_hertz")));
    /// let bad = SolverSettings { baumgarte: 1e30, ..SolverSettings::default() };
    /// assert_eq!(bad.validate(), Err(SettingsError::OutOfRange("baumgarte")));
    /// assert!(SolverSettings::default().validate().is_ok());
    /// ```
    pub fn validate(&self) -> Result<(), SettingsError> {
        use crate::limits::{MAX_DAMPING_RATIO, MAX_SPEED, MAX_SPRING_HERTZ};
        // (value, name, largest value; ∞: unbounded, ∞ allowed)
        let reals = [
            (self.baumgarte, "baumgarte", 1.0),
            (self.contact_hertz, "contact_hertz", Real::MAX),
            (
                self.contact_hertz_fraction,
                "contact_hertz_fraction",
                Real::INFINITY,
            ),
            (
                self.contact_damping_ratio,
                "contact_damping_ratio",
                MAX_DAMPING_RATIO,
            ),
            (
                self.contact_push_max_velocity,
                "contact_push_max_velocity",
                MAX_SPEED,
            ),
            (self.joint_hertz, "joint_hertz", Real::MAX),
            (
                self.joint_hertz_fraction,
                "joint_hertz_fraction",
                Real::INFINITY,
            ),
            (
                self.joint_damping_ratio,
                "joint_damping_ratio",
                MAX_DAMPING_RATIO,
            ),
            (
                self.joint_max_correction_speed,
                "joint_max_correction_speed",
                Real::MAX,
            ),
            (
                self.restitution_threshold,
                "restitution_threshold",
                MAX_SPEED,
            ),
            (
                self.contact_mass_ratio_cap,
                "contact_mass_ratio_cap",
                MAX_MASS_RATIO_CAP,
            ),
            (
                self.joint_mass_ratio_cap,
                "joint_mass_ratio_cap",
                MAX_MASS_RATIO_CAP,
            ),
            (
                self.direct_joint_hertz,
                "direct_joint_hertz",
                MAX_SPRING_HERTZ,
            ),
            (
                self.direct_joint_max_correction_speed,
                "direct_joint_max_correction_speed",
                MAX_SPEED,
            ),
            (
                self.direct_free_tree_mass_ratio,
                "direct_free_tree_mass_ratio",
                Real::INFINITY,
            ),
        ];
        for (v, name, max) in reals {
            if v.is_nan() || (v.is_infinite() && max.is_finite()) {
                return Err(SettingsError::NonFinite(name));
            }
            if v < 0.0 || v > max {
                return Err(SettingsError::OutOfRange(name));
            }
        }
        if self.substeps == 0 || self.substeps > 1024 {
            return Err(SettingsError::OutOfRange("substeps"));
        }
        if self.velocity_iterations > 1024 {
            return Err(SettingsError::OutOfRange("velocity_iterations"));
        }
        if self.relax_iterations > 1024 {
            return Err(SettingsError::OutOfRange("relax_iterations"));
        }
        Ok(())
    }

    /// The contact and joint stiffness a substep of `h` seconds solves
    /// with, Hz: `contact_hertz` and `joint_hertz`, capped at
    /// `contact_hertz_fraction` and `joint_hertz_fraction` of the substep
    /// rate `1/h`. With the usual settings at 60 Hz and 4 or more substeps
    /// the caps (30 and 60 Hz) leave them as they are; with fewer substeps
    /// the springs soften with the substep rate.
    ///
    /// ```
    /// use janus2d_core::solver::SolverSettings;
    /// let s = SolverSettings::default();
    /// assert_eq!(s.effective_hertz(1.0 / 240.0), (30.0, 60.0));
    /// let (contact, joint) = s.effective_hertz(1.0 / 120.0);
    /// assert!((contact - 15.0).abs() < 1e-3 && (joint - 30.0).abs() < 1e-3);
    /// let uncapped = SolverSettings { contact_hertz: 60.0, contact_hertz_fraction: f32::INFINITY as _, ..s };
    /// assert_eq!(uncapped.effective_hertz(1.0 / 240.0).0, 60.0);
    /// ```
    #[must_use]
    pub fn effective_hertz(&self, h: Real) -> (Real, Real) {
        if h <= 0.0 {
            return (self.contact_hertz, self.joint_hertz);
        }
        let rate = 1.0 / h;
        // A stiffness within rounding of its cap is left exactly as set
        // (30 Hz at 1/240 s: 1/h rounds to 239.99998 in f32).
        let capped = |hertz: Real, fraction: Real| {
            let cap = fraction * rate;
            if hertz <= cap * (1.0 + 1.0e-4) {
                hertz
            } else {
                cap
            }
        };
        (
            capped(self.contact_hertz, self.contact_hertz_fraction),
            capped(self.joint_hertz, self.joint_hertz_fraction),
        )
    }

    /// Builds the per-step context.
    pub fn context(&self, dt: Real, gravity: Vec2) -> StepContext {
        let (substeps, h) = match self.mode {
            SolverMode::SoftStep => {
                let n = self.substeps.max(1);
                (n, dt / n as Real)
            }
            SolverMode::PgsBaumgarte => (1, dt),
        };
        let (contact_hertz, joint_hertz) = self.effective_hertz(h);
        let (joint_softness, contact_softness, static_softness) = match self.mode {
            SolverMode::SoftStep => (
                Softness::new(joint_hertz, self.joint_damping_ratio, h),
                Softness::new(contact_hertz, self.contact_damping_ratio, h),
                Softness::new(2.0 * contact_hertz, self.contact_damping_ratio, h),
            ),
            SolverMode::PgsBaumgarte => {
                let s = Softness::baumgarte(self.baumgarte, dt);
                (s, s, s)
            }
        };
        StepContext {
            profile: true,
            dt,
            inv_dt: if dt > 0.0 { 1.0 / dt } else { 0.0 },
            h,
            inv_h: if h > 0.0 { 1.0 / h } else { 0.0 },
            substeps,
            gravity,
            joint_softness,
            contact_softness,
            static_softness,
            contact_push_max_velocity: self.contact_push_max_velocity,
            joint_max_correction_speed: self.joint_max_correction_speed,
            restitution_threshold: self.restitution_threshold,
            contact_hertz,
            contact_damping_ratio: self.contact_damping_ratio,
            joint_hertz,
            joint_damping_ratio: self.joint_damping_ratio,
            warm_starting: self.warm_starting,
            mode: self.mode,
            restitution: true,
            fast_bodies: true,
            contact_mass_ratio_cap: match self.mode {
                SolverMode::SoftStep => self.contact_mass_ratio_cap.max(1.0),
                SolverMode::PgsBaumgarte => 1.0,
            },
            joint_mass_ratio_cap: match self.mode {
                SolverMode::SoftStep => self.joint_mass_ratio_cap.max(1.0),
                SolverMode::PgsBaumgarte => 1.0,
            },
            direct_joints: self.direct_joints && self.mode == SolverMode::SoftStep,
            direct_joint_softness: Softness::new(
                self.direct_joint_hertz,
                self.joint_damping_ratio,
                h,
            ),
            direct_joint_max_correction_speed: self.direct_joint_max_correction_speed,
            direct_free_tree_mass_ratio: self.direct_free_tree_mass_ratio,
        }
    }
}

/// Time spent in each solver stage during the last step, seconds. The
/// substeps' stages (integrate, warm start, solve, relax) are timed on the
/// first substep; the whole substep loop is timed, and the later
/// substeps' time is split over the stages as the first's was (a clock
/// read per stage and substep cost a sixth of a small scene's step).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SolverProfile {
    /// Preparing bodies and constraints.
    pub prepare: f64,
    /// Integrating velocities and positions.
    pub integrate: f64,
    /// Warm starting.
    pub warm_start: f64,
    /// Solving with bias.
    pub solve: f64,
    /// Relaxing (solving without bias).
    pub relax: f64,
    /// Restitution.
    pub restitution: f64,
    /// Storing impulses and finalizing transforms.
    pub finalize: f64,
}

/// What happened in a solve besides the new state.
#[derive(Clone, Debug, Default)]
pub struct SolveReport {
    /// Bodies whose state went non-finite; they were reset to their
    /// start-of-step pose at rest.
    pub non_finite: Vec<BodyHandle>,
    /// Every moving body's pose after the step is finite and within
    /// [`POSE_LIMIT`] (checked while the poses were written, so that the
    /// caller's [`BodySet::reset_escaped`] pass can be skipped); false when
    /// unknown.
    pub poses_inside: bool,
    /// Some moving body may have travelled far enough in the step for
    /// continuous collision to sweep it ([`BodySim::may_be_fast`](crate::body::BodySim::may_be_fast), asked
    /// only when [`StepContext::fast_bodies`]). When false no body is fast
    /// ([`BodySim::is_fast`](crate::body::BodySim::is_fast)) and the continuous stage has nothing
    /// to scan.
    pub maybe_fast: bool,
    /// Stage timings.
    pub profile: SolverProfile,
}

/// The largest coordinate a pose may reach in a step, m: twice
/// [`crate::limits::MAX_COORDINATE`]; beyond it (or at inf or NaN) the body
/// is put back ([`BodySet::reset_escaped`]).
pub const POSE_LIMIT: Real = 2.0 * crate::limits::MAX_COORDINATE;

/// The first substep's stage times, s.
#[derive(Default)]
struct SubstepTimes {
    integrate: f64,
    warm_start: f64,
    solve: f64,
    relax: f64,
}

impl SubstepTimes {
    /// Adds the substep loop's `total` time to `profile`, split over the
    /// stages as the first substep's times were.
    fn spread_over(&self, total: f64, profile: &mut SolverProfile) {
        let sum = self.integrate + self.warm_start + self.solve + self.relax;
        if sum <= 0.0 {
            profile.solve += total;
            return;
        }
        let scale = total / sum;
        profile.integrate += self.integrate * scale;
        profile.warm_start += self.warm_start * scale;
        profile.solve += self.solve * scale;
        profile.relax += self.relax * scale;
    }
}

#[inline]
fn lap(t: &mut Instant) -> f64 {
    let now = Instant::now();
    let d = now.duration_since(*t).as_secs_f64();
    *t = now;
    d
}

/// The step's start for every body: the pose it began at, zero deltas, the
/// solver flags. In blocks of bodies on the team.
fn prepare_bodies(bodies: &mut BodySet, team: &Team) {
    let BodySet { sims, states, .. } = bodies;
    team.for_each_chunk_pair_mut(sims, states, BODY_BLOCK, |i, sims, states| {
        // Slot 0 is the static identity (its sim is a placeholder).
        let skip = usize::from(i == 0);
        for (sim, state) in sims.iter_mut().zip(states.iter_mut()).skip(skip) {
            sim.center0 = sim.center;
            sim.rotation0 = sim.transform.q;
            state.dp = Vec2::ZERO;
            state.dq = crate::math::Rot::IDENTITY;
            state.flags = sim.state_flags();
        }
    });
}

/// Integrates velocities of moving bodies over one substep `h`: gravity,
/// forces, damping, the maximum linear speed and the rotation limit.
pub fn integrate_velocities(ctx: &StepContext, bodies: &mut BodySet) {
    let h = ctx.h;
    let gravity = ctx.gravity;
    let has_gravity = gravity != Vec2::ZERO;
    let BodySet { sims, states, .. } = bodies;
    for (sim, state) in sims.iter().zip(states.iter_mut()).skip(1) {
        if sim.body_type != BodyType::Dynamic {
            continue;
        }
        let linear_damping = 1.0 / (1.0 + h * sim.linear_damping);
        let angular_damping = 1.0 / (1.0 + h * sim.angular_damping);
        let mut accel = sim.inv_mass * sim.force;
        if has_gravity {
            accel += sim.gravity_scale * gravity;
        }
        let mut v = linear_damping * (state.v + h * accel);
        let mut w = angular_damping * (state.w + h * sim.inv_inertia * sim.torque);
        v = clamp_speed(v, sim.max_linear_speed);
        let max_w = sim.max_rotation * ctx.inv_h;
        if w * w > max_w * max_w {
            w = w.clamp(-max_w, max_w);
        }
        state.v = v;
        state.w = w;
        state.apply_locks();
    }
}

/// The velocity integration of one body over a substep, with everything
/// that is fixed for the step (forces, gravity, damping, limits) evaluated
/// once: [`integrate_velocities`] on a compact array instead of the
/// bodies' per-step data. Same arithmetic, same results.
#[derive(Clone, Copy, Debug, Default)]
struct VelocityTerms {
    /// The body is dynamic (the others' velocities are not integrated).
    dynamic: bool,
    /// `h (F/m + s g)`, m/s.
    dv: Vec2,
    /// `h τ / I`, rad/s.
    dw: Real,
    /// `1 / (1 + h c_lin)`.
    linear_damping: Real,
    /// `1 / (1 + h c_ang)`.
    angular_damping: Real,
    /// Maximum linear speed, m/s.
    max_v: Real,
    /// Maximum angular speed over the substep, rad/s.
    max_w: Real,
}

/// The [`VelocityTerms`] of every body, by state index (state 0 and the
/// bodies that are not dynamic are marked so), in blocks on the team.
fn velocity_terms(ctx: &StepContext, bodies: &BodySet, team: &Team) -> StepTerms {
    let h = ctx.h;
    let gravity = ctx.gravity;
    let has_gravity = gravity != Vec2::ZERO;
    let sims = &bodies.sims[..];
    let mut terms = vec![VelocityTerms::default(); sims.len()];
    // The smallest speed limit, as the bits of an f64 (a limit is ≥ 0,
    // and the bits of non-negative floats order as the floats do); no
    // dynamic body: the largest Real.
    let floor_bits = std::sync::atomic::AtomicU64::new(crate::math::to_f64(Real::MAX).to_bits());
    let any_locks = std::sync::atomic::AtomicBool::new(false);
    team.for_each_chunk_mut(&mut terms, BODY_BLOCK, |i, block| {
        let start = i * BODY_BLOCK;
        let mut floor = Real::MAX;
        let mut locks = 0;
        for (k, t) in block.iter_mut().enumerate() {
            let sim = &sims[start + k];
            if start + k == 0 || sim.body_type != BodyType::Dynamic {
                continue;
            }
            let mut accel = sim.inv_mass * sim.force;
            if has_gravity {
                accel += sim.gravity_scale * gravity;
            }
            *t = VelocityTerms {
                dynamic: true,
                dv: h * accel,
                dw: h * sim.inv_inertia * sim.torque,
                linear_damping: 1.0 / (1.0 + h * sim.linear_damping),
                angular_damping: 1.0 / (1.0 + h * sim.angular_damping),
                max_v: sim.max_linear_speed,
                max_w: sim.max_rotation * ctx.inv_h,
            };
            floor = floor.min(sim.max_linear_speed.max(0.0));
            locks |= sim.linear_locks;
        }
        if locks != 0 {
            any_locks.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        floor_bits.fetch_min(
            crate::math::to_f64(floor).to_bits(),
            std::sync::atomic::Ordering::Relaxed,
        );
    });
    // Exact: the bits are of a Real widened to f64.
    let floor = crate::math::from_f64(f64::from_bits(floor_bits.into_inner()));
    StepTerms {
        terms,
        speed_floor_sq: floor * floor,
        locks: any_locks.into_inner(),
    }
}

/// The step's [`VelocityTerms`] and the square of the smallest speed limit
/// among them, m²/s²: a velocity no longer than that needs no clamp, so
/// the passes after the solve read a body's terms only when it is faster.
struct StepTerms {
    terms: Vec<VelocityTerms>,
    speed_floor_sq: Real,
    /// Some dynamic body has motion locks: without any, the passes skip
    /// the lock test (a scene without locks pays nothing for them).
    locks: bool,
}

/// [`integrate_velocities`] from precomputed terms (one per state: block
/// `i` of the states meets block `i` of the terms).
fn integrate_velocity_terms(terms: &StepTerms, states: &mut [BodyState], team: &Team) {
    team.for_each_chunk_mut(states, BODY_BLOCK, |i, block| {
        let start = i * BODY_BLOCK;
        let block_terms = &terms.terms[start..start + block.len()];
        if terms.locks {
            integrate_terms::<true>(block_terms, block);
        } else {
            integrate_terms::<false>(block_terms, block);
        }
    });
}

/// One block's velocity integration; `LOCKS`: some body may have motion
/// locks.
fn integrate_terms<const LOCKS: bool>(terms: &[VelocityTerms], states: &mut [BodyState]) {
    for (t, state) in terms.iter().zip(states.iter_mut()) {
        if !t.dynamic {
            continue;
        }
        let mut v = t.linear_damping * (state.v + t.dv);
        let mut w = t.angular_damping * (state.w + t.dw);
        v = clamp_speed(v, t.max_v);
        if w * w > t.max_w * t.max_w {
            w = w.clamp(-t.max_w, t.max_w);
        }
        state.v = v;
        state.w = w;
        // Motion locks: the locked components are zero before the solve.
        if LOCKS {
            state.apply_locks();
        }
    }
}

/// `v` shortened to length `max` when longer (direction kept). The length
/// is taken on `v` scaled by its largest component, so a velocity whose
/// `|v|²` overflows (a force of 1e30 N) is shortened, not zeroed; a
/// non-finite `v` is left for the step's finite check.
#[inline(always)]
#[must_use]
pub fn clamp_speed(v: Vec2, max: Real) -> Vec2 {
    let v2 = v.length_squared();
    if v2 <= max * max {
        return v;
    }
    if v2.is_finite() {
        return v * (max / v2.sqrt());
    }
    let big = v.x.abs().max(v.y.abs());
    if !big.is_finite() {
        return v;
    }
    let unit = v / big;
    unit * (max / unit.length())
}

/// The speed limit (and motion locks) on one block of states, the block
/// starting at state `start`: before each substep's positions are
/// integrated (`integrate_positions_on`), and again in the finalize after
/// the last stages that changed velocities (relax, restitution). A block
/// with no state above the step's smallest limit and no locks is only
/// read once (`any_faster`). (The rotation limit stays a limit of the
/// integration only: clamping spin after the solve changes valid scenes,
/// spinner's hash among them.)
#[inline(always)]
fn clamp_velocity_terms(terms: &StepTerms, block: &mut [BodyState], start: usize) {
    if terms.locks {
        for (k, state) in block.iter_mut().enumerate() {
            clamp_to_terms::<true>(state, terms, start + k);
        }
    } else if any_faster(block, terms.speed_floor_sq) {
        for (k, state) in block.iter_mut().enumerate() {
            clamp_to_terms::<false>(state, terms, start + k);
        }
    }
}

/// The positions of a block of states over a substep of length `h` (s):
/// a loop of its own, which the compiler vectorises.
#[inline(never)]
fn integrate_block(block: &mut [BodyState], h: Real) {
    for state in block {
        state.dq = state.dq.integrate(h * state.w);
        state.dp += h * state.v;
    }
}

/// Whether some state of `block` is faster than the step's smallest speed
/// limit (`floor_sq` its square, m²/s²): one branch-free pass, so a block
/// with nothing to clamp runs the plain integration.
#[inline(always)]
fn any_faster(block: &[BodyState], floor_sq: Real) -> bool {
    block
        .iter()
        .fold(false, |any, s| any | (s.v.length_squared() > floor_sq))
}

/// A dynamic body's velocity clamped to its speed limit, then its motion
/// locks (only a dynamic body has lock flags): its terms are read only
/// when it is faster than the smallest limit.
#[inline(always)]
fn clamp_to_terms<const LOCKS: bool>(state: &mut BodyState, terms: &StepTerms, i: usize) {
    if state.v.length_squared() > terms.speed_floor_sq {
        let t = &terms.terms[i];
        if t.dynamic {
            state.v = clamp_speed(state.v, t.max_v);
        }
    }
    // Motion locks: what the solve gave a locked axis does not move the
    // body (a constraint that comes last).
    if LOCKS {
        state.apply_locks();
    }
}

/// Integrates positions of moving bodies over one substep (into the deltas).
pub fn integrate_positions(ctx: &StepContext, bodies: &mut BodySet) {
    let h = ctx.h;
    for state in bodies.states.iter_mut().skip(1) {
        state.apply_locks();
        state.dq = state.dq.integrate(h * state.w);
        state.dp += h * state.v;
    }
}

/// [`integrate_positions`] on the team, in blocks of bodies.
/// The speed limit is applied first (the solve may have changed the
/// velocities): a dynamic body's velocity is clamped to its
/// `max_linear_speed` before it moves. Each body's clamp and move read
/// only its own state, so clamping the block before moving it gives the
/// same numbers as doing both body by body.
fn integrate_positions_on(
    ctx: &StepContext,
    terms: &StepTerms,
    states: &mut [BodyState],
    team: &Team,
) {
    let h = ctx.h;
    team.for_each_chunk_mut(states, BODY_BLOCK, |i, block| {
        // State 0 is the static identity: it never moves.
        let skip = usize::from(i == 0);
        let block = &mut block[skip..];
        clamp_velocity_terms(terms, block, i * BODY_BLOCK + skip);
        integrate_block(block, h);
    });
}

/// The step's end for every body: velocities clamped to their speed
/// limits (`clamp_velocity_terms`), the pose from the deltas, forces
/// cleared, and whether every pose is inside [`POSE_LIMIT`]
/// ([`SolveReport::poses_inside`]). In blocks on the team; a body whose
/// state is not finite is left for the serial pass after, which zeroes its
/// motion and reports it (in body order).
fn finalize_bodies(
    bodies: &mut BodySet,
    terms: &StepTerms,
    fast_bodies: bool,
    report: &mut SolveReport,
    team: &Team,
    beside: impl FnOnce(),
) {
    let finite = |state: &BodyState| {
        vec_is_finite(state.v)
            && state.w.is_finite()
            && vec_is_finite(state.dp)
            && state.dq.is_finite()
    };
    let any_bad = std::sync::atomic::AtomicBool::new(false);
    let any_outside = std::sync::atomic::AtomicBool::new(false);
    let any_fast = std::sync::atomic::AtomicBool::new(false);
    let BodySet { sims, states, .. } = bodies;
    let finalize = |i: usize, sims: &mut [crate::body::BodySim], states: &mut [BodyState]| {
        clamp_velocity_terms(terms, states, i * BODY_BLOCK);
        let skip = usize::from(i == 0);
        let mut outside = false;
        let mut fast = false;
        for (sim, state) in sims.iter_mut().zip(states.iter()).skip(skip) {
            if finite(state) {
                sim.center = sim.center0 + state.dp;
                sim.transform.q = state.dq.mul(sim.rotation0).normalize();
                sim.transform.p = sim.center - sim.transform.q.rotate(sim.local_center);
                sim.force = Vec2::ZERO;
                sim.torque = 0.0;
                fast |= fast_bodies && sim.may_be_fast();
            } else {
                any_bad.store(true, std::sync::atomic::Ordering::Relaxed);
            }
            outside |= !sim.pose_within(POSE_LIMIT);
        }
        if outside {
            any_outside.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        if fast {
            any_fast.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    };
    team.for_each_chunk_pair_mut_beside(sims, states, BODY_BLOCK, finalize, beside);
    report.poses_inside = !any_outside.into_inner();
    report.maybe_fast = any_fast.into_inner();
    if any_bad.into_inner() {
        for (sim, state) in sims.iter_mut().zip(states.iter_mut()).skip(1) {
            if !finite(state) {
                report.non_finite.push(sim.handle);
                state.v = Vec2::ZERO;
                state.w = 0.0;
                state.dp = Vec2::ZERO;
                state.dq = crate::math::Rot::IDENTITY;
            }
        }
    }
    states[0] = BodyState::IDENTITY;
}

/// Advances the bodies by one step, solving every batch of constraints.
///
/// `batches` holds one entry per constraint type (each a `Vec<C>`).
///
/// With the `parallel` feature the stages run on a worker team of their
/// own ([`crate::parallel`]; the world's step passes its own team to
/// [`solve_step_on`] instead): one rayon broadcast, the stages' blocks
/// claimed through atomics; the result does not depend on the number of
/// threads.
pub fn solve_step(
    settings: &SolverSettings,
    ctx: &StepContext,
    bodies: &mut BodySet,
    batches: &mut [&mut dyn ConstraintBatch],
) -> SolveReport {
    with_team(|team| solve_step_on(settings, ctx, bodies, batches, team))
}

/// Bodies per block of the integration stages.
const BODY_BLOCK: usize = 256;

/// [`solve_step`] on a team the caller holds (the world runs its whole
/// step on one team: collision stages and the solve share its workers).
pub fn solve_step_on(
    settings: &SolverSettings,
    ctx: &StepContext,
    bodies: &mut BodySet,
    batches: &mut [&mut dyn ConstraintBatch],
    team: &Team,
) -> SolveReport {
    let mut report = SolveReport::default();
    let mut t = Instant::now();
    // The stage clocks, read only while the world profiles its steps.
    let clock = |t: &mut Instant| if ctx.profile { lap(t) } else { 0.0 };
    prepare_bodies(bodies, team);
    let terms = velocity_terms(ctx, bodies, team);
    for b in batches.iter_mut() {
        b.prepare_on(ctx, bodies, team);
    }
    report.profile.prepare += clock(&mut t);

    let (substeps, solve_iterations, relax_iterations) = match ctx.mode {
        SolverMode::SoftStep => (ctx.substeps, 1, settings.relax_iterations),
        SolverMode::PgsBaumgarte => (1, settings.velocity_iterations.max(1), 0),
    };
    let active: Vec<usize> = (0..batches.len())
        .filter(|&i| batches[i].count() > 0)
        .collect();
    // Symmetric Gauss–Seidel: sweeps alternate direction (solve forwards,
    // relax backwards, and the other way round on the next substep), so
    // information travels both ways along chains and stacks, and the order
    // of creation leaves no sideways bias.
    // The substeps' stages are timed on the first substep only; the
    // loop's whole time is measured, and the later substeps' share is
    // split as the first's was (a clock read costs about 25 ns: five per
    // substep were a sixth of a small scene's step).
    let loop_start = t;
    let mut first = SubstepTimes::default();
    for substep in 0..substeps {
        let timed = substep == 0 && ctx.profile;
        let lap = |t: &mut Instant| if timed { lap(t) } else { 0.0 };
        let flip = substep % 2 == 1;
        integrate_velocity_terms(&terms, &mut bodies.states, team);
        first.integrate += lap(&mut t);
        if ctx.warm_starting {
            for &i in &active {
                batches[i].warm_start_on(ctx, &mut bodies.states, team);
            }
        }
        first.warm_start += lap(&mut t);
        for _ in 0..solve_iterations {
            for &i in &active {
                batches[i].solve_on(ctx, &mut bodies.states, true, flip, team);
            }
            for &i in &active {
                batches[i].solve_late_on(ctx, &mut bodies.states, true, team);
            }
        }
        first.solve += lap(&mut t);
        integrate_positions_on(ctx, &terms, &mut bodies.states, team);
        first.integrate += lap(&mut t);
        for _ in 0..relax_iterations {
            for &i in &active {
                batches[i].solve_on(ctx, &mut bodies.states, false, !flip, team);
            }
            for &i in &active {
                batches[i].solve_late_on(ctx, &mut bodies.states, false, team);
            }
        }
        first.relax += lap(&mut t);
    }
    if ctx.profile {
        t = Instant::now();
        first.spread_over(
            t.duration_since(loop_start).as_secs_f64(),
            &mut report.profile,
        );
    }
    if ctx.restitution {
        for &i in &active {
            batches[i].apply_restitution_on(ctx, &mut bodies.states, team);
        }
        report.profile.restitution += clock(&mut t);
    }
    // The batches keep their impulses (joints and lanes only, no body) on
    // the leader while the team finalizes the bodies (rain at two
    // threads: the lanes' store was serial while the other thread waited).
    let store = || {
        for &i in &active {
            batches[i].store_impulses();
        }
    };
    finalize_bodies(bodies, &terms, ctx.fast_bodies, &mut report, team, store);
    report.profile.finalize += clock(&mut t);
    report
}
