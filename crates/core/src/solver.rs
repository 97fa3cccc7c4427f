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
//! identity state, which the solver resets after every step.

use std::time::Instant;

use crate::body::{BodyHandle, BodySet, BodyState, BodyType};
use crate::constraint::{ConstraintBatch, SolverMode, StepContext};
use crate::math::{Real, Vec2, vec_is_finite};
use crate::softness::Softness;

/// Default largest stiffening factor of a contact between two moving
/// bodies (dimensionless, usual 1.3; 1 gives Box2D v3's contacts). See
/// [`SolverSettings::contact_mass_ratio_cap`].
pub const DEFAULT_CONTACT_MASS_RATIO_CAP: Real = 1.3;

/// Default largest stiffening factor of a joint's point rows
/// (dimensionless, usual 1.3; 1 gives Box2D v3's joints). See
/// [`SolverSettings::joint_mass_ratio_cap`].
pub const DEFAULT_JOINT_MASS_RATIO_CAP: Real = 1.3;

/// Default stiffness of the point rows solved directly, Hz (usual 240).
/// See [`SolverSettings::direct_joint_hertz`].
pub const DEFAULT_DIRECT_JOINT_HERTZ: Real = 240.0;

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
    /// Contact stiffness, Hz (usual 30).
    pub contact_hertz: Real,
    /// Contact damping ratio (usual 10).
    pub contact_damping_ratio: Real,
    /// Maximum contact push-out speed, m/s (usual 3).
    pub contact_push_max_velocity: Real,
    /// Joint stiffness, Hz (usual 60).
    pub joint_hertz: Real,
    /// Joint damping ratio (usual 2).
    pub joint_damping_ratio: Real,
    /// Maximum correction speed of a joint solved by Gauss–Seidel, m/s
    /// (usual `Real::MAX`, no cap: 5 m/s raised the 40×40 joint grid's peak
    /// gap from 0.17 to 0.32 m). Joint trees use
    /// `direct_joint_max_correction_speed` instead.
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
    /// 240, the substep rate at 60 Hz × 4). A joint's static stretch under
    /// a load is `F K / ω²` per unit effective mass: 240 Hz holds a 670:1
    /// ball on a chain of light links within ~1 cm where 60 Hz lets it
    /// stretch ~16×; an exact solve is stable at any stiffness.
    pub direct_joint_hertz: Real,
    /// Largest position-correction speed of one directly solved joint, m/s
    /// (usual 5). The exact solve corrects every joint of a chain at once,
    /// so the speeds add up along it: uncapped, a chain stretched by 1 m at
    /// each of 40 joints flings its end at 600 m/s; at 5 m/s it recovers in
    /// 0.52 s peaking at 111 m/s. Iterative joints keep
    /// `joint_max_correction_speed`.
    pub direct_joint_max_correction_speed: Real,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            mode: SolverMode::SoftStep,
            substeps: 4,
            relax_iterations: 1,
            velocity_iterations: 8,
            baumgarte: 0.2,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            contact_push_max_velocity: 3.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            joint_max_correction_speed: Real::MAX,
            restitution_threshold: 1.0,
            warm_starting: true,
            contact_mass_ratio_cap: DEFAULT_CONTACT_MASS_RATIO_CAP,
            joint_mass_ratio_cap: DEFAULT_JOINT_MASS_RATIO_CAP,
            direct_joints: true,
            direct_joint_hertz: DEFAULT_DIRECT_JOINT_HERTZ,
            direct_joint_max_correction_speed: 5.0,
        }
    }
}

