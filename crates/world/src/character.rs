//! A character controller on top of the mover
//! ([`World::cast_mover`], [`World::collide_mover`],
//! [`solve_planes`]): a capsule that the game
//! moves (not a body), with Rapier's conveniences.
//!
//! | setting            | what                                                              |
//! |--------------------|-------------------------------------------------------------------|
//! | `max_slope`        | steepest ground it walks up; steeper faces are walls it slides down |
//! | `autostep`         | steps up a ledge at most `max_height` high with `min_width` of room on top |
//! | `snap_to_ground`   | follows the ground down slopes and stairs up to this drop          |
//! | `one_way_bits`     | shapes in these filter categories block only from above            |
//! | `skin`             | the gap kept between the capsule and what it touches              |
//!
//! **Moving platforms.** The controller remembers the ground point it
//! stands on; at the next move it is first carried by what that point did
//! meanwhile (the ground body's velocity at the contact point times the
//! step, rotation included), against walls like any move.
//!
//! **One move** ([`CharacterController::move_and_slide`]):
//! 1. carried by the ground (moving platforms);
//! 2. the ground under it found; on the ground, the wanted displacement
//!    `velocity · dt` loses its downward part and follows the ground's slope
//!    (full speed up a walkable slope);
//! 3. slide: collide (planes), solve the planes, sweep the capsule along the
//!    answer ([`World::cast_mover`]: never tunnels), until it stops; a face
//!    steeper than `max_slope` also gets a vertical wall plane, so the
//!    character does not climb it but slides down it;
//! 4. blocked by a face too steep to walk while on the ground: try a step
//!    (up, across, down onto walkable ground at most `max_height` above
//!    the ground it stood on);
//! 5. off the ground after walking: slide down at most `snap_to_ground`,
//!    kept if it ends on walkable ground (a rounded bottom rolling off an
//!    edge slips past the corner onto the step below);
//! 6. the velocity clipped against what it touches; the ground remembered.
//!
//! **Portals** (when the filter has
//! [`through_portals`](QueryFilter::through_portals)). A portal's wall is
//! not solid inside its aperture, and its lips are; while part of the
//! capsule is in an aperture, what that part meets on the far side stops
//! it too ([`World::cast_mover`], [`World::collide_mover`]). When the
//! capsule's centre crosses an aperture's plane within its span
//! ([`World::mover_crossing`]), the character goes through: its centre is
//! mapped to the partner portal (`T(x) = P₂ + η Q (x − P₁)`), its capsule
//! scaled by `η` about the reference point (radius and core × η; it stays
//! upright: the capsule is not turned by `Q`, the character keeps `up`),
//! the rest of the move and the velocity mapped by `η Q` (relative to the
//! portals' own motion). [`MoveResult::capsule`] is the capsule to use from
//! then on, [`MoveResult::crossings`] lists the apertures crossed.
//!
//! **Bodies.** Static, kinematic and dynamic shapes are all obstacles; the
//! character pushes nothing (it is not a body).

use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::geometry::{Capsule, LINEAR_SLOP, Shape};
use janus2d_core::math::{PI, Real, Vec2, vec_is_finite};

use crate::World;
use crate::error::WorldError;
use crate::mover::{
    CollisionPlane, MoverCast, MoverCrossing, PlaneResult, clip_vector, lateral, solve_planes,
};
use crate::query::{QueryFilter, QueryProblem, RayHit};
use crate::shapes::ShapeHandle;

/// Extra distance beyond `skin` within which a shape counts as touched,
/// m (usual 0.01 = 2 · [`LINEAR_SLOP`]).
///
/// ```
/// use janus2d_world::character::{CONTACT_MARGIN, ONE_WAY_DEPTH};
/// assert!(CONTACT_MARGIN > 0.0 && CONTACT_MARGIN < ONE_WAY_DEPTH);
/// ```
pub const CONTACT_MARGIN: Real = 2.0 * LINEAR_SLOP;

/// How deep (m) the capsule may be in a one-way shape and still stand on it
/// (usual 0.02 = 4 · [`LINEAR_SLOP`]): deeper, it is passing through.
///
/// ```
/// use janus2d_core::geometry::LINEAR_SLOP;
/// assert_eq!(janus2d_world::character::ONE_WAY_DEPTH, 4.0 * LINEAR_SLOP);
/// ```
pub const ONE_WAY_DEPTH: Real = 4.0 * LINEAR_SLOP;

