//! Only the effects a scene calls for: a stage whose feature the scene
//! lacks does no work, shown by the per-step counters (and events switched
//! off gather nothing, shown by `World::event_work`); and sleeping.

use janus2d::prelude::*;
use janus2d::world::{EventWork, SleepSettings};
use janus2d_testbed::scenes::DT;

fn boxes_on_ground(def: WorldDef, restitution: Real) -> (World, Vec<BodyHandle>) {
    let mut world = World::new(def).unwrap();
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    world
        .create_shape(g, &ShapeDef::default(), Polygon::make_box(20.0, 1.0))
        .unwrap();
    let sd = ShapeDef::default().with_restitution(restitution);
    let bodies = (0..5)
        .map(|i| {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5 + 1.0 * i as Real)))
                .unwrap();
            world
                .create_shape(b, &sd, Polygon::make_box(0.5, 0.5))
                .unwrap();
            b
        })
        .collect();
    (world, bodies)
}

#[test]
fn no_shapes_means_no_collision_work() {
    let mut world = World::new(WorldDef::default()).unwrap();
    for i in 0..10 {
        world
            .create_body(&BodyDef::dynamic(Vec2::new(i as Real, 0.0)))
            .unwrap();
    }
    world.step(DT).unwrap();
    let c = world.counters();
    assert!(!c.collision_ran);
    assert_eq!(
        (c.pairs_tested, c.pairs_created, c.proxies_moved, c.contacts),
        (0, 0, 0, 0)
    );
    assert_eq!(world.profile().broadphase, 0.0);
    assert_eq!(world.profile().narrowphase, 0.0);
}

