//! Environment maps for renderers: direction ↔ map point, and the density
//! of a direction with respect to solid angle, checked by an independent
//! parametrisation of the sphere (z and φ, Archimedes' equal-area map)
//! rather than the map's own θ.

use std::f64::consts::PI;

use discrete_sampling::{Distribution2D, equirect_direction, equirect_point};
use rand::SeedableRng;
use rand::distr::Distribution;
use rand_pcg::Pcg64Mcg;

use crate::stats::chi_square;

const W: usize = 16;
const H: usize = 8;

/// A 16×8 map with structure in both directions, a zero texel and a
/// bright spot near the top.
fn map() -> Vec<f64> {
    let mut m: Vec<f64> = (0..W * H)
        .map(|i| 1.0 + ((i % W) % 3) as f64 + (i / W) as f64 * 0.5)
        .collect();
    m[W + 3] = 40.0;
    m[5 * W + 9] = 0.0;
    m
}

/// The direction of Archimedes' coordinates `(z, φ)`.
fn direction(z: f64, phi: f64) -> [f64; 3] {
    let r = (1.0 - z * z).max(0.0).sqrt();
    [r * phi.cos(), r * phi.sin(), z]
}

#[test]
fn direction_and_point_round_trip() {
    for j in 0..200 {
        for i in 0..200 {
            let p = [(i as f64 + 0.5) / 200.0, (j as f64 + 0.5) / 200.0];
            let d = equirect_direction(p);
            let back = equirect_point(d).unwrap();
            assert!((back[0] - p[0]).abs() < 1e-12, "{p:?} -> {back:?}");
            assert!((back[1] - p[1]).abs() < 1e-12, "{p:?} -> {back:?}");
            // Any length.
            let scaled = equirect_point([3.0 * d[0], 3.0 * d[1], 3.0 * d[2]]).unwrap();
            assert!((scaled[0] - back[0]).abs() < 1e-14 && (scaled[1] - back[1]).abs() < 1e-14);
        }
    }
    let mut rng = Pcg64Mcg::seed_from_u64(3);
    let normal = rand_distr::StandardNormal;
    for _ in 0..10_000 {
        let v: [f64; 3] = std::array::from_fn(|_| normal.sample(&mut rng));
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let p = equirect_point(v).unwrap();
        assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]));
        let d = equirect_direction(p);
        for k in 0..3 {
            assert!((d[k] - v[k] / len).abs() < 1e-12, "{v:?}");
        }
    }
    // Axes and edge cases.
    assert_eq!(equirect_point([0.0, 0.0, 1.0]), Some([0.0, 0.0]));
    assert_eq!(equirect_point([1.0, 0.0, 0.0]), Some([0.0, 0.5]));
    let down = equirect_point([0.0, 0.0, -5.0]).unwrap();
    assert!(down[1] < 1.0 && down[1] > 0.999_999);
    let just_below = equirect_point([1.0, -1e-300, 0.0]).unwrap();
    assert!(just_below[0] < 1.0);
    assert_eq!(equirect_point([0.0; 3]), None);
    assert_eq!(equirect_point([f64::NAN, 0.0, 1.0]), None);
    assert_eq!(equirect_point([f64::INFINITY, 0.0, 1.0]), None);
    assert!(equirect_point([f64::MAX, f64::MAX, 0.0]).is_some());
}

/// `∫ f(ω) dω` over the part of the sphere with `z ∈ [z0, z1]`,
/// `φ ∈ [phi0, phi1]`, by the midpoint rule in `t = asin z` (so
/// `dω = cos t dt dφ`, which absorbs the `1 / sin θ` of a lat-long density
/// at the poles), `k × k` points.
fn sphere_integral(f: impl Fn([f64; 3]) -> f64, z: [f64; 2], phi: [f64; 2], k: usize) -> f64 {
    let (t0, t1) = (z[0].asin(), z[1].asin());
    let (dt, dphi) = ((t1 - t0) / k as f64, (phi[1] - phi[0]) / k as f64);
    let mut sum = 0.0;
    for a in 0..k {
        let t = t0 + (a as f64 + 0.5) * dt;
        for b in 0..k {
            let p = phi[0] + (b as f64 + 0.5) * dphi;
            sum += f(direction(t.sin(), p)) * t.cos();
        }
    }
    sum * dt * dphi
}

