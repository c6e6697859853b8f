//! The weight shapes every sampler is tested on, made from fixed seeds.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// A standard normal variate by Box–Muller (own code, so the shapes never
/// change with a dependency's version).
fn normal(rng: &mut Pcg64Mcg) -> f64 {
    let u1 = ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
    let u2 = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Uniform random weights in `[0, 1)`.
pub(crate) fn uniform_random(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
        .collect()
}

/// Log-normal weights `exp(σ z)`.
pub(crate) fn lognormal(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n).map(|_| (sigma * normal(&mut rng)).exp()).collect()
}

/// Weights spanning `10^-decades .. 1` log-uniformly.
pub(crate) fn log_uniform(n: usize, decades: f64, seed: u64) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    (0..n)
        .map(|_| 10f64.powf(-decades * (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64))
        .collect()
}

/// The named shapes of the goodness-of-fit tests, 1,000 entries each except
/// the two-point one.
pub(crate) fn named() -> Vec<(&'static str, Vec<f64>)> {
    let mut mostly_zero = vec![0.0; 1000];
    for (i, w) in uniform_random(1000, 3).into_iter().enumerate() {
        if i % 50 == 7 {
            mostly_zero[i] = 0.1 + w;
        }
    }
    let mut single = vec![0.0; 1000];
    single[613] = 2.5;
    vec![
        ("uniform", vec![1.0; 1000]),
        ("uniform-random", uniform_random(1000, 1)),
        ("lognormal3", lognormal(1000, 3.0, 2)),
        ("mostly-zero", mostly_zero),
        ("single-nonzero", single),
        ("two-point-1e9", vec![1.0, 1e-9]),
    ]
}
