//! Scene queries on `World`: rays, shape casts, overlaps, distances, filters,
//! callbacks, typed errors and line of sight through portals.

use janus2d::base::geometry::Aabb;
use janus2d::prelude::*;
use janus2d::world::query::QueryProblem;

#[path = "../../examples/picking.rs"]
#[allow(dead_code)]
mod picking;

fn v(x: Real, y: Real) -> Vec2 {
    Vec2::new(x, y)
}

fn world() -> World {
    World::new(WorldDef::default()).unwrap()
}

fn fixed_box(world: &mut World, center: Vec2, hx: Real, hy: Real, def: &ShapeDef) -> BodyHandle {
    let b = world.create_body(&BodyDef::fixed(center)).unwrap();
    world
        .create_shape(b, def, Polygon::make_box(hx, hy))
        .unwrap();
    b
}

fn ball(world: &mut World, center: Vec2, r: Real) -> BodyHandle {
    let b = world.create_body(&BodyDef::dynamic(center)).unwrap();
    world
        .create_shape(b, &ShapeDef::default(), Circle::new(Vec2::ZERO, r).unwrap())
        .unwrap();
    b
}

/// Five unit boxes centred at x = 2, 4, …, 10 on the x axis.
fn box_row(world: &mut World) -> Vec<BodyHandle> {
    (1..=5)
        .map(|k| {
            fixed_box(
                world,
                v(2.0 * k as Real, 0.0),
                0.5,
                0.5,
                &ShapeDef::default(),
            )
        })
        .collect()
}

fn all_hits(world: &World, origin: Vec2, translation: Vec2, filter: &QueryFilter) -> Vec<RayHit> {
    let mut hits = Vec::new();
    world
        .cast_ray_with(origin, translation, filter, |h| {
            hits.push(*h);
            1.0
        })
        .unwrap();
    hits
}

#[test]
fn picking_finds_the_body_under_a_point_and_not_beside_a_ball() {
    let mut w = world();
    let crate_ = fixed_box(&mut w, v(0.0, 0.0), 1.0, 0.5, &ShapeDef::default());
    let b = ball(&mut w, v(4.0, 0.0), 0.5);
    let pick = |w: &World, p: Vec2| {
        let mut found = Vec::new();
        w.overlap_point(p, &QueryFilter::default(), |o| {
            found.push(o.body);
            true
        })
        .unwrap();
        found
    };
    assert_eq!(pick(&w, v(0.9, 0.4)), vec![crate_]);
    assert_eq!(pick(&w, v(4.3, 0.3)), vec![b]);
    // 1 cm outside the ball: inside its fat box, not in the ball.
    let outside = v(4.0 + 0.51, 0.0);
    assert!(w.bodies_in_box(&Aabb::new(outside, outside)).contains(&b));
    assert!(pick(&w, outside).is_empty());
    assert!(pick(&w, v(2.0, 0.0)).is_empty());
}

#[test]
fn closest_ray_hit_through_a_box_row_is_the_first_face() {
    let mut w = world();
    let row = box_row(&mut w);
    let hit = w
        .cast_ray_closest(v(0.0, 0.1), v(20.0, 0.0), &QueryFilter::default())
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, row[0]);
    assert!((hit.fraction - 1.5 / 20.0).abs() < 1e-6);
    assert!((hit.point - v(1.5, 0.1)).length() < 1e-5);
    assert!((hit.normal - v(-1.0, 0.0)).length() < 1e-6);
    assert_eq!(hit.portal_hops, 0);
    // Every hit, nearest first: the near faces at x = 2k − 0.5.
    let hits = all_hits(&w, v(0.0, 0.1), v(20.0, 0.0), &QueryFilter::default());
    assert_eq!(hits.len(), 5);
    for (k, h) in hits.iter().enumerate() {
        assert_eq!(h.body, row[k]);
        let expect = (2.0 * (k + 1) as Real - 0.5) / 20.0;
        assert!((h.fraction - expect).abs() < 1e-6, "{k}: {h:?}");
    }
    // A ray that stops short of the row hits nothing.
    let none = w
        .cast_ray_closest(v(0.0, 0.1), v(1.4, 0.0), &QueryFilter::default())
        .unwrap();
    assert!(none.is_none());
}

