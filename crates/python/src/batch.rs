//! `janus2d.WorldBatch`: N worlds stepped together on rayon threads with
//! the GIL released, state in and out as `(worlds, bodies, k)` arrays.

use crate::world::{PyWorld, bodies_of, joints_of, values_of};
use crate::{Excl, raise};
use janus2d::{Real, World};
use janus2d_batch::{BatchError, WorldBatch};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArray3, PyArrayLikeDyn, PyArrayMethods};
use pyo3::prelude::*;

/// The Python exception of a batch error (a world's error carries the
/// world's index as `world`).
pub(crate) fn batch_error(e: BatchError) -> PyErr {
    match e {
        BatchError::World { index, error } => {
            let err = crate::world_error(error);
            Python::attach(|py| {
                // The world's index rides on the exception.
                let _ = err.value(py).setattr("world", index);
            });
            err
        }
        BatchError::Empty => raise("BatchError", "Empty", e.to_string()),
        BatchError::WorldIndex { .. } => raise("BatchError", "WorldIndex", e.to_string()),
        BatchError::Length { .. } => raise("BatchError", "Length", e.to_string()),
        BatchError::Threads(_) => raise("BatchError", "Threads", e.to_string()),
        BatchError::Config(_) => raise("BatchError", "Config", e.to_string()),
        BatchError::Action { index, .. } => {
            let err = raise("InvalidInputError", "Action", e.to_string());
            Python::attach(|py| {
                let _ = err.value(py).setattr("world", index);
            });
            err
        }
    }
}

/// Converts `Result<T, BatchError>` into a Python result.
pub(crate) trait OrBatch<T> {
    /// The Python exception of the error.
    fn pyb(self) -> PyResult<T>;
}

impl<T> OrBatch<T> for Result<T, BatchError> {
    fn pyb(self) -> PyResult<T> {
        self.map_err(batch_error)
    }
}

fn reals(values: Vec<f64>) -> Vec<Real> {
    values.into_iter().map(|v| v as Real).collect()
}

/// `WorldBatch(world, count, threads=1)`: `count` copies of `world`
/// stepped together on `threads` threads, each world's step on one
/// thread (the same states for any thread count). Handles of the template
/// world address every world of the batch.
#[pyclass(module = "janus2d", name = "WorldBatch")]
pub struct PyWorldBatch {
    inner: Excl<WorldBatch>,
}

#[pymethods]
impl PyWorldBatch {
    #[new]
    #[pyo3(signature = (world, count, threads = 1))]
    fn py_new(world: PyRef<'_, PyWorld>, count: usize, threads: usize) -> PyResult<Self> {
        let template: World = world.inner.lock().snapshot().to_world();
        let batch = WorldBatch::with_threads(&template, count, threads).pyb()?;
        Ok(PyWorldBatch {
            inner: Excl::new(batch),
        })
    }

    fn __len__(&self) -> usize {
        self.inner.lock().len()
    }

    /// Threads of the batch's pool (settable).
    #[getter]
    fn threads(&self) -> usize {
        self.inner.lock().threads()
    }

    #[setter]
    fn set_threads(&self, threads: usize) -> PyResult<()> {
        self.inner.lock().set_threads(threads).pyb()
    }

    /// Steps every world `steps` times by `dt` on the pool, without the
    /// GIL.
    #[pyo3(signature = (dt = 1.0 / 60.0, steps = 1))]
    fn step(&self, py: Python<'_>, dt: f64, steps: usize) -> PyResult<()> {
        let mut guard = self.inner.lock();
        let batch: &mut WorldBatch = &mut guard;
        py.detach(|| batch.step_many(dt as Real, steps)).pyb()
    }

