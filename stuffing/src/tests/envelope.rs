//! The envelope fit ([`Options::envelope`]) on random smooth closed
//! surfaces: ellipsoids, tori and two spheres joined by a thin neck, at
//! random sizes and orientations from fixed seeds.

use glam::{DQuat, DVec3};

use super::{Soup, check_mesh, sphere, torus};
use crate::*;

/// SplitMix64: a small seeded generator, enough to vary the shapes.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }

    fn rotation(&mut self) -> DQuat {
        let axis = DVec3::new(
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
            self.range(-1.0, 1.0),
        );
        DQuat::from_axis_angle(
            axis.normalize_or(DVec3::Z),
            self.range(0.0, std::f64::consts::TAU),
        )
    }
}

fn transformed((p, t): Soup, scale: DVec3, rotation: DQuat) -> Soup {
    (p.iter().map(|&q| rotation * (q * scale)).collect(), t)
}

/// Shape `k` of the random family (kind by `k % 3`).
fn shape(k: u64) -> (String, Soup) {
    let mut rng = Rng(0x5eed_0000 + k);
    let rotation = rng.rotation();
    match k % 3 {
        0 => {
            let axes = DVec3::new(
                rng.range(0.4, 1.2),
                rng.range(0.4, 1.2),
                rng.range(0.4, 1.2),
            );
            let name = format!("ellipsoid {axes:.2}");
            (
                name,
                transformed(sphere(48, 1.0, DVec3::ZERO), axes, rotation),
            )
        }
        1 => {
            let (major, minor) = (rng.range(0.8, 1.2), rng.range(0.25, 0.45));
            let name = format!("torus {major:.2}, {minor:.2}");
            (
                name,
                transformed(torus(96, 48, major, minor), DVec3::ONE, rotation),
            )
        }
        _ => {
            let (length, radius) = (rng.range(1.4, 2.0), rng.range(0.6, 0.9));
            let waist = rng.range(0.18, 0.3);
            let name =
                format!("two lobes {length:.2} × {radius:.2}, neck {waist:.2} of the radius");
            (
                name,
                transformed(dumbbell(length, radius, waist), DVec3::ONE, rotation),
            )
        }
    }
}

/// A smooth closed surface of revolution about x with two lobes and a
/// thin neck between them: the unit sphere's z becomes `x = length · z`
/// and its radius `radius · sin θ`, narrowed to `waist` of it at `x = 0`
/// by a Gaussian of width `length / 5`.
fn dumbbell(length: f64, radius: f64, waist: f64) -> Soup {
    let (p, t) = sphere(64, 1.0, DVec3::ZERO);
    let width = length / 5.0;
    let p = p
        .iter()
        .map(|q| {
            let x = length * q.z;
            let narrow = 1.0 - (1.0 - waist) * (-(x / width).powi(2)).exp();
            DVec3::new(x, radius * narrow * q.x, radius * narrow * q.y)
        })
        .collect();
    (p, t)
}

fn diagonal(p: &[DVec3]) -> f64 {
    let lo = p.iter().fold(DVec3::splat(f64::INFINITY), |a, &b| a.min(b));
    let hi = p
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |a, &b| a.max(b));
    lo.distance(hi)
}

/// The envelope the property test holds, as a fraction of the diagonal
/// (the default).
const EPS: f64 = 2e-3;

/// Stuffs shape `k` at `diag / div`, plain and fitted.
fn plain_and_fitted(p: &[DVec3], t: &[[u32; 3]], div: f64) -> (TetMesh, TetMesh) {
    let mut options = Options::new(diagonal(p) / div);
    let plain = tetrahedralize(p, t, &options).unwrap();
    options.envelope = Some(EPS);
    (plain, tetrahedralize(p, t, &options).unwrap())
}

/// Ellipsoids and tori at 1/40 of the diagonal (the default spacing), the
/// two lobes at 1/80 (their neck's radius is then 1.5 to 3 spacings; at
/// 1/40 the boundary's chords across the neck alone are about `EPS` off):
/// the boundary within `EPS` of the input both ways, every dihedral angle
/// within 10°–165°, and the fit never farther from the input than the
/// plain stuffing.
#[test]
fn random_smooth_surfaces_are_held_within_the_envelope_with_the_angle_bound() {
    for k in 0..9 {
        let (name, (p, t)) = shape(k);
        let div = if k % 3 == 2 { 80.0 } else { 40.0 };
        let (plain, fitted) = plain_and_fitted(&p, &t, div);
        let (d0, d) = (
            plain.report.distance.clone().unwrap(),
            fitted.report.distance.clone().unwrap(),
        );
        let result = check_mesh(&fitted, None, (10.0, 165.0));
        assert!(result.is_ok(), "{name}: {result:?}");
        assert!(fitted.report.min_dihedral_deg >= 10.0, "{name}");
        let (lo, hi) = fitted.report.dihedral_bounds_deg;
        assert!((lo, hi) == (9.0, 165.0) && plain.report.dihedral_bounds_deg == (9.0, 162.0));
        assert!(
            d.input_to_tets <= EPS * d.diagonal && d.tets_to_input <= EPS * d.diagonal,
            "{name}: {d:?}"
        );
        assert!(d.hausdorff <= d0.hausdorff, "{name}: {d:?} vs {d0:?}");
        assert!(
            fitted.tets.len() <= 3 * plain.tets.len(),
            "{name}: the refinement stays within 3x the tetrahedra"
        );
    }
}

/// The same check has teeth: the two lobes at the default spacing (the
/// neck about a spacing across) miss the envelope, plain or fitted. The
/// fit's refinement splits edges there (within 3× the tetrahedra, every
/// new one within 10°–165°) and comes nearer than the plain stuffing.
#[test]
fn a_neck_a_spacing_thick_misses_the_envelope_at_the_default_spacing() {
    let (name, (p, t)) = shape(2);
    let (plain, fitted) = plain_and_fitted(&p, &t, 40.0);
    assert!(fitted.report.split_edges > 0, "{name}");
    assert!(fitted.tets.len() > plain.tets.len(), "{name}");
    let result = check_mesh(&fitted, None, (10.0, 165.0));
    assert!(result.is_ok(), "{name}: {result:?}");
    let (d0, d) = (
        plain.report.distance.clone().unwrap(),
        fitted.report.distance.clone().unwrap(),
    );
    assert!(d.hausdorff < d0.hausdorff, "{name}: {d:?} vs {d0:?}");
    for d in [d0, d] {
        assert!(d.hausdorff > EPS * d.diagonal, "{name}: {d:?}");
    }
}

#[test]
fn the_envelope_is_a_fraction_between_0_and_1() {
    let (p, t) = sphere(8, 1.0, DVec3::ZERO);
    for eps in [0.0, -1e-3, 1.0, f64::NAN, f64::INFINITY] {
        let mut options = Options::new(0.2);
        options.envelope = Some(eps);
        let e = tetrahedralize(&p, &t, &options).unwrap_err();
        assert!(matches!(e, Error::InvalidEnvelope { .. }), "{eps}: {e}");
        assert!(e.to_string().contains("between 0 and 1"), "{e}");
    }
}
