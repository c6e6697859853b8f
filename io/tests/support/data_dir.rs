//! Where the real data is: the one definition of `TRILUX_DATA` for the
//! workspace's tests, included by path from the other crates' tests.

use std::path::{Path, PathBuf};

/// The data folder named by `TRILUX_DATA` (a relative path is taken from
/// the workspace root, since cargo runs tests from the package folder), or
/// `None` when unset. A value that names no folder fails the test instead
/// of skipping it.
pub(crate) fn data_dir() -> Option<PathBuf> {
    let given = PathBuf::from(std::env::var_os("TRILUX_DATA")?);
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let found = [given.clone(), workspace.join(&given)]
        .into_iter()
        .find(|p| p.is_dir());
    assert!(
        found.is_some(),
        "TRILUX_DATA={} names no folder",
        given.display()
    );
    found
}
