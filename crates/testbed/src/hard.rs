//! The hard cases (stability tests: sleep off, 4 substeps, 1/60 s), each a
//! [`SceneDesc`] with its pass bounds, measured on any [`Engine`] with the
//! shared metric code of [`crate::measure`].
//!
//! | case              | pass (Box2D v3.1's figure in the bound's note)      |
//! |-------------------|-----------------------------------------------------|
//! | `single_box`      | at 90 steps \|x\|, \|y − 1\|, \|angle\| < 0.01          |
//! | `pyramid20`       | penetration ≤ 5 mm, sink ≤ 0.05 m, drift ≤ 1 cm      |
//! | `large_pyramid`   | penetration ≤ 3 cm, sink ≤ 1 m, drift ≤ 5 cm, late top speed ≤ 0.01 m/s |
//! | `vertical_stack_N`| stands (top < 0.5 m sideways) 60 s for 12; Box2D's time for 15 and 20 |
//! | `double_domino`   | all 15 topple                                       |
//! | `confined`        | none escapes, late peak speed < 0.01 m/s            |
//! | `high_mass_ratio_1` | no box > 0.5 m sideways, late penetration ≤ 6 cm  |
//! | `high_mass_ratio_2/3` | no body below ground, late penetration ≤ 0.1 m  |
//! | `bridge`          | late joint gap ≤ 2 cm                               |
//! | `ball_and_chain`  | peak joint gap ≤ 0.1 m                              |
//! | `stretched_chain` | late joint gap ≤ 1 cm, peak speed ≤ the unstretched chain's whip |
//! | `joint_grid_40`   | peak joint gap ≤ 0.2 m                              |
//!
//! "Late" is the last second of the run.

use glam::DVec2;

use crate::benchmarks::{joint_grid, pyramid};
use crate::desc::*;
use crate::engine::{BodyReading, Engine, EngineOptions, scripted_step};
use crate::measure::{ShapeIndex, max_joint_gap, outside_container, peak_speed};

/// A figure a hard case bounds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    /// Peak penetration over the run, m.
    Penetration,
    /// Peak penetration over the last second, m.
    LatePenetration,
    /// Largest sink of the probe below its start, m.
    Sink,
    /// Largest sideways drift of the probe, m.
    Drift,
    /// Probe's peak speed over the last second, m/s.
    LateProbeSpeed,
    /// Peak joint gap over the run, m.
    JointGap,
    /// Peak joint gap over the last second, m.
    LateJointGap,
    /// Peak speed of any dynamic body over the run, m/s.
    PeakSpeed,
    /// Peak speed of any dynamic body over the last second, m/s.
    LatePeakSpeed,
    /// Dynamic bodies outside the container at the end.
    Outside,
    /// Dynamic bodies whose origin ever went below y = 0.
    BelowGround,
    /// Bodies that turned more than 0.5 rad (toppled dominoes).
    Toppled,
    /// Largest sideways move of any dynamic body from its start, m.
    MaxSideways,
    /// Time the probe stayed within 0.5 m sideways of its start, s.
    StandTime,
    /// Largest of |x − x_rest|, |y − y_rest|, |angle| of the probe at the end.
    RestError,
    /// Steps after which some state was not finite.
    NonFinite,
}

impl Figure {
    /// Column name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Figure::Penetration => "penetration m",
            Figure::LatePenetration => "late penetration m",
            Figure::Sink => "sink m",
            Figure::Drift => "drift m",
            Figure::LateProbeSpeed => "late probe speed m/s",
            Figure::JointGap => "joint gap m",
            Figure::LateJointGap => "late joint gap m",
            Figure::PeakSpeed => "peak speed m/s",
            Figure::LatePeakSpeed => "late peak speed m/s",
            Figure::Outside => "outside",
            Figure::BelowGround => "below ground",
            Figure::Toppled => "toppled",
            Figure::MaxSideways => "max sideways m",
            Figure::StandTime => "stands s",
            Figure::RestError => "rest error",
            Figure::NonFinite => "non-finite steps",
        }
    }
}

/// `figure ≤ value` or `figure ≥ value`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bound {
    /// At most.
    AtMost(Figure, f64),
    /// At least.
    AtLeast(Figure, f64),
}

impl Bound {
    /// The bounded figure.
    #[must_use]
    pub fn figure(&self) -> Figure {
        match *self {
            Bound::AtMost(f, _) | Bound::AtLeast(f, _) => f,
        }
    }

