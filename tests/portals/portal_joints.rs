//! Joints through portals: a rope of 20 revolute links poured through a
//! floor portal comes out of a wall portal whole, with η = 1 and η = 2, and
//! a ragdoll thrown through a portal keeps its joints; every joint's gap is
//! measured through the portal map
//! (`janus2d_testbed::portal_joints::gap_through_map`). Set
//! `JANUS2D_REPORT=1` to print the figures.

use janus2d::prelude::*;
use janus2d::world::{PortalEvent, PortalPairHandle};
use janus2d_testbed::portal_joints::{
    EXIT_FACE_X, gap_through_map, jointed_portal_world, ragdoll, rope,
};
use janus2d_testbed::support::report;

const DT: Real = 1.0 / 60.0;

/// What a run through the portal measured.
#[derive(Debug, Default)]
struct Run {
    worst_gap: Real,
    disabled: usize,
    steps_to_through: Option<usize>,
}

/// Steps `world` for `steps` steps, measuring every joint's gap through the
/// map after each step and counting disabled-joint events; `through` says
/// when the object is wholly through.
fn run(
    world: &mut World,
    pair: PortalPairHandle,
    joints: &[JointHandle],
    steps: usize,
    through: impl Fn(&World) -> bool,
) -> Run {
    let mut r = Run::default();
    for step in 0..steps {
        world.step(DT).unwrap();
        world.validate().unwrap();
        r.disabled += world
            .events()
            .portals
            .iter()
            .filter(|e| matches!(e, PortalEvent::JointDisabled { .. }))
            .count();
        for &j in joints {
            r.worst_gap = r.worst_gap.max(gap_through_map(world, j, pair));
        }
        if r.steps_to_through.is_none() && through(world) {
            r.steps_to_through = Some(step + 1);
        }
    }
    r
}

fn rope_through(eta: Real) -> (Run, Real) {
    let (mut world, pair) = jointed_portal_world(eta);
    let (links, joints) = rope(&mut world, 20);
    let all_out = |w: &World| {
        w.crossing_count() == 0 && links.iter().all(|&b| w.position(b).unwrap().x < 0.0)
    };
    let r = run(&mut world, pair, &joints, 300, all_out);
    let first_x = world.position(links[0]).unwrap().x;
    if report() {
        eprintln!(
            "rope η = {eta}: worst gap through the map {:.2} mm, {} disabled, all 20 links out after {:?} steps, first link at x = {first_x:.2}",
            1e3 * r.worst_gap,
            r.disabled,
            r.steps_to_through
        );
    }
    for &j in &joints {
        assert!(
            world.revolute_joint(j).unwrap().is_enabled(),
            "a joint was disabled"
        );
    }
    (r, first_x)
}

fn check_rope(eta: Real) {
    let (r, first_x) = rope_through(eta);
    assert_eq!(r.disabled, 0, "joint-disabled events");
    assert!(
        r.steps_to_through.is_some(),
        "the rope did not come out whole"
    );
    assert!(
        first_x > EXIT_FACE_X + 1.0,
        "the first link is at x = {first_x}, not beyond the exit portal"
    );
    assert!(
        r.worst_gap <= 0.02,
        "worst gap through the map {} m",
        r.worst_gap
    );
}

/// A rope of 20 links poured through a floor portal comes out of a wall
/// portal whole (η = 1): no joint disabled, every gap through the map ≤ 2 cm.
#[test]
fn rope_of_twenty_links_comes_out_whole_eta_1() {
    check_rope(1.0);
}

/// The same rope through a pair with η = 2 (the links come out twice as long).
#[test]
fn rope_of_twenty_links_comes_out_whole_eta_2() {
    check_rope(2.0);
}

