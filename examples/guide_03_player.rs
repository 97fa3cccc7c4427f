//! Guide step 3 (docs/guide.md): a player. A capsule that does not rotate,
//! moved by setting its horizontal velocity each step and jumping with an
//! impulse when it stands on something. The input is scripted (run right,
//! jump when a wall is near) so that the example runs headless. Run with
//! `cargo run --example guide_03_player`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// Whether `player` stands on something: a touching contact whose normal,
/// turned to point from the other body to the player, points up.
fn grounded(world: &World, player: BodyHandle) -> Result<bool, WorldError> {
    Ok(world.body_contacts(player)?.any(|c| {
        // A contact's normal points from body A to body B.
        let up = if c.body_b == player {
            c.normal
        } else {
            -c.normal
        };
        up.y > 0.7
    }))
}

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    // A 1 m step to jump onto, from x = 5 to 15.
    let block = world.create_body(&BodyDef::fixed(Vec2::new(10.0, 0.5)))?;
    world.create_shape(block, &ShapeDef::default(), Polygon::make_box(5.0, 0.5))?;

    // The player: a 1.6 m capsule that never tips over.
    let def = BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(0.0, 0.8))
    };
    let player = world.create_body(&def)?;
    let body_shape = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default().with_friction(0.2), body_shape)?;
    let mass = world.mass(player)?;

    let (run_speed, jump_speed) = (4.0, 6.5);
    let mut was_grounded = false;
    for step in 1..=180 {
        let t = step as Real * DT;
        let on_ground = grounded(&world, player)?;
        if on_ground && !was_grounded && step > 5 {
            let p = world.position(player)?;
            println!("t = {t:.2} s: landed at ({:.2}, {:.2})", p.x, p.y);
        }
        was_grounded = on_ground;
        // Input: hold "right"; press "jump" when the block is near.
        let v = world.linear_velocity(player)?;
        world.set_linear_velocity(player, Vec2::new(run_speed, v.y))?;
        let x = world.position(player)?.x;
        // (Not while still rising from the last jump: the contact it jumped
        // from lasts until the next step.)
        if on_ground && v.y < 0.1 && (3.5..4.5).contains(&x) {
            let centre = world.center_of_mass(player)?;
            world.apply_linear_impulse(player, Vec2::new(0.0, mass * jump_speed), centre)?;
            println!("t = {t:.2} s: jump at x = {x:.2}");
        }
        world.step(DT)?;
    }
    let p = world.position(player)?;
    println!(
        "after 3 s the player is at ({:.2}, {:.2}), on top of the block: {}",
        p.x,
        p.y,
        p.y > 1.5 && grounded(&world, player)?
    );
    Ok(())
}
