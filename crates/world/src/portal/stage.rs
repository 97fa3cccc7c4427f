//! Portals in the world: bodies cross, clones appear and hand over.
//!
//! A linked pair of portals sits on two bodies (static, kinematic or
//! dynamic). A body whose shapes enter an aperture gets a **clone** at the
//! partner portal, placed by the exact clone state of the portal map
//! (the portal spec (docs/portal.md)) and scaled by `η` (`1/η` the other way); a
//! [`PortalConstraint`] makes the two copies move as one object.
//!
//! ```text
//!   entry portal (normal n₁)                  exit portal (normal n₂)
//!        │  original ░░│                        │▓▓ clone
//!        │   moving  ░░│ ──── T(x) = P₂ + ηQ(x − P₁) ───▶ │▓▓ emerging
//!        │   along −n₁░│                        │▓▓ along +n₂
//!   f₁ = area in front of entry  +  f₂ = area in front of exit  = 1
//! ```
//!
//! Life of a crossing:
//!
//! | stage     | when                                                        | effect |
//! |-----------|-------------------------------------------------------------|--------|
//! | start     | a body's shapes straddle an aperture and fit its width, or its centre swept through the aperture during the step | clone created, constraint linked, [`PortalEvent::CrossingStarted`] |
//! | straddle  | every step                                                  | masses and inertias weighted by `f₁`, `f₂` (clamped to `[F_MIN, 1 − F_MIN]`) |
//! | handover  | the original is entirely behind the entry plane (and its joints can follow) | the handle moves to the clone's body and each shape handle to the clone's matching shape, the original's body is removed, joints re-pointed, [`PortalEvent::CrossingCompleted`] |
//! | cancel    | the clone is entirely behind the exit plane (backed out; its joints can follow) | clone removed, joints re-pointed, [`PortalEvent::CrossingCancelled`] |
//! | restart   | a copy's shapes changed (one destroyed or added)            | clone removed; the original may start again at once with its shapes |
//!
//! Contacts: the wall that carries a portal collides as its solid parts
//! (manifolds clipped to them, with points at the lips; see [`super::clipping`]);
//! a crossing copy drops its contact points that lie behind its own portal
//! plane within the aperture; a copy never touches its twin. A body takes
//! part in at most one crossing: while it crosses it ignores every other
//! portal, whose hole is solid wall to it.
//!
//! Joints follow the object: a joint always joins two bodies on the same
//! side, and acts across the portal through the portal rows of the crossing
//! copy it is attached to. When the original hands over, each joint on it
//! moves to the exit side: its end on the original to the clone (the same
//! handle, anchor `c + η (l − c)` about the local centre of mass), its
//! other end to that body's copy on the exit side (its clone, or the
//! original of a crossing the other way), impulses turned by `Q` and scaled
//! by `1/η`; joints on the clone stay on that body. A backing-out clone
//! hands its joints back the same way. A crossing whose joints could not
//! follow (the other body has no copy on the side that stays: it has not
//! reached the aperture yet) goes on, however far the copy is behind its
//! plane, until they can. While a copy carries a joint it keeps at least
//! [`F_JOINTED`] of the mass, and the step solves the joints and the
//! portal rows together ([`super::coupling`]). Only a crossing that is
//! ended by force (its pair or a copy's shapes changed) disables the joints
//! that cannot follow, and reports them ([`PortalEvent::JointDisabled`]), as
//! is a joint between the two copies.
//! `η` lies in [`ETA_MIN`](janus2d_constraints::portal_map::ETA_MIN) to
//! [`ETA_MAX`](janus2d_constraints::portal_map::ETA_MAX).
//!
//! The whole stage is skipped when the world has no portal pair.
//!
//! What is here: the stage's types and state; the logic of the public
//! portal API (create, destroy and read pairs; the methods themselves are
//! on `World`, in `world/portals.rs`, and pass the stores each needs); and
//! the crossing stage, [`PortalStage::cross`], which the step calls over
//! the `Stores` (and [`PortalStage::forget_body`], which destroying a body
//! calls). The crossing stage carries out the decisions of `crossing.rs`
//! in order: it writes masses, velocities (with the momentum exchanged
//! with a dynamic portal body) and joint impulses in place, and asks for
//! each change of structure by a `PortalCommand` that the world applies
//! at once (`Stores::apply`), so that every step reads the stores as the
//! one before it left them.

use janus2d_constraints::portal_map::{BodyMotion, PortalBodyMotion, PortalFrame, PortalMap};
use janus2d_constraints::{ObjectMass, Portal, PortalConstraint, PortalConstraintDef};
use janus2d_core::body::{BodyDef, BodyHandle, BodyMass, BodyType};
use janus2d_core::math::{Real, Rot, Vec2, cross};
use janus2d_core::slots::Slots;

use super::clipping::{ApertureClip, ContactClipping};
use super::crossing::{Decision, PortalCommand, extents_in, front_fraction, shape_handles};
use crate::collision::Collision;
use crate::error::WorldError;
use crate::joints::{JointHandle, JointSet};
use crate::shapes::{ShapeHandle, ShapeStore};
use crate::stores::Stores;
use janus2d_core::body::{BodyLocation, BodySet};
use janus2d_core::handle::{Handle, PortalPairTag};

/// Smallest mass fraction a straddling copy keeps (dimensionless, usual
/// 0.1): a copy that has barely appeared is never thousands of times
/// lighter than what it touches.
pub const F_MIN: Real = 0.1;

/// Smallest mass fraction a straddling copy keeps while it carries a joint
/// to another body (dimensionless, 0.5; when both copies carry one, each
/// keeps half). The joint's load reaches the other copy through the portal
/// rows, and those move a light copy away from what it is jointed to: with
/// [`F_MIN`] the rope of `tests/portals/portal_joints.rs` opened 6.2 mm (η = 1) and
/// 24 mm (η = 2) across the portal, with this floor 1.4 and 13 mm (and
/// with the coupled passes of the joint and portal solves 0.8 and 7.7 mm).
pub const F_JOINTED: Real = 0.5;

/// How far past its span a copy held for its joints may press into the
/// aperture's side wall and still count as within it, m (two linear
/// slops).
const SPAN_SLACK: Real = 2.0 * janus2d_core::geometry::LINEAR_SLOP;

/// Half-width of the region behind a copy's plane that the clipping drops
/// for a copy wholly behind it (m): beyond any coordinate a body can have.
const HELD_HALF_WIDTH: Real = 4.0 * janus2d_core::limits::MAX_COORDINATE;

/// How a clone's mass follows from the original's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum MassModel {
    /// Density unchanged: `m₂ = η² m₁`, `I₂ = η⁴ I₁` (what a game expects).
    #[default]
    SameMaterial,
    /// Density times `η⁻⁴`: `m₂ = m₁ / η²`, `I₂ = I₁`; a full pass keeps
    /// kinetic energy.
    EnergyPreserving,
}

impl MassModel {
    /// The clone's mass properties for an original of `m` scaled by `eta`
    /// (centre in the original's local frame; scaling is about it).
    pub fn clone_mass(self, m: BodyMass, eta: Real) -> BodyMass {
        match self {
            MassModel::SameMaterial => BodyMass {
                mass: eta * eta * m.mass,
                rotational_inertia: eta.powi(4) * m.rotational_inertia,
                center: m.center,
            },
            MassModel::EnergyPreserving => BodyMass {
                mass: m.mass / (eta * eta),
                rotational_inertia: m.rotational_inertia,
                center: m.center,
            },
        }
    }
}

/// One portal: an aperture on a body.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalDef {
    /// The body carrying the portal.
    pub body: BodyHandle,
    /// Aperture centre in the body frame, m.
    pub anchor: Vec2,
    /// Outward face normal in the body frame (normalised on creation).
    pub direction: Vec2,
    /// Half the aperture width, m (> 0).
    pub half_width: Real,
}

