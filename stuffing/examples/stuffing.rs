//! Isosurface stuffing on real meshes, side by side with TetGen (and, in
//! issue #48's table, Gmsh and fTetWild).
//!
//! ```text
//! TRILUX_DATA=../shared/data cargo run --release -p tet-stuffing --example stuffing -- [--json]
//! ```
//!
//! For every mesh in `$TRILUX_DATA/meshes` and the closed boundary of
//! `$TRILUX_DATA/tets/bunny_500k`, at three lattice spacings (a fraction of
//! the bounding-box diagonal; the finest gives about 500k tetrahedra on the
//! bunny), uniform and graded: tetrahedra, median time of 3 runs, dihedral
//! angle range and cotangent-weight range. TetGen (the Python package
//! `tetgen`, run with `-pq1.2a<volume>` and a maximum volume tuned to give a
//! similar tetrahedron count) runs on the same surfaces when a Python with
//! `tetgen` is found (`$TETGEN_PYTHON`, else a venv the example sets up
//! under `target/peers-venv`, `--no-tetgen` or `--no-peers` to skip it);
//! where it refuses an input the table says why. A second table measures
//! the fast winding number against the exact sum.
//!
//! With `--distance`, only a table of how far the stuffed boundary lies
//! from each input at the default spacing (Hausdorff and mean distance as
//! shares of the diagonal, and what the measurement costs).
//!
//! With `--envelope [--runs N] [--peer-cap S]`, only issue #48's table:
//! per mesh at the default spacing, the plain stuffing beside
//! `Options::envelope` at 2·10⁻³ and 10⁻³ of the diagonal (uniform, graded,
//! and graded at half the spacing): Hausdorff distance both ways and mean,
//! tetrahedra, median time of N runs (3) without the measurement, dihedral
//! angle range, and the time and count as ratios to the plain stuffing of
//! the same run. Then the peers on the same surface, aiming at the plain
//! stuffing's count: TetGen (`-pq1.2a<volume>`), Gmsh (the surface as a
//! classified discrete entity, one volume, `Mesh.MeshSizeMax`; both keep
//! the input triangles and recalibrate their parameter up to twice) and
//! fTetWild (`pytetwild`, default envelope 10⁻³, an edge length from the
//! count, one calibration-free run), each run in a child process stopped
//! after S seconds (120), its boundary measured by
//! `tet_stuffing::surface_distance` with the same sample count; a peer
//! that refuses the input, crashes or runs out of time gets its reason.
//! The example installs them (`pip install numpy tetgen gmsh
//! pytetwild[all]`) into the venv `target/peers-venv` when they do not
//! import; `--no-peers` skips them all, `--no-tetgen` TetGen.
//!
//! With `--json`: one object per line with the keys `mesh`, `h`, `graded`,
//! `tool`, `tets`, `ms`, `min_dihedral_deg`, `max_dihedral_deg`, `error`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use tet_stuffing::glam::DVec3;
use tet_stuffing::{self as stuffing, Options, winding::WindingNumber};

// Beside the example, not in `examples/`, so that Cargo does not take it
// for an example of its own.
#[path = "stuffing/peers.rs"]
mod peers;

/// One row of the table.
struct Row {
    mesh: String,
    h: f64,
    graded: bool,
    tool: &'static str,
    tets: usize,
    ms: f64,
    min_deg: f64,
    max_deg: f64,
    /// Geometric cotangent edge weights over the mean edge length.
    weights: [f64; 2],
    error: Option<String>,
}

/// Runs TetGen through Python: reads the surface from raw files, times
/// `tetrahedralize` only, writes the result back as raw files.
const TETGEN_SCRIPT: &str = r#"
import json, sys, time
import numpy as np
import tetgen
prefix, switches, repeats = sys.argv[1], sys.argv[2], int(sys.argv[3])
v = np.fromfile(prefix + ".pos", dtype="<f8").reshape(-1, 3)
f = np.fromfile(prefix + ".tri", dtype="<u4").reshape(-1, 3).astype(np.int32)
times = []
try:
    for _ in range(repeats):
        t = tetgen.TetGen(v, f)
        t0 = time.perf_counter()
        nodes, elems = t.tetrahedralize(switches=switches)[:2]
        times.append((time.perf_counter() - t0) * 1000.0)
