//! Continuous collision: fast bodies are swept over the step and moved back
//! to their first time of impact, so they cannot pass through thin
//! geometry (as Box2D v3's `b2SolveContinuous`).
//!
//! ```text
//! in the solve's finalize (each pose written): maybe_fast, a bound of the
//!   fast test below from the body's kept extents (BodySim::fast_travel,
//!   core_reach); no body near its limit: the stage does nothing
//! after the solve's finalize (start and end poses known), before proxies move:
//!   fast test  (every awake dynamic body with a solid shape)
//!     travel = |Δc| + |Δq| · (core_reach + |local centre|)
//!     fast when travel > max(½ · min_extent, LINEAR_SLOP)
//!   sweep      (each fast body; bullets after the others)
//!     per solid shape: broadphase box query over its start ∪ end box
//!       static tree (every fast body), dynamic tree (bullets: non-bullet bodies)
//!       skip: same body, sensors, filtered, joints without collide_connected,
//!             a one-sided chain segment unless the shape's centroid crosses
//!             it from its front
//!       time_of_impact (janus2d-core); a touch at fraction 0 retries with a
//!             small disc at the shape's centroid (Box2D's fallback); the
//!             centroid never crosses a one-sided chain segment (one that
//!             starts on its line, pressed into it, is held where it started)
//!       portals: a hit inside an aperture's hole is no hit
//!     portals: a centre that crosses an aperture from its front stops just
//!       behind the aperture plane, so the crossing stage sees it straddle
//!   move back  (first fraction t < 1): pose at t; velocity kept, so the
//!     next step's speculative contact stops the body; a jointed body
//!     moves back with every moving body its enabled joints reach, and a
//!     crossing copy with its twin, all to the group's smallest t
//!   close the joints (a group of more than one body): each revolute and
//!     weld point, opened by the move (below), is closed again
//! ```
//!
//! ## Closing the joints
//!
//! Each body moves back along its own sweep: its centre on the chord,
//! its angle interpolated. A link that turns fast about a hinge moves its
//! centre on an arc, so at a fraction between the ends its hinge points
//! part by about the arc's sagitta, `r Δθ² / 8` (a link of a landing rope
//! turning 1–2 rad in a step: centimetres). After the move, each revolute
//! or weld joint `j` of the group has the separation of its world anchors
//! `C = (c_b + r_b) − (c_a + r_a) − d`, with the target `d` zero for a
//! hinge and, for a weld (its point may be soft), the separation at the
//! step's start and end interpolated to the fraction. [`CLOSING_PASSES`]
//! Gauss–Seidel passes over the group's joints (slot order) each apply
//! the position impulse `P = −K⁻¹ C`,
//!
//! ```text
//!   K = (m_a⁻¹ + m_b⁻¹) 1 + I_a⁻¹ perp(r_a) perp(r_a)ᵀ + I_b⁻¹ perp(r_b) perp(r_b)ᵀ
//!   c_b += m_b⁻¹ P    θ_b += I_b⁻¹ (r_b × P)      (a: the same with −P)
//! ```
//!
//! which closes `C` to first order. The body that hit (and its twin) does
//! not move: it touches what it hit. A crossing copy's shift `(Δc, Δθ)`
//! is carried to its twin through the map (`x₂ = T(x₁)` moves by
//! `η Q Δc`, `θ₂ = θ₁ + const` by `Δθ`), so the portal rows stay as they
//! were. Velocities are not touched: the closing adds no speed.
//!
//! A scene where nothing is fast pays a few multiplications per body in
//! the finalize pass that already writes every pose, and nothing here:
//! [`ContinuousCounters::toi_bodies`] stays 0. The bodies' copies of their
//! extents are refreshed at the step's start for the bodies whose shapes
//! changed ([`publish_extents`]).

use janus2d_core::body::{BodyLocation, BodySet, BodyType};
use janus2d_core::geometry::{
    LINEAR_SLOP, Shape, ShapeProxy, Sweep, ToiState, shape_distance, shape_extent, time_of_impact,
};
use janus2d_core::math::{Real, Rot, Transform, Vec2, cross};
use janus2d_core::parallel::Team;

