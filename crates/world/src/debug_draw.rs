//! Debug drawing: the world described as primitives (polygons, circles,
//! capsules, segments, points, transforms, text) handed to a
//! [`DebugDraw`] implementation, as Box2D's `b2DebugDraw`.
//!
//! [`World::debug_draw`] walks the world through its public accessors and
//! calls the drawer once per primitive; nothing is computed, allocated or
//! stored for drawing unless someone calls it (no cost when nobody draws).
//! Every point is in world coordinates, metres; the renderers of
//! `janus2d-render` (PNG, SVG, GIF) implement the trait.
//!
//! What gets drawn per flag of [`DrawOptions`]:
//!
//! | flag               | default | primitives                                                        |
//! |--------------------|---------|-------------------------------------------------------------------|
//! | `shapes`           | on      | circles ([`DebugDraw::solid_circle`], with a radius line showing the turn), capsules ([`DebugDraw::solid_capsule`]), polygons ([`DebugDraw::solid_polygon`], rounded by their radius), segments ([`DebugDraw::segment`]), chain segments as a segment with a short tick from its middle along its front normal (the side that collides; a fifth of its length, at most 0.25 m); coloured by body type; shapes of disabled bodies ([`World::set_body_enabled`]) always in [`Palette::disabled`]. A shape offset ([`ShapeDef::offset`](crate::ShapeDef::offset)) is in the stored geometry, so offset shapes draw where they are |
//! | `sleep`            | on      | shapes of sleeping (enabled) bodies in [`Palette::sleeping`]      |
//! | `islands`          | off     | shapes coloured by island; one outline box ([`DebugDraw::polygon`]) per island around its members' boxes, with its id as [`DebugDraw::text`] |
//! | `joints`           | on      | per joint (every kind): body origin → anchor a → anchor b ← body origin ([`DebugDraw::segment`]), both anchors as [`DebugDraw::point`]; a prismatic or wheel joint's axis through anchor a (`draw_scale` m long) with its limits as points; a mouse joint's target and pull; a motor joint's target point; a filter joint only as a line between its bodies; disabled joints in [`Palette::joint_disabled`] |
//! | `contacts`         | off     | one [`DebugDraw::point`] per manifold point of a solid contact: touching in [`Palette::contact_touching`], speculative (separation > 0) in [`Palette::contact_speculative`] |
//! | `contact_normals`  | off     | a segment of `normal_length` along the contact normal at each point |
//! | `contact_impulses` | off     | a segment of `impulse_scale × normal impulse` along the normal at each point |
//! | `aabbs`            | off     | each shape's tight world box as a [`DebugDraw::polygon`]          |
//! | `transforms`       | off     | each body's frame ([`DebugDraw::transform`]) and centre of mass ([`DebugDraw::point`]) |
//! | `portals`          | on      | per portal: its aperture ([`DebugDraw::segment`]), its outward normal, a label `a`/`b` with η ([`DebugDraw::text`]); a faint segment linking the pair |
//! | `apertures`        | off     | the last step's contact clipping regions (the aperture clipping's regions): the hole in a wall (as deep as the aperture is wide) and the half-space behind a crossing copy, as [`DebugDraw::polygon`] |
//! | `crossings`        | on      | per crossing: a segment from the original's centre of mass to its clone's, both as points |
//!
//! Without the `portals` feature the last three flags draw nothing.
//! `bounds` culls: with `Some(box)`, only shapes (and their boxes) whose
//! world box overlaps it are drawn.
//!
//! ```
//! use janus2d_world::debug_draw::{Color, DebugDraw, DrawOptions};
//! use janus2d_world::{ShapeDef, World, WorldDef};
//! use janus2d_core::{BodyDef, Vec2, Real};
//! use janus2d_core::geometry::Polygon;
//!
//! #[derive(Default)]
//! struct Count { polygons: usize }
//! impl DebugDraw for Count {
//!     fn polygon(&mut self, _: &[Vec2], _: Color) {}
//!     fn solid_polygon(&mut self, _: &[Vec2], _: Real, _: Color) { self.polygons += 1; }
//!     fn circle(&mut self, _: Vec2, _: Real, _: Color) {}
//!     fn solid_circle(&mut self, _: Vec2, _: Real, _: Vec2, _: Color) {}
//!     fn solid_capsule(&mut self, _: Vec2, _: Vec2, _: Real, _: Color) {}
//!     fn segment(&mut self, _: Vec2, _: Vec2, _: Color) {}
//!     fn point(&mut self, _: Vec2, _: f32, _: Color) {}
//! }
//!
//! let mut world = World::new(WorldDef::default()).unwrap();
//! let b = world.create_body(&BodyDef::dynamic(Vec2::ZERO)).unwrap();
//! world.create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5)).unwrap();
//! let mut count = Count::default();
//! world.debug_draw(&mut count, &DrawOptions::default());
//! assert_eq!(count.polygons, 1);
//! ```

use std::collections::BTreeMap;