impl PortalDef {
    /// A portal on `body`: an aperture centred at `anchor` (body frame,
    /// m), its face looking along `direction` (body frame; normalised on
    /// creation), `half_width` m to each side (> 0). Checked when the pair
    /// is created.
    ///
    /// ```
    /// use janus2d_world::{PortalDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let floor = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let p = PortalDef::new(floor, Vec2::new(0.0, 0.5), Vec2::Y, 1.0);
    /// assert_eq!(p.half_width, 1.0);
    /// ```
    #[must_use]
    pub fn new(body: BodyHandle, anchor: Vec2, direction: Vec2, half_width: Real) -> Self {
        PortalDef {
            body,
            anchor,
            direction,
            half_width,
        }
    }
}

/// A linked pair of portals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortalPairDef {
    /// Portal a (bodies entering it come out of b scaled by `η`).
    pub portal_a: PortalDef,
    /// Portal b (bodies entering it come out of a scaled by `1/η`).
    pub portal_b: PortalDef,
    /// Scale from a to b; `None` gives `w_b / w_a`.
    pub eta: Option<Real>,
    /// How clones' masses follow from the originals'.
    pub mass_model: MassModel,
}

impl PortalPairDef {
    /// A pair with `η = w_b / w_a` and the same-material mass model; set
    /// either with [`with_eta`](Self::with_eta) and
    /// [`with_mass_model`](Self::with_mass_model).
    ///
    /// ```
    /// use janus2d_core::body::BodyDef;
    /// use janus2d_core::math::Vec2;
    /// use janus2d_world::{MassModel, PortalDef, PortalPairDef, World, WorldDef};
    ///
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let floor = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let wall = world.create_body(&BodyDef::fixed(Vec2::new(10.0, 0.0))).unwrap();
    /// let at = |body| PortalDef { body, anchor: Vec2::ZERO, direction: Vec2::Y, half_width: 0.5 };
    /// let def = PortalPairDef::new(at(floor), at(wall))
    ///     .with_eta(2.0)
    ///     .with_mass_model(MassModel::EnergyPreserving);
    /// let pair = world.create_portal_pair(&def).unwrap();
    /// assert_eq!(world.portal_map(pair).unwrap().eta, 2.0);
    /// ```
    #[must_use]
    pub fn new(portal_a: PortalDef, portal_b: PortalDef) -> Self {
        PortalPairDef {
            portal_a,
            portal_b,
            eta: None,
            mass_model: MassModel::SameMaterial,
        }
    }

    /// The same pair with scale `eta` from a to b (instead of `w_b / w_a`);
    /// checked by [`World::create_portal_pair`](crate::World::create_portal_pair) (finite, within
    /// [`ETA_MIN`](janus2d_constraints::portal_map::ETA_MIN) to
    /// [`ETA_MAX`](janus2d_constraints::portal_map::ETA_MAX)).
    #[must_use]
    pub fn with_eta(self, eta: Real) -> Self {
        PortalPairDef {
            eta: Some(eta),
            ..self
        }
    }

    /// The same pair with mass model `mass_model` for its clones.
    #[must_use]
    pub fn with_mass_model(self, mass_model: MassModel) -> Self {
        PortalPairDef { mass_model, ..self }
    }
}

/// Where a body is against one portal's plane (its shapes' extent along
/// the outward normal).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaneSide {
    /// Entirely in front of the plane (the side it is entered from).
    Front,
    /// Partly in front, partly behind.
    Straddling,
    /// Entirely behind the plane.
    Behind,
}

/// A body's role in a crossing through a pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CrossingRole {
    /// Not crossing through this pair.
    None,
    /// The original, entering portal `entry` (0: a, 1: b).
    Original {
        /// The portal it entered.
        entry: usize,
    },
    /// The clone, emerging from the partner of portal `entry`.
    Clone {
        /// The portal the original entered.
        entry: usize,
    },
}

/// Where a body is against a portal pair (see [`World::portal_side`](crate::World::portal_side)).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PortalSide {
    /// Against portal a's plane.
    pub a: PlaneSide,
    /// Against portal b's plane.
    pub b: PlaneSide,
    /// Within the aperture's span along the plane (`|t| ≤ w`), per portal:
    /// a body that straddles a plane while within the span is in the
    /// aperture; outside it, it is in the wall or beside it.
    pub within: [bool; 2],
    /// Its part in a crossing through the pair.
    pub crossing: CrossingRole,
}

/// A generational handle to a portal pair.
pub type PortalPairHandle = Handle<PortalPairTag>;

/// What happened at the portals during the last step.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum PortalEvent {
    /// A body entered a portal: its clone was created.
    CrossingStarted {
        /// The original.
        body: BodyHandle,
        /// Its clone.
        clone: BodyHandle,
        /// The pair.
        pair: PortalPairHandle,
    },
    /// A body went through: `body` now refers to the object on the exit
    /// side, and each of its shape handles to the matching shape there
    /// (material, filter, flags and user data kept; the clone's handles are
    /// stale). Every contact of both copies ended at the handover; those of
    /// the object on the exit side begin again at the next step, under the
    /// user's shape handles.
    CrossingCompleted {
        /// The object (its handle followed it).
        body: BodyHandle,
        /// The pair.
        pair: PortalPairHandle,
    },
    /// A body backed out: its clone was removed.
    CrossingCancelled {
        /// The original.
        body: BodyHandle,
        /// The pair.
        pair: PortalPairHandle,
    },
    /// A joint could not follow a crossing that was ended by force (or
    /// joined the two copies of one object): it is disabled.
    JointDisabled {
        /// The joint.
        joint: JointHandle,
        /// The pair.
        pair: PortalPairHandle,
    },
}

/// Counters of the last portal stage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PortalCounters {
    /// Crossings in progress after the step.
    pub active_crossings: usize,
    /// Crossings started this step.
    pub started: usize,
    /// Crossings completed this step.
    pub completed: usize,
    /// Crossings cancelled this step.
    pub cancelled: usize,
    /// Bodies tested against apertures this step.
    pub bodies_tested: usize,
}

#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct PairData {
    pub(crate) portals: [PortalDef; 2],
    pub(crate) local: [Portal; 2],
    pub(crate) eta: Real,
    pub(crate) mass_model: MassModel,
}

/// A crossing in progress.
#[derive(Clone, Debug)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct Crossing {
    pub(crate) pair: u32,
    /// 0: entered portal a; 1: entered portal b.
    pub(crate) entry: usize,
    pub(crate) original: BodyHandle,
    pub(crate) clone: BodyHandle,
    pub(crate) mass_original: BodyMass,
    pub(crate) mass_clone: BodyMass,
    /// The original's shapes when the clone was made.
    pub(crate) original_shapes: Vec<ShapeHandle>,
    /// The clone's shapes (the original's, scaled).
    pub(crate) clone_shapes: Vec<ShapeHandle>,
}

/// The portal stage: pairs, crossings and their constraints, the clipping
/// it hands the narrowphase, and its events.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub(crate) struct PortalStage {
    /// Portal pair handle slots.
    pub(crate) pairs: Slots<PairData>,
    pub(crate) crossings: Vec<Crossing>,
    /// One constraint per crossing, same order.
    pub(crate) constraints: Vec<PortalConstraint>,
    /// Events pushed since the last step ended, by calls between steps
    /// (`destroy_portal_pair`, destroying a copy or a portal body) and by
    /// the step under way: reported with the next step's, as collision
    /// events are.
    pub(crate) pending_events: Vec<PortalEvent>,
    pub(crate) counters: PortalCounters,
    pub(crate) clipping: ContactClipping,
}

