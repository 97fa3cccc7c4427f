//! The standard scenes of `../shared/spec/scenes.md`, built exactly as
//! specified, for benchmarks, hard-case tests, examples and the accuracy
//! sweep.
//!
//! | scene                | bodies  | what it stresses                        |
//! |----------------------|---------|-----------------------------------------|
//! | [`large_pyramid`]    | 5,051   | deep stacking, solver convergence       |
//! | [`many_pyramids`]    | 22,001  | many islands, broadphase, cache         |
//! | [`joint_grid`]       | 10,000  | 19,800 joints                           |
//! | [`tumbler`]          | 2,027   | a motor-driven drum, constant motion    |
//! | [`smash`]            | 9,601   | a fast projectile into a block, g = 0   |
//! | [`spinner`]          | 6,078   | a paddle in a one-sided loop, mixed shapes |
//!
//! Every builder returns a [`Scene`]: the world plus a probe body (the one a
//! benchmark's sanity line and the tests track).

use janus2d_constraints::RevoluteJointDef;
use janus2d_core::body::{BodyDef, BodyHandle};
use janus2d_core::geometry::{Capsule, Circle, Polygon, Segment, make_chain};
use janus2d_core::math::{PI, Real, Vec2};
use janus2d_world::{Filter, ShapeDef, World, WorldDef};

/// Shared step length of every scene, s (1/60).
pub const DT: Real = 1.0 / 60.0;

/// A built scene.
pub struct Scene {
    /// The world.
    pub world: World,
    /// The body whose motion the scene reports.
    pub probe: BodyHandle,
    /// What the probe is.
    pub probe_label: &'static str,
    /// Steps Box2D's benchmark runs for this scene.
    pub steps: usize,
}

/// The shared settings of `../shared/spec/scenes.md`: the default world
/// (gravity (0, −10), 4 substeps, contacts 30 Hz / ζ 10, joints 60 Hz / ζ 2,
/// push-out 3 m/s) with **sleep off**, as the hard cases and the benchmark
/// scenes (but `tumbler` and `spinner`) require.
pub fn shared_settings() -> WorldDef {
    let mut def = WorldDef::default();
    def.sleep.enabled = false;
    def
}

fn new_world(def: &WorldDef) -> World {
    World::new(def.clone()).expect("valid world definition")
}

fn box_def() -> ShapeDef {
    ShapeDef::default().with_density(1.0).with_friction(0.6)
}

/// A pyramid of `base` rows of unit boxes on a static ground box of half
/// extents (100, 1) at (0, −1). `base = 100` is `large_pyramid`, `base = 20`
/// the hard case "pyramid 20".
pub fn large_pyramid(def: &WorldDef, base: usize) -> Scene {
    let mut world = new_world(def);
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    world
        .create_shape(ground, &ShapeDef::default(), Polygon::make_box(100.0, 1.0))
        .unwrap();
    let square = Polygon::make_box(0.5, 0.5);
    let sd = box_def();
    let mut top = ground;
    for i in 0..base {
        let y = (2 * i + 1) as Real * 0.5;
        for j in i..base {
            let x = (i + 1) as Real * 0.5 + (j - i) as Real - 0.5 * base as Real;
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(x, y)))
                .unwrap();
            world.create_shape(b, &sd, square).unwrap();
            top = b;
        }
    }
    Scene {
        world,
        probe: top,
        probe_label: "top box",
        steps: 500,
    }
}

/// 20 × 20 pyramids of base 10 on 20 two-sided ground segments.
pub fn many_pyramids(def: &WorldDef) -> Scene {
    let (rows, cols, base) = (20, 20, 10);
    let mut world = new_world(def);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    for r in 0..rows {
        let y = 11.0 * r as Real;
        let seg = Segment::new(Vec2::new(-110.0, y), Vec2::new(110.0, y)).unwrap();
        world
            .create_shape(ground, &ShapeDef::default(), seg)
            .unwrap();
    }
    let square = Polygon::make_box(0.5, 0.5);
    let sd = box_def();
    let mut probe = None;
    for r in 0..rows {
        let base_y = 11.0 * r as Real;
        for c in 0..cols {
            let center_x = -110.0 + 11.0 * c as Real + 1.0;
            let mut last = ground;
            for i in 0..base {
                let y = (2 * i + 1) as Real * 0.5 + base_y;
                for j in i..base {
                    let x = (i + 1) as Real * 0.5 + (j - i) as Real + center_x - 0.5;
                    let b = world
                        .create_body(&BodyDef::dynamic(Vec2::new(x, y)))
                        .unwrap();
                    world.create_shape(b, &sd, square).unwrap();
                    last = b;
                }
            }
            probe.get_or_insert(last);
        }
    }
    Scene {
        world,
        probe: probe.unwrap(),
        probe_label: "top box of the first pyramid",
        steps: 200,
    }
}

