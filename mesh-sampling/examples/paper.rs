//! Šik & Křivánek 2013, Fig. 10 and Table 1: sampling rate, preprocessing
//! time and memory of rejection sampling and of adaptive subdivision
//! (the inversion layout without and with the lookup table, the alias
//! layout, and our exact mode) against the uniform sampler, per mesh and
//! density texture, on one and two threads; then the ratios between them,
//! and the comparison with trimesh and Open3D at N = 10⁷ on the bunny.
//!
//! ```text
//! cargo run --release -p mesh-sampling --example paper -- [--json] [--mesh FILE]
//!     [--density D[,D…]] [--threads T] [--no-peers] [--no-tiled] [--tiled-only] [--bar]
//! ```
//!
//! Meshes: every mesh in `$TRILUX_DATA/meshes` (those without UVs get
//! [`spherical_uvs`]), or, without `TRILUX_DATA`, a generated icosphere and
//! torus. Densities at 1024×1024: `uniform`, `checker2`, `checker16`,
//! `checker128` (black = 0), `perlin4`, `perlin16`, `perlin64`, and
//! `hdr:<file>` for each image of `$TRILUX_DATA/hdr` (luminance, rows
//! doubled to 1024²), or a generated `hdr:sun` without data. Rates are
//! medians of five timed runs of about 0.1 s each; points are streamed
//! through [`SurfaceSampler::sample_stream`] and summed, so memory
//! bandwidth for storing them is not what is measured (the peer comparison
//! stores their positions, as the peers do). Beside each alias-layout
//! density the machine's limit for its table is probed (`support/probe.rs`:
//! random reads of 16-byte records from a table of as many records, one at
//! a time and in the sampler's blocks), and the summary gives each density
//! rate as a fraction of that probe, beside its ratio to the uniform
//! texture's rate (Sec. 5.2) and to the uniform sampler's. The ratio to
//! the uniform texture is the median of nine pairs of back-to-back runs of
//! the two samplers, so that a neighbour's load on a shared host falls on
//! both sides of each pair; `--bar` measures only that ratio (the alias
//! layout on every mesh and density), in a few minutes instead of the
//! whole table's hour.

#[path = "support/data.rs"]
mod data;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};
use std::time::Instant;

use discrete_sampling::CdfBisection;
use glam::{Vec2, Vec3};
use mesh_sampling::{
    Density, DensitySampler, DensityTexture, Layout, MeshRef, Mode, Options, RejectionSampler,
    SurfaceSampler, UniformSampler, spherical_uvs,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

#[path = "support/probe.rs"]
mod probe;

const SIZE: usize = 1024;
const RUNS: usize = 5;
/// Back-to-back pairs of runs for a ratio of two samplers' rates.
const PAIRS: usize = 9;
const BUILDS: usize = 3;
const TARGET_S: f64 = 0.1;
const PEER_N: usize = 10_000_000;

struct Args {
    json: bool,
    mesh: Option<String>,
    density: Option<String>,
    threads: Vec<usize>,
    peers: bool,
    tiled: bool,
    /// Only what the bar of Sec. 5.2 needs: the alias layout, paired with
    /// the uniform texture.
    bar: bool,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        mesh: None,
        density: None,
        threads: vec![1, 2],
        peers: true,
        tiled: true,
        bar: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--json" => args.json = true,
            "--no-peers" => args.peers = false,
            "--no-tiled" => args.tiled = false,
            "--bar" => {
                args.bar = true;
                args.tiled = false;
                args.peers = false;
            }
            "--tiled-only" => {
                args.tiled = true;
                args.peers = false;
                args.threads = Vec::new();
            }
            "--mesh" => args.mesh = Some(value("--mesh")?),
            "--density" => args.density = Some(value("--density")?),
            "--threads" => {
                let t: usize = value("--threads")?
                    .parse()
                    .map_err(|e| format!("--threads: {e}"))?;
                if t == 0 {
                    return Err("--threads must be at least 1".into());
                }
                args.threads = vec![t];
            }
            "-h" | "--help" => {
                return Err(
                    "usage: paper [--json] [--mesh FILE] [--density D[,D...]] [--threads T] [--no-peers] [--no-tiled] [--tiled-only] [--bar]"
                        .into(),
                );
            }
            other => return Err(format!("unknown argument {other} (try --help)")),
        }
    }
    Ok(args)
}

/// A mesh ready to sample: positions, UVs, triangles.
struct TestMesh {
    name: String,
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    indices: Vec<[u32; 3]>,
}

impl TestMesh {
    fn mesh(&self) -> MeshRef<'_> {
        MeshRef {
            uvs: Some(&self.uvs),
            ..MeshRef::new(&self.positions, &self.indices)
        }
    }
}

