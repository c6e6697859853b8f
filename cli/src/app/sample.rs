//! `trilux sample`: random points on a mesh, uniform or with a density
//! (texture, per-face weights, or a mesh-colours channel), to a PLY point
//! cloud.

use std::path::{Path, PathBuf};

use clap::ValueEnum;
use glam::Vec3;
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Channel, Density, DensitySampler, Mode, RejectionSampler,
    SurfaceArea, SurfacePoint, SurfaceSampler, UniformSampler, blue_noise,
};
use trilux_io::mesh::TriMesh;
use trilux_io::mesh::ply;

use super::{Context, Result, arg_error, file_cause, file_error};

/// The most points one run may ask for (about 100 bytes each while
/// sampling and writing).
pub(crate) const MAX_POINTS: u64 = 200_000_000;

#[derive(Debug, clap::Args)]
#[command(
    about = "Scatter random points on a mesh (uniform or with a density) and write a PLY point cloud",
    after_help = "Examples:\n  trilux sample ../shared/data/meshes/spot.obj -n 1000000 \\\n      --density ../shared/data/textures/spot_texture.png -o spot.ply --preview spot.png\n  trilux sample ../shared/data/meshes/spot.obj --blue-noise --radius 0.01 -o spot_blue.ply"
)]
pub(crate) struct Args {
    /// The mesh: .obj, .gltf, .glb or .ply.
    pub(crate) mesh: PathBuf,
    /// How many points (1 to 200,000,000).
    // Signed, so that `-n -5` reaches the range check and its message
    // instead of being taken for an unknown option.
    #[arg(
        short = 'n',
        long = "count",
        value_name = "N",
        allow_negative_numbers = true,
        required_unless_present = "radius"
    )]
    pub(crate) count: Option<i64>,
    /// Blue noise: points that keep their distance (Poisson-disk), following
    /// the density, by weighted sample elimination (Yuksel 2015), in
    /// progressive order (every prefix of N/2^k points is itself spread).
    #[arg(long)]
    pub(crate) blue_noise: bool,
    /// With --blue-noise, instead of -n: the disk radius in the mesh's unit
    /// (Blender's distance_min / 2); with a density, the radius where the
    /// density is its mean.
    #[arg(
        long,
        value_name = "R",
        requires = "blue_noise",
        conflicts_with = "count"
    )]
    pub(crate) radius: Option<f64>,
    /// A density texture (PNG, JPEG, HDR, EXR), looked up at the mesh's UVs;
    /// 8/16-bit values are used as stored (no sRGB decoding).
    #[arg(long, value_name = "IMAGE", group = "density_source")]
    pub(crate) density: Option<PathBuf>,
    /// Which value of the density image (or mesh colours) is the density
    /// (default: luminance); only with --density or --density-meshcolors.
    #[arg(long, value_enum)]
    pub(crate) channel: Option<ChannelArg>,
    /// One weight per triangle, one number per line (`#` comments allowed).
    #[arg(long, value_name = "FILE", group = "density_source")]
    pub(crate) face_weights: Option<PathBuf>,
    /// Mesh colours of this mesh (`trilux colors convert`) as the density.
    #[arg(long, value_name = "FILE.meshcolors", group = "density_source")]
    pub(crate) density_meshcolors: Option<PathBuf>,
    /// subdivision: Šik & Křivánek's approximation (default with a
    /// density); exact: the filtered density exactly; rejection: the
    /// paper's baseline; uniform: by area (default without a density).
    #[arg(long, value_enum)]
    pub(crate) method: Option<Method>,
    /// The random seed (same seed, same points, on any number of threads).
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// Threads to use (all by default).
    #[arg(long)]
    pub(crate) threads: Option<usize>,
    /// The PLY file to write (positions, normals, UVs, face ids).
    #[arg(short, long, value_name = "OUT.ply")]
    pub(crate) output: PathBuf,
    /// Write ASCII PLY instead of binary.
    #[arg(long)]
    pub(crate) ascii: bool,
    /// Also render a PNG (or EXR) picture of the points on the mesh.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) preview: Option<PathBuf>,
}

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
    fn name(self) -> String {
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
    fn name(self) -> &'static str {
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
    /// Blue noise, progressive, by count or radius.
    BlueNoise(BlueNoiseTarget),
}

