//! Krylov solvers, the cascade and the V-cycle: manufactured solutions,
//! reported residuals, termination, fallbacks, determinism and errors.

use crate::common;

use common::*;
use multires::{
    Cascade, CascadeOptions, CoarseSystem, Error, HierarchyOptions, Jacobi, SolveOptions, Stop,
    VCycle, VCycleOptions, Weights, bicgstab, cg, coarse, grid, pcg,
};
use sprs::{CsMat, TriMat};

fn tight() -> SolveOptions {
    SolveOptions::new(1e-10, 5_000)
}

/// `x*` with entries in [−1, 1] and `b = A x*`.
fn manufactured(a: &CsMat<f64>, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let mut rng = Rng(seed);
    let x: Vec<f64> = (0..a.rows()).map(|_| 2.0 * rng.f64() - 1.0).collect();
    let b = apply(a, &x);
    (x, b)
}

fn max_error(x: &[f64], y: &[f64]) -> f64 {
    let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    x.iter()
        .zip(y)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
        / scale
}

#[test]
fn cg_recovers_manufactured_solutions_on_grids_and_random_graphs() {
    let g = grid_problem(12);
    let (r, _) = random_geometric(1_500, 0.15, 0.2, 21);
    for (name, a) in [("grid", g.matrix), ("random graph", r)] {
        let (exact, b) = manufactured(&a, 4);
        let mut x = vec![0.0; a.rows()];
        let report = cg(&a, &b, &mut x, &tight()).unwrap();
        assert!(report.converged(), "{name}: {report:?}");
        // The reported residual is the true one, and within the tolerance.
        let true_residual = relative_residual(&a, &b, &x);
        assert!(
            (report.residual - true_residual).abs() <= 1e-3 * true_residual + 1e-15,
            "{name}"
        );
        assert!(true_residual <= 1e-10);
        assert!(
            max_error(&x, &exact) < 1e-6,
            "{name}: error {}",
            max_error(&x, &exact)
        );
    }
}

#[test]
fn a_warm_start_at_the_solution_needs_no_iteration() {
    let g = grid_problem(8);
    let (exact, b) = manufactured(&g.matrix, 5);
    let mut x = exact.clone();
    let report = cg(&g.matrix, &b, &mut x, &tight()).unwrap();
    assert_eq!((report.stop, report.iterations), (Stop::Converged, 0));
    let mut x = vec![0.0; exact.len()];
    let cold = cg(&g.matrix, &b, &mut x, &tight()).unwrap();
    // Halfway there, fewer iterations remain.
    let mut warm: Vec<f64> = exact.iter().map(|v| 0.5 * v).collect();
    let report = cg(&g.matrix, &b, &mut warm, &tight()).unwrap();
    assert!(report.iterations < cold.iterations);
}

/// A non-symmetric system: diffusion plus upwind convection on a grid.
fn convection(side: usize) -> CsMat<f64> {
    let g = grid::diffusion([side, side, side], 4.0).unwrap();
    let mut t = TriMat::new((g.matrix.rows(), g.matrix.cols()));
    for (v, (i, j)) in g.matrix.iter() {
        t.add_triplet(i, j, *v);
    }
    for i in 1..g.matrix.rows() {
        t.add_triplet(i, i, 0.8);
        t.add_triplet(i, i - 1, -0.8);
    }
    t.to_csr()
}

#[test]
fn bicgstab_solves_non_symmetric_systems() {
    let a = convection(10);
    let (exact, b) = manufactured(&a, 6);
    let mut x = vec![0.0; a.rows()];
    let report = bicgstab(&a, &b, &mut x, &tight()).unwrap();
    assert!(report.converged(), "{report:?}");
    let true_residual = relative_residual(&a, &b, &x);
    assert!((report.residual - true_residual).abs() <= 1e-3 * true_residual + 1e-15);
    assert!(max_error(&x, &exact) < 1e-6);
    // CG is not for this matrix: it refuses it, once, pointing to
    // BiCGSTAB, and so do the solvers that end in CG.
    let mut y = vec![0.0; a.rows()];
    let e = cg(&a, &b, &mut y, &tight()).unwrap_err();
    assert!(matches!(e, Error::NotSymmetric { .. }), "{e}");
    assert!(e.to_string().contains("bicgstab"), "{e}");
    assert!(matches!(
        multires::pcg(&a, &b, &mut y, &Jacobi::new(&a).unwrap(), &tight()),
        Err(Error::NotSymmetric { .. })
    ));
    assert!(matches!(
        VCycle::new(&a, Weights::Uniform, &VCycleOptions::default()),
        Err(Error::NotSymmetric { .. })
    ));
    assert!(matches!(
        Cascade::new(&a, Weights::Uniform, &CascadeOptions::default()),
        Err(Error::NotSymmetric { .. })
    ));
}