use crate::aperture::ContactClipping;
use crate::broadphase::BroadPhase;
use crate::joints::{JointSet, NoCollide};
use crate::shapes::{FAST_FRACTION, ShapeStore};
use janus2d_constraints::JointKind;

/// Work of the last continuous pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ContinuousCounters {
    /// Fast bodies swept (bullets included).
    pub toi_bodies: usize,
    /// Time-of-impact searches run.
    pub toi_calls: usize,
    /// Bodies moved back to a time of impact.
    pub toi_hits: usize,
}

/// What the continuous stage reads besides the bodies.
pub(crate) struct ContinuousInput<'a> {
    pub(crate) shapes: &'a ShapeStore,
    pub(crate) broadphase: &'a BroadPhase,
    pub(crate) no_collide: &'a NoCollide,
    /// The portal stage's aperture clipping (empty without portals).
    pub(crate) clipping: &'a ContactClipping,
    /// The joints: a jointed body is moved back with the bodies its
    /// enabled joints join it to, and its joints closed after.
    pub(crate) joints: &'a JointSet,
    /// The portal rows (one per crossing): a crossing copy's twin moves
    /// with it.
    pub(crate) portal_rows: &'a [janus2d_constraints::PortalConstraint],
    /// The solve's finalize found a body that may be fast
    /// (`SolveReport::maybe_fast`); false: the stage scans nothing.
    pub(crate) maybe_fast: bool,
}

/// Copies the extents of the bodies whose shapes changed into their
/// per-step data (`BodySim::fast_travel`, `BodySim::core_reach`), where
/// the solver's finalize reads them. The step calls it before the solve.
pub(crate) fn publish_extents(shapes: &mut ShapeStore, bodies: &mut BodySet) {
    for body in shapes.take_extent_changes() {
        let e = shapes.extent_of(body);
        if let Some(sim) = bodies.sim_mut(body) {
            sim.fast_travel = e.fast_travel();
            sim.core_reach = e.core_reach;
        }
    }
}

/// The continuous stage: the switch, its scratch lists and its counters.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct ContinuousStage {
    pub(crate) enabled: bool,
    counters: ContinuousCounters,
    fast: Vec<u32>,
    bullets: Vec<u32>,
    candidates: Vec<u32>,
    /// Scratch of the joint groups' move back: the group, a mark per
    /// moving body, and each hit body's fraction.
    #[cfg_attr(feature = "serde", serde(skip))]
    group: Vec<u32>,
    #[cfg_attr(feature = "serde", serde(skip))]
    moved: Vec<bool>,
    #[cfg_attr(feature = "serde", serde(skip))]
    fractions: Vec<Real>,
    /// Scratch of the joint closing: the group's revolute and weld joints
    /// (slot index, handle) and each one's target separation.
    #[cfg_attr(feature = "serde", serde(skip))]
    closing: Vec<(u32, crate::joints::JointHandle)>,
    #[cfg_attr(feature = "serde", serde(skip))]
    targets: Vec<Vec2>,
    /// Scratch of the joint closing: the group's crossings (original's
    /// slot, clone's slot, the map's rotation Q and scale η).
    #[cfg_attr(feature = "serde", serde(skip))]
    twin_maps: Vec<(usize, usize, Rot, Real)>,
}

/// How far behind a one-sided chain segment's line a fast shape's centroid
/// may start and still be held in front, as a fraction of its smallest
/// extent (dimensionless; 0.25).
pub const HUG_FRACTION: Real = 0.25;

impl ContinuousStage {
    /// A stage, on or off.
    pub(crate) fn new(enabled: bool) -> Self {
        ContinuousStage {
            enabled,
            counters: ContinuousCounters::default(),
            fast: Vec::new(),
            bullets: Vec::new(),
            candidates: Vec::new(),
            group: Vec::new(),
            moved: Vec::new(),
            fractions: Vec::new(),
            closing: Vec::new(),
            targets: Vec::new(),
            twin_maps: Vec::new(),
        }
    }

    /// The counters of the last pass.
    pub(crate) fn counters(&self) -> ContinuousCounters {
        self.counters
    }

