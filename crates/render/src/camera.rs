//! The camera: which part of the world a picture shows.
//!
//! ```text
//!   world (m, y up)                      picture (px, y down)
//!   center ──────────────▶ (width/2, height/2)
//!   x ↦ width/2  + scale·(x − center.x)
//!   y ↦ height/2 − scale·(y − center.y)
//! ```
//!
//! [`Camera::fit`] frames a box (the scene's, [`scene_bounds`]) with a
//! margin; [`Camera::follow`] keeps the zoom and centres a body.

use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::geometry::Aabb;
use janus2d_core::math::{Real, Vec2, from_f64, to_f64};
use janus2d_world::World;

/// A view of the world: a centre, a zoom and a picture size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World point at the picture's centre, m.
    pub center: [f64; 2],
    /// Pixels per metre (> 0).
    pub scale: f64,
    /// Picture width, px.
    pub width: u32,
    /// Picture height, px.
    pub height: u32,
}

impl Camera {
    /// A camera at `center` with `scale` pixels per metre.
    #[must_use]
    pub fn new(center: Vec2, scale: f64, width: u32, height: u32) -> Camera {
        Camera {
            center: [to_f64(center.x), to_f64(center.y)],
            scale,
            width: width.max(1),
            height: height.max(1),
        }
    }

    /// The camera that shows all of `bounds` with `margin` (a fraction of
    /// the picture, e.g. 0.05) left free on the tighter side. An empty or
    /// degenerate box gets a 1 m view.
    #[must_use]
    pub fn fit(bounds: &Aabb, width: u32, height: u32, margin: f64) -> Camera {
        let (w, h) = (f64::from(width.max(1)), f64::from(height.max(1)));
        let lo = [to_f64(bounds.lower.x), to_f64(bounds.lower.y)];
        let hi = [to_f64(bounds.upper.x), to_f64(bounds.upper.y)];
        let finite = lo.iter().chain(&hi).all(|v| v.is_finite());
        let (ext_x, ext_y) = if finite {
            ((hi[0] - lo[0]).max(1e-3), (hi[1] - lo[1]).max(1e-3))
        } else {
            (1.0, 1.0)
        };
        let center = if finite {
            [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])]
        } else {
            [0.0, 0.0]
        };
        let free = (1.0 - 2.0 * margin.clamp(0.0, 0.45)).max(0.1);
        let scale = (free * w / ext_x).min(free * h / ext_y);
        Camera {
            center,
            scale,
            width: width.max(1),
            height: height.max(1),
        }
    }

    /// The camera fitted to the world's shapes ([`scene_bounds`]).
    #[must_use]
    pub fn fit_world(world: &World, width: u32, height: u32) -> Camera {
        Camera::fit(&scene_bounds(world), width, height, 0.05)
    }

    /// Centres the camera on `body`'s centre of mass (zoom kept); a body
    /// that does not resolve leaves the camera where it is.
    pub fn follow(&mut self, world: &World, body: BodyHandle) {
        if let Ok(c) = world.center_of_mass(body) {
            self.center = [to_f64(c.x), to_f64(c.y)];
        }
    }

    /// A world point in picture coordinates (px, y down).
    #[must_use]
    pub fn to_screen(&self, p: Vec2) -> (f32, f32) {
        let x = f64::from(self.width) * 0.5 + self.scale * (to_f64(p.x) - self.center[0]);
        let y = f64::from(self.height) * 0.5 - self.scale * (to_f64(p.y) - self.center[1]);
        (x as f32, y as f32)
    }

    /// A picture point (px, y down) in world coordinates.
    #[must_use]
    pub fn to_world(&self, x: f32, y: f32) -> Vec2 {
        let wx = self.center[0] + (f64::from(x) - f64::from(self.width) * 0.5) / self.scale;
        let wy = self.center[1] - (f64::from(y) - f64::from(self.height) * 0.5) / self.scale;
        Vec2::new(from_f64(wx), from_f64(wy))
    }

    /// A length in metres as pixels.
    #[must_use]
    pub fn pixels(&self, metres: Real) -> f32 {
        (self.scale * to_f64(metres)) as f32
    }

    /// The world box the picture shows (for culling with
    /// `DrawOptions::bounds`).
    #[must_use]
    pub fn visible_box(&self) -> Aabb {
        let a = self.to_world(0.0, self.height as f32);
        let b = self.to_world(self.width as f32, 0.0);
        Aabb::new(a.min(b), a.max(b))
    }
}