#[test]
fn solvers_stop_at_the_cap_or_on_breakdown() {
    let g = grid_problem(10);
    let capped = SolveOptions::new(1e-12, 7).allow_unconverged();
    let mut x = vec![0.0; g.rhs.len()];
    let r = cg(&g.matrix, &g.rhs, &mut x, &capped).unwrap();
    assert_eq!((r.stop, r.iterations), (Stop::MaxIterations, 7));
    assert!((r.residual - relative_residual(&g.matrix, &g.rhs, &x)).abs() < 1e-12);
    // By default the cap is an error that carries the same report.
    let mut y = vec![0.0; g.rhs.len()];
    match cg(&g.matrix, &g.rhs, &mut y, &SolveOptions::new(1e-12, 7)) {
        Err(Error::NotConverged { report, tolerance }) => {
            assert_eq!((report, tolerance), (r, 1e-12));
            assert_eq!(x, y);
        }
        other => panic!("expected NotConverged, got {other:?}"),
    }
    let mut x = vec![0.0; g.rhs.len()];
    let r = bicgstab(&g.matrix, &g.rhs, &mut x, &capped).unwrap();
    assert_eq!(r.stop, Stop::MaxIterations);
    assert!(r.iterations <= 7);
    // Indefinite (eigenvalues 3 and −1) with a positive diagonal: CG
    // must stop without claiming convergence.
    let mut t = TriMat::new((2, 2));
    for (i, j, v) in [(0, 0, 1.0), (0, 1, 2.0), (1, 0, 2.0), (1, 1, 1.0)] {
        t.add_triplet(i, j, v);
    }
    let a: CsMat<f64> = t.to_csr();
    let mut x = vec![0.0; 2];
    let r = cg(&a, &[1.0, -1.0], &mut x, &tight().allow_unconverged()).unwrap();
    assert!(
        r.stop == Stop::Converged || r.stop == Stop::Breakdown,
        "{r:?}"
    );
    if r.stop == Stop::Breakdown {
        let mut y = vec![0.0; 2];
        let e = cg(&a, &[1.0, -1.0], &mut y, &tight()).unwrap_err();
        assert!(matches!(e, Error::NotConverged { .. }), "{e}");
        assert!(e.to_string().contains("broke down"), "{e}");
    }
    assert!((r.residual - relative_residual(&a, &[1.0, -1.0], &x)).abs() < 1e-9);
    // A zero right-hand side gives x = 0 at once.
    let mut x = vec![0.0; g.rhs.len()];
    let r = cg(&g.matrix, &vec![0.0; g.rhs.len()], &mut x, &tight()).unwrap();
    assert_eq!(
        (r.stop, r.iterations, r.residual),
        (Stop::Converged, 0, 0.0)
    );
}

#[test]
fn the_monitor_can_stop_a_solve() {
    let g = grid_problem(10);
    let mut x = vec![0.0; g.rhs.len()];
    let mut seen = Vec::new();
    let r = multires::cg_monitored(&g.matrix, &g.rhs, &mut x, &tight(), &mut |k, _| {
        seen.push(k);
        if k == 5 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    })
    .unwrap();
    assert_eq!((r.stop, r.iterations), (Stop::Interrupted, 5));
    assert_eq!(seen, vec![1, 2, 3, 4, 5]);
}

