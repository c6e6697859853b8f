//! Optical properties: absorption `μa` and reduced scattering `σs′` per
//! RGB channel, in mm⁻¹; the measured materials of Jensen et al. 2001; a
//! procedural heterogeneous material.

use glam::DVec3;

use crate::Error;

/// The optical properties of one homogeneous piece of material, per RGB
/// channel, in **mm⁻¹** (whatever the mesh's unit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    /// Absorption coefficient `μa ≥ 0` (mm⁻¹). 0 is valid (Spectralon).
    pub sigma_a: [f64; 3],
    /// Reduced scattering coefficient `σs′ = σs (1 − g) > 0` (mm⁻¹).
    pub sigma_s_prime: [f64; 3],
}

/// The measured materials of Jensen, Marschner, Levoy & Hanrahan, "A
/// practical model for subsurface light transport" (SIGGRAPH 2001),
/// Fig. 5, as pbrt carries them: `(name, σs′, σa)`, in mm⁻¹.
pub const MEASURED: [(&str, [f64; 3], [f64; 3]); 12] = [
    ("apple", [2.29, 2.39, 1.97], [0.0030, 0.0034, 0.046]),
    ("chicken1", [0.15, 0.21, 0.38], [0.015, 0.077, 0.19]),
    ("chicken2", [0.19, 0.25, 0.32], [0.018, 0.088, 0.20]),
    ("cream", [7.38, 5.47, 3.15], [0.0002, 0.0028, 0.0163]),
    ("ketchup", [0.18, 0.07, 0.03], [0.061, 0.97, 1.45]),
    ("marble", [2.19, 2.62, 3.00], [0.0021, 0.0041, 0.0071]),
    ("potato", [0.68, 0.70, 0.55], [0.0024, 0.0090, 0.12]),
    ("skimmilk", [0.70, 1.22, 1.90], [0.0014, 0.0025, 0.0142]),
    ("skin1", [0.74, 0.88, 1.01], [0.032, 0.17, 0.48]),
    ("skin2", [1.09, 1.59, 1.79], [0.013, 0.070, 0.145]),
    ("spectralon", [11.6, 20.4, 14.9], [0.0, 0.0, 0.0]),
    ("wholemilk", [2.55, 3.21, 3.77], [0.0011, 0.0024, 0.014]),
];

impl Medium {
    /// One of the [`MEASURED`] materials by name (case-insensitive).
    ///
    /// # Errors
    /// [`Error::UnknownMaterial`] listing the names.
    ///
    /// ```
    /// let marble = tet_diffusion::Medium::measured("Marble")?;
    /// assert_eq!(marble.sigma_s_prime, [2.19, 2.62, 3.00]);
    /// # Ok::<(), tet_diffusion::Error>(())
    /// ```
    pub fn measured(name: &str) -> Result<Self, Error> {
        MEASURED
            .iter()
            .find(|m| m.0.eq_ignore_ascii_case(name))
            .map(|m| Self {
                sigma_a: m.2,
                sigma_s_prime: m.1,
            })
            .ok_or_else(|| Error::UnknownMaterial(name.to_owned()))
    }

    /// Checks `μa ≥ 0` and `σs′ > 0`, finite; `what` names the medium in
    /// the error.
    ///
    /// # Errors
    /// [`Error::BadArgument`] naming the coefficient and channel.
    pub fn check(&self, what: &str) -> Result<(), Error> {
        for c in 0..3 {
            let a = self.sigma_a[c];
            if !(a.is_finite() && a >= 0.0) {
                return Err(Error::BadArgument {
                    what: format!("sigma_a[{c}] of {what}"),
                    value: a,
                    need: "an absorption coefficient must be finite and ≥ 0",
                });
            }
            let s = self.sigma_s_prime[c];
            if !(s.is_finite() && s > 0.0) {
                return Err(Error::BadArgument {
                    what: format!("sigma_s_prime[{c}] of {what}"),
                    value: s,
                    need: "a reduced scattering coefficient must be finite and > 0",
                });
            }
        }
        Ok(())
    }

    /// The diffusion coefficient `κ = 1 / (3 (μa + σs′))`, in mm.
    pub fn kappa(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| 1.0 / (3.0 * (self.sigma_a[c] + self.sigma_s_prime[c])))
    }

    /// The diffusion length `ℓ = 1 / √(3 μa (μa + σs′)) = √(κ / μa)` per
    /// channel, in mm (infinite without absorption).
    pub fn diffusion_length(&self) -> [f64; 3] {
        [0, 1, 2].map(|c| {
            let a = self.sigma_a[c];
            1.0 / (3.0 * a * (a + self.sigma_s_prime[c])).sqrt()
        })
    }

    /// `(1 − t) self + t other`, coefficient by coefficient.
    pub fn lerp(&self, other: &Self, t: f64) -> Self {
        let mix = |a: [f64; 3], b: [f64; 3]| [0, 1, 2].map(|c| a[c] + t * (b[c] - a[c]));
        Self {
            sigma_a: mix(self.sigma_a, other.sigma_a),
            sigma_s_prime: mix(self.sigma_s_prime, other.sigma_s_prime),
        }
    }
}

/// A procedural heterogeneous material, as the paper's Fig. 4 one: 3D
/// fractal value noise `t(x) ∈ [0, 1]` blends two media,
/// `(1 − t) a + t b`, evaluated at each tet centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// The medium where the noise is 0.
    pub a: Medium,
    /// The medium where the noise is 1.
    pub b: Medium,
    /// Size of the largest noise features, in mesh units.
    pub scale: f64,
    /// Octaves of the fractal sum (each half the size and amplitude).
    pub octaves: u32,
    /// Seed of the lattice values.
    pub seed: u64,
}

