//! UVs that tile the texture many times (game assets, raw scan
//! parameterisations in [−8, 8]²): preprocessing stays bounded, a
//! constant density is one piece per triangle, the piece budget holds,
//! and the exact mode stays exact when the budget coarsens it.

use test_support::stats;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    DEFAULT_MAX_PIECES, Density, DensitySampler, DensityTexture, MeshRef, Mode, Options,
    RejectionSampler, SurfaceSampler,
};

/// Positions, UVs and triangles.
type Mesh = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

/// An `n × n` grid over a bumpy unit square, UVs over `[lo, hi]²`.
fn grid(n: u32, lo: f32, hi: f32) -> Mesh {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            positions.push(Vec3::new(s, t, 0.1 * (7.0 * s).sin() * (5.0 * t).cos()));
            uvs.push(Vec2::new(lo + (hi - lo) * s, lo + (hi - lo) * t));
        }
    }
    let at = |x: u32, y: u32| y * (n + 1) + x;
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x + 1, y), at(x, y + 1)]);
            indices.push([at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    (positions, uvs, indices)
}

fn noise(w: usize, h: usize) -> DensityTexture {
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            1.05 + 0.5 * (6.0 * x + 1.0).sin() * (4.0 * y).cos() + 0.45 * (9.0 * x * y).sin()
        })
        .collect();
    DensityTexture::new(w, h, texels).unwrap()
}

/// A 1024² constant texture tiled 256 times: one piece per triangle (found
/// without visiting the texels), the uniform density, and the exact mode
/// and rejection sampling integrate it in O(1) per triangle.
#[test]
fn a_constant_density_over_tiled_uvs_is_one_piece_per_triangle() {
    let (p, uv, i) = grid(64, -8.0, 8.0);
    let mesh = MeshRef {
        uvs: Some(&uv),
        ..MeshRef::new(&p, &i)
    };
    let t = DensityTexture::new(1024, 1024, vec![3.0; 1024 * 1024]).unwrap();
    let area = mesh_sampling::UniformSampler::new(mesh)
        .unwrap()
        .total_area();
    for mode in [Mode::Approximate, Mode::Exact] {
        let options = Options {
            mode,
            ..Options::default()
        };
        let s = DensitySampler::with_options(mesh, Density::Texture(&t), &options).unwrap();
        assert_eq!(s.pieces(), i.len(), "{mode:?}");
        assert!((s.acceptance() - 1.0).abs() < 1e-9);
        for q in s.sample_n(1, 1000).unwrap() {
            assert!((f64::from(q.pdf) * area - 1.0).abs() < 1e-4);
        }
    }
    let r = RejectionSampler::new(mesh, &t).unwrap();
    assert!((r.total_mass() - 3.0 * area).abs() < 1e-9 * area);
}

/// A varying texture tiled 256 times: the depths ask for more pieces than
/// the budget, the subdivision is capped to fit (`Σ 4^L ≤ max_pieces`,
/// the deepest triangles first), and the exact mode still samples the
/// exact density (chi-square of per-triangle counts against the exact
/// integrals).
#[test]
fn tiled_uvs_are_capped_by_the_piece_budget_and_exact_stays_exact() {
    let (p, uv, i) = grid(16, -8.0, 8.0);
    let mesh = MeshRef {
        uvs: Some(&uv),
        ..MeshRef::new(&p, &i)
    };
    let t = noise(64, 64);
    let budget = 1 << 12;
    // Unlimited, each triangle (2 UV units² · 64² texels / 2 = 4,096
    // texels) would be at level 6: 512 · 4^6 = 2,097,152 pieces.
    let free = Options {
        max_pieces: usize::MAX,
        ..Options::default()
    };
    let full = DensitySampler::with_options(mesh, Density::Texture(&t), &free).unwrap();
    assert!((0..i.len()).all(|f| full.level(f) == 6));
    for mode in [Mode::Approximate, Mode::Exact] {
        let options = Options {
            mode,
            max_pieces: budget,
            ..Options::default()
        };
        let s = DensitySampler::with_options(mesh, Density::Texture(&t), &options).unwrap();
        let sum: usize = (0..i.len()).map(|f| 1usize << (2 * s.level(f))).sum();
        assert!(sum <= budget && s.pieces() <= budget, "{mode:?}: {sum}");
        // 512 · 4^2 = 8,192 > 4,096: level 1 for all.
        assert!((0..i.len()).all(|f| s.level(f) == 1), "{mode:?}");
        let points = s.sample_n(3, 400_000).unwrap();
        for q in points.iter().take(2000) {
            let pdf = s.pdf(q.face as usize, q.barycentric);
            assert!((pdf - q.pdf).abs() <= 1e-3 * q.pdf.max(1e-3), "{mode:?}");
        }
        if mode == Mode::Exact {
            let mut counts = vec![0u64; i.len()];
            for q in &points {
                counts[q.face as usize] += 1;
            }
            let masses: Vec<f64> = i
                .iter()
                .map(|tri| {
                    let u = tri.map(|k| uv[k as usize].as_dvec2());
                    let c = tri.map(|k| p[k as usize].as_dvec3());
                    let uv_area = 0.5 * (u[1] - u[0]).perp_dot(u[2] - u[0]).abs();
                    let area = 0.5 * (c[1] - c[0]).cross(c[2] - c[0]).length();
                    t.integral(u) * area / uv_area
                })
                .collect();
            let test = stats::chi_square(&counts, &stats::probabilities(&masses), 20.0);
            assert!(test.p_value > 1e-3, "{test:?}");
        }
    }
    // The default budget holds a 1024² noise tiled over [−8, 8]² on this
    // mesh: its 512 triangles want level 10 (4^10 texels each).
    let big = noise(1024, 1024);
    let wanted: usize = 512 << 20;
    assert!(wanted > DEFAULT_MAX_PIECES);
    let s = DensitySampler::new(mesh, Density::Texture(&big)).unwrap();
    assert!(s.pieces() <= DEFAULT_MAX_PIECES);
    assert!(s.memory_bytes() < 64 * DEFAULT_MAX_PIECES);
}
