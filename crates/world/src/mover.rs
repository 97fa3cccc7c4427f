//! The character mover's geometry: collision planes, the plane solver and
//! velocity clipping, pure functions over plane lists (in the spirit of Box2D
//! 3.2's `b2SolvePlanes` and `b2ClipVector`).
//!
//! A kinematic mover (a capsule the game moves itself, not a body) moves in
//! three parts:
//!
//! 1. [`World::collide_mover`](crate::World::collide_mover) gathers a
//!    [`PlaneResult`] for every shape the mover touches or nearly touches:
//!    the obstacle's normal (towards the mover), the separation and the
//!    contact point;
//! 2. [`solve_planes`] finds the displacement closest to the one wanted that
//!    keeps the mover in front of every [`CollisionPlane`];
//! 3. [`World::cast_mover`](crate::World::cast_mover) sweeps the mover along
//!    that displacement and stops it at the first shape in the way, so that
//!    nothing is tunnelled, however fast.
//!
//! Repeat until the mover stops moving; then [`clip_vector`] removes from
//! its velocity what the planes stop. The
//! [`CharacterController`](crate::character::CharacterController) runs this
//! loop with slope limits, steps, ground snapping, one-way and moving
//! platforms.
//!
//! **A plane** is `normal · δ ≥ offset` on the mover's displacement `δ`: a
//! mover `s` in front of an obstacle (separation `s`, positive when apart)
//! that is to keep a gap `g` has `offset = g − s`.

use janus2d_constraints::portal_map::PortalMap;
use janus2d_core::body::BodyHandle;
use janus2d_core::geometry::LINEAR_SLOP;
use janus2d_core::handle::{Handle, PortalPairTag};
use janus2d_core::math::{Real, Vec2};

use crate::query::RayHit;
use crate::shapes::ShapeHandle;

/// Most Gauss–Seidel sweeps of [`solve_planes`] (a count; usual 20).
///
/// ```
/// use janus2d_world::mover::{CollisionPlane, PLANE_SOLVER_ITERATIONS, solve_planes};
/// use janus2d_core::Vec2;
/// let mut planes = [CollisionPlane::new(Vec2::Y, 0.0), CollisionPlane::new(Vec2::X, 0.0)];
/// assert!(solve_planes(Vec2::new(-1.0, -1.0), &mut planes).iterations <= PLANE_SOLVER_ITERATIONS);
/// ```
pub const PLANE_SOLVER_ITERATIONS: usize = 20;

/// [`solve_planes`] stops when a sweep pushes less than this in all, m
/// (usual 1e-5 = [`LINEAR_SLOP`] / 500).
///
/// ```
/// use janus2d_core::geometry::LINEAR_SLOP;
/// assert!(janus2d_world::mover::PLANE_SOLVER_TOLERANCE < 0.01 * LINEAR_SLOP);
/// ```
pub const PLANE_SOLVER_TOLERANCE: Real = 0.002 * LINEAR_SLOP;

/// A shape the mover touches or nearly touches, from
/// [`World::collide_mover`](crate::World::collide_mover).
///
/// ```
/// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::{Capsule, Polygon};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let wall = world.create_body(&BodyDef::fixed(Vec2::new(1.0, 0.0))).unwrap();
/// world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 2.0)).unwrap();
/// // The capsule's right side is 5 cm from the wall's face (x = 0.5).
/// let mover = Capsule::new(Vec2::new(0.2, -0.25), Vec2::new(0.2, 0.25), 0.25).unwrap();
/// let mut found = Vec::new();
/// world.collide_mover(&mover, 0.1, &QueryFilter::default(), |p| { found.push(*p); true }).unwrap();
/// assert_eq!(found[0].body, wall);
/// assert!((found[0].separation - 0.05).abs() < 1e-4 && (found[0].normal + Vec2::X).length() < 1e-4);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneResult {
    /// The shape.
    pub shape: ShapeHandle,
    /// Its body.
    pub body: BodyHandle,
    /// Unit normal of the obstacle at `point`, towards the mover.
    pub normal: Vec2,
    /// Gap between the mover's surface and the shape's, m (negative when
    /// they overlap).
    pub separation: Real,
    /// The closest point on the shape's surface, world, m.
    pub point: Vec2,
}

