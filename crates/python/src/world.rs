//! `janus2d.World`: the world, its bodies, shapes, joints, portals,
//! queries, events, snapshots and pictures.

use crate::handles::{Body, Joint, PortalPair, Shape};
use crate::kw::{self, Take};
use crate::{Excl, OrPy, pair, raise, vec2};
use janus2d::render::{Camera, Raster};
use janus2d::{
    Aabb, BodyDef, BodyHandle, BodyType, Capsule, Circle, DistanceJointDef, DrawOptions,
    FilterJointDef, JointDef, MassModel, MotorJointDef, MouseJointDef, Polygon, PortalDef,
    PortalEvent, PortalPairDef, PrismaticJointDef, QueryFilter, Real, RevoluteJointDef, Segment,
    ShapeDef, ShapeHandle, Snapshot, Vec2, WeldJointDef, WheelJointDef, World, WorldDef,
    WorldError,
};
use numpy::{AllowTypeChange, PyArray1, PyArray2, PyArray3, PyArrayLikeDyn, PyArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

/// A janus2d world: `World(gravity=(0, -10), substeps=4, …)`; every
/// keyword is a field of the Rust `WorldDef` (its solver and sleep settings
/// flattened) and defaults to the Rust default (`janus2d.defaults("world")`).
#[pyclass(module = "janus2d", name = "World")]
pub struct PyWorld {
    pub(crate) inner: Excl<World>,
}

/// Body handles from a Python sequence of `Body` (one extraction in Rust
/// per item; no Python call).
pub fn bodies_of(seq: &Bound<'_, PyAny>) -> PyResult<Vec<BodyHandle>> {
    let mut out = Vec::new();
    for item in seq.try_iter()? {
        let item = item?;
        let b = item
            .cast::<Body>()
            .map_err(|_| PyTypeError::new_err("expected a sequence of janus2d.Body"))?;
        out.push(b.get().raw());
    }
    Ok(out)
}

/// Joint handles from a Python sequence of `Joint`.
pub fn joints_of(seq: &Bound<'_, PyAny>) -> PyResult<Vec<janus2d::JointHandle>> {
    let mut out = Vec::new();
    for item in seq.try_iter()? {
        let item = item?;
        let j = item
            .cast::<Joint>()
            .map_err(|_| PyTypeError::new_err("expected a sequence of janus2d.Joint"))?;
        out.push(j.get().raw());
    }
    Ok(out)
}

/// The values of an array-like with `shape` (checked), in C order.
pub fn values_of(
    arr: &PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    shape: &[usize],
    what: &str,
) -> PyResult<Vec<f64>> {
    let view = arr.as_array();
    if view.shape() != shape {
        return Err(PyValueError::new_err(format!(
            "`{what}` has shape {:?}, {:?} needed",
            view.shape(),
            shape
        )));
    }
    Ok(view.iter().copied().collect())
}

fn body_type_of(name: &str) -> PyResult<BodyType> {
    match name {
        "dynamic" => Ok(BodyType::Dynamic),
        "static" | "fixed" => Ok(BodyType::Static),
        "kinematic" => Ok(BodyType::Kinematic),
        other => Err(PyValueError::new_err(format!(
            "body type `{other}`: dynamic, static or kinematic"
        ))),
    }
}

fn body_type_name(t: BodyType) -> &'static str {
    match t {
        BodyType::Dynamic => "dynamic",
        BodyType::Static => "static",
        BodyType::Kinematic => "kinematic",
    }
}

fn shape_def_of(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<ShapeDef> {
    let mut take = Take::new(py, kwargs)?;
    let mut def = ShapeDef::default();
    kw::shape_def(&mut def, &mut take)?;
    take.finish("shape")?;
    Ok(def)
}

fn query_filter(
    mask_bits: u64,
    category_bits: u64,
    exclude: Option<Body>,
    through_portals: bool,
) -> QueryFilter<'static> {
    QueryFilter {
        category_bits,
        mask_bits,
        exclude_body: exclude.map(|b| b.raw()),
        through_portals,
        predicate: None,
    }
}

fn shape_pairs<'py>(
    py: Python<'py>,
    events: &[janus2d::ShapePairEvent],
) -> PyResult<Bound<'py, PyList>> {
    let items: Vec<(Shape, Shape)> = events
        .iter()
        .map(|e| (Shape::from(e.shape_a), Shape::from(e.shape_b)))
        .collect();
    PyList::new(py, items)
}

impl PyWorld {
    /// Wraps a Rust world.
    pub fn wrap(world: World) -> Self {
        PyWorld {
            inner: Excl::new(world),
        }
    }

    fn create_joint_def(&self, def: JointDef) -> PyResult<Joint> {
        Ok(self.inner.lock().create_joint(&def).py()?.into())
    }
}

fn snapshot_error(e: janus2d::SnapshotError) -> PyErr {
    let kind = match &e {
        janus2d::SnapshotError::Truncated { .. } => "Truncated",
        janus2d::SnapshotError::BadMagic => "BadMagic",
        janus2d::SnapshotError::WrongVersion { .. } => "WrongVersion",
        janus2d::SnapshotError::WrongBuild { .. } => "WrongBuild",
        janus2d::SnapshotError::TrailingBytes { .. } => "TrailingBytes",
        janus2d::SnapshotError::Checksum => "Checksum",
        janus2d::SnapshotError::Decode(_) => "Decode",
        janus2d::SnapshotError::Invalid(_) => "Invalid",
    };
    raise("SnapshotError", kind, e.to_string())
}

/// A world from snapshot bytes.
pub fn world_from_bytes(data: &[u8]) -> PyResult<World> {
    Ok(Snapshot::from_bytes(data)
        .map_err(snapshot_error)?
        .to_world())
}

