//! Per-primitive work on all threads (with the `rayon` feature) when there
//! is enough of it, in an order that does not depend on the thread count.

/// Below this many items the work stays on the calling thread: a dab or a
/// few faces cost less than handing them to other threads.
#[cfg(feature = "rayon")]
const MIN_PARALLEL_ITEMS: usize = 16;

/// `f` of each item, in the items' order. With the `rayon` feature and at
/// least `MIN_PARALLEL_ITEMS` items, the items are shared among the
/// threads; each result depends on its item only, so the results are the
/// same at any thread count.
pub(crate) fn map_ordered<I: Sync, T: Send>(
    items: &[I],
    f: impl Fn(&I) -> T + Sync + Send,
) -> Vec<T> {
    #[cfg(feature = "rayon")]
    if items.len() >= MIN_PARALLEL_ITEMS {
        use rayon::prelude::*;
        return items.par_iter().with_min_len(4).map(f).collect();
    }
    items.iter().map(f).collect()
}
