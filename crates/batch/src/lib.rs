//! # janus2d-batch
//!
//! A [`WorldBatch`] holds N independent janus2d worlds and steps them
//! together, spread over the threads of its own rayon pool. Each world's
//! own step runs on one thread (the batch parallelises over worlds, not
//! inside one), so a world's state after a step is the same bit for bit
//! whatever the number of threads.
//!
//! The worlds usually start as copies of one template world (a snapshot
//! of it), so a handle the template issued names the same body or joint in
//! every world. State goes in and out as flat arrays, world-major: for `B`
//! bodies and `N` worlds, [`WorldBatch::read_state`] fills
//! `N × B × 6` reals (`x, y, angle, vx, vy, ω` of each body in each
//! world), without a call per body from the caller's side.
//!
//! ```
//! use janus2d::prelude::*;
//! use janus2d_batch::WorldBatch;
//!
//! let mut template = World::new(WorldDef::default()).unwrap();
//! let ball = template.create_body(&BodyDef::dynamic(Vec2::new(0.0, 10.0))).unwrap();
//! template.create_shape(ball, &ShapeDef::default(), Circle::new(Vec2::ZERO, 0.5).unwrap()).unwrap();
//!
//! let mut batch = WorldBatch::new(&template, 8).unwrap();
//! batch.set_threads(2).unwrap();
//! // Give every world its own sideways speed, then step all of them.
//! let speeds: Vec<Real> = (0..8).flat_map(|i| [i as Real, 0.0, 0.0]).collect();
//! batch.write_velocities(&[ball], &speeds).unwrap();
//! batch.step(1.0 / 60.0).unwrap();
//! let mut state = vec![0.0; 8 * 6];
//! batch.read_state(&[ball], &mut state).unwrap();
//! assert!(state[6 * 7] > state[6 * 1]); // world 7 moved further right than world 1
//! ```
//!
//! ## Handles in a batch
//!
//! A handle names a slot (its index and generation). The batch resolves it
//! in each world, so worlds built by the same code in the same order share
//! handles even when they were not copied from one template (see
//! [`WorldBatch::set_world`]): the handle's world id is replaced by the id
//! of the world it is used in.

mod crew;
pub mod lander;

use janus2d::{BodyHandle, JointHandle, QueryFilter, Real, Snapshot, Vec2, World, WorldError};
use rayon::prelude::*;

/// Reals per body in [`WorldBatch::read_state`]: `x, y, angle, vx, vy, ω`.
pub const STATE_WIDTH: usize = 6;
/// Reals per body in [`WorldBatch::write_velocities`]: `vx, vy, ω`.
pub const VELOCITY_WIDTH: usize = 3;
/// Reals per body in [`WorldBatch::write_poses`]: `x, y, angle`.
pub const POSE_WIDTH: usize = 3;
/// Reals per body in [`WorldBatch::apply_forces`]: `fx, fy, torque`
/// (the force at the centre of mass).
pub const FORCE_WIDTH: usize = 3;
/// Reals per ray in [`WorldBatch::cast_rays`]: `ox, oy, tx, ty`.
pub const RAY_WIDTH: usize = 4;
/// Reals per body in [`WorldBatch::apply_impulses`]: `ix, iy, px, py`
/// (a linear impulse at a world point).
pub const IMPULSE_WIDTH: usize = 4;

/// Why a batch call was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum BatchError {
    /// A batch needs at least one world.
    Empty,
    /// A world index past the end of the batch.
    WorldIndex {
        /// The index given.
        index: usize,
        /// Worlds in the batch.
        len: usize,
    },
    /// An array of the wrong length.
    Length {
        /// Which argument.
        what: &'static str,
        /// Its required length.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// A thread count of zero, or a pool the system would not start.
    Threads(String),
    /// An environment configuration the batch cannot build (see
    /// [`lander::LanderConfig`]).
    Config(String),
    /// An action outside the environment's action space.
    Action {
        /// The index of the environment whose action it is.
        index: usize,
        /// What is wrong with it.
        why: String,
    },
    /// A world refused the call (the first world, by index, that did).
    World {
        /// The world's index in the batch.
        index: usize,
        /// What it said.
        error: WorldError,
    },
}