use janus2d_core::body::{BodyHandle, BodyType};
use janus2d_core::geometry::{Aabb, Shape};
use janus2d_core::math::{Real, Transform, Vec2};

use crate::world::World;

/// A colour, linear components in `[0, 1]` (alpha 1: opaque).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Color {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Alpha (opacity).
    pub a: f32,
}

impl Color {
    /// An opaque colour.
    #[must_use]
    pub const fn rgb(r: f32, g: f32, b: f32) -> Color {
        Color { r, g, b, a: 1.0 }
    }

    /// The same colour with another alpha.
    #[must_use]
    pub const fn with_alpha(self, a: f32) -> Color {
        Color { a, ..self }
    }

    /// The colour scaled towards black by `k` in `[0, 1]` (alpha kept).
    #[must_use]
    pub fn darker(self, k: f32) -> Color {
        let k = k.clamp(0.0, 1.0);
        Color {
            r: self.r * k,
            g: self.g * k,
            b: self.b * k,
            a: self.a,
        }
    }

    /// The colour as 8-bit RGBA.
    #[must_use]
    pub fn to_rgba8(self) -> [u8; 4] {
        let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0).round() as u8;
        [q(self.r), q(self.g), q(self.b), q(self.a)]
    }

    /// A distinct, stable colour for an integer id (islands): hues spread by
    /// the golden ratio.
    #[must_use]
    pub fn of_id(id: u32) -> Color {
        let h = (id as f32 * 0.618_034).fract();
        hsv(h, 0.55, 0.95)
    }
}

/// HSV (all in `[0, 1]`) to an opaque colour.
fn hsv(h: f32, s: f32, v: f32) -> Color {
    let i = (h * 6.0).floor();
    let f = h * 6.0 - i;
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - f * s), v * (1.0 - (1.0 - f) * s));
    let (r, g, b) = match (i as i32).rem_euclid(6) {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    Color::rgb(r, g, b)
}

/// The colours the walk uses (Box2D's choices where it has one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Palette {
    /// Shapes of static bodies.
    pub static_body: Color,
    /// Shapes of kinematic bodies.
    pub kinematic_body: Color,
    /// Shapes of awake dynamic bodies.
    pub dynamic_body: Color,
    /// Shapes of sleeping bodies (with the `sleep` flag).
    pub sleeping: Color,
    /// Shapes of disabled bodies (whatever the flags).
    pub disabled: Color,
    /// Sensor shapes (alpha applied to the body colour).
    pub sensor_alpha: f32,
    /// Joints.
    pub joint: Color,
    /// Disabled joints.
    pub joint_disabled: Color,
    /// Touching contact points.
    pub contact_touching: Color,
    /// Speculative contact points (separation > 0).
    pub contact_speculative: Color,
    /// Contact normals.
    pub contact_normal: Color,
    /// Contact impulses.
    pub contact_impulse: Color,
    /// Shape boxes.
    pub aabb: Color,
    /// Island boxes.
    pub island: Color,
    /// Portal a of each pair.
    pub portal_a: Color,
    /// Portal b of each pair.
    pub portal_b: Color,
    /// Aperture clipping regions.
    pub aperture: Color,
    /// Links from a crossing original to its clone.
    pub crossing: Color,
    /// Labels.
    pub text: Color,
}

impl Default for Palette {
    fn default() -> Self {
        Palette {
            static_body: Color::rgb(0.5, 0.9, 0.5),
            kinematic_body: Color::rgb(0.5, 0.5, 0.9),
            dynamic_body: Color::rgb(0.9, 0.7, 0.7),
            sleeping: Color::rgb(0.6, 0.6, 0.6),
            disabled: Color::rgb(0.35, 0.3, 0.3).with_alpha(0.5),
            sensor_alpha: 0.35,
            joint: Color::rgb(0.5, 0.8, 0.8),
            joint_disabled: Color::rgb(0.4, 0.4, 0.4),
            contact_touching: Color::rgb(1.0, 0.85, 0.2),
            contact_speculative: Color::rgb(0.3, 0.3, 0.95),
            contact_normal: Color::rgb(0.9, 0.9, 0.9),
            contact_impulse: Color::rgb(0.95, 0.25, 0.25),
            aabb: Color::rgb(0.9, 0.3, 0.9),
            island: Color::rgb(0.95, 0.95, 0.4),
            portal_a: Color::rgb(1.0, 0.55, 0.0),
            portal_b: Color::rgb(0.0, 0.65, 1.0),
            aperture: Color::rgb(0.9, 0.2, 0.9).with_alpha(0.8),
            crossing: Color::rgb(1.0, 1.0, 0.3),
            text: Color::rgb(0.95, 0.95, 0.95),
        }
    }
}