/// The blue-noise options of `trilux sample --blue-noise`: the library's
/// defaults, in progressive order.
pub(crate) fn blue_noise_options() -> BlueNoiseOptions {
    BlueNoiseOptions {
        progressive: true,
        ..BlueNoiseOptions::default()
    }
}

/// The points of `sampler` that `points` asks for.
fn points_of<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    points: Points,
    seed: u64,
) -> std::result::Result<Vec<SurfacePoint>, mesh_sampling::Error> {
    match points {
        Points::Random(n) => sampler.sample_n(seed, n),
        Points::BlueNoise(target) => blue_noise(sampler, target, seed, &blue_noise_options()),
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
    let (mesh_ref, texture) = match source {
        Source::Uniform => (base, None),
        Source::Texture(t) => (base, Some(t)),
        Source::FaceWeights(w) => {
            let sampler = DensitySampler::new(base, Density::PerFace(w))?;
            return Ok(points_of(&sampler, points, seed)?);
        }
        Source::Atlas(density) => (density.mesh_ref(), Some(&density.texture)),
    };
    let Some(texture) = texture else {
        return Ok(points_of(&UniformSampler::new(mesh_ref)?, points, seed)?);
    };
    let points = match (method, points) {
        (Method::Uniform, _) => points_of(&UniformSampler::new(mesh_ref)?, points, seed),
        (Method::Rejection, Points::Random(n)) => {
            RejectionSampler::new(mesh_ref, texture)?.sample_n(seed, n)
        }
        (Method::Rejection, Points::BlueNoise(_)) => {
            return Err(arg_error(
                "--method rejection",
                "blue noise draws its candidates by subdivision or exactly, not by rejection",
            ));
        }
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
    };
    Ok(points?)
}

/// Reads per-face weights: one number per line, blank lines and `#`
/// comments skipped, exactly one per triangle.
pub(crate) fn read_face_weights(path: &Path, triangles: usize) -> Result<Vec<f32>> {
    super::check_input(path)?;
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
    let (surface, colors) = super::colors::load_for(mesh, mesh_path, path)?;
    let density = trilux::colors::color_density(&surface, &colors, channel)
        .map_err(|e| file_cause(path, e))?;
    Ok(Source::Atlas(density))
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    let wanted = match (args.count, args.radius) {
        (Some(count), _) if count <= 0 || count.unsigned_abs() > MAX_POINTS => {
            return Err(arg_error(
                format!("-n {count}"),
                format!("the number of points must be between 1 and {MAX_POINTS}"),
            ));
        }
        (Some(count), _) if args.blue_noise => {
            Points::BlueNoise(BlueNoiseTarget::Count(count as usize))
        }
        (Some(count), _) => Points::Random(count as usize),
        (None, Some(r)) if r.is_finite() && r > 0.0 => {
            Points::BlueNoise(BlueNoiseTarget::Radius(r))
        }
        (None, r) => {
            return Err(arg_error(
                format!("--radius {}", r.unwrap_or(f64::NAN)),
                "the radius must be a positive number (in the mesh's unit)",
            ));
        }
    };
    if let Some(channel) = args.channel
        && args.density.is_none()
        && args.density_meshcolors.is_none()
    {
        return Err(arg_error(
            format!("--channel {}", channel.name()),
            format!(
                "a channel is read from --density IMAGE or --density-meshcolors FILE, and neither is given{}",
                if args.face_weights.is_some() {
                    " (--face-weights has one weight per triangle, no channels)"
                } else {
                    ""
                }
            ),
        ));
    }
    let channel = args.channel.unwrap_or(ChannelArg::Luminance).channel();
    super::check_output(context, &args.output, &["ply"])?;
    if let Some(p) = &args.preview {
        super::check_output(context, p, &["png", "exr"])?;
    }
    let mesh = super::read_mesh(context, &args.mesh)?;
    let has_density =
        args.density.is_some() || args.face_weights.is_some() || args.density_meshcolors.is_some();
    let method = args.method.unwrap_or(if has_density {
        Method::Subdivision
    } else {
        Method::Uniform
    });
    if method != Method::Uniform && !has_density {
        return Err(arg_error(
            format!("--method {}", method.name()),
            "this method needs a density (give --density, --face-weights or --density-meshcolors)",
        ));
    }
    if method == Method::Uniform && has_density {
        return Err(arg_error(
            "--method uniform",
            "uniform sampling is by area and would ignore the density (choose subdivision, exact or rejection)",
        ));
    }
    if method == Method::Rejection && args.blue_noise {
        return Err(arg_error(
            "--method rejection",
            "blue noise draws its candidates by subdivision or exactly, not by rejection",
        ));
    }
    if method == Method::Rejection && args.face_weights.is_some() {
        return Err(arg_error(
            "--method rejection",
            "rejection needs a texture density; per-face weights are sampled exactly by subdivision",
        ));
    }
    let source = if let Some(path) = &args.density {
        if mesh.uvs.is_none() {
            return Err(file_error(
                &args.mesh,
                "a density texture is looked up at texture coordinates, and the mesh has none",
            ));
        }
        let image = super::read_image(context, path, true)?;
        let wrap = mesh
            .materials
            .first()
            .map_or(mesh_sampling::Wrap::Repeat, |m| {
                trilux::sampling_wrap(m.wrap[0])
            });
        let texture = trilux::density_texture(&image, channel)
            .map_err(|e| file_cause(path, e))?
            .with_wrap(wrap);
        Source::Texture(texture)
    } else if let Some(path) = &args.face_weights {
        Source::FaceWeights(read_face_weights(path, mesh.indices.len())?)
    } else if let Some(path) = &args.density_meshcolors {
        context.step("baking the mesh colours", || {
            meshcolors_source(&mesh, &args.mesh, path, channel)
        })?
    } else {
        Source::Uniform
    };
    let points = super::with_threads(args.threads, || {
        context.step("sampling", || {
            draw_points(&mesh, &source, method, args.seed, wanted)
        })
    })?
    .map_err(|e| super::at(args.mesh.display(), e))?;
    let cloud = context.step("building the point cloud", || {
        trilux::point_cloud(&mesh, &points)
    });
    let format = if args.ascii {
        ply::Format::Ascii
    } else {
        ply::Format::BinaryLittleEndian
    };
    let force = context.force;
    context.step("writing the PLY file", || {
        trilux::output::write_atomic(&args.output, force, |tmp| {
            Ok(ply::write(tmp, &cloud, format)?)
        })
    })?;
    if let Some(path) = &args.preview {
        let image = context.step("rendering the preview", || {
            preview(&mesh, &points, 768, 768)
        });
        super::write_image(context, path, &image)?;
    }
    let kind = if args.blue_noise {
        format!("{}, blue noise", method.name())
    } else {
        method.name().to_string()
    };
    let text = format!(
        "{} points ({kind}) on {} ({} triangles) written to {}{}\n",
        points.len(),
        args.mesh.display(),
        mesh.indices.len(),
        args.output.display(),
        args.preview
            .as_ref()
            .map(|p| format!(", preview {}", p.display()))
            .unwrap_or_default()
    );
    let json = serde_json::json!({
        "command": "sample",
        "mesh": super::shown(&args.mesh),
        "triangles": mesh.indices.len(),
        "points": points.len(),
        "method": method.name(),
        "blue_noise": args.blue_noise,
        "seed": args.seed,
        "output": super::shown(&args.output),
        "preview": args.preview.as_deref().map(super::shown),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
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