    /// Whether `value` meets the bound.
    #[must_use]
    pub fn holds(&self, value: f64) -> bool {
        match *self {
            Bound::AtMost(_, b) => value <= b,
            Bound::AtLeast(_, b) => value >= b,
        }
    }
}

/// A hard case: a scene, how long it runs, and its bounds.
#[derive(Clone, Debug)]
pub struct HardCase {
    /// Name.
    pub name: &'static str,
    /// The scene.
    pub desc: SceneDesc,
    /// Steps to run.
    pub steps: usize,
    /// Pass bounds.
    pub bounds: Vec<Bound>,
    /// Rest pose of the probe (for [`Figure::RestError`]).
    pub rest: Option<(DVec2, f64)>,
    /// Box2D v3.1's figures at 4 substeps, as the spec quotes them.
    pub box2d: &'static str,
}

/// The figures of one run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Figures {
    values: Vec<(Figure, f64)>,
}

impl Figures {
    /// The value of `figure` (0 if it was not measured).
    #[must_use]
    pub fn get(&self, figure: Figure) -> f64 {
        self.values
            .iter()
            .find(|(f, _)| *f == figure)
            .map_or(0.0, |(_, v)| *v)
    }

    /// Every figure measured.
    #[must_use]
    pub fn all(&self) -> &[(Figure, f64)] {
        &self.values
    }
}

/// Result of a case on one engine.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The figures.
    pub figures: Figures,
    /// Whether every bound holds.
    pub pass: bool,
    /// The bounds that failed, as text.
    pub failed: Vec<String>,
    /// Mean wall time of steps 1..N−1 (the metrics are computed outside
    /// the clock), ms.
    pub step_ms: f64,
}

impl HardCase {
    /// Runs the case on engine `E` and measures it.
    pub fn run<E: Engine>(&self) -> Result<Outcome, String> {
        let mut engine = E::build(&self.desc, EngineOptions::default())?;
        Ok(self.measure(&mut engine))
    }

