//! Cache hints for passes whose next element sits behind a pointer or an
//! index.
//!
//! The hardware prefetcher follows strides, not pointers: a pass over the
//! joints that reads their boxed definitions (prepare), or over the
//! contacts that reads their shapes' records by slot (narrowphase), takes
//! a dependent cache miss per element. [`prefetch`] asks for a later
//! element's line while the current one is worked on.
//!
//! | user | asks for | ahead |
//! |------|----------|-------|
//! | joint prepare | the boxed definition | 4 joints |
//! | narrowphase | both shape records ([`Slots::prefetch`](crate::slots::Slots::prefetch)), both bodies' sim and state ([`BodySet::prefetch_hinted`](crate::body::BodySet::prefetch_hinted)) | 4 contacts |
//! | joint colours' solve | the joint record | 2 joints |
//! | contact push | the colour's next kept chunk, whole ([`prefetch_all`]) | 1 chunk |
//! | impulse store | the next chunk's contact records | 1 chunk |
//!
//! This module and [`parallel`](crate::parallel) are the crate's only
//! users of `unsafe`.
#![allow(unsafe_code)]

/// Asks the cache for the line holding `value`, ahead of a read. A hint
/// only: it reads nothing and changes nothing, on any target (a no-op
/// where no prefetch instruction is wired).
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    prefetch_address((value as *const T).cast());
}

/// [`prefetch`] of every cache line `value` spans (64-byte lines): for a
/// record written piece by piece over the next while (a solver chunk of
/// over a kilobyte), so that its writes do not each wait for their line.
#[inline(always)]
pub fn prefetch_all<T>(value: &T) {
    let p: *const u8 = (value as *const T).cast();
    for offset in (0..std::mem::size_of::<T>()).step_by(64) {
        // (`wrapping_add`: within `value`, and never dereferenced.)
        prefetch_address(p.wrapping_add(offset));
    }
}

/// The one prefetch instruction behind [`prefetch`] and [`prefetch_all`].
#[inline(always)]
fn prefetch_address(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` is a hint that performs no memory access the
    // program can observe: it cannot fault (even on an invalid address;
    // the callers pass addresses inside a live reference) and reads
    // nothing into the program. Its one requirement, SSE, is part of the
    // x86_64 baseline every x86_64 target enables.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
