//! Joints of every kind in scene files: the export round trip of the
//! built-in joint scenes (one of them, `joint_zoo`, holds every kind), a
//! hand-written file with every kind and the typed errors of bad joints.

use janus2d_cli::scene_file::{self, ErrorKind, JointKindFile, SceneFile};
use janus2d_cli::{catalog, runner};
use janus2d_constraints::{
    DistanceJoint, JointKind, MotorJoint, MouseJoint, PrismaticJoint, RevoluteJoint, WheelJoint,
};

/// A definition's debug text without the worlds' tags in its body handles
/// (`Handle(0v1@14)` → `Handle(0v1)`): two worlds, the same bodies.
fn without_world_tags(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        if c == '@' {
            while chars.peek().is_some_and(char::is_ascii_digit) {
                chars.next();
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// Every built-in joint scene written as a file and read back builds the
/// same world: the same state hash after 120 steps (the zoo's every kind,
/// the peers' weld, wheel, prismatic and distance scenes).
#[test]
fn every_joint_kind_round_trips_bit_identically() {
    let names: Vec<&str> = catalog::entries()
        .filter(|e| e.group == "joints")
        .map(|e| e.name)
        .collect();
    assert_eq!(
        names,
        [
            "weld_cantilever",
            "car",
            "elevator",
            "spring_bridge",
            "joint_zoo"
        ]
    );
    let mut kinds_seen = Vec::new();
    for name in &names {
        let desc = catalog::find(name).unwrap().build();
        let file = SceneFile::from_desc(&desc).unwrap();
        assert_eq!(
            file.joints.len(),
            desc.joints.len() + desc.extra_joints.len(),
            "{name}: every joint is written"
        );
        kinds_seen.extend(file.joints.iter().map(|j| j.kind));
        let json = file.to_json();
        let back = scene_file::parse(&json, name).unwrap();
        assert_eq!(back, file, "{name}: serialise → parse is the identity");
        let (_, built) = scene_file::load(&json, name).unwrap();
        let mut from_file = built.world;
        let mut builtin = runner::load(name).unwrap();
        assert_eq!(from_file.joint_count(), builtin.world().joint_count());
        for (a, b) in from_file
            .joint_handles()
            .iter()
            .zip(builtin.world().joint_handles())
        {
            assert_eq!(
                without_world_tags(&format!("{:?}", from_file.joint(*a).unwrap().def())),
                without_world_tags(&format!("{:?}", builtin.world().joint(*b).unwrap().def())),
                "{name}: the same joint definition"
            );
        }
        for step in 0..120 {
            from_file.step(built.dt).unwrap();
            builtin.step(step).unwrap();
        }
        assert_eq!(
            from_file.state_hash(),
            builtin.world().state_hash(),
            "{name}: the file builds the same world"
        );
    }
    kinds_seen.sort_by_key(|k| k.name());
    kinds_seen.dedup();
    assert_eq!(kinds_seen.len(), 8, "every kind exported: {kinds_seen:?}");
}

/// Every kind written by hand, world anchors and axes included.
const EVERY_KIND: &str = r#"{
  "bodies": [
    { "id": "ground", "type": "static",
      "shapes": [ { "geometry": { "box": { "half": [20, 0.5] } } } ] },
    { "id": "a", "position": [-6, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "b", "position": [-3, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "c", "position": [0, 3], "shapes": [ { "geometry": { "circle": { "radius": 0.5 } } } ] },
    { "id": "d", "position": [3, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "e", "position": [6, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "f", "position": [9, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "g", "position": [12, 3], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] },
    { "id": "h", "position": [12.3, 3.2], "shapes": [ { "geometry": { "box": { "half": [0.5, 0.5] } } } ] }
  ],
  "joints": [
    { "body_a": "ground", "body_b": "a", "anchor": [-6, 4],
      "limit": [-0.5, 0.5], "motor": { "speed": 1, "max_torque": 10 },
      "spring": { "hertz": 2, "damping_ratio": 0.5 }, "target_angle": 0.1,
      "force_threshold": 400, "user_data": 7 },
    { "type": "prismatic", "body_a": "ground", "body_b": "b", "anchor": [-3, 3],
      "axis": 1.5707963, "limit": [0, 2], "motor": { "speed": 1, "max_force": 500 },
      "target_translation": 1, "spring": { "hertz": 1, "damping_ratio": 1 } },
    { "type": "wheel", "body_a": "ground", "body_b": "c", "anchor": [0, 3], "axis": 1.5707963,
      "spring": { "hertz": 4, "damping_ratio": 0.7 }, "motor": { "speed": 5, "max_torque": 20 },
      "collide_connected": true },
    { "type": "weld", "body_a": "ground", "body_b": "d", "anchor": [3, 2.5],
      "linear_spring": { "hertz": 5, "damping_ratio": 0.7 }, "torque_threshold": 100,
      "constraint_hertz": 30, "constraint_damping_ratio": 1 },
    { "type": "distance", "body_a": "ground", "body_b": "e", "anchor_a": [6, 6], "anchor_b": [0, 0.5],
      "spring": { "hertz": 0, "damping_ratio": 0 }, "limit": [0, 3], "draw_scale": 2 },
    { "type": "motor", "body_a": "ground", "body_b": "f", "linear_offset": [9, 4],
      "angular_offset": 0.5, "max_force": 100, "max_torque": 20, "correction_factor": 0.2 },
    { "type": "mouse", "body_a": "ground", "body_b": "g", "anchor": [12, 3.4],
      "target": [12, 6], "max_force": 200, "spring": { "hertz": 3, "damping_ratio": 0.7 },
      "angular_spring": { "hertz": 1, "damping_ratio": 0.2 } },
    { "type": "filter", "body_a": "g", "body_b": "h" }
  ]
}"#;

#[test]
fn a_file_with_every_kind_builds_what_it_says() {
    let (file, built) = scene_file::load(EVERY_KIND, "every.json").unwrap();
    let w = &built.world;
    assert_eq!(file.joints.len(), 8);
    let h = w.joint_handles().to_vec();
    let kinds: Vec<JointKind> = h.iter().map(|&j| w.joint(j).unwrap().kind()).collect();
    assert_eq!(
        kinds,
        [
            JointKind::Revolute,
            JointKind::Prismatic,
            JointKind::Wheel,
            JointKind::Weld,
            JointKind::Distance,
            JointKind::Motor,
            JointKind::Mouse,
            JointKind::Filter
        ]
    );
    let r = &w.joint_of::<RevoluteJoint>(h[0]).unwrap().def();
    assert!(r.enable_limit && r.enable_motor && r.enable_spring);
    assert_eq!((r.max_motor_torque, r.target_angle), (10.0, 0.1));
    assert_eq!(r.base.force_threshold, 400.0);
    assert_eq!(w.joint_user_data(h[0]).unwrap(), 7);
    let p = &w.joint_of::<PrismaticJoint>(h[1]).unwrap().def();
    let axis = p.base.local_frame_a.axis();
    assert!(
        axis.x.abs() < 1e-6 && (axis.y - 1.0).abs() < 1e-6,
        "{axis:?}"
    );
    assert_eq!((p.max_motor_force, p.target_translation), (500.0, 1.0));
    let wh = &w.joint_of::<WheelJoint>(h[2]).unwrap().def();
    assert!(wh.enable_spring && wh.enable_motor && !wh.enable_limit);
    assert!(wh.base.collide_connected);
    let d = &w.joint_of::<DistanceJoint>(h[4]).unwrap().def();
    assert!(d.is_rope(), "{d:?}");
    assert!(
        (d.length - 2.5).abs() < 1e-6,
        "the anchors' distance: {}",
        d.length
    );
    assert_eq!(d.base.draw_scale, 2.0);
    let m = &w.joint_of::<MotorJoint>(h[5]).unwrap().def();
    assert_eq!(
        (m.max_force, m.max_torque, m.correction_factor),
        (100.0, 20.0, 0.2)
    );
    let mouse = &w.joint_of::<MouseJoint>(h[6]).unwrap().def();
    assert_eq!(
        (mouse.max_force, mouse.hertz, mouse.angular_hertz),
        (200.0, 3.0, 1.0)
    );
    assert!((mouse.base.local_frame_b.anchor.y - 0.4).abs() < 1e-6);
    // It runs.
    let mut world = built.world;
    for _ in 0..60 {
        world.step(built.dt).unwrap();
    }
    let g = world.position(built.bodies[7]).unwrap();
    assert!(g.y > 3.5, "the mouse joint lifts its box: {g:?}");
}

fn bad(from: &str, to: &str) -> scene_file::SceneFileError {
    let text = EVERY_KIND.replacen(from, to, 1);
    assert_ne!(text, EVERY_KIND, "the replacement applies");
    match scene_file::load(&text, "bad.json") {
        Err(e) => e,
        Ok(_) => panic!("`{to}` should be refused"),
    }
}

#[test]
fn bad_joints_name_the_field() {
    // An unknown type.
    let e = bad("\"type\": \"weld\"", "\"type\": \"glue\"");
    assert_eq!(
        (e.kind, e.field.as_str()),
        (ErrorKind::Data, "joints[3].type")
    );
    // A key the kind does not use.
    let e = bad(
        "\"type\": \"weld\", \"body_a\": \"ground\", \"body_b\": \"d\",",
        "\"type\": \"weld\", \"body_a\": \"ground\", \"body_b\": \"d\", \"limit\": [0, 1],",
    );
    assert_eq!(
        (e.kind, e.field.as_str()),
        (ErrorKind::Invalid, "joints[3].limit")
    );
    assert!(e.message.contains("weld"), "{e}");
    assert!(e.line > 0);
    // A linear motor given a torque.
    let e = bad("\"max_force\": 500 }", "\"max_torque\": 500 }");
    assert_eq!(e.field, "joints[1].motor.max_torque");
    // An angular motor without its torque.
    let e = bad("\"speed\": 5, \"max_torque\": 20", "\"speed\": 5");
    assert_eq!(e.field, "joints[2].motor");
    // Limits the wrong way round.
    let e = bad("\"limit\": [0, 2]", "\"limit\": [2, 0]");
    assert_eq!(e.field, "joints[1].limit");
    // A negative cap, threshold or spring.
    let e = bad("\"max_force\": 100", "\"max_force\": -100");
    assert_eq!(e.field, "joints[5].max_force");
    let e = bad("\"force_threshold\": 400", "\"force_threshold\": -1");
    assert_eq!(e.field, "joints[0].force_threshold");
    let e = bad("{ \"hertz\": 4,", "{ \"hertz\": -4,");
    assert_eq!(e.field, "joints[2].spring");
    // An axis and frame angles together.
    let e = bad(
        "\"axis\": 1.5707963, \"limit\"",
        "\"axis\": 1, \"angle_a\": 1, \"limit\"",
    );
    assert_eq!(e.field, "joints[1].axis");
    // No anchor for a kind that needs one.
    let e = bad("\"anchor\": [0, 3], ", "");
    assert_eq!(e.field, "joints[2]");
    // A mouse joint without its force cap.
    let e = bad("\"max_force\": 200, ", "");
    assert_eq!(e.field, "joints[6]");
    // The engine refuses the rest: a joint on one body, a zero length.
    let e = bad(
        "\"type\": \"filter\", \"body_a\": \"g\"",
        "\"type\": \"filter\", \"body_a\": \"h\"",
    );
    assert_eq!(
        (e.kind, e.field.as_str()),
        (ErrorKind::Invalid, "joints[7]")
    );
    assert!(e.message.starts_with("filter joint"), "{e}");
    let e = bad("\"limit\": [0, 3]", "\"length\": 0");
    assert_eq!(e.field, "joints[4]");
    // Every error names the file and the field when shown.
    assert!(e.to_string().contains("joints[4]"), "{e}");
    // The kinds' names are the file's.
    assert_eq!(JointKindFile::Mouse.name(), "mouse");
}
