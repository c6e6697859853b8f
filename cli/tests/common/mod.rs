//! Helpers shared by the end-to-end tests of the `trilux` binary.

#![allow(dead_code, reason = "each test binary uses a subset")]

use std::path::Path;
use std::process::Output;

use std::path::PathBuf;

use assert_cmd::Command;

/// The `trilux` binary of this package, which cargo builds once before
/// the tests (no nested `cargo build`).
pub(crate) fn trilux_bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_trilux"))
}

/// The data folder named by `TRILUX_DATA` (a relative path is taken from
/// the workspace root, as CI gives it), or `None` when it is unset; a
/// value that names no folder fails the test instead of skipping it.
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

/// A file of the data folder (only real-data tests call it, after
/// [`data_dir`] said the folder is there).
pub(crate) fn data(relative: &str) -> PathBuf {
    data_dir()
        .expect("TRILUX_DATA names the data folder")
        .join(relative)
}

/// Whether the real-data tests can run; prints why one is skipped.
pub(crate) fn have_data(test: &str) -> bool {
    let present = data_dir().is_some();
    if !present {
        eprintln!("{test}: skipped, it needs TRILUX_DATA (the data folder, e.g. ../shared/data)");
    }
    present
}

/// The `trilux` binary, run in `dir`.
pub(crate) fn trilux(dir: &Path) -> Command {
    let mut c = Command::new(trilux_bin());
    c.current_dir(dir);
    c
}

pub(crate) fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs and expects failure with exit code 1 or 2 and a one-paragraph
/// message containing every `needle`, no panic and no backtrace.
pub(crate) fn fails(dir: &Path, args: &[&str], needles: &[&str]) {
    let out = run(dir, args);
    failed(args, &out, needles);
}

/// Like [`fails`], and the exit code is `code` (1: the inputs or the run
/// failed; 2: the command line is wrong). Returns the message.
pub(crate) fn fails_with(dir: &Path, code: i32, args: &[&str], needles: &[&str]) -> String {
    let out = run(dir, args);
    failed(args, &out, needles);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {}", stderr(&out));
    stderr(&out)
}

fn failed(args: &[&str], out: &Output, needles: &[&str]) {
    let err = stderr(out);
    assert!(!out.status.success(), "{args:?} succeeded");
    assert!(
        matches!(out.status.code(), Some(1 | 2)),
        "{args:?}: {:?}",
        out.status
    );
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{err}"
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: {n:?} not in {err:?}");
    }
}

/// Runs with `--json` and returns the result object.
pub(crate) fn json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let out = trilux(dir).args(args).arg("--json").output().unwrap();
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Runs `trilux ARGS` in `dir` and returns what it did.
pub(crate) fn run(dir: &Path, args: &[&str]) -> Output {
    trilux(dir).args(args).output().unwrap()
}
