//! CSR helpers: input checks, the parallel mat-vec, the diagonal, and a
//! row-parallel assembler that the coarse operators and the sparse
//! product share.

use rayon::prelude::*;
use sprs::CsMat;

use crate::Error;

/// Rows per parallel task in mat-vecs and assembly.
const ROWS: usize = 1 << 11;

/// Checks that `a` is a square, finite CSR matrix; returns its size.
pub(crate) fn check_square(a: &CsMat<f64>) -> Result<usize, Error> {
    if !a.is_csr() {
        return Err(Error::NotCsr);
    }
    if a.rows() != a.cols() {
        return Err(Error::NotSquare {
            rows: a.rows(),
            cols: a.cols(),
        });
    }
    let indptr = a.indptr();
    let indptr = indptr.to_proper();
    let bad = (0..a.rows()).into_par_iter().find_first(|&row| {
        a.data()[indptr[row]..indptr[row + 1]]
            .iter()
            .any(|v| !v.is_finite())
    });
    if let Some(row) = bad {
        let range = indptr[row]..indptr[row + 1];
        let k = range.start
            + a.data()[range]
                .iter()
                .position(|v| !v.is_finite())
                .unwrap_or(0);
        return Err(Error::NotFiniteEntry {
            row,
            col: a.indices()[k],
            value: a.data()[k],
        });
    }
    Ok(a.rows())
}

/// Checks that a square CSR matrix is symmetric: every stored `a_ij` has
/// a stored `a_ji` equal to it up to rounding (`|a_ij − a_ji| ≤ 10⁻¹⁰ ·
/// max(|a_ij|, |a_ji|, √|a_ii a_jj|)`, room for assembly in different
/// orders). One parallel pass over the entries, a binary search each: about
/// the cost of a few mat-vecs, paid once per solve.
pub(crate) fn check_symmetric(a: &CsMat<f64>) -> Result<(), Error> {
    let indptr = a.indptr();
    let indptr = indptr.to_proper();
    let (indices, data) = (a.indices(), a.data());
    let row = |i: usize| {
        (
            &indices[indptr[i]..indptr[i + 1]],
            &data[indptr[i]..indptr[i + 1]],
        )
    };
    // Duplicates are summed, so look entries up by summing all matches.
    let entry = |i: usize, j: usize| -> f64 {
        let (cols, vals) = row(i);
        cols.iter()
            .zip(vals)
            .filter(|&(&c, _)| c == j)
            .map(|(_, v)| v)
            .sum()
    };
    let sorted = |i: usize| row(i).0.windows(2).all(|w| w[0] < w[1]);
    let lookup = |i: usize, j: usize| -> f64 {
        let (cols, vals) = row(i);
        if sorted(i) {
            cols.binary_search(&j).map_or(0.0, |k| vals[k])
        } else {
            entry(i, j)
        }
    };
    let diagonal = diagonal(a);
    let bad = (0..a.rows()).into_par_iter().find_map_first(|i| {
        let (cols, _) = row(i);
        cols.iter().find_map(|&j| {
            if j <= i {
                return None;
            }
            let (v, w) = (lookup(i, j), lookup(j, i));
            let scale = v
                .abs()
                .max(w.abs())
                .max((diagonal[i] * diagonal[j]).abs().sqrt());
            ((v - w).abs() > 1e-10 * scale).then_some((i, j, v, w))
        })
    });
    match bad {
        Some((row, col, value, transposed)) => Err(Error::NotSymmetric {
            row,
            col,
            value,
            transposed,
        }),
        None => Ok(()),
    }
}

