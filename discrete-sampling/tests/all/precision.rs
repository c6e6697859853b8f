//! The f64 CDF keeps dim entries reachable and correctly weighted; an f32
//! CDF, checked by the same function, does not.

use discrete_sampling::{AliasTable, CdfBisection, GuideTable, InvertibleSampler};

use crate::shapes;
use crate::stats::{chi_square, probabilities};

/// Entries with probability ≥ `floor` whose realised probability is off by
/// more than `rel` relative, or that no variate reaches.
fn misweighted(realized: &[f64], exact: &[f64], floor: f64, rel: f64) -> usize {
    realized
        .iter()
        .zip(exact)
        .filter(|&(&r, &p)| {
            p >= floor && (r - p).abs().partial_cmp(&(rel * p)) != Some(std::cmp::Ordering::Less)
        })
        .count()
}

/// A CDF summed and stored in f32, as many renderers do: the negative control.
fn f32_cdf_probabilities(weights: &[f64]) -> Vec<f64> {
    let mut running = 0.0f32;
    let cum: Vec<f32> = weights
        .iter()
        .map(|&w| {
            running += w as f32;
            running
        })
        .collect();
    let total = running;
    let mut prev = 0.0f32;
    cum.iter()
        .map(|&c| {
            let p = f64::from(c / total) - f64::from(prev / total);
            prev = c;
            p
        })
        .collect()
}

#[test]
fn entries_down_to_1e_minus_7_are_reachable_and_right() {
    const N: usize = 1_000_000;
    let weights = shapes::log_uniform(N, 9.0, 11);
    let exact = probabilities(&weights);
    let dim = exact.iter().filter(|&&p| p < 1e-7).count();
    assert!(
        dim > N / 10,
        "the shape must include entries below 1e-7 ({dim})"
    );

    let g = GuideTable::new(&weights).unwrap();
    let b = CdfBisection::new(&weights).unwrap();
    let a = AliasTable::new(&weights).unwrap();
    let guide_pdf: Vec<f64> = (0..N)
        .map(|i| discrete_sampling::DiscreteSampler::pdf(&g, i))
        .collect();
    assert_eq!(misweighted(&guide_pdf, &exact, 1e-7, 1e-6), 0);
    assert_eq!(
        misweighted(&a.realized_probabilities(), &exact, 1e-7, 1e-6),
        0
    );
    for (i, &p) in exact.iter().enumerate() {
        if p >= 1e-7 {
            let u = g.invert(i).expect("reachable");
            assert_eq!(discrete_sampling::DiscreteSampler::sample_u(&g, u), i);
            assert_eq!(b.invert(i), Some(u));
        }
    }

    // The same check on an f32 CDF finds many wrong entries.
    let f32_bad = misweighted(&f32_cdf_probabilities(&weights), &exact, 1e-7, 1e-6);
    assert!(f32_bad > N / 10, "f32 control misweighted only {f32_bad}");

    // Binned frequencies (consecutive entries merged to ≥ 20 expected).
    for (name, counts) in [
        ("guide-table", crate::counts(&g, N, 5)),
        ("alias", crate::counts(&a, N, 6)),
    ] {
        let test = chi_square(&counts, &exact, 20.0);
        assert!(
            test.p_value > 1e-3,
            "{name}: p = {:.2e} ({} dof)",
            test.p_value,
            test.dof
        );
    }
}

#[test]
fn lognormal_sigma_3_at_a_million_loses_nothing_in_f64() {
    const N: usize = 1_000_000;
    let weights = shapes::lognormal(N, 3.0, 12);
    let g = GuideTable::new(&weights).unwrap();
    let unreachable = (0..N).filter(|&i| g.invert(i).is_none()).count();
    assert_eq!(unreachable, 0);
    // The f32 CDF makes most of them unreachable (the figure in the docs).
    let f32_lost = f32_cdf_probabilities(&weights)
        .iter()
        .filter(|&&p| p == 0.0)
        .count();
    assert!(f32_lost > N / 2, "f32 lost {f32_lost} of {N}");
}
