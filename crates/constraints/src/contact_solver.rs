//! The contact solve in colours and lanes: the stages of
//! [`ContactConstraint`] run [`LANES`] contacts at a time.
//!
//! ```text
//! prepare    scalar, one ContactConstraint at a time (anchors, K, softness),
//!            then the object-mass hook, then colour and pack:
//!
//!   colour   (while the pipeline builds the constraints) greedy: the
//!            first colour in which neither dynamic body already appears
//!            (static and kinematic bodies take no colour: the solve never
//!            changes their state); constraints are built colour by colour
//!   pack     each colour's consecutive constraints in chunks of LANES,
//!            structure of arrays
//!
//!            colour 0: [c0 c3 c7 … ] [c12 … pad]     chunk = LANES lanes
//!            colour 1: [c1 c4 … pad]
//!            …
//!            overflow: c9 c40 …   (a body in every colour: solved scalar)
//!
//! warm start, solve (bias), relax (no bias)
//!            colour by colour (reversed on alternate sweeps), chunk by
//!            chunk: gather the lanes' body states, the row arithmetic of
//!            ContactConstraint::solve_rows on lanes, scatter the
//!            velocities; then the overflow contacts, scalar
//! restitution, store
//!            the lanes' impulses go back to their ContactConstraints, which
//!            do the rest scalar
//! ```
//!
//! Within a colour no dynamic body appears twice, so the lanes of a chunk
//! and the chunks of a colour are independent: the order inside a colour
//! does not change the result. A padding lane reads and writes the static
//! identity state 0 with zero masses and Jacobians, which leaves it as it
//! was; so does a lane on a static or kinematic body (its inverse masses are
//! zero, the velocity it writes back is the one it read).
//!
//! The lane type is `wide::f32x8` (8 lanes) with `f32` and `wide::f64x4`
//! (4 lanes) with the `f64` feature: SIMD without `unsafe`.

use janus2d_core::body::{BodyHandle, BodySet, BodyState};
use janus2d_core::constraint::{Constraint, ConstraintBatch, StepContext};
use janus2d_core::math::{Real, Vec2};
use wide::CmpGt;

use crate::contact::{ContactConstraint, MAX_MANIFOLD_POINTS, ROWS};

/// Lanes of the SIMD type.
#[cfg(not(feature = "f64"))]
pub const LANES: usize = 8;
/// Lanes of the SIMD type.
#[cfg(feature = "f64")]
pub const LANES: usize = 4;

#[cfg(not(feature = "f64"))]
type W = wide::f32x8;
#[cfg(feature = "f64")]
type W = wide::f64x4;

pub use janus2d_core::graph::COLOURS;
use janus2d_core::graph::ColourGraph;

/// A dynamic body that stands for a whole object (a copy crossing a
/// portal): its contacts build their effective masses on the object's
/// inverse mass and inertia, while their impulses still act on the copy
/// (see the portal stage's contact-modification hook).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectMass {
    /// The copy.
    pub body: BodyHandle,
    /// Inverse mass of the whole object as seen from this copy, 1/kg.
    pub inv_mass: Real,
    /// Inverse rotational inertia of the whole object, 1/(kg·m²).
    pub inv_inertia: Real,
}

/// The lanes' body states, gathered from the AoS states.
struct WideBody {
    v_x: W,
    v_y: W,
    w: W,
    dp_x: W,
    dp_y: W,
    q_c: W,
    q_s: W,
}

