//! Hull and polygon construction: `Polygon::from_hull` on any points and
//! radius never panics; a hull it returns passes `Shape::validate` (when
//! inside the shape extent), has positive area, finite mass and box; and
//! a hand-built polygon from the same bytes is either refused by
//! `validate` or has finite mass properties.
#![no_main]

use janus2d::base::geometry::{Polygon, Shape};
use janus2d::base::limits::MAX_EXTENT;
use janus2d::base::math::{Real, Transform, Vec2};
use libfuzzer_sys::fuzz_target;

fn reals(data: &[u8]) -> Vec<Real> {
    data.chunks_exact(4)
        .map(|c| Real::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect()
}

fuzz_target!(|data: &[u8]| {
    if data.is_empty() {
        return;
    }
    let radius_code = data[0];
    let r = reals(&data[1..]);
    let points: Vec<Vec2> = r.chunks_exact(2).map(|p| Vec2::new(p[0], p[1])).collect();
    let radius = match radius_code % 4 {
        0 => 0.0,
        1 => Real::from(radius_code) / 64.0,
        2 => -1.0,
        _ => r.first().copied().unwrap_or(0.0),
    };
    if let Ok(p) = Polygon::from_hull(&points, radius) {
        let inside = p.vertices[..p.count]
            .iter()
            .all(|v| v.x.abs() <= MAX_EXTENT && v.y.abs() <= MAX_EXTENT)
            && p.radius <= MAX_EXTENT;
        let shape = Shape::Polygon(p);
        if inside {
            if let Err(e) = shape.validate() {
                panic!("from_hull built a polygon validate refuses: {e} {p:?}");
            }
            assert!(shape.area() > 0.0, "hull without area");
            let m = shape.compute_mass(1.0);
            assert!(m.mass.is_finite() && m.rotational_inertia.is_finite());
            let b = shape.compute_aabb(&Transform::IDENTITY);
            assert!(b.lower.is_finite() && b.upper.is_finite());
        }
    }
    // The same points as a hand-built polygon literal.
    if (3..=8).contains(&points.len()) {
        let mut p = Polygon::make_box(1.0, 1.0);
        p.count = points.len();
        for (k, v) in points.iter().enumerate() {
            p.vertices[k] = *v;
        }
        let shape = Shape::Polygon(p);
        if shape.validate().is_ok() {
            let m = shape.compute_mass(1.0);
            assert!(m.mass.is_finite());
        }
    }
});
