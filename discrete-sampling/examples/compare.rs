//! Sampling speed and build cost of every 1D sampler against rand's
//! `WeightedIndex` and rand_distr's `WeightedAliasIndex`, the paper's Fig. 7
//! (table ratios) and Fig. 8 (environment maps in 1D and 2D, with and
//! without the table).
//!
//! ```text
//! cargo run --release -p discrete-sampling --example compare -- [--json] [--n N] [--shape S]
//! ```
//!
//! Shapes: `uniform` (uniform random weights), `lognormal3` (σ = 3) and, when
//! `TRILUX_DATA` is set, `hdr:<file name>` for each map in `$TRILUX_DATA/hdr`
//! (its luminance; `--shape hdr` selects all of them). All samplers draw from
//! the same `Pcg64Mcg` stream; rounds alternate between samplers and the
//! median of the rounds is reported, since the machines are shared and noisy.

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use discrete_sampling::{
    AliasTable, CdfBisection, DEFAULT_RATIO, DiscreteSampler, Distribution2D, GuideTable,
};
use rand::distr::Distribution;
use rand::distr::weighted::WeightedIndex;
use rand::{Rng, SeedableRng};
use rand_distr::weighted::WeightedAliasIndex;
use rand_pcg::Pcg64Mcg;

#[path = "../tests/support/hdr.rs"]
mod hdr;
#[path = "../tests/support/shapes.rs"]
#[allow(dead_code, reason = "shared with the tests, which use more shapes")]
mod shapes;

const SIZES: [usize; 4] = [1_000, 100_000, 1_000_000, 10_000_000];
const RATIOS: [f64; 4] = [0.25, 1.0, 4.0, 16.0];
/// Timed rounds per sampler (the median is reported).
const ROUNDS: usize = 7;
/// Builds timed per sampler.
const BUILDS: usize = 3;

/// A sampler as the benchmark sees it.
enum Built {
    RandWeighted(WeightedIndex<f64>),
    RandAlias(WeightedAliasIndex<f64>),
    Bisection(CdfBisection),
    Guide(GuideTable),
    Alias(AliasTable),
    Rng,
}

/// One configuration to measure.
struct Entry {
    sampler: &'static str,
    ratio: Option<f64>,
    built: Built,
    build_ms: f64,
    /// Per round: ns/sample through the fastest API (our `sample_into`;
    /// rand's samplers have only one sample at a time).
    ns: Vec<f64>,
    /// Per round: ns/sample one at a time through `Distribution::sample`.
    ns_single: Vec<f64>,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Draws `samples` indices and folds them so nothing is optimised away.
fn draw<D: Distribution<usize>>(d: &D, rng: &mut Pcg64Mcg, samples: usize) -> usize {
    let mut acc = 0usize;
    for _ in 0..samples {
        acc = acc.wrapping_add(d.sample(rng));
    }
    acc
}

/// Draws `samples` 2D points through `sample_into` and folds their cells.
fn draw_2d<S: DiscreteSampler>(d: &Distribution2D<S>, rng: &mut Pcg64Mcg, samples: usize) -> usize {
    let mut buf = vec![discrete_sampling::Sample2D::default(); 4096];
    let mut acc = 0usize;
    let mut left = samples;
    while left > 0 {
        let take = left.min(buf.len());
        d.sample_into(rng, &mut buf[..take]);
        acc = buf[..take]
            .iter()
            .fold(acc, |a, s| a.wrapping_add(s.cell[0] ^ s.cell[1]));
        left -= take;
    }
    acc
}

/// Draws `samples` indices through `sample_into` in blocks of 4096.
fn draw_batch<S: DiscreteSampler>(d: &S, rng: &mut Pcg64Mcg, samples: usize) -> usize {
    let mut buf = vec![0usize; 4096];
    let mut acc = 0usize;
    let mut left = samples;
    while left > 0 {
        let take = left.min(buf.len());
        d.sample_into(rng, &mut buf[..take]);
        acc = buf[..take].iter().fold(acc, |a, &i| a.wrapping_add(i));
        left -= take;
    }
    acc
}

impl Built {
    /// Whether the sampler has a batch API distinct from one at a time.
    fn has_batch(&self) -> bool {
        !matches!(self, Built::RandWeighted(_) | Built::RandAlias(_))
    }

    /// Through the batch API where there is one.
    fn run_batch(&self, rng: &mut Pcg64Mcg, samples: usize) -> usize {
        match self {
            Built::Bisection(d) => draw_batch(d, rng, samples),
            Built::Guide(d) => draw_batch(d, rng, samples),
            Built::Alias(d) => draw_batch(d, rng, samples),
            Built::Rng => {
                let mut buf = vec![0u64; 4096];
                let mut acc = 0u64;
                let mut left = samples;
                while left > 0 {
                    let take = left.min(buf.len());
                    buf[..take].iter_mut().for_each(|b| *b = rng.next_u64());
                    acc = buf[..take].iter().fold(acc, |a, &b| a.wrapping_add(b));
                    left -= take;
                }
                acc as usize
            }
            _ => self.run(rng, samples),
        }
    }

