//! `trilux info` on the second set of regression inputs: the warnings a
//! user needs (the file, the element, what was skipped) on stdout and in
//! `--json`, and exit code 0 for an intact mesh.

use crate::common;

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

/// Every intact mesh of the second set: `trilux info` exits 0 with its
/// right counts, and names what a user has to act on (the MTL case
/// variants read, so nothing to warn about; the inverted tetrahedron
/// counted; the unused-node, duplicate and non-manifold reports zero).
#[test]
fn info_accepts_every_intact_mesh_of_the_second_set() {
    let cases: [(&str, &str, u64); 7] = [
        ("mtl-keyword-case", "two_planes.obj", 4),
        (
            "gltf-texture-without-source",
            "basisu_with_png_fallback.gltf",
            1,
        ),
        ("obj-negative-indices", "blocks.obj", 6),
        ("gltf-strip-fan-interleaved", "modes.gltf", 5),
        ("ply-big-endian-polygons", "polygons_be.ply", 5),
        ("ply-tristrips", "strips.ply", 6),
        ("obj-face-vt-without-vt", "square.obj", 2),
    ];
    for (folder, name, triangles) in cases {
        let (json, _) = info(&regression(folder, name));
        assert_eq!(json["triangles"], triangles, "{name}: {json}");
    }
    let (json, _) = info(&regression("mtl-keyword-case", "two_planes.obj"));
    assert_eq!(json["warnings"].as_array().unwrap().len(), 0, "{json}");

    let (json, text) = info(&regression("tet-inverted-and-flat", "inverted.msh"));
    assert_eq!(json["unused_nodes"].as_array().unwrap().len(), 0, "{json}");
    assert!(text.contains("unused nodes: 0"), "{text}");
    // The inverted tetrahedron is named, with what diffuse does with it.
    let inverted = json["inverted_tetrahedra"].as_array().unwrap();
    assert_eq!(inverted.len(), 1, "{json}");
    assert!(
        text.contains("inverted (diffuse re-orients them): 1"),
        "{text}"
    );
    // The flat tetrahedron is a mesh to describe, not an error for info,
    // but info names it as diffuse does: tetrahedron 2.
    let (json, text) = info(&regression("tet-inverted-and-flat", "with_flat_tet.msh"));
    assert!(json["tetrahedra"].as_u64().unwrap() >= 3, "{json}");
    assert_eq!(json["flat_tetrahedra"], serde_json::json!([2]), "{json}");
    assert!(
        text.contains("flat (zero volume; diffuse refuses them): 1 — tetrahedra 2 (0-based)"),
        "{text}"
    );
}

/// The inverted tetrahedron is re-oriented and the mesh solves; the flat
/// one is refused by number (tetrahedron 2), naming the file.
#[test]
fn diffuse_solves_the_inverted_mesh_and_names_the_flat_tetrahedron() {
    let dir = tempfile::tempdir().unwrap();
    let inverted = regression("tet-inverted-and-flat", "inverted.msh");
    let out = trilux(dir.path())
        .args([
            "diffuse",
            inverted.to_str().unwrap(),
            "--size",
            "16",
            "-o",
            "i.png",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let flat = regression("tet-inverted-and-flat", "with_flat_tet.msh");
    let out = trilux(dir.path())
        .args([
            "diffuse",
            flat.to_str().unwrap(),
            "--size",
            "16",
            "-o",
            "f.png",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("with_flat_tet.msh") && err.contains("tetrahedron 2"),
        "{err}"
    );
}
