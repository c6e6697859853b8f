//! Triangle meshes: the real OBJ files of `$TRILUX_DATA/meshes` with the
//! counts of the data README, hand-written files for every OBJ feature,
//! malformed files, and round trips.

use crate::support;

use std::path::Path;

use support::{data_dir, scratch, write};

use glam::{Vec2, Vec3};
use trilux_io::mesh::{TriMesh, obj};
use trilux_io::{ErrorKind, Location};

/// file, triangles, vertices after splitting (None: only the upper bound
/// given by the `v` lines), that upper bound, has UVs, has normals.
type RealObj = (&'static str, usize, Option<usize>, usize, bool, bool);

/// A malformed file: name, bytes, the error kind it must give, the line.
type BadObj = (&'static str, &'static [u8], fn(&ErrorKind) -> bool, usize);

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_obj_files_match_the_data_readme() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    let expected: [RealObj; 6] = [
        (
            "stanford-bunny.obj",
            69_451,
            Some(34_834),
            35_947,
            false,
            false,
        ),
        ("spot.obj", 5_856, Some(3_225), 3_225, true, false),
        ("teapot.obj", 6_320, None, 3_644, false, false),
        ("fandisk.obj", 12_946, Some(6_475), 6_475, false, false),
        ("suzanne.obj", 968, None, 507, false, true),
        ("nefertiti.obj", 99_938, Some(49_971), 49_971, false, false),
    ];
    for (file, tris, verts, max_verts, uv, normal) in expected {
        let mesh = TriMesh::read(data.join("meshes").join(file)).unwrap();
        assert_eq!(mesh.indices.len(), tris, "{file}");
        if let Some(v) = verts {
            assert_eq!(mesh.positions.len(), v, "{file}");
        }
        assert!(mesh.positions.len() <= max_verts, "{file}");
        assert_eq!(mesh.uvs.is_some(), uv, "{file}");
        assert_eq!(mesh.normals.is_some(), normal, "{file}");
        assert!(mesh.area() > 0.0, "{file}");
        // Every vertex is used (unused `v` lines are dropped).
        let mut used = vec![false; mesh.positions.len()];
        mesh.indices
            .iter()
            .flatten()
            .for_each(|&i| used[i as usize] = true);
        assert!(used.iter().all(|&u| u), "{file}");
        if file == "spot.obj" {
            let uvs = mesh.uvs.as_ref().unwrap();
            let min_u = uvs.iter().map(|t| t.x).fold(f32::INFINITY, f32::min);
            assert!(
                (min_u + 0.052).abs() < 1e-3,
                "spot keeps its UVs outside [0, 1]: {min_u}"
            );
        }
    }
}

const FEATURES: &[u8] = b"# every feature\nmtllib parts.mtl\n\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 9 9 9\n\
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
o quad\nusemtl red\nf 1/1/1 2/2/1 3/3/1 4/4/1\n\
g tri \\\n  continued\nusemtl blue\nf -5/-4/-1 -3/-2/-1 -2/-1/-1\ns off\nl 1 2\n";

const MTL: &[u8] =
    b"newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\nmap_Kd -s 1 1 1 textures/blue.png\n";

