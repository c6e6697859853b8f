//! Blue noise by weighted sample elimination: spacing (relative radius ρ of
//! Lagae & Dutré against independent uniform points, which must fail the
//! same threshold), density following (chi-square on a checkerboard, and
//! nearest-neighbour spacing scaling as 1/√density), progressive prefixes,
//! determinism across thread counts, errors.
#![cfg(feature = "blue-noise")]

use test_support::data as data_dir;
use test_support::stats;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Density, DensitySampler, DensityTexture, Filter, MeshRef,
    Packing, SurfaceArea, SurfacePoint, SurfaceSampler, UniformSampler, blue_noise,
    nearest_neighbour_distances, relative_radius, relative_radius_with_density,
};

/// A threshold on ρ that every blue-noise output here clears and that
/// independent uniform points (ρ ≈ 0.01 at these counts) never reach.
const RHO_BLUE: f64 = 0.5;

/// What the dense packing reaches (MeshLab's and point-cloud-utils'
/// Poisson-disk sampling: 0.75–0.77) and elimination alone (≈ 0.69) does
/// not.
const RHO_DENSE: f64 = 0.75;

/// The unit square in the z = 0 plane as an `n × n` grid of quads, with
/// UVs equal to (x, y).
fn plane(n: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
            positions.push(Vec3::new(x, y, 0.0));
            uvs.push(Vec2::new(x, y));
        }
    }
    let mut indices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            indices.push([a, a + 1, a + n + 1]);
            indices.push([a + 1, a + n + 2, a + n + 1]);
        }
    }
    (positions, uvs, indices)
}

/// A unit sphere as a latitude-longitude grid.
fn sphere(rings: u32, segments: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = vec![Vec3::Z];
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ));
        }
    }
    positions.push(-Vec3::Z);
    let south = positions.len() as u32 - 1;
    let at = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut indices = Vec::new();
    for s in 0..segments {
        indices.push([0, at(1, s), at(1, s + 1)]);
        indices.push([south, at(rings - 1, s + 1), at(rings - 1, s)]);
        for r in 1..rings - 1 {
            indices.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
            indices.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
        }
    }
    (positions, indices)
}

fn positions(points: &[SurfacePoint]) -> Vec<Vec3> {
    points.iter().map(|p| p.position).collect()
}

/// ρ of blue noise from `sampler` and of as many independent points.
fn rho_pair<S: SurfaceSampler + SurfaceArea>(sampler: &S, n: usize, seed: u64) -> (f64, f64) {
    let area = sampler.surface_area();
    let blue = blue_noise(
        sampler,
        BlueNoiseTarget::Count(n),
        seed,
        &BlueNoiseOptions::default(),
    )
    .unwrap();
    assert_eq!(blue.len(), n);
    let random = sampler.sample_n(seed + 1, n).unwrap();
    (
        relative_radius(&positions(&blue), area),
        relative_radius(&positions(&random), area),
    )
}

#[test]
fn plane_and_sphere_are_spread_and_random_points_are_not() {
    let (p, _, i) = plane(4);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let (blue, random) = rho_pair(&s, 4000, 1);
    eprintln!("plane: ρ blue {blue:.3}, random {random:.4}");
    assert!(blue > RHO_BLUE && random < RHO_BLUE);

    let (p, i) = sphere(24, 48);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let (blue, random) = rho_pair(&s, 4000, 2);
    eprintln!("sphere: ρ blue {blue:.3}, random {random:.4}");
    assert!(blue > RHO_BLUE && random < RHO_BLUE);
}

/// The plane with a 2×2 nearest-filtered density `[[1, 4], [4, 1]]`: mass
/// fractions 0.1, 0.4, 0.4, 0.1 per quadrant.
fn checker_texture() -> DensityTexture {
    DensityTexture::new(2, 2, vec![1.0, 4.0, 4.0, 1.0])
        .unwrap()
        .with_filter(Filter::Nearest)
}

fn quadrant(uv: Vec2) -> usize {
    usize::from(uv.x >= 0.5) + 2 * usize::from(uv.y >= 0.5)
}

#[test]
fn density_counts_follow_the_density_and_spacing_scales_as_inverse_sqrt() {
    density_is_followed(&BlueNoiseOptions::default(), RHO_BLUE);
}

#[test]
fn dense_packing_follows_the_density_too() {
    density_is_followed(&BlueNoiseOptions::dense(), RHO_DENSE);
}

