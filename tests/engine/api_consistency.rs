//! API consistency: checked constructors return `Result` (the panicking
//! box makers are documented conveniences), every `is_*` getter returns
//! `Result<bool, WorldError>`, and the definitions' builders set what the
//! world then reports.

use janus2d::base::geometry::GeometryError;
use janus2d::prelude::*;
use janus2d::world::Filter;

#[test]
fn checked_box_constructors_return_typed_errors() {
    assert_eq!(
        Polygon::try_make_box(Real::NAN, 1.0),
        Err(GeometryError::NonFinite)
    );
    assert_eq!(
        Polygon::try_make_box(0.0, 1.0),
        Err(GeometryError::DegeneratePolygon)
    );
    assert_eq!(
        Polygon::try_make_box(1.0, -2.0),
        Err(GeometryError::DegeneratePolygon)
    );
    assert_eq!(
        Polygon::try_make_rounded_box(1.0, 1.0, -0.1),
        Err(GeometryError::NegativeRadius)
    );
    assert_eq!(
        Polygon::try_make_offset_box(1.0, 1.0, Vec2::new(Real::INFINITY, 0.0), 0.0),
        Err(GeometryError::NonFinite)
    );
    // The general one, public: a 2 × 1 box at (3, 0) turned 90°, rounded 0.1.
    let p = Polygon::try_make_offset_rounded_box(
        1.0,
        0.5,
        Vec2::new(3.0, 0.0),
        janus2d::base::math::PI / 2.0,
        0.1,
    )
    .unwrap();
    assert_eq!(p.count, 4);
    assert_eq!(p.radius, 0.1);
    let top = p.vertices[..4]
        .iter()
        .map(|v| v.y)
        .fold(Real::NEG_INFINITY, Real::max);
    assert!(
        (top - 1.0).abs() < 1e-5,
        "turned: the long side is vertical"
    );
    // The checked and the convenience constructors agree.
    assert_eq!(
        Polygon::try_make_box(0.5, 2.0).unwrap(),
        Polygon::make_box(0.5, 2.0)
    );
    // The convenience panics on bad input, as documented.
    assert!(std::panic::catch_unwind(|| Polygon::make_box(-1.0, 1.0)).is_err());
    // The other constructors were Result already.
    assert!(Circle::new(Vec2::ZERO, -1.0).is_err());
    assert!(Capsule::new(Vec2::ZERO, Vec2::X, Real::NAN).is_err());
    assert!(Segment::new(Vec2::ZERO, Vec2::ZERO).is_err());
}

#[test]
fn every_is_getter_returns_a_result_and_a_stale_handle_is_an_error() {
    let mut w = World::new(WorldDef::default()).unwrap();
    let b = w.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
    let gone = w.create_body(&BodyDef::dynamic(Vec2::ONE)).unwrap();
    w.destroy_body(gone).unwrap();
    type IsGetter = fn(&World, BodyHandle) -> Result<bool, WorldError>;
    let getters: [IsGetter; 4] = [
        World::is_awake,
        World::is_sleeping,
        World::is_bullet,
        World::is_fixed_rotation,
    ];
    let live: Vec<bool> = getters.iter().map(|g| g(&w, b).unwrap()).collect();
    assert_eq!(live, vec![true, false, false, false]);
    for g in getters {
        assert_eq!(g(&w, gone), Err(WorldError::StaleBody));
    }
}

#[test]
fn definition_builders_set_what_the_world_reports() {
    let mut w = World::new(
        WorldDef::default()
            .with_gravity(Vec2::new(0.0, -9.81))
            .with_hit_event_threshold(0.5),
    )
    .unwrap();
    assert_eq!(w.gravity(), Vec2::new(0.0, -9.81));
    let b = w
        .create_body(
            &BodyDef::dynamic(Vec2::ZERO)
                .with_position(Vec2::new(1.0, 2.0))
                .with_linear_damping(0.25)
                .with_angular_damping(0.5)
                .with_gravity_scale(0.0)
                .with_fixed_rotation(true)
                .with_enable_sleep(false)
                .with_sleep_threshold(Some(0.02))
                .with_user_data(9),
        )
        .unwrap();
    assert_eq!(w.position(b).unwrap(), Vec2::new(1.0, 2.0));
    assert_eq!(w.linear_damping(b).unwrap(), 0.25);
    assert_eq!(w.angular_damping(b).unwrap(), 0.5);
    assert_eq!(w.gravity_scale(b).unwrap(), 0.0);
    assert!(w.is_fixed_rotation(b).unwrap());
    assert!(!w.body_enable_sleep(b).unwrap());
    assert_eq!(w.body_sleep_threshold(b).unwrap(), Some(0.02));
    assert_eq!(w.body_user_data(b).unwrap(), 9);
    let asleep = w
        .create_body(&BodyDef::dynamic(Vec2::new(5.0, 0.0)).with_awake(false))
        .unwrap();
    w.step(1.0 / 60.0).unwrap();
    assert!(w.is_sleeping(asleep).unwrap());

    let s = w
        .create_shape(
            b,
            &ShapeDef::default()
                .sensor()
                .with_hit_events(true)
                .with_user_data(7)
                .with_filter(Filter::new(0b10, 0b11).with_group(2)),
            Circle::new(Vec2::ZERO, 0.5).unwrap(),
        )
        .unwrap();
    let def = &w.shape(s).unwrap().def;
    assert!(def.is_sensor && def.enable_hit_events);
    assert_eq!(def.user_data, 7);
    assert_eq!(
        def.filter,
        Filter {
            category_bits: 2,
            mask_bits: 3,
            group_index: 2
        }
    );
    assert!(!ShapeDef::default().sensor().with_sensor(false).is_sensor);
    let f = QueryFilter::default().with_category(0b10).with_mask(0b1);
    assert_eq!((f.category_bits, f.mask_bits), (2, 1));
}

#[cfg(feature = "portals")]
#[test]
fn portal_definitions_have_constructors() {
    use janus2d::world::{PortalDef, PortalPairDef};
    let mut w = World::new(WorldDef::default()).unwrap();
    let a = w.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    let b = w
        .create_body(&BodyDef::fixed(Vec2::new(10.0, 0.0)))
        .unwrap();
    let pa = PortalDef::new(a, Vec2::new(0.0, 0.5), Vec2::Y, 1.0);
    assert_eq!(
        pa,
        PortalDef {
            body: a,
            anchor: Vec2::new(0.0, 0.5),
            direction: Vec2::Y,
            half_width: 1.0
        }
    );
    let pair = w
        .create_portal_pair(&PortalPairDef::new(
            pa,
            PortalDef::new(b, Vec2::ZERO, Vec2::Y, 2.0),
        ))
        .unwrap();
    assert_eq!(w.portal_map(pair).unwrap().eta, 2.0);
}