except Exception as e:
    print(json.dumps({"error": str(e).strip().replace("\n", " ")}))
    sys.exit(0)
np.asarray(nodes, dtype="<f8").tofile(prefix + ".node.raw")
np.asarray(elems, dtype="<u4").tofile(prefix + ".ele.raw")
print(json.dumps({"ms": sorted(times)[len(times) // 2], "tets": int(len(elems))}))
"#;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let json = args.iter().any(|a| a == "--json");
    // `--only NAME`: just the meshes whose name contains NAME.
    let only = args
        .iter()
        .position(|a| a == "--only")
        .and_then(|i| args.get(i + 1).cloned());
    let Some(data) = std::env::var_os("TRILUX_DATA").map(PathBuf::from) else {
        eprintln!("set TRILUX_DATA to the data folder (e.g. ../shared/data)");
        std::process::exit(2);
    };
    let work = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/stuffing-bench");
    std::fs::create_dir_all(&work)?;
    let no_tetgen = args.iter().any(|a| a == "--no-tetgen" || a == "--no-peers");
    let mut inputs = inputs(&data)?;
    if let Some(only) = &only {
        inputs.retain(|(name, _, _)| name.contains(only.as_str()));
    }

    if args.iter().any(|a| a == "--distance") {
        distance_table(&inputs);
        return Ok(());
    }
    if args.iter().any(|a| a == "--envelope") {
        let number = |flag: &str, default: usize| {
            args.iter()
                .position(|a| a == flag)
                .and_then(|i| args.get(i + 1))
                .and_then(|r| r.parse().ok())
                .unwrap_or(default)
        };
        let runs = number("--runs", 3);
        let peers = if args.iter().any(|a| a == "--no-peers") {
            None
        } else {
            let wanted: Vec<peers::Peer> = peers::Peer::ALL
                .into_iter()
                .filter(|&p| !(no_tetgen && p == peers::Peer::TetGen))
                .collect();
            let cap = Duration::from_secs(number("--peer-cap", 120) as u64);
            Some(peers::Runner::new(&wanted, work, runs, cap))
        };
        envelope_table(&inputs, runs, peers.as_ref());
        return Ok(());
    }
    let python = if no_tetgen { None } else { tetgen_python() };
    if python.is_none() && !json {
        println!("(TetGen not found: set TETGEN_PYTHON to a Python with the `tetgen` package)\n");
    }
    let mut rows: Vec<Row> = Vec::new();
    let mut winding_rows = Vec::new();
    if !json {
        println!(
            "| mesh | h | graded | tool | tets | ms (median of 3) | tets/s | min dihedral | max dihedral | cot weight / mean edge | note |"
        );
        println!("|---|---|---|---|---|---|---|---|---|---|---|");
    }
    let mut printed = 0;
    for (name, positions, triangles) in &inputs {
        let (lo, hi) = bounds(positions, triangles);
        let diag = lo.distance(hi);
        winding_rows.push(measure_winding(name, positions, triangles, lo, hi)?);
        for div in [25.0, 50.0, 95.0] {
            let h = diag / div;
            let mut options = Options::new(h);
            let (uniform, ours_volume) = run_ours(name, positions, triangles, &options);
            let ours_tets = uniform.tets;
            rows.push(uniform);
            options.graded = true;
            rows.push(run_ours(name, positions, triangles, &options).0);
            if let Some(py) = &python {
                rows.push(run_tetgen(
                    py,
                    &work,
                    name,
                    h,
                    positions,
                    triangles,
                    ours_tets,
                    ours_volume,
                ));
            }
            // Rows as they come, so that a long run shows its progress.
            for r in &rows[printed..] {
                if json {
                    print_json(r);
                } else {
                    print_row(r);
                }
            }
            printed = rows.len();
        }
    }

    if json {
        return Ok(());
    }
    println!();
    println!(
        "Fast winding number (Barill et al. 2018) against the exact sum, 2,000 points in the bounding box per mesh:"
    );
    println!();
    println!(
        "| mesh | triangles | β | max error | side flips | exact µs/pt | fast µs/pt | speed-up |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for rows in &winding_rows {
        for w in rows {
            println!("{w}");
        }
    }
    println!();
    summary(&rows);
    Ok(())
}

/// `--distance`: how far the stuffed boundary lies from each input at the
/// default spacing (1/40 of the diagonal, as `trilux tetra`), with the
/// stuffing's time without and with the measurement (medians of 3).
fn distance_table(inputs: &[Surface]) {
    println!(
        "| mesh | tets | Hausdorff / diagonal | input → tets | tets → input | mean | points (input + boundary) | left out (triangles, area) | stuffing ms | measuring ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let pct = |x: f64, diag: f64| format!("{:.3} %", 100.0 * x / diag);
    for (name, p, t) in inputs {
        let (lo, hi) = bounds(p, t);
        let mut options = Options::new(lo.distance(hi) / 40.0);
        let median_ms = |options: &Options| {
            let mut ms = Vec::new();
            let mut last = None;
            for _ in 0..3 {
                match stuffing::tetrahedralize(p, t, options) {
                    Ok(m) => {
                        ms.push(m.report.elapsed.as_secs_f64() * 1e3);
                        last = Some(m);
                    }
                    Err(e) => {
                        println!("| {name} | {e} | | | | | | | | |");
                        return None;
                    }
                }
            }
            ms.sort_by(f64::total_cmp);
            last.map(|m| (m, ms[1]))
        };
        options.distance_samples = 0;
        let Some((_, plain)) = median_ms(&options) else {
            continue;
        };
        options.distance_samples = Options::new(1.0).distance_samples;
        let Some((m, measured)) = median_ms(&options) else {
            continue;
        };
        let Some(d) = &m.report.distance else {
            continue;
        };
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} + {} | {}, {:.2} % | {plain:.0} | {:.0} |",
            m.tets.len(),
            pct(d.hausdorff, d.diagonal),
            pct(d.input_to_tets, d.diagonal),
            pct(d.tets_to_input, d.diagonal),
            pct(d.mean, d.diagonal),
            d.input_samples,
            d.boundary_samples,
            d.left_out_triangles,
            100.0 * d.left_out_area,
            measured - plain
        );
    }
}

/// `--envelope`: issue #48's table. Per mesh at the default spacing (1/40
/// of the diagonal): the plain stuffing, then the envelope fit at 2·10⁻³
/// and 10⁻³ of the diagonal, uniform and graded, and graded at half the
/// spacing (what a finer lattice adds to the fit); the distances (sampled,
/// 2^16 points a side plus the vertices), tetrahedra, median time of
/// `runs` runs without the measurement, the smallest dihedral angle, and
/// the time and count as ratios to the plain stuffing of the same run.
/// Then the peers (when `peers` is given, see [`peers`]) on the same
/// surface at a count near the plain stuffing's, measured the same way.
fn envelope_table(inputs: &[Surface], runs: usize, peers: Option<&peers::Runner>) {
    println!(
        "| mesh | options | Hausdorff / diag | input → tets | tets → input | mean | tets | ms | min dihedral | max dihedral | time ratio | tet ratio | fitted vertices, split edges, sharp edges | hole caps (share, farthest) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let pct = |x: f64, diag: f64| format!("{:.3} %", 100.0 * x / diag);
    for (name, p, t) in inputs {
        let (lo, hi) = bounds(p, t);
        let base = Options::new(lo.distance(hi) / 40.0);
        // The plain stuffing's time, count and volume.
        let mut baseline: Option<(f64, usize, f64)> = None;
        for (label, envelope, graded, refine) in [
            ("default", None, false, 1.0),
            ("envelope 2e-3", Some(2e-3), false, 1.0),
            ("envelope 1e-3", Some(1e-3), false, 1.0),
            ("envelope 1e-3, graded", Some(1e-3), true, 1.0),
            ("envelope 1e-3, graded, h/2", Some(1e-3), true, 0.5),
        ] {
            let mut options = base.clone();
            options.h *= refine;
            options.envelope = envelope;
            options.graded = graded;
            options.distance_samples = 0;
            let mut ms = Vec::new();
            let mut failed = None;
            for _ in 0..runs.max(1) {
                match stuffing::tetrahedralize(p, t, &options) {
                    Ok(m) => ms.push(m.report.elapsed.as_secs_f64() * 1e3),
                    Err(e) => failed = Some(e),
                }
            }
            if let Some(e) = failed {
                println!("| {name} | {label} | {e} | | | | | | | | | | | |");
                continue;
            }
            ms.sort_by(f64::total_cmp);
            let median = ms[ms.len() / 2];
            options.distance_samples = Options::new(1.0).distance_samples;
            let m = match stuffing::tetrahedralize(p, t, &options) {
                Ok(m) => m,
                Err(e) => {
                    println!("| {name} | {label} | {e} | | | | | | | | | | | |");
                    continue;
                }
            };
            let Some(d) = &m.report.distance else {
                continue;
            };
            let (base_ms, base_tets, _) =
                *baseline.get_or_insert_with(|| (median, m.tets.len(), volume(&m)));
            println!(
                "| {name} | {label} | {} | {} | {} | {} | {} | {median:.0} | {:.2}° | {:.2}° | {:.2} | {:.2} | {}, {}, {} | {:.2} %, {} |",
                pct(d.hausdorff, d.diagonal),
                pct(d.input_to_tets, d.diagonal),
                pct(d.tets_to_input, d.diagonal),
                pct(d.mean, d.diagonal),
                m.tets.len(),
                m.report.min_dihedral_deg,
                m.report.max_dihedral_deg,
                median / base_ms,
                m.tets.len() as f64 / base_tets as f64,
                m.report.fitted_vertices,
                m.report.split_edges,
                m.report.sharp_edges,
                100.0 * d.hole_caps,
                pct(d.hole_caps_to_input, d.diagonal),
            );
        }
        if let (Some(runner), Some(baseline)) = (peers, baseline) {
            peer_rows(runner, (name, p, t), baseline);
        }
    }
}

/// The peers' rows of [`envelope_table`] for one surface, aiming at the
/// plain stuffing's count in its volume; `baseline` is that stuffing's
/// (median ms, tetrahedra, volume). A peer that is not installed, refuses
/// the surface, crashes or passes the time cap gets its reason, one line.
fn peer_rows(
    runner: &peers::Runner,
    (name, p, t): (&str, &[DVec3], &[[u32; 3]]),
    (base_ms, base_tets, volume): (f64, usize, f64),
) {
    let pct = |x: f64, diag: f64| format!("{:.3} %", 100.0 * x / diag);
    for (peer, installed) in &runner.installed {
        let result = installed
            .clone()
            .map_err(|e| format!("not installed: {e}"))
            .and_then(|()| runner.run(*peer, name, p, t, base_tets, volume));
        let m = match result {
            Ok(m) => m,
            Err(e) => {
                println!("| {name} | {} | {e} | | | | | | | | | | | |", peer.name());
                continue;
            }
        };
        let d = &m.distance;
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {:.0} | {:.2}° | {:.2}° | {:.2} | {:.2} | — | {:.2} %, {} |",
            peer.label(m.param),
            pct(d.hausdorff, d.diagonal),
            pct(d.input_to_tets, d.diagonal),
            pct(d.tets_to_input, d.diagonal),
            pct(d.mean, d.diagonal),
            m.tets,
            m.ms,
            m.min_dihedral_deg,
            m.max_dihedral_deg,
            m.ms / base_ms,
            m.tets as f64 / base_tets as f64,
            100.0 * d.hole_caps,
            pct(d.hole_caps_to_input, d.diagonal),
        );
    }
}

/// The volume a tetrahedral mesh fills, in the surface's unit cubed.
fn volume(m: &stuffing::TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|tet| stuffing::signed_volume(tet.map(|v| m.positions[v as usize])))
        .sum()
}

fn print_json(r: &Row) {
    println!(
        "{{\"mesh\":{},\"h\":{},\"graded\":{},\"tool\":\"{}\",\"tets\":{},\"ms\":{:.3},\"min_dihedral_deg\":{},\"max_dihedral_deg\":{},\"error\":{}}}",
        quote(&r.mesh),
        r.h,
        r.graded,
        r.tool,
        r.tets,
        r.ms,
        num(r.min_deg),
        num(r.max_deg),
        r.error.as_deref().map_or("null".to_string(), quote)
    );
}

fn print_row(r: &Row) {
    let rate = if r.ms > 0.0 {
        r.tets as f64 / (r.ms / 1000.0)
    } else {
        0.0
    };
    println!(
        "| {} | {:.4} | {} | {} | {} | {:.0} | {:.0} | {:.2}° | {:.2}° | {:.2} … {:.2} | {} |",
        r.mesh,
        r.h,
        if r.graded { "yes" } else { "no" },
        r.tool,
        r.tets,
        r.ms,
        rate,
        r.min_deg,
        r.max_deg,
        r.weights[0],
        r.weights[1],
        r.error.as_deref().unwrap_or("")
    );
}

/// The bars, computed from the table.
fn summary(rows: &[Row]) {
    let ours: Vec<&Row> = rows.iter().filter(|r| r.tool == "trilux").collect();
    let worst = ours.iter().map(|r| r.min_deg).fold(f64::INFINITY, f64::min);
    let worst_max = ours.iter().map(|r| r.max_deg).fold(0.0, f64::max);
    println!(
        "Smallest dihedral angle over every trilux mesh above: {worst:.2}° (largest angle {worst_max:.2}°)."
    );
    let bunny = "bunny_500k boundary";
    let finest = ours
        .iter()
        .filter(|r| r.mesh == bunny)
        .map(|r| r.h)
        .fold(f64::INFINITY, f64::min);
    let pick = |tool: &str, graded: bool| {
        rows.iter()
            .find(|r| r.mesh == bunny && r.h == finest && r.tool == tool && r.graded == graded)
    };
    if let (Some(u), Some(g)) = (pick("trilux", false), pick("trilux", true)) {
        println!(
            "Graded / uniform tetrahedra on the closed bunny at h = {:.4}: {} / {} = {:.0}%.",
            finest,
            g.tets,
            u.tets,
            100.0 * g.tets as f64 / u.tets as f64
        );
        if let Some(t) = pick("tetgen", false)
            && t.error.is_none()
        {
            println!(
                "TetGen vs uniform stuffing on the closed bunny: {} vs {} tets ({:+.0}%), {:.0} vs {:.0} ms: stuffing is {:.2}× faster ({:.0} vs {:.0} tets/s).",
                t.tets,
                u.tets,
                100.0 * (t.tets as f64 / u.tets as f64 - 1.0),
                t.ms,
                u.ms,
                t.ms / u.ms,
                u.tets as f64 / (u.ms / 1000.0),
                t.tets as f64 / (t.ms / 1000.0)
            );
        }
    }
}

/// Meshes of `$TRILUX_DATA/meshes` and the boundary of the TetGen bunny.
type Surface = (String, Vec<DVec3>, Vec<[u32; 3]>);

fn inputs(data: &Path) -> Result<Vec<Surface>, Box<dyn std::error::Error>> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(data.join("meshes"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    let mut out = Vec::new();
    for f in files {
        let m = trilux_io::mesh::TriMesh::read(&f)?;
        let name = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        out.push((
            name,
            m.positions.iter().map(|p| p.as_dvec3()).collect(),
            m.indices,
        ));
    }
    let tets = trilux_io::tet::TetMesh::read(data.join("tets/bunny_500k.node"))?;
    let boundary = tets.boundary();
    // Keep the surface's own vertices only (TetGen would keep the others).
    let mut map = vec![u32::MAX; tets.positions.len()];
    let mut positions = Vec::new();
    let triangles = boundary
        .iter()
        .map(|f| {
            f.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = positions.len() as u32;
                    positions.push(tets.positions[v as usize]);
                }
                map[v as usize]
            })
        })
        .collect();
    // The closed bunny first: it carries the comparison with TetGen.
    out.insert(0, ("bunny_500k boundary".to_string(), positions, triangles));
    Ok(out)
}

