//! Box2D v3's ten benchmark scenes, plus `pyramid20` and the portal stream,
//! as [`SceneDesc`]s.
//!
//! | scene            | steps | bodies at the end | what it stresses                      |
//! |------------------|-------|-------------------|---------------------------------------|
//! | `large_pyramid`  | 500   | 5,051             | deep stacking, solver convergence     |
//! | `pyramid20`      | 600   | 211               | the same, small                       |
//! | `many_pyramids`  | 200   | 22,001            | many islands, broadphase, cache       |
//! | `joint_grid`     | 500   | 10,000            | 19,800 joints                         |
//! | `tumbler`        | 750   | 2,027             | a motor-driven drum, sleep on         |
//! | `smash`          | 300   | 9,601             | a fast projectile into a sleeping block |
//! | `spinner`        | 500   | 6,078             | a paddle in a one-sided loop          |
//! | `rain`           | 1000  | 11,001            | ragdolls spawned and destroyed        |
//! | `junkyard`       | 800   | 8,002             | pentagons pushed by a kinematic target |
//! | `compounds`      | 500   | 3,001             | two-triangle compound bodies          |
//! | `washer`         | 500   | 8,102             | a turning kinematic ring              |
//! | `portal_stream`  | 1800  | 205               | 200 shapes through a portal (janus2d) |
//! | `hole_stream`    | 1800  | 205               | the same through a plain hole         |
//!
//! Constructions follow Box2D's benchmark set exactly (positions, sizes,
//! materials, filters); the sanity figures in [`Reference`] are Box2D's.

use std::f64::consts::PI;

use glam::DVec2;

use crate::desc::*;

/// Names of the benchmark scenes, in the order `all` runs them.
pub const NAMES: [&str; 13] = [
    "large_pyramid",
    "pyramid20",
    "many_pyramids",
    "joint_grid",
    "tumbler",
    "smash",
    "spinner",
    "rain",
    "junkyard",
    "compounds",
    "washer",
    "portal_stream",
    "hole_stream",
];

/// Box2D's ten scenes (the ones all three engines run).
pub const BOX2D_TEN: [&str; 10] = [
    "large_pyramid",
    "many_pyramids",
    "joint_grid",
    "tumbler",
    "smash",
    "spinner",
    "rain",
    "junkyard",
    "compounds",
    "washer",
];

/// A benchmark scene by name.
#[must_use]
pub fn by_name(name: &str) -> Option<SceneDesc> {
    Some(match name {
        "large_pyramid" => pyramid(100),
        "pyramid20" => {
            let mut d = pyramid(20);
            d.name = "pyramid20";
            d.steps = 600;
            d
        }
        "many_pyramids" => many_pyramids(),
        "joint_grid" => joint_grid(100, 1.0),
        "tumbler" => tumbler(),
        "smash" => smash(),
        "spinner" => spinner(),
        "rain" => rain(),
        "junkyard" => junkyard(),
        "compounds" => compounds(),
        "washer" => washer(),
        "portal_stream" => stream(true),
        "hole_stream" => stream(false),
        _ => return None,
    })
}

fn unit_box() -> ShapeDesc {
    ShapeDesc::new(square(0.5, 0.5))
}

/// A pyramid of `base` rows of unit boxes on a static ground box of half
/// extents (100, 1) at (0, −1). Probe: the top box.
#[must_use]
pub fn pyramid(base: usize) -> SceneDesc {
    let mut d = SceneDesc::new("large_pyramid", 500);
    d.add(BodyDesc::fixed(v(0.0, -1.0)).with(ShapeDesc::new(square(100.0, 1.0))));
    for i in 0..base {
        let y = (2 * i + 1) as f64 * 0.5;
        for j in i..base {
            let x = (i + 1) as f64 * 0.5 + (j - i) as f64 - 0.5 * base as f64;
            d.probe = Some(d.add(BodyDesc::dynamic(v(x, y)).with(unit_box())));
        }
    }
    d.probe_label = "top box";
    if base == 100 {
        d.reference.probe_position = Some(v(0.017, 98.77));
    }
    d
}

