//! Light sampling for renderers: an emissive triangle mesh sampled by
//! area, by per-triangle power, or by the emitted power inside triangles
//! (Šik & Křivánek 2013, Sec. 5.3, "Monte Carlo rendering with complex
//! light sources"), with radiance and pdfs in area and solid-angle measure
//! for next-event estimation and multiple importance sampling.

mod emission;
mod triangle;

use std::f64::consts::PI;
use std::sync::OnceLock;

use discrete_sampling::{DiscreteSampler, GuideTable};
use glam::{DVec2, Vec3};
use rand::Rng;
use rand::distr::Distribution;

use crate::density::{check_integration, exact_mass, map_faces, texture_uvs};
use crate::parallel::{CHUNK, check_points, for_each_chunk, unit};
use crate::point::{Frame, uniform_barycentric};
use crate::{
    Density, DensitySampler, Error, MeshRef, Mode, Options, SurfacePoint, SurfaceSampler,
    UniformSampler, luminance,
};

pub use emission::{Emission, EmissionTexture};

/// How an [`Emitter`] chooses its points. All four are unbiased (every
/// pdf is exact and positive wherever the emission is); they differ in
/// variance, build cost and memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Strategy {
    /// Uniform by area, whatever the emission (pbrt-v4, LuxCore): density
    /// `1 / A` on every triangle, dark or bright.
    Area,
    /// A triangle by its emitted power (the texture integrated exactly
    /// over it), then uniform inside it (Falcor, Cycles' light tree).
    TrianglePower,
    /// By emitted power inside triangles too: Šik & Křivánek's
    /// subdivision of each triangle into sub-triangles of about a texel,
    /// each weighted by the luminance at its barycenter (the paper's
    /// `p′`, Eq. 2), mixed with [`TrianglePower`](Self::TrianglePower) at
    /// [`EmitterOptions::defensive_fraction`] when the texture has black
    /// texels (so that the pdf is positive wherever the emission is).
    #[default]
    Texture,
    /// By emitted power exactly: density proportional to the luminance of
    /// the filtered radiance ([`Mode::Exact`]: the subdivision as the
    /// proposal and a rejection step), so that `Le / pdf` is constant in
    /// luminance over the mesh.
    TextureExact,
}

impl Strategy {
    /// The four strategies, cheapest first.
    pub const ALL: [Self; 4] = [
        Self::Area,
        Self::TrianglePower,
        Self::Texture,
        Self::TextureExact,
    ];

    /// The strategy's name: `area`, `triangle-power`, `texture` or
    /// `texture-exact`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Area => "area",
            Self::TrianglePower => "triangle-power",
            Self::Texture => "texture",
            Self::TextureExact => "texture-exact",
        }
    }

    /// The strategy named `name` (as [`name`](Self::name) spells it).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

/// Which sides of the triangles emit (Lambertian: the same radiance in
/// every direction of an emitting side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Sides {
    /// The side the geometric normal points to: the side from which the
    /// triangle's corners are seen counter-clockwise (pbrt's and Mitsuba's
    /// default area light).
    #[default]
    Front,
    /// Both sides, with the same radiance.
    Both,
}

/// How an [`Emitter`] is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterOptions {
    /// How points are chosen.
    pub strategy: Strategy,
    /// Which sides emit.
    pub sides: Sides,
    /// The subdivision of the texture strategies (its `mode` is set by
    /// the strategy).
    pub subdivision: Options,
    /// The fraction of [`Strategy::Texture`]'s points drawn by
    /// [`Strategy::TrianglePower`] instead, when the emission texture has
    /// a black texel: a sub-triangle whose barycenter sees only black
    /// texels gets density 0 in the paper's `p′`, while the filtered
    /// emission may be positive on part of it; the mixture keeps the pdf
    /// positive wherever the emission is (so the estimator stays
    /// unbiased) and costs at most a factor `1 / (1 − fraction)` in the
    /// weights elsewhere. Unused (0) for a texture without black texels
    /// and for the other strategies. In `[0, 1)`; default
    /// [`DEFAULT_DEFENSIVE_FRACTION`].
    pub defensive_fraction: f64,
}

/// The default of [`EmitterOptions::defensive_fraction`]: 5%.
pub const DEFAULT_DEFENSIVE_FRACTION: f64 = 0.05;