#[test]
fn filter_excludes_a_category_and_a_body() {
    let mut w = world();
    let hidden = ShapeDef {
        filter: Filter {
            category_bits: 0b10,
            ..Filter::default()
        },
        ..ShapeDef::default()
    };
    let glass = fixed_box(&mut w, v(2.0, 0.0), 0.5, 0.5, &hidden);
    let wall = fixed_box(&mut w, v(4.0, 0.0), 0.5, 0.5, &ShapeDef::default());
    let all = QueryFilter::default();
    let first = w
        .cast_ray_closest(v(0.0, 0.0), v(10.0, 0.0), &all)
        .unwrap()
        .unwrap();
    assert_eq!(first.body, glass);
    let no_glass = QueryFilter::default().with_mask(!0b10);
    let first = w
        .cast_ray_closest(v(0.0, 0.0), v(10.0, 0.0), &no_glass)
        .unwrap()
        .unwrap();
    assert_eq!(first.body, wall);
    assert!((first.fraction - 0.35).abs() < 1e-6);
    // Excluding the wall body too leaves nothing.
    let nothing = w
        .cast_ray_closest(v(0.0, 0.0), v(10.0, 0.0), &no_glass.excluding(wall))
        .unwrap();
    assert!(nothing.is_none());
    // Overlaps honour the filter as well.
    let mut found = Vec::new();
    w.overlap_aabb(&Aabb::new(v(1.0, -1.0), v(5.0, 1.0)), &no_glass, |o| {
        found.push(o.body);
        true
    })
    .unwrap();
    assert_eq!(found, vec![wall]);
}

#[test]
fn callback_stops_ignores_and_clips() {
    let mut w = world();
    box_row(&mut w);
    let f = QueryFilter::default();
    let (origin, d) = (v(0.0, 0.0), v(20.0, 0.0));
    // 0 stops at once.
    let mut calls = 0;
    w.cast_ray_with(origin, d, &f, |_| {
        calls += 1;
        0.0
    })
    .unwrap();
    assert_eq!(calls, 1);
    // −1 ignores: every hit still comes.
    let mut calls = 0;
    w.cast_ray_with(origin, d, &f, |_| {
        calls += 1;
        -1.0
    })
    .unwrap();
    assert_eq!(calls, 5);
    // Clipping at the second hit drops the three behind it.
    let mut seen = Vec::new();
    w.cast_ray_with(origin, d, &f, |h| {
        seen.push(h.fraction);
        if seen.len() == 2 { h.fraction } else { 1.0 }
    })
    .unwrap();
    assert_eq!(seen.len(), 2);
    assert!((seen[1] - 3.5 / 20.0).abs() < 1e-6);
}

#[test]
fn equal_fraction_hits_come_in_shape_slot_order() {
    let mut w = world();
    // Two boxes sharing the face x = 1.5; the ray runs along their seam.
    let upper = fixed_box(&mut w, v(2.0, 0.5), 0.5, 0.5, &ShapeDef::default());
    let lower = fixed_box(&mut w, v(2.0, -0.5), 0.5, 0.5, &ShapeDef::default());
    for _ in 0..3 {
        let hits = all_hits(&w, v(0.0, 0.0), v(3.0, 0.0), &QueryFilter::default());
        assert_eq!(hits.len(), 2);
        assert_eq!(hits[0].fraction, hits[1].fraction);
        assert_eq!((hits[0].body, hits[1].body), (upper, lower));
    }
}