/// 20 × 20 pyramids of base 10 on 20 two-sided ground segments. Probe: the
/// top box of the first pyramid.
#[must_use]
pub fn many_pyramids() -> SceneDesc {
    many_pyramids_of(20, 20)
}

/// `many_pyramids` with `rows` × `cols` pyramids of base 10 (the
/// benchmark is 20 × 20), for the scaling run: the same layout, more or
/// fewer rows.
#[must_use]
pub fn many_pyramids_of(rows: usize, cols: usize) -> SceneDesc {
    let base = 10;
    let mut d = SceneDesc::new("many_pyramids", 200);
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    for r in 0..rows {
        let y = 11.0 * r as f64;
        ground.shapes.push(ShapeDesc::new(Geometry::Segment {
            a: v(-110.0, y),
            b: v(110.0, y),
        }));
    }
    d.add(ground);
    for r in 0..rows {
        let base_y = 11.0 * r as f64;
        for c in 0..cols {
            let center_x = -110.0 + 11.0 * c as f64 + 1.0;
            let mut last = 0;
            for i in 0..base {
                let y = (2 * i + 1) as f64 * 0.5 + base_y;
                for j in i..base {
                    let x = (i + 1) as f64 * 0.5 + (j - i) as f64 + center_x - 0.5;
                    last = d.add(BodyDesc::dynamic(v(x, y)).with(unit_box()));
                }
            }
            d.probe.get_or_insert(last);
        }
    }
    d.probe_label = "top box of the first pyramid";
    if (rows, cols) == (20, 20) {
        d.reference.touching = Some(58_000.0);
    }
    d
}

/// `n × n` circles r 0.4 linked by revolute joints, hanging from 7 static
/// ones; the circles never collide with each other. `n = 100` is the
/// benchmark; the hard case uses `n = 40` with `gravity_scale = 2`.
/// Probe: the bottom-left circle.
#[must_use]
pub fn joint_grid(n: usize, gravity_scale: f64) -> SceneDesc {
    let mut d = SceneDesc::new("joint_grid", 500);
    d.settings.gravity *= gravity_scale;
    let mut shape = ShapeDesc::new(Geometry::Circle {
        center: DVec2::ZERO,
        radius: 0.4,
    });
    shape.filter = FilterDesc {
        category: 2,
        mask: !2,
        group: 0,
    };
    let mid = n / 2;
    for k in 0..n {
        for i in 0..n {
            let pos = v(k as f64, -(i as f64));
            let body = if i == 0 && k + 3 >= mid && k <= mid + 3 {
                BodyDesc::fixed(pos)
            } else {
                BodyDesc::dynamic(pos)
            };
            let b = d.add(body.with(shape.clone()));
            if i > 0 {
                d.join(RevoluteDesc::new(b - 1, b, v(0.0, -0.5), v(0.0, 0.5)));
            }
            if k > 0 {
                d.join(RevoluteDesc::new(b - n, b, v(0.5, 0.0), v(-0.5, 0.0)));
            }
        }
    }
    d.probe = Some(n - 1);
    d.probe_label = "bottom-left circle";
    d
}

/// A motor-driven hollow drum turning 45 × 45 small boxes; sleep on.
/// Probe: the drum. Container: the drum's inside.
#[must_use]
pub fn tumbler() -> SceneDesc {
    let mut d = SceneDesc::new("tumbler", 750);
    d.settings.sleep = true;
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO));
    let mut drum = BodyDesc::dynamic(v(0.0, 10.0));
    for (hx, hy, cx, cy) in [
        (0.5, 10.0, 10.0, 0.0),
        (0.5, 10.0, -10.0, 0.0),
        (10.0, 0.5, 0.0, 10.0),
        (10.0, 0.5, 0.0, -10.0),
    ] {
        drum.shapes
            .push(ShapeDesc::new(offset_box(hx, hy, v(cx, cy))).density(50.0));
    }
    let drum = d.add(drum);
    let mut motor = RevoluteDesc::new(ground, drum, v(0.0, 10.0), DVec2::ZERO);
    motor.motor = Some((25.0 * PI / 180.0, 1e8));
    d.join(motor);
    for i in 0..45 {
        for j in 0..45 {
            let pos = v(-9.0 + 0.4 * j as f64, 1.0 + 0.4 * i as f64);
            d.add(BodyDesc::dynamic(pos).with(ShapeDesc::new(square(0.125, 0.125))));
        }
    }
    d.probe = Some(drum);
    d.probe_label = "drum (motor 25 deg/s)";
    d.container = Some(Container {
        body: Some(drum),
        region: Region::Rect {
            center: DVec2::ZERO,
            half: v(9.6, 9.6),
        },
    });
    d.reference.probe_angle = Some(-0.829);
    d.reference.touching = Some(4_075.0);
    d
}