#[test]
fn the_cascade_and_the_v_cycle_solve_to_the_reported_residual() {
    let g = grid::diffusion([20, 18, 16], 8.0).unwrap();
    let w = Weights::Positions(&g.positions);
    let mut reference = vec![0.0; g.rhs.len()];
    let _ = cg(&g.matrix, &g.rhs, &mut reference, &tight()).unwrap();
    let options = SolveOptions::new(1e-8, 2_000);
    for system in [CoarseSystem::Substituted, CoarseSystem::Galerkin] {
        let o = CascadeOptions {
            system,
            hierarchy: HierarchyOptions {
                coarsest: 200,
                ..CascadeOptions::default().hierarchy
            },
            ..CascadeOptions::default()
        };
        let cascade = Cascade::new(&g.matrix, w, &o).unwrap();
        assert!(
            cascade.hierarchy().levels() >= 3,
            "{:?}",
            cascade.hierarchy().sizes()
        );
        let mut x = vec![0.0; g.rhs.len()];
        let report = cascade.solve(&g.matrix, &g.rhs, &mut x, &options).unwrap();
        assert!(report.finest.converged(), "{system:?}: {report:?}");
        assert!(report.fallbacks.is_empty());
        let r = relative_residual(&g.matrix, &g.rhs, &x);
        assert!((report.finest.residual - r).abs() <= 1e-3 * r + 1e-15 && r <= 1e-8);
        assert!(max_error(&x, &reference) < 1e-6);
    }
    let v = VCycle::new(&g.matrix, w, &VCycleOptions::default()).unwrap();
    let mut x = vec![0.0; g.rhs.len()];
    let report = v.solve(&g.rhs, &mut x, &options).unwrap();
    assert!(report.converged());
    let r = relative_residual(&g.matrix, &g.rhs, &x);
    assert!((report.residual - r).abs() <= 1e-3 * r + 1e-15 && r <= 1e-8);
    assert!(max_error(&x, &reference) < 1e-6);
    // Multigrid preconditioning needs far fewer iterations than Jacobi.
    let mut y = vec![0.0; g.rhs.len()];
    let jacobi = cg(&g.matrix, &g.rhs, &mut y, &options).unwrap();
    assert!(
        report.iterations * 4 < jacobi.iterations,
        "{} vs {}",
        report.iterations,
        jacobi.iterations
    );
    assert!(v.operator_complexity() > 1.0 && v.operator_complexity() < 3.0);
}

#[test]
fn the_v_cycle_is_a_symmetric_positive_definite_preconditioner() {
    use multires::prelude::*;
    let g = grid::diffusion([16, 15, 14], 7.0).unwrap();
    let v = VCycle::new(
        &g.matrix,
        Weights::Positions(&g.positions),
        &VCycleOptions::default(),
    )
    .unwrap();
    assert!(v.hierarchy().levels() >= 3);
    let mut rng = Rng(9);
    let n = g.rhs.len();
    let (r1, r2): (Vec<f64>, Vec<f64>) = (0..n).map(|_| (rng.f64() - 0.5, rng.f64() - 0.5)).unzip();
    let (mut z1, mut z2) = (vec![0.0; n], vec![0.0; n]);
    v.apply(&r1, &mut z1);
    v.apply(&r2, &mut z2);
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    // ⟨V r1, r2⟩ = ⟨r1, V r2⟩, and ⟨V r, r⟩ > 0: CG's requirements.
    let (a, b) = (dot(&z1, &r2), dot(&r1, &z2));
    assert!((a - b).abs() <= 1e-12 * a.abs().max(b.abs()), "{a} vs {b}");
    assert!(dot(&z1, &r1) > 0.0 && dot(&z2, &r2) > 0.0);
    // Applying twice gives the same result (the scratch vectors are reused).
    let mut again = vec![0.0; n];
    v.apply(&r1, &mut again);
    assert_eq!(again, z1);
}