#[test]
fn overlap_aabb_is_exact_where_the_fat_box_is_not() {
    let mut w = world();
    let b = ball(&mut w, v(0.0, 0.0), 0.5);
    let count = |w: &World, aabb: Aabb| {
        let mut n = 0;
        w.overlap_aabb(&aabb, &QueryFilter::default(), |_| {
            n += 1;
            true
        })
        .unwrap();
        n
    };
    // 1 cm to the right of the ball: the fat box (margin 0.1 m) meets it.
    let beside = Aabb::new(v(0.51, -0.2), v(0.8, 0.2));
    assert_eq!(w.bodies_in_box(&beside), vec![b]);
    assert_eq!(count(&w, beside), 0);
    // Diagonally 1 cm off the surface: still nothing.
    let k = 0.51 / (2.0 as Real).sqrt();
    assert_eq!(count(&w, Aabb::new(v(k, k), v(k + 0.5, k + 0.5))), 0);
    // 1 cm into the ball: found.
    assert_eq!(count(&w, Aabb::new(v(0.49, -0.2), v(0.8, 0.2))), 1);
}

#[test]
fn overlap_shape_and_shape_distance_match_the_layout() {
    let mut w = world();
    let row = box_row(&mut w);
    // A box of half-width 1.2 at x = 3 reaches x ∈ [1.8, 4.2]: boxes 1 and 2.
    let probe = Shape::Polygon(Polygon::make_box(1.2, 0.2));
    let mut found = Vec::new();
    w.overlap_shape(
        &probe,
        &Transform::new(v(3.0, 0.0), 0.0),
        &QueryFilter::default(),
        |o| {
            found.push(o.body);
            true
        },
    )
    .unwrap();
    assert_eq!(found, vec![row[0], row[1]]);
    // Distance between the faces of boxes 1 and 3: 6 − 2 − 1 = 3 m.
    let s1 = w.body_shapes(row[0]).unwrap()[0];
    let s3 = w.body_shapes(row[2]).unwrap()[0];
    let d = w.shape_distance(s1, s3).unwrap();
    assert!((d.distance - 3.0).abs() < 1e-5, "{d:?}");
    assert!((d.point_a.x - 2.5).abs() < 1e-5 && (d.point_b.x - 5.5).abs() < 1e-5);
    assert!((d.normal - v(1.0, 0.0)).length() < 1e-5);
}

#[test]
fn shape_cast_stops_at_the_first_box_of_the_row() {
    let mut w = world();
    let row = box_row(&mut w);
    let disc = Shape::Circle(Circle::new(Vec2::ZERO, 0.25).unwrap());
    let hit = w
        .cast_shape_closest(
            &disc,
            &Transform::new(v(0.0, 0.3), 0.0),
            v(20.0, 0.0),
            &QueryFilter::default(),
        )
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, row[0]);
    // The disc's centre stops at x = 1.25.
    assert!((hit.fraction - 1.25 / 20.0).abs() < 1e-4, "{hit:?}");
    assert!((hit.point - v(1.5, 0.3)).length() < 1e-3);
    assert!((hit.normal - v(-1.0, 0.0)).length() < 1e-4);
    // Above the row (y = 0.8 > 0.5 + 0.25) the disc passes.
    let miss = w
        .cast_shape_closest(
            &disc,
            &Transform::new(v(0.0, 0.8), 0.0),
            v(20.0, 0.0),
            &QueryFilter::default(),
        )
        .unwrap();
    assert!(miss.is_none());
}

