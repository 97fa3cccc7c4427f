//! The state hash: equal hashes mean bit-identical body states.
//!
//! FNV-1a (64 bit) over every live body in handle order: the slot index,
//! then the bits of `x, y, cos θ, sin θ, v_x, v_y, ω`. Small, stable across
//! platforms and releases, and cheap enough to run every step in a test.

use janus2d_core::body::BodySet;
use janus2d_core::math::Real;

/// The hash of every body's transform and velocity bits, in handle order.
#[must_use]
pub fn state_hash(bodies: &BodySet) -> u64 {
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
