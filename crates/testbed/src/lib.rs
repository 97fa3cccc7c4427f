//! # janus2d-testbed
//!
//! The test bed of janus2d's tests, benchmarks and examples (not published):
//! the standard scenes — Box2D v3's ten benchmark scenes, the hard cases
//! and the portal scenes — defined once, as engine-neutral data, with the
//! code that runs and measures them on any engine, and the helpers the
//! integration tests share.
//!
//! | module          | contents                                                        |
//! |-----------------|-----------------------------------------------------------------|
//! | [`desc`]        | the data: bodies, shapes, filters, joints, settings, scripts    |
//! | [`benchmarks`]  | the benchmark scenes as descriptions                            |
//! | [`hard`]        | the hard cases: description, run length, pass bounds            |
//! | [`joint_bench`] | the peers benchmark's joint scenes and their accuracy figures   |
//! | [`joint_zoo`]   | one scene holding every joint kind                              |
//! | [`engine`]      | the [`Engine`](engine::Engine) interface an adapter implements  |
//! | [`janus`]       | janus2d's adapter                                               |
//! | [`measure`]     | metric code shared by all engines (penetration, joint gap, …)  |
//! | [`run`]         | timing as Box2D does it, and the sanity figures                 |
//! | [`scenes`]      | the scenes built into janus2d worlds (tests, examples, benches) |
//! | [`metrics`]     | janus2d's error tracker for the tests and the accuracy sweep    |
//! | [`support`]     | the integration tests' helpers: body specs, strategies, momenta |
//!
//! The peers benchmark (`benches/peers`) adds Box2D's and Rapier's
//! adapters; this crate depends on janus2d alone.
//!
//! ```
//! use janus2d_testbed::engine::Engine;
//! use janus2d_testbed::{hard, janus::Janus};
//! let case = hard::single_box();
//! let outcome = case.run::<Janus>().unwrap();
//! assert!(outcome.pass, "{:?}", outcome.failed);
//! ```

pub mod benchmarks;
pub mod desc;
pub mod engine;
pub mod hard;
pub mod janus;
pub mod joint_bench;
pub mod joint_zoo;
pub mod measure;
pub mod metrics;
#[cfg(feature = "portals")]
pub mod portal_joints;
pub mod run;
pub mod scenes;
pub mod support;