#[test]
fn galerkin_and_linear_precision_give_an_accurate_start() {
    // The paper's Eq. 17 systems keep each kept vertex's own absorption and
    // source while it stands for several: on an absorbing medium their
    // solution is off. Galerkin systems with linear-precision interpolation
    // are consistent: the interpolated start is already close.
    let g = grid::diffusion([24, 24, 24], 6.0).unwrap();
    let mut reference = vec![0.0; g.rhs.len()];
    let _ = cg(&g.matrix, &g.rhs, &mut reference, &tight()).unwrap();
    let start_error = |o: &CascadeOptions| {
        let c = Cascade::new(&g.matrix, Weights::Positions(&g.positions), o).unwrap();
        let mut x = vec![0.0; g.rhs.len()];
        let mut first = None;
        let _ = c
            .solve_monitored(&g.matrix, &g.rhs, &mut x, &tight(), &mut |_, x| {
                first = Some(
                    x.iter()
                        .zip(&reference)
                        .map(|(a, b)| (a - b).powi(2))
                        .sum::<f64>()
                        .sqrt(),
                );
                std::ops::ControlFlow::Break(())
            })
            .unwrap();
        first.unwrap() / reference.iter().map(|v| v * v).sum::<f64>().sqrt()
    };
    let small = HierarchyOptions {
        coarsest: 500,
        ..CascadeOptions::default().hierarchy
    };
    let paper = start_error(&CascadeOptions {
        hierarchy: small,
        ..CascadeOptions::default()
    });
    let consistent = start_error(&CascadeOptions {
        system: CoarseSystem::Galerkin,
        hierarchy: HierarchyOptions {
            linear_precision: true,
            max_levels: 3,
            ..small
        },
        coarsest: SolveOptions::new(1e-8, 2_000),
        ..CascadeOptions::default()
    });
    assert!(consistent < 5e-3, "Galerkin start error {consistent}");
    let preset = start_error(&CascadeOptions {
        hierarchy: HierarchyOptions {
            coarsest: 500,
            ..CascadeOptions::galerkin().hierarchy
        },
        ..CascadeOptions::galerkin()
    });
    assert!(
        preset < 5e-2 && preset < paper / 5.0,
        "CascadeOptions::galerkin() start error {preset} (paper {paper})"
    );
    assert!(paper < 1.0, "the paper's cascade did not start");
    assert!(
        paper > 10.0 * consistent,
        "paper {paper} vs Galerkin {consistent}"
    );
}

#[test]
fn a_coarse_level_that_does_not_converge_falls_back_to_the_finer_one() {
    let g = grid::diffusion([14, 14, 14], 5.0).unwrap();
    let mut o = CascadeOptions {
        hierarchy: HierarchyOptions {
            coarsest: 100,
            ..CascadeOptions::default().hierarchy
        },
        ..CascadeOptions::default()
    };
    o.coarsest.max_iterations = 1;
    let cascade = Cascade::new(&g.matrix, Weights::Positions(&g.positions), &o).unwrap();
    let levels = cascade.hierarchy().levels();
    let mut x = vec![0.0; g.rhs.len()];
    let report = cascade.solve(&g.matrix, &g.rhs, &mut x, &tight()).unwrap();
    // Every coarse level failed, coarsest first; CG still solves level 0.
    let failed: Vec<usize> = report.fallbacks.iter().map(|f| f.0).collect();
    assert_eq!(failed, (1..levels).rev().collect::<Vec<_>>());
    assert_eq!(report.start_level, 0);
    assert!(report.finest.converged());
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let g = grid::diffusion([30, 30, 30], 10.0).unwrap();
    let w = Weights::Positions(&g.positions);
    let options = SolveOptions::new(1e-9, 1_000);
    let run = || {
        let mut a = vec![0.0; g.rhs.len()];
        let _ = cg(&g.matrix, &g.rhs, &mut a, &options).unwrap();
        let mut b = vec![0.0; g.rhs.len()];
        let _ = bicgstab(&g.matrix, &g.rhs, &mut b, &options).unwrap();
        let cascade = Cascade::new(&g.matrix, w, &CascadeOptions::default()).unwrap();
        let mut c = vec![0.0; g.rhs.len()];
        let _ = cascade.solve(&g.matrix, &g.rhs, &mut c, &options).unwrap();
        let v = VCycle::new(&g.matrix, w, &VCycleOptions::default()).unwrap();
        let mut d = vec![0.0; g.rhs.len()];
        let _ = v.solve(&g.rhs, &mut d, &options).unwrap();
        let coarse = coarse::galerkin(&g.matrix, &cascade.hierarchy().steps[0]);
        (a, b, c, d, coarse)
    };
    assert_eq!(one_thread(run), two_threads(run));
}

