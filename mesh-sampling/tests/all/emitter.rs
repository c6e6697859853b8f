//! Light sampling (`Emitter`): next-event estimates of the irradiance
//! from a constant-radiance square against Lambert's closed form, for
//! every strategy and for a light tree's use of `sample_in_triangle` (and
//! two wrong twins that must fail the same test); the emitted power
//! against an independent quadrature of the texture; pdfs at sampling
//! time against the pdfs from (face, barycentric); chi-square of points
//! against the texture's mass per texel; sides; determinism; errors.

use test_support::stats;

use glam::{DVec3, Vec2, Vec3};
use mesh_sampling::{
    Emission, EmissionTexture, Emitter, EmitterOptions, Error, Filter, LightSample, MeshRef, Sides,
    Strategy,
};
use rand::distr::Distribution;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Positions, UVs and triangles.
type Mesh = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

fn mesh_ref(m: &Mesh) -> MeshRef<'_> {
    MeshRef {
        uvs: Some(&m.1),
        ..MeshRef::new(&m.0, &m.2)
    }
}

/// The square `[−1, 2]²` at height `z`, in `n × n` cells of two
/// triangles, facing down (corners counter-clockwise seen from below), UV
/// `[0, 1]²` over it.
fn ceiling(n: usize, z: f32) -> Mesh {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            positions.push(Vec3::new(3.0 * s - 1.0, 3.0 * t - 1.0, z));
            uvs.push(Vec2::new(s, t));
        }
    }
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x, y + 1), at(x + 1, y)]);
            indices.push([at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)]);
        }
    }
    (positions, uvs, indices)
}

/// 12 × 12 texels, nearest filtering, black but for the middle 4 × 4,
/// which on [`ceiling`] is exactly the unit square `[0, 1]²` (whose edges
/// cut through triangles): constant radiance `LIT` there.
fn lit_square() -> EmissionTexture {
    let rgb = (0..144)
        .map(|k| {
            let (x, y) = (k % 12, k / 12);
            if (4..8).contains(&x) && (4..8).contains(&y) {
                LIT
            } else {
                [0.0; 3]
            }
        })
        .collect();
    EmissionTexture::new(12, 12, rgb)
        .unwrap()
        .with_filter(Filter::Nearest)
}

const LIT: [f32; 3] = [2.0, 1.0, 0.5];

/// Irradiance at `x` (unit normal `n`) from a polygon of constant
/// radiance `radiance` entirely above `x`'s horizon: Lambert's formula
/// `E = L/2 · |Σ βᵢ n·γᵢ|` over the polygon's edges.
fn lambert(radiance: f64, corners: &[DVec3], x: DVec3, n: DVec3) -> f64 {
    let u: Vec<DVec3> = corners.iter().map(|c| (*c - x).normalize()).collect();
    let mut sum = 0.0;
    for i in 0..u.len() {
        let (a, b) = (u[i], u[(i + 1) % u.len()]);
        sum += a.dot(b).clamp(-1.0, 1.0).acos() * n.dot(a.cross(b).normalize());
    }
    radiance * 0.5 * sum.abs()
}

fn unit_square(z: f64) -> [DVec3; 4] {
    [
        DVec3::new(0.0, 0.0, z),
        DVec3::new(1.0, 0.0, z),
        DVec3::new(1.0, 1.0, z),
        DVec3::new(0.0, 1.0, z),
    ]
}

/// The receiver: a point below the square, its normal tilted.
fn receiver() -> (Vec3, Vec3) {
    (
        Vec3::new(0.3, 0.4, 0.0),
        Vec3::new(0.3, 0.1, 1.0).normalize(),
    )
}

/// Mean and standard error.
fn mean_se(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = stats::exact_sum(values.iter().copied()) / n;
    let var = stats::exact_sum(values.iter().map(|v| (v - mean) * (v - mean))) / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// How an estimate turns a sample into irradiance.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Estimator {
    /// `Le · cos_r / pdf_ω`: right.
    Right,
    /// `Le · cos_r / pdf_A`: the area pdf used as if it were solid angle.
    AreaAsSolidAngle,
    /// `Le · cos_r / (pdf_A · d²)`: the Jacobian's cosine left out.
    NoCosine,
}

