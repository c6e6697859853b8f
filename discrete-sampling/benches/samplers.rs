//! Criterion benchmarks: per-sample cost of every sampler against rand's
//! `WeightedIndex` and rand_distr's `WeightedAliasIndex`, and build cost.
//! `cargo bench -p discrete-sampling`. For the full table of the issue (all
//! sizes, shapes and table ratios, Markdown or JSON) run the `compare`
//! example instead.

use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use discrete_sampling::{AliasTable, CdfBisection, DiscreteSampler, GuideTable};
use rand::distr::Distribution;
use rand::distr::weighted::WeightedIndex;
use rand::{Rng, SeedableRng};
use rand_distr::weighted::WeightedAliasIndex;
use rand_pcg::Pcg64Mcg;

const BATCH: usize = 4096;

fn lognormal(n: usize) -> Vec<f64> {
    let mut rng = Pcg64Mcg::seed_from_u64(2);
    (0..n)
        .map(|_| {
            let u1 = ((rng.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64;
            let u2 = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
            let z = (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
            (3.0 * z).exp()
        })
        .collect()
}

fn one_at_a_time<D: Distribution<usize>>(d: &D, rng: &mut Pcg64Mcg) -> usize {
    (0..BATCH).fold(0usize, |acc, _| acc.wrapping_add(d.sample(rng)))
}

fn sampling(c: &mut Criterion) {
    let mut group = c.benchmark_group("sample lognormal σ=3");
    group.throughput(Throughput::Elements(BATCH as u64));
    for n in [1_000usize, 100_000, 1_000_000] {
        let w = lognormal(n);
        let weighted = WeightedIndex::new(&w).unwrap();
        let rand_alias = WeightedAliasIndex::new(w.clone()).unwrap();
        let bisection = CdfBisection::new(&w).unwrap();
        let guide = GuideTable::new(&w).unwrap();
        let alias = AliasTable::new(&w).unwrap();
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        let mut out = vec![0usize; BATCH];
        group.bench_function(BenchmarkId::new("rand WeightedIndex", n), |b| {
            b.iter(|| one_at_a_time(&weighted, &mut rng))
        });
        group.bench_function(BenchmarkId::new("rand_distr WeightedAliasIndex", n), |b| {
            b.iter(|| one_at_a_time(&rand_alias, &mut rng))
        });
        group.bench_function(BenchmarkId::new("bisection", n), |b| {
            b.iter(|| {
                bisection.sample_into(&mut rng, &mut out);
                black_box(out[0])
            })
        });
        group.bench_function(BenchmarkId::new("guide table", n), |b| {
            b.iter(|| {
                guide.sample_into(&mut rng, &mut out);
                black_box(out[0])
            })
        });
        group.bench_function(BenchmarkId::new("guide table, one at a time", n), |b| {
            b.iter(|| one_at_a_time(&guide, &mut rng))
        });
        group.bench_function(BenchmarkId::new("alias", n), |b| {
            b.iter(|| {
                alias.sample_into(&mut rng, &mut out);
                black_box(out[0])
            })
        });
        group.bench_function(BenchmarkId::new("rng alone", n), |b| {
            b.iter(|| (0..BATCH).fold(0u64, |acc, _| acc.wrapping_add(rng.next_u64())))
        });
    }
    group.finish();
}

fn building(c: &mut Criterion) {
    let mut group = c.benchmark_group("build lognormal σ=3");
    for n in [100_000usize, 1_000_000] {
        let w = lognormal(n);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::new("rand WeightedIndex", n), |b| {
            b.iter(|| WeightedIndex::new(&w).unwrap())
        });
        group.bench_function(BenchmarkId::new("rand_distr WeightedAliasIndex", n), |b| {
            b.iter(|| WeightedAliasIndex::new(w.clone()).unwrap())
        });
        group.bench_function(BenchmarkId::new("guide table", n), |b| {
            b.iter(|| GuideTable::new(&w).unwrap())
        });
        group.bench_function(BenchmarkId::new("alias", n), |b| {
            b.iter(|| AliasTable::new(&w).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, sampling, building);
criterion_main!(benches);