impl PlaneResult {
    /// The plane that keeps the mover at least `gap` (m) from this shape,
    /// with no push limit and velocity clipping on.
    ///
    /// ```
    /// use janus2d_world::mover::PlaneResult;
    /// use janus2d_world::ShapeHandle;
    /// use janus2d_core::{BodyHandle, Vec2};
    /// let r = PlaneResult {
    ///     shape: ShapeHandle::new(0, 1, 0),
    ///     body: BodyHandle::new(0, 1, 0),
    ///     normal: Vec2::Y,
    ///     separation: -0.02,
    ///     point: Vec2::ZERO,
    /// };
    /// // 2 cm into the floor, to keep 1 cm off it: move up at least 3 cm.
    /// assert!((r.plane(0.01).offset - 0.03).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn plane(&self, gap: Real) -> CollisionPlane {
        CollisionPlane::new(self.normal, gap - self.separation)
    }
}

/// One constraint of [`solve_planes`]: the displacement `δ` must satisfy
/// `normal · δ ≥ offset`, with at most `push_limit` of push along `normal`.
///
/// ```
/// use janus2d_world::mover::{CollisionPlane, solve_planes};
/// use janus2d_core::Vec2;
/// // A soft plane: it pushes at most 1 cm.
/// let mut planes = [CollisionPlane { push_limit: 0.01, ..CollisionPlane::new(Vec2::Y, 0.05) }];
/// let s = solve_planes(Vec2::ZERO, &mut planes);
/// assert!((s.translation.y - 0.01).abs() < 1e-6 && (planes[0].push - 0.01).abs() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CollisionPlane {
    /// Unit normal, pointing where the mover may go.
    pub normal: Vec2,
    /// How far along `normal` the mover must at least move, m (negative:
    /// it may come that much closer).
    pub offset: Real,
    /// Most push this plane may apply, m (usual `Real::MAX`; a small one
    /// makes a soft obstacle the mover can shove through).
    pub push_limit: Real,
    /// Whether [`clip_vector`] clips against this plane (usual true).
    pub clip_velocity: bool,
    /// Output of [`solve_planes`]: the push this plane applied, m (≥ 0).
    pub push: Real,
}

impl CollisionPlane {
    /// A plane `normal · δ ≥ offset`, no push limit, clipping on.
    ///
    /// ```
    /// use janus2d_world::mover::CollisionPlane;
    /// use janus2d_core::Vec2;
    /// let floor = CollisionPlane::new(Vec2::Y, 0.0);
    /// assert!(floor.clip_velocity && floor.push == 0.0);
    /// ```
    #[must_use]
    pub fn new(normal: Vec2, offset: Real) -> Self {
        CollisionPlane {
            normal,
            offset,
            push_limit: Real::MAX,
            clip_velocity: true,
            push: 0.0,
        }
    }
}

/// What [`solve_planes`] found.
///
/// ```
/// use janus2d_world::mover::{CollisionPlane, solve_planes};
/// use janus2d_core::Vec2;
/// // Into a floor: the downward part of the move is taken out.
/// let mut planes = [CollisionPlane::new(Vec2::Y, 0.0)];
/// let s = solve_planes(Vec2::new(1.0, -1.0), &mut planes);
/// assert!((s.translation - Vec2::new(1.0, 0.0)).length() < 1e-6);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneSolution {
    /// The displacement that satisfies the planes, m.
    pub translation: Vec2,
    /// Gauss–Seidel sweeps used (0 when solved exactly, else 1 to
    /// [`PLANE_SOLVER_ITERATIONS`]).
    pub iterations: usize,
}

