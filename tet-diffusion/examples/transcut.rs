//! TransCut's Table 1 on every tetrahedral mesh in `$TRILUX_DATA/tets`
//! (default `../shared/data/tets`), plus the P1 quadrature assembly of
//! Arbree et al. beside TransCut's, the difference of their solutions, and
//! the solvers compared to 1% error.
//!
//! ```sh
//! cargo run --release -p tet-diffusion --example transcut -- [--json] [--export-mtx DIR] [--repeat R]
//! cargo run --release -p tet-diffusion --example transcut -- --matrix [--mesh FILE]... [--json] [--export-mtx DIR]
//! ```
//!
//! `--matrix` instead solves the matrix of systems: every mesh (and each
//! `--mesh` file, taken in metres) × ketchup, marble and skim milk × the
//! mesh's own size and a tenth of it. Per system: block Jacobi-PCG and
//! block V-cycle-PCG to 1% error (iterations per channel, times with the
//! block's and the hierarchy's builds), `Object::solve` with the default
//! `Method::Auto` at the residual where Jacobi-PCG reaches 1% error (what
//! it chose, its time and error) and forced to each solver; `--json` rows
//! carry `system`, `solver`, `mesh_ms`, `hierarchy_ms` and `ts_ms` (per
//! channel, the chosen solver's) beside today's keys, and `--export-mtx`
//! writes each system's red channel as `SYSTEM.A.mtx`, `.b.mtx`, `.x.mtx`
//! for `bench/peers.py` (scipy and pyamg; `bench/run.sh` runs both).
//!
//! The second table compares the solvers to 1% error for all three channels,
//! hierarchy build included (built once, shared by the channels).
//!
//! Marble (Jensen et al. 2001), η = 1.3. The bunnies are in metres
//! (1 unit = 1000 mm); the unit spheres are taken as 20 mm in radius
//! (1 unit = 20 mm). One directional light from above (one-sided). Times
//! are medians of `R` runs (default 3) in ms:
//!
//! - T_b: neighbourhoods (the validated mesh) + the V-cycle hierarchy;
//! - T_m: TransCut's three RGB matrices (cotangent weights and Eq. 10–14);
//! - T_s: per RGB channel (a third of the three-channel time), CG
//!   preconditioned by the V-cycle (one hierarchy shared by the channels)
//!   from φ = 0 to 1% relative error `‖φ − φ*‖/‖φ*‖` against a reference
//!   solved to a residual of 10⁻¹⁰;
//! - T_cut: a plane cut through the centre with 5 relaxation sweeps, the
//!   rebuild (mesh, matrices, shadows) and the warm-started three-channel
//!   re-solve to a relative residual of 10⁻³, with V-cycle-PCG (hierarchy
//!   rebuilt) and with Jacobi-PCG (`--json` gives the faster);
//! - T_paint: a 10-point ketchup stroke, the rows it changes, and the
//!   warm-started three-channel re-solve to 10⁻³, both ways;
//! - P1 quad: the P1 matrices by 27-point quadrature;
//! - max diff: `max_i |φ_i − φ_P1,i| / max_i φ_P1,i` over the boundary
//!   vertices, red channel, both solved to 10⁻¹⁰; L2 diff:
//!   `‖φ − φ_P1‖ / ‖φ_P1‖` over all vertices.

use std::fmt::Write as _;
use std::io::Write as _;
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use tet_diffusion::glam::DVec3;
use tet_diffusion::multires::{
    self, Block3, Cascade, CascadeOptions, Preconditioner, Progress, SolveOptions, VCycle,
    VCycleOptions, Weights,
};
use tet_diffusion::sprs::CsMat;
use tet_diffusion::{Cut, CutMethod, Integration, Light, Medium, Method, Object, Stroke, TetMesh};

/// A solve of channel `c` into `x` with an iteration cap and an optional
/// monitor.
type SolveFn<'a> =
    dyn Fn(usize, &mut [f64], usize, Option<&mut dyn FnMut(usize, &[f64]) -> ControlFlow<()>>) + 'a;

struct Args {
    json: bool,
    export: Option<PathBuf>,
    repeat: usize,
    /// The matrix of systems: every mesh × [`MEDIA`] × [`SCALES`].
    matrix: bool,
    /// Extra tetrahedral meshes (a stuffed one, say), in metres.
    meshes: Vec<PathBuf>,
}

/// The matrix's media: short, medium and long diffusion lengths.
const MEDIA: [&str; 3] = ["ketchup", "marble", "skimmilk"];

