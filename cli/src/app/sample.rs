//! `trilux sample`: random points on a mesh, uniform or with a density
//! (texture, per-face weights, or a mesh-colours channel), to a PLY point
//! cloud or a glTF `POINTS` primitive.

use std::path::PathBuf;

use mesh_sampling::{BlueNoiseTarget, Channel, Packing, SurfacePoint};
use trilux_io::mesh::TriMesh;
use trilux_io::mesh::{gltf, ply};

use super::ops::sample::{
    ChannelArg, MAX_POINTS, Method, Points, Source, draw_points, meshcolors_source, preview,
    read_face_weights,
};
use super::{Context, Result, arg_error, file_cause, file_error};

#[derive(Debug, clap::Args)]
#[command(
    about = "Scatter random points on a mesh (uniform or with a density) and write a PLY or glTF point cloud",
    after_help = "Examples:\n  trilux sample ../shared/data/meshes/spot.obj -n 1000000 \\\n      --density ../shared/data/textures/spot_texture.png -o spot.ply --preview spot.png\n  trilux sample ../shared/data/meshes/spot.obj --blue-noise --radius 0.01 -o spot_blue.ply\n  trilux sample ../shared/data/meshes/spot.obj -n 100000 -o spot_points.glb\n  trilux sample ../shared/data/meshes/spot.obj --rate 2000 --density ../shared/data/textures/spot_texture.png -o spot_rate.ply\n  trilux sample ../shared/data/meshes/spot.obj -n 100000 --hair 0.05:8 --hair-comb 0,-1,0:40 \\\n      -o spot_hair.usda --preview spot_hair.png"
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
        // `--max-density` requires `--rate` (which conflicts with -n): so
        // that clap asks for `--rate` alone, not for -n too.
        required_unless_present_any = ["radius", "rate", "max_density"]
    )]
    pub(crate) count: Option<i64>,
    /// Instead of -n: points per unit area (in the mesh's unit) where the
    /// density is 1 (Blender's and Houdini's "density"), a Poisson process
    /// of intensity rate × density whose points on a face depend only on
    /// the seed, the face and the density there (a raised density only
    /// adds points). The density is looked up exactly (no --method).
    #[arg(
        long,
        value_name = "R",
        allow_negative_numbers = true,
        conflicts_with_all = ["count", "blue_noise", "method"]
    )]
    pub(crate) rate: Option<f64>,
    /// With --rate: the density's ceiling, which fixes the candidates
    /// (rate × M per unit area). Default: the density's own maximum (1
    /// without a density); state it (1 for a [0, 1] channel) to keep the
    /// points when the density is edited and sampled again.
    #[arg(
        long,
        value_name = "M",
        allow_negative_numbers = true,
        requires = "rate"
    )]
    pub(crate) max_density: Option<f64>,
    /// Blue noise: points that keep their distance (Poisson-disk), following
    /// the density, by weighted sample elimination (Yuksel 2015; --packing
    /// dense packs them closer), in progressive order (every prefix of N/2^k
    /// points is itself spread).
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
    /// With --blue-noise: elimination (Yuksel 2015, 5 candidates per point,
    /// relative radius about 0.69) or dense (14 candidates, then the
    /// closest points move into the largest holes: about 0.76, as MeshLab's
    /// Poisson-disk sampling; about 6x the time). Default: elimination, as
    /// the library's `BlueNoiseOptions::default()` (Python's
    /// `trilux.blue_noise` defaults to dense).
    #[arg(long, value_enum, value_name = "PACKING", requires = "blue_noise")]
    pub(crate) packing: Option<PackingArg>,
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
    /// The point cloud to write, with normals, UVs (when the mesh has them)
    /// and face ids: .ply, or .glb / .gltf (+ .bin) as a POINTS primitive
    /// with the face ids as the _FACE attribute (meshes of at most 2^24
    /// triangles).
    #[arg(short, long, value_name = "OUT.ply")]
    pub(crate) output: PathBuf,
    /// Write ASCII PLY instead of binary (PLY only).
    #[arg(long)]
    pub(crate) ascii: bool,
    /// Also render a PNG (or EXR) picture of the points on the mesh.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) preview: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) hair: super::hair::HairArgs,
}

/// The values of `--packing`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum PackingArg {
    Elimination,
    Dense,
}