#[test]
fn every_obj_feature() {
    let dir = scratch("features");
    write(&dir, "parts.mtl", MTL);
    let mesh = obj::read(write(&dir, "m.obj", FEATURES)).unwrap();
    // The quad fans into two triangles; the last face reuses corners with
    // the same v/vt/vn, so only 4 vertices exist and v 9 9 9 is unused.
    assert_eq!(mesh.indices, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
    assert_eq!(mesh.positions.len(), 4);
    // `vt 1 1` (v up) is the top-right corner: v = 0 in TriMesh's v-down
    // convention, and `vt 1 0` the bottom right.
    assert_eq!(mesh.uvs.as_ref().unwrap()[2], Vec2::new(1.0, 0.0));
    assert_eq!(mesh.uvs.as_ref().unwrap()[1], Vec2::new(1.0, 1.0));
    assert_eq!(mesh.normals.as_ref().unwrap()[0], Vec3::Z);
    let names: Vec<_> = mesh
        .objects
        .iter()
        .map(|o| (o.name.as_str(), o.triangles.clone(), o.material))
        .collect();
    assert_eq!(
        names,
        vec![("quad", 0..2, Some(0)), ("tri continued", 2..3, Some(1))]
    );
    assert_eq!(mesh.materials[0].diffuse, [1.0, 0.0, 0.0]);
    assert_eq!(mesh.materials[1].name, "blue");
    assert_eq!(
        mesh.materials[1].diffuse_texture.as_deref(),
        Some(dir.join("textures/blue.png").as_path())
    );
    // Without the files, materials are names with the MTL defaults.
    let bare = obj::from_bytes(FEATURES, Path::new("m.obj")).unwrap();
    assert_eq!(bare.materials[0].diffuse, [0.8, 0.8, 0.8]);
}

#[test]
fn obj_round_trip() {
    let dir = scratch("roundtrip");
    let mesh = obj::read(&{
        write(&dir, "parts.mtl", MTL);
        write(&dir, "m.obj", FEATURES)
    })
    .unwrap();
    let copy = dir.join("copy.obj");
    obj::write(&copy, &mesh).unwrap();
    let back = obj::read(&copy).unwrap();
    assert_eq!(back.positions, mesh.positions);
    assert_eq!(back.uvs, mesh.uvs);
    assert_eq!(back.normals, mesh.normals);
    assert_eq!(back.indices, mesh.indices);
    assert_eq!(
        back.objects
            .iter()
            .map(|o| o.triangles.clone())
            .collect::<Vec<_>>(),
        vec![0..2, 2..3]
    );
}

#[test]
fn malformed_obj_files_name_the_line() {
    let dir = scratch("malformed");
    let cases: [BadObj; 8] = [
        (
            "nan",
            b"v 0 0 0\nv nan 0 0\n",
            |k| matches!(k, ErrorKind::NonFinite { index: 1, .. }),
            2,
        ),
        (
            "inf",
            b"v 0 0 inf\n",
            |k| matches!(k, ErrorKind::NonFinite { index: 0, .. }),
            1,
        ),
        (
            "two-corners",
            b"v 0 0 0\nv 1 0 0\nf 1 2\n",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            3,
        ),
        (
            "out-of-range",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
            |k| {
                matches!(k, ErrorKind::ReferenceOutOfRange(r)
                    if r.what == "vertex" && r.reference == 4 && r.count == 3)
            },
            4,
        ),
        (
            "zero-index",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            |k| matches!(k, ErrorKind::ReferenceOutOfRange(r) if r.reference == 0),
            4,
        ),
        (
            "bad-number",
            b"v 0 0 0,5\n",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            1,
        ),
        (
            "short-vertex",
            b"# c\nv 0 0\n",
            |k| matches!(k, ErrorKind::Truncated(_)),
            2,
        ),
        (
            "keyword",
            b"v 0 0 0\nvertex 1 2 3\n",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            2,
        ),
    ];
    for (name, bytes, kind_ok, line) in cases {
        let err = obj::read(write(&dir, &format!("{name}.obj"), bytes)).unwrap_err();
        assert!(kind_ok(&err.kind), "{name}: {err}");
        assert_eq!(err.location, Some(Location::Line(line)), "{name}: {err}");
    }
    // A missing material library leaves the mesh intact: a warning.
    let mesh = obj::read(write(&dir, "lib.obj", b"mtllib gone.mtl\nv 0 0 0\n")).unwrap();
    assert_eq!(mesh.warnings.len(), 1);
    let warning = mesh.warnings[0].to_string();
    assert!(
        warning.contains("gone.mtl") && warning.contains("line 1"),
        "{warning}"
    );
    let err = TriMesh::read("mesh.stl").unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)));
}

#[test]
fn obj_writer_refuses_inconsistent_meshes() {
    let dir = scratch("write-errors");
    let mut mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 3]],
        ..TriMesh::default()
    };
    let err = obj::write(dir.join("a.obj"), &mesh).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::InvalidInput(_)), "{err}");
    mesh.indices = vec![[0, 1, 2]];
    mesh.uvs = Some(vec![Vec2::ZERO]);
    assert!(obj::write(dir.join("b.obj"), &mesh).is_err());
}

use trilux_io::mesh::ply::{self, Format, PlyData};

