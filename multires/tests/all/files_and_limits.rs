//! Matrix Market files (round trips over random matrices and vectors, and
//! bad files that must be refused with the file and line), positions read
//! in place, and no panic on extreme arguments.

use crate::common;

use std::path::PathBuf;

use common::*;
use multires::{
    Cascade, CascadeOptions, Error, Hierarchy, HierarchyOptions, SolveOptions, VCycle,
    VCycleOptions, Weights, bicgstab, cg, grid, mtx,
};
use sprs::{CsMat, TriMat};

/// A fresh temporary folder for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("multires-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A value with any exponent, sign and mantissa (never NaN or ∞).
fn any_value(rng: &mut Rng) -> f64 {
    let v = f64::from_bits(rng.next_u64());
    if v.is_finite() { v } else { rng.f64() - 0.5 }
}

#[test]
fn matrices_and_vectors_round_trip_through_matrix_market_files() {
    let dir = temp_dir("round-trip");
    let mut rng = Rng(41);
    for case in 0..60 {
        let rows = 1 + (rng.next_u64() % 40) as usize;
        let cols = 1 + (rng.next_u64() % 40) as usize;
        let nnz = (rng.next_u64() % (rows * cols + 1) as u64) as usize;
        let mut t = TriMat::new((rows, cols));
        for _ in 0..nnz {
            let (i, j) = (
                (rng.next_u64() as usize) % rows,
                (rng.next_u64() as usize) % cols,
            );
            t.add_triplet(i, j, any_value(&mut rng));
        }
        let a: CsMat<f64> = t.to_csr();
        let path = dir.join(format!("m{case}.mtx"));
        mtx::write_matrix(&path, &a).unwrap();
        let back = mtx::read_matrix(&path).unwrap();
        assert_eq!(back.shape(), a.shape(), "case {case}");
        assert_eq!(back.indptr().raw_storage(), a.indptr().raw_storage());
        assert_eq!(back.indices(), a.indices());
        let bits = |m: &CsMat<f64>| m.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(
            bits(&back),
            bits(&a),
            "case {case}: values are kept bit for bit"
        );

        let v: Vec<f64> = (0..rows).map(|_| any_value(&mut rng)).collect();
        let vpath = dir.join(format!("v{case}.mtx"));
        mtx::write_vector(&vpath, &v).unwrap();
        let w = mtx::read_vector(&vpath).unwrap();
        assert_eq!(
            w.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn symmetric_storage_pattern_and_comments_are_read() {
    let dir = temp_dir("variants");
    let path = dir.join("sym.mtx");
    std::fs::write(
        &path,
        "%%MatrixMarket matrix coordinate real symmetric\n% a comment\n\n3 3 4\n1 1 4\n2 1 -1\n2 2 4\n3 3 2.5\n",
    )
    .unwrap();
    let a = mtx::read_matrix(&path).unwrap();
    let dense = |m: &CsMat<f64>| {
        let mut d = vec![[0.0; 3]; 3];
        for (v, (i, j)) in m.iter() {
            d[i][j] += v;
        }
        d
    };
    assert_eq!(
        dense(&a),
        [[4.0, -1.0, 0.0], [-1.0, 4.0, 0.0], [0.0, 0.0, 2.5]]
    );
    std::fs::write(
        &path,
        "%%MatrixMarket matrix coordinate pattern skew-symmetric\n2 2 1\n2 1\n",
    )
    .unwrap();
    assert_eq!(dense(&mtx::read_matrix(&path).unwrap())[0][1], -1.0);
    std::fs::write(
        &path,
        "%%MatrixMarket matrix coordinate real general\n1 4 2\n1 2 3.5\n1 4 -1\n",
    )
    .unwrap();
    assert_eq!(mtx::read_vector(&path).unwrap(), vec![0.0, 3.5, 0.0, -1.0]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_name_the_file_the_line_and_the_problem() {
    let dir = temp_dir("bad");
    let path = dir.join("bad.mtx");
    let cases: [(&str, usize, &str); 9] = [
        ("hello\n1 1 1\n", 1, "banner"),
        (
            "%%MatrixMarket matrix coordinate complex general\n1 1 1\n1 1 1 0\n",
            1,
            "complex",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n3 1 1.0\n",
            3,
            "row index",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 0 1.0\n",
            3,
            "column index",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 2\n1 1 1.0\n",
            0,
            "announces 2",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 nan\n",
            3,
            "NaN",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 1\n1 1 1\n2 2 1\n",
            4,
            "after",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n99999999999 1 1\n1 1 1\n",
            2,
            "99999999999 rows",
        ),
        (
            "%%MatrixMarket matrix coordinate real general\n2 2 18446744073709551615\n1 1 1\n",
            0,
            "announces",
        ),
    ];
    for (text, line, needle) in cases {
        std::fs::write(&path, text).unwrap();
        let e = mtx::read_matrix(&path).unwrap_err();
        match &e {
            Error::MatrixMarket { line: l, .. } => assert_eq!(*l, line, "{e}"),
            other => panic!("{other:?}"),
        }
        let message = e.to_string();
        assert!(message.contains("bad.mtx"), "{message}");
        assert!(
            message.contains(needle),
            "{message:?} should mention {needle:?}"
        );
    }
    let e = mtx::read_matrix(dir.join("missing.mtx")).unwrap_err();
    assert!(e.to_string().contains("missing.mtx"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn glam_positions_are_read_in_place_with_the_same_result() {
    let (a, points) = random_geometric(600, 0.2, 0.5, 9);
    let dvec: Vec<glam::DVec3> = points.iter().map(|&p| glam::DVec3::from_array(p)).collect();
    let options = HierarchyOptions {
        linear_precision: true,
        coarsest: 50,
        ..HierarchyOptions::default()
    };
    let arrays = Hierarchy::new(&a, Weights::Positions(&points), &options).unwrap();
    let glam = Hierarchy::new(&a, Weights::Points(&dvec), &options).unwrap();
    assert_eq!(arrays.sizes(), glam.sizes());
    for (x, y) in arrays.steps.iter().zip(&glam.steps) {
        assert_eq!(x.kept, y.kept);
        assert_eq!(x.interpolation, y.interpolation);
    }
    let slice: &[glam::DVec3] = &dvec[..10];
    let e = Hierarchy::new(&a, Weights::Points(&slice), &options).unwrap_err();
    assert!(
        matches!(e, Error::DimensionMismatch { found: 10, .. }),
        "{e}"
    );
    let mut bad = dvec.clone();
    bad[7].y = f64::NAN;
    let e = Hierarchy::new(&a, Weights::Points(&bad), &options).unwrap_err();
    assert!(matches!(e, Error::NotFiniteVector { index: 7, .. }), "{e}");
}

#[test]
fn the_cascade_reports_non_convergence_as_an_error_with_its_report() {
    let g = grid::diffusion([12, 12, 12], 6.0).unwrap();
    let cascade = Cascade::new(
        &g.matrix,
        Weights::Positions(&g.positions),
        &CascadeOptions::default(),
    )
    .unwrap();
    let mut x = vec![0.0; g.rhs.len()];
    let capped = SolveOptions::new(1e-12, 2);
    match cascade.solve(&g.matrix, &g.rhs, &mut x, &capped) {
        Err(Error::CascadeNotConverged { report, tolerance }) => {
            assert_eq!(tolerance, 1e-12);
            assert_eq!(report.finest.iterations, 2);
            assert!(!report.finest.converged());
            let r = relative_residual(&g.matrix, &g.rhs, &x);
            assert!((report.finest.residual - r).abs() <= 1e-12 * r.max(1.0));
        }
        other => panic!("expected CascadeNotConverged, got {other:?}"),
    }
    let mut y = vec![0.0; g.rhs.len()];
    let report = cascade
        .solve(&g.matrix, &g.rhs, &mut y, &capped.allow_unconverged())
        .unwrap();
    assert_eq!(report.finest.iterations, 2);
    let v = VCycle::new(&g.matrix, Weights::Uniform, &VCycleOptions::default()).unwrap();
    let e = v
        .solve(&g.rhs, &mut y, &SolveOptions::new(1e-14, 1))
        .unwrap_err();
    assert!(
        e.to_string().starts_with("the solve did not converge"),
        "{e}"
    );
}

/// Values a caller might pass by mistake.
const EXTREMES: [f64; 10] = [
    0.0,
    -0.0,
    5e-324,
    1e-300,
    1.0,
    -1.0,
    1e300,
    f64::MAX,
    f64::INFINITY,
    f64::NAN,
];

#[test]
fn extreme_arguments_give_errors_or_answers_never_panics() {
    let mut rng = Rng(7);
    let pick = |rng: &mut Rng| EXTREMES[(rng.next_u64() % EXTREMES.len() as u64) as usize];
    for round in 0..300 {
        let n = [0usize, 1, 2, 5][round % 4];
        let mut t = TriMat::new((n, n));
        for i in 0..n {
            t.add_triplet(i, i, pick(&mut rng));
            if i > 0 {
                let v = pick(&mut rng);
                t.add_triplet(i, i - 1, v);
                t.add_triplet(i - 1, i, if round % 3 == 0 { pick(&mut rng) } else { v });
            }
        }
        let a: CsMat<f64> = t.to_csr();
        let b: Vec<f64> = (0..n).map(|_| pick(&mut rng)).collect();
        let options = SolveOptions {
            tolerance: pick(&mut rng),
            max_iterations: [0, 1, 3, usize::MAX / 2][round % 4].min(50),
            require_convergence: round % 2 == 0,
        };
        let mut x: Vec<f64> = (0..n).map(|_| pick(&mut rng)).collect();
        let _ = cg(&a, &b, &mut x, &options);
        let _ = bicgstab(&a, &b, &mut x, &options);
        let hierarchy = HierarchyOptions {
            coarsest: (rng.next_u64() % 4) as usize,
            max_levels: (rng.next_u64() % 4) as usize,
            ..HierarchyOptions::default()
        };
        let positions: Vec<[f64; 3]> = (0..n)
            .map(|_| [pick(&mut rng), pick(&mut rng), pick(&mut rng)])
            .collect();
        for w in [Weights::Uniform, Weights::Positions(&positions)] {
            let _ = Hierarchy::new(&a, w, &hierarchy);
            let vo = VCycleOptions {
                hierarchy,
                damping: pick(&mut rng),
                ..VCycleOptions::default()
            };
            if let Ok(v) = VCycle::new(&a, w, &vo) {
                let _ = v.solve(&b, &mut x, &options);
            }
            let co = CascadeOptions {
                hierarchy,
                ..CascadeOptions::default()
            };
            if let Ok(c) = Cascade::new(&a, w, &co) {
                let _ = c.solve(&a, &b, &mut x, &options);
            }
        }
        let _ = grid::diffusion([n, n, (rng.next_u64() % 3) as usize], pick(&mut rng));
    }
    // Huge grid sizes are refused, not allocated.
    assert!(grid::diffusion([1 << 20, 1 << 20, 1 << 20], 1.0).is_err());
    assert!(grid::diffusion([usize::MAX, 2, 2], 1.0).is_err());
}
