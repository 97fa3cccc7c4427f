//! Coupled contacts of a light body: every normal row of a body that
//! touches a much heavier one, solved as one block.
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
//! A dynamic body `L` is light when every moving body it touches is at
//! least [`LIGHT_RATIO`] times heavier (`m_L⁻¹ > LIGHT_RATIO · m_O⁻¹` for
//! each, and at least one): it sits between static ground and heavy
//! bodies, so its rows carry their loads straight through. The collision
//! pipeline routes every contact of a light body to the contact solver's
//! scalar overflow ([`is_light`]); the solver forms one group per light
//! body from them (at most [`GROUP_CONTACTS`] manifolds; a body with more
//! is solved one contact at a time in the overflow). A light box inside a
//! pyramid of light boxes is not light in this sense (its neighbours are
//! its equals) and keeps the colours' Gauss–Seidel: routing such a box
//! under the heavy top of "high mass ratio 1" into a group raised that
//! case's sideways move from 0.25 m to 0.54 m and its late penetration
//! from 3.7 to 7.5 cm (both over their bounds), stiffened or not.
//!
//! # The springs of a group
//!
//! Each row of the group (its other body `O` is static or heavy) is built
//! on the effective mass the row would have if `L` were as heavy as its
//! heaviest neighbour `H`: with `k_L = m_L⁻¹ + i_L⁻¹ (r_L × n)²`, `k_O`
//! likewise (`0` for a static body) and `k̃_L = m_H⁻¹ + i_H⁻¹ (r_L × n)²`,
//!
//! ```text
//! ρ_group = (k_L + k_O) / (k̃_L + k_O)
//! ```
//!
//! and the row's softness is the contact softness (the static one against a
//! static body) with `Softness::with_mass_ratio(ρ_group)` where that is
//! stiffer than the row's own. The light box then deflects under the heavy
//! box as the heavy box would on the ground (1000:1 stack: penetration
//! 0.7 mm instead of 31 cm).
//!
//! # The block
//!
//! The group's normal rows `r = 1 … n` (one per manifold point, `n ≤ 8`)
//! share `L`, and may share other bodies. With `J_r` each row's Jacobian,
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
//! the manifold block of `contact.rs` over several manifolds (`b`: `s / h`
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
//! the block last it stands (0.2 mm sideways).

use janus2d_core::body::BodyState;
use janus2d_core::constraint::StepContext;
use janus2d_core::math::{Real, from_f64, to_f64};

use crate::contact::ContactConstraint;

/// How much heavier a moving neighbour makes a body light (dimensionless):
/// its contacts are solved as one coupled group.
pub const LIGHT_RATIO: Real = 10.0;

/// Most manifolds in one group (a light body with more keeps Gauss–Seidel).
pub const GROUP_CONTACTS: usize = 4;

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

/// One light body's contacts (indices into the overflow).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct ContactGroup {
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
    /// Per state: inverse mass and inertia of the heaviest moving neighbour.
    heaviest: Vec<[Real; 2]>,
    /// Per state: inverse mass of the lightest moving neighbour.
    lightest: Vec<Real>,
    /// Per state: its group + 1 (0: none, `u32::MAX`: too many contacts).
    group_of: Vec<u32>,
}