#[test]
fn no_portals_means_no_portal_stage() {
    let def = WorldDef {
        sleep: SleepSettings {
            enabled: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let (mut world, _) = boxes_on_ground(def, 0.0);
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    let c = world.counters();
    assert!(!c.portal_stage_ran);
    assert_eq!(
        (c.portal_bodies_tested, c.portal_crossings, c.portal_rows),
        (0, 0, 0)
    );
    assert_eq!(world.profile().portals, 0.0);
}

#[cfg(feature = "portals")]
#[test]
fn portals_present_means_portal_stage_runs() {
    let (mut scene, _) = janus2d_testbed::scenes::portal_drop(&WorldDef::default());
    scene.world.step(DT).unwrap();
    assert!(scene.world.counters().portal_stage_ran);
}

#[test]
fn no_restitution_means_no_restitution_contacts() {
    let def = WorldDef {
        sleep: SleepSettings {
            enabled: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let (mut world, _) = boxes_on_ground(def.clone(), 0.0);
    for _ in 0..10 {
        world.step(DT).unwrap();
    }
    assert!(world.counters().contacts > 0);
    assert_eq!(world.counters().restitution_contacts, 0);
    assert_eq!(
        world.profile().solver.restitution,
        0.0,
        "the restitution pass ran"
    );
    let (mut bouncy, _) = boxes_on_ground(def, 0.5);
    for _ in 0..10 {
        bouncy.step(DT).unwrap();
    }
    assert!(bouncy.counters().restitution_contacts > 0);
}

#[test]
fn zero_gravity_means_no_gravity_work_and_no_joints_no_joint_rows() {
    let def = WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    };
    let (mut world, _) = boxes_on_ground(def, 0.0);
    world.step(DT).unwrap();
    assert_eq!(world.counters().gravity_bodies, 0);
    assert_eq!(world.counters().joint_rows, 0);
    // Every tree direct (a one-joint free tree of like masses is left to
    // Gauss–Seidel by default: direct_free_tree_mass_ratio).
    let mut every_tree = WorldDef::default();
    every_tree.solver.direct_free_tree_mass_ratio = 0.0;
    let (mut heavy, bodies) = boxes_on_ground(every_tree, 0.0);
    heavy
        .create_revolute_joint(&RevoluteJointDef::new(
            bodies[0],
            bodies[1],
            Vec2::new(0.0, 0.5),
            Vec2::new(0.0, -0.5),
        ))
        .unwrap();
    heavy.step(DT).unwrap();
    assert_eq!(heavy.counters().gravity_bodies, 5);
    assert_eq!(heavy.counters().joint_rows, 2);
    assert_eq!(heavy.counters().direct_joint_rows, 2, "a one-joint tree");
    assert_eq!(world.counters().direct_joint_rows, 0, "no joints, no tree");
}

#[test]
fn joint_loops_and_the_switch_leave_the_tree_solve_idle() {
    let mut settings = WorldDef::default();
    settings.sleep.enabled = false;
    // Every tree direct (see the test above).
    settings.solver.direct_free_tree_mass_ratio = 0.0;
    let (mut world, bodies) = boxes_on_ground(settings.clone(), 0.0);
    let hinge = |a, b| RevoluteJointDef::new(a, b, Vec2::new(0.0, 0.5), Vec2::new(0.0, -0.5));
    world
        .create_revolute_joint(&hinge(bodies[0], bodies[1]))
        .unwrap();
    world
        .create_revolute_joint(&hinge(bodies[1], bodies[2]))
        .unwrap();
    world.step(DT).unwrap();
    assert_eq!(world.counters().direct_joint_rows, 4);
    // Closing a loop sends the whole component back to Gauss–Seidel.
    world
        .create_revolute_joint(&hinge(bodies[2], bodies[0]))
        .unwrap();
    world.step(DT).unwrap();
    assert_eq!(world.counters().direct_joint_rows, 0);
    assert_eq!(world.counters().joint_rows, 6);
    settings.solver.direct_joints = false;
    let (mut off, bodies) = boxes_on_ground(settings, 0.0);
    off.create_revolute_joint(&hinge(bodies[0], bodies[1]))
        .unwrap();
    off.step(DT).unwrap();
    assert_eq!(off.counters().direct_joint_rows, 0);
    assert_eq!(off.counters().joint_rows, 2);
}

#[test]
fn resting_stack_falls_asleep_and_costs_no_solver_work() {
    let (mut world, bodies) = boxes_on_ground(WorldDef::default(), 0.0);
    for _ in 0..240 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 5, "the stack did not sleep");
    let c = world.counters();
    assert_eq!((c.awake_bodies, c.contacts, c.pairs_tested), (0, 0, 0));
    for b in &bodies {
        assert!(world.is_sleeping(*b).unwrap());
        assert_eq!(world.linear_velocity(*b).unwrap(), Vec2::ZERO);
    }
}

#[test]
fn api_change_wakes_the_whole_island() {
    let (mut world, bodies) = boxes_on_ground(WorldDef::default(), 0.0);
    for _ in 0..240 {
        world.step(DT).unwrap();
    }
    assert!(world.is_sleeping(bodies[4]).unwrap());
    world
        .apply_linear_impulse(
            bodies[4],
            Vec2::new(0.1, 0.0),
            world.center_of_mass(bodies[4]).unwrap(),
        )
        .unwrap();
    for b in &bodies {
        assert!(
            !world.is_sleeping(*b).unwrap(),
            "island member still asleep"
        );
    }
    assert!(world.linear_velocity(bodies[4]).unwrap().x > 0.0);
}

#[test]
fn contact_from_an_awake_body_wakes_the_island() {
    let (mut world, bodies) = boxes_on_ground(WorldDef::default(), 0.0);
    for _ in 0..240 {
        world.step(DT).unwrap();
    }
    assert_eq!(world.sleeping_body_count(), 5);
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(0.0, 8.0)))
        .unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.25).unwrap(),
        )
        .unwrap();
    let mut woke = false;
    for _ in 0..120 {
        world.step(DT).unwrap();
        woke |= !world.is_sleeping(bodies[0]).unwrap();
    }
    assert!(woke, "the falling ball did not wake the stack");
}

#[test]
fn joint_change_wakes_both_bodies() {
    let (mut world, bodies) = boxes_on_ground(WorldDef::default(), 0.0);
    let j = world
        .create_revolute_joint(&RevoluteJointDef::new(
            bodies[3],
            bodies[4],
            Vec2::new(0.0, 0.5),
            Vec2::new(0.0, -0.5),
        ))
        .unwrap();
    for _ in 0..240 {
        world.step(DT).unwrap();
    }
    assert!(world.is_sleeping(bodies[4]).unwrap());
    world.enable_joint_motor(j, true).unwrap();
    assert!(!world.is_sleeping(bodies[3]).unwrap() && !world.is_sleeping(bodies[4]).unwrap());
}