/// [`LANES`] contacts in structure-of-arrays form: what the warm start and
/// the velocity iterations read and write. Names follow
/// [`ContactConstraint`]: rows 0, 1 are the normal rows, 2, 3 the friction
/// rows.
#[derive(Clone, Debug)]
struct WideContact {
    /// State index of body a per lane (0: static identity or padding).
    state_a: [u32; LANES],
    /// State index of body b per lane.
    state_b: [u32; LANES],
    /// Number of lanes in use (the rest are padding).
    len: usize,
    /// Inverse masses the impulses act with, 1/kg.
    inv_mass_a: W,
    inv_mass_b: W,
    /// Inverse inertias the impulses act with, 1/(kg·m²).
    inv_inertia_a: W,
    inv_inertia_b: W,
    /// Unit normal from a to b.
    n_x: W,
    n_y: W,
    /// Angular Jacobian parts `r_a × n`, `r_a × t` per row, m.
    ja: [W; ROWS],
    /// Angular Jacobian parts `r_b × n`, `r_b × t` per row, m.
    jb: [W; ROWS],
    /// Rigid effective mass per row, kg.
    mass: [W; ROWS],
    /// Soft effective mass per normal row, kg.
    soft_mass: [W; MAX_MANIFOLD_POINTS],
    /// Soft impulse scale per normal row.
    impulse_scale: [W; MAX_MANIFOLD_POINTS],
    /// Separation at zero deltas, m.
    base_separation: [W; MAX_MANIFOLD_POINTS],
    /// Friction coefficient.
    friction: W,
    /// Soft bias rate, 1/s.
    bias_rate: W,
    /// Accumulated impulse per row, N·s.
    impulse: [W; ROWS],
    /// Largest normal impulse increment (restitution gate), N·s.
    max_normal_impulse: [W; MAX_MANIFOLD_POINTS],
}

/// A step's contact constraints, colour by colour, and their lane-packed
/// form: the contact batch's own data.
///
/// The pipeline builds the constraints in two passes over its contacts:
/// [`ContactSolver::assign`] gives each its colour (or the overflow), then
/// [`ContactSolver::push`] appends it to that colour's list. Both passes
/// read the contacts in order and each colour's list is written in order,
/// so neither pass jumps around memory.
#[derive(Clone, Debug, Default)]
pub struct ContactSolver {
    /// Constraints per colour; the last list is the overflow.
    colours: Vec<Vec<ContactConstraint>>,
    /// Chunks, colour by colour.
    chunks: Vec<WideContact>,
    /// `colour_start[c]..colour_start[c + 1]`: the chunks of colour `c`.
    colour_start: Vec<usize>,
    /// The colouring of this step.
    graph: ColourGraph,
    /// The lanes' impulses were written back to the constraints.
    unpacked: bool,
}

/// The slot of the overflow list in [`ContactSolver`]'s colours.
pub const OVERFLOW: u8 = COLOURS as u8;

impl ContactSolver {
    /// An empty solver.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of colours (the overflow not counted).
    #[must_use]
    pub fn colour_count(&self) -> usize {
        COLOURS
    }

    /// Number of constraints in colour `colour` ([`OVERFLOW`] for the
    /// overflow, solved scalar).
    #[must_use]
    pub fn count_in(&self, colour: u8) -> usize {
        self.colours.get(colour as usize).map_or(0, Vec::len)
    }

    /// Number of constraints.
    #[must_use]
    pub fn len(&self) -> usize {
        self.colours.iter().map(Vec::len).sum()
    }

    /// True when there is no constraint.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Every constraint, colour by colour, overflow last.
    pub fn constraints(&self) -> impl Iterator<Item = &ContactConstraint> {
        self.colours.iter().flatten()
    }

    /// Drops every constraint and starts a step's colouring for
    /// `state_count` body states.
    pub fn begin(&mut self, state_count: usize) {
        self.graph.reset(state_count);
        self.colours.resize_with(COLOURS + 1, Vec::new);
        for list in &mut self.colours {
            list.clear();
        }
        self.chunks.clear();
        self.colour_start.clear();
    }

    /// The colour of a constraint whose bodies have the state indices `a`
    /// and `b` (`None` for a body the solve does not move: static,
    /// kinematic or asleep), marking both bodies in it; [`OVERFLOW`] when
    /// none is free.
    pub fn assign(&mut self, a: Option<u32>, b: Option<u32>) -> u8 {
        self.graph.assign(a, b).map_or(OVERFLOW, |c| c as u8)
    }

    /// Appends a constraint to the colour [`ContactSolver::assign`] gave it.
    pub fn push(&mut self, colour: u8, constraint: ContactConstraint) {
        let slot = (colour as usize).min(COLOURS);
        if self.colours.len() <= slot {
            self.colours.resize_with(COLOURS + 1, Vec::new);
        }
        self.colours[slot].push(constraint);
    }

