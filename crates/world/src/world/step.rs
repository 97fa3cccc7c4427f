//! The step: the pipeline that calls the stages in order over the stores
//! it passes them (see the diagram in the `world` module docs).

use super::*;

/// The default of [`World::set_team_min_work`]: a world whose step's
/// work (awake moving bodies + awake contacts + joints) is below it steps
/// on the calling thread alone, whatever rayon pool it runs in.
///
/// Waking the team (one rayon broadcast a step, and followers that wait
/// through the serial stages) costs a few to tens of µs a step; a small
/// world's parallel stages save less than that. Measured on the large
/// pyramid, 2 threads against 1, best of 5 runs of 300 steps on a 2-core
/// machine (`janus2d-peers scaling --threads 2`): 15 bodies 16–22 against
/// 13 µs, 210 bodies (≈ 610 work) 141 against 138 µs, 465 bodies
/// (≈ 1,400) 0.30 against 0.31 ms, 820 bodies (≈ 2,400) 0.46–0.49 against
/// 0.56–0.57 ms.
pub const TEAM_MIN_WORK: usize = 1024;

#[cfg(feature = "serde")]
pub(crate) fn default_team_min_work() -> usize {
    TEAM_MIN_WORK
}

/// `dt` finite, positive and within
/// [`TIME_STEP_RANGE`](janus2d_core::limits::TIME_STEP_RANGE).
pub(super) fn check_time_step(dt: Real) -> Result<(), WorldError> {
    if !(dt.is_finite() && dt > 0.0) {
        return Err(WorldError::InvalidTimeStep);
    }
    let (min, max) = janus2d_core::limits::TIME_STEP_RANGE;
    if !(min..=max).contains(&dt) {
        return Err(WorldError::OutOfBounds {
            field: "dt",
            min,
            max,
        });
    }
    Ok(())
}

impl World {
    // ----- stepping ---------------------------------------------------------

    /// The step context the solver uses for a step of `dt`: the contact
    /// and iterative joint stiffness are capped at a quarter of the
    /// substep rate ([`MAX_HERTZ_FRACTION`](janus2d_core::limits::MAX_HERTZ_FRACTION),
    /// as Box2D caps its contact hertz): a stiffer soft row cannot be
    /// resolved by the substeps (and `1e30` Hz would give no softness).
    pub fn step_context(&self, dt: Real) -> StepContext {
        let substeps = match self.settings.mode {
            janus2d_core::SolverMode::SoftStep => self.settings.substeps.max(1),
            janus2d_core::SolverMode::PgsBaumgarte => 1,
        };
        let cap = janus2d_core::limits::MAX_HERTZ_FRACTION * substeps as Real / dt;
        if self.settings.contact_hertz <= cap && self.settings.joint_hertz <= cap {
            return self.settings.context(dt, self.gravity);
        }
        let capped = SolverSettings {
            contact_hertz: self.settings.contact_hertz.min(cap),
            joint_hertz: self.settings.joint_hertz.min(cap),
            ..self.settings.clone()
        };
        capped.context(dt, self.gravity)
    }

    /// Advances the world by `dt` seconds, within
    /// [`TIME_STEP_RANGE`](janus2d_core::limits::TIME_STEP_RANGE)
    /// (1 µs … 1 s).
    ///
    /// Errors (the world unchanged): a NaN, infinite, zero or negative
    /// `dt` is [`WorldError::InvalidTimeStep`]; a positive `dt` outside
    /// the range is [`WorldError::OutOfBounds`] (`field: "dt"`). The upper
    /// bound keeps a step one sane explicit integration: the sleep timer
    /// gains `dt` each step, so a longer step would put a swinging body to
    /// sleep mid-swing, and every body would move metres between collision
    /// checks; step a long span as several steps (the solver's accuracy is
    /// for steps of a few milliseconds to 1/30 s). The lower bound keeps
    /// the substep rate and the joints' force and torque read-back
    /// (impulse over substep) finite. Every accepted `dt` keeps every
    /// number finite.
    pub fn step(&mut self, dt: Real) -> Result<(), WorldError> {
        check_time_step(dt)?;
        if self.step_work() < self.team_min_work {
            self.step_on(dt, &janus2d_core::parallel::Team::serial());
        } else {
            janus2d_core::parallel::with_team(|team| self.step_on(dt, team));
        }
        Ok(())
    }

    /// The step's work as [`TEAM_MIN_WORK`] counts it: awake moving
    /// bodies, awake contacts (those of the last step) and joints.
    fn step_work(&self) -> usize {
        self.bodies.moving_count() + self.collision.contacts.awake().len() + self.joints.len()
    }