#[cfg(feature = "portals")]
#[test]
fn portal_crossing_keeps_bodies_awake() {
    let (mut scene, _) = janus2d_testbed::scenes::portal_drop(&WorldDef::default());
    let mut asleep_while_crossing = false;
    for _ in 0..120 {
        scene.world.step(DT).unwrap();
        if scene.world.crossing_count() > 0 {
            let clone = scene.world.clone_of(scene.probe).unwrap();
            asleep_while_crossing |= scene.world.is_sleeping(scene.probe).unwrap()
                || scene.world.is_sleeping(clone).unwrap();
        }
    }
    assert!(!asleep_while_crossing);
}

#[test]
fn bodies_created_asleep_cost_nothing_until_touched() {
    let mut world = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..Default::default()
    })
    .unwrap();
    let asleep: Vec<BodyHandle> = (0..10)
        .map(|i| {
            let def = BodyDef {
                awake: false,
                ..BodyDef::dynamic(Vec2::new(i as Real * 0.4, 0.0))
            };
            let b = world.create_body(&def).unwrap();
            world
                .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.2, 0.2))
                .unwrap();
            b
        })
        .collect();
    world.step(DT).unwrap();
    assert_eq!(world.sleeping_body_count(), 10);
    assert_eq!(
        world.counters().pairs_tested,
        0,
        "touching sleeping boxes were tested"
    );
    // The contacts found between them sleep too: no step visits them
    // (they stayed in the awake list before, read at every step).
    assert_eq!(world.contact_count(), 9, "neighbours' fat boxes overlap");
    assert_eq!(world.awake_contact_count(), 0);
    let ball = world
        .create_body(&BodyDef::dynamic(Vec2::new(-3.0, 0.0)).with_velocity(Vec2::new(10.0, 0.0)))
        .unwrap();
    world
        .create_shape(
            ball,
            &ShapeDef::default(),
            Circle::new(Vec2::ZERO, 0.2).unwrap(),
        )
        .unwrap();
    for _ in 0..60 {
        world.step(DT).unwrap();
    }
    assert!(
        !world.is_sleeping(asleep[0]).unwrap(),
        "the hit box is still asleep"
    );
    assert!(world.linear_velocity(asleep[0]).unwrap().x > 0.0);
}

/// Boxes dropped from 1 to 3 m onto the ground beside a sensor, every
/// shape made with `sd`.
fn dropped_boxes(def: WorldDef, sd: &ShapeDef) -> World {
    let mut world = World::new(def).unwrap();
    let g = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, -1.0)))
        .unwrap();
    world
        .create_shape(g, sd, Polygon::make_box(20.0, 1.0))
        .unwrap();
    let zone = world
        .create_body(&BodyDef::fixed(Vec2::new(0.0, 1.0)))
        .unwrap();
    world
        .create_shape(zone, &sd.clone().sensor(), Polygon::make_box(3.0, 1.0))
        .unwrap();
    for i in 0..5 {
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(
                1.5 * i as Real - 3.0,
                1.0 + 0.5 * i as Real,
            )))
            .unwrap();
        world
            .create_shape(b, sd, Polygon::make_box(0.5, 0.5))
            .unwrap();
    }
    world
}

