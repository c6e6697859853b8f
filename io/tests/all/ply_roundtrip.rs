//! Property tests of the PLY reader and writer over random data: random
//! counts, every scalar type, random float bit patterns (so that binary
//! records often start with bytes that look like whitespace), ASCII and
//! both binary byte orders. test-support's seeded generator keeps them
//! deterministic.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use glam::{DVec3, Vec2, Vec3};
use trilux_io::mesh::ply::{self, Format, PlyData};

use test_support::SplitMix64 as Rng;

/// Random floats whose bytes cover every value.
trait Float {
    fn float(&mut self) -> f32;
}

impl Float for Rng {
    /// A finite f32 with a random mantissa and a binary exponent in
    /// `[-20, 15]`, either sign: every low byte occurs, 0x0a and 0x20
    /// included.
    fn float(&mut self) -> f32 {
        let bits = self.next_u64() as u32;
        let exponent = (127 - 20 + self.below(36) as u32) << 23;
        f32::from_bits((bits & 0x807F_FFFF) | exponent)
    }
}

/// The scalar types of PLY with their names, and how a value is encoded.
#[derive(Clone, Copy, Debug)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

const TYPES: [Ty; 8] = [
    Ty::I8,
    Ty::U8,
    Ty::I16,
    Ty::U16,
    Ty::I32,
    Ty::U32,
    Ty::F32,
    Ty::F64,
];

impl Ty {
    /// Alternately the old and the sized names (both are PLY).
    fn name(self, sized: bool) -> &'static str {
        let (old, new) = match self {
            Ty::I8 => ("char", "int8"),
            Ty::U8 => ("uchar", "uint8"),
            Ty::I16 => ("short", "int16"),
            Ty::U16 => ("ushort", "uint16"),
            Ty::I32 => ("int", "int32"),
            Ty::U32 => ("uint", "uint32"),
            Ty::F32 => ("float", "float32"),
            Ty::F64 => ("double", "float64"),
        };
        if sized { new } else { old }
    }

    /// A random value this type holds exactly.
    fn random(self, rng: &mut Rng) -> f64 {
        match self {
            Ty::I8 => f64::from(rng.next_u64() as i8),
            Ty::U8 => f64::from(rng.next_u64() as u8),
            Ty::I16 => f64::from(rng.next_u64() as i16),
            Ty::U16 => f64::from(rng.next_u64() as u16),
            Ty::I32 => f64::from(rng.next_u64() as i32),
            Ty::U32 => f64::from(rng.next_u64() as u32),
            Ty::F32 => f64::from(rng.float()),
            Ty::F64 => f64::from(rng.float()) * (1.0 + 2f64.powi(-40)),
        }
    }

    /// Encodes `v` (exactly representable) in `format`.
    fn encode(self, v: f64, format: Format, out: &mut Vec<u8>) {
        if format == Format::Ascii {
            let _ = write!(out, "{v} ");
            return;
        }
        let mut bytes: Vec<u8> = match self {
            Ty::I8 => (v as i8).to_le_bytes().to_vec(),
            Ty::U8 => (v as u8).to_le_bytes().to_vec(),
            Ty::I16 => (v as i16).to_le_bytes().to_vec(),
            Ty::U16 => (v as u16).to_le_bytes().to_vec(),
            Ty::I32 => (v as i32).to_le_bytes().to_vec(),
            Ty::U32 => (v as u32).to_le_bytes().to_vec(),
            Ty::F32 => (v as f32).to_le_bytes().to_vec(),
            Ty::F64 => v.to_le_bytes().to_vec(),
        };
        if format == Format::BinaryBigEndian {
            bytes.reverse();
        }
        out.extend_from_slice(&bytes);
    }
}

const FORMATS: [Format; 3] = [
    Format::Ascii,
    Format::BinaryLittleEndian,
    Format::BinaryBigEndian,
];

