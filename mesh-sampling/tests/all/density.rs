//! Density sampling: checkerboards, smooth noise, HDR images and tiled
//! textures against independently computed probabilities; exact mode
//! against rejection sampling; per-face and per-vertex weights; pdfs;
//! determinism; errors.

use test_support::stats;

use glam::{DVec2, Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Error, Filter, Layout, MeshRef, Mode, Options,
    RejectionSampler, SurfacePoint, SurfaceSampler, UniformSampler, Wrap,
};

/// Positions, UVs and triangles.
type Mesh = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

/// An `n × n` grid over UV `[0, 1]²` (then mapped by `uv_map`), whose 3D
/// surface is warped and bumped so that triangle areas differ.
fn grid(n: usize, uv_map: impl Fn(Vec2) -> Vec2) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = 0.15 * (7.0 * s).sin() * (5.0 * t).cos() + 0.1 * s * t;
            positions.push(Vec3::new(s.powf(1.3), t, z));
            uvs.push(uv_map(Vec2::new(s, t)));
        }
    }
    let mut indices = Vec::new();
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x + 1, y), at(x, y + 1)]);
            indices.push([at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    (positions, uvs, indices)
}

fn mesh_ref(m: &Mesh) -> MeshRef<'_> {
    MeshRef {
        uvs: Some(&m.1),
        ..MeshRef::new(&m.0, &m.2)
    }
}

/// A smooth positive density: a few sines, values in about [0.1, 2].
fn noise(w: usize, h: usize) -> DensityTexture {
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 / w as f32, (i / w) as f32 / h as f32);
            1.05 + 0.5 * (6.0 * x + 1.0).sin() * (4.0 * y).cos() + 0.45 * (9.0 * x * y).sin()
        })
        .collect();
    DensityTexture::new(w, h, texels).unwrap()
}