/// A ragdoll (torso, head, two arms, two legs) thrown spinning into a floor
/// portal comes out of the wall portal with its joints: no joint disabled,
/// worst gap through the map ≤ 2 cm, every part on the exit side after.
#[test]
fn ragdoll_thrown_through_a_portal_keeps_its_joints() {
    let (mut world, pair) = jointed_portal_world(1.0);
    let (parts, joints) = ragdoll(&mut world, Vec2::new(19.5, 3.0), Vec2::new(0.5, -6.0), 1.5);
    let all_out = |w: &World| {
        w.crossing_count() == 0 && parts.iter().all(|&b| w.position(b).unwrap().x < 0.0)
    };
    let r = run(&mut world, pair, &joints, 240, all_out);
    if report() {
        eprintln!(
            "ragdoll: worst gap through the map {:.2} mm, {} disabled, all parts out after {:?} steps",
            1e3 * r.worst_gap,
            r.disabled,
            r.steps_to_through
        );
    }
    assert_eq!(r.disabled, 0, "joint-disabled events");
    assert!(
        r.steps_to_through.is_some(),
        "the ragdoll did not come out whole"
    );
    assert!(
        r.worst_gap <= 0.02,
        "worst gap through the map {} m",
        r.worst_gap
    );
}

/// Two boxes hinged one above the other (gravity 0) go down into the floor
/// portal; once the first is through and the second is crossing, every copy
/// is sent back. The second cannot back out while its clone's joint has no
/// copy of the first on the entry side: it waits until the first starts
/// crossing back, then the joint moves to the first's copy on the entry side
/// and both come back out of the floor portal, joined, the joint never
/// disabled, its gap through the map under 1 mm.
#[test]
fn jointed_pair_backs_out_whole() {
    let (mut world, pair) = jointed_portal_world(1.0);
    world.set_gravity(Vec2::ZERO).unwrap();
    let make = |world: &mut World, y: Real| {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(20.0, y)).with_velocity(Vec2::new(0.0, -3.0)))
            .unwrap();
        world
            .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
            .unwrap();
        b
    };
    let (a, b) = (make(&mut world, 1.0), make(&mut world, 1.8));
    let joint = world
        .create_revolute_joint(&RevoluteJointDef::new(
            a,
            b,
            Vec2::new(0.0, 0.4),
            Vec2::new(0.0, -0.4),
        ))
        .unwrap();
    let mut reversed = false;
    let mut cancelled_after_restart = false;
    let mut a_restarted = false;
    let mut r = Run::default();
    for _ in 0..240 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        for e in &world.events().portals {
            match e {
                PortalEvent::JointDisabled { .. } => r.disabled += 1,
                PortalEvent::CrossingStarted { body, .. } if reversed && *body == a => {
                    a_restarted = true
                }
                PortalEvent::CrossingCancelled { body, .. } if *body == b => {
                    cancelled_after_restart = a_restarted
                }
                _ => {}
            }
        }
        r.worst_gap = r.worst_gap.max(gap_through_map(&world, joint, pair));
        let a_out = world.clone_of(a).is_none() && world.position(a).unwrap().x < 0.0;
        if !reversed && a_out && world.clone_of(b).is_some() {
            reversed = true;
            for body in [a, b, world.clone_of(b).unwrap()] {
                let v = world.linear_velocity(body).unwrap();
                world.set_linear_velocity(body, -v).unwrap();
            }
        }
    }
    if report() {
        eprintln!(
            "backing out: worst gap through the map {:.3} mm, {} disabled",
            1e3 * r.worst_gap,
            r.disabled
        );
    }
    assert!(reversed, "the first box never went through");
    assert!(
        cancelled_after_restart,
        "the second backed out before the first turned back"
    );
    assert_eq!(r.disabled, 0);
    assert_eq!(world.crossing_count(), 0);
    let j = world.revolute_joint(joint).unwrap();
    assert!(j.is_enabled());
    assert_eq!((j.def().base.body_a, j.def().base.body_b), (a, b));
    // Both back above the floor portal, moving up.
    for body in [a, b] {
        let p = world.position(body).unwrap();
        assert!(p.x > 15.0 && p.y > 1.0, "a box at {p}");
    }
    assert!(
        r.worst_gap < 1e-3,
        "worst gap through the map {} m",
        r.worst_gap
    );
}