    /// Packs each colour's prepared constraints into chunks.
    fn pack(&mut self) {
        self.chunks.clear();
        self.colour_start.clear();
        self.colour_start.push(0);
        let colours = self.colours.len().min(COLOURS);
        for list in &self.colours[..colours] {
            for start in (0..list.len()).step_by(LANES) {
                let end = (start + LANES).min(list.len());
                self.chunks.push(WideContact::empty());
                let chunk = self.chunks.last_mut().expect("just pushed");
                chunk.fill(list, start, end);
            }
            self.colour_start.push(self.chunks.len());
        }
        self.unpacked = false;
    }

    /// Writes the lanes' impulses back to their constraints (once per step).
    fn unpack(&mut self) {
        if self.unpacked {
            return;
        }
        for colour in 0..self.colour_start.len().saturating_sub(1) {
            let list = &mut self.colours[colour];
            let chunks = &self.chunks[self.colour_start[colour]..self.colour_start[colour + 1]];
            for (chunk, part) in chunks.iter().zip(list.chunks_mut(LANES)) {
                chunk.unpack(part);
            }
        }
        self.unpacked = true;
    }

    fn overflow_mut(&mut self) -> &mut [ContactConstraint] {
        self.colours
            .get_mut(COLOURS)
            .map_or(&mut [], Vec::as_mut_slice)
    }

    fn warm_start(&mut self, states: &mut [BodyState]) {
        for chunk in &mut self.chunks {
            chunk.warm_start(states);
        }
        for c in self.overflow_mut() {
            c.apply_warm_start(states);
        }
    }

    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        let (inv_h, push_max) = (ctx.inv_h, ctx.contact_push_max_velocity);
        let colours = self.colour_start.len().saturating_sub(1);
        for k in 0..colours {
            let colour = if reverse { colours - 1 - k } else { k };
            let range = self.colour_start[colour]..self.colour_start[colour + 1];
            for chunk in &mut self.chunks[range] {
                if use_bias {
                    chunk.solve::<true>(states, inv_h, push_max);
                } else {
                    chunk.solve::<false>(states, inv_h, push_max);
                }
            }
        }
        for c in self.overflow_mut() {
            if use_bias {
                c.solve_rows::<true>(states, inv_h, push_max);
            } else {
                c.solve_rows::<false>(states, inv_h, push_max);
            }
        }
    }
}

#[inline(always)]
fn splat(x: Real) -> W {
    W::splat(x)
}

/// `x` clamped to `[lo, hi]` lane by lane.
#[inline(always)]
fn clamp_w(x: W, lo: W, hi: W) -> W {
    x.fast_max(lo).fast_min(hi)
}

#[inline(always)]
fn gather(states: &[BodyState], index: &[u32; LANES]) -> WideBody {
    let mut v_x = [0.0; LANES];
    let mut v_y = [0.0; LANES];
    let mut w = [0.0; LANES];
    let mut dp_x = [0.0; LANES];
    let mut dp_y = [0.0; LANES];
    let mut q_c = [0.0; LANES];
    let mut q_s = [0.0; LANES];
    for k in 0..LANES {
        let s = &states[index[k] as usize];
        v_x[k] = s.v.x;
        v_y[k] = s.v.y;
        w[k] = s.w;
        dp_x[k] = s.dp.x;
        dp_y[k] = s.dp.y;
        q_c[k] = s.dq.c;
        q_s[k] = s.dq.s;
    }
    WideBody {
        v_x: W::from(v_x),
        v_y: W::from(v_y),
        w: W::from(w),
        dp_x: W::from(dp_x),
        dp_y: W::from(dp_y),
        q_c: W::from(q_c),
        q_s: W::from(q_s),
    }
}

/// The lanes' velocities only (the warm start needs no position deltas).
#[inline(always)]
fn gather_velocity(states: &[BodyState], index: &[u32; LANES]) -> (W, W, W) {
    let mut v_x = [0.0; LANES];
    let mut v_y = [0.0; LANES];
    let mut w = [0.0; LANES];
    for k in 0..LANES {
        let s = &states[index[k] as usize];
        v_x[k] = s.v.x;
        v_y[k] = s.v.y;
        w[k] = s.w;
    }
    (W::from(v_x), W::from(v_y), W::from(w))
}

/// Writes the lanes' velocities back. Lanes on the identity state, on a
/// static or on a kinematic body write what they read.
#[inline(always)]
fn scatter(states: &mut [BodyState], index: &[u32; LANES], v_x: W, v_y: W, w: W) {
    let (v_x, v_y, w) = (v_x.to_array(), v_y.to_array(), w.to_array());
    for k in 0..LANES {
        let s = &mut states[index[k] as usize];
        s.v = Vec2::new(v_x[k], v_y[k]);
        s.w = w[k];
    }
}

