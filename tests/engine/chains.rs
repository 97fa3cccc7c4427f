//! Chains (`World::create_chain`): rolling across internal vertices,
//! per-segment materials, loops, bad input, destruction, snapshots.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn world() -> World {
    World::new(WorldDef::default()).unwrap()
}

fn ball(w: &mut World, at: Vec2, v: Vec2, r: Real) -> BodyHandle {
    let b = w
        .create_body(&BodyDef::dynamic(at).with_velocity(v))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, r).unwrap())
        .unwrap();
    b
}

/// Flat ground from x = 12 to x = −13, five segments, run right to left
/// (front normal up).
fn five_segment_ground(w: &mut World) -> ChainHandle {
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let points = [12.0, 7.0, 2.0, -3.0, -8.0, -13.0]
        .iter()
        .map(|&x| Vec2::new(x, 0.0))
        .collect();
    w.create_chain(ground, &ChainDef::new(points)).unwrap()
}

#[test]
fn a_ball_rolls_along_a_five_segment_chain_and_stays_on_it() {
    let mut w = world();
    let chain = five_segment_ground(&mut w);
    assert_eq!(w.chain_segments(chain).unwrap().len(), 5);
    let b = ball(&mut w, Vec2::new(-11.0, 0.5), Vec2::new(6.0, 0.0), 0.5);
    let mut worst: Real = 0.0;
    for _ in 0..300 {
        w.step(DT).unwrap();
        let p = w.position(b).unwrap();
        worst = worst.max((p.y - 0.5).abs());
    }
    let x = w.position(b).unwrap().x;
    eprintln!("ball rolled to x = {x:.2}, largest |y - 0.5| = {worst:.4} m");
    // It crossed the internal vertices at −8, −3, 2 and 7 without a snag.
    assert!(x > 7.5, "x = {x}");
    assert!(worst < 0.01, "left the surface by {worst} m");
}

#[test]
fn per_segment_friction_lets_a_box_slide_twice_as_far_on_ice() {
    let mut w = world();
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let ice = SurfaceMaterial::default()
        .with_friction(0.02)
        .with_material_id(1);
    let rough = SurfaceMaterial::default()
        .with_friction(0.8)
        .with_material_id(2);
    // Segment 0 (x from 20 to 0) is ice, segment 1 (0 to −20) rough.
    let def = ChainDef::new(vec![
        Vec2::new(20.0, 0.0),
        Vec2::ZERO,
        Vec2::new(-20.0, 0.0),
    ])
    .with_segment_materials(vec![ice, rough]);
    let chain = w.create_chain(ground, &def).unwrap();
    let segs = w.chain_segments(chain).unwrap().to_vec();
    assert_eq!(w.shape(segs[0]).unwrap().def.friction, 0.02);
    assert_eq!(w.shape(segs[1]).unwrap().def.user_material_id, 2);
    let push = Vec2::new(5.0, 0.0);
    let mut make_box = |x: Real| {
        let b = w
            .create_body(&BodyDef::dynamic(Vec2::new(x, 0.5)).with_velocity(push))
            .unwrap();
        w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        b
    };
    let on_ice = make_box(2.0);
    let on_rough = make_box(-16.0);
    for _ in 0..360 {
        w.step(DT).unwrap();
    }
    let d_ice = w.position(on_ice).unwrap().x - 2.0;
    let d_rough = w.position(on_rough).unwrap().x + 16.0;
    eprintln!("slid {d_ice:.2} m on ice, {d_rough:.2} m on the rough segment");
    assert!(d_rough > 0.5, "rough: {d_rough}");
    assert!(d_ice >= 2.0 * d_rough, "ice {d_ice} vs rough {d_rough}");
}

#[test]
fn a_loop_chain_contains_a_ball_dropped_inside_it() {
    let mut w = world();
    let body = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    // An octagon of radius 4, clockwise: the front faces inward.
    let points: Vec<Vec2> = (0..8)
        .map(|i| {
            let a = -(i as Real) * core::f64::consts::FRAC_PI_4 as Real;
            Vec2::new(4.0 * a.cos(), 4.0 * a.sin())
        })
        .collect();
    let chain = w
        .create_chain(body, &ChainDef::new(points).with_loop(true))
        .unwrap();
    assert_eq!(w.chain_segments(chain).unwrap().len(), 8);
    assert_eq!(w.chain_is_loop(chain), Ok(true));
    let b = ball(&mut w, Vec2::new(1.0, 2.0), Vec2::new(8.0, 5.0), 0.3);
    let mut farthest: Real = 0.0;
    for _ in 0..300 {
        w.step(DT).unwrap();
        farthest = farthest.max(w.position(b).unwrap().length());
    }
    eprintln!("ball's largest distance from the centre in 5 s: {farthest:.3} m");
    // Inside the octagon: its inscribed radius is 4 cos(π/8) = 3.70.
    assert!(farthest < 4.0, "escaped to {farthest}");
    assert!(farthest > 3.0, "never reached the wall: {farthest}");
}