impl Default for EmitterOptions {
    fn default() -> Self {
        Self {
            strategy: Strategy::default(),
            sides: Sides::default(),
            subdivision: Options::default(),
            defensive_fraction: DEFAULT_DEFENSIVE_FRACTION,
        }
    }
}

/// A point drawn on an emitter.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LightSample {
    /// Where: face, barycentrics, position, geometric normal (the one the
    /// pdfs use), shading normal, UV, and `pdf`, the density in area
    /// measure (per unit area of the mesh) it was drawn with.
    pub point: SurfacePoint,
    /// The radiance `Le` leaving the point from an emitting side.
    pub radiance: [f32; 3],
}

impl LightSample {
    /// The density in area measure the point was drawn with.
    pub fn pdf_area(&self) -> f32 {
        self.point.pdf
    }
}

/// A light point seen from a reference point (the shading point of
/// next-event estimation).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Toward {
    /// Unit direction from the reference point to the light point (the
    /// shadow ray's); zero when they coincide.
    pub direction: Vec3,
    /// Distance from the reference point to the light point.
    pub distance: f32,
    /// Cosine at the light point between its geometric normal and the
    /// direction back to the reference point: positive when the
    /// reference point is on the front side.
    pub cos_light: f32,
    /// The density in solid angle at the reference point:
    /// `pdf_area · distance² / |cos_light|`; 0 when the light point does
    /// not emit toward the reference point (the back of a one-sided
    /// emitter, or seen edge-on), when the two coincide, or when the
    /// value would be infinite. A sample with pdf 0 contributes nothing.
    pub pdf_solid_angle: f32,
    /// The radiance arriving from the light point: `Le`, or 0 where
    /// `pdf_solid_angle` is 0 for the side.
    pub radiance: [f32; 3],
}

/// What a light BVH or light tree needs of a triangle besides its power.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TriangleBounds {
    /// The smallest corner of its axis-aligned bounding box.
    pub min: Vec3,
    /// The largest corner.
    pub max: Vec3,
    /// Its unit geometric normal (zero for a degenerate triangle): the
    /// emitting side's for a one-sided emitter.
    pub normal: Vec3,
}

/// Per-face masses drawn from a table, uniform inside each face.
#[derive(Debug, Clone)]
struct FaceTable {
    table: GuideTable,
    frames: Vec<Frame>,
    /// The density (area measure) on each face.
    pdf: Vec<f32>,
}

impl FaceTable {
    fn new(mesh: &MeshRef<'_>, masses: &[f64], total: f64) -> Result<Self, Error> {
        let table = GuideTable::new(masses).map_err(|_| Error::NoEmission {
            triangles: masses.len(),
        })?;
        let pdf = masses
            .iter()
            .enumerate()
            .map(|(f, &m)| {
                let area = mesh.area(f);
                if m > 0.0 && area > 0.0 {
                    (m / (area * total)) as f32
                } else {
                    0.0
                }
            })
            .collect();
        Ok(Self {
            table,
            frames: Frame::all(mesh),
            pdf,
        })
    }

    fn pdf(&self, face: usize) -> f32 {
        self.pdf.get(face).copied().unwrap_or(0.0)
    }

    #[inline]
    fn sample<R: Rng + ?Sized>(&self, mesh: &MeshRef<'_>, rng: &mut R) -> SurfacePoint {
        let face = self.table.sample_rng(rng);
        let xi1 = unit(rng.next_u64());
        let bary = uniform_barycentric(xi1, unit(rng.next_u64()));
        let frame = &self.frames[face];
        SurfacePoint::in_frame(mesh, frame, face as u32, bary, self.pdf[face])
    }
}

/// The sampler behind a strategy.
#[derive(Debug, Clone)]
#[expect(
    clippy::large_enum_variant,
    reason = "one per emitter, built once: boxing would add an indirection to every draw"
)]
enum Inner<'a> {
    Area(UniformSampler<'a>),
    Faces(FaceTable),
    Texture {
        sampler: DensitySampler<'a>,
        /// The per-triangle-power component and its fraction (the
        /// approximate strategy with black texels).
        mix: Option<(FaceTable, f64)>,
        /// Per piece, the mass of its face's pieces up to it (for
        /// sampling inside one triangle), built on first use.
        face_cdf: OnceLock<Vec<f64>>,
    },
}

