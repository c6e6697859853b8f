//! Shared helpers of the workspace's cross-crate and end-to-end tests:
//! the data folder, the `trilux` binary, statistics.

use std::path::PathBuf;
use std::sync::OnceLock;

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

/// The `trilux` binary, built (once per test process) with the profile of
/// the tests, so that the tests never run a stale binary.
pub fn trilux_bin() -> PathBuf {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| {
        let exe = std::env::current_exe().expect("the test's own path");
        // target/<profile>/deps/<test> → target/<profile>
        let profile_dir = exe
            .parent()
            .and_then(|d| d.parent())
            .expect("tests run from target/<profile>/deps")
            .to_path_buf();
        let release = profile_dir.file_name().is_some_and(|n| n == "release");
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let mut command = std::process::Command::new(cargo);
        command
            .args(["build", "--quiet", "-p", "trilux", "--bin", "trilux"])
            .current_dir(env!("CARGO_MANIFEST_DIR"));
        if release {
            command.arg("--release");
        }
        let status = command.status().expect("cargo runs");
        assert!(status.success(), "building the trilux binary failed");
        let bin = profile_dir.join(format!("trilux{}", std::env::consts::EXE_SUFFIX));
        assert!(bin.exists(), "{} was not built", bin.display());
        bin
    })
    .clone()
}

/// Upper quantile of the chi-square distribution with `dof` degrees of
/// freedom at `z` standard normal deviations (Wilson–Hilferty).
pub fn chi_square_quantile(dof: f64, z: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + z * a.sqrt()).powi(3)
}
