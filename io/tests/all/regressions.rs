//! Inputs that earlier versions read wrongly, each with the value it must
//! give (the files are in `tests/regressions/`, one folder per fault).

use crate::support;

use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use trilux_io::mesh::{TriMesh, obj, ply};
use trilux_io::tet::TetMesh;

fn file(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions")
        .join(folder)
        .join(name)
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() <= 1e-6
}

/// A binary body whose first byte is `0x0a` and whose vertex 2 starts with
/// `0x20`: the reader once skipped them as whitespace.
#[test]
fn ply_binary_records_starting_with_whitespace_bytes() {
    let path = file("ply-binary-whitespace", "quad.ply");
    let bytes = std::fs::read(&path).unwrap();
    let body = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .unwrap()
        + 11;
    assert_eq!(bytes[body], 0x0a, "the case must keep its first data byte");
    let mesh = TriMesh::read(file("ply-binary-whitespace", "quad.ply")).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.indices.len(), 2);
    assert!(close(mesh.positions[0], Vec3::new(1.000_001_2, 0.0, 0.0)));
    assert!(close(mesh.positions[2], Vec3::new(2.000_007_6, 1.0, 0.0)));
    assert!((mesh.area() - 1.000_003_2).abs() < 1e-6);
    // The control: a CRLF header, and records without whitespace bytes.
    let mesh = TriMesh::read(file("ply-binary-whitespace", "quad_crlf.ply")).unwrap();
    assert_eq!(mesh.positions[0], Vec3::new(1.0, 0.0, 0.0));
    assert_eq!(mesh.positions[2], Vec3::new(2.0, 1.0, 0.0));
    assert_eq!(mesh.indices.len(), 2);
    assert!((mesh.area() - 1.0).abs() < 1e-12);
    let sphere = ply::read(file("ply-binary-whitespace", "sphere_points.ply")).unwrap();
    assert_eq!(sphere.positions.len(), 1_000);
    assert_eq!(sphere.triangles.len(), 1_995);
    assert!(close(
        sphere.positions[0],
        Vec3::new(0.540_220_5, -0.132_020_94, -0.831_103)
    ));
}

/// A CRLF OBJ that starts with a UTF-8 byte-order mark before `mtllib`.
#[test]
fn obj_with_a_byte_order_mark() {
    let mesh = obj::read(file("obj-utf8-bom", "model.obj")).unwrap();
    assert_eq!(mesh.positions.len(), 3);
    assert_eq!(mesh.indices.len(), 1);
    assert_eq!(mesh.materials.len(), 1);
    assert_eq!(mesh.materials[0].name, "red");
    assert_eq!(mesh.materials[0].diffuse, [1.0, 0.0, 0.0]);
    assert_eq!(mesh.objects[0].material, Some(0));
}

/// `# …` after `v`, `g` and `f` statements.
#[test]
fn obj_with_trailing_comments() {
    let mesh = obj::read(file("obj-trailing-comments", "square.obj")).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.indices.len(), 2);
    assert!((mesh.area() - 1.0).abs() < 1e-12);
    assert_eq!(mesh.objects.len(), 1);
    assert_eq!(mesh.objects[0].name, "square");
}

/// `map_Kd test texture.png`: the file name has a space, and that file
/// exists.
#[test]
fn mtl_texture_name_with_a_space() {
    let path = file("mtl-map-kd-with-space", "plane.obj");
    let mesh = obj::read(&path).unwrap();
    let texture = mesh.materials[0].diffuse_texture.clone().unwrap();
    assert_eq!(texture.file_name().unwrap(), "test texture.png");
    assert!(texture.is_file(), "{}", texture.display());
    let image = trilux_io::image::read(&texture).unwrap();
    assert!(image.width > 0);
}

/// `.ele` attributes 1 and 1.5: reals, kept; no integer region tags.
#[test]
fn tetgen_real_attributes_are_kept() {
    let mesh = TetMesh::read(file("tetgen-real-attribute", "mesh.node")).unwrap();
    assert_eq!(mesh.positions.len(), 5);
    assert_eq!(mesh.tets.len(), 2);
    assert!((mesh.volume() - 0.5).abs() < 1e-12);
    assert_eq!(mesh.attributes, vec![vec![1.0, 1.5]]);
    assert!(mesh.regions.is_empty(), "1.5 is not a region tag");
}

/// A georeferenced scan: millimetre triangles at x ≈ 4·10^5, y ≈ 4.6·10^6,
/// where `f32` steps are 1/32 and 1/2. Read with the shift, their areas
/// and shapes survive; without it they would collapse.
#[test]
fn far_from_origin_coordinates_keep_their_triangles() {
    let dir = support::scratch("georeferenced");
    let base = DVec3::new(412_345.678, 4_612_345.125, 231.5);
    let mut text = String::new();
    let mut expected_area = 0.0;
    for k in 0..10 {
        let o = base + DVec3::new(0.01 * k as f64, 0.003 * k as f64, 0.0);
        for p in [
            o,
            o + DVec3::new(0.002, 0.0, 0.0),
            o + DVec3::new(0.0, 0.001, 0.0),
        ] {
            text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
        }
        text.push_str(&format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3));
        expected_area += 0.5 * 0.002 * 0.001;
    }
    let path = support::write(&dir, "scan.obj", text.as_bytes());
    let mesh = TriMesh::read(&path).unwrap();
    assert_ne!(mesh.origin, DVec3::ZERO);
    assert!((mesh.area() - expected_area).abs() < 1e-6 * expected_area);
    let absolute = mesh.absolute_positions();
    assert!(
        (absolute[0] - base).abs().max_element() < 1e-6,
        "{}",
        absolute[0]
    );

    // Through PLY (double coordinates) and OBJ again: the same points.
    let copy = dir.join("scan.ply");
    mesh.write(&copy).unwrap();
    let back = TriMesh::read(&copy).unwrap();
    let back_abs = back.absolute_positions();
    for (a, b) in absolute.iter().zip(&back_abs) {
        assert!((*a - *b).abs().max_element() < 1e-6);
    }
    let copy = dir.join("scan-copy.obj");
    back.write(&copy).unwrap();
    let again = TriMesh::read(&copy).unwrap();
    assert!((again.area() - expected_area).abs() < 1e-6 * expected_area);

    // Ordinary files keep a zero origin.
    let plain = obj::from_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "t.obj").unwrap();
    assert_eq!(plain.origin, DVec3::ZERO);
}

/// KHR_mesh_quantization: `UNSIGNED_SHORT` positions, node scale 0.001.
#[test]
fn gltf_quantized_positions() {
    let mesh = TriMesh::read(file("gltf-quantized-positions", "quantized.gltf")).unwrap();
    assert_eq!(mesh.positions.len(), 3);
    assert!((mesh.area() - 0.5).abs() < 1e-6, "{}", mesh.area());
    assert!(close(mesh.positions[1], Vec3::X), "{}", mesh.positions[1]);
}

/// A POSITION accessor whose sparse block moves 2 vertices.
#[test]
fn gltf_sparse_accessor() {
    let mesh = TriMesh::read(file("gltf-sparse-accessor", "sparse.gltf")).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.positions[2], Vec3::new(1.0, 2.0, 0.0));
    assert!((mesh.area() - 2.0).abs() < 1e-6, "{}", mesh.area());
}