    /// Sweeps the fast bodies and moves those that hit something back to
    /// their time of impact.
    pub(crate) fn run(&mut self, bodies: &mut BodySet, input: &ContinuousInput<'_>, team: &Team) {
        self.counters = ContinuousCounters::default();
        self.fast.clear();
        self.bullets.clear();
        if !self.enabled || !input.maybe_fast {
            // Off, or the solve's finalize saw no body travel near its
            // limit: nothing to scan.
            return;
        }
        for (i, sim) in bodies.sims.iter().enumerate().skip(1) {
            if sim.body_type != BodyType::Dynamic {
                continue;
            }
            if !sim.is_fast() {
                continue;
            }
            if sim.bullet {
                self.bullets.push(i as u32);
            } else {
                self.fast.push(i as u32);
            }
        }
        self.counters.toi_bodies = self.fast.len() + self.bullets.len();
        if self.counters.toi_bodies == 0 {
            // Nothing fast: no per-body scratch to fill.
            return;
        }
        let fast = std::mem::take(&mut self.fast);
        // Fast bodies that are not bullets sweep against static shapes
        // only, so no one's sweep reads another's move: with threads their
        // impacts are found at once and applied after, in the same order.
        if team.threads() > 1 && fast.len() >= PARALLEL_FAST {
            const BLOCK: usize = 8;
            let read = &*bodies;
            let impacts: Vec<Vec<(Real, usize)>> =
                team.map_blocks(fast.len().div_ceil(BLOCK), |b| {
                    let mut candidates = Vec::new();
                    fast[b * BLOCK..(b * BLOCK + BLOCK).min(fast.len())]
                        .iter()
                        .map(|&i| {
                            let mut calls = 0;
                            let fraction = impact_of(
                                read,
                                i as usize,
                                input,
                                false,
                                &mut candidates,
                                &mut calls,
                            );
                            (fraction, calls)
                        })
                        .collect()
                });
            self.fractions.clear();
            self.fractions.resize(bodies.sims.len(), 1.0);
            for (&i, &(fraction, calls)) in fast.iter().zip(impacts.iter().flatten()) {
                self.counters.toi_calls += calls;
                self.fractions[i as usize] = fraction;
            }
        } else {
            // Against static shapes only: no sweep reads another's move, so
            // every impact is found before any body moves, as on threads.
            self.fractions.clear();
            self.fractions.resize(bodies.sims.len(), 1.0);
            for &i in &fast {
                self.fractions[i as usize] = impact_of(
                    bodies,
                    i as usize,
                    input,
                    false,
                    &mut self.candidates,
                    &mut self.counters.toi_calls,
                );
            }
        }
        self.moved.clear();
        self.moved.resize(bodies.sims.len(), false);
        for &i in &fast {
            self.move_back(i as usize, bodies, input);
        }
        self.fast = fast;
        let bullets = std::mem::take(&mut self.bullets);
        for &i in &bullets {
            if self.moved[i as usize] {
                continue; // moved back with a jointed body already
            }
            let fraction = impact_of(
                bodies,
                i as usize,
                input,
                true,
                &mut self.candidates,
                &mut self.counters.toi_calls,
            );
            self.fractions[i as usize] = fraction;
            self.move_back(i as usize, bodies, input);
        }
        self.bullets = bullets;
    }