    /// Measures the case on an engine already built from `self.desc`.
    pub fn measure<E: Engine>(&self, engine: &mut E) -> Outcome {
        let d = &self.desc;
        let index = ShapeIndex::new(d);
        let late_from = self.steps.saturating_sub(60);
        let start: Vec<Option<BodyReading>> =
            (0..d.bodies.len()).map(|i| engine.state(i)).collect();
        let probe0 = d.probe.and_then(|p| start[p]);
        let (mut pen, mut late_pen, mut sink, mut drift, mut late_probe_speed) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let (mut gap, mut late_gap, mut speed, mut late_speed) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut below = vec![false; d.bodies.len()];
        let mut stand_time: Option<f64> = None;
        let mut non_finite = 0usize;
        let mut buf = Vec::new();
        let mut dynamic = Vec::new();
        let mut states = start.clone();
        let dt = d.settings.dt;
        let mut step_time = 0.0;
        for k in 0..self.steps {
            let t0 = std::time::Instant::now();
            scripted_step(engine, d, k, &mut buf);
            if k > 0 {
                step_time += t0.elapsed().as_secs_f64() * 1e3;
            }
            for (i, s) in states.iter_mut().enumerate() {
                *s = engine.state(i);
            }
            engine.dynamic_states(&mut dynamic);
            let late = k >= late_from;
            let finite = dynamic
                .iter()
                .all(|s| s.position.is_finite() && s.linear_velocity.is_finite());
            if !finite {
                non_finite += 1;
                continue;
            }
            let p = index.deepest_overlap(&states);
            pen = pen.max(p);
            let g = max_joint_gap(d, &states);
            gap = gap.max(g);
            let sp = peak_speed(&dynamic);
            speed = speed.max(sp);
            if late {
                late_pen = late_pen.max(p);
                late_gap = late_gap.max(g);
                late_speed = late_speed.max(sp);
            }
            for (i, s) in states.iter().enumerate() {
                if let Some(s) = s
                    && d.bodies[i].kind == BodyKind::Dynamic
                    && s.position.y < 0.0
                {
                    below[i] = true;
                }
            }
            if let (Some(p0), Some(p)) = (probe0, d.probe.and_then(|p| states[p])) {
                sink = sink.max(p0.position.y - p.position.y);
                drift = drift.max((p.position.x - p0.position.x).abs());
                if late {
                    late_probe_speed = late_probe_speed.max(p.linear_velocity.length());
                }
                if stand_time.is_none() && (p.position.x - p0.position.x).abs() > 0.5 {
                    stand_time = Some((k + 1) as f64 * dt);
                }
            }
        }
        let mut toppled = 0usize;
        let mut sideways: f64 = 0.0;
        for (i, s) in states.iter().enumerate() {
            if d.bodies[i].kind != BodyKind::Dynamic {
                continue;
            }
            if let (Some(s), Some(s0)) = (s, start[i]) {
                if (s.angle - s0.angle).abs() > 0.5 {
                    toppled += 1;
                }
                sideways = sideways.max((s.position.x - s0.position.x).abs());
            }
        }
        let rest_error = match (self.rest, d.probe.and_then(|p| states[p])) {
            (Some((pos, angle)), Some(s)) => (s.position.x - pos.x)
                .abs()
                .max((s.position.y - pos.y).abs())
                .max((s.angle - angle).abs()),
            _ => 0.0,
        };
        let container_state = d
            .container
            .as_ref()
            .and_then(|c| c.body)
            .and_then(|b| states[b]);
        let values = vec![
            (Figure::Penetration, pen),
            (Figure::LatePenetration, late_pen),
            (Figure::Sink, sink),
            (Figure::Drift, drift),
            (Figure::LateProbeSpeed, late_probe_speed),
            (Figure::JointGap, gap),
            (Figure::LateJointGap, late_gap),
            (Figure::PeakSpeed, speed),
            (Figure::LatePeakSpeed, late_speed),
            (
                Figure::Outside,
                outside_container(d, container_state, &dynamic) as f64,
            ),
            (
                Figure::BelowGround,
                below.iter().filter(|b| **b).count() as f64,
            ),
            (Figure::Toppled, toppled as f64),
            (Figure::MaxSideways, sideways),
            (
                Figure::StandTime,
                stand_time.unwrap_or(self.steps as f64 * dt),
            ),
            (Figure::RestError, rest_error),
            (Figure::NonFinite, non_finite as f64),
        ];
        let figures = Figures { values };
        let mut failed = Vec::new();
        if non_finite > 0 {
            failed.push(format!("{non_finite} non-finite steps"));
        }
        for b in &self.bounds {
            let value = figures.get(b.figure());
            if !b.holds(value) {
                failed.push(format!("{} = {value:.4} ({b:?})", b.figure().name()));
            }
        }
        Outcome {
            pass: failed.is_empty(),
            figures,
            failed,
            step_ms: step_time / self.steps.saturating_sub(1).max(1) as f64,
        }
    }
}

/// The ground of several cases: a static box half (hx, 1) at (0, −1).
fn ground_box(hx: f64, friction: f64) -> BodyDesc {
    BodyDesc::fixed(v(0.0, -1.0)).with(ShapeDesc::new(square(hx, 1.0)).friction(friction))
}

/// 2×2 box dropped from y = 4 onto a ground box, μ 0.5.
#[must_use]
pub fn single_box() -> HardCase {
    let mut d = SceneDesc::new("single_box", 90);
    d.add(ground_box(50.0, 0.5));
    d.probe = Some(
        d.add(BodyDesc::dynamic(v(0.0, 4.0)).with(ShapeDesc::new(square(1.0, 1.0)).friction(0.5))),
    );
    HardCase {
        name: "single_box",
        desc: d,
        steps: 90,
        bounds: vec![Bound::AtMost(Figure::RestError, 0.01)],
        rest: Some((v(0.0, 1.0), 0.0)),
        box2d: "",
    }
}

/// `large_pyramid` with base 20, 10 s.
#[must_use]
pub fn pyramid20() -> HardCase {
    let mut d = pyramid(20);
    d.name = "pyramid20";
    HardCase {
        name: "pyramid20",
        desc: d,
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::Penetration, 0.005),
            Bound::AtMost(Figure::Sink, 0.05),
            Bound::AtMost(Figure::Drift, 0.01),
        ],
        rest: None,
        box2d: "3.5 mm, 0.030 m, 0.8 mm",
    }
}

