//! Lights and the diffused incoming light `q(x)` of Eq. 2,
//! `q(x) = ∫ L_i(x, ω) (n · ω) F_t(ω) dω`, at the boundary vertices, with
//! shadows from rays cast against the boundary surface (a BVH from
//! `obvhs`), cached per light and vertex so that changing a light's colour
//! or re-solving does not re-trace.

use std::sync::Arc;

use glam::{DVec3, Vec3A};
use obvhs::{BvhBuildParams, bvh2::Bvh2, ray::Ray, triangle::Triangle};
use rayon::prelude::*;

use crate::error::{finite, finite_vec};
use crate::{Error, TetMesh, fresnel};

/// A light. Radiometric quantities are per mm² of surface whatever the
/// mesh's unit, so that the same object in millimetres or metres gets the
/// same `q` and `φ`.
#[derive(Debug, Clone)]
pub enum Light {
    /// A distant light: parallel rays arriving from direction `to_light`
    /// (from the surface toward the light; normalised) with `irradiance`
    /// (W/mm², RGB) on a surface facing it.
    Directional {
        /// Direction toward the light.
        to_light: DVec3,
        /// Irradiance at normal incidence, RGB.
        irradiance: [f64; 3],
    },
    /// An isotropic point light at `position` (mesh units) with radiant
    /// `intensity` (W/sr, RGB); distances are converted to mm.
    Point {
        /// Position, mesh units.
        position: DVec3,
        /// Radiant intensity, RGB.
        intensity: [f64; 3],
    },
    /// An equirectangular environment map, importance-sampled.
    Environment(Arc<Environment>),
}

impl Light {
    /// Checks that every value is finite (and the direction non-zero).
    ///
    /// # Errors
    /// [`Error::BadArgument`] naming the value.
    pub fn check(&self) -> Result<(), Error> {
        let rgb = |what: &str, v: [f64; 3]| -> Result<(), Error> {
            for (c, x) in v.into_iter().enumerate() {
                finite(|| format!("{what}[{c}] of the light"), x)?;
            }
            Ok(())
        };
        match self {
            Self::Directional {
                to_light,
                irradiance,
            } => {
                finite_vec("the light's direction", *to_light)?;
                if to_light.length_squared() == 0.0 {
                    return Err(Error::BadArgument {
                        what: "the length of the light's direction".into(),
                        value: 0.0,
                        need: "a direction must be non-zero",
                    });
                }
                rgb("irradiance", *irradiance)
            }
            Self::Point {
                position,
                intensity,
            } => {
                finite_vec("the light's position", *position)?;
                rgb("intensity", *intensity)
            }
            Self::Environment(_) => Ok(()),
        }
    }

    /// The light's directions as seen from `x`: `(unit direction toward
    /// the light, distance limit in mesh units, RGB radiance weight)`. The
    /// weight times `cos θ · F_t` is the vertex's `q` when visible.
    fn samples(&self, x: DVec3, length_unit_mm: f64, out: &mut Vec<(DVec3, f64, [f64; 3])>) {
        out.clear();
        match self {
            Self::Directional {
                to_light,
                irradiance,
            } => out.push((to_light.normalize(), f64::INFINITY, *irradiance)),
            Self::Point {
                position,
                intensity,
            } => {
                let d = *position - x;
                let r = d.length();
                if r > 0.0 {
                    let r_mm = r * length_unit_mm;
                    out.push((d / r, r, intensity.map(|i| i / (r_mm * r_mm))));
                }
            }
            Self::Environment(env) => {
                out.extend(env.samples.iter().map(|s| (s.0, f64::INFINITY, s.1)));
            }
        }
    }

    /// Number of directions per vertex.
    fn sample_count(&self) -> usize {
        match self {
            Self::Environment(env) => env.samples.len(),
            _ => 1,
        }
    }
}

/// An equirectangular (latitude–longitude) environment map of radiance,
/// reduced to a fixed set of importance-sampled directions drawn with
/// `discrete_sampling::Distribution2D::from_equirect` (proportional to
/// luminance × sin θ), so that every vertex sees the same directions and
/// the result is deterministic. Row 0 is the `+Z` pole, `φ = 2π x` from
/// `+X` toward `+Y` (`discrete_sampling::equirect_direction`).
#[derive(Debug, Clone)]
pub struct Environment {
    /// `(direction, radiance / (N · pdf(ω)))`.
    samples: Vec<(DVec3, [f64; 3])>,
}

