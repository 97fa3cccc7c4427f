//! `joint_zoo`: one scene holding every joint kind, side by side under a
//! static ceiling and on a static ground, for the command line
//! (`janus2d run joint_zoo`, `janus2d export joint_zoo`), the scene files'
//! round trip and the testbed page.
//!
//! ```text
//!   ceiling y = 10 ═══╤══════╤══════╤═══════╤═══════╤═══════════════════
//!      revolute ──────┘ weld ■  prism ╲  wheel ●  rope ┊  spring ┊
//!      (+ a hinge in `joints`)       ╲        ▼     ■        ●
//!
//!   ground  y = 0 ════════════════ motor ■ ══ mouse ■ ══ filter ■■ ═══
//! ```
//!
//! | joint | bodies | settings |
//! |-------|--------|----------|
//! | revolute (`joints`) | ceiling, bar at x = −16 | plain hinge |
//! | revolute | ceiling, bar at x = −13 | limits ±1 rad, spring 2 Hz / ζ 0.3, motor 1 rad/s ≤ 5 N·m, reference angle 0.2 |
//! | weld | ceiling, box at x = −9 | soft: 5 Hz / ζ 0.7 linear, 2 Hz / ζ 0.5 angular |
//! | prismatic | ceiling, box at x = −5 | axis −45°, limits ±1 m, motor 0.5 m/s ≤ 50 N |
//! | wheel | ceiling, disc at x = −1 | vertical axis, spring 2 Hz / ζ 0.5, limits ±0.5 m, motor 5 rad/s ≤ 10 N·m, bodies collide |
//! | distance (rope) | ceiling, box at x = 3 | max 3 m, slack below |
//! | distance (spring) | ceiling, disc at x = 6 | 2 m, spring 3 Hz / ζ 0.3 within ±200 N, limits [1, 3] m, motor 0.2 m/s ≤ 10 N |
//! | motor | ground, box at x = 9 | offset (9, 2) m, 0.3 rad, ≤ 200 N, ≤ 50 N·m, correction 0.3 |
//! | mouse | ground, box at x = 13 | target (13, 4) m, 3 Hz / ζ 0.7, ≤ 500 N |
//! | filter | two overlapping boxes at x = 17 | they pass through each other |

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use glam::DVec2;

use crate::desc::*;

/// The scene's name.
pub const NAME: &str = "joint_zoo";

