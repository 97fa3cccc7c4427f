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
//! | narrowphase | both shape records ([`Slots::prefetch`](crate::slots::Slots::prefetch)) | 4 contacts |
//!
//! This module and [`parallel`](crate::parallel) are the crate's only
//! users of `unsafe`.
#![allow(unsafe_code)]

/// Asks the cache for the line holding `value`, ahead of a read. A hint
/// only: it reads nothing and changes nothing, on any target (a no-op
/// where no prefetch instruction is wired).
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let p: *const i8 = (value as *const T).cast();
        // SAFETY: `_mm_prefetch` is a hint that performs no memory access
        // the program can observe: it cannot fault (even on an invalid
        // address; here `p` comes from a live reference) and reads nothing
        // into the program. Its one requirement, SSE, is part of the
        // x86_64 baseline every x86_64 target enables.
        unsafe {
            core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(p);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// [`prefetch`] of every cache line `value` spans (64-byte lines): for a
/// record written piece by piece over the next while (a solver chunk of
/// over a kilobyte), so that its writes do not each wait for their line.
#[inline(always)]
pub fn prefetch_all<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        let p: *const i8 = (value as *const T).cast();
        for offset in (0..std::mem::size_of::<T>()).step_by(64) {
            // SAFETY: as in `prefetch`: a hint that cannot fault and reads
            // nothing into the program; `offset` is within `value`'s own
            // bytes, so the address is inside a live object.
            unsafe {
                core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(
                    p.wrapping_add(offset),
                );
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