impl std::fmt::Display for BatchError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BatchError::Empty => write!(f, "a batch needs at least one world"),
            BatchError::WorldIndex { index, len } => {
                write!(f, "world index {index} out of range for a batch of {len}")
            }
            BatchError::Length {
                what,
                expected,
                found,
            } => write!(f, "`{what}` has {found} values, {expected} needed"),
            BatchError::Threads(why) => write!(f, "thread pool: {why}"),
            BatchError::Config(why) => write!(f, "configuration: {why}"),
            BatchError::Action { index, why } => write!(f, "environment {index}: {why}"),
            BatchError::World { index, error } => write!(f, "world {index}: {error}"),
        }
    }
}

impl std::error::Error for BatchError {}

/// N independent worlds stepped together on a rayon pool of their own.
pub struct WorldBatch {
    template: Snapshot,
    worlds: Vec<World>,
    pool: rayon::ThreadPool,
    threads: usize,
}

impl std::fmt::Debug for WorldBatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WorldBatch")
            .field("worlds", &self.worlds.len())
            .field("threads", &self.threads)
            .finish()
    }
}

/// The id a world's handles carry, read from any of its bodies.
fn owner_of(world: &World) -> Option<u32> {
    world.body_handles().next().map(|h| h.owner)
}

fn build_pool(threads: usize) -> Result<rayon::ThreadPool, BatchError> {
    if threads == 0 {
        return Err(BatchError::Threads(
            "the thread count must be at least 1".into(),
        ));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("janus2d-batch-{i}"))
        .build()
        .map_err(|e| BatchError::Threads(e.to_string()))
}

impl WorldBatch {
    /// `count` copies of `template` (its snapshot), stepped on one thread
    /// until [`set_threads`](Self::set_threads) says otherwise.
    pub fn new(template: &World, count: usize) -> Result<WorldBatch, BatchError> {
        WorldBatch::with_threads(template, count, 1)
    }

    /// `count` copies of `template` on a pool of `threads` threads.
    pub fn with_threads(
        template: &World,
        count: usize,
        threads: usize,
    ) -> Result<WorldBatch, BatchError> {
        if count == 0 {
            return Err(BatchError::Empty);
        }
        let snapshot = template.snapshot();
        let worlds: Vec<World> = (0..count).map(|_| snapshot.to_world()).collect();
        Ok(WorldBatch {
            template: snapshot,
            worlds,
            pool: build_pool(threads)?,
            threads,
        })
    }

    /// Worlds in the batch.
    #[must_use]
    pub fn len(&self) -> usize {
        self.worlds.len()
    }