fn bounds(p: &[DVec3], t: &[[u32; 3]]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for f in t {
        for &v in f {
            lo = lo.min(p[v as usize]);
            hi = hi.max(p[v as usize]);
        }
    }
    (lo, hi)
}

/// Stuffing, 3 runs, the median time; quality and volume of the last mesh.
fn run_ours(name: &str, p: &[DVec3], t: &[[u32; 3]], options: &Options) -> (Row, f64) {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..3 {
        match stuffing::tetrahedralize(p, t, options) {
            Ok(m) => {
                times.push(m.report.elapsed.as_secs_f64() * 1000.0);
                last = Some(m);
            }
            Err(e) => {
                let row = Row {
                    mesh: name.to_string(),
                    h: options.h,
                    graded: options.graded,
                    tool: "trilux",
                    tets: 0,
                    ms: 0.0,
                    min_deg: f64::NAN,
                    max_deg: f64::NAN,
                    weights: [f64::NAN; 2],
                    error: Some(e.to_string()),
                };
                return (row, 0.0);
            }
        }
    }
    times.sort_by(f64::total_cmp);
    let Some(m) = last else {
        unreachable!("three successful runs");
    };
    let volume = m
        .tets
        .iter()
        .map(|tet| stuffing::signed_volume(tet.map(|v| m.positions[v as usize])))
        .sum();
    let row = Row {
        mesh: name.to_string(),
        h: options.h,
        graded: options.graded,
        tool: "trilux",
        tets: m.tets.len(),
        ms: times[1],
        min_deg: m.report.min_dihedral_deg,
        max_deg: m.report.max_dihedral_deg,
        weights: cot_weights(&m.positions, &m.tets),
        error: None,
    };
    (row, volume)
}

