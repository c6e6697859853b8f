//! Deterministic batches: fixed-size chunks, each with its own random
//! stream seeded from `(seed, chunk)`, so the output never depends on the
//! number of threads.

use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// The most points a call returns in one `Vec`: 2²⁷ = 134,217,728 (9.7 GB
/// of [`SurfacePoint`](crate::SurfacePoint), 1.6 GB of positions). Counts
/// from arguments are checked against it before anything is allocated, so
/// that a huge count is an [`Error::TooManyPoints`](crate::Error::TooManyPoints),
/// not an aborted process. [`SurfaceSampler::sample_stream`](crate::SurfaceSampler::sample_stream)
/// has no limit: it holds one chunk per thread at a time.
pub const MAX_POINTS: usize = 1 << 27;

/// `Ok` if `requested` points (a count or an upper bound of one, NaN
/// counting as too many) fit in [`MAX_POINTS`].
pub(crate) fn check_points(requested: f64) -> Result<(), crate::Error> {
    if requested <= MAX_POINTS as f64 {
        Ok(())
    } else {
        Err(crate::Error::TooManyPoints {
            requested,
            budget: MAX_POINTS,
        })
    }
}

/// Points per chunk (and per random stream).
pub(crate) const CHUNK: usize = 1 << 14;

/// Points computed together by the batch paths, so that the memory
/// accesses of independent samples overlap.
pub(crate) const BLOCK: usize = 64;

/// A uniform `f64` in `[0, 1)` from the top 53 bits of a `u64`.
#[inline]
pub(crate) fn unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// The random stream of chunk `k`: SplitMix64 of `(seed, k)` as the seed,
/// so neighbouring chunks get unrelated streams.
pub(crate) fn chunk_rng(seed: u64, k: usize) -> Pcg64Mcg {
    let mut z = seed ^ (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    Pcg64Mcg::seed_from_u64(z ^ (z >> 31))
}

/// Runs `fill(rng_k, chunk_k)` over `out` in chunks of [`CHUNK`], on all
/// threads with the `rayon` feature.
pub(crate) fn for_each_chunk<T: Send>(
    seed: u64,
    out: &mut [T],
    fill: impl Fn(&mut Pcg64Mcg, &mut [T]) + Sync,
) {
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each(|(k, chunk)| fill(&mut chunk_rng(seed, k), chunk));
    }
    #[cfg(not(feature = "rayon"))]
    for (k, chunk) in out.chunks_mut(CHUNK).enumerate() {
        fill(&mut chunk_rng(seed, k), chunk);
    }
}

/// Like [`for_each_chunk`] over `n` items, but each chunk is filled into a
/// reused buffer and handed to `consume(first_index, chunk)` instead of
/// being kept: the same values, without holding all `n` in memory.
pub(crate) fn stream<T: Default + Clone + Send>(
    seed: u64,
    n: usize,
    fill: impl Fn(&mut Pcg64Mcg, &mut [T]) + Sync,
    consume: impl Fn(usize, &[T]) + Sync,
) {
    let run = |buf: &mut Vec<T>, k: usize| {
        buf.resize(CHUNK.min(n - k * CHUNK), T::default());
        fill(&mut chunk_rng(seed, k), buf);
        consume(k * CHUNK, buf);
    };
    let chunks = n.div_ceil(CHUNK);
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        (0..chunks)
            .into_par_iter()
            .for_each_init(Vec::new, |buf, k| run(buf, k));
    }
    #[cfg(not(feature = "rayon"))]
    {
        let mut buf = Vec::new();
        for k in 0..chunks {
            run(&mut buf, k);
        }
    }
}

/// Like [`for_each_chunk`], but each chunk is first filled into a reused
/// buffer of `B` by `fill`, then converted into `out` by `store`: for
/// outputs smaller than what the samplers produce.
pub(crate) fn for_each_chunk_via<B: Default + Clone + Send, T: Send>(
    seed: u64,
    out: &mut [T],
    fill: impl Fn(&mut Pcg64Mcg, &mut [B]) + Sync,
    store: impl Fn(&B) -> T + Sync,
) {
    let run = |buf: &mut Vec<B>, (k, chunk): (usize, &mut [T])| {
        buf.resize(chunk.len(), B::default());
        fill(&mut chunk_rng(seed, k), buf);
        for (slot, b) in chunk.iter_mut().zip(buf.iter()) {
            *slot = store(b);
        }
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        out.par_chunks_mut(CHUNK)
            .enumerate()
            .for_each_init(Vec::new, run);
    }
    #[cfg(not(feature = "rayon"))]
    {
        let mut buf = Vec::new();
        for item in out.chunks_mut(CHUNK).enumerate() {
            run(&mut buf, item);
        }
    }
}

/// The points `triangle(f)` makes for every face `f`, in face order, on all
/// threads when `rayon` is on (the stable per-triangle modes).
pub(crate) fn per_face<T: Send>(
    faces: usize,
    triangle: impl Fn(usize) -> Vec<T> + Sync + Send,
) -> Vec<T> {
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        (0..faces).into_par_iter().flat_map_iter(triangle).collect()
    }
    #[cfg(not(feature = "rayon"))]
    {
        (0..faces).flat_map(triangle).collect()
    }
}
