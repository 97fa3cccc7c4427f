//! Mass properties and areas of shapes.
//!
//! All results are exact closed forms (no approximation of rounded corners):
//! a rounded polygon is split into its core polygon, one rectangle per edge
//! (edge length × radius) and one circular sector per vertex (the sector
//! angles sum to 2π).

use super::shapes::{Capsule, Circle, Polygon, Shape};
use crate::math::{PI, Real, Vec2, cross};

/// Mass properties of a shape.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct MassData {
    /// Mass, kilograms (density × area).
    pub mass: Real,
    /// Centre of mass in the body frame, metres.
    pub center: Vec2,
    /// Rotational inertia about the centre of mass, kg·m².
    pub rotational_inertia: Real,
}

impl MassData {
    /// The mass properties of several parts of one body: total mass, the
    /// mass-weighted centre, and the inertia about that centre by the
    /// parallel-axis theorem (`I = Σ (Iᵢ + mᵢ|cᵢ|²) − m|c|²`). Parts in the
    /// order given (the sum is order-dependent in the last bit).
    ///
    /// ```
    /// use janus2d_core::geometry::MassData;
    /// use janus2d_core::Vec2;
    /// let part = |x| MassData { mass: 1.0, center: Vec2::new(x, 0.0), rotational_inertia: 0.0 };
    /// let m = MassData::combine([part(-1.0), part(1.0)]);
    /// assert_eq!(m.mass, 2.0);
    /// assert_eq!(m.center, Vec2::ZERO);
    /// assert!((m.rotational_inertia - 2.0).abs() < 1e-6);
    /// ```
    #[must_use]
    pub fn combine(parts: impl IntoIterator<Item = MassData>) -> MassData {
        let mut total = MassData::default();
        let mut first = Vec2::ZERO;
        let mut second: Real = 0.0;
        for md in parts {
            total.mass += md.mass;
            first += md.mass * md.center;
            second += md.rotational_inertia + md.mass * md.center.length_squared();
        }
        if total.mass > 0.0 {
            total.center = first / total.mass;
            total.rotational_inertia =
                (second - total.mass * total.center.length_squared()).max(0.0);
        }
        total
    }
}

/// Running sums of area, first moment and polar second moment about a
/// reference point.
#[derive(Default)]
struct Moments {
    area: Real,
    first: Vec2,
    second: Real,
}

impl Moments {
    /// Adds a piece of area `a` with centroid `c` (relative to the reference)
    /// and polar moment `i_cm` (per unit density) about its own centroid.
    #[inline]
    fn add(&mut self, a: Real, c: Vec2, i_cm: Real) {
        self.area += a;
        self.first += a * c;
        self.second += i_cm + a * c.length_squared();
    }

    fn finish(&self, density: Real, reference: Vec2) -> MassData {
        if self.area.is_nan() || self.area <= 0.0 {
            return MassData {
                mass: 0.0,
                center: reference,
                rotational_inertia: 0.0,
            };
        }
        let c = self.first / self.area;
        let i = (self.second - self.area * c.length_squared()).max(0.0);
        MassData {
            mass: density * self.area,
            center: reference + c,
            rotational_inertia: density * i,
        }
    }
}

impl Circle {
    /// Area, m²: `π r²`.
    #[inline]
    pub fn area(&self) -> Real {
        PI * self.radius * self.radius
    }

    /// Mass properties for `density` (kg/m²): `m = ρ π r²`, `I = m r² / 2`.
    pub fn compute_mass(&self, density: Real) -> MassData {
        let mass = density * self.area();
        MassData {
            mass,
            center: self.center,
            rotational_inertia: 0.5 * mass * self.radius * self.radius,
        }
    }
}

impl Capsule {
    /// Area, m²: `2 r L + π r²`.
    #[inline]
    pub fn area(&self) -> Real {
        let r = self.radius;
        2.0 * r * self.length() + PI * r * r
    }

    /// Mass properties for `density` (kg/m²): a `L × 2r` rectangle plus two
    /// half discs, combined with the parallel-axis theorem.
    pub fn compute_mass(&self, density: Real) -> MassData {
        let r = self.radius;
        let len = self.length();
        let rect_mass = density * 2.0 * r * len;
        let disc_mass = density * PI * r * r;
        // Rectangle about its centre.
        let rect_i = rect_mass * (len * len + 4.0 * r * r) / 12.0;
        // The two half discs: centroid 4r/(3π) beyond each end of the core.
        let lc = 4.0 * r / (3.0 * PI);
        let h = 0.5 * len;
        let disc_i = disc_mass * (0.5 * r * r + h * h + 2.0 * h * lc);
        MassData {
            mass: rect_mass + disc_mass,
            center: 0.5 * (self.center1 + self.center2),
            rotational_inertia: rect_i + disc_i,
        }
    }
}