/// What [`World::debug_draw`] draws (see the module's table).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DrawOptions {
    /// Shapes, coloured by body type.
    pub shapes: bool,
    /// Sleeping bodies in the sleeping colour.
    pub sleep: bool,
    /// Shapes coloured by island, and one box per island.
    pub islands: bool,
    /// Joints (every kind).
    pub joints: bool,
    /// Contact points.
    pub contacts: bool,
    /// Contact normals.
    pub contact_normals: bool,
    /// Contact normal impulses.
    pub contact_impulses: bool,
    /// Shape boxes.
    pub aabbs: bool,
    /// Body frames and centres of mass.
    pub transforms: bool,
    /// Portal apertures, normals and pair links.
    pub portals: bool,
    /// The aperture clipping regions.
    pub apertures: bool,
    /// Links from crossing originals to their clones.
    pub crossings: bool,
    /// Only what overlaps this box (world, m); `None`: everything.
    pub bounds: Option<Aabb>,
    /// Length of a drawn contact normal, m (usual 0.3).
    pub normal_length: Real,
    /// Length of a drawn impulse per N·s, m/(N·s) (usual 0.1).
    pub impulse_scale: Real,
    /// Size of a drawn point, pixels (usual 4).
    pub point_size: f32,
    /// The colours.
    pub palette: Palette,
}

impl Default for DrawOptions {
    /// Shapes (with sleep), joints, portals and crossings; no contacts,
    /// boxes, islands, transforms or aperture regions.
    fn default() -> Self {
        DrawOptions {
            shapes: true,
            sleep: true,
            islands: false,
            joints: true,
            contacts: false,
            contact_normals: false,
            contact_impulses: false,
            aabbs: false,
            transforms: false,
            portals: true,
            apertures: false,
            crossings: true,
            bounds: None,
            normal_length: 0.3,
            impulse_scale: 0.1,
            point_size: 4.0,
            palette: Palette::default(),
        }
    }
}

impl DrawOptions {
    /// Every flag on.
    #[must_use]
    pub fn all() -> Self {
        DrawOptions {
            islands: true,
            contacts: true,
            contact_normals: true,
            contact_impulses: true,
            aabbs: true,
            transforms: true,
            apertures: true,
            ..DrawOptions::default()
        }
    }

    /// Every flag off (turn on what you need).
    #[must_use]
    pub fn none() -> Self {
        DrawOptions {
            shapes: false,
            sleep: false,
            joints: false,
            portals: false,
            crossings: false,
            ..DrawOptions::default()
        }
    }
}

/// Receives the world as primitives (world coordinates, metres). The
/// first seven are required; [`DebugDraw::transform`] has a default made of
/// two segments and [`DebugDraw::text`] one that draws nothing.
pub trait DebugDraw {
    /// A closed polygon outline through `vertices` (in order).
    fn polygon(&mut self, vertices: &[Vec2], color: Color);
    /// A filled convex polygon through `vertices` (counter-clockwise),
    /// rounded by `radius` (0: sharp corners).
    fn solid_polygon(&mut self, vertices: &[Vec2], radius: Real, color: Color);
    /// A circle outline.
    fn circle(&mut self, center: Vec2, radius: Real, color: Color);
    /// A filled disc; `axis` is the unit direction of the body's x axis
    /// (draw a radius along it to show the turn).
    fn solid_circle(&mut self, center: Vec2, radius: Real, axis: Vec2, color: Color);
    /// A filled capsule: every point within `radius` of `p1`–`p2`.
    fn solid_capsule(&mut self, p1: Vec2, p2: Vec2, radius: Real, color: Color);
    /// A line segment.
    fn segment(&mut self, p1: Vec2, p2: Vec2, color: Color);
    /// A point of `size` pixels (screen size, not metres).
    fn point(&mut self, p: Vec2, size: f32, color: Color);
    /// A frame: by default its x axis in red and y axis in green, 0.25 m.
    fn transform(&mut self, xf: &Transform) {
        const AXIS: Real = 0.25;
        let x = xf.q.rotate(Vec2::X);
        let y = xf.q.rotate(Vec2::Y);
        self.segment(xf.p, xf.p + AXIS * x, Color::rgb(1.0, 0.2, 0.2));
        self.segment(xf.p, xf.p + AXIS * y, Color::rgb(0.2, 1.0, 0.2));
    }
    /// A text label at `p` (by default not drawn).
    fn text(&mut self, p: Vec2, text: &str, color: Color) {
        let _ = (p, text, color);
    }
}

/// The outline of a box, counter-clockwise from its lower corner.
#[must_use]
pub fn box_corners(b: &Aabb) -> [Vec2; 4] {
    [
        b.lower,
        Vec2::new(b.upper.x, b.lower.y),
        b.upper,
        Vec2::new(b.lower.x, b.upper.y),
    ]
}

fn shape_color(world: &World, body: BodyHandle, island: Option<u32>, o: &DrawOptions) -> Color {
    let p = &o.palette;
    let ty = world.body_type(body).unwrap_or(BodyType::Static);
    if world.is_body_enabled(body) == Ok(false) {
        return p.disabled;
    }
    if o.sleep && world.is_sleeping(body) == Ok(true) {
        return p.sleeping;
    }
    if o.islands
        && let Some(id) = island
    {
        return Color::of_id(id);
    }
    match ty {
        BodyType::Static => p.static_body,
        BodyType::Kinematic => p.kinematic_body,
        BodyType::Dynamic => p.dynamic_body,
    }
}