/// The displacement closest to `target` that keeps in front of every plane
/// (`normal · δ ≥ offset`), each plane pushing at most its `push_limit`.
///
/// In 2D the answer is `target` itself, its projection on one plane or the
/// corner of two: when no plane has a push limit, the closest feasible one
/// of these is taken (exact, whatever the angle between the planes: a steep
/// face and a wall meeting at 30° stop the mover dead). Otherwise, or when
/// the planes leave no room at all (squeezed), projected Gauss–Seidel on
/// the accumulated pushes (each clamped to `[0, push_limit]`, so a push
/// applied too early is taken back) gives the compromise. Each plane's
/// `push` is left at the push it applied. Non-finite planes are skipped.
/// Deterministic: the planes are visited in order.
///
/// ```
/// use janus2d_world::mover::{CollisionPlane, solve_planes};
/// use janus2d_core::Vec2;
/// // A floor and a wall on the right: pushing down-right stops dead, and
/// // pushing right along the floor keeps only what the wall allows.
/// let mut planes = [CollisionPlane::new(Vec2::Y, 0.0), CollisionPlane::new(-Vec2::X, -0.1)];
/// let s = solve_planes(Vec2::new(1.0, -1.0), &mut planes);
/// assert!((s.translation - Vec2::new(0.1, 0.0)).length() < 1e-4);
/// assert!(planes[0].push > 0.99 && planes[1].push > 0.89);
/// ```
#[must_use]
pub fn solve_planes(target: Vec2, planes: &mut [CollisionPlane]) -> PlaneSolution {
    for p in planes.iter_mut() {
        p.push = 0.0;
    }
    let usable =
        |p: &CollisionPlane| p.normal.is_finite() && p.offset.is_finite() && !p.push_limit.is_nan();
    if planes
        .iter()
        .filter(|p| usable(p))
        .all(|p| p.push_limit >= Real::MAX)
        && let Some(translation) = solve_exact(target, planes, &usable)
    {
        return PlaneSolution {
            translation,
            iterations: 0,
        };
    }
    for p in planes.iter_mut() {
        p.push = 0.0;
    }
    let mut delta = target;
    let mut iterations = 0;
    for _ in 0..PLANE_SOLVER_ITERATIONS {
        iterations += 1;
        let mut total: Real = 0.0;
        for p in planes.iter_mut() {
            if !usable(p) {
                continue;
            }
            let violation = p.offset - p.normal.dot(delta);
            let before = p.push;
            p.push = (before + violation).clamp(0.0, p.push_limit.max(0.0));
            let push = p.push - before;
            delta += push * p.normal;
            total += push.abs();
        }
        if total < PLANE_SOLVER_TOLERANCE {
            break;
        }
    }
    PlaneSolution {
        translation: delta,
        iterations,
    }
}

/// A candidate answer: squared distance to the target, the displacement,
/// the active planes and their pushes.
type Candidate = (Real, Vec2, [(usize, Real); 2]);

/// The closest feasible point among `target`, its projections on single
/// planes and the corners of pairs (with the pushes that give it), or
/// `None` when none is feasible.
fn solve_exact(
    target: Vec2,
    planes: &mut [CollisionPlane],
    usable: &impl Fn(&CollisionPlane) -> bool,
) -> Option<Vec2> {
    let ok: Vec<usize> = (0..planes.len()).filter(|&i| usable(&planes[i])).collect();
    let feasible = |d: Vec2| {
        ok.iter().all(|&i| {
            let p = &planes[i];
            p.normal.dot(d) >= p.offset - PLANE_SOLVER_TOLERANCE
        })
    };
    if feasible(target) {
        return Some(target);
    }
    let mut best: Option<Candidate> = None;
    let mut consider = |d: Vec2, active: [(usize, Real); 2]| {
        let dist = (d - target).length_squared();
        if best.is_none_or(|b| dist < b.0) && feasible(d) {
            best = Some((dist, d, active));
        }
    };
    for &i in &ok {
        let p = &planes[i];
        let push = p.offset - p.normal.dot(target);
        if push > 0.0 {
            consider(target + push * p.normal, [(i, push), (i, 0.0)]);
        }
    }
    for (a, &i) in ok.iter().enumerate() {
        for &j in &ok[a + 1..] {
            let (ni, nj) = (planes[i].normal, planes[j].normal);
            let k12 = ni.dot(nj);
            let (k11, k22) = (ni.dot(ni), nj.dot(nj));
            let det = k11 * k22 - k12 * k12;
            if det.abs() <= 1e-6 * k11 * k22 {
                continue; // parallel
            }
            let bi = planes[i].offset - ni.dot(target);
            let bj = planes[j].offset - nj.dot(target);
            let pi = (k22 * bi - k12 * bj) / det;
            let pj = (k11 * bj - k12 * bi) / det;
            if pi >= 0.0 && pj >= 0.0 {
                consider(target + pi * ni + pj * nj, [(i, pi), (j, pj)]);
            }
        }
    }
    let (_, d, active) = best?;
    for (i, push) in active {
        planes[i].push += push;
    }
    Some(d)
}

