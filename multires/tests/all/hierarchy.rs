//! The hierarchy of TransCut Sec. 4.1 and the coarse systems of Sec. 4.2.

use crate::common;

use common::*;
use multires::coarse::{galerkin, restrict_by_selection, selection, substituted};
use multires::{Error, Graph, Hierarchy, HierarchyOptions, Weights};
use sprs::{CsMat, TriMat};

fn options(enhance: bool) -> HierarchyOptions {
    HierarchyOptions {
        coarsest: 50,
        max_levels: 6,
        enhance,
        ..HierarchyOptions::default()
    }
}

/// The systems the properties are checked on: a bipartite 3D grid and a
/// random geometric graph (which has triangles, like a tet mesh).
/// A named matrix with the positions of its unknowns.
type System = (&'static str, CsMat<f64>, Vec<[f64; 3]>);

fn systems() -> Vec<System> {
    let g = grid_problem(9);
    let (m, p) = random_geometric(1_500, 0.16, 0.05, 7);
    vec![("grid", g.matrix, g.positions), ("random", m, p)]
}

fn kept_flags(n: usize, kept: &[u32]) -> Vec<bool> {
    let mut flags = vec![false; n];
    for &k in kept {
        flags[k as usize] = true;
    }
    flags
}

#[test]
fn the_selection_is_an_independent_set_and_covers_every_dropped_vertex() {
    for (name, m, p) in systems() {
        let h = Hierarchy::new(&m, Weights::Positions(&p), &options(false)).unwrap();
        assert!(h.levels() >= 3, "{name}: {:?}", h.sizes());
        for (l, step) in h.steps.iter().enumerate() {
            let g = &h.graphs[l];
            let kept = kept_flags(g.len(), &step.kept);
            assert_eq!(step.independent, step.kept.len());
            for i in 0..g.len() {
                if kept[i] {
                    // Independent: no kept neighbour.
                    assert!(
                        g.neighbors(i).iter().all(|&j| !kept[j as usize]),
                        "{name} level {l}: kept {i} has a kept neighbour"
                    );
                } else {
                    // Maximal: a kept neighbour to interpolate from.
                    assert!(
                        g.neighbors(i).iter().any(|&j| kept[j as usize]),
                        "{name} level {l}: dropped {i} has no kept neighbour"
                    );
                }
            }
        }
    }
}

/// Pairs of kept vertices joined at level `l` by a path kept–dropped–
/// dropped–kept (Fig. 3's `i1`, `i3`) and by no shorter path.
fn three_ring_pairs(g: &Graph, kept: &[bool]) -> Vec<(usize, usize)> {
    let mut pairs = Vec::new();
    for a in (0..g.len()).filter(|&a| kept[a]) {
        for &j in g.neighbors(a) {
            if kept[j as usize] {
                continue;
            }
            for &k in g.neighbors(j as usize) {
                if kept[k as usize] || k == j {
                    continue;
                }
                for &b in g.neighbors(k as usize) {
                    let b = b as usize;
                    let two_apart = g.neighbors(a).iter().any(|&x| g.adjacent(x as usize, b));
                    if b != a && kept[b] && !g.adjacent(a, b) && !two_apart {
                        pairs.push((a, b));
                    }
                }
            }
        }
    }
    pairs
}

/// Whether `a` and `b` (level-`l` indices, both kept) are within two
/// edges of each other at level `l + 1`: directly, or through the kept
/// vertex the enhancement put between them.
fn connected_at_next(next: &Graph, coarse: &[u32], a: usize, b: usize) -> bool {
    let (ca, cb) = (coarse[a] as usize, coarse[b] as usize);
    next.adjacent(ca, cb)
        || next
            .neighbors(ca)
            .iter()
            .any(|&x| next.adjacent(x as usize, cb))
}

#[test]
fn enhancement_keeps_three_ring_neighbours_connected() {
    for (name, m, p) in systems() {
        let mut lost_without = 0;
        for enhance in [true, false] {
            let h = Hierarchy::new(&m, Weights::Positions(&p), &options(enhance)).unwrap();
            for (l, step) in h.steps.iter().enumerate() {
                let g = &h.graphs[l];
                let kept = kept_flags(g.len(), &step.kept);
                let mut coarse = vec![u32::MAX; g.len()];
                for (c, &k) in step.kept.iter().enumerate() {
                    coarse[k as usize] = c as u32;
                }
                if enhance {
                    // Every dropped–dropped edge has a kept common neighbour…
                    for i in (0..g.len()).filter(|&i| !kept[i]) {
                        for &j in g.neighbors(i) {
                            let j = j as usize;
                            if !kept[j] {
                                assert!(
                                    g.neighbors(i)
                                        .iter()
                                        .any(|&k| kept[k as usize] && g.adjacent(k as usize, j)),
                                    "{name} level {l}: edge ({i}, {j}) not represented"
                                );
                            }
                        }
                    }
                    assert!(step.kept.len() >= step.independent);
                }
                // …so Fig. 3's pairs stay connected at the next level.
                for (a, b) in three_ring_pairs(g, &kept) {
                    let ok = connected_at_next(&h.graphs[l + 1], &coarse, a, b);
                    if enhance {
                        assert!(ok, "{name} level {l}: {a} and {b} lost their connection");
                    } else if !ok {
                        lost_without += 1;
                    }
                }
            }
        }
        // The test can fail: without the enhancement, connections are lost.
        assert!(
            lost_without > 0,
            "{name}: no connection lost without enhancement"
        );
    }
}

#[test]
fn interpolation_follows_eq_16() {
    let (m, p) = random_geometric(800, 0.2, 0.05, 3);
    let h = Hierarchy::new(&m, Weights::Positions(&p), &options(true)).unwrap();
    let step = &h.steps[0];
    let g = &h.graphs[0];
    let kept = kept_flags(g.len(), &step.kept);
    for (i, row) in step.interpolation.outer_iterator().enumerate() {
        let entries: Vec<(usize, f64)> = row.iter().map(|(c, &v)| (c, v)).collect();
        if kept[i] {
            let c = step.kept.iter().position(|&k| k as usize == i).unwrap();
            assert_eq!(entries, vec![(c, 1.0)]);
            continue;
        }
        // λ_ij = 1/|x_i − x_j| over the kept 1-ring, divided by their sum.
        let kept_nb: Vec<usize> = g
            .neighbors(i)
            .iter()
            .map(|&j| j as usize)
            .filter(|&j| kept[j])
            .collect();
        let total: f64 = kept_nb.iter().map(|&j| 1.0 / dist(p[i], p[j])).sum();
        assert_eq!(entries.len(), kept_nb.len());
        for (&(c, v), &j) in entries.iter().zip(&kept_nb) {
            assert_eq!(step.kept[c] as usize, j);
            assert!((v - (1.0 / dist(p[i], p[j])) / total).abs() < 1e-14);
        }
    }
}

#[test]
fn linear_precision_reproduces_linear_functions() {
    let (m, p) = random_geometric(1_200, 0.2, 0.05, 5);
    for precise in [false, true] {
        let o = HierarchyOptions {
            linear_precision: precise,
            ..options(true)
        };
        let h = Hierarchy::new(&m, Weights::Positions(&p), &o).unwrap();
        let step = &h.steps[0];
        let coarse_x: Vec<f64> = step.kept.iter().map(|&k| p[k as usize][0]).collect();
        let fine_x = apply(&step.interpolation, &coarse_x);
        // Rows whose kept neighbours surround the vertex in 3D.
        let worst = (0..p.len())
            .filter(|&i| step.interpolation.outer_view(i).unwrap().nnz() >= 6)
            .map(|i| (fine_x[i] - p[i][0]).abs())
            .fold(0.0f64, f64::max);
        if precise {
            assert!(worst < 1e-9, "linear precision error {worst}");
        } else {
            assert!(
                worst > 1e-3,
                "inverse-distance weights are not linear-exact: {worst}"
            );
        }
    }
    assert_eq!(
        Hierarchy::new(
            &m,
            Weights::Uniform,
            &HierarchyOptions {
                linear_precision: true,
                ..options(true)
            }
        )
        .unwrap_err(),
        Error::InvalidOption("linear_precision needs Weights::Positions or Weights::Points")
    );
}

#[test]
fn coarse_systems_equal_the_sparse_products() {
    for (name, m, p) in systems() {
        let h = Hierarchy::new(&m, Weights::Positions(&p), &options(true)).unwrap();
        let mut level = m.clone();
        for step in &h.steps {
            let s = selection(step, level.rows());
            let pm = &step.interpolation;
            // sprs's own products, independent of ours.
            let smp: CsMat<f64> = &(&s * &level) * pm;
            let eq17 = substituted(&level, step);
            assert!(
                max_difference(&eq17, &smp) < 1e-13,
                "{name}: Eq. 17 ≠ S M P"
            );
            let pt: CsMat<f64> = pm.transpose_view().to_csr();
            let ptmp: CsMat<f64> = &(&pt * &level) * pm;
            assert!(
                max_difference(&galerkin(&level, step), &ptmp) < 1e-13,
                "{name}: Galerkin ≠ Pᵀ M P"
            );
            let b: Vec<f64> = (0..level.rows()).map(|i| i as f64).collect();
            assert_eq!(restrict_by_selection(&b, step), apply(&s, &b));
            // Eq. 17's pattern is the coarse edge set.
            let g = &h.graphs[h.steps.iter().position(|x| std::ptr::eq(x, step)).unwrap() + 1];
            for (r, row) in eq17.outer_iterator().enumerate() {
                for (c, _) in row.iter() {
                    assert!(
                        c == r || g.adjacent(r, c),
                        "{name}: entry ({r}, {c}) off the coarse graph"
                    );
                }
            }
            level = eq17;
        }
    }
}

#[test]
fn eq_17_by_hand_on_a_path() {
    // 0 — 1 — 2 with 1 dropped, interpolated from 0 and 2 with weights
    // 1/1 and 1/2 (positions 0, 1, 3): λ_10/λ_1 = 2/3, λ_12/λ_1 = 1/3.
    let mut t = TriMat::new((3, 3));
    for (i, j, v) in [
        (0, 0, 4.0),
        (0, 1, -1.0),
        (1, 0, -2.0),
        (1, 1, 5.0),
        (1, 2, -2.0),
        (2, 1, -1.5),
        (2, 2, 3.0),
    ] {
        t.add_triplet(i, j, v);
    }
    let m: CsMat<f64> = t.to_csr();
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]];
    let o = HierarchyOptions {
        coarsest: 1,
        max_levels: 2,
        seed: 1,
        ..HierarchyOptions::default()
    };
    // Try seeds until vertex 1 is the dropped one (the codes are random).
    let (h, _) = (1..64)
        .map(|seed| {
            let h = Hierarchy::new(&m, Weights::Positions(&p), &HierarchyOptions { seed, ..o })
                .unwrap();
            (h, seed)
        })
        .find(|(h, _)| h.steps.first().is_some_and(|s| s.kept == [0, 2]))
        .expect("a seed that drops the middle vertex");
    let c = substituted(&m, &h.steps[0]).to_dense();
    // M'_00 = M_00 + M_01 λ_10/λ_1 = 4 − 2/3; M'_02 = M_01 λ_12/λ_1 = −1/3;
    // M'_20 = M_21 λ_10/λ_1 = −1; M'_22 = 3 − 1.5/3 = 2.5.
    let expected = [[4.0 - 2.0 / 3.0, -1.0 / 3.0], [-1.0, 2.5]];
    for r in 0..2 {
        for col in 0..2 {
            assert!(
                (c[[r, col]] - expected[r][col]).abs() < 1e-15,
                "({r}, {col}): {}",
                c[[r, col]]
            );
        }
    }
}

