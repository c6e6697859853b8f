//! Semidefinite and broken systems (`tests/regressions/solver-singular`,
//! after pyamg#223, amgcl#31 and Krylov.jl#189): the pure-Neumann path
//! Laplacian is singular with the constants as null space. With a
//! consistent right-hand side `e_0 − e_{n−1}` the solution is fixed up to
//! a constant by the closed form `x_i − x_{i+1} = 1`, so
//! `x_0 − x_{n−1} = n − 1`; plain CG and the V-cycle-preconditioned CG
//! must both find it. An inconsistent right-hand side and a zero row must
//! be errors that leave a finite `x` no worse than the start.

use std::path::{Path, PathBuf};

use multires::mtx::{read_matrix, read_vector};
use multires::{Error, SolveOptions, VCycle, VCycleOptions, Weights, cg, pcg};

fn file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/regressions/solver-singular")
        .join(name)
}

/// `‖b − A x‖ / ‖b‖`.
fn relative_residual(a: &multires::sprs::CsMat<f64>, b: &[f64], x: &[f64]) -> f64 {
    let mut r = vec![0.0; b.len()];
    multires::matrix::mul_vec(a, x, &mut r);
    let num: f64 = r.iter().zip(b).map(|(r, b)| (b - r) * (b - r)).sum();
    let den: f64 = b.iter().map(|b| b * b).sum();
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

fn check_neumann(matrix: &str, rhs: &str, n: usize) {
    let a = read_matrix(file(matrix)).unwrap();
    let b = read_vector(file(rhs)).unwrap();
    assert_eq!(b.len(), n);
    let options = SolveOptions::new(1e-9, 20 * n);
    let closed_form = |x: &[f64]| {
        assert!(
            ((x[0] - x[n - 1]) - (n - 1) as f64).abs() < 1e-5,
            "{}",
            x[0] - x[n - 1]
        );
        for i in 0..n - 1 {
            assert!(
                (x[i] - x[i + 1] - 1.0).abs() < 1e-5,
                "{i}: {}",
                x[i] - x[i + 1]
            );
        }
    };
    let mut x = vec![0.0; n];
    let report = cg(&a, &b, &mut x, &options).unwrap();
    assert!(report.converged() && relative_residual(&a, &b, &x) < 1e-7);
    closed_form(&x);

    // The V-cycle: small enough coarsest levels for the dense solve, which
    // is singular here.
    for coarsest in [4, 50] {
        let mut vopts = VCycleOptions::default();
        vopts.hierarchy.coarsest = coarsest;
        let v = VCycle::new(&a, Weights::Uniform, &vopts).unwrap();
        let mut x = vec![0.0; n];
        let report = v.solve(&b, &mut x, &options).unwrap();
        assert!(report.converged(), "{report}");
        assert!(relative_residual(&a, &b, &x) < 1e-7);
        assert!(x.iter().all(|v| v.is_finite()));
        closed_form(&x);
        // And as a preconditioner handed to pcg.
        let mut y = vec![0.0; n];
        let report = pcg(&a, &b, &mut y, &v, &options).unwrap();
        assert!(report.converged());
        closed_form(&y);
    }
}

#[test]
fn neumann_laplacians_converge_with_and_without_the_v_cycle() {
    check_neumann("neumann32.mtx", "rhs_consistent.mtx", 32);
    check_neumann("neumann1000.mtx", "rhs1000_consistent.mtx", 1000);
}

/// All ones is not in the range: no solver can converge; the error says
/// so, and `x` is the best iterate, finite, no worse than the start.
#[test]
fn an_inconsistent_singular_system_leaves_the_best_iterate() {
    let a = read_matrix(file("neumann32.mtx")).unwrap();
    let b = read_vector(file("rhs_inconsistent.mtx")).unwrap();
    let start: Vec<f64> = (0..32).map(|i| 0.1 * i as f64).collect();
    let start_residual = relative_residual(&a, &b, &start);
    for max_iterations in [5, 40, 500] {
        let mut x = start.clone();
        let e = cg(&a, &b, &mut x, &SolveOptions::new(1e-9, max_iterations)).unwrap_err();
        let Error::NotConverged { report, .. } = e else {
            panic!("{e}");
        };
        assert!(x.iter().all(|v| v.is_finite()), "{x:?}");
        let residual = relative_residual(&a, &b, &x);
        assert!(residual <= start_residual, "{residual} > {start_residual}");
        assert!((report.residual - residual).abs() <= 1e-9 * residual.max(1.0));
        assert!(x.iter().all(|v| v.abs() < 1e6), "{x:?}");
        // The smallest residual of an inconsistent system is that of the
        // range projection: ‖b − b̄‖ / ‖b‖ with b̄ the part along the
        // constants, here b itself, so 1. No iterate can beat it.
        assert!(residual >= 1.0 - 1e-9);

        let mut vopts = VCycleOptions::default();
        vopts.hierarchy.coarsest = 4;
        let v = VCycle::new(&a, Weights::Uniform, &vopts).unwrap();
        let mut x = start.clone();
        let e = v.solve(&b, &mut x, &SolveOptions::new(1e-9, max_iterations));
        assert!(matches!(e, Err(Error::NotConverged { .. })), "{e:?}");
        assert!(x.iter().all(|v| v.is_finite()));
        assert!(relative_residual(&a, &b, &x) <= start_residual);
    }
}

/// `Q = [1 0; 0 0]`: the zero diagonal is named before iterating, and `x`
/// is untouched.
#[test]
fn a_zero_row_is_named_and_x_is_kept() {
    let a = read_matrix(file("zero_row.mtx")).unwrap();
    let b = read_vector(file("rhs_zero_row.mtx")).unwrap();
    let mut x = vec![0.5, -0.25];
    let e = cg(&a, &b, &mut x, &SolveOptions::default()).unwrap_err();
    assert!(matches!(e, Error::BadDiagonal { .. }), "{e}");
    assert!(e.to_string().contains('1'), "{e}");
    assert_eq!(x, vec![0.5, -0.25]);
    // Without the Jacobi scaling (identity preconditioner), CG breaks
    // down on it or stops short; x stays finite, no worse than the start.
    struct Identity;
    impl multires::Preconditioner for Identity {
        fn apply(&self, r: &[f64], z: &mut [f64]) {
            z.copy_from_slice(r);
        }
    }
    let start_residual = relative_residual(&a, &b, &x);
    let result = pcg(&a, &b, &mut x, &Identity, &SolveOptions::default());
    assert!(
        matches!(result, Err(Error::NotConverged { .. })),
        "{result:?}"
    );
    assert!(x.iter().all(|v| v.is_finite()));
    assert!(relative_residual(&a, &b, &x) <= start_residual);
}