impl PortalStage {
    /// True when the world has a portal pair (otherwise the stage is skipped).
    pub(crate) fn is_active(&self) -> bool {
        !self.pairs.is_empty()
    }

    /// The clipping the narrowphase applies.
    pub(crate) fn clipping(&self) -> &ContactClipping {
        &self.clipping
    }

    /// The portal rows, one per crossing (same order).
    pub(crate) fn constraints(&self) -> &[PortalConstraint] {
        &self.constraints
    }

    /// The portal constraints, as the solver's third batch.
    pub(crate) fn constraints_mut(&mut self) -> &mut Vec<PortalConstraint> {
        &mut self.constraints
    }

    /// Ends a step's events: those pushed since the last step (between
    /// steps, then by this step) become the step's, in order (what
    /// `StepEvents::portals` holds).
    pub(crate) fn take_events(&mut self) -> Vec<PortalEvent> {
        std::mem::take(&mut self.pending_events)
    }

    /// Portal rows, bodies tested and crossings of the step.
    pub(crate) fn counters_for_step(&self, ran: bool) -> (usize, usize, usize) {
        (
            3 * self.constraints.len(),
            if ran { self.counters.bodies_tested } else { 0 },
            self.crossings.len(),
        )
    }

    /// Bodies a crossing keeps awake: the two copies and both portal bodies.
    pub(crate) fn keep_awake(&self) -> Vec<BodyHandle> {
        let mut out = Vec::with_capacity(4 * self.crossings.len());
        for c in &self.crossings {
            let (entry, exit) = self.portal_bodies(c);
            out.extend([c.original, c.clone, entry, exit]);
        }
        out
    }

    /// The bodies carrying a crossing's entry and exit portals.
    pub(crate) fn portal_bodies(&self, c: &Crossing) -> (BodyHandle, BodyHandle) {
        let d = self.pairs.at(c.pair).expect("live pair");
        (d.portals[c.entry].body, d.portals[1 - c.entry].body)
    }

    /// Builds the contact clipping for this step's narrowphase.
    pub(crate) fn build_clipping(&mut self, bodies: &BodySet, shapes: &crate::shapes::ShapeStore) {
        let mut clipping = std::mem::take(&mut self.clipping);
        clipping.clips.clear();
        clipping.ignored_pairs.clear();
        clipping.copies.clear();
        for (index, d) in self.pairs.iter() {
            for k in 0..2 {
                let f = frame_in(bodies, &d.portals[k], &d.local[k]);
                clipping.clips.push(ApertureClip {
                    body: d.portals[k].body,
                    point: f.point,
                    normal: f.normal,
                    half_width: d.local[k].half_width,
                    hole: true,
                    aperture: 2 * index + k as u32,
                });
            }
        }
        for c in &self.crossings {
            let d = self.pairs.at(c.pair).expect("live pair");
            let (entry, exit) = (c.entry, 1 - c.entry);
            for (body, side) in [(c.original, entry), (c.clone, exit)] {
                let f = frame_in(bodies, &d.portals[side], &d.local[side]);
                // A copy wholly behind its plane (a crossing held for its
                // joints) is all on the other side: it touches nothing
                // behind the plane, in the aperture's span or beside it
                // (inside the wall that carries the portal).
                let wholly_behind = extents_in(bodies, shapes, body, &f).is_some_and(|e| e.1 < 0.0);
                clipping.clips.push(ApertureClip {
                    body,
                    point: f.point,
                    normal: f.normal,
                    half_width: if wholly_behind {
                        HELD_HALF_WIDTH
                    } else {
                        d.local[side].half_width
                    },
                    hole: false,
                    aperture: 2 * c.pair + side as u32,
                });
                clipping.copies.push((body, 2 * c.pair + side as u32));
            }
            clipping.ignored_pairs.push((c.original, c.clone));
        }
        self.clipping = clipping;
    }

    /// Both apertures of every pair in world space, with the map to the
    /// partner, for rays and shape casts through portals.
    pub(crate) fn query_apertures(
        &self,
        bodies: &BodySet,
        owner: u32,
    ) -> Vec<crate::query::QueryAperture> {
        let mut out = Vec::with_capacity(2 * self.pairs.len());
        for (index, d) in self.pairs.iter() {
            let frames = [
                frame_in(bodies, &d.portals[0], &d.local[0]),
                frame_in(bodies, &d.portals[1], &d.local[1]),
            ];
            for k in 0..2 {
                let eta = if k == 0 { d.eta } else { 1.0 / d.eta };
                out.push(crate::query::QueryAperture {
                    pair: self.pairs.handle(index, owner),
                    side: k,
                    body: d.portals[k].body,
                    half_width: d.local[k].half_width,
                    map: PortalMap {
                        frame1: frames[k],
                        frame2: frames[1 - k],
                        eta,
                    },
                });
            }
        }
        out
    }

    /// The contact-modification hook's data: the contact constraints of
    /// crossing copies build their effective masses on the whole object.
    /// With `v₂ = ηQ v₁` (static portals) an impulse on the clone moves the
    /// object as if its mass were `m₂ + m₁/η²` (and `m₁ + η² m₂` seen from
    /// the original); rotation is shared, so the inertia is `I₁ + I₂`.
    /// Fills `out` (cleared first), one entry per copy.
    pub(crate) fn object_masses(&self, bodies: &BodySet, out: &mut Vec<ObjectMass>) {
        out.clear();
        for (c, pc) in self.crossings.iter().zip(&self.constraints) {
            let eta = pc.def().eta;
            let (Some(s1), Some(s2)) = (bodies.sim(c.original), bodies.sim(c.clone)) else {
                continue;
            };
            let inertia = s1.inertia + s2.inertia;
            let inv_inertia = if inertia > 0.0 && s1.inv_inertia > 0.0 {
                1.0 / inertia
            } else {
                0.0
            };
            let m_orig = s1.mass + eta * eta * s2.mass;
            let m_clone = s2.mass + s1.mass / (eta * eta);
            out.push(ObjectMass {
                body: c.original,
                inv_mass: 1.0 / m_orig,
                inv_inertia,
            });
            out.push(ObjectMass {
                body: c.clone,
                inv_mass: 1.0 / m_clone,
                inv_inertia,
            });
        }
    }

    /// True when a crossing copy carries an enabled joint (the step then
    /// solves joints and portal rows together, see [`super::coupling`]).
    pub(crate) fn copies_carry_joints(&self, joints: &crate::joints::JointSet) -> bool {
        self.crossings.iter().any(|c| {
            [c.original, c.clone].iter().any(|&b| {
                joints
                    .of_body(b)
                    .iter()
                    .any(|&h| joints.get(h).is_ok_and(|j| j.is_enabled()))
            })
        })
    }

    /// True when `body` carries a portal or is crossing one.
    pub(crate) fn involves(&self, body: BodyHandle) -> bool {
        self.crossing_of(body).is_some()
            || self
                .pairs
                .iter()
                .any(|(_, d)| d.portals.iter().any(|p| p.body == body))
    }

