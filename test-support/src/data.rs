//! Where the real data is: the one definition of `TRILUX_DATA` for the
//! workspace's tests.

use std::path::{Path, PathBuf};

/// The data folder named by `TRILUX_DATA` (a relative path is taken from
/// the workspace root, as CI gives it, since cargo runs tests from the
/// package folder), or `None` when unset.
///
/// # Panics
/// When `TRILUX_DATA` names no folder: a typo fails the test instead of
/// skipping it.
pub fn data_dir() -> Option<PathBuf> {
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

/// The six surface meshes of the data README (`meshes/NAME.obj`), open
/// and closed: the set every real-data test of a surface algorithm runs
/// on.
pub const MESHES: [&str; 6] = [
    "fandisk",
    "nefertiti",
    "spot",
    "stanford-bunny",
    "suzanne",
    "teapot",
];

/// A file of the data folder; call it only after [`data_dir`] or
/// [`have_data`] said the folder is there.
///
/// # Panics
/// When `TRILUX_DATA` is unset.
pub fn data(relative: &str) -> PathBuf {
    data_dir()
        .expect("TRILUX_DATA names the data folder")
        .join(relative)
}

/// Whether the real-data tests can run; prints why `test` is skipped
/// when they cannot.
pub fn have_data(test: &str) -> bool {
    let present = data_dir().is_some();
    if !present {
        eprintln!("{test}: skipped, it needs TRILUX_DATA (the data folder, e.g. ../shared/data)");
    }
    present
}
