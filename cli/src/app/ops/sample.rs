//! Drawing points on a mesh (uniform, a density, blue noise), the
//! per-face weights file and the preview of points (`sample`, `demo`).

use std::path::Path;

use clap::ValueEnum;
use glam::Vec3;
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Channel, Density, DensitySampler, MeshRef, Mode, Packing,
    RejectionSampler, ScatterDensity, ScatterOptions, SurfaceArea, SurfacePoint, SurfaceSampler,
    UniformSampler, blue_noise, scatter,
};
use trilux_io::mesh::TriMesh;

use crate::app::{Result, arg_error, file_cause, file_error};

/// The most points one run may ask for (about 100 bytes each while
/// sampling and writing).
pub(crate) const MAX_POINTS: u64 = 200_000_000;

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum ChannelArg {
    Luminance,
    R,
    G,
    B,
    A,
}

impl ChannelArg {
    /// The name on the command line.
    pub(crate) fn name(self) -> String {
        self.to_possible_value()
            .map(|v| v.get_name().to_string())
            .unwrap_or_default()
    }

    pub(crate) fn channel(self) -> Channel {
        match self {
            Self::Luminance => Channel::Luminance,
            Self::R => Channel::Index(0),
            Self::G => Channel::Index(1),
            Self::B => Channel::Index(2),
            Self::A => Channel::Index(3),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum Method {
    Subdivision,
    Exact,
    Rejection,
    Uniform,
}

impl Method {
    pub(crate) fn name(self) -> &'static str {
        match self {
            Self::Subdivision => "subdivision",
            Self::Exact => "exact",
            Self::Rejection => "rejection",
            Self::Uniform => "uniform",
        }
    }
}

/// The density a run samples.
pub(crate) enum Source {
    Uniform,
    Texture(mesh_sampling::DensityTexture),
    FaceWeights(Vec<f32>),
    /// Mesh colours, as a texture over a mesh of per-corner vertices.
    Atlas(trilux::colors::ColorDensity),
}

/// How many points a run draws, and how.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Points {
    /// This many independent points.
    Random(usize),
    /// Blue noise, progressive, by count or radius, packed by elimination
    /// or densely.
    BlueNoise(BlueNoiseTarget, Packing),
    /// A Poisson process of `rate × density` points per unit area, with
    /// the density's ceiling (`None`: its own maximum).
    Rate { rate: f64, max_density: Option<f64> },
}

/// What a sampler draws: [`Points`] but the rate mode, which scatters
/// instead.
#[derive(Debug, Clone, Copy)]
enum Draw {
    Random(usize),
    BlueNoise(BlueNoiseTarget, Packing),
}

/// Points by rate (`--rate`): the library's scatter of `source` on
/// `mesh`, a mesh-colours density over its per-corner mesh (same faces).
/// A density above `--max-density`, or a rate that asks for too many
/// points, is an error of that argument.
fn scatter_points(
    mesh: MeshRef<'_>,
    source: &Source,
    rate: f64,
    max_density: Option<f64>,
    seed: u64,
) -> Result<Vec<SurfacePoint>> {
    let (mesh, density) = match source {
        Source::Uniform => (mesh, ScatterDensity::Uniform),
        Source::Texture(t) => (mesh, Density::Texture(t).into()),
        Source::FaceWeights(w) => (mesh, Density::PerFace(w).into()),
        Source::Atlas(d) => (d.mesh_ref(), Density::Texture(&d.texture).into()),
    };
    let options = ScatterOptions {
        max_density,
        seed,
        ..ScatterOptions::new(rate)
    };
    scatter(mesh, density, &options).map_err(|e| match e {
        mesh_sampling::Error::DensityOutOfRange { face, value, max } => arg_error(
            format!("--max-density {max}"),
            format!(
                "the density on face {face} is {value}, above the ceiling (raise it, or leave it \
                 out for the density's own maximum)"
            ),
        ),
        // The library's message names its streaming API; a CLI user can
        // only lower the rate, so say by how much.
        mesh_sampling::Error::TooManyPoints { requested, budget } => arg_error(
            format!("--rate {rate}"),
            too_many_by_rate(rate, requested, budget),
        ),
        e => e.into(),
    })
}

/// Why `--rate rate` is refused when it would draw about `requested`
/// points (candidates: rate × the density's ceiling × area) and a run
/// writes at most `budget`: the largest rate that fits.
fn too_many_by_rate(rate: f64, requested: f64, budget: usize) -> String {
    let fits = rate * budget as f64 / requested;
    format!(
        "this rate would draw about {requested:.3e} points (rate × the density's ceiling × the \
         mesh's area), and one run writes at most {budget}: give a --rate of at most {fits:.3e}, \
         or -n N for a fixed count"
    )
}

/// The blue-noise options of `trilux sample --blue-noise [--packing P]`:
/// the library's defaults for the packing (`BlueNoiseOptions::default()`
/// or `::dense()`), in progressive order.
pub(crate) fn blue_noise_options(packing: Packing) -> BlueNoiseOptions {
    let base = match packing {
        Packing::Elimination => BlueNoiseOptions::default(),
        Packing::Dense => BlueNoiseOptions::dense(),
    };
    BlueNoiseOptions {
        progressive: true,
        ..base
    }
}

/// The points of `sampler` that `points` asks for. A blue-noise target
/// the library refuses (a radius so small the candidates exceed the
/// memory budget) is an error of the argument that set it, `-n` or
/// `--radius`: the options themselves are the library's defaults.
fn points_of<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    points: Draw,
    seed: u64,
) -> Result<Vec<SurfacePoint>> {
    match points {
        Draw::Random(n) => Ok(sampler.sample_n(seed, n)?),
        Draw::BlueNoise(target, packing) => {
            blue_noise(sampler, target, seed, &blue_noise_options(packing)).map_err(|e| match e {
                mesh_sampling::Error::InvalidOption(problem) => {
                    arg_error(target_argument(target), problem)
                }
                e => e.into(),
            })
        }
    }
}

