//! No public function panics on any argument value: constructors and
//! samplers fed zeros, subnormals, huge and tiny values, NaN, infinities,
//! out-of-range indices and variates, in random combinations (fixed seed).

use discrete_sampling::{
    AliasTable, CdfBisection, DiscreteSampler, Distribution2D, GuideTable, InvertibleSampler,
    equirect_direction, equirect_point, luminance, pdf_solid_angle,
};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64Mcg;

const EXTREMES: [f64; 14] = [
    0.0,
    -0.0,
    5e-324,
    1e-320,
    f64::MIN_POSITIVE,
    1e-300,
    0.5,
    1.0,
    1e300,
    f64::MAX,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
    -1.0,
];

fn pick(rng: &mut Pcg64Mcg) -> f64 {
    if rng.random_bool(0.7) {
        EXTREMES[rng.random_range(0..EXTREMES.len())]
    } else {
        rng.random::<f64>() * 10f64.powi(rng.random_range(-300..300))
    }
}

fn exercise<S: InvertibleSampler>(s: &S, rng: &mut Pcg64Mcg) {
    for _ in 0..20 {
        let u = pick(rng);
        let (i, rest) = s.sample_remapped(u);
        assert!(i < s.len() && (0.0..1.0).contains(&rest), "u = {u}");
        let index = [0, s.len(), usize::MAX, i][rng.random_range(0..4)];
        let p = s.pdf(index);
        assert!((0.0..=1.0).contains(&p));
        if let Some(v) = s.invert(index) {
            assert_eq!(s.sample_u(v), index);
        }
    }
}

#[test]
fn extreme_arguments_give_errors_or_answers_never_panics() {
    let mut rng = Pcg64Mcg::seed_from_u64(2024);
    for round in 0..3000 {
        let n = [0, 1, 2, 3, 7, 64][round % 6];
        let weights: Vec<f64> = (0..n).map(|_| pick(&mut rng)).collect();
        let ratio = pick(&mut rng);
        if let Ok(b) = CdfBisection::new(&weights) {
            exercise(&b, &mut rng);
        }
        if let Ok(g) = GuideTable::new(&weights) {
            exercise(&g, &mut rng);
        }
        if let Ok(g) = GuideTable::with_ratio(&weights, ratio) {
            exercise(&g, &mut rng);
        }
        if let Ok(a) = AliasTable::new(&weights) {
            for _ in 0..20 {
                let (i, rest) = a.sample_remapped(pick(&mut rng));
                assert!(i < n && (0.0..1.0).contains(&rest));
                assert!(a.pdf(usize::MAX) == 0.0 && a.pdf(i) > 0.0);
            }
        }
        let (w, h) = [
            (0, 0),
            (1, n),
            (n, 1),
            (2, n / 2),
            (usize::MAX, 2),
            (3, usize::MAX),
        ][round % 6];
        for d in [
            Distribution2D::new(&weights, w, h),
            Distribution2D::from_equirect(&weights, w, h),
        ]
        .into_iter()
        .flatten()
        {
            for _ in 0..10 {
                let u = [pick(&mut rng), pick(&mut rng)];
                let s = d.sample_u(u);
                assert_eq!(d.cell_at(s.point), Some(s.cell));
                assert!(s.pdf > 0.0 && s.pdf.is_finite());
                let q = [pick(&mut rng), pick(&mut rng)];
                let _ = (d.pdf(q), d.invert(q), d.cell_probability([usize::MAX, 0]));
                let dir = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
                let p = d.pdf_direction(dir);
                assert!(p >= 0.0, "pdf_direction({dir:?}) = {p}");
                let _ = (d.sample_direction(u), d.row(usize::MAX));
            }
        }
        let q = [pick(&mut rng), pick(&mut rng)];
        let _ = (equirect_direction(q), pdf_solid_angle(pick(&mut rng), q));
        let dir = [pick(&mut rng), pick(&mut rng), pick(&mut rng)];
        if let Some(p) = equirect_point(dir) {
            assert!((0.0..1.0).contains(&p[0]) && (0.0..1.0).contains(&p[1]));
        }
        let _ = luminance([pick(&mut rng) as f32, f32::NAN, f32::INFINITY]);
    }
}

#[test]
fn huge_counts_are_refused_before_allocating() {
    // A width × height that overflows, or that does not match the data.
    let err = Distribution2D::new(&[1.0f64; 4], usize::MAX, usize::MAX).unwrap_err();
    assert!(err.to_string().contains("needs"), "{err}");
    let err = GuideTable::with_ratio(&[1.0f64; 4], 1e12).unwrap_err();
    assert!(err.to_string().contains("ratio"), "{err}");
}