    /// Checks pairs ↔ crossings ↔ clones ↔ constraints (for
    /// `World::validate`): portal bodies live, η finite and positive, one
    /// constraint per crossing naming its two copies and portal bodies,
    /// copies live, distinct and in no other crossing.
    pub(crate) fn check(&self, bodies: &BodySet) -> Result<(), String> {
        self.pairs.check().map_err(|e| format!("pair slots: {e}"))?;
        for (index, d) in self.pairs.iter() {
            if !(d.eta.is_finite() && d.eta > 0.0) {
                return Err(format!("pair {index}: eta {}", d.eta));
            }
            for portal in &d.local {
                if portal.validate().is_err() || check_portal_extent(portal).is_err() {
                    return Err(format!("pair {index}: portal {portal:?}"));
                }
            }
            if let Some(p) = d.portals.iter().find(|p| !bodies.contains(p.body)) {
                return Err(format!(
                    "pair {index}: portal body {:?} is not live",
                    p.body
                ));
            }
        }
        if self.crossings.len() != self.constraints.len() {
            return Err(format!(
                "{} crossings, {} constraints",
                self.crossings.len(),
                self.constraints.len()
            ));
        }
        for (k, (c, pc)) in self.crossings.iter().zip(&self.constraints).enumerate() {
            if self.pairs.at(c.pair).is_none() {
                return Err(format!("crossing {k}: its pair is gone"));
            }
            // (A decoded entry of 32 indexed the pair's two portals.)
            if c.entry > 1 {
                return Err(format!("crossing {k}: entry portal {}", c.entry));
            }
            if c.original == c.clone || !bodies.contains(c.original) || !bodies.contains(c.clone) {
                return Err(format!(
                    "crossing {k}: copies {:?}, {:?}",
                    c.original, c.clone
                ));
            }
            // The copies' full masses, which the crossing hands back to
            // them: within the body limits (a decoded snapshot's denormal
            // inertia gave the copy an infinite inverse inertia at the
            // next step).
            for m in [c.mass_original, c.mass_clone] {
                let inertia_ok = m.rotational_inertia == 0.0
                    || janus2d_core::limits::in_range(
                        m.rotational_inertia,
                        janus2d_core::limits::INERTIA_RANGE,
                    );
                if !(janus2d_core::limits::in_range(m.mass, janus2d_core::limits::MASS_RANGE)
                    && inertia_ok
                    && janus2d_core::math::vec_is_finite(m.center))
                {
                    return Err(format!("crossing {k}: a copy's mass {m:?}"));
                }
            }
            let def = pc.def();
            if def.body != c.original || def.clone != c.clone {
                return Err(format!("crossing {k}: its constraint names other bodies"));
            }
            let (entry, exit) = self.portal_bodies(c);
            if def.portal_body_a != entry || def.portal_body_b != exit {
                return Err(format!(
                    "crossing {k}: its constraint names other portal bodies"
                ));
            }
            let shared = self.crossings[k + 1..].iter().any(|o| {
                [o.original, o.clone].contains(&c.original)
                    || [o.original, o.clone].contains(&c.clone)
            });
            if shared {
                return Err(format!("crossing {k}: a copy is in another crossing"));
            }
        }
        Ok(())
    }

    pub(crate) fn crossing_of(&self, body: BodyHandle) -> Option<usize> {
        self.crossings
            .iter()
            .position(|c| c.original == body || c.clone == body)
    }
}

fn frame_in(bodies: &BodySet, def: &PortalDef, local: &Portal) -> PortalFrame {
    PortalFrame::new(&bodies.solver_body(def.body).sim.transform, local)
}

fn motion_in(bodies: &BodySet, body: BodyHandle) -> PortalBodyMotion {
    let b = bodies.solver_body(body);
    PortalBodyMotion {
        center: b.sim.center,
        linear_velocity: b.state.v,
        angular_velocity: b.state.w,
    }
}

/// The enabled joints attached to a body, in the body's list order.
fn joints_attached_to(joints: &JointSet, body: BodyHandle) -> Vec<JointHandle> {
    joints
        .of_body(body)
        .iter()
        .copied()
        .filter(|h| joints.get(*h).is_ok_and(|j| j.is_enabled()))
        .collect()
}

/// Sets a dynamic body's mass properties without touching its velocity.
fn apply_mass_keep_velocity(bodies: &mut BodySet, body: BodyHandle, mass: BodyMass) {
    let fixed = bodies
        .record(body)
        .map(|r| r.fixed_rotation)
        .unwrap_or(false);
    bodies.apply_mass(body, mass, fixed);
}

/// Wakes a body and sets its velocity (no checks), its speed within the
/// body's `max_linear_speed` (a clone leaves the exit at η times the
/// original's speed, which may be over it) and its angular speed within
/// [`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED).
fn set_velocity(stores: &mut Stores<'_>, body: BodyHandle, v: Vec2, w: Real) {
    stores.apply(PortalCommand::Wake(body));
    let max = stores.bodies.sim(body).map(|s| s.max_linear_speed);
    if let (Some(s), Some(max)) = (stores.bodies.state_mut(body), max) {
        s.v = janus2d_core::solver::clamp_speed(v, max);
        s.w = bounded_spin(w);
    }
}

/// `w` within ±[`MAX_ANGULAR_SPEED`](janus2d_core::limits::MAX_ANGULAR_SPEED),
/// rad/s; a NaN is 0. A light portal body handed a heavy crossing's spin
/// (`ΔI ω` over its own tiny inertia) reached ω = ∞ in the
/// random-operation soak (seed 3549), after the solve's non-finite check.
fn bounded_spin(w: Real) -> Real {
    let max = janus2d_core::limits::MAX_ANGULAR_SPEED;
    if w.is_nan() { 0.0 } else { w.clamp(-max, max) }
}

/// Wakes a body and adds an impulse at a world point to it when it is
/// dynamic (no checks), its speed kept within its `max_linear_speed` (a
/// light portal body taking a heavy crossing's momentum went to 515 m/s
/// in the random-operation soak, over the 400 m/s limit).
fn push_body(stores: &mut Stores<'_>, body: BodyHandle, impulse: Vec2, point: Vec2, angular: Real) {
    stores.apply(PortalCommand::Wake(body));
    if let Some(BodyLocation::Moving(i)) = stores.bodies.location(body) {
        let sim = &stores.bodies.sims[i as usize];
        if sim.body_type == BodyType::Dynamic {
            let (im, ii, c) = (sim.inv_mass, sim.inv_inertia, sim.center);
            let max = sim.max_linear_speed;
            let st = &mut stores.bodies.states[i as usize];
            st.v = janus2d_core::solver::clamp_speed(st.v + im * impulse, max);
            st.w = bounded_spin(st.w + ii * cross(point - c, impulse) + ii * angular);
        }
    }
}

/// A portal's anchor coordinates and half-width within the shape limit
/// [`MAX_EXTENT`](janus2d_core::limits::MAX_EXTENT) (a half-width of 1e30
/// let every resting body fall through).
fn check_portal_extent(p: &Portal) -> Result<(), WorldError> {
    let max = janus2d_core::limits::MAX_EXTENT;
    if p.anchor.x.abs() > max || p.anchor.y.abs() > max {
        return Err(WorldError::OutOfBounds {
            field: "anchor",
            min: -max,
            max,
        });
    }
    if p.half_width > max {
        return Err(WorldError::OutOfBounds {
            field: "half_width",
            min: 0.0,
            max,
        });
    }
    Ok(())
}

