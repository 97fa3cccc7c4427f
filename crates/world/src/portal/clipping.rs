//! Aperture clipping: the contact points the narrowphase drops because
//! they lie in a portal's aperture.
//!
//! The portal stage builds a [`ContactClipping`] before the narrowphase;
//! the narrowphase applies it to every manifold it computes (an empty one
//! costs a single check).

use janus2d_core::body::BodyHandle;
use janus2d_core::math::{Real, Vec2};

use crate::contacts::Contact;

/// A region where contact points are dropped: a portal's aperture.
///
/// ```text
///        lip        aperture (|t| < w)       lip
///   ─────────────●━━━━━━━━━━━━━━━━━━━━━●─────────────  wall surface, normal n
///                 points here are dropped
/// ```
///
/// - `Hole`: the aperture is a hole in the wall body that carries the portal:
///   contact points between that body and anything else are dropped when
///   they lie in the aperture's span (|t| < w), from in front of the surface
///   down to a depth of 2w behind it; the lips (|t| ≥ w) still collide.
/// - `Behind`: a crossing copy's points that lie behind its own portal
///   plane within the aperture are dropped (that part of the object is on
///   the other side).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ApertureClip {
    /// The body whose contacts are clipped (the wall, or the crossing copy).
    pub body: BodyHandle,
    /// Aperture centre, world, m.
    pub point: Vec2,
    /// Outward unit normal, world.
    pub normal: Vec2,
    /// Half-width, m.
    pub half_width: Real,
    /// True for a hole in a wall, false for a crossing copy.
    pub hole: bool,
}

impl ApertureClip {
    #[inline]
    fn drops(&self, p: Vec2) -> bool {
        let d = p - self.point;
        let s = d.dot(self.normal);
        let t = janus2d_core::math::cross(self.normal, d);
        if t.abs() >= self.half_width {
            return false;
        }
        if self.hole {
            // The hole runs from the aperture surface into the wall, as
            // deep as the aperture is wide; speculative points in front of
            // the surface belong to it too.
            s > -2.0 * self.half_width
        } else {
            s < 0.0
        }
    }
}

/// Clipping that drops nothing (the narrowphase's input without portals).
pub static NO_CLIPPING: ContactClipping = ContactClipping {
    clips: Vec::new(),
    ignored_pairs: Vec::new(),
};

/// What the portal stage asks the narrowphase to drop.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactClipping {
    /// Aperture regions.
    pub clips: Vec<ApertureClip>,
    /// Pairs of bodies that never touch (a crossing copy and its twin).
    pub ignored_pairs: Vec<(BodyHandle, BodyHandle)>,
}

impl ContactClipping {
    /// True when nothing is clipped (the narrowphase then skips the check).
    pub fn is_empty(&self) -> bool {
        self.clips.is_empty() && self.ignored_pairs.is_empty()
    }

    /// True when `p` lies in the hole of an aperture on `body` (a point the
    /// narrowphase would drop from a contact with that body).
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn in_hole(&self, body: BodyHandle, p: Vec2) -> bool {
        self.clips
            .iter()
            .any(|clip| clip.hole && clip.body == body && clip.drops(p))
    }

    /// True when the pair `(a, b)` never touches (a crossing copy and its twin).
    pub(crate) fn ignores(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.ignored_pairs
            .iter()
            .any(|&(x, y)| (a == x && b == y) || (a == y && b == x))
    }

    /// Drops the points of `c` that the clipping covers.
    pub(crate) fn apply(&self, c: &mut Contact) {
        if self
            .ignored_pairs
            .iter()
            .any(|&(x, y)| (c.body_a == x && c.body_b == y) || (c.body_a == y && c.body_b == x))
        {
            c.point_count = 0;
            return;
        }
        let mut k = 0;
        while k < c.point_count {
            let p = c.points[k].point;
            let dropped = self.clips.iter().any(|clip| {
                let involved = c.body_a == clip.body || c.body_b == clip.body;
                involved && clip.drops(p)
            });
            if dropped {
                c.points[k] = c.points[c.point_count - 1];
                c.point_count -= 1;
            } else {
                k += 1;
            }
        }
    }
}