/// A heavy fast box smashing into a block of 120 × 80 small boxes created
/// asleep; gravity 0, sleep on. Probe: the projectile.
#[must_use]
pub fn smash() -> SceneDesc {
    let mut d = SceneDesc::new("smash", 300);
    d.settings.gravity = DVec2::ZERO;
    d.settings.sleep = true;
    let mut projectile =
        BodyDesc::dynamic(v(-20.0, 0.0)).with(ShapeDesc::new(square(4.0, 4.0)).density(8.0));
    projectile.linear_velocity = v(40.0, 0.0);
    d.probe = Some(d.add(projectile));
    for i in 0..120 {
        for j in 0..80 {
            let mut b = BodyDesc::dynamic(v(30.0 + 0.4 * i as f64, 0.4 * (j as f64 - 40.0)))
                .with(ShapeDesc::new(square(0.2, 0.2)));
            b.awake = false;
            d.add(b);
        }
    }
    d.probe_label = "projectile";
    d.reference.probe_position = Some(v(92.4, 1.36));
    d.reference.touching = Some(1_893.0);
    d
}

/// A motorised paddle stirring 6,076 mixed shapes inside a one-sided loop;
/// sleep on. Probe: the paddle. Container: the loop.
#[must_use]
pub fn spinner() -> SceneDesc {
    let mut d = SceneDesc::new("spinner", 500);
    d.settings.sleep = true;
    // Clockwise, so each segment's colliding side faces inwards.
    let points = (0..360)
        .map(|i| {
            let a = -(i as f64) * 2.0 * PI / 360.0;
            v(40.0 * a.cos(), 32.0 + 40.0 * a.sin())
        })
        .collect();
    let ground = d.add(
        BodyDesc::fixed(DVec2::ZERO)
            .with(ShapeDesc::new(Geometry::ChainLoop { points }).friction(0.1)),
    );
    let paddle = d.add(
        BodyDesc::dynamic(v(0.0, 12.0)).with(
            ShapeDesc::new(Geometry::Box {
                half: v(0.4, 20.0),
                center: DVec2::ZERO,
                angle: 0.0,
                radius: 0.2,
            })
            .friction(0.0),
        ),
    );
    let mut motor = RevoluteDesc::new(ground, paddle, v(0.0, 12.0), DVec2::ZERO);
    motor.motor = Some((5.0, f64::MAX));
    d.join(motor);
    let material = |g| ShapeDesc {
        density: 0.25,
        friction: 0.1,
        restitution: 0.1,
        ..ShapeDesc::new(g)
    };
    let (mut x, mut y) = (-23.0, 2.0);
    for i in 0..6076 {
        let g = match i % 3 {
            0 => Geometry::Capsule {
                a: v(-0.25, 0.0),
                b: v(0.25, 0.0),
                radius: 0.25,
            },
            1 => Geometry::Circle {
                center: DVec2::ZERO,
                radius: 0.35,
            },
            _ => square(0.35, 0.35),
        };
        d.add(BodyDesc::dynamic(v(x, y)).with(material(g)));
        x += 0.5;
        if x >= 23.0 {
            x = -23.0;
            y += 0.5;
        }
    }
    d.probe = Some(paddle);
    d.probe_label = "paddle";
    d.container = Some(Container {
        body: None,
        region: Region::Disc {
            center: v(0.0, 32.0),
            radius: 40.0,
        },
    });
    d.reference.probe_angle = Some(-2.322);
    d.reference.touching = Some(16_116.0);
    d
}