/// `n × n` circles r 0.4 linked by revolute joints, hanging from 7 static
/// ones; the circles never collide with each other. `n = 100` is the
/// benchmark; the hard case uses `n = 40` with doubled gravity.
pub fn joint_grid(def: &WorldDef, n: usize) -> Scene {
    let mut world = new_world(def);
    let sd = ShapeDef {
        filter: Filter {
            category_bits: 2,
            mask_bits: !2u64,
            group_index: 0,
        },
        ..ShapeDef::default()
    };
    let circle = Circle::new(Vec2::ZERO, 0.4).unwrap();
    let mut grid: Vec<BodyHandle> = Vec::with_capacity(n * n);
    let mid = n / 2;
    for k in 0..n {
        for i in 0..n {
            let pos = Vec2::new(k as Real, -(i as Real));
            let is_static = i == 0 && k + 3 >= mid && k <= mid + 3;
            let body_def = if is_static {
                BodyDef::fixed(pos)
            } else {
                BodyDef::dynamic(pos)
            };
            let b = world.create_body(&body_def).unwrap();
            world.create_shape(b, &sd, circle).unwrap();
            if i > 0 {
                let above = grid[grid.len() - 1];
                world
                    .create_revolute_joint(&RevoluteJointDef::new(
                        above,
                        b,
                        Vec2::new(0.0, -0.5),
                        Vec2::new(0.0, 0.5),
                    ))
                    .unwrap();
            }
            if k > 0 {
                let left = grid[grid.len() - n];
                world
                    .create_revolute_joint(&RevoluteJointDef::new(
                        left,
                        b,
                        Vec2::new(0.5, 0.0),
                        Vec2::new(-0.5, 0.0),
                    ))
                    .unwrap();
            }
            grid.push(b);
        }
    }
    Scene {
        world,
        probe: grid[n - 1],
        probe_label: "bottom-left circle",
        steps: 500,
    }
}

/// A motor-driven hollow drum turning 45 × 45 small boxes.
pub fn tumbler(def: &WorldDef) -> Scene {
    let mut world = new_world(def);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let drum = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 10.0)))
        .unwrap();
    let wall = ShapeDef::default().with_density(50.0);
    for (hx, hy, cx, cy) in [
        (0.5, 10.0, 10.0, 0.0),
        (0.5, 10.0, -10.0, 0.0),
        (10.0, 0.5, 0.0, 10.0),
        (10.0, 0.5, 0.0, -10.0),
    ] {
        world
            .create_shape(
                drum,
                &wall,
                Polygon::make_offset_box(hx, hy, Vec2::new(cx, cy), 0.0),
            )
            .unwrap();
    }
    let motor = RevoluteJointDef::new(ground, drum, Vec2::new(0.0, 10.0), Vec2::ZERO)
        .with_motor(25.0 * PI / 180.0, 1e8);
    world.create_revolute_joint(&motor).unwrap();
    let small = Polygon::make_box(0.125, 0.125);
    let sd = box_def();
    for i in 0..45 {
        for j in 0..45 {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(
                    -9.0 + 0.4 * j as Real,
                    1.0 + 0.4 * i as Real,
                )))
                .unwrap();
            world.create_shape(b, &sd, small).unwrap();
        }
    }
    Scene {
        world,
        probe: drum,
        probe_label: "drum (motor 25 deg/s)",
        steps: 750,
    }
}

/// A heavy fast box smashing into a block of 120 × 80 small boxes, g = 0;
/// the block is created asleep (run it with sleep on, as Box2D does).
pub fn smash(def: &WorldDef) -> Scene {
    let mut def = def.clone();
    def.gravity = Vec2::ZERO;
    let mut world = new_world(&def);
    let projectile = world
        .create_body(&BodyDef::dynamic(Vec2::new(-20.0, 0.0)).with_velocity(Vec2::new(40.0, 0.0)))
        .unwrap();
    world
        .create_shape(
            projectile,
            &ShapeDef::default().with_density(8.0),
            Polygon::make_box(4.0, 4.0),
        )
        .unwrap();
    let small = Polygon::make_box(0.2, 0.2);
    let sd = box_def();
    for i in 0..120 {
        for j in 0..80 {
            let pos = Vec2::new(30.0 + 0.4 * i as Real, 0.4 * (j as Real - 40.0));
            let asleep = BodyDef {
                awake: false,
                ..BodyDef::dynamic(pos)
            };
            let b = world.create_body(&asleep).unwrap();
            world.create_shape(b, &sd, small).unwrap();
        }
    }
    Scene {
        world,
        probe: projectile,
        probe_label: "projectile",
        steps: 300,
    }
}