#[test]
fn events_switched_off_everywhere_gather_nothing() {
    let def = WorldDef {
        sleep: SleepSettings {
            enabled: false,
            ..Default::default()
        },
        ..Default::default()
    };
    let off = ShapeDef::default()
        .with_contact_events(false)
        .with_sensor_events(false)
        .with_hit_events(false);
    let mut world = dropped_boxes(def.clone(), &off);
    let mut contacts = 0;
    for k in 0..90 {
        world.step(DT).unwrap();
        contacts += world.counters().contacts;
        // No gathering read a point, a contact or a body.
        assert_eq!(world.event_work(), EventWork::default(), "step {k}");
        let e = &world.events().collision;
        assert!(
            e.contact_begin.is_empty()
                && e.contact_end.is_empty()
                && e.sensor_begin.is_empty()
                && e.sensor_end.is_empty()
                && e.hits.is_empty()
                && e.forces.is_empty()
                && world.events().moves.is_empty(),
            "step {k}: {e:?}"
        );
    }
    println!("all events off: {contacts} contact constraints over 90 steps, event work 0");
    assert!(contacts > 0, "there were contacts to gather from");

    // Each switch turned on makes its gathering read, and only its own.
    let mut hits = dropped_boxes(def.clone(), &off.clone().with_hit_events(true));
    let mut forces = dropped_boxes(def.clone(), &off.clone().with_force_event_threshold(1.0));
    let mut moves = dropped_boxes(def.with_move_events(true), &off);
    let (mut hit_points, mut hit_events) = (0, 0);
    for _ in 0..90 {
        hits.step(DT).unwrap();
        forces.step(DT).unwrap();
        moves.step(DT).unwrap();
        let h = hits.event_work();
        hit_points += h.hit_points_read;
        hit_events += hits.events().collision.hits.len();
        assert_eq!((h.force_contacts_read, h.move_bodies_read), (0, 0));
        let f = forces.event_work();
        assert_eq!(f.force_contacts_read, forces.contacts().count());
        assert_eq!((f.hit_points_read, f.move_bodies_read), (0, 0));
        let m = moves.event_work();
        assert_eq!(m.move_bodies_read, 5, "the five awake boxes");
        assert_eq!((m.hit_points_read, m.force_contacts_read), (0, 0));
    }
    println!("hit events on: {hit_points} approach points read, {hit_events} hit events");
    assert!(
        hit_points >= hit_events && hit_events >= 5,
        "each box lands once"
    );
}

/// The direct tree solve runs only where Gauss–Seidel would not hold:
/// a short free chain of like masses (a ragdoll's limb) is left to the
/// iterative rows; a mass spread at the ratio, a fixed end, or a path
/// longer than the step's sweeps (`2 × substeps` joints) sends it to the
/// tree (`SolverSettings::direct_free_tree_mass_ratio`).
#[test]
fn short_free_trees_of_like_masses_skip_the_tree_solve() {
    // A horizontal chain of `links` boxes in zero gravity, hinged end to
    // end; body 0 of mass `first_mass` (the rest 1 kg); pinned to a
    // static body if `pinned`. Returns the direct rows of one step.
    let direct_rows = |links: usize, first_mass: Real, pinned: bool, settings: WorldDef| {
        let mut world = World::new(WorldDef {
            gravity: Vec2::ZERO,
            ..settings
        })
        .unwrap();
        let mut bodies = Vec::new();
        for i in 0..links {
            let mass = if i == 0 { first_mass } else { 1.0 };
            let b = world
                .create_body(
                    &BodyDef::dynamic(Vec2::new(i as Real, 0.0)).with_mass(mass, 0.1 * mass),
                )
                .unwrap();
            bodies.push(b);
        }
        let hinge = |a, b| RevoluteJointDef::new(a, b, Vec2::new(0.5, 0.0), Vec2::new(-0.5, 0.0));
        for pair in bodies.windows(2) {
            world
                .create_revolute_joint(&hinge(pair[0], pair[1]))
                .unwrap();
        }
        if pinned {
            let pin = world
                .create_body(&BodyDef::fixed(Vec2::new(-1.0, 0.0)))
                .unwrap();
            world.create_revolute_joint(&hinge(pin, bodies[0])).unwrap();
        }
        world.step(DT).unwrap();
        world.counters().direct_joint_rows
    };
    let default = WorldDef::default;
    assert_eq!(default().solver.substeps, 4, "8 sweeps a step");
    // 6 links, a path of 5 joints, masses 1 … 9.9: Gauss–Seidel.
    assert_eq!(direct_rows(6, 9.9, false, default()), 0);
    // A spread of 10 reaches the default ratio.
    assert_eq!(direct_rows(6, 10.0, false, default()), 10);
    // A fixed end: always the tree.
    assert_eq!(direct_rows(6, 1.0, true, default()), 12);
    // A path of 8 joints is within the sweeps, 9 is not.
    assert_eq!(direct_rows(9, 1.0, false, default()), 0);
    assert_eq!(direct_rows(10, 1.0, false, default()), 18);
    // At 2 substeps (4 sweeps) the 6-link chain takes the tree.
    let mut two = default();
    two.solver.substeps = 2;
    assert_eq!(direct_rows(6, 1.0, false, two), 10);
    // Ratio 0: every tree; ∞: no short free tree.
    let mut every = default();
    every.solver.direct_free_tree_mass_ratio = 0.0;
    assert_eq!(direct_rows(6, 1.0, false, every), 10);
    let mut none = default();
    none.solver.direct_free_tree_mass_ratio = Real::INFINITY;
    assert_eq!(direct_rows(6, 1e6, false, none), 0);
    // NaN is refused at the boundary.
    let mut bad = default();
    bad.solver.direct_free_tree_mass_ratio = Real::NAN;
    assert!(World::new(bad).is_err());
}