/// Checks a vector's length and entries.
pub(crate) fn check_vector(what: &'static str, v: &[f64], n: usize) -> Result<(), Error> {
    if v.len() != n {
        return Err(Error::DimensionMismatch {
            what,
            expected: n,
            found: v.len(),
        });
    }
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(Error::NotFiniteVector {
            what,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// The diagonal of a square CSR matrix (0 where no entry is stored;
/// duplicates summed).
pub fn diagonal(a: &CsMat<f64>) -> Vec<f64> {
    let indptr = a.indptr();
    let indptr = indptr.to_proper();
    (0..a.rows())
        .into_par_iter()
        .map(|row| {
            let range = indptr[row]..indptr[row + 1];
            a.indices()[range.clone()]
                .iter()
                .zip(&a.data()[range])
                .filter(|&(&col, _)| col == row)
                .map(|(_, v)| v)
                .sum()
        })
        .collect()
}

/// `1 / diag(a)`, or the error naming the first diagonal entry that is not
/// usable (`positive`: CG's Jacobi needs it > 0, BiCGSTAB's only ≠ 0).
pub(crate) fn inverse_diagonal(a: &CsMat<f64>, positive: bool) -> Result<Vec<f64>, Error> {
    let d = diagonal(a);
    let bad = |v: f64| if positive { v <= 0.0 } else { v == 0.0 };
    if let Some(row) = d.iter().position(|&v| bad(v)) {
        return Err(Error::BadDiagonal {
            row,
            value: d[row],
            need: if positive {
                "Jacobi-preconditioned CG needs a positive diagonal"
            } else {
                "Jacobi preconditioning needs a non-zero diagonal"
            },
        });
    }
    Ok(d.into_iter().map(|v| 1.0 / v).collect())
}

/// `y ← A x`, rows in parallel (each row's sum in storage order, so the
/// result does not depend on the number of threads).
pub fn mul_vec(a: &CsMat<f64>, x: &[f64], y: &mut [f64]) {
    debug_assert!(a.is_csr());
    debug_assert_eq!(x.len(), a.cols());
    debug_assert_eq!(y.len(), a.rows());
    let indptr = a.indptr();
    let indptr = indptr.to_proper();
    let (indices, data) = (a.indices(), a.data());
    y.par_chunks_mut(ROWS).enumerate().for_each(|(c, y)| {
        let first = c * ROWS;
        for (k, y) in y.iter_mut().enumerate() {
            let range = indptr[first + k]..indptr[first + k + 1];
            let mut s = 0.0;
            for (&col, &v) in indices[range.clone()].iter().zip(&data[range]) {
                s += v * x[col];
            }
            *y = s;
        }
    });
}

/// Assembles a `rows × cols` CSR matrix whose row `i` is what `row(i, buf)`
/// pushes into `buf` as `(column, value)` pairs, duplicates summed in push
/// order, columns sorted. Rows are built in parallel chunks and stitched,
/// so the result does not depend on the number of threads.
pub(crate) fn assemble(
    rows: usize,
    cols: usize,
    row: impl Fn(usize, &mut Vec<(usize, f64)>) + Sync,
) -> CsMat<f64> {
    let chunks: Vec<(Vec<usize>, Vec<usize>, Vec<f64>)> = (0..rows.div_ceil(ROWS))
        .into_par_iter()
        .map(|c| {
            let range = c * ROWS..((c + 1) * ROWS).min(rows);
            let mut counts = Vec::with_capacity(range.len());
            let mut indices = Vec::new();
            let mut data = Vec::new();
            let mut buf = Vec::new();
            for i in range {
                buf.clear();
                row(i, &mut buf);
                // Stable: equal columns keep push order, so sums are reproducible.
                buf.sort_by_key(|&(col, _)| col);
                let before = indices.len();
                for &(col, v) in &buf {
                    if indices.len() > before && *indices.last().unwrap_or(&usize::MAX) == col {
                        *data.last_mut().unwrap_or(&mut 0.0) += v;
                    } else {
                        indices.push(col);
                        data.push(v);
                    }
                }
                counts.push(indices.len() - before);
            }
            (counts, indices, data)
        })
        .collect();
    stitch(rows, cols, chunks)
}

/// Joins per-chunk `(row lengths, columns, values)` into one CSR matrix.
fn stitch(rows: usize, cols: usize, chunks: Vec<(Vec<usize>, Vec<usize>, Vec<f64>)>) -> CsMat<f64> {
    let nnz = chunks.iter().map(|c| c.1.len()).sum();
    let mut indptr = Vec::with_capacity(rows + 1);
    let mut indices = Vec::with_capacity(nnz);
    let mut data = Vec::with_capacity(nnz);
    indptr.push(0);
    for (counts, i, d) in chunks {
        for n in counts {
            indptr.push(indptr.last().copied().unwrap_or(0) + n);
        }
        indices.extend(i);
        data.extend(d);
    }
    CsMat::new((rows, cols), indptr, indices, data)
}

/// `A B` for CSR matrices, rows in parallel. Each row is accumulated in
/// a dense scratch row (one per worker, reset per row) in the order of
/// `A`'s and `B`'s storage, so the sums do not depend on the threads.
pub fn product(a: &CsMat<f64>, b: &CsMat<f64>) -> CsMat<f64> {
    debug_assert!(a.is_csr() && b.is_csr());
    debug_assert_eq!(a.cols(), b.rows());
    let (ap, bp) = (a.indptr(), b.indptr());
    let (ap, bp) = (ap.to_proper(), bp.to_proper());
    let (rows, cols) = (a.rows(), b.cols());
    let chunks: Vec<(Vec<usize>, Vec<usize>, Vec<f64>)> = (0..rows.div_ceil(ROWS))
        .into_par_iter()
        .map_init(
            || (vec![usize::MAX; cols], vec![0.0f64; cols]),
            |(mark, acc), c| {
                let range = c * ROWS..((c + 1) * ROWS).min(rows);
                let mut counts = Vec::with_capacity(range.len());
                let mut indices = Vec::new();
                let mut data = Vec::new();
                for i in range {
                    let before = indices.len();
                    for k in ap[i]..ap[i + 1] {
                        let (mid, va) = (a.indices()[k], a.data()[k]);
                        for m in bp[mid]..bp[mid + 1] {
                            let col = b.indices()[m];
                            if mark[col] != i {
                                mark[col] = i;
                                acc[col] = 0.0;
                                indices.push(col);
                            }
                            acc[col] += va * b.data()[m];
                        }
                    }
                    indices[before..].sort_unstable();
                    data.extend(indices[before..].iter().map(|&col| acc[col]));
                    counts.push(indices.len() - before);
                }
                (counts, indices, data)
            },
        )
        .collect();
    stitch(rows, cols, chunks)
}

/// `Aᵀ` as a CSR matrix.
pub fn transpose(a: &CsMat<f64>) -> CsMat<f64> {
    a.transpose_view().to_csr()
}

#[cfg(test)]
mod tests {
    use super::*;
    use sprs::TriMat;

    fn small() -> CsMat<f64> {
        let mut t = TriMat::new((3, 3));
        for (i, j, v) in [
            (0, 0, 4.0),
            (0, 2, -1.0),
            (1, 1, 3.0),
            (2, 0, -1.0),
            (2, 2, 5.0),
            (1, 0, 2.0),
        ] {
            t.add_triplet(i, j, v);
        }
        t.to_csr()
    }

    #[test]
    fn product_and_matvec_agree_with_sprs() {
        let a = small();
        let b = &a * &a;
        let ours = product(&a, &a);
        assert_eq!(ours.to_dense(), b.to_dense());
        let mut y = vec![0.0; 3];
        mul_vec(&a, &[1.0, 2.0, 3.0], &mut y);
        assert_eq!(y, vec![1.0, 8.0, 14.0]);
        assert_eq!(diagonal(&a), vec![4.0, 3.0, 5.0]);
        assert_eq!(transpose(&a).to_dense(), a.transpose_view().to_dense());
    }

    #[test]
    fn assembly_sums_duplicates_and_sorts() {
        let m = assemble(2, 3, |i, out| {
            out.extend([(2, 1.0), (0, 2.0), (2, 0.5 + i as f64)]);
        });
        assert_eq!(m.indices(), &[0, 2, 0, 2]);
        assert_eq!(m.data(), &[2.0, 1.5, 2.0, 2.5]);
    }
}