/// Red-channel irradiance at `x` (normal `n`) of one sample.
fn estimate(emitter: &Emitter<'_>, s: &LightSample, x: Vec3, n: Vec3, how: Estimator) -> f64 {
    let t = emitter.toward(s, x);
    if t.pdf_solid_angle == 0.0 {
        return 0.0;
    }
    let cos_r = f64::from(n.dot(t.direction).max(0.0));
    let le = f64::from(t.radiance[0]);
    let pdf = match how {
        Estimator::Right => f64::from(t.pdf_solid_angle),
        Estimator::AreaAsSolidAngle => f64::from(s.pdf_area()),
        Estimator::NoCosine => f64::from(s.pdf_area()) * f64::from(t.distance).powi(2),
    };
    le * cos_r / pdf
}

/// The closed form agrees with a midpoint quadrature of
/// `L cos θ_r cos θ_l / d²` over the square (so the reference of the
/// tests below is right, not only self-consistent).
#[test]
fn lamberts_formula_matches_quadrature() {
    let (x, n) = receiver();
    let (x, n) = (x.as_dvec3(), n.as_dvec3());
    let k = 400;
    let mut sum = 0.0;
    for j in 0..k {
        for i in 0..k {
            let p = DVec3::new(
                (i as f64 + 0.5) / k as f64,
                (j as f64 + 0.5) / k as f64,
                1.0,
            );
            let d = p - x;
            let r2 = d.length_squared();
            let w = d / r2.sqrt();
            sum += n.dot(w) * w.z / r2;
        }
    }
    let quadrature = 2.0 * sum / (k * k) as f64;
    let closed = lambert(2.0, &unit_square(1.0), x, n);
    assert!(
        (quadrature - closed).abs() < 1e-5 * closed,
        "{quadrature} vs {closed}"
    );
}

/// Every strategy's next-event estimate of the irradiance from the lit
/// square (nearest-filtered texture, black around it, on triangles its
/// edges cut) matches Lambert's closed form within 4 standard errors
/// (measured from the samples, and at most 1.5% of the irradiance so the
/// test has power); both wrong twins fail the same test by more than 10
/// standard errors. The subdivision strategy here needs its defensive
/// mixture: triangles cut by the square's edge have parts lit where the
/// barycenter of a sub-triangle is black.
#[test]
fn next_event_estimates_match_the_closed_form_and_wrong_twins_fail() {
    let mesh = ceiling(5, 1.0);
    let texture = lit_square();
    let (x, n) = receiver();
    let want = lambert(2.0, &unit_square(1.0), x.as_dvec3(), n.as_dvec3());
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    for strategy in Strategy::ALL {
        let options = EmitterOptions {
            strategy,
            ..Default::default()
        };
        let emitter = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
        if strategy == Strategy::Texture {
            assert!(emitter.defensive_fraction() > 0.0);
        }
        let samples = emitter.sample_n(11, 200_000).unwrap();
        for how in [
            Estimator::Right,
            Estimator::AreaAsSolidAngle,
            Estimator::NoCosine,
        ] {
            let values: Vec<f64> = samples
                .iter()
                .map(|s| estimate(&emitter, s, x, n, how))
                .collect();
            let (mean, se) = mean_se(&values);
            let z = (mean - want) / se;
            if how == Estimator::Right {
                assert!(
                    z.abs() < 4.0 && se < 0.015 * want,
                    "{strategy:?}: {mean} ± {se} vs {want}"
                );
            } else {
                assert!(
                    z.abs() > 10.0,
                    "{strategy:?} {how:?} should fail: {mean} ± {se} vs {want}"
                );
            }
        }
    }
}

