//! Curves out (USD text, `.hair`, glTF lines and root points) and back:
//! random strands written and read again, exactly.

use std::path::Path;

use test_support::SplitMix64;
use trilux_io::curves::{self, Curves, hair, usda};
use trilux_io::glam::{Vec2, Vec3};
use trilux_io::mesh::gltf;

/// Random curves: varying counts (2 to 12 points), optional widths and
/// root data.
fn random_curves(rng: &mut SplitMix64, uniform: bool) -> Curves {
    let n = 1 + rng.below(40) as usize;
    let fixed = 2 + rng.below(10) as u32;
    let counts: Vec<u32> = (0..n)
        .map(|_| {
            if uniform {
                fixed
            } else {
                2 + rng.below(11) as u32
            }
        })
        .collect();
    let total: u32 = counts.iter().sum();
    let mut coord = || (rng.f32() - 0.5) * 10f32.powi(rng.below(7) as i32 - 3);
    let points: Vec<Vec3> = (0..total)
        .map(|_| Vec3::new(coord(), coord(), coord()))
        .collect();
    let widths = (rng.below(2) == 0).then(|| (0..total).map(|_| rng.f32() * 0.01).collect());
    let roots = rng.below(2) == 0;
    Curves {
        points,
        counts,
        widths,
        faces: roots.then(|| (0..n).map(|_| rng.below(1 << 20) as u32).collect()),
        barycentrics: roots.then(|| (0..n).map(|_| rng.barycentric()).collect()),
        normals: roots.then(|| {
            (0..n)
                .map(|_| Vec3::new(rng.f32() - 0.5, rng.f32() - 0.5, 1.0).normalize())
                .collect()
        }),
        uvs: roots.then(|| (0..n).map(|_| Vec2::new(rng.f32(), rng.f32())).collect()),
    }
}

#[test]
fn hair_files_read_back_the_points_counts_and_widths_written() {
    let dir = crate::support::scratch("curves");
    let mut rng = SplitMix64(11);
    for case in 0..60 {
        let curves = random_curves(&mut rng, case % 2 == 0);
        let path = dir.join(format!("case{case}.hair"));
        curves::write(&path, &curves).unwrap();
        let back = hair::read(&path).unwrap();
        assert_eq!(back.points, curves.points, "case {case}");
        assert_eq!(back.counts, curves.counts, "case {case}");
        assert_eq!(back.widths, curves.widths, "case {case}");
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..4], b"HAIR");
        // Segments array only when the curves differ in length.
        let flags = u32::from_le_bytes(bytes[12..16].try_into().unwrap());
        let uniform = curves.counts.iter().all(|&c| c == curves.counts[0]);
        assert_eq!(flags & 1 == 0, uniform, "case {case}");
    }
}

#[test]
fn damaged_hair_files_are_errors_naming_the_byte() {
    let dir = crate::support::scratch("curves");
    let curves = random_curves(&mut SplitMix64(3), false);
    let path = dir.join("ok.hair");
    hair::write(&path, &curves).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let bad = dir.join("bad.hair");
    std::fs::write(&bad, &bytes[..bytes.len() - 1]).unwrap();
    let e = hair::read(&bad).unwrap_err().to_string();
    assert!(e.contains("byte 128") && e.contains("declares"), "{e}");
    let mut wrong = bytes.clone();
    wrong[..4].copy_from_slice(b"HAIX");
    std::fs::write(&bad, &wrong).unwrap();
    let e = hair::read(&bad).unwrap_err().to_string();
    assert!(e.contains("signature HAIR"), "{e}");
    let mut huge = bytes.clone();
    huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(&bad, &huge).unwrap();
    assert!(hair::read(&bad).is_err());
    std::fs::write(&bad, &bytes[..100]).unwrap();
    let e = hair::read(&bad).unwrap_err().to_string();
    assert!(e.contains("128-byte"), "{e}");
}

#[test]
fn inconsistent_curves_are_refused_naming_what() {
    let dir = crate::support::scratch("curves");
    let good = Curves::uniform(vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z], 2);
    assert_eq!(good.counts, vec![2, 2]);
    let cases: Vec<(Curves, &str)> = vec![
        (
            Curves {
                counts: vec![2, 1, 1],
                ..good.clone()
            },
            "curve 1 has 1 point",
        ),
        (
            Curves {
                counts: vec![3, 2],
                ..good.clone()
            },
            "sum to 5 points",
        ),
        (
            Curves {
                widths: Some(vec![0.1; 3]),
                ..good.clone()
            },
            "3 widths for 4 points",
        ),
        (
            Curves {
                widths: Some(vec![0.1, f32::NAN, 0.1, 0.1]),
                ..good.clone()
            },
            "width of point 1",
        ),
        (
            Curves {
                uvs: Some(vec![Vec2::ZERO]),
                ..good.clone()
            },
            "1 root UVs for 2 curves",
        ),
        (
            Curves {
                points: vec![Vec3::ZERO, Vec3::X, Vec3::NAN, Vec3::Z],
                ..good.clone()
            },
            "point 2 is not finite",
        ),
    ];
    for (curves, want) in cases {
        for ext in ["usda", "hair", "glb"] {
            let path = dir.join(format!("bad.{ext}"));
            let e = curves::write(&path, &curves).unwrap_err().to_string();
            assert!(e.contains(want) && e.contains("bad."), "{ext}: {e}");
        }
    }
    let e = curves::write(dir.join("x.abc"), &good)
        .unwrap_err()
        .to_string();
    assert!(e.contains(".usda"), "{e}");
}