/// An emissive triangle mesh for a renderer's light sampling: points drawn
/// by one of four [`Strategy`]s behind one API, their radiance `Le`, and
/// pdfs in area and solid-angle measure, evaluated the same way at
/// sampling time and at a BSDF-sampled hit (from face and barycentrics:
/// no UV inversion, no extra ray; correct with overlapping and tiled UVs).
/// For renderers with their own light structure:
/// [`triangle_power`](Self::triangle_power),
/// [`triangle_bounds`](Self::triangle_bounds) and
/// [`sample_in_triangle`](Self::sample_in_triangle).
///
/// Conventions: radiance in the caller's unit, lengths in the mesh's;
/// Lambertian emission from the front side (counter-clockwise corners,
/// the geometric normal's side) or from both ([`Sides`]); every pdf uses
/// the geometric normal, never the shading normal; powers are Rec. 709
/// luminance, `Φ = sides · π · ∫ Y(Le) dA`.
///
/// # Performance
/// Building integrates the texture exactly over every triangle (one
/// clipping step per texel cell a triangle's UVs cover, O(1) where the
/// texture is constant) and, for the texture strategies, builds the
/// [`DensitySampler`] (memory: its pieces, about 16 bytes per texel the
/// mesh covers). A sample costs the strategy's draw (a table lookup and
/// two variates; the exact strategy's rejection step accepts
/// [`DensitySampler::acceptance`] of its proposals), the radiance lookup
/// (four texels) and, for the subdivision strategy, a check that the
/// point's stored barycentrics lie in the sub-triangle drawn (so that its
/// pdf is [`pdf_area`](Self::pdf_area)'s there, bit for bit); a pdf from `(face,
/// barycentric)` costs a search of the triangle's pieces for the
/// subdivision strategy, a texture lookup for the exact one, O(1) for the
/// others.
///
/// # Example
/// Next-event estimation of the irradiance at a point below a textured
/// quad:
/// ```
/// use glam::{Vec2, Vec3};
/// use mesh_sampling::{Emission, EmissionTexture, Emitter, EmitterOptions, MeshRef};
///
/// // A unit square at z = 1 facing down (seen counter-clockwise from below).
/// let positions = [
///     Vec3::new(0.0, 0.0, 1.0),
///     Vec3::new(0.0, 1.0, 1.0),
///     Vec3::new(1.0, 0.0, 1.0),
///     Vec3::new(1.0, 1.0, 1.0),
/// ];
/// let uvs = [Vec2::ZERO, Vec2::Y, Vec2::X, Vec2::ONE];
/// let indices = [[0, 1, 2], [2, 1, 3]];
/// let mesh = MeshRef { uvs: Some(&uvs), ..MeshRef::new(&positions, &indices) };
/// let texture = EmissionTexture::new(2, 2, vec![[1.0; 3], [4.0; 3], [0.5; 3], [2.0; 3]])?;
/// let emission = Emission::Texture { texture: &texture, scale: 1.0 };
/// let emitter = Emitter::new(mesh, emission, &EmitterOptions::default())?;
///
/// let x = Vec3::new(0.5, 0.5, 0.0); // the receiver, facing up
/// let samples = emitter.sample_n(7, 10_000)?;
/// let mut irradiance = 0.0;
/// for s in &samples {
///     let t = emitter.toward(s, x);
///     if t.pdf_solid_angle > 0.0 {
///         let cos_receiver = t.direction.z.max(0.0);
///         irradiance += t.radiance[0] * cos_receiver / t.pdf_solid_angle;
///     }
///     // The same pdf from (face, barycentric), as at a BSDF-sampled hit:
///     let p = emitter.pdf_solid_angle(s.point.face as usize, s.point.barycentric, x);
///     assert_eq!(p, t.pdf_solid_angle);
/// }
/// irradiance /= samples.len() as f32;
/// assert!(irradiance > 0.0);
/// # Ok::<(), mesh_sampling::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct Emitter<'a> {
    mesh: MeshRef<'a>,
    emission: Emission<'a>,
    strategy: Strategy,
    sides: Sides,
    /// `∫ Y(Le) dA` over each face (exact), the scale included.
    masses: Vec<f64>,
    total_mass: f64,
    inner: Inner<'a>,
}

