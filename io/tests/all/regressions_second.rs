//! The second set of inputs earlier versions read wrongly (the files are
//! in `tests/regressions/`, one folder per fault; the right values are
//! those of `../shared/regressions/README.md`, "Second set"), with sibling
//! inputs of each class.

use crate::support;

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use trilux_io::mesh::{TriMesh, obj, ply};
use trilux_io::tet::TetMesh;

fn file(folder: &str, name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions")
        .join(folder)
        .join(name)
}

/// Twice the signed area of triangle `t` seen from +z.
fn signed_area2(mesh: &TriMesh, t: usize) -> f32 {
    let [a, b, c] = mesh.indices[t].map(|i| mesh.positions[i as usize]);
    (b - a).cross(c - a).z
}

fn warnings_text(mesh: &TriMesh) -> String {
    mesh.warnings
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// `element tristrips` `0 1 2 3 4 5 -1 6 7 8 9`: six triangles by the
/// OpenGL strip rule, all counter-clockwise from +z.
#[test]
fn ply_triangle_strips() {
    let mesh = TriMesh::read(file("ply-tristrips", "strips.ply")).unwrap();
    assert_eq!(mesh.positions.len(), 10);
    assert_eq!(mesh.indices.len(), 6);
    assert!((mesh.area() - 3.0).abs() < 1e-6, "{}", mesh.area());
    let signed: f32 = (0..6).map(|t| signed_area2(&mesh, t)).sum::<f32>() / 2.0;
    assert!((signed - 3.0).abs() < 1e-6, "{signed}");
    assert!((0..6).all(|t| signed_area2(&mesh, t) > 0.0));
    let first = mesh.indices[0].map(|i| mesh.positions[i as usize]);
    assert_eq!(
        first,
        [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::ZERO,
            Vec3::new(1.0, 1.0, 0.0)
        ]
    );
    assert!(mesh.warnings.is_empty(), "{}", warnings_text(&mesh));
}

/// Siblings of the strip class: ASCII, big-endian, a degenerate joint,
/// strips and faces in one file, and an element nobody reads (warned).
#[test]
fn ply_strip_siblings() {
    let header = |format: &str, extra: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex 5\nproperty float x\nproperty float y\n\
             property float z\nelement tristrips 1\nproperty list int int vertex_indices\n{extra}\
             end_header\n"
        )
    };
    let points = [
        [0.0f32, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
        [1.0, 1.0],
        [0.0, 2.0],
    ];
    let mut ascii = header(
        "ascii",
        "element edge 1\nproperty int vertex1\nproperty int vertex2\n",
    );
    for p in points {
        ascii.push_str(&format!("{} {} 0\n", p[0], p[1]));
    }
    // 0 1 2 3 3 4: the repeated 3 makes two degenerate triangles, dropped.
    ascii.push_str("7 0 1 2 3 3 2 4\n0 1\n");
    let mesh = ply::from_bytes(ascii.as_bytes(), "strips.ply").unwrap();
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [2, 1, 3], [3, 2, 4]]);
    assert_eq!(mesh.warnings.len(), 1);
    let warning = mesh.warnings[0].to_string();
    assert!(
        warning.contains("strips.ply") && warning.contains("`edge`"),
        "{warning}"
    );

    let mut be = header("binary_big_endian", "").into_bytes();
    for p in points {
        for v in [p[0], p[1], 0.0] {
            be.extend_from_slice(&v.to_be_bytes());
        }
    }
    be.extend_from_slice(&6i32.to_be_bytes());
    for i in [0i32, 1, 2, -1, 2, 3] {
        be.extend_from_slice(&i.to_be_bytes());
    }
    let mesh = ply::from_bytes(&be, "strips_be.ply").unwrap();
    assert_eq!(
        mesh.triangles,
        vec![[0, 1, 2]],
        "a 2-vertex strip has no triangle"
    );

    // An index past the vertices is named with what it indexes.
    let bad = ascii.replace("7 0 1 2 3 3 2 4", "3 0 1 9");
    let e = ply::from_bytes(bad.as_bytes(), "bad.ply")
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertex 9") && e.contains("5 vertices"), "{e}");
}