/// Our own bilinear lookup (repeat), independent of the library's.
fn bilinear(t: &DensityTexture, uv: DVec2) -> f64 {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let (x, y) = (uv.x * w as f64 - 0.5, uv.y * h as f64 - 0.5);
    let (x0, y0) = (x.floor(), y.floor());
    let texel =
        |i: i64, j: i64| f64::from(t.texels()[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize]);
    let (i, j) = (x0 as i64, y0 as i64);
    let (fx, fy) = (x - x0, y - y0);
    let top = texel(i, j) * (1.0 - fx) + texel(i + 1, j) * fx;
    let bottom = texel(i, j + 1) * (1.0 - fx) + texel(i + 1, j + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

fn area(p: [Vec3; 3]) -> f64 {
    let [a, b, c] = p.map(Vec3::as_dvec3);
    0.5 * (b - a).cross(c - a).length()
}

/// The paper's `p′` mass per texel, computed from scratch: every face cut
/// into `4^L` sub-triangles (L from the texels covered and the longest
/// UV edge), each
/// weighted by the bilinear density at its barycenter times its area, and
/// binned by the texel its barycenter lies in.
fn approximate_bin_masses(m: &Mesh, t: &DensityTexture) -> Vec<f64> {
    let (w, h) = (t.width(), t.height());
    let mut bins = vec![0.0; w * h];
    for tri in &m.2 {
        let uv = tri.map(|i| m.1[i as usize].as_dvec2());
        // Šik & Křivánek Sec. 3.4: sub-triangles no larger than a texel
        // (texels / 4^L ≤ 1); and 2^L ≥ longest edge / 2 texels.
        let tx = uv.map(|p| p * DVec2::new(w as f64, h as f64));
        let texels = 0.5 * (tx[1] - tx[0]).perp_dot(tx[2] - tx[0]).abs();
        let longest = (0..3)
            .map(|k| (tx[(k + 1) % 3] - tx[k]).length())
            .fold(0.0, f64::max);
        let mut level = 0u32;
        while texels / 4f64.powi(level as i32) > 1.0 || f64::from(1u32 << level) < longest / 2.0 {
            level += 1;
        }
        let n = 1u32 << level;
        let sub_area = area(tri.map(|i| m.0[i as usize])) / f64::from(n * n);
        for i in 0..n {
            for j in 0..n - i {
                let mut centres = vec![(f64::from(i) + 1.0 / 3.0, f64::from(j) + 1.0 / 3.0)];
                if i + j + 1 < n {
                    centres.push((f64::from(i) + 2.0 / 3.0, f64::from(j) + 2.0 / 3.0));
                }
                for (a, b) in centres {
                    let (u, v) = (a / f64::from(n), b / f64::from(n));
                    let p = uv[0] + (uv[1] - uv[0]) * u + (uv[2] - uv[0]) * v;
                    bins[texel_of(t, p)] += bilinear(t, p) * sub_area;
                }
            }
        }
    }
    bins
}

/// The texel (repeat) a UV lies in.
fn texel_of(t: &DensityTexture, uv: DVec2) -> usize {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let x = ((uv.x * w as f64).floor() as i64).rem_euclid(w);
    let y = ((uv.y * h as f64).floor() as i64).rem_euclid(h);
    (y * w + x) as usize
}

/// The UV of a sample, from its barycentrics, in f64.
fn uv_of(m: &Mesh, p: &SurfacePoint) -> DVec2 {
    let [a, b, c] = m.2[p.face as usize].map(|i| m.1[i as usize].as_dvec2());
    let [_, u, v] = p.barycentric.map(f64::from);
    a + (b - a) * u + (c - a) * v
}

fn texel_counts(m: &Mesh, t: &DensityTexture, points: &[SurfacePoint]) -> Vec<u64> {
    let mut counts = vec![0u64; t.width() * t.height()];
    for p in points {
        counts[texel_of(t, uv_of(m, p))] += 1;
    }
    counts
}

fn face_counts(faces: usize, points: &[SurfacePoint]) -> Vec<u64> {
    let mut counts = vec![0u64; faces];
    for p in points {
        counts[p.face as usize] += 1;
    }
    counts
}

/// Exact per-face masses of the bilinear texture (the texture's clipped
/// integral, itself checked against quadrature in the unit tests).
fn exact_face_masses(m: &Mesh, t: &DensityTexture) -> Vec<f64> {
    m.2.iter()
        .map(|tri| {
            let uv = tri.map(|i| m.1[i as usize].as_dvec2());
            let uv_area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs();
            t.integral(uv) * area(tri.map(|i| m.0[i as usize])) / uv_area
        })
        .collect()
}

fn exact() -> Options {
    Options {
        mode: Mode::Exact,
        ..Options::default()
    }
}

const N: usize = 1_000_000;

#[test]
fn checkerboards_put_no_point_in_a_black_texel_and_split_white_by_area() {
    for k in [2usize, 8] {
        let texels = (0..k * k).map(|i| ((i % k + i / k) % 2) as f32).collect();
        let t = DensityTexture::new(k, k, texels)
            .unwrap()
            .with_filter(Filter::Nearest);
        let m = grid(16, |uv| uv);
        // Expected: the 3D area of each texel's triangles (the grid is
        // aligned with the texels, so each triangle lies in one).
        let mut expected = vec![0.0; k * k];
        for tri in &m.2 {
            let uv = tri.map(|i| m.1[i as usize].as_dvec2());
            let texel = texel_of(&t, (uv[0] + uv[1] + uv[2]) / 3.0);
            expected[texel] += area(tri.map(|i| m.0[i as usize])) * f64::from(t.texels()[texel]);
        }
        for options in [Options::default(), exact()] {
            let sampler =
                DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &options).unwrap();
            let points = sampler.sample_n(3, 200_000).unwrap();
            let counts = texel_counts(&m, &t, &points);
            for (texel, &c) in counts.iter().enumerate() {
                assert!(
                    t.texels()[texel] > 0.0 || c == 0,
                    "{k}×{k} {:?}: {c} points in black texel {texel}",
                    options.mode
                );
            }
            let test = stats::chi_square(&counts, &stats::probabilities(&expected), 20.0);
            assert!(test.p_value > 1e-3, "{k}×{k} {:?}: {test:?}", options.mode);
        }
    }
}

#[test]
fn approximate_mode_samples_the_papers_p_prime() {
    let t = noise(16, 16);
    let m = grid(8, |uv| uv);
    let expected = approximate_bin_masses(&m, &t);
    for layout in [Layout::Alias, Layout::Inversion] {
        let options = Options {
            layout,
            ..Options::default()
        };
        let sampler =
            DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &options).unwrap();
        assert_eq!(sampler.layout(), layout);
        assert!((0..m.2.len()).all(|f| sampler.level(f) == 1));
        let counts = texel_counts(&m, &t, &sampler.sample_n(5, N).unwrap());
        let test = stats::chi_square(&counts, &stats::probabilities(&expected), 20.0);
        assert!(test.p_value > 1e-3, "{layout:?}: {test:?}");
        // The normalisation is Σ f_i |D_i| (Eq. 2).
        let total: f64 = expected.iter().sum();
        assert!((sampler.total_mass() - total).abs() < 1e-5 * total);
    }
}