/// The argument as typed that set a blue-noise target.
fn target_argument(target: BlueNoiseTarget) -> String {
    match target {
        BlueNoiseTarget::Count(n) => format!("-n {n}"),
        BlueNoiseTarget::Radius(r) => format!("--radius {r}"),
    }
}

/// Draws `n` points of `source` on `mesh` with `method`.
pub(crate) fn draw(
    mesh: &TriMesh,
    source: &Source,
    method: Method,
    seed: u64,
    n: usize,
) -> Result<Vec<SurfacePoint>> {
    draw_points(mesh, source, method, seed, Points::Random(n))
}

/// Draws the points `points` asks for, of `source` on `mesh` with `method`
/// (blue noise with any method but rejection).
pub(crate) fn draw_points(
    mesh: &TriMesh,
    source: &Source,
    method: Method,
    seed: u64,
    points: Points,
) -> Result<Vec<SurfacePoint>> {
    let base = trilux::mesh_ref(mesh);
    let points = match points {
        Points::Rate { rate, max_density } => {
            return scatter_points(base, source, rate, max_density, seed);
        }
        Points::Random(n) => Draw::Random(n),
        Points::BlueNoise(target, packing) => Draw::BlueNoise(target, packing),
    };
    let (mesh_ref, texture) = match source {
        Source::Uniform => (base, None),
        Source::Texture(t) => (base, Some(t)),
        Source::FaceWeights(w) => {
            let sampler = DensitySampler::new(base, Density::PerFace(w))?;
            return points_of(&sampler, points, seed);
        }
        Source::Atlas(density) => (density.mesh_ref(), Some(&density.texture)),
    };
    let Some(texture) = texture else {
        return points_of(&UniformSampler::new(mesh_ref)?, points, seed);
    };
    match (method, points) {
        (Method::Uniform, _) => points_of(&UniformSampler::new(mesh_ref)?, points, seed),
        (Method::Rejection, Draw::Random(n)) => {
            Ok(RejectionSampler::new(mesh_ref, texture)?.sample_n(seed, n)?)
        }
        (Method::Rejection, Draw::BlueNoise(..)) => Err(arg_error(
            "--method rejection",
            "blue noise draws its candidates by subdivision or exactly, not by rejection",
        )),
        (Method::Subdivision | Method::Exact, _) => {
            let options = mesh_sampling::Options {
                mode: if method == Method::Exact {
                    Mode::Exact
                } else {
                    Mode::Approximate
                },
                ..Default::default()
            };
            let sampler =
                DensitySampler::with_options(mesh_ref, Density::Texture(texture), &options)?;
            points_of(&sampler, points, seed)
        }
    }
}