/// The matrix's unit scales: the mesh's own size and a tenth of it (the
/// same object 10× smaller: diffusion lengths 10× longer against it).
const SCALES: [f64; 2] = [1.0, 0.1];

fn parse() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        export: None,
        repeat: 3,
        matrix: false,
        meshes: Vec::new(),
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        match a.as_str() {
            "--json" => args.json = true,
            "--matrix" => args.matrix = true,
            "--mesh" => args
                .meshes
                .push(it.next().ok_or("--mesh needs a file")?.into()),
            "--export-mtx" => {
                args.export = Some(it.next().ok_or("--export-mtx needs a folder")?.into())
            }
            "--repeat" => {
                args.repeat = it
                    .next()
                    .and_then(|r| r.parse().ok())
                    .filter(|&r| r > 0)
                    .ok_or("--repeat needs a positive count")?
            }
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    Ok(args)
}

fn main() {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!(
                "transcut: {e}\nusage: transcut [--json] [--matrix] [--mesh FILE]... [--export-mtx DIR] [--repeat R]"
            );
            std::process::exit(2);
        }
    };
    let data = std::env::var_os("TRILUX_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("../shared/data"));
    let dir = data.join("tets");
    let meshes = match list(&dir) {
        Ok(mut m) if !m.is_empty() => {
            m.extend(args.meshes.iter().cloned());
            m
        }
        _ => {
            eprintln!(
                "transcut: no tetrahedral meshes in {} (set TRILUX_DATA to the data folder)",
                dir.display()
            );
            std::process::exit(1);
        }
    };
    if let Some(d) = &args.export
        && let Err(e) = std::fs::create_dir_all(d)
    {
        eprintln!("transcut: cannot create {}: {e}", d.display());
        std::process::exit(1);
    }
    let mut table = String::from(
        "| mesh | #tets | #levels | T_b ms | T_m ms | T_s ms/channel | T_cut ms (V-cycle / Jacobi) | T_paint ms (V-cycle / Jacobi) | P1 quad ms | quad / T_m | max diff vs P1 | L2 diff vs P1 | peak MB |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut solvers = String::from(
        "| mesh | solver | build ms | iterations to 1% (per channel) | 3-channel solve ms | build + solve ms | speed-up vs Jacobi-PCG |\n|---|---|---:|---:|---:|---:|---:|\n",
    );
    let mut systems = String::from(SystemRow::HEADER);
    for path in meshes {
        let name = path
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        if args.matrix {
            match matrix(&name, &path, &args) {
                Ok(rows) => {
                    for row in rows {
                        if args.json {
                            println!("{}", row.json());
                        } else {
                            systems.push_str(&row.markdown());
                        }
                    }
                }
                Err(e) => eprintln!("transcut: {name}: {e}"),
            }
            let _ = std::io::stdout().flush();
            continue;
        }
        match bench(&name, &path, &args) {
            Ok(row) => {
                if args.json {
                    println!("{}", row.json());
                } else {
                    table.push_str(&row.markdown());
                    solvers.push_str(&row.solvers);
                }
            }
            Err(e) => eprintln!("transcut: {name}: {e}"),
        }
        let _ = std::io::stdout().flush();
    }
    if !args.json {
        if args.matrix {
            println!("{systems}");
        } else {
            println!("{table}\n{solvers}");
        }
    }
}

/// One mesh per name: TetGen `.node` first, then Gmsh `.msh` or MEDIT
/// `.mesh` (the data's `bunny_500k.msh` is the same mesh as its `.node`).
fn list(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    let mut by_stem: std::collections::BTreeMap<String, PathBuf> = Default::default();
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    files.sort();
    for ext in ["node", "msh", "mesh"] {
        for f in &files {
            if f.extension().is_some_and(|e| e == ext) {
                let stem = f
                    .file_stem()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .to_string();
                match by_stem.entry(stem) {
                    std::collections::btree_map::Entry::Occupied(_) => eprintln!(
                        "transcut: skipping {} (same mesh as the .node file)",
                        f.display()
                    ),
                    std::collections::btree_map::Entry::Vacant(e) => {
                        e.insert(f.clone());
                    }
                }
            }
        }
    }
    let mut out: Vec<(u64, PathBuf)> = by_stem
        .into_values()
        .map(|p| (std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0), p))
        .collect();
    out.sort();
    Ok(out.into_iter().map(|p| p.1).collect())
}

