//! `manifolds`: the contact manifold routines of janus2d and Box2D on the
//! same recorded shape pairs, ns per pair (issue 31's micro-benchmark).
//!
//! Each of the ten benchmark scenes runs in janus2d for `--steps` steps
//! (default 120); then every awake solid contact between two bodies of one
//! shape each is recorded: the two shapes in their body frames and the
//! transform of body b in body a's frame. Pairs go in Box2D's argument
//! order (segment, then polygon, capsule, circle as shape a). Each engine's
//! routine then runs over every recorded pair of a kind, in order, the
//! whole list repeated until it has run for at least 0.2 s; the best of
//! three such runs is reported.
//!
//! | kind | janus2d | Box2D |
//! |---|---|---|
//! | any pair | `geometry::manifold::collide` | `b2Collide<A>And<B>` / `b2Collide<A>s` |
//!
//! Both get the pair in body a's frame and the same speculative distance
//! (Box2D's 4 linear slops, 2 cm). Box2D's routines are called through
//! `boxdd-sys` directly: `boxdd`'s safe wrappers validate the shapes and
//! take a lease on every call, which would time the wrapper, not the
//! routine. Chain segments (whose Box2D routine needs a cache) and compound
//! bodies are left out and counted.

use std::hint::black_box;
use std::time::Instant;

use boxdd_sys::ffi;
use janus2d_core::geometry::manifold::collide;
use janus2d_core::geometry::{Capsule, Circle, LINEAR_SLOP, Polygon, Segment, Shape};
use janus2d_core::math::{Transform, Vec2};
use janus2d_testbed::benchmarks;
use janus2d_testbed::engine::{Engine, EngineOptions, scripted_step};
use janus2d_testbed::janus::Janus;

use crate::Args;

/// One recorded pair: shape a, shape b in b's body frame, and b's body
/// frame in a's.
#[derive(Clone, Copy)]
struct Pair {
    a: Shape,
    b: Shape,
    b_in_a: Transform,
}

/// Box2D's argument order: the lower rank is shape a.
fn rank(s: &Shape) -> Option<u8> {
    match s {
        Shape::Segment(_) => Some(0),
        Shape::Polygon(_) => Some(1),
        Shape::Capsule(_) => Some(2),
        Shape::Circle(_) => Some(3),
        Shape::ChainSegment(_) => None,
    }
}

const KINDS: [&str; 4] = ["segment", "polygon", "capsule", "circle"];

/// The recorded pairs of one scene, and how many contacts were left out.
fn record(scene: &str, steps: usize) -> Result<(Vec<Pair>, usize), String> {
    let desc = benchmarks::by_name(scene).ok_or_else(|| format!("unknown scene {scene}"))?;
    let mut engine = Janus::build(&desc, EngineOptions { threads: 1 })?;
    let mut buf = Vec::new();
    for k in 0..steps {
        scripted_step(&mut engine, &desc, k, &mut buf);
    }
    let world = &engine.world;
    let (mut pairs, mut skipped) = (Vec::new(), 0);
    for c in world.contacts() {
        if c.sensor || !c.enabled {
            continue;
        }
        let one_shape = |body| {
            let shapes = world.body_shapes(body).ok()?;
            let [s] = shapes[..] else { return None };
            Some(world.shape(s).ok()?.geometry)
        };
        let (Some(sa), Some(sb)) = (one_shape(c.body_a), one_shape(c.body_b)) else {
            skipped += 1;
            continue;
        };
        let (Ok(xa), Ok(xb)) = (world.transform(c.body_a), world.transform(c.body_b)) else {
            skipped += 1;
            continue;
        };
        let (Some(ra), Some(rb)) = (rank(&sa), rank(&sb)) else {
            skipped += 1;
            continue;
        };
        pairs.push(if ra <= rb {
            Pair {
                a: sa,
                b: sb,
                b_in_a: xa.inv_mul(&xb),
            }
        } else {
            Pair {
                a: sb,
                b: sa,
                b_in_a: xb.inv_mul(&xa),
            }
        });
    }
    Ok((pairs, skipped))
}

fn v2(v: Vec2) -> ffi::b2Vec2 {
    ffi::b2Vec2 { x: v.x, y: v.y }
}

