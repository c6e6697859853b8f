//! Property tests of the glTF writer over random data: every mesh, point
//! cloud and attribute written reads back through the crate's own reader
//! with the same counts and values, in both containers (`.glb`, `.gltf` +
//! `.bin`), with 16- and 32-bit indices, objects, materials with embedded
//! textures, and far-from-origin shifts. Each file also goes through the
//! Khronos glTF-Validator (`test_support::gltf::validate`).

use glam::{DVec3, Vec2, Vec3};
use test_support::SplitMix64 as Rng;
use trilux_io::image::{Image, srgb_to_linear};
use trilux_io::mesh::gltf::{self, Attribute, AttributeValues, Points, VertexData};
use trilux_io::mesh::ply::PlyData;
use trilux_io::mesh::{Material, Object, TriMesh, Wrap};

use crate::support::scratch;

fn unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - 1.0;
        if let Some(u) = v.try_normalize().filter(|_| v.length() > 0.1) {
            return u;
        }
    }
}

fn vec2s(rng: &mut Rng, n: usize) -> Vec<Vec2> {
    (0..n)
        .map(|_| Vec2::new(rng.f32() * 4.0 - 2.0, rng.f32()))
        .collect()
}

/// An image whose linear values come from 8-bit sRGB codes, so that the
/// writer's 8-bit PNG holds them exactly.
fn image(rng: &mut Rng) -> Image {
    let (width, height) = (1 + rng.below(9) as u32, 1 + rng.below(9) as u32);
    let code = |rng: &mut Rng| srgb_to_linear(rng.below(256) as f32 / 255.0);
    let pixels = (0..width * height)
        .map(|_| {
            [
                code(rng),
                code(rng),
                code(rng),
                rng.below(256) as f32 / 255.0,
            ]
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

fn attributes(rng: &mut Rng, n: usize) -> Vec<Attribute> {
    let names = ["PHI", "RADIANCE", "PDF", "W_2"];
    let k = rng.below(names.len() as u64 + 1) as usize;
    names[..k]
        .iter()
        .map(|name| {
            let kind = rng.below(4);
            let mut f = || rng.f32() * 200.0 - 100.0;
            let values = match kind {
                0 => AttributeValues::Scalar((0..n).map(|_| f()).collect()),
                1 => AttributeValues::Vec2((0..n).map(|_| Vec2::new(f(), f())).collect()),
                2 => AttributeValues::Vec3((0..n).map(|_| Vec3::new(f(), f(), f())).collect()),
                _ => AttributeValues::Vec4((0..n).map(|_| [f(), f(), f(), f()]).collect()),
            };
            Attribute {
                name: name.to_string(),
                values,
            }
        })
        .collect()
}

fn colors(rng: &mut Rng, n: usize, opaque: bool) -> Vec<[f32; 4]> {
    (0..n)
        .map(|_| {
            let a = if opaque { 1.0 } else { rng.f32() };
            [rng.f32(), rng.f32(), rng.f32(), a]
        })
        .collect()
}

/// A far shift sometimes, as a georeferenced scan has.
fn origin(rng: &mut Rng) -> DVec3 {
    match rng.below(3) {
        0 => DVec3::new(412_345.0, 4_612_345.0, 120.0),
        _ => DVec3::ZERO,
    }
}

/// A random mesh of `n` vertices: objects with materials (every material
/// used, in order, as the reader numbers them by first use).
fn random_mesh(rng: &mut Rng, n: usize) -> TriMesh {
    let triangles = 1 + rng.below(2 * n as u64 + 1) as usize;
    let indices = (0..triangles)
        .map(|_| [0; 3].map(|_: u32| rng.below(n as u64) as u32))
        .collect::<Vec<_>>();
    let positions = (0..n)
        .map(|_| Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 10.0 - 5.0)
        .collect();
    let uvs = (rng.below(3) > 0).then(|| vec2s(rng, n));
    let mut mesh = TriMesh {
        positions,
        origin: origin(rng),
        normals: (rng.below(2) == 0).then(|| (0..n).map(|_| unit(rng)).collect()),
        uvs1: (uvs.is_some() && rng.below(3) == 0).then(|| vec2s(rng, n)),
        indices,
        ..TriMesh::default()
    };
    if uvs.is_some() && rng.below(2) == 0 {
        // Objects over the triangles, each with its own material.
        let cuts = 1 + rng.below(3.min(triangles as u64)) as usize;
        let mut start = 0;
        for k in 0..cuts {
            let end = if k + 1 == cuts {
                triangles
            } else {
                start + 1 + rng.below((triangles - start - (cuts - k)) as u64 + 1) as usize
            };
            let wraps = [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge];
            mesh.materials.push(Material {
                name: format!("m{k}"),
                diffuse: [rng.f32(), rng.f32(), rng.f32()],
                diffuse_texture: None,
                diffuse_image: (rng.below(2) == 0).then(|| image(rng)),
                wrap: [0, 1].map(|_| wraps[rng.below(3) as usize]),
                scalar_images: Vec::new(),
            });
            mesh.objects.push(Object {
                name: format!("part {k}"),
                triangles: start..end,
                material: Some(k),
            });
            start = end;
        }
    }
    mesh.uvs = uvs;
    mesh
}

fn assert_positions(written: &[Vec3], origin: DVec3, read: &TriMeshLike) {
    assert_eq!(read.positions.len(), written.len());
    for (i, (p, q)) in written.iter().zip(read.positions.iter()).enumerate() {
        let a = origin + p.as_dvec3();
        let b = read.origin + q.as_dvec3();
        // Exact without a shift; within the f32 steps of the shift and
        // of a 10-unit mesh otherwise.
        let tol = if origin == DVec3::ZERO {
            0.0
        } else {
            2e-6 * 16.0
        };
        assert!((a - b).abs().max_element() <= tol, "vertex {i}: {a} vs {b}");
    }
}

/// Positions and shift of what was read.
struct TriMeshLike<'a> {
    positions: &'a [Vec3],
    origin: DVec3,
}

fn assert_normals(written: Option<&Vec<Vec3>>, read: Option<&Vec<Vec3>>) {
    assert_eq!(written.is_some(), read.is_some());
    for (a, b) in written
        .into_iter()
        .flatten()
        .zip(read.into_iter().flatten())
    {
        assert!((*a - *b).abs().max_element() < 1e-6, "normal {a} vs {b}");
    }
}

/// glTF keeps attributes by name: they come back in name order.
fn sorted(mut data: VertexData) -> VertexData {
    data.attributes.sort_by(|a, b| a.name.cmp(&b.name));
    data
}

fn extension(rng: &mut Rng) -> &'static str {
    if rng.below(2) == 0 { "glb" } else { "gltf" }
}

#[test]
fn random_meshes_with_colours_and_attributes_read_back_as_written() {
    let mut rng = Rng(0x617c_f00d);
    let dir = scratch("gltf-roundtrip-meshes");
    for case in 0..60 {
        // Mostly small; one mesh past 65 535 vertices for 32-bit indices.
        let n = if case == 7 {
            70_000
        } else {
            1 + rng.below(300) as usize
        };
        let mesh = random_mesh(&mut rng, n);
        let opaque = rng.below(2) == 0;
        let data = VertexData {
            colors: (rng.below(2) == 0).then(|| colors(&mut rng, n, opaque)),
            attributes: attributes(&mut rng, n),
        };
        let path = dir.join(format!("mesh{case}.{}", extension(&mut rng)));
        gltf::write_with(&path, &mesh, &data).unwrap();
        test_support::gltf::validate(&path);
        let scene = gltf::read_scene(&path).unwrap();
        let read = &scene.mesh;
        assert!(read.warnings.is_empty(), "{:?}", read.warnings);
        assert_eq!(read.indices, mesh.indices, "case {case}");
        assert_positions(
            &mesh.positions,
            mesh.origin,
            &TriMeshLike {
                positions: &read.positions,
                origin: read.origin,
            },
        );
        assert_normals(mesh.normals.as_ref(), read.normals.as_ref());
        assert_eq!(read.uvs, mesh.uvs, "case {case}");
        assert_eq!(read.uvs1, mesh.uvs1, "case {case}");
        assert!(
            scene.vertex_data == sorted(data.clone()),
            "case {case}: vertex data differ"
        );
        assert!(scene.points.positions.is_empty());
        // Triangles without a material come back with the writer's
        // fallback (glTF's own default is a black-looking metal).
        let fallback = if data.colors.is_some() {
            gltf::UNLIT_MATERIAL
        } else {
            gltf::DEFAULT_MATERIAL
        };
        if mesh.objects.is_empty() {
            assert_eq!(read.objects.len(), 1);
            assert_eq!(read.objects[0].triangles, 0..mesh.indices.len());
            assert_eq!(read.materials.len(), 1);
            assert_eq!(read.materials[0].name, fallback);
            assert_eq!(read.materials[0].diffuse, [1.0; 3]);
        } else {
            assert_eq!(read.objects, mesh.objects, "case {case}");
            assert_eq!(read.materials.len(), mesh.materials.len());
        }
        for (a, b) in mesh.materials.iter().zip(&read.materials) {
            assert_eq!((&a.name, a.diffuse), (&b.name, b.diffuse));
            // Wrap modes belong to a texture's sampler.
            if a.diffuse_image.is_some() {
                assert_eq!(a.wrap, b.wrap);
            }
            assert_eq!(a.diffuse_image, b.diffuse_image, "case {case}");
        }
        // TriMesh::write picks glTF by extension too, and read() agrees.
        let again = dir.join(format!("again{case}.glb"));
        mesh.write(&again).unwrap();
        assert_eq!(trilux_io::mesh::read(&again).unwrap().indices, mesh.indices);
    }
}

#[test]
fn random_point_clouds_read_back_as_written() {
    let mut rng = Rng(0x0090_1375);
    let dir = scratch("gltf-roundtrip-points");
    for case in 0..40 {
        let n = 1 + rng.below(500) as usize;
        let ply = PlyData {
            positions: (0..n)
                .map(|_| Vec3::new(rng.f32(), rng.f32(), rng.f32()) * 2.0 - 1.0)
                .collect(),
            origin: origin(&mut rng),
            normals: (rng.below(2) == 0).then(|| (0..n).map(|_| unit(&mut rng)).collect()),
            colors: (rng.below(2) == 0).then(|| {
                (0..n)
                    .map(|_| [0; 4].map(|_: u8| rng.below(256) as u8))
                    .collect()
            }),
            uvs: (rng.below(2) == 0).then(|| vec2s(&mut rng, n)),
            face_ids: (rng.below(2) == 0).then(|| {
                (0..n)
                    .map(|_| rng.below(1 << 24) as u32)
                    .collect::<Vec<_>>()
            }),
            scalars: (0..rng.below(3))
                .map(|k| (format!("s{k}"), (0..n).map(|_| rng.f32()).collect()))
                .collect(),
            ..PlyData::default()
        };
        let points = Points::from(&ply);
        let path = dir.join(format!("points{case}.{}", extension(&mut rng)));
        gltf::write_points(&path, &points).unwrap();
        test_support::gltf::validate(&path);
        let scene = gltf::read_scene(&path).unwrap();
        assert!(scene.mesh.indices.is_empty());
        let read = &scene.points;
        assert_positions(
            &points.positions,
            points.origin,
            &TriMeshLike {
                positions: &read.positions,
                origin: read.origin,
            },
        );
        assert_normals(points.normals.as_ref(), read.normals.as_ref());
        assert_eq!(read.uvs, points.uvs, "case {case}");
        assert_eq!(read.faces, ply.face_ids, "case {case}");
        assert!(
            read.vertex_data == sorted(points.vertex_data.clone()),
            "case {case}"
        );
        // The 8-bit colours (sRGB-decoded on the way in) come back exactly.
        let bytes = read.vertex_data.colors.as_ref().map(|c| {
            c.iter()
                .map(|&[r, g, b, a]| {
                    let code = |v: f32| (v * 255.0).round() as u8;
                    let encode = trilux_io::image::linear_to_srgb;
                    [code(encode(r)), code(encode(g)), code(encode(b)), code(a)]
                })
                .collect::<Vec<_>>()
        });
        assert_eq!(bytes, ply.colors);
        // read() keeps the triangles only, and says so.
        let mesh = gltf::read(&path).unwrap();
        assert!(
            mesh.warnings
                .iter()
                .any(|w| w.to_string().contains("points"))
        );
    }
}

#[test]
fn a_texture_file_is_embedded_as_it_is() {
    let dir = scratch("gltf-texture-file");
    let texture = dir.join("checker.png");
    let checker = Image {
        width: 2,
        height: 2,
        pixels: vec![
            [1.0, 0.0, 0.0, 1.0],
            [0.0, 1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0, 1.0],
            [1.0, 1.0, 1.0, 1.0],
        ],
    };
    trilux_io::image::write(&texture, &checker).unwrap();
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y]),
        objects: vec![Object {
            name: "quad".into(),
            triangles: 0..1,
            material: Some(0),
        }],
        materials: vec![Material {
            name: "checker".into(),
            diffuse: [1.0; 3],
            diffuse_texture: Some(texture.clone()),
            diffuse_image: None,
            wrap: [Wrap::ClampToEdge; 2],
            scalar_images: Vec::new(),
        }],
        ..TriMesh::default()
    };
    let path = dir.join("textured.glb");
    mesh.write(&path).unwrap();
    test_support::gltf::validate(&path);
    let read = gltf::read(&path).unwrap();
    assert_eq!(read.materials[0].diffuse_image.as_ref(), Some(&checker));
    // A texture that is not there is an error naming it, not a mesh
    // without its texture.
    let mut missing = mesh.clone();
    missing.materials[0].diffuse_texture = Some(dir.join("gone.png"));
    let err = missing.write(dir.join("missing.glb")).unwrap_err();
    assert!(err.to_string().contains("gone.png"), "{err}");
}