#[test]
fn bad_input_is_an_error() {
    let g = grid_problem(4);
    let n = g.rhs.len();
    let mut x = vec![0.0; n];
    let o = tight();
    assert_eq!(
        cg(&g.matrix, &g.rhs[1..], &mut x, &o).unwrap_err(),
        Error::DimensionMismatch {
            what: "right-hand side",
            expected: n,
            found: n - 1
        }
    );
    let mut short = vec![0.0; n + 2];
    assert!(matches!(
        bicgstab(&g.matrix, &g.rhs, &mut short, &o),
        Err(Error::DimensionMismatch {
            what: "start vector",
            ..
        })
    ));
    let mut nan_b = g.rhs.clone();
    nan_b[3] = f64::NAN;
    assert!(matches!(
        cg(&g.matrix, &nan_b, &mut x, &o),
        Err(Error::NotFiniteVector { index: 3, .. })
    ));
    let mut bad = g.matrix.clone();
    bad.data_mut()[10] = f64::INFINITY;
    let e = cg(&bad, &g.rhs, &mut x, &o).unwrap_err();
    assert!(matches!(e, Error::NotFiniteEntry { .. }), "{e}");
    assert!(e.to_string().contains("inf"));
    // A zero diagonal entry (row 2) for Jacobi.
    let mut t = TriMat::new((3, 3));
    for (i, j, v) in [(0, 0, 2.0), (1, 1, 2.0), (2, 1, 1.0), (1, 2, 1.0)] {
        t.add_triplet(i, j, v);
    }
    let zero: CsMat<f64> = t.to_csr();
    let mut x3 = vec![0.0; 3];
    assert!(matches!(
        cg(&zero, &[1.0, 1.0, 1.0], &mut x3, &o),
        Err(Error::BadDiagonal { row: 2, .. })
    ));
    assert!(matches!(
        bicgstab(&zero, &[1.0, 1.0, 1.0], &mut x3, &o),
        Err(Error::BadDiagonal { row: 2, .. })
    ));
    assert!(matches!(
        Jacobi::new(&zero),
        Err(Error::BadDiagonal { row: 2, .. })
    ));
    let rect: CsMat<f64> = TriMat::<f64>::new((2, 3)).to_csr();
    assert_eq!(
        cg(&rect, &[1.0, 1.0], &mut [0.0, 0.0], &o).unwrap_err(),
        Error::NotSquare { rows: 2, cols: 3 }
    );
    let csc = g.matrix.to_other_storage();
    assert_eq!(cg(&csc, &g.rhs, &mut x, &o).unwrap_err(), Error::NotCsr);
    let jacobi = Jacobi::new(&g.matrix).unwrap();
    let nan_tolerance = SolveOptions {
        tolerance: f64::NAN,
        ..o
    };
    assert!(matches!(
        pcg(&g.matrix, &g.rhs, &mut x, &jacobi, &nan_tolerance),
        Err(Error::InvalidOption(_))
    ));
    let cascade = Cascade::new(&g.matrix, Weights::Uniform, &CascadeOptions::default()).unwrap();
    let other = grid_problem(3);
    assert!(matches!(
        cascade.solve(
            &other.matrix,
            &other.rhs,
            &mut vec![0.0; other.rhs.len()],
            &o
        ),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        grid::diffusion([0, 3, 3], 2.0),
        Err(Error::InvalidOption(_))
    ));
    assert!(matches!(
        grid::diffusion([3, 3, 3], f64::NAN),
        Err(Error::InvalidOption(_))
    ));
    let damped = VCycleOptions {
        damping: 0.0,
        ..VCycleOptions::default()
    };
    assert!(matches!(
        VCycle::new(&g.matrix, Weights::Uniform, &damped),
        Err(Error::InvalidOption(_))
    ));
}

