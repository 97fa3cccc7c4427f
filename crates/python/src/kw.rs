//! Definitions as keyword arguments: each Rust definition struct is walked
//! field by field by a [`Visitor`]; [`Take`] moves keyword values into a
//! definition that starts at its Rust default, [`Dump`] writes the
//! defaults into a dict (`janus2d.defaults(kind)`). A keyword no field
//! takes is a `TypeError`, as for a Python function.

use janus2d::{
    BodyDef, DistanceJointDef, JointDefBase, MotorJointDef, MouseJointDef, PrismaticJointDef, Real,
    RevoluteJointDef, ShapeDef, Vec2, WeldJointDef, WheelJointDef, WorldDef,
};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A value a definition field holds, to and from Python.
pub trait Field: Sized {
    /// From a Python value.
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self>;
    /// To a Python value.
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>>;
}

impl Field for bool {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        obj.extract()
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.into_pyobject(py)?.to_owned().into_any())
    }
}

impl Field for Real {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        Ok(obj.extract::<f64>()? as Real)
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok((f64::from(*self)).into_pyobject(py)?.into_any())
    }
}

impl Field for u32 {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        obj.extract()
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.into_pyobject(py)?.into_any())
    }
}

impl Field for u64 {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        obj.extract()
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.into_pyobject(py)?.into_any())
    }
}

impl Field for i32 {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        obj.extract()
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok(self.into_pyobject(py)?.into_any())
    }
}

impl Field for Vec2 {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        crate::vec2(obj)
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        Ok((f64::from(self.x), f64::from(self.y))
            .into_pyobject(py)?
            .into_any())
    }
}

impl Field for Option<Real> {
    fn load(obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        if obj.is_none() {
            Ok(None)
        } else {
            Ok(Some(Real::load(obj)?))
        }
    }
    fn store<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match self {
            Some(v) => v.store(py),
            None => Ok(py.None().into_bound(py)),
        }
    }
}

/// Walks the fields of a definition.
pub trait Visitor {
    /// One field, by its Python keyword.
    fn field<T: Field>(&mut self, name: &'static str, slot: &mut T) -> PyResult<()>;
}

/// Moves keyword values into fields; what is left over is unknown.
pub struct Take<'py> {
    left: Bound<'py, PyDict>,
}

impl<'py> Take<'py> {
    /// Takes from a copy of `kwargs` (`None`: nothing given).
    pub fn new(py: Python<'py>, kwargs: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        let left = match kwargs {
            Some(k) => k.copy()?,
            None => PyDict::new(py),
        };
        Ok(Take { left })
    }

    /// Takes one keyword by hand (not a definition field), if given.
    pub fn pop<T: Field>(&mut self, name: &'static str) -> PyResult<Option<T>> {
        match self.left.get_item(name)? {
            Some(v) => {
                let value = T::load(&v)
                    .map_err(|e| PyTypeError::new_err(format!("keyword `{name}`: {e}")))?;
                self.left.del_item(name)?;
                Ok(Some(value))
            }
            None => Ok(None),
        }
    }

    /// A `TypeError` naming any keyword no field took.
    pub fn finish(self, what: &str) -> PyResult<()> {
        if self.left.is_empty() {
            return Ok(());
        }
        let names: Vec<String> = self
            .left
            .keys()
            .iter()
            .map(|k| k.str().map(|s| s.to_string()).unwrap_or_default())
            .collect();
        Err(PyTypeError::new_err(format!(
            "{what}: unexpected keyword argument(s): {}",
            names.join(", ")
        )))
    }
}

impl Visitor for Take<'_> {
    fn field<T: Field>(&mut self, name: &'static str, slot: &mut T) -> PyResult<()> {
        if let Some(v) = self.pop(name)? {
            *slot = v;
        }
        Ok(())
    }
}

/// Writes each field's value into a dict.
pub struct Dump<'py> {
    /// The dict written.
    pub dict: Bound<'py, PyDict>,
}

impl Visitor for Dump<'_> {
    fn field<T: Field>(&mut self, name: &'static str, slot: &mut T) -> PyResult<()> {
        let py = self.dict.py();
        self.dict.set_item(name, slot.store(py)?)
    }
}

macro_rules! fields {
    ($v:expr, $d:expr; $($name:ident),* $(,)?) => {{
        $( $v.field(stringify!($name), &mut $d.$name)?; )*
        Ok::<(), PyErr>(())
    }};
}

/// `WorldDef`: gravity, continuous, hit threshold, the solver and sleep
/// settings (flattened: `substeps`, `sleep_enabled`, …).
pub fn world_def<V: Visitor>(d: &mut WorldDef, v: &mut V) -> PyResult<()> {
    fields!(v, d; gravity, enable_continuous, hit_event_threshold, enable_move_events)?;
    let s = &mut d.solver;
    fields!(v, s; substeps, relax_iterations, velocity_iterations, baumgarte, contact_hertz,
        contact_hertz_fraction, contact_damping_ratio, contact_push_max_velocity, joint_hertz,
        joint_hertz_fraction, joint_damping_ratio, joint_max_correction_speed,
        restitution_threshold, warm_starting, contact_mass_ratio_cap, joint_mass_ratio_cap,
        direct_joints, direct_joint_hertz, direct_joint_max_correction_speed,
        direct_free_tree_mass_ratio)?;
    v.field("sleep_enabled", &mut d.sleep.enabled)?;
    v.field("sleep_linear_threshold", &mut d.sleep.linear_threshold)?;
    v.field("time_to_sleep", &mut d.sleep.time_to_sleep)
}