/// Šik & Křivánek Sec. 3.4: "each triangle is subdivided so that its
/// sub-triangles are smaller than a texel of the density texture mapped
/// on the triangle". The reference level is written from that sentence
/// (and from the documented edge rule: no sub-triangle edge longer than
/// two texels), by counting up, not from the implementation's logarithms.
#[test]
fn subdivision_depth_follows_the_papers_rule() {
    let t = noise(256, 128);
    let (w, h) = (256.0, 128.0);
    // Triangles of many sizes and shapes in UV space.
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    let mut indices = Vec::new();
    let mut rng = 0x2545_F491_4F6C_DD1Du64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f32 / (1u64 << 53) as f32
    };
    for k in 0..300 {
        let scale = 10f32.powf(-3.0 + 3.0 * k as f32 / 300.0);
        let base = Vec2::new(next(), next());
        let corners = [
            base,
            base + Vec2::new(next(), next() * 0.3) * scale,
            base + Vec2::new(next() * 0.3, next()) * scale,
        ];
        for c in corners {
            positions.push(Vec3::new(c.x, c.y, 0.0));
            uvs.push(c);
        }
        let i = 3 * k as u32;
        indices.push([i, i + 1, i + 2]);
    }
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    for depth in [
        mesh_sampling::Depth::AtMostOneTexel,
        mesh_sampling::Depth::Nearest,
    ] {
        let options = Options {
            depth,
            max_level: 13,
            max_pieces: usize::MAX,
            ..Options::default()
        };
        let s = DensitySampler::with_options(mesh, Density::Texture(&t), &options).unwrap();
        for (f, tri) in indices.iter().enumerate() {
            let p = tri.map(|i| uvs[i as usize].as_dvec2() * DVec2::new(w, h));
            let texels = 0.5 * (p[1] - p[0]).perp_dot(p[2] - p[0]).abs();
            let longest = (0..3)
                .map(|k| (p[(k + 1) % 3] - p[k]).length())
                .fold(0.0, f64::max);
            let mut by_edge = 0;
            while 2.0 * f64::from(1u32 << by_edge) < longest {
                by_edge += 1;
            }
            let fits = |l: i32| texels / 4f64.powi(l) <= 1.0;
            let by_area = match depth {
                // The smallest level whose sub-triangles fit in a texel.
                mesh_sampling::Depth::AtMostOneTexel => (0..).find(|&l| fits(l)).unwrap(),
                // One of the two levels around it: the one whose
                // sub-triangle size is nearer a texel, in log scale.
                _ => {
                    let up = (0..).find(|&l| fits(l)).unwrap();
                    let down = (up - 1).max(0);
                    let (a, b) = (texels / 4f64.powi(down), 4f64.powi(up) / texels);
                    if up > 0 && a < b { down } else { up }
                }
            };
            let expected = by_area.max(by_edge).min(13) as u8;
            assert_eq!(
                s.level(f),
                expected,
                "{depth:?}, face {f}: {texels} texels, edge {longest}"
            );
        }
    }
}

/// An affine UV map that aligns with nothing.
fn skewed(uv: Vec2) -> Vec2 {
    Vec2::new(
        0.83 * uv.x + 0.21 * uv.y + 0.07,
        -0.17 * uv.x + 0.91 * uv.y + 0.05,
    )
}

#[test]
fn exact_mode_matches_the_exact_integrals_per_triangle() {
    let t = noise(16, 16);
    let m = grid(6, skewed);
    let sampler =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &exact()).unwrap();
    let masses = exact_face_masses(&m, &t);
    let counts = face_counts(m.2.len(), &sampler.sample_n(6, N).unwrap());
    let test = stats::chi_square(&counts, &stats::probabilities(&masses), 20.0);
    assert!(test.p_value > 1e-3, "{test:?}");
    let total: f64 = masses.iter().sum();
    assert!((sampler.total_mass() - total).abs() < 1e-9 * total);
    assert!(sampler.acceptance() > 0.8, "{}", sampler.acceptance());
}

#[test]
fn tiled_and_clamped_uvs_outside_the_unit_square() {
    let t = noise(8, 8);
    // UVs over [−1, 2]²: nine tiles with repeat.
    let m = grid(12, |uv| uv * 3.0 - Vec2::ONE);
    for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
        let t = t.clone().with_wrap(wrap);
        let sampler =
            DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &exact()).unwrap();
        let masses = exact_face_masses(&m, &t);
        let counts = face_counts(m.2.len(), &sampler.sample_n(7, N).unwrap());
        let test = stats::chi_square(&counts, &stats::probabilities(&masses), 20.0);
        assert!(test.p_value > 1e-3, "{wrap:?}: {test:?}");
    }
    // With repeat, a flat mesh gives every tile the same mass.
    let flat: Mesh = {
        let (mut p, uv, i) = grid(12, |uv| uv * 3.0 - Vec2::ONE);
        for (q, s) in p.iter_mut().zip(&uv) {
            *q = Vec3::new(s.x, s.y, 0.0);
        }
        (p, uv, i)
    };
    let sampler = DensitySampler::new(mesh_ref(&flat), Density::Texture(&t)).unwrap();
    let mut tiles = [0u64; 9];
    for p in sampler.sample_n(8, 300_000).unwrap() {
        let uv = uv_of(&flat, &p);
        let (x, y) = ((uv.x + 1.0).floor() as usize, (uv.y + 1.0).floor() as usize);
        tiles[y.min(2) * 3 + x.min(2)] += 1;
    }
    let test = stats::chi_square(&tiles, &[1.0 / 9.0; 9], 20.0);
    assert!(test.p_value > 1e-3, "{tiles:?}");
}

/// Two-sample chi-square on equal sample sizes: Σ (a − b)² / (a + b).
fn two_sample_p(a: &[u64], b: &[u64]) -> f64 {
    let (mut stat, mut bins) = (0.0, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        if x + y > 0 {
            let d = x as f64 - y as f64;
            stat += d * d / (x + y) as f64;
            bins += 1;
        }
    }
    stats::gamma_q((bins - 1) as f64 / 2.0, stat / 2.0)
}