/// MeshLab's per-corner UVs (`property list uchar float texcoord`) and
/// `comment TextureFile`: vertices split per corner, the texture named.
#[test]
fn ply_per_corner_texcoords_and_texture_file() {
    let dir = support::scratch("ply-texcoord");
    std::fs::write(
        dir.join("wood.png"),
        std::fs::read(file("mtl-keyword-case", "wood.png")).unwrap(),
    )
    .unwrap();
    let text = "ply\nformat ascii 1.0\ncomment TextureFile wood.png\nelement vertex 4\n\
                property float x\nproperty float y\nproperty float z\nelement face 2\n\
                property list uchar int vertex_indices\nproperty list uchar float texcoord\n\
                end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
                3 0 1 2 6 0 0 1 0 1 1\n3 0 2 3 6 0.5 0.5 1 1 0 1\n";
    let path = support::write(&dir, "quad.ply", text.as_bytes());
    let mesh = TriMesh::read(&path).unwrap();
    // Vertex 0 has two UVs, vertex 2 the same one twice: 5 vertices.
    assert_eq!(mesh.indices.len(), 2);
    assert_eq!(mesh.positions.len(), 5);
    let uvs = mesh.uvs.as_ref().unwrap();
    let corner_uv = |t: usize, k: usize| uvs[mesh.indices[t][k] as usize];
    // v flipped to TriMesh's v-down convention.
    assert_eq!(corner_uv(0, 0), Vec2::new(0.0, 1.0));
    assert_eq!(corner_uv(0, 2), Vec2::new(1.0, 0.0));
    assert_eq!(corner_uv(1, 0), Vec2::new(0.5, 0.5));
    assert_eq!(corner_uv(1, 2), Vec2::new(0.0, 0.0));
    assert!((mesh.area() - 1.0).abs() < 1e-6);
    let texture = mesh.materials[0].diffuse_texture.clone().unwrap();
    assert_eq!(texture, dir.join("wood.png"));
    assert_eq!(mesh.objects[0].material, Some(0));
    assert!(mesh.warnings.is_empty(), "{}", warnings_text(&mesh));

    // A TextureFile that does not exist: the mesh, and a warning.
    std::fs::remove_file(dir.join("wood.png")).unwrap();
    let mesh = TriMesh::read(&path).unwrap();
    assert_eq!(mesh.indices.len(), 2);
    assert_eq!(
        mesh.materials[0].diffuse_texture,
        Some(dir.join("wood.png"))
    );
    assert!(
        warnings_text(&mesh).contains("wood.png"),
        "{}",
        warnings_text(&mesh)
    );

    // A texcoord list of the wrong length is an error naming the face.
    let bad = text.replace("6 0.5 0.5 1 1 0 1", "4 0.5 0.5 1 1");
    let e = ply::from_bytes(bad.as_bytes(), "bad.ply")
        .unwrap_err()
        .to_string();
    assert!(e.contains("face 1"), "{e}");
}

/// Face properties the reader does not read are named in a warning; the
/// big-endian polygon file of the second set keeps reading.
#[test]
fn ply_big_endian_polygons_keep_passing() {
    let mesh = TriMesh::read(file("ply-big-endian-polygons", "polygons_be.ply")).unwrap();
    assert_eq!(mesh.positions.len(), 7);
    assert_eq!(mesh.indices.len(), 5);
    assert!((mesh.area() - 2.25).abs() < 1e-6);
    assert_eq!(mesh.positions[6], Vec3::new(1.5, 1.5, 0.0));
    let text = warnings_text(&mesh);
    assert!(text.contains("element `face`"), "{text}");
}

/// `f v/vt/vn` corners in a file without `vt` lines: the geometry, the
/// UV indices dropped with a warning.
#[test]
fn obj_face_texcoords_without_vt_lines() {
    let path = file("obj-face-vt-without-vt", "square.obj");
    let mesh = obj::read(&path).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert_eq!(mesh.indices.len(), 2);
    assert!((mesh.area() - 1.0).abs() < 1e-12);
    assert_eq!(mesh.uvs, None);
    assert!(mesh.normals.is_some());
    assert_eq!(mesh.warnings.len(), 1);
    let w = mesh.warnings[0].to_string();
    assert!(
        w.contains("square.obj") && w.contains("line 7") && w.contains("`vt`"),
        "{w}"
    );

    // Siblings: `f v//vn` without `vn` lines, and an index past the `vt`
    // lines there are, which is an error naming what is indexed.
    let mesh = obj::from_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", "n.obj").unwrap();
    assert_eq!((mesh.indices.len(), mesh.normals.is_none()), (1, true));
    assert!(mesh.warnings[0].message.contains("`vn`"));
    let e = obj::from_bytes(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/4 3/1\n",
        "t.obj",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("texture coordinate 4 of face 0, but the file has 1 `vt` lines"),
        "{e}"
    );
    let e = obj::from_bytes(b"v 0 0 0\nf 1 2 3\n", "v.obj")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("vertex 2 of face 0, but the file has 1 `v` lines"),
        "{e}"
    );
}

/// `map_kd` and `Map_Kd`: MTL keywords compared ignoring case.
#[test]
fn mtl_keywords_ignore_case() {
    let mesh = obj::read(file("mtl-keyword-case", "two_planes.obj")).unwrap();
    let texture = |name: &str| {
        let m = mesh.materials.iter().find(|m| m.name == name).unwrap();
        m.diffuse_texture
            .as_ref()
            .unwrap()
            .file_name()
            .unwrap()
            .to_owned()
    };
    assert_eq!(texture("lower"), "wood.png");
    assert_eq!(texture("capital"), "stone.png");
    assert!(mesh.warnings.is_empty(), "{}", warnings_text(&mesh));
}