/// `large_pyramid`, 10 s.
#[must_use]
pub fn large_pyramid() -> HardCase {
    HardCase {
        name: "large_pyramid",
        desc: pyramid(100),
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::Penetration, 0.03),
            Bound::AtMost(Figure::Sink, 1.0),
            Bound::AtMost(Figure::Drift, 0.05),
            Bound::AtMost(Figure::LateProbeSpeed, 0.01),
        ],
        rest: None,
        box2d: "2.1 cm, 0.73 m, 4 mm, 0.0004 m/s",
    }
}

/// The vertical stack scene: `rows` 1 m boxes (μ 0.3) with 0.1 m gaps,
/// x −0.01 for even rows and +0.01 for odd ones, on a ground box half
/// (100, 1), μ 0.6. Probe: the top box.
#[must_use]
pub fn vertical_stack_scene(rows: usize) -> SceneDesc {
    let mut d = SceneDesc::new("vertical_stack", 3600);
    d.add(ground_box(100.0, 0.6));
    for i in 0..rows {
        let x = if i % 2 == 0 { -0.01 } else { 0.01 };
        d.probe = Some(
            d.add(
                BodyDesc::dynamic(v(x, 0.55 + 1.1 * i as f64))
                    .with(ShapeDesc::new(square(0.5, 0.5)).friction(0.3)),
            ),
        );
    }
    d.probe_label = "top box";
    d
}

/// The vertical stack of `rows`, 60 s: every stack must stand the 60 s
/// (Box2D v3.1 fell at 9.5 s with 15 rows and 6.48 s with 20; Box2D v3.2
/// and Rapier stand).
#[must_use]
pub fn vertical_stack(rows: usize) -> HardCase {
    let (name, stand, box2d) = match rows {
        12 => ("vertical_stack_12", 60.0, "stands 60 s"),
        15 => ("vertical_stack_15", 60.0, "v3.1 falls at 9.5 s"),
        _ => ("vertical_stack_20", 60.0, "v3.1 falls at 6.5 s"),
    };
    HardCase {
        name,
        desc: vertical_stack_scene(rows),
        steps: 3600,
        bounds: vec![Bound::AtLeast(Figure::StandTime, stand)],
        rest: None,
        box2d,
    }
}

/// 15 dominoes half 0.125×0.5, spacing 1, μ 0.6; the first pushed at its
/// top by an impulse (0.2, 0) — given as the velocity that impulse makes
/// (the body is at rest), so every engine gets exactly the same push.
#[must_use]
pub fn double_domino() -> HardCase {
    let mut d = SceneDesc::new("double_domino", 600);
    d.add(ground_box(50.0, 0.6));
    let (hx, hy) = (0.125, 0.5);
    let mass = 4.0 * hx * hy;
    let inertia = mass * (4.0 * hx * hx + 4.0 * hy * hy) / 12.0;
    let impulse = v(0.2, 0.0);
    let r = v(0.0, 1.0) - v(0.0, 0.5);
    for i in 0..15 {
        let mut b =
            BodyDesc::dynamic(v(i as f64, 0.5)).with(ShapeDesc::new(square(hx, hy)).friction(0.6));
        if i == 0 {
            b.linear_velocity = impulse / mass;
            b.angular_velocity = r.perp_dot(impulse) / inertia;
        }
        d.add(b);
    }
    HardCase {
        name: "double_domino",
        desc: d,
        steps: 600,
        bounds: vec![Bound::AtLeast(Figure::Toppled, 15.0)],
        rest: None,
        box2d: "all topple",
    }
}

/// 625 circles r 0.5 on a 25×25 grid of pitch 0.72 (overlapping) inside
/// capsule walls enclosing ±10.5 × 0..20.5, gravity 0.
#[must_use]
pub fn confined() -> HardCase {
    let mut d = SceneDesc::new("confined", 600);
    d.settings.gravity = DVec2::ZERO;
    let (x0, x1, y0, y1) = (-10.5, 10.5, 0.0, 20.5);
    let mut walls = BodyDesc::fixed(DVec2::ZERO);
    for (a, b) in [
        (v(x0, y0), v(x1, y0)),
        (v(x1, y0), v(x1, y1)),
        (v(x1, y1), v(x0, y1)),
        (v(x0, y1), v(x0, y0)),
    ] {
        walls
            .shapes
            .push(ShapeDesc::new(Geometry::Capsule { a, b, radius: 0.5 }));
    }
    d.add(walls);
    for i in 0..25 {
        for j in 0..25 {
            let pos = v(-8.64 + 0.72 * i as f64, 1.5 + 0.72 * j as f64);
            d.add(
                BodyDesc::dynamic(pos).with(ShapeDesc::new(Geometry::Circle {
                    center: DVec2::ZERO,
                    radius: 0.5,
                })),
            );
        }
    }
    d.container = Some(Container {
        body: None,
        region: Region::Rect {
            center: v(0.0, 0.5 * (y0 + y1)),
            half: v(0.5 * (x1 - x0), 0.5 * (y1 - y0)),
        },
    });
    HardCase {
        name: "confined",
        desc: d,
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::Outside, 0.0),
            Bound::AtMost(Figure::LatePeakSpeed, 0.01),
        ],
        rest: None,
        box2d: "",
    }
}