fn load_meshes(filter: Option<&str>) -> Result<Vec<TestMesh>, String> {
    let mut out = Vec::new();
    let files: Vec<PathBuf> = match (filter, data::data_dir()) {
        (Some(f), _) if Path::new(f).is_file() => vec![PathBuf::from(f)],
        (_, Some(dir)) => {
            let dir = dir.join("meshes");
            let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
                .map_err(|e| format!("{}: {e}", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                        matches!(
                            e.to_ascii_lowercase().as_str(),
                            "obj" | "ply" | "gltf" | "glb"
                        )
                    })
                })
                .filter(|p| filter.is_none_or(|f| p.file_name().is_some_and(|n| n == f)))
                .collect();
            files.sort();
            files
        }
        (_, None) => {
            let built_in: Vec<TestMesh> = [icosphere(5), torus(192, 96)]
                .into_iter()
                .filter(|m| filter.is_none_or(|f| m.name == f))
                .collect();
            if built_in.is_empty() {
                return Err(format!(
                    "--mesh {}: not a file, and without TRILUX_DATA the meshes are the built-in icosphere and torus",
                    filter.unwrap_or_default()
                ));
            }
            return Ok(built_in);
        }
    };
    for file in files {
        let m = trilux_io::mesh::TriMesh::read(&file).map_err(|e| e.to_string())?;
        let name = file
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .into_owned();
        let (positions, uvs, indices) = match m.uvs {
            Some(uvs) => (m.positions, uvs, m.indices),
            None => spherical_uvs(&m.positions, &m.indices).map_err(|e| e.to_string())?,
        };
        out.push(TestMesh {
            name,
            positions,
            uvs,
            indices,
        });
    }
    if out.is_empty() {
        return Err(format!("no mesh matches {filter:?}"));
    }
    Ok(out)
}

/// A unit icosphere, `levels` times 1-to-4 subdivided, spherically mapped.
fn icosphere(levels: u32) -> TestMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .to_vec();
    let mut indices: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(indices.len() * 4);
        for [a, b, c] in indices {
            let (ab, bc, ca) = (
                mid(a, b, &mut positions),
                mid(b, c, &mut positions),
                mid(c, a, &mut positions),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        indices = next;
    }
    let (positions, uvs, indices) =
        spherical_uvs(&positions, &indices).expect("the icosphere is a valid mesh");
    TestMesh {
        name: "icosphere".into(),
        positions,
        uvs,
        indices,
    }
}

