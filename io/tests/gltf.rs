//! glTF: the three container variants of `$TRILUX_DATA/gltf` with the
//! counts of the data README, node transforms, and hostile or broken
//! files (URIs outside the folder, short buffers).

mod support;

use support::{data_dir, scratch};

use glam::Vec3;
use trilux_io::ErrorKind;
use trilux_io::mesh::gltf::{self, Options};
use trilux_io::mesh::{TriMesh, Wrap};

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_gltf_files_match_the_data_readme() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    let gltf_dir = data.join("gltf");

    // Embedded variant: data: URIs for the buffer and the PNG.
    let boxed = TriMesh::read(gltf_dir.join("BoxTextured/BoxTextured.gltf")).unwrap();
    assert_eq!((boxed.positions.len(), boxed.indices.len()), (24, 12));
    assert!(boxed.normals.is_some());
    let max_u = boxed
        .uvs
        .as_ref()
        .unwrap()
        .iter()
        .map(|t| t.x)
        .fold(0.0f32, f32::max);
    assert!((max_u - 6.0).abs() < 1e-5, "UVs span [0, 6]: {max_u}");
    let material = &boxed.materials[boxed.objects[0].material.unwrap()];
    assert_eq!(material.wrap, [Wrap::Repeat; 2]);
    let texture = material.diffuse_image.as_ref().unwrap();
    assert_eq!((texture.width, texture.height), (211, 211));
    assert!(
        (boxed.area() - 6.0).abs() < 1e-4,
        "a unit cube: {}",
        boxed.area()
    );

    // Separate .gltf + .bin + PNG files.
    let helmet = TriMesh::read(gltf_dir.join("FlightHelmet/FlightHelmet.gltf")).unwrap();
    assert_eq!(helmet.objects.len(), 6);
    assert_eq!(
        (helmet.positions.len(), helmet.indices.len()),
        (55_392, 94_722)
    );
    for object in &helmet.objects {
        let m = &helmet.materials[object.material.unwrap()];
        let file = m.diffuse_texture.as_ref().unwrap();
        assert!(
            file.starts_with(gltf_dir.join("FlightHelmet")),
            "{}",
            file.display()
        );
        assert_eq!(m.diffuse_image.as_ref().unwrap().width, 512);
    }

    // Binary GLB, non-indexed, no normals, texture in a buffer view.
    let fox = TriMesh::read(gltf_dir.join("Fox.glb")).unwrap();
    assert_eq!((fox.positions.len(), fox.indices.len()), (1_728, 576));
    assert!(fox.normals.is_none());
    assert!(fox.uvs.is_some());
    let image = fox.materials[0].diffuse_image.as_ref().unwrap();
    assert!(image.width > 0 && fox.materials[0].diffuse_texture.is_none());
}

/// One triangle: positions (0,0,0), (1,0,0), (0,1,0) and u16 indices in a
/// 44-byte buffer, as the bytes and the glTF JSON that reads them.
fn triangle(uri: &str, byte_length: usize, node: &str) -> (Vec<u8>, String) {
    let mut bin = Vec::new();
    for p in [[0.0f32, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        for x in p {
            bin.extend_from_slice(&x.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{node}],"meshes":[{{"name":"tri","primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
"buffers":[{{"uri":"{uri}","byteLength":{byte_length}}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}]}}"#
    );
    (bin, json)
}

#[test]
fn node_transforms_are_applied_and_mirrors_keep_the_winding() {
    let dir = scratch("transforms");
    let (bin, json) = triangle(
        "tri.bin",
        44,
        r#"{"mesh":0,"translation":[10,0,0],"scale":[2,2,2]}"#,
    );
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    std::fs::write(dir.join("t.gltf"), json).unwrap();
    let mesh = TriMesh::read(dir.join("t.gltf")).unwrap();
    assert_eq!(
        mesh.positions,
        vec![
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(12.0, 0.0, 0.0),
            Vec3::new(10.0, 2.0, 0.0)
        ]
    );
    assert_eq!(mesh.indices, vec![[0, 1, 2]]);
    assert_eq!(mesh.objects[0].name, "tri");

    let (_, json) = triangle("tri.bin", 44, r#"{"mesh":0,"scale":[-1,1,1]}"#);
    std::fs::write(dir.join("m.gltf"), json).unwrap();
    let mirrored = TriMesh::read(dir.join("m.gltf")).unwrap();
    assert_eq!(
        mirrored.indices,
        vec![[0, 2, 1]],
        "a mirror flips the winding back"
    );
}

#[test]
fn uris_cannot_leave_the_folder_unless_allowed() {
    let root = scratch("hostile");
    let inner = root.join("asset");
    std::fs::create_dir_all(&inner).unwrap();
    let (bin, _) = triangle("", 44, "{}");
    std::fs::write(root.join("secret.bin"), &bin).unwrap();
    for uri in [
        "../secret.bin",
        "/etc/hostname",
        "http://example.com/x.bin",
        "file:///etc/hostname",
        "sub/../../secret.bin",
        "%2E%2E/secret.bin",
    ] {
        let (_, json) = triangle(uri, 44, r#"{"mesh":0}"#);
        let path = inner.join("h.gltf");
        std::fs::write(&path, json).unwrap();
        let err = gltf::read(&path).unwrap_err();
        assert!(
            matches!(err.kind, ErrorKind::OutsideFolder(_)),
            "{uri}: {err}"
        );
    }
    let (_, json) = triangle("../secret.bin", 44, r#"{"mesh":0}"#);
    let path = inner.join("ok.gltf");
    std::fs::write(&path, json).unwrap();
    let allowed = Options {
        allow_outside_folder: true,
    };
    assert_eq!(gltf::read_with(&path, allowed).unwrap().indices.len(), 1);
}

#[test]
fn broken_gltf_files() {
    let dir = scratch("broken");
    // The buffer file is shorter than its declared byteLength.
    let (bin, json) = triangle("short.bin", 44, r#"{"mesh":0}"#);
    std::fs::write(dir.join("short.bin"), &bin[..30]).unwrap();
    std::fs::write(dir.join("a.gltf"), json).unwrap();
    let err = TriMesh::read(dir.join("a.gltf")).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Truncated(_)), "{err}");
    // The buffer declares too few bytes for its views: refused by the glTF
    // validation or by our accessor check, never a panic.
    let (bin, json) = triangle("tri.bin", 20, r#"{"mesh":0}"#);
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    std::fs::write(dir.join("b.gltf"), json).unwrap();
    assert!(TriMesh::read(dir.join("b.gltf")).is_err());
    // Not JSON at all, a missing buffer file.
    std::fs::write(dir.join("c.gltf"), b"{ nope").unwrap();
    let err = TriMesh::read(dir.join("c.gltf")).unwrap_err();
    assert!(
        matches!(err.kind, ErrorKind::Codec { format: "glTF", .. }),
        "{err}"
    );
    let (_, json) = triangle("gone.bin", 44, r#"{"mesh":0}"#);
    std::fs::write(dir.join("d.gltf"), json).unwrap();
    let err = TriMesh::read(dir.join("d.gltf")).unwrap_err();
    assert!(
        matches!(err.kind, ErrorKind::Io(_)) && err.path.ends_with("gone.bin"),
        "{err}"
    );
}
