//! `collide` on every shape pair: two shapes of any kind, hand-built from
//! the bytes; those `Shape::validate` accepts are placed by any finite
//! transforms within the world's coordinates and collided both ways. The
//! manifold has at most two points, all finite, and a unit normal.
#![no_main]

use janus2d::base::geometry::{Capsule, ChainSegment, Circle, Polygon, Segment, Shape, collide};
use janus2d::base::limits::MAX_COORDINATE;
use janus2d::base::math::{Real, Transform, Vec2};
use libfuzzer_sys::fuzz_target;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let (b, rest) = self.0.split_first().map_or((0, &[][..]), |(b, r)| (*b, r));
        self.0 = rest;
        b
    }
    /// A real: small values mostly, special ones sometimes.
    fn real(&mut self) -> Real {
        match self.byte() {
            0 => Real::NAN,
            1 => Real::INFINITY,
            2 => 1e30,
            3 => -0.0,
            4 => 1e-30,
            5 => 1e6,
            b => {
                let lo = self.byte();
                (Real::from(b) - 128.0) / 16.0 + Real::from(lo) / 4096.0
            }
        }
    }
    fn vec(&mut self) -> Vec2 {
        Vec2::new(self.real(), self.real())
    }
}

fn shape(b: &mut Bytes) -> Shape {
    match b.byte() % 6 {
        0 => Shape::Circle(Circle {
            center: b.vec(),
            radius: b.real(),
        }),
        1 => Shape::Capsule(Capsule {
            center1: b.vec(),
            center2: b.vec(),
            radius: b.real(),
        }),
        2 => {
            let n = 3 + (b.byte() % 6) as usize;
            let pts: Vec<Vec2> = (0..n).map(|_| b.vec()).collect();
            let r = b.real().abs() * 0.1;
            Polygon::from_hull(&pts, r).map_or(
                Shape::Circle(Circle {
                    center: Vec2::ZERO,
                    radius: 0.5,
                }),
                Shape::Polygon,
            )
        }
        3 => Shape::Segment(Segment {
            point1: b.vec(),
            point2: b.vec(),
        }),
        4 => Shape::ChainSegment(ChainSegment {
            ghost1: b.vec(),
            segment: Segment {
                point1: b.vec(),
                point2: b.vec(),
            },
            ghost2: b.vec(),
        }),
        _ => {
            // A hand-built polygon: a box with fuzzed vertices and normals.
            let mut p = Polygon::make_box(0.5, 0.5);
            for k in 0..4 {
                if b.byte().is_multiple_of(2) {
                    p.vertices[k] = b.vec();
                }
                if b.byte().is_multiple_of(4) {
                    p.normals[k] = b.vec();
                }
            }
            p.radius = b.real().abs() * 0.1;
            Shape::Polygon(p)
        }
    }
}

fn transform(b: &mut Bytes) -> Transform {
    let p = b.vec();
    let scale = match b.byte() % 4 {
        0 => 1.0,
        1 => 1e3,
        2 => 1e6,
        _ => MAX_COORDINATE / 8.0,
    };
    Transform::new(p * scale, b.real())
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let (sa, sb) = (shape(&mut b), shape(&mut b));
    let (xa, xb) = (transform(&mut b), transform(&mut b));
    if sa.validate().is_err() || sb.validate().is_err() {
        return;
    }
    let fine = |x: &Transform| {
        x.p.is_finite()
            && x.q.is_finite()
            && x.p.x.abs() <= MAX_COORDINATE
            && x.p.y.abs() <= MAX_COORDINATE
    };
    if !fine(&xa) || !fine(&xb) {
        return;
    }
    for (a, ta, c, tc) in [(&sa, &xa, &sb, &xb), (&sb, &xb, &sa, &xa)] {
        let m = collide(a, ta, c, tc, 0.02);
        assert!(m.point_count <= 2, "{} points", m.point_count);
        if m.point_count > 0 {
            assert!(m.normal.is_finite(), "normal {:?}", m.normal);
            assert!(
                (m.normal.length() - 1.0).abs() < 1e-3,
                "normal {:?}",
                m.normal
            );
        }
        for p in m.points() {
            assert!(
                p.point.is_finite()
                    && p.separation.is_finite()
                    && p.anchor_a.is_finite()
                    && p.anchor_b.is_finite(),
                "{m:?}"
            );
        }
    }
});