struct Row {
    mesh: String,
    tets: usize,
    levels: usize,
    tb: f64,
    /// T_b's two parts: the validated mesh and the hierarchy.
    mesh_ms: f64,
    hierarchy_ms: f64,
    tm: f64,
    ts: f64,
    tcut: [f64; 2],
    tpaint: [f64; 2],
    quad: f64,
    diff: f64,
    diff_l2: f64,
    solver: &'static str,
    peak_mb: f64,
    solvers: String,
}

impl Row {
    fn markdown(&self) -> String {
        format!(
            "| {} | {} | {} | {:.0} | {:.0} | {:.0} | {:.0} / {:.0} | {:.0} / {:.0} | {:.0} | {:.1}× | {:.2}% | {:.2}% | {:.0} |\n",
            self.mesh,
            self.tets,
            self.levels,
            self.tb,
            self.tm,
            self.ts,
            self.tcut[0],
            self.tcut[1],
            self.tpaint[0],
            self.tpaint[1],
            self.quad,
            self.quad / self.tm,
            100.0 * self.diff,
            100.0 * self.diff_l2,
            self.peak_mb
        )
    }

    fn json(&self) -> String {
        format!(
            "{{\"mesh\":\"{}\",\"tets\":{},\"levels\":{},\"tb_ms\":{:.3},\"tm_ms\":{:.3},\"ts_ms\":{:.3},\"tcut_ms\":{:.3},\"tpaint_ms\":{:.3},\"fem_quadrature_tm_ms\":{:.3},\"max_rel_diff_vs_fem\":{:.6},\"solver\":\"{}\",\"mesh_ms\":{:.3},\"hierarchy_ms\":{:.3},\"peak_mb\":{:.1}}}",
            self.mesh,
            self.tets,
            self.levels,
            self.tb,
            self.tm,
            self.ts,
            self.tcut[0].min(self.tcut[1]),
            self.tpaint[0].min(self.tpaint[1]),
            self.quad,
            self.diff,
            self.solver,
            self.mesh_ms,
            self.hierarchy_ms,
            self.peak_mb
        )
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Resets the kernel's peak-RSS counter (Linux ≥ 4.0); false elsewhere.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Peak resident memory, MB (`VmHWM`).
fn peak_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// `‖x‖₂`.
fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn relative_error(x: &[f64], reference: &[f64], norm: f64) -> f64 {
    x.iter()
        .zip(reference)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt()
        / norm
}

fn bench(name: &str, path: &Path, args: &Args) -> Result<Row, String> {
    reset_peak();
    let unit_mm = unit_of(name);
    let marble = Medium::measured("marble").map_err(|e| e.to_string())?;
    // T_b: neighbourhoods (validated mesh) …
    let (mesh, mesh_ms) = read_mesh(path, args)?;
    let tets = mesh.tets().len();
    let mut object = Object::homogeneous(mesh, unit_mm, marble, 1.3).map_err(|e| e.to_string())?;
    for w in object.warnings() {
        eprintln!("transcut: {name}: warning: {w}");
    }
    let light = Light::Directional {
        to_light: DVec3::new(0.1, 1.0, 0.3),
        irradiance: [1.0; 3],
    };
    object.add_light(light).map_err(|e| e.to_string())?;
    // T_m.
    let tm = median((0..args.repeat).map(|_| object.reassemble()).collect());
    let positions = object.mesh().positions().to_vec();
    let weights = Weights::Points(&positions);
    let matrices: [CsMat<f64>; 3] = std::array::from_fn(|c| object.matrix(c).clone());
    let rhs: [Vec<f64>; 3] = std::array::from_fn(|c| object.rhs(c).to_vec());
    // … + the hierarchy.
    let vopts = VCycleOptions::default();
    let mut hier_ms = Vec::new();
    let mut vcycle = None;
    for _ in 0..args.repeat {
        let t = Instant::now();
        vcycle = Some(VCycle::new(&matrices[1], weights, &vopts).map_err(|e| e.to_string())?);
        hier_ms.push(ms(t));
    }
    let vcycle = vcycle.ok_or("no run")?;
    let (mesh_only, hierarchy_only) = (median(mesh_ms), median(hier_ms.clone()));
    let tb = mesh_only + hierarchy_only;
    let levels = vcycle.hierarchy().levels();
    // Tight references.
    let tight = SolveOptions::new(1e-10, 20_000);
    let mut reference: [Vec<f64>; 3] = std::array::from_fn(|_| vec![0.0; positions.len()]);
    for c in 0..3 {
        // `tight` requires convergence: a reference that misses it is an Err.
        let _converged = multires::pcg(&matrices[c], &rhs[c], &mut reference[c], &vcycle, &tight)
            .map_err(|e| e.to_string())?;
    }
    let norms: [f64; 3] = std::array::from_fn(|c| norm(&reference[c]));
    // Iterations to 1% error for a solver, found with a monitor, then timed
    // without it.
    let to_one_percent = |solve: &SolveFn<'_>| -> (usize, f64) {
        let mut total_iterations = 0;
        let mut times = Vec::new();
        let mut counts = [0usize; 3];
        for c in 0..3 {
            let mut x = vec![0.0; positions.len()];
            let mut hit = usize::MAX;
            let mut monitor = |k: usize, x: &[f64]| {
                if relative_error(x, &reference[c], norms[c]) <= 0.01 {
                    hit = k;
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            };
            solve(c, &mut x, 20_000, Some(&mut monitor));
            counts[c] = hit;
            total_iterations += hit;
        }
        for _ in 0..args.repeat {
            let t = Instant::now();
            for (c, &k) in counts.iter().enumerate() {
                let mut x = vec![0.0; positions.len()];
                solve(c, &mut x, k, None);
            }
            times.push(ms(t));
        }
        (total_iterations / 3, median(times))
    };
    let mut solvers = String::new();
    let mut results: Vec<(&str, f64, usize, f64)> = Vec::new();
    let zero_tol = |k: usize| SolveOptions::new(0.0, k).allow_unconverged();
    // V-cycle-PCG (shared hierarchy).
    let (it, ts) = to_one_percent(&|c, x, k, m| {
        let _ = match m {
            Some(m) => multires::pcg_monitored(&matrices[c], &rhs[c], x, &vcycle, &zero_tol(k), m),
            None => multires::pcg(&matrices[c], &rhs[c], x, &vcycle, &zero_tol(k)),
        };
    });
    results.push(("V-cycle-PCG", median(hier_ms), it, ts));
    let ts = ts / 3.0;
    // Jacobi-PCG.
    let (it, tj) = to_one_percent(&|c, x, k, m| {
        let _ = match m {
            Some(m) => multires::cg_monitored(&matrices[c], &rhs[c], x, &zero_tol(k), m),
            None => multires::cg(&matrices[c], &rhs[c], x, &zero_tol(k)),
        };
    });
    results.push(("Jacobi-PCG", 0.0, it, tj));
    // The paper's cascade and its Galerkin variant.
    for (label, copts) in [
        ("cascade (Eq. 17)", CascadeOptions::default()),
        ("cascade, Galerkin", CascadeOptions::galerkin()),
    ] {
        let t = Instant::now();
        let cascade = Cascade::new(&matrices[1], weights, &copts).map_err(|e| e.to_string())?;
        let build = ms(t);
        let (it, tc) = to_one_percent(&|c, x, k, m| {
            let _ = match m {
                Some(m) => cascade.solve_monitored(&matrices[c], &rhs[c], x, &zero_tol(k), m),
                None => cascade.solve(&matrices[c], &rhs[c], x, &zero_tol(k)),
            };
        });
        results.push((label, build, it, tc));
    }
    let jacobi_total = results[1].1 + results[1].3;
    for (label, build, it, t) in &results {
        let _ = writeln!(
            solvers,
            "| {name} | {label} | {build:.0} | {it} | {t:.0} | {:.0} | {:.2}× |",
            build + t,
            jacobi_total / (build + t)
        );
    }
    // P1 by quadrature, and the difference of the solutions.
    let quad_ms: Vec<f64> = (0..args.repeat)
        .map(|_| {
            let t = Instant::now();
            let p1 = object.fem_reference(Integration::Quadrature);
            let e = ms(t);
            drop(p1);
            e
        })
        .collect();
    let quad = median(quad_ms);
    let diff = {
        let p1 = object.fem_reference(Integration::ClosedForm);
        let a = object.boundary_factor();
        let system = p1.consistent(a);
        let mesh = object.mesh();
        let mut q = vec![0.0; positions.len()];
        for (k, &v) in mesh.boundary_vertices().iter().enumerate() {
            q[v as usize] = object.incident()[k][0];
        }
        let b = p1.load(&q, a, object.fdr());
        let v = VCycle::new(&system[0], weights, &vopts).map_err(|e| e.to_string())?;
        let mut x = vec![0.0; b.len()];
        let _converged =
            multires::pcg(&system[0], &b, &mut x, &v, &tight).map_err(|e| e.to_string())?;
        let peak = mesh
            .boundary_vertices()
            .iter()
            .map(|&i| x[i as usize].abs())
            .fold(0.0, f64::max);
        let max = mesh
            .boundary_vertices()
            .iter()
            .map(|&i| (reference[0][i as usize] - x[i as usize]).abs() / peak)
            .fold(0.0, f64::max);
        (max, relative_error(&reference[0], &x, norm(&x)))
    };
    let (diff, diff_l2) = diff;
    if let Some(dir) = &args.export {
        write_mtx(&dir.join(format!("{name}.A.mtx")), &matrices[0]).map_err(|e| e.to_string())?;
        write_vector(&dir.join(format!("{name}.b.mtx")), &rhs[0]).map_err(|e| e.to_string())?;
        write_vector(&dir.join(format!("{name}.x.mtx")), &reference[0])
            .map_err(|e| e.to_string())?;
    }
    drop(vcycle);
    // T_cut: cut, rebuild, warm re-solve (from the reference φ), with the
    // V-cycle (built after the cut) and with Jacobi-PCG (no build).
    object
        .set_phi(reference.clone())
        .map_err(|e| e.to_string())?;
    object.settings.tolerance = 1e-3;
    let center = object.mesh().positions().iter().sum::<DVec3>() / positions.len() as f64;
    let plane = Cut::Plane {
        point: center,
        normal: DVec3::new(1.0, 0.0, 0.2),
    };
    let mut tcut = [0.0; 2];
    let mut cut_objects = Vec::new();
    for (k, method) in [Method::VCyclePcg, Method::JacobiPcg]
        .into_iter()
        .enumerate()
    {
        let mut o = object.clone();
        o.settings.method = method;
        let t = Instant::now();
        o.cut(&plane, CutMethod::Relax { sweeps: 5 })
            .map_err(|e| e.to_string())?;
        o.solve().map_err(|e| e.to_string())?;
        tcut[k] = ms(t);
        cut_objects.push(o);
    }
    drop(object);
    // T_paint: a stroke across the top of what is left, then a warm re-solve.
    let (lo, hi) = cut_objects[0].mesh().positions().iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let size = (hi - lo).length();
    let points = (0..10)
        .map(|k| {
            let s = k as f64 / 9.0;
            DVec3::new(
                lo.x + (0.3 + 0.4 * s) * (hi.x - lo.x),
                hi.y - 0.05 * (hi.y - lo.y),
                (lo.z + hi.z) / 2.0,
            )
        })
        .collect();
    let stroke = Stroke {
        points,
        radius: 0.03 * size,
        medium: Medium::measured("ketchup").map_err(|e| e.to_string())?,
        strength: 0.8,
    };
    let mut tpaint = [0.0; 2];
    for (k, o) in cut_objects.iter_mut().enumerate() {
        let t = Instant::now();
        o.paint(&stroke).map_err(|e| e.to_string())?;
        o.solve().map_err(|e| e.to_string())?;
        tpaint[k] = ms(t);
    }
    Ok(Row {
        mesh: name.to_owned(),
        tets,
        levels,
        tb,
        mesh_ms: mesh_only,
        hierarchy_ms: hierarchy_only,
        tm,
        ts,
        tcut,
        tpaint,
        quad,
        diff,
        diff_l2,
        solver: "V-cycle-PCG",
        peak_mb: peak_mb(),
        solvers,
    })
}

/// Matrix Market, coordinate real general, 1-based.
fn write_mtx(path: &Path, a: &CsMat<f64>) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "%%MatrixMarket matrix coordinate real general")?;
    writeln!(out, "{} {} {}", a.rows(), a.cols(), a.nnz())?;
    for (i, row) in a.outer_iterator().enumerate() {
        for (j, v) in row.iter() {
            writeln!(out, "{} {} {:e}", i + 1, j + 1, v)?;
        }
    }
    out.flush()
}