/// A motorised paddle stirring 6,076 mixed shapes inside a one-sided loop.
pub fn spinner(def: &WorldDef) -> Scene {
    let mut world = new_world(def);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let points: Vec<Vec2> = (0..360)
        .map(|i| {
            // Clockwise, so each segment's front normal (to the right of
            // its direction, the side that collides) points inwards.
            let a = -(i as Real) * 2.0 * PI / 360.0;
            Vec2::new(40.0 * a.cos(), 32.0 + 40.0 * a.sin())
        })
        .collect();
    let loop_def = ShapeDef::default().with_friction(0.1);
    for seg in make_chain(&points, true).unwrap() {
        world.create_shape(ground, &loop_def, seg).unwrap();
    }
    let paddle = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 12.0)))
        .unwrap();
    world
        .create_shape(
            paddle,
            &ShapeDef::default().with_friction(0.0),
            Polygon::make_rounded_box(0.4, 20.0, 0.2),
        )
        .unwrap();
    let motor = RevoluteJointDef::new(ground, paddle, Vec2::new(0.0, 12.0), Vec2::ZERO)
        .with_motor(5.0, Real::MAX);
    world.create_revolute_joint(&motor).unwrap();
    let sd = ShapeDef {
        density: 0.25,
        friction: 0.1,
        restitution: 0.1,
        ..ShapeDef::default()
    };
    let capsule = Capsule::new(Vec2::new(-0.25, 0.0), Vec2::new(0.25, 0.0), 0.25).unwrap();
    let circle = Circle::new(Vec2::ZERO, 0.35).unwrap();
    let square = Polygon::make_box(0.35, 0.35);
    let (mut x, mut y) = (-23.0, 2.0);
    for i in 0..6076 {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, y)))
            .unwrap();
        match i % 3 {
            0 => world.create_shape(b, &sd, capsule),
            1 => world.create_shape(b, &sd, circle),
            _ => world.create_shape(b, &sd, square),
        }
        .unwrap();
        x += 0.5;
        if x >= 23.0 {
            x = -23.0;
            y += 0.5;
        }
    }
    Scene {
        world,
        probe: paddle,
        probe_label: "paddle",
        steps: 500,
    }
}

/// Builds a benchmark scene by name.
pub fn by_name(name: &str, def: &WorldDef) -> Option<Scene> {
    Some(match name {
        "large_pyramid" => large_pyramid(def, 100),
        "pyramid20" => {
            let mut s = large_pyramid(def, 20);
            s.steps = 600;
            s
        }
        "many_pyramids" => many_pyramids(def),
        "joint_grid" => joint_grid(def, 100),
        "tumbler" => tumbler(def),
        "smash" => smash(def),
        "spinner" => spinner(def),
        #[cfg(feature = "portals")]
        "portal_stream" => portal_stream(def, true),
        "hole_stream" => portal_stream(def, false),
        _ => return None,
    })
}

/// Names of the benchmark scenes, in the order `all` runs them.
pub const NAMES: [&str; 9] = [
    "large_pyramid",
    "pyramid20",
    "many_pyramids",
    "joint_grid",
    "tumbler",
    "smash",
    "spinner",
    "portal_stream",
    "hole_stream",
];

#[cfg(feature = "portals")]
/// The portal "drop" scene: a 1 m box falls 5 m onto a floor portal (2 m
/// aperture, facing up); the partner sits on a wall to the left, facing +x.
/// Returns the scene (probe: the box) and the pair.
pub fn portal_drop(def: &WorldDef) -> (Scene, janus2d_world::PortalPairHandle) {
    use janus2d_world::{PortalDef, PortalPairDef};
    let mut world = new_world(def);
    let floor = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
        .unwrap();
    world
        .create_shape(floor, &ShapeDef::default(), Polygon::make_box(10.0, 0.5))
        .unwrap();
    let wall = world
        .create_body(&BodyDef::fixed(Vec2::new(-20.0, 5.0)))
        .unwrap();
    world
        .create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))
        .unwrap();
    let entry = PortalDef {
        body: floor,
        anchor: Vec2::new(0.0, 0.5),
        direction: Vec2::Y,
        half_width: 1.0,
    };
    let exit = PortalDef {
        body: wall,
        anchor: Vec2::new(0.5, 0.0),
        direction: Vec2::X,
        half_width: 1.0,
    };
    let pair = world
        .create_portal_pair(&PortalPairDef::new(entry, exit))
        .unwrap();
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 5.5)))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    (
        Scene {
            world,
            probe: b,
            probe_label: "box",
            steps: 120,
        },
        pair,
    )
}