/// `vector` with what points into the planes removed: for each plane with
/// `clip_velocity` set, `v ← v − min(0, v · n) n`, in order, three sweeps
/// (so that a crease of two planes stops it).
///
/// ```
/// use janus2d_world::mover::{CollisionPlane, clip_vector};
/// use janus2d_core::Vec2;
/// let floor = [CollisionPlane::new(Vec2::Y, 0.0)];
/// // Falling and running: the floor keeps the run.
/// assert_eq!(clip_vector(Vec2::new(3.0, -5.0), &floor), Vec2::new(3.0, 0.0));
/// // Jumping: nothing to clip.
/// assert_eq!(clip_vector(Vec2::new(3.0, 5.0), &floor), Vec2::new(3.0, 5.0));
/// ```
#[must_use]
pub fn clip_vector(vector: Vec2, planes: &[CollisionPlane]) -> Vec2 {
    let mut v = vector;
    for _ in 0..3 {
        let mut clipped = false;
        for p in planes {
            if !p.clip_velocity || !p.normal.is_finite() {
                continue;
            }
            let into = v.dot(p.normal);
            if into < 0.0 {
                v -= into * p.normal;
                clipped = true;
            }
        }
        if !clipped {
            break;
        }
    }
    v
}

/// How far behind a portal plane (m) the centre of a mover may be and still
/// count as in front of it (usual 5e-6 = [`LINEAR_SLOP`] / 100): a mover
/// that has just come out lies on the exit plane up to rounding.
///
/// ```
/// use janus2d_core::geometry::LINEAR_SLOP;
/// assert!(janus2d_world::mover::MOVER_PLANE_TOLERANCE < LINEAR_SLOP);
/// ```
pub const MOVER_PLANE_TOLERANCE: Real = 0.01 * LINEAR_SLOP;

/// A portal aperture a mover's centre goes through, from
/// [`World::mover_crossing`](crate::World::mover_crossing) (and in
/// [`MoveResult::crossings`](crate::character::MoveResult::crossings)).
///
/// The mover comes out of the partner portal: its centre at
/// `map.map_point(point)`, its size times `map.eta`, its velocity relative
/// to the portals mapped by `η Q` ([`PortalMap::map_vector`]).
///
/// ```
/// use janus2d_world::mover::MoverCrossing;
/// use janus2d_constraints::portal_map::{PortalFrame, PortalMap};
/// use janus2d_core::{BodyHandle, Vec2};
/// use janus2d_core::handle::Handle;
/// // A floor portal at the origin, its partner on a wall at x = 10 facing +x, η = 2.
/// let map = PortalMap::new(
///     PortalFrame::from_point_normal(Vec2::ZERO, Vec2::Y),
///     PortalFrame::from_point_normal(Vec2::new(10.0, 0.0), Vec2::X),
///     2.0,
/// ).unwrap();
/// let c = MoverCrossing {
///     pair: Handle::new(0, 1, 0),
///     entered: 0,
///     fraction: 0.5,
///     point: Vec2::ZERO,
///     map,
///     bodies: [BodyHandle::new(0, 1, 0), BodyHandle::new(1, 1, 0)],
/// };
/// // Falling at 3 m/s, it leaves the wall at 6 m/s.
/// assert!((c.map.map_vector(Vec2::new(0.0, -3.0)) - Vec2::new(6.0, 0.0)).length() < 1e-5);
/// assert_eq!(c.exit_point(), Vec2::new(10.0, 0.0));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoverCrossing {
    /// The portal pair.
    pub pair: Handle<PortalPairTag>,
    /// The side entered: 0 for portal a, 1 for portal b.
    pub entered: usize,
    /// Fraction of the translation at which the centre meets the aperture,
    /// in `[0, 1]`.
    pub fraction: Real,
    /// Where the centre meets the entered aperture, world, m.
    pub point: Vec2,
    /// The map from the entered portal to its partner.
    pub map: PortalMap,
    /// The bodies that carry the entered portal and its partner.
    pub bodies: [BodyHandle; 2],
}

impl MoverCrossing {
    /// Where the centre comes out of the partner portal, world, m.
    #[must_use]
    pub fn exit_point(&self) -> Vec2 {
        self.map.map_point(self.point)
    }
}