/// A slide stops when the plane solver moves it less than this, m (usual
/// 5e-5 = [`LINEAR_SLOP`] / 100).
///
/// ```
/// use janus2d_core::geometry::LINEAR_SLOP;
/// assert!(janus2d_world::character::SLIDE_TOLERANCE < LINEAR_SLOP);
/// ```
pub const SLIDE_TOLERANCE: Real = 0.01 * LINEAR_SLOP;

/// Stepping up ledges (Rapier's autostep).
///
/// ```
/// use janus2d_world::character::{Autostep, CharacterController};
/// let a = Autostep::default();
/// assert_eq!((a.max_height, a.min_width), (0.3, 0.1));
/// let cc = CharacterController::new().with_autostep(Some(Autostep { max_height: 0.25, ..a }));
/// assert_eq!(cc.autostep.unwrap().max_height, 0.25);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Autostep {
    /// Highest ledge stepped up, m, measured from the ground point the
    /// character stands on to where it lands on the ledge (usual 0.3).
    pub max_height: Real,
    /// Least free room on top of the ledge, m: a step moves the character
    /// at least this far onto it (usual 0.1).
    pub min_width: Real,
}

impl Default for Autostep {
    fn default() -> Self {
        Autostep {
            max_height: 0.3,
            min_width: 0.1,
        }
    }
}

/// The ground a character stands on.
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef, QueryFilter};
/// use janus2d_world::character::CharacterController;
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::{Capsule, Polygon};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5))).unwrap();
/// world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5)).unwrap();
/// let capsule = Capsule::new(Vec2::new(0.0, 0.25), Vec2::new(0.0, 0.75), 0.25).unwrap();
/// let mut cc = CharacterController::new();
/// let r = cc.move_and_slide(&world, &capsule, Vec2::new(0.0, 0.01), Vec2::new(1.0, -1.0), 1.0 / 60.0, &QueryFilter::default()).unwrap();
/// let ground = r.ground.unwrap();
/// assert_eq!(ground.body, floor);
/// assert!((ground.normal - Vec2::Y).length() < 1e-3 && ground.point.y.abs() < 1e-3);
/// assert_eq!(ground.velocity, Vec2::ZERO);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ground {
    /// The shape.
    pub shape: ShapeHandle,
    /// Its body.
    pub body: BodyHandle,
    /// The ground's unit normal at the contact.
    pub normal: Vec2,
    /// The contact point on the ground's surface, world, m.
    pub point: Vec2,
    /// The ground's velocity at that point, m/s (a moving platform's).
    pub velocity: Vec2,
}

/// What one [`CharacterController::move_and_slide`] did.
///
/// ```
/// use janus2d_world::{ShapeDef, World, WorldDef, QueryFilter};
/// use janus2d_world::character::CharacterController;
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::{Capsule, Polygon};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let floor = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5))).unwrap();
/// world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5)).unwrap();
/// let capsule = Capsule::new(Vec2::new(0.0, 0.25), Vec2::new(0.0, 0.75), 0.25).unwrap();
/// let mut cc = CharacterController::new();
/// let r = cc.move_and_slide(&world, &capsule, Vec2::new(0.0, 0.01), Vec2::new(3.0, -1.0), 0.5, &QueryFilter::default()).unwrap();
/// assert!(r.grounded && !r.stepped);
/// assert!((r.position.x - 1.5).abs() < 1e-3, "walked 3 m/s for 0.5 s: {:?}", r.position);
/// assert!(r.velocity.y.abs() < 1e-3, "the floor absorbed the downward part");
/// assert_eq!(r.carried, Vec2::ZERO);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct MoveResult {
    /// Where the character is now (the capsule's reference point), m.
    pub position: Vec2,
    /// The velocity given, less what points into what it touches, m/s.
    pub velocity: Vec2,
    /// Standing on walkable ground at the end of the move.
    pub grounded: bool,
    /// That ground.
    pub ground: Option<Ground>,
    /// How far the ground carried it before it moved (moving platforms), m.
    pub carried: Vec2,
    /// It stepped up a ledge.
    pub stepped: bool,
    /// It was snapped down to the ground.
    pub snapped: bool,
    /// Collide–solve–cast rounds used.
    pub iterations: usize,
    /// What it touches at the end (within `skin` + [`CONTACT_MARGIN`]).
    pub contacts: Vec<PlaneResult>,
    /// The character's capsule now, relative to `position`: the one given,
    /// scaled by the `η` of every portal crossed (use it for the next move).
    pub capsule: Capsule,
    /// The portal apertures its centre went through, in order (empty
    /// unless the filter has `through_portals`).
    pub crossings: Vec<MoverCrossing>,
    /// The product of the crossings' `η`: how much the character grew
    /// (1 without a crossing).
    pub scale: Real,
}