/// Counts per quadrant of the checkerboard density (χ²), the spacing ratio
/// of dense to sparse quadrants, and ρ against each point's own density
/// at least `rho_min`.
fn density_is_followed(options: &BlueNoiseOptions, rho_min: f64) {
    let (p, uv, i) = plane(4);
    let mesh = MeshRef {
        uvs: Some(&uv),
        ..MeshRef::new(&p, &i)
    };
    let texture = checker_texture();
    let sampler = DensitySampler::new(mesh, Density::Texture(&texture)).unwrap();
    let n = 8000;
    let points = blue_noise(&sampler, BlueNoiseTarget::Count(n), 5, options).unwrap();
    let mut counts = [0u64; 4];
    for q in &points {
        counts[quadrant(q.uv.unwrap())] += 1;
    }
    let chi = stats::chi_square(&counts, &[0.1, 0.4, 0.4, 0.1], 5.0);
    eprintln!(
        "counts {counts:?}: χ² = {:.2}, p = {:.3}",
        chi.statistic, chi.p_value
    );
    assert!(chi.p_value > 1e-3, "{chi:?}");

    // Mean nearest-neighbour distance away from the density's edges and the
    // border: the dense quadrants' is half the sparse ones' (√4), within
    // 10% (each mean is over about a thousand points of a blue-noise set,
    // whose spacing varies by a few per cent).
    let xyz = positions(&points);
    let nn = nearest_neighbour_distances(&xyz);
    let (mut sum, mut cnt) = ([0.0f64; 2], [0usize; 2]);
    for (q, d) in points.iter().zip(&nn) {
        let uv = q.uv.unwrap();
        let margin = [
            uv.x,
            uv.y,
            1.0 - uv.x,
            1.0 - uv.y,
            (uv.x - 0.5).abs(),
            (uv.y - 0.5).abs(),
        ];
        if margin.iter().all(|&m| m > 0.05) {
            let dense = usize::from(matches!(quadrant(uv), 1 | 2));
            sum[dense] += f64::from(*d);
            cnt[dense] += 1;
        }
    }
    let ratio = (sum[0] / cnt[0] as f64) / (sum[1] / cnt[1] as f64);
    eprintln!("sparse/dense mean NN distance: {ratio:.3} (expected 2)");
    assert!((ratio - 2.0).abs() < 0.2, "ratio {ratio}");
    // And the spacing is blue everywhere, each point measured against its
    // own density; independent points from the same density are not.
    let pdf: Vec<f32> = points.iter().map(|p| p.pdf).collect();
    let blue = relative_radius_with_density(&xyz, &pdf);
    let random = sampler.sample_n(6, n).unwrap();
    let random_pdf: Vec<f32> = random.iter().map(|p| p.pdf).collect();
    let random = relative_radius_with_density(&positions(&random), &random_pdf);
    eprintln!("density-adaptive ρ: blue {blue:.3}, random {random:.4}");
    assert!(blue >= rho_min && random < RHO_BLUE, "ρ {blue}");
}

#[test]
fn progressive_prefixes_are_spread() {
    let (p, _, i) = plane(4);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let opts = BlueNoiseOptions {
        progressive: true,
        ..BlueNoiseOptions::default()
    };
    let n = 4000;
    let points = blue_noise(&s, BlueNoiseTarget::Count(n), 3, &opts).unwrap();
    assert_eq!(points.len(), n);
    let xyz = positions(&points);
    for prefix in [n / 4, n / 16, n] {
        let rho = relative_radius(&xyz[..prefix], 1.0);
        let random = relative_radius(&positions(&s.sample_n(9, prefix).unwrap()), 1.0);
        eprintln!("prefix {prefix}: ρ {rho:.3} (random {random:.3})");
        assert!(rho > RHO_BLUE && random < RHO_BLUE);
    }
    // The non-progressive result, by contrast, is ordered by candidate:
    // its first quarter is a random subset and not spread.
    let plain = blue_noise(
        &s,
        BlueNoiseTarget::Count(n),
        3,
        &BlueNoiseOptions::default(),
    )
    .unwrap();
    let rho = relative_radius(&positions(&plain[..n / 4]), 1.0);
    eprintln!("plain prefix {}: ρ {rho:.3}", n / 4);
    assert!(rho < RHO_BLUE);
}

#[test]
fn a_radius_gives_the_hexagonal_count() {
    let (p, _, i) = plane(2);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let r = 0.01;
    let points = blue_noise(
        &s,
        BlueNoiseTarget::Radius(r),
        1,
        &BlueNoiseOptions::default(),
    )
    .unwrap();
    let expected = (1.0 / (2.0 * 3f64.sqrt() * r * r)).round() as usize;
    assert_eq!(points.len(), expected);
}

