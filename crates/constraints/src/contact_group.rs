//! Coupled contacts of a light cluster: every normal row of the bodies
//! that sit under (or between) a much heavier one, solved as one block.
//!
//! # Why
//!
//! A soft contact row is a spring `ω² m_eff` built on the row's effective
//! mass. A light box under a heavy one carries the heavy box's weight `W`
//! on springs built on the *light* box's mass, so both of its contacts give
//! by `W / (ω² m_light)`: at 1000:1 the heavy box sinks 31 cm into the
//! light one and the pair tilts. Stiffer rows (springs built on the heavy
//! box's mass) would hold it, but then the light box sits between stiff
//! rows that one Gauss–Seidel pass per substep couples explicitly, and it
//! rings (`docs/stability.md`: contact mass-ratio caps above 2.5). Solving
//! all of the light box's rows *at once* makes that coupling implicit, and
//! an implicit (exact) solve of soft rows is stable at any stiffness.
//!
//! # Who is light
//!
//! Moving bodies joined by contacts of comparable masses (neither side
//! [`LIGHT_RATIO`] times heavier than the other) form clusters (union–find
//! over the step's contacts). A cluster is light when some moving body
//! outside it, touching one of its members, is at least `LIGHT_RATIO`
//! times heavier than that member (`m_L⁻¹ > LIGHT_RATIO · m_H⁻¹`), and it
//! has at most [`GROUP_CONTACTS`] contacts: a light box under a heavy one,
//! two light boxes stacked under it, a row of light boxes under a heavy
//! plank. The collision pipeline finds the light clusters
//! ([`Clusters::assign`]) and routes their contacts to the contact
//! solver's scalar overflow, each tagged with its cluster; the solver
//! solves each cluster's contacts as one group. A cluster too large for
//! a group (the pyramids of "high mass ratio 1" under their heavy tops)
//! keeps the colours' Gauss–Seidel, and so does a cluster that holds or
//! touches a body the block cannot model: one a motor turns (its torque,
//! possibly unbounded, is outside the block, which then presses the light
//! body through whatever lies behind it) or a portal object's body (its
//! contacts build on the whole object's masses through the portal rows).
//!
//! # The springs of a group
//!
//! Each row of a group is built on the effective mass the row would have
//! if every member of the cluster were as heavy as the heaviest body `H`
//! the cluster touches: with `k_a = m_a⁻¹ + i_a⁻¹ (r_a × n)²`, `k_b`
//! likewise (`0` for a static body), and `k̃` the same with `(m_H⁻¹, i_H⁻¹)`
//! for a side in the cluster and unchanged for a side outside it,
//!
//! ```text
//! ρ_group = (k_a + k_b) / (k̃_a + k̃_b)
//! ```
//!
//! and the row's softness is the contact softness (the static one against a
//! static body) with `Softness::with_mass_ratio(ρ_group)` where that is
//! stiffer than the row's own. The light boxes then deflect under the heavy
//! box as the heavy box would on the ground (1000:1 stack: penetration
//! 0.7 mm instead of 31 cm).
//!
//! # The block
//!
//! The group's normal rows `r = 1 … n` (one per manifold point, `n ≤ 32`)
//! share the cluster's bodies, and may share others. With `J_r` each row's Jacobian,
//! `K = J M⁻¹ Jᵀ`:
//!
//! ```text
//! K_rs = Σ over bodies B in both rows  σ_r σ_s (n_r · n_s) m_B⁻¹ + a_r a_s i_B⁻¹
//! ```
//!
//! (`σ = −1`, `a = −(r_a × n)` on a row's body a; `σ = 1`, `a = r_b × n`
//! on its body b). Each soft row alone is `Δλ_r = −m_r s_m (Ċ_r + b_r) −
//! s_i λ_r`; its fixed point `Ċ_r + b_r + (s_i / s_m) k_rr λ_r = 0` is a
//! compliant row of compliance `γ_r = k_rr s_i / s_m`. All rows at once,
//! with `Ċ` at the current velocities and `λ` the accumulated impulses:
//!
//! ```text
//! K' λ' = K λ − (Ċ + b),   K' = K + diag(k_rr (1 / s_m,r − 1))
//! ```
//!
//! the manifold block of [`crate::contact_row`] over several manifolds (`b`: `s / h`
//! speculative, `max(β s, −v_push)` soft, `max(s / h, 0)` relaxing, `s_m
//! = 1` where rigid). It is solved by Cholesky in `f64` (`K` mixes the light
//! body's and the heavy body's inverse masses, a condition number of about
//! the mass ratio). The clamp `λ' ≥ 0` makes it a small linear
//! complementarity problem, `w = K' λ' − (K λ − (Ċ + b)) ≥ 0`, `λ' ≥ 0`,
//! `λ'_r w_r = 0`, solved exactly by Murty's least-index principal
//! pivoting: hold the rows of an active set at `w = 0` and the others at
//! `λ' = 0`, solve, flip the first row whose sign condition fails (an
//! active `λ' < 0`, an inactive `w < 0`), repeat; for a positive definite
//! `K'` this ends after finitely many rounds. Only dropping rows that come
//! out negative, without taking back rows that then close, is not enough:
//! a 400:1 box dropped from 15 m onto two light boxes lost their ground
//! rows on impact and pushed them through the ground at 8 substeps. A
//! pivot below `10⁻⁹` of its diagonal (redundant rows, in a rigid relax
//! pass), or more than 64 rounds, leaves the group to Gauss–Seidel for
//! that pass.
//!
//! The friction rows go first, one by one (clamped by the normal impulses
//! so far), and the block last: with the friction rows after it, the
//! stiff block and the friction rows pushed the light box back and forth
//! (up to `μ λ` on 1 kg each pass) and the 1000:1 stack blew apart; with
//! the block last it stands (0.05 mm sideways).
//!
//! Each body's velocity change `M⁻¹ Jᵀ Δλ` is summed over the rows in
//! `f64` and added to its (`f32`) state once: a light body takes large
//! opposite impulses whose sum is small.

