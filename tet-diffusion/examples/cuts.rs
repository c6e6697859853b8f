//! The exact cut against TransCut's relaxation cut: time of the cut with
//! its rebuild and the warm-started re-solve, the flatness of the cut face
//! and the angles of the tets it makes.
//!
//! ```sh
//! TRILUX_DATA=../shared/data cargo run --release -p tet-diffusion --example cuts -- [MESH.node ...] [--runs R] [--planes P] [--angles-only]
//! ```
//!
//! Default mesh `$TRILUX_DATA/tets/bunny_500k.node` (in metres: 1 unit =
//! 1000 mm), marble, η = 1.3, one directional light; `φ` is first solved
//! to a relative residual of 10⁻⁸. The first table: a plane through the
//! centre of the vertices with normal (1, 0, 0.2) (as the `transcut`
//! example's T_cut), `R` runs (default 5), medians in ms, each run on a
//! fresh copy: *cut* is `Object::cut` (mesh, matrices, shadows rebuilt),
//! *re-solve* the three channels to a relative residual of 10⁻³ from the
//! carried `φ` with Jacobi-PCG (the faster choice after an edit) — and
//! their sum, with the exact/relax ratio of the sums. *Off plane* is the
//! largest distance of a cut-face vertex from the plane over the bounding
//! box diagonal (for the relaxation, of the vertices it could not pull onto
//! it). The second table: the smallest dihedral angle the exact cut made
//! over `P` planes (default 24) through random points of the box with random
//! normals (fixed seed), with the mesh's own smallest angle and the planes
//! the angle bound refused (`Error::CutAngleBound`). The timing table gives
//! the cut's phases from `CutReport::times` and the output starts with
//! `/proc/loadavg`; `--angles-only` skips the timing.

use std::time::Instant;

use tet_diffusion::glam::DVec3;
use tet_diffusion::{Cut, CutMethod, Light, Medium, Method, Object, TetMesh};

fn main() {
    if let Err(e) = run() {
        eprintln!("cuts: {e}");
        std::process::exit(1);
    }
}

struct Args {
    meshes: Vec<std::path::PathBuf>,
    runs: usize,
    planes: usize,
    angles_only: bool,
}

fn args() -> Result<Args, String> {
    let mut a = Args {
        meshes: Vec::new(),
        runs: 5,
        planes: 24,
        angles_only: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut number = |name: &str| -> Result<usize, String> {
            it.next()
                .and_then(|v| v.parse().ok())
                .filter(|&n: &usize| n > 0)
                .ok_or_else(|| format!("{name} needs a positive whole number"))
        };
        match x.as_str() {
            "--runs" => a.runs = number("--runs")?,
            "--planes" => a.planes = number("--planes")?,
            "--angles-only" => a.angles_only = true,
            _ if x.starts_with("--") => return Err(format!("unknown option {x}")),
            _ => a.meshes.push(x.into()),
        }
    }
    if a.meshes.is_empty() {
        let data = std::env::var_os("TRILUX_DATA").unwrap_or_else(|| "../shared/data".into());
        a.meshes.push(
            std::path::Path::new(&data)
                .join("tets")
                .join("bunny_500k.node"),
        );
    }
    Ok(a)
}

fn read(path: &std::path::Path) -> Result<(TetMesh, f64), String> {
    let file =
        trilux_io::tet::TetMesh::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mesh = TetMesh::new(&file.positions, &file.tets)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let (lo, hi) = bounds(&mesh);
    // Scans in metres (a diagonal under 5 units) are 1000 mm per unit.
    let unit = if (hi - lo).length() < 5.0 {
        1000.0
    } else {
        10.0
    };
    Ok((mesh, unit))
}

fn bounds(mesh: &TetMesh) -> (DVec3, DVec3) {
    mesh.positions()
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// The largest distance from the plane of a boundary vertex of `after`
/// that was not a boundary vertex of `before` (where it is now), over the
/// box diagonal `size`.
fn off_plane(before: &TetMesh, after: &TetMesh, point: DVec3, n: DVec3, size: f64) -> f64 {
    let old: std::collections::HashSet<[u64; 3]> = before
        .boundary_vertices()
        .iter()
        .map(|&v| before.positions()[v as usize].to_array().map(f64::to_bits))
        .collect();
    after
        .boundary_vertices()
        .iter()
        .map(|&v| after.positions()[v as usize])
        .filter(|x| !old.contains(&x.to_array().map(f64::to_bits)))
        .map(|x| (x - point).dot(n).abs() / size)
        .fold(0.0, f64::max)
}

use test_support::SplitMix64 as Random;

/// The first line of `/proc/loadavg`, to print beside the timings.
fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map_or_else(|_| "unknown".into(), |l| l.trim().to_owned())
}