/// Where the character stood: a point fixed in the ground body.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Anchor {
    body: BodyHandle,
    local: Vec2,
    world: Vec2,
}

/// A kinematic capsule character: slope limit, autostep, snap to ground,
/// one-way platforms, moving platforms (see the [module docs](self)).
///
/// The settings are public fields; the controller also remembers the ground
/// it stood on (for moving platforms), so keep one controller per
/// character.
///
/// ```
/// use janus2d_world::{World, WorldDef, ShapeDef, QueryFilter};
/// use janus2d_world::character::CharacterController;
/// use janus2d_core::{BodyDef, Vec2};
/// use janus2d_core::geometry::{Capsule, Polygon};
/// let mut world = World::new(WorldDef::default()).unwrap();
/// let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5))).unwrap();
/// world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5)).unwrap();
/// let capsule = Capsule::new(Vec2::new(0.0, 0.25), Vec2::new(0.0, 0.75), 0.25).unwrap();
/// let mut cc = CharacterController::new();
/// let (mut p, dt) = (Vec2::new(0.0, 0.01), 1.0 / 60.0); // standing a skin up
/// for _ in 0..60 {
///     let r = cc.move_and_slide(&world, &capsule, p, Vec2::new(2.0, -10.0), dt, &QueryFilter::default()).unwrap();
///     p = r.position;
///     // On the floor, the fall is clipped off the velocity.
///     assert!(r.grounded && r.velocity.y.abs() < 1e-3);
/// }
/// // A second at 2 m/s along the floor, standing on it a skin above.
/// assert!((p.x - 2.0).abs() < 0.01 && p.y > 0.0 && p.y < 0.02, "{p}");
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct CharacterController {
    /// The up direction, unit (usual (0, 1)).
    pub up: Vec2,
    /// Steepest ground the character walks up, rad, in `[0, π/2)` (usual
    /// π/4).
    pub max_slope: Real,
    /// Gap kept between the capsule and what it touches, m (usual 0.01).
    pub skin: Real,
    /// Stepping up ledges (usual on: [`Autostep::default`]).
    pub autostep: Option<Autostep>,
    /// Largest drop the character is snapped down when walking off a ledge
    /// or down a slope, m (usual `Some(0.2)`).
    pub snap_to_ground: Option<Real>,
    /// Filter categories of one-way platforms: a shape whose
    /// `category_bits` meets these blocks only from above (usual 0: none).
    pub one_way_bits: u64,
    /// Most collide–solve–cast rounds of a slide (usual 5).
    pub max_iterations: usize,
    anchor: Option<Anchor>,
}

impl Default for CharacterController {
    fn default() -> Self {
        CharacterController {
            up: Vec2::Y,
            max_slope: PI / 4.0,
            skin: 2.0 * LINEAR_SLOP,
            autostep: Some(Autostep::default()),
            snap_to_ground: Some(0.2),
            one_way_bits: 0,
            max_iterations: 5,
            anchor: None,
        }
    }
}

/// What a move reads of the world at one pose.
struct Touch {
    contacts: Vec<PlaneResult>,
    /// One-way shapes the capsule is passing through (ignored by casts).
    passing: Vec<ShapeHandle>,
}

impl CharacterController {
    /// The default controller (see the field docs).
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// let cc = CharacterController::new();
    /// assert_eq!(cc.autostep.unwrap().max_height, 0.3);
    /// ```
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets the steepest walkable slope, rad (builder style).
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// let cc = CharacterController::new().with_max_slope(0.5);
    /// assert_eq!(cc.max_slope, 0.5);
    /// ```
    #[must_use]
    pub fn with_max_slope(mut self, radians: Real) -> Self {
        self.max_slope = radians;
        self
    }

