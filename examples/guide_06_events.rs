//! Guide step 6 (docs/guide.md): events. After each step the world lists
//! what began and ended: contacts, sensor overlaps (coins the player
//! collects), hits above a speed (a crate landing hard) and joints past a
//! force threshold, all in one `StepEvents`. Events describe the last step only; read them before
//! the next one. Shape user data tells the game what a shape is. Run with
//! `cargo run --example guide_06_events`.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;
const COIN: u64 = 7; // user data marking a coin

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;

    // Three coins: sensors, which report overlaps and never push.
    let coin_def = ShapeDef {
        is_sensor: true,
        user_data: COIN,
        ..ShapeDef::default()
    };
    let coins = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    for x in [2.0, 4.0, 6.0] {
        world.create_shape(coins, &coin_def, Circle::new(Vec2::new(x, 0.8), 0.2)?)?;
    }
    // A crate that falls from 5 m, with hit events on.
    let crate_ = world.create_body(&BodyDef::dynamic(Vec2::new(10.0, 5.0)))?;
    let loud = ShapeDef {
        enable_hit_events: true,
        ..ShapeDef::default()
    };
    world.create_shape(crate_, &loud, Polygon::make_box(0.5, 0.5))?;

    let player = world.create_body(&BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(0.0, 0.8))
    })?;
    let capsule = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default(), capsule)?;

    let mut score = 0;
    for step in 1..=120 {
        let v = world.linear_velocity(player)?;
        world.set_linear_velocity(player, Vec2::new(4.0, v.y))?;
        world.step(DT)?;
        let t = step as Real * DT;
        let events = world.events();
        for e in &events.collision.sensor_begin {
            // The sensor is the coin, the visitor the player?
            let (coin, other) = (e.sensor_shape, e.visitor_shape);
            if world.shape_user_data(coin)? == COIN && world.shape_body(other)? == player {
                score += 1;
                println!("t = {t:.2} s: coin collected (score {score})");
            }
        }
        for hit in &events.collision.hits {
            println!(
                "t = {t:.2} s: hit at ({:.2}, {:.2}), {:.1} m/s",
                hit.point_b.x, hit.point_b.y, hit.approach_speed
            );
        }
        for e in &events.collision.contact_begin {
            let bodies = [world.shape_body(e.shape_a)?, world.shape_body(e.shape_b)?];
            if bodies.contains(&crate_) {
                let n = e.manifold.normal;
                println!(
                    "t = {t:.2} s: the crate touches the ground ({} points, normal ({:.2}, {:.2}))",
                    e.manifold.point_count, n.x, n.y
                );
            }
        }
    }
    println!("score {score} of 3");
    Ok(())
}
