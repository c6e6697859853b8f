//! The adapters of the `trilux` library: round trips through mesh colours
//! and the atlas, the UV convention across file formats, welding, point
//! clouds, tetrahedral meshes, previews.

use glam::{Vec2, Vec3};
use mesh_sampling::{Channel, Density, DensitySampler, SurfaceSampler};
use trilux::shapes;
use trilux_io::image::Image;
use trilux_io::mesh::TriMesh;
use trilux_tests::data;

/// `n` area-uniform points `(face, barycentrics)`.
fn points(mesh: &TriMesh, n: usize) -> Vec<(u32, [f32; 3])> {
    mesh_sampling::UniformSampler::new(trilux::mesh_ref(mesh))
        .unwrap()
        .sample_n(11, n)
        .unwrap()
        .iter()
        .map(|p| (p.face, p.barycentric))
        .collect()
}

/// PSNR (sRGB-encoded, dB) of the baked mesh + image against the source
/// texture, and of a baked mesh read with its v flipped (a wrong UV
/// convention), which must be far worse.
fn round_trip(mesh: &TriMesh, texture: Option<&Image>) -> (f64, f64, f64) {
    let (surface, colors) = trilux::to_mesh_colors(mesh, texture, &Default::default()).unwrap();
    let atlas = mesh_colors::atlas::bake(&colors, &Default::default()).unwrap();
    let (baked, image) = trilux::atlas_mesh(&surface, &atlas, None);
    assert_eq!(baked.indices.len(), mesh.indices.len());
    for (f, (tri, new)) in mesh.indices.iter().zip(&baked.indices).enumerate() {
        for (k, (&v, &w)) in tri.iter().zip(new).enumerate() {
            assert_eq!(
                baked.positions[w as usize], mesh.positions[v as usize],
                "face {f} corner {k}"
            );
        }
    }
    assert_eq!(
        (image.width as usize, image.height as usize),
        (atlas.texture.width(), atlas.texture.height())
    );
    let source = trilux::SurfaceTexture::new(mesh, texture).unwrap();
    let back = trilux::SurfaceTexture::new(&baked, None).unwrap();
    let pts = points(mesh, 100_000);
    let via_colors = trilux::colors::psnr(
        &pts,
        |f, b| source.color(f, b),
        |f, b| {
            let mut out = [0.0; 3];
            colors.linear(f as usize, b, &mut out).unwrap();
            out
        },
    );
    let via_atlas = trilux::colors::psnr(&pts, |f, b| source.color(f, b), |f, b| back.color(f, b));
    let mut flipped = baked.clone();
    for uv in flipped.uvs.as_mut().unwrap() {
        uv.y = 1.0 - uv.y;
    }
    let wrong = trilux::SurfaceTexture::new(&flipped, None).unwrap();
    let via_wrong = trilux::colors::psnr(&pts, |f, b| source.color(f, b), |f, b| wrong.color(f, b));
    (via_colors, via_atlas, via_wrong)
}

