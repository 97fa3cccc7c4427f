//! Hash maps keyed by slot indices and handles, with a cheap hasher.
//!
//! The world's maps (the joints' no-collide pairs, the collision events'
//! pair index) are keyed by a few small integers and looked up on the
//! step's hot path: a contact's begin or end event, a new pair's filter.
//! The standard library's default hasher resists flooding attacks at about
//! 20 ns a key; these keys come from the engine's own slot allocator, so a
//! multiply-rotate hasher does the job at a fraction of that.
//!
//! | map | key | looked up |
//! |---|---|---|
//! | `NoCollide::pairs` | two body slots | each new broadphase pair |
//! | `CollisionEvents` index | two shape handles, sensor flag | each begin/end event |
//!
//! Neither map is iterated where order matters (snapshots write the
//! no-collide pairs sorted), so the fixed hasher keeps results
//! deterministic, as the random one did.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A hash map over [`KeyHasher`].
pub(crate) type KeyMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// Multiply-rotate hasher for small integer keys: each word is folded in
/// as `h = (rotl(h, 5) ^ w) · K`, with `K` an odd 64-bit constant whose
/// bits are well mixed (the golden ratio's fraction, 2⁶⁴/φ).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct KeyHasher(u64);

/// 2⁶⁴/φ rounded to odd: every key bit reaches the high bits the table
/// reads.
const MIX: u64 = 0x9e37_79b9_7f4a_7c15;

impl KeyHasher {
    #[inline]
    fn fold(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(MIX);
    }
}

impl Hasher for KeyHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut word = [0u8; 8];
            word.copy_from_slice(c);
            self.fold(u64::from_le_bytes(word));
        }
        let rest = chunks.remainder();
        if !rest.is_empty() {
            let mut word = [0u8; 8];
            word[..rest.len()].copy_from_slice(rest);
            self.fold(u64::from_le_bytes(word));
        }
    }

    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.fold(u64::from(i));
    }

    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.fold(u64::from(i));
    }

    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.fold(i);
    }

    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.fold(i as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        // The table reads the top bits for its tags and the low bits for
        // the bucket: fold the high half down so both are mixed.
        self.0 ^ (self.0 >> 29)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::hash::{BuildHasher, Hash};

    fn hash_of<T: Hash>(t: &T) -> u64 {
        BuildHasherDefault::<KeyHasher>::default().hash_one(t)
    }

    #[test]
    fn neighbouring_slot_pairs_spread_over_buckets() {
        // 64 × 64 neighbouring slot pairs into the low 12 bits (a table
        // of 4096 buckets): a random hash fills 4096 (1 − 1/e) ≈ 2589 of
        // them (σ ≈ 20); a hasher that kept the keys' structure would
        // fill far fewer or collide in rows.
        let mut seen = std::collections::BTreeSet::new();
        for a in 0u32..64 {
            for b in 0u32..64 {
                seen.insert(hash_of(&(a, b)) & 0xfff);
            }
        }
        assert!(seen.len() >= 2500, "{} distinct buckets", seen.len());
        // The top 7 bits (the table's tags) take at least 100 of 128.
        let tags: std::collections::BTreeSet<u64> =
            (0u32..4096).map(|i| hash_of(&(i, i + 1)) >> 57).collect();
        assert!(tags.len() >= 100, "{} distinct tags", tags.len());
    }

    #[test]
    fn key_map_finds_what_it_holds() {
        let mut m: KeyMap<(u32, u32, bool), u32> = KeyMap::default();
        for i in 0..1000u32 {
            m.insert((i, i * 7, i % 3 == 0), i);
        }
        assert_eq!(m.len(), 1000);
        for i in 0..1000u32 {
            assert_eq!(m.get(&(i, i * 7, i % 3 == 0)), Some(&i));
            assert_eq!(m.get(&(i, i * 7, i % 3 != 0)), None);
        }
    }
}
