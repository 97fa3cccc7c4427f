//! Portals: the portal constraint and its map on their own (properties,
//! the small simulator) and portals in the world (scenes, apertures,
//! grazing entries, stiff loads, edge cases, joints through a portal).
//! The world's portal tests need the `portals` feature.

#[cfg(feature = "portals")]
mod portal_apertures;
#[cfg(feature = "portals")]
mod portal_continuous;
#[cfg(feature = "portals")]
mod portal_distance;
#[cfg(feature = "portals")]
mod portal_edges;
#[cfg(feature = "portals")]
mod portal_filter;
#[cfg(feature = "portals")]
mod portal_grazing;
#[cfg(feature = "portals")]
mod portal_joints;
#[cfg(feature = "portals")]
mod portal_motor;
#[cfg(feature = "portals")]
mod portal_mouse;
#[cfg(feature = "portals")]
mod portal_mover;
#[cfg(feature = "portals")]
mod portal_prismatic;
mod portal_properties;
#[cfg(feature = "portals")]
mod portal_scenes;
#[cfg(feature = "portals")]
mod portal_shape_handles;
mod portal_sim;
#[cfg(feature = "portals")]
mod portal_stiff;
#[cfg(feature = "portals")]
mod portal_weld;
#[cfg(feature = "portals")]
mod portal_wheel;