#[test]
fn non_finite_or_degenerate_queries_are_typed_errors_and_change_nothing() {
    let mut w = world();
    box_row(&mut w);
    ball(&mut w, v(0.0, 3.0), 0.5);
    w.step(1.0 / 60.0).unwrap();
    let before = w.state_hash();
    let f = QueryFilter::default();
    fn err<T>(field: &'static str, problem: QueryProblem) -> Result<T, WorldError> {
        Err(WorldError::BadQuery { field, problem })
    }
    assert_eq!(
        w.cast_ray_closest(v(Real::NAN, 0.0), v(1.0, 0.0), &f),
        err("origin", QueryProblem::NonFinite)
    );
    assert_eq!(
        w.cast_ray_closest(v(0.0, 0.0), v(Real::INFINITY, 0.0), &f),
        err("translation", QueryProblem::NonFinite)
    );
    assert_eq!(
        w.cast_ray_closest(v(0.0, 0.0), Vec2::ZERO, &f),
        err("translation", QueryProblem::ZeroLength)
    );
    assert_eq!(
        w.overlap_point(v(0.0, Real::NAN), &f, |_| true),
        err("point", QueryProblem::NonFinite)
    );
    assert_eq!(
        w.overlap_aabb(&Aabb::new(v(1.0, 1.0), v(0.0, 0.0)), &f, |_| true),
        err("aabb", QueryProblem::Inverted)
    );
    let bad_disc = Shape::Circle(Circle {
        center: Vec2::ZERO,
        radius: -1.0,
    });
    assert!(matches!(
        w.cast_shape_closest(&bad_disc, &Transform::IDENTITY, v(1.0, 0.0), &f),
        Err(WorldError::BadQuery {
            field: "shape",
            problem: QueryProblem::Shape(_)
        })
    ));
    let bad_xf = Transform::new(v(0.0, Real::NAN), 0.0);
    let disc = Shape::Circle(Circle::new(Vec2::ZERO, 0.5).unwrap());
    assert_eq!(
        w.overlap_shape(&disc, &bad_xf, &f, |_| true),
        err("transform", QueryProblem::NonFinite)
    );
    assert!(
        WorldError::BadQuery {
            field: "origin",
            problem: QueryProblem::NonFinite
        }
        .to_string()
        .contains("origin")
    );
    assert_eq!(w.state_hash(), before);
    // The world steps on as before.
    w.step(1.0 / 60.0).unwrap();
}

#[test]
fn picking_example_grabs_the_box_under_the_cursor() {
    let report = picking::run().unwrap();
    assert_eq!(report.picked_by_point, Some(report.target));
    assert_eq!(report.picked_by_ray, Some(report.target));
    assert!(report.missed_beside_ball);
    assert!(
        (report.ray_fraction - 0.45).abs() < 1e-3,
        "{}",
        report.ray_fraction
    );
}

/// Small deterministic generator (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((self.0 >> 40) as Real) / ((1u64 << 24) as Real)
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.unit()
    }
}

/// A jumble of circles, boxes, capsules and rounded boxes, turned, some
/// dynamic, some static; returns (world, every shape with its body).
fn jumble(seed: u64) -> (World, Vec<(ShapeHandle, BodyHandle)>) {
    let mut w = World::new(WorldDef {
        gravity: Vec2::ZERO,
        ..WorldDef::default()
    })
    .unwrap();
    let mut rng = Lcg(seed);
    let mut out = Vec::new();
    for i in 0..60 {
        let p = v(rng.range(-20.0, 20.0), rng.range(-20.0, 20.0));
        let angle = rng.range(-3.0, 3.0);
        let def = if i % 3 == 0 {
            BodyDef::fixed(p)
        } else {
            BodyDef::dynamic(p)
        };
        let b = w.create_body(&def).unwrap();
        w.set_transform(b, p, angle).unwrap();
        let geometry: Shape = match i % 4 {
            0 => Circle::new(v(0.2, 0.0), rng.range(0.2, 1.0))
                .unwrap()
                .into(),
            1 => Polygon::make_box(rng.range(0.2, 1.5), rng.range(0.2, 1.5)).into(),
            2 => Capsule::new(v(-0.5, 0.0), v(0.5, 0.3), rng.range(0.1, 0.5))
                .unwrap()
                .into(),
            _ => Polygon::make_rounded_box(rng.range(0.2, 1.0), rng.range(0.2, 1.0), 0.2).into(),
        };
        let s = w.create_shape(b, &ShapeDef::default(), geometry).unwrap();
        out.push((s, b));
    }
    (w, out)
}