impl Groups {
    /// Forms the groups of the overflow contacts the pipeline marked
    /// `coupled` (less those that build on a portal object's masses,
    /// `hooked`) and stiffens their rows (module docs).
    pub(crate) fn build(
        &mut self,
        ctx: &StepContext,
        overflow: &mut [ContactConstraint],
        coupled: &[bool],
        hooked: &[bool],
        state_count: usize,
    ) {
        self.groups.clear();
        self.grouped.clear();
        self.grouped.resize(overflow.len(), false);
        if overflow.is_empty() {
            return;
        }
        // Only the light bodies' own contacts: every one of a light body's
        // contacts is marked, and each marked contact has its light body
        // on one side, so the light bodies found among them are the
        // pipeline's.
        let free = |c: usize| {
            coupled.get(c).copied().unwrap_or(false) && !hooked.get(c).copied().unwrap_or(false)
        };
        self.heaviest.clear();
        self.heaviest.resize(state_count, [Real::INFINITY, 0.0]);
        self.lightest.clear();
        self.lightest.resize(state_count, 0.0);
        for (k, c) in overflow.iter().enumerate() {
            let (a, b) = (c.state_a as usize, c.state_b as usize);
            if a == 0 || b == 0 || !free(k) {
                continue;
            }
            let [m_a, i_a, m_b, i_b] = c.applied_masses;
            if m_b < self.heaviest[a][0] {
                self.heaviest[a] = [m_b, i_b];
            }
            if m_a < self.heaviest[b][0] {
                self.heaviest[b] = [m_a, i_a];
            }
            self.lightest[a] = self.lightest[a].max(m_b);
            self.lightest[b] = self.lightest[b].max(m_a);
        }
        self.group_of.clear();
        self.group_of.resize(state_count, 0);
        for (k, c) in overflow.iter().enumerate() {
            if !free(k) {
                continue;
            }
            let [m_a, _, m_b, _] = c.applied_masses;
            for (s, m) in [(c.state_a as usize, m_a), (c.state_b as usize, m_b)] {
                if s == 0 || !is_light(m, self.lightest[s]) {
                    continue;
                }
                match self.group_of[s] {
                    u32::MAX => {}
                    0 => {
                        let mut g = ContactGroup::default();
                        g.members[0] = k as u32;
                        g.len = 1;
                        self.groups.push(g);
                        self.group_of[s] = self.groups.len() as u32;
                    }
                    i => {
                        let g = &mut self.groups[i as usize - 1];
                        if (g.len as usize) < GROUP_CONTACTS {
                            g.members[g.len as usize] = k as u32;
                            g.len += 1;
                        } else {
                            g.len = 0;
                            self.group_of[s] = u32::MAX;
                        }
                    }
                }
            }
        }
        // Stiffen the rows of every group that stands (a full one is
        // dropped: its body keeps Gauss–Seidel).
        self.groups.retain(|g| g.len > 0);
        let (heaviest, lightest) = (&self.heaviest, &self.lightest);
        for g in &self.groups {
            for &k in &g.members[..g.len as usize] {
                self.grouped[k as usize] = true;
            }
        }
        // Stiffening per contact and light side (a contact between two
        // light bodies may stand in two groups: the stiffer spring wins).
        for (k, c) in overflow.iter_mut().enumerate() {
            if !self.grouped[k] {
                continue;
            }
            let [m_a, i_a, m_b, i_b] = c.applied_masses;
            let (a, b) = (c.state_a as usize, c.state_b as usize);
            for (light_is_a, s, m_l) in [(true, a, m_a), (false, b, m_b)] {
                if s == 0 || !is_light(m_l, lightest[s]) {
                    continue;
                }
                let [m_h, i_h] = heaviest[s];
                c.stiffen_for_light_side(ctx, light_is_a, [m_a, i_a, m_b, i_b], [m_h, i_h]);
            }
        }
    }
}

/// One group's friction rows one by one, then its normal rows as one
/// block (module docs). Returns false where the block is singular: the
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
        let [m_a, i_a, m_b, i_b] = c.applied_masses;
        let (nx, ny) = (to_f64(c.normal.x), to_f64(c.normal.y));
        [
            (
                c.state_a,
                -nx,
                -ny,
                -to_f64(c.ja[i]),
                to_f64(m_a),
                to_f64(i_a),
            ),
            (c.state_b, nx, ny, to_f64(c.jb[i]), to_f64(m_b), to_f64(i_b)),
        ]
    };
    let mut k_mat = [[0.0f64; GROUP_ROWS]; GROUP_ROWS];
    for r in 0..n {
        let sr = side(rows[r].0, rows[r].1);
        for s in 0..=r {
            let ss = side(rows[s].0, rows[s].1);
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
        let nrm = c.normal;
        let c_dot = (sb.v - sa.v).dot(nrm) + (sb.w * c.jb[i] - sa.w * c.ja[i]);
        let dpn = (sb.dp - sa.dp).dot(nrm);
        let (bias, ms, _) = c.normal_terms::<USE_BIAS>(i, dpn, sa.dq, sb.dq, inv_h, push_max);
        old[r] = to_f64(c.impulse[i]);
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
    // Apply Δλ = λ' − λ.
    for r in 0..n {
        let (k, i) = rows[r];
        let c = &mut overflow[k];
        let new = if active[r] {
            from_f64(x[r].max(0.0))
        } else {
            0.0
        };
        let d = new - c.impulse[i];
        c.impulse[i] = new;
        if d > c.max_normal_impulse[i] {
            c.max_normal_impulse[i] = d;
        }
        let [m_a, i_a, m_b, i_b] = c.applied_masses;
        let p = d * c.normal;
        let (ia, ib) = (c.state_a as usize, c.state_b as usize);
        states[ia].v -= m_a * p;
        states[ia].w -= i_a * d * c.ja[i];
        states[ib].v += m_b * p;
        states[ib].w += i_b * d * c.jb[i];
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
        groups.build(&ctx, &mut overflow, &[true; 2], &[false; 2], state_count);
        assert_eq!(groups.groups.len(), 1, "one light body");
        assert_eq!(groups.groups[0].members(), &[0, 1]);
        let momentum = |states: &[BodyState]| {
            states[1..]
                .iter()
                .fold(Vec2::ZERO, |p, s| p + s.v / s.inv_mass)
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
                let c_dot = (sb.v - sa.v).dot(c.normal) + (sb.w * c.jb[i] - sa.w * c.ja[i]);
                assert!(c_dot.abs() < 1e-4, "point {i} still closes at {c_dot} m/s");
                assert!(c.impulse[i] > 0.0);
            }
        }
        assert!((momentum(&states) - p0).length() < 1e-2, "momentum");
    }
}
