//! Shared helpers of the workspace's cross-crate and end-to-end tests:
//! the data folder, statistics. (The end-to-end tests of the `trilux`
//! binary are in `cli/tests/`, where cargo builds the binary for them.)

// The one data-folder lookup of the workspace's tests.
pub use test_support::data::{MESHES, data, data_dir};

/// Upper quantile of the chi-square distribution with `dof` degrees of
/// freedom at `z` standard normal deviations (Wilson–Hilferty).
pub fn chi_square_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}
