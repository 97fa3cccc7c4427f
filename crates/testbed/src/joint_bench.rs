//! The joint scenes of the peers benchmark (`janus2d-peers joints`): one
//! scene per joint kind a game reaches for, each with accuracy figures
//! computed from the poses any engine reports, so that janus2d, Box2D and
//! Rapier are measured by one yardstick at equal substeps.
//!
//! | scene             | joints                         | run  | figures |
//! |-------------------|--------------------------------|------|---------|
//! | `weld_cantilever` | 10 rigid welds (ground + 10 boxes) | 2 s | tip sag at the end, peak tip sag |
//! | `car`             | 2 wheel joints (springs, rear motor) | 6 s | worst wheel distance from its axis, time to 10 m/s |
//! | `elevator`        | 1 prismatic (motor 1 m/s, upper limit) | 5 s | worst off-axis error, worst angle error, limit overshoot |
//! | `spring_bridge`   | 21 distance joints (springs, max length) | 4 s | worst length error past the limits, mid-span sag |
//!
//! Every scene uses the shared [`Settings`] (1/60 s, 4 substeps, joints
//! 60 Hz / ζ 2, sleep off); the figures are read after every step, outside
//! any timing.
//!
//! # The scenes
//!
//! - **`weld_cantilever`**: a static ground and ten boxes of 1 m × 0.25 m,
//!   density 4 kg/m² (1 kg each), laid end to end along +x from the
//!   origin, each welded rigidly (both hertz 0) to the one before at their
//!   shared end, the first to the ground at (0, 0). An exact solver holds
//!   the beam straight; the tip sag (m, positive down: the drop of the far
//!   end's midpoint of the last box below y = 0) measures how much the
//!   welds give.
//! - **`car`**: a chassis of 2.5 m × 0.5 m (25 kg) on two wheels of radius
//!   0.4 m (≈ 5 kg, friction 0.9), each on a wheel joint with a vertical
//!   suspension axis at (±1, −0.6) in the chassis frame, springs 4 Hz /
//!   ζ 0.7, limits ±0.3 m; the rear wheel's motor drives −40 rad/s (about
//!   16 m/s) with at most 60 N·m. The ground is a line of segments with a
//!   10 cm high, 2 m wide bump every 8 m from x = 10 m (the car takes them
//!   at 8 to 14 m/s and leaves the ground). Figures: the largest
//!   distance of either wheel centre from its axis line (m), and the first
//!   time the chassis goes 10 m/s forward (s; "never" if it does not).
//! - **`elevator`**: a 10 kg platform (2 m × 0.2 m) on a vertical prismatic
//!   joint to the ground at (0, 1), limits [0, 3] m, motor 1 m/s up with at
//!   most 5,000 N, carrying a 100 kg box (1 m square) set 0.3 m off centre.
//!   Figures: the largest distance of the platform's anchor from the axis
//!   line (m), the largest turn of the platform (rad), and the largest
//!   translation past the upper limit (m).
//! - **`spring_bridge`**: 20 planks of 1 m × 0.2 m (4 kg) between two static
//!   posts, 0.25 m apart, each gap spanned by one distance joint between the
//!   facing plank ends (rest length 0.25 m, spring 4 Hz / ζ 0.5, length
//!   limits [0.1, 0.35] m); three 10 kg boxes fall on it at a quarter, half
//!   and three quarters of the span. Figures: the largest length of any
//!   joint outside its limits (m) and the sag of the middle plank at the
//!   end (m).

use std::f64::consts::FRAC_PI_2;

use glam::DVec2;

use crate::desc::*;
use crate::engine::{BodyReading, Engine, EngineOptions, scripted_step};

/// Names of the joint scenes, in the order `joints` runs them.
pub const NAMES: [&str; 4] = ["weld_cantilever", "car", "elevator", "spring_bridge"];

/// What a scene measures (private: the layout of each scene's bodies).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Probe {
    /// Tip of body `tip` at its local point `local`.
    Cantilever { tip: usize, local: DVec2 },
    /// Chassis body, and the scene's wheel joints (indices into
    /// `extra_joints`).
    Car { chassis: usize, wheels: [usize; 2] },
    /// The prismatic joint (index into `extra_joints`).
    Elevator { joint: usize },
    /// Every distance joint, and the middle plank.
    Bridge { middle: usize },
}