/// Box2D's `rain`: 5 ground rows of 501 small boxes, ragdolls raining in
/// columns (see [`Script::Rain`]); sleep on. No probe.
#[must_use]
pub fn rain() -> SceneDesc {
    let mut d = SceneDesc::new("rain", 1000);
    d.settings.sleep = true;
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    for row in 0..5 {
        let y = 45.0 * row as f64;
        for j in 0..=500 {
            let x = -125.0 + 0.5 * j as f64;
            ground
                .shapes
                .push(ShapeDesc::new(offset_box(0.25, 0.25, v(x, y))));
        }
    }
    d.add(ground);
    d.script = Script::Rain {
        rows: 5,
        columns: 40,
        group_size: 5,
    };
    d.reference.bodies = Some(11_001.0);
    d.reference.awake = Some(10_296.0);
    d
}

/// The group of `size` ragdolls of rain's (row, column).
#[must_use]
pub fn rain_group(row: usize, column: usize, size: usize) -> (Vec<BodyDesc>, Vec<RevoluteDesc>) {
    let mut position = v(
        -125.0 + 6.25 * (column as f64 + 0.5),
        40.0 + 45.0 * row as f64,
    );
    let (mut bodies, mut joints) = (Vec::new(), Vec::new());
    for i in 0..size {
        ragdoll(
            position,
            1.0,
            0.05,
            5.0,
            0.5,
            i as i32 + 1,
            &mut bodies,
            &mut joints,
        );
        position.x += 0.5;
    }
    (bodies, joints)
}

/// Box2D's `CreateHuman`: 11 capsule bones (a foot polygon on each shin),
/// 10 limited revolute joints with an angular spring and a friction motor.
/// Bodies and joints are appended; joint indices are into `bodies`.
pub fn ragdoll(
    position: DVec2,
    scale: f64,
    friction_torque: f64,
    hertz: f64,
    damping_ratio: f64,
    group: i32,
    bodies: &mut Vec<BodyDesc>,
    joints: &mut Vec<RevoluteDesc>,
) {
    let s = scale;
    let filter = FilterDesc {
        category: 2,
        mask: 1 | 2,
        group: -group,
    };
    let bone_shape = |g| ShapeDesc {
        friction: 0.2,
        filter,
        ..ShapeDesc::new(g)
    };
    let foot = ShapeDesc {
        friction: 0.05,
        filter: FilterDesc { mask: 1, ..filter },
        ..ShapeDesc::new(Geometry::Hull {
            points: vec![
                v(-0.03 * s, -0.185 * s),
                v(0.11 * s, -0.185 * s),
                v(0.11 * s, -0.16 * s),
                v(-0.03 * s, -0.14 * s),
            ],
            radius: 0.015 * s,
        })
    };
    // (parent, body y, capsule y0, y1, radius, damping, friction scale,
    //  pivot y, limits, reference angle, foot)
    type Bone = (
        Option<usize>,
        f64,
        f64,
        f64,
        f64,
        f64,
        f64,
        f64,
        (f64, f64),
        f64,
        bool,
    );
    let bones: [Bone; 11] = [
        (
            None,
            0.95,
            -0.02,
            0.02,
            0.095,
            0.0,
            1.0,
            0.0,
            (0.0, 0.0),
            0.0,
            false,
        ), // hip
        (
            Some(0),
            1.2,
            -0.135,
            0.135,
            0.09,
            0.0,
            0.5,
            1.0,
            (-0.25, 0.0),
            0.0,
            false,
        ), // torso
        (
            Some(1),
            1.475,
            -0.038,
            0.039,
            0.075,
            0.1,
            0.25,
            1.4,
            (-0.3, 0.1),
            0.0,
            false,
        ), // head
        (
            Some(0),
            0.775,
            -0.125,
            0.125,
            0.06,
            0.0,
            1.0,
            0.9,
            (-0.05, 0.4),
            0.0,
            false,
        ), // upper left leg
        (
            Some(3),
            0.475,
            -0.155,
            0.125,
            0.045,
            0.0,
            0.5,
            0.625,
            (-0.5, -0.02),
            0.0,
            true,
        ), // lower left leg
        (
            Some(0),
            0.775,
            -0.125,
            0.125,
            0.06,
            0.0,
            1.0,
            0.9,
            (-0.05, 0.4),
            0.0,
            false,
        ), // upper right leg
        (
            Some(5),
            0.475,
            -0.155,
            0.125,
            0.045,
            0.0,
            0.5,
            0.625,
            (-0.5, -0.02),
            0.0,
            true,
        ), // lower right leg
        (
            Some(1),
            1.225,
            -0.125,
            0.125,
            0.035,
            0.0,
            0.5,
            1.35,
            (-0.1, 0.8),
            0.0,
            false,
        ), // upper left arm
        (
            Some(7),
            0.975,
            -0.125,
            0.125,
            0.03,
            0.1,
            0.1,
            1.1,
            (-0.2, 0.3),
            0.25,
            false,
        ), // lower left arm
        (
            Some(1),
            1.225,
            -0.125,
            0.125,
            0.035,
            0.0,
            0.5,
            1.35,
            (-0.1, 0.8),
            0.0,
            false,
        ), // upper right arm
        (
            Some(9),
            0.975,
            -0.125,
            0.125,
            0.03,
            0.1,
            0.1,
            1.1,
            (-0.2, 0.3),
            0.25,
            false,
        ), // lower right arm
    ];
    let first = bodies.len();
    for (
        parent,
        y,
        y0,
        y1,
        radius,
        damping,
        friction_scale,
        pivot_y,
        (lo, hi),
        reference,
        has_foot,
    ) in bones
    {
        let at = position + v(0.0, y * s);
        let mut body = BodyDesc::dynamic(at).with(bone_shape(Geometry::Capsule {
            a: v(0.0, y0 * s),
            b: v(0.0, y1 * s),
            radius: radius * s,
        }));
        if has_foot {
            body.shapes.push(foot.clone());
        }
        body.linear_damping = damping;
        body.sleep_threshold = 0.1;
        bodies.push(body);
        if let Some(parent) = parent {
            let parent = first + parent;
            let pivot = position + v(0.0, pivot_y * s);
            let child = bodies.len() - 1;
            let mut joint =
                RevoluteDesc::new(parent, child, pivot - bodies[parent].position, pivot - at);
            joint.reference_angle = reference * PI;
            joint.limit = Some((lo * PI, hi * PI));
            joint.motor = Some((0.0, friction_scale * friction_torque * s));
            if hertz > 0.0 {
                joint.spring = Some((hertz, damping_ratio));
            }
            joints.push(joint);
        }
    }
}

