//! Guide step 1 (docs/guide.md): a world, stepped at 60 Hz. A world with
//! no bodies is valid; `step` takes the time step in seconds and returns an
//! error instead of panicking on bad input. Run with `cargo run --example
//! guide_01_world`.

use janus2d::prelude::*;

fn main() -> Result<(), WorldError> {
    // Gravity (0, -10) m/s², Box2D's soft step with 4 substeps, sleeping on.
    let mut world = World::new(WorldDef::default())?;
    println!(
        "gravity {:?} m/s², {} substeps",
        world.gravity(),
        world.settings().substeps
    );
    for _ in 0..60 {
        world.step(1.0 / 60.0)?;
    }
    println!(
        "stepped {} times: {} bodies",
        world.step_count(),
        world.body_count()
    );
    // Bad input is a typed error naming the problem, and the world is unchanged.
    let err = world.step(0.0).unwrap_err();
    println!("step(0.0) is refused: {err}");
    Ok(())
}