/// Siblings of the side-file class: a missing `.mtl`, a missing texture,
/// `usemtl` of a material no library defines, unknown MTL statements:
/// the mesh is read and each is a warning naming the file and the line.
#[test]
fn obj_side_files_never_refuse_the_mesh() {
    let dir = support::scratch("obj-side-files");
    let obj_text = b"mtllib missing.mtl\nmtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n\
                     usemtl known\nf 1/1 2/1 3/1\nusemtl ghost\nf 1/1 3/1 2/1\n";
    let path = support::write(&dir, "m.obj", obj_text);
    support::write(
        &dir,
        "lib.mtl",
        b"NEWMTL known\nKD 0.5 0.25 1\nMAP_KD gone.png\nillum 2\nweird 1 2\nodd\n",
    );
    let mesh = obj::read(&path).unwrap();
    assert_eq!(mesh.indices.len(), 2);
    let known = &mesh.materials[0];
    assert_eq!(
        (known.name.as_str(), known.diffuse),
        ("known", [0.5, 0.25, 1.0])
    );
    assert_eq!(known.diffuse_texture, Some(dir.join("gone.png")));
    let text = warnings_text(&mesh);
    assert_eq!(mesh.warnings.len(), 4, "{text}");
    assert!(
        text.contains("missing.mtl") && text.contains("line 1"),
        "{text}"
    );
    assert!(
        text.contains("gone.png") && text.contains("\"known\""),
        "{text}"
    );
    assert!(
        text.contains("\"ghost\"") && text.contains("line 9"),
        "{text}"
    );
    assert!(
        text.contains("2 statement(s)") && text.contains("`weird`"),
        "{text}"
    );
}

/// A glTF texture whose only image is in `KHR_texture_basisu`: the
/// triangle with its UVs and material, and a warning naming the texture
/// and the extension; the PNG fallback is decoded.
#[test]
fn gltf_texture_without_source() {
    let mesh = TriMesh::read(file("gltf-texture-without-source", "basisu_only.gltf")).unwrap();
    assert_eq!(mesh.positions.len(), 3);
    assert!((mesh.area() - 0.5).abs() < 1e-6);
    assert!(mesh.uvs.is_some());
    assert_eq!(mesh.materials[0].name, "albedo");
    assert!(mesh.materials[0].diffuse_image.is_none());
    let text = warnings_text(&mesh);
    assert!(
        text.contains("texture 0") && text.contains("KHR_texture_basisu"),
        "{text}"
    );
    let mesh = TriMesh::read(file(
        "gltf-texture-without-source",
        "basisu_with_png_fallback.gltf",
    ))
    .unwrap();
    assert!(mesh.materials[0].diffuse_image.is_some());
    assert!(mesh.warnings.is_empty(), "{}", warnings_text(&mesh));
}

/// Keep passing: relative OBJ indices with `l` and `p`; glTF strips and
/// fans with interleaved attributes.
#[test]
fn second_set_controls_keep_passing() {
    let mesh = obj::read(file("obj-negative-indices", "blocks.obj")).unwrap();
    assert_eq!((mesh.positions.len(), mesh.indices.len()), (12, 6));
    assert!((mesh.area() - 8.0).abs() < 1e-6);
    let names: Vec<&str> = mesh.objects.iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, ["first", "second", "third"]);

    let mesh = TriMesh::read(file("gltf-strip-fan-interleaved", "modes.gltf")).unwrap();
    assert_eq!((mesh.positions.len(), mesh.indices.len()), (9, 5));
    assert!((mesh.area() - 3.5).abs() < 1e-6);
    assert!((0..5).all(|t| signed_area2(&mesh, t) > 0.0));
    assert!(mesh.normals.unwrap().iter().all(|&n| n == Vec3::Z));
}

/// Keep passing: a Gmsh mesh with an inverted tetrahedron, and one with a
/// flat tetrahedron.
#[test]
fn gmsh_inverted_and_flat_keep_passing() {
    let mesh = TetMesh::read(file("tet-inverted-and-flat", "inverted.msh")).unwrap();
    assert!((mesh.volume() - 0.5).abs() < 1e-12);
    let inverted = (0..mesh.tets.len())
        .filter(|&t| mesh.signed_volume6(t) < 0.0)
        .count();
    assert_eq!(inverted, 1);
    let boundary = mesh.boundary();
    assert_eq!(boundary.len(), 6);
    assert!((trilux_io::tet::enclosed_volume(&mesh.positions, &boundary) - 0.5).abs() < 1e-12);
    let flat = TetMesh::read(file("tet-inverted-and-flat", "with_flat_tet.msh")).unwrap();
    assert!((0..flat.tets.len()).any(|t| flat.signed_volume6(t) == 0.0));
}
