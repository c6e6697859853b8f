//! Šik & Křivánek 2013, Fig. 1a (Sec. 6): 6·10⁶ hair roots placed by a
//! density texture, each grown into an 8-segment strand, in memory —
//! "the complete generation of hair including hair root placement took
//! only 1.6 seconds" (4 cores, 2013). Writing the strands (`.hair`) is
//! timed apart.
//!
//! ```text
//! cargo run --release -p mesh-sampling --example hair -- [--threads T] [--roots N]
//!     [--segments K] [--runs R] [--mesh FILE --texture IMAGE] [--write DIR]
//! ```
//!
//! The mesh is `$TRILUX_DATA/meshes/spot.obj` with its texture
//! `textures/spot_texture.png` (luminance as the density, 8-bit values as
//! stored), or a generated UV sphere with a generated banded texture when
//! `TRILUX_DATA` is unset. Roots are drawn in random order
//! ([`SurfaceSampler::sample_n`]: one alias-table column a point, the
//! default layout); the uniform sampler's roots are the baseline of the
//! same run. Strands get a length of 2 % of the mesh's size, a slight
//! comb, curl and noise; a second row adds clumping to 10⁴ centres.
//! The whole pipeline is timed twice: roots stored by `sample_n` and then
//! grown, and grown chunk by chunk as they are drawn
//! (`grow_strands_sampled`, the same strands bit for bit). Each time is
//! the median of `--runs` (5) runs on a pool of `--threads` (2) threads;
//! the table is Markdown on stdout.

#[path = "support/data.rs"]
mod data;
use std::path::PathBuf;
use std::time::Instant;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, HairOptions, MeshRef, StrandParams, Strands,
    SurfacePoint, SurfaceSampler, UniformSampler, grow_strands, grow_strands_sampled, luminance,
};

struct Args {
    threads: usize,
    roots: usize,
    segments: u32,
    runs: usize,
    mesh: Option<PathBuf>,
    texture: Option<PathBuf>,
    write: Option<PathBuf>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        threads: 2,
        roots: 6_000_000,
        segments: 8,
        runs: 5,
        mesh: None,
        texture: None,
        write: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().ok_or(format!("{flag} needs a value"));
        let number = |v: String| v.parse::<usize>().map_err(|e| format!("{flag} {v}: {e}"));
        match flag.as_str() {
            "--threads" => args.threads = number(value()?)?.max(1),
            "--roots" => args.roots = number(value()?)?,
            "--segments" => args.segments = number(value()?)? as u32,
            "--runs" => args.runs = number(value()?)?.max(1),
            "--mesh" => args.mesh = Some(value()?.into()),
            "--texture" => args.texture = Some(value()?.into()),
            "--write" => args.write = Some(value()?.into()),
            other => return Err(format!("unknown argument {other}")),
        }
    }
    Ok(args)
}

/// A mesh with UVs and smooth normals, and its density texture.
struct Scene {
    name: String,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
    texture: DensityTexture,
}

impl Scene {
    fn mesh(&self) -> MeshRef<'_> {
        MeshRef {
            uvs: Some(&self.uvs),
            normals: Some(&self.normals),
            ..MeshRef::new(&self.positions, &self.indices)
        }
    }

    fn size(&self) -> f32 {
        let (lo, hi) = self
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
                (lo.min(p), hi.max(p))
            });
        (hi - lo).length()
    }
}

fn load(args: &Args) -> Result<Scene, String> {
    let (mesh, texture_path) = match (&args.mesh, &args.texture, data::data_dir()) {
        (Some(m), Some(t), _) => (m.clone(), t.clone()),
        (Some(_), None, _) | (None, Some(_), _) => {
            return Err("--mesh and --texture go together".into());
        }
        (None, None, Some(dir)) => (
            dir.join("meshes/spot.obj"),
            dir.join("textures/spot_texture.png"),
        ),
        (None, None, None) => return Ok(generated()),
    };
    let m = trilux_io::mesh::TriMesh::read(&mesh).map_err(|e| e.to_string())?;
    let uvs = m
        .uvs
        .clone()
        .ok_or(format!("{}: the mesh has no UVs", mesh.display()))?;
    let options = trilux_io::image::ReadOptions {
        raw: true,
        ..Default::default()
    };
    let image = trilux_io::image::read_with(&texture_path, options).map_err(|e| e.to_string())?;
    let texels = image
        .pixels
        .iter()
        .map(|p| luminance([p[0], p[1], p[2]]))
        .collect();
    let texture = DensityTexture::new(image.width as usize, image.height as usize, texels)
        .map_err(|e| e.to_string())?;
    let normals = match m.normals {
        Some(n) => n,
        None => smooth_normals(&m.positions, &m.indices),
    };
    Ok(Scene {
        name: format!(
            "{} + {}",
            mesh.file_name().unwrap_or_default().to_string_lossy(),
            texture_path
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
        ),
        positions: m.positions,
        normals,
        uvs,
        indices: m.indices,
        texture,
    })
}