    /// Always false: a batch holds at least one world.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.worlds.is_empty()
    }

    /// Threads of the batch's pool.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Steps on a new pool of `threads` threads from now on (the worlds'
    /// states do not depend on it).
    pub fn set_threads(&mut self, threads: usize) -> Result<(), BatchError> {
        self.pool = build_pool(threads)?;
        self.threads = threads;
        Ok(())
    }

    /// The worlds, in order.
    #[must_use]
    pub fn worlds(&self) -> &[World] {
        &self.worlds
    }

    /// World `index`.
    pub fn world(&self, index: usize) -> Result<&World, BatchError> {
        let len = self.worlds.len();
        self.worlds
            .get(index)
            .ok_or(BatchError::WorldIndex { index, len })
    }

    /// World `index`, to change it.
    pub fn world_mut(&mut self, index: usize) -> Result<&mut World, BatchError> {
        let len = self.worlds.len();
        self.worlds
            .get_mut(index)
            .ok_or(BatchError::WorldIndex { index, len })
    }

    /// Replaces world `index` with `world` (for instance one built by the
    /// template's code with other random terrain: its handles then match
    /// the template's by index and generation).
    pub fn set_world(&mut self, index: usize, world: World) -> Result<(), BatchError> {
        self.check_index(index)?;
        self.worlds[index] = world;
        Ok(())
    }

    /// The snapshot every world starts from and [`reset`](Self::reset)
    /// returns to.
    #[must_use]
    pub fn template(&self) -> &Snapshot {
        &self.template
    }

    /// Puts world `index` back to the template.
    pub fn reset(&mut self, index: usize) -> Result<(), BatchError> {
        self.check_index(index)?;
        self.worlds[index].restore(&self.template);
        Ok(())
    }

    /// Puts every world whose entry in `mask` is true back to the
    /// template (`mask` has one entry per world).
    pub fn reset_where(&mut self, mask: &[bool]) -> Result<(), BatchError> {
        self.check_len("mask", mask.len(), self.worlds.len())?;
        // Serial: a snapshot cannot be shared between threads (a world is
        // `Send`, not `Sync`), and a restore is a copy.
        for (world, &reset) in self.worlds.iter_mut().zip(mask) {
            if reset {
                world.restore(&self.template);
            }
        }
        Ok(())
    }

    /// Each world's [`World::state_hash`], in order.
    #[must_use]
    pub fn state_hashes(&self) -> Vec<u64> {
        self.worlds.iter().map(World::state_hash).collect()
    }

    /// Steps every world by `dt` seconds, `steps` times, on the pool.
    /// Stops at the first step a world refuses and names the first such
    /// world; worlds are independent, so the others have taken their steps.
    pub fn step_many(&mut self, dt: Real, steps: usize) -> Result<(), BatchError> {
        self.for_each_world(|_, world| {
            for _ in 0..steps {
                // One thread per world: the batch's pool is the parallelism
                // (a world's own team would only compete with it).
                world.step_serial(dt)?;
            }
            Ok(())
        })
    }

    /// Steps every world by `dt` seconds on the pool.
    pub fn step(&mut self, dt: Real) -> Result<(), BatchError> {
        self.step_many(dt, 1)
    }

    /// Calls `f(index, world)` for every world on the pool (a controller
    /// that acts on each world, then steps it, in one parallel pass). The
    /// error is that of the lowest-index world that returned one.
    pub fn for_each_world<F>(&mut self, f: F) -> Result<(), BatchError>
    where
        F: Fn(usize, &mut World) -> Result<(), WorldError> + Sync,
    {
        let results: Vec<Result<(), WorldError>> = self.pool.install(|| {
            self.worlds
                .par_iter_mut()
                .enumerate()
                .map(|(i, world)| f(i, world))
                .collect()
        });
        first_error(results)
    }

    /// Fills `out` (`len() × bodies.len() × 6`, world-major) with
    /// `x, y, angle, vx, vy, ω` of each body in each world. `x, y` is the
    /// body origin.
    pub fn read_state(&self, bodies: &[BodyHandle], out: &mut [Real]) -> Result<(), BatchError> {
        let width = bodies.len() * STATE_WIDTH;
        self.check_len("out", out.len(), self.worlds.len() * width)?;
        if width == 0 {
            return Ok(());
        }
        // Reads are serial: a world is `Send` but not `Sync` (its pre-solve
        // hook), and a read is a few loads per body.
        let results: Vec<Result<(), WorldError>> = {
            out.chunks_mut(width)
                .enumerate()
                .map(|(i, row)| {
                    let world = &self.worlds[i];
                    for (k, &b) in bodies.iter().enumerate() {
                        let b = rebase(owner_of(world), b);
                        let p = world.position(b)?;
                        let v = world.linear_velocity(b)?;
                        let cell = &mut row[k * STATE_WIDTH..(k + 1) * STATE_WIDTH];
                        cell[0] = p.x;
                        cell[1] = p.y;
                        cell[2] = world.angle(b)?;
                        cell[3] = v.x;
                        cell[4] = v.y;
                        cell[5] = world.angular_velocity(b)?;
                    }
                    Ok(())
                })
                .collect()
        };
        first_error(results)
    }

    /// Fills `out` (`len() × bodies.len()`) with the number of touching
    /// solid contacts of each body in each world (a foot on the ground).
    pub fn read_contact_counts(
        &self,
        bodies: &[BodyHandle],
        out: &mut [u32],
    ) -> Result<(), BatchError> {
        let width = bodies.len();
        self.check_len("out", out.len(), self.worlds.len() * width)?;
        if width == 0 {
            return Ok(());
        }
        // Reads are serial: a world is `Send` but not `Sync` (its pre-solve
        // hook), and a read is a few loads per body.
        let results: Vec<Result<(), WorldError>> = {
            out.chunks_mut(width)
                .enumerate()
                .map(|(i, row)| {
                    let world = &self.worlds[i];
                    for (k, &b) in bodies.iter().enumerate() {
                        let b = rebase(owner_of(world), b);
                        let n = world.body_contacts(b)?.count();
                        row[k] = u32::try_from(n).unwrap_or(u32::MAX);
                    }
                    Ok(())
                })
                .collect()
        };
        first_error(results)
    }

    /// Fills `out` (`len() × bodies.len()`) with whether each body is
    /// awake in each world.
    pub fn read_awake(&self, bodies: &[BodyHandle], out: &mut [bool]) -> Result<(), BatchError> {
        let width = bodies.len();
        self.check_len("out", out.len(), self.worlds.len() * width)?;
        for (i, row) in out.chunks_mut(width.max(1)).enumerate().take(self.len()) {
            let world = &self.worlds[i];
            for (k, &b) in bodies.iter().enumerate() {
                let b = rebase(owner_of(world), b);
                row[k] = world
                    .is_awake(b)
                    .map_err(|error| BatchError::World { index: i, error })?;
            }
        }
        Ok(())
    }

    /// Sets `vx, vy, ω` of each body in each world from `velocities`
    /// (`len() × bodies.len() × 3`, world-major).
    pub fn write_velocities(
        &mut self,
        bodies: &[BodyHandle],
        velocities: &[Real],
    ) -> Result<(), BatchError> {
        self.per_body(
            bodies,
            velocities,
            VELOCITY_WIDTH,
            "velocities",
            |w, b, c| {
                w.set_linear_velocity(b, Vec2::new(c[0], c[1]))?;
                w.set_angular_velocity(b, c[2])
            },
        )
    }

    /// Moves each body in each world to `x, y, angle` from `poses`
    /// (`len() × bodies.len() × 3`, world-major).
    pub fn write_poses(&mut self, bodies: &[BodyHandle], poses: &[Real]) -> Result<(), BatchError> {
        self.per_body(bodies, poses, POSE_WIDTH, "poses", |w, b, c| {
            w.set_transform(b, Vec2::new(c[0], c[1]), c[2])
        })
    }

    /// Applies a force `fx, fy` at the centre of mass and a torque to each
    /// body in each world for the next step (`len() × bodies.len() × 3`).
    /// Zero entries are skipped, so a resting body is not woken.
    pub fn apply_forces(
        &mut self,
        bodies: &[BodyHandle],
        forces: &[Real],
    ) -> Result<(), BatchError> {
        self.per_body(bodies, forces, FORCE_WIDTH, "forces", |w, b, c| {
            if c[0] != 0.0 || c[1] != 0.0 {
                w.apply_force_to_center(b, Vec2::new(c[0], c[1]))?;
            }
            if c[2] != 0.0 {
                w.apply_torque(b, c[2])?;
            }
            Ok(())
        })
    }

    /// Applies a linear impulse `ix, iy` at the world point `px, py` to
    /// each body in each world (`len() × bodies.len() × 4`). Zero impulses
    /// are skipped.
    pub fn apply_impulses(
        &mut self,
        bodies: &[BodyHandle],
        impulses: &[Real],
    ) -> Result<(), BatchError> {
        self.per_body(bodies, impulses, IMPULSE_WIDTH, "impulses", |w, b, c| {
            if c[0] != 0.0 || c[1] != 0.0 {
                w.apply_linear_impulse(b, Vec2::new(c[0], c[1]), Vec2::new(c[2], c[3]))?;
            }
            Ok(())
        })
    }

    /// Sets the motor speed of each joint in each world
    /// (`len() × joints.len()`, world-major).
    pub fn set_motor_speeds(
        &mut self,
        joints: &[JointHandle],
        speeds: &[Real],
    ) -> Result<(), BatchError> {
        self.per_joint(joints, speeds, "speeds", |w, j, s| {
            w.set_joint_motor_speed(j, s)
        })
    }

    /// Sets the largest motor torque of each revolute or wheel joint in
    /// each world (`len() × joints.len()`, world-major).
    pub fn set_max_motor_torques(
        &mut self,
        joints: &[JointHandle],
        torques: &[Real],
    ) -> Result<(), BatchError> {
        self.per_joint(joints, torques, "torques", |w, j, t| {
            w.set_joint_max_motor_torque(j, t)
        })
    }

    /// Fills `out` (`len() × joints.len() × 2`) with each joint's angle
    /// (radians, body B relative to body A) and relative angular speed
    /// (rad/s) in each world.
    pub fn read_joint_angles(
        &self,
        joints: &[JointHandle],
        out: &mut [Real],
    ) -> Result<(), BatchError> {
        let width = joints.len() * 2;
        self.check_len("out", out.len(), self.worlds.len() * width)?;
        if width == 0 {
            return Ok(());
        }
        // Reads are serial: a world is `Send` but not `Sync` (its pre-solve
        // hook), and a read is a few loads per body.
        let results: Vec<Result<(), WorldError>> = {
            out.chunks_mut(width)
                .enumerate()
                .map(|(i, row)| {
                    let world = &self.worlds[i];
                    for (k, &j) in joints.iter().enumerate() {
                        let j = rebase(owner_of(world), j);
                        let (a, b) = world.joints().bodies_of(j)?;
                        row[2 * k] = world.joint_angle(j)?;
                        row[2 * k + 1] = world.angular_velocity(b)? - world.angular_velocity(a)?;
                    }
                    Ok(())
                })
                .collect()
        };
        first_error(results)
    }

    /// Casts rays in every world and fills `out` (`len() × rays`) with the
    /// fraction of the closest hit along each ray (1 where nothing is hit).
    /// `rays` holds `ox, oy, tx, ty` (origin and translation) per ray per
    /// world (`len() × rays × 4`). A lidar, as in a walker.
    pub fn cast_rays(
        &self,
        rays: &[Real],
        filter: &QueryFilter,
        out: &mut [Real],
    ) -> Result<(), BatchError> {
        let per_world = out.len() / self.worlds.len();
        self.check_len("out", out.len(), self.worlds.len() * per_world)?;
        self.check_len("rays", rays.len(), out.len() * RAY_WIDTH)?;
        if per_world == 0 {
            return Ok(());
        }
        for (i, (row, world)) in out.chunks_mut(per_world).zip(&self.worlds).enumerate() {
            let ray_row = &rays[i * per_world * RAY_WIDTH..(i + 1) * per_world * RAY_WIDTH];
            for (k, r) in ray_row.chunks(RAY_WIDTH).enumerate() {
                let hit = world
                    .cast_ray_closest(Vec2::new(r[0], r[1]), Vec2::new(r[2], r[3]), filter)
                    .map_err(|error| BatchError::World { index: i, error })?;
                row[k] = hit.map_or(1.0, |h| h.fraction);
            }
        }
        Ok(())
    }

    fn per_body<F>(
        &mut self,
        bodies: &[BodyHandle],
        values: &[Real],
        width: usize,
        what: &'static str,
        f: F,
    ) -> Result<(), BatchError>
    where
        F: Fn(&mut World, BodyHandle, &[Real]) -> Result<(), WorldError> + Sync,
    {
        let row = bodies.len() * width;
        self.check_len(what, values.len(), self.worlds.len() * row)?;
        if row == 0 {
            return Ok(());
        }
        let results: Vec<Result<(), WorldError>> = self.pool.install(|| {
            self.worlds
                .par_iter_mut()
                .zip(values.par_chunks(row))
                .map(|(world, row)| {
                    for (k, &b) in bodies.iter().enumerate() {
                        let b = rebase(owner_of(world), b);
                        f(world, b, &row[k * width..(k + 1) * width])?;
                    }
                    Ok(())
                })
                .collect()
        });
        first_error(results)
    }

    fn per_joint<F>(
        &mut self,
        joints: &[JointHandle],
        values: &[Real],
        what: &'static str,
        f: F,
    ) -> Result<(), BatchError>
    where
        F: Fn(&mut World, JointHandle, Real) -> Result<(), WorldError> + Sync,
    {
        let row = joints.len();
        self.check_len(what, values.len(), self.worlds.len() * row)?;
        if row == 0 {
            return Ok(());
        }
        let results: Vec<Result<(), WorldError>> = self.pool.install(|| {
            self.worlds
                .par_iter_mut()
                .zip(values.par_chunks(row))
                .map(|(world, row)| {
                    for (k, &j) in joints.iter().enumerate() {
                        let j = rebase(owner_of(world), j);
                        f(world, j, row[k])?;
                    }
                    Ok(())
                })
                .collect()
        });
        first_error(results)
    }

    fn check_index(&self, index: usize) -> Result<(), BatchError> {
        if index < self.worlds.len() {
            Ok(())
        } else {
            Err(BatchError::WorldIndex {
                index,
                len: self.worlds.len(),
            })
        }
    }

    fn check_len(
        &self,
        what: &'static str,
        found: usize,
        expected: usize,
    ) -> Result<(), BatchError> {
        if found == expected {
            Ok(())
        } else {
            Err(BatchError::Length {
                what,
                expected,
                found,
            })
        }
    }
}

/// The handle `h` as the world with id `owner` issued it (unchanged when
/// the world has no id yet).
fn rebase<K>(
    owner: Option<u32>,
    h: janus2d::base::handle::Handle<K>,
) -> janus2d::base::handle::Handle<K> {
    match owner {
        Some(owner) => janus2d::base::handle::Handle::new(h.index, h.generation, owner),
        None => h,
    }
}

fn first_error(results: Vec<Result<(), WorldError>>) -> Result<(), BatchError> {
    for (index, r) in results.into_iter().enumerate() {
        r.map_err(|error| BatchError::World { index, error })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests;