/// One joint scene: its description and the figures it reports.
#[derive(Clone, Debug)]
pub struct JointScene {
    /// Name.
    pub name: &'static str,
    /// The scene (its `steps` is the run length).
    pub desc: SceneDesc,
    /// The figures' names with units, in the order [`JointScene::measure`]
    /// returns them.
    pub figures: &'static [&'static str],
    probe: Probe,
}

/// A scene's figures on one engine.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointFigures {
    /// One value per name of [`JointScene::figures`]; `NaN` for an event
    /// that never happened (the car never reaching 10 m/s).
    pub values: Vec<f64>,
    /// Mean wall time of the measured run's steps 1..N−1, ms (the figures
    /// are read outside the clock; the peers table times separately).
    pub step_ms: f64,
}

/// Every joint scene.
#[must_use]
pub fn all() -> Vec<JointScene> {
    NAMES.iter().filter_map(|n| by_name(n)).collect()
}

/// A joint scene by name.
#[must_use]
pub fn by_name(name: &str) -> Option<JointScene> {
    Some(match name {
        "weld_cantilever" => weld_cantilever(),
        "car" => car(),
        "elevator" => elevator(),
        "spring_bridge" => spring_bridge(),
        _ => return None,
    })
}

/// A point given in a body's frame, in the world.
fn world_point(s: &BodyReading, local: DVec2) -> DVec2 {
    s.position + DVec2::from_angle(s.angle).rotate(local)
}

/// The world origins of a joint's two frames and a's frame axis in the
/// world.
fn frames_in_world(b: &JointBaseDesc, a: &BodyReading, bb: &BodyReading) -> (DVec2, DVec2, DVec2) {
    (
        world_point(a, b.frame_a.anchor),
        world_point(bb, b.frame_b.anchor),
        DVec2::from_angle(a.angle + b.frame_a.angle),
    )
}

/// Distance of b's frame origin from a's frame axis line, and translation
/// along that axis.
fn axis_offsets(b: &JointBaseDesc, a: &BodyReading, bb: &BodyReading) -> (f64, f64) {
    let (pa, pb, axis) = frames_in_world(b, a, bb);
    let d = pb - pa;
    (axis.perp_dot(d).abs(), axis.dot(d))
}

impl JointScene {
    /// Runs the scene on engine `E` (one thread) and measures it.
    pub fn measure<E: Engine>(&self) -> Result<JointFigures, String> {
        let d = &self.desc;
        let mut engine = E::build(d, EngineOptions::default())?;
        let n = d.bodies.len();
        let read = |e: &E| -> Vec<BodyReading> {
            (0..n).map(|i| e.state(i).unwrap_or_default()).collect()
        };
        let start = read(&engine);
        let dt = d.settings.dt;
        let mut values = vec![0.0f64; self.figures.len()];
        if let Probe::Car { .. } = self.probe {
            values[1] = f64::NAN;
        }
        let mut buf = Vec::new();
        let mut step_time = 0.0;
        for k in 0..d.steps {
            let t0 = std::time::Instant::now();
            scripted_step(&mut engine, d, k, &mut buf);
            if k > 0 {
                step_time += t0.elapsed().as_secs_f64();
            }
            let s = read(&engine);
            let t = (k + 1) as f64 * dt;

            match self.probe {
                Probe::Cantilever { tip, local } => {
                    let sag = world_point(&start[tip], local).y - world_point(&s[tip], local).y;
                    values[0] = sag;
                    values[1] = values[1].max(sag);
                }
                Probe::Car { chassis, wheels } => {
                    for w in wheels {
                        if let JointDesc::Wheel(j) = &d.extra_joints[w] {
                            let (off, _) =
                                axis_offsets(&j.base, &s[j.base.body_a], &s[j.base.body_b]);
                            values[0] = values[0].max(off);
                        }
                    }
                    if values[1].is_nan() && s[chassis].linear_velocity.x >= 10.0 {
                        values[1] = t;
                    }
                }
                Probe::Elevator { joint } => {
                    if let JointDesc::Prismatic(j) = &d.extra_joints[joint] {
                        let (a, b) = (&s[j.base.body_a], &s[j.base.body_b]);
                        let (off, along) = axis_offsets(&j.base, a, b);
                        values[0] = values[0].max(off);
                        let turn =
                            (b.angle + j.base.frame_b.angle) - (a.angle + j.base.frame_a.angle);
                        values[1] = values[1].max(turn.sin().atan2(turn.cos()).abs());
                        if let Some((_, upper)) = j.limit {
                            values[2] = values[2].max(along - upper);
                        }
                    }
                }
                Probe::Bridge { middle } => {
                    for j in &d.extra_joints {
                        if let JointDesc::Distance(j) = j {
                            let (pa, pb, _) =
                                frames_in_world(&j.base, &s[j.base.body_a], &s[j.base.body_b]);
                            let len = (pb - pa).length();
                            let (lo, hi) = j.limit.unwrap_or((j.length, j.length));
                            values[0] = values[0].max(len - hi).max(lo - len);
                        }
                    }
                    values[1] = start[middle].position.y - s[middle].position.y;
                }
            }
        }
        Ok(JointFigures {
            values,
            step_ms: step_time * 1e3 / d.steps.saturating_sub(1).max(1) as f64,
        })
    }
}

