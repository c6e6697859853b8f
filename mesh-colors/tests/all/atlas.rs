//! Mesh colours → atlas texture: bilinear lookups at the new UVs reproduce
//! the linear filter (exactly for affine colours), agree across edges, and
//! the texture → mesh colours → texture round trip keeps the image.

use crate::data;
use crate::support;

use glam::Vec3;
use mesh_colors::{MeshColors, Topology, atlas, convert};
use support::Rng;

fn atlas_at(a: &atlas::Atlas, f: usize, b: [f32; 3], out: &mut [f32]) {
    let uv = a.corner_uvs[f];
    let p = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
    a.texture.bilinear(p.into(), out);
}

#[test]
fn bilinear_atlas_lookups_match_the_linear_filter_and_have_no_seams() {
    let (positions, faces) = support::grid(6, 0.4);
    let mut rng = Rng(8);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << rng.below(5)).collect();
    let mut mc =
        MeshColors::new(Topology::new(positions.len(), &faces).unwrap(), &levels, 3).unwrap();
    let affine = |p: Vec3| [0.2 + p.x - 0.5 * p.y + p.z, 0.5 * p.y, 1.0 - p.x];
    mc.fill(&positions, |p, out| {
        out.copy_from_slice(&affine(p.as_vec3()))
    })
    .unwrap();
    let baked = atlas::bake(&mc, &atlas::Options::default()).unwrap();
    let texels = baked.texture.width() * baked.texture.height();
    assert!(
        texels < 3 * mc.sample_count(),
        "{texels} texels for {} samples",
        mc.sample_count()
    );
    let (mut a, mut b) = ([0.0f32; 3], [0.0f32; 3]);
    let mut worst = 0.0f32;
    for _ in 0..100_000 {
        let f = rng.below(faces.len() as u64) as usize;
        let bary = rng.barycentric();
        mc.linear(f, bary, &mut a).unwrap();
        atlas_at(&baked, f, bary, &mut b);
        worst = worst.max((0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max));
    }
    assert!(worst < 2e-5, "affine colours: atlas differs by {worst}");
    // Random colours: both sides of every edge read the same atlas values.
    for x in mc.samples_mut() {
        *x = rng.f32();
    }
    let baked = atlas::bake(
        &mc,
        &atlas::Options {
            gutter: 2,
            ..Default::default()
        },
    )
    .unwrap();
    let t = mc.topology();
    let mut seam = 0.0f32;
    for (e, fs) in t.edge_faces().iter().enumerate() {
        if fs[1] == mesh_colors::NO_FACE {
            continue;
        }
        let [va, vb] = t.edges()[e];
        for s in 0..=32 {
            let s = s as f32 / 32.0;
            let bary = |f: u32| {
                t.faces()[f as usize].map(|v| {
                    if v == va {
                        1.0 - s
                    } else if v == vb {
                        s
                    } else {
                        0.0
                    }
                })
            };
            atlas_at(&baked, fs[0] as usize, bary(fs[0]), &mut a);
            atlas_at(&baked, fs[1] as usize, bary(fs[1]), &mut b);
            seam = seam.max((0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max));
        }
    }
    assert!(seam < 1e-4, "seam of {seam} in the atlas");
}