#[test]
fn exact_mode_and_rejection_sample_the_same_distribution() {
    // A contrasted density (max/mean about 8) on a skewed mapping.
    let base = noise(24, 24);
    let t = DensityTexture::new(24, 24, base.texels().iter().map(|v| v.powi(3)).collect()).unwrap();
    let m = grid(6, skewed);
    let mesh = mesh_ref(&m);
    let exact_points = DensitySampler::with_options(mesh, Density::Texture(&t), &exact())
        .unwrap()
        .sample_n(9, N)
        .unwrap();
    let rejection = RejectionSampler::new(mesh, &t).unwrap();
    let reject_points = rejection.sample_n(10, N).unwrap();
    let p = two_sample_p(
        &texel_counts(&m, &t, &exact_points),
        &texel_counts(&m, &t, &reject_points),
    );
    assert!(p > 1e-3, "exact vs rejection: p = {p:.2e}");
    // The same test tells the approximate p′ apart from the filtered
    // density on this sharp, misaligned texture at its coarsest depth.
    let coarse = Options {
        max_level: 1,
        ..Options::default()
    };
    let approximate = DensitySampler::with_options(mesh, Density::Texture(&t), &coarse)
        .unwrap()
        .sample_n(11, N)
        .unwrap();
    let p = two_sample_p(
        &texel_counts(&m, &t, &approximate),
        &texel_counts(&m, &t, &reject_points),
    );
    assert!(p < 1e-9, "the test cannot see p′ ≠ f: p = {p:.2e}");
    // Rejection's pdf is the exact normalised density too.
    let sampler = DensitySampler::with_options(mesh, Density::Texture(&t), &exact()).unwrap();
    for q in &reject_points[..1000] {
        let a = sampler.pdf(q.face as usize, q.barycentric);
        assert!((a - q.pdf).abs() <= 1e-4 * a, "{a} vs {}", q.pdf);
    }
}

#[test]
fn per_face_and_per_vertex_weights() {
    let m = grid(5, |uv| uv);
    let mesh = mesh_ref(&m);
    let face_w: Vec<f32> = (0..m.2.len()).map(|f| ((f * 7) % 5) as f32).collect();
    let sampler = DensitySampler::new(mesh, Density::PerFace(&face_w)).unwrap();
    let masses: Vec<f64> =
        m.2.iter()
            .zip(&face_w)
            .map(|(tri, &w)| f64::from(w) * area(tri.map(|i| m.0[i as usize])))
            .collect();
    let counts = face_counts(m.2.len(), &sampler.sample_n(12, 300_000).unwrap());
    let test = stats::chi_square(&counts, &stats::probabilities(&masses), 20.0);
    assert!(test.p_value > 1e-3, "per face: {test:?}");

    let vertex_w: Vec<f32> = (0..m.0.len())
        .map(|v| ((v * 3) % 4) as f32 + 0.5 * (v % 2) as f32)
        .collect();
    let sampler = DensitySampler::new(mesh, Density::PerVertex(&vertex_w)).unwrap();
    let masses: Vec<f64> =
        m.2.iter()
            .map(|tri| {
                let w: f64 = tri.iter().map(|&i| f64::from(vertex_w[i as usize])).sum();
                area(tri.map(|i| m.0[i as usize])) * w / 3.0
            })
            .collect();
    let counts = face_counts(m.2.len(), &sampler.sample_n(13, 300_000).unwrap());
    let test = stats::chi_square(&counts, &stats::probabilities(&masses), 20.0);
    assert!(test.p_value > 1e-3, "per vertex: {test:?}");
}

#[test]
fn stable_mode_counts_by_mass_and_keeps_untouched_triangles() {
    let m = grid(6, |uv| uv);
    let mesh = mesh_ref(&m);
    let face_w: Vec<f32> = (0..m.2.len()).map(|f| ((f * 7) % 5) as f32).collect();
    let rate = 3_000.0;
    let sampler = DensitySampler::new(mesh, Density::PerFace(&face_w)).unwrap();
    let before = sampler.sample_stable(5, rate).unwrap();
    // Each triangle gets rate · mass rounded down or up; none on weight 0.
    for (f, tri) in m.2.iter().enumerate() {
        let n = before.iter().filter(|p| p.face as usize == f).count() as f64;
        let expected = rate * f64::from(face_w[f]) * area(tri.map(|i| m.0[i as usize]));
        assert!(
            (n - expected.floor()).abs() < 1e-9 || (n - expected.ceil()).abs() < 1e-9,
            "face {f}: {n} for {expected}"
        );
    }
    // Reweighting triangle 0 moves none of the other points.
    let mut reweighted = face_w.clone();
    reweighted[0] = 4.5;
    let edited = DensitySampler::new(mesh, Density::PerFace(&reweighted)).unwrap();
    let after = edited.sample_stable(5, rate).unwrap();
    let others = |points: &[SurfacePoint]| -> Vec<(u32, [f32; 3])> {
        points
            .iter()
            .filter(|p| p.face != 0)
            .map(|p| (p.face, p.barycentric))
            .collect()
    };
    assert_eq!(others(&before), others(&after));
    assert_ne!(before.len(), after.len());
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(
        one.install(|| sampler.sample_stable(5, rate).unwrap()),
        before
    );
    assert!(sampler.sample_stable(5, f64::NAN).is_err());
    assert!(sampler.sample_stable(5, -2.0).is_err());

    // Exact mode thins the proposals: never on black, and the total keeps
    // rate · (exact mass) within a few standard deviations.
    let k = 8;
    let texels = (0..k * k).map(|i| ((i % k + i / k) % 2) as f32).collect();
    let t = DensityTexture::new(k, k, texels).unwrap();
    let m = grid(9, skewed);
    let sampler =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &exact()).unwrap();
    let rate = 200_000.0;
    let points = sampler.sample_stable(6, rate).unwrap();
    let expected: f64 = rate * exact_face_masses(&m, &t).iter().sum::<f64>();
    let n = points.len() as f64;
    assert!(
        (n - expected).abs() < 5.0 * expected.sqrt(),
        "{n} points for {expected}"
    );
    for p in &points {
        assert!(
            bilinear(&t, uv_of(&m, p)) > 0.0,
            "a point where the density is 0"
        );
    }
}