/// `BodyDef` (the body type and position are arguments of their own).
pub fn body_def<V: Visitor>(d: &mut BodyDef, v: &mut V) -> PyResult<()> {
    fields!(v, d; angle, linear_velocity, angular_velocity, linear_damping, angular_damping,
        gravity_scale, max_linear_speed, max_rotation, fixed_rotation, awake, bullet,
        enable_sleep, sleep_threshold, user_data, enable_move_events)
}

/// `ShapeDef` with its filter flattened (`category_bits`, `mask_bits`,
/// `group_index`).
pub fn shape_def<V: Visitor>(d: &mut ShapeDef, v: &mut V) -> PyResult<()> {
    fields!(v, d; density, friction, restitution, is_sensor, enable_hit_events,
        enable_contact_events, enable_sensor_events, force_event_threshold, user_data)?;
    let f = &mut d.filter;
    fields!(v, f; category_bits, mask_bits, group_index)
}

/// The fields every joint kind shares.
pub fn joint_base<V: Visitor>(d: &mut JointDefBase, v: &mut V) -> PyResult<()> {
    fields!(v, d; collide_connected, user_data, constraint_hertz, constraint_damping_ratio,
        force_threshold, torque_threshold, draw_scale)
}

/// `RevoluteJointDef`.
pub fn revolute<V: Visitor>(d: &mut RevoluteJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; enable_limit, lower_angle, upper_angle, enable_motor, motor_speed,
        max_motor_torque, enable_spring, hertz, damping_ratio, target_angle)
}

/// `PrismaticJointDef`.
pub fn prismatic<V: Visitor>(d: &mut PrismaticJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; enable_limit, lower_translation, upper_translation, enable_motor, motor_speed,
        max_motor_force, enable_spring, hertz, damping_ratio, target_translation)
}

/// `WeldJointDef`.
pub fn weld<V: Visitor>(d: &mut WeldJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; linear_hertz, linear_damping_ratio, angular_hertz, angular_damping_ratio)
}

/// `DistanceJointDef` (its rest length is an argument of its own).
pub fn distance<V: Visitor>(d: &mut DistanceJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; enable_limit, min_length, max_length, enable_spring, hertz, damping_ratio,
        lower_force, upper_force, enable_motor, motor_speed, max_motor_force)
}

/// `WheelJointDef`.
pub fn wheel<V: Visitor>(d: &mut WheelJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; enable_spring, hertz, damping_ratio, enable_limit, lower_translation,
        upper_translation, enable_motor, motor_speed, max_motor_torque)
}

/// `MotorJointDef`.
pub fn motor<V: Visitor>(d: &mut MotorJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; linear_offset, angular_offset, max_force, max_torque, correction_factor)
}

/// `MouseJointDef` (target and largest force are arguments of their own).
pub fn mouse<V: Visitor>(d: &mut MouseJointDef, v: &mut V) -> PyResult<()> {
    joint_base(&mut d.base, v)?;
    fields!(v, d; hertz, damping_ratio, angular_hertz, angular_damping_ratio)
}

/// The Rust defaults of one definition kind as a dict.
pub fn defaults<'py>(py: Python<'py>, kind: &str) -> PyResult<Bound<'py, PyDict>> {
    let mut dump = Dump {
        dict: PyDict::new(py),
    };
    let mut base = JointDefBase::default();
    match kind {
        "world" => world_def(&mut WorldDef::default(), &mut dump)?,
        "body" => body_def(&mut BodyDef::dynamic(Vec2::ZERO), &mut dump)?,
        "shape" => shape_def(&mut ShapeDef::default(), &mut dump)?,
        "revolute" => revolute(&mut RevoluteJointDef::from_base(base), &mut dump)?,
        "prismatic" => prismatic(&mut PrismaticJointDef::from_base(base), &mut dump)?,
        "weld" => weld(&mut WeldJointDef::from_base(base), &mut dump)?,
        "distance" => distance(&mut DistanceJointDef::from_base(base, 1.0), &mut dump)?,
        "wheel" => wheel(&mut WheelJointDef::from_base(base), &mut dump)?,
        "motor" => motor(&mut MotorJointDef::from_base(base), &mut dump)?,
        "mouse" => mouse(
            &mut MouseJointDef::from_base(base, Vec2::ZERO, 1.0),
            &mut dump,
        )?,
        "filter" => joint_base(&mut base, &mut dump)?,
        other => {
            return Err(PyValueError::new_err(format!(
                "no definition kind `{other}` (world, body, shape, revolute, prismatic, weld, \
                 distance, wheel, motor, mouse, filter)"
            )));
        }
    }
    Ok(dump.dict)
}