/// Guards the solver profile against counting the substep loop twice: the
/// stages are timed inside the step, so they add up to no more than it,
/// and with the timers off the solver's stages read zero.
#[test]
fn stage_times_add_up_to_no_more_than_the_step() {
    let mut scene = janus2d_testbed::scenes::joint_grid(&WorldDef::default(), 30);
    let world = &mut scene.world;
    for _ in 0..5 {
        world.step(DT).unwrap();
        let p = world.profile();
        let s = &p.solver;
        let solver = s.prepare + s.integrate + s.warm_start + s.solve + s.relax;
        let stages = p.broadphase + p.narrowphase + p.portals + p.continuous + p.sleep;
        assert!(solver > 0.0, "the solver stages were not timed");
        assert!(
            stages + solver + s.restitution + s.finalize <= p.total,
            "stages {} + solver {solver} exceed the step {}",
            stages + s.restitution + s.finalize,
            p.total
        );
    }
    world.set_profiling(false);
    world.step(DT).unwrap();
    let s = &world.profile().solver;
    assert_eq!(
        (s.prepare, s.integrate, s.warm_start, s.solve, s.relax),
        (0.0, 0.0, 0.0, 0.0, 0.0)
    );
    assert!(world.profile().total > 0.0);
}

/// Guards the joint base's copies of its definition (row count, motor
/// switch, threshold switch; kept so the step's end and contact building
/// read no boxed definition): each setter and `set_joint_def` updates them
/// at once, so the step's row counter, the driven flag and the joint
/// events follow every change.
#[test]
fn joint_counters_follow_every_definition_change() {
    // The bob hangs 1 m below the pin at rest: the joint carries 10 N.
    let (mut world, _, j) = crate::joint_api::pendulum(|_| {});
    world.step(DT).unwrap();
    assert_eq!(world.counters().joint_rows, 2);
    world.set_joint_limits(j, -0.1, 0.1).unwrap();
    world.enable_joint_limit(j, true).unwrap();
    world.step(DT).unwrap();
    assert_eq!(world.counters().joint_rows, 4);
    assert!(!world.joint(j).unwrap().is_driven());
    world.set_joint_max_motor_torque(j, 5.0).unwrap();
    world.enable_joint_motor(j, true).unwrap();
    // Before any step: contact building reads the flag first.
    assert!(world.joint(j).unwrap().is_driven());
    world.step(DT).unwrap();
    assert_eq!(world.counters().joint_rows, 5);
    assert!(world.events().joints.is_empty());
    // A threshold below the hanging bob's 10 N: one event next step.
    let mut def = world.joint(j).unwrap().def();
    def.base_mut().force_threshold = 1.0;
    world.set_joint_def(j, def).unwrap();
    world.step(DT).unwrap();
    assert_eq!(world.events().joints.len(), 1);
    world.set_joint_enabled(j, false).unwrap();
    world.step(DT).unwrap();
    assert_eq!(world.counters().joint_rows, 0);
}