fn floor_and_walls(ground: &mut BodyDesc, half_count: i32, wall_count: i32) {
    for i in -half_count..=half_count {
        ground
            .shapes
            .push(ShapeDesc::new(offset_box(0.55, 0.5, v(i as f64, 0.0))));
    }
    for x in [-half_count, half_count] {
        for k in 0..wall_count {
            ground.shapes.push(ShapeDesc::new(offset_box(
                0.5,
                0.55,
                v(x as f64, 1.0 + k as f64),
            )));
        }
    }
}

/// Box2D's `junkyard`: 8,000 pentagons between walls, pushed by a
/// kinematic box driven to a target each step; sleep on. Probe: the pusher.
#[must_use]
pub fn junkyard() -> SceneDesc {
    let mut d = SceneDesc::new("junkyard", 800);
    d.settings.sleep = true;
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    floor_and_walls(&mut ground, 80, 50);
    d.add(ground);
    // Five points at multiples of the golden angle: an irregular pentagon.
    let phi = PI * (5.0f64.sqrt() - 1.0);
    let pentagon = Geometry::Hull {
        points: (0..5)
            .map(|i| {
                let theta = phi * i as f64;
                v(0.25 * theta.cos(), 0.25 * theta.sin())
            })
            .collect(),
        radius: 0.0,
    };
    let mut side = -0.1;
    for i in 0..200 {
        let x = 1.5 * (2.0 * i as f64 - 200.0) * 0.25;
        for j in 0..40 {
            let y = j as f64 + 15.0;
            d.add(BodyDesc::dynamic(v(x + side, y)).with(ShapeDesc::new(pentagon.clone())));
            side = -side;
        }
    }
    let pusher = d.add(
        BodyDesc::kinematic(DVec2::ZERO).with(ShapeDesc::new(offset_box(2.0, 4.0, v(0.0, 4.0)))),
    );
    d.script = Script::Pusher {
        body: pusher,
        amplitude: 60.0,
        rate: 0.2,
    };
    d.probe = Some(pusher);
    d.probe_label = "pusher";
    d.reference.probe_position = Some(v(27.654, 0.0));
    d.reference.touching = Some(16_526.0);
    d
}