    /// Moves body `i` back to its fraction of the step's sweep (nothing
    /// at 1), and with it every moving body its enabled joints join it to
    /// and every crossing copy's twin, directly or through others, all to
    /// the smallest fraction among them: a jointed body rewound alone
    /// would open its joints by what its neighbours travelled after the
    /// impact (a link landing at 30 m/s, 50 cm a step), a copy rewound
    /// without its twin its portal rows. Then closes the group's joints
    /// (module docs). Each body moves once per pass.
    fn move_back(&mut self, i: usize, bodies: &mut BodySet, input: &ContinuousInput<'_>) {
        let joints = input.joints;
        let twins = &input.clipping.ignored_pairs;
        if self.moved[i] || self.fractions[i] >= 1.0 {
            return;
        }
        self.group.clear();
        self.group.push(i as u32);
        self.moved[i] = true;
        let mut fraction = self.fractions[i];
        // The body at the group's fraction: it touches what it hit there.
        let mut hit = i;
        let mut next = 0;
        while next < self.group.len() && !(joints.is_empty() && twins.is_empty()) {
            let handle = bodies.sims[self.group[next] as usize].handle;
            next += 1;
            let joined = joints.of_body(handle).iter().filter_map(|&jh| {
                let joint = joints.get(jh).ok()?;
                if !joint.is_enabled() {
                    return None;
                }
                joint.other_body(handle)
            });
            let twinned = twins.iter().filter_map(|&(x, y)| {
                if x == handle {
                    Some(y)
                } else if y == handle {
                    Some(x)
                } else {
                    None
                }
            });
            for other in joined.chain(twinned) {
                let Some(BodyLocation::Moving(k)) = bodies.location(other) else {
                    continue;
                };
                let k = k as usize;
                if self.moved[k] || bodies.sims[k].body_type != BodyType::Dynamic {
                    continue;
                }
                self.moved[k] = true;
                if self.fractions[k] < fraction {
                    fraction = self.fractions[k];
                    hit = k;
                }
                self.group.push(k as u32);
            }
        }
        let close = self.group.len() > 1 && self.gather_joints(fraction, bodies, input);
        for &k in &self.group {
            let sweep = sweep_of(bodies, k as usize);
            let sim = &mut bodies.sims[k as usize];
            sim.transform = sweep.transform_at(fraction);
            sim.center = sweep.center_at(fraction);
            self.counters.toi_hits += 1;
        }
        if close {
            self.close_joints(hit, bodies, input);
        }
    }

    /// Lists the revolute and weld joints of the group about to move back
    /// to `fraction`, each with its target separation of the two anchors:
    /// zero for a hinge, a weld's start and end values interpolated to the
    /// fraction (what the solve left, carried back). False when there are
    /// none.
    fn gather_joints(
        &mut self,
        fraction: Real,
        bodies: &BodySet,
        input: &ContinuousInput<'_>,
    ) -> bool {
        let joints = input.joints;
        self.closing.clear();
        for &k in &self.group {
            let handle = bodies.sims[k as usize].handle;
            for &jh in joints.of_body(handle) {
                let Ok(joint) = joints.get(jh) else { continue };
                if joint.is_enabled()
                    && matches!(joint.kind(), JointKind::Revolute | JointKind::Weld)
                {
                    self.closing.push((jh.index, jh));
                }
            }
        }
        // Each joint once, in slot order (the walk meets most twice).
        self.closing.sort_unstable_by_key(|&(index, _)| index);
        self.closing.dedup_by_key(|&mut (index, _)| index);
        self.targets.clear();
        for &(_, jh) in &self.closing {
            let Ok(joint) = joints.get(jh) else { continue };
            let (a, b) = joint.bodies();
            let (la, lb) = joint.local_anchors();
            let at = |body, local, t: Real| match bodies.location(body) {
                Some(BodyLocation::Moving(k)) => {
                    sweep_of(bodies, k as usize).transform_at(t).apply(local)
                }
                _ => bodies.solver_body(body).sim.transform.apply(local),
            };
            // As the solve left it, carried back.
            let d0 = at(b, lb, 0.0) - at(a, la, 0.0);
            let d1 = at(b, lb, 1.0) - at(a, la, 1.0);
            let left = d0 + fraction * (d1 - d0);
            if joint.kind() != JointKind::Revolute {
                // A weld's point may be soft (its linear spring).
                self.targets.push(left);
                continue;
            }
            // A hinge's point is rigid: closed, by no more than the
            // distance a body may travel unswept in a step (a joint made
            // far from satisfied is left to the solve's capped correction).
            let reach = FAST_FRACTION
                * input
                    .shapes
                    .extent_of(a)
                    .min_extent
                    .min(input.shapes.extent_of(b).min_extent);
            let open = left.length();
            self.targets.push(if open <= reach {
                Vec2::ZERO
            } else {
                left * (1.0 - reach / open)
            });
        }
        !self.closing.is_empty()
    }