/// Three pyramids of base 10 with 2 m boxes (μ 0.5) on a two-sided segment
/// (−66, 0)–(66, 0), centred at x = −20 + 22 j; each single top box has
/// density 100 (j + 1) and starts 2 m higher.
#[must_use]
pub fn high_mass_ratio_1() -> HardCase {
    let mut d = SceneDesc::new("high_mass_ratio_1", 600);
    d.add(
        BodyDesc::fixed(DVec2::ZERO).with(
            ShapeDesc::new(Geometry::Segment {
                a: v(-66.0, 0.0),
                b: v(66.0, 0.0),
            })
            .friction(0.5),
        ),
    );
    for j in 0..3 {
        let offset = -20.0 + 22.0 * j as f64;
        for r in 0..10 {
            let count = 10 - r;
            let top = count == 1;
            let y = 1.0 + 2.0 * r as f64 + if top { 2.0 } else { 0.0 };
            let density = if top { 100.0 * (j + 1) as f64 } else { 1.0 };
            for i in 0..count {
                let x = 2.0 * (i as f64 - count as f64 / 2.0) + offset;
                d.add(
                    BodyDesc::dynamic(v(x, y)).with(
                        ShapeDesc::new(square(1.0, 1.0))
                            .friction(0.5)
                            .density(density),
                    ),
                );
            }
        }
    }
    HardCase {
        name: "high_mass_ratio_1",
        desc: d,
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::MaxSideways, 0.5),
            Bound::AtMost(Figure::LatePenetration, 0.06),
        ],
        rest: None,
        box2d: "stands, 4.4 cm",
    }
}

/// Two 1 m boxes at x = ±9 and a 20 m box (400:1) dropped from y = 26, on
/// a ground segment (`thick_ground == false`, ratio 2) or a thick static
/// box (ratio 3).
#[must_use]
pub fn high_mass_ratio_drop(thick_ground: bool) -> HardCase {
    let name = if thick_ground {
        "high_mass_ratio_3"
    } else {
        "high_mass_ratio_2"
    };
    let mut d = SceneDesc::new(name, 600);
    let ground = if thick_ground {
        ShapeDesc::new(offset_box(40.0, 5.0, v(0.0, -5.0)))
    } else {
        ShapeDesc::new(Geometry::Segment {
            a: v(-40.0, 0.0),
            b: v(40.0, 0.0),
        })
    };
    d.add(BodyDesc::fixed(DVec2::ZERO).with(ground));
    d.add(BodyDesc::dynamic(v(-9.0, 0.5)).with(ShapeDesc::new(square(0.5, 0.5))));
    d.add(BodyDesc::dynamic(v(9.0, 0.5)).with(ShapeDesc::new(square(0.5, 0.5))));
    d.add(BodyDesc::dynamic(v(0.0, 26.0)).with(ShapeDesc::new(square(10.0, 10.0))));
    HardCase {
        name,
        desc: d,
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::BelowGround, 0.0),
            Bound::AtMost(Figure::LatePenetration, 0.1),
        ],
        rest: None,
        box2d: "0.082 m",
    }
}