#[test]
fn the_hierarchy_does_not_depend_on_the_thread_count() {
    let (m, p) = random_geometric(2_000, 0.14, 0.05, 11);
    let build = || Hierarchy::new(&m, Weights::Positions(&p), &options(true)).unwrap();
    let (a, b) = (one_thread(build), two_threads(build));
    assert_eq!(a.sizes(), b.sizes());
    assert_eq!(a.graphs, b.graphs);
    for (x, y) in a.steps.iter().zip(&b.steps) {
        assert_eq!(x.kept, y.kept);
        assert_eq!(x.interpolation, y.interpolation);
    }
}

#[test]
fn bad_input_is_an_error() {
    let g = grid_problem(3);
    let short = &g.positions[1..];
    assert!(matches!(
        Hierarchy::new(&g.matrix, Weights::Positions(short), &options(true)),
        Err(Error::DimensionMismatch {
            what: "positions",
            ..
        })
    ));
    let mut twin = g.positions.clone();
    twin[1] = twin[0];
    let e = Hierarchy::new(
        &g.matrix,
        Weights::Positions(&twin),
        &HierarchyOptions {
            coarsest: 1,
            ..options(true)
        },
    );
    assert!(matches!(e, Err(Error::BadWeight { .. })), "{e:?}");
    let mut nan = g.positions.clone();
    nan[5][2] = f64::NAN;
    assert!(matches!(
        Hierarchy::new(&g.matrix, Weights::Positions(&nan), &options(true)),
        Err(Error::NotFiniteVector {
            what: "positions",
            index: 5,
            ..
        })
    ));
    let negative = |_: usize, _: usize| -1.0;
    assert!(matches!(
        Hierarchy::new(
            &g.matrix,
            Weights::Custom(&negative),
            &HierarchyOptions {
                coarsest: 1,
                ..options(true)
            }
        ),
        Err(Error::BadWeight { value: -1.0, .. })
    ));
    let rect: CsMat<f64> = TriMat::<f64>::new((3, 4)).to_csr();
    assert_eq!(
        Hierarchy::new(&rect, Weights::Uniform, &options(true)).unwrap_err(),
        Error::NotSquare { rows: 3, cols: 4 }
    );
}
