//! Prefetch hints: asking the processor to start loading memory that will be read soon, so that
//! a traversal or paths side by side wait for several cache misses at once instead of one after
//! another (Intel's and AMD's optimisation manuals, "software prefetching"). Hints only: they
//! never fault and never change a result.

/// Asks for the cache line holding the start of `x`.
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    prefetch_line((x as *const T).cast());
}

/// Asks for every cache line of `x`, from its start in steps of 64 bytes.
#[inline(always)]
pub(crate) fn prefetch_all<T>(x: &T) {
    let p: *const u8 = (x as *const T).cast();
    for offset in (0..std::mem::size_of::<T>()).step_by(64) {
        prefetch_line(p.wrapping_add(offset));
    }
}

#[inline(always)]
#[allow(unsafe_code)]
fn prefetch_line(p: *const u8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching never faults, whatever the address; SSE is part of x86-64.
    unsafe {
        std::arch::x86_64::_mm_prefetch(p.cast(), std::arch::x86_64::_MM_HINT_T0);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
