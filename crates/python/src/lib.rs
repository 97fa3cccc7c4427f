//! `janus2d._janus2d`: the native half of the `janus2d` Python package
//! (pyo3, abi3). The Python package (`python/janus2d`) re-exports it and
//! adds the exceptions, the Gymnasium environments and helpers.
//!
//! Every Rust error becomes a typed Python exception from
//! `janus2d.errors`; nothing here panics on user input.

use janus2d::{Real, Vec2, WorldError};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Mutex, MutexGuard, PoisonError};

mod batch;
mod handles;
mod kw;
mod lander;
mod world;

pub use handles::{Body, Joint, PortalPair, Shape};

/// A value behind a mutex, so a `Send`-only Rust value (a world holds a
/// `Send` pre-solve hook) can live in a Python object, which must be
/// `Sync`. The lock is uncontended: Python's own borrow rules already give
/// each call exclusive access.
pub struct Excl<T>(Mutex<T>);

impl<T> Excl<T> {
    /// Wraps `value`.
    pub fn new(value: T) -> Self {
        Excl(Mutex::new(value))
    }

    /// The value (a poisoned lock, which only a panic could leave, is
    /// taken over: every call leaves the value consistent or unchanged).
    pub fn lock(&self) -> MutexGuard<'_, T> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// A 2-vector from any Python pair of numbers.
pub fn vec2(obj: &Bound<'_, PyAny>) -> PyResult<Vec2> {
    let (x, y): (f64, f64) = obj
        .extract()
        .map_err(|_| PyTypeError::new_err("expected a pair of numbers (x, y)"))?;
    Ok(Vec2::new(x as Real, y as Real))
}

/// A pair of floats for Python.
pub fn pair(v: Vec2) -> (f64, f64) {
    (f64::from(v.x), f64::from(v.y))
}

/// A Python exception of class `class` from `janus2d.errors`, with
/// `kind` (the Rust variant) as an attribute.
pub fn raise(class: &str, kind: &str, message: String) -> PyErr {
    Python::attach(|py| {
        let made = (|| -> PyResult<PyErr> {
            let cls = py.import("janus2d.errors")?.getattr(class)?;
            let err = cls.call1((message.clone(),))?;
            err.setattr("kind", kind)?;
            Ok(PyErr::from_value(err))
        })();
        made.unwrap_or_else(|e| e)
    })
}

/// The Python exception of a world error.
pub fn world_error(e: WorldError) -> PyErr {
    let message = e.to_string();
    let (class, kind) = match &e {
        WorldError::StaleBody => ("StaleHandleError", "StaleBody"),
        WorldError::StaleJoint => ("StaleHandleError", "StaleJoint"),
        WorldError::StaleShape => ("StaleHandleError", "StaleShape"),
        WorldError::StalePortal => ("StaleHandleError", "StalePortal"),
        WorldError::StaleChain => ("StaleHandleError", "StaleChain"),
        WorldError::ChainSegmentShape => ("InvalidInputError", "ChainSegmentShape"),
        WorldError::ForeignHandle => ("ForeignHandleError", "ForeignHandle"),
        WorldError::WrongJointKind => ("WrongJointKindError", "WrongJointKind"),
        WorldError::NotDynamic => ("BodyTypeError", "NotDynamic"),
        WorldError::NotMovable => ("BodyTypeError", "NotMovable"),
        WorldError::PortalBody => ("PortalBodyError", "PortalBody"),
        WorldError::DisabledBody => ("BodyTypeError", "DisabledBody"),
        WorldError::Body(_) => ("InvalidInputError", "Body"),
        WorldError::Joint(_) => ("InvalidInputError", "Joint"),
        WorldError::Geometry(_) => ("InvalidInputError", "Geometry"),
        WorldError::Portal(_) => ("InvalidInputError", "Portal"),
        WorldError::InvalidTimeStep => ("InvalidInputError", "InvalidTimeStep"),
        WorldError::NonFinite(_) => ("InvalidInputError", "NonFinite"),
        WorldError::OutOfRange(_) => ("InvalidInputError", "OutOfRange"),
        WorldError::OutOfBounds { .. } => ("InvalidInputError", "OutOfBounds"),
        WorldError::BadQuery { .. } => ("InvalidInputError", "BadQuery"),
    };
    raise(class, kind, message)
}

/// Converts `Result<T, WorldError>` into a Python result.
pub trait OrPy<T> {
    /// The Python exception of the error.
    fn py(self) -> PyResult<T>;
}

impl<T> OrPy<T> for Result<T, WorldError> {
    fn py(self) -> PyResult<T> {
        self.map_err(world_error)
    }
}

impl<T> OrPy<T> for Result<T, janus2d::GeometryError> {
    fn py(self) -> PyResult<T> {
        self.map_err(|e| world_error(WorldError::Geometry(e)))
    }
}

/// The Rust defaults of a definition kind (`"world"`, `"body"`,
/// `"shape"`, `"revolute"`, `"prismatic"`, `"weld"`, `"distance"`,
/// `"wheel"`, `"motor"`, `"mouse"`, `"filter"`) as a dict of the keyword
/// arguments that kind takes.
#[pyfunction]
fn defaults<'py>(py: Python<'py>, kind: &str) -> PyResult<Bound<'py, PyDict>> {
    kw::defaults(py, kind)
}

/// Bytes per real of this build (4: `f32`; the engine's precision).
#[pyfunction]
fn real_bytes() -> usize {
    std::mem::size_of::<Real>()
}

/// The native module.
#[pymodule]
fn _janus2d(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<world::PyWorld>()?;
    m.add_class::<batch::PyWorldBatch>()?;
    m.add_class::<lander::PyLanderBatch>()?;
    m.add_class::<Body>()?;
    m.add_class::<Shape>()?;
    m.add_class::<Joint>()?;
    m.add_class::<PortalPair>()?;
    m.add_function(wrap_pyfunction!(defaults, m)?)?;
    m.add_function(wrap_pyfunction!(real_bytes, m)?)?;
    m.add("SNAPSHOT_VERSION", janus2d::world::SNAPSHOT_VERSION)?;
    Ok(())
}