#[test]
fn ray_casts_match_brute_force_over_every_shape() {
    let (w, shapes) = jumble(7);
    let mut rng = Lcg(8);
    let f = QueryFilter::default();
    for _ in 0..200 {
        let origin = v(rng.range(-25.0, 25.0), rng.range(-25.0, 25.0));
        let d = v(rng.range(-30.0, 30.0), rng.range(-30.0, 30.0));
        let ray = janus2d::base::geometry::RayInput::new(origin, d);
        let mut brute: Vec<(Real, ShapeHandle)> = shapes
            .iter()
            .filter_map(|&(s, b)| {
                let xf = w.transform(b).unwrap();
                let g = &w.shape(s).unwrap().geometry;
                g.ray_cast(&xf, &ray).map(|h| (h.fraction, s))
            })
            .collect();
        brute.sort_by(|a, b| a.0.total_cmp(&b.0));
        let hits = all_hits(&w, origin, d, &f);
        assert_eq!(hits.len(), brute.len());
        for (h, (fr, s)) in hits.iter().zip(&brute) {
            assert!((h.fraction - fr).abs() < 1e-6);
            assert!(hits.iter().any(|x| x.shape == *s));
        }
        let closest = w.cast_ray_closest(origin, d, &f).unwrap();
        assert_eq!(closest.map(|h| h.fraction), brute.first().map(|b| b.0));
    }
}

#[test]
fn overlaps_match_brute_force_over_every_shape() {
    use janus2d::base::geometry::{ShapeProxy, shapes_overlap};
    let (w, shapes) = jumble(9);
    let mut rng = Lcg(10);
    let f = QueryFilter::default();
    let mut nonempty = 0;
    for _ in 0..200 {
        let c = v(rng.range(-22.0, 22.0), rng.range(-22.0, 22.0));
        let half = v(rng.range(0.1, 2.0), rng.range(0.1, 2.0));
        let aabb = Aabb::new(c - half, c + half);
        let boxed = ShapeProxy::from_box(aabb.lower, aabb.upper);
        let point = ShapeProxy::point(c);
        let mut want_box = Vec::new();
        let mut want_point = Vec::new();
        for &(s, b) in &shapes {
            let xf = w.transform(b).unwrap();
            let p = ShapeProxy::from_shape(&w.shape(s).unwrap().geometry);
            if shapes_overlap(&p, &xf, &boxed, &Transform::IDENTITY) {
                want_box.push(s);
            }
            if shapes_overlap(&p, &xf, &point, &Transform::IDENTITY) {
                want_point.push(s);
            }
        }
        want_box.sort();
        want_point.sort();
        let mut got_box = Vec::new();
        w.overlap_aabb(&aabb, &f, |o| {
            got_box.push(o.shape);
            true
        })
        .unwrap();
        let mut got_point = Vec::new();
        w.overlap_point(c, &f, |o| {
            got_point.push(o.shape);
            true
        })
        .unwrap();
        assert_eq!(got_box, want_box);
        assert_eq!(got_point, want_point);
        nonempty += usize::from(!want_box.is_empty());
    }
    assert!(nonempty > 20, "the boxes met shapes only {nonempty} times");
}

#[test]
fn shape_cast_fraction_is_the_first_touch() {
    let (w, _) = jumble(11);
    let mut rng = Lcg(12);
    let f = QueryFilter::default();
    let disc = Shape::Circle(Circle::new(Vec2::ZERO, 0.3).unwrap());
    let probe = Shape::Polygon(Polygon::make_box(0.3, 0.2));
    let mut hits = 0;
    for i in 0..100 {
        let shape = if i % 2 == 0 { &disc } else { &probe };
        let start = Transform::new(
            v(rng.range(-25.0, 25.0), rng.range(-25.0, 25.0)),
            rng.range(-3.0, 3.0),
        );
        let d = v(rng.range(-30.0, 30.0), rng.range(-30.0, 30.0));
        let touching = |t: Real| {
            let xf = Transform {
                p: start.p + t * d,
                q: start.q,
            };
            let mut n = 0;
            w.overlap_shape(shape, &xf, &f, |_| {
                n += 1;
                true
            })
            .unwrap();
            n > 0
        };
        if touching(0.0) {
            continue;
        }
        let Some(hit) = w.cast_shape_closest(shape, &start, d, &f).unwrap() else {
            // No hit: the swept shape touches nothing along the way.
            assert!((1..=200).all(|k| !touching(k as Real / 200.0)));
            continue;
        };
        hits += 1;
        let len = d.length();
        // Just before the fraction: apart; a millimetre past: touching.
        assert!(
            !touching((hit.fraction - 2e-3 / len).max(0.0)),
            "{i}: {hit:?}"
        );
        assert!(touching(hit.fraction + 1e-3 / len), "{i}: {hit:?}");
    }
    assert!(hits > 20, "only {hits} casts hit");
}

