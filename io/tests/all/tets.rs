//! Tetrahedral mesh reading and writing: the real meshes of
//! `$TRILUX_DATA/tets` with the counts of the data README, round trips,
//! hand-written files for each format variant, and malformed files.

use crate::support;

use std::path::Path;

use support::{data_dir, scratch, write};

use trilux_io::tet::{TetMesh, enclosed_volume, gmsh, medit, tetgen, vtu};
use trilux_io::{ErrorKind, Location};

/// A face up to rotation (orientation kept).
fn canonical(f: [u32; 3]) -> [u32; 3] {
    let k = (0..3).min_by_key(|&i| f[i]).unwrap();
    [f[k], f[(k + 1) % 3], f[(k + 2) % 3]]
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_tetgen_meshes_match_the_data_readme() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    // name, nodes, tets, boundary triangles, total volume (data README).
    let expected = [
        ("sphere_20k", 3_626, 19_443, 1_938, 4.15274),
        ("sphere_200k", 38_019, 201_502, 20_480, 4.18652),
        ("bunny_50k", 10_206, 51_369, 7_108, 7.50498e-4),
        ("bunny_500k", 93_375, 507_125, 43_188, 7.54483e-4),
    ];
    for (name, nodes, tets, faces, volume) in expected {
        let files = tetgen::read_all(data.join("tets").join(format!("{name}.node"))).unwrap();
        let mesh = &files.mesh;
        assert_eq!(files.first_index, 1, "{name}");
        assert_eq!(mesh.positions.len(), nodes, "{name}");
        assert_eq!(mesh.tets.len(), tets, "{name}");
        assert!(mesh.regions.is_empty());
        assert!(
            (0..tets).all(|t| mesh.signed_volume6(t) > 0.0),
            "{name}: all positive"
        );
        assert!(
            ((mesh.volume() - volume) / volume).abs() < 1e-5,
            "{name}: volume"
        );

        // The derived boundary is the file's face list, orientation included,
        // and it encloses the tets' volume.
        let boundary = mesh.boundary();
        assert_eq!(boundary.len(), faces, "{name}");
        let mut derived: Vec<_> = boundary.iter().map(|&f| canonical(f)).collect();
        let mut listed: Vec<_> = files.faces.unwrap().iter().map(|&f| canonical(f)).collect();
        derived.sort_unstable();
        listed.sort_unstable();
        assert_eq!(derived, listed, "{name}: boundary vs .face");
        let enclosed = enclosed_volume(&mesh.positions, &boundary);
        assert!(
            ((enclosed - mesh.volume()) / mesh.volume()).abs() < 1e-12,
            "{name}"
        );
    }
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_gmsh_41_equals_the_tetgen_pair() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    let tets = data.join("tets");
    let from_msh = TetMesh::read(tets.join("bunny_500k.msh")).unwrap();
    let from_tetgen = TetMesh::read(tets.join("bunny_500k.ele")).unwrap();
    assert_eq!(from_msh, from_tetgen);
}

#[test]
fn tetgen_round_trip_is_exact() {
    let dir = scratch("roundtrip");
    let mesh = TetMesh {
        positions: vec![
            glam::DVec3::new(0.1, -0.0, 1e-300),
            glam::DVec3::new(1.0 / 3.0, 2.0, -7.25e12),
            glam::DVec3::new(f64::MIN_POSITIVE, 0.5, 0.25),
            glam::DVec3::new(-1.0, 1.0, std::f64::consts::PI),
        ],
        tets: vec![[0, 1, 2, 3], [3, 2, 1, 0]],
        regions: vec![7, -2],
        attributes: vec![vec![7.0, -2.0]],
        warnings: Vec::new(),
    };
    let path = dir.join("m.node");
    tetgen::write(&path, &mesh).unwrap();
    assert_eq!(TetMesh::read(&path).unwrap(), mesh);
    let plain = TetMesh {
        regions: Vec::new(),
        attributes: Vec::new(),
        ..mesh
    };
    tetgen::write(&path, &plain).unwrap();
    assert_eq!(TetMesh::read(dir.join("m.ele")).unwrap(), plain);
}