/// Reads per-face weights: one number per line, blank lines and `#`
/// comments skipped, exactly one per triangle.
pub(crate) fn read_face_weights(path: &Path, triangles: usize) -> Result<Vec<f32>> {
    crate::app::check_input(path)?;
    let text = std::fs::read_to_string(path).map_err(|source| trilux::Error::File {
        path: path.to_path_buf(),
        source,
    })?;
    let mut weights = Vec::with_capacity(triangles);
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let w: f32 = line.parse().map_err(|_| {
            file_error(
                path,
                format!(
                    "line {}: expected a weight (a number), found {line:?}",
                    i + 1
                ),
            )
        })?;
        if !(w.is_finite() && w >= 0.0) {
            return Err(file_error(
                path,
                format!("line {}: weight {w} is not finite and >= 0", i + 1),
            ));
        }
        weights.push(w);
    }
    if weights.len() != triangles {
        return Err(file_error(
            path,
            format!(
                "{} weights for a mesh of {triangles} triangles (one per triangle, in file order)",
                weights.len()
            ),
        ));
    }
    Ok(weights)
}

/// A density from one channel of mesh colours made for `mesh` (read from
/// `mesh_path`).
pub(crate) fn meshcolors_source(
    mesh: &TriMesh,
    mesh_path: &Path,
    path: &Path,
    channel: Channel,
) -> Result<Source> {
    let (surface, colors) = crate::app::ops::colors::load_for(mesh, mesh_path, path)?;
    let density = trilux::colors::color_density(&surface, &colors, channel)
        .map_err(|e| file_cause(path, e))?;
    Ok(Source::Atlas(density))
}

/// The mesh in grey with the points (at most 300,000 of them) as orange
/// splats.
pub(crate) fn preview(
    mesh: &TriMesh,
    points: &[SurfacePoint],
    width: u32,
    height: u32,
) -> trilux_io::image::Image {
    use trilux::preview::{Camera, Renderer, lambert};
    let Some((lo, hi)) = trilux::mesh::bounds(mesh) else {
        return trilux::preview::render_mesh(&[], &[], width, height);
    };
    let mut r = Renderer::new(width, height, Camera::fit(lo, hi));
    r.draw_mesh(&mesh.positions, &mesh.indices, |f| lambert([0.55; 3], f));
    let step = points.len().div_ceil(300_000).max(1);
    let shown: Vec<Vec3> = points.iter().step_by(step).map(|p| p.position).collect();
    let radius = (250.0 / (shown.len() as f32).sqrt()).clamp(0.5, 3.0);
    r.draw_points(&shown, radius, |_| [1.0, 0.35, 0.05]);
    r.image()
}

/// A preview of hair: the mesh in grey, the strands as light blue lines
/// (at most about 100,000 of them, evenly strided) and their roots as
/// orange points, as [`preview`] draws points.
pub(crate) fn strands_preview(
    mesh: &TriMesh,
    points: &[SurfacePoint],
    strands: &mesh_sampling::Strands,
    width: u32,
    height: u32,
) -> trilux_io::image::Image {
    use trilux::preview::{Camera, Renderer, lambert};
    let Some((lo, hi)) = trilux::mesh::bounds(mesh) else {
        return trilux::preview::render_mesh(&[], &[], width, height);
    };
    // The box grown by the strands, so that long hair stays in the picture.
    let (lo, hi) =
        trilux::preview::bounds(&strands.points).map_or((lo, hi), |(a, b)| (lo.min(a), hi.max(b)));
    let mut r = Renderer::new(width, height, Camera::fit(lo, hi));
    r.draw_mesh(&mesh.positions, &mesh.indices, |f| lambert([0.55; 3], f));
    let per = strands.points_per_strand();
    let step = strands.len().div_ceil(100_000).max(1);
    let segments: Vec<(Vec3, Vec3)> = strands
        .points
        .chunks_exact(per)
        .step_by(step)
        .flat_map(|s| s.windows(2).map(|w| (w[0], w[1])))
        .collect();
    r.draw_lines(&segments, |_| [0.45, 0.75, 1.0]);
    let shown: Vec<Vec3> = points.iter().step_by(step).map(|p| p.position).collect();
    let radius = (150.0 / (shown.len() as f32).sqrt()).clamp(0.5, 2.0);
    r.draw_points(&shown, radius, |_| [1.0, 0.35, 0.05]);
    r.image()
}