/// A light tree's use: a triangle chosen with probability proportional to
/// `triangle_power`, a point in it by `sample_in_triangle`, the pdf the
/// product of the two; the estimate matches the closed form for every
/// strategy, and `pdf_in_triangle` gives each sample's pdf.
#[test]
fn light_tree_estimates_through_sample_in_triangle_match_the_closed_form() {
    let mesh = ceiling(5, 1.0);
    let texture = lit_square();
    let (x, n) = receiver();
    let want = lambert(2.0, &unit_square(1.0), x.as_dvec3(), n.as_dvec3());
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    for strategy in Strategy::ALL {
        let options = EmitterOptions {
            strategy,
            ..Default::default()
        };
        let emitter = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
        let powers: Vec<f64> = (0..mesh.2.len())
            .map(|f| emitter.triangle_power(f).unwrap())
            .collect();
        let total: f64 = powers.iter().sum();
        assert!((total - emitter.power()).abs() < 1e-9 * total);
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let values: Vec<f64> = (0..100_000)
            .map(|_| {
                let mut t = rng.random::<f64>() * total;
                let f = (0..powers.len())
                    .find(|&f| {
                        t -= powers[f];
                        t < 0.0 && powers[f] > 0.0
                    })
                    .unwrap_or_else(|| powers.iter().rposition(|&p| p > 0.0).unwrap());
                let u = [rng.random::<f64>(), rng.random::<f64>()];
                let s = emitter.sample_in_triangle(f, u).unwrap();
                assert_eq!(s.point.face as usize, f);
                assert_eq!(
                    emitter.pdf_in_triangle(f, s.point.barycentric),
                    s.point.pdf,
                    "{strategy:?}"
                );
                let toward = emitter.toward(&s, x);
                if toward.pdf_solid_angle > 0.0 {
                    f64::from(toward.radiance[0]) * f64::from(n.dot(toward.direction).max(0.0))
                        / (f64::from(toward.pdf_solid_angle) * powers[f] / total)
                } else {
                    0.0
                }
            })
            .collect();
        let (mean, se) = mean_se(&values);
        assert!(
            (mean - want).abs() < 4.0 * se && se < 0.015 * want,
            "{strategy:?}: {mean} ± {se} vs {want}"
        );
    }
}

/// Per-face radiance (some triangles lit): the estimate matches the sum
/// of Lambert's formula over the lit triangles, for every strategy.
#[test]
fn per_face_radiance_estimates_match_the_closed_form() {
    let mesh = ceiling(4, 1.0);
    let radiance: Vec<[f32; 3]> = (0..mesh.2.len())
        .map(|f| {
            if f % 3 == 0 {
                [1.0 + f as f32 * 0.1, 0.0, 0.0]
            } else {
                [0.0; 3]
            }
        })
        .collect();
    let (x, n) = receiver();
    let want: f64 = (0..mesh.2.len())
        .filter(|f| f % 3 == 0)
        .map(|f| {
            let corners = mesh.2[f].map(|i| mesh.0[i as usize].as_dvec3());
            lambert(
                f64::from(radiance[f][0]),
                &corners,
                x.as_dvec3(),
                n.as_dvec3(),
            )
        })
        .sum();
    for strategy in Strategy::ALL {
        let options = EmitterOptions {
            strategy,
            ..Default::default()
        };
        let emitter =
            Emitter::new(mesh_ref(&mesh), Emission::PerFace(&radiance), &options).unwrap();
        let values: Vec<f64> = emitter
            .sample_n(5, 100_000)
            .unwrap()
            .iter()
            .map(|s| estimate(&emitter, s, x, n, Estimator::Right))
            .collect();
        let (mean, se) = mean_se(&values);
        assert!(
            (mean - want).abs() < 4.0 * se && se < 0.02 * want,
            "{strategy:?}: {mean} ± {se} vs {want}"
        );
    }
}