/// The portal "stream" scene: 200 mixed shapes (boxes, circles, capsules)
/// pour down a funnel into a floor portal and come out of a wall portal
/// into a second room below. With `with_portal == false` the portal is
/// replaced by a plain 2 m hole in the funnel's floor (the bodies fall
/// straight through to the room below), for the cost comparison.
pub fn portal_stream(def: &WorldDef, with_portal: bool) -> Scene {
    let mut world = new_world(def);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let sd = ShapeDef::default();
    let solid = |world: &mut World, hx: Real, hy: Real, c: Vec2, a: Real| {
        world
            .create_shape(ground, &sd, Polygon::make_offset_box(hx, hy, c, a))
            .unwrap();
    };
    // Funnel: two slopes down to a 2 m opening at (0, 0), side walls.
    // 45° slopes whose upper faces run from (±10, 9) down to the aperture's
    // edges (±1, 0), so nothing can rest beside the opening.
    let slope = PI / 4.0;
    let normal_out = Vec2::new(-0.25 * (0.5 as Real).sqrt(), 0.25 * (0.5 as Real).sqrt());
    solid(
        &mut world,
        6.5,
        0.25,
        Vec2::new(5.5, 4.5) - normal_out,
        slope,
    );
    solid(
        &mut world,
        6.5,
        0.25,
        Vec2::new(-5.5, 4.5) - Vec2::new(-normal_out.x, normal_out.y),
        -slope,
    );
    solid(&mut world, 0.25, 12.0, Vec2::new(-10.25, 12.0), 0.0);
    solid(&mut world, 0.25, 12.0, Vec2::new(10.25, 12.0), 0.0);
    // Room below: floor, side walls.
    solid(&mut world, 40.0, 0.5, Vec2::new(0.0, -30.5), 0.0);
    solid(&mut world, 0.5, 10.0, Vec2::new(40.5, -20.0), 0.0);
    if with_portal {
        #[cfg(not(feature = "portals"))]
        panic!("the portal stream needs the `portals` feature");
        // The funnel's floor carries the entry portal; the exit is on a
        // wall of the room below, facing +x.
        #[cfg(feature = "portals")]
        {
            use janus2d_world::{PortalDef, PortalPairDef};
            let floor = world
                .create_body(&BodyDef::fixed(Vec2::new(0.0, -0.5)))
                .unwrap();
            world
                .create_shape(floor, &sd, Polygon::make_box(1.5, 0.5))
                .unwrap();
            let exit_wall = world
                .create_body(&BodyDef::fixed(Vec2::new(-40.5, -25.0)))
                .unwrap();
            world
                .create_shape(exit_wall, &sd, Polygon::make_box(0.5, 5.0))
                .unwrap();
            let entry = PortalDef {
                body: floor,
                anchor: Vec2::new(0.0, 0.5),
                direction: Vec2::Y,
                half_width: 1.0,
            };
            let exit = PortalDef {
                body: exit_wall,
                anchor: Vec2::new(0.5, 0.0),
                direction: Vec2::X,
                half_width: 1.0,
            };
            world
                .create_portal_pair(&PortalPairDef::new(entry, exit))
                .unwrap();
        }
    } else {
        // The same floor with a 2 m hole; the exit wall is kept as scenery.
        solid(&mut world, 0.25, 0.5, Vec2::new(-1.25, -0.5), 0.0);
        solid(&mut world, 0.25, 0.5, Vec2::new(1.25, -0.5), 0.0);
        solid(&mut world, 0.5, 5.0, Vec2::new(-40.5, -25.0), 0.0);
    }
    let capsule = Capsule::new(Vec2::new(-0.1, 0.0), Vec2::new(0.1, 0.0), 0.12).unwrap();
    let circle = Circle::new(Vec2::ZERO, 0.15).unwrap();
    let square = Polygon::make_box(0.15, 0.15);
    let mut probe = ground;
    for i in 0..200 {
        let (row, col) = (i / 20, i % 20);
        let pos = Vec2::new(-8.55 + 0.9 * col as Real, 10.0 + 0.6 * row as Real);
        let b = world.create_body(&BodyDef::dynamic(pos)).unwrap();
        match i % 3 {
            0 => world.create_shape(b, &sd, square),
            1 => world.create_shape(b, &sd, circle),
            _ => world.create_shape(b, &sd, capsule),
        }
        .unwrap();
        probe = b;
    }
    Scene {
        world,
        probe,
        probe_label: "last shape",
        steps: 1800,
    }
}

