//! `trilux sample … --hair LEN[:SEGMENTS]`: a strand grown from every
//! sampled point (Šik & Křivánek 2013, Sec. 6), written as USD text
//! (`BasisCurves` + the roots as `Points`), glTF lines + root points,
//! Cem Yuksel's `.hair`, or the roots as a PLY point cloud with face,
//! barycentric, normal and id.

use std::path::{Path, PathBuf};

use mesh_sampling::{HairOptions, StrandParams, Strands, SurfacePoint, grow_strands_with};
use trilux_io::curves;
use trilux_io::mesh::{TriMesh, ply};

use super::ops::sample::ChannelArg;
use super::{Context, Result, arg_error, file_cause};

/// The outputs `-o` takes with `--hair`.
pub(crate) const OUTPUTS: &[&str] = &["usda", "usd", "glb", "gltf", "hair", "ply"];

/// Segments per strand without `:SEGMENTS` (Šik & Křivánek's Fig. 1a).
const DEFAULT_SEGMENTS: u32 = 8;

#[derive(Debug, Clone, clap::Args)]
pub(crate) struct HairArgs {
    /// Grow a hair strand from every point: its length LEN in the mesh's
    /// unit along the surface normal, in SEGMENTS segments (default 8);
    /// -o then takes .usda or .usd (USD text: BasisCurves + the roots as
    /// Points), .glb/.gltf (LINES + root POINTS), .hair (Cem Yuksel's
    /// format) or .ply (the roots, with face, barycentrics, normal and id).
    #[arg(long, value_name = "LEN[:SEGMENTS]", allow_hyphen_values = true)]
    pub(crate) hair: Option<String>,
    /// With --hair: comb the strands toward the world direction X,Y,Z,
    /// tilted ANGLE degrees from the normal (e.g. 0,-1,0:40).
    #[arg(
        long,
        value_name = "X,Y,Z:ANGLE",
        requires = "hair",
        allow_hyphen_values = true
    )]
    pub(crate) hair_comb: Option<String>,
    /// With --hair: a curl of RADIUS (mesh units, at the tip) and TURNS
    /// turns over the strand.
    #[arg(
        long,
        value_name = "RADIUS:TURNS",
        requires = "hair",
        allow_hyphen_values = true
    )]
    pub(crate) hair_curl: Option<String>,
    /// With --hair: pull strands toward CENTRES clump centres (roots drawn
    /// from the seed), the tips AMOUNT (0 to 1) of the way.
    #[arg(
        long,
        value_name = "CENTRES:AMOUNT",
        requires = "hair",
        allow_hyphen_values = true
    )]
    pub(crate) hair_clumps: Option<String>,
    /// With --hair: each strand's length is LEN times this mesh-colours
    /// channel at its root (a painted length map of this mesh).
    #[arg(
        long,
        value_name = "FILE.meshcolors",
        requires = "hair",
        group = "hair_length"
    )]
    pub(crate) hair_length_meshcolors: Option<PathBuf>,
    /// With --hair: each strand's length is LEN times this texture (PNG,
    /// JPEG, HDR, EXR; values as stored) at its root's UV.
    #[arg(long, value_name = "IMAGE", requires = "hair", group = "hair_length")]
    pub(crate) hair_length_texture: Option<PathBuf>,
    /// Which value of --hair-length-meshcolors or --hair-length-texture
    /// scales the length (default: luminance).
    #[arg(long, value_enum, requires = "hair_length")]
    pub(crate) hair_length_channel: Option<ChannelArg>,
}

/// The strand shape the arguments ask for.
struct Spec {
    length: f32,
    segments: u32,
    comb: (glam::Vec3, f32),
    curl: (f32, f32),
    clumps: (usize, f32),
}

impl HairArgs {
    /// Whether `--hair` was given.
    pub(crate) fn on(&self) -> bool {
        self.hair.is_some()
    }