    /// Closes the joints [`Self::gather_joints`] listed, now that their
    /// group has moved back (module docs, "closing the joints"): each
    /// point is brought to its target separation by [`CLOSING_PASSES`]
    /// Gauss–Seidel position passes. The body that hit (`hit`, and its
    /// twin when it is a crossing copy) does not move; a crossing copy's
    /// correction is carried to its twin through the portal map.
    fn close_joints(&mut self, hit: usize, bodies: &mut BodySet, input: &ContinuousInput<'_>) {
        let joints = input.joints;
        // The group's crossings: (original, clone, Q, η), slots in `sims`.
        self.twin_maps.clear();
        for pc in input.portal_rows {
            let d = pc.def();
            let (Some(BodyLocation::Moving(k1)), Some(BodyLocation::Moving(k2))) =
                (bodies.location(d.body), bodies.location(d.clone))
            else {
                continue;
            };
            let map = pc.map(bodies);
            self.twin_maps
                .push((k1 as usize, k2 as usize, map.rotation(), map.eta));
        }
        let twin_maps = &self.twin_maps;
        let twin_of = |k: usize| {
            twin_maps.iter().find_map(|&(k1, k2, q, eta)| {
                if k1 == k {
                    Some((k2, q, eta))
                } else if k2 == k {
                    // The inverse map: Q⁻¹ and 1/η.
                    Some((k1, Rot { c: q.c, s: -q.s }, 1.0 / eta))
                } else {
                    None
                }
            })
        };
        let pinned = twin_of(hit).map(|(t, _, _)| t);
        // A body the pass may move: a moving dynamic body of the group
        // (every such joint partner is in it), neither the one that hit
        // nor its twin.
        let movable = |bodies: &BodySet, handle: janus2d_core::body::BodyHandle| -> Option<usize> {
            let Some(BodyLocation::Moving(k)) = bodies.location(handle) else {
                return None;
            };
            let k = k as usize;
            (k != hit && Some(k) != pinned && bodies.sims[k].body_type == BodyType::Dynamic)
                .then_some(k)
        };
        // Moves body k by (Δc, Δθ) about its centre.
        let shift = |bodies: &mut BodySet, k: usize, dc: Vec2, da: Real| {
            let sim = &mut bodies.sims[k];
            sim.center += dc;
            let q = sim.transform.q.integrate(da);
            sim.transform = Transform {
                p: sim.center - q.rotate(sim.local_center),
                q,
            };
        };
        for _ in 0..CLOSING_PASSES {
            for (n, &(_, jh)) in self.closing.iter().enumerate() {
                let Ok(joint) = joints.get(jh) else { continue };
                let (a, b) = joint.bodies();
                let (la, lb) = joint.local_anchors();
                let (ka, kb) = (movable(bodies, a), movable(bodies, b));
                if ka.is_none() && kb.is_none() {
                    continue;
                }
                let arm = |k: Option<usize>, body, local: Vec2| -> (Vec2, Vec2, Real, Real) {
                    let sim = match k {
                        Some(k) => &bodies.sims[k],
                        None => bodies.solver_body(body).sim,
                    };
                    let r = sim.transform.q.rotate(local - sim.local_center);
                    let (im, ii) = if k.is_some() {
                        (sim.inv_mass, sim.inv_inertia)
                    } else {
                        (0.0, 0.0)
                    };
                    (sim.center, r, im, ii)
                };
                let (ca, ra, ma, ia) = arm(ka, a, la);
                let (cb, rb, mb, ib) = arm(kb, b, lb);
                let c = (cb + rb) - (ca + ra) - self.targets[n];
                // K = (ma + mb) 1 + ia perp(ra) perp(ra)ᵀ + ib perp(rb) perp(rb)ᵀ
                let k11 = ma + mb + ia * ra.y * ra.y + ib * rb.y * rb.y;
                let k12 = -ia * ra.x * ra.y - ib * rb.x * rb.y;
                let k22 = ma + mb + ia * ra.x * ra.x + ib * rb.x * rb.x;
                let det = k11 * k22 - k12 * k12;
                if det <= Real::EPSILON * (k11 * k22).max(Real::MIN_POSITIVE) {
                    continue;
                }
                // P = −K⁻¹ C: b moves by +P, a by −P.
                let p = Vec2::new(
                    -(k22 * c.x - k12 * c.y) / det,
                    -(k11 * c.y - k12 * c.x) / det,
                );
                for (k, sign, r, m, i) in [(ka, -1.0, ra, ma, ia), (kb, 1.0, rb, mb, ib)] {
                    let Some(k) = k else { continue };
                    let (dc, da) = (sign * m * p, sign * i * cross(r, p));
                    shift(bodies, k, dc, da);
                    // The twin follows through the map: x₂ = T(x₁) moves
                    // by η Q Δx₁, θ₂ = θ₁ + const by Δθ₁.
                    if let Some((t, q, eta)) = twin_of(k) {
                        shift(bodies, t, eta * q.rotate(dc), da);
                    }
                }
            }
        }
    }
}

