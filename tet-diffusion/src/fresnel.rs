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

/// The radiance leaving into air (index 1) per unit of the hemispherical
/// flux `J⁺` that meets the boundary from inside, toward an outside
/// direction at cosine `cos_o` to the normal: `F_t(cos_o) / (π η²)`, per
/// steradian.
///
/// `F_t J⁺ / π` is Eq. 3 of TransCut as printed: the radiance just
/// *inside* the boundary. Radiance divided by the square of the index is
/// invariant along a refracted ray, so the radiance in air is that over
/// `η²`; integrated over the outgoing hemisphere it lets out
/// `(1 − F_dr,ext) J⁺ / η² = (1 − F_dr) J⁺` (Stokes), the flux the
/// boundary condition (Eq. 2) lets out. The renderer evaluates this per
/// fragment, from the direction to the eye.
///
/// ```
/// use tet_diffusion::fresnel::{exit_radiance_factor, transmittance};
/// let f = exit_radiance_factor(1.0, 1.3);
/// assert!((f - transmittance(1.0, 1.3) / (std::f64::consts::PI * 1.69)).abs() < 1e-15);
/// ```
pub fn exit_radiance_factor(cos_o: f64, eta: f64) -> f64 {
    transmittance(cos_o, eta) / (std::f64::consts::PI * eta * eta)
}

/// The radiance just inside the boundary per unit of `J⁺`: `F_t(cos_o) / π`
/// (Eq. 3 as printed; see [`exit_radiance_factor`] for the radiance in air).
pub fn inside_radiance_factor(cos_o: f64, eta: f64) -> f64 {
    transmittance(cos_o, eta) / std::f64::consts::PI
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

    /// `∫ f(cos θ) cos θ dω` over the hemisphere, by the midpoint rule in
    /// `cos²θ` (so that the weight is uniform).
    fn hemisphere(f: impl Fn(f64) -> f64) -> f64 {
        let n = 200_000;
        (0..n)
            .map(|i| f(((i as f64 + 0.5) / n as f64).sqrt()))
            .sum::<f64>()
            * std::f64::consts::PI
            / n as f64
    }

    #[test]
    fn the_exit_radiance_lets_out_what_the_boundary_condition_does() {
        // Stokes: ∫ F_t(ω)/(π η²) cos dω = 1 − F_dr(η) up to the fit of
        // F_dr (within 0.3 % of the exact integral for 1 ≤ η ≤ 1.5), and
        // the inside form is η² too bright.
        for eta in [1.0, 1.1, 1.3, 1.5] {
            let out = hemisphere(|c| exit_radiance_factor(c, eta));
            let expected = 1.0 - diffuse_reflectance(eta);
            assert!(
                (out / expected - 1.0).abs() < 3e-3,
                "η = {eta}: {out} vs {expected}"
            );
            let inside = hemisphere(|c| inside_radiance_factor(c, eta));
            assert!((inside / out - eta * eta).abs() < 1e-9);
        }
    }
}
