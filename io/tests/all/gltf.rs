//! glTF: the three container variants of `$TRILUX_DATA/gltf` with the
//! counts of the data README, node transforms, and hostile or broken
//! files (URIs outside the folder, short buffers).

use crate::support;

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

/// A glTF built in code: one buffer file, a view per added array, and
/// accessors over them.
#[derive(Default)]
struct Asset {
    bin: Vec<u8>,
    views: Vec<String>,
    accessors: Vec<String>,
}

impl Asset {
    /// Appends `bytes` (4-byte aligned) as a buffer view with an optional
    /// stride; returns its index.
    fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let stride = stride.map_or(String::new(), |s| format!(r#","byteStride":{s}"#));
        self.views.push(format!(
            r#"{{"buffer":0,"byteOffset":{},"byteLength":{}{stride}}}"#,
            self.bin.len(),
            bytes.len()
        ));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Adds an accessor given as JSON members; returns its index.
    fn accessor(&mut self, members: &str) -> usize {
        self.accessors.push(format!("{{{members}}}"));
        self.accessors.len() - 1
    }

    /// Writes `name.gltf` and its buffer into `dir` with the given
    /// primitive attributes, material section and extensions; reads it.
    fn read(
        &self,
        dir: &std::path::Path,
        name: &str,
        primitive: &str,
        extra: &str,
    ) -> trilux_io::Result<TriMesh> {
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0}}],"meshes":[{{"primitives":[{{{primitive}}}]}}],
"buffers":[{{"uri":"{name}.bin","byteLength":{}}}],
"bufferViews":[{}],"accessors":[{}]{extra}}}"#,
            self.bin.len(),
            self.views.join(","),
            self.accessors.join(",")
        );
        let path = dir.join(format!("{name}.gltf"));
        std::fs::write(&path, json).unwrap();
        TriMesh::read(path)
    }
}

fn bytes<T: Copy, const N: usize>(values: &[T], to: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    values.iter().flat_map(|&v| to(v)).collect()
}

/// Positions as non-normalized `BYTE` (KHR_mesh_quantization), normals as
/// normalized `BYTE`, UVs as normalized `UNSIGNED_BYTE` and `SHORT`, a
/// strided view: every component type decodes through the one decoder.
#[test]
fn integer_component_types_decode_as_the_spec_says() {
    let dir = scratch("gltf-types");
    let mut a = Asset::default();
    // VEC3 of i8 padded to 4 bytes per element (byteStride 4).
    let pos = a.view(&[0, 0, 0, 0, 10, 0, 0, 0, 0, 20, 0, 0], Some(4));
    a.accessor(&format!(
        r#""bufferView":{pos},"componentType":5120,"count":3,"type":"VEC3","min":[0,0,0],"max":[10,20,0]"#
    ));
    let normals = a.view(&[0, 0, 127, 0, 0, 0, 129, 0, 0, 0, 127, 0], Some(4)); // 129 = -127
    a.accessor(&format!(
        r#""bufferView":{normals},"componentType":5120,"normalized":true,"count":3,"type":"VEC3""#
    ));
    let uv0 = a.view(&[0, 255, 0, 0, 255, 0, 0, 0, 51, 102, 0, 0], Some(4));
    a.accessor(&format!(
        r#""bufferView":{uv0},"componentType":5121,"normalized":true,"count":3,"type":"VEC2""#
    ));
    let uv1 = a.view(
        &bytes(&[0i16, -32768, 32767, 0, 16384, -16384], i16::to_le_bytes),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{uv1},"componentType":5122,"normalized":true,"count":3,"type":"VEC2""#
    ));
    let mesh = a
        .read(
            &dir,
            "types",
            r#""attributes":{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2,"TEXCOORD_1":3}"#,
            r#","extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"]"#,
        )
        .unwrap();
    assert_eq!(
        mesh.positions,
        vec![
            Vec3::ZERO,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(0.0, 20.0, 0.0)
        ]
    );
    assert!((mesh.area() - 100.0).abs() < 1e-9);
    let normals = mesh.normals.unwrap();
    assert_eq!(normals[0], Vec3::Z);
    assert_eq!(normals[1], Vec3::NEG_Z);
    let uvs = mesh.uvs.unwrap();
    assert_eq!(uvs[0], glam::Vec2::new(0.0, 1.0));
    assert_eq!(uvs[1], glam::Vec2::new(1.0, 0.0));
    assert!((uvs[2] - glam::Vec2::new(0.2, 0.4)).abs().max_element() < 1e-6);
    let uvs1 = mesh.uvs1.unwrap();
    assert_eq!(uvs1[0], glam::Vec2::new(0.0, -1.0), "-32768 clamps to -1");
    assert_eq!(uvs1[1], glam::Vec2::new(1.0, 0.0));
    assert!((uvs1[2] - glam::Vec2::new(16384.0 / 32767.0, -16384.0 / 32767.0)).length() < 1e-6);
}