    /// Sets the work (awake moving bodies + awake contacts + joints, as
    /// counted when a step begins) below which [`World::step`] runs on the
    /// calling thread alone instead of on its rayon pool's team; default
    /// [`TEAM_MIN_WORK`]. 0 puts every step on the team, `usize::MAX`
    /// none. The state is the same bit for bit either way (the parallel
    /// stages give the same results on any thread count); only the time
    /// differs. Not in a snapshot's bytes: a world read back from bytes
    /// has the default.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef, TEAM_MIN_WORK};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// assert_eq!(world.team_min_work(), TEAM_MIN_WORK);
    /// world.set_team_min_work(0);
    /// world.step(1.0 / 60.0).unwrap();
    /// assert_eq!(world.team_min_work(), 0);
    /// ```
    pub fn set_team_min_work(&mut self, work: usize) {
        self.team_min_work = work;
    }

    /// The work below which a step runs on the calling thread alone
    /// ([`World::set_team_min_work`]).
    #[must_use]
    pub fn team_min_work(&self) -> usize {
        self.team_min_work
    }

    /// [`World::step`] on the calling thread alone, whatever rayon pool it
    /// runs in: for a world stepped beside many others on threads of their
    /// own (as a batch of worlds does), where the step's own team would
    /// only compete with them. The same state as [`World::step`], bit for
    /// bit, and the same errors.
    ///
    /// ```
    /// use janus2d_world::{World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let build = || {
    ///     let mut world = World::new(WorldDef::default()).unwrap();
    ///     let body = world.create_body(&BodyDef::dynamic(Vec2::new(0.0, 4.0))).unwrap();
    ///     (world, body)
    /// };
    /// let ((mut a, body), (mut b, _)) = (build(), build());
    /// a.step(1.0 / 60.0).unwrap();
    /// b.step_serial(1.0 / 60.0).unwrap();
    /// assert_eq!(a.state_hash(), b.state_hash());
    /// assert!(a.position(body).unwrap().y < 4.0);
    /// ```
    pub fn step_serial(&mut self, dt: Real) -> Result<(), WorldError> {
        check_time_step(dt)?;
        self.step_on(dt, &janus2d_core::parallel::Team::serial());
        Ok(())
    }