/// A torus with its natural (around, across) UV map.
fn torus(around: u32, across: u32) -> TestMesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for j in 0..=across {
        for i in 0..=around {
            let (u, v) = (i as f32 / around as f32, j as f32 / across as f32);
            let (a, b) = (u * std::f32::consts::TAU, v * std::f32::consts::TAU);
            let r = 1.0 + 0.35 * b.cos();
            positions.push(Vec3::new(r * a.cos(), 0.35 * b.sin(), r * a.sin()));
            uvs.push(Vec2::new(u, v));
        }
    }
    let at = |i: u32, j: u32| j * (around + 1) + i;
    let mut indices = Vec::new();
    for j in 0..across {
        for i in 0..around {
            indices.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
            indices.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    TestMesh {
        name: "torus".into(),
        positions,
        uvs,
        indices,
    }
}

/// The density textures, by name.
fn densities(filter: Option<&str>) -> Result<Vec<(String, DensityTexture)>, String> {
    let mut names: Vec<String> = [
        "uniform",
        "checker2",
        "checker16",
        "checker128",
        "perlin4",
        "perlin16",
        "perlin64",
    ]
    .map(String::from)
    .to_vec();
    let hdr_files: Vec<PathBuf> = match data::data_dir() {
        Some(dir) => {
            let mut f: Vec<PathBuf> = std::fs::read_dir(dir.join("hdr"))
                .map_err(|e| format!("{}: {e}", dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("hdr")))
                .collect();
            f.sort();
            f
        }
        None => Vec::new(),
    };
    if hdr_files.is_empty() {
        names.push("hdr:sun".into());
    }
    for f in &hdr_files {
        names.push(format!(
            "hdr:{}",
            f.file_name().unwrap_or_default().to_string_lossy()
        ));
    }
    let mut out = Vec::new();
    for name in names {
        // A comma-separated list of names (`hdr` for every image).
        let wanted = |f: &str| f == name || (f == "hdr" && name.starts_with("hdr:"));
        if filter.is_some_and(|f| !f.split(',').any(wanted)) {
            continue;
        }
        let texels: Vec<f32> = match name.as_str() {
            "uniform" => vec![1.0; SIZE * SIZE],
            n if n.starts_with("checker") => {
                let k: usize = n["checker".len()..].parse().map_err(|_| n.to_string())?;
                grid_fn(|x, y| ((x * k / SIZE + y * k / SIZE) % 2) as f32)
            }
            n if n.starts_with("perlin") => {
                let f: usize = n["perlin".len()..].parse().map_err(|_| n.to_string())?;
                grid_fn(|x, y| {
                    let (u, v) = (
                        (x as f64 + 0.5) / SIZE as f64,
                        (y as f64 + 0.5) / SIZE as f64,
                    );
                    (0.5 + 0.7 * perlin(u * f as f64, v * f as f64, f)).clamp(0.0, 1.0) as f32
                })
            }
            "hdr:sun" => grid_fn(|x, y| {
                let (u, v) = (x as f32 / SIZE as f32, y as f32 / SIZE as f32);
                let sky = 0.2 + 0.8 * (1.0 - v);
                let d2 = (u - 0.7).powi(2) + (v - 0.3).powi(2);
                if d2 < 0.004f32.powi(2) { 5e4 } else { sky }
            }),
            n => {
                let file = hdr_files
                    .iter()
                    .find(|f| f.file_name().is_some_and(|f| f.to_string_lossy() == n[4..]))
                    .ok_or(format!("no density {n}"))?;
                let image = trilux_io::image::read(file).map_err(|e| e.to_string())?;
                let (w, h) = (image.width as usize, image.height as usize);
                grid_fn(|x, y| {
                    let p = image.pixels[(y * h / SIZE) * w + x * w / SIZE];
                    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
                })
            }
        };
        out.push((
            name,
            DensityTexture::new(SIZE, SIZE, texels).map_err(|e| e.to_string())?,
        ));
    }
    if out.is_empty() {
        return Err(format!("no density matches {filter:?}"));
    }
    Ok(out)
}

fn grid_fn(f: impl Fn(usize, usize) -> f32) -> Vec<f32> {
    (0..SIZE * SIZE).map(|i| f(i % SIZE, i / SIZE)).collect()
}

/// Periodic 2D Perlin gradient noise with `period` cells, in about
/// [−0.7, 0.7].
fn perlin(x: f64, y: f64, period: usize) -> f64 {
    let gradient = |i: i64, j: i64| {
        let (i, j) = (
            i.rem_euclid(period as i64) as u64,
            j.rem_euclid(period as i64) as u64,
        );
        let mut h = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ j.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
        h ^= h >> 29;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        let angle = (h >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
        (angle.cos(), angle.sin())
    };
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let corner = |di: i64, dj: i64| {
        let g = gradient(x0 as i64 + di, y0 as i64 + dj);
        g.0 * (fx - di as f64) + g.1 * (fy - dj as f64)
    };
    let (sx, sy) = (fade(fx), fade(fy));
    let top = corner(0, 0) + (corner(1, 0) - corner(0, 0)) * sx;
    let bottom = corner(0, 1) + (corner(1, 1) - corner(0, 1)) * sx;
    top + (bottom - top) * sy
}

/// One measured row.
#[derive(Debug, Clone)]
struct Row {
    mesh: String,
    triangles: usize,
    density: String,
    method: &'static str,
    threads: usize,
    msamples_per_s: f64,
    preprocess_ms: f64,
    memory_mb: f64,
    max_over_mean: f64,
    acceptance: f64,
    pieces: usize,
    /// The alias layout's rate over the uniform texture's, the median of
    /// [`PAIRS`] back-to-back pairs of runs (`subdivision` rows).
    paired: Option<f64>,
    /// The largest relative change of a piece's value to fit the alias
    /// columns ([`DensitySampler::value_tolerance`]; 0 elsewhere).
    value_tolerance: f64,
}

impl Row {
    fn json(&self) -> String {
        format!(
            "{{\"mesh\": \"{}\", \"density\": \"{}\", \"method\": \"{}\", \"msamples_per_s\": {:.3}, \
             \"preprocess_ms\": {:.2}, \"memory_mb\": {:.2}, \"threads\": {}, \"max_over_mean\": {:.3}, \
             \"triangles\": {}, \"acceptance\": {:.4}, \"pieces\": {}, \"vs_uniform_texture\": {}, \"value_tolerance\": {:e}}}",
            self.mesh,
            self.density,
            self.method,
            self.msamples_per_s,
            self.preprocess_ms,
            self.memory_mb,
            self.threads,
            self.max_over_mean,
            self.triangles,
            self.acceptance,
            self.pieces,
            self.paired.map_or("null".into(), |x| format!("{x:.4}")),
            self.value_tolerance
        )
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Million points per second of `sample` (streamed), median of [`RUNS`]
/// runs sized to about [`TARGET_S`] each.
fn rate(sampler: &impl SurfaceSampler) -> f64 {
    measure(|n| timed_stream(sampler, n))
}

/// Seconds for `n` points of `sampler`, streamed and summed.
fn timed_stream(sampler: &impl SurfaceSampler, n: usize) -> f64 {
    let start = Instant::now();
    sampler.sample_stream(1, n, |_, chunk| {
        let s: f32 = chunk.iter().map(|p| p.position.x + p.pdf).sum();
        black_box(s);
    });
    start.elapsed().as_secs_f64()
}

/// The rates (M points/s) of `a` and `b` and the median of `a`'s over
/// `b`'s in [`PAIRS`] pairs of runs of the same count (about
/// [`TARGET_S`] of `a`), the order alternating from pair to pair. On a
/// host whose neighbours come and go, two samplers measured seconds apart
/// can see different machines; a pair's two runs see nearly the same.
fn paired_rates(a: &impl SurfaceSampler, b: &impl SurfaceSampler) -> (f64, f64, f64) {
    // A sampler too slow to calibrate is measured at the first count.
    let n = calibrate(|n| timed_stream(a, n)).unwrap_or(1 << 10);
    let (mut ta, mut tb, mut ratio) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..PAIRS {
        let (x, y) = if k % 2 == 0 {
            let x = timed_stream(a, n);
            (x, timed_stream(b, n))
        } else {
            let y = timed_stream(b, n);
            (timed_stream(a, n), y)
        };
        ta.push(x);
        tb.push(y);
        ratio.push(y / x);
    }
    let rate = |t: Vec<f64>| n as f64 / median(t) / 1e6;
    (rate(ta), rate(tb), median(ratio))
}

/// Million triples of `u64` per second from the chunked generators the
/// samplers use: the cost of the random numbers a point consumes (one for
/// the table, two for the point in the triangle).
fn rng_rate() -> f64 {
    let run = |n: usize| {
        let start = Instant::now();
        let chunks = n.div_ceil(1 << 14);
        let work = |k: usize| {
            let mut rng = Pcg64Mcg::seed_from_u64(k as u64);
            let mut s = 0u64;
            for _ in 0..1 << 14 {
                s = s.wrapping_add(rng.next_u64() ^ rng.next_u64() ^ rng.next_u64());
            }
            black_box(s);
        };
        {
            use rayon::prelude::*;
            (0..chunks).into_par_iter().for_each(work);
        }
        start.elapsed().as_secs_f64()
    };
    measure(run)
}

/// Million items per second of `run(n)`: the median of [`RUNS`] runs
/// sized to about [`TARGET_S`] each. A sampler so slow that a probe of
/// 1,024 points (one chunk, so one thread) takes over [`TARGET_S`]
/// (rejection at an acceptance of 1e-5) is reported from that one run.
fn measure(run: impl Fn(usize) -> f64) -> f64 {
    let n = match calibrate(&run) {
        Ok(n) => n,
        Err(rate) => return rate,
    };
    let times: Vec<f64> = (0..RUNS).map(|_| run(n)).collect();
    n as f64 / median(times) / 1e6
}

/// The count that makes one `run` take about [`TARGET_S`], or `Err` with
/// the rate (M items/s) of a first run of 1,024 that already takes longer.
fn calibrate(run: impl Fn(usize) -> f64) -> Result<usize, f64> {
    let mut n = 1 << 10;
    let mut t = run(n);
    if t > TARGET_S {
        return Err(n as f64 / t / 1e6);
    }
    while t < TARGET_S / 8.0 {
        n *= 4;
        t = run(n);
    }
    Ok(((n as f64 * TARGET_S / t) as usize).max(1 << 10))
}

/// Median build time (ms) of [`BUILDS`] builds, and the last build.
fn build<T>(f: impl Fn() -> T) -> (f64, T) {
    build_n(BUILDS, f)
}

/// Median build time (ms) of `n` builds, and the last build.
fn build_n<T>(n: usize, f: impl Fn() -> T) -> (f64, T) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..n.max(1) {
        let start = Instant::now();
        let built = f();
        times.push(start.elapsed().as_secs_f64() * 1e3);
        last = Some(built);
    }
    (median(times), last.expect("BUILDS > 0"))
}

fn measure_pair(
    m: &TestMesh,
    name: &str,
    texture: &DensityTexture,
    threads: usize,
    bar: bool,
) -> Result<Vec<Row>, String> {
    let mesh = m.mesh();
    let texture_mb = texture.memory_bytes() as f64 / 1e6;
    let (reject_ms, rejection) = build_n(if bar { 1 } else { BUILDS }, || {
        RejectionSampler::new(mesh, texture)
    });
    let rejection = rejection.map_err(|e| format!("{}, {name}: {e}", m.name))?;
    let area = UniformSampler::new(mesh)
        .map_err(|e| e.to_string())?
        .total_area();
    let max_over_mean = f64::from(texture.max()) * area / rejection.total_mass();
    let row = |method, msamples_per_s, preprocess_ms, memory_mb, acceptance, pieces| Row {
        mesh: m.name.clone(),
        triangles: m.indices.len(),
        density: name.to_string(),
        method,
        threads,
        msamples_per_s,
        preprocess_ms,
        memory_mb,
        max_over_mean,
        acceptance,
        pieces,
        paired: None,
        value_tolerance: 0.0,
    };
    let density = Density::Texture(texture);
    // The uniform texture (Sec. 5.2): one piece per face, value 1.
    let flat_texture = DensityTexture::new(1, 1, vec![1.0]).map_err(|e| e.to_string())?;
    let flat =
        DensitySampler::new(mesh, Density::Texture(&flat_texture)).map_err(|e| e.to_string())?;
    let (ms, alias) = build_n(if bar { 1 } else { BUILDS }, || {
        DensitySampler::new(mesh, density)
    });
    let alias = alias.map_err(|e| e.to_string())?;
    let (alias_rate, _, paired) = paired_rates(&alias, &flat);
    let alias_row = Row {
        paired: Some(paired),
        value_tolerance: alias.value_tolerance(),
        ..row(
            "subdivision",
            alias_rate,
            ms,
            alias.memory_bytes() as f64 / 1e6,
            1.0,
            alias.pieces(),
        )
    };
    let table_mb = alias.table_bytes() as f64 / 1e6;
    let pieces = alias.pieces();
    drop(alias);
    if bar {
        return Ok(vec![alias_row]);
    }
    let mut rows = vec![row(
        "rejection",
        rate(&rejection),
        reject_ms,
        rejection.memory_bytes() as f64 / 1e6 + texture_mb,
        rejection.acceptance(),
        m.indices.len(),
    )];
    let inversion = Options {
        layout: Layout::Inversion,
        ..Options::default()
    };
    // Its build is the inversion layout's (timed below): built once.
    let (ms, no_table) = build_n(1, || {
        DensitySampler::<CdfBisection>::with_table(mesh, density, &inversion)
    });
    let no_table = no_table.map_err(|e| e.to_string())?;
    let bytes = no_table.memory_bytes();
    rows.push(row(
        "subdivision-no-table",
        rate(&no_table),
        ms,
        bytes as f64 / 1e6,
        1.0,
        no_table.pieces(),
    ));
    drop(no_table);
    let (ms, table) = build(|| DensitySampler::with_options(mesh, density, &inversion));
    let table = table.map_err(|e| e.to_string())?;
    let bytes = table.memory_bytes();
    rows.push(row(
        "subdivision-inversion",
        rate(&table),
        ms,
        bytes as f64 / 1e6,
        1.0,
        table.pieces(),
    ));
    drop(table);
    rows.push(alias_row);
    // The limit for a table of this size, on this pool.
    let limit = probe::probe(pieces, 1 << 22, RUNS);
    rows.push(row(
        "probe-latency",
        limit.latency,
        0.0,
        table_mb,
        1.0,
        pieces,
    ));
    rows.push(row("probe-batch", limit.batch, 0.0, table_mb, 1.0, pieces));
    let exact_options = Options {
        mode: Mode::Exact,
        ..Options::default()
    };
    let (ms, exact) = build_n(1, || {
        DensitySampler::with_options(mesh, density, &exact_options)
    });
    let exact = exact.map_err(|e| e.to_string())?;
    rows.push(row(
        "exact",
        rate(&exact),
        ms,
        exact.memory_bytes() as f64 / 1e6 + texture_mb,
        exact.acceptance(),
        exact.pieces(),
    ));
    Ok(rows)
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())
}

fn print_markdown(rows: &[Row]) {
    println!(
        "| mesh | triangles | density | max/mean | method | threads | M samples/s | preprocess ms | memory MB | pieces | acceptance |"
    );
    println!("|---|---:|---|---:|---|---:|---:|---:|---:|---:|---:|");
    for r in rows {
        println!(
            "| {} | {} | {} | {:.1} | {} | {} | {:.2} | {:.1} | {:.1} | {} | {:.3} |",
            r.mesh,
            r.triangles,
            r.density,
            r.max_over_mean,
            r.method,
            r.threads,
            r.msamples_per_s,
            r.preprocess_ms,
            r.memory_mb,
            r.pieces,
            r.acceptance
        );
    }
}

/// The ratios that matter, from the rows of this run: each density's
/// rate against the uniform sampler's on the same mesh and thread count
/// (both layouts), against rejection, and two threads against one.
fn print_summary(rows: &[Row]) {
    let find = |mesh: &str, density: &str, method: &str, threads: usize| {
        rows.iter().find(|r| {
            r.mesh == mesh && r.density == density && r.method == method && r.threads == threads
        })
    };
    println!("\n## Density rate / uniform sampler rate (same mesh, same threads)\n");
    println!(
        "Beside it, the alias layout's rate against the uniform texture's (the density sampler with a constant texture, Sec. 5.2; the median of 9 back-to-back pairs of runs) and as a fraction of the probe: random 16-byte reads from a table of as many records, in the sampler's blocks (and the probe's one-at-a-time rate).\n"
    );
    println!(
        "| mesh | density | threads | alias layout | inversion layout | speed-up over rejection | alias / uniform texture | alias / probe batch | probe M reads/s: latency / batch |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|---:|");
    let mut worst: [Option<(f64, &Row)>; 2] = [None, None];
    let mut worst_flat: Option<(f64, &Row)> = None;
    for r in rows.iter().filter(|r| r.method == "subdivision") {
        let Some(u) = find(&r.mesh, "-", "uniform-sampler", r.threads) else {
            continue;
        };
        let alias = r.msamples_per_s / u.msamples_per_s;
        let inversion = find(&r.mesh, &r.density, "subdivision-inversion", r.threads)
            .map(|i| i.msamples_per_s / u.msamples_per_s);
        let rejection = find(&r.mesh, &r.density, "rejection", r.threads)
            .map(|j| r.msamples_per_s / j.msamples_per_s);
        // Paired runs where measured, else this run's two rows.
        let flat = r.paired.or_else(|| {
            find(&r.mesh, "uniform", "subdivision", r.threads)
                .map(|f| r.msamples_per_s / f.msamples_per_s)
        });
        let batch = find(&r.mesh, &r.density, "probe-batch", r.threads);
        let latency = find(&r.mesh, &r.density, "probe-latency", r.threads);
        let percent = |x: Option<f64>| x.map_or("-".into(), |x| format!("{:.0}%", 100.0 * x));
        println!(
            "| {} | {} | {} | {:.0}% | {} | {} | {} | {} | {} |",
            r.mesh,
            r.density,
            r.threads,
            100.0 * alias,
            percent(inversion),
            rejection.map_or("-".into(), |x| format!("{x:.1}×")),
            percent(flat),
            percent(batch.map(|b| r.msamples_per_s / b.msamples_per_s)),
            match (latency, batch) {
                (Some(l), Some(b)) => format!("{:.1} / {:.1}", l.msamples_per_s, b.msamples_per_s),
                _ => "-".into(),
            },
        );
        if let Some(flat) = flat
            && worst_flat.is_none_or(|(w, _)| flat < w)
        {
            worst_flat = Some((flat, r));
        }
        for (slot, ratio) in worst.iter_mut().zip([Some(alias), inversion]) {
            if let Some(ratio) = ratio
                && slot.is_none_or(|(w, _)| ratio < w)
            {
                *slot = Some((ratio, r));
            }
        }
    }
    println!();
    if let Some((ratio, r)) = worst_flat {
        println!(
            "- Lowest density rate against the uniform texture's (alias layout; Šik & Křivánek: at most 35% lower): {:.0}% ({}, {}, {} thread(s))",
            100.0 * ratio,
            r.mesh,
            r.density,
            r.threads
        );
    }
    let rounded = rows
        .iter()
        .filter(|r| r.value_tolerance > 0.0)
        .max_by(|a, b| a.value_tolerance.total_cmp(&b.value_tolerance));
    match rounded {
        Some(r) => println!(
            "- Values rounded to fit the alias columns: by at most {:.1e} (relative; {}, {})",
            r.value_tolerance, r.mesh, r.density
        ),
        None => println!("- Values rounded to fit the alias columns: none (every value exact)"),
    }
    for (name, w) in ["alias", "inversion"].iter().zip(worst) {
        if let Some((ratio, r)) = w {
            println!(
                "- Lowest density rate with the {name} layout: {:.0}% of the uniform sampler's ({}, {}, {} thread(s))",
                100.0 * ratio,
                r.mesh,
                r.density,
                r.threads
            );
        }
    }
    let mut worst_scaling: Option<(f64, &Row)> = None;
    for r in rows
        .iter()
        .filter(|r| r.method == "subdivision" && r.threads == 2)
    {
        if let Some(one) = find(&r.mesh, &r.density, "subdivision", 1) {
            let s = r.msamples_per_s / one.msamples_per_s;
            if worst_scaling.is_none_or(|(w, _)| s < w) {
                worst_scaling = Some((s, r));
            }
        }
    }
    if let Some((s, r)) = worst_scaling {
        println!(
            "- Two threads / one thread (alias layout): lowest {s:.2}× ({}, {})",
            r.mesh, r.density
        );
    }
    let rng = rows.iter().find(|r| r.method == "rng" && r.threads == 1);
    if let Some(rng) = rng
        && let Some(u) = rows
            .iter()
            .find(|r| r.method == "uniform-sampler" && r.threads == 1 && r.mesh.contains("bunny"))
    {
        println!(
            "- One thread, {}: {:.1} ns per uniform point, {:.1} ns for its three random u64 ({:.2}×)",
            u.mesh,
            1e3 / u.msamples_per_s,
            1e3 / rng.msamples_per_s,
            rng.msamples_per_s / u.msamples_per_s
        );
    }
}

/// Our uniform sampler against trimesh and Open3D at N = 10⁷, all storing
/// the positions (the peers return arrays; trimesh adds face indices).
fn peers(m: &TestMesh, file: &Path, threads: &[usize], json: bool) -> Result<(), String> {
    let mesh = m.mesh();
    let uniform = UniformSampler::new(mesh).map_err(|e| e.to_string())?;
    let mut ours = Vec::new();
    for &t in threads {
        let times: Vec<f64> = pool(t)?.install(|| {
            (0..3)
                .map(|seed| {
                    let start = Instant::now();
                    black_box(uniform.sample_positions(seed, PEER_N).unwrap());
                    start.elapsed().as_secs_f64()
                })
                .collect()
        });
        ours.push((t, PEER_N as f64 / median(times) / 1e6));
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("bench/peers.sh");
    eprintln!("running the Python peers (first run installs them into target/peers-venv)…");
    let out = Command::new("bash")
        .arg(&script)
        .arg(file)
        .arg(PEER_N.to_string())
        .arg("3")
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("{}: {e}", script.display()))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let field = |line: &str, key: &str| -> Option<String> {
        let at = line.find(&format!("\"{key}\": "))? + key.len() + 4;
        let rest = &line[at..];
        let end = rest.find([',', '}'])?;
        Some(rest[..end].trim_matches('"').to_string())
    };
    let mut peer_rates = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{')) {
        let peer = field(line, "peer").unwrap_or_default();
        match field(line, "msamples_per_s").and_then(|v| v.parse::<f64>().ok()) {
            Some(r) => peer_rates.push((peer, r)),
            None => eprintln!("peer {peer} failed: {line}"),
        }
    }
    if json {
        for (t, r) in &ours {
            println!(
                "{{\"mesh\": \"{}\", \"density\": \"uniform\", \"method\": \"uniform-sample-positions\", \"msamples_per_s\": {r:.3}, \"threads\": {t}, \"n\": {PEER_N}}}",
                m.name
            );
        }
        for line in text.lines().filter(|l| l.starts_with('{')) {
            println!("{line}");
        }
        return Ok(());
    }
    println!(
        "\n## Against trimesh and Open3D ({}, N = 10⁷, positions stored)\n",
        m.name
    );
    println!("| sampler | threads | M samples/s |");
    println!("|---|---:|---:|");
    for (t, r) in &ours {
        println!("| mesh-sampling UniformSampler::sample_positions | {t} | {r:.1} |");
    }
    for (peer, r) in &peer_rates {
        println!("| {peer} | 1 | {r:.2} |");
    }
    println!();
    for (peer, r) in &peer_rates {
        if let Some((_, ours)) = ours.iter().find(|(t, _)| *t == 1) {
            println!("- one thread against {peer} (one thread): {:.1}×", ours / r);
        }
    }
    Ok(())
}

/// A 64 × 64 grid (8,192 triangles) over a bumpy square, its UVs
/// spanning `[lo, hi]²`.
fn tiled_grid(lo: f32, hi: f32) -> TestMesh {
    let n = 64u32;
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for y in 0..=n {
        for x in 0..=n {
            let (s, t) = (x as f32 / n as f32, y as f32 / n as f32);
            let z = 0.1 * (7.0 * s).sin() * (5.0 * t).cos();
            positions.push(Vec3::new(s, t, z));
            uvs.push(Vec2::new(lo + (hi - lo) * s, lo + (hi - lo) * t));
        }
    }
    let at = |x: u32, y: u32| y * (n + 1) + x;
    let mut indices = Vec::new();
    for y in 0..n {
        for x in 0..n {
            indices.push([at(x, y), at(x + 1, y), at(x, y + 1)]);
            indices.push([at(x + 1, y), at(x + 1, y + 1), at(x, y + 1)]);
        }
    }
    TestMesh {
        name: format!("grid UV [{lo}, {hi}]²"),
        positions,
        uvs,
        indices,
    }
}

/// Tiled UVs: the same mesh with UVs in `[0, 1]²` and in `[−8, 8]²` (the
/// texture tiled 256 times), with a constant and a noise density:
/// preprocessing time against the uniform sampler's build, pieces, memory.
fn print_tiled(textures: &[(String, DensityTexture)]) -> Result<(), String> {
    println!("\n## Tiled UVs (64 × 64 grid, 8,192 triangles, 1024² textures, default options)\n");
    println!(
        "| UVs | density | uniform sampler build ms | density build ms | ratio | pieces | memory MB | rejection build ms |"
    );
    println!("|---|---|---:|---:|---:|---:|---:|---:|");
    let mut noise_ms = Vec::new();
    for (lo, hi) in [(0.0, 1.0), (-8.0, 8.0)] {
        let m = tiled_grid(lo, hi);
        let mesh = m.mesh();
        let (uniform_ms, _) = build(|| UniformSampler::new(mesh));
        for (name, texture) in textures
            .iter()
            .filter(|(n, _)| n == "uniform" || n == "perlin16")
        {
            let (ms, sampler) = build(|| DensitySampler::new(mesh, Density::Texture(texture)));
            let sampler = sampler.map_err(|e| format!("{}, {name}: {e}", m.name))?;
            // Rejection integrates exactly: O(1) per face on a constant
            // footprint, one step per texel cell otherwise.
            let rejection = if name == "uniform" {
                let (ms, r) = build(|| RejectionSampler::new(mesh, texture));
                r.map_err(|e| e.to_string())?;
                format!("{ms:.1}")
            } else {
                "-".into()
            };
            if name != "uniform" {
                noise_ms.push(ms);
            }
            println!(
                "| [{lo}, {hi}]² | {name} | {uniform_ms:.1} | {ms:.1} | {:.2}× | {} | {:.1} | {rejection} |",
                ms / uniform_ms,
                sampler.pieces(),
                sampler.memory_bytes() as f64 / 1e6,
            );
        }
    }
    if let [unit, tiled] = noise_ms[..] {
        println!(
            "\n- Noise density, UVs in [−8, 8]² against [0, 1]²: {:.2}× the preprocessing time (piece budget {})",
            tiled / unit,
            mesh_sampling::DEFAULT_MAX_PIECES
        );
    }
    Ok(())
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let meshes = load_meshes(args.mesh.as_deref())?;
    let textures = densities(args.density.as_deref())?;
    let mut rows = Vec::new();
    for &t in &args.threads {
        let r = pool(t)?.install(rng_rate);
        let rng_row = Row {
            mesh: String::new(),
            triangles: 0,
            density: String::new(),
            method: "rng",
            threads: t,
            msamples_per_s: r,
            preprocess_ms: 0.0,
            memory_mb: 0.0,
            max_over_mean: 1.0,
            acceptance: 1.0,
            pieces: 0,
            paired: None,
            value_tolerance: 0.0,
        };
        if args.json {
            println!("{}", rng_row.json());
        }
        rows.push(rng_row);
    }
    for m in &meshes {
        for &t in &args.threads {
            let uniform = UniformSampler::new(m.mesh()).map_err(|e| e.to_string())?;
            let (ms, _) = build(|| UniformSampler::new(m.mesh()));
            let r = pool(t)?.install(|| rate(&uniform));
            let row = Row {
                mesh: m.name.clone(),
                triangles: m.indices.len(),
                density: "-".into(),
                method: "uniform-sampler",
                threads: t,
                msamples_per_s: r,
                preprocess_ms: ms,
                memory_mb: uniform.memory_bytes() as f64 / 1e6,
                max_over_mean: 1.0,
                acceptance: 1.0,
                pieces: m.indices.len(),
                paired: None,
                value_tolerance: 0.0,
            };
            if args.json {
                println!("{}", row.json());
            }
            rows.push(row);
        }
        for (name, texture) in &textures {
            for &t in &args.threads {
                eprintln!("{} / {name} / {t} thread(s)…", m.name);
                let measured = pool(t)?.install(|| measure_pair(m, name, texture, t, args.bar))?;
                if args.json {
                    for r in &measured {
                        println!("{}", r.json());
                    }
                }
                rows.extend(measured);
            }
        }
    }
    if !args.json && !rows.is_empty() {
        println!("# mesh-sampling: Šik & Křivánek 2013, Fig. 10 and Table 1\n");
        print_markdown(&rows);
        print_summary(&rows);
    }
    if args.tiled {
        let all = densities(None)?;
        print_tiled(&all)?;
    }
    if args.peers
        && let Some(bunny) = meshes.iter().find(|m| m.name.contains("bunny"))
        && let Some(dir) = data::data_dir()
    {
        peers(
            bunny,
            &dir.join("meshes").join(&bunny.name),
            &args.threads,
            args.json,
        )?;
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