/// Matrix Market, array real general, n × 1.
fn write_vector(path: &Path, x: &[f64]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "%%MatrixMarket matrix array real general")?;
    writeln!(out, "{} 1", x.len())?;
    for v in x {
        writeln!(out, "{v:e}")?;
    }
    out.flush()
}

/// Millimetres per mesh unit: the unit spheres are 20 mm in radius, the
/// rest (the bunnies, a stuffed mesh from metres) in metres.
fn unit_of(name: &str) -> f64 {
    if name.starts_with("sphere") {
        20.0
    } else {
        1000.0
    }
}

/// One system of the matrix: a mesh, a medium and a unit scale, its
/// solvers to 1% error from φ = 0 (all three channels).
struct SystemRow {
    system: String,
    mesh: String,
    tets: usize,
    levels: usize,
    n: usize,
    nnz: usize,
    mesh_ms: f64,
    tm_ms: f64,
    /// [`multires::Block3`]'s build (renumbering, checks).
    block_ms: f64,
    jacobi_iterations: [usize; 3],
    /// Block Jacobi-PCG, block build included.
    jacobi_ms: f64,
    hierarchy_ms: f64,
    vcycle_iterations: [usize; 3],
    /// Block V-cycle-PCG, block build included, hierarchy not.
    vcycle_ms: f64,
    /// What `Method::Auto` chose at the residual Jacobi-PCG reaches 1%
    /// error at, its time (everything: block, probe, hierarchy if built)
    /// and its error against the reference.
    solver: String,
    /// Why (the choice's report).
    choice: String,
    auto_ms: f64,
    auto_hierarchy_ms: f64,
    auto_error: f64,
    /// `Object::solve` forced to each, at the same tolerance.
    forced_ms: [f64; 2],
}