    /// The pipeline of one step of `dt` (checked), every threaded stage on
    /// `team`: the step's one worker team, held from the pair search to
    /// the store of the impulses (with the `parallel` feature and a rayon
    /// pool of more than one thread; serial otherwise).
    fn step_on(&mut self, dt: Real, team: &janus2d_core::parallel::Team) {
        let mut ctx = self.step_context(dt);
        let profiling = !self.profiling_off;
        ctx.profile = profiling;
        let mut event_work = crate::profile::EventWork::default();
        let start = std::time::Instant::now();
        let mut t = start;
        let mut lap = || {
            if !profiling {
                return 0.0;
            }
            let now = std::time::Instant::now();
            let d = now.duration_since(t).as_secs_f64();
            t = now;
            d
        };
        let mut sp = crate::profile::StepProfile::default();
        self.islands
            .apply_pending(self.sleep_settings.enabled, &mut self.bodies);
        self.collision.publish_extents(&mut self.bodies);
        let has_shapes = self.collision.has_shapes();
        let has_portals = self.portals.is_active();
        if has_portals && self.portals.clone_aliases().next().is_some() {
            // A crossing couples trees through portal rows the joint forest
            // does not see (a rope across an aperture is two short chains
            // to it): while any body crosses, every tree is solved directly.
            ctx.direct_free_tree_mass_ratio = 0.0;
        }
        if has_portals {
            self.portals
                .build_clipping(&self.bodies, self.collision.shape_store());
            sp.portals += lap();
        }
        // Last step's collision events are replaced at this step's end:
        // their lists' memory goes to the new ones.
        self.collision
            .recycle_events(std::mem::take(&mut self.events.collision));
        if has_shapes {
            // Clones answer for their originals in the joints' no-collide
            // pairs (set every step: crossings come and go).
            self.joints.set_clone_aliases(self.portals.clone_aliases());
            self.collision.update_pairs(
                &self.bodies,
                self.joints.no_collide(),
                &mut self.hooks,
                team,
            );
            sp.broadphase += lap();
            let mut wake = std::mem::take(&mut self.wake_list);
            wake.clear();
            // The joints' colours for the contacts' graph to leave free,
            // made on the leader while the other threads start on the
            // narrowphase (they read the bodies only); a step with no
            // awake contact colours none (joint-only scenes pay nothing
            // here).
            let reserve = self.collision.has_awake_contacts();
            let (joints, bodies) = (&mut self.joints, &self.bodies);
            self.collision
                .collide(bodies, dt, self.portals.clipping(), &mut wake, team, || {
                    if reserve {
                        joints.refresh_reserved(bodies);
                    }
                });
            self.wake_all(&wake);
            let woke = !wake.is_empty();
            self.wake_list = wake;
            let touches = self.collision.take_touch_changes();
            self.islands.apply_touch_changes(touches, &self.bodies);
            self.portals
                .object_masses(&self.bodies, &mut self.object_masses);
            // Woken bodies take new state indices (the joints' keys), and
            // a woken contact may be the first awake one: colour again
            // (nothing to do when the keys are as they were). The same
            // sequence for every thread count.
            if (woke || !reserve) && self.collision.has_awake_contacts() {
                self.joints.refresh_reserved(&self.bodies);
            }
            self.contact_builder.build(
                self.collision.contact_handoff(),
                &self.bodies,
                woke,
                &self.object_masses,
                self.joints.driven_bodies(),
                self.hooks.pre_solve.as_mut(),
                self.joints.reserved(),
                &mut self.contact_solver,
                team,
            );
            sp.narrowphase += lap();
        } else {
            self.contact_solver.begin();
        }
        // No restitution anywhere: no restitution pass.
        ctx.restitution = has_shapes && self.collision.has_restitution();
        ctx.fast_bodies = has_shapes && self.continuous.enabled;
        let couple = has_portals && self.portals.copies_carry_joints(&self.joints);
        let mut graph = janus2d_constraints::GraphBatch {
            joints: self.joints.batch(),
            contacts: janus2d_constraints::ContactBatch {
                solver: &mut self.contact_solver,
                object_masses: &self.object_masses,
            },
        };
        let mut portals = janus2d_constraints::PortalBatch {
            constraints: self.portals.constraints_mut(),
        };
        let passes = if couple {
            crate::portal::coupling::COUPLING_PASSES
        } else {
            0
        };
        // On the team or on the leader alone, whichever the last trial
        // found faster (`TeamChoice`): the same result either way.
        let alone = janus2d_core::parallel::Team::serial();
        let timed = (team.threads() > 1).then(std::time::Instant::now);
        let work = graph.count() + portals.count();
        let solve_team = if timed.is_none() || self.solve_team.on_team(work) {
            team
        } else {
            &alone
        };
        let (settings, bodies) = (&self.settings, &mut self.bodies);
        let mut solve = |batches: &mut [&mut dyn ConstraintBatch]| {
            solve_step_on(settings, &ctx, bodies, batches, solve_team)
        };
        let mut report = if passes > 0 {
            let mut coupled = crate::portal::coupling::CoupledBatches {
                batches: [&mut graph, &mut portals],
                passes,
            };
            solve(&mut [&mut coupled])
        } else {
            solve(&mut [&mut graph, &mut portals])
        };
        if let Some(start) = timed {
            self.solve_team.record(start.elapsed().as_secs_f64());
        }
        // The solver checks velocities and deltas; a pose they carried out
        // of the world (or to inf) is put back here, before any box is
        // computed from it.
        // (The solve's finalize checked the poses as it wrote them.)
        if !report.poses_inside {
            self.bodies
                .reset_escaped(janus2d_core::solver::POSE_LIMIT, &mut report.non_finite);
        }
        lap();
        if has_shapes {
            // Continuous collision, the proxies' boxes, then the impulses
            // back into the contacts beside the proxy moves
            // (`Collision::end_step`).
            let continuous = &mut self.continuous;
            let (no_collide, clipping) = (self.joints.no_collide(), self.portals.clipping());
            let portal_rows = self.portals.constraints();
            let maybe_fast = report.maybe_fast;
            let joints = &self.joints;
            let (builder, solver) = (&self.contact_builder, &self.contact_solver);
            let continuous_time = self.collision.end_step(
                &mut self.bodies,
                self.step_count,
                dt,
                |contacts, team, beside| builder.store_impulses(contacts, solver, team, beside),
                |bodies, shapes, broadphase, team| {
                    let start = profiling.then(std::time::Instant::now);
                    let input = crate::continuous::ContinuousInput {
                        shapes,
                        broadphase,
                        no_collide,
                        clipping,
                        joints,
                        portal_rows,
                        maybe_fast,
                    };
                    continuous.run(bodies, &input, team);
                    start.map_or(0.0, |s| s.elapsed().as_secs_f64())
                },
                team,
            );
            if self.collision.has_hit_events() {
                let (solver, threshold) = (&self.contact_solver, self.hit_event_threshold);
                event_work.hit_points_read = self
                    .collision
                    .collect_hits(|hit| solver.for_each_approach(threshold, hit));
            }
            // Only when some shape has a finite force threshold.
            if self.collision.has_force_events() {
                event_work.force_contacts_read = self.collision.collect_forces(dt);
            }
            let both = lap();
            sp.continuous += continuous_time;
            sp.broadphase += both - continuous_time;
        }
        // A body reset for a non-finite state starts from rest: its joints'
        // and contacts' kept impulses go too, or their warm start would
        // carry it off again at the next step.
        for &b in &report.non_finite {
            self.joints.forget_impulses(b);
            self.collision.forget_impulses(b);
        }
        if has_portals {
            let (portals, mut stores) = self.portals_and_stores();
            portals.cross(&mut stores);
            sp.portals += lap();
        }
        // The bodies that moved: the awake ones before the sleep stage.
        let mut moves = if self.move_events {
            event_work.move_bodies_read = self.bodies.sims.len().saturating_sub(1);
            self.gather_moves()
        } else {
            Vec::new()
        };
        if self.sleep_settings.enabled {
            let keep_awake = self.portals.keep_awake();
            let (shapes, contacts) = self.collision.sleep_parts();
            let input = SleepInput {
                dt,
                settings: self.sleep_settings,
                shapes,
                keep_awake: &keep_awake,
            };
            self.islands
                .update(&input, &mut self.bodies, contacts, &self.joints, team);
            sp.sleep += lap();
        }
        // Non-finite read-backs reset, the row counts and the threshold
        // events, in one pass over the joints.
        let joint_end = self.joints.end_step(team);
        sp.solver = report.profile;
        sp.total = start.elapsed().as_secs_f64();
        self.counters = crate::profile::StepCounters::gather(&crate::profile::CounterSources {
            collision_ran: has_shapes,
            collision: self.collision.counters(),
            contacts: self.contact_solver.len(),
            joint_rows: joint_end.rows,
            direct_joint_rows: joint_end.direct_rows,
            portal_stage_ran: has_portals,
            portals: self.portals.counters_for_step(has_portals),
            gravity: self.gravity != Vec2::ZERO,
            bodies: &self.bodies,
            continuous: self.continuous.counters(),
        });
        self.step_profile = sp;
        self.event_work = event_work;
        for m in &mut moves {
            m.fell_asleep = self.bodies.is_sleeping(m.body);
        }
        self.events = StepEvents {
            non_finite_bodies: report.non_finite,
            collision: self.collision.take_events(),
            joints: joint_end.events,
            #[cfg(feature = "portals")]
            portals: self.portals.take_events(),
            moves,
        };
        self.step_count += 1;
    }