#[pymethods]
impl PyWorld {
    #[new]
    #[pyo3(signature = (**kwargs))]
    fn py_new(py: Python<'_>, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let mut take = Take::new(py, kwargs)?;
        let mut def = WorldDef::default();
        kw::world_def(&mut def, &mut take)?;
        if let Some(mode) = take.pop::<u32>("solver_mode")? {
            def.solver.mode = match mode {
                0 => janus2d::SolverMode::SoftStep,
                1 => janus2d::SolverMode::PgsBaumgarte,
                _ => {
                    return Err(PyValueError::new_err(
                        "solver_mode: 0 (soft step) or 1 (PGS)",
                    ));
                }
            };
        }
        take.finish("World")?;
        Ok(PyWorld::wrap(World::new(def).py()?))
    }

    // ---- the step -------------------------------------------------------

    /// Steps the world `steps` times by `dt` seconds (the GIL is released
    /// while it runs).
    #[pyo3(signature = (dt = 1.0 / 60.0, steps = 1))]
    fn step(&self, py: Python<'_>, dt: f64, steps: u32) -> PyResult<()> {
        let mut world = self.inner.lock();
        let world: &mut World = &mut world;
        py.detach(|| {
            for _ in 0..steps {
                world.step(dt as Real)?;
            }
            Ok::<(), WorldError>(())
        })
        .py()
    }

    /// Gravity, m/s².
    #[getter]
    fn gravity(&self) -> (f64, f64) {
        pair(self.inner.lock().gravity())
    }

    #[setter]
    fn set_gravity(&self, g: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner.lock().set_gravity(vec2(g)?).py()
    }

    /// Steps taken so far.
    #[getter]
    fn step_count(&self) -> u64 {
        self.inner.lock().step_count()
    }

    /// Live bodies (portal clones included).
    #[getter]
    fn body_count(&self) -> usize {
        self.inner.lock().body_count()
    }

    /// Live shapes.
    #[getter]
    fn shape_count(&self) -> usize {
        self.inner.lock().shape_count()
    }

    /// Live joints.
    #[getter]
    fn joint_count(&self) -> usize {
        self.inner.lock().joint_count()
    }

    /// Touching contacts.
    #[getter]
    fn touching_contact_count(&self) -> usize {
        self.inner.lock().touching_contact_count()
    }

    /// A 64-bit hash of the whole simulation state (equal states, equal
    /// hashes: the determinism check).
    fn state_hash(&self) -> u64 {
        self.inner.lock().state_hash()
    }

    /// Every live body.
    fn bodies(&self) -> Vec<Body> {
        self.inner.lock().body_handles().map(Body::from).collect()
    }

    // ---- bodies ---------------------------------------------------------

    /// Creates a body: `create_body("dynamic", (x, y), angle=0, …)`; the
    /// keywords are the Rust `BodyDef`'s fields (`janus2d.defaults("body")`)
    /// plus `mass` and `rotational_inertia` (both or neither: a fixed
    /// mass instead of the shapes' density).
    #[pyo3(signature = (body_type = "dynamic", position = None, **kwargs))]
    fn create_body(
        &self,
        py: Python<'_>,
        body_type: &str,
        position: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Body> {
        let p = match position {
            Some(p) => vec2(p)?,
            None => Vec2::ZERO,
        };
        let mut def = match body_type_of(body_type)? {
            BodyType::Dynamic => BodyDef::dynamic(p),
            BodyType::Static => BodyDef::fixed(p),
            BodyType::Kinematic => BodyDef::kinematic(p),
        };
        let mut take = Take::new(py, kwargs)?;
        kw::body_def(&mut def, &mut take)?;
        let mass = take.pop::<Real>("mass")?;
        let inertia = take.pop::<Real>("rotational_inertia")?;
        take.finish("create_body")?;
        match (mass, inertia) {
            (Some(m), Some(i)) => def = def.with_mass(m, i),
            (None, None) => {}
            _ => {
                return Err(PyTypeError::new_err(
                    "create_body: give both `mass` and `rotational_inertia`, or neither",
                ));
            }
        }
        Ok(self.inner.lock().create_body(&def).py()?.into())
    }

    /// Destroys a body, its shapes and its joints.
    fn destroy_body(&self, body: Body) -> PyResult<()> {
        self.inner.lock().destroy_body(body.raw()).py()
    }

    /// The body origin, m.
    fn position(&self, body: Body) -> PyResult<(f64, f64)> {
        Ok(pair(self.inner.lock().position(body.raw()).py()?))
    }

    /// The body angle, rad.
    fn angle(&self, body: Body) -> PyResult<f64> {
        Ok(f64::from(self.inner.lock().angle(body.raw()).py()?))
    }

    /// The centre of mass in world coordinates, m.
    fn center_of_mass(&self, body: Body) -> PyResult<(f64, f64)> {
        Ok(pair(self.inner.lock().center_of_mass(body.raw()).py()?))
    }

    /// The velocity of the centre of mass, m/s.
    fn linear_velocity(&self, body: Body) -> PyResult<(f64, f64)> {
        Ok(pair(self.inner.lock().linear_velocity(body.raw()).py()?))
    }

    /// The angular velocity, rad/s.
    fn angular_velocity(&self, body: Body) -> PyResult<f64> {
        Ok(f64::from(
            self.inner.lock().angular_velocity(body.raw()).py()?,
        ))
    }

    /// Mass, kg.
    fn mass(&self, body: Body) -> PyResult<f64> {
        Ok(f64::from(self.inner.lock().mass(body.raw()).py()?))
    }

    /// Rotational inertia about the centre of mass, kg·m².
    fn rotational_inertia(&self, body: Body) -> PyResult<f64> {
        Ok(f64::from(
            self.inner.lock().rotational_inertia(body.raw()).py()?,
        ))
    }

    /// `"dynamic"`, `"static"` or `"kinematic"`.
    fn body_type(&self, body: Body) -> PyResult<&'static str> {
        Ok(body_type_name(
            self.inner.lock().body_type(body.raw()).py()?,
        ))
    }

    /// Whether the body is awake.
    fn is_awake(&self, body: Body) -> PyResult<bool> {
        self.inner.lock().is_awake(body.raw()).py()
    }

    /// Wakes the body (or puts its island to sleep).
    fn set_awake(&self, body: Body, awake: bool) -> PyResult<()> {
        self.inner.lock().set_awake(body.raw(), awake).py()
    }

