//! A rope through a portal, headless: 20 hinged links (0.5 m each) fall
//! into a floor portal and come out of a wall portal whole, with η = 1 and
//! η = 2 (the links come out twice as long). Every step it measures each
//! joint's gap through the portal map: the distance of the joint's two
//! anchors and, when the joint is on a copy of a crossing link, the anchor
//! on the joint's other body mapped through the crossing's map against the
//! anchor carried to the other copy. Run with
//! `cargo run --release --example portal_rope`.

use janus2d::prelude::*;
use janus2d::world::{CrossingRole, PortalDef, PortalEvent, PortalPairDef, PortalPairHandle};

/// What happened to one rope.
pub struct Report {
    /// The pair's scale.
    pub eta: Real,
    /// Links that went through (their crossing completed; all 20: the
    /// rope came out whole).
    pub links_through: usize,
    /// Steps until the last link was through (`None`: never).
    pub steps_to_through: Option<usize>,
    /// Worst joint gap through the map over the run, m (metres of the side
    /// it is measured on).
    pub worst_gap: Real,
    /// Joint-disabled events.
    pub disabled: usize,
    /// The first link's position at the end, m.
    pub first_link: Vec2,
}

/// The floor portal's centre x and the exit face's x, m.
const ENTRY_X: Real = 20.0;
const EXIT_X: Real = -19.5;

/// One joint's gap through the map, m.
fn gap_through_map(world: &World, joint: JointHandle, pair: PortalPairHandle) -> Real {
    let Ok(j) = world.revolute_joint(joint) else {
        return Real::INFINITY;
    };
    let ends = [
        (j.def().base.body_a, j.def().base.local_frame_a.anchor),
        (j.def().base.body_b, j.def().base.local_frame_b.anchor),
    ];
    let anchor =
        |(b, l): (BodyHandle, Vec2)| world.transform(b).map_or(Vec2::ZERO, |xf| xf.apply(l));
    let mut gap = (anchor(ends[0]) - anchor(ends[1])).length();
    for k in 0..2 {
        let (body, local) = ends[k];
        let Ok(side) = world.portal_side(body, pair) else {
            continue;
        };
        if side.crossing == CrossingRole::None {
            continue;
        }
        // The crossing's constraint names both copies; its map goes from
        // the original's side to the clone's.
        let Some(pc) = world
            .portal_constraints()
            .iter()
            .find(|pc| pc.def().body == body || pc.def().clone == body)
        else {
            continue;
        };
        let map = world.portal_constraint_map(pc);
        let (twin, map, scale) = if pc.def().body == body {
            (pc.def().clone, map, map.eta)
        } else {
            (pc.def().body, map.inverse(), 1.0 / map.eta)
        };
        // The twin's frame is this copy's scaled about the local centre of mass.
        let (Ok(xf), Ok(center)) = (world.transform(body), world.center_of_mass(body)) else {
            continue;
        };
        let c = xf.apply_inv(center);
        let on_twin = anchor((twin, c + scale * (local - c)));
        gap = gap.max((map.map_point(anchor(ends[1 - k])) - on_twin).length());
    }
    gap
}

/// Builds the scene with scale `eta`, drops the rope and runs 5 s.
pub fn run(eta: Real) -> Result<Report, WorldError> {
    let mut world = World::new(WorldDef::default())?;
    // Floor with its top at y = 0, a wall whose face is at x = −19.5.
    let floor = world.create_body(&BodyDef::fixed(Vec2::new(ENTRY_X, -0.5)))?;
    world.create_shape(floor, &ShapeDef::default(), Polygon::make_box(4.0, 0.5))?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::new(EXIT_X - 0.5, 5.0)))?;
    world.create_shape(wall, &ShapeDef::default(), Polygon::make_box(0.5, 5.0))?;
    let pair = world.create_portal_pair(
        &PortalPairDef::new(
            PortalDef {
                body: floor,
                anchor: Vec2::new(0.0, 0.5),
                direction: Vec2::Y,
                half_width: 1.0,
            },
            PortalDef {
                body: wall,
                anchor: Vec2::new(0.5, 0.0),
                direction: Vec2::X,
                half_width: eta,
            },
        )
        .with_eta(eta),
    )?;
    // The rope: hanging straight, its lowest end 1 m above the portal.
    let mut links: Vec<BodyHandle> = Vec::new();
    let mut joints = Vec::new();
    for i in 0..20 {
        let b = world.create_body(&BodyDef::dynamic(Vec2::new(
            ENTRY_X + 0.3,
            1.25 + 0.5 * i as Real,
        )))?;
        world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.05, 0.25))?;
        if let Some(&prev) = links.last() {
            joints.push(world.create_revolute_joint(&RevoluteJointDef::new(
                prev,
                b,
                Vec2::new(0.0, 0.25),
                Vec2::new(0.0, -0.25),
            ))?);
        }
        links.push(b);
    }
    let (mut worst_gap, mut disabled, mut steps_to_through) = (0.0 as Real, 0, None);
    let mut through: Vec<BodyHandle> = Vec::new();
    for step in 0..300 {
        world.step(1.0 / 60.0)?;
        for e in &world.events().portals {
            match *e {
                PortalEvent::JointDisabled { .. } => disabled += 1,
                PortalEvent::CrossingCompleted { body, .. } if !through.contains(&body) => {
                    through.push(body)
                }
                _ => {}
            }
        }
        for &j in &joints {
            worst_gap = worst_gap.max(gap_through_map(&world, j, pair));
        }
        let out = links.iter().filter(|b| through.contains(b)).count();
        if steps_to_through.is_none() && out == links.len() && world.crossing_count() == 0 {
            steps_to_through = Some(step + 1);
        }
    }
    Ok(Report {
        eta,
        links_through: links.iter().filter(|b| through.contains(b)).count(),
        steps_to_through,
        worst_gap,
        disabled,
        first_link: world.position(links[0])?,
    })
}

fn main() -> Result<(), WorldError> {
    for eta in [1.0, 2.0] {
        let r = run(eta)?;
        println!(
            "η = {}: {} of 20 links through (all out after {} steps), worst joint gap through the map {:.2} mm, {} joints disabled; first link now at ({:.1}, {:.1}), out of the wall portal at x = {EXIT_X}",
            r.eta,
            r.links_through,
            r.steps_to_through
                .map_or("-".to_string(), |s| s.to_string()),
            r.worst_gap * 1000.0,
            r.disabled,
            r.first_link.x,
            r.first_link.y
        );
    }
    Ok(())
}