#[test]
fn bad_input_is_refused_naming_the_problem() {
    let dir = scratch("gltf-bad-input");
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        ..TriMesh::default()
    };
    let write = |data: &VertexData| {
        gltf::write_with(dir.join("bad.glb"), &mesh, data)
            .unwrap_err()
            .to_string()
    };
    let scalar = |name: &str, values: Vec<f32>| VertexData {
        attributes: vec![Attribute {
            name: name.into(),
            values: AttributeValues::Scalar(values),
        }],
        ..VertexData::default()
    };
    assert!(write(&scalar("PHI", vec![1.0])).contains("1 values for 3 vertices"));
    assert!(write(&scalar("PHI", vec![1.0, f32::NAN, 0.0])).contains("not finite at vertex 1"));
    assert!(write(&scalar("no space", vec![0.0; 3])).contains("letters, digits"));
    let colors = VertexData {
        colors: Some(vec![[0.0, 2.0, 0.0, 1.0]; 3]),
        ..VertexData::default()
    };
    assert!(write(&colors).contains("not in [0, 1]"));
    let mut broken = mesh.clone();
    broken.indices[0][2] = 3;
    let err = broken
        .write(dir.join("broken.glb"))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("triangle 0 references a missing vertex"),
        "{err}"
    );
    let err = mesh.write(dir.join("mesh.stl")).unwrap_err().to_string();
    assert!(err.contains(".glb"), "{err}");
    let far = Points {
        positions: vec![Vec3::ZERO],
        faces: Some(vec![1 << 24]),
        ..Points::default()
    };
    let err = gltf::write_points(dir.join("far.glb"), &far)
        .unwrap_err()
        .to_string();
    assert!(err.contains("2^24"), "{err}");
    // Nothing was left behind by the refused writes.
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
}