/// The numbers of the array attribute `name` in our own USD text.
fn usda_array(text: &str, name: &str) -> Vec<f64> {
    let start = text
        .find(&format!(" {name} = ["))
        .unwrap_or_else(|| panic!("no {name}"));
    let body = &text[start..];
    let open = body.find('[').unwrap();
    let close = body.find(']').unwrap();
    body[open + 1..close]
        .split([',', '(', ')', ' '])
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect()
}

#[test]
fn usd_text_holds_the_curves_roots_and_stage_metadata_exactly() {
    let dir = crate::support::scratch("curves");
    let mut rng = SplitMix64(5);
    for case in 0..30 {
        let curves = random_curves(&mut rng, case % 3 == 0);
        let path = dir.join(format!("case{case}.usda"));
        let stage = usda::Stage {
            meters_per_unit: 0.01,
            up_axis: usda::UpAxis::Z,
            ..usda::Stage::default()
        };
        usda::write(&path, &curves, &stage).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("#usda 1.0\n"));
        for line in [
            "metersPerUnit = 0.01",
            "upAxis = \"Z\"",
            "defaultPrim = \"hair\"",
            "def BasisCurves \"strands\"",
            "uniform token type = \"linear\"",
            "def Points \"roots\"",
        ] {
            assert!(text.contains(line), "case {case}: {line}");
        }
        // The curves' prim comes first: its arrays are the first found.
        let counts: Vec<u32> = usda_array(&text, "curveVertexCounts")
            .iter()
            .map(|&c| c as u32)
            .collect();
        assert_eq!(counts, curves.counts);
        let flat: Vec<f32> = usda_array(&text, "points")
            .iter()
            .map(|&v| v as f32)
            .collect();
        let want: Vec<f32> = curves.points.iter().flat_map(|p| p.to_array()).collect();
        assert_eq!(flat, want, "case {case}: shortest round-trip text is exact");
        if let Some(w) = &curves.widths {
            let got: Vec<f32> = usda_array(&text, "widths")
                .iter()
                .map(|&v| v as f32)
                .collect();
            assert_eq!(&got, w);
        }
        if let Some(uvs) = &curves.uvs {
            let st = usda_array(&text, "primvars:st");
            for (c, uv) in uvs.iter().enumerate() {
                assert_eq!(st[2 * c] as f32, uv.x);
                assert_eq!(st[2 * c + 1] as f32, 1.0 - uv.y, "v up in USD");
            }
            let faces = usda_array(&text, "primvars:surface_face");
            let want: Vec<f64> = curves
                .faces
                .as_ref()
                .unwrap()
                .iter()
                .map(|&f| f64::from(f))
                .collect();
            assert_eq!(faces, want);
        }
        let roots = &text[text.find("def Points").unwrap()..];
        let ids = usda_array(roots, "ids");
        assert_eq!(ids.len(), curves.counts.len());
        let root_points = usda_array(roots, "points");
        let first = curves.offsets();
        for (c, &i) in first.iter().enumerate() {
            let p = curves.points[i].to_array();
            assert_eq!(
                root_points[3 * c..3 * c + 3]
                    .iter()
                    .map(|&v| v as f32)
                    .collect::<Vec<_>>(),
                p
            );
        }
    }
}

#[test]
fn gltf_lines_and_root_points_validate_and_read_back() {
    let dir = crate::support::scratch("curves");
    let mut rng = SplitMix64(8);
    for case in 0..6 {
        let mut curves = random_curves(&mut rng, false);
        if case == 0 {
            // Past 65,535 vertices: 32-bit indices.
            curves = Curves::uniform(
                (0..70_000 * 3)
                    .map(|i| Vec3::new(i as f32 * 1e-3, (i % 3) as f32, 0.0))
                    .collect(),
                3,
            );
        }
        for ext in ["glb", "gltf"] {
            let path = dir.join(format!("case{case}.{ext}"));
            curves::write(&path, &curves).unwrap();
            test_support::gltf::validate(&path);
            check_lines(&path, &curves);
            let scene = gltf::read_scene(&path).unwrap();
            let first = curves.offsets();
            let roots: Vec<Vec3> = first.iter().map(|&i| curves.points[i]).collect();
            assert_eq!(scene.points.positions, roots, "case {case}");
            assert_eq!(scene.points.faces, curves.faces, "case {case}");
            assert_eq!(scene.points.uvs, curves.uvs, "case {case}");
            assert!(
                scene
                    .mesh
                    .warnings
                    .iter()
                    .any(|w| w.to_string().contains("Lines")),
                "the reader says it left the lines out"
            );
        }
    }
}

/// The `LINES` primitive joins exactly consecutive points of each curve.
fn check_lines(path: &Path, curves: &Curves) {
    let file = ::gltf::Gltf::open(path).unwrap();
    let bin = match &file.blob {
        Some(blob) => blob.clone(),
        None => std::fs::read(path.with_extension("bin")).unwrap(),
    };
    let mesh = file.meshes().find(|m| m.name() == Some("strands")).unwrap();
    let primitive = mesh.primitives().next().unwrap();
    assert_eq!(primitive.mode(), ::gltf::mesh::Mode::Lines);
    let reader = primitive.reader(|_| Some(&bin[..]));
    let positions: Vec<Vec3> = reader.read_positions().unwrap().map(Vec3::from).collect();
    assert_eq!(positions, curves.points);
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    let mut want = Vec::new();
    for (first, &count) in curves.offsets().iter().zip(&curves.counts) {
        for i in *first as u32..*first as u32 + count - 1 {
            want.extend([i, i + 1]);
        }
    }
    assert_eq!(indices, want);
}
