//! The crossing stage's decisions: what happens to each crossing in
//! progress and which bodies begin one, read from the bodies, the shapes
//! and the broadphase, and returned as [`Decision`]s the stage carries out
//! (`PortalStage::cross`); and the [`PortalCommand`]s by which it asks
//! the world for each change of structure on the way.
//!
//! ```text
//! review (crossings in progress, in order)
//!   a copy's shapes changed (one destroyed or added) → Restart(original)
//!   original entirely behind the entry plane   → Complete(original)
//!   clone entirely behind the exit plane       → Cancel(original)
//!   otherwise                                  → Weigh(original)
//! entries (pairs in slot order, portal a then b, candidates by handle)
//!   a dynamic body not crossing, not crossed this step, whose shapes
//!   straddle the aperture and fit its width, or whose centre swept
//!   through the aperture during the step      → Start { pair, entry, body }
//! ```
//!
//! Neither pass changes anything: the poses they read do not change while
//! the stage carries the decisions out (only masses, velocities and which
//! bodies exist do), so carrying them out in order gives the same result
//! as deciding each one just before it is carried out.

use janus2d_constraints::portal_map::PortalFrame;
use janus2d_core::body::{BodyHandle, BodySet, BodyType};
use janus2d_core::geometry::{Aabb, Shape};
use janus2d_core::math::{Real, Vec2, cross};

use super::stage::{PairData, PortalStage};
use crate::broadphase::BroadPhase;
use crate::joints::JointHandle;
use crate::shapes::{ShapeDef, ShapeHandle, ShapeStore};

/// What the crossing stage does with a crossing in progress or a body at
/// an aperture (the stage carries each out, in order).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Decision {
    /// The original went through: its handle moves to the clone's body.
    Complete(BodyHandle),
    /// The body backed out: its clone is removed.
    Cancel(BodyHandle),
    /// Both copies straddle: re-weigh their masses by area in front.
    Weigh(BodyHandle),
    /// A copy's shapes changed since the clone was made: the clone is
    /// removed and the original may start again in the same step, with
    /// the shapes it has now.
    Restart(BodyHandle),
    /// A body enters portal `entry` (0: a, 1: b) of pair slot `pair`.
    Start {
        /// Pair slot.
        pair: u32,
        /// Which portal of the pair it enters.
        entry: usize,
        /// The body.
        body: BodyHandle,
    },
}

/// A change to the world's structure that the portal stage asks of the
/// world (`Stores::apply`, in `world/internal.rs`), which applies it at
/// once: the stage reads the stores again before its next command, so
/// the order of operations is the stage's.
// A command is applied as soon as it is made, never stored: the size of
// the shape variant (large with `f64`) costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum PortalCommand {
    /// Wake the island of a body.
    Wake(BodyHandle),
    /// Attach a shape known to be valid (a clone's scaled copy of the
    /// original's); the body's mass is left as it is.
    AddShape {
        /// The body.
        body: BodyHandle,
        /// Material, filter and flags.
        def: ShapeDef,
        /// The geometry in the body's frame.
        geometry: Shape,
    },
    /// Set a body's mass from its shapes.
    MassFromShapes(BodyHandle),
    /// Disable a live joint (the solver skips it; it stays until destroyed).
    DisableJoint(JointHandle),
    /// Move one end of a joint from `from` to `to`, with local anchor
    /// `anchor` in `to`'s frame.
    RepointJoint {
        /// The joint.
        joint: JointHandle,
        /// The body its end leaves.
        from: BodyHandle,
        /// The body its end moves to.
        to: BodyHandle,
        /// The new local anchor on `to`.
        anchor: Vec2,
    },
    /// Exchange two bodies' identities (handles, islands; each shape
    /// handle moves to the matching shape of the other body).
    SwapIdentity(BodyHandle, BodyHandle),
    /// Destroy a live body, its shapes and joints.
    DestroyBody(BodyHandle),
}

impl PortalStage {
    /// Decides what happens to each crossing in progress.
    pub(crate) fn review(&self, bodies: &BodySet, shapes: &ShapeStore) -> Vec<Decision> {
        let mut out = Vec::with_capacity(self.crossings.len());
        for c in &self.crossings {
            let d = self.pairs.at(c.pair).expect("live pair");
            let f_entry = frame(bodies, d, c.entry);
            let f_exit = frame(bodies, d, 1 - c.entry);
            let behind = |body, f: &PortalFrame| {
                extents_in(bodies, shapes, body, f).is_some_and(|e| e.1 < 0.0)
            };
            let owner = bodies.owner();
            let changed = shape_handles(shapes, c.original, owner) != c.original_shapes
                || shape_handles(shapes, c.clone, owner) != c.clone_shapes;
            out.push(if changed {
                Decision::Restart(c.original)
            } else if behind(c.original, &f_entry) {
                Decision::Complete(c.original)
            } else if behind(c.clone, &f_exit) {
                Decision::Cancel(c.original)
            } else {
                Decision::Weigh(c.original)
            });
        }
        out
    }

