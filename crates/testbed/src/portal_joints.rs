//! Jointed bodies through portals: the rope and ragdoll scenes of
//! `tests/portals/portal_joints.rs` and `examples/portal_rope.rs`, and the joint
//! gap measured through the portal map.
//!
//! ```text
//!   exit wall (x = −20, portal b facing +x, half-width η)
//!   │▓ ─▶ rope comes out, falls freely          rope (20 links, 0.5 m)
//!   │▓                                                 ║
//!   │▓                                                 ║
//!                                            floor ══ portal a (x = 20, facing +y, half-width 1)
//! ```
//!
//! The gap of a joint is measured as the world holds it (the distance of
//! its two world anchors) and, when one of its bodies is a copy of a
//! crossing object, again on the other copy: the anchor on the joint's
//! other body mapped through the crossing's map (T, or T⁻¹ for a clone)
//! against the anchor carried to the twin (`c + s (l − c)`, `s` = η or 1/η
//! about the common local centre of mass). So a tension that the portal
//! rows pass on badly shows as a gap even though each joint holds.

use janus2d_constraints::RevoluteJointDef;
use janus2d_core::body::{BodyDef, BodyHandle};
use janus2d_core::geometry::{Circle, Polygon};
use janus2d_core::math::{Real, Vec2};
use janus2d_world::{
    CrossingRole, JointHandle, PortalPairDef, PortalPairHandle, ShapeDef, World, WorldDef,
};

use crate::support::{portal_def, wall};

/// Where the rope's floor portal is (its centre), m.
pub const ENTRY_CENTER: Vec2 = Vec2::new(20.0, 0.0);
/// The x of the exit wall's face (portal b's plane), m.
pub const EXIT_FACE_X: Real = -19.5;

/// The portal scene of the jointed tests: a floor portal (half-width 1 m,
/// facing +y, at [`ENTRY_CENTER`]) linked with scale `eta` to a wall portal
/// (half-width `eta` m, facing +x, centre 5 m up on the face at
/// [`EXIT_FACE_X`]),. Nothing else: what comes out falls freely (no landing
/// impact to mix with what the portal does). Default world (gravity
/// −10 m/s²).
#[must_use]
pub fn jointed_portal_world(eta: Real) -> (World, PortalPairHandle) {
    let mut world = World::new(WorldDef::default()).expect("the default world");
    let floor = wall(&mut world, Vec2::new(ENTRY_CENTER.x, -0.5), 4.0, 0.5);
    let exit = wall(&mut world, Vec2::new(EXIT_FACE_X - 0.5, 5.0), 0.5, 5.0);
    let pair = world
        .create_portal_pair(
            &PortalPairDef::new(
                portal_def(floor, Vec2::new(0.0, 0.5), Vec2::Y, 1.0),
                portal_def(exit, Vec2::new(0.5, 0.0), Vec2::X, eta),
            )
            .with_eta(eta),
        )
        .expect("a valid pair");
    (world, pair)
}

/// A rope of `links` box links (0.5 m long, 0.1 m thick, density 1),
/// hanging straight up from 1 m above the floor portal (0.3 m off its
/// centre), jointed end to end (no collision between neighbours). Returns
/// the links (first = lowest) and the joints (joint `i` joins links `i` and
/// `i + 1`).
pub fn rope(world: &mut World, links: usize) -> (Vec<BodyHandle>, Vec<JointHandle>) {
    let half = 0.25;
    let x = ENTRY_CENTER.x + 0.3;
    let mut bodies = Vec::with_capacity(links);
    let mut joints = Vec::with_capacity(links);
    for i in 0..links {
        let y = 1.0 + half + 2.0 * half * i as Real;
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, y)))
            .expect("a link");
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.05, half))
            .expect("a link shape");
        if let Some(&prev) = bodies.last() {
            let def = RevoluteJointDef::new(prev, b, Vec2::new(0.0, half), Vec2::new(0.0, -half));
            joints.push(world.create_revolute_joint(&def).expect("a hinge"));
        }
        bodies.push(b);
    }
    (bodies, joints)
}

