use glam::{Vec2, Vec3};
use test_support::SplitMix64;
use test_support::stats::{chi_square, gamma_q};

use super::*;
use crate::mesh::test_grid;
use crate::{DensityTexture, Filter};

/// A flat `n × n` grid of unit cells, two equal triangles per cell, with
/// UVs spanning `[0, 1]²`.
fn flat_grid(n: u32) -> (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) {
    let m = n + 1;
    let positions = (0..m * m)
        .map(|k| Vec3::new((k % m) as f32, (k / m) as f32, 0.0))
        .collect();
    let uvs = (0..m * m)
        .map(|k| Vec2::new((k % m) as f32 / n as f32, (k / m) as f32 / n as f32))
        .collect();
    let mut indices = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * m + i;
            indices.push([a, a + 1, a + m]);
            indices.push([a + 1, a + m + 1, a + m]);
        }
    }
    (positions, uvs, indices)
}

fn options(rate: f64, max: f64, seed: u64) -> ScatterOptions {
    ScatterOptions {
        max_density: Some(max),
        seed,
        ..ScatterOptions::new(rate)
    }
}

/// Whether `small` is `big` with some points left out, in order, bit for
/// bit (the superset property, face by face) but for the intensity each
/// point reports, which follows the density.
fn is_subsequence(small: &[SurfacePoint], big: &[SurfacePoint]) -> bool {
    let mut rest = big.iter();
    small
        .iter()
        .all(|p| rest.any(|q| SurfacePoint { pdf: p.pdf, ..*q } == *p))
}

fn random_weights(rng: &mut SplitMix64, n: usize) -> Vec<f32> {
    (0..n).map(|_| rng.f32()).collect()
}

#[test]
fn unchanged_faces_keep_bit_identical_points() {
    let (positions, normals, indices) = test_grid(12);
    let mesh = MeshRef {
        normals: Some(&normals),
        ..MeshRef::new(&positions, &indices)
    };
    let mut rng = SplitMix64(3);
    for trial in 0..20 {
        let before = random_weights(&mut rng, indices.len());
        let mut after = before.clone();
        let mut edited = vec![false; indices.len()];
        for _ in 0..10 {
            let f = rng.below(indices.len() as u64) as usize;
            after[f] = rng.f32();
            edited[f] = true;
        }
        let opts = options(40.0, 1.0, trial);
        let a = Scatter::new(mesh, Density::PerFace(&before).into(), &opts).unwrap();
        let b = Scatter::new(mesh, Density::PerFace(&after).into(), &opts).unwrap();
        for f in (0..indices.len()).filter(|&f| !edited[f]) {
            assert_eq!(
                a.face_points(f),
                b.face_points(f),
                "trial {trial}, face {f}"
            );
        }
        // The edits did change something somewhere (the test can fail).
        assert_ne!(a.points(), b.points(), "trial {trial}");
    }
}

#[test]
fn raising_the_density_adds_points_and_lowering_removes_them() {
    let (positions, uvs, indices) = flat_grid(8);
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let mut rng = SplitMix64(11);
    for trial in 0..20 {
        // Per-vertex weights, a texture and a function, each raised
        // pointwise by a random amount.
        let low = random_weights(&mut rng, positions.len());
        let high: Vec<f32> = low.iter().map(|&w| (w + rng.f32()).min(2.0)).collect();
        let opts = options(30.0, 2.0, trial);
        let lo = Scatter::new(mesh, Density::PerVertex(&low).into(), &opts).unwrap();
        let hi = Scatter::new(mesh, Density::PerVertex(&high).into(), &opts).unwrap();
        let tex_lo = DensityTexture::new(9, 9, random_weights(&mut rng, 81)).unwrap();
        let tex_hi = DensityTexture::new(
            9,
            9,
            tex_lo.texels().iter().map(|&t| t + rng.f32()).collect(),
        )
        .unwrap();
        let t_lo = Scatter::new(mesh, Density::Texture(&tex_lo).into(), &opts).unwrap();
        let t_hi = Scatter::new(mesh, Density::Texture(&tex_hi).into(), &opts).unwrap();
        let f_lo = |f: usize, b: [f32; 3]| low[f % low.len()] * b[0];
        let f_hi = |f: usize, b: [f32; 3]| high[f % high.len()] * b[0] + 0.5 * b[1];
        let fn_lo = Scatter::new(mesh, ScatterDensity::Function(&f_lo), &opts).unwrap();
        let fn_hi = Scatter::new(mesh, ScatterDensity::Function(&f_hi), &opts).unwrap();
        for (small, big) in [(&lo, &hi), (&t_lo, &t_hi), (&fn_lo, &fn_hi)] {
            assert!(big.points().len() > small.points().len(), "trial {trial}");
            for f in 0..indices.len() {
                assert!(
                    is_subsequence(small.face_points(f), big.face_points(f)),
                    "trial {trial}, face {f}"
                );
            }
        }
    }
}

