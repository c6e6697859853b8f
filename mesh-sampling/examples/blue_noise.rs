//! Blue-noise points on the data meshes by weighted sample elimination
//! (`trilux`) and by the dense packing (`trilux-dense`: elimination of 14
//! candidates per point, then farthest-point relocation), beside Open3D's
//! `sample_points_poisson_disk` and MeshLab's Poisson-disk sampling timed in
//! the same run, and optionally Yuksel's own C++ elimination.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p mesh-sampling --example blue_noise -- [--json] [--no-peers] [--n 10000,100000] [--mesh spot] [--packing elimination,dense] [--threads 1,2] [--peer-cy auto|BIN] [--blender auto|PYTHON]
//! ```
//!
//! For each of the Stanford bunny, spot and fandisk, at N = 10⁴, 10⁵ and
//! 10⁶: uniform blue noise and blue noise following a 3D Perlin-noise
//! density (per-vertex weights `exp(2·noise)`, about 1:20 from darkest to
//! brightest), on 1 and 2 threads; the time (median of three runs below
//! 10⁶ points, one run at 10⁶), output points per second, the relative
//! radius ρ of Lagae & Dutré (1 for a hexagonal packing; with a density,
//! each point's spacing is measured against its own density's packing
//! radius, `relative_radius_with_density`) and the number of candidates.
//!
//! **Python peers** (uniform only: they take no density) run through
//! `bench/peers.sh` with `bench/blue_noise_peer.py`, which sets up a venv
//! under `target/` on first use (numpy, open3d-cpu, pymeshlab); their points
//! come back through a file so that ρ is measured the same way. Open3D's
//! `sample_points_poisson_disk(N)` returns N points; MeshLab's
//! `generate_sampling_poisson_disk(samplenum = N)` (pymeshlab, defaults)
//! returns a count near N but not N (about 1.46 N on the bunny), so its row
//! shows its own count, its ρ is measured at that count and the speed
//! ratios compare points per second. `cpu_ms / ms` of the peer script gives
//! the peers' thread count (both keep one thread busy).
//!
//! **cySampleElim.** With `--peer-cy BIN`, Yuksel's own C++ elimination
//! (cySampleElim.h of his cyCodeBase, not part of this repository) is timed
//! on the very candidates trilux's elimination draws (5 N uniform points
//! for seed 0, written to a file): `BIN CANDIDATES.f32 N AREA OUT.f32` must
//! eliminate the little-endian `f32` triples to N, write them to OUT.f32
//! and print `{"ms": …, "threads": …}` with the time of the elimination
//! alone; ρ is measured here. `bench/cy_sample_elim.cpp` is such a driver,
//! with the library's default weight function (α = 8, weight limiting
//! β = 0.65, γ = 1.5), Euclidean 3D distances and the weight radius
//! `2 r_max` of N disks over the surface area, as trilux's. `--peer-cy auto`
//! builds it into `target/peer-cy/`: set `CYCODEBASE` to a checkout of
//! cyCodeBase (or its bare git directory; its `HEAD` is read) on the first
//! run, which copies the five headers it needs to
//! `target/peer-cy/include/`; later runs reuse them. It compiles with
//! `${CXX:-g++} -O3 -march=native`, against TBB when `-ltbb` links (Debian:
//! `apt-get install libtbb-dev`): cySampleElim is sequential except for its
//! k-d tree build, which only TBB parallelises, and the row's thread count
//! is what the driver reports. For example
//!
//! ```sh
//! CYCODEBASE=/path/to/cyCodeBase TRILUX_DATA=../shared/data cargo run --release -p mesh-sampling --example blue_noise -- --n 100000 --packing elimination,dense --peer-cy auto
//! ```
//!
//! Markdown on stdout, or with `--json` one object per line with the keys
//! `mesh`, `density`, `n`, `points` (the output count: N except MeshLab's),
//! `tool`, `threads`, `ms`, `rho`, `candidates`.

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::Vec3;
use mesh_sampling::{
    BlueNoiseOptions, BlueNoiseTarget, Density, DensitySampler, MeshRef, Packing, SurfaceArea,
    SurfaceSampler, UniformSampler, blue_noise, relative_radius, relative_radius_with_density,
};

const MESHES: [&str; 3] = ["stanford-bunny", "spot", "fandisk"];