/// The pair API's logic: the world's portal methods (`world/portals.rs`)
/// pass what each reads and changes.
impl PortalStage {
    /// Creates a linked pair of portals on live bodies of `bodies`; see
    /// `World::create_portal_pair` for what is rejected. Turns the
    /// collision stage's uniform margins on.
    pub(crate) fn create_pair(
        &mut self,
        def: &PortalPairDef,
        bodies: &BodySet,
        collision: &mut Collision,
    ) -> Result<PortalPairHandle, WorldError> {
        let mut local = Vec::with_capacity(2);
        for p in [def.portal_a, def.portal_b] {
            if !bodies.contains(p.body) {
                return Err(if p.body.owner == bodies.owner() {
                    WorldError::StaleBody
                } else {
                    WorldError::ForeignHandle
                });
            }
            // A copy in a crossing may be destroyed by the stage at any
            // step: it cannot carry a portal.
            if self.crossing_of(p.body).is_some() {
                return Err(WorldError::PortalBody);
            }
            let portal = Portal::new(p.anchor, p.direction, p.half_width)
                .map_err(WorldError::Portal)?
                .normalized();
            check_portal_extent(&portal)?;
            local.push(portal);
        }
        let local = [local[0], local[1]];
        let eta = def.eta.unwrap_or(local[1].half_width / local[0].half_width);
        janus2d_constraints::portal_map::validate_eta(eta).map_err(WorldError::Portal)?;
        let (lo, hi) = janus2d_core::limits::ETA_RANGE;
        if !(lo..=hi).contains(&eta) {
            return Err(WorldError::OutOfBounds {
                field: "eta",
                min: lo,
                max: hi,
            });
        }
        let data = PairData {
            portals: [def.portal_a, def.portal_b],
            local,
            eta,
            mass_model: def.mass_model,
        };
        // Portals keep every shape's fat box at the full margin (see
        // `Collision::use_uniform_margins`).
        collision.use_uniform_margins();
        let (index, generation) = self.pairs.insert(data);
        Ok(PortalPairHandle::new(index, generation, bodies.owner()))
    }

    /// The slot of a live pair of the world `owner` (`StalePortal` or
    /// `ForeignHandle` otherwise).
    pub(crate) fn pair_slot(&self, pair: PortalPairHandle, owner: u32) -> Result<u32, WorldError> {
        self.pairs
            .resolve(pair, owner)
            .map(|_| pair.index)
            .map_err(|e| WorldError::of_handle(e, WorldError::StalePortal))
    }

    fn pair_handle(&self, index: u32, owner: u32) -> PortalPairHandle {
        self.pairs.handle(index, owner)
    }

    /// Destroys a portal pair, cancelling every crossing in progress
    /// through it.
    pub(crate) fn destroy_pair(
        &mut self,
        pair: PortalPairHandle,
        stores: &mut Stores<'_>,
    ) -> Result<(), WorldError> {
        let index = self.pair_slot(pair, stores.bodies.owner())?;
        self.remove_pair(index, stores);
        Ok(())
    }

    /// Removes live pair `index`, cancelling its crossings.
    fn remove_pair(&mut self, index: u32, stores: &mut Stores<'_>) {
        while let Some(k) = self.crossings.iter().position(|c| c.pair == index) {
            self.cancel_crossing(k, stores);
        }
        let generation = self.pairs.generation(index);
        self.pairs.remove(index, generation);
    }

    /// The pair's map from portal a to portal b at the portal bodies'
    /// present poses.
    pub(crate) fn map(
        &self,
        pair: PortalPairHandle,
        bodies: &BodySet,
    ) -> Result<PortalMap, WorldError> {
        let index = self.pair_slot(pair, bodies.owner())?;
        let d = self.pairs.at(index).expect("live pair");
        Ok(PortalMap {
            frame1: frame_in(bodies, &d.portals[0], &d.local[0]),
            frame2: frame_in(bodies, &d.portals[1], &d.local[1]),
            eta: d.eta,
        })
    }

    /// Where live `body` is against the two portals of `pair` and its part
    /// in a crossing through the pair (see `World::portal_side`).
    pub(crate) fn side(
        &self,
        body: BodyHandle,
        pair: PortalPairHandle,
        bodies: &BodySet,
        shapes: &ShapeStore,
    ) -> Result<PortalSide, WorldError> {
        let index = self.pair_slot(pair, bodies.owner())?;
        let d = self.pairs.at(index).expect("live pair");
        let center = bodies.sim(body).map_or(Vec2::ZERO, |s| s.center);
        let mut sides = [PlaneSide::Front; 2];
        let mut within = [false; 2];
        for k in 0..2 {
            let f = frame_in(bodies, &d.portals[k], &d.local[k]);
            let (n0, n1, t0, t1) = extents_in(bodies, shapes, body, &f).unwrap_or_else(|| {
                let s = (center - f.point).dot(f.normal);
                let t = (center - f.point).dot(f.tangent);
                (s, s, t, t)
            });
            sides[k] = if n0 >= 0.0 {
                PlaneSide::Front
            } else if n1 <= 0.0 {
                PlaneSide::Behind
            } else {
                PlaneSide::Straddling
            };
            let w = d.local[k].half_width;
            within[k] = t0 >= -w && t1 <= w;
        }
        let crossing = self
            .crossings
            .iter()
            .find(|c| c.pair == index && (c.original == body || c.clone == body))
            .map_or(CrossingRole::None, |c| {
                if c.original == body {
                    CrossingRole::Original { entry: c.entry }
                } else {
                    CrossingRole::Clone { entry: c.entry }
                }
            });
        Ok(PortalSide {
            a: sides[0],
            b: sides[1],
            within,
            crossing,
        })
    }

    /// Every live pair with its definition as the stage holds it
    /// (directions normalised, `eta` set to the pair's scale).
    pub(crate) fn pair_defs(
        &self,
        owner: u32,
    ) -> impl Iterator<Item = (PortalPairHandle, PortalPairDef)> + '_ {
        self.pairs.iter().map(move |(index, d)| {
            let def = |k: usize| PortalDef {
                direction: d.local[k].direction,
                half_width: d.local[k].half_width,
                ..d.portals[k]
            };
            let pair = PortalPairDef {
                portal_a: def(0),
                portal_b: def(1),
                eta: Some(d.eta),
                mass_model: d.mass_model,
            };
            (self.pair_handle(index, owner), pair)
        })
    }

    /// `(clone, original)` body slots of the crossings in progress.
    pub(crate) fn clone_aliases(&self) -> impl Iterator<Item = (u32, u32)> + '_ {
        self.crossings
            .iter()
            .map(|c| (c.clone.index, c.original.index))
    }

    /// The clone of `body` while it crosses, if any.
    pub(crate) fn clone_of(&self, body: BodyHandle) -> Option<BodyHandle> {
        self.crossings
            .iter()
            .find(|c| c.original == body)
            .map(|c| c.clone)
    }

    /// Largest portal constraint error `|x₂ − T(x₁)|` over crossings, m.
    pub(crate) fn max_error(&self, bodies: &BodySet) -> Real {
        self.constraints
            .iter()
            .map(|c| c.position_error(bodies))
            .fold(0.0, Real::max)
    }

    /// Called when a body is about to be destroyed: ends the crossings it
    /// takes part in and destroys the portal pairs it carries.
    pub(crate) fn forget_body(&mut self, body: BodyHandle, stores: &mut Stores<'_>) {
        let carried: Vec<u32> = self
            .pairs
            .iter()
            .filter(|(_, d)| d.portals.iter().any(|p| p.body == body))
            .map(|(i, _)| i)
            .collect();
        for index in carried {
            self.remove_pair(index, stores);
        }
        while let Some(k) = self.crossing_of(body) {
            self.cancel_crossing(k, stores);
        }
    }
}

/// The crossing stage: the verb the step calls over the stores, and what
/// it carries out. Masses, velocities and joint impulses are written in
/// place; every change of structure is a [`PortalCommand`] the world
/// applies at once (`Stores::apply`), in the order the stage emits them.
impl PortalStage {
    /// The crossing stage: reviews the crossings in progress and finds new
    /// entries (reading bodies, shapes and the broadphase), then carries
    /// out each decision in order.
    pub(crate) fn cross(&mut self, stores: &mut Stores<'_>) {
        let mut counters = PortalCounters::default();
        let mut crossed: Vec<BodyHandle> = Vec::new();
        // 0. A joint between the two copies of one object would hold it
        // against its own map: disabled, so that the crossing can end.
        self.unjoin_copies(stores);
        // 1. Crossings in progress: hand over, cancel, or re-weight.
        let review = self.review(stores.bodies, &stores.collision.shapes);
        for decision in review {
            self.carry_out(decision, stores, &mut counters, &mut crossed);
        }
        // 2. New crossings.
        let (entries, tested) = self.entries(
            stores.bodies,
            &stores.collision.shapes,
            &stores.collision.broadphase,
            &crossed,
        );
        counters.bodies_tested = tested;
        for decision in entries {
            self.carry_out(decision, stores, &mut counters, &mut crossed);
        }
        counters.active_crossings = self.crossings.len();
        self.counters = counters;
    }

