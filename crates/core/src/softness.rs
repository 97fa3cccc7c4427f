//! Soft constraints: one [`Softness`] type for every soft row.
//!
//! A soft constraint behaves like a damped spring of stiffness `ω² m` and
//! damping `2 ζ ω m` (with `ω = 2π f`, `f` in hertz, `ζ` the damping ratio)
//! integrated implicitly over one substep of length `h`. Solving the
//! implicit spring for the row impulse gives (Box2D v3's "soft step", after
//! Catto, *Solver2D*, 2024):
//!
//! ```text
//! λ = -m_eff · mass_scale · (ċ + bias_rate · c) - impulse_scale · λ_acc
//!
//! a1 = 2ζ + hω        a2 = hω · a1        a3 = 1 / (1 + a2)
//! bias_rate     = ω / a1              [1/s]
//! mass_scale    = a2 · a3             [-]
//! impulse_scale = a3                  [-]
//! ```
//!
//! | case                        | bias_rate | mass_scale | impulse_scale |
//! |-----------------------------|-----------|------------|---------------|
//! | rigid, no position feedback | 0         | 1          | 0             |
//! | soft (hertz, ζ, h)          | ω / a1    | a2 a3      | a3            |
//! | Baumgarte (β, dt)           | β / dt    | 1          | 0             |
//!
//! The same three numbers serve contacts, joints, joint springs and the
//! portal constraint, and express the plain PGS-with-Baumgarte baseline.
//!
//! **Mass-ratio-aware stiffness.** The spring above has stiffness
//! `k = ω² m_eff`: a light body pressed by a heavy one (or a light link
//! pulling a heavy load) deflects by `F / (ω² m_eff)`, with `m_eff` set by
//! the light body. Building the spring on a larger mass `ρ m_eff` (`ρ ≥ 1`,
//! stiffness `ρ ω² m_eff`, damping `2 ζ ω ρ m_eff`) and solving the implicit
//! step again with the row's true effective mass gives
//!
//! ```text
//! bias_rate'     = ω / a1                 (unchanged)
//! mass_scale'    = ρ a2 / (1 + ρ a2)
//! impulse_scale' = 1 / (1 + ρ a2)         (a2 = mass_scale / impulse_scale)
//! ```
//!
//! so the static deflection shrinks by `ρ`. One Gauss–Seidel iteration per
//! substep only stays stable up to a modest `ρ` (the solver caps it, see
//! `SolverSettings`), because neighbouring rows share bodies and their
//! combined stiffness grows faster than the per-row implicit solve damps.

use crate::math::{Real, TAU};

/// Coefficients of a soft constraint row for one substep length.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Softness {
    /// Position error feedback rate, 1/s.
    pub bias_rate: Real,
    /// Scale applied to the effective mass (dimensionless, in (0, 1]).
    pub mass_scale: Real,
    /// Fraction of the accumulated impulse removed each iteration (dimensionless).
    pub impulse_scale: Real,
}

impl Default for Softness {
    fn default() -> Self {
        Self::RIGID
    }
}

impl Softness {
    /// A rigid row with no position feedback.
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// The soft coefficients of a spring of `hertz` (Hz) and `damping_ratio`
    /// (dimensionless) over a step of `h` seconds. `hertz == 0` gives
    /// [`Softness::RIGID`].
    ///
    /// ```
    /// use janus2d_core::softness::Softness;
    /// let s = Softness::new(30.0, 10.0, 1.0 / 240.0);
    /// assert!(s.mass_scale > 0.0 && s.mass_scale < 1.0);
    /// assert!((s.mass_scale + s.impulse_scale - 1.0).abs() < 1e-6);
    /// ```
    pub fn new(hertz: Real, damping_ratio: Real, h: Real) -> Softness {
        if hertz <= 0.0 || h <= 0.0 {
            return Softness::RIGID;
        }
        let omega = TAU * hertz;
        let a1 = 2.0 * damping_ratio + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Softness {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }

    /// The same spring built on `rho` times the row's effective mass
    /// (dimensionless, clamped to `≥ 1`): `rho` times stiffer, with the same
    /// bias rate (see the module docs). Rigid rows are returned unchanged.
    ///
    /// ```
    /// use janus2d_core::softness::Softness;
    /// let s = Softness::new(30.0, 10.0, 1.0 / 240.0);
    /// let t = s.with_mass_ratio(2.0);
    /// assert_eq!(t.bias_rate, s.bias_rate);
    /// assert!(t.mass_scale > s.mass_scale && t.impulse_scale < s.impulse_scale);
    /// assert_eq!(s.with_mass_ratio(1.0), s);
    /// ```
    pub fn with_mass_ratio(self, rho: Real) -> Softness {
        if self.impulse_scale <= 0.0 || rho.is_nan() || rho <= 1.0 {
            return self;
        }
        let a2 = self.mass_scale / self.impulse_scale;
        let rho_a2 = rho * a2;
        // mass_scale + impulse_scale = 1 (also for an infinite ρ: rigid).
        let impulse_scale = 1.0 / (1.0 + rho_a2);
        Softness {
            bias_rate: self.bias_rate,
            mass_scale: 1.0 - impulse_scale,
            impulse_scale,
        }
    }

    /// Rigid rows with Baumgarte position feedback: `bias = β c / dt`.
    pub fn baumgarte(beta: Real, dt: Real) -> Softness {
        Softness {
            bias_rate: if dt > 0.0 { beta / dt } else { 0.0 },
            mass_scale: 1.0,
            impulse_scale: 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_hertz_is_rigid() {
        assert_eq!(Softness::new(0.0, 1.0, 0.01), Softness::RIGID);
    }

    #[test]
    fn mass_ratio_scales_the_static_stiffness() {
        // Static deflection is c = λ s_i / (m s_m β h): scaling s_m / s_i by
        // ρ makes the row ρ times stiffer at rest.
        let s = Softness::new(60.0, 2.0, 1.0 / 240.0);
        let rho = 1.3;
        let t = s.with_mass_ratio(rho);
        let a2 = s.mass_scale / s.impulse_scale;
        assert!((t.mass_scale / t.impulse_scale - rho * a2).abs() < 1e-4 * rho * a2);
        assert!((t.mass_scale + t.impulse_scale - 1.0).abs() < 1e-6);
        assert_eq!(Softness::RIGID.with_mass_ratio(4.0), Softness::RIGID);
        let r = s.with_mass_ratio(Real::INFINITY);
        assert_eq!((r.mass_scale, r.impulse_scale), (1.0, 0.0));
    }

    #[test]
    fn stiff_limit_approaches_rigid_feedback() {
        // For a very stiff spring the mass scale approaches 1 and the
        // impulse scale 0.
        let s = Softness::new(1.0e6, 1.0, 1.0 / 60.0);
        assert!(s.mass_scale > 0.999);
        assert!(s.impulse_scale < 1e-3);
    }
}