#[test]
fn torus_to_mesh_colours_to_atlas_keeps_positions_and_texture() {
    let torus = shapes::torus(64, 32);
    let noise = shapes::noise(128, 128, 3);
    let (colors, atlas, wrong) = round_trip(&torus, Some(&noise));
    // Documented in the crate docs of `trilux::colors`: ≥ 35 dB on smooth
    // textures at the default budget; the atlas adds < 1 dB of loss.
    assert!(colors > 35.0, "mesh colours {colors:.2} dB");
    assert!(
        atlas > 35.0 && atlas > colors - 1.0,
        "atlas {atlas:.2} dB vs {colors:.2}"
    );
    assert!(wrong < atlas - 10.0, "a flipped v must show: {wrong:.2} dB");
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn spot_to_mesh_colours_to_atlas_and_through_files() {
    let spot = TriMesh::read(data("meshes/spot.obj")).unwrap();
    let texture = trilux_io::image::read(data("textures/spot_texture.png")).unwrap();
    let (colors, atlas, wrong) = round_trip(&spot, Some(&texture));
    assert!(colors > 38.0, "mesh colours {colors:.2} dB");
    assert!(atlas > 38.0, "atlas {atlas:.2} dB");
    assert!(wrong < 25.0, "a flipped v must show: {wrong:.2} dB");

    // Through files: OBJ + MTL + 8-bit PNG written and read back.
    let (surface, mc) = trilux::to_mesh_colors(&spot, Some(&texture), &Default::default()).unwrap();
    let baked_atlas = mesh_colors::atlas::bake(
        &mc,
        &mesh_colors::atlas::Options {
            gutter: 2,
            mip_levels: 0,
        },
    )
    .unwrap();
    let (baked, _) = trilux::atlas_mesh(&surface, &baked_atlas, None);
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("spot_atlas.obj");
    baked.write(&obj).unwrap();
    let back = TriMesh::read(&obj).unwrap();
    assert_eq!(back.indices.len(), spot.indices.len());
    let source = trilux::SurfaceTexture::new(&spot, Some(&texture)).unwrap();
    let read = trilux::SurfaceTexture::new(&back, None).unwrap();
    let psnr = trilux::colors::psnr(
        &points(&spot, 100_000),
        |f, b| source.color(f, b),
        |f, b| read.color(f, b),
    );
    assert!(psnr > 36.0, "read back from OBJ + PNG: {psnr:.2} dB");
}

/// A minimal glTF (embedded buffer) of positions, UVs and indices: the
/// same mesh in the format whose UV convention `TriMesh` uses.
fn write_gltf(path: &std::path::Path, mesh: &TriMesh) {
    fn base64(bytes: &[u8]) -> String {
        const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = String::new();
        for c in bytes.chunks(3) {
            let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
            let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
            for k in 0..4 {
                if k <= c.len() {
                    out.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    out.push('=');
                }
            }
        }
        out
    }
    let uvs = mesh.uvs.as_ref().unwrap();
    let mut buffer = Vec::new();
    for p in &mesh.positions {
        for c in p.to_array() {
            buffer.extend_from_slice(&c.to_le_bytes());
        }
    }
    let uv_offset = buffer.len();
    for t in uvs {
        for c in t.to_array() {
            buffer.extend_from_slice(&c.to_le_bytes());
        }
    }
    let index_offset = buffer.len();
    for i in mesh.indices.iter().flatten() {
        buffer.extend_from_slice(&i.to_le_bytes());
    }
    let (lo, hi) = trilux::preview::bounds(&mesh.positions).unwrap();
    let n = mesh.positions.len();
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2}}]}}],
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{uv_offset}}},{{"buffer":0,"byteOffset":{uv_offset},"byteLength":{uv_len}}},{{"buffer":0,"byteOffset":{index_offset},"byteLength":{index_len}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","min":[{},{},{}],"max":[{},{},{}]}},
{{"bufferView":1,"componentType":5126,"count":{n},"type":"VEC2"}},
{{"bufferView":2,"componentType":5125,"count":{m},"type":"SCALAR"}}]}}"#,
        lo.x,
        lo.y,
        lo.z,
        hi.x,
        hi.y,
        hi.z,
        len = buffer.len(),
        data = base64(&buffer),
        uv_len = index_offset - uv_offset,
        index_len = buffer.len() - index_offset,
        m = mesh.indices.len() * 3,
    );
    std::fs::write(path, json).unwrap();
}

