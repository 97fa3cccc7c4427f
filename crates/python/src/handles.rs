//! Handles as small immutable Python values: equal, hashable and
//! picklable; they carry the issuing world's id, so a handle used on
//! another world is a `ForeignHandleError`.

use janus2d::base::handle::Handle;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

macro_rules! handle_class {
    ($name:ident, $py:literal, $doc:literal) => {
        #[doc = $doc]
        #[pyclass(module = "janus2d", name = $py, frozen, eq, hash, from_py_object)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub struct $name {
            /// Slot index.
            #[pyo3(get)]
            pub index: u32,
            /// The slot's generation when issued.
            #[pyo3(get)]
            pub generation: u32,
            /// Id of the issuing world.
            #[pyo3(get)]
            pub owner: u32,
        }

        impl<K> From<Handle<K>> for $name {
            fn from(h: Handle<K>) -> Self {
                $name {
                    index: h.index,
                    generation: h.generation,
                    owner: h.owner,
                }
            }
        }

        impl $name {
            /// The engine handle.
            pub fn raw<K>(&self) -> Handle<K> {
                Handle::new(self.index, self.generation, self.owner)
            }
        }

        #[pymethods]
        impl $name {
            /// A handle from its parts (as pickling stores it).
            #[new]
            fn new(index: u32, generation: u32, owner: u32) -> Self {
                $name {
                    index,
                    generation,
                    owner,
                }
            }

            fn __repr__(&self) -> String {
                format!("{}({}v{}@{})", $py, self.index, self.generation, self.owner)
            }

            fn __getnewargs__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
                PyTuple::new(py, [self.index, self.generation, self.owner])
            }
        }
    };
}

handle_class!(Body, "Body", "A body handle (`World.create_body`).");
handle_class!(Shape, "Shape", "A shape handle (`World.create_box`, …).");
handle_class!(
    Joint,
    "Joint",
    "A joint handle (`World.create_revolute_joint`, …)."
);
handle_class!(
    PortalPair,
    "PortalPair",
    "A portal pair handle (`World.create_portal_pair`)."
);