#[test]
fn pdf_of_a_direction_integrates_to_one_over_the_sphere() {
    let d = Distribution2D::from_equirect(&map(), W, H).unwrap();
    // Cells are crossed at the edges of the quadrature's cells: O(1/k).
    let integral = sphere_integral(|w| d.pdf_direction(w), [-1.0, 1.0], [0.0, 2.0 * PI], 1600);
    assert!((integral - 1.0).abs() < 2e-3, "∫ p dω = {integral}");
    assert_eq!(d.pdf_direction([0.0; 3]), 0.0);
    assert_eq!(d.pdf_direction([f64::NAN; 3]), 0.0);
}

/// Equal-area bins on the sphere: 8 bands of z, 16 sectors of φ.
const BANDS: usize = 8;
const SECTORS: usize = 16;

fn bin_of(dir: [f64; 3]) -> usize {
    let band = (((dir[2] + 1.0) / 2.0 * BANDS as f64) as usize).min(BANDS - 1);
    let mut phi = dir[1].atan2(dir[0]);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let sector = ((phi / (2.0 * PI) * SECTORS as f64) as usize).min(SECTORS - 1);
    band * SECTORS + sector
}

/// Each bin's probability from `pdf_direction`.
fn bin_probabilities(d: &Distribution2D) -> Vec<f64> {
    let mut p = vec![0.0; BANDS * SECTORS];
    for band in 0..BANDS {
        for sector in 0..SECTORS {
            let z = [band, band + 1].map(|b| -1.0 + 2.0 * b as f64 / BANDS as f64);
            let phi = [sector, sector + 1].map(|s| 2.0 * PI * s as f64 / SECTORS as f64);
            p[band * SECTORS + sector] = sphere_integral(|w| d.pdf_direction(w), z, phi, 40);
        }
    }
    let total: f64 = p.iter().sum();
    assert!((total - 1.0).abs() < 1e-2, "{total}");
    p.iter().map(|x| x / total).collect()
}

#[test]
fn sampled_directions_follow_pdf_direction() {
    let d = Distribution2D::from_equirect(&map(), W, H).unwrap();
    let expected = bin_probabilities(&d);
    let mut rng = Pcg64Mcg::seed_from_u64(11);
    let mut counts = vec![0u64; BANDS * SECTORS];
    for _ in 0..200_000 {
        let s: discrete_sampling::Sample2D = d.sample(&mut rng);
        let ds = d.sample_direction(invert(&d, s.point));
        counts[bin_of(ds.direction)] += 1;
        // The density of the drawn direction, evaluated from the direction
        // alone, is the one the sample reports (away from cell edges,
        // where the direction's rounding may cross into the neighbour).
        let [x, y] = ds.point;
        let (fx, fy) = ((x * W as f64).fract(), (y * H as f64).fract());
        if fx.min(1.0 - fx) > 1e-9 && fy.min(1.0 - fy) > 1e-9 {
            let p = d.pdf_direction(ds.direction);
            assert!((p - ds.pdf).abs() <= 1e-9 * ds.pdf, "{p} vs {}", ds.pdf);
        }
    }
    let test = chi_square(&counts, &expected, 20.0);
    assert!(test.p_value > 1e-3, "p = {:.2e}", test.p_value);

    // The same test rejects a map sampled without the sin θ weight.
    let flat = Distribution2D::new(&map(), W, H).unwrap();
    let mut wrong = vec![0u64; BANDS * SECTORS];
    for _ in 0..200_000 {
        let s = flat.sample(&mut rng);
        wrong[bin_of(equirect_direction(s.point))] += 1;
    }
    let test = chi_square(&wrong, &expected, 20.0);
    assert!(test.p_value < 1e-9, "p = {:.2e}", test.p_value);
}

/// The variates of a point (so `sample_direction` is exercised through
/// its own variate path).
fn invert(d: &Distribution2D, point: [f64; 2]) -> [f64; 2] {
    d.invert(point).expect("sampled points have density")
}