impl Environment {
    /// Builds the sample set from `width × height` RGB radiance (W/(mm²·sr)),
    /// row-major, row 0 at the top, with `samples` directions placed on a
    /// Hammersley point set.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`], [`Error::BadArgument`] for a non-finite
    /// or negative pixel or zero samples, [`Error::Environment`] for an
    /// all-black map.
    pub fn new(
        rgb: &[[f32; 3]],
        width: usize,
        height: usize,
        samples: usize,
    ) -> Result<Self, Error> {
        if rgb.len() != width.saturating_mul(height) {
            return Err(Error::LengthMismatch {
                what: "the environment map",
                expected: width.saturating_mul(height),
                found: rgb.len(),
            });
        }
        if samples == 0 {
            return Err(Error::BadArgument {
                what: "the number of environment samples".into(),
                value: 0.0,
                need: "at least one sample",
            });
        }
        for (i, p) in rgb.iter().enumerate() {
            for (c, &v) in p.iter().enumerate() {
                if !(v.is_finite() && v >= 0.0) {
                    return Err(Error::BadArgument {
                        what: format!(
                            "channel {c} of environment pixel {i} (row {}, column {})",
                            i / width.max(1),
                            i % width.max(1)
                        ),
                        value: v as f64,
                        need: "radiance must be finite and ≥ 0",
                    });
                }
            }
        }
        let lum: Vec<f32> = rgb
            .iter()
            .map(|p| discrete_sampling::luminance(*p))
            .collect();
        let dist = discrete_sampling::Distribution2D::from_equirect(&lum, width, height)
            .map_err(Error::Environment)?;
        let mut out = Vec::with_capacity(samples);
        for k in 0..samples {
            let u = [(k as f64 + 0.5) / samples as f64, radical_inverse(k as u32)];
            let s = dist.sample_u(u);
            let pdf = discrete_sampling::pdf_solid_angle(s.pdf, s.point);
            if pdf <= 0.0 {
                continue;
            }
            let d = discrete_sampling::equirect_direction(s.point);
            let texel = rgb[s.cell[1] * width + s.cell[0]];
            let w = texel.map(|l| l as f64 / (pdf * samples as f64));
            out.push((DVec3::from_array(d), w));
        }
        Ok(Self { samples: out })
    }
}

/// Van der Corput radical inverse in base 2.
fn radical_inverse(k: u32) -> f64 {
    k.reverse_bits() as f64 / 4_294_967_296.0
}

/// The boundary surface for shadow rays.
#[derive(Clone)]
pub(crate) struct Shadows {
    bvh: Bvh2,
    triangles: Vec<Triangle>,
    vertices: Vec<[u32; 3]>,
    /// Offset of ray origins along the normal, mesh units.
    epsilon: f64,
}

impl std::fmt::Debug for Shadows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Shadows({} triangles)", self.triangles.len())
    }
}

impl Shadows {
    pub(crate) fn new(mesh: &TetMesh) -> Self {
        let p = mesh.positions();
        let to = |v: u32| Vec3A::from(p[v as usize].as_vec3());
        let triangles: Vec<Triangle> = mesh
            .boundary()
            .iter()
            .map(|f| Triangle {
                v0: to(f[0]),
                v1: to(f[1]),
                v2: to(f[2]),
            })
            .collect();
        let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(
            &triangles,
            BvhBuildParams::fast_build(),
            &mut std::time::Duration::default(),
        );
        let (lo, hi) = p.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), &x| (lo.min(x), hi.max(x)),
        );
        Self {
            bvh,
            triangles,
            vertices: mesh.boundary().to_vec(),
            epsilon: 1e-4 * (hi - lo).length(),
        }
    }

    /// Whether the ray from boundary vertex `v` at `x` (normal `n`) in
    /// direction `d` reaches distance `tmax` without hitting the surface
    /// (the triangles around `v` excluded).
    fn visible(&self, v: u32, x: DVec3, n: DVec3, d: DVec3, tmax: f64) -> bool {
        let origin = x + n * self.epsilon;
        let ray = Ray::new(
            Vec3A::from(origin.as_vec3()),
            Vec3A::from(d.as_vec3()),
            0.0,
            tmax as f32,
        );
        self.bvh.ray_traverse_miss(ray, |ray, id| {
            let t = self.bvh.primitive_indices[id] as usize;
            if self.vertices[t].contains(&v) {
                f32::INFINITY
            } else {
                self.triangles[t].intersect(ray)
            }
        })
    }
}