/// Files written here by an independent encoder, with random property
/// types and orders, read by `ply::from_bytes`: every value comes back.
#[test]
fn random_files_of_every_scalar_type_read_back_exactly() {
    let mut rng = Rng(0x5EED_0001);
    let mut whitespace_records = 0;
    for case in 0..600 {
        let format = FORMATS[case % 3];
        let n = rng.below(40) as usize + usize::from(case % 7 == 0) * 200;
        // x, y, z, s, t and two extra scalars, random types, shuffled.
        let mut props: Vec<(&str, Ty)> = ["x", "y", "z", "s", "t", "extra_a", "extra_b"]
            .into_iter()
            .map(|name| (name, TYPES[rng.below(8) as usize]))
            .collect();
        for i in (1..props.len()).rev() {
            props.swap(i, rng.below(i as u64 + 1) as usize);
        }
        let count_ty = [Ty::U8, Ty::U16, Ty::I32, Ty::U32][rng.below(4) as usize];
        let index_ty = [Ty::I32, Ty::U32, Ty::U16][rng.below(3) as usize];
        let polygons = if n >= 3 { rng.below(20) as usize } else { 0 };
        let sized = case % 2 == 0;

        let mut out = format!(
            "ply\nformat {} 1.0\ncomment case {case}\nelement vertex {n}\n",
            match format {
                Format::Ascii => "ascii",
                Format::BinaryLittleEndian => "binary_little_endian",
                Format::BinaryBigEndian => "binary_big_endian",
            }
        );
        for (name, ty) in &props {
            let _ = writeln!(out, "property {} {name}", ty.name(sized));
        }
        let _ = writeln!(out, "element face {polygons}");
        let _ = writeln!(
            out,
            "property list {} {} vertex_indices\nend_header",
            count_ty.name(sized),
            index_ty.name(sized)
        );
        let mut bytes = out.into_bytes();
        let mut values: Vec<Vec<f64>> = vec![Vec::new(); props.len()];
        for _ in 0..n {
            let start = bytes.len();
            for (k, (_, ty)) in props.iter().enumerate() {
                let v = ty.random(&mut rng);
                ty.encode(v, format, &mut bytes);
                values[k].push(v);
            }
            if format == Format::Ascii {
                bytes.push(b'\n');
            } else if bytes.get(start).is_some_and(u8::is_ascii_whitespace) {
                whitespace_records += 1;
            }
        }
        let mut expected_triangles = Vec::new();
        for _ in 0..polygons {
            let corners = 3 + rng.below(4) as usize;
            let ids: Vec<u32> = (0..corners).map(|_| rng.below(n as u64) as u32).collect();
            count_ty.encode(corners as f64, format, &mut bytes);
            for &i in &ids {
                index_ty.encode(f64::from(i), format, &mut bytes);
            }
            if format == Format::Ascii {
                bytes.push(b'\n');
            }
            for k in 1..corners - 1 {
                expected_triangles.push([ids[0], ids[k], ids[k + 1]]);
            }
        }

        let data = ply::from_bytes(&bytes, "random.ply")
            .unwrap_or_else(|e| panic!("case {case} ({format:?}): {e}"));
        let column = |name: &str| {
            let k = props.iter().position(|(p, _)| *p == name).unwrap();
            &values[k]
        };
        assert_eq!(data.positions.len(), n, "case {case}");
        for i in 0..n {
            let file = DVec3::new(column("x")[i], column("y")[i], column("z")[i]);
            let read = data.origin + data.positions[i].as_dvec3();
            if data.origin == DVec3::ZERO {
                assert_eq!(data.positions[i], file.as_vec3(), "case {case} vertex {i}");
            } else {
                let scale = (file - data.origin).abs().max_element().max(1e-30);
                assert!(
                    (read - file).abs().max_element() <= scale * 1e-7,
                    "case {case} vertex {i}: {read} vs {file}"
                );
            }
            let uv = data.uvs.as_ref().unwrap()[i];
            assert_eq!(uv.x, column("s")[i] as f32, "case {case}");
            assert_eq!(uv.y, 1.0 - column("t")[i] as f32, "case {case}");
        }
        assert_eq!(data.triangles, expected_triangles, "case {case}");
        assert_eq!(data.scalars.len(), 2, "case {case}");
        for (name, got) in &data.scalars {
            let want: Vec<f32> = column(name).iter().map(|&v| v as f32).collect();
            assert_eq!(got, &want, "case {case} {name}");
        }
    }
    assert!(
        whitespace_records > 100,
        "the data must exercise records starting with whitespace bytes: {whitespace_records}"
    );
}