    /// The world-level part of [`World::validate`]: gravity and settings
    /// within their limits, the contact solver's colours adding up.
    pub(crate) fn check_world_values(&self) -> Result<(), String> {
        // One owner id: every store issues and resolves handles with the
        // bodies' (a snapshot's bytes carry each store's copy).
        let owner = self.bodies.owner();
        if self.collision.owner != owner || self.joints.owner() != owner {
            return Err(format!(
                "owner ids differ: bodies {owner}, shapes {}, joints {}",
                self.collision.owner,
                self.joints.owner()
            ));
        }
        check_gravity(self.gravity).map_err(|e| e.to_string())?;
        check_settings(&self.settings).map_err(|e| e.to_string())?;
        self.sleep_settings.validate().map_err(|e| e.to_string())?;
        let coloured: usize = (0..janus2d_core::graph::COLOURS as u8)
            .map(|k| self.contact_solver.count_in(k))
            .sum::<usize>()
            + self.contact_solver.overflow().len();
        if coloured != self.contact_solver.len() {
            return Err(format!(
                "{coloured} contacts in colours, {} in the solver",
                self.contact_solver.len()
            ));
        }
        Ok(())
    }

    /// A hash of every body's transform and velocity bits, in handle order,
    /// then of the chains (slot, generation, loop flag, segment shapes;
    /// a world without chains adds nothing) (FNV-1a, 64 bit): equal hashes
    /// mean bit-identical states.
    ///
    /// ```
    /// use janus2d_world::{ChainDef, World, WorldDef};
    /// use janus2d_core::{BodyDef, Vec2};
    /// let mut world = World::new(WorldDef::default()).unwrap();
    /// let ground = world.create_body(&BodyDef::fixed(Vec2::ZERO)).unwrap();
    /// let before = world.state_hash();
    /// let chain = world.create_chain(ground, &ChainDef::new(vec![Vec2::ZERO, Vec2::new(1.0, 0.0)])).unwrap();
    /// assert_ne!(world.state_hash(), before);
    /// world.destroy_chain(chain).unwrap();
    /// assert_eq!(world.state_hash(), before);
    /// ```
    pub fn state_hash(&self) -> u64 {
        crate::hash::state_hash(&self.bodies, &self.collision.chains)
    }
}
