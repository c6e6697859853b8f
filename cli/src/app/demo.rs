//! `trilux demo`: every pipeline on built-in data, with a preview each.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mesh_sampling::Channel;
use trilux::shapes;
use trilux_io::mesh::TriMesh;

use super::ops::sample::{Method, Source, draw};
use super::{Context, Result};

/// `--size` of the previews: 1 to 4096 pixels.
fn preview_size(text: &str) -> std::result::Result<u32, String> {
    super::args::pixels(text, 4096)
}

#[derive(Debug, clap::Args)]
#[command(
    about = "Run every pipeline on built-in data (meshes and images made in code), writing outputs and a preview of each",
    after_help = "Example:\n  trilux demo --out trilux-demo\n  (re-run into the same folder with --force)"
)]
pub(crate) struct Args {
    /// The folder to write into (created if missing).
    #[arg(long, default_value = "trilux-demo")]
    pub(crate) out: PathBuf,
    /// Preview size in pixels.
    #[arg(long, default_value_t = 512, value_parser = preview_size)]
    pub(crate) size: u32,
}

/// One pipeline's result for the summary.
struct Done {
    name: &'static str,
    what: String,
    seconds: f64,
    files: Vec<PathBuf>,
}

struct Demo<'a> {
    context: &'a mut Context,
    out: PathBuf,
    size: u32,
    done: Vec<Done>,
}

impl Demo<'_> {
    fn path(&self, name: &str) -> PathBuf {
        self.out.join(name)
    }

    fn write_mesh(&self, name: &str, mesh: &TriMesh) -> Result<PathBuf> {
        let path = self.path(name);
        trilux::output::write_atomic_files(&path, self.context.force, |tmp| Ok(mesh.write(tmp)?))?;
        Ok(path)
    }

    fn write_image(&self, name: &str, image: &trilux_io::image::Image) -> Result<PathBuf> {
        let path = self.path(name);
        super::write_image(self.context, &path, image)?;
        Ok(path)
    }

    fn write_points(
        &self,
        name: &str,
        mesh: &TriMesh,
        points: &[mesh_sampling::SurfacePoint],
    ) -> Result<PathBuf> {
        let path = self.path(name);
        let cloud = trilux::point_cloud(mesh, points);
        trilux::output::write_atomic(&path, self.context.force, |tmp| {
            Ok(trilux_io::mesh::ply::write(
                tmp,
                &cloud,
                trilux_io::mesh::ply::Format::BinaryLittleEndian,
            )?)
        })?;
        Ok(path)
    }

    /// Runs one pipeline under a spinner and records it.
    fn run(
        &mut self,
        name: &'static str,
        f: impl FnOnce(&Self) -> Result<(String, Vec<PathBuf>)>,
    ) -> Result<()> {
        let bar = self.context.spinner(name);
        let start = Instant::now();
        let result = f(self);
        bar.finish_and_clear();
        let (what, files) = result.map_err(|e| super::at(format!("demo pipeline {name}"), e))?;
        self.done.push(Done {
            name,
            what,
            seconds: start.elapsed().as_secs_f64(),
            files,
        });
        Ok(())
    }
}

/// The points pipeline: sample, write PLY and a preview.
fn points_pipeline(
    demo: &Demo<'_>,
    stem: &str,
    mesh: &TriMesh,
    source: &Source,
    method: Method,
    n: usize,
) -> Result<Vec<PathBuf>> {
    let points = draw(mesh, source, method, 1, n)?;
    let ply = demo.write_points(&format!("{stem}.ply"), mesh, &points)?;
    let png = demo.write_image(
        &format!("{stem}.png"),
        &super::ops::sample::preview(mesh, &points, demo.size, demo.size),
    )?;
    Ok(vec![ply, png])
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    prepare(context, &args.out)?;
    let start = Instant::now();
    let mut demo = Demo {
        context,
        out: args.out.clone(),
        size: args.size,
        done: Vec::new(),
    };
    let inputs = Inputs::new()?;
    let pipelines: [(&'static str, PipelineFn); 7] = [
        ("inputs", write_inputs),
        ("uniform", uniform),
        ("density", density),
        ("sky", sky),
        ("colors", colors),
        ("colors-density", colors_density),
        ("translucent", translucent),
    ];
    for (name, pipeline) in pipelines {
        demo.run(name, |d| pipeline(d, &inputs))?;
    }
    summary(demo, start.elapsed().as_secs_f64());
    Ok(())
}

/// Creates the folder `out`, which must be empty unless `--force`.
fn prepare(context: &Context, out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(super::file_error(
            out,
            "a file, not a folder (--out names the folder to write into)",
        ));
    }
    std::fs::create_dir_all(out).map_err(|source| trilux::Error::File {
        path: out.to_path_buf(),
        source,
    })?;
    if !context.force
        && std::fs::read_dir(out)
            .map(|mut d| d.next().is_some())
            .unwrap_or(false)
    {
        return Err(super::file_error(
            out,
            "the folder is not empty; pass --force to overwrite the demo's files in it, or choose another folder",
        ));
    }
    Ok(())
}

