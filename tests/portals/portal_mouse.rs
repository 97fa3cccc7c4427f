//! A mouse joint dragging a box into a portal: the target sits below the
//! floor portal, so the box is pulled into it (its clone comes out of the
//! wall portal, η = 0.5 and 1). The mouse joint's other end is the static
//! ground, which has no copy on the exit side: the crossing cannot
//! complete while the box is within the aperture and the joint acts on the
//! entry copy through the portal rows. It must not explode.
//!
//! Bound: no body faster than `sqrt(2 (F/m + g) D)` (22 m/s) at any step,
//! every state finite (`World::validate`). The mouse does at most `F`
//! (50 N on the 1 kg box) of work per metre of its pull and gravity `m g`,
//! and the target is `D` = 4 m from the start: a box that gained more
//! speed than that energy gives was pushed by something else.

use janus2d::prelude::*;
use janus2d_constraints::MouseJointDef;
use janus2d_testbed::portal_joints::{ENTRY_CENTER, jointed_portal_world};
use janus2d_testbed::support::report;

const DT: Real = 1.0 / 60.0;

fn drag_into_portal(eta: Real) -> (Real, bool) {
    let (mut world, _pair) = jointed_portal_world(eta);
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -20.0)))
        .unwrap();
    let start = ENTRY_CENTER + Vec2::new(0.2, 2.0);
    let b = world.create_body(&BodyDef::dynamic(start)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.2, 0.2))
        .unwrap();
    let mass = world.mass(b).unwrap();
    let target = ENTRY_CENTER + Vec2::new(0.2, -2.0);
    let max_force = 50.0 * mass;
    world
        .create_joint(&MouseJointDef::new(ground, b, target, max_force).into())
        .unwrap();
    let mut peak: Real = 0.0;
    let mut crossed = false;
    for _ in 0..300 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        crossed |= world.clone_of(b).is_some();
        for h in [Some(b), world.clone_of(b)].into_iter().flatten() {
            peak = peak.max(world.linear_velocity(h).unwrap().length());
        }
    }
    let bound = (2.0 * (50.0 + 10.0) * 4.0 as Real).sqrt();
    if report() {
        eprintln!(
            "mouse into a portal η = {eta}: crossed {crossed}, peak speed {peak:.3} m/s (bound {bound:.1}), box at {:?}",
            world.position(b).unwrap()
        );
    }
    (peak, crossed)
}

#[test]
fn mouse_drag_into_a_portal_does_not_explode() {
    let bound = (2.0 * (50.0 + 10.0) * 4.0 as Real).sqrt();
    for eta in [0.5, 1.0] {
        let (peak, crossed) = drag_into_portal(eta);
        assert!(crossed, "η = {eta}: the box never entered the portal");
        assert!(
            peak.is_finite() && peak <= bound,
            "η = {eta}: peak speed {peak} m/s > {bound}"
        );
    }
}