/// The cotangent edge-weight range `tet-diffusion` computes (TransCut
/// Eq. 10 without κ), over the mean edge length: dimensionless.
fn cot_weights(p: &[DVec3], t: &[[u32; 4]]) -> [f64; 2] {
    match tet_diffusion::TetMesh::new(p, t) {
        Ok(m) => {
            let q = m.quality();
            let l = q.mean_edge_length;
            [q.edge_weight_range[0] / l, q.edge_weight_range[1] / l]
        }
        Err(_) => [f64::NAN; 2],
    }
}

/// A Python with the `tetgen` package: `$TETGEN_PYTHON`, else the peers'
/// venv under `target/` (shared with mesh-sampling's peer benchmarks),
/// created and filled with `pip install numpy tetgen` when missing.
fn tetgen_python() -> Option<PathBuf> {
    let has_tetgen = |p: &Path| {
        Command::new(p)
            .args(["-c", "import tetgen"])
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if let Some(p) = std::env::var_os("TETGEN_PYTHON").map(PathBuf::from) {
        return has_tetgen(&p).then_some(p);
    }
    let venv = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/peers-venv");
    let python = venv.join("bin/python");
    if has_tetgen(&python) {
        return Some(python);
    }
    eprintln!(
        "setting up TetGen: python3 -m venv {} && pip install numpy tetgen",
        venv.display()
    );
    let run = |cmd: &mut Command| cmd.status().is_ok_and(|s| s.success());
    let made = python.exists() || run(Command::new("python3").arg("-m").arg("venv").arg(&venv));
    let installed = made
        && run(Command::new(&python).args(["-m", "pip", "install", "--quiet", "numpy", "tetgen"]));
    if !installed {
        eprintln!("could not set up TetGen; the table has trilux only");
    }
    (installed && has_tetgen(&python)).then_some(python)
}

/// TetGen with `-pq1.2a<vol>`, the maximum volume tuned (once) so that the
/// count is within 20% of `target` tetrahedra.
#[expect(
    clippy::too_many_arguments,
    reason = "one call site, all inputs of one row"
)]
fn run_tetgen(
    python: &Path,
    work: &Path,
    name: &str,
    h: f64,
    p: &[DVec3],
    t: &[[u32; 3]],
    target: usize,
    volume: f64,
) -> Row {
    let mut row = Row {
        mesh: name.to_string(),
        h,
        graded: false,
        tool: "tetgen",
        tets: 0,
        ms: 0.0,
        min_deg: f64::NAN,
        max_deg: f64::NAN,
        weights: [f64::NAN; 2],
        error: None,
    };
    let prefix = work.join(name.replace(' ', "_"));
    if let Err(e) = peers::write_surface(&prefix, p, t) {
        row.error = Some(format!("could not write the surface: {e}"));
        return row;
    }
    let script = work.join("tetgen_run.py");
    if let Err(e) = std::fs::write(&script, TETGEN_SCRIPT) {
        row.error = Some(format!("could not write the script: {e}"));
        return row;
    }
    let target = target.max(1) as f64;
    let mut max_volume = if volume > 0.0 {
        volume / target
    } else {
        h * h * h / 12.0
    };
    for attempt in 0..3 {
        // Calibration runs once; the final run is timed 3 times.
        let repeats = 1;
        let switches = format!("pq1.2a{max_volume:.6e}Q");
        // In the work folder: TetGen leaves debug files where it fails.
        let out = Command::new(python)
            .current_dir(work)
            .arg(&script)
            .arg(prefix.to_string_lossy().as_ref())
            .arg(&switches)
            .arg(repeats.to_string())
            .output();
        let out = match out {
            Ok(o) => o,
            Err(e) => {
                row.error = Some(format!("could not run Python: {e}"));
                return row;
            }
        };
        let text = String::from_utf8_lossy(&out.stdout);
        let line = text.lines().last().unwrap_or("");
        if !out.status.success() || line.is_empty() {
            let err = String::from_utf8_lossy(&out.stderr);
            let reason = err
                .lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .unwrap_or("no output");
            row.error = Some(format!("TetGen failed: {}", reason.trim()));
            return row;
        }
        if let Some(e) = field(line, "error") {
            row.error = Some(format!("TetGen refused: {e}"));
            return row;
        }
        let tets = field(line, "tets")
            .and_then(|s| s.parse::<f64>().ok())
            .unwrap_or(0.0);
        if tets == 0.0 {
            row.error = Some("TetGen returned no tetrahedra".to_string());
            return row;
        }
        let ratio = tets / target;
        if (0.8..=1.2).contains(&ratio) || attempt == 2 {
            // Time it: the median of 3 runs.
            let out = Command::new(python)
                .current_dir(work)
                .arg(&script)
                .arg(prefix.to_string_lossy().as_ref())
                .arg(&switches)
                .arg("3")
                .output();
            let Ok(out) = out else {
                row.error = Some("could not run Python".to_string());
                return row;
            };
            let text = String::from_utf8_lossy(&out.stdout);
            let line = text.lines().last().unwrap_or("");
            row.ms = field(line, "ms")
                .and_then(|s| s.parse().ok())
                .unwrap_or(0.0);
            row.tets = field(line, "tets")
                .and_then(|s| s.parse().ok())
                .unwrap_or(0);
            break;
        }
        max_volume *= ratio;
    }
    match read_raw(&prefix) {
        Some((nodes, elems)) => {
            let q = stuffing::quality(&nodes, &elems);
            row.min_deg = q.min_dihedral_deg;
            row.max_deg = q.max_dihedral_deg;
            row.weights = cot_weights(&nodes, &elems);
        }
        None => row.error = Some("could not read TetGen's output back".to_string()),
    }
    row
}