/// 160 planks half 0.5×0.125 (density 20; mass set directly, no shapes),
/// linear damping 0.1, hinged end to end, both ends pinned. Probe: the
/// middle plank.
#[must_use]
pub fn bridge_scene() -> SceneDesc {
    let mut d = SceneDesc::new("bridge", 600);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO));
    let (hx, hy) = (0.5, 0.125);
    let m = 20.0 * 4.0 * hx * hy;
    let inertia = m * (4.0 * hx * hx + 4.0 * hy * hy) / 12.0;
    let n = 160;
    let x0 = -(n as f64) * hx;
    let mut prev = ground;
    for i in 0..n {
        let mut body = BodyDesc::dynamic(v(x0 + hx + 2.0 * hx * i as f64, 0.0));
        body.mass = Some((m, inertia));
        body.linear_damping = 0.1;
        let b = d.add(body);
        let anchor_a = if i == 0 { v(x0, 0.0) } else { v(hx, 0.0) };
        d.join(RevoluteDesc::new(prev, b, anchor_a, v(-hx, 0.0)));
        if i == n / 2 {
            d.probe = Some(b);
        }
        prev = b;
    }
    d.join(RevoluteDesc::new(prev, ground, v(hx, 0.0), v(-x0, 0.0)));
    d.probe_label = "middle plank";
    d
}

/// The bridge: late joint gap ≤ 2 cm.
#[must_use]
pub fn bridge() -> HardCase {
    HardCase {
        name: "bridge",
        desc: bridge_scene(),
        steps: 600,
        bounds: vec![Bound::AtMost(Figure::LateJointGap, 0.02)],
        rest: None,
        box2d: "1.4 cm",
    }
}

/// 40 capsule links (half-length 0.5, r 0.125, density 20) in a horizontal
/// line from a static pin at (0, 40), jointed end to end, and a ball r 8
/// (density 20, ≈ 670:1) jointed to the last link. Probe: the ball.
#[must_use]
pub fn ball_and_chain_scene() -> SceneDesc {
    let mut d = SceneDesc::new("ball_and_chain", 600);
    let pin = d.add(BodyDesc::fixed(v(0.0, 40.0)));
    let link = ShapeDesc::new(Geometry::Capsule {
        a: v(-0.5, 0.0),
        b: v(0.5, 0.0),
        radius: 0.125,
    })
    .density(20.0);
    let mut prev = pin;
    let mut prev_anchor = DVec2::ZERO;
    for i in 0..40 {
        let b = d.add(BodyDesc::dynamic(v(0.5 + i as f64, 40.0)).with(link.clone()));
        d.join(RevoluteDesc::new(prev, b, prev_anchor, v(-0.5, 0.0)));
        prev = b;
        prev_anchor = v(0.5, 0.0);
    }
    let ball = d.add(
        BodyDesc::dynamic(v(48.0, 40.0)).with(
            ShapeDesc::new(Geometry::Circle {
                center: DVec2::ZERO,
                radius: 8.0,
            })
            .density(20.0),
        ),
    );
    d.join(RevoluteDesc::new(prev, ball, prev_anchor, v(-8.0, 0.0)));
    d.probe = Some(ball);
    d.probe_label = "ball";
    d
}

/// The ball and chain: peak joint gap ≤ 0.1 m.
#[must_use]
pub fn ball_and_chain() -> HardCase {
    HardCase {
        name: "ball_and_chain",
        desc: ball_and_chain_scene(),
        steps: 600,
        bounds: vec![Bound::AtMost(Figure::JointGap, 0.1)],
        rest: None,
        box2d: "0.24 m",
    }
}

/// 40 non-colliding circles r 0.25 in a horizontal line, the first jointed
/// to a static body at the origin; anchors ±0.5 (rest spacing 1), bodies
/// placed `spacing` apart (2: a 1 m error at every joint).
#[must_use]
pub fn chain_scene(spacing: f64) -> SceneDesc {
    let mut d = SceneDesc::new("stretched_chain", 600);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO));
    let mut circle = ShapeDesc::new(Geometry::Circle {
        center: DVec2::ZERO,
        radius: 0.25,
    });
    circle.filter.mask = 0;
    let mut prev = ground;
    for i in 0..40 {
        let b = d.add(BodyDesc::dynamic(v(spacing * (i as f64 + 0.5), 0.0)).with(circle.clone()));
        let anchor_a = if i == 0 { DVec2::ZERO } else { v(0.5, 0.0) };
        d.join(RevoluteDesc::new(prev, b, anchor_a, v(-0.5, 0.0)));
        prev = b;
    }
    d.probe = Some(prev);
    d.probe_label = "free end";
    d
}

/// Peak speed the unstretched chain's free end reaches by swinging alone
/// (≈ 67 m/s), with 5% headroom: the stretched chain's correction may add
/// no speed of its own.
pub const CHAIN_WHIP_SPEED: f64 = 67.0 * 1.05;

