//! Deterministic checks: the guide table is the same inversion as
//! bisection, inversion round-trips, the alias table holds exactly the
//! weights' mass, and zero weights are unreachable at every boundary.

use discrete_sampling::{AliasTable, CdfBisection, DiscreteSampler, GuideTable, InvertibleSampler};

use crate::shapes;
use crate::stats::probabilities;

/// Variates at and around every CDF step, plus a regular grid.
fn probe_variates(cdf: &[f64]) -> Vec<f64> {
    let mut us = vec![0.0, 1.0 - f64::EPSILON / 2.0, 0.5];
    for &c in cdf {
        us.push(c);
        us.push(f64::from_bits(c.to_bits().saturating_sub(1)).max(0.0));
        us.push(f64::from_bits(c.to_bits() + 1));
    }
    us.extend((0..10_000).map(|j| j as f64 / 10_000.0));
    us.retain(|u| (0.0..1.0).contains(u));
    us
}

#[test]
fn guide_table_equals_bisection_for_every_variate() {
    for (shape, weights) in shapes::named() {
        let reference = CdfBisection::new(&weights).unwrap();
        let us = probe_variates(reference.cdf());
        for ratio in [0.01, 0.25, 1.0, 4.0, 16.0, 64.0] {
            let g = GuideTable::with_ratio(&weights, ratio).unwrap();
            assert_eq!(g.cdf(), reference.cdf());
            for &u in &us {
                assert_eq!(
                    g.sample_remapped(u),
                    reference.sample_remapped(u),
                    "{shape}, ratio {ratio}, u = {u:e}"
                );
            }
        }
    }
}

#[test]
fn bisection_matches_a_linear_scan() {
    for (shape, weights) in shapes::named() {
        let b = CdfBisection::new(&weights).unwrap();
        let cdf = b.cdf();
        for u in probe_variates(cdf) {
            let scan = (0..weights.len()).find(|&i| cdf[i + 1] > u).unwrap();
            assert_eq!(b.sample_u(u), scan, "{shape}, u = {u:e}");
            assert!(weights[scan] > 0.0);
        }
    }
}

#[test]
fn zero_weights_are_never_returned_at_any_boundary() {
    for (shape, weights) in shapes::named() {
        let cdf = CdfBisection::new(&weights).unwrap().cdf().to_vec();
        for (name, f) in crate::all_samplers(&weights) {
            for u in probe_variates(&cdf) {
                let i = f(u).0;
                assert!(
                    weights[i] > 0.0,
                    "{name} on {shape} gave zero-weight {i} at u = {u:e}"
                );
            }
            for u in [-1.0, f64::NAN, 1.0, 2.0, f64::INFINITY] {
                let i = f(u).0;
                assert!(weights[i] > 0.0, "{name} on {shape}: out-of-range u = {u}");
            }
        }
    }
}

#[test]
fn invert_round_trips_every_reachable_index() {
    for (shape, weights) in shapes::named() {
        let g = GuideTable::new(&weights).unwrap();
        let b = CdfBisection::new(&weights).unwrap();
        for (i, &w) in weights.iter().enumerate() {
            match (g.invert(i), b.invert(i)) {
                (Some(u), Some(v)) => {
                    assert_eq!(u, v);
                    assert_eq!(g.sample_u(u), i, "{shape}: index {i}");
                    assert_eq!(g.sample_remapped(u).1, 0.0);
                }
                (None, None) => assert_eq!(w, 0.0, "{shape}: positive {i} not invertible"),
                other => panic!("{shape}: samplers disagree on {i}: {other:?}"),
            }
        }
        assert_eq!(g.invert(weights.len()), None);
    }
}

#[test]
fn pdf_is_the_weight_share() {
    for (shape, weights) in shapes::named() {
        let exact = probabilities(&weights);
        let g = GuideTable::new(&weights).unwrap();
        let a = AliasTable::new(&weights).unwrap();
        let realized = a.realized_probabilities();
        for (i, &p) in exact.iter().enumerate() {
            let tol = 1e-14 + 1e-12 * p;
            assert!((g.pdf(i) - p).abs() <= tol, "{shape} guide pdf({i})");
            assert!((a.pdf(i) - p).abs() <= tol, "{shape} alias pdf({i})");
            assert!(
                (realized[i] - p).abs() <= tol,
                "{shape} alias table mass({i})"
            );
            if p == 0.0 {
                assert_eq!(realized[i], 0.0);
                assert_eq!(g.pdf(i), 0.0);
            }
        }
        assert_eq!(g.pdf(usize::MAX), 0.0);
        assert_eq!(a.pdf(weights.len()), 0.0);
    }
}

#[test]
fn weight_types_convert_losslessly() {
    let from_f32 = GuideTable::new(&[1.0f32, 3.0]).unwrap();
    let from_u32 = GuideTable::new(&[1u32, 3]).unwrap();
    let from_i32 = AliasTable::new(&[1i32, 3]).unwrap();
    assert_eq!(from_f32.pdf(1), 0.75);
    assert_eq!(from_u32.pdf(1), 0.75);
    assert_eq!(from_i32.pdf(1), 0.75);
}
