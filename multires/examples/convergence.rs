//! Relative error against time for Jacobi-PCG, TransCut's cascade and
//! V-cycle-preconditioned CG (the paper's Fig. 7), with hierarchy build
//! times (T_b) and solve times to 1% and 0.1% error (T_s).
//!
//! ```sh
//! cargo run --release -p multires --example convergence -- [--json]
//!     [--grid N]... [--matrix A.mtx [--rhs b.mtx]] [--threads T]
//!     [--repeat R] [--csv DIR]
//! ```
//!
//! Default systems: the 7-point Laplacian + mass on cubic grids of 10⁵
//! and 10⁶ unknowns, diffusion length √(κ/μ) = 30 cells, lit on the face
//! x = 0. Times are medians of `R` runs (default 3). The error is
//! `‖x − x*‖ / ‖x*‖` against a reference solved to a relative residual of
//! 10⁻¹¹; the time spent measuring it is not counted.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use multires::{
    Cascade, CascadeOptions, CoarseSystem, SolveOptions, VCycle, VCycleOptions, Weights, cg,
    cg_monitored, grid,
};
use sprs::CsMat;

struct Args {
    json: bool,
    grids: Vec<usize>,
    matrix: Option<PathBuf>,
    rhs: Option<PathBuf>,
    threads: Option<usize>,
    repeat: usize,
    csv: PathBuf,
}

fn parse() -> Result<Args, String> {
    let mut args = Args {
        json: false,
        grids: Vec::new(),
        matrix: None,
        rhs: None,
        threads: None,
        repeat: 3,
        csv: PathBuf::from("target/convergence"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--json" => args.json = true,
            "--grid" => args.grids.push(parse_count(&value("--grid")?)?),
            "--matrix" => args.matrix = Some(value("--matrix")?.into()),
            "--rhs" => args.rhs = Some(value("--rhs")?.into()),
            "--threads" => {
                args.threads = Some(
                    value("--threads")?
                        .parse()
                        .map_err(|e| format!("--threads: {e}"))?,
                )
            }
            "--repeat" => {
                args.repeat = value("--repeat")?
                    .parse()
                    .map_err(|e| format!("--repeat: {e}"))?
            }
            "--csv" => args.csv = value("--csv")?.into(),
            "-h" | "--help" => {
                return Err("usage: convergence [--json] [--grid N]... [--matrix A.mtx [--rhs b.mtx]] [--threads T] [--repeat R] [--csv DIR]".into());
            }
            other => return Err(format!("unknown argument {other}")),
        }
    }
    if args.rhs.is_some() && args.matrix.is_none() {
        return Err("--rhs needs --matrix".into());
    }
    if args.grids.is_empty() && args.matrix.is_none() {
        args.grids = vec![100_000, 1_000_000];
    }
    args.repeat = args.repeat.max(1);
    Ok(args)
}

/// `100000`, `1e6`, `1_000_000`.
fn parse_count(s: &str) -> Result<usize, String> {
    let clean = s.replace('_', "");
    clean
        .parse::<usize>()
        .or_else(|_| clean.parse::<f64>().map(|v| v as usize))
        .map_err(|e| format!("--grid {s}: {e}"))
}

/// A system to solve.
struct System {
    name: String,
    matrix: CsMat<f64>,
    rhs: Vec<f64>,
    positions: Option<Vec<[f64; 3]>>,
}

fn read_matrix(path: &Path) -> Result<CsMat<f64>, String> {
    multires::mtx::read_matrix(path).map_err(|e| e.to_string())
}

/// A vector in Matrix Market form, `n` entries.
fn read_vector(path: &Path, n: usize) -> Result<Vec<f64>, String> {
    let v = multires::mtx::read_vector(path).map_err(|e| e.to_string())?;
    if v.len() != n {
        return Err(format!(
            "{}: {} values, the matrix has {n} rows",
            path.display(),
            v.len()
        ));
    }
    Ok(v)
}

/// One solver's measurements.
struct Run {
    build_ms: f64,
    /// (ms since the start of the solve, relative error).
    curve: Vec<(f64, f64)>,
    iterations: usize,
    detail: String,
}

impl Run {
    fn time_to(&self, error: f64) -> Option<f64> {
        self.curve
            .iter()
            .find(|&&(_, e)| e <= error)
            .map(|&(t, _)| t)
    }
    fn iterations_to(&self, error: f64, offset: usize) -> Option<usize> {
        self.curve
            .iter()
            .position(|&(_, e)| e <= error)
            .map(|k| k + offset)
    }
}

