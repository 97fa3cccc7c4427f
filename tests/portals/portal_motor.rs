//! A motor-joined pair through a portal with η = 2: a 0.4 m box (a) and
//! a 0.3 m box (b) held 0.6 m above it by a motor joint fall through the
//! floor portal of `jointed_portal_world` and come out of the wall portal
//! twice as large. The joint follows them (no joint disabled), its linear
//! offset scales with the pair (0.6 m → 1.2 m: a length in a's frame, see
//! `MotorJoint::carry_through_portal`), and the drive's error — b's anchor
//! against its target on a — stays within 1 cm measured through the map
//! while a copy crosses (in the metres of the side it is measured on), and
//! within 1 cm on the exit side after.
//!
//! Why 1 cm, the bound of the moving-platform scene: the pair falls
//! freely, so the drive has no steady load; what it resists is the portal
//! rows' transfer of each copy's motion while it crosses, a transient the
//! drive (400 N on a 1 kg body, 400 g) closes at `β/h` = 72 /s.
//! Set `JANUS2D_REPORT=1` to print the figures.

use janus2d::prelude::*;
use janus2d::world::{CrossingRole, PortalEvent, PortalPairHandle};
use janus2d_constraints::portal_map::PortalMap;
use janus2d_testbed::portal_joints::{ENTRY_CENTER, jointed_portal_world};
use janus2d_testbed::support::report;

const DT: Real = 1.0 / 60.0;
const ETA: Real = 2.0;
const OFFSET: Vec2 = Vec2::new(0.0, 0.6);

/// The twin of `body` through `pair` when it is a copy in a crossing: the
/// other copy, the map from `body`'s side to the twin's, and the scale
/// from `body`'s frame to the twin's (as the testbed's gap through the
/// map).
pub(crate) fn twin(
    world: &World,
    body: BodyHandle,
    pair: PortalPairHandle,
) -> Option<(BodyHandle, PortalMap, Real)> {
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
    let xf = world.transform(body).unwrap();
    xf.apply_inv(world.center_of_mass(body).unwrap())
}

/// The motor joint's linear error through the map, m: the distance of b's
/// anchor from its target on a as the world holds them, and for each end
/// on a crossing copy, again on the twin's side (the other end's point
/// mapped there against this end's point carried to the twin,
/// `c + s (l − c)`).
fn error_through_map(world: &World, joint: JointHandle, pair: PortalPairHandle) -> Real {
    let j = world.joint_of::<MotorJoint>(joint).unwrap();
    let ends = [
        (j.def().base.body_a, j.def().target_anchor_a()),
        (j.def().base.body_b, j.def().base.local_frame_b.anchor),
    ];
    let at = |(b, l): (BodyHandle, Vec2)| world.transform(b).unwrap().apply(l);
    let mut error = (at(ends[0]) - at(ends[1])).length();
    for k in 0..2 {
        let (body, local) = ends[k];
        if let Some((twin, map, scale)) = twin(world, body, pair) {
            let c = local_center(world, body);
            let on_twin = world
                .transform(twin)
                .unwrap()
                .apply(c + scale * (local - c));
            error = error.max((map.map_point(at(ends[1 - k])) - on_twin).length());
        }
    }
    error
}

/// The relative angle error `θ_b − θ_a − θ_ref − θ_off`, rad.
fn angle_error(world: &World, joint: JointHandle) -> Real {
    let def = &world.joint_of::<MotorJoint>(joint).unwrap().def();
    let (qa, qb) = (
        world.transform(def.base.body_a).unwrap().q,
        world.transform(def.base.body_b).unwrap().q,
    );
    janus2d_core::math::wrap_angle(
        qa.relative_angle(qb) - def.base.reference_angle() - def.angular_offset,
    )
}

#[test]
fn motor_joined_pair_keeps_its_offset_through_a_portal() {
    let (mut world, pair) = jointed_portal_world(ETA);
    let shape = ShapeDef::default();
    let x = ENTRY_CENTER.x + 0.2;
    let a = world
        .create_body(&BodyDef::dynamic(Vec2::new(x, 1.5)))
        .unwrap();
    world
        .create_shape(a, &shape, Polygon::make_box(0.2, 0.2))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(x, 1.5) + OFFSET))
        .unwrap();
    world
        .create_shape(b, &shape, Polygon::make_box(0.15, 0.15))
        .unwrap();
    let joint = world
        .create_joint(
            &MotorJointDef::new(a, b)
                .with_offset(OFFSET, 0.0)
                .with_max_force(400.0)
                .with_max_torque(100.0)
                .into(),
        )
        .unwrap();
    let (mut crossing_error, mut after_error, mut worst_angle): (Real, Real, Real) =
        (0.0, 0.0, 0.0);
    let mut disabled = 0;
    let mut out_at = None;
    for step in 0..240 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        disabled += world
            .events()
            .portals
            .iter()
            .filter(|e| matches!(e, PortalEvent::JointDisabled { .. }))
            .count();
        let error = error_through_map(&world, joint, pair);
        worst_angle = worst_angle.max(angle_error(&world, joint).abs());
        let out = world.crossing_count() == 0
            && [a, b].iter().all(|&h| world.position(h).unwrap().x < 0.0);
        if out {
            out_at.get_or_insert(step + 1);
            after_error = after_error.max(error);
        } else {
            crossing_error = crossing_error.max(error);
        }
    }
    let j = world.joint_of::<MotorJoint>(joint).unwrap();
    let offset = j.def().linear_offset;
    if report() {
        eprintln!(
            "motor pair through η = {ETA}: worst error {:.3} mm while crossing, {:.3} mm after \
             (bound 10 mm), worst angle {worst_angle:.2e} rad, offset {offset} m, out after \
             {out_at:?} steps, {disabled} disabled",
            1e3 * crossing_error,
            1e3 * after_error
        );
    }
    assert_eq!(disabled, 0);
    assert!(j.is_enabled());
    assert!(out_at.is_some(), "the pair did not come out");
    assert_eq!((j.def().base.body_a, j.def().base.body_b), (a, b));
    // The offset scaled with the pair: η × 0.6 m.
    assert!((offset - ETA * OFFSET).length() < 1e-5, "offset {offset}");
    assert!(
        crossing_error <= 0.01,
        "error while crossing {crossing_error} m"
    );
    assert!(after_error <= 0.01, "error after {after_error} m");
    assert!(worst_angle <= 0.01, "angle error {worst_angle} rad");
}
