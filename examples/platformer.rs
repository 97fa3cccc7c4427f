//! A platformer character, headless: a capsule moved by a
//! `CharacterController` walks along the floor, steps up a 0.2 m stair,
//! climbs a 30° slope, drops off a ledge, rides a platform moving at 3 m/s,
//! then jumps up through a one-way ledge and lands on it. In a second
//! room it walks into a wall portal and comes out of its partner, twice
//! as wide, twice as large and twice as fast. Prints what happened. Run
//! with `cargo run --release --example platformer`.

use janus2d::prelude::*;
use janus2d::{PortalDef, PortalPairDef};

const DT: Real = 1.0 / 60.0;
const GRAVITY: Real = 10.0;
const WALK: Real = 2.0;
const ONE_WAY: u64 = 0b10;

/// What the run did.
pub struct Report {
    /// Steps taken up a ledge.
    pub steps_up: usize,
    /// Highest point reached on the slope's plateau, m.
    pub plateau_height: Real,
    /// How far the platform carried the character, m.
    pub ridden: Real,
    /// Largest drift of the character from its place on the platform, m.
    pub ride_drift: Real,
    /// Height the character ended at, standing on the one-way ledge, m.
    pub final_height: Real,
    /// Whether it ended standing on the one-way ledge.
    pub on_ledge: bool,
}

fn fixed(world: &mut World, at: Vec2, polygon: Polygon, def: &ShapeDef) -> Result<(), WorldError> {
    let b = world.create_body(&BodyDef::fixed(at))?;
    world.create_shape(b, def, polygon)?;
    Ok(())
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
    Walk,
    Board,
    Ride,
    ToLedge,
    Jump,
    Done,
}