fn sample_ply() -> PlyData {
    PlyData {
        positions: vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.5, 0.0, 0.0),
            Vec3::new(0.0, 1.0, -2.0),
        ],
        triangles: vec![[0, 1, 2]],
        normals: Some(vec![Vec3::Z; 3]),
        colors: Some(vec![[255, 0, 0, 255], [0, 255, 0, 128], [0, 0, 255, 0]]),
        uvs: Some(vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.25, 1.0),
        ]),
        scalars: vec![("quality".to_string(), vec![0.5, 1.0, -3.0])],
        ..PlyData::default()
    }
}

#[test]
fn ply_binary_header_and_layout_follow_the_spec() {
    let bytes = ply::to_bytes(
        Path::new("t.ply"),
        &sample_ply(),
        Format::BinaryLittleEndian,
    )
    .unwrap();
    let header = "ply\nformat binary_little_endian 1.0\ncomment written by trilux-io\n\
element vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float ny\nproperty float nz\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n\
property float s\nproperty float t\nproperty float quality\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    assert!(bytes.starts_with(header.as_bytes()));
    let body = &bytes[header.len()..];
    // Vertex: 3 + 3 floats, 4 uchar, 2 + 1 floats = 40 bytes; face: 1 + 3·4.
    assert_eq!(body.len(), 3 * 40 + 13);
    let f32_at = |o: usize| f32::from_le_bytes(body[o..o + 4].try_into().unwrap());
    assert_eq!(f32_at(40), 1.5); // x of vertex 1
    assert_eq!(f32_at(2 * 40 + 8), -2.0); // z of vertex 2
    assert_eq!(&body[40 + 24..40 + 28], &[0, 255, 0, 128]); // rgba of vertex 1
    assert_eq!(f32_at(2 * 40 + 28), 0.25); // s of vertex 2
    assert_eq!(f32_at(2 * 40 + 36), -3.0); // quality of vertex 2
    assert_eq!(body[120], 3);
    assert_eq!(i32::from_le_bytes(body[129..133].try_into().unwrap()), 2);
}

#[test]
fn ply_round_trips_in_both_formats() {
    let dir = scratch("ply");
    for format in [Format::Ascii, Format::BinaryLittleEndian] {
        let path = dir.join(format!("{format:?}.ply"));
        ply::write(&path, &sample_ply(), format).unwrap();
        assert_eq!(ply::read(&path).unwrap(), sample_ply(), "{format:?}");
    }
    let cloud = PlyData {
        positions: vec![Vec3::ONE, Vec3::NEG_ONE],
        ..PlyData::default()
    };
    let path = dir.join("cloud.ply");
    ply::write(&path, &cloud, Format::Ascii).unwrap();
    assert_eq!(ply::read(&path).unwrap(), cloud);
}

