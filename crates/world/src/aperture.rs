//! Aperture clipping: a wall that carries a portal collides as its solid
//! parts, and a crossing copy as its part in front of its own portal.
//!
//! The portal stage builds a [`ContactClipping`] before the narrowphase;
//! the narrowphase hands every manifold it computes to
//! [`ContactClipping::clip_manifold`] before storing it (an empty clipping
//! costs a single check).
//!
//! A two-point manifold is a segment of the body's footprint on the other
//! surface (the two points and their separations are affine along it).
//! Clipping removes from that segment the parts that lie in a region and
//! keeps its extreme solid points: an end that lies in a region is
//! replaced by the point where the segment leaves the region (an aperture
//! edge, the lip), with its separation and anchors interpolated. So a
//! plank with one end over an aperture is held at its other end and at the
//! lip; a box on the strip between two apertures is held at the two lips;
//! a footprint wholly over an aperture keeps no point and falls in.
//!
//! ```text
//!   footprint   p0 ●━━━━━━━━━━━━━━━━━━━━━━━━━━━● p1
//!   wall     ──────────────●     aperture     ●─────────── (normal n)
//!                        lip  (points dropped)  lip
//!   kept        p0 ●━━━━━━━● q                 (q: new point at the lip,
//!                                               id LIP_ID_LOW / HIGH)
//! ```
//!
//! | region | body | span | depth |
//! |--------|------|------|-------|
//! | `Hole` | the wall carrying the portal | `|t| < w` | `s > −2w` (into the wall as deep as the aperture is wide; in front of the surface too) |
//! | `Behind` | a crossing copy | `|t| < w` | `s < 0` (that part of the object is on the other side) |
//!
//! A one-point manifold keeps its point unless a region covers it.
//!
//! **A copy against its own wall.** Between a crossing copy and the wall
//! that carries the aperture it passes through, the copy's points behind
//! its plane are dropped beside the span too (that part is on the other
//! side), and the lips act as the sides of the aperture: where the copy's
//! cross-section at the plane reaches past `|t| = w`, a lip corner pushes
//! it back into the span, as a corner pushes a face: along the normal of
//! the copy's edge that crosses the plane there (or from a rounded
//! vertex's centre), with a speculative margin of a few linear slops only
//! (a fast grazing entry is through before its section would reach the
//! far lip). A tilted link sliding down past the corner is pushed off its
//! face, not jerked along the tangent at its sliding speed times the tilt;
//! a copy wholly behind its plane (held there for its joints) is kept in
//! the slot `|t| < w` as between two side walls. The deeper of this side
//! contact and the clipped manifold is kept. Without it the two copies of
//! a link pushed past a lip were each pushed out of their own wall, in
//! opposite directions through the map.
//!
//! ```text
//!            span |t| < w
//!   ────────●               ●────────   wall surface (normal n)
//!        ▶ ┃│  copy crossing  │┃ ◀       the lips hold its section at the
//!          ┃│                 │┃         plane within the span
//! ```
//!
//! **Speculative points land where the body will arrive.** A speculative
//! point (separation > 0) acts for the whole step, so what matters is where
//! the body's point meets the wall, not where it is at the start of the
//! step: against a hole, each point is also tested at its arrival
//! `p' = p + τ u` (dropped when either lies in the hole), with `u` the point's velocity relative to the wall and
//! `τ = separation / approach speed` (when `τ ≤ 1.5 dt`; a point that
//! arrives later does not act this step and stays put). A fast body entering
//! at a shallow angle, still over a lip at the start of the step but over
//! the aperture when it reaches the wall's plane, gets no point that would
//! stop it: it crosses in that step.
//!
//! ```text
//!   start of step   ▣ ─ ─ ─ ─ ─ ─▶ p'            (u: grazing, fast)
//!   wall ─────────────●     p' in the aperture   ●────────
//!                    lip   → the point is dropped  lip
//! ```

use janus2d_core::body::BodyHandle;
use janus2d_core::geometry::{Manifold, ManifoldPoint, RayInput, Shape};
use janus2d_core::math::{Real, Transform, Vec2};

/// How the two bodies of a contact move at the start of the step (what the
/// speculative points of a manifold are computed for).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PairMotion {
    /// Centres of mass of body a and body b, m.
    pub center: [Vec2; 2],
    /// Linear velocities, m/s.
    pub velocity: [Vec2; 2],
    /// Angular velocities, rad/s.
    pub angular_velocity: [Real; 2],
    /// The step, s.
    pub dt: Real,
}