#[test]
fn zero_normals_become_face_normals() {
    let dir = scratch("gltf-zero-normals");
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        indices: vec![[0, 1, 2]],
        normals: Some(vec![
            Vec3::ZERO,
            Vec3::new(0.0, 0.0, 2.0),
            Vec3::NAN,
            Vec3::ZERO,
        ]),
        ..TriMesh::default()
    };
    let path = dir.join("normals.gltf");
    mesh.write(&path).unwrap();
    test_support::gltf::validate(&path);
    let read = gltf::read(&path).unwrap();
    assert_eq!(read.normals.unwrap(), vec![Vec3::Z; 4]);
    assert!(dir.join("normals.bin").is_file());
}

/// Pieces over consecutive runs of vertices (a fracture's, meshes put one
/// after the other) get vertex accessors of their own, so each loads
/// alone; they read back as written.
#[test]
fn pieces_over_their_own_vertices_have_their_own_accessors() {
    let mut rng = Rng(0x005e_ed0f_9ec5);
    let dir = scratch("gltf-pieces");
    for case in 0..20 {
        let pieces = 2 + rng.below(3) as usize;
        let mut mesh = TriMesh::default();
        let mut colours = Vec::new();
        for k in 0..pieces {
            let first = mesh.positions.len() as u32;
            let n = 3 + rng.below(40) as u32;
            mesh.positions
                .extend((0..n).map(|_| Vec3::new(rng.f32(), rng.f32(), k as f32)));
            let start = mesh.indices.len();
            // Every vertex of the run used, the first and last included.
            mesh.indices.push([first, first + 1, first + n - 1]);
            for _ in 0..rng.below(2 * u64::from(n)) {
                mesh.indices
                    .push([0; 3].map(|_: u32| first + rng.below(u64::from(n)) as u32));
            }
            mesh.objects.push(Object {
                name: format!("piece {k}"),
                triangles: start..mesh.indices.len(),
                material: None,
            });
            colours.extend((0..n).map(|_| [rng.f32(), rng.f32(), rng.f32(), 1.0]));
        }
        let data = VertexData {
            colors: Some(colours),
            attributes: attributes(&mut rng, mesh.positions.len()),
        };
        let path = dir.join(format!("pieces{case}.gltf"));
        gltf::write_with(&path, &mesh, &data).unwrap();
        test_support::gltf::validate(&path);
        let json = std::fs::read_to_string(&path).unwrap();
        let own = json.matches("\"POSITION\":").count();
        assert_eq!(own, pieces, "one POSITION accessor per piece");
        let scene = gltf::read_scene(&path).unwrap();
        assert_eq!(scene.mesh.positions, mesh.positions, "case {case}");
        assert_eq!(scene.mesh.indices, mesh.indices, "case {case}");
        let names: Vec<_> = scene.mesh.objects.iter().map(|o| &o.name).collect();
        assert_eq!(
            names,
            mesh.objects.iter().map(|o| &o.name).collect::<Vec<_>>()
        );
        assert!(scene.vertex_data == sorted(data), "case {case}");
    }
    // Pieces that share a vertex share the accessors.
    let mut shared = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
        indices: vec![[0, 1, 2], [1, 2, 3]],
        ..TriMesh::default()
    };
    shared.objects = (0..2)
        .map(|k| Object {
            name: format!("part {k}"),
            triangles: k..k + 1,
            material: None,
        })
        .collect();
    let path = dir.join("shared.gltf");
    shared.write(&path).unwrap();
    let json = std::fs::read_to_string(&path).unwrap();
    assert_eq!(json.matches("\"POSITION\":0").count(), 2);
    assert_eq!(gltf::read(&path).unwrap().positions, shared.positions);
}

