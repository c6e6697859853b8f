//! `trilux bench sampling|colors`: the measurements behind the crates'
//! claims, as Markdown tables (or JSON) and PNG plots. Speeds are ratios
//! against a baseline in the same run; times are medians.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::ValueEnum;
use mesh_sampling::{
    Channel, Density, DensitySampler, Mode, RejectionSampler, SurfaceSampler, UniformSampler,
};
use serde_json::{Value, json};
use trilux_io::mesh::TriMesh;

use super::ops::colors::psnr_against;
use super::ops::plot::{Series, line_plot};
use super::{Context, Result, invalid};

#[derive(Debug, clap::Args)]
#[command(
    about = "Measure the samplers or mesh colours (Markdown tables, PNG plots); run with --release",
    after_help = "Example:\n  TRILUX_DATA=../shared/data cargo run --release -p trilux -- bench sampling --plots plots\n  (without TRILUX_DATA, built-in meshes and textures are used)"
)]
pub(crate) struct Args {
    /// What to measure.
    #[arg(value_enum)]
    pub(crate) what: What,
    /// Write PNG plots into this folder.
    #[arg(long, value_name = "DIR")]
    pub(crate) plots: Option<PathBuf>,
    /// Points for the command-line overhead measurement (sampling).
    #[arg(long, default_value_t = 10_000_000)]
    pub(crate) points: usize,
    /// Repetitions per timing (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub(crate) repeats: usize,
    /// The data folder (default: $TRILUX_DATA; built-in data without it).
    #[arg(long, value_name = "DIR")]
    pub(crate) data: Option<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum What {
    Sampling,
    Colors,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median seconds of `repeats` runs of `f`.
fn time<T>(repeats: usize, mut f: impl FnMut() -> T) -> f64 {
    median(
        (0..repeats.max(1))
            .map(|_| {
                let start = Instant::now();
                std::hint::black_box(f());
                start.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

pub(crate) fn run(context: &mut Context, args: Args) -> Result<()> {
    if args.repeats == 0 {
        return Err(super::arg_error(
            "--repeats 0",
            "at least one repetition is needed",
        ));
    }
    if let Some(dir) = &args.plots {
        std::fs::create_dir_all(dir).map_err(|source| trilux::Error::File {
            path: dir.clone(),
            source,
        })?;
    }
    let data = args
        .data
        .clone()
        .or_else(|| std::env::var_os("TRILUX_DATA").map(PathBuf::from));
    if cfg!(debug_assertions) && !context.json {
        eprintln!("note: this is a debug build; run with --release for meaningful timings");
    }
    match args.what {
        What::Sampling => sampling(context, &args, data.as_deref()),
        What::Colors => colors(context, &args, data.as_deref()),
    }
}

/// The bunny with a spherical UV projection (the paper maps its textures
/// the same way), or the built-in blob.
fn sampling_mesh(data: Option<&Path>) -> Result<(String, TriMesh, Option<PathBuf>)> {
    let (name, mesh, file) = match data {
        Some(d) => {
            let file = d.join("meshes/stanford-bunny.obj");
            (
                "stanford-bunny".to_string(),
                TriMesh::read(&file)?,
                Some(file),
            )
        }
        None => ("built-in blob".to_string(), trilux::shapes::blob(6), None),
    };
    let (positions, uvs, indices) = mesh_sampling::spherical_uvs(&mesh.positions, &mesh.indices)?;
    Ok((
        name,
        TriMesh {
            positions,
            uvs: Some(uvs),
            indices,
            ..TriMesh::default()
        },
        file,
    ))
}

/// What a benchmark collects: the Markdown table, the JSON rows and the
/// curves to plot.
#[derive(Default)]
struct Collected {
    table: String,
    rows: Vec<Value>,
    series: Vec<Series>,
}

fn sampling(context: &mut Context, args: &Args, data: Option<&Path>) -> Result<()> {
    let (name, mesh, file) = context.step("reading the mesh", || sampling_mesh(data))?;
    let mesh_ref = trilux::mesh_ref(&mesh);
    let noise = trilux::density_texture(&trilux::shapes::noise(512, 512, 3), Channel::Luminance)?;
    let sky_image = match data {
        Some(d) => trilux_io::image::read(d.join("hdr/spiaggia_di_mondello_1k.hdr"))?,
        None => trilux::shapes::sky(1024, 512),
    };
    let sky = trilux::density_texture(&sky_image, Channel::Luminance)?;
    let r = args.repeats;
    let mut out = Collected {
        table: format!(
            "## Sampling on {name} ({} triangles), medians of {r}\n\n| density | method | build (ms) | ns per point (10⁶ points) | speed-up vs rejection |\n|---|---|---|---|---|\n",
            mesh.indices.len()
        ),
        ..Collected::default()
    };
    for (density_name, texture) in [("noise 512²", &noise), ("HDR sky (peaky)", &sky)] {
        density_rows(context, r, mesh_ref, (density_name, texture), &mut out)?;
    }
    let per_uniform = uniform_row(r, mesh_ref, &mut out)?;

    // The command line against the library on the same job.
    let overhead = context.step("command line vs library", || {
        cli_overhead(args.points, file.as_deref())
    })?;
    out.table.push_str(&format!(
        "\n## `trilux sample` against the library ({} points, uniform, binary PLY, one run each)\n\n| | seconds |\n|---|---|\n| library: sampler + points + PLY write | {:.2} |\n| `trilux -q sample MESH -n N -o OUT.ply` (process, mesh read included) | {:.2} |\n| ratio | {:.2} |\n",
        args.points, overhead.0, overhead.1, overhead.1 / overhead.0
    ));
    let plots = plot(
        context,
        args,
        "sampling_time.png",
        &format!("Time to draw N points on {name} (noise density)"),
        (("points", "seconds"), (true, true)),
        &out.series,
    )?;
    let json = json!({"command": "bench sampling", "mesh": name, "triangles": mesh.indices.len(),
        "rows": out.rows, "uniform_ns_per_point": per_uniform * 1e9,
        "cli_vs_library": {"points": args.points, "library_s": overhead.0, "cli_s": overhead.1, "ratio": overhead.1 / overhead.0},
        "plots": plots});
    context.report(&out.table, json);
    Ok(())
}

/// The point counts of the sampling curves; the table's ns per point is
/// the last.
const SIZES: [usize; 3] = [10_000, 100_000, 1_000_000];

/// The rows of one density: subdivision, exact and rejection sampling.
fn density_rows(
    context: &mut Context,
    r: usize,
    mesh_ref: mesh_sampling::MeshRef<'_>,
    (density_name, texture): (&str, &mesh_sampling::DensityTexture),
    out: &mut Collected,
) -> Result<()> {
    let rejection = RejectionSampler::new(mesh_ref, texture)?;
    // Rejection's cost grows as 1 / acceptance: on a peaky map it is
    // measured on fewer points and scaled.
    let rejection_points = if rejection.acceptance() < 0.01 {
        10_000
    } else {
        1_000_000
    };
    let build_rej = time(r, || RejectionSampler::new(mesh_ref, texture).map(|_| ()));
    let per_rej = time(r, || rejection.sample_n(1, rejection_points)) / rejection_points as f64;
    let mut measure = |method: &str, build: f64, per_point: f64, curve: Vec<(f64, f64)>| {
        out.table.push_str(&format!(
            "| {density_name} | {method} | {:.1} | {:.1} | {:.1}× |\n",
            build * 1e3,
            per_point * 1e9,
            per_rej / per_point
        ));
        out.rows.push(json!({"density": density_name, "method": method, "build_ms": build * 1e3,
                         "ns_per_point": per_point * 1e9, "speedup_vs_rejection": per_rej / per_point}));
        if density_name.starts_with("noise") {
            out.series.push(Series {
                name: method.to_string(),
                points: curve,
            });
        }
    };
    for (method, mode) in [("subdivision", Mode::Approximate), ("exact", Mode::Exact)] {
        let options = mesh_sampling::Options {
            mode,
            ..Default::default()
        };
        let build = time(r, || {
            DensitySampler::with_options(mesh_ref, Density::Texture(texture), &options).map(|_| ())
        });
        let sampler = context.step(&format!("{density_name}: {method}"), || {
            DensitySampler::with_options(mesh_ref, Density::Texture(texture), &options)
        })?;
        let curve = curve(r, |n| sampler.sample_n(1, n));
        let per = curve[2].1 / SIZES[2] as f64;
        measure(method, build, per, curve);
    }
    let curve = if rejection_points == 1_000_000 {
        curve(r, |n| rejection.sample_n(1, n))
    } else {
        Vec::new()
    };
    measure(
        &format!("rejection (acceptance {:.4})", rejection.acceptance()),
        build_rej,
        per_rej,
        curve,
    );
    Ok(())
}

/// The uniform sampler's row and curve; returns its seconds per point.
fn uniform_row(r: usize, mesh_ref: mesh_sampling::MeshRef<'_>, out: &mut Collected) -> Result<f64> {
    let uniform = UniformSampler::new(mesh_ref)?;
    let per_uniform = time(r, || uniform.sample_n(1, 1_000_000)) / 1e6;
    out.table.push_str(&format!(
        "| none | uniform | {:.1} | {:.1} | — |\n",
        time(r, || UniformSampler::new(mesh_ref).map(|_| ())) * 1e3,
        per_uniform * 1e9
    ));
    out.series.push(Series {
        name: "uniform".into(),
        points: curve(r, |n| uniform.sample_n(1, n)),
    });
    Ok(per_uniform)
}

/// Median seconds of `draw(n)` at each of [`SIZES`].
fn curve<T>(r: usize, draw: impl Fn(usize) -> T) -> Vec<(f64, f64)> {
    SIZES
        .iter()
        .map(|&n| (n as f64, time(r, || draw(n))))
        .collect()
}

/// Draws `series` into `file_name` of `--plots` when it is given; returns
/// the paths written (none without `--plots` or without a font).
fn plot(
    context: &mut Context,
    args: &Args,
    file_name: &str,
    title: &str,
    (labels, log): ((&str, &str), (bool, bool)),
    series: &[Series],
) -> Result<Vec<String>> {
    let mut plots = Vec::new();
    if let Some(dir) = &args.plots {
        let path = dir.join(file_name);
        if line_plot(context, &path, title, labels, log, series)? {
            plots.push(super::shown(&path));
        } else {
            eprintln!("note: no font for plot labels was found; plots skipped");
        }
    }
    Ok(plots)
}

/// Seconds for the library (uniform sampler, `n` points, point cloud, PLY
/// write) and for the `trilux sample` process doing the same from the file.
fn cli_overhead(n: usize, file: Option<&Path>) -> Result<(f64, f64)> {
    let dir = std::env::temp_dir().join(format!("trilux-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|source| trilux::Error::File {
        path: dir.clone(),
        source,
    })?;
    let result = (|| {
        let file = match file {
            Some(f) => f.to_path_buf(),
            None => {
                let f = dir.join("blob.obj");
                trilux::shapes::blob(6).write(&f)?;
                f
            }
        };
        let mesh = TriMesh::read(&file)?;
        let out = dir.join("library.ply");
        let start = Instant::now();
        let points = UniformSampler::new(trilux::mesh_ref(&mesh))?.sample_n(0, n)?;
        let cloud = trilux::point_cloud(&mesh, &points);
        trilux_io::mesh::ply::write(
            &out,
            &cloud,
            trilux_io::mesh::ply::Format::BinaryLittleEndian,
        )?;
        let library = start.elapsed().as_secs_f64();
        drop((points, cloud));
        let exe = std::env::current_exe().map_err(|source| trilux::Error::File {
            path: "trilux".into(),
            source,
        })?;
        let start = Instant::now();
        let status = std::process::Command::new(exe)
            .args(["-q", "sample"])
            .arg(&file)
            .args(["-n", &n.to_string(), "--force", "-o"])
            .arg(dir.join("cli.ply"))
            .stdout(std::process::Stdio::null())
            .status()
            .map_err(|source| trilux::Error::File {
                path: "trilux".into(),
                source,
            })?;
        let cli = start.elapsed().as_secs_f64();
        if !status.success() {
            return Err(invalid(format!(
                "bench sampling: the `trilux sample` run on {} failed",
                file.display()
            )));
        }
        Ok((library, cli))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn colors(context: &mut Context, args: &Args, data: Option<&Path>) -> Result<()> {
    let (name, mesh, texture) = match data {
        Some(d) => (
            "spot".to_string(),
            TriMesh::read(d.join("meshes/spot.obj"))?,
            trilux_io::image::read(d.join("textures/spot_texture.png"))?,
        ),
        None => (
            "built-in torus".to_string(),
            trilux::shapes::torus(128, 64),
            trilux::shapes::noise(512, 512, 5),
        ),
    };
    let r = args.repeats;
    let mut out = Collected {
        table: format!(
            "## Mesh colours of {name} ({} triangles, {}×{} texture), medians of {r}\n\n| budget (× texels) | samples | convert (ms) | PSNR (dB) |\n|---|---|---|---|\n",
            mesh.indices.len(),
            texture.width,
            texture.height
        ),
        ..Collected::default()
    };
    let points = super::ops::colors::surface_points(&mesh, 200_000, 3)?;
    let colors = conversions(context, r, (&mesh, &texture), &points, &mut out)?;
    let lookup_ns = lookups(r, (&mesh, &texture), &points, &colors, &mut out.table)?;
    let plots = plot(
        context,
        args,
        "colors_psnr.png",
        &format!("Mesh colours of {name}: PSNR against the texture"),
        (("samples", "PSNR (dB)"), (true, false)),
        &out.series,
    )?;
    let json = json!({"command": "bench colors", "mesh": name, "conversions": out.rows,
        "lookup_ns": lookup_ns,
        "plots": plots});
    context.report(&out.table, json);
    Ok(())
}

/// Converts at budgets of 1/16 to 2 × the texels, each row timed and
/// measured (PSNR at `points`); returns the mesh colours at the texel
/// budget.
fn conversions(
    context: &mut Context,
    r: usize,
    (mesh, texture): (&TriMesh, &trilux_io::image::Image),
    points: &[(u32, [f32; 3])],
    out: &mut Collected,
) -> Result<mesh_colors::MeshColors> {
    let texels = (texture.width * texture.height) as usize;
    let mut curve = Vec::new();
    let source = trilux::SurfaceTexture::new(mesh, Some(texture))?;
    let mut finest = None;
    for fraction in [0.0625, 0.125, 0.25, 0.5, 1.0, 2.0] {
        let options = trilux::ConvertOptions {
            max_samples: Some(((texels as f64) * fraction) as usize),
            density: fraction.max(1.0),
            max_level: 10,
        };
        let seconds = time(r.min(3), || {
            trilux::to_mesh_colors(mesh, Some(texture), &options).map(|_| ())
        });
        let (_surface, colors) = context
            .step(&format!("converting at {fraction}× texels"), || {
                trilux::to_mesh_colors(mesh, Some(texture), &options)
            })?;
        let psnr = psnr_against(points, &source, &colors);
        out.table.push_str(&format!(
            "| {fraction} | {} | {:.1} | {psnr:.2} |\n",
            colors.sample_count(),
            seconds * 1e3
        ));
        out.rows.push(json!({"budget_fraction": fraction, "samples": colors.sample_count(), "convert_ms": seconds * 1e3, "psnr_db": psnr}));
        curve.push((colors.sample_count() as f64, psnr));
        if fraction == 1.0 {
            finest = Some(colors);
        }
    }
    out.series.push(Series {
        name: "linear filter".into(),
        points: curve,
    });
    finest.ok_or_else(|| invalid("bench colors: no conversion was made at the texel budget"))
}

/// Lookups: mesh colours (linear, trilinear MIP) against the texture's
/// bilinear filter at the same surface points; appends their table and
/// returns the nanoseconds per lookup as JSON.
fn lookups(
    r: usize,
    (mesh, texture): (&TriMesh, &trilux_io::image::Image),
    points: &[(u32, [f32; 3])],
    colors: &mesh_colors::MeshColors,
    table: &mut String,
) -> Result<Value> {
    let n = points.len();
    let tex = trilux::colors::texture(texture)?;
    let uvs = mesh
        .uvs
        .as_ref()
        .ok_or_else(|| invalid("bench colors: the mesh has no texture coordinates"))?;
    let point_uvs: Vec<[f32; 2]> = points
        .iter()
        .map(|&(f, b)| {
            let t = mesh.indices[f as usize].map(|v| uvs[v as usize]);
            let p = t[0] * b[0] + t[1] * b[1] + t[2] * b[2];
            [p.x, p.y]
        })
        .collect();
    let mut out = vec![0.0f32; 3 * n];
    let t_texture = time(r, || {
        for (uv, o) in point_uvs.iter().zip(out.chunks_exact_mut(3)) {
            tex.bilinear(*uv, o);
        }
    });
    let t_linear = time(r, || {
        for (&(f, b), o) in points.iter().zip(out.chunks_exact_mut(3)) {
            let _ = colors.linear(f as usize, b, o);
        }
    });
    let t_batch = time(r, || colors.linear_into(points, &mut out));
    let mip = colors.mip_map();
    let footprints = vec![0.05f32; n];
    let t_mip = time(r, || mip.trilinear_into(points, &footprints, &mut out));
    let ns = |t: f64| t / n as f64 * 1e9;
    table.push_str(&format!(
        "\n## Lookups at {n} surface points (one thread unless noted)\n\n| filter | ns per lookup | vs texture bilinear |\n|---|---|---|\n| texture bilinear (baseline) | {:.1} | 1.00 |\n| mesh colours linear | {:.1} | {:.2} |\n| mesh colours linear, batch (all threads) | {:.1} | {:.2} |\n| mesh colours trilinear MIP, batch (all threads) | {:.1} | {:.2} |\n",
        ns(t_texture), ns(t_linear), t_linear / t_texture, ns(t_batch), t_batch / t_texture, ns(t_mip), t_mip / t_texture
    ));
    Ok(
        json!({"texture_bilinear": ns(t_texture), "linear": ns(t_linear), "linear_batch": ns(t_batch), "trilinear_batch": ns(t_mip)}),
    )
}