impl PackingArg {
    fn packing(self) -> Packing {
        match self {
            Self::Elimination => Packing::Elimination,
            Self::Dense => Packing::Dense,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Self::Elimination => "elimination",
            Self::Dense => "dense",
        }
    }
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    let wanted = wanted(&args)?;
    let channel = args.channel.unwrap_or(ChannelArg::Luminance).channel();
    super::check_output(context, "-o", &args.output, args.hair.outputs())?;
    let ext = super::extension(&args.output);
    let gltf = ext == "glb" || ext == "gltf";
    if ext != "ply" && args.ascii {
        return Err(arg_error(
            "--ascii",
            format!(
                "ASCII is a PLY encoding, and {} is {} (write .ply, or leave out --ascii)",
                args.output.display(),
                format_name(&ext)
            ),
        ));
    }
    if let Some(p) = &args.preview {
        super::check_output(context, "--preview", p, &["png", "exr"])?;
    }
    let mesh = super::read_mesh(context, &args.mesh)?;
    if gltf {
        check_gltf_faces(&args.output, mesh.indices.len())?;
    }
    let method = method(&args)?;
    let source = source(context, &args, &mesh, channel)?;
    let points = super::with_threads(args.threads, || {
        context.step("sampling", || {
            draw_points(&mesh, &source, method, args.seed, wanted)
        })
    })?
    // A usage error names its argument already; anything else is the mesh's.
    .map_err(|e| {
        if e.is_usage() {
            e
        } else {
            super::at(args.mesh.display(), e)
        }
    })?;
    if args.hair.on() {
        let sampling = sampling_json(&args, method);
        return super::hair::run(context, &args, &mesh, &points, sampling);
    }
    let files = write(context, &args, &mesh, &points)?;
    report(context, &args, (&mesh, &points), method, &files);
    Ok(())
}

/// What an output's extension `ext` (lower case) holds, in words.
fn format_name(ext: &str) -> &'static str {
    match ext {
        "ply" => "PLY",
        "glb" | "gltf" => "glTF",
        "usda" | "usd" => "USD text already",
        "hair" => "Cem Yuksel's binary .hair format",
        _ => "not PLY",
    }
}

/// How many points `-n` or `--radius` asks for; a `--channel` needs a
/// density with channels.
fn wanted(args: &Args) -> Result<Points> {
    let packing = args.packing.unwrap_or(PackingArg::Elimination).packing();
    // clap's `requires = "rate"` lets `-n N --max-density M` through (-n
    // conflicts with --rate, and clap then waives the requirement).
    if let (Some(m), None) = (args.max_density, args.rate) {
        return Err(arg_error(
            format!("--max-density {m}"),
            "the ceiling is of the density scattered by --rate: give --rate R",
        ));
    }
    let wanted = match (args.count, args.radius) {
        _ if args.rate.is_some() => rate_points(args.rate, args.max_density)?,
        (Some(count), _) if count <= 0 || count.unsigned_abs() > MAX_POINTS => {
            return Err(arg_error(
                format!("-n {count}"),
                format!("the number of points must be between 1 and {MAX_POINTS}"),
            ));
        }
        (Some(count), _) if args.blue_noise => {
            Points::BlueNoise(BlueNoiseTarget::Count(count as usize), packing)
        }
        (Some(count), _) => Points::Random(count as usize),
        (None, Some(r)) if r.is_finite() && r > 0.0 => {
            Points::BlueNoise(BlueNoiseTarget::Radius(r), packing)
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
    Ok(wanted)
}

/// `--rate R [--max-density M]`: both finite, the rate positive.
fn rate_points(rate: Option<f64>, max_density: Option<f64>) -> Result<Points> {
    let rate = rate.unwrap_or(f64::NAN);
    if !(rate.is_finite() && rate > 0.0) {
        return Err(arg_error(
            format!("--rate {rate}"),
            "the rate must be a positive number (points per unit area)",
        ));
    }
    if let Some(m) = max_density.filter(|m| !(m.is_finite() && *m > 0.0)) {
        return Err(arg_error(
            format!("--max-density {m}"),
            "the density's ceiling must be a positive number",
        ));
    }
    Ok(Points::Rate { rate, max_density })
}

/// The method: `--method`, or by default subdivision with a density and
/// uniform without; checked against the density and `--blue-noise`.
fn method(args: &Args) -> Result<Method> {
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
    Ok(method)
}

/// The density to sample: a texture, per-face weights, a mesh-colours
/// channel, or none.
fn source(context: &mut Context, args: &Args, mesh: &TriMesh, channel: Channel) -> Result<Source> {
    let source = if let Some(path) = &args.density {
        // The image first: a wrong path is the first thing to tell.
        let image = super::read_image(context, path, true)?;
        if mesh.uvs.is_none() {
            return Err(file_error(
                &args.mesh,
                "a density texture is looked up at texture coordinates, and the mesh has none \
                 (give the mesh UVs, or use --face-weights or --density-meshcolors)",
            ));
        }
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
            meshcolors_source(mesh, &args.mesh, path, channel)
        })?
    } else {
        Source::Uniform
    };
    Ok(source)
}

/// Refuses a glTF output for a mesh of more than 2^24 triangles, before
/// sampling: glTF stores each point's face id as an `f32` attribute,
/// exact below 2^24 only.
fn check_gltf_faces(output: &std::path::Path, triangles: usize) -> Result<()> {
    if triangles > GLTF_MAX_FACES {
        return Err(file_error(
            output,
            format!(
                "the mesh has {triangles} triangles, and glTF stores each point's face id as a \
                 32-bit float, exact only for the first 2^24 ({GLTF_MAX_FACES}) triangles \
                 (write .ply for larger meshes)"
            ),
        ));
    }
    Ok(())
}

