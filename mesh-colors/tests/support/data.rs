//! The textured meshes of `$TRILUX_DATA`, as (name, welded positions,
//! faces, per-corner UVs (v = 0 at image row 0, as `TriMesh` gives them), RGB texture): spot with its
//! PNG, and every textured primitive of the glTF models. Shared by the
//! tests and the `lookup` example.

#![allow(dead_code, reason = "each user needs a subset")]

use std::path::Path;

use glam::{Vec2, Vec3};
use mesh_colors::{Texture, Wrap};
use trilux_io::mesh::TriMesh;

/// One textured mesh.
pub(crate) struct Textured {
    pub(crate) name: String,
    pub(crate) positions: Vec<Vec3>,
    pub(crate) faces: Vec<[u32; 3]>,
    pub(crate) corner_uvs: Vec<[Vec2; 3]>,
    pub(crate) texture: Texture,
}

pub(crate) use test_support::data::data_dir;

/// An RGB texture with sRGB-encoded values (as stored in the file: the
/// values PSNR is usually quoted on) from a linear RGBA image.
fn rgb(image: &trilux_io::image::Image, wrap: Wrap) -> Texture {
    let data = image
        .pixels
        .iter()
        .flat_map(|p| [0, 1, 2].map(|c| trilux_io::image::linear_to_srgb(p[c])))
        .collect();
    Texture::new(image.width as usize, image.height as usize, 3, data)
        .unwrap()
        .with_wrap(wrap)
}

/// The triangles `range` of `mesh`, welded by position and compacted.
fn part(
    mesh: &TriMesh,
    range: std::ops::Range<usize>,
) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<[Vec2; 3]>) {
    let uvs = mesh.uvs.as_ref().expect("a textured mesh has UVs");
    let tris = &mesh.indices[range];
    let (welded, faces, _) = mesh_colors::weld(&mesh.positions, tris);
    // Compact to the vertices these faces use.
    let mut map = vec![u32::MAX; welded.len()];
    let mut positions = Vec::new();
    let faces: Vec<[u32; 3]> = faces
        .iter()
        .map(|f| {
            f.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = positions.len() as u32;
                    positions.push(welded[v as usize]);
                }
                map[v as usize]
            })
        })
        .collect();
    // TriMesh UVs already follow the texture convention (v = 0 at image
    // row 0) for OBJ and glTF alike: no flip here.
    let corner_uvs = tris.iter().map(|t| t.map(|v| uvs[v as usize])).collect();
    (positions, faces, corner_uvs)
}

/// Every textured mesh of the data folder.
pub(crate) fn textured_meshes(dir: &Path) -> Vec<Textured> {
    let mut out = Vec::new();
    let spot = TriMesh::read(dir.join("meshes/spot.obj")).unwrap();
    let image = trilux_io::image::read(dir.join("textures/spot_texture.png")).unwrap();
    let (positions, faces, corner_uvs) = part(&spot, 0..spot.indices.len());
    out.push(Textured {
        name: "spot".into(),
        positions,
        faces,
        corner_uvs,
        texture: rgb(&image, Wrap::Repeat),
    });
    for file in [
        "gltf/BoxTextured/BoxTextured.gltf",
        "gltf/Fox.glb",
        "gltf/FlightHelmet/FlightHelmet.gltf",
    ] {
        let mesh = TriMesh::read(dir.join(file)).unwrap();
        let stem = Path::new(file)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .to_string();
        for (k, object) in mesh.objects.iter().enumerate() {
            let Some(material) = object.material.map(|m| &mesh.materials[m]) else {
                continue;
            };
            let Some(image) = &material.diffuse_image else {
                continue;
            };
            let wrap = match material.wrap[0] {
                trilux_io::mesh::Wrap::ClampToEdge => Wrap::ClampToEdge,
                trilux_io::mesh::Wrap::MirroredRepeat => Wrap::MirroredRepeat,
                trilux_io::mesh::Wrap::Repeat => Wrap::Repeat,
            };
            let (positions, faces, corner_uvs) = part(&mesh, object.triangles.clone());
            let name = if mesh.objects.len() > 1 {
                format!("{stem}/{k}")
            } else {
                stem.clone()
            };
            out.push(Textured {
                name,
                positions,
                faces,
                corner_uvs,
                texture: rgb(image, wrap),
            });
        }
    }
    out
}

/// `n` surface points, uniform by area (a deterministic SplitMix stream).
pub(crate) fn surface_points(
    positions: &[Vec3],
    faces: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> Vec<(u32, [f32; 3])> {
    let mut cdf = Vec::with_capacity(faces.len());
    let mut total = 0.0f64;
    for f in faces {
        let [a, b, c] = f.map(|v| positions[v as usize].as_dvec3());
        total += 0.5 * (b - a).cross(c - a).length();
        cdf.push(total);
    }
    let mut state = seed;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let x = next() * total;
            let f = cdf.partition_point(|&c| c <= x).min(faces.len() - 1);
            let (mut u, mut v) = (next() as f32, next() as f32);
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            (f as u32, [u, v, 1.0 - u - v])
        })
        .collect()
}