fn b2_polygon(p: &Polygon) -> ffi::b2Polygon {
    let mut out = ffi::b2Polygon {
        vertices: [ffi::b2Vec2 { x: 0.0, y: 0.0 }; 8],
        normals: [ffi::b2Vec2 { x: 0.0, y: 0.0 }; 8],
        centroid: v2(p.centroid),
        radius: p.radius,
        count: p.count as i32,
    };
    for k in 0..p.count {
        out.vertices[k] = v2(p.vertices[k]);
        out.normals[k] = v2(p.normals[k]);
    }
    out
}

fn b2_circle(c: &Circle) -> ffi::b2Circle {
    ffi::b2Circle {
        center: v2(c.center),
        radius: c.radius,
    }
}

fn b2_capsule(c: &Capsule) -> ffi::b2Capsule {
    ffi::b2Capsule {
        center1: v2(c.center1),
        center2: v2(c.center2),
        radius: c.radius,
    }
}

fn b2_segment(s: &Segment) -> ffi::b2Segment {
    ffi::b2Segment {
        point1: v2(s.point1),
        point2: v2(s.point2),
    }
}

/// A pair as Box2D's routine takes it.
enum B2Pair {
    Circles(ffi::b2Circle, ffi::b2Circle),
    CapsuleCircle(ffi::b2Capsule, ffi::b2Circle),
    Capsules(ffi::b2Capsule, ffi::b2Capsule),
    PolygonCircle(ffi::b2Polygon, ffi::b2Circle),
    PolygonCapsule(ffi::b2Polygon, ffi::b2Capsule),
    Polygons(ffi::b2Polygon, ffi::b2Polygon),
    SegmentCircle(ffi::b2Segment, ffi::b2Circle),
    SegmentCapsule(ffi::b2Segment, ffi::b2Capsule),
    SegmentPolygon(ffi::b2Segment, ffi::b2Polygon),
}

fn b2_pair(p: &Pair) -> Option<B2Pair> {
    use Shape as S;
    Some(match (&p.a, &p.b) {
        (S::Circle(a), S::Circle(b)) => B2Pair::Circles(b2_circle(a), b2_circle(b)),
        (S::Capsule(a), S::Circle(b)) => B2Pair::CapsuleCircle(b2_capsule(a), b2_circle(b)),
        (S::Capsule(a), S::Capsule(b)) => B2Pair::Capsules(b2_capsule(a), b2_capsule(b)),
        (S::Polygon(a), S::Circle(b)) => B2Pair::PolygonCircle(b2_polygon(a), b2_circle(b)),
        (S::Polygon(a), S::Capsule(b)) => B2Pair::PolygonCapsule(b2_polygon(a), b2_capsule(b)),
        (S::Polygon(a), S::Polygon(b)) => B2Pair::Polygons(b2_polygon(a), b2_polygon(b)),
        (S::Segment(a), S::Circle(b)) => B2Pair::SegmentCircle(b2_segment(a), b2_circle(b)),
        (S::Segment(a), S::Capsule(b)) => B2Pair::SegmentCapsule(b2_segment(a), b2_capsule(b)),
        (S::Segment(a), S::Polygon(b)) => B2Pair::SegmentPolygon(b2_segment(a), b2_polygon(b)),
        _ => return None,
    })
}

/// Box2D's routine for one pair; returns its point count.
fn b2_collide(p: &B2Pair, xf: ffi::b2Transform) -> i32 {
    // SAFETY: each call passes pointers to live, initialised values of the
    // `#[repr(C)]` types bindgen generated from Box2D's headers, which the
    // routine only reads during the call; the polygons come from janus2d's
    // validated polygons (2..=8 vertices, unit outward normals), so
    // Box2D's own preconditions hold. The routines keep no state.
    let m = unsafe {
        match p {
            B2Pair::Circles(a, b) => ffi::b2CollideCircles(a, b, xf),
            B2Pair::CapsuleCircle(a, b) => ffi::b2CollideCapsuleAndCircle(a, b, xf),
            B2Pair::Capsules(a, b) => ffi::b2CollideCapsules(a, b, xf),
            B2Pair::PolygonCircle(a, b) => ffi::b2CollidePolygonAndCircle(a, b, xf),
            B2Pair::PolygonCapsule(a, b) => ffi::b2CollidePolygonAndCapsule(a, b, xf),
            B2Pair::Polygons(a, b) => ffi::b2CollidePolygons(a, b, xf),
            B2Pair::SegmentCircle(a, b) => ffi::b2CollideSegmentAndCircle(a, b, xf),
            B2Pair::SegmentCapsule(a, b) => ffi::b2CollideSegmentAndCapsule(a, b, xf),
            B2Pair::SegmentPolygon(a, b) => ffi::b2CollideSegmentAndPolygon(a, b, xf),
        }
    };
    m.pointCount
}

