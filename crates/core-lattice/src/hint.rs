//! A cache prefetch hint, for models that know which memory a later step reads (the animats'
//! next turns' cells, DLCA's next clusters' records): one of the workspace's two places of
//! `unsafe` code (the other is the orthtree's arena in `spatial`; `unsafe_code` is denied
//! everywhere else). Stable Rust has no
//! safe non-blocking prefetch: `_mm_prefetch` is a
//! `#[target_feature]` function and `std::hint::prefetch_read` is unstable.

/// Asks the CPU to start loading the cache line holding `r` into every cache level, without
/// waiting for it. A hint only: it never faults and changes no value any load returns.
#[inline(always)]
#[allow(unsafe_code)]
pub fn prefetch<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `_mm_prefetch` needs SSE, which every x86_64 CPU has (it is in the target's
    // baseline), and it does not dereference its pointer, which comes from a live reference.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>((r as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}
