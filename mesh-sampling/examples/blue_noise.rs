//! Blue-noise points on the data meshes by weighted sample elimination
//! (`trilux`) and by the dense packing (`trilux-dense`: elimination of 14
//! candidates per point, then farthest-point relocation), beside Open3D's
//! `sample_points_poisson_disk` timed in the same run.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p mesh-sampling --example blue_noise -- [--json] [--no-peers] [--n 10000,100000] [--mesh spot] [--packing elimination,dense]
//! ```
//!
//! For each of the Stanford bunny, spot and fandisk, at N = 10⁴, 10⁵ and
//! 10⁶: uniform blue noise and blue noise following a 3D Perlin-noise
//! density (per-vertex weights `exp(2·noise)`, about 1:20 from darkest to
//! brightest), on 1 and 2 threads; the time (median of three runs below
//! 10⁶ points, one run at 10⁶), output points per second, the relative
//! radius ρ of Lagae & Dutré (1 for a hexagonal packing; with a density,
//! each point's spacing is measured against its own density's packing
//! radius, `relative_radius_with_density`) and the number of candidates. Open3D (uniform only: it takes no density) is run through
//! `bench/peers.sh`, which sets up a venv under `target/` on first use; its
//! points come back through a file so that ρ is measured the same way.
//! With `--peer-cy BIN`, Yuksel's own C++ elimination (cySampleElim, not
//! part of this repository) is timed on the very candidates trilux's
//! elimination draws (5 N uniform points for seed 0, written to a file):
//! `BIN CANDIDATES.f32 N AREA OUT.f32` must eliminate the little-endian
//! `f32` triples to N, write them to OUT.f32 and print `{"ms": …}` with
//! the time of the elimination alone; ρ is measured here.
//! Markdown on stdout, or with `--json` one object per line with the keys
//! `mesh`, `density`, `n`, `tool`, `threads`, `ms`, `rho`, `candidates`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use glam::Vec3;
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Density, DensitySampler, MeshRef, Packing, SurfaceArea,
    SurfaceSampler, UniformSampler, blue_noise, relative_radius, relative_radius_with_density,
};

const MESHES: [&str; 3] = ["stanford-bunny", "spot", "fandisk"];

struct Args {
    json: bool,
    peers: bool,
    counts: Vec<usize>,
    meshes: Vec<String>,
    packings: Vec<Packing>,
    peer_cy: Option<PathBuf>,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        peers: true,
        counts: vec![10_000, 100_000, 1_000_000],
        meshes: MESHES.iter().map(ToString::to_string).collect(),
        packings: vec![Packing::Elimination, Packing::Dense],
        peer_cy: None,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--json" => args.json = true,
            "--no-peers" => args.peers = false,
            "--n" => {
                let list = it
                    .next()
                    .ok_or("--n needs a comma-separated list of counts")?;
                args.counts = list
                    .split(',')
                    .map(|s| {
                        s.trim()
                            .parse()
                            .map_err(|_| format!("--n: '{s}' is not a count"))
                    })
                    .collect::<Result<_, _>>()?;
            }
            "--mesh" => {
                let list = it
                    .next()
                    .ok_or("--mesh needs a comma-separated list of mesh names")?;
                args.meshes = list.split(',').map(|s| s.trim().to_string()).collect();
            }
            "--peer-cy" => {
                args.peer_cy = Some(PathBuf::from(
                    it.next()
                        .ok_or("--peer-cy needs the path of the cySampleElim driver")?,
                ));
            }
            "--packing" => {
                let list = it
                    .next()
                    .ok_or("--packing needs a comma-separated list of elimination, dense")?;
                args.packings = list
                    .split(',')
                    .map(|s| match s.trim() {
                        "elimination" => Ok(Packing::Elimination),
                        "dense" => Ok(Packing::Dense),
                        other => Err(format!(
                            "--packing: '{other}' is not a packing (elimination or dense)"
                        )),
                    })
                    .collect::<Result<_, _>>()?;
            }
            other => {
                return Err(format!(
                    "unknown argument '{other}' (try --json, --no-peers, --n, --mesh, --packing, --peer-cy)"
                ));
            }
        }
    }
    Ok(args)
}

