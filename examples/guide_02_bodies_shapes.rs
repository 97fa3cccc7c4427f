//! Guide step 2 (docs/guide.md): bodies and shapes. A body is a pose and a
//! velocity; shapes attached to it give it its collision and, from their
//! density, its mass. The level: a static ground box, a one-sided chain of
//! hills, and a box, a ball and a capsule dropped onto them. Run with
//! `cargo run --example guide_02_bodies_shapes`.

use janus2d::prelude::*;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;

    // Static ground: 40 m wide, its top at y = 0 (make_box takes half sizes).
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;

    // Hills from x = 6 to 18 as a chain of one-sided segments. A segment is
    // solid on the right-hand side of its direction, so a chain walked on
    // from above runs right to left.
    let hills: Vec<Vec2> = (0..=12)
        .map(|i| {
            let x = 18.0 - i as Real;
            Vec2::new(x, 0.5 * (0.5 * (x - 6.0)).sin().abs())
        })
        .collect();
    let terrain = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    for segment in make_chain(&hills, false)? {
        world.create_shape(terrain, &ShapeDef::default(), segment)?;
    }

    // Three dynamic bodies, 1 kg/m² (the default density) unless set.
    let crate_ = world.create_body(&BodyDef::dynamic(Vec2::new(-2.0, 3.0)))?;
    world.create_shape(crate_, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
    let ball = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 5.0)))?;
    let rubber = ShapeDef::default().with_restitution(0.6);
    world.create_shape(ball, &rubber, Circle::new(Vec2::ZERO, 0.4)?)?;
    let log = world.create_body(&BodyDef::dynamic(Vec2::new(9.0, 4.0)).with_angle(0.3))?;
    let capsule = Capsule::new(Vec2::new(-0.8, 0.0), Vec2::new(0.8, 0.0), 0.25)?;
    world.create_shape(log, &ShapeDef::default().with_density(2.0), capsule)?;

    for (name, body) in [("crate", crate_), ("ball", ball), ("log", log)] {
        println!("{name}: {:.2} kg", world.mass(body)?);
    }
    for _ in 0..240 {
        world.step(1.0 / 60.0)?;
    }
    for (name, body) in [("crate", crate_), ("ball", ball), ("log", log)] {
        let p = world.position(body)?;
        println!(
            "after 4 s the {name} is at ({:.2}, {:.2}), {}",
            p.x,
            p.y,
            if world.is_sleeping(body)? {
                "asleep"
            } else {
                "awake"
            }
        );
    }
    Ok(())
}
