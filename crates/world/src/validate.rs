//! The world validator: every cross-structure invariant, checked on demand.
//!
//! [`World::validate`] runs each stage's own check in the order below and
//! returns the first broken invariant as an [`InvariantError`]. It reads
//! only, allocates little, and costs nothing unless called (tests, debug
//! tools, a fuzzer after every operation).
//!
//! | [`Invariant`]    | checked by                 | what                                                              |
//! |------------------|----------------------------|-------------------------------------------------------------------|
//! | `Bodies`         | `BodySet::check_invariants`, `World::check_disabled` | handles ↔ slots ↔ arrays, sentinel, finite numbers, settings in range, lock bits, fixed rotation ⇒ no inverse inertia, dynamic mass; disabled bodies out of the solver, the islands and the contacts, the joints kept off for them off |
//! | `Shapes`         | `ShapeStore::check`, `World::check_chains` | shapes ↔ bodies ↔ body lists, valid geometry, finite boxes; chains ↔ live segment shapes of one body |
//! | `Proxies`        | `Collision::check_proxies` | shapes ↔ broadphase proxies, tree by type, fat box ⊇ shape box    |
//! | `Contacts`       | `ContactSet::check`        | contacts ↔ pair index ↔ per-body lists, sleep lists, finite data  |
//! | `Joints`         | `JointSet::check`          | joint handles ↔ slots ↔ bodies ↔ body lists, definitions valid, no-collide pairs |
//! | `Islands`        | `Islands::check`           | islands ↔ dynamic bodies, positions, sleeping islands asleep      |
//! | `Portals`        | `PortalStage::check`       | pairs ↔ crossings ↔ clones ↔ portal constraints                   |
//! | `World`          | here                       | gravity and settings finite and within their limits               |
//!
//! The contact colouring is rebuilt at every step from the contacts and
//! kept inside the contact solver, which exposes only per-colour counts:
//! the validator checks that those add up to the touching contacts.

use crate::world::World;

/// Which invariant broke.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Invariant {
    /// Body handles, slots and arrays.
    Bodies,
    /// Shapes and their bodies.
    Shapes,
    /// Shapes and broadphase proxies.
    Proxies,
    /// Contacts, pairs and per-body lists.
    Contacts,
    /// Joints and their bodies.
    Joints,
    /// Islands, bodies and sleep state.
    Islands,
    /// Portal pairs, crossings, clones and constraints.
    Portals,
    /// World-level values (gravity, settings, colour counts).
    World,
}

/// The first broken invariant [`World::validate`] found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InvariantError {
    /// The invariant.
    pub invariant: Invariant,
    /// What is wrong, in words.
    pub detail: String,
}

impl std::fmt::Display for InvariantError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:?} invariant broken: {}", self.invariant, self.detail)
    }
}

impl std::error::Error for InvariantError {}

fn tag(invariant: Invariant) -> impl FnOnce(String) -> InvariantError {
    move |detail| InvariantError { invariant, detail }
}

impl World {
    /// Checks every cross-structure invariant of the world (see
    /// [`Invariant`]) and returns the first one broken. A world
    /// reached through the public API always passes.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, ShapeDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// use janus2d_core::geometry::Polygon;
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let b = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.0))).unwrap();
    /// world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
    /// world.step(1.0 / 60.0).unwrap();
    /// assert_eq!(world.validate(), Ok(()));
    /// ```
    pub fn validate(&self) -> Result<(), InvariantError> {
        use Invariant as I;
        let bodies = &self.bodies;
        bodies.check_invariants().map_err(tag(I::Bodies))?;
        let c = &self.collision;
        c.shapes.check(bodies).map_err(tag(I::Shapes))?;
        self.check_chains().map_err(tag(I::Shapes))?;
        c.check_proxies(bodies).map_err(tag(I::Proxies))?;
        c.contacts
            .check(bodies, &c.shapes)
            .map_err(tag(I::Contacts))?;
        self.contact_builder
            .check_graph()
            .map_err(tag(I::Contacts))?;
        self.joints.check(bodies).map_err(tag(I::Joints))?;
        self.islands.check(bodies).map_err(tag(I::Islands))?;
        self.portals.check(bodies).map_err(tag(I::Portals))?;
        self.check_disabled().map_err(tag(I::Bodies))?;
        self.check_world_values().map_err(tag(I::World))
    }
}
