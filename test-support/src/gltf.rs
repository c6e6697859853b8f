//! The Khronos glTF-Validator on the glTF files the tests write: zero
//! errors and zero warnings, infos (and hints) listed.
//!
//! [`validate`] runs the validator's npm package (`gltf-validator`,
//! pinned by `cli/tests/browser/package-lock.json`) with `node`, from
//! `target/browser-e2e` where `.ci/run` installs it:
//!
//! ```sh
//! mkdir -p target/browser-e2e
//! cp cli/tests/browser/package.json cli/tests/browser/package-lock.json target/browser-e2e/
//! (cd target/browser-e2e && npm ci)
//! ```
//!
//! Without `node` or the package a test that validates prints a notice
//! and passes, unless the environment variable `CI` is set: CI must run
//! the validator.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The node script: `node --input-type=module - FILE` with it on stdin.
const SCRIPT: &str = include_str!("gltf_validate.mjs");

/// Validates the `.glb` or `.gltf` file at `path` (its external buffers
/// and images are read relative to it) with the Khronos glTF-Validator.
///
/// Prints the codes of the infos and hints on stderr.
///
/// # Panics
/// When the report has an error or a warning (the message lists them all
/// with their JSON pointers), when the file cannot be read or is neither
/// glTF nor GLB, and when `node` or the validator is missing while `CI`
/// is set.
pub fn validate(path: &Path) {
    let Some(report) = report(path) else { return };
    let (bad, fine): (Vec<&Issue>, Vec<&Issue>) = report
        .issues
        .iter()
        .partition(|i| matches!(i.severity.as_str(), "error" | "warning"));
    assert!(
        bad.is_empty(),
        "glTF-Validator {} on {}: {} error(s), {} warning(s):\n{}",
        report.version,
        path.display(),
        report.count("error"),
        report.count("warning"),
        bad.iter()
            .map(|i| format!("  {i}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    let codes: Vec<String> = fine
        .iter()
        .map(|i| format!("{} {} ({})", i.severity, i.code, i.pointer))
        .collect();
    eprintln!(
        "glTF-Validator {} on {}: valid, {} info(s)/hint(s){}{}",
        report.version,
        path.display(),
        codes.len(),
        if codes.is_empty() { "" } else { ": " },
        codes.join(", ")
    );
}

/// One message of the validator's report.
#[derive(Debug, Clone)]
struct Issue {
    /// `error`, `warning`, `info` or `hint`.
    severity: String,
    code: String,
    /// The JSON pointer (or `byte N` in a GLB) the message is about.
    pointer: String,
    message: String,
}

impl std::fmt::Display for Issue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} {} at {}: {}",
            self.severity, self.code, self.pointer, self.message
        )
    }
}

/// The validator's report on one file.
#[derive(Debug, Clone)]
struct Report {
    version: String,
    issues: Vec<Issue>,
}

impl Report {
    fn count(&self, severity: &str) -> usize {
        self.issues
            .iter()
            .filter(|i| i.severity == severity)
            .count()
    }
}

/// The workspace's `target/browser-e2e`, where the npm packages are.
fn npm_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/browser-e2e")
}

/// Says why the validator cannot run: a failure under CI, else a notice.
fn missing(what: &str) {
    assert!(
        std::env::var_os("CI").is_none(),
        "CI must run the glTF-Validator, but {what}"
    );
    eprintln!("notice: the glTF-Validator check is skipped: {what}");
}