#[test]
fn dense_packing_clears_the_dense_threshold_where_elimination_does_not() {
    let (p, _, i) = plane(4);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let (p, i) = sphere(24, 48);
    let sphere = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    for (name, rho) in [
        ("plane", dense_and_plain(&s, 6000, 1)),
        ("sphere", dense_and_plain(&sphere, 6000, 2)),
    ] {
        eprintln!("{name}: ρ dense {:.3}, elimination {:.3}", rho.0, rho.1);
        assert!(rho.0 >= RHO_DENSE && rho.1 < RHO_DENSE, "{name}: {rho:?}");
    }
}

/// ρ (against each point's own density) of the dense packing and of
/// elimination alone; the dense set has exactly `n` points.
fn dense_and_plain<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    n: usize,
    seed: u64,
) -> (f64, f64) {
    let rho = |options: &BlueNoiseOptions| {
        let points = blue_noise(sampler, BlueNoiseTarget::Count(n), seed, options).unwrap();
        assert_eq!(points.len(), n);
        let pdf: Vec<f32> = points.iter().map(|p| p.pdf).collect();
        relative_radius_with_density(&positions(&points), &pdf)
    };
    (
        rho(&BlueNoiseOptions::dense()),
        rho(&BlueNoiseOptions::default()),
    )
}

#[test]
fn dense_progressive_order_keeps_the_dense_set_and_spreads_its_prefixes() {
    let (p, _, i) = plane(4);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let n = 4000;
    let dense = BlueNoiseOptions::dense();
    let plain = blue_noise(&s, BlueNoiseTarget::Count(n), 3, &dense).unwrap();
    let progressive = BlueNoiseOptions {
        progressive: true,
        ..dense
    };
    let ordered = blue_noise(&s, BlueNoiseTarget::Count(n), 3, &progressive).unwrap();
    // The same points, in another order.
    let key = |p: &SurfacePoint| (p.face, p.barycentric.map(f32::to_bits));
    let mut a: Vec<_> = plain.iter().map(key).collect();
    let mut b: Vec<_> = ordered.iter().map(key).collect();
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    for prefix in [n / 16, n / 4] {
        let rho = relative_radius(&positions(&ordered[..prefix]), 1.0);
        eprintln!("dense prefix {prefix}: ρ {rho:.3}");
        assert!(rho > RHO_BLUE, "prefix {prefix}: ρ {rho}");
    }
    assert!(relative_radius(&positions(&ordered), 1.0) >= RHO_DENSE);
}

#[test]
fn same_output_on_one_and_two_threads() {
    let (p, uv, i) = plane(4);
    let mesh = MeshRef {
        uvs: Some(&uv),
        ..MeshRef::new(&p, &i)
    };
    let texture = checker_texture();
    let sampler = DensitySampler::new(mesh, Density::Texture(&texture)).unwrap();
    for base in [BlueNoiseOptions::default(), BlueNoiseOptions::dense()] {
        for progressive in [false, true] {
            let opts = BlueNoiseOptions {
                progressive,
                ..base
            };
            let run = |threads| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        blue_noise(&sampler, BlueNoiseTarget::Count(20_000), 11, &opts).unwrap()
                    })
            };
            assert_eq!(run(1), run(2), "{opts:?}");
        }
    }
}