#[test]
fn a_linear_density_is_linear_inside_the_triangle() {
    // Weight on the first corner only: density ∝ b0, so b0 ~ Beta(2, 2)
    // (CDF 3x² − 2x³) and b1 has CDF 1 − (1 − x)³.
    let positions = [Vec3::ZERO, Vec3::X, Vec3::new(0.2, 1.3, 0.4)];
    let indices = [[0, 1, 2]];
    let w = [1.0, 0.0, 0.0];
    let sampler =
        DensitySampler::new(MeshRef::new(&positions, &indices), Density::PerVertex(&w)).unwrap();
    let points = sampler.sample_n(14, 200_000).unwrap();
    let bins = 20;
    for (corner, cdf) in [
        (
            0,
            (|x: f64| 3.0 * x * x - 2.0 * x * x * x) as fn(f64) -> f64,
        ),
        (1, |x: f64| 1.0 - (1.0 - x).powi(3)),
    ] {
        let mut counts = vec![0u64; bins];
        for p in &points {
            let b = f64::from(p.barycentric[corner]);
            counts[((b * bins as f64) as usize).min(bins - 1)] += 1;
        }
        let probs: Vec<f64> = (0..bins)
            .map(|k| cdf((k + 1) as f64 / bins as f64) - cdf(k as f64 / bins as f64))
            .collect();
        let test = stats::chi_square(&counts, &probs, 20.0);
        assert!(test.p_value > 1e-3, "corner {corner}: {test:?}");
    }
    // The pdf is linear: 2·b0/A·… normalised: ∫ b0 dA = A/3.
    let a = area(positions);
    for p in &points[..100] {
        let expected = f64::from(p.barycentric[0]) / (a / 3.0);
        assert!((f64::from(p.pdf) - expected).abs() < 1e-4 * expected.max(1.0));
    }
}

#[test]
fn pdfs_agree_with_the_samples_and_integrate_to_one() {
    let t = noise(16, 16);
    let m = grid(6, skewed);
    let mesh = mesh_ref(&m);
    let face_w: Vec<f32> = (0..m.2.len()).map(|f| (f % 3) as f32).collect();
    let vertex_w: Vec<f32> = (0..m.0.len()).map(|v| (v % 4) as f32).collect();
    let tolerant = Options {
        merge_tolerance: 0.2,
        ..Options::default()
    };
    let samplers = [
        DensitySampler::new(mesh, Density::Texture(&t)).unwrap(),
        DensitySampler::with_options(mesh, Density::Texture(&t), &tolerant).unwrap(),
        DensitySampler::with_options(mesh, Density::Texture(&t), &exact()).unwrap(),
        DensitySampler::new(mesh, Density::PerFace(&face_w)).unwrap(),
        DensitySampler::new(mesh, Density::PerVertex(&vertex_w)).unwrap(),
    ];
    let uniform = UniformSampler::new(mesh).unwrap();
    let probes = uniform.sample_n(15, 200_000).unwrap();
    for (k, s) in samplers.iter().enumerate() {
        for p in s.sample_n(16, 2000).unwrap() {
            let q = s.pdf(p.face as usize, p.barycentric);
            assert!(
                (q - p.pdf).abs() <= 1e-4 * q,
                "sampler {k}: {q} vs {}",
                p.pdf
            );
        }
        // E_uniform[pdf] · A = ∫ pdf dA = 1.
        let mean: f64 = probes
            .iter()
            .map(|p| f64::from(s.pdf(p.face as usize, p.barycentric)))
            .sum::<f64>()
            / probes.len() as f64;
        let integral = mean * uniform.total_area();
        assert!(
            (integral - 1.0).abs() < 0.01,
            "sampler {k}: ∫ pdf = {integral}"
        );
    }
    assert!(
        samplers[1].pieces() < samplers[0].pieces(),
        "a tolerance merges more"
    );
    assert_eq!(samplers[0].pdf(m.2.len(), [1.0, 0.0, 0.0]), 0.0);
    // Barycentrics outside the triangle are moved onto it; a point of it
    // is taken as it is.
    for s in &samplers {
        for f in [0, 7] {
            assert_eq!(s.pdf(f, [5.0, -3.0, -1.0]), s.pdf(f, [1.0, 0.0, 0.0]));
            let (a, b) = (
                s.pdf(f, [1.0, 2.0, -0.5]),
                s.pdf(f, [1.0 / 3.0, 2.0 / 3.0, 0.0]),
            );
            assert!((a - b).abs() <= 1e-6 * b, "{a} vs {b}");
            assert_eq!(s.pdf(f, [0.0; 3]), 0.0);
            assert_eq!(s.pdf(f, [-1.0, -1.0, -1.0]), 0.0);
            assert!(s.pdf(f, [0.2, 0.3, 0.5]) >= 0.0);
        }
    }
}