impl WideContact {
    /// The zero chunk: every lane a padding lane.
    fn empty() -> Self {
        let z = W::splat(0.0);
        WideContact {
            state_a: [0; LANES],
            state_b: [0; LANES],
            len: 0,
            inv_mass_a: z,
            inv_mass_b: z,
            inv_inertia_a: z,
            inv_inertia_b: z,
            n_x: z,
            n_y: z,
            ja: [z; ROWS],
            jb: [z; ROWS],
            mass: [z; ROWS],
            soft_mass: [z; MAX_MANIFOLD_POINTS],
            impulse_scale: [z; MAX_MANIFOLD_POINTS],
            base_separation: [z; MAX_MANIFOLD_POINTS],
            friction: z,
            bias_rate: z,
            impulse: [z; ROWS],
            max_normal_impulse: [z; MAX_MANIFOLD_POINTS],
        }
    }

    /// Loads constraints `start..end` (at most [`LANES`]) into the lanes.
    fn fill(&mut self, constraints: &[ContactConstraint], start: usize, end: usize) {
        self.len = end - start;
        for (k, c) in constraints[start..end].iter().enumerate() {
            self.state_a[k] = c.state_a;
            self.state_b[k] = c.state_b;
            let [m_a, i_a, m_b, i_b] = c.applied_masses;
            self.inv_mass_a.as_array_mut()[k] = m_a;
            self.inv_inertia_a.as_array_mut()[k] = i_a;
            self.inv_mass_b.as_array_mut()[k] = m_b;
            self.inv_inertia_b.as_array_mut()[k] = i_b;
            self.n_x.as_array_mut()[k] = c.normal.x;
            self.n_y.as_array_mut()[k] = c.normal.y;
            for row in 0..ROWS {
                self.ja[row].as_array_mut()[k] = c.ja[row];
                self.jb[row].as_array_mut()[k] = c.jb[row];
                self.mass[row].as_array_mut()[k] = c.mass[row];
                self.impulse[row].as_array_mut()[k] = c.impulse[row];
            }
            for p in 0..MAX_MANIFOLD_POINTS {
                self.soft_mass[p].as_array_mut()[k] = c.soft_mass[p];
                self.impulse_scale[p].as_array_mut()[k] = c.impulse_scale[p];
                self.base_separation[p].as_array_mut()[k] = c.base_separation[p];
                self.max_normal_impulse[p].as_array_mut()[k] = c.max_normal_impulse[p];
            }
            self.friction.as_array_mut()[k] = c.friction;
            self.bias_rate.as_array_mut()[k] = c.bias_rate;
        }
    }

    /// Writes the lanes' impulses back to the constraints this chunk was
    /// filled from (`constraints`, in lane order).
    fn unpack(&self, constraints: &mut [ContactConstraint]) {
        let impulse = self.impulse.map(W::to_array);
        let max_normal = self.max_normal_impulse.map(W::to_array);
        for (k, c) in constraints.iter_mut().take(self.len).enumerate() {
            for row in 0..ROWS {
                c.impulse[row] = impulse[row][k];
            }
            for i in 0..MAX_MANIFOLD_POINTS {
                c.max_normal_impulse[i] = max_normal[i][k];
            }
        }
    }

    /// Applies the kept impulses: `Δv = M⁻¹ Jᵀ λ`.
    #[inline(always)]
    fn warm_start(&mut self, states: &mut [BodyState]) {
        let (n_x, n_y) = (self.n_x, self.n_y);
        let lambda = &self.impulse;
        let (pn, pt) = (lambda[0] + lambda[1], lambda[2] + lambda[3]);
        // p = pn n + pt t with t = (n_y, −n_x).
        let p_x = pn * n_x + pt * n_y;
        let p_y = pn * n_y - pt * n_x;
        let l_a = dot_rows(lambda, &self.ja);
        let l_b = dot_rows(lambda, &self.jb);
        let (v_x, v_y, w) = gather_velocity(states, &self.state_a);
        scatter(
            states,
            &self.state_a,
            v_x - self.inv_mass_a * p_x,
            v_y - self.inv_mass_a * p_y,
            w - self.inv_inertia_a * l_a,
        );
        let (v_x, v_y, w) = gather_velocity(states, &self.state_b);
        scatter(
            states,
            &self.state_b,
            v_x + self.inv_mass_b * p_x,
            v_y + self.inv_mass_b * p_y,
            w + self.inv_inertia_b * l_b,
        );
    }

