//! The random-operation soak (issue 35): seeded random sequences of the
//! public API with sane values (positions within ±15 m, velocities within
//! ±8 m/s, masses up to 5 kg): bodies of every type with every shape kind
//! (a kinematic body may carry chain segments), every joint kind with
//! limits, motors and springs (created between any two bodies, so often
//! metres from satisfied), portal pairs, sleep, kinematic targets, forces
//! and impulses, setters of bodies, shapes and joints, the exact tree solve
//! switched on and off, destruction of everything. After every step no
//! dynamic body is faster than its `max_linear_speed` and
//! [`World::validate`] passes.
//!
//! CI runs a few thousand operations; the long run (1,000,000 operations
//! in release, outside CI):
//!
//! ```text
//! cargo test --release --test engine -- --ignored --nocapture soak
//! JANUS_SOAK_OPS=200000 cargo test --release --test engine -- --ignored --nocapture soak
//! ```

use janus2d::constraints::JointKind;
use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

/// Largest mass the soak gives a body, kg.
const MAX_MASS: Real = 5.0;
/// Largest coordinate of a position the soak sets, m.
const REACH: Real = 15.0;
/// Largest speed the soak sets, m/s.
const SPEED: Real = 8.0;
/// Bodies beyond this many are not created (the soak destroys instead).
const MAX_BODIES: usize = 80;

/// A small seeded generator (xorshift64*).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Rng {
        Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1)
    }
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    /// Uniform in `[lo, hi)`.
    fn real(&mut self, lo: Real, hi: Real) -> Real {
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u as Real
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, p: f64) -> bool {
        ((self.next() >> 11) as f64 / (1u64 << 53) as f64) < p
    }
    fn vec(&mut self, r: Real) -> Vec2 {
        Vec2::new(self.real(-r, r), self.real(-r, r))
    }
    fn unit(&mut self) -> Vec2 {
        let a = self.real(0.0, std::f32::consts::TAU as Real);
        Vec2::new(a.cos(), a.sin())
    }
    fn pick<T: Copy>(&mut self, list: &[T]) -> Option<T> {
        (!list.is_empty()).then(|| list[self.below(list.len())])
    }
}

/// What a soak did and saw.
#[derive(Clone, Debug, Default)]
pub struct SoakReport {
    /// API calls made (steps included).
    pub operations: u64,
    /// Steps taken.
    pub steps: u64,
    /// Calls the world refused with an error (a stale handle, two static
    /// bodies joined, …): each left the world unchanged.
    pub refused: u64,
    /// The fastest dynamic body after any step, m/s.
    pub worst_speed: Real,
    /// That speed over the body's `max_linear_speed`.
    pub worst_speed_ratio: Real,
    /// Times `World::validate` failed after a step (the run stops at the
    /// first, so 0 or 1).
    pub validate_failures: u64,
    /// Bodies the steps reset for a non-finite state.
    pub non_finite_resets: u64,
    /// Resets of a body already reset within the last 60 steps: a reset
    /// body that did not recover (issue 35, "reset once").
    pub repeated_resets: u64,
    /// Joints and portal pairs created.
    pub joints_created: u64,
    pub portal_pairs_created: u64,
    /// Portal crossings completed.
    pub crossings_completed: u64,
    /// The most bodies alive at once.
    pub most_bodies: usize,
}

impl SoakReport {
    fn add(&mut self, other: &SoakReport) {
        self.operations += other.operations;
        self.steps += other.steps;
        self.refused += other.refused;
        self.worst_speed = self.worst_speed.max(other.worst_speed);
        self.worst_speed_ratio = self.worst_speed_ratio.max(other.worst_speed_ratio);
        self.validate_failures += other.validate_failures;
        self.non_finite_resets += other.non_finite_resets;
        self.repeated_resets += other.repeated_resets;
        self.joints_created += other.joints_created;
        self.portal_pairs_created += other.portal_pairs_created;
        self.crossings_completed += other.crossings_completed;
        self.most_bodies = self.most_bodies.max(other.most_bodies);
    }
}

/// Counts a call and whether it was refused.
fn call<T>(report: &mut SoakReport, r: Result<T, WorldError>) -> Option<T> {
    report.operations += 1;
    match r {
        Ok(v) => Some(v),
        Err(_) => {
            report.refused += 1;
            None
        }
    }
}