/// A mesh whose deep faces and many constant ones leave the alias
/// columns too few bits for all of a value's mantissa over a density
/// spanning forty binades: the values are rounded, and the table draws
/// and reports the rounded ones, within `value_tolerance` of the exact
/// ones (which the inversion layout keeps).
#[test]
fn rounded_values_are_drawn_and_reported_alike() {
    // Left half constant; right half 2^±20 (Nearest, so the left half's
    // faces are one piece each).
    let size = 1024;
    let texels: Vec<f32> = (0..size * size)
        .map(|i| {
            let (x, y) = (i % size, i / size);
            if x < size / 2 {
                1.0
            } else {
                (20.0 * ((x as f32 * 0.05).sin() * (y as f32 * 0.03).cos())).exp2()
            }
        })
        .collect();
    let t = DensityTexture::new(size, size, texels)
        .unwrap()
        .with_filter(Filter::Nearest);
    // u⁶ crowds most faces into the constant half; the last columns
    // stretch over the varying half and are subdivided deep.
    let m = grid(64, |uv| Vec2::new(uv.x.powi(6), uv.y));
    let mesh = mesh_ref(&m);
    for mode in [Mode::Approximate, Mode::Exact] {
        let options = |layout| Options {
            mode,
            layout,
            ..Options::default()
        };
        let alias =
            DensitySampler::with_options(mesh, Density::Texture(&t), &options(Layout::Alias))
                .unwrap();
        let exact_values =
            DensitySampler::with_options(mesh, Density::Texture(&t), &options(Layout::Inversion))
                .unwrap();
        let tolerance = alias.value_tolerance();
        assert_eq!(alias.layout(), Layout::Alias);
        assert!(
            tolerance > 0.0 && tolerance <= 2f64.powi(-13),
            "{mode:?}: tolerance {tolerance}, {} pieces, deepest {}",
            alias.pieces(),
            (0..m.2.len()).map(|f| alias.level(f)).max().unwrap()
        );
        assert_eq!(exact_values.value_tolerance(), 0.0);
        assert_eq!(alias.pieces(), exact_values.pieces());
        let mass = alias.total_mass() / exact_values.total_mass();
        assert!(
            (mass - 1.0).abs() <= 2.0 * tolerance,
            "{mode:?}: mass ratio {mass}"
        );
        for p in alias.sample_n(3, 20_000).unwrap() {
            // What is drawn is what is reported, …
            let q = alias.pdf(p.face as usize, p.barycentric);
            assert!((q - p.pdf).abs() <= 1e-6 * q, "{mode:?}: {q} vs {}", p.pdf);
            // … within the tolerance of the exact values (exact mode:
            // the filtered density, whatever the bounds).
            let e = f64::from(exact_values.pdf(p.face as usize, p.barycentric));
            let bound = if mode == Mode::Exact {
                1e-6
            } else {
                3.0 * tolerance
            };
            assert!(
                (f64::from(p.pdf) - e).abs() <= bound * e,
                "{mode:?}: {} vs exact {e}",
                p.pdf
            );
        }
        // The two layouts sample one distribution (the difference, at
        // most the tolerance, is far below what 10⁶ points resolve).
        let faces = m.2.len();
        let a = face_counts(faces, &alias.sample_n(4, N).unwrap());
        let b = face_counts(faces, &exact_values.sample_n(5, N).unwrap());
        let p = two_sample_p(&a, &b);
        assert!(p > 1e-3, "{mode:?}: alias vs inversion p = {p:.2e}");
    }
}

#[test]
fn merging_keeps_one_piece_per_face_for_a_constant_density() {
    let t = DensityTexture::new(64, 64, vec![3.0; 64 * 64]).unwrap();
    let m = grid(4, |uv| uv);
    let sampler = DensitySampler::new(mesh_ref(&m), Density::Texture(&t)).unwrap();
    assert_eq!(sampler.pieces(), m.2.len());
    assert!((0..m.2.len()).all(|f| sampler.level(f) == 4));
}

#[test]
fn a_sliver_is_subdivided_by_its_longest_edge() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.001, 0.0)];
    let uvs = [Vec2::ZERO, Vec2::X, Vec2::new(0.5, 0.001)];
    let indices = [[0, 1, 2]];
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let t = noise(256, 256);
    let sampler = DensitySampler::new(mesh, Density::Texture(&t)).unwrap();
    // 256 texels long but 0.13 texels² of area: cut along its length, into
    // 2⁷ segments of two texels per edge.
    assert_eq!(sampler.level(0), 7);
}