/// A unit triangle with two UV sets, a base-colour texture that reads
/// `TEXCOORD_1` and carries a KHR_texture_transform.
fn textured(
    dir: &std::path::Path,
    name: &str,
    texture_info: &str,
    required: &str,
) -> trilux_io::Result<TriMesh> {
    let image = trilux_io::image::Image {
        width: 2,
        height: 1,
        pixels: vec![[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]],
    };
    trilux_io::image::write_png(
        dir.join("tex.png"),
        &image,
        trilux_io::image::PngDepth::Eight,
    )
    .unwrap();
    let mut a = Asset::default();
    let p = a.view(
        &bytes(
            &[0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            f32::to_le_bytes,
        ),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{p},"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]"#
    ));
    let t0 = a.view(
        &bytes(&[0.0f32, 0.0, 0.5, 0.0, 0.0, 0.5], f32::to_le_bytes),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{t0},"componentType":5126,"count":3,"type":"VEC2""#
    ));
    let t1 = a.view(
        &bytes(&[0.0f32, 0.0, 1.0, 0.0, 0.0, 1.0], f32::to_le_bytes),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{t1},"componentType":5126,"count":3,"type":"VEC2""#
    ));
    a.read(
        dir,
        name,
        r#""attributes":{"POSITION":0,"TEXCOORD_0":1,"TEXCOORD_1":2},"material":0"#,
        &format!(
            r#","materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{{texture_info}}}}}}}],
"textures":[{{"source":0}}],"images":[{{"uri":"tex.png"}}]{required}"#
        ),
    )
}

