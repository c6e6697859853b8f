//! Floating-point range edges that once gave wrong answers (the regression
//! inputs listed in the shared regression folder's README), each with its
//! right value.

use discrete_sampling::{
    AliasTable, CdfBisection, DiscreteSampler, Distribution2D, GuideTable, InvertibleSampler,
};

use crate::all_samplers;

/// The largest `f64` below 1.
const TOP: f64 = 1.0 - f64::EPSILON / 2.0;

/// `pdf` of every 1D sampler type for `weights`.
fn pdfs(weights: &[f64]) -> Vec<(&'static str, Vec<f64>)> {
    let n = weights.len();
    let b = CdfBisection::new(weights).unwrap();
    let g = GuideTable::new(weights).unwrap();
    let a = AliasTable::new(weights).unwrap();
    vec![
        ("bisection", (0..n).map(|i| b.pdf(i)).collect()),
        ("guide-table", (0..n).map(|i| g.pdf(i)).collect()),
        ("alias", (0..n).map(|i| a.pdf(i)).collect()),
        ("alias (realised)", a.realized_probabilities()),
    ]
}

/// Fraction of 3·10⁵ evenly spread variates (and of 10⁵ random draws)
/// that each sampler gives to each entry.
fn frequencies(weights: &[f64]) -> Vec<(String, Vec<f64>)> {
    const N: usize = 300_000;
    let mut out = Vec::new();
    for (name, sampler) in all_samplers(weights) {
        let mut counts = vec![0usize; weights.len()];
        for j in 0..N {
            let (i, rest) = sampler((j as f64 + 0.5) / N as f64);
            assert!((0.0..1.0).contains(&rest), "{name}: remainder {rest}");
            counts[i] += 1;
        }
        out.push((name, counts.iter().map(|&c| c as f64 / N as f64).collect()));
    }
    let g = GuideTable::new(weights).unwrap();
    let a = AliasTable::new(weights).unwrap();
    for (name, counts) in [
        ("guide-table rng", crate::counts(&g, 100_000, 3)),
        ("alias rng", crate::counts(&a, 100_000, 4)),
    ] {
        out.push((
            name.into(),
            counts.iter().map(|&c| c as f64 / 100_000.0).collect(),
        ));
    }
    out
}

#[test]
fn subnormal_weights_5e_324_and_1e_323_give_one_third_and_two_thirds() {
    let weights = [5e-324, 1e-323];
    for (name, p) in pdfs(&weights) {
        assert!((p[0] - 1.0 / 3.0).abs() < 1e-15, "{name}: {p:?}");
        assert!((p[1] - 2.0 / 3.0).abs() < 1e-15, "{name}: {p:?}");
    }
    for (name, f) in frequencies(&weights) {
        // Evenly spread variates: exact to 1/N; random draws: 5 σ of 10⁵.
        assert!((f[0] - 1.0 / 3.0).abs() < 0.008, "{name}: {f:?}");
        assert!((f[1] - 2.0 / 3.0).abs() < 0.008, "{name}: {f:?}");
    }
    let g = GuideTable::new(&weights).unwrap();
    assert_eq!(g.invert(1).map(|u| g.sample_u(u)), Some(1));
}

#[test]
fn a_zero_weight_next_to_subnormal_ones_is_never_drawn() {
    let weights = [0.0, 1e-320, 1e-320];
    for (name, p) in pdfs(&weights) {
        assert_eq!(p[0], 0.0, "{name}: {p:?}");
        assert!((p[1] - 0.5).abs() < 1e-15, "{name}: {p:?}");
        assert!((p[2] - 0.5).abs() < 1e-15, "{name}: {p:?}");
    }
    for (name, f) in frequencies(&weights) {
        assert_eq!(f[0], 0.0, "{name}: {f:?}");
        assert!((f[1] - 0.5).abs() < 0.008, "{name}: {f:?}");
    }
    for (name, sampler) in all_samplers(&weights) {
        for u in [0.0, 1e-300, 0.25, 0.5, TOP] {
            assert_ne!(sampler(u).0, 0, "{name} at u = {u}");
        }
    }
    assert_eq!(CdfBisection::new(&weights).unwrap().invert(0), None);
}

#[test]
fn lat_long_texel_at_the_top_variate_keeps_its_point_inside() {
    // 8×4 lat-long map, one texel (5, 2) = 1000, the rest 0.
    let (w, h) = (8, 4);
    let mut map = vec![0.0f64; w * h];
    map[2 * w + 5] = 1000.0;
    for d in [
        Distribution2D::from_equirect(&map, w, h).unwrap(),
        Distribution2D::new(&map, w, h).unwrap(),
    ] {
        for u in [[0.0, TOP], [TOP, TOP], [0.0, 0.0], [TOP, 0.0]] {
            let s = d.sample_u(u);
            assert_eq!(s.cell, [5, 2], "u = {u:?}");
            let [x, y] = s.point;
            assert!((5.0 / 8.0..6.0 / 8.0).contains(&x), "x = {x} for u = {u:?}");
            assert!((2.0 / 4.0..3.0 / 4.0).contains(&y), "y = {y} for u = {u:?}");
            assert_eq!(d.cell_at(s.point), Some([5, 2]));
            assert_eq!(s.pdf, 32.0);
            assert_eq!(d.pdf(s.point), 32.0);
            let back = d.invert(s.point).expect("the point has density");
            let again = d.sample_u(back);
            assert_eq!(again.cell, [5, 2]);
            for k in 0..2 {
                assert!((again.point[k] - s.point[k]).abs() < 1e-12, "{u:?}");
            }
        }
    }
}

/// The class behind the lat-long case: for every grid size up to 40 and
/// remainders at 0, just above 0 and just below 1, the placed point is
/// inside its cell, never on the next cell's lower edge.
#[test]
fn sampled_points_never_reach_the_upper_edge_of_their_cell() {
    for n in 1..=40usize {
        let weights = vec![1.0f64; n * n];
        let d = Distribution2D::new(&weights, n, n).unwrap();
        for cell in 0..n {
            for frac in [0.0, 1e-17, 0.5, TOP] {
                // The variate that lands at `frac` of cell `cell` (all
                // cells have width 1/n).
                let u = ((cell as f64 + frac) / n as f64).min(TOP);
                let s = d.sample_u([u, u]);
                assert_eq!(d.cell_at(s.point), Some(s.cell), "n = {n}, u = {u}");
                assert_eq!(d.pdf(s.point), s.pdf);
            }
        }
    }
}

#[test]
fn nan_variates_count_as_zero_everywhere() {
    let weights = [0.0, 2.0, 1.0];
    for (name, sampler) in all_samplers(&weights) {
        let (i, rest) = sampler(f64::NAN);
        assert_eq!((i, rest), sampler(0.0), "{name}");
    }
    let d = Distribution2D::new(&[0.0, 1.0, 2.0, 3.0], 2, 2).unwrap();
    assert_eq!(d.sample_u([f64::NAN, f64::NAN]), d.sample_u([0.0, 0.0]));
    assert_eq!(d.pdf([f64::NAN, 0.5]), 0.0);
    assert_eq!(d.invert([0.5, f64::NAN]), None);
}