/// One measured configuration.
struct Row {
    mesh: &'static str,
    density: &'static str,
    n: usize,
    tool: String,
    threads: usize,
    ms: f64,
    rho: f64,
    candidates: usize,
}

impl Row {
    fn json(&self) -> String {
        format!(
            "{{\"mesh\": \"{}\", \"density\": \"{}\", \"n\": {}, \"tool\": \"{}\", \"threads\": {}, \"ms\": {:.2}, \"rho\": {:.4}, \"candidates\": {}}}",
            self.mesh,
            self.density,
            self.n,
            self.tool,
            self.threads,
            self.ms,
            self.rho,
            self.candidates
        )
    }
}

/// Smooth 3D gradient noise (Perlin 2002) in about [-1, 1].
fn perlin(p: Vec3) -> f32 {
    let hash = |x: i32, y: i32, z: i32| -> u32 {
        let mut h = (x as u32).wrapping_mul(0x8DA6_B343)
            ^ (y as u32).wrapping_mul(0xD816_3841)
            ^ (z as u32).wrapping_mul(0xCB1A_B31F);
        h ^= h >> 15;
        h = h.wrapping_mul(0x2C1B_3C6D);
        h ^ (h >> 12)
    };
    let grad = |h: u32, d: Vec3| -> f32 {
        // The 12 edge directions of a cube.
        let (u, v) = match h % 12 {
            0..=3 => (d.x, d.y),
            4..=7 => (d.x, d.z),
            _ => (d.y, d.z),
        };
        (if h & 1 == 0 { u } else { -u }) + (if h & 2 == 0 { v } else { -v })
    };
    let fade = |t: f32| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let cell = p.floor();
    let f = p - cell;
    let (x, y, z) = (cell.x as i32, cell.y as i32, cell.z as i32);
    let mut corners = [0.0f32; 8];
    for (k, c) in corners.iter_mut().enumerate() {
        let o = Vec3::new((k & 1) as f32, ((k >> 1) & 1) as f32, (k >> 2) as f32);
        *c = grad(hash(x + o.x as i32, y + o.y as i32, z + o.z as i32), f - o);
    }
    let (u, v, w) = (fade(f.x), fade(f.y), fade(f.z));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(corners[0], corners[1], u);
    let x10 = lerp(corners[2], corners[3], u);
    let x01 = lerp(corners[4], corners[5], u);
    let x11 = lerp(corners[6], corners[7], u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

/// Per-vertex weights `exp(2·noise)` with about four noise periods across
/// the mesh's bounding box.
fn noise_weights(positions: &[Vec3]) -> Vec<f32> {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(a, b), &p| (a.min(p), b.max(p)),
    );
    let scale = 4.0 / (hi - lo).max_element();
    positions
        .iter()
        .map(|&p| (2.0 * perlin((p - lo) * scale)).exp())
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())
}

/// Times `blue_noise` on `sampler` and measures the spacing of its output.
fn ours<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    n: usize,
    threads: usize,
    options: &BlueNoiseOptions,
) -> Result<(f64, f64), String> {
    let runs = if n >= 1_000_000 { 1 } else { 3 };
    let mut times = Vec::new();
    let mut points = Vec::new();
    for seed in 0..runs {
        let start = Instant::now();
        points = pool(threads)?
            .install(|| blue_noise(sampler, BlueNoiseTarget::Count(n), seed as u64, options))
            .map_err(|e| e.to_string())?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    let xyz: Vec<Vec3> = points.iter().map(|p| p.position).collect();
    let pdf: Vec<f32> = points.iter().map(|p| p.pdf).collect();
    Ok((median(times), relative_radius_with_density(&xyz, &pdf)))
}

/// Points stored as little-endian `f32` triples (what the peers write).
fn read_points(path: &Path) -> Result<Vec<Vec3>, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(bytes
        .chunks_exact(12)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
            Vec3::new(f(0), f(4), f(8))
        })
        .collect())
}