/// A box of half extents (`hx`, `hy`) with the given density.
fn block(hx: f64, hy: f64, density: f64) -> ShapeDesc {
    ShapeDesc::new(square(hx, hy)).density(density)
}

/// Ten boxes of 1 m × 0.25 m (1 kg) welded rigidly end to end from a
/// static ground at the origin, horizontal under gravity; 2 s.
#[must_use]
pub fn weld_cantilever() -> JointScene {
    let (links, hx, hy) = (10usize, 0.5, 0.125);
    let mut d = SceneDesc::new("weld_cantilever", 120);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO).with(ShapeDesc::new(offset_box(
        0.5,
        0.5,
        v(-0.5, 0.0),
    ))));
    let mut prev = ground;
    for i in 0..links {
        let b = d.add(BodyDesc::dynamic(v(hx + 2.0 * hx * i as f64, 0.0)).with(block(hx, hy, 4.0)));
        let anchor_prev = if prev == ground {
            DVec2::ZERO
        } else {
            v(hx, 0.0)
        };
        d.join_any(WeldDesc::new(prev, b, anchor_prev, v(-hx, 0.0)));
        prev = b;
    }
    d.probe = Some(prev);
    d.probe_label = "tip box";
    JointScene {
        name: "weld_cantilever",
        desc: d,
        figures: &["tip sag m", "peak tip sag m"],
        probe: Probe::Cantilever {
            tip: prev,
            local: v(hx, 0.0),
        },
    }
}

/// A chassis on two sprung wheel joints, the rear one driven, over a
/// ground with bumps; 6 s.
#[must_use]
pub fn car() -> JointScene {
    let mut d = SceneDesc::new("car", 360);
    // The ground: flat at y = 0 from x = −20 m to 200 m, a bump (10 cm
    // high, 2 m wide) every 8 m from x = 10 m.
    let mut points = vec![v(-20.0, 0.0)];
    let mut x = 10.0;
    while x + 2.0 < 200.0 {
        points.extend([v(x, 0.0), v(x + 1.0, 0.1), v(x + 2.0, 0.0)]);
        x += 8.0;
    }
    points.push(v(200.0, 0.0));
    let mut ground = BodyDesc::fixed(DVec2::ZERO);
    for w in points.windows(2) {
        ground = ground.with(ShapeDesc::new(Geometry::Segment { a: w[0], b: w[1] }).friction(0.9));
    }
    d.add(ground);
    let chassis = d.add(BodyDesc::dynamic(v(0.0, 1.0)).with(block(1.25, 0.25, 20.0)));
    let wheel = |x: f64| {
        BodyDesc::dynamic(v(x, 0.4)).with(
            ShapeDesc::new(Geometry::Circle {
                center: DVec2::ZERO,
                radius: 0.4,
            })
            .density(10.0)
            .friction(0.9),
        )
    };
    let rear = d.add(wheel(-1.0));
    let front = d.add(wheel(1.0));
    for (w, x) in [(rear, -1.0), (front, 1.0)] {
        let mut j = WheelDesc::new(
            JointBaseDesc::new(chassis, w, v(x, -0.6), DVec2::ZERO).with_axis_angle(FRAC_PI_2),
        );
        j.spring = Some((4.0, 0.7));
        j.limit = Some((-0.3, 0.3));
        if w == rear {
            j.motor = Some((-40.0, 60.0));
        }
        d.join_any(j);
    }
    d.probe = Some(chassis);
    d.probe_label = "chassis";
    JointScene {
        name: "car",
        desc: d,
        figures: &["worst wheel off-axis m", "time to 10 m/s s"],
        probe: Probe::Car {
            chassis,
            wheels: [0, 1],
        },
    }
}