#[test]
fn the_uv_set_the_material_names_is_the_one_read() {
    let dir = scratch("gltf-texcoord");
    let mesh = textured(&dir, "set1", r#""index":0,"texCoord":1"#, "").unwrap();
    let uvs = mesh.uvs.as_ref().unwrap();
    assert_eq!(
        uvs[1],
        glam::Vec2::new(1.0, 0.0),
        "TEXCOORD_1, not TEXCOORD_0"
    );
    assert_eq!(mesh.uvs1.as_ref().unwrap()[1], glam::Vec2::new(1.0, 0.0));
    let mesh = textured(&dir, "set0", r#""index":0"#, "").unwrap();
    assert_eq!(mesh.uvs.as_ref().unwrap()[1], glam::Vec2::new(0.5, 0.0));
    assert_eq!(mesh.materials[0].diffuse_image.as_ref().unwrap().width, 2);

    // A texture reading a set the primitive lacks is an error, not a
    // mesh with zero UVs.
    let err = textured(&dir, "set3", r#""index":0,"texCoord":3"#, "").unwrap_err();
    assert!(err.to_string().contains("TEXCOORD_3"), "{err}");
}

#[test]
fn khr_texture_transform_is_applied_to_the_uvs() {
    let dir = scratch("gltf-transform");
    // Scale (2, 3), then a quarter turn, then offset (0.5, 0.25):
    // (1, 0) -> (2, 0) -> (0, 2) -> (0.5, 2.25).
    let info = r#""index":0,"texCoord":1,"extensions":{"KHR_texture_transform":{"offset":[0.5,0.25],"rotation":1.5707963267948966,"scale":[2,3]}}"#;
    let required = r#","extensionsUsed":["KHR_texture_transform"],"extensionsRequired":["KHR_texture_transform"]"#;
    let mesh = textured(&dir, "tt", info, required).unwrap();
    let uvs = mesh.uvs.unwrap();
    assert!(
        (uvs[0] - glam::Vec2::new(0.5, 0.25)).length() < 1e-6,
        "{}",
        uvs[0]
    );
    assert!(
        (uvs[1] - glam::Vec2::new(0.5, 2.25)).length() < 1e-6,
        "{}",
        uvs[1]
    );
    // (0, 1) -> (0, 3) -> (-3, 0) -> (-2.5, 0.25).
    assert!(
        (uvs[2] - glam::Vec2::new(-2.5, 0.25)).length() < 1e-6,
        "{}",
        uvs[2]
    );
    // The second set stays as stored.
    assert_eq!(mesh.uvs1.unwrap()[1], glam::Vec2::new(1.0, 0.0));
}

#[test]
fn a_required_extension_that_is_not_honoured_is_named() {
    let dir = scratch("gltf-extension");
    let required = r#","extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"]"#;
    let err = textured(&dir, "draco", r#""index":0"#, required).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Unsupported(_)), "{err}");
    assert!(
        err.to_string().contains("KHR_draco_mesh_compression"),
        "{err}"
    );
}

/// A sparse accessor without a buffer view: zeros with two substituted
/// elements.
#[test]
fn sparse_accessors_over_zeros() {
    let dir = scratch("gltf-sparse-zeros");
    let mut a = Asset::default();
    let idx = a.view(&bytes(&[1u16, 2], u16::to_le_bytes), None);
    let val = a.view(
        &bytes(&[1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0], f32::to_le_bytes),
        None,
    );
    a.accessor(&format!(
        r#""componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
"sparse":{{"count":2,"indices":{{"bufferView":{idx},"componentType":5123}},"values":{{"bufferView":{val}}}}}"#
    ));
    let mesh = a
        .read(&dir, "zeros", r#""attributes":{"POSITION":0}"#, "")
        .unwrap();
    assert_eq!(mesh.positions, vec![Vec3::ZERO, Vec3::X, Vec3::Y]);
    assert_eq!(mesh.indices, vec![[0, 1, 2]]);

    // A sparse index beyond the count is refused.
    let mut b = Asset::default();
    let idx = b.view(&bytes(&[1u16, 7], u16::to_le_bytes), None);
    let val = b.view(
        &bytes(&[1.0f32, 0.0, 0.0, 0.0, 1.0, 0.0], f32::to_le_bytes),
        None,
    );
    b.accessor(&format!(
        r#""componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
"sparse":{{"count":2,"indices":{{"bufferView":{idx},"componentType":5123}},"values":{{"bufferView":{val}}}}}"#
    ));
    let err = b
        .read(&dir, "beyond", r#""attributes":{"POSITION":0}"#, "")
        .unwrap_err();
    assert!(err.to_string().contains("sparse index 7"), "{err}");
}

/// The same textured triangle as an OBJ (v up) and as a glTF (v down),
/// over a texture whose top row is red and bottom row blue: both files'
/// UVs must land on the same texels. Without the OBJ reader's flip (or
/// with a flip added to glTF) the corners would land on opposite rows.
#[test]
fn obj_and_gltf_uvs_land_on_the_same_texels() {
    use trilux_io::image::{Image, PngDepth};
    let dir = scratch("uv-agreement");
    let texture = Image {
        width: 1,
        height: 2,
        pixels: vec![[1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]],
    };
    trilux_io::image::write_png(dir.join("tex.png"), &texture, PngDepth::Eight).unwrap();
    let texel = |mesh: &TriMesh, i: usize| {
        let uv = mesh.uvs.as_ref().unwrap()[i];
        let image = mesh.materials[0]
            .diffuse_image
            .clone()
            .unwrap_or_else(|| trilux_io::image::read(dir.join("tex.png")).unwrap());
        let x = ((uv.x * image.width as f32) as u32).min(image.width - 1);
        let y = ((uv.y * image.height as f32) as u32).min(image.height - 1);
        image.pixels[(y * image.width + x) as usize]
    };
    // Corner 0 in the upper half of the picture, corners 1 and 2 in the
    // lower half, as each format writes it.
    std::fs::write(dir.join("t.mtl"), "newmtl m\nmap_Kd tex.png\n").unwrap();
    std::fs::write(
        dir.join("t.obj"),
        "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.75\nvt 0.5 0.25\nvt 0.2 0.1\nusemtl m\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let obj = TriMesh::read(dir.join("t.obj")).unwrap();
    let mut a = Asset::default();
    let p = a.view(
        &bytes(
            &[0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
            f32::to_le_bytes,
        ),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{p},"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]"#
    ));
    let t = a.view(
        &bytes(&[0.5f32, 0.25, 0.5, 0.75, 0.2, 0.9], f32::to_le_bytes),
        None,
    );
    a.accessor(&format!(
        r#""bufferView":{t},"componentType":5126,"count":3,"type":"VEC2""#
    ));
    let gltf = a
        .read(
            &dir,
            "t",
            r#""attributes":{"POSITION":0,"TEXCOORD_0":1},"material":0"#,
            r#","materials":[{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}],
"textures":[{"source":0}],"images":[{"uri":"tex.png"}]"#,
        )
        .unwrap();
    let red = [1.0, 0.0, 0.0, 1.0];
    let blue = [0.0, 0.0, 1.0, 1.0];
    for (mesh, name) in [(&obj, "OBJ"), (&gltf, "glTF")] {
        assert_eq!(texel(mesh, 0), red, "{name}");
        assert_eq!(texel(mesh, 1), blue, "{name}");
        assert_eq!(texel(mesh, 2), blue, "{name}");
    }
    for i in 0..3 {
        let (u, v) = (obj.uvs.as_ref().unwrap()[i], gltf.uvs.as_ref().unwrap()[i]);
        assert!((u - v).abs().max_element() < 1e-6, "corner {i}: {u} vs {v}");
    }
}

/// An accessor without a buffer view declaring 10^9 elements: refused
/// with the number before anything is allocated.
#[test]
fn zero_filled_accessors_have_a_budget() {
    let dir = scratch("gltf-budget");
    let mut a = Asset::default();
    let idx = a.view(&bytes(&[1u16], u16::to_le_bytes), None);
    let val = a.view(&bytes(&[1.0f32, 0.0, 0.0], f32::to_le_bytes), None);
    a.accessor(&format!(
        r#""componentType":5126,"count":1000000000,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
"sparse":{{"count":1,"indices":{{"bufferView":{idx},"componentType":5123}},"values":{{"bufferView":{val}}}}}"#
    ));
    let err = a
        .read(&dir, "huge", r#""attributes":{"POSITION":0}"#, "")
        .unwrap_err();
    assert!(matches!(err.kind, ErrorKind::LimitExceeded(_)), "{err}");
    assert!(err.to_string().contains("1000000000"), "{err}");
}

/// A node translation to georeferenced coordinates (x ≈ 4·10^5,
/// y ≈ 4.6·10^6) is applied in f64: the millimetre triangle keeps its
/// area, and the shift is recorded in `origin`.
#[test]
fn far_node_translations_keep_the_triangles() {
    let dir = scratch("gltf-far");
    let (bin, json) = triangle(
        "tri.bin",
        44,
        // Values the f32 of glTF's JSON holds exactly.
        r#"{"mesh":0,"translation":[412345.5,4612345.5,231.0],"scale":[0.001,0.001,0.001]}"#,
    );
    std::fs::write(dir.join("tri.bin"), &bin).unwrap();
    std::fs::write(dir.join("far.gltf"), json).unwrap();
    let mesh = TriMesh::read(dir.join("far.gltf")).unwrap();
    assert_ne!(mesh.origin, glam::DVec3::ZERO);
    assert!((mesh.area() - 0.5e-6).abs() < 1e-9, "{}", mesh.area());
    let first = mesh.absolute_positions()[0];
    assert!((first - glam::DVec3::new(412_345.5, 4_612_345.5, 231.0)).length() < 1e-6);
}

/// The 19 bytes on which the fuzzer found the `gltf` crate's GLB split
/// overflowing (`length - 12` with a total length of 1), and a GLB made
/// from a real glTF triangle: the broken header is an `Err` naming the
/// file and the field, and the intact container still reads.
#[test]
fn glb_headers_are_checked_before_the_gltf_crate_splits_them() {
    let crash = b"glTFdxte\x01\x00\x00\x00nsUsem ";
    let err = gltf::from_bytes(crash, "fuzzed.glb", Options::default()).unwrap_err();
    let text = err.to_string();
    assert!(text.starts_with("fuzzed.glb: byte 4:"), "{text}");
    assert!(text.contains("GLB version"), "{text}");

    let dir = scratch("gltf-glb-header");
    let (bin, json) = triangle("unused.bin", 44, r#"{"mesh":0}"#);
    // The same triangle as a GLB: the buffer without a URI is the BIN chunk.
    let json = json.replace(r#""uri":"unused.bin","#, "");
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = b"glTF\x02\x00\x00\x00\0\0\0\0".to_vec();
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    let total = glb.len() as u32;
    glb[8..12].copy_from_slice(&total.to_le_bytes());
    let mesh = gltf::from_bytes(&glb, dir.join("tri.glb"), Options::default()).unwrap();
    assert_eq!(mesh.indices.len(), 1);

    for (field, value) in [(8, 1u32), (8, total + 1), (12, u32::MAX)] {
        let mut broken = glb.clone();
        broken[field..field + 4].copy_from_slice(&value.to_le_bytes());
        let err = gltf::from_bytes(&broken, dir.join("tri.glb"), Options::default()).unwrap_err();
        let text = err.to_string();
        assert!(text.contains(&format!("tri.glb: byte {field}:")), "{text}");
    }
}