fn run() -> Result<(), String> {
    let a = args()?;
    let load_start = loadavg();
    let mut timing = String::from(
        "| mesh | #tets | cut | split ms | mesh ms | assembly ms | lights ms | cut ms | re-solve ms | cut + re-solve ms | exact / relax | split tets | min created dihedral ° | off plane |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut angles = String::from(
        "| mesh | mesh's min dihedral ° | planes | refused | min created dihedral ° | median over planes ° |\n|---|---|---|---|---|---|\n",
    );
    for path in &a.meshes {
        let name = path
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        let (mesh, unit) = read(path)?;
        let (lo, hi) = bounds(&mesh);
        let size = (hi - lo).length();
        let tets = mesh.tets().len();
        let own_min = mesh.quality().min_dihedral;
        let mut object = Object::homogeneous(
            mesh,
            unit,
            Medium::measured("marble").map_err(|e| e.to_string())?,
            1.3,
        )
        .map_err(|e| e.to_string())?;
        object
            .add_light(Light::Directional {
                to_light: DVec3::new(0.3, 1.0, 0.6),
                irradiance: [1.0; 3],
            })
            .map_err(|e| e.to_string())?;
        object.settings.tolerance = 1e-8;
        object.solve().map_err(|e| e.to_string())?;
        object.settings.tolerance = 1e-3;
        object.settings.method = Method::JacobiPcg;
        let centre =
            object.mesh().positions().iter().sum::<DVec3>() / object.mesh().vertex_count() as f64;
        let normal = DVec3::new(1.0, 0.0, 0.2).normalize();
        let plane = Cut::Plane {
            point: centre,
            normal,
        };
        let mut totals = [0.0; 2];
        let methods = if a.angles_only {
            Vec::new()
        } else {
            vec![
                ("exact", CutMethod::Exact),
                ("relax (5 sweeps)", CutMethod::Relax { sweeps: 5 }),
            ]
        };
        for (k, (label, method)) in methods.into_iter().enumerate() {
            let (mut cut_ms, mut solve_ms, mut sum_ms) = (Vec::new(), Vec::new(), Vec::new());
            let mut phases: [Vec<f64>; 4] = Default::default();
            let mut last = None;
            for _ in 0..a.runs {
                let mut o = object.clone();
                let t = Instant::now();
                let report = o.cut(&plane, method).map_err(|e| e.to_string())?;
                let c = ms(t);
                let t = Instant::now();
                o.solve().map_err(|e| e.to_string())?;
                let s = ms(t);
                let p = report.times;
                for (v, x) in
                    phases
                        .iter_mut()
                        .zip([p.split_ms, p.mesh_ms, p.assembly_ms, p.lights_ms])
                {
                    v.push(x);
                }
                cut_ms.push(c);
                solve_ms.push(s);
                sum_ms.push(c + s);
                last = Some((
                    report,
                    off_plane(object.mesh(), o.mesh(), centre, normal, size),
                ));
            }
            let (report, off) = last.ok_or("no run")?;
            totals[k] = median(sum_ms.clone());
            let ratio = if k == 1 {
                format!("{:.2}", totals[0] / totals[1])
            } else {
                String::new()
            };
            let min_created = if report.min_created_dihedral.is_finite() {
                format!("{:.2}", report.min_created_dihedral)
            } else {
                "—".into()
            };
            let [p0, p1, p2, p3] = phases.map(median);
            timing.push_str(&format!(
                "| {name} | {tets} | {label} | {p0:.0} | {p1:.0} | {p2:.0} | {p3:.0} | {:.0} | {:.0} | {:.0} | {ratio} | {} | {min_created} | {off:.1e} |\n",
                median(cut_ms),
                median(solve_ms),
                totals[k],
                report.split_tets,
            ));
        }
        // Angles over random planes.
        let mut rng = Random(0x5EED);
        let mut mins = Vec::new();
        let mut refused = 0;
        for _ in 0..a.planes {
            let p = lo
                + (hi - lo)
                    * DVec3::new(
                        0.25 + 0.5 * rng.f64(),
                        0.25 + 0.5 * rng.f64(),
                        0.25 + 0.5 * rng.f64(),
                    );
            let n = loop {
                let v = DVec3::new(rng.f64(), rng.f64(), rng.f64()) * 2.0 - 1.0;
                if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                    break v;
                }
            };
            let mut o = object.clone();
            o.set_shadows(false);
            match o.cut(
                &Cut::Plane {
                    point: p,
                    normal: n,
                },
                CutMethod::Exact,
            ) {
                Ok(r) if r.min_created_dihedral.is_finite() => mins.push(r.min_created_dihedral),
                Ok(_) | Err(tet_diffusion::Error::CutRemovesEverything { .. }) => {}
                Err(e @ tet_diffusion::Error::CutAngleBound { .. }) => {
                    refused += 1;
                    eprintln!("{name}: plane through {p} normal {n} refused: {e}");
                }
                Err(e) => return Err(e.to_string()),
            }
        }
        let worst = mins.iter().copied().fold(f64::INFINITY, f64::min);
        let planes = mins.len();
        let med = if mins.is_empty() {
            f64::NAN
        } else {
            median(mins)
        };
        angles.push_str(&format!(
            "| {name} | {own_min:.2} | {planes} | {refused} | {worst:.2} | {med:.2} |\n"
        ));
    }
    let threads = rayon::current_num_threads();
    println!(
        "Medians of {} runs, {threads} threads; /proc/loadavg at the start: {load_start}, at the end: {}.\n",
        a.runs,
        loadavg()
    );
    println!("{timing}\n{angles}");
    Ok(())
}