#[test]
fn colour_rounding_just_outside_zero_to_one_is_clamped_and_more_is_refused() {
    let dir = scratch("gltf-colour-slack");
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        ..TriMesh::default()
    };
    let with = |c: [f32; 4]| VertexData {
        colors: Some(vec![c, [0.5; 4], [0.5; 4]]),
        ..VertexData::default()
    };
    let path = dir.join("slack.glb");
    gltf::write_with(&path, &mesh, &with([1.000_000_1, -1e-7, 0.25, 1.0])).unwrap();
    let back = gltf::read_scene(&path).unwrap().vertex_data.colors.unwrap();
    assert_eq!(back[0], [1.0, 0.0, 0.25, 1.0]);
    let refused = |c: [f32; 4]| {
        gltf::write_with(dir.join("refused.glb"), &mesh, &with(c))
            .unwrap_err()
            .to_string()
    };
    assert!(refused([1.01, 0.0, 0.0, 1.0]).contains("is not in [0, 1]"));
    assert!(refused([f32::NAN, 0.0, 0.0, 1.0]).contains("is not finite"));
}

/// A scalar image of `w × h` with its values in red.
fn scalar(rng: &mut Rng, w: u32, h: u32) -> Image {
    let pixels = (0..w * h).map(|_| [rng.f32(), 0.5, 0.5, 1.0]).collect();
    Image {
        width: w,
        height: h,
        pixels,
    }
}

