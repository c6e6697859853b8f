//! Scatter by rate on a 10⁵-face mesh: a full build against an update of
//! 1 % of the faces (a brush stroke: the faces in a disc, and the same
//! number scattered at random), and the rate mode's points per second
//! against `DensitySampler::sample_stable` (Blender's per-triangle mode)
//! at the same expected count. Medians of `ROUNDS` runs, interleaved so
//! that a load change hits all alike; prints a Markdown table.
//!
//! ```text
//! cargo run --release -p mesh-sampling --example scatter -- [POINTS]
//! ```
//!
//! The mesh: a 224 × 224 grid of unit cells (100,352 triangles) with a
//! bumpy height field, and a painted-like per-vertex density in `[0, 1]`
//! (ceiling 1); `POINTS` is the expected number of points (default 10⁶).

use std::hint::black_box;
use std::process::ExitCode;
use std::time::Instant;

use glam::Vec3;
use mesh_sampling::{Density, DensitySampler, MeshRef, Scatter, ScatterOptions};

const CELLS: u32 = 224;
const ROUNDS: usize = 11;

fn grid() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = CELLS + 1;
    let positions = (0..m * m)
        .map(|k| {
            let (x, y) = ((k % m) as f32, (k / m) as f32);
            Vec3::new(x, y, 2.0 * (x * 0.11).sin() * (y * 0.07).cos())
        })
        .collect();
    let mut indices = Vec::new();
    for j in 0..CELLS {
        for i in 0..CELLS {
            let a = j * m + i;
            indices.push([a, a + 1, a + m]);
            indices.push([a + 1, a + m + 1, a + m]);
        }
    }
    (positions, indices)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next().map(str::to_owned))
        .unwrap_or_else(|| "unknown".into())
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

fn run() -> Result<(), String> {
    let points: f64 = match std::env::args().nth(1) {
        Some(s) => s.parse().map_err(|e| format!("POINTS {s}: {e}"))?,
        None => 1e6,
    };
    let (positions, indices) = grid();
    let mesh = MeshRef::new(&positions, &indices);
    let faces = indices.len();
    // A smooth density in [0.1, 0.9], like a painted channel.
    let mut weights: Vec<f32> = positions
        .iter()
        .map(|p| 0.5 + 0.4 * (p.x * 0.05).sin() * (p.y * 0.03).cos())
        .collect();
    let area: f64 = (0..faces).map(|f| mesh.area(f)).sum();
    let mass: f64 = (0..faces)
        .map(|f| {
            let w: f32 = indices[f].iter().map(|&i| weights[i as usize]).sum();
            mesh.area(f) * f64::from(w) / 3.0
        })
        .sum();
    let rate = points / mass;
    let options = ScatterOptions {
        max_density: Some(1.0),
        seed: 1,
        ..ScatterOptions::new(rate)
    };
    let err = |e: mesh_sampling::Error| e.to_string();

    // The edits, each on 1 % of the faces (those touching the vertices
    // painted): a disc in the middle of the face order, a disc at its
    // start (every later point moves), and vertices scattered at random.
    let radius = ((0.01 * faces as f64 / 2.0) / std::f64::consts::PI).sqrt() as f32;
    let disc = |x: f32, y: f32| -> Vec<bool> {
        positions
            .iter()
            .map(|p| (p.truncate() - glam::Vec2::new(x, y)).length() < radius)
            .collect()
    };
    let mut state = 0x1234_5678_u64;
    let mut scattered = vec![false; positions.len()];
    for _ in 0..faces / 100 / 6 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        scattered[((state >> 33) % positions.len() as u64) as usize] = true;
    }
    let edits: Vec<(&str, Vec<bool>)> = vec![
        ("a disc mid-order", disc(100.0, 120.0)),
        ("a disc at the start of the face order", disc(112.0, 14.0)),
        ("scattered vertices", scattered),
    ];
    let edits: Vec<(&str, Vec<bool>, Vec<u32>)> = edits
        .into_iter()
        .map(|(name, painted)| {
            let touched = (0..faces as u32)
                .filter(|&f| indices[f as usize].iter().any(|&v| painted[v as usize]))
                .collect();
            (name, painted, touched)
        })
        .collect();

    let base = weights.clone(); // the baseline's density (the scatter's is painted)
    let sampler = DensitySampler::new(mesh, Density::PerVertex(&base)).map_err(err)?;
    let per_mass = points / sampler.total_mass();
    let mut scatter =
        Scatter::new(mesh, Density::PerVertex(&weights).into(), &options).map_err(err)?;
    let (mut build, mut stable) = (vec![], vec![]);
    let mut update_t = vec![vec![]; edits.len()];
    let (mut built, mut drawn) = (0, 0);
    for round in 0..ROUNDS {
        let t = Instant::now();
        let s = Scatter::new(mesh, Density::PerVertex(&weights).into(), &options).map_err(err)?;
        build.push(t.elapsed().as_secs_f64());
        built = black_box(s).points().len();

        let t = Instant::now();
        let p = sampler.sample_stable(round as u64, per_mass).map_err(err)?;
        stable.push(t.elapsed().as_secs_f64());
        drawn = black_box(p).len();

        // Paint up or down (every round changes counts).
        let gain = if round % 2 == 0 { 1.6 } else { 0.625 };
        for ((_, painted, touched), times) in edits.iter().zip(&mut update_t) {
            for (w, _) in weights.iter_mut().zip(painted).filter(|(_, p)| **p) {
                *w = (*w * gain).min(1.0);
            }
            let t = Instant::now();
            let update = scatter
                .update_faces(touched, Density::PerVertex(&weights).into())
                .map_err(err)?;
            times.push(t.elapsed().as_secs_f64());
            black_box(update);
        }
    }
    // The updates leave what a rebuild gives.
    let rebuilt = Scatter::new(mesh, Density::PerVertex(&weights).into(), &options).map_err(err)?;
    if rebuilt.points() != scatter.points() {
        return Err("an update differs from a rebuild".into());
    }

    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let (b, s) = (median(build), median(stable));
    let ms = |x: f64| format!("{:.2} ms", x * 1e3);
    println!(
        "{faces} triangles, area {area:.0}, rate {rate:.2} per unit area (ceiling 1), {} candidates expected; \
         {threads} threads, load {} at the end; medians of {ROUNDS}\n",
        (rate * area).round(),
        load()
    );
    println!("| row | time | points | rate | ratio |");
    println!("|---|---|---|---|---|");
    println!(
        "| `sample_stable` (baseline) | {} | {drawn} | {:.1} M/s | 1 |",
        ms(s),
        drawn as f64 / s / 1e6
    );
    println!(
        "| scatter, full build | {} | {built} | {:.1} M/s | {:.2}× the baseline's points/s |",
        ms(b),
        built as f64 / b / 1e6,
        (built as f64 / b) / (drawn as f64 / s)
    );
    for ((name, _, touched), times) in edits.iter().zip(update_t) {
        let t = median(times);
        println!(
            "| update, {name}: {} faces ({:.1} %) | {} | | | {:.0}× faster than a build |",
            touched.len(),
            100.0 * touched.len() as f64 / faces as f64,
            ms(t),
            b / t
        );
    }
    Ok(())
}