/// The system allocator, counting the bytes live and their peak: the
/// memory column is the peak during a `blue_noise` call over what was live
/// before it (the mesh and sampler are not counted, the output is).
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards to the system allocator; only counts.
#[expect(
    unsafe_code,
    reason = "a counting global allocator is the honest way to measure peak memory"
)]
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is passed on unchanged.
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as above.
        let p = unsafe { System.alloc_zeroed(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as above.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            let live = if new_size >= layout.size() {
                LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed) + new_size
                    - layout.size()
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed)
                    - (layout.size() - new_size)
            };
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns its result with the peak bytes allocated during
/// it above what was live before.
fn peak_during<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed).saturating_sub(base))
}

struct Args {
    json: bool,
    peers: bool,
    counts: Vec<usize>,
    meshes: Vec<String>,
    packings: Vec<Packing>,
    peer_cy: Option<PeerCy>,
    threads: Vec<usize>,
    /// Blender's Python (`bench/blender_scatter.py`), for the scatter rows.
    blender: Option<PathBuf>,
}

/// Where the cySampleElim driver comes from.
enum PeerCy {
    /// A driver built elsewhere.
    Bin(PathBuf),
    /// `bench/cy_sample_elim.cpp`, built into `target/peer-cy/`.
    Auto,
}