impl PairMotion {
    /// Velocity of the material point of body `k` at `p`.
    #[inline]
    fn velocity_at(&self, k: usize, p: Vec2) -> Vec2 {
        self.velocity[k] + self.angular_velocity[k] * (p - self.center[k]).perp()
    }
}

/// The two shapes of a contact where they are, for the lip points of a
/// lone point that a hole drops ([`ContactClipping::clip_manifold`]).
#[derive(Clone, Copy, Debug)]
pub struct PairShapes<'a> {
    /// Shape a and shape b.
    pub shapes: [&'a Shape; 2],
    /// Their bodies' transforms.
    pub transforms: [Transform; 2],
    /// The contact's speculative distance, m.
    pub speculative: Real,
}

/// Feature id of a point made where the footprint's low end (point 0's
/// side) leaves a region (chosen above every polygon feature id).
pub const LIP_ID_LOW: u16 = 0xFFF0;
/// Feature id of a point made where the footprint's high end (point 1's
/// side) leaves a region.
pub const LIP_ID_HIGH: u16 = 0xFFF1;

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
    /// Which aperture it is (`2 × pair slot + portal`, 0: a, 1: b): a
    /// crossing copy collides with the holes of every other aperture as
    /// solid wall (see [`ContactClipping::copies`]).
    pub aperture: u32,
}

impl ApertureClip {
    /// Depth range `(lo, hi)` of the region along the normal (open).
    #[inline]
    fn depth_range(&self) -> (Real, Real) {
        if self.hole {
            (-2.0 * self.half_width, Real::INFINITY)
        } else {
            (Real::NEG_INFINITY, 0.0)
        }
    }

    /// Frame coordinates `(s, t)` of a world point.
    #[inline]
    fn coords(&self, p: Vec2) -> (Real, Real) {
        let d = p - self.point;
        (
            d.dot(self.normal),
            janus2d_core::math::cross(self.normal, d),
        )
    }

    #[inline]
    fn drops(&self, p: Vec2) -> bool {
        let (s, t) = self.coords(p);
        let (lo, hi) = self.depth_range();
        t.abs() < self.half_width && s > lo && s < hi
    }

    /// The open parameter interval `(u0, u1)` of the segment
    /// `p0 + u (p1 − p0)` that lies in the region (empty: `u0 ≥ u1`).
    #[must_use]
    pub fn segment_interval(&self, p0: Vec2, p1: Vec2) -> (Real, Real) {
        let (s0, t0) = self.coords(p0);
        let (s1, t1) = self.coords(p1);
        let (lo, hi) = self.depth_range();
        let (a, b) = open_range(t0, t1, -self.half_width, self.half_width);
        let (c, d) = open_range(s0, s1, lo, hi);
        (a.max(c), b.min(d))
    }
}

/// The open range of `u` (unbounded) where `lo < f0 + u (f1 − f0) < hi`.
#[inline]
fn open_range(f0: Real, f1: Real, lo: Real, hi: Real) -> (Real, Real) {
    let df = f1 - f0;
    if df == 0.0 {
        return if f0 > lo && f0 < hi {
            (Real::NEG_INFINITY, Real::INFINITY)
        } else {
            (Real::INFINITY, Real::NEG_INFINITY)
        };
    }
    let ua = (lo - f0) / df;
    let ub = (hi - f0) / df;
    // An infinite bound gives ±inf (never NaN: df ≠ 0 and f0 finite).
    if ua < ub { (ua, ub) } else { (ub, ua) }
}

/// Clipping that drops nothing (the narrowphase's input without portals).
#[cfg_attr(feature = "portals", allow(dead_code))]
pub static NO_CLIPPING: ContactClipping = ContactClipping {
    clips: Vec::new(),
    ignored_pairs: Vec::new(),
    copies: Vec::new(),
};

/// What the portal stage asks the narrowphase to drop.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContactClipping {
    /// Aperture regions.
    pub clips: Vec<ApertureClip>,
    /// Pairs of bodies that never touch (a crossing copy and its twin).
    pub ignored_pairs: Vec<(BodyHandle, BodyHandle)>,
    /// Each crossing copy with the aperture it passes through. A body
    /// crosses one portal at a time, so the hole of any other aperture is
    /// solid wall to it: a long body that reaches a second aperture while
    /// crossing a first is held there, never falls in.
    pub copies: Vec<(BodyHandle, u32)>,
}

