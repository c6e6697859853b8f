//! The density sampler against the machine's limit and against itself
//! with a uniform texture (Šik & Křivánek 2013, Sec. 5.2: "drops at most
//! by 35% compared to the sampling rate with a uniform texture"), on each
//! mesh and thread count, measured interleaved (uniform texture, alias,
//! inversion, uniform sampler, probe, …) so that load changes on a shared
//! machine hit all alike; quotes the median of each ratio over the rounds.
//!
//! ```text
//! TRILUX_DATA=… cargo run --release -p mesh-sampling --example layouts -- [MESH|all] [DENSITY] [THREADS,…] [MAX_PIECES] [TOLERANCE]
//! ```
//!
//! `MESH` is a file name in `$TRILUX_DATA/meshes` (default `all`: every
//! mesh there; no UVs: spherical ones), `DENSITY` one of `noise` (smooth
//! value noise at 64 cells, default) or `uniform`, at 1024²; `THREADS` a
//! comma-separated list (default `1,2`); `TOLERANCE` the
//! `Options::merge_tolerance` (default 0: `p′` exactly). The probe
//! (`support/probe.rs`) reads random 16-byte records from a table of the
//! alias table's size: one at a time (latency) and in the sampler's blocks.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Layout, MeshRef, Options, SurfaceSampler,
    UniformSampler, spherical_uvs,
};

#[path = "support/probe.rs"]
mod probe;

const SIZE: usize = 1024;
const ROUNDS: usize = 7;
const N: usize = 2_000_000;

fn texture(name: &str) -> Result<DensityTexture, String> {
    let hash = |x: u64, y: u64| {
        let mut h = x.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ y.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        h ^= h >> 29;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        (h >> 11) as f32 / (1u64 << 53) as f32
    };
    let texels = match name {
        "uniform" => vec![1.0; SIZE * SIZE],
        "noise" => (0..SIZE * SIZE)
            .map(|i| {
                let (x, y) = ((i % SIZE) as f32 / 16.0, (i / SIZE) as f32 / 16.0);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = (x - x0, y - y0);
                let at = |dx: f32, dy: f32| hash((x0 + dx) as u64 % 64, (y0 + dy) as u64 % 64);
                let top = at(0.0, 0.0) + (at(1.0, 0.0) - at(0.0, 0.0)) * fx;
                let bottom = at(0.0, 1.0) + (at(1.0, 1.0) - at(0.0, 1.0)) * fx;
                0.1 + top + (bottom - top) * fy
            })
            .collect(),
        other => return Err(format!("unknown density {other} (noise or uniform)")),
    };
    DensityTexture::new(SIZE, SIZE, texels).map_err(|e| e.to_string())
}

fn rate(sampler: &impl SurfaceSampler, seed: u64) -> f64 {
    let start = Instant::now();
    sampler.sample_stream(seed, N, |_, chunk| {
        let s: f32 = chunk.iter().map(|p| p.position.x + p.pdf).sum();
        black_box(s);
    });
    N as f64 / start.elapsed().as_secs_f64() / 1e6
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// One mesh, its UVs (spherical ones when it has none).
type Loaded = (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>);

fn load(file: &Path) -> Result<Loaded, String> {
    let m = trilux_io::mesh::TriMesh::read(file).map_err(|e| e.to_string())?;
    match m.uvs {
        Some(uvs) => Ok((m.positions, uvs, m.indices)),
        None => spherical_uvs(&m.positions, &m.indices).map_err(|e| e.to_string()),
    }
}

struct Config {
    density: DensityTexture,
    flat: DensityTexture,
    options: Options,
}

fn row(name: &str, loaded: &Loaded, threads: usize, config: &Config) -> Result<(), String> {
    let (positions, uvs, indices) = loaded;
    let mesh = MeshRef {
        uvs: Some(uvs),
        ..MeshRef::new(positions, indices)
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let err = |e: mesh_sampling::Error| e.to_string();
    let uniform = UniformSampler::new(mesh).map_err(err)?;
    let options = config.options;
    let flat = DensitySampler::with_options(mesh, Density::Texture(&config.flat), &options)
        .map_err(err)?;
    let alias = DensitySampler::with_options(mesh, Density::Texture(&config.density), &options)
        .map_err(err)?;
    let inversion = DensitySampler::with_options(
        mesh,
        Density::Texture(&config.density),
        &Options {
            layout: Layout::Inversion,
            ..options
        },
    )
    .map_err(err)?;
    let pieces = alias.pieces();
    let (mut f, mut a, mut i, mut u, mut p) = (vec![], vec![], vec![], vec![], vec![]);
    let mut latency = 0.0;
    pool.install(|| {
        latency = probe::probe(pieces, N / 4, 1).latency;
        for round in 0..ROUNDS as u64 {
            f.push(rate(&flat, round));
            a.push(rate(&alias, round));
            i.push(rate(&inversion, round));
            u.push(rate(&uniform, round));
            p.push(probe::probe(pieces, N, 1).batch);
        }
    });
    let ratio =
        |x: &[f64], y: &[f64]| -> f64 { median(x.iter().zip(y).map(|(x, y)| x / y).collect()) };
    let table = alias.table_bytes() as f64;
    println!(
        "| {name} | {threads} | {pieces} | {:.1} | {:.1} | {:.1} | {:.1} | {:.0}% | {:.0}% | {:.1} / {:.1} | {:.0}% | {:.0}% |",
        table / 1e6,
        table / pieces as f64,
        median(f.clone()),
        median(a.clone()),
        100.0 * ratio(&a, &f),
        100.0 * ratio(&a, &u),
        latency,
        median(p.clone()),
        100.0 * ratio(&a, &p),
        100.0 * ratio(&i, &f),
    );
    Ok(())
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh_name = args.first().map_or("all", String::as_str);
    let density = args.get(1).map_or("noise", String::as_str);
    let threads: Vec<usize> = args
        .get(2)
        .map_or("1,2", String::as_str)
        .split(',')
        .map(|t| t.parse().map_err(|e| format!("threads {t}: {e}")))
        .collect::<Result<_, _>>()?;
    let max_pieces: usize = args
        .get(3)
        .map_or(Ok(mesh_sampling::DEFAULT_MAX_PIECES), |t| t.parse())
        .map_err(|e| format!("{e}"))?;
    let merge_tolerance: f32 = args
        .get(4)
        .map_or(Ok(0.0), |t| t.parse())
        .map_err(|e| format!("{e}"))?;
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").ok_or("set TRILUX_DATA")?);
    let files: Vec<PathBuf> = if mesh_name == "all" {
        let mut files: Vec<PathBuf> = std::fs::read_dir(dir.join("meshes"))
            .map_err(|e| e.to_string())?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "obj" || e == "ply"))
            .collect();
        files.sort();
        files
    } else {
        vec![dir.join("meshes").join(mesh_name)]
    };
    let config = Config {
        density: texture(density)?,
        flat: texture("uniform")?,
        options: Options {
            max_pieces,
            merge_tolerance,
            ..Options::default()
        },
    };
    println!(
        "Density `{density}` 1024², merge tolerance {merge_tolerance}; M points/s, medians of {ROUNDS} interleaved rounds of {N} points; ratios are medians of the per-round ratios.\n"
    );
    println!(
        "| mesh | threads | pieces | table MB | bytes/piece | uniform texture M/s | density (alias) M/s | density / uniform texture | density / uniform sampler | probe M reads/s: latency / batch | density / probe batch | inversion / uniform texture |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for file in &files {
        let name = file
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let loaded = load(file)?;
        for &t in &threads {
            row(&name, &loaded, t, &config)?;
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
