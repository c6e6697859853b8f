//! Sampling inside one triangle, for renderers that choose the triangle
//! themselves (a light BVH or light tree weighted by
//! [`Emitter::triangle_power`]).

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

use super::{Emission, Emitter, Inner, LightSample};
use crate::parallel::unit;
use crate::point::uniform_barycentric;
use crate::{DensitySampler, Error, Mode, SurfacePoint};

/// Per piece of `sampler`, the mass of its face's pieces up to and
/// including it.
fn cumulative_masses(sampler: &DensitySampler<'_>) -> Vec<f64> {
    let faces = sampler.mesh().indices.len();
    let mut out = Vec::with_capacity(sampler.pieces());
    for f in 0..faces {
        let mut sum = 0.0;
        for k in sampler.face_range(f).unwrap_or_default() {
            sum += sampler.piece_mass(sampler.piece_at(k));
            out.push(sum);
        }
    }
    out
}

/// `x` clamped into `[0, 1]`, NaN counting as 0.
#[expect(clippy::manual_clamp, reason = "max maps NaN to 0; clamp keeps NaN")]
fn clamp_unit(x: f64) -> f64 {
    x.max(0.0).min(1.0)
}

impl Emitter<'_> {
    /// A point of triangle `face` for the uniform variates `u` (in
    /// `[0, 1)²`; clamped into it, NaN counting as 0), distributed inside
    /// the triangle as the strategy distributes points inside triangles:
    /// uniformly for [`Area`](super::Strategy::Area) and
    /// [`TrianglePower`](super::Strategy::TrianglePower) (and per-face
    /// radiance), by the subdivision's `p′` restricted to the triangle
    /// (mixed with uniform at the defensive fraction, see
    /// [`EmitterOptions::defensive_fraction`](super::EmitterOptions::defensive_fraction))
    /// for [`Texture`](super::Strategy::Texture), and proportionally to the
    /// emitted luminance for [`TextureExact`](super::Strategy::TextureExact).
    /// The sample's `pdf` is the density **given the triangle**
    /// ([`pdf_in_triangle`](Self::pdf_in_triangle)): multiply it by your
    /// structure's probability of choosing `face`.
    ///
    /// `TextureExact` draws its first proposal from `u` and, when that is
    /// rejected, further proposals from a random stream seeded by `u`, so
    /// the point is a function of `u` alone (stratification of `u` helps
    /// through the first proposal, taken with probability
    /// [`DensitySampler::acceptance`] on average).
    ///
    /// The texture strategies build, on the first call (or the first
    /// [`pdf_in_triangle`](Self::pdf_in_triangle)), the cumulative masses
    /// of each triangle's pieces (8 bytes a piece), then find a piece by
    /// bisection among its triangle's.
    ///
    /// # Errors
    /// [`Error::NoSuchFace`]; [`Error::DarkTriangle`] for a triangle with
    /// no area, or (texture strategies) no emission, to sample.
    pub fn sample_in_triangle(&self, face: usize, u: [f64; 2]) -> Result<LightSample, Error> {
        if face >= self.mesh.indices.len() {
            return Err(self.no_such_face(face));
        }
        let [u0, u1] = u.map(clamp_unit);
        let dark = Error::DarkTriangle { face };
        let bary = match &self.inner {
            Inner::Texture {
                sampler, face_cdf, ..
            } if !matches!(self.emission, Emission::PerFace(_)) => {
                if self.masses[face] <= 0.0 {
                    return Err(dark);
                }
                let cdf = face_cdf.get_or_init(|| cumulative_masses(sampler));
                let range = sampler.face_range(face).unwrap_or_default();
                let cdf = &cdf[range.clone()];
                let pick = |x: f64| {
                    let total = cdf.last().copied().unwrap_or(0.0);
                    let t = x * total;
                    let k = cdf.partition_point(|&c| c <= t).min(cdf.len() - 1);
                    let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
                    let rest = clamp_unit((t - lo) / (cdf[k] - lo));
                    (sampler.piece_at(range.start + k), rest)
                };
                match sampler.mode() {
                    Mode::Exact => {
                        let Emission::Texture { texture, .. } = self.emission else {
                            return Err(dark);
                        };
                        let y = texture.luminance();
                        let mut rng = Pcg64Mcg::seed_from_u64(
                            u0.to_bits() ^ u1.to_bits().rotate_left(29) ^ face as u64,
                        );
                        let (mut x0, mut x1) = (u0, u1);
                        loop {
                            let (piece, rest) = pick(x0);
                            let bary = sampler.place(piece, rest, x1);
                            let f = y.eval(self.uv_at(face, bary));
                            if unit(rng.next_u64()) * f64::from(piece.value) < f {
                                break bary;
                            }
                            (x0, x1) = (unit(rng.next_u64()), unit(rng.next_u64()));
                        }
                    }
                    Mode::Approximate => {
                        let alpha = self.in_triangle_fraction(cdf);
                        if u0 < alpha {
                            uniform_barycentric(u0 / alpha, u1)
                        } else {
                            let (piece, rest) = pick((u0 - alpha) / (1.0 - alpha));
                            sampler.place(piece, rest, u1)
                        }
                    }
                }
            }
            _ => {
                if self.mesh.area(face) <= 0.0 {
                    return Err(dark);
                }
                uniform_barycentric(u0, u1)
            }
        };
        let pdf = self.pdf_in_triangle(face, bary);
        let point = SurfacePoint::on(&self.mesh, face as u32, bary, pdf)?;
        Ok(self.light_sample(point))
    }

    /// The density in area measure, given triangle `face`, with which
    /// [`sample_in_triangle`](Self::sample_in_triangle) draws the point
    /// at `barycentric` (the value its sample carries, bit for bit). 0
    /// for a face that does not exist or that it refuses, and where it
    /// never draws.
    pub fn pdf_in_triangle(&self, face: usize, barycentric: [f32; 3]) -> f32 {
        let Some(&mass) = self.masses.get(face) else {
            return 0.0;
        };
        let area = self.mesh.area(face);
        if area <= 0.0 || area.is_nan() {
            return 0.0;
        }
        match (&self.inner, self.emission) {
            (Inner::Texture { sampler, .. }, Emission::Texture { texture, scale })
                if sampler.mode() == Mode::Exact =>
            {
                if mass <= 0.0 || !barycentric.iter().all(|b| b.is_finite()) {
                    return 0.0;
                }
                let f = texture.luminance().eval(self.uv_at(face, barycentric));
                (f * f64::from(scale) / mass) as f32
            }
            (
                Inner::Texture {
                    sampler, face_cdf, ..
                },
                Emission::Texture { .. },
            ) => {
                if mass <= 0.0 {
                    return 0.0;
                }
                let cdf = face_cdf.get_or_init(|| cumulative_masses(sampler));
                let range = sampler.face_range(face).unwrap_or_default();
                let cdf = &cdf[range];
                let alpha = self.in_triangle_fraction(cdf);
                let p = if alpha < 1.0 {
                    let value = f64::from(sampler.pdf(face, barycentric)) * sampler.total_mass();
                    (1.0 - alpha) * value / cdf[cdf.len() - 1]
                } else {
                    0.0
                };
                (p + alpha / area) as f32
            }
            _ => (1.0 / area) as f32,
        }
    }

    /// The uniform share inside a triangle whose pieces' cumulative masses
    /// are `cdf`, for the approximate texture strategy: the defensive
    /// fraction, or 1 when the subdivision has no mass there.
    fn in_triangle_fraction(&self, cdf: &[f64]) -> f64 {
        if cdf.last().is_none_or(|&m| m <= 0.0) {
            1.0
        } else {
            self.defensive_fraction()
        }
    }
}