/// The hard case "vertical stack": `rows` 1 m boxes in a column with 0.1 m
/// gaps, x alternating ±0.01, μ 0.3, on a ground box (top at y = 0).
/// Probe: the top box; it rests at (0, rows − 0.5) while the stack stands.
pub fn vertical_stack(def: &WorldDef, rows: usize) -> Scene {
    let mut world = new_world(def);
    let ground = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    let sd = ShapeDef::default().with_friction(0.3);
    world
        .create_shape(ground, &sd, Polygon::make_box(50.0, 1.0))
        .unwrap();
    let mut top = ground;
    for i in 0..rows {
        let x = if i % 2 == 0 { 0.01 } else { -0.01 };
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(x, 0.55 + 1.1 * i as Real)))
            .unwrap();
        world
            .create_shape(b, &sd, Polygon::make_box(0.5, 0.5))
            .unwrap();
        top = b;
    }
    Scene {
        world,
        probe: top,
        probe_label: "top box",
        steps: 3600,
    }
}

/// The hard case "ball and chain": 40 capsule links (half-length 0.5,
/// r 0.125, density 20) in a horizontal line from a static pin at (0, 40),
/// jointed end to end, and a ball r 8 (density 20, ≈ 670:1) jointed to the
/// last link. Probe: the ball.
pub fn ball_and_chain(def: &WorldDef) -> Scene {
    let mut world = new_world(def);
    let pin = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 40.0)))
        .unwrap();
    let sd = ShapeDef::default().with_density(20.0);
    let link = Capsule::new(Vec2::new(-0.5, 0.0), Vec2::new(0.5, 0.0), 0.125).unwrap();
    let mut prev = pin;
    let mut prev_anchor = Vec2::ZERO;
    for i in 0..40 {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.5 + i as Real, 40.0)))
            .unwrap();
        world.create_shape(b, &sd, link).unwrap();
        world
            .create_revolute_joint(&RevoluteJointDef::new(
                prev,
                b,
                prev_anchor,
                Vec2::new(-0.5, 0.0),
            ))
            .unwrap();
        prev = b;
        prev_anchor = Vec2::new(0.5, 0.0);
    }
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(48.0, 40.0)))
        .unwrap();
    world
        .create_shape(ball, &sd, Circle::new(Vec2::ZERO, 8.0).unwrap())
        .unwrap();
    world
        .create_revolute_joint(&RevoluteJointDef::new(
            prev,
            ball,
            prev_anchor,
            Vec2::new(-8.0, 0.0),
        ))
        .unwrap();
    Scene {
        world,
        probe: ball,
        probe_label: "ball",
        steps: 600,
    }
}

/// The hard case "bridge": 160 planks half 0.5×0.125 (density 20, mass set
/// directly, linear damping 0.1; joints only, no shapes) hinged end to end,
/// both ends pinned. Probe: the middle plank.
pub fn bridge(def: &WorldDef) -> Scene {
    let mut world = new_world(def);
    let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let (hx, hy): (Real, Real) = (0.5, 0.125);
    let density: Real = 20.0;
    let m = density * 4.0 * hx * hy;
    let inertia = m * (4.0 * hx * hx + 4.0 * hy * hy) / 12.0;
    let n = 160;
    let x0 = -(n as Real) * hx;
    let mut prev = ground;
    let mut middle = ground;
    for i in 0..n {
        let mut body =
            BodyDef::dynamic(Vec2::new(x0 + hx + 2.0 * hx * i as Real, 0.0)).with_mass(m, inertia);
        body.linear_damping = 0.1;
        let b = world.create_body(&body).unwrap();
        let anchor_a = if i == 0 {
            Vec2::new(x0, 0.0)
        } else {
            Vec2::new(hx, 0.0)
        };
        world
            .create_revolute_joint(&RevoluteJointDef::new(
                prev,
                b,
                anchor_a,
                Vec2::new(-hx, 0.0),
            ))
            .unwrap();
        if i == n / 2 {
            middle = b;
        }
        prev = b;
    }
    world
        .create_revolute_joint(&RevoluteJointDef::new(
            prev,
            ground,
            Vec2::new(hx, 0.0),
            Vec2::new(-x0, 0.0),
        ))
        .unwrap();
    Scene {
        world,
        probe: middle,
        probe_label: "middle plank",
        steps: 600,
    }
}
