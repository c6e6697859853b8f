//! `trilux colors convert|bake|render`: textured meshes to mesh colours,
//! mesh colours to an atlas, and pictures of mesh colours.

use std::path::PathBuf;

use super::ops::colors::{Filter, convert_mesh, load_for, render_colors, render_colors_from};
use super::{Context, Result, arg_error, file_cause, file_error};

#[derive(Debug, clap::Subcommand)]
#[command(
    about = "Mesh colours: convert a textured mesh, bake an atlas, render",
    after_help = "Example:\n  trilux colors convert ../shared/data/meshes/spot.obj \\\n      --texture ../shared/data/textures/spot_texture.png -o spot.meshcolors\n  trilux colors render ../shared/data/meshes/spot.obj spot.meshcolors --filter mip -o spot.png"
)]
pub(crate) enum Command {
    Convert(ConvertArgs),
    Bake(BakeArgs),
    Render(RenderArgs),
}

#[derive(Debug, clap::Args)]
#[command(
    about = "Convert a textured mesh to mesh colours (.meshcolors); seams are welded and averaged",
    after_help = "Example:\n  trilux colors convert ../shared/data/meshes/spot.obj \\\n      --texture ../shared/data/textures/spot_texture.png -o spot.meshcolors"
)]
pub(crate) struct ConvertArgs {
    /// The mesh: .obj, .gltf, .glb or .ply, with UVs.
    pub(crate) mesh: PathBuf,
    /// The texture (default: each material's base colour texture).
    #[arg(long, value_name = "IMAGE")]
    pub(crate) texture: Option<PathBuf>,
    /// The highest face resolution, a power of two up to 1024.
    #[arg(long, value_name = "R", default_value_t = 256)]
    pub(crate) max_res: u32,
    /// At most this many samples (default: the textures' texel count).
    #[arg(long, value_name = "N")]
    pub(crate) budget: Option<usize>,
    /// The .meshcolors file to write.
    #[arg(short, long, value_name = "OUT.meshcolors")]
    pub(crate) output: PathBuf,
    /// Also render a picture of the mesh colours.
    #[arg(long, value_name = "OUT.png")]
    pub(crate) preview: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
#[command(
    about = "Bake mesh colours to a texture atlas: an OBJ with UVs, its .mtl and a PNG, or one glTF file with the atlas embedded",
    after_help = "Examples:\n  trilux colors bake ../shared/data/meshes/spot.obj spot.meshcolors -o spot_atlas.obj\n  trilux colors bake ../shared/data/meshes/spot.obj spot.meshcolors -o spot_atlas.glb"
)]
pub(crate) struct BakeArgs {
    /// The mesh the colours were made for.
    pub(crate) mesh: PathBuf,
    /// The mesh colours.
    pub(crate) colors: PathBuf,
    /// The mesh to write: .obj (the atlas goes beside it as NAME_0.png
    /// and NAME.mtl), .glb (one file, the atlas embedded) or .gltf (with
    /// NAME.bin beside it, the atlas inside).
    #[arg(short, long, value_name = "OUT.obj")]
    pub(crate) output: PathBuf,
    /// MIP-safe packing for this many MIP levels (0: compact packing).
    #[arg(long, value_name = "LEVELS", default_value_t = 0)]
    pub(crate) mip: u32,
    /// Texels of padding around each block.
    #[arg(long, default_value_t = 2)]
    pub(crate) gutter: u32,
}

#[derive(Debug, clap::Args)]
#[command(
    about = "Render mesh colours on their mesh to a PNG (8-bit sRGB) or EXR (linear)",
    after_help = "Example:\n  trilux colors render ../shared/data/meshes/spot.obj spot.meshcolors --filter mip -o spot.png"
)]
pub(crate) struct RenderArgs {
    /// The mesh the colours were made for.
    pub(crate) mesh: PathBuf,
    /// The mesh colours.
    pub(crate) colors: PathBuf,
    /// How colours are filtered per pixel.
    #[arg(long, value_enum, default_value_t = Filter::Linear)]
    pub(crate) filter: Filter,
    #[command(flatten)]
    pub(crate) picture: super::args::PictureArgs,
    /// The picture: .png or .exr.
    #[arg(short, long, value_name = "OUT.png")]
    pub(crate) output: PathBuf,
}

pub(crate) fn run(context: &mut Context, command: Command) -> Result<()> {
    match command {
        Command::Convert(args) => convert(context, args),
        Command::Bake(args) => bake(context, args),
        Command::Render(args) => render(context, args),
    }
}

fn convert(context: &mut Context, args: ConvertArgs) -> Result<()> {
    check_convert(context, &args)?;
    let mesh = super::read_mesh(context, &args.mesh)?;
    if mesh.uvs.is_none() {
        return Err(file_error(
            &args.mesh,
            "the mesh has no texture coordinates, so there is no texture to convert",
        ));
    }
    let texture = match &args.texture {
        Some(p) => Some(super::read_image(context, p, false)?),
        None => None,
    };
    let options = trilux::ConvertOptions {
        max_level: args.max_res.trailing_zeros() as u8,
        max_samples: args.budget,
        ..Default::default()
    };
    let (surface, colors, psnr) = convert_mesh(context, &mesh, texture.as_ref(), &options)
        .map_err(|e| match e {
            trilux::Error::MissingTexture => file_error(
                &args.mesh,
                "the mesh's materials have no texture (give one with --texture IMAGE)",
            ),
            other => super::at(args.mesh.display(), other),
        })?;
    let force = context.force;
    context.step("writing the mesh colours", || {
        trilux::output::write_atomic(&args.output, force, |tmp| {
            mesh_colors::file::save(tmp, &colors, None).map_err(|e| file_cause(&args.output, e))
        })
    })?;
    if let Some(p) = &args.preview {
        let image = context.step("rendering the preview", || {
            render_colors(&surface, &colors, Filter::Linear, 768)
        });
        super::write_image(context, p, &image)?;
    }
    let (text, json) = convert_summary(context, &args, (&surface, &colors), psnr);
    context.report(&text, json);
    Ok(())
}