/// A smooth RGB texture on a warped grid whose UVs overlap and tile.
fn warped(n: usize) -> (Mesh, EmissionTexture) {
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = 0.15 * (7.0 * s).sin() * (5.0 * t).cos();
            positions.push(Vec3::new(s.powf(1.3), t, z));
            // Folded (overlapping) in u, tiled twice in v.
            uvs.push(Vec2::new(0.8 - (1.6 * s - 0.8).abs(), 2.0 * t));
        }
    }
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x + 1, y), at(x, y + 1)]);
            indices.push([at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    let (w, h) = (24, 16);
    let rgb = (0..w * h)
        .map(|k| {
            let (x, y) = ((k % w) as f32 / w as f32, (k / w) as f32 / h as f32);
            [
                1.0 + (6.0 * x).sin() * (4.0 * y).cos(),
                0.5 + 0.4 * (9.0 * x * y).sin(),
                (3.0 * y).sin().abs() * 3.0,
            ]
        })
        .collect();
    (
        (positions, uvs, indices),
        EmissionTexture::new(w, h, rgb).unwrap(),
    )
}

/// The bilinear luminance at `uv` with repeat, computed here from the RGB
/// texels (independently of the library's filtering).
fn luminance_at(t: &EmissionTexture, uv: Vec2) -> f64 {
    let (w, h) = (t.width() as i64, t.height() as i64);
    let (x, y) = (
        f64::from(uv.x) * w as f64 - 0.5,
        f64::from(uv.y) * h as f64 - 0.5,
    );
    let (x0, y0) = (x.floor(), y.floor());
    let y_of = |i: i64, j: i64| {
        let c = t.texels()[(j.rem_euclid(h) * w + i.rem_euclid(w)) as usize];
        0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let (fx, fy) = (x - x0, y - y0);
    let top = y_of(i, j) * (1.0 - fx) + y_of(i + 1, j) * fx;
    let bottom = y_of(i, j + 1) * (1.0 - fx) + y_of(i + 1, j + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// `power()` is `sides · π · scale · ∫ Y dA` of the texture, against a
/// midpoint quadrature on 4⁵ sub-triangles per triangle; the triangle
/// powers add up to it, two sides emit twice, and the strategy does not
/// change it.
#[test]
fn the_power_is_the_textures_integral() {
    let (mesh, texture) = warped(6);
    let scale = 2.5f32;
    let mut want = 0.0;
    let k = 32usize; // 32² = 4⁵ sub-triangles per triangle
    for tri in &mesh.2 {
        let p = tri.map(|i| mesh.0[i as usize].as_dvec3());
        let t = tri.map(|i| mesh.1[i as usize]);
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        let mut sum = 0.0;
        // Midpoints of the k² sub-triangles of a regular split.
        for j in 0..k {
            for i in 0..k - j {
                for (a, b, upward) in [(i, j, true), (i, j, false)] {
                    if !upward && a + b + 1 >= k {
                        continue;
                    }
                    let (u, v) = if upward {
                        (
                            (a as f32 + 1.0 / 3.0) / k as f32,
                            (b as f32 + 1.0 / 3.0) / k as f32,
                        )
                    } else {
                        (
                            (a as f32 + 2.0 / 3.0) / k as f32,
                            (b as f32 + 2.0 / 3.0) / k as f32,
                        )
                    };
                    sum += luminance_at(&texture, t[0] + (t[1] - t[0]) * u + (t[2] - t[0]) * v);
                }
            }
        }
        want += sum / (k * k) as f64 * area;
    }
    want *= std::f64::consts::PI * f64::from(scale);
    let emission = Emission::Texture {
        texture: &texture,
        scale,
    };
    for strategy in Strategy::ALL {
        for sides in [Sides::Front, Sides::Both] {
            let options = EmitterOptions {
                strategy,
                sides,
                ..Default::default()
            };
            let e = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
            let factor = if sides == Sides::Both { 2.0 } else { 1.0 };
            assert!(
                (e.power() - factor * want).abs() < 2e-4 * want,
                "{strategy:?} {sides:?}: {} vs {}",
                e.power(),
                factor * want
            );
            let sum: f64 = (0..mesh.2.len())
                .map(|f| e.triangle_power(f).unwrap())
                .sum();
            assert!((sum - e.power()).abs() < 1e-9 * sum);
        }
    }
}

/// The pdf a sample carries is the pdf from (face, barycentric), in area
/// and in solid angle (bit for bit), for every strategy, on the lit
/// square (defensive mixture) and the warped, overlapping, tiled mesh.
#[test]
fn pdfs_at_sampling_time_equal_pdfs_from_face_and_barycentrics() {
    let square = (ceiling(5, 1.0), lit_square());
    let warped = warped(6);
    let references = [Vec3::new(0.3, 0.4, 0.0), Vec3::new(0.5, 0.5, 2.0)];
    for (mesh, texture) in [&square, &warped] {
        let emission = Emission::Texture {
            texture,
            scale: 1.0,
        };
        for strategy in Strategy::ALL {
            for sides in [Sides::Front, Sides::Both] {
                let options = EmitterOptions {
                    strategy,
                    sides,
                    ..Default::default()
                };
                let e = Emitter::new(mesh_ref(mesh), emission, &options).unwrap();
                let mut rng = Pcg64Mcg::seed_from_u64(9);
                let single: Vec<LightSample> = (0..2000).map(|_| e.sample(&mut rng)).collect();
                let batch = e.sample_n(4, 20_000).unwrap();
                for s in single.iter().chain(&batch) {
                    let (f, b) = (s.point.face as usize, s.point.barycentric);
                    assert!(s.point.pdf > 0.0, "{strategy:?}");
                    assert_eq!(e.pdf_area(f, b), s.point.pdf, "{strategy:?} at {f} {b:?}");
                    assert_eq!(e.radiance(f, b), s.radiance);
                    for &r in &references {
                        let t = e.toward(s, r);
                        assert_eq!(e.pdf_solid_angle(f, b, r), t.pdf_solid_angle);
                        let expect_emit = t.pdf_solid_angle > 0.0;
                        assert_eq!(
                            e.radiance_toward(f, b, r),
                            if expect_emit { s.radiance } else { [0.0; 3] }
                        );
                    }
                }
            }
        }
    }
}

/// The pdf is positive wherever the filtered emission is: on the lit
/// square's triangles cut by its edge, the paper's `p′` alone (defensive
/// fraction 0, the wrong twin) is 0 at lit points, the default mixture is
/// not; the exact strategy never is. Checked on a lattice of points of
/// every triangle.
#[test]
fn the_pdf_is_positive_wherever_the_emission_is() {
    let mesh = ceiling(5, 1.0);
    let texture = lit_square();
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    let lit_but_zero = |strategy, defensive_fraction| {
        let options = EmitterOptions {
            strategy,
            defensive_fraction,
            ..Default::default()
        };
        let e = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
        let k = 40;
        let mut count = 0;
        for f in 0..mesh.2.len() {
            for j in 0..k {
                for i in 0..k - j {
                    let (u, v) = ((i as f32 + 0.3) / k as f32, (j as f32 + 0.3) / k as f32);
                    let b = [1.0 - u - v, u, v];
                    if e.radiance(f, b)[0] > 0.0 && e.pdf_area(f, b) == 0.0 {
                        count += 1;
                    }
                }
            }
        }
        count
    };
    assert!(lit_but_zero(Strategy::Texture, 0.0) > 0);
    assert_eq!(lit_but_zero(Strategy::Texture, 0.05), 0);
    assert_eq!(lit_but_zero(Strategy::TextureExact, 0.0), 0);
    assert_eq!(lit_but_zero(Strategy::TrianglePower, 0.0), 0);
    assert_eq!(lit_but_zero(Strategy::Area, 0.0), 0);
}

/// The exact strategy's density is proportional to the luminance of the
/// radiance: `Y(Le) / pdf_A` is the same for every sample, `Φ / (sides ·
/// π)`, so the estimate of the power has no variance.
#[test]
fn exact_sampling_makes_luminance_over_pdf_constant() {
    let (mesh, texture) = warped(6);
    let emission = Emission::Texture {
        texture: &texture,
        scale: 0.5,
    };
    let options = EmitterOptions {
        strategy: Strategy::TextureExact,
        sides: Sides::Both,
        ..Default::default()
    };
    let e = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
    let want = e.power() / (2.0 * std::f64::consts::PI);
    for s in e.sample_n(1, 20_000).unwrap() {
        let [r, g, b] = s.radiance.map(f64::from);
        let y = 0.2126 * r + 0.7152 * g + 0.0722 * b;
        let ratio = y / f64::from(s.pdf_area());
        assert!((ratio - want).abs() < 1e-5 * want, "{ratio} vs {want}");
    }
}

/// Many samples of the subdivision strategy on two large triangles with a
/// fine texture, where some points' `f32` barycentrics round across a
/// sub-triangle's edge: the pdf they carry is still the pdf at their
/// stored barycentrics, for every one of them.
#[test]
fn pdfs_agree_also_where_barycentrics_round_across_sub_triangles() {
    let positions = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let uvs = [Vec2::ZERO, Vec2::Y, Vec2::X, Vec2::ONE];
    let indices = [[0, 1, 2], [2, 1, 3]];
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let (w, h) = (256, 128);
    let rgb = (0..w * h)
        .map(|k| {
            let v = 0.5 + ((k * 7919) % 97) as f32;
            [v, v, v]
        })
        .collect();
    let texture = EmissionTexture::new(w, h, rgb).unwrap();
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    let e = Emitter::new(mesh, emission, &EmitterOptions::default()).unwrap();
    let x = Vec3::new(0.5, 0.5, 0.0);
    for s in e.sample_n(6, 400_000).unwrap() {
        let (f, b) = (s.point.face as usize, s.point.barycentric);
        assert_eq!(e.pdf_area(f, b), s.point.pdf, "at {f} {b:?}");
        assert_eq!(e.pdf_solid_angle(f, b, x), e.toward(&s, x).pdf_solid_angle);
    }
}

/// The texture strategies draw points by the texture's mass per texel
/// (chi-square on a flat square whose UVs map it once, nearest filtering,
/// so a texel's mass is its value times its area); the area strategy
/// fails the same test.
#[test]
fn texture_strategies_follow_the_mass_per_texel() {
    let (w, h) = (16usize, 16usize);
    let rgb: Vec<[f32; 3]> = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let v =
                0.1 + ((x * 7 + y * 3) % 11) as f32 + if x == 3 && y == 12 { 40.0 } else { 0.0 };
            [v, 0.5 * v, 0.25 * v]
        })
        .collect();
    let texture = EmissionTexture::new(w, h, rgb.clone())
        .unwrap()
        .with_filter(Filter::Nearest);
    let positions = [
        Vec3::ZERO,
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.0, 2.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
    ];
    let uvs = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
    let indices = [[0, 1, 2], [1, 3, 2]];
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let weights: Vec<f64> = texture
        .luminance()
        .texels()
        .iter()
        .map(|&y| f64::from(y))
        .collect();
    let expected = stats::probabilities(&weights);
    let emission = Emission::Texture {
        texture: &texture,
        scale: 3.0,
    };
    for strategy in Strategy::ALL {
        let options = EmitterOptions {
            strategy,
            ..Default::default()
        };
        let e = Emitter::new(mesh, emission, &options).unwrap();
        let mut counts = vec![0u64; w * h];
        for s in e.sample_n(21, 200_000).unwrap() {
            let uv = s.point.uv.unwrap();
            let x = ((uv.x * w as f32) as usize).min(w - 1);
            let y = ((uv.y * h as f32) as usize).min(h - 1);
            counts[y * w + x] += 1;
        }
        let test = stats::chi_square(&counts, &expected, 20.0);
        match strategy {
            Strategy::Texture | Strategy::TextureExact => {
                assert!(test.p_value > 1e-4, "{strategy:?}: {test:?}");
            }
            _ => assert!(test.p_value < 1e-12, "{strategy:?} should fail: {test:?}"),
        }
    }
}

/// One-sided: a reference behind the emitter gets pdf 0 and no radiance;
/// two-sided, the same estimate from behind as from the front.
#[test]
fn one_sided_emitters_are_dark_from_behind_and_two_sided_are_not() {
    let mesh = ceiling(5, 1.0);
    let texture = lit_square();
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    let below = (Vec3::new(0.3, 0.4, 0.0), Vec3::Z);
    let above = (Vec3::new(0.3, 0.4, 2.0), Vec3::NEG_Z);
    for strategy in Strategy::ALL {
        let front = Emitter::new(
            mesh_ref(&mesh),
            emission,
            &EmitterOptions {
                strategy,
                ..Default::default()
            },
        )
        .unwrap();
        let both = Emitter::new(
            mesh_ref(&mesh),
            emission,
            &EmitterOptions {
                strategy,
                sides: Sides::Both,
                ..Default::default()
            },
        )
        .unwrap();
        assert!((both.power() - 2.0 * front.power()).abs() < 1e-9 * front.power());
        let samples = front.sample_n(2, 20_000).unwrap();
        for s in &samples {
            let t = front.toward(s, above.0);
            assert_eq!((t.pdf_solid_angle, t.radiance), (0.0, [0.0; 3]));
            assert!(t.cos_light < 0.0);
        }
        let estimate_from = |(x, n): (Vec3, Vec3)| {
            let samples = both.sample_n(2, 50_000).unwrap();
            let v: Vec<f64> = samples
                .iter()
                .map(|s| estimate(&both, s, x, n, Estimator::Right))
                .collect();
            mean_se(&v)
        };
        let ((a, sa), (b, sb)) = (estimate_from(below), estimate_from(above));
        // Mirror images: the same samples give the same estimate.
        assert!((a - b).abs() < 1e-9 * a + 1e-3 * (sa + sb), "{a} vs {b}");
    }
}

/// Batches are the same on one thread and on many.
#[test]
fn batches_do_not_depend_on_the_thread_count() {
    let (mesh, texture) = warped(6);
    let emission = Emission::Texture {
        texture: &texture,
        scale: 1.0,
    };
    for strategy in Strategy::ALL {
        let options = EmitterOptions {
            strategy,
            ..Default::default()
        };
        let e = Emitter::new(mesh_ref(&mesh), emission, &options).unwrap();
        let many = e.sample_n(8, 40_000).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let one = pool.install(|| e.sample_n(8, 40_000).unwrap());
        assert_eq!(many, one, "{strategy:?}");
    }
}

#[test]
fn bad_input_is_an_error_naming_the_problem() {
    let mesh = ceiling(2, 1.0);
    let texture = lit_square();
    let m = mesh_ref(&mesh);
    let opts = EmitterOptions::default();
    let tex = |scale| Emission::Texture {
        texture: &texture,
        scale,
    };
    assert_eq!(
        Emitter::new(m, tex(-1.0), &opts).unwrap_err(),
        Error::InvalidScale(-1.0)
    );
    assert!(matches!(
        Emitter::new(m, tex(f32::NAN), &opts),
        Err(Error::InvalidScale(_))
    ));
    assert_eq!(
        Emitter::new(m, tex(0.0), &opts).unwrap_err(),
        Error::NoEmission { triangles: 8 }
    );
    let no_uvs = MeshRef::new(&mesh.0, &mesh.2);
    assert_eq!(
        Emitter::new(no_uvs, tex(1.0), &opts).unwrap_err(),
        Error::MissingUvs
    );
    assert_eq!(
        Emitter::new(m, Emission::PerFace(&[[1.0; 3]; 3]), &opts).unwrap_err(),
        Error::RadianceLength {
            len: 3,
            expected: 8
        }
    );
    let mut radiance = vec![[1.0f32; 3]; 8];
    radiance[5][1] = f32::INFINITY;
    let e = Emitter::new(m, Emission::PerFace(&radiance), &opts).unwrap_err();
    assert_eq!(
        e,
        Error::InvalidRadiance {
            face: 5,
            value: f32::INFINITY
        }
    );
    assert!(e.to_string().contains("face 5"), "{e}");
    for fraction in [-0.1, 1.0, f64::NAN] {
        let o = EmitterOptions {
            defensive_fraction: fraction,
            ..Default::default()
        };
        assert!(matches!(
            Emitter::new(m, tex(1.0), &o),
            Err(Error::InvalidOption(_))
        ));
    }
    let e = Emitter::new(m, tex(1.0), &opts).unwrap();
    assert_eq!(
        e.triangle_power(8).unwrap_err(),
        Error::NoSuchFace { face: 8, count: 8 }
    );
    assert!(e.triangle_bounds(99).is_err());
    assert!(matches!(
        e.sample_in_triangle(8, [0.5; 2]),
        Err(Error::NoSuchFace { .. })
    ));
    // Triangle 0 is at the corner, all black.
    assert_eq!(e.triangle_power(0).unwrap(), 0.0);
    assert_eq!(
        e.sample_in_triangle(0, [0.5; 2]).unwrap_err(),
        Error::DarkTriangle { face: 0 }
    );
    assert_eq!(e.pdf_area(99, [1.0, 0.0, 0.0]), 0.0);
    assert_eq!(e.pdf_solid_angle(99, [1.0, 0.0, 0.0], Vec3::ZERO), 0.0);
    assert_eq!(e.radiance(99, [1.0, 0.0, 0.0]), [0.0; 3]);
    assert_eq!(e.pdf_area(3, [f32::NAN; 3]), 0.0);
    // Variates outside [0, 1) are clamped, NaN is 0: no panic.
    let lit = (0..8)
        .find(|&f| e.triangle_power(f).unwrap() > 0.0)
        .unwrap();
    for u in [[f64::NAN, 2.0], [-1.0, 1.0], [1.0, 1.0]] {
        let s = e.sample_in_triangle(lit, u).unwrap();
        assert!(s.point.pdf > 0.0);
    }
    let b = e.triangle_bounds(0).unwrap();
    assert_eq!(b.normal, Vec3::NEG_Z);
    assert!(b.min.cmple(b.max).all());
}

/// Each HDR image of `$TRILUX_DATA/hdr` (1024 × 512, one with a sun) as
/// the emission of a one-sided panel of 2 × 16 × 16 triangles above a
/// receiver: every strategy's next-event estimate of the irradiance agrees
/// with a midpoint quadrature of `Le cos θ_r cos θ_l / d²` (2 × 2 points
/// per texel) within 5 standard errors (but the area strategy's, whose
/// heavy tail makes its standard error unreliable), and the texture
/// strategies' sample variance is below the area strategy's (printed: the
/// paper's Fig. 1b in one number per strategy, without timing).
#[test]
#[cfg_attr(
    not(trilux_data),
    ignore = "needs TRILUX_DATA (the data folder, e.g. ../shared/data)"
)]
fn hdr_luminaires_agree_with_quadrature() {
    let dir = test_support::data::data_dir().expect("TRILUX_DATA names the data folder");
    let mut files: Vec<_> = std::fs::read_dir(dir.join("hdr"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "hdr"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    // The panel [0, 1]² at z = 1, facing down; image row 0 at y = 0.
    let n = 16;
    let (mut positions, mut uvs, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            positions.push(Vec3::new(s, t, 1.0));
            uvs.push(Vec2::new(s, t));
        }
    }
    let at = |x: usize, y: usize| (y * (n + 1) + x) as u32;
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x, y + 1), at(x + 1, y)]);
            indices.push([at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)]);
        }
    }
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let (x, normal) = (DVec3::new(0.4, 0.55, 0.0), DVec3::Z);
    for file in files {
        let image = trilux_io::image::read(&file).unwrap();
        let (w, h) = (image.width as usize, image.height as usize);
        let flat: Vec<f32> = image.pixels.iter().flatten().copied().collect();
        let texture = EmissionTexture::from_channels(w, h, &flat, 4)
            .unwrap()
            .with_wrap(mesh_sampling::Wrap::ClampToEdge);
        // The reference: the midpoint rule on 2w × 2h points.
        let (kw, kh) = (2 * w, 2 * h);
        let mut sum = 0.0;
        for j in 0..kh {
            for i in 0..kw {
                let (s, t) = ((i as f64 + 0.5) / kw as f64, (j as f64 + 0.5) / kh as f64);
                let le = texture.eval(glam::DVec2::new(s, t))[0];
                let d = DVec3::new(s, t, 1.0) - x;
                let r2 = d.length_squared();
                let dir = d / r2.sqrt();
                sum += le * normal.dot(dir).max(0.0) * dir.z / r2;
            }
        }
        let want = sum / (kw * kh) as f64;
        let emission = Emission::Texture {
            texture: &texture,
            scale: 1.0,
        };
        let mut variance = Vec::new();
        for strategy in Strategy::ALL {
            let options = EmitterOptions {
                strategy,
                ..Default::default()
            };
            let e = Emitter::new(mesh, emission, &options).unwrap();
            let values: Vec<f64> = e
                .sample_n(17, 100_000)
                .unwrap()
                .iter()
                .map(|s| estimate(&e, s, x.as_vec3(), normal.as_vec3(), Estimator::Right))
                .collect();
            let (mean, se) = mean_se(&values);
            // By area, a small sun is hit a handful of times in 10⁵
            // samples: the heavy tail makes the sample's standard error
            // itself unreliable, so that estimate is only printed.
            assert!(
                strategy == Strategy::Area || (mean - want).abs() < 5.0 * se + 1e-4 * want,
                "{} {strategy:?}: {mean} ± {se} vs {want}",
                file.display()
            );
            let relative = (se * se * values.len() as f64) / (want * want);
            eprintln!(
                "{}: {:>14} {mean:.4} ± {se:.4} (reference {want:.4}), relative variance \
                 {relative:.3e}",
                file.display(),
                strategy.name()
            );
            variance.push(relative);
        }
        assert!(
            variance[2] < variance[0] && variance[3] < variance[0],
            "{variance:?}"
        );
    }
}
