//! The density sampler's two layouts against the uniform sampler on one
//! mesh, measured interleaved (uniform, alias, inversion, uniform, …) so
//! that load changes on a shared machine hit all three alike; quotes the
//! median of each ratio over the rounds.
//!
//! ```text
//! TRILUX_DATA=… cargo run --release -p mesh-sampling --example layouts -- [MESH] [DENSITY] [THREADS] [MAX_PIECES]
//! ```
//!
//! `MESH` is a file name in `$TRILUX_DATA/meshes` (default the bunny; no
//! UVs: spherical ones), `DENSITY` one of `noise` (smooth value noise at
//! 64 cells, default) or `uniform`, at 1024².

use std::hint::black_box;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Layout, MeshRef, Options, SurfaceSampler,
    UniformSampler, spherical_uvs,
};

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

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh_name = args.first().map_or("stanford-bunny.obj", String::as_str);
    let density = args.get(1).map_or("noise", String::as_str);
    let threads: usize = args
        .get(2)
        .map_or(Ok(1), |t| t.parse())
        .map_err(|e| format!("{e}"))?;
    let max_pieces: usize = args
        .get(3)
        .map_or(Ok(mesh_sampling::DEFAULT_MAX_PIECES), |t| t.parse())
        .map_err(|e| format!("{e}"))?;
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").ok_or("set TRILUX_DATA")?);
    let m = trilux_io::mesh::TriMesh::read(dir.join("meshes").join(mesh_name))
        .map_err(|e| e.to_string())?;
    let (positions, uvs, indices): (Vec<Vec3>, Vec<Vec2>, Vec<[u32; 3]>) = match m.uvs {
        Some(uvs) => (m.positions, uvs, m.indices),
        None => spherical_uvs(&m.positions, &m.indices).map_err(|e| e.to_string())?,
    };
    let mesh = MeshRef {
        uvs: Some(&uvs),
        ..MeshRef::new(&positions, &indices)
    };
    let t = texture(density)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    let uniform = UniformSampler::new(mesh).map_err(|e| e.to_string())?;
    let options = Options {
        max_pieces,
        ..Options::default()
    };
    let alias = DensitySampler::with_options(mesh, Density::Texture(&t), &options)
        .map_err(|e| e.to_string())?;
    let inversion = DensitySampler::with_options(
        mesh,
        Density::Texture(&t),
        &Options {
            layout: Layout::Inversion,
            ..options
        },
    )
    .map_err(|e| e.to_string())?;
    let (mut a, mut i, mut u_all) = (Vec::new(), Vec::new(), Vec::new());
    pool.install(|| {
        for round in 0..ROUNDS as u64 {
            u_all.push(rate(&uniform, round));
            a.push(rate(&alias, round));
            i.push(rate(&inversion, round));
        }
    });
    let ratios = |x: &[f64]| -> Vec<f64> { x.iter().zip(&u_all).map(|(x, u)| x / u).collect() };
    let best = |x: &[f64]| x.iter().copied().fold(0.0, f64::max);
    // The median of the per-round ratios, and the ratio of the fastest
    // runs (the runs least disturbed by other work on the machine).
    println!(
        "| {mesh_name} | {density} | {threads} | {} | {:.1} | {:.0}% ({:.0}%) | {:.0}% ({:.0}%) |",
        alias.pieces(),
        median(u_all.clone()),
        100.0 * median(ratios(&a)),
        100.0 * best(&a) / best(&u_all),
        100.0 * median(ratios(&i)),
        100.0 * best(&i) / best(&u_all),
    );
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
