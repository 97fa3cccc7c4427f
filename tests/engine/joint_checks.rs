//! What the joint kinds' property tests share: the step context they
//! build rows at, the finite-difference step and its tolerance, and the
//! check that every block's `K` is `J M⁻¹ Jᵀ` of its rows.

use janus2d_core::constraint::{ConstraintRows, StepContext};
use janus2d_core::math::{Real, Vec2};
use janus2d_core::solver::SolverSettings;
use janus2d_testbed::support::{EPS, d};
use proptest::prelude::*;
use proptest::test_runner::TestCaseError;

/// The context rows are reported at: default settings, 1/60 s, no gravity.
pub(super) fn ctx() -> StepContext {
    SolverSettings::default().context(1.0 / 60.0, Vec2::ZERO)
}

/// The finite-difference step of the `J = dC/dx` checks.
#[cfg(feature = "f64")]
pub(super) const FD_STEP: Real = 1.0e-5;
/// The finite-difference step of the `J = dC/dx` checks.
#[cfg(not(feature = "f64"))]
pub(super) const FD_STEP: Real = 5.0e-3;

/// `(8 eps / ε + 4 ε²) M`: rounding over the step plus truncation, for a
/// `C` of size `M` (see `tests/portals/portal_properties.rs`).
pub(super) fn fd_tolerance(c_mag: f64) -> f64 {
    let step = d(FD_STEP);
    (8.0 * EPS / step + 4.0 * step * step) * c_mag
}

/// Relative tolerance of the momentum checks.
#[cfg(feature = "f64")]
pub(super) const CONSERVATION_TOL: f64 = 1e-12;
/// Relative tolerance of the momentum checks.
#[cfg(not(feature = "f64"))]
pub(super) const CONSERVATION_TOL: f64 = 1e-5;

/// `Σ inv_m |J_i,lin| |J_j,lin| + inv_i |J_i,ang| |J_j,ang|` over shared
/// bodies: the size of the terms rounding acts on in `(J M⁻¹ Jᵀ)_ij`.
pub(super) fn jmj_scale(rows: &ConstraintRows, i: usize, j: usize) -> f64 {
    let mut scale = 0.0f64;
    for a in &rows.rows[i].jacobian {
        for b in &rows.rows[j].jacobian {
            if a.body == b.body {
                scale += d(a.inv_mass) * d(a.linear.length()) * d(b.linear.length())
                    + d(a.inv_inertia) * d(a.angular.abs()) * d(b.angular.abs());
            }
        }
    }
    scale
}

/// Every block's `K` equals `J M⁻¹ Jᵀ` of its rows within `32 eps` of
/// the terms' size ([`jmj_scale`]), and the blocks cover every row;
/// returns the worst error as a fraction of its bound.
pub(super) fn k_blocks_match(rows: &ConstraintRows) -> Result<f64, TestCaseError> {
    let mut worst = 0.0f64;
    let mut covered = 0;
    for block in &rows.blocks {
        covered += block.len;
        for p in 0..block.len {
            for q in 0..block.len {
                let (i, j) = (block.first_row + p, block.first_row + q);
                let jmj = d(rows.jmj(i, j));
                let bound = 32.0 * EPS * jmj_scale(rows, i, j);
                let err = (d(block.k[p][q]) - jmj).abs();
                prop_assert!(
                    err <= bound,
                    "K[{i}][{j}] = {} vs {jmj} (error {err:.3e} > {bound:.3e})",
                    block.k[p][q]
                );
                if bound > 0.0 {
                    worst = worst.max(err / bound);
                }
            }
        }
    }
    prop_assert_eq!(covered, rows.rows.len());
    Ok(worst)
}