/// cySampleElim's time (ms, the elimination alone, as the driver reports
/// it) and ρ on trilux's own candidates for `n` points (seed 0).
fn cy_sample_elim(
    bin: &Path,
    sampler: &UniformSampler<'_>,
    n: usize,
) -> Result<(f64, f64), String> {
    let dir = std::env::temp_dir().join(format!("trilux-cy-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let candidates = sampler
        .sample_positions(0, 5 * n)
        .map_err(|e| e.to_string())?;
    let bytes: Vec<u8> = candidates
        .iter()
        .flatten()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let (input, output) = (dir.join("candidates.f32"), dir.join("out.f32"));
    std::fs::write(&input, bytes).map_err(|e| format!("{}: {e}", input.display()))?;
    let area = sampler.surface_area();
    let out = Command::new(bin)
        .arg(&input)
        .arg(n.to_string())
        .arg(area.to_string())
        .arg(&output)
        .output()
        .map_err(|e| format!("{}: {e}", bin.display()))?;
    if !out.status.success() {
        return Err(format!(
            "{} failed: {}",
            bin.display(),
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let ms: f64 = text
        .split("\"ms\":")
        .nth(1)
        .and_then(|rest| rest.split([',', '}']).next())
        .and_then(|v| v.trim().parse().ok())
        .ok_or_else(|| format!("{}: no \"ms\" in its output {text:?}", bin.display()))?;
    let xyz = read_points(&output)?;
    let _ = std::fs::remove_dir_all(&dir);
    Ok((ms, relative_radius(&xyz, area)))
}

/// Open3D's rows for `file`, or an explanation of why there are none.
fn open3d(file: &Path, counts: &[usize], area: f64) -> Result<Vec<(usize, f64, f64)>, String> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out_dir = std::env::temp_dir().join(format!("trilux-blue-noise-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let output = Command::new("bash")
        .arg(here.join("bench/peers.sh"))
        .arg(file)
        .arg(&out_dir)
        .args(counts.iter().map(ToString::to_string))
        .env("PEER_SCRIPT", "blue_noise_peer.py")
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("bench/peers.sh: {e}"))?;
    let text = String::from_utf8_lossy(&output.stdout);
    let field = |line: &str, key: &str| -> Option<String> {
        let at = line.find(&format!("\"{key}\": "))? + key.len() + 4;
        let rest = &line[at..];
        let end = rest.find([',', '}'])?;
        Some(rest[..end].trim().trim_matches('"').to_string())
    };
    let mut rows = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{')) {
        if let Some(e) = field(line, "error") {
            eprintln!("Open3D: {e}");
            continue;
        }
        let n: usize = field(line, "n")
            .and_then(|v| v.parse().ok())
            .ok_or("Open3D: no n")?;
        let ms: f64 = field(line, "ms")
            .and_then(|v| v.parse().ok())
            .ok_or("Open3D: no ms")?;
        let path = PathBuf::from(field(line, "points").ok_or("Open3D: no points file")?);
        let xyz = read_points(&path)?;
        rows.push((n, ms, relative_radius(&xyz, area)));
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    Ok(rows)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").ok_or(
        "set TRILUX_DATA to the data folder (for example ../shared/data): the benchmark reads its meshes",
    )?);
    let mut rows: Vec<Row> = Vec::new();
    for name in &args.meshes {
        let name: &'static str = MESHES
            .iter()
            .find(|m| *m == name)
            .ok_or_else(|| format!("--mesh: no data mesh '{name}' (one of {MESHES:?})"))?;
        let file = dir.join(format!("meshes/{name}.obj"));
        let mesh = trilux_io::mesh::TriMesh::read(&file).map_err(|e| e.to_string())?;
        let mesh_ref = MeshRef::new(&mesh.positions, &mesh.indices);
        let uniform = UniformSampler::new(mesh_ref).map_err(|e| e.to_string())?;
        let weights = noise_weights(&mesh.positions);
        let noisy = DensitySampler::new(mesh_ref, Density::PerVertex(&weights))
            .map_err(|e| e.to_string())?;
        for &n in &args.counts {
            for &packing in &args.packings {
                let (tool, options) = match packing {
                    Packing::Elimination => ("trilux", BlueNoiseOptions::default()),
                    Packing::Dense => ("trilux-dense", BlueNoiseOptions::dense()),
                };
                let candidates = (options.candidate_factor * n as f64).ceil() as usize;
                for threads in [1, 2] {
                    eprintln!("{name}, N = {n}, {tool}, {threads} thread(s)…");
                    for (density, row) in [
                        ("uniform", ours(&uniform, n, threads, &options)?),
                        ("perlin", ours(&noisy, n, threads, &options)?),
                    ] {
                        rows.push(Row {
                            mesh: name,
                            density,
                            n,
                            tool: tool.into(),
                            threads,
                            ms: row.0,
                            rho: row.1,
                            candidates,
                        });
                    }
                }
            }
        }
        if let Some(bin) = &args.peer_cy {
            for &n in &args.counts {
                eprintln!("{name}, N = {n}: cySampleElim…");
                match cy_sample_elim(bin, &uniform, n) {
                    Ok((ms, rho)) => rows.push(Row {
                        mesh: name,
                        density: "uniform",
                        n,
                        tool: "cySampleElim".into(),
                        threads: rayon::current_num_threads(),
                        ms,
                        rho,
                        candidates: 5 * n,
                    }),
                    Err(e) => eprintln!("cySampleElim did not run: {e}"),
                }
            }
        }
        if args.peers {
            eprintln!("{name}: Open3D (first run installs it into target/peers-venv)…");
            match open3d(&file, &args.counts, uniform.surface_area()) {
                Ok(peer) => {
                    for (n, ms, rho) in peer {
                        rows.push(Row {
                            mesh: name,
                            density: "uniform",
                            n,
                            tool: "open3d".into(),
                            threads: 1,
                            ms,
                            rho,
                            candidates: 5 * n,
                        });
                    }
                }
                Err(e) => eprintln!("Open3D did not run: {e}"),
            }
        }
    }
    if args.json {
        for r in &rows {
            println!("{}", r.json());
        }
        return Ok(());
    }
    println!("| mesh | density | N | tool | threads | ms | M points/s | ρ | candidates |");
    println!("|---|---|---:|---|---:|---:|---:|---:|---:|");
    for r in &rows {
        println!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.3} | {:.3} | {} |",
            r.mesh,
            r.density,
            r.n,
            r.tool,
            r.threads,
            r.ms,
            r.n as f64 / r.ms / 1e3,
            r.rho,
            r.candidates
        );
    }
    for peer in ["open3d", "cySampleElim"] {
        if !rows.iter().any(|r| r.tool == peer) {
            continue;
        }
        println!("\nSpeed against {peer} at the same N (uniform; points/s ratio):\n");
        for r in rows.iter().filter(|r| r.tool == peer) {
            for t in [1, 2] {
                for tool in ["trilux", "trilux-dense"] {
                    if let Some(o) = rows.iter().find(|o| {
                        o.tool == tool
                            && o.mesh == r.mesh
                            && o.n == r.n
                            && o.density == "uniform"
                            && o.threads == t
                    }) {
                        println!(
                            "- {} N = {}, {tool}, {t} thread(s): {:.1}× {peer}'s rate, ρ {:.3} vs {:.3}",
                            r.mesh,
                            r.n,
                            r.ms / o.ms,
                            o.rho,
                            r.rho
                        );
                    }
                }
            }
        }
    }
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