struct Soak {
    world: World,
    rng: Rng,
    seed: u64,
    bodies: Vec<BodyHandle>,
    shapes: Vec<ShapeHandle>,
    joints: Vec<JointHandle>,
    #[cfg(feature = "portals")]
    pairs: Vec<janus2d::world::PortalPairHandle>,
    report: SoakReport,
    /// Bodies reset for a non-finite state, with the step of their reset.
    reset_at: Vec<(BodyHandle, u64)>,
}

/// A random shape of size up to `size` m and its area, m².
fn random_shape(rng: &mut Rng, size: Real, chain: bool) -> Shape {
    let s = |rng: &mut Rng| rng.real(0.1, size);
    match rng.below(if chain { 6 } else { 5 }) {
        0 => Shape::Polygon(Polygon::make_box(s(rng), s(rng))),
        1 => Shape::Circle(Circle::new(rng.vec(0.3), s(rng)).unwrap()),
        2 => {
            let half = Vec2::new(s(rng), 0.0);
            Shape::Capsule(Capsule::new(-half, half, 0.5 * s(rng)).unwrap())
        }
        3 => {
            let points: Vec<Vec2> = (0..3 + rng.below(6)).map(|_| rng.vec(size)).collect();
            match Polygon::from_hull(&points, 0.0) {
                Ok(p) => Shape::Polygon(p),
                Err(_) => Shape::Polygon(Polygon::make_rounded_box(s(rng), s(rng), 0.05)),
            }
        }
        4 => Shape::Polygon(Polygon::make_rounded_box(s(rng), s(rng), 0.5 * s(rng))),
        _ => {
            let a = rng.vec(2.0 * size);
            let b = a + Vec2::new(rng.real(0.5, 2.0), rng.real(-0.5, 0.5));
            match Segment::new(a, b) {
                Ok(seg) if rng.chance(0.5) => Shape::Segment(seg),
                _ => {
                    let pts = [a, b, b + Vec2::new(1.0, 0.3), b + Vec2::new(2.0, 0.0)];
                    let chain = make_chain(&pts, false).unwrap();
                    Shape::ChainSegment(chain[rng.below(chain.len())])
                }
            }
        }
    }
}

impl Soak {
    fn new(seed: u64) -> Soak {
        let mut def = WorldDef::default();
        let mut rng = Rng::new(seed);
        def.solver.direct_joints = rng.chance(0.7);
        let mut world = World::new(def).unwrap();
        // A floor and two walls keep most things within reach.
        let ground = world
            .create_body(&BodyDef::fixed(Vec2::new(0.0, -REACH - 1.0)))
            .unwrap();
        let mut shapes = Vec::new();
        for (hx, hy, c) in [
            (3.0 * REACH, 1.0, Vec2::ZERO),
            (1.0, 2.0 * REACH, Vec2::new(-3.0 * REACH, 2.0 * REACH)),
            (1.0, 2.0 * REACH, Vec2::new(3.0 * REACH, 2.0 * REACH)),
        ] {
            shapes.push(
                world
                    .create_shape(
                        ground,
                        &ShapeDef::default(),
                        Polygon::make_offset_box(hx, hy, c, 0.0),
                    )
                    .unwrap(),
            );
        }
        Soak {
            world,
            rng,
            seed,
            bodies: vec![ground],
            shapes,
            joints: Vec::new(),
            #[cfg(feature = "portals")]
            pairs: Vec::new(),
            report: SoakReport::default(),
            reset_at: Vec::new(),
        }
    }

    /// A live body, the floor among them (joints and portals may use it).
    fn live_body(&mut self) -> Option<BodyHandle> {
        self.bodies.retain(|&b| self.world.body_type(b).is_ok());
        self.rng.pick(&self.bodies)
    }

    /// A live body other than the floor (the first body: it stays static,
    /// where it is, and its 400 kg never become dynamic).
    fn live_movable_body(&mut self) -> Option<BodyHandle> {
        self.bodies.retain(|&b| self.world.body_type(b).is_ok());
        (self.bodies.len() > 1).then(|| self.bodies[1 + self.rng.below(self.bodies.len() - 1)])
    }