/// Area-weighted vertex normals.
fn smooth_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let face = (b - a).cross(c - a);
        for &i in t {
            n[i as usize] += face;
        }
    }
    n.into_iter().map(|v| v.normalize_or(Vec3::Z)).collect()
}

/// A UV sphere (256 × 128 quads) and a 1024² texture of bands in v with a
/// checker in u: a density that varies inside triangles.
fn generated() -> Scene {
    let (nu, nv) = (256u32, 128u32);
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=nv {
        for i in 0..=nu {
            let (u, v) = (i as f32 / nu as f32, j as f32 / nv as f32);
            let (theta, phi) = (v * std::f32::consts::PI, u * std::f32::consts::TAU);
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut indices = Vec::new();
    let at = |i: u32, j: u32| j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    let normals = positions.iter().map(|p| p.normalize()).collect();
    let size = 1024;
    let texels = (0..size * size)
        .map(|k| {
            let (x, y) = (k % size, k / size);
            let band = 0.5 + 0.5 * (y as f32 / 24.0).sin();
            let checker = if (x / 64 + y / 64) % 2 == 0 { 1.0 } else { 0.2 };
            band * checker
        })
        .collect();
    Scene {
        name: "generated UV sphere + banded texture".into(),
        positions,
        normals,
        uvs,
        indices,
        texture: DensityTexture::new(size, size, texels).expect("a valid generated texture"),
    }
}

/// The median of `runs` timings of `f` (seconds), and the last result.
fn median<T>(runs: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs {
        // The previous result is dropped before the next run, untimed.
        drop(last.take());
        let start = Instant::now();
        let out = f();
        times.push(start.elapsed().as_secs_f64());
        last = Some(out);
    }
    times.sort_by(f64::total_cmp);
    (times[times.len() / 2], last.expect("at least one run"))
}

fn params(length: f32) -> impl Fn(&SurfacePoint) -> StrandParams + Sync {
    move |_| StrandParams {
        comb: Vec3::Y,
        comb_angle: 0.3,
        curl_radius: 0.05 * length,
        curl_turns: 1.0,
        noise: 0.02 * length,
        ..StrandParams::straight(length)
    }
}

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hair: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let scene = load(&args)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(args.threads)
        .build()
        .map_err(|e| e.to_string())?;
    let n = args.roots;
    let length = 0.02 * scene.size();
    let options = HairOptions {
        segments: args.segments,
        ..HairOptions::default()
    };
    let clumped = HairOptions {
        clumps: 10_000,
        ..options
    };
    let clump_params = {
        let base = params(length);
        move |p: &SurfacePoint| StrandParams {
            clump: 0.5,
            ..base(p)
        }
    };
    let err = |e: mesh_sampling::Error| e.to_string();
    pool.install(|| -> Result<(), String> {
        let mesh = scene.mesh();
        let (t_build, sampler) = median(args.runs, || {
            DensitySampler::new(mesh, Density::Texture(&scene.texture))
        });
        let sampler = sampler.map_err(err)?;
        let uniform = UniformSampler::new(mesh).map_err(err)?;
        let (t_uniform, _) = median(args.runs, || uniform.sample_n(1, n));
        let (t_roots, roots) = median(args.runs, || sampler.sample_n(1, n));
        let roots = roots.map_err(err)?;
        let (t_strands, strands) =
            median(args.runs, || grow_strands(&roots, &options, params(length)));
        let strands = strands.map_err(err)?;
        let (t_clumped, clumped_strands) =
            median(args.runs, || grow_strands(&roots, &clumped, &clump_params));
        drop(clumped_strands.map_err(err)?);
        let (t_two_step, whole) =
            median(args.runs, || -> Result<Strands, mesh_sampling::Error> {
                let roots = sampler.sample_n(1, n)?;
                grow_strands(&roots, &options, params(length))
            });
        drop(whole.map_err(err)?);
        let grow_params = params(length);
        let (t_whole, whole) = median(args.runs, || {
            grow_strands_sampled(&sampler, 1, n, &options, |_, p| grow_params(p))
        });
        drop(whole.map_err(err)?);
        let mb = |s: &Strands| (s.points.len() * 12 + s.roots.len() * 40) as f64 / 1e6;
        println!(
            "Hair (Šik & Křivánek 2013, Fig. 1a): {n} roots on {} ({} triangles, {}×{} texture), \
             {}-segment strands, {} threads, median of {} runs; uptime load: {}\n",
            scene.name,
            scene.indices.len(),
            scene.texture.width(),
            scene.texture.height(),
            args.segments,
            args.threads,
            args.runs,
            load_average()
        );
        println!("| step | median time | rate | vs. baseline |");
        println!("|---|---|---|---|");
        let rate = |t: f64| format!("{:.1} M/s", n as f64 / t / 1e6);
        println!(
            "| density sampler built (subdivision of the texture, once per texture) | {:.3} s | | |",
            t_build
        );
        println!(
            "| uniform roots (area only: the baseline) | {:.3} s | {} roots | 1.00× |",
            t_uniform,
            rate(t_uniform)
        );
        println!(
            "| roots by the density texture (random order, alias layout) | {:.3} s | {} roots | {:.2}× the baseline's time |",
            t_roots,
            rate(t_roots),
            t_roots / t_uniform
        );
        println!(
            "| {}-segment strands (comb, curl, noise; {:.0} MB) | {:.3} s | {} strands | |",
            args.segments,
            mb(&strands),
            t_strands,
            rate(t_strands)
        );
        println!(
            "| the same strands clumped to 10⁴ centres | {:.3} s | {} strands | {:.2}× unclumped |",
            t_clumped,
            rate(t_clumped),
            t_clumped / t_strands
        );
        println!(
            "| roots stored (`sample_n`), then strands (`grow_strands`) | {:.3} s | {} hairs | {:.2}× the paper's time |",
            t_two_step,
            rate(t_two_step),
            t_two_step / 1.6
        );
        println!(
            "| **roots + strands, in memory, grown as drawn** (`grow_strands_sampled`; paper: 1.6 s, 4 cores, 2013) | **{:.3} s** | {} hairs | **{:.2}× the paper's time** |",
            t_whole,
            rate(t_whole),
            t_whole / 1.6
        );
        if let Some(dir) = &args.write {
            std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
            let path = dir.join("hair.hair");
            let curves = to_curves(strands);
            let bytes = curves.points.len() * 12 + curves.widths.as_ref().map_or(0, |w| w.len() * 4);
            let start = Instant::now();
            trilux_io::curves::write(&path, &curves).map_err(|e| e.to_string())?;
            let t = start.elapsed().as_secs_f64();
            println!(
                "| writing them (`.hair`, {:.0} MB, one run, apart from the above) | {:.3} s | {:.0} MB/s | |",
                bytes as f64 / 1e6,
                t,
                bytes as f64 / t / 1e6
            );
        }
        Ok(())
    })
}

/// The strands as the writer's plain data (the points moved, not copied).
fn to_curves(strands: Strands) -> trilux_io::curves::Curves {
    let per = strands.points_per_strand() as u32;
    let n = strands.len();
    trilux_io::curves::Curves {
        faces: Some(strands.roots.iter().map(|r| r.face).collect()),
        barycentrics: Some(strands.roots.iter().map(|r| r.barycentric).collect()),
        normals: Some(strands.roots.iter().map(|r| r.normal).collect()),
        uvs: strands
            .roots
            .iter()
            .map(|r| r.uv)
            .collect::<Option<Vec<_>>>(),
        points: strands.points,
        counts: vec![per; n],
        widths: strands.widths,
    }
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_string))
        .unwrap_or_else(|| "unknown".into())
}