impl ContactClipping {
    /// True when nothing is clipped (the narrowphase then skips the check).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.clips.is_empty() && self.ignored_pairs.is_empty()
    }

    /// True when `p` lies in a hole of an aperture on `body` that is open
    /// to `other` (a point the narrowphase would drop from a contact
    /// between them; see [`ContactClipping::copies`]).
    #[cfg_attr(not(feature = "portals"), allow(dead_code))]
    pub(crate) fn in_hole_for(&self, body: BodyHandle, other: BodyHandle, p: Vec2) -> bool {
        self.clips.iter().any(|clip| {
            clip.hole
                && clip.body == body
                && clip.drops(p)
                && self.hole_open_to(other, clip.aperture)
        })
    }

    /// True when the hole of `aperture` lets `body` in: always, unless the
    /// body is a crossing copy passing through another aperture.
    #[inline]
    fn hole_open_to(&self, body: BodyHandle, aperture: u32) -> bool {
        let mut crossing = false;
        for &(copy, through) in &self.copies {
            if copy == body {
                if through == aperture {
                    return true;
                }
                crossing = true;
            }
        }
        !crossing
    }

    /// The points where the other body's footprint lies over the lips of
    /// `clip` (a hole on one of the two bodies): for each lip corner
    /// `L = P ± w t` the other shape is cast along the face normal from
    /// below its lowest point through `L`; where it meets the shape within
    /// the speculative distance of the face, a point at `L` with that
    /// separation (normal: the face's). A lone point (a circle, a corner)
    /// dropped in the aperture so leaves a body wider than the aperture
    /// resting on the lips; one within the span gets none and falls in.
    fn lip_points(
        &self,
        clip: &ApertureClip,
        body_a: BodyHandle,
        shapes: &PairShapes<'_>,
        m: &mut Manifold,
    ) {
        let (wall, other) = if clip.body == body_a { (0, 1) } else { (1, 0) };
        let (shape, xf) = (shapes.shapes[other], &shapes.transforms[other]);
        let n = clip.normal;
        let (low, _) = shape.support_extent(xf, n);
        let low = low - clip.point.dot(n);
        if low > shapes.speculative {
            return;
        }
        let tangent = n.perp();
        let margin = 0.1 * clip.half_width + janus2d_core::geometry::SPECULATIVE_DISTANCE;
        m.normal = if wall == 0 { n } else { -n };
        m.point_count = 0;
        for (side, id) in [(-1.0, LIP_ID_LOW), (1.0, LIP_ID_HIGH)] {
            let lip = clip.point + side * clip.half_width * tangent;
            let origin = lip + (low - margin) * n;
            let ray = RayInput::new(origin, (shapes.speculative - low + margin) * n);
            let Some(hit) = shape.ray_cast(xf, &ray) else {
                continue;
            };
            let separation = (hit.point - lip).dot(n);
            if separation >= shapes.speculative {
                continue;
            }
            let point = lip + 0.5 * separation * n;
            m.points[m.point_count] = ManifoldPoint {
                point,
                anchor_a: point - shapes.transforms[0].p,
                anchor_b: point - shapes.transforms[1].p,
                separation,
                id,
            };
            m.point_count += 1;
        }
    }

    /// The hole clip of the aperture a crossing copy passes through when
    /// the pair is that copy and the wall carrying the aperture, and which
    /// of the two the copy is (0: a, 1: b).
    fn own_wall(&self, body_a: BodyHandle, body_b: BodyHandle) -> Option<(&ApertureClip, usize)> {
        self.copies.iter().find_map(|&(c, aperture)| {
            let (wall, copy) = if c == body_a {
                (body_b, 0)
            } else if c == body_b {
                (body_a, 1)
            } else {
                return None;
            };
            let clip = self
                .clips
                .iter()
                .find(|k| k.hole && k.body == wall && k.aperture == aperture)?;
            Some((clip, copy))
        })
    }

    /// True when the pair `(a, b)` never touches (a crossing copy and its twin).
    pub(crate) fn ignores(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.ignored_pairs
            .iter()
            .any(|&(x, y)| (a == x && b == y) || (a == y && b == x))
    }

    /// Clips the manifold between `body_a` and `body_b` to the solid parts
    /// (module docs): empties it for an ignored pair, drops a lone point a
    /// region covers, and trims a two-point footprint to its extreme solid
    /// points, making points at the region edges it meets.
    ///
    /// ```
    /// use janus2d_core::body::BodyHandle;
    /// use janus2d_core::geometry::{Manifold, ManifoldPoint};
    /// use janus2d_core::math::{Real, Vec2};
    /// use janus2d_world::aperture::{ApertureClip, ContactClipping, PairMotion};
    ///
    /// // A floor at y = 0 with a 1 m aperture at the origin; a plank's
    /// // footprint from x = −0.3 (over the aperture) to x = 3.
    /// let wall = BodyHandle::new(1, 0, 0);
    /// let plank = BodyHandle::new(2, 0, 0);
    /// let clipping = ContactClipping {
    ///     clips: vec![ApertureClip {
    ///         body: wall,
    ///         point: Vec2::ZERO,
    ///         normal: Vec2::Y,
    ///         half_width: 0.5,
    ///         hole: true,
    ///         aperture: 0,
    ///     }],
    ///     ignored_pairs: vec![],
    ///     copies: vec![],
    /// };
    /// let point = |x: Real| ManifoldPoint {
    ///     point: Vec2::new(x, 0.0),
    ///     separation: -0.01,
    ///     ..Default::default()
    /// };
    /// let mut m = Manifold {
    ///     normal: Vec2::Y,
    ///     points: [point(-0.3), point(3.0)],
    ///     point_count: 2,
    /// };
    /// // Both at rest: the points are clipped where they are.
    /// clipping.clip_manifold(wall, plank, &PairMotion::default(), None, &mut m);
    /// assert_eq!(m.point_count, 2);
    /// // The end over the aperture moved to the lip at x = 0.5.
    /// assert!((m.points[0].point.x - 0.5).abs() < 1e-5);
    /// assert!((m.points[1].point.x - 3.0).abs() < 1e-5);
    /// ```
    pub fn clip_manifold(
        &self,
        body_a: BodyHandle,
        body_b: BodyHandle,
        motion: &PairMotion,
        shapes: Option<&PairShapes<'_>>,
        m: &mut Manifold,
    ) {
        if m.point_count == 0 {
            return;
        }
        if self.ignores(body_a, body_b) {
            m.point_count = 0;
            return;
        }
        let involved = |clip: &&ApertureClip| {
            let other = if clip.body == body_a {
                body_b
            } else if clip.body == body_b {
                body_a
            } else {
                return false;
            };
            !clip.hole || self.hole_open_to(other, clip.aperture)
        };
        if !self.clips.iter().any(|c| involved(&c)) {
            return;
        }
        if let Some(shapes) = shapes
            && let Some((clip, copy)) = self.own_wall(body_a, body_b)
        {
            let side = side_wall(clip, copy, shapes);
            // The copy's part behind its plane is on the other side,
            // beside the span too: against its own wall only the side
            // walls hold it there.
            let (p0, p1) = (m.points[0], m.points[1]);
            let front: Vec<ManifoldPoint> = [p0, p1][..m.point_count]
                .iter()
                .copied()
                .filter(|p| (p.point - clip.point).dot(clip.normal) >= 0.0)
                .collect();
            m.point_count = front.len();
            m.points[..front.len()].copy_from_slice(&front);
            if let Some(side) = side {
                let deepest = |m: &Manifold| {
                    m.points[..m.point_count]
                        .iter()
                        .map(|p| p.separation)
                        .fold(Real::MAX, Real::min)
                };
                if m.point_count == 0 || deepest(&side) < deepest(m) {
                    *m = side;
                    return;
                }
            }
            if m.point_count == 0 {
                return;
            }
        }
        // Where each point meets a hole's wall (its own place when it
        // touches already or does not approach).
        let arrival = |clip: &ApertureClip, p: &ManifoldPoint| -> Vec2 {
            if p.separation <= 0.0 {
                return p.point;
            }
            let (wall, other) = if clip.body == body_a { (0, 1) } else { (1, 0) };
            let u = motion.velocity_at(other, p.point) - motion.velocity_at(wall, p.point);
            let approach = -u.dot(clip.normal);
            if approach <= 0.0 {
                return p.point;
            }
            // A point that arrives just after the step still acts in its
            // last substeps, so its true arrival decides; one that arrives
            // later does not act this step and is left where it is.
            let tau = p.separation / approach;
            if tau > 1.5 * motion.dt {
                return p.point;
            }
            p.point + tau * u
        };
        // A hole covers a point where it is and where it arrives: the
        // arrival only ever drops a point (a point over the aperture now is
        // never held by the lip it is heading for).
        if m.point_count == 1 {
            let p = m.points[0];
            let dropped = self
                .clips
                .iter()
                .filter(involved)
                .find(|c| c.drops(p.point) || (c.hole && c.drops(arrival(c, &p))));
            if let Some(clip) = dropped {
                m.point_count = 0;
                if clip.hole
                    && let Some(shapes) = shapes
                {
                    self.lip_points(clip, body_a, shapes, m);
                }
            }
            return;
        }
        let (p0, p1) = (m.points[0], m.points[1]);
        let intervals = || {
            self.clips.iter().filter(involved).flat_map(|c| {
                let now = c.segment_interval(p0.point, p1.point);
                let later = if c.hole {
                    c.segment_interval(arrival(c, &p0), arrival(c, &p1))
                } else {
                    (1.0, 0.0)
                };
                [now, later].into_iter().filter(|&(lo, hi)| lo < hi)
            })
        };
        // Lowest solid parameter: step past every region covering it.
        let mut u_low: Real = 0.0;
        let mut u_high: Real = 1.0;
        for _ in 0..=2 * self.clips.len() {
            let mut moved = false;
            for (lo, hi) in intervals() {
                // A region covers the parameter where a search coming from
                // outside enters it (two regions that touch leave nothing
                // solid between them) but not where it leaves it (that
                // edge, the lip, is solid).
                if lo <= u_low && u_low < hi {
                    u_low = hi;
                    moved = true;
                }
                if lo < u_high && u_high <= hi {
                    u_high = lo;
                    moved = true;
                }
            }
            if !moved {
                break;
            }
        }
        if u_low > u_high || u_low > 1.0 || u_high < 0.0 {
            m.point_count = 0;
            return;
        }
        // An end that survived is kept as it is (its id warm-starts it);
        // a point at a region edge is interpolated along the footprint.
        let at = |u: Real, id: u16| -> ManifoldPoint {
            if u == 0.0 {
                return p0;
            }
            if u == 1.0 {
                return p1;
            }
            let lerp = |a: Vec2, b: Vec2| a + (b - a) * u;
            ManifoldPoint {
                point: lerp(p0.point, p1.point),
                anchor_a: lerp(p0.anchor_a, p1.anchor_a),
                anchor_b: lerp(p0.anchor_b, p1.anchor_b),
                separation: p0.separation + (p1.separation - p0.separation) * u,
                id,
            }
        };
        let low = at(u_low, LIP_ID_LOW);
        let high = at(u_high, LIP_ID_HIGH);
        if u_high - u_low <= Real::EPSILON {
            m.points[0] = low;
            m.point_count = 1;
        } else {
            m.points = [low, high];
        }
    }
}