/// The texels (`x + y·W`) that `n` density-sampled points land on, the
/// density being the luminance of `texture` at the mesh's UVs.
fn texels_hit(mesh: &TriMesh, texture: &Image, n: usize) -> Vec<u32> {
    let density = trilux::density_texture(texture, Channel::Luminance).unwrap();
    let sampler = DensitySampler::new(trilux::mesh_ref(mesh), Density::Texture(&density)).unwrap();
    let (w, h) = (texture.width as f32, texture.height as f32);
    sampler
        .sample_n(5, n)
        .unwrap()
        .iter()
        .map(|p| {
            let uv = p.uv.unwrap();
            let x = (uv.x.rem_euclid(1.0) * w).min(w - 1.0) as u32;
            let y = (uv.y.rem_euclid(1.0) * h).min(h - 1.0) as u32;
            x + y * texture.width
        })
        .collect()
}

/// Mean luminance of the texels hit: density sampling must favour the
/// bright texels of the very texture it read.
fn mean_luminance(texture: &Image, texels: &[u32]) -> f64 {
    let lum = texture.luminance();
    texels
        .iter()
        .map(|&t| f64::from(lum[t as usize]))
        .sum::<f64>()
        / texels.len() as f64
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn spot_obj_and_gltf_sample_the_same_texels_and_a_wrong_convention_does_not() {
    // Density: the dark patches of the cow (1 − luminance), small and
    // asymmetric, so a wrong v lands elsewhere.
    let spot_texture = trilux_io::image::read(data("textures/spot_texture.png")).unwrap();
    let texture = Image {
        pixels: spot_texture
            .luminance()
            .iter()
            .map(|&l| {
                let d = (1.0 - l).max(0.0);
                [d, d, d, 1.0]
            })
            .collect(),
        ..spot_texture
    };
    let obj = TriMesh::read(data("meshes/spot.obj")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let gltf_path = dir.path().join("spot.gltf");
    write_gltf(&gltf_path, &obj);
    let gltf = TriMesh::read(&gltf_path).unwrap();
    let n = 20_000;
    let from_obj = texels_hit(&obj, &texture, n);
    let from_gltf = texels_hit(&gltf, &texture, n);
    let same = from_obj
        .iter()
        .zip(&from_gltf)
        .filter(|(a, b)| a == b)
        .count();
    assert!(
        same as f64 > 0.99 * n as f64,
        "only {same} of {n} points on the same texel"
    );
    // Sampling by the density finds its dense texels (against points
    // uniform on the surface), ...
    let uniform: Vec<u32> = mesh_sampling::UniformSampler::new(trilux::mesh_ref(&obj))
        .unwrap()
        .sample_n(5, n)
        .unwrap()
        .iter()
        .map(|p| {
            let uv = p.uv.unwrap();
            let (w, h) = (texture.width as f32, texture.height as f32);
            (uv.x.rem_euclid(1.0) * w).min(w - 1.0) as u32
                + (uv.y.rem_euclid(1.0) * h).min(h - 1.0) as u32 * texture.width
        })
        .collect();
    let uniform_mean = mean_luminance(&texture, &uniform);
    let hit_mean = mean_luminance(&texture, &from_obj);
    assert!(
        hit_mean > uniform_mean * 1.5,
        "{hit_mean} vs {uniform_mean}"
    );
    // ... and a mesh read with the other convention (v not flipped) lands
    // elsewhere.
    let mut wrong = obj.clone();
    for uv in wrong.uvs.as_mut().unwrap() {
        uv.y = 1.0 - uv.y;
    }
    let from_wrong = texels_hit(&wrong, &texture, n);
    let same_wrong = from_obj
        .iter()
        .zip(&from_wrong)
        .filter(|(a, b)| a == b)
        .count();
    assert!(
        (same_wrong as f64) < 0.2 * n as f64,
        "{same_wrong} of {n} on the same texel"
    );
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn gltf_written_as_obj_reads_back_with_the_same_uvs_and_texels() {
    for file in ["gltf/BoxTextured/BoxTextured.gltf", "gltf/Fox.glb"] {
        let mesh = TriMesh::read(data(file)).unwrap();
        let texture = mesh
            .materials
            .iter()
            .find_map(|m| m.diffuse_image.clone())
            .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let obj = dir.path().join("copy.obj");
        mesh.write(&obj).unwrap();
        let back = TriMesh::read(&obj).unwrap();
        let (a, b) = (mesh.uvs.as_ref().unwrap(), back.uvs.as_ref().unwrap());
        // Vertices may be re-split, so compare per triangle corner.
        for (t, u) in mesh.indices.iter().zip(&back.indices) {
            for k in 0..3 {
                assert!(
                    (a[t[k] as usize] - b[u[k] as usize]).abs().max_element() < 1e-5,
                    "{file}"
                );
            }
        }
        assert_eq!(
            texels_hit(&mesh, &texture, 5_000),
            texels_hit(&back, &texture, 5_000),
            "{file}"
        );
    }
}

#[test]
fn welding_joins_seams_and_keeps_faces_that_mesh_colours_cannot_share() {
    // The torus's seams are duplicated vertices: welded, it is closed.
    let torus = shapes::torus(16, 8);
    let surface = trilux::ColorMesh::new(&torus).unwrap();
    assert_eq!(surface.positions.len(), 16 * 8);
    assert_eq!(surface.detached, 0);
    surface.topology().unwrap();
    // Three triangles on one edge and a degenerate one: two detached.
    let mesh = TriMesh {
        positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, Vec3::X],
        indices: vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 1, 5]],
        ..TriMesh::default()
    };
    let surface = trilux::ColorMesh::new(&mesh).unwrap();
    assert_eq!(surface.detached, 2);
    assert_eq!(surface.faces.len(), 4);
    surface.topology().unwrap();
    // A face index out of range is an error, not a panic.
    let bad = TriMesh {
        positions: vec![Vec3::ZERO; 3],
        indices: vec![[0, 1, 7]],
        ..TriMesh::default()
    };
    assert!(
        trilux::ColorMesh::new(&bad)
            .unwrap_err()
            .to_string()
            .contains("triangle 0")
    );
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn the_teapot_welds_to_its_merged_vertex_count() {
    let teapot = TriMesh::read(data("meshes/teapot.obj")).unwrap();
    let surface = trilux::ColorMesh::new(&teapot).unwrap();
    assert_eq!(
        surface.positions.len() + 2 * surface.detached,
        3_241 + 2 * surface.detached
    );
    surface.topology().unwrap();
}

#[test]
fn point_clouds_carry_uvs_normals_and_faces_and_round_trip_through_ply() {
    let torus = shapes::torus(24, 12);
    let pts = mesh_sampling::UniformSampler::new(trilux::mesh_ref(&torus))
        .unwrap()
        .sample_n(2, 1000)
        .unwrap();
    let cloud = trilux::point_cloud(&torus, &pts);
    for (p, (uv, face)) in pts.iter().zip(
        cloud
            .uvs
            .as_ref()
            .unwrap()
            .iter()
            .zip(cloud.face_ids.as_ref().unwrap()),
    ) {
        assert_eq!(*face, p.face);
        assert!((*uv - p.uv.unwrap()).abs().max_element() < 1e-5);
    }
    let dir = tempfile::tempdir().unwrap();
    for format in [
        trilux_io::mesh::ply::Format::Ascii,
        trilux_io::mesh::ply::Format::BinaryLittleEndian,
    ] {
        let path = dir.path().join("points.ply");
        trilux_io::mesh::ply::write(&path, &cloud, format).unwrap();
        let back = trilux_io::mesh::ply::read(&path).unwrap();
        assert_eq!(back.positions.len(), 1000);
        assert_eq!(back.face_ids, cloud.face_ids);
        let (a, b) = (back.uvs.unwrap(), cloud.uvs.as_ref().unwrap().clone());
        assert!(
            a.iter()
                .zip(&b)
                .all(|(x, y): (&Vec2, &Vec2)| (*x - *y).abs().max_element() < 1e-5)
        );
    }
}

#[test]
fn density_textures_take_a_channel_or_the_rec709_luminance() {
    let image = Image {
        width: 2,
        height: 1,
        pixels: vec![[1.0, 0.0, 0.0, 0.5], [0.5, 0.25, 2.0, 1.0]],
    };
    let lum = trilux::density_texture(&image, Channel::Luminance).unwrap();
    assert!((lum.texels()[0] - 0.2126).abs() < 1e-6);
    // 0.2126·0.5 + 0.7152·0.25 + 0.0722·2
    assert!((lum.texels()[1] - 0.4295).abs() < 1e-6);
    let alpha = trilux::density_texture(&image, Channel::Index(3)).unwrap();
    assert_eq!(alpha.texels(), &[0.5, 1.0]);
    let negative = Image {
        width: 1,
        height: 1,
        pixels: vec![[-1.0, 0.0, 0.0, 1.0]],
    };
    assert!(trilux::density_texture(&negative, Channel::Index(0)).is_err());
}

#[test]
fn built_in_shapes_are_closed_and_outward() {
    for mesh in [shapes::icosphere(3), shapes::blob(3), shapes::torus(32, 16)] {
        let shape = trilux::mesh::shape(&mesh);
        assert_eq!(
            (shape.boundary_edges, shape.non_manifold_edges, shape.parts),
            (0, 0, 1)
        );
        let p: Vec<glam::DVec3> = mesh.positions.iter().map(|p| p.as_dvec3()).collect();
        assert!(trilux_io::tet::enclosed_volume(&p, &mesh.indices) > 0.0);
    }
}

#[test]
fn a_regular_tetrahedron_has_dihedral_angles_of_arccos_one_third() {
    use glam::DVec3;
    let p = [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ];
    for a in trilux::tet::dihedral_angles(p) {
        assert!((a - (1.0f64 / 3.0).acos().to_degrees()).abs() < 1e-9, "{a}");
    }
    // A flat (sliver) tetrahedron has angles of 0° and 180°.
    let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
    let a = trilux::tet::dihedral_angles(flat);
    assert!(
        a.iter().any(|&x| x < 1e-6) && a.iter().any(|&x| x > 180.0 - 1e-6),
        "{a:?}"
    );
    // A face of no area gives NaN.
    let degenerate = [DVec3::ZERO, DVec3::X, DVec3::X, DVec3::Y];
    assert!(
        trilux::tet::dihedral_angles(degenerate)
            .iter()
            .any(|a| a.is_nan())
    );
}

#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn tet_meshes_give_their_surface_and_the_readme_dihedral_range() {
    let mesh = trilux_io::tet::TetMesh::read(data("tets/sphere_20k.node")).unwrap();
    let (lo, hi) = trilux::tet::dihedral_range(&mesh).unwrap();
    // The data README: 1.486° .. 176.97°.
    assert!(
        (lo - 1.486).abs() < 0.01 && (hi - 176.97).abs() < 0.01,
        "{lo} {hi}"
    );
    let surface = trilux::tet::surface(&mesh);
    assert_eq!(surface.indices.len(), 1_938);
    assert_eq!(trilux::mesh::shape(&surface).boundary_edges, 0);
    assert_eq!(trilux::tet::positions_f64(&mesh).len(), 3_626);
}

#[test]
fn previews_draw_the_mesh_in_the_middle_and_background_at_the_corner() {
    let sphere = shapes::icosphere(3);
    let image = trilux::preview::render_mesh(&sphere.positions, &sphere.indices, 64, 64);
    let at = |x: u32, y: u32| image.pixels[(y * 64 + x) as usize];
    let (centre, corner) = (at(32, 32), at(1, 1));
    assert!(
        (centre[0] - corner[0]).abs() > 0.05,
        "{centre:?} vs {corner:?}"
    );
    assert!(centre[0] > 0.2);
}