    fn create_body(&mut self) {
        if self.bodies.len() >= MAX_BODIES {
            return self.destroy_body();
        }
        let rng = &mut self.rng;
        let ty = match rng.below(10) {
            0..=6 => BodyType::Dynamic,
            7 | 8 => BodyType::Kinematic,
            _ => BodyType::Static,
        };
        let mut def = BodyDef::dynamic(rng.vec(REACH));
        def.body_type = ty;
        def.angle = rng.real(-3.0, 3.0);
        if ty != BodyType::Static {
            def.linear_velocity = rng.vec(SPEED);
            def.angular_velocity = rng.real(-4.0, 4.0);
        }
        def.fixed_rotation = rng.chance(0.05);
        def.bullet = rng.chance(0.05);
        def.awake = rng.chance(0.9);
        def.gravity_scale = if rng.chance(0.1) {
            rng.real(-1.0, 2.0)
        } else {
            1.0
        };
        def.linear_damping = if rng.chance(0.1) {
            rng.real(0.0, 2.0)
        } else {
            0.0
        };
        let Some(b) = call(&mut self.report, self.world.create_body(&def)) else {
            return;
        };
        self.bodies.push(b);
        let count = 1 + usize::from(self.rng.chance(0.3));
        for _ in 0..count {
            self.add_shape_to(b, ty != BodyType::Dynamic, count);
        }
        if ty == BodyType::Dynamic && self.rng.chance(0.1) {
            let mass = self.rng.real(0.05, MAX_MASS);
            let body_mass = BodyMass {
                mass,
                rotational_inertia: mass * self.rng.real(0.02, 0.5),
                center: self.rng.vec(0.2),
            };
            call(&mut self.report, self.world.set_mass(b, body_mass));
        }
    }

    /// A shape on `b` (chains allowed on bodies that are not dynamic), of
    /// a density that keeps the body within `MAX_MASS` over `count` shapes.
    fn add_shape_to(&mut self, b: BodyHandle, chain: bool, count: usize) {
        let shape = random_shape(&mut self.rng, 0.8, chain);
        let area = shape.area().max(1e-3);
        let mass = self.rng.real(0.05, MAX_MASS / count as Real);
        let mut def = ShapeDef::default()
            .with_density(mass / area)
            .with_friction(self.rng.real(0.0, 1.0))
            .with_restitution(if self.rng.chance(0.2) {
                self.rng.real(0.0, 0.8)
            } else {
                0.0
            });
        if self.rng.chance(0.08) {
            def = def.sensor();
        }
        if self.rng.chance(0.1) {
            def = def.with_hit_events(true);
        }
        if let Some(s) = call(&mut self.report, self.world.create_shape(b, &def, shape)) {
            self.shapes.push(s);
        }
    }

    fn destroy_body(&mut self) {
        // Never the floor (the first body).
        if self.bodies.len() > 1 {
            let k = 1 + self.rng.below(self.bodies.len() - 1);
            let b = self.bodies.swap_remove(k);
            call(&mut self.report, self.world.destroy_body(b));
        }
    }

