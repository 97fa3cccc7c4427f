//! The filter joint: no rows, it only stops its two bodies colliding. Two
//! 1 m boxes of 1 kg start half overlapping in a world without gravity;
//! the left one moves right at 2 m/s. With a filter joint between them it
//! passes through the other (no contact, neither is pushed); without one
//! the contact first pushes the overlap apart and then the two collide.
//! Prints each run's contacts, final positions and velocities.
//! Run with `cargo run --release --example joint_filter`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// Runs 2 s; returns the steps the two boxes touched and both final
/// positions and velocities along x.
fn run(filtered: bool) -> Result<(usize, [Real; 4]), WorldError> {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    };
    let mut world = World::new(def)?;
    let shape = ShapeDef::default();
    let mover = world.create_body(&BodyDef::dynamic(Vec2::new(-0.5, 0.0)))?;
    world.create_shape(mover, &shape, Polygon::make_box(0.5, 0.5))?;
    let still = world.create_body(&BodyDef::dynamic(Vec2::ZERO))?;
    world.create_shape(still, &shape, Polygon::make_box(0.5, 0.5))?;
    world.set_linear_velocity(mover, Vec2::new(2.0, 0.0))?;
    if filtered {
        world.create_joint(&FilterJointDef::new(mover, still).into())?;
    }
    let mut touching = 0;
    for _ in 0..120 {
        world.step(DT)?;
        let between = world
            .body_contacts(mover)?
            .filter(|c| c.body_a == still || c.body_b == still)
            .count();
        touching += usize::from(between > 0);
    }
    Ok((
        touching,
        [
            world.position(mover)?.x,
            world.linear_velocity(mover)?.x,
            world.position(still)?.x,
            world.linear_velocity(still)?.x,
        ],
    ))
}

fn main() -> Result<(), WorldError> {
    for (label, filtered) in [("filter joint", true), ("no joint", false)] {
        let (touching, [x_a, v_a, x_b, v_b]) = run(filtered)?;
        println!(
            "{label:>12}: touching in {touching:3} of 120 steps; moving box at x = {x_a:5.2} m \
             ({v_a:.2} m/s), the other at x = {x_b:5.2} m ({v_b:.2} m/s)"
        );
    }
    Ok(())
}