/// Every joint kind in one scene (5 s at 60 Hz; see the module table).
#[must_use]
pub fn joint_zoo() -> SceneDesc {
    let mut d = SceneDesc::new(NAME, 300);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO).with(ShapeDesc::new(offset_box(
        21.0,
        0.5,
        v(0.0, -0.5),
    ))));
    let ceiling = d.add(
        BodyDesc::fixed(v(0.0, 10.0)).with(ShapeDesc::new(offset_box(21.0, 0.2, v(0.0, 0.2)))),
    );
    // The ceiling's frame: a world point p is p − (0, 10) on it.
    let on_ceiling = |p: DVec2| p - v(0.0, 10.0);
    let block = |hx: f64, hy: f64| ShapeDesc::new(square(hx, hy));
    let disc = |r: f64| {
        ShapeDesc::new(Geometry::Circle {
            center: DVec2::ZERO,
            radius: r,
        })
    };

    // Revolute, as a plain `joints` hinge: a bar hanging from x = −16.
    let bar = d.add(BodyDesc::dynamic(v(-16.0, 9.0)).with(block(0.1, 1.0)));
    d.join(RevoluteDesc::new(
        ceiling,
        bar,
        on_ceiling(v(-16.0, 10.0)),
        v(0.0, 1.0),
    ));

    // Revolute with everything: a horizontal bar swinging from x = −14.
    let arm = d.add(BodyDesc::dynamic(v(-13.0, 10.0 - 0.15)).with(block(1.0, 0.1)));
    let mut hinge = RevoluteDesc::new(ceiling, arm, on_ceiling(v(-14.0, 9.85)), v(-1.0, 0.0));
    hinge.reference_angle = 0.2;
    hinge.limit = Some((-1.0, 1.0));
    hinge.spring = Some((2.0, 0.3));
    hinge.motor = Some((1.0, 5.0));
    d.join_any(hinge);

    // Weld, soft: a box under the ceiling at x = −9.
    let welded = d.add(BodyDesc::dynamic(v(-9.0, 9.0)).with(block(0.5, 0.5)));
    let mut weld = WeldDesc::new(ceiling, welded, on_ceiling(v(-9.0, 9.8)), v(0.0, 0.8));
    weld.linear_hertz = 5.0;
    weld.linear_damping_ratio = 0.7;
    weld.angular_hertz = 2.0;
    weld.angular_damping_ratio = 0.5;
    d.join_any(weld);

    // Prismatic along −45°, driven down to its limit.
    let slider = d.add(BodyDesc::dynamic(v(-5.0, 8.0)).with(block(0.4, 0.4)));
    let mut prismatic = PrismaticDesc::new(
        JointBaseDesc::new(ceiling, slider, on_ceiling(v(-5.0, 8.0)), DVec2::ZERO)
            .with_axis_angle(-FRAC_PI_4),
    );
    prismatic.limit = Some((-1.0, 1.0));
    prismatic.motor = Some((0.5, 50.0));
    d.join_any(prismatic);

    // Wheel on a vertical sprung axis, spinning.
    let wheel = d.add(BodyDesc::dynamic(v(-1.0, 8.0)).with(disc(0.5)));
    let mut w = WheelDesc::new(
        JointBaseDesc::new(ceiling, wheel, on_ceiling(v(-1.0, 8.0)), DVec2::ZERO)
            .with_axis_angle(FRAC_PI_2),
    );
    w.base.collide_connected = true;
    w.spring = Some((2.0, 0.5));
    w.limit = Some((-0.5, 0.5));
    w.motor = Some((5.0, 10.0));
    d.join_any(w);

    // Distance as a rope: 3 m at most, slack below (hanging 2 m down).
    let hung = d.add(BodyDesc::dynamic(v(3.0, 8.0)).with(block(0.3, 0.3)));
    let mut rope = DistanceDesc::new(
        JointBaseDesc::new(ceiling, hung, on_ceiling(v(3.0, 10.0)), v(0.0, 0.3)),
        3.0,
    );
    rope.spring = Some((0.0, 0.0));
    rope.limit = Some((0.0, 3.0));
    d.join_any(rope);

    // Distance as a bounded spring with a motor.
    let bob = d.add(BodyDesc::dynamic(v(6.0, 8.0)).with(disc(0.3)));
    let mut spring = DistanceDesc::new(
        JointBaseDesc::new(ceiling, bob, on_ceiling(v(6.0, 10.0)), DVec2::ZERO),
        2.0,
    );
    spring.spring = Some((3.0, 0.3));
    spring.spring_force = (-200.0, 200.0);
    spring.limit = Some((1.0, 3.0));
    spring.motor = Some((0.2, 10.0));
    d.join_any(spring);

    // Motor: a box driven to (9, 2) and 0.3 rad above the ground's origin.
    let driven = d.add(BodyDesc::dynamic(v(9.0, 0.5)).with(block(0.5, 0.5)));
    let mut motor =
        MotorJointDesc::new(JointBaseDesc::new(ground, driven, DVec2::ZERO, DVec2::ZERO));
    motor.linear_offset = v(9.0, 2.0);
    motor.angular_offset = 0.3;
    motor.max_force = 200.0;
    motor.max_torque = 50.0;
    d.join_any(motor);

    // Mouse: a box pulled up by its corner toward (13, 4).
    let pulled = d.add(BodyDesc::dynamic(v(13.0, 0.5)).with(block(0.5, 0.5)));
    let mut mouse = MouseJointDesc::new(
        JointBaseDesc::new(ground, pulled, DVec2::ZERO, v(0.4, 0.4)),
        v(13.0, 4.0),
        500.0,
    );
    mouse.hertz = 3.0;
    d.join_any(mouse);

    // Filter: two overlapping boxes that never collide.
    let left = d.add(BodyDesc::dynamic(v(16.8, 0.5)).with(block(0.5, 0.5)));
    let right = d.add(BodyDesc::dynamic(v(17.2, 0.9)).with(block(0.5, 0.5)));
    d.join_any(FilterJointDesc {
        base: JointBaseDesc::new(left, right, DVec2::ZERO, DVec2::ZERO),
    });

    d.probe = Some(pulled);
    d.probe_label = "pulled box";
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::janus::Janus;

    #[test]
    fn every_kind_is_there_and_the_scene_runs() {
        let d = joint_zoo();
        let mut kinds: Vec<&str> = d.all_joints().map(|j| j.kind_name()).collect();
        kinds.sort_unstable();
        kinds.dedup();
        assert_eq!(
            kinds,
            [
                "distance",
                "filter",
                "motor",
                "mouse",
                "prismatic",
                "revolute",
                "weld",
                "wheel"
            ]
        );
        let mut j = Janus::new(&d).expect("every kind builds");
        for _ in 0..d.steps {
            j.world
                .step(d.settings.dt as janus2d_core::math::Real)
                .unwrap();
        }
        for (i, &h) in j.bodies.iter().enumerate() {
            let p = j.world.position(h).unwrap();
            assert!(p.is_finite() && p.y > -1.0, "body {i} at {p:?}");
        }
        // The mouse joint lifted its box toward (13, 4); the filter pair fell
        // through each other onto the ground.
        let pulled = j.world.position(j.bodies[d.probe.unwrap()]).unwrap();
        assert!(pulled.y > 2.0, "{pulled:?}");
        let n = j.bodies.len();
        let (a, b) = (
            j.world.position(j.bodies[n - 2]).unwrap(),
            j.world.position(j.bodies[n - 1]).unwrap(),
        );
        assert!((a.y - b.y).abs() < 0.1, "{a:?} {b:?}");
        // The motor joint holds its box at the offset.
        let driven = j.world.position(j.bodies[n - 4]).unwrap();
        let want = janus2d_core::math::Vec2::new(9.0, 2.0);
        assert!(driven.distance(want) < 0.05, "{driven:?}");
    }
}