fn parse_args() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        peers: true,
        counts: vec![10_000, 100_000, 1_000_000],
        meshes: MESHES.iter().map(ToString::to_string).collect(),
        packings: vec![Packing::Elimination, Packing::Dense],
        peer_cy: None,
        threads: vec![1, 2],
        blender: None,
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
            "--blender" => {
                let py = it
                    .next()
                    .ok_or("--blender needs Blender's Python (auto: target/bpy-venv/bin/python)")?;
                args.blender = Some(if py == "auto" {
                    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bpy-venv/bin/python")
                } else {
                    PathBuf::from(py)
                });
            }
            "--threads" => {
                let list = it
                    .next()
                    .ok_or("--threads needs a comma-separated list of thread counts")?;
                args.threads = list
                    .split(',')
                    .map(|s| {
                        s.trim()
                            .parse()
                            .map_err(|_| format!("--threads: '{s}' is not a count"))
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
                let bin = it
                    .next()
                    .ok_or("--peer-cy needs the path of the cySampleElim driver, or auto")?;
                args.peer_cy = Some(if bin == "auto" {
                    PeerCy::Auto
                } else {
                    PeerCy::Bin(PathBuf::from(bin))
                });
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
                    "unknown argument '{other}' (try --json, --no-peers, --n, --mesh, --packing, --threads, --peer-cy, --blender)"
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
    /// The output count: `n`, except for MeshLab's rows.
    points: usize,
    tool: String,
    threads: usize,
    ms: f64,
    rho: f64,
    candidates: usize,
    /// Peak bytes per output point during the call (0: not measured).
    bytes_per_point: f64,
}

impl Row {
    fn json(&self) -> String {
        format!(
            "{{\"mesh\": \"{}\", \"density\": \"{}\", \"n\": {}, \"points\": {}, \"tool\": \"{}\", \"threads\": {}, \"ms\": {:.2}, \"rho\": {:.4}, \"candidates\": {}, \"bytes_per_point\": {:.1}}}",
            self.mesh,
            self.density,
            self.n,
            self.points,
            self.tool,
            self.threads,
            self.ms,
            self.rho,
            self.candidates,
            self.bytes_per_point
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

/// Times `blue_noise` on `sampler` and measures the spacing of its output
/// and the peak memory of the call: (ms, ρ, bytes per output point).
fn ours<S: SurfaceSampler + SurfaceArea>(
    sampler: &S,
    n: usize,
    threads: usize,
    options: &BlueNoiseOptions,
) -> Result<(f64, f64, f64), String> {
    let runs = if n >= 1_000_000 { 1 } else { 3 };
    let mut times = Vec::new();
    let mut points = Vec::new();
    let mut peak = 0;
    let pool = pool(threads)?;
    for seed in 0..runs {
        drop(std::mem::take(&mut points));
        let start = Instant::now();
        let (result, bytes) = peak_during(|| {
            pool.install(|| blue_noise(sampler, BlueNoiseTarget::Count(n), seed as u64, options))
        });
        times.push(start.elapsed().as_secs_f64() * 1e3);
        points = result.map_err(|e| e.to_string())?;
        peak = peak.max(bytes);
    }
    let xyz: Vec<Vec3> = points.iter().map(|p| p.position).collect();
    let pdf: Vec<f32> = points.iter().map(|p| p.pdf).collect();
    Ok((
        median(times),
        relative_radius_with_density(&xyz, &pdf),
        peak as f64 / n as f64,
    ))
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

/// A JSON line's value for `key` (numbers and strings without commas).
fn field(line: &str, key: &str) -> Option<String> {
    let at = line.find(&format!("\"{key}\": "))? + key.len() + 4;
    let rest = &line[at..];
    let end = rest.find([',', '}'])?;
    Some(rest[..end].trim().trim_matches('"').to_string())
}

/// The cySampleElim driver's source (`--peer-cy auto` compiles it).
const CY_DRIVER: &str = include_str!("../bench/cy_sample_elim.cpp");

/// The cyCodeBase headers the driver includes, directly or not.
const CY_HEADERS: [&str; 5] = [
    "cyCore.h",
    "cyHeap.h",
    "cyPointCloud.h",
    "cySampleElim.h",
    "cyVector.h",
];

/// Builds `bench/cy_sample_elim.cpp` into `target/peer-cy/` (headers from
/// `$CYCODEBASE`, a checkout or a bare git directory, or from an earlier
/// run) and returns the driver's path. Rebuilds only when the source or a
/// header changed.
fn build_cy_driver() -> Result<PathBuf, String> {
    let target = std::env::var_os("CARGO_TARGET_DIR").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../target"),
        PathBuf::from,
    );
    let dir = target.join("peer-cy");
    let include = dir.join("include");
    std::fs::create_dir_all(&include).map_err(|e| format!("{}: {e}", include.display()))?;
    let mut changed = false;
    let mut put = |path: &Path, bytes: &[u8]| -> Result<(), String> {
        if std::fs::read(path).ok().as_deref() != Some(bytes) {
            std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))?;
            changed = true;
        }
        Ok(())
    };
    if let Some(source) = std::env::var_os("CYCODEBASE").map(PathBuf::from) {
        for header in CY_HEADERS {
            let bytes = if source.join(header).is_file() {
                std::fs::read(source.join(header))
                    .map_err(|e| format!("{}: {e}", source.join(header).display()))?
            } else {
                let out = Command::new("git")
                    .arg("--git-dir")
                    .arg(&source)
                    .arg("show")
                    .arg(format!("HEAD:{header}"))
                    .output()
                    .map_err(|e| format!("git: {e}"))?;
                if !out.status.success() {
                    return Err(format!(
                        "CYCODEBASE={}: no {header} there, nor in its git HEAD ({})",
                        source.display(),
                        String::from_utf8_lossy(&out.stderr).trim()
                    ));
                }
                out.stdout
            };
            put(&include.join(header), &bytes)?;
        }
    } else if let Some(missing) = CY_HEADERS.iter().find(|h| !include.join(h).is_file()) {
        return Err(format!(
            "--peer-cy auto: no {missing} in {}; set CYCODEBASE to a checkout of Cem Yuksel's \
             cyCodeBase (or its bare git directory) once, and its headers are copied there",
            include.display()
        ));
    }
    let source = dir.join("cy_sample_elim.cpp");
    put(&source, CY_DRIVER.as_bytes())?;
    let bin = dir.join("cy_sample_elim");
    if bin.is_file() && !changed {
        return Ok(bin);
    }
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "g++".to_string());
    let compile = |tbb: bool| -> Result<std::process::Output, String> {
        let mut cmd = Command::new(&cxx);
        cmd.args(["-O3", "-march=native", "-std=c++17"]);
        if tbb {
            cmd.arg("-DTRILUX_CY_TBB");
        }
        cmd.arg("-I").arg(&include).arg(&source).arg("-o").arg(&bin);
        if tbb {
            cmd.arg("-ltbb");
        }
        eprintln!("building the cySampleElim driver: {cmd:?}");
        cmd.output().map_err(|e| format!("{cxx}: {e}"))
    };
    let with_tbb = compile(true)?;
    if with_tbb.status.success() {
        return Ok(bin);
    }
    eprintln!("(no TBB: cySampleElim's k-d tree build stays sequential)");
    let plain = compile(false)?;
    if !plain.status.success() {
        return Err(format!(
            "{cxx} could not build {}: {}",
            source.display(),
            String::from_utf8_lossy(&plain.stderr)
        ));
    }
    Ok(bin)
}

/// cySampleElim's time (ms, the elimination alone, as the driver reports
/// it), ρ and thread count on trilux's own candidates for `n` points
/// (seed 0).
fn cy_sample_elim(
    bin: &Path,
    sampler: &UniformSampler<'_>,
    n: usize,
) -> Result<(f64, f64, usize), String> {
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
    let ms: f64 = field(&text, "ms")
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| format!("{}: no \"ms\" in its output {text:?}", bin.display()))?;
    // A driver that does not say runs on one thread.
    let threads = field(&text, "threads")
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let xyz = read_points(&output)?;
    let _ = std::fs::remove_dir_all(&dir);
    if xyz.len() != n {
        return Err(format!(
            "{} wrote {} points, not {n}",
            bin.display(),
            xyz.len()
        ));
    }
    Ok((ms, relative_radius(&xyz, area), threads))
}

/// One row of a Python peer.
struct PeerRow {
    tool: String,
    n: usize,
    points: usize,
    ms: f64,
    threads: usize,
    rho: f64,
}

/// Open3D's and MeshLab's rows for `file`, or an explanation of why there
/// are none.
fn python_peers(file: &Path, counts: &[usize], area: f64) -> Result<Vec<PeerRow>, String> {
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
    let mut rows = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{')) {
        let peer = field(line, "peer").ok_or("a peer line without \"peer\"")?;
        if let Some(e) = field(line, "error") {
            eprintln!("{peer}: {e}");
            continue;
        }
        let number = |key: &str| -> Result<f64, String> {
            field(line, key)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("{peer}: no {key} in {line}"))
        };
        let (ms, cpu_ms) = (number("ms")?, number("cpu_ms")?);
        let path =
            PathBuf::from(field(line, "file").ok_or_else(|| format!("{peer}: no points file"))?);
        let xyz = read_points(&path)?;
        let n = number("n")? as usize;
        rows.push(PeerRow {
            tool: peer,
            n,
            points: xyz.len(),
            ms,
            threads: (cpu_ms / ms).round().max(1.0) as usize,
            rho: relative_radius(&xyz, area),
        });
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    Ok(rows)
}

/// (tool, case, points, ms, ρ or NaN) of a scatter row.
type ScatterRow = (String, String, usize, f64, f64);

/// Blender's Distribute Points on Faces (`bench/blender_scatter.py`, run
/// by `python`, Blender as a module) on `file`, beside trilux's uniform and
/// per-vertex sampling of as many points (median of three, on the given
/// threads) and its blue noise at Blender's Poisson counts: rows of
/// (tool, case, points, ms, ρ or NaN).
fn blender_rows(
    python: &Path,
    file: &Path,
    mesh: &trilux_io::mesh::TriMesh,
    threads: usize,
) -> Result<Vec<ScatterRow>, String> {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out_dir = std::env::temp_dir().join(format!("trilux-blender-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let output = Command::new(python)
        .arg(here.join("bench/blender_scatter.py"))
        .arg(file)
        .arg(&out_dir)
        .stderr(std::process::Stdio::inherit())
        .output()
        .map_err(|e| format!("{}: {e}", python.display()))?;
    let text = String::from_utf8_lossy(&output.stdout);
    let mesh_ref = MeshRef::new(&mesh.positions, &mesh.indices);
    let uniform = UniformSampler::new(mesh_ref).map_err(|e| e.to_string())?;
    let area = uniform.surface_area();
    let pool = pool(threads)?;
    let time = |f: &(dyn Fn(u64) -> usize + Sync)| -> (f64, usize) {
        let mut ms = Vec::new();
        let mut count = 0;
        for seed in 0..3 {
            let start = Instant::now();
            count = pool.install(|| f(seed));
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        (median(ms), count)
    };
    let mut rows = Vec::new();
    for line in text.lines().filter(|l| l.starts_with('{')) {
        let case = field(line, "case").ok_or("a Blender line without \"case\"")?;
        let number = |key: &str| -> Result<f64, String> {
            field(line, key)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("blender {case}: no {key} in {line}"))
        };
        let (n, ms) = (number("n")? as usize, number("ms")?);
        let xyz = read_points(&PathBuf::from(
            field(line, "file").ok_or("a Blender line without \"file\"")?,
        ))?;
        let version = field(line, "version").unwrap_or_default();
        let tool = format!("Blender {version}");
        if case.starts_with("poisson") {
            rows.push((
                tool,
                case.clone(),
                xyz.len(),
                ms,
                relative_radius(&xyz, area),
            ));
            continue;
        }
        rows.push((tool, case.clone(), xyz.len(), ms, f64::NAN));
        if case == "random" {
            let (ms, count) =
                time(&|seed| uniform.sample_positions(seed, n).map_or(0, |p| p.len()));
            rows.push(("trilux".into(), case.clone(), count, ms, f64::NAN));
            // In face order, as Blender's node walks the faces: the same
            // independent points as a set, each group of faces in cache.
            let (ms, count) = time(&|seed| {
                uniform
                    .sample_positions_grouped(seed, n)
                    .map_or(0, |p| p.len())
            });
            rows.push((
                "trilux, grouped in face order".into(),
                case,
                count,
                ms,
                f64::NAN,
            ));
        } else if case == "random-vertex" {
            // Blender's per-vertex density, the same weights.
            let bytes = std::fs::read(out_dir.join("blender_vertex_weights.f32"))
                .map_err(|e| format!("Blender's vertex weights: {e}"))?;
            let w: Vec<f32> = bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect();
            let sampler =
                DensitySampler::new(mesh_ref, Density::PerVertex(&w)).map_err(|e| e.to_string())?;
            let (ms, count) =
                time(&|seed| sampler.sample_positions(seed, n).map_or(0, |p| p.len()));
            rows.push(("trilux".into(), case, count, ms, f64::NAN));
        }
    }
    // trilux's elimination at the count of Blender's Poisson rows.
    let counts: Vec<usize> = rows
        .iter()
        .filter(|r| r.1.starts_with("poisson"))
        .map(|r| r.2)
        .collect();
    if let Some(&n) = counts.first() {
        for (tool, options) in [
            ("trilux", BlueNoiseOptions::default()),
            ("trilux-dense", BlueNoiseOptions::dense()),
        ] {
            let (ms, rho, _) = ours(&uniform, n, threads, &options)?;
            rows.push((tool.into(), "blue noise".into(), n, ms, rho));
        }
    }
    let _ = std::fs::remove_dir_all(&out_dir);
    Ok(rows)
}

fn run() -> Result<(), String> {
    let args = parse_args()?;
    let dir = PathBuf::from(std::env::var_os("TRILUX_DATA").ok_or(
        "set TRILUX_DATA to the data folder (for example ../shared/data): the benchmark reads its meshes",
    )?);
    let peer_cy = match &args.peer_cy {
        None => None,
        Some(PeerCy::Bin(bin)) => Some(bin.clone()),
        Some(PeerCy::Auto) => Some(build_cy_driver()?),
    };
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
                for &threads in &args.threads {
                    eprintln!("{name}, N = {n}, {tool}, {threads} thread(s)…");
                    for (density, row) in [
                        ("uniform", ours(&uniform, n, threads, &options)?),
                        ("perlin", ours(&noisy, n, threads, &options)?),
                    ] {
                        rows.push(Row {
                            mesh: name,
                            density,
                            n,
                            points: n,
                            tool: tool.into(),
                            threads,
                            ms: row.0,
                            rho: row.1,
                            candidates,
                            bytes_per_point: row.2,
                        });
                    }
                }
            }
        }
        if let Some(bin) = &peer_cy {
            for &n in &args.counts {
                eprintln!("{name}, N = {n}: cySampleElim…");
                match cy_sample_elim(bin, &uniform, n) {
                    Ok((ms, rho, threads)) => rows.push(Row {
                        mesh: name,
                        density: "uniform",
                        n,
                        points: n,
                        tool: "cySampleElim".into(),
                        threads,
                        ms,
                        rho,
                        candidates: 5 * n,
                        bytes_per_point: 0.0,
                    }),
                    Err(e) => eprintln!("cySampleElim did not run: {e}"),
                }
            }
        }
        if args.peers {
            eprintln!(
                "{name}: Open3D and MeshLab (the first run installs them into target/peers-venv)…"
            );
            match python_peers(&file, &args.counts, uniform.surface_area()) {
                Ok(peer) => {
                    for r in peer {
                        // Open3D eliminates 5 N candidates; MeshLab throws
                        // darts at a Monte Carlo pool of 20 N points.
                        // (pcu's pool is VCG's own: not counted.)
                        let candidates = match r.tool.as_str() {
                            "meshlab" => 20 * r.n,
                            "pcu" => 0,
                            _ => 5 * r.n,
                        };
                        rows.push(Row {
                            mesh: name,
                            density: "uniform",
                            n: r.n,
                            points: r.points,
                            tool: r.tool,
                            threads: r.threads,
                            ms: r.ms,
                            rho: r.rho,
                            candidates,
                            bytes_per_point: 0.0,
                        });
                    }
                }
                Err(e) => eprintln!("the Python peers did not run: {e}"),
            }
        }
    }
    let mut scatter = Vec::new();
    if let (Some(python), Some(name)) = (&args.blender, args.meshes.first()) {
        let file = dir.join(format!("meshes/{name}.obj"));
        let mesh = trilux_io::mesh::TriMesh::read(&file).map_err(|e| e.to_string())?;
        let threads = args.threads.iter().copied().max().unwrap_or(2);
        eprintln!("{name}: Blender's Distribute Points on Faces and trilux ({threads} threads)…");
        match blender_rows(python, &file, &mesh, threads) {
            Ok(r) => scatter = r.into_iter().map(|r| (name.clone(), threads, r)).collect(),
            Err(e) => eprintln!("Blender did not run: {e}"),
        }
    }
    if args.json {
        for (mesh, threads, (tool, case, points, ms, rho)) in &scatter {
            println!(
                "{{\"mesh\": \"{mesh}\", \"scatter\": \"{case}\", \"tool\": \"{tool}\", \"threads\": {threads}, \"points\": {points}, \"ms\": {ms:.2}, \"rho\": {rho:.4}}}"
            );
        }
        for r in &rows {
            println!("{}", r.json());
        }
        return Ok(());
    }
    println!(
        "| mesh | density | N | points | tool | threads | ms | M points/s | ρ | candidates | peak B/point |"
    );
    println!("|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|");
    for r in &rows {
        let bytes = if r.bytes_per_point > 0.0 {
            format!("{:.0}", r.bytes_per_point)
        } else {
            "—".to_string()
        };
        println!(
            "| {} | {} | {} | {} | {} | {} | {:.1} | {:.3} | {:.3} | {} | {bytes} |",
            r.mesh,
            r.density,
            r.n,
            r.points,
            r.tool,
            r.threads,
            r.ms,
            r.points as f64 / r.ms / 1e3,
            r.rho,
            r.candidates
        );
    }
    if !scatter.is_empty() {
        println!(
            "\nScatter beside Blender's Distribute Points on Faces (evaluation of the node only; \
             ρ for Poisson rows, measured as ours):\n"
        );
        println!("| mesh | case | tool | threads | points | ms | M points/s | ρ |");
        println!("|---|---|---|---:|---:|---:|---:|---:|");
        for (mesh, threads, (tool, case, points, ms, rho)) in &scatter {
            let rho = if rho.is_nan() {
                "—".to_string()
            } else {
                format!("{rho:.3}")
            };
            println!(
                "| {mesh} | {case} | {tool} | {threads} | {points} | {ms:.1} | {:.2} | {rho} |",
                *points as f64 / ms / 1e3
            );
        }
    }
    for peer in ["cySampleElim", "open3d", "meshlab", "pcu"] {
        if !rows.iter().any(|r| r.tool == peer) {
            continue;
        }
        println!("\nSpeed against {peer} at the same target N (uniform; ratio of points/s):\n");
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
                        // Points per second: MeshLab's count is not N.
                        let rate = |x: &Row| x.points as f64 / x.ms;
                        let count = if r.points == r.n {
                            String::new()
                        } else {
                            format!(" ({peer} returned {} points)", r.points)
                        };
                        println!(
                            "- {} N = {}, {tool}, {t} thread(s): {:.2}× {peer}'s rate{count}, ρ {:.3} vs {:.3}",
                            r.mesh,
                            r.n,
                            rate(o) / rate(r),
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