#[test]
fn ply_reads_other_writers_layouts() {
    // Big-endian doubles, float colours, a quad, a skipped element.
    let mut bytes = b"ply\nformat binary_big_endian 1.0\nobj_info made by hand\n\
element vertex 4\nproperty double x\nproperty double y\nproperty double z\n\
property float red\nproperty float green\nproperty float blue\nproperty ushort flags\n\
element material 1\nproperty list uint uchar name\n\
element face 1\nproperty uchar tag\nproperty list uchar uint vertex_index\nend_header\n"
        .to_vec();
    for (i, p) in [
        [0.0f64, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ]
    .iter()
    .enumerate()
    {
        for x in p {
            bytes.extend_from_slice(&x.to_be_bytes());
        }
        for c in [1.0f32, 0.5, 0.0] {
            bytes.extend_from_slice(&c.to_be_bytes());
        }
        bytes.extend_from_slice(&(i as u16).to_be_bytes());
    }
    bytes.extend_from_slice(&2u32.to_be_bytes());
    bytes.extend_from_slice(b"ab");
    bytes.push(7);
    bytes.push(4);
    for i in [0u32, 1, 2, 3] {
        bytes.extend_from_slice(&i.to_be_bytes());
    }
    let data = ply::from_bytes(&bytes, Path::new("be.ply")).unwrap();
    assert_eq!(data.positions[2], Vec3::new(1.0, 1.0, 0.0));
    assert_eq!(data.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(data.colors.as_ref().unwrap()[0], [255, 128, 0, 255]);
    assert_eq!(
        data.scalars,
        vec![("flags".to_string(), vec![0.0, 1.0, 2.0, 3.0])]
    );

    let ascii = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
property float z\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0\n1 0 0\n0 1 0\n0 1\n3 0 1 2\n";
    let data = ply::from_bytes(ascii, Path::new("a.ply")).unwrap();
    assert_eq!(data.triangles, vec![[0, 1, 2]]);
}

#[test]
fn malformed_ply_files() {
    type KindCheck = fn(&ErrorKind) -> bool;
    let head = "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n";
    let cases: Vec<(String, KindCheck)> = vec![
        ("plx\n".into(), |k| matches!(k, ErrorKind::Syntax { .. })),
        (format!("{head}end_header\n0.0 0.0 0.0\n1.0 1.0"), |k| {
            matches!(k, ErrorKind::Truncated(_))
        }),
        (format!("{head}end_header\n0 0 0\nnan 1 1\n"), |k| {
            matches!(k, ErrorKind::NonFinite { index: 1, .. })
        }),
        (
            format!(
                "{head}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1 1\n3 0 1 5\n"
            ),
            |k| matches!(k, ErrorKind::ReferenceOutOfRange(r) if r.reference == 5),
        ),
        (
            format!(
                "{head}element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 1 1\n2 0 1\n"
            ),
            |k| matches!(k, ErrorKind::Syntax { .. }),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nend_header\n1\n".into(),
            |k| matches!(k, ErrorKind::Syntax { .. }),
        ),
        (
            "ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty float x\nend_header\n1\n"
                .into(),
            |k| matches!(k, ErrorKind::CountTooLarge { .. }),
        ),
        (
            "ply\nformat ascii 1.0\nproperty float x\nend_header\n".into(),
            |k| matches!(k, ErrorKind::Syntax { .. }),
        ),
        ("ply\nformat ascii 2.0\n".into(), |k| {
            matches!(k, ErrorKind::Syntax { .. })
        }),
    ];
    for (text, kind_ok) in cases {
        let err = ply::from_bytes(text.as_bytes(), Path::new("bad.ply")).unwrap_err();
        assert!(kind_ok(&err.kind), "{text:?}: {err}");
        assert!(err.to_string().starts_with("bad.ply"), "{err}");
    }
    let mut wrong = sample_ply();
    wrong.uvs = Some(vec![Vec2::ZERO]);
    let err = ply::to_bytes(Path::new("w.ply"), &wrong, Format::Ascii).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::InvalidInput(_)), "{err}");
}

/// TriMesh's UVs are v-down (glTF); OBJ and PLY store v up. A triangle
/// whose first corner is the image's top-left corner in the file's
/// convention (`vt 0 1`) must come out at uv (0, 0), and both writers must
/// restore the file's values.
#[test]
fn obj_and_ply_uvs_are_flipped_to_v_down_once() {
    let dir = scratch("uv-convention");
    let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 1\nvt 1 1\nvt 0.25 0.75\nf 1/1 2/2 3/3\n";
    let mesh = obj::read(write(&dir, "uv.obj", text)).unwrap();
    let expected = vec![
        Vec2::new(0.0, 0.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.25, 0.25),
    ];
    assert_eq!(mesh.uvs.as_ref().unwrap(), &expected);
    let copy = dir.join("copy.obj");
    obj::write(&copy, &mesh).unwrap();
    let written = std::fs::read_to_string(&copy).unwrap();
    assert!(written.contains("vt 0 1\n") && written.contains("vt 0.25 0.75\n"));
    assert_eq!(obj::read(&copy).unwrap().uvs.unwrap(), expected);

    let ply_text = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nproperty float s\nproperty float t\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0 0 1\n1 0 0 1 1\n0 1 0 0.25 0.75\n3 0 1 2\n";
    let data = ply::from_bytes(ply_text, Path::new("uv.ply")).unwrap();
    assert_eq!(data.uvs.as_ref().unwrap(), &expected);
    let bytes = ply::to_bytes(Path::new("uv.ply"), &data, Format::Ascii).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    assert!(
        text.contains("0 0 0 0 1\n") && text.contains("0 1 0 0.25 0.75\n"),
        "{text}"
    );
}

