//! How well spread a point set is: nearest-neighbour distances and the
//! relative radius ρ of Lagae & Dutré ("A Comparison of Methods for
//! Generating Poisson Disk Distributions", 2008).

use glam::Vec3;
use kiddo::SquaredEuclidean;
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use std::num::NonZero;

/// A k-d tree over positions (32 points per leaf).
type Tree = ImmutableKdTree<f32, u32, 3, 32>;

/// The radius of the densest packing of `n` disks on area `area`:
/// `r_max = √(A / (2√3 N))` (hexagonal packing; Yuksel 2015 Eq. 4 and
/// Lagae & Dutré 2008). Two points of a hexagonal lattice of `n` points
/// are `2 r_max` apart.
pub fn max_poisson_radius(area: f64, n: usize) -> f64 {
    (area / (2.0 * 3f64.sqrt() * n as f64)).sqrt()
}

/// The Euclidean distance from each point to its nearest other point, in
/// the points' order (`f32::INFINITY` for a single point).
pub fn nearest_neighbour_distances(points: &[Vec3]) -> Vec<f32> {
    let coords: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
    let tree = Tree::new_from_slice(&coords);
    let two = NonZero::new(2).expect("2 is not zero");
    let nearest = |p: &[f32; 3]| {
        tree.nearest_n::<SquaredEuclidean>(p, two)
            .iter()
            .map(|nb| nb.distance)
            .nth(1)
            .map_or(f32::INFINITY, f32::sqrt)
    };
    #[cfg(feature = "rayon")]
    {
        use rayon::prelude::*;
        coords.par_iter().map(nearest).collect()
    }
    #[cfg(not(feature = "rayon"))]
    coords.iter().map(nearest).collect()
}

/// The relative radius `ρ = (d_min / 2) / r_max` of points spread over a
/// surface of area `area`, where `d_min` is the smallest distance between
/// two points and `r_max` is [`max_poisson_radius`]: 1 for a hexagonal
/// lattice, about 0.75 or more for good Poisson-disk sets, and close to 0
/// for independent uniform points (Lagae & Dutré 2008, Sec. 2). Distances
/// are Euclidean in 3D, as in the elimination.
///
/// Returns 0 for fewer than two points or a non-positive area.
pub fn relative_radius(points: &[Vec3], area: f64) -> f64 {
    if points.len() < 2 || area.is_nan() || area <= 0.0 {
        return 0.0;
    }
    let d_min = nearest_neighbour_distances(points)
        .into_iter()
        .fold(f32::INFINITY, f32::min);
    f64::from(d_min) / 2.0 / max_poisson_radius(area, points.len())
}

/// [`relative_radius`] for points that follow a density: each point's
/// half nearest-neighbour distance is measured against the packing radius
/// its own density asks for, `r_i = √(1 / (2√3 N p_i))`, and ρ is the
/// smallest ratio. `pdf[i]` is the density w.r.t. area at point `i` (the
/// [`SurfacePoint::pdf`](crate::SurfacePoint::pdf) of the sampler that drew
/// it); with `p_i = 1/A` this is [`relative_radius`].
///
/// Returns 0 for fewer than two points, lengths that differ, or a density
/// that is not finite and positive.
pub fn relative_radius_with_density(points: &[Vec3], pdf: &[f32]) -> f64 {
    let n = points.len();
    if n < 2 || pdf.len() != n || pdf.iter().any(|p| !(p.is_finite() && *p > 0.0)) {
        return 0.0;
    }
    let scale = 2.0 * 3f64.sqrt() * n as f64;
    nearest_neighbour_distances(points)
        .iter()
        .zip(pdf)
        .map(|(&d, &p)| f64::from(d) / 2.0 * (scale * f64::from(p)).sqrt())
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hexagonal_lattice_has_relative_radius_one() {
        // Rows of a triangular lattice with spacing s: area per point
        // is s² √3 / 2.
        let s = 0.1f32;
        let (nx, ny) = (40, 40);
        let mut points = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let x = i as f32 * s + if j % 2 == 1 { s / 2.0 } else { 0.0 };
                points.push(Vec3::new(x, j as f32 * s * 3f32.sqrt() / 2.0, 0.0));
            }
        }
        let area = points.len() as f64 * f64::from(s * s) * 3f64.sqrt() / 2.0;
        let rho = relative_radius(&points, area);
        assert!((rho - 1.0).abs() < 1e-3, "ρ = {rho}");
        let nn = nearest_neighbour_distances(&points);
        assert!(nn.iter().all(|&d| (d - s).abs() < 1e-4));
        let uniform = vec![(1.0 / area) as f32; points.len()];
        let with_density = relative_radius_with_density(&points, &uniform);
        assert!((with_density - rho).abs() < 1e-4);
        // Twice the density asks for √2 smaller spacing: ρ grows by √2.
        let denser = vec![(2.0 / area) as f32; points.len()];
        let r2 = relative_radius_with_density(&points, &denser);
        assert!((r2 / rho - 2f64.sqrt()).abs() < 1e-4);
    }

    #[test]
    fn degenerate_inputs_give_zero() {
        assert_eq!(relative_radius(&[], 1.0), 0.0);
        assert_eq!(relative_radius(&[Vec3::ZERO], 1.0), 0.0);
        assert_eq!(relative_radius(&[Vec3::ZERO, Vec3::X], f64::NAN), 0.0);
        assert_eq!(
            nearest_neighbour_distances(&[Vec3::ONE]),
            vec![f32::INFINITY]
        );
    }
}