    fn create_joint(&mut self) {
        let (Some(a), Some(b)) = (self.live_body(), self.live_body()) else {
            return;
        };
        let rng = &mut self.rng;
        let kind = JointKind::ALL[rng.below(JointKind::ALL.len())];
        let (la, lb) = (rng.vec(1.0), rng.vec(1.0));
        let mut def: JointDef = match kind {
            JointKind::Revolute => RevoluteJointDef::new(a, b, la, lb).into(),
            JointKind::Prismatic => PrismaticJointDef::new(a, b, la, lb, rng.unit()).into(),
            JointKind::Weld => {
                let def = WeldJointDef::new(a, b, la, lb);
                if rng.chance(0.3) {
                    def.with_stiffness(rng.real(0.0, 10.0), 1.0, rng.real(0.0, 10.0), 1.0)
                        .into()
                } else {
                    def.into()
                }
            }
            JointKind::Distance => DistanceJointDef::new(a, b, la, lb, rng.real(0.1, 5.0)).into(),
            JointKind::Wheel => WheelJointDef::new(a, b, la, lb, rng.unit()).into(),
            JointKind::Motor => MotorJointDef::new(a, b)
                .with_offset(rng.vec(2.0), rng.real(-1.0, 1.0))
                .with_max_force(rng.real(0.0, 500.0))
                .with_max_torque(rng.real(0.0, 200.0))
                .into(),
            JointKind::Mouse => {
                MouseJointDef::new(a, b, rng.vec(REACH), rng.real(0.0, 1000.0)).into()
            }
            JointKind::Filter => FilterJointDef::new(a, b).into(),
        };
        if let Some(l) = def.limits_mut() {
            *l.enable = rng.chance(0.5);
            let lo = rng.real(-2.0, 0.5);
            *l.lower = if kind == JointKind::Distance {
                lo.abs()
            } else {
                lo
            };
            *l.upper = *l.lower + rng.real(0.0, 2.0);
        }
        if let Some(m) = def.motor_mut() {
            *m.enable = rng.chance(0.4);
            *m.speed = rng.real(-5.0, 5.0);
            *m.max = rng.real(0.0, if m.linear { 500.0 } else { 200.0 });
        }
        if let Some(s) = def.spring_mut() {
            *s.enable = rng.chance(0.3);
            *s.hertz = rng.real(0.0, 10.0);
            *s.damping_ratio = rng.real(0.0, 2.0);
        }
        def.base_mut().collide_connected = rng.chance(0.3);
        if let Some(j) = call(&mut self.report, self.world.create_joint(&def)) {
            self.joints.push(j);
            self.report.joints_created += 1;
        }
    }

    fn joint_setter(&mut self) {
        self.joints.retain(|&j| self.world.joint(j).is_ok());
        let Some(j) = self.rng.pick(&self.joints) else {
            return;
        };
        let rng = &mut self.rng;
        let r = match rng.below(9) {
            0 => {
                let lo = rng.real(-1.0, 0.5);
                let hi = lo + rng.real(0.0, 2.0);
                self.world
                    .set_joint_limits(j, lo.abs(), hi.abs() + lo.abs())
            }
            1 => self.world.enable_joint_limit(j, rng.chance(0.5)),
            2 => self.world.set_joint_motor_speed(j, rng.real(-5.0, 5.0)),
            3 => self
                .world
                .set_joint_max_motor_torque(j, rng.real(0.0, 200.0)),
            4 => self
                .world
                .set_joint_max_motor_force(j, rng.real(0.0, 500.0)),
            5 => self.world.enable_joint_motor(j, rng.chance(0.5)),
            6 => self
                .world
                .set_joint_spring(j, rng.real(0.0, 10.0), rng.real(0.0, 2.0)),
            7 => self.world.enable_joint_spring(j, rng.chance(0.5)),
            _ => self.world.set_joint_enabled(j, rng.chance(0.7)),
        };
        call(&mut self.report, r);
    }

    fn destroy_joint(&mut self) {
        if !self.joints.is_empty() {
            let k = self.rng.below(self.joints.len());
            let j = self.joints.swap_remove(k);
            call(&mut self.report, self.world.destroy_joint(j));
        }
    }

    fn body_setter(&mut self) {
        let Some(b) = self.live_movable_body() else {
            return;
        };
        let mass = self.world.mass(b).unwrap_or(1.0).max(0.05);
        let rng = &mut self.rng;
        let r = match rng.below(16) {
            0 | 1 => self.world.set_linear_velocity(b, rng.vec(SPEED)),
            2 => self.world.set_angular_velocity(b, rng.real(-5.0, 5.0)),
            3 | 4 => self
                .world
                .set_transform(b, rng.vec(REACH), rng.real(-3.0, 3.0)),
            5 => self.world.apply_force_to_center(b, rng.vec(100.0)),
            6 => self.world.apply_force(b, rng.vec(100.0), rng.vec(REACH)),
            7 => self
                .world
                .apply_linear_impulse(b, rng.vec(SPEED * mass), rng.vec(REACH)),
            8 => self.world.apply_torque(b, rng.real(-50.0, 50.0)),
            9 => self.world.apply_angular_impulse(b, rng.real(-2.0, 2.0)),
            10 => {
                let ty = [BodyType::Static, BodyType::Kinematic, BodyType::Dynamic][rng.below(3)];
                self.world.set_body_type(b, ty)
            }
            11 => self.world.set_awake(b, rng.chance(0.5)),
            12 => self.world.set_body_enable_sleep(b, rng.chance(0.8)),
            13 => self.world.set_bullet(b, rng.chance(0.3)),
            14 => {
                let target = Transform::new(rng.vec(REACH), rng.real(-3.0, 3.0));
                self.world.set_target_transform(b, target, DT)
            }
            _ => self.world.wake_body(b),
        };
        call(&mut self.report, r);
    }