/// Gauss–Seidel passes that close a moved-back group's joints (8: a
/// 20-link rope's hinges end within 1 mm, where 4 passes leave 2 mm).
pub const CLOSING_PASSES: usize = 8;

/// Fast bodies from which the non-bullet sweeps run on threads.
const PARALLEL_FAST: usize = 32;

/// Body `i`'s sweep over the step (start pose to the solve's end pose).
fn sweep_of(bodies: &BodySet, i: usize) -> Sweep {
    let sim = &bodies.sims[i];
    Sweep::between(
        sim.local_center,
        sim.center0,
        sim.rotation0,
        sim.center,
        sim.transform.q,
    )
}

/// [`first_impact`] of body `i`'s sweep over the step.
fn impact_of(
    bodies: &BodySet,
    i: usize,
    input: &ContinuousInput<'_>,
    bullet: bool,
    candidates: &mut Vec<u32>,
    toi_calls: &mut usize,
) -> Real {
    let sweep = sweep_of(bodies, i);
    let handle = bodies.sims[i].handle;
    first_impact(handle, &sweep, bodies, input, bullet, candidates, toi_calls)
}

/// The first fraction of the step at which the body's sweep meets what it
/// may not pass (1: nothing); `candidates` is scratch, `toi_calls` counts
/// the time-of-impact searches.
fn first_impact(
    body: janus2d_core::body::BodyHandle,
    sweep: &Sweep,
    bodies: &BodySet,
    input: &ContinuousInput<'_>,
    bullet: bool,
    candidates: &mut Vec<u32>,
    toi_calls: &mut usize,
) -> Real {
    let shapes = input.shapes;
    let bp = input.broadphase;
    let xf1 = sweep.transform_at(0.0);
    let xf2 = sweep.transform_at(1.0);
    let mut best: Real = 1.0;
    for &s in shapes.of_body(body) {
        let fast_shape = shapes.at(s);
        if fast_shape.def.is_sensor {
            continue;
        }
        let geometry = &fast_shape.geometry;
        let proxy = ShapeProxy::from_shape(geometry);
        let swept = geometry
            .compute_aabb(&xf1)
            .union(&geometry.compute_aabb(&xf2));
        let centroid = geometry.centroid();
        let (c1, c2) = (xf1.apply(centroid), xf2.apply(centroid));
        // Read only against a chain segment or at a touch at the start.
        let shape_min = || shape_extent(geometry, centroid).min_extent;
        candidates.clear();
        bp.static_tree().query(&swept, |proxy| {
            candidates.push(bp.payload(proxy));
            true
        });
        if bullet {
            bp.dynamic_tree().query(&swept, |proxy| {
                candidates.push(bp.payload(proxy));
                true
            });
        }
        // Tree order depends on history; the answer must not.
        candidates.sort_unstable();
        candidates.dedup();
        for &other_slot in candidates.iter() {
            let other = shapes.at(other_slot);
            if other.body == body
                || other.def.is_sensor
                || !fast_shape.def.filter.should_collide(&other.def.filter)
                || input.no_collide.contains(body, other.body)
                || input.clipping.ignores(body, other.body)
            {
                continue;
            }
            let Some(other_sim) = bodies.sim(other.body) else {
                continue;
            };
            let other_sweep = if other_sim.body_type == BodyType::Static {
                Sweep::stationary(&other_sim.transform)
            } else {
                if other_sim.bullet {
                    continue; // bullets do not sweep against bullets
                }
                match bodies.location(other.body) {
                    Some(BodyLocation::Moving(_)) => Sweep::between(
                        other_sim.local_center,
                        other_sim.center0,
                        other_sim.rotation0,
                        other_sim.center,
                        other_sim.transform.q,
                    ),
                    _ => Sweep::stationary(&other_sim.transform),
                }
            };
            // One-sided chain segments: only a centroid that goes from
            // the front to behind the segment's line is stopped, and it
            // never crosses the segment itself (a shape pressed deep into
            // the chain, where the time of impact sees an overlap, would
            // escape once its centre is behind).
            let mut chain_fraction: Real = 1.0;
            if let Shape::ChainSegment(chain) = &other.geometry {
                let xf = other_sim.transform;
                let p1 = xf.apply(chain.segment.point1);
                let p2 = xf.apply(chain.segment.point2);
                let n = xf.q.rotate(chain.normal());
                let (o1, o2) = ((c1 - p1).dot(n), (c2 - p1).dot(n));
                if o2 > 0.0 || o1 == o2 || o1 < -HUG_FRACTION * shape_min() {
                    continue; // ends in front, or started well behind
                }
                let e = p2 - p1;
                let slack = LINEAR_SLOP / e.length();
                let within = |x: Vec2| {
                    let along = (x - p1).dot(e) / e.length_squared();
                    (-slack..=1.0 + slack).contains(&along)
                };
                // Where the centroid's path meets the line (its start
                // when it starts behind).
                let crossing = if o1 > 0.0 {
                    c1 + (o1 / (o1 - o2)) * (c2 - c1)
                } else {
                    c1
                };
                if within(crossing) || (o1 <= 0.0 && within(c2)) {
                    chain_fraction = if o1 <= LINEAR_SLOP {
                        // Hugging the chain (pressed into it, up to a
                        // fraction of its extent behind): held where it
                        // started rather than let out.
                        0.0
                    } else {
                        (o1 - LINEAR_SLOP) / (o1 - o2)
                    };
                }
            }
            let other_proxy = ShapeProxy::from_shape(&other.geometry);
            *toi_calls += 1;
            let out = time_of_impact(&other_proxy, &other_sweep, &proxy, sweep, best);
            let usable = |state: ToiState| matches!(state, ToiState::Hit | ToiState::Failed);
            let mut hit = None;
            if out.fraction > 0.0 && out.fraction < best && usable(out.state) {
                hit = Some((out.fraction, proxy));
            } else if out.fraction == 0.0 && out.state != ToiState::Separated {
                // Touching at the start: a small disc at the centroid
                // still must not pass (Box2D's fallback).
                let mut small = ShapeProxy::point(centroid);
                small.radius = 0.25 * shape_min();
                *toi_calls += 1;
                let out = time_of_impact(&other_proxy, &other_sweep, &small, sweep, best);
                if out.fraction > 0.0 && out.fraction < best && usable(out.state) {
                    hit = Some((out.fraction, small));
                }
            }
            if chain_fraction < best && hit.is_none_or(|(f, _)| chain_fraction < f) {
                let mut centre = ShapeProxy::point(centroid);
                centre.radius = 0.0;
                hit = Some((chain_fraction, centre));
            }
            let Some((fraction, hit_proxy)) = hit else {
                continue;
            };
            if !input.clipping.clips.is_empty() {
                // A hit inside an aperture's hole is no hit: the body
                // goes through the portal instead.
                let d = shape_distance(
                    &other_proxy,
                    &other_sweep.transform_at(fraction),
                    &hit_proxy,
                    &sweep.transform_at(fraction),
                );
                if input.clipping.in_hole_for(other.body, body, d.point_a) {
                    continue;
                }
            }
            best = fraction;
        }
    }
    best.min(aperture_fraction(body, sweep, input.clipping))
}