/// Face ids glTF's `f32` `_FACE` attribute holds exactly: 0 to 2^24 − 1.
const GLTF_MAX_FACES: usize = gltf::FACE_ID_LIMIT as usize;

/// The point cloud (PLY or glTF by extension), and the preview when
/// asked for.
fn write(
    context: &mut Context,
    args: &Args,
    mesh: &TriMesh,
    points: &[SurfacePoint],
) -> Result<Vec<PathBuf>> {
    let cloud = context.step("building the point cloud", || {
        trilux::point_cloud(mesh, points)
    });
    let format = if args.ascii {
        ply::Format::Ascii
    } else {
        ply::Format::BinaryLittleEndian
    };
    let force = context.force;
    let files = if super::extension(&args.output) == "ply" {
        context.step("writing the PLY file", || {
            trilux::output::write_atomic(&args.output, force, |tmp| {
                Ok(ply::write(tmp, &cloud, format)?)
            })
        })?;
        vec![args.output.clone()]
    } else {
        let points = gltf::Points::from(&cloud);
        context.step("writing the glTF file", || {
            trilux::output::write_gltf(&args.output, force, |tmp| gltf::write_points(tmp, &points))
        })?
    };
    if let Some(path) = &args.preview {
        let image = context.step("rendering the preview", || preview(mesh, points, 768, 768));
        super::write_image(context, path, &image)?;
    }
    Ok(files)
}

/// The summary line, or the JSON object; `files` are the point cloud's
/// (a `.gltf` and its `.bin`, or one file).
fn report(
    context: &Context,
    args: &Args,
    (mesh, points): (&TriMesh, &[SurfacePoint]),
    method: Method,
    files: &[PathBuf],
) {
    let packing = args.packing.unwrap_or(PackingArg::Elimination);
    let kind = if let Some(rate) = args.rate {
        format!("rate {rate} per unit area")
    } else if args.blue_noise {
        format!("{}, blue noise by {}", method.name(), packing.name())
    } else {
        method.name().to_string()
    };
    let text = format!(
        "{} point{} ({kind}) on {} ({} triangles) written to {}{}\n",
        points.len(),
        if points.len() == 1 { "" } else { "s" },
        args.mesh.display(),
        mesh.indices.len(),
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        args.preview
            .as_ref()
            .map(|p| format!(", preview {}", p.display()))
            .unwrap_or_default()
    );
    let mut json = serde_json::json!({
        "command": "sample",
        "mesh": super::shown(&args.mesh),
        "triangles": mesh.indices.len(),
        "points": points.len(),
        "output": super::shown(&args.output),
        "files": files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    if let (Some(json), serde_json::Value::Object(fields)) =
        (json.as_object_mut(), sampling_json(args, method))
    {
        json.extend(fields);
    }
    context.report(&text, json);
}

/// How the points were drawn, as `--json` reports it with and without
/// `--hair`: method, rate, max_density, blue_noise, packing, seed and
/// preview.
pub(crate) fn sampling_json(args: &Args, method: Method) -> serde_json::Value {
    let packing = args.packing.unwrap_or(PackingArg::Elimination);
    serde_json::json!({
        "method": if args.rate.is_some() { "rate" } else { method.name() },
        "rate": args.rate,
        "max_density": args.max_density,
        "blue_noise": args.blue_noise,
        "packing": args.blue_noise.then_some(packing.name()),
        "seed": args.seed,
        "preview": args.preview.as_deref().map(super::shown),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use trilux_io::glam::Vec3;

    /// A face id of 2^24 or more, which glTF's `f32` `_FACE` cannot hold:
    /// the writer's error, naming the output (not its temporary name), and
    /// nothing left behind; a mesh with that many triangles is refused
    /// before sampling.
    #[test]
    fn a_face_id_gltf_cannot_hold_is_an_error_naming_the_output() {
        let dir = tempfile::tempdir().unwrap();
        let cloud = ply::PlyData {
            positions: vec![Vec3::ZERO, Vec3::X],
            face_ids: Some(vec![0, GLTF_MAX_FACES as u32]),
            ..ply::PlyData::default()
        };
        let points = gltf::Points::from(&cloud);
        for name in ["far.glb", "far.gltf"] {
            let out = dir.path().join(name);
            let e = trilux::output::write_gltf(&out, false, |tmp| gltf::write_points(tmp, &points))
                .unwrap_err();
            let text = e.to_string();
            assert!(
                text.starts_with(&format!("{}: ", out.display()))
                    && text.contains("point 1 lies on face 16777216")
                    && text.contains("2^24"),
                "{text}"
            );
            assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        }
        let out = dir.path().join("big.glb");
        assert!(check_gltf_faces(&out, GLTF_MAX_FACES).is_ok());
        let e = check_gltf_faces(&out, GLTF_MAX_FACES + 1).unwrap_err();
        assert_eq!(e.place(), Some(out.display().to_string()));
        let why = std::error::Error::source(&e).unwrap().to_string();
        assert!(
            why.contains("16777217 triangles") && why.contains(".ply"),
            "{why}"
        );
    }
}