/// A ragdoll of six bodies jointed as a tree (torso; head, two arms, two
/// legs on the torso) with its torso centre at `at`, moving at `velocity`
/// and turning at `spin`. Returns the bodies (torso first) and the joints.
pub fn ragdoll(
    world: &mut World,
    at: Vec2,
    velocity: Vec2,
    spin: Real,
) -> (Vec<BodyHandle>, Vec<JointHandle>) {
    let shape = ShapeDef::default();
    let make = |world: &mut World, offset: Vec2| {
        world
            .create_body(
                &BodyDef::dynamic(at + offset)
                    .with_velocity(velocity + spin * Vec2::new(-offset.y, offset.x))
                    .with_angular_velocity(spin),
            )
            .expect("a ragdoll part")
    };
    let torso = make(world, Vec2::ZERO);
    world
        .create_shape(torso, &shape, Polygon::make_box(0.2, 0.35))
        .expect("torso");
    let head = make(world, Vec2::new(0.0, 0.55));
    world
        .create_shape(head, &shape, Circle::new(Vec2::ZERO, 0.15).expect("head"))
        .expect("head");
    let mut bodies = vec![torso, head];
    let mut joints = vec![
        world
            .create_revolute_joint(&RevoluteJointDef::new(
                torso,
                head,
                Vec2::new(0.0, 0.4),
                Vec2::new(0.0, -0.15),
            ))
            .expect("neck"),
    ];
    // Arms hang from the shoulders, legs from the hips.
    for (attach, half) in [
        (Vec2::new(-0.25, 0.3), 0.3),
        (Vec2::new(0.25, 0.3), 0.3),
        (Vec2::new(-0.12, -0.35), 0.35),
        (Vec2::new(0.12, -0.35), 0.35),
    ] {
        let limb = make(world, attach - Vec2::new(0.0, half));
        world
            .create_shape(limb, &shape, Polygon::make_box(0.06, half))
            .expect("limb");
        joints.push(
            world
                .create_revolute_joint(&RevoluteJointDef::new(
                    torso,
                    limb,
                    attach,
                    Vec2::new(0.0, half),
                ))
                .expect("a shoulder or hip"),
        );
        bodies.push(limb);
    }
    (bodies, joints)
}

/// The twin of `body` through `pair` when it is a copy in a crossing: the
/// other copy, the map from `body`'s side to the twin's, and the scale
/// from `body`'s frame to the twin's.
fn twin(
    world: &World,
    body: BodyHandle,
    pair: PortalPairHandle,
) -> Option<(BodyHandle, janus2d_constraints::portal_map::PortalMap, Real)> {
    let side = world.portal_side(body, pair).ok()?;
    let pc = world.portal_constraints().iter().find(|pc| {
        let d = pc.def();
        d.body == body || d.clone == body
    })?;
    let map = world.portal_constraint_map(pc);
    match side.crossing {
        CrossingRole::Original { .. } => Some((pc.def().clone, map, map.eta)),
        CrossingRole::Clone { .. } => Some((pc.def().body, map.inverse(), 1.0 / map.eta)),
        CrossingRole::None => None,
    }
}

/// A body's local centre of mass.
fn local_center(world: &World, body: BodyHandle) -> Vec2 {
    let xf = world.transform(body).expect("a live body");
    xf.apply_inv(world.center_of_mass(body).expect("a live body"))
}

/// The joint's gap through the portal map, m: the largest of its world
/// anchors' distance and, for each end on a crossing copy, the distance on
/// the twin's side between the other end's anchor mapped there and the
/// anchor carried to the twin (in the metres of the side it is measured
/// on). A disabled joint reads `Real::INFINITY`.
#[must_use]
pub fn gap_through_map(world: &World, joint: JointHandle, pair: PortalPairHandle) -> Real {
    let Ok(j) = world.revolute_joint(joint) else {
        return Real::INFINITY;
    };
    if !j.is_enabled() {
        return Real::INFINITY;
    }
    let ends = [
        (j.def().base.body_a, j.def().base.local_frame_a.anchor),
        (j.def().base.body_b, j.def().base.local_frame_b.anchor),
    ];
    let world_anchor = |(b, l): (BodyHandle, Vec2)| world.transform(b).expect("live").apply(l);
    let mut gap = (world_anchor(ends[0]) - world_anchor(ends[1])).length();
    for k in 0..2 {
        let (body, local) = ends[k];
        let other = world_anchor(ends[1 - k]);
        if let Some((twin, map, scale)) = twin(world, body, pair) {
            let c = local_center(world, body);
            let carried = c + scale * (local - c);
            let on_twin = world.transform(twin).expect("live").apply(carried);
            gap = gap.max((map.map_point(other) - on_twin).length());
        }
    }
    gap
}
