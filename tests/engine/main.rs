//! The engine and its API: bodies, shapes, joints, contacts, queries,
//! continuous collision, snapshots and the step's stages, one module per
//! former test file. One binary instead of one per file: each integration
//! test binary links the engine and the testbed again.

mod api_consistency;
#[cfg(feature = "portals")]
mod api_state_machine;
mod bad_input;
mod breakable_joint;
mod chains;
mod collision_api;
mod contact_data;
mod contact_modification;
mod contact_properties;
mod continuous;
mod continuous_joints;
mod distance;
mod effects;
mod event_replay;
mod filter;
mod joint_api;
mod joint_checks;
mod joint_correction;
mod joint_events;
mod joint_tree_mixed;
mod joint_tree_properties;
mod kinematic_targets;
mod module_imports;
mod motion_setters;
mod motor;
mod mouse;
mod mover;
mod pendulum;
mod point_queries;
mod prismatic;
mod queries;
mod reliability;
mod revolute_properties;
mod setters;
mod shape_body_setters;
mod snapshot;
mod soak;
mod stages;
mod step_events;
mod surface_materials;
mod tree_momentum;
mod weld;
mod wheel;
