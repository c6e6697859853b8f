//! Test systems shared by the integration tests.

#![allow(dead_code, reason = "each test file uses a subset")]

use multires::grid;
use sprs::{CsMat, TriMat};

/// SplitMix64, the workspace's one copy (test-support).
#[allow(unused_imports, reason = "each test binary uses a subset")]
pub(crate) use test_support::SplitMix64 as Rng;

/// A random geometric graph in the unit cube (points joined within
/// `radius`: it has triangles, like a tetrahedral mesh), as the weighted
/// graph Laplacian (weights 1/distance) plus `mass` on the diagonal;
/// with the points.
pub(crate) fn random_geometric(
    n: usize,
    radius: f64,
    mass: f64,
    seed: u64,
) -> (CsMat<f64>, Vec<[f64; 3]>) {
    let mut rng = Rng(seed);
    let points: Vec<[f64; 3]> = (0..n).map(|_| [rng.f64(), rng.f64(), rng.f64()]).collect();
    let mut t = TriMat::new((n, n));
    let mut diag = vec![mass; n];
    for i in 0..n {
        for j in i + 1..n {
            let d = dist(points[i], points[j]);
            if d < radius {
                let w = 1.0 / d;
                t.add_triplet(i, j, -w);
                t.add_triplet(j, i, -w);
                diag[i] += w;
                diag[j] += w;
            }
        }
    }
    for (i, d) in diag.into_iter().enumerate() {
        t.add_triplet(i, i, d);
    }
    (t.to_csr(), points)
}

pub(crate) fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// The diffusion grid of the benchmark, smaller.
pub(crate) fn grid_problem(side: usize) -> grid::Problem {
    grid::diffusion([side, side + 1, side + 2], 6.0).unwrap()
}

/// `‖b − A x‖ / ‖b‖`, computed serially from scratch.
pub(crate) fn relative_residual(a: &CsMat<f64>, b: &[f64], x: &[f64]) -> f64 {
    let mut r2 = 0.0;
    for (i, row) in a.outer_iterator().enumerate() {
        let ax: f64 = row.iter().map(|(j, v)| v * x[j]).sum();
        r2 += (b[i] - ax).powi(2);
    }
    let b2: f64 = b.iter().map(|v| v * v).sum();
    (r2 / b2).sqrt()
}

/// `A x`, serially.
pub(crate) fn apply(a: &CsMat<f64>, x: &[f64]) -> Vec<f64> {
    a.outer_iterator()
        .map(|row| row.iter().map(|(j, v)| v * x[j]).sum())
        .collect()
}

/// Largest entry-wise difference of two matrices with the same shape,
/// relative to the largest entry of `b`.
pub(crate) fn max_difference(a: &CsMat<f64>, b: &CsMat<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    let (da, db) = (a.to_dense(), b.to_dense());
    let scale = db.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    da.iter()
        .zip(db.iter())
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

pub(crate) fn one_thread<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(f)
}

pub(crate) fn two_threads<T: Send>(f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(f)
}
