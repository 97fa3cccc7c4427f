//! The state hash: equal hashes mean bit-identical body states.
//!
//! FNV-1a (64 bit) over every live body in handle order: the slot index,
//! then the bits of `x, y, cos θ, sin θ, v_x, v_y, ω`; then, when the world
//! has chains, every chain in slot order: its slot index and generation,
//! its loop flag and its segment shapes' slot indices (a world without
//! chains hashes as before chains existed). Small, stable across
//! platforms and releases, and cheap enough to run every step in a test.

use janus2d_core::body::BodySet;
use janus2d_core::math::Real;

use crate::chains::ChainSet;

/// The hash of every body's transform and velocity bits, in handle order,
/// then of the chains (none: nothing added).
#[must_use]
pub(crate) fn state_hash(bodies: &BodySet, chains: &ChainSet) -> u64 {
    let mut h = Fnv::new();
    for handle in bodies.handles() {
        let (Some(sim), Some(st)) = (bodies.sim(handle), bodies.state(handle)) else {
            continue;
        };
        h.write_u32(handle.index);
        for x in [
            sim.transform.p.x,
            sim.transform.p.y,
            sim.transform.q.c,
            sim.transform.q.s,
            st.v.x,
            st.v.y,
            st.w,
        ] {
            h.write_real(x);
        }
    }
    for (index, chain) in chains.slots.iter() {
        h.write_u32(index);
        h.write_u32(chains.slots.generation(index));
        h.write_u32(u32::from(chain.is_loop));
        h.write_u32(chain.segments.len() as u32);
        for s in &chain.segments {
            h.write_u32(s.index);
        }
    }
    h.finish()
}

/// FNV-1a, 64 bit.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn write_bytes(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= *b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.write_bytes(&v.to_le_bytes());
    }
    fn write_real(&mut self, v: Real) {
        self.write_bytes(&v.to_bits().to_le_bytes());
    }
    fn finish(&self) -> u64 {
        self.0
    }
}