#[test]
fn bad_targets_and_options_are_errors_that_say_why() {
    let (p, _, i) = plane(1);
    let s = UniformSampler::new(MeshRef::new(&p, &i)).unwrap();
    let d = BlueNoiseOptions::default();
    let err = |t, o: &BlueNoiseOptions| blue_noise(&s, t, 0, o).unwrap_err().to_string();
    assert!(err(BlueNoiseTarget::Count(0), &d).contains("0 points"));
    for r in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        assert!(
            err(BlueNoiseTarget::Radius(r), &d).contains("radius"),
            "{r}"
        );
    }
    // Subnormal radius: an astronomically large count, refused before
    // anything is allocated.
    assert!(err(BlueNoiseTarget::Radius(1e-300), &d).contains("more than"));
    assert!(err(BlueNoiseTarget::Count(usize::MAX), &d).contains("more than"));
    let huge = err(BlueNoiseTarget::Count(100_000_000), &d);
    assert!(huge.contains("memory budget"), "{huge}");
    for bad in [
        BlueNoiseOptions {
            candidate_factor: 0.5,
            ..d
        },
        BlueNoiseOptions {
            candidate_factor: f64::NAN,
            ..d
        },
        BlueNoiseOptions { alpha: 0.0, ..d },
        BlueNoiseOptions { beta: 1.0, ..d },
        BlueNoiseOptions {
            gamma: f64::NAN,
            ..d
        },
    ] {
        assert!(err(BlueNoiseTarget::Count(10), &bad).contains("out of range"));
    }
    // A factor of 1 keeps every candidate; one point works.
    let one = BlueNoiseOptions {
        candidate_factor: 1.0,
        ..d
    };
    assert_eq!(
        blue_noise(&s, BlueNoiseTarget::Count(5), 0, &one)
            .unwrap()
            .len(),
        5
    );
    assert_eq!(
        blue_noise(&s, BlueNoiseTarget::Count(1), 0, &d)
            .unwrap()
            .len(),
        1
    );
    // The dense packing: the same checks, its larger footprint counted in
    // the budget, and the corner cases (no spare candidate, one point).
    let dense = BlueNoiseOptions::dense();
    assert!(err(BlueNoiseTarget::Count(0), &dense).contains("0 points"));
    let tight = BlueNoiseOptions {
        max_memory_bytes: 1 << 20,
        ..dense
    };
    assert!(err(BlueNoiseTarget::Count(2000), &tight).contains("memory budget"));
    let bad = BlueNoiseOptions {
        candidate_factor: 0.0,
        ..dense
    };
    assert!(err(BlueNoiseTarget::Count(10), &bad).contains("out of range"));
    for (n, factor) in [(5, 1.0), (1, 14.0), (2, 14.0)] {
        let o = BlueNoiseOptions {
            candidate_factor: factor,
            packing: Packing::Dense,
            ..d
        };
        assert_eq!(
            blue_noise(&s, BlueNoiseTarget::Count(n), 0, &o)
                .unwrap()
                .len(),
            n
        );
    }
}

/// The data meshes, uniform: blue noise clears the threshold, independent
/// points do not.
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn data_meshes_are_spread() {
    let dir = data_dir::data_dir().expect("TRILUX_DATA");
    // Every data mesh, at a count whose 10⁵ candidates take the tiled
    // parallel elimination; ρ at least 0.65 (Yuksel's elimination reaches
    // about 0.69; independent points about 0.01).
    for name in data_dir::MESHES {
        let mesh = trilux_io::mesh::TriMesh::read(dir.join(format!("meshes/{name}.obj"))).unwrap();
        let s = UniformSampler::new(MeshRef::new(&mesh.positions, &mesh.indices)).unwrap();
        let (blue, random) = rho_pair(&s, 20_000, 4);
        eprintln!("{name}: ρ blue {blue:.3}, random {random:.4}");
        assert!(blue >= 0.65 && random < RHO_BLUE, "{name}: ρ {blue}");
    }
}

/// Per-vertex weights `exp(sin(…) cos(…))`: smooth, up to 1:7 from the
/// lowest to the highest, two periods across the bounding box. (With
/// steeper gradients no set can keep every point at 0.75 of its own
/// density's packing radius: a point on the sparse side of a steep slope
/// has denser-spaced neighbours; `exp(2 …)` over three periods, 1:55,
/// gives 0.74 dense and 0.67 eliminated.)
fn wave_weights(positions: &[Vec3]) -> Vec<f32> {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    let k = std::f32::consts::TAU * 2.0 / (hi - lo).max_element();
    positions
        .iter()
        .map(|p| (((p.x - lo.x) * k).sin() * ((p.y - lo.y) * k).cos()).exp())
        .collect()
}

/// The meshes of the dense packing's bar (bunny, spot, fandisk), uniform
/// and with a smooth density: ρ ≥ 0.75 (each point against its own
/// density) where elimination alone stays below.
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn dense_packing_reaches_three_quarters_on_the_data_meshes() {
    let dir = data_dir::data_dir().expect("TRILUX_DATA");
    for name in ["stanford-bunny", "spot", "fandisk"] {
        let mesh = trilux_io::mesh::TriMesh::read(dir.join(format!("meshes/{name}.obj"))).unwrap();
        let mesh_ref = MeshRef::new(&mesh.positions, &mesh.indices);
        let uniform = UniformSampler::new(mesh_ref).unwrap();
        let weights = wave_weights(&mesh.positions);
        let waves = DensitySampler::new(mesh_ref, Density::PerVertex(&weights)).unwrap();
        for (density, rho) in [
            ("uniform", dense_and_plain(&uniform, 20_000, 8)),
            ("waves", dense_and_plain(&waves, 20_000, 9)),
        ] {
            eprintln!(
                "{name}, {density}: ρ dense {:.3}, elimination {:.3}",
                rho.0, rho.1
            );
            assert!(
                rho.0 >= RHO_DENSE && rho.1 < RHO_DENSE,
                "{name}, {density}: {rho:?}"
            );
        }
    }
}
