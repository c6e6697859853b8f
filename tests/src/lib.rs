//! Shared helpers of the workspace's cross-crate and end-to-end tests:
//! the data folder, statistics. (The end-to-end tests of the `trilux`
//! binary are in `cli/tests/`, where cargo builds the binary for them.)

use std::path::PathBuf;

/// The data folder named by `TRILUX_DATA`, or `None` (tests that need it
/// are `#[ignore]`d at build time when it is unset, see `build.rs`).
pub fn data_dir() -> Option<PathBuf> {
    std::env::var_os("TRILUX_DATA").map(PathBuf::from)
}

/// A file of the data folder (panics with a readable message when
/// `TRILUX_DATA` is unset: only real-data tests call it).
pub fn data(relative: &str) -> PathBuf {
    let dir = data_dir().expect("TRILUX_DATA names the data folder");
    // CI gives a path relative to the workspace root; tests run in the
    // package folder.
    let dir = if dir.is_relative() {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(dir)
    } else {
        dir
    };
    dir.join(relative)
}

/// Upper quantile of the chi-square distribution with `dof` degrees of
/// freedom at `z` standard normal deviations (Wilson–Hilferty).
pub fn chi_square_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}