/// The fraction at which the body's centre, crossing a portal aperture from
/// its front within its span, is a linear slop behind it (1: none). A body already crossing is left to
/// the portal stage.
fn aperture_fraction(
    body: janus2d_core::body::BodyHandle,
    sweep: &Sweep,
    clipping: &ContactClipping,
) -> Real {
    let mut best: Real = 1.0;
    if clipping.clips.iter().any(|c| !c.hole && c.body == body) {
        return best;
    }
    for clip in clipping.clips.iter().filter(|c| c.hole && c.body != body) {
        let s0 = (sweep.c1 - clip.point).dot(clip.normal);
        let s1 = (sweep.c2 - clip.point).dot(clip.normal);
        // Stopped a linear slop behind the plane, so that the crossing
        // stage sees the centre swept through (never frozen on the plane).
        if s0 > 0.0 && s1 < -LINEAR_SLOP {
            let u = (s0 + LINEAR_SLOP) / (s0 - s1);
            let x = sweep.center_at(u);
            if cross(clip.normal, x - clip.point).abs() < clip.half_width && u < best {
                best = u;
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::BodyExtent;
    use janus2d_core::body::{BodyDef, BodySet, BodySim};
    use proptest::prelude::*;

    /// A body moved by `(dx, dy, dθ)` from a start pose, with shapes of
    /// these extents, its local centre at `(lx, ly)`.
    fn moved(extent: BodyExtent, motion: [Real; 3], local_center: Vec2) -> BodySim {
        let mut bodies = BodySet::new();
        let h = bodies
            .create(&BodyDef::dynamic(Vec2::new(1.0, 2.0)))
            .unwrap();
        let mut sim = *bodies.sim(h).unwrap();
        sim.local_center = local_center;
        sim.center0 = Vec2::new(1.0, 2.0);
        sim.rotation0 = Rot::from_angle(0.3);
        sim.center = sim.center0 + Vec2::new(motion[0], motion[1]);
        sim.transform.q = Rot::from_angle(0.3 + motion[2]);
        sim.fast_travel = extent.fast_travel();
        sim.core_reach = extent.core_reach;
        sim
    }

    proptest! {
        #![proptest_config(ProptestConfig {
            cases: 2000,
            // A fixed set of cases unless PROPTEST_RNG_SEED asks for another.
            rng_seed: crate::test_support::fixed_unless_asked(
                ProptestConfig::default().rng_seed,
                0x6a61_6e75_7332_6463,
            ),
            ..ProptestConfig::default()
        })]

        /// The solve's bound never misses a body the exact test calls
        /// fast: when it says no body may be fast, skipping the scan
        /// changes nothing.
        #[test]
        fn the_finalize_bound_holds_every_fast_body(
            min_extent in 1.0e-3f64..10.0,
            reach_over in 0.0f64..5.0,
            dx in -20.0f64..20.0,
            dy in -20.0f64..20.0,
            dtheta in -3.0f64..3.0,
            scale in prop::sample::select(vec![1.0e-4f64, 1.0e-2, 0.1, 1.0]),
            lx in -2.0f64..2.0,
            ly in -2.0f64..2.0,
        ) {
            let e = BodyExtent {
                min_extent: min_extent as Real,
                max_extent: (min_extent * (1.0 + reach_over)) as Real,
                core_reach: (min_extent * reach_over) as Real,
            };
            let motion = [(dx * scale) as Real, (dy * scale) as Real, (dtheta * scale) as Real];
            let sim = moved(e, motion, Vec2::new(lx as Real, ly as Real));
            if sim.is_fast() {
                prop_assert!(sim.may_be_fast(), "fast but not flagged: {e:?} {motion:?}");
            }
        }
    }

    #[test]
    fn the_finalize_bound_is_not_everything() {
        // A 1 m box that moved 1 cm and turned 0.01 rad is not flagged; one
        // that moved 60 cm is fast and flagged.
        let e = BodyExtent {
            min_extent: 0.5,
            max_extent: 0.71,
            core_reach: 0.71,
        };
        let slow = moved(e, [0.01, 0.0, 0.01], Vec2::ZERO);
        assert!(!slow.may_be_fast());
        let fast = moved(e, [0.6, 0.0, 0.0], Vec2::ZERO);
        assert!(fast.is_fast() && fast.may_be_fast());
        // No solid shape: never.
        let bare = moved(BodyExtent::default(), [50.0, 0.0, 1.0], Vec2::ZERO);
        assert!(!bare.is_fast() && !bare.may_be_fast());
    }
}
