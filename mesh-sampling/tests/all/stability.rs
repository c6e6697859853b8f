//! Value stability: the first points of the uniform, density and blue-noise
//! samplers and of the scatter by rate for a fixed seed, pinned, so that a change of layout, of the
//! random stream or of the build that moves points is a conscious one (the
//! statistical tests would pass for any correct sampler).

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Filter, MeshRef, SurfacePoint, SurfaceSampler,
    UniformSampler,
};

/// A 4 × 4 grid of quads over the unit square (UVs equal to (x, y)), with
/// its corner lifted so that triangles differ in area.
fn grid() -> (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) {
    let n = 4u32;
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            positions.push(Vec3::new(x, y, x * y));
            uvs.push(Vec2::new(x, y));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            indices.push([a, a + 1, a + n + 1]);
            indices.push([a + 1, a + n + 2, a + n + 1]);
        }
    }
    (positions, uvs, indices)
}

/// An 8 × 8 texture with distinct smooth values.
fn texture() -> DensityTexture {
    let texels = (0..64)
        .map(|k| 1.0 + ((k % 8) as f32 * 0.7).sin() + 0.1 * (k / 8) as f32)
        .collect();
    DensityTexture::new(8, 8, texels).unwrap()
}

/// (face, barycentrics) of each point, as pinned below.
fn summary(points: &[SurfacePoint]) -> Vec<(u32, [f32; 3])> {
    points.iter().map(|p| (p.face, p.barycentric)).collect()
}

fn assert_pinned(what: &str, got: &[(u32, [f32; 3])], want: &[(u32, [f32; 3])]) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?}");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        let close = g.1.iter().zip(&w.1).all(|(a, b)| (a - b).abs() <= 1e-6);
        assert!(
            g.0 == w.0 && close,
            "{what}, point {k}: {g:?}, pinned {w:?}\nall: {got:?}"
        );
    }
}

#[test]
fn uniform_points_are_pinned() {
    let (positions, _, indices) = grid();
    let sampler = UniformSampler::new(MeshRef::new(&positions, &indices)).unwrap();
    let got = summary(&sampler.sample_n(2026, 4).unwrap());
    assert_pinned("uniform", &got, &UNIFORM);
}

#[test]
fn density_points_are_pinned_for_both_filters() {
    let (positions, uvs, indices) = grid();
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    for filter in [Filter::Bilinear, Filter::Nearest] {
        let t = texture().with_filter(filter);
        let sampler = DensitySampler::new(mesh, Density::Texture(&t)).unwrap();
        assert_eq!(sampler.layout(), mesh_sampling::Layout::Alias);
        let got = summary(&sampler.sample_n(2026, 4).unwrap());
        let want = if filter == Filter::Bilinear {
            &DENSITY_BILINEAR[..]
        } else {
            &DENSITY_NEAREST[..]
        };
        assert_pinned(&format!("density {filter:?}"), &got, want);
    }
}

#[cfg(feature = "blue-noise")]
#[test]
fn blue_noise_points_are_pinned() {
    use mesh_sampling::{BlueNoiseOptions, BlueNoiseTarget, blue_noise};
    let (positions, _, indices) = grid();
    let sampler = UniformSampler::new(MeshRef::new(&positions, &indices)).unwrap();
    let points = blue_noise(
        &sampler,
        BlueNoiseTarget::Count(200),
        2026,
        &BlueNoiseOptions::default(),
    )
    .unwrap();
    assert_pinned("blue noise", &summary(&points[..4]), &BLUE_NOISE);
}

/// The dense packing's output (in candidate order, as elimination's):
/// pinned so that a change of the relocation is a conscious one.
#[cfg(feature = "blue-noise")]
#[test]
fn dense_blue_noise_points_are_pinned() {
    use mesh_sampling::{BlueNoiseOptions, BlueNoiseTarget, blue_noise};
    let (positions, _, indices) = grid();
    let sampler = UniformSampler::new(MeshRef::new(&positions, &indices)).unwrap();
    let points = blue_noise(
        &sampler,
        BlueNoiseTarget::Count(200),
        2026,
        &BlueNoiseOptions::dense(),
    )
    .unwrap();
    assert_pinned(
        "dense blue noise",
        &summary(&points[..4]),
        &DENSE_BLUE_NOISE,
    );
}

const UNIFORM: [(u32, [f32; 3]); 4] = [
    (24, [0.8187891, 0.048960943, 0.13224994]),
    (26, [0.11395139, 0.4261354, 0.4599132]),
    (17, [0.3382452, 0.26578057, 0.39597422]),
    (15, [0.13347909, 0.7937605, 0.0727604]),
];
const DENSITY_BILINEAR: [(u32, [f32; 3]); 4] = [
    (27, [0.40939456, 0.024480471, 0.566125]),
    (25, [0.056975696, 0.2130677, 0.7299566]),
    (26, [0.1691226, 0.13289028, 0.69798714]),
    (12, [0.066739544, 0.39688024, 0.53638023]),
];
const DENSITY_NEAREST: [(u32, [f32; 3]); 4] = [
    (27, [0.40939456, 0.024480471, 0.566125]),
    (25, [0.056975696, 0.2130677, 0.7299566]),
    (26, [0.1691226, 0.13289028, 0.69798714]),
    (13, [0.066739544, 0.39688024, 0.53638023]),
];
#[cfg(feature = "blue-noise")]
const BLUE_NOISE: [(u32, [f32; 3]); 4] = [
    (9, [0.38604233, 0.21321447, 0.40074322]),
    (29, [0.42950585, 0.20256558, 0.36792856]),
    (24, [0.3164817, 0.05297244, 0.63054585]),
    (14, [0.67422014, 0.24694732, 0.078832515]),
];
#[cfg(feature = "blue-noise")]
const DENSE_BLUE_NOISE: [(u32, [f32; 3]); 4] = [
    (26, [0.36348602, 0.34464824, 0.29186577]),
    (26, [0.22327833, 0.71232885, 0.06439283]),
    (24, [0.22073233, 0.0010215836, 0.7782461]),
    (27, [0.33791137, 0.6594927, 0.0025959532]),
];

#[test]
fn scatter_points_are_pinned() {
    use mesh_sampling::{ScatterOptions, scatter};
    let (positions, uvs, indices) = grid();
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let texture = texture();
    let options = ScatterOptions {
        max_density: Some(3.0),
        seed: 7,
        ..ScatterOptions::new(40.0)
    };
    let points = scatter(mesh, Density::Texture(&texture).into(), &options).unwrap();
    // The count too: the Poisson counts come from rand_distr, whose
    // algorithm could change with its version.
    assert_eq!(points.len(), 69);
    assert_pinned("scatter", &summary(&points[..5]), &SCATTER);
}

const SCATTER: [(u32, [f32; 3]); 5] = [
    (0, [0.08851688, 0.15822013, 0.753263]),
    (0, [0.32814494, 0.14349052, 0.52836454]),
    (1, [0.079830065, 0.81083816, 0.109331764]),
    (1, [0.10329119, 0.81875247, 0.07795631]),
    (2, [0.4192004, 0.48506197, 0.09573764]),
];
