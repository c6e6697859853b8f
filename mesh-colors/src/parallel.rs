//! Per-primitive work on all threads (with the `rayon` feature) when there
//! is enough of it, in an order that does not depend on the thread count.

/// Below this many samples of work the items stay on the calling thread:
/// waking the other threads costs more than a dab's few hundred samples
/// (measured on `paint_bench`'s dab rate: a count of items alone sent
/// every level of a dab's MIP refresh to the pool, 20 % slower).
#[cfg(feature = "rayon")]
const MIN_PARALLEL_SAMPLES: usize = 16_384;

/// `f` of each item, in the items' order. With the `rayon` feature and
/// `samples` (about how many samples the items compute in all) at least
/// `MIN_PARALLEL_SAMPLES`, the items are shared among the threads; each
/// result depends on its item only, so the results are the same at any
/// thread count.
pub(crate) fn map_ordered<I: Sync, T: Send>(
    items: &[I],
    samples: usize,
    f: impl Fn(&I) -> T + Sync + Send,
) -> Vec<T> {
    #[cfg(feature = "rayon")]
    if samples >= MIN_PARALLEL_SAMPLES && items.len() > 1 {
        use rayon::prelude::*;
        return items.par_iter().map(f).collect();
    }
    #[cfg(not(feature = "rayon"))]
    let _ = samples;
    items.iter().map(f).collect()
}

/// `a` and `b` at once (on two threads with the `rayon` feature): for two
/// large memory moves that touch different arrays.
pub(crate) fn join(a: impl FnOnce() + Send, b: impl FnOnce() + Send) {
    #[cfg(feature = "rayon")]
    {
        rayon::join(a, b);
    }
    #[cfg(not(feature = "rayon"))]
    {
        a();
        b();
    }
}