impl SystemRow {
    const HEADER: &str = "| system | unknowns | T_mesh ms | T_m ms | Jacobi-PCG iterations (R/G/B) | Jacobi-PCG ms | hierarchy ms | V-cycle iterations | V-cycle-PCG ms | chosen | chosen ms (error) | forced Jacobi / V-cycle ms | chosen / best forced |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|\n";

    fn markdown(&self) -> String {
        let best = self.forced_ms[0].min(self.forced_ms[1]);
        format!(
            "| {} | {} | {:.0} | {:.0} | {:?} | {:.1} | {:.0} | {:?} | {:.1} | {} | {:.1} ({:.2}%) | {:.1} / {:.1} | {:.2}× |\n",
            self.system,
            self.n,
            self.mesh_ms,
            self.tm_ms,
            self.jacobi_iterations,
            self.jacobi_ms,
            self.hierarchy_ms,
            self.vcycle_iterations,
            self.vcycle_ms,
            self.solver,
            self.auto_ms,
            100.0 * self.auto_error,
            self.forced_ms[0],
            self.forced_ms[1],
            self.auto_ms / best
        )
    }

    /// `ts_ms` and `hierarchy_ms` per channel for the chosen solver (what
    /// a solve costs beyond the mesh is their sum), beside the rest.
    fn json(&self) -> String {
        let chosen_hierarchy = self.auto_hierarchy_ms / 3.0;
        format!(
            "{{\"system\":\"{}\",\"mesh\":\"{}\",\"tets\":{},\"levels\":{},\"tb_ms\":{:.3},\"n\":{},\"nnz\":{},\"mesh_ms\":{:.3},\"tm_ms\":{:.3},\"block_ms\":{:.3},\"solver\":\"{}\",\"solver_choice\":\"{}\",\"hierarchy_ms\":{:.3},\"ts_ms\":{:.3},\"auto_ms\":{:.3},\"auto_error\":{:.5},\"jacobi_iterations\":{:?},\"jacobi_ms\":{:.3},\"vcycle_hierarchy_ms\":{:.3},\"vcycle_iterations\":{:?},\"vcycle_ms\":{:.3},\"forced_jacobi_ms\":{:.3},\"forced_vcycle_ms\":{:.3}}}",
            self.system,
            self.mesh,
            self.tets,
            self.levels,
            self.mesh_ms + self.auto_hierarchy_ms,
            self.n,
            self.nnz,
            self.mesh_ms,
            self.tm_ms,
            self.block_ms,
            self.solver,
            self.choice,
            chosen_hierarchy,
            self.auto_ms / 3.0 - chosen_hierarchy,
            self.auto_ms,
            self.auto_error,
            self.jacobi_iterations,
            self.jacobi_ms,
            self.hierarchy_ms,
            self.vcycle_iterations,
            self.vcycle_ms,
            self.forced_ms[0],
            self.forced_ms[1]
        )
    }
}