    /// Disables every enabled joint between a crossing's two copies and
    /// reports it ([`PortalEvent::JointDisabled`]).
    fn unjoin_copies(&mut self, stores: &mut Stores<'_>) {
        for k in 0..self.crossings.len() {
            let (original, clone, index) = {
                let c = &self.crossings[k];
                (c.original, c.clone, c.pair)
            };
            let between: Vec<JointHandle> = joints_attached_to(stores.joints, original)
                .into_iter()
                .filter(|j| {
                    stores.joints.bodies_of(*j).is_ok_and(|(a, b)| {
                        (a == original && b == clone) || (a == clone && b == original)
                    })
                })
                .collect();
            let pair = self.pair_handle(index, stores.bodies.owner());
            for joint in between {
                stores.apply(PortalCommand::DisableJoint(joint));
                self.pending_events
                    .push(PortalEvent::JointDisabled { joint, pair });
            }
        }
    }

    /// The world frames of crossing `k`'s entry and exit portals.
    fn crossing_frames(&self, k: usize, bodies: &BodySet) -> (PortalFrame, PortalFrame) {
        let c = &self.crossings[k];
        let d = self.pairs.at(c.pair).expect("live pair");
        (
            frame_in(bodies, &d.portals[c.entry], &d.local[c.entry]),
            frame_in(bodies, &d.portals[1 - c.entry], &d.local[1 - c.entry]),
        )
    }

    /// Carries out one decision of the crossing stage.
    fn carry_out(
        &mut self,
        decision: Decision,
        stores: &mut Stores<'_>,
        counters: &mut PortalCounters,
        crossed: &mut Vec<BodyHandle>,
    ) {
        match decision {
            Decision::Complete(original) => {
                if let Some(k) = self.crossing_of(original) {
                    if self.joints_can_follow(k, true, stores.joints)
                        || !self.within_span(k, true, stores)
                    {
                        self.complete_crossing(k, stores);
                        counters.completed += 1;
                        crossed.push(original);
                    } else {
                        // A joint on the original has no copy of its other
                        // body on the exit side yet: the crossing goes on
                        // (the joint acts through the portal rows).
                        let (f_entry, f_exit) = self.crossing_frames(k, stores.bodies);
                        self.weigh_crossing(k, &f_entry, &f_exit, stores);
                    }
                }
            }
            Decision::Cancel(original) => {
                if let Some(k) = self.crossing_of(original) {
                    if self.joints_can_follow(k, false, stores.joints)
                        || !self.within_span(k, false, stores)
                    {
                        self.cancel_crossing(k, stores);
                        counters.cancelled += 1;
                        crossed.push(original);
                    } else {
                        let (f_entry, f_exit) = self.crossing_frames(k, stores.bodies);
                        self.weigh_crossing(k, &f_entry, &f_exit, stores);
                    }
                }
            }
            Decision::Restart(original) => {
                if let Some(k) = self.crossing_of(original) {
                    self.cancel_crossing(k, stores);
                    counters.cancelled += 1;
                    // The mass it had at the start is stale: its shapes
                    // give it now (unless the user set one).
                    let follows = stores
                        .bodies
                        .record(original)
                        .is_some_and(|r| !r.mass_override);
                    if follows && stores.bodies.body_type(original) == Some(BodyType::Dynamic) {
                        stores.apply(PortalCommand::MassFromShapes(original));
                    }
                }
            }
            Decision::Weigh(original) => {
                if let Some(k) = self.crossing_of(original) {
                    let (f_entry, f_exit) = self.crossing_frames(k, stores.bodies);
                    self.weigh_crossing(k, &f_entry, &f_exit, stores);
                }
            }
            Decision::Start { pair, entry, body } => {
                if self.start_crossing(pair, entry, body, stores).is_none() {
                    return;
                }
                counters.started += 1;
                crossed.push(body);
                // A fast body may already be entirely through.
                let k = self.crossings.len() - 1;
                let (f_entry, f_exit) = self.crossing_frames(k, stores.bodies);
                let through = extents_in(stores.bodies, &stores.collision.shapes, body, &f_entry)
                    .is_some_and(|e| e.1 < 0.0);
                if through
                    && (self.joints_can_follow(k, true, stores.joints)
                        || !self.within_span(k, true, stores))
                {
                    self.complete_crossing(k, stores);
                    counters.completed += 1;
                } else {
                    self.weigh_crossing(k, &f_entry, &f_exit, stores);
                }
            }
        }
    }

    /// Creates the clone of `body` entering portal `entry` of pair `index`.
    fn start_crossing(
        &mut self,
        index: u32,
        entry: usize,
        body: BodyHandle,
        stores: &mut Stores<'_>,
    ) -> Option<()> {
        let d = self.pairs.at(index).cloned()?;
        // A crossing wakes the portal bodies (their constraint rows act now).
        stores.apply(PortalCommand::Wake(d.portals[0].body));
        stores.apply(PortalCommand::Wake(d.portals[1].body));
        let exit = 1 - entry;
        let eta = if entry == 0 { d.eta } else { 1.0 / d.eta };
        let f1 = frame_in(stores.bodies, &d.portals[entry], &d.local[entry]);
        let f2 = frame_in(stores.bodies, &d.portals[exit], &d.local[exit]);
        let map = PortalMap::new(f1, f2, eta).ok()?;
        let (sim, state) = {
            let b = stores.bodies.solver_body(body);
            (*b.sim, *b.state)
        };
        let record = stores.bodies.record(body)?.clone();
        let motion = BodyMotion {
            center: sim.center,
            angle: sim.transform.q.angle(),
            linear_velocity: state.v,
            angular_velocity: state.w,
        };
        let clone_motion = map.clone_state(
            &motion,
            &motion_in(stores.bodies, d.portals[entry].body),
            &motion_in(stores.bodies, d.portals[exit].body),
        );
        let full = BodyMass {
            mass: sim.mass,
            rotational_inertia: sim.inertia,
            center: sim.local_center,
        };
        let mass_clone = d.mass_model.clone_mass(full, eta);
        let q2 = Rot::from_angle(clone_motion.angle);
        let origin = clone_motion.center - q2.rotate(sim.local_center);
        let clone_def = BodyDef {
            body_type: BodyType::Dynamic,
            position: origin,
            angle: clone_motion.angle,
            linear_damping: sim.linear_damping,
            angular_damping: sim.angular_damping,
            gravity_scale: sim.gravity_scale,
            max_linear_speed: sim.max_linear_speed,
            max_rotation: sim.max_rotation,
            mass: Some(mass_clone),
            fixed_rotation: record.fixed_rotation,
            motion_locks: janus2d_core::MotionLocks {
                linear_x: sim.linear_locks & janus2d_core::BodyState::LOCK_X != 0,
                linear_y: sim.linear_locks & janus2d_core::BodyState::LOCK_Y != 0,
                angular: record.fixed_rotation,
            },
            // Speeds scale by η through the portal.
            sleep_threshold: sim.sleep_threshold.map(|t| eta * t),
            bullet: sim.bullet,
            user_data: record.user_data,
            ..BodyDef::default()
        };
        // The new handle is needed at once: a store-level call, not a
        // command.
        let clone = stores.insert_body(&clone_def).ok()?;
        let shapes: Vec<u32> = stores.collision.shapes.of_body(body).to_vec();
        for s in shapes {
            let data = stores.collision.shapes.at(s);
            let geometry = data.geometry.scaled(eta, sim.local_center);
            let mut def = data.def.clone();
            if d.mass_model == MassModel::EnergyPreserving {
                def.density /= eta.powi(4);
            }
            stores.apply(PortalCommand::AddShape {
                body: clone,
                def,
                geometry,
            });
        }
        let owner = stores.bodies.owner();
        let original_shapes = shape_handles(&stores.collision.shapes, body, owner);
        let clone_shapes = shape_handles(&stores.collision.shapes, clone, owner);
        apply_mass_keep_velocity(stores.bodies, clone, mass_clone);
        set_velocity(
            stores,
            clone,
            clone_motion.linear_velocity,
            clone_motion.angular_velocity,
        );
        // The clone's momentum comes out of the exit portal's body.
        let clone_full = (mass_clone.mass, mass_clone.rotational_inertia);
        exchange_with_portal(stores, clone, (0.0, 0.0), clone_full, d.portals[exit].body);
        let constraint = PortalConstraint::new(PortalConstraintDef {
            body,
            clone,
            portal_body_a: d.portals[entry].body,
            portal_body_b: d.portals[exit].body,
            portal_a: d.local[entry],
            portal_b: d.local[exit],
            eta,
        })
        .ok()?;
        self.crossings.push(Crossing {
            pair: index,
            entry,
            original: body,
            clone,
            mass_original: full,
            mass_clone,
            original_shapes,
            clone_shapes,
        });
        self.constraints.push(constraint);
        let pair = self.pair_handle(index, owner);
        self.pending_events
            .push(PortalEvent::CrossingStarted { body, clone, pair });
        Some(())
    }

