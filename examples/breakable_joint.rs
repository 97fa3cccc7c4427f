//! A sign hung from a ceiling by two revolute joints that break above a
//! force threshold: each joint's `force_threshold` makes the step report a
//! joint event (`world.events().joints`) when its force passes it, and the
//! joint named by the event is destroyed, no polling. A ball dropped on it
//! snaps both joints; a light one does not.
//! Run with `cargo run --release --example breakable_joint`.

use janus2d::prelude::*;

/// Force above which a joint breaks, N.
pub const BREAK_FORCE: Real = 400.0;

/// What happened to the sign.
#[derive(Debug)]
pub struct Report {
    /// Upward force of the two joints together on the sign while it just
    /// hangs, N (two hooks on one rigid sign share the sideways load in a
    /// way statics leaves open; their vertical sum is its weight).
    pub hanging_force: Real,
    /// The sign's weight `m g`, N.
    pub sign_weight: Real,
    /// Largest force read on a joint before it broke, N.
    pub peak_force: Real,
    /// Steps at which each joint broke (`None`: it held).
    pub broke_at: [Option<usize>; 2],
    /// How far the sign's centre fell below where it hung, m.
    pub sign_drop: Real,
}

/// Hangs a 2 kg sign, drops a ball (radius 0.3 m) of `ball_density`
/// kg/m² on it from 2.7 m above and simulates 3 s at 60 Hz.
pub fn run(ball_density: Real) -> Result<Report, WorldError> {
    let dt: Real = 1.0 / 60.0;
    let mut world = World::new(WorldDef::default())?;
    // The hooks: a static body without shapes, so nothing but the sign
    // stops the ball.
    let ceiling = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 10.0)))?;
    // A 2 m × 0.5 m sign of 2 kg, hanging 1 m under the ceiling by two
    // joints at its top corners' anchors.
    let sign_at = Vec2::new(0.0, 8.65);
    let sign = world.create_body(&BodyDef::dynamic(sign_at))?;
    let sign_def = ShapeDef {
        density: 2.0,
        ..ShapeDef::default()
    };
    world.create_shape(sign, &sign_def, Polygon::make_box(1.0, 0.25))?;
    let mut joints = Vec::new();
    for x in [-0.9, 0.9] {
        let anchor = Vec2::new(x, 8.9);
        let mut def = RevoluteJointDef::new(
            ceiling,
            sign,
            anchor - Vec2::new(0.0, 10.0),
            anchor - sign_at,
        );
        def.base.force_threshold = BREAK_FORCE;
        joints.push(world.create_revolute_joint(&def)?);
    }
    world.set_body_enable_sleep(sign, false)?;
    for _ in 0..60 {
        world.step(dt)?;
    }
    let hanging_force = joints
        .iter()
        .map(|&j| world.joint_force(j).map(|f| f.y))
        .sum::<Result<Real, _>>()?;
    let sign_weight = world.mass(sign)? * -world.gravity().y;

    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.3, 11.9)))?;
    let ball_def = ShapeDef {
        density: ball_density,
        ..ShapeDef::default()
    };
    world.create_shape(ball, &ball_def, Circle::new(Vec2::ZERO, 0.3)?)?;
    let (mut peak_force, mut broke_at): (Real, [Option<usize>; 2]) = (0.0, [None, None]);
    for step in 0..180 {
        world.step(dt)?;
        let crossed: Vec<_> = world
            .events()
            .joints
            .iter()
            .map(|e| (e.joint, e.force))
            .collect();
        for (j, force) in crossed {
            let Some(k) = joints.iter().position(|&h| h == j) else {
                continue;
            };
            world.destroy_joint(j)?;
            broke_at[k] = Some(step);
            println!("step {step:3}: joint {k} broke at {:.0} N", force.length());
        }
        // The report's peak: the largest force a joint held.
        for (k, &j) in joints.iter().enumerate() {
            if broke_at[k].is_none() {
                peak_force = peak_force.max(world.joint_force(j)?.length());
            }
        }
    }
    let sign_drop = sign_at.y - world.position(sign)?.y;
    Ok(Report {
        hanging_force,
        sign_weight,
        peak_force,
        broke_at,
        sign_drop,
    })
}

fn main() -> Result<(), WorldError> {
    for (label, density) in [("light ball", 0.5), ("heavy ball", 200.0)] {
        let r = run(density)?;
        let broke: Vec<String> = r
            .broke_at
            .iter()
            .enumerate()
            .filter_map(|(k, step)| step.map(|s| format!("joint {k} at step {s}")))
            .collect();
        let outcome = if broke.is_empty() {
            format!(
                "both held, peak {:.0} N below the {BREAK_FORCE} N limit",
                r.peak_force
            )
        } else {
            format!(
                "broke above the {BREAK_FORCE} N limit ({}; largest force read before: {:.0} N)",
                broke.join(", "),
                r.peak_force
            )
        };
        println!(
            "{label}: the joints carried {:.2} N (sign weight {:.2} N); {outcome}; the sign fell {:.2} m",
            r.hanging_force, r.sign_weight, r.sign_drop
        );
    }
    Ok(())
}