/// The file's tetrahedra as a validated mesh, built `repeat` times: the
/// mesh and each build's time (T_b's neighbourhoods), ms.
fn read_mesh(path: &Path, args: &Args) -> Result<(TetMesh, Vec<f64>), String> {
    let file = trilux_io::tet::TetMesh::read(path).map_err(|e| e.to_string())?;
    let mut times = Vec::new();
    let mut mesh = None;
    for _ in 0..args.repeat {
        let t = Instant::now();
        mesh = Some(TetMesh::new(&file.positions, &file.tets).map_err(|e| e.to_string())?);
        times.push(ms(t));
    }
    Ok((mesh.ok_or("no run")?, times))
}

/// The matrix's rows of one mesh: every medium × scale.
fn matrix(name: &str, path: &Path, args: &Args) -> Result<Vec<SystemRow>, String> {
    let (mesh, mesh_ms) = read_mesh(path, args)?;
    let mesh_ms = median(mesh_ms);
    let mut rows = Vec::new();
    for medium in MEDIA {
        for scale in SCALES {
            let system = format!("{name}-{medium}-{scale}x");
            let mut row = system_row(&system, &mesh, unit_of(name) * scale, medium, mesh_ms, args)?;
            row.mesh = name.to_owned();
            eprintln!("transcut: {}", row.markdown().trim_end());
            rows.push(row);
        }
    }
    Ok(rows)
}

