//! Matrix Market files (`.mtx`, NIST's exchange format): read a system
//! someone else assembled, write one for another solver.
//!
//! Matrices: `coordinate` with `real`, `double`, `integer` or `pattern`
//! fields (pattern entries are 1) and `general`, `symmetric`,
//! `skew-symmetric` or `hermitian` (real, so symmetric) storage; duplicate
//! entries are summed. Vectors: `array` or `coordinate`, `n × 1` or `1 × n`.
//! `complex` fields are refused by name.
//!
//! Sizes come from the file's header, so they are checked against
//! [`MAX_DIMENSION`] before anything is allocated, and the entry count is
//! never trusted for an allocation larger than the file can hold.
//!
//! # Example
//! ```
//! use multires::{mtx, SolveOptions, VCycle, VCycleOptions, Weights};
//! # let dir = std::env::temp_dir().join(format!("multires-mtx-doc-{}", std::process::id()));
//! # std::fs::create_dir_all(&dir).unwrap();
//! # let p = multires::grid::diffusion([10, 10, 10], 4.0)?;
//! # mtx::write_matrix(dir.join("A.mtx"), &p.matrix)?;
//! # mtx::write_vector(dir.join("b.mtx"), &p.rhs)?;
//! let a = mtx::read_matrix(dir.join("A.mtx"))?;
//! let b = mtx::read_vector(dir.join("b.mtx"))?;
//! let mut x = vec![0.0; b.len()];
//! let report = VCycle::new(&a, Weights::Uniform, &VCycleOptions::default())?
//!     .solve(&b, &mut x, &SolveOptions::default())?;
//! assert!(report.converged());
//! # std::fs::remove_dir_all(&dir).unwrap();
//! # Ok::<(), multires::Error>(())
//! ```

use std::fmt::Write as _;
use std::path::Path;

use sprs::{CsMat, TriMat};

use crate::Error;

/// The largest number of rows or columns a file may declare: 2²⁷ (134
/// million), 1 GiB of CSR row pointers. Larger headers are refused before
/// allocating.
pub const MAX_DIMENSION: usize = 1 << 27;

/// The storage schemes of the banner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Symmetry {
    General,
    Symmetric,
    Skew,
}

/// The banner and the size line, and where the entries start.
struct Header {
    coordinate: bool,
    pattern: bool,
    symmetry: Symmetry,
    rows: usize,
    cols: usize,
    /// Entries announced (coordinate) or `rows · cols` (array).
    entries: usize,
}

fn err(path: &Path, line: usize, message: impl Into<String>) -> Error {
    Error::MatrixMarket {
        path: path.to_path_buf(),
        line,
        message: message.into(),
    }
}

