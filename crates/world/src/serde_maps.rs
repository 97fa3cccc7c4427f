//! Serde helpers the stores share (with the `serde` feature): the
//! solver settings field by field, and hash maps as key-sorted sequences
//! so that snapshot bytes do not depend on iteration order.

/// Serde for [`SolverSettings`](janus2d_core::solver::SolverSettings),
/// field by field (the solver's file carries no serde attribute).
#[cfg(feature = "serde")]
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(remote = "janus2d_core::solver::SolverSettings")]
pub(crate) struct SettingsDef {
    mode: janus2d_core::SolverMode,
    substeps: u32,
    relax_iterations: u32,
    velocity_iterations: u32,
    baumgarte: janus2d_core::math::Real,
    contact_hertz: janus2d_core::math::Real,
    contact_hertz_fraction: janus2d_core::math::Real,
    contact_damping_ratio: janus2d_core::math::Real,
    contact_push_max_velocity: janus2d_core::math::Real,
    joint_hertz: janus2d_core::math::Real,
    joint_hertz_fraction: janus2d_core::math::Real,
    joint_damping_ratio: janus2d_core::math::Real,
    joint_max_correction_speed: janus2d_core::math::Real,
    restitution_threshold: janus2d_core::math::Real,
    warm_starting: bool,
    contact_mass_ratio_cap: janus2d_core::math::Real,
    joint_mass_ratio_cap: janus2d_core::math::Real,
    direct_joints: bool,
    direct_joint_hertz: janus2d_core::math::Real,
    direct_joint_max_correction_speed: janus2d_core::math::Real,
    direct_free_tree_mass_ratio: janus2d_core::math::Real,
}

/// Serde for the world's hash maps as key-sorted sequences: the bytes of
/// a snapshot do not depend on a map's iteration order.
#[cfg(feature = "serde")]
pub(crate) mod sorted_map {
    use std::collections::{BTreeMap, HashMap};
    use std::hash::Hash;

    /// Writes the map in key order.
    pub(crate) fn serialize<K, V, H, S>(map: &HashMap<K, V, H>, s: S) -> Result<S::Ok, S::Error>
    where
        K: serde::Serialize + Ord,
        V: serde::Serialize,
        S: serde::Serializer,
    {
        let sorted: BTreeMap<&K, &V> = map.iter().collect();
        serde::Serialize::serialize(&sorted, s)
    }

    /// Reads a map written by [`serialize`].
    pub(crate) fn deserialize<'de, K, V, H, D>(d: D) -> Result<HashMap<K, V, H>, D::Error>
    where
        K: serde::Deserialize<'de> + Eq + Hash + Ord,
        H: std::hash::BuildHasher + Default,
        V: serde::Deserialize<'de>,
        D: serde::Deserializer<'de>,
    {
        let sorted: BTreeMap<K, V> = serde::Deserialize::deserialize(d)?;
        Ok(sorted.into_iter().collect())
    }
}

/// Serde for a list whose order carries no meaning (the broadphase's move
/// buffer): written sorted, so that a snapshot's bytes do not depend on
/// the order the step happened to fill it in (the proxy update by shape
/// slot on a team, by body on one thread). Read as written: the same
/// format as a plain sequence.
#[cfg(feature = "serde")]
pub(crate) mod sorted_ids {
    /// Writes the ids in increasing order.
    pub(crate) fn serialize<S: serde::Serializer>(ids: &[u32], s: S) -> Result<S::Ok, S::Error> {
        let mut sorted = ids.to_vec();
        sorted.sort_unstable();
        serde::Serialize::serialize(&sorted, s)
    }

    /// Reads ids written by [`serialize`] (or by a plain sequence).
    pub(crate) fn deserialize<'de, D: serde::Deserializer<'de>>(
        d: D,
    ) -> Result<Vec<u32>, D::Error> {
        serde::Deserialize::deserialize(d)
    }
}