    /// The body's user data (a u64).
    fn body_user_data(&self, body: Body) -> PyResult<u64> {
        self.inner.lock().body_user_data(body.raw()).py()
    }

    /// Teleports the body.
    fn set_transform(&self, body: Body, position: &Bound<'_, PyAny>, angle: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_transform(body.raw(), vec2(position)?, angle as Real)
            .py()
    }

    /// Sets the velocity of the centre of mass.
    fn set_linear_velocity(&self, body: Body, v: &Bound<'_, PyAny>) -> PyResult<()> {
        self.inner
            .lock()
            .set_linear_velocity(body.raw(), vec2(v)?)
            .py()
    }

    /// Sets the angular velocity.
    fn set_angular_velocity(&self, body: Body, w: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_angular_velocity(body.raw(), w as Real)
            .py()
    }

    /// A force for the next step at a world point (default: the centre of
    /// mass), N.
    #[pyo3(signature = (body, force, point = None))]
    fn apply_force(
        &self,
        body: Body,
        force: &Bound<'_, PyAny>,
        point: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut w = self.inner.lock();
        let f = vec2(force)?;
        match point {
            Some(p) => w.apply_force(body.raw(), f, vec2(p)?).py(),
            None => w.apply_force_to_center(body.raw(), f).py(),
        }
    }

    /// A torque for the next step, N·m.
    fn apply_torque(&self, body: Body, torque: f64) -> PyResult<()> {
        self.inner
            .lock()
            .apply_torque(body.raw(), torque as Real)
            .py()
    }

    /// A linear impulse at a world point (default: the centre of mass), N·s.
    #[pyo3(signature = (body, impulse, point = None))]
    fn apply_linear_impulse(
        &self,
        body: Body,
        impulse: &Bound<'_, PyAny>,
        point: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let mut w = self.inner.lock();
        let p = match point {
            Some(p) => vec2(p)?,
            None => w.center_of_mass(body.raw()).py()?,
        };
        w.apply_linear_impulse(body.raw(), vec2(impulse)?, p).py()
    }

    /// An angular impulse, N·m·s.
    fn apply_angular_impulse(&self, body: Body, impulse: f64) -> PyResult<()> {
        self.inner
            .lock()
            .apply_angular_impulse(body.raw(), impulse as Real)
            .py()
    }

    /// Number of touching solid contacts of the body.
    fn contact_count(&self, body: Body) -> PyResult<usize> {
        Ok(self.inner.lock().body_contacts(body.raw()).py()?.count())
    }

    /// The bodies touching this one through solid contacts.
    fn touching_bodies(&self, body: Body) -> PyResult<Vec<Body>> {
        let w = self.inner.lock();
        let b = body.raw();
        let mut out = Vec::new();
        for c in w.body_contacts(b).py()? {
            let other = if c.body_a == b { c.body_b } else { c.body_a };
            out.push(Body::from(other));
        }
        Ok(out)
    }

    // ---- bulk state: numpy arrays, one call for many bodies ---------------