/// Where a mover cast stopped, from
/// [`World::cast_mover`](crate::World::cast_mover).
///
/// ```
/// use janus2d_world::{World, WorldDef, QueryFilter};
/// use janus2d_core::Vec2;
/// use janus2d_core::geometry::Capsule;
/// let world = World::new(WorldDef::default()).unwrap();
/// let mover = Capsule::new(Vec2::ZERO, Vec2::Y, 0.25).unwrap();
/// let cast = world.cast_mover(&mover, Vec2::new(5.0, 0.0), &QueryFilter::default()).unwrap();
/// assert_eq!((cast.fraction, cast.hit), (1.0, None), "nothing in the way");
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoverCast {
    /// Fraction of the translation the mover can travel, in `[0, 1]` (1:
    /// nothing in the way).
    pub fraction: Real,
    /// The shape that stopped it: point and normal on that shape's surface
    /// (`portal_hops` 1 when it was met through an aperture: the point and
    /// normal are then mapped back to the mover's side).
    pub hit: Option<RayHit>,
}

/// The vertical part of `v` along `up` removed: what lies in the ground
/// plane of a world whose up is `up` (unit).
///
/// ```
/// use janus2d_world::mover::lateral;
/// use janus2d_core::Vec2;
/// assert_eq!(lateral(Vec2::new(2.0, -3.0), Vec2::Y), Vec2::new(2.0, 0.0));
/// ```
#[must_use]
pub fn lateral(v: Vec2, up: Vec2) -> Vec2 {
    v - v.dot(up) * up
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_plane_is_an_exact_projection() {
        let n = Vec2::new(-0.5, (0.75 as Real).sqrt());
        let mut p = [CollisionPlane::new(n, 0.0)];
        let s = solve_planes(Vec2::new(1.0, 0.0), &mut p);
        assert!(s.translation.dot(n).abs() < 1e-5);
        assert!((s.translation - Vec2::new(0.75, 0.433_012_7)).length() < 1e-5);
        assert!((p[0].push - 0.5).abs() < 1e-5);
    }

    #[test]
    fn a_plane_not_violated_pushes_nothing() {
        let mut p = [CollisionPlane::new(Vec2::Y, -0.2)];
        let s = solve_planes(Vec2::new(0.0, -0.1), &mut p);
        assert_eq!(s.translation, Vec2::new(0.0, -0.1));
        assert_eq!((p[0].push, s.iterations), (0.0, 0));
    }

    #[test]
    fn push_limit_caps_the_push() {
        let mut p = [CollisionPlane {
            push_limit: 0.1,
            ..CollisionPlane::new(Vec2::Y, 0.5)
        }];
        let s = solve_planes(Vec2::ZERO, &mut p);
        assert!((s.translation.y - 0.1).abs() < 1e-6);
    }

    #[test]
    fn a_v_crease_stops_the_mover() {
        let a = Vec2::new(1.0, 1.0).normalize();
        let b = Vec2::new(-1.0, 1.0).normalize();
        let mut p = [CollisionPlane::new(a, 0.0), CollisionPlane::new(b, 0.0)];
        let s = solve_planes(Vec2::new(0.3, -1.0), &mut p);
        assert!(s.translation.length() < 1e-4, "{s:?}");
        let v = clip_vector(Vec2::new(0.3, -1.0), &p);
        assert!(v.dot(a) >= -1e-6 && v.dot(b) >= -1e-6, "{v:?}");
    }

    #[test]
    fn a_steep_face_and_its_wall_stop_the_mover_exactly() {
        // The creep that Gauss–Seidel leaves between planes 30° apart.
        let steep = Vec2::new(-(0.75 as Real).sqrt(), 0.5);
        let mut p = [
            CollisionPlane::new(steep, 0.0),
            CollisionPlane::new(-Vec2::X, 0.0),
        ];
        let s = solve_planes(Vec2::new(0.033, 0.0), &mut p);
        assert!(s.translation.length() < 1e-7, "{s:?}");
        // With a push limit the iterative path is taken, and creeps.
        p[0].push_limit = 10.0;
        let s = solve_planes(Vec2::new(0.033, 0.0), &mut p);
        assert_eq!(s.iterations, PLANE_SOLVER_ITERATIONS);
    }

    #[test]
    fn nan_planes_are_skipped() {
        let mut p = [
            CollisionPlane::new(Vec2::new(Real::NAN, 0.0), 0.0),
            CollisionPlane::new(Vec2::Y, 0.0),
        ];
        let s = solve_planes(Vec2::new(1.0, -1.0), &mut p);
        assert!((s.translation - Vec2::new(1.0, 0.0)).length() < 1e-6);
    }
}
