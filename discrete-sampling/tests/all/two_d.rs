//! The 2D piecewise-constant distribution on images with known cell
//! probabilities, and the lat-long helpers.

use discrete_sampling::{
    CdfBisection, Distribution2D, Sample2D, equirect_direction, pdf_solid_angle,
};
use rand::SeedableRng;
use rand_pcg::Pcg64Mcg;

use crate::stats::{chi_square, probabilities};

const W: usize = 7;
const H: usize = 5;

/// A 7×5 image with zeros, a whole zero row and a bright cell.
fn image() -> Vec<f64> {
    let mut img: Vec<f64> = (0..W * H).map(|i| ((i * 7) % 5) as f64).collect();
    for x in 0..W {
        img[2 * W + x] = 0.0;
    }
    img[4 * W + 6] = 40.0;
    img
}

#[test]
fn cells_are_drawn_with_their_probabilities() {
    let img = image();
    let d = Distribution2D::new(&img, W, H).unwrap();
    let exact = probabilities(&img);
    let total: f64 = (0..H)
        .flat_map(|y| (0..W).map(move |x| [x, y]))
        .map(|c| d.cell_probability(c))
        .sum();
    assert!((total - 1.0).abs() < 1e-12);

    let mut rng = Pcg64Mcg::seed_from_u64(21);
    let mut counts = vec![0u64; W * H];
    let mut within = [0u64; 16]; // position inside the cell, 4×4 sub-bins
    let mut batch = vec![Sample2D::default(); 1000];
    for _ in 0..1000 {
        d.sample_into(&mut rng, &mut batch);
        for s in &batch {
            let [x, y] = s.point;
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
            let cell = [(x * W as f64) as usize, (y * H as f64) as usize];
            assert_eq!(cell, s.cell);
            let index = cell[1] * W + cell[0];
            assert!(img[index] > 0.0, "sample in a zero cell {cell:?}");
            let expected_pdf = exact[index] * (W * H) as f64;
            assert!((s.pdf - expected_pdf).abs() < 1e-12 * expected_pdf);
            assert_eq!(d.pdf(s.point), s.pdf);
            counts[index] += 1;
            let fx = x * W as f64 - cell[0] as f64;
            let fy = y * H as f64 - cell[1] as f64;
            within[(fy * 4.0) as usize * 4 + (fx * 4.0) as usize] += 1;
        }
    }
    let test = chi_square(&counts, &exact, 20.0);
    assert!(test.p_value > 1e-3, "cells: p = {:.2e}", test.p_value);
    let test = chi_square(&within, &[1.0 / 16.0; 16], 20.0);
    assert!(
        test.p_value > 1e-3,
        "inside cells: p = {:.2e}",
        test.p_value
    );
}

#[test]
fn the_same_test_rejects_a_2d_sampler_that_ignores_the_conditional() {
    // Wrong: the row from the marginal, but the column uniform over the row.
    let img = image();
    let d = Distribution2D::new(&img, W, H).unwrap();
    let mut counts = vec![0u64; W * H];
    let mut state = 12345u64;
    for _ in 0..200_000 {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u0 = (state >> 11) as f64 / (1u64 << 53) as f64;
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u1 = (state >> 11) as f64 / (1u64 << 53) as f64;
        let row = d.sample_u([0.5, u1]).cell[1];
        counts[row * W + (u0 * W as f64) as usize] += 1;
    }
    assert!(chi_square(&counts, &probabilities(&img), 20.0).p_value < 1e-9);
}

#[test]
fn invert_round_trips_and_bisection_rows_agree() {
    let img = image();
    let d = Distribution2D::new(&img, W, H).unwrap();
    let plain = Distribution2D::<CdfBisection>::with_sampler(&img, W, H).unwrap();
    for j in 0..=100 {
        for i in 0..=100 {
            let u = [i as f64 / 100.0, j as f64 / 100.0];
            let s = d.sample_u(u);
            assert_eq!(s, plain.sample_u(u), "u = {u:?}");
            let back = d.invert(s.point).expect("sampled points have density");
            let again = d.sample_u(back);
            assert_eq!(again.cell, s.cell);
            for axis in 0..2 {
                assert!((again.point[axis] - s.point[axis]).abs() < 1e-12);
            }
        }
    }
    assert_eq!(d.invert([0.5, 2.5 / H as f64]), None); // the zero row
    assert_eq!(d.pdf([0.5, 2.5 / H as f64]), 0.0);
    assert_eq!(d.pdf([1.0, 0.5]), 0.0);
    assert_eq!(d.pdf([f64::NAN, 0.5]), 0.0);
}

#[test]
fn equirect_map_of_constant_radiance_is_uniform_over_the_sphere() {
    let (w, h) = (64, 32);
    let d = Distribution2D::from_equirect(&vec![1.0f32; w * h], w, h).unwrap();
    for row in 0..h {
        let point = [0.3, (row as f64 + 0.5) / h as f64];
        let p = pdf_solid_angle(d.pdf(point), point);
        // Midpoint rule error of ∫ sin θ dθ with 32 rows is below 0.1%.
        assert!(
            (p * 4.0 * std::f64::consts::PI - 1.0).abs() < 1e-3,
            "row {row}: {p}"
        );
    }
    // Without the sin θ weight the poles would be over-sampled.
    let flat = Distribution2D::new(&vec![1.0f32; w * h], w, h).unwrap();
    let pole = [0.3, 0.5 / h as f64];
    assert!(pdf_solid_angle(flat.pdf(pole), pole) * 4.0 * std::f64::consts::PI > 10.0);

    let [x, y, z] = equirect_direction([0.25, 0.5]);
    assert!((x.abs() + (y - 1.0).abs() + z.abs()) < 1e-12);
    assert!((equirect_direction([0.0, 0.0])[2] - 1.0).abs() < 1e-12);
    assert_eq!(pdf_solid_angle(1.0, [0.5, 0.0]), 0.0);
}

#[test]
fn alias_rows_give_the_same_distribution() {
    // The alias method scrambles the order of u, so points differ from the
    // guide table's, but cells must still follow the image.
    let img = image();
    let d = Distribution2D::<discrete_sampling::AliasTable>::with_sampler(&img, W, H).unwrap();
    let mut rng = Pcg64Mcg::seed_from_u64(5);
    let mut counts = vec![0u64; W * H];
    let mut batch = vec![Sample2D::default(); 1000];
    for _ in 0..500 {
        d.sample_into(&mut rng, &mut batch);
        for s in &batch {
            counts[s.cell[1] * W + s.cell[0]] += 1;
            assert_eq!(d.pdf(s.point), s.pdf);
        }
    }
    let test = chi_square(&counts, &probabilities(&img), 20.0);
    assert!(test.p_value > 1e-3, "alias rows: p = {:.2e}", test.p_value);
}