    /// The extensions `-o` takes.
    pub(crate) fn outputs(&self) -> &'static [&'static str] {
        if self.on() {
            OUTPUTS
        } else {
            &["ply", "glb", "gltf"]
        }
    }

    /// The parsed arguments, each error naming its argument as typed.
    fn spec(&self) -> Result<Spec> {
        let hair = self.hair.as_deref().unwrap_or_default();
        let typed = format!("--hair {hair}");
        let (len, segments) = match hair.split_once(':') {
            Some((l, s)) => (l, Some(s)),
            None => (hair, None),
        };
        let length: f32 = len
            .trim()
            .parse()
            .ok()
            .filter(|l: &f32| l.is_finite() && *l > 0.0)
            .ok_or_else(|| {
                arg_error(
                    &typed,
                    "the length must be a positive number in the mesh's unit (as in --hair 0.05 or --hair 0.05:8)",
                )
            })?;
        let segments = match segments {
            None => DEFAULT_SEGMENTS,
            Some(s) => s
                .trim()
                .parse::<u32>()
                .ok()
                .filter(|&k| (1..=mesh_sampling::MAX_SEGMENTS).contains(&k))
                .ok_or_else(|| {
                    arg_error(
                        &typed,
                        format!(
                            "SEGMENTS must be a whole number from 1 to {}",
                            mesh_sampling::MAX_SEGMENTS
                        ),
                    )
                })?,
        };
        let comb = match &self.hair_comb {
            None => (glam::Vec3::ZERO, 0.0),
            Some(c) => parse_comb(c)?,
        };
        let curl = match &self.hair_curl {
            None => (0.0, 0.0),
            Some(c) => {
                let typed = format!("--hair-curl {c}");
                let [radius, turns] = pair(c, &typed, "RADIUS:TURNS, as in 0.01:2")?;
                if radius < 0.0 {
                    return Err(arg_error(typed, "the radius must be >= 0"));
                }
                (radius, turns)
            }
        };
        let clumps = match &self.hair_clumps {
            None => (0, 0.0),
            Some(c) => {
                let typed = format!("--hair-clumps {c}");
                let [centres, amount] = pair(c, &typed, "CENTRES:AMOUNT, as in 1000:0.5")?;
                if !(centres >= 1.0 && centres.fract() == 0.0 && centres <= 1e8) {
                    return Err(arg_error(
                        typed,
                        "CENTRES must be a whole number from 1 to 100,000,000",
                    ));
                }
                if !(0.0..=1.0).contains(&amount) {
                    return Err(arg_error(typed, "AMOUNT must be from 0 to 1"));
                }
                (centres as usize, amount)
            }
        };
        Ok(Spec {
            length,
            segments,
            comb,
            curl,
            clumps,
        })
    }
}

/// `--hair LEN[:SEGMENTS]`'s LEN as typed, in `f64` (checked by
/// [`HairArgs::spec`] already).
fn typed_length(args: &HairArgs) -> Option<f64> {
    let hair = args.hair.as_deref()?;
    hair.split(':').next()?.trim().parse().ok()
}

/// `A:B` as two finite numbers.
fn pair(text: &str, typed: &str, expected: &str) -> Result<[f32; 2]> {
    let bad = || arg_error(typed, format!("expected {expected}"));
    let (a, b) = text.split_once(':').ok_or_else(bad)?;
    let number = |s: &str| s.trim().parse::<f32>().ok().filter(|v| v.is_finite());
    Ok([number(a).ok_or_else(bad)?, number(b).ok_or_else(bad)?])
}

/// `X,Y,Z:ANGLE` (degrees, 0 to 180) as a direction and radians.
fn parse_comb(text: &str) -> Result<(glam::Vec3, f32)> {
    let typed = format!("--hair-comb {text}");
    let bad = || {
        arg_error(
            &typed,
            "expected X,Y,Z:ANGLE (a direction and degrees from the normal, 0 to 180), as in 0,-1,0:40",
        )
    };
    let (dir, angle) = text.split_once(':').ok_or_else(bad)?;
    let v: Vec<f32> = dir
        .split(',')
        .map(|s| s.trim().parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| bad())?;
    let angle: f32 = angle.trim().parse().map_err(|_| bad())?;
    let [x, y, z] = v[..] else { return Err(bad()) };
    let direction = glam::Vec3::new(x, y, z);
    if !direction.is_finite() || direction == glam::Vec3::ZERO || !(0.0..=180.0).contains(&angle) {
        return Err(bad());
    }
    Ok((direction, angle.to_radians()))
}

