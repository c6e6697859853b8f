//! Integration tests of `discrete-sampling`: one binary, one module a topic.

#[path = "../support/hdr.rs"]
mod hdr;
#[path = "../support/shapes.rs"]
mod shapes;
use test_support::stats;

mod environment;
mod errors;
mod exactness;
mod goodness_of_fit;
mod no_panic;
mod precision;
mod real_data;
mod regressions;
mod stability;
mod two_d;

use discrete_sampling::{AliasTable, CdfBisection, DiscreteSampler, GuideTable};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

/// A sampler seen through its `sample_remapped`.
type VariateSampler = Box<dyn Fn(f64) -> (usize, f64)>;

/// Every 1D sampler configuration under test, by name.
pub(crate) fn all_samplers(weights: &[f64]) -> Vec<(String, VariateSampler)> {
    let mut out: Vec<(String, VariateSampler)> = Vec::new();
    let b = CdfBisection::new(weights).unwrap();
    out.push(("bisection".into(), Box::new(move |u| b.sample_remapped(u))));
    for ratio in [0.25, 1.0, 4.0, 16.0] {
        let g = GuideTable::with_ratio(weights, ratio).unwrap();
        out.push((
            format!("guide-table×{ratio}"),
            Box::new(move |u| g.sample_remapped(u)),
        ));
    }
    let a = AliasTable::new(weights).unwrap();
    out.push(("alias".into(), Box::new(move |u| a.sample_remapped(u))));
    out
}

/// Counts of `samples` draws of `sampler` through its `rand` interface.
pub(crate) fn counts<S: DiscreteSampler>(sampler: &S, samples: usize, seed: u64) -> Vec<u64> {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut counts = vec![0u64; sampler.len()];
    let mut batch = vec![0usize; 4096];
    let mut left = samples;
    while left > 0 {
        let take = left.min(batch.len());
        sampler.sample_into(&mut rng, &mut batch[..take]);
        for &i in &batch[..take] {
            counts[i] += 1;
        }
        left -= take;
    }
    counts
}
