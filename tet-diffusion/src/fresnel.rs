//! Fresnel terms of the diffusive boundary condition (TransCut Eq. 2–3,
//! after Jensen et al. 2001).

/// The diffuse Fresnel reflectance `F_dr(η)` of a boundary with relative
/// index of refraction `η`, by the fit of Egan & Hilgeman used by Jensen et
/// al. 2001: `F_dr = −1.440/η² + 0.710/η + 0.668 + 0.0636 η`.
///
/// ```
/// let f = tet_diffusion::fresnel::diffuse_reflectance(1.3);
/// assert!((f - 0.444763).abs() < 1e-6);
/// ```
pub fn diffuse_reflectance(eta: f64) -> f64 {
    -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta
}

/// `A = (1 + F_dr) / (1 − F_dr)`, the internal-reflection factor of the
/// boundary condition (Eq. 2).
pub fn boundary_factor(eta: f64) -> f64 {
    let f = diffuse_reflectance(eta);
    (1.0 + f) / (1.0 - f)
}

/// Fresnel transmittance `F_t = 1 − F_r` of unpolarised light crossing
/// from outside (index 1) into a medium of relative index `eta` at an
/// angle with cosine `cos_i` to the normal (the same value holds for light
/// leaving at that outside angle). 0 for grazing light, and for total
/// internal reflection when `eta < 1`.
pub fn transmittance(cos_i: f64, eta: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin_t2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin_t2 >= 1.0 {
        return 0.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    1.0 - 0.5 * (r_parl * r_parl + r_perp * r_perp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinned_values_of_the_fit() {
        // Two wrong transcriptions of the fit circulate; these pin ours.
        assert!((diffuse_reflectance(1.3) - 0.444763).abs() < 5e-7);
        assert!((boundary_factor(1.3) - 2.602064).abs() < 5e-7);
        assert!((diffuse_reflectance(1.0) - 0.0016).abs() < 1e-12);
    }

    #[test]
    fn transmittance_limits() {
        // Normal incidence: 1 − ((η − 1)/(η + 1))².
        let r = (0.5f64 / 2.5).powi(2);
        assert!((transmittance(1.0, 1.5) - (1.0 - r)).abs() < 1e-12);
        assert_eq!(transmittance(0.0, 1.5), 0.0);
        assert!((transmittance(0.7, 1.0) - 1.0).abs() < 1e-12);
        // Total internal reflection beyond the critical angle.
        assert_eq!(transmittance(0.1, 1.0 / 1.5), 0.0);
        // Monotone in the angle.
        assert!(transmittance(0.9, 1.3) > transmittance(0.3, 1.3));
    }
}