/// `trilux sample … --hair`: grows the strands from the sampled `points`,
/// writes them to `-o` and reports.
pub(crate) fn run(
    context: &mut Context,
    sample: &super::sample::Args,
    mesh: &TriMesh,
    points: &[SurfacePoint],
    sampling: serde_json::Value,
) -> Result<()> {
    let args = &sample.hair;
    let spec = args.spec()?;
    let (files, strands, total) = grow_and_write(
        context,
        args,
        &spec,
        (mesh, &sample.mesh),
        points,
        (sample.seed, &sample.output, sample.ascii),
        sample.preview.as_deref(),
    )?;
    let written = files
        .iter()
        .map(|f| f.display().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let s = if strands == 1 { "" } else { "s" };
    // A PLY holds the roots only: say so rather than count curve points
    // the file does not have.
    let written = if super::extension(&sample.output) == "ply" {
        format!("; the {strands} root{s} written to {written} (PLY holds no curves)")
    } else {
        format!(" written to {written}")
    };
    let text = format!(
        "{strands} strand{s} of {} segments ({total} points) grown on {} ({} triangles){written}{}\n",
        spec.segments,
        sample.mesh.display(),
        mesh.indices.len(),
        sample
            .preview
            .as_ref()
            .map(|p| format!(", preview {}", p.display()))
            .unwrap_or_default()
    );
    let mut json = serde_json::json!({
        "command": "sample",
        "mesh": super::shown(&sample.mesh),
        "triangles": mesh.indices.len(),
        "points": points.len(),
        "strands": strands,
        "segments": spec.segments,
        "strand_points": total,
        // The length as typed (f64), not its f32 with its rounding noise.
        "length": typed_length(args),
        "output": super::shown(&sample.output),
        "files": files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    // The sampling's own fields (method, rate, seed, …), as plain
    // `sample --json` prints them.
    if let (Some(json), serde_json::Value::Object(fields)) = (json.as_object_mut(), sampling) {
        json.extend(fields);
    }
    context.report(&text, json);
    Ok(())
}

/// Grows the strands from `points` and writes them to `output`; returns
/// the files written and the strands' count and points.
fn grow_and_write(
    context: &mut Context,
    args: &HairArgs,
    spec: &Spec,
    (mesh, mesh_path): (&TriMesh, &Path),
    points: &[SurfacePoint],
    (seed, output, ascii): (u64, &Path, bool),
    preview: Option<&Path>,
) -> Result<(Vec<PathBuf>, usize, usize)> {
    let scale = length_scale(context, args, mesh, mesh_path, points)?;
    let options = HairOptions {
        segments: spec.segments,
        seed,
        clumps: spec.clumps.0,
        widths: true,
    };
    let strands = context.step("growing the strands", || {
        grow_strands_with(points, &options, |i, _| {
            let length = spec.length * scale.as_ref().map_or(1.0, |s| s[i]);
            StrandParams {
                comb: spec.comb.0,
                comb_angle: spec.comb.1,
                curl_radius: spec.curl.0,
                curl_turns: spec.curl.1,
                clump: spec.clumps.1,
                ..StrandParams::straight(length)
            }
        })
    })?;
    let (count, total) = (strands.len(), strands.points.len());
    // Drawn before `write` takes the strands, written after the strands
    // (as `sample` writes its preview after the points).
    let image = preview.map(|_| {
        context.step("rendering the preview", || {
            super::ops::sample::strands_preview(mesh, points, &strands, 768, 768)
        })
    });
    let files = write(context, strands, mesh, points, (output, ascii))?;
    if let (Some(path), Some(image)) = (preview, image) {
        super::write_image(context, path, &image)?;
    }
    Ok((files, count, total))
}

/// Per-root length factors from `--hair-length-meshcolors` (clamped to
/// be >= 0), or `None`.
fn length_scale(
    context: &mut Context,
    args: &HairArgs,
    mesh: &TriMesh,
    mesh_path: &Path,
    points: &[SurfacePoint],
) -> Result<Option<Vec<f32>>> {
    let channel = args.hair_length_channel.unwrap_or(ChannelArg::Luminance);
    if let Some(path) = &args.hair_length_texture {
        return texture_scale(context, (path, channel), mesh, mesh_path, points).map(Some);
    }
    let Some(path) = &args.hair_length_meshcolors else {
        return Ok(None);
    };
    let (_, colors) = super::ops::colors::load_for(mesh, mesh_path, path)?;
    let c = colors.channels();
    let lookups: Vec<(u32, [f32; 3])> = points.iter().map(|p| (p.face, p.barycentric)).collect();
    let mut values = vec![0.0f32; lookups.len() * c];
    context
        .step("reading the length channel", || {
            colors.linear_into(&lookups, &mut values)
        })
        .map_err(|e| file_cause(path, e))?;
    let pick = |v: &[f32]| -> Option<f32> {
        match channel {
            ChannelArg::Luminance if c >= 3 => Some(mesh_sampling::luminance([v[0], v[1], v[2]])),
            ChannelArg::Luminance => v.first().copied(),
            other => {
                let i = match other {
                    ChannelArg::R => 0,
                    ChannelArg::G => 1,
                    ChannelArg::B => 2,
                    _ => 3,
                };
                v.get(i).copied()
            }
        }
    };
    values
        .chunks_exact(c)
        .map(|v| {
            pick(v)
                .map(|x| if x.is_finite() { x.max(0.0) } else { 0.0 })
                .ok_or_else(|| {
                    arg_error(
                        format!("--hair-length-channel {}", channel.name()),
                        format!("{} has {c} channel(s)", path.display()),
                    )
                })
        })
        .collect::<Result<Vec<f32>>>()
        .map(Some)
}

/// Per-root length factors from `--hair-length-texture`: the texture's
/// `channel` (bilinear, wrapped as the mesh's first material says) at
/// each root's UV, clamped to be >= 0.
fn texture_scale(
    context: &mut Context,
    (path, channel): (&Path, ChannelArg),
    mesh: &TriMesh,
    mesh_path: &Path,
    points: &[SurfacePoint],
) -> Result<Vec<f32>> {
    let image = super::read_image(context, path, true)?;
    if mesh.uvs.is_none() {
        return Err(super::file_error(
            mesh_path,
            "--hair-length-texture is looked up at texture coordinates, and the mesh has none \
             (use --hair-length-meshcolors)",
        ));
    }
    let wrap = mesh
        .materials
        .first()
        .map_or(mesh_sampling::Wrap::Repeat, |m| {
            trilux::sampling_wrap(m.wrap[0])
        });
    let texture = trilux::density_texture(&image, channel.channel())
        .map_err(|e| file_cause(path, e))?
        .with_wrap(wrap);
    Ok(points
        .iter()
        .map(|p| {
            let uv = p.uv.unwrap_or_default().as_dvec2();
            let v = texture.eval(uv) as f32;
            if v.is_finite() { v.max(0.0) } else { 0.0 }
        })
        .collect())
}

/// The strands as the file `output` names.
fn write(
    context: &mut Context,
    strands: Strands,
    mesh: &TriMesh,
    points: &[SurfacePoint],
    (output, ascii): (&Path, bool),
) -> Result<Vec<PathBuf>> {
    let force = context.force;
    let ext = super::extension(output);
    if ext == "ply" {
        let cloud = roots_cloud(mesh, points);
        let format = if ascii {
            ply::Format::Ascii
        } else {
            ply::Format::BinaryLittleEndian
        };
        context.step("writing the roots (PLY)", || {
            trilux::output::write_atomic(output, force, |tmp| Ok(ply::write(tmp, &cloud, format)?))
        })?;
        return Ok(vec![output.to_path_buf()]);
    }
    let curves = context.step("building the curves", || {
        trilux::hair::into_curves(strands, mesh.origin)
    });
    if ext == "glb" || ext == "gltf" {
        return context.step("writing the glTF file", || {
            trilux::output::write_gltf(output, force, |tmp| curves::write_gltf(tmp, &curves))
        });
    }
    context.step(&format!("writing the .{ext} file"), || {
        trilux::output::write_atomic(output, force, |tmp| {
            match ext.as_str() {
                // `.usd` may hold text or binary (crate) USD; Blender and
                // Houdini read either, so text is written for both.
                "usda" | "usd" => {
                    curves::usda::write(tmp, &curves, &curves::usda::Stage::default())?
                }
                _ => curves::hair::write(tmp, &curves)?,
            }
            Ok(())
        })
    })?;
    Ok(vec![output.to_path_buf()])
}

/// The roots as a PLY point cloud: normals, UVs and `face_id` as
/// `trilux::point_cloud` writes them, plus the barycentrics `bary0..2`
/// and the strand's index as the integer property `id`.
fn roots_cloud(mesh: &TriMesh, points: &[SurfacePoint]) -> ply::PlyData {
    let mut cloud = trilux::point_cloud(mesh, points);
    for k in 0..3 {
        cloud.scalars.push((
            format!("bary{k}"),
            points.iter().map(|p| p.barycentric[k]).collect(),
        ));
    }
    // Strand indices as `uint id` (u32: `sample` draws fewer than 2^32).
    cloud.ids = Some((0..points.len()).map(|i| i as u32).collect());
    cloud
}