/// The built-in meshes and images the pipelines run on.
struct Inputs {
    blob: TriMesh,
    torus: TriMesh,
    sphere: TriMesh,
    checker: trilux_io::image::Image,
    noise: trilux_io::image::Image,
    sky: trilux_io::image::Image,
}

impl Inputs {
    fn new() -> Result<Inputs> {
        let sphere = {
            let ico = shapes::icosphere(5);
            let (positions, uvs, indices) =
                mesh_sampling::spherical_uvs(&ico.positions, &ico.indices)?;
            TriMesh {
                normals: Some(positions.iter().map(|p| p.normalize()).collect()),
                positions,
                uvs: Some(uvs),
                indices,
                objects: ico.objects,
                ..TriMesh::default()
            }
        };
        Ok(Inputs {
            blob: shapes::blob(5),
            torus: shapes::torus(128, 64),
            sphere,
            checker: shapes::checkerboard(512, 512, 8),
            noise: shapes::noise(256, 256, 7),
            sky: shapes::sky(512, 256),
        })
    }
}

/// What a pipeline did and the files it wrote.
type Pipeline = Result<(String, Vec<PathBuf>)>;

/// One pipeline on the built-in inputs.
type PipelineFn = fn(&Demo<'_>, &Inputs) -> Pipeline;

/// The built-in inputs, written too so that every command can be re-run on them.
fn write_inputs(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let files = vec![
        d.write_mesh("blob.obj", &i.blob)?,
        d.write_mesh("torus.obj", &i.torus)?,
        d.write_mesh("sphere.obj", &i.sphere)?,
        d.write_image("checkerboard.png", &i.checker)?,
        d.write_image("noise.png", &i.noise)?,
        d.write_image("sky.exr", &i.sky)?,
    ];
    Ok((
        "built-in meshes (blob, torus, UV sphere) and images (checkerboard, noise, HDR sky)".into(),
        files,
    ))
}

/// Points uniform by area on the blob.
fn uniform(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let n = 200_000;
    let files = points_pipeline(
        d,
        "blob_uniform",
        &i.blob,
        &Source::Uniform,
        Method::Uniform,
        n,
    )?;
    Ok((format!("{n} points uniform by area on the blob"), files))
}

/// Points on the torus by the noise texture (subdivision).
fn density(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let n = 200_000;
    let density = trilux::density_texture(&i.noise, Channel::Luminance)?;
    let files = points_pipeline(
        d,
        "torus_noise",
        &i.torus,
        &Source::Texture(density),
        Method::Subdivision,
        n,
    )?;
    Ok((
        format!("{n} points on the torus, density = noise texture (subdivision)"),
        files,
    ))
}

/// Points on a sphere by the HDR sky's luminance (exact).
fn sky(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let n = 100_000;
    let density = trilux::density_texture(&i.sky, Channel::Luminance)?;
    let files = points_pipeline(
        d,
        "sphere_sky",
        &i.sphere,
        &Source::Texture(density),
        Method::Exact,
        n,
    )?;
    Ok((
        format!("{n} points on a sphere by the HDR sky's luminance (exact)"),
        files,
    ))
}

/// The checkerboard torus to mesh colours, an atlas and a MIP-filtered render.
fn colors(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let mut quiet = Context {
        json: false,
        force: d.context.force,
        progress: false,
        timings: Vec::new(),
    };
    let (surface, colors, psnr) = super::ops::colors::convert_mesh(
        &mut quiet,
        &i.torus,
        Some(&i.checker),
        &Default::default(),
    )?;
    let file = d.path("torus.meshcolors");
    trilux::output::write_atomic(&file, d.context.force, |tmp| {
        mesh_colors::file::save(tmp, &colors, None).map_err(|e| super::file_cause(&file, e))
    })?;
    let atlas = mesh_colors::atlas::bake(&colors, &Default::default())?;
    let (baked, _) = trilux::atlas_mesh(&surface, &atlas, None);
    let mut files = vec![file];
    files.extend(trilux::output::write_atomic_files(
        &d.path("torus_atlas.obj"),
        d.context.force,
        |tmp| Ok(baked.write(tmp)?),
    )?);
    files.push(d.write_image(
        "torus_colors.png",
        &super::ops::colors::render_colors(
            &surface,
            &colors,
            super::ops::colors::Filter::Mip,
            d.size,
        ),
    )?);
    let what = format!(
        "checkerboard torus → {} mesh colours ({psnr:.1} dB) → {}×{} atlas OBJ; MIP-filtered render",
        colors.sample_count(),
        atlas.texture.width(),
        atlas.texture.height()
    );
    Ok((what, files))
}

/// Points on the torus by its mesh colours' luminance.
fn colors_density(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    let n = 200_000;
    let file = d.path("torus.meshcolors");
    let source = super::ops::sample::meshcolors_source(
        &i.torus,
        &d.path("torus.obj"),
        &file,
        Channel::Luminance,
    )?;
    let files = points_pipeline(
        d,
        "torus_colors_points",
        &i.torus,
        &source,
        Method::Subdivision,
        n,
    )?;
    Ok((
        format!("{n} points on the torus, density = its mesh colours' luminance"),
        files,
    ))
}

/// The blob stuffed, then TransCut's diffusion in marble, cut open.
fn translucent(d: &Demo<'_>, i: &Inputs) -> Pipeline {
    // The blob stuffed (isosurface stuffing), then TransCut's diffusion
    // in marble, lit from the upper front and cut open to show the
    // light bleeding through the inside.
    let (stuffed, _) = super::ops::stuff::stuff(
        &i.blob,
        Path::new("blob.obj"),
        super::ops::stuff::Spacing::Given {
            h: Some(0.06),
            option: "--spacing",
        },
        true,
        false,
        None,
    )?;
    let tets = trilux::tet::from_stuffing(&stuffed, i.blob.origin);
    let files = trilux::output::write_atomic_files(&d.path("blob.node"), d.context.force, |tmp| {
        Ok(trilux_io::tet::write(tmp, &tets)?)
    })?;
    let solver = |e: tet_diffusion::Error| super::placed("diffusion on the stuffed blob", false, e);
    let mesh = tet_diffusion::TetMesh::new(&tets.positions, &tets.tets).map_err(solver)?;
    let marble = tet_diffusion::Medium::measured("marble").map_err(solver)?;
    let media = vec![marble; mesh.tets().len()];
    // The blob is about 2 units across: 20 mm per unit makes a 4 cm
    // stone, small enough for marble to glow through.
    let mut object = tet_diffusion::Object::new(mesh, 20.0, media, 1.3).map_err(solver)?;
    let light = tet_diffusion::Light::Directional {
        to_light: glam::DVec3::new(0.3, 1.0, 0.6),
        irradiance: [1.0; 3],
    };
    object.add_light(light.clone()).map_err(solver)?;
    object
        .cut(
            &tet_diffusion::Cut::Plane {
                point: glam::DVec3::new(0.0, 0.0, 0.35),
                normal: glam::DVec3::Z,
            },
            tet_diffusion::CutMethod::Exact,
        )
        .map_err(solver)?;
    let report = object.solve().map_err(solver)?;
    let image = trilux::tet::render(std::slice::from_ref(&object), &[light], d.size, None);
    let mut files = files;
    files.push(d.write_image("blob_marble.png", &trilux::tet::tone_map(&image))?);
    let r = &stuffed.report;
    Ok((
        format!(
            "blob stuffed into {} tetrahedra (dihedral {:.1}°..{:.1}°), cut open, marble diffusion solved by {} ({} level{})",
            r.tets,
            r.min_dihedral_deg,
            r.max_dihedral_deg,
            report.choice.solver,
            report.levels,
            if report.levels == 1 { "" } else { "s" }
        ),
        files,
    ))
}

/// The table of pipelines, or the JSON object.
fn summary(demo: Demo<'_>, total: f64) {
    let Demo {
        context, done, out, ..
    } = demo;
    let mut text = format!(
        "trilux demo: {} pipelines in {total:.1} s, written to {}\n\n",
        done.len(),
        out.display()
    );
    text.push_str("| pipeline | what | seconds | files |\n|---|---|---|---|\n");
    for d in &done {
        text.push_str(&format!(
            "| {} | {} | {:.2} | {} |\n",
            d.name,
            d.what,
            d.seconds,
            d.files
                .iter()
                .map(|f| file_name(f))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    let json = serde_json::json!({
        "command": "demo",
        "out": super::shown(&out),
        "seconds": super::round(total, 3),
        "pipelines": done.iter().map(|d| serde_json::json!({
            "name": d.name, "what": d.what, "seconds": super::round(d.seconds, 3),
            "files": d.files.iter().map(|f| super::shown(f)).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
    });
    context.report(&text, json);
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
