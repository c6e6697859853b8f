//! A software prefetch hint, the crate's one `unsafe` block: the batch
//! pipeline asks for the lines of later blocks while the current block
//! computes, so that its cache misses overlap the computation (a plain
//! load would hold the core's look-ahead until the line arrives; a
//! prefetch instruction retires at once).

/// Asks the core to bring the cache line of `slice[index]` into L1,
/// without waiting for it. Never reads the element: an index out of range
/// is harmless (the hint goes to a pointer that is never dereferenced). A
/// no-op off x86_64.
#[inline(always)]
pub(crate) fn prefetch<T>(slice: &[T], index: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let p = slice.as_ptr().wrapping_add(index).cast::<i8>();
        #[expect(
            unsafe_code,
            reason = "`_mm_prefetch` needs the sse target feature: the crate's one unsafe block"
        )]
        // SAFETY: `_mm_prefetch` is unsafe to call only because it is a
        // `#[target_feature(enable = "sse")]` function, and sse is part
        // of the x86_64 baseline, so it is available on every x86_64
        // target. The instruction is a hint: it never dereferences `p`
        // (which may be any address, here built with `wrapping_add`) and
        // cannot fault.
        unsafe {
            _mm_prefetch::<_MM_HINT_T0>(p);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (slice, index);
}

#[cfg(test)]
mod tests {
    use super::prefetch;

    #[test]
    fn prefetching_any_index_leaves_the_data_alone() {
        let data: Vec<u64> = (0..1000).collect();
        for i in [0, 1, 500, 999, 1000, 1 << 40, usize::MAX] {
            prefetch(&data, i);
        }
        prefetch::<u8>(&[], 3);
        assert!(data.iter().enumerate().all(|(i, &v)| v == i as u64));
    }
}