/// Runs the course and prints what happens.
pub fn run() -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let solid = ShapeDef::default();
    // The floor (top y = 0), a 0.2 m stair, a 30° slope up to a plateau.
    fixed(
        &mut world,
        Vec2::new(15.0, -0.5),
        Polygon::make_box(20.0, 0.5),
        &solid,
    )?;
    fixed(
        &mut world,
        Vec2::new(4.5, 0.1),
        Polygon::make_box(1.5, 0.1),
        &solid,
    )?;
    let rise = 2.0 * (30.0 as Real).to_radians().tan();
    let ramp = Polygon::from_hull(
        &[Vec2::ZERO, Vec2::new(2.0, 0.0), Vec2::new(2.0, rise)],
        0.0,
    )?;
    fixed(&mut world, Vec2::new(6.0, 0.2), ramp, &solid)?;
    fixed(
        &mut world,
        Vec2::new(9.0, 0.1 + 0.5 * rise),
        Polygon::make_box(1.0, 0.1 + 0.5 * rise),
        &solid,
    )?;
    // A platform 0.05 m above the floor (its top 0.25 m up), waiting at x = 13.
    let platform = world.create_body(&BodyDef::kinematic(Vec2::new(13.0, 0.15)))?;
    world.create_shape(platform, &solid, Polygon::make_box(1.5, 0.1))?;
    // A one-way ledge 2 m up at x = 24.
    let one_way = ShapeDef {
        filter: Filter {
            category_bits: ONE_WAY,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    fixed(
        &mut world,
        Vec2::new(24.0, 2.0),
        Polygon::make_box(1.5, 0.1),
        &one_way,
    )?;

    let capsule = Capsule::new(Vec2::new(0.0, 0.25), Vec2::new(0.0, 0.75), 0.25)?;
    let mut cc = CharacterController::new().with_one_way_bits(ONE_WAY);
    let filter = QueryFilter::default();
    let (mut p, mut vy) = (Vec2::new(0.0, 0.01), 0.0);
    let mut phase = Phase::Walk;
    let mut report = Report {
        steps_up: 0,
        plateau_height: 0.0,
        ridden: 0.0,
        ride_drift: 0.0,
        final_height: 0.0,
        on_ledge: false,
    };
    let mut ride_start: Option<(Real, Vec2, Vec2)> = None;
    let mut was_grounded = true;
    for k in 0..1200 {
        let t = k as Real * DT;
        world.step(DT)?;
        let vx = match phase {
            Phase::Walk | Phase::Board | Phase::ToLedge => WALK,
            _ => 0.0,
        };
        let r = cc.move_and_slide(&world, &capsule, p, Vec2::new(vx, vy), DT, &filter)?;
        p = r.position;
        vy = if r.grounded { 0.0 } else { r.velocity.y } - GRAVITY * DT;
        let on = |b: BodyHandle| r.ground.is_some_and(|g| g.body == b);
        if r.stepped {
            report.steps_up += 1;
            println!("t = {t:5.2} s  stepped up a ledge at x = {:.2}", p.x);
        }
        if was_grounded && !r.grounded && phase != Phase::Jump {
            println!(
                "t = {t:5.2} s  left the ground at x = {:.2}, y = {:.3}",
                p.x, p.y
            );
        }
        if !was_grounded && r.grounded {
            println!("t = {t:5.2} s  landed at x = {:.2}, y = {:.3}", p.x, p.y);
        }
        was_grounded = r.grounded;
        if (8.0..10.0).contains(&p.x) {
            report.plateau_height = report.plateau_height.max(p.y);
        }
        match phase {
            Phase::Walk if p.x > 10.5 => {
                println!(
                    "t = {t:5.2} s  over the 30° slope and its plateau (bottom up to y = {:.3}), on to the platform",
                    report.plateau_height
                );
                phase = Phase::Board;
            }
            Phase::Board if on(platform) && p.x > 12.8 => {
                println!(
                    "t = {t:5.2} s  on the platform at x = {:.2}: it moves right at 3 m/s",
                    p.x
                );
                world.set_linear_velocity(platform, Vec2::new(3.0, 0.0))?;
                let at = world.position(platform)?;
                ride_start = Some((t, p - at, p));
                phase = Phase::Ride;
            }
            Phase::Ride => {
                let (t0, offset0, p0) = ride_start.unwrap_or((t, Vec2::ZERO, p));
                let offset = p - world.position(platform)?;
                report.ride_drift = report.ride_drift.max((offset - offset0).length());
                if t - t0 >= 2.0 {
                    world.set_linear_velocity(platform, Vec2::ZERO)?;
                    report.ridden = (p - p0).length();
                    println!(
                        "t = {t:5.2} s  the platform stops: carried {:.2} m, drift from its place on it {:.5} m",
                        report.ridden, report.ride_drift
                    );
                    phase = Phase::ToLedge;
                }
            }
            Phase::ToLedge if p.x >= 24.0 => {
                println!("t = {t:5.2} s  under the one-way ledge: jump");
                vy = 8.0;
                phase = Phase::Jump;
            }
            Phase::Jump if !r.grounded && vy < 0.0 && p.y > 2.1 => {
                println!(
                    "t = {t:5.2} s  through the one-way ledge (bottom at y = {:.3}), falling back",
                    p.y
                );
                phase = Phase::Done;
            }
            _ => {}
        }
        if k % 60 == 0 {
            println!(
                "t = {t:5.2} s  x = {:6.3}  y = {:6.3}  {}",
                p.x,
                p.y,
                if r.grounded { "grounded" } else { "in the air" }
            );
        }
        if phase == Phase::Done && r.grounded {
            report.final_height = p.y;
            report.on_ledge = (p.y - 2.1).abs() < 0.02;
            println!(
                "t = {t:5.2} s  standing on the one-way ledge: bottom at y = {:.3} (its top is 2.1)",
                p.y
            );
            break;
        }
    }
    Ok(report)
}

/// The portal room: walls at x = 5 (an aperture 2.4 m wide, from y = −0.2)
/// and x = −20 (its partner, 4.8 m wide, from y = 0.1: η = 2). The character walks right
/// at 2 m/s into the first; returns its scale and speed as it comes out.
pub fn portal_run() -> Result<(Real, Real), WorldError> {
    let mut world = World::new(WorldDef::default())?;
    let solid = ShapeDef::default();
    fixed(
        &mut world,
        Vec2::new(0.0, -0.5),
        Polygon::make_box(30.0, 0.5),
        &solid,
    )?;
    let mut wall = |x: Real| -> Result<BodyHandle, WorldError> {
        let b = world.create_body(&BodyDef::fixed(Vec2::new(x, 2.5)))?;
        world.create_shape(b, &solid, Polygon::make_box(0.5, 3.5))?;
        Ok(b)
    };
    let (a, b) = (wall(5.5)?, wall(-20.5)?);
    world.create_portal_pair(&PortalPairDef::new(
        PortalDef::new(a, Vec2::new(-0.5, -1.5), -Vec2::X, 1.2),
        PortalDef::new(b, Vec2::new(0.5, 0.0), Vec2::X, 2.4),
    ))?;
    // Through portals: the filter says so.
    let filter = QueryFilter::default().through_portals();
    let mut capsule = Capsule::new(Vec2::new(0.0, 0.25), Vec2::new(0.0, 0.75), 0.25)?;
    let mut cc = CharacterController::new();
    let (mut p, mut v) = (Vec2::new(2.0, 0.01), Vec2::new(WALK, 0.0));
    let mut out = (1.0, WALK);
    for k in 0..180 {
        let t = k as Real * DT;
        let r = cc.move_and_slide(
            &world,
            &capsule,
            p,
            v - Vec2::new(0.0, GRAVITY * DT),
            DT,
            &filter,
        )?;
        if let Some(c) = r.crossings.first() {
            println!(
                "t = {t:5.2} s  through the portal at ({:.2}, {:.2}): out at ({:.2}, {:.2}), \
                 capsule radius {:.2} (x{:.1}), moving at {:.2} m/s",
                c.point.x,
                c.point.y,
                c.exit_point().x,
                c.exit_point().y,
                r.capsule.radius,
                r.scale,
                r.velocity.length()
            );
            out = (r.scale, r.velocity.length());
        }
        (capsule, p, v) = (r.capsule, r.position, r.velocity);
    }
    println!(
        "after 3 s: x = {:.2}, y = {:.3}, walking at {:.2} m/s",
        p.x, p.y, v.x
    );
    Ok(out)
}

fn main() -> Result<(), WorldError> {
    let r = run()?;
    println!(
        "\nsummary: {} step(s) up, plateau at y = {:.3}, rode {:.2} m with {:.5} m drift, ended at y = {:.3} ({})",
        r.steps_up,
        r.plateau_height,
        r.ridden,
        r.ride_drift,
        r.final_height,
        if r.on_ledge {
            "on the one-way ledge"
        } else {
            "not on the ledge"
        }
    );
    println!("\nthe portal room:");
    let (scale, speed) = portal_run()?;
    println!("came out scaled by {scale:.2}, at {speed:.2} m/s (walked in at {WALK:.2})");
    Ok(())
}
