//! A hinged chain swinging under gravity, simulated headless, with a short
//! readout: run with `cargo run --release --example chain`.

use janus2d::prelude::*;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    let links = 20;
    let mut prev = ground;
    let mut bodies = Vec::new();
    for i in 0..links {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(i as Real + 0.5, 0.0)).with_mass(1.0, 0.1))?;
        let anchor_a = if i == 0 {
            Vec2::ZERO
        } else {
            Vec2::new(0.5, 0.0)
        };
        world.create_revolute_joint(&RevoluteJointDef::new(
            prev,
            b,
            anchor_a,
            Vec2::new(-0.5, 0.0),
        ))?;
        bodies.push(b);
        prev = b;
    }
    let tip = *bodies.last().expect("links");
    let dt = 1.0 / 60.0;
    println!(
        "janus2d: hinged chain of {links} links released horizontally, dt = 1/60 s, 4 substeps"
    );
    println!(
        "{:>6} {:>10} {:>10} {:>12} {:>12}",
        "t [s]", "tip x", "tip y", "tip |v|", "max gap"
    );
    let mut worst_gap: Real = 0.0;
    for step in 1..=600 {
        world.step(dt)?;
        worst_gap = worst_gap.max(world.max_joint_gap());
        if step % 60 == 0 {
            let p = world.position(tip)?;
            let v = world.linear_velocity(tip)?;
            println!(
                "{:>6.2} {:>10.3} {:>10.3} {:>12.3} {:>12.5}",
                step as Real * dt,
                p.x,
                p.y,
                v.length(),
                world.max_joint_gap()
            );
        }
    }
    println!(
        "10 s simulated: {} bodies, {} joints, worst joint gap {:.4} m",
        world.body_count(),
        world.joint_count(),
        worst_gap
    );
    Ok(())
}