#[test]
fn tetgen_zero_based_attributes_markers_and_quadratic() {
    let dir = scratch("tetgen-variants");
    write(
        &dir,
        "q.node",
        b"# zero-based, one attribute, markers\n5 3 1 1\n0 0 0 0 9.5 1\n1 1 0 0 9.5 1\n\
          2 0 1 0 9.5 0\n3 0 0 1 9.5 1 # trailing comment\n4 1 1 1 0 0\n",
    );
    write(
        &dir,
        "q.ele",
        b"2 10 2\n0 0 1 2 3 4 4 4 4 4 4 3 0.5\n1 4 1 3 2 0 0 0 0 0 0 -1 0\n",
    );
    let mesh = TetMesh::read(dir.join("q.node")).unwrap();
    assert_eq!(mesh.positions.len(), 5);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3], [4, 1, 3, 2]]);
    assert_eq!(mesh.regions, vec![3, -1]);
    assert_eq!(mesh.boundary().len(), 6);
}

/// One tetrahedron and a triangle, in Gmsh 2.2 ASCII with physical tags and
/// non-contiguous node tags.
const GMSH_22: &[u8] = b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n\
$PhysicalNames\n1\n3 5 \"body\"\n$EndPhysicalNames\n\
$Nodes\n5\n10 0 0 0\n20 1 0 0\n30 0 1 0\n40 0 0 1\n50 1 1 1\n$EndNodes\n\
$Elements\n4\n1 2 2 9 1 10 20 30\n2 4 2 5 1 10 20 30 40\n3 15 2 0 1 50\n\
4 11 2 6 2 50 20 40 30 10 10 10 10 10 10\n$EndElements\n";

#[test]
fn gmsh_22_ascii() {
    let mesh = gmsh_from(GMSH_22);
    assert_eq!(mesh.positions.len(), 5);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3], [4, 1, 3, 2]]);
    assert_eq!(mesh.regions, vec![5, 6]);
}

fn gmsh_from(bytes: &[u8]) -> TetMesh {
    let dir = scratch(&format!("gmsh-{}", bytes.len()));
    gmsh::read(write(&dir, "m.msh", bytes)).unwrap()
}

/// The same mesh as GMSH_22 in the 2.2 binary layout.
fn gmsh_22_binary() -> Vec<u8> {
    let mut b = b"$MeshFormat\n2.2 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n5\n");
    for (tag, p) in [
        (10, [0.0, 0.0, 0.0]),
        (20, [1.0, 0.0, 0.0]),
        (30, [0.0, 1.0, 0.0]),
        (40, [0.0, 0.0, 1.0]),
        (50, [1.0, 1.0, 1.0]),
    ] {
        b.extend_from_slice(&i32::to_le_bytes(tag));
        for x in p {
            b.extend_from_slice(&f64::to_le_bytes(x));
        }
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n4\n");
    let block = |b: &mut Vec<u8>, kind: i32, ints: &[&[i32]], ntags: i32| {
        for x in [kind, ints.len() as i32, ntags] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        for rec in ints {
            for &x in *rec {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
    };
    block(&mut b, 2, &[&[1, 9, 1, 10, 20, 30]], 2);
    block(&mut b, 4, &[&[2, 5, 1, 10, 20, 30, 40]], 2);
    block(&mut b, 15, &[&[3, 0, 1, 50]], 2);
    block(
        &mut b,
        11,
        &[&[4, 6, 2, 50, 20, 40, 30, 10, 10, 10, 10, 10, 10]],
        2,
    );
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

#[test]
fn gmsh_22_binary_equals_ascii() {
    // The same mesh, and the same skipped elements said (from another
    // scratch file).
    let (mut binary, mut ascii) = (gmsh_from(&gmsh_22_binary()), gmsh_from(GMSH_22));
    for w in binary.warnings.iter_mut().chain(ascii.warnings.iter_mut()) {
        w.path = std::path::PathBuf::new();
    }
    assert_eq!(binary, ascii);
    assert_eq!(binary.warnings.len(), 1);
}

#[test]
fn gmsh_41_ascii_with_entities_and_physical_tags() {
    let text = b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
$Entities\n1 0 1 2\n7 0 0 0 0\n3 0 0 0 1 1 1 0 0\n\
1 0 0 0 1 1 1 1 42 1 3\n2 0 0 0 1 1 1 0 1 3\n$EndEntities\n\
$Nodes\n2 5 10 50\n3 1 0 4\n10\n20\n30\n40\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
0 7 0 1\n50\n1 1 1\n$EndNodes\n\
$Elements\n3 3 1 3\n2 3 2 1\n1 10 20 30\n3 1 4 1\n2 10 20 30 40\n3 2 4 1\n3 50 20 40 30\n$EndElements\n";
    let mesh = gmsh_from(text);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3], [4, 1, 3, 2]]);
    assert_eq!(mesh.regions, vec![42, 0]);
}