    /// Weighs the two copies of crossing `k` by their area fractions.
    fn weigh_crossing(
        &mut self,
        k: usize,
        f_entry: &PortalFrame,
        f_exit: &PortalFrame,
        stores: &mut Stores<'_>,
    ) {
        let c = self.crossings[k].clone();
        let shapes = &stores.collision.shapes;
        let a = front_fraction(stores.bodies, shapes, c.original, f_entry);
        let b = front_fraction(stores.bodies, shapes, c.clone, f_exit);
        let f = if a + b > 0.0 { a / (a + b) } else { 0.5 };
        let mut f = f.clamp(F_MIN, 1.0 - F_MIN);
        // A copy that carries a joint keeps at least F_JOINTED of the
        // object: the joint's load passes through the portal rows, which
        // move a light copy away from what it is jointed to.
        let joints: &JointSet = stores.joints;
        let jointed = |copy: BodyHandle, twin: BodyHandle| {
            joints_attached_to(joints, copy).iter().any(|&j| {
                joints
                    .bodies_of(j)
                    .is_ok_and(|(a, b)| a != twin && b != twin)
            })
        };
        match (jointed(c.original, c.clone), jointed(c.clone, c.original)) {
            (true, false) => f = f.max(F_JOINTED),
            (false, true) => f = f.min(1.0 - F_JOINTED),
            (true, true) => f = f.clamp(F_JOINTED.min(0.5), (1.0 - F_JOINTED).max(0.5)),
            (false, false) => {}
        }
        let scale = |m: BodyMass, f: Real| BodyMass {
            mass: f * m.mass,
            rotational_inertia: f * m.rotational_inertia,
            center: m.center,
        };
        let (entry_body, exit_body) = self.portal_bodies(&c);
        set_copy_mass(stores, c.original, scale(c.mass_original, f), entry_body);
        set_copy_mass(stores, c.clone, scale(c.mass_clone, 1.0 - f), exit_body);
    }

    /// Removes crossing `k` and its constraint, returning it.
    fn take_crossing(&mut self, k: usize) -> Crossing {
        self.constraints.remove(k);
        self.crossings.remove(k)
    }

    /// The original went through: the handle follows the object to the
    /// exit side; the original's old body is removed.
    fn complete_crossing(&mut self, k: usize, stores: &mut Stores<'_>) {
        let c = self.take_crossing(k);
        let (entry_body, exit_body) = self.portal_bodies(&c);
        set_copy_mass(stores, c.clone, c.mass_clone, exit_body);
        // What is left of the original goes into the entry portal's body.
        if let Some(b) = stores.bodies.sim(c.original).copied() {
            exchange_with_portal(
                stores,
                c.original,
                (b.mass, b.inertia),
                (0.0, 0.0),
                entry_body,
            );
        }
        let pair = self.pair_handle(c.pair, stores.bodies.owner());
        // Joints on the original move to the exit side with it: their
        // other bodies to their copies there (checked by
        // `joints_can_follow`; one that has none is disabled).
        let on_original = joints_attached_to(stores.joints, c.original);
        let on_clone = joints_attached_to(stores.joints, c.clone);
        let q = self.crossing_rotation(&c, stores.bodies);
        let eta = self.crossing_eta(&c);
        stores.apply(PortalCommand::SwapIdentity(c.original, c.clone));
        // The handle `original` is now the exit copy (the clone's frame:
        // the original's scaled by η about the centre of mass).
        for joint in on_original {
            self.carry_joint(
                joint,
                &c,
                (c.original, c.original),
                eta,
                q,
                1.0 / eta,
                stores,
            );
        }
        // Joints on the clone follow its body, which `original` now names.
        for joint in on_clone {
            if let Some(anchor) = anchor_on(stores.joints, joint, c.clone) {
                stores.apply(PortalCommand::RepointJoint {
                    joint,
                    from: c.clone,
                    to: c.original,
                    anchor,
                });
            }
        }
        stores.apply(PortalCommand::DestroyBody(c.clone));
        self.pending_events.push(PortalEvent::CrossingCompleted {
            body: c.original,
            pair,
        });
    }

    /// The body backed out (or the crossing is ended): remove the clone and
    /// restore the original's full mass.
    fn cancel_crossing(&mut self, k: usize, stores: &mut Stores<'_>) {
        let (entry_body, exit_body) = self.portal_bodies(&self.crossings[k]);
        let c = self.take_crossing(k);
        if stores.bodies.contains(c.original) {
            set_copy_mass(stores, c.original, c.mass_original, entry_body);
        }
        if stores.bodies.contains(c.original) && stores.bodies.contains(c.clone) {
            // Joints on the clone move back to the original, their other
            // bodies to their copies on the entry side.
            // Qᵀ: back from the exit side to the entry side.
            let q = self
                .crossing_rotation(&c, stores.bodies)
                .inv_mul(Rot::IDENTITY);
            let eta = self.crossing_eta(&c);
            for joint in joints_attached_to(stores.joints, c.clone) {
                self.carry_joint(joint, &c, (c.clone, c.original), 1.0 / eta, q, eta, stores);
            }
        }
        if stores.bodies.contains(c.clone) {
            if let Some(b) = stores.bodies.sim(c.clone).copied() {
                exchange_with_portal(stores, c.clone, (b.mass, b.inertia), (0.0, 0.0), exit_body);
            }
            stores.apply(PortalCommand::DestroyBody(c.clone));
        }
        let pair = self.pair_handle(c.pair, stores.bodies.owner());
        self.pending_events.push(PortalEvent::CrossingCancelled {
            body: c.original,
            pair,
        });
    }