    /// Sets or turns off autostep (builder style).
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// assert!(CharacterController::new().with_autostep(None).autostep.is_none());
    /// ```
    #[must_use]
    pub fn with_autostep(mut self, autostep: Option<Autostep>) -> Self {
        self.autostep = autostep;
        self
    }

    /// Sets or turns off snapping to the ground (builder style).
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// assert_eq!(CharacterController::new().with_snap_to_ground(Some(0.5)).snap_to_ground, Some(0.5));
    /// ```
    #[must_use]
    pub fn with_snap_to_ground(mut self, distance: Option<Real>) -> Self {
        self.snap_to_ground = distance;
        self
    }

    /// Sets the filter categories of one-way platforms (builder style).
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// assert_eq!(CharacterController::new().with_one_way_bits(0b100).one_way_bits, 4);
    /// ```
    #[must_use]
    pub fn with_one_way_bits(mut self, bits: u64) -> Self {
        self.one_way_bits = bits;
        self
    }

    /// Forgets the remembered ground (after teleporting the character), so
    /// that the next move is not carried.
    ///
    /// ```
    /// use janus2d_world::character::CharacterController;
    /// let mut cc = CharacterController::new();
    /// cc.forget_ground();
    /// ```
    pub fn forget_ground(&mut self) {
        self.anchor = None;
    }