    /// One sample at a time.
    fn run(&self, rng: &mut Pcg64Mcg, samples: usize) -> usize {
        match self {
            Built::RandWeighted(d) => draw(d, rng, samples),
            Built::RandAlias(d) => draw(d, rng, samples),
            Built::Bisection(d) => draw(d, rng, samples),
            Built::Guide(d) => draw(d, rng, samples),
            Built::Alias(d) => draw(d, rng, samples),
            Built::Rng => {
                let mut acc = 0usize;
                for _ in 0..samples {
                    acc = acc.wrapping_add(rng.next_u64() as usize);
                }
                acc
            }
        }
    }
}

/// Builds `BUILDS` times and keeps the last, with the median build time.
fn timed_build(mut make: impl FnMut() -> Built) -> (Built, f64) {
    let mut times = Vec::new();
    let mut built = None;
    for _ in 0..BUILDS {
        drop(built.take());
        let t = Instant::now();
        let b = black_box(make());
        times.push(t.elapsed().as_secs_f64() * 1e3);
        built = Some(b);
    }
    (built.expect("BUILDS > 0"), median(times))
}

fn build_all(weights: &[f64]) -> Vec<Entry> {
    let mut entries = Vec::new();
    let mut push = |sampler, ratio, (built, build_ms)| {
        entries.push(Entry {
            sampler,
            ratio,
            built,
            build_ms,
            ns: Vec::new(),
            ns_single: Vec::new(),
        })
    };
    push(
        "rand-weighted-index",
        None,
        timed_build(|| Built::RandWeighted(WeightedIndex::new(weights).expect("valid"))),
    );
    push(
        "rand-distr-alias",
        None,
        timed_build(|| Built::RandAlias(WeightedAliasIndex::new(weights.to_vec()).expect("valid"))),
    );
    push(
        "bisection",
        None,
        timed_build(|| Built::Bisection(CdfBisection::new(weights).expect("valid"))),
    );
    for ratio in RATIOS {
        push(
            "guide-table",
            Some(ratio),
            timed_build(|| Built::Guide(GuideTable::with_ratio(weights, ratio).expect("valid"))),
        );
    }
    push(
        "guide-table-default",
        Some(DEFAULT_RATIO),
        timed_build(|| Built::Guide(GuideTable::new(weights).expect("valid"))),
    );
    push(
        "alias",
        None,
        timed_build(|| Built::Alias(AliasTable::new(weights).expect("valid"))),
    );
    push("rng", None, (Built::Rng, 0.0));
    entries
}

/// Samples per round: enough to leave the caches' warm-up behind.
fn samples_per_round(n: usize) -> usize {
    if n >= 1_000_000 { 1 << 21 } else { 1 << 22 }
}

fn measure(entries: &mut [Entry], n: usize) {
    let samples = samples_per_round(n);
    for e in entries.iter() {
        // Warm-up: page in the tables.
        black_box(e.built.run(&mut Pcg64Mcg::seed_from_u64(0), samples / 8));
    }
    for round in 0..ROUNDS {
        for e in entries.iter_mut() {
            let seed = round as u64 + 1;
            let t = Instant::now();
            black_box(e.built.run(&mut Pcg64Mcg::seed_from_u64(seed), samples));
            let single = t.elapsed().as_secs_f64() * 1e9 / samples as f64;
            e.ns_single.push(single);
            if e.built.has_batch() {
                let t = Instant::now();
                black_box(
                    e.built
                        .run_batch(&mut Pcg64Mcg::seed_from_u64(seed), samples),
                );
                e.ns.push(t.elapsed().as_secs_f64() * 1e9 / samples as f64);
            } else {
                e.ns.push(single);
            }
        }
    }
}

/// One measured row.
struct Row {
    sampler: &'static str,
    shape: String,
    n: usize,
    ratio: Option<f64>,
    ns: f64,
    ns_single: f64,
    build_ms: f64,
    /// Whether `ns` is a batch API's time (else it repeats `ns_single`).
    has_batch: bool,
}

fn rows_for(shape: &str, weights: &[f64]) -> Vec<Row> {
    let mut entries = build_all(weights);
    measure(&mut entries, weights.len());
    entries
        .into_iter()
        .map(|e| Row {
            sampler: e.sampler,
            shape: shape.to_string(),
            n: weights.len(),
            ratio: e.ratio,
            ns: median(e.ns),
            ns_single: median(e.ns_single),
            build_ms: e.build_ms,
            has_batch: e.built.has_batch(),
        })
        .collect()
}

fn print_json(row: &Row) {
    let ratio = row.ratio.map_or("null".to_string(), |r| r.to_string());
    println!(
        "{{\"sampler\":\"{}\",\"shape\":\"{}\",\"n\":{},\"table_ratio\":{},\"ns_per_sample\":{:.3},\"ns_per_sample_one_at_a_time\":{:.3},\"build_ms\":{:.3}}}",
        row.sampler,
        row.shape.replace('\\', "\\\\").replace('"', "\\\""),
        row.n,
        ratio,
        row.ns,
        row.ns_single,
        row.build_ms
    );
}

/// One row per sampler. Speed-ups compare like with like: one sample at a
/// time against rand's `WeightedIndex` one at a time (rand has no batch
/// API), and our batch API against the same sampler one at a time.
fn print_markdown(rows: &[Row]) {
    println!(
        "| shape | n | sampler | table ratio | one at a time ns | × RNG | vs WeightedIndex | batch ns | batch gain | build ms |"
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for row in rows {
        let same = |name: &str| {
            rows.iter()
                .find(|r| r.sampler == name && r.shape == row.shape && r.n == row.n)
                .map(|r| r.ns_single)
        };
        let rng = same("rng").unwrap_or(f64::NAN);
        let baseline = same("rand-weighted-index").unwrap_or(f64::NAN);
        let (batch, gain) = if row.has_batch {
            (
                format!("{:.2}", row.ns),
                format!("{:.2}×", row.ns_single / row.ns),
            )
        } else {
            ("—".to_string(), "—".to_string())
        };
        println!(
            "| {} | {} | {} | {} | {:.2} | {:.2} | {:.2}× | {} | {} | {:.2} |",
            row.shape,
            row.n,
            row.sampler,
            row.ratio.map_or("—".to_string(), |r| r.to_string()),
            row.ns_single,
            row.ns_single / rng,
            baseline / row.ns_single,
            batch,
            gain,
            row.build_ms
        );
    }
}

/// The headline comparisons of this run, one at a time against rand's
/// samplers one at a time.
fn print_summary(rows: &[Row]) {
    let find = |sampler: &str, shape: &str, n: usize| {
        rows.iter()
            .find(|r| r.sampler == sampler && r.shape == shape && r.n == n)
    };
    println!("\n### Summary (one sample at a time, this run)\n");
    for row in rows.iter().filter(|r| r.sampler == "guide-table-default") {
        if let Some(w) = find("rand-weighted-index", &row.shape, row.n) {
            println!(
                "- guide table vs rand's WeightedIndex, {} n = {}: {:.2}× faster per sample, same index for every variate as bisection",
                row.shape,
                row.n,
                w.ns_single / row.ns_single
            );
        }
    }
    for row in rows.iter().filter(|r| r.sampler == "alias") {
        if let Some(r) = find("rand-distr-alias", &row.shape, row.n) {
            println!(
                "- alias table vs rand_distr's WeightedAliasIndex, {} n = {}: {:.2}× per sample, build {:.2}× as fast",
                row.shape,
                row.n,
                r.ns_single / row.ns_single,
                r.build_ms / row.build_ms
            );
        }
    }
}

/// The paper's Fig. 8: an environment map sampled as one 1D distribution
/// over all texels or as marginal + conditionals, each with and without the
/// lookup table, all through the batch APIs. Weights include the sin θ of
/// lat-long maps. A 2D sample also places the point inside its texel (two
/// divisions for the remapped variates) and computes its density.
fn figure_8(lum: &hdr::Luminance) {
    let (w, h) = (lum.width, lum.height);
    let weights: Vec<f64> = lum
        .values
        .iter()
        .enumerate()
        .map(|(i, &l)| {
            let theta = std::f64::consts::PI * ((i / w) as f64 + 0.5) / h as f64;
            f64::from(l) * theta.sin()
        })
        .collect();
    let d1_bis = CdfBisection::new(&weights).expect("valid map");
    let d1_gt = GuideTable::new(&weights).expect("valid map");
    let d2_bis = Distribution2D::<CdfBisection>::with_sampler(&weights, w, h).expect("valid map");
    let d2_gt = Distribution2D::<GuideTable>::with_sampler(&weights, w, h).expect("valid map");
    let samples = 1 << 22;
    let mut times: [Vec<f64>; 4] = Default::default();
    let seconds = |run: &dyn Fn() -> usize| {
        let t = Instant::now();
        black_box(run());
        t.elapsed().as_secs_f64()
    };
    for round in 0..ROUNDS {
        let rng = || Pcg64Mcg::seed_from_u64(round as u64 + 1);
        times[0].push(seconds(&|| draw_batch(&d1_bis, &mut rng(), samples)));
        times[1].push(seconds(&|| draw_batch(&d1_gt, &mut rng(), samples)));
        times[2].push(seconds(&|| draw_2d(&d2_bis, &mut rng(), samples)));
        times[3].push(seconds(&|| draw_2d(&d2_gt, &mut rng(), samples)));
    }
    let ns: Vec<f64> = times
        .into_iter()
        .map(|t| median(t) * 1e9 / samples as f64)
        .collect();
    println!(
        "| {} | {}×{} | {:.2} | {:.2} | {:.2}× | {:.2} | {:.2} | {:.2}× |",
        lum.name,
        w,
        h,
        ns[0],
        ns[1],
        ns[0] / ns[1],
        ns[2],
        ns[3],
        ns[2] / ns[3]
    );
}

struct Options {
    json: bool,
    n: Option<usize>,
    shape: Option<String>,
}

const USAGE: &str = "usage: compare [--json] [--n N] [--shape uniform|lognormal3|hdr|hdr:<file>]";

fn parse_args() -> Result<Options, String> {
    let mut opts = Options {
        json: false,
        n: None,
        shape: None,
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--json" => opts.json = true,
            "--n" => {
                let v = args.next().ok_or("--n needs a value")?;
                let n: usize = v
                    .parse()
                    .map_err(|_| format!("--n {v}: not a whole number"))?;
                if n == 0 {
                    return Err("--n must be at least 1".into());
                }
                opts.n = Some(n);
            }
            "--shape" => opts.shape = Some(args.next().ok_or("--shape needs a value")?),
            "-h" | "--help" => {
                println!("{USAGE}");
                std::process::exit(0);
            }
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    Ok(opts)
}

fn main() -> ExitCode {
    let opts = match parse_args() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("compare: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let wants = |shape: &str| match &opts.shape {
        None => true,
        Some(s) if s == "hdr" => shape.starts_with("hdr:"),
        Some(s) => s == shape,
    };
    if let Some(s) = &opts.shape
        && !matches!(s.as_str(), "uniform" | "lognormal3" | "hdr")
        && !s.starts_with("hdr:")
    {
        eprintln!("compare: unknown shape {s:?}\n{USAGE}");
        return ExitCode::from(2);
    }
    let sizes: Vec<usize> = opts.n.map_or(SIZES.to_vec(), |n| vec![n]);

    let mut rows = Vec::new();
    let emit = |shape: &str, weights: &[f64], rows: &mut Vec<Row>| {
        let new = rows_for(shape, weights);
        if opts.json {
            new.iter().for_each(print_json);
        } else {
            eprintln!("measured {shape} n = {}", weights.len());
        }
        rows.extend(new);
    };
    for &n in &sizes {
        if wants("uniform") {
            emit("uniform", &shapes::uniform_random(n, 1), &mut rows);
        }
        if wants("lognormal3") {
            emit("lognormal3", &shapes::lognormal(n, 3.0, 2), &mut rows);
        }
    }

    let mut maps = Vec::new();
    let hdr_wanted = opts.shape.as_ref().is_none_or(|s| s.starts_with("hdr"));
    match hdr::hdr_files() {
        None if hdr_wanted => eprintln!("note: TRILUX_DATA is not set; HDR shapes skipped"),
        None => {}
        Some(files) => {
            for path in files {
                let lum = match hdr::load_luminance(&path) {
                    Ok(l) => l,
                    Err(e) => {
                        eprintln!("compare: {e}");
                        return ExitCode::FAILURE;
                    }
                };
                let shape = format!("hdr:{}", lum.name);
                if !wants(&shape) || opts.n.is_some_and(|n| n != lum.values.len()) {
                    continue;
                }
                let weights: Vec<f64> = lum.values.iter().map(|&v| f64::from(v)).collect();
                emit(&shape, &weights, &mut rows);
                maps.push(lum);
            }
        }
    }

    if !opts.json {
        println!(
            "## discrete-sampling: ns per sample (median of {ROUNDS} rounds) and build time\n"
        );
        print_markdown(&rows);
        print_summary(&rows);
        if !maps.is_empty() {
            println!(
                "\n### Fig. 8: environment maps, 1D vs 2D, with and without the table (ns/sample)\n"
            );
            println!(
                "| map | size | 1D bisection | 1D table | 1D speed-up | 2D bisection | 2D table | 2D speed-up |"
            );
            println!("|---|---|---:|---:|---:|---:|---:|---:|");
            maps.iter().for_each(figure_8);
        }
    }
    ExitCode::SUCCESS
}