    fn shape_op(&mut self) {
        self.shapes.retain(|&s| self.world.shape(s).is_ok());
        let k = self.rng.below(8);
        if k < 2 {
            if let Some(b) = self.live_movable_body() {
                let dynamic = self.world.body_type(b).ok() == Some(BodyType::Dynamic);
                let count = self.world.body_shapes(b).map_or(1, |s| s.len() + 1);
                self.add_shape_to(b, !dynamic, count);
            }
            return;
        }
        let Some(s) = self.rng.pick(&self.shapes) else {
            return;
        };
        if self.world.shape_body(s).ok() == Some(self.bodies[0]) {
            // The floor keeps its shapes as they are.
            return;
        }
        let rng = &mut self.rng;
        let r = match k {
            2 => self.world.destroy_shape(s),
            3 => self.world.set_shape_friction(s, rng.real(0.0, 1.0)),
            4 => self.world.set_shape_restitution(s, rng.real(0.0, 0.8)),
            5 => {
                let mass = self.world.shape_body(s).and_then(|b| self.world.mass(b));
                let area = self.world.shape(s).map_or(1.0, |d| d.geometry.area());
                // Keeps the body within MAX_MASS whatever its other shapes weigh.
                let room = (MAX_MASS - mass.unwrap_or(MAX_MASS)).max(0.0);
                let density = self.world.shape(s).map_or(1.0, |d| d.def.density);
                let most = density + room / area.max(1e-3);
                self.world.set_shape_density(s, rng.real(0.0, most))
            }
            6 => {
                let filter = Filter {
                    category_bits: 1 << rng.below(3),
                    mask_bits: if rng.chance(0.7) {
                        u64::MAX
                    } else {
                        rng.next()
                    },
                    group_index: rng.below(3) as i32 - 1,
                };
                self.world.set_shape_filter(s, filter)
            }
            _ => self.world.set_shape_sensor(s, rng.chance(0.2)),
        };
        call(&mut self.report, r);
    }

    #[cfg(feature = "portals")]
    fn portal_op(&mut self) {
        use janus2d::world::{PortalDef, PortalPairDef};
        self.pairs.retain(|&p| self.world.portal_map(p).is_ok());
        if self.rng.chance(0.3) && !self.pairs.is_empty() {
            let k = self.rng.below(self.pairs.len());
            let p = self.pairs.swap_remove(k);
            call(&mut self.report, self.world.destroy_portal_pair(p));
            return;
        }
        let (Some(a), Some(b)) = (self.live_body(), self.live_body()) else {
            return;
        };
        let rng = &mut self.rng;
        let w = rng.real(0.3, 2.0);
        let mut def = PortalPairDef::new(
            PortalDef::new(a, rng.vec(1.0), rng.unit(), w),
            PortalDef::new(b, rng.vec(1.0), rng.unit(), w * rng.real(0.5, 2.0)),
        );
        if rng.chance(0.3) {
            def = def.with_eta(rng.real(0.5, 2.0));
        }
        if let Some(p) = call(&mut self.report, self.world.create_portal_pair(&def)) {
            self.pairs.push(p);
            self.report.portal_pairs_created += 1;
        }
    }

    #[cfg(not(feature = "portals"))]
    fn portal_op(&mut self) {}

    fn settings_op(&mut self) {
        let mut settings = self.world.settings().clone();
        match self.rng.below(3) {
            0 => settings.direct_joints = !settings.direct_joints,
            1 => settings.substeps = [2, 4, 4, 8][self.rng.below(4)],
            _ => {
                let mut sleep = self.world.sleep_settings();
                sleep.enabled = self.rng.chance(0.8);
                call(&mut self.report, self.world.set_sleep_settings(sleep));
                return;
            }
        }
        call(&mut self.report, self.world.set_settings(settings));
    }