    fn check(&self) -> Result<(), WorldError> {
        let range = |ok: bool, field: &'static str| {
            if ok {
                Ok(())
            } else {
                Err(WorldError::OutOfRange(field))
            }
        };
        range(
            vec_is_finite(self.up) && (self.up.length() - 1.0).abs() < 1e-3,
            "up",
        )?;
        range(
            self.max_slope.is_finite() && self.max_slope >= 0.0 && self.max_slope < 0.5 * PI,
            "max_slope",
        )?;
        range(self.skin.is_finite() && self.skin >= 0.0, "skin")?;
        if let Some(a) = self.autostep {
            range(
                a.max_height.is_finite() && a.max_height >= 0.0,
                "max_height",
            )?;
            range(a.min_width.is_finite() && a.min_width >= 0.0, "min_width")?;
        }
        if let Some(d) = self.snap_to_ground {
            range(d.is_finite() && d >= 0.0, "snap_to_ground")?;
        }
        range(self.max_iterations >= 1, "max_iterations")
    }

    /// Moves the character whose shape is `capsule` (relative to
    /// `position`) from `position` with `velocity` for `dt` seconds against
    /// the shapes `filter` accepts (leave out the character's own body with
    /// [`QueryFilter::excluding`] if it has one), and returns where it ended
    /// (see the [module docs](self) for the steps).
    ///
    /// Gravity is the caller's: add it to `velocity` while the character is
    /// in the air; on the ground the downward part of `velocity` is absorbed.
    /// The world is not changed.
    ///
    /// Errors: an invalid capsule (non-positive radius, …: `BadQuery {
    /// field: "mover" }`), a non-finite `position` or `velocity`
    /// (`NonFinite`), a `dt` not finite and positive (`InvalidTimeStep`), a
    /// setting out of its range (`OutOfRange` naming it).
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, WorldError, QueryFilter};
    /// use janus2d_world::character::CharacterController;
    /// use janus2d_core::Vec2;
    /// use janus2d_core::geometry::Capsule;
    /// let world = World::new(WorldDef::default()).unwrap();
    /// let bad = Capsule { center1: Vec2::ZERO, center2: Vec2::Y, radius: -1.0 };
    /// let mut cc = CharacterController::new();
    /// let r = cc.move_and_slide(&world, &bad, Vec2::ZERO, Vec2::X, 0.1, &QueryFilter::default());
    /// assert!(matches!(r, Err(WorldError::BadQuery { field: "mover", .. })));
    /// ```
    pub fn move_and_slide(
        &mut self,
        world: &World,
        capsule: &Capsule,
        position: Vec2,
        velocity: Vec2,
        dt: Real,
        filter: &QueryFilter,
    ) -> Result<MoveResult, WorldError> {
        self.check()?;
        Shape::Capsule(*capsule)
            .validate()
            .map_err(|e| WorldError::BadQuery {
                field: "mover",
                problem: QueryProblem::Shape(e),
            })?;
        if !vec_is_finite(position) {
            return Err(WorldError::NonFinite("position"));
        }
        if !vec_is_finite(velocity) {
            return Err(WorldError::NonFinite("velocity"));
        }
        if !dt.is_finite() || dt <= 0.0 {
            return Err(WorldError::InvalidTimeStep);
        }
        let mut mv = Mover {
            cc: self,
            world,
            capsule: *capsule,
            filter,
            cos_slope: self.max_slope.cos(),
            crossings: Vec::new(),
        };
        let mut iterations = 0;

        // 1. Carried by the ground since the last move.
        let mut pos = position;
        let mut carried = Vec2::ZERO;
        if let Some(a) = self.anchor
            && let Ok(ty) = world.body_type(a.body)
            && ty != BodyType::Static
            && let Ok(xf) = world.transform(a.body)
        {
            let carry = xf.apply(a.local) - a.world;
            if vec_is_finite(carry) && carry.length_squared() > 0.0 {
                let (p, n) = mv.slide(pos, carry)?;
                iterations += n;
                carried = p - pos;
                pos = p;
            }
        }

        // Carried through a portal: the velocity goes through too.
        let mut velocity = velocity;
        for c in &mv.crossings {
            velocity = world.mover_velocity_through(c, velocity)?;
        }
        let carried_crossings = mv.crossings.len();

        // 2. The ground under it; the wanted displacement along it.
        let start_ground = mv.ground(&mv.touch(pos)?.contacts);
        let desired = velocity * dt;
        let rising = desired.dot(self.up) > 0.0;
        let on_ground = start_ground.is_some() && !rising;
        let delta = match start_ground {
            Some(g) if !rising => {
                let lat = lateral(desired, self.up);
                // Along the ground, and down onto it by what exceeds the skin.
                lat - (g.normal.dot(lat) / g.normal.dot(self.up)) * self.up
                    - (g.separation - self.skin).max(0.0) * g.normal
            }
            _ => desired,
        };

        // 3. Slide.
        let before = pos;
        let crossed_before_walk = mv.crossings.len();
        let (mut p, n) = mv.slide(pos, delta)?;
        iterations += n;

        // 4. Blocked on the ground: a step (not after a portal).
        let mut stepped = false;
        let lat = lateral(delta, self.up);
        let lat_len = lat.length();
        if on_ground && lat_len > 0.0 && mv.crossings.len() == crossed_before_walk {
            let dir = lat / lat_len;
            let progress = (p - before).dot(dir);
            if progress < lat_len - 0.1 * LINEAR_SLOP
                && let Some(a) = self.autostep
                && let Some(g) = start_ground
                && mv.walled(p, dir)?
                && let Some(q) = mv.step(p, dir, lat_len - progress, g.point, a)?
            {
                p = q;
                stepped = true;
            }
        }

        // 5. Walked off the ground: snap down to it.
        let mut touch = mv.touch(p)?;
        let mut ground = mv.ground(&touch.contacts);
        let mut snapped = false;
        if on_ground
            && !stepped
            && ground.is_none()
            && let Some(d) = self.snap_to_ground
            && d > 0.0
        {
            // A slide down, so that a rounded bottom rolling off an edge
            // slips past the corner onto the ground below.
            let (q, n) = mv.slide(p, -d * self.up)?;
            iterations += n;
            let t = mv.touch(q)?;
            if let Some(g) = mv.ground(&t.contacts) {
                p = q;
                snapped = true;
                touch = t;
                ground = Some(g);
            }
        }

        // 6. Velocity clipped; the ground remembered.
        let planes: Vec<CollisionPlane> = touch
            .contacts
            .iter()
            .flat_map(|c| mv.planes_of(c))
            .collect();
        for c in &mv.crossings[carried_crossings..] {
            velocity = world.mover_velocity_through(c, velocity)?;
        }
        let velocity = clip_vector(velocity, &planes);
        let Mover {
            capsule: now,
            crossings,
            ..
        } = mv;
        let scale = crossings.iter().map(|c| c.map.eta).product();
        let ground = match ground {
            Some(g) => Some(Ground {
                shape: g.shape,
                body: g.body,
                normal: g.normal,
                point: g.point,
                velocity: world.mover_point_velocity(g.body, g.point)?,
            }),
            None => None,
        };
        self.anchor = match ground {
            Some(g) => {
                let xf = world.transform(g.body)?;
                Some(Anchor {
                    body: g.body,
                    local: xf.apply_inv(g.point),
                    world: g.point,
                })
            }
            None => None,
        };
        Ok(MoveResult {
            position: p,
            velocity,
            grounded: ground.is_some(),
            ground,
            carried,
            stepped,
            snapped,
            iterations,
            contacts: touch.contacts,
            capsule: now,
            crossings,
            scale,
        })
    }
}