#[test]
fn an_owned_v_cycle_kept_across_a_change_of_values_still_preconditions() {
    let g = grid::diffusion([16, 16, 16], 6.0).unwrap();
    let w = Weights::Positions(&g.positions);
    let v = VCycle::new(&g.matrix, w, &VCycleOptions::default())
        .unwrap()
        .into_owned();
    assert_eq!(v.rows(), g.rhs.len());
    // The same pattern, values changed as painting a stronger absorber
    // into a third of the grid does: the diagonal grows there.
    let mut changed = g.matrix.clone();
    let n = changed.rows();
    for (i, mut row) in changed.outer_iterator_mut().enumerate() {
        if i < n / 3 {
            for (j, value) in row.iter_mut() {
                if i == j {
                    *value *= 1.5;
                }
            }
        }
    }
    let options = SolveOptions::new(1e-8, 2_000);
    let mut reference = vec![0.0; n];
    let _ = cg(&changed, &g.rhs, &mut reference, &tight()).unwrap();
    let mut x = vec![0.0; n];
    let stale = pcg(&changed, &g.rhs, &mut x, &v, &options).unwrap();
    assert!(stale.converged());
    assert!(max_error(&x, &reference) < 1e-6);
    // Fewer iterations than Jacobi; a fresh V-cycle of the changed matrix
    // needs fewer still (43 vs 14 vs 96 here: the change is drastic, a
    // diagonal 1.5× larger on a third of the rows).
    let fresh = VCycle::new(&changed, w, &VCycleOptions::default()).unwrap();
    let mut y = vec![0.0; n];
    let rebuilt = fresh.solve(&g.rhs, &mut y, &options).unwrap();
    let mut z = vec![0.0; n];
    let jacobi = cg(&changed, &g.rhs, &mut z, &options).unwrap();
    assert!(
        stale.iterations * 2 < jacobi.iterations && rebuilt.iterations <= stale.iterations,
        "kept {} rebuilt {} jacobi {}",
        stale.iterations,
        rebuilt.iterations,
        jacobi.iterations
    );
}

#[test]
fn a_refreshed_v_cycle_recovers_the_fresh_convergence_on_changed_values() {
    let g = grid::diffusion([16, 16, 16], 6.0).unwrap();
    let w = Weights::Positions(&g.positions);
    let kept = VCycle::new(&g.matrix, w, &VCycleOptions::default())
        .unwrap()
        .into_owned();
    // Refreshed for the matrix it was built from: the same operators, so
    // the same iterates bit for bit; no drift.
    let same = kept.refreshed(&g.matrix).unwrap();
    let options = SolveOptions::new(1e-8, 2_000);
    let n = g.rhs.len();
    let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
    let ra = kept.solve(&g.rhs, &mut a, &options).unwrap();
    let rb = same.solve(&g.rhs, &mut b, &options).unwrap();
    assert_eq!(ra, rb);
    assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert_eq!(kept.diagonal_drift(&g.matrix), 0.0);
    assert!(kept.memory_bytes() > g.matrix.nnz() * 12);
    // A third of the diagonal 1.5× larger: drift 1/3 · 0.5.
    let mut changed = g.matrix.clone();
    for (i, mut row) in changed.outer_iterator_mut().enumerate() {
        if i < n / 3 {
            for (j, value) in row.iter_mut() {
                if i == j {
                    *value *= 1.5;
                }
            }
        }
    }
    let drift = kept.diagonal_drift(&changed);
    assert!(
        (drift - (n / 3) as f64 * 0.5 / n as f64).abs() < 1e-12,
        "{drift}"
    );
    let refreshed = kept.refreshed(&changed).unwrap();
    let fresh = VCycle::new(&changed, w, &VCycleOptions::default()).unwrap();
    let mut x = vec![0.0; n];
    let stale = pcg(&changed, &g.rhs, &mut x, &kept, &options).unwrap();
    let mut y = vec![0.0; n];
    let r = refreshed.solve(&g.rhs, &mut y, &options).unwrap();
    let mut z = vec![0.0; n];
    let f = fresh.solve(&g.rhs, &mut z, &options).unwrap();
    assert!(
        r.iterations < stale.iterations && r.iterations <= f.iterations + 2,
        "refreshed {} kept {} fresh {}",
        r.iterations,
        stale.iterations,
        f.iterations
    );
    assert!(max_error(&y, &z) < 1e-6);
    // Another size is refused.
    let small = grid::diffusion([4, 4, 4], 6.0).unwrap();
    assert!(matches!(
        kept.refreshed(&small.matrix),
        Err(Error::DimensionMismatch { .. })
    ));
    assert_eq!(kept.diagonal_drift(&small.matrix), 1.0);
}