const TARGET: f64 = 1e-3;

/// Records (time, error) at each call, with the measuring time removed,
/// and stops once the error is below `TARGET`.
struct Recorder<'r> {
    reference: &'r [f64],
    norm: f64,
    start: Instant,
    excluded: f64,
    curve: Vec<(f64, f64)>,
}

impl<'r> Recorder<'r> {
    fn new(reference: &'r [f64]) -> Self {
        Self {
            reference,
            norm: reference.iter().map(|v| v * v).sum::<f64>().sqrt(),
            start: Instant::now(),
            excluded: 0.0,
            curve: Vec::new(),
        }
    }
    fn record(&mut self, x: &[f64]) -> ControlFlow<()> {
        let entered = Instant::now();
        let t = (entered - self.start).as_secs_f64() * 1e3 - self.excluded;
        let diff: f64 = x
            .iter()
            .zip(self.reference)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt();
        let error = diff / self.norm;
        self.curve.push((t, error));
        self.excluded += entered.elapsed().as_secs_f64() * 1e3;
        if error <= TARGET {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

fn run_pcg(s: &System, reference: &[f64], opts: &SolveOptions) -> Result<Run, String> {
    let mut x = vec![0.0; s.rhs.len()];
    let mut rec = Recorder::new(reference);
    let _ = rec.record(&x);
    let report = cg_monitored(&s.matrix, &s.rhs, &mut x, opts, &mut |_, x| rec.record(x))
        .map_err(|e| e.to_string())?;
    Ok(Run {
        build_ms: 0.0,
        iterations: report.iterations,
        curve: rec.curve,
        detail: String::new(),
    })
}

fn weights(s: &System) -> Weights<'_> {
    match &s.positions {
        Some(p) => Weights::Positions(p),
        None => Weights::Uniform,
    }
}

fn run_cascade(s: &System, reference: &[f64], opts: &SolveOptions) -> Result<Run, String> {
    cascade_with(s, reference, opts, &cascade_options())
}

/// The paper's cascade: Eq. 17's systems on the enhanced hierarchy.
fn cascade_options() -> CascadeOptions {
    CascadeOptions::default()
}

/// Galerkin coarse systems with linear-precision interpolation
/// ([`CascadeOptions::galerkin`]; without positions, Galerkin systems on
/// the paper's hierarchy).
fn run_cascade_galerkin(s: &System, reference: &[f64], opts: &SolveOptions) -> Result<Run, String> {
    let options = match s.positions {
        Some(_) => CascadeOptions::galerkin(),
        None => CascadeOptions {
            system: CoarseSystem::Galerkin,
            ..CascadeOptions::default()
        },
    };
    cascade_with(s, reference, opts, &options)
}

fn cascade_with(
    s: &System,
    reference: &[f64],
    opts: &SolveOptions,
    options: &CascadeOptions,
) -> Result<Run, String> {
    let t = Instant::now();
    let cascade = Cascade::new(&s.matrix, weights(s), options).map_err(|e| e.to_string())?;
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut x = vec![0.0; s.rhs.len()];
    let mut rec = Recorder::new(reference);
    let report = cascade
        .solve_monitored(&s.matrix, &s.rhs, &mut x, opts, &mut |_, x| rec.record(x))
        .map_err(|e| e.to_string())?;
    let coarse: Vec<String> = report
        .coarse
        .iter()
        .map(|(l, r)| format!("L{l}:{}", r.iterations))
        .collect();
    Ok(Run {
        build_ms,
        iterations: report.finest.iterations,
        curve: rec.curve,
        detail: format!(
            "levels {:?}, nnz {:?}; coarse iterations {}{}",
            cascade.hierarchy().sizes(),
            cascade.nonzeros(),
            coarse.join(" "),
            if report.fallbacks.is_empty() {
                String::new()
            } else {
                format!(
                    "; fell back from {:?}",
                    report.fallbacks.iter().map(|f| f.0).collect::<Vec<_>>()
                )
            }
        ),
    })
}

fn run_vcycle(s: &System, reference: &[f64], opts: &SolveOptions) -> Result<Run, String> {
    let t = Instant::now();
    let v =
        VCycle::new(&s.matrix, weights(s), &VCycleOptions::default()).map_err(|e| e.to_string())?;
    let build_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut x = vec![0.0; s.rhs.len()];
    let mut rec = Recorder::new(reference);
    let _ = rec.record(&x);
    let report = v
        .solve_monitored(&s.rhs, &mut x, opts, &mut |_, x| rec.record(x))
        .map_err(|e| e.to_string())?;
    Ok(Run {
        build_ms,
        iterations: report.iterations,
        curve: rec.curve,
        detail: format!(
            "levels {:?}; operator complexity {:.2}",
            v.hierarchy().sizes(),
            v.operator_complexity()
        ),
    })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median build and solve times over the runs; the curve of the median-time run.
struct Summary {
    solver: &'static str,
    tb: f64,
    ts1: Option<f64>,
    ts01: Option<f64>,
    iterations: Option<usize>,
    detail: String,
    curve: Vec<(f64, f64)>,
}

fn summarise(solver: &'static str, runs: Vec<Run>, offset: usize) -> Summary {
    let times = |e: f64| -> Option<f64> {
        let t: Option<Vec<f64>> = runs.iter().map(|r| r.time_to(e)).collect();
        t.map(median)
    };
    let ts01 = times(1e-3);
    let mid = runs
        .iter()
        .min_by(|a, b| {
            let key = |r: &Run| (r.time_to(1e-3).unwrap_or(f64::MAX) - ts01.unwrap_or(0.0)).abs();
            key(a).total_cmp(&key(b))
        })
        .map_or(0, |r| {
            runs.iter().position(|q| std::ptr::eq(q, r)).unwrap_or(0)
        });
    Summary {
        solver,
        tb: median(runs.iter().map(|r| r.build_ms).collect()),
        ts1: times(1e-2),
        ts01,
        iterations: runs[mid]
            .iterations_to(1e-3, offset)
            .or(Some(runs[mid].iterations)),
        detail: runs[mid].detail.clone(),
        curve: runs[mid].curve.clone(),
    }
}

fn fmt(v: Option<f64>) -> String {
    v.map_or("—".into(), |v| format!("{v:.0}"))
}

fn main() {
    let args = match parse() {
        Ok(a) => a,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    if let Some(t) = args.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build_global()
    {
        eprintln!("--threads: {e}");
        std::process::exit(2);
    }
    let mut systems = Vec::new();
    for &n in &args.grids {
        let dims = grid::cube_for(n);
        let p = match grid::diffusion(dims, 30.0) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("--grid {n}: {e}");
                std::process::exit(2);
            }
        };
        systems.push(System {
            name: format!("grid{}x{}x{}", dims[0], dims[1], dims[2]),
            matrix: p.matrix,
            rhs: p.rhs,
            positions: Some(p.positions),
        });
    }
    if let Some(path) = &args.matrix {
        let loaded = read_matrix(path).and_then(|m| {
            let rhs = match &args.rhs {
                Some(r) => read_vector(r, m.rows())?,
                None => vec![1.0; m.rows()],
            };
            Ok((m, rhs))
        });
        match loaded {
            Ok((matrix, rhs)) => systems.push(System {
                name: path
                    .file_name()
                    .map_or("matrix".into(), |f| f.to_string_lossy().into_owned()),
                matrix,
                rhs,
                positions: None,
            }),
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(1);
            }
        }
    }
    let threads = rayon::current_num_threads();
    if !args.json {
        println!("# multires: TransCut Sec. 4, Fig. 7 (relative error vs time)\n");
        println!(
            "{threads} thread(s); medians of {} runs; T_b = hierarchy and coarse operators, T_s = solve from x = 0.\n",
            args.repeat
        );
    }
    let mut all = Vec::new();
    for s in &systems {
        eprintln!("{}: reference solve…", s.name);
        let mut reference = vec![0.0; s.rhs.len()];
        // The reference's report is printed, converged or not.
        let tight = SolveOptions::new(1e-11, 50_000).allow_unconverged();
        let report = match cg(&s.matrix, &s.rhs, &mut reference, &tight) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("{}: {e}", s.name);
                std::process::exit(1);
            }
        };
        // The recorder stops each solver at the error target; stagnating
        // first is reported in its row, not an error.
        let opts = SolveOptions::new(1e-13, 20_000).allow_unconverged();
        let mut summaries = Vec::new();
        type Solver = fn(&System, &[f64], &SolveOptions) -> Result<Run, String>;
        // The cascade's first point is level 0's start (iteration 0).
        let solvers: [(&'static str, Solver, usize); 4] = [
            ("pcg", run_pcg, 0),
            ("cascade", run_cascade, 0),
            ("cascade-galerkin", run_cascade_galerkin, 0),
            ("vcycle-pcg", run_vcycle, 0),
        ];
        for (name, solver, offset) in solvers {
            eprintln!("{}: {name}…", s.name);
            let runs: Result<Vec<Run>, String> = (0..args.repeat)
                .map(|_| solver(s, &reference, &opts))
                .collect();
            match runs {
                Ok(runs) => summaries.push(summarise(name, runs, offset)),
                Err(e) => eprintln!("{}: {name}: {e}", s.name),
            }
        }
        if let Err(e) = write_csv(&args.csv, &s.name, &summaries) {
            eprintln!("{e}");
        }
        if args.json {
            for m in &summaries {
                println!(
                    "{{\"matrix\":\"{}\",\"rows\":{},\"nnz\":{},\"solver\":\"{}\",\"tb_ms\":{:.3},\"ts_1pct_ms\":{},\"ts_01pct_ms\":{},\"iterations\":{},\"threads\":{}}}",
                    s.name,
                    s.matrix.rows(),
                    s.matrix.nnz(),
                    m.solver,
                    m.tb,
                    m.ts1.map_or("null".into(), |v| format!("{v:.3}")),
                    m.ts01.map_or("null".into(), |v| format!("{v:.3}")),
                    m.iterations.map_or("null".into(), |v| v.to_string()),
                    threads
                );
            }
        } else {
            println!(
                "## {} ({} rows, {} non-zeros; reference: {} CG iterations to residual {:.1e})\n",
                s.name,
                s.matrix.rows(),
                s.matrix.nnz(),
                report.iterations,
                report.residual
            );
            println!(
                "| solver | T_b ms | T_s 1% ms | T_s 0.1% ms | T_b + T_s 0.1% ms | level-0 iterations to 0.1% | notes |"
            );
            println!("|---|---:|---:|---:|---:|---:|---|");
            for m in &summaries {
                println!(
                    "| {} | {:.0} | {} | {} | {} | {} | {} |",
                    m.solver,
                    m.tb,
                    fmt(m.ts1),
                    fmt(m.ts01),
                    fmt(m.ts01.map(|t| t + m.tb)),
                    m.iterations.map_or("—".into(), |i| i.to_string()),
                    m.detail
                );
            }
            println!(
                "\nCurves: {}\n",
                args.csv.join(format!("{}.csv", s.name)).display()
            );
        }
        all.push((s.name.clone(), s.matrix.rows(), summaries));
    }
    if !args.json {
        print_summary(&all);
    }
}