/// `obj::write` keeps materials: `mtllib`, `usemtl`, the `.mtl` with `Kd`
/// and `map_Kd` (a clamped texture stays clamped), and decoded textures
/// without a file are written beside the OBJ. Reading it back gives the
/// same materials and objects.
#[test]
fn obj_written_with_materials_reads_back_with_them() {
    use trilux_io::image::Image;
    use trilux_io::mesh::{Material, Object, Wrap};
    let dir = scratch("materials");
    let texture = dir.join("wood grain.png");
    let pixels = Image {
        width: 2,
        height: 2,
        pixels: vec![[1.0, 0.5, 0.25, 1.0]; 4],
    };
    trilux_io::image::write_png(&texture, &pixels, trilux_io::image::PngDepth::Eight).unwrap();
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE],
        indices: vec![[0, 1, 2], [1, 3, 2]],
        uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE]),
        objects: vec![
            Object {
                name: "left half".into(),
                triangles: 0..1,
                material: Some(0),
            },
            Object {
                name: "right".into(),
                triangles: 1..2,
                material: Some(1),
            },
        ],
        materials: vec![
            Material {
                name: "wood".into(),
                diffuse: [1.0, 0.5, 0.25],
                diffuse_texture: Some(texture.clone()),
                diffuse_image: None,
                wrap: [Wrap::ClampToEdge; 2],
                scalar_images: Vec::new(),
            },
            Material {
                name: String::new(),
                diffuse: [0.0, 0.0, 1.0],
                diffuse_texture: None,
                diffuse_image: Some(pixels.clone()),
                wrap: [Wrap::Repeat; 2],
                scalar_images: Vec::new(),
            },
        ],
        ..TriMesh::default()
    };
    let path = dir.join("out.obj");
    mesh.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("mtllib out.mtl\n"), "{text}");
    assert!(text.contains("usemtl wood\n") && text.contains("usemtl material_1\n"));
    let mtl = std::fs::read_to_string(dir.join("out.mtl")).unwrap();
    assert!(mtl.contains("map_Kd -clamp on wood grain.png\n"), "{mtl}");
    assert!(mtl.contains("map_Kd out_1.png\n"), "{mtl}");

    let back = obj::read(&path).unwrap();
    assert_eq!(back.materials.len(), 2);
    assert_eq!(back.materials[0].name, "wood");
    assert_eq!(back.materials[0].diffuse, [1.0, 0.5, 0.25]);
    assert_eq!(
        back.materials[0].diffuse_texture.as_deref(),
        Some(texture.as_path())
    );
    assert_eq!(back.materials[0].wrap, [Wrap::ClampToEdge; 2]);
    assert_eq!(back.materials[1].name, "material_1");
    let written = back.materials[1].diffuse_texture.clone().unwrap();
    assert_eq!(trilux_io::image::read(&written).unwrap().width, 2);
    let objects: Vec<_> = back
        .objects
        .iter()
        .map(|o| (o.name.as_str(), o.triangles.clone(), o.material))
        .collect();
    assert_eq!(
        objects,
        vec![("left half", 0..1, Some(0)), ("right", 1..2, Some(1))]
    );
    assert_eq!(back.uvs, mesh.uvs);
    assert_eq!(back.positions, mesh.positions);

    // Through PLY the geometry survives; unknown extensions are refused.
    mesh.write(dir.join("out.ply")).unwrap();
    let ply_back = TriMesh::read(dir.join("out.ply")).unwrap();
    assert_eq!(ply_back.positions, mesh.positions);
    assert_eq!(ply_back.indices, mesh.indices);
    assert_eq!(ply_back.uvs, mesh.uvs);
    let err = mesh.write(dir.join("out.stl")).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)), "{err}");
    let mut bad = mesh.clone();
    bad.materials[0].name = "a # b".into();
    assert!(matches!(
        bad.write(dir.join("bad.obj")).unwrap_err().kind,
        ErrorKind::InvalidInput(_)
    ));
}

