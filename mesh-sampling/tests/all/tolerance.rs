//! `Options::merge_tolerance`: where the texture is piecewise constant (with
//! values further apart than the tolerance) the pieces and the density are
//! those of `p′` exactly; where it is smooth, fewer pieces, each value
//! within the tolerance of `p′`; and a sampler built with it still samples
//! its own `pdf` (each UV cell's area recovered as the mean of `1 / pdf`).

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Filter, MeshRef, Options, SurfaceSampler,
};

type Mesh = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

/// Two triangles over UV `[0, 1]²`, the second lifted out of the plane.
fn square() -> Mesh {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.5)];
    let uvs = vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
    (positions, uvs, vec![[0, 1, 2], [1, 3, 2]])
}

fn mesh_ref(m: &Mesh) -> MeshRef<'_> {
    MeshRef {
        uvs: Some(&m.1),
        ..MeshRef::new(&m.0, &m.2)
    }
}

fn with(tolerance: f32) -> Options {
    Options {
        merge_tolerance: tolerance,
        ..Options::default()
    }
}

/// Barycentrics on a fine grid of each face (inside, off the edges).
fn probes(faces: usize) -> Vec<(usize, [f32; 3])> {
    let mut out = Vec::new();
    for f in 0..faces {
        for i in 0..60 {
            for j in 0..60 - i {
                let (u, v) = ((i as f32 + 0.3) / 61.0, (j as f32 + 0.4) / 61.0);
                out.push((f, [1.0 - u - v, u, v]));
            }
        }
    }
    out
}

#[test]
fn a_piecewise_constant_texture_is_unchanged_by_the_tolerance() {
    let m = square();
    // 32 × 32 texels of 1 and 3 in blocks of 4 (nearest): neighbours
    // differ by 2/3 of the larger, more than any tolerance used here.
    let texels = (0..32 * 32)
        .map(|k| {
            if ((k % 32) / 4 + (k / 32) / 4) % 2 == 0 {
                1.0
            } else {
                3.0
            }
        })
        .collect();
    let t = DensityTexture::new(32, 32, texels)
        .unwrap()
        .with_filter(Filter::Nearest);
    let exact =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &with(0.0)).unwrap();
    for tolerance in [0.01, 0.1, 0.5] {
        let s = DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &with(tolerance))
            .unwrap();
        assert_eq!(s.pieces(), exact.pieces(), "tolerance {tolerance}");
        assert_eq!(s.total_mass(), exact.total_mass());
        for (f, b) in probes(2) {
            assert_eq!(
                s.pdf(f, b),
                exact.pdf(f, b),
                "tolerance {tolerance}, face {f}, {b:?}"
            );
        }
    }
}

#[test]
fn a_smooth_texture_takes_fewer_pieces_each_within_the_tolerance() {
    let m = square();
    // A gentle ramp: 1 to 1.5 across 256 texels.
    let texels = (0..256 * 256)
        .map(|k| 1.0 + 0.5 * ((k % 256) as f32 + (k / 256) as f32) / 510.0)
        .collect();
    let t = DensityTexture::new(256, 256, texels).unwrap();
    let exact =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &with(0.0)).unwrap();
    let tolerance = 0.05;
    let s =
        DensitySampler::with_options(mesh_ref(&m), Density::Texture(&t), &with(tolerance)).unwrap();
    assert!(
        s.pieces() * 20 < exact.pieces(),
        "{} pieces against {}",
        s.pieces(),
        exact.pieces()
    );
    // Unnormalised values: pdf × total mass.
    for (f, b) in probes(2) {
        let a = f64::from(s.pdf(f, b)) * s.total_mass();
        let e = f64::from(exact.pdf(f, b)) * exact.total_mass();
        assert!(
            (a - e).abs() <= 2.0 * f64::from(tolerance) * a.max(e),
            "face {f}, {b:?}: {a} against p′ = {e}"
        );
    }
    // The draws follow the sampler's own pdf: E[1_R / pdf] over its
    // points is the area of R (∫_R p · 1/p dA) for every cell R of a 6 × 6
    // UV grid, within 4.5 standard errors; a sampler drawing anything but
    // its pdf would miss some cells' areas.
    let n = 400_000;
    let points = s.sample_n(3, n).unwrap();
    let cell = |uv: Vec2| {
        let q = |x: f32| ((x * 6.0) as usize).min(5);
        (q(uv.x), q(uv.y))
    };
    let (mut sum, mut sum2) = ([[0.0f64; 6]; 6], [[0.0f64; 6]; 6]);
    for p in &points {
        let (i, j) = cell(p.uv.unwrap());
        let w = 1.0 / f64::from(p.pdf);
        sum[i][j] += w;
        sum2[i][j] += w * w;
    }
    // Face 0 is its own UV triangle; face 1's area is its UV area times
    // this; the diagonal u + v = 1 halves the cells i + j = 5.
    let scale = (0.25f64 + 0.25 + 1.0).sqrt();
    for i in 0..6 {
        for j in 0..6 {
            let cell_area = 1.0 / 36.0;
            let area = match (i + j).cmp(&5) {
                std::cmp::Ordering::Less => cell_area,
                std::cmp::Ordering::Greater => cell_area * scale,
                std::cmp::Ordering::Equal => 0.5 * cell_area * (1.0 + scale),
            };
            let mean = sum[i][j] / n as f64;
            let var = sum2[i][j] / n as f64 - mean * mean;
            let z = (mean - area) / (var / n as f64).sqrt();
            assert!(
                z.abs() < 4.5,
                "cell ({i}, {j}): {mean} for area {area}, z = {z}"
            );
        }
    }
}