/// Box2D's `compounds`: 3,000 bodies of two triangles each between walls;
/// sleep on. Probe: the last body.
#[must_use]
pub fn compounds() -> SceneDesc {
    let mut d = SceneDesc::new("compounds", 500);
    d.settings.sleep = true;
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    floor_and_walls(&mut ground, 40, 100);
    ground.shapes.push(ShapeDesc::new(Geometry::Segment {
        a: v(-800.0, -80.0),
        b: v(800.0, -80.0),
    }));
    d.add(ground);
    let triangle = |points: [DVec2; 3]| {
        ShapeDesc::new(Geometry::Hull {
            points: points.to_vec(),
            radius: 0.0,
        })
        .friction(0.5)
    };
    let left = triangle([v(-1.0, 0.0), v(0.5, 1.0), v(0.0, 2.0)]);
    let right = triangle([v(1.0, 0.0), v(-0.5, 1.0), v(0.0, 2.0)]);
    let mut side = 0.25;
    for i in 0..20 {
        let x = 2.0 * i as f64 - 19.0;
        for j in 0..150 {
            let y = 2.25 * j as f64 + 0.575 + 5.0;
            d.probe = Some(
                d.add(
                    BodyDesc::dynamic(v(x + side, y))
                        .with(left.clone())
                        .with(right.clone()),
                ),
            );
            side = -side;
        }
    }
    d.probe_label = "last compound";
    d.reference.touching = Some(12_161.0);
    d
}

/// Box2D's `washer`: a kinematic ring (36 wall quads, 4 paddles) turning
/// 8,100 small boxes; sleep on, hit events on. Probe: the ring.
/// Container: inside the ring.
#[must_use]
pub fn washer() -> SceneDesc {
    let mut d = SceneDesc::new("washer", 500);
    d.settings.sleep = true;
    d.add(BodyDesc::fixed(DVec2::ZERO));
    let mut ring = BodyDesc::kinematic(v(0.0, 10.0));
    ring.angular_velocity = 25.0 * PI / 180.0;
    ring.linear_velocity = v(0.001, -0.002);
    let (r0, r1, r2) = (14.0, 16.0, 18.0);
    let sector = PI / 18.0;
    let widen = 0.1 * sector;
    let dir = |a: f64| v(a.cos(), a.sin());
    let quad = |p: [DVec2; 4]| {
        ShapeDesc::new(Geometry::Hull {
            points: p.to_vec(),
            radius: 0.0,
        })
    };
    for i in 0..36 {
        let a1 = sector * i as f64;
        let a2 = if i == 35 {
            0.0
        } else {
            sector * (i + 1) as f64
        };
        let (w1, w2) = (dir(a1 - widen), dir(a2 + widen));
        ring.shapes.push(quad([r1 * w1, r2 * w1, r1 * w2, r2 * w2]));
        if i % 9 == 0 {
            let (u1, u2) = (dir(a1), dir(a2));
            ring.shapes.push(quad([r0 * u1, r1 * u1, r0 * u2, r1 * u2]));
        }
    }
    let ring = d.add(ring);
    for i in 0..90 {
        for j in 0..90 {
            let mut shape = ShapeDesc::new(square(0.1, 0.1));
            shape.hit_events = true;
            d.add(BodyDesc::dynamic(v(-9.9 + 0.21 * j as f64, 0.1 + 0.21 * i as f64)).with(shape));
        }
    }
    d.probe = Some(ring);
    d.probe_label = "ring";
    d.container = Some(Container {
        body: Some(ring),
        region: Region::Disc {
            center: DVec2::ZERO,
            radius: 16.5,
        },
    });
    d.reference.probe_angle = Some(-2.647);
    d.reference.touching = Some(19_359.0);
    d
}