/// A light with its per-vertex, per-direction visibility.
#[derive(Debug, Clone)]
pub(crate) struct LitLight {
    pub(crate) light: Light,
    /// Bit `k · samples + s`: boundary vertex `k` sees direction `s`.
    visible: Vec<u64>,
}

impl LitLight {
    /// Bytes of its visibility bits.
    pub(crate) fn bytes(&self) -> usize {
        self.visible.len() * 8
    }

    /// Traces the light's shadow rays from every boundary vertex.
    pub(crate) fn trace(
        light: Light,
        mesh: &TetMesh,
        shadows: Option<&Shadows>,
        unit_mm: f64,
    ) -> Self {
        let ns = light.sample_count();
        let bv = mesh.boundary_vertices();
        let rows: Vec<Vec<bool>> = bv
            .par_iter()
            .with_min_len(64)
            .map_init(Vec::new, |buf, &v| {
                let x = mesh.positions()[v as usize];
                let n = mesh.vertex_normals()[v as usize];
                light.samples(x, unit_mm, buf);
                let mut row = vec![false; ns];
                for (s, &(d, tmax, _)) in buf.iter().enumerate() {
                    row[s] =
                        n.dot(d) > 0.0 && shadows.is_none_or(|sh| sh.visible(v, x, n, d, tmax));
                }
                row
            })
            .collect();
        let mut visible = vec![0u64; (bv.len() * ns).div_ceil(64)];
        for (k, row) in rows.iter().enumerate() {
            for (s, &on) in row.iter().enumerate() {
                if on {
                    let bit = k * ns + s;
                    visible[bit / 64] |= 1 << (bit % 64);
                }
            }
        }
        Self { light, visible }
    }

    /// Adds this light's `q` at every boundary vertex to `q`.
    pub(crate) fn add_q(&self, mesh: &TetMesh, eta: f64, unit_mm: f64, q: &mut [[f64; 3]]) {
        let ns = self.light.sample_count();
        let bv = mesh.boundary_vertices();
        q.par_iter_mut()
            .enumerate()
            .with_min_len(64)
            .for_each_init(Vec::new, |buf, (k, qk)| {
                let v = bv[k] as usize;
                let x = mesh.positions()[v];
                let n = mesh.vertex_normals()[v];
                self.light.samples(x, unit_mm, buf);
                for (s, &(d, _, w)) in buf.iter().enumerate() {
                    let bit = k * ns + s;
                    if self.visible[bit / 64] >> (bit % 64) & 1 == 1 {
                        let cos = n.dot(d);
                        let f = cos * fresnel::transmittance(cos, eta);
                        for c in 0..3 {
                            qk[c] += w[c] * f;
                        }
                    }
                }
            });
    }

    /// Replaces the light's colour (irradiance or intensity), keeping its
    /// geometry and cached visibility.
    pub(crate) fn set_color(&mut self, rgb: [f64; 3]) {
        match &mut self.light {
            Light::Directional { irradiance, .. } => *irradiance = rgb,
            Light::Point { intensity, .. } => *intensity = rgb,
            Light::Environment(_) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_environment_integrates_cosine() {
        // A white sky of radiance 1: the estimate of ∫ cos⁺ dω over the
        // upper hemisphere is π (without Fresnel).
        let (w, h) = (64, 32);
        let env = Environment::new(&vec![[1.0; 3]; w * h], w, h, 4096).unwrap();
        let n = DVec3::new(0.3, -0.2, 0.9).normalize();
        let e: f64 = env
            .samples
            .iter()
            .map(|(d, l)| l[0] * n.dot(*d).max(0.0))
            .sum();
        assert!((e - std::f64::consts::PI).abs() < 0.02, "{e}");
        assert!(Environment::new(&[[0.0; 3]; 4], 2, 2, 8).is_err());
        assert!(Environment::new(&[[f32::NAN; 3]; 4], 2, 2, 8).is_err());
    }
}