    /// `(n, 6)` float64: `x, y, angle, vx, vy, ω` of each body (origin
    /// position, centre-of-mass velocity).
    fn get_state<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let handles = bodies_of(bodies)?;
        let w = self.inner.lock();
        let mut out = Vec::with_capacity(handles.len() * 6);
        for &b in &handles {
            let p = w.position(b).py()?;
            let v = w.linear_velocity(b).py()?;
            out.extend([
                p.x,
                p.y,
                w.angle(b).py()?,
                v.x,
                v.y,
                w.angular_velocity(b).py()?,
            ]);
        }
        let out: Vec<f64> = out.into_iter().map(f64::from).collect();
        PyArray1::from_vec(py, out).reshape([handles.len(), 6])
    }

    /// `(n, 2)` float64: each body's origin.
    fn get_positions<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let handles = bodies_of(bodies)?;
        let w = self.inner.lock();
        let mut out = Vec::with_capacity(handles.len() * 2);
        for &b in &handles {
            let p = w.position(b).py()?;
            out.extend([f64::from(p.x), f64::from(p.y)]);
        }
        PyArray1::from_vec(py, out).reshape([handles.len(), 2])
    }

    /// `(n,)` float64: each body's angle.
    fn get_angles<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let handles = bodies_of(bodies)?;
        let w = self.inner.lock();
        let out: PyResult<Vec<f64>> = handles
            .iter()
            .map(|&b| Ok(f64::from(w.angle(b).py()?)))
            .collect();
        Ok(PyArray1::from_vec(py, out?))
    }

    /// `(n, 3)` float64: `vx, vy, ω` of each body.
    fn get_velocities<'py>(
        &self,
        py: Python<'py>,
        bodies: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let handles = bodies_of(bodies)?;
        let w = self.inner.lock();
        let mut out = Vec::with_capacity(handles.len() * 3);
        for &b in &handles {
            let v = w.linear_velocity(b).py()?;
            let av = w.angular_velocity(b).py()?;
            out.extend([f64::from(v.x), f64::from(v.y), f64::from(av)]);
        }
        PyArray1::from_vec(py, out).reshape([handles.len(), 3])
    }

    /// Sets `x, y, angle, vx, vy, ω` of each body from an `(n, 6)` array.
    /// Every row is checked before any body changes.
    fn set_state(
        &self,
        bodies: &Bound<'_, PyAny>,
        state: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let values = values_of(&state, &[handles.len(), 6], "state")?;
        if values.iter().any(|v| !v.is_finite()) {
            return Err(crate::world_error(WorldError::NonFinite("state")));
        }
        let mut w = self.inner.lock();
        for &b in &handles {
            w.position(b).py()?;
        }
        for (&b, row) in handles.iter().zip(values.chunks(6)) {
            let r: Vec<Real> = row.iter().map(|&x| x as Real).collect();
            w.set_transform(b, Vec2::new(r[0], r[1]), r[2]).py()?;
            if w.body_type(b).py()? != BodyType::Static {
                w.set_linear_velocity(b, Vec2::new(r[3], r[4])).py()?;
                w.set_angular_velocity(b, r[5]).py()?;
            }
        }
        Ok(())
    }

    /// Sets `vx, vy, ω` of each body from an `(n, 3)` array.
    fn set_velocities(
        &self,
        bodies: &Bound<'_, PyAny>,
        velocities: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let values = values_of(&velocities, &[handles.len(), 3], "velocities")?;
        let mut w = self.inner.lock();
        for (&b, r) in handles.iter().zip(values.chunks(3)) {
            w.set_linear_velocity(b, Vec2::new(r[0] as Real, r[1] as Real))
                .py()?;
            w.set_angular_velocity(b, r[2] as Real).py()?;
        }
        Ok(())
    }

    /// Applies `fx, fy` at the centre of mass and a torque to each body
    /// from an `(n, 3)` array, for the next step.
    fn apply_forces(
        &self,
        bodies: &Bound<'_, PyAny>,
        forces: PyArrayLikeDyn<'_, f64, AllowTypeChange>,
    ) -> PyResult<()> {
        let handles = bodies_of(bodies)?;
        let values = values_of(&forces, &[handles.len(), 3], "forces")?;
        let mut w = self.inner.lock();
        for (&b, r) in handles.iter().zip(values.chunks(3)) {
            w.apply_force_to_center(b, Vec2::new(r[0] as Real, r[1] as Real))
                .py()?;
            w.apply_torque(b, r[2] as Real).py()?;
        }
        Ok(())
    }

    // ---- shapes ---------------------------------------------------------

    /// A box of half widths `hx`, `hy` (optionally offset, turned and
    /// rounded); keywords are the `ShapeDef`'s (`janus2d.defaults("shape")`).
    #[pyo3(signature = (body, hx, hy, center = None, angle = 0.0, radius = 0.0, **kwargs))]
    fn create_box(
        &self,
        py: Python<'_>,
        body: Body,
        hx: f64,
        hy: f64,
        center: Option<&Bound<'_, PyAny>>,
        angle: f64,
        radius: f64,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Shape> {
        let def = shape_def_of(py, kwargs)?;
        let c = match center {
            Some(c) => vec2(c)?,
            None => Vec2::ZERO,
        };
        let (hx, hy, angle, radius) = (hx as Real, hy as Real, angle as Real, radius as Real);
        let poly = if radius == 0.0 {
            Polygon::try_make_offset_box(hx, hy, c, angle).py()?
        } else if c == Vec2::ZERO && angle == 0.0 {
            Polygon::try_make_rounded_box(hx, hy, radius).py()?
        } else {
            return Err(PyValueError::new_err(
                "create_box: a rounded box cannot be offset or turned (use create_polygon)",
            ));
        };
        Ok(self
            .inner
            .lock()
            .create_shape(body.raw(), &def, poly)
            .py()?
            .into())
    }

    /// A circle.
    #[pyo3(signature = (body, radius, center = None, **kwargs))]
    fn create_circle(
        &self,
        py: Python<'_>,
        body: Body,
        radius: f64,
        center: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Shape> {
        let def = shape_def_of(py, kwargs)?;
        let c = match center {
            Some(c) => vec2(c)?,
            None => Vec2::ZERO,
        };
        let circle = Circle::new(c, radius as Real).py()?;
        Ok(self
            .inner
            .lock()
            .create_shape(body.raw(), &def, circle)
            .py()?
            .into())
    }

    /// A capsule from `p1` to `p2`.
    #[pyo3(signature = (body, p1, p2, radius, **kwargs))]
    fn create_capsule(
        &self,
        py: Python<'_>,
        body: Body,
        p1: &Bound<'_, PyAny>,
        p2: &Bound<'_, PyAny>,
        radius: f64,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Shape> {
        let def = shape_def_of(py, kwargs)?;
        let capsule = Capsule::new(vec2(p1)?, vec2(p2)?, radius as Real).py()?;
        Ok(self
            .inner
            .lock()
            .create_shape(body.raw(), &def, capsule)
            .py()?
            .into())
    }

    /// The convex hull of up to 8 points (body frame), optionally rounded.
    #[pyo3(signature = (body, points, radius = 0.0, **kwargs))]
    fn create_polygon(
        &self,
        py: Python<'_>,
        body: Body,
        points: &Bound<'_, PyAny>,
        radius: f64,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Shape> {
        let def = shape_def_of(py, kwargs)?;
        let pts: PyResult<Vec<Vec2>> = points.try_iter()?.map(|p| vec2(&p?)).collect();
        let poly = Polygon::from_hull(&pts?, radius as Real).py()?;
        Ok(self
            .inner
            .lock()
            .create_shape(body.raw(), &def, poly)
            .py()?
            .into())
    }

    /// A two-sided segment.
    #[pyo3(signature = (body, p1, p2, **kwargs))]
    fn create_segment(
        &self,
        py: Python<'_>,
        body: Body,
        p1: &Bound<'_, PyAny>,
        p2: &Bound<'_, PyAny>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Shape> {
        let def = shape_def_of(py, kwargs)?;
        let seg = Segment::new(vec2(p1)?, vec2(p2)?).py()?;
        Ok(self
            .inner
            .lock()
            .create_shape(body.raw(), &def, seg)
            .py()?
            .into())
    }

    /// One-sided chain segments through `points` (solid on the right of
    /// their direction), closed into a loop if `closed`.
    #[pyo3(signature = (body, points, closed = false, **kwargs))]
    fn create_chain(
        &self,
        py: Python<'_>,
        body: Body,
        points: &Bound<'_, PyAny>,
        closed: bool,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Vec<Shape>> {
        let def = shape_def_of(py, kwargs)?;
        let pts: PyResult<Vec<Vec2>> = points.try_iter()?.map(|p| vec2(&p?)).collect();
        let segments = janus2d::make_chain(&pts?, closed).py()?;
        let mut w = self.inner.lock();
        w.body_type(body.raw()).py()?;
        let mut out = Vec::with_capacity(segments.len());
        for s in segments {
            out.push(Shape::from(w.create_shape(body.raw(), &def, s).py()?));
        }
        Ok(out)
    }

    /// Destroys a shape (the body's mass follows its remaining shapes).
    fn destroy_shape(&self, shape: Shape) -> PyResult<()> {
        self.inner
            .lock()
            .destroy_shape(shape.raw::<janus2d::base::handle::ShapeTag>())
            .py()
    }

    /// The body a shape belongs to.
    fn shape_body(&self, shape: Shape) -> PyResult<Body> {
        let h: ShapeHandle = shape.raw();
        Ok(self.inner.lock().shape_body(h).py()?.into())
    }

    /// The shape's user data.
    fn shape_user_data(&self, shape: Shape) -> PyResult<u64> {
        let h: ShapeHandle = shape.raw();
        self.inner.lock().shape_user_data(h).py()
    }

    /// The shapes of a body.
    fn body_shapes(&self, body: Body) -> PyResult<Vec<Shape>> {
        let w = self.inner.lock();
        Ok(w.body_shapes(body.raw())
            .py()?
            .into_iter()
            .map(Shape::from)
            .collect())
    }

    // ---- joints ---------------------------------------------------------

    /// A revolute joint (a pin) at the world point `anchor`; keywords are
    /// the `RevoluteJointDef`'s (`janus2d.defaults("revolute")`).
    #[pyo3(signature = (body_a, body_b, anchor, **kwargs))]
    fn create_revolute_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        anchor: &Bound<'_, PyAny>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let base = self
            .inner
            .lock()
            .joint_base_at(body_a.raw(), body_b.raw(), vec2(anchor)?)
            .py()?;
        let mut def = RevoluteJointDef::from_base(base);
        let mut take = Take::new(py, kwargs)?;
        kw::revolute(&mut def, &mut take)?;
        take.finish("create_revolute_joint")?;
        self.create_joint_def(def.into())
    }

    /// A prismatic joint (a slide along the world direction `axis`).
    #[pyo3(signature = (body_a, body_b, anchor, axis = None, **kwargs))]
    fn create_prismatic_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        anchor: &Bound<'_, PyAny>,
        axis: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let axis = match axis {
            Some(a) => vec2(a)?,
            None => Vec2::X,
        };
        let base = self
            .inner
            .lock()
            .joint_base_along(
                body_a.raw(),
                body_b.raw(),
                vec2(anchor)?,
                axis.y.atan2(axis.x),
            )
            .py()?;
        let mut def = PrismaticJointDef::from_base(base);
        let mut take = Take::new(py, kwargs)?;
        kw::prismatic(&mut def, &mut take)?;
        take.finish("create_prismatic_joint")?;
        self.create_joint_def(def.into())
    }

    /// A wheel joint (a sprung suspension along `axis`, default up).
    #[pyo3(signature = (body_a, body_b, anchor, axis = None, **kwargs))]
    fn create_wheel_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        anchor: &Bound<'_, PyAny>,
        axis: Option<&Bound<'_, PyAny>>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let axis = match axis {
            Some(a) => vec2(a)?,
            None => Vec2::Y,
        };
        let base = self
            .inner
            .lock()
            .joint_base_along(
                body_a.raw(),
                body_b.raw(),
                vec2(anchor)?,
                axis.y.atan2(axis.x),
            )
            .py()?;
        let mut def = WheelJointDef::from_base(base);
        let mut take = Take::new(py, kwargs)?;
        kw::wheel(&mut def, &mut take)?;
        take.finish("create_wheel_joint")?;
        self.create_joint_def(def.into())
    }

    /// A weld joint at the world point `anchor`.
    #[pyo3(signature = (body_a, body_b, anchor, **kwargs))]
    fn create_weld_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        anchor: &Bound<'_, PyAny>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let base = self
            .inner
            .lock()
            .joint_base_at(body_a.raw(), body_b.raw(), vec2(anchor)?)
            .py()?;
        let mut def = WeldJointDef::from_base(base);
        let mut take = Take::new(py, kwargs)?;
        kw::weld(&mut def, &mut take)?;
        take.finish("create_weld_joint")?;
        self.create_joint_def(def.into())
    }

    /// A distance joint between world points `anchor_a` (on body A) and
    /// `anchor_b` (on body B); `length` defaults to their distance.
    #[pyo3(signature = (body_a, body_b, anchor_a, anchor_b, length = None, **kwargs))]
    fn create_distance_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        anchor_a: &Bound<'_, PyAny>,
        anchor_b: &Bound<'_, PyAny>,
        length: Option<f64>,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let (pa, pb) = (vec2(anchor_a)?, vec2(anchor_b)?);
        let base = {
            let w = self.inner.lock();
            let mut base = w.joint_base_at(body_a.raw(), body_b.raw(), pa).py()?;
            // Body B's anchor is its own world point.
            let other = w.joint_base_at(body_a.raw(), body_b.raw(), pb).py()?;
            base.local_frame_b = other.local_frame_b;
            base
        };
        let len = length.map_or((pb - pa).length(), |l| l as Real);
        let mut def = DistanceJointDef::from_base(base, len);
        let mut take = Take::new(py, kwargs)?;
        kw::distance(&mut def, &mut take)?;
        take.finish("create_distance_joint")?;
        self.create_joint_def(def.into())
    }

    /// A motor joint driving body B toward an offset pose from body A.
    #[pyo3(signature = (body_a, body_b, **kwargs))]
    fn create_motor_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let mut def = MotorJointDef::new(body_a.raw(), body_b.raw());
        let mut take = Take::new(py, kwargs)?;
        kw::motor(&mut def, &mut take)?;
        take.finish("create_motor_joint")?;
        self.create_joint_def(def.into())
    }

    /// A mouse joint pulling body B's point under `target` toward it.
    #[pyo3(signature = (body_a, body_b, target, max_force, **kwargs))]
    fn create_mouse_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        target: &Bound<'_, PyAny>,
        max_force: f64,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let t = vec2(target)?;
        let base = self
            .inner
            .lock()
            .joint_base_at(body_a.raw(), body_b.raw(), t)
            .py()?;
        let mut def = MouseJointDef::from_base(base, t, max_force as Real);
        let mut take = Take::new(py, kwargs)?;
        kw::mouse(&mut def, &mut take)?;
        take.finish("create_mouse_joint")?;
        self.create_joint_def(def.into())
    }

    /// A filter joint: no rows, its two bodies stop colliding.
    #[pyo3(signature = (body_a, body_b, **kwargs))]
    fn create_filter_joint(
        &self,
        py: Python<'_>,
        body_a: Body,
        body_b: Body,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Joint> {
        let mut def = FilterJointDef::new(body_a.raw(), body_b.raw());
        let mut take = Take::new(py, kwargs)?;
        kw::joint_base(&mut def.base, &mut take)?;
        take.finish("create_filter_joint")?;
        self.create_joint_def(def.into())
    }

    /// Destroys a joint.
    fn destroy_joint(&self, joint: Joint) -> PyResult<()> {
        self.inner.lock().destroy_joint(joint.raw()).py()
    }

    /// The joint's kind: `"revolute"`, `"prismatic"`, ….
    fn joint_kind(&self, joint: Joint) -> PyResult<String> {
        let w = self.inner.lock();
        let kind = w.joints().kind(joint.raw()).py()?;
        Ok(format!("{kind:?}").to_lowercase())
    }

    /// The joint's two bodies.
    fn joint_bodies(&self, joint: Joint) -> PyResult<(Body, Body)> {
        let w = self.inner.lock();
        let (a, b) = w.joints().bodies_of(joint.raw()).py()?;
        Ok((a.into(), b.into()))
    }

    /// The joint angle (body B relative to body A, from the reference), rad.
    fn joint_angle(&self, joint: Joint) -> PyResult<f64> {
        Ok(f64::from(self.inner.lock().joint_angle(joint.raw()).py()?))
    }

    /// The joint's constraint force on body B in the last step, N.
    fn joint_force(&self, joint: Joint) -> PyResult<(f64, f64)> {
        Ok(pair(self.inner.lock().joint_force(joint.raw()).py()?))
    }

    /// The joint's constraint torque on body B in the last step, N·m.
    fn joint_torque(&self, joint: Joint) -> PyResult<f64> {
        Ok(f64::from(self.inner.lock().joint_torque(joint.raw()).py()?))
    }

    /// Sets a joint motor's speed (rad/s or m/s).
    fn set_joint_motor_speed(&self, joint: Joint, speed: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_joint_motor_speed(joint.raw(), speed as Real)
            .py()
    }

    /// Sets a revolute or wheel motor's largest torque, N·m.
    fn set_joint_max_motor_torque(&self, joint: Joint, torque: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_joint_max_motor_torque(joint.raw(), torque as Real)
            .py()
    }

    /// Sets a prismatic or distance motor's largest force, N.
    fn set_joint_max_motor_force(&self, joint: Joint, force: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_joint_max_motor_force(joint.raw(), force as Real)
            .py()
    }

    /// Turns a joint's motor on or off.
    fn enable_joint_motor(&self, joint: Joint, on: bool) -> PyResult<()> {
        self.inner.lock().enable_joint_motor(joint.raw(), on).py()
    }

    /// Sets a joint's limits (angles or translations).
    fn set_joint_limits(&self, joint: Joint, lower: f64, upper: f64) -> PyResult<()> {
        self.inner
            .lock()
            .set_joint_limits(joint.raw(), lower as Real, upper as Real)
            .py()
    }

    /// Turns a joint's limit on or off.
    fn enable_joint_limit(&self, joint: Joint, on: bool) -> PyResult<()> {
        self.inner.lock().enable_joint_limit(joint.raw(), on).py()
    }

    // ---- portals --------------------------------------------------------

    /// A portal pair: portal A on `body_a` at `anchor_a` (body frame)
    /// facing `direction_a` with `half_width_a`, and the same for B; `eta`
    /// is the scale B/A (default 1), `mass_model` `"same_material"` or
    /// `"energy_preserving"`.
    #[pyo3(signature = (body_a, anchor_a, direction_a, half_width_a, body_b, anchor_b,
        direction_b, half_width_b, eta = None, mass_model = "same_material"))]
    fn create_portal_pair(
        &self,
        body_a: Body,
        anchor_a: &Bound<'_, PyAny>,
        direction_a: &Bound<'_, PyAny>,
        half_width_a: f64,
        body_b: Body,
        anchor_b: &Bound<'_, PyAny>,
        direction_b: &Bound<'_, PyAny>,
        half_width_b: f64,
        eta: Option<f64>,
        mass_model: &str,
    ) -> PyResult<PortalPair> {
        let mut def = PortalPairDef::new(
            PortalDef::new(
                body_a.raw(),
                vec2(anchor_a)?,
                vec2(direction_a)?,
                half_width_a as Real,
            ),
            PortalDef::new(
                body_b.raw(),
                vec2(anchor_b)?,
                vec2(direction_b)?,
                half_width_b as Real,
            ),
        );
        def.eta = eta.map(|e| e as Real);
        def.mass_model = match mass_model {
            "same_material" => MassModel::SameMaterial,
            "energy_preserving" => MassModel::EnergyPreserving,
            other => {
                return Err(PyValueError::new_err(format!(
                    "mass_model `{other}`: same_material or energy_preserving"
                )));
            }
        };
        Ok(self.inner.lock().create_portal_pair(&def).py()?.into())
    }

    /// Destroys a portal pair (crossings in progress are cancelled).
    fn destroy_portal_pair(&self, pair: PortalPair) -> PyResult<()> {
        self.inner.lock().destroy_portal_pair(pair.raw()).py()
    }

    /// Bodies crossing a portal now.
    #[getter]
    fn crossing_count(&self) -> usize {
        self.inner.lock().crossing_count()
    }

    /// The clone of a body crossing a portal, or None.
    fn clone_of(&self, body: Body) -> Option<Body> {
        self.inner.lock().clone_of(body.raw()).map(Body::from)
    }

    /// The last step's portal events: dicts with `type`
    /// (`"crossing_started"`, `"crossing_completed"`,
    /// `"crossing_cancelled"`, `"joint_disabled"`) and their handles.
    fn portal_events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let w = self.inner.lock();
        let list = PyList::empty(py);
        for e in &w.events().portals {
            let d = PyDict::new(py);
            match *e {
                PortalEvent::CrossingStarted { body, clone, pair } => {
                    d.set_item("type", "crossing_started")?;
                    d.set_item("body", Body::from(body))?;
                    d.set_item("clone", Body::from(clone))?;
                    d.set_item("pair", PortalPair::from(pair))?;
                }
                PortalEvent::CrossingCompleted { body, pair } => {
                    d.set_item("type", "crossing_completed")?;
                    d.set_item("body", Body::from(body))?;
                    d.set_item("pair", PortalPair::from(pair))?;
                }
                PortalEvent::CrossingCancelled { body, pair } => {
                    d.set_item("type", "crossing_cancelled")?;
                    d.set_item("body", Body::from(body))?;
                    d.set_item("pair", PortalPair::from(pair))?;
                }
                PortalEvent::JointDisabled { joint, pair, .. } => {
                    d.set_item("type", "joint_disabled")?;
                    d.set_item("joint", Joint::from(joint))?;
                    d.set_item("pair", PortalPair::from(pair))?;
                }
                #[allow(unreachable_patterns)]
                _ => d.set_item("type", "other")?,
            }
            list.append(d)?;
        }
        Ok(list)
    }

    // ---- queries --------------------------------------------------------

    /// The closest hit of a ray from `origin` along `translation`, or
    /// None: a dict with `shape`, `body`, `point`, `normal`, `fraction`,
    /// `portal_hops`.
    #[pyo3(signature = (origin, translation, mask_bits = u64::MAX, category_bits = 1,
        exclude = None, through_portals = false))]
    fn cast_ray<'py>(
        &self,
        py: Python<'py>,
        origin: &Bound<'py, PyAny>,
        translation: &Bound<'py, PyAny>,
        mask_bits: u64,
        category_bits: u64,
        exclude: Option<Body>,
        through_portals: bool,
    ) -> PyResult<Option<Bound<'py, PyDict>>> {
        let filter = query_filter(mask_bits, category_bits, exclude, through_portals);
        let hit = self
            .inner
            .lock()
            .cast_ray_closest(vec2(origin)?, vec2(translation)?, &filter)
            .py()?;
        let Some(hit) = hit else { return Ok(None) };
        let d = PyDict::new(py);
        d.set_item("shape", Shape::from(hit.shape))?;
        d.set_item("body", Body::from(hit.body))?;
        d.set_item("point", pair(hit.point))?;
        d.set_item("normal", pair(hit.normal))?;
        d.set_item("fraction", f64::from(hit.fraction))?;
        d.set_item("portal_hops", hit.portal_hops)?;
        Ok(Some(d))
    }

    /// `(shape, body)` of every solid shape containing `point`.
    #[pyo3(signature = (point, mask_bits = u64::MAX, category_bits = 1, exclude = None))]
    fn overlap_point(
        &self,
        point: &Bound<'_, PyAny>,
        mask_bits: u64,
        category_bits: u64,
        exclude: Option<Body>,
    ) -> PyResult<Vec<(Shape, Body)>> {
        let filter = query_filter(mask_bits, category_bits, exclude, false);
        let mut out = Vec::new();
        self.inner
            .lock()
            .overlap_point(vec2(point)?, &filter, |o| {
                out.push((Shape::from(o.shape), Body::from(o.body)));
                true
            })
            .py()?;
        Ok(out)
    }

    /// `(shape, body)` of every shape whose surface meets the box
    /// `lower`–`upper`.
    #[pyo3(signature = (lower, upper, mask_bits = u64::MAX, category_bits = 1, exclude = None))]
    fn overlap_aabb(
        &self,
        lower: &Bound<'_, PyAny>,
        upper: &Bound<'_, PyAny>,
        mask_bits: u64,
        category_bits: u64,
        exclude: Option<Body>,
    ) -> PyResult<Vec<(Shape, Body)>> {
        let filter = query_filter(mask_bits, category_bits, exclude, false);
        let aabb = Aabb::new(vec2(lower)?, vec2(upper)?);
        let mut out = Vec::new();
        self.inner
            .lock()
            .overlap_aabb(&aabb, &filter, |o| {
                out.push((Shape::from(o.shape), Body::from(o.body)));
                true
            })
            .py()?;
        Ok(out)
    }

    // ---- events ---------------------------------------------------------

    /// The last step's events: a dict of `contact_begin`, `contact_end`
    /// (lists of shape pairs), `contact_begin_manifolds` (dicts with
    /// `normal`, `points`, `user_material_ids`, one per begin),
    /// `sensor_begin`, `sensor_end` (lists of (sensor, visitor) pairs),
    /// `hits` (dicts with `shape_a`, `shape_b`, `point`, `point_a`,
    /// `point_b`, `normal`, `approach_speed`), `forces` (dicts with
    /// `shape_a`, `shape_b`, `total_force`, `max_force`), `moves` (dicts
    /// with `body`, `position`, `angle`, `user_data`, `fell_asleep`),
    /// `joints` (dicts with `joint`, `force`, `torque`) and
    /// `non_finite_bodies`. Portal events: `portal_events()`.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = self.inner.lock();
        let e = w.events();
        let d = PyDict::new(py);
        let begins: Vec<(Shape, Shape)> = e
            .collision
            .contact_begin
            .iter()
            .map(|b| (Shape::from(b.shape_a), Shape::from(b.shape_b)))
            .collect();
        d.set_item("contact_begin", PyList::new(py, begins)?)?;
        let manifolds = PyList::empty(py);
        for b in &e.collision.contact_begin {
            let md = PyDict::new(py);
            md.set_item("normal", pair(b.manifold.normal))?;
            let points: Vec<(f64, f64)> = b.manifold.points().iter().map(|&p| pair(p)).collect();
            md.set_item("points", points)?;
            md.set_item("user_material_ids", b.manifold.user_material_ids.to_vec())?;
            manifolds.append(md)?;
        }
        d.set_item("contact_begin_manifolds", manifolds)?;
        d.set_item("contact_end", shape_pairs(py, &e.collision.contact_end)?)?;
        let sensors = |list: &[janus2d::world::SensorEvent]| -> Vec<(Shape, Shape)> {
            list.iter()
                .map(|s| (Shape::from(s.sensor_shape), Shape::from(s.visitor_shape)))
                .collect()
        };
        d.set_item(
            "sensor_begin",
            PyList::new(py, sensors(&e.collision.sensor_begin))?,
        )?;
        d.set_item(
            "sensor_end",
            PyList::new(py, sensors(&e.collision.sensor_end))?,
        )?;
        let forces = PyList::empty(py);
        for f in &e.collision.forces {
            let fd = PyDict::new(py);
            fd.set_item("shape_a", Shape::from(f.shape_a))?;
            fd.set_item("shape_b", Shape::from(f.shape_b))?;
            fd.set_item("total_force", pair(f.total_force))?;
            fd.set_item("max_force", f64::from(f.max_force_magnitude))?;
            forces.append(fd)?;
        }
        d.set_item("forces", forces)?;
        let moves = PyList::empty(py);
        for m in &e.moves {
            let md = PyDict::new(py);
            md.set_item("body", Body::from(m.body))?;
            md.set_item("position", pair(m.transform.p))?;
            md.set_item("angle", f64::from(m.transform.q.angle()))?;
            md.set_item("user_data", m.user_data)?;
            md.set_item("fell_asleep", m.fell_asleep)?;
            moves.append(md)?;
        }
        d.set_item("moves", moves)?;
        let hits = PyList::empty(py);
        for h in &e.collision.hits {
            let hd = PyDict::new(py);
            hd.set_item("shape_a", Shape::from(h.shape_a))?;
            hd.set_item("shape_b", Shape::from(h.shape_b))?;
            hd.set_item("point", pair(h.point))?;
            hd.set_item("point_a", pair(h.point_a))?;
            hd.set_item("point_b", pair(h.point_b))?;
            hd.set_item("normal", pair(h.normal))?;
            hd.set_item("approach_speed", f64::from(h.approach_speed))?;
            hits.append(hd)?;
        }
        d.set_item("hits", hits)?;
        let joints = PyList::empty(py);
        for j in &e.joints {
            let jd = PyDict::new(py);
            jd.set_item("joint", Joint::from(j.joint))?;
            jd.set_item("force", pair(j.force))?;
            jd.set_item("torque", f64::from(j.torque))?;
            jd.set_item("user_data", j.user_data)?;
            joints.append(jd)?;
        }
        d.set_item("joints", joints)?;
        let nf: Vec<Body> = e.non_finite_bodies.iter().map(|&b| b.into()).collect();
        d.set_item("non_finite_bodies", nf)?;
        Ok(d)
    }

    // ---- snapshots ------------------------------------------------------

    /// The whole world as bytes (a versioned, checksummed snapshot).
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let bytes = self.inner.lock().snapshot().to_bytes();
        PyBytes::new(py, &bytes)
    }

    /// A world from `to_bytes` output; bad bytes raise `SnapshotError`.
    #[staticmethod]
    fn from_bytes(data: &[u8]) -> PyResult<PyWorld> {
        Ok(PyWorld::wrap(world_from_bytes(data)?))
    }

    /// Puts this world back to the state in `data` (from `to_bytes`);
    /// handles this world issued before resolve again.
    fn restore(&self, data: &[u8]) -> PyResult<()> {
        let snapshot = Snapshot::from_bytes(data).map_err(snapshot_error)?;
        self.inner.lock().restore(&snapshot);
        Ok(())
    }

    /// An independent copy (same handles, same future).
    fn copy(&self) -> PyWorld {
        PyWorld::wrap(self.inner.lock().snapshot().to_world())
    }

    fn __copy__(&self) -> PyWorld {
        self.copy()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> PyWorld {
        self.copy()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let from_bytes = slf.get_type().getattr("from_bytes")?;
        let bytes = slf.borrow().to_bytes(py);
        PyTuple::new(py, [from_bytes, PyTuple::new(py, [bytes])?.into_any()])
    }

    fn __repr__(&self) -> String {
        let w = self.inner.lock();
        format!(
            "World(bodies={}, shapes={}, joints={}, step_count={})",
            w.body_count(),
            w.shape_count(),
            w.joint_count(),
            w.step_count()
        )
    }

    // ---- pictures -------------------------------------------------------

    /// An RGB picture of the world, `(height, width, 3)` uint8, drawn by
    /// the render crate. `center` (m) and `scale` (pixels per metre) set
    /// the camera; without them it fits the whole world.
    #[pyo3(signature = (width = 600, height = 400, center = None, scale = None))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        width: u32,
        height: u32,
        center: Option<&Bound<'py, PyAny>>,
        scale: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray3<u8>>> {
        if width == 0 || height == 0 || width > 8192 || height > 8192 {
            return Err(PyValueError::new_err("width and height: 1 to 8192 pixels"));
        }
        let w = self.inner.lock();
        let camera = match (center, scale) {
            (Some(c), Some(s)) if s.is_finite() && s > 0.0 => {
                Camera::new(vec2(c)?, s, width, height)
            }
            (None, None) => Camera::fit_world(&w, width, height),
            _ => {
                return Err(PyValueError::new_err(
                    "render: give `center` and a positive `scale` together, or neither",
                ));
            }
        };
        let mut raster = Raster::new(camera).map_err(|e| PyValueError::new_err(e.to_string()))?;
        raster.draw_world(&w, &DrawOptions::default());
        let rgba = raster.rgba();
        let rgb: Vec<u8> = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        PyArray1::from_vec(py, rgb).reshape([height as usize, width as usize, 3])
    }
}
