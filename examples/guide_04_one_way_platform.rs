//! Guide step 4 (docs/guide.md): a one-way platform. The player jumps up
//! through a thin platform from below and lands on top of it. A pre-solve
//! hook, called for every touching contact before the solve, returns
//! `false` to switch a contact off for this step: here, the platform's
//! contact with anything that is below it or moving up. Run with `cargo run
//! --example guide_04_one_way_platform`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    // A 4 m platform, 20 cm thick, its top at y = 2.5, right above the player.
    let platform = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 2.4)))?;
    let deck = world.create_shape(platform, &ShapeDef::default(), Polygon::make_box(2.0, 0.1))?;

    let def = BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(0.0, 0.8))
    };
    let player = world.create_body(&def)?;
    let capsule = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default(), capsule)?;

    // The hook sees both shapes, the normal (from A to B) and the bodies'
    // velocities. Keep the platform's contact only when the other body is
    // above it (the normal from the platform to it points up) and not
    // moving up.
    world.set_pre_solve(Some(Box::new(move |c| {
        let (up, other_velocity) = if c.shape_a == deck {
            (c.normal, c.velocity_b)
        } else if c.shape_b == deck {
            (-c.normal, c.velocity_a)
        } else {
            return true; // not the platform: solve as usual
        };
        up.y > 0.7 && other_velocity.y <= 0.5
    })));

    // Stand for half a second, then jump with 8 m/s.
    let mut peak = Real::MIN;
    for step in 1..=150 {
        if step == 30 {
            let m = world.mass(player)?;
            let centre = world.center_of_mass(player)?;
            world.apply_linear_impulse(player, Vec2::new(0.0, 8.0 * m), centre)?;
            println!(
                "t = {:.2} s: jump from y = {:.2}",
                step as Real * DT,
                world.position(player)?.y
            );
        }
        world.step(DT)?;
        peak = peak.max(world.position(player)?.y);
    }
    let feet = world.position(player)?.y - 0.8;
    println!("rose to y = {peak:.2} through the platform (top at 2.50)");
    println!("after 2.5 s the player's feet are at y = {feet:.2}: standing on the platform");
    Ok(())
}
