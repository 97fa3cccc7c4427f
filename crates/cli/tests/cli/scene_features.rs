//! Issue 32's definition fields in scene files: motion locks, the enabled
//! flag, shape offsets, chain objects with per-segment surface materials
//! (and each shape material key). A hand-written file using every one
//! survives serialise → parse unchanged, and builds the same world as the
//! same definitions given to the API directly: the same state hash after
//! every step of 120.

use janus2d_cli::scene_file::{self, ErrorKind};
use janus2d_core::body::{BodyDef, MotionLocks};
use janus2d_core::geometry::{Capsule, Circle, Polygon, Shape};
use janus2d_core::material::CombineRule;
use janus2d_core::math::{Real, Vec2};
use janus2d_world::{ChainDef, Filter, ShapeDef, SurfaceMaterial, World, WorldDef};

const FILE: &str = r#"{
  "name": "issue 32 fields",
  "settings": { "dt": 0.016666666666666666 },
  "bodies": [
    { "id": "ground", "type": "static",
      "chains": [ { "points": [[8, 0], [2, 0], [-2, 0], [-8, 0]], "user_data": 5,
                    "filter": { "category": 2, "mask": 65535, "group": 0 },
                    "hit_events": true,
                    "materials": [
                      { "friction": 0.2, "material": 7 },
                      { "friction": 0.9, "rolling_resistance": 0.3, "friction_combine": "max" },
                      { "tangent_speed": 1.5, "restitution": 0.2, "restitution_combine": "min", "material": 9 } ] } ] },
    { "id": "ball", "position": [5, 0.6], "linear_velocity": [-3, 0],
      "shapes": [ { "geometry": { "circle": { "radius": 0.5 } }, "rolling_resistance": 0.1,
                    "friction_combine": "average", "material": 3 } ] },
    { "id": "slider", "position": [-5, 3], "motion_locks": { "x": true, "rotation": true },
      "shapes": [ { "geometry": { "box": { "half": [0.4, 0.3] } },
                    "offset": { "position": [0.3, 0], "angle": 0.4 } } ] },
    { "id": "off", "position": [0, 4], "enabled": false,
      "shapes": [ { "geometry": { "capsule": { "a": [-0.5, 0], "b": [0.5, 0], "radius": 0.2 } },
                    "offset": { "position": [0, 0.5] } } ] },
    { "id": "hover", "position": [-1, 1.5], "linear_velocity": [2, 0], "motion_locks": { "y": true },
      "shapes": [ { "geometry": { "box": { "half": [0.25, 0.25] } }, "tangent_speed": 0.5,
                    "restitution_combine": "max" } ] }
  ]
}"#;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

/// The file's world built through the API, in the builder's order
/// (per body: create, shapes, chains, then disable).
fn by_hand() -> World {
    let mut w = World::new(WorldDef::default()).unwrap();
    let ground = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let materials = vec![
        SurfaceMaterial::default()
            .with_friction(0.2)
            .with_material_id(7),
        SurfaceMaterial {
            friction_combine: CombineRule::Max,
            ..SurfaceMaterial::default()
                .with_friction(0.9)
                .with_rolling_resistance(0.3)
        },
        SurfaceMaterial {
            restitution_combine: CombineRule::Min,
            ..SurfaceMaterial::default()
                .with_tangent_speed(1.5)
                .with_restitution(0.2)
                .with_material_id(9)
        },
    ];
    let mut chain = ChainDef::new(vec![v(8.0, 0.0), v(2.0, 0.0), v(-2.0, 0.0), v(-8.0, 0.0)])
        .with_segment_materials(materials)
        .with_filter(Filter::new(2, 65535))
        .with_user_data(5);
    chain.enable_hit_events = true;
    w.create_chain(ground, &chain).unwrap();

    let ball = w
        .create_body(&BodyDef {
            linear_velocity: v(-3.0, 0.0),
            ..BodyDef::dynamic(v(5.0, 0.6))
        })
        .unwrap();
    let sd = ShapeDef {
        rolling_resistance: 0.1,
        friction_combine: CombineRule::Average,
        user_material_id: 3,
        ..ShapeDef::default()
    };
    w.create_shape(ball, &sd, Circle::new(Vec2::ZERO, 0.5).unwrap())
        .unwrap();

    let locks = MotionLocks {
        linear_x: true,
        linear_y: false,
        angular: true,
    };
    let slider = w
        .create_body(&BodyDef::dynamic(v(-5.0, 3.0)).with_motion_locks(locks))
        .unwrap();
    let sd = ShapeDef::default().with_offset(v(0.3, 0.0), 0.4);
    w.create_shape(slider, &sd, Polygon::make_box(0.4, 0.3))
        .unwrap();

    let off = w.create_body(&BodyDef::dynamic(v(0.0, 4.0))).unwrap();
    let sd = ShapeDef::default().with_offset(v(0.0, 0.5), 0.0);
    let capsule = Capsule::new(v(-0.5, 0.0), v(0.5, 0.0), 0.2).unwrap();
    w.create_shape(off, &sd, capsule).unwrap();
    w.set_body_enabled(off, false).unwrap();

    let hover = w
        .create_body(&BodyDef {
            linear_velocity: v(2.0, 0.0),
            ..BodyDef::dynamic(v(-1.0, 1.5)).with_motion_locks(MotionLocks::Y)
        })
        .unwrap();
    let sd = ShapeDef {
        tangent_speed: 0.5,
        restitution_combine: CombineRule::Max,
        ..ShapeDef::default()
    };
    w.create_shape(hover, &sd, Polygon::make_box(0.25, 0.25))
        .unwrap();
    w
}