use janus2d_core::body::BodyState;
use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, from_f64, to_f64};

use janus2d_core::union_find::{find, union};

use crate::contact::ContactConstraint;
use crate::contact_row::Delta;
pub use janus2d_core::contact_input::NO_CLUSTER;

/// How much heavier a moving neighbour makes a body light (dimensionless):
/// its contacts are solved as one coupled group.
pub const LIGHT_RATIO: Real = 10.0;

/// Most manifolds in one group (a light cluster with more contacts keeps
/// the colours' Gauss–Seidel). A group of 14 (28 rows) costs about
/// 0.1 ms/step: the dense solve grows as rows³.
pub const GROUP_CONTACTS: usize = 16;

const GROUP_ROWS: usize = 2 * GROUP_CONTACTS;

/// Most pivoting rounds of one group's block (Murty's method ends in
/// finitely many for a positive definite `K'`; more rounds than this leave
/// the group to Gauss–Seidel for the pass).
const MURTY_ROUNDS: usize = 64;

/// Whether a body of inverse mass `inv_mass` is light beside a moving
/// neighbour of inverse mass `neighbour_inv_mass` (1/kg).
#[inline]
#[must_use]
pub fn is_light(inv_mass: Real, neighbour_inv_mass: Real) -> bool {
    neighbour_inv_mass > 0.0 && inv_mass > LIGHT_RATIO * neighbour_inv_mass
}

/// What [`Clusters::assign`] reads of one contact.
#[derive(Clone, Copy, Debug)]
pub struct ContactBodies {
    /// State index of each body.
    pub state: [u32; 2],
    /// Whether the solve moves each body.
    pub moving: [bool; 2],
    /// Inverse mass of each body, 1/kg.
    pub inv_mass: [Real; 2],
}

/// The light clusters of a step's contacts (module docs), with their
/// scratch.
#[derive(Clone, Debug, Default)]
pub struct Clusters {
    parent: Vec<u32>,
    heavier: Vec<bool>,
    count: Vec<u32>,
    blocked: Vec<bool>,
}

