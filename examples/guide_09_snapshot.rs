//! Guide step 9 (docs/guide.md): snapshots. `World::snapshot` copies the
//! whole world (bodies, shapes, contacts with their warm-start impulses,
//! joints, portals, sleep); `World::restore` puts it back, and the run
//! continues bit for bit as it would have. A checkpoint to respawn at, a
//! rewind, or a replay. With the `serde` feature a snapshot also goes to
//! bytes (`Snapshot::to_bytes`, `Snapshot::from_bytes`) for a save file.
//! Run with `cargo run --example guide_09_snapshot`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    // A small stack of crates and a ball rolling into it.
    let mut crates = Vec::new();
    for i in 0..5 {
        let b = world.create_body(&BodyDef::dynamic(Vec2::new(3.0, 0.5 + i as Real)))?;
        world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
        crates.push(b);
    }
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(-3.0, 0.5)).with_velocity(Vec2::new(8.0, 0.0)))?;
    world.create_shape(
        ball,
        &ShapeDef::default().with_density(5.0),
        Circle::new(Vec2::ZERO, 0.5)?,
    )?;

    // The checkpoint: just before the ball hits the stack.
    for _ in 0..20 {
        world.step(DT)?;
    }
    let checkpoint = world.snapshot();
    let at = world.step_count();
    for _ in 0..120 {
        world.step(DT)?;
    }
    let first: Vec<Vec2> = crates
        .iter()
        .map(|&b| world.position(b))
        .collect::<Result<_, _>>()?;
    let first_hash = world.state_hash();
    println!(
        "step {}: top crate at ({:.3}, {:.3})",
        world.step_count(),
        first[4].x,
        first[4].y
    );

    // The player dies; back to the checkpoint, and the same 120 steps again.
    world.restore(&checkpoint);
    println!(
        "restored to step {} (the checkpoint was taken at step {at})",
        world.step_count()
    );
    for _ in 0..120 {
        world.step(DT)?;
    }
    let again: Vec<Vec2> = crates
        .iter()
        .map(|&b| world.position(b))
        .collect::<Result<_, _>>()?;
    println!(
        "step {}: top crate at ({:.3}, {:.3}); the same bits: {}",
        world.step_count(),
        again[4].x,
        again[4].y,
        again == first && world.state_hash() == first_hash
    );
    Ok(())
}