/// One move's view: the controller's settings, the world, the capsule.
struct Mover<'a> {
    cc: &'a CharacterController,
    world: &'a World,
    capsule: Capsule,
    filter: &'a QueryFilter<'a>,
    cos_slope: Real,
    /// The portals crossed so far (the capsule is scaled by each).
    crossings: Vec<MoverCrossing>,
}

impl Mover<'_> {
    fn placed(&self, pos: Vec2, grow: Real) -> Capsule {
        Capsule {
            center1: self.capsule.center1 + pos,
            center2: self.capsule.center2 + pos,
            radius: self.capsule.radius + grow,
        }
    }

    fn is_one_way(&self, shape: ShapeHandle) -> bool {
        self.cc.one_way_bits != 0
            && self
                .world
                .shape(shape)
                .is_ok_and(|s| s.def.filter.category_bits & self.cc.one_way_bits != 0)
    }

    /// What the capsule at `pos` touches (within skin + margin), without the
    /// one-way shapes it is passing through.
    fn touch(&self, pos: Vec2) -> Result<Touch, WorldError> {
        let mut contacts = Vec::new();
        let mut passing = Vec::new();
        self.world.collide_mover(
            &self.placed(pos, 0.0),
            self.cc.skin + CONTACT_MARGIN,
            self.filter,
            |c| {
                if self.is_one_way(c.shape)
                    && (c.normal.dot(self.cc.up) < self.cos_slope || c.separation < -ONE_WAY_DEPTH)
                {
                    if c.separation < 0.0 {
                        passing.push(c.shape);
                    }
                } else {
                    contacts.push(*c);
                }
                true
            },
        )?;
        Ok(Touch { contacts, passing })
    }

    /// The walkable contact nearest the capsule (ties: first in slot order).
    fn ground(&self, contacts: &[PlaneResult]) -> Option<PlaneResult> {
        let mut best: Option<PlaneResult> = None;
        for c in contacts {
            if c.normal.dot(self.cc.up) >= self.cos_slope
                && best.is_none_or(|b| c.separation < b.separation)
            {
                best = Some(*c);
            }
        }
        best
    }

    /// The solver planes of a contact: its own, and for a face too steep to
    /// walk (not a ceiling) a vertical wall that stops walking into it.
    fn planes_of(&self, c: &PlaneResult) -> impl Iterator<Item = CollisionPlane> {
        let up = self.cc.up;
        let own = CollisionPlane::new(c.normal, self.cc.skin - c.separation);
        let rise = c.normal.dot(up);
        let wall = if rise < self.cos_slope && rise > 0.0 {
            let h = lateral(c.normal, up);
            let len = h.length();
            (len > 0.0).then(|| CollisionPlane::new(h / len, (own.offset / len).min(0.0)))
        } else {
            None
        };
        std::iter::once(own).chain(wall)
    }

    /// Sweeps the capsule (grown by the skin) from `pos` along `delta`,
    /// one-way shapes blocking only from above.
    fn cast(
        &self,
        pos: Vec2,
        delta: Vec2,
        passing: &[ShapeHandle],
    ) -> Result<MoverCast, WorldError> {
        let accept = |hit: &RayHit| {
            if !self.is_one_way(hit.shape) {
                return true;
            }
            !passing.contains(&hit.shape) && hit.normal.dot(self.cc.up) >= self.cos_slope
        };
        self.world
            .cast_mover_with(&self.placed(pos, self.cc.skin), delta, self.filter, accept)
    }

    /// Collide, solve, cast until the capsule stops: `(end, rounds)`. A
    /// cast whose centre reaches a portal aperture stops there; the
    /// character goes through (see [`Mover::cross`]) and the rest of the
    /// move goes on from the far side.
    fn slide(&mut self, pos: Vec2, delta: Vec2) -> Result<(Vec2, usize), WorldError> {
        let mut target = pos + delta;
        let mut p = pos;
        let mut rounds = 0;
        for _ in 0..self.cc.max_iterations {
            rounds += 1;
            let touch = self.touch(p)?;
            let mut planes: Vec<CollisionPlane> = touch
                .contacts
                .iter()
                .flat_map(|c| self.planes_of(c))
                .collect();
            let solution = solve_planes(target - p, &mut planes).translation;
            if !vec_is_finite(solution) || solution.length() < SLIDE_TOLERANCE {
                break;
            }
            let crossing = if self.filter.through_portals {
                self.world
                    .mover_crossing(&self.placed(p, 0.0), solution, self.filter)?
            } else {
                None
            };
            let reach = crossing.map_or(1.0, |c| c.fraction) * solution;
            let cast = self.cast(p, reach, &touch.passing)?;
            p += cast.fraction * reach;
            if let Some(c) = crossing
                && cast.fraction >= 1.0
            {
                let rest = target - p;
                p = self.cross(&c, p);
                target = p + c.map.map_vector(rest);
            }
        }
        Ok((p, rounds))
    }

    /// Takes the character at `pos`, its centre on the aperture of `c`,
    /// through to the partner portal: the centre mapped, the capsule scaled
    /// by `η` about the reference point. Returns the new reference point.
    fn cross(&mut self, c: &MoverCrossing, pos: Vec2) -> Vec2 {
        let eta = c.map.eta;
        let centre = 0.5 * (self.capsule.center1 + self.capsule.center2);
        let out = c.map.map_point(pos + centre) - eta * centre;
        self.capsule = Capsule {
            center1: eta * self.capsule.center1,
            center2: eta * self.capsule.center2,
            radius: eta * self.capsule.radius,
        };
        self.crossings.push(*c);
        out
    }

    /// Whether the capsule at `pos` touches a face too steep to walk that
    /// faces against `dir` (what a step may get over).
    fn walled(&self, pos: Vec2, dir: Vec2) -> Result<bool, WorldError> {
        let up = self.cc.up;
        Ok(self
            .touch(pos)?
            .contacts
            .iter()
            .any(|c| c.normal.dot(up) < self.cos_slope && c.normal.dot(dir) < 0.0))
    }

    /// A step up from `pos` (blocked walking along `dir` with `remaining`
    /// to go, standing on the ground at `foot`): up by the step height,
    /// across, down onto walkable ground whose edge is at most the step
    /// height above `foot`.
    fn step(
        &self,
        pos: Vec2,
        dir: Vec2,
        remaining: Real,
        foot: Vec2,
        a: Autostep,
    ) -> Result<Option<Vec2>, WorldError> {
        let up = self.cc.up;
        if a.max_height <= 0.0 {
            return Ok(None);
        }
        let passing = self.touch(pos)?.passing;
        let lift = self.cast(pos, a.max_height * up, &passing)?;
        let rise = lift.fraction * a.max_height;
        if rise <= LINEAR_SLOP {
            return Ok(None);
        }
        let high = pos + rise * up;
        // Far enough for the rounded bottom to rest on the ledge's top.
        let rounding = self.capsule.radius * (1.0 - self.cc.max_slope.sin()) + self.cc.skin;
        let across = remaining.max(a.min_width).max(rounding);
        let passing = self.touch(high)?.passing;
        if self.cast(high, across * dir, &passing)?.fraction < 1.0 {
            return Ok(None);
        }
        let over = high + across * dir;
        let drop = rise + CONTACT_MARGIN;
        let passing = self.touch(over)?.passing;
        let down = self.cast(over, -drop * up, &passing)?;
        let Some(hit) = down.hit else {
            return Ok(None);
        };
        let landed = over - down.fraction * drop * up;
        let ledge = (hit.point - foot).dot(up);
        if hit.normal.dot(up) < self.cos_slope
            || (landed - pos).dot(up) <= LINEAR_SLOP
            || ledge > a.max_height
        {
            return Ok(None);
        }
        Ok(Some(landed))
    }
}