impl Noise {
    /// The noise value in `[0, 1]` at `x` (mesh units).
    pub fn value(&self, x: DVec3) -> f64 {
        let (mut sum, mut norm, mut amplitude, mut p) = (0.0, 0.0, 1.0, x / self.scale);
        for o in 0..self.octaves.max(1) {
            sum += amplitude * value_noise(p, self.seed.wrapping_add(o as u64));
            norm += amplitude;
            amplitude *= 0.5;
            p *= 2.0;
        }
        (sum / norm).clamp(0.0, 1.0)
    }

    /// The medium at `x`.
    pub fn medium(&self, x: DVec3) -> Medium {
        self.a.lerp(&self.b, self.value(x))
    }

    /// The media of every tet of `mesh`, by its centre.
    ///
    /// # Errors
    /// [`Error::BadArgument`] for a scale that is not positive and finite,
    /// and the checks of [`Medium::check`] on both media.
    pub fn media(&self, mesh: &crate::TetMesh) -> Result<Vec<Medium>, Error> {
        if !(self.scale.is_finite() && self.scale > 0.0) {
            return Err(Error::BadArgument {
                what: "the noise scale".into(),
                value: self.scale,
                need: "it must be positive and finite",
            });
        }
        self.a.check("the noise's first medium")?;
        self.b.check("the noise's second medium")?;
        Ok((0..mesh.tets().len())
            .map(|t| self.medium(mesh.tet_center(t)))
            .collect())
    }
}

/// A hash of a lattice point to `[0, 1)` (splitmix64 finaliser).
fn lattice(i: [i64; 3], seed: u64) -> f64 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for c in i {
        h ^= c as u64;
        h = h.wrapping_add(0x9E37_79B9_7F4A_7C15);
        h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 31;
    }
    (h >> 11) as f64 / (1u64 << 53) as f64
}

/// Trilinear interpolation of lattice values with smoothstep weights.
fn value_noise(p: DVec3, seed: u64) -> f64 {
    let f = p.floor();
    let i = [f.x as i64, f.y as i64, f.z as i64];
    let t = (p - f).to_array().map(|t| t * t * (3.0 - 2.0 * t));
    let mut v = 0.0;
    for corner in 0..8 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1];
        let w: f64 = (0..3)
            .map(|k| if o[k] == 1 { t[k] } else { 1.0 - t[k] })
            .product();
        v += w * lattice(
            [i[0] + o[0] as i64, i[1] + o[1] as i64, i[2] + o[2] as i64],
            seed,
        );
    }
    v
}

/// A warning that a channel's diffusion length is below the mesh's mean
/// edge length: the mesh cannot resolve the light's fall-off there (the
/// paper's stated limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolutionWarning {
    /// A tet (the first found) with this medium.
    pub tet: usize,
    /// The channel (0 red, 1 green, 2 blue).
    pub channel: usize,
    /// Its diffusion length, mm.
    pub diffusion_length_mm: f64,
    /// The mesh's mean edge length, mm.
    pub edge_length_mm: f64,
}

impl std::fmt::Display for ResolutionWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tetrahedron {}: the {} channel's diffusion length {:.3} mm is below the mean edge length {:.3} mm; refine the mesh to resolve it",
            self.tet,
            ["red", "green", "blue"][self.channel],
            self.diffusion_length_mm,
            self.edge_length_mm
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_and_checks() {
        assert_eq!(MEASURED.len(), 12);
        let k = Medium::measured("ketchup").unwrap();
        assert_eq!(k.sigma_a, [0.061, 0.97, 1.45]);
        assert!(Medium::measured("jade").is_err());
        for (name, ..) in MEASURED {
            Medium::measured(name).unwrap().check(name).unwrap();
        }
        let bad = Medium {
            sigma_a: [0.0, -1.0, 0.0],
            sigma_s_prime: [1.0; 3],
        };
        let e = bad.check("tetrahedron 4").unwrap_err().to_string();
        assert!(e.contains("sigma_a[1] of tetrahedron 4"), "{e}");
        let bad = Medium {
            sigma_a: [0.0; 3],
            sigma_s_prime: [1.0, 0.0, 1.0],
        };
        assert!(bad.check("x").is_err());
        let m = Medium::measured("marble").unwrap();
        let l = m.diffusion_length();
        let kappa = m.kappa();
        assert!((l[0] - (kappa[0] / m.sigma_a[0]).sqrt()).abs() < 1e-9 * l[0]);
        assert!(Medium::measured("spectralon").unwrap().diffusion_length()[0].is_infinite());
    }

    #[test]
    fn noise_is_smooth_and_in_range() {
        let n = Noise {
            a: Medium::measured("marble").unwrap(),
            b: Medium::measured("ketchup").unwrap(),
            scale: 1.0,
            octaves: 3,
            seed: 7,
        };
        let mut lo: f64 = 1.0;
        let mut hi: f64 = 0.0;
        for k in 0..1000 {
            let x = DVec3::new(k as f64 * 0.013, (k as f64 * 0.7).sin(), 0.3);
            let v = n.value(x);
            lo = lo.min(v);
            hi = hi.max(v);
            let dv = (n.value(x + DVec3::X * 1e-6) - v).abs();
            assert!(dv < 1e-4);
        }
        assert!(lo >= 0.0 && hi <= 1.0 && hi - lo > 0.2);
    }
}