fn read_raw(prefix: &Path) -> Option<(Vec<DVec3>, Vec<[u32; 4]>)> {
    let node = std::fs::read(prefix.with_extension("node.raw")).ok()?;
    let ele = std::fs::read(prefix.with_extension("ele.raw")).ok()?;
    let f = |b: &[u8]| f64::from_le_bytes(b.try_into().unwrap_or([0; 8]));
    let u = |b: &[u8]| u32::from_le_bytes(b.try_into().unwrap_or([0; 4]));
    let nodes = node
        .chunks_exact(24)
        .map(|c| DVec3::new(f(&c[0..8]), f(&c[8..16]), f(&c[16..24])))
        .collect();
    let elems = ele
        .chunks_exact(16)
        .map(|c| [u(&c[0..4]), u(&c[4..8]), u(&c[8..12]), u(&c[12..16])])
        .collect();
    Some((nodes, elems))
}

/// The value of `"key": value` in a one-line JSON object from the Python
/// scripts (TetGen's here, the peers' in `peers.rs`): a string as written
/// (escapes kept, ended by the first unescaped quote), else the number.
fn field<'a>(line: &'a str, key: &str) -> Option<&'a str> {
    let pat = format!("\"{key}\": ");
    let start = line.find(&pat)? + pat.len();
    let rest = &line[start..];
    if let Some(s) = rest.strip_prefix('"') {
        let mut escaped = false;
        let end = s.char_indices().find_map(|(i, c)| {
            let ends = c == '"' && !escaped;
            escaped = c == '\\' && !escaped;
            ends.then_some(i)
        })?;
        Some(&s[..end])
    } else {
        let end = rest.find([',', '}']).unwrap_or(rest.len());
        Some(rest[..end].trim())
    }
}