impl Clusters {
    /// The light cluster of each side of each of `n` contacts (`read(k)`:
    /// contact `k`'s bodies), into `out[k]`: a cluster id (the state index
    /// of its root) or [`NO_CLUSTER`]. Without a [`light_pair`] among the
    /// contacts there is none: the pipeline then skips this.
    ///
    /// `excluded` lists state indices of bodies a group cannot model: a
    /// body a motor turns (the motor's torque, up to unbounded, is outside
    /// the block, which would then press the light body through whatever is
    /// behind it) and a portal object's bodies (their contacts build on the
    /// whole object's masses through the portal rows). A cluster that has
    /// such a body as a member or touches one keeps Gauss–Seidel.
    pub fn assign(
        &mut self,
        state_count: usize,
        n: usize,
        read: impl Fn(usize) -> ContactBodies,
        excluded: &[u32],
        out: &mut Vec<[u32; 2]>,
    ) {
        out.clear();
        out.resize(n, [NO_CLUSTER; 2]);
        let ratio = |c: &ContactBodies| {
            let [m_a, m_b] = c.inv_mass;
            (is_light(m_a, m_b), is_light(m_b, m_a))
        };
        let moving_pair = |c: &ContactBodies| c.moving == [true, true];
        self.parent.clear();
        self.parent.extend(0..state_count as u32);
        for k in 0..n {
            let c = read(k);
            if moving_pair(&c) && ratio(&c) == (false, false) {
                union(&mut self.parent, c.state[0], c.state[1]);
            }
        }
        self.heavier.clear();
        self.heavier.resize(state_count, false);
        self.count.clear();
        self.count.resize(state_count, 0);
        // Each side's root into `out` for now; the light ones stay.
        for (k, roots) in out.iter_mut().enumerate() {
            let c = read(k);
            for s in 0..2 {
                if c.moving[s] {
                    roots[s] = find(&mut self.parent, c.state[s]);
                }
            }
            match ratio(&c) {
                (true, _) if moving_pair(&c) => self.heavier[roots[0] as usize] = true,
                (_, true) if moving_pair(&c) => self.heavier[roots[1] as usize] = true,
                _ => {}
            }
            match *roots {
                [a, b] if a == b && a != NO_CLUSTER => self.count[a as usize] += 1,
                [a, b] => {
                    for r in [a, b] {
                        if r != NO_CLUSTER {
                            self.count[r as usize] += 1;
                        }
                    }
                }
            }
        }
        // Excluded bodies, and every cluster one of them touches, are not
        // light.
        if !excluded.is_empty() {
            self.blocked.clear();
            self.blocked.resize(state_count, false);
            for &i in excluded {
                if (i as usize) < state_count {
                    self.blocked[i as usize] = true;
                }
            }
            for (k, roots) in out.iter().enumerate() {
                let c = read(k);
                let touches = (0..2).any(|s| c.moving[s] && self.blocked[c.state[s] as usize]);
                if touches {
                    for &r in roots {
                        if r != NO_CLUSTER {
                            self.heavier[r as usize] = false;
                        }
                    }
                }
            }
        }
        for roots in out.iter_mut() {
            for r in roots.iter_mut() {
                if *r != NO_CLUSTER
                    && !(self.heavier[*r as usize]
                        && self.count[*r as usize] as usize <= GROUP_CONTACTS)
                {
                    *r = NO_CLUSTER;
                }
            }
        }
    }
}

/// Whether a contact's two bodies (`moving`, inverse masses in 1/kg) are
/// both moved by the solve and one is light beside the other.
#[inline]
#[must_use]
pub fn light_pair(moving: [bool; 2], inv_mass: [Real; 2]) -> bool {
    let [m_a, m_b] = inv_mass;
    moving == [true, true] && (is_light(m_a, m_b) || is_light(m_b, m_a))
}

/// One light cluster's contacts (indices into the overflow).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ContactGroup {
    /// The cluster id.
    cluster: u32,
    /// `[m_H⁻¹, i_H⁻¹]` of the heaviest moving body the cluster touches.
    heavy: [Real; 2],
    members: [u32; GROUP_CONTACTS],
    len: u32,
}

impl ContactGroup {
    /// Its contacts (indices into the overflow).
    pub(crate) fn members(&self) -> &[u32] {
        &self.members[..self.len as usize]
    }
}

/// Scratch and result of the grouping: which overflow contacts are solved
/// in groups.
#[derive(Clone, Debug, Default)]
pub(crate) struct Groups {
    pub(crate) groups: Vec<ContactGroup>,
    /// Per overflow contact: solved in a group (not on its own).
    pub(crate) grouped: Vec<bool>,
    /// Per cluster id (a state index): its group + 1 (0: none).
    group_of: Vec<u32>,
}