    /// One step and its checks; bodies that left the arena are destroyed.
    fn step(&mut self) {
        let dt = [DT, DT, DT, 1.0 / 120.0, 1.0 / 30.0][self.rng.below(5)];
        call(&mut self.report, self.world.step(dt));
        self.report.steps += 1;
        let events = self.world.events();
        self.report.non_finite_resets += events.non_finite_bodies.len() as u64;
        let step = self.report.steps;
        self.reset_at.retain(|&(_, at)| step - at < 60);
        for &b in &events.non_finite_bodies {
            if self.reset_at.iter().any(|&(r, _)| r == b) {
                self.report.repeated_resets += 1;
            }
            self.reset_at.push((b, step));
        }
        #[cfg(feature = "portals")]
        {
            self.report.crossings_completed += self
                .world
                .events()
                .portals
                .iter()
                .filter(|e| matches!(e, janus2d::portal::PortalEvent::CrossingCompleted { .. }))
                .count() as u64;
        }
        let mut gone = Vec::new();
        for b in self.world.body_handles().collect::<Vec<_>>() {
            if self.world.body_type(b).ok() != Some(BodyType::Dynamic) {
                continue;
            }
            let v = self.world.linear_velocity(b).unwrap().length();
            let max = BodyDef::default().max_linear_speed;
            self.report.worst_speed = self.report.worst_speed.max(v);
            self.report.worst_speed_ratio = self.report.worst_speed_ratio.max(v / max);
            assert!(
                v <= max * (1.0 + 1e-5),
                "seed {}, step {}: {b:?} at {v} m/s, over its {max} m/s",
                self.seed,
                self.report.steps
            );
            let p = self.world.position(b).unwrap();
            if p.y < -3.0 * REACH || p.x.abs() > 4.0 * REACH || p.y > 6.0 * REACH {
                gone.push(b);
            }
        }
        if let Err(e) = self.world.validate() {
            self.report.validate_failures += 1;
            panic!(
                "seed {}, step {} (operation {}): {e}",
                self.seed, self.report.steps, self.report.operations
            );
        }
        self.report.most_bodies = self.report.most_bodies.max(self.world.body_count());
        for b in gone {
            call(&mut self.report, self.world.destroy_body(b));
        }
    }

    fn operation(&mut self) {
        match self.rng.below(100) {
            0..=29 => self.step(),
            30..=39 => self.create_body(),
            40..=43 => self.destroy_body(),
            44..=53 => self.create_joint(),
            54..=55 => self.destroy_joint(),
            56..=61 => self.joint_setter(),
            62..=79 => self.body_setter(),
            80..=89 => self.shape_op(),
            90..=95 => self.portal_op(),
            96..=97 => self.settings_op(),
            _ => {
                // A query now and then (they must not disturb anything).
                let from = self.rng.vec(REACH);
                let to = self.rng.vec(REACH) - from;
                self.report.operations += 1;
                let _ = self
                    .world
                    .cast_ray_closest(from, to, &QueryFilter::default());
            }
        }
    }
}

/// Runs `operations` operations from `seed` (a new world every
/// `per_world` operations, the seed advancing) and returns what it saw.
pub fn soak(seed: u64, operations: u64, per_world: u64) -> SoakReport {
    let mut total = SoakReport::default();
    let mut world_seed = seed;
    while total.operations < operations {
        let mut soak = Soak::new(world_seed);
        let budget = per_world.min(operations - total.operations);
        while soak.report.operations < budget {
            soak.operation();
        }
        total.add(&soak.report);
        world_seed = world_seed.wrapping_add(1);
    }
    total
}