/// The exact superset test rejects thresholds re-drawn at each build (a
/// different stream for the raised density): the property is not
/// vacuous.
#[test]
fn the_superset_test_rejects_redrawn_thresholds() {
    let (positions, uvs, indices) = flat_grid(8);
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let low = vec![0.3f32; positions.len()];
    let high = vec![0.6f32; positions.len()];
    let lo = Scatter::new(
        mesh,
        Density::PerVertex(&low).into(),
        &options(30.0, 1.0, 5),
    )
    .unwrap();
    let redrawn = Scatter::new(
        mesh,
        Density::PerVertex(&high).into(),
        &options(30.0, 1.0, 6),
    )
    .unwrap();
    assert!(!(0..indices.len()).all(|f| is_subsequence(lo.face_points(f), redrawn.face_points(f))));
}

#[test]
fn updates_give_the_points_of_a_rebuild() {
    let (positions, normals, indices) = test_grid(20);
    let mesh = MeshRef {
        normals: Some(&normals),
        ..MeshRef::new(&positions, &indices)
    };
    let mut rng = SplitMix64(21);
    let opts = options(25.0, 1.0, 99);
    let mut weights = random_weights(&mut rng, positions.len());
    let mut scatter = Scatter::new(mesh, Density::PerVertex(&weights).into(), &opts).unwrap();
    let (mut in_place, mut moved) = (0, 0);
    for step in 0..40 {
        // Edit a few vertices; the faces touching them change. Every
        // fourth step scales nothing at all (same counts: in place).
        let mut touched = Vec::new();
        if step % 4 != 0 {
            for _ in 0..5 {
                let v = rng.below(positions.len() as u64) as u32;
                weights[v as usize] = rng.f32();
                touched.push(v);
            }
        }
        let mut faces: Vec<u32> = (0..indices.len() as u32)
            .filter(|&f| indices[f as usize].iter().any(|v| touched.contains(v)))
            .collect();
        faces.push(rng.below(indices.len() as u64) as u32); // an unchanged face
        faces.reverse(); // any order
        let old = scatter.points().to_vec();
        let update = scatter
            .update_faces(&faces, Density::PerVertex(&weights).into())
            .unwrap();
        let rebuilt = Scatter::new(mesh, Density::PerVertex(&weights).into(), &opts).unwrap();
        assert_eq!(scatter.points(), rebuilt.points(), "step {step}");
        assert_eq!(scatter.offsets(), rebuilt.offsets(), "step {step}");
        // What the update reports is all that changed.
        let mut sorted = faces.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(update.faces, sorted);
        let stable = update.moved_from.unwrap_or(old.len()).min(old.len());
        for (k, (a, b)) in old[..stable].iter().zip(scatter.points()).enumerate() {
            let recomputed = update.faces.binary_search(&a.face).is_ok();
            assert!(
                a == b || recomputed,
                "step {step}: point {k} changed unreported"
            );
        }
        match update.moved_from {
            None => in_place += 1,
            Some(_) => moved += 1,
        }
    }
    assert!(
        in_place > 0 && moved > 0,
        "{in_place} in place, {moved} moved"
    );
}

#[test]
fn the_same_points_on_any_number_of_threads() {
    let (positions, normals, indices) = test_grid(70); // > 4 chunks of faces
    let mesh = MeshRef {
        normals: Some(&normals),
        ..MeshRef::new(&positions, &indices)
    };
    let weights = random_weights(&mut SplitMix64(8), indices.len());
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                scatter(
                    mesh,
                    Density::PerFace(&weights).into(),
                    &options(10.0, 1.0, 4),
                )
                .unwrap()
            })
    };
    let one = run(1);
    assert!(one.len() > 10_000);
    assert_eq!(one, run(3));
}

