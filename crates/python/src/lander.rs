//! `janus2d.LanderBatch`: N LunarLanders whose whole environment step
//! (engines, world step, observation, reward, termination) runs in Rust,
//! one call per step for the batch, with the GIL released.

use crate::Excl;
use crate::batch::OrBatch;
use crate::handles::Body;
use crate::world::PyWorld;
use janus2d_batch::BatchError;
use janus2d_batch::lander::{LanderActions, LanderBatch, LanderConfig, OBS_WIDTH, TERRAIN_DRAWS};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArrayLikeDyn, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// `LanderBatch(count, threads=1, continuous=False, gravity=-10.0,
/// portal=False, dispersion=True, max_episode_steps=0, autoreset=False,
/// seed=0, enable_wind=False, wind_power=15.0, turbulence_power=1.5)`: `count` landers with Gymnasium's LunarLander rules, each
/// step of every lander done in Rust. `step` takes the actions of all
/// landers and returns `(obs, reward, terminated, truncated)` arrays;
/// with `autoreset`, a lander whose episode ended is reset by its next
/// step (reward 0, its first observation returned).
#[pyclass(module = "janus2d", name = "LanderBatch")]
pub struct PyLanderBatch {
    inner: Excl<LanderBatch>,
}

/// The actions of `n` landers as Rust wants them; a value that is no
/// action is an `InvalidInputError` (kind `Action`) naming the lander.
enum Owned {
    Discrete(Vec<i64>),
    Continuous(Vec<f64>),
}

fn action_error(index: usize, why: String) -> PyErr {
    crate::batch::batch_error(BatchError::Action { index, why })
}

fn actions_of(obj: &Bound<'_, PyAny>, continuous: bool) -> PyResult<Owned> {
    // The usual case first, without a conversion: an int64 array of
    // discrete actions.
    if !continuous && let Ok(ints) = obj.extract::<PyReadonlyArrayDyn<'_, i64>>() {
        return Ok(Owned::Discrete(ints.as_array().iter().copied().collect()));
    }
    let array: PyArrayLikeDyn<'_, f64, AllowTypeChange> = obj.extract().map_err(|_| {
        action_error(
            0,
            "actions must be numbers (an integer per lander, or two floats)".into(),
        )
    })?;
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    if continuous {
        return Ok(Owned::Continuous(values));
    }
    let mut out = Vec::with_capacity(values.len());
    for (i, v) in values.into_iter().enumerate() {
        if v.fract() != 0.0 || !v.is_finite() {
            return Err(action_error(
                i,
                format!("action {v} is not an integer of Discrete(4)"),
            ));
        }
        out.push(v as i64);
    }
    Ok(Owned::Discrete(out))
}

impl Owned {
    fn view(&self) -> LanderActions<'_> {
        match self {
            Owned::Discrete(a) => LanderActions::Discrete(a),
            Owned::Continuous(a) => LanderActions::Continuous(a),
        }
    }
}

/// `(n, 8)` observations from their values in order, without a copy.
fn obs_array(py: Python<'_>, obs: Vec<f32>, n: usize) -> PyResult<Bound<'_, PyArray2<f32>>> {
    let array = numpy::ndarray::Array2::from_shape_vec((n, OBS_WIDTH), obs)
        .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
    Ok(PyArray2::from_owned_array(py, array))
}

impl PyLanderBatch {
    fn observations<'py>(
        py: Python<'py>,
        batch: &LanderBatch,
    ) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let obs: Vec<f32> = batch.outcomes().flat_map(|o| o.observation).collect();
        obs_array(py, obs, batch.len())
    }
}