/// The validator's report on `path`, or `None` (after [`missing`]) when
/// node or the package is not there.
fn report(path: &Path) -> Option<Report> {
    assert!(
        path.is_file(),
        "no glTF file to validate at {}",
        path.display()
    );
    let path = std::path::absolute(path).expect("an absolute path");
    let dir = npm_dir();
    if !dir.join("node_modules/gltf-validator").is_dir() {
        missing(&format!(
            "gltf-validator is not installed in {} (see .ci/run)",
            dir.display()
        ));
        return None;
    }
    let child = Command::new("node")
        .args(["--input-type=module", "-"])
        .arg(&path)
        .current_dir(&dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn();
    let mut child = match child {
        Ok(c) => c,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            missing("no node");
            return None;
        }
        Err(e) => panic!("cannot start node: {e}"),
    };
    child
        .stdin
        .take()
        .expect("piped stdin")
        .write_all(SCRIPT.as_bytes())
        .expect("the validator script written to node's stdin");
    let out = child.wait_with_output().expect("node ran");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        Some(0) => {}
        Some(3) => {
            missing(stderr.trim());
            return None;
        }
        _ => panic!(
            "the glTF-Validator did not run on {} ({}):\n{stderr}{stdout}",
            path.display(),
            out.status
        ),
    }
    Some(parse(&stdout).unwrap_or_else(|e| {
        panic!(
            "unreadable output of gltf_validate.mjs on {}: {e}\n{stdout}{stderr}",
            path.display()
        )
    }))
}