/// Random point clouds and meshes through `ply::write` and `ply::read` in
/// every output format: nothing is lost.
#[test]
fn written_files_read_back_in_every_format() {
    let mut rng = Rng(0x5EED_0002);
    for case in 0..300 {
        let n = rng.below(60) as usize + 1;
        let positions: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.float(), rng.float(), rng.float()))
            .collect();
        let pick = |rng: &mut Rng| rng.below(2) == 0;
        let data = PlyData {
            normals: pick(&mut rng).then(|| {
                (0..n)
                    .map(|_| Vec3::new(rng.float(), rng.float(), rng.float()))
                    .collect()
            }),
            colors: pick(&mut rng).then(|| {
                (0..n)
                    .map(|_| (rng.next_u64() as u32).to_le_bytes())
                    .collect()
            }),
            // Multiples of 2^-12 in [0, 1]: 1 - (1 - v) is exact for them.
            uvs: pick(&mut rng).then(|| {
                (0..n)
                    .map(|_| {
                        let q = |rng: &mut Rng| (rng.below(4097) as f32) / 4096.0;
                        Vec2::new(q(&mut rng), q(&mut rng))
                    })
                    .collect()
            }),
            face_ids: pick(&mut rng).then(|| (0..n).map(|_| rng.next_u64() as u32).collect()),
            ids: pick(&mut rng).then(|| (0..n).map(|_| rng.next_u64() as u32).collect()),
            triangles: if pick(&mut rng) {
                (0..rng.below(30))
                    .map(|_| [0, 1, 2].map(|_| rng.below(n as u64) as u32))
                    .collect()
            } else {
                Vec::new()
            },
            scalars: (0..rng.below(3))
                .map(|k| {
                    let column = (0..n).map(|_| rng.float() * rng.f32()).collect();
                    (format!("quality_{k}"), column)
                })
                .collect(),
            positions,
            ..PlyData::default()
        };
        // The reader may re-centre far-out random data; compare the
        // absolute points then, exactly otherwise.
        for format in FORMATS {
            let bytes = ply::to_bytes("w.ply", &data, format).unwrap();
            let back = ply::from_bytes(&bytes, Path::new("w.ply"))
                .unwrap_or_else(|e| panic!("case {case} {format:?}: {e}"));
            if back.origin == DVec3::ZERO {
                assert_eq!(back, data, "case {case} {format:?}");
            } else {
                let same_rest = PlyData {
                    positions: data.positions.clone(),
                    origin: DVec3::ZERO,
                    ..back.clone()
                };
                assert_eq!(same_rest, data, "case {case} {format:?}");
                for (p, q) in data.positions.iter().zip(&back.positions) {
                    let q = back.origin + q.as_dvec3();
                    let tolerance = 1e-6 * (p.as_dvec3() - back.origin).abs().max_element();
                    assert!((p.as_dvec3() - q).abs().max_element() <= tolerance);
                }
            }
        }
    }
}

/// A point cloud with a non-zero origin goes out as `double` coordinates
/// and keeps its precision.
#[test]
fn shifted_point_clouds_keep_their_precision() {
    let origin = DVec3::new(412_345.0, 4_612_345.0, 231.0);
    let data = PlyData {
        positions: vec![
            Vec3::ZERO,
            Vec3::new(0.001, 0.0, 0.0),
            Vec3::new(0.0, 0.002, 0.5),
        ],
        origin,
        ..PlyData::default()
    };
    for format in FORMATS {
        let bytes = ply::to_bytes("far.ply", &data, format).unwrap();
        assert!(String::from_utf8_lossy(&bytes).contains("property double x"));
        let back = ply::from_bytes(&bytes, "far.ply").unwrap();
        for (p, q) in data.positions.iter().zip(&back.positions) {
            let a = origin + p.as_dvec3();
            let b = back.origin + q.as_dvec3();
            assert!((a - b).abs().max_element() < 1e-7, "{format:?}: {a} vs {b}");
        }
    }
}