#[pymethods]
impl PyLanderBatch {
    #[new]
    #[pyo3(signature = (count, threads = 1, continuous = false, gravity = -10.0,
        portal = false, dispersion = true, max_episode_steps = 0, autoreset = false, seed = 0,
        enable_wind = false, wind_power = 15.0, turbulence_power = 1.5))]
    fn py_new(
        py: Python<'_>,
        count: usize,
        threads: usize,
        continuous: bool,
        gravity: f64,
        portal: bool,
        dispersion: bool,
        max_episode_steps: u32,
        autoreset: bool,
        seed: u64,
        enable_wind: bool,
        wind_power: f64,
        turbulence_power: f64,
    ) -> PyResult<Self> {
        let config = LanderConfig {
            continuous,
            gravity,
            portal,
            dispersion,
            max_episode_steps,
            autoreset,
            enable_wind,
            wind_power,
            turbulence_power,
        };
        let batch = py
            .detach(|| LanderBatch::new(count, config, seed, threads))
            .pyb()?;
        Ok(PyLanderBatch {
            inner: Excl::new(batch),
        })
    }

    fn __len__(&self) -> usize {
        self.inner.lock().len()
    }

    /// Threads the batch steps on (settable; one: the calling thread).
    #[getter]
    fn threads(&self) -> usize {
        self.inner.lock().threads()
    }

    #[setter]
    fn set_threads(&self, threads: usize) -> PyResult<()> {
        self.inner.lock().set_threads(threads).pyb()
    }

    /// Whether the landers take `Box(-1, 1, (2,))` actions.
    #[getter]
    fn continuous(&self) -> bool {
        self.inner.lock().config().continuous
    }

    /// Reseeds every lander from `seed` (each its own stream) and starts
    /// new episodes; returns the first observations, `(n, 8)` float32.
    fn reset<'py>(&self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let mut guard = self.inner.lock();
        let batch: &mut LanderBatch = &mut guard;
        py.detach(|| batch.reset_all(seed)).pyb()?;
        Self::observations(py, &guard)
    }

    /// Starts a new episode of lander `index` on the terrain of `draws`
    /// (12 random heights, 0 to 6.67 m) with the initial push `push`
    /// (`fx, fy`, N); returns its first observation.
    fn reset_with<'py>(
        &self,
        py: Python<'py>,
        index: usize,
        draws: [f64; TERRAIN_DRAWS],
        push: (f64, f64),
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        if !draws
            .iter()
            .chain([&push.0, &push.1])
            .all(|v| v.is_finite())
        {
            return Err(crate::batch::batch_error(BatchError::Config(
                "reset_with: terrain and push must be finite".into(),
            )));
        }
        let mut batch = self.inner.lock();
        batch.reset_with(index, &draws, [push.0, push.1]).pyb()?;
        Ok(PyArray1::from_slice(
            py,
            &batch.outcome(index).pyb()?.observation,
        ))
    }

    /// Steps every lander with its action (`(n,)` integers, or `(n, 2)`
    /// floats when continuous), without the GIL; returns `(obs (n, 8)
    /// float32, reward (n,) float64, terminated (n,) bool, truncated (n,)
    /// bool)`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        actions: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let mut guard = self.inner.lock();
        let owned = actions_of(actions, guard.config().continuous)?;
        let batch: &mut LanderBatch = &mut guard;
        py.detach(|| batch.step(owned.view())).pyb()?;
        let n = guard.len();
        let mut obs = Vec::with_capacity(n * OBS_WIDTH);
        let mut reward = Vec::with_capacity(n);
        let mut terminated = Vec::with_capacity(n);
        let mut truncated = Vec::with_capacity(n);
        for o in guard.outcomes() {
            obs.extend_from_slice(&o.observation);
            reward.push(o.reward);
            terminated.push(o.terminated);
            truncated.push(o.truncated);
        }
        let obs = obs_array(py, obs, n)?;
        PyTuple::new(
            py,
            [
                obs.into_any(),
                PyArray1::from_vec(py, reward).into_any(),
                PyArray1::from_vec(py, terminated).into_any(),
                PyArray1::from_vec(py, truncated).into_any(),
            ],
        )
    }

    /// One step of a one-lander batch: `action` is an integer (or a pair
    /// of floats when continuous); returns `(obs (8,) float32, reward,
    /// terminated)`. The single environment's fast path.
    fn step_one<'py>(
        &self,
        py: Python<'py>,
        action: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray1<f32>>, f64, bool)> {
        let mut batch = self.inner.lock();
        if batch.len() != 1 {
            return Err(crate::batch::batch_error(BatchError::Length {
                what: "landers (step_one steps a batch of one)",
                expected: 1,
                found: batch.len(),
            }));
        }
        let continuous = batch.config().continuous;
        let result = match (continuous, action.extract::<i64>()) {
            (false, Ok(a)) => batch.step(LanderActions::Discrete(&[a])),
            _ => {
                let owned = actions_of(action, continuous)?;
                batch.step(owned.view())
            }
        };
        result.pyb()?;
        let o = batch.outcome(0).pyb()?;
        Ok((
            PyArray1::from_slice(py, &o.observation),
            o.reward,
            o.terminated,
        ))
    }

    /// Every lander's last observation, `(n, 8)` float32.
    fn observations_now<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        Self::observations(py, &self.inner.lock())
    }

    /// Steps of each lander's current episode, `(n,)` uint32.
    fn episode_steps<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let batch = self.inner.lock();
        let steps: Vec<u32> = (0..batch.len())
            .filter_map(|i| batch.env(i).ok().map(|e| e.episode_steps()))
            .collect();
        PyArray1::from_vec(py, steps)
    }

    /// Portal crossings each lander's hull completed in its current
    /// episode (portal variant), `(n,)` uint32.
    fn portal_crossings<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        let batch = self.inner.lock();
        let counts: Vec<u32> = (0..batch.len())
            .filter_map(|i| batch.env(i).ok().map(|e| e.portal_crossings()))
            .collect();
        PyArray1::from_vec(py, counts)
    }

    /// The bodies of lander `index`'s world: `(ground, hull, left leg,
    /// right leg)`, handles for [`world`](Self::world)'s copy.
    fn bodies(&self, index: usize) -> PyResult<(Body, Body, Body, Body)> {
        let batch = self.inner.lock();
        let b = batch.env(index).pyb()?.bodies();
        Ok((
            b.ground.into(),
            b.hull.into(),
            b.legs[0].into(),
            b.legs[1].into(),
        ))
    }

    /// The pad's ends `(left, right)`, m, of lander `index`.
    fn pad(&self, index: usize) -> PyResult<(f64, f64)> {
        Ok(self.inner.lock().env(index).pyb()?.bodies().pad)
    }

    /// A copy of lander `index`'s world.
    fn world(&self, index: usize) -> PyResult<PyWorld> {
        let batch = self.inner.lock();
        let w = batch.env(index).pyb()?.world();
        Ok(PyWorld::wrap(w.snapshot().to_world()))
    }

    /// Each lander's world state hash, `(n,)` uint64.
    fn state_hashes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        let batch = self.inner.lock();
        let hashes: Vec<u64> = (0..batch.len())
            .filter_map(|i| batch.env(i).ok().map(|e| e.world().state_hash()))
            .collect();
        PyArray1::from_vec(py, hashes)
    }

    fn __repr__(&self) -> String {
        let b = self.inner.lock();
        format!(
            "LanderBatch(landers={}, threads={}, continuous={}, portal={})",
            b.len(),
            b.threads(),
            b.config().continuous,
            b.config().portal
        )
    }
}