/// A malformed TetGen pair: name, `.node`, `.ele` (empty: a valid one), the
/// error kind it must give, and the line.
type TetGenCase = (
    &'static str,
    &'static [u8],
    &'static [u8],
    fn(&ErrorKind) -> bool,
    usize,
);

/// A malformed `.msh` file: name, bytes, the error kind it must give.
type GmshCase<'a> = (&'static str, &'a [u8], fn(&ErrorKind) -> bool);

/// Each malformed file, the error kind it must give, and the line.
#[test]
fn malformed_files_name_the_problem_and_the_line() {
    let dir = scratch("malformed");
    let node = b"4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n";
    write(&dir, "ok.node", node);

    let cases: Vec<TetGenCase> = vec![
        // (name, .node, .ele, expected kind, line)
        (
            "truncated-node",
            b"3 3 0 0\n1 0.0 0.0 0.0\n2 1.0 0.0 0.0\n3 0.0 1.0",
            b"",
            |k| matches!(k, ErrorKind::Truncated(_)),
            4,
        ),
        (
            "short-file",
            b"4 3 0 0\n1 0 0 0\n2 1 0",
            b"",
            |k| matches!(k, ErrorKind::CountTooLarge { declared: 4, .. }),
            1,
        ),
        (
            "nan",
            b"2 3 0 0\n1 0 0 0\n2 nan 0 0\n",
            b"",
            |k| matches!(k, ErrorKind::NonFinite { index: 1, .. }),
            3,
        ),
        (
            "inf",
            b"1 3 0 0\n1 0 inf 0\n",
            b"",
            |k| matches!(k, ErrorKind::NonFinite { index: 0, .. }),
            2,
        ),
        (
            "bad-number",
            b"1 3 0 0\n1 0 0,5 0\n",
            b"",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            2,
        ),
        (
            "skipped-index",
            b"2 3 0 0\n1 0 0 0\n3 0 0 1\n",
            b"",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            3,
        ),
        (
            "huge-count",
            b"99999999999 3 0 0\n1 0 0 0\n",
            b"",
            |k| matches!(k, ErrorKind::CountTooLarge { .. }),
            1,
        ),
        (
            "dimension-2",
            b"1 2 0 0\n1 0 0\n",
            b"",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            1,
        ),
        (
            "trailing",
            b"1 3 0 0\n1 0 0 0\n2 0 0 0\n",
            b"",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            3,
        ),
        (
            "missing-node",
            node,
            b"1 4 0\n1 1 2 3 5\n",
            |k| {
                matches!(
                    k,
                    ErrorKind::IndexOutOfRange {
                        index: 0,
                        node: 5,
                        count: 4,
                        ..
                    }
                )
            },
            2,
        ),
        (
            "zero-node",
            node,
            b"2 4 0\n1 1 2 3 4\n2 0 1 2 3\n",
            |k| {
                matches!(
                    k,
                    ErrorKind::IndexOutOfRange {
                        index: 1,
                        node: 0,
                        ..
                    }
                )
            },
            3,
        ),
        (
            "truncated-ele",
            node,
            b"2 4 0\n1   1   2   3   4\n2 1 2",
            |k| matches!(k, ErrorKind::Truncated(_)),
            3,
        ),
        (
            "ele-count",
            node,
            b"4000000000 4 0\n1 1 2 3 4\n",
            |k| matches!(k, ErrorKind::CountTooLarge { .. }),
            1,
        ),
        (
            "nan-attribute",
            node,
            b"1 4 1\n1 1 2 3 4 nan\n",
            |k| matches!(k, ErrorKind::Syntax { .. }),
            2,
        ),
    ];
    for (name, node_bytes, ele_bytes, kind_ok, line) in cases {
        write(&dir, &format!("{name}.node"), node_bytes);
        write(
            &dir,
            &format!("{name}.ele"),
            if ele_bytes.is_empty() {
                b"1 4 0\n1 1 1 1 1\n"
            } else {
                ele_bytes
            },
        );
        let err = TetMesh::read(dir.join(format!("{name}.node"))).unwrap_err();
        assert!(kind_ok(&err.kind), "{name}: {err}");
        assert_eq!(err.location, Some(Location::Line(line)), "{name}: {err}");
        assert!(
            err.to_string().contains(&format!("{name}.")),
            "{name}: {err}"
        );
    }
}