/// Linear slops within which a copy's cross-section at its plane meets a
/// lip corner before it touches (its speculative margin there).
const SECTION_MARGIN_SLOPS: Real = 4.0;

/// The contact of a crossing copy (pair side `copy`) with the sides of
/// the aperture `clip` it passes through. Where the copy crosses the
/// plane, its cross-section there must lie within the span `|t| < w`: the
/// lip corners `L = P ± w t` hold it (a part behind the plane is on the
/// other side, where it may reach past the span; a fast grazing entry
/// does). The corner meets the feature of the section's end on its side:
///
/// | feature at the plane | normal (the copy's, toward `L`) | separation |
/// |---|---|---|
/// | core edge crossing at `t`, outward normal `m` | `m` | `(w − ±t)(m · ±t) − r` |
/// | rounded vertex `C` within `r` of the plane | `(L − C)/‖L − C‖` | `‖L − C‖ − r` |
/// | rounded vertex already past the lip | `±t` | `w − (±t + reach)` |
///
/// one point per side, the deeper side kept. A copy wholly behind its
/// plane (held there for its joints) is held in the slot `|t| < w` behind
/// the lips ([`slot_wall`]). `None` when neither side is near, or for a
/// shape without an area.
fn side_wall(clip: &ApertureClip, copy: usize, shapes: &PairShapes<'_>) -> Option<Manifold> {
    let xf = &shapes.transforms[copy];
    let capsule;
    let (core, radius): (&[Vec2], Real) = match shapes.shapes[copy] {
        Shape::Polygon(p) => (&p.vertices[..p.count], p.radius),
        Shape::Capsule(c) => {
            capsule = [c.center1, c.center2];
            (&capsule[..], c.radius)
        }
        Shape::Circle(c) => (std::slice::from_ref(&c.center), c.radius),
        _ => return None,
    };
    let n = clip.normal;
    let tangent = n.perp();
    let coords = |v: Vec2| {
        let d = xf.apply(v) - clip.point;
        (d.dot(n), d.dot(tangent))
    };
    let wholly = core.iter().all(|&v| coords(v).0 + radius <= 0.0);
    if wholly {
        return slot_wall(clip, copy, shapes, core, radius, &coords);
    }
    // The cross-section at the plane: the core's edges crossing it (their
    // outward normal), and a rounded vertex within its radius of it (its
    // centre).
    let mut section: Vec<SectionFeature> = Vec::with_capacity(2 * core.len());
    for (k, &v) in core.iter().enumerate() {
        let (s0, t0) = coords(v);
        if s0.abs() < radius {
            section.push(SectionFeature::Cap {
                centre: xf.apply(v),
                t: t0,
                reach: (radius * radius - s0 * s0).sqrt(),
            });
        }
        if core.len() > 1 {
            let next = core[(k + 1) % core.len()];
            let (s1, t1) = coords(next);
            if (s0 < 0.0) != (s1 < 0.0) {
                let u = s0 / (s0 - s1);
                let edge = xf.apply(next) - xf.apply(v);
                section.push(SectionFeature::Edge {
                    t: t0 + u * (t1 - t0),
                    outward: Vec2::new(edge.y, -edge.x).normalize_or_zero(),
                });
            }
        }
    }
    // A cross-section point acts when it is about to touch: the section
    // moves with the copy only while it straddles (a fast grazing entry is
    // through before its section would reach the far lip), so its
    // speculative margin is a few slops, not the step's travel.
    let near_enough = shapes
        .speculative
        .min(SECTION_MARGIN_SLOPS * janus2d_core::geometry::LINEAR_SLOP);
    let mut best: Option<Manifold> = None;
    for (side, id) in [(-1.0, LIP_ID_LOW), (1.0, LIP_ID_HIGH)] {
        let lip = clip.point + side * clip.half_width * tangent;
        let toward_lip = side * tangent;
        // (separation, the copy's outward normal toward the lip corner).
        let touch = |f: &SectionFeature| -> Option<(Real, Vec2)> {
            match *f {
                SectionFeature::Edge { t, outward } => {
                    let facing = outward.dot(toward_lip);
                    // The other side's edge, or one along the plane.
                    if facing <= 0.0 {
                        return None;
                    }
                    let across = clip.half_width - side * t;
                    Some((across * facing - radius, outward))
                }
                SectionFeature::Cap { centre, t, reach } => {
                    let d = lip - centre;
                    let length = d.length();
                    if d.dot(toward_lip) > 0.0 && length > 0.0 {
                        Some((length - radius, d / length))
                    } else {
                        // The centre is past the lip: push straight back.
                        Some((clip.half_width - (side * t + reach), toward_lip))
                    }
                }
            }
        };
        let Some((separation, outward)) = section
            .iter()
            .filter_map(touch)
            .filter(|&(separation, _)| separation < near_enough)
            .min_by(|a, b| a.0.total_cmp(&b.0))
        else {
            continue;
        };
        let point = lip - 0.5 * separation * outward;
        let mut m = Manifold {
            // The pair's normal runs from a to b; the copy is pushed along
            // minus its outward normal, away from the lip corner.
            normal: if copy == 1 { -outward } else { outward },
            point_count: 1,
            ..Manifold::default()
        };
        m.points[0] = ManifoldPoint {
            point,
            anchor_a: point - shapes.transforms[0].p,
            anchor_b: point - shapes.transforms[1].p,
            separation,
            id,
        };
        if best.is_none_or(|b: Manifold| separation < b.points[0].separation) {
            best = Some(m);
        }
    }
    best
}