    /// One velocity iteration on every lane: the arithmetic of
    /// `ContactConstraint::solve_rows`, lane by lane.
    #[inline(always)]
    fn solve<const USE_BIAS: bool>(
        &mut self,
        states: &mut [BodyState],
        inv_h: Real,
        push_max: Real,
    ) {
        let a = gather(states, &self.state_a);
        let b = gather(states, &self.state_b);
        let (n_x, n_y) = (self.n_x, self.n_y);
        let (ja, jb) = (self.ja, self.jb);
        let dpn = (b.dp_x - a.dp_x) * n_x + (b.dp_y - a.dp_y) * n_y;

        // Ċ of every row at the loaded velocities (t = (n_y, −n_x)).
        let dv_x = b.v_x - a.v_x;
        let dv_y = b.v_y - a.v_y;
        let dvn = dv_x * n_x + dv_y * n_y;
        let dvt = dv_x * n_y - dv_y * n_x;
        let c0 = dvn + (b.w * jb[0] - a.w * ja[0]);
        let c1 = dvn + (b.w * jb[1] - a.w * ja[1]);
        let c2 = dvt + (b.w * jb[2] - a.w * ja[2]);
        let c3 = dvt + (b.w * jb[3] - a.w * ja[3]);

        // K_ij = J_j M⁻¹ J_iᵀ for i < j (n · t = 0).
        let (i_a, i_b) = (self.inv_inertia_a, self.inv_inertia_b);
        let m_sum = self.inv_mass_a + self.inv_mass_b;
        let (ka0, ka1, ka2) = (i_a * ja[0], i_a * ja[1], i_a * ja[2]);
        let (kb0, kb1, kb2) = (i_b * jb[0], i_b * jb[1], i_b * jb[2]);
        let k01 = m_sum + (ka0 * ja[1] + kb0 * jb[1]);
        let k02 = ka0 * ja[2] + kb0 * jb[2];
        let k03 = ka0 * ja[3] + kb0 * jb[3];
        let k12 = ka1 * ja[2] + kb1 * jb[2];
        let k13 = ka1 * ja[3] + kb1 * jb[3];
        let k23 = m_sum + (ka2 * ja[3] + kb2 * jb[3]);

        let (inv_h, push_max) = (splat(inv_h), splat(push_max));
        let d0 = self.normal_row::<USE_BIAS>(0, c0, dpn, &a, &b, inv_h, push_max);
        let c1 = c1 + k01 * d0;
        let d1 = self.normal_row::<USE_BIAS>(1, c1, dpn, &a, &b, inv_h, push_max);
        let c2 = (c2 + k02 * d0) + k12 * d1;
        let d2 = self.friction_row(2, c2);
        let c3 = ((c3 + k03 * d0) + k13 * d1) + k23 * d2;
        let d3 = self.friction_row(3, c3);

        let d = [d0, d1, d2, d3];
        let (pn, pt) = (d0 + d1, d2 + d3);
        let p_x = pn * n_x + pt * n_y;
        let p_y = pn * n_y - pt * n_x;
        let l_a = dot_rows(&d, &ja);
        let l_b = dot_rows(&d, &jb);
        scatter(
            states,
            &self.state_a,
            a.v_x - self.inv_mass_a * p_x,
            a.v_y - self.inv_mass_a * p_y,
            a.w - i_a * l_a,
        );
        scatter(
            states,
            &self.state_b,
            b.v_x + self.inv_mass_b * p_x,
            b.v_y + self.inv_mass_b * p_y,
            b.w + i_b * l_b,
        );
    }