/// A 10 kg platform on a vertical prismatic joint driven up at 1 m/s to
/// its upper limit, carrying a 100 kg load; 5 s.
#[must_use]
pub fn elevator() -> JointScene {
    let mut d = SceneDesc::new("elevator", 300);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO).with(block(5.0, 0.5, 1.0)));
    // 2 m × 0.2 m at 25 kg/m²: 10 kg.
    let platform = d.add(BodyDesc::dynamic(v(0.0, 1.0)).with(block(1.0, 0.1, 25.0)));
    // 1 m square at 100 kg/m², resting on the platform 0.3 m off centre.
    let load = d.add(BodyDesc::dynamic(v(0.3, 1.6)).with(block(0.5, 0.5, 100.0)));
    let mut j = PrismaticDesc::new(
        JointBaseDesc::new(ground, platform, v(0.0, 1.0), DVec2::ZERO).with_axis_angle(FRAC_PI_2),
    );
    j.limit = Some((0.0, 3.0));
    j.motor = Some((1.0, 5000.0));
    d.join_any(j);
    d.probe = Some(load);
    d.probe_label = "load";
    JointScene {
        name: "elevator",
        desc: d,
        figures: &["worst off-axis m", "worst angle rad", "limit overshoot m"],
        probe: Probe::Elevator { joint: 0 },
    }
}

/// Planks joined by sprung distance joints with length limits between two
/// static posts, loaded by three falling boxes; 4 s.
#[must_use]
pub fn spring_bridge() -> JointScene {
    let (planks, hx, hy, gap) = (20usize, 0.5, 0.1, 0.25);
    let mut d = SceneDesc::new("spring_bridge", 240);
    let span = planks as f64 * 2.0 * hx + (planks + 1) as f64 * gap;
    let x0 = -0.5 * span;
    let left = d.add(BodyDesc::fixed(v(x0, 0.0)).with(ShapeDesc::new(offset_box(
        0.25,
        1.0,
        v(-0.25, -1.0 + hy),
    ))));
    let mut ends = Vec::with_capacity(planks);
    let mut middle = left;
    for i in 0..planks {
        let x = x0 + gap + hx + i as f64 * (2.0 * hx + gap);
        let b = d.add(BodyDesc::dynamic(v(x, 0.0)).with(block(hx, hy, 20.0)));
        if i == planks / 2 {
            middle = b;
        }
        ends.push(b);
    }
    let right = d.add(BodyDesc::fixed(v(-x0, 0.0)).with(ShapeDesc::new(offset_box(
        0.25,
        1.0,
        v(0.25, -1.0 + hy),
    ))));
    let link = |a: usize, b: usize, anchor_a: DVec2, anchor_b: DVec2| {
        let mut j = DistanceDesc::new(JointBaseDesc::new(a, b, anchor_a, anchor_b), gap);
        j.spring = Some((4.0, 0.5));
        j.limit = Some((0.1, 0.35));
        j
    };
    d.join_any(link(left, ends[0], DVec2::ZERO, v(-hx, 0.0)));
    for w in ends.windows(2) {
        d.join_any(link(w[0], w[1], v(hx, 0.0), v(-hx, 0.0)));
    }
    d.join_any(link(ends[planks - 1], right, v(hx, 0.0), DVec2::ZERO));
    for f in [0.25, 0.5, 0.75] {
        d.add(BodyDesc::dynamic(v(x0 + f * span, 1.0)).with(block(0.5, 0.5, 10.0)));
    }
    d.probe = Some(middle);
    d.probe_label = "middle plank";
    JointScene {
        name: "spring_bridge",
        desc: d,
        figures: &["worst length error m", "mid-span sag m"],
        probe: Probe::Bridge { middle },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::janus::Janus;

    #[test]
    fn scenes_are_listed_and_well_formed() {
        let scenes = all();
        assert_eq!(scenes.len(), NAMES.len());
        for s in &scenes {
            assert_eq!(s.desc.name, s.name);
            for j in &s.desc.extra_joints {
                let (a, b) = j.bodies();
                assert!(a < s.desc.bodies.len() && b < s.desc.bodies.len());
            }
        }
    }

    #[test]
    fn janus_builds_and_runs_every_joint_scene() {
        for s in all() {
            let f = s.measure::<Janus>().expect("every kind builds");
            let finite = f
                .values
                .iter()
                .filter(|v| !v.is_nan())
                .all(|v| v.is_finite());
            assert!(finite, "{}: {f:?}", s.name);
        }
    }
}