#[test]
fn queries_see_sleeping_bodies() {
    let mut w = world();
    fixed_box(&mut w, v(0.0, -0.5), 5.0, 0.5, &ShapeDef::default());
    let b = ball(&mut w, v(0.0, 0.5), 0.5);
    for _ in 0..200 {
        w.step(1.0 / 60.0).unwrap();
    }
    assert!(w.is_sleeping(b).unwrap());
    let hit = w
        .cast_ray_closest(v(-3.0, 0.5), v(6.0, 0.0), &QueryFilter::default())
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, b);
    assert!((hit.point.x + 0.5).abs() < 0.01);
    assert!(w.is_sleeping(b).unwrap(), "a query does not wake anything");
}

#[test]
fn ray_starting_inside_a_shape_skips_it() {
    let mut w = world();
    let row = box_row(&mut w);
    // From the centre of the first box: it is not hit, the second is.
    let hit = w
        .cast_ray_closest(v(2.0, 0.0), v(10.0, 0.0), &QueryFilter::default())
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, row[1]);
    assert!((hit.fraction - 0.15).abs() < 1e-6);
}

#[cfg(feature = "portals")]
mod through_portals {
    use super::*;
    use janus2d::world::{PortalDef, PortalPairDef};

    /// Wall A (face x = 5, aperture centred at (5, 0), half-width 1, facing
    /// −x); wall B (face x = 20.5 at y = 10, aperture half-width 2, facing
    /// +x): η = 2, Q = identity.
    fn portal_scene() -> (World, BodyHandle, BodyHandle, BodyHandle, BodyHandle) {
        let mut w = world();
        let a = fixed_box(&mut w, v(5.5, 0.0), 0.5, 3.0, &ShapeDef::default());
        let b = fixed_box(&mut w, v(20.0, 10.0), 0.5, 3.0, &ShapeDef::default());
        w.create_portal_pair(&PortalPairDef::new(
            PortalDef {
                body: a,
                anchor: v(-0.5, 0.0),
                direction: -Vec2::X,
                half_width: 1.0,
            },
            PortalDef {
                body: b,
                anchor: v(0.5, 0.0),
                direction: Vec2::X,
                half_width: 2.0,
            },
        ))
        .unwrap();
        // Behind the exit, on the mapped line y = 10 + 2 · 0.5 = 11.
        let target = fixed_box(&mut w, v(25.0, 11.0), 0.5, 0.5, &ShapeDef::default());
        // Behind wall A on the unmapped line: only seen without portals' help.
        let decoy = fixed_box(&mut w, v(8.0, 0.5), 0.5, 0.5, &ShapeDef::default());
        (w, a, b, target, decoy)
    }