#[test]
fn bad_chain_input_gives_typed_errors_and_leaves_the_world_unchanged() {
    use janus2d::base::geometry::GeometryError;
    let mut w = world();
    let body = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    five_segment_ground(&mut w);
    let (hash, shapes, chains) = (w.state_hash(), w.shape_count(), w.chain_count());
    let p = |x: Real, y: Real| Vec2::new(x, y);
    let cases: Vec<(ChainDef, WorldError)> = vec![
        (
            ChainDef::new(vec![p(0.0, 0.0)]),
            WorldError::Geometry(GeometryError::TooFewPoints {
                found: 1,
                needed: 2,
            }),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0)]).with_loop(true),
            WorldError::Geometry(GeometryError::TooFewPoints {
                found: 2,
                needed: 3,
            }),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(Real::NAN, 0.0)]),
            WorldError::NonFinite("points"),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1e8, 0.0)]),
            WorldError::OutOfBounds {
                field: "points",
                min: -janus2d::base::limits::MAX_EXTENT,
                max: janus2d::base::limits::MAX_EXTENT,
            },
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.0)]),
            WorldError::Geometry(GeometryError::DegenerateSegment),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0), p(2.0, 0.0)])
                .with_segment_materials(vec![SurfaceMaterial::default(); 3]),
            WorldError::OutOfRange("materials"),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0)]).with_segment_materials(vec![]),
            WorldError::OutOfRange("materials"),
        ),
        (
            ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0)])
                .with_material(SurfaceMaterial::default().with_friction(-1.0)),
            WorldError::OutOfRange("friction"),
        ),
    ];
    let n = cases.len();
    for (def, expected) in cases {
        assert_eq!(def.validate(), Err(expected.clone()));
        assert_eq!(w.create_chain(body, &def), Err(expected));
        assert_eq!(
            (w.state_hash(), w.shape_count(), w.chain_count()),
            (hash, shapes, chains)
        );
    }
    // A stale body.
    let gone = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    w.destroy_body(gone).unwrap();
    let hash = w.state_hash();
    let good = ChainDef::new(vec![p(0.0, 0.0), p(1.0, 0.0)]);
    assert_eq!(w.create_chain(gone, &good), Err(WorldError::StaleBody));
    assert_eq!(w.state_hash(), hash);
    assert_eq!(w.validate(), Ok(()));
    eprintln!("{} bad definitions refused, world unchanged", n + 1);
}

#[test]
fn destroy_chain_removes_every_segment_and_stale_handles_are_errors() {
    let mut w = world();
    let box_body = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    w.create_shape(box_body, &ShapeDef::default(), Polygon::make_box(1.0, 1.0))
        .unwrap();
    let before = w.shape_count();
    let chain = five_segment_ground(&mut w);
    assert_eq!((w.shape_count(), w.chain_count()), (before + 5, 1));
    // A segment is not destroyed alone, nor turned into another shape.
    let seg = w.chain_segments(chain).unwrap()[2];
    assert_eq!(w.shape_chain(seg), Ok(Some(chain)));
    assert_eq!(w.destroy_shape(seg), Err(WorldError::ChainSegmentShape));
    assert_eq!(
        w.set_circle(seg, Circle::new(Vec2::ZERO, 1.0).unwrap()),
        Err(WorldError::ChainSegmentShape)
    );
    assert_eq!(w.shape_count(), before + 5);
    w.destroy_chain(chain).unwrap();
    assert_eq!((w.shape_count(), w.chain_count()), (before, 0));
    assert_eq!(w.destroy_chain(chain), Err(WorldError::StaleChain));
    assert_eq!(w.chain_segments(chain), Err(WorldError::StaleChain));
    assert_eq!(w.chain_body(chain), Err(WorldError::StaleChain));
    assert_eq!(w.shape(seg).err(), Some(WorldError::StaleShape));
    // Destroying the body destroys its chains.
    let chain = five_segment_ground(&mut w);
    let body = w.chain_body(chain).unwrap();
    w.destroy_body(body).unwrap();
    assert_eq!((w.shape_count(), w.chain_count()), (before, 0));
    assert_eq!(w.chain_segments(chain), Err(WorldError::StaleChain));
    // Another world's chain handle is foreign.
    let mut other = world();
    let theirs = five_segment_ground(&mut other);
    assert_eq!(w.destroy_chain(theirs), Err(WorldError::ForeignHandle));
    assert_eq!(w.validate(), Ok(()));
    eprintln!("5 segments made and removed twice; shape count back to {before}");
}

#[test]
fn a_snapshot_with_chains_continues_bit_identically() {
    let mut w = world();
    five_segment_ground(&mut w);
    ball(&mut w, Vec2::new(-10.0, 0.5), Vec2::new(4.0, 0.0), 0.5);
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(3.0, 2.0)))
        .unwrap();
    w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.4, 0.4))
        .unwrap();
    for _ in 0..30 {
        w.step(DT).unwrap();
    }
    let saved = w.snapshot();
    let chain = w.chain_handles()[0];
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    let after = w.state_hash();
    w.restore(&saved);
    assert_eq!(w.chain_segments(chain).unwrap().len(), 5);
    for _ in 0..60 {
        w.step(DT).unwrap();
    }
    assert_eq!(w.state_hash(), after);
    #[cfg(feature = "serde")]
    {
        let bytes = saved.to_bytes();
        let mut back = janus2d::world::Snapshot::from_bytes(&bytes)
            .unwrap()
            .to_world();
        assert_eq!(back.chain_count(), 1);
        for _ in 0..60 {
            back.step(DT).unwrap();
        }
        assert_eq!(back.state_hash(), after);
    }
    eprintln!("60 steps after restore: state hash {after:#018x} both times");
}