fn draw_geometry<D: DebugDraw + ?Sized>(draw: &mut D, xf: &Transform, shape: &Shape, color: Color) {
    match shape {
        Shape::Circle(c) => draw.solid_circle(xf.apply(c.center), c.radius, xf.q.x_axis(), color),
        Shape::Capsule(c) => {
            draw.solid_capsule(xf.apply(c.center1), xf.apply(c.center2), c.radius, color);
        }
        Shape::Polygon(p) => {
            let mut v = [Vec2::ZERO; janus2d_core::geometry::MAX_POLYGON_VERTICES];
            for (w, l) in v.iter_mut().zip(&p.vertices[..p.count]) {
                *w = xf.apply(*l);
            }
            draw.solid_polygon(&v[..p.count], p.radius, color);
        }
        Shape::Segment(s) => draw.segment(xf.apply(s.point1), xf.apply(s.point2), color),
        Shape::ChainSegment(c) => {
            let (p1, p2) = (xf.apply(c.segment.point1), xf.apply(c.segment.point2));
            draw.segment(p1, p2, color);
            // The front normal (d.y, −d.x)/|d|: the side that collides.
            let d = p2 - p1;
            let length = d.length();
            if length > 0.0 {
                let normal = Vec2::new(d.y, -d.x) / length;
                let tick = (0.2 * length).min(0.25);
                let mid = 0.5 * (p1 + p2);
                draw.segment(mid, mid + tick * normal, color);
            }
        }
    }
}

impl World {
    /// Draws the world through `draw`: shapes, joints, contacts, boxes,
    /// islands, portals… as `options` says (see [`crate::debug_draw`]).
    /// Reads only, through the world's public accessors; costs nothing when
    /// not called.
    pub fn debug_draw(&self, draw: &mut (impl DebugDraw + ?Sized), options: &DrawOptions) {
        draw_world(self, draw, options);
    }
}

/// The walk behind [`World::debug_draw`].
fn draw_world<D: DebugDraw + ?Sized>(world: &World, draw: &mut D, o: &DrawOptions) {
    let island_of = |body| world.island_id(body);
    let visible = |b: &Aabb| o.bounds.is_none_or(|v| v.overlaps(b));
    let want_bodies = o.shapes || o.aabbs || o.islands || o.transforms;
    if want_bodies {
        let mut island_boxes: BTreeMap<u32, Aabb> = BTreeMap::new();
        for body in world.bodies().handles() {
            let Ok(xf) = world.transform(body) else {
                continue;
            };
            let island = if o.islands { island_of(body) } else { None };
            let color = shape_color(world, body, island, o);
            for sh in world.body_shapes(body).unwrap_or_default() {
                let Ok(data) = world.shape(sh) else {
                    continue;
                };
                if let Some(id) = island {
                    island_boxes
                        .entry(id)
                        .and_modify(|b| *b = b.union(&data.aabb))
                        .or_insert(data.aabb);
                }
                if !visible(&data.aabb) {
                    continue;
                }
                if o.shapes {
                    let c = if data.def.is_sensor {
                        color.with_alpha(o.palette.sensor_alpha)
                    } else {
                        color
                    };
                    draw_geometry(draw, &xf, &data.geometry, c);
                }
                if o.aabbs {
                    draw.polygon(&box_corners(&data.aabb), o.palette.aabb);
                }
            }
            if o.transforms && o.bounds.is_none_or(|v| v.overlaps(&Aabb::new(xf.p, xf.p))) {
                draw.transform(&xf);
                if let Ok(c) = world.center_of_mass(body) {
                    draw.point(c, o.point_size, o.palette.text);
                }
            }
        }
        for (id, b) in &island_boxes {
            if visible(b) {
                draw.polygon(&box_corners(b), o.palette.island);
                draw.text(
                    Vec2::new(b.lower.x, b.upper.y),
                    &format!("island {id}"),
                    o.palette.island,
                );
            }
        }
    }
    if o.joints {
        for &j in world.joint_handles() {
            let Ok(joint) = world.joint(j) else {
                continue;
            };
            let (body_a, body_b) = joint.bodies();
            let (Ok(xa), Ok(xb)) = (world.transform(body_a), world.transform(body_b)) else {
                continue;
            };
            let (anchor_a, anchor_b) = joint.local_anchors();
            let pa = xa.apply(anchor_a);
            let pb = xb.apply(anchor_b);
            if !visible(&Aabb::new(pa.min(pb), pa.max(pb))) {
                continue;
            }
            let c = if joint.is_enabled() {
                o.palette.joint
            } else {
                o.palette.joint_disabled
            };
            let scale = joint.def_base().draw_scale;
            if joint.kind() == janus2d_constraints::JointKind::Filter {
                // No rows: only a line between the two bodies.
                draw.segment(xa.p, xb.p, c);
                continue;
            }
            draw.segment(xa.p, pa, c);
            draw.segment(pa, pb, c);
            draw.segment(xb.p, pb, c);
            draw.point(pa, o.point_size, c);
            draw.point(pb, o.point_size, c);
            draw_kind(draw, joint, &xa, pa, scale, c, o.point_size);
        }
    }
    if o.contacts || o.contact_normals || o.contact_impulses {
        for c in world.contacts() {
            if !c.touching || c.sensor || !c.enabled {
                continue;
            }
            for p in &c.points[..c.point_count] {
                if !visible(&Aabb::new(p.point, p.point)) {
                    continue;
                }
                if o.contacts {
                    let color = if p.separation > 0.0 {
                        o.palette.contact_speculative
                    } else {
                        o.palette.contact_touching
                    };
                    draw.point(p.point, o.point_size, color);
                }
                if o.contact_normals {
                    draw.segment(
                        p.point,
                        p.point + o.normal_length * c.normal,
                        o.palette.contact_normal,
                    );
                }
                if o.contact_impulses {
                    let end = p.point + (o.impulse_scale * p.normal_impulse) * c.normal;
                    draw.segment(p.point, end, o.palette.contact_impulse);
                }
            }
        }
    }
    #[cfg(feature = "portals")]
    draw_portals(world, draw, o);
}