/// Reads the script's tab-separated lines (see `gltf_validate.mjs`) and
/// checks them against the report's own counts.
fn parse(stdout: &str) -> Result<Report, String> {
    let mut version = None;
    let mut issues = Vec::new();
    let mut counts = None;
    for line in stdout.lines() {
        let fields: Vec<&str> = line.split('\t').collect();
        match fields.as_slice() {
            ["validator", v] => version = Some(v.to_string()),
            ["issue", severity, code, pointer, message] => issues.push(Issue {
                severity: severity.to_string(),
                code: code.to_string(),
                pointer: pointer.to_string(),
                message: message.to_string(),
            }),
            ["counts", e, w, i, h, complete] => {
                let n = |s: &str| s.parse::<usize>().map_err(|e| format!("{s}: {e}"));
                counts = Some(([n(e)?, n(w)?, n(i)?, n(h)?], *complete == "complete"));
            }
            _ => return Err(format!("unexpected line {line:?}")),
        }
    }
    let version = version.ok_or("no version line")?;
    let (counts, complete) = counts.ok_or("no counts line")?;
    if !complete {
        return Err("the validator truncated its report".into());
    }
    let report = Report { version, issues };
    let listed = ["error", "warning", "info", "hint"].map(|s| report.count(s));
    if listed != counts {
        return Err(format!(
            "the report counts {counts:?} errors/warnings/infos/hints but lists {listed:?}"
        ));
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::panic::{AssertUnwindSafe, catch_unwind};

    /// A GLB: the JSON chunk padded with spaces, the BIN chunk with zeros.
    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut j = json.as_bytes().to_vec();
        j.resize(j.len().next_multiple_of(4), b' ');
        let mut b = bin.to_vec();
        b.resize(b.len().next_multiple_of(4), 0);
        let total = 12 + 8 + j.len() + 8 + b.len();
        let mut out = Vec::with_capacity(total);
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(j);
        out.extend((b.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(b);
        out
    }

    /// One triangle: three positions (36 bytes) and three u16 indices
    /// (6 bytes at offset 36), in a buffer given by `buffer` (a GLB's
    /// `{"byteLength":44}` or a `.gltf`'s with a `uri`), with `extra`
    /// spliced into the node.
    fn triangle_json(buffer: &str, extra: &str) -> String {
        format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0{extra}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"accessors":[
 {{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
 {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
"bufferViews":[
 {{"buffer":0,"byteOffset":0,"byteLength":36,"target":34962}},
 {{"buffer":0,"byteOffset":36,"byteLength":6,"target":34963}}],
"buffers":[{buffer}]}}"#
        )
    }

    fn triangle_bin(indices: [u16; 3]) -> Vec<u8> {
        let mut bin = Vec::new();
        for p in [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.]] {
            for c in p {
                bin.extend(c.to_le_bytes());
            }
        }
        for i in indices {
            bin.extend(i.to_le_bytes());
        }
        bin.extend([0, 0]);
        bin
    }

    /// A fresh scratch folder (test-support has no tempfile).
    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("test-support-gltf-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn write_glb(dir: &Path, indices: [u16; 3], extra: &str) -> PathBuf {
        let path = dir.join("triangle.glb");
        let json = triangle_json(r#"{"byteLength":44}"#, extra);
        std::fs::write(&path, glb(&json, &triangle_bin(indices))).unwrap();
        path
    }

    /// `validate`'s panic message on `path`, or `None` when it returned.
    fn failure(path: &Path) -> Option<String> {
        let e = catch_unwind(AssertUnwindSafe(|| validate(path))).err()?;
        Some(
            e.downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default(),
        )
    }

    // The failing cases use catch_unwind rather than #[should_panic]:
    // without node or the package (and CI unset) `validate` returns, and
    // these tests skip (`report` is None) instead of failing; when the
    // validator runs, they check the panic names the issue.

    #[test]
    fn a_valid_glb_passes() {
        let dir = scratch("valid");
        let path = write_glb(&dir, [0, 1, 2], "");
        if report(&path).is_none() {
            return;
        }
        validate(&path);
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn an_index_out_of_range_is_an_error_that_fails() {
        let dir = scratch("oob");
        let path = write_glb(&dir, [0, 1, 3], "");
        if report(&path).is_none() {
            return;
        }
        let message = failure(&path).expect("validate must panic on an index out of range");
        assert!(
            message.contains("1 error(s), 0 warning(s)")
                && message.contains("error ACCESSOR_INDEX_OOB at /meshes/0/primitives/0/indices"),
            "{message}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_warning_alone_fails() {
        let dir = scratch("warning");
        let path = write_glb(&dir, [0, 1, 2], r#","colour":[1,0,0]"#);
        if report(&path).is_none() {
            return;
        }
        let message = failure(&path).expect("validate must panic on a warning");
        assert!(
            message.contains("0 error(s), 1 warning(s)")
                && message.contains("warning UNEXPECTED_PROPERTY at /nodes/0/colour"),
            "{message}"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_gltf_buffer_is_read_relative_to_the_file() {
        // node runs in target/browser-e2e: a wrong base would not find
        // triangle.bin, and the missing file shows that it is read at all.
        let dir = scratch("external");
        let path = dir.join("triangle.gltf");
        let json = triangle_json(r#"{"byteLength":44,"uri":"triangle.bin"}"#, "");
        std::fs::write(&path, json).unwrap();
        std::fs::write(dir.join("triangle.bin"), triangle_bin([0, 1, 2])).unwrap();
        if report(&path).is_none() {
            return;
        }
        validate(&path);
        std::fs::write(dir.join("triangle.bin"), triangle_bin([0, 1, 3])).unwrap();
        let oob = failure(&path).expect("the external buffer's bad index must fail");
        assert!(oob.contains("ACCESSOR_INDEX_OOB"), "{oob}");
        std::fs::remove_file(dir.join("triangle.bin")).unwrap();
        let gone = failure(&path).expect("a missing external buffer must fail");
        assert!(gone.contains("error IO_ERROR at /buffers/0"), "{gone}");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_file_that_is_not_gltf_fails() {
        let dir = scratch("garbage");
        let path = dir.join("garbage.glb");
        std::fs::write(&path, b"not a glTF file").unwrap();
        if report(&write_glb(&dir, [0, 1, 2], "")).is_none() {
            return;
        }
        let message = failure(&path).expect("validate must panic on a file that is not glTF");
        assert!(message.contains("garbage.glb"), "{message}");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn the_sample_models_fox_passes_and_flight_helmets_warnings_fail() {
        if !crate::data::have_data("the_sample_models") {
            return;
        }
        let fox = crate::data::data("gltf/Fox.glb");
        if report(&fox).is_none() {
            return;
        }
        validate(&fox);
        validate(&crate::data::data("gltf/BoxTextured/BoxTextured.gltf"));
        // FlightHelmet's external PNGs carry colour-space chunks the
        // validator warns about: they are read, and a warning fails.
        let helmet = failure(&crate::data::data("gltf/FlightHelmet/FlightHelmet.gltf"))
            .expect("FlightHelmet has warnings");
        assert!(
            helmet.contains("0 error(s), 15 warning(s)")
                && helmet.contains("warning IMAGE_FEATURES_UNSUPPORTED at /images/14"),
            "{helmet}"
        );
    }
}
