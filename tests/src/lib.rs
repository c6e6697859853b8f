//! Shared helpers of the workspace's cross-crate and end-to-end tests.

use std::path::PathBuf;

/// The data folder named by `TRILUX_DATA`, or `None` (tests that need it
/// are `#[ignore]`d at build time when it is unset).
pub fn data_dir() -> Option<PathBuf> {
    std::env::var_os("TRILUX_DATA").map(PathBuf::from)
}