    #[test]
    fn ray_through_a_portal_hits_the_box_behind_the_exit_at_the_mapped_point() {
        let (w, a, _b, target, _decoy) = portal_scene();
        let (origin, d) = (v(0.0, 0.5), v(10.0, 0.0));
        // Off by default: the wall is hit at the aperture.
        let plain = w
            .cast_ray_closest(origin, d, &QueryFilter::default())
            .unwrap()
            .unwrap();
        assert_eq!(plain.body, a);
        assert!((plain.fraction - 0.5).abs() < 1e-6);
        // Through: crosses at (5, 0.5) → (20.5, 11), 5 m left × η = 10 m,
        // the target's face at x = 24.5 is 4 m on: fraction 0.5 + 0.4 · 0.5.
        let through = QueryFilter::default().through_portals();
        let hit = w.cast_ray_closest(origin, d, &through).unwrap().unwrap();
        assert_eq!(hit.body, target);
        assert!((hit.point - v(24.5, 11.0)).length() < 1e-4, "{hit:?}");
        assert!((hit.fraction - 0.7).abs() < 1e-5);
        assert!((hit.normal - v(-1.0, 0.0)).length() < 1e-5);
        assert_eq!(hit.portal_hops, 1);
        let hop = hit.last_portal.unwrap();
        assert_eq!(hop.entered, 0);
        assert!((hop.entry_point - v(5.0, 0.5)).length() < 1e-5);
        assert!((hop.exit_point - v(20.5, 11.0)).length() < 1e-5);
        // Every hit: only the target (the decoy and the walls are not seen).
        let hits = all_hits(&w, origin, d, &through);
        assert_eq!(hits.len(), 1);
        // Outside the aperture's span (y = 1.5 > w = 1) the wall stops the ray.
        let lip = w
            .cast_ray_closest(v(0.0, 1.5), d, &through)
            .unwrap()
            .unwrap();
        assert_eq!(lip.body, a);
        assert_eq!(lip.portal_hops, 0);
    }

    #[test]
    fn ray_through_a_turned_exit_leaves_along_its_normal() {
        // Entry faces −x at (5, 0); exit faces +y on a floor at (30, 0).
        let mut w = world();
        let a = fixed_box(&mut w, v(5.5, 0.0), 0.5, 3.0, &ShapeDef::default());
        let floor = fixed_box(&mut w, v(30.0, -0.5), 3.0, 0.5, &ShapeDef::default());
        w.create_portal_pair(&PortalPairDef::new(
            PortalDef {
                body: a,
                anchor: v(-0.5, 0.0),
                direction: -Vec2::X,
                half_width: 1.0,
            },
            PortalDef {
                body: floor,
                anchor: v(0.0, 0.5),
                direction: Vec2::Y,
                half_width: 1.0,
            },
        ))
        .unwrap();
        // Q = R(π/2): the offset +0.5 along y at the entry maps to −0.5 along x.
        let ceiling = fixed_box(&mut w, v(29.5, 4.5), 1.0, 0.5, &ShapeDef::default());
        let through = QueryFilter::default().through_portals();
        let hit = w
            .cast_ray_closest(v(0.0, 0.5), v(10.0, 0.0), &through)
            .unwrap()
            .unwrap();
        assert_eq!(hit.body, ceiling);
        // Crossed at fraction 0.5 at (30 − 0.5, 0); the ceiling's face y = 4 is 4 m on.
        assert!((hit.point - v(29.5, 4.0)).length() < 1e-4, "{hit:?}");
        assert!((hit.fraction - 0.9).abs() < 1e-5);
        assert!((hit.normal - v(0.0, -1.0)).length() < 1e-5);
    }

    #[test]
    fn facing_portals_end_after_the_hop_limit() {
        use janus2d::world::query::MAX_PORTAL_HOPS;
        // Entry faces −x at x = 5, exit faces +x at x = −5: a ray along +x
        // comes back to the entry after every pass.
        let mut w = world();
        let a = fixed_box(&mut w, v(5.5, 0.0), 0.5, 3.0, &ShapeDef::default());
        let b = fixed_box(&mut w, v(-5.5, 0.0), 0.5, 3.0, &ShapeDef::default());
        w.create_portal_pair(&PortalPairDef::new(
            PortalDef {
                body: a,
                anchor: v(-0.5, 0.0),
                direction: -Vec2::X,
                half_width: 1.0,
            },
            PortalDef {
                body: b,
                anchor: v(0.5, 0.0),
                direction: Vec2::X,
                half_width: 1.0,
            },
        ))
        .unwrap();
        let through = QueryFilter::default().through_portals();
        let hit = w
            .cast_ray_closest(v(0.0, 0.0), v(100.0, 0.0), &through)
            .unwrap()
            .unwrap();
        assert_eq!(hit.portal_hops, MAX_PORTAL_HOPS);
        assert_eq!(hit.body, a, "after the last hop the aperture is a wall");
        // 5 m to the entry, then 10 m per pass.
        let expect = (5.0 + 10.0 * MAX_PORTAL_HOPS as Real) / 100.0;
        assert!((hit.fraction - expect).abs() < 1e-5, "{hit:?}");
    }