impl<'a> Emitter<'a> {
    /// Validates the mesh and the emission, integrates the emission over
    /// every triangle (exactly: the filtered texture's integral) and
    /// builds the strategy's sampler (on all threads for large meshes and
    /// textures; the result does not depend on the thread count). With
    /// per-face radiance the emission is constant over each triangle, so
    /// the two texture strategies are
    /// [`TrianglePower`](Strategy::TrianglePower), which is then exact.
    ///
    /// # Errors
    /// The mesh's ([`MeshRef::validate`]); for a texture,
    /// [`Error::MissingUvs`], [`Error::NonFiniteUv`],
    /// [`Error::InvalidScale`], [`Error::IntegrationTooLarge`] when its UVs
    /// tile it too many times to integrate exactly, and the density
    /// sampler's ([`DensitySampler::with_table`]) for the texture
    /// strategies; for per-face radiance [`Error::RadianceLength`] and
    /// [`Error::InvalidRadiance`]; [`Error::InvalidOption`] for a
    /// defensive fraction outside `[0, 1)` or an emitted power that
    /// overflows; [`Error::NoEmission`] when nothing emits.
    pub fn new(
        mesh: MeshRef<'a>,
        emission: Emission<'a>,
        options: &EmitterOptions,
    ) -> Result<Self, Error> {
        mesh.validate()?;
        let alpha = options.defensive_fraction;
        if !(0.0..1.0).contains(&alpha) {
            return Err(Error::InvalidOption(format!(
                "defensive_fraction {alpha} is not in [0, 1)"
            )));
        }
        let faces = mesh.indices.len();
        let many = faces >= 1 << 12;
        let masses: Vec<f64> = match emission {
            Emission::PerFace(rgb) => {
                if rgb.len() != faces {
                    return Err(Error::RadianceLength {
                        len: rgb.len(),
                        expected: faces,
                    });
                }
                for (face, c) in rgb.iter().enumerate() {
                    if let Some(&value) = c.iter().find(|x| !(x.is_finite() && **x >= 0.0)) {
                        return Err(Error::InvalidRadiance { face, value });
                    }
                }
                (0..faces)
                    .map(|f| f64::from(luminance(rgb[f])) * mesh.area(f))
                    .collect()
            }
            Emission::Texture { texture, scale } => {
                if !(scale.is_finite() && scale >= 0.0) {
                    return Err(Error::InvalidScale(scale));
                }
                let uvs = texture_uvs(&mesh)?;
                let y = texture.luminance();
                check_integration(&mesh, uvs, y)?;
                map_faces(many, faces, |f| {
                    exact_mass(&mesh, uvs, y, f) * f64::from(scale)
                })
            }
        };
        let total_mass: f64 = masses.iter().sum();
        if total_mass.is_infinite() {
            return Err(Error::InvalidOption(
                "the emitted power overflows: lower the scale or the radiance".into(),
            ));
        }
        if total_mass.is_nan() || total_mass <= 0.0 {
            return Err(Error::NoEmission { triangles: faces });
        }
        let inner = match (options.strategy, emission) {
            (Strategy::Area, _) => Inner::Area(UniformSampler::new(mesh)?),
            (Strategy::TrianglePower, _) | (_, Emission::PerFace(_)) => {
                Inner::Faces(FaceTable::new(&mesh, &masses, total_mass)?)
            }
            (strategy, Emission::Texture { texture, .. }) => {
                let exact = strategy == Strategy::TextureExact;
                let subdivision = Options {
                    mode: if exact {
                        Mode::Exact
                    } else {
                        Mode::Approximate
                    },
                    ..options.subdivision
                };
                let density = Density::Texture(texture.luminance());
                let mut sampler = DensitySampler::with_options(mesh, density, &subdivision)?;
                // A sample's pdf is the one pdf_area gives at its stored
                // barycentrics, also where rounding them crossed a
                // sub-triangle's edge.
                sampler.settle_pdfs();
                let mix = if !exact && texture.has_black_texel() && alpha > 0.0 {
                    Some((FaceTable::new(&mesh, &masses, total_mass)?, alpha))
                } else {
                    None
                };
                Inner::Texture {
                    sampler,
                    mix,
                    face_cdf: OnceLock::new(),
                }
            }
        };
        Ok(Self {
            mesh,
            emission,
            strategy: options.strategy,
            sides: options.sides,
            masses,
            total_mass,
            inner,
        })
    }