#[test]
fn zero_area_triangles_are_never_sampled() {
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.0, 0.0, 0.0)];
    let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
    let indices = [[0, 1, 2], [0, 1, 3]];
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let t = noise(8, 8);
    for options in [Options::default(), exact()] {
        let sampler = DensitySampler::with_options(mesh, Density::Texture(&t), &options).unwrap();
        assert!(
            sampler
                .sample_n(17, 10_000)
                .unwrap()
                .iter()
                .all(|p| p.face == 0)
        );
        assert_eq!(sampler.pdf(1, [0.3, 0.3, 0.4]), 0.0);
    }
    let w = [1.0, 1.0];
    let sampler = DensitySampler::new(mesh, Density::PerFace(&w)).unwrap();
    assert!(
        sampler
            .sample_n(18, 10_000)
            .unwrap()
            .iter()
            .all(|p| p.face == 0)
    );
}

#[test]
fn batches_do_not_depend_on_the_thread_count() {
    let t = noise(16, 16);
    let m = grid(6, skewed);
    let mesh = mesh_ref(&m);
    for options in [Options::default(), exact()] {
        let run = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| {
                    let s =
                        DensitySampler::with_options(mesh, Density::Texture(&t), &options).unwrap();
                    (s.pieces(), s.total_mass(), s.sample_n(19, 50_000).unwrap())
                })
        };
        let one = run(1);
        assert_eq!(one, run(2));
    }
    let r = RejectionSampler::new(mesh, &t).unwrap();
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| r.sample_n(20, 50_000).unwrap())
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn streaming_hands_out_the_points_of_sample_n() {
    let t = noise(16, 16);
    let m = grid(6, skewed);
    let sampler =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &exact()).unwrap();
    let n = 40_000; // two full chunks and a partial one
    let streamed = std::sync::Mutex::new(vec![SurfacePoint::default(); n]);
    sampler.sample_stream(25, n, |first, chunk| {
        streamed.lock().unwrap()[first..first + chunk.len()].copy_from_slice(chunk);
    });
    let points = sampler.sample_n(25, n).unwrap();
    assert_eq!(streamed.into_inner().unwrap(), points);
    let positions: Vec<[f32; 3]> = points.iter().map(|p| p.position.to_array()).collect();
    assert_eq!(sampler.sample_positions(25, n).unwrap(), positions);
}

#[test]
fn points_follow_a_deformed_mesh() {
    let t = noise(16, 16);
    let m = grid(4, |uv| uv);
    let sampler = DensitySampler::new(mesh_ref(&m), Density::Texture(&t)).unwrap();
    let points = sampler.sample_n(21, 100).unwrap();
    let moved: Vec<Vec3> = m.0.iter().map(|p| *p * 2.0 + Vec3::Z).collect();
    let deformed = MeshRef::new(&moved, &m.2);
    for p in points {
        let q = SurfacePoint::on(&deformed, p.face, p.barycentric, p.pdf).unwrap();
        assert!((q.position - (p.position * 2.0 + Vec3::Z)).length() < 1e-5);
    }
}

#[test]
fn bad_input_is_an_error() {
    let m = grid(2, |uv| uv);
    let mesh = mesh_ref(&m);
    let t = noise(4, 4);
    assert_eq!(
        DensityTexture::new(0, 4, vec![]).unwrap_err(),
        Error::EmptyTexture {
            width: 0,
            height: 4
        }
    );
    assert!(matches!(
        DensityTexture::new(2, 2, vec![1.0, f32::NAN, 0.0, 1.0]),
        Err(Error::InvalidTexel { x: 1, y: 0, .. })
    ));
    assert!(matches!(
        DensityTexture::new(2, 2, vec![1.0; 3]),
        Err(Error::TextureSize {
            expected: 4,
            len: 3
        })
    ));
    let huge = DensityTexture::new(usize::MAX, 2, vec![1.0]).unwrap_err();
    assert_eq!(
        huge,
        Error::TextureTooLarge {
            width: usize::MAX,
            height: 2
        }
    );
    assert!(huge.to_string().contains("more texels than"), "{huge}");
    let zero = DensityTexture::new(4, 4, vec![0.0; 16]).unwrap();
    for options in [Options::default(), exact()] {
        assert!(matches!(
            DensitySampler::with_options(mesh, Density::Texture(&zero), &options),
            Err(Error::ZeroDensity { .. })
        ));
    }
    assert!(matches!(
        RejectionSampler::new(mesh, &zero),
        Err(Error::ZeroDensity { .. })
    ));
    let no_uvs = MeshRef::new(&m.0, &m.2);
    assert_eq!(
        DensitySampler::new(no_uvs, Density::Texture(&t)).unwrap_err(),
        Error::MissingUvs
    );
    let mut bad_uvs = m.1.clone();
    bad_uvs[3].x = f32::INFINITY;
    let bad = MeshRef {
        uvs: Some(&bad_uvs),
        ..no_uvs
    };
    assert_eq!(
        DensitySampler::new(bad, Density::Texture(&t)).unwrap_err(),
        Error::NonFiniteUv { vertex: 3 }
    );
    assert_eq!(
        DensitySampler::new(mesh, Density::PerFace(&[1.0; 3])).unwrap_err(),
        Error::WeightLength {
            what: "face",
            len: 3,
            expected: 8
        }
    );
    let short = DensitySampler::new(mesh, Density::PerVertex(&[1.0; 3])).unwrap_err();
    assert_eq!(short.to_string(), "vertex weights: 3 given for 9 vertices");
    let mut w = vec![1.0; 9];
    w[4] = -1.0;
    assert_eq!(
        DensitySampler::new(mesh, Density::PerVertex(&w)).unwrap_err(),
        Error::InvalidWeight {
            what: "vertex",
            index: 4,
            value: -1.0
        }
    );
    assert!(matches!(
        DensitySampler::new(mesh, Density::PerFace(&[0.0; 8])),
        Err(Error::ZeroDensity { triangles: 8 })
    ));
    let deep = Options {
        max_level: 14,
        ..Options::default()
    };
    assert!(matches!(
        DensitySampler::with_options(mesh, Density::Texture(&t), &deep),
        Err(Error::InvalidOption(_))
    ));
    assert!(matches!(
        DensitySampler::new(MeshRef::new(&m.0, &[]), Density::PerFace(&[])),
        Err(Error::Empty)
    ));
    let oob = [[0, 1, 99]];
    assert!(matches!(
        DensitySampler::new(MeshRef::new(&m.0, &oob), Density::PerFace(&[1.0])),
        Err(Error::IndexOutOfRange {
            triangle: 0,
            vertex: 99,
            ..
        })
    ));
}

