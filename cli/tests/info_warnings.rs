//! `trilux info` on the second set of regression inputs: the warnings a
//! user needs (the file, the element, what was skipped) on stdout and in
//! `--json`, and exit code 0 for an intact mesh.

mod common;

use std::path::{Path, PathBuf};

use common::{stderr, trilux};

fn regression(folder: &str, name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../io/tests/regressions")
        .join(folder)
        .join(name)
}

/// Runs `trilux info FILE --json` and `trilux info FILE`, expects success,
/// and returns the JSON and the text.
fn info(file: &Path) -> (serde_json::Value, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = trilux(dir.path())
        .args(["info", file.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}: {}", file.display(), stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let out = trilux(dir.path())
        .args(["info", file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    (json, String::from_utf8_lossy(&out.stdout).into_owned())
}

#[test]
fn info_lists_what_the_readers_skipped() {
    // Dangling `vt` indices: the geometry, and the warning naming them.
    let (json, text) = info(&regression("obj-face-vt-without-vt", "square.obj"));
    assert_eq!(json["triangles"], 2);
    let warnings = json["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1);
    let w = warnings[0].as_str().unwrap();
    assert!(w.contains("square.obj") && w.contains("`vt`"), "{w}");
    assert!(
        text.contains("warnings: 1") && text.contains("`vt`"),
        "{text}"
    );

    // Strips are triangles now, not a point cloud, and nothing is skipped.
    let (json, _) = info(&regression("ply-tristrips", "strips.ply"));
    assert_eq!(json["triangles"], 6);
    assert_eq!(json["warnings"].as_array().unwrap().len(), 0);

    // A texture only in an extension: named with the extension.
    let (json, text) = info(&regression(
        "gltf-texture-without-source",
        "basisu_only.gltf",
    ));
    assert_eq!(json["triangles"], 1);
    assert!(text.contains("KHR_texture_basisu"), "{text}");

    // Extra face properties of a big-endian PLY: named.
    let (json, _) = info(&regression("ply-big-endian-polygons", "polygons_be.ply"));
    let w = json["warnings"][0].as_str().unwrap();
    assert!(w.contains("polygons_be.ply") && w.contains("`face`"), "{w}");
}