impl Polygon {
    /// Area, m²: core area + perimeter × radius + π radius².
    pub fn area(&self) -> Real {
        let r = self.radius;
        self.core_area() + self.core_perimeter() * r + PI * r * r
    }

    /// Mass properties for `density` (kg/m²), exact also for a rounded polygon
    /// (including the 2-vertex capsule form).
    pub fn compute_mass(&self, density: Real) -> MassData {
        let n = self.count;
        let r = self.radius;
        // Reference point near the middle keeps the sums well conditioned.
        let o = self.centroid;
        let mut m = Moments::default();
        // Core: triangle fan about the reference point.
        for i in 0..n {
            let e1 = self.vertices[i] - o;
            let e2 = self.vertices[(i + 1) % n] - o;
            let d = cross(e1, e2);
            let a = 0.5 * d;
            // Polar moment of the triangle about o: (D/12)(e1² + e1·e2 + e2²).
            let i_o = d / 12.0 * (e1.dot(e1) + e1.dot(e2) + e2.dot(e2));
            let c = (e1 + e2) / 3.0;
            // `add` wants the moment about the piece's centroid.
            m.add(a, c, i_o - a * c.length_squared());
        }
        if r > 0.0 {
            for i in 0..n {
                let j = (i + 1) % n;
                let a_v = self.vertices[i];
                let b_v = self.vertices[j];
                let nrm = self.normals[i];
                // Edge rectangle of length L and width r, outside the edge.
                let len = a_v.distance(b_v);
                let area = len * r;
                let c = 0.5 * (a_v + b_v) + 0.5 * r * nrm - o;
                m.add(area, c, area * (len * len + r * r) / 12.0);
                // Sector at vertex j, from normal i to normal j (counter-clockwise).
                let n_next = self.normals[j];
                let theta = cross(nrm, n_next).abs().atan2(nrm.dot(n_next));
                if theta > 0.0 {
                    let sa = 0.5 * theta * r * r;
                    let half = 0.5 * theta;
                    let (sin_h, cos_h) = half.sin_cos();
                    let dir = cos_h * nrm + sin_h * nrm.perp();
                    let dist = 4.0 * r * sin_h / (3.0 * theta);
                    let c = b_v + dist * dir - o;
                    // About the apex: sa r²/2; shift to the sector centroid.
                    m.add(sa, c, sa * (0.5 * r * r - dist * dist));
                }
            }
        }
        m.finish(density, o)
    }
}

impl Shape {
    /// Area in square metres (0 for segments and chain segments).
    pub fn area(&self) -> Real {
        match self {
            Shape::Circle(c) => c.area(),
            Shape::Capsule(c) => c.area(),
            Shape::Polygon(p) => p.area(),
            Shape::Segment(_) | Shape::ChainSegment(_) => 0.0,
        }
    }