#[test]
fn gmsh_errors() {
    let dir = scratch("gmsh-errors");
    let binary = gmsh_22_binary();
    let cases: Vec<GmshCase> = vec![
        ("v3", b"$MeshFormat\n3.0 0 8\n$EndMeshFormat\n", |k| matches!(k, ErrorKind::Unsupported(_))),
        ("no-nodes", b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n", |k| matches!(k, ErrorKind::Truncated(_))),
        (
            "missing-node",
            b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n$Elements\n1\n1 4 0 1 1 1 9\n$EndElements\n",
            |k| matches!(k, ErrorKind::IndexOutOfRange { node: 9, count: 1, .. }),
        ),
        (
            "huge",
            b"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n123456789012\n",
            |k| matches!(k, ErrorKind::CountTooLarge { .. }),
        ),
        ("binary-short", &binary[..120], |k| matches!(k, ErrorKind::CountTooLarge { .. })),
        ("binary-truncated", &binary[..binary.len() - 30], |k| matches!(k, ErrorKind::Truncated(_))),
        ("garbage", b"hello", |k| matches!(k, ErrorKind::Syntax { .. })),
    ];
    for (name, bytes, kind_ok) in cases {
        let err = gmsh::read(write(&dir, &format!("{name}.msh"), bytes)).unwrap_err();
        assert!(kind_ok(&err.kind), "{name}: {err}");
        assert!(
            err.location.is_some() || matches!(err.kind, ErrorKind::Truncated(_)),
            "{name}"
        );
    }
}

#[test]
fn missing_files_and_unknown_extensions() {
    let err = TetMesh::read("/nonexistent/trilux/mesh.node").unwrap_err();
    assert!(matches!(err.kind, ErrorKind::Io(_)));
    assert!(
        err.to_string()
            .starts_with("/nonexistent/trilux/mesh.node: ")
    );
    assert!(std::error::Error::source(&err).is_some());
    let err = TetMesh::read("mesh.stl").unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)), "{err}");
}

const MEDIT: &[u8] = b"# a comment\nMeshVersionFormatted 2\n\nDimension\n3\n\
Vertices\n5\n0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 1\n1 1 1 2\n\
Edges\n1\n1 2 0\nCorners\n2\n1\n2\n\
Tetrahedra\n2\n1 2 3 4 3\n5 2 4 3 4\n\
Triangles\n1\n1 2 3 0\nNormals\n1\n0.0 0.0 1.0\nEnd\n";

#[test]
fn medit_reads_blocks_in_any_order_and_round_trips() {
    let dir = scratch("medit");
    let mesh = TetMesh::read(write(&dir, "m.mesh", MEDIT)).unwrap();
    assert_eq!(mesh.positions.len(), 5);
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3], [4, 1, 3, 2]]);
    assert_eq!(mesh.regions, vec![3, 4]);
    let copy = dir.join("copy.mesh");
    medit::write(&copy, &mesh).unwrap();
    assert_eq!(TetMesh::read(&copy).unwrap(), mesh);
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn real_mesh_through_medit_and_back() {
    let data = data_dir().expect("TRILUX_DATA names the data folder");
    let mesh = TetMesh::read(data.join("tets/bunny_50k.node")).unwrap();
    let dir = scratch("medit-real");
    let path = dir.join("bunny.mesh");
    medit::write(&path, &mesh).unwrap();
    assert_eq!(TetMesh::read(&path).unwrap(), mesh);
}