fn write_csv(dir: &Path, name: &str, summaries: &[Summary]) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let path = dir.join(format!("{name}.csv"));
    let mut out = String::from("solver,time_ms,relative_error\n");
    for m in summaries {
        for (t, e) in &m.curve {
            out.push_str(&format!("{},{t:.3},{e:.6e}\n", m.solver));
        }
    }
    std::fs::write(&path, out).map_err(|e| format!("{}: {e}", path.display()))
}

/// The speed-ups of the largest grid run against Jacobi-PCG, like for
/// like: solve only (the hierarchy already built, as when one matrix is
/// solved for many right-hand sides), and with the build included (one
/// solve after every change of the matrix).
fn print_summary(runs: &[(String, usize, Vec<Summary>)]) {
    let Some((name, _, s)) = runs
        .iter()
        .filter(|b| b.0.starts_with("grid"))
        .max_by_key(|b| b.1)
    else {
        return;
    };
    let get = |solver: &str| s.iter().find(|m| m.solver == solver);
    let Some(pcg) = get("pcg") else {
        return;
    };
    println!("## Speed-up over Jacobi-PCG ({name})\n");
    println!("| solver | to | solve only | build + solve |");
    println!("|---|---|---:|---:|");
    let ratio = |base: Option<f64>, own: Option<f64>| match base.zip(own) {
        Some((b, o)) => format!("{:.2}×", b / o),
        None => "not reached".into(),
    };
    for solver in ["cascade", "cascade-galerkin", "vcycle-pcg"] {
        let Some(m) = get(solver) else { continue };
        for (label, base, own) in [("1%", pcg.ts1, m.ts1), ("0.1%", pcg.ts01, m.ts01)] {
            println!(
                "| {solver} | {label} | {} | {} |",
                ratio(base, own),
                ratio(base, own.map(|o| o + m.tb)),
            );
        }
    }
}