    /// True when every enabled joint on the copy that crossing `k` would
    /// remove (the original when it completes, `complete`, the clone when
    /// it backs out) can follow the object: its other body has a copy on
    /// the side that stays. A joint between the two copies does not count
    /// (it is disabled at the start of the stage).
    fn joints_can_follow(&self, k: usize, complete: bool, joints: &JointSet) -> bool {
        let c = &self.crossings[k];
        let (leaving, staying) = if complete {
            (c.original, c.clone)
        } else {
            (c.clone, c.original)
        };
        let leaving_side = if complete { c.entry } else { 1 - c.entry };
        joints_attached_to(joints, leaving)
            .into_iter()
            .all(|joint| {
                joints.bodies_of(joint).is_ok_and(|(a, b)| {
                    let other = if a == leaving { b } else { a };
                    other == staying || self.twin_across(other, c.pair, leaving_side).is_some()
                })
            })
    }

    /// True when the copy that crossing `k` would remove (the original when
    /// it completes, `complete`, the clone when it backs out) lies within
    /// its portal's span (`|t| ≤ w` for all its shapes): only such a copy
    /// is held for its joints. One that has slid beside the aperture,
    /// behind the wall, ends its crossing and its joints that cannot follow
    /// are disabled.
    fn within_span(&self, k: usize, complete: bool, stores: &Stores<'_>) -> bool {
        let c = &self.crossings[k];
        let d = self.pairs.at(c.pair).expect("live pair");
        let (body, side) = if complete {
            (c.original, c.entry)
        } else {
            (c.clone, 1 - c.entry)
        };
        let f = frame_in(stores.bodies, &d.portals[side], &d.local[side]);
        let w = d.local[side].half_width;
        // Held against a side wall, it may press into it by the contacts'
        // slop.
        let w = w + SPAN_SLACK;
        extents_in(stores.bodies, &stores.collision.shapes, body, &f)
            .is_some_and(|(_, _, t0, t1)| t0 >= -w && t1 <= w)
    }

    /// The other copy of `body` through pair slot `pair`, when `body` is
    /// the copy in front of portal `side` of a crossing through it: the
    /// twin, and the scale from `body`'s frame to the twin's about their
    /// common local centre of mass (`(twin, centre, scale)`).
    fn twin_across(
        &self,
        body: BodyHandle,
        pair: u32,
        side: usize,
    ) -> Option<(BodyHandle, Vec2, Real)> {
        self.crossings
            .iter()
            .zip(&self.constraints)
            .find_map(|(m, pc)| {
                if m.pair != pair {
                    return None;
                }
                let eta = pc.def().eta;
                if m.original == body && m.entry == side {
                    Some((m.clone, m.mass_original.center, eta))
                } else if m.clone == body && 1 - m.entry == side {
                    Some((m.original, m.mass_original.center, 1.0 / eta))
                } else {
                    None
                }
            })
    }

    /// The scale `η` of crossing `c` (entry to exit).
    fn crossing_eta(&self, c: &Crossing) -> Real {
        let d = self.pairs.at(c.pair).expect("live pair");
        if c.entry == 0 { d.eta } else { 1.0 / d.eta }
    }

    /// The rotation `Q` of crossing `c`'s map (entry to exit), now.
    fn crossing_rotation(&self, c: &Crossing, bodies: &BodySet) -> Rot {
        let d = self.pairs.at(c.pair).expect("live pair");
        let f1 = frame_in(bodies, &d.portals[c.entry], &d.local[c.entry]);
        let f2 = frame_in(bodies, &d.portals[1 - c.entry], &d.local[1 - c.entry]);
        PortalMap {
            frame1: f1,
            frame2: f2,
            eta: 1.0,
        }
        .rotation()
    }

    /// Carries joint `joint` through crossing `c`: its end on `from` moves
    /// to `to` (`(from, to)`; anchor scaled by `scale` about the object's
    /// local centre of mass), its other end to that body's copy on the
    /// same side (scaled the same way), and its impulses turn by `q` and
    /// scale by `impulse_scale`. Its other body having no copy there (a
    /// forced end of the crossing), the joint is disabled and reported.
    #[allow(clippy::too_many_arguments)]
    fn carry_joint(
        &mut self,
        joint: JointHandle,
        c: &Crossing,
        (from, to): (BodyHandle, BodyHandle),
        scale: Real,
        q: Rot,
        impulse_scale: Real,
        stores: &mut Stores<'_>,
    ) {
        let Ok((a, b)) = stores.joints.bodies_of(joint) else {
            return;
        };
        let other = if a == from { b } else { a };
        let leaving_side = if from == c.original {
            c.entry
        } else {
            1 - c.entry
        };
        let twin = self.twin_across(other, c.pair, leaving_side);
        let center = c.mass_original.center;
        if let Some(anchor) = anchor_on(stores.joints, joint, from) {
            stores.apply(PortalCommand::RepointJoint {
                joint,
                from,
                to,
                anchor: center + scale * (anchor - center),
            });
        }
        match twin {
            Some((other_twin, other_center, other_scale)) => {
                if let Some(anchor) = anchor_on(stores.joints, joint, other) {
                    let anchor = other_center + other_scale * (anchor - other_center);
                    stores.apply(PortalCommand::RepointJoint {
                        joint,
                        from: other,
                        to: other_twin,
                        anchor,
                    });
                }
                if let Ok(j) = stores.joints.joint_mut(joint) {
                    j.carry_through_portal(q, impulse_scale);
                }
            }
            None => {
                stores.apply(PortalCommand::DisableJoint(joint));
                let pair = self.pair_handle(c.pair, stores.bodies.owner());
                self.pending_events
                    .push(PortalEvent::JointDisabled { joint, pair });
            }
        }
    }
}

/// A joint's local anchor on `body` (`None` when `body` is neither end).
fn anchor_on(joints: &JointSet, joint: JointHandle, body: BodyHandle) -> Option<Vec2> {
    joints.get(joint).ok()?.local_anchor_on(body)
}

/// Sets a crossing copy's (weighted) mass, velocity unchanged. The mass
/// that leaves (or enters) through the portal carries its momentum to
/// (or from) the portal body, so with a dynamic portal body the total
/// linear and angular momentum is unchanged:
///
/// ```text
/// Δm = m_old − m_new,  ΔI = I_old − I_new
/// portal body:  linear impulse Δm v at the copy's centre x,
///               angular impulse ΔI ω
/// ```
///
/// Static and kinematic portal bodies absorb it (infinite mass).
fn set_copy_mass(
    stores: &mut Stores<'_>,
    body: BodyHandle,
    new: BodyMass,
    portal_body: BodyHandle,
) {
    let Some(b) = stores.bodies.sim(body).copied() else {
        return;
    };
    if stores.bodies.body_type(portal_body) == Some(BodyType::Dynamic) {
        let st = *stores.bodies.state(body).expect("live");
        let dm = b.mass - new.mass;
        let di = b.inertia - new.rotational_inertia;
        push_body(stores, portal_body, dm * st.v, b.center, di * st.w);
    }
    if new.mass > 0.0 {
        apply_mass_keep_velocity(stores.bodies, body, new);
    }
}

/// The momentum of `body` as if its mass went from `from` to `to`
/// (velocity fixed) is exchanged with the portal body: the portal body
/// receives `(m_from − m_to) v` at the copy's centre and
/// `(I_from − I_to) ω`. Used when a copy appears (`from` = 0) or
/// disappears (`to` = 0) as a whole.
fn exchange_with_portal(
    stores: &mut Stores<'_>,
    body: BodyHandle,
    from: (Real, Real),
    to: (Real, Real),
    portal_body: BodyHandle,
) {
    if stores.bodies.body_type(portal_body) != Some(BodyType::Dynamic) {
        return;
    }
    let Some(b) = stores.bodies.sim(body).copied() else {
        return;
    };
    let st = *stores.bodies.state(body).expect("live");
    push_body(
        stores,
        portal_body,
        (from.0 - to.0) * st.v,
        b.center,
        (from.1 - to.1) * st.w,
    );
}