#[cfg(feature = "portals")]
fn draw_portals<D: DebugDraw + ?Sized>(world: &World, draw: &mut D, o: &DrawOptions) {
    let perp = |n: Vec2| Vec2::new(-n.y, n.x);
    if o.portals {
        for (_, def) in world.portal_pairs() {
            let mut centers = [Vec2::ZERO; 2];
            let eta = def.eta.unwrap_or(1.0);
            for (k, p) in [def.portal_a, def.portal_b].iter().enumerate() {
                let Ok(xf) = world.transform(p.body) else {
                    continue;
                };
                let c = xf.apply(p.anchor);
                let n = xf.q.rotate(p.direction);
                let t = perp(n);
                let color = if k == 0 {
                    o.palette.portal_a
                } else {
                    o.palette.portal_b
                };
                centers[k] = c;
                draw.segment(c - p.half_width * t, c + p.half_width * t, color);
                draw.segment(c, c + 0.5 * p.half_width * n, color);
                draw.point(c - p.half_width * t, o.point_size, color);
                draw.point(c + p.half_width * t, o.point_size, color);
                let label = if k == 0 {
                    format!("a (η {eta:.2})")
                } else {
                    format!("b (η {:.2})", 1.0 / eta)
                };
                draw.text(c + 0.7 * p.half_width * n, &label, color);
            }
            draw.segment(centers[0], centers[1], o.palette.portal_a.with_alpha(0.2));
        }
    }
    if o.apertures {
        let pairs: Vec<_> = world.portal_pairs().collect();
        for clip in &world.portal_clipping().clips {
            let n = clip.normal;
            let t = perp(n);
            // A copy wholly behind its plane clips the whole half-space
            // behind it: drawn as wide as its aperture.
            let aperture_width = pairs
                .iter()
                .find(|(h, _)| h.index == clip.aperture / 2)
                .map(|(_, d)| {
                    if clip.aperture % 2 == 0 {
                        d.portal_a.half_width
                    } else {
                        d.portal_b.half_width
                    }
                });
            let w = aperture_width.map_or(clip.half_width, |a| clip.half_width.min(a));
            let depth = if clip.hole { 2.0 * w } else { w };
            let c = clip.point;
            let quad = [
                c - w * t,
                c + w * t,
                c + w * t - depth * n,
                c - w * t - depth * n,
            ];
            let color = if clip.hole {
                o.palette.aperture
            } else {
                o.palette.aperture.darker(0.6)
            };
            draw.polygon(&quad, color);
        }
    }
    if o.crossings {
        for pc in world.portal_constraints() {
            let d = pc.def();
            let (Ok(a), Ok(b)) = (world.center_of_mass(d.body), world.center_of_mass(d.clone))
            else {
                continue;
            };
            draw.segment(a, b, o.palette.crossing);
            draw.point(a, o.point_size * 1.5, o.palette.crossing);
            draw.point(b, o.point_size * 1.5, o.palette.crossing);
        }
    }
}