/// The portal "stream": 200 mixed shapes (boxes, circles, capsules) pour
/// down a funnel into a floor portal and come out of a wall portal into a
/// room below. With `with_portal == false` the portal is a plain 2 m hole
/// in the funnel's floor, for the cost comparison. Probe: the last shape.
#[must_use]
pub fn stream(with_portal: bool) -> SceneDesc {
    let mut d = SceneDesc::new(
        if with_portal {
            "portal_stream"
        } else {
            "hole_stream"
        },
        1800,
    );
    let turned = |hx, hy, c, a| {
        ShapeDesc::new(Geometry::Box {
            half: v(hx, hy),
            center: c,
            angle: a,
            radius: 0.0,
        })
    };
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    // Funnel: 45° slopes whose upper faces run from (±10, 9) down to the
    // aperture's edges (±1, 0), side walls.
    let slope = PI / 4.0;
    let n = 0.25 * 0.5f64.sqrt();
    ground
        .shapes
        .push(turned(6.5, 0.25, v(5.5 + n, 4.5 - n), slope));
    ground
        .shapes
        .push(turned(6.5, 0.25, v(-5.5 - n, 4.5 - n), -slope));
    ground.shapes.push(turned(0.25, 12.0, v(-10.25, 12.0), 0.0));
    ground.shapes.push(turned(0.25, 12.0, v(10.25, 12.0), 0.0));
    // Room below: floor, side wall.
    ground.shapes.push(turned(40.0, 0.5, v(0.0, -30.5), 0.0));
    ground.shapes.push(turned(0.5, 10.0, v(40.5, -20.0), 0.0));
    if with_portal {
        d.add(ground);
        let floor = d.add(BodyDesc::fixed(v(0.0, -0.5)).with(ShapeDesc::new(square(1.5, 0.5))));
        let wall = d.add(BodyDesc::fixed(v(-40.5, -25.0)).with(ShapeDesc::new(square(0.5, 5.0))));
        d.portals.push(PortalDesc {
            entry: (floor, v(0.0, 0.5), v(0.0, 1.0), 1.0),
            exit: (wall, v(0.5, 0.0), v(1.0, 0.0), 1.0),
        });
    } else {
        ground.shapes.push(turned(0.25, 0.5, v(-1.25, -0.5), 0.0));
        ground.shapes.push(turned(0.25, 0.5, v(1.25, -0.5), 0.0));
        ground.shapes.push(turned(0.5, 5.0, v(-40.5, -25.0), 0.0));
        d.add(ground);
    }
    for i in 0..200 {
        let (row, col) = (i / 20, i % 20);
        let pos = v(-8.55 + 0.9 * col as f64, 10.0 + 0.6 * row as f64);
        let g = match i % 3 {
            0 => square(0.15, 0.15),
            1 => Geometry::Circle {
                center: DVec2::ZERO,
                radius: 0.15,
            },
            _ => Geometry::Capsule {
                a: v(-0.1, 0.0),
                b: v(0.1, 0.0),
                radius: 0.12,
            },
        };
        d.probe = Some(d.add(BodyDesc::dynamic(pos).with(ShapeDesc::new(g))));
    }
    d.probe_label = "last shape";
    d
}

/// The portal "drop": a 1 m box falls 5 m onto a floor portal (2 m
/// aperture, facing up); the partner sits on a wall to the left, facing +x.
/// Probe: the box.
#[must_use]
pub fn portal_drop() -> SceneDesc {
    let mut d = SceneDesc::new("portal_drop", 120);
    let floor = d.add(BodyDesc::fixed(v(0.0, -0.5)).with(ShapeDesc::new(square(10.0, 0.5))));
    let wall = d.add(BodyDesc::fixed(v(-20.0, 5.0)).with(ShapeDesc::new(square(0.5, 5.0))));
    d.portals.push(PortalDesc {
        entry: (floor, v(0.0, 0.5), v(0.0, 1.0), 1.0),
        exit: (wall, v(0.5, 0.0), v(1.0, 0.0), 1.0),
    });
    d.probe = Some(d.add(BodyDesc::dynamic(v(0.0, 5.5)).with(unit_box())));
    d.probe_label = "box";
    d
}