/// Issue 35: a short soak (four worlds of 10,000 operations): after every
/// step no dynamic body is faster than its speed limit and the world
/// validates (the run panics with the seed and step otherwise), and no
/// body is ever reset for a non-finite state: kept joint and portal
/// impulses are bounded (`ROW_SPEED_BOUND`) and a portal row's non-finite
/// impulse is not warm-started again (before, rows that could not all hold
/// overflowed and the same bodies were reset step after step).
#[test]
fn random_operations_keep_every_body_within_its_speed_limit_and_the_world_valid() {
    let report = soak(35, 40_000, 10_000);
    eprintln!("soak: {report:?}");
    assert!(report.steps > 10_000, "too few steps: {report:?}");
    assert!(report.joints_created > 1_000, "too few joints: {report:?}");
    if cfg!(feature = "portals") {
        assert!(
            report.crossings_completed > 0,
            "no portal crossing: {report:?}"
        );
    }
    assert_eq!(report.validate_failures, 0);
    assert!(report.worst_speed_ratio <= 1.0 + 1e-5, "{report:?}");
    assert_eq!(report.non_finite_resets, 0, "{report:?}");
}

/// Issue 35, "reset once": the first world of the short soak (seed 35,
/// 10,000 operations) holds bodies whose joints and portal rows cannot all
/// hold (tree joints to kinematic bodies, crossing copies' joints far from
/// satisfied). Their kept impulses grew until they overflowed, and the
/// same bodies were reset for a non-finite state step after step (3,511
/// resets in this world); a portal row's NaN impulse was warm-started into
/// the reset bodies again. Now every kept impulse is bounded and a
/// non-finite portal impulse is dropped: no body is reset at all.
#[test]
fn rows_that_cannot_all_hold_never_reset_their_bodies_again_and_again() {
    let report = soak(35, 10_000, 10_000);
    assert!(report.steps > 2_000, "too few steps: {report:?}");
    assert_eq!(report.non_finite_resets, 0, "{report:?}");
    assert_eq!(report.validate_failures, 0);
}

/// The world of seed 3549 to its 1,300th operation: a light dynamic
/// portal body took a crossing copy's spin (`ΔI ω` over its own tiny
/// inertia) and left the step with ω = ∞, after the solve's non-finite
/// check (found by the long soak). Every step validates, every body
/// within its speed limit.
#[test]
fn a_portal_body_handed_a_crossings_spin_keeps_a_finite_angular_velocity() {
    let report = soak(3549, 1_300, 20_000);
    assert!(report.steps > 300, "too few steps: {report:?}");
    assert_eq!(report.validate_failures, 0);
    assert!(report.worst_speed_ratio <= 1.0 + 1e-5, "{report:?}");
    assert_eq!(report.non_finite_resets, 0, "{report:?}");
}

/// The long soak: `JANUS_SOAK_OPS` operations (default 1,000,000) over
/// worlds of 20,000 operations each, the first seeded `JANUS_SOAK_SEED`
/// (default 3500, the next ones counting up: a failure names its world's
/// seed, and `JANUS_SOAK_SEED=that JANUS_SOAK_OPS=n` replays it alone);
/// prints its figures.
#[test]
#[ignore = "long: run in release with --ignored"]
fn random_operation_soak_of_a_million_operations() {
    let var = |name: &str| std::env::var(name).ok().and_then(|s| s.parse::<u64>().ok());
    let operations = var("JANUS_SOAK_OPS").unwrap_or(1_000_000);
    let seed = var("JANUS_SOAK_SEED").unwrap_or(3500);
    let start = std::time::Instant::now();
    let report = soak(seed, operations, 20_000);
    println!(
        "soak of {} operations: {} steps, {} refused, worst speed {:.2} m/s ({:.4} of the limit), \
         {} validate failures, {} non-finite resets ({} of a body reset within 60 steps), \
         {} joints and {} portal pairs created, \
         {} crossings completed, at most {} bodies, {:.1} s",
        report.operations,
        report.steps,
        report.refused,
        report.worst_speed,
        report.worst_speed_ratio,
        report.validate_failures,
        report.non_finite_resets,
        report.repeated_resets,
        report.joints_created,
        report.portal_pairs_created,
        report.crossings_completed,
        report.most_bodies,
        start.elapsed().as_secs_f64()
    );
    assert_eq!(report.validate_failures, 0);
    assert!(report.worst_speed_ratio <= 1.0 + 1e-5, "{report:?}");
    // Reset once: a body reset for a non-finite state recovers (issue 35).
    // A reset is rare (none or one in a million operations); a body reset
    // again soon after is what must never happen.
    assert_eq!(report.repeated_resets, 0, "{report:?}");
}
