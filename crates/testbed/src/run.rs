//! Timing as Box2D's benchmark does it, on any [`Engine`], and the sanity
//! figures that show a run did the same work as Box2D.
//!
//! ```text
//!  repeat r = 1..R:   fresh world ─ step 0 (untimed) ─┬─ steps 1..N−1 ─┐ one block
//!                                                     └── timed ───────┘
//!  reported: the minimum block over the repeats (total ms, ms/step), the
//!  stage times averaged over that block's steps, and the sanity figures
//!  after its last step.
//! ```

use std::time::Instant;

use crate::desc::{ANGLE_TOLERANCE, COUNT_TOLERANCE, POSITION_TOLERANCE, Reference, SceneDesc};
use crate::engine::{BodyReading, Engine, EngineOptions, StageTimes, scripted_step};
use crate::measure::outside_container;

/// What a run left behind: the figures compared with Box2D's.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sanity {
    /// Bodies in the world.
    pub bodies: usize,
    /// Awake bodies.
    pub awake: usize,
    /// Touching shape pairs.
    pub touching: usize,
    /// The probe's state.
    pub probe: Option<BodyReading>,
    /// Dynamic bodies outside the container (None: the scene has none).
    pub outside: Option<usize>,
}

impl Sanity {
    /// Reads the figures off an engine after its last step.
    pub fn read<E: Engine>(engine: &E, desc: &SceneDesc) -> Sanity {
        let mut dynamic = Vec::new();
        engine.dynamic_states(&mut dynamic);
        let container_state = desc
            .container
            .as_ref()
            .and_then(|c| c.body)
            .and_then(|b| engine.state(b));
        Sanity {
            bodies: engine.body_count(),
            awake: engine.awake_count(),
            touching: engine.touching_count(),
            probe: desc.probe.and_then(|p| engine.state(p)),
            outside: desc
                .container
                .as_ref()
                .map(|_| outside_container(desc, container_state, &dynamic)),
        }
    }

    /// The figures that differ from Box2D's stored reference (the scene's
    /// [`Reference`]) by more than the tolerances of [`crate::desc`], as
    /// text (empty: same work).
    #[must_use]
    pub fn flags(&self, desc: &SceneDesc) -> Vec<String> {
        self.flags_against(&desc.reference)
    }

    /// These figures as a reference for another run (Box2D's, measured in
    /// the same run, is what the peers benchmark compares with).
    #[must_use]
    pub fn as_reference(&self) -> Reference {
        Reference {
            touching: Some(self.touching as f64),
            awake: Some(self.awake as f64),
            bodies: Some(self.bodies as f64),
            probe_position: self.probe.map(|p| p.position),
            probe_angle: self.probe.map(|p| p.angle),
        }
    }

    /// The figures that differ from `r` by more than the tolerances of
    /// [`crate::desc`], as text; bodies outside the container are always
    /// flagged.
    #[must_use]
    pub fn flags_against(&self, r: &Reference) -> Vec<String> {
        let mut out = Vec::new();
        let count = |name: &str, value: usize, reference: Option<f64>, out: &mut Vec<String>| {
            if let Some(reference) = reference
                && ((value as f64 - reference).abs() > COUNT_TOLERANCE * reference)
            {
                out.push(format!("{name} {value} vs Box2D {reference:.0}"));
            }
        };
        count("touching", self.touching, r.touching, &mut out);
        count("awake", self.awake, r.awake, &mut out);
        count("bodies", self.bodies, r.bodies, &mut out);
        if let Some(p) = self.probe {
            if let Some(rp) = r.probe_position
                && (p.position - rp).length() > POSITION_TOLERANCE
            {
                out.push(format!(
                    "probe ({:.3}, {:.3}) vs Box2D ({:.3}, {:.3})",
                    p.position.x, p.position.y, rp.x, rp.y
                ));
            }
            // Angles compare modulo a full turn (engines wrap differently).
            let turn = std::f64::consts::TAU;
            if let Some(ra) = r.probe_angle
                && ((p.angle - ra + 0.5 * turn).rem_euclid(turn) - 0.5 * turn).abs()
                    > ANGLE_TOLERANCE
            {
                out.push(format!("probe angle {:.3} vs Box2D {ra:.3}", p.angle));
            }
        }
        if let Some(n) = self.outside
            && n > 0
        {
            out.push(format!("{n} bodies outside the container"));
        }
        out
    }
}

/// One scene timed on one engine.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Timing {
    /// Minimum over the repeats of the timed block, ms.
    pub total_ms: f64,
    /// Steps in the timed block.
    pub timed_steps: usize,
    /// Stage times averaged over the best block's steps, ms.
    pub stages: StageTimes,
    /// Figures after the best block's last step.
    pub sanity: Sanity,
}

impl Timing {
    /// ms per timed step.
    #[must_use]
    pub fn ms_per_step(&self) -> f64 {
        self.total_ms / self.timed_steps.max(1) as f64
    }
}

/// Times `desc` on `E`: `repeats` fresh worlds of `steps` steps each (the
/// scene's own count if `None`).
pub fn time_scene<E: Engine>(
    desc: &SceneDesc,
    options: EngineOptions,
    repeats: usize,
    steps: Option<usize>,
) -> Result<Timing, String> {
    let steps = steps.unwrap_or(desc.steps).max(2);
    let mut best: Option<Timing> = None;
    let mut buf = Vec::new();
    for _ in 0..repeats.max(1) {
        let mut engine = E::build(desc, options)?;
        scripted_step(&mut engine, desc, 0, &mut buf);
        let mut stages = StageTimes::default();
        let start = Instant::now();
        for k in 1..steps {
            scripted_step(&mut engine, desc, k, &mut buf);
            stages.accumulate(&engine.stage_times());
        }
        let total_ms = start.elapsed().as_secs_f64() * 1e3;
        if best.as_ref().is_none_or(|b| total_ms < b.total_ms) {
            best = Some(Timing {
                total_ms,
                timed_steps: steps - 1,
                stages: stages.scaled((steps - 1) as f64),
                sanity: Sanity::read(&engine, desc),
            });
        }
    }
    Ok(best.expect("at least one repeat"))
}