    /// The normal row of point `i` on every lane; returns the increment.
    #[inline(always)]
    fn normal_row<const USE_BIAS: bool>(
        &mut self,
        i: usize,
        c_dot: W,
        dpn: W,
        a: &WideBody,
        b: &WideBody,
        inv_h: W,
        push_max: W,
    ) -> W {
        let (ja, jb) = (&self.ja, &self.jb);
        // n · (dq r) = (r × n) sin − (r × t) cos.
        let s = self.base_separation[i]
            + dpn
            + (b.q_s * jb[i] - b.q_c * jb[i + 2])
            + (a.q_c * ja[i + 2] - a.q_s * ja[i]);
        let old = self.impulse[i];
        let rigid = self.mass[i];
        let zero = W::splat(0.0);
        let (mass, offset) = if USE_BIAS {
            let speculative = s.cmp_gt(zero);
            let soft = self.soft_mass[i];
            let bias = (self.bias_rate * s).fast_max(zero - push_max);
            let soft_offset = zero - soft * bias - self.impulse_scale[i] * old;
            let rigid_offset = zero - rigid * (s * inv_h);
            (
                speculative.blend(rigid, soft),
                speculative.blend(rigid_offset, soft_offset),
            )
        } else {
            (rigid, zero - rigid * (s * inv_h).fast_max(zero))
        };
        let d = (offset - mass * c_dot).fast_max(zero - old);
        self.impulse[i] = old + d;
        self.max_normal_impulse[i] = d.fast_max(self.max_normal_impulse[i]);
        d
    }

    /// Friction row `i` (2 or 3) on every lane; returns the increment.
    #[inline(always)]
    fn friction_row(&mut self, i: usize, c_dot: W) -> W {
        let zero = W::splat(0.0);
        let old = self.impulse[i];
        let max_friction = self.friction * self.impulse[i - MAX_MANIFOLD_POINTS];
        let min_friction = zero - max_friction;
        let d = clamp_w(
            zero - self.mass[i] * c_dot,
            min_friction - old,
            max_friction - old,
        );
        self.impulse[i] = clamp_w(old + d, min_friction, max_friction);
        d
    }
}

/// `Σ x_k y_k` over the rows, as `(x₀y₀ + x₁y₁) + (x₂y₂ + x₃y₃)`.
#[inline(always)]
fn dot_rows(x: &[W; ROWS], y: &[W; ROWS]) -> W {
    (x[0] * y[0] + x[1] * y[1]) + (x[2] * y[2] + x[3] * y[3])
}

/// The contact constraints of a step, in their colours, as one batch for
/// the solver.
pub struct ContactBatch<'a> {
    /// The constraints and their packed form.
    pub solver: &'a mut ContactSolver,
    /// The contact-modification hook's data: bodies whose contacts build
    /// their effective masses on a whole object's mass (portal copies).
    pub object_masses: &'a [ObjectMass],
}

impl ConstraintBatch for ContactBatch<'_> {
    fn count(&self) -> usize {
        self.solver.len()
    }

    fn prepare(&mut self, ctx: &StepContext, bodies: &BodySet) {
        let objects = self.object_masses;
        for c in self.solver.colours.iter_mut().flatten() {
            c.prepare(ctx, bodies);
            if objects.is_empty() {
                continue;
            }
            let find = |body| objects.iter().find(|o| o.body == body);
            let (oa, ob) = (find(c.body_a), find(c.body_b));
            if oa.is_some() || ob.is_some() {
                let [m_a, i_a, m_b, i_b] = c.applied_masses;
                let (m_a, i_a) = oa.map_or((m_a, i_a), |o| (o.inv_mass, o.inv_inertia));
                let (m_b, i_b) = ob.map_or((m_b, i_b), |o| (o.inv_mass, o.inv_inertia));
                c.prepare_rows(ctx, bodies, [m_a, i_a, m_b, i_b]);
            }
        }
        self.solver.pack();
    }

    fn warm_start(&mut self, _ctx: &StepContext, states: &mut [BodyState]) {
        self.solver.warm_start(states);
    }

    fn solve(
        &mut self,
        ctx: &StepContext,
        states: &mut [BodyState],
        use_bias: bool,
        reverse: bool,
    ) {
        self.solver.solve(ctx, states, use_bias, reverse);
    }

    fn apply_restitution(&mut self, ctx: &StepContext, states: &mut [BodyState]) {
        self.solver.unpack();
        for c in self.solver.colours.iter_mut().flatten() {
            c.apply_restitution(ctx, states);
        }
    }

    fn store_impulses(&mut self) {
        self.solver.unpack();
    }
}