    /// Mass, local centre of mass and rotational inertia about that centre for
    /// `density` in kg/m². Segments and chain segments have zero mass (their
    /// centre is their midpoint).
    pub fn compute_mass(&self, density: Real) -> MassData {
        match self {
            Shape::Circle(c) => c.compute_mass(density),
            Shape::Capsule(c) => c.compute_mass(density),
            Shape::Polygon(p) => p.compute_mass(density),
            Shape::Segment(_) | Shape::ChainSegment(_) => MassData {
                mass: 0.0,
                center: self.centroid(),
                rotational_inertia: 0.0,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::shapes::{ChainSegment, Segment};

    /// Relative tolerance: 1e-5 holds in f32, 1e-10 in f64.
    #[cfg(not(feature = "f64"))]
    const REL: Real = 1e-5;
    #[cfg(feature = "f64")]
    const REL: Real = 1e-10;

    fn close(a: Real, b: Real) -> bool {
        (a - b).abs() <= REL * b.abs().max(1.0)
    }

    #[test]
    fn box_mass_matches_closed_form() {
        let (hx, hy, rho) = (1.5, 0.5, 2.0);
        let md = Shape::Polygon(Polygon::make_box(hx, hy)).compute_mass(rho);
        let m = rho * 4.0 * hx * hy;
        let i = m * (4.0 * hx * hx + 4.0 * hy * hy) / 12.0;
        assert!(close(md.mass, m), "{} vs {m}", md.mass);
        assert!(
            close(md.rotational_inertia, i),
            "{} vs {i}",
            md.rotational_inertia
        );
        assert!(md.center.length() < REL);

        // Offset, turned box: same mass and inertia about its own centre.
        let c = Vec2::new(3.0, -2.0);
        let md2 = Polygon::make_offset_box(hx, hy, c, 0.7).compute_mass(rho);
        assert!(close(md2.mass, m));
        assert!(
            close(md2.rotational_inertia, i),
            "{} vs {i}",
            md2.rotational_inertia
        );
        assert!((md2.center - c).length() < 10.0 * REL);
    }

    #[test]
    fn circle_mass_matches_closed_form() {
        let c = Circle::new(Vec2::new(1.0, 2.0), 0.75).unwrap();
        let md = Shape::Circle(c).compute_mass(3.0);
        let m = 3.0 * PI * 0.75 * 0.75;
        assert!(close(md.mass, m));
        assert!(close(md.rotational_inertia, 0.5 * m * 0.75 * 0.75));
        assert_eq!(md.center, Vec2::new(1.0, 2.0));
    }

    #[test]
    fn capsule_mass_matches_closed_form_and_polygon_form() {
        let (r, l, rho) = (0.25, 2.0, 1.5);
        let cap = Capsule::new(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0), r).unwrap();
        let md = cap.compute_mass(rho);
        // Independent closed form: rectangle + full disc + parallel axis of
        // each half disc (centroid 4r/3π from its flat side).
        let m_rect = rho * 2.0 * r * l;
        let m_half = 0.5 * rho * PI * r * r;
        let k = 4.0 * r / (3.0 * PI);
        let i_half_cm = m_half * (0.5 * r * r - k * k);
        let i = m_rect * (l * l + 4.0 * r * r) / 12.0
            + 2.0 * (i_half_cm + m_half * (0.5 * l + k).powi(2));
        assert!(close(md.mass, m_rect + 2.0 * m_half));
        assert!(
            close(md.rotational_inertia, i),
            "{} vs {i}",
            md.rotational_inertia
        );
        assert!(close(cap.area(), 2.0 * r * l + PI * r * r));

        // The general rounded-polygon path agrees on the 2-vertex form.
        let p = Polygon::make_capsule(cap.center1, cap.center2, r);
        let mp = p.compute_mass(rho);
        assert!(close(mp.mass, md.mass));
        assert!(
            close(mp.rotational_inertia, i),
            "{} vs {i}",
            mp.rotational_inertia
        );
        assert!(mp.center.length() < REL);
    }

    #[test]
    fn rounded_box_mass_is_exact() {
        let (hx, hy, r, rho) = (1.0, 0.5, 0.2, 1.0);
        let p = Polygon::make_rounded_box(hx, hy, r);
        let area = 4.0 * hx * hy + 2.0 * (2.0 * hx + 2.0 * hy) * r + PI * r * r;
        assert!(close(p.area(), area));
        let md = p.compute_mass(rho);
        assert!(close(md.mass, area));
        // Independent decomposition: cross of two rectangles + 4 quarter discs.
        let (w, h) = (2.0 * hx, 2.0 * hy);
        let m1 = (w + 2.0 * r) * h; // wide rectangle
        let i1 = m1 * ((w + 2.0 * r).powi(2) + h * h) / 12.0;
        let m2 = w * r; // top and bottom strips
        let i2 = 2.0 * (m2 * (w * w + r * r) / 12.0 + m2 * (hy + 0.5 * r).powi(2));
        let mq = 0.25 * PI * r * r; // quarter disc
        let k = 4.0 * r / (3.0 * PI);
        let iq_cm = 0.5 * mq * r * r - mq * 2.0 * k * k;
        let iq = 4.0 * (iq_cm + mq * ((hx + k).powi(2) + (hy + k).powi(2)));
        let i = i1 + i2 + iq;
        assert!(
            close(md.rotational_inertia, i),
            "{} vs {i}",
            md.rotational_inertia
        );
        assert!(md.center.length() < REL);
    }

    #[test]
    fn hull_triangle_mass_and_centroid() {
        let p = Polygon::from_hull(
            &[
                Vec2::new(0.0, 0.0),
                Vec2::new(3.0, 0.0),
                Vec2::new(0.0, 3.0),
            ],
            0.0,
        )
        .unwrap();
        let md = p.compute_mass(2.0);
        assert!(close(md.mass, 9.0));
        assert!((md.center - Vec2::new(1.0, 1.0)).length() < 10.0 * REL);
        // Right isoceles triangle with legs a: I_cm = m a² / 9.
        assert!(close(md.rotational_inertia, 9.0 * 9.0 / 9.0));
    }

    #[test]
    fn segments_have_no_mass() {
        let s = Segment::new(Vec2::new(0.0, 0.0), Vec2::new(2.0, 0.0)).unwrap();
        let md = Shape::Segment(s).compute_mass(10.0);
        assert_eq!(md.mass, 0.0);
        assert_eq!(md.rotational_inertia, 0.0);
        assert_eq!(md.center, Vec2::new(1.0, 0.0));
        let c = Shape::ChainSegment(ChainSegment {
            ghost1: s.point1,
            segment: s,
            ghost2: s.point2,
        });
        assert_eq!(c.area(), 0.0);
        assert_eq!(c.compute_mass(1.0).mass, 0.0);
    }
}