/// The stretched chain: late gap ≤ 1 cm, peak speed ≤ the whip's.
#[must_use]
pub fn stretched_chain() -> HardCase {
    HardCase {
        name: "stretched_chain",
        desc: chain_scene(2.0),
        steps: 600,
        bounds: vec![
            Bound::AtMost(Figure::LateJointGap, 0.01),
            Bound::AtMost(Figure::PeakSpeed, CHAIN_WHIP_SPEED),
        ],
        rest: None,
        box2d: "correction alone reaches 273 m/s",
    }
}

/// One member of the stretched-chain family: a chain of `links`
/// non-colliding links (anchors ±0.5 on each, rest spacing 1 m) hinged to
/// a static pin at the origin, laid out along the direction `angle`
/// (rad; 0 lying to the right, −π/2 hanging, −π/4 at 45° below), its
/// bodies placed `stretch` m apart (1: unstretched; 2: a 1 m error at every
/// joint), turned to the direction so every error is along the chain.
/// Links are circles of r 0.25 or capsules of half-length 0.3 and r 0.125
/// (density 1). Released from rest under gravity for 10 s.
#[must_use]
pub fn posed_chain(angle: f64, stretch: f64, links: usize, capsules: bool) -> SceneDesc {
    let mut d = SceneDesc::new("stretched_chain_family", 600);
    let ground = d.add(BodyDesc::fixed(DVec2::ZERO));
    let mut link = ShapeDesc::new(if capsules {
        Geometry::Capsule {
            a: v(-0.3, 0.0),
            b: v(0.3, 0.0),
            radius: 0.125,
        }
    } else {
        Geometry::Circle {
            center: DVec2::ZERO,
            radius: 0.25,
        }
    });
    link.filter.mask = 0;
    let axis = DVec2::from_angle(angle);
    let mut prev = ground;
    for i in 0..links {
        let mut body = BodyDesc::dynamic(axis * (stretch * (i as f64 + 0.5))).with(link.clone());
        body.angle = angle;
        let b = d.add(body);
        let anchor_a = if i == 0 { DVec2::ZERO } else { v(0.5, 0.0) };
        d.join(RevoluteDesc::new(prev, b, anchor_a, v(-0.5, 0.0)));
        prev = b;
    }
    d.probe = Some(prev);
    d.probe_label = "free end";
    d
}

/// A member of the stretched-chain family with its unstretched twin.
#[derive(Clone, Debug)]
pub struct ChainFamilyCase {
    /// `pose/stretch/links/shape`, e.g. `hanging x2 40 capsules`.
    pub name: String,
    /// The chain released stretched.
    pub stretched: SceneDesc,
    /// The same chain built unstretched and released the same way.
    pub unstretched: SceneDesc,
    /// The pose is hanging (an unstretched hanging chain does not swing).
    pub hanging: bool,
}

/// Speed a hanging chain may reach while its stretch is corrected, m/s
/// (it would not move at all unstretched).
pub const HANGING_RECOVERY_SPEED: f64 = 3.0;

impl ChainFamilyCase {
    /// The bound on the stretched chain's peak speed, m/s: its
    /// unstretched twin's peak + 5%, at least [`HANGING_RECOVERY_SPEED`]
    /// for a hanging chain.
    #[must_use]
    pub fn speed_bound(&self, unstretched_peak: f64) -> f64 {
        let bound = unstretched_peak * 1.05;
        if self.hanging {
            bound.max(HANGING_RECOVERY_SPEED)
        } else {
            bound
        }
    }
}

/// The stretched-chain family: lying, hanging and at 45°; stretched 1.5×,
/// 2× and 3×; 20 and 40 links; circles and capsules (36 members). Each is
/// bounded by its unstretched twin ([`ChainFamilyCase::speed_bound`]) and
/// every joint back within 1 cm over the last second.
#[must_use]
pub fn stretched_chain_family() -> Vec<ChainFamilyCase> {
    let poses = [
        ("lying", 0.0, false),
        ("hanging", -std::f64::consts::FRAC_PI_2, true),
        ("45deg", -std::f64::consts::FRAC_PI_4, false),
    ];
    let mut out = Vec::new();
    for (pose, angle, hanging) in poses {
        for stretch in [1.5, 2.0, 3.0] {
            for links in [20, 40] {
                for capsules in [false, true] {
                    out.push(ChainFamilyCase {
                        name: format!(
                            "{pose} x{stretch} {links} {}",
                            if capsules { "capsules" } else { "circles" }
                        ),
                        stretched: posed_chain(angle, stretch, links, capsules),
                        unstretched: posed_chain(angle, 1.0, links, capsules),
                        hanging,
                    });
                }
            }
        }
    }
    out
}