impl Groups {
    /// Forms one group per cluster from the overflow contacts the pipeline
    /// tagged (`clusters[k]`, from [`Clusters::assign`]; those that build
    /// on a portal object's masses, `hooked`, take no part) and stiffens
    /// their rows (module docs).
    pub(crate) fn build(
        &mut self,
        ctx: &StepContext,
        overflow: &mut [ContactConstraint],
        clusters: &[[u32; 2]],
        hooked: &[bool],
        state_count: usize,
    ) {
        self.groups.clear();
        self.grouped.clear();
        self.grouped.resize(overflow.len(), false);
        let ids = |k: usize| {
            if hooked.get(k).copied().unwrap_or(false) {
                [NO_CLUSTER; 2]
            } else {
                clusters.get(k).copied().unwrap_or([NO_CLUSTER; 2])
            }
        };
        if (0..overflow.len()).all(|k| ids(k) == [NO_CLUSTER; 2]) {
            return;
        }
        self.group_of.clear();
        self.group_of.resize(state_count, 0);
        let mut full = false;
        for (k, c) in overflow.iter().enumerate() {
            let pair = ids(k);
            let [m_a, i_a, m_b, i_b] = c.applied_masses();
            for s in 0..2 {
                let id = pair[s];
                if id == NO_CLUSTER || (s == 1 && pair[0] == id) {
                    continue;
                }
                let g = match self.group_of[id as usize] {
                    0 => {
                        self.groups.push(ContactGroup {
                            cluster: id,
                            heavy: [Real::INFINITY, 0.0],
                            members: [0; GROUP_CONTACTS],
                            len: 0,
                        });
                        self.group_of[id as usize] = self.groups.len() as u32;
                        self.groups.len() - 1
                    }
                    i => i as usize - 1,
                };
                let group = &mut self.groups[g];
                if (group.len as usize) < GROUP_CONTACTS {
                    group.members[group.len as usize] = k as u32;
                    group.len += 1;
                } else {
                    full = true;
                    group.len = GROUP_CONTACTS as u32 + 1;
                }
                // The other side, moving, outside the cluster and heavier.
                let (m_s, [m_o, i_o]) = if s == 0 {
                    (m_a, [m_b, i_b])
                } else {
                    (m_b, [m_a, i_a])
                };
                if pair[1 - s] != id && is_light(m_s, m_o) && m_o < group.heavy[0] {
                    group.heavy = [m_o, i_o];
                }
            }
        }
        if full {
            self.groups.retain(|g| g.len as usize <= GROUP_CONTACTS);
        }
        self.groups.retain(|g| g.heavy[0].is_finite());
        for g in &self.groups {
            for &k in g.members() {
                self.grouped[k as usize] = true;
                let pair = ids(k as usize);
                let c = &mut overflow[k as usize];
                let masses = c.applied_masses();
                c.stiffen_for_group(ctx, pair.map(|id| id == g.cluster), masses, g.heavy);
            }
        }
    }
}

