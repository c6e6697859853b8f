//! The machine's own limit for the density sampler's table: random reads
//! of its record size (16 bytes) from a table of the same size, in the
//! batches of the sampler's streams (chunks of 16,384 on the current rayon
//! pool), measured two ways:
//!
//! - **latency**: one read at a time, each address the last value read (a
//!   pointer chase along one random cycle through the whole table): what a
//!   draw costs when nothing overlaps;
//! - **batch**: the sampler's pattern, blocks of 64 addresses from the
//!   random stream (one `u64` each, scaled by a 128-bit product like the
//!   alias table's column), their loads issued in a loop of loads alone,
//!   so that as many misses are in flight as the core allows.
//!
//! A density sampler whose rate approaches the batch probe's is at the
//! memory limit: its draws cost one read of the table each.

use std::hint::black_box;
use std::time::Instant;

use mesh_sampling::rand::{Rng, SeedableRng};
use mesh_sampling::rand_pcg::Pcg64Mcg;
use rayon::prelude::*;

const CHUNK: usize = 1 << 14;
const BLOCK: usize = 64;

/// Million reads per second, latency-bound and batched.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Probe {
    pub(crate) latency: f64,
    pub(crate) batch: f64,
}

/// A table of `records` 16-byte records: the first word of each is the
/// index of its successor on one random cycle through all of them (the
/// records in shuffled order, the last linked to the first), the second
/// random bits. A chase along the cycle
/// visits every record; a chase through a random function instead would
/// fall, after about √n steps, into a cycle of about √n records, which
/// the cache then holds.
pub(crate) fn table(records: usize) -> Vec<[u64; 2]> {
    let n = records.max(1);
    let mut rng = Pcg64Mcg::seed_from_u64(n as u64);
    let mut order: Vec<u64> = (0..n as u64).collect();
    for i in (1..n).rev() {
        let j = index(rng.next_u64(), i + 1);
        order.swap(i, j);
    }
    let mut t = vec![[0u64; 2]; n];
    for k in 0..n {
        t[order[k] as usize] = [order[(k + 1) % n], rng.next_u64()];
    }
    t
}

fn index(bits: u64, n: usize) -> usize {
    ((u128::from(bits) * n as u128) >> 64) as usize
}

/// `reads` dependent reads, in chunks on the pool's threads (seconds).
fn chase(table: &[[u64; 2]], reads: usize) -> f64 {
    let n = table.len();
    let start = Instant::now();
    (0..reads.div_ceil(CHUNK)).into_par_iter().for_each(|k| {
        let mut rng = Pcg64Mcg::seed_from_u64(k as u64);
        let mut at = index(rng.next_u64(), n);
        for _ in 0..CHUNK {
            // The next address is the value just read.
            at = table[at][0] as usize;
        }
        black_box(at);
    });
    start.elapsed().as_secs_f64()
}

/// `reads` independent reads in the sampler's blocks (seconds).
fn batch(table: &[[u64; 2]], reads: usize) -> f64 {
    let n = table.len();
    let start = Instant::now();
    (0..reads.div_ceil(CHUNK)).into_par_iter().for_each(|k| {
        let mut rng = Pcg64Mcg::seed_from_u64(k as u64);
        let mut at = [0usize; BLOCK];
        let mut got = [[0u64; 2]; BLOCK];
        let mut sum = 0u64;
        for _ in 0..CHUNK / BLOCK {
            for a in &mut at {
                *a = index(rng.next_u64(), n);
            }
            for (g, &a) in got.iter_mut().zip(&at) {
                *g = table[a];
            }
            sum = got.iter().fold(sum, |s, g| s ^ g[0] ^ g[1]);
        }
        black_box(sum);
    });
    start.elapsed().as_secs_f64()
}

/// Both probes on a table of `records` records, `reads` reads each, the
/// median of `runs` runs, on the current rayon pool.
pub(crate) fn probe(records: usize, reads: usize, runs: usize) -> Probe {
    let t = table(records);
    let median = |f: &dyn Fn() -> f64| {
        let mut times: Vec<f64> = (0..runs.max(1)).map(|_| f()).collect();
        times.sort_by(f64::total_cmp);
        let reads = reads.div_ceil(CHUNK) * CHUNK;
        reads as f64 / times[times.len() / 2] / 1e6
    };
    Probe {
        latency: median(&|| chase(&t, reads)),
        batch: median(&|| batch(&t, reads)),
    }
}