    /// `(worlds, bodies, 6)` float64: `x, y, angle, vx, vy, ω`.
    fn get_state<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let handles = bodies_of(bodies)?;
        let batch = self.inner.lock();
        let mut out = vec![0.0 as Real; batch.len() * handles.len() * 6];
        batch.read_state(&handles, &mut out).pyb()?;
        let out: Vec<f64> = out.into_iter().map(f64::from).collect();
        PyArray1::from_vec(py, out).reshape([batch.len(), handles.len(), 6])
    }

    /// `(worlds, bodies)` int: touching solid contacts of each body.
    fn get_contact_counts<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<u32>>> {
        let handles = bodies_of(bodies)?;
        let batch = self.inner.lock();
        let mut out = vec![0u32; batch.len() * handles.len()];
        batch.read_contact_counts(&handles, &mut out).pyb()?;
        PyArray1::from_vec(py, out).reshape([batch.len(), handles.len()])
    }

    /// `(worlds, bodies)` bool: whether each body is awake.
    fn get_awake<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<bool>>> {
        let handles = bodies_of(bodies)?;
        let batch = self.inner.lock();
        let mut out = vec![false; batch.len() * handles.len()];
        batch.read_awake(&handles, &mut out).pyb()?;
        PyArray1::from_vec(py, out).reshape([batch.len(), handles.len()])
    }

    /// `(worlds, joints, 2)` float64: each joint's angle and relative
    /// angular speed.
    fn get_joint_angles<'py>(
        &self,
        py: Python<'py>,
        joints: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let handles = joints_of(joints)?;
        let batch = self.inner.lock();
        let mut out = vec![0.0 as Real; batch.len() * handles.len() * 2];
        batch.read_joint_angles(&handles, &mut out).pyb()?;
        let out: Vec<f64> = out.into_iter().map(f64::from).collect();
        PyArray1::from_vec(py, out).reshape([batch.len(), handles.len(), 2])
    }

    /// Sets `vx, vy, ω` from a `(worlds, bodies, 3)` array.
    fn set_velocities(
        &self,
        bodies: &Bound<'_, PyAny>,
        velocities: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let mut batch = self.inner.lock();
        let v = values_of(&velocities, &[batch.len(), handles.len(), 3], "velocities")?;
        batch.write_velocities(&handles, &reals(v)).pyb()
    }

    /// Moves bodies to `x, y, angle` from a `(worlds, bodies, 3)` array.
    fn set_poses(
        &self,
        bodies: &Bound<'_, PyAny>,
        poses: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let mut batch = self.inner.lock();
        let v = values_of(&poses, &[batch.len(), handles.len(), 3], "poses")?;
        batch.write_poses(&handles, &reals(v)).pyb()
    }

    /// Forces `fx, fy` at the centre of mass and torques from a
    /// `(worlds, bodies, 3)` array, for the next step.
    fn apply_forces(
        &self,
        bodies: &Bound<'_, PyAny>,
        forces: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let mut batch = self.inner.lock();
        let v = values_of(&forces, &[batch.len(), handles.len(), 3], "forces")?;
        batch.apply_forces(&handles, &reals(v)).pyb()
    }

    /// Linear impulses `ix, iy` at world points `px, py` from a
    /// `(worlds, bodies, 4)` array.
    fn apply_impulses(
        &self,
        bodies: &Bound<'_, PyAny>,
        impulses: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let mut batch = self.inner.lock();
        let v = values_of(&impulses, &[batch.len(), handles.len(), 4], "impulses")?;
        batch.apply_impulses(&handles, &reals(v)).pyb()
    }

    /// Motor speeds from a `(worlds, joints)` array.
    fn set_motor_speeds(
        &self,
        joints: &Bound<'_, PyAny>,
        speeds: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = joints_of(joints)?;
        let mut batch = self.inner.lock();
        let v = values_of(&speeds, &[batch.len(), handles.len()], "speeds")?;
        batch.set_motor_speeds(&handles, &reals(v)).pyb()
    }

    /// Largest motor torques from a `(worlds, joints)` array.
    fn set_max_motor_torques(
        &self,
        joints: &Bound<'_, PyAny>,
        torques: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = joints_of(joints)?;
        let mut batch = self.inner.lock();
        let v = values_of(&torques, &[batch.len(), handles.len()], "torques")?;
        batch.set_max_motor_torques(&handles, &reals(v)).pyb()
    }

    /// Ray casts in every world: `rays` is `(worlds, rays, 4)` (`ox, oy,
    /// tx, ty`: origin and translation); returns `(worlds, rays)` float64,
    /// the closest hit's fraction along each ray (1 where none).
    #[pyo3(signature = (rays, mask_bits = u64::MAX, category_bits = 1))]
    fn cast_rays<'py>(
        &self,
        py: Python<'py>,
        rays: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
        mask_bits: u64,
        category_bits: u64,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let batch = self.inner.lock();
        let shape = rays.as_array().shape().to_vec();
        if shape.len() != 3 || shape[0] != batch.len() || shape[2] != 4 {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "`rays` has shape {shape:?}, ({}, n, 4) needed",
                batch.len()
            )));
        }
        let v = values_of(&rays, &shape, "rays")?;
        let filter = janus2d::QueryFilter {
            category_bits,
            mask_bits,
            ..janus2d::QueryFilter::default()
        };
        let mut out = vec![0.0 as Real; shape[0] * shape[1]];
        batch.cast_rays(&reals(v), &filter, &mut out).pyb()?;
        let out: Vec<f64> = out.into_iter().map(f64::from).collect();
        PyArray1::from_vec(py, out).reshape([shape[0], shape[1]])
    }

    /// Each world's state hash, `(worlds,)` uint64.
    fn state_hashes<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u64>> {
        PyArray1::from_vec(py, self.inner.lock().state_hashes())
    }

    /// Puts world `index` back to the template.
    fn reset(&self, index: usize) -> PyResult<()> {
        self.inner.lock().reset(index).pyb()
    }

    /// Puts every world whose `mask` entry is true back to the template.
    fn reset_where(&self, mask: Vec<bool>) -> PyResult<()> {
        self.inner.lock().reset_where(&mask).pyb()
    }

    /// Replaces world `index` with a copy of `world` (built by the same
    /// code as the template, so the template's handles address it).
    fn set_world(&self, index: usize, world: PyRef<'_, PyWorld>) -> PyResult<()> {
        let copy = world.inner.lock().snapshot().to_world();
        self.inner.lock().set_world(index, copy).pyb()
    }

    /// A copy of world `index` as a `World`.
    fn world(&self, index: usize) -> PyResult<PyWorld> {
        let batch = self.inner.lock();
        let w = batch.world(index).pyb()?;
        Ok(PyWorld::wrap(w.snapshot().to_world()))
    }

    /// Snapshot bytes of world `index` (as `World.to_bytes`).
    fn world_bytes<'py>(
        &self,
        py: Python<'py>,
        index: usize,
    ) -> PyResult<Bound<'py, pyo3::types::PyBytes>> {
        let batch = self.inner.lock();
        let w = batch.world(index).pyb()?;
        Ok(pyo3::types::PyBytes::new(py, &w.snapshot().to_bytes()))
    }

    /// Sets world `index` from snapshot bytes.
    fn set_world_bytes(&self, index: usize, data: &[u8]) -> PyResult<()> {
        let world = crate::world::world_from_bytes(data)?;
        self.inner.lock().set_world(index, world).pyb()
    }

    fn __repr__(&self) -> String {
        let b = self.inner.lock();
        format!("WorldBatch(worlds={}, threads={})", b.len(), b.threads())
    }
}