/// One group's friction rows one by one, then its normal rows as one
/// block (module docs). The friction rows and each normal row's bias and
/// mass scale are the contact rows' own (`ContactRows::friction_row`,
/// `ContactRows::normal_terms`); only the block is the group's. Returns false where the block is singular: the
/// caller then solves the members one by one (their friction rows again).
pub(crate) fn solve_group<const USE_BIAS: bool>(
    group: &ContactGroup,
    overflow: &mut [ContactConstraint],
    states: &mut [BodyState],
    inv_h: Real,
    push_max: Real,
) -> bool {
    // Friction first, so that the stiff normal rows have the last word.
    for &k in group.members() {
        overflow[k as usize].solve_friction_rows(states);
    }
    // The rows: (member, point).
    let mut rows = [(0usize, 0usize); GROUP_ROWS];
    let mut n = 0;
    for &k in &group.members[..group.len as usize] {
        for i in 0..overflow[k as usize].point_count() {
            rows[n] = (k as usize, i);
            n += 1;
        }
    }
    if n == 0 {
        return true;
    }
    // Each row's two sides: (state, σ n, a, m⁻¹, i⁻¹), in f64.
    let side = |k: usize, i: usize| {
        let c = &overflow[k];
        let [m_a, i_a, m_b, i_b] = c.applied_masses();
        let (nx, ny) = (to_f64(c.rows.n_x), to_f64(c.rows.n_y));
        [
            (
                c.state_a,
                -nx,
                -ny,
                -to_f64(c.rows.ja[i]),
                to_f64(m_a),
                to_f64(i_a),
            ),
            (
                c.state_b,
                nx,
                ny,
                to_f64(c.rows.jb[i]),
                to_f64(m_b),
                to_f64(i_b),
            ),
        ]
    };
    let mut sides = [[(0u32, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64); 2]; GROUP_ROWS];
    for r in 0..n {
        sides[r] = side(rows[r].0, rows[r].1);
    }
    let mut k_mat = [[0.0f64; GROUP_ROWS]; GROUP_ROWS];
    for r in 0..n {
        let sr = sides[r];
        for s in 0..=r {
            let ss = sides[s];
            let mut sum = 0.0;
            for &(br, xr, yr, ar, m, inv_i) in &sr {
                for &(bs, xs, ys, as_, _, _) in &ss {
                    if br == bs && br != 0 {
                        sum += (xr * xs + yr * ys) * m + ar * as_ * inv_i;
                    }
                }
            }
            k_mat[r][s] = sum;
            k_mat[s][r] = sum;
        }
    }
    // Ċ, bias and mass scale of each row; the right-hand side K λ − (Ċ + b).
    let mut rhs = [0.0f64; GROUP_ROWS];
    let mut diag = [0.0f64; GROUP_ROWS];
    let mut old = [0.0f64; GROUP_ROWS];
    for r in 0..n {
        let (k, i) = rows[r];
        let c = &overflow[k];
        let (sa, sb) = (&states[c.state_a as usize], &states[c.state_b as usize]);
        let (nrm, rows) = (c.normal(), &c.rows);
        let c_dot = (sb.v - sa.v).dot(nrm) + (sb.w * rows.jb[i] - sa.w * rows.ja[i]);
        let dpn = (sb.dp - sa.dp).dot(nrm);
        let (da, db) = (Delta::of(sa), Delta::of(sb));
        let (bias, ms, _) = rows.normal_terms::<USE_BIAS>(i, dpn, &da, &db, inv_h, push_max);
        old[r] = to_f64(rows.impulse[i]);
        rhs[r] = -(to_f64(c_dot) + to_f64(bias));
        diag[r] = k_mat[r][r] / to_f64(ms);
    }
    for r in 0..n {
        for s in 0..n {
            rhs[r] += k_mat[r][s] * old[s];
        }
    }
    // The complementarity problem `w = K' λ' − rhs`, `λ' ≥ 0`, `w ≥ 0`,
    // `λ'_r w_r = 0` by Murty's least-index principal pivoting: solve with
    // the rows of the active set held at `w = 0` (the others at `λ' = 0`),
    // flip the first row that breaks its sign condition, repeat.
    let mut active = [false; GROUP_ROWS];
    active[..n].fill(true);
    let mut x = [0.0f64; GROUP_ROWS];
    let scale = rhs[..n].iter().fold(0.0f64, |m, r| m.max(r.abs()));
    let mut solved = false;
    for _ in 0..MURTY_ROUNDS {
        if !cholesky_solve(&k_mat, &diag, &rhs, &active, n, &mut x) {
            return false;
        }
        let residual = |r: usize| {
            let mut w = diag[r] * x[r] - rhs[r];
            for s in 0..n {
                if s != r {
                    w += k_mat[r][s] * x[s];
                }
            }
            w
        };
        let broken = (0..n).find(|&r| {
            if active[r] {
                x[r] < 0.0
            } else {
                residual(r) < -1e-9 * scale
            }
        });
        match broken {
            Some(r) => active[r] = !active[r],
            None => {
                solved = true;
                break;
            }
        }
    }
    if !solved {
        return false;
    }
    // Apply Δλ = λ' − λ, each body's change summed in f64 first: a light
    // body between heavy ones takes large opposite impulses whose sum is
    // small, and adding them one by one to its f32 velocity leaves their
    // rounding (a 1e6:1 box dropped 2 m on a light box threw it 3.8 km
    // with the increments added one by one, 2 cm with the sums).
    let mut changed = [(0u32, [0.0f64; 3]); 2 * GROUP_ROWS];
    let mut bodies = 0;
    for r in 0..n {
        let (k, i) = rows[r];
        let c = &mut overflow[k];
        let new = if active[r] {
            from_f64(x[r].max(0.0))
        } else {
            0.0
        };
        let rows = &mut c.rows;
        let d = to_f64(new) - to_f64(rows.impulse[i]);
        let d_real = new - rows.impulse[i];
        rows.impulse[i] = new;
        if d_real > rows.max_normal_impulse[i] {
            rows.max_normal_impulse[i] = d_real;
        }
        for (state, x, y, ang, m, inv_i) in sides[r] {
            if state == 0 {
                continue;
            }
            let slot = match changed[..bodies].iter().position(|b| b.0 == state) {
                Some(j) => j,
                None => {
                    changed[bodies].0 = state;
                    bodies += 1;
                    bodies - 1
                }
            };
            let dv = &mut changed[slot].1;
            dv[0] += m * x * d;
            dv[1] += m * y * d;
            dv[2] += inv_i * ang * d;
        }
    }
    for &(state, [dx, dy, dw]) in &changed[..bodies] {
        let st = &mut states[state as usize];
        st.v.x = from_f64(to_f64(st.v.x) + dx);
        st.v.y = from_f64(to_f64(st.v.y) + dy);
        st.w = from_f64(to_f64(st.w) + dw);
    }
    true
}

