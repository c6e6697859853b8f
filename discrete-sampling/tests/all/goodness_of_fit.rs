//! Chi-square goodness of fit of every sampler against the exact
//! probabilities, and a wrong sampler the same test rejects.

use discrete_sampling::{AliasTable, CdfBisection, DiscreteSampler, Error, GuideTable};

use crate::stats::{chi_square, probabilities};
use crate::{counts, shapes};

const SAMPLES: usize = 1_000_000;
const ALPHA: f64 = 1e-3;

fn check<S: DiscreteSampler>(name: &str, shape: &str, sampler: &S, weights: &[f64], seed: u64) {
    let observed = counts(sampler, SAMPLES, seed);
    let exact = probabilities(weights);
    let test = chi_square(&observed, &exact, 20.0);
    assert!(
        test.p_value > ALPHA,
        "{name} on {shape}: chi² = {:.1} with {} dof, p = {:.2e}",
        test.statistic,
        test.dof,
        test.p_value
    );
    for (i, &w) in weights.iter().enumerate() {
        assert!(
            w > 0.0 || observed[i] == 0,
            "{name} on {shape} drew zero-weight {i}"
        );
    }
}

#[test]
fn every_sampler_fits_every_shape() {
    for (s, (shape, weights)) in shapes::named().iter().enumerate() {
        let seed = 1000 + s as u64;
        check(
            "bisection",
            shape,
            &CdfBisection::new(weights).unwrap(),
            weights,
            seed,
        );
        for ratio in [0.25, 1.0, 4.0, 16.0] {
            let g = GuideTable::with_ratio(weights, ratio).unwrap();
            check(&format!("guide-table×{ratio}"), shape, &g, weights, seed);
        }
        check(
            "alias",
            shape,
            &AliasTable::new(weights).unwrap(),
            weights,
            seed,
        );
    }
}

/// The classic off-by-one: searching `cdf[i] > u` instead of
/// `cdf[i + 1] > u` returns the entry after the right one.
struct OffByOne(CdfBisection);

impl DiscreteSampler for OffByOne {
    fn from_weights<W: Copy + Into<f64>>(weights: &[W]) -> Result<Self, Error> {
        CdfBisection::new(weights).map(Self)
    }
    fn len(&self) -> usize {
        self.0.len()
    }
    fn pdf(&self, index: usize) -> f64 {
        self.0.pdf(index)
    }
    fn memory_bytes(&self) -> usize {
        self.0.memory_bytes()
    }
    fn sample_remapped(&self, u: f64) -> (usize, f64) {
        let i = self
            .0
            .cdf()
            .partition_point(|&c| c <= u)
            .min(self.len() - 1);
        (i, 0.5)
    }
}

#[test]
fn the_same_test_rejects_an_off_by_one_sampler() {
    for (shape, weights) in shapes::named() {
        if matches!(shape, "single-nonzero" | "two-point-1e9") {
            continue; // the bug cannot show on one outcome
        }
        let wrong = OffByOne::from_weights(&weights).unwrap();
        let observed = counts(&wrong, SAMPLES, 7);
        let test = chi_square(&observed, &probabilities(&weights), 20.0);
        assert!(
            test.p_value < 1e-9,
            "off-by-one sampler passed on {shape}: p = {:.2e}",
            test.p_value
        );
    }
}

#[test]
fn single_nonzero_and_two_point_extremes() {
    let mut single = vec![0.0; 1000];
    single[613] = 2.5;
    for (name, f) in crate::all_samplers(&single) {
        for j in 0..=1000 {
            let u = j as f64 / 1000.0;
            assert_eq!(f(u).0, 613, "{name} at u = {u}");
        }
    }
    // 1 : 1e9 — the dim entry owns an interval of width 1e-9 / (1 + 1e-9).
    let two = [1.0, 1e-9];
    let g = GuideTable::new(&two).unwrap();
    let b = CdfBisection::new(&two).unwrap();
    let a = AliasTable::new(&two).unwrap();
    let p_dim = 1e-9 / (1.0 + 1e-9);
    assert!((g.pdf(1) - p_dim).abs() < 1e-15);
    assert!((b.pdf(1) - p_dim).abs() < 1e-15);
    assert!((a.realized_probabilities()[1] - p_dim).abs() < 1e-15);
    assert_eq!(g.sample_u(1.0 - p_dim / 2.0), 1);
    assert_eq!(g.sample_u(1.0 - 2.0 * p_dim), 0);
    // In the alias table the dim entry's mass sits at the start of column 1.
    assert_eq!(a.sample_u(0.5 + p_dim / 2.0), 1);
    assert_eq!(a.sample_u(0.5 + 3.0 * p_dim), 0);
}

#[test]
fn remapped_variates_are_uniform() {
    let weights = shapes::lognormal(1000, 3.0, 2);
    let mut rng_u = 0x9E37_79B9_7F4A_7C15u64;
    for (name, f) in crate::all_samplers(&weights) {
        let mut bins = vec![0u64; 32];
        for _ in 0..200_000 {
            // splitmix64 as an independent variate source
            rng_u = rng_u.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = rng_u;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            let u = (z >> 11) as f64 / (1u64 << 53) as f64;
            let (_, rest) = f(u);
            assert!((0.0..1.0).contains(&rest), "{name}: remainder {rest}");
            bins[(rest * 32.0) as usize] += 1;
        }
        let test = chi_square(&bins, &[1.0 / 32.0; 32], 20.0);
        assert!(
            test.p_value > ALPHA,
            "{name}: remainders not uniform, p = {:.2e}",
            test.p_value
        );
    }
}
