//! Per-face and per-vertex weights: checks, and the closed-form draw of
//! a linear density's corner component.

use crate::Error;
use crate::subdivision::SubTriangle;

/// Barycentrics with density proportional to the weight of `corner`: that
/// weight is Beta(2, 2) (the uniform marginal `2(1 − b)` times `b`), drawn
/// by inverting its CDF `3b² − 2b³` in closed form; the other two split
/// the rest uniformly.
pub(super) fn linear_corner_barycentric(corner: usize, xi1: f64, xi2: f64) -> [f32; 3] {
    // 4y³ − 3y = 1 − 2ξ for y = b − 1/2 is cos 3θ = 1 − 2ξ with y = cos θ;
    // the root in [−1/2, 1/2] has 3θ in [π, 2π].
    let theta = (2.0 * std::f64::consts::PI - (1.0 - 2.0 * xi1).clamp(-1.0, 1.0).acos()) / 3.0;
    let b = (0.5 + theta.cos()).clamp(0.0, 1.0);
    let other = xi2 * (1.0 - b);
    let mut bary = [0.0f32; 3];
    bary[corner] = b as f32;
    bary[(corner + 1) % 3] = other as f32;
    bary[(corner + 2) % 3] = (1.0 - b - other).max(0.0) as f32;
    bary
}

/// The share of its face's area (times the weight's normalisation) a
/// piece covers: `4^-level` for sub-triangles, 1/3 for a linear component
/// (∫ b_c dA = A / 3).
pub(super) fn piece_fraction(part: SubTriangle) -> f64 {
    if part.corner().is_some() {
        1.0 / 3.0
    } else {
        part.area_fraction()
    }
}

pub(super) fn check_weights(what: &'static str, w: &[f32], expected: usize) -> Result<(), Error> {
    if w.len() != expected {
        return Err(Error::WeightLength {
            what,
            len: w.len(),
            expected,
        });
    }
    if let Some(index) = w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
        return Err(Error::InvalidWeight {
            what,
            index,
            value: w[index],
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_corner_component_has_beta22_weight() {
        // The CDF of the corner weight is 3b² − 2b³: invert and check.
        for k in 0..=100 {
            let xi = k as f64 / 100.0;
            let b = f64::from(linear_corner_barycentric(1, xi, 0.3)[1]);
            let cdf = 3.0 * b * b - 2.0 * b * b * b;
            assert!((cdf - xi).abs() < 1e-5, "{xi} -> {b} -> {cdf}");
        }
    }
}
