//! Built-in data generated in code: meshes and images for the demo, the
//! examples and the tests (no file needed).

use std::collections::HashMap;
use std::f32::consts::{PI, TAU};

use glam::{Vec2, Vec3};
use trilux_io::image::Image;
use trilux_io::mesh::{Object, TriMesh};

fn with_object(mut mesh: TriMesh, name: &str) -> TriMesh {
    mesh.objects = vec![Object {
        name: name.into(),
        triangles: 0..mesh.indices.len(),
        material: None,
    }];
    mesh
}

/// A unit icosphere: the icosahedron subdivided `subdivisions` times
/// (20·4ⁿ triangles, counter-clockwise seen from outside), with normals,
/// without UVs.
pub fn icosphere(subdivisions: u32) -> TriMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions.min(9) {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(faces.len() * 4);
        for f in &faces {
            let mut m = [0u32; 3];
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                m[k] = *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    positions
                        .push(((positions[a as usize] + positions[b as usize]) * 0.5).normalize());
                    positions.len() as u32 - 1
                });
            }
            next.extend([
                [f[0], m[0], m[2]],
                [f[1], m[1], m[0]],
                [f[2], m[2], m[1]],
                m,
            ]);
        }
        faces = next;
    }
    let normals = positions.clone();
    with_object(
        TriMesh {
            positions,
            indices: faces,
            normals: Some(normals),
            ..TriMesh::default()
        },
        "icosphere",
    )
}

/// A torus of major radius 1 and minor radius 0.4 around the y axis, as a
/// `major × minor` grid with normals and UVs (u around the ring, v around
/// the tube, `[0, 1]²`; the seams have duplicated vertices).
pub fn torus(major: u32, minor: u32) -> TriMesh {
    let (major, minor) = (major.max(3), minor.max(3));
    let (big, small) = (1.0f32, 0.4f32);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    // Angles from the index modulo the count, so that the seam's
    // duplicated vertices have bit-identical positions (they weld).
    for i in 0..=major {
        let u = i as f32 / major as f32;
        let (su, cu) = ((i % major) as f32 / major as f32 * TAU).sin_cos();
        for j in 0..=minor {
            let v = j as f32 / minor as f32;
            let (sv, cv) = ((j % minor) as f32 / minor as f32 * TAU).sin_cos();
            let n = Vec3::new(cu * cv, sv, su * cv);
            positions.push(Vec3::new(cu * big, 0.0, su * big) + n * small);
            normals.push(n);
            uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| i * (minor + 1) + j;
    let mut indices = Vec::new();
    for i in 0..major {
        for j in 0..minor {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            indices.push([a, c, b]);
            indices.push([a, d, c]);
        }
    }
    with_object(
        TriMesh {
            positions,
            indices,
            normals: Some(normals),
            uvs: Some(uvs),
            ..TriMesh::default()
        },
        "torus",
    )
}

/// A smooth bumpy blob: an icosphere with its radius modulated by a few
/// sines (radius between about 0.75 and 1.25), normals from the faces.
pub fn blob(subdivisions: u32) -> TriMesh {
    let mut mesh = icosphere(subdivisions);
    for p in &mut mesh.positions {
        let d = *p;
        let r = 1.0
            + 0.12 * (3.0 * d.x + 1.0).sin() * (2.0 * d.y).cos()
            + 0.08 * (5.0 * d.z).sin()
            + 0.05 * (7.0 * d.y + 2.0 * d.x).cos();
        *p = d * r;
    }
    mesh.normals = Some(vertex_normals(&mesh.positions, &mesh.indices));
    mesh.objects[0].name = "blob".into();
    mesh
}

/// Area-weighted vertex normals.
pub fn vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let face = (b - a).cross(c - a);
        for &v in t {
            n[v as usize] += face;
        }
    }
    n.iter().map(|v| v.normalize_or(Vec3::Y)).collect()
}

/// A `width × height` checkerboard of `cells × cells` squares, warm and
/// cool colours (linear RGB, alpha 1), brighter in the top-left cell so
/// that flips and rotations show.
pub fn checkerboard(width: u32, height: u32, cells: u32) -> Image {
    let cells = cells.max(1);
    let pixels = (0..height)
        .flat_map(|y| {
            (0..width).map(move |x| {
                let (cx, cy) = (x * cells / width.max(1), y * cells / height.max(1));
                if cx == 0 && cy == 0 {
                    [1.0, 0.9, 0.2, 1.0]
                } else if (cx + cy) % 2 == 0 {
                    [0.8, 0.25, 0.1, 1.0]
                } else {
                    [0.1, 0.3, 0.7, 1.0]
                }
            })
        })
        .collect();
    Image {
        width,
        height,
        pixels,
    }
}

/// Deterministic value noise in `[0, 1]`, five octaves, tiling at the
/// image's borders (grey, alpha 1).
pub fn noise(width: u32, height: u32, seed: u64) -> Image {
    let hash = |x: i64, y: i64, o: u64| {
        let mut z = seed
            ^ (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ o.wrapping_mul(0x1656_67B1_9E37_79F9);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let (mut value, mut amp, mut total) = (0.0, 1.0, 0.0);
            for o in 0..5u32 {
                let period = 4i64 << o;
                let fx = x as f32 / width.max(1) as f32 * period as f32;
                let fy = y as f32 / height.max(1) as f32 * period as f32;
                let (x0, y0) = (fx.floor() as i64, fy.floor() as i64);
                let (tx, ty) = (fx - x0 as f32, fy - y0 as f32);
                let s = |t: f32| t * t * (3.0 - 2.0 * t);
                let at =
                    |i: i64, j: i64| hash(i.rem_euclid(period), j.rem_euclid(period), u64::from(o));
                let top = at(x0, y0) + (at(x0 + 1, y0) - at(x0, y0)) * s(tx);
                let bottom = at(x0, y0 + 1) + (at(x0 + 1, y0 + 1) - at(x0, y0 + 1)) * s(tx);
                value += amp * (top + (bottom - top) * s(ty));
                total += amp;
                amp *= 0.5;
            }
            let v = value / total;
            pixels.push([v, v, v, 1.0]);
        }
    }
    Image {
        width,
        height,
        pixels,
    }
}

/// A synthetic sky as an equirectangular HDR map (row 0 is the zenith):
/// a blue gradient, a dark ground, and a sun about 10⁴ times brighter than
/// the sky — a peaky density, like a real beach map.
pub fn sky(width: u32, height: u32) -> Image {
    let sun = Vec3::new(0.6, 0.55, 0.3).normalize();
    let mut pixels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        let theta = (y as f32 + 0.5) / height as f32 * PI;
        for x in 0..width {
            let phi = (x as f32 + 0.5) / width as f32 * TAU;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            let px = if d.y < 0.0 {
                [0.08, 0.07, 0.05, 1.0]
            } else {
                let t = d.y;
                [0.3 + 0.3 * (1.0 - t), 0.5 + 0.25 * (1.0 - t), 0.9, 1.0]
            };
            let c = d.dot(sun);
            let glow = if c > 0.999 {
                5_000.0
            } else {
                2.0 * (40.0 * (c - 1.0)).exp()
            };
            pixels.push([px[0] + glow, px[1] + glow * 0.95, px[2] + glow * 0.85, 1.0]);
        }
    }
    Image {
        width,
        height,
        pixels,
    }
}