    #[test]
    fn clipping_before_the_portal_keeps_the_ray_on_this_side() {
        let (mut w, _a, _b, target, _decoy) = portal_scene();
        let near = fixed_box(&mut w, v(3.0, 0.5), 0.25, 0.25, &ShapeDef::default());
        let through = QueryFilter::default().through_portals();
        let hit = w
            .cast_ray_closest(v(0.0, 0.5), v(10.0, 0.0), &through)
            .unwrap()
            .unwrap();
        assert_eq!(hit.body, near);
        assert!((hit.fraction - 0.275).abs() < 1e-6);
        // Ignoring it, the ray goes on through the portal to the target.
        let mut bodies = Vec::new();
        w.cast_ray_with(v(0.0, 0.5), v(10.0, 0.0), &through, |h| {
            bodies.push(h.body);
            -1.0
        })
        .unwrap();
        assert_eq!(bodies, vec![near, target]);
    }

    #[test]
    fn shape_too_wide_for_the_aperture_meets_its_lips() {
        let (w, a, _b, _target, _decoy) = portal_scene();
        // Radius 1.5 around y = 0.5 reaches the lip end (5, 1) when its centre
        // is √(1.5² − 0.5²) = √2 before the face.
        let disc = Shape::Circle(Circle::new(Vec2::ZERO, 1.5).unwrap());
        let through = QueryFilter::default().through_portals();
        let hit = w
            .cast_shape_closest(
                &disc,
                &Transform::new(v(0.0, 0.5), 0.0),
                v(10.0, 0.0),
                &through,
            )
            .unwrap()
            .unwrap();
        assert_eq!(hit.body, a);
        assert_eq!(hit.portal_hops, 0);
        let expect = (5.0 - (2.0 as Real).sqrt()) / 10.0;
        assert!((hit.fraction - expect).abs() < 1e-4, "{hit:?}");
        assert!((hit.point - v(5.0, 1.0)).length() < 1e-4);
        // Without the flag the face is met first, at the aperture.
        let plain = w
            .cast_shape_closest(
                &disc,
                &Transform::new(v(0.0, 0.5), 0.0),
                v(10.0, 0.0),
                &QueryFilter::default(),
            )
            .unwrap()
            .unwrap();
        assert!((plain.fraction - 0.35).abs() < 1e-4, "{plain:?}");
    }

    #[test]
    fn shape_cast_through_a_portal_is_scaled_and_continues() {
        let (w, _a, _b, target, _decoy) = portal_scene();
        // A disc of radius 0.2 fits the aperture; its image has radius 0.4.
        let disc = Shape::Circle(Circle::new(Vec2::ZERO, 0.2).unwrap());
        let through = QueryFilter::default().through_portals();
        let hit = w
            .cast_shape_closest(
                &disc,
                &Transform::new(v(0.0, 0.5), 0.0),
                v(10.0, 0.0),
                &through,
            )
            .unwrap()
            .unwrap();
        assert_eq!(hit.body, target);
        assert_eq!(hit.portal_hops, 1);
        // Centre stops 0.4 before x = 24.5: 3.6 m of the 10 m leg.
        assert!((hit.fraction - (0.5 + 0.5 * 0.36)).abs() < 1e-4, "{hit:?}");
        assert!((hit.point - v(24.5, 11.0)).length() < 1e-3);
    }
}