/// Where a crossing copy's boundary meets its aperture's plane.
#[derive(Clone, Copy, Debug)]
enum SectionFeature {
    /// A core edge crossing the plane at lateral coordinate `t`, with its
    /// outward unit normal (world).
    Edge { t: Real, outward: Vec2 },
    /// A rounded vertex within its radius of the plane: its centre
    /// (world), lateral coordinate `t` and its section's half-width there.
    Cap { centre: Vec2, t: Real, reach: Real },
}

/// A copy wholly behind its plane (held there for its joints), kept in the
/// slot `|t| < w` behind the lips as between two side walls: normal `∓t`
/// into the span, the deeper side, up to two points.
fn slot_wall(
    clip: &ApertureClip,
    copy: usize,
    shapes: &PairShapes<'_>,
    core: &[Vec2],
    radius: Real,
    coords: &dyn Fn(Vec2) -> (Real, Real),
) -> Option<Manifold> {
    let tangent = clip.normal.perp();
    let mut best: Option<Manifold> = None;
    for (side, id) in [(-1.0, LIP_ID_LOW), (1.0, LIP_ID_HIGH)] {
        let mut m = Manifold::default();
        // Into the span from this side, as the pair's normal (a to b).
        let into_span = -side * tangent;
        m.normal = if copy == 1 { into_span } else { -into_span };
        let mut near: Vec<(Real, Real)> = core
            .iter()
            .map(|&v| {
                let (s, t) = coords(v);
                (clip.half_width - (side * t + radius), s)
            })
            .filter(|&(separation, _)| separation < shapes.speculative)
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (k, &(separation, s)) in near.iter().take(2).enumerate() {
            let point = clip.point + side * clip.half_width * tangent + s * clip.normal
                - 0.5 * separation * into_span;
            m.points[k] = ManifoldPoint {
                point,
                anchor_a: point - shapes.transforms[0].p,
                anchor_b: point - shapes.transforms[1].p,
                separation,
                id: id + 2 * k as u16,
            };
            m.point_count = k + 1;
        }
        if m.point_count > 0
            && best.is_none_or(|b: Manifold| m.points[0].separation < b.points[0].separation)
        {
            best = Some(m);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn handle(i: u32) -> BodyHandle {
        BodyHandle::new(i, 0, 0)
    }

    fn floor_with(centres: &[Real], w: Real) -> ContactClipping {
        ContactClipping {
            clips: centres
                .iter()
                .enumerate()
                .map(|(k, &x)| ApertureClip {
                    body: handle(1),
                    point: Vec2::new(x, 0.0),
                    normal: Vec2::Y,
                    half_width: w,
                    hole: true,
                    aperture: 2 * k as u32,
                })
                .collect(),
            ignored_pairs: vec![],
            copies: vec![],
        }
    }

    fn footprint(x0: Real, x1: Real, s0: Real, s1: Real) -> Manifold {
        let p = |x: Real, s: Real, id: u16| ManifoldPoint {
            point: Vec2::new(x, 0.0),
            anchor_a: Vec2::new(x, 1.0),
            anchor_b: Vec2::new(x - 1.0, 0.5),
            separation: s,
            id,
        };
        Manifold {
            normal: Vec2::Y,
            points: [p(x0, s0, 1), p(x1, s1, 2)],
            point_count: 2,
        }
    }

    #[test]
    fn end_over_an_aperture_moves_to_the_lip_with_interpolated_data() {
        let clipping = floor_with(&[0.0], 0.5);
        let mut m = footprint(-0.3, 3.7, -0.01, -0.03);
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 2);
        let u = 0.8 / 4.0;
        let q = m.points[0];
        assert!((q.point.x - 0.5).abs() < 1e-5);
        assert!((q.anchor_a.x - 0.5).abs() < 1e-5);
        assert!((q.anchor_b.x + 0.5).abs() < 1e-5);
        assert!((q.separation - (-0.01 - 0.02 * u)).abs() < 1e-6);
        assert_eq!(q.id, LIP_ID_LOW);
        assert_eq!(m.points[1].id, 2);
    }

    #[test]
    fn strip_between_two_apertures_keeps_both_lips() {
        let clipping = floor_with(&[-1.0, 1.0], 0.7);
        let mut m = footprint(-0.6, 0.6, 0.0, 0.0);
        clipping.clip_manifold(handle(2), handle(1), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 2);
        assert!((m.points[0].point.x + 0.3).abs() < 1e-5);
        assert!((m.points[1].point.x - 0.3).abs() < 1e-5);
        assert_eq!((m.points[0].id, m.points[1].id), (LIP_ID_LOW, LIP_ID_HIGH));
    }

    #[test]
    fn footprint_within_an_aperture_keeps_nothing() {
        let clipping = floor_with(&[0.0], 0.5);
        let mut m = footprint(-0.4, 0.4, 0.0, 0.0);
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 0);
        // Spanning two touching apertures: nothing solid in between.
        let clipping = floor_with(&[-0.5, 0.5], 0.5);
        let mut m = footprint(-0.8, 0.8, 0.0, 0.0);
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 0);
    }

    #[test]
    fn plank_across_an_aperture_keeps_its_ends() {
        let clipping = floor_with(&[0.0], 0.5);
        let mut m = footprint(-2.0, 2.0, 0.0, 0.0);
        let before = m;
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m, before);
        // Another pair of bodies is not clipped at all.
        let mut m = footprint(-0.4, 0.4, 0.0, 0.0);
        clipping.clip_manifold(handle(3), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 2);
    }

    #[test]
    fn speculative_points_are_clipped_where_they_arrive() {
        let clipping = floor_with(&[0.0], 0.5);
        // Over the lip at x ∈ [−0.7, −0.6], 0.1 m up, moving at (10, −1):
        // it reaches the floor after 0.1 s, 1 m further on, in the aperture.
        let mut m = footprint(-0.7, -0.6, 0.1, 0.1);
        let motion = |v: Vec2| PairMotion {
            center: [Vec2::new(0.0, -0.5), Vec2::new(-0.65, 0.2)],
            velocity: [Vec2::ZERO, v],
            angular_velocity: [0.0, 0.0],
            dt: 0.2,
        };
        clipping.clip_manifold(
            handle(1),
            handle(2),
            &motion(Vec2::new(10.0, -1.0)),
            None,
            &mut m,
        );
        assert_eq!(m.point_count, 0);
        // Slower, it lands on the lip: kept.
        let mut m = footprint(-0.7, -0.6, 0.1, 0.1);
        clipping.clip_manifold(
            handle(1),
            handle(2),
            &motion(Vec2::new(0.5, -1.0)),
            None,
            &mut m,
        );
        assert_eq!(m.point_count, 2);
        // Moving away: where it is (over the lip), kept.
        let mut m = footprint(-0.7, -0.6, 0.1, 0.1);
        clipping.clip_manifold(
            handle(1),
            handle(2),
            &motion(Vec2::new(10.0, 1.0)),
            None,
            &mut m,
        );
        assert_eq!(m.point_count, 2);
    }

    #[test]
    fn a_copy_crossing_elsewhere_finds_the_hole_solid() {
        let mut clipping = floor_with(&[0.0], 0.5);
        // Body 2 crosses aperture 5 (another pair): the floor's hole holds it.
        clipping.copies.push((handle(2), 5));
        let mut m = footprint(-0.4, 0.4, 0.0, 0.0);
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 2);
        // Crossing through this very aperture: the hole is open.
        clipping.copies.push((handle(2), 0));
        let mut m = footprint(-0.4, 0.4, 0.0, 0.0);
        clipping.clip_manifold(handle(1), handle(2), &PairMotion::default(), None, &mut m);
        assert_eq!(m.point_count, 0);
    }

    /// A tilted link straddling the plane with its face at the lip corner
    /// is pushed off that face (the pair's normal is minus the face's
    /// outward normal), by the corner's distance to the face, not along
    /// the aperture's tangent.
    #[test]
    fn lip_corner_pushes_a_tilted_copy_off_its_face() {
        let clipping = floor_with(&[0.0], 0.5);
        let clip = &clipping.clips[0];
        let tilt: Real = 0.33;
        let link = Shape::Polygon(janus2d_core::geometry::Polygon::make_box(0.05, 0.25));
        let wall = Shape::Polygon(janus2d_core::geometry::Polygon::make_box(4.0, 0.5));
        let centre = Vec2::new(0.45, 0.0);
        let shapes = PairShapes {
            shapes: [&wall, &link],
            transforms: [
                Transform::new(Vec2::new(0.0, -0.5), 0.0),
                Transform::new(centre, tilt),
            ],
            speculative: 0.04,
        };
        let m = side_wall(clip, 1, &shapes).expect("the lip touches the link");
        assert_eq!(m.point_count, 1);
        let face = Vec2::new(tilt.cos(), tilt.sin());
        assert!((m.normal + face).length() < 1e-5, "normal {}", m.normal);
        let corner = Vec2::new(0.5, 0.0);
        let expected = (corner - centre).dot(face) - 0.05;
        let got = m.points[0].separation;
        assert!(
            (got - expected).abs() < 1e-5,
            "separation {got} vs {expected}"
        );
        assert!(got < 0.0);
    }
}