/// `‖x − x*‖ / ‖x*‖` of each channel.
fn errors(x: &[Vec<f64>; 3], reference: &[Vec<f64>; 3]) -> [f64; 3] {
    std::array::from_fn(|c| relative_error(&x[c], &reference[c], norm(&reference[c])))
}

fn system_row(
    system: &str,
    mesh: &TetMesh,
    unit_mm: f64,
    medium: &str,
    mesh_ms: f64,
    args: &Args,
) -> Result<SystemRow, String> {
    let medium = Medium::measured(medium).map_err(|e| e.to_string())?;
    let mut object =
        Object::homogeneous(mesh.clone(), unit_mm, medium, 1.3).map_err(|e| e.to_string())?;
    object
        .add_light(Light::Directional {
            to_light: DVec3::new(0.1, 1.0, 0.3),
            irradiance: [1.0; 3],
        })
        .map_err(|e| e.to_string())?;
    let tm_ms = median((0..args.repeat).map(|_| object.reassemble()).collect());
    let matrices: [CsMat<f64>; 3] = std::array::from_fn(|c| object.matrix(c).clone());
    let m = [&matrices[0], &matrices[1], &matrices[2]];
    let rhs: [Vec<f64>; 3] = std::array::from_fn(|c| object.rhs(c).to_vec());
    let b = [&rhs[0][..], &rhs[1][..], &rhs[2][..]];
    let n = rhs[0].len();
    // The reference: V-cycle-PCG to 10⁻¹⁰.
    let mut tight = object.clone();
    tight.settings.method = Method::VCyclePcg;
    tight.settings.tolerance = 1e-10;
    tight.settings.max_iterations = 20_000;
    tight.solve().map_err(|e| e.to_string())?;
    let reference: [Vec<f64>; 3] = std::array::from_fn(|c| tight.phi(c).to_vec());
    drop(tight);
    // Block Jacobi-PCG: iterations to 1% error per channel, and the
    // residual there.
    let mut block_ms = Vec::new();
    let mut block = None;
    for _ in 0..args.repeat {
        let t = Instant::now();
        block = Some(Block3::new(m).map_err(|e| e.to_string())?);
        block_ms.push(ms(t));
    }
    let block = block.ok_or("no run")?;
    let block_ms = median(block_ms);
    let count = |pre: Option<[&dyn Preconditioner; 3]>| -> Result<([usize; 3], f64), String> {
        let mut hit = [usize::MAX; 3];
        let mut residual_at = f64::INFINITY;
        let mut monitor = |p: &Progress<'_>| {
            for c in 0..3 {
                if hit[c] == usize::MAX {
                    let x = p.solution(c).unwrap_or_default();
                    if relative_error(&x, &reference[c], norm(&reference[c])) <= 0.01 {
                        hit[c] = p.iteration();
                        residual_at = residual_at.min(p.residual()[c]);
                    }
                }
            }
            if hit.iter().all(|&h| h != usize::MAX) {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        };
        let mut x = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        let [x0, x1, x2] = &mut x;
        let options = SolveOptions::new(0.0, 20_000).allow_unconverged();
        let _ = match pre {
            Some(v) => block.pcg(b, [x0, x1, x2], v, &options, Some(&mut monitor)),
            None => block.cg(b, [x0, x1, x2], &options, Some(&mut monitor)),
        }
        .map_err(|e| e.to_string())?;
        Ok((hit, residual_at))
    };
    let timed = |pre: Option<[&dyn Preconditioner; 3]>, k: usize| -> f64 {
        let runs = (0..args.repeat)
            .map(|_| {
                let mut x = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
                let [x0, x1, x2] = &mut x;
                let options = SolveOptions::new(0.0, k).allow_unconverged();
                let t = Instant::now();
                let _ = match pre {
                    Some(v) => block.pcg(b, [x0, x1, x2], v, &options, None),
                    None => block.cg(b, [x0, x1, x2], &options, None),
                };
                ms(t)
            })
            .collect();
        median(runs)
    };
    let (jacobi_iterations, tolerance) = count(None)?;
    let jacobi_ms = block_ms + timed(None, jacobi_iterations.into_iter().max().unwrap_or(0));
    // V-cycle-PCG: the hierarchy as `Object` builds it (one, each
    // channel's operators on it).
    let positions = object.mesh().positions().to_vec();
    let weights = Weights::Points(&positions);
    let mut hier_ms = Vec::new();
    let mut vcycles = None;
    for _ in 0..args.repeat {
        let t = Instant::now();
        let green = VCycle::new(&matrices[1], weights, &VCycleOptions::default())
            .map_err(|e| e.to_string())?;
        let red = green.refreshed(&matrices[0]).map_err(|e| e.to_string())?;
        let blue = green.refreshed(&matrices[2]).map_err(|e| e.to_string())?;
        hier_ms.push(ms(t));
        vcycles = Some([red, green, blue]);
    }
    let hierarchy_ms = median(hier_ms);
    let v = vcycles.ok_or("no run")?;
    let pre: [&dyn Preconditioner; 3] = [&v[0], &v[1], &v[2]];
    let (vcycle_iterations, _) = count(Some(pre))?;
    let vcycle_ms = block_ms + timed(Some(pre), vcycle_iterations.into_iter().max().unwrap_or(0));
    // `Object::solve`, auto and forced, at the residual of 1% error.
    let mut fresh = object.clone();
    fresh.settings.tolerance = tolerance;
    fresh.settings.max_iterations = 20_000;
    fresh.forget_hierarchy();
    // The three round-robin (auto, Jacobi, V-cycle, auto, ...), so that a
    // drift of the machine's speed falls on all alike, after one untimed
    // round (the allocator's first touch of the vectors).
    let methods = [Method::Auto, Method::JacobiPcg, Method::VCyclePcg];
    let mut times: [Vec<f64>; 3] = Default::default();
    let mut last = None;
    for round in 0..=args.repeat {
        for (k, &method) in methods.iter().enumerate() {
            let mut o = fresh.clone();
            o.settings.method = method;
            let t = Instant::now();
            let r = o.solve().map_err(|e| e.to_string())?;
            if round > 0 {
                times[k].push(ms(t));
            }
            if k == 0 {
                last = Some((r, o));
            }
        }
    }
    let (r, o) = last.ok_or("no run")?;
    let x: [Vec<f64>; 3] = std::array::from_fn(|c| o.phi(c).to_vec());
    let auto_error = errors(&x, &reference).into_iter().fold(0.0, f64::max);
    let (choice, auto_hierarchy_ms, levels) = (r.choice, r.hierarchy_ms, r.levels);
    let [auto_ms, jacobi_forced, vcycle_forced] = times.map(median);
    let forced_ms = [jacobi_forced, vcycle_forced];
    if let Some(dir) = &args.export {
        write_mtx(&dir.join(format!("{system}.A.mtx")), &matrices[0]).map_err(|e| e.to_string())?;
        write_vector(&dir.join(format!("{system}.b.mtx")), &rhs[0]).map_err(|e| e.to_string())?;
        write_vector(&dir.join(format!("{system}.x.mtx")), &reference[0])
            .map_err(|e| e.to_string())?;
    }
    Ok(SystemRow {
        system: system.to_owned(),
        mesh: String::new(),
        tets: mesh.tets().len(),
        levels,
        n,
        nnz: block.nnz(),
        mesh_ms,
        tm_ms,
        block_ms,
        jacobi_iterations,
        jacobi_ms,
        hierarchy_ms,
        vcycle_iterations,
        vcycle_ms,
        solver: choice.solver.to_string(),
        choice: choice.to_string(),
        auto_ms,
        auto_hierarchy_ms: if auto_hierarchy_ms > 0.0 {
            auto_hierarchy_ms
        } else {
            0.0
        },
        auto_error,
        forced_ms,
    })
}