fn read_text(path: &Path) -> Result<String, Error> {
    let bytes = std::fs::read(path).map_err(|e| err(path, 0, format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        err(
            path,
            0,
            format!(
                "not a text file (invalid UTF-8 at byte {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// The data lines (1-based numbers) after the banner, comments and blank
/// lines skipped.
fn data_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .skip(1)
        .map(|(k, l)| (k + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('%'))
}

fn parse_header(path: &Path, text: &str) -> Result<Header, Error> {
    let banner = text
        .lines()
        .next()
        .unwrap_or_default()
        .trim_start_matches('\u{feff}');
    let words: Vec<String> = banner
        .split_whitespace()
        .map(str::to_ascii_lowercase)
        .collect();
    if words.len() != 5 || words[0] != "%%matrixmarket" || words[1] != "matrix" {
        return Err(err(
            path,
            1,
            format!(
                "expected a banner \"%%MatrixMarket matrix <format> <field> <symmetry>\", found {banner:?}"
            ),
        ));
    }
    let coordinate = match words[2].as_str() {
        "coordinate" => true,
        "array" => false,
        other => {
            return Err(err(
                path,
                1,
                format!("unknown format {other:?} (coordinate or array)"),
            ));
        }
    };
    let pattern = match words[3].as_str() {
        "real" | "double" | "integer" => false,
        "pattern" if coordinate => true,
        other => {
            return Err(err(
                path,
                1,
                format!("field {other:?} is not supported (real, double, integer or pattern)"),
            ));
        }
    };
    let symmetry = match words[4].as_str() {
        "general" => Symmetry::General,
        "symmetric" | "hermitian" => Symmetry::Symmetric,
        "skew-symmetric" => Symmetry::Skew,
        other => return Err(err(path, 1, format!("unknown symmetry {other:?}"))),
    };
    let (line, size) = data_lines(text)
        .next()
        .ok_or_else(|| err(path, 0, "the file ends before the size line"))?;
    let numbers: Vec<usize> = size
        .split_whitespace()
        .map(|w| w.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| err(path, line, format!("bad size line {size:?}")))?;
    let expected = if coordinate { 3 } else { 2 };
    if numbers.len() != expected {
        return Err(err(
            path,
            line,
            format!("the size line needs {expected} whole numbers, found {size:?}"),
        ));
    }
    let (rows, cols) = (numbers[0], numbers[1]);
    for (what, n) in [("rows", rows), ("columns", cols)] {
        if n > MAX_DIMENSION {
            return Err(err(
                path,
                line,
                format!("{n} {what} is more than the {MAX_DIMENSION} this reader allows"),
            ));
        }
    }
    if symmetry != Symmetry::General && rows != cols {
        return Err(err(
            path,
            line,
            format!("a symmetric matrix must be square, not {rows}×{cols}"),
        ));
    }
    let entries = if coordinate { numbers[2] } else { rows * cols };
    Ok(Header {
        coordinate,
        pattern,
        symmetry,
        rows,
        cols,
        entries,
    })
}

fn number(path: &Path, line: usize, word: Option<&str>, what: &str) -> Result<f64, Error> {
    let word = word.ok_or_else(|| err(path, line, format!("missing {what}")))?;
    let v: f64 = word
        .parse()
        .map_err(|_| err(path, line, format!("{what} {word:?} is not a number")))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(err(path, line, format!("{what} is {v}")))
    }
}

fn index(
    path: &Path,
    line: usize,
    word: Option<&str>,
    what: &str,
    n: usize,
) -> Result<usize, Error> {
    let word = word.ok_or_else(|| err(path, line, format!("missing {what} index")))?;
    match word.parse::<usize>() {
        Ok(i) if (1..=n).contains(&i) => Ok(i - 1),
        _ => Err(err(
            path,
            line,
            format!("{what} index {word:?} is not in 1..={n}"),
        )),
    }
}

/// The `(row, column, value)` entries of the file, symmetric storage
/// mirrored, in file order.
fn triplets(path: &Path, text: &str, h: &Header) -> Result<TriMat<f64>, Error> {
    // Never reserve more than the file could hold (an entry takes at least
    // 4 bytes, "1 1\n"), whatever the header claims.
    let reserve = h.entries.min(text.len() / 4)
        * if h.symmetry == Symmetry::General {
            1
        } else {
            2
        };
    let mut tri = TriMat::with_capacity((h.rows, h.cols), reserve);
    let mut lines = data_lines(text).skip(1);
    let mut read = 0usize;
    while read < h.entries {
        let Some((line, l)) = lines.next() else {
            return Err(err(
                path,
                0,
                format!(
                    "the header announces {} entries but the file has {read}",
                    h.entries
                ),
            ));
        };
        let mut words = l.split_whitespace();
        let (i, j) = if h.coordinate {
            (
                index(path, line, words.next(), "row", h.rows)?,
                index(path, line, words.next(), "column", h.cols)?,
            )
        } else {
            // Array data is column-major.
            (read % h.rows.max(1), read / h.rows.max(1))
        };
        let v = if h.pattern {
            1.0
        } else {
            number(path, line, words.next(), "value")?
        };
        if let Some(extra) = words.next() {
            return Err(err(
                path,
                line,
                format!("unexpected {extra:?} after the entry"),
            ));
        }
        tri.add_triplet(i, j, v);
        if i != j {
            match h.symmetry {
                Symmetry::General => {}
                Symmetry::Symmetric => tri.add_triplet(j, i, v),
                Symmetry::Skew => tri.add_triplet(j, i, -v),
            }
        }
        read += 1;
    }
    if let Some((line, l)) = lines.next() {
        return Err(err(
            path,
            line,
            format!("{l:?} after the {} announced entries", h.entries),
        ));
    }
    Ok(tri)
}

/// Reads a sparse matrix as CSR (duplicates summed).
///
/// # Errors
/// [`Error::MatrixMarket`] naming the file and line: unreadable file, bad
/// banner or size line, a dimension above [`MAX_DIMENSION`], an index out
/// of range, a value that is not a finite number, fewer or more entries
/// than announced.
pub fn read_matrix(path: impl AsRef<Path>) -> Result<CsMat<f64>, Error> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let header = parse_header(path, &text)?;
    Ok(triplets(path, &text, &header)?.to_csr())
}

/// Reads a vector: an `array` or `coordinate` file of `n × 1` or `1 × n`.
///
/// # Errors
/// As [`read_matrix`], and a file with more than one row and column.
pub fn read_vector(path: impl AsRef<Path>) -> Result<Vec<f64>, Error> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let header = parse_header(path, &text)?;
    if header.rows != 1 && header.cols != 1 {
        return Err(err(
            path,
            0,
            format!(
                "a vector must be n×1 or 1×n, not {}×{}",
                header.rows, header.cols
            ),
        ));
    }
    let tri = triplets(path, &text, &header)?;
    let mut v = vec![0.0; header.rows.max(header.cols)];
    for (&x, (i, j)) in tri
        .data()
        .iter()
        .zip(tri.row_inds().iter().zip(tri.col_inds()))
    {
        v[i.max(j).to_owned()] += x;
    }
    Ok(v)
}

fn write_text(path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|e| err(path, 0, format!("cannot write: {e}")))
}

/// Writes a sparse matrix (`coordinate real general`, values in Rust's
/// shortest round-trip form, so reading it back gives the same bits).
///
/// # Errors
/// [`Error::MatrixMarket`] when the file cannot be written.
pub fn write_matrix(path: impl AsRef<Path>, a: &CsMat<f64>) -> Result<(), Error> {
    let mut text = String::from("%%MatrixMarket matrix coordinate real general\n");
    let _ = writeln!(text, "{} {} {}", a.rows(), a.cols(), a.nnz());
    for (&v, (i, j)) in a.iter() {
        let _ = writeln!(text, "{} {} {v:e}", i + 1, j + 1);
    }
    write_text(path.as_ref(), &text)
}

/// Writes a vector (`array real general`, `n × 1`).
///
/// # Errors
/// [`Error::MatrixMarket`] when the file cannot be written.
pub fn write_vector(path: impl AsRef<Path>, v: &[f64]) -> Result<(), Error> {
    let mut text = String::from("%%MatrixMarket matrix array real general\n");
    let _ = writeln!(text, "{} 1", v.len());
    for x in v {
        let _ = writeln!(text, "{x:e}");
    }
    write_text(path.as_ref(), &text)
}