/// Exact against fast winding numbers at random points of the bounding box.
fn measure_winding(
    name: &str,
    p: &[DVec3],
    t: &[[u32; 3]],
    lo: DVec3,
    hi: DVec3,
) -> Result<Vec<String>, Box<dyn std::error::Error>> {
    let mut state = 0x5EED_u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let pad = (hi - lo) * 0.05;
    let points: Vec<DVec3> = (0..2000)
        .map(|_| lo - pad + (hi - lo + 2.0 * pad) * DVec3::new(next(), next(), next()))
        .collect();
    let wn = WindingNumber::new(p, t, 2.0)?;
    let start = Instant::now();
    let exact: Vec<f64> = points.iter().map(|&q| wn.exact(q)).collect();
    let exact_us = start.elapsed().as_secs_f64() * 1e6 / points.len() as f64;
    let mut out = Vec::new();
    for beta in [1.5, 2.0, 3.0] {
        let wn = wn.clone().with_beta(beta)?;
        let start = Instant::now();
        let fast: Vec<f64> = points.iter().map(|&q| wn.fast(q)).collect();
        let fast_us = start.elapsed().as_secs_f64() * 1e6 / points.len() as f64;
        let err = fast
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let flips = fast
            .iter()
            .zip(&exact)
            .filter(|(a, b)| (**a > 0.5) != (**b > 0.5))
            .count();
        out.push(format!(
            "| {name} | {} | {beta} | {err:.2e} | {flips} | {exact_us:.1} | {fast_us:.2} | {:.0}× |",
            t.len(),
            exact_us / fast_us
        ));
    }
    Ok(out)
}

fn quote(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        "null".to_string()
    }
}