#[test]
fn bad_arguments_are_errors() {
    let (positions, uvs, indices) = flat_grid(2);
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let uniform = ScatterDensity::Uniform;
    for rate in [f64::NAN, -1.0, f64::INFINITY] {
        let e = Scatter::new(mesh, uniform, &ScatterOptions::new(rate)).unwrap_err();
        assert!(matches!(e, Error::InvalidDensity(_)), "{e}");
    }
    for max in [f64::NAN, -1.0, f64::INFINITY] {
        let e = Scatter::new(mesh, uniform, &options(1.0, max, 0)).unwrap_err();
        assert!(matches!(e, Error::InvalidMaxDensity(_)), "{e}");
    }
    let e = Scatter::new(mesh, uniform, &options(1e9, 1.0, 0)).unwrap_err();
    assert!(matches!(e, Error::TooManyPoints { .. }), "{e}");
    let f = |_: usize, _: [f32; 3]| 0.5;
    let e = Scatter::new(
        mesh,
        ScatterDensity::Function(&f),
        &ScatterOptions::new(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("max_density"), "{e}");
    // A weight above the ceiling names its face, whether or not a
    // candidate falls there; clamping takes it as the ceiling.
    let mut w = vec![0.5f32; indices.len()];
    w[5] = 3.0;
    let e = Scatter::new(mesh, Density::PerFace(&w).into(), &options(0.001, 1.0, 0)).unwrap_err();
    assert_eq!(
        e,
        Error::DensityOutOfRange {
            face: 5,
            value: 3.0,
            max: 1.0
        }
    );
    let clamped = ScatterOptions {
        clamp: true,
        ..options(50.0, 1.0, 0)
    };
    let s = Scatter::new(mesh, Density::PerFace(&w).into(), &clamped).unwrap();
    let w1: Vec<f32> = w.iter().map(|&x| x.min(1.0)).collect();
    let t = Scatter::new(mesh, Density::PerFace(&w1).into(), &clamped).unwrap();
    assert_eq!(s.points().len(), t.points().len());
    // Weights at the ceiling interpolate to it, up to rounding: not an
    // error, and every candidate is kept (as uniform density 1).
    let ones = vec![1.0f32; positions.len()];
    let full = Scatter::new(
        mesh,
        Density::PerVertex(&ones).into(),
        &options(500.0, 1.0, 0),
    )
    .unwrap();
    let all = Scatter::new(mesh, uniform, &options(500.0, 1.0, 0)).unwrap();
    let same = |a: &Scatter<'_>, b: &Scatter<'_>| {
        a.points().len() == b.points().len()
            && a.points()
                .iter()
                .zip(b.points())
                .all(|(p, q)| p.barycentric == q.barycentric)
    };
    assert!(same(&full, &all));
    // A function's NaN or negative value is an error even when clamping.
    let nan = |face: usize, _: [f32; 3]| if face == 3 { f32::NAN } else { 0.5 };
    let e = Scatter::new(mesh, ScatterDensity::Function(&nan), &clamped).unwrap_err();
    assert!(matches!(e, Error::DensityOutOfRange { face: 3, .. }), "{e}");
    let e = Scatter::new(
        mesh,
        Density::PerFace(&w[..3]).into(),
        &options(1.0, 1.0, 0),
    );
    assert!(matches!(e, Err(Error::WeightLength { .. })));
    // Updates: a face out of range, or a bad density, leave it unchanged.
    let mut s = Scatter::new(mesh, uniform, &options(50.0, 1.0, 0)).unwrap();
    let before = s.points().to_vec();
    let e = s.update_faces(&[0, 8], uniform).unwrap_err();
    assert_eq!(e, Error::NoSuchFace { face: 8, count: 8 });
    let e = s
        .update_faces(&[0, 5], Density::PerFace(&w).into())
        .unwrap_err();
    assert!(matches!(e, Error::DensityOutOfRange { face: 5, .. }), "{e}");
    assert_eq!(s.points(), &before[..]);
    let e = s
        .update_faces(&[0], ScatterDensity::Function(&|_, _| 1.5))
        .unwrap_err();
    assert!(matches!(e, Error::DensityOutOfRange { face: 0, .. }), "{e}");
    // Faces that do not exist have no points.
    assert!(s.face_points(usize::MAX).is_empty() && s.face_range(8).is_empty());
    // An empty mesh.
    let e = Scatter::new(
        MeshRef::new(&positions, &[]),
        uniform,
        &ScatterOptions::new(1.0),
    );
    assert!(matches!(e, Err(Error::Empty)));
}

/// Scatter's count on a face, or a deliberately wrong one: the mean
/// rounded up or down at random (Blender's per-triangle count), with the
/// right mean but no Poisson variance.
fn counts(mesh: MeshRef<'_>, weights: &[f32], rate: f64, wrong: bool) -> Vec<u64> {
    let s = Scatter::new(
        mesh,
        Density::PerFace(weights).into(),
        &options(rate, 1.0, 17),
    )
    .unwrap();
    (0..mesh.indices.len())
        .map(|f| {
            if wrong {
                let mean = rate * f64::from(weights[f]) * mesh.area(f);
                let mut rng = chunk_rng(17, f);
                let whole = mean.floor();
                (whole + f64::from(u8::from(unit(rng.next_u64()) < mean - whole))) as u64
            } else {
                s.face_range(f).len() as u64
            }
        })
        .collect()
}

/// The Poisson probabilities of `0..len - 1`, and the tail in the last.
fn poisson_pmf(mean: f64, len: usize) -> Vec<f64> {
    let mut p = vec![(-mean).exp()];
    for k in 1..len - 1 {
        p.push(p[k - 1] * mean / k as f64);
    }
    p.push(1.0 - p.iter().sum::<f64>());
    p
}

#[test]
fn counts_on_faces_are_poisson() {
    // 20,000 equal faces (area ½) with weight ½: the count on each is
    // Poisson with mean rate · ½ · ½ = 3.
    let (positions, _, indices) = flat_grid(100);
    let mesh = MeshRef::new(&positions, &indices);
    let weights = vec![0.5f32; indices.len()];
    let histogram = |counts: &[u64]| {
        let mut h = vec![0u64; 16];
        for &c in counts {
            h[(c as usize).min(15)] += 1;
        }
        h
    };
    let pmf = poisson_pmf(3.0, 16);
    let right = chi_square(&histogram(&counts(mesh, &weights, 12.0, false)), &pmf, 5.0);
    assert!(right.p_value > 1e-3, "{right:?}");
    let wrong = chi_square(&histogram(&counts(mesh, &weights, 12.0, true)), &pmf, 5.0);
    assert!(wrong.p_value < 1e-6, "{wrong:?}");
}

/// The dispersion statistic `Σ (n_f − μ_f)² / μ_f` over faces of unequal
/// means: chi-square with one degree of freedom a face under the Poisson
/// hypothesis; its two-sided p-value.
fn dispersion_p(counts: &[u64], means: &[f64]) -> f64 {
    let d: f64 = counts
        .iter()
        .zip(means)
        .filter(|(_, m)| **m > 0.0)
        .map(|(&n, &m)| (n as f64 - m).powi(2) / m)
        .sum();
    let dof = means.iter().filter(|&&m| m > 0.0).count() as f64;
    let upper = gamma_q(dof / 2.0, d / 2.0);
    2.0 * upper.min(1.0 - upper)
}

#[test]
fn counts_have_the_mean_and_variance_of_rate_times_mass() {
    // Uneven areas (the grid's heights) and random weights.
    let (positions, _, indices) = test_grid(60);
    let mesh = MeshRef::new(&positions, &indices);
    let weights = random_weights(&mut SplitMix64(5), indices.len());
    let rate = 4.0;
    let means: Vec<f64> = (0..indices.len())
        .map(|f| rate * f64::from(weights[f]) * mesh.area(f))
        .collect();
    let total: f64 = means.iter().sum();
    let right = counts(mesh, &weights, rate, false);
    let n: u64 = right.iter().sum();
    assert!(
        (n as f64 - total).abs() < 4.0 * total.sqrt(),
        "{n} vs {total}"
    );
    let p = dispersion_p(&right, &means);
    assert!(p > 1e-3, "p = {p}");
    let p = dispersion_p(&counts(mesh, &weights, rate, true), &means);
    assert!(p < 1e-6, "p = {p}");
}

#[test]
fn positions_follow_a_texture_within_faces() {
    // One unit square (two faces), a 4×4 nearest-texel density: the
    // points per texel are multinomial with the texels' shares.
    let (positions, uvs, indices) = flat_grid(1);
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let texels: Vec<f32> = (0..16).map(|k| 0.05 + (k * 7 % 16) as f32 / 16.0).collect();
    let texture = DensityTexture::new(4, 4, texels.clone())
        .unwrap()
        .with_filter(Filter::Nearest);
    let shares = test_support::stats::probabilities(
        &texels.iter().map(|&t| f64::from(t)).collect::<Vec<_>>(),
    );
    let cell_counts = |points: &[SurfacePoint]| {
        let mut c = vec![0u64; 16];
        for p in points {
            let uv = p.uv.unwrap();
            let (x, y) = ((uv.x * 4.0) as usize, (uv.y * 4.0) as usize);
            c[y.min(3) * 4 + x.min(3)] += 1;
        }
        c
    };
    let opts = options(200_000.0, f64::from(texture.max()), 2);
    let points = scatter(mesh, Density::Texture(&texture).into(), &opts).unwrap();
    let right = chi_square(&cell_counts(&points), &shares, 5.0);
    assert!(right.p_value > 1e-3, "{right:?}");
    // Wrong: the right number of points, spread uniformly.
    let mean = texels.iter().map(|&t| f64::from(t)).sum::<f64>() / 16.0;
    let uniform = scatter(
        mesh,
        ScatterDensity::Uniform,
        &options(200_000.0 * mean, 1.0, 2),
    )
    .unwrap();
    let wrong = chi_square(&cell_counts(&uniform), &shares, 5.0);
    assert!(wrong.p_value < 1e-6, "{wrong:?}");
    // Each point reports its intensity, rate × density.
    for p in &points[..100] {
        let d = texture.eval(p.uv.unwrap().as_dvec2());
        assert!((f64::from(p.pdf) - 200_000.0 * d).abs() < 1e-2 * f64::from(p.pdf));
    }
}

#[test]
fn positions_follow_a_per_vertex_gradient() {
    // One triangle with weights (0, 0, 1) at its corners: the density is
    // the third barycentric.
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let indices = [[0u32, 1, 2]];
    let mesh = MeshRef::new(&positions, &indices);
    let bins = 20;
    let probs: Vec<f64> = (0..bins)
        .map(|k| {
            let (a, b) = (k as f64 / bins as f64, (k + 1) as f64 / bins as f64);
            // Uniform on the triangle, b2 has density 2 (1 − t); times
            // the density t, normalised: 6 t (1 − t), CDF 3t² − 2t³.
            (3.0 * b * b - 2.0 * b * b * b) - (3.0 * a * a - 2.0 * a * a * a)
        })
        .collect();
    let histogram = |points: &[SurfacePoint]| {
        let mut h = vec![0u64; bins];
        for p in points {
            h[((p.barycentric[2] * bins as f32) as usize).min(bins - 1)] += 1;
        }
        h
    };
    let w = [0.0f32, 0.0, 1.0];
    let points = scatter(
        mesh,
        Density::PerVertex(&w).into(),
        &options(400_000.0, 1.0, 9),
    )
    .unwrap();
    let right = chi_square(&histogram(&points), &probs, 5.0);
    assert!(right.p_value > 1e-3, "{right:?}");
    // Wrong: the same points thinned with the threshold taken against 2
    // instead of the ceiling: accepts as if the density were halved and
    // offset (keep iff u < (1 + b2) / 2).
    let half = |_: usize, b: [f32; 3]| 0.5 + 0.5 * b[2];
    let wrong = scatter(
        mesh,
        ScatterDensity::Function(&half),
        &options(400_000.0, 1.0, 9),
    )
    .unwrap();
    let wrong = chi_square(&histogram(&wrong), &probs, 5.0);
    assert!(wrong.p_value < 1e-6, "{wrong:?}");
}

#[test]
fn updates_with_counts_rising_and_falling_in_any_mix_give_a_rebuild() {
    let (positions, _, indices) = flat_grid(16);
    let mesh = MeshRef::new(&positions, &indices);
    let mut rng = SplitMix64(77);
    let opts = options(20.0, 1.0, 3);
    let mut weights = random_weights(&mut rng, indices.len());
    // Without room around the points: the first update that grows needs a
    // new buffer, later ones move either side.
    let mut scatter =
        Scatter::build(mesh, Density::PerFace(&weights).into(), &opts, false).unwrap();
    let (mut moved_front, mut regrown) = (false, false);
    for step in 0..200 {
        let faces: Vec<u32> = (0..1 + rng.below(12))
            .map(|_| rng.below(indices.len() as u64) as u32)
            .collect();
        for &f in &faces {
            // Zero, full, or anything between.
            weights[f as usize] = [0.0, 1.0, rng.f32()][rng.below(3) as usize];
        }
        let (base, room) = (scatter.base, scatter.buffer.len());
        scatter
            .update_faces(&faces, Density::PerFace(&weights).into())
            .unwrap();
        moved_front |= base != 0 && scatter.base != base && scatter.buffer.len() == room;
        regrown |= scatter.buffer.len() != room;
        let rebuilt = Scatter::new(mesh, Density::PerFace(&weights).into(), &opts).unwrap();
        assert!(scatter.points() == rebuilt.points(), "step {step}");
        assert_eq!(scatter.offsets(), rebuilt.offsets(), "step {step}");
    }
    assert!(moved_front, "no update moved the points before an edit");
    assert!(regrown, "no update needed a new buffer");
}
