//! Guide step 5 (docs/guide.md): scene queries. They read the world and
//! never change it: a ray down from the player's feet (is it standing on
//! something, and what), a ray to an enemy (line of sight, blocked by a
//! wall), a point test (what is under the mouse), a box test (what is near)
//! and a shape cast (how far can the player dash). Category bits keep
//! coins out of the player's rays. Run with `cargo run --example
//! guide_05_queries`.

use janus2d::Aabb;
use janus2d::prelude::*;

const COIN: u64 = 2;

fn main() -> Result<(), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let ground = world.create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))?;
    world.create_shape(ground, &ShapeDef::default(), Polygon::make_box(20.0, 0.5))?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(4.0, 1.5)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.25, 1.5))?;
    let enemy = world.create_body(&BodyDef::dynamic(Vec2::new(8.0, 0.5)))?;
    world.create_shape(enemy, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))?;
    let coin = world.create_body(&BodyDef::fixed(Vec2::new(0.0, 0.3)))?;
    let coin_def = ShapeDef {
        is_sensor: true,
        filter: Filter {
            category_bits: COIN,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    world.create_shape(coin, &coin_def, Circle::new(Vec2::ZERO, 0.2)?)?;
    let player = world.create_body(&BodyDef {
        fixed_rotation: true,
        ..BodyDef::dynamic(Vec2::new(0.0, 0.8))
    })?;
    let capsule = Capsule::new(Vec2::new(0.0, -0.5), Vec2::new(0.0, 0.5), 0.3)?;
    world.create_shape(player, &ShapeDef::default(), capsule)?;
    for _ in 0..30 {
        world.step(1.0 / 60.0)?;
    }

    // The player's own queries skip the player's body and see everything
    // but coins.
    let mine = QueryFilter::default().excluding(player).with_mask(!COIN);
    let feet = world.position(player)? - Vec2::new(0.0, 0.8);
    match world.cast_ray_closest(feet + Vec2::new(0.0, 0.1), Vec2::new(0.0, -0.2), &mine)? {
        Some(hit) => println!(
            "ground ray: stands on {:?} at y = {:.3}, normal ({:.1}, {:.1})",
            if hit.body == ground {
                "the ground"
            } else {
                "something"
            },
            hit.point.y,
            hit.normal.x,
            hit.normal.y
        ),
        None => println!("ground ray: in the air"),
    }

    let eye = world.position(player)? + Vec2::new(0.0, 0.5);
    let to_enemy = world.position(enemy)? - eye;
    let seen = world.cast_ray_closest(eye, to_enemy, &mine)?;
    println!(
        "line of sight to the enemy: {}",
        match seen {
            Some(hit) if hit.body == enemy => "clear".to_string(),
            Some(hit) => format!(
                "blocked at x = {:.2} (the wall: {})",
                hit.point.x,
                hit.body == wall
            ),
            None => "nothing there".to_string(),
        }
    );

    // What is under the mouse at (8, 0.5)? Sensors are skipped by queries.
    let mut picked = Vec::new();
    world.overlap_point(Vec2::new(8.0, 0.5), &QueryFilter::default(), |o| {
        picked.push(o.body);
        true // go on
    })?;
    println!("under the mouse: the enemy: {}", picked == [enemy]);

    // Everything within 5 m of the player (fat boxes, then exact shapes).
    let p = world.position(player)?;
    let mut near = 0;
    let area = Aabb::new(p - Vec2::splat(5.0), p + Vec2::splat(5.0));
    world.overlap_aabb(&area, &mine, |_| {
        near += 1;
        true
    })?;
    println!("shapes within 5 m of the player: {near} (ground, wall)");

    // How far can the player dash right before it hits something? Sweep its
    // own capsule 10 m to the right.
    let from = Transform::new(world.position(player)? + Vec2::new(0.0, 0.05), 0.0);
    let dash = Vec2::new(10.0, 0.0);
    let shape = Shape::Capsule(capsule);
    if let Some(hit) = world.cast_shape_closest(&shape, &from, dash, &mine)? {
        println!("dash: free for {:.2} m of 10", hit.fraction * dash.length());
    }
    Ok(())
}