#[test]
fn every_issue_32_field_round_trips_and_builds_the_api_world() {
    let file = scene_file::parse(FILE, "issue32.json").unwrap();
    let json = file.to_json();
    let back = scene_file::parse(&json, "again.json").unwrap();
    assert_eq!(back, file, "serialise → parse is the identity");
    for key in [
        "\"motion_locks\"",
        "\"enabled\": false",
        "\"offset\"",
        "\"chains\"",
        "\"materials\"",
        "\"rolling_resistance\"",
        "\"tangent_speed\"",
        "\"restitution_combine\"",
    ] {
        assert!(json.contains(key), "the written file keeps {key}");
    }

    let (_, built) = scene_file::load(&json, "again.json").unwrap();
    let mut from_file = built.world;
    let mut api = by_hand();
    assert_eq!(from_file.state_hash(), api.state_hash(), "as built");
    assert_eq!(from_file.chain_count(), 1);
    assert_eq!(from_file.shape_count(), 3 + 4);

    // The file's values reached the world.
    let chain = from_file.chain_handles()[0];
    assert_eq!(from_file.chain_user_data(chain), Ok(5));
    let segments = from_file.chain_segments(chain).unwrap().to_vec();
    let def = |s| from_file.shape(s).unwrap().def.clone();
    assert_eq!(
        (def(segments[0]).friction, def(segments[0]).user_material_id),
        (0.2, 7)
    );
    assert_eq!(def(segments[1]).friction_combine, CombineRule::Max);
    assert_eq!(def(segments[2]).tangent_speed, 1.5);
    assert_eq!(def(segments[2]).filter.category_bits, 2);
    let [ball, slider, off, hover] = [1, 2, 3, 4].map(|i| built.bodies[i]);
    assert_eq!(from_file.is_body_enabled(off), Ok(false));
    assert_eq!(
        from_file.motion_locks(slider).unwrap(),
        MotionLocks {
            linear_x: true,
            linear_y: false,
            angular: true
        }
    );
    let slider_shape = from_file.body_shapes(slider).unwrap()[0];
    let Shape::Polygon(p) = from_file.shape(slider_shape).unwrap().geometry else {
        panic!("a box");
    };
    let centroid = p.centroid;
    assert!(
        (centroid.x - 0.3).abs() < 1e-6 && centroid.y.abs() < 1e-6,
        "the offset moved the box: centroid {centroid:?}"
    );

    let start_slider = from_file.position(slider).unwrap();
    let start_hover = from_file.position(hover).unwrap();
    let start_off = from_file.position(off).unwrap();
    for step in 0..120 {
        from_file.step(built.dt).unwrap();
        api.step(built.dt).unwrap();
        assert_eq!(
            from_file.state_hash(),
            api.state_hash(),
            "step {step}: the file and the API give bit-identical states"
        );
    }
    assert_eq!(from_file.validate(), Ok(()));
    // The fields acted: locked axes held, the disabled body stayed put,
    // the ball rolled along the chain.
    let slider_now = from_file.position(slider).unwrap();
    assert_eq!(slider_now.x, start_slider.x, "x lock");
    assert!(
        slider_now.y < start_slider.y - 1.0,
        "it fell: {slider_now:?}"
    );
    assert_eq!(from_file.angle(slider), Ok(0.0), "rotation lock");
    assert_eq!(
        from_file.position(hover).unwrap().y,
        start_hover.y,
        "y lock"
    );
    assert_eq!(from_file.position(off), Ok(start_off), "disabled");
    let ball_now = from_file.position(ball).unwrap();
    assert!(
        ball_now.x < 3.0 && (ball_now.y - 0.5).abs() < 0.05,
        "the ball rolls 2 m or more on the chain: {ball_now:?}"
    );
}

#[test]
fn bad_chains_and_offsets_name_their_field() {
    let one_point = FILE.replace("[[8, 0], [2, 0], [-2, 0], [-8, 0]]", "[[8, 0]]");
    let e = scene_file::load(&one_point, "bad.json").err().unwrap();
    assert_eq!(e.kind, ErrorKind::Invalid);
    assert_eq!(e.field, "bodies[0].chains[0]");
    let two_materials = FILE.replace("{ \"friction\": 0.2, \"material\": 7 },", "");
    let e = scene_file::load(&two_materials, "bad.json").err().unwrap();
    assert_eq!(e.field, "bodies[0].chains[0]");
    assert!(e.message.contains("materials"), "{}", e.message);
    let far = FILE.replace(
        "\"offset\": { \"position\": [0, 0.5] }",
        "\"offset\": { \"position\": [0, 1e9] }",
    );
    let e = scene_file::load(&far, "bad.json").err().unwrap();
    assert_eq!(e.field, "bodies[3].shapes[0]");
    let typo = FILE.replace("\"rotation\": true", "\"spin\": true");
    let e = scene_file::load(&typo, "bad.json").err().unwrap();
    assert_eq!(e.kind, ErrorKind::Data);
    assert!(e.field.starts_with("bodies[2].motion_locks"), "{}", e.field);
}