/// The 8-bit RGBA pixels of the image behind texture `index`.
fn texture_pixels(doc: &::gltf::Gltf, blob: &[u8], index: usize) -> Vec<[u8; 4]> {
    let texture = doc.textures().nth(index).unwrap();
    let ::gltf::image::Source::View { view, .. } = texture.source().unwrap().source() else {
        panic!("an embedded image")
    };
    let png = &blob[view.offset()..view.offset() + view.length()];
    let decoded = ::image::load_from_memory(png).unwrap().to_rgba8();
    decoded.pixels().map(|p| p.0).collect()
}

#[test]
fn scalar_textures_fill_the_metallic_roughness_and_occlusion_slots_or_their_own() {
    let dir = scratch("gltf-scalar-textures");
    let mut rng = Rng(45);
    let (w, h) = (5, 3);
    let names = ["roughness", "metallic", "occlusion", "density"];
    let images: Vec<Image> = names.iter().map(|_| scalar(&mut rng, w, h)).collect();
    let mut mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
        indices: vec![[0, 1, 2]],
        uvs: Some(vec![Vec2::ZERO, Vec2::X, Vec2::Y]),
        objects: vec![Object {
            name: "part".into(),
            triangles: 0..1,
            material: Some(0),
        }],
        materials: vec![Material {
            name: "painted".into(),
            diffuse: [1.0; 3],
            diffuse_texture: None,
            diffuse_image: Some(image(&mut rng)),
            wrap: [Wrap::ClampToEdge; 2],
            scalar_images: names
                .iter()
                .map(|n| n.to_string())
                .zip(images.clone())
                .collect(),
        }],
        ..TriMesh::default()
    };
    let path = dir.join("scalars.glb");
    mesh.write(&path).unwrap();
    test_support::gltf::validate(&path);

    let bytes = std::fs::read(&path).unwrap();
    let doc = ::gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = doc.blob.as_deref().unwrap();
    let material = doc.materials().next().unwrap();
    let pbr = material.pbr_metallic_roughness();
    assert_eq!((pbr.metallic_factor(), pbr.roughness_factor()), (1.0, 1.0));
    // Stored as data (no sRGB curve), 8 bits, in the channels glTF names.
    let byte = |v: f32| (v * 255.0).round() as u8;
    let packed = texture_pixels(
        &doc,
        blob,
        pbr.metallic_roughness_texture().unwrap().texture().index(),
    );
    let occlusion = texture_pixels(
        &doc,
        blob,
        material.occlusion_texture().unwrap().texture().index(),
    );
    let extras: serde_json::Value =
        serde_json::from_str(material.extras().as_ref().unwrap().get()).unwrap();
    let density_index = extras["scalar_textures"]["density"].as_u64().unwrap() as usize;
    assert_eq!(
        doc.textures().nth(density_index).unwrap().name(),
        Some("density")
    );
    let density = texture_pixels(&doc, blob, density_index);
    for i in 0..(w * h) as usize {
        assert_eq!(
            packed[i][1],
            byte(images[0].pixels[i][0]),
            "roughness in G, texel {i}"
        );
        assert_eq!(
            packed[i][2],
            byte(images[1].pixels[i][0]),
            "metallic in B, texel {i}"
        );
        assert_eq!(
            occlusion[i][0],
            byte(images[2].pixels[i][0]),
            "occlusion in R, texel {i}"
        );
        assert_eq!(
            density[i][0],
            byte(images[3].pixels[i][0]),
            "density, texel {i}"
        );
    }
    // The base colour still reads back as written.
    let read = gltf::read(&path).unwrap();
    assert!(read.materials[0].diffuse_image.is_some());

    // Refused, naming the problem: two of a name, and roughness and
    // metallic of different sizes (glTF packs them into one texture).
    let mut twice = mesh.clone();
    twice.materials[0]
        .scalar_images
        .push(("density".into(), scalar(&mut rng, w, h)));
    let err = twice.write(dir.join("twice.glb")).unwrap_err().to_string();
    assert!(
        err.contains("two scalar textures named \"density\""),
        "{err}"
    );
    mesh.materials[0].scalar_images[1].1 = scalar(&mut rng, w + 1, h);
    let err = mesh.write(dir.join("sizes.glb")).unwrap_err().to_string();
    assert!(err.contains("roughness is 5×3 and metallic 6×3"), "{err}");
}