/// A solver setting that is out of its range, named by its field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// The field is NaN.
    NonFinite(&'static str),
    /// The field is negative, or an iteration count is 0 (substeps) or
    /// above 1024.
    OutOfRange(&'static str),
}

impl SolverSettings {
    /// Checks every field: no real is NaN or negative, `substeps` is in
    /// `1..=1024`, the iteration counts at most 1024. The error names the
    /// first field that is wrong.
    ///
    /// ```
    /// use janus2d_core::solver::{SettingsError, SolverSettings};
    /// let bad = SolverSettings { contact_hertz: -1.0, ..SolverSettings::default() };
    /// assert_eq!(bad.validate(), Err(SettingsError::OutOfRange("contact_hertz")));
    /// assert!(SolverSettings::default().validate().is_ok());
    /// ```
    pub fn validate(&self) -> Result<(), SettingsError> {
        let reals = [
            (self.baumgarte, "baumgarte"),
            (self.contact_hertz, "contact_hertz"),
            (self.contact_damping_ratio, "contact_damping_ratio"),
            (self.contact_push_max_velocity, "contact_push_max_velocity"),
            (self.joint_hertz, "joint_hertz"),
            (self.joint_damping_ratio, "joint_damping_ratio"),
            (
                self.joint_max_correction_speed,
                "joint_max_correction_speed",
            ),
            (self.restitution_threshold, "restitution_threshold"),
            (self.contact_mass_ratio_cap, "contact_mass_ratio_cap"),
            (self.joint_mass_ratio_cap, "joint_mass_ratio_cap"),
            (self.direct_joint_hertz, "direct_joint_hertz"),
            (
                self.direct_joint_max_correction_speed,
                "direct_joint_max_correction_speed",
            ),
        ];
        for (v, name) in reals {
            if v.is_nan() {
                return Err(SettingsError::NonFinite(name));
            }
            if v < 0.0 {
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

    /// Builds the per-step context.
    pub fn context(&self, dt: Real, gravity: Vec2) -> StepContext {
        let (substeps, h) = match self.mode {
            SolverMode::SoftStep => {
                let n = self.substeps.max(1);
                (n, dt / n as Real)
            }
            SolverMode::PgsBaumgarte => (1, dt),
        };
        let (joint_softness, contact_softness, static_softness) = match self.mode {
            SolverMode::SoftStep => (
                Softness::new(self.joint_hertz, self.joint_damping_ratio, h),
                Softness::new(self.contact_hertz, self.contact_damping_ratio, h),
                Softness::new(2.0 * self.contact_hertz, self.contact_damping_ratio, h),
            ),
            SolverMode::PgsBaumgarte => {
                let s = Softness::baumgarte(self.baumgarte, dt);
                (s, s, s)
            }
        };
        StepContext {
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
            contact_hertz: self.contact_hertz,
            contact_damping_ratio: self.contact_damping_ratio,
            joint_hertz: self.joint_hertz,
            joint_damping_ratio: self.joint_damping_ratio,
            warm_starting: self.warm_starting,
            mode: self.mode,
            restitution: true,
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
        }
    }
}

/// Time spent in each solver stage during the last step, seconds.
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
    /// Stage timings.
    pub profile: SolverProfile,
}

#[inline]
fn lap(t: &mut Instant) -> f64 {
    let now = Instant::now();
    let d = now.duration_since(*t).as_secs_f64();
    *t = now;
    d
}

fn prepare_bodies(bodies: &mut BodySet) {
    let BodySet { sims, states, .. } = bodies;
    for (sim, state) in sims.iter_mut().zip(states.iter_mut()).skip(1) {
        sim.center0 = sim.center;
        sim.rotation0 = sim.transform.q;
        state.dp = Vec2::ZERO;
        state.dq = crate::math::Rot::IDENTITY;
        state.inv_mass = sim.inv_mass;
        state.inv_inertia = sim.inv_inertia;
    }
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
        let max_v = sim.max_linear_speed;
        let v2 = v.length_squared();
        if v2 > max_v * max_v {
            v *= max_v / v2.sqrt();
        }
        let max_w = sim.max_rotation * ctx.inv_h;
        if w * w > max_w * max_w {
            w = w.clamp(-max_w, max_w);
        }
        state.v = v;
        state.w = w;
    }
}

/// The velocity integration of one dynamic body over a substep, with
/// everything that is fixed for the step (forces, gravity, damping, limits)
/// evaluated once: [`integrate_velocities`] on a compact array instead of
/// the bodies' per-step data. Same arithmetic, same results.
#[derive(Clone, Copy, Debug)]
struct VelocityTerms {
    /// Index of the body's state.
    state: u32,
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

/// The [`VelocityTerms`] of every dynamic body, in state order.
fn velocity_terms(ctx: &StepContext, bodies: &BodySet) -> Vec<VelocityTerms> {
    let h = ctx.h;
    let gravity = ctx.gravity;
    let has_gravity = gravity != Vec2::ZERO;
    let mut terms = Vec::with_capacity(bodies.sims.len());
    for (i, sim) in bodies.sims.iter().enumerate().skip(1) {
        if sim.body_type != BodyType::Dynamic {
            continue;
        }
        let mut accel = sim.inv_mass * sim.force;
        if has_gravity {
            accel += sim.gravity_scale * gravity;
        }
        terms.push(VelocityTerms {
            state: i as u32,
            dv: h * accel,
            dw: h * sim.inv_inertia * sim.torque,
            linear_damping: 1.0 / (1.0 + h * sim.linear_damping),
            angular_damping: 1.0 / (1.0 + h * sim.angular_damping),
            max_v: sim.max_linear_speed,
            max_w: sim.max_rotation * ctx.inv_h,
        });
    }
    terms
}

/// [`integrate_velocities`] from precomputed terms.
fn integrate_velocity_terms(terms: &[VelocityTerms], states: &mut [BodyState]) {
    for t in terms {
        let state = &mut states[t.state as usize];
        let mut v = t.linear_damping * (state.v + t.dv);
        let mut w = t.angular_damping * (state.w + t.dw);
        let v2 = v.length_squared();
        if v2 > t.max_v * t.max_v {
            v *= t.max_v / v2.sqrt();
        }
        if w * w > t.max_w * t.max_w {
            w = w.clamp(-t.max_w, t.max_w);
        }
        state.v = v;
        state.w = w;
    }
}

/// Integrates positions of moving bodies over one substep (into the deltas).
pub fn integrate_positions(ctx: &StepContext, bodies: &mut BodySet) {
    let h = ctx.h;
    for state in bodies.states.iter_mut().skip(1) {
        state.dq = state.dq.integrate(h * state.w);
        state.dp += h * state.v;
    }
}

fn finalize_bodies(bodies: &mut BodySet, report: &mut SolveReport) {
    let BodySet { sims, states, .. } = bodies;
    for (sim, state) in sims.iter_mut().zip(states.iter_mut()).skip(1) {
        let ok = vec_is_finite(state.v)
            && state.w.is_finite()
            && vec_is_finite(state.dp)
            && state.dq.is_finite();
        if !ok {
            report.non_finite.push(sim.handle);
            state.v = Vec2::ZERO;
            state.w = 0.0;
            state.dp = Vec2::ZERO;
            state.dq = crate::math::Rot::IDENTITY;
            continue;
        }
        sim.center = sim.center0 + state.dp;
        sim.transform.q = state.dq.mul(sim.rotation0).normalize();
        sim.transform.p = sim.center - sim.transform.q.rotate(sim.local_center);
        sim.force = Vec2::ZERO;
        sim.torque = 0.0;
    }
    states[0] = BodyState::IDENTITY;
}

/// Advances the bodies by one step, solving every batch of constraints.
///
/// `batches` holds one entry per constraint type (each a `Vec<C>`).
pub fn solve_step(
    settings: &SolverSettings,
    ctx: &StepContext,
    bodies: &mut BodySet,
    batches: &mut [&mut dyn ConstraintBatch],
) -> SolveReport {
    let mut report = SolveReport::default();
    let mut t = Instant::now();
    prepare_bodies(bodies);
    let terms = velocity_terms(ctx, bodies);
    for b in batches.iter_mut() {
        b.prepare(ctx, bodies);
    }
    report.profile.prepare += lap(&mut t);

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
    for substep in 0..substeps {
        let flip = substep % 2 == 1;
        integrate_velocity_terms(&terms, &mut bodies.states);
        report.profile.integrate += lap(&mut t);
        if ctx.warm_starting {
            for &i in &active {
                batches[i].warm_start(ctx, &mut bodies.states);
            }
        }
        report.profile.warm_start += lap(&mut t);
        for _ in 0..solve_iterations {
            for &i in &active {
                batches[i].solve(ctx, &mut bodies.states, true, flip);
            }
            for &i in &active {
                batches[i].solve_late(ctx, &mut bodies.states, true);
            }
        }
        report.profile.solve += lap(&mut t);
        integrate_positions(ctx, bodies);
        report.profile.integrate += lap(&mut t);
        for _ in 0..relax_iterations {
            for &i in &active {
                batches[i].solve(ctx, &mut bodies.states, false, !flip);
            }
            for &i in &active {
                batches[i].solve_late(ctx, &mut bodies.states, false);
            }
        }
        report.profile.relax += lap(&mut t);
    }
    if ctx.restitution {
        for &i in &active {
            batches[i].apply_restitution(ctx, &mut bodies.states);
        }
        report.profile.restitution += lap(&mut t);
    }
    for &i in &active {
        batches[i].store_impulses();
    }
    finalize_bodies(bodies, &mut report);
    report.profile.finalize += lap(&mut t);
    report
}
