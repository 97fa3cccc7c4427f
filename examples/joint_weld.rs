//! The weld joint as a cantilever: ten 1 m × 0.25 m boxes of 1 kg welded
//! rigidly end to end from a wall, horizontal under gravity, 2 s at 60 Hz
//! and 4 substeps (the peers benchmark's `weld_cantilever`; Box2D 3.2 sags
//! 0.55 m on it, docs/performance.md). Rigid welds form a tree, so the
//! exact tree solve takes all three rows of each; the same beam solved by
//! Gauss–Seidel alone (`direct_joints: false`) is shown beside it. Prints
//! the tip sag and what the root weld carries against the beam's weight
//! and moment.
//! Run with `cargo run --release --example joint_weld`.

use janus2d::prelude::*;

const LINKS: usize = 10;

/// The beam's tip sag at the end and its peak (m, down), and the root
/// weld's force (N) and torque (N·m).
fn cantilever(direct_joints: bool) -> Result<(Real, Real, Vec2, Real), WorldError> {
    let mut def = WorldDef::default();
    def.solver.direct_joints = direct_joints;
    def.sleep.enabled = false;
    let mut world = World::new(def)?;
    let wall = world.create_body(&BodyDef::fixed(Vec2::ZERO))?;
    // 1 m × 0.25 m at 4 kg/m² = 1 kg.
    let shape = ShapeDef::default().with_density(4.0);
    let (mut prev, mut boxes, mut welds) = (wall, Vec::new(), Vec::new());
    for k in 0..LINKS {
        let b = world.create_body(&BodyDef::dynamic(Vec2::new(k as Real + 0.5, 0.0)))?;
        world.create_shape(b, &shape, Polygon::make_box(0.5, 0.125))?;
        // Welded rigidly (both hertz 0, the default) at the shared end,
        // the frames placed from the world point.
        let base = world.joint_base_at(prev, b, Vec2::new(k as Real, 0.0))?;
        welds.push(world.create_joint(&WeldJointDef::from_base(base).into())?);
        boxes.push(b);
        prev = b;
    }
    let tip = *boxes.last().expect("ten boxes");
    let (mut sag, mut peak) = (0.0, 0.0 as Real);
    for _ in 0..120 {
        world.step(1.0 / 60.0)?;
        sag = -world.transform(tip)?.apply(Vec2::new(0.5, 0.0)).y;
        peak = peak.max(sag);
    }
    Ok((
        sag,
        peak,
        world.joint_force(welds[0])?,
        world.joint_torque(welds[0])?,
    ))
}

fn main() -> Result<(), WorldError> {
    let (sag, peak, force, torque) = cantilever(true)?;
    println!(
        "rigid welds, tree solve: tip sag {:.1} mm (peak {:.1} mm); the root weld carries \
         {:.1} N up and {torque:.1} N·m (weight 100 N, moment Σ m g x = 500 N·m)",
        1e3 * sag,
        1e3 * peak,
        force.y
    );
    let (sag, peak, _, _) = cantilever(false)?;
    println!(
        "the same welds, Gauss–Seidel only: tip sag {:.1} mm (peak {:.1} mm: the beam swings down \
         and springs back)",
        1e3 * sag,
        1e3 * peak
    );
    Ok(())
}