#[test]
fn medit_errors() {
    let dir = scratch("medit-errors");
    let cases: Vec<GmshCase> = vec![
        ("dim2", b"MeshVersionFormatted 1\nDimension 2\nEnd\n", |k| matches!(k, ErrorKind::Syntax { .. })),
        ("no-vertices", b"MeshVersionFormatted 1\nDimension 3\nEnd\n", |k| matches!(k, ErrorKind::Truncated(_))),
        ("unknown", b"MeshVersionFormatted 1\nDimension 3\nSolAtVertices\n1\n", |k| matches!(k, ErrorKind::Unsupported(_))),
        (
            "zero-index",
            b"MeshVersionFormatted 1\nDimension 3\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n0 1 1 1 0\nEnd\n",
            |k| matches!(k, ErrorKind::IndexOutOfRange { node: 0, count: 1, .. }),
        ),
        ("nan", b"MeshVersionFormatted 1\nDimension 3\nVertices\n1\n0 NaN 0 0\nEnd\n", |k| matches!(k, ErrorKind::NonFinite { .. })),
        ("no-end", b"MeshVersionFormatted 1\nDimension 3\nVertices\n1\n0 0 0 0\n", |k| matches!(k, ErrorKind::Truncated(_))),
        ("huge", b"MeshVersionFormatted 1\nDimension 3\nVertices\n4000000000\n0 0 0 0\n", |k| matches!(k, ErrorKind::CountTooLarge { .. })),
    ];
    for (name, bytes, kind_ok) in cases {
        let err = medit::read(write(&dir, &format!("{name}.mesh"), bytes)).unwrap_err();
        assert!(kind_ok(&err.kind), "{name}: {err}");
    }
}

/// Decodes standard base64, independently of the writer's encoder.
fn decode_base64(text: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let mut out = Vec::new();
    for quad in text.trim().as_bytes().chunks(4) {
        let pad = quad.iter().filter(|&&c| c == b'=').count();
        let n = quad
            .iter()
            .take(4 - pad)
            .fold(0u32, |acc, &c| (acc << 6) | u32::from(value(c)))
            << (6 * pad);
        let bytes = [(n >> 16) as u8, (n >> 8) as u8, n as u8];
        out.extend_from_slice(&bytes[..3 - pad]);
    }
    out
}

/// The text content of each `<DataArray …>` in document order.
fn data_arrays(doc: &str) -> Vec<(String, String)> {
    doc.split("<DataArray ")
        .skip(1)
        .map(|part| {
            let (attrs, rest) = part.split_once('>').unwrap();
            let content = rest.split("</DataArray>").next().unwrap();
            (attrs.to_string(), content.trim().to_string())
        })
        .collect()
}

#[test]
fn vtu_arrays_decode_to_the_mesh_and_fields() {
    let mesh = gmsh_from(GMSH_22);
    let temperature = [0.5, 1.0 / 3.0, -2.0, 1e-300, 7.0];
    let volume: Vec<f64> = (0..2).map(|t| mesh.signed_volume6(t) / 6.0).collect();
    let points = [vtu::Field {
        name: "T<K>",
        values: &temperature,
    }];
    let cells = [vtu::Field {
        name: "volume",
        values: &volume,
    }];
    let path = Path::new("out.vtu");
    let binary = vtu::to_string(path, &mesh, &points, &cells, vtu::Encoding::Base64).unwrap();
    assert!(binary.contains("NumberOfPoints=\"5\" NumberOfCells=\"2\""));
    assert!(binary.contains("Name=\"T&lt;K&gt;\""));
    let arrays = data_arrays(&binary);
    assert_eq!(arrays.len(), 6);
    let f64s = |content: &str| {
        let bytes = decode_base64(content);
        let len = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
        assert_eq!(len, bytes.len() - 8);
        bytes[8..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect::<Vec<_>>()
    };
    assert_eq!(f64s(&arrays[0].1), temperature);
    assert_eq!(f64s(&arrays[1].1), volume);
    let coords: Vec<f64> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    assert_eq!(f64s(&arrays[2].1), coords);
    let connectivity: Vec<i64> = decode_base64(&arrays[3].1)[8..]
        .chunks_exact(8)
        .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let expected: Vec<i64> = mesh.tets.iter().flatten().map(|&i| i64::from(i)).collect();
    assert_eq!(connectivity, expected);
    assert_eq!(decode_base64(&arrays[5].1)[8..], [10, 10]);

    let ascii = vtu::to_string(path, &mesh, &points, &cells, vtu::Encoding::Ascii).unwrap();
    let arrays = data_arrays(&ascii);
    let parsed: Vec<f64> = arrays[0]
        .1
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(parsed, temperature);
    assert_eq!(arrays[4].1, "4 8");
    assert_eq!(arrays[5].1, "10 10");

    let wrong = [vtu::Field {
        name: "short",
        values: &temperature[..3],
    }];
    let err = vtu::to_string(path, &mesh, &wrong, &[], vtu::Encoding::Ascii).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::InvalidInput(_)), "{err}");
    assert!(
        err.to_string()
            .contains("\"short\" has 3 values for 5 nodes"),
        "{err}"
    );
}