/// MTL texture options are parsed, not taken for the file name; names
/// keep their spaces; `-s`/`-o` are applied to the UVs.
#[test]
fn mtl_texture_options() {
    use trilux_io::mesh::Wrap;
    let dir = scratch("mtl-options");
    let obj_text = b"\xEF\xBB\xBFmtllib my lib.mtl\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\n\
vt 0 0\r\nvt 1 0\r\nvt 0 1\r\nusemtl a b\r\nf 1/1 2/2 3/3 # comment\r\n";
    let cases: [(&str, Option<(&str, Wrap)>); 6] = [
        (
            "map_Kd -blendu on -blendv off -bm 0.5 -boost 2 -cc off -clamp on -imfchan l -mm 0 1 -t 0 0 -texres 512 my file.png",
            Some(("my file.png", Wrap::ClampToEdge)),
        ),
        (
            "map_Kd -s 1 1 1 -o 0 0 0 textures/a b.png # trailing",
            Some(("textures/a b.png", Wrap::Repeat)),
        ),
        ("map_Kd -s 1 1 plain.png", Some(("plain.png", Wrap::Repeat))),
        (
            "map_Kd -clamp off -o 0 x.png",
            Some(("x.png", Wrap::Repeat)),
        ),
        (
            "map_Kd -s 2 2 1 scaled.png",
            Some(("scaled.png", Wrap::Repeat)),
        ),
        ("map_Kd -unknown 3 f.png", None),
    ];
    for (k, (line, expected)) in cases.into_iter().enumerate() {
        let sub = dir.join(k.to_string());
        std::fs::create_dir_all(&sub).unwrap();
        write(
            &sub,
            "my lib.mtl",
            format!("newmtl a b\nKd 0 1 0\n{line}\n").as_bytes(),
        );
        let result = obj::read(write(&sub, "m.obj", obj_text));
        match expected {
            Some((file, wrap)) => {
                let mesh = result.unwrap_or_else(|e| panic!("{line}: {e}"));
                let m = &mesh.materials[0];
                assert_eq!(m.name, "a b");
                assert_eq!(m.diffuse, [0.0, 1.0, 0.0]);
                assert_eq!(
                    m.diffuse_texture.as_deref(),
                    Some(sub.join(file).as_path()),
                    "{line}"
                );
                assert_eq!(m.wrap, [wrap; 2], "{line}");
                let uvs = mesh.uvs.unwrap();
                if line.contains("-s 2 2") {
                    // vt (1, 0) and (0, 1), v up, scaled by 2: (2, 0) and
                    // (0, 2), i.e. (2, 1) and (0, -1) v down.
                    assert_eq!(
                        uvs,
                        vec![
                            Vec2::new(0.0, 1.0),
                            Vec2::new(2.0, 1.0),
                            Vec2::new(0.0, -1.0)
                        ]
                    );
                } else {
                    assert_eq!(
                        uvs,
                        vec![Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::ZERO],
                        "{line}"
                    );
                }
            }
            None => {
                let err = result.unwrap_err();
                assert_eq!(err.location, Some(Location::Line(3)), "{line}: {err}");
                assert!(err.path.ends_with("my lib.mtl"), "{err}");
            }
        }
    }
}

/// A vertex shared by a triangle whose texture is shifted (`-o`) and one
/// whose texture is not is split, so each triangle reads its own texels.
#[test]
fn mtl_offsets_split_shared_vertices() {
    let dir = scratch("mtl-offset");
    write(
        &dir,
        "m.mtl",
        b"newmtl plain\nmap_Kd a.png\nnewmtl shifted\nmap_Kd -o 0.5 0.25 b.png\n",
    );
    let text =
        b"mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n\
usemtl plain\nf 1/1 2/2 3/3\nusemtl shifted\nf 2/2 4/4 3/3\n";
    let mesh = obj::read(write(&dir, "m.obj", text)).unwrap();
    // Vertices 1 and 2 (0-based) are shared: split into copies.
    assert_eq!(mesh.positions.len(), 6);
    let uvs = mesh.uvs.as_ref().unwrap();
    let uv_of = |t: usize, c: usize| uvs[mesh.indices[t][c] as usize];
    assert_eq!(
        uv_of(0, 1),
        Vec2::new(1.0, 1.0),
        "plain: vt (1, 0) is v-down (1, 1)"
    );
    // Shifted: vt (1, 0) + (0.5, 0.25) = (1.5, 0.25) v up = (1.5, 0.75) v down.
    assert_eq!(uv_of(1, 0), Vec2::new(1.5, 0.75));
    assert_eq!(mesh.positions[mesh.indices[1][0] as usize], Vec3::X);
    assert!((mesh.area() - 1.0).abs() < 1e-12);
}
