//! Contact data read after the step (issue 13, item 4): per-body and
//! per-shape touching contacts with points, normal, separation, and the
//! normal and tangent impulses totalled over the step; begin events after
//! a joint that kept two bodies apart is destroyed.

use janus2d::prelude::*;

const DT: Real = 1.0 / 60.0;

fn world_with(substeps: u32) -> World {
    World::new(WorldDef {
        solver: SolverSettings {
            substeps,
            ..SolverSettings::default()
        },
        ..WorldDef::default()
    })
    .unwrap()
}

fn ground(world: &mut World, angle: Real) -> BodyHandle {
    let g = world
        .create_body(&BodyDef {
            angle,
            ..BodyDef::fixed(Vec2::ZERO)
        })
        .unwrap();
    world
        .create_shape(
            g,
            &ShapeDef::default(),
            Polygon::make_offset_box(20.0, 0.5, Vec2::new(0.0, -0.5), 0.0),
        )
        .unwrap();
    g
}

fn settle(world: &mut World, steps: usize) {
    for _ in 0..steps {
        world.step(DT).unwrap();
    }
}

/// Sum over a body's touching contacts of the step-total normal impulse, N·s.
fn total_push(world: &World, body: BodyHandle) -> Real {
    world
        .body_contacts(body)
        .unwrap()
        .map(|c| c.total_normal_impulse())
        .sum()
}

#[test]
fn resting_box_total_normal_impulse_is_its_weight_times_the_step_at_any_substep_count() {
    for substeps in [1, 2, 4, 8] {
        let mut w = world_with(substeps);
        ground(&mut w, 0.0);
        let b = w
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)))
            .unwrap();
        w.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        w.set_body_enable_sleep(b, false).unwrap();
        settle(&mut w, 120);
        let weight_impulse = w.mass(b).unwrap() * -w.gravity().y * DT;
        let push = total_push(&w, b);
        assert!(
            (push - weight_impulse).abs() < 0.01 * weight_impulse,
            "{substeps} substeps: total {push} N·s, m g dt = {weight_impulse}"
        );
        // The kept (warm-start) impulse is one substep's share.
        let kept: Real = w
            .body_contacts(b)
            .unwrap()
            .flat_map(|c| c.points().iter().map(|p| p.normal_impulse))
            .sum();
        let share = weight_impulse / substeps as Real;
        assert!(
            (kept - share).abs() < 0.02 * share,
            "{substeps} substeps: kept {kept} N·s, m g dt / n = {share}"
        );
        // Points, normal and separation are those of a box at rest.
        let c = w.body_contacts(b).unwrap().next().unwrap();
        assert_eq!(c.points().len(), 2);
        assert!(c.normal.y.abs() > 0.999, "normal {}", c.normal);
        for p in c.points() {
            assert!(p.separation.abs() < 0.01, "separation {}", p.separation);
            assert!(p.total_tangent_impulse.abs() < 1e-3 * weight_impulse);
        }
    }
}

#[test]
fn box_held_by_friction_on_a_slope_reads_the_slope_force_components() {
    let slope: Real = 0.3; // rad; tan 0.3 = 0.31 < μ = 0.6
    let mut w = world_with(4);
    ground(&mut w, slope);
    let (s, c) = (slope.sin(), slope.cos());
    let b = w
        .create_body(&BodyDef {
            angle: slope,
            ..BodyDef::dynamic(Vec2::new(-0.5 * s, 0.5 * c))
        })
        .unwrap();
    let def = ShapeDef {
        friction: 0.6,
        ..ShapeDef::default()
    };
    w.create_shape(b, &def, Polygon::make_box(0.5, 0.5))
        .unwrap();
    w.set_body_enable_sleep(b, false).unwrap();
    settle(&mut w, 120);
    assert!(w.linear_velocity(b).unwrap().length() < 1e-3, "it slides");
    let weight_impulse = w.mass(b).unwrap() * -w.gravity().y * DT;
    let contact = w.body_contacts(b).unwrap().next().unwrap();
    let normal: Real = contact.total_normal_impulse();
    let tangent: Real = contact
        .points()
        .iter()
        .map(|p| p.total_tangent_impulse)
        .sum();
    assert!(
        (normal - weight_impulse * c).abs() < 0.01 * weight_impulse,
        "normal {normal}, m g cos θ dt = {}",
        weight_impulse * c
    );
    assert!(
        (tangent.abs() - weight_impulse * s).abs() < 0.01 * weight_impulse,
        "tangent {tangent}, m g sin θ dt = {}",
        weight_impulse * s
    );
}

#[test]
fn shape_contacts_name_only_that_shapes_contacts() {
    let mut w = world_with(4);
    ground(&mut w, 0.0);
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)))
        .unwrap();
    let left = w
        .create_shape(
            b,
            &ShapeDef::default(),
            Polygon::make_offset_box(0.5, 0.5, Vec2::new(-1.0, 0.0), 0.0),
        )
        .unwrap();
    let up = w
        .create_shape(
            b,
            &ShapeDef::default(),
            Polygon::make_offset_box(0.5, 0.5, Vec2::new(-1.0, 2.0), 0.0),
        )
        .unwrap();
    let right = w
        .create_shape(
            b,
            &ShapeDef::default(),
            Polygon::make_offset_box(0.5, 0.5, Vec2::new(1.0, 0.0), 0.0),
        )
        .unwrap();
    settle(&mut w, 60);
    assert_eq!(w.body_contacts(b).unwrap().count(), 2);
    assert_eq!(w.shape_contacts(left).unwrap().count(), 1);
    assert_eq!(w.shape_contacts(right).unwrap().count(), 1);
    assert_eq!(w.shape_contacts(up).unwrap().count(), 0);
    let c = w.shape_contacts(left).unwrap().next().unwrap();
    assert!(c.shapes.contains(&left));
    // The two ground contacts share the body's weight.
    let weight_impulse = w.mass(b).unwrap() * -w.gravity().y * DT;
    let push = total_push(&w, b);
    assert!(
        (push - weight_impulse).abs() < 0.01 * weight_impulse,
        "{push}"
    );
}

