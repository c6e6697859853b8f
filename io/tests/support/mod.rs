//! Helpers shared by the integration tests of `trilux-io`.

#![allow(dead_code, reason = "each test binary uses a subset")]

use std::path::{Path, PathBuf};

#[allow(unused_imports, reason = "each test binary uses a subset")]
pub(crate) use test_support::data::data_dir;

/// A fresh scratch folder, unique even for tests running in parallel.
pub(crate) fn scratch(name: &str) -> PathBuf {
    use std::sync::atomic::{AtomicUsize, Ordering};
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("trilux-io-{}-{n}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `bytes` to `dir/name` and returns the path.
pub(crate) fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}
