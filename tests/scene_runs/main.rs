//! Whole scenes over many steps: the hard cases and joint scenes with
//! their bounds, the metrics, and determinism (golden hashes, the same
//! result for any thread count). The slowest of the integration tests.

mod determinism;
mod hard_cases;
mod joint_scenes;
mod metrics;