use data_dir::data_dir;
use test_support::data as data_dir;

/// Each HDR image of `$TRILUX_DATA/hdr`, its luminance box-filtered to
/// 64×32 (the sun stays thousands of times brighter than the sky), on a
/// plane: the approximate mode against the from-scratch `p′` per texel,
/// the exact mode against the exact integrals per triangle.
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn hdr_images_as_densities() {
    let dir = data_dir().expect("TRILUX_DATA names the data folder");
    let mut files: Vec<_> = std::fs::read_dir(dir.join("hdr"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "hdr"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    for file in files {
        let image = trilux_io::image::read(&file).unwrap();
        let (w, h) = (image.width as usize, image.height as usize);
        let (bw, bh) = (64, 32);
        let mut texels = vec![0.0f32; bw * bh];
        for (i, p) in image.pixels.iter().enumerate() {
            let (x, y) = ((i % w) * bw / w, (i / w) * bh / h);
            texels[y * bw + x] += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
        let t = DensityTexture::new(bw, bh, texels).unwrap();
        let m = grid(16, |uv| uv);
        let mesh = mesh_ref(&m);
        let approximate = DensitySampler::new(mesh, Density::Texture(&t)).unwrap();
        let counts = texel_counts(&m, &t, &approximate.sample_n(22, N).unwrap());
        let expected = approximate_bin_masses(&m, &t);
        let test = stats::chi_square(&counts, &stats::probabilities(&expected), 20.0);
        assert!(
            test.p_value > 1e-3,
            "{}: approximate {test:?}",
            file.display()
        );

        let exact_sampler =
            DensitySampler::with_options(mesh, Density::Texture(&t), &exact()).unwrap();
        let counts = face_counts(m.2.len(), &exact_sampler.sample_n(23, N).unwrap());
        let test = stats::chi_square(
            &counts,
            &stats::probabilities(&exact_face_masses(&m, &t)),
            20.0,
        );
        assert!(test.p_value > 1e-3, "{}: exact {test:?}", file.display());
        eprintln!(
            "{}: max/mean {:.0}, exact-mode acceptance {:.3}",
            file.display(),
            f64::from(t.max()) * uniform_area(mesh) / exact_sampler.total_mass(),
            exact_sampler.acceptance()
        );
    }
}

fn uniform_area(mesh: MeshRef<'_>) -> f64 {
    UniformSampler::new(mesh).unwrap().total_area()
}

/// The Stanford bunny, spherically mapped, with an 8×8 black-and-white
/// checkerboard: the exact mode never lands on black, whatever the
/// mapping; the approximate mode does near texel edges (that is the
/// paper's approximation, documented).
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn bunny_checkerboard_exact_mode_never_lands_on_black() {
    let dir = data_dir().expect("TRILUX_DATA names the data folder");
    let bunny = trilux_io::mesh::TriMesh::read(dir.join("meshes/stanford-bunny.obj")).unwrap();
    let (positions, uvs, indices) =
        mesh_sampling::spherical_uvs(&bunny.positions, &bunny.indices).unwrap();
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let k = 8;
    let t = DensityTexture::new(
        k,
        k,
        (0..k * k).map(|i| ((i % k + i / k) % 2) as f32).collect(),
    )
    .unwrap()
    .with_filter(Filter::Nearest);
    let m: Mesh = (positions.clone(), uvs.clone(), indices.clone());
    let on_black = |s: &DensitySampler<'_>| -> u64 {
        let counts = texel_counts(&m, &t, &s.sample_n(24, 200_000).unwrap());
        let black = counts.iter().zip(t.texels()).filter(|(_, v)| **v == 0.0);
        black.map(|(c, _)| c).sum()
    };
    let exact_sampler = DensitySampler::with_options(mesh, Density::Texture(&t), &exact()).unwrap();
    assert_eq!(on_black(&exact_sampler), 0);
    let black = on_black(&DensitySampler::new(mesh, Density::Texture(&t)).unwrap());
    eprintln!(
        "approximate mode: {black} of 200000 points on black (sub-triangles straddling texel edges)"
    );
}