/// Destroying the pair while the rope crosses ends every crossing by force:
/// the joints that cannot follow are disabled and reported (with the next
/// step's events), the rest stay,
/// every joint handle stays valid and the world stays consistent.
#[test]
fn destroying_the_pair_under_a_crossing_rope_disables_only_what_cannot_follow() {
    let (mut world, pair) = jointed_portal_world(1.0);
    let (links, joints) = rope(&mut world, 20);
    // Until the first links are through and the next ones crossing.
    for _ in 0..120 {
        world.step(DT).unwrap();
        if world.position(links[2]).unwrap().x < 0.0 && world.crossing_count() > 0 {
            break;
        }
    }
    assert!(world.crossing_count() > 0, "no crossing to end");
    world.destroy_portal_pair(pair).unwrap();
    world.validate().unwrap();
    // Events of a call between steps come with the next step's.
    world.step(DT).unwrap();
    let reported = world
        .events()
        .portals
        .iter()
        .filter(|e| matches!(e, PortalEvent::JointDisabled { .. }))
        .count();
    let disabled = joints
        .iter()
        .filter(|&&j| !world.revolute_joint(j).unwrap().is_enabled())
        .count();
    assert_eq!(world.crossing_count(), 0);
    assert!(disabled >= 1, "a joint across the portal stayed enabled");
    assert_eq!(reported, disabled);
    assert!(disabled < joints.len());
    for _ in 0..30 {
        world.step(DT).unwrap();
        world.validate().unwrap();
    }
}

#[allow(dead_code)]
#[path = "../../examples/portal_rope.rs"]
mod portal_rope;

/// The rope example: with η = 1 and η = 2 all 20 links go through, no
/// joint is disabled, the worst gap through the map is under 2 cm and the
/// first link ends beyond the wall portal.
#[test]
fn rope_example_comes_out_whole() {
    for eta in [1.0, 2.0] {
        let r = portal_rope::run(eta).unwrap();
        assert_eq!(r.links_through, 20, "η = {eta}");
        assert!(r.steps_to_through.is_some(), "η = {eta}");
        assert_eq!(r.disabled, 0, "η = {eta}");
        assert!(r.worst_gap <= 0.02, "η = {eta}: worst gap {}", r.worst_gap);
        assert!(
            r.first_link.x > EXIT_FACE_X + 1.0,
            "η = {eta}: first link at {}",
            r.first_link
        );
    }
}

/// The rope of the other tests with every link given `drift` m/s along +x
/// (η = `eta`), run for 300 steps (printed with `JANUS2D_REPORT=1`).
fn dragged_rope(eta: Real, drift: Real) -> Run {
    let (mut world, pair) = jointed_portal_world(eta);
    let (links, joints) = rope(&mut world, 20);
    for &b in &links {
        world.set_linear_velocity(b, Vec2::new(drift, 0.0)).unwrap();
    }
    let r = run(&mut world, pair, &joints, 300, |w| w.crossing_count() == 0);
    if report() {
        eprintln!(
            "dragged rope η = {eta}, {drift:+} m/s: worst gap {:.1} mm, {} disabled",
            1e3 * r.worst_gap,
            r.disabled
        );
    }
    r
}

/// A rope drifting sideways onto the lip: the rope of the other tests,
/// given 0.5 m/s along +x, reaches the aperture's edge while it pours; the
/// links that no longer fit the aperture are dragged across the lip. No
/// joint is disabled and every gap through the map stays within 2 cm.
/// Measured: 16.0 mm (f32), with a lip corner pushing a straddling link
/// along the normal of the link's own face (`aperture.rs`, `side_wall`);
/// 20.5 mm when it pushed along the aperture's tangent, which jerked a
/// tilted link sideways at 4.9 m/s as it slid down past the corner. At
/// 0.7 m/s: 11.3 mm (15.5 before), 1 m/s 3.0 mm (2.3), −0.5 m/s 1.3 mm.
#[test]
fn rope_drifting_onto_the_lip_keeps_its_joints() {
    let r = dragged_rope(1.0, 0.5);
    assert_eq!(r.disabled, 0);
    assert!(
        r.worst_gap <= 0.02,
        "worst gap through the map {} m",
        r.worst_gap
    );
}