#[test]
fn contact_queries_on_a_stale_handle_are_errors() {
    let mut w = world_with(4);
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    w.destroy_body(b).unwrap();
    assert!(matches!(w.body_contacts(b), Err(WorldError::StaleBody)));
    assert!(w.shape_contacts(s).is_err());
}

/// A box pinned inside a static block by a joint (collide_connected off)
/// has no contact with it; once the joint goes, the pair is found again
/// at the next step (a begin event) and the box is pushed out, though it
/// never moved out of its fat box.
#[test]
fn destroying_a_joint_lets_its_resting_bodies_collide_again() {
    let mut w = world_with(4);
    w.set_gravity(Vec2::ZERO).unwrap();
    let block = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let block_shape = w
        .create_shape(block, &ShapeDef::default(), Polygon::make_box(1.0, 1.0))
        .unwrap();
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 1.2)))
        .unwrap();
    let box_shape = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    let joint = w
        .create_revolute_joint(&RevoluteJointDef::new(
            block,
            b,
            Vec2::new(0.0, 1.2),
            Vec2::ZERO,
        ))
        .unwrap();
    settle(&mut w, 10);
    assert_eq!(
        w.body_contacts(b).unwrap().count(),
        0,
        "jointed: no contact"
    );
    w.destroy_joint(joint).unwrap();
    w.step(DT).unwrap();
    let began = &w.events().collision.contact_begin;
    assert!(
        began.iter().any(|e| {
            [e.shape_a, e.shape_b].contains(&block_shape)
                && [e.shape_a, e.shape_b].contains(&box_shape)
        }),
        "no begin event after the joint went: {began:?}"
    );
    settle(&mut w, 60);
    // Pushed out of the block: its bottom (y − 0.5) rises to the top (1.0).
    let y = w.position(b).unwrap().y;
    assert!(y > 1.49, "still inside the block: y = {y}");
}

fn resting_pair() -> (World, ShapeHandle, BodyHandle, ShapeHandle) {
    let mut w = world_with(4);
    let g = ground(&mut w, 0.0);
    let g_shape = w.body_shapes(g).unwrap()[0];
    let b = w
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5)))
        .unwrap();
    let s = w
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    settle(&mut w, 5);
    assert_eq!(w.body_contacts(b).unwrap().count(), 1);
    (w, g_shape, b, s)
}

fn ended(w: &World, a: ShapeHandle, b: ShapeHandle) -> usize {
    w.events()
        .collision
        .contact_end
        .iter()
        .filter(|e| [e.shape_a, e.shape_b].contains(&a) && [e.shape_a, e.shape_b].contains(&b))
        .count()
}

#[test]
fn joining_touching_bodies_reports_their_contact_end_at_the_next_step() {
    let (mut w, g_shape, b, s) = resting_pair();
    let g = w.shape_body(g_shape).unwrap();
    w.create_revolute_joint(&RevoluteJointDef::new(
        g,
        b,
        Vec2::new(0.0, 0.5),
        Vec2::ZERO,
    ))
    .unwrap();
    w.step(DT).unwrap();
    assert_eq!(ended(&w, g_shape, s), 1);
    assert_eq!(w.body_contacts(b).unwrap().count(), 0);
}

#[test]
fn destroying_a_touching_shape_reports_its_contact_end_at_the_next_step() {
    let (mut w, g_shape, b, s) = resting_pair();
    w.destroy_shape(s).unwrap();
    w.step(DT).unwrap();
    assert_eq!(ended(&w, g_shape, s), 1);
    assert_eq!(w.body_contacts(b).unwrap().count(), 0);
}

/// A box 5 cm above the ground (beyond the 2 cm speculative distance),
/// no gravity, moving at `velocity` for one step: the number of touching
/// contacts after it and the box's height.
fn box_above_ground_after_a_step(velocity: Vec2) -> (usize, Real) {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    ground(&mut world, 0.0);
    let b = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.55)).with_velocity(velocity))
        .unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
        .unwrap();
    world.step(DT).unwrap();
    (world.touching_contact_count(), world.position(b).unwrap().y)
}

#[test]
fn speculative_points_come_only_where_the_bodies_can_close_the_gap() {
    // Sliding along the ground at 12 m/s: the pair's reach within the step
    // (2 cm + 12 m/s × 1/60 s = 22 cm) covers the 5 cm gap, but nothing
    // closes it, so no point is kept and nothing touches.
    let (touching, y) = box_above_ground_after_a_step(Vec2::new(12.0, 0.0));
    assert_eq!(touching, 0, "a box sliding past the ground touches it");
    assert!((y - 0.55).abs() < 1e-6, "the sliding box moved to y = {y}");
    // Falling at 6 m/s (10 cm a step) it closes the gap: the point is kept
    // and the box stops on the ground instead of passing into it.
    let (touching, y) = box_above_ground_after_a_step(Vec2::new(0.0, -6.0));
    assert_eq!(touching, 1, "a box falling onto the ground has no contact");
    assert!(
        y > 0.5 - 0.005,
        "the falling box went into the ground to y = {y}"
    );
}