/// Best of three runs of `f` over the list, each repeated for ≥ 0.2 s:
/// ns per call.
fn time_per_item(n: usize, mut f: impl FnMut() -> usize) -> f64 {
    let mut best = f64::MAX;
    for _ in 0..3 {
        let start = Instant::now();
        let mut calls = 0usize;
        while start.elapsed().as_secs_f64() < 0.2 {
            black_box(f());
            calls += n;
        }
        best = best.min(start.elapsed().as_secs_f64() * 1e9 / calls as f64);
    }
    best
}

/// `manifolds [--scenes a,b] [--steps N]`: the table, one row per kind of
/// pair, over the pairs of every scene asked for.
pub fn cmd_manifolds(args: &Args) {
    let steps = args.steps.unwrap_or(120);
    let mut all: Vec<Pair> = Vec::new();
    let mut skipped = 0;
    for scene in args.scene_names() {
        match record(&scene, steps) {
            Ok((pairs, left_out)) => {
                println!(
                    "{scene:14} {:6} pairs recorded, {left_out} left out (compound bodies, chain segments)",
                    pairs.len()
                );
                all.extend(pairs);
                skipped += left_out;
            }
            Err(e) => eprintln!("{scene}: {e}"),
        }
    }
    let spec = 4.0 * LINEAR_SLOP;
    println!();
    println!(
        "contact manifolds, ns per pair (best of three runs of ≥ 0.2 s; {} pairs, {skipped} left out)",
        all.len()
    );
    println!(
        "{:20} {:>7} {:>9} {:>9} {:>8}",
        "shape a / shape b", "pairs", "janus2d", "Box2D", "ratio"
    );
    let (mut total_j, mut total_b, mut total_n) = (0.0, 0.0, 0usize);
    for ra in 0..4u8 {
        for rb in ra..4u8 {
            let pairs: Vec<&Pair> = all
                .iter()
                .filter(|p| rank(&p.a) == Some(ra) && rank(&p.b) == Some(rb))
                .collect();
            if pairs.is_empty() {
                continue;
            }
            let identity = Transform::IDENTITY;
            let janus = time_per_item(pairs.len(), || {
                pairs
                    .iter()
                    .map(|p| collide(&p.a, &identity, &p.b, &p.b_in_a, spec).point_count)
                    .sum()
            });
            let b2: Vec<(B2Pair, ffi::b2Transform)> = pairs
                .iter()
                .filter_map(|p| {
                    let xf = ffi::b2Transform {
                        p: v2(p.b_in_a.p),
                        q: ffi::b2Rot {
                            c: p.b_in_a.q.c,
                            s: p.b_in_a.q.s,
                        },
                    };
                    b2_pair(p).map(|b| (b, xf))
                })
                .collect();
            let box2d = time_per_item(b2.len(), || {
                b2.iter().map(|(p, xf)| b2_collide(p, *xf) as usize).sum()
            });
            let name = format!("{} / {}", KINDS[ra as usize], KINDS[rb as usize]);
            println!(
                "{name:20} {:7} {janus:9.1} {box2d:9.1} {:8.2}",
                pairs.len(),
                janus / box2d
            );
            total_j += janus * pairs.len() as f64;
            total_b += box2d * pairs.len() as f64;
            total_n += pairs.len();
        }
    }
    if total_n > 0 {
        println!(
            "{:20} {total_n:7} {:9.1} {:9.1} {:8.2}",
            "all (pair-weighted)",
            total_j / total_n as f64,
            total_b / total_n as f64,
            total_j / total_b
        );
    }
}