    /// Finds the bodies that begin a crossing; also returns how many
    /// bodies were tested against apertures.
    pub(crate) fn entries(
        &self,
        bodies: &BodySet,
        shapes: &ShapeStore,
        broadphase: &BroadPhase,
        crossed: &[BodyHandle],
    ) -> (Vec<Decision>, usize) {
        let mut out = Vec::new();
        let mut planned: Vec<BodyHandle> = Vec::new();
        let mut tested = 0;
        for (index, d) in self.pairs.iter() {
            for entry in 0..2 {
                let f = frame(bodies, d, entry);
                let w = d.local[entry].half_width;
                let candidates = aperture_candidates(bodies, shapes, broadphase, &f, w, d);
                tested += candidates.len();
                for body in candidates {
                    if crossed.contains(&body)
                        || planned.contains(&body)
                        || self.crossing_of(body).is_some()
                    {
                        continue;
                    }
                    let Some((n0, n1, t0, t1)) = extents_in(bodies, shapes, body, &f) else {
                        continue;
                    };
                    let straddles = n0 < 0.0 && n1 > 0.0 && t0 >= -w && t1 <= w;
                    let Some(sim) = bodies.sim(body) else {
                        continue;
                    };
                    let s0 = (sim.center0 - f.point).dot(f.normal);
                    let s1 = (sim.center - f.point).dot(f.normal);
                    let swept = s0 > 0.0 && s1 <= 0.0 && {
                        let x = sim.center0 + (sim.center - sim.center0) * (s0 / (s0 - s1));
                        cross(f.normal, x - f.point).abs() < w
                    };
                    if straddles || swept {
                        planned.push(body);
                        out.push(Decision::Start {
                            pair: index,
                            entry,
                            body,
                        });
                    }
                }
            }
        }
        (out, tested)
    }
}

/// The world frame of portal `k` of a pair.
fn frame(bodies: &BodySet, d: &PairData, k: usize) -> PortalFrame {
    PortalFrame::new(
        &bodies.solver_body(d.portals[k].body).sim.transform,
        &d.local[k],
    )
}

/// The handles of a body's shapes, in the store's order (generations
/// tell a shape made in a freed slot from the one that was there).
pub(crate) fn shape_handles(shapes: &ShapeStore, body: BodyHandle, owner: u32) -> Vec<ShapeHandle> {
    shapes
        .of_body(body)
        .iter()
        .map(|&s| shapes.handle_of(s, owner))
        .collect()
}

/// Extents `(min_n, max_n, min_t, max_t)` of a body's shapes in a portal
/// frame (`None` for a body without shapes).
pub(crate) fn extents_in(
    bodies: &BodySet,
    shapes: &ShapeStore,
    body: BodyHandle,
    f: &PortalFrame,
) -> Option<(Real, Real, Real, Real)> {
    let xf = bodies.sim(body)?.transform;
    let list = shapes.of_body(body);
    if list.is_empty() {
        return None;
    }
    let (mut n0, mut n1, mut t0, mut t1) = (Real::MAX, Real::MIN, Real::MAX, Real::MIN);
    let offset_n = f.point.dot(f.normal);
    let offset_t = f.point.dot(f.tangent);
    for &s in list {
        let shape = &shapes.at(s).geometry;
        let (a, b) = shape.support_extent(&xf, f.normal);
        n0 = n0.min(a - offset_n);
        n1 = n1.max(b - offset_n);
        let (a, b) = shape.support_extent(&xf, f.tangent);
        t0 = t0.min(a - offset_t);
        t1 = t1.max(b - offset_t);
    }
    Some((n0, n1, t0, t1))
}

/// Fraction of a body's shape area in front of a portal plane.
pub(crate) fn front_fraction(
    bodies: &BodySet,
    shapes: &ShapeStore,
    body: BodyHandle,
    f: &PortalFrame,
) -> Real {
    let Some(sim) = bodies.sim(body) else {
        return 0.0;
    };
    let xf = sim.transform;
    let (mut front, mut total) = (0.0, 0.0);
    for &s in shapes.of_body(body) {
        let shape = &shapes.at(s).geometry;
        front += shape.area_in_front(&xf, f.point, f.normal);
        total += shape.area();
    }
    if total > 0.0 { front / total } else { 0.0 }
}

/// Dynamic bodies whose shapes' boxes touch an aperture region (both sides
/// of the segment), sorted by handle for a deterministic order.
fn aperture_candidates(
    bodies: &BodySet,
    shapes: &ShapeStore,
    broadphase: &BroadPhase,
    f: &PortalFrame,
    w: Real,
    d: &PairData,
) -> Vec<BodyHandle> {
    let a = f.point - w * f.tangent;
    let b = f.point + w * f.tangent;
    let region = Aabb::new(a.min(b), a.max(b)).fattened(crate::collision::AABB_MARGIN);
    let mut out = Vec::new();
    broadphase.query(&region, |_, payload| {
        out.push(shapes.at(payload).body);
        true
    });
    out.sort();
    out.dedup();
    out.retain(|b| {
        bodies.body_type(*b) == Some(BodyType::Dynamic) && d.portals.iter().all(|p| p.body != *b)
    });
    out
}
