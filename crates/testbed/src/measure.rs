//! Metric code shared by every engine: figures computed from the scene
//! description and the poses an engine reports, never from the engine's own
//! contact data, so that three engines are measured by one yardstick.
//!
//! | figure         | unit | definition                                                |
//! |----------------|------|-----------------------------------------------------------|
//! | penetration    | m    | deepest overlap of any two shapes that may collide, at the current poses (janus2d's narrowphase run on the description's shapes) |
//! | joint gap      | m    | largest distance between the two world anchors of a joint |
//! | sink / drift   | m    | how far the probe's origin went below / sideways of its start |
//! | peak speed     | m/s  | largest linear speed of any dynamic body                  |
//! | outside        | 1    | dynamic bodies whose origin is outside the scene's container |

use std::collections::BTreeSet;

use glam::DVec2;
use janus2d_core::geometry::{Shape, collide};
use janus2d_core::math::{Real, Transform, to_f64};

use janus2d_world::Filter;

use crate::desc::{BodyKind, SceneDesc};
use crate::engine::BodyReading;
use crate::janus::{filter, shapes_of, vec};

struct IndexedShape {
    body: usize,
    shape: Shape,
    filter: Filter,
    moving: bool,
}

/// The scene's shapes, ready to be placed at any engine's poses.
pub struct ShapeIndex {
    shapes: Vec<IndexedShape>,
    /// Body pairs (low, high) joined by a joint that does not collide.
    joined: BTreeSet<(usize, usize)>,
}

impl ShapeIndex {
    /// Indexes the initial bodies of `desc`.
    #[must_use]
    pub fn new(desc: &SceneDesc) -> ShapeIndex {
        let mut shapes = Vec::new();
        for (body, b) in desc.bodies.iter().enumerate() {
            for s in &b.shapes {
                for shape in shapes_of(&s.geometry).unwrap_or_default() {
                    shapes.push(IndexedShape {
                        body,
                        shape,
                        filter: filter(&s.filter),
                        moving: b.kind != BodyKind::Static,
                    });
                }
            }
        }
        let joined = desc
            .all_joints()
            .filter(|j| !j.collide_connected())
            .map(|j| {
                let (a, b) = j.bodies();
                (a.min(b), a.max(b))
            })
            .collect();
        ShapeIndex { shapes, joined }
    }

    /// Deepest overlap (≥ 0, m) of any two shapes that may collide, with
    /// body `i` at `states[i]` (a body without a state is skipped).
    #[must_use]
    pub fn deepest_overlap(&self, states: &[Option<BodyReading>]) -> f64 {
        struct Placed {
            shape: usize,
            xf: Transform,
            lower: DVec2,
            upper: DVec2,
        }
        let mut placed: Vec<Placed> = Vec::with_capacity(self.shapes.len());
        for (k, s) in self.shapes.iter().enumerate() {
            let Some(st) = states.get(s.body).copied().flatten() else {
                continue;
            };
            let xf = Transform::new(vec(st.position), st.angle as Real);
            let aabb = s.shape.compute_aabb(&xf);
            placed.push(Placed {
                shape: k,
                xf,
                lower: DVec2::new(to_f64(aabb.lower.x), to_f64(aabb.lower.y)),
                upper: DVec2::new(to_f64(aabb.upper.x), to_f64(aabb.upper.y)),
            });
        }
        placed.sort_by(|a, b| a.lower.x.total_cmp(&b.lower.x).then(a.shape.cmp(&b.shape)));
        let mut deepest: f64 = 0.0;
        for (i, a) in placed.iter().enumerate() {
            let sa = &self.shapes[a.shape];
            for b in &placed[i + 1..] {
                if b.lower.x > a.upper.x {
                    break;
                }
                let sb = &self.shapes[b.shape];
                if sa.body == sb.body
                    || !(sa.moving || sb.moving)
                    || b.lower.y > a.upper.y
                    || b.upper.y < a.lower.y
                    || !sa.filter.should_collide(&sb.filter)
                    || self
                        .joined
                        .contains(&(sa.body.min(sb.body), sa.body.max(sb.body)))
                {
                    continue;
                }
                let m = collide(&sa.shape, &a.xf, &sb.shape, &b.xf, 0.0);
                for p in m.points() {
                    deepest = deepest.max(-to_f64(p.separation));
                }
            }
        }
        deepest
    }
}

/// Largest distance between the world anchors of the scene's revolute
/// `joints` (the other kinds' anchors need not meet).
#[must_use]
pub fn max_joint_gap(desc: &SceneDesc, states: &[Option<BodyReading>]) -> f64 {
    let world_point =
        |st: &BodyReading, local: DVec2| st.position + DVec2::from_angle(st.angle).rotate(local);
    desc.joints
        .iter()
        .filter_map(|j| {
            let a = states.get(j.body_a).copied().flatten()?;
            let b = states.get(j.body_b).copied().flatten()?;
            Some((world_point(&a, j.local_a) - world_point(&b, j.local_b)).length())
        })
        .fold(0.0, f64::max)
}

/// Dynamic bodies whose origin lies outside the scene's container (0 when
/// it has none).
#[must_use]
pub fn outside_container(
    desc: &SceneDesc,
    container_state: Option<BodyReading>,
    dynamic: &[BodyReading],
) -> usize {
    let Some(c) = &desc.container else {
        return 0;
    };
    let frame = match c.body {
        Some(_) => match container_state {
            Some(s) => s,
            None => return 0,
        },
        None => BodyReading::default(),
    };
    let to_local = DVec2::from_angle(-frame.angle);
    dynamic
        .iter()
        .filter(|st| {
            !c.region
                .contains(to_local.rotate(st.position - frame.position))
        })
        .count()
}

/// Largest linear speed of the given bodies.
#[must_use]
pub fn peak_speed(dynamic: &[BodyReading]) -> f64 {
    dynamic
        .iter()
        .map(|s| s.linear_velocity.length())
        .fold(0.0, f64::max)
}