/// Solves `A x = rhs` over the active rows (`A = K` with the diagonal
/// `diag`), inactive rows zero, by Cholesky. False where a pivot falls
/// below `10⁻⁹` of its diagonal.
fn cholesky_solve(
    k: &[[f64; GROUP_ROWS]; GROUP_ROWS],
    diag: &[f64; GROUP_ROWS],
    rhs: &[f64; GROUP_ROWS],
    active: &[bool; GROUP_ROWS],
    n: usize,
    x: &mut [f64; GROUP_ROWS],
) -> bool {
    let mut idx = [0usize; GROUP_ROWS];
    let mut m = 0;
    for r in 0..n {
        if active[r] {
            idx[m] = r;
            m += 1;
        }
    }
    let mut l = [[0.0f64; GROUP_ROWS]; GROUP_ROWS];
    for i in 0..m {
        for j in 0..=i {
            let a = if i == j {
                diag[idx[i]]
            } else {
                k[idx[i]][idx[j]]
            };
            let mut sum = a;
            for p in 0..j {
                sum -= l[i][p] * l[j][p];
            }
            if i == j {
                // Also false for a NaN pivot.
                if sum.is_nan() || sum <= 1e-9 * a {
                    return false;
                }
                l[i][i] = sum.sqrt();
            } else {
                l[i][j] = sum / l[j][j];
            }
        }
    }
    let mut y = [0.0f64; GROUP_ROWS];
    for i in 0..m {
        let mut sum = rhs[idx[i]];
        for p in 0..i {
            sum -= l[i][p] * y[p];
        }
        y[i] = sum / l[i][i];
    }
    for i in (0..m).rev() {
        let mut sum = y[i];
        for p in i + 1..m {
            sum -= l[p][i] * y[p];
        }
        y[i] = sum / l[i][i];
    }
    x[..n].fill(0.0);
    for i in 0..m {
        x[idx[i]] = y[i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::ContactPointInput;
    use janus2d_core::body::{BodyDef, BodySet};
    use janus2d_core::constraint::Constraint;
    use janus2d_core::math::Vec2;
    use janus2d_core::solver::SolverSettings;

    /// A 1 kg box squeezed between two 1000 kg boxes closing at 2 m/s, in
    /// free space: one rigid pass of the group stops every point (Gauss–
    /// Seidel would need thousands of passes at this ratio) and keeps the
    /// momentum.
    #[test]
    fn one_pass_stops_a_light_box_between_heavy_ones() {
        let mut set = BodySet::new();
        let heavy = |y: Real, v: Real| {
            BodyDef::dynamic(Vec2::new(0.1, y))
                .with_mass(1000.0, 1000.0 / 6.0)
                .with_velocity(Vec2::new(0.0, v))
        };
        let below = set.create(&heavy(-1.0, 1.0)).unwrap();
        let light = set
            .create(&BodyDef::dynamic(Vec2::ZERO).with_mass(1.0, 1.0 / 6.0))
            .unwrap();
        let above = set.create(&heavy(1.0, -1.0)).unwrap();
        let ctx = SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO);
        // Points at x = −0.4 and 0.5 (world), on the faces y = ∓0.5.
        let points = |dx_a: Real, dx_b: Real| {
            [-0.4, 0.5].map(|x| ContactPointInput {
                anchor_a: Vec2::new(x - dx_a, 0.5),
                anchor_b: Vec2::new(x - dx_b, -0.5),
                separation: 0.0,
                normal_impulse: 0.0,
                tangent_impulse: 0.0,
            })
        };
        let mut overflow = vec![
            ContactConstraint::new(below, light, Vec2::Y, &points(0.1, 0.0), 0.6, 0.0, 0),
            ContactConstraint::new(light, above, Vec2::Y, &points(0.0, 0.1), 0.6, 0.0, 1),
        ];
        for c in &mut overflow {
            c.prepare(&ctx, &set);
        }
        let mut groups = Groups::default();
        let state_count = set.states.len();
        let l = set.state_index(light).unwrap();
        let clusters = [[NO_CLUSTER, l], [l, NO_CLUSTER]];
        groups.build(&ctx, &mut overflow, &clusters, &[false; 2], state_count);
        assert_eq!(groups.groups.len(), 1, "one light cluster");
        assert_eq!(groups.groups[0].members(), &[0, 1]);
        let sims = &set.sims;
        let momentum = |states: &[BodyState]| {
            states[1..]
                .iter()
                .zip(&sims[1..])
                .fold(Vec2::ZERO, |p, (s, sim)| p + s.v / sim.inv_mass)
        };
        let mut states = set.states.clone();
        let p0 = momentum(&states);
        let g = groups.groups[0];
        assert!(solve_group::<false>(
            &g,
            &mut overflow,
            &mut states,
            ctx.inv_h,
            3.0
        ));
        for c in &overflow {
            let (sa, sb) = (&states[c.state_a as usize], &states[c.state_b as usize]);
            for i in 0..2 {
                let r = &c.rows;
                let c_dot = (sb.v - sa.v).dot(c.normal()) + (sb.w * r.jb[i] - sa.w * r.ja[i]);
                assert!(c_dot.abs() < 1e-4, "point {i} still closes at {c_dot} m/s");
                assert!(r.impulse[i] > 0.0);
            }
        }
        assert!((momentum(&states) - p0).length() < 1e-2, "momentum");
    }

    /// Two light boxes stacked under a heavy one on the ground form one
    /// cluster; boxes of equal mass with nothing heavier form none; nor
    /// does a cluster that touches an excluded body.
    #[test]
    fn clusters_of_light_bodies_under_a_heavy_one() {
        let body = |state: [u32; 2], inv_mass: [Real; 2]| ContactBodies {
            state,
            moving: state.map(|s| s != 0),
            inv_mass,
        };
        // States: 1, 2 light (1 kg), 3 heavy (1000 kg); 0 the ground.
        let stack = [
            body([0, 1], [0.0, 1.0]),
            body([1, 2], [1.0, 1.0]),
            body([2, 3], [1.0, 0.001]),
        ];
        let mut clusters = Clusters::default();
        let mut out = Vec::new();
        clusters.assign(4, stack.len(), |k| stack[k], &[], &mut out);
        assert_eq!(out, vec![[NO_CLUSTER, 1], [1, 1], [1, NO_CLUSTER]]);
        // The heavy box turned by a motor (excluded): no cluster.
        clusters.assign(4, stack.len(), |k| stack[k], &[3], &mut out);
        assert_eq!(out, vec![[NO_CLUSTER; 2]; 3]);
        // A member excluded (a portal object's body): none either.
        clusters.assign(4, stack.len(), |k| stack[k], &[1], &mut out);
        assert_eq!(out, vec![[NO_CLUSTER; 2]; 3]);
        let equal = [body([0, 1], [0.0, 1.0]), body([1, 2], [1.0, 1.0])];
        clusters.assign(3, equal.len(), |k| equal[k], &[], &mut out);
        assert_eq!(out, vec![[NO_CLUSTER; 2]; 2]);
    }
}
