//! Helpers shared by the end-to-end tests of the `trilux` binary.

#![allow(dead_code, reason = "each test binary uses a subset")]

use std::path::Path;
use std::process::Output;

use std::path::PathBuf;

use assert_cmd::Command;

#[cfg(feature = "web")]
pub(crate) mod web;

/// The `trilux` binary of this package, which cargo builds once before
/// the tests (no nested `cargo build`).
pub(crate) fn trilux_bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_trilux"))
}

#[allow(unused_imports, reason = "each test binary uses a subset")]
pub(crate) use test_support::data::{data, have_data};

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

/// A built-in textured torus (`major` × `minor` segments) and a noise
/// texture of `side` × `side` pixels, written as `torus.obj` and
/// `noise.png` in `dir`.
pub(crate) fn torus_and_noise(
    dir: &Path,
    [major, minor]: [u32; 2],
    side: u32,
) -> (PathBuf, PathBuf) {
    let torus = dir.join("torus.obj");
    trilux::shapes::torus(major, minor).write(&torus).unwrap();
    let noise = dir.join("noise.png");
    trilux_io::image::write(&noise, &trilux::shapes::noise(side, side, 1)).unwrap();
    (torus, noise)
}

/// The built-in bumpy blob (closed, about unit size) written as
/// `blob.obj` in `dir`.
pub(crate) fn blob(dir: &Path) -> PathBuf {
    let path = dir.join("blob.obj");
    trilux::shapes::blob(2).write(&path).unwrap();
    path
}

/// Asserts that no temporary `.partial` file or folder is left in `dir`.
pub(crate) fn no_partial_files(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".partial"), "left behind: {name}");
    }
}

/// Copies the browser script `name` from `cli/tests/browser/`, and the
/// `lib.mjs` it imports, into `target/browser-e2e` (beside node_modules,
/// so that their import of playwright-core resolves); the script's path
/// there.
pub(crate) fn browser_script(name: &str) -> PathBuf {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let (from, to) = (
        root.join("cli/tests/browser"),
        root.join("target/browser-e2e"),
    );
    for file in ["lib.mjs", name] {
        std::fs::copy(from.join(file), to.join(file))
            .unwrap_or_else(|e| panic!("copying {file} into {}: {e}", to.display()));
    }
    to.join(name)
}