/// What a kind draws beyond its anchors (`scale`: the joint's
/// `draw_scale`, 1 = 0.5 m): the axis of a prismatic or wheel joint
/// through anchor a (with its limits as points), a mouse joint's target,
/// a motor joint's target point on a.
fn draw_kind<D: DebugDraw + ?Sized>(
    draw: &mut D,
    joint: &janus2d_constraints::Joint,
    xa: &Transform,
    pa: Vec2,
    scale: Real,
    c: Color,
    point_size: f32,
) {
    use janus2d_constraints::Joint as J;
    let base = joint.def_base();
    let axis = || xa.q.rotate(base.local_frame_a.axis());
    let half = 0.5 * scale;
    let mut axis_with_limits = |limits: Option<(Real, Real)>| {
        let n = axis();
        draw.segment(pa - half * n, pa + half * n, c);
        if let Some((lower, upper)) = limits {
            draw.point(pa + lower * n, point_size, c);
            draw.point(pa + upper * n, point_size, c);
        }
    };
    match joint {
        J::Prismatic(j) => axis_with_limits(
            j.def()
                .enable_limit
                .then_some((j.def().lower_translation, j.def().upper_translation)),
        ),
        J::Wheel(j) => axis_with_limits(
            j.def()
                .enable_limit
                .then_some((j.def().lower_translation, j.def().upper_translation)),
        ),
        J::Mouse(j) => {
            draw.point(j.def().target, 2.0 * point_size, c);
            draw.segment(pa, j.def().target, c);
        }
        J::Motor(j) => {
            let target = xa.apply(base.local_frame_a.anchor)
                + xa.q.rotate(
                    janus2d_core::math::Rot::from_angle(base.local_frame_a.angle)
                        .rotate(j.def().linear_offset),
                );
            draw.point(target, 2.0 * point_size, c);
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ShapeDef, WorldDef};
    use janus2d_core::body::BodyDef;
    use janus2d_core::geometry::{Circle, Polygon, Segment};

    /// Counts every primitive.
    #[derive(Default, Debug)]
    struct Recorder {
        polygons: usize,
        solid_polygons: usize,
        circles: usize,
        solid_circles: usize,
        capsules: usize,
        segments: usize,
        points: usize,
        transforms: usize,
        texts: Vec<String>,
        colors: Vec<Color>,
    }

    impl DebugDraw for Recorder {
        fn polygon(&mut self, _: &[Vec2], _: Color) {
            self.polygons += 1;
        }
        fn solid_polygon(&mut self, v: &[Vec2], _: Real, c: Color) {
            assert!(v.len() >= 3);
            self.solid_polygons += 1;
            self.colors.push(c);
        }
        fn circle(&mut self, _: Vec2, _: Real, _: Color) {
            self.circles += 1;
        }
        fn solid_circle(&mut self, _: Vec2, _: Real, _: Vec2, _: Color) {
            self.solid_circles += 1;
        }
        fn solid_capsule(&mut self, _: Vec2, _: Vec2, _: Real, _: Color) {
            self.capsules += 1;
        }
        fn segment(&mut self, _: Vec2, _: Vec2, _: Color) {
            self.segments += 1;
        }
        fn point(&mut self, _: Vec2, _: f32, _: Color) {
            self.points += 1;
        }
        fn transform(&mut self, _: &Transform) {
            self.transforms += 1;
        }
        fn text(&mut self, _: Vec2, t: &str, _: Color) {
            self.texts.push(t.to_owned());
        }
    }

    fn stack(n: usize) -> World {
        let mut def = WorldDef::default();
        def.sleep.enabled = false;
        let mut world = World::new(def).unwrap();
        let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        world
            .create_shape(
                ground,
                &ShapeDef::default(),
                Segment::new(Vec2::new(-10.0, 0.0), Vec2::new(10.0, 0.0)).unwrap(),
            )
            .unwrap();
        for i in 0..n {
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.5 + i as Real)))
                .unwrap();
            world
                .create_shape(b, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
                .unwrap();
        }
        world
    }

    #[test]
    fn one_polygon_per_box_and_nothing_else_by_default() {
        let world = stack(5);
        let mut r = Recorder::default();
        // Through a trait object too.
        let d: &mut dyn DebugDraw = &mut r;
        world.debug_draw(d, &DrawOptions::default());
        assert_eq!(r.solid_polygons, 5);
        assert_eq!(r.segments, 1, "the ground segment");
        assert_eq!(r.points + r.polygons + r.transforms, 0);
        assert!(
            r.colors
                .iter()
                .all(|c| *c == Palette::default().dynamic_body)
        );
    }

    #[test]
    fn nothing_with_every_flag_off() {
        let mut world = stack(3);
        for _ in 0..30 {
            world.step(1.0 / 60.0).unwrap();
        }
        let mut r = Recorder::default();
        world.debug_draw(&mut r, &DrawOptions::none());
        assert_eq!(
            r.solid_polygons + r.segments + r.points + r.polygons + r.transforms + r.texts.len(),
            0
        );
    }

    #[test]
    fn counts_per_flag() {
        let mut world = stack(3);
        for _ in 0..60 {
            world.step(1.0 / 60.0).unwrap();
        }
        let points: usize = world
            .contacts()
            .filter(|c| c.is_solid_touching())
            .map(|c| c.point_count)
            .sum();
        // 3 boxes on a segment: 3 touching contacts of 2 points.
        assert_eq!(points, 6);
        let only = |f: fn(&mut DrawOptions)| {
            let mut o = DrawOptions::none();
            f(&mut o);
            let mut r = Recorder::default();
            world.debug_draw(&mut r, &o);
            r
        };
        assert_eq!(only(|o| o.contacts = true).points, points);
        assert_eq!(only(|o| o.contact_normals = true).segments, points);
        assert_eq!(only(|o| o.contact_impulses = true).segments, points);
        assert_eq!(only(|o| o.aabbs = true).polygons, 4, "one box per shape");
        let t = only(|o| o.transforms = true);
        assert_eq!(
            (t.transforms, t.points),
            (4, 4),
            "one frame and centre per body"
        );
        // One island: the three boxes touch each other (the ground is static).
        let i = only(|o| o.islands = true);
        assert_eq!(i.polygons, 1);
        assert_eq!(i.texts.len(), 1);
        // Culling: a box far away sees nothing.
        let far = only(|o| {
            o.shapes = true;
            o.bounds = Some(Aabb::new(Vec2::splat(100.0), Vec2::splat(101.0)));
        });
        assert_eq!(far.solid_polygons + far.segments, 0);
    }

    #[test]
    fn circles_capsules_joints_and_sleep_colours() {
        let mut world = World::new(WorldDef::default()).unwrap();
        let a = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let b = world
            .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)))
            .unwrap();
        world
            .create_shape(
                a,
                &ShapeDef::default(),
                Circle::new(Vec2::ZERO, 0.5).unwrap(),
            )
            .unwrap();
        world
            .create_shape(
                b,
                &ShapeDef::default(),
                janus2d_core::geometry::Capsule::new(Vec2::ZERO, Vec2::X, 0.2).unwrap(),
            )
            .unwrap();
        world
            .create_revolute_joint(&janus2d_constraints::RevoluteJointDef::new(
                a,
                b,
                Vec2::new(1.0, 0.0),
                Vec2::ZERO,
            ))
            .unwrap();
        let mut r = Recorder::default();
        world.debug_draw(&mut r, &DrawOptions::default());
        assert_eq!((r.solid_circles, r.capsules), (1, 1));
        assert_eq!(
            (r.segments, r.points),
            (3, 2),
            "one joint: 3 segments, 2 anchors"
        );
    }

    #[test]
    fn each_kind_draws_its_own_details() {
        use janus2d_constraints::{
            FilterJointDef, JointDef, MouseJointDef, PrismaticJointDef, WeldJointDef,
        };
        let count = |def: &dyn Fn(BodyHandle, BodyHandle) -> JointDef| {
            let mut world = World::new(WorldDef::default()).unwrap();
            let a = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
            let b = world
                .create_body(&BodyDef::dynamic(Vec2::new(1.0, 0.0)))
                .unwrap();
            world.create_joint(&def(a, b)).unwrap();
            let mut r = Recorder::default();
            world.debug_draw(&mut r, &DrawOptions::default());
            (r.segments, r.points)
        };
        let weld = count(&|a, b| WeldJointDef::new(a, b, Vec2::X, Vec2::ZERO).into());
        assert_eq!(weld, (3, 2), "the anchors only");
        let slide = count(&|a, b| {
            PrismaticJointDef::new(a, b, Vec2::X, Vec2::ZERO, Vec2::Y)
                .with_limits(-1.0, 1.0)
                .into()
        });
        assert_eq!(slide, (4, 4), "the axis, and its two limits as points");
        let mouse = count(&|a, b| {
            let mut d = MouseJointDef::new(a, b, Vec2::new(3.0, 2.0), 100.0);
            d.base.local_frame_b.anchor = Vec2::ZERO;
            d.into()
        });
        assert_eq!(mouse, (4, 3), "the pull and the target");
        let filter = count(&|a, b| FilterJointDef::new(a, b).into());
        assert_eq!(filter, (1, 0), "a line between the bodies");
    }

    #[test]
    fn island_colours_are_distinct() {
        let c: Vec<[u8; 4]> = (0..8).map(|i| Color::of_id(i).to_rgba8()).collect();
        for i in 0..c.len() {
            for j in 0..i {
                assert_ne!(c[i], c[j]);
            }
        }
    }

    #[cfg(feature = "portals")]
    #[test]
    fn portals_apertures_and_crossings() {
        use crate::{PortalDef, PortalPairDef};
        let mut world = World::new(WorldDef::default()).unwrap();
        let floor = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        let wall = world
            .create_body(&BodyDef::fixed(Vec2::new(5.0, 2.0)))
            .unwrap();
        world
            .create_portal_pair(&PortalPairDef::new(
                PortalDef {
                    body: floor,
                    anchor: Vec2::ZERO,
                    direction: Vec2::Y,
                    half_width: 1.0,
                },
                PortalDef {
                    body: wall,
                    anchor: Vec2::ZERO,
                    direction: Vec2::new(-1.0, 0.0),
                    half_width: 1.0,
                },
            ))
            .unwrap();
        let only = |world: &World, f: fn(&mut DrawOptions)| {
            let mut o = DrawOptions::none();
            f(&mut o);
            let mut r = Recorder::default();
            world.debug_draw(&mut r, &o);
            r
        };
        let p = only(&world, |o| o.portals = true);
        // Per portal: aperture, normal; plus the pair link.
        assert_eq!(p.segments, 5);
        assert_eq!(p.points, 4);
        assert_eq!(p.texts.len(), 2);
        let box_ = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, 0.6)))
            .unwrap();
        world
            .create_shape(box_, &ShapeDef::default(), Polygon::make_box(0.3, 0.3))
            .unwrap();
        let mut crossed = false;
        for _ in 0..60 {
            world.step(1.0 / 60.0).unwrap();
            if world.crossing_count() > 0 {
                crossed = true;
                break;
            }
        }
        assert!(crossed, "the box starts crossing");
        world.step(1.0 / 60.0).unwrap();
        let c = only(&world, |o| o.crossings = true);
        assert_eq!(c.segments, world.crossing_count());
        let a = only(&world, |o| o.apertures = true);
        // Two holes, and the two copies of the crossing in progress.
        assert_eq!(a.polygons, world.portal_clipping().clips.len());
        assert!(a.polygons >= 4, "{}", a.polygons);
    }

    /// Every segment and circle with its colour.
    #[derive(Default)]
    struct Lines {
        segments: Vec<(Vec2, Vec2, Color)>,
        circles: Vec<(Vec2, Color)>,
        polygons: Vec<Color>,
    }

    impl DebugDraw for Lines {
        fn polygon(&mut self, _: &[Vec2], _: Color) {}
        fn solid_polygon(&mut self, _: &[Vec2], _: Real, c: Color) {
            self.polygons.push(c);
        }
        fn circle(&mut self, _: Vec2, _: Real, _: Color) {}
        fn solid_circle(&mut self, p: Vec2, _: Real, _: Vec2, c: Color) {
            self.circles.push((p, c));
        }
        fn solid_capsule(&mut self, _: Vec2, _: Vec2, _: Real, _: Color) {}
        fn segment(&mut self, a: Vec2, b: Vec2, c: Color) {
            self.segments.push((a, b, c));
        }
        fn point(&mut self, _: Vec2, _: f32, _: Color) {}
    }

    /// A chain draws each segment and a tick on its colliding side; an
    /// offset circle draws at its offset; a disabled body's shapes draw in
    /// the disabled colour, asleep or not, and again in the body colour once
    /// enabled.
    #[test]
    fn chains_offsets_and_disabled_bodies() {
        use crate::ChainDef;
        let mut world = World::new(WorldDef::default()).unwrap();
        let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
        // Walked on from above: right to left; segments 4 m and 1 m long.
        let points = vec![
            Vec2::new(4.0, 0.0),
            Vec2::new(0.0, 0.0),
            Vec2::new(-1.0, 0.0),
        ];
        world.create_chain(ground, &ChainDef::new(points)).unwrap();
        let ball = world
            .create_body(&BodyDef::dynamic(Vec2::new(0.0, 3.0)))
            .unwrap();
        let def = ShapeDef::default().with_offset(Vec2::new(1.5, 0.0), 0.0);
        world
            .create_shape(ball, &def, Circle::new(Vec2::ZERO, 0.25).unwrap())
            .unwrap();
        let off = world
            .create_body(&BodyDef::dynamic(Vec2::new(-3.0, 3.0)))
            .unwrap();
        world
            .create_shape(off, &ShapeDef::default(), Polygon::make_box(0.5, 0.5))
            .unwrap();
        world.set_body_enabled(off, false).unwrap();

        let palette = Palette::default();
        let mut r = Lines::default();
        world.debug_draw(&mut r, &DrawOptions::default());
        // Two chain segments, each with its tick: 4 segments.
        assert_eq!(r.segments.len(), 4);
        let ticks: Vec<_> = r.segments.iter().filter(|(a, b, _)| a.y != b.y).collect();
        assert_eq!(ticks.len(), 2, "one tick per chain segment");
        for (a, b, c) in &ticks {
            assert_eq!(*c, palette.static_body);
            assert_eq!(a.y, 0.0);
            // Up (the colliding side of right-to-left ground), a fifth of
            // the segment's length capped at 0.25 m.
            let expected = if a.x == 2.0 { 0.25 } else { 0.2 };
            assert!(a.x == 2.0 || a.x == -0.5, "{a:?}");
            assert!((b.y - expected).abs() < 1e-6, "tick {a:?} → {b:?}");
        }
        // The circle is drawn at body origin + offset.
        assert_eq!(r.circles.len(), 1);
        assert_eq!(r.circles[0].0, Vec2::new(1.5, 3.0));
        // The disabled box: drawn, in the disabled colour (the sleeping
        // colour would be the same with and without the `sleep` flag).
        assert_eq!(r.polygons, vec![palette.disabled]);
        assert_ne!(palette.disabled, palette.sleeping);
        let mut r = Lines::default();
        world.debug_draw(
            &mut r,
            &DrawOptions {
                sleep: false,
                ..DrawOptions::default()
            },
        );
        assert_eq!(r.polygons, vec![palette.disabled]);
        world.set_body_enabled(off, true).unwrap();
        let mut r = Lines::default();
        world.debug_draw(&mut r, &DrawOptions::default());
        assert_eq!(r.polygons, vec![palette.dynamic_body]);
    }
}