/// `joint_grid` with N = 40 and doubled gravity: peak gap ≤ 0.2 m.
#[must_use]
pub fn joint_grid_40() -> HardCase {
    let mut d = joint_grid(40, 2.0);
    d.name = "joint_grid_40";
    HardCase {
        name: "joint_grid_40",
        desc: d,
        steps: 600,
        bounds: vec![Bound::AtMost(Figure::JointGap, 0.2)],
        rest: None,
        box2d: "0.20 m",
    }
}

/// Every hard case, in the spec's order.
#[must_use]
pub fn all() -> Vec<HardCase> {
    vec![
        single_box(),
        pyramid20(),
        large_pyramid(),
        vertical_stack(12),
        vertical_stack(15),
        vertical_stack(20),
        double_domino(),
        confined(),
        high_mass_ratio_1(),
        high_mass_ratio_drop(false),
        high_mass_ratio_drop(true),
        bridge(),
        ball_and_chain(),
        stretched_chain(),
        joint_grid_40(),
    ]
}

/// A light 1 m box (density 1, μ 0.6) on a ground box, under a 1 m box
/// `ratio` times denser placed 0.1 m off centre with a 1 cm gap, 10 s.
/// Bound: the light box moves at most 5 cm sideways (it is not squeezed
/// out). Probe: the light box.
#[must_use]
pub fn mass_ratio_stack(ratio: f64) -> HardCase {
    let mut d = SceneDesc::new("mass_ratio_stack", 600);
    d.add(ground_box(50.0, 0.6));
    let light =
        d.add(BodyDesc::dynamic(v(0.0, 0.5)).with(ShapeDesc::new(square(0.5, 0.5)).friction(0.6)));
    d.add(
        BodyDesc::dynamic(v(0.1, 1.51)).with(
            ShapeDesc::new(square(0.5, 0.5))
                .friction(0.6)
                .density(ratio),
        ),
    );
    d.probe = Some(light);
    d.probe_label = "light box";
    HardCase {
        name: "mass_ratio_stack",
        desc: d,
        steps: 600,
        bounds: vec![Bound::AtMost(Figure::Drift, 0.05)],
        rest: None,
        box2d: "",
    }
}

/// A chain of `links` light links (1 m, mass 1, I = 1/12, no shapes)
/// hinged end to end from a static pin at the origin, horizontal, with a
/// bob of mass `ratio` (I = ratio / 32, a disc of r 0.25) hinged at the
/// last link's free end; it swings down under gravity for 10 s. Bound:
/// every joint within 1 cm over the run. Probe: the bob.
#[must_use]
pub fn mass_ratio_chain(links: usize, ratio: f64) -> HardCase {
    let mut d = SceneDesc::new("mass_ratio_chain", 600);
    let pin = d.add(BodyDesc::fixed(DVec2::ZERO));
    let mut prev = pin;
    let mut prev_anchor = DVec2::ZERO;
    for i in 0..links {
        let mut link = BodyDesc::dynamic(v(0.5 + i as f64, 0.0));
        link.mass = Some((1.0, 1.0 / 12.0));
        let b = d.add(link);
        d.join(RevoluteDesc::new(prev, b, prev_anchor, v(-0.5, 0.0)));
        prev = b;
        prev_anchor = v(0.5, 0.0);
    }
    let mut bob = BodyDesc::dynamic(v(links as f64, 0.0));
    bob.mass = Some((ratio, ratio / 32.0));
    let bob = d.add(bob);
    d.join(RevoluteDesc::new(prev, bob, prev_anchor, DVec2::ZERO));
    d.probe = Some(bob);
    d.probe_label = "bob";
    HardCase {
        name: if links == 1 {
            "mass_ratio_bob"
        } else {
            "mass_ratio_chain"
        },
        desc: d,
        steps: 600,
        bounds: vec![Bound::AtMost(Figure::JointGap, 0.01)],
        rest: None,
        box2d: "",
    }
}