fn union(acc: Option<Aabb>, b: &Aabb) -> Option<Aabb> {
    Some(acc.map_or(*b, |a| a.union(b)))
}

/// The box around every shape of the world, a moving body's shapes as the
/// disc they sweep turning about its centre of mass; when the static shapes reach
/// more than 20 times beyond the moving ones both ways (a huge static
/// box around a small pile), the moving bodies' box grown to 3 times its
/// size, clipped to the whole. A moving body without shapes counts as a
/// 1 m box around its origin. An empty world gives a 2 m box around the origin.
#[must_use]
pub fn scene_bounds(world: &World) -> Aabb {
    let mut all: Option<Aabb> = None;
    let mut moving: Option<Aabb> = None;
    for body in world.body_handles() {
        let dynamic = world.body_type(body).is_ok_and(|t| t != BodyType::Static);
        let shapes = world.body_shapes(body).unwrap_or_default();
        let mut own: Option<Aabb> = None;
        for s in &shapes {
            if let Ok(d) = world.shape(*s) {
                own = union(own, &d.aabb);
            }
        }
        if let Some(mut b) = own {
            // A moving body counts as the disc its shapes sweep turning
            // about its centre of mass: a drum turning on a pin stays in
            // view at every angle, not only at the first.
            if dynamic
                && let Ok(c) = world.center_of_mass(body)
                && c.is_finite()
            {
                let reach = [
                    b.lower,
                    b.upper,
                    Vec2::new(b.lower.x, b.upper.y),
                    Vec2::new(b.upper.x, b.lower.y),
                ]
                .iter()
                .map(|p| (*p - c).length())
                .fold(0.0 as Real, Real::max);
                if reach.is_finite() {
                    b = b.union(&Aabb::new(c - Vec2::splat(reach), c + Vec2::splat(reach)));
                }
            }
            all = union(all, &b);
            if dynamic {
                moving = union(moving, &b);
            }
        }
        // A moving body without shapes (the bridge's planks have a mass
        // and no shapes): a 1 m box around its origin, so that the joints
        // drawn between such bodies are in view.
        if dynamic
            && shapes.is_empty()
            && let Ok(p) = world.position(body)
            && p.is_finite()
        {
            let b = Aabb::new(p - Vec2::splat(0.5), p + Vec2::splat(0.5));
            all = union(all, &b);
            moving = union(moving, &b);
        }
    }
    let Some(all) = all else {
        return Aabb::new(Vec2::splat(-1.0), Vec2::splat(1.0));
    };
    let wide = |b: &Aabb, m: &Aabb| {
        let (e, f) = (b.upper - b.lower, m.upper - m.lower);
        to_f64(e.x) > 20.0 * to_f64(f.x.max(0.5)) && to_f64(e.y) > 20.0 * to_f64(f.y.max(0.5))
    };
    match moving {
        Some(m) if wide(&all, &m) => {
            let c = 0.5 * (m.lower + m.upper);
            let h = 1.5 * (m.upper - m.lower);
            let grown = Aabb::new(c - h, c + h);
            Aabb::new(grown.lower.max(all.lower), grown.upper.min(all.upper))
        }
        _ => all,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_fit() {
        let b = Aabb::new(Vec2::new(-10.0, 0.0), Vec2::new(10.0, 5.0));
        let cam = Camera::fit(&b, 400, 300, 0.05);
        // 20 m wide into 90% of 400 px: 18 px/m (the height allows 54).
        assert!((cam.scale - 18.0).abs() < 1e-9);
        for p in [b.lower, b.upper, Vec2::new(3.0, 2.0)] {
            let (x, y) = cam.to_screen(p);
            assert!((0.0..=400.0).contains(&x) && (0.0..=300.0).contains(&y));
            let q = cam.to_world(x, y);
            assert!((q - p).length() < 1e-3);
        }
        let (x0, _) = cam.to_screen(b.lower);
        assert!((x0 - 20.0).abs() < 1e-3, "5% margin: {x0}");
        let v = cam.visible_box();
        assert!(v.contains(&b));
    }

    #[test]
    fn degenerate_boxes_fit() {
        let p = Aabb::new(Vec2::ONE, Vec2::ONE);
        let cam = Camera::fit(&p, 100, 100, 0.0);
        assert!(cam.scale.is_finite() && cam.scale > 0.0);
        let nan = Aabb::new(Vec2::splat(Real::NAN), Vec2::ONE);
        let cam = Camera::fit(&nan, 100, 100, 0.0);
        assert!(cam.scale.is_finite());
    }
}