/// The dragged rope over drift speeds and both η: the cases that hold
/// (no joint disabled, every gap through the map within 2 cm) in both
/// precisions keep holding. Measured worst gap, f32 / f64: η = 1 at −0.7,
/// −0.5, 0.2, 0.3, 0.5, 1, 1.5 and 2 m/s 1.3–16.0 / 1.3–15.9 mm; η = 2 at
/// −0.7, −0.5, 0.2, 0.3 and 2 m/s 3.5–6.4 / 3.5–5.5 mm. Not held (printed
/// with `JANUS2D_REPORT=1`): η = 1 at 0.7 m/s holds in f32 (11.3 mm) but
/// disables a joint in f64; η = 1 at −1 and −1.5 m/s and η = 2 at −1.5,
/// −1, 0.7 and 1 m/s disable a joint (a link held behind the entry for its
/// joints follows its clone out of the span, see docs/portal.md); η = 2
/// opens to 0.15 m at 0.5 m/s, and at 1.5 m/s disables a joint in f32
/// (76 mm in f64).
#[test]
fn rope_dragged_onto_a_lip_over_speeds_and_eta_keeps_the_cases_that_held() {
    let holds: [(Real, &[Real]); 2] = [
        (1.0, &[-0.7, -0.5, 0.2, 0.3, 0.5, 1.0, 1.5, 2.0]),
        (2.0, &[-0.7, -0.5, 0.2, 0.3, 2.0]),
    ];
    let all: [Real; 11] = [-1.5, -1.0, -0.7, -0.5, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0];
    let mut failed = Vec::new();
    for (eta, held) in holds {
        for v in all {
            let r = dragged_rope(eta, v);
            let ok = r.disabled == 0 && r.worst_gap <= 0.02;
            if held.contains(&v) && !ok {
                failed.push(format!("η = {eta}, {v} m/s: {r:?}"));
            }
        }
    }
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

/// The portal bodies take their share: two hinged boxes (gravity 0, sleep
/// off) launched through a pair of portals on two free dynamic slabs. The
/// total linear and angular momentum of every dynamic body is conserved
/// while the joint acts through the portal rows, at both handovers and
/// after (relative 1e-5 in f32, 1e-10 in f64, as for one body); both boxes
/// come out joined, the joint never disabled, its gap through the map
/// under 1 mm.
#[test]
fn jointed_pair_through_dynamic_portal_bodies_conserves_momentum() {
    let (mut world, _, _, pair) = janus2d_testbed::support::free_slab_portals();
    let make = |world: &mut World, x: Real| {
        let body = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, 0.1)).with_velocity(Vec2::new(4.0, 0.0)))
            .unwrap();
        world
            .create_shape(body, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
            .unwrap();
        body
    };
    let (lead, tail) = (make(&mut world, -1.0), make(&mut world, -1.8));
    let joint = world
        .create_revolute_joint(&RevoluteJointDef::new(
            lead,
            tail,
            Vec2::new(-0.4, 0.0),
            Vec2::new(0.4, 0.0),
        ))
        .unwrap();
    let momentum = janus2d_testbed::support::world_momentum;
    let (p0, l0) = momentum(&world);
    let scale_p = p0.length();
    let scale_l = l0.abs().max(scale_p * 20.0);
    let (mut worst_p, mut worst_l) = (0.0 as Real, 0.0 as Real);
    let mut r = Run::default();
    let mut completed = 0;
    for _ in 0..150 {
        world.step(DT).unwrap();
        world.validate().unwrap();
        for e in &world.events().portals {
            match e {
                PortalEvent::JointDisabled { .. } => r.disabled += 1,
                PortalEvent::CrossingCompleted { .. } => completed += 1,
                _ => {}
            }
        }
        r.worst_gap = r.worst_gap.max(gap_through_map(&world, joint, pair));
        let (p, l) = momentum(&world);
        worst_p = worst_p.max((p - p0).length() / scale_p);
        worst_l = worst_l.max((l - l0).abs() / scale_l);
    }
    if report() {
        eprintln!(
            "jointed pair, dynamic portal bodies: momentum error linear {worst_p:.3e}, angular {worst_l:.3e}; worst gap through the map {:.3} mm",
            1e3 * r.worst_gap
        );
    }
    assert_eq!(completed, 2, "both boxes go through");
    assert_eq!(r.disabled, 0);
    assert!(world.revolute_joint(joint).unwrap().is_enabled());
    assert!(
        r.worst_gap < 1e-3,
        "worst gap through the map {} m",
        r.worst_gap
    );
    #[cfg(not(feature = "f64"))]
    let tol = 1e-5;
    #[cfg(feature = "f64")]
    let tol = 1e-10;
    assert!(worst_p <= tol, "linear momentum error {worst_p}");
    assert!(worst_l <= tol, "angular momentum error {worst_l}");
}