#[test]
fn mip_safe_atlas_levels_have_no_seams_for_affine_colours() {
    let (positions, faces) = support::grid(5, 0.4);
    let mut rng = Rng(12);
    let levels: Vec<u32> = (0..faces.len()).map(|_| 1 << (1 + rng.below(4))).collect();
    let mut mc =
        MeshColors::new(Topology::new(positions.len(), &faces).unwrap(), &levels, 2).unwrap();
    let affine = |p: Vec3| [0.2 + p.x - 0.5 * p.y + p.z, 0.5 * p.y - 0.3 * p.x];
    mc.fill(&positions, |p, out| {
        out.copy_from_slice(&affine(p.as_vec3()))
    })
    .unwrap();
    let (mut a, mut b) = ([0.0f32; 2], [0.0f32; 2]);
    let worst_at =
        |baked: &atlas::Atlas, lod: f32, rng: &mut Rng, a: &mut [f32; 2], b: &mut [f32; 2]| {
            let mut texture = baked.texture.clone();
            texture.build_mips();
            let mut worst = 0.0f32;
            for _ in 0..20_000 {
                let f = rng.below(faces.len() as u64) as usize;
                let bary = rng.barycentric();
                mc.linear(f, bary, a).unwrap();
                let uv = baked.corner_uvs[f];
                let p = bary[0] * uv[0] + bary[1] * uv[1] + bary[2] * uv[2];
                texture.trilinear(p.into(), lod, b);
                worst = worst.max((a[0] - b[0]).abs().max((a[1] - b[1]).abs()));
            }
            worst
        };
    let safe = atlas::bake(
        &mc,
        &atlas::Options {
            mip_levels: 2,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(safe.texture.width() % 4, 0);
    for lod in [0.0, 1.0, 1.5, 2.0] {
        let worst = worst_at(&safe, lod, &mut rng, &mut a, &mut b);
        assert!(worst < 1e-4, "MIP-safe atlas at lod {lod}: {worst}");
    }
    // The compact packing is right at level 0 but bleeds at level 2: the
    // test can tell the difference.
    let compact = atlas::bake(&mc, &atlas::Options::default()).unwrap();
    assert!(worst_at(&compact, 0.0, &mut rng, &mut a, &mut b) < 1e-4);
    assert!(worst_at(&compact, 2.0, &mut rng, &mut a, &mut b) > 1e-2);
}

/// Texture → mesh colours → atlas on the real textured meshes: the round
/// trip PSNR against the source must stay above the conversion's own
/// 35 dB bar: the atlas adds only the bilinear twist term, measured at
/// 50–59 dB against the mesh colours, so it cannot cost more than a
/// fraction of a dB on top of the conversion error.
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn texture_round_trip_psnr_on_real_meshes() {
    let dir = data::data_dir().expect("TRILUX_DATA must name the data folder for this test");
    for m in data::textured_meshes(&dir) {
        if m.name == "BoxTextured" {
            continue; // tiles its texture six times; see the convert test
        }
        let topology = Topology::new(m.positions.len(), &m.faces).unwrap();
        let mc = convert::from_texture(topology, &m.corner_uvs, &m.texture, &Default::default())
            .unwrap();
        let baked = atlas::bake(&mc, &atlas::Options::default()).unwrap();
        let points = data::surface_points(&m.positions, &m.faces, 200_000, 3);
        let (mut src, mut got, mut lin) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3]);
        let (mut se_trip, mut se_atlas) = (0.0f64, 0.0f64);
        for &(f, b) in &points {
            let uv = m.corner_uvs[f as usize];
            let p = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
            m.texture.bilinear(p.into(), &mut src);
            atlas_at(&baked, f as usize, b, &mut got);
            mc.linear(f as usize, b, &mut lin).unwrap();
            for c in 0..3 {
                se_trip += f64::from(got[c] - src[c]).powi(2);
                se_atlas += f64::from(got[c] - lin[c]).powi(2);
            }
        }
        let psnr = |se: f64| 10.0 * (1.0 / (se / (3 * points.len()) as f64)).log10();
        let texels = baked.texture.width() * baked.texture.height();
        eprintln!(
            "{}: atlas {}×{} ({texels} texels for {} colours), round trip {:.2} dB, atlas vs mesh colours {:.2} dB",
            m.name,
            baked.texture.width(),
            baked.texture.height(),
            mc.sample_count(),
            psnr(se_trip),
            psnr(se_atlas)
        );
        assert!(
            psnr(se_trip) > 35.0,
            "{}: round trip {:.2} dB",
            m.name,
            psnr(se_trip)
        );
        // The MIP-safe packing: the same at level 0, at about twice the texels.
        let safe = atlas::bake(
            &mc,
            &atlas::Options {
                mip_levels: 2,
                ..Default::default()
            },
        )
        .unwrap();
        let mut se_safe = 0.0f64;
        for &(f, b) in &points {
            let uv = m.corner_uvs[f as usize];
            let p = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
            m.texture.bilinear(p.into(), &mut src);
            atlas_at(&safe, f as usize, b, &mut got);
            se_safe += (0..3)
                .map(|c| f64::from(got[c] - src[c]).powi(2))
                .sum::<f64>();
        }
        eprintln!(
            "{}: MIP-safe atlas (2 levels) {}×{}, round trip {:.2} dB",
            m.name,
            safe.texture.width(),
            safe.texture.height(),
            psnr(se_safe)
        );
        assert!(psnr(se_safe) > 35.0);
    }
}
