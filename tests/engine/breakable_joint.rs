//! The breakable-joint example (issue 13, item 7; the joints break on their
//! joint events, issue 30): the joints read the
//! sign's weight while it hangs, a light ball leaves them whole, a heavy
//! one breaks both and the sign falls.

// The example keeps its name inside this module of the same name.
#[allow(dead_code, clippy::module_inception)]
#[path = "../../examples/breakable_joint.rs"]
mod breakable_joint;

use breakable_joint::{BREAK_FORCE, run};

#[test]
fn hanging_sign_joints_carry_its_weight() {
    let r = run(0.5).unwrap();
    assert!(
        (r.hanging_force - r.sign_weight).abs() < 0.01 * r.sign_weight,
        "the joints carry {} N, the weight is {} N",
        r.hanging_force,
        r.sign_weight
    );
}

#[test]
fn light_ball_leaves_the_joints_whole() {
    let r = run(0.5).unwrap();
    assert_eq!(r.broke_at, [None, None], "{r:?}");
    assert!(r.peak_force < BREAK_FORCE);
    assert!(r.peak_force > 0.5 * r.sign_weight, "{r:?}");
    assert!(r.sign_drop.abs() < 0.05, "the sign moved {} m", r.sign_drop);
}

#[test]
fn heavy_ball_breaks_both_joints_and_the_sign_falls() {
    let r = run(200.0).unwrap();
    assert!(r.broke_at.iter().all(Option::is_some), "{r:?}");
    assert!(r.sign_drop > 5.0, "the sign fell only {} m", r.sign_drop);
}