/// The arguments' own checks, before any file is read.
fn check_convert(context: &Context, args: &ConvertArgs) -> Result<()> {
    if !args.max_res.is_power_of_two() || args.max_res > 1 << mesh_colors::MAX_LEVEL {
        return Err(arg_error(
            format!("--max-res {}", args.max_res),
            format!(
                "the face resolution must be a power of two from 1 to {}",
                1 << mesh_colors::MAX_LEVEL
            ),
        ));
    }
    if args.budget == Some(0) {
        return Err(arg_error("--budget 0", "at least one sample is needed"));
    }
    super::check_output(context, "-o", &args.output, &["meshcolors"])?;
    if let Some(p) = &args.preview {
        super::check_output(context, "--preview", p, &["png", "exr"])?;
    }
    Ok(())
}

/// What `colors convert` reports: counts, resolutions, welding, PSNR.
fn convert_summary(
    context: &Context,
    args: &ConvertArgs,
    (surface, colors): (&trilux::ColorMesh, &mesh_colors::MeshColors),
    psnr: f64,
) -> (String, serde_json::Value) {
    let (lo, hi) = (0..colors.face_count())
        .filter_map(|f| colors.face_resolution(f))
        .fold((u32::MAX, 0), |(a, b), r| (a.min(r), b.max(r)));
    let text = format!(
        "{} faces, {} samples (face resolutions {lo}..{hi}), {} vertices after welding{}; PSNR against the texture {psnr:.2} dB; written to {}\n",
        colors.face_count(),
        colors.sample_count(),
        surface.positions.len(),
        if surface.detached > 0 {
            format!(
                " ({} faces kept apart: degenerate or on a non-manifold edge)",
                surface.detached
            )
        } else {
            String::new()
        },
        args.output.display()
    );
    let json = serde_json::json!({
        "command": "colors convert",
        "mesh": super::shown(&args.mesh),
        "faces": colors.face_count(),
        "samples": colors.sample_count(),
        "vertices": surface.positions.len(),
        "detached_faces": surface.detached,
        "resolution": [lo, hi],
        "psnr_db": super::round(psnr, 3),
        "output": super::shown(&args.output),
        "seconds": context.timings_json(),
    });
    (text, json)
}

fn bake(context: &mut Context, args: BakeArgs) -> Result<()> {
    super::check_output(context, "-o", &args.output, &["obj", "glb", "gltf"])?;
    let mesh = super::read_mesh(context, &args.mesh)?;
    let (surface, colors) = context.step("reading the mesh colours", || {
        load_for(&mesh, &args.mesh, &args.colors)
    })?;
    let atlas = context
        .step("baking the atlas", || {
            mesh_colors::atlas::bake(
                &colors,
                &mesh_colors::atlas::Options {
                    gutter: args.gutter,
                    mip_levels: args.mip,
                },
            )
        })
        .map_err(|e| super::at(args.colors.display(), e))?;
    // No texture file named: the OBJ writer writes the atlas image
    // beside the .obj and .mtl as NAME_0.png; the glTF writer embeds
    // it as a PNG.
    let (baked, image) = trilux::atlas_mesh(&surface, &atlas, None);
    let force = context.force;
    let files = if super::extension(&args.output) == "obj" {
        context.step("writing OBJ, MTL and PNG", || {
            trilux::output::write_atomic_files(&args.output, force, |tmp| Ok(baked.write(tmp)?))
        })?
    } else {
        context.step("writing glTF", || {
            trilux::output::write_gltf(&args.output, force, |tmp| baked.write(tmp))
        })?
    };
    let text = format!(
        "{} faces baked to a {}×{} atlas{}: {}\n",
        colors.face_count(),
        image.width,
        image.height,
        if args.mip > 0 {
            format!(" (MIP-safe for {} levels)", args.mip)
        } else {
            String::new()
        },
        files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let json = serde_json::json!({
        "command": "colors bake",
        "faces": colors.face_count(),
        "atlas": [image.width, image.height],
        "mip_levels": args.mip,
        "output": super::shown(&args.output),
        "files": files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
}

fn render(context: &mut Context, args: RenderArgs) -> Result<()> {
    super::check_output(context, "-o", &args.output, &["png", "exr"])?;
    let (size, view) = (args.picture.size, args.picture.direction());
    let mesh = super::read_mesh(context, &args.mesh)?;
    let (surface, colors) = context.step("reading the mesh colours", || {
        load_for(&mesh, &args.mesh, &args.colors)
    })?;
    let image = context.step("rendering", || {
        render_colors_from(&surface, &colors, args.filter, size, view)
    });
    super::write_image(context, &args.output, &image)?;
    let text = format!(
        "{}×{} picture of {} written to {}\n",
        image.width,
        image.height,
        args.colors.display(),
        args.output.display()
    );
    let json = serde_json::json!({
        "command": "colors render",
        "size": [image.width, image.height],
        "filter": format!("{:?}", args.filter).to_lowercase(),
        "output": super::shown(&args.output),
        "seconds": context.timings_json(),
    });
    context.report(&text, json);
    Ok(())
}