    /// The mesh.
    pub fn mesh(&self) -> &MeshRef<'a> {
        &self.mesh
    }

    /// The emission.
    pub fn emission(&self) -> Emission<'a> {
        self.emission
    }

    /// The strategy asked for.
    pub fn strategy(&self) -> Strategy {
        self.strategy
    }

    /// Which sides emit.
    pub fn sides(&self) -> Sides {
        self.sides
    }

    /// The fraction of points drawn by per-triangle power in
    /// [`Strategy::Texture`] (see
    /// [`EmitterOptions::defensive_fraction`]): 0 when not mixed.
    pub fn defensive_fraction(&self) -> f64 {
        match &self.inner {
            Inner::Texture {
                mix: Some((_, a)), ..
            } => *a,
            _ => 0.0,
        }
    }

    /// The density sampler of the texture strategies (for its
    /// statistics: [`DensitySampler::pieces`],
    /// [`DensitySampler::acceptance`], memory).
    pub fn density_sampler(&self) -> Option<&DensitySampler<'a>> {
        match &self.inner {
            Inner::Texture { sampler, .. } => Some(sampler),
            _ => None,
        }
    }

    /// Heap memory of the emitter's tables (not the mesh or texture it
    /// borrows), in bytes.
    pub fn memory_bytes(&self) -> usize {
        let faces = |t: &FaceTable| {
            t.table.memory_bytes() + t.frames.len() * size_of::<Frame>() + t.pdf.len() * 4
        };
        self.masses.len() * size_of::<f64>()
            + match &self.inner {
                Inner::Area(u) => u.memory_bytes(),
                Inner::Faces(t) => faces(t),
                Inner::Texture {
                    sampler,
                    mix,
                    face_cdf,
                } => {
                    sampler.memory_bytes()
                        + mix.as_ref().map_or(0, |(t, _)| faces(t))
                        + face_cdf.get().map_or(0, |c| c.len() * size_of::<f64>())
                }
            }
    }

    /// The total emitted power: `sides · π · ∫ Y(Le) dA` over the mesh,
    /// with the texture integrated exactly, in luminance (Rec. 709 `Y`;
    /// for a grey emission the radiance's unit times area).
    pub fn power(&self) -> f64 {
        self.side_factor() * PI * self.total_mass
    }

    /// The power emitted by triangle `face` (the texture integrated
    /// exactly over it, as in [`power`](Self::power)): the weight a light
    /// BVH or light tree gives the triangle.
    ///
    /// # Errors
    /// [`Error::NoSuchFace`].
    pub fn triangle_power(&self, face: usize) -> Result<f64, Error> {
        let m = self.masses.get(face).ok_or(self.no_such_face(face))?;
        Ok(self.side_factor() * PI * m)
    }

    /// Triangle `face`'s bounding box and geometric normal.
    ///
    /// # Errors
    /// [`Error::NoSuchFace`].
    pub fn triangle_bounds(&self, face: usize) -> Result<TriangleBounds, Error> {
        let [a, b, c] = self.mesh.corners(face).ok_or(self.no_such_face(face))?;
        Ok(TriangleBounds {
            min: a.min(b).min(c),
            max: a.max(b).max(c),
            normal: Frame::new(&self.mesh, face).normal(),
        })
    }

    /// The radiance `Le` leaving barycentrics `barycentric` of triangle
    /// `face` from an emitting side (the texture filtered at the point's
    /// UV, times the scale; or the face's radiance). Zero for a face that
    /// does not exist.
    pub fn radiance(&self, face: usize, barycentric: [f32; 3]) -> [f32; 3] {
        match self.emission {
            Emission::PerFace(rgb) => rgb.get(face).copied().unwrap_or_default(),
            Emission::Texture { texture, scale } => {
                if face >= self.mesh.indices.len() {
                    return [0.0; 3];
                }
                let uv = self.uv_at(face, barycentric);
                texture.eval(uv).map(|c| (c * f64::from(scale)) as f32)
            }
        }
    }

    /// The radiance leaving the point toward `reference` (a ray's
    /// origin, for a BSDF-sampled hit): [`radiance`](Self::radiance), or 0
    /// when `reference` sees the back of a one-sided emitter (or the
    /// triangle edge-on).
    pub fn radiance_toward(&self, face: usize, barycentric: [f32; 3], reference: Vec3) -> [f32; 3] {
        let Some(frame) = self.frame(face) else {
            return [0.0; 3];
        };
        let position = frame.at(barycentric[1], barycentric[2]);
        let cos = -frame
            .normal()
            .as_dvec3()
            .dot(position.as_dvec3() - reference.as_dvec3());
        if self.emits(cos) {
            self.radiance(face, barycentric)
        } else {
            [0.0; 3]
        }
    }

    /// The density in area measure with which this emitter draws the
    /// point at `barycentric` of `face`: the value a sample there carries
    /// (bit for bit: the same computation). 0 for a face that does not
    /// exist, for barycentrics that are not finite, and where the strategy
    /// never draws. Barycentrics off the triangle are handled as
    /// [`DensitySampler::pdf`] does.
    pub fn pdf_area(&self, face: usize, barycentric: [f32; 3]) -> f32 {
        if !barycentric.iter().all(|b| b.is_finite()) {
            return 0.0;
        }
        match &self.inner {
            Inner::Area(u) => {
                if face < self.mesh.indices.len() {
                    u.pdf(face)
                } else {
                    0.0
                }
            }
            Inner::Faces(t) => t.pdf(face),
            Inner::Texture { sampler, mix, .. } => {
                let p = sampler.pdf(face, barycentric);
                match mix {
                    Some((faces, alpha)) => mixed(p, faces.pdf(face), *alpha),
                    None => p,
                }
            }
        }
    }

    /// The density in solid angle at `reference` with which this emitter
    /// draws the point at `barycentric` of `face`:
    /// `pdf_area · d² / |cos θ_l|` with the geometric normal, 0 where
    /// [`Toward::pdf_solid_angle`] is 0 (what [`toward`](Self::toward)
    /// gives for a sample there, bit for bit). For multiple importance
    /// sampling at a BSDF-sampled hit on the emitter.
    pub fn pdf_solid_angle(&self, face: usize, barycentric: [f32; 3], reference: Vec3) -> f32 {
        let pdf = self.pdf_area(face, barycentric);
        let Some(frame) = self.frame(face).filter(|_| pdf > 0.0) else {
            return 0.0;
        };
        let position = frame.at(barycentric[1], barycentric[2]);
        self.geometry(position, frame.normal(), pdf, reference)
            .pdf_solid_angle
    }

    /// The sample seen from `reference`: direction, distance, the cosine
    /// at the light, the solid-angle pdf and the radiance arriving (0 from
    /// the back of a one-sided emitter).
    pub fn toward(&self, sample: &LightSample, reference: Vec3) -> Toward {
        let p = &sample.point;
        let mut t = self.geometry(p.position, p.normal, p.pdf, reference);
        if t.pdf_solid_angle > 0.0 {
            t.radiance = sample.radiance;
        }
        t
    }

    /// Fills `out` with independent samples drawn from `rng`.
    pub fn sample_into<R: Rng + ?Sized>(&self, rng: &mut R, out: &mut [LightSample]) {
        let mut points = vec![SurfacePoint::default(); out.len().min(CHUNK)];
        for block in out.chunks_mut(CHUNK) {
            let points = &mut points[..block.len()];
            match &self.inner {
                Inner::Area(u) => u.sample_into(rng, points),
                Inner::Faces(t) => {
                    for p in points.iter_mut() {
                        *p = t.sample(&self.mesh, rng);
                    }
                }
                Inner::Texture { sampler, mix, .. } => {
                    sampler.sample_into(rng, points);
                    if let Some((faces, alpha)) = mix {
                        for p in points.iter_mut() {
                            self.mix_in(sampler, faces, *alpha, rng, p);
                        }
                    }
                }
            }
            for (slot, p) in block.iter_mut().zip(points.iter()) {
                *slot = self.light_sample(*p);
            }
        }
    }

    /// `n` samples from `seed`, on all threads (with the `rayon`
    /// feature), the same on any number of threads.
    ///
    /// # Errors
    /// [`Error::TooManyPoints`] if `n` exceeds [`MAX_POINTS`](crate::MAX_POINTS).
    pub fn sample_n(&self, seed: u64, n: usize) -> Result<Vec<LightSample>, Error> {
        check_points(n as f64)?;
        let mut out = vec![LightSample::default(); n];
        for_each_chunk(seed, &mut out, |rng, chunk| self.sample_into(rng, chunk));
        Ok(out)
    }

    /// The point's radiance attached.
    #[inline]
    fn light_sample(&self, point: SurfacePoint) -> LightSample {
        LightSample {
            radiance: self.radiance(point.face as usize, point.barycentric),
            point,
        }
    }

    /// Replaces `p` (drawn by the density sampler) by a per-triangle-power
    /// point with probability `alpha`, and gives it the mixture's pdf.
    #[inline]
    fn mix_in<R: Rng + ?Sized>(
        &self,
        sampler: &DensitySampler<'_>,
        faces: &FaceTable,
        alpha: f64,
        rng: &mut R,
        p: &mut SurfacePoint,
    ) {
        let density = if unit(rng.next_u64()) < alpha {
            *p = faces.sample(&self.mesh, rng);
            sampler.pdf(p.face as usize, p.barycentric)
        } else {
            p.pdf
        };
        p.pdf = mixed(density, faces.pdf(p.face as usize), alpha);
    }

    /// The texture coordinate at `barycentric` of `face` (of a validated
    /// face of a mesh with UVs), in `f64` as the density sampler computes it.
    fn uv_at(&self, face: usize, barycentric: [f32; 3]) -> DVec2 {
        let uvs = self.mesh.uvs.unwrap_or_default();
        let [a, b, c] = self.mesh.indices[face].map(|i| uvs[i as usize].as_dvec2());
        let (u, v) = (f64::from(barycentric[1]), f64::from(barycentric[2]));
        a + (b - a) * u + (c - a) * v
    }

    fn frame(&self, face: usize) -> Option<Frame> {
        (face < self.mesh.indices.len()).then(|| Frame::new(&self.mesh, face))
    }

    /// Whether a side whose cosine (of the normal with the direction to
    /// the viewer) is `cos` emits.
    fn emits(&self, cos: f64) -> bool {
        match self.sides {
            Sides::Front => cos > 0.0,
            Sides::Both => cos != 0.0,
        }
    }

    fn side_factor(&self) -> f64 {
        match self.sides {
            Sides::Front => 1.0,
            Sides::Both => 2.0,
        }
    }

    fn no_such_face(&self, face: usize) -> Error {
        Error::NoSuchFace {
            face,
            count: self.mesh.indices.len(),
        }
    }

    /// The light point at `position` with unit geometric normal `normal`
    /// and area pdf `pdf_area`, seen from `reference` (radiance left 0).
    fn geometry(&self, position: Vec3, normal: Vec3, pdf_area: f32, reference: Vec3) -> Toward {
        let d = position.as_dvec3() - reference.as_dvec3();
        let distance2 = d.length_squared();
        let distance = distance2.sqrt();
        if !(distance > 0.0 && distance.is_finite()) {
            return Toward::default();
        }
        let direction = d / distance;
        let cos = -normal.as_dvec3().dot(direction);
        let pdf = if self.emits(cos) {
            (f64::from(pdf_area) * distance2 / cos.abs()) as f32
        } else {
            0.0
        };
        Toward {
            direction: direction.as_vec3(),
            distance: distance as f32,
            cos_light: cos as f32,
            pdf_solid_angle: if pdf.is_finite() { pdf } else { 0.0 },
            radiance: [0.0; 3],
        }
    }
}

/// The mixture `(1 − α) p_density + α p_faces`, in `f64` and rounded once.
#[inline]
fn mixed(density: f32, faces: f32, alpha: f64) -> f32 {
    ((1.0 - alpha) * f64::from(density) + alpha * f64::from(faces)) as f32
}

impl Distribution<LightSample> for Emitter<'_> {
    fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> LightSample {
        let point = match &self.inner {
            Inner::Area(u) => u.sample(rng),
            Inner::Faces(t) => t.sample(&self.mesh, rng),
            Inner::Texture { sampler, mix, .. } => {
                let mut p = sampler.sample(rng);
                if let Some((faces, alpha)) = mix {
                    self.mix_in(sampler, faces, *alpha, rng, &mut p);
                }
                p
            }
        };
        self.light_sample(point)
    }
}
