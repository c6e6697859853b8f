//! Budgets checked before allocating, and no panic on extreme arguments:
//! zero, subnormal, huge and NaN values and out-of-range indices fed to
//! every constructor, lookup, edit and bake (fixed seed).

use crate::support;

use glam::{Vec2, Vec3};
use mesh_colors::{
    Blend, Brush, Error, MAX_SAMPLE_VALUES, MeshColors, Painter, Texture, Topology, Wrap, atlas,
    convert, luminance,
};
use support::Rng;

#[test]
fn mesh_colours_beyond_the_budget_are_refused_before_allocating() {
    // 5000 faces at R = 1024 (about 2.6 · 10⁹ samples): the error names the
    // count; nothing of that size is allocated.
    let faces: Vec<[u32; 3]> = (0..5000u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    let topology = Topology::new(15_000, &faces).unwrap();
    match MeshColors::uniform(topology.clone(), 1024, 3) {
        Err(Error::TooLarge {
            requested, budget, ..
        }) => {
            assert_eq!(budget, MAX_SAMPLE_VALUES);
            assert!(requested > budget);
        }
        other => panic!("expected TooLarge, got {:?}", other.map(|_| ())),
    }
    let e = MeshColors::uniform(topology, 1024, 3)
        .unwrap_err()
        .to_string();
    assert!(e.contains("1073741824"), "{e}");
    // A vertex count no memory holds, with no faces at all.
    let huge = Topology::new(usize::MAX / 2, &[]).unwrap();
    assert!(matches!(
        MeshColors::new(huge, &[], 1),
        Err(Error::TooLarge { .. })
    ));
}

#[test]
fn atlas_and_gutter_sizes_are_checked_before_allocating() {
    let (positions, faces) = support::grid(2, 0.0);
    let mc = MeshColors::uniform(Topology::new(positions.len(), &faces).unwrap(), 4, 3).unwrap();
    for gutter in [atlas::MAX_GUTTER + 1, u32::MAX] {
        let e = atlas::bake(
            &mc,
            &atlas::Options {
                gutter,
                ..Default::default()
            },
        )
        .unwrap_err();
        assert!(matches!(e, Error::TooLarge { .. }), "{e}");
        assert!(e.to_string().contains(&gutter.to_string()), "{e}");
    }
    // 40 blocks with the widest gutter: about 52 000 texels a side, past
    // the side limit, which the error names.
    let many: Vec<[u32; 3]> = (0..40u32).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
    let mc = MeshColors::uniform(Topology::new(120, &many).unwrap(), 4, 1).unwrap();
    let e = atlas::bake(
        &mc,
        &atlas::Options {
            gutter: atlas::MAX_GUTTER,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            Error::TooLarge {
                budget: atlas::MAX_SIDE,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("atlas side"), "{e}");
    // Within the budget it bakes.
    assert!(atlas::bake(&mc, &atlas::Options::default()).is_ok());
}

const EXTREMES: [f32; 12] = [
    0.0,
    -0.0,
    1e-45,
    1e-38,
    0.5,
    1.0,
    -1.0,
    1e30,
    f32::MAX,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::NAN,
];

fn pick(rng: &mut Rng) -> f32 {
    if rng.below(3) == 0 {
        rng.f32() * 4.0 - 2.0
    } else {
        EXTREMES[rng.below(EXTREMES.len() as u64) as usize]
    }
}

fn index(rng: &mut Rng, n: usize) -> usize {
    [
        0,
        n.saturating_sub(1),
        n,
        usize::MAX,
        rng.below(n as u64 + 1) as usize,
    ][rng.below(5) as usize]
}

#[test]
fn extreme_arguments_give_errors_or_answers_never_panics() {
    let mut rng = Rng(99);
    let (positions, faces) = support::grid(3, 0.3);
    for round in 0..400 {
        let channels = [0usize, 1, 3, 64, 65][round % 5];
        let resolutions: Vec<u32> = (0..faces.len())
            .map(|_| [0u32, 1, 2, 3, 8, 2048, u32::MAX][rng.below(7) as usize])
            .collect();
        let topology = Topology::new(positions.len(), &faces).unwrap();
        let _ = Topology::new(index(&mut rng, 40), &faces);
        let Ok(mut mc) = MeshColors::new(topology.clone(), &resolutions, channels)
            .or_else(|_| MeshColors::uniform(topology.clone(), 4, 3))
        else {
            panic!("a valid layout was refused");
        };
        let c = mc.channels();
        let n = mc.face_count();
        let mut out = vec![0.0f32; c];
        for _ in 0..10 {
            let f = index(&mut rng, n);
            let b = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
            let _ = mc.nearest(f, b, &mut out);
            let _ = mc.linear(f, b, &mut out);
            let _ = mc.linear(f, b, &mut out[..0]);
            let _ = (mc.face_resolution(f), mc.face_level(f), mc.face_index(f));
            let _ = (mc.edge_resolution(f), mc.edge_index(f), mc.vertex_index(f));
            let _ = mc.sample(index(&mut rng, mc.sample_count()));
            let _ = mc.sample_mut(index(&mut rng, mc.sample_count()));
            let a = [rng.below(9) as u32, u32::MAX, rng.below(3) as u32];
            let _ = mc.lattice_index(f, a);
            let _ = mesh_colors::edit::child_of(b);
        }
        for x in mc.samples_mut() {
            *x = pick(&mut rng);
        }
        let mip = mc.mip_map();
        for _ in 0..10 {
            let f = index(&mut rng, n);
            let b = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
            let _ = mip.trilinear(f, b, pick(&mut rng), &mut out);
            let _ = mip.at_level(f, b, rng.below(20) as u8, &mut out);
            let d = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
            let _ = mip.anisotropic(f, b, d, d, rng.below(100) as u32, &mut out);
        }
        let points: Vec<(u32, [f32; 3])> = (0..8)
            .map(|_| (index(&mut rng, n) as u32, [pick(&mut rng); 3]))
            .collect();
        let mut batch = vec![0.0f32; points.len() * c];
        let _ = mc.linear_into(&points, &mut batch);
        let _ = mip.trilinear_into(&points, &[pick(&mut rng); 8], &mut batch);
        let _ = mc.linear_into(&points, &mut batch[..1]);

        // Edits.
        let _ = mc.set_face_resolution(index(&mut rng, n), [0, 3, 4, 4096, u32::MAX][round % 5]);
        let _ = mc.delete_faces(&[index(&mut rng, n), index(&mut rng, n)]);
        let _ = mc.add_faces(&[[0, 1, 2]], &[2], index(&mut rng, 20));
        if round % 20 == 0 {
            let _ = mc.subdivide();
        }

        // Painting with odd positions, cells and brushes.
        let moved: Vec<Vec3> = positions
            .iter()
            .map(|&p| {
                if rng.below(40) == 0 {
                    Vec3::splat(pick(&mut rng))
                } else {
                    p
                }
            })
            .collect();
        if let Ok(painter) = Painter::new(&mc, &moved, pick(&mut rng)) {
            let color = vec![pick(&mut rng); c];
            let brush = Brush {
                center: Vec3::new(pick(&mut rng), 0.5, 0.0),
                radius: pick(&mut rng),
                color: &color,
                strength: pick(&mut rng),
                blend: if round % 2 == 0 {
                    Blend::Mix
                } else {
                    Blend::Add
                },
            };
            let _ = painter.paint(&mut mc, &brush);
        }

        // Textures, conversion and baking.
        let (w, h) = (1 + rng.below(4) as usize, 1 + rng.below(4) as usize);
        let data: Vec<f32> = (0..w * h * c).map(|_| pick(&mut rng)).collect();
        let _ = Texture::new(w, h, c, data.clone()).map(|t| t.with_wrap(Wrap::MirroredRepeat));
        let _ = Texture::new(usize::MAX, 2, c, data.clone());
        let _ = Texture::new(w, h, 0, Vec::new());
        if let Ok(mut t) = Texture::new(w, h, c, data) {
            t.build_mips();
            for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
                let t = t.clone().with_wrap(wrap);
                t.bilinear([pick(&mut rng), pick(&mut rng)], &mut out);
                t.trilinear([pick(&mut rng), pick(&mut rng)], pick(&mut rng), &mut out);
                let _ = t.texel(index(&mut rng, w), index(&mut rng, h));
            }
            let uvs: Vec<[Vec2; 3]> = (0..faces.len())
                .map(|_| [Vec2::new(pick(&mut rng), pick(&mut rng)); 3])
                .collect();
            let options = convert::Options {
                density: f64::from(pick(&mut rng)),
                max_level: rng.below(12) as u8,
                max_samples: [None, Some(0), Some(usize::MAX)][round % 3],
            };
            let _ = convert::from_texture(topology.clone(), &uvs, &t, &options);
            let _ = convert::fill(&mut mc, &uvs[1..], &t);
            let _ = convert::psnr(&mc, &uvs, &t, &points, f64::from(pick(&mut rng)));
        }
        let _ = atlas::bake(
            &mc,
            &atlas::Options {
                gutter: rng.below(6) as u32,
                // MIP-safe packing at the clamp (8 levels: 256-texel
                // blocks) is slow to fill; once is enough.
                mip_levels: if round == 7 {
                    u32::MAX
                } else {
                    [0, 1, 2][round % 3]
                },
            },
        );
        let _ = luminance([pick(&mut rng); 3]);
    }
}