/// `tet::write` picks the format by extension; real attributes survive a
/// TetGen round trip, and region tags exist only for integer attributes.
#[test]
fn tet_write_by_extension_keeps_real_attributes() {
    let dir = scratch("tet-write");
    let mesh = TetMesh {
        positions: vec![
            glam::DVec3::ZERO,
            glam::DVec3::X,
            glam::DVec3::Y,
            glam::DVec3::Z,
            glam::DVec3::ONE,
        ],
        tets: vec![[0, 1, 2, 3], [4, 1, 3, 2]],
        regions: Vec::new(),
        attributes: vec![vec![1.0, 1.5], vec![-2.0, 1e-3]],
        warnings: Vec::new(),
    };
    trilux_io::tet::write(dir.join("m.node"), &mesh).unwrap();
    assert_eq!(trilux_io::tet::read(dir.join("m.ele")).unwrap(), mesh);
    let tagged = TetMesh {
        attributes: vec![vec![3.0, -1.0]],
        ..mesh.clone()
    };
    trilux_io::tet::write(dir.join("t.ele"), &tagged).unwrap();
    let back = trilux_io::tet::read(dir.join("t.node")).unwrap();
    assert_eq!(back.regions, vec![3, -1]);
    assert_eq!(back.attributes, tagged.attributes);
    // Regions that contradict the first attribute cannot both be written.
    let contradiction = TetMesh {
        regions: vec![1, 2],
        ..tagged.clone()
    };
    let err = trilux_io::tet::write(dir.join("c.node"), &contradiction).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::InvalidInput(_)), "{err}");

    trilux_io::tet::write(dir.join("m.mesh"), &mesh).unwrap();
    let medit_back = trilux_io::tet::read(dir.join("m.mesh")).unwrap();
    assert_eq!(medit_back.tets, mesh.tets);
    trilux_io::tet::write(dir.join("m.vtu"), &mesh).unwrap();
    assert!(
        std::fs::read_to_string(dir.join("m.vtu"))
            .unwrap()
            .contains("UnstructuredGrid")
    );
    let err = trilux_io::tet::write(dir.join("m.off"), &mesh).unwrap_err();
    assert!(matches!(err.kind, ErrorKind::UnknownExtension(..)), "{err}");
}

/// Meshes built by hand may be inconsistent: the measures say NaN instead
/// of panicking, and the boundary still comes out.
#[test]
fn inconsistent_hand_built_meshes_do_not_panic() {
    let mesh = TetMesh {
        positions: vec![glam::DVec3::ZERO, glam::DVec3::X],
        tets: vec![[0, 1, 2, 3]],
        ..TetMesh::default()
    };
    assert!(mesh.signed_volume6(0).is_nan());
    assert!(mesh.signed_volume6(7).is_nan());
    assert!(mesh.volume().is_nan());
    assert_eq!(mesh.boundary().len(), 4);
    assert!(trilux_io::tet::enclosed_volume(&mesh.positions, &[[0, 1, 9]]).is_nan());
    let tri = trilux_io::mesh::TriMesh {
        positions: vec![glam::Vec3::ZERO],
        indices: vec![[0, 1, 2]],
        ..Default::default()
    };
    assert!(tri.area().is_nan());
}
